"""The expectation's mean near grazing with Eq. 5, the slope-conditioned and the multi-scale masking,
against the ray-traced ensemble mean.

1. For the ensembles of ``pipelines/texture_vs_raytrace.py`` at pitch −6° (view zenith 79.6–88.4°;
   winds 5, 10, 15 m/s; upwind from a 15 m mast and crosswind from 20 m; 48×64 px over 12°; LWIR,
   LOWTRAN midlatitude summer, sea 290 K, no foam, no path, flat Earth) it renders the expectation image
   (``seed=None``) with ``shadowing=True`` (the paper's Eq. 5), ``"correlated"``
   (:mod:`roughsea_torch.masking`) and ``"multiscale"`` (:mod:`roughsea_torch.multiscale_masking`) and
   reports, per 8-row bin, in kelvin, the ray-traced ensemble mean minus each (± the standard error over
   16 seeds). The ray tracer traces the bands up to 64 rad/m and leaves the shorter waves to the model
   (Eq. 5 in ``--load``'s trace); with ``--load-multiscale`` (a trace whose untraced waves take the
   multi-scale masking, ``texture_vs_raytrace.py --ray-shadowing multiscale``) a last column compares
   the multi-scale expectation with it, both then treating every wave alike.
2. ``--sweep``: which waves make the difference. Looking crosswind at 5 m/s (−6°), the ray-traced ensemble
   mean (8 seeds, 4 rays per pixel) with the traced bands cut at k_max = 1, 4, 16 and 64 rad/m (Eq. 5
   for the rest), against the multi-scale cascade over the same bands (the seen along-view slope of the
   traced bands' variance σ_t² from the closed form of :mod:`roughsea_torch.multiscale_masking`, Eq. 5
   for the rest about it; a mixture of ``apparent_radiance`` over that density, 8 view zeniths per bin).

3. The first hit's lever: the texture of a textured render is the unresolved model's response to the
   resolved slope at each hit, so its amplitude goes with dT_b/dm∥, the brightness temperature's
   derivative in the along-view mean slope (autograd; LWIR, midlatitude summer, 290 K, isotropic
   unresolved rms 0.061 and 0.1 along the view, about 5 m/s's unresolved part), per option and view zenith.

The ray-traced side of 1 is read from pickles written by ``texture_vs_raytrace.py --save`` (no tracing);
without one, run that pipeline first (``--save results.pkl``, about 10 minutes). The sweep traces
(about 1 minute).

Usage:
    python pipelines/shadowing_mean.py --load results.pkl [--load-multiscale results_ms.pkl] [--sweep] [--out docs]
"""

from __future__ import annotations

import argparse
import datetime as dt
import math
import os
import pickle
import sys
import time
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")

import numpy as np  # noqa: E402
import torch  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "pipelines"))

from _report import pyplot, write_report  # noqa: E402
import texture_vs_raytrace as tvr  # noqa: E402

import roughsea_torch as rs  # noqa: E402
from roughsea_torch import raytrace as rt  # noqa: E402
from roughsea_torch.atmosphere import load_sky  # noqa: E402
from roughsea_torch.multiscale_masking import multiscale_ratio  # noqa: E402
from tqdm import tqdm  # noqa: E402

PITCH = -6.0


def expectation_bins(direction: str, wind: float, shadowing) -> tuple[np.ndarray, np.ndarray]:
    """(bin means [K], view zenith of the bins' centres [deg]) of the expectation image."""
    mast, wdir = tvr.DIRECTIONS[direction]
    cams = rs.make_camera(tvr.H, tvr.W, hfov_deg=tvr.HFOV, altitude_m=mast, pitch_deg=PITCH)
    sc = rs.SeaScene(wind_speed=wind, wind_direction=wdir, sea_temperature=tvr.T_SEA, seed=None, time_s=tvr.TIME_S,
                     foam=False, path=False, sky="midlatitude_summer", shadowing=shadowing)
    img = tvr.render(cams, sc)[0, 0].numpy()
    return np.array([img[r0:r0 + tvr.BIN].mean() for r0 in range(0, tvr.H, tvr.BIN)])


def run(saved: dict, saved_ms: dict | None) -> list[dict]:
    rows = []
    ms_ens = {(e["direction"], e["wind"], e["pitch"]): e for e in (saved_ms or {}).get("ens", [])}
    for e in saved["ens"]:
        if e["pitch"] != PITCH:
            continue
        eq5 = expectation_bins(e["direction"], e["wind"], True)
        cor = expectation_bins(e["direction"], e["wind"], "correlated")
        mul = expectation_bins(e["direction"], e["wind"], "multiscale")
        other = ms_ens.get((e["direction"], e["wind"], e["pitch"]))
        for i, (b, m5, mc, mm) in enumerate(zip(e["bins"], eq5, cor, mul)):
            rows.append(dict(direction=e["direction"], wind=e["wind"], vz=b["vz"], ray=b["ray"], se=b["ray_se"],
                             ray_cor=b["ray"] - float(mc - m5), ray_mul=b["ray"] - float(mm - m5),
                             ray_ms_mul=None if other is None else other["bins"][i]["ray"] - float(mm - m5),
                             se_ms=None if other is None else other["bins"][i]["ray_se"]))
    return rows


def sweep(bar_desc: str = "k_max sweep") -> list[dict]:
    """Part 2 of the module docstring: per k_max, the ray-traced ensemble's bin means and the cascade's,
    both minus the Eq. 5 expectation image [K]."""
    direction, wind = "crosswind", 5.0
    mast, wdir = tvr.DIRECTIONS[direction]
    seeds = list(range(200, 208))
    cams = rs.make_camera(tvr.H, tvr.W, hfov_deg=tvr.HFOV, altitude_m=mast, pitch_deg=PITCH, batch_size=len(seeds))
    cam1 = rs.make_camera(tvr.H, tvr.W, hfov_deg=tvr.HFOV, altitude_m=mast, pitch_deg=PITCH)
    geo = rs.view_geometry(cam1, earth_radius_m=math.inf)
    vz_rows = geo.view_zenith.double().reshape(tvr.H, tvr.W).mean(-1).numpy()  # (H,) [rad]
    los = float(geo.view_azimuth.double().mean()) - wdir  # the view's azimuth from the upwind axis
    eq5 = expectation_bins(direction, wind, True)
    field = rs.SeaScene(wind_speed=wind, wind_direction=wdir, sea_temperature=tvr.T_SEA, seed=seeds[:1],
                        time_s=tvr.TIME_S).wave_field(
        1, torch.float64, torch.device("cpu"))
    total = rs.SlopeStatistics.cox_munk(wind, anisotropic=True)
    band = rs.LWIR
    m = rs.band_refractive_index(band, tvr.T_SEA).to(torch.complex128)
    rb = rs.band_radiance(torch.tensor(tvr.T_SEA, dtype=torch.float64), band)
    sky = load_sky("midlatitude_summer", band, dtype=torch.float64)
    c, s = math.cos(los), math.sin(los)
    out = []
    for k_max in tqdm((1.0, 4.0, 16.0, 64.0), desc=bar_desc):
        ray = rt.raytraced_image(cams, wind, seed=seeds, time_s=tvr.TIME_S, wind_direction=wdir, sea_temperature=tvr.T_SEA,
                                 rays_per_pixel=4, k_max=k_max)["brightness_temperature"].double()
        per_seed = np.array([[ray[i, 0, r0:r0 + tvr.BIN].mean().item() for r0 in range(0, tvr.H, tvr.BIN)]
                             for i in range(len(seeds))])
        traced = rt._unresolved_statistics(total, rt.TracedSurface(field, tvr.TIME_S, k_max).traced_covariance,
                                           torch.tensor([wdir], dtype=torch.float64))[0]
        cov_t = [float(v) - float(u) for v, u in zip((total.var_upwind, total.var_crosswind, total.cov), traced)]
        var_par = cov_t[0] * c * c + 2 * cov_t[2] * c * s + cov_t[1] * s * s
        var_acr = cov_t[0] * s * s - 2 * cov_t[2] * c * s + cov_t[1] * c * c
        rest = rs.SlopeStatistics.from_variances(*(torch.as_tensor(float(v), dtype=torch.float64) for v in traced))
        model = []
        for r0 in range(0, tvr.H, tvr.BIN):
            rows = np.linspace(vz_rows[r0], vz_rows[r0 + tvr.BIN - 1], 8)
            model.append(np.mean([cascade_radiance(th, los, var_par, var_acr, rest, m, rb, sky) for th in rows]))
        bt = rs.brightness_temperature(torch.tensor(model, dtype=torch.float64), band).numpy()
        out.append(dict(k_max=k_max, ray=per_seed.mean(0) - eq5, ray_se=per_seed.std(0, ddof=1) / math.sqrt(len(seeds)),
                        cascade=bt - eq5, var_par=var_par))
    return out


def lever() -> list[dict]:
    """Part 3 of the module docstring: dT_b/dm∥ [K per unit slope] per option, view zenith and rms."""
    band, dt = rs.LWIR, torch.float64
    m = rs.band_refractive_index(band, tvr.T_SEA).to(torch.complex128)
    rb = rs.band_radiance(torch.tensor(tvr.T_SEA, dtype=dt), band)
    sky = load_sky("midlatitude_summer", band, dtype=dt)
    rows = []
    for th_deg in (82.0, 86.0, 88.0):
        for sig in (0.061, 0.1):
            row = dict(th=th_deg, sigma=sig)
            for name, option in (("eq5", True), ("correlated", "correlated"), ("multiscale", "multiscale")):
                mean = torch.tensor(0.0, dtype=dt, requires_grad=True)
                var = torch.tensor(sig * sig, dtype=dt)
                st = rs.SlopeStatistics.from_variances(var, var).shifted(mean, torch.tensor(0.0, dtype=dt))
                ra = rs.apparent_radiance(torch.tensor(math.radians(th_deg), dtype=dt), 0.0, st, m, rb, sky, shadowing=option)
                (g,) = torch.autograd.grad(rs.brightness_temperature(ra, band), mean)
                row[name] = float(g)
            rows.append(row)
    return rows


def cascade_radiance(th: float, los: float, var_par: float, var_acr: float, rest, m, rb, sky, n: int = 600) -> float:
    """R_a [W m⁻² sr⁻¹] of the multi-scale cascade over slopes of along/across-view variances (var_par,
    var_acr) with Eq. 5 for ``rest`` (SlopeStatistics) about each: the seen along-view slope s of the cascaded
    part has the density ∝ h φ_V(h − h₀) Q (= (h/h₀)[φ_V(h − h₀) − φ_V(h + h₀)]), h = cot θ̂ + s, h₀ = cot θ̂,
    V = var_par, Q the package's factor (:func:`~roughsea_torch.multiscale_masking.multiscale_ratio`), its
    across-view slope N(0, var_acr) (12 Gauss–Hermite nodes)."""
    h0, sd = 1.0 / math.tan(th), math.sqrt(var_par)
    h = torch.linspace(1e-9, h0 + 9.0 * sd, n, dtype=torch.float64)
    dens = h * torch.exp(-(h - h0) ** 2 / (2 * var_par)) * multiscale_ratio((h - h0) / sd, torch.tensor(h0 / sd))
    xg, wg = np.polynomial.hermite_e.hermegauss(12)
    xg, wg = torch.as_tensor(xg), torch.as_tensor(wg / wg.sum())
    par = (h - h0)[:, None].expand(-1, 12)
    acr = (math.sqrt(var_acr) * xg)[None, :].expand(n, -1)
    c, s = math.cos(los), math.sin(los)
    up, cr = (par * c - acr * s).reshape(-1), (par * s + acr * c).reshape(-1)
    st = rs.SlopeStatistics.from_variances(rest.var_upwind.expand_as(up), rest.var_crosswind.expand_as(up),
                                           rest.cov.expand_as(up)).shifted(up, cr)
    ra = rs.apparent_radiance(torch.full_like(up, th), torch.full_like(up, los), st, m, rb, sky).reshape(n, 12)
    return float(((ra * wg).sum(1) * dens).sum() / dens.sum())


def report(rows: list[dict], source: str, source_ms: str | None, sw: list[dict] | None, lev: list[dict],
           seconds: float) -> str:
    ms = source_ms is not None
    lines = [
        "# The expectation's mean near grazing: Eq. 5 and the masking options against the ray tracer",
        "",
        f"Written by `pipelines/shadowing_mean.py` ({dt.date.today().isoformat()}, {seconds:.0f} s) from the ray-traced "
        f"ensembles of `{source}`" + (f" and `{source_ms}`" if ms else "") + " (`pipelines/texture_vs_raytrace.py --save`, "
        "16 seeds, 4 rays per pixel; the bands up to 64 rad/m traced, the shorter waves left to the model: Eq. 5"
        + (", and in the second trace the multi-scale masking" if ms else "") + ").",
        "",
        "Per 8-row bin, mean brightness temperature differences [K]: the ray-traced ensemble mean minus the expectation "
        "image with the paper's Eq. 5 (± standard error over the seeds), with `shadowing=\"correlated\"` and with "
        "`shadowing=\"multiscale\"`" + ("; last column: the trace whose untraced waves take the multi-scale masking, "
                                          "minus the multi-scale expectation." if ms else "."),
        "",
        "| looking | wind [m/s] | view zenith [°] | ray − Eq. 5 [K] | ray − corr. [K] | ray − multiscale [K] |"
        + (" ray (multiscale beyond 64 rad/m) − multiscale [K] |" if ms else ""),
        "|---|---:|---|---:|---:|---:|" + ("---:|" if ms else ""),
    ]
    for r in rows:
        lines.append(f"| {r['direction']} | {r['wind']:g} | {r['vz'][0]:.1f}–{r['vz'][1]:.1f} | "
                     f"{r['ray']:+.3f} ± {r['se']:.3f} | {r['ray_cor']:+.3f} | {r['ray_mul']:+.3f} |"
                     + (f" {r['ray_ms_mul']:+.3f} ± {r['se_ms']:.3f} |" if ms and r["ray_ms_mul"] is not None else
                        " – |" if ms else ""))
    cols = [("Eq. 5", "ray"), ("correlated", "ray_cor"), ("multiscale", "ray_mul")]
    if ms:
        cols.append(("multiscale against the trace with multi-scale masking beyond 64 rad/m", "ray_ms_mul"))
    parts = []
    for name, key in cols:
        vals = [r[key] for r in rows if r[key] is not None]
        parts.append(f"{name}: largest |offset| {max(abs(v) for v in vals):.3f} K, within 0.05 K in "
                     f"{sum(abs(v) <= 0.05 for v in vals)} / {len(vals)} bins")
    lines += ["", "; ".join(parts) + "."]
    if sw:
        lines += [
            "",
            "## Which waves make the difference",
            "",
            "Looking crosswind at 5 m/s from 20 m, 6° down; 8 seeds, 4 rays per pixel. The ray tracer traces the bands up "
            "to k_max and leaves the rest to Eq. 5; the cascade is the multi-scale masking over the same traced bands' "
            "slope variance σ_t² along the view, with Eq. 5 for the rest about each seen slope. Both minus the Eq. 5 "
            "expectation image, per 8-row bin [K].",
            "",
            "| k_max [rad/m] | σ_t² along the view | " + " | ".join(f"bin {i + 1}: ray / cascade" for i in range(len(sw[0]["ray"])))
            + " |",
            "|---:|---:|" + "---|" * len(sw[0]["ray"]),
        ]
        for e in sw:
            cells = " | ".join(f"{a:+.3f} ± {se:.3f} / {b:+.3f}" for a, se, b in zip(e["ray"], e["ray_se"], e["cascade"]))
            lines.append(f"| {e['k_max']:g} | {e['var_par']:.4f} | {cells} |")
        worst = max(abs(a - b) for e in sw for a, b in zip(e["ray"], e["cascade"]))
        lines += ["", f"Largest |ray − cascade| over the table: {worst:.3f} K (bins from the top: 87.1–88.4°, 85.6–86.9°, "
                      "84.1–85.4°, 82.6–83.9°, 81.1–82.4°, 79.6–80.9°)."]
    lines += [
        "",
        "## The first hit's lever",
        "",
        "dT_b/dm∥ [K per unit slope]: how much the unresolved model's brightness temperature moves with the resolved "
        "slope along the view at a hit (LWIR, midlatitude summer, 290 K; isotropic unresolved slopes of rms σ_u). "
        "The first hit's clutter scales with it.",
        "",
        "| view zenith [°] | σ_u | Eq. 5 | correlated | multiscale |",
        "|---:|---:|---:|---:|---:|",
    ]
    lines += [f"| {r['th']:g} | {r['sigma']:g} | {r['eq5']:+.2f} | {r['correlated']:+.2f} | {r['multiscale']:+.2f} |"
              for r in lev]
    return "\n".join(lines) + "\n"


def figure(rows: list[dict], out: Path) -> None:
    plt = pyplot()
    if plt is None:
        return
    fig, axes = plt.subplots(1, 2, figsize=(10, 5.0), sharey=True)
    for ax, direction in zip(axes, ("upwind", "crosswind")):
        for wind, color in zip((5.0, 10.0, 15.0), ("C0", "C1", "C2")):
            rr = [r for r in rows if r["direction"] == direction and r["wind"] == wind]
            if not rr:
                continue
            vz = [0.5 * (r["vz"][0] + r["vz"][1]) for r in rr]
            ax.errorbar(vz, [r["ray"] for r in rr], [r["se"] for r in rr], color=color, marker="o",
                        label=f"{wind:g} m/s, Eq. 5")
            ax.plot(vz, [r["ray_cor"] for r in rr], color=color, marker="s", ls=":", label=f"{wind:g} m/s, correlated")
            ax.plot(vz, [r["ray_mul"] for r in rr], color=color, marker="^", ls="--", label=f"{wind:g} m/s, multiscale")
            if all(r["ray_ms_mul"] is not None for r in rr):
                ax.plot(vz, [r["ray_ms_mul"] for r in rr], color=color, marker="*", ms=9, ls="-.",
                        label=f"{wind:g} m/s, multiscale, trace alike")
        ax.axhline(0.0, color="k", lw=0.5)
        ax.axhspan(-0.05, 0.05, color="0.9", zorder=0)
        ax.set_title(f"looking {direction}")
        ax.set_xlabel("view zenith [deg]")
    axes[0].set_ylabel("ray-traced mean − expectation [K]")
    handles, labels = axes[1].get_legend_handles_labels()
    fig.legend(handles, labels, fontsize=7, ncol=3, loc="lower center")
    fig.tight_layout(rect=(0, 0.2, 1, 1))
    fig.savefig(out / "shadowing_mean.png", dpi=110)
    plt.close(fig)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--load", required=True, help="a pickle of texture_vs_raytrace.py --save")
    ap.add_argument("--load-multiscale", default=None,
                    help="a pickle of texture_vs_raytrace.py --ray-shadowing multiscale --save (optional)")
    ap.add_argument("--sweep", action="store_true", help="also trace the k_max sweep (about a minute)")
    ap.add_argument("--out", default=str(ROOT / "docs"))
    args = ap.parse_args()
    torch.set_num_threads(1)
    with open(args.load, "rb") as fh:
        saved = pickle.load(fh)
    saved_ms = None
    if args.load_multiscale:
        with open(args.load_multiscale, "rb") as fh:
            saved_ms = pickle.load(fh)
    t0 = time.perf_counter()
    rows = run(saved, saved_ms)
    sw = sweep() if args.sweep else None
    text = report(rows, Path(args.load).name, Path(args.load_multiscale).name if args.load_multiscale else None, sw,
                  lever(), time.perf_counter() - t0)
    out = write_report(args.out, "shadowing_mean.md", text)
    figure(rows, out)


if __name__ == "__main__":
    main()

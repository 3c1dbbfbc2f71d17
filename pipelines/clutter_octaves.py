"""Which waves make the clutter near grazing: the ray tracer's clutter, octave by octave, against the
textured render's.

The textured render (``TableSize(texture_hit="first")``) resolves the waves down to about a pixel's
across-view footprint and gives the shorter ones the model's expectation about the resolved slope at
each hit. The ray tracer of the same realization (``raytrace.raytraced_image``) takes explicitly the
bands it traces. Tracing fewer bands (k_max = 4, 8, 16, 64 rad/m; the rest statistical, with the
masking ``--shadowing``) shows how much clutter each octave adds; a variant whose rays meet every band
up to 64 rad/m but take the slope of the bands up to 4 rad/m only (``slope_k_max=4``) separates what
the short waves' heights do (they hide what lies behind them) from what their slopes do.

Per case and 8-row bin it reports, in kelvin: σ (the clutter's standard deviation about each row's mean,
the ray tracer's sampling variance removed) of each trace and of the textured render (multi-scale and
Eq. 5 masking); the added part D = T₆₄ − T₄ (two traces with independent sub-pixel rays, so every
second moment below is free of the sampling noise): its variance, its correlation with the clutter of
T₄ (0: new clutter of its own; > 0: the short waves amplify the resolved clutter), its autocorrelation
at one pixel across and along the view (0: independent from pixel to pixel); and the correlation of the
textured render with T₄ and T₆₄.

``--pixel-scaling``: whether the added part is the finite number of short waves a pixel holds. With
the rays meeting every band up to 64 rad/m, the same hits give T₆₄ (slopes of every traced band) and
T₄ (``slope_k_max=4``), so D = T₆₄ − T₄ is exactly paired ray by ray; two ray seeds give two estimates of
D whose covariance is its variance free of sampling noise. Cameras of 6°, 12° and 24° field of view
(48×64 px: pixels of 1/4, 1 and 4 times the area), pitch −3°, give var D per view-zenith bin
(85.5–87°, 87–88.5°): a variance that falls as 1/(pixel area) is finite sampling.

The scene is ``texture_vs_raytrace.py``'s (48×64 px over 12°, pitch −6°, LWIR, LOWTRAN midlatitude
summer, sea 290 K, no foam, no path, flat Earth; upwind from a 15 m mast, crosswind from 20 m), one
realization (``--seed``, ``--time``).

Usage:
    python pipelines/clutter_octaves.py [--cases upwind:5 crosswind:5 upwind:10] [--rays 128] [--out docs]
    python pipelines/clutter_octaves.py --pixel-scaling [--cases upwind:5 upwind:10] [--out docs]

About 25 s per trace at 128 rays per pixel on one thread; 6 traces per case.
"""

from __future__ import annotations

import argparse
import datetime as dt
import math
import os
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

K_LIST = (4.0, 8.0, 16.0, 64.0)
BINS = 3  # the top three 8-row bins (view zenith 83–88.4°)


def second_moments(a: np.ndarray, b: np.ndarray, same: bool, noise: np.ndarray | None = None) -> dict:
    """Noise-free second moments of the clutter (row means removed) of two images of one bin (rows, W):
    the covariance at lag 0 and at one pixel across (columns) and along (rows) the view. ``same``: a and b
    are one image, whose sampling variance ``noise`` (per pixel) is removed at lag 0; else their noises
    are independent and no correction is needed."""
    x, y = tvr.clutter(a), tvr.clutter(b)
    c0 = float((x * y).mean())
    across = 0.5 * float((x[:, 1:] * y[:, :-1]).mean() + (x[:, :-1] * y[:, 1:]).mean())
    along = 0.5 * float((x[1:] * y[:-1]).mean() + (x[:-1] * y[1:]).mean())
    if same and noise is not None:  # removing a row's mean leaves its white noise −σ²/W correlated across
        c0 -= float(noise.mean()) * (1.0 - 1.0 / x.shape[1])
        across += float(noise.mean()) / x.shape[1]
    return dict(c0=c0, across=across, along=along)


def added_part(t64: dict, t4: dict) -> dict:
    """Variance [K²] of D = T₆₄ − T₄, its correlation with T₄'s clutter and its autocorrelation at one
    pixel across and along the view, from the noise-free second moments (``second_moments``)."""
    m66 = second_moments(t64["T"], t64["T"], True, t64["noise"])
    m44 = second_moments(t4["T"], t4["T"], True, t4["noise"])
    m64 = second_moments(t64["T"], t4["T"], False)
    d = {k: m66[k] + m44[k] - 2.0 * m64[k] for k in ("c0", "across", "along")}
    var_d = d["c0"]
    ok = var_d > 0 and m44["c0"] > 0
    return dict(var=var_d, corr_t4=(m64["c0"] - m44["c0"]) / math.sqrt(var_d * m44["c0"]) if ok else math.nan,
                acf_across=d["across"] / var_d if var_d > 0 else math.nan,
                acf_along=d["along"] / var_d if var_d > 0 else math.nan)


def trace(cams, wind: float, direction: float, seed: int, time_s: float, rays: int, k_max: float,
          slope_k_max: float | None, ray_seed: int, shadowing) -> dict:
    out = rt.raytraced_image(cams, wind, seed=seed, time_s=time_s, wind_direction=direction, sea_temperature=tvr.T_SEA,
                             rays_per_pixel=rays, k_max=k_max, slope_k_max=slope_k_max, shadowing=shadowing,
                             ray_seed=ray_seed)
    return dict(T=out["brightness_temperature"][0, 0].double().numpy(),
                noise=out["brightness_temperature_noise_var"][0, 0].double().numpy())


def textured(cams, wind: float, direction: float, seed: int, time_s: float, shadowing) -> np.ndarray:
    """The first-hit textured render (``texture_vs_raytrace.render``) of the traced realization [K]."""
    scene = rs.SeaScene(wind_speed=wind, wind_direction=direction, sea_temperature=tvr.T_SEA, seed=seed, time_s=time_s,
                        foam=False, path=False, shadowing=shadowing)
    return tvr.render(cams, scene, table=rs.TableSize(texture_hit="first"))[0, 0].numpy()


def masking(option: str) -> bool | str:
    """``--shadowing`` as ``SeaScene(shadowing=)`` and ``raytraced_image(shadowing=)`` take it."""
    return True if option == "eq5" else option


def run_case(direction_name: str, wind: float, args) -> dict:
    mast, direction = tvr.DIRECTIONS[direction_name]
    cams = rs.make_camera(tvr.H, tvr.W, hfov_deg=tvr.HFOV, altitude_m=mast, pitch_deg=-6.0)
    vz = np.degrees(rs.view_geometry(cams, earth_radius_m=math.inf).view_zenith[0].double().numpy())
    traces = {}
    for i, k in enumerate(K_LIST):
        traces[k] = trace(cams, wind, direction, args.seed, args.time, args.rays, k, None, i + 1, masking(args.shadowing))
    traces["split"] = trace(cams, wind, direction, args.seed, args.time, args.rays, 64.0, 4.0, len(K_LIST) + 1,
                            masking(args.shadowing))
    tex = {name: textured(cams, wind, direction, args.seed, args.time, sh)
           for name, sh in (("multiscale", "multiscale"), ("eq5", True))}
    bins = []
    for b in range(BINS):
        sl = slice(b * tvr.BIN, (b + 1) * tvr.BIN)
        cut = {k: dict(T=v["T"][sl], noise=v["noise"][sl]) for k, v in traces.items()}
        row = dict(vz=(float(vz[sl].min()), float(vz[sl].max())),
                   sigma={k: tvr.sigma(v["T"], v["noise"]) for k, v in cut.items()},
                   sigma_tex={n: tvr.sigma(t[sl]) for n, t in tex.items()},
                   added=added_part(cut[64.0], cut[4.0]),
                   r_tex={k: tvr.correlation(tex["multiscale"][sl], cut[k]["T"], cut[k]["noise"]) for k in (4.0, 64.0)},
                   r4_tex={k: tvr.block_correlation(tex["multiscale"][sl], cut[k]["T"], cut[k]["noise"]) for k in (4.0, 64.0)})
        bins.append(row)
    return dict(direction=direction_name, wind=wind, bins=bins)


FOVS = (6.0, 12.0, 24.0)
VZ_BINS = ((85.5, 87.0), (87.0, 88.5))


def pixel_scaling(direction_name: str, wind: float, args) -> dict:
    """var D = var(T₆₄ − T₄) [K²] per field of view and view-zenith bin (``--pixel-scaling``; module docstring):
    the covariance of the two ray seeds' D clutter (row means removed), averaged over the rows whose
    centre pixel's view zenith lies in the bin; and var T₄ alike (noise removed)."""
    mast, direction = tvr.DIRECTIONS[direction_name]
    out = {}
    for fov in FOVS:
        cams = rs.make_camera(tvr.H, tvr.W, hfov_deg=fov, altitude_m=mast, pitch_deg=-3.0)
        vz = np.degrees(rs.view_geometry(cams, earth_radius_m=math.inf).view_zenith[0, :, tvr.W // 2].double().numpy())
        d, t4 = [], []
        for ray_seed in (1, 2):
            full = trace(cams, wind, direction, args.seed, args.time, args.rays, 64.0, None, ray_seed, masking(args.shadowing))
            low = trace(cams, wind, direction, args.seed, args.time, args.rays, 64.0, 4.0, ray_seed, masking(args.shadowing))
            d.append(full["T"] - low["T"])
            t4.append(low["T"])
        for lo, hi in VZ_BINS:
            rows = (vz >= lo) & (vz < hi)
            if rows.sum() < 2:
                continue
            cov = lambda a, b: float((tvr.clutter(a[rows]) * tvr.clutter(b[rows])).mean())  # noqa: E731
            out[(fov, lo)] = {"var_d": cov(d[0], d[1]), "var_t4": cov(t4[0], t4[1]), "rows": int(rows.sum())}
    return {"direction": direction_name, "wind": wind, "bins": out}


def scaling_report(cases: list[dict], args, seconds: float) -> str:
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else math.nan
    lines = [f"# The short waves' clutter against pixel size ({dt.date.today().isoformat()})", "",
             f"`python pipelines/clutter_octaves.py --pixel-scaling --rays {args.rays} --seed {args.seed} --time "
             f"{args.time} --cases {' '.join(args.cases)}` ({seconds / 60:.1f} min, one thread, load average {load:.1f}). "
             "48×64 px, pitch −3°, 6°, 12° and 24° fields of view (pixel areas 1/4, 1, 4); rays meeting every band "
             "up to 64 rad/m; D = T₆₄ − T₄ at the same hits (the slopes of bands up to 64 against up to 4 rad/m), "
             "its variance the covariance of two ray seeds' D (no sampling noise). [K²]", "",
             "| case | view zenith | var D, 6° | 12° | 24° | 12° / 6° | 24° / 12° | var T₄, 6° | 12° | 24° |",
             "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for c in cases:
        for lo, hi in VZ_BINS:
            v = [c["bins"].get((f, lo)) for f in FOVS]
            vd = [x["var_d"] if x else math.nan for x in v]
            vt = [x["var_t4"] if x else math.nan for x in v]
            ratio = lambda a, b: a / b if b > 0 and a > 0 else math.nan  # noqa: E731
            lines.append(f"| {c['direction']} {c['wind']:.0f} m/s | {lo}–{hi}° | " + " | ".join(fmt(x, 5) for x in vd)
                         + f" | {fmt(ratio(vd[1], vd[0]), 2)} | {fmt(ratio(vd[2], vd[1]), 2)} | "
                         + " | ".join(fmt(x, 5) for x in vt) + " |")
    lines += ["", "Finite sampling of independent patches would give ratios of 1/4 (variance ∝ 1/pixel area); the "
              "reading is in `docs/texture.md` §12.", ""]
    return "\n".join(lines)


def fmt(x: float, nd: int = 3) -> str:
    return "–" if x is None or (isinstance(x, float) and math.isnan(x)) else f"{x:.{nd}f}"


def report(cases: list[dict], args, seconds: float) -> str:
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else math.nan
    lines = [f"# Which waves make the clutter near grazing ({dt.date.today().isoformat()})", "",
             f"`python pipelines/clutter_octaves.py --rays {args.rays} --seed {args.seed} --time {args.time} "
             f"--shadowing {args.shadowing} --cases {' '.join(args.cases)}` ({seconds / 60:.1f} min, one thread, "
             f"load average {load:.1f}). Pitch −6°, 48×64 px over 12°, LWIR, midlatitude summer, sea 290 K; "
             f"the ray tracer's untraced waves and the textured render's unresolved ones take the "
             f"{'multi-scale masking' if args.shadowing == 'multiscale' else 'Eq. 5 masking'} (the textured Eq. 5 "
             "column excepted). σ in K, sampling noise removed.", "",
             "## σ of the ray tracer by the bands it traces, and of the textured render", "",
             "| case | view zenith | traced ≤ 4 | ≤ 8 | ≤ 16 | ≤ 64 | rays meet ≤ 64, slopes of ≤ 4 | textured, multi-scale "
             "| textured, Eq. 5 |", "|---|---|---:|---:|---:|---:|---:|---:|---:|"]
    for c in cases:
        for b in c["bins"]:
            s = b["sigma"]
            lines.append(f"| {c['direction']} {c['wind']:.0f} m/s | {b['vz'][0]:.1f}–{b['vz'][1]:.1f}° | "
                         + " | ".join(fmt(s[k]) for k in K_LIST) + f" | {fmt(s['split'])} | "
                         f"{fmt(b['sigma_tex']['multiscale'])} | {fmt(b['sigma_tex']['eq5'])} |")
    lines += ["", "## The added part D = T₆₄ − T₄, and the textured render against the traces", "",
              "| case | view zenith | var D [K²] | var T₄ [K²] | corr(D, T₄) | D's autocorrelation, 1 px across "
              "| 1 px along | r textured–T₄ | r textured–T₆₄ | 4×4 r textured–T₄ | 4×4 r textured–T₆₄ |",
              "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for c in cases:
        for b in c["bins"]:
            a = b["added"]
            lines.append(f"| {c['direction']} {c['wind']:.0f} m/s | {b['vz'][0]:.1f}–{b['vz'][1]:.1f}° | "
                         f"{fmt(a['var'], 4)} | {fmt(b['sigma'][4.0] ** 2, 4)} | {fmt(a['corr_t4'], 2)} | "
                         f"{fmt(a['acf_across'], 2)} | {fmt(a['acf_along'], 2)} | {fmt(b['r_tex'][4.0], 2)} | "
                         f"{fmt(b['r_tex'][64.0], 2)} | {fmt(b['r4_tex'][4.0], 2)} | {fmt(b['r4_tex'][64.0], 2)} |")
    lines += ["", "Second moments of D from two traces with independent sub-pixel rays (no sampling noise in their "
              "covariance); a correlation is – where a variance does not stand out of its sampling error. The "
              "reading is in `docs/texture.md` (\"The short waves' clutter near grazing\").", ""]
    return "\n".join(lines)


def figure(cases: list[dict], out: Path) -> None:
    plt = pyplot()
    if plt is None:
        return
    fig, axes = plt.subplots(1, len(cases), figsize=(4.2 * len(cases), 3.6), squeeze=False)
    for ax, c in zip(axes[0], cases):
        for i, b in enumerate(c["bins"]):
            col = f"C{i}"
            label = f"{b['vz'][0]:.1f}–{b['vz'][1]:.1f}°"
            ax.plot(K_LIST, [b["sigma"][k] for k in K_LIST], "o-", color=col, label=f"ray-traced, {label}")
            ax.plot([64.0], [b["sigma"]["split"]], "x", color=col, ms=9)
            ax.axhline(b["sigma_tex"]["multiscale"], color=col, ls="--", lw=1)
        ax.set_xscale("log", base=2)
        ax.set_xticks(K_LIST, [f"{k:.0f}" for k in K_LIST])
        ax.set_xlabel("largest traced wavenumber k_max [rad/m]")
        ax.set_title(f"{c['direction']} {c['wind']:.0f} m/s, −6°")
        ax.grid(alpha=0.3)
    axes[0][0].set_ylabel("clutter σ [K]")
    axes[0][0].legend(fontsize=7, title="o ray-traced, x heights ≤64 / slopes ≤4,\n-- textured (multi-scale)",
                      title_fontsize=7)
    fig.tight_layout()
    fig.savefig(out / "clutter_octaves.png", dpi=110)
    plt.close(fig)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cases", nargs="+", default=["upwind:5", "crosswind:5", "upwind:10", "crosswind:10"],
                    help="DIRECTION:WIND cases (directions: upwind, crosswind)")
    ap.add_argument("--rays", type=int, default=128, help="rays per pixel of each trace")
    ap.add_argument("--seed", type=int, default=23)
    ap.add_argument("--time", type=float, default=7.0)
    ap.add_argument("--shadowing", default="multiscale", choices=["multiscale", "eq5"],
                    help="masking of the waves the tracer does not trace and the texture does not resolve")
    ap.add_argument("--pixel-scaling", action="store_true",
                    help="var(T64 - T4) at 6, 12 and 24 degree fields of view instead (clutter_octaves_pixels.md)")
    ap.add_argument("--out", default="docs")
    args = ap.parse_args()
    torch.set_num_threads(1)
    t0 = time.perf_counter()
    cases = []
    for spec in args.cases:
        d, w = spec.split(":")
        if d not in tvr.DIRECTIONS:
            raise ValueError(f"--cases: direction must be one of {sorted(tvr.DIRECTIONS)}; got {d!r}")
        print(f"{d} {w} m/s ...", flush=True)
        cases.append(pixel_scaling(d, float(w), args) if args.pixel_scaling else run_case(d, float(w), args))
    if args.pixel_scaling:
        write_report(args.out, "clutter_octaves_pixels.md", scaling_report(cases, args, time.perf_counter() - t0))
        return
    out = write_report(args.out, "clutter_octaves.md", report(cases, args, time.perf_counter() - t0))
    figure(cases, out)


if __name__ == "__main__":
    main()

"""How fast textured clutter decorrelates in time, against wind and range, and why.

A static camera 20 m above the sea, 256 rows over 28° from the horizon down (1.9 mrad pixels, ranges
45 m to the horizon), looking upwind, LWIR, midlatitude-summer sky and path, foam off (the waves'
slopes alone). For each wind, ``--seeds`` realizations are rendered as clips (``--seconds`` at
``--fps``); the clutter is each frame minus the expectation image. Per range bin (rows whose slant
range is within ±15 % of 50, 100, 200, 500, 1000, 2000 m) the clutter's correlation against the lag is
pooled over the bin's pixels and the seeds (the clutter's ensemble mean is 0: no time mean is removed), and its 1/e time read off (linear interpolation between
frames).

Beside it, the linear prediction: at a fixed point a Gaussian sea surface's slope along the view has
the temporal autocorrelation

    ρ(τ) = ∫∫ F(k, φ) k² cos²φ w(k f)² cos(ω(k) τ) k dk dφ / (same with τ = 0)

(F the ECKV directional spectrum, ``rs.spectrum.elfouhaily_spectrum``; ω the gravity–capillary
dispersion relation; w the band window of the pixel's footprint f, taken per wavenumber; φ from the
view direction). A radiance linear in the resolved slope inherits it. Its 1/e time is set by the
spread of ω over the waves the footprint resolves: a near pixel resolves short, fast waves and
decorrelates within a fraction of a second; a far pixel resolves only the waves near the spectral
peak (ω_p ≈ 0.88 g/U10), and ρ ≈ cos(ω_p τ) reaches 1/e near τ = 1.2/ω_p.

Schwering (1991, Proc. SPIE 1486, doi:10.1117/12.45749) reported time constants of about 1 s for
marine LWIR image sequences to become uncorrelated.

Writes ``--out``/clutter_time.md and clutter_time.png.

Usage:
    python pipelines/clutter_time.py [--winds 4 8 12 16] [--seeds 3] [--seconds 10] [--fps 20] [--out docs]
"""

from __future__ import annotations

import argparse
import math
import warnings
from pathlib import Path

import torch
from tqdm.auto import tqdm

import roughsea_torch as rs
from roughsea_torch.spectrum import dispersion, elfouhaily_spectrum
from roughsea_torch.wave_bands import band_window

RANGES = (50.0, 100.0, 200.0, 500.0, 1000.0, 2000.0)
H, W, VFOV, PITCH, ALTITUDE = 256, 48, 28.0, -14.0, 20.0


def one_over_e(lags: torch.Tensor, corr: torch.Tensor) -> float:
    """The first lag at which corr falls to 1/e, linearly between samples (nan if it never does)."""
    target = math.exp(-1.0)
    below = (corr < target).nonzero()
    if not below.numel():
        return float("nan")
    i = int(below[0, 0])
    if i == 0:
        return 0.0
    c0, c1 = float(corr[i - 1]), float(corr[i])
    return float(lags[i - 1] + (lags[i] - lags[i - 1]) * (c0 - target) / (c0 - c1))


def rendered(wind: float, seeds: int, seconds: float, fps: float) -> tuple[torch.Tensor, dict, dict, torch.Tensor]:
    """Per range bin: the pooled clutter correlation against the lag, its 1/e time, and each bin's
    footprint; and the lags."""
    hfov = VFOV * W / H
    cams = rs.make_camera(H, W, hfov_deg=hfov, altitude_m=ALTITUDE, pitch_deg=PITCH, batch_size=seeds)
    kw = dict(wind_speed=wind, sea_temperature=290.0, foam=False)
    mean = rs.render(cams, rs.SeaScene(**kw), output="brightness_temperature")[:, 0]
    times = torch.arange(int(round(fps * seconds)), dtype=torch.float64) / fps
    clip = rs.render_clip(cams, rs.SeaScene(**kw, seed=list(range(11, 11 + seeds))), times,
                          output="brightness_temperature", progress=False)[:, :, 0]  # (B, T, H, W)
    geom = rs.view_geometry(cams)
    d = clip - mean[:, None]
    lags = times[: len(times) // 2]
    corr, t_e, foot = {}, {}, {}
    ifov = VFOV / H * math.pi / 180.0
    for r0 in RANGES:
        sel = geom.is_sea & ((geom.range_m - r0).abs() < 0.15 * r0)
        if int(sel[0].sum()) < W:
            continue
        x = d[:, :, sel[0]]  # (B, T, N): the same pixels in every image (same camera)
        c = torch.stack([(x[:, : x.shape[1] - k] * x[:, k:]).mean() for k in range(len(lags))])
        corr[r0] = c / c[0]
        t_e[r0] = one_over_e(lags, corr[r0])
        cos_t = geom.cos_view_zenith[0][sel[0]].mean()
        foot[r0] = float(r0 * ifov / cos_t)
    return lags, corr, t_e, foot


def predicted(wind: float, footprint: float, lags: torch.Tensor) -> torch.Tensor:
    """ρ(τ) of the slope along the view at a fixed point, for waves the footprint resolves."""
    k = torch.logspace(-3.5, 3.0, 1500, dtype=torch.float64)
    phi = torch.linspace(-math.pi, math.pi, 73, dtype=torch.float64)[:-1]
    F = elfouhaily_spectrum(k[:, None], phi[None, :], wind)
    w = band_window(torch.tensor([footprint], dtype=torch.float64), k.tolist())[0]
    density = (F * k[:, None] ** 3 * torch.cos(phi[None, :]) ** 2).sum(1) * w * w  # ∫ dφ, per unit k
    dk = torch.gradient(k)[0]
    om = dispersion(k)
    c = torch.stack([(density * dk * torch.cos(om * t)).sum() for t in lags])
    return c / c[0]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--winds", type=float, nargs="+", default=[4.0, 8.0, 12.0, 16.0])
    ap.add_argument("--seeds", type=int, default=3)
    ap.add_argument("--seconds", type=float, default=10.0)
    ap.add_argument("--fps", type=float, default=20.0)
    ap.add_argument("--out", default="docs")
    args = ap.parse_args()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rows, curves = [], {}
    for wind in tqdm(args.winds, desc="winds"):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # light winds: the resolved slopes' rescaling (reconcile_scale)
            lags, corr, t_e, foot = rendered(wind, args.seeds, args.seconds, args.fps)
        for r0 in corr:
            pred = predicted(wind, foot[r0], lags)
            rows.append((wind, r0, foot[r0], t_e[r0], one_over_e(lags, pred)))
            curves[(wind, r0)] = (lags, corr[r0], pred)
    omega_p = {w: 0.877 * 9.81 / w for w in args.winds}
    lines = ["# Textured clutter in time: decorrelation against wind and range", "",
             f"`python pipelines/clutter_time.py --winds {' '.join(f'{w:g}' for w in args.winds)} --seeds {args.seeds} "
             f"--seconds {args.seconds:g} --fps {args.fps:g}`", "",
             f"A static camera {ALTITUDE:g} m up, {H} rows over {VFOV:g}° from the horizon down (pixels of "
             f"{VFOV / H * math.pi / 180 * 1e3:.1f} mrad), looking upwind; LWIR, midlatitude-summer sky and path, "
             "no foam. The clutter is each frame minus the expectation image; its correlation against the lag is "
             "pooled over the pixels within ±15 % of each range and over the seeds. *Predicted*: the linear "
             "theory of the module docstring (the slope along the view at a fixed point, the waves the footprint "
             "resolves). 1.2/ω_p is where cos(ω_p τ) = 1/e for the spectral peak's ω_p = 0.877 g/U10.", "",
             "| wind [m/s] | range [m] | footprint along the view [m] | rendered 1/e time [s] | predicted [s] | 1.2/ω_p [s] |",
             "|---:|---:|---:|---:|---:|---:|"]
    for wind, r0, f, te, tp in rows:
        lines.append(f"| {wind:g} | {r0:g} | {f:.2f} | {te:.2f} | {tp:.2f} | {1.2 / omega_p[wind]:.2f} |")
    lines += ["", "Schwering (1991) measured about 1 s for marine LWIR image sequences to become uncorrelated.", "",
              "## Where the time scale comes from", "",
              "- A pixel's clutter is the resolved waves' slope at its footprint. Each wave keeps its amplitude and "
              "turns its phase at ω(k) (the dispersion relation), so at a fixed pixel the correlation is the "
              "spectrum-weighted mean of cos(ω τ) over the waves the footprint resolves (the module docstring). The "
              "rendered 1/e times follow that linear theory to about 25 % out to 500 m; beyond, few waves are "
              "resolved per pixel, the realization's own amplitudes dominate and the estimate scatters (and at "
              "4 m/s nothing is resolved past about 700 m).",
              "- The time therefore grows with range: near pixels resolve short, fast waves (0.25–0.3 s at 50 m), far "
              "pixels only the long waves near the spectral peak (1–1.5 s at 500 m, 2–3 s at 1–2 km at 12–16 m/s; "
              "1.2/ω_p is the time of a pixel that resolves the peak and nothing shorter; farther pixels lose even "
              "the peak's short side and are slower still).",
              "- A single number for a whole image pools its pixels weighted by their clutter variance, which is "
              "largest in the nearest rows: from a 20 m mast looking 4° down (128 × 160 over 20°, 8 m/s) it gave "
              "0.36 s. Measured sequences of distant sea (footprints of metres to tens of metres, ranges of hundreds "
              "of metres and more) correspond to the table's 0.5–2 s rows, which bracket Schwering's ~1 s. We could "
              "not reach his ranges and pixel sizes beyond the abstract, so this is a consistency check, not a "
              "validation.",
              "- Left out, shortening a real pixel's correlation a little: the unresolved waves enter the model only "
              "through the mean (Eq. 10), so a pixel carries no fast, unresolved part of the clutter; left out, "
              "lengthening it: nothing identified (swell, absent from the wind-sea spectrum, would add slow "
              "components).", ""]
    report = "\n".join(lines) + "\n"
    (out / "clutter_time.md").write_text(report)
    print(report)

    fig, axes = plt.subplots(1, len(args.winds), figsize=(3.2 * len(args.winds), 3.0), sharey=True, squeeze=False)
    axes = axes[0]
    for ax, wind in zip(axes, args.winds):
        for r0 in RANGES:
            if (wind, r0) not in curves:
                continue
            lags, c, p = curves[(wind, r0)]
            line = ax.plot(lags, c, label=f"{r0:g} m")[0]
            ax.plot(lags, p, ":", color=line.get_color())
        ax.axhline(math.exp(-1), color="0.5", lw=0.8)
        ax.axvline(1.0, color="k", lw=0.8, ls="--")
        ax.set_title(f"{wind:g} m/s (solid: rendered, dotted: linear theory)", fontsize=7)
        ax.set_xlabel("lag [s]")
    axes[0].set_ylabel("clutter correlation")
    axes[0].legend(fontsize=6, title="range", title_fontsize=6)
    fig.tight_layout()
    fig.savefig(out / "clutter_time.png", dpi=120)


if __name__ == "__main__":
    main()

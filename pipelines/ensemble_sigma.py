"""The clutter's σ over an ensemble of realizations, textured against ray-traced, with many rays per pixel
and a confidence interval: the check of ``texture_vs_raytrace.py``'s "σ over the ensemble's seeds" where
the clutter is weaker than the ray tracer's noise at the few rays per pixel an ensemble there affords.

At 5 m/s and 87–88.4°, crosswind, the clutter's σ is about 0.04 K: at 32 rays per pixel one pixel's
Monte Carlo noise is 0.13 K, and the noise-corrected σ rests on removing ten times its variance, which
the per-pixel variance over the rays estimates only to a few per cent. Here each realization is traced
with 256 rays per pixel (noise 0.046 K) and the ratio σ textured / σ ray-traced (√ of the bins' clutter
variances averaged over the seeds, the ray tracer's noise removed, as in ``texture_vs_raytrace.py``) is
given with a 95 % bootstrap interval over the seeds.

Same cameras, scenes and ray tracer as ``texture_vs_raytrace.py`` (48×64 px over 12°, LWIR, LOWTRAN
midlatitude-summer sky, no foam, no path, flat Earth, t = 3 s), the textured side
``TableSize(texture_hit="first")``; ``--shadowing`` on both sides (the textured scene's and the ray
tracer's untraced waves').

Usage:
    python pipelines/ensemble_sigma.py [--cases crosswind:5:-6] [--seeds 100-115] [--rays 256]
        [--shadowing multiscale] [--workers 2] [--cache ens.pkl] [--out docs]

About 105 s per realization and case on one core; ``--workers 2`` traces two realizations at a time
(one torch thread each). ``--cache``: per-realization images kept in (and read back from) this pickle.
"""

from __future__ import annotations

import argparse
import datetime as dt
import math
import pickle
import sys
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np
import torch
from tqdm import tqdm

sys.path.insert(0, str(Path(__file__).resolve().parent))
import texture_vs_raytrace as tv  # noqa: E402  (also puts this checkout's package first on the path)
from _report import write_report  # noqa: E402

import roughsea_torch as rs  # noqa: E402
from roughsea_torch import raytrace as rt  # noqa: E402

BINS = (0, 8, 16)  # the first rows of the 8-row bins reported (view zenith 84–88.4° at pitch −6°)


def trace_one(key: tuple[str, float, float, int], rays: int, shadowing: str) -> dict:
    """Textured and ray-traced brightness temperature [K] (H, W) of one realization, and the ray tracer's
    per-pixel noise variance [K²]."""
    torch.set_num_threads(1)
    direction_name, wind, pitch, seed = key
    tv.TABLE = rs.TableSize(texture_hit="first")
    tv.SHADOWING = True if shadowing == "eq5" else shadowing
    mast, direction = tv.DIRECTIONS[direction_name]
    cams = rs.make_camera(tv.H, tv.W, hfov_deg=tv.HFOV, altitude_m=mast, pitch_deg=pitch)
    tex = tv.render(cams, tv.scene(wind, direction, seed))[0, 0].numpy()
    out = rt.raytraced_image(cams, wind, seed=seed, time_s=tv.TIME_S, wind_direction=direction,
                             sea_temperature=tv.T_SEA, rays_per_pixel=rays, shadowing=tv.SHADOWING)
    return dict(tex=tex, ray=out["brightness_temperature"][0, 0].double().numpy(),
                noise=out["brightness_temperature_noise_var"][0, 0].double().numpy())


def bin_ratio(images: list[dict], r0: int, boot: int = 4000) -> dict:
    """σ of both over the seeds in rows r0 … r0 + 7, their ratio and its 95 % bootstrap interval over the seeds."""
    sl = slice(r0, r0 + tv.BIN)
    vt = np.array([tv.signal_variance(im["tex"][sl])[0] for im in images])
    vr = np.array([tv.signal_variance(im["ray"][sl], im["noise"][sl])[0] for im in images])
    rng = np.random.default_rng(0)
    idx = rng.integers(0, len(images), (boot, len(images)))
    ratios = np.sqrt(vt[idx].mean(1) / np.maximum(vr[idx].mean(1), 1e-30))
    lo, hi = np.percentile(ratios, [2.5, 97.5])
    return dict(sigma_tex=math.sqrt(vt.mean()), sigma_ray=math.sqrt(max(vr.mean(), 0.0)),
                ratio=math.sqrt(vt.mean() / vr.mean()) if vr.mean() > 0 else math.nan, lo=float(lo), hi=float(hi),
                noise=math.sqrt(np.mean([im["noise"][sl].mean() for im in images])))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--cases", nargs="+", default=["crosswind:5:-6"], metavar="DIR:WIND:PITCH")
    ap.add_argument("--seeds", default="100-115", help="first-last (inclusive), as texture_vs_raytrace.py's ensemble")
    ap.add_argument("--rays", type=int, default=256, help="rays per pixel")
    ap.add_argument("--shadowing", choices=("eq5", "correlated", "multiscale"), default="multiscale")
    ap.add_argument("--workers", type=int, default=1)
    ap.add_argument("--cache", default=None, help="pickle of per-realization images, read and extended")
    ap.add_argument("--out", default=str(tv.ROOT / "docs"))
    args = ap.parse_args()
    first, last = (int(v) for v in args.seeds.split("-"))
    seeds = list(range(first, last + 1))
    cases = []
    for pat in args.cases:
        d, w, p = pat.split(":")
        if d not in tv.DIRECTIONS:
            raise ValueError(f"--cases: direction must be one of {sorted(tv.DIRECTIONS)}, got {d!r}")
        cases.append((d, float(w), float(p)))
    cache: dict = {}
    if args.cache and Path(args.cache).exists():
        with open(args.cache, "rb") as fh:
            cache = pickle.load(fh)
    keys = [(d, w, p, s) for d, w, p in cases for s in seeds]
    todo = [k for k in keys if (k, args.rays, args.shadowing) not in cache]
    with tqdm(total=len(todo), unit="realization", desc="traced") as bar, \
            ProcessPoolExecutor(max_workers=max(1, args.workers)) as pool:
        futures = {k: pool.submit(trace_one, k, args.rays, args.shadowing) for k in todo}
        for k, fut in futures.items():
            cache[(k, args.rays, args.shadowing)] = fut.result()
            bar.update(1)
            if args.cache:
                with open(args.cache, "wb") as fh:
                    pickle.dump(cache, fh)
    rows = []
    for d, w, p in cases:
        images = [cache[((d, w, p, s), args.rays, args.shadowing)] for s in seeds]
        cams = rs.make_camera(tv.H, tv.W, hfov_deg=tv.HFOV, altitude_m=tv.DIRECTIONS[d][0], pitch_deg=p)
        vz = np.degrees(rs.view_geometry(cams, earth_radius_m=tv.INF).view_zenith[0].double().numpy())
        for r0 in BINS:
            b = bin_ratio(images, r0)
            inside = 0.85 <= b["lo"] and b["hi"] <= 1.2
            rows.append(f"| {d} {w:g} m/s, {p:g}° | {r0}–{r0 + tv.BIN - 1} | {vz[r0:r0 + tv.BIN].min():.1f}–"
                        f"{vz[r0:r0 + tv.BIN].max():.1f} | {b['sigma_tex']:.4f} | {b['sigma_ray']:.4f} | {b['noise']:.3f} | "
                        f"{b['ratio']:.2f} | {b['lo']:.2f}–{b['hi']:.2f} | {'yes' if inside else 'no'} |")
    command = ("python pipelines/ensemble_sigma.py --cases " + " ".join(args.cases) + f" --seeds {args.seeds} "
               f"--rays {args.rays} --shadowing {args.shadowing}")
    date = dt.datetime.now().astimezone().strftime("%Y-%m-%d %H:%M %Z")
    report = "\n".join([
        "# Clutter σ over an ensemble, textured against ray-traced, at many rays per pixel", "",
        f"Made by `{command}` on {date} (torch {torch.__version__}).", "",
        f"{len(seeds)} realizations (seeds {first}–{last}, t = 3 s), {args.rays} rays per pixel, shadowing "
        f"`{args.shadowing}` on both sides, first hit on the textured side; σ: √ of the bin's clutter variance "
        "(about the row means) averaged over the seeds, the ray tracer's Monte Carlo variance removed; noise: one "
        "ray-traced pixel's rms Monte Carlo error; interval: 95 % bootstrap over the seeds; inside: the whole "
        "interval within the issue's 0.85–1.2.", "",
        "| case | rows | view zenith [°] | σ tex [K] | σ ray [K] | noise [K] | ratio | 95 % interval | inside |",
        "|---|---|---|---:|---:|---:|---:|---|---|", *rows, ""])
    write_report(args.out, "texture_vs_raytrace_ensemble_sigma.md", report)


if __name__ == "__main__":
    main()

"""The first hit near the horizon: its seed average against the expectation image, and its whitecaps.

The scene a user of the README's near-grazing recipe gets: 256×320 px over 12° from a 15 m mast, 3° down,
LWIR, midlatitude-summer sky and path, ``SeaScene(..., shadowing="multiscale")`` with
``TableSize(texture_hit="first")``. For 5, 10 and 15 m/s it measures:

- the mean over 12 seeds of the first hit minus the expectation image, in bands of depression below the
  local horizontal, without whitecaps, with whitecaps in the mean plane (``texture_hit_foam_tilt=False``)
  and on their facets (the default);
- on one seed, what the whitecaps do to the image (with minus without): the darkest pixel, and the share of
  sea pixels they darken by more than 0.5 K;
- the band below the horizon where the first hit has no clutter (every seed's pixel equal to the
  expectation image within 1e-4 K), in degrees.

Usage:
    python pipelines/first_hit_horizon.py [--out docs] [--threads 2] [--seeds 12]
"""

from __future__ import annotations

import argparse
import datetime as dt
import math
import sys
import time
import warnings
from pathlib import Path

import torch

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(Path(__file__).resolve().parent))
import roughsea_torch as rs  # noqa: E402
from _report import write_report  # noqa: E402

BANDS = ((0.2, 0.7), (0.7, 1.5), (1.5, 3.0))  # [deg] of depression below the local horizontal
WINDS = (5.0, 10.0, 15.0)


def render(cams, wind, seeds, foam: bool, tilt: bool = True) -> torch.Tensor:
    kw = dict(wind_speed=wind, sea_temperature=290.0, shadowing="multiscale", **({} if foam else {"foam": False}))
    table = rs.TableSize(texture_hit="first", texture_hit_foam_tilt=tilt) if seeds is not None else rs.TableSize()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return rs.render(cams, rs.SeaScene(**kw, seed=seeds), output="brightness_temperature", table=table)[:, 0]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", default=str(ROOT / "docs"))
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--seeds", type=int, default=12)
    args = ap.parse_args()
    torch.set_num_threads(max(1, args.threads))
    t0 = time.perf_counter()
    n = args.seeds
    cams = rs.make_camera(256, 320, hfov_deg=12.0, altitude_m=15.0, pitch_deg=-3.0, batch_size=n)
    one = rs.make_camera(256, 320, hfov_deg=12.0, altitude_m=15.0, pitch_deg=-3.0)
    geo = rs.view_geometry(one)
    sea = geo.is_sea[0]
    dep = 90.0 - torch.rad2deg(geo.view_zenith[0][:, 160].double())
    seeds = list(range(100, 100 + n))
    mean_rows, foam_rows, band_rows = [], [], []
    for wind in WINDS:
        cells = []
        for label, foam, tilt in (("no whitecaps", False, True), ("whitecaps in the mean plane", True, False),
                                  ("whitecaps on their facets (default)", True, True)):
            tex = render(cams, wind, seeds, foam, tilt)
            flat = render(one, wind, None, foam)[0]
            d = (tex.double().mean(0) - flat.double()).mean(1)  # per row [K]
            cells.append((label, [float(d[(dep > lo) & (dep < hi)].mean()) for lo, hi in BANDS]))
            if foam and tilt:  # the clutter-free band: rows where every seed equals the expectation image
                same = ((tex.double() - flat.double()).abs() <= 1e-4).all(0)
                rows = [r for r in range(sea.shape[0]) if bool(sea[r].any()) and bool(same[r][sea[r]].all())]
                deepest = max((float(dep[r]) for r in rows), default=float("nan"))
                horizon = float(dep[[r for r in range(sea.shape[0]) if bool(sea[r].any())][0]])
                band_rows.append(f"| {wind:g} m/s | {deepest - horizon:.2f}° (to {deepest:.2f}° below the horizontal) |"
                                 if rows else f"| {wind:g} m/s | none: clutter up to the horizon's row |")
        for label, vals in cells:
            mean_rows.append(f"| {wind:g} m/s | {label} | " + " | ".join(f"{v:+.3f}" for v in vals) + " |")
        bare = render(one, wind, [1], False)[0]
        for label, tilt in (("in the mean plane", False), ("on their facets (default)", True)):
            d = (render(one, wind, [1], True, tilt)[0] - bare)[sea]
            foam_rows.append(f"| {wind:g} m/s | {label} | {float(d.min()):+.2f} | {100 * float((d < -0.5).double().mean()):.1f} % |")
    report = "\n".join([
        "# The first hit near the horizon: seed average and whitecaps",
        "",
        f"Made by `python pipelines/first_hit_horizon.py --threads {args.threads} --seeds {n}` on "
        f"{dt.datetime.now(dt.timezone.utc):%Y-%m-%d %H:%M} UTC (torch {torch.__version__}, {args.threads} thread(s), "
        f"{time.perf_counter() - t0:.0f} s). 256×320 px over 12° from 15 m, 3° down, LWIR, midlatitude summer with its "
        "path, `shadowing=\"multiscale\"`, `TableSize(texture_hit=\"first\")`.",
        "",
        f"Mean over {n} seeds of the first hit minus the expectation image [K], by depression below the local horizontal:",
        "",
        "| wind | whitecaps | " + " | ".join(f"{lo:g}–{hi:g}°" for lo, hi in BANDS) + " |",
        "|---|---|" + "---:|" * len(BANDS),
        *mean_rows,
        "",
        "What the whitecaps do to one image (seed 1; with minus without):",
        "",
        "| wind | whitecaps | darkest pixel [K] | sea pixels darkened by > 0.5 K |",
        "|---|---|---:|---:|",
        *foam_rows,
        "",
        "The band below the horizon without clutter (every seed's pixel equal to the expectation image within 1e-4 K):",
        "",
        "| wind | below the horizon |",
        "|---|---|",
        *band_rows,
        "",
    ])
    write_report(args.out, "first_hit_horizon.md", report)


if __name__ == "__main__":
    main()

"""The glitter's cost: one 512 × 640 MWIR daytime textured render (10 m mast looking 6° down towards
the sun 15° above the horizon, 8 m/s, seed 4) with ``TableSize(glitter=True)`` and without,
alternately, median of ``--runs`` runs each (one thread). Prints a markdown table.

Usage:
    PYTHONPATH=. python pipelines/bench_glitter.py [--runs 3]
"""

from __future__ import annotations

import argparse
import math
import statistics
import time

import torch

import roughsea_torch as rs


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--runs", type=int, default=3)
    args = ap.parse_args()
    torch.set_num_threads(1)
    cam = rs.make_camera(512, 640, hfov_deg=30.0, altitude_m=10.0, pitch_deg=-6.0)
    scene = rs.SeaScene(wind_speed=8.0, sea_temperature=290.0, band=rs.MWIR, seed=4, sun=rs.Sun(math.radians(75.0), 0.0, 12.0))
    tables = {"glitter off": rs.TableSize(), "glitter on": rs.TableSize(glitter=True)}
    for t in tables.values():  # warm-up: wave field, skies
        rs.render(cam, scene, table=t)
    times = {k: [] for k in tables}
    for _ in range(args.runs):
        for k, t in tables.items():
            t0 = time.perf_counter()
            rs.render(cam, scene, table=t)
            times[k].append(time.perf_counter() - t0)
    print("| 512 × 640 MWIR daytime, textured | median [s] | runs [s] |\n|---|---|---|")
    for k, v in times.items():
        print(f"| {k} | {statistics.median(v):.2f} | {', '.join(f'{x:.2f}' for x in v)} |")


if __name__ == "__main__":
    main()

"""What the area-weighted horizon costs: a render with ``horizon="area"`` (the default) against
``horizon="centre"`` (every pixel by its centre ray), timed alternately in the same run, one torch
thread, median of ``--repeats`` runs.

Scenes: one image and a batch of 4 images of 512×640, float32, the README's default scene
(LOWTRAN7 midlatitude-summer sky, path, radiance) and kelvin output, camera 20 m up looking at the
horizon (pitch −1°) with roll 0° and 10°; and a textured scene (``seed=``). Prints a Markdown table.

Usage:
    python pipelines/bench_horizon.py [--repeats 5]
"""

from __future__ import annotations

import argparse
import statistics
import time

import torch

import roughsea_torch as rs


def timed(fn, repeats: int) -> list[float]:
    ts = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        ts.append(time.perf_counter() - t0)
    return ts


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--repeats", type=int, default=5)
    args = ap.parse_args()
    torch.set_num_threads(1)
    cases = [
        ("default, 1 image, roll 0°", 1, 0.0, dict(), "radiance"),
        ("default, 1 image, roll 10°", 1, 10.0, dict(), "radiance"),
        ("default kelvin, 1 image, roll 10°", 1, 10.0, dict(), "brightness_temperature"),
        ("default, 4 images, roll 3°", 4, 3.0, dict(), "radiance"),
        ("textured (seed=1), 1 image, roll 3°", 1, 3.0, dict(seed=1), "radiance"),
    ]
    print("| scene | horizon='centre' [ms] | horizon='area' [ms] | ratio | pixels blended |")
    print("|---|---|---|---|---|")
    for name, B, roll, kw, output in cases:
        cams = rs.make_camera(512, 640, hfov_deg=20.0, altitude_m=20.0, pitch_deg=-1.0, roll_deg=roll, batch_size=B)
        scene = rs.SeaScene(wind_speed=8.0, sea_temperature=290.0, **kw)
        fns = {m: (lambda m=m: rs.render(cams, scene, output=output, horizon=m)) for m in ("centre", "area")}
        for f in fns.values():
            f()  # warm-up
        ts = {"centre": [], "area": []}
        for _ in range(args.repeats):  # alternate, so that a load on the machine hits both
            for m, f in fns.items():
                ts[m] += timed(f, 1)
        c, a = (1e3 * statistics.median(ts[m]) for m in ("centre", "area"))
        n = int((fns["area"]() != fns["centre"]()).sum())
        print(f"| {name} | {c:.1f} | {a:.1f} | {a / c:.3f} | {n} |")


if __name__ == "__main__":
    main()

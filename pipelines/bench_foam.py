"""Time of a 512×640 textured storm render with foam (15 m/s, LWIR, a 20 m mast looking 3° down), one
thread, median of 5 (after one warm-up): run it with PYTHONPATH set to a checkout before and after a
change to the whitecaps (docs/foam_table.md quotes both).

    PYTHONPATH=. python pipelines/bench_foam.py
"""

from __future__ import annotations

import statistics
import time

import torch

import roughsea_torch as rs


def main() -> None:
    torch.set_num_threads(1)
    cams = rs.make_camera(512, 640, hfov_deg=20.0, altitude_m=20.0, pitch_deg=-3.0, dtype=torch.float32)
    runs = {}
    for name, foam in (("foam", "auto"), ("no foam", False)):
        scene = rs.SeaScene(wind_speed=15.0, sea_temperature=290.0, seed=7, time_s=1.0, foam=foam)
        rs.render(cams, scene)
        times = []
        for _ in range(5):
            t0 = time.perf_counter()
            rs.render(cams, scene)
            times.append(time.perf_counter() - t0)
        runs[name] = statistics.median(times)
    print("| render (512×640, 15 m/s, textured) | median of 5 [s] |")
    print("|---|---|")
    for name, t in runs.items():
        print(f"| {name} | {t:.2f} |")


if __name__ == "__main__":
    main()

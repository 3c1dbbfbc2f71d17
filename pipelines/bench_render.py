"""Speed and memory of the renderer against torch's own floor, ``grid_sample``, in the same run.

The renderer issue's benchmark: 16 images 512×640, float32, each with its own wind, wind
direction, sea temperature and camera pose, anisotropic (and isotropic) Cox–Munk slopes. Times the
whole ``render`` (geometry + model + images) against ``torch.nn.functional.grid_sample`` producing
an output of the same size (the floor of any per-pixel lookup), and against ``method="direct"``
(timed on a subsampled batch and extrapolated per sea pixel). Then what leaving things out buys
(sky work, azimuth dimension, table span, gradient bookkeeping), the table's error against direct
evaluation, and peak memory of a batch of 64 (separate processes; resident memory sampled every
millisecond during the render, over the resident memory just before it).

Median of ``--repeats`` runs. Writes a Markdown report to stdout and ``--out``/bench_render.md,
and bench_render.png.

Usage:
    python pipelines/bench_render.py [--repeats 5] [--out docs]
"""

from __future__ import annotations

import argparse
import datetime as dt
import json
import platform
import statistics
import subprocess
import sys
import time
from pathlib import Path

import torch
import torch.nn.functional as F

import roughsea_torch as rs

H, W, B = 512, 640, 16


def sky(c):
    return 11.0 + 19.0 * (1.0 - c) ** 8


def batch(B: int, seed: int = 0, pitch=(-8.0, -1.0)):
    g = torch.Generator().manual_seed(seed)

    def u(lo, hi):
        return lo + (hi - lo) * torch.rand(B, generator=g)

    cam = dict(altitude_m=torch.exp(u(2.3, 6.2)), pitch_deg=u(*pitch), yaw_deg=u(-180, 180), roll_deg=u(-3, 3))
    scene = dict(wind_speed=u(1, 20), wind_direction=u(-3.14, 3.14), sea_temperature=u(285, 300))
    return cam, scene


def med(fn, repeats: int) -> float:
    fn()  # warm-up
    ts = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        ts.append(time.perf_counter() - t0)
    return statistics.median(ts)


def _rss_mb() -> float:
    with open("/proc/self/status") as f:
        for line in f:
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) / 1024
    return float("nan")


def memory_child(b: int, aniso: bool) -> None:
    """Peak resident memory of one render of b images over the process's resident memory just
    before it (after a warm-up render), sampled every millisecond from /proc/self/status."""
    import threading

    cam, sc = batch(b)
    small = rs.make_camera(8, 8, **{k: v[:1] for k, v in cam.items()})
    rs.render(small, rs.SeaScene(**{k: v[:1] for k, v in sc.items()}, anisotropic=aniso, sky=sky))
    cams = rs.make_camera(H, W, **cam)
    scene = rs.SeaScene(**sc, anisotropic=aniso, sky=sky)
    base = _rss_mb()
    peak = [base]
    done = threading.Event()

    def poll() -> None:
        while not done.is_set():
            peak[0] = max(peak[0], _rss_mb())
            time.sleep(0.001)

    t = threading.Thread(target=poll)
    t.start()
    img = rs.render(cams, scene)
    done.set()
    t.join()
    peak[0] = max(peak[0], _rss_mb())
    print(json.dumps({"peak_mb": peak[0] - base, "output_mb": img.numel() * img.element_size() / 2**20}))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--out", type=Path, default=Path("docs"))
    ap.add_argument("--memory-child", nargs=2, help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.memory_child:
        memory_child(int(args.memory_child[0]), args.memory_child[1] == "aniso")
        return

    cam, sc = batch(B)
    cams = rs.make_camera(H, W, **cam)
    src = torch.rand(B, 1, H, W)
    grid = torch.rand(B, H, W, 2) * 2 - 1
    floor = med(lambda: F.grid_sample(src, grid, mode="bilinear", align_corners=True), args.repeats)
    lines = []
    res = {}
    for aniso in (True, False):
        scene = rs.SeaScene(**sc, anisotropic=aniso, sky=sky)
        t = med(lambda: rs.render(cams, scene), args.repeats)
        res[aniso] = t
        lines.append((f"render, {'anisotropic' if aniso else 'isotropic'} (geometry + model + images)", t, t / floor))
    # components, anisotropic
    scene = rs.SeaScene(**sc, anisotropic=True, sky=sky)
    tg = med(lambda: rs.view_geometry(cams), args.repeats)
    lines.append(("  of which view_geometry", tg, tg / floor))
    # direct method, extrapolated per sea pixel from a subsampled batch (same poses, 32×40 pixels)
    small = rs.make_camera(32, 40, **cam)
    g_small = rs.view_geometry(small)
    td_small = med(lambda: rs.render(small, scene, method="direct", geometry=g_small), 1)
    n_small = int(g_small.is_sea.sum())
    n_full = int(rs.view_geometry(cams).is_sea.sum())
    td = td_small / n_small * n_full
    lines.append(("method='direct' (extrapolated from 32×40)", td, td / floor))
    # leaving things out
    all_sea_cam, _ = batch(B, seed=1, pitch=(-60.0, -40.0))
    cams_sea = rs.make_camera(H, W, **all_sea_cam)
    assert bool(rs.view_geometry(cams_sea).is_sea.all())
    cam_sky = dict(all_sea_cam, pitch_deg=all_sea_cam["pitch_deg"] * 0 - 2.0)
    cams_sky = rs.make_camera(H, W, **cam_sky)
    t_sea = med(lambda: rs.render(cams_sea, scene), args.repeats)
    t_sky = med(lambda: rs.render(cams_sky, scene), args.repeats)
    w = sc["wind_speed"].clone().requires_grad_(True)
    scene_grad = rs.SeaScene(**dict(sc, wind_speed=w), anisotropic=True, sky=sky)
    t_grad = med(lambda: rs.render(cams, scene_grad), args.repeats)
    full = rs.TableSize(span="full")
    t_full = med(lambda: rs.render(cams, scene, table=full), args.repeats)
    # accuracy against direct on the subsampled batch: restricted vs full span, same nodes
    direct = rs.render(small, scene, method="direct", geometry=g_small)
    sea = g_small.is_sea[:, None]
    err = lambda img: float(((img - direct).abs() / direct.abs())[sea].max())  # noqa: E731
    e_pix = err(rs.render(small, scene, geometry=g_small))
    e_full = err(rs.render(small, scene, geometry=g_small, table=full))
    # memory, batch 64, separate processes
    mem = {}
    for kind in ("aniso", "iso"):
        out = subprocess.run([sys.executable, __file__, "--memory-child", "64", kind], capture_output=True, text=True, check=True)
        mem[kind] = json.loads(out.stdout.strip().splitlines()[-1])

    head = (f"Renderer benchmark: {B} images {H}×{W}, float32, per-image wind/direction/sea temperature/pose; "
            f"{platform.processor() or platform.machine()}, {torch.get_num_threads()} threads, torch {torch.__version__}, "
            f"{dt.date.today().isoformat()}. Median of {args.repeats}.\nCommand: `python pipelines/bench_render.py --repeats {args.repeats}`\n")
    t1 = ["| what | time | × grid_sample floor |", "|---|---:|---:|", f"| grid_sample, same output size (floor) | {floor * 1e3:.0f} ms | 1.0 |"]
    t1 += [f"| {name} | {t * 1e3:,.0f} ms | {r:,.1f} |" for name, t, r in lines]
    t2 = ["| leaving out | with | without | saving |", "|---|---:|---:|---:|",
          f"| sky work (horizon in view vs all-sea views) | {t_sky * 1e3:.0f} ms | {t_sea * 1e3:.0f} ms | {t_sky / t_sea:.2f}× |",
          f"| azimuth dimension (anisotropic vs isotropic) | {res[True] * 1e3:.0f} ms | {res[False] * 1e3:.0f} ms | {res[True] / res[False]:.2f}× |",
          f"| gradient bookkeeping (wind requires grad vs not) | {t_grad * 1e3:.0f} ms | {res[True] * 1e3:.0f} ms | {t_grad / res[True]:.2f}× |",
          f"| table over all angles vs over the pixels' span (25×9 nodes) | {t_full * 1e3:.0f} ms, error {e_full:.1e} | {res[True] * 1e3:.0f} ms, error {e_pix:.1e} | {e_full / max(e_pix, 1e-30):.0f}× error |"]
    t3 = ["| batch 64, 512×640 | peak memory over baseline | output size | ratio |", "|---|---:|---:|---:|"]
    t3 += [f"| {k} | {v['peak_mb']:.0f} MB | {v['output_mb']:.0f} MB | {v['peak_mb'] / v['output_mb']:.1f}× |" for k, v in mem.items()]
    speed = f"Table render vs direct: {td / res[True]:,.0f}× faster (anisotropic)."
    text = head + "\n" + "\n".join(t1) + "\n\n" + speed + "\n\n" + "\n".join(t2) + "\n\n" + "\n".join(t3) + "\n"
    print(text)
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "bench_render.md").write_text(text)
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(8, 3.5))
    names = ["grid_sample floor"] + [n.split(" (")[0].strip() for n, *_ in lines]
    ax.barh(names, [floor] + [t for _, t, _ in lines])
    ax.set_xscale("log")
    ax.set_xlabel("seconds (16 × 512×640, float32)")
    ax.invert_yaxis()
    fig.tight_layout()
    fig.savefig(args.out / "bench_render.png", dpi=110)


if __name__ == "__main__":
    main()

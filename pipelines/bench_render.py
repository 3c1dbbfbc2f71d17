"""Speed and memory of the renderer against torch's own floor, ``grid_sample``, in the same run.

The scenes users render: 16 images 512×640, float32, each with its own wind speed, wind direction,
sea temperature and camera pose (altitude 10–500 m, pitch −8…−1°, yaw, roll):

- **default**: the README's default scene, LOWTRAN7 midlatitude-summer sky, path on, radiance;
- **default, kelvin**: the same with ``output="brightness_temperature"``;
- **callable sky**: an analytic sky (a callable of cos zenith), anisotropic Cox–Munk, no path.

Each is timed against the floor: one bilinear ``torch.nn.functional.grid_sample`` of a
(16, 1, 256, 64) table to a (16, 512, 640) grid (the cost of any per-pixel lookup), timed in the
same run, with 1 and 2 torch threads, on an idle machine and with a competing process (a busy loop
in another process, as in a training job whose data loader shares the cores). Then, on 2 threads
and no load: ``method="direct"`` (timed on a subsampled batch, extrapolated per sea pixel), what
leaving things out buys, the table's error against per-pixel evaluation, and peak memory of a batch
of 64 (separate processes; resident memory sampled every millisecond over the resident memory just
before the render).

Median of ``--repeats`` runs. Writes a Markdown report to stdout and ``--out``/bench_render.md, and
bench_render.png.

Usage:
    python pipelines/bench_render.py [--repeats 7] [--out docs]
"""

from __future__ import annotations

import argparse
import datetime as dt
import json
import os
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


def analytic_sky(c):
    return 11.0 + 19.0 * (1.0 - c) ** 8


def batch(B: int, seed: int = 0, pitch=(-8.0, -1.0)):
    g = torch.Generator().manual_seed(seed)

    def u(lo, hi):
        return lo + (hi - lo) * torch.rand(B, generator=g)

    cam = dict(altitude_m=torch.exp(u(2.3, 6.2)), pitch_deg=u(*pitch), yaw_deg=u(-180, 180), roll_deg=u(-3, 3))
    scene = dict(wind_speed=u(1, 20), wind_direction=u(-3.14, 3.14), sea_temperature=u(285, 300))
    return cam, scene


SCENES = {
    "default (LOWTRAN7 sky, path, radiance)": (dict(), "radiance"),
    "default, output in kelvin": (dict(), "brightness_temperature"),
    "callable sky, anisotropic Cox–Munk": (dict(sky=analytic_sky), "radiance"),
}


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


def memory_child(b: int, kind: str) -> None:
    """Peak resident memory of one render of b images over the process's resident memory just
    before it (after a warm-up render), sampled every millisecond from /proc/self/status."""
    cam, sc = batch(b)
    extra = dict(sky=analytic_sky) if kind == "callable" else {}
    small = rs.make_camera(8, 8, **{k: v[:1] for k, v in cam.items()})
    rs.render(small, rs.SeaScene(**{k: v[:1] for k, v in sc.items()}, **extra))
    cams = rs.make_camera(H, W, **cam)
    scene = rs.SeaScene(**sc, **extra)
    img, peak = peak_memory(lambda: rs.render(cams, scene))
    print(json.dumps({"peak_mb": peak, "output_mb": img.numel() * img.element_size() / 2**20}))


def peak_memory(fn):
    """(fn(), peak resident memory [MB] during it over the resident memory just before it), sampled
    every millisecond from /proc/self/status."""
    import threading

    base = _rss_mb()
    peak = [base]
    done = threading.Event()

    def poll() -> None:
        while not done.is_set():
            peak[0] = max(peak[0], _rss_mb())
            time.sleep(0.001)

    t = threading.Thread(target=poll)
    t.start()
    out = fn()
    done.set()
    t.join()
    return out, max(peak[0], _rss_mb()) - base


class Competitor:
    """A busy loop in another process for the duration of a ``with`` block."""

    def __enter__(self):
        self.p = subprocess.Popen([sys.executable, "-c", "while True: pass"])
        time.sleep(0.5)
        return self

    def __exit__(self, *exc):
        self.p.kill()
        self.p.wait()


def speed_table(repeats: int, cams, sc) -> list[dict]:
    src = torch.rand(B, 1, 256, 64)
    grid = torch.rand(B, H, W, 2) * 2 - 1
    scenes = {name: (rs.SeaScene(**sc, **extra), out) for name, (extra, out) in SCENES.items()}
    rows = []
    for load in (False, True):
        ctx = Competitor() if load else None
        if ctx:
            ctx.__enter__()
        try:
            for threads in (1, 2):
                torch.set_num_threads(threads)
                floor = med(lambda: F.grid_sample(src, grid, mode="bilinear", align_corners=True), repeats)
                for name, (scene, out) in scenes.items():
                    t = med(lambda: rs.render(cams, scene, output=out), repeats)
                    rows.append(dict(scene=name, threads=threads, load=load, time=t, floor=floor))
        finally:
            if ctx:
                ctx.__exit__(None, None, None)
    torch.set_num_threads(2)
    return rows


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--repeats", type=int, default=7)
    ap.add_argument("--out", type=Path, default=Path("docs"))
    ap.add_argument("--memory-child", nargs=2, help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.memory_child:
        memory_child(int(args.memory_child[0]), args.memory_child[1])
        return

    cam, sc = batch(B)
    cams = rs.make_camera(H, W, **cam)
    rows = speed_table(args.repeats, cams, sc)

    # on 2 threads, no load: direct evaluation, leaving things out, accuracy, memory
    src = torch.rand(B, 1, 256, 64)
    grid = torch.rand(B, H, W, 2) * 2 - 1
    floor = med(lambda: F.grid_sample(src, grid, mode="bilinear", align_corners=True), args.repeats)
    scene = rs.SeaScene(**sc)
    t_def = med(lambda: rs.render(cams, scene), args.repeats)
    small = rs.make_camera(32, 40, **cam)
    g_small = rs.view_geometry(small)
    td_small = med(lambda: rs.render(small, scene, method="direct", geometry=g_small), 1)
    n_small = int(g_small.is_sea.sum())
    n_full = int(rs.view_geometry(cams).is_sea.sum())
    td = td_small / n_small * n_full
    all_sea_cam, _ = batch(B, seed=1, pitch=(-60.0, -40.0))
    cams_sea = rs.make_camera(H, W, **all_sea_cam)
    assert bool(rs.view_geometry(cams_sea).is_sea.all())
    cams_sky = rs.make_camera(H, W, **dict(all_sea_cam, pitch_deg=all_sea_cam["pitch_deg"] * 0 - 2.0))
    t_sea = med(lambda: rs.render(cams_sea, scene), args.repeats)
    t_sky = med(lambda: rs.render(cams_sky, scene), args.repeats)
    t_iso = med(lambda: rs.render(cams, rs.SeaScene(**sc, anisotropic=False)), args.repeats)
    t_nopath = med(lambda: rs.render(cams, rs.SeaScene(**sc, path=False)), args.repeats)
    w = sc["wind_speed"].clone().requires_grad_(True)
    scene_grad = rs.SeaScene(**dict(sc, wind_speed=w))
    t_grad = med(lambda: rs.render(cams, scene_grad), args.repeats)
    full = rs.TableSize(span="full")
    t_full = med(lambda: rs.render(cams, scene, table=full), args.repeats)
    direct = rs.render(small, scene, method="direct", geometry=g_small)
    sea = g_small.is_sea[:, None]
    err = lambda img: float(((img - direct).abs() / direct.abs())[sea].max())  # noqa: E731
    err_sky = lambda img: float(((img - direct).abs() / direct.abs())[~sea].max())  # noqa: E731
    img_pix = rs.render(small, scene)
    e_pix, e_sky = err(img_pix), err_sky(img_pix)
    e_full = err(rs.render(small, scene, table=full))
    mem = {}
    for kind in ("default", "callable"):
        out = subprocess.run([sys.executable, __file__, "--memory-child", "64", kind], capture_output=True, text=True,
                             check=True)
        mem[kind] = json.loads(out.stdout.strip().splitlines()[-1])

    head = (f"Renderer benchmark: {B} images {H}×{W}, float32, per-image wind/direction/sea temperature/pose; "
            f"{platform.processor() or platform.machine()}, {os.cpu_count()} cores, torch {torch.__version__}, "
            f"{dt.date.today().isoformat()}. Median of {args.repeats}. Floor: one bilinear grid_sample of a "
            f"(16, 1, 256, 64) table to (16, {H}, {W}), timed in the same run and setting.\n"
            f"Command: `python pipelines/bench_render.py --repeats {args.repeats}`\n")
    t1 = ["| scene | threads | competing process | floor | render | × floor |", "|---|---:|---|---:|---:|---:|"]
    for r in rows:
        t1.append(f"| {r['scene']} | {r['threads']} | {'yes' if r['load'] else 'no'} | {r['floor'] * 1e3:.0f} ms | "
                  f"{r['time'] * 1e3:.0f} ms | {r['time'] / r['floor']:.1f} |")
    t1b = ["| scene | competing process | 2 threads / 1 thread (time) |", "|---|---|---:|"]
    for name in SCENES:
        for load in (False, True):
            t = {r["threads"]: r["time"] for r in rows if r["scene"] == name and r["load"] == load}
            t1b.append(f"| {name} | {'yes' if load else 'no'} | {t[2] / t[1]:.2f} |")
    t2 = ["| on 2 threads, no load (default scene) | time | × floor |", "|---|---:|---:|",
          f"| grid_sample floor | {floor * 1e3:.0f} ms | 1.0 |",
          f"| render, default scene | {t_def * 1e3:.0f} ms | {t_def / floor:.1f} |",
          f"| method='direct' (extrapolated from 32×40) | {td * 1e3:,.0f} ms | {td / floor:,.0f} |"]
    t3 = ["| leaving out (default scene, 2 threads) | with | without | saving |", "|---|---:|---:|---:|",
          f"| sky work (horizon in view vs all-sea views) | {t_sky * 1e3:.0f} ms | {t_sea * 1e3:.0f} ms | {t_sky / t_sea:.2f}× |",
          f"| azimuth dimension (anisotropic vs isotropic) | {t_def * 1e3:.0f} ms | {t_iso * 1e3:.0f} ms | {t_def / t_iso:.2f}× |",
          f"| path between sea and sensor (on vs off) | {t_def * 1e3:.0f} ms | {t_nopath * 1e3:.0f} ms | {t_def / t_nopath:.2f}× |",
          f"| gradient bookkeeping (wind requires grad vs not) | {t_grad * 1e3:.0f} ms | {t_def * 1e3:.0f} ms | {t_grad / t_def:.2f}× |",
          f"| table over all angles vs over the pixels' span | {t_full * 1e3:.0f} ms, error {e_full:.1e} | {t_def * 1e3:.0f} ms, error {e_pix:.1e} | {e_full / max(e_pix, 1e-30):.1f}× error |"]
    acc = (f"Table against per-pixel evaluation (`method='direct'`), default scene at 32×40: worst sea pixel "
           f"{e_pix:.1e}, worst sky pixel {e_sky:.1e} (relative).")
    t4 = ["| batch 64, 512×640 | peak memory over baseline | output size | ratio |", "|---|---:|---:|---:|"]
    t4 += [f"| {k} | {v['peak_mb']:.0f} MB | {v['output_mb']:.0f} MB | {v['peak_mb'] / v['output_mb']:.1f}× |"
           for k, v in mem.items()]
    text = (head + "\n" + "\n".join(t1) + "\n\n" + "\n".join(t1b) + "\n\n" + "\n".join(t2) + "\n\n"
            + f"Table render vs direct: {td / t_def:,.0f}× faster.\n\n" + "\n".join(t3) + "\n\n" + acc + "\n\n"
            + "\n".join(t4) + "\n")
    print(text)
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "bench_render.md").write_text(text)
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(9, 3.8))
    names = list(SCENES)
    settings = [(1, False), (2, False), (1, True), (2, True)]
    width = 0.2
    for k, (th, load) in enumerate(settings):
        vals = [next(r["time"] / r["floor"] for r in rows if r["scene"] == n and r["threads"] == th and r["load"] == load)
                for n in names]
        ax.bar([i + (k - 1.5) * width for i in range(len(names))], vals, width,
               label=f"{th} thread{'s' if th > 1 else ''}{', competing process' if load else ''}")
    ax.set_xticks(range(len(names)), [n.replace(" (", "\n(") for n in names], fontsize=8)
    ax.set_ylabel("time / grid_sample floor")
    ax.set_title(f"render of {B}×{H}×{W}, float32")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(args.out / "bench_render.png", dpi=110)


if __name__ == "__main__":
    main()

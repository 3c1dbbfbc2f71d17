"""Speed and memory of textured seas (``SeaScene(seed=...)``) against the expectation images, and of
daytime scenes (the sun's glint) against the same by night, in one run.

The README's default scene (LOWTRAN7 midlatitude-summer sky, path on, radiance), 16 images 512×640,
float32, each with its own wind, direction, sea temperature and camera pose (altitude 10–500 m,
pitch −8…−1°; ``bench_render.batch``), rendered as expectation images and as textured realizations
(one seed per image), with 1 and 2 torch threads. Median of ``--repeats`` runs; the ratio is
textured / expectation timed in the same run. Then peak resident memory of each (separate
processes, sampled every millisecond over the resident memory just before the render; the batch
of 16 and one of 64), against the output's size, and where the textured render's time goes (1
thread).

Usage:
    python pipelines/bench_texture.py [--repeats 5] [--out docs]
"""

from __future__ import annotations

import argparse
import datetime as dt
import json
import math
import os
import platform
import subprocess
import sys
import time
from pathlib import Path

import torch

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _report import pyplot, write_report  # noqa: E402
from bench_render import B, H, W, batch, med, peak_memory  # noqa: E402

import roughsea_torch as rs  # noqa: E402


def alternately(f, g, repeats: int) -> tuple[float, float]:
    """The medians [s] of ``repeats`` timings of f and of g, run in turn (the machine's load falls on both)."""
    tf, tg = [], []
    for _ in range(repeats):
        for fn, out in ((f, tf), (g, tg)):
            t0 = time.perf_counter()
            fn()
            out.append(time.perf_counter() - t0)
    return sorted(tf)[len(tf) // 2], sorted(tg)[len(tg) // 2]


def scenes(b: int = B):
    cam, sc = batch(b)
    cams = rs.make_camera(H, W, **cam)
    return cams, rs.SeaScene(**sc), rs.SeaScene(**sc, seed=list(range(b)), time_s=12.5)


def memory_child(spec: str) -> None:
    kind, b = spec.split(":")
    b = int(b)
    cam, sc = batch(b)
    small = rs.make_camera(8, 8, **{k: v[:1] for k, v in cam.items()})
    extra = dict(seed=[0]) if kind == "textured" else {}
    rs.render(small, rs.SeaScene(**{k: v[:1] for k, v in sc.items()}, **extra))
    cams = rs.make_camera(H, W, **cam)
    scene = rs.SeaScene(**sc, **(dict(seed=list(range(b)), time_s=12.5) if kind == "textured" else {}))
    img, peak = peak_memory(lambda: rs.render(cams, scene))
    print(json.dumps({"peak_mb": peak, "output_mb": img.numel() * img.element_size() / 2**20}))


def stages(cams, textured) -> list[tuple[str, float]]:
    """Self time of the textured render's main parts (1 thread, torch profiler's CPU totals)."""
    from torch.profiler import ProfilerActivity, profile, record_function

    import roughsea_torch.renderer.texture as cl

    wrapped = {}
    for name in ("node_values", "volume", "pixels"):
        f = getattr(cl.TextureTable, name)

        def w(self, *a, _f=f, _n=name, **k):
            with record_function(f"texture.{_n}"):
                return _f(self, *a, **k)

        wrapped[name] = f
        setattr(cl.TextureTable, name, w)
    try:
        rs.render(cams, textured)
        with profile(activities=[ProfilerActivity.CPU]) as prof:
            t0 = time.perf_counter()
            with record_function("render"):
                rs.render(cams, textured)
            total = time.perf_counter() - t0
    finally:
        for name, f in wrapped.items():
            setattr(cl.TextureTable, name, f)
    ev = {e.key: e.cpu_time_total / 1e6 for e in prof.key_averages() if e.key.startswith(("texture.", "render"))}
    return [("whole render", total)] + [(k, v) for k, v in sorted(ev.items()) if k != "render"]


def band_reads(cams, textured) -> dict:
    """What the wave field's band lookups cost in one textured render (1 thread): the number of
    bilinear reads (point × channel) of the band tiles per pixel, and the time ``grid_sample``
    takes over them (timed around each call of ``WaveField._sample_points``); and the same
    kernel's cost per point for 1, 2 and 3 channels on random points of a doubled tile, which
    shows whether channels or points set it."""
    import torch.nn.functional as F

    import roughsea_torch.waves as wv

    class Timed:  # torch.nn.functional with grid_sample timed
        def __init__(self):
            self.t, self.reads = 0.0, 0

        def __getattr__(self, name):
            return getattr(F, name)

        def grid_sample(self, tile, grid, *a, **k):
            t0 = time.perf_counter()
            out = F.grid_sample(tile, grid, *a, **k)
            self.t += time.perf_counter() - t0
            self.reads += grid.shape[0] * grid.shape[1] * grid.shape[2] * tile.shape[1]
            return out

    rs.render(cams, textured)
    timed, orig = Timed(), wv.F_nn
    wv.F_nn = timed
    try:
        rs.render(cams, textured)
    finally:
        wv.F_nn = orig
    n = 2 * wv.WaveBands().tile_size + 1
    points = 2**18
    grid = torch.rand(1, 1, points, 2, generator=torch.Generator().manual_seed(0)) * 2 - 1
    per_channel = {}
    for c in (1, 2, 3):
        tile = torch.randn(1, c, n, n)
        per_channel[c] = med(lambda: F.grid_sample(tile, grid, mode="bilinear", padding_mode="border",
                                                   align_corners=True), 15) / points * 1e9
    pixels = B * H * W
    return {"reads_per_pixel": timed.reads / pixels, "read_time": timed.t, "ns_per_point": per_channel}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--out", default="docs")
    ap.add_argument("--memory-child", help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.memory_child:
        memory_child(args.memory_child)
        return
    cams, mean_scene, tex_scene = scenes()
    lines = [f"# Textured seas against expectation images ({dt.date.today()}, {platform.processor() or platform.machine()}, "
             f"torch {torch.__version__}, {os.cpu_count()} cores)", "",
             f"16 images {H}×{W} float32, README default scene (LOWTRAN7 sky, path, radiance), median of {args.repeats}; "
             "`python pipelines/bench_texture.py`", "",
             "| threads | expectation [s] | textured [s] | textured / expectation |", "|---:|---:|---:|---:|"]
    rows = []
    for threads in (1, 2):
        torch.set_num_threads(threads)
        t_mean = med(lambda: rs.render(cams, mean_scene), args.repeats)
        t_tex = med(lambda: rs.render(cams, tex_scene), args.repeats)
        rows.append((threads, t_mean, t_tex))
        lines.append(f"| {threads} | {t_mean:.3f} | {t_tex:.3f} | {t_tex / t_mean:.2f} |")
        print(lines[-1], file=sys.stderr)
    # where pixels meet the resolved waves: the sweep along ground tracks (TableSize(texture_hit="first"):
    # crests hide what is behind them) against the flat-sea point (the default), timed alternately
    first = rs.TableSize(texture_hit="first")
    lines += ["", "Textured with the sweep (`TableSize(texture_hit=\"first\")`: a crest hides what is behind it, a "
              "pixel averages what it sees) against the flat-sea point (the default), timed alternately:", "",
              "| threads | flat point [s] | sweep [s] | sweep / flat point |", "|---:|---:|---:|---:|"]
    for threads in (1, 2):
        torch.set_num_threads(threads)
        t_flat, t_first = alternately(lambda: rs.render(cams, tex_scene), lambda: rs.render(cams, tex_scene, table=first),
                                      args.repeats)
        lines.append(f"| {threads} | {t_flat:.3f} | {t_first:.3f} | {t_first / t_flat:.2f} |")
        print(lines[-1], file=sys.stderr)
    # by day: the same batch with the sun 10° above the horizon straight ahead of each camera (its
    # glint per pixel where it can be seen), LOWTRAN7 irradiance, against the same batch by night
    cam, sc = batch(B)
    ahead = torch.deg2rad(cam["yaw_deg"].double())
    day_kw = dict(sun_zenith=torch.full((B,), math.radians(80.0), dtype=torch.float64), sun_azimuth=ahead)
    lines += ["", "By day: the sun 10° above the horizon ahead of each camera (LOWTRAN7 irradiance), 1 thread:", "",
              "| render | night [s] | day [s] | day / night |", "|---|---:|---:|---:|"]
    torch.set_num_threads(1)
    for name, extra in (("expectation", {}), ("textured", dict(seed=list(range(B)), time_s=12.5))):
        night = rs.SeaScene(**sc, **extra)
        day = rs.SeaScene(**sc, **extra, **day_kw)
        t_n = med(lambda: rs.render(cams, night), args.repeats)
        t_d = med(lambda: rs.render(cams, day), args.repeats)
        lines.append(f"| {name} | {t_n:.3f} | {t_d:.3f} | {t_d / t_n:.2f} |")
        print(lines[-1], file=sys.stderr)
    # the TableSize that brings textured MWIR glint pixels under the day sky's aureole from 7e-4 to 2.4e-4 of
    # per-pixel evaluation (tests/test_sun.py), against the default, timed alternately
    refined = rs.TableSize(texture_quadrature=(20, 16), texture_azimuth_sun=17, fine_texture_azimuth=64)
    t_def, t_ref = alternately(lambda: rs.render(cams, day), lambda: rs.render(cams, day, table=refined), args.repeats)
    lines += ["", "Textured by day with the TableSize refined for the sun's aureole (`texture_quadrature=(20, 16), "
              "texture_azimuth_sun=17, fine_texture_azimuth=64`), against the default, timed alternately, 1 thread:", "",
              "| default [s] | refined [s] | refined / default |", "|---:|---:|---:|",
              f"| {t_def:.3f} | {t_ref:.3f} | {t_ref / t_def:.2f} |"]
    print(lines[-1], file=sys.stderr)
    # a camera with every azimuth in view (straight down) takes more azimuth nodes by day (TableSize.azimuth_day)
    lines += ["", "By day looking down (MWIR, LOWTRAN7 day sky, sun 34° from the zenith, 4 images 256×320, 20 m, "
              "30° field of view, 8 m/s), 1 thread: at −90° every azimuth is in view and the tables take more "
              "azimuth nodes:", "", "| render | pitch −60° [s] | pitch −90° [s] | ratio |", "|---|---:|---:|---:|"]
    for name, seed in (("expectation", None), ("textured", [1, 2, 3, 4])):
        t_p = []
        for pitch in (-60.0, -90.0):
            c = rs.make_camera(256, 320, hfov_deg=30.0, altitude_m=20.0, pitch_deg=pitch, batch_size=4)
            s_ = rs.SeaScene(wind_speed=8.0, sea_temperature=290.0, band=rs.MWIR, sun_zenith=0.6, seed=seed)
            t_p.append(med(lambda: rs.render(c, s_), args.repeats))
        lines.append(f"| {name} | {t_p[0]:.3f} | {t_p[1]:.3f} | {t_p[1] / t_p[0]:.2f} |")
        print(lines[-1], file=sys.stderr)
    lines += ["", "Peak resident memory over the process's before the render (separate processes, 2 threads; a batch "
              "of 64 as well, where the fixed part, tables and per-thread workspaces, weighs less):", "",
              "| render | images | peak [MB] | output [MB] | peak / output |", "|---|---:|---:|---:|---:|"]
    for b in (B, 64):
        for kind in ("expectation", "textured"):
            out = subprocess.run([sys.executable, __file__, "--memory-child", f"{kind}:{b}"], capture_output=True,
                                 text=True, check=True, env=dict(os.environ, OMP_NUM_THREADS="2"))
            m = json.loads(out.stdout.strip().splitlines()[-1])
            lines.append(f"| {kind} | {b} | {m['peak_mb']:.0f} | {m['output_mb']:.0f} | {m['peak_mb'] / m['output_mb']:.1f} |")
            print(lines[-1], file=sys.stderr)
    torch.set_num_threads(1)
    lines += ["", "Where the textured render's time goes (1 thread, profiler CPU totals):", "", "| part | s |", "|---|---:|"]
    lines += [f"| {k} | {v:.3f} |" for k, v in stages(cams, tex_scene)]
    # the floor that the band lookups set: the 3x goal leaves 2 expectation renders for all of the texture
    reads = band_reads(cams, tex_scene)
    t_mean1 = rows[0][1]
    ns = reads["ns_per_point"]
    lines += ["", "The wave field's band lookups (1 thread): bilinear reads of the band tiles, a point and a "
              "channel each, timed in the render; `grid_sample`'s cost per point on a doubled 257×257 tile "
              f"(random points, median of 15): {ns[1]:.1f} ns with 1 channel, {ns[2]:.1f} with 2, {ns[3]:.1f} "
              "with 3, so channels, not points, set it.", "",
              "| reads per pixel | time in grid_sample [s] | ns per read | that time / expectation render |",
              "|---:|---:|---:|---:|",
              f"| {reads['reads_per_pixel']:.1f} | {reads['read_time']:.3f} | "
              f"{reads['read_time'] / (reads['reads_per_pixel'] * B * H * W) * 1e9:.2f} | "
              f"{reads['read_time'] / t_mean1:.2f} |"]
    print("\n".join(lines[-5:]), file=sys.stderr)
    out = write_report(args.out, "bench_texture.md", "\n".join(lines) + "\n")
    plt = pyplot()
    if plt is not None:
        fig, ax = plt.subplots(figsize=(5, 3.2))
        x = range(len(rows))
        ax.bar([i - 0.2 for i in x], [r[1] for r in rows], 0.4, label="expectation")
        ax.bar([i + 0.2 for i in x], [r[2] for r in rows], 0.4, label="textured")
        ax.set_xticks(list(x), [f"{r[0]} thread{'s' if r[0] > 1 else ''}" for r in rows])
        ax.set_ylabel("seconds for 16 × 512×640")
        ax.legend()
        fig.tight_layout()
        fig.savefig(out / "bench_texture.png", dpi=120)


if __name__ == "__main__":
    main()

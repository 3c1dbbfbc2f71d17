"""What the first-hit texture (``TableSize(texture_hit="first")``, the sweep of renderer/hits.py) costs
against the default textured render (the flat point) and the expectation image, before and after a
change of the sweep, and where its time goes.

One LWIR image, 10 m/s looking upwind, a 15 m mast, pitch −6°, 12° field of view (view zenith 79–89°,
ranges 80 m to the horizon's last resolved waves), float32, foam on (the scene's default) and no
earth curvature change (the renderer's default), at 512×640 and 256×320; and at 512×640, one thread, a
far-field-heavy camera (20 m mast, pitch −2°: rows from 170 m to the horizon). Each configuration is
timed in turn within one loop (so the machine's load falls on all of them), median of ``--repeats``,
with 1 and 2 torch threads. ``--baseline DIR``: a checkout (e.g. ``git archive main roughsea_torch | tar -x
-C DIR``) whose ``roughsea_torch`` is loaded beside this one under another name and timed as
"first-hit, baseline". Variants: ``TableSize`` fields of the sweep's parts (its two tracks per pixel, its
cap on the samples' footprint, both as before 2026-11-27's evening), a coarser sweep (``texture_hit_across``
2) and the unresolved waves' patch moments (``texture_hit_lean``), timed as well.

Then, 1 thread, where the first-hit render's time goes (each stage timed around its call, the rest of
the render left to "other"), and the sweep's size: samples per track, tracks, samples per pixel, the
share of the samples whose slopes, crest, texture and foam are read (visible, within the track's
pixels' windows).

Usage:
    python pipelines/bench_first_hit.py [--repeats 5] [--baseline /tmp/base] [--out docs]
"""

from __future__ import annotations

import argparse
import datetime as dt
import importlib.util
import platform
import sys
import time
import warnings
from pathlib import Path

import torch

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(Path(__file__).resolve().parent))
from _report import write_report  # noqa: E402

import roughsea_torch as rs  # noqa: E402
import roughsea_torch.renderer.swept as sx  # noqa: E402
import roughsea_torch.renderer.texture as tx  # noqa: E402
import roughsea_torch.waves as wv  # noqa: E402
import roughsea_torch.whitecaps as wc  # noqa: E402

SIZES = ((512, 640), (256, 320))
SCENE = dict(wind_speed=10.0, sea_temperature=290.0, seed=11, time_s=3.0)
CAMERA = dict(hfov_deg=12.0, altitude_m=15.0, pitch_deg=-6.0)
FAR_CAMERA = dict(hfov_deg=12.0, altitude_m=20.0, pitch_deg=-2.0)  # timed at 512×640, one thread
CAMERAS = {"15 m, −6°": CAMERA, "20 m, −2°": FAR_CAMERA}
VARIANTS = {"first-hit, one track (texture_hit_tracks=1)": dict(texture_hit_tracks=1.0),
            "first-hit, no footprint cap (texture_hit_finest=0, min_step 1/64)":
                dict(texture_hit_finest=0.0, texture_hit_min_step=1 / 64),
            "first-hit, the sweep's former settings (one track, no cap, min_step 1/64)":
                dict(texture_hit_tracks=1.0, texture_hit_finest=0.0, texture_hit_min_step=1 / 64),
            "first-hit, across 2": dict(texture_hit_across=2.0),
            "first-hit, patch moments (texture_hit_lean)": dict(texture_hit_lean=True)}


def load_baseline(path: str):
    """The package ``roughsea_torch`` of the checkout ``path``, imported as ``roughsea_baseline`` (its
    imports are relative, so it runs on its own modules)."""
    init = Path(path) / "roughsea_torch" / "__init__.py"
    spec = importlib.util.spec_from_file_location("roughsea_baseline", init, submodule_search_locations=[str(init.parent)])
    mod = importlib.util.module_from_spec(spec)
    sys.modules["roughsea_baseline"] = mod
    spec.loader.exec_module(mod)
    return mod


def renders(size: tuple[int, int], base, camera: dict = CAMERA) -> dict:
    """name → a function rendering the size's image that way."""
    cams = rs.make_camera(*size, **camera)
    out = {"expectation": lambda: rs.render(cams, rs.SeaScene(**{k: v for k, v in SCENE.items() if k != "seed"})),
           "textured, flat point (default)": lambda: rs.render(cams, rs.SeaScene(**SCENE)),
           "first-hit": lambda: rs.render(cams, rs.SeaScene(**SCENE), table=rs.TableSize(texture_hit="first"))}
    if base is not None:
        bcams = base.make_camera(*size, **camera)
        out["first-hit, baseline"] = lambda: base.render(bcams, base.SeaScene(**SCENE),
                                                         table=base.TableSize(texture_hit="first"))
    for name, kw in VARIANTS.items():
        out[name] = lambda kw=kw: rs.render(cams, rs.SeaScene(**SCENE), table=rs.TableSize(texture_hit="first", **kw))
    return out


def timings(fns: dict, repeats: int) -> dict:
    """The median [s] of each, all timed in turn ``repeats`` times after a warm-up call each."""
    for f in fns.values():
        f()
    ts = {k: [] for k in fns}
    for _ in range(repeats):
        for k, f in fns.items():
            t0 = time.perf_counter()
            f()
            ts[k].append(time.perf_counter() - t0)
    return {k: sorted(v)[len(v) // 2] for k, v in ts.items()}


class Stages:
    """Wall time spent in the sweep's stages of one first-hit render (1 thread), each function of
    renderer/swept.py's namespace (or of the WaveField, or the texture table's volume read) wrapped with a
    timer; and the sweep's size."""

    WRAPPED = {"layout (sample points)": "sweep_layout", "envelope (running minimum)": "sweep_envelope",
               "visible samples": "visible_samples", "pixels' windows: search and average": "pixel_hits",
               "quantile x at the samples": "resolved_quantile", "across-view quantile y at the samples": "_across_quantile",
               "foam at the samples": "whitecap_cover"}
    NESTED = "  of which the streak noise"  # (inside "foam at the samples": not added to the stages' sum)

    def __init__(self):
        self.t = {k: 0.0 for k in list(self.WRAPPED) + [self.NESTED, "wave-field reads: elevation",
                                                        "wave-field reads: slopes (+ crest)", "texture volume reads"]}
        self.size = {}

    def run(self, render) -> float:
        saved = {n: getattr(sx, n) for n in self.WRAPPED.values() if hasattr(sx, n)}
        sample, read, streaks = wv.WaveField.sample_unchecked, tx.TextureTable._read_volume, wc.streak_noise

        def timed(label, f):
            def w(*a, **k):
                t0 = time.perf_counter()
                out = f(*a, **k)
                self.t[label] += time.perf_counter() - t0
                if label.startswith("layout") and out is not None:
                    self.size.update(ns_laid=out.shape[0], nt=out.shape[1])
                if label.startswith("envelope"):  # the samples whose elevation is read (the last call's)
                    self.size.update(ns=out[1].shape[1])
                if label == "visible samples":
                    self.size["visible"] = float(out.float().mean())
                    self.size["read"] = int(out.sum())
                return out
            return w

        def sample_timed(field, xt, *a, **k):
            t0 = time.perf_counter()
            out = sample(field, xt, *a, **k)
            elev_only = k.get("slopes", True) is False
            self.t["wave-field reads: elevation" if elev_only else "wave-field reads: slopes (+ crest)"] += time.perf_counter() - t0
            return out

        for label, n in self.WRAPPED.items():
            if n in saved:
                setattr(sx, n, timed(label, saved[n]))
        wv.WaveField.sample_unchecked = sample_timed
        tx.TextureTable._read_volume = timed("texture volume reads", read)
        wc.streak_noise = timed(self.NESTED, streaks)
        try:
            t0 = time.perf_counter()
            render()
            return time.perf_counter() - t0
        finally:
            for n, f in saved.items():
                setattr(sx, n, f)
            wv.WaveField.sample_unchecked, tx.TextureTable._read_volume, wc.streak_noise = sample, read, streaks


TABLES = [(1, SIZES[0], "15 m, −6°"), (1, SIZES[1], "15 m, −6°"), (1, SIZES[0], "20 m, −2°"),
          (2, SIZES[0], "15 m, −6°"), (2, SIZES[1], "15 m, −6°")]
STAGES = [(SIZES[0], "15 m, −6°"), (SIZES[1], "15 m, −6°"), (SIZES[0], "20 m, −2°")]


def reading(results: dict, stages: dict, baseline: bool) -> list[str]:
    """The report's reading, from the measured times (1 thread)."""
    out = ["## Reading", ""]
    for size, cam in STAGES:
        t = results[(1, size, cam)]
        total, st = stages[(size, cam)]
        n = st.size["ns"] * st.size["nt"]
        reads = st.t["wave-field reads: elevation"] + st.t["wave-field reads: slopes (+ crest)"]
        line = (f"- {size[0]}×{size[1]}, {cam}, 1 thread: the first hit costs "
                f"{t['first-hit'] / t['textured, flat point (default)']:.1f}× the default textured render and "
                f"{t['first-hit'] / t['expectation']:.0f}× the expectation image")
        if baseline:
            line += f" (the baseline's: {t['first-hit, baseline'] / t['textured, flat point (default)']:.1f}×; "
            line += f"{t['first-hit, baseline'] / t['first-hit']:.2f}× faster now)"
        out.append(line + f". The sweep takes {n / (size[0] * size[1]):.0f} samples per pixel (the elevation at each), "
                   f"{st.size['read'] / (size[0] * size[1]):.0f} read in full, {1e9 * total / n:.0f} ns per sample all "
                   f"told, against {1e9 * t['textured, flat point (default)'] / (size[0] * size[1]):.0f} ns per pixel "
                   f"for the whole default render; the wave-field reads are {100 * reads / total:.0f} % of it, the foam "
                   f"at the samples {100 * st.t['foam at the samples'] / total:.0f} % (its streak noise "
                   f"{100 * st.t[Stages.NESTED] / total:.0f} %).")
    two = [results[(2, size, "15 m, −6°")]["first-hit"] / results[(1, size, "15 m, −6°")]["first-hit"] for size in SIZES]
    out.append(f"- Two threads against one, first hit at 15 m, −6°: {two[0]:.2f}× (512×640) and {two[1]:.2f}× (256×320) the "
               "time. A render of one image runs on one intra-op thread (`_parallel.one_thread`, called by `render`), "
               "so torch's own parallel loops (e.g. `grid_sample`'s over the batch) do not serve it.")
    out += ["- The cost is the number of samples: the elevation at every one of them (the running horizon needs it) "
            "and the slopes, crest variable, texture and foam at the visible ones within the track's windows. The "
            "coarser sweeps above trade samples for accuracy against the ray tracer (docs/texture.md, the sweep).", ""]
    return out


def stage_table(size: tuple[int, int], cam: str, st: Stages, total: float) -> list[str]:
    """The stages of one first-hit render, as a table."""
    ns, nt = st.size["ns"], st.size["nt"]
    lines = [f"Where the first-hit render's time goes, {size[0]}×{size[1]}, {cam}, 1 thread (one render, {total:.3f} s, "
             f"the median of 3; {ns} samples per track (of {st.size['ns_laid']} laid out) × {nt} tracks = "
             f"{ns * nt / 1e6:.2f} M samples, "
             f"{ns * nt / (size[0] * size[1]):.1f} per pixel, {100 * st.size['visible']:.0f} % of them read in full):", "",
             "| stage | s | share |", "|---|---:|---:|"]
    rest = total - sum(v for k, v in st.t.items() if k != Stages.NESTED)
    for k, v in list(st.t.items()) + [("other (tables, per-pixel terms, gathers, scatters)", rest)]:
        lines.append(f"| {k} | {v:.3f} | {100 * v / total:.0f} % |")
    return lines + [""]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--baseline", default=None, help="a checkout whose roughsea_torch is timed as the baseline")
    ap.add_argument("--out", default=str(ROOT / "docs"))
    args = ap.parse_args()
    warnings.simplefilter("ignore")
    base = load_baseline(args.baseline) if args.baseline else None
    lines = [f"# The first-hit texture's cost ({dt.date.today().isoformat()}, {platform.machine()}, torch "
             f"{torch.__version__}, 2 cores shared with other jobs)", "",
             f"One LWIR image, 10 m/s upwind, 12° field of view, float32, foam on; a 15 m mast looking 6° down, and "
             f"a 20 m mast looking 2° down; all renders of a table timed in turn, median of {args.repeats}; "
             f"`python pipelines/bench_first_hit.py{' --baseline <main>' if base else ''}`", ""]
    results = {}
    for threads, size, cam in TABLES:
        torch.set_num_threads(threads)
        t = timings(renders(size, base, CAMERAS[cam]), args.repeats)
        results[(threads, size, cam)] = t
        lines += [f"{size[0]}×{size[1]}, {cam}, {threads} thread{'s' if threads > 1 else ''}:", "",
                  "| render | time [s] | × expectation | × default textured |", "|---|---:|---:|---:|"]
        for k, v in t.items():
            lines.append(f"| {k} | {v:.3f} | {v / t['expectation']:.1f} | {v / t['textured, flat point (default)']:.2f} |")
        if base is not None:
            lines.append(f"\nfirst-hit baseline / first-hit: {t['first-hit, baseline'] / t['first-hit']:.2f}")
        lines.append("")
        print("\n".join(lines[-(len(t) + 4):]), file=sys.stderr)
    torch.set_num_threads(1)
    stages = {}
    for size, cam in STAGES:
        cams = rs.make_camera(*size, **CAMERAS[cam])
        f = lambda: rs.render(cams, rs.SeaScene(**SCENE), table=rs.TableSize(texture_hit="first"))  # noqa: E731
        f()
        runs = []
        for _ in range(3):
            st = Stages()
            runs.append((st.run(f), st))
        total, st = sorted(runs, key=lambda r: r[0])[1]
        lines += stage_table(size, cam, st, total)
        print("\n".join(lines[-(len(st.t) + 5):]), file=sys.stderr)
        stages[(size, cam)] = (total, st)
    lines += reading(results, stages, base is not None)
    write_report(args.out, "bench_first_hit.md", "\n".join(lines) + "\n")


if __name__ == "__main__":
    main()

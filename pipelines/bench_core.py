"""Speed of the core model: evaluations per second of ``apparent_radiance`` against the numpy reference.

The core issue's benchmark: 1e5 view directions × 16 sea states (Cox–Munk winds 0–30 m/s,
isotropic and anisotropic), default accuracy, float32 (and float64), against the numpy reference
timed in the same run on a sample of the same cases (it takes ~0.5 s per evaluation, so it is
timed on ``--ref-evals`` evaluations and its rate extrapolated). Median of ``--repeats`` runs.

Writes a Markdown table to stdout and ``--out``/bench_core.md, and a bar chart bench_core.png.

Usage:
    python pipelines/bench_core.py [--views 100000] [--states 16] [--repeats 3] [--out docs]
"""

from __future__ import annotations

import argparse
import datetime as dt
import math
import platform
import statistics
import time
from pathlib import Path

import numpy as np
import torch
from tqdm import tqdm

import roughsea_torch as rs
import roughsea_torch.reference as ref


def sky(c):
    return 11.0 + 19.0 * (1.0 - c) ** 8


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--views", type=int, default=100_000)
    ap.add_argument("--states", type=int, default=16)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--ref-evals", type=int, default=12)
    ap.add_argument("--dtypes", default="float32", help="comma-separated: float32,float64")
    ap.add_argument("--out", type=Path, default=Path("docs"))
    args = ap.parse_args()
    g = torch.Generator().manual_seed(0)
    th = torch.rand(args.views, 1, generator=g, dtype=torch.float64) * (89.99 * math.pi / 180)
    ph = torch.rand(args.views, 1, generator=g, dtype=torch.float64) * (2 * math.pi)
    winds = torch.linspace(0.0, 30.0, args.states, dtype=torch.float64)
    m = 1.218 + 0.0508j
    rows = []
    rng = np.random.default_rng(0)
    picks = rng.integers(0, args.views, args.ref_evals), rng.integers(0, args.states, args.ref_evals)
    for aniso in (False, True):
        # numpy reference on a sample of the same cases
        t_ref = []
        for i, j in tqdm(list(zip(*picks)), desc=f"reference ({'aniso' if aniso else 'iso'})", leave=False):
            s = ref.SlopeStatistics.cox_munk(float(winds[j]), anisotropic=aniso)
            t0 = time.perf_counter()
            ref.apparent_radiance(float(th[i, 0]), float(ph[i, 0]), s, m, sea_radiance=30.0, sky=sky)
            t_ref.append(time.perf_counter() - t0)
        ref_rate = 1.0 / statistics.median(t_ref)
        for dtype in [getattr(torch, d) for d in args.dtypes.split(",")]:
            s = rs.SlopeStatistics.cox_munk(winds.to(dtype), anisotropic=aniso)
            times = []
            for _ in tqdm(range(args.repeats), desc=f"torch {str(dtype)[6:]} ({'aniso' if aniso else 'iso'})", leave=False):
                t0 = time.perf_counter()
                out = rs.apparent_radiance(th.to(dtype), ph.to(dtype), s, m, sea_radiance=30.0, sky=sky)
                times.append(time.perf_counter() - t0)
            assert out.shape == (args.views, args.states) and torch.isfinite(out).all()
            rate = args.views * args.states / statistics.median(times)
            rows.append((("anisotropic" if aniso else "isotropic"), str(dtype)[6:], rate, ref_rate, rate / ref_rate,
                         statistics.median(times)))
    header = (f"Core benchmark, {args.views} view directions × {args.states} sea states (Cox–Munk 0–30 m/s), "
              f"default accuracy; {platform.processor() or platform.machine()}, {torch.get_num_threads()} threads, "
              f"torch {torch.__version__}, {dt.date.today().isoformat()}.\n"
              f"Command: `python pipelines/bench_core.py --views {args.views} --states {args.states} --repeats {args.repeats} --dtypes {args.dtypes}`\n")
    table = ["| slopes | dtype | torch evals/s | reference evals/s | speed-up | torch wall time (median) |",
             "|---|---|---:|---:|---:|---:|"]
    for slopes, dtype, rate, rrate, ratio, t in rows:
        table.append(f"| {slopes} | {dtype} | {rate:,.0f} | {rrate:.2f} | {ratio:,.0f}× | {t:.1f} s |")
    text = header + "\n" + "\n".join(table) + "\n"
    print(text)
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "bench_core.md").write_text(text)
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 3.5))
    labels = [f"{s}\n{d}" for s, d, *_ in rows]
    ax.bar(labels, [r[2] for r in rows], label="torch")
    ax.bar(labels, [r[3] for r in rows], label="numpy reference")
    ax.set_yscale("log")
    ax.set_ylabel("evaluations / s")
    ax.set_title("apparent_radiance throughput (CPU)")
    ax.legend()
    fig.tight_layout()
    fig.savefig(args.out / "bench_core.png", dpi=110)


if __name__ == "__main__":
    main()

"""This checkout against another git revision, timed alternately: did a change slow anything down?

Each workload (the benchmarks' headline renders: ``bench_render``'s expectation batch, ``bench_texture``'s
textured batch, ``bench_augmentation``'s textured training batch) runs in a fresh process for one tree,
then for the other, ``--repeats`` times in turn, so that the machine's load (cores shared with other
jobs) falls on both alike; each process times its workload ``--inner`` times after a warm-up and keeps
the median. The report gives the median over the rounds, the ratio, and the spread of the ratio
over the rounds (its run-to-run noise).

    python pipelines/bench_versions.py --against 6cdd3b1 [--repeats 5] [--threads 1 2] [--out docs]

The other revision is checked out into a temporary worktree (``git worktree add``), removed at the end.
Writes ``bench_versions.md``.
"""

from __future__ import annotations

import argparse
import datetime as dt
import json
import os
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

from _report import write_report

ROOT = Path(__file__).resolve().parents[1]

CHILD = r'''
import json, statistics, sys, time, warnings
import torch
torch.set_num_threads(int(sys.argv[2]))
warnings.simplefilter("ignore")
import roughsea_torch as rs
from roughsea_torch.augmentation import RandomSeaBackground
name, inner = sys.argv[1], int(sys.argv[3])
B, H, W = 16, 512, 640
g = torch.Generator().manual_seed(0)
u = lambda lo, hi: lo + (hi - lo) * torch.rand(B, generator=g)
cams = rs.make_camera(H, W, hfov_deg=u(20.0, 40.0), altitude_m=u(10.0, 100.0), pitch_deg=u(-10.0, -1.0),
                      yaw_deg=u(0.0, 360.0), batch_size=B)
kw = dict(wind_speed=u(2.0, 15.0), wind_direction=u(0.0, 6.28), sea_temperature=u(285.0, 300.0))
if name == "expectation":
    sc = rs.SeaScene(**kw)
    job = lambda: rs.render(cams, sc)
elif name == "textured":
    sc = rs.SeaScene(**kw, seed=list(range(B)), time_s=12.5)
    job = lambda: rs.render(cams, sc)
else:
    aug = RandomSeaBackground(output="brightness_temperature")
    x = torch.zeros(8, 1, 256, 320)
    job = lambda: aug(x, generator=torch.Generator().manual_seed(3))
job()
times = []
for _ in range(inner):
    t0 = time.perf_counter(); job(); times.append(time.perf_counter() - t0)
print(json.dumps(statistics.median(times)))
'''


def run(tree: Path, name: str, threads: int, inner: int) -> float:
    env = dict(os.environ, PYTHONPATH=str(tree))
    out = subprocess.run([sys.executable, "-c", CHILD, name, str(threads), str(inner)], capture_output=True, text=True,
                         env=env, cwd=tree, timeout=3600)
    if out.returncode:
        raise RuntimeError(out.stderr[-2000:])
    return float(json.loads(out.stdout.strip().splitlines()[-1]))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--against", required=True, help="the git revision to compare with (e.g. the commit before a change)")
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--inner", type=int, default=3)
    ap.add_argument("--threads", type=int, nargs="+", default=[1, 2])
    ap.add_argument("--workloads", nargs="+", default=["expectation", "textured", "augmentation"])
    ap.add_argument("--out", default=str(ROOT / "docs"))
    args = ap.parse_args()
    rev = subprocess.run(["git", "rev-parse", "--short", args.against], capture_output=True, text=True, cwd=ROOT,
                         check=True).stdout.strip()
    head = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True, cwd=ROOT,
                          check=True).stdout.strip()
    load0 = os.getloadavg()[0]
    with tempfile.TemporaryDirectory() as tmp:
        other = Path(tmp) / "other"
        subprocess.run(["git", "worktree", "add", "--detach", str(other), rev], cwd=ROOT, check=True, capture_output=True)
        try:
            lines = [f"# This checkout ({head}) against {rev}, timed alternately ({dt.date.today()})", "",
                     f"`python pipelines/bench_versions.py --against {args.against} --repeats {args.repeats}`: each "
                     f"workload in a fresh process per tree, the trees in turn, {args.repeats} rounds; each process keeps "
                     f"the median of {args.inner} runs after a warm-up. Workloads: 16 images 512×640 (expectation, "
                     "textured), an augmentation batch of 8 textured 256×320 images.", "",
                     f"| workload | threads | {rev} [s] | {head} [s] | ratio | ratio's spread over rounds |",
                     "|---|---:|---:|---:|---:|---|"]
            for name in args.workloads:
                for threads in args.threads:
                    old, new = [], []
                    for _ in range(args.repeats):
                        old.append(run(other, name, threads, args.inner))
                        new.append(run(ROOT, name, threads, args.inner))
                    ratios = [n / o for n, o in zip(new, old)]
                    lines.append(f"| {name} | {threads} | {statistics.median(old):.3f} | {statistics.median(new):.3f} | "
                                 f"{statistics.median(new) / statistics.median(old):.3f} | "
                                 f"{min(ratios):.3f}–{max(ratios):.3f} |")
                    print(lines[-1], file=sys.stderr)
        finally:
            subprocess.run(["git", "worktree", "remove", "--force", str(other)], cwd=ROOT, capture_output=True)
    lines += ["", f"Load average {load0:.1f} at the start, {os.getloadavg()[0]:.1f} at the end (2 cores; other jobs "
              "shared them)."]
    write_report(args.out, "bench_versions.md", "\n".join(lines) + "\n")


if __name__ == "__main__":
    main()

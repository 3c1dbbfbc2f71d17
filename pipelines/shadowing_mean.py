"""The expectation's mean near grazing with Eq. 5 and with the slope-conditioned masking, against the
ray-traced ensemble mean.

For the ensembles of ``pipelines/texture_vs_raytrace.py`` at pitch −6° (view zenith 79.6–88.4°;
winds 5, 10, 15 m/s; upwind from a 15 m mast and crosswind from 20 m; 48×64 px over 12°; LWIR,
LOWTRAN midlatitude summer, sea 290 K, no foam, no path, flat Earth) it renders the expectation image
(``seed=None``) with ``shadowing=True`` (the paper's Eq. 5) and ``shadowing="correlated"``
(:mod:`roughsea_torch.masking`) and reports, per 8-row bin, in kelvin:

- ray-traced − Eq. 5 (the ensemble's saved mean offset, ± its standard error over 16 seeds);
- ray-traced − correlated = (ray-traced − Eq. 5) − (correlated − Eq. 5);
- correlated − Eq. 5.

The ray-traced side is read from a pickle written by ``texture_vs_raytrace.py --save`` (no tracing);
without one, run that pipeline first (``--save results.pkl``, about 10 minutes).

Usage:
    python pipelines/shadowing_mean.py --load results.pkl [--out docs]
"""

from __future__ import annotations

import argparse
import datetime as dt
import math
import os
import pickle
import sys
import time
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")

import numpy as np  # noqa: E402
import torch  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "pipelines"))

from _report import pyplot, write_report  # noqa: E402
import texture_vs_raytrace as tvr  # noqa: E402

import roughsea_torch as rs  # noqa: E402

PITCH = -6.0


def expectation_bins(direction: str, wind: float, shadowing) -> tuple[np.ndarray, np.ndarray]:
    """(bin means [K], view zenith of the bins' centres [deg]) of the expectation image."""
    mast, wdir = tvr.DIRECTIONS[direction]
    cams = rs.make_camera(tvr.H, tvr.W, hfov_deg=tvr.HFOV, altitude_m=mast, pitch_deg=PITCH)
    sc = rs.SeaScene(wind_speed=wind, wind_direction=wdir, sea_temperature=tvr.T_SEA, seed=None, time_s=tvr.TIME_S,
                     foam=False, path=False, sky="midlatitude_summer", shadowing=shadowing)
    img = tvr.render(cams, sc)[0, 0].numpy()
    return np.array([img[r0:r0 + tvr.BIN].mean() for r0 in range(0, tvr.H, tvr.BIN)])


def run(saved: dict) -> list[dict]:
    rows = []
    for e in saved["ens"]:
        if e["pitch"] != PITCH:
            continue
        eq5 = expectation_bins(e["direction"], e["wind"], True)
        cor = expectation_bins(e["direction"], e["wind"], "correlated")
        for b, m5, mc in zip(e["bins"], eq5, cor):
            rows.append(dict(direction=e["direction"], wind=e["wind"], vz=b["vz"], ray=b["ray"], se=b["ray_se"],
                             shift=float(mc - m5), ray_cor=b["ray"] - float(mc - m5)))
    return rows


def report(rows: list[dict], source: str, seconds: float) -> str:
    lines = [
        "# The expectation's mean near grazing: Eq. 5 and the slope-conditioned masking against the ray tracer",
        "",
        f"Written by `pipelines/shadowing_mean.py` ({dt.date.today().isoformat()}, {seconds:.0f} s) from the ray-traced "
        f"ensembles of `{source}` (`pipelines/texture_vs_raytrace.py --save`, 16 seeds, 4 rays per pixel).",
        "",
        "Per 8-row bin, mean brightness temperature differences [K]. `ray − Eq. 5`: the ray-traced ensemble mean "
        "minus the expectation image with the paper's shadowing (± standard error over the seeds); "
        "`ray − corr.`: the same against `shadowing=\"correlated\"`; `corr. − Eq. 5`: what the option changes.",
        "",
        "| looking | wind [m/s] | view zenith [°] | ray − Eq. 5 [K] | ray − corr. [K] | corr. − Eq. 5 [K] |",
        "|---|---:|---|---:|---:|---:|",
    ]
    for r in rows:
        lines.append(f"| {r['direction']} | {r['wind']:g} | {r['vz'][0]:.1f}–{r['vz'][1]:.1f} | "
                     f"{r['ray']:+.3f} ± {r['se']:.3f} | {r['ray_cor']:+.3f} | {r['shift']:+.3f} |")
    worst5 = max(abs(r["ray"]) for r in rows)
    worstc = max(abs(r["ray_cor"]) for r in rows)
    within5 = sum(abs(r["ray"]) <= 0.05 for r in rows)
    withinc = sum(abs(r["ray_cor"]) <= 0.05 for r in rows)
    better = sum(abs(r["ray_cor"]) < abs(r["ray"]) for r in rows)
    lines += ["", f"Largest |offset|: Eq. 5 {worst5:.3f} K, correlated {worstc:.3f} K; bins within 0.05 K: Eq. 5 "
                  f"{within5} / {len(rows)}, correlated {withinc} / {len(rows)}; the option is closer in {better} / "
                  f"{len(rows)} bins."]
    return "\n".join(lines) + "\n"


def figure(rows: list[dict], out: Path) -> None:
    plt = pyplot()
    if plt is None:
        return
    fig, axes = plt.subplots(1, 2, figsize=(10, 3.8), sharey=True)
    for ax, direction in zip(axes, ("upwind", "crosswind")):
        for wind, color in zip((5.0, 10.0, 15.0), ("C0", "C1", "C2")):
            rr = [r for r in rows if r["direction"] == direction and r["wind"] == wind]
            if not rr:
                continue
            vz = [0.5 * (r["vz"][0] + r["vz"][1]) for r in rr]
            ax.errorbar(vz, [r["ray"] for r in rr], [r["se"] for r in rr], color=color, marker="o",
                        label=f"{wind:g} m/s, Eq. 5")
            ax.plot(vz, [r["ray_cor"] for r in rr], color=color, marker="s", ls="--", label=f"{wind:g} m/s, correlated")
        ax.axhline(0.0, color="k", lw=0.5)
        ax.set_title(f"looking {direction}")
        ax.set_xlabel("view zenith [deg]")
    axes[0].set_ylabel("ray-traced mean − expectation [K]")
    axes[1].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(out / "shadowing_mean.png", dpi=110)
    plt.close(fig)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--load", required=True, help="a pickle of texture_vs_raytrace.py --save")
    ap.add_argument("--out", default=str(ROOT / "docs"))
    args = ap.parse_args()
    torch.set_num_threads(1)
    with open(args.load, "rb") as fh:
        saved = pickle.load(fh)
    t0 = time.perf_counter()
    rows = run(saved)
    out = write_report(args.out, "shadowing_mean.md", report(rows, Path(args.load).name, time.perf_counter() - t0))
    figure(rows, out)


if __name__ == "__main__":
    main()

"""Accuracy of the textured table render against per-pixel evaluation, from grazing to straight down.

The table method reads each sea pixel's texture from a volume computed at nodes (``renderer.texture.TextureTable``);
``method="direct"`` evaluates the two-scale model at every pixel. This sweeps the view from grazing
to nadir (pitch −1° … −90°, 30° field of view, 24×32 pixels), two heights (20 and 300 m), three
winds (3, 8, 15 m/s), float32 and float64, one realization each (seed 12, t = 1.5 s, whitecaps off
so that only the texture differs), and reports the largest |table − direct| over the sea pixels in
kelvin (brightness temperature), beside the texture's own standard deviation (direct − expectation
image). Writes ``texture_accuracy.md`` and ``texture_accuracy.png`` to ``--out``.

Usage:
    python pipelines/texture_accuracy.py [--out docs]
"""

from __future__ import annotations

import argparse
import datetime as dt
import sys
import warnings
from pathlib import Path

import torch

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _report import pyplot, write_report  # noqa: E402

import roughsea_torch as rs  # noqa: E402

PITCHES = (-90.0, -70.0, -45.0, -20.0, -8.0, -3.0, -1.0)
ALTITUDES = (20.0, 300.0)
WINDS = (3.0, 8.0, 15.0)


def one(dtype: torch.dtype, altitude: float, pitch: float, wind: float) -> tuple[float, float]:
    """(max |table − direct| [K], texture std [K]) over the sea pixels of one scene."""
    cams = rs.make_camera(24, 32, hfov_deg=30.0, altitude_m=altitude, pitch_deg=pitch, dtype=dtype)

    def scene(seed):
        return rs.SeaScene(wind_speed=torch.tensor(wind, dtype=dtype), sea_temperature=290.0, wind_direction=0.3,
                           seed=seed, time_s=1.5, foam=0.0)

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the slope-scaling warning of light winds
        table, direct = (rs.render(cams, scene(12), method=m, output="brightness_temperature")[0, 0].double()
                         for m in ("table", "direct"))
    mean = rs.render(cams, scene(None), output="brightness_temperature")[0, 0].double()
    sea = rs.view_geometry(cams).is_sea[0]
    return float((table - direct)[sea].abs().max()), float((direct - mean)[sea].std())


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default="docs")
    args = ap.parse_args()
    rows = []
    for dtype in (torch.float64, torch.float32):
        for alt in ALTITUDES:
            for pitch in PITCHES:
                for wind in WINDS:
                    err, std = one(dtype, alt, pitch, wind)
                    rows.append((str(dtype).replace("torch.", ""), alt, pitch, wind, err, std))
                    print(f"{rows[-1][0]} {alt:5.0f} m pitch {pitch:5.0f} wind {wind:4.0f}: "
                          f"max |table - direct| {err:.4f} K, texture std {std:.4f} K", file=sys.stderr)
    big = [r for r in rows if r[5] > 1e-3]
    lines = [f"# Textured table render against per-pixel evaluation ({dt.date.today()}, torch {torch.__version__})", "",
             "24×32 pixels, 30° field of view, one realization (seed 12, t = 1.5 s, whitecaps off), LWIR, "
             "README default sky; brightness temperature. `python pipelines/texture_accuracy.py`", "",
             f"- Worst error, grazing (pitch ≥ −20°): {max(r[4] for r in rows if r[2] >= -20):.4f} K; "
             f"steep (pitch ≤ −45°): {max(r[4] for r in rows if r[2] <= -45):.4f} K.",
             f"- Where the texture's standard deviation exceeds 1 mK ({len(big)} of {len(rows)} scenes), the "
             f"worst error is {max(r[4] / r[5] for r in big):.3f} of it.", "",
             "| dtype | altitude [m] | pitch [deg] | wind [m/s] | max abs(table − direct) [K] | texture std [K] |",
             "|---|---:|---:|---:|---:|---:|"]
    lines += [f"| {d} | {a:.0f} | {p:.0f} | {w:.0f} | {e:.4f} | {s:.4f} |" for d, a, p, w, e, s in rows]
    out = write_report(args.out, "texture_accuracy.md", "\n".join(lines) + "\n")
    plt = pyplot()
    if plt is None:
        return
    fig, axes = plt.subplots(1, 2, figsize=(10, 3.8), sharey=True)
    for ax, alt in zip(axes, ALTITUDES):
        for i, wind in enumerate(WINDS):
            sel = [r for r in rows if r[0] == "float64" and r[1] == alt and r[3] == wind]
            x = [-r[2] for r in sel]
            ax.semilogy(x, [max(r[4], 1e-6) for r in sel], "o-", color=f"C{i}", label=f"error, {wind:.0f} m/s")
            ax.semilogy(x, [max(r[5], 1e-6) for r in sel], "--", color=f"C{i}", alpha=0.6,
                        label=f"texture std, {wind:.0f} m/s")
        ax.set_xlabel("camera pitch below the horizon [deg]")
        ax.set_title(f"{alt:.0f} m up, float64")
        ax.grid(alpha=0.3)
    axes[0].set_ylabel("kelvin")
    axes[1].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(out / "texture_accuracy.png", dpi=110)


if __name__ == "__main__":
    main()

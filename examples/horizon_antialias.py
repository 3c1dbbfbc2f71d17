"""The horizon under roll, by centre rays and by area: a zoom on the horizon of a 20 m high LWIR
camera (default scene: LOWTRAN7 midlatitude-summer sky and path, 290 K sea, 8 m/s) rolled 4°,
rendered with ``horizon="centre"`` (each pixel sea or sky by its centre ray: a staircase) and
``horizon="area"`` (the default: a pixel the horizon crosses reads the area-weighted mix of its sea
and sky parts), their difference, and the mean over the zoom's rows of each column (a staircase
is a saw tooth; the area mix follows the horizon's sub-pixel position).

Writes ``horizon_antialias.png`` to ``--out`` and prints the largest column-to-column step of the
column means for both.

Usage:
    python examples/horizon_antialias.py [--out outputs/examples]
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path

import numpy as np
import torch

import roughsea_torch as rs
from _common import plt


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", type=Path, default=Path(__file__).resolve().parents[1] / "outputs" / "examples")
    args = ap.parse_args()
    torch.set_num_threads(1)
    h, H, W, roll = 20.0, 240, 320, 4.0
    dip = math.degrees(math.acos(rs.EARTH_RADIUS_M / (rs.EARTH_RADIUS_M + h)))
    cams = rs.make_camera(H, W, hfov_deg=16.0, altitude_m=h, pitch_deg=-dip, roll_deg=roll, dtype=torch.float64)
    scene = rs.SeaScene(wind_speed=8.0, sea_temperature=290.0)
    imgs = {m: rs.render(cams, scene, output="brightness_temperature", horizon=m)[0, 0] for m in ("centre", "area")}
    r0, c0, rows, cols = H // 2 - 6, W // 2 - 30, 12, 60
    crop = {m: im[r0:r0 + rows, c0:c0 + cols].numpy() for m, im in imgs.items()}  # matplotlib takes numpy arrays
    vmin = float(min(c.min() for c in crop.values()))
    vmax = float(max(c.max() for c in crop.values()))
    fig, axes = plt.subplots(4, 1, figsize=(8.0, 9.0), gridspec_kw={"height_ratios": [1, 1, 1, 1.3]})
    for ax, (m, title) in zip(axes[:2], [("centre", 'horizon="centre": each pixel by its centre ray'),
                                        ("area", 'horizon="area" (default): area-weighted pixels on the horizon')]):
        im = ax.imshow(crop[m], cmap="inferno", vmin=vmin, vmax=vmax, interpolation="nearest")
        ax.set_title(title, fontsize=9)
        ax.set_xticks([])
        ax.set_yticks([])
        fig.colorbar(im, ax=ax, label="K", fraction=0.03)
    diff = crop["area"] - crop["centre"]
    lim = float(abs(diff).max())
    im = axes[2].imshow(diff, cmap="RdBu_r", vmin=-lim, vmax=lim, interpolation="nearest")
    axes[2].set_title("area − centre [K] (zero off the horizon, bit for bit)", fontsize=9)
    axes[2].set_xticks([])
    axes[2].set_yticks([])
    fig.colorbar(im, ax=axes[2], label="K", fraction=0.03)
    x = range(c0, c0 + cols)
    for m, style in (("centre", "-o"), ("area", "-s")):
        means = crop[m].mean(0)
        axes[3].plot(x, means, style, ms=3, lw=1, label=f'horizon="{m}"')
        print(f'horizon="{m}": largest step of the column means {float(abs(np.diff(means)).max()):.3f} K')
    axes[3].set_xlabel("image column")
    axes[3].set_ylabel(f"mean of {rows} rows [K]")
    axes[3].set_title(f"column means across the horizon, roll {roll:g}° (0.07 row a column)", fontsize=9)
    axes[3].legend(fontsize=8)
    fig.suptitle(f"LWIR horizon, {h:g} m, 290 K sea, 8 m/s, midlatitude summer: zoom {rows}×{cols} px", fontsize=10)
    fig.tight_layout()
    args.out.mkdir(parents=True, exist_ok=True)
    fig.savefig(args.out / "horizon_antialias.png", dpi=110)
    print(f"wrote {args.out}/horizon_antialias.png")


if __name__ == "__main__":
    main()

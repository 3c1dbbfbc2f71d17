"""One camera, one sea temperature, winds from 0 to 30 m/s: how roughness changes the picture.

Writes ``wind_sweep.png`` (brightness temperature images on one colour scale) and
``wind_sweep_profile.png`` (the central column's brightness temperature vs image row) to ``--out``.

The 30 m/s image is past the whitecap law's range: the package warns ("wind_speed above 25 m/s ...")
and holds the whitecap fraction at its 25 m/s value; the warning is expected.

Usage:
    python examples/wind_sweep.py [--out outputs/examples] [--sky midlatitude_summer]
"""

from __future__ import annotations

import argparse
from pathlib import Path

import matplotlib.pyplot as plt
import torch

import roughsea_torch as rs
from _common import save_grid


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", type=Path, default=Path(__file__).resolve().parents[1] / "outputs" / "examples")
    ap.add_argument("--sky", default="midlatitude_summer")
    args = ap.parse_args()
    winds = torch.tensor([0.0, 2.0, 5.0, 10.0, 15.0, 20.0, 25.0, 30.0])
    B = len(winds)
    cams = rs.make_camera(256, 320, hfov_deg=30.0, altitude_m=25.0, pitch_deg=-4.0, yaw_deg=0.0, batch_size=B)
    scene = rs.SeaScene(wind_speed=winds, wind_direction=0.0, sea_temperature=293.0, sky=args.sky)
    bt = rs.render(cams, scene, output="brightness_temperature")
    save_grid(bt, [f"wind {w:.0f} m/s" for w in winds.tolist()], args.out / "wind_sweep.png",
              label="brightness temperature [K]", shared_scale=True)
    fig, ax = plt.subplots(figsize=(6, 4))
    for w, img in zip(winds.tolist(), bt[:, 0, :, 160]):
        ax.plot(img.numpy(), label=f"{w:.0f} m/s")
    ax.set_xlabel("image row (0 = top)")
    ax.set_ylabel("brightness temperature [K]")
    ax.set_title("central column, sea 293 K, 25 m, pitch −4°")
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(args.out / "wind_sweep_profile.png", dpi=110)
    print(f"wrote {args.out}/wind_sweep.png and wind_sweep_profile.png")


if __name__ == "__main__":
    main()

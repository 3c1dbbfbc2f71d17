"""Autograd sensitivity maps: how each pixel's brightness temperature moves with wind and sea temperature.

``rs.pixel_derivative`` (a Jacobian–vector product through geometry, model tables and
grid_sample) gives, per pixel, dT_b/dW [K per m/s] and dT_b/dT_sea [K/K], plus dT_b/dpitch [K/deg]. Writes ``sensitivity_maps.png`` to
``--out``. The three maps show the sea pixels only (the sky is left blank), each on the colour range of
the sea more than ~2° below the horizon (0.5–99.5 % of the sea pixels with sea 20 rows above them): within
~2° of the horizon dT_b/dpitch climbs to ~27 K/deg on the horizon's row and clips to its bar's top;
below, it is about −0.13 K/deg, with a pixel-scale speckle of ~0.004 K/deg rms (float32 and float64 alike)
that a central difference of ±0.05° does not show: the derivative of the renderer's interpolated tables.

Usage:
    python examples/sensitivity_maps.py [--out outputs/examples] [--sky midlatitude_summer]
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path

import torch

import roughsea_torch as rs
from _common import colour_range, save_grid


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", type=Path, default=Path(__file__).resolve().parents[1] / "outputs" / "examples")
    ap.add_argument("--sky", default="midlatitude_summer")
    args = ap.parse_args()
    wind = torch.tensor(8.0, requires_grad=True)
    t_sea = torch.tensor(291.0, requires_grad=True)
    pitch = torch.tensor(-3.0, requires_grad=True)
    cams = rs.make_camera(192, 256, hfov_deg=30.0, altitude_m=20.0, pitch_deg=pitch)
    scene = rs.SeaScene(wind_speed=wind, wind_direction=0.6, sea_temperature=t_sea, sky=args.sky)
    bt = rs.render(cams, scene, output="brightness_temperature")
    maps = [rs.pixel_derivative(bt, x) for x in (wind, t_sea, pitch)]
    sea = rs.view_geometry(cams).is_sea[:, None]
    out = [bt.detach()] + [torch.where(sea, m, torch.tensor(math.nan)) for m in maps]
    k = 20  # rows, 2.3° at 0.117° a row: the horizon's steep rows are left out of the maps' colour ranges
    below = sea.clone()
    below[..., k:, :] &= sea[..., :-k, :]
    below[..., :k, :] = False
    ranges = [colour_range(out[0])] + [colour_range(m[below]) for m in maps]
    save_grid(torch.cat(out), ["brightness temperature [K]", "dT_b / d wind [K per m/s]", "dT_b / dT_sea [K/K]",
                               "dT_b / d pitch [K per deg]"], args.out / "sensitivity_maps.png", label="", ncols=2,
              cmap="coolwarm", ranges=ranges, note="each panel has its own colour range: four different quantities; "
                                                   "maps' ranges: sea > 2° below the horizon")
    print(f"wrote {args.out}/sensitivity_maps.png")


if __name__ == "__main__":
    main()

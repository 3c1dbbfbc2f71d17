"""The same sea seen from a mast (20 m) and from an aircraft (2 km), looking at the horizon.

From 20 m the horizon is 0.14° below the horizontal and 16 km away; from 2 km it is 1.44° down
and 160 km away, and every sea pixel is seen at a steeper angle. Writes ``altitude_compare.png``
(brightness temperature, one colour range) and ``altitude_compare_range.png`` (slant range, km, each
panel its own colour range: 16 km and 160 km horizons) to ``--out``.

Usage:
    python examples/altitude_compare.py [--out outputs/examples] [--sky midlatitude_summer]
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path

import torch

import roughsea_torch as rs
from _common import save_grid


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", type=Path, default=Path(__file__).resolve().parents[1] / "outputs" / "examples")
    ap.add_argument("--sky", default="midlatitude_summer")
    args = ap.parse_args()
    alt = torch.tensor([20.0, 2000.0])
    dip = torch.rad2deg(torch.sqrt(2 * alt / rs.EARTH_RADIUS_M))
    cams = rs.make_camera(384, 480, hfov_deg=20.0, altitude_m=alt, pitch_deg=-dip - 5.0)
    scene = rs.SeaScene(wind_speed=8.0, wind_direction=0.5, sea_temperature=290.0, sky=args.sky)
    geom = rs.view_geometry(cams)
    bt = rs.render(cams, scene, output="brightness_temperature", geometry=geom)
    titles = [f"altitude {a:.0f} m (horizon dip {d:.2f}°)" for a, d in zip(alt.tolist(), dip.tolist())]
    save_grid(bt, titles, args.out / "altitude_compare.png", label="brightness temperature [K]", ncols=2)
    rng = torch.where(geom.is_sea, geom.range_m / 1000.0, torch.tensor(math.nan))[:, None]
    save_grid(rng, titles, args.out / "altitude_compare_range.png", label="slant range [km]", ncols=2, cmap="viridis",
              shared_scale=False)
    print(f"wrote {args.out}/altitude_compare.png and altitude_compare_range.png")


if __name__ == "__main__":
    main()

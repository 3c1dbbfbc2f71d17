"""The image across the horizon, for sensors at a few altitudes: brightness temperature of the
centre column against the elevation of each pixel's ray, sea below the depressed horizon and sky
above it, in the default scene (LOWTRAN7 midlatitude summer, LWIR, path on).

Sea pixels near the horizon see the sea through the lowest air (τ · R_a + L_path at a range of up
to √(2hR)); sky pixels see the sky from the sensor's altitude, and the rays between the horizon dip
and the local horizontal cross the same lowest air as the sea's horizon row, so the image is
continuous across the horizon. Writes ``horizon_profile.png`` to ``--out`` and prints the jump
across the horizon (last sea pixel to first sky pixel) for each altitude.

Usage:
    python examples/horizon_profile.py [--out outputs/examples]
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path

import torch

import roughsea_torch as rs
from _common import plt


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", type=Path, default=Path(__file__).resolve().parents[1] / "outputs" / "examples")
    args = ap.parse_args()
    alts = [5.0, 20.0, 100.0, 1000.0, 5000.0]
    H, W, vfov = 1024, 8, 4.0  # 0.004° a row
    fig, ax = plt.subplots(figsize=(7.5, 4.2))
    for h in alts:
        dip = math.degrees(math.asin(math.sqrt(h * (2 * rs.EARTH_RADIUS_M + h)) / (rs.EARTH_RADIUS_M + h)))
        hfov = 2 * math.degrees(math.atan(math.tan(math.radians(vfov / 2)) * W / H))
        cams = rs.make_camera(H, W, hfov_deg=hfov, altitude_m=h, pitch_deg=-dip, dtype=torch.float64)
        geom = rs.view_geometry(cams)
        scene = rs.SeaScene(wind_speed=6.0, sea_temperature=290.0)
        bt = rs.render(cams, scene, output="brightness_temperature", geometry=geom)[0, 0, :, W // 2]
        sea = geom.is_sea[0, :, W // 2]
        f = cams.intrinsics[0, 1, 1].item()
        elev = -dip - torch.rad2deg(torch.atan((torch.arange(H, dtype=torch.float64) - (H - 1) / 2) / f))
        ax.plot(elev + dip, bt, lw=1.2, label=f"{h:g} m (dip {dip:.2f}°)")
        k = int(sea.nonzero()[0])  # first sea row from the top
        print(f"altitude {h:7.1f} m: last sky pixel {bt[k - 1]:.3f} K, first sea pixel {bt[k]:.3f} K, "
              f"jump {bt[k] - bt[k - 1]:+.3f} K")
    ax.axvline(0.0, color="k", lw=0.6)
    ax.set_xlim(-1.5, 1.5)
    ax.set_xlabel("elevation of the ray above the depressed horizon [deg]")
    ax.set_ylabel("brightness temperature [K]")
    ax.set_title("LWIR across the horizon, midlatitude summer, 290 K sea, 6 m/s")
    ax.legend(fontsize=8)
    fig.tight_layout()
    args.out.mkdir(parents=True, exist_ok=True)
    fig.savefig(args.out / "horizon_profile.png", dpi=110)
    print(f"wrote {args.out}/horizon_profile.png")


if __name__ == "__main__":
    main()

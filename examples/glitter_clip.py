"""Sun glitter in an MWIR daytime clip: the glint of a textured sea as the smooth expectation and as
glitter (``TableSize(glitter=True)``, :mod:`roughsea_torch.glitter`).

Writes ``glitter_clip.png`` to ``--out``: a 10 m mast looking 6° down towards the sun, 15° above the
horizon straight ahead, wind 8 m/s, MWIR (3–5 µm), E_sun = 12 W m⁻², a 640-pixel-wide camera with a
30° field of view cropped to the glint path (the central 96 × 144 pixels of its 512 × 640 image:
the same pixels, 0.82 mrad); frames 0.1 s apart. Top row: the glint as the expectation over each
pixel's unresolved facets; bottom row: the same frames with glitter. One colour range for the figure.

Usage:
    python examples/glitter_clip.py [--out docs] [--frames 3] [--dt 0.1]
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
    ap.add_argument("--frames", type=int, default=3)
    ap.add_argument("--dt", type=float, default=0.1)
    args = ap.parse_args()
    torch.set_num_threads(1)
    H, W = 96, 144  # the crop of a 512 × 640, 30° camera: same pixel size
    hfov = math.degrees(2 * math.atan(W / 640 * math.tan(math.radians(15.0))))
    cam = rs.make_camera(H, W, hfov_deg=hfov, altitude_m=10.0, pitch_deg=-6.0, yaw_deg=0.0)
    scene = rs.SeaScene(wind_speed=8.0, sea_temperature=290.0, band=rs.MWIR, seed=4, sun=rs.Sun(math.radians(75.0), 0.0, 12.0),
                        foam=False)
    times = [i * args.dt for i in range(args.frames)]
    rows = []
    for glitter in (False, True):
        clip = rs.render_clip(cam, scene, times, output="brightness_temperature", table=rs.TableSize(glitter=glitter))
        rows.append(clip[0])  # (T, 1, H, W)
    images = torch.cat(rows)
    titles = [f"{'glitter' if g else 'smooth glint (default)'}, t = {t:.2f} s" for g in (False, True) for t in times]
    lo = float(torch.quantile(images.flatten().float(), 0.005))
    hi = float(torch.quantile(rows[0].flatten().float(), 0.999))  # the smooth path's top: glitter spots clip to white
    save_grid(images, titles, args.out / "glitter_clip.png", label="brightness temperature [K]", ncols=args.frames,
              ranges=[(lo, hi)] * images.shape[0],
              note="MWIR, sun 15° up ahead, 8 m/s, 10 m mast; one colour range (glitter spots clip at its top)")
    print(f"wrote {args.out / 'glitter_clip.png'}")


if __name__ == "__main__":
    main()

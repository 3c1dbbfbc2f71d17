"""Sun glitter in an MWIR daytime clip: the glint of a textured sea as the smooth expectation and as
glitter (``TableSize(glitter=True)``, :mod:`roughsea_torch.glitter`), in the glint path and at its edge.

Writes ``glitter_clip.png`` to ``--out``: a 10 m mast looking 6° down, the sun 15° above the horizon
straight ahead, wind 8 m/s, MWIR (3–5 µm), E_sun = 12 W m⁻², a 640-pixel-wide camera with a 30° field
of view cropped to 96 × 144 pixels (0.82 mrad, 70–150 m range); frames 0.1 s apart. Rows 1–2: the
crop looking at the sun (the path's core, a few glitter spots per pixel), smooth and with glitter, one
colour range; rows 3–4: the crop turned 11° to the side (the path's edge, well under one spot per
pixel: sparse flashes), smooth and with glitter, their own colour range. The glitter's draws are tied
to the sea points the pixels see (``docs/glitter.md``).

Usage:
    python examples/glitter_clip.py [--out outputs/examples] [--frames 3] [--dt 0.1]

(``--out docs`` rewrites the repository's ``docs/glitter_clip.png``)
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path

import torch

import roughsea_torch as rs
from _common import save_grid

EDGE_YAW_DEG = 11.0


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", type=Path, default=Path(__file__).resolve().parents[1] / "outputs" / "examples")
    ap.add_argument("--frames", type=int, default=3)
    ap.add_argument("--dt", type=float, default=0.1)
    args = ap.parse_args()
    torch.set_num_threads(1)
    H, W = 96, 144  # the crop of a 512 × 640, 30° camera: same pixel size
    hfov = math.degrees(2 * math.atan(W / 640 * math.tan(math.radians(15.0))))
    scene = rs.SeaScene(wind_speed=8.0, sea_temperature=290.0, band=rs.MWIR, seed=4, sun=rs.Sun(math.radians(75.0), 0.0, 12.0),
                        foam=False)
    times = [i * args.dt for i in range(args.frames)]
    rows, titles, ranges = [], [], []
    for yaw, where in ((0.0, "sun ahead"), (EDGE_YAW_DEG, f"{EDGE_YAW_DEG:g}° aside")):
        cam = rs.make_camera(H, W, hfov_deg=hfov, altitude_m=10.0, pitch_deg=-6.0, yaw_deg=yaw)
        pair = [rs.render_clip(cam, scene, times, output="brightness_temperature", table=rs.TableSize(glitter=g))[0]
                for g in (False, True)]  # (T, 1, H, W) each
        lo = float(torch.quantile(torch.cat(pair).flatten().float(), 0.005))
        # in the core the smooth path's top (glitter spots clip to white); at the edge the flashes' own top
        hi = float(torch.quantile((pair[0] if yaw == 0.0 else pair[1]).flatten().float(), 0.999))
        for g, clip in zip((False, True), pair):
            rows.append(clip)
            titles += [f"{where}, {'glitter' if g else 'smooth (default)'}, t = {t:.2f} s" for t in times]
            ranges += [(lo, hi)] * len(times)
    images = torch.cat(rows)
    save_grid(images, titles, args.out / "glitter_clip.png", label="brightness temperature [K]", ncols=args.frames,
              ranges=ranges, note="MWIR, sun 15° up, 8 m/s, 10 m mast; rows 1–2 one colour range (spots clip at its top), "
                                  "rows 3–4 another")
    print(f"wrote {args.out / 'glitter_clip.png'}")


if __name__ == "__main__":
    main()

"""Textured seas: near-range realizations across winds, and a clip from a moving mast.

Writes to ``--out``:

- ``textured_winds.png``: for winds of 2, 5, 10 and 15 m/s, the expectation image (top row) and one
  realization of the same scene (``SeaScene(seed=...)``, bottom row): LWIR, midlatitude-summer
  LOWTRAN7 sky and path, a camera 15 m above the sea looking 8° down (ranges 60 m to the horizon),
  whitecaps on the crests (the default); one colour scale per wind, the 0.5–99.5 % range of the sea
  pixels of both images;
- ``textured_clip.gif``: a 4 s clip at 10 frames/s of one realization seen from a mast that
  pitches ±1° (6 s period), rolls ±2° (9 s) and heaves ±0.5 m (``rs.PlatformMotion``), grey scale
  fixed over the clip;
- ``textured_clip_frames.png``: four of its frames.

Usage:
    python examples/textured_sea.py [--out outputs/examples] [--height 256] [--width 320]  (default: the repository's)
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np
import torch

import roughsea_torch as rs
from _common import save_grid


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", type=Path, default=Path(__file__).resolve().parents[1] / "outputs" / "examples")
    ap.add_argument("--height", type=int, default=256)
    ap.add_argument("--width", type=int, default=320)
    ap.add_argument("--frames", type=int, default=40)
    ap.add_argument("--fps", type=float, default=10.0)
    args = ap.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)

    winds = torch.tensor([2.0, 5.0, 10.0, 15.0])
    cams = rs.make_camera(args.height, args.width, hfov_deg=20.0, altitude_m=15.0, pitch_deg=-8.0, batch_size=4)
    mean = rs.render(cams, rs.SeaScene(wind_speed=winds, sea_temperature=290.0), output="brightness_temperature")
    t0 = time.perf_counter()
    tex = rs.render(cams, rs.SeaScene(wind_speed=winds, sea_temperature=290.0, seed=[1, 2, 3, 4], time_s=0.0),
                    output="brightness_temperature")
    print(f"4 textured {args.height}x{args.width} images in {time.perf_counter() - t0:.2f} s")
    titles = [f"expectation, W = {w:g} m/s" for w in winds.tolist()] + [f"realization, W = {w:g} m/s" for w in winds.tolist()]
    # one colour scale per wind, shared by the expectation and the realization: the 0.5–99.5 % range of
    # the sea pixels of both (the horizon's bright rows and the darkest whitecaps clip to its ends)
    sea = rs.view_geometry(cams).is_sea  # (B, H, W)
    ranges = []
    for i in range(len(winds)):
        v = torch.cat([mean[i, 0][sea[i]], tex[i, 0][sea[i]]])
        ranges.append((float(v.quantile(0.005)), float(v.quantile(0.995))))
    save_grid(torch.cat([mean, tex]), titles, args.out / "textured_winds.png", label="brightness temperature [K]",
              ranges=ranges + ranges, note="each wind (column) has its own colour range, shared by its expectation "
                                          "image and its realization (0.5–99.5 % of their sea pixels)")

    motion = rs.PlatformMotion(height=args.height // 2, width=args.width // 2, hfov_deg=20.0, altitude_m=15.0,
                               pitch_deg=-5.0, pitch_amplitude_deg=1.0, roll_amplitude_deg=2.0, heave_amplitude_m=0.5)
    times = torch.arange(args.frames) / args.fps
    t0 = time.perf_counter()
    clip = rs.render_clip(motion, rs.SeaScene(wind_speed=8.0, sea_temperature=290.0, seed=7), times,
                          output="brightness_temperature", progress=True)[0, :, 0]  # (T, H, W)
    print(f"{args.frames} frames in {time.perf_counter() - t0:.2f} s")
    lo, hi = float(clip.quantile(0.01)), float(clip.quantile(0.99))
    from PIL import Image

    frames = [Image.fromarray((255 * ((f - lo) / (hi - lo)).clamp(0, 1)).to(torch.uint8).numpy()) for f in clip]
    frames[0].save(args.out / "textured_clip.gif", save_all=True, append_images=frames[1:],
                   duration=int(1000 / args.fps), loop=0)
    pick = np.linspace(0, args.frames - 1, 4).round().astype(int)
    save_grid(clip[pick][:, None], [f"t = {float(times[i]):.1f} s" for i in pick], args.out / "textured_clip_frames.png",
              label="brightness temperature [K]")
    print(f"wrote {args.out}/textured_winds.png, textured_clip.gif, textured_clip_frames.png")


if __name__ == "__main__":
    main()

"""The main job: render a batch of infrared sea backgrounds on the built-in default scene.

Eight 512×640 LWIR (8–12 µm) images, each with its own wind, wind direction, sea temperature (air − sea
in [−3, 1] K, the atmosphere's surface air) and camera pose, under the shipped LOWTRAN7
midlatitude-summer sky, each a textured sea realization (wave clutter; ``--no-texture`` renders the
expectation images, the mean over the slope statistics). Writes to ``--out``:

- ``grid_brightness_temperature.png``: the batch as a picture grid (brightness temperature, K), one
  colour range for all;
- ``grid_sea_detail.png``: the same, each panel's colour range from its lower half (sea: the clutter
  shows; the sky clips to either end of the bar);
- ``image_XX.png``: each image as a 16-bit grayscale PNG, linear in brightness temperature between
  the ``bt_lo`` and ``bt_hi`` of ``metadata.json``;
- ``metadata.json``: every parameter that made each image.

Usage:
    python examples/render_default.py [--out outputs/default] [--batch 8] [--height 512] [--width 640]

(the default ``--out`` is the repository's ``outputs/default``, from whatever directory it runs)
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import torch

import roughsea_torch as rs
from _common import colour_range, save_grid, save_png16


def default_batch(batch: int, seed: int = 0, air_temperature: float | None = None) -> dict[str, torch.Tensor]:
    """The batch's parameters; with the atmosphere's surface ``air_temperature`` [K] the sea is drawn
    within [−1, +3] K of it (air − sea in [−3, 1] K, as over the open sea), else in [285, 300] K."""
    g = torch.Generator().manual_seed(seed)

    def u(lo: float, hi: float) -> torch.Tensor:
        return lo + (hi - lo) * torch.rand(batch, generator=g)

    return dict(
        wind_speed=u(1.0, 20.0), wind_direction=u(-3.14159, 3.14159),
        sea_temperature=u(285.0, 300.0) if air_temperature is None else air_temperature - u(-3.0, 1.0),
        altitude_m=torch.exp(u(2.3, 6.2)),  # 10 m … 500 m
        pitch_deg=u(-8.0, -1.0), yaw_deg=u(-180.0, 180.0), roll_deg=u(-3.0, 3.0),
    )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", type=Path, default=Path(__file__).resolve().parents[1] / "outputs" / "default")
    ap.add_argument("--batch", type=int, default=8)
    ap.add_argument("--height", type=int, default=512)
    ap.add_argument("--width", type=int, default=640)
    ap.add_argument("--hfov", type=float, default=30.0, help="horizontal field of view [deg]")
    ap.add_argument("--sky", default="midlatitude_summer", help="shipped atmosphere name, or a constant radiance")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--texture", action=argparse.BooleanOptionalAction, default=True,
                    help="textured sea realizations (default) or expectation images (--no-texture)")
    args = ap.parse_args()

    try:
        sky = float(args.sky)  # a constant sky radiance [W m-2 sr-1]
    except ValueError:
        sky = args.sky  # a shipped atmosphere
    air = rs.atmosphere.surface_air_temperature(sky) if isinstance(sky, str) else None  # [K], the atmosphere's
    p = default_batch(args.batch, args.seed, air)
    cams = rs.make_camera(args.height, args.width, hfov_deg=args.hfov, altitude_m=p["altitude_m"],
                          pitch_deg=p["pitch_deg"], yaw_deg=p["yaw_deg"], roll_deg=p["roll_deg"])
    wave_seeds = [1000 * args.seed + i for i in range(args.batch)] if args.texture else None
    scene = rs.SeaScene(wind_speed=p["wind_speed"], wind_direction=p["wind_direction"],
                        sea_temperature=p["sea_temperature"], sky=sky, seed=wave_seeds)
    t0 = time.perf_counter()
    bt = rs.render(cams, scene, output="brightness_temperature")
    dt = time.perf_counter() - t0
    print(f"rendered {args.batch} images {args.height}x{args.width} in {dt:.2f} s")

    titles = [
        f"W={w:.1f} m/s T_sea={t:.1f} K h={h:.0f} m pitch={pt:.1f}°"
        for w, t, h, pt in zip(p["wind_speed"].tolist(), p["sea_temperature"].tolist(),
                               p["altitude_m"].tolist(), p["pitch_deg"].tolist())
    ]
    args.out.mkdir(parents=True, exist_ok=True)
    save_grid(bt, titles, args.out / "grid_brightness_temperature.png", label="brightness temperature [K]")
    sea = [colour_range(img[0, args.height // 2:], (1.0, 99.0)) for img in bt]  # the lower half: sea at these pitches
    save_grid(bt, titles, args.out / "grid_sea_detail.png", label="brightness temperature [K]", ranges=sea,
              note="each panel's colour range from its lower half (1–99 %): the sea's clutter; the sky clips")
    lo, hi = 250.0, 310.0
    res = scene.resolved(args.batch, torch.float32, torch.device("cpu"))
    meta = {"roughsea_torch": rs.__version__, "band_m": [8e-6, 12e-6], "sky": args.sky, "path": scene.path is not None,
            "foam": "auto (Monahan's whitecap fraction on the crests)", "earth_radius_m": rs.EARTH_RADIUS_M,
            "table": repr(rs.TableSize()), "image_size": [args.height, args.width], "hfov_deg": args.hfov,
            "bt_lo": lo, "bt_hi": hi, "render_seconds": dt, "images": []}
    for i in range(args.batch):
        save_png16(bt[i, 0], args.out / f"image_{i:02d}.png", lo, hi)
        meta["images"].append({k: float(v[i]) for k, v in p.items()} | {"file": f"image_{i:02d}.png"}
                              | {"whitecap_fraction": float(res.foam[i]) if res.foam is not None else 0.0}
                              | ({"air_temperature": float(air)} if air is not None else {})
                              | ({"wave_seed": wave_seeds[i], "time_s": 0.0} if wave_seeds else {}))
    (args.out / "metadata.json").write_text(json.dumps(meta, indent=2))
    print(f"wrote {args.out}/grid_brightness_temperature.png, grid_sea_detail.png, {args.batch} 16-bit PNGs and metadata.json")


if __name__ == "__main__":
    main()

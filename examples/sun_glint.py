"""Daytime seas: the sun's glint in MWIR and LWIR.

Writes to ``--out``:

- ``sun_glint_scenes.png``: expectation images of a 20 m mast looking 3° down towards the sun, the
  sun 5°, 15° and 30° above the horizon straight ahead, wind 6 m/s, midlatitude-summer LOWTRAN7 sky
  and path; top row MWIR (3–5 µm), bottom row LWIR (8–12 µm). The direct solar irradiance at the
  surface and the scattered day sky are the atmosphere's LOWTRAN7 tables at each sun elevation (the
  scene's ``sun_zenith=``; e.g. MWIR 1.7, 4.5 and 6.5 W m⁻² at 5°, 15° and 30°), unless
  ``--mwir-irradiance`` / ``--lwir-irradiance`` [W m⁻², normal to the beam] fix one value for all;
- ``sun_glint_profile.png``: the glint radiance against view zenith in the sun's vertical plane,
  sun 20° above the horizon, MWIR, for winds of 2, 5, 10 and 15 m/s (``rs.glint_radiance``).

Usage:
    python examples/sun_glint.py [--out outputs/examples]  (default: the repository's, from any directory)
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path

import torch

import roughsea_torch as rs
from _common import colour_range, plt, save_grid


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", type=Path, default=Path(__file__).resolve().parents[1] / "outputs" / "examples")
    ap.add_argument("--height", type=int, default=256)
    ap.add_argument("--width", type=int, default=320)
    ap.add_argument("--mwir-irradiance", type=float, default=None, help="W m-2 (default: LOWTRAN7 by sun elevation)")
    ap.add_argument("--lwir-irradiance", type=float, default=None, help="W m-2 (default: LOWTRAN7 by sun elevation)")
    args = ap.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)

    elevations = [5.0, 15.0, 30.0]
    cams = rs.make_camera(args.height, args.width, hfov_deg=30.0, altitude_m=20.0, pitch_deg=-3.0, yaw_deg=0.0,
                          batch_size=len(elevations))
    zen = torch.tensor([math.radians(90.0 - e) for e in elevations])
    images, titles = [], []
    for band, name, e_sun in ((rs.MWIR, "MWIR", args.mwir_irradiance), (rs.LWIR, "LWIR", args.lwir_irradiance)):
        if e_sun is None:  # the atmosphere's own sun and day sky (world azimuth 0: straight ahead, +x)
            scene = rs.SeaScene(wind_speed=6.0, sea_temperature=290.0, band=band, sun_zenith=zen, sun_azimuth=0.0)
            e = rs.solar.load_solar_irradiance("midlatitude_summer", band)(zen.double())
        else:
            scene = rs.SeaScene(wind_speed=6.0, sea_temperature=290.0, band=band,
                                sun=rs.Sun(zenith=zen, azimuth=0.0, irradiance=e_sun))
            e = torch.full((len(elevations),), e_sun)
        images.append(rs.render(cams, scene, output="brightness_temperature"))
        titles += [f"{name}, sun {el:g}° up ahead, E = {float(ei):.2g} W/m²" for el, ei in zip(elevations, e)]
    # one colour range per band (row), 0.5–99.5 % of its pixels: the sun's disk (a few pixels, thousands of
    # kelvin in MWIR) clips to the bar's top instead of turning the sea and the glint black
    rows = [colour_range(im) for im in images]
    save_grid(torch.cat(images), titles, args.out / "sun_glint_scenes.png", label="brightness temperature [K]", ncols=3,
              ranges=[r for r in rows for _ in elevations], note="each band (row) has its own colour range, 0.5–99.5 % "
                                                                 "of its pixels (the sun's disk clips to the top)")

    th = torch.linspace(math.radians(50.0), math.radians(89.5), 300, dtype=torch.float64)
    e_mwir = args.mwir_irradiance if args.mwir_irradiance is not None else float(
        rs.solar.load_solar_irradiance("midlatitude_summer", rs.MWIR)(torch.tensor(math.radians(70.0), dtype=torch.float64)))
    sun = rs.Sun(math.radians(70.0), math.pi, e_mwir)  # LOS azimuth 0 faces a sun at azimuth π
    fig, ax = plt.subplots(figsize=(6, 3.6))
    for wind in (2.0, 5.0, 10.0, 15.0):
        g = rs.glint_radiance(th, 0.0, rs.SlopeStatistics.cox_munk(wind), band_index := 1.39 + 0.01j, sun)
        ax.semilogy(torch.rad2deg(th), g, label=f"{wind:g} m/s")
    ax.axvline(70.0, color="0.6", ls=":", lw=0.8)
    ax.set_xlabel("view zenith [deg] (sun's vertical plane, sun at 70° zenith)")
    ax.set_ylabel("glint radiance [W m⁻² sr⁻¹]")
    ax.set_title(f"MWIR glint, E_sun = {e_mwir:.2g} W/m² (LOWTRAN7 at 20° up), n = {band_index.real:g}", fontsize=9)
    ax.set_ylim(1e-3, None)
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(args.out / "sun_glint_profile.png", dpi=120)
    print(f"wrote {args.out}/sun_glint_scenes.png and sun_glint_profile.png")


if __name__ == "__main__":
    main()

"""The sky in renders (roughsea_torch.renderer.sky_terms): sky pixels see the sky along their ray
(from the camera's altitude, no warm line at the horizon), the scattered day sky in the sky pixels and
in the sea's reflection, the sun's disk in the sky."""

from __future__ import annotations

import math

import torch

import roughsea_torch as rs

from conftest import make_cams, make_scene


def test_the_suns_disk_in_the_sky_carries_its_irradiance():
    """A narrow camera looking at the sun 3° above the horizon: the disk's radiance summed over the
    sky pixels' solid angles is E_sun (1 %), and the table render equals the per-pixel one."""
    cams = make_cams(128, 160, hfov_deg=3.0, pitch_deg=3.0)
    sun = rs.Sun(math.radians(87.0), 0.0, 12.0)
    scene = make_scene(wind_speed=6.0, band=rs.MWIR, sun=sun)
    img = rs.render(cams, scene)
    night = rs.render(cams, make_scene(wind_speed=6.0, band=rs.MWIR))
    sky = ~rs.view_geometry(cams).is_sea[0]
    total = float(((img - night)[0, 0] * sky).sum()) / float(cams.fx[0]) ** 2  # pixel solid angle ≈ 1/f² here
    assert abs(total / 12.0 - 1) < 0.01
    direct = rs.render(cams, scene, method="direct")
    assert float(((img - direct) / direct).abs().max()) < 1e-5

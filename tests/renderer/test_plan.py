"""What a render decides before it starts (roughsea_torch.renderer.plan): the azimuth coordinate's
period and the node counts by day, and what a precomputed geometry cannot serve."""

from __future__ import annotations

import math

import pytest
import torch

import roughsea_torch as rs

from conftest import make_cams, make_scene


def test_sunny_scene_with_precomputed_geometry_is_a_clear_error():
    """The glint and the sun's disk are per pixel and need the cameras (the disk's size is the
    pixel's field of view): render(..., geometry=) of a sunny scene raises a ValueError that says
    so (it failed with an UnboundLocalError inside the renderer), and the cameras' render works."""
    cams = make_cams(8, 10, hfov_deg=20.0, pitch_deg=-4.0)
    scene = make_scene(wind_speed=5.0, sun=rs.Sun(math.radians(70.0), 0.0, 10.0))
    with pytest.raises(ValueError, match="geometry="):
        rs.render(cams, scene, geometry=rs.view_geometry(cams))
    assert bool(torch.isfinite(rs.render(cams, scene)).all())


@pytest.mark.parametrize("pitch", [-90.0, -80.0])
def test_day_sky_looking_straight_down_matches_per_pixel(pitch, dtype):
    """Under the LOWTRAN day sky the sea is not the same half a turn round (the scattered sky is
    brighter towards the sun), so the table's azimuth coordinate runs over 2π; it ran over π, and a
    camera looking down at the nadir (every azimuth in view) read the sky of the opposite azimuth
    over half the image: MWIR, 20 m up, 8 m/s, sun 34° from the zenith, 0.22–0.26 K off per-pixel
    evaluation (found in review). With every azimuth in view a render also takes twice the mean's
    azimuth nodes and four times the texture's (the aureole's structure spread over the whole turn;
    found by a second new-user trial, up to 0.025 K and 0.056 K without at 32×40). Four sun and wind
    azimuths: the expectation images within 0.015 K (5.4e-3 to 7.3e-3 measured), the textured seas
    within 0.03 K (1.0e-2 to 1.4e-2); the extra nodes planted away, all four cases fail."""
    cams = make_cams(pitch_deg=pitch, yaw_deg=torch.zeros(4), batch_size=4, dtype=dtype)
    for seed, bound in ((None, 0.015), ([1, 2, 3, 4], 0.03)):
        scene = make_scene(foam=0.0, band=rs.MWIR, sun_zenith=0.6, seed=seed,
                           sun_azimuth=torch.tensor([0.5, 1.6, 2.8, -2.0]),
                           wind_direction=torch.tensor([0.0, 1.0, -0.7, 2.5]))
        table, direct = (rs.render(cams, scene, method=m, output="brightness_temperature").double()
                         for m in ("table", "direct"))
        assert float((table - direct).abs().max()) < bound


def test_day_texture_looking_straight_down_with_a_low_sun_matches_per_pixel():
    """With every azimuth in view (nadir camera, 60° field of view) under the LOWTRAN day sky the plan
    takes four times the texture's azimuth nodes (the aureole's structure spread over the whole turn,
    make_plan / _day_nodes_for_every_azimuth). A low sun (74° from the zenith) and a high one (29°),
    the camera turned half round for the low one: the textured table render is within 0.03 K of
    per-pixel evaluation, the bound tests/test_sun.py asserts for a sun at 34° (0.012–0.013 K here)."""
    dt = torch.float64
    cams = rs.make_camera(16, 16, hfov_deg=60.0, altitude_m=20.0, pitch_deg=-90.0,
                          yaw_deg=torch.tensor([10.0, 200.0], dtype=dt), batch_size=2, dtype=dt)
    scene = rs.SeaScene(wind_speed=8.0, sea_temperature=290.0, band=rs.MWIR, sun_zenith=torch.tensor([0.5, 1.3], dtype=dt),
                        sun_azimuth=torch.tensor([0.3, 2.5], dtype=dt), seed=[5, 6])
    table, direct = (rs.render(cams, scene, method=m, output="brightness_temperature") for m in ("table", "direct"))
    assert float((table - direct).abs().max()) < 0.03

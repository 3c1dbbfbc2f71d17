"""roughsea_torch.renderer.plan: the table layout a render decides once (node counts, coordinates)."""

from __future__ import annotations

import torch

import roughsea_torch as rs


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

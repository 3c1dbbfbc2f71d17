"""roughsea_torch.renderer.texture: the textured sea's volume against per-pixel evaluation, for the
scene options the texture's table must carry (tests/test_clutter.py covers the default scene)."""

from __future__ import annotations

import torch

import roughsea_torch as rs


def test_textured_table_matches_per_pixel_evaluation_with_an_air_temperature():
    """A named atmosphere with its air temperature raised 6 K (the sky and path radiances scaled by
    B(T_air)/B(T_atm), scenes.md): the texture volume's reflected sky carries the same scale as the
    per-pixel evaluation (method='direct'), to the texture table's accuracy: within 1.5 % of the
    texture's own amplitude and 3e-4 of the radiance (tests/test_clutter.py's bounds)."""
    cams = rs.make_camera(24, 16, hfov_deg=12.0, altitude_m=10.0, pitch_deg=-6.0, batch_size=2, dtype=torch.float64)

    def scene(seed):
        return rs.SeaScene(wind_speed=8.0, sea_temperature=290.0, sky="midlatitude_summer", path=False,
                           air_temperature=torch.tensor([300.0, 291.0], dtype=torch.float64), seed=seed,
                           time_s=torch.tensor([0.0, 2.0], dtype=torch.float64))

    table, direct = (rs.render(cams, scene([11, 12]), method=m) for m in ("table", "direct"))
    mean = rs.render(cams, scene(None))
    amp = (direct - mean).abs().max()
    err = (table - direct).abs()
    assert float(amp / mean.max()) > 3e-3
    assert float(err.max()) < 0.015 * float(amp)
    assert float(err.max() / direct.max()) < 3e-4

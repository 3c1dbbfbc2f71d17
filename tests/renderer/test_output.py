"""The render's output in kelvin (roughsea_torch.renderer.output): a negative radiance has no
brightness temperature, and says so."""

from __future__ import annotations

import pytest
import torch

import roughsea_torch as rs

from conftest import make_cams, make_scene


@pytest.mark.parametrize("method", ["table", "direct"])
def test_kelvin_of_a_negative_radiance_is_an_error(method):
    """Without shadowing (Eq. 7) R_a goes negative near the horizon; such a pixel has no brightness
    temperature. It was clamped to a tiny radiance and came out near 13 K; now a ValueError says
    why. The radiance output is left as the model gives it."""
    cams = make_cams(16, 16, hfov_deg=10.0, pitch_deg=-0.3, dtype=torch.float32)
    scene = make_scene(wind_speed=10.0, sky=5.0, shadowing=False, path=False)
    assert float(rs.render(cams, scene, method=method).min()) < 0.0
    with pytest.raises(ValueError, match="no brightness temperature.*shadowing=True"):
        rs.render(cams, scene, method=method, output="brightness_temperature")

"""roughsea_torch.renderer.scene: the per-image values a scene resolves to."""

from __future__ import annotations

import pytest
import torch

import roughsea_torch as rs
from roughsea_torch.foam import whitecap_fraction


@pytest.mark.parametrize("band", [(2.41e-6, 2.61e-6), (5.89e-6, 6.09e-6), (6.91e-6, 7.11e-6), (14.85e-6, 15.0e-6)],
                         ids=["centre_2.51um", "centre_5.99um", "centre_7.01um", "centre_14.93um"])
def test_auto_foam_reaches_the_edges_of_the_measured_band_ranges(band):
    """foam='auto' is Monahan's whitecap fraction for every band centred in the foam emissivity's
    measured ranges, 2.5–6 µm and 7–15 µm (scenes.md §5), up to their edges (bands centred within
    0.5 % of each): the render equals the one with that fraction given explicitly (a float64 and a
    float32 evaluation of Monahan's law: 1.5e-9 apart), and the foam is there (12 m/s: 1.8 % of the
    sea, 0.8–2 % of the radiance here)."""
    cams = rs.make_camera(8, 8, hfov_deg=10.0, altitude_m=10.0, pitch_deg=-10.0, dtype=torch.float64)

    def render(foam):
        return rs.render(cams, rs.SeaScene(wind_speed=12.0, sea_temperature=290.0, band=band, sky=5.0, path=False,
                                           foam=foam))

    auto, none = render("auto"), render(0.0)
    torch.testing.assert_close(auto, render(float(whitecap_fraction(12.0))), rtol=1e-8, atol=0)
    assert float((auto - none).abs().max() / none.max()) > 5e-3

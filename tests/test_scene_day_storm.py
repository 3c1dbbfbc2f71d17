"""Scenes by day and in storms: the sun's irradiance from the LOWTRAN7 table, foam on where the wind
warrants it (Monahan & O'Muircheartaigh 1980), each with clear errors."""

import math

import pytest
import torch

import roughsea_torch as rs
from roughsea_torch.solar import load_solar_irradiance


def _cams(b=1):
    return rs.make_camera(24, 32, hfov_deg=20.0, altitude_m=20.0, pitch_deg=-4.0, batch_size=b, dtype=torch.float64)


def test_sun_from_zenith_takes_the_lowtran_irradiance_of_the_scene_band():
    z = torch.tensor([math.radians(30.0), math.radians(80.0)], dtype=torch.float64)
    for band in (rs.MWIR, rs.LWIR):
        sc = rs.SeaScene(wind_speed=6.0, sea_temperature=290.0, band=band, sky="tropical", sun_zenith=z, sun_azimuth=0.0)
        want = load_solar_irradiance("tropical", band)(z)
        torch.testing.assert_close(sc.sun.irradiance, want, rtol=1e-12, atol=0.0)
    with pytest.raises(ValueError, match="sun_zenith"):
        rs.SeaScene(wind_speed=6.0, sea_temperature=290.0, sky=10.0, sun_zenith=0.5)
    with pytest.raises(ValueError, match="not both"):
        rs.SeaScene(wind_speed=6.0, sea_temperature=290.0, sun=rs.Sun(0.5, 0.0, 1.0), sun_zenith=0.5)


def test_foam_keeps_the_second_law_and_vanishes_without_wind():
    """A sky at the sea's blackbody radiance: foam (whatever its emissivity) changes nothing; no wind,
    no foam: the default 'auto' equals foam=False bit for bit; a storm's foam changes the image."""
    rb = 30.0
    cams = _cams()
    storm = rs.render(cams, rs.SeaScene(wind_speed=25.0, sea_radiance=rb, sky=rb, path=False))
    assert torch.allclose(storm[0, 0][rs.view_geometry(cams).is_sea[0]], torch.tensor(rb, dtype=torch.float64), rtol=1e-12, atol=0)
    calm = dict(wind_speed=0.0, sea_temperature=290.0)
    assert torch.equal(rs.render(cams, rs.SeaScene(**calm)), rs.render(cams, rs.SeaScene(**calm, foam=False)))
    windy = dict(wind_speed=20.0, sea_temperature=290.0)
    with_foam = rs.render(cams, rs.SeaScene(**windy), output="brightness_temperature")
    without = rs.render(cams, rs.SeaScene(**windy, foam=False), output="brightness_temperature")
    assert float((with_foam - without).abs().max()) > 0.1  # kelvin: 7 % whitecaps at 20 m/s


def test_foam_fraction_errors():
    with pytest.raises(ValueError, match="foam"):
        rs.SeaScene(wind_speed=5.0, sea_temperature=290.0, foam=1.5)
    with pytest.raises(ValueError, match="foam"):
        rs.SeaScene(wind_speed=5.0, sea_temperature=290.0, foam="yes")

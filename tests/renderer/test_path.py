"""The air between the camera and the sea (roughsea_torch.renderer.path): transmittance and path
radiance compose per pixel (a synthetic Beer–Lambert path), and a camera outside the path tables is an
error naming its altitude."""

from __future__ import annotations

import pytest
import torch

import roughsea_torch as rs

from conftest import make_cams, make_scene, smooth_sky


class BeerLambertPath:
    """A synthetic isothermal path: τ = exp(−r / 5 km), L = (1 − τ) B(T_air) (Kirchhoff)."""

    def __init__(self, t_air: float):
        self.l_air = float(rs.band_radiance(torch.tensor(t_air, dtype=torch.float64)))

    def __call__(self, altitude_m, range_m, clamp=False):
        tau = torch.exp(-range_m / 5000.0)
        return tau, (1.0 - tau) * self.l_air


def test_path_composes_transmittance_and_path_radiance_per_pixel():
    """radiance at the sensor = τ(range) · R_a + L_path on every sea pixel; sky pixels unchanged;
    far sea pixels tend to the air's brightness temperature."""
    cams = make_cams(40, 48, hfov_deg=3.0, pitch_deg=-0.5)
    geom = rs.view_geometry(cams)
    base = dict(wind_speed=6.0, sea_temperature=285.0, sky=smooth_sky)
    # per ray: each pixel by its centre ray (the horizon's area-weighted pixels mix two rays)
    off = rs.render(cams, rs.SeaScene(**base, path=False), geometry=geom, horizon="centre")
    on = rs.render(cams, rs.SeaScene(**base, path=BeerLambertPath(295.0)), geometry=geom, horizon="centre")
    tau = torch.exp(-geom.range_m / 5000.0)[:, None]
    sea = geom.is_sea[:, None]
    expected = tau * off + (1 - tau) * float(rs.band_radiance(torch.tensor(295.0, dtype=torch.float64)))
    # the path is read per row of the table, not per pixel: 3.6e-8 measured here (float64)
    torch.testing.assert_close(on[sea], expected[sea], rtol=1e-7, atol=0)
    assert torch.equal(on[~sea], off[~sea])
    far = (geom.range_m[:, None] > 10_000)[sea]
    gap_on = (rs.brightness_temperature(on)[sea][far] - 295.0).abs()
    gap_off = (rs.brightness_temperature(off)[sea][far] - 295.0).abs()
    assert far.any() and (gap_on < 0.2 * gap_off).all()  # τ < 0.14: mostly air


def test_camera_outside_the_path_tables_is_an_error():
    """The path tables cover 2 m – 5 km: a camera outside them with the path on is a ValueError
    naming altitude_m and the range (it was silently clamped); with path=False it renders."""
    scene = make_scene(wind_speed=5.0)
    for h in (0.5, 8000.0):
        cams = make_cams(8, 10, altitude_m=h, dtype=torch.float32)
        for method in ("table", "direct"):
            with pytest.raises(ValueError, match=r"altitude_m must lie in \[2, 5000\] m"):
                rs.render(cams, scene, method=method)
        img = rs.render(cams, make_scene(wind_speed=5.0, path=False))
        assert torch.isfinite(img).all()

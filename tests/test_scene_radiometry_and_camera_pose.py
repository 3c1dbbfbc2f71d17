"""Scenes and cameras against physics computed outside the library: the sea radiance of a scene in
its own band (MWIR is not LWIR), explicit slopes / sea radiance / spectral response reaching the
rendered pixels, the camera roll seen as the horizon's tilt, and the dataset generator's printed
default config.

(Owned alongside ``test_render.py``, which others are rewriting; these tests use only the public
API: ``make_camera``, ``view_geometry``, ``SeaScene``, ``render``.)
"""

from __future__ import annotations

import json
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import torch
from scipy import integrate

import roughsea_torch as rs
import roughsea_torch.reference as ref

from conftest import smooth_sky

F64 = torch.float64
ROOT = Path(__file__).resolve().parents[1]
H, C, KB = 6.62607015e-34, 299792458.0, 1.380649e-23  # CODATA 2018, typed in


def planck_band(T: float, lo: float, hi: float) -> float:
    f = lambda lam: 2 * H * C * C / lam**5 / math.expm1(H * C / (lam * KB * T))  # noqa: E731
    return integrate.quad(f, lo, hi, epsabs=0.0, epsrel=1e-13, limit=200)[0]


def small_cameras(pitch_deg: float = -8.0, roll_deg: float = 0.0, batch_size: int = 1):
    return rs.make_camera(24, 32, hfov_deg=40.0, altitude_m=20.0, pitch_deg=pitch_deg, roll_deg=roll_deg,
                          batch_size=batch_size, dtype=F64)


def test_scene_sea_radiance_is_the_band_radiance_of_its_own_band():
    """A 290 K sea under a sky of the same band radiance (no path): every pixel, sea or sky, is the
    band radiance of a 290 K blackbody in the scene's band, from Planck integrated here (MWIR
    3–5 µm: 1.28 W m⁻² sr⁻¹; LWIR: 32.5 W m⁻² sr⁻¹; a scene given the other band's sea radiance is off
    by 25×), and its brightness temperature is 290 K. (The LWIR default is exercised by every
    other scene test.)"""
    band = (3e-6, 5e-6)
    L = planck_band(290.0, *band)
    scene = rs.SeaScene(wind_speed=torch.tensor(6.0, dtype=F64), sea_temperature=290.0, band=band, sky=L, path=False)
    cams = small_cameras(pitch_deg=-2.0)
    geom = rs.view_geometry(cams)
    assert bool(geom.is_sea.any()) and bool((~geom.is_sea).any())
    img = rs.render(cams, scene)
    np.testing.assert_allclose(img.numpy(), L, rtol=1e-6)
    bt = rs.render(cams, scene, output="brightness_temperature")
    np.testing.assert_allclose(bt.numpy(), 290.0, rtol=0, atol=1e-4)


def test_scene_response_shapes_the_sea_radiance():
    """A tabulated spectral response (the reference integrates it with scipy): a 295 K sea under a
    sky equal to that response-weighted band radiance renders that radiance everywhere; the flat
    band's would differ by ~30 %."""
    wl = np.array([7.5e-6, 8.5e-6, 10e-6, 11.5e-6, 12.5e-6])
    resp = np.array([0.0, 0.9, 1.0, 0.7, 0.0])
    band = (7.5e-6, 12.5e-6)
    L = float(ref.band_radiance(295.0, band, (wl, resp)))
    assert abs(L / float(ref.band_radiance(295.0, band)) - 1) > 0.1
    scene = rs.SeaScene(wind_speed=torch.tensor(6.0, dtype=F64), sea_temperature=295.0, band=band, response=(wl, resp),
                        sky=L, path=False)
    img = rs.render(small_cameras(pitch_deg=-2.0), scene)
    np.testing.assert_allclose(img.numpy(), L, rtol=1e-6)


def test_explicit_slopes_and_sea_radiance_reach_the_pixels():
    """SeaScene(slopes=..., sea_radiance=...) with a correlated anisotropic law and a wind
    direction: sea pixels equal the numpy reference's Eq. 10 at each pixel's own view zenith and
    relative azimuth φ̂ = LOS azimuth − wind direction (docs/physics.md §2)."""
    a, b, r, wd, rb = 0.28, 0.11, 0.5, 0.7, 31.0
    scene = rs.SeaScene(slopes=rs.SlopeStatistics(torch.tensor(a, dtype=F64), b, r), wind_direction=wd,
                        sea_radiance=rb, sky=smooth_sky, refractive_index=1.153 + 0.0968j, path=False)
    cams = rs.make_camera(24, 32, hfov_deg=60.0, altitude_m=20.0, pitch_deg=-20.0, yaw_deg=35.0, dtype=F64)
    geom = rs.view_geometry(cams)
    img = rs.render(cams, scene, geometry=geom)
    for (i, j) in ((23, 0), (12, 31)):
        assert bool(geom.is_sea[0, i, j])
        th = float(geom.view_zenith[0, i, j])
        ph = float(geom.view_azimuth[0, i, j]) - wd
        want = float(ref.apparent_radiance(th, ph, ref.SlopeStatistics(a, b, r), 1.153 + 0.0968j, rb, smooth_sky, epsrel=1e-9))
        assert abs(float(img[0, 0, i, j]) / want - 1) < 5e-5, (i, j, float(img[0, 0, i, j]), want)
    # the law is anisotropic and seen off its axes: the pixels above are not insensitive to it
    other = rs.SeaScene(slopes=rs.SlopeStatistics(torch.tensor(b, dtype=F64), a, r), wind_direction=wd,
                        sea_radiance=rb, sky=smooth_sky, refractive_index=1.153 + 0.0968j, path=False)
    assert float((rs.render(cams, other, geometry=geom) - img).abs().max()) > 1e-3


def horizon_tilt_deg(cams) -> float:
    """Angle [deg] of the horizon in the image, counter-clockwise as seen (image y points down):
    a least-squares line through the first sea row of every column."""
    sea = rs.view_geometry(cams).is_sea[0].numpy()
    H, W = sea.shape
    cols, rows = [], []
    for x in range(W):
        ys = np.nonzero(sea[:, x])[0]
        if 0 < ys.size < H:
            cols.append(x)
            rows.append(ys[0] - 0.5)  # the edge lies between the last sky and the first sea pixel
    slope = np.polyfit(cols, rows, 1)[0]
    return -math.degrees(math.atan(slope))


@pytest.mark.parametrize("roll", [0.0, 10.0, -25.0])
def test_camera_roll_tilts_the_horizon_by_the_roll_angle(roll):
    """A camera rolled by ρ about its optical axis sees the horizon rotated by ρ in the image
    (make_camera: positive roll turns it counter-clockwise). Measured from the sea mask of a
    level 30°-fov camera (the horizon's curvature over 30° is far below a pixel)."""
    cams = rs.make_camera(240, 320, hfov_deg=30.0, altitude_m=20.0, pitch_deg=0.0, roll_deg=roll, dtype=F64)
    assert abs(horizon_tilt_deg(cams) - roll) < 0.3


def test_print_default_config_is_complete_and_valid():
    """``generate_dataset.py --print-default-config`` prints TOML, the format ``--config`` reads (it
    printed JSON, which tomllib refuses: found by a new user), equal to DEFAULT_CONFIG but for the keys
    whose default is "not set" (TOML has no null: left out, and named in a comment); it passes the
    config validation as is, and names every key the validation knows (an unknown key is rejected,
    so a config written from the printout is complete)."""
    import tomllib

    out = subprocess.run([sys.executable, str(ROOT / "pipelines" / "generate_dataset.py"), "--print-default-config"],
                         capture_output=True, text=True, timeout=120, cwd=ROOT)
    assert out.returncode == 0, out.stderr
    printed = tomllib.loads(out.stdout)
    from roughsea_torch.dataset import DEFAULT_CONFIG, resolve_config

    assert "scene.air_temperature" in out.stdout.split("\n\n")[0]  # the unset key, named in the header comment
    printed_unset = {**printed, "scene": {**printed["scene"], "air_temperature": None}}
    assert printed_unset == json.loads(json.dumps(DEFAULT_CONFIG))
    resolve_config(printed)
    with pytest.raises(ValueError, match="no_such_key"):
        resolve_config({**printed, "no_such_key": 1})

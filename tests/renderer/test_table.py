"""The table method (roughsea_torch.renderer.table) against the per-pixel evaluation (the direct
method): every sea pixel, the rows next to the horizon included, and the sky pixels, over five varied
cameras, both dtypes, isotropic and anisotropic seas, a callable and the LOWTRAN sky; and a calm
anisotropic sea, whose kink along the wind the folded azimuth must resolve."""

from __future__ import annotations

import pytest
import torch

import roughsea_torch as rs

from conftest import DEG, make_cams, make_scene, smooth_sky, varied_cameras


# Measured worst relative errors of the table against per-pixel evaluation over these scenes (sea
# pixels; float32 / float64): 8.2e-7 / 2.6e-7 with a callable sky, 6.8e-7 / 3.7e-7 with the LOWTRAN sky
# and the path (the path table is read per table row, not per pixel). Sky pixels: 4.5e-7 with a
# callable sky; with the sky from the camera's altitude 4.2e-5 (0.003 K) in the row at the local
# horizontal, where it has a square-root edge (rays just below it pass a tangent point near the
# camera), 1e-6 elsewhere.
SEA_TOL = {"fn": 2e-6, "midlatitude_summer": 2e-6}


SKY_TOL = {"fn": 1e-6, "midlatitude_summer": 1e-4}


@pytest.mark.filterwarnings("ignore:wind_speed above 25 m/s:UserWarning")  # 40 m/s: the whitecap law's cap (tests/test_foam.py)
@pytest.mark.parametrize("anisotropic", [False, True])
@pytest.mark.parametrize("sky_kind", ["fn", "midlatitude_summer"])
def test_table_render_matches_direct_per_pixel_evaluation(dtype, anisotropic, sky_kind):
    """Every sea pixel within a few 1e-6 relative of apparent_radiance at its own (θ̂, φ̂) (with the
    path: τ R_a + L_path at its own range), including the rows next to the horizon (θ̂ up to
    89.99° here); sky pixels within 1e-6 of the sky along their ray. Both sources of the table's
    spans: the cameras' border (the default) and a precomputed per-pixel geometry."""
    cams = varied_cameras(dtype)
    scene = rs.SeaScene(
        wind_speed=torch.tensor([2.0, 10.0, 25.0, 0.0, 40.0]), anisotropic=anisotropic,
        wind_direction=torch.tensor([0.3, 1.0, 2.5, -1.0, 0.0]),
        sea_temperature=torch.tensor([285.0, 295.0, 300.0, 275.0, 290.0]), sky=smooth_sky if sky_kind == "fn" else sky_kind,
    )
    geom = rs.view_geometry(cams)
    direct = rs.render(cams, scene, geometry=geom, method="direct")
    sea = geom.is_sea[:, None]
    near_horizon = (geom.view_zenith > 89.9 * DEG)[:, None] & sea
    assert near_horizon.sum() > 0 and (~sea).sum() > 0  # the checks cover grazing rows and sky
    for table in (rs.render(cams, scene), rs.render(cams, scene, geometry=geom)):
        assert table.shape == (5, 1, 64, 80) and table.dtype == dtype
        rel = (table - direct).abs() / direct.abs()
        assert rel[sea].max() <= SEA_TOL[sky_kind]
        assert rel[~sea].max() <= SKY_TOL[sky_kind]


@pytest.mark.parametrize("wind", [0.0, 0.01, 0.05])
def test_calm_anisotropic_sea_along_the_wind(wind):
    """Cox–Munk at W → 0 has a → 0: the rms slope along the view → b |sin φ̂| has a kink at views
    along the wind, sharp at grazing. The table folds the azimuth by the mirror symmetry (the kink
    at the interval's end) and uses more azimuth nodes for thin slope ellipses; every sea pixel,
    horizon row included, stays within the renderer's 2e-5 of the direct evaluation."""
    cam = make_cams(48, 64, pitch_deg=-8.0, yaw_deg=torch.tensor([0.0, 10.0, 170.0]), dtype=torch.float32)
    scene = make_scene(wind_speed=wind, wind_direction=0.0, sky=lambda c: 10 + 20 * (1 - c) ** 6)
    t = rs.render(cam, scene)
    d = rs.render(cam, scene, method="direct")
    sea = rs.view_geometry(cam).is_sea
    assert float(((t - d).abs() / d.abs())[:, 0][sea].max()) < 2e-5

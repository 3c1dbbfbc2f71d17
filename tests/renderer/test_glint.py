"""The sun's glint in renders (roughsea_torch.renderer.glint): the table against the per-pixel
evaluation, with the glint's smooth factor in the table and its sharp part per pixel, on smooth and
textured seas; a sun that sees no glint changes nothing. (The glint's physics: tests/test_sun.py.)"""

from __future__ import annotations

import math

import torch

import roughsea_torch as rs

from conftest import make_cams, make_scene


def _sunny_scene(sun, **kw):
    return make_scene(wind_speed=torch.tensor([5.0, 10.0]), band=rs.MWIR, sun=sun, **kw)


def test_render_with_sun_matches_per_pixel_evaluation_and_leaves_out_what_sees_no_glint():
    """MWIR, sun ahead of the camera 20° and 10° above the horizon: the table render equals the
    per-pixel evaluation (the glint itself is per pixel) to 1e-6 and the glint is strong (the
    brightest pixel well above the sea's own radiance); a sun behind the camera on these seas
    changes no pixel beyond rounding (the sunless render takes the in-place pixel path, the sunny one
    the general path: 3.4e-16 relative measured)."""
    cams = make_cams(32, 40, hfov_deg=20.0, batch_size=2)
    sun = rs.Sun(torch.tensor([math.radians(70.0), math.radians(80.0)]), 0.0, 12.0)  # world azimuth 0: ahead
    table = rs.render(cams, _sunny_scene(sun))
    direct = rs.render(cams, _sunny_scene(sun), method="direct")
    mean = rs.render(cams, _sunny_scene(None))
    assert float(((table - direct) / direct).abs().max()) < 1e-6
    assert float((table / mean).max()) > 5.0
    behind = rs.render(cams, _sunny_scene(rs.Sun(math.radians(40.0), math.pi, 12.0)))
    assert float(((behind - mean) / mean).abs().max()) < 1e-13
    kelvin = rs.render(cams, _sunny_scene(sun), output="brightness_temperature")
    assert float(kelvin.max()) > 320.0


def test_glint_in_the_table_matches_per_pixel_evaluation(dtype):
    """The table holds the glint's smooth factor L_sun G1 / D (TableSize.glint) and each pixel applies
    its sharp part, P ρ t (the sun's ellipse probability in slope space, the Fresnel reflectance and
    facet cosine at the facets that mirror the sun), where a check at the fine cells' centres finds
    the table within 1e-5 of the radiance; else the whole glint stays per pixel. MWIR, sun 15° up
    ahead (glint up to 23× the sea), correlated slopes (so the table runs over the unfolded azimuth):
    every pixel within 2e-5 of the per-pixel evaluation (7.0e-6 float64, 1.3e-5 float32 measured),
    and the table's glint is in use (the render differs from forcing the per-pixel glint with
    glint_tolerance=0, which is itself within 2e-6). Planted: the pixel's azimuth turned the wrong
    way (sin φ̂ negated) loses the glint (0.96 off)."""
    cams = make_cams(48, 64, altitude_m=torch.tensor([20.0, 150.0, 80.0]), pitch_deg=torch.tensor([-3.0, -12.0, -8.0]),
                     yaw_deg=torch.tensor([10.0, -30.0, 5.0]), dtype=dtype)
    slopes = rs.SlopeStatistics.from_variances(torch.tensor([0.03, 0.05, 0.03]), torch.tensor([0.02, 0.03, 0.02]),
                                               torch.tensor([0.006, -0.01, 0.004]))
    kw = dict(slopes=slopes, wind_direction=torch.tensor([0.4, 2.0, -1.0]), sea_temperature=291.0, band=rs.MWIR)
    scene = rs.SeaScene(**kw, sun=rs.Sun(math.radians(75.0), 0.0, 8.0))
    table = rs.render(cams, scene)
    per_pixel = rs.render(cams, scene, table=rs.TableSize(glint_tolerance=0.0))
    direct = rs.render(cams, scene, geometry=rs.view_geometry(cams), method="direct")
    night = rs.render(cams, rs.SeaScene(**kw))
    assert float((table / night).max()) > 10.0
    assert not torch.equal(table, per_pixel)
    assert float(((per_pixel - direct) / direct).abs().max()) < 2e-6
    assert float(((table - direct) / direct).abs().max()) < 2e-5


def test_textured_glint_table_matches_per_pixel():
    """A textured MWIR sea with the sun ahead: table render against per-pixel evaluation, 2e-4 (4.8e-5
    measured; the glint is per pixel in both, the table's reading its pixel's visible quantile x' from
    the texture volume where per-pixel evaluation inverts the visible-slope distribution; with the
    night's 33 texture ζ nodes, TableSize.texture_zenith_sun planted at 33, 3.8e-4); the glint carries
    texture."""
    cams = make_cams(hfov_deg=20.0, altitude_m=15.0, pitch_deg=-6.0, batch_size=2)
    sun = rs.Sun(torch.tensor([math.radians(75.0), math.radians(80.0)], dtype=torch.float64), 0.0, 12.0)

    def scene(seed):
        return make_scene(wind_speed=torch.tensor([5.0, 10.0]), band=rs.MWIR, sun=sun, seed=seed, path=False, sky=1.0)

    table, direct, mean = rs.render(cams, scene([1, 2])), rs.render(cams, scene([1, 2]), method="direct"), rs.render(cams, scene(None))
    assert float(((table - direct) / direct).abs().max()) < 2e-4
    assert float((table / mean).max()) > 1.2 and float((table / mean).min()) < 0.8

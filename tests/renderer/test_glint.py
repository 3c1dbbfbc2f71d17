"""The sun's glint in renders (roughsea_torch.renderer.glint): the table against the per-pixel
evaluation, with the glint's smooth factor in the table and its sharp part per pixel, on smooth and
textured seas; a sun that sees no glint changes nothing. (The glint's physics: tests/test_sun.py.)"""

from __future__ import annotations

import math

import numpy as np
import pytest
import torch

import roughsea_torch as rs
from roughsea_torch.renderer.glint import fixed_glitter_latent

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


def _glitter_pair(times, table_kw=None, dtype=torch.float64, seed=4):
    """Glint of a textured MWIR near-range patch looking towards the sun (10 m, 6° down, sun 15° up),
    without and with glitter, at the clip's times: (plain, glittered) glint radiances (T, H, W)."""
    cams = make_cams(40, 48, hfov_deg=48 * 0.047, altitude_m=10.0, pitch_deg=-8.0, dtype=dtype)
    sun = rs.Sun(math.radians(75.0), 0.0, 12.0)
    kw = dict(band=rs.MWIR, seed=seed, foam=False, path=False)
    out = []
    for glitter in (False, True):
        table = rs.TableSize(glitter=glitter, **(table_kw or {}))
        lit = rs.render_clip(cams, make_scene(sun=sun, **kw), times, table=table)
        dark = rs.render_clip(cams, make_scene(sun=rs.Sun(math.radians(75.0), 0.0, 0.0), **kw), times, table=table)
        out.append((lit - dark)[0, :, 0])
    return out


def _block_ratio(plain, glit, keep, rows=2, cols=4):
    """The glint-weighted mean ratio Σ w r over the kept pixels and its standard error from blocks of
    rows × cols pixels (the glitter is correlated over about one footprint across the view, so
    neighbouring columns are not independent): (mean, standard error)."""
    w = torch.where(keep, plain, torch.zeros_like(plain))
    wr = torch.where(keep, glit, torch.zeros_like(glit))
    pool = lambda t: torch.nn.functional.avg_pool2d(t.reshape(-1, 1, *t.shape[-2:]), (rows, cols)).flatten()  # noqa: E731
    bw, bwr = pool(w), pool(wr)
    ok = bw > 0
    bw, bwr = bw[ok], bwr[ok]
    mean = float(bwr.sum() / bw.sum())
    n = bw.numel()
    se = float(torch.sqrt(((bwr - mean * bw) ** 2).sum() * n / (n - 1)) / bw.sum())
    return mean, se


def test_glitter_keeps_the_glint_mean_and_sparkles():
    """TableSize(glitter=True) multiplies each textured pixel's glint by a factor of mean 1: the mean
    over a clip's frames (1 s apart, beyond two of the default 0.25 s steps) and pixels, weighted by
    the glint, is the render without glitter within three standard errors (from 2 × 4 pixel blocks;
    measured ~1e-2 here: the exact mean is the Gauss–Hermite test below), while the spread across
    pixels grows and the 99th percentile rises well above the smooth path's (near range: a few spots
    per pixel)."""
    plain, glit = _glitter_pair([0.0, 1.0, 2.0, 3.0])
    keep = plain > 0.05 * plain.max()
    mean, se = _block_ratio(plain, glit, keep)
    assert abs(mean - 1.0) < 3 * se and se < 0.03, (mean, se)
    cv = lambda t: float(t.std() / t.mean())  # noqa: E731
    q99 = lambda t: float(torch.quantile(t, 0.99) / t.mean())  # noqa: E731
    assert cv(glit[keep]) > 1.5 * cv(plain[keep])
    assert q99(glit[keep]) > 2.0 * q99(plain[keep])


def test_glitter_render_mean_over_the_latent_is_the_render_without_glitter(dtype):
    """The ensemble mean of the glitter at render level, without sampling error: the latent forced to
    each node zᵢ of a 32-node Gauss–Hermite rule for every pixel (``fixed_glitter_latent``), the renders
    summed with the weights, equal the render without glitter within 1e-3 of each pixel's glint
    (E g = 1 for g = exp(σz − σ²/2); the rule is exact to 1e-15 for σ ≤ 4, the largest σ a pixel
    reaches being ln(1 + F(1 + κ)·1e6)^½ ≈ 4). Textured MWIR near range with the path (its τ multiplies
    the glint too), float64 and float32 (the issue asks 1e-3; measured 1.2e-15 and 2.3e-7). Planted:
    the −σ²/2 dropped (2.3 off); σ² in the exponent's −σ²/2 taken 2 % larger than in σz (2.4e-2 off)."""
    cams = make_cams(24, 32, hfov_deg=32 * 0.047, altitude_m=10.0, pitch_deg=-8.0, dtype=dtype)
    kw = dict(band=rs.MWIR, seed=4, foam=False)
    lit = make_scene(sun=rs.Sun(math.radians(75.0), 0.0, 12.0), **kw)
    plain = rs.render(cams, lit)
    glint = (plain - rs.render(cams, make_scene(sun=rs.Sun(math.radians(75.0), 0.0, 0.0), **kw))).double()
    x, w = np.polynomial.hermite_e.hermegauss(32)
    w = w / w.sum()
    on = rs.TableSize(glitter=True)
    mean = torch.zeros_like(glint)
    renders = {}
    for xi, wi in zip(x, w):
        with fixed_glitter_latent(float(xi)):
            r = rs.render(cams, lit, table=on).double()
        renders[float(xi)] = r
        mean = mean + wi * r
    keep = glint > 1e-3 * glint.max()
    assert int(keep.sum()) > 200
    err = float(((mean - plain.double()).abs() / glint)[keep].max())
    assert err < (1e-5 if dtype == torch.float32 else 1e-9), err
    # the nodes are far apart: the glint at a high node is many times the plain glint at some pixels
    hi = renders[float(x[-6])]  # z ≈ 3.6
    assert float(((hi - plain.double()) / glint)[keep].max()) > 2.0


def test_glitter_is_tied_to_the_sea_not_to_the_pixel_grid():
    """A camera yawed by one pixel at the same instant sees the same glitter on the same sea points:
    the log glitter factor (glint with glitter over without) of its column j correlates ≥ 0.9 with the
    unturned camera's column j ± 1 (the one whose sea points coincide, to 5 % of a footprint), and
    about 0 for a realization of another seed (measured 0.9997 and 0.03; the same column of both
    cameras, 0.38: neighbouring columns share lattice cells). Planted: a latent tied to the pixel
    numbers (the old one) gives 0.04."""
    def factor(yaw, seed):
        cams = make_cams(40, 48, hfov_deg=48 * 0.047, altitude_m=10.0, pitch_deg=-8.0, yaw_deg=yaw)
        kw = dict(band=rs.MWIR, seed=seed, foam=False, path=False)
        on = rs.TableSize(glitter=True)
        dark = rs.render(cams, make_scene(sun=rs.Sun(math.radians(75.0), 0.0, 0.0), **kw))
        lit = make_scene(sun=rs.Sun(math.radians(75.0), 0.0, 12.0), **kw)
        glint = (rs.render(cams, lit) - dark)[0, 0]
        geo = rs.view_geometry(cams)
        pts = torch.stack([geo.range_m * geo.dx, geo.range_m * geo.dy])[:, 0]
        return torch.log((rs.render(cams, lit, table=on) - dark)[0, 0] / glint), glint, pts, geo.range_m[0]

    f0, g0, p0, r0 = factor(0.0, 4)
    step = math.degrees(math.atan(math.tan(math.radians(48 * 0.047 / 2)) / 24))  # one pixel at the centre
    f1, _, p1, _ = factor(step, 4)
    f2, _, _, _ = factor(step, 5)
    shift = 1 if float((p1[:, :, :-1] - p0[:, :, 1:]).abs().max()) < float((p1[:, :, 1:] - p0[:, :, :-1]).abs().max()) else -1
    a = (slice(None), slice(None, -1)) if shift == 1 else (slice(None), slice(1, None))
    b = (slice(None), slice(1, None)) if shift == 1 else (slice(None), slice(None, -1))
    mismatch = (p1[(slice(None),) + a] - p0[(slice(None),) + b]).norm(dim=0) / (r0[b] * 0.047 * math.pi / 180)
    assert float(mismatch.max()) < 0.05
    keep = g0[b] > 0.05 * g0.max()
    corr = lambda u, v: float(torch.corrcoef(torch.stack([u[keep], v[keep]]))[0, 1])  # noqa: E731
    assert corr(f1[a], f0[b]) >= 0.9
    assert abs(corr(f2[a], f0[b])) < 0.15


def test_glitter_is_coherent_in_time():
    """A pixel's glitter factor persists over much less than its lifetime and is forgotten beyond
    two lifetimes (the waves move too, so the factor is taken as the ratio of the two renders)."""
    plain, glit = _glitter_pair([0.0, 0.01, 1.0], {"glitter_lifetime_s": 0.175})
    keep = (plain > 0.05 * plain.max()).all(0)
    lr = torch.log(glit / plain)[:, keep]
    lr = lr - lr.mean(1, keepdim=True)
    corr = lambda a, b: float((a * b).sum() / torch.sqrt((a * a).sum() * (b * b).sum()))  # noqa: E731
    assert corr(lr[0], lr[1]) > 0.9
    assert abs(corr(lr[0], lr[2])) < 0.15


def test_glitter_in_float32_is_finite_and_leaves_untextured_scenes_alone():
    plain, glit = _glitter_pair([0.0], dtype=torch.float32)
    assert glit.dtype == torch.float32 and bool(torch.isfinite(glit).all())
    cams = make_cams(16, 20, hfov_deg=20.0, batch_size=2)
    scene = _sunny_scene(rs.Sun(math.radians(75.0), 0.0, 12.0))
    assert torch.equal(rs.render(cams, scene), rs.render(cams, scene, table=rs.TableSize(glitter=True)))


def test_glitter_settings_are_checked():
    with pytest.raises(ValueError, match="glitter_lifetime_s"):
        rs.TableSize(glitter_lifetime_s=0.0)
    with pytest.raises(ValueError, match="TableSize.glitter must be a bool"):
        rs.TableSize(glitter=1)

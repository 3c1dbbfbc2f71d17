"""The sweep along ground tracks (roughsea_torch.renderer.hits): first hits and what a pixel sees of a
resolved surface, against brute force on profiles with known answers, and the renders it makes."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
import torch

import roughsea_torch as rs
from roughsea_torch.raytrace import raytraced_image
from roughsea_torch._parallel import in_blocks
from roughsea_torch.clutter import footprint
from roughsea_torch.geometry import slant_range
from roughsea_torch.renderer.hits import (Sweep, centre_element, covers, footprint_fade, nonzero_2d, pixel_hits,
                                          pixel_windows, read_at, sample_step, sweep_envelope, sweep_layout,
                                          visible_average, visible_samples)
from roughsea_torch.renderer.swept import pixel_tracks

F64 = torch.float64
H_CAM = 10.0


def _sweep(r: torch.Tensor) -> Sweep:
    zero = torch.zeros(1, dtype=F64)
    return Sweep(r, zero, r[:, None], 0 * r[:, None], r, torch.tensor(H_CAM, dtype=F64), 0.0, 0.0, 1.0)


def _bump(r: torch.Tensor, at: float = 100.0, height: float = 2.0, width: float = 4.0) -> torch.Tensor:
    return height * torch.exp(-0.5 * ((r - at) / width) ** 2)


def _brute_first_hit(r: torch.Tensor, eta: torch.Tensor, tau: float) -> float:
    """The first r where the ray of depression τ from height H_CAM is at or below the surface."""
    below = (H_CAM - tau * r) <= eta
    return float(r[below.nonzero()[0, 0]]) if bool(below.any()) else math.inf


def test_first_hit_is_the_crest_in_front_not_the_flat_point():
    """A 2 m crest at 100 m, camera 10 m up: rays aimed at the flat sea behind it (100–125 m) meet the
    crest first. The sweep's first hit agrees with a dense brute-force march to a sample; planted, the
    last crossing of t instead of its running minimum (the flat-sea point, or the far side of the
    crest) misses it by tens of metres."""
    r = torch.linspace(20.0, 400.0, 3801, dtype=F64)
    eta = _bump(r)
    sw = _sweep(r)
    t, m = sweep_envelope(sw, eta[:, None])
    taus = torch.tensor([0.4, 0.2, 0.105, 0.095, 0.085, 0.081, 0.06, 0.03], dtype=F64)  # H/τ = flat point
    j = torch.zeros(taus.shape[0], dtype=torch.long)
    k, hit = centre_element(m, j, taus)
    assert bool(hit.all())
    dense = torch.linspace(20.0, 400.0, 38001, dtype=F64)
    for i, tau in enumerate(taus.tolist()):
        truth = _brute_first_hit(dense, _bump(dense), tau)
        assert abs(float(r[k[i]]) - truth) <= 0.11, (tau, float(r[k[i]]), truth)
    hidden = (taus < H_CAM / 100.0) & (taus > H_CAM / 125.0)  # flat points behind the crest
    assert bool((r[k[hidden]] < 100.0).all())  # met on the crest's front face


@pytest.mark.parametrize("overwrite", [False, True])
def test_visible_average_weights_what_the_pixel_sees(overwrite):
    """A quantity 1 on the crest's near face (from its foot to its top), 0 elsewhere: a pixel whose window
    spans the depressions about the crest's top sees the near face there, not the trough hidden behind
    it, so its average is the near face's share of its window, computed by brute force over a fine fan
    of rays (2,000 per window); a window of steep rays, entirely on the flat sea before the crest, sees
    0; a quantity 1 everywhere averages to 1 where the sweep covers the window. ``overwrite``: the same
    through :func:`pixel_hits` letting the cumulative sums take the values' buffer."""
    r = torch.linspace(20.0, 400.0, 7601, dtype=F64)
    eta = _bump(r)
    sw = _sweep(r)
    _, m = sweep_envelope(sw, eta[:, None])
    top = float(r[eta.argmax()])
    near = ((r <= top) & (r >= top - 12.0)).to(F64)
    values = torch.stack([near, torch.ones_like(near)])[:, None, :]  # (C=2, nt=1, ns)
    t_top = torch.tensor([0.06, 0.075, 0.2], dtype=F64)
    t_bot = torch.tensor([0.09, 0.085, 0.3], dtype=F64)
    j = torch.zeros(3, dtype=torch.long)
    if overwrite:
        avg = pixel_hits(m, values.clone(), j, t_top, t_bot, 0.5 * (t_top + t_bot), overwrite=True)[0]
    else:
        avg = visible_average(m, values, j, t_top, t_bot)
    fan = lambda a, b: torch.linspace(a, b, 2001, dtype=F64)[1:-1]  # noqa: E731
    dense = torch.linspace(20.0, 400.0, 76001, dtype=F64)
    dense_eta = _bump(dense)
    for i in range(3):
        hits = torch.tensor([_brute_first_hit(dense, dense_eta, float(tau)) for tau in fan(float(t_top[i]), float(t_bot[i]))])
        assert abs(float(avg[0, i]) - float(((hits <= top) & (hits >= top - 12.0)).to(F64).mean())) < 0.02
        assert abs(float(avg[1, i]) - 1.0) < 1e-9
    assert float(avg[0, 2]) < 1e-9  # steep rays land before the crest


def test_read_at_is_the_dense_array_read_at_those_indices():
    """:func:`read_at` gives what numpy's dense array (the values at their indices, 0 elsewhere) gives at
    any flat positions, present or not, in the shape of the positions; 0 from an empty index."""
    rng = np.random.default_rng(3)
    n = 500
    index = np.sort(rng.choice(n, 180, replace=False))
    values = rng.normal(size=180)
    dense = np.zeros(n)
    dense[index] = values
    at = rng.integers(0, n, size=(7, 40))
    got = read_at(torch.from_numpy(index), torch.from_numpy(values), torch.from_numpy(at))
    assert got.shape == (7, 40) and np.array_equal(got.numpy(), dense[at])
    assert not np.isin(at, index).all()  # (some positions are absent)
    empty = read_at(torch.zeros(0, dtype=torch.long), torch.zeros(0, dtype=F64), torch.from_numpy(at))
    assert empty.shape == (7, 40) and not empty.any()


def test_nonzero_2d_is_numpys_nonzero_in_row_major_order():
    """:func:`nonzero_2d` gives numpy's ``nonzero`` of a 2-D mask (rows, columns) and their flat indices
    row · W + col, in row-major order; empty for a mask without a True element."""
    mask = np.random.default_rng(5).random((37, 23)) < 0.3
    flat, row, col = nonzero_2d(torch.from_numpy(mask))
    r, c = np.nonzero(mask)
    assert np.array_equal(row.numpy(), r) and np.array_equal(col.numpy(), c)
    assert np.array_equal(flat.numpy(), r * 23 + c) and flat.dtype == row.dtype == col.dtype == torch.int64
    assert all(t.numel() == 0 for t in nonzero_2d(torch.zeros(4, 5, dtype=torch.bool)))


def test_in_blocks_joins_a_pointwise_function_over_all_points():
    """:func:`in_blocks` of a pointwise function (two outputs, the second with a leading axis) over 2.5
    blocks equals numpy's whole-array result; one call on no point gives empty outputs."""
    x = np.random.default_rng(7).normal(size=45)
    xt = torch.from_numpy(x)
    a, b = in_blocks(lambda u, e: (xt[u:e] * 3.0 + 1.0, torch.stack([xt[u:e], xt[u:e] * xt[u:e]])), 45, 18)
    assert np.array_equal(a.numpy(), x * 3.0 + 1.0) and np.array_equal(b.numpy(), np.stack([x, x * x]))
    (e,) = in_blocks(lambda u, e: (xt[u:e],), 0, 18)
    assert e.numel() == 0


def _render(hit: str, sky=None, **kw):
    cams = rs.make_camera(24, 32, hfov_deg=12.0, altitude_m=15.0, pitch_deg=kw.pop("pitch", -6.0), dtype=F64)
    scene = rs.SeaScene(wind_speed=kw.pop("wind", 10.0), sea_temperature=290.0, seed=kw.pop("seed", 11), time_s=3.0,
                        foam=False, path=False, **({} if sky is None else {"sky": sky}))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return rs.render(cams, scene, output="brightness_temperature", table=rs.TableSize(texture_hit=hit)), cams


def test_second_law_holds_with_the_sweep():
    """A sky at the sea's own blackbody radiance: every pixel of a swept textured sea is 290 K."""
    rb = float(rs.band_radiance(torch.tensor(290.0, dtype=F64)))
    img, _ = _render("first", sky=rb)
    assert float((img - 290.0).abs().max()) < 2e-4


def test_far_field_of_the_sweep_is_the_expectation_image():
    """Where no band of the field is resolved (a 300 m mast looking 0.3° down: footprints of hundreds
    of metres), the swept textured image is the expectation image (to 1e-10 relative: the texture
    table's own rounding, as for the flat point)."""
    cams = rs.make_camera(12, 16, hfov_deg=4.0, altitude_m=300.0, pitch_deg=-0.3, dtype=F64)
    tex = rs.render(cams, rs.SeaScene(wind_speed=3.0, sea_temperature=290.0, seed=1), table=rs.TableSize(texture_hit="first"))
    mean = rs.render(cams, rs.SeaScene(wind_speed=3.0, sea_temperature=290.0))
    assert torch.allclose(tex, mean, rtol=1e-10, atol=0.0)


def _far_camera_renders(wind: float, **scene_kw):
    """A far-field camera (24×32 over 30°, a 300 m mast, 3° down: rows from 2 km to beyond the horizon):
    the swept textured image, the expectation image (no seed), and its far pixels, the sea pixels whose
    footprint as the sweep's fade takes it (the side of the square of its area, R δ / √cos θ̂) resolves
    no band of the field even at 0.8 × it (from the view geometry and WaveField.resolved_covariance),
    but the row the horizon crosses."""
    cams = rs.make_camera(24, 32, hfov_deg=30.0, altitude_m=300.0, pitch_deg=-3.0, dtype=F64)
    kw = dict(wind_speed=wind, sea_temperature=290.0, time_s=3.0, path=False, **scene_kw)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        tex = rs.render(cams, rs.SeaScene(seed=11, **kw), output="brightness_temperature",
                        table=rs.TableSize(texture_hit="first"))[0, 0]
        mean = rs.render(cams, rs.SeaScene(**kw), output="brightness_temperature")[0, 0]
    geo = rs.view_geometry(cams)
    sea = geo.is_sea[0]
    foot = geo.range_m[0] / cams.fx[0] / torch.cos(geo.view_zenith[0]).sqrt()
    field = rs.SeaScene(seed=11, **kw).wave_field(1, F64, torch.device("cpu"))
    var = field.resolved_covariance(torch.where(sea, 0.8 * foot, torch.zeros_like(foot))[None])
    # (not the row the horizon crosses: its sea part lies lower, where footprints resolve waves)
    return tex, mean, sea & (var[0][0] + var[1][0] == 0) & torch.nn.functional.pad(sea[:-1], (0, 0, 1, 0))


@pytest.mark.parametrize("wind, scene_kw", [(5.0, dict(foam=False)), (15.0, dict(foam=False)), (15.0, {}),
                                            (5.0, dict(foam=False, sun_zenith=math.radians(80.0), sun_azimuth=0.0))])
def test_far_field_camera_of_the_sweep_is_the_expectation_image(wind, scene_kw):
    """From a 300 m mast looking 3° down with 0.94° pixels, the pixels whose own footprint resolves no wave
    (320 at 5 m/s, 64 at 15 m/s) are the expectation image within 1e-3 K with the first hit, though the
    sweep's samples, filtered at far finer footprints there, still resolve waves: with foam (15 m/s, the
    scene's default) and with a sun 10° above the horizon ahead (its glint) too (measured 4e-7 to 6e-6
    K). Planted, the sweep not fading out with the pixel's own footprint (hits.footprint_fade ≡ 1):
    0.09, 0.17, 0.30 and 1.19 K off in the four cases (the samples' visible-area weighting leans the
    mean away from the expectation image's Eq. 5, pipelines/first_hit_far_field.py). (On the 20 m, 2°
    down camera of pipelines/texture_vs_raytrace.py with 0.19° pixels, since the fade takes the
    footprint's area rather than its length along the view, no pixel below the horizon row resolves no
    wave at 15 m/s: across the view they are 16 m wide at 5 km, and the swell's crests running along
    the view stay resolved.)"""
    tex, mean, far = _far_camera_renders(wind, **scene_kw)
    assert int(far.sum()) >= 64
    assert float((tex - mean)[far].abs().max()) < 1e-3


def test_gradient_through_the_fading_rows_follows_the_texture():
    """Where the sweep's weight g falls to 0 with the pixel's footprint (5 m/s from 20 m, 1° down, 24×32
    over 6°: rows 10–11, g 0.03 and 0.75, footprints (the side of their area) near the end of the field's
    longest band's window), the pitch derivative of the texture's mean (first hit − expectation) follows
    the central differences at h = 2e-3° and 4e-3° (mean 0.665 K per degree) within 25 % (measured 0.751;
    at smaller h the differences scatter, 0.32–0.74, as the sweep's samples move with the pose). Planted,
    the weight detached: 0.270, and the test fails. And g itself: its derivative in the footprint equals
    central differences to 1e-6 over its octave."""
    def texture(pitch):
        cams = rs.make_camera(24, 32, hfov_deg=6.0, altitude_m=20.0, pitch_deg=pitch, dtype=F64)
        kw = dict(wind_speed=5.0, sea_temperature=290.0, time_s=3.0, foam=False, path=False)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            tex = rs.render(cams, rs.SeaScene(seed=11, **kw), table=rs.TableSize(texture_hit="first"),
                            output="brightness_temperature")
            mean = rs.render(cams, rs.SeaScene(**kw), output="brightness_temperature")
        return (tex - mean)[0, 0, 10:12].mean()

    p = torch.tensor(-1.0, dtype=F64, requires_grad=True)
    (grad,) = torch.autograd.grad(texture(p), [p])
    central = sum(float(texture(-1.0 + h) - texture(-1.0 - h)) / (2 * h) for h in (2e-3, 4e-3)) / 2
    assert abs(central) > 0.1 and abs(float(grad) - central) < 0.25 * abs(central), (float(grad), central)
    field = rs.SeaScene(wind_speed=5.0, sea_temperature=290.0, seed=11).wave_field(1, F64, torch.device("cpu"))
    f = torch.linspace(20.0, 80.0, 61, dtype=F64, requires_grad=True)
    (dg,) = torch.autograd.grad(footprint_fade(field, 0, f).sum(), [f])
    fd = (footprint_fade(field, 0, f.detach() + 1e-5) - footprint_fade(field, 0, f.detach() - 1e-5)) / 2e-5
    assert float(dg.abs().max()) > 1e-3 and float((dg - fd).abs().max()) < 1e-6


def test_footprint_fade_vanishes_exactly_where_the_pixel_resolves_no_band():
    """The sweep's weight g(f) at a pixel footprint f: in [0, 1], non-increasing in f, 1 at footprints
    resolving all but the field's longest band's edge, and 0 exactly where WaveField.resolved_covariance
    (every band's window) is 0, at 5 and 15 m/s (whose longest bands differ)."""
    f = torch.logspace(-1, 4, 2001, dtype=F64)
    for wind in (5.0, 15.0):
        field = rs.SeaScene(wind_speed=wind, sea_temperature=290.0, seed=3).wave_field(1, F64, torch.device("cpu"))
        g = footprint_fade(field, 0, f)
        var = field.resolved_covariance(f[None])
        resolved = (var[0][0] + var[1][0]) > 0
        assert bool(((g > 0) == resolved).all())
        assert bool(((g >= 0) & (g <= 1)).all()) and bool((g[1:] <= g[:-1]).all())
        assert float(g[0]) == 1.0 and bool(resolved.any()) and not bool(resolved.all())


@pytest.mark.parametrize("wind", [5.0, 15.0])
def test_second_law_holds_with_the_sweep_on_the_far_field_camera(wind):
    """Sky = R_B on the far-field camera: every pixel (the swept rows, those where the sweep fades out with
    the pixel's footprint, the far field) is 290 K within 1e-3 K with the first hit. (Foam off: the
    whitecaps' own radiance departs from R_B by a few mK in the expectation image.)"""
    rb = float(rs.band_radiance(torch.tensor(290.0, dtype=F64)))
    tex, _, _ = _far_camera_renders(wind, sky=rb, foam=False)
    assert float((tex - 290.0).abs().max()) < 1e-3


def test_sweep_sees_crests_the_flat_point_misses():
    """At 15 m/s looking upwind from 15 m the swept image differs from the flat-point one by more than
    its own noise where waves are resolved, and both keep the expectation's far field (top rows at
    87–88° barely resolve anything at 15 m: within 0.3 K)."""
    first, _ = _render("first", wind=15.0)
    flat, _ = _render("flat", wind=15.0)
    assert float((first - flat).abs().max()) > 0.3
    assert bool(torch.isfinite(first).all())


def test_gradients_through_the_sweep_follow_the_image():
    """The swept image's mean has finite gradients in the wind and the pitch within 10 % of central
    differences (h = 0.01; the sweep's choice of elements is piecewise constant, so smaller steps
    scatter: at 1e-3 the wind's reads 0.071 against autograd's 0.066 K per m/s)."""
    tab = rs.TableSize(texture_hit="first")

    def mean(w, pitch):
        cams = rs.make_camera(16, 20, hfov_deg=12.0, altitude_m=15.0, pitch_deg=pitch, dtype=F64)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            return rs.render(cams, rs.SeaScene(wind_speed=w, sea_temperature=290.0, seed=11, time_s=3.0, foam=False),
                             table=tab, output="brightness_temperature").mean()

    w = torch.tensor(10.0, dtype=F64, requires_grad=True)
    p = torch.tensor(-6.0, dtype=F64, requires_grad=True)
    gw, gp = torch.autograd.grad(mean(w, p), [w, p])
    h = 1e-2
    fw = (mean(torch.tensor(10.0 + h, dtype=F64), -6.0) - mean(torch.tensor(10.0 - h, dtype=F64), -6.0)) / (2 * h)
    fp = (mean(torch.tensor(10.0, dtype=F64), -6.0 + h) - mean(torch.tensor(10.0, dtype=F64), -6.0 - h)) / (2 * h)
    for g, f in ((gw, fw), (gp, fp)):
        assert math.isfinite(float(g)) and abs(float(g) - float(f)) < 0.1 * abs(float(f))


def test_sample_step_is_half_the_across_scaled_cosine_clamped():
    """The sweep's spacing (TableSize.texture_hit_*): across · cos θ̂ / 2 pixels, within [min_step, step]."""
    for cos_view, across, want in ((0.2, 1.0, 0.1), (0.2, 2.0, 0.2), (0.9, 2.0, 0.25), (0.02, 1.0, 1 / 32), (0.1, 3.0, 0.15)):
        assert sample_step(cos_view, 0.25, 1 / 32, across) == pytest.approx(want, rel=1e-15)
    torch.testing.assert_close(sample_step(torch.tensor([0.2, 0.9], dtype=F64), 0.25, 1 / 32, 2.0),
                               torch.tensor([0.2, 0.25], dtype=F64), rtol=1e-15, atol=0)


def test_sample_step_caps_the_samples_footprint_in_metres():
    """``finest`` [m] (TableSize.texture_hit_finest): where ``across`` · R δ exceeds it, the spacing s is
    finest · cos θ̂ / (2 R δ), i.e. the samples' footprint along the view 2 s R δ / cos θ̂ is ``finest``
    metres; where it does not, or with finest = 0, the spacing stays across · cos θ̂ / 2; never below
    min_step. Planted, the cap without its cosine: the footprint at cos θ̂ = 0.05 is 0.98 m, not 0.15 m,
    and the first check fails."""
    cos_v = np.array([0.05, 0.05, 0.3, 0.05])
    width = np.array([1.4, 0.1, 1.4, 40.0])  # R δ [m]
    s = sample_step(cos_v, 0.25, 1 / 512, 0.7, 0.15, width)
    fp = 2.0 * s * width / cos_v
    assert fp[0] == pytest.approx(0.15, rel=1e-14)  # 0.7 · 1.4 m > 0.15 m: capped
    assert s[1] == pytest.approx(0.35 * 0.05, rel=1e-14) and fp[1] == pytest.approx(0.07, rel=1e-14)  # below the cap
    assert fp[2] == pytest.approx(0.15, rel=1e-14) and s[2] < 0.25
    assert s[3] == 1 / 512  # the cap would ask for 9.4e-5 px: min_step holds
    assert np.array_equal(sample_step(cos_v, 0.25, 1 / 512, 0.7, 0.0, width), sample_step(cos_v, 0.25, 1 / 512, 0.7))
    got = sample_step(torch.tensor(cos_v), 0.25, 1 / 512, 0.7, 0.15, torch.tensor(width))
    torch.testing.assert_close(got, torch.tensor(s), rtol=1e-15, atol=0)
    assert sample_step(0.05, 0.25, 1 / 512, 0.7, 0.15, 1.4) == pytest.approx(float(s[0]), rel=1e-15)


@pytest.mark.parametrize("tracks, n", [(2.0, 2), (3.0, 3), (4.0, 4), (2.5, 2)])
def test_a_pixels_tracks_span_its_width_evenly(tracks, n):
    """With ``TableSize.texture_hit_tracks`` = n, a pixel averages the n tracks across its width: they
    lie at its centre ± (q − (n − 1)/2) δ/n, the midpoint rule of a box δ wide, also for pixels whose
    centres lie exactly on the grid φ_min + k δ of the least azimuth (where offsets of half a spacing
    would be rounding ties) and for the pixel at φ_min itself. Planted, the tracks not started (n − 1)/2 spacings before φ_min
    (sweep_layout): n = 2 rounds both of a pixel's tracks to one (or to its edges), n = 3 and 4 clamp
    the first pixel's left tracks, and every case fails. A non-whole ``tracks`` (2.5) takes n = ⌊tracks⌋
    tracks δ/n apart; planted, δ/tracks apart (as at first): they sit at ±0.2 δ or at −0.4 δ and 0 by
    turns, and that case fails."""
    wf = rs.SeaScene(wind_speed=10.0, sea_temperature=290.0, seed=1).wave_field(1, F64, torch.device("cpu"))
    ifov = 1e-3
    phi = torch.cat([0.3 + ifov * torch.arange(12, dtype=F64),  # centres on the grid of the least azimuth
                     0.3 + ifov * (torch.arange(12, dtype=F64) + 0.37)])
    tan_g = torch.full_like(phi, 0.08)
    sw = sweep_layout(wf, 0, torch.zeros(2, dtype=F64), torch.tensor(15.0, dtype=F64), tan_g, phi, ifov, math.inf,
                      step=0.25, min_step=1 / 64, across=0.7, tracks=tracks)
    j, got_n = pixel_tracks(phi, sw, tracks)
    assert got_n == n and j.shape == (n * phi.numel(),)
    j = j.reshape(n, -1)  # (block q: every pixel's track q)
    on_grid = slice(0, 12)
    for q in range(n):
        want = (q - 0.5 * (n - 1)) * ifov / n
        torch.testing.assert_close(sw.az[j[q]][on_grid] - phi[on_grid], torch.full((12,), want, dtype=F64),
                                   rtol=0, atol=1e-12)
    # off the grid: every track within the pixel's width, their mean within half a spacing of the centre
    off = slice(12, None)
    az = torch.stack([sw.az[jq][off] for jq in j])
    assert bool(((az - phi[off]).abs() <= 0.5 * ifov + 1e-12).all())
    assert bool(((az.mean(0) - phi[off]).abs() <= 0.5 * ifov / n + 1e-12).all())


_TURN_DELTA = 6.0 / 16  # the pixel size [deg] of _turned's camera


def _turned(yaw: float, tracks: float, seed, output: str = "radiance", **scene_kw) -> torch.Tensor:
    """A first-hit render (H, W) of a 12×16 camera over 6° (δ = 0.375°), 15 m up, 4° down, turned by ``yaw``
    [deg], with ``tracks`` per pixel: 10 m/s, no foam, no path; ``seed`` None: the expectation image."""
    cams = rs.make_camera(12, 16, hfov_deg=6.0, altitude_m=15.0, pitch_deg=-4.0, yaw_deg=yaw, dtype=F64)
    sc = rs.SeaScene(wind_speed=10.0, sea_temperature=290.0, time_s=3.0, path=False, foam=False, seed=seed, **scene_kw)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return rs.render(cams, sc, output=output, table=rs.TableSize(texture_hit="first", texture_hit_tracks=tracks))[0, 0]


@pytest.mark.parametrize("n", [2, 3])
def test_a_pixels_tracks_are_the_mean_of_one_track_renders_of_turned_cameras(n):
    """The n-track box across each pixel (TableSize.texture_hit_tracks = n) against its definition from
    outside the sweep: the mean of n one-track renders (each pixel its centre's track) from the camera
    turned in yaw by (q − (n − 1)/2) δ/n, whose pixel centres are the n tracks' azimuths (12×16 over 6°,
    15 m, 4° down, 10 m/s; texture = textured − expectation, radiance): equal to 3e-3 of the texture's
    standard deviation at worst (measured 1.3e-3 and 1.2e-3: the sweeps' layouts differ a little with the
    camera; the one-track render of the unturned camera is up to 1.2 and 0.9 standard deviations off).
    Planted, every block on the nearest track: 1.16 and 0.89, and the test fails."""
    def texture(yaw, tracks):
        return _turned(yaw, tracks, seed=11) - _turned(yaw, tracks, seed=None)

    box = texture(0.0, float(n))
    turned = sum(texture((q - 0.5 * (n - 1)) * _TURN_DELTA / n, 1.0) for q in range(n)) / n
    assert float((box - turned).abs().max()) < 3e-3 * float(box.std()), (float((box - turned).abs().max()), float(box.std()))
    assert float((texture(0.0, 1.0) - box).abs().max()) > 0.3 * float(box.std())  # (the box is not the line)


def test_the_glint_of_a_box_pixel_is_the_mean_over_its_tracks():
    """With two tracks per pixel the glint takes the mean of the centre ray's first hits on both (the
    resolved quantile and covariance): a sun 10° up ahead, 10 m/s, the camera of the test above,
    brightness temperature. The two-track image lies near the mean of the two one-track images turned
    by ∓δ/4 (the glint is not linear in the hit, so not on it): rms 0.10 of their difference (measured
    0.050 against 0.500 K). Planted, the glint from the first track alone (or the nearest, a rounding tie
    on alternating sides of the centre, as at first): 0.50, column-to-column stripes, and the test fails."""
    kw = dict(sun_zenith=math.radians(80.0), sun_azimuth=0.0, output="brightness_temperature")
    box = _turned(0.0, 2.0, seed=11, **kw)
    a, b = (_turned(s * _TURN_DELTA / 4, 1.0, seed=11, **kw) for s in (-1.0, 1.0))
    rms = lambda v: float(v.pow(2).mean().sqrt())  # noqa: E731
    assert rms(a - b) > 0.2 and rms(box - 0.5 * (a + b)) < 0.25 * rms(a - b), (rms(box - 0.5 * (a + b)), rms(a - b))


@pytest.mark.parametrize("earth_radius", [math.inf, 6.371e6])
def test_each_sample_is_filtered_at_the_footprint_of_the_volume_row_it_reads(earth_radius):
    """The sweep's samples read the texture volume at the row of their own view zenith (cos θ̂ with the
    local vertical tilted by r/R, as ``SweptTexture._swept_samples`` takes it), whose nodes split the
    waves at the footprint ``footprint(R(cos θ̂), cos θ̂, δ · 2 s(cos θ̂))`` (``TextureTable._scale``): the
    slopes a sample resolves must be those, on a flat and on a curved Earth, or near the horizon a wave
    band is counted twice or not at all. Written here from those two rules; equal to 1e-9 over three
    cameras (15, 20 and 300 m; 0.38°, 0.19° and 0.94° pixels). Planted, the sample's footprint from the
    flat sea's cos θ̂ on the curved Earth (as before 2026-11-27's evening): up to 20 % off at 15–20 m and
    4.5× at 300 m (review), and the test fails."""
    wf = rs.SeaScene(wind_speed=10.0, sea_temperature=290.0, seed=1).wave_field(1, F64, torch.device("cpu"))
    steps = dict(step=0.25, min_step=1 / 512, across=0.7, finest=0.15)
    for h, ifov in ((15.0, math.radians(6 / 16)), (20.0, math.radians(12 / 64)), (300.0, math.radians(30 / 32))):
        tan_g = torch.linspace(0.01, 0.12, 50, dtype=F64)
        sw = sweep_layout(wf, 0, torch.zeros(2, dtype=F64), torch.tensor(h, dtype=F64), tan_g, torch.zeros(50, dtype=F64),
                          ifov, earth_radius, tracks=2.0, **steps)
        cos_k = torch.sin(torch.atan(sw.flat_depression()) + 2.0 * sw.curv * sw.r).clamp(1e-9, 1.0)
        R = slant_range(cos_k, torch.tensor(h, dtype=F64), earth_radius)
        node = footprint(R, cos_k, ifov * 2.0 * sample_step(cos_k, **steps, width=R * ifov))
        torch.testing.assert_close(sw.footprint, node, rtol=1e-9, atol=0)


def test_flat_sea_depression_follows_the_earths_curvature():
    """On a sphere of radius R the sea point at horizontal distance r from a camera h above it lies at
    depression tan γ = (R + h − R cos(r/R)) / (R sin(r/R)) ≈ (h + r²/2R)/r: the flat-sea depression
    of the sweep and its envelope of a calm sea (η = 0) agree with the exact sphere to 1e-4 (5.7e-5:
    the small-angle form; R = 20 km here, so the curvature is 20 % of the depression at 400 m)."""
    R = 2.0e4
    r = torch.linspace(20.0, 400.0, 40, dtype=F64)
    zero = torch.zeros(1, dtype=F64)
    sw = Sweep(r, zero, r[:, None], 0 * r[:, None], r, torch.tensor(H_CAM, dtype=F64), 0.5 / R, 0.0, 1.0)
    exact = (R + H_CAM - R * torch.cos(r / R)) / (R * torch.sin(r / R))
    torch.testing.assert_close(sw.flat_depression(), exact, rtol=1e-4, atol=0)
    t, _ = sweep_envelope(sw, torch.zeros(r.shape[0], 1, dtype=F64))
    torch.testing.assert_close(t[0], exact, rtol=1e-4, atol=0)


def test_visible_samples_hold_every_point_a_ray_reaches():
    """Two crests (2 m at 100 m, 1.5 m at 140 m), camera 10 m up. A sample is seen where the straight line
    from the camera to it passes above every sample before it (brute force, each sample against all the
    nearer ones); the sweep reads texture only at :func:`visible_samples`: every seen sample is among
    them, every one of them is seen or bounds an element whose far end is, and the troughs behind the
    crests are left out. Planted, a selection of the near ends of visible elements only (the far end
    dropped) fails the first check."""
    r = torch.linspace(20.0, 400.0, 1901, dtype=F64)
    eta = _bump(r) + _bump(r, at=140.0, height=1.5, width=3.0)
    _, m = sweep_envelope(_sweep(r), eta[:, None])
    vis = visible_samples(m)[0]
    line = H_CAM - (H_CAM - eta)[None, :] * r[:, None] / r[None, :]  # [k', k]: the line to sample k at r_k'
    seen = torch.tensor([bool((line[:k, k] > eta[:k]).all()) for k in range(r.shape[0])])
    assert bool(vis[seen].all())
    assert bool((seen | torch.roll(seen, -1))[vis].all())
    assert float((~vis).double().mean()) > 0.05  # the shadows behind the crests (13 %)
    assert torch.equal(visible_samples(m.T, dim=0).T, visible_samples(m))  # the samples' axis first: the same


def test_sweep_until_keeps_every_window_that_reaches_its_least_depression():
    """A 2 m crest at 100 m and a 1.8 m deep trough about 200 m, camera 10 m up, |η| ≤ 2 m: the sweep cut
    by ``Sweep.until(0.05)`` (the flat point of depression 0.05 is at 200 m, in the trough; the ray meets
    the surface at ~236 m) still holds the first hit of every ray of depression ≥ 0.05 (brute force on a
    dense profile, to a sample), and each window [τ_top ≥ 0.05, τ_bottom] sees the share of the crest's
    near face and of the surface from 180 to 240 m (the trough's far side) that a brute-force fan of rays sees; ``covers`` says so. The
    shorter sweep ends within 10 m of where (h + η_max)/r = 0.05 (240 m). Planted, ``until`` ignoring
    η_max (a cut at the flat point): the rays beyond 200 m are lost, ``covers`` is False and the first
    check fails."""
    r = torch.linspace(20.0, 400.0, 3801, dtype=F64)
    profile = lambda x: _bump(x) - 1.8 * torch.exp(-0.5 * ((x - 215.0) / 25.0) ** 2)  # noqa: E731
    sw = Sweep(r, torch.zeros(1, dtype=F64), r[:, None], 0 * r[:, None], r, torch.tensor(H_CAM, dtype=F64), 0.0, 0.0,
               1.0, 2.0)
    short = sw.until(0.05)
    assert short.shape[0] < sw.shape[0] and abs(float(short.r[-1]) - 240.0) < 10.0
    assert torch.equal(short.r, r[:short.shape[0]])
    _, m = sweep_envelope(short, profile(short.r)[:, None])
    tau = torch.tensor([0.05, 0.051, 0.06, 0.08, 0.1, 0.2], dtype=F64)
    j = torch.zeros(tau.shape[0], dtype=torch.long)
    dense = torch.linspace(20.0, 400.0, 38001, dtype=F64)
    dense_eta = profile(dense)
    k, hit = centre_element(m, j, tau)
    for i, t in enumerate(tau.tolist()):
        truth = _brute_first_hit(dense, dense_eta, t)
        assert bool(hit[i]) and abs(float(short.r[k[i]]) - truth) <= 0.11, (t, float(short.r[k[i]]), truth)
    t_top = torch.tensor([0.05, 0.055, 0.075], dtype=F64)
    t_bot = torch.tensor([0.054, 0.07, 0.09], dtype=F64)
    jw = torch.zeros(3, dtype=torch.long)
    assert covers(m, jw, t_top)
    face = ((r <= 100.0) & (r >= 88.0)) | ((r >= 180.0) & (r <= 240.0))
    values = face.to(F64)[None, None, :short.shape[0]]
    avg = visible_average(m, values, jw, t_top, t_bot)
    for i in range(3):  # brute force: a fan of 400 rays over the window, each marched on the dense profile at once
        fan = torch.linspace(float(t_top[i]), float(t_bot[i]), 402, dtype=F64)[1:-1, None]
        below = (H_CAM - fan * dense[None, :]) <= dense_eta[None, :]
        hits = dense[below.to(torch.int8).argmax(1)]
        share = float((((hits <= 100.0) & (hits >= 88.0)) | ((hits >= 180.0) & (hits <= 240.0))).to(F64).mean())
        assert abs(float(avg[0, i]) - share) < 0.02, (i, float(avg[0, i]), share)


def test_visible_samples_within_the_windows_hold_what_their_rays_reach():
    """The same two crests; the windows of a track span the depressions [0.06, 0.09]. Every sample that a
    ray of those depressions reaches (seen, brute force as above, at a depression within them) is among
    ``visible_samples(m, window=...)``, so are both ends of the element each ray of them first meets (a
    brute-force march on the samples, 31 rays from 0.06 to 0.09: the partial elements at the windows'
    edges), and each selected sample lies between the first hits of the steepest and shallowest rays,
    one sample either side; samples before and beyond (the flat sea in front, the far field) are left
    out. Planted, the window tested on the element's near end only (m[k] ≤ hi instead of m[k + 1] ≤ hi):
    the steepest ray's element loses its near end; the window ignored: the last check fails."""
    r = torch.linspace(20.0, 400.0, 1901, dtype=F64)
    eta = _bump(r) + _bump(r, at=140.0, height=1.5, width=3.0)
    t, m = sweep_envelope(_sweep(r), eta[:, None])
    lo, hi = 0.06, 0.09
    sel = visible_samples(m, window=(torch.tensor([[lo]], dtype=F64), torch.tensor([[hi]], dtype=F64)))[0]
    line = H_CAM - (H_CAM - eta)[None, :] * r[:, None] / r[None, :]
    seen = torch.tensor([bool((line[:k, k] > eta[:k]).all()) for k in range(r.shape[0])])
    reached = seen & (t[0] >= lo) & (t[0] <= hi)
    assert int(reached.sum()) > 50 and bool(sel[reached].all())
    for tau in torch.linspace(lo, hi, 31, dtype=F64).tolist():
        k = int(((H_CAM - tau * r) <= eta).to(torch.int8).argmax())
        assert bool(sel[k - 1]) and bool(sel[k]), tau
    first, last = _brute_first_hit(r, eta, hi), _brute_first_hit(r, eta, lo)
    dr = float(r[1] - r[0]) * 1.01
    assert bool(((r[sel] >= first - dr) & (r[sel] <= last + dr)).all())
    assert int(sel.sum()) < int(visible_samples(m)[0].sum())


def test_pixel_hits_is_the_average_and_the_centre_hit_of_one_search():
    """:func:`pixel_hits` (one search for the windows' edges and the centre rays) gives what
    :func:`visible_average` and :func:`centre_element` give apart, on a crest with tracks of different
    lengths of ray lists."""
    r = torch.linspace(20.0, 400.0, 3801, dtype=F64)
    eta = torch.stack([_bump(r), _bump(r, at=60.0, height=1.0)], 1)
    sw = Sweep(r, torch.zeros(2, dtype=F64), r[:, None].expand(-1, 2), 0 * r[:, None].expand(-1, 2), r,
               torch.tensor(H_CAM, dtype=F64), 0.0, 0.0, 1.0)
    _, m = sweep_envelope(sw, eta)
    tau = torch.linspace(0.03, 0.4, 23, dtype=F64)
    j = (torch.arange(23) % 3 == 0).long()
    top, bottom = pixel_windows(tau, 0.01)
    values = torch.stack([torch.sin(r / 7.0)[None, :].expand(2, -1), torch.ones(2, r.shape[0], dtype=F64)])
    avg, k, hit = pixel_hits(m, values, j, top, bottom, tau)
    torch.testing.assert_close(avg, visible_average(m, values, j, top, bottom), rtol=0, atol=0)
    k0, hit0 = centre_element(m, j, tau)
    assert torch.equal(k, k0) and torch.equal(hit, hit0)


@pytest.fixture(scope="module")
def grazing_ray_trace():
    """The camera both swept-render tests compare on (10 m/s upwind, 15 m mast, 4.5° down, 16×32 pixels
    over 6°: view zenith 85–88°) and its brute-force ray traces (16 rays per pixel) of seeds 11, 12 and 13,
    traced once."""
    cams = rs.make_camera(16, 32, hfov_deg=6.0, altitude_m=15.0, pitch_deg=-4.5, dtype=F64)
    return cams, {seed: raytraced_image(cams, 10.0, seed=seed, time_s=3.0, rays_per_pixel=16) for seed in (11, 12, 13)}


def _against_the_ray_tracer(cams, rays, table, seed: int = 11) -> tuple[float, float]:
    """σ of the render's clutter about the row means over the ray tracer's (its sampling variance
    removed), and their noise-corrected per-pixel correlation, on realization ``seed`` of ``rays``."""
    ray = rays[seed]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        img = rs.render(cams, rs.SeaScene(wind_speed=10.0, sea_temperature=290.0, seed=seed, time_s=3.0, foam=False,
                                          path=False), output="brightness_temperature", table=table)
    tb, noise = ray["brightness_temperature"][0, 0], ray["brightness_temperature_noise_var"][0, 0]
    a = img.reshape(tb.shape) - img.reshape(tb.shape).mean(1, keepdim=True)
    b = tb - tb.mean(1, keepdim=True)
    sigma_a, sigma_b = float((a * a).mean().sqrt()), float(((b * b).mean() - noise.mean()).sqrt())
    return sigma_a / sigma_b, float((a * b).mean()) / (sigma_a * sigma_b)


def test_swept_render_matches_the_ray_tracer_near_grazing(grazing_ray_trace):
    """The swept texture against the brute-force ray tracer of the same realization (10 m/s upwind, 15 m
    mast, 4.5° down, 16×32 pixels over 6°: view zenith 85–88°, the pixel size of
    pipelines/texture_vs_raytrace.py): the clutter about the row means has σ within 0.85–1.2 of the
    ray-traced one and a per-pixel correlation ≥ 0.9, both with the ray tracer's sampling noise (16 rays
    per pixel) removed. (Measured on seed 11 0.968 and 0.981 with the sweep's defaults, 0.94–0.98 and
    1.006–1.010 on seeds 12 and 13; with one track per pixel and no cap on the samples' footprint, the
    defaults until 2026-11-27's evening, 0.96 and 0.963; before the tiles were turned 1.00 and 1.006, and
    0.95 and 0.997 with the spacings before 2026-11-27, across 1 and min step 1/32; the flat point gives
    0.17 and 0.13.) Planted (on the former defaults), the visible samples' texture scattered back in the
    wrong layout (sample-major, not track-major): 0.49 and −0.02."""
    ratio, r = _against_the_ray_tracer(*grazing_ray_trace, rs.TableSize(texture_hit="first"))
    assert 0.85 < ratio < 1.2 and r > 0.9, (ratio, r)


def test_visibility_on_the_finer_elevation_matches_the_ray_tracer(grazing_ray_trace):
    """``TableSize.texture_hit_visibility=0.5`` (the running horizon on the elevation at half the samples'
    footprint, twice the samples, node values still at the full footprint) against the brute-force ray
    tracer on the camera of :func:`test_swept_render_matches_the_ray_tracer_near_grazing` (10 m/s upwind,
    view zenith 85–88°): averaged over three realizations (seeds 11, 12, 13), σ of the clutter within
    0.95–1.1 of the ray-traced one and the noise-corrected per-pixel correlation > 0.98. (Measured with
    the sweep's defaults since 2026-11-27's evening: 0.975 and 1.000, one realization's r 0.982–1.013;
    with the former ones 0.97 and 0.991, one realization's r 0.967–1.005; on seed 11 before the tiles were turned 1.01 and 1.007, the
    default v = 1 1.00 and 1.006; with the spacings before 2026-11-27, 0.989 and 0.9986 against 0.965 and
    0.9969.) Planted, the node values read at the finer footprint too (the texture smoothed less, the
    slopes' response not that of the pixel's band window): σ 0.880, r 0.993 (seed 11 alone, before the
    tiles were turned: σ 0.897); the layout not refined, its values read at twice its footprint: σ 1.061,
    r 0.971 (per seed 0.948, 0.987, 0.977; seed 11 before the tiles were turned: r 0.949)."""
    table = rs.TableSize(texture_hit="first", texture_hit_visibility=0.5)
    got = [_against_the_ray_tracer(*grazing_ray_trace, table, seed) for seed in (11, 12, 13)]
    ratio, r = (sum(v) / len(got) for v in zip(*got))
    assert 0.95 < ratio < 1.1 and r > 0.98, got


@pytest.mark.usefixtures("one_thread")
def test_first_hit_texture_nodes_resolve_the_model_response():
    """The first hit reads the model's response at the resolved slope as it is, through a Chebyshev–Lobatto
    volume in x = a/σ_a; near grazing that response is strongly curved. The default (TableSize.texture_first
    = 25) equals a converged 65-node volume to an rms of 1 % of the clutter's standard deviation and 0.02 K
    at most (5 m/s upwind, 15 m mast, 6° down, 48×64 over 12°, float64; measured 0.25 % and 4.7 mK; 17
    nodes, the default before the sweep's finer samples of 2026-11-27, 1.1 % and 11 mK). With 9 nodes
    the error is 72 % rms and 0.40 K, with a +0.16 K bias, and the test fails. Planted, the volume read
    in x over the fine grid's overhang beyond the nodes (±width (1 + ex), as before 2026-11-27): the
    65-node polynomial extrapolated there reaches 8900 (radiance units) against 3 at the nodes, a
    sample of the sweep reads it, rms 0.60 K, and the test fails."""
    cams = rs.make_camera(48, 64, hfov_deg=12.0, altitude_m=15.0, pitch_deg=-6.0, dtype=torch.float64)
    kw = dict(wind_speed=5.0, sea_temperature=290.0, foam=False, path=False)
    sea = rs.view_geometry(cams).is_sea[0]

    def render(table):
        return rs.render(cams, rs.SeaScene(**kw, seed=11, time_s=3.0), output="brightness_temperature", table=table)[0, 0]

    default = render(rs.TableSize(texture_hit="first"))
    converged = render(rs.TableSize(texture_hit="first", texture_first=65))
    clutter = (converged - rs.render(cams, rs.SeaScene(**kw), output="brightness_temperature")[0, 0])[sea]
    err = (default - converged)[sea]
    assert float(err.pow(2).mean().sqrt()) < 0.01 * float(clutter.std()), (err.pow(2).mean().sqrt(), clutter.std())
    assert float(err.abs().max()) < 0.02, err.abs().max()


def test_first_hit_texture_rows_stay_within_the_volumes_nodes():
    """The sweep's samples reach beyond the pixels' rows (the running horizon starts nearer, windows
    overhang by half a pixel), and a sunny scene's volume has 65 ζ nodes (TableSize.texture_zenith_sun).
    Read within the nodes' range in ζ, its image with 65 and with 129 nodes agree to 5 mK (sun 10° up
    ahead, 10 m/s, 24×32 over 30° from 20 m, 10° down; measured 0.9 mK). Planted, the samples read the
    fine grid's overhang in ζ, where the nodes' polynomial is extrapolated (as at first): 7.6 K apart,
    and the test fails."""
    cams = rs.make_camera(24, 32, hfov_deg=30.0, altitude_m=20.0, pitch_deg=-10.0, dtype=F64)
    sc = rs.SeaScene(wind_speed=10.0, sea_temperature=290.0, seed=11, time_s=3.0, path=False,
                     sun_zenith=math.radians(80.0), sun_azimuth=0.0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        a, b = (rs.render(cams, sc, output="brightness_temperature",
                          table=rs.TableSize(texture_hit="first", texture_zenith_sun=nz))[0, 0] for nz in (65, 129))
    assert float((a - b).abs().max()) < 5e-3, float((a - b).abs().max())


def test_across_view_slope_texture_matches_the_ray_tracer_crosswind():
    """Looking across a 10 m/s wind from 20 m, 9° down (16×64 pixels over 12°, view zenith ≈ 80–82.5°, the
    comparison pipeline's pixel size), the resolved slope across the line of sight carries much of the
    clutter's pattern (steep oblique crests: it turns the reflected ray sideways). The first hit with its
    across-view texture (``TableSize.texture_hit_cross``, default) correlates with the brute-force ray
    trace of the same realization at ≥ 0.94 per pixel and after 4×4 block averaging, the ray tracer's
    sampling noise (16 rays per pixel) removed. (Measured 0.957 and 0.955; without it, ``texture_hit_cross
    =False``, 0.920 and 0.897, and the test fails. With one track per pixel, the sweep's default until
    2026-11-27's evening, 0.95 and 0.986 against 0.83 and 0.65: the two tracks across each pixel now
    carry part of what the across-view texture gave.)"""
    cams = rs.make_camera(16, 64, hfov_deg=12.0, altitude_m=20.0, pitch_deg=-9.0, dtype=F64)
    ray = raytraced_image(cams, 10.0, seed=11, time_s=3.0, wind_direction=math.pi / 2, rays_per_pixel=16)
    tb, noise = ray["brightness_temperature"][0, 0], ray["brightness_temperature_noise_var"][0, 0]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        img = rs.render(cams, rs.SeaScene(wind_speed=10.0, wind_direction=math.pi / 2, sea_temperature=290.0, seed=11,
                                          time_s=3.0, foam=False, path=False), output="brightness_temperature",
                        table=rs.TableSize(texture_hit="first"))[0, 0]
    a, b = img - img.mean(1, keepdim=True), tb - tb.mean(1, keepdim=True)

    def blocks(x):
        return x.reshape(4, 4, 16, 4).mean((1, 3))

    r = float((a * b).mean() / (a.pow(2).mean() * (b.pow(2).mean() - noise.mean())).sqrt())
    ab, bb = blocks(a), blocks(b)
    r4 = float((ab * bb).mean() / (ab.pow(2).mean() * (bb.pow(2).mean() - blocks(noise).mean() / 16)).sqrt())
    assert r > 0.94 and r4 > 0.94, (r, r4)


def test_across_view_slope_texture_keeps_the_mean():
    """The across-view term g y + h (y² − 1) has mean 0 over y ~ N(0, 1) (its quadratic's mean is the
    along-view node value): over 4 seeds of a 48×64 crosswind image (10 m/s, 20 m mast, 8° down) the
    render with it differs from the render without by a mean under a tenth of the difference's rms (measured
    0.002 K against 0.040 K). Planted, the −1 dropped (the node value at y = 0 taken as the mean): 0.031 K
    against 0.052 K, and the test fails."""
    cams = rs.make_camera(48, 64, hfov_deg=12.0, altitude_m=20.0, pitch_deg=-8.0, dtype=F64, batch_size=4)
    sc = rs.SeaScene(wind_speed=10.0, wind_direction=math.pi / 2, sea_temperature=290.0, seed=[1, 2, 3, 4], time_s=3.0,
                     foam=False, path=False)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        on, off = (rs.render(cams, sc, output="brightness_temperature",
                             table=rs.TableSize(texture_hit="first", texture_hit_cross=c)) for c in (True, False))
    d = on - off
    assert float(d.pow(2).mean().sqrt()) > 0.01  # the term is there
    assert abs(float(d.mean())) < 0.1 * float(d.pow(2).mean().sqrt()), (d.mean(), d.pow(2).mean().sqrt())


def _ensemble_offsets(ray_shadowing, options) -> dict:
    """Mean first-hit render − ray trace [K] over 12 seeds (10 m/s across the view from 20 m, 4° down, 8×32
    over 6°, view zenith ≈ 85–87°; the trace's untraced waves masked by ``ray_shadowing``, 2 rays per
    pixel), for the paper's Eq. 5 (``True``) and each of ``options`` (SeaScene shadowing), on the same seeds."""
    seeds = list(range(100, 112))
    cams = rs.make_camera(8, 32, hfov_deg=6.0, altitude_m=20.0, pitch_deg=-4.0, batch_size=len(seeds), dtype=F64)
    ray = raytraced_image(cams, 10.0, seed=seeds, time_s=3.0, wind_direction=math.pi / 2, rays_per_pixel=2,
                          shadowing=ray_shadowing)["brightness_temperature"]
    off = {}
    for sh in (True, *options):
        sc = rs.SeaScene(wind_speed=10.0, wind_direction=math.pi / 2, sea_temperature=290.0, seed=seeds, time_s=3.0,
                         foam=False, path=False, shadowing=sh)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            tex = rs.render(cams, sc, output="brightness_temperature", table=rs.TableSize(texture_hit="first"))
        off[sh] = float((tex - ray).mean())
    return off


def test_first_hit_with_correlated_shadowing_meets_the_ray_traced_ensemble_mean():
    """The ensemble mean near grazing (issue criterion: within 0.05 K of the ray-traced one). Looking across a
    10 m/s wind from 20 m, 4° down (8×32 pixels over 6°, view zenith ≈ 85–87°), 12 seeds: the first-hit
    render with ``SeaScene(shadowing="correlated")`` minus the brute-force ray trace of the same realizations
    (2 rays per pixel) is within 0.05 K on average (measured +0.000 ± 0.007 K), and on the same seeds
    at least 0.02 K below the paper's Eq. 5 for the unresolved part (the default: +0.032 ± 0.007 K; the
    paired difference has no seed-to-seed noise of the waves), so that the option is seen to act: planted,
    the option ignored, the difference is 0 and the test fails. (+0.060 ± 0.005 K for Eq. 5 with the
    sweep's coarser samples and one track per pixel, the defaults until 2026-11-27's evening: Eq. 5 leaves
    out how the waves between 10 cm and the sweep's footprint hide one another, fewer of them since the
    samples' footprint is at most 0.15 m.)"""
    off = _ensemble_offsets(True, ("correlated",))
    assert abs(off["correlated"]) < 0.05 and off[True] - off["correlated"] > 0.02, off


def test_first_hit_with_multiscale_masking_meets_the_ray_traced_ensemble_mean():
    """The same camera and seeds with ``SeaScene(shadowing="multiscale")``, against the ray trace whose untraced
    waves (k > 64 rad/m) take the same masking, so that both treat every wave alike: the first hit renders the
    resolved waves' hiding, the option the rest's, and the ensemble means agree within 0.05 K (measured
    −0.008 ± 0.007 K; −0.016 ± 0.005 K with the sweep's defaults until 2026-11-27's evening). The paper's
    Eq. 5 for the unresolved part is +0.106 K off this trace (+0.135 K before), the correlated masking
    +0.074 K (+0.096 K); on the same seeds Eq. 5 is at least 0.08 K above the option (measured 0.114 K;
    planted, the option ignored: 0, and the test fails)."""
    off = _ensemble_offsets("multiscale", ("multiscale",))
    assert abs(off["multiscale"]) < 0.05 and off[True] - off["multiscale"] > 0.08, off

"""The reflected sun in the expectation (roughsea_torch.sun): Cox & Munk's glitter formula where the
slopes are broad, a mirror on a flat sea, energy conservation over all view directions, finite
gradients on a calm sea, and float32/float64 agreement."""

import math

import numpy as np
import pytest
import torch

import roughsea_torch as rs
import roughsea_torch.reference as ref
from roughsea_torch.sun import _ellipse_probability

from conftest import M11

M = 1.35 + 0.01j  # a water-like index (the glint scales with ρ; any n, k serves)


def _unit(zenith, azimuth):
    return np.array([math.sin(zenith) * math.cos(azimuth), math.sin(zenith) * math.sin(azimuth), math.cos(zenith)])


def _fresnel(c, m=M):
    """Unpolarized Fresnel reflectance, written out (independent of roughsea_torch.optics)."""
    m2 = m * m
    root = np.sqrt(m2 - (1 - c * c) + 0j)
    rs_ = abs((c - root) / (c + root)) ** 2
    rp_ = abs((m2 * c - root) / (m2 * c + root)) ** 2
    return 0.5 * (rs_ + rp_)


def _cox_munk_glitter(th, ph, ts, ps, var, E):
    """ρ E N(s_g) / (4 cos θ̂ cos⁴β): Cox & Munk (1954), the glitter of a sun of irradiance E."""
    v, w = _unit(th, ph), _unit(ts, ps)
    h = (v + w) / np.linalg.norm(v + w)
    s = h[:2] / h[2]
    S = np.array([[var[0], var[2]], [var[2], var[1]]])
    N = math.exp(-0.5 * s @ np.linalg.solve(S, s)) / (2 * math.pi * math.sqrt(np.linalg.det(S)))
    return _fresnel(h @ v) * E * N / (4 * math.cos(th) * h[2] ** 4)


@pytest.mark.parametrize("th,ph,ts,ps", [(60, 0.3, 30, 0.3 + math.pi), (80, 0.0, 60, math.pi), (30, 1.0, 20, 2.0)])
def test_broad_slopes_give_cox_munk_glitter(th, ph, ts, ps):
    """High sun, slopes far broader than the disk, no shadowing or masking: the closed form, 1e-3."""
    var = (3.16e-3 * 10, 0.003 + 1.92e-3 * 10, 0.0)  # anisotropic Cox–Munk, 10 m/s
    th, ts = math.radians(th), math.radians(ts)
    slopes = rs.SlopeStatistics.from_variances(*var)
    got = rs.glint_radiance(torch.tensor(th, dtype=torch.float64), ph, slopes, M, rs.Sun(ts, ps, 10.0),
                            shadowing=False, sun_masking=False)
    want = _cox_munk_glitter(th, ph, ts, ps, var, 10.0)
    assert abs(float(got) / want - 1) < 1e-3


def test_flat_sea_mirrors_the_sun():
    """A flat sea: ρ L_sun inside the sun's mirror image, nothing outside it."""
    th = math.radians(70.0)
    flat = rs.SlopeStatistics(0.0, 0.0)
    sun_in = rs.Sun(th + math.radians(0.2), math.pi, 10.0)  # 0.2° inside the 0.267° disk
    sun_out = rs.Sun(th + math.radians(0.3), math.pi, 10.0)
    L = 10.0 / float(sun_in.solid_angle)
    got_in = float(rs.glint_radiance(torch.tensor(th, dtype=torch.float64), 0.0, flat, M, sun_in))
    got_out = float(rs.glint_radiance(torch.tensor(th, dtype=torch.float64), 0.0, flat, M, sun_out))
    assert abs(got_in / (_fresnel(math.cos(th)) * L) - 1) < 1e-6  # the flat facet's own ρ(θ̂)
    assert got_out == 0.0


def test_energy_is_conserved_over_all_view_directions():
    """∫ R_glint cos θ̂ dω over the view hemisphere = E cos θ_s ∫ N(s) t_sun(s) ρ(Ω_sun(s)) ds over the
    facets that reflect the sun upwards (Eq. 4 bookkeeping: each facet intercepts sunlight by its
    projected area towards the sun and sends ρ of it into one direction); 5 m/s, sun at 40°."""
    var = 0.003 + 5.12e-3 * 5
    slopes = rs.SlopeStatistics.from_variances(var / 2, var / 2, 0.0)
    ts, ps, E = math.radians(40.0), 0.0, 10.0
    # left: Gauss–Legendre over cos θ̂ ∈ [0, 1] and φ̂
    xc, wc = np.polynomial.legendre.leggauss(160)
    xp, wp = np.polynomial.legendre.leggauss(128)
    c = torch.tensor(0.5 * (xc + 1), dtype=torch.float64)[:, None]
    phi = torch.tensor(math.pi * (xp + 1), dtype=torch.float64)[None, :]
    R = rs.glint_radiance(torch.acos(c), phi, slopes, M, rs.Sun(ts, ps, E), shadowing=False, sun_masking=False)
    W = torch.tensor(0.5 * wc, dtype=torch.float64)[:, None] * torch.tensor(math.pi * wp, dtype=torch.float64)[None, :]
    left = float((R * c * W).sum())
    # right: a fine slope grid, mirror directions of the sun kept where they point up
    g = np.linspace(-1.2, 1.2, 1201)
    sx, sy = np.meshgrid(g, g, indexing="ij")
    N = np.exp(-0.5 * (sx**2 + sy**2) / (var / 2)) / (2 * math.pi * var / 2)
    n = np.stack([-0 * sx + sx, sy, np.ones_like(sx)], -1) / np.sqrt(1 + sx**2 + sy**2)[..., None]  # ∝ (s, 1)
    w = _unit(ts, ps)
    cos_i = n @ w
    r = 2 * cos_i[..., None] * n - w  # the reflected sun
    t_sun = cos_i * np.sqrt(1 + sx**2 + sy**2)  # cos Ω / cos β
    keep = (cos_i > 0) & (r[..., 2] > 0)
    right = E * float((N * t_sun * _fresnel(cos_i) * keep).sum()) * (g[1] - g[0]) ** 2
    assert abs(left / right - 1) < 2e-3


def test_ellipse_probability_against_closed_forms():
    """The Gaussian mass of a disk about the mean is 1 − exp(−r²/2) (Rayleigh); of a small far disk,
    π r² φ₂(c) (1 + r²(|c|² − 2)/8) (Taylor)."""
    t = lambda v: torch.tensor(v, dtype=torch.float64)  # noqa: E731
    for r in (0.3, 1.0, 3.0):
        p, _, _ = _ellipse_probability(t(0.0), t(0.0), t(1 / r**2), t(0.0), t(1 / r**2), t(1 / r**4))
        assert abs(float(p) - (1 - math.exp(-r * r / 2))) < 1e-9
    r, c = 0.05, (1.5, -0.7)
    p, m1, m2 = _ellipse_probability(t(c[0]), t(c[1]), t(1 / r**2), t(0.0), t(1 / r**2), t(1 / r**4))
    assert abs(float(m1 / p) - c[0]) < 1e-3 and abs(float(m2 / p) - c[1]) < 1e-3  # the disk's centroid
    c2 = c[0] ** 2 + c[1] ** 2
    want = math.pi * r * r * math.exp(-c2 / 2) / (2 * math.pi) * (1 + r * r * (c2 - 2) / 8)
    assert abs(float(p) / want - 1) < 1e-6


def test_small_ellipse_closed_form_against_the_noncentral_chi_square():
    """A disk of radius 0.2 (tr S = 0.08, inside the closed form's range) at several distances from
    the mean: its Gaussian mass is the noncentral χ² CDF with 2 degrees of freedom (scipy), to 1e-6
    relative; the second-order rule alone (the earlier one) is 2e-5 to 5e-4 off here."""
    from scipy.stats import ncx2

    t = lambda v: torch.tensor(v, dtype=torch.float64)  # noqa: E731
    r = 0.2
    for c in ((1.5, -0.7), (2.5, 1.0), (0.3, 0.2), (3.5, 0.0)):
        p, _, _ = _ellipse_probability(t(c[0]), t(c[1]), t(1 / r**2), t(0.0), t(1 / r**2), t(1 / r**4))
        want = ncx2.cdf(r * r, 2, c[0] ** 2 + c[1] ** 2)
        assert abs(float(p) / want - 1) < 1e-6


def test_sun_masking_is_smith_g1():
    """sun_masking multiplies by Smith's G1 = 1/(1 + Λ(θ_sun)) (zero-mean slopes), Λ in closed form."""
    var = 0.003 + 5.12e-3 * 12
    slopes = rs.SlopeStatistics.from_variances(var / 2, var / 2, 0.0)
    th, ts = torch.tensor(math.radians(70.0), dtype=torch.float64), math.radians(80.0)
    sun = rs.Sun(ts, math.pi, 10.0)
    on = rs.glint_radiance(th, 0.0, slopes, M, sun, sun_masking=True)
    off = rs.glint_radiance(th, 0.0, slopes, M, sun, sun_masking=False)
    mu = (math.cos(ts) / math.sin(ts)) / math.sqrt(var / 2)
    lam = (math.exp(-mu * mu / 2) / math.sqrt(2 * math.pi) - mu * 0.5 * math.erfc(mu / math.sqrt(2))) / mu
    assert abs(float(on / off) * (1 + lam) - 1) < 1e-9
    assert lam > 0.05  # a low sun: the check is not trivial


def test_no_sun_below_the_horizon_and_none_changes_nothing():
    s = rs.SlopeStatistics.cox_munk(8.0)
    th = torch.tensor(math.radians(75.0), dtype=torch.float64)
    below = rs.glint_radiance(th, 0.0, s, M, rs.Sun(math.radians(95.0), math.pi, 10.0))
    assert float(below) == 0.0
    a = rs.apparent_radiance(th, 0.0, s, M, sea_radiance=30.0, sky=12.0)
    b = rs.apparent_radiance(th, 0.0, s, M, sea_radiance=30.0, sky=12.0, sun=None)
    assert torch.equal(a, b)
    c = rs.apparent_radiance(th, 0.0, s, M, sea_radiance=30.0, sky=12.0, sun=rs.Sun(math.radians(60.0), math.pi, 10.0))
    assert float(c) > float(a)


@pytest.mark.parametrize("wind", [0.0, 1.0, 8.0])
def test_gradients_with_respect_to_the_sun_are_finite_and_right(wind):
    """d R_glint / d(sun zenith, sun azimuth) against a float64 central difference, a calm sea included
    (the disk's edge is sharp there, but the Gaussian mass of the ellipse is smooth)."""
    slopes = rs.SlopeStatistics.cox_munk(wind)
    th = torch.tensor(math.radians(70.0), dtype=torch.float64)

    def f(z, a):
        return rs.glint_radiance(th, 0.05, slopes, M, rs.Sun(z, a, 10.0))

    z = torch.tensor(math.radians(69.0), dtype=torch.float64, requires_grad=True)
    a = torch.tensor(math.pi, dtype=torch.float64, requires_grad=True)
    gz, ga = torch.autograd.grad(f(z, a), (z, a))
    h = 1e-6
    for g, fd in ((gz, (f(z.detach() + h, a.detach()) - f(z.detach() - h, a.detach())) / (2 * h)),
                  (ga, (f(z.detach(), a.detach() + h) - f(z.detach(), a.detach() - h)) / (2 * h))):
        assert torch.isfinite(g)
        assert abs(float(g) - float(fd)) <= 1e-4 * abs(float(fd)) + 1e-6


@pytest.mark.parametrize("wind", [0.0, 0.3, 5.0, 15.0])
def test_float32_agrees_with_float64(wind):
    out = {}
    for dt in (torch.float32, torch.float64):
        out[dt] = rs.glint_radiance(torch.tensor(1.0, dtype=dt), 0.3, rs.SlopeStatistics.cox_munk(torch.tensor(wind, dtype=dt)),
                                    M, rs.Sun(0.6, 0.3 + math.pi, 10.0))
    assert out[torch.float32].dtype == torch.float32
    assert abs(float(out[torch.float32].double() / out[torch.float64]) - 1) < 1e-4


def test_bad_sun_is_a_value_error():
    with pytest.raises(ValueError, match="irradiance"):
        rs.Sun(0.5, 0.0, -1.0)
    with pytest.raises(ValueError, match="sun"):
        rs.apparent_radiance(1.0, 0.0, rs.SlopeStatistics.cox_munk(5.0), M, sea_radiance=30.0, sky=10.0, sun=(0.5, 0.0, 10.0))


def _sunny_scene(sun, **kw):
    return rs.SeaScene(wind_speed=torch.tensor([5.0, 10.0]), sea_temperature=290.0, band=rs.MWIR, sun=sun, **kw)


def test_render_with_sun_matches_per_pixel_evaluation_and_leaves_out_what_sees_no_glint():
    """MWIR, sun ahead of the camera 20° and 10° above the horizon: the table render equals the
    per-pixel evaluation (the glint itself is per pixel) to 1e-6 and the glint is strong (the
    brightest pixel well above the sea's own radiance); a sun behind the camera on these seas
    changes no pixel beyond rounding (the sunless render takes the in-place pixel path, the sunny one
    the general path: 3.4e-16 relative measured)."""
    cams = rs.make_camera(32, 40, hfov_deg=20.0, altitude_m=20.0, pitch_deg=-5.0, batch_size=2, dtype=torch.float64)
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


@pytest.mark.parametrize("th_deg,sun_deg", [(60.0, 58.0), (80.0, 78.0), (86.0, 85.0)])
def test_glint_of_the_two_scales_averages_to_the_expectation_glint(th_deg, sun_deg):
    """The two-scale pixel's glint (its unresolved Gaussian about the visible resolved slope a'(x))
    averaged over x ~ N(0, 1) equals the glint of the total slope law (the mixture identity the
    texture rests on, here with the sun's disk as the sky), 1e-4; with the sun-side masking of the
    total law on both (the renderer's choice), likewise. (Each pixel's own unresolved G1 would not
    average to it: 1 % off at 80°, 11 % at 86°.)"""
    from roughsea_torch.clutter import unresolved_statistics, visible_slope

    dt = torch.float64
    th, ph = torch.tensor(math.radians(th_deg), dtype=dt), torch.tensor(0.2, dtype=dt)
    vx, vy, cxy = (torch.tensor(v, dtype=dt) for v in (0.02, 0.014, 0.002))
    var_a, kap = torch.tensor(0.008, dtype=dt), torch.tensor(0.15, dtype=dt)
    c, s_ = torch.cos(ph), torch.sin(ph)
    suu = vx * c * c + 2 * cxy * c * s_ + vy * s_ * s_
    x, w = np.polynomial.hermite_e.hermegauss(120)
    x, w = torch.tensor(x, dtype=dt), torch.tensor(w / w.sum(), dtype=dt)
    ap = visible_slope(x[None], torch.cos(th)[None], torch.sin(th)[None], var_a.sqrt()[None], (suu - var_a).sqrt()[None])[0]
    sun = rs.Sun(math.radians(sun_deg), 0.2 + math.pi, 12.0)
    law = rs.SlopeStatistics.from_variances(vx, vy, cxy)
    parts = rs.glint_radiance(th, ph, unresolved_statistics(vx, vy, cxy, ph, var_a, kap, ap), M, sun, sun_masking=False)
    total = rs.glint_radiance(th, ph, law, M, sun, sun_masking=False)
    assert abs(float((w * parts).sum() / total) - 1) < 1e-4
    g1 = rs.sun.sun_masking_factor(law, sun)
    masked = rs.glint_radiance(th, ph, law, M, sun, sun_masking=True)
    assert abs(float((w * parts * g1).sum() / masked) - 1) < 1e-4
    assert float(parts.max() / parts.min()) > 1.5  # the texture of the glint is real


def test_textured_glint_table_matches_per_pixel():
    """A textured MWIR sea with the sun ahead: table render against per-pixel evaluation, 2e-4 (4.8e-5
    measured; the glint is per pixel in both, the table's reading its pixel's visible quantile x' from
    the texture volume where per-pixel evaluation inverts the visible-slope distribution; with the
    night's 33 texture ζ nodes, TableSize.texture_zenith_sun planted at 33, 3.8e-4); the glint carries
    texture."""
    cams = rs.make_camera(24, 32, hfov_deg=20.0, altitude_m=15.0, pitch_deg=-6.0, batch_size=2, dtype=torch.float64)
    sun = rs.Sun(torch.tensor([math.radians(75.0), math.radians(80.0)], dtype=torch.float64), 0.0, 12.0)

    def scene(seed):
        return rs.SeaScene(wind_speed=torch.tensor([5.0, 10.0]), sea_temperature=290.0, band=rs.MWIR, sun=sun, seed=seed,
                           path=False, sky=1.0)

    table, direct, mean = rs.render(cams, scene([1, 2])), rs.render(cams, scene([1, 2]), method="direct"), rs.render(cams, scene(None))
    assert float(((table - direct) / direct).abs().max()) < 2e-4
    assert float((table / mean).max()) > 1.2 and float((table / mean).min()) < 0.8


def test_textured_day_with_the_lowtran_day_sky_matches_per_pixel_and_keeps_the_sky():
    """A textured MWIR sea under the LOWTRAN day sky (the scattered sky differs by azimuth, so the
    mean's table takes TableSize.azimuth_day azimuth nodes and the texture its own, fewer,
    TableSize.texture_azimuth_sun): the sky pixels are the expectation image's (3.6e-8; they were
    0.6 % low: the crest-foam mix took a whitecap fraction W of each sky pixel from the foam
    channel's sky, which lacks the scattered sky), and the sea pixels match per-pixel evaluation to
    2e-3 (7.3e-4 measured, 1.0e-3 before the texture nodes' window was cut to 4.5σ; the texture's
    nodes at the mean's azimuths shifted by π/2, planted, give 4e-2). The 7e-4 is at glint pixels,
    which reflect the sky's bright aureole about the sun: there the texture's departure from the
    mean is sharp both in slope and in azimuth, and two of the texture's discretizations share it
    (against a converged per-pixel render, 80×80 quadrature, 7.0e-4): the nodes' rule
    (TableSize.texture_quadrature (20, 16) alone: 4.5e-4) and their azimuths (17 with
    fine_texture_azimuth=64 alone: 6.9e-4); both give 2.4e-4 (asserted below 4e-4; the azimuths
    alone, planted, fail) at 1.7x the time of a textured day render (docs/bench_texture.md); the
    default keeps the cheaper nodes. With an explicit rs.Sun (no day sky) the default
    gives 8e-5, with the sun behind the cameras 1.8e-5, in LWIR 2e-5."""
    cams = rs.make_camera(24, 32, hfov_deg=40.0, altitude_m=15.0, pitch_deg=-5.0,
                          yaw_deg=torch.tensor([0.0, 30.0], dtype=torch.float64), batch_size=2, dtype=torch.float64)

    def scene(seed):
        return rs.SeaScene(wind_speed=torch.tensor([5.0, 10.0]), wind_direction=torch.tensor([0.4, -1.0]),
                           sea_temperature=290.0, band=rs.MWIR, sun_zenith=math.radians(72.0), sun_azimuth=0.2, seed=seed)

    table, direct, mean = rs.render(cams, scene([1, 2])), rs.render(cams, scene([1, 2]), method="direct"), rs.render(cams, scene(None))
    sea = rs.view_geometry(cams).is_sea[:, None]
    assert bool((~sea).any()) and bool(sea.any())
    assert float(((table - mean) / mean)[~sea].abs().max()) < 1e-6
    assert float(((table - direct) / direct)[sea].abs().max()) < 2e-3
    assert float(((direct - mean) / mean)[sea].abs().max()) > 0.1  # the sea carries texture and glint
    fine = rs.TableSize(texture_quadrature=(20, 16), texture_azimuth_sun=17, fine_texture_azimuth=64)
    refined = rs.render(cams, scene([1, 2]), table=fine)
    assert float(((refined - direct) / direct)[sea].abs().max()) < 4e-4


def test_the_suns_disk_in_the_sky_carries_its_irradiance():
    """A narrow camera looking at the sun 3° above the horizon: the disk's radiance summed over the
    sky pixels' solid angles is E_sun (1 %), and the table render equals the per-pixel one."""
    cams = rs.make_camera(128, 160, hfov_deg=3.0, altitude_m=20.0, pitch_deg=3.0, dtype=torch.float64)
    sun = rs.Sun(math.radians(87.0), 0.0, 12.0)
    scene = rs.SeaScene(wind_speed=6.0, sea_temperature=290.0, band=rs.MWIR, sun=sun)
    img = rs.render(cams, scene)
    night = rs.render(cams, rs.SeaScene(wind_speed=6.0, sea_temperature=290.0, band=rs.MWIR))
    sky = ~rs.view_geometry(cams).is_sea[0]
    total = float(((img - night)[0, 0] * sky).sum()) / float(cams.fx[0]) ** 2  # pixel solid angle ≈ 1/f² here
    assert abs(total / 12.0 - 1) < 0.01
    direct = rs.render(cams, scene, method="direct")
    assert float(((img - direct) / direct).abs().max()) < 1e-5


def test_sunny_scene_with_precomputed_geometry_is_a_clear_error():
    """The glint and the sun's disk are per pixel and need the cameras (the disk's size is the
    pixel's field of view): render(..., geometry=) of a sunny scene raises a ValueError that says
    so (it failed with an UnboundLocalError inside the renderer), and the cameras' render works."""
    cams = rs.make_camera(8, 10, hfov_deg=20.0, altitude_m=20.0, pitch_deg=-4.0, dtype=torch.float64)
    scene = rs.SeaScene(wind_speed=5.0, sea_temperature=290.0, sun=rs.Sun(math.radians(70.0), 0.0, 10.0))
    with pytest.raises(ValueError, match="geometry="):
        rs.render(cams, scene, geometry=rs.view_geometry(cams))
    assert bool(torch.isfinite(rs.render(cams, scene)).all())


@pytest.mark.parametrize("dtype", [torch.float64, torch.float32])
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
    cams = rs.make_camera(48, 64, hfov_deg=30.0, altitude_m=torch.tensor([20.0, 150.0, 80.0]),
                          pitch_deg=torch.tensor([-3.0, -12.0, -8.0]), yaw_deg=torch.tensor([10.0, -30.0, 5.0]), dtype=dtype)
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


@pytest.mark.parametrize("dtype", [torch.float64, torch.float32])
@pytest.mark.parametrize("pitch", [-90.0, -80.0])
def test_day_sky_looking_straight_down_matches_per_pixel(pitch, dtype):
    """Under the LOWTRAN day sky the sea is not the same half a turn round (the scattered sky is
    brighter towards the sun), so the table's azimuth coordinate runs over 2π; it ran over π, and a
    camera looking down at the nadir (every azimuth in view) read the sky of the opposite azimuth
    over half the image: MWIR, 20 m up, 8 m/s, sun 34° from the zenith, 0.22–0.26 K off per-pixel
    evaluation (found in review). With every azimuth in view a render also takes twice the mean's
    azimuth nodes and four times the texture's (the aureole's structure spread over the whole turn;
    found by a second new-user trial, up to 0.025 K and 0.056 K without at 32×40). Four sun and wind
    azimuths: the expectation images within 0.015 K (5.4e-3 to 7.3e-3 measured), the textured seas
    within 0.03 K (1.0e-2 to 1.4e-2); the extra nodes planted away, all four cases fail."""
    cams = rs.make_camera(24, 32, hfov_deg=30.0, altitude_m=20.0, pitch_deg=pitch, yaw_deg=torch.zeros(4),
                          batch_size=4, dtype=dtype)
    for seed, bound in ((None, 0.015), ([1, 2, 3, 4], 0.03)):
        scene = rs.SeaScene(wind_speed=8.0, sea_temperature=290.0, foam=0.0, band=rs.MWIR, sun_zenith=0.6, seed=seed,
                            sun_azimuth=torch.tensor([0.5, 1.6, 2.8, -2.0]),
                            wind_direction=torch.tensor([0.0, 1.0, -0.7, 2.5]))
        table, direct = (rs.render(cams, scene, method=m, output="brightness_temperature").double()
                         for m in ("table", "direct"))
        assert float((table - direct).abs().max()) < bound


# ------------------------------------------------------------------------------------------------
# Against the numpy reference
# ------------------------------------------------------------------------------------------------
# The reflected sun: (view zenith [deg], view azimuth, (a, b, r), mean, sun zenith [deg], sun azimuth,
# shadowing, sun masking)
GLINT = [
    (60.0, 0.3, (0.15, 0.12, 0.0), (0.0, 0.0), 30.0, 0.3 + math.pi, True, True),
    (80.0, 0.0, (0.18, 0.14, 0.0), (0.0, 0.0), 75.0, math.pi, True, True),
    (85.0, 0.2, (0.12, 0.09, 0.3), (0.03, -0.02), 80.0, 0.2 + math.pi, True, True),
    (70.0, 0.0, (0.02, 0.015, 0.0), (0.0, 0.0), 69.5, math.pi, False, False),
    (70.0, 0.0, (0.003, 0.003, 0.0), (0.0, 0.0), 70.1, math.pi, True, True),
    (45.0, 1.0, (0.1, 0.1, 0.0), (0.05, 0.05), 40.0, 1.0 + math.pi, True, False),
    # sun 5° up, view 86.55° just off its vertical plane: the disk's image is long and thin and the
    # mean lies outside it, beyond 90° of the rays to its centre (a bug once put P at 1 % of this)
    (86.5506, math.pi - 8.3e-4, (0.0992, 0.1221, 0.0), (0.0, 0.0), 85.0, 0.0, True, True),
    (86.5506, math.pi - 0.01, (0.0992, 0.1221, 0.0), (0.0, 0.0), 85.0, 0.0, True, True),
]


@pytest.mark.parametrize("dtype, rtol", [(torch.float64, 1e-3), (torch.float32, 1e-3)], ids=["float64", "float32"])
def test_glint_matches_reference(dtype, rtol):
    """rs.glint_radiance (ellipse mass about the specular slope, t and ρ at the facets' mean slope)
    against the reference (nested quadrature over the sun's disk in direction space): broad and calm
    laws, a shifted mean, shadowing and sun masking on and off, a grazing sun. Measured: 4.6e-4 at
    worst (the linearized disk image and t, ρ taken at one point), both dtypes."""
    for th, ph, (a, b, r), mu, sz, sa, sh, mask in GLINT:
        want = float(ref.glint_radiance(math.radians(th), ph, ref.SlopeStatistics(a, b, r), M11, math.radians(sz), sa, 10.0,
                                        shadowing=sh, sun_masking=mask, slope_mean=mu))
        s = rs.SlopeStatistics(torch.tensor(a, dtype=dtype), torch.tensor(b, dtype=dtype), torch.tensor(r, dtype=dtype))
        if mu != (0.0, 0.0):
            s = s.shifted(torch.tensor(mu[0], dtype=dtype), torch.tensor(mu[1], dtype=dtype))
        got = rs.glint_radiance(torch.tensor(math.radians(th), dtype=dtype), ph, s, M11, rs.Sun(math.radians(sz), sa, 10.0),
                                shadowing=sh, sun_masking=mask)
        assert got.dtype == dtype
        assert want > 0 and abs(float(got) / want - 1) <= rtol, (th, sz, a, float(got), want)

"""The reflected sun in the expectation (roughsea_torch.sun): Cox & Munk's glitter formula where the
slopes are broad, a mirror on a flat sea, energy conservation over all view directions, finite
gradients on a calm sea, float32/float64 agreement, and the numpy reference. (The glint in renders:
tests/renderer/test_glint.py; of the two-scale sea: tests/test_clutter.py.)"""

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

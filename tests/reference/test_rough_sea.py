"""The numpy reference with a shifted slope law (``slope_mean``): slopes N(s; mu, Sigma), mu != 0.

Every fact is checked against something that does not go through the reference's own quadrature:
a closed form, plain-vector mirror geometry, the zero-mean code path, a Gauss-Hermite mixture over
mu (the two-scale principle of docs/texture.md sec. 5), or an exact symmetry of the model.
Convention (docs/physics.md sec. 2): s = tan(theta) (cos phi, sin phi) is the direction the facet normal
leans towards, n = (s_x, s_y, 1)/sqrt(1 + |s|^2); phi_hat is the azimuth of the line of sight
sea -> sensor from the upwind axis. Runs in about half a minute.
"""

import cmath
import math

import numpy as np
import pytest
from scipy import stats

import roughsea_torch.reference as ref

DEG = math.pi / 180.0
M10 = complex(1.218, 0.0508)  # water at 10 um, Hale & Querry (docs/physics.md sec. 6)
RB = 30.0                     # sea radiance, equal to the sky at the horizon


def sky(c):
    """Smooth analytic sky of the reflected ray's cos(zenith): 10 at the zenith, 30 at the horizon."""
    return 10.0 + 20.0 * (1.0 - c) ** 4


# ------------------------------------------------------------------- independent pieces

def closed_form_area(th, ph, a, b, r, mu, shadowing):
    """D = E[t H(t)], t = cos th + sin th u, u = s . (cos ph, sin ph) ~ N(m, sigma^2) (docs/physics.md sec. 3)."""
    c, s = math.cos(ph), math.sin(ph)
    m = mu[0] * c + mu[1] * s
    sigma = math.sqrt(a * a * c * c + 2.0 * r * a * b * c * s + b * b * s * s)
    mean_t = math.cos(th) + math.sin(th) * m
    if not shadowing:
        return mean_t  # Eq. 4 denominator: no H, so E[t]
    sd_t = math.sin(th) * sigma
    z = mean_t / sd_t
    return mean_t * stats.norm.cdf(z) + sd_t * stats.norm.pdf(z)


def fresnel_textbook(cos_i, m):
    """Unpolarized Fresnel reflectance of a medium of complex index m = n + ik (Snell with complex cos)."""
    cos_t = cmath.sqrt(1.0 - (1.0 - cos_i * cos_i) / (m * m))
    rs = (cos_i - m * cos_t) / (cos_i + m * cos_t)
    rp = (m * cos_i - cos_t) / (m * cos_i + cos_t)
    return 0.5 * (abs(rs) ** 2 + abs(rp) ** 2)


def mirror_facet(th, ph, mu, m, sky_fn, sea_radiance):
    """One facet of slope mu with plain vectors: (emissivity, apparent radiance, cos Omega, cos theta')."""
    n = np.array([mu[0], mu[1], 1.0])
    n /= np.linalg.norm(n)                                     # normal leans towards mu
    v = np.array([math.sin(th) * math.cos(ph), math.sin(th) * math.sin(ph), math.cos(th)])  # LOS
    cos_omega = float(n @ v)
    reflected = 2.0 * cos_omega * n - v                        # law of reflection
    rho = fresnel_textbook(cos_omega, m)
    seen = sky_fn(reflected[2]) if reflected[2] >= 0.0 else sea_radiance  # below horizontal: the sea
    return 1.0 - rho, (1.0 - rho) * sea_radiance + rho * seen, cos_omega, float(reflected[2])


# ------------------------------------------------------------------- 1. projected area

@pytest.mark.parametrize("shadowing", [True, False], ids=["shadowing", "no_shadowing"])
@pytest.mark.parametrize("law", [(0.2, 0.12, 0.3), (0.05, 0.2, -0.6), (0.3, 0.01, 0.8),
                                 (1e-4, 5e-5, 0.4)],
                         ids=["aniso_r0.3", "aniso_r-0.6", "thin_r0.8", "narrow_1e-4"])
def test_projected_area_with_mean_matches_closed_form(law, shadowing):
    a, b, r = law
    views = [(30.0, 20.0), (60.0, 135.0), (85.0, 250.0), (88.5, 10.0), (89.0, 300.0)]
    means = [(0.1, -0.05), (-0.3, 0.2), (0.15, 0.4)]
    th = np.array([v[0] for v in views])[:, None] * DEG
    ph = np.array([v[1] for v in views])[:, None] * DEG
    mx = np.array([mu[0] for mu in means])[None, :]
    my = np.array([mu[1] for mu in means])[None, :]
    got = ref.projected_area(th, ph, ref.SlopeStatistics(a, b, r), shadowing, slope_mean=(mx, my))
    assert got.shape == (len(views), len(means))
    want = np.array([[closed_form_area(t * DEG, p * DEG, a, b, r, mu, shadowing) for mu in means]
                     for t, p in views])
    # narrow law: a peak of angular width ~1e-4 around the mean azimuth, which quad finds only with
    # the breakpoints placed around it; views where the mean facet is hidden give D ~ 0 in both
    np.testing.assert_allclose(got, want, rtol=1e-9, atol=1e-13)


# ------------------------------------------------------------------- 2. narrow-Gaussian limit

NARROW_CASES = [  # (theta_hat, phi_hat) [deg], mean, (a, b, r)
    (60.0, 80.0, (0.1, -0.05), (1e-3, 1e-3, 0.0)),
    (88.0, 200.0, (-0.2, 0.05), (1e-3, 1e-3, 0.0)),   # grazing, facet tilted towards the sensor
    (70.0, 0.0, (-0.3, 0.0), (1e-3, 1e-3, 0.0)),      # facet leans away: reflected ray into the sea
    (85.0, 30.0, (0.15, 0.1), (1e-3, 5e-4, 0.4)),     # anisotropic, correlated
]


@pytest.mark.parametrize("thd,phd,mu,law", NARROW_CASES)
def test_narrow_gaussian_tends_to_the_mirror_facet_of_the_mean(thd, phd, mu, law):
    th, ph = thd * DEG, phd * DEG
    e_facet, r_facet, cos_omega, _ = mirror_facet(th, ph, mu, M10, sky, RB)
    assert cos_omega > 0.0
    S = ref.SlopeStatistics(*law)
    e = float(ref.emissivity(th, ph, S, M10, slope_mean=mu))
    r = float(ref.apparent_radiance(th, ph, S, M10, RB, sky, slope_mean=mu))
    # the error of the limit is second order in the rms slope (first-order terms cancel by symmetry)
    tol = 200.0 * max(law[0], law[1]) ** 2
    assert abs(e - e_facet) <= tol, (e, e_facet)
    assert abs(r / r_facet - 1.0) <= tol, (r, r_facet)
    # the flat tilted sea (a = b = 0) is that facet exactly, without quadrature
    flat = ref.SlopeStatistics(0.0, 0.0)
    assert float(ref.emissivity(th, ph, flat, M10, slope_mean=mu)) == pytest.approx(e_facet, rel=1e-13)
    assert float(ref.apparent_radiance(th, ph, flat, M10, RB, sky, slope_mean=mu)) == pytest.approx(
        r_facet, rel=1e-13)


def test_narrow_limit_cases_cover_both_sides_of_the_horizon():
    cos_tp = [mirror_facet(t * DEG, p * DEG, mu, M10, sky, RB)[3] for t, p, mu, _ in NARROW_CASES]
    assert min(cos_tp) < 0.0 < max(cos_tp)


# ------------------------------------------------------------------- 3. second law

@pytest.mark.parametrize("shadowing", [True, False], ids=["shadowing", "no_shadowing"])
def test_second_law_with_mean(shadowing):
    S = ref.SlopeStatistics(0.2, 0.12, 0.3)
    th = np.array([60.0, 85.0, 89.0, 75.0]) * DEG
    ph = np.array([80.0, 200.0, 10.0, 180.0]) * DEG
    mx = np.array([0.1, -0.3, 0.4, 0.25])
    my = np.array([-0.05, 0.2, 0.0, -0.1])
    got = ref.apparent_radiance(th, ph, S, M10, RB, RB, shadowing, slope_mean=(mx, my))
    np.testing.assert_allclose(got, RB, rtol=1e-9)
    one = ref.apparent_radiance(th[1], ph[1], S, M10, RB, lambda c: np.full_like(c, RB), shadowing,
                                slope_mean=(mx[1], my[1]))
    np.testing.assert_allclose(one, RB, rtol=1e-9)


# ------------------------------------------------------------------- 4. mirror symmetry

def test_mirror_symmetry_with_mean():
    """Reflecting the crosswind axis maps (phi_hat, mu_y, r) to (-phi_hat, -mu_y, -r); the sky depends
    on zenith only, so R_a is unchanged."""
    ph = 35.0 * DEG
    diag = ref.SlopeStatistics(0.2, 0.1, 0.0)
    r1 = float(ref.apparent_radiance(87.0 * DEG, ph, diag, M10, RB, sky, slope_mean=(0.1, 0.15)))
    r2 = float(ref.apparent_radiance(87.0 * DEG, -ph, diag, M10, RB, sky, slope_mean=(0.1, -0.15)))
    assert r1 == pytest.approx(r2, rel=1e-9)
    r3 = float(ref.apparent_radiance(87.0 * DEG, ph, diag, M10, RB, sky, slope_mean=(0.1, -0.15)))
    assert abs(r3 / r1 - 1.0) > 1e-4  # the crosswind mean does matter: not a trivial pass
    c1 = float(ref.apparent_radiance(75.0 * DEG, ph, ref.SlopeStatistics(0.2, 0.1, 0.5), M10, RB, sky,
                                     slope_mean=(0.1, 0.15)))
    c2 = float(ref.apparent_radiance(75.0 * DEG, -ph, ref.SlopeStatistics(0.2, 0.1, -0.5), M10, RB,
                                     sky, slope_mean=(0.1, -0.15)))
    assert c1 == pytest.approx(c2, rel=1e-9)


# ------------------------------------------------------------------- 5. zero mean

# computed with the reference before slope_mean existed: law (0.2, 0.12, 0.3), m = M10, R_B = 30, sky()
BEFORE = [  # (theta_hat, phi_hat) [deg], shadowing, projected_area, emissivity, apparent_radiance
    (60.0, 80.0, True, 0.5000001664491259, 0.9546990416747607, 29.34014233854258),
    (88.0, 200.0, False, 0.034899496702501094, 0.8388627165909254, 20.94669540581795),
]


@pytest.mark.parametrize("thd,phd,shadowing,d0,e0,r0", BEFORE)
def test_zero_mean_reproduces_the_unshifted_reference(thd, phd, shadowing, d0, e0, r0):
    th, ph = thd * DEG, phd * DEG
    S = ref.SlopeStatistics(0.2, 0.12, 0.3)
    zero = (0.0, 0.0)
    d = float(ref.projected_area(th, ph, S, shadowing, slope_mean=zero))
    e = float(ref.emissivity(th, ph, S, M10, shadowing, slope_mean=zero))
    r = float(ref.apparent_radiance(th, ph, S, M10, RB, sky, shadowing, slope_mean=zero))
    # the recorded numbers (rtol 1e-12 only so that a scipy upgrade moving the last bit is not a failure;
    # with this environment they are equal bit for bit)
    np.testing.assert_allclose([d, e, r], [d0, e0, r0], rtol=1e-12, atol=0.0)
    # zero mean runs the default code path: bit for bit, also for -0.0
    assert d == float(ref.projected_area(th, ph, S, shadowing))
    assert e == float(ref.emissivity(th, ph, S, M10, shadowing))
    assert r == float(ref.apparent_radiance(th, ph, S, M10, RB, sky, shadowing))
    assert d == float(ref.projected_area(th, ph, S, shadowing, slope_mean=(-0.0, np.zeros(1)))[0])


def test_tiny_mean_joins_the_zero_mean_path():
    """mu -> 0 through the shifted density and its support cut lands on Eq. A7 (the unshifted path)."""
    th, ph = 60.0 * DEG, 80.0 * DEG
    S = ref.SlopeStatistics(0.2, 0.12, 0.3)
    tiny = (1e-9, -1e-9)
    d0 = float(ref.projected_area(th, ph, S))
    d1 = float(ref.projected_area(th, ph, S, slope_mean=tiny))
    r0 = float(ref.apparent_radiance(th, ph, S, M10, RB, sky))
    r1 = float(ref.apparent_radiance(th, ph, S, M10, RB, sky, slope_mean=tiny))
    assert d1 != d0  # the shifted path ran
    assert abs(d1 / d0 - 1.0) < 1e-8 and abs(r1 / r0 - 1.0) < 1e-8


# ------------------------------------------------------------------- 6. two-scale mixture

def test_gaussian_mixture_over_the_mean_equals_the_total_law():
    """int N(mu; 0, Sigma_r) D_u(mu) R_a(mu; Sigma_u) dmu / D_total = R_a(0; Sigma_u + Sigma_r).

    Sigma_r = sigma_r^2 e e^T, e = (cos phi_hat, sin phi_hat) (rank one along the LOS azimuth), so
    mu = m e with m ~ N(0, sigma_r^2): a 1-D Gauss-Hermite rule. D_total is the closed form.
    """
    th, ph = 60.0 * DEG, 80.0 * DEG
    au, bu, ru = 0.12, 0.08, 0.3
    sr = 0.08
    c, s = math.cos(ph), math.sin(ph)
    a_t = math.sqrt(au * au + sr * sr * c * c)
    b_t = math.sqrt(bu * bu + sr * sr * s * s)
    r_t = (ru * au * bu + sr * sr * c * s) / (a_t * b_t)
    unresolved = ref.SlopeStatistics(au, bu, ru)
    r_total = float(ref.apparent_radiance(th, ph, ref.SlopeStatistics(a_t, b_t, r_t), M10, RB, sky))
    d_total = closed_form_area(th, ph, a_t, b_t, r_t, (0.0, 0.0), True)

    def mixture(n):
        x, w = np.polynomial.hermite_e.hermegauss(n)  # weight exp(-x^2/2)
        w = w / math.sqrt(2.0 * math.pi)
        mx, my = sr * x * c, sr * x * s
        d_u = ref.projected_area(th, ph, unresolved, slope_mean=(mx, my))
        r_u = ref.apparent_radiance(th, ph, unresolved, M10, RB, sky, slope_mean=(mx, my))
        return float(np.sum(w * d_u * r_u)) / d_total, float(np.sum(w * d_u)), float(np.sum(w * r_u))

    coarse, _, _ = mixture(8)
    fine, area, unweighted = mixture(10)
    tol = 2.0 * abs(fine - coarse) + 1e-9 * r_total  # rule convergence + quadrature tolerance
    assert tol < 1e-6 * r_total                       # the rule has converged: the check has teeth
    assert abs(fine - r_total) <= tol, (fine, r_total, tol)
    assert abs(area / d_total - 1.0) < 1e-8           # the same mixture for the area itself
    # what is being resolved is not negligible: the total law differs from the unresolved one, and
    # averaging R_a over the tilts without the projected-area weight D_u is visibly biased
    r_unresolved = float(ref.apparent_radiance(th, ph, unresolved, M10, RB, sky))
    assert abs(r_total / r_unresolved - 1.0) > 1000.0 * tol / r_total
    assert abs(unweighted / r_total - 1.0) > 100.0 * tol / r_total


# ------------------------------------------------------------------- input handling, degenerate laws

def test_slope_mean_validation_and_degenerate_laws():
    S = ref.SlopeStatistics(0.2, 0.12)
    with pytest.raises(ValueError):
        ref.projected_area(1.0, 0.0, S, slope_mean=(0.1,))
    with pytest.raises(ValueError):
        ref.emissivity(1.0, 0.0, S, M10, slope_mean=(math.nan, 0.0))
    with pytest.raises(NotImplementedError):
        ref.projected_area(1.0, 0.0, ref.SlopeStatistics(0.2, 0.0), slope_mean=(0.1, 0.1))
    # flat sea tilted away from the sensor: the facet is hidden (area 0, emissivity 0/0)
    flat = ref.SlopeStatistics(0.0, 0.0)
    away = (-1.0, 0.0)  # leans away from a sensor at phi_hat = 0, 80 deg: cos th + sin th m < 0
    assert float(ref.projected_area(80 * DEG, 0.0, flat, slope_mean=away)) == 0.0
    assert math.isnan(float(ref.emissivity(80 * DEG, 0.0, flat, M10, slope_mean=away)))
    w = math.cos(80 * DEG) - math.sin(80 * DEG)
    assert float(ref.projected_area(80 * DEG, 0.0, flat, False, slope_mean=away)) == pytest.approx(w)

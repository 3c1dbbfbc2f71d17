"""Slope-conditioned masking of a correlated Gaussian surface (reference: numpy + scipy quadrature).

Smith's (1967) monostatic masking of a point of height xi0 and slope gamma0 (along the view
azimuth, gamma = d(height)/dl with l the horizontal distance towards the sensor) is

    S(xi0, gamma0) = H(mu - gamma0) exp(-int_0^inf g(l) dl),     mu = cot(theta_hat),

g(l) dl being the probability that the surface crosses the ray in [l, l + dl] given that the ray
is above it at l (Smith's normalization; Wagner's (1967) omits the division by that probability).
With heights and slopes at l taken independent of those at the origin (the uncorrelated surface),
g = Lambda mu p(z) / F(z), z = xi0 + mu l, and S averaged over xi0 is H(mu - gamma0) / (1 + Lambda),
whose slope dependence is the step alone: it cancels in the normalization of Eq. 5.

Bourlier, Berginc and Saillard (IEEE TAP 2002) keep the correlation between the origin and the
point l in the crossing rate (the first term of Rice's series, Ricciardi and Sato). Here the rate
is conditioned on the origin's height AND slope (xi0, gamma0), which is what makes the masking
depend on the facet's slope:

    g(l) = p(z | xi0, gamma0) E[(gamma(l) - mu)^+ | xi(l) = z, xi0, gamma0] / P(xi(l) < z | xi0, gamma0),

for a Gaussian height autocorrelation R(l) = sigma_h^2 exp(-l^2 / L^2) (the correlation the
references above test against). In units sigma_h = L = 1 the slope rms along the ray is sqrt(2)
and everything depends on nu = mu / sigma and x = -gamma0 / sigma only (sigma the rms slope along
the view): the model's s_par is -gamma0, so x = (s_par - mean) / sigma_par and the facet faces
the sensor when x > -nu. For l > L_TAIL (R < 1e-10) the rate is the uncorrelated one, integrated
in closed form: -Lambda ln F(xi0 + mu L_TAIL).

Functions (scalars; each an independent scipy quadrature):

- :func:`smith_lambda` Lambda(nu) = phi(nu)/nu - Phi(-nu) (Smith 1967, with nu = mu/sigma);
- :func:`masking` S(x, nu), averaged over the origin's height; ``correlated=False`` gives the
  uncorrelated Smith integral (a check: 1/(1 + Lambda));
- :func:`masking_ratio` Q(x, nu) = S (1 + Lambda): the factor the correlated option puts on the
  facet weight of Eq. 5 (1 for every facet if the surface were uncorrelated).
"""

import math
import warnings
from functools import lru_cache

from scipy import integrate
from scipy.interpolate import CubicSpline
from scipy.special import log_ndtr, ndtr

__all__ = ["smith_lambda", "masking", "masking_ratio", "masking_curve", "L_TAIL"]

SIGMA = math.sqrt(2.0)  # rms slope of R(l) = exp(-l^2): -R''(0) = 2
L_TAIL = 5.0
_INV_SQRT_2PI = 1.0 / math.sqrt(2.0 * math.pi)


def _phi(x):
    return math.exp(-0.5 * x * x) * _INV_SQRT_2PI


def smith_lambda(nu):
    """Smith's Lambda at nu = cot(theta_hat) / sigma_par: phi(nu)/nu - Phi(-nu)."""
    return _phi(nu) / nu - ndtr(-nu)


def _conditional(l, xi0, g0):
    """Moments of (xi(l), gamma(l)) given (xi0, gamma0) for R(l) = exp(-l^2)."""
    e = math.exp(-l * l)
    R, R1, R2 = e, -2.0 * l * e, (4.0 * l * l - 2.0) * e
    m_xi = R * xi0 - R1 * g0 / 2.0
    m_ga = R1 * xi0 - R2 * g0 / 2.0
    y = 2.0 * l * l
    v_xi = -math.expm1(-y) - y * math.exp(-y)                # 1 - R^2 - R1^2 / 2
    v_ga = 2.0 - R1 * R1 - R2 * R2 / 2.0
    c = -R * R1 - R1 * R2 / 2.0
    return m_xi, m_ga, v_xi, v_ga, c


def _rate(l, xi0, g0, mu, correlated):
    z = xi0 + mu * l
    if not correlated:
        return smith_lambda(mu / SIGMA) * mu * _phi(z) / ndtr(z)
    m_xi, m_ga, v_xi, v_ga, c = _conditional(l, xi0, g0)
    if not v_xi > 0.0:  # l = 0: the ray starts on the facet it leaves (x > -nu), no crossing yet
        return 0.0
    sd = math.sqrt(v_xi)
    zs = (z - m_xi) / sd
    m = m_ga + c / v_xi * (z - m_xi)
    s = math.sqrt(max(v_ga - c * c / v_xi, 0.0))
    d = m - mu
    if s > 0.0:
        excess = s * _phi(d / s) + d * ndtr(d / s)
    else:
        excess = max(d, 0.0)
    return _phi(zs) / sd * excess / ndtr(zs)


def _masked_exponent(xi0, g0, mu, correlated):
    pts = [1e-3, 1e-2, 0.1, 0.5, 1.0, 2.0]
    with warnings.catch_warnings():  # roundoff: the conditional variances cancel like l^-2 at l < 1e-3
        warnings.simplefilter("ignore", integrate.IntegrationWarning)
        inner = integrate.quad(_rate, 0.0, L_TAIL, args=(xi0, g0, mu, correlated), points=pts,
                               limit=400, epsabs=1e-11, epsrel=1e-8)[0]
    tail = -smith_lambda(mu / SIGMA) * log_ndtr(xi0 + mu * L_TAIL)
    return inner + tail


def masking(x, nu, correlated=True):
    """S(x, nu): probability that a facet of standardized slope x (along the view, towards the
    sensor) is seen from a line of sight of nu = cot(theta_hat)/sigma_par, averaged over heights."""
    x, nu = float(x), float(nu)
    if not nu > 0.0:
        raise ValueError("nu must be > 0")
    if x <= -nu:
        return 0.0
    mu, g0 = nu * SIGMA, -x * SIGMA

    def f(xi0):
        return _phi(xi0) * math.exp(-_masked_exponent(xi0, g0, mu, correlated))

    with warnings.catch_warnings():  # the inner integral's roundoff (~1e-8) limits this one
        warnings.simplefilter("ignore", integrate.IntegrationWarning)
        return integrate.quad(f, -9.0, 9.0, points=[-2.0, 0.0, 2.0], limit=200, epsabs=1e-10, epsrel=1e-7)[0]


def masking_ratio(x, nu):
    """Q(x, nu) = S(x, nu) (1 + Lambda(nu)) [dimensionless]; 0 for x <= -nu."""
    return masking(x, nu) * (1.0 + smith_lambda(nu))


NU_MIN, NU_MAX, W_MAX = 0.01, 8.0, 16.0  # the model's range (roughsea_torch.masking): nu clamped, x + nu held
W_MIN = 1e-4  # below it Q is held (the tangent ray's limit is slow to integrate; t ~ x + nu weighs it out)


@lru_cache(maxsize=64)
def masking_curve(nu, sigma_par, nodes=41):
    """Q as a function of the slope along the view s_par (not standardized) for one view: Q((s_par)/sigma_par,
    nu) with nu clamped to [NU_MIN, NU_MAX] and x + nu held at W_MAX beyond, as the model defines it;
    computed at ``nodes`` points uniform in sqrt(x + nu) on [0, 4] (x + nu = W_MIN at the first) and interpolated by a cubic spline
    (scipy) in sqrt(x + nu). 0 where x <= -nu (the true nu, not the clamped one)."""
    nu_true = float(nu)
    nu_c = min(max(nu_true, NU_MIN), NU_MAX)
    p = [math.sqrt(W_MAX) * i / (nodes - 1) for i in range(nodes)]
    q = [masking_ratio(max(pi * pi, W_MIN) - nu_c, nu_c) for pi in p]
    spline = CubicSpline(p, q)

    def f(s_par):
        w = s_par / sigma_par + nu_true
        if w <= 0.0:
            return 0.0
        return float(spline(math.sqrt(min(w, W_MAX))))

    return f

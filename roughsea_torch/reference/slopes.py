"""Sea-surface slope statistics and the facet-normal density of the paper (Eq. 1, A7/A8).

Reference implementation (numpy only). Angles in radians; slopes are dimensionless
(rise over run). The facet normal has polar angle theta (from the zenith) and azimuth
phi measured from the upwind axis x_s towards the crosswind axis y_s (x_s rotated +90 deg).
"""

import math

import numpy as np

__all__ = ["SlopeStatistics", "slope_pdf", "check_slope_arrays", "pdf_scalar"]


def check_slope_arrays(std_upwind, std_crosswind, corr):
    """Validate rms slopes (>= 0, not NaN) and correlation (|r| < 1); raise ValueError naming the argument.
    Returns the three as float64 arrays. Shared within the reference (``rough_sea``)."""
    a = np.asarray(std_upwind, dtype=np.float64)
    b = np.asarray(std_crosswind, dtype=np.float64)
    r = np.asarray(corr, dtype=np.float64)
    if np.any(np.isnan(a)) or np.any(a < 0) or np.any(np.isinf(a)):
        raise ValueError("std_upwind must be finite and >= 0")
    if np.any(np.isnan(b)) or np.any(b < 0) or np.any(np.isinf(b)):
        raise ValueError("std_crosswind must be finite and >= 0")
    if np.any(np.isnan(r)) or np.any(np.abs(r) >= 1):
        raise ValueError("corr must satisfy |corr| < 1")
    return a, b, r


class SlopeStatistics:
    """Gaussian slope law of the sea surface (paper Appendix A).

    The slope components (s_x, s_y) = (dh/dx, dh/dy) = tan(theta) (cos phi, sin phi), x upwind,
    y crosswind, are bivariate normal N(0, Sigma) with
    Sigma = [[a^2, r a b], [r a b, b^2]].

    Attributes (float64 numpy arrays, broadcast against each other):
      std_upwind    a = sigma_x, rms slope along the upwind axis (dimensionless, >= 0)
      std_crosswind b = sigma_y, rms slope along the crosswind axis (dimensionless, >= 0)
      corr          r, correlation of s_x and s_y (|r| < 1)
    """

    def __init__(self, std_upwind, std_crosswind, corr=0.0):
        a, b, r = check_slope_arrays(std_upwind, std_crosswind, corr)
        a, b, r = np.broadcast_arrays(a, b, r)
        self.std_upwind = np.array(a, dtype=np.float64)
        self.std_crosswind = np.array(b, dtype=np.float64)
        self.corr = np.array(r, dtype=np.float64)

    @classmethod
    def cox_munk(cls, wind_speed, anisotropic=False):
        """Cox & Munk (1954) clean-surface slope statistics.

        wind_speed: W in m/s at 12.5 m height (>= 0).
        isotropic (paper Eq. 12): sigma^2 = 0.003 + 5.12e-3 W, a^2 = b^2 = sigma^2 / 2.
        anisotropic: upwind a^2 = 3.16e-3 W, crosswind b^2 = 0.003 + 1.92e-3 W, corr = 0.
        """
        w = np.asarray(wind_speed, dtype=np.float64)
        if np.any(np.isnan(w)) or np.any(w < 0) or np.any(np.isinf(w)):
            raise ValueError("wind_speed must be finite and >= 0")
        if anisotropic:
            a = np.sqrt(3.16e-3 * w)
            b = np.sqrt(0.003 + 1.92e-3 * w)
        else:
            sigma2 = 0.003 + 5.12e-3 * w  # Eq. 12
            a = np.sqrt(0.5 * sigma2)
            b = np.sqrt(0.5 * sigma2)
        return cls(a, b, 0.0)

    def __repr__(self):
        return "SlopeStatistics(std_upwind=%r, std_crosswind=%r, corr=%r)" % (
            self.std_upwind, self.std_crosswind, self.corr)


def pdf_scalar(theta, phi, a, b, r):
    """p(theta, phi) of Eq. A7/A8 for one point, a > 0, b > 0, |r| < 1 (per rad^2). Shared within the
    reference (the integrand of ``facet_integral``).

    Eq. A7: p = sec^2(theta) tan(theta) / (2 pi a b sqrt(1 - r^2))
                * exp(-tan^2(theta) E(phi, r) / (2 (1 - r^2)))
    Eq. A8: E = cos^2(phi)/a^2 + sin^2(phi)/b^2 - 2 r cos(phi) sin(phi) / (a b).

    Sign check of the r term: the bivariate normal of (s_x, s_y) with covariance
    [[a^2, r a b], [r a b, b^2]] has exponent
      -1/(2(1-r^2)) [s_x^2/a^2 - 2 r s_x s_y/(a b) + s_y^2/b^2];
    with s_x = tan(theta) cos(phi), s_y = tan(theta) sin(phi) this is exactly
    -tan^2(theta) E / (2 (1 - r^2)) with the minus sign of A8. The paper's A8 agrees.
    Jacobian: ds_x ds_y = tan(theta) sec^2(theta) dtheta dphi.
    """
    if not (0.0 <= theta < 0.5 * math.pi):
        return 0.0
    t = math.tan(theta)
    c = math.cos(phi)
    s = math.sin(phi)
    one_r2 = 1.0 - r * r
    e = c * c / (a * a) + s * s / (b * b) - 2.0 * r * c * s / (a * b)  # Eq. A8
    cos_t = math.cos(theta)
    sec2 = 1.0 / (cos_t * cos_t)
    return (sec2 * t / (2.0 * math.pi * a * b * math.sqrt(one_r2))
            * math.exp(-t * t * e / (2.0 * one_r2)))  # Eq. A7


def slope_pdf(theta, phi, slopes):
    """Density p(theta, phi) of facet-normal directions, Eq. A7/A8 (Eq. 1 when corr = 0).

    theta: polar angle of the facet normal [rad], phi: its azimuth from the upwind axis [rad].
    slopes: SlopeStatistics. Returns the density per rad^2 with respect to dtheta dphi over
    theta in [0, pi/2), phi in [0, 2 pi); it is 0 for theta outside [0, pi/2).

    If an rms slope is exactly 0 the slope law is degenerate (no density): the function then
    returns 0 off the support and +inf on it (phi = 0 or pi when the crosswind slope is 0,
    phi = pi/2 or 3pi/2 when the upwind slope is 0, theta > 0); both 0: +inf at theta = 0 only.
    """
    a, b, r = check_slope_arrays(slopes.std_upwind, slopes.std_crosswind, slopes.corr)
    th, ph, a, b, r = np.broadcast_arrays(np.asarray(theta, dtype=np.float64),
                                          np.asarray(phi, dtype=np.float64), a, b, r)
    out = np.empty(th.shape, dtype=np.float64)
    for idx in np.ndindex(th.shape):
        t_, p_, a_, b_, r_ = float(th[idx]), float(ph[idx]), float(a[idx]), float(b[idx]), float(r[idx])
        if a_ > 0.0 and b_ > 0.0:
            out[idx] = pdf_scalar(t_, p_, a_, b_, r_)
        elif not (0.0 <= t_ < 0.5 * math.pi):
            out[idx] = 0.0
        elif a_ == 0.0 and b_ == 0.0:
            out[idx] = math.inf if t_ == 0.0 else 0.0
        elif b_ == 0.0:
            out[idx] = math.inf if (t_ > 0.0 and math.sin(p_) == 0.0) else 0.0
        else:
            out[idx] = math.inf if (t_ > 0.0 and math.cos(p_) == 0.0) else 0.0
    return out

"""Foam (whitecaps), reference (numpy/scipy): written plainly from the formulas.

Same physics as ``roughsea_torch.foam`` (see its docstring for sources and what is left out),
independent of it:

- Whitecap fraction, Monahan & O'Muircheartaigh 1980 (J. Phys. Oceanogr. 10, 2094-2099):
  W = min(1, 3.84e-6 * U10**3.41), U10 [m/s] at 10 m.
- Foam emissivity: eps_f = min(1, eps_w(theta) + delta(theta)), eps_w = 1 - Fresnel reflectance
  of flat water, delta linear in theta [deg] through (0, 0), (45, 0), (65, 0.04) (Niclos et al.
  2007, J. Geophys. Res. 112, C12020) and (90, 0.09) (extrapolation of that slope).
- Foam radiance: eps_f R_B + (1 - eps_f) E_sky/pi.
- E_sky/pi = (1/pi) int R_s cos(theta) d omega = 2 int_0^1 R_s(mu) mu dmu, by adaptive quadrature.
- Mixture: (1 - f) R_a + f R_foam.
"""

import math

import numpy as np
from scipy import integrate

from .fresnel import fresnel_reflectance

__all__ = ["whitecap_fraction", "foam_emissivity", "foam_radiance", "sky_hemispherical_mean", "with_foam"]

A_MONAHAN = 3.84e-6
B_MONAHAN = 3.41
EXCESS_DEG = np.array([0.0, 45.0, 65.0, 90.0])
EXCESS = np.array([0.0, 0.0, 0.04, 0.09])


def _check(name, x, lo, hi):
    v = np.asarray(x, dtype=np.float64)
    if np.any(np.isnan(v)) or np.any(v < lo) or np.any(v > hi):
        raise ValueError(f"{name} must lie in [{lo}, {hi}]")
    return v


def whitecap_fraction(wind_speed):
    """W = min(1, 3.84e-6 U10^3.41); wind_speed U10 [m/s] >= 0."""
    u = _check("wind_speed", wind_speed, 0.0, np.inf)
    if np.any(np.isinf(u)):
        raise ValueError("wind_speed must be finite")
    return np.minimum(1.0, A_MONAHAN * u ** B_MONAHAN)


def _default_index(band):
    lo, hi = band
    centre = 0.5 * (lo + hi)
    if 7e-6 <= centre <= 15e-6:
        return 1.218 + 0.0508j
    if 2.5e-6 <= centre <= 6e-6:
        return 1.351 + 0.0046j
    raise ValueError("band: centre must be in the MWIR or LWIR")


def foam_emissivity(view_zenith, band=(8e-6, 12e-6), refractive_index=None):
    """eps_f(theta) = min(1, 1 - rho_Fresnel(cos theta) + delta(theta)); theta [rad] in [0, pi/2]."""
    theta = _check("view_zenith", view_zenith, 0.0, math.pi / 2)
    m = _default_index(band) if refractive_index is None else refractive_index
    eps_w = 1.0 - fresnel_reflectance(np.cos(theta), m)
    delta = np.interp(np.degrees(theta), EXCESS_DEG, EXCESS)
    return np.minimum(1.0, eps_w + delta)


def foam_radiance(view_zenith, band, sea_radiance, sky_irradiance_over_pi, refractive_index=None):
    """R_foam = eps_f R_B + (1 - eps_f) E_sky/pi."""
    eps = foam_emissivity(view_zenith, band, refractive_index)
    rb = _check("sea_radiance", sea_radiance, 0.0, np.inf)
    es = _check("sky_irradiance_over_pi", sky_irradiance_over_pi, 0.0, np.inf)
    return eps * rb + (1.0 - eps) * es


def sky_hemispherical_mean(sky, n=64):
    """(1/pi) int R_s cos(theta) d omega over the upper hemisphere, for a scalar callable of mu
    (or a constant). ``n`` is accepted for the torch signature; scipy.quad is adaptive."""
    if not callable(sky):
        return _check("sky", sky, 0.0, np.inf)
    val, _ = integrate.quad(lambda mu: 2.0 * float(sky(mu)) * mu, 0.0, 1.0, epsabs=0.0, epsrel=1e-13, limit=200)
    return val


def with_foam(apparent_radiance, foam_fraction, foam_radiance):
    """(1 - f) R_a + f R_foam."""
    ra = _check("apparent_radiance", apparent_radiance, 0.0, np.inf)
    f = _check("foam_fraction", foam_fraction, 0.0, 1.0)
    rf = _check("foam_radiance", foam_radiance, 0.0, np.inf)
    return (1.0 - f) * ra + f * rf

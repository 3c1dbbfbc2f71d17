"""Foam (whitecaps), reference (numpy/scipy): written plainly from the formulas.

Same physics as ``roughsea_torch.foam`` (see its docstring for sources and what is left out),
independent of it:

- Whitecap fraction, Monahan & O'Muircheartaigh 1980 (J. Phys. Oceanogr. 10, 2094-2099):
  W = 3.84e-6 * min(U10, 25)**3.41, U10 [m/s] at 10 m; a UserWarning above 25 m/s (the end of the
  law's data).
- Foam emissivity: eps_f = min(1, eps_w(theta) + delta(theta)), eps_w = 1 - Fresnel reflectance
  of flat water, delta linear in theta [deg] through (0, 0), (45, 0), (65, 0.04) (Niclos et al.
  2007, J. Geophys. Res. 112, C12020); from 65 to 85 deg linear in eps_w from 0.04 to 0.23 at 85 deg
  (Branch et al. 2016, their maximum, 8.9 um); 0.23 beyond.
- Foam radiance: eps_f R_B + (1 - eps_f) S.
- S, the sky the foam reflects: "reciprocal" S = int rho_f R_s mu dmu / int rho_f mu dmu with
  rho_f = 1 - eps_f (mu = cos of the incidence zenith); "lambertian" S = E_sky/pi =
  2 int_0^1 R_s(mu) mu dmu. Adaptive quadrature, split at the kinks of delta.
- Mixture: (1 - f) R_a + f R_foam.
- Active and residual foam: the active state radiates at the bulk temperature T + 0.2 K (the cool skin
  disrupted; Jessup, Zappa & Yeh 1997), the residual at the skin's T; the expectation mixes
  a R_act + (1 - a) R_res.
"""

import math
import warnings

import numpy as np
from scipy import integrate

from .fresnel import fresnel_reflectance
from .planck import band_radiance

__all__ = ["whitecap_fraction", "foam_emissivity", "foam_radiance", "sky_hemispherical_mean", "foam_sky_radiance",
           "with_foam", "foam_state_radiances", "foam_mean_radiance"]

A_MONAHAN = 3.84e-6
B_MONAHAN = 3.41
U_MAX = 25.0
EXCESS_DEG = np.array([0.0, 45.0, 65.0])
EXCESS = np.array([0.0, 0.0, 0.04])


def _check(name, x, lo, hi):
    v = np.asarray(x, dtype=np.float64)
    if np.any(np.isnan(v)) or np.any(v < lo) or np.any(v > hi):
        raise ValueError(f"{name} must lie in [{lo}, {hi}]")
    return v


def whitecap_fraction(wind_speed):
    """W = 3.84e-6 min(U10, 25)^3.41; wind_speed U10 [m/s] >= 0; warns above 25 m/s."""
    u = _check("wind_speed", wind_speed, 0.0, np.inf)
    if np.any(np.isinf(u)):
        raise ValueError("wind_speed must be finite")
    if np.any(u > U_MAX):
        warnings.warn("wind_speed above 25 m/s: whitecap fraction held at its 25 m/s value", UserWarning, stacklevel=2)
    return A_MONAHAN * np.minimum(u, U_MAX) ** B_MONAHAN


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
    e65 = 1.0 - fresnel_reflectance(math.cos(math.radians(65.0)), m)
    e85 = 1.0 - fresnel_reflectance(math.cos(math.radians(85.0)), m)
    deg = np.degrees(theta)
    delta = np.where(deg <= 65.0, np.interp(deg, EXCESS_DEG, EXCESS),
                     np.where(deg <= 85.0, 0.04 + 0.19 * (e65 - eps_w) / (e65 - e85), 0.23))
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


def foam_sky_radiance(sky, band=(8e-6, 12e-6), refractive_index=None, reflection="reciprocal"):
    """S for a scalar callable sky of mu (or a constant): the reflectance-weighted ("reciprocal") or
    cosine-weighted ("lambertian") mean of the sky over the upper hemisphere."""
    if reflection == "lambertian":
        return sky_hemispherical_mean(sky)
    if reflection != "reciprocal":
        raise ValueError("reflection must be 'reciprocal' or 'lambertian'")
    if not callable(sky):
        return _check("sky", sky, 0.0, np.inf)

    def rho(mu):
        return 1.0 - float(foam_emissivity(math.acos(min(1.0, mu)), band, refractive_index))

    kinks = [math.cos(math.radians(a)) for a in (85.0, 65.0, 45.0)]
    opts = dict(epsabs=0.0, epsrel=1e-13, limit=200, points=kinks)
    num, _ = integrate.quad(lambda mu: rho(mu) * float(sky(mu)) * mu, 0.0, 1.0, **opts)
    den, _ = integrate.quad(lambda mu: rho(mu) * mu, 0.0, 1.0, **opts)
    return num / den


def with_foam(apparent_radiance, foam_fraction, foam_radiance):
    """(1 - f) R_a + f R_foam."""
    ra = _check("apparent_radiance", apparent_radiance, 0.0, np.inf)
    f = _check("foam_fraction", foam_fraction, 0.0, 1.0)
    rf = _check("foam_radiance", foam_radiance, 0.0, np.inf)
    return (1.0 - f) * ra + f * rf


SKIN_DEFICIT_K = 0.2  # bulk minus skin temperature [K], Jessup, Zappa & Yeh 1997 ("a few tenths of a degree")


def foam_state_radiances(view_zenith, band, sea_temperature, sky_radiance, refractive_index=None,
                         deficit_k=SKIN_DEFICIT_K):
    """(active, residual) foam radiance: eps_f B(T + dT) + (1 - eps_f) S and eps_f B(T) + (1 - eps_f) S,
    T the skin (sea) temperature [K], dT the skin deficit that active breaking mixes away."""
    eps = foam_emissivity(view_zenith, band, refractive_index)
    b_skin = band_radiance(sea_temperature, band)
    b_bulk = band_radiance(sea_temperature + deficit_k, band)
    return eps * b_bulk + (1.0 - eps) * sky_radiance, eps * b_skin + (1.0 - eps) * sky_radiance


def foam_mean_radiance(view_zenith, band, sea_temperature, sky_radiance, active_share, refractive_index=None,
                       deficit_k=SKIN_DEFICIT_K):
    """The expectation's foam radiance a R_act + (1 - a) R_res, a the active share of the cover."""
    act, res = foam_state_radiances(view_zenith, band, sea_temperature, sky_radiance, refractive_index, deficit_k)
    return active_share * act + (1.0 - active_share) * res

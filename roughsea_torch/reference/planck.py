"""Planck radiance, band radiance and brightness temperature (reference, numpy/scipy).

SI units: wavelength in metres, temperature in kelvin, spectral radiance in W m^-2 sr^-1 m^-1,
band radiance in W m^-2 sr^-1. Constants: CODATA 2018 exact values.
"""

import math

import numpy as np
from scipy import integrate, optimize

__all__ = ["planck_radiance", "band_radiance", "brightness_temperature",
           "H_PLANCK", "C_LIGHT", "K_BOLTZMANN"]

H_PLANCK = 6.62607015e-34   # J s
C_LIGHT = 299792458.0       # m s^-1
K_BOLTZMANN = 1.380649e-23  # J K^-1


def _planck_scalar(lam, temp):
    x = H_PLANCK * C_LIGHT / (lam * K_BOLTZMANN * temp)
    return 2.0 * H_PLANCK * C_LIGHT ** 2 / lam ** 5 / math.expm1(x)


def planck_radiance(wavelength, temperature):
    """Blackbody spectral radiance B_lambda(T) = 2 h c^2 / lambda^5 / (exp(h c/(lambda k T)) - 1).

    wavelength [m] (> 0), temperature [K] (> 0). Returns W m^-2 sr^-1 m^-1 (float64 array).
    """
    lam = np.asarray(wavelength, dtype=np.float64)
    temp = np.asarray(temperature, dtype=np.float64)
    if np.any(~(lam > 0)):
        raise ValueError("wavelength must be > 0")
    if np.any(~(temp > 0)):
        raise ValueError("temperature must be > 0")
    x = H_PLANCK * C_LIGHT / (lam * K_BOLTZMANN * temp)
    return np.asarray(2.0 * H_PLANCK * C_LIGHT ** 2 / lam ** 5 / np.expm1(x), dtype=np.float64)


def _response_function(response):
    """Return (callable response(lambda) -> float, list of table nodes or [])."""
    if response is None:
        return (lambda lam: 1.0), []
    if callable(response):
        return (lambda lam: float(np.asarray(response(np.array([lam])), dtype=np.float64).reshape(-1)[0])), []
    lam_tab = np.asarray(response[0], dtype=np.float64)
    val_tab = np.asarray(response[1], dtype=np.float64)
    if lam_tab.ndim != 1 or val_tab.shape != lam_tab.shape or np.any(np.diff(lam_tab) <= 0):
        raise ValueError("response table must be 1-d arrays, wavelength strictly ascending")
    return (lambda lam: float(np.interp(lam, lam_tab, val_tab, left=0.0, right=0.0))), list(lam_tab)


def _check_band(band):
    lo, hi = float(band[0]), float(band[1])
    if not (0.0 < lo < hi) or not math.isfinite(hi):
        raise ValueError("band must be (lambda_lo, lambda_hi) with 0 < lambda_lo < lambda_hi [m]")
    return lo, hi


def _band_scalar(temp, lo, hi, resp, nodes):
    pts = [x for x in nodes if lo < x < hi]
    res = integrate.quad(lambda lam: resp(lam) * _planck_scalar(lam, temp), lo, hi,
                         points=pts or None, epsabs=0.0, epsrel=1e-12,
                         limit=max(200, 4 * len(pts) + 50))
    return res[0]


def band_radiance(temperature, band, response=None):
    """Band radiance L = int_{lambda_lo}^{lambda_hi} response(lambda) B_lambda(T) dlambda [W m^-2 sr^-1].

    temperature [K] (broadcasts), band = (lambda_lo, lambda_hi) [m]. response: None (= 1), a callable
    of wavelength [m], or a table (wavelength [m], response) interpolated linearly (np.interp, 0
    outside the table). scipy.integrate.quad with epsrel = 1e-12, table nodes passed as breakpoints.
    """
    lo, hi = _check_band(band)
    resp, nodes = _response_function(response)
    temp = np.asarray(temperature, dtype=np.float64)
    if np.any(~(temp > 0)):
        raise ValueError("temperature must be > 0")
    out = np.empty(temp.shape, dtype=np.float64)
    for idx in np.ndindex(temp.shape):
        out[idx] = _band_scalar(float(temp[idx]), lo, hi, resp, nodes)
    return out


def brightness_temperature(radiance, band, response=None):
    """Temperature [K] whose band_radiance(T, band, response) equals radiance [W m^-2 sr^-1].

    Solved with scipy.optimize.brentq on [150, 400] K (xtol 1e-12 K); raises ValueError when the
    radiance lies outside band_radiance over that interval.
    """
    lo, hi = _check_band(band)
    resp, nodes = _response_function(response)
    rad = np.asarray(radiance, dtype=np.float64)
    out = np.empty(rad.shape, dtype=np.float64)
    r_lo = _band_scalar(150.0, lo, hi, resp, nodes)
    r_hi = _band_scalar(400.0, lo, hi, resp, nodes)
    for idx in np.ndindex(rad.shape):
        target = float(rad[idx])
        if not (r_lo <= target <= r_hi):
            raise ValueError("radiance outside the band radiance of 150..400 K")
        out[idx] = optimize.brentq(lambda t: _band_scalar(t, lo, hi, resp, nodes) - target,
                                   150.0, 400.0, xtol=1e-12, rtol=4 * np.finfo(float).eps,
                                   maxiter=200)
    return out

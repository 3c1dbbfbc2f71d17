"""Fresnel power reflectance of a flat air -> absorbing-medium interface (reference, numpy).

Complex index m = n + i k with k >= 0 (time dependence exp(-i omega t)). With c = cos(incidence)
and w = m cos(transmission angle) = sqrt(m^2 - sin^2(incidence)) (principal branch, Im w >= 0):

    r_s = (c - w) / (c + w),     r_p = (m^2 c - w) / (m^2 c + w),
    R_s = |r_s|^2,  R_p = |r_p|^2,  unpolarized R = (R_s + R_p) / 2.

At normal incidence R = ((n-1)^2 + k^2) / ((n+1)^2 + k^2); at grazing incidence (c = 0) R = 1.
"""

import cmath

import numpy as np

__all__ = ["fresnel_reflectance", "as_complex_index", "fresnel_scalar"]


def as_complex_index(refractive_index):
    """Convert a refractive index given as complex, complex array, or (n, k) pair to complex128.

    Raises ValueError('refractive_index ...') when k < 0 (the n - ik convention is rejected) or NaN.
    """
    m = refractive_index
    if isinstance(m, (tuple, list)) and len(m) == 2 and not any(np.iscomplexobj(x) for x in m):
        n = np.asarray(m[0], dtype=np.float64)
        k = np.asarray(m[1], dtype=np.float64)
        m = n + 1j * k
    else:
        m = np.asarray(m)
        m = m.astype(np.complex128)
    if np.any(np.isnan(m.real)) or np.any(np.isnan(m.imag)):
        raise ValueError("refractive_index must not be NaN")
    if np.any(m.imag < 0):
        raise ValueError("refractive_index: k must be >= 0 (convention m = n + i k)")
    return m


def fresnel_scalar(c, m, polarization="unpolarized"):
    """Fresnel reflectance for one cos(incidence) c in [0, 1] and complex m (plain Python; the formulas
    above). Shared within the reference: the integrands of ``rough_sea`` and ``sun`` call it per point."""
    sin2 = 1.0 - c * c
    m2 = m * m
    w = cmath.sqrt(m2 - sin2)
    rs = (c - w) / (c + w)
    rp = (m2 * c - w) / (m2 * c + w)
    Rs = rs.real * rs.real + rs.imag * rs.imag
    Rp = rp.real * rp.real + rp.imag * rp.imag
    if polarization == "s":
        return Rs
    if polarization == "p":
        return Rp
    return 0.5 * (Rs + Rp)


def fresnel_reflectance(cos_incidence, refractive_index, polarization="unpolarized"):
    """Fresnel power reflectance rho (dimensionless) of an air -> medium interface.

    cos_incidence: cosine of the incidence angle, in [-1, 1]; the result is even in it (|cos| is
    used). refractive_index: complex n + ik (k >= 0), complex array, or an (n, k) pair.
    polarization: "s", "p" or "unpolarized" (mean of the two). Broadcasts; returns float64 array.
    """
    if polarization not in ("s", "p", "unpolarized"):
        raise ValueError("polarization must be 's', 'p' or 'unpolarized'")
    m = as_complex_index(refractive_index)
    c = np.abs(np.asarray(cos_incidence, dtype=np.float64))
    if np.any(c > 1.0 + 1e-12):
        raise ValueError("cos_incidence must lie in [-1, 1]")
    c = np.minimum(c, 1.0)
    c, m = np.broadcast_arrays(c, m)
    sin2 = 1.0 - c * c
    m2 = m * m
    w = np.sqrt(m2 - sin2)  # principal branch: Im(m^2 - sin^2) = 2 n k >= 0 -> Im w >= 0
    rs = (c - w) / (c + w)
    rp = (m2 * c - w) / (m2 * c + w)
    Rs = np.abs(rs) ** 2
    Rp = np.abs(rp) ** 2
    if polarization == "s":
        out = Rs
    elif polarization == "p":
        out = Rp
    else:
        out = 0.5 * (Rs + Rp)
    return np.asarray(out, dtype=np.float64)


"""Fresnel reflection of a complex refractive index, and the optical constants of water.

Sign convention: m = n + i k with k ≥ 0 for an absorbing medium (``docs/physics.md`` §6). The
reflectance only depends on |r|², so tables in the n − i k convention give the same ρ once their
k is taken as positive.
"""

from __future__ import annotations

import functools
from importlib import resources
from typing import Any

import numpy as np
import torch

from ._validation import as_tensor, check_finite_range, resolve_dtype_device
from .radiometry import LWIR, SpectralBand, as_band, band_weights

__all__ = [
    "split_refractive_index",
    "fresnel_terms",
    "fresnel_reflectance",
    "fresnel_emissivity",
    "water_refractive_index",
    "water_table",
    "band_refractive_index",
    "band_index_lookup",
    "band_reflectance",
]

WATER_SOURCES = ("hale_querry", "segelstein")


def split_refractive_index(
    refractive_index: Any, dtype: torch.dtype, device: torch.device
) -> tuple[torch.Tensor, torch.Tensor]:
    """(n, k) tensors from a Python complex, a complex tensor/array, or an (n, k) pair.

    Raises ``ValueError`` for k < 0, n ≤ 0 or NaN.
    """
    if isinstance(refractive_index, (tuple, list)) and len(refractive_index) == 2:
        n, k = refractive_index
    elif isinstance(refractive_index, torch.Tensor) and refractive_index.is_complex():
        n, k = refractive_index.real, refractive_index.imag
    elif isinstance(refractive_index, np.ndarray) and np.iscomplexobj(refractive_index):
        n, k = refractive_index.real, refractive_index.imag
    elif isinstance(refractive_index, (complex, float, int)) or (
        isinstance(refractive_index, torch.Tensor) and refractive_index.is_floating_point()
    ):
        z = refractive_index
        n, k = (z.real, z.imag) if isinstance(z, complex) else (z, 0.0)
    else:
        raise ValueError(
            "refractive_index must be a complex number, a complex tensor or an (n, k) pair; "
            f"got {type(refractive_index).__name__}"
        )
    check_finite_range("refractive_index (real part n)", n, 0.0, lo_open=True)
    check_finite_range("refractive_index (imaginary part k)", k, 0.0)
    return as_tensor(n, dtype, device), as_tensor(k, dtype, device)


def fresnel_terms(c: torch.Tensor, n: torch.Tensor, k: torch.Tensor, emission: bool = False
                   ) -> tuple[torch.Tensor, torch.Tensor]:
    """(|r_s|², |r_p|²), or with ``emission`` (1 − |r_s|², 1 − |r_p|²), each from its own form.

    c = |cos i| ∈ [0, 1]. With m² = M + i N (M = n² − k², N = 2 n k) and
    √(m² − sin² i) = p + i q (principal root, p ≥ 0, q ≥ 0):

        |r_s|² = ((c − p)² + q²) / ((c + p)² + q²),        1 − |r_s|² = 4 c p / ((c + p)² + q²)
        |r_p|² = ((M c − p)² + (N c − q)²) / ((M c + p)² + (N c + q)²),
        1 − |r_p|² = 4 c (M p + N q) / ((M c + p)² + (N c + q)²)

    The second forms give the emissivity 1 − ρ without cancellation near normal incidence. Only the
    pair asked for is formed (the model's integrands need one or the other).
    """
    M = n * n - k * k
    N = 2.0 * n * k
    A = M - (1.0 - c * c)  # Re(m² − sin² i)
    mod = torch.sqrt(A * A + N * N)
    if c.device.type == "cpu" and bool((M > 1.0).all()):  # A ≥ M − 1 > 0 at every angle (water): p is
        # the large component (the check would stall a CUDA stream; there the general form below)
        p = torch.sqrt(0.5 * (mod + A))
        q = N / (2.0 * p)
    else:  # stable complex square root: the large component from a sum, the other from N / (2·it)
        pos = A >= 0
        big = torch.sqrt(0.5 * (mod + A.abs()))
        big_safe = torch.where(big > 0, big, torch.ones_like(big))
        small = torch.where(big > 0, N / (2.0 * big_safe), torch.zeros_like(big))
        p = torch.where(pos, big, small)
        q = torch.where(pos, small, big)
    ds = (c + p) ** 2 + q * q
    Mc, Nc = M * c, N * c
    dp = (Mc + p) ** 2 + (Nc + q) ** 2
    if emission:
        return 4.0 * c * p / ds, 4.0 * c * (M * p + N * q) / dp
    return ((c - p) ** 2 + q * q) / ds, ((Mc - p) ** 2 + (Nc - q) ** 2) / dp


def fresnel_reflectance(
    cos_incidence: Any, refractive_index: Any, polarization: str = "unpolarized"
) -> torch.Tensor:
    """Fresnel power reflectance ρ of an air → medium interface (paper: "the Fresnel formula").

    Args:
        cos_incidence: cos of the angle of incidence, in [-1, 1]; ρ is even in it (|cos| is used).
        refractive_index: m = n + i k (k ≥ 0) as a complex, a complex tensor or an (n, k) pair.
        polarization: ``"unpolarized"`` (mean of s and p, the paper's choice), ``"s"`` or ``"p"``.

    Returns:
        ρ, dimensionless, broadcast over the inputs.

    Example:
        >>> r0 = fresnel_reflectance(1.0, 1.218 + 0.0508j)
        >>> round(1 - float(r0), 5)
        0.98982
    """
    check_finite_range("cos_incidence", cos_incidence, -1.0, 1.0)
    if polarization not in ("unpolarized", "s", "p"):
        raise ValueError(f"polarization must be 'unpolarized', 's' or 'p'; got {polarization!r}")
    dtype, device = resolve_dtype_device(cos_incidence=cos_incidence, refractive_index=refractive_index)
    c = as_tensor(cos_incidence, dtype, device).abs()
    n, k = split_refractive_index(refractive_index, dtype, device)
    rs, rp = fresnel_terms(c, n, k)
    if polarization == "s":
        return rs
    if polarization == "p":
        return rp
    return 0.5 * (rs + rp)


def fresnel_emissivity(cos_incidence: Any, refractive_index: Any) -> torch.Tensor:
    """Facet emissivity 1 − ρ (Kirchhoff), computed without cancellation [dimensionless]."""
    check_finite_range("cos_incidence", cos_incidence, -1.0, 1.0)
    dtype, device = resolve_dtype_device(cos_incidence=cos_incidence, refractive_index=refractive_index)
    c = as_tensor(cos_incidence, dtype, device).abs()
    n, k = split_refractive_index(refractive_index, dtype, device)
    es, ep = fresnel_terms(c, n, k, emission=True)
    return 0.5 * (es + ep)


# -- optical constants of water --------------------------------------------------------------


@functools.lru_cache(maxsize=4)
def water_table(source: str = "hale_querry") -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The shipped table (wavelength [m], n, k) of liquid water at 25 °C.

    Sources (refractiveindex.info database, CC0; generated by ``pipelines/make_water_table.py``):
    ``"hale_querry"`` — Hale & Querry 1973, Appl. Opt. 12, 555 (default; the paper's era);
    ``"segelstein"`` — Segelstein 1981, finer sampling, same group.
    """
    if source not in WATER_SOURCES:
        raise ValueError(f"source must be one of {WATER_SOURCES}; got {source!r}")
    text = resources.files("roughsea_torch").joinpath("data", f"water_{source}.csv").read_text()
    rows = [ln for ln in text.splitlines() if ln and not ln.startswith("#")][1:]
    arr = np.array([[float(v) for v in ln.split(",")] for ln in rows])
    return arr[:, 0] * 1e-6, arr[:, 1], arr[:, 2]


def water_refractive_index(wavelength: Any, source: str = "hale_querry") -> torch.Tensor:
    """Complex refractive index n + i k of liquid water, linear interpolation in wavelength.

    Args:
        wavelength: λ [m], within the shipped table (about 2.5–15 µm).
        source: ``"hale_querry"`` (default) or ``"segelstein"``.

    Returns:
        complex tensor (complex64 for float32 input, else complex128), shape of ``wavelength``.
    """
    wl, n, k = water_table(source)
    check_finite_range("wavelength", wavelength, float(wl[0]), float(wl[-1]), unit="m")
    dtype, device = resolve_dtype_device(wavelength=wavelength)
    lam = as_tensor(wavelength, dtype, device)
    wl_t = torch.as_tensor(wl, dtype=dtype, device=device)
    nk = torch.as_tensor(np.stack([n, k]), dtype=dtype, device=device)
    i = torch.searchsorted(wl_t, lam.detach().contiguous(), right=True).clamp(1, wl.size - 1)
    x0, x1 = wl_t[i - 1], wl_t[i]
    f = (lam - x0) / (x1 - x0)
    out = nk[:, i - 1] * (1.0 - f) + nk[:, i] * f
    return torch.complex(out[0], out[1])


def band_refractive_index(
    band: Any = LWIR,
    temperature: Any = 300.0,
    response: Any = None,
    source: str = "hale_querry",
    method: str = "fit",
) -> torch.Tensor:
    """One effective refractive index of water for a sensor band.

    Args:
        band: (λ_lo, λ_hi) [m] or a ``SpectralBand``.
        temperature: T [K] of the Planck weight (the sea temperature); float or tensor.
        response: relative spectral response; None = flat.
        method: ``"fit"`` (default): the (n, k ≥ 0) whose Fresnel reflectance best fits, in least
            squares over incidence angles 0–89.9°, the band-averaged reflectance
            ρ̄(θ) = Σ w(λ) ρ(θ; m(λ)), w ∝ B_λ(T) · response (:func:`band_reflectance`);
            where the plain average fits better (e.g. 3–5 µm, where the optimum wants k < 0) the
            average is returned; ``"average"``: n and k averaged with those weights (the paper's
            choice).

    Returns:
        complex tensor n̄ + i k̄ of the shape of ``temperature``.

    Notes:
        ``docs/physics.md`` §6: averaging n and k is not averaging ρ. Over 8–12 µm at 290 K the
        average index overstates the flat-sea emissivity by up to 0.008 (0.25 K of brightness
        temperature near 80°); the fitted index matches the band-averaged ρ to 6e-5 at every
        angle. Over 3–5 µm both agree to 2e-4 (``pipelines/band_averaging.py``).
    """
    if method not in ("fit", "average"):
        raise ValueError(f"method must be 'fit' or 'average'; got {method!r}")
    b = as_band(band, response)
    dtype, device = resolve_dtype_device(temperature=temperature)
    lam, w = band_weights(b, temperature, torch.float64, device)
    m = water_refractive_index(lam, source)
    avg = (m * w.to(m.dtype)).sum(-1)
    if method == "average":
        return avg.to(torch.complex64 if dtype == torch.float32 else torch.complex128)
    # Gauss–Newton on (n, k) against the band-averaged reflectance, batched over temperatures.
    c = torch.cos(torch.deg2rad(torch.linspace(0.0, 89.9, 181, dtype=torch.float64, device=device)))
    target = band_reflectance(c, b, torch.as_tensor(temperature, dtype=torch.float64, device=device)[..., None], None, source)
    n, k = avg.real.clone(), avg.imag.clone()
    h = 1e-6
    for _ in range(12):
        def res(nn, kk):
            rs, rp = fresnel_terms(c, nn[..., None], kk[..., None])
            return 0.5 * (rs + rp) - target

        r0 = res(n, k)
        jn = (res(n + h, k) - res(n - h, k)) / (2 * h)
        k_lo = (k - h).clamp_min(0.0)
        jk = (res(n, k + h) - res(n, k_lo)) / (k + h - k_lo)[..., None]
        a11, a12, a22 = (jn * jn).sum(-1), (jn * jk).sum(-1), (jk * jk).sum(-1)
        g1, g2 = (jn * r0).sum(-1), (jk * r0).sum(-1)
        det = a11 * a22 - a12 * a12
        n = n - (a22 * g1 - a12 * g2) / det
        k = (k - (a11 * g2 - a12 * g1) / det).clamp_min(0.0)
    # keep whichever of the fit and the plain average matches ρ̄ better at its worst angle (in the
    # MWIR the least-squares optimum wants k < 0, and the bounded fit loses to the average)
    def worst(nn, kk):
        rs, rp = fresnel_terms(c, nn[..., None], kk[..., None])
        return (0.5 * (rs + rp) - target).abs().amax(-1)

    use_fit = worst(n, k) <= worst(avg.real, avg.imag)
    out = torch.where(use_fit, torch.complex(n, k), avg)
    return out.to(torch.complex64 if dtype == torch.float32 else torch.complex128)


_INDEX_T0, _INDEX_DT, _INDEX_NT = 180.0, 2.0, 91  # the band-index table: 180-360 K every 2 K


@functools.lru_cache(maxsize=16)
def _band_index_table(band: SpectralBand) -> tuple[torch.Tensor, torch.Tensor]:
    """n and k of the band-effective water index at 180–360 K every 2 K, (2, N_T), and their
    T-derivatives at the nodes, (2, N_T): 4th-order centred differences (2nd-order one-sided at the
    ends; the fit is smooth in T)."""
    t = _INDEX_T0 + _INDEX_DT * torch.arange(_INDEX_NT, dtype=torch.float64)
    m = band_refractive_index(band, t)
    y = torch.stack([m.real, m.imag])
    d = torch.empty_like(y)
    d[:, 2:-2] = (y[:, :-4] - 8 * y[:, 1:-3] + 8 * y[:, 3:-1] - y[:, 4:]) / (12 * _INDEX_DT)
    d[:, 1], d[:, -2] = (y[:, 2] - y[:, 0]) / (2 * _INDEX_DT), (y[:, -1] - y[:, -3]) / (2 * _INDEX_DT)
    d[:, 0] = (-3 * y[:, 0] + 4 * y[:, 1] - y[:, 2]) / (2 * _INDEX_DT)
    d[:, -1] = (3 * y[:, -1] - 4 * y[:, -2] + y[:, -3]) / (2 * _INDEX_DT)
    return y, d


def band_index_lookup(band: SpectralBand, temperature: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
    """The band-effective water index (n, k) at T_sea [K] (a float64 tensor, any shape):
    ``band_refractive_index`` tabulated every 2 K over 180–360 K per band and read by a cubic
    Hermite interpolant, differentiable in T (within 1e-8 of the direct fit; a fit costs ~20 ms,
    a lookup ~0.1 ms). Its T-derivative is the interpolant's, so the gradient of an image with
    respect to the sea temperature includes how the Planck weights of the band move the index."""
    try:
        y, d = _band_index_table(band)
    except TypeError:  # a band with an unhashable response (e.g. arrays): fit directly
        m = band_refractive_index(band, temperature)
        return m.real, m.imag
    y, d = y.to(temperature.device), d.to(temperature.device)
    f = ((temperature - _INDEX_T0) / _INDEX_DT).clamp(0.0, _INDEX_NT - 1.0)
    i = f.detach().floor().long().clamp(max=_INDEX_NT - 2)
    s = f - i
    s2, s3 = s * s, s * s * s
    h00, h10, h01, h11 = 2 * s3 - 3 * s2 + 1, s3 - 2 * s2 + s, 3 * s2 - 2 * s3, s3 - s2
    out = h00 * y[:, i] + h10 * _INDEX_DT * d[:, i] + h01 * y[:, i + 1] + h11 * _INDEX_DT * d[:, i + 1]
    return out[0], out[1]


def band_reflectance(
    cos_incidence: Any,
    band: Any = LWIR,
    temperature: Any = 300.0,
    response: Any = None,
    source: str = "hale_querry",
) -> torch.Tensor:
    """Band-averaged Fresnel reflectance ρ̄ = Σ w(λ) ρ(cos i; m(λ)), w ∝ B_λ(T) · response.

    Args:
        cos_incidence: cos of the incidence angle; a float or tensor of shape S.
        temperature: T [K] for the Planck weight; float or tensor broadcastable with S.

    Returns:
        ρ̄ of the broadcast shape.
    """
    b = as_band(band, response)
    dtype, device = resolve_dtype_device(cos_incidence=cos_incidence, temperature=temperature)
    lam, w = band_weights(b, temperature, dtype, device)
    m = water_refractive_index(lam, source)
    c = as_tensor(cos_incidence, dtype, device).abs().unsqueeze(-1)
    rs, rp = fresnel_terms(c, m.real.to(dtype), m.imag.to(dtype))
    return (0.5 * (rs + rp) * w).sum(-1)

"""Foam (whitecaps): coverage against wind, foam emissivity, foam radiance and the area mixture.

In the mean model (``docs/physics.md`` §12) foam is an area fraction ``f`` of the sea. A pixel sees

    R = (1 − f) R_a + f R_foam                                          (:func:`with_foam`)

with R_a the apparent radiance of the foam-free rough sea (Eq. 10) and

    R_foam = ε_f(θ̂) R_B + (1 − ε_f(θ̂)) S                                 (:func:`foam_radiance`)

with ε_f the foam's measured emissivity and S the sky radiance it reflects (:func:`foam_sky_radiance`):
by default the sky weighted by the foam's own reflectance 1 − ε_f at each incidence, the reciprocal
reflection that Kirchhoff's law fixes from ε_f (below); ``reflection="lambertian"`` gives the
cosine-weighted hemispherical mean E_sky/π = 2 ∫₀¹ R_s(μ) μ dμ (:func:`sky_hemispherical_mean`), the
previous model. Both are weighted means of the sky: if R_s ≡ R_B then R_foam = R_B (second law),
whatever ε_f.

Sources and numbers
-------------------
Whitecap coverage (:func:`whitecap_fraction`):
    Monahan, E. C. and O'Muircheartaigh, I. (1980), "Optimal power-law description of oceanic
    whitecap coverage dependence on wind speed", J. Phys. Oceanogr. 10, 2094–2099:
    W = 3.84e-6 · U10^3.41 (W a fraction, U10 the wind speed at 10 m [m/s]), the robust
    (biweight) fit to the combined Monahan 1971 and Toba & Chaen 1973 data. W(10 m/s) = 0.99 %,
    W(15 m/s) = 3.9 %. The data end at about 20–25 m/s: the law is not taken past
    :data:`MONAHAN_MAX_WIND` = 25 m/s. Above it W is held at W(25 m/s) = 22.4 % (dW/dU = 0 there)
    and a ``UserWarning`` says so (the uncapped power law would reach a sea all foam at 38.7 m/s).
    Not verified against the paper's own text (not reachable here): the
    coefficients are as quoted, identically, by many secondary sources. Alternatives, not
    implemented: Monahan & O'Muircheartaigh 1986 (Int. J. Remote Sens. 7, 627–642),
    W = 2.95e-6 U10^3.52 (sometimes misattributed to 1980); Callaghan et al. 2008 (Geophys. Res.
    Lett. 35, L23609, piecewise law for 3.7–23.1 m/s); Anguelova & Webster 2006 (J. Geophys.
    Res. 111, C03017) and Salisbury et al. 2013 (J. Geophys. Res. 118, 6201–6222) document an
    order-of-magnitude scatter of W at a given U10 (sea temperature, fetch, wind history).

Foam emissivity (:func:`foam_emissivity`), thermal infrared, two measurements:
    Niclòs, R., Valor, E., Caselles, V., Coll, C. and Sánchez, J. M. (2007), "Foam effect on the
    sea surface emissivity in the 8–14 µm region", J. Geophys. Res. 112, C12020,
    doi:10.1029/2007JC004521 (controlled-condition measurements, multichannel radiometer,
    8–14 µm): the foam effect is negligible at low observation angles, significant above 45°, and
    the foam minus foam-free emissivity difference is about +0.04 at 65° (slightly band
    dependent); foam reduces the angular variation of the emissivity.
    Branch, R., Chickadel, C. C. and Jessup, A. T. (2016), "Infrared emissivity of seawater and
    foam at large incidence angles in the 3–14 µm wavelength range", Remote Sens. Environ. (FTIR,
    60°–85°, 3.5–5.5 and 8–14 µm): foam emissivity is higher than water's at every wavelength and
    angle above 65° where the difference is significant; the difference grows with angle to a
    maximum of 0.23 at 8.9 µm and 85°.
    Only these summary numbers could be checked (the papers' abstracts); the angle- and
    wavelength-resolved values were not reachable. The model is the measured DIFFERENCE added to
    the flat-water Fresnel emissivity ε_w(θ̂) of the same band (both papers measure foam against
    flat water):

        ε_f(θ̂) = min(1, ε_w(θ̂) + Δ(θ̂)),   Δ through the anchors
        (0°, 0), (45°, 0), (65°, 0.04)   Niclòs et al. 2007 (linear in θ̂ between them),
        (85°, 0.23)                      Branch et al. 2016 (their maximum: 8.9 µm),
        held at 0.23 beyond 85° (no measurement there).

    From 65° to 85° Δ is linear in the water's emissivity ε_w(θ̂) (not in θ̂): Branch et al. report
    that both emissivities fall steeply above 65°, foam's less; an excess linear in θ̂ would make foam's
    emissivity rise from 65° to 70° (ε_w falls slowly there), this makes it fall, less than water's.

    0.23 is Branch's spectral maximum, so Δ(85°) is an upper end for a band average (the 8–12 µm
    average of their spectrum is not public); the previous model (Niclòs's 45°–65° slope
    continued, 0.08 at 85°) is the lower end they showed too low. The same Δ is used in the
    3–5 µm band, where Branch et al. report the sign (foam higher above 65°) but no number here.
    ε_w uses one refractive index per band (default: Hale & Querry at 10 µm, 1.218 + 0.0508i,
    for bands centred in 7–15 µm, the default of ``apparent_radiance``; at 4 µm, 1.351 + 0.0046i,
    for bands centred in 2.5–6 µm); pass ``refractive_index`` (e.g. from
    :func:`~roughsea_torch.optics.band_refractive_index`) to use the one given to Eq. 10.

Foam's reflection of the sky (:func:`foam_sky_radiance`): in the thermal infrared water absorbs
within ~10 µm (LWIR) to ~100 µm (MWIR), so foam does not scatter in volume (Anguelova & Gaiser
2012, Remote Sens. 4, 1162–1189: volume scattering in foam is weak, absorption sits in the wet
films); what it reflects is surface (Fresnel) reflection off its bubble caps, strongest at grazing
incidence. Only its directional-hemispherical reflectance 1 − ε_f(θ) is measured (Kirchhoff).
The BRDF used is the one that reciprocity and Kirchhoff fix from it alone, separable
(f(θ_v, θ_i) = (1 − ε_f(θ_v))(1 − ε_f(θ_i)) / (π ρ̄), ρ̄ = 2 ∫₀¹ (1 − ε_f(μ)) μ dμ; the
construction of the diffuse term of Ashikhmin & Shirley 2000, J. Graphics Tools 5(2), 25–32):

    R_foam = ε_f(θ̂) R_B + (1 − ε_f(θ̂)) S,   S = ∫₀¹ ρ_f(μ) R_s(μ) μ dμ / ∫₀¹ ρ_f(μ) μ dμ,

ρ_f = 1 − ε_f: the sky weighted by the foam's own reflectance at each incidence, i.e. towards the
warm sky near the horizon (``reflection="reciprocal"``, the default). ``"lambertian"`` is the
previous model, S = E_sky/π = 2 ∫ R_s μ dμ (the cosine-weighted hemispherical mean, colder).
Either way R_s ≡ R_B gives R_foam = R_B (second law), whatever ε_f. Under the midlatitude-summer
LWIR sky S is 272 K (reciprocal) against 252 K (Lambertian), and Eq. 10 for a surface of Fresnel
facets with slope variances 0.3–1 (bubble caps) reflects 268–270 K at 60°–88°: the reciprocal
weighting is where a facet model of foam lands, not the horizon's 289 K a smooth mirror would see
(``docs/foam_table.md``).

In a textured image (``docs/texture.md`` §8) foam sits on the breaking crests:
:func:`crest_foam_fraction` gives each pixel its own fraction f_pix from the resolved crest
variable of the :class:`~roughsea_torch.waves.WaveField`, with E[f_pix] = W exactly and
f_pix = W where the footprint resolves no wave; the pixel is then (1 − f_pix) R_a + f_pix R_foam.

Left out: foam is a patch of the mean plane (its slopes are not those of the waves: near grazing
foam on facets tilted towards the camera would be seen at a smaller local incidence and read warmer),
no shadowing of foam, no foam on the sky-reflection weights of Eq. 10, no multiple reflection
between foam and water, no spray; a foam temperature different from the sea's only for active
whitecaps (the disrupted skin, :mod:`roughsea_torch.whitecaps`).
"""

from __future__ import annotations

import math
import warnings
from functools import lru_cache
from typing import Any

import numpy as np
import torch

from ._validation import as_tensor, check_finite_range, resolve_dtype_device
from .atmosphere import as_sky
from .optics import fresnel_emissivity
from .radiometry import LWIR, as_band

__all__ = [
    "MONAHAN_COEFFICIENT",
    "MONAHAN_EXPONENT",
    "MONAHAN_MAX_WIND",
    "FOAM_EMISSIVITY_EXCESS",
    "FOAM_REFLECTIONS",
    "whitecap_fraction",
    "foam_emissivity",
    "foam_radiance",
    "sky_hemispherical_mean",
    "foam_sky_weights",
    "foam_sky_radiance",
    "with_foam",
    "CREST_FOAM_FLOOR",
    "crest_foam_fraction",
    "crest_fraction_from_variances",
    "vanishing_crest",
]

MONAHAN_COEFFICIENT = 3.84e-6  # Monahan & O'Muircheartaigh 1980, W = a U10^b (fraction, U10 in m/s)
MONAHAN_EXPONENT = 3.41
MONAHAN_MAX_WIND = 25.0  # [m/s] the end of the law's data (about 20–25 m/s): W is held above it

# Foam minus flat-water emissivity Δ(θ̂), its anchors [(deg, Δ)]: Niclòs et al. 2007 to 65° (8–14 µm),
# Branch et al. 2016 at 85° (their maximum, 8.9 µm); held beyond 85° (see the module docstring).
FOAM_EMISSIVITY_EXCESS = ((0.0, 0.0), (45.0, 0.0), (65.0, 0.04), (85.0, 0.23))
FOAM_REFLECTIONS = ("reciprocal", "lambertian")  # foam_sky_radiance: the default first

CREST_FOAM_FLOOR = 0.05  # ρ: σ_u is at least ρ σ_X (crest_foam_fraction)
_SQRT_HALF = math.sqrt(0.5)
_W_MIN = 1e-30  # below this whitecap fraction f_pix is scaled linearly to 0 (crest_foam_fraction)

_LWIR_INDEX = 1.218 + 0.0508j  # Hale & Querry 1973, 10 µm
_MWIR_INDEX = 1.351 + 0.0046j  # Hale & Querry 1973, 4 µm


def whitecap_fraction(wind_speed: Any) -> torch.Tensor:
    """Fraction of the sea covered by whitecaps, W = 3.84e-6 · min(U10, 25 m/s)^3.41.

    Monahan & O'Muircheartaigh (1980), J. Phys. Oceanogr. 10, 2094–2099, taken only over its data
    (to about 20–25 m/s): above :data:`MONAHAN_MAX_WIND` = 25 m/s W is held at W(25) = 0.2245 and a
    ``UserWarning`` says so (the gradient in the wind is 0 there).

    Args:
        wind_speed: U10, wind speed at 10 m [m/s], finite and ≥ 0; float or tensor.

    Returns:
        W in [0, 0.2245], the shape of ``wind_speed``; 0 at zero wind, differentiable in the wind
        (dW/dU = 0 at U = 0 and above 25 m/s).
    """
    check_finite_range("wind_speed", wind_speed, 0.0, math.inf, hi_open=True, unit="m/s")
    dtype, device = resolve_dtype_device(wind_speed=wind_speed)
    u = as_tensor(wind_speed, dtype, device)
    if bool((u.detach() > MONAHAN_MAX_WIND).any()):
        warnings.warn(
            f"wind_speed above {MONAHAN_MAX_WIND:g} m/s: the whitecap law of Monahan & O'Muircheartaigh (1980) "
            f"is fitted to about 20-25 m/s; the whitecap fraction is held at its {MONAHAN_MAX_WIND:g} m/s value "
            f"({MONAHAN_COEFFICIENT * MONAHAN_MAX_WIND ** MONAHAN_EXPONENT:.4f}) and does not change with the wind there",
            UserWarning, stacklevel=2,
        )
    return MONAHAN_COEFFICIENT * torch.clamp(u, max=MONAHAN_MAX_WIND).pow(MONAHAN_EXPONENT)


def _band_index(band: Any) -> complex:
    """Default refractive index of water for a band, from the band's centre wavelength."""
    b = as_band(band)
    centre = 0.5 * (b.lo + b.hi)
    if 7e-6 <= centre <= 15e-6:
        return _LWIR_INDEX
    if 2.5e-6 <= centre <= 6e-6:
        return _MWIR_INDEX
    raise ValueError(
        f"band: foam emissivity is measured in the thermal infrared only; the band centre must lie in "
        f"[2.5e-6, 6e-6] m (MWIR) or [7e-6, 15e-6] m (LWIR), got {centre!r} m"
    )


@lru_cache(maxsize=8)
def _excess_table(dtype: torch.dtype, device: str) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
    """The anchors up to 65° (Niclòs), where Δ is linear in θ between them."""
    pts = FOAM_EMISSIVITY_EXCESS[:3]
    x = torch.tensor([math.radians(a) for a, _ in pts], dtype=torch.float64)
    y = torch.tensor([d for _, d in pts], dtype=torch.float64)
    slope = (y[1:] - y[:-1]) / (x[1:] - x[:-1])
    return tuple(t.to(dtype=dtype, device=device) for t in (x, y, slope))  # type: ignore[return-value]


def _emissivity_excess(theta: torch.Tensor, eps_w: torch.Tensor, m: Any) -> torch.Tensor:
    """Δ(θ̂) (θ̂ in radians; ε_w the flat water's emissivity there, index ``m``): linear in θ̂ through the
    anchors up to 65°; from 65° to 85° linear in the water's emissivity, Δ = Δ₆₅ + (Δ₈₅ − Δ₆₅)
    (ε_w(65°) − ε_w(θ̂)) / (ε_w(65°) − ε_w(85°)) (the excess grows as the water's emissivity falls, so
    foam's emissivity falls too, less than water's: Branch et al. 2016); Δ₈₅ beyond 85°."""
    x, y, slope = _excess_table(theta.dtype, str(theta.device))
    i = torch.bucketize(theta.detach(), x[1:-1], right=True)  # interval index in [0, 1]
    low = y[i] + slope[i] * (theta - x[i])
    (a65, d65), (a85, d85) = FOAM_EMISSIVITY_EXCESS[2], FOAM_EMISSIVITY_EXCESS[3]
    ends = torch.tensor([math.cos(math.radians(a65)), math.cos(math.radians(a85))], dtype=theta.dtype,
                        device=theta.device)
    # at every element (not once per index): the vectorized and scalar paths of the Fresnel terms round
    # differently, and an image of a batch must be bitwise the image rendered alone
    e = fresnel_emissivity(ends.reshape((2,) + (1,) * eps_w.ndim).expand((2,) + eps_w.shape), m).to(eps_w.dtype)
    mid = d65 + (d85 - d65) * (e[0] - eps_w) / (e[0] - e[1])
    return torch.where(theta <= x[-1], low, torch.where(theta <= math.radians(a85), mid, torch.full_like(mid, d85)))


def foam_emissivity(view_zenith: Any, band: Any = LWIR, refractive_index: Any = None) -> torch.Tensor:
    """Directional emissivity of foam ε_f(θ̂) in a thermal-infrared band [dimensionless].

    ε_f = min(1, ε_w(θ̂) + Δ(θ̂)): the flat-water Fresnel emissivity plus the measured foam excess
    Δ (Niclòs et al. 2007: 0 up to 45°, +0.04 at 65°; Branch et al. 2016: 0.23 at 85°, held to 90°;
    between 65° and 85° linear in ε_w, see the module docstring).

    Args:
        view_zenith: θ̂ [rad] in [0, π/2], zenith angle of the line of sight.
        band: (λ_lo, λ_hi) [m] or a ``SpectralBand`` centred in the MWIR (2.5–6 µm) or LWIR
            (7–15 µm); it chooses the default refractive index.
        refractive_index: water index m = n + ik for ε_w; None = the band's default.

    Returns:
        ε_f in [0, 1], the broadcast shape of the inputs.
    """
    check_finite_range("view_zenith", view_zenith, 0.0, math.pi / 2, unit="rad")
    m = _band_index(band) if refractive_index is None else refractive_index
    dtype, device = resolve_dtype_device(view_zenith=view_zenith, refractive_index=m)
    return _foam_emissivity(as_tensor(view_zenith, dtype, device), m, dtype)


def _foam_emissivity(theta: torch.Tensor, m: Any, dtype: torch.dtype) -> torch.Tensor:
    """ε_f at zenith angles ``theta`` [rad] (checked) for the water index ``m`` (a complex number, a
    complex tensor or an (n, k) pair broadcasting against ``theta``)."""
    eps_w = fresnel_emissivity(torch.cos(theta), m)
    if isinstance(m, (torch.Tensor, tuple, list)):
        eps_w = eps_w.to(dtype)
    return torch.clamp(eps_w + _emissivity_excess(theta, eps_w, m), max=1.0)


def foam_radiance(
    view_zenith: Any,
    band: Any,
    sea_radiance: Any,
    sky_irradiance_over_pi: Any,
    refractive_index: Any = None,
) -> torch.Tensor:
    """Radiance of a foam patch, R_foam = ε_f R_B + (1 − ε_f) S [W m⁻² sr⁻¹].

    Args:
        view_zenith: θ̂ [rad] in [0, π/2].
        band: the sensor band (see :func:`foam_emissivity`).
        sea_radiance: R_B, blackbody band radiance at the sea (foam) temperature [W m⁻² sr⁻¹], ≥ 0.
        sky_irradiance_over_pi: S, the sky radiance the foam reflects [W m⁻² sr⁻¹], ≥ 0
            (:func:`foam_sky_radiance`; with ``reflection="lambertian"`` it is E_sky/π, hence the name).
        refractive_index: see :func:`foam_emissivity`.

    Returns:
        R_foam, the broadcast shape of the inputs.
    """
    check_finite_range("sea_radiance", sea_radiance, 0.0, math.inf, hi_open=True, unit="W m-2 sr-1")
    check_finite_range(
        "sky_irradiance_over_pi", sky_irradiance_over_pi, 0.0, math.inf, hi_open=True, unit="W m-2 sr-1"
    )
    dtype, device = resolve_dtype_device(
        view_zenith=view_zenith, sea_radiance=sea_radiance, sky_irradiance_over_pi=sky_irradiance_over_pi
    )
    eps = foam_emissivity(view_zenith, band, refractive_index).to(dtype=dtype, device=device)
    rb = as_tensor(sea_radiance, dtype, device)
    es = as_tensor(sky_irradiance_over_pi, dtype, device)
    # Written as E + ε (R_B − E): exactly R_B when E = R_B.
    return es + eps * (rb - es)


@lru_cache(maxsize=16)
def _gauss_legendre_unit(n: int) -> tuple[np.ndarray, np.ndarray]:
    """Nodes μᵢ and weights of 2 ∫₀¹ g(μ) μ dμ ≈ Σ wᵢ g(μᵢ) (Gauss–Legendre on [0, 1])."""
    x, w = np.polynomial.legendre.leggauss(n)
    mu = 0.5 * (x + 1.0)
    return mu, w * mu  # 2 · (w/2) · μ


def sky_hemispherical_mean(
    sky: Any,
    n: int = 64,
    dtype: torch.dtype | None = None,
    device: Any = None,
) -> torch.Tensor:
    """Cosine-weighted hemispherical mean of the sky radiance, E_sky/π [W m⁻² sr⁻¹].

    E_sky/π = (1/π) ∫ R_s(θ) cos θ dω = 2 ∫₀¹ R_s(μ) μ dμ (μ = cos θ, azimuthally uniform sky),
    by n-point Gauss–Legendre in μ on [0, 1] (exact for R_s polynomial in μ of degree ≤ 2n − 2).

    Args:
        sky: R_s as a callable of cos(zenith) (receives a tensor of shape (n,), returns (..., n)),
            a constant (float or tensor, returned as is: its mean is itself), or any form
            :func:`~roughsea_torch.atmosphere.as_sky` accepts (table, named atmosphere).
        n: number of nodes, ≥ 1.
        dtype, device: of the nodes given to a callable sky (default ``torch.get_default_dtype()``
            and CPU); for a float constant, of the result.

    Returns:
        E_sky/π: the shape of a constant sky, or the leading shape (...) of a callable's output.
    """
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 1:
        raise ValueError(f"n must be an integer ≥ 1, got {n!r}")
    if isinstance(sky, (int, float, np.ndarray, np.generic, torch.Tensor)) and not isinstance(sky, bool):
        check_finite_range("sky", sky, 0.0, math.inf, hi_open=True, unit="W m-2 sr-1")
        dt, dev = resolve_dtype_device(sky=sky)
        if not isinstance(sky, torch.Tensor):
            dt = dtype if dtype is not None else dt
            dev = torch.device(device) if device is not None else dev
        return as_tensor(sky, dt, dev)
    if sky is None:
        raise ValueError("sky is required: a callable of cos(zenith), a (zenith, radiance) table or a constant")
    if not callable(sky):
        sky = as_sky(sky)
    dt = dtype if dtype is not None else torch.get_default_dtype()
    if dt not in (torch.float32, torch.float64):
        raise ValueError(f"dtype must be torch.float32 or torch.float64, got {dt}")
    dev = torch.device(device) if device is not None else torch.device("cpu")
    mu_np, w_np = _gauss_legendre_unit(int(n))
    mu = torch.as_tensor(mu_np, dtype=dt, device=dev)
    w = torch.as_tensor(w_np, dtype=dt, device=dev)
    r = torch.as_tensor(sky(mu))
    if r.shape[-1:] != (int(n),):
        r = r.expand(*r.shape[:-1], int(n)) if r.ndim and r.shape[-1] == 1 else r.expand(int(n))
    return (r * w.to(r.dtype)).sum(-1)


# the kinks of Δ(θ) in μ = cos θ (85°, 65°, 45°): one Gauss–Legendre panel between each two
_PANEL_EDGES_MU = (0.0, math.cos(math.radians(85.0)), math.cos(math.radians(65.0)), math.cos(math.radians(45.0)), 1.0)


@lru_cache(maxsize=16)
def _panel_nodes(n: int) -> tuple[np.ndarray, np.ndarray]:
    """Nodes μᵢ in (0, 1) and weights of ∫₀¹ g(μ) dμ ≈ Σ wᵢ g(μᵢ): n-point Gauss–Legendre on each of
    the four panels between the kinks of Δ (the integrand is smooth on each, so the rule converges
    spectrally)."""
    x, w = np.polynomial.legendre.leggauss(n)
    mus, ws = [], []
    for a, b in zip(_PANEL_EDGES_MU[:-1], _PANEL_EDGES_MU[1:]):
        mus.append(a + (b - a) * (x + 1) / 2)
        ws.append(w * (b - a) / 2)
    return np.concatenate(mus), np.concatenate(ws)


def _check_reflection(reflection: Any) -> str:
    if reflection not in FOAM_REFLECTIONS:
        raise ValueError(f"reflection must be one of {FOAM_REFLECTIONS}; got {reflection!r}")
    return reflection


def _trailing(m: Any) -> Any:
    """The refractive index with a trailing axis for the quadrature nodes (tensors only)."""
    if isinstance(m, (tuple, list)):
        return tuple(t[..., None] if isinstance(t, torch.Tensor) else t for t in m)
    return m[..., None] if isinstance(m, torch.Tensor) else m


def foam_sky_weights(
    band: Any = LWIR,
    refractive_index: Any = None,
    reflection: str = "reciprocal",
    n: int = 16,
    dtype: torch.dtype | None = None,
    device: Any = None,
) -> tuple[torch.Tensor, torch.Tensor]:
    """Nodes μᵢ = cos θᵢ and weights wᵢ of the sky the foam reflects, S = Σᵢ wᵢ R_s(μᵢ) (Σ wᵢ = 1).

    ``"reciprocal"`` (default): wᵢ ∝ ρ_f(μᵢ) μᵢ Δμᵢ with ρ_f = 1 − ε_f (:func:`foam_emissivity`), the
    sky weighted by the foam's reflectance at each incidence (module docstring); ``"lambertian"``:
    wᵢ ∝ μᵢ Δμᵢ (S = E_sky/π). Gauss–Legendre, ``n`` nodes on each of the 4 panels between the kinks of
    Δ (4n nodes).

    Args:
        band, refractive_index: as :func:`foam_emissivity`; a tensor index (or (n, k) pair of tensors)
            of shape (...) gives weights of shape (..., 4n).
        reflection: ``"reciprocal"`` or ``"lambertian"``.
        n: nodes per panel, ≥ 1.
        dtype, device: of the nodes (default: those of a tensor index, else the default dtype, CPU).

    Returns:
        μ (4n,) and w (..., 4n).
    """
    _check_reflection(reflection)
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 1:
        raise ValueError(f"n must be an integer ≥ 1, got {n!r}")
    m = _band_index(band) if refractive_index is None else refractive_index
    parts = dict(enumerate(m)) if isinstance(m, (tuple, list)) else {0: m}
    tensors = {f"refractive_index_{i}": v for i, v in parts.items() if isinstance(v, torch.Tensor)}
    dt, dev = resolve_dtype_device(**tensors)
    dt = dtype if dtype is not None else (dt if tensors else torch.get_default_dtype())
    dev = torch.device(device) if device is not None else dev
    mu_np, w_np = _panel_nodes(int(n))
    mu = torch.as_tensor(mu_np, dtype=dt, device=dev)
    w = torch.as_tensor(w_np, dtype=dt, device=dev) * mu
    if reflection == "reciprocal":
        w = w * (1.0 - _foam_emissivity(torch.acos(mu), _trailing(m), dt))
    return mu, w / w.sum(-1, keepdim=True)


def foam_sky_radiance(
    sky: Any,
    band: Any = LWIR,
    refractive_index: Any = None,
    reflection: str = "reciprocal",
    n: int = 16,
    dtype: torch.dtype | None = None,
    device: Any = None,
) -> torch.Tensor:
    """S, the sky radiance a foam patch reflects [W m⁻² sr⁻¹]: R_foam = ε_f R_B + (1 − ε_f) S.

    ``reflection="reciprocal"`` (default): S = ∫₀¹ ρ_f R_s μ dμ / ∫₀¹ ρ_f μ dμ, ρ_f = 1 − ε_f (the
    reciprocal BRDF fixed by the measured emissivity, module docstring); ``"lambertian"``: S = E_sky/π
    = 2 ∫₀¹ R_s μ dμ (:func:`sky_hemispherical_mean`, the previous model). A weighted mean: a sky
    R_s ≡ c gives S = c (second law).

    Args:
        sky: R_s as a callable of cos(zenith) (receives μ of shape (4n,), returns (..., 4n)), a
            constant (returned as is), or any form :func:`~roughsea_torch.atmosphere.as_sky` accepts.
        band, refractive_index, n: see :func:`foam_sky_weights` (a batched index broadcasts against
            the sky's leading shape).
        reflection: ``"reciprocal"`` or ``"lambertian"``.
        dtype, device: of the nodes (see :func:`foam_sky_weights`).

    Returns:
        S, the broadcast of the sky's leading shape and the index's shape.
    """
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 1:
        raise ValueError(f"n must be an integer ≥ 1, got {n!r}")
    if _check_reflection(reflection) == "lambertian":
        return sky_hemispherical_mean(sky, 4 * int(n), dtype, device)
    if isinstance(sky, (int, float, np.ndarray, np.generic, torch.Tensor)) and not isinstance(sky, bool):
        return sky_hemispherical_mean(sky, dtype=dtype, device=device)  # checked, returned as is
    if sky is None:
        raise ValueError("sky is required: a callable of cos(zenith), a (zenith, radiance) table or a constant")
    if not callable(sky):
        sky = as_sky(sky)
    mu, w = foam_sky_weights(band, refractive_index, reflection, n, dtype, device)
    r = torch.as_tensor(sky(mu))
    return (r * w.to(r.dtype)).sum(-1)


def with_foam(apparent_radiance: Any, foam_fraction: Any, foam_radiance: Any) -> torch.Tensor:
    """Area-fraction mixture R = (1 − f) R_a + f R_foam [W m⁻² sr⁻¹].

    Args:
        apparent_radiance: R_a of the foam-free sea (Eq. 10) [W m⁻² sr⁻¹], finite and ≥ 0.
        foam_fraction: f in [0, 1] (e.g. :func:`whitecap_fraction`).
        foam_radiance: R_foam [W m⁻² sr⁻¹], finite and ≥ 0 (:func:`foam_radiance`).

    Returns:
        R, the broadcast shape of the inputs; f = 0 gives R_a exactly and f = 1 gives R_foam.
    """
    check_finite_range("apparent_radiance", apparent_radiance, 0.0, math.inf, hi_open=True, unit="W m-2 sr-1")
    check_finite_range("foam_fraction", foam_fraction, 0.0, 1.0)
    check_finite_range("foam_radiance", foam_radiance, 0.0, math.inf, hi_open=True, unit="W m-2 sr-1")
    dtype, device = resolve_dtype_device(
        apparent_radiance=apparent_radiance, foam_fraction=foam_fraction, foam_radiance=foam_radiance
    )
    ra = as_tensor(apparent_radiance, dtype, device)
    f = as_tensor(foam_fraction, dtype, device)
    rf = as_tensor(foam_radiance, dtype, device)
    # Written as the two weights: exactly R_a at f = 0 and exactly R_foam at f = 1.
    return (1.0 - f) * ra + f * rf


def crest_foam_fraction(  # ~80 lines for its docstring (the derivation of the exact mean); the code is 15
    crest: Any,
    resolved_variance: Any,
    total_variance: Any,
    whitecap_fraction: Any,
    *,
    floor: float = CREST_FOAM_FLOOR,
) -> torch.Tensor:
    """Foam fraction of a textured pixel, foam on the resolved crests: f_pix = Φ((X_r − c)/σ_u).

    The pixel's footprint splits a Gaussian crest variable X (total variance σ_X²) into the part the
    pixel resolves, X_r (the pixel's sample, variance σ_r²), and the unresolved rest, independent of
    X_r, of variance σ_X² − σ_r². Foam covers the surface where X exceeds a threshold c, so the
    fraction of the pixel's footprint under foam, given what the pixel resolves, is the probability
    that the unresolved part lifts X above c:

        f_pix = Φ((X_r − c) / σ_u),   σ_u² = max(σ_X² − σ_r², 0) + ρ² σ_X²,
        c = Φ⁻¹(1 − W) √(σ_r² + σ_u²),

    Φ the standard normal distribution function, W the whitecap fraction (Monahan &
    O'Muircheartaigh 1980, :func:`whitecap_fraction`), ρ = ``floor``.

    Exact mean. For X_r ~ N(0, σ_r²) and Z ~ N(0, 1) independent, E[Φ((X_r − c)/σ_u)] =
    P(X_r + σ_u Z > c) = P(N(0, σ_r² + σ_u²) > c) = Φ(−Φ⁻¹(1 − W)) = W, whatever σ_u: the floor ρ and
    the position-averaged variances only shape the pattern, never the ensemble mean (c is taken with
    the same σ_r² + σ_u²). Far field: σ_r = 0, X_r = 0 give f_pix = W, the uniform-fraction image.
    Only a σ_r² that is not the true variance of X_r at the point moves the mean:
    :meth:`WaveField.crest_variance` is a position average, and the texel-scale ripple of the point
    variance about it averages out over positions.

    No bias of the slope texture. Each Fourier component's X is in phase with its elevation and its
    slope in quadrature, so X_r and the resolved slope at a point are uncorrelated, hence (Gaussian)
    independent: the foam mixture leaves the ensemble mean of the slope-driven texture unchanged,
    E[(1 − f_pix) T] = (1 − W) E[T].

    Which crest. X is the :class:`~roughsea_torch.waves.WaveField`'s crest variable (``sample(...,
    crest=True)``): the downward vertical acceleration −a_z/g of the waves from the spectral peak to
    about ten times its wavenumber (sources there). Any zero-mean Gaussian field works: the elevation
    η puts the foam on the tops of the highest (dominant) crests instead.

    Degenerate ends. W = 0 gives exactly 0 (below W = 1e-30, f_pix is the value at 1e-30 scaled by
    W/1e-30: the mean stays exact, the gradient finite); W = 1 gives exactly 1; σ_X² = 0 (a field
    without crest variance) gives f_pix = W; σ_u → 0 (a footprint that resolves every band) would make
    f_pix a step in X_r: the floor ρ keeps σ_u ≥ ρ σ_X (default 0.05, an edge 0.1 σ_X wide), so f_pix
    and its gradients stay finite.

    Args:
        crest: X_r, the pixel's resolved crest variable (or elevation [m]), any shape.
        resolved_variance: σ_r², its variance (same unit squared), ≥ 0.
        total_variance: σ_X², the variance of the whole synthesized field, ≥ 0 (values below σ_r²
            are taken as σ_r²: nothing unresolved).
        whitecap_fraction: W in [0, 1], the area fraction of the mean model.
        floor: ρ ≥ 0, the smallest σ_u as a fraction of σ_X (ρ = 0 only with σ_r² < σ_X² everywhere).
    All broadcast together (e.g. X_r (B, H, W), σ_X² and W of shape (B, 1, 1)); float32/float64 and
    device follow the inputs; differentiable in all four.

    Returns:
        f_pix in [0, 1], the broadcast shape.

    Example:
        >>> import torch
        >>> x = torch.tensor([-1.0, 0.0, 2.0, 3.0])
        >>> f = crest_foam_fraction(x, torch.tensor(1.0), torch.tensor(1.1), torch.tensor(0.01))
        >>> [round(v, 3) for v in f.tolist()]
        [0.0, 0.0, 0.084, 0.959]
        >>> round(float(crest_foam_fraction(0.0, 0.0, 1.1, 0.01)), 6)  # nothing resolved: W
        0.01
    """
    check_finite_range("crest", crest)
    check_finite_range("resolved_variance", resolved_variance, 0.0, math.inf, hi_open=True)
    check_finite_range("total_variance", total_variance, 0.0, math.inf, hi_open=True)
    check_finite_range("whitecap_fraction", whitecap_fraction, 0.0, 1.0)
    if not (isinstance(floor, (int, float)) and not isinstance(floor, bool) and math.isfinite(floor) and floor >= 0):
        raise ValueError(f"floor must be a finite float ≥ 0; got {floor!r}")
    dtype, device = resolve_dtype_device(
        crest=crest, resolved_variance=resolved_variance, total_variance=total_variance,
        whitecap_fraction=whitecap_fraction,
    )
    x = as_tensor(crest, dtype, device)
    v_r = as_tensor(resolved_variance, dtype, device)
    v_t = as_tensor(total_variance, dtype, device)
    w = as_tensor(whitecap_fraction, dtype, device)
    return crest_fraction_from_variances(x, v_r, v_t, w, floor)


def crest_fraction_from_variances(x: torch.Tensor, v_r: torch.Tensor, v_t: torch.Tensor, w: torch.Tensor,
                                  floor: float = CREST_FOAM_FLOOR) -> torch.Tensor:
    """:func:`crest_foam_fraction` on tensors already checked (the renderer's, per pixel): the crest
    variable X_r (``x``), its resolved and total variances σ_r², σ_X² (``v_r``, ``v_t``) and the
    whitecap fraction W (``w``), of one dtype and device, broadcasting together."""
    v_u = torch.clamp(v_t - v_r, min=0.0) + (floor * floor) * v_t
    known = v_u > 0  # False only without crest variance at all (or ρ = 0 and nothing unresolved)
    v_u = torch.where(known, v_u, torch.ones_like(v_u))
    inner = w < 1.0
    w_q = torch.where(inner, torch.clamp(w, min=_W_MIN), torch.full_like(w, 0.5))
    q = -torch.special.ndtri(w_q)  # Φ⁻¹(1 − W), accurate for small W (no 1 − W rounding)
    z = (x - q * torch.sqrt(v_r + v_u)) * torch.rsqrt(v_u)
    f = 0.5 * torch.erfc(-z * _SQRT_HALF)  # Φ(z), accurate in the lower tail (torch.special.ndtr is not)
    f = torch.where(w < _W_MIN, f * (w / _W_MIN), f)  # exactly 0 at W = 0, mean still W
    f = torch.where(known, f, w)
    return torch.where(inner, f, torch.ones_like(f))



# erfc(a) and its derivative −(2/√π) e^(−a²) are exactly 0 in float32 from a ≈ 10.2 and in float64 from
# a ≈ 27.3 (underflow); with a margin (which also covers the rounding of the arguments, relative 1e-7 or less)
_ERFC_ZERO = {torch.float32: 11.0, torch.float64: 28.0}


def vanishing_crest(v_r: torch.Tensor, v_t: torch.Tensor, w: torch.Tensor, dtype: torch.dtype,
                    floor: float = CREST_FOAM_FLOOR) -> torch.Tensor:
    """x₀ (float64, the broadcast shape): :func:`crest_fraction_from_variances` (x, ``v_r``, ``v_t``,
    ``w``) computed in ``dtype`` is exactly 0, and so are its derivatives, for every crest x ≤ x₀; +inf
    where it does not depend on x (W ≥ 1: 1; no crest variance: W); −inf for a dtype other than float32
    and float64. f = Φ(z) = erfc(−z/√2)/2, z = (x − c)/σ_u, underflows to 0 with its derivative from
    −z/√2 ≥ a (a = 11 in float32, 28 in float64: erfc is 0 from 10.2 and 27.3), i.e. for
    x ≤ c − √2 a σ_u. (A caller may then skip what only moves x below x₀.)"""
    a = _ERFC_ZERO.get(dtype)
    v_r, v_t, w = (t.detach().double() for t in (v_r, v_t, w))
    v_u = torch.clamp(v_t - v_r, min=0.0) + (floor * floor) * v_t
    q = -torch.special.ndtri(torch.clamp(w, min=_W_MIN, max=1.0))  # (W ≥ 1: +inf below)
    x0 = q * torch.sqrt(v_r + v_u) - (math.sqrt(2.0) * (a or 0.0)) * torch.sqrt(v_u)
    x0 = torch.where((v_u > 0) & (w < 1.0), x0, torch.full_like(x0, math.inf))
    return x0 if a is not None else torch.full_like(x0, -math.inf)

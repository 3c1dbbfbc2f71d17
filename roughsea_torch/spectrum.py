"""The wind-wave spectrum of Elfouhaily et al. (1997) and the gravity–capillary dispersion relation.

- :func:`elfouhaily_spectrum` (with :func:`elfouhaily_omnidirectional` and
  :func:`elfouhaily_spreading`): the unified directional wavenumber spectrum of Elfouhaily,
  Chapron, Katsaros & Vandemark, *A unified directional spectrum for long and short wind-driven
  waves*, J. Geophys. Res. 102(C7), 15781–15796, 1997 ("ECKV"; equation numbers below are the
  paper's).
- :func:`dispersion`: deep-water gravity–capillary dispersion ω² = g k (1 + (k/k_m)²),
  g = 9.81 m s⁻², k_m = 370 rad m⁻¹ (ECKV Eq. 24; phase-speed minimum c_m = √(2g/k_m) ≈ 0.23 m s⁻¹).

The random sea surfaces synthesized from this spectrum are :class:`roughsea_torch.waves.WaveField`;
the constants and the spectrum functions are also importable from :mod:`roughsea_torch.waves`.
Properties measured with this implementation (peak, Hs, mean-square slope against Cox & Munk):
``docs/notes/wave_spectrum.md``.

Why not a library
-----------------
The PyPI package ``wavespectra`` only holds frequency spectra (JONSWAP, Pierson–Moskowitz, TMA),
needs xarray/dask and is numpy-only (no autograd), so ECKV is written here in torch, following the
paper's equations. The constants were cross-checked against three public implementations: RTTOV's
``rttov_refsun.F90`` / ``rttov_const.F90`` (EUMETSAT NWP SAF; equation numbers in comments),
``oceansar`` (``oceansar/spec/elfouhaily.py``, ``oceansar/spread/elfouhaily.py``) and the FFT
ocean of Bruneton, Neyret & Holzschuch (2010) as reproduced in public ports. They agree on
every constant below except the two points listed under *Deviations*.

ECKV as implemented (k [rad m⁻¹], U10 [m s⁻¹], Ω_c inverse wave age, default 0.84 = fully developed)
----------------------------------------------------------------------------------------------------
- k_p = g Ω_c² / U10² (Eq. 3); c(k) = ω(k)/k (Eq. 24); Ω = U10 / c(k_p) (text after Eq. 31).
- Long waves (Eqs. 2, 3, 31–34): α_p = 6·10⁻³ √Ω, γ = 1.7 (Ω_c < 1) or 1.7 + 6 log₁₀ Ω_c,
  σ = 0.08 (1 + 4 Ω_c⁻³), Γ = exp[−(√(k/k_p) − 1)² / (2σ²)], J_p = γ^Γ,
  L_PM = exp[−(5/4)(k_p/k)²], F_p = L_PM J_p exp[−(Ω/√10)(√(k/k_p) − 1)],
  B_l = ½ α_p (c_p/c) F_p.
- Short waves (Eqs. 40, 41, 44): c_m = 0.23 m s⁻¹, k_m = 370 rad m⁻¹,
  α_m = 10⁻² [1 + ln(u*/c_m)] (u* ≤ c_m) or 10⁻² [1 + 3 ln(u*/c_m)] (u* > c_m),
  F_m = exp[−¼ (k/k_m − 1)²], B_h = ½ α_m (c_m/c) F_m.
- Friction velocity (Eqs. 60, 66): z₀ = 3.7·10⁻⁵ (U10²/g) Ω^0.9, u* = κ U10 / ln(10 m / z₀),
  κ = 0.41 (the von Kármán value RTTOV and Bruneton et al. use).
- Omnidirectional elevation spectrum S(k) = k⁻³ (B_l + B_h) (Eq. 30), ∫ S dk = ⟨η²⟩.
- Spreading (Eqs. 49, 57, 59): Φ(k, φ) = (1 + Δ(k) cos 2φ) / (2π), ∫₀^{2π} Φ dφ = 1,
  Δ(k) = tanh[a₀ + a_p (c/c_p)^2.5 + a_m (c_m/c)^2.5], a₀ = ln 2 / 4, a_p = 4, a_m = 0.13 u*/c_m.
- Directional spectrum F(k, φ) = S(k) Φ(k, φ) / k, so that ∫∫ F k dk dφ = ⟨η²⟩ [m²] and the slope
  covariance is ∫∫ F k kᵀ k dk dφ; F is in m⁴ (per rad² of wavenumber plane).

Deviations (Notes)
------------------
1. F_m is multiplied by L_PM, as McDaniel (2001) proposed and oceansar and Bruneton et al. do:
   without it B_h ∝ c_m/c ∝ √k below the peak, S ∝ k^-2.5 as k → 0 and the elevation variance
   diverges. The factor changes nothing above k ≈ 3 k_p, where the short-wave part matters.
2. α_m is clipped at 0. With Eqs. 60/66, u* < c_m/e (U10 ≲ 2.7 m s⁻¹) makes Eq. 44 negative and
   with it the spectrum (RTTOV floors the wind at 0.6 m s⁻¹ for the same reason). Below that wind
   the short-wave part is absent; the gradient with respect to wind speed is then that of B_l.
"""

from __future__ import annotations

import math
from typing import Any

import torch

from ._validation import as_tensor, check_finite_range, resolve_dtype_device
from .slopes import MAX_WIND_SPEED

__all__ = [
    "GRAVITY",
    "K_M",
    "C_M",
    "VON_KARMAN",
    "MAX_WIND",
    "dispersion",
    "check_wind_speed",
    "check_wave_age",
    "eckv_terms",
    "elfouhaily_omnidirectional",
    "elfouhaily_spreading",
    "elfouhaily_spectrum",
]

GRAVITY = 9.81  # g [m s⁻²]
K_M = 370.0  # k_m, wavenumber of the phase-speed minimum [rad m⁻¹] (ECKV text below Eq. 40)
C_M = 0.23  # c_m, minimum phase speed [m s⁻¹] (ECKV text below Eq. 40)
VON_KARMAN = 0.41  # κ in u* = κ U10 / ln(10/z0) (ECKV Eq. 60)
MAX_WIND = MAX_WIND_SPEED  # [m s⁻¹] upper bound accepted for U10: the package's one range (slopes.MAX_WIND_SPEED)
_A0 = math.log(2.0) / 4.0  # a_0 (ECKV Eq. 59)
_AP = 4.0  # a_p (ECKV Eq. 59)


def dispersion(k: Any) -> torch.Tensor:
    """Angular frequency ω(k) = √(g k (1 + (k/k_m)²)) of deep-water gravity–capillary waves [rad s⁻¹].

    Args:
        k: wavenumber [rad m⁻¹], ≥ 0; float or tensor of any shape.

    Returns:
        ω with the shape, dtype and device of ``k`` (ECKV Eq. 24 with g = 9.81 m s⁻², k_m = 370 rad m⁻¹).
        The phase speed ω/k has its minimum √(2g/k_m) ≈ 0.2303 m s⁻¹ at k = k_m.

    Example:
        >>> round(float(dispersion(370.0) / 370.0), 4)
        0.2303
    """
    check_finite_range("k", k, 0.0, unit="rad/m")
    dtype, device = resolve_dtype_device(k=k)
    kt = as_tensor(k, dtype, device)
    return torch.sqrt(GRAVITY * kt * (1.0 + (kt / K_M) ** 2))


def check_wind_speed(name: str, wind_speed: Any) -> None:
    """``ValueError`` naming ``name`` unless ``wind_speed`` is a wind speed U10 in (0, MAX_WIND] m/s
    (float or tensor); 0 gets its own message (a calm sea has no wave texture)."""
    vals = wind_speed.detach() if isinstance(wind_speed, torch.Tensor) else torch.as_tensor(wind_speed, dtype=torch.float64)
    if vals.numel() and bool((vals == 0).any()):
        raise ValueError(
            f"{name} must lie in (0, {MAX_WIND:g}] m/s; got 0. A calm sea has no wave texture: "
            "render the expectation alone (the statistical slope model) instead of a WaveField"
        )
    check_finite_range(name, wind_speed, 0.0, MAX_WIND, lo_open=True, unit="m/s")


def check_wave_age(inverse_wave_age: Any) -> None:
    """``ValueError`` unless ``inverse_wave_age`` Ω_c lies in [0.84, 5] (0.84: a fully developed sea)."""
    check_finite_range("inverse_wave_age", inverse_wave_age, 0.84, 5.0)


def eckv_terms(k: torch.Tensor, wind: torch.Tensor, omega_c: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
    """(S(k), Δ(k)) of ECKV (Eqs. 30 and 57; module docstring) for broadcastable tensors k [rad m⁻¹],
    U10 [m s⁻¹] and Ω_c; no validation (callers check)."""
    g = GRAVITY
    c = torch.sqrt(g / k * (1.0 + (k / K_M) ** 2))  # Eq. 24
    kp = g * omega_c**2 / wind**2  # Eq. 3
    cp = torch.sqrt(g / kp * (1.0 + (kp / K_M) ** 2))
    big_omega = wind / cp  # text after Eq. 31
    alpha_p = 6e-3 * torch.sqrt(big_omega)  # Eq. 34
    sigma = 0.08 * (1.0 + 4.0 * omega_c ** (-3.0))  # Eq. 3
    gamma = torch.where(omega_c < 1.0, torch.full_like(omega_c, 1.7), 1.7 + 6.0 * torch.log10(omega_c))
    root = torch.sqrt(k / kp)
    big_gamma = torch.exp(-((root - 1.0) ** 2) / (2.0 * sigma**2))
    jp = torch.exp(big_gamma * torch.log(gamma))  # γ^Γ, Eq. 3
    lpm = torch.exp(-1.25 * (kp / k) ** 2)  # Eq. 2
    fp = lpm * jp * torch.exp(-big_omega / math.sqrt(10.0) * (root - 1.0))  # Eq. 32
    b_l = 0.5 * alpha_p * (cp / c) * fp  # Eq. 31

    z0 = 3.7e-5 * wind**2 / g * big_omega**0.9  # Eq. 66
    ustar = VON_KARMAN * wind / torch.log(10.0 / z0)  # Eq. 60
    log_ratio = torch.log(ustar / C_M)
    alpha_m = 0.01 * torch.where(ustar <= C_M, 1.0 + log_ratio, 1.0 + 3.0 * log_ratio)  # Eq. 44
    alpha_m = torch.clamp(alpha_m, min=0.0)  # deviation 2 (module notes)
    fm = lpm * torch.exp(-0.25 * (k / K_M - 1.0) ** 2)  # Eq. 41 × L_PM (deviation 1)
    b_h = 0.5 * alpha_m * (C_M / c) * fm  # Eq. 40

    s = (b_l + b_h) / k**3  # Eq. 30
    a_m = 0.13 * ustar / C_M  # Eq. 59
    delta = torch.tanh(_A0 + _AP * (c / cp) ** 2.5 + a_m * (C_M / c) ** 2.5)  # Eq. 57
    return s, delta


def _spectrum_inputs(k: Any, wind_speed: Any, inverse_wave_age: Any, **extra: Any):
    check_finite_range("k", k, 0.0, lo_open=True, unit="rad/m")
    check_wind_speed("wind_speed", wind_speed)
    check_wave_age(inverse_wave_age)
    dtype, device = resolve_dtype_device(k=k, wind_speed=wind_speed, inverse_wave_age=inverse_wave_age, **extra)
    return (
        dtype,
        device,
        as_tensor(k, dtype, device),
        as_tensor(wind_speed, dtype, device),
        as_tensor(inverse_wave_age, dtype, device),
    )


def elfouhaily_omnidirectional(k: Any, wind_speed: Any, inverse_wave_age: Any = 0.84) -> torch.Tensor:
    """Omnidirectional elevation spectrum S(k) = k⁻³ (B_l + B_h) of ECKV (Eq. 30) [m³ rad⁻¹].

    Args:
        k: wavenumber [rad m⁻¹], > 0.
        wind_speed: U10, wind speed at 10 m [m s⁻¹], in (0, 80].
        inverse_wave_age: Ω_c = U10 / c_p [dimensionless] in [0.84, 5]; 0.84 is a fully developed sea.

    Inputs broadcast; differentiable in all three; float32/float64 and device follow the inputs.
    ∫ S dk = ⟨η²⟩ [m²] and ∫ k² S dk is the total mean-square slope.

    Example:
        >>> import torch
        >>> k = torch.logspace(-3, 1, 2001, dtype=torch.float64)
        >>> s = elfouhaily_omnidirectional(k, 10.0)
        >>> kp = 9.81 * 0.84**2 / 10.0**2
        >>> round(float(k[s.argmax()] / kp), 2)
        0.98
    """
    _, _, kt, u, om = _spectrum_inputs(k, wind_speed, inverse_wave_age)
    return eckv_terms(kt, u, om)[0]


def elfouhaily_spreading(k: Any, wind_speed: Any, inverse_wave_age: Any = 0.84) -> torch.Tensor:
    """Spreading ratio Δ(k) of ECKV (Eq. 57) [dimensionless, in (0, 1)].

    The angular distribution is Φ(k, φ) = (1 + Δ(k) cos 2φ) / (2π) (Eq. 49), which integrates to 1
    over φ ∈ [0, 2π); the upwind (φ = 0) to crosswind ratio of slope variance per wavenumber is
    (1 + Δ/2) / (1 − Δ/2). Arguments as in :func:`elfouhaily_omnidirectional`.
    """
    _, _, kt, u, om = _spectrum_inputs(k, wind_speed, inverse_wave_age)
    return eckv_terms(kt, u, om)[1]


def elfouhaily_spectrum(k: Any, phi: Any, wind_speed: Any, inverse_wave_age: Any = 0.84) -> torch.Tensor:
    """Directional wavenumber spectrum F(k, φ) = S(k) (1 + Δ(k) cos 2φ) / (2π k) of ECKV [m⁴ rad⁻²].

    Normalized so that ∫₀^∞ ∫₀^{2π} F(k, φ) k dφ dk = ⟨η²⟩ [m²] (so F d²k, with d²k = k dk dφ the
    wavenumber-plane element, is the elevation variance of the modes in d²k).

    Args:
        k: wavenumber [rad m⁻¹], > 0.
        phi: direction of the wave vector measured from the DOWNWIND direction [rad]. F is
            centrosymmetric (F(k, φ) = F(k, φ + π)), as ECKV's spreading is.
        wind_speed: U10 [m s⁻¹] in (0, 80].
        inverse_wave_age: Ω_c in [0.84, 5] (default 0.84, fully developed).

    Returns:
        F broadcast over the inputs; float32/float64 and device follow them; differentiable in
        k, φ and wind_speed. Equations and deviations: module docstring.

    Example:
        >>> import math, torch
        >>> k = torch.tensor(1.0, dtype=torch.float64)
        >>> up, cross = elfouhaily_spectrum(k, torch.tensor([0.0, math.pi / 2]), 10.0)
        >>> bool(up > cross)
        True
    """
    check_finite_range("phi", phi, unit="rad")
    dtype, device, kt, u, om = _spectrum_inputs(k, wind_speed, inverse_wave_age, phi=phi)
    ph = as_tensor(phi, dtype, device)
    s, delta = eckv_terms(kt, u, om)
    return s / kt * (1.0 + delta * torch.cos(2.0 * ph)) / (2.0 * math.pi)

"""Wind-wave spectrum and a synthesized, band-split random sea surface (texture for near range).

What is here
------------
- :func:`elfouhaily_spectrum` (with :func:`elfouhaily_omnidirectional` and
  :func:`elfouhaily_spreading`): the unified directional wavenumber spectrum of Elfouhaily,
  Chapron, Katsaros & Vandemark, *A unified directional spectrum for long and short wind-driven
  waves*, J. Geophys. Res. 102(C7), 15781–15796, 1997 ("ECKV"; equation numbers below are the
  paper's).
- :func:`dispersion`: deep-water gravity–capillary dispersion ω² = g k (1 + (k/k_m)²),
  g = 9.81 m s⁻², k_m = 370 rad m⁻¹ (ECKV Eq. 24; phase-speed minimum c_m = √(2g/k_m) ≈ 0.23 m s⁻¹).
- :class:`WaveField`: Gaussian random surfaces (elevation, slopes and a crest variable for the
  foam, the downward acceleration of the breaking range) synthesized by an inverse discrete Fourier
  transform of random Fourier amplitudes shaped by the spectrum (Tessendorf, *Simulating ocean water*, SIGGRAPH course notes,
  2001), split into octave bands so that each band can be faded out where a pixel footprint no
  longer resolves it (``docs/waves.md`` §2, the two-scale principle). :class:`WaveBands` is the
  band layout.

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

Facts measured with this implementation (``tests/test_waves.py``): the omnidirectional peak is at
0.977 k_p; for Ω_c = 0.84 the long-wave part alone gives Hs = 4 √⟨η²⟩ = 0.249 U10²/g, 13 % above
Pierson–Moskowitz (0.209 U19.5²/g = 0.220 U10²/g); the total mean-square slope (k ≤ 10³ rad/m) is
0.032, 0.061 and 0.083 at U10 = 5, 10, 15 m s⁻¹ against Cox & Munk's clean-surface
0.003 + 5.12·10⁻³ W (W at 12.5 m) = 0.029, 0.055, 0.081 ± 0.004. The long-wave part alone
contributes a wind-independent ≈ 0.018 (the shape scales with k_p), so at U10 ≲ 3 m s⁻¹ ECKV is
rougher than Cox–Munk.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from numbers import Integral
from typing import Any

import numpy as np
import torch
import torch.nn.functional as F_nn

from ._validation import (ParsedSeeds, as_tensor, check_finite_range, check_same_device, parse_seeds, per_batch,
                          resolve_dtype_device)

__all__ = [
    "GRAVITY",
    "K_M",
    "C_M",
    "dispersion",
    "elfouhaily_omnidirectional",
    "elfouhaily_spreading",
    "elfouhaily_spectrum",
    "CREST_CUTOFF",
    "WaveBands",
    "WaveField",
]

GRAVITY = 9.81  # g [m s⁻²]
K_M = 370.0  # k_m, wavenumber of the phase-speed minimum [rad m⁻¹] (ECKV text below Eq. 40)
C_M = 0.23  # c_m, minimum phase speed [m s⁻¹] (ECKV text below Eq. 40)
VON_KARMAN = 0.41  # κ in u* = κ U10 / ln(10/z0) (ECKV Eq. 60)
MAX_WIND = 80.0  # [m s⁻¹] upper bound accepted for U10
MAX_TIME_S = 1e9  # [s] |time| of a realization: WaveField.sample, SeaScene(time_s=), render_clip
MAX_WIND_DIRECTION = 1e6  # [rad] |wind direction| accepted by WaveField and SeaScene
_A0 = math.log(2.0) / 4.0  # a_0 (ECKV Eq. 59)
_AP = 4.0  # a_p (ECKV Eq. 59)
CREST_CUTOFF = 10.0  # k_b / k_p of the crest variable's low pass (WaveField docstring, *Crest variable*)


# ---------------------------------------------------------------------------------------------
# Dispersion and the ECKV spectrum
# ---------------------------------------------------------------------------------------------
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


def _check_wind(name: str, wind_speed: Any) -> None:
    vals = wind_speed.detach() if isinstance(wind_speed, torch.Tensor) else torch.as_tensor(wind_speed, dtype=torch.float64)
    if vals.numel() and bool((vals == 0).any()):
        raise ValueError(
            f"{name} must lie in (0, {MAX_WIND:g}] m/s; got 0. A calm sea has no wave texture: "
            "render the expectation alone (the statistical slope model) instead of a WaveField"
        )
    check_finite_range(name, wind_speed, 0.0, MAX_WIND, lo_open=True, unit="m/s")


def check_time(name: str, time_s: Any) -> None:
    """``ValueError`` naming ``name`` unless ``time_s`` is a number or tensor of times in
    [−MAX_TIME_S, MAX_TIME_S] [s] (finite): the times a wave field is sampled at."""
    check_finite_range(name, time_s, -MAX_TIME_S, MAX_TIME_S, unit="s")


def _check_wave_age(inverse_wave_age: Any) -> None:
    check_finite_range("inverse_wave_age", inverse_wave_age, 0.84, 5.0)


def _eckv(k: torch.Tensor, wind: torch.Tensor, omega_c: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
    """(S(k), Δ(k)) of ECKV for broadcastable tensors; no validation (callers check)."""
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
    _check_wind("wind_speed", wind_speed)
    _check_wave_age(inverse_wave_age)
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
    return _eckv(kt, u, om)[0]


def elfouhaily_spreading(k: Any, wind_speed: Any, inverse_wave_age: Any = 0.84) -> torch.Tensor:
    """Spreading ratio Δ(k) of ECKV (Eq. 57) [dimensionless, in (0, 1)].

    The angular distribution is Φ(k, φ) = (1 + Δ(k) cos 2φ) / (2π) (Eq. 49), which integrates to 1
    over φ ∈ [0, 2π); the upwind (φ = 0) to crosswind ratio of slope variance per wavenumber is
    (1 + Δ/2) / (1 − Δ/2). Arguments as in :func:`elfouhaily_omnidirectional`.
    """
    _, _, kt, u, om = _spectrum_inputs(k, wind_speed, inverse_wave_age)
    return _eckv(kt, u, om)[1]


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
    s, delta = _eckv(kt, u, om)
    return s / kt * (1.0 + delta * torch.cos(2.0 * ph)) / (2.0 * math.pi)


# ---------------------------------------------------------------------------------------------
# Band layout
# ---------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class WaveBands:
    """Layout of the synthesized bands: wavenumber edges and the periodic tile of each band.

    Band o holds the Fourier modes with k_o⁻ ≤ |k| < k_o⁺ (``k_edges[o]``, ``k_edges[o + 1]``). It is
    synthesized on its own periodic tile of ``tile_size`` × ``tile_size`` texels whose fundamental
    Δk_o = k_o⁻ / ``inner_radius``, i.e. tile length L_o = 2π ``inner_radius`` / k_o⁻; the band's
    annulus then spans ``inner_radius`` … ``inner_radius`` · k_o⁺/k_o⁻ fundamentals.

    Defaults and why:
        - ``k_edges`` = 2⁻⁸ … 2⁸ rad m⁻¹: 16 octave bands, wavelengths 2.45 cm … 1608 m (a 20 m s⁻¹
          fully developed sea peaks at 363 m, 30 m s⁻¹ at 816 m).
        - ``inner_radius`` = 4: an octave band holds the lattice points 4 ≤ |k|/Δk < 8, about
          π (8² − 4²) ≈ 150 modes (75 independent complex amplitudes and their conjugates).
        - ``tile_size`` = 128: the highest mode of a band is 8 Δk = 2π/16 per texel, 16 texels per
          wavelength. Bilinear interpolation (see :class:`WaveField`) then keeps, averaged over
          positions, a fraction (2 + cos θx)(2 + cos θy)/9 of a mode's variance (θ = k·texel ≤ 0.39
          here, ≥ 0.95); :meth:`WaveField.band_covariance` includes that factor exactly. A band's
          tile costs (N + 1)² × 3 channels × 4 bytes = 0.2 MB in float32, 3.2 MB for the 16 bands.

    Tile lengths differ from band to band (L_o = 6434 m … 0.196 m by halves), so no pattern repeats
    across bands; a single band repeats with its own period of 4–8 of its wavelengths.

    Example:
        >>> b = WaveBands()
        >>> b.n_bands, round(b.tile_length[0], 1), round(b.tile_length[-1], 4)
        (16, 6434.0, 0.1963)
    """

    k_edges: tuple[float, ...] = tuple(2.0**e for e in range(-8, 9))
    tile_size: int = 128
    inner_radius: float = 4.0

    def __post_init__(self) -> None:
        edges = tuple(float(e) for e in self.k_edges)
        object.__setattr__(self, "k_edges", edges)
        if len(edges) < 2:
            raise ValueError("k_edges: need at least 2 edges (one band) [rad/m]")
        if not all(math.isfinite(e) and e > 0 for e in edges):
            raise ValueError(f"k_edges must be finite and > 0 rad/m; got {edges}")
        if not all(b > a for a, b in zip(edges[:-1], edges[1:])):
            raise ValueError(f"k_edges must be strictly increasing; got {edges}")
        if isinstance(self.tile_size, bool) or not isinstance(self.tile_size, Integral) or self.tile_size < 8 or self.tile_size % 2:
            raise ValueError(f"tile_size must be an even integer ≥ 8; got {self.tile_size!r}")
        object.__setattr__(self, "tile_size", int(self.tile_size))
        if not (math.isfinite(self.inner_radius) and self.inner_radius > 0):
            raise ValueError(f"inner_radius must be finite and > 0 fundamentals; got {self.inner_radius!r}")
        for o in range(self.n_bands):
            outer = self.inner_radius * edges[o + 1] / edges[o]
            if outer > self.tile_size / 4:
                raise ValueError(
                    f"k_edges/inner_radius: band {o} reaches {outer:g} fundamentals of its tile; keep it "
                    f"≤ tile_size/4 = {self.tile_size / 4:g} (half the Nyquist index) so bilinear "
                    "interpolation stays accurate"
                )

    @classmethod
    def octaves(cls, k_min: float, n_bands: int, *, tile_size: int = 128, inner_radius: float = 4.0) -> WaveBands:
        """``n_bands`` octave bands starting at ``k_min`` [rad m⁻¹]."""
        return cls(tuple(float(k_min) * 2.0**o for o in range(int(n_bands) + 1)), tile_size, inner_radius)

    @property
    def n_bands(self) -> int:
        return len(self.k_edges) - 1

    @property
    def band_wavenumber(self) -> tuple[float, ...]:
        """Centre (geometric mean) wavenumber of each band [rad m⁻¹]."""
        return tuple(math.sqrt(a * b) for a, b in zip(self.k_edges[:-1], self.k_edges[1:]))

    @property
    def fundamental(self) -> tuple[float, ...]:
        """Δk_o, the lattice spacing of each band's tile [rad m⁻¹]."""
        return tuple(a / self.inner_radius for a in self.k_edges[:-1])

    @property
    def tile_length(self) -> tuple[float, ...]:
        """L_o = 2π/Δk_o, the period of each band's tile [m]."""
        return tuple(2.0 * math.pi / dk for dk in self.fundamental)

    @property
    def max_index(self) -> int:
        """Largest |lattice index| any band uses (the compact spectrum is (2M+1) × (M+1))."""
        return max(
            int(math.ceil(self.inner_radius * b / a)) for a, b in zip(self.k_edges[:-1], self.k_edges[1:])
        )


# ---------------------------------------------------------------------------------------------
# Band window
# ---------------------------------------------------------------------------------------------
_WIN_LO = 1.0 / math.sqrt(2.0)  # u = k_o f / π below which a band is fully resolved (w = 1)
_WIN_HI = math.sqrt(2.0)  # u above which it is fully unresolved (w = 0)
_CHUNK_ELEMENTS = 2**18  # point-evaluations per chunk in WaveField.sample
_BLOCK = 512  # points per block of the footprint's range (WaveField._sample_points)
_DOUBLED_ELEMENTS = 2**21  # elements of the doubled band tiles made in one copy (WaveField._sample_points)


def _window(footprint: torch.Tensor, k_centre: float | Sequence[float]) -> torch.Tensor:
    """w = 1 − smoothstep(t), t = clamp((u − u₀)/(u₁ − u₀), 0, 1), u = k_o f / π (see band_weights),
    for one band's centre k_o, or for a sequence of them (one more trailing axis, a band each)."""
    if isinstance(k_centre, (list, tuple)):
        scale = torch.tensor([k / math.pi / (_WIN_HI - _WIN_LO) for k in k_centre], dtype=footprint.dtype,
                             device=footprint.device)
        footprint = footprint[..., None]
    else:
        scale = k_centre / math.pi / (_WIN_HI - _WIN_LO)
    t = torch.clamp(footprint * scale - _WIN_LO / (_WIN_HI - _WIN_LO), 0.0, 1.0)
    return 1.0 - t * t * (3.0 - 2.0 * t)


# ---------------------------------------------------------------------------------------------
# The random surface
# ---------------------------------------------------------------------------------------------
class WaveField:
    """A batch of random sea surfaces (one per image), split into octave bands, evaluated at points.

    Args:
        wind_speed: U10 [m s⁻¹] in (0, 80]; float or tensor (B,). Differentiable (the Fourier
            amplitudes are √(F Δk²) of the spectrum at this wind; the random draws are fixed).
            0 raises: a calm sea has no texture, render the expectation alone.
        seed: an int (then B = 1; a numpy integer or 0-D integer tensor/array counts as one) or a
            sequence / 1-D integer tensor or array of B ints, each in [0, 2**63).
        wind_direction: world azimuth of the UPWIND slope axis x_s [rad] (``docs/physics.md`` §2);
            float or (B,). The waves travel DOWNWIND, towards azimuth ``wind_direction + π``.
        inverse_wave_age: Ω_c in [0.84, 5]; float or (B,).
        dtype: torch.float32 or torch.float64, the dtype of tiles and outputs.
        device: the device of tiles and outputs; default the device of the tensor arguments, else CPU.
        bands: a :class:`WaveBands` layout (default: 16 octaves, 2.45 cm … 1.6 km).
        min_band_share: leave out the bands (per image) that carry less than this share of the
            image's slope variance and less than this share of its crest variable's variance,
            in [0, 1); default 0 (every band). Left-out bands have zero amplitudes, so every
            statistic (:meth:`band_covariance`, :meth:`resolved_covariance`, the variances) is
            that of the field without them, and :meth:`sample` skips them. The renderer uses
            ``TableSize.texture_min_band_share`` (1e-8; ``SeaScene.wave_field``): on the
            spectrum's low-k flank, far below the peak of a light wind, whole octaves carry 1e-10
            to 1e-7 of the slope variance (their slope amplitude 1e-5 to 3e-4 of the field's);
            they still carry elevation, which the renderer does not use. The set left out changes
            in steps with the wind, so a realization jumps by that little as the wind crosses a
            threshold (the gradient with respect to the wind does not see the step).

    Synthesis (Tessendorf 2001, with two changes that make the result exact and one-way):
        For band o on its tile (length L_o, N × N texels, lattice k = Δk_o (i, j)), every mode of
        the band's annulus gets a complex amplitude H₀(k) = W(k) √(F(k, φ) Δk_o²) where W is
        complex white noise made Hermitian, W(−k) = W(k)*, with E|W|² = 1 (so each real component of
        H₀ has variance F Δk²/2, and ⟨η²⟩ = Σ_k F Δk² exactly, summing over the whole lattice).
        Time: H(k, t) = H₀(k) exp(−i s(k) ω(k) t) with s(k) = sign(k · d) for d the downwind unit
        vector (ties on the crosswind line broken antisymmetrically). s(−k) = −s(k) keeps H
        Hermitian (real field), and each pair H(k) e^{ik·x} + H(−k) e^{−ik·x} is one wave travelling
        DOWNWIND at its phase speed ω/k. (Tessendorf's h₀(k) e^{iωt} + h₀*(−k) e^{−iωt} with
        independent h₀(k), h₀(−k) sends half of the energy upwind; ECKV's spreading is
        centrosymmetric and does not say which way a wave runs, the wind does.)
        Elevation η̂ = H, slopes ŝ = −i k H (s = −∇η, ``docs/physics.md`` §2), computed spectrally.
        Field on the texels: η(x_n) = Σ_k H(k) e^{ik·x_n}, evaluated directly on the (N + 1)²
        texels of the circularly padded tile by two small matmuls (along y over the 2M + 1 = 17
        non-zero rows, along x over the M + 1 = 9 stored columns): cheaper than an inverse FFT of
        a 128² grid that is 99 % zeros, and no padding copy.

    Random draws:
        Image i draws its white noise on the CPU from ``torch.Generator().manual_seed(seed_i)`` in
        float64 (all bands at once, fixed order), then casts and moves it. Everything per image
        (spectrum, phases, the two matmuls) runs in a per-image loop on tensors whose shapes do not
        depend on the batch, and the batched steps afterwards are elementwise or per-sample
        (``grid_sample``; points split into chunks only along the points), so image i of a batch is
        bitwise the image rendered alone, on the same device and dtype (tested on CPU, 1 and 2
        threads). The spectrum, its gradient and the phases ω t are computed in float64
        and cast, so float32 and float64 fields agree to float32 rounding.

    Evaluation (:meth:`sample`):
        Each band's tile is padded circularly by one texel and sampled bilinearly with
        ``grid_sample`` (align_corners=True) at (x mod L_o, y mod L_o): all channels (η, s_x, s_y)
        of a band in one call, 16 calls for the default layout. Bilinear interpolation at a
        fraction u of a texel keeps a share (1 − u)² + u² + 2u(1 − u) cos θ of a mode's variance per
        axis (θ = k_axis × texel), (2 + cos θ)/3 on average over positions;
        :meth:`band_covariance` includes that factor, so it and :meth:`resolved_covariance` are
        the covariance of what :meth:`sample` returns at uniformly distributed points. For the
        default layout the factor is ≥ 0.95 per mode and the band-averaged slope-variance loss
        1.3–2.4 % (U10 = 10 m/s; more in the lowest bands); what stays uncorrected is the
        texel-scale ripple of the ensemble variance about that average, from +1.3…+2.5 % at texel
        nodes to −0.7…−1.2 % at texel centres.

    Band window:
        :meth:`band_weights`: compact, C¹, one octave wide, so a band is exactly absent beyond
        1.41 π / k_o of footprint; :meth:`sample` then skips it, and only evaluates each band on
        the contiguous range of points where some image still needs it (points are processed in
        chunks), which is where most of the time goes on a CPU. The window multiplies every
        channel alike (elevation, slopes, crest variable): what a footprint resolves of η is the
        same bands as of the slopes; :meth:`elevation_variance` and :meth:`crest_variance` are the
        variances of what :meth:`sample` returns at a footprint (position averages, like
        :meth:`resolved_covariance`).

    Crest variable (``sample(..., crest=True)``; where foam goes, :func:`~roughsea_torch.foam.crest_foam_fraction`):
        X = Σ_k G(k) H(k) e^{ik·x},  G(k) = (ω(k)²/g) / √(1 + (k/k_b)⁴),  k_b = ``CREST_CUTOFF`` k_p = 10 k_p,
        k_p = g Ω_c²/U10² (ECKV Eq. 3). For linear waves ∂²η/∂t² = −ω² η component by component,
        so X is the downward vertical acceleration of the surface in units of g, −a_z/g, of the
        waves from the spectral peak up to about k_b (a second-order Butterworth low pass: half
        power at k_b, the variance per octave falling 16-fold per octave above). Dimensionless,
        zero-mean Gaussian; each component's X is in phase with its elevation (X > 0 on crests)
        and in quadrature with its slope, so X and the slopes at a point are uncorrelated.
        Differentiable in the wind (k_b moves with k_p).

        Why this and not the elevation. (1) The breaking criterion of Longuet-Higgins (1969,
        *On wave breaking and the equilibrium spectrum of wind-generated waves*, Proc. R. Soc.
        Lond. A 310, 151–159): a crest breaks when its downward acceleration reaches g/2, the value
        at the crest of the limiting Stokes wave; Snyder & Kennedy (1983, *On the formation of
        whitecaps by a threshold mechanism, Part I*, J. Phys. Oceanogr. 13, 1482–1492) and
        Srokosz (1986, *On the probability of wave breaking in deep water*, J. Phys. Oceanogr. 16,
        382–385) made it the breaking / whitecap probability of a Gaussian sea, the area where
        −a_z exceeds a threshold; on the whole spectrum that acceleration is dominated by the
        short waves and the result depends on the spectral cut-off (their caveat). Only the
        variable is taken from there: the level comes from Monahan & O'Muircheartaigh's W (on this
        linear field the g/2 threshold would cover 2e-7 to 6e-7 of the sea at any wind, σ_X ≈ 0.10 as
        ECKV scales with k_p; W puts the threshold at 0.39 g, 0.24 g, 0.13 g for U10 = 2, 10,
        20 m/s). (2) The cut-off: whitecaps come from the breaking of the dominant waves and of
        waves somewhat shorter (Banner, Babanin & Young 2000, *Breaking probability for dominant
        waves on the sea surface*, J. Phys. Oceanogr. 30, 3145–3160, dominant wavelengths 3–300 m;
        Phillips' Λ(c), the length of breaking crests per unit area and breaker speed c, spans
        speeds below c_p), while waves much shorter than the peak break without entraining air
        (microscale breaking, Banner & Phillips 1974, J. Fluid Mech. 65) and leave no whitecap;
        k_b = 10 k_p is the wavelength λ_p/10, the phase speed c_p/√10 ≈ 0.32 c_p. The ratio is a
        modelling choice, not a measured constant (``CREST_CUTOFF``).
        (3) Short breakers ride on the long crests, where they are steepened (Longuet-Higgins &
        Stewart 1960, J. Fluid Mech. 8; Phillips & Banner 1974, J. Fluid Mech. 66) and where
        whitecaps are seen (Donelan, Longuet-Higgins & Turner 1972, *Periodicity in whitecaps*,
        Nature 239): with the weight ω² ≈ g k the octaves between k_p and k_b carry similar shares
        of X (the saturation spectrum is nearly flat there), so X exceeds its threshold where
        shorter crests sit on longer ones. Checked here: the abstracts of Banner et al. (2000)
        and of Stringari et al. (2021, arXiv:2101.11904, a Gaussian-field breaking model for the
        dominant waves); the other references are cited from the literature, not re-read.

        Measured (``sample`` on 512 m (10 m/s) and 1024 m (20 m/s) squares, 3 seeds, footprint
        0, foam where f_pix > 1/2): correlation of X with η 0.82 (10 m/s); foam patches, as
        equivalent diameters median / area-weighted, 2.5 / 5.5 m at 10 m/s and 12 / 49 m at
        20 m/s (they scale with λ_p ∝ U10² and grow with W). With η as the crest variable the
        foam covers the tops of the highest dominant crests instead: 1.1 / 16 m and 1.3 / 119 m.

    Attributes:
        batch_size (int), n_bands (int), bands (WaveBands), dtype, device,
        band_wavenumber: (n_bands,) centre wavenumbers k_o [rad m⁻¹].

    Example:
        >>> import torch
        >>> field = WaveField(10.0, seed=0)
        >>> out = field.sample(torch.zeros(1, 5), torch.linspace(0.0, 1.0, 5)[None])
        >>> sorted(out), tuple(out["slope_x"].shape)
        (['elevation', 'slope_x', 'slope_y'], (1, 5))
    """

    def __init__(
        self,
        wind_speed: Any,
        seed: Any,
        *,
        wind_direction: Any = 0.0,
        inverse_wave_age: Any = 0.84,
        dtype: torch.dtype = torch.float32,
        device: torch.device | str | None = None,
        bands: WaveBands | None = None,
        min_band_share: float = 0.0,
    ):
        if not (isinstance(min_band_share, (int, float)) and 0.0 <= float(min_band_share) < 1.0):
            raise ValueError(f"min_band_share must be a number in [0, 1); got {min_band_share!r}")
        if dtype not in (torch.float32, torch.float64):
            raise ValueError(f"dtype must be torch.float32 or torch.float64; got {dtype}")
        if bands is None:
            bands = WaveBands()
        if not isinstance(bands, WaveBands):
            raise ValueError(f"bands must be a WaveBands; got {type(bands).__name__}")
        seeds = parse_seeds(seed)
        _check_wind("wind_speed", wind_speed)
        check_finite_range("wind_direction", wind_direction, -MAX_WIND_DIRECTION, MAX_WIND_DIRECTION, unit="rad")
        _check_wave_age(inverse_wave_age)
        tensor_device = check_same_device(
            wind_speed=wind_speed, wind_direction=wind_direction, inverse_wave_age=inverse_wave_age
        )
        self.device = torch.device(device) if device is not None else (tensor_device or torch.device("cpu"))
        self.dtype = dtype
        self.bands = bands
        self.n_bands = bands.n_bands

        batch = _batch_size(seeds, wind_speed=wind_speed, wind_direction=wind_direction, inverse_wave_age=inverse_wave_age)
        if seeds.single and batch != 1:
            raise ValueError(
                f"seed: an int seed makes a batch of 1, but the other arguments have B = {batch}; "
                "pass a sequence of B seeds"
            )
        self.batch_size = batch
        self.seeds = tuple(seeds.values)

        f64 = torch.float64
        self.wind_speed = per_batch("wind_speed", wind_speed, batch, f64, self.device)
        self.wind_direction = per_batch("wind_direction", wind_direction, batch, f64, self.device)
        self.inverse_wave_age = per_batch("inverse_wave_age", inverse_wave_age, batch, f64, self.device)
        self.band_wavenumber = torch.tensor(bands.band_wavenumber, dtype=dtype, device=self.device)
        self._build_lattice()

        amplitudes, covariances, signs, gains, variances = [], [], [], [], []
        for b in range(batch):
            amp, cov, sgn, gain, var = self._image_spectrum(b)
            amplitudes.append(amp)
            covariances.append(cov)
            signs.append(sgn)
            gains.append(gain)
            variances.append(var)
        # bands below min_band_share of the image's slope variance and of its crest variable's are
        # left out (zero amplitudes, covariance and variances: sample skips them)
        cov64, var64 = torch.stack(covariances), torch.stack(variances)  # (B, n_bands, 3), (B, n_bands, 2)
        slope = cov64[..., 0] + cov64[..., 1]
        crest = var64[..., 1]
        share = torch.maximum(slope / slope.sum(-1, keepdim=True).clamp_min(1e-300),
                              crest / crest.sum(-1, keepdim=True).clamp_min(1e-300))
        on = share.detach() >= float(min_band_share)
        self._band_on = on.cpu()  # (B, n_bands) bool
        if not bool(on.all()):
            keep = on.to(torch.float64)
            amplitudes = [a * keep[b, :, None, None].to(a.device) for b, a in enumerate(amplitudes)]
            covariances = [c * keep[b, :, None].to(c.device) for b, c in enumerate(covariances)]
            variances = [v * keep[b, :, None].to(v.device) for b, v in enumerate(variances)]
        self.min_band_share = float(min_band_share)
        cdt = torch.complex64 if dtype == torch.float32 else torch.complex128
        self._h0 = [a.to(cdt) for a in amplitudes]  # per image (n_bands, 2M+1, M+1) complex
        self._sign = signs  # per image (n_bands, 2M+1, M+1) float64 ±1 (0 outside the bands)
        self._covariance = torch.stack(covariances).to(dtype)  # (B, n_bands, 3)
        self._crest_gain = [g.to(dtype) for g in gains]  # per image (n_bands, 2M+1, M+1) real, G(k)
        # per band (B, n_bands, 2): variances of the elevation and of the crest variable
        self._variance = torch.stack(variances).to(dtype)

    # -- construction helpers ----------------------------------------------------------------
    def _build_lattice(self) -> None:
        """Lattice of each band's compact half spectrum: rows i_y = −M..M, columns i_x = 0..M."""
        bands, dev, f64 = self.bands, self.device, torch.float64
        m = bands.max_index
        n = bands.tile_size
        iy = torch.arange(-m, m + 1, dtype=f64).view(-1, 1).expand(2 * m + 1, m + 1)
        ix = torch.arange(0, m + 1, dtype=f64).view(1, -1).expand(2 * m + 1, m + 1)
        r2 = ix**2 + iy**2
        dk = torch.tensor(bands.fundamental, dtype=f64).view(-1, 1, 1)
        ratio = torch.tensor([b / a for a, b in zip(bands.k_edges[:-1], bands.k_edges[1:])], dtype=f64).view(-1, 1, 1)
        inner2 = bands.inner_radius**2
        mask = (r2 >= inner2) & (r2 < inner2 * ratio**2)  # (n_bands, 2M+1, M+1)
        # the half plane: i_x > 0, plus i_x = 0 with both signs of i_y
        kx = ix * dk
        ky = iy * dk
        k = torch.sqrt(kx**2 + ky**2)
        self._mask = mask.to(dev)
        self._kx = kx.to(dev)
        self._ky = ky.to(dev)
        self._k = torch.where(mask, k, torch.ones_like(k)).to(dev)  # safe (no k = 0) where masked out
        self._dk2 = (dk**2).expand_as(k).to(dev)
        self._omega = dispersion(self._k)  # float64 [rad/s]
        # each stored mode with i_x > 0 stands for itself and its conjugate mirror −k
        self._multiplicity = torch.where(ix > 0, 2.0, 1.0).to(dev).expand_as(k)
        # bilinear interpolation keeps (2 + cos θx)(2 + cos θy)/9 of a mode's variance on average
        theta = 2.0 * math.pi / n
        self._interp = ((2.0 + torch.cos(theta * ix)) * (2.0 + torch.cos(theta * iy)) / 9.0).to(dev)
        # the inverse DFT evaluated on the (N+1) × (N+1) texels 0..N of the circularly padded tile
        # (texel N repeats texel 0 exactly): along y over the 2M+1 non-zero rows,
        # E[n, r] = exp(2πi i_y(r) n / N); along x a real transform over the M+1 stored columns,
        # η[n, m] = Σ_c w_c (Re Y[n, c] cos(2π c m/N) − Im Y[n, c] sin(2π c m/N)), w_0 = 1, w_c = 2
        # (the columns c > 0 stand for ±c; column 0 is real by Hermitian symmetry).
        texel = torch.arange(n + 1, dtype=f64)
        texel[-1] = 0.0
        rows = torch.arange(-m, m + 1, dtype=f64)
        phase = 2.0 * math.pi * torch.outer(texel, rows) / n
        cdt = torch.complex64 if self.dtype == torch.float32 else torch.complex128
        self._ey = torch.polar(torch.ones_like(phase), phase).to(cdt).to(dev)  # (N+1, 2M+1)
        cols = torch.arange(0, m + 1, dtype=f64)
        phase = 2.0 * math.pi * torch.outer(cols, texel) / n  # (M+1, N+1)
        weight = torch.where(cols > 0, 2.0, 1.0).view(-1, 1)
        self._cx = (weight * torch.cos(phase)).to(self.dtype).to(dev)
        self._sx = (weight * torch.sin(phase)).to(self.dtype).to(dev)
        self._m = m

    def _white_noise(self, seed: int) -> torch.Tensor:
        """Hermitian complex white noise, E|W|² = 1, for all bands: (n_bands, 2M+1, M+1), CPU float64."""
        m = self._m
        gen = torch.Generator(device="cpu").manual_seed(seed)
        z = torch.randn((self.n_bands, 2 * m + 1, 2 * m + 1, 2), generator=gen, dtype=torch.float64)
        z = torch.complex(z[..., 0], z[..., 1]) / math.sqrt(2.0)  # E|z|² = 1, rows i_y, cols i_x = −M..M
        w = (z + torch.conj(torch.flip(z, dims=(-2, -1)))) / math.sqrt(2.0)  # W(−k) = W(k)*
        return w[..., m:]  # columns i_x = 0..M

    def _image_spectrum(self, b: int) -> tuple[torch.Tensor, ...]:
        """Amplitudes H₀ (complex128), band covariance (n_bands, 3), travel signs, the crest
        variable's gain G(k) (float64) and the band variances of η and of the crest variable
        (n_bands, 2) of image b."""
        wind = self.wind_speed[b]
        direction = self.wind_direction[b]
        omega_c = self.inverse_wave_age[b]
        s, delta = _eckv(self._k, wind, omega_c)
        # cos 2φ with φ the angle from the downwind (equivalently upwind) axis, from components
        cu, su = torch.cos(direction), torch.sin(direction)
        along = self._kx * cu + self._ky * su  # k · (upwind unit vector)
        across = -self._kx * su + self._ky * cu
        cos2phi = (along**2 - across**2) / self._k**2
        spec = s / self._k * (1.0 + delta * cos2phi) / (2.0 * math.pi)  # F(k, φ) [m⁴]
        var = torch.where(self._mask, spec * self._dk2, torch.zeros_like(spec))  # E|H₀|² [m²]
        positive = var > 0
        amp = torch.where(positive, torch.sqrt(torch.where(positive, var, torch.ones_like(var))), torch.zeros_like(var))
        noise = self._white_noise(self.seeds[b]).to(self.device)
        h0 = noise * amp
        # travel sign: +1 where k points downwind (k · upwind < 0), ties broken by the crosswind part
        down = -along
        sign = torch.where(down != 0, torch.sign(down), torch.sign(across))
        sign = torch.where(self._mask, sign, torch.zeros_like(sign))
        weight = var * self._multiplicity * self._interp
        cov = torch.stack(
            [
                (weight * self._kx**2).sum(dim=(-2, -1)),
                (weight * self._ky**2).sum(dim=(-2, -1)),
                (weight * self._kx * self._ky).sum(dim=(-2, -1)),
            ],
            dim=-1,
        )
        # the crest variable (WaveField docstring): G(k) = ω²/g × |2nd-order Butterworth low pass at k_b|
        k_b = CREST_CUTOFF * GRAVITY * omega_c**2 / wind**2  # CREST_CUTOFF × k_p (ECKV Eq. 3)
        gain = self._omega**2 / GRAVITY * torch.rsqrt(1.0 + (self._k / k_b) ** 4)
        gain = torch.where(self._mask, gain, torch.zeros_like(gain))
        variance = torch.stack([weight.sum(dim=(-2, -1)), (weight * gain**2).sum(dim=(-2, -1))], dim=-1)
        return h0, cov, sign, gain, variance

    # -- band statistics -------------------------------------------------------------------
    def band_weights(self, footprint: Any) -> torch.Tensor:
        """Resolved-part window w_o(f) of each band for a pixel footprint f [m] → (..., n_bands) in [0, 1].

        w_o = 1 − smoothstep(t), t = clamp((u − 2^{−1/2}) / (2^{1/2} − 2^{−1/2}), 0, 1),
        u = k_o f / π, smoothstep(t) = 3t² − 2t³, k_o the band centre. So w_o = 1 while the footprint
        is at most 0.71 × half a centre wavelength (k_o f ≤ 0.71 π), 0 from 1.41 × (k_o f ≥ 1.41 π),
        and in between it falls monotonically over exactly one octave of footprint (one octave in
        log f, hence in log k at a fixed footprint), C¹ (the smoothstep has zero slope at both
        ends). Compact support means a band is exactly off (and skipped) beyond its window.

        Args:
            footprint: f ≥ 0 [m], tensor of any shape (float accepted); 0 gives all 1, +inf all 0.
                Differentiable (the gradient is 0 where w is 0 or 1).
        """
        return _window(self._footprint_tensor(footprint), tuple(self.bands.band_wavenumber))  # every band at once

    def band_covariance(self) -> torch.Tensor:
        """Expected world-frame slope covariance of each band, (B, n_bands, 3) = (var_x, var_y, cov_xy).

        Σ over the band's discrete modes k (whole lattice) of E|H₀(k)|² k kᵀ = F(k, φ) Δk² k kᵀ, times
        the bilinear factor (2 + cos θx)(2 + cos θy)/9 of each mode: the covariance of the band's
        slopes as :meth:`sample` returns them, averaged over positions. Not the continuous integral
        ∫ F k kᵀ d²k over the annulus: for the default layout the lattice sum (without the bilinear
        factor) is 3–6 % above it for bands above the peak (lattice points vs area, at 4–8 Δk), and
        well below it for bands on the steep low-k flank of the peak. Dimensionless;
        differentiable in wind_speed.
        """
        return self._covariance

    def resolved_covariance(self, footprint: Any) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
        """Covariance of the slopes that ``sample(..., footprint=footprint)`` returns.

        Σ_o w_o(f)² C_o (bands are disjoint in k and independent), C_o from :meth:`band_covariance`.

        Args:
            footprint: f [m] ≥ 0 (inf allowed), shape (B, ...) (a float or 0-d tensor is used for
                every image).

        Returns:
            (var_x, var_y, cov_xy), each of shape (B, ...), dimensionless world-frame slope moments.
        """
        cov = self._windowed(self._covariance, footprint)  # (B, ..., 3)
        return cov[..., 0], cov[..., 1], cov[..., 2]

    def band_elevation_variance(self) -> torch.Tensor:
        """Expected elevation variance of each band, (B, n_bands) [m²]: Σ over the band's modes of
        E|H₀(k)|² times the bilinear factor (as :meth:`band_covariance`, without k kᵀ)."""
        return self._variance[..., 0]

    def band_crest_variance(self) -> torch.Tensor:
        """Expected variance of the crest variable X in each band, (B, n_bands) [dimensionless]:
        Σ over the band's modes of E|H₀(k)|² G(k)² times the bilinear factor."""
        return self._variance[..., 1]

    def elevation_variance(self, footprint: Any = None) -> torch.Tensor:
        """Variance of the elevation that ``sample(..., footprint=footprint)`` returns [m²].

        Σ_o w_o(f)² V_o, V_o from :meth:`band_elevation_variance` (averaged over positions, like
        :meth:`resolved_covariance`).

        Args:
            footprint: None (every band at full weight: the total variance σ_η² of the synthesized
                field, shape (B,)) or f [m] ≥ 0 (inf allowed) of shape (B, ...) (a float or 0-d
                tensor is used for every image): the resolved variance σ_r²(f), shape (B, ...).
        """
        return self._windowed_variance(self._variance[..., 0], footprint)

    def crest_variance(self, footprint: Any = None) -> torch.Tensor:
        """Variance of the crest variable X that ``sample(..., footprint=footprint, crest=True)``
        returns [dimensionless]: the total σ_X² (footprint None, shape (B,)) or the resolved
        Σ_o w_o(f)² V_o^X (shape (B, ...)); arguments as :meth:`elevation_variance`."""
        return self._windowed_variance(self._variance[..., 1], footprint)

    def _windowed(self, per_band: torch.Tensor, footprint: Any) -> torch.Tensor:
        """Σ_o w_o(footprint)² · per_band[:, o, :] for per-band moments (B, n_bands, K): (B, ..., K)."""
        f = self._footprint_tensor(footprint)
        if f.ndim == 0:
            f = f.expand(self.batch_size)
        if f.shape[0] != self.batch_size:
            raise ValueError(
                f"footprint: must have shape (B, ...) with B = {self.batch_size}; got {tuple(f.shape)}"
            )
        w2 = self.band_weights(f) ** 2  # (B, ..., n_bands)
        flat = w2.reshape(self.batch_size, -1, self.n_bands)
        return torch.bmm(flat, per_band).reshape(*f.shape, per_band.shape[-1])

    def _windowed_variance(self, band_var: torch.Tensor, footprint: Any) -> torch.Tensor:
        if footprint is None:
            return band_var.sum(-1)
        return self._windowed(band_var[:, :, None], footprint)[..., 0]

    # -- evaluation ------------------------------------------------------------------------
    def _footprint_tensor(self, footprint: Any) -> torch.Tensor:
        if footprint is None:
            raise ValueError("footprint is required (a tensor of pixel footprints [m], ≥ 0)")
        f = as_tensor(footprint, self.dtype, self.device)
        if f.numel() and not bool((f >= 0).all()):
            bad = f.detach()[~(f.detach() >= 0)].flatten()[0].item()
            raise ValueError(f"footprint must lie in [0, inf] m and not be NaN; got {bad!r}")
        return f

    def _tiles(self, time_s: torch.Tensor, elevation: bool, crest: bool = False) -> torch.Tensor:
        """Band tiles at the given times, (n_bands, B, C, N+1, N+1); C = (η,) s_x, s_y (, X)."""
        tiles = []
        kx = self._kx.to(self.dtype)
        ky = self._ky.to(self.dtype)
        for b in range(self.batch_size):
            wt = self._omega * time_s[b]  # float64 phases
            cos, sin = torch.cos(wt), torch.sin(wt)
            rot = torch.complex(cos, -self._sign[b] * sin).to(self._h0[b].dtype)  # exp(−i s ω t)
            h = self._h0[b] * rot
            minus_i_h = torch.complex(h.imag, -h.real)  # −i H
            channels = [minus_i_h * kx, minus_i_h * ky]
            if elevation:
                channels.insert(0, h)
            if crest:
                channels.append(h * self._crest_gain[b])  # X̂ = G(k) H
            spec = torch.stack(channels, dim=1)  # (n_bands, C, 2M+1, M+1)
            rows = torch.matmul(self._ey, spec)  # (n_bands, C, N+1, M+1): inverse DFT along y
            field = torch.matmul(rows.real, self._cx) - torch.matmul(rows.imag, self._sx)  # (…, N+1, N+1)
            tiles.append(field)
        return torch.stack(tiles, dim=1)

    def sample(
        self,
        x: Any,
        y: Any,
        time_s: Any = 0.0,
        footprint: Any = None,
        elevation: bool = True,
        crest: bool = False,
    ) -> dict[str, torch.Tensor]:
        """Surface slopes (and elevation, and the crest variable) of each image's field at its points.

        Args:
            x, y: world coordinates [m], tensors of shape (B, ...) (broadcast together; row i holds
                the points of image i); finite. Gradients flow to them (pose gradients).
            time_s: time [s], float or (B,), in [−MAX_TIME_S, MAX_TIME_S] = [−1e9, 1e9] (finite).
            footprint: None (every band at full weight) or the pixel footprint f [m] per point,
                a tensor broadcastable to x, ≥ 0, inf allowed: each band is multiplied by
                :meth:`band_weights` (f). Differentiable.
            elevation: also return the elevation.
            crest: also return the crest variable X (class docstring, *Crest variable*): one more
                channel of the same band loop (no second pass over the bands).

        Returns:
            dict with 'slope_x', 'slope_y' (world-frame slopes s = −∇η, dimensionless, computed
            spectrally as −i k η̂) and, if asked, 'elevation' η [m] and 'crest' X [dimensionless];
            each of shape x.shape, in the field's dtype on its device. Every channel carries the
            same band weights w_o(f). Their covariance at uniformly spread points is
            :meth:`resolved_covariance` (f) (sum of :meth:`band_covariance` without footprint);
            the variances of η and X are :meth:`elevation_variance` (f) and :meth:`crest_variance` (f).
        """
        xt = x if isinstance(x, torch.Tensor) else torch.as_tensor(x)
        yt = y if isinstance(y, torch.Tensor) else torch.as_tensor(y)
        for name, t in (("x", xt), ("y", yt)):
            if t.device != self.device:
                raise ValueError(f"{name} is on {t.device}, the WaveField on {self.device}; move the points")
            if t.ndim == 0:
                raise ValueError(f"{name}: must have shape (B, ...) with B = {self.batch_size}; got a scalar")
        xt, yt = torch.broadcast_tensors(xt.to(self.dtype), yt.to(self.dtype))
        shape = xt.shape
        if shape[0] != self.batch_size:
            raise ValueError(f"x, y: must have shape (B, ...) with B = {self.batch_size}; got {tuple(shape)}")
        for name, t in (("x", xt), ("y", yt)):
            if t.numel() and not bool(torch.isfinite(t.detach()).all()):
                raise ValueError(f"{name} must be finite world coordinates [m] (no NaN or inf)")
        check_time("time_s", time_s)
        t_s = per_batch("time_s", time_s, self.batch_size, torch.float64, self.device)
        f = None
        if footprint is not None:
            f = self._footprint_tensor(footprint)
            try:
                f = torch.broadcast_to(f, shape)
            except RuntimeError as err:
                raise ValueError(f"footprint: shape {tuple(f.shape)} does not broadcast to x {tuple(shape)}") from err
        return self.sample_unchecked(xt, yt, t_s, f, elevation, crest)

    def sample_unchecked(self, xt: torch.Tensor, yt: torch.Tensor, t_s: torch.Tensor, f: torch.Tensor | None,
                         elevation: bool, crest: bool) -> dict[str, torch.Tensor]:
        """:meth:`sample` without its input checks, for callers whose arguments are checked already (the
        renderer's own pixels): ``xt``, ``yt`` (B, ...) of the field's dtype and device, finite; times
        ``t_s`` (B,) float64 within ±MAX_TIME_S; footprints ``f`` of x's shape (≥ 0) or None. Returns what
        :meth:`sample` returns; unchecked input gives unchecked output (NaN, wrong shapes)."""
        shape = xt.shape
        batch = self.batch_size
        npts = int(np.prod(shape[1:])) if len(shape) > 1 else 1
        names = (["elevation"] if elevation else []) + ["slope_x", "slope_y"] + (["crest"] if crest else [])
        if npts == 0:
            return {name: xt.new_zeros(shape) for name in names}
        xy = torch.stack((xt.reshape(batch, npts), yt.reshape(batch, npts)), dim=-1)  # (B, P, 2)
        if f is not None:
            f = f.reshape(batch, npts)
        tiles = self._tiles(t_s, elevation, crest)
        acc = self._sample_points(tiles, xy, f)
        return {name: acc[:, c].reshape(shape) for c, name in enumerate(names)}

    # TEMPORARY alias for clutter.TextureTable until the renderer moves; the lead removes it at merge.
    _sample = sample_unchecked

    def _sample_points(self, tiles: torch.Tensor, xy: torch.Tensor, f: torch.Tensor | None) -> torch.Tensor:
        """Σ_o w_o · bilinear(tile_o) at points xy (B, P, 2) → (B, C, P).

        Band by band, then chunk by chunk of about 2**18 point-evaluations (the temporaries stay in
        cache). Each band's tile is doubled to 2N + 1 texels per side (the period twice, circularly;
        several bands per copy, up to ``_DOUBLED_ELEMENTS``) so that its grid is ``frac(x / L_o)``
        ∈ (−1, 1) straight away: ``frac`` costs a quarter of the floor-division ``remainder``. Points beyond a band's window (w = 0) are not evaluated,
        and the window multiplies only the points where it is below 1: both found from the
        footprint's minimum and maximum over blocks of points, so the skipped work would have
        added exactly 0 or multiplied by exactly 1 (results do not depend on chunks or blocks). A
        band whose tile is zero for every image (``min_band_share``) is skipped."""
        batch, npts = xy.shape[0], xy.shape[1]
        n_ch = tiles.shape[2]
        acc = torch.zeros((batch, n_ch, npts), dtype=self.dtype, device=self.device)
        chunk = max(1024, _CHUNK_ELEMENTS // batch)
        f_all = None if f is None else f.detach()
        if f_all is not None:  # per block of points: the footprint's least and largest value over the batch
            nblk = -(-npts // _BLOCK)
            pad = nblk * _BLOCK - npts
            fb = f_all if pad == 0 else torch.cat([f_all, f_all[:, -1:].expand(batch, pad)], 1)
            fb = fb.reshape(batch, nblk, _BLOCK)
            f_min, f_max = fb.amin(dim=(0, 2)), fb.amax(dim=(0, 2))
            f_min, f_max = f_min.cpu().numpy(), f_max.cpu().numpy()
        margin = 1e-3  # the tensor window is exactly 0 (or 1) well inside these bounds
        n = tiles.shape[-1] - 1
        work = []  # (band, point runs, blocks where the window may be < 1) of the bands that add something
        for o, k_o in enumerate(self.bands.band_wavenumber):
            if not self._band_on[:, o].any():
                continue
            runs, part = [(0, npts)], None
            if f_all is not None:
                runs = _runs(f_min < _WIN_HI * (1.0 + margin) * math.pi / k_o, npts)
                if not runs:
                    continue
                part = f_max > _WIN_LO * (1.0 - margin) * math.pi / k_o
            work.append((o, runs, part))
        # the tiles doubled: the period twice, plus texel 2N = texel 0 (circular), a few bands per copy
        per_copy = max(1, _DOUBLED_ELEMENTS // (tiles[0].numel() // (n + 1) ** 2 * (2 * n + 1) ** 2))
        doubled: dict[int, torch.Tensor] = {}
        for i, (o, runs, part) in enumerate(work):
            if o not in doubled:
                group = [w[0] for w in work[i:i + per_copy]]
                core = tiles.index_select(0, torch.tensor(group, device=tiles.device))[..., :n, :n]
                copy = core.new_empty(core.shape[:-2] + (2 * n + 1, 2 * n + 1))
                for rows in (slice(0, n), slice(n, 2 * n)):
                    for cols in (slice(0, n), slice(n, 2 * n)):
                        copy[..., rows, cols] = core
                copy[..., 2 * n, :] = copy[..., 0, :]
                copy[..., :, 2 * n] = copy[..., :, 0]
                doubled = {g: copy[j] for j, g in enumerate(group)}
            tile = doubled[o]
            k_o, length = self.bands.band_wavenumber[o], self.bands.tile_length[o]
            for lo, hi in runs:
                for a in range(lo, hi, chunk):
                    e = min(hi, a + chunk)
                    grid = xy[:, a:e] * (1.0 / length)
                    grid = torch.frac(grid) if grid.requires_grad else torch.frac(grid, out=grid)
                    values = F_nn.grid_sample(tile, grid.unsqueeze(1), mode="bilinear", padding_mode="border",
                                              align_corners=True).squeeze(2)  # (B, C, P')
                    flagged = None if part is None else np.flatnonzero(part[a // _BLOCK : -(-e // _BLOCK)])
                    if flagged is not None and flagged.size:  # the window where it may be below 1 (exactly 1
                        # elsewhere), one span from the first to the last flagged block of the chunk
                        u = max(a, (a // _BLOCK + int(flagged[0])) * _BLOCK)
                        v = min(e, (a // _BLOCK + int(flagged[-1]) + 1) * _BLOCK)
                        if u < v:
                            w = _window(f[:, u:v], k_o).unsqueeze(1)
                            if values.requires_grad or w.requires_grad:
                                values = torch.cat([values[..., : u - a], values[..., u - a : v - a] * w,
                                                    values[..., v - a :]], -1)
                            else:
                                values[..., u - a : v - a] *= w
                    acc[..., a:e] += values  # in place on our own buffer; autograd records the slice
        return acc


def _runs(blocks: np.ndarray, npts: int, gap: int = 4) -> list[tuple[int, int]]:
    """Point ranges [a, b) covering the True blocks of ``blocks`` (blocks of ``_BLOCK`` points), runs
    less than ``gap`` blocks apart merged (fewer, larger calls), clipped to ``npts``."""
    on = np.flatnonzero(blocks)
    if on.size == 0:
        return []
    cut = np.flatnonzero(np.diff(on) > gap)
    starts = np.concatenate([on[:1], on[cut + 1]])
    ends = np.concatenate([on[cut], on[-1:]]) + 1
    return [(int(a) * _BLOCK, min(npts, int(b) * _BLOCK)) for a, b in zip(starts, ends)]


# ---------------------------------------------------------------------------------------------
# argument helpers
# ---------------------------------------------------------------------------------------------
def _batch_size(seeds: ParsedSeeds, **items: Any) -> int:
    """B from the per-image arguments: tensors/arrays of shape (B,) and the seed sequence."""
    sizes: dict[str, int] = {}
    if not seeds.single:
        sizes["seed"] = len(seeds.values)
    for name, v in items.items():
        if isinstance(v, (torch.Tensor, np.ndarray)) and v.ndim > 0:
            if v.ndim != 1:
                raise ValueError(f"{name}: must be a float or a tensor of shape (B,); got shape {tuple(v.shape)}")
            sizes[name] = int(v.shape[0])
    distinct = set(sizes.values())
    if len(distinct) > 1:
        listing = ", ".join(f"{k} has {v}" for k, v in sizes.items())
        raise ValueError(f"seed, wind_speed, wind_direction, inverse_wave_age: batch sizes differ ({listing})")
    return distinct.pop() if distinct else 1


# TEMPORARY alias for render.py until the renderer moves (seed parsing is _validation.parse_seeds); the lead
# removes it at merge.
_seeds = parse_seeds

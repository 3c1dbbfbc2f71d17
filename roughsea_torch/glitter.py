"""Sun glitter: how many facets glint in a pixel, and a per-pixel draw of the glint about its mean.

The expectation's glint (:mod:`roughsea_torch.sun`) is the mean over the slope law. A pixel at near
range holds only a few facets that mirror the sun, so its glint is that mean times a random factor
with mean 1 whose spread grows as the number of glinting facets falls. Derivation and the checks
against a brute-force trace of the same surface: ``docs/glitter.md``.

Number of glitter spots (Longuet-Higgins 1960)
----------------------------------------------
The surface η(x, y) is a stationary Gaussian field; its slope s = −∇η maps a neighbourhood of a
point into slope space with the Jacobian −H (H the Hessian of η). A glitter spot is a connected set
of surface points whose facet mirrors some point of the sun's disk into the camera: the preimage,
under s, of the sun's small ellipse E about the specular slope s_g (:mod:`roughsea_torch.sun`). For
a disk much smaller than the slopes' spread each spot surrounds one *specular point* (s(x) = s_g),
and the spots per unit horizontal area are, by the Kac–Rice formula,

    n = E[ |det H| δ(s − s_g) ] = p(s_g) · E|det H|,

since at one point a Gaussian field's first and second derivatives are uncorrelated (Longuet-Higgins
1960, J. Opt. Soc. Am. 50, 838–844, and Proc. Camb. Phil. Soc. 57, 1961, on specular points). The
expected number of spots in a pixel's footprint of horizontal area A is N = A p(s_g) E|det H|. The
sun's solid angle does not enter N: it sets each spot's area (Ω-proportional, below) and so the
glint's mean, ρ L_sun Σ (spot areas) ∝ E_sun.

E|det H| from the curvature spectrum
------------------------------------
In the upwind frame, with the ECKV spreading (1 + Δ(k) cos 2φ) (centrosymmetric, so the odd moments
vanish), a = η_uu, b = η_cc, c = η_uc are Gaussian with
E a² = ∫ S k⁴ (3/8 + Δ/4) dk, E b² = ∫ S k⁴ (3/8 − Δ/4) dk, E c² = E ab = ∫ S k⁴ / 8 dk
(:func:`curvature_moments`, S the omnidirectional spectrum). det H = ab − c² is a quadratic form
of (a, b, c); diagonalized, det H = λ₁ z₁² − μ₂ z₂² − μ₃ z₃² with z i.i.d. N(0, 1),
λ₁ = (C + √(AB))/2, μ₂ = (√(AB) − C)/2, μ₃ = C (A = E a², B = E b², C = E c²); E det H = 0 (for any
stationary surface). Writing z₂, z₃ in polar form, μ₂z₂² + μ₃z₃² = 2 m(ψ) e with e ~ Exp(1) and
m(ψ) = μ₂ cos² ψ + μ₃ sin² ψ, and E(λ₁z² − 2me)⁺ = λ₁ − 2m + 2m / √(1 + λ₁/m), so

    E|det H| = 2 ⟨λ₁ − 2 m(ψ) + 2 m(ψ) / √(1 + λ₁ / m(ψ))⟩_ψ

(:func:`mean_abs_hessian_determinant`; isotropic: A = B = 3C, E|det H| = ∫ S k⁴ dk / (2√3)).

The spread of a pixel's glint
-----------------------------
A spot about a specular point with Hessian H covers the horizontal area area(E) / |det H| (the
linearized preimage), so the pixel's glint is a compound Poisson sum Σ_i w_i over K ~ Poisson(N)
spots with weights w ∝ 1/|det H| drawn from the spots' Hessian law, whose density is
∝ |det H| φ(H) (Kac–Rice again). Its mean is exactly the expectation's glint whatever N, and

    Var / mean² = (1 + κ) / N,  1 + κ = E_spot[w²] / E_spot[w]² = E|det H| · E[|det H| w²] / E[|det H| w]².

With w = 1/|det H| exactly, E[1/|det H|] diverges logarithmically at det H = 0, where the linearized
spot grows without bound. A real spot stops growing where the slope's next term takes over: along
the eigenvector of the small eigenvalue λ₂, s changes by λ₂ r + T r²/2 (T the rms third derivative
of η along a direction), so the spot reaches at most r ≈ √(2a/T) for the ellipse's radius a in slope
space, and the weight saturates as if |λ₂| ≥ λ_c = √(aT/2). :func:`glitter_spread` evaluates κ with
w = 1/(|λ₁| max(|λ₂|, λ_c)) over a fixed quasi-random sample of Hessians (deterministic).

Clustering. The spots are not a Poisson process: specular points are born and die in pairs (where
det H changes sign), and the unresolved waves longer than the curvature scale gather them. On the
brute force the spot counts per pixel scatter about their local mean with a variance F times the
mean, where a Poisson count would give 1. The model takes a factor F = :data:`GLITTER_CLUSTERING`
on the variance, Var / mean² = F (1 + κ) / N, measured on the brute force's spot counts at two
geometries (``docs/glitter.md`` §1), not derived; its dependence on the footprint and the wind is
not modelled.

The draw (:func:`glitter_factor`)
---------------------------------
A log-normal factor g = exp(σ z − σ²/2) with σ² = ln(1 + F(1 + κ)/N) and z ~ N(0, 1): E g = 1 exactly
and Var g = F(1 + κ)/N, the clustered compound Poisson's first two moments (a gamma law has them too; the
log-normal's mean is exact in closed form for any σ, which the renderer's mean-preservation rests
on, and a Gaussian z makes it coherent in time, below). For N ≫ F (1 + κ) it tends to 1.

Coherence in time: each node of the lattice below carries z(t) = cos(πu/2) z_j + sin(πu/2) z_{j+1},
u = frac(t/τ + φ), j = ⌊t/τ + φ⌋, with i.i.d. N(0, 1) values z_j (a counter-based hash of the seed,
the node and j) and a phase φ per node: exactly N(0, 1) at every t (cos² + sin² = 1), continuous,
correlated 0.95, 0.83, 0.57, 0.31 at 0.2, 0.4, 0.7, 1.0 τ and independent beyond 2τ; a point's
excursions above z = 2 (the brightest 2 %) last 0.68 τ on average. Which τ: the turnover of the
specular points themselves is set by the curvature-weighted frequency ω_c of
:func:`curvature_moments`, 1/ω_c ≈ 21 ms for the default field's centimetre waves at 4–12 m/s, while
MWIR sequences show hotspots lasting 0.15–0.20 s (Schwering 1991, Proc. SPIE 1486). The default
τ = :data:`GLITTER_LIFETIME_S` = 0.25 s follows the measurement (hotspots of 0.17 s), not the
derivation (``docs/glitter.md`` §1 discusses the gap, with the brute force's own turnover).

Anchoring: the latent is a field on the sea, z(x, y, t) at the horizontal world point (x, y) a pixel
sees, so that a camera that moves or turns finds the same glitter on the same sea points. The lattice
follows the pixel's footprint s (its across-view size): with λ = log₂(s / 1 m), ℓ = ⌊λ⌋ and
f = λ − ℓ, z = cos(πf/2) z_ℓ + sin(πf/2) z_{ℓ+1}, where z_ℓ is the field on the square lattice of
cell 2^ℓ m, interpolated inside a cell from its four nodes with the weights cos or sin of π u/2 per
axis (u the position in the cell). The eight weights' squares sum to 1, so z is exactly N(0, 1) at
every point, footprint and time, and continuous in all three; points more than 2 cells (≤ 4 s) apart
are independent, and points one footprint apart share nodes (their latents correlate by 0.26–0.39,
as s falls between two powers of 2). The cells are fixed in the earth frame: the resolved waves, which move
through them, carry the glint's bright facets (N follows the resolved slope), and the surface drift
(~3 % of U10) moves a point by less than a footprint across the view within a lifetime beyond about
70 m (``docs/glitter.md`` §1).
"""

from __future__ import annotations

import math
from typing import Any, NamedTuple

import torch

from ._validation import as_tensor, check_finite_range, resolve_dtype_device
from .counter_hash import bits_uniform, splitmix64
from .quadrature import gauss_nodes
from .spectrum import (
    check_wave_age,
    check_wind_speed,
    dispersion,
    elfouhaily_omnidirectional,
    elfouhaily_spreading,
)

__all__ = ["GLITTER_K_MAX", "GLITTER_LIFETIME_S", "GLITTER_CLUSTERING", "CurvatureMoments", "curvature_moments",
           "mean_abs_hessian_determinant", "specular_slope_density", "glitter_count", "glitter_spread",
           "glitter_factor", "glitter_factor_unchecked", "glitter_latent", "glitter_latent_unchecked"]

GLITTER_K_MAX = 256.0  # [rad m⁻¹] the curvature's top wavenumber: the default wave field's shortest band edge
GLITTER_LIFETIME_S = 0.25  # [s] the latent's step τ: hotspots (z > 2) then last 0.17 s, Schwering's (1991) 0.15–0.20 s
GLITTER_CLUSTERING = 2.2  # F: the spots' count variance over Poisson's (docs/glitter.md §1: 3.0 and 1.6 on two patches)
_DECADES = 14.0  # e-folds of wavenumber below k_max in the moments' integral (k⁴ S is negligible below)
_N_K = 192  # Gauss–Legendre nodes in ln k
_N_PSI = 64  # uniform nodes of the periodic ψ average of E|det H|
_N_HESS = 4096  # quasi-random Hessians of glitter_spread
_STEP = -7046029254386353131  # odd 64-bit multipliers of the lattice hash (int64)


class CurvatureMoments(NamedTuple):
    """The Hessian's second moments in the upwind frame [m⁻²]: ``uu`` = E η_uu², ``cc`` = E η_cc²,
    ``uc`` = E η_uc² = E η_uu η_cc; ``third``: the rms third derivative of η along a direction [m⁻²],
    √(5 m₆ / 16) with m₆ = ∫ S k⁶ dk; ``omega``: the curvature-weighted angular frequency
    √(∫ S k⁴ ω² dk / ∫ S k⁴ dk) [rad s⁻¹]."""

    uu: torch.Tensor
    cc: torch.Tensor
    uc: torch.Tensor
    third: torch.Tensor
    omega: torch.Tensor


def curvature_moments(wind_speed: Any, inverse_wave_age: Any = 0.84, k_max: Any = GLITTER_K_MAX) -> CurvatureMoments:
    """Second moments of the surface's Hessian from the ECKV spectrum up to ``k_max`` (module docstring).

    Args:
        wind_speed: U10 [m s⁻¹] in (0, 80]; float or tensor (any shape).
        inverse_wave_age: Ω_c in [0.84, 5].
        k_max: top wavenumber [rad m⁻¹] in [1, 1e4]: the shortest waves that make facets (the default,
            256 rad m⁻¹, is the default wave field's top band edge, the surface the brute force traces).

    Returns:
        :class:`CurvatureMoments`, each of the broadcast shape; dtype and device follow the inputs
        (the default dtype for floats); differentiable in the wind. ∫ over ln k by Gauss–Legendre on
        [k_max e⁻¹⁴, k_max].
    """
    check_wind_speed("wind_speed", wind_speed)
    check_wave_age(inverse_wave_age)
    check_finite_range("k_max", k_max, 1.0, 1e4, unit="rad/m")
    dtype, device = resolve_dtype_device(wind_speed=wind_speed, inverse_wave_age=inverse_wave_age, k_max=k_max)
    u, om, km = (as_tensor(v, dtype, device) for v in (wind_speed, inverse_wave_age, k_max))
    x, w = gauss_nodes("gl", _N_K, dtype, device)
    half = 0.5 * _DECADES
    lk = torch.log(km)[..., None] + half * (x - 1.0)  # (…, n) ln k
    k = torch.exp(lk)
    s = elfouhaily_omnidirectional(k, u[..., None], om[..., None])
    delta = elfouhaily_spreading(k, u[..., None], om[..., None])
    wk = w * half * s * k  # S dk = S k d(ln k)
    k4 = wk * k ** 4
    m4 = k4.sum(-1)
    uu = (k4 * (0.375 + 0.25 * delta)).sum(-1)
    cc = (k4 * (0.375 - 0.25 * delta)).sum(-1)
    uc = m4 / 8.0
    third = torch.sqrt(5.0 / 16.0 * (k4 * k * k).sum(-1))
    omega = torch.sqrt((k4 * dispersion(k) ** 2).sum(-1) / m4)
    return CurvatureMoments(uu, cc, uc, third, omega)


def _det_eigen(uu: torch.Tensor, cc: torch.Tensor, uc: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
    """(λ₁, μ₂, μ₃) of det H = λ₁ z₁² − μ₂ z₂² − μ₃ z₃² (module docstring)."""
    g = torch.sqrt(uu * cc)
    return 0.5 * (uc + g), 0.5 * (g - uc).clamp_min(0.0), uc


def mean_abs_hessian_determinant(uu: Any, cc: Any, uc: Any) -> torch.Tensor:
    """E|det H| [m⁻⁴] of a Gaussian Hessian with E η_uu² = ``uu``, E η_cc² = ``cc`` and
    E η_uc² = E η_uu η_cc = ``uc`` (:class:`CurvatureMoments`; all > 0, uu·cc > uc²), by the ψ average
    of the module docstring (64 uniform nodes of a smooth periodic integrand: exact to rounding).
    Broadcast shape; dtype/device follow the inputs; differentiable."""
    for name, v in (("uu", uu), ("cc", cc), ("uc", uc)):
        check_finite_range(name, v, 0.0, lo_open=True, unit="m-4")
    dtype, device = resolve_dtype_device(uu=uu, cc=cc, uc=uc)
    a, b, c = (as_tensor(v, dtype, device) for v in (uu, cc, uc))
    if bool((a * b <= c * c).any()):
        raise ValueError("uu, cc, uc: the Hessian's covariance must be positive definite (uu·cc > uc²)")
    lam1, mu2, mu3 = _det_eigen(a, b, c)
    psi = torch.arange(_N_PSI, dtype=dtype, device=device) * (2.0 * math.pi / _N_PSI)
    m = mu2[..., None] * torch.cos(psi) ** 2 + mu3[..., None] * torch.sin(psi) ** 2
    l1 = lam1[..., None]
    return 2.0 * (l1 - 2.0 * m + 2.0 * m * torch.rsqrt(1.0 + l1 / m)).mean(-1)


def specular_slope_density(cos_view: torch.Tensor, sin_view: torch.Tensor, cos_az: torch.Tensor, sin_az: torch.Tensor,
                           vx: torch.Tensor, vy: torch.Tensor, cxy: torch.Tensor, mx: torch.Tensor, my: torch.Tensor,
                           sun_zenith: torch.Tensor, sun_azimuth: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
    """p(s_g), the Gaussian slope density (covariance vx, vy, cxy; mean mx, my; upwind frame) at the
    specular slope s_g = (v + ω_sun)_xy / (v + ω_sun)_z of a line of sight (cos/sin of its zenith and
    of its azimuth from upwind) and the sun; and |det J| of the sun disk's map into slope space,
    J = ∂s/∂(disk offset) (:mod:`roughsea_torch.sun`), so that the sun's ellipse has area
    π α² |det J|. Checked tensors of one dtype and device (the renderer's pixels); 0 for a sun below
    the horizon."""
    cs, ss = torch.cos(sun_zenith), torch.sin(sun_zenith)
    above = cs > 0
    csp = torch.where(above, cs, torch.ones_like(cs))
    q = cos_view + csp
    sgx = (sin_view * cos_az + ss * torch.cos(sun_azimuth)) / q
    sgy = (sin_view * sin_az + ss * torch.sin(sun_azimuth)) / q
    det = (vx * vy - cxy * cxy).clamp_min(1e-30)
    dx, dy = sgx - mx, sgy - my
    d2 = (vy * dx * dx - 2.0 * cxy * dx * dy + vx * dy * dy) / det
    p = torch.exp(-0.5 * d2) / (2.0 * math.pi * torch.sqrt(det))
    det_j = (csp + ss * (sgx * torch.cos(sun_azimuth) + sgy * torch.sin(sun_azimuth))) / (q * q)
    return torch.where(above, p, torch.zeros_like(p)), det_j.abs()


def glitter_count(slope_density: Any, footprint_area: Any, mean_abs_det: Any) -> torch.Tensor:
    """N = A p(s_g) E|det H|: the expected number of glitter spots in a footprint of horizontal area
    ``footprint_area`` [m²] (≥ 0), from the slope density at the specular slope ``slope_density``
    (≥ 0, :func:`specular_slope_density`) and ``mean_abs_det`` = E|det H| [m⁻⁴] (> 0,
    :func:`mean_abs_hessian_determinant`). Broadcast shape; differentiable."""
    check_finite_range("slope_density", slope_density, 0.0)
    check_finite_range("footprint_area", footprint_area, 0.0, unit="m2")
    check_finite_range("mean_abs_det", mean_abs_det, 0.0, lo_open=True, unit="m-4")
    dtype, device = resolve_dtype_device(slope_density=slope_density, footprint_area=footprint_area,
                                         mean_abs_det=mean_abs_det)
    return as_tensor(footprint_area, dtype, device) * as_tensor(slope_density, dtype, device) * as_tensor(
        mean_abs_det, dtype, device)


def glitter_spread(moments: CurvatureMoments, ellipse_radius: Any, clustering: float = GLITTER_CLUSTERING) -> torch.Tensor:
    """F (1 + κ): 1 + κ = E_spot[w²] / E_spot[w]² of the spots' weights (module docstring), from the
    Hessian's moments and the sun ellipse's radius a in slope space (√(α² |det J|), > 0), times the
    clustering factor F ≥ 1 (1: Poisson spots). Over a fixed scrambled-Sobol sample of 4096 Hessians
    (seed 0: deterministic); shape of the moments."""
    check_finite_range("ellipse_radius", ellipse_radius, 0.0, 1.0, lo_open=True)
    check_finite_range("clustering", clustering, 1.0, 100.0)
    uu, cc, uc, third = moments.uu, moments.cc, moments.uc, moments.third
    dtype, device = uu.dtype, uu.device
    sob = torch.quasirandom.SobolEngine(3, scramble=True, seed=0).draw(_N_HESS, dtype=torch.float64)
    z = (math.sqrt(2.0) * torch.erfinv(2.0 * (sob * (1 - 2e-9) + 1e-9) - 1.0)).to(dtype=dtype, device=device)
    # (a, b, c) with Var a = uu, Var b = cc, Cov(a, b) = uc, Var c = uc, c independent
    l11 = torch.sqrt(uu)[..., None]
    l21 = (uc / torch.sqrt(uu))[..., None]
    l22 = torch.sqrt((cc - uc * uc / uu).clamp_min(0.0))[..., None]
    a = l11 * z[:, 0]
    b = l21 * z[:, 0] + l22 * z[:, 1]
    c = torch.sqrt(uc)[..., None] * z[:, 2]
    mid, rad = 0.5 * (a + b), torch.sqrt(0.25 * (a - b) ** 2 + c * c)
    big, small = mid.abs() + rad, (mid.abs() - rad).abs()  # |λ| larger and smaller
    lam_c = torch.sqrt(as_tensor(ellipse_radius, dtype, device) * third / 2.0)[..., None]
    det = big * small
    w = 1.0 / (big * torch.maximum(small, lam_c))
    return clustering * det.mean(-1) * (det * w * w).mean(-1) / (det * w).mean(-1) ** 2


def _uniform(key: torch.Tensor) -> torch.Tensor:
    """A float64 in (0, 1) from the hash of ``key``."""
    return bits_uniform(splitmix64(key))


def _in_time(key: torch.Tensor, t: torch.Tensor) -> torch.Tensor:
    """z(t) of lattice nodes ``key`` (int64 hashes) at ``t`` in lifetimes: cos(πu/2) z_j + sin(πu/2) z_{j+1}
    with u = frac(t + φ), j = ⌊t + φ⌋, a phase φ (the key's own bits) and i.i.d. N(0, 1) values z_j per
    node (the inverse normal CDF of the hash of the key and j)."""
    s = t + bits_uniform(key)
    j = torch.floor(s)
    u = s - j
    kj = key + j.to(torch.int64) * _STEP  # (an odd multiplier: distinct steps, distinct keys)
    z0 = torch.special.ndtri(_uniform(kj))
    z1 = torch.special.ndtri(_uniform(kj + _STEP))
    return torch.cos(0.5 * math.pi * u) * z0 + torch.sin(0.5 * math.pi * u) * z1


def glitter_latent(seed: Any, x: Any, y: Any, footprint: Any, time_s: Any = 0.0,
                   lifetime_s: Any = GLITTER_LIFETIME_S) -> torch.Tensor:
    """The latent z(t) ~ N(0, 1) of sea points (``x``, ``y``) [m] (horizontal world coordinates, each
    in [−1e7, 1e7]) seen by pixels whose footprint measures ``footprint`` [m] (their across-view size,
    in [1e-6, 1e6]) in a realization with seed ``seed`` (int in [0, 2**63)) at time ``time_s`` [s]
    (|t| ≤ 1e9) for a lifetime ``lifetime_s`` [s] > 0 (module docstring, *Anchoring*). Arguments
    broadcast; float64 of the broadcast shape, on the inputs' device; the same arguments give the
    same values on every device. Not differentiable (a draw)."""
    if isinstance(seed, bool) or not isinstance(seed, int) or not 0 <= seed < 2 ** 63:
        raise ValueError(f"seed must be an int in [0, 2**63); got {seed!r}")
    check_finite_range("x", x, -1e7, 1e7, unit="m")
    check_finite_range("y", y, -1e7, 1e7, unit="m")
    check_finite_range("footprint", footprint, 1e-6, 1e6, unit="m")
    check_finite_range("time_s", time_s, -1e9, 1e9, unit="s")
    check_finite_range("lifetime_s", lifetime_s, 0.0, 1e6, lo_open=True, unit="s")
    _, device = resolve_dtype_device(x=x, y=y, footprint=footprint, time_s=time_s, lifetime_s=lifetime_s)
    f64 = lambda v: as_tensor(v, torch.float64, device).detach()  # noqa: E731
    return glitter_latent_unchecked(seed, f64(x), f64(y), f64(footprint), f64(time_s) / f64(lifetime_s))


def glitter_latent_unchecked(seed: int, x: torch.Tensor, y: torch.Tensor, footprint: torch.Tensor,
                             t: torch.Tensor) -> torch.Tensor:
    """:func:`glitter_latent` without its checks, ``t`` in lifetimes: float64 tensors on one device
    that broadcast (the renderer's own pixels)."""
    x, y, footprint, t = torch.broadcast_tensors(x, y, footprint, t)
    lev = torch.log2(footprint)
    l0 = torch.floor(lev)
    f = lev - l0
    level = torch.stack([l0, l0 + 1.0])  # (2, …): the two levels about the footprint
    w_level = torch.stack([torch.cos(0.5 * math.pi * f), torch.sin(0.5 * math.pi * f)])
    cell = torch.exp2(level)
    gx, gy = x / cell, y / cell
    ix, iy = torch.floor(gx), torch.floor(gy)
    ux, uy = gx - ix, gy - iy
    base = int(splitmix64(torch.tensor([seed]))[0]) + level.to(torch.int64) * -4658895280553007687
    ix, iy = ix.to(torch.int64), iy.to(torch.int64)
    z = torch.zeros_like(x)
    for a in (0, 1):
        wx = torch.cos(0.5 * math.pi * ux) if a == 0 else torch.sin(0.5 * math.pi * ux)
        for b in (0, 1):
            wy = torch.cos(0.5 * math.pi * uy) if b == 0 else torch.sin(0.5 * math.pi * uy)
            key = splitmix64(base + (ix + a) * -7723592293110705685 + (iy + b) * 0x5851F42D4C957F2D)
            z = z + (w_level * wx * wy * _in_time(key, t)).sum(0)
    return z


def glitter_factor(count: Any, latent: Any, spread: Any = 1.0) -> torch.Tensor:
    """The glitter factor g = exp(σ z − σ²/2), σ² = ln(1 + spread / N), of pixels with N = ``count``
    expected spots (≥ 0; N = 0 is taken as 1e-6: a pixel that almost never glints flashes rarely and
    brightly), latent ``latent`` z (standard normal: :func:`glitter_latent`, or any N(0, 1) draws) and
    ``spread`` = F (1 + κ) ≥ 1 (:func:`glitter_spread`): E g = 1 and Var g = spread / N exactly when z is
    N(0, 1). Broadcast shape; dtype/device follow ``count``; differentiable in N."""
    check_finite_range("count", count, 0.0)
    check_finite_range("latent", latent, -40.0, 40.0)
    check_finite_range("spread", spread, 1.0)
    dtype, device = resolve_dtype_device(count=count, spread=spread)
    return glitter_factor_unchecked(as_tensor(count, dtype, device), as_tensor(latent, dtype, device),
                                    as_tensor(spread, dtype, device))


def glitter_factor_unchecked(count: torch.Tensor, latent: torch.Tensor, spread: torch.Tensor) -> torch.Tensor:
    """:func:`glitter_factor` without its checks, for the renderer's own (checked) pixels: tensors of
    one dtype and device that broadcast."""
    var = torch.log1p(spread / count.clamp_min(1e-6))
    return torch.exp(torch.sqrt(var) * latent - 0.5 * var)

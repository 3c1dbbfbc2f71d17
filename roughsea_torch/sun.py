"""The reflected sun (glint) in the facet-weighted expectation (``docs/physics.md`` §10).

The sun is a uniform disk of radiance L_sun = E_sun / Ω_sun, angular radius α (0.267°, Ω_sun =
2π(1 − cos α) ≈ 6.8e-5 sr) and direction ω_sun. In Eq. 10 it replaces R_s(θ') on the facets whose
mirror direction falls in the disk, so its contribution is

    R_glint = (1/D) ∫_E N(s; μ, Σ) t(s) ρ(Ω(s)) L_sun ds,

E the set of slopes that reflect the line of sight into the disk, D the Eq. 5 (or Eq. 7)
denominator. The disk is small, so E is an ellipse about the specular slope s_g = (p_x, p_y)/p_z,
p = v + ω_sun (v the line of sight), the image of the disk under the linearized map ω → s
(∂s/∂ω = (e_xy − s e_z)/p_z along the disk's tangent basis e); t and ρ are taken at the mean slope
of the facets in E, s* = E[s | s ∈ E] (s_g for broad slopes, the mean slope on a calm sea; they vary
by O(α tan θ̂) across E). What remains is the Gaussian probability of the ellipse,
P = ∫_E N ds, computed exactly for any width: in whitened
slopes the ellipse is E' and P = (1/2π) ∫ [exp(−ρ₁²/2) − exp(−ρ₂²/2)] dψ over the rays from the
mean, ρ₁ < ρ₂ where a ray enters and leaves E' (ρ₁ → 0 when the mean lies inside E'). So

- slopes broader than the disk: P → N(s_g) · area(E), and R_glint → ρ E_sun N(s_g) / (4 D cos⁴β_g),
  Cox & Munk's (1954) sun-glitter formula (with D = cos θ̂ without shadowing);
- a calm sea (slopes narrower than the disk): P → 1 inside the sun's mirror image and 0 outside, and
  R_glint → ρ L_sun (a flat sea mirrors the sun), finite, with finite gradients.

View side: the shadowing of Eq. 5 (D), as for the sky. Sun side (not in the paper): Smith's (1967)
masking of the facets from the sun, G1 = e_s / D_s with D_s the projected area of the facets seen
from the sun (Eq. 5's denominator for the sun's direction) and e_s that of their mean plane
(cos θ_sun for zero-mean slopes, so G1 = 1/(1 + Λ_sun)); ``sun_masking=False`` leaves it out.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import torch

from ._validation import as_tensor, check_finite_range
from .facets import denominator, facet_geometry, prepare_inputs, visible_ratio
from .optics import fresnel_terms, split_refractive_index
from .quadrature import gauss_nodes

__all__ = ["Sun", "SUN_RADIUS", "glint_radiance", "sun_masking_factor", "glint_from_moments", "glint_sharp_factor"]

SUN_RADIUS = math.radians(0.2666)  # angular radius of the sun's disk at 1 AU [rad]
_SQRT_HALF = math.sqrt(0.5)
_SMALL_ELLIPSE = 0.1  # tr K⁻¹ below which the glint's ellipse takes the fourth-order closed form
_N_RAYS = 48  # rays from the mean over the ellipse (Gauss–Legendre, or uniform when the mean is inside)


@dataclass(frozen=True)
class Sun:
    """The sun as a small disk in the sky.

    Args:
        zenith: zenith angle of the sun's centre [rad] (> π/2: below the horizon, no glint).
        azimuth: its azimuth [rad], measured like ``view_azimuth`` (from the upwind axis).
        irradiance: E_sun, the direct irradiance at the surface on a plane normal to the beam
            [W m⁻² in the band], ≥ 0.
        radius: angular radius of the disk [rad] (0.267°).

    Floats or tensors broadcasting with the view angles; gradients flow to all of them.
    """

    zenith: Any
    azimuth: Any
    irradiance: Any
    radius: Any = SUN_RADIUS

    def __post_init__(self) -> None:
        check_finite_range("sun zenith", self.zenith, 0.0, math.pi, unit="rad")
        check_finite_range("sun azimuth", self.azimuth, unit="rad")
        check_finite_range("sun irradiance", self.irradiance, 0.0, unit="W m-2")
        check_finite_range("sun radius", self.radius, 0.0, 0.1, lo_open=True, unit="rad")

    @property
    def solid_angle(self) -> Any:
        """Ω_sun = 2π (1 − cos α) [sr]."""
        r = self.radius
        return 4.0 * math.pi * (torch.sin(r / 2) ** 2 if isinstance(r, torch.Tensor) else math.sin(r / 2) ** 2)


def _ellipse_probability(cx: torch.Tensor, cy: torch.Tensor, k11: torch.Tensor, k12: torch.Tensor,
                         k22: torch.Tensor, det_k: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
    """P(z ∈ E') and its first moment ∫_E' z φ₂: the closed form of a small ellipse where E' is much
    smaller than the unit Gaussian (most glint pixels, slopes broader than the sun), the ray
    integration (:func:`_ellipse_probability_rays`) elsewhere (calm seas)."""
    tr_s = (k11 + k22) / det_k  # trace of S = K⁻¹: the ellipse's squared semi-axes summed
    small = tr_s < _SMALL_ELLIPSE
    if bool(small.all()):
        return _small_ellipse(cx, cy, k11, k12, k22, det_k)
    if not bool(small.any()):
        return _ellipse_probability_rays(cx, cy, k11, k12, k22, det_k)
    out = [torch.empty_like(cx) for _ in range(3)]
    for sel, fn in ((small, _small_ellipse), (~small, _ellipse_probability_rays)):
        vals = fn(cx[sel], cy[sel], k11[sel], k12[sel], k22[sel], det_k[sel])
        out = [o.index_put((sel,), v) for o, v in zip(out, vals)]
    return out[0], out[1], out[2]


def _small_ellipse(cx: torch.Tensor, cy: torch.Tensor, k11: torch.Tensor, k12: torch.Tensor, k22: torch.Tensor,
                   det_k: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
    """A small ellipse E' = {c + w : wᵀ K w ≤ 1}, S = K⁻¹, area π √det S. The mean of a function over
    the ellipse is Σₙ (Δ_S/4)ⁿ f(c) / (n! (n+1)!) (Δ_S = ∇ᵀ S ∇; the uniform disk's moment series),
    here to n = 2. With g = cᵀSc − tr S and T = g² + 2 tr S² − 4 cᵀS²c:
    P = area φ₂(c) F, F = 1 + g/8 + T/192, and
    ∫ z φ₂ = area φ₂(c) [c F − S c (1/4 + g/48) + S² c/24].
    Used where tr S < ``_SMALL_ELLIPSE`` (0.1); its accuracy there, measured against a fine ray
    integration: ``docs/notes/sun_glint.md``."""
    s11, s12, s22 = k22 / det_k, -k12 / det_k, k11 / det_k
    area = math.pi * torch.rsqrt(det_k)
    phi = torch.exp(-0.5 * (cx * cx + cy * cy)) / (2.0 * math.pi)
    scx, scy = s11 * cx + s12 * cy, s12 * cx + s22 * cy
    g = cx * scx + cy * scy - (s11 + s22)
    s2x, s2y = s11 * scx + s12 * scy, s12 * scx + s22 * scy
    t2 = g * g + 2.0 * (s11 * s11 + 2.0 * s12 * s12 + s22 * s22) - 4.0 * (scx * scx + scy * scy)
    f = 1.0 + g / 8.0 + t2 / 192.0
    base = area * phi
    a = 0.25 + g / 48.0
    return ((base * f).clamp(0.0, 1.0), base * (cx * f - a * scx + s2x / 24.0),
            base * (cy * f - a * scy + s2y / 24.0))


def _ellipse_probability_rays(cx: torch.Tensor, cy: torch.Tensor, k11: torch.Tensor, k12: torch.Tensor,
                              k22: torch.Tensor, det_k: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
    """P(z ∈ E') for z ~ N(0, I₂), E' = {z : (z − c)ᵀ K (z − c) ≤ 1} (K symmetric positive definite,
    det_k its determinant, given from its factors so that it carries no cancellation).

    Along a ray z = ρ d from the origin, (ρ d − c)ᵀ K (ρ d − c) ≤ 1 between the roots ρ₁ ≤ ρ₂ of
    a ρ² − 2 b ρ + c₀ = 0 (a = dᵀKd, b = dᵀKc, c₀ = cᵀKc − 1), and the ray carries
    (1/2π)[exp(−max(ρ₁, 0)²/2) − exp(−ρ₂²/2)] of the probability. The discriminant is taken as
    b² − a c₀ = a − det K (d × c)² (Lagrange's identity), free of the cancellation of the textbook
    form when E' is small and far. With the origin inside E' (c₀ < 0) every ray counts: a uniform
    rule over the angle (periodic, smooth). Outside, only the rays between the two tangents
    (a = det K (d × c)²) do: Gauss–Legendre over that angle, substituted ψ = m + h sin(πx/2) so that
    the square-root ends of the integrand become smooth.
    """
    dtype, device = cx.dtype, cx.device
    kc1, kc2 = k11 * cx + k12 * cy, k12 * cx + k22 * cy
    c0 = cx * kc1 + cy * kc2 - 1.0
    inside = c0 < 0
    # The rays that meet E' from an outside origin: a − det K (d × c)² ≥ 0, i.e. dᵀ Q d ≥ 0 with
    # Q = K − det K c⊥c⊥ᵀ (c⊥ = (c_y, −c_x)), indefinite outside. With Q's eigenpairs λ₁ > 0 > λ₂,
    # u₁, u₂ (u₁ towards c), they are d = cos ψ u₁ + sin ψ u₂, |ψ| ≤ γ = atan √(λ₁ / −λ₂) < π/2; a long
    # thin E' can reach beyond ±π/2 of the direction to its centre, which this frame allows.
    dk = det_k
    q11, q12, q22 = k11 - dk * cy * cy, k12 + dk * cx * cy, k22 - dk * cx * cx
    qm, qd = 0.5 * (q11 + q22), torch.sqrt((0.5 * (q11 - q22)) ** 2 + q12 * q12)
    lam1, lam2 = qm + qd, qm - qd
    phi1 = 0.5 * torch.atan2(2.0 * q12, q11 - q22)
    phi1 = torch.where(torch.cos(phi1) * cx + torch.sin(phi1) * cy < 0, phi1 + math.pi, phi1)
    neg = lam2 < 0
    gamma = torch.where(neg, torch.atan(torch.sqrt(lam1.clamp_min(0.0) / torch.where(neg, -lam2, torch.ones_like(lam2)))),
                        torch.full_like(lam1, 0.5 * math.pi))
    th_c = torch.where(inside, torch.zeros_like(phi1), phi1)
    psi1, psi2 = -gamma, gamma
    x, w = gauss_nodes("gl", _N_RAYS, dtype, device)
    mid, half = 0.5 * (psi1 + psi2), 0.5 * (psi2 - psi1)
    u = torch.sin(0.5 * math.pi * x)
    du = 0.5 * math.pi * torch.cos(0.5 * math.pi * x)
    psi_out = mid[..., None] + half[..., None] * u
    w_out = half[..., None] * du * w / (2.0 * math.pi)
    psi_in = torch.arange(_N_RAYS, dtype=dtype, device=device) * (2.0 * math.pi / _N_RAYS)
    w_in = torch.full_like(psi_in, 1.0 / _N_RAYS)
    psi = torch.where(inside[..., None], psi_in, psi_out)
    wts = torch.where(inside[..., None], w_in, w_out)
    th = th_c[..., None] + psi
    dx, dy = torch.cos(th), torch.sin(th)
    a = k11[..., None] * dx * dx + 2 * k12[..., None] * dx * dy + k22[..., None] * dy * dy
    b = kc1[..., None] * dx + kc2[..., None] * dy
    cross = dx * cy[..., None] - dy * cx[..., None]
    root = torch.sqrt((a - det_k[..., None] * cross * cross).clamp_min(0.0))
    rho2 = (b + root) / a
    # ρ₁ = c₀ / (a ρ₂) without cancellation (the product of the roots is c₀/a)
    rho1 = torch.where(inside[..., None], torch.zeros_like(rho2),
                       c0[..., None] / (a * torch.where(rho2 > 0, rho2, torch.ones_like(rho2))))
    e1, e2 = torch.exp(-0.5 * rho1 * rho1), torch.exp(-0.5 * rho2 * rho2)
    prob = (wts * (e1 - e2)).sum(-1).clamp(0.0, 1.0)
    # first moment ∫_E' z φ₂(z) dz: along a ray ∫ ρ² e^{−ρ²/2} dρ = F(ρ), F = √(π/2) erf(ρ/√2) − ρ e^{−ρ²/2}
    rt = math.sqrt(math.pi / 2)
    m = (rt * (torch.erfc(rho1 * _SQRT_HALF) - torch.erfc(rho2 * _SQRT_HALF)) - rho2 * e2 + rho1 * e1) * wts  # erfc: no tail cancellation
    return prob, (m * dx).sum(-1), (m * dy).sum(-1)


def glint_radiance(view_zenith: Any, view_azimuth: Any, slopes: Any, refractive_index: Any, sun: Sun,
                   shadowing: bool = True, sun_masking: bool = True) -> torch.Tensor:
    """The reflected sun's contribution to the apparent radiance (Eq. 10 with the sun's disk as the
    sky) [W m⁻² sr⁻¹ in the irradiance's band] (module docstring).

    Args:
        view_zenith, view_azimuth: θ̂, φ̂ of the line of sight sea → sensor [rad].
        slopes: :class:`~roughsea_torch.SlopeStatistics` (shifted statistics allowed).
        refractive_index: m = n + i k of the sea.
        sun: :class:`Sun`.
        shadowing: Eq. 5 (view side) or Eq. 7.
        sun_masking: Smith's G1 for the sun's direction.

    Returns:
        R_glint, the broadcast shape, the inputs' dtype and device; 0 for a sun below the horizon.
    """
    dtype, device, vz, va, vx, vy, cxy, mx, my = prepare_inputs(view_zenith, view_azimuth, slopes, refractive_index,
                                                                sun_zenith=sun.zenith, sun_azimuth=sun.azimuth,
                                                                sun_irradiance=sun.irradiance)
    n, k = split_refractive_index(refractive_index, dtype, device)
    tz, tp = as_tensor(sun.zenith, dtype, device), as_tensor(sun.azimuth, dtype, device)
    e_sun, alpha = as_tensor(sun.irradiance, dtype, device), as_tensor(sun.radius, dtype, device)
    out = glint_from_moments(vz, va, vx, vy, cxy, mx, my, n, k, tz, tp, e_sun, alpha, shadowing)
    if sun_masking:
        out = out * sun_masking_factor(slopes, sun, dtype, device)
    return out


def _specular_ellipse(ct: torch.Tensor, st: torch.Tensor, cph: torch.Tensor, sph: torch.Tensor, vx: torch.Tensor,
                      vy: torch.Tensor, cxy: torch.Tensor, mx: torch.Tensor, my: torch.Tensor, tz: torch.Tensor,
                      tp: torch.Tensor, alpha: torch.Tensor) -> tuple[torch.Tensor, ...]:
    """The sun's image in whitened slope space for lines of sight of cos/sin θ̂ (``ct``, ``st``) and
    cos/sin φ̂ (``cph``, ``sph``): (c_x, c_y, K₁₁, K₁₂, K₂₂, det K, l₁₁, l₂₁, l₂₂, above), the ellipse
    E' = {z : (z − c)ᵀ K (z − c) ≤ 1} about the whitened specular slope c, the Cholesky factor L of
    Σ, and whether the sun is above the horizon (module docstring)."""
    cs, ss = torch.cos(tz), torch.sin(tz)
    cp, sp = torch.cos(tp), torch.sin(tp)
    above = cs > 0
    csp = torch.where(above, cs, torch.ones_like(cs))  # keep the sun's arithmetic finite below the horizon
    q = ct + csp
    sgx, sgy = (st * cph + ss * cp) / q, (st * sph + ss * sp) / q  # the specular slope s_g (facet normal ∝ (s, 1))
    # the disk's tangent basis at ω_sun, e1 = (cs cp, cs sp, −ss), e2 = (−sp, cp, 0), and the
    # Jacobian ∂s/∂u (2×2), u the disk's offset [rad]
    j11, j21 = (csp * cp + sgx * ss) / q, (csp * sp + sgy * ss) / q
    j12, j22 = -sp / q, cp / q
    # whitened slopes: z = L⁻¹ (s − μ), Σ = L Lᵀ (floors keep a flat sea finite)
    floor = 1e-24
    l11 = torch.sqrt(vx.clamp_min(floor))
    l21 = cxy / l11
    l22 = torch.sqrt((vy - l21 * l21).clamp_min(floor))
    cxw = (sgx - mx) / l11
    cyw = ((sgy - my) - l21 * cxw) / l22
    # E' = {c + M w : |w| ≤ 1}, M = α L⁻¹ J; K = M⁻ᵀ M⁻¹ = (1/α²) Lᵀ J⁻ᵀ J⁻¹ L
    det_j = j11 * j22 - j12 * j21
    i11, i12, i21, i22 = j22 / det_j, -j12 / det_j, -j21 / det_j, j11 / det_j  # J⁻¹
    # N = J⁻¹ L
    n11, n12 = i11 * l11 + i12 * l21, i12 * l22
    n21, n22 = i21 * l11 + i22 * l21, i22 * l22
    inv_a2 = 1.0 / (alpha * alpha)
    k11 = (n11 * n11 + n21 * n21) * inv_a2
    k12 = (n11 * n12 + n21 * n22) * inv_a2
    k22 = (n12 * n12 + n22 * n22) * inv_a2
    det_k = (l11 * l22 / (det_j * alpha * alpha)) ** 2  # det K = (det J⁻¹ det L / α²)², from the factors
    return cxw, cyw, k11, k12, k22, det_k, l11, l21, l22, above


def glint_sharp_factor(ct: torch.Tensor, st: torch.Tensor, cva: torch.Tensor, sva: torch.Tensor, vx: torch.Tensor,
                       vy: torch.Tensor, cxy: torch.Tensor, mx: torch.Tensor, my: torch.Tensor, n: torch.Tensor,
                       k: torch.Tensor, tz: torch.Tensor, tp: torch.Tensor, alpha: torch.Tensor
                       ) -> tuple[torch.Tensor, torch.Tensor]:
    """P ρ t of the glint (module docstring): the part of the glint that is sharp in the view direction
    (the rest, L_sun / D, is smooth).

    P is the Gaussian probability of the sun's ellipse in slope space; ρ and t = cos Ω / cos θ are the
    Fresnel reflectance and the facet weight at the mean slope s* of the facets that mirror the sun.

    Args:
        ct, st, cva, sva: cos θ̂, sin θ̂, cos φ̂, sin φ̂ of the line of sight.
        vx, vy, cxy: the slope covariance (upwind/crosswind frame); mx, my: the mean slope (tensors,
            zero for a zero-mean law).
        n, k: the refractive index m = n + i k.
        tz, tp, alpha: the sun's zenith, azimuth and angular radius [rad].
    All checked tensors of one dtype and device that broadcast together.

    Returns:
        (P ρ t, whether the sun is above the horizon), the broadcast shape.
    """
    cxw, cyw, k11, k12, k22, det_k, l11, l21, l22, above = _specular_ellipse(ct, st, cva, sva, vx, vy, cxy, mx, my,
                                                                             tz, tp, alpha)
    shape = torch.broadcast_shapes(cxw.shape, cyw.shape, k11.shape, k12.shape, k22.shape, det_k.shape)
    ell = tuple(x.expand(shape) for x in (cxw, cyw, k11, k12, k22, det_k))
    prob, mzx, mzy = _ellipse_probability(*ell)
    # t and ρ at s* = E[s | s ∈ E], the facets that actually mirror the sun: s_g + O(α²) for broad
    # slopes, the mean slope for a calm sea (a flat sea mirrors the sun with ρ(θ̂), not with the
    # ρ of the facet that would mirror the disk's centre: O(α tan θ̂) apart)
    ok = prob > 1e-300
    ps = torch.where(ok, prob, torch.ones_like(prob))
    zx = torch.where(ok, mzx / ps, ell[0])
    zy = torch.where(ok, mzy / ps, ell[1])
    s_x = mx + l11 * zx
    s_y = my + l21 * zx + l22 * zy
    t_g = ct + st * (s_x * cva + s_y * sva)
    cos_omega = (t_g * torch.rsqrt(1.0 + s_x * s_x + s_y * s_y)).clamp(0.0, 1.0)
    rs_, rp_ = fresnel_terms(cos_omega, n, k)
    return 0.5 * (rs_ + rp_) * t_g * prob, above


def glint_from_moments(vz: torch.Tensor, va: torch.Tensor, vx: torch.Tensor, vy: torch.Tensor, cxy: torch.Tensor,
                       mx: torch.Tensor | None, my: torch.Tensor | None, n: torch.Tensor, k: torch.Tensor,
                       tz: torch.Tensor, tp: torch.Tensor, e_sun: torch.Tensor, alpha: torch.Tensor, shadowing: bool,
                       smooth: bool = False) -> Any:
    """:func:`glint_radiance` without the sun's masking, from the slope moments as checked tensors (the
    renderer calls it on its own pixels, whose values need no second check): P ρ t L_sun / D
    (:func:`glint_sharp_factor`) [W m⁻² sr⁻¹ in the irradiance's band].

    Args:
        vz, va: θ̂, φ̂ of the line of sight [rad].
        vx, vy, cxy: the slope covariance; mx, my: the mean slope, or None for zero mean.
        n, k: the refractive index m = n + i k.
        tz, tp: the sun's zenith and azimuth [rad]; e_sun: its irradiance [W m⁻²]; alpha: its angular
            radius [rad].
        shadowing: Eq. 5 (True) or Eq. 7 for D.
        smooth: only the smooth factor L_sun / D (0 for a sun below the horizon), which the renderer
            tabulates.
    All tensors of one dtype and device that broadcast together; the result has the broadcast shape.
    """
    dtype, device = vz.dtype, vz.device
    zero = torch.zeros((), dtype=dtype, device=device)
    if mx is None:
        mx = my = zero
    D = denominator(facet_geometry(vz, va, vx, vy, cxy, mx, my), shadowing)
    l_sun = e_sun / (4.0 * math.pi * torch.sin(0.5 * alpha) ** 2)  # Ω_sun = 2π(1 − cos α), without cancellation
    ratio = visible_ratio if shadowing else torch.div  # (Eq. 7's D = e may be negative: as it is)
    if smooth:
        return torch.where(torch.cos(tz) > 0, ratio(l_sun, D), zero)
    sharp, above = glint_sharp_factor(torch.cos(vz), torch.sin(vz), torch.cos(va), torch.sin(va), vx, vy, cxy, mx, my,
                                      n, k, tz, tp, alpha)
    return torch.where(above, ratio(sharp * l_sun, D), zero)


def sun_masking_factor(slopes: Any, sun: Sun, dtype: torch.dtype = torch.float64, device: Any = None) -> torch.Tensor:
    """Smith's G1 for the sun's direction [dimensionless, in [0, 1]]: e_s / D_s, D_s the projected area
    of the facets towards the sun (Eq. 5's denominator for the sun's direction) and e_s that of their
    mean plane (cos θ_sun for zero-mean slopes: G1 = 1/(1 + Λ_sun)).

    A textured sea applies the G1 of the scene's total slope law to every pixel's glint (the resolved
    waves mask the sun too), so that its ensemble mean is the expectation's glint."""
    tz, tp = as_tensor(sun.zenith, dtype, device), as_tensor(sun.azimuth, dtype, device)
    vx, vy, cxy = slopes.tensors(dtype, device)
    mx, my = slopes.mean_tensors(dtype, device)
    gs = facet_geometry(tz.clamp_max(math.pi / 2), tp, vx, vy, cxy, mx, my)
    d_sun = denominator(gs, True)
    e_s = (gs.ct + gs.st * gs.mu).clamp_min(0.0)
    return (e_s / d_sun.clamp_min(torch.finfo(dtype).tiny)).clamp(0.0, 1.0)


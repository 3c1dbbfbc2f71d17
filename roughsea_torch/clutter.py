"""Two-scale sea clutter: what one pixel of a textured sea sees (``docs/texture.md`` §5–6).

A pixel's footprint splits the waves in two (Bruneton, Neyret & Holzschuch, *Real-time realistic
ocean lighting using seamless transitions from geometry to BRDF*, CGF 29(2), 2010; the ONERA
multiresolution infrared sea model, Caillault, Fauqueux et al. 2007–2009):

- the **resolved** waves (longer than the footprint) are geometry: a
  :class:`~roughsea_torch.waves.WaveField` filtered at the footprint gives the resolved slope at
  the point the pixel's ray meets;
- the rest stays **statistical**: the paper's expectation (Eq. 10) about the resolved slope, with the
  covariance left over, so that resolved and unresolved parts always add up to the scene's
  :class:`~roughsea_torch.slopes.SlopeStatistics` Σ (Cox–Munk by default).

What is resolved. Of the resolved slope s_r only its component along the line of sight,
a = s_r · ê (ê the horizontal unit vector from the sea point towards the sensor), is geometry; its
regression E[s_r | a] = a (ê + κ_r ê⊥) fixes the mean of the unresolved Gaussian, and the residual
s_r − E[s_r | a] (Gaussian, independent of a) joins the unresolved covariance:

    μ = a' (ê + κ_r ê⊥),      Σ_u = Σ − σ_a² w wᵀ,   w = ê + κ_r ê⊥,   σ_a² = êᵀ Σ_r ê.

So Σ_u + Cov(E[s_r | a]) = Σ exactly. The component across the line of sight tilts the reflected
ray sideways, which for a sky symmetric in azimuth changes its zenith only to second order; it is
kept statistical here (its radiance effect stays in the mean); the renderer's first hit adds its
texture to second order (``TableSize.texture_hit_cross``, :mod:`roughsea_torch.renderer.texture`).

Which slope a pixel sees (the Eq. 5 weighting of the resolved part). A ray meets a facet in
proportion to the facet's visible projected area towards the sensor. Sampling the resolved slope
where the ray meets the mean plane z = 0 gives a ~ N(0, σ_a²), which weights every tilt equally: the
classic bias, growing towards grazing. The slope the ray actually meets has the density

    p(a') = N(a'; 0, σ_a²) · D_u(a') / D,

D_u(a') the projected area (Eq. 5 denominator) of the unresolved facets about a', D = ∫ N D_u
that of the total statistics. Then, for any pixel radiance R(a') = R_a(μ(a'), Σ_u) (the shifted
expectation), ∫ p R da' = R_a(0, Σ): the ensemble mean is the expectation image exactly (Smith's
visible-slope distribution applied to the resolved scale). :func:`visible_slope` maps the
flat-point sample monotonically onto p (quantile to quantile): x = a/σ_a ~ N(0, 1) becomes
a' = F_p⁻¹(Φ(x)). The map is monotone, so the clutter's spatial pattern is the wave field's; only
its slope histogram leans towards the sensor, most near grazing. What it leaves out: the parallax
of the resolved waves (the ray meets the crest a little before the flat point) and hiding of one
resolved wave by another, which a ray-marched first hit would give; near grazing those move where a
texture feature appears, not the mean.
"""

from __future__ import annotations

import math
from typing import Any

import torch

from .slopes import SlopeStatistics

__all__ = ["visible_slope", "unresolved_statistics", "two_scale_statistics", "pixel_resolved_slope", "resolved_quantile",
           "along_view", "along_variance", "view_moments", "footprint",
           "reconcile_scale"]

_SQRT_HALF = math.sqrt(0.5)
_INV_SQRT_2PI = 1.0 / math.sqrt(2.0 * math.pi)


def _projected_area_1d(e: torch.Tensor, s: torch.Tensor) -> torch.Tensor:
    """E[t H(t)] for t ~ N(e, s²): e Φ(e/s) + s φ(e/s), finite as s → 0 (→ max(e, 0))."""
    tiny = torch.finfo(e.dtype).tiny
    ss = s.clamp_min(tiny)
    z = (e / ss).clamp(-40.0, 40.0)
    return e * 0.5 * torch.erfc(-z * _SQRT_HALF) + ss * _INV_SQRT_2PI * torch.exp(-0.5 * z * z)


def visible_slope(
    x: torch.Tensor,
    cos_t: torch.Tensor,
    sin_t: torch.Tensor,
    sigma_r: torch.Tensor,
    sigma_u: torch.Tensor,
    nodes: int = 1025,
    width: float = 8.0,
) -> torch.Tensor:
    """The resolved along-view slope a' a ray meets, from the flat-point quantile x.

    Args:
        x: standard-normal quantile of the resolved slope at the flat-sea point, a/σ_a; shape
            (..., n) (n quantiles per geometry).
        cos_t, sin_t: cos θ̂ and sin θ̂ of the line of sight, (...).
        sigma_r: σ_a, rms of the resolved along-view slope, (...), ≥ 0.
        sigma_u: rms of the unresolved along-view slope (Σ_u's), (...), ≥ 0.
        nodes: grid of the cumulative distribution (over ±``width`` σ_a).

    Returns:
        a' (..., n): F_p⁻¹(Φ(x)) with p(a') ∝ N(a'; 0, σ_a²) D_u(a'), D_u(a') = E[t H(t)],
        t = cos θ̂ + sin θ̂ (a' + σ_u z). Computed on a fixed grid in a'/σ_a (cumulative trapezoid,
        linear inverse), differentiable in every argument. σ_a = 0 gives 0. Error against a 16-times
        finer grid, over random x within ±4.5, σ_a 0.01–0.21, σ_u 0.005–0.205, cos θ̂ 0.001–1: median
        3e-5 σ_a; up to 3.4e-4 σ_a (cos θ̂ > 0.2) and 1.6e-3 σ_a (grazing) where σ_u ≪ σ_a, at the
        quantiles in the tail where the visible density nearly vanishes (facets turned away).
    """
    out_dtype, device = x.dtype, x.device
    shape = torch.broadcast_shapes(x.shape[:-1], cos_t.shape, sin_t.shape, sigma_r.shape, sigma_u.shape)
    rows = math.prod(shape)
    step = max(1, 2**22 // (nodes * x.shape[-1]))  # the grid is (rows, nodes): bound it in memory
    if rows > step:
        xs = x.expand(*shape, x.shape[-1]).reshape(rows, x.shape[-1])
        others = [t.expand(shape).reshape(rows) for t in (cos_t, sin_t, sigma_r, sigma_u)]
        parts = [visible_slope(xs[i:i + step], *(o[i:i + step] for o in others), nodes=nodes, width=width)
                 for i in range(0, rows, step)]
        return torch.cat(parts).reshape(*shape, x.shape[-1])
    # in float64 whatever the dtype: the quantiles at the ends of the node range (x = ±4.5,
    # 1 − Φ = 3.4e-6) sit where float32's cumulative sum has lost the digits that place them, and a
    # misplaced end node of the texture's x-interpolant spreads over every x
    dtype = torch.float64
    x = x.to(dtype)
    xi = torch.linspace(-width, width, nodes, dtype=dtype, device=device)
    ct, st, sr, su = (t.to(dtype)[..., None] for t in (cos_t, sin_t, sigma_r, sigma_u))
    f = torch.exp(-0.5 * xi * xi) * _projected_area_1d(ct + st * sr * xi, st * su)  # (..., nodes)
    h = 2.0 * width / (nodes - 1)
    cdf = torch.cat([torch.zeros_like(f[..., :1]), torch.cumsum(0.5 * h * (f[..., 1:] + f[..., :-1]), -1)], -1)
    cdf = cdf / cdf[..., -1:]
    q = 0.5 * torch.erfc(-x * _SQRT_HALF)
    cdf_d = cdf.detach().expand(*q.shape[:-1], nodes).contiguous()
    i = torch.searchsorted(cdf_d, q.detach().contiguous()).clamp(1, nodes - 1)
    c0, c1 = torch.gather(cdf.expand_as(cdf_d), -1, i - 1), torch.gather(cdf.expand_as(cdf_d), -1, i)
    frac = ((q - c0) / (c1 - c0).clamp_min(torch.finfo(dtype).tiny)).clamp(0.0, 1.0)
    xi_p = -width + h * ((i - 1).to(dtype) + frac)
    return (sr * xi_p).to(out_dtype)


def unresolved_statistics(
    vx: torch.Tensor, vy: torch.Tensor, cxy: torch.Tensor, phi: torch.Tensor,
    var_a: torch.Tensor, kappa: torch.Tensor, a_visible: torch.Tensor,
) -> SlopeStatistics:
    """The unresolved Gaussian under a resolved along-view slope a' (module docstring).

    Args:
        vx, vy, cxy: the scene's total slope covariance (upwind, crosswind frame).
        phi: φ̂, azimuth of the line of sight (sea → sensor) from the upwind axis [rad].
        var_a: σ_a², variance of the resolved slope along the line of sight.
        kappa: κ_r, regression of the resolved across-view slope on a.
        a_visible: a', the resolved along-view slope the ray meets.
    All broadcast together.

    Returns:
        N(μ, Σ − σ_a² w wᵀ) as shifted :class:`SlopeStatistics`, w = ê + κ_r ê⊥ in the upwind frame.
    """
    c, s = torch.cos(phi), torch.sin(phi)
    wx, wy = c - kappa * s, s + kappa * c
    stats = SlopeStatistics.from_variances(vx - var_a * wx * wx, vy - var_a * wy * wy, cxy - var_a * wx * wy)
    return stats.shifted(a_visible * wx, a_visible * wy)


def two_scale_statistics(
    vx: torch.Tensor, vy: torch.Tensor, cxy: torch.Tensor, phi: torch.Tensor, cos_t: torch.Tensor,
    x: torch.Tensor, var_a: torch.Tensor, kappa: torch.Tensor, visible: torch.Tensor | None = None,
    return_visible: bool = False,
) -> Any:
    """The unresolved statistics of pixels (or table nodes) whose resolved along-view slope sits at
    the flat-point quantile ``x`` (shape (..., n) against the others' (...)): the along-view
    unresolved rms σ_u = √(êᵀΣê − σ_a²), the visible slope a' (:func:`visible_slope`) and
    :func:`unresolved_statistics`. The one place the renderer builds them (table nodes, per-pixel
    evaluation, glint).

    ``visible``: the visible quantile x' = a'/σ_a where the caller has it already (the renderer reads
    it from its texture volume), instead of inverting :func:`visible_slope`'s distribution here.
    ``return_visible``: also return x' (shape of ``x``)."""
    c, s = torch.cos(phi), torch.sin(phi)
    sig_a = torch.sqrt(var_a.clamp_min(1e-30))
    if visible is None:
        sig_u = torch.sqrt((vx * c * c + 2.0 * cxy * c * s + vy * s * s - var_a).clamp_min(1e-30))
        sin_t = torch.sqrt((1.0 - cos_t * cos_t).clamp_min(0.0))
        ap = visible_slope(x, cos_t, sin_t, sig_a, sig_u)
    else:
        ap = visible * sig_a[(...,) + (None,) * (visible.ndim - sig_a.ndim)]
    e = (...,) + (None,) * (ap.ndim - phi.ndim)
    stats = unresolved_statistics(vx[e], vy[e], cxy[e], phi[e], var_a[e], kappa[e], ap)
    return (stats, ap / sig_a[e]) if return_visible else stats


def along_variance(cov: tuple[torch.Tensor, torch.Tensor, torch.Tensor], ex: torch.Tensor, ey: torch.Tensor
                   ) -> torch.Tensor:
    """σ_a²: the variance along the unit vector ê = (ex, ey) of slopes of covariance ``cov`` = (var_x, var_y,
    cov_xy) in the same frame (world or upwind)."""
    cxx, cyy, cxy = cov
    return cxx * ex * ex + 2.0 * cxy * ex * ey + cyy * ey * ey


def _along(cov: tuple[torch.Tensor, torch.Tensor, torch.Tensor], ex: torch.Tensor, ey: torch.Tensor
           ) -> tuple[torch.Tensor, torch.Tensor]:
    """(σ_a², c_a⊥): the variance along ê = (ex, ey) of a slope field of covariance ``cov`` = (var_x,
    var_y, cov_xy), and the covariance of its components along ê and ê⊥ (ê turned +90°)."""
    cxx, cyy, cxy = cov
    return along_variance(cov, ex, ey), (cyy - cxx) * ex * ey + cxy * (ex * ex - ey * ey)


def view_moments(cov: tuple[torch.Tensor, torch.Tensor, torch.Tensor], ex: torch.Tensor, ey: torch.Tensor
                 ) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
    """(σ_a², c_a⊥, σ_⊥²): the covariance of a slope field (``cov`` = (var_x, var_y, cov_xy)) in the frame
    of the unit vector ê = (ex, ey) and ê⊥ (ê turned +90°): the variances along each and their covariance
    (:func:`along_view`'s κ_r = c_a⊥/σ_a²; the across-view residual's variance is σ_⊥² − c_a⊥²/σ_a²)."""
    var_a, cov_ap = _along(cov, ex, ey)
    cxx, cyy, cxy = cov
    return var_a, cov_ap, cxx * ey * ey - 2.0 * cxy * ex * ey + cyy * ex * ex


def along_view(cov: tuple[torch.Tensor, torch.Tensor, torch.Tensor], ex: torch.Tensor, ey: torch.Tensor
               ) -> tuple[torch.Tensor, torch.Tensor]:
    """(σ_a², κ_r): the variance of a slope field of covariance ``cov`` = (var_x, var_y, cov_xy)
    along the unit vector ê = (ex, ey), and the regression of its component along ê⊥ (ê turned
    +90°) on that along ê (0 where σ_a² = 0)."""
    var_a, cov_ap = _along(cov, ex, ey)
    ok = var_a > 1e-30
    kappa = torch.where(ok, cov_ap / torch.where(ok, var_a, torch.ones_like(var_a)), torch.zeros_like(var_a))
    return torch.where(ok, var_a, torch.zeros_like(var_a)), kappa


def resolved_quantile(
    slope_x: torch.Tensor, slope_y: torch.Tensor, cov: tuple[torch.Tensor, torch.Tensor, torch.Tensor],
    dx: torch.Tensor, dy: torch.Tensor,
) -> torch.Tensor:
    """x = a/σ_a of pixels: the resolved slope (world frame) at their flat-sea point along the line
    of sight, a = s · ê with ê = −(dx, dy)/|(dx, dy)|, over its rms σ_a = √(êᵀ C ê), C = (var_x,
    var_y, cov_xy) the resolved covariance. The ratio does not depend on the length of (dx, dy),
    so it is taken unnormalized: x = −(s_x dx + s_y dy) / √(dᵀ C d). x = 0 (and its gradient 0) where
    σ_a² ≤ 1e-30 in float64, 1e-24 in float32 (rms slopes of 1e-15 and 1e-12: nothing resolved),
    beyond which rsqrt's derivative q^(−3/2) would overflow."""
    cxx, cyy, cxy = cov
    q = cxx * dx * dx + 2.0 * cxy * dx * dy + cyy * dy * dy
    ok = q > (1e-30 if q.dtype == torch.float64 else 1e-24) * (dx * dx + dy * dy)
    return torch.where(ok, -(slope_x * dx + slope_y * dy) * torch.rsqrt(torch.where(ok, q, torch.ones_like(q))),
                       torch.zeros_like(q))


def pixel_resolved_slope(
    slope_x: torch.Tensor, slope_y: torch.Tensor, cov: tuple[torch.Tensor, torch.Tensor, torch.Tensor],
    dx: torch.Tensor, dy: torch.Tensor,
) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
    """(x = a/σ_a, σ_a², κ_r) of pixels from the resolved slope (world frame) at their flat-sea
    point, its covariance (var_x, var_y, cov_xy) and the world components dx, dy of the rays
    (the line of sight to the sensor is −(dx, dy) horizontally): x from :func:`resolved_quantile`,
    σ_a² and κ_r from :func:`along_view`. x = 0 where σ_a = 0 (:func:`resolved_quantile`'s threshold)."""
    inv = torch.rsqrt((dx * dx + dy * dy).clamp_min(1e-30))
    var_a, kappa = along_view(cov, -dx * inv, -dy * inv)
    return resolved_quantile(slope_x, slope_y, cov, dx, dy), var_a, kappa


def footprint(range_m: torch.Tensor, cos_t: torch.Tensor, ifov: torch.Tensor) -> torch.Tensor:
    """Length [m] of a pixel's footprint on the sea along the view: R δ / cos θ̂ (``docs/texture.md``
    §4; across the view it is R δ). The window of the resolved waves takes this, the longer side,
    so no wave shorter than the footprint in any direction is taken as geometry."""
    return range_m * ifov / cos_t.clamp_min(1e-9)


def reconcile_scale(field_cov: tuple[torch.Tensor, torch.Tensor, torch.Tensor], vx: torch.Tensor, vy: torch.Tensor,
                    cxy: torch.Tensor, wind_direction: torch.Tensor, limit: float = 0.8) -> torch.Tensor:
    """λ ≤ 1 such that λ² C ≤ ``limit`` · Σ in every direction, C the world-frame covariance of the
    resolved slopes at a footprint (:meth:`WaveField.resolved_covariance`), Σ the scene's total slope
    covariance (upwind frame, its upwind axis at world azimuth ``wind_direction``); all broadcast.

    The two scales must add up to Σ, so the resolved part may never exceed it. Where a spectrum's
    resolved bands carry more slope variance than Σ in some direction (a wind law and a spectrum that
    disagree; with ECKV against anisotropic Cox–Munk this happens only for footprints of a few
    centimetres), the resolved slopes there are scaled by λ(footprint), a smooth function of the
    footprint, and the unresolved part keeps at least 1 − ``limit`` of Σ. The renderer warns when
    it happens.
    """
    c, s = torch.cos(wind_direction), torch.sin(wind_direction)
    cxx, cyy, cc = field_cov  # to the upwind frame: u = x c + y s, v = −x s + y c
    uu = cxx * c * c + 2 * cc * c * s + cyy * s * s
    vv = cxx * s * s - 2 * cc * c * s + cyy * c * c
    uv = (cyy - cxx) * c * s + cc * (c * c - s * s)
    det = (vx * vy - cxy * cxy).clamp_min(1e-30)
    # largest eigenvalue of Σ⁻¹ C (2×2): trace and determinant
    tr = (vy * uu - 2 * cxy * uv + vx * vv) / det
    dt = (uu * vv - uv * uv) / det
    # √ of the discriminant where it is > 0 only: at 0 (a repeated eigenvalue, e.g. nothing resolved,
    # C = 0, at sky pixels and in the far field) √'s derivative is infinite, and times the zero
    # gradient of a clamp it made the pose gradient NaN
    disc = tr * tr - 4 * dt
    pos = disc > 0
    root = torch.where(pos, torch.sqrt(torch.where(pos, disc, torch.ones_like(disc))), torch.zeros_like(disc))
    lam_max = 0.5 * (tr + root)
    return torch.sqrt(torch.clamp(limit / lam_max.clamp_min(1e-30), max=1.0))

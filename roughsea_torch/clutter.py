"""Two-scale sea clutter: what one pixel of a textured sea sees (``docs/waves.md`` §2–3).

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
kept statistical (its radiance effect stays in the mean, its texture is left out).

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
           "along_view", "footprint",
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


def along_view(cov: tuple[torch.Tensor, torch.Tensor, torch.Tensor], ex: torch.Tensor, ey: torch.Tensor
               ) -> tuple[torch.Tensor, torch.Tensor]:
    """(σ_a², κ_r): the variance of a slope field of covariance ``cov`` = (var_x, var_y, cov_xy)
    along the unit vector ê = (ex, ey), and the regression of its component along ê⊥ (ê turned
    +90°) on that along ê (0 where σ_a² = 0)."""
    cxx, cyy, cxy = cov
    var_a = cxx * ex * ex + 2.0 * cxy * ex * ey + cyy * ey * ey
    cov_ap = (cyy - cxx) * ex * ey + cxy * (ex * ex - ey * ey)
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
    """Length [m] of a pixel's footprint on the sea along the view: R δ / cos θ̂ (``docs/waves.md``
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


class TextureTable:
    """The renderer's texture volume for a chunk of images (used by :func:`~roughsea_torch.render.render`).

    Per image, the realization's departure from the expectation, Δ(ζ, o, x) = R(a'(x)) − R_a, at
    Chebyshev–Lobatto nodes in ζ (its own), azimuth o (the mean table's) and the flat-point
    quantile x of the resolved along-view slope; resampled spectrally to a fine volume (x, ζ, o)
    times the path transmittance τ(ζ) of each row, read per sea pixel trilinearly (two bilinear
    ``grid_sample`` of the two slices of x about the pixel, and a lerp). The nodes' footprint, resolved covariance and unresolved Gaussian follow the
    node's (θ̂, φ̂) and the camera's range at θ̂ (for one camera the range is a function of θ̂);
    nodes where nothing is resolved (far field) are not evaluated and hold Δ = 0.
    """

    def __init__(self, table: Any, nz: int, nphi: int, B: int, dtype: torch.dtype, device: torch.device,
                 scene: Any, cg: Any):
        from ._validation import per_batch
        from .render import _lobatto_interp

        self.scene, self.B, self.dtype, self.device = scene, B, dtype, device
        self.width = float(table.texture_width)
        xx, Lx, self.ex = _lobatto_interp(int(table.texture), int(table.fine_texture))
        self.xnodes = torch.as_tensor(xx * self.width, dtype=dtype, device=device)
        self.Lx = torch.as_tensor(Lx, dtype=dtype, device=device)
        # with a sun the volume also carries the glint's visible quantile, which needs more ζ nodes
        nz = int(table.texture_zenith) if scene.sun is None else max(int(table.texture_zenith), int(table.texture_zenith_sun))
        xz, Lz, self.ez = _lobatto_interp(nz, int(table.fine_texture_zenith))
        self.xz = torch.as_tensor(xz, dtype=torch.float64, device=device)
        self.Lz = torch.as_tensor(Lz, dtype=dtype, device=device)
        _, La, self.ea = _lobatto_interp(nphi, int(table.fine_texture_azimuth))
        self.La = torch.as_tensor(La, dtype=dtype, device=device)
        self.ifov = 1.0 / cg.cameras.fx.to(dtype)  # δ [rad per pixel] at the image centre
        self.centres = cg.centres.to(dtype)
        # the wave phases ω t in float64 whatever the dtype: a float32 time rounds to 1/16 s at 1e6 s
        self.time = per_batch("time_s", scene.time_s, B, torch.float64, device)
        self.quadrature = tuple(int(v) for v in table.texture_quadrature)
        self.quadrature_steep = tuple(int(v) for v in table.texture_quadrature_steep)
        self.steep_cos = math.cos(math.radians(float(table.texture_steep_zenith_deg)))
        self.window = float(table.texture_quadrature_width)
        self.min_band_share = float(table.texture_min_band_share)
        self.scaled = False  # whether some resolved slopes were scaled down (reconcile_scale)

    def field(self, sl: slice, p: dict) -> Any:
        """The wave field of images ``sl``."""
        return self.scene.wave_field(self.B, self.dtype, self.device, sl, self.min_band_share)

    def resolved(self, wf: Any, L: torch.Tensor, p: dict, sl: slice) -> tuple[tuple[torch.Tensor, ...], torch.Tensor]:
        """The reconciled resolved covariance at footprints L (b, ...) and its scale λ (b, ...)."""
        cov = wf.resolved_covariance(L)
        ex = (slice(None),) + (None,) * (L.ndim - 1)
        lam = reconcile_scale(cov, *(p[k][sl][ex] for k in ("vx", "vy", "cxy", "wind_direction")))
        if not self.scaled and bool((lam < 1).any()):
            self.scaled = True  # the renderer warns once the render is done, from the caller's thread
        return tuple(c * lam * lam for c in cov), lam

    def node_values(self, sl: slice, p: dict, wf: Any, ph_nodes: torch.Tensor, sky: Any, scene: Any, q: Any,
                    altitude: torch.Tensor, earth_radius_m: float, eps: torch.Tensor, lo: torch.Tensor,
                    span_z: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
        """The texture at its nodes for images ``sl``: (Δ, active), Δ (b, C, nz, nphi, nx), C = 1, or 2
        with a sun (channel 1: the visible quantile x' = a'/σ_a that the glint's unresolved Gaussian
        is centred on, read per pixel instead of inverting :func:`visible_slope`'s distribution at
        every pixel), and active (b,) bool: whether any node of the image resolves a wave (Δ = 0
        and x' = x where none does). Made of many small operations: the renderer runs it for
        groups of images, then :meth:`volume` per chunk of pixels."""
        from .expectation import _reflection_terms
        from .render import _sky_per_image, _slant_range
        from .sky import TabulatedSky, select_sky

        dtype, device = self.dtype, self.device
        # the texture's own ζ nodes over the sea rows' span (it varies faster in ζ than the mean:
        # the resolved scale moves with the footprint, one octave of the spectrum per 0.35 in ζ)
        b_, nz, nphi = ph_nodes.shape[0], self.xz.numel(), ph_nodes.shape[1]
        zeta = lo[:, None] + span_z[:, None] * (self.xz + 1) / 2
        th_nodes = torch.acos((eps[:, None] * torch.sinh(zeta)).clamp(0.0, 1.0)).to(dtype)
        h = altitude[sl].to(dtype)
        cos_n = torch.cos(th_nodes)
        L = footprint(_slant_range(cos_n, h[:, None], earth_radius_m), cos_n, self.ifov[sl, None])
        cov, _ = self.resolved(wf, L, p, sl)
        cov = tuple(c[:, :, None] for c in cov)  # (b, nz, 1)
        phw = ph_nodes + p["wind_direction"][sl, None].to(dtype)  # LOS azimuth in the world
        var_a, kap = along_view(cov, torch.cos(phw)[:, None, :], torch.sin(phw)[:, None, :])  # (b, nz, nphi)
        vx, vy, cxy = (p[k][sl, None, None] for k in ("vx", "vy", "cxy"))
        c, s = torch.cos(ph_nodes)[:, None, :], torch.sin(ph_nodes)[:, None, :]
        suu = vx * c * c + 2.0 * cxy * c * s + vy * s * s
        active = (var_a > 1e-10 * suu).expand(b_, nz, nphi)
        if not bool(active.any()):
            zero = torch.zeros(b_, 1, nz, nphi, self.xnodes.numel(), dtype=dtype, device=device)
            if scene.sun is not None:
                zero = torch.cat([zero, self.xnodes.expand(b_, 1, nz, nphi, -1)], 1)
            return zero, torch.zeros(b_, dtype=torch.bool, device=device)
        idx = active.nonzero(as_tuple=True)
        img = idx[0]
        full = lambda t: t.expand(b_, nz, nphi)[idx]  # noqa: E731
        va_, kp_ = full(var_a), full(kap)
        ct = full(cos_n[:, :, None])
        ph = full(ph_nodes[:, None, :])
        shifted, x_vis = two_scale_statistics(vx[img, 0, 0], vy[img, 0, 0], cxy[img, 0, 0], ph, ct,
                                              self.xnodes.expand(img.numel(), -1), va_, kp_, return_visible=True)  # (M, nx)
        # one more column, the expectation itself (nothing resolved), on the same quadrature: Δ is
        # the difference of two evaluations whose quadrature errors nearly cancel, so the texture
        # nodes can take a coarser rule than the mean table (TableSize.texture_quadrature)
        cols = shifted.mean_upwind.shape
        moments = [torch.cat([a.expand(cols), b[:, None]], 1) for a, b in ((shifted.var_upwind, vx[img, 0, 0]),
                                                                          (shifted.var_crosswind, vy[img, 0, 0]),
                                                                          (shifted.cov, cxy[img, 0, 0]))]
        moments += [torch.cat([m, torch.zeros_like(m[:, :1])], 1) for m in (shifted.mean_upwind, shifted.mean_crosswind)]
        day_sky = isinstance(sky, TabulatedSky) and sky.radiance.ndim == 4 and sky.radiance.shape[2] > 1

        def terms(sel: torch.Tensor | slice, outer: int, inner: int) -> tuple[torch.Tensor, torch.Tensor]:
            """(T_s, T_ρ) of the active nodes ``sel`` on an (outer, inner) rule whose Gaussian window
            is cut at ±texture_quadrature_width standard deviations."""
            im = img[sel]
            stats = SlopeStatistics.from_variances(*(m[sel] for m in moments[:3])).shifted(*(m[sel] for m in moments[3:]))
            if day_sky:  # a sky per azimuth node (by day: the scattered sky along each node's mirror azimuth)
                sky_m = sky.with_radiance(sky.radiance[:, 0].to(dtype=dtype, device=device)[im, idx[2][sel]][:, None, :])
            else:
                sky_m = _sky_per_image(select_sky(sky_of_chunk(sky, b_), im.cpu()), im.numel(), dtype, device, 1)
            t_s, t_rho, _ = _reflection_terms(torch.acos(ct[sel].clamp(-1.0, 1.0))[:, None], ph[sel][:, None], stats,
                                              (p["n"][sl][im, None], p["k"][sl][im, None]), sky_m, scene.shadowing,
                                              q.with_(outer=outer, inner=inner, width=min(float(q.width), self.window)),
                                              None, scene.sky_masking)
            if p["air_scale"] is not None:
                t_s = t_s * p["air_scale"][sl][im, None].to(t_s.dtype)
            return t_s, t_rho

        # steep views (θ̂ < texture_steep_zenith_deg) take a finer rule: there the texture is a few mK
        # and the shifted Gaussian, narrow and near the edge of the sky-reflecting disc, needs it
        steep = ct > self.steep_cos
        if not bool(steep.any()):
            t_s, t_rho = terms(slice(None), *self.quadrature)
        elif bool(steep.all()):
            t_s, t_rho = terms(slice(None), *self.quadrature_steep)
        else:
            groups = [(m.nonzero().flatten(), rule) for m, rule in ((~steep, self.quadrature), (steep, self.quadrature_steep))]
            parts = [(sel, terms(sel, *rule)) for sel, rule in groups]
            t_s, t_rho = (torch.zeros(ct.shape[0], cols[1] + 1, dtype=parts[0][1][0].dtype, device=device)
                          .index_put((parts[0][0],), parts[0][1][i]).index_put((parts[1][0],), parts[1][1][i])
                          for i in (0, 1))
        rb = p["rb"][sl][img, None].to(t_s.dtype)
        v = rb - rb * t_rho + t_s
        delta = torch.zeros(b_, nz, nphi, self.xnodes.numel(), dtype=dtype, device=device)
        delta = delta.index_put(idx, (v[:, :-1] - v[:, -1:]).to(dtype))
        if scene.sun is not None:  # channel 1: the visible quantile x' = a'/σ_a, for the glint (x' = x where
            # nothing is resolved: unused there)
            xv = self.xnodes.expand(b_, nz, nphi, -1).clone().index_put(idx, x_vis.to(dtype))
            delta = torch.stack([delta, xv], 1)
        else:
            delta = delta[:, None]
        return delta, active.flatten(1).any(1)

    def volume(self, delta: torch.Tensor, sl: slice, scene: Any, altitude: torch.Tensor, earth_radius_m: float,
               eps: torch.Tensor, lo: torch.Tensor, span_z: torch.Tensor) -> torch.Tensor:
        """The fine texture volume of images ``sl`` from their node values Δ (:meth:`node_values`), τ
        included, laid out (b, C, fine_texture_zenith, fine_texture · fine_texture_azimuth) (the
        slices of x side by side)."""
        from .render import _slant_range

        dtype, device = self.dtype, self.device
        h = altitude[sl].to(dtype)
        # laid out (b, C, ζ, x, azimuth) and flattened to (b, C, ζ, x · azimuth): the slices of x side
        # by side along the width, read by two bilinear lookups and a lerp (see pixels)
        vol = torch.einsum("rz,bczpx,ap,fx->bcrfa", self.Lz, delta, self.La, self.Lx).contiguous()
        if scene.path is not None:
            Mt = self.Lz.shape[0]
            y = torch.linspace(-1.0 - self.ez, 1.0 + self.ez, Mt, dtype=torch.float64, device=device)
            cos_rows = (eps[:, None] * torch.sinh(lo[:, None] + span_z[:, None] * (y + 1) / 2)).clamp(0.0, 1.0).to(dtype)
            tau, _ = scene.path(h[:, None].expand_as(cos_rows), _slant_range(cos_rows, h[:, None], earth_radius_m),
                                clamp=True)
            t_ = tau.to(dtype)[:, None, :, None, None]
            if vol.requires_grad or t_.requires_grad:
                vol = torch.cat([vol[:, :1] * t_, vol[:, 1:]], 1)
            else:  # in place on the einsum's own output
                vol[:, :1] *= t_
        return vol.flatten(-2)

    def pixels(self, sl: slice, p: dict, wf: Any, vol: torch.Tensor, cos_t: torch.Tensor,
               zeta: torch.Tensor, o: torch.Tensor, dx: torch.Tensor, dy: torch.Tensor, sea: torch.Tensor,
               lo: torch.Tensor, span_z: torch.Tensor, a: torch.Tensor, b: torch.Tensor, altitude: torch.Tensor,
               earth_radius_m: float, eps: torch.Tensor, crest: bool = False) -> tuple:
        """The texture of every pixel of images ``sl`` (0 off the sea), (b, H, W); and each pixel's
        flat-point quantile x and resolved covariance (world frame), for the glint.

        With ``crest=True`` a fourth element (X_r, σ_r², σ_X²) for the foam on crests
        (:func:`~roughsea_torch.foam.crest_foam_fraction`): the pixel's resolved crest variable
        X_r (b, H, W), sampled in the same pass over the bands as the slopes (one more channel), its
        variance σ_r² (b, H, W) at the pixel's footprint (tabulated on the texture's rows like the
        covariance) and the field's total σ_X² (b, 1, 1); X_r = σ_r² = 0 off the sea (f_pix = W there)."""
        import torch.nn.functional as F

        from .render import _slant_range

        dtype = self.dtype
        h = altitude[sl].to(dtype)[:, None, None]
        R = _slant_range(cos_t, h, earth_radius_m)
        L = footprint(R, cos_t, self.ifov[sl, None, None])
        cen = self.centres[sl]
        X = cen[:, 0, None, None] + R * dx
        Y = cen[:, 1, None, None] + R * dy
        # (the field's own entry without the input checks: X, Y, L come from the finite geometry)
        smp = wf._sample(X, Y, self.time[sl], L, elevation=False, crest=crest)
        gy = (2.0 * (zeta - lo.to(dtype)[:, None, None]) / span_z.to(dtype)[:, None, None] - 1.0) / (1.0 + self.ez)
        # σ_a of each pixel from the resolved covariance of its row: for one camera the footprint is a
        # function of θ̂ alone, so the covariance is tabulated on the texture's rows and read
        # linearly in ζ (one 3-channel lookup instead of the 16 band windows per pixel); the
        # reconciling scale λ cancels in x = λ a / (λ σ_a)
        rows = (lo[:, None] + span_z[:, None] * (torch.linspace(-1.0 - self.ez, 1.0 + self.ez, self.Lz.shape[0],
                dtype=torch.float64, device=lo.device) + 1) / 2)
        cos_r = (eps[:, None] * torch.sinh(rows)).clamp(1e-9, 1.0).to(dtype)
        L_r = footprint(_slant_range(cos_r, h[:, :, 0], earth_radius_m), cos_r, self.ifov[sl, None])
        row_stats = list(wf.resolved_covariance(L_r)) + ([wf.crest_variance(L_r)] if crest else [])
        cov_rows = torch.stack(row_stats, 1)[..., None]  # (b, 3 (+1 with crest), rows, 1)
        grid = torch.stack([torch.zeros_like(gy), gy], -1)
        cov = F.grid_sample(cov_rows, grid, mode="bilinear", padding_mode="border", align_corners=True)
        x = resolved_quantile(smp["slope_x"], smp["slope_y"], (cov[:, 0], cov[:, 1], cov[:, 2]), dx, dy)
        # trilinear in (x, ζ, azimuth) as two bilinear reads of the slices of x that hold the pixel
        # (side by side along the width: column i · n_az + azimuth index) and a lerp between them;
        # border values beyond each axis, as a 3-D grid_sample (whose CPU kernel costs ~3x more)
        n_x, n_az = self.Lx.shape[0], self.La.shape[0]
        a_, b2 = a.to(dtype)[:, None, None], b.to(dtype)[:, None, None]
        col = ((2.0 * (o - a_) / (b2 - a_) - 1.0) / (1.0 + self.ea)).clamp(-1.0, 1.0).add(1.0).mul((n_az - 1) / 2.0)
        z = (x / (self.width * (1.0 + self.ex))).clamp(-1.0, 1.0).add(1.0).mul((n_x - 1) / 2.0)
        i0 = torch.floor(z.detach()).clamp_(max=n_x - 2)
        fz = z - i0
        scale = 2.0 / (n_x * n_az - 1)
        g0 = (i0 * float(n_az)).add_(col).mul_(scale).sub_(1.0)
        del col, z
        grid = torch.stack([g0, gy], 1)
        read = F.grid_sample(vol, grid.permute(0, 2, 3, 1), mode="bilinear", padding_mode="border", align_corners=True)
        if torch.is_grad_enabled() and (grid.requires_grad or vol.requires_grad):
            # (grid_sample keeps its grid for the backward pass of either)
            grid = torch.stack([g0 + n_az * scale, gy], 1)
        else:
            grid[:, 0] += n_az * scale  # the next slice of x, one block of columns to the right
        upper = F.grid_sample(vol, grid.permute(0, 2, 3, 1), mode="bilinear", padding_mode="border", align_corners=True)
        del grid
        read = torch.lerp(read, upper, fz[:, None]) if read.requires_grad or fz.requires_grad else read.lerp_(upper, fz[:, None])
        del upper
        out = read[:, 0]
        # x (or, with a sun, the visible quantile x' read from channel 1) and the resolved covariance go
        # back too: the glint of the same realization needs them
        result = (torch.where(sea, out, torch.zeros_like(out)), x if vol.shape[1] == 1 else (x, read[:, 1]),
                  (cov[:, 0], cov[:, 1], cov[:, 2]))
        if crest:
            zero = torch.zeros_like(out)
            result = result + ((torch.where(sea, smp["crest"], zero), torch.where(sea, cov[:, 3], zero),
                                wf.crest_variance()[:, None, None]),)
        return result


def sky_of_chunk(sky: Any, b: int) -> Any:
    """A sky reshaped by the renderer to broadcast over (b, nz, nphi) back to one entry per image."""
    from .sky import ConstantSky, TabulatedSky

    if isinstance(sky, TabulatedSky) and sky.radiance.ndim > 1:
        return sky.with_radiance(sky.radiance.reshape(b, sky.radiance.shape[-1]))
    if isinstance(sky, ConstantSky):
        r = torch.as_tensor(sky.radiance)
        if r.ndim > 0:
            return ConstantSky(r.reshape(b))
    return sky

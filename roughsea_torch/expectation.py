"""The facet-weighted expectation: rough-sea emissivity and apparent radiance (paper Eqs. 5–10).

The paper writes the expectation over facet-normal angles (θ, φ). Here it is evaluated in slope
space (``docs/physics.md`` §3), where it is exact and cheaper:

    p(θ, φ) dθ dφ = N(s; 0, Σ) ds,      cos Ω / cos θ = t(s) = cos θ̂ + sin θ̂ · s∥,

s∥ (written u) being the slope along the view azimuth and s⊥ (written v) the slope across it. The
weight of Eq. 5 is N(s) · t(s) · H(t > 0) / D with the closed-form denominator

    D = cos θ̂ · Φ(μ) + sin θ̂ · σ∥ · φ(μ),   μ = cot θ̂ / σ∥       (shadowing, Eq. 5)
    D = cos θ̂                                                    (no shadowing, Eq. 7)

Two integrals are evaluated, each on a tensor-product rule that puts every discontinuity of its
integrand on the boundary of its domain (so that Gauss rules converge spectrally):

- emissivity ε̄ = (1/D) ∫ N t (1 − ρ) ds over the visible half-plane u > −cot θ̂: Gauss–Legendre
  in u/σ∥ over the Gaussian window cut at the shadow edge, Gauss–Hermite in v given u;
- apparent radiance, Eq. 10 rewritten with ∫ f̂ = 1 as

      R_a = R_B + (1/D) ∫_C N t ρ(Ω) [R_s(θ') − R_B] ds,

  where C is the disc (u − tan θ̂)² + v² < sec² θ̂ of facets whose reflected ray reaches the sky
  (outside it the ray meets the sea and sees R_B, docs/physics.md §4, so the integrand vanishes). The
  disc is parametrized by ψ, its polar angle about its centre, u = tan θ̂ − sec θ̂ cos ψ, and the
  chord |v| < sec θ̂ sin ψ: its square-root edges become smooth. ψ is shifted by ψ₀ (u = 0) and the
  Gaussian window is mapped without cancellation, which keeps float32 accurate for σ down to 1e-3.
  If R_s ≡ R_B the integrand is identically zero, so R_a = R_B holds to rounding (second law).

Cos θ' of the reflected ray (Eq. 9) is evaluated as cos θ̂ (h − v)(h + v) / (1 + |s|²) with
h = sec θ̂ sin ψ the half-chord: exact, and free of the cancellation of 2 cos Ω cos θ − cos θ̂.

Everything broadcasts over batch shapes, follows the inputs' dtype and device, and carries
gradients; edge cases (σ → 0, θ̂ → 90°, degenerate Σ) are guarded so that values and gradients stay
finite.
"""

from __future__ import annotations

import math
from typing import Any, Callable

import torch

from ._parallel import map_chunks
from ._validation import as_tensor, check_finite_range, check_same_device
from .atmosphere import as_sky
from .facets import FacetGeometry, denominator, facet_geometry, normal_cdf, normal_pdf, prepare_inputs, visible_ratio
from .foam import foam_radiance, foam_sky_radiance, with_foam
from .masking import MASKED_OPTIONS, check_shadowing, facet_masking, masked_denominator, view_nu
from .optics import fresnel_terms, split_refractive_index
from .quadrature import Quadrature, gauss_nodes
from .radiometry import LWIR
from .sky import ConstantSky, TabulatedSky, select_sky
from .slopes import SlopeStatistics
from .sun import Sun, glint_radiance

__all__ = [
    "Quadrature",
    "projected_area",
    "smith_lambda",
    "emissivity",
    "apparent_radiance",
    "reflection_terms",
]



def _asin2(x: torch.Tensor) -> torch.Tensor:
    """2 asin(x) with x clamped to [−1, 1] and a zero (not NaN) gradient where |x| ≥ 1.

    ``asin(x.clamp(-1, 1))`` would pass the gradient through at |x| = 1 exactly, where asin' = ∞,
    and 0 · ∞ = NaN would reach the inputs' gradients (``docs/notes/expectation.md``).
    """
    inside = x.abs() < 1.0
    safe = torch.where(inside, x, torch.zeros_like(x))
    return torch.where(inside, 2.0 * torch.asin(safe), math.pi * torch.sign(x))


# -- per-evaluation geometry -----------------------------------------------------------------


# -- the two integrals -----------------------------------------------------------------------


def _emissivity_numerator(
    g: FacetGeometry, n: torch.Tensor, k: torch.Tensor, shadowing: bool, q: Quadrature
) -> torch.Tensor:
    """∫ N t (1 − ρ(|cos Ω|)) ds over t > 0 (and t < 0 without shadowing, negative weight)."""
    dtype, device = g.ct.dtype, g.ct.device
    xg, wg = gauss_nodes("gl", q.outer, dtype, device)
    zh, wh = gauss_nodes("gh", q.hermite, dtype, device)
    K = float(q.width)
    a = g.st * g.su
    e = g.ct + g.st * g.mu  # the mean of t
    big = e > K * a
    xs = -e / torch.where(big, torch.ones_like(a), a)
    xs = torch.where(big, torch.full_like(xs, -K), xs.clamp(-K, K))  # shadow edge in (u − m∥)/σ∥
    panels = [(xs, torch.full_like(xs, K))]
    if not shadowing:
        panels.append((torch.full_like(xs, -K), xs))
    n_, k_ = n[:, None, None], k[:, None, None]
    total = torch.zeros_like(g.ct)
    for lo, hi in panels:
        half = 0.5 * (hi - lo)
        x = (0.5 * (hi + lo))[:, None] + half[:, None] * xg  # (m, no)
        W = half[:, None] * wg * normal_pdf(x)
        if shadowing in MASKED_OPTIONS:  # the slope-conditioned or multi-scale masking (roughsea_torch.masking)
            W = W * facet_masking(shadowing, x, view_nu(g)[:, None])
        du = g.su[:, None] * x
        u = g.mu[:, None] + du
        t = g.ct[:, None] + g.st[:, None] * u
        v = (g.mv[:, None] + g.kappa[:, None] * du)[..., None] + g.tau[:, None, None] * zh  # (m, no, nh)
        cos_o = t.abs()[..., None] * torch.rsqrt(1.0 + u[..., None] ** 2 + v * v)
        es, ep = fresnel_terms(cos_o.clamp_max(1.0), n_, k_, emission=True)
        e = (0.5 * (es + ep) * wh).sum(-1)
        total = total + (W * t * e).sum(-1)
    return total


def _sky_numerator(
    g: FacetGeometry,
    n: torch.Tensor,
    k: torch.Tensor,
    sky: Callable[[torch.Tensor], torch.Tensor],
    q: Quadrature,
    split: bool,
    masking: bool = False,
    shadowing: bool | str = True,
) -> tuple[torch.Tensor, torch.Tensor]:
    """(∫_C N t ρ(Ω) R_s(θ') ds, ∫_C N t ρ(Ω) ds) over the disc C of sky-reflecting facets; with
    ``masking`` each ρ times Smith's G1 of the reflected ray (the masked part of the ray sees the
    sea, R_B, which the form R_B (1 − T_ρ) + T_s then takes care of)."""
    dtype, device = g.ct.dtype, g.ct.device
    tiny = torch.finfo(dtype).tiny
    xo, wo = gauss_nodes("gl", q.outer, dtype, device)
    xi, wi = gauss_nodes("gl", q.inner, dtype, device)
    K = float(q.width)
    ct, st, su = g.ct, g.st, g.su
    mu, mv = g.mu, g.mv
    lo, hi, psi0 = _sky_panels(g, K, split, tiny)
    half = (0.5 * (hi - lo))[..., None]  # (m, P, 1)
    delta = ((0.5 * (hi + lo))[..., None] + half * xo).flatten(1)  # (m, P·no)
    wdelta = (half * wo).flatten(1)
    inv_ct = (1.0 / ct)[:, None]
    u = 2.0 * inv_ct * torch.sin(psi0[:, None] + 0.5 * delta) * torch.sin(0.5 * delta)
    h = (inv_ct * torch.sin(psi0[:, None] + delta)).clamp_min(0.0)  # half-chord = du/dψ
    x = (u - mu[:, None]) / su[:, None]
    W = wdelta * h * normal_pdf(x) / su[:, None]
    if shadowing in MASKED_OPTIONS:  # the slope-conditioned or multi-scale masking (roughsea_torch.masking)
        W = W * facet_masking(shadowing, x, view_nu(g)[:, None])
    t = ct[:, None] + st[:, None] * u
    c = mv[:, None] + g.kappa[:, None] * (u - mu[:, None])
    tau = g.tau[:, None]
    z_lo = ((-h - c) / tau).clamp(-K, K)
    z_hi = ((h - c) / tau).clamp(-K, K)
    zh = 0.5 * (z_hi - z_lo)
    z = (0.5 * (z_hi + z_lo))[..., None] + zh[..., None] * xi  # (m, P·no, ni)
    Wz = zh[..., None] * wi * normal_pdf(z)
    v = c[..., None] + tau[..., None] * z
    inv = 1.0 / (1.0 + u[..., None] ** 2 + v * v)
    cos_o = (t[..., None] * torch.sqrt(inv)).clamp(0.0, 1.0)
    hh = h[..., None]
    cos_r = (ct[:, None, None] * (hh - v) * (hh + v) * inv).clamp(0.0, 1.0)
    rs, rp = fresnel_terms(cos_o, n[:, None, None], k[:, None, None])
    m = cos_r.shape[0]
    radiance = sky(cos_r.reshape(m, -1)).reshape(cos_r.shape)
    w_rho = Wz * 0.5 * (rs + rp)
    if masking:
        w_rho = w_rho / (1.0 + _reflected_ray_lambda(g, u, v, t, inv, cos_r, tiny))
    wt = W * t
    return (wt * (w_rho * radiance).sum(-1)).sum(-1), (wt * w_rho.sum(-1)).sum(-1)


def _sky_panels(g: FacetGeometry, K: float, split: bool, tiny: float
                ) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
    """The outer panels of the sky integral in δ = ψ − ψ₀ (ψ the polar angle about the sky disc's
    centre, ψ₀ its value at u = 0): (lo, hi) of shape (m, P), P = 3 with ``split`` else 1, and ψ₀.
    The Gaussian window [m∥ − Kσ∥, m∥ + Kσ∥] is cut to the disc, and with ``split`` the panel is also
    split where the Gaussian ridge leaves the disc."""
    ct, st, su = g.ct, g.st, g.su
    mu, mv = g.mu, g.mv
    alpha = ct / (1.0 + st)  # −u at the near edge of the disc
    B = ct * torch.rsqrt(2.0 * (1.0 + st))  # sin(ψ₀/2)
    psi0 = 2.0 * torch.asin(B)
    sqrt_1mB2 = torch.sqrt(1.0 - B * B)

    def shift(u: torch.Tensor) -> torch.Tensor:
        """δ = ψ(u) − ψ₀ without cancellation: sin²(ψ/2) − sin²(ψ₀/2) = u cos θ̂ / 2."""
        d = 0.5 * u * ct
        A = torch.sqrt((B * B + d).clamp_min(tiny))
        C = torch.sqrt((1.0 - B * B - d).clamp_min(tiny))
        return _asin2(d / (A * sqrt_1mB2 + B * C))

    u_far = (1.0 + st) / ct
    u_lo = torch.maximum(-alpha, mu - K * su)
    u_hi = torch.minimum(u_far, mu + K * su)
    # At the disc's own edges the angle is exact (ψ = 0, π): shift() would take the square root of
    # a rounding-level number there, and jitter every node by ~√ε.
    d_lo = torch.where(-alpha >= mu - K * su, -psi0, shift(u_lo))
    d_hi = torch.where(u_far <= mu + K * su, math.pi - psi0, shift(u_hi))
    d_hi = torch.maximum(d_hi, d_lo)  # a shifted window may miss the disc: an empty panel
    # Where the ridge s⊥ = κ s∥ of the Gaussian leaves the disc, the chord edge sweeps through the
    # inner Gaussian and the outer integrand steps within ~τ/|κ|: split the outer panel there.
    # The exits of the ridge s⊥ = κ s∥ + d (d = m⊥ − κ m∥) solve (1 + κ²) u² − 2 (tan θ̂ − κ d) u
    # + d² − 1 = 0 (zero mean: both roots real, one on each side of 0; a shifted ridge that misses
    # the disc gives its tangent point, where splitting is harmless).
    # Only a thin ridge (τ < split·|κ|·σ∥, e.g. a/b ≫ 1 or |r| → 1) needs it; Cox–Munk anisotropy
    # (a/b ≤ 1.3, r = 0) does not, and keeps a single panel (a third of the work). The decision is
    # made per sea state by the caller, so results do not depend on batching or chunking.
    if split:
        kap2 = 1.0 + g.kappa * g.kappa
        dd = mv - g.kappa * mu
        bq = st / ct - g.kappa * dd
        root = torch.sqrt((bq * bq - kap2 * (dd * dd - 1.0)).clamp_min(0.0))
        qq = bq + torch.where(bq >= 0, root, -root)  # the larger-magnitude root times (1 + κ²)
        qq = torch.where(qq.abs() > tiny, qq, torch.full_like(qq, tiny))
        r1, r2 = qq / kap2, (dd * dd - 1.0) / qq  # the product of the roots is (d² − 1)/(1 + κ²)
        u_minus, u_plus = torch.minimum(r1, r2), torch.maximum(r1, r2)
        d_m = torch.minimum(torch.maximum(shift(u_minus), d_lo), d_hi)
        d_p = torch.minimum(torch.maximum(shift(u_plus), d_m), d_hi)
        panels = [(d_lo, d_m), (d_m, d_p), (d_p, d_hi)]
    else:
        panels = [(d_lo, d_hi)]
    lo = torch.stack([a for a, _ in panels], -1)  # (m, P)
    hi = torch.stack([b for _, b in panels], -1)
    return lo, hi, psi0


def _reflected_ray_lambda(g: FacetGeometry, u: torch.Tensor, v: torch.Tensor, t: torch.Tensor, inv: torch.Tensor,
                          cos_r: torch.Tensor, tiny: float) -> torch.Tensor:
    """Smith's Λ of the reflected ray at the sky integral's nodes (facet slopes u, v in the view frame,
    t = cos Ω / cos θ, inv = 1/(1 + |s|²), cos θ' = ``cos_r``): G1 = 1/(1 + Λ)."""
    st, su = g.st, g.su
    # the reflected ray r = 2 (n·v) n − v in the view frame (u along the view, v across), and the
    # rms slope of the law along r's azimuth: Λ = [φ(μ) − μ (1 − Φ(μ))]/μ, μ = cot θ'/σ(r)
    uu = u[..., None]
    rx = 2.0 * t[..., None] * uu * inv - st[:, None, None]
    ry = 2.0 * t[..., None] * v * inv
    rh2 = (rx * rx + ry * ry).clamp_min(tiny)
    su2 = (su * su)[:, None, None]
    kap, tau2 = g.kappa[:, None, None], (g.tau * g.tau)[:, None, None]
    s2 = (su2 * rx * rx + 2.0 * kap * su2 * rx * ry + (tau2 + kap * kap * su2) * ry * ry) / rh2
    mu_r = cos_r / torch.sqrt(rh2 * s2.clamp_min(tiny))
    mu_c = mu_r.clamp_min(1e-6)
    return (normal_pdf(mu_c) - mu_c * normal_cdf(-mu_c)) / mu_c


def _sky_terms(
    g: FacetGeometry,
    n: torch.Tensor,
    k: torch.Tensor,
    sky_fn: Callable,
    shape: torch.Size,
    D: torch.Tensor,
    q: Quadrature,
    masking: bool = False,
    shadowing: bool | str = True,
) -> tuple[torch.Tensor, torch.Tensor]:
    """Flat (T_s, T_ρ) = (1/D)(∫_C N t ρ R_s, ∫_C N t ρ), so that R_a = R_B (1 − T_ρ) + T_s (Eq. 10).

    The sky disc's outer panel is split per sea state where the Gaussian ridge is thin; the
    grouping makes results independent of batching and chunking.
    """
    device = g.ct.device
    need_split = (g.tau < q.split * g.kappa.abs() * g.su).detach()
    total = need_split.numel()
    out_s = out_r = None
    for split in (False, True):
        idx = torch.nonzero(need_split == split).flatten()
        if idx.numel() == 0:
            continue
        step = max(1, q.chunk // ((3 if split else 1) * q.outer * q.inner))

        def one(sel: torch.Tensor, split: bool = split) -> tuple[torch.Tensor, torch.Tensor]:
            i_s, i_r = _sky_numerator(g.take(sel), n[sel], k[sel], _sky_chunk(sky_fn, shape, sel, device), q, split,
                                      masking, shadowing)
            ratio = visible_ratio if shadowing else torch.div  # (Eq. 7's D = e may be negative: as it is)
            return ratio(i_s, D[sel]), ratio(i_r, D[sel])

        # chunks on worker threads of one intra-op thread each (roughsea_torch._parallel)
        parts = map_chunks(one, [idx[i : i + step] for i in range(0, idx.numel(), step)], device)
        vs, vr = torch.cat([s for s, _ in parts]), torch.cat([r for _, r in parts])
        if idx.numel() == total:
            out_s, out_r = vs, vr
        else:
            zeros = torch.zeros(total, dtype=vs.dtype, device=device)
            out_s = (zeros if out_s is None else out_s).index_put((idx,), vs)
            out_r = (zeros if out_r is None else out_r).index_put((idx,), vr)
    return out_s, out_r


# -- argument handling -----------------------------------------------------------------------


def _sky_batch_shape(sky: Any) -> tuple[int, ...]:
    if isinstance(sky, TabulatedSky):
        return tuple(sky.radiance.shape[:-1])
    if isinstance(sky, ConstantSky):
        return tuple(torch.as_tensor(sky.radiance).shape)
    return ()


def _sky_chunk(sky: Any, shape: torch.Size, sl: torch.Tensor | slice, device: torch.device) -> Callable:
    """The sky restricted to the flat batch elements ``sl`` (batched tables/constants only)."""
    if isinstance(sky, TabulatedSky) and sky.radiance.ndim > 1:
        nz = sky.radiance.shape[-1]
        sky = sky.with_radiance(sky.radiance.to(device).expand(*shape, nz).reshape(-1, nz))
    elif isinstance(sky, ConstantSky) and torch.as_tensor(sky.radiance).ndim > 0:
        sky = ConstantSky(torch.as_tensor(sky.radiance, device=device).expand(shape).reshape(-1))
    return select_sky(sky, sl)


def _run_chunked(
    batch_shape: torch.Size,
    per_eval_points: int,
    q: Quadrature,
    fn: Callable[[slice], torch.Tensor],
    dtype: torch.dtype,
    device: torch.device,
) -> torch.Tensor:
    total = int(math.prod(batch_shape))
    if total == 0:
        return torch.zeros(batch_shape, dtype=dtype, device=device)
    step = max(1, q.chunk // max(per_eval_points, 1))
    if total <= step:
        return fn(slice(0, total)).reshape(batch_shape)
    # independent chunks on worker threads of one intra-op thread each (no OpenMP barrier between
    # the many operations of a chunk; roughsea_torch._parallel); the chunks do not depend on the
    # thread count, so neither do the results
    parts = map_chunks(fn, [slice(i, min(i + step, total)) for i in range(0, total, step)], device)
    return torch.cat(parts).reshape(batch_shape)


# -- public functions ------------------------------------------------------------------------


def projected_area(view_zenith: Any, view_azimuth: Any, slopes: SlopeStatistics, shadowing: bool = True) -> torch.Tensor:
    """LOS-projected area of the visible facets per unit horizontal area: the denominator of Eq. 5.

    Args:
        view_zenith: θ̂, zenith angle of the line of sight sea → sensor [rad], in [0, π/2].
        view_azimuth: φ̂, its azimuth from the upwind axis [rad].
        slopes: slope statistics.
        shadowing: True for Eq. 5 (facets turned away removed), False for Eq. 4/7.

    Returns:
        D [dimensionless]: cos θ̂ Φ(μ) + sin θ̂ σ∥ φ(μ) with μ = cot θ̂/σ∥ (= cos θ̂ (1 + Λ), Smith's
        shadowing function Λ), or cos θ̂ without shadowing (Eq. 7).
    """
    if check_shadowing(shadowing) in MASKED_OPTIONS:
        raise ValueError(f"projected_area: shadowing must be True (Eq. 5) or False (Eq. 7); the {shadowing!r} "
                         "masking's normalization is not Eq. 5's projected area")
    _, _, vz, va, vx, vy, cxy, mx, my = prepare_inputs(view_zenith, view_azimuth, slopes)
    return denominator(facet_geometry(vz, va, vx, vy, cxy, mx, my), shadowing)


def smith_lambda(view_zenith: Any, view_azimuth: Any, slopes: SlopeStatistics) -> torch.Tensor:
    """Smith's (1967) Λ = D / cos θ̂ − 1: the fraction of LOS-projected area added by facets that
    face the sensor beyond the horizontal projection [dimensionless]. Diverges as θ̂ → 90°."""
    _, _, vz, va, vx, vy, cxy, mx, my = prepare_inputs(view_zenith, view_azimuth, slopes)
    g = facet_geometry(vz, va, vx, vy, cxy, mx, my)
    return denominator(g, True) / g.ct - 1.0


def emissivity(
    view_zenith: Any,
    view_azimuth: Any,
    slopes: SlopeStatistics,
    refractive_index: Any = 1.218 + 0.0508j,
    shadowing: bool | str = True,
    quadrature: Quadrature | None = None,
) -> torch.Tensor:
    """Rough-sea emissivity ε̄(θ̂, φ̂) = ∫∫ f̂ [1 − ρ(Ω)] dθ dφ (Eq. 5 weights; Eq. 7 without shadowing).

    Args:
        view_zenith: θ̂ [rad] in [0, π/2]; float or tensor.
        view_azimuth: φ̂ [rad] from the upwind axis; float or tensor.
        slopes: :class:`SlopeStatistics` (floats or tensors).
        refractive_index: m = n + i k of the sea (k ≥ 0): complex, complex tensor or (n, k).
        shadowing: Eq. 5 (True, default) or Eq. 7 (False; facets turned away then count with
            negative weight and ρ at |cos Ω|, as Eq. 4 is written); or "correlated": Eq. 5 with the
            slope-conditioned masking of :mod:`roughsea_torch.masking` (facets tilted towards the
            sensor weigh more near grazing); or "multiscale": Eq. 5 with the masking of a sea of many
            scales (:mod:`roughsea_torch.multiscale_masking`; the mean a ray tracer of the waves gives).
        quadrature: accuracy control; ``Quadrature.default(dtype)`` when None.

    Returns:
        ε̄ [dimensionless], the broadcast shape of all inputs, the inputs' dtype and device.

    Example:
        >>> s = SlopeStatistics.cox_munk(5.0)
        >>> round(float(emissivity(0.0, 0.0, s, 1.218 + 0.0508j)), 4)
        0.9898
    """
    shadowing = check_shadowing(shadowing)
    dtype, device, vz, va, vx, vy, cxy, mx, my = prepare_inputs(view_zenith, view_azimuth, slopes, refractive_index)
    n, k = split_refractive_index(refractive_index, dtype, device)
    q = quadrature or Quadrature.default(dtype)
    shape = torch.broadcast_shapes(vz.shape, va.shape, vx.shape, vy.shape, cxy.shape, n.shape, k.shape)
    work = _work_dtype(dtype, shadowing)
    vz, va, vx, vy, cxy, n, k = (t.to(work) for t in (vz, va, vx, vy, cxy, n, k))
    mx, my = (None if t is None else t.to(work) for t in (mx, my))
    g = facet_geometry(vz, va, vx, vy, cxy, mx, my).flat(shape)
    D = _denominator(g, shadowing, q)
    nf, kf = n.expand(shape).reshape(-1), k.expand(shape).reshape(-1)
    points = q.outer * q.hermite * (1 if shadowing else 2)

    def one(sl: slice) -> torch.Tensor:
        ratio = visible_ratio if shadowing else torch.div  # (Eq. 7's D = e may be negative: as it is)
        return ratio(_emissivity_numerator(g.take(sl), nf[sl], kf[sl], shadowing, q), D[sl]).to(dtype)

    return _run_chunked(shape, points, q, one, dtype, device)


def _denominator(g: FacetGeometry, shadowing: bool | str, q: Quadrature) -> torch.Tensor:
    """D of Eq. 5/7 (closed form), or D_Q of a masked option on the emissivity's own nodes."""
    if shadowing in MASKED_OPTIONS:
        return masked_denominator(g, q.outer, q.width, shadowing)
    return denominator(g, shadowing)


def _work_dtype(dtype: torch.dtype, shadowing: bool) -> torch.dtype:
    """The dtype the integrals are accumulated in.

    Without shadowing, Eq. 7 cancels the negative projected area of facets turned away against the
    positive one: near grazing ε̄ ~ cos θ̂ while each part is ~σ∥, a condition number ~σ∥ tan θ̂
    (10³ at 89.99°); and R_a = R_B (1 − T_ρ) + T_s with T_ρ, T_s/R_B ~ σ∥/cos θ̂ ≫ 1 cancel to
    R_B + O(1). Both are computed in float64 whatever the dtype, and the result is rounded once
    (the float32 errors this avoids: ``docs/notes/expectation.md``). With shadowing (T_ρ ≤ 1, ε̄ a
    mean of positive terms) the dtype itself is used.
    """
    return torch.float64 if not shadowing else dtype


def apparent_radiance(
    view_zenith: Any,
    view_azimuth: Any,
    slopes: SlopeStatistics,
    refractive_index: Any = 1.218 + 0.0508j,
    sea_radiance: Any = None,
    sky: Any = None,
    shadowing: bool | str = True,
    quadrature: Quadrature | None = None,
    sun: Any = None,
    sun_masking: bool = True,
    foam_fraction: Any = None,
    sky_masking: bool = False,
) -> torch.Tensor:
    """Apparent radiance of the rough sea, Eq. 10 [W m⁻² sr⁻¹ (units of the radiances given)].

    R_a = ∫∫ f̂(θ, φ) {[1 − ρ(Ω)] R_B + ρ(Ω) R_s(θ')} dθ dφ, with f̂ of Eq. 5 (or Eq. 7), Ω of
    Eq. 6 and θ' of Eq. 9. Reflected rays that point into the sea (cos θ' < 0) see R_B.

    Args:
        view_zenith: θ̂ [rad] in [0, π/2].
        view_azimuth: φ̂ [rad] from the upwind axis.
        slopes: :class:`SlopeStatistics`.
        refractive_index: m = n + i k (k ≥ 0).
        sea_radiance: R_B, blackbody radiance at the sea temperature [W m⁻² sr⁻¹], ≥ 0.
        sky: R_s(θ'): a callable of cos(zenith), a (zenith [rad], radiance) table, a
            :class:`~roughsea_torch.sky.TabulatedSky`, a constant, or a named atmosphere.
        shadowing: Eq. 5 (True, default), Eq. 7 (False), "correlated" (Eq. 5 with the
            slope-conditioned masking of :mod:`roughsea_torch.masking`) or "multiscale" (Eq. 5 with the
            masking of a sea of many scales, :mod:`roughsea_torch.multiscale_masking`); the sun's glint
            keeps Eq. 5 with either.
        quadrature: accuracy control; ``Quadrature.default(dtype)`` when None.
        sun: ``None`` (default: no sun, every result as without it) or a
            :class:`~roughsea_torch.sun.Sun`: its reflection off the waves (the glint,
            :func:`~roughsea_torch.sun.glint_radiance`) is added; ``sky`` is then the rest of the sky.
        sun_masking: with a sun, Smith's masking of the facets from the sun's side (default True).
        sky_masking: Smith's masking of the reflected ray (its masked part meets the sea and sees
            R_B), off by default as in the paper; Mitsuba 3's rough dielectrics include it.
        foam_fraction: ``None`` (default, no foam) or the whitecap fraction f in [0, 1] (e.g.
            :func:`~roughsea_torch.foam.whitecap_fraction` of the wind): (1 − f) R_a + f R_foam,
            R_foam = ε_f R_B + (1 − ε_f) S (:mod:`roughsea_torch.foam`).

    Returns:
        R_a, the broadcast shape of the inputs (including a batched sky's leading dims).

    Notes:
        The emission term is not integrated separately: with ∫ f̂ = 1, Eq. 10 equals
        R_B + ∫ f̂ ρ (R_s − R_B), whose integrand is non-zero only on facets that reflect sky;
        it is evaluated as R_B (1 − T_ρ) + T_s with T_ρ = ∫_C f̂ ρ and T_s = ∫_C f̂ ρ R_s over
        those facets, so R_s ≡ R_B gives R_a = R_B to rounding.
        A user callable ``sky`` receives a tensor of shape (M, N) (M sea states of a chunk, N
        directions each) and must act elementwise.
    """
    check_finite_range("sea_radiance", sea_radiance, 0.0, unit="W m-2 sr-1")
    t_s, t_rho, dtype = _reflection_integrals(
        view_zenith, view_azimuth, slopes, refractive_index, sky, shadowing, quadrature, dict(sea_radiance=sea_radiance),
        sky_masking,
    )
    rb = as_tensor(sea_radiance, dtype, t_s.device).to(t_s.dtype)
    out = (rb - rb * t_rho + t_s).to(dtype)
    if sun is not None:
        if not isinstance(sun, Sun):
            raise ValueError(f"sun must be None or a roughsea_torch.Sun; got {type(sun).__name__}")
        out = out + glint_radiance(view_zenith, view_azimuth, slopes, refractive_index, sun, bool(shadowing),
                                   sun_masking)  # the glint keeps Eq. 5's weight with a masked option (docs/shadowing.md)
    if foam_fraction is not None:
        check_finite_range("foam_fraction", foam_fraction, 0.0, 1.0)
        e_sky = foam_sky_radiance(as_sky(sky), LWIR, refractive_index, dtype=out.dtype, device=out.device)
        rf = foam_radiance(as_tensor(view_zenith, out.dtype, out.device), LWIR, rb.to(out.dtype), e_sky,
                           refractive_index=refractive_index)
        out = with_foam(out, as_tensor(foam_fraction, out.dtype, out.device), rf)
    return out


def reflection_terms(
    view_zenith: Any,
    view_azimuth: Any,
    slopes: SlopeStatistics,
    refractive_index: Any = 1.218 + 0.0508j,
    sky: Any = None,
    shadowing: bool | str = True,
    quadrature: Quadrature | None = None,
    *,
    sky_masking: bool = False,
    working_dtype: bool = False,
) -> tuple[torch.Tensor, torch.Tensor]:
    """The two sky-reflection integrals of Eq. 10: R_a = R_B (1 − T_ρ) + T_s.

    T_ρ = ∫∫ f̂ ρ(Ω) H(cos θ') and T_s = ∫∫ f̂ ρ(Ω) R_s(θ') H(cos θ') over the facets whose reflected
    ray reaches the sky (the others see the sea, R_B). T_ρ is dimensionless; T_s has the units of
    the sky radiance. Both are independent of the sea temperature, so a renderer can tabulate them
    once per sea state and apply R_B per pixel. Arguments as :func:`apparent_radiance`.

    Returns:
        (T_s, T_ρ), the broadcast shape of the inputs (including a batched sky's leading dims), in the
        inputs' dtype; with ``working_dtype=True`` in the dtype they are accumulated in instead
        (float64 without shadowing, :func:`_work_dtype`; the inputs' dtype with shadowing).

    Without shadowing T_ρ and T_s/R_B grow like σ∥/cos θ̂ near grazing and R_B (1 − T_ρ) + T_s
    cancels them: combine them in float64 there (``working_dtype=True``; ``apparent_radiance`` does).
    """
    t_s, t_rho, dtype = _reflection_integrals(view_zenith, view_azimuth, slopes, refractive_index, sky, shadowing,
                                              quadrature, None, sky_masking)
    if working_dtype:
        return t_s, t_rho
    return t_s.to(dtype), t_rho.to(dtype)


def _reflection_integrals(
    view_zenith: Any,
    view_azimuth: Any,
    slopes: SlopeStatistics,
    refractive_index: Any,
    sky: Any,
    shadowing: bool,
    quadrature: Quadrature | None,
    extra_tensors: dict | None,
    sky_masking: bool = False,
) -> tuple[torch.Tensor, torch.Tensor, torch.dtype]:
    """(T_s, T_ρ) in the working dtype (:func:`_work_dtype`), and the call's dtype; the tensors among
    ``extra_tensors`` (``apparent_radiance``'s sea radiance) join the dtype and device resolution."""
    shadowing = check_shadowing(shadowing)
    sky_fn = as_sky(sky)
    sky_tensor = sky_fn.radiance if isinstance(sky_fn, (TabulatedSky, ConstantSky)) else None
    extra = {k: v for k, v in (extra_tensors or {}).items() if isinstance(v, torch.Tensor)}
    dtype, device, vz, va, vx, vy, cxy, mx, my = prepare_inputs(view_zenith, view_azimuth, slopes, refractive_index, **extra)
    if isinstance(sky_tensor, torch.Tensor):  # a sky table follows the call's dtype; only its device must match
        check_same_device(view_zenith=vz, sky=sky_tensor)
    n, k = split_refractive_index(refractive_index, dtype, device)
    q = quadrature or Quadrature.default(dtype)
    shape = torch.broadcast_shapes(
        vz.shape, va.shape, vx.shape, vy.shape, cxy.shape, n.shape, k.shape, _sky_batch_shape(sky_fn)
    )
    work = _work_dtype(dtype, shadowing)
    vz, va, vx, vy, cxy, n, k = (t.to(work) for t in (vz, va, vx, vy, cxy, n, k))
    mx, my = (None if t is None else t.to(work) for t in (mx, my))
    g = facet_geometry(vz, va, vx, vy, cxy, mx, my).flat(shape)
    if g.ct.numel() == 0:
        z = torch.zeros(shape, dtype=work, device=device)
        return z, z, dtype
    D = _denominator(g, shadowing, q)
    nf, kf = n.expand(shape).reshape(-1), k.expand(shape).reshape(-1)
    t_s, t_rho = _sky_terms(g, nf, kf, sky_fn, shape, D, q, sky_masking, shadowing)
    return t_s.reshape(shape), t_rho.reshape(shape), dtype


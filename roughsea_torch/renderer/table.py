"""The table method: per image, the model at a few nodes, one fine table, one lookup per pixel.

Per image one fine table holds, in one array read by one bilinear ``grid_sample`` per pixel,
everything a pixel can see:

- rows 0 … M_z − 1 (the sea): τ(ζ) · R_a(ζ, o) + L_path(ζ) over ζ = asinh(cos θ̂/ε) and the
  azimuth coordinate o. R_a comes from the model at Chebyshev–Lobatto nodes resampled spectrally
  (barycentric matrices L_z, L_o); the path is exact per row, since for one camera the slant range
  is a function of θ̂ alone. As matrices, fine = [τ L_z | L_path] · [R_a ; 1] · L_oᵀ.
- rows M_z … M_z + M_s − 1 (the sky): the sky radiance over the cosine of the ray's zenith at the
  camera, constant along o.

The stages, in order (each a function below, over a :class:`~roughsea_torch.renderer.plan.RenderPlan`):

1. :func:`node_values` — the spans of the view angles each image's pixels cover (from its border,
   :mod:`~roughsea_torch.renderer.coordinates`), the nodes over them, the model at the nodes (the
   mean R_a, and a textured sea's departures from it). Many small operations: run for groups of
   images at once.
2. :func:`fine_table` — the fine table of each image of a chunk: sea rows (path, foam), sky rows,
   the azimuth resampling, and the extra channel (foam on crests, or the glint's smooth factor).
3. :func:`table_maps` and :func:`lookup` — each pixel's table coordinates and one ``grid_sample``
   (in place in a reused workspace on the main CPU path, :mod:`~roughsea_torch.renderer.pixels`).
4. :func:`per_pixel_terms` — what a table cannot hold: the scattered day sky of sky pixels, the
   texture volume, the glint's sharp factor or the whole glint, the foam on crests, the sun's disk,
   and the conversion to kelvin where radiances were added per pixel.

Chunks of ``plan.chunk`` images run stages 2–4 independently, spread over worker threads
(:func:`~roughsea_torch._parallel.map_chunks`); results do not depend on the chunking.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Any, Callable

import torch
import torch.nn.functional as F

from .._parallel import map_chunks
from ..expectation import reflection_terms
from ..sky import select_sky
from ..slopes import SlopeStatistics
from .coordinates import (ViewSpans, angle_of_ratio, asinh_fast, azimuth_coordinate, azimuth_ratio, camera_spans,
                          geometry_spans, ratio_of_angle)
from .foam_terms import foam_radiance_of_images, foam_state_radiances_of_images
from .glint import glint_pixels, glint_sharp_pixels, glint_table, glitter_inputs
from .output import kelvin
from .path import path_rows
from .pixels import table_grid
from .plan import RenderPlan
from .settings import FINE_OVERHANG
from .sky_terms import day_sky_pixels, sky_per_image, sky_rows, sky_with_day, sun_disk_pixels
from .spectral import barycentric
from .texture import warn_eq7, warn_scaled

__all__ = ["render_table", "node_values", "fine_table", "table_maps", "lookup", "per_pixel_terms"]


@dataclass
class NodeValues:
    """Stage 1's result for a group of images (b,): their spans (``spans``), the sea rows' span in ζ
    (``lo``, ``span_z``, float64), the azimuth span [a, b] of the nodes (None when isotropic), the
    mean R_a at the nodes ``coarse`` (b, nz, nphi), and for a textured sea the texture's node values
    ``delta`` and whether each image resolves a wave ``active`` (:meth:`TextureTable.node_values`)."""

    spans: ViewSpans
    lo: torch.Tensor
    span_z: torch.Tensor
    coarse: torch.Tensor
    a: torch.Tensor | None = None
    b: torch.Tensor | None = None
    delta: torch.Tensor | None = None
    active: torch.Tensor | None = None


def map_tensors(fn: Callable, *vals: Any) -> Any:
    """``fn`` over the tensors of stage results (a tensor, a tuple of them, a dataclass of them, or
    None), several results zipped (e.g. to join groups of images, or to slice a chunk out)."""
    v = vals[0]
    if v is None:
        return None
    if dataclasses.is_dataclass(v):
        return type(v)(**{f.name: map_tensors(fn, *(getattr(x, f.name) for x in vals)) for f in dataclasses.fields(v)})
    if isinstance(v, tuple):
        return tuple(map_tensors(fn, *z) for z in zip(*vals))
    return fn(*vals)


def render_table(plan: RenderPlan) -> torch.Tensor:
    """The table method over a plan: (B, H, W), in kelvin with ``plan.brightness``."""
    B, device = plan.B, plan.device
    # where the chunks of pixels are smaller than 4 images (textured scenes), the nodes first, for
    # groups of up to 4 images (their model's temporaries stay tens of MB) spread over the workers,
    # every per-image tensor then joined over the batch; otherwise each chunk its own nodes
    group = max(1, min(4, -(-B // max(1, torch.get_num_threads()))))
    node_all = None
    if plan.chunk < group:
        parts = map_chunks(lambda sl: node_values(plan, sl), [slice(i, min(i + group, B)) for i in range(0, B, group)],
                           device)
        node_all = map_tensors(lambda *t: torch.cat(t), *parts)
    chunks = [slice(i, min(i + plan.chunk, B)) for i in range(0, B, plan.chunk)]
    out = torch.empty(B, plan.H, plan.W, dtype=plan.dtype, device=device) if len(chunks) > 1 else None

    def chunk_of(sl: slice) -> torch.Tensor | None:
        nd = node_values(plan, sl) if node_all is None else map_tensors(lambda t: t[sl], node_all)
        vals = render_chunk(plan, nd, sl)
        if vals.requires_grad or out is None:
            return vals
        out[sl] = vals  # written by the chunk's own thread: no serial concatenation at the end
        return None

    parts = map_chunks(chunk_of, chunks, device)
    if plan.textured and plan.texture.scaled:
        warn_scaled()
    if plan.textured and plan.texture.eq7_vanishing:
        warn_eq7()
    if parts[0] is None:
        return out
    return parts[0] if len(parts) == 1 else torch.cat(parts)


def render_chunk(plan: RenderPlan, nd: NodeValues, sl: slice) -> torch.Tensor:
    """Stages 2–4 for the images ``sl``: (b, H, W). Everything here is per image, so chunks run
    independently."""
    ft = fine_table(plan, nd, sl)
    maps = table_maps(plan, ft, sl)
    fast = fast_lookup(plan, ft, maps, sl)
    if fast is not None:
        return fast
    rays = pixel_rays(plan, maps, sl)
    vals, second = lookup(plan, ft, maps, rays)
    return per_pixel_terms(plan, ft, maps, rays, vals, second, sl)


# ---- stage 1: spans, nodes, the model at the nodes ---------------------------------------------


def node_values(plan: RenderPlan, sl: slice) -> NodeValues:
    """Images ``sl``: spans, and the model at the nodes (the mean's, and the texture's departures
    from it)."""
    p = plan.p
    wd = p.wind_direction[sl]
    rg = (geometry_spans(plan.geometry, sl, wd, plan.inv_eps[sl], plan.iso, plan.fold) if plan.geometry is not None
          else camera_spans(plan.cameras, sl, wd, plan.inv_eps[sl], plan.iso, plan.fold, plan.period))
    lo, span_z, th_nodes = zenith_nodes(plan, rg, sl)
    a = b = None
    if plan.iso:
        ph_nodes = torch.zeros(sl.stop - sl.start, 1, dtype=plan.dtype, device=plan.device)
    else:
        a, b = azimuth_span(plan, rg)
        ph_nodes = azimuth_nodes(plan, rg, a, b, plan.xp_t)
    coarse, sky = mean_at_nodes(plan, sl, th_nodes, ph_nodes)
    nd = NodeValues(rg, lo, span_z, coarse, a, b)
    if plan.textured:  # the realization's departure from R_a at the nodes, per quantile of the resolved slope
        ph_tex, sky_tex = ph_nodes, sky
        if plan.nphi_tex != plan.nphi:  # its own azimuth nodes, and the scattered sky along their mirror azimuths
            ph_tex = azimuth_nodes(plan, rg, a, b, plan.xp_tex)
            sky_tex = sky_with_day(select_sky(p.sky, sl), plan.day, p, sl, ph_tex[:, None, :])
        tex = plan.texture
        nd.delta, nd.active = tex.node_values(sl, tex.field(sl), ph_tex, sky_tex, lo, span_z)
    return nd


def zenith_nodes(plan: RenderPlan, rg: ViewSpans, sl: slice) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
    """The sea rows' span in ζ (lo (b,), span (b,), float64, padded by 1e-6 of the span) and the view
    zeniths θ̂ [rad] of the ζ nodes over it, (b, nz) float64."""
    lo, hi = (torch.where(rg.any_sea, v, torch.full_like(v, d)) for v, d in zip(rg.zeta, (0.0, 1.0)))
    if plan.table.span == "full":
        lo, hi = torch.zeros_like(lo), torch.asinh(1.0 / plan.eps[sl])
    pad = torch.clamp(1e-6 * (hi - lo), min=1e-9)
    lo, hi = lo - pad, hi + pad
    span_z = hi - lo
    th_nodes = torch.acos((plan.eps[sl, None] * torch.sinh(lo[:, None] + span_z[:, None] * (plan.xz_t + 1) / 2))
                          .clamp(0.0, 1.0))
    return lo, span_z, th_nodes


def azimuth_span(plan: RenderPlan, rg: ViewSpans) -> tuple[torch.Tensor, torch.Tensor]:
    """The azimuth coordinate's node span [a, b] (b,) of each image, float64, padded."""
    a, b = (torch.where(rg.any_sea, v, torch.full_like(v, d)) for v, d in zip(rg.azimuth, (0.0, 1.0)))
    if plan.table.span == "full":
        a, b = torch.zeros_like(a), torch.full_like(b, math.pi / 2 if plan.fold else plan.period)
    pad = torch.clamp(1e-6 * (b - a), min=1e-6)
    a, b = a - pad, b + pad
    if plan.fold:  # ψ ∈ [0, π/2]: keep the nodes inside it (the kink stays at the interval's end)
        a, b = a.clamp_min(0.0), b.clamp_max(math.pi / 2)
    return a, b


def azimuth_nodes(plan: RenderPlan, rg: ViewSpans, a: torch.Tensor, b: torch.Tensor, x: torch.Tensor) -> torch.Tensor:
    """Lobatto nodes x ∈ [−1, 1] → φ̂ [rad] from upwind over [a, b], (b, n): the pixels'
    o = wrap_P(φ̂ − c) + P/2, so nodes sit at φ̂ = c + o − P/2 (folded: φ̂ = o = ψ)."""
    shift = 0.0 if plan.fold else plan.period / 2
    return (rg.centre[:, None] - shift + a[:, None] + (b - a)[:, None] * (x + 1) / 2).to(plan.dtype)


def mean_at_nodes(plan: RenderPlan, sl: slice, th_nodes: torch.Tensor, ph_nodes: torch.Tensor) -> tuple[torch.Tensor, Any]:
    """R_a (Eq. 10) at the nodes, (b, nz, nphi) in the render's dtype, and the sky it reflects there.
    T_s and T_ρ are combined in the model's working dtype: float64 without shadowing, where they grow
    like σ∥/cos θ̂ and R_B (1 − T_ρ) + T_s cancels them."""
    p, scene, dtype = plan.p, plan.scene, plan.dtype
    b_ = sl.stop - sl.start
    vz = th_nodes.to(dtype)[:, :, None].expand(b_, plan.nz, plan.nphi)
    va = ph_nodes[:, None, :].expand(b_, plan.nz, plan.nphi)
    slopes = SlopeStatistics.from_variances(p.vx[sl, None, None], p.vy[sl, None, None], p.cxy[sl, None, None])
    if plan.day is None:
        sky = sky_per_image(select_sky(p.sky, sl), b_, dtype, plan.device, 2)
    else:  # per azimuth node: the scattered sky along the mirror azimuth
        sky = sky_with_day(select_sky(p.sky, sl), plan.day, p, sl, ph_nodes[:, None, :])
    t_s, t_rho = reflection_terms(vz, va, slopes, (p.n[sl, None, None], p.k[sl, None, None]), sky, scene.shadowing,
                                  plan.quadrature, sky_masking=scene.sky_masking, working_dtype=True)
    if p.air_scale is not None:
        t_s = t_s * p.air_scale[sl, None, None].to(t_s.dtype)
    rb = p.rb[sl, None, None].to(t_s.dtype)
    return (rb - rb * t_rho + t_s).to(dtype), sky


# ---- stage 2: the fine tables ---------------------------------------------------------------------


@dataclass
class FineTable:
    """Stage 2's result for a chunk of images: the fine table ``fine`` (b, C, M_z + M_s, columns), C = 1
    or 2 (channel 1: the foam on crests, or the glint's smooth factor); the sea rows' span in ζ
    (``lo``, ``span_z``) and the azimuth span (``az_lo``, ``az_hi``: of the ratio u or the angle o;
    ``a``, ``b``: of the angle); the sky rows' first cosine ``s0`` and step ``ds``; whether any pixel
    sees sky; the path's τ per sea row (or None); whether channel 1 is the crest foam (``crest``) and
    which images' glint the table holds (``glint_tab`` (b,) bool, or None); the texture volume of a
    textured chunk (or None)."""

    fine: torch.Tensor
    spans: ViewSpans
    lo: torch.Tensor
    span_z: torch.Tensor
    a: torch.Tensor | None
    b: torch.Tensor | None
    az_lo: torch.Tensor | None
    az_hi: torch.Tensor | None
    s0: torch.Tensor
    ds: torch.Tensor
    has_sky: bool
    tau: torch.Tensor | None
    crest: bool
    glint_tab: torch.Tensor | None
    texture: torch.Tensor | None


def fine_table(plan: RenderPlan, nd: NodeValues, sl: slice) -> FineTable:
    """Images ``sl``: the fine tables from the nodes' values. Sea rows [τ L_z | L_path] · [R_a ; 1] · L_oᵀ
    at ζ = lo + span (y_z + 1)/2, sky rows at cos = s0 + j ds (a ray at the horizontal, cos = 0, where a
    sea-level sky is held constant below, a kink, falls on a row); row r is read at
    gy = 2 r / (N − 1) − 1."""
    delta = None
    if plan.textured and bool(nd.active.any()):  # the fine texture volume of the chunk (None: nothing resolved)
        delta = plan.texture.volume(nd.delta, sl, nd.lo, nd.span_z)
    # textured seas put their whitecaps on the crests, a fraction f_pix per pixel: the fine table
    # then carries the foam-free sea and the foam as two channels, mixed per pixel
    crest = plan.textured and delta is not None and plan.p.foam is not None
    sea_rows, tau, foam_rows = sea_rows_of(plan, nd, sl, crest)
    sky, s0, ds, has_sky = sky_block(plan, nd.spans, sl)
    if plan.brightness and not (plan.textured or plan.sunny):  # in kelvin at the azimuth nodes, before the azimuth
        # resampling: the brightness temperature is as smooth in azimuth as the radiance, and this costs
        # (M_z + M_s) × nphi conversions an image instead of one a pixel
        sea_rows = kelvin(sea_rows, plan.scene.band)
        if has_sky:
            sky = kelvin(sky, plan.scene.band)
    az_lo = az_hi = glint_tab = r_glint = None
    if plan.iso:
        fine = torch.cat([sea_rows, sky[:, :, None]], 1)  # (b, N, 1)
    else:  # sea rows resampled in azimuth; sky rows repeated (not through L_o, whose overhang
        # rows sum to 1 only to rounding: sky pixels may read the border columns)
        sea_cols, col_angle, y, az_lo, az_hi = azimuth_columns(plan, nd, sea_rows)
        if plan.sunny and not (plan.fold or plan.textured):  # the glint's smooth factor, where the table resolves it
            scale = None if plan.scene.path is None else tau.to(plan.dtype)
            if plan.p.foam is not None:
                f = 1.0 - plan.p.foam[sl].to(plan.dtype)[:, None]
                scale = f.expand(sl.stop - sl.start, plan.Mz) if scale is None else scale * f
            r_glint, glint_tab = glint_table(plan.scene, plan.p, sl, plan.eps[sl], nd.lo, nd.span_z, plan.y_z, col_angle, y,
                                             nd.spans.centre, plan.period / 2, sea_cols, scale, plan.table, plan.dtype)
        fine = torch.cat([sea_cols, sky[:, :, None].expand(-1, -1, plan.Lp.shape[0])], 1)
    if crest:  # channels 1 and 2: the active and residual foam (sky rows alike), one grid_sample reads all
        fine = torch.stack([fine] + [torch.cat([r, sky], 1)[:, :, None].expand_as(fine) for r in foam_rows], 1)
    elif glint_tab is not None and bool(glint_tab.any()):  # channel 1: the glint's smooth factor (0 on sky rows)
        fine = torch.stack([fine, torch.cat([r_glint, torch.zeros_like(fine[:, plan.Mz:])], 1)], 1)
    else:
        fine = fine[:, None]
    return FineTable(fine, nd.spans, nd.lo, nd.span_z, nd.a, nd.b, az_lo, az_hi, s0, ds, has_sky, tau, crest, glint_tab,
                     delta)


def sea_rows_of(plan: RenderPlan, nd: NodeValues, sl: slice, crest: bool) -> tuple[torch.Tensor, Any, Any]:
    """The sea rows of the images ``sl`` (b, M_z, nphi): τ · R_a + L_path resampled from the ζ nodes,
    with the whitecaps mixed in (unless they sit on the crests); and τ per row (or None), and the
    foam's radiance per row (b, M_z) (or None; with ``crest`` the active and residual foam's, a pair)."""
    p, scene, dtype, device = plan.p, plan.scene, plan.dtype, plan.device
    b_ = sl.stop - sl.start
    lo, span_z = nd.lo, nd.span_z
    tau = l_path = foam_rows = None
    if scene.path is not None:
        cos_rows = (plan.eps[sl, None] * torch.sinh(lo[:, None] + span_z[:, None] * (plan.y_z + 1) / 2)).clamp(0.0, 1.0).to(dtype)
        tau, l_path = path_rows(scene.path, cos_rows, plan.altitude[sl].to(dtype)[:, None], plan.earth_radius_m)
        if p.air_scale is not None:
            l_path = l_path * p.air_scale[sl, None].to(dtype)
        sea_rows = torch.cat([tau[:, :, None] * plan.Lz, l_path[:, :, None].to(dtype)], -1) @ torch.cat(
            [nd.coarse, torch.ones(b_, 1, plan.nphi, dtype=dtype, device=device)], 1)
    else:
        sea_rows = plan.Lz @ nd.coarse  # (b, M_z, nphi)
    if p.foam is not None:
        # whitecaps, an area fraction f: (1 − f) · sea + f · foam, the foam exact on every fine row
        # (its emissivity has kinks in θ̂ that the nodes would smooth), through the same path
        cos_f = (plan.eps[sl, None] * torch.sinh(lo[:, None] + span_z[:, None] * (plan.y_z + 1) / 2)).clamp(0.0, 1.0).to(dtype)
        theta_f = torch.acos(cos_f)
        foam_rows = foam_state_radiances_of_images(theta_f, p, sl, scene) if crest else \
            foam_radiance_of_images(theta_f, p, sl, scene)  # the two states' on crests, their mean otherwise
        if scene.path is not None:
            foam_rows = tuple(tau.to(dtype) * r + l_path.to(dtype) for r in foam_rows) if crest else \
                tau.to(dtype) * foam_rows + l_path.to(dtype)
        if not crest:
            f = p.foam[sl].to(dtype)[:, None, None]
            sea_rows = sea_rows + f * (foam_rows[:, :, None] - sea_rows)
    return sea_rows, tau, foam_rows


def sky_block(plan: RenderPlan, rg: ViewSpans, sl: slice) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor, bool]:
    """The sky rows of the images ``sl`` (b, M_s) over the span of their sky pixels' ray-zenith
    cosines, the first row's cosine ``s0`` and the step ``ds`` (b,) (a ray at the horizontal, cos = 0,
    falls on a row), and whether any pixel sees sky (no sky work otherwise)."""
    Ms, device, dtype = plan.Ms, plan.device, plan.dtype
    s_lo, s_hi = (torch.where(rg.any_sky, v, torch.full_like(v, d)) for v, d in zip(rg.sky, (0.0, 1.0)))
    s_pad = torch.clamp(1e-6 * (s_hi - s_lo), min=1e-7)
    s_lo, s_hi = s_lo - s_pad, s_hi + s_pad
    ds = (s_hi - s_lo) * (1.0 + plan.es) / (Ms - 1)
    s0 = s_lo - FINE_OVERHANG * ds
    r0 = -s0 / ds
    s0 = torch.where((r0 > 0) & (r0 < Ms - 1), s0 - (torch.ceil(r0) - r0) * ds, s0)
    has_sky = bool(rg.any_sky.any())
    if has_sky:
        s_rows = (s0[:, None] + ds[:, None] * torch.arange(Ms, dtype=torch.float64, device=device)).to(dtype)
        air = None if plan.p.air_scale is None else plan.p.air_scale[sl]
        sky = sky_rows(select_sky(plan.p.sky, sl), air, plan.scene, s_rows, plan.altitude[sl]).to(dtype)
    else:  # no sky work when no pixel sees sky
        sky = torch.zeros(sl.stop - sl.start, Ms, dtype=dtype, device=device)
    return sky, s0, ds, has_sky


def azimuth_columns(plan: RenderPlan, nd: NodeValues, sea_rows: torch.Tensor) -> tuple:
    """The sea rows resampled to the fine columns, (b, M_z, columns); the map from column coordinates
    t ∈ [−1, 1] to the angle o; the columns' coordinates y; and the span of the coordinate the pixels
    read (the ratio u of :func:`azimuth_ratio`, columns uniform in u, or the angle o)."""
    a, b, fold = nd.a, nd.b, plan.fold
    y = torch.linspace(-1.0 - plan.ep, 1.0 + plan.ep, plan.Lp.shape[0], dtype=torch.float64, device=plan.device)
    if plan.ratio:  # columns uniform in u (azimuth_ratio): the node coordinate of each, per image
        u_a, u_b = ratio_of_angle(a, fold), ratio_of_angle(b, fold)

        def col_angle(t: torch.Tensor) -> torch.Tensor:  # the angle o of column coordinates t ∈ [−1, 1]
            return angle_of_ratio(u_a[:, None] + (u_b - u_a)[:, None] * (t + 1) / 2, fold)

        L_cols = barycentric(plan.xp, 2.0 * (col_angle(y) - a[:, None]) / (b - a)[:, None] - 1.0).to(plan.dtype)
        return sea_rows @ L_cols.transpose(1, 2), col_angle, y, u_a, u_b

    def col_angle(t: torch.Tensor) -> torch.Tensor:  # columns uniform in the angle o
        return a[:, None] + (b - a)[:, None] * (t + 1) / 2

    return sea_rows @ plan.Lp.T, col_angle, y, a, b


# ---- stage 3: table coordinates and the lookup ---------------------------------------------------


@dataclass
class TableMaps:
    """Per image (b, 1, 1), in the render's dtype: the affine maps from a pixel's ζ (sea) or
    ray-zenith cosine (sky) to the table's row coordinate gy (``k_sea``, ``b_sea``, ``k_sky``,
    ``b_sky``) and from its azimuth coordinate to gx (``k_az``, ``b_az``; None when isotropic); the
    azimuth coordinate's ``offset`` (b,); and, from cameras, ``c1`` = k_r/ε and ``sh`` the sine of
    the horizon dip, so that (cos θ̂/ε)² = c1² (dz² − sh²)."""

    k_sea: torch.Tensor
    b_sea: torch.Tensor
    k_sky: torch.Tensor
    b_sky: torch.Tensor
    offset: torch.Tensor | None
    k_az: torch.Tensor | None
    b_az: torch.Tensor | None
    c1: torch.Tensor | None
    sh: torch.Tensor | None


def table_maps(plan: RenderPlan, ft: FineTable, sl: slice) -> TableMaps:
    """The :class:`TableMaps` of the images ``sl``."""
    dtype, cg = plan.dtype, plan.cameras
    wd = plan.p.wind_direction[sl]
    k_sea = (2.0 / (plan.N - 1)) * (plan.Mz - 1) / (ft.span_z * (1.0 + plan.ez))  # dgy/dζ
    b_sea = -1.0 - k_sea * (ft.lo - plan.ez * ft.span_z / 2)
    k_sky = (2.0 / (plan.N - 1)) / ft.ds
    b_sky = 2.0 * plan.Mz / (plan.N - 1) - 1.0 - k_sky * ft.s0
    k_sea, b_sea, k_sky, b_sky = (v.to(dtype)[:, None, None] for v in (k_sea, b_sea, k_sky, b_sky))
    # the azimuth coordinate's offset: o = (ray azimuth + offset) mod π (folded: ψ = |o − π/2|)
    offset = k_az = b_az = c1 = sh = None
    if not plan.iso:
        offset = ((math.pi / 2 - wd).to(dtype) if plan.fold else
                  (math.pi / 2 - ft.spans.centre - wd.double()).to(dtype) if plan.period == math.pi else
                  (-ft.spans.centre - wd.double()).to(dtype))
        # gx = b_az + k_az · (the azimuth coordinate: its ratio stand-in u, or the angle)
        lo_a, hi_a = ft.az_lo, ft.az_hi
        k_az = (2.0 / ((hi_a - lo_a) * (1.0 + plan.ep))).to(dtype)[:, None, None]
        b_az = ((-2.0 * lo_a / (hi_a - lo_a) - 1.0) / (1.0 + plan.ep)).to(dtype)[:, None, None]
    if cg is not None:  # per image: (cos θ̂/ε)² = c1² (dz² − s_h²), c1 = k_r/ε, s_h the horizon dip's sine
        c1 = (plan.inv_eps[sl] if cg.flat else cg.k_r[sl].to(dtype) * plan.inv_eps[sl])[:, None, None]
        sh = cg.s_h[sl, None, None] if not cg.flat else torch.zeros_like(c1)
    return TableMaps(k_sea, b_sea, k_sky, b_sky, offset, k_az, b_az, c1, sh)


def fast_lookup(plan: RenderPlan, ft: FineTable, maps: TableMaps, sl: slice) -> torch.Tensor | None:
    """The main path, in place in a reused workspace (:mod:`~roughsea_torch.renderer.pixels`): from
    cameras, without texture or sun, on the CPU (where fresh memory page-faults; CUDA has its caching
    allocator), with no gradient through the rays or the per-image maps. (b, H, W), or None where it
    does not apply."""
    cg = plan.cameras
    if (plan.geometry is not None or plan.textured or plan.sunny or (not plan.iso and not plan.ratio) or cg.requires_grad
            or plan.device.type != "cpu"):
        return None
    xy = cg.separable_xy(sl)
    if xy is None:
        return None
    per_image = [maps.c1, maps.sh, maps.k_sea, maps.b_sea, maps.k_sky, maps.b_sky]
    if not plan.iso:
        per_image += [maps.offset, maps.k_az, maps.b_az]
    if torch.is_grad_enabled() and any(t.requires_grad for t in per_image):
        return None  # a gradient through the per-image maps (e.g. wind_direction): the general path
    az_map = None if plan.iso else dict(offset=maps.offset, fold=plan.fold, k=maps.k_az, b=maps.b_az)
    grid, _ = table_grid(cg, sl, xy, maps.c1, maps.sh, (maps.k_sea, maps.b_sea),
                         (maps.k_sky, maps.b_sky) if ft.has_sky else None, az_map,
                         fresh_grid=torch.is_grad_enabled() and ft.fine.requires_grad)
    return F.grid_sample(ft.fine, grid, mode="bilinear", padding_mode="border", align_corners=True)[:, 0]


@dataclass
class PixelRays:
    """The general path's per-pixel quantities, each (b, H, W): ``cos`` (sea: cos θ̂ from a given
    geometry, or the ray's local-vertical component dz from cameras; sky: the ray's zenith cosine),
    the ray's world components ``dx``, ``dy`` (None where not needed), the sea mask (``sea`` bool,
    None where not needed; ``seaf`` as 1/0), ζ, ``q`` = (cos θ̂/ε)² (from cameras) and the azimuth
    coordinate ``az`` the table reads (None when isotropic)."""

    cos: torch.Tensor
    dx: torch.Tensor | None
    dy: torch.Tensor | None
    sea: torch.Tensor | None
    seaf: torch.Tensor
    zeta: torch.Tensor
    q: torch.Tensor | None
    az: torch.Tensor | None


def pixel_rays(plan: RenderPlan, maps: TableMaps, sl: slice) -> PixelRays:
    """The :class:`PixelRays` of the images ``sl``: from a given geometry, or straight from the
    cameras' rays (ζ from dz: cos θ̂ / ε = (k_r/ε) √((dz + s_h)(dz − s_h)))."""
    dtype, geometry, cg = plan.dtype, plan.geometry, plan.cameras
    q_ = c_t = s_t = None
    if geometry is not None:
        cos, sea = geometry.cos_view_zenith[sl], geometry.is_sea[sl]
        seaf = sea.to(dtype)
        dx, dy = geometry.dx[sl], geometry.dy[sl]
        zeta = asinh_fast((cos * plan.inv_eps[sl, None, None]).clamp_min(0.0))
    else:
        cos, dx, dy = cg.ray_components(sl, need_xy=not (plan.iso or plan.ratio) or plan.sunny)
        if plan.ratio:  # the table's azimuth coordinate from components along axes turned by the offset
            c_t, s_t = cg.ray_components(sl, azimuth_offset=maps.offset)
        # q = (cos θ̂/ε)² = c1² (dz² − s_h²); sky pixels (unused) and the horizon row are held at
        # a tiny q > 0, which keeps √'s gradient finite
        # the sea mask as 1/0 in the image dtype, written by the compare (a bool → float copy costs
        # ~6 compares); as bool only where the texture or the glint needs it
        c1, sh = maps.c1, maps.sh
        seaf = torch.lt(cos.detach(), -sh.detach(), out=torch.empty(cos.shape, dtype=dtype, device=plan.device))
        sea = seaf.bool() if (plan.textured or plan.sunny) else None
        q_ = torch.addcmul(-(c1 * sh) ** 2, cos, cos * (c1 * c1)).clamp_min(1e-30)
        # asinh √q as a log: torch.asinh is ~20x slower on the CPU
        zeta = torch.log(torch.sqrt(q_) + torch.sqrt(q_ + 1.0))
    az = None
    if not plan.iso:
        az = (azimuth_ratio(c_t, s_t, plan.fold) if plan.ratio
              else azimuth_coordinate(dx, dy, maps.offset, plan.fold, plan.period))
    return PixelRays(cos, dx, dy, sea, seaf, zeta, q_, az)


def lookup(plan: RenderPlan, ft: FineTable, maps: TableMaps, rays: PixelRays) -> tuple[torch.Tensor, torch.Tensor | None]:
    """The fine table at each pixel by one bilinear ``grid_sample``: channel 0 (b, H, W) and channel 1
    (the glint's smooth factor), channels 1–2 (the crest foam's active and residual states) or None.

    Bilinear, not bicubic: torch's bicubic is Keys' kernel with a = −0.75, which converges only to
    first order; bilinear on the fine table is second order (~3e-7 at 3072 rows). The grid is stacked
    in planes (b, 2, H, W) and passed as a (b, H, W, 2) view: grid_sample reads it as fast, and planes
    stack ~4x faster than interleaved pairs."""
    gy = torch.addcmul(maps.b_sea, rays.zeta, maps.k_sea)
    if ft.has_sky:  # cos: the sky pixels' cos of the ray's zenith (dz); lerp by weight 0 or 1 is an
        # exact select, and costs an eighth of torch.where on the CPU
        gy = torch.lerp(torch.addcmul(maps.b_sky, rays.cos, maps.k_sky), gy, rays.seaf)
    gx = torch.zeros_like(gy) if plan.iso else torch.addcmul(maps.b_az, rays.az, maps.k_az)
    vals = F.grid_sample(ft.fine, torch.stack([gx, gy], 1).permute(0, 2, 3, 1), mode="bilinear",
                         padding_mode="border", align_corners=True)
    if vals.shape[1] == 2:
        return vals[:, 0], vals[:, 1]
    if vals.shape[1] == 3:  # the crest foam's two states
        return vals[:, 0], vals[:, 1:]
    return vals[:, 0], None


# ---- stage 4: what the table cannot hold -----------------------------------------------------------


def per_pixel_terms(plan: RenderPlan, ft: FineTable, maps: TableMaps, rays: PixelRays, vals: torch.Tensor,
                    second: torch.Tensor | None, sl: slice) -> torch.Tensor:
    """The pixels' values (b, H, W) from the lookup's: plus the scattered day sky of sky pixels, the
    texture, the glint (the table's smooth factor times its sharp factor per pixel, or wholly per
    pixel), mixed with the foam on crests, plus the sun's disk; in kelvin where radiances were added
    here."""
    dtype, scene, p = plan.dtype, plan.scene, plan.p
    cos, dx, dy, sea = rays.cos, rays.dx, rays.dy, rays.sea
    foam_vals = second if ft.crest else None
    r_vals = None if ft.crest else second  # the glint's smooth factor, times its Gaussian core below
    if plan.day is not None and ft.has_sky:  # the scattered sky of the sky pixels, by zenith and azimuth, at them alone
        flat = (rays.seaf.reshape(-1) == 0).nonzero().squeeze(1)
        at = lambda t: t.reshape(-1).index_select(0, flat)  # noqa: E731
        v = day_sky_pixels(plan.day, sl, at(cos), at(dx), at(dy), torch.div(flat, plan.H * plan.W, rounding_mode="floor"))
        vals = vals.reshape(-1).index_add(0, flat, v).reshape(vals.shape)
    resolved = cos_t = f_pix = None
    if plan.textured or plan.sunny:  # cos θ̂ of the sea pixels, from q (these scenes need the cameras)
        cos_t = plan.eps[sl, None, None].to(dtype) * torch.sqrt(rays.q)
    if plan.textured and ft.texture is not None:  # (textured: always the angle coordinate, az)
        def coordinate(ddx: torch.Tensor, ddy: torch.Tensor, i: int) -> torch.Tensor:  # of image i's directions
            return azimuth_coordinate(ddx, ddy, maps.offset[i:i + 1], plan.fold, plan.period)

        texture, x_pix, cov_pix, f_pix = plan.texture.pixels(sl, ft.texture, cos_t, rays.zeta, rays.az, cos, dx, dy, sea,
                                                             ft.lo, ft.span_z, ft.a, ft.b, coordinate, crest=ft.crest)
        vals = vals + texture
        resolved = (x_pix, cov_pix)
    if r_vals is not None:
        vals = vals + r_vals * glint_sharp_pixels(scene, p, sl, cos_t, dx, dy, sea & ft.glint_tab[:, None, None])
    if plan.sunny and (ft.glint_tab is None or not bool(ft.glint_tab.all())):  # the rest per pixel
        vals = vals + pixel_glint(plan, ft, rays, cos_t, resolved, sl)
    if ft.crest:  # (sea + texture + glint) + f_act (active − ·) + f_res (residual − ·)
        # no foam in the sky: there the covers would be a W and (1 − a) W, and the mix would take that
        # share of the sky pixels from the foam channels' sky rows, which lack the day's scattered sky
        # (added to the sky pixels of channel 0 above)
        f_act, f_res = (torch.where(sea, f, torch.zeros_like(f)) for f in f_pix[:2])
        vals = vals + f_act * (foam_vals[:, 0] - vals) + f_res * (foam_vals[:, 1] - vals)
        if len(f_pix) > 2:  # the first hit's foam on its facets, at their own incidence (TableSize.texture_hit_foam_tilt)
            vals = vals + torch.where(sea, f_pix[2], torch.zeros_like(f_pix[2]))
    if plan.sunny and ft.has_sky:  # the sun's disk itself, where it is in view
        ifov = (1.0 / plan.cameras.cameras.fx.to(dtype))[sl]
        vals = vals + sun_disk_pixels(scene, plan.B, sl, cos, dx, dy, ~sea, ifov)
    if (plan.textured or plan.sunny) and plan.brightness:  # per pixel: texture and glint are added in radiance
        vals = kelvin(vals, scene.band)
    return vals


def pixel_glint(plan: RenderPlan, ft: FineTable, rays: PixelRays, cos_t: torch.Tensor, resolved: tuple | None,
                sl: slice) -> torch.Tensor:
    """The whole glint of the sea pixels whose image the table does not serve (b, H, W), through the
    path's τ at the pixel's row, times 1 − f for whitecaps mixed per image."""
    dtype, p = plan.dtype, plan.p
    rows = None
    if plan.scene.path is not None:  # each pixel's fractional sea row of the fine table
        rows = (ft.tau.to(dtype), (rays.zeta - (ft.lo - plan.ez * ft.span_z / 2).to(dtype)[:, None, None])
                * ((plan.Mz - 1) / (ft.span_z * (1.0 + plan.ez))).to(dtype)[:, None, None])
    sea = rays.sea if ft.glint_tab is None else rays.sea & ~ft.glint_tab[:, None, None]
    glitter = None
    if plan.table.glitter and resolved is not None and plan.texture is not None:  # TableSize.glitter
        tex = plan.texture
        sun = plan.scene.sun
        zen = torch.as_tensor(sun.zenith, dtype=torch.float64).expand(plan.B)[sl]
        rad = torch.as_tensor(sun.radius, dtype=torch.float64).expand(plan.B)[sl]
        glitter = glitter_inputs(tex.field(sl), cos_t, rays.dx, rays.dy, tex.centres[sl], tex.altitude[sl], tex.ifov[sl],
                                 tex.earth_radius_m, tex.time[sl], zen, rad, plan.table.glitter_lifetime_s)
    glint = glint_pixels(plan.scene, p, sl, cos_t, rays.dx, rays.dy, sea, rows, resolved, glitter)
    if p.foam is not None and not ft.crest:
        glint = glint * (1.0 - p.foam[sl].to(dtype))[:, None, None]
    return glint

"""Sun glint in a render: the sun's reflection off the waves, R_glint = P ρ t · L_sun G1 / D
(:mod:`roughsea_torch.sun`), added to the sea pixels that can see it.

- :func:`glint_mask`: the sea pixels whose specular slope lies within reach of the slope law (the
  rest carry less than exp(−18) of the glint's peak).
- :func:`glint_table`: the glint's smooth factor L_sun G1 / D tabulated on the fine table's sea rows
  and columns (for images it serves, checked against direct evaluation), times the sharp factor
  P ρ t evaluated per pixel (:func:`glint_sharp_pixels`).
- :func:`glint_pixels`: the whole glint per pixel, for the other images and for textured seas
  (each pixel's own unresolved Gaussian about its resolved slope); with ``TableSize.glitter`` the
  textured pixel's glint times its glitter factor (:mod:`roughsea_torch.glitter`), whose inputs
  :func:`glitter_inputs` makes.

Radiance in W m⁻² sr⁻¹ in the scene's band; azimuths relative to upwind.
"""

from __future__ import annotations

import contextlib
import math
from typing import Any, Callable, Iterator

import torch

from ..clutter import along_view, two_scale_statistics
from ..geometry import slant_range
from ..glitter import (curvature_moments, glitter_factor_unchecked, glitter_latent_unchecked, glitter_spread,
                       mean_abs_hessian_determinant, specular_slope_density)
from ..slopes import SlopeStatistics
from ..sun import glint_from_moments, glint_sharp_factor, sun_masking_factor
from .scene import SceneParameters, SeaScene
from .settings import FINE_OVERHANG, TableSize
from .sky_terms import relative_sun
from .spectral import barycentric, lobatto_interp
from .texture import single_quantile

__all__ = ["glint_mask", "glint_pixels", "glint_table", "glint_sharp_pixels", "glitter_inputs", "fixed_glitter_latent",
           "over_kept_pixels", "upwind_los"]

_FIXED_LATENT: list[float | None] = [None]  # fixed_glitter_latent's value while its block runs


@contextlib.contextmanager
def fixed_glitter_latent(z: float) -> Iterator[None]:
    """Within the ``with`` block, every textured pixel's glitter latent is ``z`` (a finite float in
    [−40, 40]) instead of its draw (:func:`~roughsea_torch.glitter.glitter_latent`). For evaluating a
    render's mean over the latent exactly: Σᵢ wᵢ render(zᵢ) over Gauss–Hermite nodes zᵢ and weights wᵢ
    (probabilists') is the ensemble mean of the glitter, node by node for every pixel at once
    (``tests/renderer/test_glint.py``). Process-wide (renders in other threads see it too); not
    reentrant."""
    if isinstance(z, bool) or not isinstance(z, (int, float)) or not -40.0 <= float(z) <= 40.0:
        raise ValueError(f"z must be a finite number in [-40, 40]; got {z!r}")
    if _FIXED_LATENT[0] is not None:
        raise ValueError("fixed_glitter_latent is already active (not reentrant)")
    _FIXED_LATENT[0] = float(z)
    try:
        yield
    finally:
        _FIXED_LATENT[0] = None


def over_kept_pixels(keep: torch.Tensor, fn: Any, dtype: torch.dtype) -> torch.Tensor:
    """``fn(m, at)`` over the kept pixels of each image m of ``keep`` (b, H, W) bool, into (b, H, W) (0
    elsewhere); ``at(t)`` gathers a (b, H, W) field at the pixels of the call. Image by image (its sun
    and slope law are scalars), in blocks of 2¹⁶ of its kept pixels, whose temporaries stay in cache and
    in the allocator's heap (a fresh multi-megabyte temporary page-faults on every operation); every
    operation is per pixel, so blocks change no value. Gathers by index_select on flat indices
    (boolean-mask indexing costs ~4× more)."""
    b_, H, W = keep.shape
    out = torch.zeros(b_, H * W, dtype=dtype, device=keep.device)
    for m in range(b_):
        flat = keep[m].reshape(-1).nonzero().squeeze(1)
        parts = []
        for i in range(0, flat.numel(), 1 << 16):
            fl = flat[i:i + (1 << 16)]
            parts.append(fn(m, lambda t, fl=fl: t[m].reshape(-1).index_select(0, fl)))
        if parts:
            out = out.index_put((torch.full_like(flat, m), flat), parts[0] if len(parts) == 1 else torch.cat(parts))
    return out.reshape(b_, H, W)


def upwind_los(x: torch.Tensor, y: torch.Tensor, cw: torch.Tensor, sw: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
    """(cos φ̂, sin φ̂) of the line of sight in the upwind frame, from the ray's world components x, y
    (the line of sight is −(x, y) horizontally) and the cosine and sine of the wind direction."""
    inv = torch.rsqrt((x * x + y * y).clamp_min(1e-30))
    return -(x * cw + y * sw) * inv, (x * sw - y * cw) * inv


def glint_mask(p: SceneParameters, sl: slice, sun: Any, cos_t: torch.Tensor, dx: torch.Tensor, dy: torch.Tensor,
                sea: torch.Tensor) -> torch.Tensor:
    """The sea pixels of images ``sl`` that can see glint (b, H, W) bool: those whose specular slope lies
    within 6 standard deviations (whitened) of the slope law, plus the sun disk's own extent (the rest
    carries less than exp(−18) = 1.5e-8 of the glint's peak), with the sun up. ``sun``: the images' sun
    relative to upwind."""
    dtype = cos_t.dtype
    per_img = [getattr(p, k)[sl].to(dtype) for k in ("wind_direction", "vx", "vy", "cxy")] + [sun.zenith, sun.azimuth, sun.radius]

    def reachable(m: int, at: Any) -> torch.Tensor:
        wd, a2, b2, c2, sz, sa, radius = (v[m] for v in per_img)
        ct = at(cos_t).clamp(0.0, 1.0)
        st = torch.sqrt((1 - ct * ct).clamp_min(0.0))
        cph, sph = upwind_los(at(dx), at(dy), torch.cos(wd), torch.sin(wd))
        vx_, vy_ = st * cph, st * sph
        wx, wy, wz = torch.sin(sz) * torch.cos(sa), torch.sin(sz) * torch.sin(sa), torch.cos(sz)
        qz = ct + wz
        sgx, sgy = (vx_ + wx) / qz, (vy_ + wy) / qz
        det = (a2 * b2 - c2 * c2).clamp_min(1e-30)
        d2 = (b2 * sgx * sgx - 2 * c2 * sgx * sgy + a2 * sgy * sgy) / det
        lam_min = (0.5 * (a2 + b2 - torch.sqrt((a2 - b2) ** 2 + 4 * c2 * c2))).clamp_min(1e-24)
        reach = radius * 2.0 * (1 + sgx * sgx + sgy * sgy) / qz.clamp_min(1e-6) / torch.sqrt(lam_min)
        return ((wz > 0) & (torch.sqrt(d2) - reach < 6.0)).to(dtype)

    with torch.no_grad():
        return over_kept_pixels(sea, reachable, dtype) > 0


def glint_pixels(scene: SeaScene, p: SceneParameters, sl: slice, cos_t: torch.Tensor, dx: torch.Tensor,
                  dy: torch.Tensor, sea: torch.Tensor, tau_rows: tuple[torch.Tensor, torch.Tensor] | None,
                  resolved: tuple | None = None, glitter: tuple | None = None) -> torch.Tensor:
    """τ · R_glint at the sea pixels of images ``sl`` (b, H, W), 0 elsewhere, evaluated at the pixels that
    can see glint (:func:`glint_mask`). On a
    textured sea (``resolved`` = each pixel's flat-point quantile x and resolved covariance) the glint
    is that of the pixel's own unresolved Gaussian about its visible resolved slope, as the sky's
    reflection is (:mod:`roughsea_torch.clutter`), so its ensemble mean is the expectation's glint
    (``resolved[0]`` may be the pair (x, x'), x' the visible quantile read from the texture volume).
    ``tau_rows`` = (τ at the fine table's sea rows (b, M_z), each pixel's fractional row (b, H, W))
    with a path, else None. ``glitter`` (textured seas only): :func:`glitter_inputs`' (footprint area,
    E|det H|, F (1 + κ), and the latent's sea points and footprints, seeds, times and step); each pixel's
    glint is then multiplied by its glitter factor, N = area · p(s_g) · E|det H| with p the pixel's own
    unresolved Gaussian, z the latent at its flat-sea point (:mod:`roughsea_torch.glitter`), or the value
    :func:`fixed_glitter_latent` sets."""
    b_, H, W = cos_t.shape
    dtype, device = cos_t.dtype, cos_t.device
    B = p.vx.shape[0]
    sun = relative_sun(scene, p, B, dtype, device, torch.arange(sl.start, sl.stop, device=device))
    keep = glint_mask(p, sl, sun, cos_t, dx, dy, sea)
    # the sun's masking is Smith's G1 of the scene's total slope law (resolved waves mask the sun too):
    # one value per image
    g1 = None
    if scene.sun_masking:
        g1 = sun_masking_factor(SlopeStatistics.from_variances(p.vx[sl], p.vy[sl], p.cxy[sl]), sun, dtype, device)
    per_img = [getattr(p, k)[sl].to(dtype) for k in ("wind_direction", "vx", "vy", "cxy", "n", "k")]
    per_img += [sun.zenith, sun.azimuth, sun.irradiance, sun.radius]

    def glint_of_pixels(m: int, at: Any) -> torch.Tensor:
        wd, vx, vy, cxy, n_, k_, tz, tp, e_sun, al = (v[m] for v in per_img)
        c_k, dx_k, dy_k = at(cos_t), at(dx), at(dy)
        phi = torch.atan2(-dy_k, -dx_k) - wd
        mx = my = None
        if resolved is not None:
            inv = torch.rsqrt((dx_k ** 2 + dy_k ** 2).clamp_min(1e-30))
            var_a, kap = along_view(tuple(at(c) for c in resolved[1]), -dx_k * inv, -dy_k * inv)
            # the pixel's visible quantile x', read from the texture volume where the table gives it
            x, x_vis = resolved[0] if isinstance(resolved[0], tuple) else (resolved[0], None)
            shifted = single_quantile(two_scale_statistics(vx.expand_as(phi), vy.expand_as(phi), cxy.expand_as(phi), phi,
                                                         c_k, at(x)[:, None], var_a, kap,
                                                         visible=None if x_vis is None else at(x_vis)[:, None]))
            (vx, vy, cxy), (mx, my) = shifted.tensors(dtype, device), shifted.mean_tensors(dtype, device)
        g = glint_from_moments(torch.acos(c_k.clamp(-1.0, 1.0)), phi, vx, vy, cxy, mx, my, n_, k_, tz, tp, e_sun, al, scene.shadowing)
        if glitter is not None and mx is not None:
            area, edet, spread, (gx, gy, across), seeds, times, tau = glitter
            p_sg, _ = specular_slope_density(c_k, torch.sqrt((1.0 - c_k * c_k).clamp_min(0.0)), torch.cos(phi), torch.sin(phi),
                                             vx, vy, cxy, mx, my, tz, tp)
            if _FIXED_LATENT[0] is None:  # at the kept pixels only
                z = glitter_latent_unchecked(seeds[m], at(gx), at(gy), at(across),
                                             torch.tensor(float(times[m]) / tau, dtype=torch.float64, device=device)).to(dtype)
            else:
                z = torch.full_like(p_sg, _FIXED_LATENT[0])
            g = g * glitter_factor_unchecked(at(area) * p_sg * edet[m], z, spread[m])
        if g1 is not None:
            g = g * g1[m]
        if tau_rows is not None:  # the path's transmittance: quadratic through the table's 3 nearest rows
            tau_r, row = tau_rows
            nr = tau_r.shape[1]
            r = at(row).clamp(0.0, nr - 1.0)
            i = r.detach().round().clamp(1, nr - 2).long()
            t = r - i.to(r.dtype)
            tm, t0, tq = (tau_r[m].index_select(0, i + d) for d in (-1, 0, 1))
            g = g * (t0 + t * (0.5 * (tq - tm) + t * (0.5 * (tq + tm) - t0)))
        return g

    return over_kept_pixels(keep, glint_of_pixels, dtype)


def glitter_inputs(field: Any, cos_t: torch.Tensor, dx: torch.Tensor, dy: torch.Tensor, centres: torch.Tensor,
                   altitude: torch.Tensor, ifov: torch.Tensor, earth_radius_m: float, time_s: torch.Tensor,
                   sun_zenith: torch.Tensor, sun_radius: torch.Tensor, lifetime_s: float) -> tuple[Any, ...]:
    """The glitter's inputs for :func:`glint_pixels` of a chunk of b images (:mod:`roughsea_torch.glitter`):
    each pixel's horizontal footprint area (R δ)² / cos θ̂ [m²] (b, H, W) (R the slant range at the
    camera ``altitude`` (b,), δ = ``ifov`` (b,), cos θ̂ = ``cos_t``); E|det H| (b,) and F (1 + κ) (b,) from
    the curvature of the image's wave ``field`` (its wind and wave age, up to its top band edge), κ
    at the sun ellipse's radius α/(2 √cos θ_sun) of the sun's own mirror direction; and what the
    latent z of a pixel needs (:func:`~roughsea_torch.glitter.glitter_latent`, evaluated at the
    pixels that can see glint): the world x, y [m] of the pixel's flat-sea point (the camera's
    ``centres`` (b, 3) plus R times the ray's world components ``dx``, ``dy``) and its across-view
    footprint R δ [m], float64 (b, H, W) without gradient; the field's seeds (so a clip's frames of
    one realization share their glitter's history), the images' times ``time_s`` (b,) and
    ``lifetime_s``."""
    dtype = cos_t.dtype
    R = slant_range(cos_t, altitude.to(dtype)[:, None, None], earth_radius_m)
    area = (R * ifov.to(dtype)[:, None, None]) ** 2 / cos_t.clamp_min(1e-9)
    mom = curvature_moments(field.wind_speed.detach(), field.inverse_wave_age.detach(), float(field.bands.k_edges[-1]))
    edet = mean_abs_hessian_determinant(mom.uu, mom.cc, mom.uc).to(dtype)
    radius = sun_radius.detach().to(torch.float64) * 0.5 * torch.rsqrt(torch.cos(sun_zenith.detach().to(torch.float64)).clamp_min(1e-3))
    spread = glitter_spread(mom, radius.clamp(1e-9, 1.0)).to(dtype)
    with torch.no_grad():
        r64, c64 = R.to(torch.float64), centres.to(torch.float64)
        x = c64[:, 0, None, None] + r64 * dx.to(torch.float64)
        y = c64[:, 1, None, None] + r64 * dy.to(torch.float64)
        across = (r64 * ifov.to(torch.float64)[:, None, None]).clamp_min(1e-6)
    return area, edet, spread, (x, y, across), tuple(int(v) for v in field.seeds), time_s.detach().cpu(), lifetime_s


def glint_table(scene: SeaScene, p: SceneParameters, sl: slice, eps: torch.Tensor, lo: torch.Tensor,
                      span_z: torch.Tensor, y_z: torch.Tensor, col_angle: Callable[[torch.Tensor], torch.Tensor],
                      y_cols: torch.Tensor, centre: torch.Tensor, shift: float, sea_cols: torch.Tensor,
                      scale_rows: torch.Tensor | None, table: TableSize, dtype: torch.dtype) -> tuple[torch.Tensor, torch.Tensor]:
    """The smooth factor L_sun G1 / D of the glint of images ``sl`` (the glint is P ρ t · L_sun G1 / D,
    ``roughsea_torch.sun.glint_sharp_factor`` the sharp part, which :func:`glint_sharp_pixels` evaluates per
    pixel) on the fine table's sea rows and unfolded columns (``col_angle``: the azimuth coordinate o of
    column coordinates y ∈ [−1, 1], φ̂ = ``centre`` + o − ``shift``), times ``scale_rows`` (b, M_z)
    (the path's τ, the foam's 1 − f); (b, M_z, M_o), and which images it serves (b,) bool (zero for the
    others, whose glint stays wholly per pixel).

    The factor is evaluated at ``table.glint``² Chebyshev–Lobatto nodes (in ζ over the sea rows' span,
    in azimuth over every column) and resampled spectrally. An image is served when its pixels span
    less than π in azimuth (a coordinate of period π would fold the glint, which has none; under a day
    sky the period is 2π, and the table keeps to spans below π all the same) and, at the centres of the fine cells
    of 48 rows and every other column (where bilinear reading errs most), the table's glint is within
    ``table.glint_tolerance`` of direct evaluation, relative to the radiance there (``sea_cols``, the
    sea's fine table, plus the glint).
    """
    Mz, device = y_z.shape[0], lo.device
    B = p.vx.shape[0]
    sun = relative_sun(scene, p, B, dtype, device, torch.arange(sl.start, sl.stop, device=device))
    e = (slice(None), None, None)
    per = [getattr(p, k)[sl].to(dtype)[e] for k in ("vx", "vy", "cxy", "n", "k")]
    tz, tp, e_sun, al = (v[e] for v in (sun.zenith, sun.azimuth, sun.irradiance, sun.radius))
    g1 = None
    if scene.sun_masking:
        g1 = sun_masking_factor(SlopeStatistics.from_variances(p.vx[sl], p.vy[sl], p.cxy[sl]), sun, dtype,
                                device)[e]
    zero = torch.zeros((), dtype=dtype, device=device)

    def angles(zeta: torch.Tensor, o: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:  # ζ (b, R), o (b, C), float64
        th = torch.acos((eps[:, None] * torch.sinh(zeta)).clamp(0.0, 1.0)).to(dtype)[:, :, None]
        return th, (centre[:, None] + o - shift).to(dtype)[:, None, :]

    def smooth(th: torch.Tensor, ph: torch.Tensor) -> torch.Tensor:
        r = glint_from_moments(th, ph, per[0], per[1], per[2], None, None, per[3], per[4], tz, tp, e_sun, al, scene.shadowing,
                   smooth=True)
        return r if g1 is None else r * g1

    def sharp(th: torch.Tensor, ph: torch.Tensor) -> torch.Tensor:
        return glint_sharp_factor(torch.cos(th), torch.sin(th), torch.cos(ph), torch.sin(ph), per[0], per[1], per[2], zero, zero,
                            per[3], per[4], tz, tp, al)[0]

    n = int(table.glint)
    xg, L_rows, _ = lobatto_interp(n, Mz)  # rows: nodes over the sea span, the fine rows' overhang two cells
    # (the factor has a kink at the horizon, ζ = 0, where the overhang below it holds θ̂ = 90°)
    xg_t = torch.as_tensor(xg, dtype=torch.float64, device=device)
    ang = col_angle(y_cols)
    a0, a1 = ang[:, 0], ang[:, -1]  # columns: nodes over every column, overhang included (it has no kink,
    # and a polynomial of this degree must not be extrapolated by the columns' coarser cells)
    th_n, ph_n = angles(lo[:, None] + span_z[:, None] * (xg_t + 1) / 2, a0[:, None] + (a1 - a0)[:, None] * (xg_t + 1) / 2)
    r_nodes = smooth(th_n, ph_n)
    L_rows = torch.as_tensor(L_rows, dtype=dtype, device=device)
    L_cols = barycentric(xg, 2.0 * (ang - a0[:, None]) / (a1 - a0)[:, None] - 1.0).to(dtype)
    fine = L_rows @ r_nodes @ L_cols.transpose(1, 2)
    if scale_rows is not None:
        fine = fine * scale_rows[:, :, None]
    with torch.no_grad():  # the check
        i = torch.linspace(FINE_OVERHANG, Mz - 2 - FINE_OVERHANG, 48, device=device).round().long().unique()  # rows pixels read
        j = torch.arange(0, y_cols.shape[0] - 1, 2, device=device)
        th, ph = angles(lo[:, None] + span_z[:, None] * (0.5 * (y_z[i] + y_z[i + 1]) + 1) / 2,
                        col_angle(0.5 * (y_cols[j + 1] + y_cols[j])))
        r_c, s_c = smooth(th, ph), sharp(th, ph)
        if scale_rows is not None:
            r_c = r_c * (0.5 * (scale_rows[:, i] + scale_rows[:, i + 1]))[:, :, None]
        cell = lambda t: 0.25 * (t[:, i][:, :, j + 1] + t[:, i][:, :, j] + t[:, i + 1][:, :, j + 1]  # noqa: E731
                                 + t[:, i + 1][:, :, j])
        err = (cell(fine) - r_c).abs() * s_c / (cell(sea_cols).abs() + r_c.abs() * s_c)
        ok = ((err.flatten(1).amax(1) < table.glint_tolerance) & ((a1 - a0) < math.pi - 1e-3)
              & torch.isfinite(r_nodes).flatten(1).all(1))
    return torch.where(ok[:, None, None], fine, torch.zeros_like(fine)), ok


def glint_sharp_pixels(scene: SeaScene, p: SceneParameters, sl: slice, cos_t: torch.Tensor, dx: torch.Tensor,
                        dy: torch.Tensor, sea: torch.Tensor) -> torch.Tensor:
    """P ρ t at the sea pixels that can see glint (:func:`glint_mask`) (b, H, W), 0 elsewhere: the
    glint's part that is sharp in the view direction (``roughsea_torch.sun.glint_sharp_factor``, the ellipse's probability in closed form or by rays
    as it is small or not), for the pixel's line of sight, whose azimuth in the upwind frame comes from
    the ray's world components: (cos φ̂, sin φ̂) = −(dx, dy)/|(dx, dy)| turned by −wind_direction."""
    dtype, device = cos_t.dtype, cos_t.device
    b_, H, W = cos_t.shape
    B = p.vx.shape[0]
    sun = relative_sun(scene, p, B, dtype, device, torch.arange(sl.start, sl.stop, device=device))
    wd = p.wind_direction[sl].to(dtype)
    per_img = [torch.cos(wd), torch.sin(wd), *(getattr(p, k)[sl].to(dtype) for k in ("vx", "vy", "cxy", "n", "k")), sun.zenith,
               sun.azimuth, sun.radius]
    zero = torch.zeros((), dtype=dtype, device=device)

    def sharp_factor(m: int, at: Any) -> torch.Tensor:
        cw, sw, vx, vy, cxy, n_, k_, tz, tp, al = (v[m] for v in per_img)
        c = at(cos_t)
        cph, sph = upwind_los(at(dx), at(dy), cw, sw)
        return glint_sharp_factor(c, torch.sqrt((1.0 - c * c).clamp_min(0.0)), cph, sph, vx, vy, cxy, zero, zero, n_, k_, tz, tp,
                            al)[0]

    return over_kept_pixels(glint_mask(p, sl, sun, cos_t, dx, dy, sea), sharp_factor, dtype)


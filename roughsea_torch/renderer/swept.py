"""The first-hit texture of a textured render (``TableSize(texture_hit="first")``): per image, the
sweep of the resolved surface along ground tracks (:mod:`~roughsea_torch.renderer.hits`), the texture,
foam and (with ``texture_hit_lean``) the unresolved waves' patch moments at its visible samples
(:mod:`~roughsea_torch.renderer.lean`), and each pixel's average over the visible surface of its
window. A mixin of :class:`~roughsea_torch.renderer.texture.TextureTable`, whose volume, scene and
settings it uses; the physics and its measurements: ``docs/texture.md`` §11.

Sources: as :mod:`~roughsea_torch.renderer.hits` (the running-horizon column sweep of height-field
renderers; the two-scale split of Bruneton, Neyret & Holzschuch 2010) and
:mod:`~roughsea_torch.renderer.lean` (LEAN mapping, Olano & Baker 2010).
"""

from __future__ import annotations

import math
from typing import Any

import torch

from .._parallel import BLOCK, in_blocks
from ..clutter import along_variance, footprint, reconcile_scale, resolved_quantile, view_moments
from ..geometry import slant_range
from ..whitecaps import whitecap_cover
from .foam_terms import foam_state_radiances_of_images
from .hits import (Sweep, covers, flat_nonzero, footprint_fade, nonzero_2d, pixel_hits, pixel_windows, read_at,
                   sweep_envelope, sweep_layout, track_count, track_windows, visible_samples)
from .lean import ELL_CLAMP, ShortWaveMoments, projected_area, weighted_window
from .path import path_rows

__all__ = ["SweptTexture", "facet_cosine", "pixel_tracks"]

FOAM_NODES = 1025  # nodes in cos θ of the foam's radiance per image (TableSize.texture_hit_foam_tilt)


class SweptTexture:
    """The sweep's part of :class:`~roughsea_torch.renderer.texture.TextureTable` (``texture_hit="first"``):
    its :meth:`_pixels_swept` is what ``TextureTable.pixels`` returns with the first hit. It reads the
    table's fields (the scene and its parameters, the camera's δ and centres, the times, the sweep's
    settings) and its volume (``_read_volume``)."""

    def _pixels_swept(self, sl: slice, vol: torch.Tensor, cos_t: torch.Tensor, dz: torch.Tensor, dx: torch.Tensor,
                      dy: torch.Tensor, sea: torch.Tensor, lo: torch.Tensor, span_z: torch.Tensor, a: torch.Tensor,
                      b: torch.Tensor, coordinate: Any, crest: bool) -> tuple:
        """:meth:`pixels` by the sweep: per image, the resolved surface along ground tracks, the texture
        and foam fraction at each sample, each pixel's angular average over the visible surface of its
        window; for the glint, x and the covariance at its centre ray's first hit. The texture, the
        resolved covariance and the foam covers fade out with the pixel's own footprint
        (:func:`footprint_fade` g: the texture g · the sweep's, the covariance g² · the hit's, the covers
        g · the sweep's + (1 − g) · the flat point's), so where the pixel resolves no band it is the flat
        point's, i.e. the expectation image."""
        zero = torch.zeros_like(dz)
        # with crest: the covers (f_act, f_res) and, with the foam's tilt, its radiance change from the mean plane's
        n_foam = 2 + int(self.foam_tilt)
        texture, x_c, f_pix = zero.clone(), zero.clone(), tuple(zero.clone() for _ in range(n_foam)) if crest else None
        cov_c = [zero.clone() for _ in range(3)]
        h = self.altitude[sl].to(self.dtype)
        for i in range(dz.shape[0]):
            s = sea[i]
            if not bool(s.any()):
                continue
            im = sl.start + i
            wf = self.field(slice(im, im + 1))
            R = slant_range(cos_t[i][s], h[i], self.earth_radius_m)
            L = footprint(R, cos_t[i][s], self.ifov[im])
            # (the fade at the side of the square of the pixel's footprint's area, R δ / √cos θ̂: near
            # grazing its footprint is R δ across, far shorter than along, and still resolves the waves whose
            # crests run along the view)
            g = footprint_fade(wf, 0, L * cos_t[i][s].clamp_min(1e-9).sqrt())
            rho = torch.sqrt(dx[i] * dx[i] + dy[i] * dy[i]).clamp_min(1e-30)
            tan_g, phi = (-dz[i] / rho)[s], torch.atan2(dy[i], dx[i])[s]
            sw = None
            if bool((g.detach() > 0).any()):  # (else no pixel resolves a band: the expectation image)
                sw = sweep_layout(wf, 0, self.centres[im], self.altitude[im], tan_g, phi, float(self.ifov[im]),
                                  self.earth_radius_m, tracks=self.hit_tracks, **self.hit_layout)
            if sw is None:
                g = torch.zeros_like(g)
            flat = self._flat_covers(im, wf, R, L, dx[i][s], dy[i][s], g) if crest else None
            if crest:
                for c in range(2):
                    f_pix[c][i] = f_pix[c][i].index_put((s,), flat[c])
            if sw is None:
                continue
            tau_t, tau_b = pixel_windows(tan_g, float(self.ifov[im]))
            # each pixel's n tracks across its width (one: the nearest), all pixels' n blocks in one: the
            # window averages, and the centre ray's first hit on each, are the means over its n tracks
            j, n = pixel_tracks(phi, sw, self.hit_tracks)
            P = tan_g.numel()
            tt_all, tb_all, g_all = tau_t.repeat(n), tau_b.repeat(n), g.repeat(n)
            sw, m = self._swept_envelope(im, wf, sw, j, tt_all, g_all)
            on = flat_nonzero(g_all.detach() > 0)  # (the pixels' tracks that take the sweep's texture)
            window = track_windows(sw.shape[1], j.index_select(0, on), tt_all.index_select(0, on), tb_all.index_select(0, on))
            values, x_k, cov_k = self._swept_samples(im, i, wf, sw, m, window, vol, lo, span_z, a, b, coordinate, crest)
            avg, k, hit = pixel_hits(m, values, j, tt_all, tb_all, tan_g.repeat(n), overwrite=True)
            # (x = 0 where g = 0: the pixel resolves nothing, its resolved covariance g² C is 0 too)
            x_h = torch.where(hit & (g_all.detach() > 0), read_at(*x_k, k * sw.shape[1] + j), torch.zeros_like(g_all))
            avg = avg.reshape(avg.shape[0], n, P).mean(1)
            x_h, cov_h = x_h.reshape(n, P).mean(0), [cov_k[c][k].reshape(n, P).mean(0) for c in range(3)]
            # (with the patch moments: the weighted average over the window's covered part, times that part)
            tex = weighted_window(avg[0], avg[-2], avg[-1]) if self.lean else avg[0]
            texture[i] = texture[i].index_put((s,), g * tex)
            if crest:  # the active and residual covers (and the foam's tilt: the sweep's alone, 0 at the flat point)
                for c in range(2):
                    f_pix[c][i] = f_pix[c][i].index_put((s,), flat[c] + g * avg[1 + c])
                if self.foam_tilt:
                    f_pix[2][i] = f_pix[2][i].index_put((s,), g * avg[3])
            x_c[i] = x_c[i].index_put((s,), x_h)
            for c in range(3):  # (g² C: the glint's resolved part fades with the texture)
                cov_c[c][i] = cov_c[c][i].index_put((s,), g * g * cov_h[c])
        return texture, (x_c, x_c), tuple(cov_c), f_pix

    def _flat_covers(self, im: int, wf: Any, R: torch.Tensor, L: torch.Tensor, dx: torch.Tensor, dy: torch.Tensor,
                     g: torch.Tensor) -> list[torch.Tensor]:
        """(1 − g) · the foam covers (f_act, f_res) of pixels of image ``im`` at their flat-sea points, as
        :meth:`pixels` takes them with ``texture_hit="flat"`` (without its column filter), each (P,):
        slant ranges ``R``, footprints ``L``, ray directions ``dx``, ``dy`` and the sweep's weights ``g``
        (P,); evaluated only where g < 1."""
        out = [torch.zeros_like(g), torch.zeros_like(g)]
        need = flat_nonzero(g.detach() < 1.0)
        if need.numel() == 0:
            return out
        pick = lambda v: v.index_select(0, need)  # noqa: E731
        Rn, Ln, t_s = pick(R), pick(L)[None], self.time[im:im + 1]
        X = (self.centres[im, 0] + Rn * pick(dx))[None]
        Y = (self.centres[im, 1] + Rn * pick(dy))[None]
        crest = wf.sample_unchecked(X, Y, t_s, Ln, elevation=False, crest=True, slopes=False)["crest"]
        covers = whitecap_cover(wf, X, Y, t_s, Ln, crest, wf.crest_variance(Ln), wf.crest_variance()[:, None],
                                self.p.foam[im:im + 1].to(self.dtype)[:, None], trails=self.foam_trails)
        w = 1.0 - pick(g)
        return [o.index_put((need,), w * f[0]) for o, f in zip(out, covers)]

    def _swept_envelope(self, im: int, wf: Any, sw: Sweep, j: torch.Tensor, tau_top: torch.Tensor,
                        g: torch.Tensor) -> tuple[Sweep, torch.Tensor]:
        """(the sweep, its running minimum m (nt, ns)) of image ``im``: the elevation read at every sample
        up to the last that a pixel taking the sweep's texture (g > 0) can see (:meth:`Sweep.until` the
        least upper edge ``tau_top`` of their windows; the rows beyond, where g = 0, are the expectation
        image), the whole sweep where that prefix would not reach some window's edge (:func:`covers`:
        an elevation beyond the sweep's bound η_max)."""
        def envelope(cand: Sweep) -> torch.Tensor:
            ns, nt = cand.shape
            fp = cand.footprint[:, None].expand(ns, nt).reshape(1, -1)
            eta = wf.sample_unchecked(cand.x.reshape(1, -1), cand.y.reshape(1, -1), self.time[im:im + 1], fp,
                                      elevation=True, crest=False, slopes=False)["elevation"]
            return sweep_envelope(cand, eta[0].reshape(ns, nt))[1]

        on = flat_nonzero(g.detach() > 0)
        jo, to = j.index_select(0, on), tau_top.index_select(0, on)
        short = sw.until(float(to.min()))
        if short is not sw:
            m = envelope(short)
            if covers(m, jo, to):
                return short, m
        return sw, envelope(sw)

    def _swept_samples(self, im: int, i: int, wf: Any, sw: Sweep, m: torch.Tensor, window: tuple, vol: torch.Tensor,
                       lo: torch.Tensor, span_z: torch.Tensor, a: torch.Tensor, b: torch.Tensor, coordinate: Any,
                       crest: bool) -> tuple:
        """At the sweep's samples of image ``im`` (chunk index ``i``), given its running minimum m (nt, ns)
        (:meth:`_swept_envelope`): the texture and foam fraction (C, nt, ns), the resolved quantiles x and
        the resolved covariance (3 of (ns,)). The slopes, the crest variable, the texture and the foam are
        read only at the visible samples within the depressions ``window`` = (lo, hi) (nt,) that the
        track's pixels see (:func:`visible_samples`: near grazing about half the samples are hidden, and
        the sweep starts where the steepest ray might meet a crest of η_max, before the windows), 0
        elsewhere; their per-point work in blocks (:func:`~roughsea_torch._parallel.in_blocks`). The
        quantiles x come as (the read samples' flat indices, sample-major (ns, nt), ascending; x at each),
        for :func:`~roughsea_torch.renderer.hits.read_at`."""
        dtype = self.dtype
        ns, nt = sw.shape
        fpk = sw.footprint / self.hit_visibility  # (ns,) the node values' footprint F_s
        X, Y, t_s = sw.x.reshape(1, -1), sw.y.reshape(1, -1), self.time[im:im + 1]
        # the samples read, sample-major (ns, nt)
        sel, row, col = nonzero_2d(visible_samples(m.T, dim=0, window=(window[0][None, :], window[1][None, :])))
        pick = lambda v, idx: v.reshape(-1).index_select(0, idx)  # noqa: E731  (faster than v[idx] on CPU)
        Xv, Yv, fv = pick(X, sel)[None], pick(Y, sel)[None], pick(fpk, row)[None]
        smp = wf.sample_unchecked(Xv, Yv, t_s, fv, elevation=False, crest=crest)
        cov_k = tuple(c[0] for c in wf.resolved_covariance(fpk[None]))  # 3 of (ns,)
        cx, sx = torch.cos(sw.az), torch.sin(sw.az)  # the tracks' ray directions (camera → sea)
        # each sample's row in the volume: ζ of its flat view zenith (the local vertical tilts by r/R)
        cos_k = sw.view_cosine()
        zeta_k = torch.asinh(cos_k.double() / self.eps[im]).to(dtype)
        # (within the nodes' range in ζ: samples beyond the pixels' rows read its edge, not the fine grid's
        # overhang, where the nodes' polynomial is extrapolated)
        lim = 1.0 / (1.0 + self.ez)
        gy_k = ((2.0 * (zeta_k - lo[i].to(dtype)) / span_z[i].to(dtype) - 1.0) * lim).clamp(-lim, lim)
        o_t = coordinate(cx[None, None, :], sx[None, None, :], i)
        lean = (self._lean_samples(im, wf, sw, fpk, cov_k, Xv[0], Yv[0], row, col, smp["slope_x"][0], smp["slope_y"][0],
                                   cos_k) if self.lean else None)
        n_cross = 2 + 2 * self.lean  # the cross channels' distance from the volume's end

        def block(u: int, e: int) -> tuple:  # the texture at the read samples u:e, and x of their resolved slope
            r_, c_ = row[u:e], col[u:e]
            s_x, s_y = smp["slope_x"][0, u:e], smp["slope_y"][0, u:e]
            cov_v, cx_v, sx_v = tuple(pick(c, r_) for c in cov_k), pick(cx, c_), pick(sx, c_)
            x_v = resolved_quantile(s_x, s_y, cov_v, cx_v, sx_v)  # (for the glint: the resolved slope alone)
            if lean is not None:  # the unresolved waves' mean slope over the sample's patch added
                s_x, s_y = s_x + lean[0][u:e], s_y + lean[1][u:e]
            x_t = x_v if lean is None else resolved_quantile(s_x, s_y, cov_v, cx_v, sx_v)
            read = self._read_volume(vol[i:i + 1], x_t[None, None], pick(o_t, c_)[None, None], pick(gy_k, r_)[None, None],
                                     a[i:i + 1], b[i:i + 1])[0, :, 0]  # (C, e − u)
            out = read[0]
            if lean is not None:  # + b ℓ + c ℓ², ℓ the log of the along-view unresolved variance's scale
                ell = lean[2][u:e]
                out = out + read[-2] * ell + read[-1] * (ell * ell)
            if not self.cross:
                return out, x_v
            # + g y + h (y² − 1), y the across-view residual of the resolved slope over its rms
            y = _across_quantile(s_x, s_y, cov_v, cx_v, sx_v, x_t)
            return out + read[-n_cross] * y + read[-n_cross + 1] * (y * y - 1.0), x_v

        grad = torch.is_grad_enabled() and any(v.requires_grad for v in (vol, smp["slope_x"], cov_k[0], gy_k, o_t, a, b)
                                               + (() if lean is None else lean))
        tex, x_v = in_blocks(block, sel.numel(), max(sel.numel(), 1) if grad else BLOCK)  # (whole with a graph)
        weights = []
        if lean is not None:  # each sample weighted by its patch's visible projected area over the node's; the
            # pixels' averages divide by the weights' own (:meth:`_pixels_swept`)
            tex = lean[3] * tex
            weights = [lean[3], torch.ones_like(tex)]
        values = [tex]
        if crest:
            var_r = pick(wf.crest_variance(fpk[None]), row)[None]
            f_act, f_res = whitecap_cover(wf, Xv, Yv, t_s, fv, smp["crest"], var_r, wf.crest_variance()[:, None],
                                          self.p.foam[im:im + 1].to(dtype)[:, None], trails=self.foam_trails)
            values += [f_act[0], f_res[0]]
            if self.foam_tilt:
                values.append(self._foam_tilt(im, row, col, cx, sx, cos_k, cov_k, smp["slope_x"][0], smp["slope_y"][0],
                                              f_act[0], f_res[0]))
        values += weights
        # back to every sample (0 at the hidden ones), in the (nt, ns) layout of the envelope, row by row
        full, at = x_v.new_zeros(len(values), nt * ns), (col * ns).add_(row)
        for c, v in enumerate(values):
            full[c].index_copy_(0, at, v)
        return full.reshape(-1, nt, ns), (sel, x_v), cov_k

    def _foam_tilt(self, im: int, row: torch.Tensor, col: torch.Tensor, cx: torch.Tensor, sx: torch.Tensor,
                   cos_k: torch.Tensor, cov_k: tuple, s_x: torch.Tensor, s_y: torch.Tensor, f_act: torch.Tensor,
                   f_res: torch.Tensor) -> torch.Tensor:
        """τ [f_act (R_act(θ_f) − R_act(θ̂)) + f_res (R_res(θ_f) − R_res(θ̂))] at the read samples of image ``im``
        (sweep rows ``row``, tracks ``col``; the tracks' ray directions ``cx``, ``sx`` and the rows' cos θ̂
        ``cos_k``; the resolved slopes ``s_x``, ``s_y`` and the covers there): the foam's radiance change when it
        lies on the sample's resolved facet, seen at θ_f (:func:`facet_cosine` of the reconciled slope λ s,
        ``docs/texture.md`` §7), rather than in the mean plane (``TableSize.texture_hit_foam_tilt``); τ the
        path's transmittance at the row (1 without a path)."""
        p, dtype = self.p, self.dtype
        if not bool(((f_act + f_res).detach() > 0).any()):  # (no foam on any sample: nothing to add)
            return torch.zeros_like(f_act)
        pick = lambda v, idx: v.reshape(-1).index_select(0, idx)  # noqa: E731
        lam = pick(reconcile_scale(cov_k, p.vx[im], p.vy[im], p.cxy[im], p.wind_direction[im]), row)
        cos_f = facet_cosine(pick(cos_k, row), pick(cx, col), pick(sx, col), lam * s_x, lam * s_y)
        # both states' radiances on FOAM_NODES nodes uniform in cos θ (interior: acos' is infinite at 1), linear
        # between them (the foam's emissivity is smooth in θ but for kinks, sub-node here); the mean plane's per
        # sweep row, the facet's per sample
        nodes = torch.linspace(0.0, 1.0, FOAM_NODES, dtype=torch.float64, device=cos_k.device).clamp(1e-6, 1.0 - 1e-6)
        act, res = foam_state_radiances_of_images(torch.acos(nodes).to(dtype)[None], p, slice(im, im + 1), self.scene)

        def lerp(c: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:  # (R_act, R_res) at the cosines c
            u = c.clamp(0.0, 1.0) * (FOAM_NODES - 1)
            i0 = torch.floor(u.detach()).clamp(max=FOAM_NODES - 2).long()
            w = u - i0
            return tuple(t[0].index_select(0, i0) * (1 - w) + t[0].index_select(0, i0 + 1) * w for t in (act, res))

        (fa, fr), (pa, pr) = lerp(cos_f), lerp(cos_k)
        d = f_act * (fa - pick(pa, row)) + f_res * (fr - pick(pr, row))
        if self.scene.path is not None:
            tau, _ = path_rows(self.scene.path, cos_k[None], self.altitude[im:im + 1].to(dtype)[:, None], self.earth_radius_m)
            d = d * pick(tau[0].to(dtype), row)
        return d

    def _lean_samples(self, im: int, wf: Any, sw: Sweep, fpk: torch.Tensor, cov_k: tuple, x: torch.Tensor,
                      y: torch.Tensor, row: torch.Tensor, col: torch.Tensor, s_x: torch.Tensor, s_y: torch.Tensor,
                      cos_k: torch.Tensor) -> tuple:
        """(μ_x, μ_y, ℓ, w) at the read samples (world points ``x``, ``y``; sweep rows ``row``, tracks ``col``;
        the resolved slopes ``s_x``, ``s_y`` there; ``cos_k`` (ns,) the rows' cos θ̂) of image ``im``
        (:mod:`~roughsea_torch.renderer.lean`). The model's slope moves by κ μ, μ the unresolved waves' mean
        slope over each sample's patch (world frame); returned is the shift of the field's slope that does it,
        κ μ / λ (the volume is read at the raw slope's x). ℓ = ln((σ_u² + δ)/σ_u²), clamped to ±ln 3, where
        σ_u² is the unresolved Gaussian's along-view variance (the scene's total less the reconciled resolved
        part at the sample's footprint F_s = ``fpk``) and δ = κ² (C − V) along the view, the patch covariance's
        departure from its expectation. κ = λ √min(1, σ_u² / (λ² V)) maps the field's unresolved bands onto
        the unresolved Gaussian (λ :func:`~roughsea_torch.clutter.reconcile_scale` at F_s, and never more
        of it than it holds), so that σ_u² + δ ≥ 0. w: the patch's visible projected area over the node's
        (Eq. 5's D, :func:`~roughsea_torch.renderer.lean.projected_area`, about λ a + κ μ∥ with σ_u² e^ℓ,
        against λ a with σ_u²)."""
        p = self.p
        pick = lambda v, idx: v.reshape(-1).index_select(0, idx)  # noqa: E731
        rho = torch.sqrt(sw.r * sw.r + sw.h * sw.h)
        # the patch: lean_across · R δ across × the sample's length along the view (half its footprint)
        patch = torch.sqrt(self.lean_across * rho * self.ifov[im] * 0.5 * sw.footprint)
        mx, my, cxx, cyy, cxy, vxx, vyy, vxy = ShortWaveMoments(wf, 0, self.time[im:im + 1])(x, y, fpk, patch, row)
        ex, ey = pick(torch.cos(sw.az), col), pick(torch.sin(sw.az), col)
        lam = reconcile_scale(cov_k, p.vx[im], p.vy[im], p.cxy[im], p.wind_direction[im])  # (ns,)
        lam2 = pick(lam * lam, row)
        wd = p.wind_direction[im].to(self.dtype)
        cr, sr = pick(torch.cos(sw.az - wd), col), pick(torch.sin(sw.az - wd), col)
        total = along_variance((p.vx[im], p.vy[im], p.cxy[im]), cr, sr)  # (upwind frame, relative azimuth)
        v_u = (total - lam2 * along_variance(tuple(pick(c, row) for c in cov_k), ex, ey)).clamp_min(1e-12)
        v_f = along_variance((vxx, vyy, vxy), ex, ey)
        kappa2 = lam2 * torch.clamp(v_u / (lam2 * v_f).clamp_min(1e-30), max=1.0)
        kappa = kappa2.sqrt()
        delta = kappa2 * (along_variance((cxx, cyy, cxy), ex, ey) - v_f)
        ell = torch.log((v_u + delta).clamp_min(v_u * math.exp(-ELL_CLAMP)) / v_u).clamp(-ELL_CLAMP, ELL_CLAMP)
        # the patch's visible projected area (Eq. 5's D about the along-view mean and rms) over the node's
        lam = pick(lam, row)
        a_r = -(s_x * ex + s_y * ey) * lam
        mu_a = -(mx * ex + my * ey) * kappa
        ct = pick(cos_k, row)
        st = torch.sqrt((1.0 - ct * ct).clamp_min(0.0))
        w = (projected_area(ct + st * (a_r + mu_a), st * torch.sqrt(v_u * torch.exp(ell)))
             / projected_area(ct + st * a_r, st * v_u.sqrt()))
        # the shift of the field's slope that moves the model's (λ times it, the volume's x = a/σ_a of the raw
        # slope, docs/texture.md §7) by κ μ
        shift = kappa / lam
        return shift * mx, shift * my, ell, w


def pixel_tracks(phi: torch.Tensor, sw: Sweep, tracks: float) -> tuple[torch.Tensor, int]:
    """(j, n): the tracks of pixels whose centre rays have azimuths ``phi`` (P,) [rad] on the sweep ``sw``
    (``tracks`` per pixel width, :func:`~roughsea_torch.renderer.hits.sweep_layout`). n = ⌊tracks⌋ (at
    least 1, :func:`~roughsea_torch.renderer.hits.track_count`); j (n P,): for q = 0 … n − 1 the block of
    every pixel's track at its centre + (q − (n − 1)/2) δ/n, n tracks spanning its width evenly (the
    midpoint rule of a box δ wide; with n = 1 the nearest track)."""
    n = track_count(tracks)
    u = (phi.detach() - sw.p0) / sw.dphi
    last = sw.az.shape[0] - 1
    return torch.cat([(u + (q - 0.5 * (n - 1))).round().clamp(0, last).long() for q in range(n)]), n


def _across_quantile(slope_x: torch.Tensor, slope_y: torch.Tensor, cov: tuple, dx: torch.Tensor, dy: torch.Tensor,
                     x: torch.Tensor) -> torch.Tensor:
    """y = c_r/σ_r: the resolved slope's component across the line of sight (ê⊥ = ê turned +90°, ê = −(dx,
    dy) the unit horizontal direction towards the sensor) less its regression κ_r a on the along-view
    slope a = x σ_a, over the residual's rms σ_r; clamped to ±3.5 (the quadratic in y is fitted at ±√3); 0
    where σ_r² ≤ 1e-12 σ_a² (nothing resolved across)."""
    ex, ey = -dx, -dy
    var_a, cov_ap, var_p = view_moments(cov, ex, ey)
    ok_a = var_a > 1e-30
    inv_a = torch.where(ok_a, var_a, torch.ones_like(var_a)).reciprocal()
    var_r = var_p - cov_ap * cov_ap * inv_a
    ok = ok_a & (var_r > 1e-12 * (var_a + var_p))
    c_r = slope_y * ex - slope_x * ey - cov_ap * x * inv_a.sqrt()
    y = c_r * torch.rsqrt(torch.where(ok, var_r, torch.ones_like(var_r)))
    return torch.where(ok, y.clamp(-3.5, 3.5), torch.zeros_like(y))


def facet_cosine(cos_view: torch.Tensor, dx: torch.Tensor, dy: torch.Tensor, slope_x: torch.Tensor,
                 slope_y: torch.Tensor) -> torch.Tensor:
    """cos of the angle between a facet's normal and the line of sight to the sensor: (cos θ̂ + sin θ̂ a)/√(1 + |s|²),
    for a view of zenith cosine ``cos_view`` whose ray runs along the horizontal unit vector (``dx``, ``dy``)
    (camera → sea), and a facet of world-frame slope s = (``slope_x``, ``slope_y``) = −∇η (``docs/physics.md``
    §2; normal (s, 1)/√(1 + |s|²)); a = −s · (dx, dy) is its slope towards the sensor. Negative where the facet
    faces away. All broadcast together."""
    sin_view = torch.sqrt((1.0 - cos_view * cos_view).clamp_min(0.0))
    a = -(slope_x * dx + slope_y * dy)
    return (cos_view + sin_view * a) * torch.rsqrt(1.0 + slope_x * slope_x + slope_y * slope_y)

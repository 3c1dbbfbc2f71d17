"""The texture of a textured sea in the table method: per image, the realization's departure from the
expectation at Chebyshev–Lobatto nodes, resampled to a fine volume and read per sea pixel.

The physics is :mod:`roughsea_torch.clutter`'s two-scale model (waves longer than a pixel's
footprint are geometry; the rest stays statistical about the resolved slope, so the two add up to
the scene's slope law and the ensemble mean is the expectation image); the wave field is
:class:`~roughsea_torch.waves.WaveField`. This module tabulates it: Δ(ζ, o, x) = R(a'(x)) − R_a
over the view's ζ and azimuth coordinate o and the flat-point quantile x of the resolved along-view
slope, and reads it per pixel trilinearly (two bilinear ``grid_sample`` and a lerp).
"""

from __future__ import annotations

import math
import os
import sys
import warnings
from typing import Any

import torch
import torch.nn.functional as F

from .._validation import per_batch
from ..clutter import (along_variance, along_view, footprint, reconcile_scale, resolved_quantile, two_scale_statistics,
                       view_moments)
from ..expectation import reflection_terms
from ..geometry import slant_range
from ..sky import ConstantSky, TabulatedSky, select_sky
from ..slopes import SlopeStatistics
from ..whitecaps import whitecap_cover
from .antialias import FOAM_TAPS, TEXTURE_TAPS, filter_columns
from .hits import sample_step
from .lean import log_variance_quadratic, variance_columns
from .path import path_rows
from .scene import SceneParameters
from .sky_terms import sky_per_image
from .spectral import lobatto_interp
from .swept import SweptTexture

__all__ = ["TextureTable", "sky_of_chunk", "single_quantile", "warn_scaled", "warn_eq7", "SCALE_WARNING"]

# render() warns when reconcile_scale scales some pixel's resolved slopes by less than this (their
# variance more than halved): the texture is then markedly weaker than the spectrum alone would give.
# Milder scalings (light winds near range, by design: docs/texture.md §7) pass silently.
SCALE_WARNING = 0.7
_ROOT3 = math.sqrt(3.0)


class TextureTable(SweptTexture):
    """The texture volume of the images of a textured render (made once per render, read per chunk).

    Per image, the realization's departure from the expectation, Δ(ζ, o, x) = R(a'(x)) − R_a, at
    Chebyshev–Lobatto nodes in ζ (its own), azimuth o (the mean table's) and the flat-point
    quantile x of the resolved along-view slope; resampled spectrally to a fine volume (x, ζ, o)
    times the path transmittance τ(ζ) of each row, read per sea pixel trilinearly (two bilinear
    ``grid_sample`` of the two slices of x about the pixel, and a lerp). The nodes' footprint,
    resolved covariance and unresolved Gaussian follow the node's (θ̂, φ̂) and the camera's range at
    θ̂ (for one camera the range is a function of θ̂); nodes where nothing is resolved (far field)
    are not evaluated and hold Δ = 0. With the first hit the volume also carries g and h of the
    across-view slope's texture g y + h (y² − 1) (``TableSize.texture_hit_cross``; its last two
    channels, y the across-view residual of the resolved slope over its rms, ``docs/texture.md`` §11).

    Args:
        table: the render's :class:`~roughsea_torch.renderer.settings.TableSize` (its texture fields).
        nphi: azimuth nodes of the texture (the mean table's span).
        scene, p: the scene and its per-image values (:class:`SceneParameters`, B images).
        cameras: the render's :class:`~roughsea_torch.geometry.CameraGeometry`.
        quadrature: the render's model quadrature.
        altitude: (B,) camera altitudes [m]; earth_radius_m: R [m]; eps: (B,) the ζ scale ε, float64.
    """

    def __init__(self, table: Any, nphi: int, scene: Any, p: SceneParameters, cameras: Any, quadrature: Any,
                 altitude: torch.Tensor, earth_radius_m: float, eps: torch.Tensor, dtype: torch.dtype,
                 device: torch.device):
        self.scene, self.p, self.q = scene, p, quadrature
        self.B, self.dtype, self.device = p.batch_size, dtype, device
        self.altitude, self.earth_radius_m, self.eps = altitude, earth_radius_m, eps
        self.width = float(table.texture_width)
        n_x = int(table.texture_first if table.texture_hit == "first" else table.texture)
        xx, Lx, self.ex = lobatto_interp(n_x, int(table.fine_texture))
        self.xnodes = torch.as_tensor(xx * self.width, dtype=dtype, device=device)
        self.Lx = torch.as_tensor(Lx, dtype=dtype, device=device)
        # with a sun the volume also carries the glint's visible quantile, which needs more ζ nodes
        nz = int(table.texture_zenith) if scene.sun is None else max(int(table.texture_zenith), int(table.texture_zenith_sun))
        xz, Lz, self.ez = lobatto_interp(nz, int(table.fine_texture_zenith))
        self.xz = torch.as_tensor(xz, dtype=torch.float64, device=device)
        self.Lz = torch.as_tensor(Lz, dtype=dtype, device=device)
        _, La, self.ea = lobatto_interp(nphi, int(table.fine_texture_azimuth))
        self.La = torch.as_tensor(La, dtype=dtype, device=device)
        self.ifov = 1.0 / cameras.cameras.fx.to(dtype)  # δ [rad per pixel] at the image centre
        self.centres = cameras.centres.to(dtype)
        # the wave phases ω t in float64 whatever the dtype: a float32 time rounds to 1/16 s at 1e6 s
        self.time = per_batch("time_s", scene.time_s, self.B, torch.float64, device)
        self.quadrature = tuple(int(v) for v in table.texture_quadrature)
        self.quadrature_steep = tuple(int(v) for v in table.texture_quadrature_steep)
        self.steep_cos = math.cos(math.radians(float(table.texture_steep_zenith_deg)))
        self.window = float(table.texture_quadrature_width)
        self.min_band_share = float(table.texture_min_band_share)
        self.first_hit = table.texture_hit == "first"
        # the across-view resolved slope as texture too (first hit): two more channels, the quadratic's
        # coefficients in y = c_r/σ_r (TableSize.texture_hit_cross)
        self.cross = self.first_hit and bool(table.texture_hit_cross)
        # the unresolved waves' own patch moments at each sample (TableSize.texture_hit_lean): two more
        # channels, the quadratic's coefficients in ℓ, the log of the along-view unresolved variance's scale
        self.lean = self.first_hit and bool(table.texture_hit_lean)
        self.lean_across = float(table.texture_hit_lean_across)
        # the volume's channels that are radiances (τ applies): Δ, (x' with a sun: not), (g, h across), (lean)
        self.radiance_channels = ([True] + ([False] if scene.sun is not None else []) + [True, True] * self.cross
                                  + [True, True] * self.lean)
        self.foam_trails = bool(table.foam_trails)
        # each visible sample's foam at its resolved facet's incidence (TableSize.texture_hit_foam_tilt): one
        # more channel per sample, the foam's radiance change from the mean plane's
        self.foam_tilt = self.first_hit and bool(table.texture_hit_foam_tilt)
        self.antialias = bool(table.texture_antialias)  # (renderer.antialias; the sweep is not filtered)
        # the sweep (TableSize.texture_hit_*): samples s(θ̂) pixels apart in depression, each filtered at
        # twice its spacing's footprint along the view, and the volume built for those footprints
        self.hit_steps = dict(step=float(table.texture_hit_step), min_step=float(table.texture_hit_min_step),
                              across=float(table.texture_hit_across), finest=float(table.texture_hit_finest))
        self.hit_tracks = float(table.texture_hit_tracks)
        # the layout the running horizon is built on: spacings × v, the elevation at v · F_s; the node
        # values read at every visible sample with the footprint F_s = its footprint / v
        self.hit_visibility = float(table.texture_hit_visibility)
        self.hit_layout = {k: v * self.hit_visibility for k, v in self.hit_steps.items()}
        self.scaled = False  # whether some resolved slopes were scaled down (reconcile_scale)
        self.eq7_vanishing = False  # whether Eq. 7's projected area vanished at some node (warn_eq7)

    def _scale(self, cos_view: torch.Tensor, width: torch.Tensor) -> Any:
        """The footprint of the texture's nodes, in whole pixels' along-view footprints: 1, or with the
        sweep twice its sample spacing at that view (:func:`~roughsea_torch.renderer.hits.sample_step`;
        ``width`` = R δ [m] there)."""
        return 2.0 * sample_step(cos_view, **self.hit_steps, width=width) if self.first_hit else 1.0

    def field(self, sl: slice) -> Any:
        """The wave field of images ``sl``."""
        return self.scene.wave_field(self.B, self.dtype, self.device, sl, self.min_band_share)

    def resolved(self, wf: Any, L: torch.Tensor, sl: slice) -> tuple[tuple[torch.Tensor, ...], torch.Tensor]:
        """The reconciled resolved covariance at footprints L (b, ...) and its scale λ (b, ...)."""
        cov = wf.resolved_covariance(L)
        ex = (slice(None),) + (None,) * (L.ndim - 1)
        lam = reconcile_scale(cov, *(getattr(self.p, k)[sl][ex] for k in ("vx", "vy", "cxy", "wind_direction")))
        if not self.scaled and bool((lam < SCALE_WARNING).any()):
            self.scaled = True  # the renderer warns once the render is done, from the caller's thread
        return tuple(c * lam * lam for c in cov), lam

    def node_values(self, sl: slice, wf: Any, ph_nodes: torch.Tensor, sky: Any, lo: torch.Tensor,
                    span_z: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
        """The texture at its nodes for images ``sl``: (Δ, active), Δ (b, C, nz, nphi, nx), C = 1, or 2
        with a sun (channel 1: the visible quantile x' = a'/σ_a that the glint's unresolved Gaussian
        is centred on, read per pixel instead of inverting :func:`~roughsea_torch.clutter.visible_slope`'s
        distribution at every pixel), and active (b,) bool: whether any node of the image resolves a
        wave (Δ = 0 and x' = x where none does). ``ph_nodes`` (b, nphi) the azimuth nodes φ̂ [rad]
        from upwind, ``sky`` the sky at them, ``lo``, ``span_z`` (b,) the sea rows' span in ζ. Made of
        many small operations: the renderer runs it for groups of images, then :meth:`volume` per
        chunk of pixels."""
        dtype, device = self.dtype, self.device
        b_, nz, nphi = ph_nodes.shape[0], self.xz.numel(), ph_nodes.shape[1]
        nodes = self._active_nodes(sl, wf, ph_nodes, lo, span_z)
        nx = self.xnodes.numel()
        if nodes is None:
            zero = torch.zeros(b_, 1, nz, nphi, nx, dtype=dtype, device=device)
            if self.scene.sun is not None:
                zero = torch.cat([zero, self.xnodes.expand(b_, 1, nz, nphi, -1)], 1)
            if self.cross or self.lean:
                zero = torch.cat([zero] + [zero[:, :1]] * (2 * (self.cross + self.lean)), 1)
            return zero, torch.zeros(b_, dtype=torch.bool, device=device)
        active, idx, ct, ph, moments, x_vis = nodes
        img = idx[0]
        t_s, t_rho = self._reflection_by_rule(sl, sky, b_, idx, ct, ph, moments)
        rb = self.p.rb[sl][img, None].to(t_s.dtype)
        v = rb - rb * t_rho + t_s
        zero = torch.zeros(b_, nz, nphi, nx, dtype=dtype, device=device)
        channels = [zero.index_put(idx, (v[:, :nx] - v[:, nx:nx + 1]).to(dtype))]
        if self.scene.sun is not None:  # channel 1: the visible quantile x' = a'/σ_a, for the glint (x' = x where
            # nothing is resolved: unused there)
            channels.append(self.xnodes.expand(b_, nz, nphi, -1).clone().index_put(idx, x_vis.to(dtype)))
        if self.cross:  # the last two: g, h of R(y) ≈ R̄ + g y + h (y² − 1), R̄ the along-view node value
            # (the mean over y ~ N(0, 1)), through R(±√3): three-point Gauss–Hermite, exact for the quadratic
            r_m, r_p = v[:, nx + 1:3 * nx + 1].unflatten(1, (2, nx)).unbind(1)
            r_bar = v[:, :nx]
            channels += [zero.index_put(idx, ((r_p - r_m) / (2.0 * _ROOT3)).to(dtype)),
                         zero.index_put(idx, ((0.5 * (r_p + r_m) - r_bar) / 2.0).to(dtype))]
        if self.lean:  # the last two: b, c of R(ℓ) ≈ R̄ + b ℓ + c ℓ², through ℓ = ±ln 2 (the along-view unresolved
            # variance halved and doubled)
            a0 = nx + 1 + 2 * nx * self.cross
            r_m, r_p = v[:, a0:a0 + 2 * nx].unflatten(1, (2, nx)).unbind(1)
            channels += [zero.index_put(idx, c_.to(dtype)) for c_ in log_variance_quadratic(r_m, v[:, :nx], r_p)]
        return torch.stack(channels, 1), active.flatten(1).any(1)

    def _active_nodes(self, sl: slice, wf: Any, ph_nodes: torch.Tensor, lo: torch.Tensor, span_z: torch.Tensor) -> Any:
        """The nodes of images ``sl`` that resolve a wave, or None: (active (b, nz, nphi) bool, their
        indices, cos θ̂ and φ̂ at each, the moments of the unresolved Gaussians (one column per x
        node, and one more, the expectation itself: nothing resolved), the visible quantiles x')."""
        dtype, p = self.dtype, self.p
        # the texture's own ζ nodes over the sea rows' span (it varies faster in ζ than the mean:
        # the resolved scale moves with the footprint, one octave of the spectrum per 0.35 in ζ)
        b_, nz, nphi = ph_nodes.shape[0], self.xz.numel(), ph_nodes.shape[1]
        zeta = lo[:, None] + span_z[:, None] * (self.xz + 1) / 2
        th_nodes = torch.acos((self.eps[sl][:, None] * torch.sinh(zeta)).clamp(0.0, 1.0)).to(dtype)
        h = self.altitude[sl].to(dtype)
        cos_n = torch.cos(th_nodes)
        R = slant_range(cos_n, h[:, None], self.earth_radius_m)
        L = footprint(R, cos_n, self.ifov[sl, None] * self._scale(cos_n, R * self.ifov[sl, None]))
        cov, _ = self.resolved(wf, L, sl)
        cov = tuple(c[:, :, None] for c in cov)  # (b, nz, 1)
        phw = ph_nodes + p.wind_direction[sl, None].to(dtype)  # LOS azimuth in the world
        var_a, kap = along_view(cov, torch.cos(phw)[:, None, :], torch.sin(phw)[:, None, :])  # (b, nz, nphi)
        vx, vy, cxy = (getattr(p, k)[sl, None, None] for k in ("vx", "vy", "cxy"))
        c, s = torch.cos(ph_nodes)[:, None, :], torch.sin(ph_nodes)[:, None, :]
        suu = along_variance((vx, vy, cxy), c, s)
        active = (var_a > 1e-10 * suu).expand(b_, nz, nphi)
        if not bool(active.any()):
            return None
        idx = active.nonzero(as_tuple=True)
        img = idx[0]
        full = lambda t: t.expand(b_, nz, nphi)[idx]  # noqa: E731
        va_, kp_ = full(var_a), full(kap)
        ct = full(cos_n[:, :, None])
        ph = full(ph_nodes[:, None, :])
        # the resolved slope a pixel sees: at its ray's first hit as it is (the hits weight the facets),
        # or at its flat-sea point mapped onto the visible-slope distribution
        x = self.xnodes.expand(img.numel(), -1)
        shifted, x_vis = two_scale_statistics(vx[img, 0, 0], vy[img, 0, 0], cxy[img, 0, 0], ph, ct, x, va_, kp_,
                                              visible=x if self.first_hit else None, return_visible=True)  # (M, nx)
        # one more column, the expectation itself (nothing resolved), on the same quadrature: Δ is
        # the difference of two evaluations whose quadrature errors nearly cancel, so the texture
        # nodes can take a coarser rule than the mean table (TableSize.texture_quadrature)
        cols = shifted.mean_upwind.shape
        moments = [torch.cat([a.expand(cols), b[:, None]], 1) for a, b in ((shifted.var_upwind, vx[img, 0, 0]),
                                                                          (shifted.var_crosswind, vy[img, 0, 0]),
                                                                          (shifted.cov, cxy[img, 0, 0]))]
        moments += [torch.cat([m, torch.zeros_like(m[:, :1])], 1) for m in (shifted.mean_upwind, shifted.mean_crosswind)]
        if self.scene.shadowing is False and not self.eq7_vanishing:
            self._check_eq7(ct, x_vis * va_.sqrt()[:, None], x)
        if self.cross:  # 2 × nx more columns: the resolved across-view residual as geometry at y = ±√3
            moments = self._cross_columns(moments, cov, phw, var_a, kap, full, ph, x.shape[1])
        if self.lean:  # 2 × nx more: the along-view unresolved variance scaled by ½ and 2
            moments = variance_columns(moments, ph, x.shape[1])
        return active, idx, ct, ph, moments, x_vis

    def _check_eq7(self, ct: torch.Tensor, a_vis: torch.Tensor, x: torch.Tensor) -> None:
        """Flags the render when, without shadowing (Eq. 7), a node within 3 σ_a of the resolved slope's
        mean tilts the mean facet away from the sensor: its along-view mean slope is a' (``a_vis``, (M, nx);
        :func:`~roughsea_torch.clutter.unresolved_statistics`), and where e = cos θ̂ + sin θ̂ a' ≤ 0 Eq. 7
        divides by a projected area that vanishes or is negative, so the texture there means nothing
        (:func:`warn_eq7`)."""
        e = ct[:, None] + torch.sqrt((1.0 - ct * ct).clamp_min(0.0))[:, None] * a_vis
        if bool(((e <= 0) & (x.abs() <= 3.0)).any()):
            self.eq7_vanishing = True

    @staticmethod
    def _cross_columns(moments: list, cov: tuple, phw: torch.Tensor, var_a: torch.Tensor, kap: torch.Tensor,
                       full: Any, ph: torch.Tensor, nx: int) -> list:
        """The node columns with the resolved slope's across-view residual c_r (variance σ_r² = ê⊥ᵀ C ê⊥ −
        κ_r² σ_a², independent of a) taken out of the unresolved covariance and put into the mean at
        c_r = y σ_r, y = −√3, √3 (ê⊥ = ê turned +90°, in the upwind frame (−sin φ̂, cos φ̂)), appended
        to the first nx columns of ``moments`` (var_up, var_cr, cov, mean_up, mean_cr)."""
        var_p = view_moments(cov, torch.cos(phw)[:, None, :], torch.sin(phw)[:, None, :])[2]
        var_r = full((var_p - kap * kap * var_a).clamp_min(0.0))[:, None]  # (M, 1)
        sig_r = var_r.sqrt()
        px, py = -torch.sin(ph)[:, None], torch.cos(ph)[:, None]
        vu, vc, cv, mu, mc = (m[:, :nx] for m in moments)
        extra = [vu - var_r * px * px, vc - var_r * py * py, cv - var_r * px * py]
        out = [torch.cat([m] + [e] * 2, 1) for m, e in zip(moments[:3], extra)]
        for m, mean, d in ((moments[3], mu, px), (moments[4], mc, py)):
            out.append(torch.cat([m] + [mean + y * sig_r * d for y in (-_ROOT3, _ROOT3)], 1))
        return out

    def _reflection_by_rule(self, sl: slice, sky: Any, b_: int, idx: tuple, ct: torch.Tensor, ph: torch.Tensor,
                            moments: list) -> tuple[torch.Tensor, torch.Tensor]:
        """(T_s, T_ρ) of the active nodes, (M, nx + 1). Steep views (θ̂ < texture_steep_zenith_deg) take a
        finer rule: there the texture is a few mK and the shifted Gaussian, narrow and near the edge
        of the sky-reflecting disc, needs it."""
        steep = ct > self.steep_cos
        if not bool(steep.any()):
            return self._reflection(sl, sky, b_, idx, ct, ph, moments, slice(None), *self.quadrature)
        if bool(steep.all()):
            return self._reflection(sl, sky, b_, idx, ct, ph, moments, slice(None), *self.quadrature_steep)
        groups = [(m.nonzero().flatten(), rule) for m, rule in ((~steep, self.quadrature), (steep, self.quadrature_steep))]
        parts = [(sel, self._reflection(sl, sky, b_, idx, ct, ph, moments, sel, *rule)) for sel, rule in groups]
        cols = moments[0].shape[1]
        return tuple(torch.zeros(ct.shape[0], cols, dtype=parts[0][1][0].dtype, device=self.device)
                     .index_put((parts[0][0],), parts[0][1][i]).index_put((parts[1][0],), parts[1][1][i])
                     for i in (0, 1))

    def _reflection(self, sl: slice, sky: Any, b_: int, idx: tuple, ct: torch.Tensor, ph: torch.Tensor, moments: list,
                    sel: torch.Tensor | slice, outer: int, inner: int) -> tuple[torch.Tensor, torch.Tensor]:
        """(T_s, T_ρ) of the active nodes ``sel`` on an (outer, inner) rule whose Gaussian window is cut
        at ±texture_quadrature_width standard deviations."""
        dtype, device, p, q, scene = self.dtype, self.device, self.p, self.q, self.scene
        im = idx[0][sel]
        stats = SlopeStatistics.from_variances(*(m[sel] for m in moments[:3])).shifted(*(m[sel] for m in moments[3:]))
        if isinstance(sky, TabulatedSky) and sky.radiance.ndim == 4 and sky.radiance.shape[2] > 1:
            # a sky per azimuth node (by day: the scattered sky along each node's mirror azimuth)
            sky_m = sky.with_radiance(sky.radiance[:, 0].to(dtype=dtype, device=device)[im, idx[2][sel]][:, None, :])
        else:
            sky_m = sky_per_image(select_sky(sky_of_chunk(sky, b_), im.cpu()), im.numel(), dtype, device, 1)
        t_s, t_rho = reflection_terms(torch.acos(ct[sel].clamp(-1.0, 1.0))[:, None], ph[sel][:, None], stats,
                                      (p.n[sl][im, None], p.k[sl][im, None]), sky_m, scene.shadowing,
                                      q.with_(outer=outer, inner=inner, width=min(float(q.width), self.window)),
                                      sky_masking=scene.sky_masking, working_dtype=True)
        if p.air_scale is not None:
            t_s = t_s * p.air_scale[sl][im, None].to(t_s.dtype)
        return t_s, t_rho

    def volume(self, delta: torch.Tensor, sl: slice, lo: torch.Tensor, span_z: torch.Tensor) -> torch.Tensor:
        """The fine texture volume of images ``sl`` from their node values Δ (:meth:`node_values`), τ
        included, laid out (b, C, fine_texture_zenith, fine_texture · fine_texture_azimuth) (the
        slices of x side by side)."""
        dtype, device = self.dtype, self.device
        h = self.altitude[sl].to(dtype)
        # laid out (b, C, ζ, x, azimuth) and flattened to (b, C, ζ, x · azimuth): the slices of x side
        # by side along the width, read by two bilinear lookups and a lerp (see pixels)
        vol = torch.einsum("rz,bczpx,ap,fx->bcrfa", self.Lz, delta, self.La, self.Lx).contiguous()
        if self.scene.path is not None:
            Mt = self.Lz.shape[0]
            y = torch.linspace(-1.0 - self.ez, 1.0 + self.ez, Mt, dtype=torch.float64, device=device)
            cos_rows = (self.eps[sl][:, None] * torch.sinh(lo[:, None] + span_z[:, None] * (y + 1) / 2)).clamp(0.0, 1.0).to(dtype)
            tau, _ = path_rows(self.scene.path, cos_rows, h[:, None], self.earth_radius_m)
            t_ = tau.to(dtype)[:, None, :, None, None]
            rad = torch.tensor(self.radiance_channels, device=device)[None, :, None, None, None]
            t_ = torch.where(rad, t_, torch.ones_like(t_))  # (b, C, ...): τ on the radiance channels, 1 elsewhere
            # (in place on the einsum's own output where nothing needs its graph)
            vol = vol * t_ if vol.requires_grad or t_.requires_grad else vol.mul_(t_)
        return vol.flatten(-2)

    def pixels(self, sl: slice, vol: torch.Tensor, cos_t: torch.Tensor, zeta: torch.Tensor, o: torch.Tensor,
               dz: torch.Tensor, dx: torch.Tensor, dy: torch.Tensor, sea: torch.Tensor, lo: torch.Tensor,
               span_z: torch.Tensor, a: torch.Tensor, b: torch.Tensor, coordinate: Any, crest: bool = False) -> tuple:
        """The texture of every pixel of images ``sl`` (0 off the sea), (b, H, W); each pixel's resolved
        quantile x and resolved covariance (world frame), for the glint; and with ``crest`` its foam
        covers (f_act, f_res) (:func:`~roughsea_torch.whitecaps.whitecap_cover`, 0 off the sea), else None.

        Pixels: cos θ̂ ``cos_t``, ζ ``zeta`` and the azimuth coordinate ``o`` (the angle, over the
        span [a, b]) of their line of sight, the ray's components along the camera's vertical ``dz``
        and world x, y ``dx``, ``dy``, the sea mask; ``coordinate(dx, dy, i)`` the azimuth coordinate
        of world directions for image i of the chunk. With ``TableSize.texture_hit="first"`` a pixel
        sees the visible surface of its depression window along its ground track
        (:mod:`~roughsea_torch.renderer.hits`); with ``"flat"`` its flat-sea point."""
        if self.first_hit:
            return self._pixels_swept(sl, vol, cos_t, dz, dx, dy, sea, lo, span_z, a, b, coordinate, crest)
        wf = self.field(sl)
        dtype = self.dtype
        h = self.altitude[sl].to(dtype)[:, None, None]
        R = slant_range(cos_t, h, self.earth_radius_m)
        L = footprint(R, cos_t, self.ifov[sl, None, None])
        cen = self.centres[sl]
        X = cen[:, 0, None, None] + R * dx
        Y = cen[:, 1, None, None] + R * dy
        # (the field's own entry without the input checks: X, Y, L come from the finite geometry)
        smp = wf.sample_unchecked(X, Y, self.time[sl], L, elevation=False, crest=crest)
        gy = (2.0 * (zeta - lo.to(dtype)[:, None, None]) / span_z.to(dtype)[:, None, None] - 1.0) / (1.0 + self.ez)
        cov = self._row_statistics(sl, wf, gy, lo, span_z, h, crest)
        x = resolved_quantile(smp["slope_x"], smp["slope_y"], (cov[:, 0], cov[:, 1], cov[:, 2]), dx, dy)
        read = self._read_volume(vol, x, o, gy, a, b)
        out = read[:, 0]
        f_pix = None
        if crest:
            zero = torch.zeros_like(out)
            f_act, f_res = whitecap_cover(wf, X, Y, self.time[sl], L, torch.where(sea, smp["crest"], zero),
                                          torch.where(sea, cov[:, 3], zero), wf.crest_variance()[:, None, None],
                                          self.p.foam[sl].to(dtype)[:, None, None], trails=self.foam_trails)
            f_pix = (torch.where(sea, f_act, zero), torch.where(sea, f_res, zero))
        out = torch.where(sea, out, torch.zeros_like(out))
        if self.antialias:  # the band at the rows' Nyquist folds into one-pixel lines (renderer.antialias)
            out = filter_columns(out, sea, TEXTURE_TAPS)
            f_pix = None if f_pix is None else tuple(filter_columns(f, sea, FOAM_TAPS) for f in f_pix)
        # x (or, with a sun, the visible quantile x' read from channel 1) and the resolved covariance go
        # back too: the glint of the same realization needs them
        return (out, x if vol.shape[1] == 1 else (x, read[:, 1]),
                (cov[:, 0], cov[:, 1], cov[:, 2]), f_pix)

    def _row_statistics(self, sl: slice, wf: Any, gy: torch.Tensor, lo: torch.Tensor, span_z: torch.Tensor,
                        h: torch.Tensor, crest: bool) -> torch.Tensor:
        """Each pixel's resolved slope covariance (and, with ``crest``, its crest variable's variance),
        (b, 3 or 4, H, W), read at its row coordinate ``gy``. For one camera the footprint is a function
        of θ̂ alone, so the covariance is tabulated on the texture's rows and read linearly in ζ (one
        lookup instead of the 16 band windows per pixel); the reconciling scale λ cancels in
        x = λ a / (λ σ_a)."""
        dtype = self.dtype
        rows = (lo[:, None] + span_z[:, None] * (torch.linspace(-1.0 - self.ez, 1.0 + self.ez, self.Lz.shape[0],
                dtype=torch.float64, device=lo.device) + 1) / 2)
        cos_r = (self.eps[sl][:, None] * torch.sinh(rows)).clamp(1e-9, 1.0).to(dtype)
        L_r = footprint(slant_range(cos_r, h[:, :, 0], self.earth_radius_m), cos_r, self.ifov[sl, None])
        row_stats = list(wf.resolved_covariance(L_r)) + ([wf.crest_variance(L_r)] if crest else [])
        cov_rows = torch.stack(row_stats, 1)[..., None]  # (b, 3 (+1 with crest), rows, 1)
        grid = torch.stack([torch.zeros_like(gy), gy], -1)
        return F.grid_sample(cov_rows, grid, mode="bilinear", padding_mode="border", align_corners=True)

    def _read_volume(self, vol: torch.Tensor, x: torch.Tensor, o: torch.Tensor, gy: torch.Tensor, a: torch.Tensor,
                     b: torch.Tensor) -> torch.Tensor:
        """The volume at each pixel's (x, ζ, azimuth), (b, C, H, W): trilinear as two bilinear reads of
        the slices of x that hold the pixel (side by side along the width: column i · n_az + azimuth
        index) and a lerp between them; border values beyond each axis, as a 3-D grid_sample (whose
        CPU kernel costs ~3x more)."""
        dtype = self.dtype
        n_x, n_az = self.Lx.shape[0], self.La.shape[0]
        a_, b2 = a.to(dtype)[:, None, None], b.to(dtype)[:, None, None]
        col = ((2.0 * (o - a_) / (b2 - a_) - 1.0) / (1.0 + self.ea)).clamp(-1.0, 1.0).add(1.0).mul((n_az - 1) / 2.0)
        # (x within the nodes' range ±width: the fine grid's overhang beyond it, there for the other axes'
        # reads, would extrapolate the nodes' polynomial, by up to ~1e6 for 65 nodes)
        lim = 1.0 / (1.0 + self.ex)
        z = (x / (self.width * (1.0 + self.ex))).clamp(-lim, lim).add(1.0).mul((n_x - 1) / 2.0)
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
        return torch.lerp(read, upper, fz[:, None]) if read.requires_grad or fz.requires_grad else read.lerp_(upper, fz[:, None])


def sky_of_chunk(sky: Any, b: int) -> Any:
    """A sky reshaped by the renderer to broadcast over (b, nz, nphi) back to one entry per image."""
    if isinstance(sky, TabulatedSky) and sky.radiance.ndim > 1:
        return sky.with_radiance(sky.radiance.reshape(b, sky.radiance.shape[-1]))
    if isinstance(sky, ConstantSky):
        r = torch.as_tensor(sky.radiance)
        if r.ndim > 0:
            return ConstantSky(r.reshape(b))
    return sky


def single_quantile(stats: SlopeStatistics) -> SlopeStatistics:
    """Shifted statistics of shape (..., 1) (one flat-point quantile each) as shape (...)."""
    return SlopeStatistics.from_variances(stats.var_upwind[..., 0], stats.var_crosswind[..., 0], stats.cov[..., 0]).shifted(
        stats.mean_upwind[..., 0], stats.mean_crosswind[..., 0])


def warn_eq7() -> None:
    """The warning of a textured render without shadowing whose resolved tilts turn the mean facet away
    (:meth:`TextureTable._check_eq7`), pointing at the user's line (as :func:`warn_scaled`)."""
    warnings.warn("SeaScene(shadowing=False, seed=...): near grazing the resolved waves tilt some pixels' mean facet "
                  "away from the sensor, where Eq. 7 divides by a projected area that vanishes or is negative: "
                  "the texture there is meaningless (radiances far out of range). Use shadowing=True (Eq. 5), "
                  "'correlated' or 'multiscale' for textured seas seen near grazing.", stacklevel=_user_level())


def _user_level() -> int:
    """The stacklevel of the first frame outside this package, kornia and torch, seen from the caller's caller."""
    here = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))  # the package, roughsea_torch/
    others = tuple(os.path.dirname(os.path.abspath(m.__file__)) for m in (torch, sys.modules.get("kornia")) if m is not None)
    frame, level = sys._getframe(2), 2
    while frame is not None and frame.f_code.co_filename.startswith((here, *others)):
        frame, level = frame.f_back, level + 1
    return level


def warn_scaled() -> None:
    """The warning of :func:`~roughsea_torch.clutter.reconcile_scale`, from the calling thread (the
    chunks run on workers) and pointing at the user's line: the first frame outside this package,
    kornia and torch (an augmentation's own call chain runs through both)."""
    level = _user_level()
    # one fixed text, so Python's default filter shows it once per calling line, not once a batch
    warnings.warn("SeaScene(seed=...): where a pixel's footprint resolves more slope variance in the wave spectrum than "
                  "the scene's slope law allows (ECKV against Cox-Munk: light winds, centimetre footprints), the "
                  "resolved slopes are scaled down so that the two scales still add up to SlopeStatistics "
                  "(roughsea_torch.clutter.reconcile_scale); here some by more than 30 %, so the texture is weaker "
                  "than the spectrum's. Nothing is wrong: the mean stays the slope law's; pass slopes= to use another "
                  "law", stacklevel=level)


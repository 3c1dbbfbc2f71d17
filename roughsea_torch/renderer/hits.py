"""What a pixel sees of the resolved sea: a sweep along ground tracks (height-field rendering).

Near grazing a ray meets the crest of a resolved wave before the flat-sea point it is aimed at, a
crest hides the trough behind it, and a pixel's footprint holds several resolved crests of which it
sees only the faces turned towards it. This module sweeps the resolved surface η(x, y, t)
(:meth:`~roughsea_torch.waves.WaveField.sample` with a footprint's band window) along ground tracks
from the camera outwards and gives each pixel the visible surface within its field of view.

Method (the running horizon of height-field renderers, applied to the sea):

- A camera at height h looks along a ground track of azimuth φ. The sea point at horizontal distance
  r along it, at elevation η(r), is seen under the depression t(r) = (h − η(r) + r²/(2R))/r (tangent of
  the angle below the horizontal; r²/(2R) is the Earth's curvature, R its radius).
- With the running minimum m(r) = min over r' ≤ r of t(r') (it never increases), a ray of depression
  τ first meets the surface at the first r where m(r) ≤ τ; the surface between two samples r_k, r_k+1
  is seen over the depressions [m_k+1, m_k] (none where it is hidden, m_k+1 = m_k). One sweep of a
  track (η at its samples, then the running minimum) serves every pixel on it, whatever its depression.
- A pixel covers the depressions [τ_top, τ_bottom] of its upper and lower edges. It sees the visible
  pieces of the track that fall in that interval, each in proportion to its angular size, so its
  texture is the angular average of the texture along its visible pieces (a box filter in depression,
  found from cumulative sums and binary searches); the parts of the interval with no resolved surface
  (beyond the sweep) add nothing. Where nothing is resolved the average is exactly 0 (the far field
  keeps the expectation image).
- Samples run at depressions s(θ̂) pixels apart (δ the camera's angular pixel size at its centre), and
  the surface at a sample is filtered at the footprint of twice that spacing along the view, 2 s R δ /
  cos θ̂ (the waves shorter than it stay statistical, about the resolved slope): s = ``across`` ·
  cos θ̂ / 2 clamped into [``min_step``, ``step``], so that near grazing, where a pixel's footprint is
  1/cos θ̂ times longer along the view than across, the samples resolve the waves down to ``across``
  times its width across (:func:`sample_step`). Tracks run at azimuths ``1/tracks`` pixel apart; a
  pixel takes its nearest track.
- The samples' finer footprints resolve waves that the pixel's own footprint does not, and the hits
  weight those facets by their visible area, not by the expectation's Eq. 5 weight: their mean leaves
  the expectation image. So the sweep's part fades out with the pixel's own footprint
  (:func:`footprint_fade`), to exactly 0 where the pixel resolves no band: the far field is the
  expectation image.
- Only what some pixel sees is read. The elevation is read at every sample up to the first that the
  shallowest window of a pixel with g > 0 must reach (:meth:`Sweep.until`, for any surface within the
  sweep's elevation bound; :func:`covers` checks it after the running minimum); the slopes, crest
  variable, texture and foam only at the visible samples whose elements meet the depressions the
  track's pixels' windows span (:func:`visible_samples` with a window, :func:`track_windows`). What
  is left out (the flat sea between the sweep's start and the nearest window, hidden troughs, the
  rows beyond the last window) would enter a pixel's average only through the cumulative sum's part
  before its window, which cancels.

Everything is differentiable in the wind (through η, the slopes and the crest variable) and the pose
(through t and the pixels' depressions); the choice of samples and elements is not (indices are
detached), as in any piecewise-linear interpolation.

Sources: the running-horizon column sweep of height-field ("voxel space") terrain renderers, e.g.
D. Cohen-Or, E. Rich, U. Lerner & V. Shenkar, *A real-time photo-realistic visual flythrough*, IEEE
TVCG 2(3), 255–265, 1996; F. K. Musgrave, *Grid tracing: fast ray tracing for height fields*, Yale
University technical report 639, 1988; the two-scale split of E. Bruneton, F. Neyret & N. Holzschuch,
*Real-time realistic ocean lighting using seamless transitions from geometry to BRDF*, Computer
Graphics Forum 29(2), 2010. The brute-force reference it is tested against is
:mod:`roughsea_torch.raytrace`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
import torch

from ..clutter import footprint
from ..geometry import slant_range
from ..wave_bands import band_window

__all__ = ["Sweep", "sweep_layout", "sweep_envelope", "running_minimum", "track_windows", "covers", "visible_samples",
           "flat_nonzero", "nonzero_2d", "read_at", "pixel_windows", "visible_average",
           "centre_element", "pixel_hits", "sample_step", "footprint_fade", "track_count", "view_cosine"]


def sample_step(cos_view: Any, step: float, min_step: float, across: float, finest: float = 0.0,
                width: Any = None) -> Any:
    """The sweep's sample spacing [pixels of depression] at a view of zenith cosine ``cos_view``:
    ``across`` · cos θ̂ / 2 clamped into [``min_step``, ``step``] (a tensor or a numpy array).

    ``finest`` > 0 [m] with ``width`` = R δ [m] (the pixel's width across the view there, of
    ``cos_view``'s shape): at most ``finest`` · cos θ̂ / (2 R δ), i.e. the samples' footprint along the
    view (twice the spacing's, 2 s R δ / cos θ̂) at most ``finest`` metres: ``across`` · R δ grows with
    the range, and near the horizon it would leave unresolved the short waves whose crests still hide
    what lies behind them (``docs/texture.md`` §13). Still no finer than ``min_step``."""
    half = 0.5 * across * cos_view
    if finest > 0.0 and width is not None:
        cap = (0.5 * finest) * cos_view / width
        half = torch.minimum(half, cap) if isinstance(half, torch.Tensor) else np.minimum(half, cap)
    return half.clip(min_step, step) if hasattr(half, "clip") else min(max(half, min_step), step)


def footprint_fade(field: Any, image: int, pixel_footprint: torch.Tensor) -> torch.Tensor:
    """g, the weight of the swept texture at pixels whose own footprint (R δ / cos θ̂,
    :func:`~roughsea_torch.clutter.footprint`) is ``pixel_footprint`` [m] (any shape): the window
    (:func:`~roughsea_torch.wave_bands.band_window`) of the longest band the ``image`` -th image of the
    field holds (nonzero slope variance), at that footprint. 1 while the pixel resolves that band fully,
    falling (C¹) over the octave of footprint in which it stops resolving it, exactly 0 where it resolves
    no band: there the sweep's samples, filtered at finer footprints, would still resolve waves, whose
    visible-area weighting leans the mean away from the expectation image; a pixel takes g · the
    sweep's texture, i.e. the expectation image where it resolves nothing (``docs/texture.md`` §11).
    Differentiable in the footprint (the band's choice is not)."""
    cov = field.band_covariance()[image]  # (n_bands, 3)
    on = ((cov[:, 0] + cov[:, 1]).detach() > 0).tolist()
    k = [kc for kc, o in zip(field.bands.band_wavenumber, on) if o]
    if not k:
        return torch.zeros_like(pixel_footprint)
    return band_window(pixel_footprint, float(min(k)))


def track_count(tracks: float) -> int:
    """n = ⌊``tracks``⌋, at least 1: the tracks a pixel averages across its width (``TableSize.texture_hit_tracks``;
    with n ≥ 2 they are δ/n apart, :func:`sweep_layout`, :func:`~roughsea_torch.renderer.swept.pixel_tracks`)."""
    return max(1, int(math.floor(tracks + 1e-9)))


def view_cosine(r: torch.Tensor, h: Any, curv: float) -> torch.Tensor:
    """cos θ̂ of the sea point at horizontal distance ``r`` [m] seen from height ``h`` [m]: the sine of its
    depression atan((h + r²/(2R))/r) plus the local vertical's tilt r/R (``curv`` = 1/(2R)), clamped into
    [1e-9, 1]; the view zenith of the volume's row a sample reads."""
    return torch.sin(torch.atan((h + curv * r * r) / r) + 2.0 * curv * r).clamp(1e-9, 1.0)


@dataclass
class Sweep:
    """One image's sweep: sample distances ``r`` (ns,) [m] and track azimuths ``az`` (nt,) [rad], the
    points (``x``, ``y``: (ns, nt) world [m]) and their footprints ``footprint`` (ns,) [m]; the camera's
    height ``h`` [m] and the curvature term ``curv`` = 1/(2R) [m⁻¹]; the first track's azimuth ``p0``
    and the tracks' spacing ``dphi`` [rad]; ``eta_max`` [m], the bound of the resolved elevation
    :func:`sweep_layout` assumed (:meth:`until`)."""

    r: torch.Tensor
    az: torch.Tensor
    x: torch.Tensor
    y: torch.Tensor
    footprint: torch.Tensor
    h: torch.Tensor
    curv: float
    p0: float
    dphi: float
    eta_max: float = 0.0

    @property
    def shape(self) -> tuple[int, int]:
        return self.r.shape[0], self.az.shape[0]

    def flat_depression(self) -> torch.Tensor:
        """t0 (ns,): the depression of the flat sea's point at each sample."""
        return (self.h + self.curv * self.r * self.r) / self.r

    def view_cosine(self) -> torch.Tensor:
        """cos θ̂ (ns,) at each sample (:func:`view_cosine`)."""
        return view_cosine(self.r, self.h, self.curv)

    def until(self, tau: float) -> "Sweep":
        """The sweep's first samples (the same points), up to the first whose depression is ≤ ``tau`` (a
        tangent) for any surface within ±``eta_max``: (h + η_max + r²/(2R))/r ≤ τ. A ray of depression
        τ' ≥ τ first meets that surface at or before it, so every pixel whose window's upper edge is at
        least τ reads the same elements of the shorter sweep as of the whole one (its running minimum
        along a track depends only on the samples before; :func:`covers` checks it after the fact). The
        whole sweep where no sample qualifies."""
        ns = self.r.shape[0]
        r = self.r.detach()
        t_hi = (float(self.h.detach()) + self.eta_max + self.curv * r * r) / r
        k = flat_nonzero(t_hi <= tau)
        if k.numel() == 0 or int(k[0]) >= ns - 1:
            return self
        n = max(int(k[0]) + 1, 2)
        return Sweep(self.r[:n], self.az, self.x[:n], self.y[:n], self.footprint[:n], self.h, self.curv, self.p0,
                     self.dphi, self.eta_max)


def sweep_layout(field: Any, image: int, centre: torch.Tensor, h: torch.Tensor, tan_g: torch.Tensor, phi: torch.Tensor,
                 ifov: float, earth_radius_m: float, *, step: float, min_step: float, across: float, tracks: float,
                 finest: float = 0.0, height_sigmas: float = 5.0) -> Sweep | None:
    """The sweep of one image, or None where its sea pixels resolve no wave.

    Args:
        field: the image's :class:`~roughsea_torch.waves.WaveField` (its ``image`` -th image).
        centre: world x, y of the camera [m]; h: its height above the sea [m] (0-D tensor).
        tan_g, phi: the sea pixels' depressions (tangent) and ray azimuths [rad], 1-D.
        ifov: δ, the angular pixel size at the image centre [rad]; earth_radius_m: R [m] (``inf``: flat).
        step, min_step, across, finest: the samples' spacing in depression, in pixels, and the cap on
            their footprint [m] (:func:`sample_step`); tracks: tracks per pixel width (with n = ⌊tracks⌋
            ≥ 2, n of them, the tracks start (n − 1)/2 spacings before the least azimuth and end as far
            beyond the largest: the n tracks across every pixel exist, and across a pixel whose centre
            lies on the grid of the least azimuth, φ_min + k δ, they sit at its centre + (q − (n − 1)/2)
            δ/n, not on rounding ties; :func:`~roughsea_torch.renderer.swept.pixel_tracks`).
        height_sigmas: the resolved elevation's bound, in its standard deviations (the sweep starts where
            the steepest ray may first meet a crest).
    """
    dtype, device = tan_g.dtype, tan_g.device
    curv = 0.0 if math.isinf(earth_radius_m) else 0.5 / earth_radius_m
    hf = float(h.detach())
    k_min = min(field.bands.band_wavenumber)
    l_end = 1.42 * math.pi / k_min  # footprint beyond which no band is resolved (the window's outer edge)
    r_end = math.sqrt(max(l_end * hf / (ifov * 2.0 * min_step) - hf * hf, 0.0))  # the finest sample's reach
    tg = tan_g.detach()
    tg_max, tg_min = float(tg.max()), float(tg.min())
    sig = float(field.elevation_variance(torch.tensor(2.0 * min_step * ifov * hf, dtype=torch.float64))[image].detach().sqrt())
    eta_max = height_sigmas * sig
    r0 = max(0.05, (hf - eta_max) / tg_max) if hf > eta_max else 0.05
    r1 = min(r_end, 1.2 * hf / max(tg_min, 1e-9) + eta_max / max(tg_min, 1e-9))
    if r1 <= r0:
        return None
    # depressions γ from the sweep's start to its end, spaced s(θ̂) δ apart (cos θ̂ = sin γ, flat sea):
    # k(γ) = ∫ dγ / (s δ) on a fine grid, inverted at whole k
    g_far, g_near = math.atan(hf / r1), math.atan(hf / r0)
    grid = np.linspace(g_far, g_near, 20001)
    width = hf / np.sin(grid) * ifov  # R δ [m] at each depression (flat sea)
    dk = 1.0 / (ifov * sample_step(np.sin(grid), step, min_step, across, finest, width))
    k_of_g = np.concatenate([[0.0], np.cumsum(0.5 * (dk[1:] + dk[:-1]) * np.diff(grid))])
    ns = int(math.ceil(k_of_g[-1])) + 1
    if ns < 2:
        return None
    gam = np.interp(np.linspace(0.0, k_of_g[-1], ns), k_of_g, grid)[::-1].copy()  # near to far
    r = torch.as_tensor(hf / np.tan(gam), dtype=dtype, device=device)
    ph = phi.detach()
    p0, p1 = float(ph.min()), float(ph.max())
    n = track_count(tracks)
    dphi = ifov / (tracks if n == 1 else n)
    wide = 0.5 * (n - 1) * dphi  # (see tracks above)
    p0, p1 = p0 - wide, p1 + wide
    nt = int(math.ceil((p1 - p0) / dphi)) + 1
    az = p0 + dphi * torch.arange(nt, dtype=dtype, device=device)
    cen = centre.to(dtype)
    if torch.is_grad_enabled() and cen.requires_grad:
        x, y = cen[0] + r[:, None] * torch.cos(az)[None, :], cen[1] + r[:, None] * torch.sin(az)[None, :]
    else:  # (the products' own arrays: c + r cos φ = r cos φ + c)
        x, y = (r[:, None] * torch.cos(az)[None, :]).add_(cen[0]), (r[:, None] * torch.sin(az)[None, :]).add_(cen[1])
    # each sample filtered at the footprint of the volume's row it reads (TextureTable._scale): its view zenith,
    # the local vertical tilted by r/R, and its slant range on the (curved) sea
    h_ = h.detach().to(dtype)
    cos_k = view_cosine(r, h_, curv)
    R_k = slant_range(cos_k, h_, earth_radius_m)
    fp = footprint(R_k, cos_k, ifov * 2.0 * sample_step(cos_k, step, min_step, across, finest, R_k * ifov))
    return Sweep(r, az, x, y, fp, h.to(dtype), curv, p0, dphi, eta_max)


def sweep_envelope(sweep: Sweep, eta: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
    """(t, m), each (nt, ns): the depressions of the surface's samples (η (ns, nt) [m]) and their
    running minimum along each track (detached: it only chooses elements)."""
    r = sweep.r
    top = (sweep.h + sweep.curv * r * r)[None, :]
    if torch.is_grad_enabled() and (eta.requires_grad or top.requires_grad):
        t = ((top - eta.T) / r[None, :]).contiguous()
    else:  # (in place on η's copy in the tracks' layout: a blocked transpose, then contiguous passes)
        t = eta.T.to(torch.result_type(top, eta), copy=True, memory_format=torch.contiguous_format)
        t = torch.sub(top, t, out=t).div_(r[None, :])
    return t, running_minimum(t.detach())


def running_minimum(t: torch.Tensor) -> torch.Tensor:
    """The running minimum of t (nt, ns) along its last axis, m[:, k] = min over k' ≤ k of t[:, k'] (a
    new tensor): numpy's ``minimum.accumulate`` on the CPU (it writes no index tensor, as ``torch.cummin``
    does), ``torch.cummin`` elsewhere; the same values (a minimum rounds nothing)."""
    if t.device.type == "cpu" and not t.requires_grad:
        return torch.from_numpy(np.minimum.accumulate(t.numpy(), axis=-1))
    return torch.cummin(t, dim=-1).values


def track_windows(nt: int, j: torch.Tensor, tau_top: torch.Tensor, tau_bottom: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
    """(lo, hi), each (nt,): the least upper edge and the largest lower edge (depressions, tangents) of the
    windows of the pixels on each track (``j`` (P,) their tracks); +inf and −inf on tracks without any."""
    lo = torch.full((nt,), math.inf, dtype=tau_top.dtype, device=tau_top.device)
    hi = torch.full((nt,), -math.inf, dtype=tau_top.dtype, device=tau_top.device)
    return (lo.scatter_reduce(0, j, tau_top.detach(), "amin"), hi.scatter_reduce(0, j, tau_bottom.detach(), "amax"))


def covers(m: torch.Tensor, j: torch.Tensor, tau_top: torch.Tensor) -> bool:
    """Whether the running minimum m (nt, ns) of a sweep reaches, on each pixel's track ``j`` (P,), the
    depression of its window's upper edge ``tau_top`` (P,) by its last sample: then the pixel's window
    ends within the sweep, and more samples beyond would not change what it sees."""
    return bool((m[:, -1].index_select(0, j) <= tau_top.detach()).all())


def visible_samples(m: torch.Tensor, dim: int = -1, window: tuple[torch.Tensor, torch.Tensor] | None = None) -> torch.Tensor:
    """The samples that bound a visible element (m[k] > m[k + 1] on either side along ``dim``, the samples'
    axis: -1 for m (nt, ns), 0 for its transpose), the only ones :func:`visible_average` and
    :func:`centre_element` read (a hidden element spans no depression); bool of m's shape, contiguous.

    ``window`` = (lo, hi), each track's depressions (tangents) that its pixels' windows span (broadcasting
    against m along the tracks' axis, e.g. (nt, 1) for m (nt, ns)): only the visible elements whose
    depressions [m[k + 1], m[k]] meet [lo, hi]. The others lie before every window of their track or
    beyond it: they enter a pixel's average only through the cumulative sum's part before its window,
    which cancels (their values may be anything finite, e.g. 0, at float rounding)."""
    n = m.shape[dim]
    near, far = m.narrow(dim, 0, n - 1), m.narrow(dim, 1, n - 1)
    span = near > far
    if window is not None:
        span &= (far <= window[1]) & (near >= window[0])
    vis = torch.zeros(m.shape, dtype=torch.bool, device=m.device)
    vis.narrow(dim, 0, n - 1).copy_(span)
    vis.narrow(dim, 1, n - 1).logical_or_(span)
    return vis


def flat_nonzero(mask: torch.Tensor) -> torch.Tensor:
    """The indices (int64) of the True elements of a bool tensor, flattened in order: numpy's on the CPU
    (10–20× faster than ``torch.nonzero`` there), torch's elsewhere."""
    flat = mask.reshape(-1)
    if flat.device.type == "cpu":
        return torch.from_numpy(np.flatnonzero(flat.numpy())).to(torch.int64)
    return flat.nonzero().squeeze(1)


def read_at(index: torch.Tensor, values: torch.Tensor, at: torch.Tensor) -> torch.Tensor:
    """A quantity known at some flat indices, read at others: ``values`` (N,) at the ascending flat indices
    ``index`` (N,), read at ``at`` (any shape), 0 where ``at`` is not among them: what the dense array that
    holds ``values`` at ``index`` and 0 elsewhere gives at ``at``, without that array (one binary search
    per read)."""
    if index.numel() == 0:
        return values.new_zeros(at.shape)
    pos = torch.searchsorted(index, at.detach()).clamp_(max=index.numel() - 1)
    found = index.index_select(0, pos.reshape(-1)).reshape(at.shape) == at
    got = values.index_select(0, pos.reshape(-1)).reshape(at.shape)
    return torch.where(found, got, torch.zeros_like(got))


def nonzero_2d(mask: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
    """(flat, row, col): the True elements of a 2-D bool tensor (R, W) in row-major order, as flat indices
    (row · W + col) and as rows and columns, int64 (:func:`flat_nonzero`; on the CPU the rows and columns
    from numpy's ``divmod``, faster there than torch's integer division)."""
    flat, w = flat_nonzero(mask), mask.shape[1]
    if flat.device.type == "cpu":
        row, col = np.divmod(flat.numpy(), w)
        return flat, torch.from_numpy(row), torch.from_numpy(col)
    row = torch.div(flat, w, rounding_mode="floor")
    return flat, row, flat - row * w


def pixel_windows(tan_g: torch.Tensor, ifov: float) -> tuple[torch.Tensor, torch.Tensor]:
    """(τ_top, τ_bottom): the depressions (tangents) of the upper and lower edges of pixels whose centre
    ray has depression ``tan_g``, δ = ``ifov`` [rad] tall."""
    g = torch.atan(tan_g)
    return torch.tan(g - 0.5 * ifov), torch.tan((g + 0.5 * ifov).clamp(max=0.5 * math.pi - 1e-6))


def _first_below(m: torch.Tensor, j: torch.Tensor, *taus: torch.Tensor) -> list[torch.Tensor]:
    """For each ray (track j, depression τ) of each set ``taus`` (P,): the first sample index k with
    m[j, k] ≤ τ (ns if none); m (nt, ns) non-increasing along k. One batched search for all the sets:
    each track's rays padded to a row."""
    nt, n = m.shape[0], len(taus)
    order = torch.argsort(j, stable=True)
    js = j[order]
    counts = torch.bincount(js, minlength=nt)
    starts = torch.cumsum(counts, 0) - counts
    rank = torch.arange(js.numel(), device=j.device) - starts[js]
    tau = torch.stack([t.detach() for t in taus], 1)  # (P, n)
    vals = torch.full((nt, int(counts.max()), n), -math.inf, dtype=tau.dtype, device=tau.device)
    vals[js, rank] = -tau[order]
    k = torch.searchsorted(-m.contiguous(), vals.reshape(nt, -1)).reshape(vals.shape)  # first k: −m[k] ≥ −τ
    out = torch.empty((js.numel(), n), dtype=k.dtype, device=k.device)
    out[order] = k[js, rank]
    return list(out.unbind(1))


def _element_sums(m: torch.Tensor, values: torch.Tensor, out: torch.Tensor, tracks: int = 4) -> torch.Tensor:
    """F (C, nt, ns) into ``out`` (which may be ``values`` itself): F[..., k] = Σ_{e<k} span_e el_e, with
    el_e = (v_e + v_e+1)/2 the element's mean and span_e = m_e − m_e+1 the depressions it covers (0 where
    hidden), one cumulative sum over a leading 0 (0 + 0 = 0 exactly); a few ``tracks`` at a time, so
    that the products stay in cache and no second array of the values' size is needed."""
    nt = values.shape[1]
    for a in range(0, nt, tracks):
        s = slice(a, a + tracks)
        prod = torch.add(values[:, s, 1:], values[:, s, :-1]).mul_(0.5).mul_((m[s, :-1] - m[s, 1:]).to(values.dtype))
        out[:, s, 0] = 0.0
        out[:, s, 1:] = prod
        out[:, s].cumsum_(-1)
    return out


def _window_average(m: torch.Tensor, values: torch.Tensor, j: torch.Tensor, tau_top: torch.Tensor,
                    tau_bottom: torch.Tensor, k_top: torch.Tensor, k_bottom: torch.Tensor,
                    overwrite: bool = False) -> torch.Tensor:
    """:func:`visible_average` given the first samples below each window's edges (:func:`_first_below`),
    from the cumulative sums F of :func:`_element_sums`; ``overwrite``: F takes the buffer of ``values``
    (without a graph), whose elements' means at the windows' edges are read before."""
    C, nt, ns = values.shape
    m_ = m.reshape(-1)  # (read by flat index_select: faster on the CPU)
    edges = [(tau, k, j * ns + (k - 1).clamp(0, ns - 2)) for tau, k in ((tau_top, k_top), (tau_bottom, k_bottom))]
    if torch.is_grad_enabled() and (values.requires_grad or m.requires_grad):
        el = 0.5 * (values[..., 1:] + values[..., :-1])  # (C, nt, ns − 1)
        span = (m[:, :-1] - m[:, 1:]).to(values.dtype)
        F = torch.cat([torch.zeros_like(el[..., :1]), torch.cumsum(span * el, -1)], -1)
        els = [el.reshape(C, -1).index_select(1, at - j) for _, _, at in edges]  # (flat (j, e))
    else:  # (the same two operations at the edges only)
        v_ = values.reshape(C, -1)
        els = [0.5 * (v_.index_select(1, at + 1) + v_.index_select(1, at)) for _, _, at in edges]
        own = overwrite and values.is_contiguous()  # (an expanded tensor shares its elements)
        F = _element_sums(m, values, values if own else values.new_empty(values.shape))
    F_ = F.reshape(C, -1)
    parts = []
    for (tau, k, at), el in zip(edges, els):  # F(τ): ∫ over the visible depressions ≥ τ
        inside = (k > 0) & (k < ns)  # element e = k − 1 holds τ (m[e + 1] ≤ τ ≤ m[e])
        part = F_.index_select(1, at) + (m_.index_select(0, at).to(values.dtype) - tau) * el
        parts.append(torch.where(inside, part, torch.where(k >= ns, F_.index_select(1, j * ns + ns - 1),
                                                           torch.zeros_like(part))))
    return (parts[0] - parts[1]) / (tau_bottom - tau_top)


def visible_average(m: torch.Tensor, values: torch.Tensor, j: torch.Tensor, tau_top: torch.Tensor,
                    tau_bottom: torch.Tensor) -> torch.Tensor:
    """The angular average over each pixel's depression window [τ_top, τ_bottom] of a quantity along its
    track's visible surface, (C, P).

    ``values`` (C, nt, ns): the quantity at the samples (the element between samples k and k + 1 takes
    their mean); ``m`` (nt, ns) the running minimum of :func:`sweep_envelope`; ``j`` (P,) each pixel's
    track. Parts of the window beyond the sweep count as 0."""
    k_top, k_bottom = _first_below(m, j, tau_top, tau_bottom)
    return _window_average(m, values, j, tau_top, tau_bottom, k_top, k_bottom)


def centre_element(m: torch.Tensor, j: torch.Tensor, tau: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
    """The sample index k (P,) of the first hit of each pixel's centre ray (the sample at the end of the
    element it meets, clamped into the sweep), and whether it meets the surface within the sweep."""
    (k,) = _first_below(m, j, tau)
    ns = m.shape[1]
    return k.clamp(1, ns - 1), (k > 0) & (k < ns)


def pixel_hits(m: torch.Tensor, values: torch.Tensor, j: torch.Tensor, tau_top: torch.Tensor, tau_bottom: torch.Tensor,
               tau: torch.Tensor, overwrite: bool = False) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
    """:func:`visible_average` over the windows [τ_top, τ_bottom] and :func:`centre_element` of the centre
    rays τ together, from one search: (average (C, P), k (P,), hit (P,)). ``overwrite``: ``values`` is not
    needed afterwards, its buffer may hold the cumulative sums (where no graph is kept)."""
    k_top, k_bottom, k = _first_below(m, j, tau_top, tau_bottom, tau)
    ns = m.shape[1]
    return (_window_average(m, values, j, tau_top, tau_bottom, k_top, k_bottom, overwrite), k.clamp(1, ns - 1),
            (k > 0) & (k < ns))

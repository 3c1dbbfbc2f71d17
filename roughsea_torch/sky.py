"""Downwelling sky radiance R_s as a function of the zenith angle of the reflected ray (Eq. 10).

Three forms are accepted wherever a ``sky`` argument appears:

- a callable ``f(cos_zenith) -> radiance`` (elementwise, shape preserving) [W m⁻² sr⁻¹];
- a table: a :class:`TabulatedSky`, or a pair ``(zenith [rad], radiance)`` of 1-d arrays/tensors;
- a constant: a float, or a tensor broadcastable against the batch of view directions.

Named atmospheres (LOWTRAN7 tables) come from :func:`roughsea_torch.atmosphere.load_sky`, and
:func:`roughsea_torch.atmosphere.as_sky` turns any of these forms (or an atmosphere's name) into a
callable; this module stays below the atmospheres and never imports them.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import torch

from ._lookup import bucket_grid, next_nodes

__all__ = ["TabulatedSky", "ConstantSky", "select_sky", "pchip_derivatives"]


def pchip_derivatives(x: torch.Tensor, y: torch.Tensor) -> torch.Tensor:
    """Node derivatives of the monotone piecewise-cubic Hermite interpolant (Fritsch–Butland).

    The same rule as ``scipy.interpolate.PchipInterpolator``: weighted harmonic mean of the
    neighbouring secant slopes inside, zero at local extrema, the non-centred three-point
    formula (limited to keep monotonicity) at the ends. ``y`` may carry leading batch dims.
    """
    h = x[1:] - x[:-1]
    m = (y[..., 1:] - y[..., :-1]) / h
    if x.numel() == 2:
        return torch.cat([m, m], dim=-1)
    m0, m1 = m[..., :-1], m[..., 1:]
    w1 = 2.0 * h[1:] + h[:-1]
    w2 = h[1:] + 2.0 * h[:-1]
    same = (torch.sign(m0) == torch.sign(m1)) & (m0 != 0) & (m1 != 0)
    m0s = torch.where(same, m0, torch.ones_like(m0))
    m1s = torch.where(same, m1, torch.ones_like(m1))
    inner = torch.where(same, (w1 + w2) / (w1 / m0s + w2 / m1s), torch.zeros_like(m0))

    def edge(h0, h1, ma, mb):
        d = ((2.0 * h0 + h1) * ma - h0 * mb) / (h0 + h1)
        d = torch.where(torch.sign(d) != torch.sign(ma), torch.zeros_like(d), d)
        clip = (torch.sign(ma) != torch.sign(mb)) & (d.abs() > 3.0 * ma.abs())
        return torch.where(clip, 3.0 * ma, d)

    d_first = edge(h[0], h[1], m[..., :1], m[..., 1:2])
    d_last = edge(h[-1], h[-2], m[..., -1:], m[..., -2:-1])
    return torch.cat([d_first, inner, d_last], dim=-1)


class TabulatedSky:
    """Sky radiance tabulated over zenith angle, interpolated by PCHIP in the zenith angle.

    Args:
        zenith: (Nz,) zenith angles [rad], strictly ascending, within [0, π/2].
        radiance: (..., Nz) band radiance [W m⁻² sr⁻¹]; leading dims (one table per sea state)
            broadcast against the leading (batch) dims of the query.

    Calling it with ``cos_zenith`` interpolates; outside the table range the end values are held.
    With a batched table the query must have shape (*batch, N): the last dim runs over
    directions of one batch element. The interpolant is C¹ and monotone where the data are
    (``scipy.interpolate.PchipInterpolator`` gives the same curve), so it never invents the
    overshoot a cubic spline adds next to the steep rise at the horizon.

    Example:
        >>> sky = TabulatedSky(torch.tensor([0.0, 1.0, 1.5707963]), torch.tensor([11.0, 14.0, 40.0]))
        >>> round(float(sky(torch.tensor(1.0))), 4)
        11.0
    """

    def __init__(self, zenith: Any, radiance: Any):
        z = torch.as_tensor(zenith)
        r = torch.as_tensor(radiance)
        if not z.is_floating_point():
            z = z.double()
        if not r.is_floating_point():
            r = r.to(z.dtype)
        if z.ndim != 1 or z.numel() < 2:
            raise ValueError(f"zenith must be a 1-d table of at least 2 angles; got shape {tuple(z.shape)}")
        if r.shape[-1] != z.numel():
            raise ValueError(
                f"radiance must have the table size {z.numel()} as its last dim; got shape {tuple(r.shape)}"
            )
        zd = z.detach()
        if torch.isnan(zd).any() or (zd[1:] <= zd[:-1]).any() or zd[0] < 0 or zd[-1] > math.pi / 2 + 1e-6:
            raise ValueError("zenith must be strictly ascending within [0, pi/2] rad")
        if torch.isnan(r.detach()).any() or (r.detach() < 0).any():
            raise ValueError("radiance must be finite and >= 0 (W m-2 sr-1)")
        self.zenith = z
        self.radiance = r
        self._cache: dict[tuple[torch.dtype, torch.device], tuple[torch.Tensor, ...]] = {}

    def _tables(self, dtype: torch.dtype, device: torch.device) -> tuple[torch.Tensor, ...]:
        """Per (dtype, device): the nodes z, radiance r, PCHIP slopes d, and for the lookup a
        uniform bucket grid over [z₀, z_end] (origin, 1/width) whose width is the smallest node
        spacing, so a bucket meets at most two intervals, with per bucket its first interval and
        where the next one starts (M, 2) (:mod:`roughsea_torch._lookup`); and per interval (of each
        row of a batched table) its start, 1/width and the power-form coefficients of the cubic in
        t ∈ [0, 1], (rows · (N−1), 6) (one gather a query)."""
        key = (dtype, device)
        if self.radiance.requires_grad or key not in self._cache:
            z64 = self.zenith.detach().double().cpu()
            z_0, inv_width, start = bucket_grid(z64)
            split = next_nodes(z64, start)  # a query at or past it is in the next interval
            z = self.zenith.to(dtype=dtype, device=device)
            r = self.radiance.to(dtype=dtype, device=device)
            d = pchip_derivatives(z, r)
            bucket = (torch.tensor(z_0, dtype=dtype, device=device),
                      torch.tensor(inv_width, dtype=dtype, device=device),
                      torch.stack([start.to(dtype), split.to(dtype)], -1).to(device))
            # y(t) = y0 + t (h d0 + t (3Δ − h(2 d0 + d1) + t (−2Δ + h(d0 + d1)))), per interval (and per
            # table row of a batched sky: (rows · (N − 1), 6), row-major)
            h = z[1:] - z[:-1]
            dy = r[..., 1:] - r[..., :-1]
            d0, d1 = d[..., :-1], d[..., 1:]
            coef = torch.stack([z[:-1].expand_as(dy), (1.0 / h).expand_as(dy), r[..., :-1], h * d0,
                                3 * dy - h * (2 * d0 + d1), -2 * dy + h * (d0 + d1)], -1).reshape(-1, 6)
            out = (z, r, d, *bucket, coef)
            if self.radiance.requires_grad:
                return out
            self._cache[key] = out
        return self._cache[key]

    def __call__(self, cos_zenith: torch.Tensor) -> torch.Tensor:
        cz = cos_zenith
        z, r, d, z0, inv_w, bucket, coef = self._tables(cz.dtype, cz.device)
        # acos has an infinite slope at cos = 1: hold the query a rounding step away from it.
        one = 1.0 - torch.finfo(cz.dtype).eps
        theta = torch.acos(cz.clamp(0.0, one)).clamp(z[0], z[-1])
        # interval index: the bucket's first interval, plus one where θ is at or past the next
        # node (one gather of (first, next node) and a compare instead of a binary search)
        # (index_select on flat indices: advanced indexing costs ~3-4x more on the CPU)
        th = theta.detach()
        kb = ((th - z0) * inv_w).long().clamp_(0, bucket.shape[0] - 1).reshape(-1)
        sb = bucket.index_select(0, kb).reshape(*th.shape, 2)
        i = (sb[..., 0] + (th >= sb[..., 1]).to(th.dtype)).long().clamp_(max=z.numel() - 2)
        if r.ndim > 1:  # a batched sky: the query's interval in its own row of the table
            lead = torch.broadcast_shapes(r.shape[:-1], i.shape[:-1])
            shape = (*lead, i.shape[-1])
            rows = torch.arange(int(np.prod(r.shape[:-1])), device=i.device).reshape(*r.shape[:-1], 1)
            i = (rows * (z.numel() - 1)).expand(shape) + i.expand(shape)
            theta = theta.expand(shape)
        # one gather of the interval's start, 1/width and four coefficients
        c = coef.index_select(0, i.reshape(-1)).reshape(*i.shape, coef.shape[-1])
        t = (theta - c[..., 0]) * c[..., 1]
        return c[..., 2] + t * (c[..., 3] + t * (c[..., 4] + t * c[..., 5]))

    def with_radiance(self, radiance: torch.Tensor) -> TabulatedSky:
        """The same zenith nodes with other (already validated) radiance rows."""
        out = TabulatedSky.__new__(TabulatedSky)
        out.zenith, out.radiance, out._cache = self.zenith, radiance, {}
        return out

    def __repr__(self) -> str:
        return f"TabulatedSky(n_zenith={self.zenith.numel()}, batch={tuple(self.radiance.shape[:-1])})"


class ConstantSky:
    """Sky radiance independent of direction [W m⁻² sr⁻¹]; a float or a per-sea-state tensor."""

    def __init__(self, radiance: Any):
        self.radiance = radiance

    def __call__(self, cos_zenith: torch.Tensor) -> torch.Tensor:
        r = torch.as_tensor(self.radiance, dtype=cos_zenith.dtype, device=cos_zenith.device)
        if r.ndim:
            r = r.unsqueeze(-1)
        return r.expand(torch.broadcast_shapes(r.shape, cos_zenith.shape))

    def __repr__(self) -> str:
        return f"ConstantSky({self.radiance!r})"


def select_sky(sky: Any, index: Any) -> Any:
    """The sky of some sea states: rows ``index`` of a batched table or constant whose leading dim
    runs over the (flattened) batch; a shared sky is returned as it is."""
    if isinstance(sky, TabulatedSky) and sky.radiance.ndim > 1:
        return sky.with_radiance(sky.radiance[index])
    if isinstance(sky, ConstantSky) and torch.as_tensor(sky.radiance).ndim > 0:
        return ConstantSky(torch.as_tensor(sky.radiance)[index])
    return sky

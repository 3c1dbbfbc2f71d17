"""Spectral resampling of the table method: Chebyshev–Lobatto nodes on [−1, 1] and the barycentric
matrices that evaluate their interpolating polynomial on a fine uniform grid (Berrut & Trefethen,
*Barycentric Lagrange interpolation*, SIAM Review 46(3), 2004).

A table's model values at n nodes become its fine rows or columns by one matrix product; the fine
grid overhangs the node interval by ``FINE_OVERHANG`` cells so that ``grid_sample`` never reads the
clamped border for a pixel inside the interval.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np
import torch

from .settings import FINE_OVERHANG

__all__ = ["lobatto_interp", "barycentric"]


@lru_cache(maxsize=32)
def lobatto_interp(n: int, m: int) -> tuple[np.ndarray, np.ndarray, float]:
    """Chebyshev–Lobatto nodes on [−1, 1] (ascending), the barycentric matrix that evaluates the
    interpolant on m uniform points of [−1 − e, 1 + e], and e.

    The fine grid overhangs the node interval by ``FINE_OVERHANG`` cells so that ``grid_sample`` never
    reads the clamped border for a pixel inside the interval; the overhang is the interpolant
    continued a hair outside [−1, 1].
    """
    if n == 1:
        return np.zeros(1), np.ones((m, 1)), 0.0
    e = 2.0 * FINE_OVERHANG / (m - 1 - 2 * FINE_OVERHANG)
    x = np.cos(np.pi * np.arange(n) / (n - 1))[::-1].copy()
    w = (-1.0) ** np.arange(n)
    w[0] *= 0.5
    w[-1] *= 0.5
    y = np.linspace(-1.0 - e, 1.0 + e, m)
    diff = y[:, None] - x[None, :]
    exact = np.isclose(diff, 0.0, atol=1e-15)
    diff[exact] = 1.0
    L = w / diff
    L = L / L.sum(1, keepdims=True)
    rows = exact.any(1)
    L[rows] = exact[rows].astype(float)
    return x, L, e


def barycentric(x: np.ndarray, t: torch.Tensor) -> torch.Tensor:
    """Matrix (..., m, n) evaluating the interpolant on the Chebyshev–Lobatto nodes ``x`` (n,) at the
    points ``t`` (..., m) of the node coordinate (the batched form of :func:`lobatto_interp`)."""
    n = len(x)
    w = (-1.0) ** np.arange(n)
    w[0] *= 0.5
    w[-1] *= 0.5
    xt = torch.as_tensor(x, dtype=t.dtype, device=t.device)
    wt = torch.as_tensor(w, dtype=t.dtype, device=t.device)
    diff = t[..., None] - xt
    exact = diff.abs() < 1e-15
    L = wt / torch.where(exact, torch.ones_like(diff), diff)
    L = L / L.sum(-1, keepdim=True)
    hit = exact.any(-1, keepdim=True)
    return torch.where(hit, exact.to(L.dtype), L)


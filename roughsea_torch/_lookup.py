"""Interval lookup in a table of ascending nodes by a uniform bucket grid: one gather and one compare
a query, where a binary search (``torch.searchsorted``) takes ~log₂ N dependent steps.

The buckets are no wider than the narrowest interval, so a bucket meets at most two intervals: a
query lies in its bucket's first interval ``start`` or the one after, and one compare with the
node that starts the next interval decides. Used by the sky tables (:mod:`roughsea_torch.sky`,
nodes in zenith angle) and the brightness-temperature table (:mod:`roughsea_torch.radiometry`,
buckets in log L).
"""

from __future__ import annotations

import math

import torch

__all__ = ["bucket_grid", "next_nodes"]


def bucket_grid(x: torch.Tensor) -> tuple[float, float, torch.Tensor]:
    """For ascending nodes ``x`` (1-D, float64, at least 2): (origin x₀, 1/width, start), with
    ``start[k]`` (int64) the interval [x_i, x_{i+1}] holding the left edge of bucket k; the bucket
    of a query q is ``floor((q − x₀)/width)`` clamped to the grid."""
    width = float((x[1:] - x[:-1]).min()) * (1.0 - 1e-6)
    nb = int(math.ceil(float(x[-1] - x[0]) / width)) + 1
    edges = x[0] + width * torch.arange(nb, dtype=torch.float64, device=x.device)
    start = (torch.searchsorted(x, edges, right=True) - 1).clamp(0, x.numel() - 2)
    return float(x[0]), 1.0 / width, start


def next_nodes(values: torch.Tensor, start: torch.Tensor) -> torch.Tensor:
    """Per bucket, the node value (in ``values``' own monotone coordinate) from which a query lies in
    the interval after ``start``: ``values[start + 1]``, +inf where ``start`` is the last interval."""
    n = values.numel()
    return torch.where(start + 1 <= n - 2, values[(start + 1).clamp_max(n - 1)], math.inf)

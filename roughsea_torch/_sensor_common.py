"""Argument checks and the straight-through rounding shared by the sensor model's stages
(:mod:`roughsea_torch.sensor`, :mod:`roughsea_torch.sensor_noise`).

Each check returns the checked value or raises ``ValueError`` naming the argument.
"""

from __future__ import annotations

import math
from typing import Any

import torch

from ._validation import check_finite_range

__all__ = ["check_image", "check_int", "check_pair", "round_ste"]


def check_image(name: str, x: Any, allow_integer: bool = False) -> torch.Tensor:
    """``x`` as a (B, C, H, W) float32/float64 tensor, or ``ValueError`` naming ``name``.

    With ``allow_integer``, integer tensors (counts straight from a camera) are converted to the
    default dtype."""
    if not isinstance(x, torch.Tensor):
        raise ValueError(f"{name} must be a torch.Tensor of shape (B, C, H, W); got {type(x).__name__}")
    if x.ndim != 4:
        raise ValueError(f"{name} must have shape (B, C, H, W); got shape {tuple(x.shape)}")
    if allow_integer and not (x.dtype.is_floating_point or x.dtype.is_complex):
        x = x.to(torch.get_default_dtype())
    if x.dtype not in (torch.float32, torch.float64):
        raise ValueError(f"{name} must be float32 or float64; got {x.dtype}")
    return x


def check_int(name: str, x: Any, lo: int, hi: float = math.inf) -> int:
    if isinstance(x, bool) or not isinstance(x, int):
        raise ValueError(f"{name} must be an integer; got {x!r}")
    check_finite_range(name, x, lo, hi)
    return int(x)


def check_pair(name: str, x: Any, lo: float, unit: str, lo_open: bool = False) -> tuple[float, float]:
    try:
        a, b = x
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a (low, high) pair [{unit}]; got {x!r}") from None
    check_finite_range(f"{name}[0]", a, lo, math.inf, lo_open=lo_open, hi_open=True, unit=unit)
    check_finite_range(f"{name}[1]", b, lo, math.inf, lo_open=lo_open, hi_open=True, unit=unit)
    a, b = float(a), float(b)
    if not a < b:
        raise ValueError(f"{name} must satisfy low < high; got ({a:g}, {b:g}) {unit}")
    return a, b



def round_ste(x: torch.Tensor) -> torch.Tensor:
    """round(x) forward, identity backward (straight-through estimator)."""
    return x + (torch.round(x) - x).detach()


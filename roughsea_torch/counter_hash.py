"""Counter-based random numbers: a hash of an integer key, and a uniform in (0, 1) from its bits.

Used where a draw must be a function of (seed, place, time) alone, so that an image of a batch is
bitwise the image rendered alone and a clip is coherent in time (the glitter's latent,
:mod:`roughsea_torch.glitter`; the foam's streak field, :mod:`roughsea_torch.foam_streaks`).

Source: the finalizer of splitmix64 (Steele, Lea & Flood 2014, "Fast splittable pseudorandom number
generators", OOPSLA; constants as in Vigna's public-domain ``splitmix64.c``).
"""

from __future__ import annotations

import torch

__all__ = ["splitmix64", "bits_uniform"]


def splitmix64(x: torch.Tensor) -> torch.Tensor:
    """splitmix64's finalizer on int64 tensors (wrapping arithmetic; logical shifts by masking)."""
    def shr(v: torch.Tensor, s: int) -> torch.Tensor:
        return (v >> s) & ((1 << (64 - s)) - 1)
    x = x + (-7046029254386353131)  # 0x9E3779B97F4A7C15 as int64
    x = (x ^ shr(x, 30)) * (-4658895280553007687)  # 0xBF58476D1CE4E5B9
    x = (x ^ shr(x, 27)) * (-7723592293110705685)  # 0x94D049BB133111EB
    return x ^ shr(x, 31)


def bits_uniform(h: torch.Tensor) -> torch.Tensor:
    """A float64 in (0, 1) from the top 52 bits of the int64 ``h`` (already a hash)."""
    return (((h >> 12) & ((1 << 52) - 1)).to(torch.float64) + 0.5) * (2.0 ** -52)

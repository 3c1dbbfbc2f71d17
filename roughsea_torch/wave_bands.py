"""The band layout of a synthesized sea surface, and the window that fades a band out with the footprint.

A :class:`~roughsea_torch.waves.WaveField` splits the Fourier modes of the sea surface into bands
of wavenumber (octaves by default), each synthesized on its own periodic tile (:class:`WaveBands`),
so that each band can be faded out where a pixel footprint no longer resolves it
(:func:`band_window`; the two-scale principle).

Every public name here is also importable from :mod:`roughsea_torch.waves`.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from numbers import Integral

import torch

__all__ = ["WaveBands", "WINDOW_LO", "WINDOW_HI", "GOLDEN_ANGLE", "band_window"]

GOLDEN_ANGLE = math.pi * (3.0 - math.sqrt(5.0))  # [rad] 137.5°: band o's tile is turned by o times this


@dataclass(frozen=True)
class WaveBands:
    """Layout of the synthesized bands: wavenumber edges and the periodic tile of each band.

    Band o holds the Fourier modes with k_o⁻ ≤ |k| < k_o⁺ (``k_edges[o]``, ``k_edges[o + 1]``). It is
    synthesized on its own periodic tile of ``tile_size`` × ``tile_size`` texels whose fundamental
    Δk_o = k_o⁻ / ``inner_radius``, i.e. tile length L_o = 2π ``inner_radius`` / k_o⁻; the band's
    annulus then spans ``inner_radius`` … ``inner_radius`` · k_o⁺/k_o⁻ fundamentals.

    Defaults and why:
        - ``k_edges`` = 2⁻⁸ … 2⁸ rad m⁻¹: 16 octave bands, wavelengths 2.45 cm … 1608 m (a 20 m s⁻¹
          fully developed sea peaks at 363 m, 30 m s⁻¹ at 816 m).
        - ``inner_radius`` = 4: an octave band holds the lattice points 4 ≤ |k|/Δk < 8, about
          π (8² − 4²) ≈ 150 modes (75 independent complex amplitudes and their conjugates).
        - ``tile_rotation`` = the golden angle π(3 − √5) ≈ 137.5°: band o's tile is turned by o times it
          about the vertical (``tile_angle``). Without it every tile is aligned with the world's x and y
          axes and, the lengths halving, the short bands repeat *together*: their sum repeats exactly
          every few metres along x and y, which a camera looking along an axis sees as dotted
          streaks. Turned by multiples of an angle that is an irrational fraction of a turn, no two
          bands share a lattice direction, so no direction repeats more than one band's pattern.
          ``tile_rotation=0`` gives the aligned tiles (the realizations made before 2026-11-27).
        - ``tile_size`` = 128: the highest mode of a band is 8 Δk = 2π/16 per texel, 16 texels per
          wavelength. Bilinear interpolation (see :class:`~roughsea_torch.waves.WaveField`) then
          keeps, averaged over positions, a fraction (2 + cos θx)(2 + cos θy)/9 of a mode's variance
          (θ = k·texel ≤ 0.39 here, ≥ 0.95); :meth:`~roughsea_torch.waves.WaveField.band_covariance`
          includes that factor exactly. A band's tile costs (N + 1)² × 3 channels × 4 bytes = 0.2 MB
          in float32, 3.2 MB for the 16 bands.

    Tile lengths differ from band to band (L_o = 6434 m … 0.196 m by halves) and the tiles are turned
    by different angles, so no pattern repeats across bands; a single band repeats with its own period
    of 4–8 of its wavelengths along its tile's axes. A tile's texel (row i, column j) lies at tile
    coordinates (v, u) = (i, j) L_o / N, i.e. at world x = u cos α_o − v sin α_o, y = u sin α_o +
    v cos α_o (α_o = ``tile_angle[o]``); :meth:`tile_units` maps world points to tile periods.

    Example:
        >>> b = WaveBands()
        >>> b.n_bands, round(b.tile_length[0], 1), round(b.tile_length[-1], 4)
        (16, 6434.0, 0.1963)
    """

    k_edges: tuple[float, ...] = tuple(2.0**e for e in range(-8, 9))
    tile_size: int = 128
    inner_radius: float = 4.0
    tile_rotation: float = GOLDEN_ANGLE

    def __post_init__(self) -> None:
        edges = tuple(float(e) for e in self.k_edges)
        object.__setattr__(self, "k_edges", edges)
        if len(edges) < 2:
            raise ValueError("k_edges: need at least 2 edges (one band) [rad/m]")
        if not all(math.isfinite(e) and e > 0 for e in edges):
            raise ValueError(f"k_edges must be finite and > 0 rad/m; got {edges}")
        if not all(b > a for a, b in zip(edges[:-1], edges[1:])):
            raise ValueError(f"k_edges must be strictly increasing; got {edges}")
        if isinstance(self.tile_size, bool) or not isinstance(self.tile_size, Integral) or self.tile_size < 8 or self.tile_size % 2:
            raise ValueError(f"tile_size must be an even integer ≥ 8; got {self.tile_size!r}")
        object.__setattr__(self, "tile_size", int(self.tile_size))
        if not (math.isfinite(self.inner_radius) and self.inner_radius > 0):
            raise ValueError(f"inner_radius must be finite and > 0 fundamentals; got {self.inner_radius!r}")
        if isinstance(self.tile_rotation, bool) or not isinstance(self.tile_rotation, (int, float)) \
                or not math.isfinite(self.tile_rotation) or abs(self.tile_rotation) > 2.0 * math.pi:
            raise ValueError(f"tile_rotation must be a finite angle in [-2π, 2π] rad; got {self.tile_rotation!r}")
        object.__setattr__(self, "tile_rotation", float(self.tile_rotation))
        for o in range(self.n_bands):
            outer = self.inner_radius * edges[o + 1] / edges[o]
            if outer > self.tile_size / 4:
                raise ValueError(
                    f"k_edges/inner_radius: band {o} reaches {outer:g} fundamentals of its tile; keep it "
                    f"≤ tile_size/4 = {self.tile_size / 4:g} (half the Nyquist index) so bilinear "
                    "interpolation stays accurate"
                )

    @classmethod
    def octaves(cls, k_min: float, n_bands: int, *, tile_size: int = 128, inner_radius: float = 4.0,
                tile_rotation: float = GOLDEN_ANGLE) -> WaveBands:
        """``n_bands`` octave bands starting at ``k_min`` [rad m⁻¹]."""
        return cls(tuple(float(k_min) * 2.0**o for o in range(int(n_bands) + 1)), tile_size, inner_radius,
                   tile_rotation)

    @property
    def n_bands(self) -> int:
        return len(self.k_edges) - 1

    @property
    def band_wavenumber(self) -> tuple[float, ...]:
        """Centre (geometric mean) wavenumber of each band [rad m⁻¹]."""
        return tuple(math.sqrt(a * b) for a, b in zip(self.k_edges[:-1], self.k_edges[1:]))

    @property
    def fundamental(self) -> tuple[float, ...]:
        """Δk_o, the lattice spacing of each band's tile [rad m⁻¹]."""
        return tuple(a / self.inner_radius for a in self.k_edges[:-1])

    @property
    def tile_length(self) -> tuple[float, ...]:
        """L_o = 2π/Δk_o, the period of each band's tile [m]."""
        return tuple(2.0 * math.pi / dk for dk in self.fundamental)

    @property
    def tile_angle(self) -> tuple[float, ...]:
        """α_o = o · ``tile_rotation`` mod 2π, the angle [rad] from the world x axis to band o's tile axis u
        (counter-clockwise seen from above)."""
        return tuple(math.remainder(o * self.tile_rotation, 2.0 * math.pi) for o in range(self.n_bands))

    def tile_units(self, o: int, xy: torch.Tensor) -> torch.Tensor:
        """World points ``xy`` (..., 2) = (x, y) [m] in band ``o``'s tile periods: (u, v) / L_o with u = x cos α_o
        + y sin α_o, v = −x sin α_o + y cos α_o (``xy / L_o`` exactly for an unturned tile). Whole numbers
        are the tile's corners; the fractional part is where the periodic tile is read."""
        length = self.tile_length[o]
        alpha = self.tile_angle[o]
        if alpha == 0.0:
            return xy * (1.0 / length)
        c, s = math.cos(alpha) / length, math.sin(alpha) / length
        # one multiplication or addition per kernel, each rounded once whatever the kernel's path (vector lanes
        # or scalar tail), so a point's value does not depend on how it was batched; a 2×2 matmul costs about
        # twice as much, a complex product's scalar tail rounds differently from its lanes
        x, y = xy[..., 0], xy[..., 1]
        if xy.requires_grad:
            return torch.stack((x * c + y * s, y * c - x * s), -1)
        out = torch.empty_like(xy)
        u, v = out[..., 0], out[..., 1]
        torch.mul(x, c, out=u)
        u.add_(y * s)
        torch.mul(y, c, out=v)
        v.sub_(x * s)
        return out

    @property
    def max_index(self) -> int:
        """Largest |lattice index| any band uses (the compact spectrum is (2M+1) × (M+1))."""
        return max(
            int(math.ceil(self.inner_radius * b / a)) for a, b in zip(self.k_edges[:-1], self.k_edges[1:])
        )


WINDOW_LO = 1.0 / math.sqrt(2.0)  # u = k_o f / π below which a band is fully resolved (w = 1)
WINDOW_HI = math.sqrt(2.0)  # u above which it is fully unresolved (w = 0)


def band_window(footprint: torch.Tensor, k_centre: float | Sequence[float]) -> torch.Tensor:
    """The resolved-part window of a band at a pixel footprint f [m] (a tensor, any shape):
    w = 1 − smoothstep(t), t = clamp((u − u₀)/(u₁ − u₀), 0, 1), u = k_o f / π, u₀ = ``WINDOW_LO``,
    u₁ = ``WINDOW_HI`` (:meth:`~roughsea_torch.waves.WaveField.band_weights`), for one band's centre
    k_o [rad m⁻¹], or for a sequence of them (one more trailing axis, a band each)."""
    if isinstance(k_centre, (list, tuple)):
        scale = torch.tensor([k / math.pi / (WINDOW_HI - WINDOW_LO) for k in k_centre], dtype=footprint.dtype,
                             device=footprint.device)
        footprint = footprint[..., None]
    else:
        scale = k_centre / math.pi / (WINDOW_HI - WINDOW_LO)
    t = torch.clamp(footprint * scale - WINDOW_LO / (WINDOW_HI - WINDOW_LO), 0.0, 1.0)
    return 1.0 - t * t * (3.0 - 2.0 * t)

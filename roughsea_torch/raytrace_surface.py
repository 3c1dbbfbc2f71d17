"""The surface the brute-force ray tracer meets (:mod:`roughsea_torch.raytrace`) and its march.

- :class:`TracedSurface`: η(x, y, t) of a :class:`~roughsea_torch.waves.WaveField` realization's bands
  up to a wavenumber, read once per band from ``WaveField.sample`` and interpolated here, with exact
  bounds on its height and slope (a bilinear interpolant takes its extremes on its nodes, and its
  largest gradient at a cell's corner).
- :func:`march_first_hits`: rays stepped by the gap to the surface over a Lipschitz bound of its fall
  (J. C. Hart, *Sphere tracing: a geometric method for the antialiased ray tracing of implicit
  surfaces*, The Visual Computer 12(10), 527–545, 1996), the longest safe step over the bands' partial
  sums, then bisection: the first hit, never a later one.

Conventions: world frame right-handed, z up, sea level z = 0, metres.
"""

from __future__ import annotations

import math
from typing import Any, Callable, Protocol

import numpy as np
import torch

from .waves import WaveField

__all__ = ["Surface", "TracedSurface", "march_first_hits", "check_count", "check_positive"]


_WINDOW_FULL = 1.0 / math.sqrt(2.0)  # k_o f / π at and below which the field's band window is exactly 1


class Surface(Protocol):
    """What :func:`march_first_hits` traces: a height field with global bounds.

    Attributes:
        eta_max: (B,) tensor [m], ≥ |η| everywhere (per image).
        lipschitz: (B,) tensor [dimensionless], ≥ |∇η| everywhere.
        dtype, device: of the positions it takes.

    Calling it with x, y (B, P) [m] returns (η [m], s_x, s_y), each (B, P), s = −∇η.

    Optionally (a surface that is a sum of parts, as :class:`TracedSurface`), for sharper steps:
    ``partial_elevations(x, y)`` → (B, K, P) the partial sums η_{≤j} of its K parts (the last is η),
    with ``level_slack`` (B, K) [m] ≥ |η − η_{≤j}| and ``level_lipschitz`` (B, K) ≥ |∇η_{≤j}|.
    """

    eta_max: torch.Tensor
    lipschitz: torch.Tensor
    dtype: torch.dtype
    device: torch.device

    def __call__(self, x: torch.Tensor, y: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]: ...


# ---------------------------------------------------------------------------------------------
# The traced surface: a WaveField's bands up to k_max at one time
# ---------------------------------------------------------------------------------------------
class TracedSurface:
    """The bands of a :class:`WaveField` with upper edge ≤ ``k_max`` at time ``time_s``, as a
    :class:`Surface` with exact bounds.

    Args:
        field: the wave field (B images); its dtype is the dtype of the trace.
        time_s: time [s], float or (B,).
        k_max: largest traced wavenumber [rad m⁻¹], > 0 (``inf``: every band). A band is traced iff
            its upper edge ``field.bands.k_edges[o + 1]`` ≤ k_max. The bands must be octaves
            (the default layout) so that the field's window can select them exactly.

    Attributes:
        n_traced: number of traced bands (the lowest ones).
        footprint: a footprint [m] at which ``field.sample`` returns exactly the traced bands
            (None when every band is traced).
        traced_covariance: (B, 3) world-frame (var_x, var_y, cov_xy) of the traced slopes.
        eta_max: (B,) [m] and lipschitz: (B,) [dimensionless], bounds of |η| and |∇η|.
        level_slack: (B, K) [m], bounds of |η − η_{≤j}| (the bands above j); level_lipschitz: (B, K),
            bounds of |∇η_{≤j}| (:class:`Surface`, the march's sharper steps).
    """

    def __init__(self, field: WaveField, time_s: Any = 0.0, k_max: float = 64.0):
        if not isinstance(field, WaveField):
            raise ValueError(f"field must be a roughsea_torch.WaveField; got {type(field).__name__}")
        if not (isinstance(k_max, (int, float)) and k_max > 0 and not math.isnan(k_max)):
            raise ValueError(f"k_max must be a number > 0 [rad/m] (inf for every band); got {k_max!r}")
        self.field = field
        self.time_s = time_s
        self.dtype, self.device = field.dtype, field.device
        edges = field.bands.k_edges
        self.n_traced = sum(1 for o in range(field.n_bands) if edges[o + 1] <= k_max * (1.0 + 1e-12))
        self.footprint = None if self.n_traced == field.n_bands else self._selecting_footprint(self.n_traced - 1)
        B = field.batch_size
        if self.n_traced == 0:
            zero = torch.zeros(B, dtype=self.dtype, device=self.device)
            self.traced_covariance = torch.zeros(B, 3, dtype=self.dtype, device=self.device)
            self.eta_max, self.lipschitz = zero, zero.clone()
            self.level_slack, self.level_lipschitz = zero[:, None], zero[:, None].clone()
            return
        f = torch.zeros((), dtype=self.dtype) if self.footprint is None else torch.tensor(self.footprint, dtype=self.dtype)
        weights = field.band_weights(f.to(self.device)).detach().cpu()
        expected = torch.tensor([1.0] * self.n_traced + [0.0] * (field.n_bands - self.n_traced), dtype=self.dtype)
        if not torch.equal(weights, expected):
            raise ValueError(
                f"k_max = {k_max!r}: the field's band window cannot select exactly the bands with upper edge "
                f"≤ k_max (got weights {weights.tolist()}); the bands must be octaves"
            )
        cov = field.resolved_covariance(f.to(self.device))
        self.traced_covariance = torch.stack(cov, -1).detach()
        self._tiles = self._read_tiles()
        self._elevation_tiles = [t[:, :1].contiguous() for t in self._tiles]
        band_eta, band_lip = self._bounds()
        self.eta_max, self.lipschitz = band_eta.sum(1), band_lip.sum(1)
        self.level_lipschitz = band_lip.cumsum(1)  # L of the bands ≤ j
        rest = band_eta.sum(1, keepdim=True) - band_eta.cumsum(1)  # η_max of the bands > j
        self.level_slack = torch.where(rest > 0, rest * (1.0 + 1e-9) + 1e-12, torch.zeros_like(rest))

    def _selecting_footprint(self, last: int) -> float | None:
        """Footprint [m] at which the window is exactly 1 for bands ≤ ``last`` and exactly 0 above
        (None: every band, −1: no band is selected by an infinite footprint)."""
        if last < 0:
            return math.inf
        if last == self.field.n_bands - 1:
            return None
        k_o = self.field.bands.band_wavenumber[last]
        return _WINDOW_FULL * math.pi / k_o * (1.0 + 1e-9)

    def _read_tiles(self) -> list[torch.Tensor]:
        """Each traced band's tile of (η, s_x, s_y) at the time, read at its nodes through
        ``field.sample`` (bands ≤ o minus bands ≤ o − 1, one call for all), periodic-padded:
        (B, 3, n + 1, n + 1) each."""
        field, B = self.field, self.field.batch_size
        n = field.bands.tile_size
        idx = torch.arange(n, dtype=self.dtype, device=self.device)
        xs, ys, fs = [], [], []
        for o in range(self.n_traced):
            h = field.bands.tile_length[o] / n
            gu, gv = torch.meshgrid(idx * h, idx * h, indexing="xy")  # (n, n): row j = v, column i = u (tile axes)
            ca, sa = math.cos(field.bands.tile_angle[o]), math.sin(field.bands.tile_angle[o])
            gx, gy = gu * ca - gv * sa, gu * sa + gv * ca  # the texels in the world
            for last in (o, o - 1):  # the same nodes with bands ≤ o and with bands ≤ o − 1
                xs.append(gx.reshape(-1))
                ys.append(gy.reshape(-1))
                f = self._selecting_footprint(last)
                fs.append(torch.full((n * n,), 0.0 if f is None else f, dtype=self.dtype, device=self.device))
        x, y, f = (torch.cat(v)[None].expand(B, -1) for v in (xs, ys, fs))
        with torch.no_grad():
            out = self.field.sample(x, y, self.time_s, footprint=f, elevation=True)
        vals = torch.stack([out[c] for c in ("elevation", "slope_x", "slope_y")], 1).reshape(B, 3, self.n_traced, 2, n, n)
        tiles = []
        for o in range(self.n_traced):
            band = vals[:, :, o, 0] - vals[:, :, o, 1]
            band = torch.cat([band, band[:, :, :1]], 2)  # periodic: row n = row 0, column n = column 0
            tiles.append(torch.cat([band, band[:, :, :, :1]], 3).contiguous())
        return tiles

    def _bounds(self) -> tuple[torch.Tensor, torch.Tensor]:
        """Per traced band, (B, K) each: max |node| (the bilinear interpolant's largest |η|) and the
        largest gradient of the interpolant (its |∇|² is convex on a cell, so a corner of a cell holds
        it), with a relative margin far above the rounding of the subtraction and interpolation."""
        B, n = self.field.batch_size, self.field.bands.tile_size
        etas, lips = [], []
        for o, tile in enumerate(self._tiles):
            h = self.field.bands.tile_length[o] / n
            ext = tile[:, 0]  # (B, n+1, n+1) elevation
            etas.append(ext.abs().amax((1, 2)))
            dx = (ext[:, :, 1:] - ext[:, :, :-1]) / h  # (B, n+1, n): along x, at rows j
            dy = (ext[:, 1:] - ext[:, :-1]) / h  # (B, n, n+1): along y, at columns i
            best = torch.zeros(B, dtype=self.dtype, device=self.device)
            for a in (0, 1):  # the four corners of every cell
                for b in (0, 1):
                    gxa = dx[:, a : a + n, :]  # ∂x at the cell's row j + a
                    gyb = dy[:, :, b : b + n]  # ∂y at the cell's column i + b
                    best = torch.maximum(best, (gxa**2 + gyb**2).sqrt().amax((1, 2)))
            lips.append(best)
        margin = lambda v: torch.stack(v, 1) * (1.0 + 1e-9) + 1e-12  # noqa: E731
        return margin(etas), margin(lips)

    def _lookup(self, tiles: list[torch.Tensor], x: torch.Tensor, y: torch.Tensor) -> list[torch.Tensor]:
        """Each band's bilinear interpolation at (u mod L_o, v mod L_o), (u, v) the point in the tile's turned axes
        (``WaveBands.tile_units``): a (B, C, P) tensor per band."""
        xy = torch.stack([x, y], -1)[:, None]  # (B, 1, P, 2)
        out = []
        for o, tile in enumerate(tiles):
            grid = self.field.bands.tile_units(o, xy) * 2.0
            grid = torch.remainder(grid, 2.0, out=grid).sub_(1.0)  # (u mod L) / L mapped to [−1, 1)
            out.append(torch.nn.functional.grid_sample(tile, grid, mode="bilinear", padding_mode="border",
                                                       align_corners=True)[:, :, 0])
        return out

    def __call__(self, x: torch.Tensor, y: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
        """(η [m], s_x, s_y) of the traced bands at world points x, y (B, P) [m]: the bilinear
        interpolation of each band's tile at (u mod L_o, v mod L_o), summed over the traced bands
        (what ``field.sample`` returns, to rounding: ``tests/test_raytrace.py``)."""
        if self.n_traced == 0:
            z = torch.zeros_like(x)
            return z, z, z
        acc = sum(self._lookup(self._tiles, x, y))
        return acc[:, 0], acc[:, 1], acc[:, 2]

    def partial_elevations(self, x: torch.Tensor, y: torch.Tensor) -> torch.Tensor:
        """(B, K, P) [m]: η of the traced bands ≤ j at x, y (B, P), j = 0 … K − 1 (the last is η)."""
        if self.n_traced == 0:
            return torch.zeros_like(x)[:, None]
        return torch.cat(self._lookup(self._elevation_tiles, x, y), 1).cumsum(1)


# ---------------------------------------------------------------------------------------------
# Rays and the march
# ---------------------------------------------------------------------------------------------
def check_count(name: str, value: Any, lo: int) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < lo:
        raise ValueError(f"{name} must be an int ≥ {lo}; got {value!r}")
    return int(value)


def check_positive(name: str, value: Any, unit: str, allow_inf: bool = False) -> float:
    ok = isinstance(value, (int, float)) and not isinstance(value, bool) and value > 0
    ok = ok and (allow_inf or math.isfinite(value)) and not math.isnan(value)
    if not ok:
        raise ValueError(f"{name} must be a number > 0 [{unit}]{' (inf allowed)' if allow_inf else ''}; got {value!r}")
    return float(value)


def _padded(b_idx: torch.Tensor, values: torch.Tensor, B: int) -> tuple[torch.Tensor, tuple[torch.Tensor, torch.Tensor]]:
    """Values of rays listed by image ``b_idx`` (sorted or not) laid out as (B, P) with P the largest
    count of any image (padding repeats the image's first value, or 0); and the (image, slot) of each."""
    if B == 1:
        return values[None], (b_idx, torch.arange(b_idx.numel(), device=b_idx.device))
    counts = torch.bincount(b_idx, minlength=B)
    P = int(counts.max()) if b_idx.numel() else 0
    order = torch.argsort(b_idx, stable=True)
    starts = torch.cumsum(counts, 0) - counts
    slot = torch.empty_like(b_idx)
    slot[order] = torch.arange(b_idx.numel(), device=b_idx.device) - starts[b_idx[order]]
    grid = torch.zeros((B, max(P, 1)), dtype=values.dtype, device=values.device)
    grid[b_idx, slot] = values
    return grid, (b_idx, slot)


def _bisect(gap: Callable[[torch.Tensor], torch.Tensor], lo: torch.Tensor, hi: torch.Tensor, tol: float) -> torch.Tensor:
    """The crossing of rays bracketed by ``lo`` (gap > 0) and ``hi`` (gap ≤ 0) along them, bisected until
    the brackets are shorter than ``tol`` (or the dtype's resolution is reached): their midpoints."""
    while True:  # keep lo above the surface and hi on or below it
        open_ = (hi - lo) > tol
        if not bool(open_.any()):
            break
        mid = 0.5 * (lo + hi)
        below = gap(mid) <= 0
        stuck = (mid <= lo) | (mid >= hi)  # the dtype's resolution reached
        hi = torch.where(open_ & below & ~stuck, mid, hi)
        lo = torch.where(open_ & ~below & ~stuck, mid, lo)
        if bool(stuck[open_].all()):
            break
    return 0.5 * (lo + hi)


def march_first_hits(  # ~90 lines: the march loop (a safe step, the crossing test, the bisection's bracket) reads best whole
    centres: torch.Tensor,
    directions: torch.Tensor,
    surface: Surface,
    *,
    tolerance_m: float = 1e-7,
    min_step_m: float = 5e-3,
    max_steps: int = 100_000,
    active: torch.Tensor | None = None,
) -> dict[str, torch.Tensor]:
    """First intersections of rays with a height field (Lipschitz-bounded march, then bisection).

    Args:
        centres: (B, 3) ray origins [m] (camera centres), each above ``surface.eta_max``.
        directions: (B, N, 3) unit ray directions.
        surface: a :class:`Surface` (B images), in the dtype of the trace.
        tolerance_m: bisection stops when the bracket along the ray is shorter [m], > 0.
        min_step_m: smallest march step [m], > 0 (module docstring, Method 4).
        max_steps: march iterations allowed before a ``RuntimeError``.
        active: (B, N) bool, the rays to trace (default: every descending ray). Rays that do not
            descend are never traced.

    Returns:
        dict of (B, N) tensors: 'hit' (bool), 't' distance along the ray to the hit [m] (inf where
        not hit), 'x', 'y', 'z' the hit point [m], 'slope_x', 'slope_y' the surface's slopes there,
        'steps' march steps taken (int64).
    """
    tol = check_positive("tolerance_m", tolerance_m, "m")
    hmin = check_positive("min_step_m", min_step_m, "m")
    max_steps = check_count("max_steps", max_steps, 1)
    if centres.ndim != 2 or centres.shape[-1] != 3:
        raise ValueError(f"centres must have shape (B, 3); got {tuple(centres.shape)}")
    if directions.ndim != 3 or directions.shape[-1] != 3 or directions.shape[0] != centres.shape[0]:
        raise ValueError(f"directions must have shape (B, N, 3) with B = {centres.shape[0]}; got {tuple(directions.shape)}")
    dt, dev = surface.dtype, surface.device
    C, D = centres.to(dt), directions.to(dt)
    B, N = D.shape[:2]
    eta_max, lip = surface.eta_max.to(dt), surface.lipschitz.to(dt)
    if bool((C[:, 2] <= eta_max).any()):
        raise ValueError(f"cameras (centres): every camera must be above the traced waves' highest possible crest "
                         f"(z > eta_max = {eta_max.tolist()} m); got z = {C[:, 2].tolist()} m")
    dz = D[..., 2]
    down = dz < 0
    act = down if active is None else (active.to(dev) & down)
    safe_dz = torch.where(down, dz, torch.full_like(dz, -1.0))
    t_top = (C[:, 2:3] - eta_max[:, None]) / (-safe_dz)
    t_bot = (C[:, 2:3] + eta_max[:, None]) / (-safe_dz)
    horizontal = torch.sqrt((1.0 - dz * dz).clamp_min(0.0))
    levels = hasattr(surface, "partial_elevations")
    if levels:  # step bounds from every partial sum η_{≤j}: its gap less the rest's amplitude, its own L
        slack, lip_j = surface.level_slack.to(dt), surface.level_lipschitz.to(dt)  # (B, K)
    else:
        slack, lip_j = torch.zeros_like(lip)[:, None], lip[:, None]

    out_t = torch.full((B, N), math.inf, dtype=dt, device=dev)
    steps = torch.zeros((B, N), dtype=torch.int64, device=dev)

    def gap(b_idx: torch.Tensor, r_idx: torch.Tensor, t: torch.Tensor, partial: bool = False) -> torch.Tensor:
        """z − η at distance t along rays (b_idx, r_idx), evaluated as (B, P) padded per image; with
        ``partial``, (P, K) z − η_{≤j} (the last column z − η)."""
        pos = C[b_idx] + t[:, None] * D[b_idx, r_idx]
        x, y = _padded(b_idx, pos[:, 0], B), _padded(b_idx, pos[:, 1], B)
        if partial and levels:
            return pos[:, 2:3] - surface.partial_elevations(x[0], y[0]).transpose(1, 2)[x[1]]
        eta = surface(x[0], y[0])[0]
        g = pos[:, 2] - eta[x[1]]
        return g[:, None] if partial else g

    # the march, on the rays still active (compacted every iteration)
    b_idx, r_idx = act.nonzero(as_tuple=True)
    t = t_top[b_idx, r_idx]
    t_lo = t.clone()
    brackets = []  # (b, r, t_lo, t_hi) of the rays whose gap has become ≤ 0
    for it in range(max_steps + 1):
        if b_idx.numel() == 0:
            break
        if it == max_steps:
            raise RuntimeError(f"march_first_hits: {b_idx.numel()} rays still marching after max_steps = {max_steps}")
        g = gap(b_idx, r_idx, t, partial=True)  # (P, K)
        steps[b_idx, r_idx] += 1
        crossed = (g[:, -1] <= 0) | (t >= t_bot[b_idx, r_idx])  # at the slab's bottom the gap is ≤ 0 (but for rounding)
        if bool(crossed.any()):
            brackets.append((b_idx[crossed], r_idx[crossed], t_lo[crossed], t[crossed]))
        keep = ~crossed
        b_idx, r_idx, t, g = b_idx[keep], r_idx[keep], t[keep], g[keep]
        t_lo = t
        # z − η_{≤j} less the rest's amplitude is below the true gap and falls no faster than
        # |d_z| + L_{≤j} |d_h| per metre: every level j gives a safe step; take the longest
        rate = -safe_dz[b_idx, r_idx, None] + lip_j[b_idx] * horizontal[b_idx, r_idx, None]
        step = ((g - slack[b_idx]) / rate).amax(1).clamp_min(hmin)
        t = torch.minimum(t + step, t_bot[b_idx, r_idx])
    if brackets:
        b_idx, r_idx, lo, hi = (torch.cat(parts) for parts in zip(*brackets))
        out_t[b_idx, r_idx] = _bisect(lambda t_: gap(b_idx, r_idx, t_), lo, hi, tol)
    hit = torch.isfinite(out_t)
    tt = torch.where(hit, out_t, torch.zeros_like(out_t))
    pos = C[:, None, :] + tt[..., None] * D
    _, sx, sy = surface(pos[..., 0], pos[..., 1])
    nan = torch.full_like(tt, math.nan)
    return {
        "hit": hit,
        "t": out_t,
        "x": torch.where(hit, pos[..., 0], nan),
        "y": torch.where(hit, pos[..., 1], nan),
        "z": torch.where(hit, pos[..., 2], nan),
        "slope_x": torch.where(hit, sx, nan),
        "slope_y": torch.where(hit, sy, nan),
        "steps": steps,
    }


"""Fine structure of the foam cover: an anisotropic Gaussian lattice field ν, streaks along the wind.

Whitecaps and the residual foam they leave are not smooth blobs: foam lies in patches, filaments and,
from about Beaufort 7 (14 m/s), in well-marked streaks along the wind (the WMO Beaufort scale's sea
state descriptions: "foam ... blown in streaks along the direction of the wind" from force 7;
"dense streaks" from force 9). The crest variable X of the wave field (whose bands stop near ten
times the peak wavenumber, tens of metres at storm winds) has none of that. :mod:`~roughsea_torch.whitecaps`
thresholds X + s ν instead of X, with ν an independent, exactly N(0, 1) field of a few metres:

    ν(x) = Σ_{corners} w_u w_v z_{ij},   w = cos(π f/2) or sin(π f/2) per axis,

z_{ij} i.i.d. N(0, 1) on a lattice of spacing ℓ_along × ℓ_across in the wind's frame (a counter-based
hash of the image's seed and the node, splitmix64's finalizer, through Φ⁻¹), f the point's fraction
of its cell. The squares of the four weights sum to 1, so ν is N(0, 1) at every point, whatever f
(not only on average); it is continuous, and correlated over about one cell. ℓ_along =
:data:`STREAK_LENGTH_M` = 2 m; ℓ_across = ℓ_along / A(U10), A = 1 + 4 s((U10 − 8)/12) (s the
smoothstep): isotropic at and below 8 m/s, five times longer than wide (0.4 m) from 20 m/s, the
Beaufort scale's onset of streaks (force 7–9, 14–24 m/s) taken as the ramp. The lattice is anchored in
the drifting surface (ν is read at x − v t, v the foam's drift): the structure drifts with the foam
and does not flicker. The scales and the ramp are this model's choices within the 0.3–3 m that the
descriptions suggest; no measured spectrum of foam texture was used.
"""

from __future__ import annotations

import math
from typing import Sequence

import torch

from ._parallel import BLOCK, in_blocks
from .counter_hash import bits_uniform, splitmix64

__all__ = ["STREAK_LENGTH_M", "STREAK_ANISOTROPY", "streak_lengths", "streak_noise", "cell_bound", "resolved_amplitude",
           "resolved_share"]

STREAK_LENGTH_M = 2.0  # [m] ℓ_along, the lattice cell along the wind
STREAK_ANISOTROPY = 5.0  # ℓ_along / ℓ_across from 20 m/s (Beaufort 8–9: dense streaks)
_RAMP = (8.0, 20.0)  # [m/s] isotropic below, fully anisotropic above (Beaufort 5 to 8–9)


def streak_lengths(wind_speed: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
    """(ℓ_along, ℓ_across) [m] at U10 ``wind_speed`` [m/s] (any shape; differentiable)."""
    t = ((wind_speed - _RAMP[0]) / (_RAMP[1] - _RAMP[0])).clamp(0.0, 1.0)
    a = 1.0 + (STREAK_ANISOTROPY - 1.0) * t * t * (3.0 - 2.0 * t)
    return torch.full_like(wind_speed, STREAK_LENGTH_M), STREAK_LENGTH_M / a


def resolved_amplitude(footprint: torch.Tensor | None, length_across: torch.Tensor) -> torch.Tensor | float:
    """√r = (1 − (L / 2ℓ_across)²)₊, r = √r² the share of ν's variance a footprint L [m] keeps: 1 for a
    point (None), 0 from two cells across (the footprint averages the lattice away: the far field's
    cover is then exactly the crest variable's, W where nothing is resolved). Only r enters the resolved
    variance, so the cover's ensemble mean stays exact whatever this approximation of the averaging.
    (√r is returned rather than r: the square root's gradient at r = 0 would be infinite.)"""
    if footprint is None:
        return 1.0
    q = footprint / (2.0 * length_across)
    return (1.0 - q * q).clamp_min(0.0)


def resolved_share(footprint: torch.Tensor | None, length_across: torch.Tensor) -> torch.Tensor | float:
    """r = (1 − (L / 2ℓ_across)²)₊² (:func:`resolved_amplitude` squared)."""
    a = resolved_amplitude(footprint, length_across)
    return a * a


def _node_normal(base: torch.Tensor, i: torch.Tensor, j: torch.Tensor) -> torch.Tensor:
    """z_ij ~ N(0, 1), i.i.d. over nodes and seeds: Φ⁻¹ of a 52-bit uniform from one hash of the seed's
    base and the node (the node's key i P₁ + j P₂, P₂ > 2³¹: distinct for any lattice a scene reaches)."""
    u = bits_uniform(splitmix64(base + i * 1_000_003 + j * 2_147_483_659))
    return torch.special.ndtri(u)


def streak_noise(x: torch.Tensor, y: torch.Tensor, seeds: Sequence[int], cos_wind: torch.Tensor, sin_wind: torch.Tensor,
                 length_along: torch.Tensor, length_across: torch.Tensor, where: torch.Tensor | None = None,
                 below: torch.Tensor | None = None) -> torch.Tensor:
    """ν at world points (x, y) [m] (B, ...) of B images (module docstring).

    Args:
        x, y: (B, ...) [m], float32/float64 (the result's dtype); seeds: B ints.
        cos_wind, sin_wind: (B,) the wind's direction (its axis; sign irrelevant).
        length_along, length_across: (B,) the lattice cell [m] > 0.
        where: bool, x's shape, or None: ν only there, 0 elsewhere (the far field, where a footprint
            averages ν away, costs nothing).
        below: float64, x's shape, or None: where ν is certainly at most ``below`` (its cell's bound
            :func:`cell_bound` is), ν is not computed and 0 is returned (for a caller to whom any
            ν ≤ ``below`` gives the same result, e.g. a foam cover that is exactly 0 there); elsewhere
            ν itself. A bound needs the lattice table (points whose cells fill their box); without it
            ν is computed everywhere.

    Returns:
        ν (B, ...), exactly N(0, 1) at every point for a random seed; continuous; differentiable in
        x, y, the direction and the lengths (not in the node values). The same values bit for bit
        whatever ``where``, ``below`` or the number of points (the arithmetic is per point).
    """
    base = splitmix64(torch.tensor([int(sd) for sd in seeds], dtype=torch.int64, device=x.device) * 0x5DEECE66D + 17)
    # image by image (image i of a batch is then bitwise the image rendered alone), and within an image block
    # by block of points (_parallel.in_blocks), so that the per-point temporaries stay in cache
    out = []
    for i in range(x.shape[0]):
        xd, yd = x[i].to(torch.float64), y[i].to(torch.float64)
        lim = None if below is None else below[i].to(torch.float64)
        if where is not None:
            xd, yd = xd[where[i]], yd[where[i]]
            lim = None if lim is None else lim[where[i]]
        shape = xd.shape
        xd, yd = xd.reshape(-1), yd.reshape(-1)
        lim = None if lim is None else lim.reshape(-1)
        frame = tuple(t[i].to(torch.float64) for t in (cos_wind, sin_wind, length_along, length_across))
        (nu,) = in_blocks(lambda u, e: (_block_noise(base[i], xd[u:e], yd[u:e], frame, None if lim is None else lim[u:e]),),
                          xd.shape[0], _BLOCK)
        nu = nu.reshape(shape).to(x.dtype)
        out.append(nu if where is None else torch.zeros_like(x[i]).index_put((where[i],), nu))
    return torch.stack(out)


_BLOCK = BLOCK  # points per block of streak_noise's per-point work (a module constant the tests vary)
_CORNERS = ((0, 0), (0, 1), (1, 0), (1, 1))


def _block_noise(base: torch.Tensor, xd: torch.Tensor, yd: torch.Tensor, frame: tuple,
                 lim: torch.Tensor | None) -> torch.Tensor:
    """ν (float64) at the points (xd, yd) (P,) of one image, ``frame`` = (cos, sin, ℓ_along, ℓ_across)
    of the wind; 0 where :func:`cell_bound` ≤ ``lim`` (P,) (not computed), with ``lim`` not None."""
    c, s, la, lc = frame
    u = (xd * c + yd * s) / la
    v = (yd * c - xd * s) / lc
    iu, iv = torch.floor(u.detach()), torch.floor(v.detach())
    fu, fv = u - iu, v - iv
    i0, j0 = iu.to(torch.int64), iv.to(torch.int64)
    lattice = _node_table(base, i0, j0)
    sel = None
    if lattice is not None and lim is not None:
        table, idx, nj = lattice
        sel = _flat_true(cell_bound(table).index_select(0, idx) > lim)
        fu, fv, idx = fu.index_select(0, sel), fv.index_select(0, sel), idx.index_select(0, sel)
        lattice = table, idx, nj
    wu = (torch.cos(0.5 * math.pi * fu), torch.sin(0.5 * math.pi * fu))
    wv = (torch.cos(0.5 * math.pi * fv), torch.sin(0.5 * math.pi * fv))
    if lattice is None:  # points scattered over a large box: each corner hashed per point
        corners = [_node_normal(base, i0 + p, j0 + q) for p, q in _CORNERS]
    else:
        table, idx, nj = lattice
        corners = [table.view(-1).index_select(0, idx + (p * nj + q)) for p, q in _CORNERS]
    nu = sum(wu[p] * wv[q] * z for (p, q), z in zip(_CORNERS, corners))
    return nu if sel is None else xd.new_zeros(xd.shape).index_put((sel,), nu)


def _node_table(base: torch.Tensor, i0: torch.Tensor, j0: torch.Tensor) -> tuple | None:
    """(z over the box of nodes that the cells (i0, j0) (P,) touch, (ni, nj); each point's cell as a flat
    index into it; nj), or None where the cells do not fill their box densely (more than 4 nodes per
    point) or there are no points. One hash and one Φ⁻¹ per node instead of four per point, the same
    values bit for bit."""
    if i0.numel() == 0:
        return None
    ia, ja = int(i0.min()), int(j0.min())
    ni, nj = int(i0.max()) - ia + 2, int(j0.max()) - ja + 2
    if ni * nj > 4 * i0.numel():
        return None
    gi = torch.arange(ia, ia + ni, dtype=torch.int64, device=i0.device)[:, None]
    gj = torch.arange(ja, ja + nj, dtype=torch.int64, device=i0.device)[None, :]
    return _node_normal(base, gi, gj), (i0 - ia) * nj + (j0 - ja), nj


def cell_bound(table: torch.Tensor) -> torch.Tensor:
    """An upper bound of ν over each cell of a node table z (ni, nj), flat (ni nj,) indexed by the cell's
    lower corner (the last row and column, no cell's, +inf): (1 + 1e-9) ‖z⁺‖₂ + 1e-12 over the cell's
    four corners. ν = Σ w_p z_p with weights w_p ≥ 0 whose squares sum to 1, so ν ≤ Σ w_p z_p⁺ ≤ ‖z⁺‖₂
    (Cauchy–Schwarz); the factor and the term cover the rounding of the weights and of the sum (a few
    1e-16 of Σ |w_p z_p| ≤ ‖z‖₂, and |z| < 8.3 for a 52-bit uniform)."""
    zp = table.clamp_min(0.0)
    zp = zp * zp
    ss = ((zp[:-1, :-1] + zp[:-1, 1:]) + zp[1:, :-1]) + zp[1:, 1:]
    out = torch.full_like(table, math.inf)
    out[:-1, :-1] = torch.sqrt(ss) * (1.0 + 1e-9) + 1e-12
    return out.view(-1)


def _flat_true(mask: torch.Tensor) -> torch.Tensor:
    """The flat indices (int64, 1-D) where the 1-D bool ``mask`` is True."""
    return torch.nonzero(mask).view(-1)

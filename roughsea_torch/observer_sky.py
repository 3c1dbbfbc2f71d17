"""The clear sky seen by a sensor at altitude h (0–5 km), above and below the local horizontal (LOWTRAN7).

:func:`load_observer_sky` gives the sky seen from altitude h: above the local horizontal, LOWTRAN's
sky from H1 = h; below it down to the geometric horizon, the segment to the tangent point and then
the sky seen horizontally from there, continuous with the sea's horizon row of the renderer
(:func:`~roughsea_torch.lowtran.load_path`, :func:`~roughsea_torch.lowtran.load_sky`).

Source: LOWTRAN7 (AFGL; Kneizys et al. 1988, *Users guide to LOWTRAN 7*, AFGL-TR-88-0177), tables
``observer_<name>.npz`` made by ``pipelines/lowtran_observer_sky.py``; settings and every measured
error in :func:`observer_provenance`. Interpolation and accuracy: :class:`ObserverSky`.

:class:`ObserverSky`, :func:`load_observer_sky` and :func:`observer_provenance` are also importable
from :mod:`roughsea_torch.atmosphere`.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import numpy as np
import torch

from ._tables import read_table, table_dir
from .lowtran import (ATMOSPHERES, EARTH_RADIUS_M, AtmosphericPath, atmosphere_tables, check_band, check_dtype,
                      horizon_range, load_path, query_tensors, sky_band_radiance, spectral_weights)
from .radiometry import LWIR, SpectralBand
from .sky import pchip_derivatives

__all__ = ["ObserverSky", "load_observer_sky", "observer_provenance", "observer_tables"]


def observer_tables(name: Any, data_dir: str | Path | None = None) -> dict[str, Any]:
    """The raw arrays of the observer-sky table ``observer_<name>.npz`` (read-only, cached);
    ``ValueError`` for an atmosphere without one."""
    d = table_dir(data_dir)
    avail = [n for n in ATMOSPHERES if (d / f"observer_{n}.npz").is_file()]
    if not isinstance(name, str) or name not in avail:
        listing = ", ".join(avail) if avail else f"none (no observer_*.npz tables in {d})"
        raise ValueError(f"name: unknown atmosphere {name!r} for the observer sky; available: {listing}")
    return read_table(str(d / f"observer_{name}.npz"))


def observer_provenance(name: str, *, data_dir: str | Path | None = None) -> dict[str, Any]:
    """How the observer-sky tables of ``name`` were made (settings, versions, date, command, grids)
    and the errors measured on them (held-out LOWTRAN values, agreement with :func:`~roughsea_torch.lowtran.load_sky` at
    h = 0, continuity at the dip); a copy, JSON-like dict."""
    return json.loads(json.dumps(observer_tables(name, data_dir)["provenance"]))


_KIND_LINEAR, _KIND_LOG, _KIND_BELOW, _KIND_ABOVE, _KIND_SQRT = 0, 1, 2, 3, 4


def _int16_factors(t: dict[str, Any], key: str) -> np.ndarray:
    """Rank-K coefficients stored as int16 with a per-component step and offset, as float64."""
    return (t[key + "_coef_int16"].astype(np.float64) + 32767.0) * t[key + "_coef_step"] + t[key + "_coef_offset"]


class _AltitudeGrid:
    """Fractional node index of an altitude, piecewise linear in a per-cell coordinate: h (or √h) on
    the first cell [0, h₁], log(L − h + c_b) negated within a span below a LOWTRAN level L, log(h − L + c_a)
    above a level, log h elsewhere (the generator's ``cell_kind``). Differentiable in h."""

    def __init__(self, nodes: np.ndarray, levels: np.ndarray, below_span: float, below_offset: float,
                 above_offset: float, sqrt_first: bool = False, above_levels: bool = True,
                 linear: bool = False):
        h = np.array(nodes, dtype=np.float64)
        if h.ndim != 1 or h.size < 2 or np.any(np.diff(h) <= 0):
            raise ValueError("observer tables: altitudes must be strictly ascending")
        kind = np.empty(h.size - 1, dtype=np.int64)
        lev = np.zeros(h.size - 1)
        for k, (a, b) in enumerate(zip(h[:-1], h[1:])):
            below = [lv for lv in levels if b <= lv + 1e-9 and a >= lv - below_span - 1e-9]
            if a == 0.0:
                kind[k] = _KIND_LINEAR
            elif below:
                kind[k], lev[k] = _KIND_BELOW, below[0]
            elif above_levels and a >= levels[0] - 1e-9:
                kind[k], lev[k] = _KIND_ABOVE, 1000.0 * math.floor(a / 1000.0 + 1e-9)
            else:
                kind[k] = _KIND_LINEAR if linear else _KIND_LOG
        if sqrt_first:
            kind[0] = _KIND_SQRT
        self.nodes, self.kind, self.level = h, kind, lev
        self.below_offset, self.above_offset = float(below_offset), float(above_offset)
        self.g0 = np.array([self._g_np(a, kd, lv) for a, kd, lv in zip(h[:-1], kind, lev)])
        self.g1 = np.array([self._g_np(b, kd, lv) for b, kd, lv in zip(h[1:], kind, lev)])
        self._cache: dict[tuple[torch.dtype, torch.device], tuple[torch.Tensor, ...]] = {}

    def _g_np(self, h: float, kind: int, lv: float) -> float:
        if kind == _KIND_LINEAR:
            return h
        if kind == _KIND_SQRT:
            return math.sqrt(h)
        if kind == _KIND_BELOW:
            return -math.log(lv - h + self.below_offset)
        if kind == _KIND_ABOVE:
            return math.log(h - lv + self.above_offset)
        return math.log(h)

    def _tensors(self, dtype: torch.dtype, device: torch.device) -> tuple[torch.Tensor, ...]:
        key = (dtype, device)
        if key not in self._cache:
            f = lambda a: torch.tensor(np.array(a, dtype=np.float64), dtype=dtype, device=device)  # noqa: E731
            self._cache[key] = (f(self.nodes), torch.as_tensor(self.kind, device=device), f(self.level),
                                f(self.g0), f(self.g1))
        return self._cache[key]

    def index(self, h: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
        """(i, w): the cell index (long) and the weight of its upper node, w ∈ [0, 1]."""
        nodes, kind, lev, g0, g1 = self._tensors(h.dtype, h.device)
        i = (torch.searchsorted(nodes, h.detach().contiguous(), right=True) - 1).clamp(0, nodes.numel() - 2)
        k, lv = kind[i], lev[i]
        g = torch.where(k == _KIND_LINEAR, h, torch.log(h.clamp_min(1e-30)))
        g = torch.where(k == _KIND_SQRT, torch.sqrt(h.clamp_min(1e-12)), g)
        g = torch.where(k == _KIND_BELOW, -torch.log((lv - h).clamp_min(0.0) + self.below_offset), g)
        g = torch.where(k == _KIND_ABOVE, torch.log((h - lv).clamp_min(0.0) + self.above_offset), g)
        return i, (g - g0[i]) / (g1[i] - g0[i])


def _pchip_power_form(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Per-interval cubic coefficients (..., N−1, 4) in t ∈ [0, 1] of the PCHIP interpolant of rows
    y (..., N) over nodes x (:func:`roughsea_torch.sky.pchip_derivatives`, float64)."""
    xt = torch.tensor(np.array(x, dtype=np.float64))
    yt = torch.tensor(np.array(y, dtype=np.float64))
    d = pchip_derivatives(xt, yt)
    h = xt[1:] - xt[:-1]
    dy = yt[..., 1:] - yt[..., :-1]
    d0, d1 = d[..., :-1], d[..., 1:]
    return torch.stack([yt[..., :-1], h * d0, 3 * dy - h * (2 * d0 + d1), -2 * dy + h * (d0 + d1)], -1).numpy()


class ObserverSky:
    """Clear-sky band radiance arriving at a sensor at altitude h along a ray of zenith angle z.

    Build it with :func:`load_observer_sky`. ``sky(altitude_m, cos_zenith)`` → band radiance
    ∫ L_λ r dλ [W m⁻² sr⁻¹]; the inputs broadcast (e.g. altitude (B, 1), cos (B, N): the altitude
    work is done on the altitude's own shape); the output has the broadcast shape, the inputs'
    floating dtype (float32 or float64; the table's for Python numbers) and device, and is
    differentiable in both inputs (finite gradients everywhere in the valid range, also exactly at
    cos z = 0 and at the dip). Attribute ``altitude_range_m`` = (0, 5000).

    Valid inputs: ``altitude_range_m[0] ≤ h ≤ altitude_range_m[1]`` and −sin(dip(h)) ≤ cos z ≤ 1,
    dip(h) = asin(√(h(2R+h))/(R+h)) the depression of the geometric horizon (R = 6371 km, straight
    rays: the renderer's geometry); rays below −sin(dip) meet the sea. Anything else raises
    ``ValueError`` (naming the argument and the range) unless ``clamp=True``, which holds h and then
    cos z at the ends of their ranges.

    Source: LOWTRAN7 (AFGL; Kneizys et al. 1988, *Users guide to LOWTRAN 7*, AFGL-TR-88-0177), via
    ``pipelines/lowtran_observer_sky.py``; settings and every measured error in
    :func:`observer_provenance`.

    - cos z ≥ 0: LOWTRAN's sky from H1 = h (ITYPE 3 to space), 112 altitude nodes (0 m, the path
      tables' nodes, 1–120 m below each LOWTRAN level) × the 39 zenith nodes of :func:`~roughsea_torch.lowtran.load_sky`
      (0.1° at the horizon). The h = 0 row *is* :func:`~roughsea_torch.lowtran.load_sky`'s table (agreement ≤ 6e-5, the
      int16 storage). PCHIP in the zenith angle (monotone, C¹;
      :func:`roughsea_torch.sky.pchip_derivatives`), linear in h between altitude nodes (in
      −log(L − h + 1 m) within 3 m below a level L = 1…5 km, where LOWTRAN's near-horizontal sky
      steps by up to 2 %). Held-out error (LOWTRAN at cell centres, 8–12 and 3–5 µm, six
      atmospheres): ≤ 1.9e-3 LWIR, ≤ 3.0e-3 MWIR (the worst 13 m below a level); within 10 m of a
      level ≤ 2.3e-2 (LOWTRAN's own steps).
    - −sin(dip) ≤ cos z < 0 (rays between the local horizontal and the horizon, which pass a tangent
      point at h_t = (R+h) sin z − R and go back up): the spectral composition
      L_seg(h → h_t) + τ_seg · S(h_t, 90°) of LOWTRAN's sensor–tangent segment (range-matched slant
      path, or horizontal path below 200 m of height span, as the path tables) and LOWTRAN's sky seen
      horizontally from h_t; 68 altitude nodes × 13 nodes of x = −cos z / sin(dip) ∈ [0, 1] (dense
      near the horizontal), PCHIP in √(x + 1e-4) (LOWTRAN's band-model absorptance grows like the
      square root of a short segment), linear in log h (log(h − L + 3 m) above a level, √h on
      [0, 2 m]). Both ends are pinned to the values the renderer uses, the pins fading linearly in
      x: at x = 0 to the upward sky at 90° (continuity at the local horizontal), at x = 1 to
      ``L_path(h, r_hor) + τ(h, r_hor) · sky₀(90°)`` (:func:`~roughsea_torch.lowtran.load_path`, :func:`~roughsea_torch.lowtran.load_sky`: the sea's
      horizon row, exactly). The dip pin is the difference between that band-composed horizon value
      and the spectral one: ≤ 3.5e-3 (≤ 0.08 K) except subarctic winter LWIR, 1.7e-2 (up to 0.74 K:
      the band composition τ_band · sky₀_band overestimates there). Held-out error after the pins,
      h ≥ 2 m, beyond x × the dip pin: ≤ 2.2e-3 below 1 km, ≤ 8.2e-3 above (where the tangent
      height crosses a LOWTRAN level; LOWTRAN's layer steps also put bumps of ≤ 0.3 K in the
      profile there); 0–2 m (below the path tables): ≤ 1.2e-2.
    """

    def __init__(self, name: str, band: SpectralBand, tables: dict[str, Any], path: AtmosphericPath,
                 sky0_horizon: float, dtype: torch.dtype, device: Any):
        self.name = name
        self.band = band
        self.reference_temperature = path.reference_temperature
        t = tables
        lam = 1e-2 / t["wavenumber_cm1"].astype(np.float64)
        w = spectral_weights(lam, band)
        up = _int16_factors(t, "up_radiance") @ (t["up_radiance_basis"].astype(np.float64) @ w)
        below = _int16_factors(t, "below_radiance") @ (t["below_radiance_basis"].astype(np.float64) @ w)
        if not (np.all(up > 0) and np.all(below > 0)):
            raise ValueError("band/response: the band radiance is not > 0 at every node of the observer tables; "
                             "widen the band or check the response")
        levels = np.asarray(t["levels_m"], dtype=np.float64)
        args = (levels, float(t["below_level_span_m"]), float(t["below_level_offset_m"]),
                float(t["above_level_offset_m"]))
        h_up = np.asarray(t["altitude_m"], dtype=np.float64)
        h_b = np.asarray(t["below_altitude_m"], dtype=np.float64)
        self._grid_up = _AltitudeGrid(h_up, *args, above_levels=bool(t["up_above_level_coordinate"]),
                                      linear=bool(t["up_linear_in_h"]))
        self._grid_b = _AltitudeGrid(h_b, *args, sqrt_first=bool(t["below_first_cell_sqrt"]),
                                     above_levels=bool(t["below_above_level_coordinate"]),
                                     linear=bool(t["below_linear_in_h"]))
        self.altitude_range_m = (float(h_up[0]), float(h_up[-1]))
        zen = np.asarray(t["zenith_rad"], dtype=np.float64)
        # x = 0 column of the below-horizontal table: the upward sky at 90° (the same LOWTRAN runs)
        k = np.searchsorted(h_up, h_b)
        if not np.allclose(h_up[np.minimum(k, h_up.size - 1)], h_b, rtol=1e-9, atol=1e-9):
            raise ValueError("observer tables: the below-horizontal altitudes must be upward nodes")
        below = np.concatenate([up[k, -1:], below], axis=1)
        self._x0 = float(t["below_x0"])
        self._eps = float(t["below_sqrt_eps"])
        xb = np.asarray(t["below_x"], dtype=np.float64)
        tb = np.log1p(xb / self._x0) / math.log1p(1.0 / self._x0)
        if not np.allclose(tb, np.linspace(0.0, 1.0, tb.size), atol=1e-9):
            raise ValueError("observer tables: the below-horizontal nodes must be uniform in log(1 + x/x0)")
        self._nb = tb.size - 1
        ub = np.sqrt(xb + self._eps)  # the interpolation coordinate (the nodes' placement: tb)
        self._zen = zen
        self._up_coef = _pchip_power_form(zen, up)  # (Nh, Nz-1, 4)
        self._b_coef = _pchip_power_form(ub, below)  # (Nb, Nx-1, 4)
        self._ub = ub
        self._up_90 = up[:, -1]
        self._b_ends = below[:, [0, -1]]
        self._path = path
        self._sky0_horizon = float(sky0_horizon)
        self._path_h_min = path.altitude_range_m[0]
        self.dtype = dtype
        self.device = torch.device(device) if device is not None else torch.device("cpu")
        self._cache: dict[tuple[torch.dtype, torch.device], tuple[torch.Tensor, ...]] = {}
        self._tensors(dtype, self.device)

    def _tensors(self, dtype: torch.dtype, device: torch.device) -> tuple[torch.Tensor, ...]:
        key = (dtype, device)
        if key not in self._cache:
            f = lambda a: torch.tensor(np.array(a, dtype=np.float64), dtype=dtype, device=device)  # noqa: E731
            # per (altitude cell, angle interval): the cubic coefficients of the cell's lower and upper
            # altitude rows side by side, so that one gather fetches all 8
            up8 = np.concatenate([self._up_coef[:-1], self._up_coef[1:]], -1).reshape(-1, 8)
            b8 = np.concatenate([self._b_coef[:-1], self._b_coef[1:]], -1).reshape(-1, 8)
            self._cache[key] = (f(self._zen), f(up8), f(b8), f(self._up_90), f(self._b_ends), f(self._ub))
        return self._cache[key]

    @staticmethod
    def sin_dip(altitude_m: torch.Tensor) -> torch.Tensor:
        """sin of the depression of the geometric horizon, √(h(2R+h))/(R+h) (R = 6371 km)."""
        h = altitude_m
        # (clamped away from 0 so that the gradient at h = 0 stays finite)
        return torch.sqrt((h * (2.0 * EARTH_RADIUS_M + h)).clamp_min(1e-12)) / (EARTH_RADIUS_M + h)

    # -- parts ------------------------------------------------------------------------------------

    def _up(self, h: torch.Tensor, c: torch.Tensor) -> torch.Tensor:
        zen, up_coef = self._tensors(c.dtype, c.device)[:2]
        nz = zen.numel()
        i, w = self._grid_up.index(h)
        one = 1.0 - torch.finfo(c.dtype).eps  # acos has an infinite slope at 1
        theta = torch.acos(c.clamp(0.0, one))
        j = (torch.searchsorted(zen, theta.detach().contiguous(), right=True) - 1).clamp(0, nz - 2)
        t = (theta - zen[j]) / (zen[j + 1] - zen[j])
        base = i * (nz - 1) + j
        return self._eval8(up_coef, base, t, w)

    @staticmethod
    def _eval8(table: torch.Tensor, base: torch.Tensor, t: torch.Tensor, w: torch.Tensor) -> torch.Tensor:
        """Cubic rows (lower, upper altitude) at t, blended with weight w: one index_select."""
        shape = torch.broadcast_shapes(base.shape, t.shape, w.shape)
        c = torch.index_select(table, 0, base.expand(shape).reshape(-1)).reshape(*shape, 8)
        y0 = c[..., 0] + t * (c[..., 1] + t * (c[..., 2] + t * c[..., 3]))
        y1 = c[..., 4] + t * (c[..., 5] + t * (c[..., 6] + t * c[..., 7]))
        return y0 + w * (y1 - y0)

    def _up_horizon(self, h: torch.Tensor) -> torch.Tensor:
        up_90 = self._tensors(h.dtype, h.device)[3]
        i, w = self._grid_up.index(h)
        return up_90[i] + w * (up_90[i + 1] - up_90[i])

    def _dip_value(self, h: torch.Tensor) -> torch.Tensor:
        """L_path(h, r_hor) + τ(h, r_hor) · sky₀(90°): what the renderer gives the sea's horizon row;
        below the path tables' lowest altitude (2 m) it goes to sky₀(90°) at h = 0 linearly in √h
        (the horizon range is ∝ √h)."""
        lo = self._path_h_min
        hp = h.clamp_min(lo)
        tau, lp = self._path(hp, horizon_range(hp))
        d = lp + tau * self._sky0_horizon
        frac = torch.sqrt((h / lo).clamp(1e-12, 1.0))
        return torch.where(h >= lo, d, self._sky0_horizon + frac * (d - self._sky0_horizon))

    def _below_table(self, h: torch.Tensor, x: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
        """The below-horizontal table at (h, x), and at x = 0 and x = 1."""
        _, _, b_coef, _, b_ends, ub = self._tensors(x.dtype, x.device)
        nb = self._nb
        i, w = self._grid_b.index(h)
        # the interval from the nodes' placement (uniform in log(1 + x/x0)); within it, the
        # coordinate √(x + ε), which follows the band-model rise 1 − τ ∝ √(segment) near x = 0
        j = (torch.log1p(x.detach() / self._x0) * (nb / math.log1p(1.0 / self._x0))).long().clamp(0, nb - 1)
        u0 = ub[j]
        t = (torch.sqrt(x + self._eps) - u0) / (ub[j + 1] - u0)
        base = i * nb + j
        e0, e1 = b_ends[i], b_ends[i + 1]
        ends = e0 + w.unsqueeze(-1) * (e1 - e0)
        return self._eval8(b_coef, base, t, w), ends[..., 0], ends[..., 1]

    def _x(self, h: torch.Tensor, c: torch.Tensor) -> torch.Tensor:
        return (-c / self.sin_dip(h)).clamp(0.0, 1.0)

    def _below_unpinned(self, h: torch.Tensor, c: torch.Tensor) -> torch.Tensor:
        """The below-horizontal table alone (no pins): for the generator's continuity check."""
        return self._below_table(h, self._x(h, c))[0]

    def _below_pinned(self, h: torch.Tensor, c: torch.Tensor) -> torch.Tensor:
        x = self._x(h, c)
        v, v0, v1 = self._below_table(h, x)
        return v + (1.0 - x) * (self._up_horizon(h) - v0) + x * (self._dip_value(h) - v1)

    # -- call -------------------------------------------------------------------------------------

    def __call__(self, altitude_m: Any, cos_zenith: Any, *, clamp: bool = False) -> torch.Tensor:
        h, c, dtype, device = query_tensors(("altitude_m", altitude_m), ("cos_zenith", cos_zenith), self.dtype, self.device)
        lo, hi = self.altitude_range_m
        slack = 1e-6 if dtype == torch.float64 else 1e-5
        if not clamp:
            hd = h.detach()
            ok_h = (hd >= lo - slack * max(hi, 1.0)) & (hd <= hi * (1 + slack))  # False for NaN
            if not bool(ok_h.all()):
                raise ValueError(f"altitude_m must lie in [{lo:g}, {hi:g}] m (the observer-sky tables); "
                                 f"got {hd[~ok_h].reshape(-1)[0].item()!r}")
        h = h.clamp(lo, hi)  # clamp=False: rounding only
        sd = self.sin_dip(h)
        if not clamp:
            hb, cb = torch.broadcast_tensors(h.detach(), c.detach())
            sdb = self.sin_dip(hb)
            ok_c = (cb >= -sdb - slack * (sdb + 1e-3)) & (cb <= 1.0 + slack)
            if not bool(ok_c.all()):
                k = torch.nonzero(~ok_c.reshape(-1))[0, 0]
                hv, cv = hb.reshape(-1)[k].item(), cb.reshape(-1)[k].item()
                lim = math.sqrt(hv * (2 * EARTH_RADIUS_M + hv)) / (EARTH_RADIUS_M + hv)
                raise ValueError(
                    f"cos_zenith must lie in [-sin(dip), 1] = [{-lim:.6g}, 1] for altitude_m = {hv:g} "
                    f"(dip = {math.degrees(math.asin(lim)):.4g} deg: rays below it meet the sea); got {cv!r}")
        c = torch.where(c > 1.0, torch.ones_like(c), c)  # (where, not min/max: the gradient at the
        c = torch.where(c < -sd, -sd, c)                  # ends goes to cos_zenith, not half of it)
        if h.numel() == 0 or c.numel() == 0:
            return torch.empty(torch.broadcast_shapes(h.shape, c.shape), dtype=dtype, device=device)
        # altitude-only quantities (node indices, pins) are computed on the altitude's own shape
        # (e.g. (B, 1)) and broadcast against the rays
        below = self._below_pinned(h, c)
        up = self._up(h, c)
        return torch.where(c >= 0, up, below)

    def __repr__(self) -> str:
        return (f"ObserverSky({self.name!r}, band=({self.band.lo:.3g}, {self.band.hi:.3g}) m, altitude "
                f"{self.altitude_range_m[0]:g}-{self.altitude_range_m[1]:g} m)")


def load_observer_sky(
    name: str,
    band: Any = LWIR,
    response: Any = None,
    *,
    reference_temperature: float | None = None,
    dtype: torch.dtype = torch.float32,
    device: Any = None,
    data_dir: str | Path | None = None,
) -> ObserverSky:
    """Clear-sky band radiance seen by a sensor at altitude h (0–5 km), above and below the local
    horizontal, of a LOWTRAN7 model atmosphere (Kneizys et al. 1988).

    Args:
        name: one of :func:`available_atmospheres` (with an ``observer_<name>.npz`` table).
        band, response: as in :func:`~roughsea_torch.lowtran.load_sky` (band integration by :func:`spectral_weights`).
        reference_temperature: T_ref of the path transmittance that the horizon value is pinned to
            (as :func:`~roughsea_torch.lowtran.load_path`; default the surface air temperature).
        dtype, device: of the tables (Python-number queries get this dtype).
        data_dir: directory of the tables (default: the shipped ones).

    Returns:
        An :class:`ObserverSky`; ``sky(altitude_m, cos_zenith)`` → band radiance [W m⁻² sr⁻¹] for
        −sin(dip(h)) ≤ cos z ≤ 1.

    Raises:
        ValueError: unknown ``name``, a band outside the tables' coverage, a bad response or dtype.
    """
    t = observer_tables(name, data_dir)
    b = check_band(band, response, name, data_dir)
    dt = check_dtype(dtype)
    path = load_path(name, b, reference_temperature=reference_temperature, dtype=torch.float64, data_dir=data_dir)
    sky0 = float(sky_band_radiance(atmosphere_tables(name, data_dir), b)[-1])  # the sea-level sky at 90° (its last node)
    return ObserverSky(name, b, t, path, sky0, dt, device)

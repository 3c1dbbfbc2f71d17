"""The air between the sea and the sensor in a render: radiance at the sensor = τ · R_a + L_path per
sea pixel, τ and L_path from the scene's path model (``roughsea_torch.atmosphere.AtmosphericPath``)
at the pixel's slant range [m] and the camera's altitude [m]. For one camera the slant range is a
function of the view zenith alone, so the table method applies the path per fine-table row.
"""

from __future__ import annotations

from typing import Any

import torch

from ..geometry import slant_range

__all__ = ["check_path_altitude", "apply_path", "path_rows"]


def check_path_altitude(path: Any, altitude: torch.Tensor) -> None:
    """The path model's own check of the camera altitudes (a ray straight down, range = altitude,
    is valid at any altitude the tables cover), with the way out named."""
    h = altitude.detach()
    try:
        path(h, h, clamp=False)
    except ValueError as e:
        raise ValueError(f"{e}; SeaScene(path=False) renders without the air between sea and sensor") from None


def apply_path(path: Any, radiance: torch.Tensor, altitude: torch.Tensor, range_m: torch.Tensor, sea: torch.Tensor,
                air_scale: torch.Tensor | None = None) -> torch.Tensor:
    """τ · R_a + L_path at each sea pixel (other pixels unchanged); (b, H, W). ``air_scale`` (b,)
    scales L_path (SeaScene's air_temperature)."""
    h = altitude.to(radiance.dtype)[:, None, None].expand_as(radiance)
    r = torch.where(sea, range_m.to(radiance.dtype), h)  # any valid range off the sea
    tau, lp = path(h, r, clamp=True)
    if air_scale is not None:
        lp = lp * air_scale[:, None, None]
    return torch.where(sea, tau * radiance + lp, radiance)



def path_rows(path: Any, cos_rows: torch.Tensor, altitude: torch.Tensor, earth_radius_m: float
              ) -> tuple[torch.Tensor, torch.Tensor]:
    """(τ, L_path) of a table's rows, each (b, rows): the lines of sight of zenith cosine ``cos_rows``
    (b, rows) from cameras at ``altitude`` (b, 1) [m] over a sea of radius ``earth_radius_m`` [m]."""
    return path(altitude.expand_as(cos_rows), slant_range(cos_rows, altitude, earth_radius_m), clamp=True)


"""What a render hands back: radiance or brightness temperature."""

from __future__ import annotations

import torch

from ..radiometry import SpectralBand, brightness_temperature

__all__ = ["kelvin"]


def kelvin(radiance: torch.Tensor, band: SpectralBand) -> torch.Tensor:
    """Brightness temperature [K] of band radiances that must be > 0 (``ValueError`` otherwise:
    without shadowing, Eq. 7 makes R_a negative near the horizon, which has no temperature)."""
    low = radiance.detach().amin()
    if not bool(low > 0):
        raise ValueError(f"output='brightness_temperature': a radiance of {float(low):.3g} W m-2 sr-1 (<= 0) has no "
                         "brightness temperature; without shadowing (Eq. 7) R_a goes negative near the horizon: "
                         "use shadowing=True or output='radiance'")
    return brightness_temperature(radiance, band)


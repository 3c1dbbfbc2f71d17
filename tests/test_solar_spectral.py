"""roughsea_torch.solar: the spectral table behind the band irradiance (tests/test_solar.py holds the
rest of the module's tests)."""

from __future__ import annotations

import numpy as np
import pytest

from roughsea_torch.atmosphere import spectral_weights
from roughsea_torch.radiometry import LWIR, MWIR, as_band
from roughsea_torch.solar import SOLAR_ATMOSPHERES, load_solar_irradiance, load_solar_spectral


@pytest.mark.parametrize("band", [LWIR, MWIR], ids=["lwir", "mwir"])
def test_spectral_table_integrates_to_the_band_irradiance(band):
    """load_solar_spectral's direct irradiance, integrated over the band on its own wavelength grid
    (the spectral weights of ``wavelength_m``), is load_solar_irradiance's value at every LOWTRAN
    sun-zenith node, and its TOA spectrum gives the band's TOA irradiance; the wavelengths are
    those of the wavenumbers (λ ν̃ = 1, ν̃ in cm⁻¹)."""
    for name in SOLAR_ATMOSPHERES:
        spec = load_solar_spectral(name)
        np.testing.assert_allclose(spec["wavelength_m"] * spec["wavenumber_cm1"] * 100.0, 1.0, rtol=1e-15)
        w = spectral_weights(spec["wavelength_m"], as_band(band))
        e = load_solar_irradiance(name, band)
        np.testing.assert_allclose(e.zenith_nodes_rad, spec["sun_zenith_rad"], rtol=0, atol=0)
        np.testing.assert_allclose(spec["direct_irradiance"] @ w, e.node_irradiance, rtol=1e-12, atol=0)
        assert spec["toa_irradiance"] @ w == pytest.approx(e.toa, rel=1e-12)

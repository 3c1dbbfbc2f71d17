"""roughsea_torch.sensor: SensorModel.typical_lwir is the camera its docstring describes (tests/test_sensor.py
holds the rest of the module's tests)."""

from __future__ import annotations

import torch

import roughsea_torch as rs
from roughsea_torch.radiometry import LWIR


def test_typical_lwir_counts_span_220_to_340_k_over_14_bits():
    """'14 bits over 220–340 K': counts linear in the band radiance, the radiances of 220 K and 340 K
    blackbodies at 0 and 2¹⁴ − 1 (ToCounts), so a T-kelvin blackbody is round((L(T) − L(220)) /
    (L(340) − L(220)) · 16383); a count is ≈ 6 mK near 300 K."""
    counts = rs.SensorModel.typical_lwir().counts
    T = torch.tensor([220.0, 230.0, 260.0, 300.0, 300.1, 330.0, 340.0], dtype=torch.float64)
    L = rs.band_radiance(T, LWIR)
    lo, hi = rs.band_radiance(torch.tensor([220.0, 340.0], dtype=torch.float64), LWIR)
    c = counts(L.view(1, 1, 1, -1)).flatten()
    torch.testing.assert_close(c, torch.round((L - lo) / (hi - lo) * (2**14 - 1)), rtol=0, atol=0)
    assert c[0] == 0 and c[-1] == 2**14 - 1
    assert 0.1 / float(c[4] - c[3]) < 7e-3


def test_typical_lwir_fixed_pattern_at_the_calibration_point():
    """'0.1 K pixel and 0.05 K column offsets about a 300 K calibration': a uniform 300 K scene
    through the fixed pattern alone (the gain errors vanish at the calibration point) has column means
    of standard deviation 0.05 K and, about them, pixel offsets of standard deviation 0.1 K (1024 ×
    1024 pixels: sampling errors 2 % and 0.07 %)."""
    fp = rs.SensorModel.typical_lwir(seed=3).fixed_pattern
    L = rs.band_radiance(torch.full((1, 1, 1024, 1024), 300.0, dtype=torch.float64), LWIR)
    t = rs.brightness_temperature(fp(L), LWIR)[0, 0] - 300.0
    cols = t.mean(0)
    assert abs(float(cols.std()) / 0.05 - 1) < 0.1
    assert abs(float((t - cols).std()) / 0.1 - 1) < 3e-3

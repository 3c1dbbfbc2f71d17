"""roughsea_torch.wave_bands: the layout of the synthesized wavenumber bands."""

from __future__ import annotations

import math

import pytest

from roughsea_torch.wave_bands import WaveBands


@pytest.mark.parametrize("k_min, n", [(2.0**-8, 16), (0.05, 1), (0.3, 5)])
def test_octaves_are_n_bands_each_doubling_from_k_min(k_min, n):
    """WaveBands.octaves(k_min, n): n bands, edges k_min · 2^o (o = 0 … n), so each band spans one
    octave and the last ends at k_min · 2^n; the default layout is octaves(2⁻⁸, 16)."""
    b = WaveBands.octaves(k_min, n)
    assert b.n_bands == n
    assert b.k_edges[0] == k_min and b.k_edges[-1] == pytest.approx(k_min * 2.0**n, rel=1e-15)
    assert all(hi / lo == pytest.approx(2.0, rel=1e-15) for lo, hi in zip(b.k_edges[:-1], b.k_edges[1:]))
    assert all(c == pytest.approx(math.sqrt(2.0) * lo, rel=1e-15) for c, lo in zip(b.band_wavenumber, b.k_edges))
    if (k_min, n) == (2.0**-8, 16):
        assert b == WaveBands()

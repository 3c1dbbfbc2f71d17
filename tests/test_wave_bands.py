"""The band layout of the synthesized sea (roughsea_torch.wave_bands): each band's resolved-part
window at a pixel footprint, and the layout's checks. Single-threaded, as tests/test_waves.py."""

from __future__ import annotations

import math

import pytest
import torch

from roughsea_torch.waves import WaveBands, WaveField

pytestmark = pytest.mark.usefixtures("one_thread")


def test_band_weights_window():
    """band_weights: 1 at f = 0, 0 at f = inf, monotone and C¹ in log f, one octave wide around
    k_o f = π (1 below 0.707 π, 0 above 1.414 π), finite gradients (also at inf)."""
    field = WaveField(10.0, 0, dtype=torch.float64)
    k0 = float(field.band_wavenumber[5])
    f = torch.cat([torch.tensor([0.0, math.inf]), torch.logspace(-4, 4, 4001)]).to(torch.float64).requires_grad_()
    w = field.band_weights(f)
    assert w.shape == (f.shape[0], field.n_bands)
    assert bool((w[0] == 1).all()) and bool((w[1] == 0).all())
    assert bool(((w >= 0) & (w <= 1)).all())
    w5 = w[2:, 5].detach()
    assert bool((w5[1:] <= w5[:-1]).all())  # monotone non-increasing in f
    u = f[2:].detach() * k0 / math.pi
    assert bool((w5[u <= 0.7] == 1).all()) and bool((w5[u >= 1.42] == 0).all())
    inside = (u > 0.75) & (u < 1.35)
    assert bool(((w5[inside] > 0) & (w5[inside] < 1)).all())
    w.sum().backward()
    assert bool(torch.isfinite(f.grad).all())
    # C¹ in log f: dw/dlog f has no jump (it is 0 at both ends of the transition). On this grid
    # (Δ log f = 0.0046) a C¹ window changes dw/dlog f by ≤ 0.1 per step; a C⁰ ramp would jump by 1.4.
    dw = torch.diff(w5) / math.log(10 ** (8 / 4000))
    assert float(dw.abs().max()) > 1.0  # the transition is resolved by the grid
    assert float(torch.diff(dw).abs().max()) < 0.2
    # resolved covariance: f = 0 → everything, f = inf → nothing
    vx, vy, cxy = field.resolved_covariance(torch.tensor([0.0], dtype=torch.float64))
    total = field.band_covariance().sum(1)[0]
    torch.testing.assert_close(torch.stack([vx[0], vy[0], cxy[0]]), total)
    assert float(field.resolved_covariance(torch.tensor([math.inf], dtype=torch.float64))[0][0]) == 0.0


def test_wave_bands_errors():
    with pytest.raises(ValueError, match="k_edges must be strictly increasing"):
        WaveBands(k_edges=(1.0, 0.5))
    with pytest.raises(ValueError, match="tile_size/4"):
        WaveBands(k_edges=(1.0, 2.0), tile_size=16)


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

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
    for bad in (math.nan, 7.0, "1", True):
        with pytest.raises(ValueError, match=r"tile_rotation must be a finite angle in \[-2π, 2π\]"):
            WaveBands(tile_rotation=bad)


def _short_slopes(field: WaveField, x: torch.Tensor, y: torch.Tensor) -> torch.Tensor:
    """slope_x of the bands a 1.5 m footprint leaves out (the waves shorter than about 1.5 m)."""
    full = field.sample(x, y, 0.0, elevation=False)["slope_x"]
    return full - field.sample(x, y, 0.0, footprint=torch.full_like(x, 1.5), elevation=False)["slope_x"]


def test_turned_tiles_do_not_repeat_together():
    """With every tile aligned with the world axes (``tile_rotation=0``) the bands shorter than ~1.5 m, whose
    tile lengths halve (12.57 m, 6.28 m, …), repeat together: their slopes at x and x + 12.57 m are equal to
    rounding, which a camera looking along x sees as dotted streaks. Each tile turned by its own multiple of
    the golden angle (the default), the two differ by about √2 times their rms (uncorrelated), and also at
    the shift along y and along the diagonal; the slopes' variance is the same."""
    gen = torch.Generator().manual_seed(3)
    x = torch.rand(1, 3000, generator=gen, dtype=torch.float64) * 200.0
    y = torch.rand(1, 3000, generator=gen, dtype=torch.float64) * 200.0
    period = 4.0 * math.pi  # the tile length of the band 1–2 rad/m (inner radius 4)
    aligned = WaveField(5.0, 4, dtype=torch.float64, bands=WaveBands(tile_rotation=0.0))
    a = _short_slopes(aligned, x, y)
    torch.testing.assert_close(_short_slopes(aligned, x + period, y), a, rtol=0.0, atol=1e-9)
    turned = WaveField(5.0, 4, dtype=torch.float64)
    b = _short_slopes(turned, x, y)
    rms = float(b.pow(2).mean().sqrt())
    assert rms == pytest.approx(float(a.pow(2).mean().sqrt()), rel=0.1)
    for dx, dy in ((period, 0.0), (0.0, period), (period, period)):
        diff = float((_short_slopes(turned, x + dx, y + dy) - b).pow(2).mean().sqrt())
        assert diff > 1.2 * rms, (dx, dy, diff / rms)


def test_tile_units_put_a_texel_where_the_field_has_it():
    """``slope_tiles`` gives band o's texel (row i, column j) at tile coordinates (v, u) = (i, j) L_o / N; the
    world point x = u cos α − v sin α, y = u sin α + v cos α (α = o × the golden angle, the layout's
    documented turn) must sample that texel's value exactly (a texel node: no interpolation), and
    ``tile_units`` must map it to whole multiples of 1/N."""
    bands = WaveBands()
    field = WaveField(9.0, 2, dtype=torch.float64)
    n = bands.tile_size
    tiles = field.slope_tiles(torch.tensor([0.7], dtype=torch.float64))  # (n_bands, 1, 2, N, N)
    gen = torch.Generator().manual_seed(1)
    for o in (3, 6, 9):
        alpha = o * math.pi * (3.0 - math.sqrt(5.0))
        i = torch.randint(0, n, (50,), generator=gen)
        j = torch.randint(0, n, (50,), generator=gen)
        h = bands.tile_length[o] / n
        u, v = j.double() * h, i.double() * h
        x, y = u * math.cos(alpha) - v * math.sin(alpha), u * math.sin(alpha) + v * math.cos(alpha)
        units = bands.tile_units(o, torch.stack([x, y], -1)) * n
        torch.testing.assert_close(units, torch.stack([j, i], -1).double(), rtol=0.0, atol=1e-9)
        lone = WaveField(9.0, 2, dtype=torch.float64, bands=bands)
        # only band o: the footprint that keeps bands ≤ o minus the one that keeps bands ≤ o − 1
        # (window 1 up to k f = π/√2 for band `last`, 0 from there on for band `last` + 1)
        keep = lambda last: math.pi / (math.sqrt(2.0) * bands.band_wavenumber[last]) * (1 + 1e-9) if last >= 0 else math.inf  # noqa: E731
        at = lambda last: lone.sample(x[None], y[None], 0.7, footprint=torch.full((1, 50), keep(last), dtype=torch.float64))  # noqa: E731
        s = at(o)["slope_x"] - at(o - 1)["slope_x"]
        torch.testing.assert_close(s[0], tiles[o, 0, 0, i, j], rtol=0.0, atol=1e-9 * float(tiles[o, 0, 0].abs().max()))


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

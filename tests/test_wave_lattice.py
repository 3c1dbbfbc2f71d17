"""The Fourier lattice of each band (roughsea_torch.wave_lattice): the band covariances a field
reports are the sums over its discrete modes, with the bilinear interpolation's loss; a turned band's waves
travel downwind in the world frame. Single-threaded,
as tests/test_waves.py."""

from __future__ import annotations

import math

import pytest
import torch

from roughsea_torch.spectrum import dispersion
from roughsea_torch.waves import WaveBands, WaveField, elfouhaily_spectrum

pytestmark = pytest.mark.usefixtures("one_thread")


def _lattice_covariance(bands: WaveBands, wind: float, wind_direction: float, bilinear: bool = True) -> torch.Tensor:
    """Σ over each band's lattice modes of F(k, φ) Δk² k kᵀ (× the bilinear factor), rebuilt from the
    public spectrum: modes k = Δk (i û + j v̂), inner_radius ≤ |(i, j)| < inner_radius · k⁺/k⁻, along the
    tile's axes û = (cos α, sin α), v̂ = (−sin α, cos α), α = o · tile_rotation (band o; the bilinear factor
    counts along the tile's axes)."""
    out = []
    for o in range(bands.n_bands):
        dk, n = bands.fundamental[o], bands.tile_size
        ratio = bands.k_edges[o + 1] / bands.k_edges[o]
        m = math.ceil(bands.inner_radius * ratio)
        idx = torch.arange(-m, m + 1, dtype=torch.float64)
        i, j = torch.meshgrid(idx, idx, indexing="xy")
        r2 = i**2 + j**2
        keep = (r2 >= bands.inner_radius**2) & (r2 < (bands.inner_radius * ratio) ** 2)
        alpha = o * bands.tile_rotation
        kx = (i[keep] * math.cos(alpha) - j[keep] * math.sin(alpha)) * dk
        ky = (i[keep] * math.sin(alpha) + j[keep] * math.cos(alpha)) * dk
        phi = torch.atan2(ky, kx) - (wind_direction + math.pi)  # from downwind
        v = elfouhaily_spectrum(torch.sqrt(kx**2 + ky**2), phi, wind) * dk**2
        if bilinear:
            v = v * (2 + torch.cos(2 * math.pi * i[keep] / n)) * (2 + torch.cos(2 * math.pi * j[keep] / n)) / 9
        out.append(torch.stack([(v * kx * kx).sum(), (v * ky * ky).sum(), (v * kx * ky).sum()]))
    return torch.stack(out)


@pytest.mark.parametrize("bands", [WaveBands(), WaveBands(tile_rotation=0.0),
                                   WaveBands(k_edges=(3.0, 5.0, 9.0), tile_size=64, inner_radius=5.0)])
def test_band_covariance_is_the_lattice_sum(bands):
    """band_covariance = Σ over the band's discrete modes of F(k, φ) Δk² k kᵀ × (2 + cos θx)(2 + cos θy)/9
    (the position-averaged bilinear factor), in the world frame for wind_direction 0.7 rad."""
    field = WaveField(torch.tensor([9.0, 14.0], dtype=torch.float64), [0, 1], wind_direction=0.7, dtype=torch.float64, bands=bands)
    for b, wind in enumerate((9.0, 14.0)):
        ref = _lattice_covariance(bands, wind, 0.7)
        torch.testing.assert_close(field.band_covariance()[b], ref, rtol=1e-10, atol=1e-12 * float(ref.abs().max()))
    assert field.band_wavenumber.shape == (bands.n_bands,)
    torch.testing.assert_close(field.band_wavenumber[0], torch.tensor(math.sqrt(bands.k_edges[0] * bands.k_edges[1]), dtype=torch.float64))


def test_bilinear_correction_on_a_coarse_tile():
    """On a coarse tile the interpolation loss is large (modes up to θ = 1.57 rad per texel): the sampled
    slope variance at uniform random points matches band_covariance (which includes the factor) to
    3 % (> 4 standard errors over 150 seeds), while the uncorrected lattice sum is more than 10 % off."""
    bands = WaveBands(k_edges=(2.0, 4.0), tile_size=64, inner_radius=8.0)  # ~600 modes, θ ≤ 16·2π/64
    n_seeds, npts = 150, 4096
    field = WaveField(torch.full((n_seeds,), 10.0), list(range(n_seeds)), wind_direction=0.3, dtype=torch.float32, bands=bands)
    gen = torch.Generator().manual_seed(11)
    side = bands.tile_length[0]
    x = torch.rand(n_seeds, npts, generator=gen) * side
    y = torch.rand(n_seeds, npts, generator=gen) * side
    out = field.sample(x, y, time_s=0.0, elevation=False)
    cov = field.band_covariance()[:, 0].double()
    for c, key in enumerate(("slope_x", "slope_y")):
        err = out[key].double().pow(2).mean(1) / cov[:, c] - 1
        mean, se = float(err.mean()), float(err.std() / math.sqrt(n_seeds))
        assert 4 * se < 0.03 and abs(mean) < 0.03, (key, mean, se)
    uncorrected = _lattice_covariance(bands, 10.0, 0.3, bilinear=False)[0]
    assert float(uncorrected[0] / cov[0, 0]) > 1.10


def test_a_turned_band_travels_downwind_along_its_own_axis():
    """Band 1 of the layout (0.125–0.5–0.505 rad/m, inner radius 4) is turned by the golden angle α = 137.5°
    and holds only the lattice modes (±4, 0), (0, ±4) along its tile's axes: k = 4Δk û, û = (cos α, sin α),
    and 4Δk v̂. The slope along û, s_û = s_x cos α + s_y sin α, sees only the (±4, 0) pair (k ∥ û: a plane
    wave along û). With the wind 0.3 rad off û (upwind axis at α + π + 0.3) that wave travels downwind,
    along +û at its phase speed c = ω(k)/k: s_û(x + c t û, t) = s_û(x, 0) on the band's texel nodes (no
    interpolation), and not upwind. Band 1 alone: the field at every band minus the field at a footprint
    that keeps band 0 whole and band 1 out. (Planted, the travel signs taken from the tile's indices, not
    the world wavevector: the wave runs along −û and the test fails.)"""
    k1 = 0.5
    bands = WaveBands(k_edges=(k1 / 4, k1, 1.01 * k1))
    alpha = bands.tile_angle[1]
    assert abs(math.degrees(alpha) - 137.5) < 0.1  # the default turn (band 1: once the golden angle)
    field = WaveField(10.0, 7, wind_direction=alpha + math.pi + 0.3, dtype=torch.float64, bands=bands)
    c = float(dispersion(torch.tensor(k1, dtype=torch.float64))) / k1
    h = bands.tile_length[1] / bands.tile_size
    shift, t = 5 * h, 5 * h / c
    ux, uy, vx, vy = math.cos(alpha), math.sin(alpha), -math.sin(alpha), math.cos(alpha)
    u = torch.arange(128, dtype=torch.float64)[None] * h  # texel nodes: u = m h, v = 3 h
    keep0 = torch.full_like(u, math.pi / (math.sqrt(2.0) * bands.band_wavenumber[0]) * (1 + 1e-9))

    def s_u(along: float, time: float) -> torch.Tensor:
        x, y = (u + along) * ux + 3 * h * vx, (u + along) * uy + 3 * h * vy
        full, low = field.sample(x, y, time, elevation=False), field.sample(x, y, time, footprint=keep0, elevation=False)
        return (full["slope_x"] - low["slope_x"]) * ux + (full["slope_y"] - low["slope_y"]) * uy

    s0 = s_u(0.0, 0.0)
    scale = float(s0.abs().max())
    assert scale > 0
    torch.testing.assert_close(s_u(shift, t), s0, rtol=0, atol=1e-9 * scale)
    assert float((s_u(0.0, t) - s0).abs().max()) > 0.5 * scale  # it did move
    assert float((s_u(-shift, t) - s0).abs().max()) > 0.5 * scale  # not upwind

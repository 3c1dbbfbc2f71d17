"""The wave spectrum (roughsea_torch.spectrum, Elfouhaily et al. 1997 = ECKV) against published facts.

Each test asserts a fact that a wrong implementation would break; the sources of the reference values
are given next to them. Single-threaded (restored afterwards): small calls, steady timings on a shared
2-core machine.
"""

from __future__ import annotations

import math

import pytest
import torch

from roughsea_torch.spectrum import (
    C_M,
    GRAVITY,
    K_M,
    dispersion,
    elfouhaily_omnidirectional,
    elfouhaily_spectrum,
    elfouhaily_spreading,
)

pytestmark = pytest.mark.usefixtures("one_thread")


def _trapz(f: torch.Tensor, k: torch.Tensor) -> float:
    return float(torch.trapezoid(f, k))


def _w125(u10: float) -> float:
    """Wind at 12.5 m (Cox & Munk's anemometer) from U10 by the log profile with ECKV's z0 (Eq. 66)."""
    z0 = 3.7e-5 * u10**2 / GRAVITY * 0.84**0.9
    return u10 * math.log(12.5 / z0) / math.log(10.0 / z0)


K = torch.logspace(-4, 4, 200_001, dtype=torch.float64)


@pytest.mark.parametrize("u10", [5.0, 10.0, 20.0])
def test_omnidirectional_peak_at_kp(u10):
    """ECKV Eq. 3: k_p = g Ω_c²/U10² (Ω_c = 0.84). The maximum of S(k) lies 2.3 % below k_p, pulled
    down by the long-wave side factor exp(−Ω/√10 (√(k/k_p) − 1)) of Eq. 32; 5 % tolerance."""
    kp = GRAVITY * 0.84**2 / u10**2
    s = elfouhaily_omnidirectional(K, u10)
    k_peak = float(K[s.argmax()])
    assert abs(k_peak / kp - 1.0) < 0.05
    assert 0.0 < float(s[K < 0.5 * kp].max()) < 0.2 * float(s.max())  # a single, sharp peak


@pytest.mark.parametrize("u10", [5.0, 10.0, 20.0])
def test_significant_height_near_pierson_moskowitz(u10):
    """Fully developed sea (Ω_c = 0.84): Hs = 4 √∫S dk against Pierson & Moskowitz (1964).

    PM: S(f) = α g² (2π)⁻⁴ f⁻⁵ exp(−β (f₀/f)⁴), α = 0.0081, β = 0.74, f₀ = g / (2π U19.5), so
    ⟨η²⟩ = α U19.5⁴ / (4 β g²) and Hs = 0.2092 U19.5²/g; U19.5 = 1.026 U10 (Mobley, Ocean Optics Web
    Book, "Wave variance spectra: examples"). ECKV's long-wave branch is JONSWAP-shaped (γ = 1.7 even
    when fully developed, Eq. 3) with α_p = 6e-3 √Ω (Eq. 34), not PM's α, so it need not coincide:
    measured +13 % (long-wave part) to +16 % (with the short-wave part). Tolerance ±20 %; a factor 2
    in the variance normalization would move Hs by 41 %.
    """
    hs = 4.0 * math.sqrt(_trapz(elfouhaily_omnidirectional(K, u10), K))
    hs_pm = 0.2092 * (1.026 * u10) ** 2 / GRAVITY
    assert abs(hs / hs_pm - 1.0) < 0.20


@pytest.mark.parametrize("u10", [5.0, 10.0, 15.0])
@pytest.mark.parametrize("k_max", [1e3, 1e4])
def test_mean_square_slope_within_cox_munk(u10, k_max):
    """Slope variances against Cox & Munk (1954, clean surface, W at 12.5 m):
    total 0.003 + 5.12e-3 W ± 0.004, upwind 3.16e-3 W ± 0.004, crosswind 0.003 + 1.92e-3 W ± 0.002.

    ECKV's short-wave level α_m (Eq. 44) was set so that the spectrum agrees with Cox & Munk's in situ
    slopes (ECKV abstract: the criteria include "agreement with in situ observations of Cox and Munk
    [1954]"). Tolerance: twice CM's quoted scatter. Measured (k ≤ 1e3): total +0.003/+0.006/+0.002
    at 5/10/15 m/s. Upwind and crosswind come from integrating the directional F(k, φ) over φ, so the
    spreading (Eq. 57) and its normalization are tested too; upwind must exceed crosswind.
    """
    w = _w125(u10)
    k = torch.logspace(-3, math.log10(k_max), 4001, dtype=torch.float64)
    phi = torch.arange(64, dtype=torch.float64) * (2 * math.pi / 64)
    f = elfouhaily_spectrum(k[:, None], phi[None, :], u10)  # φ from downwind
    dphi = 2 * math.pi / 64
    up = _trapz(k**3 * (f * torch.cos(phi) ** 2).sum(1) * dphi, k)
    cross = _trapz(k**3 * (f * torch.sin(phi) ** 2).sum(1) * dphi, k)
    total = _trapz(k**2 * elfouhaily_omnidirectional(k, u10), k)
    assert up + cross == pytest.approx(total, rel=1e-9)
    assert up > 1.2 * cross
    assert abs(total - (0.003 + 5.12e-3 * w)) <= 2 * 0.004
    assert abs(up - 3.16e-3 * w) <= 2 * 0.004
    assert abs(cross - (0.003 + 1.92e-3 * w)) <= 2 * 0.002


def test_spreading_integrates_to_one(dtype):
    """(1 + Δ cos 2φ)/(2π) integrates to 1 over [0, 2π) (ECKV Eq. 49): ∫ F(k, φ) k dφ = S(k)."""
    k = torch.logspace(-3, 3.5, 57, dtype=dtype)
    phi = torch.arange(32, dtype=dtype) * (2 * math.pi / 32)
    f = elfouhaily_spectrum(k[:, None], phi[None, :], 12.0)
    s = elfouhaily_omnidirectional(k, 12.0)
    assert f.dtype == dtype
    torch.testing.assert_close((f * k[:, None]).sum(1) * (2 * math.pi / 32), s, rtol=1e-5 if dtype == torch.float32 else 1e-12, atol=0)
    delta = elfouhaily_spreading(k, 12.0)
    assert bool(((delta > 0) & (delta <= 1)).all())
    # long waves are narrow (Δ → 1), short gravity waves broader
    assert float(delta[0]) > 0.99 and float(delta[torch.argmin((k - 30.0).abs())]) < 0.6


def test_dispersion_capillary_minimum():
    """ω² = g k (1 + (k/k_m)²): phase speed minimum √(2 g / k_m) ≈ 0.23 m/s at k_m (ECKV Eq. 24)."""
    k = torch.tensor([0.5 * K_M, K_M, 2.0 * K_M], dtype=torch.float64)
    c = dispersion(k) / k
    assert float(c[1]) == pytest.approx(C_M, abs=1e-3)
    assert float(c[1]) < float(c[0]) and float(c[1]) < float(c[2])
    assert float(dispersion(torch.tensor(0.01, dtype=torch.float64))) == pytest.approx(math.sqrt(GRAVITY * 0.01), rel=1e-8)


def test_spectrum_errors():
    with pytest.raises(ValueError, match=r"k must lie in \(0, inf\]"):
        elfouhaily_spectrum(0.0, 0.0, 10.0)
    with pytest.raises(ValueError, match="phi"):
        elfouhaily_spectrum(1.0, float("nan"), 10.0)
    with pytest.raises(ValueError, match="wind_speed"):
        elfouhaily_omnidirectional(1.0, 0.0)

"""The wave spectrum (roughsea_torch.spectrum, Elfouhaily et al. 1997 = ECKV) against published facts.

Each test asserts a fact that a wrong implementation would break; the sources of the reference values
are given next to them. Single-threaded (restored afterwards): small calls, steady timings on a shared
2-core machine.
"""

from __future__ import annotations

import math

import numpy as np
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


def test_phase_speed_is_smallest_at_k_m_and_follows_eq_24():
    """c(k) = ω/k of ω² = g k (1 + (k/k_m)²) has its only minimum at k = k_m, where c = √(2g/k_m);
    on a dense grid over 0.3–3 k_m the smallest c is at k_m to the grid's spacing, and ω(2 k_m)² =
    10 g k_m (the capillary term, (k/k_m)² = 4, is 4× the gravity term there)."""
    k = torch.linspace(0.3, 3.0, 2701, dtype=torch.float64) * K_M
    c = dispersion(k) / k
    k_min = float(k[torch.argmin(c)])
    assert abs(k_min / K_M - 1.0) < 1e-3
    assert abs(float(c.min()) - math.sqrt(2.0 * GRAVITY / K_M)) < 1e-9
    w2 = float(dispersion(torch.tensor(2.0 * K_M, dtype=torch.float64))) ** 2
    assert abs(w2 / (10.0 * GRAVITY * K_M) - 1.0) < 1e-12


def _eckv_numpy(k, u10, omega_c):
    """S(k) and Δ(k) of Elfouhaily et al. (1997), transcribed in numpy from the paper's equations (as
    listed in the module docstring, with its two documented deviations: F_m × L_PM and α_m ≥ 0)."""
    g, k_m, c_m = 9.81, 370.0, 0.23
    c = np.sqrt(g / k * (1 + (k / k_m) ** 2))  # Eq. 24
    k_p = g * omega_c**2 / u10**2  # Eq. 3
    c_p = np.sqrt(g / k_p * (1 + (k_p / k_m) ** 2))
    big_omega = u10 / c_p
    alpha_p = 6e-3 * np.sqrt(big_omega)  # Eq. 34
    gamma = 1.7 if omega_c < 1 else 1.7 + 6 * np.log10(omega_c)  # Eq. 3
    sigma = 0.08 * (1 + 4 / omega_c**3)  # Eq. 3
    big_gamma = np.exp(-((np.sqrt(k / k_p) - 1) ** 2) / (2 * sigma**2))
    l_pm = np.exp(-1.25 * (k_p / k) ** 2)  # Eq. 2
    f_p = l_pm * gamma**big_gamma * np.exp(-big_omega / np.sqrt(10) * (np.sqrt(k / k_p) - 1))  # Eq. 32
    b_l = 0.5 * alpha_p * (c_p / c) * f_p  # Eq. 31
    z_0 = 3.7e-5 * u10**2 / g * big_omega**0.9  # Eq. 66
    u_star = 0.41 * u10 / np.log(10 / z_0)  # Eq. 60
    alpha_m = 1e-2 * (1 + np.log(u_star / c_m)) if u_star <= c_m else 1e-2 * (1 + 3 * np.log(u_star / c_m))  # Eq. 44
    alpha_m = max(alpha_m, 0.0)
    f_m = l_pm * np.exp(-0.25 * (k / k_m - 1) ** 2)  # Eq. 41 (× L_PM)
    b_h = 0.5 * alpha_m * (c_m / c) * f_m  # Eq. 40
    a_m = 0.13 * u_star / c_m  # Eq. 59
    delta = np.tanh(np.log(2) / 4 + 4 * (c / c_p) ** 2.5 + a_m * (c_m / c) ** 2.5)  # Eq. 57
    return (b_l + b_h) / k**3, delta  # Eq. 30


@pytest.mark.parametrize("u10", [2.0, 5.0, 10.0, 25.0])
@pytest.mark.parametrize("omega_c", [0.84, 0.999, 1.005, 2.0, 5.0])
def test_eckv_spectrum_and_spreading_follow_the_papers_equations(u10, omega_c):
    """elfouhaily_omnidirectional and elfouhaily_spreading against ECKV's equations transcribed
    independently in numpy, from below the peak to the capillary range (k = 10⁻³–10⁴ rad/m), for
    light to strong winds and wave ages either side of γ's switch at Ω_c = 1."""
    k = np.logspace(-3, 4, 400)
    s_ref, d_ref = _eckv_numpy(k, u10, omega_c)
    kt = torch.as_tensor(k)
    s = elfouhaily_omnidirectional(kt, u10, omega_c).numpy()
    d = elfouhaily_spreading(kt, u10, omega_c).numpy()
    np.testing.assert_allclose(d, d_ref, rtol=1e-12, atol=0)
    big = s_ref > 1e-300  # the spectrum underflows far below the peak (L_PM)
    np.testing.assert_allclose(s[big], s_ref[big], rtol=1e-11, atol=0)

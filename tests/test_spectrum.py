"""roughsea_torch.spectrum: the ECKV spectrum (Elfouhaily et al. 1997) and the dispersion relation (Eq. 24)."""

from __future__ import annotations

import math

import numpy as np
import pytest
import torch

from roughsea_torch.spectrum import GRAVITY, K_M, dispersion, elfouhaily_omnidirectional, elfouhaily_spreading


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

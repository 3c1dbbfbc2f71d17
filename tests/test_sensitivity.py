"""``pixel_derivative`` (roughsea_torch.sensitivity: per-pixel d image / d parameter) against
derivatives known in closed form: dL/dT of Planck's law integrated over the band (constants typed in),
and d(a w²)/dw; and against central differences of a render, pixel by pixel."""

from __future__ import annotations

import math
import warnings

import pytest
import torch
from scipy import integrate

import roughsea_torch as rs

from conftest import C, H, KB, make_cams, make_scene, smooth_sky


def dplanck_band_dT(T: float, lo: float = 8e-6, hi: float = 12e-6) -> float:
    """∫ ∂B_λ/∂T dλ, ∂B/∂T = B · x e^x / (T (e^x − 1)), x = hc/(λ k T)."""

    def f(lam: float) -> float:
        x = H * C / (lam * KB * T)
        return 2 * H * C * C / lam**5 * x * math.exp(x) / (T * math.expm1(x) ** 2)

    return integrate.quad(f, lo, hi, epsabs=0.0, epsrel=1e-12)[0]


def test_pixel_derivative_of_band_radiance_images_is_planck_slope():
    """Images L(T_b + offset) with one sea temperature per image (B,): each image's map is its own
    dL/dT, and a scalar parameter shared by the images gives every pixel its slope."""
    T = torch.tensor([280.0, 300.0], dtype=torch.float64, requires_grad=True)
    offsets = torch.linspace(-5.0, 5.0, 12, dtype=torch.float64).reshape(1, 1, 3, 4)
    images = rs.band_radiance(T[:, None, None, None] + offsets)
    d = rs.pixel_derivative(images, T)
    assert d.shape == images.shape
    for b in range(2):
        for k, off in enumerate(offsets.flatten().tolist()):
            want = dplanck_band_dT(float(T[b].detach()) + off)
            assert abs(float(d[b].flatten()[k]) / want - 1) < 1e-9
    w = torch.tensor(3.0, dtype=torch.float64, requires_grad=True)
    coeff = torch.arange(1.0, 7.0, dtype=torch.float64).reshape(1, 1, 2, 3)
    torch.testing.assert_close(rs.pixel_derivative(coeff * w**2, w), coeff * 2 * 3.0, rtol=1e-14, atol=0)


def test_pixel_derivative_unused_parameter_and_errors():
    w = torch.tensor(2.0, requires_grad=True)
    v = torch.tensor(5.0, requires_grad=True)
    img = (v * torch.ones(1, 1, 2, 2)) ** 2
    assert torch.equal(rs.pixel_derivative(img, w), torch.zeros_like(img))
    with pytest.raises(ValueError, match="parameter"):
        rs.pixel_derivative(img, torch.tensor(1.0))


def test_pixel_derivative_matches_finite_differences_per_pixel():
    """Per-pixel dT_b/dW by the double-backward JVP equals central differences, pixel by pixel."""
    def bt(w):
        cams = make_cams(16, 20, hfov_deg=25.0, altitude_m=15.0, pitch_deg=-4.0)
        return rs.render(cams, make_scene(wind_speed=w, wind_direction=0.6, sea_temperature=291.0, sky=smooth_sky),
                         output="brightness_temperature")

    w = torch.tensor(8.0, dtype=torch.float64, requires_grad=True)
    d = rs.pixel_derivative(bt(w), w)
    fd = (bt(torch.tensor(8.001, dtype=torch.float64)) - bt(torch.tensor(7.999, dtype=torch.float64))) / 0.002
    torch.testing.assert_close(d, fd, rtol=1e-4, atol=1e-7)
    assert d.abs().max() > 0.05  # wind matters to these sea pixels


def _bt(wind, anisotropic=True, method="direct"):
    # 11 columns: the middle one looks exactly upwind (yaw 0 looks along +x, the upwind axis)
    cams = rs.make_camera(9, 11, hfov_deg=15.0, altitude_m=20.0, pitch_deg=-3.0, dtype=torch.float64)
    return rs.render(cams, rs.SeaScene(wind_speed=wind, anisotropic=anisotropic, sea_temperature=290.0),
                     output="brightness_temperature", method=method)


def test_wind_gradient_at_a_calm_sea_warns_that_it_is_not_a_derivative():
    """At W = 0 the anisotropic law's upwind variance vanishes: along the wind axis autograd's wind
    gradient is 0 where a one-sided finite difference converges to about −4.7 K per m/s (the square
    root of the rms slope has no derivative to follow), and the table method's is ~1e3 K per m/s off
    the axis. Asking for it warns; W = 0.1, isotropic slopes and no gradient do not."""
    w = torch.tensor(0.0, dtype=torch.float64, requires_grad=True)
    with pytest.warns(UserWarning, match="is not the derivative"):
        img = _bt(w)
    auto = rs.pixel_derivative(img, w)[0, 0, 5, 5]
    zero = _bt(torch.tensor(0.0, dtype=torch.float64))
    fd = [float(((_bt(torch.tensor(h, dtype=torch.float64)) - zero) / h)[0, 0, 5, 5]) for h in (1e-5, 1e-6)]
    assert abs(fd[0] - fd[1]) < 1e-2 * abs(fd[1]) and abs(fd[1]) > 1.0  # the one-sided derivative exists
    assert math.isfinite(float(auto)) and abs(float(auto) - fd[1]) > 1.0  # autograd does not give it
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        _bt(torch.tensor(0.1, dtype=torch.float64, requires_grad=True))
        _bt(torch.tensor(0.0, dtype=torch.float64, requires_grad=True), anisotropic=False)
        _bt(torch.tensor(0.0, dtype=torch.float64))  # no gradient asked for


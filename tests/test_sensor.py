"""The sensor model (roughsea_torch.sensor): blur, ADC, display, and the chain of stages. (The random
stages, temporal noise and fixed pattern: tests/test_sensor_noise.py.)

Statistical tolerances are set from the sample size N: the sample standard deviation of N normal
draws has a relative standard error 1/√(2(N − 1)), and a sample mean σ/√N; every bound below is at
least 5 such standard errors, with seeded generators so that the tests are deterministic anyway.
"""

from __future__ import annotations

import pytest
import torch

import roughsea_torch as rs
from roughsea_torch.radiometry import LWIR, band_radiance
from roughsea_torch.sensor import (
    DetectorNoise,
    FixedPatternNoise,
    OpticsBlur,
    SensorModel,
    ToCounts,
    ToDisplay,
    counts_to_radiance,
    optics_blur,
    radiance_to_counts,
    to_display,
)

from conftest import eps, gen, radiance_image


# ------------------------------------------------------------------------------------------------
# OpticsBlur
# ------------------------------------------------------------------------------------------------
def test_blur_conserves_mean_reduces_variance_and_keeps_constants(dtype, device):
    """Content farther from the border than the kernel radius keeps its sum exactly (normalized
    kernel); a noise image loses variance; a constant image is unchanged (reflected border)."""
    sigma = 1.5  # kernel 2⌈4σ⌉ + 1 = 13, radius 6 < the 12-pixel margin below
    x = torch.zeros(2, 1, 48, 48, dtype=dtype, device=device)
    x[:, :, 12:36, 12:36] = 10.0 + torch.rand(2, 1, 24, 24, generator=gen(0), dtype=dtype).to(device)
    x0 = x.clone()
    y = optics_blur(x, sigma)
    assert torch.equal(x, x0)  # input not edited
    assert y.shape == x.shape and y.dtype == dtype and y.device.type == device.type
    torch.testing.assert_close(y.sum((1, 2, 3)), x.sum((1, 2, 3)), rtol=50 * eps(dtype), atol=0.0)
    assert not torch.equal(y, x)

    noise = torch.randn(2, 1, 48, 48, generator=gen(1), dtype=dtype).to(device)
    assert (OpticsBlur(sigma)(noise).var((1, 2, 3)) < 0.2 * noise.var((1, 2, 3))).all()

    const = torch.full((2, 3, 17, 9), 38.5, dtype=dtype, device=device)
    torch.testing.assert_close(OpticsBlur(0.7)(const), const, rtol=10 * eps(dtype), atol=0.0)


@pytest.mark.parametrize("sigma", [0.7, 1.5])
def test_blur_point_spread_has_the_given_width(sigma):
    """The PSF of a point source has second moment σ² per axis (to the kernel's truncation at
    ~4σ and its sampling) and unit sum: the blur width is σ pixels, not merely 'some blur'."""
    x = torch.zeros(1, 1, 41, 41, dtype=torch.float64)
    x[..., 20, 20] = 1.0
    y = optics_blur(x, sigma)[0, 0]
    r = torch.arange(41, dtype=torch.float64) - 20
    torch.testing.assert_close(y.sum(), torch.tensor(1.0, dtype=torch.float64), rtol=1e-12, atol=0)
    var_x = float((y.sum(0) * r**2).sum())
    var_y = float((y.sum(1) * r**2).sum())
    assert abs(var_x / sigma**2 - 1) < 0.02 and abs(var_y / sigma**2 - 1) < 0.02


def test_blur_per_image_sigma_matches_a_loop_and_zero_is_identity(dtype, device):
    x = torch.rand(3, 2, 20, 24, generator=gen(2), dtype=dtype).to(device)
    sigma = torch.tensor([0.0, 0.7, 2.0], dtype=dtype, device=device)
    y = optics_blur(x, sigma, kernel_size=15)
    for i in range(3):
        yi = optics_blur(x[i : i + 1], float(sigma[i]), kernel_size=15)
        torch.testing.assert_close(y[i : i + 1], yi, rtol=10 * eps(dtype), atol=10 * eps(dtype))
    assert torch.equal(y[0], x[0])  # σ = 0: the unit impulse
    assert torch.equal(optics_blur(x, 0.0), x)
    # the automatic kernel never exceeds what a reflected border allows on a tiny image
    assert optics_blur(x[:, :, :3, :4], 5.0).shape == (3, 2, 3, 4)


def test_blur_gradcheck_image_and_sigma():
    x = torch.rand(2, 1, 7, 8, dtype=torch.float64, generator=gen(3)).requires_grad_()
    s = torch.tensor([0.8, 1.3], dtype=torch.float64, requires_grad=True)
    assert torch.autograd.gradcheck(lambda a, b: optics_blur(a, b, kernel_size=5), (x, s), fast_mode=True)


# ------------------------------------------------------------------------------------------------
# ToCounts
# ------------------------------------------------------------------------------------------------
def test_to_counts_values_clamp_and_inverse(dtype, device):
    adc = ToCounts(bits=14, temperature_range=(250.0, 330.0))
    L64 = band_radiance(torch.tensor([250.0, 300.0, 330.0], dtype=torch.float64))
    expect_300 = round(((L64[1] - L64[0]) / (L64[2] - L64[0]) * 16383).item())  # 8579.98 → 8580
    T = torch.tensor([200.0, 250.0, 300.0, 330.0, 400.0], dtype=dtype, device=device)
    c = adc(band_radiance(T).view(1, 1, 1, 5))
    assert c.dtype == dtype and c.device.type == device.type
    assert c.flatten().tolist() == [0.0, 0.0, float(expect_300), 16383.0, 16383.0]
    assert adc.full_scale == 16383

    T = 255.0 + 70.0 * torch.rand(2, 1, 30, 30, generator=gen(0), dtype=torch.float64)
    L = band_radiance(T).to(dtype=dtype, device=device)
    c = adc(L)
    assert torch.equal(c, c.round()) and c.min() > 0 and c.max() < 16383
    err_counts = (adc.counts_to_radiance(c) - L).abs() * adc.gain
    assert err_counts.max().item() <= 0.5 + 16383 * 4 * eps(dtype)
    # integer counts (as a camera delivers them) are accepted by the inverse
    back = counts_to_radiance(c.to(torch.int32), adc.gain, adc.offset)
    torch.testing.assert_close(back.double(), adc.counts_to_radiance(c).double(), rtol=2 * eps(torch.float32), atol=0.0)

    assert ToCounts(bits=8)(band_radiance(torch.full((1, 1, 1, 1), 400.0, dtype=dtype))).item() == 255.0
    same = ToCounts(radiance_range=(L64[0].item(), L64[2].item()))
    assert same.gain == pytest.approx(adc.gain, rel=1e-14) and same.offset == pytest.approx(adc.offset, rel=1e-12)


def test_to_counts_straight_through_gradient(dtype, device):
    adc = ToCounts()
    L = band_radiance(torch.tensor([200.0, 260.0, 300.0, 320.0, 400.0], dtype=dtype, device=device))
    L = L.view(1, 1, 1, 5).requires_grad_()
    adc(L).sum().backward()
    g = L.grad.flatten()
    assert torch.isfinite(g).all()
    torch.testing.assert_close(g[1:4], torch.full_like(g[1:4], adc.gain), rtol=eps(dtype), atol=0.0)
    assert g[0].item() == 0.0 and g[4].item() == 0.0  # clamped
    # the rounding-free ADC has the same gradient, and values differing by < 0.5 count
    Lf = L.detach()
    assert (radiance_to_counts(Lf, adc.gain, adc.offset, rounding=False) - adc(Lf)).abs().max() <= 0.5


# ------------------------------------------------------------------------------------------------
# ToDisplay
# ------------------------------------------------------------------------------------------------
def test_to_display_percentiles_monotone_and_range(dtype, device):
    """101 values per image: the 1st and 99th percentiles are exactly the 2nd and 100th values,
    which must map to 0 and 255; two images with different scales are stretched separately."""
    base = torch.arange(101, dtype=dtype, device=device)
    x = torch.stack([base, 1000.0 + torch.exp(base / 20.0)]).view(2, 1, 1, 101).flip(-1)
    y = ToDisplay(1.0, 99.0)(x)
    assert y.dtype == dtype and y.shape == x.shape
    assert y.min() == 0 and y.max() == 255 and torch.equal(y, y.round())
    for i in range(2):
        order = torch.argsort(x[i].flatten())
        yi = y[i].flatten()[order]
        assert (yi.diff() >= 0).all()  # monotone in the input
        assert yi[0] == 0 and yi[1] == 0 and yi[99] == 255 and yi[100] == 255
        assert 0 < yi[50] < 255
    u8 = to_display(x, output_dtype=torch.uint8)
    assert u8.dtype == torch.uint8 and torch.equal(u8.to(dtype), y)
    # agrees with torch.quantile on a random image (up to rounding ties)
    r = torch.rand(3, 2, 20, 30, generator=gen(0), dtype=dtype).to(device)
    q = torch.quantile(r.flatten(1), torch.tensor([0.05, 0.95], dtype=dtype, device=device), dim=1)
    lo, hi = q[0].view(3, 1, 1, 1), q[1].view(3, 1, 1, 1)
    ref = (255 * ((r - lo) / (hi - lo)).clamp(0, 1)).round()
    assert (to_display(r, 5.0, 95.0) - ref).abs().max() <= 1
    # a constant image gives 0, not NaN
    assert torch.equal(to_display(torch.ones(1, 1, 4, 4, dtype=dtype)), torch.zeros(1, 1, 4, 4, dtype=dtype))


def test_to_display_beyond_the_torch_quantile_limit():
    """2²⁴ + 2 pixels (torch.quantile refuses more than 2²⁴): the percentiles of the values
    0 … N − 1 (exact in float32 below 2²⁴) are p·(N − 1)."""
    n = 2**24 + 2
    x = torch.arange(n, dtype=torch.float32).flip(0).view(1, 1, 2, n // 2)
    y = to_display(x)
    lo, hi = 0.01 * (n - 1), 0.99 * (n - 1)
    assert y.min() == 0 and y.max() == 255
    assert (y[x <= lo] == 0).all() and (y[x >= hi] == 255).all()
    mid = x.flatten()[n // 2].item()
    assert y.flatten()[n // 2].item() == round(255 * (mid - lo) / (hi - lo))


# ------------------------------------------------------------------------------------------------
# SensorModel
# ------------------------------------------------------------------------------------------------
def test_sensor_model_reproducible_and_differentiable(dtype, device):
    L = radiance_image(dtype, device)
    sensor = SensorModel.typical_lwir()
    a = sensor(L, generator=gen(0))
    assert a.dtype == dtype and a.shape == L.shape and a.device.type == device.type
    assert torch.equal(a, sensor(L, generator=gen(0)))  # bitwise
    assert torch.equal(a, SensorModel.typical_lwir()(L, generator=gen(0)))
    assert not torch.equal(a, sensor(L, generator=gen(1)))
    assert torch.equal(a, a.round()) and a.min() >= 0 and a.max() <= 16383
    Lg = L.clone().requires_grad_()
    sensor(Lg, generator=gen(0)).sum().backward()
    assert torch.isfinite(Lg.grad).all() and Lg.grad.abs().sum() > 0


def test_sensor_model_stages_none_and_composition(dtype, device):
    L = radiance_image(dtype, device)
    assert torch.equal(SensorModel()(L, generator=gen(0)), L)  # all None: identity
    adc = ToCounts()
    assert torch.equal(SensorModel(counts=adc)(L), adc(L))
    blur, noise, fpn, disp = OpticsBlur(1.0), DetectorNoise(0.08), FixedPatternNoise(seed=2), ToDisplay()
    chained = SensorModel(blur, noise, fpn, adc, disp)(L, generator=gen(4))
    by_hand = disp(adc(fpn(noise(blur(L), generator=gen(4)))))
    assert torch.equal(chained, by_hand)
    # any module works as a stage; one without a generator argument is called without it
    assert torch.equal(SensorModel(blur=torch.nn.Identity(), counts=adc)(L, generator=gen(0)), adc(L))
    # without temporal noise the chain is deterministic and batched equals looped
    quiet = SensorModel(blur=OpticsBlur(0.7), fixed_pattern=FixedPatternNoise(), counts=ToCounts())
    looped = torch.cat([quiet(L[i : i + 1]) for i in range(L.shape[0])])
    torch.testing.assert_close(quiet(L), looped, rtol=0, atol=1.0)  # counts: at most one rounding step apart


@pytest.mark.parametrize(
    "make, name",
    [
        (lambda: OpticsBlur(sigma_px=-1.0), "sigma_px"),
        (lambda: OpticsBlur(sigma_px=float("nan")), "sigma_px"),
        (lambda: OpticsBlur(kernel_size=4), "kernel_size"),
        (lambda: optics_blur(torch.ones(2, 1, 8, 8), torch.ones(3)), "sigma_px"),
        (lambda: optics_blur(torch.ones(1, 1, 4, 4), 1.0, kernel_size=9), "kernel_size"),
        (lambda: ToCounts(bits=0), "bits"),
        (lambda: ToCounts(bits=32), "bits"),
        (lambda: ToCounts(gain=10.0), "offset"),
        (lambda: ToCounts(gain=-1.0, offset=0.0), "gain"),
        (lambda: ToCounts(temperature_range=(330.0, 250.0)), "temperature_range"),
        (lambda: ToCounts(radiance_range=(1.0,)), "radiance_range"),
        (lambda: ToDisplay(low_percentile=99.0, high_percentile=1.0), "low_percentile"),
        (lambda: ToDisplay(high_percentile=101.0), "high_percentile"),
        (lambda: ToDisplay(output_dtype=torch.int16), "output_dtype"),
        (lambda: SensorModel(blur=lambda x: x), "blur"),
        (lambda: SensorModel()(torch.ones(1, 8, 8)), "radiance"),
        (lambda: SensorModel()(torch.ones(1, 1, 8, 8, dtype=torch.float16)), "radiance"),
        (lambda: ToCounts()([[1.0]]), "radiance"),
        (lambda: to_display(torch.ones(4, 4)), "image"),
    ],
)
def test_bad_arguments_raise_value_error_naming_the_argument(make, name):
    with pytest.raises(ValueError, match=name):
        make()


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


def test_to_display_over_the_full_range_is_the_min_max_stretch():
    """low_percentile = 0 and high_percentile = 100 (the documented ends of their range) are the
    image's minimum and maximum: the stretch is round(255 (x − min)/(max − min)) per image, the
    minimum at 0 and the maximum at 255."""
    x = torch.rand(2, 1, 9, 11, generator=gen(4), dtype=torch.float64) * torch.tensor([1.0, 30.0]).view(2, 1, 1, 1)
    lo, hi = x.amin((1, 2, 3), keepdim=True), x.amax((1, 2, 3), keepdim=True)
    torch.testing.assert_close(to_display(x, 0.0, 100.0), torch.round(255.0 * (x - lo) / (hi - lo)), rtol=0, atol=0)

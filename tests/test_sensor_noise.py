"""The sensor's random stages (roughsea_torch.sensor_noise): temporal noise with the NETD in kelvin
per pixel or at a reference temperature, the noise-equivalent radiance, the fixed pattern; seeded and
reproducible, per image.

Statistical tolerances are set from the sample size N: the sample standard deviation of N normal
draws has a relative standard error 1/√(2(N − 1)), and a sample mean σ/√N; every bound below is at
least 5 such standard errors, with seeded generators so that the tests are deterministic anyway.
"""

from __future__ import annotations

import math

import pytest
import torch

from roughsea_torch.radiometry import LWIR, MWIR, band_radiance, brightness_temperature
from roughsea_torch.sensor import SensorModel
from roughsea_torch.sensor_noise import (
    DetectorNoise,
    FixedPatternNoise,
    detector_noise,
    noise_equivalent_radiance,
)

from conftest import eps, gen, radiance_image, uniform_image


# ------------------------------------------------------------------------------------------------
# DetectorNoise
# ------------------------------------------------------------------------------------------------
@pytest.mark.parametrize("band", [LWIR, MWIR], ids=["LWIR", "MWIR"])
def test_detector_noise_has_the_netd_in_kelvin_and_zero_mean(dtype, device, band):
    """Uniform 300 K image, N = 65 536 pixels: the std of the brightness temperature of the noisy
    image is the NETD (relative standard error 1/√(2N) = 0.28 %; bound 2 % ≈ 7 s.e.), and the
    noise mean is within 5 σ/√N of zero."""
    netd = 0.05
    L = uniform_image(300.0, (4, 1, 128, 128), dtype, device, band)
    y = DetectorNoise(netd_k=netd, band=band)(L, generator=gen(0))
    n = L.numel()
    T = brightness_temperature(y, band).double()
    assert abs(T.std().item() / netd - 1.0) < 0.02
    sigma_L = noise_equivalent_radiance(netd, 300.0, band).item()
    assert abs((y - L).double().mean().item()) < 5 * sigma_L / math.sqrt(n)
    assert abs(T.mean().item() - 300.0) < 5 * netd / math.sqrt(n) + 1e-4


def test_detector_noise_per_pixel_versus_reference_temperature(dtype, device):
    """Per-pixel mode: the noise is NETD in kelvin on a cold and a hot half alike; with a fixed
    reference temperature the noise is one radiance σ = NETD·dL/dT(T_ref) everywhere (so more
    kelvin on the cold half). Halves of 32 768 pixels: 2.8 % bound ≈ 7 s.e."""
    netd = 0.05
    T = torch.cat([torch.full((2, 1, 128, 64), 260.0), torch.full((2, 1, 128, 64), 320.0)], dim=-1)
    L = band_radiance(T.to(dtype=dtype, device=device))
    y = detector_noise(L, netd, generator=gen(1))
    Tb = brightness_temperature(y).double()
    for half in (Tb[..., :64], Tb[..., 64:]):
        assert abs(half.std().item() / netd - 1.0) < 0.028
    y_ref = DetectorNoise(netd, reference_temperature=300.0)(L, generator=gen(1))
    sigma_ref = noise_equivalent_radiance(netd, 300.0).item()
    for half in ((y_ref - L)[..., :64], (y_ref - L)[..., 64:]):
        assert abs(half.double().std().item() / sigma_ref - 1.0) < 0.028
    # same draws, scaled: the ratio of the two noises is dL/dT(T_pixel) / dL/dT(300 K) exactly
    ratio = (y - L).double()[..., :64].std() / (y_ref - L).double()[..., :64].std()
    expect = (noise_equivalent_radiance(netd, 260.0) / sigma_ref).item()
    assert abs(ratio.item() / expect - 1.0) < 1e-3


def test_noise_equivalent_radiance_is_the_derivative_of_band_radiance():
    T = torch.tensor([250.0, 300.0, 330.0], dtype=torch.float64)
    h = 1e-3
    fd = (band_radiance(T + h) - band_radiance(T - h)) / (2 * h)
    torch.testing.assert_close(noise_equivalent_radiance(1.0, T), fd, rtol=1e-8, atol=0.0)
    assert noise_equivalent_radiance(0.05, torch.tensor(300.0, dtype=torch.float32)).dtype == torch.float32


def test_detector_noise_generator_reproducible_and_per_image_netd(dtype, device):
    L = uniform_image(290.0, (2, 1, 16, 16), dtype, device)
    a = detector_noise(L, generator=gen(5))
    assert torch.equal(a, detector_noise(L, generator=gen(5)))
    assert not torch.equal(a, detector_noise(L, generator=gen(6)))
    torch.manual_seed(7)
    b = detector_noise(L)
    torch.manual_seed(7)
    assert torch.equal(b, detector_noise(L))  # generator=None: the global RNG
    y = detector_noise(L, torch.tensor([0.0, 0.1], dtype=dtype), generator=gen(5))
    assert torch.equal(y[0], L[0]) and not torch.equal(y[1], L[1])


@pytest.mark.parametrize("band", [LWIR, MWIR], ids=["LWIR", "MWIR"])
def test_detector_noise_std_is_netd_times_the_exact_slope_per_pixel(dtype, band):
    """Same generator, same draws z: y − L = NETD · dL/dT(T) · z pixel by pixel, with dL/dT the
    band sum of ∂B/∂T (noise_equivalent_radiance) at each pixel's temperature, from 100 K to
    1200 K (above the sensor's 499 K table, too); below 100 K, at 100 K."""
    T = torch.cat([torch.linspace(100.0, 1200.0, 4999, dtype=torch.float64), torch.tensor([60.0])])
    L = band_radiance(T, band).to(dtype).view(1, 1, 100, 50)
    z = torch.randn(L.shape, generator=gen(4), dtype=dtype)
    netd = 10.0  # σ is linear in the NETD; a large one keeps the rounding of y = L + σz out of y − L
    y = detector_noise(L, netd, band=band, generator=gen(4))
    ok = z.abs() > 0.1
    sigma = ((y - L) / z)[ok].double()
    want = noise_equivalent_radiance(netd, T.clamp_min(100.0), band).view(L.shape)[ok]
    assert float(((sigma - want) / want).abs().max()) < 3e-5


def test_detector_noise_per_image_generators_match_each_image_alone(dtype):
    """A sequence of generators, one per image: the batch equals each image noised alone with its
    own generator, bit for bit (the noise of an image does not depend on its batch)."""
    L = radiance_image(dtype, "cpu", B=3, H=17, W=23)
    batch = detector_noise(L, generator=[gen(10), gen(11), gen(12)])
    alone = torch.cat([detector_noise(L[i : i + 1], generator=gen(10 + i)) for i in range(3)])
    assert torch.equal(batch, alone)
    assert not torch.equal(batch[0], batch[1] - L[1] + L[0])
    sensor = SensorModel.typical_lwir()
    a = sensor(L, generator=[gen(1), gen(2), gen(3)])
    assert torch.equal(a, sensor(L, generator=[gen(1), gen(2), gen(3)]))
    with pytest.raises(ValueError, match="generator"):
        sensor(L, generator=[gen(1), gen(2)])
    with pytest.raises(ValueError, match="generator"):
        detector_noise(L, generator=[gen(1)])


@pytest.mark.skipif(not torch.cuda.is_available(), reason="no CUDA")
def test_cpu_generator_gives_the_same_noise_on_cuda():
    L = radiance_image(torch.float64, "cpu")
    a = detector_noise(L, generator=gen(3))
    b = detector_noise(L.cuda(), generator=gen(3)).cpu()
    torch.testing.assert_close(a, b, rtol=1e-12, atol=0.0)


# ------------------------------------------------------------------------------------------------
# FixedPatternNoise
# ------------------------------------------------------------------------------------------------
def test_fixed_pattern_is_fixed_per_seed(dtype, device):
    L = band_radiance(torch.linspace(270, 310, 24 * 32).reshape(1, 1, 24, 32).to(dtype=dtype, device=device))
    fpn = FixedPatternNoise(seed=3)
    a = fpn(L)
    assert a.dtype == dtype and a.shape == L.shape
    assert torch.equal(a, fpn(L))  # same on every call
    assert torch.equal(a, FixedPatternNoise(seed=3)(L))  # a function of the seed alone
    assert not torch.equal(a, FixedPatternNoise(seed=4)(L))
    assert torch.equal(fpn(L.expand(3, 2, -1, -1)), a.expand(3, 2, -1, -1))  # same on every image and channel
    g64, o64 = fpn.pattern(24, 32, torch.float64)
    g, o = fpn.pattern(24, 32, dtype, device)
    torch.testing.assert_close(g.double().cpu(), g64, rtol=eps(dtype), atol=0.0)
    torch.testing.assert_close(o.double().cpu(), o64, rtol=eps(dtype), atol=0.0)


def test_fixed_pattern_spatial_statistics_match_parameters():
    """Each component alone, measured in kelvin through brightness_temperature at T_ref = 300 K
    (or through the gain at 330 K): pixel offset and gain over 128×128 = 16 384 pixels (s.e.
    0.55 %, bound 3 %), columns over 4 096 columns (s.e. 1.1 %, bound 6 %)."""
    T_ref = 300.0
    L_ref = uniform_image(T_ref, (1, 1, 128, 128), torch.float64, "cpu")
    pix = FixedPatternNoise(gain_std=0.0, offset_std_k=0.1, column_std_k=0.0, seed=1)(L_ref)
    dT = brightness_temperature(pix) - T_ref
    assert abs(dT.std().item() / 0.1 - 1.0) < 0.03
    assert abs(dT.mean().item()) < 5 * 0.1 / 128

    L_col = uniform_image(T_ref, (1, 1, 8, 4096), torch.float64, "cpu")
    col = FixedPatternNoise(gain_std=0.0, offset_std_k=0.0, column_std_k=0.05, seed=1)(L_col)
    assert torch.equal(col, col[:, :, :1].expand_as(col))  # stripes: every row the same
    assert abs((brightness_temperature(col[0, 0, 0]) - T_ref).std().item() / 0.05 - 1.0) < 0.06

    L_hot = uniform_image(330.0, (1, 1, 128, 128), torch.float64, "cpu")
    fpn = FixedPatternNoise(gain_std=0.01, offset_std_k=0.0, column_std_k=0.0, seed=1)
    l_ref = band_radiance(torch.tensor(T_ref, dtype=torch.float64))
    rel = (fpn(L_hot) - l_ref) / (L_hot - l_ref) - 1.0
    assert abs(rel.std().item() / 0.01 - 1.0) < 0.03
    # gain errors pivot about the calibration point: at T_ref the image is unchanged
    torch.testing.assert_close(fpn(L_ref), L_ref, rtol=1e-14, atol=0.0)


@pytest.mark.parametrize(
    "make, name",
    [
        (lambda: DetectorNoise(netd_k=-0.01), "netd_k"),
        (lambda: DetectorNoise(reference_temperature=0.0), "reference_temperature"),
        (lambda: FixedPatternNoise(gain_std=-0.1), "gain_std"),
        (lambda: FixedPatternNoise(offset_std_k=float("inf")), "offset_std_k"),
        (lambda: FixedPatternNoise(column_std_k=-1.0), "column_std_k"),
        (lambda: FixedPatternNoise(seed=-1), "seed"),
        (lambda: FixedPatternNoise(seed=1.5), "seed"),
    ],
)
def test_bad_arguments_raise_value_error_naming_the_argument(make, name):
    with pytest.raises(ValueError, match=name):
        make()

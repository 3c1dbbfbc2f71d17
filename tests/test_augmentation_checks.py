"""The checks of the random-sea augmentations (roughsea_torch._augmentation_checks): a replayed draw
that does not fit the input, or the input itself, raises a ``ValueError`` that names the field and
what it must be (no error from deep inside the render)."""

from __future__ import annotations

import pytest
import torch

import roughsea_torch as rs
from roughsea_torch.augmentation import RandomSeaBackground

from conftest import TIME_RANGE

H, W = 8, 10  # the replayed draws' images
H_IN, W_IN = 24, 32  # the input checks' images


def _background_and_draw():
    aug = rs.RandomSeaBackground(output="brightness_temperature")
    params = aug.sampler.sample(2, generator=torch.Generator().manual_seed(0))
    params["batch_prob"] = torch.ones(2)
    return aug, params


@pytest.mark.parametrize(
    "change, message",
    [
        (lambda p: p.update(wave_seed=p["wave_seed"].double() + 0.5), r"params\['wave_seed'\]: must have an integer dtype"),
        (lambda p: p.update(wave_seed=p["wave_seed"][:1]), r"params\['wave_seed'\]: has 1 values but the input has B = 2"),
        (lambda p: p.update(wave_seed=torch.tensor([1, 2, 3])), r"params\['wave_seed'\]: has 3 values but the input has B = 2"),
        (lambda p: p.update(wave_seed=torch.tensor([-5, 3])), r"params\['wave_seed'\]: seeds must lie in \[0, 2\*\*63\)"),
        (lambda p: p.update(time_s=p["time_s"][:1]), r"params\['time_s'\]: has 1 values but the input has B = 2"),
        (lambda p: p.update(time_s=torch.tensor([float("inf"), 3.0], dtype=torch.float64)), r"params\['time_s'\] must lie in " + TIME_RANGE),
        (lambda p: p.update(time_s=torch.tensor([float("nan"), 3.0], dtype=torch.float64)), r"params\['time_s'\] must lie in " + TIME_RANGE),
        (lambda p: p.update(atmosphere=torch.tensor([0, 4])), r"params\['atmosphere'\]: indices must lie in \[0, 0\]"),
        (lambda p: p.pop("wind_speed"), r"params: missing \['wind_speed'\]"),
        (lambda p: p.update(noise_seed=torch.tensor([-1, 3])), r"params\['noise_seed'\]: seeds must lie in"),
        (lambda p: p.update(is_day=torch.tensor([True, False])), r"'is_day' needs \['sun_elevation_deg', 'sun_azimuth_deg'\]"),
        (lambda p: p.update(pitch_amplitude_deg=torch.ones(2, dtype=torch.float64)), r"platform motion needs all"),
    ],
)
def test_replayed_background_params_are_checked(change, message):
    aug, params = _background_and_draw()
    change(params)
    with pytest.raises(ValueError, match=message):
        aug(torch.zeros(2, 1, H, W), params=params)


def test_replayed_background_params_on_another_batch_size():
    """Used to raise KeyError: 'wind_speed' from inside render_parameters."""
    aug, params = _background_and_draw()
    with pytest.raises(ValueError, match=r"params\['wind_speed'\]: has 2 values but the input has B = 3 images"):
        aug(torch.zeros(3, 1, H, W), params=params)


def test_replayed_background_time_is_checked_before_the_sensor():
    """With a sensor model an infinite replayed time used to end in an IndexError."""
    aug = rs.RandomSeaBackground(sensor=rs.SensorModel(), altitude_m=15.0)
    params = aug.sampler.sample(1, generator=torch.Generator().manual_seed(0))
    params["time_s"] = torch.tensor([float("inf")], dtype=torch.float64)
    with pytest.raises(ValueError, match=r"params\['time_s'\] must lie in " + TIME_RANGE):
        aug(torch.zeros(1, 1, H, W), params=params)


def test_replayed_clip_params_are_checked():
    aug = rs.RandomSeaClip(output="brightness_temperature")
    params = aug.generate_parameters(2)
    x = torch.zeros(2, 2, 1, H, W)
    with pytest.raises(ValueError, match=r"params\['wind_speed'\]: has 2 values but the input has B = 3"):
        aug(torch.zeros(3, 2, 1, H, W), params=params)
    with pytest.raises(ValueError, match=r"params\['wave_seed'\]: must have an integer dtype"):
        aug(x, params=dict(params, wave_seed=params["wave_seed"].double()))
    with pytest.raises(ValueError, match=r"params\['wave_seed'\]: has 1 values"):
        aug(x, params=dict(params, wave_seed=params["wave_seed"][:1]))
    with pytest.raises(ValueError, match=r"params\['time_s'\]: has 1 values"):
        aug(x, params=dict(params, time_s=params["time_s"][:1]))
    with pytest.raises(ValueError, match=r"params\['time_s'\] must lie in " + TIME_RANGE):
        aug(x, params=dict(params, time_s=torch.tensor([float("inf"), 0.0], dtype=torch.float64)))
    with pytest.raises(ValueError, match=r"params\['batch_prob'\]: must hold 2 values"):
        aug(x, params=dict(params, batch_prob=torch.ones(1)))


@pytest.mark.parametrize("dtype", [torch.float16, torch.bfloat16])
@pytest.mark.parametrize("mode", ["replace", "composite"])
def test_half_precision_input_is_refused(dtype, mode):
    """float16 steps are 0.25 K near 290 K (rounding by up to 0.125 K, against a 0.05 K NETD) and hold integers
    exactly only to 2048: the output cannot carry the result in the input's dtype."""
    assert float(torch.tensor(290.0, dtype=torch.float16).nextafter(torch.tensor(300.0, dtype=torch.float16)) - 290.0) == 0.25
    x = torch.zeros(1, 2 if mode == "composite" else 1, H_IN, W_IN, dtype=dtype)
    with pytest.raises(ValueError, match=r"input: dtype .*float32"):
        RandomSeaBackground(mode=mode, output="brightness_temperature")(x)


@pytest.mark.parametrize("bad", [2.0, -0.1, float("nan")])
def test_alpha_outside_the_unit_interval_is_refused(bad):
    x = torch.zeros(2, 2, H_IN, W_IN)
    x[:, 0] = 300.0
    x[1, 1, 3, 4] = bad
    with pytest.raises(ValueError, match=r"alpha \(input channel 1.*\[0, 1\]"):
        RandomSeaBackground(mode="composite", output="radiance")(x)
    x[1, 1, 3, 4] = 1.0  # the edges of the range are fine
    RandomSeaBackground(mode="composite", output="radiance")(x)

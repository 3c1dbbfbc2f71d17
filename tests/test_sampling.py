"""The scene draws (roughsea_torch.sampling, SceneSampler): within their ranges, fixed values kept,
indexed draws independent of the batch, the texture's and the day's draws after the older ones (so
that turning them on changes no other draw), and the checks of every range."""

from __future__ import annotations

import math

import pytest
import torch

import roughsea_torch as rs
from roughsea_torch.augmentation import RandomSeaBackground, RandomSeaClip, SceneSampler

from conftest import gen

H, W = 24, 32
MOTION = {"pitch_amplitude_deg": (0.0, 1.0)}


def test_draws_within_ranges_and_fixed_values():
    s = SceneSampler(wind_speed=(2.0, 4.0), pitch_deg=-3.0, hfov_deg=(10.0, 12.0), atmospheres=["tropical", "us_standard"])
    p = s.sample(500, generator=torch.Generator().manual_seed(0))
    assert bool(((p["wind_speed"] >= 2.0) & (p["wind_speed"] <= 4.0)).all())
    assert float(p["wind_speed"].max() - p["wind_speed"].min()) > 1.9  # spread over the range
    assert torch.equal(p["pitch_deg"], torch.full((500,), -3.0, dtype=torch.float64))
    assert set(p["atmosphere"].tolist()) == {0, 1}
    # air temperature left out: each image gets its atmosphere's own surface air temperature
    own = torch.tensor([rs.atmosphere.surface_air_temperature(n) for n in ("tropical", "us_standard")], dtype=torch.float64)
    assert torch.equal(p["air_temperature"], own[p["atmosphere"]])
    # fixing one range does not change the draws of the others
    q = SceneSampler(wind_speed=(2.0, 4.0), pitch_deg=(-5.0, -1.0), hfov_deg=(10.0, 12.0),
                     atmospheres=["tropical", "us_standard"]).sample(500, generator=torch.Generator().manual_seed(0))
    assert torch.equal(p["wind_speed"], q["wind_speed"]) and torch.equal(p["hfov_deg"], q["hfov_deg"])


def test_indexed_draws_do_not_depend_on_the_batch():
    s = SceneSampler()
    a = s.sample_indexed(11, [5, 6, 7])
    b = s.sample_indexed(11, [7])
    for k in a:
        assert torch.equal(a[k][2:], b[k])
    c = s.sample_indexed(12, [7])
    assert not torch.equal(c["wind_speed"], b["wind_speed"])


def test_texture_draws_come_after_the_old_ones():
    """Texture adds a wave seed (int64) and a time (float64, within time_s) per image, drawn after
    the other parameters: with the same generator seed, every other draw is what texture=False
    (the behaviour before texture existed) draws."""
    g = lambda: torch.Generator().manual_seed(21)  # noqa: E731
    off = SceneSampler(atmospheres=["tropical", "us_standard"]).sample(64, generator=g())
    on = SceneSampler(atmospheres=["tropical", "us_standard"], texture=True, time_s=(100.0, 200.0)).sample(64, generator=g())
    assert set(on) - set(off) == {"wave_seed", "time_s"}
    assert all(torch.equal(off[k], on[k]) for k in off)
    assert on["wave_seed"].dtype == torch.int64 and len(set(on["wave_seed"].tolist())) == 64
    assert on["time_s"].dtype == torch.float64
    assert bool(((on["time_s"] >= 100.0) & (on["time_s"] < 200.0)).all()) and float(on["time_s"].std()) > 20.0
    # the same through the augmentation: texture on and off share the scenes
    a = RandomSeaBackground(output="brightness_temperature", generator=torch.Generator().manual_seed(5))
    b = RandomSeaBackground(output="brightness_temperature", generator=torch.Generator().manual_seed(5), texture=False)
    a(torch.zeros(2, 1, H, W))
    b(torch.zeros(2, 1, H, W))
    assert "wave_seed" not in b._params
    assert all(torch.equal(a._params[k], b._params[k]) for k in off)


@pytest.mark.parametrize("altitude", [(0.5, 100.0), (10.0, 6000.0), 1.0])
def test_altitudes_outside_the_path_tables_are_refused(altitude):
    """The path tables cover camera altitudes 2 m – 5 km: with the path on, a range leaving them is
    refused at construction (naming altitude_m and the allowed range); with path=False the
    sampler's wider 0.5 m – 20 km stays allowed."""
    lo, hi = rs.atmosphere.load_path("tropical").altitude_range_m
    assert (lo, hi) == (2.0, 5000.0)
    for make in (lambda **k: RandomSeaBackground(atmospheres=["tropical", "us_standard"], **k),
                 lambda **k: SceneSampler(atmospheres=["tropical", "us_standard"], **k)):
        with pytest.raises(ValueError, match=r"altitude_m.*\[2, 5000\] m"):
            make(altitude_m=altitude)
        make(altitude_m=altitude, path=False)
        make(altitude_m=(2.0, 5000.0))
    with pytest.raises(ValueError, match="altitude_m"):
        SceneSampler(altitude_m=(0.1, 10.0), path=False)  # below the sampler's own 0.5 m


@pytest.mark.parametrize("texture", [False, True])
def test_daytime_zero_draws_and_renders_as_before(texture):
    """daytime = 0 (with sun ranges given or not): the same keys and values, the generator left in
    the same state, and the same images, as a sampler constructed without the new arguments."""
    old = SceneSampler(texture=texture, motion=MOTION, wind_speed=(2.0, 12.0))
    new = SceneSampler(texture=texture, motion=MOTION, wind_speed=(2.0, 12.0), daytime=0.0,
                       sun_elevation_deg=(5.0, 20.0), sun_azimuth_deg=(-30.0, 30.0))
    g_old, g_new = gen(3), gen(3)
    a, b = old.sample(6, g_old), new.sample(6, g_new)
    assert a.keys() == b.keys() and "is_day" not in b
    assert all(torch.equal(a[k], b[k]) for k in a)
    assert torch.equal(torch.rand(4, generator=g_old), torch.rand(4, generator=g_new))
    x = torch.zeros(2, 1, H, W)
    y0 = RandomSeaBackground(texture=texture, output="brightness_temperature")(x, generator=gen(5))
    y1 = RandomSeaBackground(texture=texture, output="brightness_temperature", daytime=0.0,
                             sun_elevation_deg=10.0)(x, generator=gen(5))
    assert torch.equal(y0, y1)


def test_daytime_draws_come_after_the_others():
    """daytime > 0 adds is_day and the sun's fields; every other field is the daytime-0 draw."""
    a = SceneSampler(texture=True, motion=MOTION).sample(5, gen(9))
    b = SceneSampler(texture=True, motion=MOTION, daytime=0.5).sample(5, gen(9))
    assert set(b) - set(a) == {"is_day", "sun_elevation_deg", "sun_azimuth_deg"}
    assert all(torch.equal(a[k], b[k]) for k in a)
    assert b["is_day"].dtype == torch.bool and b["sun_elevation_deg"].dtype == torch.float64


@pytest.mark.parametrize("daytime", [0.25, 0.8])
def test_is_day_frequency_follows_daytime(daytime):
    """Over 400 draws the count of day images is within 4 binomial σ of 400·daytime; the sun's
    fields stay in their ranges, the azimuth relative to each image's yaw (or world)."""
    n = 400
    s = SceneSampler(daytime=daytime, yaw_deg=(-90.0, 90.0), sun_elevation_deg=(3.0, 40.0), sun_azimuth_deg=(-60.0, 60.0))
    p = s.sample(n, gen(11))
    k = int(p["is_day"].sum())
    assert abs(k - n * daytime) <= 4.0 * math.sqrt(n * daytime * (1 - daytime)), k
    assert bool(((p["sun_elevation_deg"] >= 3.0) & (p["sun_elevation_deg"] <= 40.0)).all())
    rel = p["sun_azimuth_deg"] - p["yaw_deg"]
    assert bool(((rel >= -60.0 - 1e-9) & (rel <= 60.0 + 1e-9)).all())
    assert float(p["yaw_deg"].abs().max()) > 60.0  # so that relative and world differ
    world = SceneSampler(daytime=daytime, yaw_deg=(-90.0, 90.0), sun_azimuth_deg=(-60.0, 60.0),
                         sun_azimuth_relative_to_yaw=False).sample(n, gen(11))
    assert bool(((world["sun_azimuth_deg"] >= -60.0) & (world["sun_azimuth_deg"] <= 60.0)).all())
    assert bool(SceneSampler(daytime=1.0).sample(50, gen(0))["is_day"].all())


@pytest.mark.parametrize(
    "kwargs, name",
    [
        ({"daytime": -0.1}, "daytime"),
        ({"daytime": 1.5}, "daytime"),
        ({"daytime": float("nan")}, "daytime"),
        ({"daytime": True}, "daytime"),
        ({"daytime": "0.5"}, "daytime"),
        ({"sun_elevation_deg": (-5.0, 10.0)}, "sun_elevation_deg"),
        ({"sun_elevation_deg": (10.0, 95.0)}, "sun_elevation_deg"),
        ({"sun_elevation_deg": (30.0, 10.0)}, "sun_elevation_deg"),
        ({"sun_azimuth_deg": (0.0, 1e5)}, "sun_azimuth_deg"),
        ({"sun_azimuth_deg": (0.0, float("inf"))}, "sun_azimuth_deg"),
        ({"sun_azimuth_relative_to_yaw": "yes"}, "sun_azimuth_relative_to_yaw"),
    ],
)
@pytest.mark.parametrize("cls", [SceneSampler, RandomSeaBackground, RandomSeaClip])
def test_bad_day_settings_raise_naming_the_argument(cls, kwargs, name):
    with pytest.raises(ValueError, match=name):
        cls(**kwargs)


def test_platform_phase_is_uniform_over_a_turn():
    """phase_rad is drawn uniform in [0, 2π) (SceneSampler's docstring): over 4000 draws every
    phase is in [0, 2π) and the mean and variance are π and π²/3 (4000 draws: standard errors
    0.03 and 0.05, the bounds are 4 of them)."""
    ph = SceneSampler(motion=MOTION).sample(4000, gen(5))["phase_rad"]
    assert bool(((ph >= 0) & (ph < 2 * math.pi)).all())
    assert abs(float(ph.mean()) - math.pi) < 0.12
    assert abs(float(ph.var()) - math.pi**2 / 3) < 0.2

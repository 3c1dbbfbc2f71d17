"""Day images in the augmentations: ``daytime`` draws whether an image is by day and where its sun
is; off (0.0, the default) nothing changes, on the sun's glint is in the images and replays bit
for bit."""

from __future__ import annotations

import math

import pytest
import torch

import roughsea_torch as rs
from roughsea_torch.augmentation import RandomSeaBackground, RandomSeaClip, SceneSampler, render_parameters

H, W = 24, 32
MOTION = {"pitch_amplitude_deg": (0.0, 1.0)}


def _g(seed: int) -> torch.Generator:
    return torch.Generator().manual_seed(seed)


@pytest.mark.parametrize("texture", [False, True])
def test_daytime_zero_draws_and_renders_as_before(texture):
    """daytime = 0 (with sun ranges given or not): the same keys and values, the generator left in
    the same state, and the same images, as a sampler constructed without the new arguments."""
    old = SceneSampler(texture=texture, motion=MOTION, wind_speed=(2.0, 12.0))
    new = SceneSampler(texture=texture, motion=MOTION, wind_speed=(2.0, 12.0), daytime=0.0,
                       sun_elevation_deg=(5.0, 20.0), sun_azimuth_deg=(-30.0, 30.0))
    g_old, g_new = _g(3), _g(3)
    a, b = old.sample(6, g_old), new.sample(6, g_new)
    assert a.keys() == b.keys() and "is_day" not in b
    assert all(torch.equal(a[k], b[k]) for k in a)
    assert torch.equal(torch.rand(4, generator=g_old), torch.rand(4, generator=g_new))
    x = torch.zeros(2, 1, H, W)
    y0 = RandomSeaBackground(texture=texture, output="brightness_temperature")(x, generator=_g(5))
    y1 = RandomSeaBackground(texture=texture, output="brightness_temperature", daytime=0.0,
                             sun_elevation_deg=10.0)(x, generator=_g(5))
    assert torch.equal(y0, y1)


def test_daytime_draws_come_after_the_others():
    """daytime > 0 adds is_day and the sun's fields; every other field is the daytime-0 draw."""
    a = SceneSampler(texture=True, motion=MOTION).sample(5, _g(9))
    b = SceneSampler(texture=True, motion=MOTION, daytime=0.5).sample(5, _g(9))
    assert set(b) - set(a) == {"is_day", "sun_elevation_deg", "sun_azimuth_deg"}
    assert all(torch.equal(a[k], b[k]) for k in a)
    assert b["is_day"].dtype == torch.bool and b["sun_elevation_deg"].dtype == torch.float64


def test_mwir_glint_ahead_is_much_brighter_than_by_night():
    """MWIR, 5 m/s, camera 20 m up looking 3° down, the sun 10° up straight ahead: the glint raises
    the brightest pixel by > 10 K over the same draw by night; the sun behind the camera adds no
    glint (out of view), only the sunlight the aerosol scatters into the sky (its sky pixels and
    the sea's reflection of it): everywhere >= 0 and under 1 K (0.37 K measured), a tenth of the glint."""
    kw = dict(wind_speed=5.0, altitude_m=20.0, pitch_deg=-3.0, hfov_deg=20.0, band=rs.MWIR,
              output="brightness_temperature")
    x = torch.zeros(2, 1, H, W)
    night = RandomSeaBackground(**kw)
    day = RandomSeaBackground(**kw, daytime=1.0, sun_elevation_deg=10.0, sun_azimuth_deg=0.0)
    behind = RandomSeaBackground(**kw, daytime=1.0, sun_elevation_deg=10.0, sun_azimuth_deg=180.0)
    yn, yd, yb = night(x, generator=_g(1)), day(x, generator=_g(1)), behind(x, generator=_g(1))
    assert day._params["is_day"].all()
    assert torch.equal(day._params["wave_seed"], night._params["wave_seed"])  # the same sea
    gain = yd.amax(dim=(1, 2, 3)) - yn.amax(dim=(1, 2, 3))
    assert bool((gain > 10.0).all()), gain
    assert float((yb - yn).min()) >= -1e-4 and float((yb - yn).max()) < min(1.0, 0.1 * float(gain.min()))


def test_day_draws_replay_bit_for_bit():
    """Still images and clips with day images: params replay the same output bit for bit, and
    render_parameters of the params is the augmentation's radiance (day and night images batched
    together)."""
    x = torch.zeros(4, 1, H, W)
    aug = RandomSeaBackground(daytime=0.5, band=rs.MWIR, sun_azimuth_deg=(-20.0, 20.0), wind_speed=(3.0, 10.0))
    y = aug(x, generator=_g(2))
    p = aug._params
    assert 0 < int(p["is_day"].sum()) < 4  # both kinds in the batch
    assert torch.equal(aug(x, params=p), y)
    assert torch.equal(render_parameters(p, H, W, aug.sampler.atmospheres, band=rs.MWIR), y)
    clip = RandomSeaClip(daytime=1.0, band=rs.MWIR, sun_elevation_deg=8.0, sun_azimuth_deg=0.0, wind_speed=5.0,
                         altitude_m=20.0, pitch_deg=-3.0, output="brightness_temperature", frame_rate=10.0,
                         texture=False)
    xc = torch.zeros(1, 2, 1, H, W)
    yc = clip(xc, generator=_g(4))
    assert torch.equal(clip(xc, params=clip._params), yc)
    assert float(yc.amax(dim=(2, 3, 4)).min()) > 350.0  # the glint in every frame (the sea is ~290 K)


@pytest.mark.parametrize("daytime", [0.25, 0.8])
def test_is_day_frequency_follows_daytime(daytime):
    """Over 400 draws the count of day images is within 4 binomial σ of 400·daytime; the sun's
    fields stay in their ranges, the azimuth relative to each image's yaw (or world)."""
    n = 400
    s = SceneSampler(daytime=daytime, yaw_deg=(-90.0, 90.0), sun_elevation_deg=(3.0, 40.0), sun_azimuth_deg=(-60.0, 60.0))
    p = s.sample(n, _g(11))
    k = int(p["is_day"].sum())
    assert abs(k - n * daytime) <= 4.0 * math.sqrt(n * daytime * (1 - daytime)), k
    assert bool(((p["sun_elevation_deg"] >= 3.0) & (p["sun_elevation_deg"] <= 40.0)).all())
    rel = p["sun_azimuth_deg"] - p["yaw_deg"]
    assert bool(((rel >= -60.0 - 1e-9) & (rel <= 60.0 + 1e-9)).all())
    assert float(p["yaw_deg"].abs().max()) > 60.0  # so that relative and world differ
    world = SceneSampler(daytime=daytime, yaw_deg=(-90.0, 90.0), sun_azimuth_deg=(-60.0, 60.0),
                         sun_azimuth_relative_to_yaw=False).sample(n, _g(11))
    assert bool(((world["sun_azimuth_deg"] >= -60.0) & (world["sun_azimuth_deg"] <= 60.0)).all())
    assert bool(SceneSampler(daytime=1.0).sample(50, _g(0))["is_day"].all())


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

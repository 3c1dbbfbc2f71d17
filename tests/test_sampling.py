"""The scene draws (roughsea_torch.sampling, SceneSampler): within their ranges, fixed values kept,
indexed draws independent of the batch, the texture's and the day's draws after the older ones (so
that turning them on changes no other draw), and the checks of every range."""

from __future__ import annotations

import math
import warnings

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


# ------------------------------------------------------------------------------------------------
# The air as the sea plus a drawn air-sea difference
# ------------------------------------------------------------------------------------------------
# the scene fields drawn before air_sea_difference existed, one uniform each, in this order
OLD_DRAWN = ("wind_speed", "wind_direction_deg", "sea_temperature", "air_temperature", "altitude_m", "pitch_deg",
             "roll_deg", "yaw_deg", "hfov_deg")
ATMS = ("tropical", "subarctic_winter")
RANGES = dict(wind_speed=(2.0, 12.0), sea_temperature=(285.0, 302.0), altitude_m=(10.0, 60.0), yaw_deg=(-20.0, 20.0))


def _recompute(n, seed, air_sea=None):
    """The draws of SceneSampler(atmospheres=ATMS, texture=True, motion=MOTION, daytime=0.5, **RANGES),
    recomputed from the generator as its docstring orders them (nine scene uniforms, atmosphere,
    noise seed, wave seed, time, six motion uniforms and the phase, three day uniforms), the
    scene fields as low + (high − low) u; ``air_sea``: the air as sea + low + (high − low) u of the
    air's row."""
    g = gen(seed)
    u = torch.rand(len(OLD_DRAWN), n, generator=g, dtype=torch.float64)
    atm = torch.randint(len(ATMS), (n,), generator=g)
    noise = torch.randint(0, 2**62, (n,), generator=g)
    wave = torch.randint(0, 2**62, (n,), generator=g)
    time_s = 0.0 + (3600.0 - 0.0) * torch.rand(n, generator=g, dtype=torch.float64)
    um = torch.rand(7, n, generator=g, dtype=torch.float64)
    us = torch.rand(3, n, generator=g, dtype=torch.float64)
    defaults = {"wind_direction_deg": (0.0, 360.0), "pitch_deg": (-10.0, -1.0), "roll_deg": (-2.0, 2.0),
                "hfov_deg": (20.0, 40.0), **RANGES}
    out = {name: defaults[name][0] + (defaults[name][1] - defaults[name][0]) * u[i]
           for i, name in enumerate(OLD_DRAWN) if name != "air_temperature"}
    own = torch.tensor([rs.atmosphere.surface_air_temperature(a) for a in ATMS], dtype=torch.float64)
    out["air_temperature"] = own[atm] if air_sea is None else out["sea_temperature"] + (
        air_sea[0] + (air_sea[1] - air_sea[0]) * u[OLD_DRAWN.index("air_temperature")])
    motion = {"pitch_amplitude_deg": (0.0, 1.0), "roll_amplitude_deg": (0.0, 4.0), "heave_amplitude_m": (0.0, 1.0),
              "pitch_period_s": (5.0, 12.0), "roll_period_s": (5.0, 12.0), "heave_period_s": (5.0, 12.0)}  # MOTION, defaults
    out.update({name: lo + (hi - lo) * um[i] for i, (name, (lo, hi)) in enumerate(motion.items())})
    out.update(atmosphere=atm, noise_seed=noise, wave_seed=wave, time_s=time_s, phase_rad=2.0 * math.pi * um[-1],
               is_day=us[0] < 0.5, sun_elevation_deg=2.0 + 58.0 * us[1],
               sun_azimuth_deg=-180.0 + 360.0 * us[2] + out["yaw_deg"])
    return out, g


def test_draws_without_air_sea_difference_are_unchanged():
    """Without air_sea_difference (left out, or None) every field is what the sampler drew before the
    option existed, bit for bit: an independent recomputation from the generator in the documented
    order, with nine scene uniforms (a tenth row, or a draw of the difference anywhere, would shift
    the atmosphere, seeds, texture, motion and sun), and the generator is left in the same state.
    With it, only the air changes: the sea plus a difference from the air's own uniform row."""
    n = 16
    kw = dict(atmospheres=ATMS, texture=True, motion=MOTION, daytime=0.5, **RANGES)
    want, g_want = _recompute(n, 31)
    g_a, g_b = gen(31), gen(31)
    a = SceneSampler(**kw).sample(n, g_a)
    b = SceneSampler(air_sea_difference=None, **kw).sample(n, g_b)
    assert set(a) == set(b) == set(want) | {"air_sea_difference"}
    for k, v in want.items():
        assert torch.equal(a[k], v), k
        assert torch.equal(b[k], v), k
    after = torch.rand(4, generator=g_want)  # the generator's next draws after the recomputation's
    assert torch.equal(torch.rand(4, generator=g_a), after) and torch.equal(torch.rand(4, generator=g_b), after)
    # with the difference: the air is the sea plus it; every other field as without
    want_d, g_want_d = _recompute(n, 31, air_sea=(-3.0, 1.0))
    g_c = gen(31)
    c = SceneSampler(air_sea_difference=(-3.0, 1.0), **kw).sample(n, g_c)
    for k, v in want_d.items():
        assert torch.equal(c[k], v), k
    assert not torch.equal(c["air_temperature"], a["air_temperature"])
    assert torch.equal(torch.rand(4, generator=g_c), torch.rand(4, generator=g_want_d))


def test_air_sea_difference_is_uniform_and_independent_of_the_sea():
    """air_sea_difference=(−3, 1): every image's T_air − T_sea lies in [−3, 1] K (to rounding), and
    the record ``air_sea_difference`` is that difference; over 4000 draws the difference is uniform
    (Kolmogorov–Smirnov statistic below 1.95/√n, the 0.1 % critical value) and uncorrelated with the
    sea (|r| < 4/√n), and the sea keeps its own uniform range."""
    from scipy import stats

    n = 4000
    p = SceneSampler(sea_temperature=(285.0, 302.0), air_sea_difference=(-3.0, 1.0),
                     atmospheres=["tropical", "us_standard"]).sample(n, gen(17))
    d = p["air_temperature"] - p["sea_temperature"]
    assert float(d.min()) >= -3.0 - 1e-9 and float(d.max()) <= 1.0 + 1e-9
    torch.testing.assert_close(p["air_sea_difference"], d, rtol=0, atol=1e-9)
    assert stats.kstest(d.numpy(), stats.uniform(loc=-3.0, scale=4.0).cdf).statistic < 1.95 / math.sqrt(n)
    assert stats.kstest(p["sea_temperature"].numpy(), stats.uniform(loc=285.0, scale=17.0).cdf).statistic < 1.95 / math.sqrt(n)
    r = float(torch.corrcoef(torch.stack([d, p["sea_temperature"]]))[0, 1])
    assert abs(r) < 4.0 / math.sqrt(n), r
    # without it the record is the air the sampler drew (here each atmosphere's own) minus the sea
    q = SceneSampler(sea_temperature=(285.0, 302.0), atmospheres=["tropical"]).sample(50, gen(1))
    own = rs.atmosphere.surface_air_temperature("tropical")
    assert torch.equal(q["air_temperature"], torch.full((50,), own, dtype=torch.float64))
    torch.testing.assert_close(q["air_sea_difference"], own - q["sea_temperature"], rtol=0, atol=1e-12)


def test_a_fixed_air_sea_difference_holds_exactly():
    """A number holds the difference fixed: T_air = T_sea − 2 K in every image, in the same-on-batch
    draw too."""
    s = SceneSampler(sea_temperature=(280.0, 300.0), air_sea_difference=-2.0)
    for p in (s.sample(20, gen(2)), s.sample(5, gen(2), same_on_batch=True), s.sample_indexed(3, [0, 9])):
        torch.testing.assert_close(p["air_temperature"], p["sea_temperature"] - 2.0, rtol=0, atol=1e-12)
        assert torch.equal(p["air_sea_difference"], torch.full_like(p["sea_temperature"], -2.0))


@pytest.mark.parametrize(
    "kwargs, pattern",
    [
        (dict(air_temperature=(283.0, 303.0), air_sea_difference=(-3.0, 1.0)), r"air_temperature and air_sea_difference"),
        (dict(air_temperature=290.0, air_sea_difference=0.0), r"air_temperature and air_sea_difference"),
        (dict(air_sea_difference=(-31.0, 1.0)), r"air_sea_difference.*\[-30, 30\]"),
        (dict(air_sea_difference=(1.0, -3.0)), r"air_sea_difference.*inverted"),
        (dict(air_sea_difference=(0.0, float("nan"))), r"air_sea_difference"),
        (dict(air_sea_difference="cold"), r"air_sea_difference"),
        (dict(sea_temperature=(300.0, 320.0), air_sea_difference=(0.0, 20.0)),
         r"air_sea_difference: sea_temperature \(300, 320\) K.*\[300, 340\] K.*\[230, 330\] K"),
    ],
)
@pytest.mark.parametrize("cls", [SceneSampler, RandomSeaBackground, RandomSeaClip])
def test_bad_air_sea_difference_raises_naming_it(cls, kwargs, pattern):
    """Both ways of drawing the air at once, a difference outside [−30, 30] K or not a range, and a
    sea range plus difference that leaves the air's [230, 330] K: a ValueError naming the arguments."""
    with pytest.raises(ValueError, match=pattern):
        cls(**kwargs)
    assert SceneSampler(sea_temperature=(260.0, 300.0), air_sea_difference=(-30.0, 30.0)).ranges["air_sea_difference"] \
        == (-30.0, 30.0)  # the edges of both allowed ranges are accepted


def test_a_pose_range_above_the_horizon_warns():
    """Draws whose lowest pitch is half the widest field of view or more look only at the sky (a landscape
    image's lower edge is then above the horizon): a new user's "sea backgrounds" came out sky-only without
    a word. The rendered image confirms it; a range that reaches below the horizon does not warn."""
    with pytest.warns(UserWarning, match="pitch_deg"):
        s = SceneSampler(pitch_deg=(12.0, 20.0), hfov_deg=(16.0, 24.0), roll_deg=0.0, path=False)
    p = s.sample(1, torch.Generator().manual_seed(0))
    cams = rs.make_camera(12, 16, hfov_deg=float(p["hfov_deg"][0]), pitch_deg=float(p["pitch_deg"][0]), altitude_m=20.0)
    assert not bool(rs.view_geometry(cams).is_sea.any())  # no pixel sees the sea
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        SceneSampler(pitch_deg=(-2.0, 20.0), hfov_deg=(16.0, 24.0), path=False)

"""Bad inputs of textured scenes, clips and replayed augmentation draws raise a ``ValueError`` that
names the argument and its allowed range (no silent NaN, no error from deep inside)."""

from __future__ import annotations

import numpy as np
import pytest
import torch

import roughsea_torch as rs
from roughsea_torch import dataset as D
from roughsea_torch._validation import check_finite_range

H, W = 8, 10
TIME_RANGE = r"\[-1e\+09, 1e\+09\] s"


def scene(**kw):
    return rs.SeaScene(**{"wind_speed": 8.0, "sea_temperature": 290.0, "seed": 1, **kw})


def cams(batch_size=1):
    return rs.make_camera(H, W, batch_size=batch_size, altitude_m=15.0, pitch_deg=-5.0)


@pytest.mark.parametrize("t", [float("inf"), float("-inf"), float("nan"), 2e9, torch.tensor([0.0, float("inf")])])
def test_scene_time_must_be_finite_within_the_wave_sampler_range(t):
    """SeaScene checks time_s at construction against WaveField.sample's [-1e9, 1e9] s (inf used to
    render NaN pixels, 1e12 used to render, NaN reported the range [-inf, inf])."""
    with pytest.raises(ValueError, match=r"time_s must lie in " + TIME_RANGE):
        scene(time_s=t)


def test_scene_time_is_checked_whenever_it_is_set():
    """render_clip and the augmentations set a copied scene's time frame by frame: that is checked too."""
    s = scene(time_s=torch.tensor([0.0, 1.0]))
    with pytest.raises(ValueError, match=r"time_s must lie in " + TIME_RANGE):
        s.time_s = torch.tensor([float("inf"), 1.0])
    with pytest.raises(ValueError, match=r"time_s: must be a float or a tensor of shape \(B,\)"):
        s.time_s = torch.zeros(2, 2)
    assert torch.equal(s.time_s, torch.tensor([0.0, 1.0]))  # a refused value is not kept


@pytest.mark.parametrize("t", ["0", ["a"], [0.0, 1.0], 1j])
def test_scene_time_must_be_a_real_number_or_tensor(t):
    with pytest.raises(ValueError, match=r"^time_s"):
        scene(time_s=t)


def test_check_finite_range_names_non_numeric_and_complex_input():
    for x in ("a", ["a"], np.array(["a"]), [[1.0, 2.0], [3.0]]):
        with pytest.raises(ValueError, match=r"^x must be a real number or a tensor of real numbers"):
            check_finite_range("x", x)
    with pytest.raises(ValueError, match=r"^x must be real"):  # the imaginary part used to be dropped
        check_finite_range("x", np.array([1.0 + 1.0j]))


@pytest.mark.parametrize("bad", [float("nan"), float("inf"), -2e6])
def test_wind_direction_reports_its_real_range(bad):
    """NaN used to report [-inf, inf] (SeaScene's check) while inf reported WaveField's [-1e6, 1e6]."""
    for seed in (1, None):
        with pytest.raises(ValueError, match=r"wind_direction must lie in \[-1e\+06, 1e\+06\] rad"):
            scene(wind_direction=bad, seed=seed)


def test_render_clip_checks_every_time_argument():
    motion = rs.PlatformMotion(height=H, width=W, altitude_m=15.0)
    times = torch.arange(2) / 25.0
    for start in (float("nan"), float("inf"), torch.tensor([0.0, float("nan")])):
        with pytest.raises(ValueError, match=r"^start_s must lie in " + TIME_RANGE):
            rs.render_clip(motion, scene(), times, start_s=start)
    with pytest.raises(ValueError, match=r"^start_s \+ times_s must lie in " + TIME_RANGE):
        rs.render_clip(motion, scene(), times, start_s=1e9)  # the last frame at 1e9 + 0.04 s
    with pytest.raises(ValueError, match=r"^scene.time_s \+ times_s must lie in " + TIME_RANGE):
        rs.render_clip(motion, scene(time_s=1e9), times)
    with pytest.raises(ValueError, match=r"^times_s must lie in " + TIME_RANGE):
        rs.render_clip(motion, scene(), torch.tensor([0.0, float("inf")]))
    with pytest.raises(ValueError, match=r"^times_s must be a real number"):
        rs.render_clip(motion, scene(), ["a"])
    with pytest.raises(ValueError, match=r"^times_s: must be a non-empty 1-D sequence.*\(2, 2\)"):
        rs.render_clip(motion, scene(), torch.zeros(2, 2))  # used to be flattened to 4 frames
    with pytest.raises(ValueError, match=r"^time_s must lie in " + TIME_RANGE):
        motion.cameras(float("inf"))  # used to fail on the NaN pitch it made


def test_a_sequence_of_seeds_needs_one_per_image():
    """seed=[1] used to be copied to every image (two identical realizations)."""
    with pytest.raises(ValueError, match=r"seed: a sequence of seeds needs one per image, B = 2; got 1"):
        rs.render(cams(2), scene(seed=[1], wind_speed=torch.tensor([8.0, 8.0])))
    with pytest.raises(ValueError, match=r"seed: a sequence of seeds needs one per image, B = 2; got 1"):
        rs.render(cams(2), scene(seed=[1]))  # the scene's other fields are scalars: B from the cameras
    with pytest.raises(ValueError, match=r"seed: a sequence of seeds needs one per image, B = 2; got 3"):
        scene(seed=[1, 2, 3], wind_speed=torch.tensor([5.0, 8.0])).batch_size
    # a plain int (also as a 0-D tensor) keeps its documented meaning: image i's seed derived from (seed, i)
    derived = [int(np.random.SeedSequence((7, i)).generate_state(1, np.uint64)[0] >> 1) for i in range(2)]
    assert scene(seed=7).seeds(2) == derived
    assert scene(seed=torch.tensor(7)).seeds(2) == derived
    assert scene(seed=7).seeds(1) == [7] and scene(seed=[7]).seeds(1) == [7]


def test_numpy_integer_seeds_are_ints():
    """A shard stores wave_seed as np.int64: SeaScene(seed=shard["wave_seed"][i]) is that int seed."""
    shard = {"wave_seed": np.array([3, 5], dtype=np.int64)}
    a = rs.render(cams(), scene(seed=shard["wave_seed"][0], foam=False))
    assert torch.equal(a, rs.render(cams(), scene(seed=3, foam=False)))
    assert scene(seed=np.int64(3)).seeds(2) == scene(seed=3).seeds(2)
    assert scene(seed=shard["wave_seed"]).seeds(2) == [3, 5]
    assert scene(seed=np.array(5)).seeds(1) == [5]
    assert scene(seed=[np.int32(4), np.uint64(6)]).seeds(2) == [4, 6]
    for bad in (np.float64(3.0), np.bool_(True), True, 1.5, np.int64(-1), -1, np.array([1.0, 2.0]),
                np.array([True, False]), np.array([[1, 2]]), torch.tensor(3.0), torch.tensor([[1]])):
        with pytest.raises(ValueError, match=r"^seed"):
            scene(seed=bad)


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


@pytest.mark.parametrize("chunk", [0, -1, 1.5, True, "2"])
def test_render_chunk_must_be_a_positive_int(chunk):
    with pytest.raises(ValueError, match=r"^chunk must be None or an int in \[1, inf\)"):
        rs.render(cams(), scene(seed=None), chunk=chunk)


def test_frame_render_parameters_docstring_matches_its_result():
    """The docstring promised an "atmosphere_name" key the result never had."""
    meta = {name: 1.0 for name, *_r in D.SCENE_FIELDS}
    meta.update(atmosphere="midlatitude_summer", noise_seed=np.int64(9), wave_seed=np.int64(4), time_s=2.5)
    p = D.frame_render_parameters(meta)
    doc = D.frame_render_parameters.__doc__
    assert "atmosphere" not in p and "atmosphere_name" not in doc
    assert 'meta["atmosphere"]' in doc
    for key in set(p) - {name for name, *_r in D.SCENE_FIELDS}:
        assert f"``{key}``" in doc, key


@pytest.mark.parametrize("kw,name", [(dict(pitch_deg=-89.5, pitch_amplitude_deg=1.0), "pitch_amplitude_deg"),
                                     (dict(roll_deg=179.0, roll_amplitude_deg=2.0), "roll_amplitude_deg"),
                                     (dict(hfov_deg=200.0), "hfov_deg")])
def test_platform_motion_checks_its_poses_when_built(kw, name):
    """A mast whose pose ± amplitude leaves the cameras' range is refused when it is built, naming
    the amplitude (it was refused only at the first frame that left it, naming pitch_deg or
    roll_deg); the poses it does accept all make cameras."""
    with pytest.raises(ValueError, match=name):
        rs.PlatformMotion(**kw)
    ok = rs.PlatformMotion(pitch_deg=-88.0, pitch_amplitude_deg=2.0, roll_deg=178.0, roll_amplitude_deg=2.0)
    for t in (1.5, 4.5, 0.0, 2.25):  # the extremes of pitch (period 6 s) and roll (9 s, phase π/2)
        ok.cameras(t)


def test_texture_rules_accept_lists_and_numpy_numbers():
    """TableSize's texture rules: a list [20, 16] is kept as the tuple (it passed the check, then the
    render raised TypeError: unhashable type: 'list'); numpy integers and floats are numbers; a rule
    of a zero or a float is a ValueError naming it (found in review)."""
    t = rs.TableSize(texture_quadrature=[20, 16], texture_quadrature_steep=(np.int64(16), 16),
                     texture_quadrature_width=np.float32(4.5))
    assert t.texture_quadrature == (20, 16) and t.texture_quadrature_steep == (16, 16)
    assert torch.isfinite(rs.render(cams(), scene(seed=1), table=t)).all()
    for bad in (dict(texture_quadrature=(0, 16)), dict(texture_quadrature=(2.5, 16)), dict(texture_quadrature_width=0.5)):
        with pytest.raises(ValueError, match=f"TableSize.{next(iter(bad))}"):
            rs.TableSize(**bad)


def test_foam_true_is_refused_and_augmentations_take_one_setting():
    """foam=True read as a whitecap fraction of 1 (a sea all foam) where a user means "on": it is a
    ValueError that points at 'auto'. An augmentation takes one foam setting for every image (a
    per-image tensor failed whenever the gate picked a subset; found in review)."""
    for make in (lambda f: rs.SeaScene(wind_speed=8.0, sea_temperature=290.0, foam=f),
                 lambda f: rs.RandomSeaBackground(foam=f), lambda f: rs.RandomSeaClip(foam=f)):
        with pytest.raises(ValueError, match="'auto'"):
            make(True)
    with pytest.raises(ValueError, match="foam: one setting for every image"):
        rs.RandomSeaBackground(foam=torch.tensor([0.0, 1.0]))
    assert rs.SeaScene(wind_speed=8.0, sea_temperature=290.0, foam=torch.tensor([0.0, 1.0])).foam is not None

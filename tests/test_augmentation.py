"""The random-sea augmentations (roughsea_torch.augmentation): RandomSeaBackground for still images
and RandomSeaClip for clips. Kornia conventions (shapes, layouts, masks and boxes in
AugmentationSequential, VideoSequential), reproducibility (replay from the kept parameters, seeds,
DataLoader workers), the physics of the compositing (alpha blending in radiance) and of the parameters'
plumbing into the renderer; clips: temporal coherence of the sea, the platform's motion in the image,
frames that equal still images rendered at their pose and time; day images: ``daytime`` draws
whether an image is by day and where its sun is; on, the sun's glint is in the images and replays
bit for bit. (The draws themselves: tests/test_sampling.py; the checks of inputs and replayed draws:
tests/test_augmentation_checks.py.)"""

from __future__ import annotations

import math

import kornia.augmentation as K
import pytest
import torch

import roughsea_torch as rs
from roughsea_torch.augmentation import (
    RandomSeaBackground,
    RandomSeaClip,
    frame_noise_seed,
    frame_parameters,
    render_parameters,
)

from conftest import gen

H, W = 24, 32
STILL = dict(pitch_amplitude_deg=0.0, roll_amplitude_deg=0.0, heave_amplitude_m=0.0)  # a camera that does not move


def small(**kw):
    kw.setdefault("output", "brightness_temperature")
    return RandomSeaBackground(**kw)


def clip(**kw):
    kw.setdefault("output", "brightness_temperature")
    return RandomSeaClip(**kw)


# ------------------------------------------------------------------------------------------------
# Still images: RandomSeaBackground
# ------------------------------------------------------------------------------------------------
@pytest.mark.parametrize("channels", [1, 3])
def test_shape_dtype_and_values(dtype, channels):
    aug = small(sea_temperature=(285.0, 300.0))
    x = torch.zeros(3, channels, H, W, dtype=dtype)
    y = aug(x, generator=torch.Generator().manual_seed(1))
    assert y.shape == x.shape and y.dtype == dtype
    # every channel carries the same rendered image, and every value is a plausible temperature
    assert torch.equal(y[:, :1].expand_as(y), y)
    assert bool(((y > 200.0) & (y < 310.0)).all())


def test_keepdim_unbatched_input():
    aug = small(keepdim=True)
    y = aug(torch.zeros(1, H, W), generator=torch.Generator().manual_seed(0))
    assert y.shape == (1, H, W)


def test_replay_and_seeding():
    aug = small(wind_speed=(0.5, 20.0), atmospheres=["tropical", "subarctic_winter", "us_standard"],
                air_temperature=(260.0, 300.0))
    x = torch.zeros(4, 1, H, W)
    a = aug(x, generator=torch.Generator().manual_seed(7))
    params = {k: v.clone() for k, v in aug._params.items()}
    assert torch.equal(aug(x, params=params), a)  # replay from the kept parameters
    assert torch.equal(aug(x, generator=torch.Generator().manual_seed(7)), a)  # same seed, same batch
    b = aug(x, generator=torch.Generator().manual_seed(8))
    assert not torch.equal(a, b)
    torch.manual_seed(3)
    c = aug(x)
    torch.manual_seed(3)
    assert torch.equal(aug(x), c)  # no generator: the global one


def test_same_on_batch():
    aug = small(same_on_batch=True)
    y = aug(torch.zeros(3, 1, H, W), generator=torch.Generator().manual_seed(2))
    assert torch.equal(y[0], y[1]) and torch.equal(y[0], y[2])


def test_p_gates_images_and_skips_their_rendering():
    x = torch.full((8, 1, H, W), -1.0)
    aug = small(p=0.5)
    y = aug(x, generator=torch.Generator().manual_seed(4))
    gate = aug._params["batch_prob"] > 0.5
    assert 0 < int(gate.sum()) < 8
    assert bool((y[~gate] == -1.0).all())
    # each selected image is the render of its own parameter row
    own = {k: v[gate] for k, v in aug._params.items() if v.ndim == 1 and v.shape[0] == 8}
    want = rs.brightness_temperature(render_parameters(own, H, W, aug.sampler.atmospheres), rs.LWIR)
    torch.testing.assert_close(y[gate], want, rtol=0, atol=1e-4)
    assert torch.equal(small(p=0.0)(x), x)


def test_inside_augmentation_sequential_with_masks_and_boxes():
    aug = small()
    seq = K.AugmentationSequential(aug, K.RandomHorizontalFlip(p=1.0), data_keys=["input", "mask", "bbox_xyxy"])
    x = torch.zeros(2, 1, H, W)
    m = torch.zeros(2, 1, H, W)
    m[:, :, 5:9, 2:6] = 1.0
    boxes = torch.tensor([[[2.0, 5.0, 6.0, 9.0]]]).repeat(2, 1, 1)
    torch.manual_seed(0)
    y, m2, b2 = seq(x, m, boxes)
    assert bool((y > 200.0).all())  # the sea was rendered inside the container
    # the sea is rendered, then flipped; masks and boxes move with the flip only
    assert torch.equal(m2, m.flip(-1))
    assert torch.allclose(b2[..., 0], W - 1 - boxes[..., 2]) and torch.allclose(b2[..., 2], W - 1 - boxes[..., 0])  # kornia: x -> W - 1 - x
    y2, m3, _ = seq(x, m, boxes, params=seq._params)
    assert torch.equal(y2, y) and torch.equal(m3, m2)


def test_texture_replays_bit_for_bit_and_differs_between_draws():
    aug = small(wind_speed=(5.0, 12.0), pitch_deg=(-15.0, -8.0), altitude_m=(10.0, 20.0), hfov_deg=30.0)
    x = torch.zeros(3, 1, H, W)
    y = aug(x, generator=torch.Generator().manual_seed(2))
    params = {k: v.clone() for k, v in aug._params.items()}
    assert torch.equal(aug(x, params=params), y)
    assert torch.equal(aug(x, generator=torch.Generator().manual_seed(2)), y)
    # another wave seed, everything else kept: the sea's clutter changes, the sky does not
    other = dict(params, wave_seed=params["wave_seed"] + 1)
    z = aug(x, params=other)
    sea = rs.view_geometry(rs.make_camera(H, W, hfov_deg=30.0, altitude_m=params["altitude_m"],
                                          pitch_deg=params["pitch_deg"], roll_deg=params["roll_deg"])).is_sea[:, None]
    assert torch.equal(z[~sea], y[~sea])
    for i in range(3):  # every image's near range (bottom rows) changes by a visible amount
        assert float((z[i, 0, -4:] - y[i, 0, -4:]).abs().max()) > 0.02  # K
    # and the same seed at another time is another frame of the same sea
    later = dict(params, time_s=params["time_s"] + 10.0)
    assert float((aug(x, params=later)[:, 0, -4:] - y[:, 0, -4:]).abs().max()) > 0.02


@pytest.mark.parametrize("wind", [5.0, 12.0])
def test_texture_is_zero_mean_clutter_around_the_expectation(wind):
    """At near range (10 m up, 15° down) the texture departs from the expectation image by a
    plausible clutter (std between 0.01 and 3 K); over sixteen realizations the mean departure over
    the sea pixels is zero within 4 standard errors of the realizations' own means (the expectation
    is the ensemble mean; the brightness temperature's curvature leaves ~1e-4 K: 0.002 K allowed).
    A bias of 0.4 of the clutter's std (plant ``+ 0.4 * std`` on ``tex``) fails. (At 12 m/s the
    realizations' means scatter by 0.22-0.35 of the clutter's std, waves longer than the image: with
    eight realizations 4 standard errors + 0.002 K reached 0.51 of the std on the tiles turned per band,
    0.34 with these sixteen; 0.14-0.17 at 5 m/s.) Without whitecaps
    (their ensemble mean: tests/renderer/test_foam_terms.py)."""
    kw = dict(wind_speed=wind, pitch_deg=-15.0, altitude_m=10.0, roll_deg=0.0, hfov_deg=30.0, same_on_batch=True,
              foam=0.0)  # the waves' texture (whitecaps, rare and dark, make the realizations' means heavy-tailed)
    aug = small(**kw)
    aug(torch.zeros(1, 1, H, W), generator=torch.Generator().manual_seed(0))
    seeds = [11, 2**40 + 3, 77777, 2**61 + 5, 5, 2**33 + 1, 424242, 2**50 + 9,
             12, 2**41 + 7, 31337, 2**62 + 11, 6, 2**34 + 3, 909090, 2**51 + 13]
    B = len(seeds)
    params = {k: v.expand(B).clone() for k, v in aug._params.items() if v.ndim == 1 and v.shape[0] == 1}
    params["wave_seed"] = torch.tensor(seeds)
    tex = aug(torch.zeros(B, 1, H, W), params=params)
    flat = small(texture=False, **kw)(torch.zeros(B, 1, H, W), params={k: v for k, v in params.items()
                                                                       if k not in ("wave_seed", "time_s")})
    sea = rs.view_geometry(rs.make_camera(H, W, hfov_deg=30.0, altitude_m=10.0, pitch_deg=-15.0)).is_sea[0]
    d = (tex - flat)[:, 0][:, sea].double()
    std, mean = float(d.std()), float(d.mean())
    se = float(d.mean(1).std()) / math.sqrt(B)  # the realizations' means scatter (waves longer than the image)
    assert 0.01 < std < 3.0
    assert abs(mean) < 4 * se + 0.002, (mean, se, std)
    assert 4 * se + 0.002 < 0.4 * std  # the check can see a bias of 0.4 of the clutter
    # the realizations differ from each other (not one texture repeated)
    assert float((tex[0] - tex[1])[:, sea].abs().max()) > 0.1 * std


def test_calm_sea_is_the_expectation_image():
    """WaveField has no waves at W = 0: with texture on, a calm image is rendered as the
    expectation (its wave seed and time are drawn and ignored), in a batch with textured ones."""
    aug = small(wind_speed=0.0, pitch_deg=-10.0)
    x = torch.zeros(2, 1, H, W)
    y = aug(x, generator=torch.Generator().manual_seed(1))
    assert "wave_seed" in aug._params
    flat = small(texture=False)(x, params={k: v for k, v in aug._params.items() if k not in ("wave_seed", "time_s")})
    assert torch.equal(y, flat)
    mixed = {k: v.clone() for k, v in aug._params.items()}
    mixed["wind_speed"] = torch.tensor([0.0, 8.0], dtype=torch.float64)
    m = aug(x, params=mixed)
    torch.testing.assert_close(m[:1], flat[:1], rtol=0, atol=1e-4)
    ref = small(texture=False)(x, params={k: v for k, v in mixed.items() if k not in ("wave_seed", "time_s")})
    assert not torch.allclose(m[1:], ref[1:], rtol=0, atol=1e-3)  # the windy one is textured


def test_composite_is_alpha_blending_in_radiance(dtype):
    aug = RandomSeaBackground(mode="composite", output="radiance")
    x = torch.zeros(2, 2, H, W, dtype=dtype)
    x[:, 0] = 320.0  # a hot target [K]
    x[:, 1, :8] = 1.0  # opaque rows
    x[:, 1, 8:16] = 0.5  # half-transparent rows
    y = aug(x, generator=torch.Generator().manual_seed(0))
    sea = RandomSeaBackground(output="radiance")(x[:, :1], params=aug._params)
    t = rs.band_radiance(torch.tensor(320.0, dtype=dtype), rs.LWIR)
    torch.testing.assert_close(y[:, 0, :8], t.expand(2, 8, W))
    torch.testing.assert_close(y[:, 0, 8:16], 0.5 * (t + sea[:, 0, 8:16]))
    torch.testing.assert_close(y[:, 0, 16:], sea[:, 0, 16:], rtol=0, atol=0)
    assert torch.equal(y[:, 1], x[:, 1])  # alpha passes through
    # the same target given as radiance (target_unit="radiance") composites to the same image
    xr = x.clone()
    xr[:, 0] = t
    yr = RandomSeaBackground(mode="composite", output="radiance", target_unit="radiance")(xr, params=aug._params)
    torch.testing.assert_close(yr, torch.cat([y[:, :1], x[:, 1:]], 1), rtol=1e-6, atol=0)
    # a half-covering 320 K target over a ~290 K sea is warmer than the temperature average:
    # blending happens in radiance, which is convex in temperature
    bt = rs.brightness_temperature(y[:, 0, 8:16], rs.LWIR)
    bt_sea = rs.brightness_temperature(sea[:, 0, 8:16], rs.LWIR)
    assert bool((bt > 0.5 * (320.0 + bt_sea)).all())


def test_gradient_to_target_temperature():
    aug = RandomSeaBackground(mode="composite", output="brightness_temperature")
    x = torch.zeros(1, 2, H, W, dtype=torch.float64)
    x[:, 1, 4:8, 4:8] = 0.3
    x[:, 0] = 310.0
    x.requires_grad_(True)
    y = aug(x, generator=torch.Generator().manual_seed(0))
    (g,) = torch.autograd.grad(y[:, 0].sum(), x)
    assert torch.isfinite(g).all()
    # T_out = T_b(α B(T_t) + (1 − α) L_sea): dT_out/dT_t = α B'(T_t) / B'(T_out)
    t = torch.tensor([310.0], dtype=torch.float64, requires_grad=True)
    (db_t,) = torch.autograd.grad(rs.band_radiance(t, rs.LWIR).sum(), t)
    t_out = y[0, 0, 4:8, 4:8].detach().reshape(-1).requires_grad_(True)
    (db_out,) = torch.autograd.grad(rs.band_radiance(t_out, rs.LWIR).sum(), t_out)
    torch.testing.assert_close(g[0, 0, 4:8, 4:8].reshape(-1), 0.3 * db_t / db_out, rtol=1e-6, atol=0)
    assert float(g[0, 0, 10:].abs().max()) == 0.0  # α = 0: the target does not show


@pytest.mark.parametrize(
    "kwargs, key",
    [
        (dict(wind_speed=(10.0, 2.0)), "wind_speed"),
        (dict(altitude_m=(-5.0, 10.0)), "altitude_m"),
        (dict(pitch_deg=(-95.0, 0.0)), "pitch_deg"),
        (dict(sea_temperature="warm"), "sea_temperature"),
        (dict(atmospheres=["martian"]), "atmospheres"),
        (dict(atmospheres=[]), "atmospheres"),
        (dict(mode="paste"), "mode"),
        (dict(output="counts"), "output"),
        (dict(texture="yes"), "texture"),
        (dict(time_s=(-1.0, 10.0)), "time_s"),
        (dict(time_s=(20.0, 10.0)), "time_s"),
    ],
)
def test_bad_arguments_name_the_key(kwargs, key):
    with pytest.raises(ValueError, match=key):
        RandomSeaBackground(**kwargs)


def test_composite_needs_two_channels():
    with pytest.raises(ValueError, match="2 channels"):
        RandomSeaBackground(mode="composite")(torch.zeros(1, 1, H, W))


def test_sensor_output_replays_with_its_noise():
    from roughsea_torch.sensor import SensorModel

    aug = RandomSeaBackground(sensor=SensorModel.typical_lwir(), same_on_batch=True)
    x = torch.zeros(2, 1, H, W)
    y = aug(x, generator=torch.Generator().manual_seed(0))
    assert torch.equal(y, y.round()) and float(y.min()) >= 0 and float(y.max()) <= 2**14 - 1  # 14-bit counts
    assert torch.equal(aug(x, params=aug._params), y)  # the noise replays too
    # same scene on both images (same_on_batch) but the temporal noise differs with the noise seed
    params = {k: v.clone() for k, v in aug._params.items()}
    params["noise_seed"] = torch.tensor([1, 2])
    z = aug(x, params=params)
    d = (z[0] - z[1]).float()
    assert float(d.abs().max()) > 0 and abs(float(d.mean())) < 3.0 * float(d.std()) / d.numel() ** 0.5 + 1.0


@pytest.mark.skipif(not torch.cuda.is_available(), reason="needs CUDA")
def test_cuda_matches_cpu():
    """Parameters are drawn on the CPU, so a seed gives the same scenes on CUDA; the images agree
    to float32 rounding of the model (sensor noise too: it is drawn on the CPU per image)."""
    from roughsea_torch.sensor import SensorModel

    aug = RandomSeaBackground(output="brightness_temperature")
    x = torch.zeros(2, 1, H, W)
    a = aug(x, generator=torch.Generator().manual_seed(0))
    b = aug.to("cuda")(x.cuda(), generator=torch.Generator().manual_seed(0))
    torch.testing.assert_close(b.cpu(), a, rtol=0, atol=2e-3)  # kelvin
    s = RandomSeaBackground(sensor=SensorModel.typical_lwir())
    c = s(x, generator=torch.Generator().manual_seed(1))
    d = s.to("cuda")(x.cuda(), generator=torch.Generator().manual_seed(1))
    assert float((d.cpu() - c).abs().max()) <= 2.0  # counts: rounding of nearly equal radiances


class _SeaImages(torch.utils.data.Dataset):
    """Each item: one sea image drawn by the augmentation's own generator (what a user writes),
    with the wave seed it drew."""

    def __init__(self, aug):
        self.aug = aug

    def __len__(self):
        return 6

    def __getitem__(self, i):
        img = self.aug(torch.zeros(1, 1, 16, 20))[0]
        return img, int(self.aug._params["wave_seed"][0]), torch.utils.data.get_worker_info().id


def _worker_images(seed):
    aug = small(generator=torch.Generator().manual_seed(seed), wind_speed=(5.0, 12.0))
    loader = torch.utils.data.DataLoader(_SeaImages(aug), batch_size=1, num_workers=2)
    out = {0: [], 1: []}
    seeds = {0: [], 1: []}
    for img, wave_seed, wid in loader:
        out[int(wid)].append(img[0])
        seeds[int(wid)].append(int(wave_seed))
    return out, seeds


def test_dataloader_workers_draw_their_own_scenes():
    """A generator seeded once and copied into 2 DataLoader workers: the workers' scenes and wave
    seeds differ (each worker gets its own stream), and a second run with the same seed repeats
    them all."""
    a, sa = _worker_images(3)
    assert len(a[0]) == len(a[1]) == 3
    assert all(not torch.equal(x, y) for x in a[0] for y in a[1])
    assert len(set(sa[0] + sa[1])) == 6  # six textures, none shared between or within workers
    b, sb = _worker_images(3)
    assert all(torch.equal(x, y) for k in (0, 1) for x, y in zip(a[k], b[k]))
    assert sa == sb
    # the replay from kept parameters is unaffected (outside workers, from the instance's generator)
    aug = small(generator=torch.Generator().manual_seed(3))
    y = aug(torch.zeros(2, 1, 16, 20))
    assert torch.equal(aug(torch.zeros(2, 1, 16, 20), params=aug._params), y)


def test_foam_setting_reaches_the_rendered_seas():
    """RandomSeaBackground(foam=False) renders seas without whitecaps (the user's switch for the
    model's dark whitecaps near grazing): its images are render_parameters(..., foam=False) of its
    draw, bitwise, and at 15 m/s they differ from the default's, which are colder at their coldest
    sea pixel (the whitecaps). A bad setting is a ValueError naming foam."""
    from roughsea_torch.augmentation import render_parameters

    kw = dict(wind_speed=(15.0, 15.0), altitude_m=(15.0, 15.0), pitch_deg=(-6.0, -6.0), output="radiance")
    x = torch.zeros(2, 1, 24, 32)
    off = RandomSeaBackground(foam=False, **kw)
    y_off = off(x, generator=torch.Generator().manual_seed(3))
    assert torch.equal(y_off, render_parameters(off._params, 24, 32, off.sampler.atmospheres, foam=False))
    on = RandomSeaBackground(**kw)
    y_on = on(x, params=off._params)
    assert torch.equal(y_on, render_parameters(off._params, 24, 32, off.sampler.atmospheres))
    sea = rs.view_geometry(rs.make_camera(24, 32, hfov_deg=off._params["hfov_deg"], altitude_m=15.0,
                                          pitch_deg=-6.0, yaw_deg=off._params["yaw_deg"],
                                          roll_deg=off._params["roll_deg"])).is_sea[:, None]
    assert float(y_on[sea].min()) < float(y_off[sea].min()) - 0.05  # W m-2 sr-1: the whitecaps
    with pytest.raises(ValueError, match="foam"):
        RandomSeaBackground(foam="yes")


def test_texture_off_wins_over_a_replayed_textured_draw():
    """RandomSeaBackground(texture=False) given a textured augmentation's draw (which holds wave
    seeds) renders the expectation images of that draw (it rendered the textured seas); so does
    RandomSeaClip(texture=False)."""
    kw = dict(wind_speed=(8.0, 8.0), altitude_m=(10.0, 10.0), pitch_deg=(-8.0, -8.0), output="radiance")
    x = torch.zeros(2, 1, 24, 32)
    tex = RandomSeaBackground(**kw)
    y_tex = tex(x, generator=torch.Generator().manual_seed(1))
    assert "wave_seed" in tex._params
    y_off = RandomSeaBackground(texture=False, **kw)(x, params=tex._params)
    flat = {k: v for k, v in tex._params.items() if k != "wave_seed"}
    assert torch.equal(y_off, render_parameters(flat, 24, 32, tex.sampler.atmospheres))
    assert not torch.equal(y_off, y_tex)
    clip_kw = kw
    clip = rs.RandomSeaClip(**clip_kw)
    v = torch.zeros(2, 2, 1, 24, 32)
    v_tex = clip(v, generator=torch.Generator().manual_seed(1))
    v_off = rs.RandomSeaClip(texture=False, **clip_kw)(v, params=clip._params)
    assert not torch.equal(v_off, v_tex)
    assert torch.equal(v_off, rs.RandomSeaClip(texture=False, **clip_kw)(v, params={k: w for k, w in clip._params.items()
                                                                                   if k != "wave_seed"}))


def test_constructors_list_their_arguments():
    """RandomSeaBackground and RandomSeaClip take the shared arguments (RandomSeaBase._set_up's, one
    default each) through **shared, and inspect.signature still lists every argument in the order of
    the keyword-only constructors they had; an unknown keyword is Python's own TypeError."""
    import inspect

    from roughsea_torch.augmentation import MOTION_FIELDS, RandomSeaBase, RandomSeaClip

    shared = {n: q for n, q in inspect.signature(RandomSeaBase._set_up).parameters.items() if q.kind is q.KEYWORD_ONLY}
    still = inspect.signature(RandomSeaBackground).parameters
    clip = inspect.signature(RandomSeaClip).parameters
    assert list(still) == [*shared, "p", "same_on_batch", "keepdim"]
    assert list(clip) == ["frame_rate", "data_format", *(f[0] for f in MOTION_FIELDS), *shared, "p", "same_on_batch"]
    assert all(q.kind is q.KEYWORD_ONLY for q in (*still.values(), *clip.values()))
    assert all(still[n].default == q.default and clip[n].default == q.default for n, q in shared.items())
    assert still["texture"].default is True and clip["wind_speed"].default == (1.0, 15.0)
    for cls in (RandomSeaBackground, RandomSeaClip):
        with pytest.raises(TypeError, match=rf"^{cls.__name__}\.__init__\(\) got an unexpected keyword argument 'wind'$"):
            cls(wind=3.0, p=0.5)


def test_air_sea_difference_reaches_the_rendered_seas():
    """RandomSeaBackground(air_sea_difference=) draws each image's air as its sea plus the difference
    (kept in ``_params``, replayed), and the render uses that air: with the same generator (the same
    sea, wind, pose and atmosphere), air 5 K above the sea makes every pixel brighter than air 5 K
    below it (the sky the sea reflects and the path to the camera scale with B(T_air) / B(T_atm),
    docs/physics.md, *Air temperature*). RandomSeaClip forwards the range too."""
    x = torch.zeros(3, 1, H, W)
    kw = dict(sea_temperature=(285.0, 300.0), atmospheres=["midlatitude_summer", "subarctic_winter"], texture=False)
    warm, cold = small(air_sea_difference=5.0, **kw), small(air_sea_difference=-5.0, **kw)
    y_warm, y_cold = warm(x, generator=gen(4)), cold(x, generator=gen(4))
    for aug, d in ((warm, 5.0), (cold, -5.0)):
        p = aug._params
        torch.testing.assert_close(p["air_temperature"] - p["sea_temperature"], torch.full((3,), d, dtype=torch.float64),
                                   rtol=0, atol=1e-9)
    assert torch.equal(warm._params["sea_temperature"], cold._params["sea_temperature"])
    assert bool((y_warm > y_cold).all())
    assert torch.equal(warm(x, params={k: v.clone() for k, v in warm._params.items()}), y_warm)
    c = clip(air_sea_difference=(-3.0, 1.0), sea_temperature=(285.0, 300.0), texture=False, frame_rate=5.0)
    c(torch.zeros(4, 2, 1, 8, 10), generator=gen(2))
    d = c._params["air_temperature"] - c._params["sea_temperature"]
    assert float(d.min()) >= -3.0 - 1e-9 and float(d.max()) <= 1.0 + 1e-9


# ------------------------------------------------------------------------------------------------
# Clips: RandomSeaClip
# ------------------------------------------------------------------------------------------------
def test_layouts_and_replay():
    """BTCHW and BCTHW hold the same clip (the output keeps the input's layout); a replay from the
    kept parameters is bit for bit, and every clip has its own wave seed and start time."""
    a = clip(frame_rate=25.0, wind_speed=(5.0, 12.0))
    x = torch.zeros(2, 2, 2, H, W)  # B, T, C, H, W
    y = a(x, generator=torch.Generator().manual_seed(0))
    assert y.shape == x.shape and y.dtype == x.dtype
    assert torch.equal(y[:, :, :1], y[:, :, 1:])  # channels repeat the rendered frame
    assert torch.equal(a(x, params={k: v.clone() for k, v in a._params.items()}), y)
    assert a._params["wave_seed"].shape == (2,) and a._params["wave_seed"][0] != a._params["wave_seed"][1]
    b = clip(frame_rate=25.0, wind_speed=(5.0, 12.0), data_format="bcthw")
    z = b(x.transpose(1, 2), generator=torch.Generator().manual_seed(0))
    assert z.shape == (2, 2, 2, H, W) and torch.equal(z.transpose(1, 2), y)
    assert not torch.equal(y[:, 0], y[:, 1])  # the frames are not one image repeated


def test_frames_are_stills_at_their_pose_and_time():
    """Frame t of a clip is the still image of the clip's scene at the frame's pose and time
    (frame_parameters): the motion and the time reach the renderer, nothing else differs."""
    a = clip(frame_rate=2.0, wind_speed=8.0, pitch_deg=-6.0, altitude_m=15.0, pitch_amplitude_deg=2.0,
             roll_amplitude_deg=4.0, heave_amplitude_m=1.0)
    T = 3
    y = a(torch.zeros(1, T, 1, H, W), generator=torch.Generator().manual_seed(3))
    f = frame_parameters(a._params, T, 2.0)
    torch.testing.assert_close(f["time_s"][0], a._params["time_s"][0] + torch.tensor([0.0, 0.5, 1.0], dtype=torch.float64),
                               rtol=0, atol=1e-9)
    p = a._params
    # the pose is PlatformMotion's at t / frame_rate (pitch: amplitude · sin(2π t / T_p + φ) about the mean)
    want = p["pitch_deg"] + p["pitch_amplitude_deg"] * torch.sin(2 * math.pi * 0.5 / p["pitch_period_s"] + p["phase_rad"])
    torch.testing.assert_close(f["pitch_deg"][:, 1], want, rtol=0, atol=1e-12)
    assert f["noise_seed"][0, 0] == p["noise_seed"][0] and f["noise_seed"][0, 2] == frame_noise_seed(int(p["noise_seed"][0]), 2)
    for t in range(T):
        still = {k: v for k, v in p.items() if isinstance(v, torch.Tensor) and v.ndim == 1 and v.shape[0] == 1}
        still.update({k: f[k][:, t] for k in ("pitch_deg", "roll_deg", "altitude_m", "time_s")})
        L = render_parameters(still, H, W, a.sampler.atmospheres)
        assert torch.equal(rs.brightness_temperature(L, rs.LWIR), y[:, t])


def test_consecutive_frames_are_coherent():
    """The same sea 40 ms later (25 Hz) differs far less than 10 s later, when the waves at near
    range have moved by many wavelengths; the sky does not change with time."""
    kw = dict(wind_speed=(5.0, 12.0), pitch_deg=-15.0, altitude_m=10.0, roll_deg=0.0, hfov_deg=30.0, **STILL)
    fast = clip(frame_rate=25.0, **kw)
    x = torch.zeros(3, 2, 1, H, W)
    a = fast(x, generator=torch.Generator().manual_seed(0))
    b = clip(frame_rate=0.1, **kw)(x, params=fast._params)  # the same clips, frames 10 s apart
    assert torch.equal(a[:, 0], b[:, 0])
    sea = rs.view_geometry(rs.make_camera(H, W, hfov_deg=30.0, altitude_m=10.0, pitch_deg=-15.0)).is_sea[0]
    for i in range(3):
        near = float((a[i, 1, 0] - a[i, 0, 0])[sea].pow(2).mean().sqrt())
        far = float((b[i, 1, 0] - b[i, 0, 0])[sea].pow(2).mean().sqrt())
        assert 0.01 < far < 3.0  # K: decorrelated clutter
        assert near < 0.3 * far
        assert torch.equal(a[i, 1, 0][~sea], a[i, 0, 0][~sea])


def test_pitch_motion_moves_the_horizon():
    """A pitching camera (2°, 4 s period, sampled at 1 Hz): the horizon (the row where the warm
    sky near the horizon gives way to the sea, the largest drop of the row-mean brightness
    temperature) moves between frames by f · Δtan(pitch), f the focal length in pixels."""
    h, hfov = 48, 20.0
    a = clip(frame_rate=1.0, pitch_amplitude_deg=2.0, pitch_period_s=4.0, roll_amplitude_deg=0.0, heave_amplitude_m=0.0,
             pitch_deg=0.0, roll_deg=0.0, hfov_deg=hfov, altitude_m=20.0, wind_speed=8.0,
             generator=torch.Generator().manual_seed(0))
    params = a.generate_parameters(1)
    params["phase_rad"] = torch.tensor([0.0], dtype=torch.float64)  # pitch 0°, +2°, 0°, −2°, ...
    y = a(torch.zeros(1, 4, 1, h, W), params=params)
    pitch = frame_parameters(params, 4, 1.0)["pitch_deg"][0]
    torch.testing.assert_close(pitch, torch.tensor([0.0, 2.0, 0.0, -2.0], dtype=torch.float64), rtol=0, atol=1e-12)
    profile = y[0, :, 0].double().mean(-1)  # (T, H)
    rows = (profile[:, :-1] - profile[:, 1:]).argmax(-1).double()  # the drop between row r and r + 1
    f = (W / 2) / math.tan(math.radians(hfov / 2))
    dip = math.acos(rs.EARTH_RADIUS_M / (rs.EARTH_RADIUS_M + 20.0))
    want = torch.tensor([f * math.tan(math.radians(p) + dip) for p in pitch.tolist()], dtype=torch.float64)
    shift = rows - rows[0]  # looking up moves the horizon down the image (larger row)
    assert abs(float(shift[1] - (want[1] - want[0]))) <= 1.0 and abs(float(shift[3] - (want[3] - want[0]))) <= 1.0
    assert float(shift[1]) >= 2.0 and float(shift[3]) <= -2.0 and abs(float(shift[2])) <= 1.0


def test_composite_p_and_video_sequential():
    """Targets composite frame by frame (an opaque 320 K patch reads 320 K in every frame, alpha
    passes through); p gates whole clips; frame-wise kornia augmentations go after it."""
    a = clip(frame_rate=10.0, mode="composite", wind_speed=8.0)
    x = torch.zeros(2, 3, 2, H, W)
    x[:, :, 0] = 320.0
    x[:, :, 1, 2:6, 3:9] = 1.0
    y = a(x, generator=torch.Generator().manual_seed(1))
    torch.testing.assert_close(y[:, :, 0, 2:6, 3:9], torch.full((2, 3, 4, 6), 320.0), rtol=0, atol=1e-3)
    assert torch.equal(y[:, :, 1], x[:, :, 1])
    assert float((y[:, :, 0, 10:] - 320.0).abs().min()) > 5.0  # the sea, not the target, elsewhere
    g = clip(frame_rate=10.0, p=0.5, wind_speed=8.0)
    z = g(torch.full((8, 2, 1, H, W), -1.0), generator=torch.Generator().manual_seed(2))
    keep = g._params["batch_prob"] > 0.5
    assert 0 < int(keep.sum()) < 8
    assert bool((z[~keep] == -1.0).all()) and bool((z[keep] > 200.0).all())
    seq = K.VideoSequential(K.RandomHorizontalFlip(p=1.0), data_format="BTCHW")
    v = clip(frame_rate=10.0, wind_speed=8.0)
    c = v(torch.zeros(1, 2, 1, H, W), generator=torch.Generator().manual_seed(3))
    assert torch.equal(seq(c), c.flip(-1))


def test_sensor_noise_changes_from_frame_to_frame():
    """With a still camera over the expectation sea (texture off) two frames differ only by the
    sensor's temporal noise: about √2 · NETD rms in kelvin, not zero."""
    from roughsea_torch.sensor import DetectorNoise, SensorModel

    netd = 0.05
    a = RandomSeaClip(frame_rate=25.0, texture=False, sensor=SensorModel(noise=DetectorNoise(netd_k=netd)),
                      pitch_deg=-10.0, **STILL)
    y = a(torch.zeros(2, 2, 1, H, W, dtype=torch.float64), generator=torch.Generator().manual_seed(4))
    bt = rs.brightness_temperature(y[:, :, 0], rs.LWIR)
    rms = float((bt[:, 1] - bt[:, 0]).pow(2).mean().sqrt())
    assert 0.8 * math.sqrt(2) * netd < rms < 1.2 * math.sqrt(2) * netd
    assert torch.equal(a(torch.zeros(2, 2, 1, H, W, dtype=torch.float64), params=a._params), y)


@pytest.mark.parametrize(
    "kwargs, key",
    [
        (dict(frame_rate=0.0), "frame_rate"),
        (dict(frame_rate=float("nan")), "frame_rate"),
        (dict(data_format="BCHW"), "data_format"),
        (dict(heave_amplitude_m=(0.0, 12.0), altitude_m=(10.0, 20.0)), "heave_amplitude_m"),
        (dict(pitch_amplitude_deg=5.0, pitch_deg=(-88.0, -1.0)), "pitch_amplitude_deg"),
        (dict(roll_period_s=(0.0, 5.0)), "roll_period_s"),
        (dict(pitch_amplitude_deg=(3.0, 1.0)), "pitch_amplitude_deg"),
        (dict(p=1.5), "p"),
        (dict(texture=1), "texture"),
    ],
)
def test_clip_bad_arguments_name_the_key(kwargs, key):
    with pytest.raises(ValueError, match=key):
        RandomSeaClip(**kwargs)


def test_bad_input_is_refused():
    with pytest.raises(ValueError, match=r"input must be a 5-D clip B, T, C, H, W"):
        clip()(torch.zeros(2, 1, H, W))
    with pytest.raises(ValueError, match="2 channels"):
        clip(mode="composite")(torch.zeros(1, 2, 1, H, W))
    with pytest.raises(ValueError, match=r"input: dtype"):
        clip()(torch.zeros(1, 2, 1, H, W, dtype=torch.float16))


def test_clip_wave_time_stays_float64_in_float32_clips():
    """The augmentations hand the wave time to the renderer in float64: a float32 clip at 86 000 s
    (inside the default draw range's bound) matches the float64 clip to 6e-4 K (2.7e-4 measured;
    1.4e-3 when the time was cast to float32, found in review)."""
    out = {}
    for dtype in (torch.float32, torch.float64):
        clip = rs.RandomSeaClip(wind_speed=(6.0, 6.0), altitude_m=(10.0, 10.0), pitch_deg=(-8.0, -8.0),
                                time_s=(86000.0, 86000.0), output="brightness_temperature", foam=False)
        out[dtype] = clip(torch.zeros(1, 3, 1, 16, 20, dtype=dtype), generator=torch.Generator().manual_seed(0)).double()
    assert float((out[torch.float32] - out[torch.float64]).abs().max()) < 6e-4


# ------------------------------------------------------------------------------------------------
# Day images
# ------------------------------------------------------------------------------------------------
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
    yn, yd, yb = night(x, generator=gen(1)), day(x, generator=gen(1)), behind(x, generator=gen(1))
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
    y = aug(x, generator=gen(2))
    p = aug._params
    assert 0 < int(p["is_day"].sum()) < 4  # both kinds in the batch
    assert torch.equal(aug(x, params=p), y)
    assert torch.equal(render_parameters(p, H, W, aug.sampler.atmospheres, band=rs.MWIR), y)
    clip = RandomSeaClip(daytime=1.0, band=rs.MWIR, sun_elevation_deg=8.0, sun_azimuth_deg=0.0, wind_speed=5.0,
                         altitude_m=20.0, pitch_deg=-3.0, output="brightness_temperature", frame_rate=10.0,
                         texture=False)
    xc = torch.zeros(1, 2, 1, H, W)
    yc = clip(xc, generator=gen(4))
    assert torch.equal(clip(xc, params=clip._params), yc)
    assert float(yc.amax(dim=(2, 3, 4)).min()) > 350.0  # the glint in every frame (the sea is ~290 K)


@pytest.mark.parametrize("cls", [RandomSeaBackground, RandomSeaClip])
def test_composite_mode_refuses_a_gate_that_would_mix_units(cls):
    """In composite mode an input is a target chip (kelvin and α): a chip left out by p < 1 came back
    beside sensor counts in one batch (means 305 K and ~7000 counts). p < 1 is refused there, naming
    p; replace mode keeps kornia's p (an unselected image is the input itself)."""
    with pytest.raises(ValueError, match=r"^p must be 1 with mode='composite'"):
        cls(mode="composite", p=0.5)
    assert cls(mode="composite", p=1.0).p == 1.0
    assert cls(mode="replace", p=0.5).p == 0.5


def test_replace_mode_leaves_unselected_images_as_they_came():
    aug = RandomSeaBackground(p=0.5, output="brightness_temperature", texture=False)
    x = torch.full((8, 1, 12, 16), -1.0)
    y = aug(x, generator=torch.Generator().manual_seed(3))
    kept = (y == -1.0).flatten(1).all(1)
    assert 0 < int(kept.sum()) < 8  # some images left out, some rendered
    assert bool((y[~kept] > 200.0).all())  # the rendered ones are sea temperatures


"""RandomSeaBackground and SceneSampler: kornia conventions, reproducibility, and physics of the
compositing and of the parameters' plumbing into the renderer."""

from __future__ import annotations

import math

import kornia.augmentation as K
import pytest
import torch

import roughsea_torch as rs
from roughsea_torch.augmentation import RandomSeaBackground, SceneSampler, render_parameters

H, W = 24, 32


def small(**kw):
    kw.setdefault("output", "brightness_temperature")
    return RandomSeaBackground(**kw)


@pytest.mark.parametrize("dtype", [torch.float32, torch.float64])
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


def test_rendering_matches_an_explicit_scene():
    """The parameters reach the renderer in the documented units (wind direction in degrees,
    per-image atmospheres): a mixed-atmosphere batch equals each image rendered on its own."""
    s = SceneSampler(atmospheres=["tropical", "midlatitude_winter"], air_temperature=(270.0, 300.0),
                     yaw_deg=(-180.0, 180.0), pitch_deg=(-25.0, -2.0))
    p = s.sample(4, generator=torch.Generator().manual_seed(9))
    p["atmosphere"] = torch.tensor([0, 1, 0, 1])
    img = render_parameters(p, H, W, s.atmospheres, dtype=torch.float64)
    no_path = render_parameters(p, H, W, s.atmospheres, dtype=torch.float64, path=False)
    for i in range(4):
        cam = rs.make_camera(H, W, hfov_deg=float(p["hfov_deg"][i]), altitude_m=float(p["altitude_m"][i]),
                             pitch_deg=float(p["pitch_deg"][i]), yaw_deg=float(p["yaw_deg"][i]),
                             roll_deg=float(p["roll_deg"][i]), dtype=torch.float64)
        scene = rs.SeaScene(wind_speed=float(p["wind_speed"][i]), wind_direction=math.radians(float(p["wind_direction_deg"][i])),
                            sea_temperature=float(p["sea_temperature"][i]), air_temperature=float(p["air_temperature"][i]),
                            sky=s.atmospheres[int(p["atmosphere"][i])])
        ref = rs.render(cam, scene)
        torch.testing.assert_close(img[i : i + 1], ref, rtol=1e-7, atol=0.0)  # batching order only
        scene.path = None
        torch.testing.assert_close(no_path[i : i + 1], rs.render(cam, scene), rtol=1e-7, atol=0.0)
    assert not torch.allclose(img, no_path)


def test_textured_parameters_reach_the_renderer():
    """A textured draw renders, image by image, ``SeaScene(seed=wave_seed, time_s=time_s)``: the
    seed and the time [s] reach the renderer (and the batch does not change an image)."""
    s = SceneSampler(atmospheres=["tropical", "us_standard"], wind_speed=(4.0, 12.0), pitch_deg=(-15.0, -5.0),
                     altitude_m=(10.0, 30.0), texture=True)
    p = s.sample(3, generator=torch.Generator().manual_seed(4))
    img = render_parameters(p, H, W, s.atmospheres, dtype=torch.float64)
    for i in range(3):
        cam = rs.make_camera(H, W, hfov_deg=float(p["hfov_deg"][i]), altitude_m=float(p["altitude_m"][i]),
                             pitch_deg=float(p["pitch_deg"][i]), yaw_deg=float(p["yaw_deg"][i]),
                             roll_deg=float(p["roll_deg"][i]), dtype=torch.float64)
        scene = rs.SeaScene(wind_speed=float(p["wind_speed"][i]), wind_direction=math.radians(float(p["wind_direction_deg"][i])),
                            sea_temperature=float(p["sea_temperature"][i]), sky=s.atmospheres[int(p["atmosphere"][i])],
                            seed=int(p["wave_seed"][i]), time_s=float(p["time_s"][i]))
        torch.testing.assert_close(img[i : i + 1], rs.render(cam, scene), rtol=1e-7, atol=0.0)
        scene.time_s = float(p["time_s"][i]) + 5.0  # another moment of the same sea is another image
        assert not torch.allclose(img[i : i + 1], rs.render(cam, scene), rtol=1e-5, atol=0.0)


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
    a = small(generator=torch.Generator().manual_seed(5))
    b = small(generator=torch.Generator().manual_seed(5), texture=False)
    a(torch.zeros(2, 1, H, W))
    b(torch.zeros(2, 1, H, W))
    assert "wave_seed" not in b._params
    assert all(torch.equal(a._params[k], b._params[k]) for k in off)


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
    plausible clutter (std between 0.01 and 3 K); over four realizations the mean departure over
    the sea pixels is a small fraction of it (the expectation is the ensemble mean; the
    brightness temperature's curvature and four samples leave a little)."""
    kw = dict(wind_speed=wind, pitch_deg=-15.0, altitude_m=10.0, roll_deg=0.0, hfov_deg=30.0, same_on_batch=True)
    aug = small(**kw)
    aug(torch.zeros(1, 1, H, W), generator=torch.Generator().manual_seed(0))
    B = 4
    params = {k: v.expand(B).clone() for k, v in aug._params.items() if v.ndim == 1 and v.shape[0] == 1}
    params["wave_seed"] = torch.tensor([11, 2**40 + 3, 77777, 2**61 + 5])
    tex = aug(torch.zeros(B, 1, H, W), params=params)
    flat = small(texture=False, **kw)(torch.zeros(B, 1, H, W), params={k: v for k, v in params.items()
                                                                       if k not in ("wave_seed", "time_s")})
    sea = rs.view_geometry(rs.make_camera(H, W, hfov_deg=30.0, altitude_m=10.0, pitch_deg=-15.0)).is_sea[0]
    d = (tex - flat)[:, 0][:, sea].double()
    std, mean = float(d.std()), float(d.mean())
    assert 0.01 < std < 3.0
    assert abs(mean) < 0.2 * std
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


@pytest.mark.parametrize("dtype", [torch.float32, torch.float64])
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


@pytest.mark.parametrize("dtype", [torch.float16, torch.bfloat16])
@pytest.mark.parametrize("mode", ["replace", "composite"])
def test_half_precision_input_is_refused(dtype, mode):
    """float16 steps are 0.25 K near 290 K (rounding by up to 0.125 K, against a 0.05 K NETD) and hold integers
    exactly only to 2048: the output cannot carry the result in the input's dtype."""
    assert float(torch.tensor(290.0, dtype=torch.float16).nextafter(torch.tensor(300.0, dtype=torch.float16)) - 290.0) == 0.25
    x = torch.zeros(1, 2 if mode == "composite" else 1, H, W, dtype=dtype)
    with pytest.raises(ValueError, match=r"input: dtype .*float32"):
        RandomSeaBackground(mode=mode, output="brightness_temperature")(x)


@pytest.mark.parametrize("bad", [2.0, -0.1, float("nan")])
def test_alpha_outside_the_unit_interval_is_refused(bad):
    x = torch.zeros(2, 2, H, W)
    x[:, 0] = 300.0
    x[1, 1, 3, 4] = bad
    with pytest.raises(ValueError, match=r"alpha \(input channel 1.*\[0, 1\]"):
        RandomSeaBackground(mode="composite", output="radiance")(x)
    x[1, 1, 3, 4] = 1.0  # the edges of the range are fine
    RandomSeaBackground(mode="composite", output="radiance")(x)


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

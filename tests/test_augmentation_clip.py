"""RandomSeaClip: kornia's video layouts, replay, temporal coherence of the sea, the platform's
motion in the image, and frames that equal still images rendered at their pose and time."""

from __future__ import annotations

import math

import kornia.augmentation as K
import pytest
import torch

import roughsea_torch as rs
from roughsea_torch.augmentation import RandomSeaClip, frame_noise_seed, frame_parameters, render_parameters

H, W = 24, 32
STILL = dict(pitch_amplitude_deg=0.0, roll_amplitude_deg=0.0, heave_amplitude_m=0.0)  # a camera that does not move


def clip(**kw):
    kw.setdefault("output", "brightness_temperature")
    return RandomSeaClip(**kw)


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
def test_bad_arguments_name_the_key(kwargs, key):
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

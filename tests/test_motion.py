"""The platform's motion and clips (roughsea_torch.motion): PlatformMotion checks its poses when it is
built, render_clip every time argument (a ValueError naming it and its range)."""

from __future__ import annotations

import copy
import math

import pytest
import torch

import roughsea_torch as rs

from conftest import TIME_RANGE, make_scene

H, W = 8, 10


def test_render_clip_checks_every_time_argument():
    motion = rs.PlatformMotion(height=H, width=W, altitude_m=15.0)
    times = torch.arange(2) / 25.0
    for start in (float("nan"), float("inf"), torch.tensor([0.0, float("nan")])):
        with pytest.raises(ValueError, match=r"^start_s must lie in " + TIME_RANGE):
            rs.render_clip(motion, make_scene(seed=1), times, start_s=start)
    with pytest.raises(ValueError, match=r"^start_s \+ times_s must lie in " + TIME_RANGE):
        rs.render_clip(motion, make_scene(seed=1), times, start_s=1e9)  # the last frame at 1e9 + 0.04 s
    with pytest.raises(ValueError, match=r"^scene.time_s \+ times_s must lie in " + TIME_RANGE):
        rs.render_clip(motion, make_scene(seed=1, time_s=1e9), times)
    with pytest.raises(ValueError, match=r"^times_s must lie in " + TIME_RANGE):
        rs.render_clip(motion, make_scene(seed=1), torch.tensor([0.0, float("inf")]))
    with pytest.raises(ValueError, match=r"^times_s must be a real number"):
        rs.render_clip(motion, make_scene(seed=1), ["a"])
    with pytest.raises(ValueError, match=r"^times_s: must be a non-empty 1-D sequence.*\(2, 2\)"):
        rs.render_clip(motion, make_scene(seed=1), torch.zeros(2, 2))  # used to be flattened to 4 frames
    with pytest.raises(ValueError, match=r"^time_s must lie in " + TIME_RANGE):
        motion.cameras(float("inf"))  # used to fail on the NaN pitch it made


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


def test_platform_pose_follows_the_documented_harmonic_motion():
    """pitch(t) = pitch + A_p sin(2π t/T_p + φ), roll(t) = roll + A_r sin(2π t/T_r + φ + π/2) and
    altitude(t) = altitude + A_h sin(2π t/T_h + φ) (the class docstring), for one platform and for a
    batch of platforms, over more than a period of each."""
    kw = {"altitude_m": 20.0, "pitch_deg": -3.0, "roll_deg": 1.0, "pitch_amplitude_deg": 1.5, "roll_amplitude_deg": 2.5,
          "heave_amplitude_m": 0.7, "pitch_period_s": 6.0, "roll_period_s": 9.0, "heave_period_s": 7.0, "phase_rad": 0.4}
    motion = rs.PlatformMotion(**kw)
    for t in (0.0, 1.3, 2.25, 4.0, 7.7, 11.0):
        pose = motion.pose(t)
        assert pose["pitch_deg"] == pytest.approx(-3.0 + 1.5 * math.sin(2 * math.pi * t / 6.0 + 0.4), abs=1e-12)
        assert pose["roll_deg"] == pytest.approx(1.0 + 2.5 * math.sin(2 * math.pi * t / 9.0 + 0.4 + math.pi / 2), abs=1e-12)
        assert pose["altitude_m"] == pytest.approx(20.0 + 0.7 * math.sin(2 * math.pi * t / 7.0 + 0.4), abs=1e-12)
    batch = rs.PlatformMotion(**{**kw, "phase_rad": torch.tensor([0.0, 1.0], dtype=torch.float64)})
    t = torch.tensor([0.5, 3.0], dtype=torch.float64)
    arg = 2 * math.pi * t / 9.0 + torch.tensor([0.0, 1.0], dtype=torch.float64) + math.pi / 2
    torch.testing.assert_close(batch.pose(t)["roll_deg"], 1.0 + 2.5 * torch.sin(arg), rtol=0, atol=1e-12)


@pytest.mark.parametrize("start", [None, 3.0, torch.tensor([3.0, 10.0], dtype=torch.float64)], ids=["scene_time", "float", "per_image"])
def test_clip_frame_t_shows_the_sea_at_start_plus_t(start):
    """render_clip: frame t is the sea of the scene's realization at start_s + times_s[t] (start_s
    defaults to the scene's time_s), each image's own start when start_s is per image, seen by the
    cameras of that time (still cameras here): equal to a still render at that time."""
    cams = rs.make_camera(12, 10, hfov_deg=10.0, altitude_m=10.0, pitch_deg=-8.0, batch_size=2, dtype=torch.float64)
    scene = rs.SeaScene(wind_speed=8.0, sea_temperature=290.0, sky=10.0, path=False, seed=[1, 2], time_s=1.0)
    times = [0.0, 0.4, 2.0]
    clip = rs.render_clip(cams, scene, torch.tensor(times, dtype=torch.float64), start_s=start)
    base = 1.0 if start is None else start
    for k, t in enumerate(times):
        still = copy.copy(scene)
        still.time_s = base + t
        torch.testing.assert_close(clip[:, k], rs.render(cams, still), rtol=1e-12, atol=0)
    assert float((clip[:, 2] - clip[:, 0]).abs().max()) > 1e-3  # the sea moved

"""roughsea_torch.motion: the moving platform's pose and the clip's frame times."""

from __future__ import annotations

import copy
import math

import pytest
import torch

import roughsea_torch as rs


def test_platform_pose_follows_the_documented_harmonic_motion():
    """pitch(t) = pitch + A_p sin(2π t/T_p + φ), roll(t) = roll + A_r sin(2π t/T_r + φ + π/2) and
    altitude(t) = altitude + A_h sin(2π t/T_h + φ) (the class docstring), for one platform and for a
    batch of platforms, over more than a period of each."""
    kw = dict(altitude_m=20.0, pitch_deg=-3.0, roll_deg=1.0, pitch_amplitude_deg=1.5, roll_amplitude_deg=2.5,
              heave_amplitude_m=0.7, pitch_period_s=6.0, roll_period_s=9.0, heave_period_s=7.0, phase_rad=0.4)
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

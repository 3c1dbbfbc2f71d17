"""The platform's motion and clips (roughsea_torch.motion): PlatformMotion checks its poses when it is
built, render_clip every time argument (a ValueError naming it and its range)."""

from __future__ import annotations

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

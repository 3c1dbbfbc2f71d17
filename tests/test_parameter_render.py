"""Rendering drawn parameters (roughsea_torch.parameter_render, render_parameters): the parameters
reach the renderer in the documented units, per image (each image equals its own scene rendered
alone), textured draws with their seed and time."""

from __future__ import annotations

import math
import warnings

import torch

import roughsea_torch as rs
from roughsea_torch.augmentation import SceneSampler, render_parameters

H, W = 24, 32


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


def test_drawn_wind_directions_beyond_a_turn_render_silently_as_the_same_direction():
    """The samplers accept wind directions in [−3600, 3600]°; drawn beyond a full turn they are the same
    direction wrapped, so rendering them neither triggers SeaScene's degrees warning (radians beyond 2π) nor
    changes the image: a textured batch drawn in [360, 720)° equals the same draws less 360° (to 1e-9 in
    float64, relative: the wrap rounds the angle's last bits)."""
    s = SceneSampler(wind_direction_deg=(360.0, 720.0), texture=True, pitch_deg=(-10.0, -4.0))
    p = s.sample(2, generator=torch.Generator().manual_seed(4))
    q = dict(p, wind_direction_deg=p["wind_direction_deg"] - 360.0)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        a = render_parameters(p, H, W, s.atmospheres, dtype=torch.float64)
        b = render_parameters(q, H, W, s.atmospheres, dtype=torch.float64)
    assert float(((a - b) / b).abs().max()) < 1e-9

"""roughsea_torch.raytrace_glitter: the glitter spots of a realization (Newton from ray hits), checked
with the wave field's public sampling: each spot mirrors the camera's ray into the sun."""

from __future__ import annotations

import math

import pytest
import torch

import roughsea_torch as rs
from roughsea_torch.optics import band_refractive_index
from roughsea_torch.raytrace_glitter import glitter_spots

pytestmark = pytest.mark.usefixtures("one_thread")

SUN_Z = math.radians(75.0)


def _patch(seed=1):
    cam = rs.make_camera(10, 10, hfov_deg=10 * 0.047, altitude_m=10.0, pitch_deg=-10.0, dtype=torch.float64)
    scene = rs.SeaScene(wind_speed=8.0, band=rs.MWIR, sea_temperature=290.0, seed=seed, foam=False, path=False)
    return cam, scene.wave_field(1, torch.float64, torch.device("cpu"))


def test_each_spot_mirrors_the_camera_ray_into_the_sun_and_the_two_areas_agree():
    cam, field = _patch()
    out = glitter_spots(cam, field, SUN_Z, 0.0, 12.0, band_refractive_index(rs.MWIR, 290.0), rays_per_pixel=32,
                        third_derivative=1600.0)
    assert out["spots"] > 50
    x, y = out["spot_x"][None], out["spot_y"][None]
    smp = field.sample(x, y)  # the field's own evaluation (the tracer reads its tiles separately)
    c = -(cam.rotation_matrix.transpose(-1, -2) @ cam.translation_vector)[0, :, 0]
    p = torch.stack([x[0], y[0], smp["elevation"][0]], -1)
    v = torch.nn.functional.normalize(c - p, dim=-1)
    n = torch.nn.functional.normalize(torch.stack([smp["slope_x"][0], smp["slope_y"][0], torch.ones_like(x[0])], -1), dim=-1)
    r = 2.0 * (v * n).sum(-1, keepdim=True) * n - v
    sun = torch.tensor([math.sin(SUN_Z), 0.0, math.cos(SUN_Z)], dtype=torch.float64)
    angle = torch.acos(((r * sun).sum(-1)).clamp(-1.0, 1.0))
    assert float(angle.max()) < 1e-6  # specular for the sun's centre (its radius is 4.7e-3 rad)
    # the pixel of each spot is where the camera sees it
    uv = cam.project(p[None])[0]
    torch.testing.assert_close(uv, torch.stack([out["spot_u"], out["spot_v"]], -1))
    # the box-integrated and the linearized (capped) areas agree on the patch's glint within 15 %
    a, b = float(out["glint"].sum()), float(out["linearized_glint"].sum())
    assert abs(a / b - 1.0) < 0.15
    assert int(out["spots_per_pixel"].sum()) == out["spots"]


def test_bad_input_raises_value_error():
    cam, field = _patch()
    with pytest.raises(ValueError, match="float64 WaveField"):
        glitter_spots(cam, rs.WaveField(8.0, seed=1), SUN_Z, 0.0, 12.0, 1.4 + 0.01j)
    with pytest.raises(ValueError, match="rays_per_pixel"):
        glitter_spots(cam, field, SUN_Z, 0.0, 12.0, 1.4 + 0.01j, rays_per_pixel=0)

"""render() and SeaRenderer (roughsea_torch.renderer.api) end to end: the image is invariant under a
rotation of the whole scene, obeys the second law through every stage, carries gradients that match
finite differences (and none when nothing requires them), SeaRenderer equals render, and the render's
own arguments are checked."""

from __future__ import annotations

import math

import pytest
import torch

import roughsea_torch as rs

from conftest import make_cams, make_scene, smooth_sky, varied_cameras


def test_rotating_wind_and_camera_together_leaves_the_image_unchanged():
    """Azimuth conventions end to end: the scene is symmetric under a rotation about the vertical, so
    yaw + δ with wind direction + δ gives the same image (anisotropic slopes, table method)."""
    def img(yaw_deg, wind_dir):
        cams = make_cams(altitude_m=30.0, pitch_deg=-4.0, yaw_deg=yaw_deg)
        return rs.render(cams, make_scene(wind_speed=15.0, wind_direction=wind_dir, sky=smooth_sky))

    a = img(0.0, 0.3)
    b = img(40.0, 0.3 + math.radians(40.0))
    c = img(40.0, 0.3)  # camera turned, wind not: a different view of the anisotropic sea
    torch.testing.assert_close(a, b, rtol=2e-6, atol=0)
    assert (a - c).abs().max() > 1e-3


def test_second_law_whole_image_is_uniform_brightness_temperature():
    """Sky radiance equal to the sea's blackbody radiance everywhere ⇒ every pixel, sea or sky, is
    at the sea temperature (Eq. 10 with R_s ≡ R_B, through geometry, tables and grid_sample; the active
    whitecaps' skin deficit set to 0, so that the foam too is at the sea temperature)."""
    t_sea = 291.5
    rb = float(rs.band_radiance(torch.tensor(t_sea, dtype=torch.float64)))
    cams = varied_cameras(torch.float64, 32, 40)
    scene = rs.SeaScene(wind_speed=torch.tensor([1.0, 5.0, 10.0, 20.0, 30.0]), sea_temperature=t_sea, sky=rb,
                        skin_deficit=0.0)
    with pytest.warns(UserWarning, match="above 25 m/s"):  # 30 m/s: the whitecap law is held at 25 m/s
        bt = rs.render(cams, scene, output="brightness_temperature")
    torch.testing.assert_close(bt, torch.full_like(bt, t_sea), rtol=0, atol=1e-9)


def test_gradients_match_finite_differences():
    """d image / d (wind speed, sea temperature, pitch, altitude), float64, table method."""
    def image(w, t, pitch, alt):
        cams = make_cams(12, 16, hfov_deg=20.0, altitude_m=alt, pitch_deg=pitch, yaw_deg=10.0)
        scene = make_scene(wind_speed=w, wind_direction=0.4, sea_temperature=t, sky=smooth_sky)
        return rs.render(cams, scene, output="brightness_temperature")

    x0 = [torch.tensor(v, dtype=torch.float64) for v in (7.0, 290.0, -6.0, 30.0)]
    xs = [v.clone().requires_grad_(True) for v in x0]
    img = image(*xs)
    weights = torch.linspace(0.5, 1.5, img.numel(), dtype=torch.float64).reshape(img.shape)
    grads = torch.autograd.grad((img * weights).sum(), xs)
    steps = (1e-3, 1e-3, 1e-4, 1e-3)
    for i, (g, h) in enumerate(zip(grads, steps)):
        up = [v.clone() for v in x0]
        dn = [v.clone() for v in x0]
        up[i] += h
        dn[i] -= h
        fd = ((image(*up) - image(*dn)) * weights).sum() / (2 * h)
        assert torch.isfinite(g)
        assert abs(float(g) - float(fd)) <= 2e-3 * abs(float(fd)) + 1e-8, (i, float(g), float(fd))


def test_nothing_requires_grad_means_no_graph():
    cams = make_cams(8, 8, dtype=torch.float32)
    img = rs.render(cams, make_scene(wind_speed=5.0, sky=smooth_sky))
    assert img.grad_fn is None and not img.requires_grad


def test_module_equals_function_and_no_sky_work_when_no_sky():
    """An all-sea view makes no call for the sky rows of the table (shape (B, fine_sky)); a view
    with sky does."""
    shapes = []

    def counting_sky(c):
        shapes.append(tuple(c.shape))
        return smooth_sky(c)

    scene = make_scene(sky=counting_sky)
    all_sea = make_cams(16, 16, altitude_m=100.0, pitch_deg=-60.0, dtype=torch.float32)
    assert rs.view_geometry(all_sea).is_sea.all()
    a = rs.SeaRenderer()(all_sea, scene)
    rows = (1, rs.TableSize().fine_sky)
    assert rows not in shapes
    b = rs.render(all_sea, scene)
    assert torch.equal(a, b)
    shapes.clear()
    rs.render(make_cams(16, 16, altitude_m=100.0, pitch_deg=0.0, dtype=torch.float32), scene)
    assert rows in shapes


@pytest.mark.parametrize(
    "call, match",
    [
        (lambda: rs.render(rs.make_camera(8, 8, batch_size=2), rs.SeaScene(wind_speed=torch.ones(3), sea_temperature=290.0, sky=1.0)), "batch size"),
        (lambda: rs.render(rs.make_camera(8, 8), rs.SeaScene(wind_speed=3.0, sea_temperature=290.0, sky=1.0), method="fast"), "method"),
    ],
)
def test_render_errors(call, match):
    with pytest.raises(ValueError, match=match):
        call()


@pytest.mark.parametrize("chunk", [0, -1, 1.5, True, "2"])
def test_render_chunk_must_be_a_positive_int(chunk):
    cams = make_cams(8, 10, batch_size=1, altitude_m=15.0, dtype=torch.float32)
    with pytest.raises(ValueError, match=r"^chunk must be None or an int in \[1, inf\)"):
        rs.render(cams, make_scene(seed=None), chunk=chunk)

"""The per-pixel chain (roughsea_torch.renderer.pixels): in place in a per-thread workspace kept
between calls, bit-identical when repeated and equal to the general (autograd) path; the general path
where a gradient flows through the table's coordinates; no workspace kept for ended threads."""

from __future__ import annotations

import threading

import pytest
import torch

import roughsea_torch as rs

from conftest import make_cams, make_scene, smooth_sky, varied_cameras


@pytest.mark.filterwarnings("ignore:wind_speed above 25 m/s:UserWarning")  # winds past the whitecap law's cap (tests/test_foam.py)
@pytest.mark.parametrize("anisotropic", [False, True])
def test_workspace_reused_across_calls_and_equal_to_the_autograd_path(anisotropic):
    """Without gradients through the rays, the per-pixel chain runs in place in a per-thread workspace
    kept between calls (roughsea_torch.renderer.pixels). A render repeated after renders of other cameras,
    shapes and dtypes, and after release_workspace, is bit-identical; and it equals the general path
    (taken when the pose requires grad) to float32 rounding (2.4e-7 relative measured), sea and sky."""
    scene = rs.SeaScene(wind_speed=torch.tensor([2.0, 10.0, 25.0, 0.0, 40.0]), anisotropic=anisotropic,
                        wind_direction=torch.tensor([0.3, 1.0, 2.5, -1.0, 0.0]), sea_temperature=290.0,
                        sky="midlatitude_summer")
    cams = varied_cameras(torch.float32)
    first = rs.render(cams, scene)
    rs.render(varied_cameras(torch.float32, 40, 48), scene)
    rs.render(make_cams(64, 80, altitude_m=torch.full((5,), 50.0), pitch_deg=torch.full((5,), 4.0), dtype=torch.float32), scene)
    rs.render(varied_cameras(torch.float64), scene)
    assert torch.equal(rs.render(cams, scene), first)
    rs.release_workspace()
    assert torch.equal(rs.render(cams, scene), first)
    from roughsea_torch.renderer import pixels as _pixels
    assert _pixels._spaces  # the in-place path ran (it holds a workspace again)
    alt = torch.tensor([20.0, 200.0, 2000.0, 5.0, 20.0], requires_grad=True)
    cams_grad = rs.make_camera(64, 80, hfov_deg=torch.tensor([30.0, 30.0, 60.0, 10.0, 40.0]), altitude_m=alt,
                               pitch_deg=torch.tensor([-3.0, -10.0, -45.0, -0.5, -89.0]),
                               yaw_deg=torch.tensor([0.0, 40.0, 100.0, -30.0, 0.0]),
                               roll_deg=torch.tensor([0.0, 5.0, -10.0, 2.0, 0.0]))
    general = rs.render(cams_grad, scene)
    assert general.requires_grad
    assert float(((general.detach() - first) / first).abs().max()) < 1e-6


def test_wind_direction_gradient_through_the_table_coordinates():
    """The table's azimuth coordinate depends on wind_direction (its offset and span), so a gradient
    with respect to it flows through the per-pixel maps: the renderer then takes the general path, not
    the in-place one (whose out= operations record no gradient: it raised). float64, anisotropic sea,
    d(weighted image)/d(wind_direction) against a central difference to 5e-3 relative: through the
    table's azimuth coordinate the derivative is the slope of the bilinear cell, first-order accurate
    (1.8e-3 measured; a gradient through the table's values, e.g. wind speed, is 2e-3-exact,
    tests/renderer/test_api.py::test_gradients_match_finite_differences)."""
    cams = make_cams(altitude_m=torch.tensor([20.0, 150.0]), pitch_deg=torch.tensor([-3.0, -10.0]),
                     yaw_deg=torch.tensor([10.0, -30.0]))

    def image(wd):
        return rs.render(cams, rs.SeaScene(wind_speed=torch.tensor([6.0, 12.0]), wind_direction=wd, sea_temperature=291.0))

    wd0 = torch.tensor([0.3, 1.0], dtype=torch.float64)
    wd = wd0.clone().requires_grad_(True)
    img = image(wd)
    weights = torch.linspace(0.5, 1.5, img.numel(), dtype=torch.float64).reshape(img.shape)
    (grad,) = torch.autograd.grad((img * weights).sum(), wd)
    for i in range(2):
        h = torch.zeros(2, dtype=torch.float64)
        h[i] = 1e-4
        fd = ((image(wd0 + h) - image(wd0 - h)) * weights).sum() / 2e-4
        assert abs(float(grad[i]) - float(fd)) <= 5e-3 * abs(float(fd)) + 1e-9, (i, float(grad[i]), float(fd))


def test_workspace_of_an_ended_thread_is_dropped():
    """A thread that rendered and ended leaves no workspace behind once another thread allocates one
    (roughsea_torch.renderer.pixels keys them by thread; the planes of ended threads were kept)."""
    from roughsea_torch.renderer import pixels as _pixels

    scene = make_scene(wind_speed=6.0, sky=smooth_sky)
    rs.release_workspace()
    before = torch.get_num_threads()
    torch.set_num_threads(1)  # the render runs on the calling thread
    try:
        t = threading.Thread(target=lambda: rs.render(make_cams(16, 20, dtype=torch.float32), scene))
        t.start()
        t.join()
        assert t.ident in _pixels._spaces
        rs.render(make_cams(12, 16, dtype=torch.float32), scene)
        assert t.ident not in _pixels._spaces and threading.get_ident() in _pixels._spaces
    finally:
        torch.set_num_threads(before)
        rs.release_workspace()

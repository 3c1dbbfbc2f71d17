"""Area-weighted horizon pixels (roughsea_torch.renderer.horizon): the closed-form area of a square
below a line against a brute-force count; a straddling pixel's value against the area mix of
independent renders of the sea and the sky at the centroids of its two parts, with the horizon's
row from kornia's projection of a far point on the horizon circle; the staircase under roll; the
second law (a sky at the sea's blackbody radiance leaves every pixel at R_B); pixels away from the
horizon bit for bit; finite gradients through the pose."""

from __future__ import annotations

import math

import pytest
import torch
from kornia.geometry.camera import PinholeCamera

import roughsea_torch as rs
from roughsea_torch.renderer.horizon import coverage

from conftest import make_scene

pytestmark = pytest.mark.usefixtures("one_thread")


def test_coverage_is_the_area_below_the_line():
    """coverage(a, p, q) = the area of du, dv ∈ [−½, ½] where a + p du + q dv < 0, against a count
    over a 2000 × 2000 grid of the square (error ≤ ~1e-3), lines of every slope, through corners,
    axis-parallel (p or q = 0), and missing the square."""
    g = torch.Generator().manual_seed(0)
    a = torch.cat([torch.rand(40, generator=g, dtype=torch.float64) * 2 - 1, torch.tensor([0.0, 0.3, -0.3, 0.7, 2.0, -2.0],
                                                                                         dtype=torch.float64)])
    p = torch.cat([torch.randn(40, generator=g, dtype=torch.float64), torch.tensor([1.0, 0.0, 1.0, 1.0, 1.0, 1.0],
                                                                                  dtype=torch.float64)])
    q = torch.cat([torch.randn(40, generator=g, dtype=torch.float64), torch.tensor([1.0, 1.0, 0.0, 1.0, 1.0, 1.0],
                                                                                  dtype=torch.float64)])
    n = 2000
    t = (torch.arange(n, dtype=torch.float64) + 0.5) / n - 0.5
    du, dv = t[:, None], t[None, :]
    count = torch.stack([((ai + pi * du + qi * dv) < 0).double().mean() for ai, pi, qi in zip(a, p, q)])
    assert torch.allclose(coverage(a, p, q), count, atol=2e-3)


def _horizon_row(cams: PinholeCamera, altitude: float) -> float:
    """Image row of the (dipped) horizon straight ahead, from kornia's projection of a far point on
    the horizon circle: dip δ with cos δ = R/(R + h) below the local horizontal."""
    R = rs.EARTH_RADIUS_M
    d = math.acos(R / (R + altitude))
    L = 1.0e4
    pt = torch.tensor([[L * math.cos(d), 0.0, altitude - L * math.sin(d)]], dtype=cams.intrinsics.dtype)
    return float(cams.project(pt)[0, 1])


def _shifted(cams: PinholeCamera, dv: float) -> PinholeCamera:
    """The cameras with the principal point moved so that each pixel's centre ray is the original
    ray through the point dv rows below the centre."""
    K = cams.intrinsics.clone()
    K[:, 1, 2] -= dv
    return PinholeCamera(K, cams.extrinsics, cams.height, cams.width)


SKY_T = 260.0  # a constant sky's brightness temperature [K]: no sub-pixel structure above the horizon


def _setup(target: float, dtype=torch.float64, H: int = 21, W: int = 9):
    """A camera 20 m up, roll 0, hfov 10°, whose horizon crosses the centre column at row 10 with
    about ``target`` of that pixel below it; the horizon's row v_h (kornia), the pixel (r, c), f."""
    h = 20.0
    dip = math.degrees(math.acos(rs.EARTH_RADIUS_M / (rs.EARTH_RADIUS_M + h)))
    vfov = 2 * math.degrees(math.atan(math.tan(math.radians(5.0)) * H / W))
    cams = rs.make_camera(H, W, hfov_deg=10.0, altitude_m=h, pitch_deg=-dip + (target - 0.5) * vfov / H, dtype=dtype)
    v_h = _horizon_row(cams, h)
    r = int(math.floor(v_h + 0.5))
    return cams, v_h, r, W // 2, r + 0.5 - v_h


@pytest.mark.parametrize("method", ["table", "direct"])
@pytest.mark.parametrize("target", [0.1, 0.5, 0.7])
def test_straddling_pixel_is_the_area_mix_of_sea_and_sky(method, target):
    """Roll 0, the horizon at a sub-pixel row v_h of the centre column (kornia's projection of a far
    horizon point): the pixel of row r it crosses reads f R_sea + (1 − f) L_sky with f = r + ½ − v_h
    (the area below the horizon), L_sky a constant sky and R_sea the mean of the sea over the
    pixel's sea part, from 16 independent centre-ray renders (horizon="centre") of cameras whose
    principal point puts points of that part at the pixel's centre. Within 1e-3 of the contrast
    (measured ≤ 5.5e-4: the sea part's value is extrapolated from the centres below); the centre
    ray alone misses by 10-50 % (planted: blend_horizon returning its input fails every case)."""
    cams, v_h, r, c, f = _setup(target)
    assert 0.05 < f < 0.95
    sky = float(rs.band_radiance(SKY_T))
    scene = make_scene(sky=rs.ConstantSky(sky))
    img = rs.render(cams, scene, method=method)[0, 0]
    t = (torch.arange(16, dtype=torch.float64) + 0.5) / 16
    sea = torch.stack([rs.render(_shifted(cams, v_h + ti * f - r), scene, method=method, horizon="centre")[0, 0, r, c]
                       for ti in t.tolist()]).mean()
    assert abs(float(img[r, c] - (f * sea + (1 - f) * sky))) < 1e-3 * float(sea - sky)


@pytest.mark.parametrize("output", ["radiance", "brightness_temperature"])
def test_roll_removes_the_staircase(output):
    """Roll 3°: along the image the horizon climbs 0.05 row a column. The column sums of the rows
    around the horizon then change smoothly, by at most the contrast times the change of the
    covered area (0.05 a column) plus the sea's own drift; by centre rays they jump by the whole
    contrast where the staircase steps. The largest step of the column sums drops below a quarter
    of the centre rays' (measured: 0.07 against 0.55 of the contrast)."""
    h, H, W, roll = 20.0, 16, 96, 3.0
    dip = math.degrees(math.acos(rs.EARTH_RADIUS_M / (rs.EARTH_RADIUS_M + h)))
    cams = rs.make_camera(H, W, hfov_deg=12.0, altitude_m=h, pitch_deg=-dip, roll_deg=roll, dtype=torch.float64)
    scene = make_scene(sky=rs.ConstantSky(float(rs.band_radiance(SKY_T))))
    steps = {}
    for mode in ("centre", "area"):
        img = rs.render(cams, scene, output=output, horizon=mode)[0, 0]
        steps[mode] = img.sum(0).diff().abs().max()
    contrast = 290.0 - SKY_T if output != "radiance" else float(rs.band_radiance(290.0) - rs.band_radiance(SKY_T))
    assert steps["centre"] > 0.3 * contrast  # the staircase is there by centre rays
    assert steps["area"] < 0.25 * steps["centre"]
    assert steps["area"] < (math.tan(math.radians(roll)) * 1.5 + 0.05) * contrast


@pytest.mark.parametrize("method,seed,dtype", [("table", None, torch.float64), ("direct", None, torch.float32),
                                               ("table", 3, torch.float32)])
def test_second_law_a_blackbody_sky_leaves_every_pixel_at_r_b(method, seed, dtype):
    """A sky at the sea's own blackbody radiance R_B, no path: every facet sees R_B (emitted plus
    reflected), so every pixel, those the horizon crosses included, reads R_B: the mix cannot invent
    contrast. With roll, textured and flat, both methods, in radiance and in kelvin (the active
    whitecaps' skin deficit set to 0, so that the foam too is at the sea temperature)."""
    rb = float(rs.band_radiance(torch.tensor(290.0, dtype=torch.float64)))
    scene = make_scene(sky=rs.ConstantSky(rb), seed=seed, skin_deficit=0.0)
    cams = rs.make_camera(24, 40, hfov_deg=20.0, altitude_m=30.0, pitch_deg=-1.0, roll_deg=7.0, dtype=dtype)
    img = rs.render(cams, scene, method=method)
    assert torch.allclose(img, torch.full_like(img, rb), rtol=1e-5 if dtype == torch.float32 else 1e-9, atol=0)
    bt = rs.render(cams, scene, method=method, output="brightness_temperature")
    assert (bt - 290.0).abs().max() < (2e-3 if dtype == torch.float32 else 1e-6)


def _line_distance(cams: PinholeCamera, h: float, H: int, W: int) -> torch.Tensor:
    """Each pixel centre's distance [px] from the horizon line through the projections of two far
    horizon points (kornia), (H, W)."""
    R = rs.EARTH_RADIUS_M
    d = math.acos(R / (R + h))
    L = 1.0e4
    az = torch.tensor([-0.2, 0.2], dtype=torch.float64)
    pts = torch.stack([L * math.cos(d) * torch.cos(az), L * math.cos(d) * torch.sin(az),
                       torch.full_like(az, h - L * math.sin(d))], -1)
    uv = torch.cat([cams.project(p[None].to(cams.intrinsics.dtype)).double() for p in pts])
    t = uv[1] - uv[0]
    n = torch.stack([-t[1], t[0]]) / t.norm()
    v, u = torch.meshgrid(torch.arange(H, dtype=torch.float64), torch.arange(W, dtype=torch.float64), indexing="ij")
    return ((u - uv[0, 0]) * n[0] + (v - uv[0, 1]) * n[1]).abs()


@pytest.mark.parametrize("method,seed", [("table", None), ("direct", None), ("table", 5)])
def test_pixels_away_from_the_horizon_are_bitwise_unchanged(method, seed):
    """Pixels more than a pixel's half-diagonal plus the horizon's curvature (0.8 px) from the
    horizon line (kornia's projection of two far horizon points) are bit for bit what the centre
    ray gives (horizon="centre"), in radiance and kelvin; the pixels on the line do change. With
    the horizon out of view (looking 45° down, or 20° up) nothing changes."""
    h, H, W = 20.0, 24, 40
    scene = make_scene(seed=seed, sky="midlatitude_summer", path="midlatitude_summer")
    cams = rs.make_camera(H, W, hfov_deg=8.0, altitude_m=h, pitch_deg=-0.5, roll_deg=-6.0, yaw_deg=0.0)
    far = _line_distance(cams, h, H, W) > 0.8
    for output in ("radiance", "brightness_temperature"):
        a = rs.render(cams, scene, method=method, output=output)[0, 0]
        b = rs.render(cams, scene, method=method, output=output, horizon="centre")[0, 0]
        assert torch.equal(a[far], b[far])
        assert (a[~far] != b[~far]).sum() >= W // 2
    for pitch in (-45.0, 20.0):
        cams = rs.make_camera(H, W, hfov_deg=8.0, altitude_m=h, pitch_deg=pitch)
        assert torch.equal(rs.render(cams, scene, method=method), rs.render(cams, scene, method=method, horizon="centre"))


@pytest.mark.parametrize("dtype", [torch.float32, torch.float64])
def test_gradients_through_the_coverage_are_finite_and_right(dtype):
    """d(straddling pixel)/d(pitch) through f: finite, and in float64 equal to a central difference
    (the pixel's value moves with the horizon across it); the pixels away from it are unchanged in
    value but the gradient is finite everywhere."""
    scene = make_scene(sky=rs.ConstantSky(float(rs.band_radiance(SKY_T))))
    h, c = 20.0, 4
    dip = math.degrees(math.acos(rs.EARTH_RADIUS_M / (rs.EARTH_RADIUS_M + h)))

    def pixel(pitch: torch.Tensor) -> torch.Tensor:
        cm = rs.make_camera(21, 9, hfov_deg=10.0, altitude_m=h, pitch_deg=pitch, dtype=dtype)
        return rs.render(cm, scene)[0, 0]

    pitch = torch.tensor(-dip - 0.02, dtype=dtype, requires_grad=True)
    img = pixel(pitch)
    (g_all,) = torch.autograd.grad(img.sum(), pitch, retain_graph=True)
    assert torch.isfinite(g_all)
    (g,) = torch.autograd.grad(img[10, c], pitch)
    assert torch.isfinite(g) and g != 0
    if dtype == torch.float64:
        e = 1e-4
        fd = (pixel(torch.tensor(-dip - 0.02 + e, dtype=dtype))[10, c] - pixel(torch.tensor(-dip - 0.02 - e, dtype=dtype))[10, c]) / (2 * e)
        assert torch.allclose(g, fd, rtol=1e-3)


@pytest.mark.parametrize("roll,skew,flat", [(0.0, 0.0, False), (30.0, 0.0, False), (63.0, 0.0, True), (90.0, 0.0, False),
                                            (-140.0, 0.0, False), (20.0, 6.0, False)])
def test_every_pixel_the_horizon_crosses_is_found_with_its_area(roll, skew, flat):
    """Any roll, a kornia camera with a skew, flat or curved Earth: the pixels whose square holds both
    sea and sky rays, by a brute-force 12 × 12 sampling of each square (rays from kornia's
    normalization, as the renderer's, which ignores a skew; sea iff the ray dips below the horizon,
    cos δ = R/(R + h)), are all among the
    pixels found, and the found f matches the sampled fraction (within the sampling's 1/12 per
    crossed row of samples)."""
    from roughsea_torch.geometry import CameraGeometry
    from roughsea_torch.renderer.horizon import horizon_pixels, sea_fraction
    from kornia.geometry.conversions import normalize_points_with_intrinsics

    h, H, W = 50.0, 20, 28
    R = math.inf if flat else rs.EARTH_RADIUS_M
    cams = rs.make_camera(H, W, hfov_deg=30.0, altitude_m=h, pitch_deg=-2.0, roll_deg=roll, dtype=torch.float64)
    if skew:
        K = cams.intrinsics.clone()
        K[:, 0, 1] = skew
        cams = PinholeCamera(K, cams.extrinsics, cams.height, cams.width)
    cg = CameraGeometry(cams, R)
    n = 12
    t = (torch.arange(n, dtype=torch.float64) + 0.5) / n - 0.5
    v, u = torch.meshgrid(torch.arange(H, dtype=torch.float64), torch.arange(W, dtype=torch.float64), indexing="ij")
    pu = (u[:, :, None, None] + t[None, None, None, :]).expand(H, W, n, n)
    pv = (v[:, :, None, None] + t[None, None, :, None]).expand(H, W, n, n)
    xy = normalize_points_with_intrinsics(torch.stack([pu, pv], -1).reshape(1, -1, 2), cams.camera_matrix)[0]
    d = torch.cat([xy, torch.ones_like(xy[:, :1])], 1)
    d = d / d.norm(dim=1, keepdim=True)
    world = d @ cams.rotation_matrix[0]  # camera → world (rows: world components)
    sin_dip = 0.0 if flat else math.sqrt(1 - (rs.EARTH_RADIUS_M / (rs.EARTH_RADIUS_M + h)) ** 2)
    frac = (world[:, 2] < -sin_dip).double().reshape(H, W, n * n).mean(-1)
    crossed = (frac > 0) & (frac < 1)
    assert crossed.sum() >= min(H, W) // 2
    bi, pv_, pu_ = horizon_pixels(cg)
    found = torch.zeros(H, W, dtype=torch.bool)
    found[pv_, pu_] = True
    assert bool(found[crossed].all())
    f, *_ = sea_fraction(cg, bi, pv_, pu_)
    assert (f - frac[pv_, pu_]).abs().max() < 2.5 / n

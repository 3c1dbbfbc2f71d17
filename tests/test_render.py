"""Cameras, per-pixel geometry and the renderer."""

from __future__ import annotations

import math
import threading

import pytest
import torch

import roughsea_torch as rs

DEG = math.pi / 180


def sky(c):
    return 11.0 + 19.0 * (1.0 - c) ** 8


def varied_cameras(dtype, H=64, W=80):
    """Five cameras: low near-horizontal, 200 m, 2 km oblique wide, 5 m grazing narrow, nadir."""
    return rs.make_camera(
        H, W,
        hfov_deg=torch.tensor([30.0, 30.0, 60.0, 10.0, 40.0]),
        altitude_m=torch.tensor([20.0, 200.0, 2000.0, 5.0, 20.0]),
        pitch_deg=torch.tensor([-3.0, -10.0, -45.0, -0.5, -89.0]),
        yaw_deg=torch.tensor([0.0, 40.0, 100.0, -30.0, 0.0]),
        roll_deg=torch.tensor([0.0, 5.0, -10.0, 2.0, 0.0]),
        dtype=dtype,
    )


# Measured worst relative errors of the table against per-pixel evaluation over these scenes (sea
# pixels; float32 / float64): 8.2e-7 / 2.6e-7 with a callable sky, 6.8e-7 / 3.7e-7 with the LOWTRAN sky
# and the path (the path table is read per table row, not per pixel). Sky pixels: 4.5e-7 with a
# callable sky; with the sky from the camera's altitude 4.2e-5 (0.003 K) in the row at the local
# horizontal, where it has a square-root edge (rays just below it pass a tangent point near the
# camera), 1e-6 elsewhere.
SEA_TOL = {"fn": 2e-6, "midlatitude_summer": 2e-6}
SKY_TOL = {"fn": 1e-6, "midlatitude_summer": 1e-4}


@pytest.mark.parametrize("dtype", [torch.float32, torch.float64])
@pytest.mark.parametrize("anisotropic", [False, True])
@pytest.mark.parametrize("sky_kind", ["fn", "midlatitude_summer"])
def test_table_render_matches_direct_per_pixel_evaluation(dtype, anisotropic, sky_kind):
    """Every sea pixel within a few 1e-6 relative of apparent_radiance at its own (θ̂, φ̂) (with the
    path: τ R_a + L_path at its own range), including the rows next to the horizon (θ̂ up to
    89.99° here); sky pixels within 1e-6 of the sky along their ray. Both sources of the table's
    spans: the cameras' border (the default) and a precomputed per-pixel geometry."""
    cams = varied_cameras(dtype)
    scene = rs.SeaScene(
        wind_speed=torch.tensor([2.0, 10.0, 25.0, 0.0, 40.0]), anisotropic=anisotropic,
        wind_direction=torch.tensor([0.3, 1.0, 2.5, -1.0, 0.0]),
        sea_temperature=torch.tensor([285.0, 295.0, 300.0, 275.0, 290.0]), sky=sky if sky_kind == "fn" else sky_kind,
    )
    geom = rs.view_geometry(cams)
    direct = rs.render(cams, scene, geometry=geom, method="direct")
    sea = geom.is_sea[:, None]
    near_horizon = (geom.view_zenith > 89.9 * DEG)[:, None] & sea
    assert near_horizon.sum() > 0 and (~sea).sum() > 0  # the checks cover grazing rows and sky
    for table in (rs.render(cams, scene), rs.render(cams, scene, geometry=geom)):
        assert table.shape == (5, 1, 64, 80) and table.dtype == dtype
        rel = (table - direct).abs() / direct.abs()
        assert rel[sea].max() <= SEA_TOL[sky_kind]
        assert rel[~sea].max() <= SKY_TOL[sky_kind]


def test_horizon_depression_and_distance_on_a_sphere():
    """docs/physics.md §9: at h = 20 m the horizon is depressed by √(2h/R) = 0.1436° and lies √(2hR) ≈ 16 km
    away. A camera pitched to the horizon: the first sea row is the one just below it, and the
    sea pixel farthest away is at ≈ the horizon distance."""
    h, R = 20.0, 6_371_000.0
    dip = math.degrees(math.sqrt(2 * h / R))
    H = 2001
    cams = rs.make_camera(H, 3, hfov_deg=0.6, altitude_m=h, pitch_deg=-dip, dtype=torch.float64)
    geom = rs.view_geometry(cams, earth_radius_m=R)
    col = geom.is_sea[0, :, 1]
    first = int(torch.nonzero(col)[0])
    f = float(cams.fx[0])
    elev = lambda row: -dip + math.degrees(math.atan(((H - 1) / 2 - row) / f))  # noqa: E731
    row_deg = math.degrees(math.atan(1 / f))  # one row [deg]
    # the sea starts at the depressed horizon, 0.1436° below the horizontal (docs/physics.md §9)
    assert elev(first) <= -0.1436 + row_deg and elev(first - 1) > -0.1436 - row_deg
    far = float(geom.range_m[0, first, 1])
    assert abs(far - math.sqrt(2 * h * R)) / math.sqrt(2 * h * R) < 0.02
    assert float(geom.view_zenith[0, first, 1]) > 89.9 * DEG  # LOS tangent at the horizon


def test_rotating_wind_and_camera_together_leaves_the_image_unchanged():
    """Azimuth conventions end to end: the scene is symmetric under a rotation about the vertical, so
    yaw + δ with wind direction + δ gives the same image (anisotropic slopes, table method)."""
    def img(yaw_deg, wind_dir):
        cams = rs.make_camera(24, 32, hfov_deg=30.0, altitude_m=30.0, pitch_deg=-4.0, yaw_deg=yaw_deg, dtype=torch.float64)
        return rs.render(cams, rs.SeaScene(wind_speed=15.0, wind_direction=wind_dir, sea_temperature=290.0, sky=sky))

    a = img(0.0, 0.3)
    b = img(40.0, 0.3 + math.radians(40.0))
    c = img(40.0, 0.3)  # camera turned, wind not: a different view of the anisotropic sea
    torch.testing.assert_close(a, b, rtol=2e-6, atol=0)
    assert (a - c).abs().max() > 1e-3


def test_flat_sea_geometry_is_the_plane():
    cams = rs.make_camera(33, 5, hfov_deg=20.0, altitude_m=50.0, pitch_deg=-30.0, dtype=torch.float64)
    geom = rs.view_geometry(cams, earth_radius_m=float("inf"))
    centre = geom.view_zenith[0, 16, 2]
    assert abs(float(centre) - 60 * DEG) < 1e-12  # optical axis 30° below horizontal → θ̂ = 60°
    assert abs(float(geom.range_m[0, 16, 2]) - 50.0 / math.sin(30 * DEG)) < 1e-9
    sphere = rs.view_geometry(cams)
    # on a sphere the local vertical at the hit tilts away from the camera: θ̂ grows, slightly
    assert float(sphere.view_zenith[0, 16, 2]) > float(centre)
    assert float(sphere.view_zenith[0, 16, 2]) - float(centre) < 1e-4


def test_los_azimuth_points_back_to_the_camera():
    """A camera with yaw 0 looks along +x: the LOS sea → sensor of its central pixel points to −x."""
    cams = rs.make_camera(11, 11, hfov_deg=20.0, altitude_m=10.0, pitch_deg=-20.0, yaw_deg=0.0, dtype=torch.float64)
    az = float(rs.view_geometry(cams).view_azimuth[0, 5, 5])
    assert abs(abs(az) - math.pi) < 1e-9
    cams = rs.make_camera(11, 11, hfov_deg=20.0, altitude_m=10.0, pitch_deg=-20.0, yaw_deg=90.0, dtype=torch.float64)
    az = float(rs.view_geometry(cams).view_azimuth[0, 5, 5])
    assert abs(az + math.pi / 2) < 1e-9


def test_sky_pixels_see_the_sky_along_their_ray():
    cams = rs.make_camera(40, 40, hfov_deg=40.0, altitude_m=20.0, pitch_deg=15.0, dtype=torch.float64)
    scene = rs.SeaScene(wind_speed=5.0, sea_temperature=290.0, sky=sky)
    geom = rs.view_geometry(cams)
    img = rs.render(cams, scene, geometry=geom)
    s = ~geom.is_sea[0]
    # the table holds the sky at 2048 rows evenly spaced in cos(zenith): 3.4e-7 measured (float64)
    torch.testing.assert_close(img[0, 0][s], sky(geom.cos_view_zenith[0][s].clamp(0, 1)), rtol=1e-6, atol=0)


def test_second_law_whole_image_is_uniform_brightness_temperature():
    """Sky radiance equal to the sea's blackbody radiance everywhere ⇒ every pixel, sea or sky, is
    at the sea temperature (Eq. 10 with R_s ≡ R_B, through geometry, tables and grid_sample)."""
    t_sea = 291.5
    rb = float(rs.band_radiance(torch.tensor(t_sea, dtype=torch.float64)))
    cams = varied_cameras(torch.float64, 32, 40)
    scene = rs.SeaScene(wind_speed=torch.tensor([1.0, 5.0, 10.0, 20.0, 30.0]), sea_temperature=t_sea, sky=rb)
    bt = rs.render(cams, scene, output="brightness_temperature")
    torch.testing.assert_close(bt, torch.full_like(bt, t_sea), rtol=0, atol=1e-9)


def test_gradients_match_finite_differences():
    """d image / d (wind speed, sea temperature, pitch, altitude), float64, table method."""
    def image(w, t, pitch, alt):
        cams = rs.make_camera(12, 16, hfov_deg=20.0, altitude_m=alt, pitch_deg=pitch, yaw_deg=10.0, dtype=torch.float64)
        scene = rs.SeaScene(wind_speed=w, wind_direction=0.4, sea_temperature=t, sky=sky)
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
    cams = rs.make_camera(8, 8, altitude_m=20.0, pitch_deg=-5.0)
    img = rs.render(cams, rs.SeaScene(wind_speed=5.0, sea_temperature=290.0, sky=sky))
    assert img.grad_fn is None and not img.requires_grad


def test_module_equals_function_and_no_sky_work_when_no_sky():
    """An all-sea view makes no call for the sky rows of the table (shape (B, fine_sky)); a view
    with sky does."""
    shapes = []

    def counting_sky(c):
        shapes.append(tuple(c.shape))
        return sky(c)

    scene = rs.SeaScene(wind_speed=8.0, sea_temperature=290.0, sky=counting_sky)
    all_sea = rs.make_camera(16, 16, altitude_m=100.0, pitch_deg=-60.0)
    assert rs.view_geometry(all_sea).is_sea.all()
    a = rs.SeaRenderer()(all_sea, scene)
    rows = (1, rs.TableSize().fine_sky)
    assert rows not in shapes
    b = rs.render(all_sea, scene)
    assert torch.equal(a, b)
    shapes.clear()
    rs.render(rs.make_camera(16, 16, altitude_m=100.0, pitch_deg=0.0), scene)
    assert rows in shapes


@pytest.mark.parametrize(
    "call, match",
    [
        (lambda: rs.make_camera(8, 8, altitude_m=0.0), "altitude_m"),
        (lambda: rs.make_camera(8, 8, pitch_deg=95.0), "pitch_deg"),
        (lambda: rs.make_camera(8, 8, hfov_deg=0.0), "hfov_deg"),
        (lambda: rs.SeaScene(sea_temperature=290.0, sky=1.0), "wind_speed"),
        (lambda: rs.SeaScene(wind_speed=3.0, sky=1.0), "sea_temperature"),
        (lambda: rs.SeaScene(wind_speed=-3.0, sea_temperature=290.0, sky=1.0), "wind_speed"),
        (lambda: rs.SeaScene(wind_speed=3.0, sea_temperature=500.0, sky=1.0), "sea_temperature"),
        (lambda: rs.render(rs.make_camera(8, 8, batch_size=2), rs.SeaScene(wind_speed=torch.ones(3), sea_temperature=290.0, sky=1.0)), "batch size"),
        (lambda: rs.render(rs.make_camera(8, 8), rs.SeaScene(wind_speed=3.0, sea_temperature=290.0, sky=1.0), method="fast"), "method"),
        (lambda: rs.view_geometry(rs.make_camera(8, 8), earth_radius_m=-1.0), "earth_radius_m"),
    ],
)
def test_render_errors(call, match):
    with pytest.raises(ValueError, match=match):
        call()


def test_pixel_derivative_matches_finite_differences_per_pixel():
    """Per-pixel dT_b/dW by the double-backward JVP equals central differences, pixel by pixel."""
    def bt(w):
        cams = rs.make_camera(16, 20, hfov_deg=25.0, altitude_m=15.0, pitch_deg=-4.0, dtype=torch.float64)
        return rs.render(cams, rs.SeaScene(wind_speed=w, wind_direction=0.6, sea_temperature=291.0, sky=sky),
                         output="brightness_temperature")

    w = torch.tensor(8.0, dtype=torch.float64, requires_grad=True)
    d = rs.pixel_derivative(bt(w), w)
    fd = (bt(torch.tensor(8.001, dtype=torch.float64)) - bt(torch.tensor(7.999, dtype=torch.float64))) / 0.002
    torch.testing.assert_close(d, fd, rtol=1e-4, atol=1e-7)
    assert d.abs().max() > 0.05  # wind matters to these sea pixels


class BeerLambertPath:
    """A synthetic isothermal path: τ = exp(−r / 5 km), L = (1 − τ) B(T_air) (Kirchhoff)."""

    def __init__(self, t_air: float):
        self.l_air = float(rs.band_radiance(torch.tensor(t_air, dtype=torch.float64)))

    def __call__(self, altitude_m, range_m, clamp=False):
        tau = torch.exp(-range_m / 5000.0)
        return tau, (1.0 - tau) * self.l_air


def test_path_composes_transmittance_and_path_radiance_per_pixel():
    """radiance at the sensor = τ(range) · R_a + L_path on every sea pixel; sky pixels unchanged;
    far sea pixels tend to the air's brightness temperature."""
    cams = rs.make_camera(40, 48, hfov_deg=3.0, altitude_m=20.0, pitch_deg=-0.5, dtype=torch.float64)
    geom = rs.view_geometry(cams)
    base = dict(wind_speed=6.0, sea_temperature=285.0, sky=sky)
    off = rs.render(cams, rs.SeaScene(**base, path=False), geometry=geom)
    on = rs.render(cams, rs.SeaScene(**base, path=BeerLambertPath(295.0)), geometry=geom)
    tau = torch.exp(-geom.range_m / 5000.0)[:, None]
    sea = geom.is_sea[:, None]
    expected = tau * off + (1 - tau) * float(rs.band_radiance(torch.tensor(295.0, dtype=torch.float64)))
    # the path is read per row of the table, not per pixel: 3.6e-8 measured here (float64)
    torch.testing.assert_close(on[sea], expected[sea], rtol=1e-7, atol=0)
    assert torch.equal(on[~sea], off[~sea])
    far = (geom.range_m[:, None] > 10_000)[sea]
    gap_on = (rs.brightness_temperature(on)[sea][far] - 295.0).abs()
    gap_off = (rs.brightness_temperature(off)[sea][far] - 295.0).abs()
    assert far.any() and (gap_on < 0.2 * gap_off).all()  # τ < 0.14: mostly air


def test_scene_path_arguments():
    with pytest.raises(ValueError, match="path=True needs a named atmosphere"):
        rs.SeaScene(wind_speed=3.0, sea_temperature=290.0, sky=1.0, path=True)
    with pytest.raises(ValueError, match="path must be"):
        rs.SeaScene(wind_speed=3.0, sea_temperature=290.0, sky=1.0, path=3.0)
    assert rs.SeaScene(wind_speed=3.0, sea_temperature=290.0, sky=1.0).path is None  # no model for a custom sky


@pytest.mark.parametrize("dtype", [torch.float32, torch.float64])
def test_default_scene_with_named_atmosphere_and_path(dtype):
    """The README's default scene: shipped LOWTRAN sky (float64 tables) in a float32 or float64 render,
    path on; table matches direct; the image keeps the cameras' dtype."""
    cams = rs.make_camera(24, 32, hfov_deg=30.0, altitude_m=torch.tensor([20.0, 300.0]),
                          pitch_deg=torch.tensor([-2.0, -6.0]), dtype=dtype)
    scene = rs.SeaScene(wind_speed=torch.tensor([4.0, 12.0]), wind_direction=0.3, sea_temperature=290.0)
    assert scene.path is not None
    geom = rs.view_geometry(cams)
    table = rs.render(cams, scene, geometry=geom, output="brightness_temperature")
    direct = rs.render(cams, scene, geometry=geom, method="direct", output="brightness_temperature")
    assert table.dtype == dtype
    torch.testing.assert_close(table, direct, rtol=0, atol=2e-3)  # 2 mK
    mst = rs.SeaScene(wind_speed=5.0, sea_temperature=290.0, band=rs.MWIR)
    assert 0.5 < float(mst.sky(torch.tensor(1.0))) < 1.2  # the MWIR sky, not the LWIR one


def test_air_temperature_shifts_sky_and_path():
    """SeaScene(air_temperature=): the atmosphere's own value changes nothing; warmer air makes
    the optically thick horizon sky warmer by about the same number of kelvin, and distant sea
    (long, thick paths) more than the sea below the camera (short path, sea emission)."""
    cam = rs.make_camera(64, 80, hfov_deg=30.0, altitude_m=20.0, pitch_deg=-2.0, batch_size=2, dtype=torch.float64)
    t_atm = rs.atmosphere.surface_air_temperature("midlatitude_summer")
    base = rs.render(cam, rs.SeaScene(wind_speed=8.0, sea_temperature=290.0), output="brightness_temperature")
    air = torch.tensor([t_atm, t_atm + 10.0], dtype=torch.float64)
    warm = rs.render(cam, rs.SeaScene(wind_speed=8.0, sea_temperature=290.0, air_temperature=air), output="brightness_temperature")
    assert torch.equal(warm[0], base[0])
    # the table method scales the reflected-sky term, the direct one a per-image sky table: same image
    direct = rs.render(cam, rs.SeaScene(wind_speed=8.0, sea_temperature=290.0, air_temperature=air), method="direct")
    table = rs.render(cam, rs.SeaScene(wind_speed=8.0, sea_temperature=290.0, air_temperature=air))
    torch.testing.assert_close(table, direct, rtol=2e-5, atol=0.0)
    geom = rs.view_geometry(cam)
    d = (warm[1] - base[1])[0]
    sky, sea = ~geom.is_sea[1], geom.is_sea[1]
    horizon_sky = sky & (geom.cos_view_zenith[1] < 0.01)  # within ~0.6 deg above the horizon
    assert 9.0 < float(d[horizon_sky].min()) <= float(d[horizon_sky].max()) < 10.0
    far = sea & (geom.range_m[1] > 1000.0)
    near = sea & (geom.range_m[1] < 120.0)
    assert float(d[far].mean()) > 2.0 * float(d[near].mean()) > 0.0
    with pytest.raises(ValueError, match="air_temperature"):
        rs.SeaScene(wind_speed=8.0, sea_temperature=290.0, sky=10.0, air_temperature=290.0)
    with pytest.raises(ValueError, match="air_temperature"):
        rs.SeaScene(wind_speed=8.0, sea_temperature=290.0, air_temperature=400.0)


@pytest.mark.parametrize("wind", [0.0, 0.01, 0.05])
def test_calm_anisotropic_sea_along_the_wind(wind):
    """Cox–Munk at W → 0 has a → 0: the rms slope along the view → b |sin φ̂| has a kink at views
    along the wind, sharp at grazing. The table folds the azimuth by the mirror symmetry (the kink
    at the interval's end) and uses more azimuth nodes for thin slope ellipses; every sea pixel,
    horizon row included, stays within the renderer's 2e-5 of the direct evaluation."""
    cam = rs.make_camera(48, 64, hfov_deg=30.0, altitude_m=20.0, pitch_deg=-8.0,
                         yaw_deg=torch.tensor([0.0, 10.0, 170.0]))
    scene = rs.SeaScene(wind_speed=wind, wind_direction=0.0, sea_temperature=290.0, sky=lambda c: 10 + 20 * (1 - c) ** 6)
    t = rs.render(cam, scene)
    d = rs.render(cam, scene, method="direct")
    sea = rs.view_geometry(cam).is_sea
    assert float(((t - d).abs() / d.abs())[:, 0][sea].max()) < 2e-5


@pytest.mark.parametrize("method", ["table", "direct"])
def test_sea_temperature_gradient_matches_central_difference(method):
    """d(image)/dT_sea includes how the band-effective water index moves with T_sea (its Planck
    weights): autograd against a float64 central difference, at 1e-6 relative. (With the index
    fitted from a detached temperature the gradient was 3.2e-4 off.)"""
    cams = rs.make_camera(12, 16, hfov_deg=30.0, altitude_m=20.0, pitch_deg=-6.0, dtype=torch.float64)

    def img(t):
        return rs.render(cams, rs.SeaScene(wind_speed=7.0, sea_temperature=t, sky=sky), method=method)

    t0 = torch.tensor(291.3, dtype=torch.float64, requires_grad=True)
    out = img(t0)
    w = torch.linspace(0.5, 1.5, out.numel(), dtype=torch.float64).reshape(out.shape)  # every pixel counts
    (g,) = torch.autograd.grad((out * w).sum(), t0)
    h = 1e-3
    with torch.no_grad():
        fd = ((img(t0 + h) - img(t0 - h)) * w).sum() / (2 * h)
    assert abs(float(g) - float(fd)) <= 1e-6 * abs(float(fd))


def test_scene_fields_changed_after_a_render_take_effect():
    """A SeaScene keeps no derived state: change its sea temperature after a render and the next
    render equals that of a scene made with the new value (the band index included)."""
    cams = rs.make_camera(8, 10, pitch_deg=-5.0, dtype=torch.float64)
    scene = rs.SeaScene(wind_speed=5.0, sea_temperature=280.0, sky=sky)
    rs.render(cams, scene)
    scene.sea_temperature = 300.0
    fresh = rs.render(cams, rs.SeaScene(wind_speed=5.0, sea_temperature=300.0, sky=sky))
    assert torch.equal(rs.render(cams, scene), fresh)


def test_camera_outside_the_path_tables_is_an_error():
    """The path tables cover 2 m – 5 km: a camera outside them with the path on is a ValueError
    naming altitude_m and the range (it was silently clamped); with path=False it renders."""
    scene = rs.SeaScene(wind_speed=5.0, sea_temperature=290.0)
    for h in (0.5, 8000.0):
        cams = rs.make_camera(8, 10, altitude_m=h, pitch_deg=-5.0)
        for method in ("table", "direct"):
            with pytest.raises(ValueError, match=r"altitude_m must lie in \[2, 5000\] m"):
                rs.render(cams, scene, method=method)
        img = rs.render(cams, rs.SeaScene(wind_speed=5.0, sea_temperature=290.0, path=False))
        assert torch.isfinite(img).all()


@pytest.mark.parametrize("altitude", [20.0, 100.0])
def test_no_warm_line_at_the_horizon(altitude):
    """The report: from a 20 m mast a one-pixel line at the horizon was 0.6–1.2 K warmer than the
    sky just above it, because sky pixels saw the sea-level sky while the sea's horizon row sees
    ~16 km of warm surface air. A ray just above the depressed horizon crosses that same air: its
    radiance is L_path(h, r_hor) + τ(h, r_hor) · sky₀(90°) (midlatitude summer LWIR from 20 m:
    ≈ 294.1 K). The sky pixels next to the horizon must show it, and the sea's first row must not
    be warmer than them."""
    h = altitude
    dip = math.degrees(math.asin(math.sqrt(h * (2 * rs.EARTH_RADIUS_M + h)) / (rs.EARTH_RADIUS_M + h)))
    H, W, vfov = 400, 4, 1.0  # 0.0025° a row
    hfov = 2 * math.degrees(math.atan(math.tan(math.radians(vfov / 2)) * W / H))
    cams = rs.make_camera(H, W, hfov_deg=hfov, altitude_m=h, pitch_deg=-dip + 0.0011, dtype=torch.float64)
    geom = rs.view_geometry(cams)
    bt = rs.render(cams, rs.SeaScene(wind_speed=6.0, sea_temperature=290.0), geometry=geom,
                   output="brightness_temperature")[0, 0, :, W // 2]
    k = int(geom.is_sea[0, :, W // 2].nonzero()[0])  # first sea row
    path = rs.atmosphere.load_path("midlatitude_summer", dtype=torch.float64)
    sky0 = rs.atmosphere.load_sky("midlatitude_summer", dtype=torch.float64)
    r_hor = rs.atmosphere.horizon_range(torch.tensor(h, dtype=torch.float64))
    tau, lp = path(torch.tensor(h, dtype=torch.float64), r_hor)
    dip_bt = float(rs.brightness_temperature(lp + tau * sky0(torch.tensor(0.0, dtype=torch.float64))))
    assert abs(float(bt[k - 1]) - dip_bt) < 0.02  # the sky row just above the horizon
    assert float(bt[k]) < float(bt[k - 1]) + 0.05  # no warm line below it
    assert float(bt[:k].max()) < dip_bt + 0.05  # nor anywhere in the sky near the horizon


@pytest.mark.parametrize("method", ["table", "direct"])
def test_kelvin_of_a_negative_radiance_is_an_error(method):
    """Without shadowing (Eq. 7) R_a goes negative near the horizon; such a pixel has no brightness
    temperature. It was clamped to a tiny radiance and came out near 13 K; now a ValueError says
    why. The radiance output is left as the model gives it."""
    cams = rs.make_camera(16, 16, hfov_deg=10.0, altitude_m=20.0, pitch_deg=-0.3)
    scene = rs.SeaScene(wind_speed=10.0, sea_temperature=290.0, sky=5.0, shadowing=False, path=False)
    assert float(rs.render(cams, scene, method=method).min()) < 0.0
    with pytest.raises(ValueError, match="no brightness temperature.*shadowing=True"):
        rs.render(cams, scene, method=method, output="brightness_temperature")


def test_correlated_slopes_unfolded_azimuth_matches_direct():
    """Correlated slope components (r ≠ 0) leave R_a without the mirror symmetry the table folds by:
    the table then runs over the unfolded azimuth coordinate (period π about the image's centre
    azimuth, read through its cheap ratio stand-in); every pixel within 1e-5 of the per-pixel
    evaluation (3.6e-6 measured; a sign slip in the ratio's lower half plane gave 6.8e-4)."""
    cams = rs.make_camera(32, 40, hfov_deg=30.0, altitude_m=torch.tensor([20.0, 150.0]),
                          pitch_deg=torch.tensor([-2.0, -12.0]), yaw_deg=torch.tensor([10.0, -30.0]), dtype=torch.float64)
    slopes = rs.SlopeStatistics.from_variances(torch.tensor([0.01, 0.03]), torch.tensor([0.02, 0.02]),
                                               torch.tensor([0.004, -0.006]))
    scene = rs.SeaScene(slopes=slopes, wind_direction=torch.tensor([0.4, 2.0]), sea_temperature=291.0, band=rs.MWIR)
    g = rs.view_geometry(cams)
    table, direct = rs.render(cams, scene), rs.render(cams, scene, geometry=g, method="direct")
    assert float(((table - direct) / direct).abs().max()) < 1e-5


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
    rs.render(rs.make_camera(64, 80, altitude_m=torch.full((5,), 50.0), pitch_deg=torch.full((5,), 4.0)), scene)
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
    test_gradients_match_finite_differences)."""
    cams = rs.make_camera(24, 32, hfov_deg=30.0, altitude_m=torch.tensor([20.0, 150.0]),
                          pitch_deg=torch.tensor([-3.0, -10.0]), yaw_deg=torch.tensor([10.0, -30.0]), dtype=torch.float64)

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

    scene = rs.SeaScene(wind_speed=6.0, sea_temperature=290.0, sky=sky)
    rs.release_workspace()
    before = torch.get_num_threads()
    torch.set_num_threads(1)  # the render runs on the calling thread
    try:
        t = threading.Thread(target=lambda: rs.render(rs.make_camera(16, 20, altitude_m=20.0, pitch_deg=-5.0), scene))
        t.start()
        t.join()
        assert t.ident in _pixels._spaces
        rs.render(rs.make_camera(12, 16, altitude_m=20.0, pitch_deg=-5.0), scene)
        assert t.ident not in _pixels._spaces and threading.get_ident() in _pixels._spaces
    finally:
        torch.set_num_threads(before)
        rs.release_workspace()

"""The sky in renders (roughsea_torch.renderer.sky_terms): sky pixels see the sky along their ray
(from the camera's altitude: no warm line at the horizon), the scattered day sky in the sky pixels and
in the sea's reflection (the table against the per-pixel evaluation by day), the sun's disk in the
sky."""

from __future__ import annotations

import math

import pytest
import torch

import roughsea_torch as rs

from conftest import make_cams, make_scene, smooth_sky


def test_sky_pixels_see_the_sky_along_their_ray():
    cams = make_cams(40, 40, hfov_deg=40.0, pitch_deg=15.0)
    scene = make_scene(wind_speed=5.0, sky=smooth_sky)
    geom = rs.view_geometry(cams)
    img = rs.render(cams, scene, geometry=geom, horizon="centre")  # per ray (each pixel by its centre ray)
    s = ~geom.is_sea[0]
    # the table holds the sky at 2048 rows evenly spaced in cos(zenith): 3.4e-7 measured (float64)
    torch.testing.assert_close(img[0, 0][s], smooth_sky(geom.cos_view_zenith[0][s].clamp(0, 1)), rtol=1e-6, atol=0)


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
    cams = make_cams(H, W, hfov_deg=hfov, altitude_m=h, pitch_deg=-dip + 0.0011)
    geom = rs.view_geometry(cams)
    bt = rs.render(cams, make_scene(wind_speed=6.0), geometry=geom,
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


def _day_scene(**kw):
    base = dict(wind_speed=0.5, sea_temperature=290.0, band=rs.MWIR, sky="midlatitude_summer", path=False,
                sun_zenith=math.radians(60.0), sun_azimuth=0.0, foam=False)
    base.update(kw)
    return rs.SeaScene(**base)


def test_day_sky_pixels_add_the_scattered_sky_by_zenith_and_azimuth():
    """Sky pixels by day = by night + the LOWTRAN scattered sky along each ray (its zenith, its azimuth
    from the sun's), brighter towards the sun (the aerosol's forward scattering) than away."""
    from roughsea_torch.daysky import load_scattered_sky

    cams = make_cams(hfov_deg=40.0, pitch_deg=25.0, yaw_deg=torch.tensor([0.0, 180.0]))
    g = rs.view_geometry(cams)
    sky = ~g.is_sea
    assert bool(sky.all())
    sun_az = math.radians(45.0)  # 45° off the yaw-0 camera's axis: the sun's disk out of its view
    day = rs.render(cams, _day_scene(sun_azimuth=sun_az))[:, 0]
    night = rs.render(cams, make_scene(wind_speed=0.5, band=rs.MWIR, path=False, foam=False))[:, 0]
    ds = load_scattered_sky("midlatitude_summer", rs.MWIR, aerosol="maritime")
    want = ds(g.cos_view_zenith, torch.atan2(g.dy, g.dx) - sun_az, torch.full_like(g.cos_view_zenith, math.radians(60.0)))
    torch.testing.assert_close(day - night, want, rtol=1e-9, atol=1e-12)
    assert float((day - night)[0].mean()) > 1.5 * float((day - night)[1].mean())  # yaw 0 looks towards the sun


@pytest.mark.parametrize("sun_az, wind_dir, spread", [(0.0, 0.0, 0.08), (1.0, 0.3, 0.09)],
                         ids=["sun_on_the_wind_axis", "sun_off_it"])
def test_day_sky_reflected_by_a_calm_sea_along_the_mirror_azimuth(sun_az, wind_dir, spread):
    """The sun 60° from the zenith behind the camera (no glint in view), calm sea: by day the sea pixels
    gain the reflection of the scattered sky along their mirror direction (the camera's look azimuth,
    away from the sun), as apparent_radiance computes it with that sky as a zenith-only table
    (R_B = 0), to 2e-3; ≈ ρ(θ̂) × that sky within 8 % (9 % with the wind turned: the slopes spread the
    reflected zeniths), and ~3x less than the sky towards the sun would give (a mirror azimuth off by
    π fails both). Also
    with the sun and the wind off the world's x axis (the sun 57° and the wind 17° from it): the
    scattered sky depends on the azimuth from the sun, the slope law on the azimuth from upwind (the
    sun's azimuth from upwind with its sign flipped puts the mirror direction 80° off)."""
    from roughsea_torch.daysky import load_scattered_sky

    cams = make_cams(16, 16, hfov_deg=6.0, pitch_deg=-20.0, yaw_deg=torch.tensor([math.degrees(sun_az) + 180.0]))
    g = rs.view_geometry(cams)
    assert bool(g.is_sea.all())
    scene = _day_scene(sun_azimuth=sun_az, wind_direction=wind_dir)
    plus = (rs.render(cams, scene)[:, 0]
            - rs.render(cams, _day_scene(aerosol=None, sun_azimuth=sun_az, wind_direction=wind_dir))[:, 0]).reshape(-1)
    ds = load_scattered_sky("midlatitude_summer", rs.MWIR, aerosol="maritime")
    look = torch.atan2(g.dy, g.dx).reshape(-1) - sun_az  # the rays' azimuths from the sun's: the mirror direction
    th, ph = g.view_zenith.reshape(-1), g.view_azimuth.reshape(-1) - wind_dir
    z = scene.sky.zenith.double()
    sun_z = math.radians(60.0)
    table = ds(torch.cos(z)[None, :], look[:, None], torch.full((1, 1), sun_z, dtype=torch.float64))
    m = rs.band_refractive_index(rs.MWIR, 290.0).to(torch.complex128)
    want = rs.apparent_radiance(th, ph, rs.SlopeStatistics.cox_munk(0.5, anisotropic=True), m, sea_radiance=0.0,
                                sky=rs.TabulatedSky(z, table))
    assert float(((plus - want) / want).abs().max()) < 2e-3
    s_mirror = ds(torch.cos(th), look, torch.full_like(look, sun_z))
    rho = 1.0 - rs.fresnel_emissivity(torch.cos(th), m)
    assert float((plus / (rho * s_mirror) - 1).abs().max()) < spread
    towards = ds(torch.cos(th), look + math.pi, torch.full_like(look, sun_z))
    assert bool((towards > 2.0 * s_mirror).all())


def test_day_scene_table_equals_per_pixel_evaluation():
    """A full MWIR daytime scene (LOWTRAN sky and path, the sun 20° up ahead with its glint, the
    scattered sky in the sky pixels and in the sea's reflection, anisotropic slopes, foam): the table
    render equals the per-pixel evaluation to 2e-5 by day without aerosol (glint rows and sky
    included) and to 1e-4 with the scattered sky (3.7e-5 measured: its azimuth table is piecewise
    linear, TableSize.azimuth_day; 7 azimuth nodes, planted, leave 1.9e-3)."""
    cams = make_cams(32, 40, altitude_m=torch.tensor([20.0, 150.0]), pitch_deg=torch.tensor([-2.0, -12.0]),
                     yaw_deg=torch.tensor([10.0, -30.0]))
    scene = rs.SeaScene(wind_speed=torch.tensor([4.0, 12.0]), wind_direction=torch.tensor([0.4, 2.0]),
                        sea_temperature=291.0, band=rs.MWIR, sun_zenith=math.radians(70.0), sun_azimuth=0.0)
    assert scene.day_sky is not None
    g = rs.view_geometry(cams)
    table = rs.render(cams, scene)
    direct = rs.render(cams, scene, geometry=g, method="direct")
    night = rs.render(cams, rs.SeaScene(wind_speed=torch.tensor([4.0, 12.0]), wind_direction=torch.tensor([0.4, 2.0]),
                                        sea_temperature=291.0, band=rs.MWIR))
    assert float((table / night).max()) > 2.0  # the glint is in view
    assert float(((table - direct) / direct).abs().max()) < 1e-4
    clear = rs.SeaScene(wind_speed=torch.tensor([4.0, 12.0]), wind_direction=torch.tensor([0.4, 2.0]),
                        sea_temperature=291.0, band=rs.MWIR, sun_zenith=math.radians(70.0), sun_azimuth=0.0, aerosol=None)
    table, direct = rs.render(cams, clear), rs.render(cams, clear, geometry=g, method="direct")
    assert float(((table - direct) / direct).abs().max()) < 2e-5


def test_the_suns_disk_in_the_sky_carries_its_irradiance():
    """A narrow camera looking at the sun 3° above the horizon: the disk's radiance summed over the
    sky pixels' solid angles is E_sun (1 %), and the table render equals the per-pixel one."""
    cams = make_cams(128, 160, hfov_deg=3.0, pitch_deg=3.0)
    sun = rs.Sun(math.radians(87.0), 0.0, 12.0)
    scene = make_scene(wind_speed=6.0, band=rs.MWIR, sun=sun)
    img = rs.render(cams, scene)
    night = rs.render(cams, make_scene(wind_speed=6.0, band=rs.MWIR))
    sky = ~rs.view_geometry(cams).is_sea[0]
    total = float(((img - night)[0, 0] * sky).sum()) / float(cams.fx[0]) ** 2  # pixel solid angle ≈ 1/f² here
    assert abs(total / 12.0 - 1) < 0.01
    direct = rs.render(cams, scene, method="direct")
    assert float(((img - direct) / direct).abs().max()) < 1e-5


@pytest.mark.parametrize("hfov_deg, size, pitch_deg, zenith_deg", [(3.0, (128, 160), 3.0, 87.0), (30.0, (64, 80), -1.0, 85.94)])
def test_the_suns_disk_is_the_same_in_float32(hfov_deg, size, pitch_deg, zenith_deg):
    """The disk's cover of each pixel (the share of L_sun it shows) in a float32 render is the float64
    render's to float32 rounding: measured 5e-5 (3° lens, 688 disk pixels) and 6e-7 (30° lens, 4 pixels)
    of L_sun; bound 1e-3. Planted (the old code): the angle from the sun's centre through 2 − 2 cos(ang)
    of the rays' dot product, which cancels in float32 (1e-5 rad at the disk's edge): 6.4 % and 0.2 % of
    L_sun; fails."""
    sun = rs.Sun(math.radians(zenith_deg), 0.0, 12.0)
    l_sun = 12.0 / (4 * math.pi * math.sin(0.5 * sun.radius) ** 2)
    disk = {}
    for dtype in (torch.float32, torch.float64):
        cams = rs.make_camera(*size, hfov_deg=hfov_deg, altitude_m=20.0, pitch_deg=pitch_deg, dtype=dtype)
        day = rs.render(cams, rs.SeaScene(wind_speed=6.0, sea_temperature=290.0, band=rs.MWIR, sun=sun))
        night = rs.render(cams, rs.SeaScene(wind_speed=6.0, sea_temperature=290.0, band=rs.MWIR))
        disk[dtype] = (day - night).double() / l_sun
    assert int((disk[torch.float64] > 0.5).sum()) >= 1  # the disk is in view
    assert float((disk[torch.float32] - disk[torch.float64]).abs().max()) < 1e-3

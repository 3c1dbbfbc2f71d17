"""Scenes by day and in storms: the sun's irradiance from the LOWTRAN7 table, foam on where the wind
warrants it (Monahan & O'Muircheartaigh 1980), each with clear errors."""

import math

import pytest
import torch

import roughsea_torch as rs
from roughsea_torch.radiometry import as_band
from roughsea_torch.solar import load_solar_irradiance


def _cams(b=1):
    return rs.make_camera(24, 32, hfov_deg=20.0, altitude_m=20.0, pitch_deg=-4.0, batch_size=b, dtype=torch.float64)


def test_sun_from_zenith_takes_the_lowtran_irradiance_of_the_scene_band():
    z = torch.tensor([math.radians(30.0), math.radians(80.0)], dtype=torch.float64)
    for band in (rs.MWIR, rs.LWIR):
        sc = rs.SeaScene(wind_speed=6.0, sea_temperature=290.0, band=band, sky="tropical", sun_zenith=z, sun_azimuth=0.0)
        want = load_solar_irradiance("tropical", band, aerosol="maritime")(z)  # the default aerosol dims the beam
        torch.testing.assert_close(sc.sun.irradiance, want, rtol=1e-12, atol=0.0)
        clear = rs.SeaScene(wind_speed=6.0, sea_temperature=290.0, band=band, sky="tropical", sun_zenith=z,
                            sun_azimuth=0.0, aerosol=None)
        torch.testing.assert_close(clear.sun.irradiance, load_solar_irradiance("tropical", band)(z), rtol=1e-12, atol=0.0)
        assert bool((sc.sun.irradiance < 0.97 * clear.sun.irradiance).all())
    # the irradiance is kept between reads, keyed by the fields' values: a changed field (a new
    # tensor, the same tensor changed in place, another aerosol) takes effect
    sc = rs.SeaScene(wind_speed=6.0, sea_temperature=290.0, band=rs.MWIR, sky="tropical", sun_zenith=z.clone(), sun_azimuth=0.0)
    first = sc.sun.irradiance.clone()
    sc.sun_zenith = z.flip(0)
    torch.testing.assert_close(sc.sun.irradiance, first.flip(0), rtol=1e-12, atol=0.0)
    sc.sun_zenith[0] = z[0]
    torch.testing.assert_close(sc.sun.irradiance, first[0].expand(2), rtol=1e-12, atol=0.0)
    sc.aerosol = None
    torch.testing.assert_close(sc.sun.irradiance, load_solar_irradiance("tropical", rs.MWIR)(sc.sun_zenith), rtol=1e-12, atol=0.0)
    # another band (a new object, whatever its response), a caller changing what it got, inference mode
    narrow = as_band((4.4e-6, 4.9e-6))
    sc.band = narrow
    torch.testing.assert_close(sc.sun.irradiance, load_solar_irradiance("tropical", narrow)(sc.sun_zenith), rtol=1e-12, atol=0.0)
    sc.sun.irradiance.mul_(2.0)
    torch.testing.assert_close(sc.sun.irradiance, load_solar_irradiance("tropical", narrow)(sc.sun_zenith), rtol=1e-12, atol=0.0)
    with torch.inference_mode():
        sc.sun.irradiance
    w = torch.ones(2, dtype=torch.float64, requires_grad=True)
    (sc.sun.irradiance * w).sum().backward()
    assert w.grad is not None
    with pytest.raises(ValueError, match="sun_zenith"):
        rs.SeaScene(wind_speed=6.0, sea_temperature=290.0, sky=10.0, sun_zenith=0.5)
    with pytest.raises(ValueError, match="not both"):
        rs.SeaScene(wind_speed=6.0, sea_temperature=290.0, sun=rs.Sun(0.5, 0.0, 1.0), sun_zenith=0.5)


def test_foam_keeps_the_second_law_and_vanishes_without_wind():
    """A sky at the sea's blackbody radiance: foam (whatever its emissivity) changes nothing; no wind,
    no foam: the default 'auto' equals foam=False bit for bit; a storm's foam changes the image."""
    rb = 30.0
    cams = _cams()
    storm = rs.render(cams, rs.SeaScene(wind_speed=25.0, sea_radiance=rb, sky=rb, path=False))
    assert torch.allclose(storm[0, 0][rs.view_geometry(cams).is_sea[0]], torch.tensor(rb, dtype=torch.float64), rtol=1e-12, atol=0)
    calm = dict(wind_speed=0.0, sea_temperature=290.0)
    assert torch.equal(rs.render(cams, rs.SeaScene(**calm)), rs.render(cams, rs.SeaScene(**calm, foam=False)))
    windy = dict(wind_speed=20.0, sea_temperature=290.0)
    with_foam = rs.render(cams, rs.SeaScene(**windy), output="brightness_temperature")
    without = rs.render(cams, rs.SeaScene(**windy, foam=False), output="brightness_temperature")
    assert float((with_foam - without).abs().max()) > 0.1  # kelvin: 7 % whitecaps at 20 m/s


def test_foam_fraction_errors():
    with pytest.raises(ValueError, match="foam"):
        rs.SeaScene(wind_speed=5.0, sea_temperature=290.0, foam=1.5)
    with pytest.raises(ValueError, match="foam"):
        rs.SeaScene(wind_speed=5.0, sea_temperature=290.0, foam="yes")


def test_textured_foam_sits_on_crests_keeps_the_second_law_and_matches_per_pixel_evaluation():
    """A textured storm sea puts its whitecaps on crests (foam.crest_foam_fraction), not as a uniform
    veil: the foam's change to the image concentrates in few pixels (the tenth of the sea pixels it
    changes most carry over half of the change; a uniform fraction W, as in the expectation, spreads
    it over all and gives 0.29 here). The table equals the per-pixel evaluation to 1 % of the
    texture's amplitude, and a sky at the sea's blackbody radiance leaves every pixel at R_B."""
    cams = rs.make_camera(48, 64, hfov_deg=30.0, altitude_m=20.0, pitch_deg=-8.0, batch_size=2, dtype=torch.float64)
    g = rs.view_geometry(cams)
    sea = g.is_sea[:, None]
    kw = dict(wind_speed=torch.tensor([14.0, 20.0]), sea_temperature=290.0, sky=lambda c: 12.0 + 18.0 * (1 - c) ** 6,
              path=False, seed=[3, 4])
    foamy = rs.render(cams, rs.SeaScene(**kw))
    bare = rs.render(cams, rs.SeaScene(**kw, foam=False))
    for i in range(2):
        d = (foamy - bare)[i][sea[i]].abs()
        top = d.sort(descending=True).values[: d.numel() // 10]
        assert float(top.sum() / d.sum()) > 0.5
    direct = rs.render(cams, rs.SeaScene(**kw), method="direct", geometry=g)
    amplitude = float((foamy - rs.render(cams, rs.SeaScene(**dict(kw, seed=None)))).abs().max())
    assert float((foamy - direct).abs()[sea].max()) < 0.01 * amplitude
    rb = 27.5
    img = rs.render(cams, rs.SeaScene(wind_speed=20.0, sea_radiance=rb, sky=rb, path=False, seed=[5, 6]))
    torch.testing.assert_close(img[sea], torch.full_like(img[sea], rb), rtol=1e-12, atol=0.0)


def _day_scene(**kw):
    base = dict(wind_speed=0.5, sea_temperature=290.0, band=rs.MWIR, sky="midlatitude_summer", path=False,
                sun_zenith=math.radians(60.0), sun_azimuth=0.0, foam=False)
    base.update(kw)
    return rs.SeaScene(**base)


def test_day_sky_pixels_add_the_scattered_sky_by_zenith_and_azimuth():
    """Sky pixels by day = by night + the LOWTRAN scattered sky along each ray (its zenith, its azimuth
    from the sun's), brighter towards the sun (the aerosol's forward scattering) than away."""
    from roughsea_torch.daysky import load_scattered_sky

    cams = rs.make_camera(24, 32, hfov_deg=40.0, altitude_m=20.0, pitch_deg=25.0, yaw_deg=torch.tensor([0.0, 180.0]),
                          dtype=torch.float64)
    g = rs.view_geometry(cams)
    sky = ~g.is_sea
    assert bool(sky.all())
    sun_az = math.radians(45.0)  # 45° off the yaw-0 camera's axis: the sun's disk out of its view
    day = rs.render(cams, _day_scene(sun_azimuth=sun_az))[:, 0]
    night = rs.render(cams, rs.SeaScene(wind_speed=0.5, sea_temperature=290.0, band=rs.MWIR, path=False, foam=False))[:, 0]
    ds = load_scattered_sky("midlatitude_summer", rs.MWIR, aerosol="maritime")
    want = ds(g.cos_view_zenith, torch.atan2(g.dy, g.dx) - sun_az, torch.full_like(g.cos_view_zenith, math.radians(60.0)))
    torch.testing.assert_close(day - night, want, rtol=1e-9, atol=1e-12)
    assert float((day - night)[0].mean()) > 1.5 * float((day - night)[1].mean())  # yaw 0 looks towards the sun


def test_day_sky_reflected_by_a_calm_sea_along_the_mirror_azimuth():
    """The sun 60° from the zenith behind the camera (no glint in view), calm sea: by day the sea pixels
    gain the reflection of the scattered sky along their mirror direction (the camera's look azimuth,
    away from the sun), as apparent_radiance computes it with that sky as a zenith-only table
    (R_B = 0), to 2e-3; ≈ ρ(θ̂) × that sky within 8 % (the slopes spread the reflected zeniths), and
    ~3x less than the sky towards the sun would give (a mirror azimuth off by π fails both)."""
    from roughsea_torch.daysky import load_scattered_sky

    cams = rs.make_camera(16, 16, hfov_deg=6.0, altitude_m=20.0, pitch_deg=-20.0, yaw_deg=torch.tensor([180.0]),
                          dtype=torch.float64)
    g = rs.view_geometry(cams)
    assert bool(g.is_sea.all())
    scene = _day_scene()
    plus = (rs.render(cams, scene)[:, 0] - rs.render(cams, _day_scene(aerosol=None))[:, 0]).reshape(-1)
    ds = load_scattered_sky("midlatitude_summer", rs.MWIR, aerosol="maritime")
    look = torch.atan2(g.dy, g.dx).reshape(-1)  # the rays' world azimuths: the mirror direction
    th, ph = g.view_zenith.reshape(-1), g.view_azimuth.reshape(-1)
    z = scene.sky.zenith.double()
    sun_z = math.radians(60.0)
    table = ds(torch.cos(z)[None, :], look[:, None], torch.full((1, 1), sun_z, dtype=torch.float64))
    m = rs.band_refractive_index(rs.MWIR, 290.0).to(torch.complex128)
    want = rs.apparent_radiance(th, ph, rs.SlopeStatistics.cox_munk(0.5, anisotropic=True), m, sea_radiance=0.0,
                                sky=rs.TabulatedSky(z, table))
    assert float(((plus - want) / want).abs().max()) < 2e-3
    s_mirror = ds(torch.cos(th), look, torch.full_like(look, sun_z))
    rho = 1.0 - rs.fresnel_emissivity(torch.cos(th), m)
    assert float((plus / (rho * s_mirror) - 1).abs().max()) < 0.08
    towards = ds(torch.cos(th), look + math.pi, torch.full_like(look, sun_z))
    assert bool((towards > 2.0 * s_mirror).all())


def test_day_scene_table_equals_per_pixel_evaluation():
    """A full MWIR daytime scene (LOWTRAN sky and path, the sun 20° up ahead with its glint, the
    scattered sky in the sky pixels and in the sea's reflection, anisotropic slopes, foam): the table
    render equals the per-pixel evaluation to 2e-5 by day without aerosol (glint rows and sky
    included) and to 1e-4 with the scattered sky (3.7e-5 measured: its azimuth table is piecewise
    linear, TableSize.azimuth_day; 7 azimuth nodes, planted, leave 1.9e-3)."""
    cams = rs.make_camera(32, 40, hfov_deg=30.0, altitude_m=torch.tensor([20.0, 150.0]),
                          pitch_deg=torch.tensor([-2.0, -12.0]), yaw_deg=torch.tensor([10.0, -30.0]),
                          dtype=torch.float64)
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

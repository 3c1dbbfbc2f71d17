"""The scene (roughsea_torch.renderer.scene, SeaScene): how its arguments reach the pixels (the sea
radiance of its own band, a spectral response, explicit slopes, the path, air temperature, the sun
from its zenith, seeds), its defaults, and the checks of every argument: bad inputs raise a
``ValueError`` that names the argument and its allowed range (no silent NaN, no error from deep
inside). Scenes and cameras against physics computed outside the library (Planck integrated here,
the numpy reference)."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
import torch

import roughsea_torch as rs
import roughsea_torch.reference as ref
from roughsea_torch.foam import whitecap_fraction
from roughsea_torch.radiometry import as_band
from roughsea_torch.solar import load_solar_irradiance

from conftest import TIME_RANGE, horizon_sky, make_cams, make_scene, planck_band, smooth_sky

F64 = torch.float64


def seeded_scene(**kw):
    """A textured sea (seed 1) with the common wind and sea temperature; keywords override."""
    return make_scene(**{"seed": 1, **kw})


def small_cams(batch_size=1):
    """8 × 10 pixels, 15 m up, looking 5° down, float32."""
    return make_cams(8, 10, batch_size=batch_size, altitude_m=15.0, dtype=torch.float32)


@pytest.mark.parametrize(
    "call, match",
    [
        (lambda: rs.SeaScene(sea_temperature=290.0, sky=1.0), "wind_speed"),
        (lambda: rs.SeaScene(wind_speed=3.0, sky=1.0), "sea_temperature"),
        (lambda: rs.SeaScene(wind_speed=-3.0, sea_temperature=290.0, sky=1.0), "wind_speed"),
        (lambda: rs.SeaScene(wind_speed=3.0, sea_temperature=500.0, sky=1.0), "sea_temperature"),
    ],
)
def test_scene_errors(call, match):
    with pytest.raises(ValueError, match=match):
        call()


def test_default_scene_with_named_atmosphere_and_path(dtype):
    """The README's default scene: shipped LOWTRAN sky (float64 tables) in a float32 or float64 render,
    path on; table matches direct; the image keeps the cameras' dtype."""
    cams = make_cams(altitude_m=torch.tensor([20.0, 300.0]), pitch_deg=torch.tensor([-2.0, -6.0]), dtype=dtype)
    scene = make_scene(wind_speed=torch.tensor([4.0, 12.0]), wind_direction=0.3)
    assert scene.path is not None
    geom = rs.view_geometry(cams)
    table = rs.render(cams, scene, geometry=geom, output="brightness_temperature")
    direct = rs.render(cams, scene, geometry=geom, method="direct", output="brightness_temperature")
    assert table.dtype == dtype
    torch.testing.assert_close(table, direct, rtol=0, atol=2e-3)  # 2 mK
    mst = make_scene(wind_speed=5.0, band=rs.MWIR)
    assert 0.5 < float(mst.sky(torch.tensor(1.0))) < 1.2  # the MWIR sky, not the LWIR one


def test_scene_sea_radiance_is_the_band_radiance_of_its_own_band():
    """A 290 K sea under a sky of the same band radiance (no path): every pixel, sea or sky, is the
    band radiance of a 290 K blackbody in the scene's band, from Planck integrated here (MWIR
    3–5 µm: 1.28 W m⁻² sr⁻¹; LWIR: 32.5 W m⁻² sr⁻¹; a scene given the other band's sea radiance is off
    by 25×), and its brightness temperature is 290 K. (The LWIR default is exercised by every
    other scene test.)"""
    band = (3e-6, 5e-6)
    L = planck_band(290.0, *band)
    # skin_deficit=0: active whitecaps at the sea's temperature too
    scene = make_scene(wind_speed=torch.tensor(6.0, dtype=F64), band=band, sky=L, path=False, skin_deficit=0.0)
    cams = make_cams(hfov_deg=40.0, pitch_deg=-2.0, roll_deg=0.0, batch_size=1)
    geom = rs.view_geometry(cams)
    assert bool(geom.is_sea.any()) and bool((~geom.is_sea).any())
    img = rs.render(cams, scene)
    np.testing.assert_allclose(img.numpy(), L, rtol=1e-6)
    bt = rs.render(cams, scene, output="brightness_temperature")
    np.testing.assert_allclose(bt.numpy(), 290.0, rtol=0, atol=1e-4)


def test_scene_response_shapes_the_sea_radiance():
    """A tabulated spectral response (the reference integrates it with scipy): a 295 K sea under a
    sky equal to that response-weighted band radiance renders that radiance everywhere; the flat
    band's would differ by ~30 %."""
    wl = np.array([7.5e-6, 8.5e-6, 10e-6, 11.5e-6, 12.5e-6])
    resp = np.array([0.0, 0.9, 1.0, 0.7, 0.0])
    band = (7.5e-6, 12.5e-6)
    L = float(ref.band_radiance(295.0, band, (wl, resp)))
    assert abs(L / float(ref.band_radiance(295.0, band)) - 1) > 0.1
    scene = rs.SeaScene(wind_speed=torch.tensor(6.0, dtype=F64), sea_temperature=295.0, band=band, response=(wl, resp),
                        sky=L, path=False, skin_deficit=0.0)  # active whitecaps at the sea's temperature too
    img = rs.render(make_cams(hfov_deg=40.0, pitch_deg=-2.0, roll_deg=0.0, batch_size=1), scene)
    np.testing.assert_allclose(img.numpy(), L, rtol=1e-6)


def test_explicit_slopes_and_sea_radiance_reach_the_pixels():
    """SeaScene(slopes=..., sea_radiance=...) with a correlated anisotropic law and a wind
    direction: sea pixels equal the numpy reference's Eq. 10 at each pixel's own view zenith and
    relative azimuth φ̂ = LOS azimuth − wind direction (docs/physics.md §2)."""
    a, b, r, wd, rb = 0.28, 0.11, 0.5, 0.7, 31.0
    scene = rs.SeaScene(slopes=rs.SlopeStatistics(torch.tensor(a, dtype=F64), b, r), wind_direction=wd,
                        sea_radiance=rb, sky=smooth_sky, refractive_index=1.153 + 0.0968j, path=False)
    cams = make_cams(hfov_deg=60.0, pitch_deg=-20.0, yaw_deg=35.0)
    geom = rs.view_geometry(cams)
    img = rs.render(cams, scene, geometry=geom)
    for (i, j) in ((23, 0), (12, 31)):
        assert bool(geom.is_sea[0, i, j])
        th = float(geom.view_zenith[0, i, j])
        ph = float(geom.view_azimuth[0, i, j]) - wd
        want = float(ref.apparent_radiance(th, ph, ref.SlopeStatistics(a, b, r), 1.153 + 0.0968j, rb, smooth_sky, epsrel=1e-9))
        assert abs(float(img[0, 0, i, j]) / want - 1) < 5e-5, (i, j, float(img[0, 0, i, j]), want)
    # the law is anisotropic and seen off its axes: the pixels above are not insensitive to it
    other = rs.SeaScene(slopes=rs.SlopeStatistics(torch.tensor(b, dtype=F64), a, r), wind_direction=wd,
                        sea_radiance=rb, sky=smooth_sky, refractive_index=1.153 + 0.0968j, path=False)
    assert float((rs.render(cams, other, geometry=geom) - img).abs().max()) > 1e-3


def test_scene_path_arguments():
    with pytest.raises(ValueError, match="path=True needs a named atmosphere"):
        rs.SeaScene(wind_speed=3.0, sea_temperature=290.0, sky=1.0, path=True)
    with pytest.raises(ValueError, match="path must be"):
        rs.SeaScene(wind_speed=3.0, sea_temperature=290.0, sky=1.0, path=3.0)
    assert rs.SeaScene(wind_speed=3.0, sea_temperature=290.0, sky=1.0).path is None  # no model for a custom sky


def test_air_temperature_shifts_sky_and_path():
    """SeaScene(air_temperature=): the atmosphere's own value changes nothing; warmer air makes
    the optically thick horizon sky warmer by about the same number of kelvin, and distant sea
    (long, thick paths) more than the sea below the camera (short path, sea emission)."""
    cam = make_cams(64, 80, pitch_deg=-2.0, batch_size=2)
    t_atm = rs.atmosphere.surface_air_temperature("midlatitude_summer")
    base = rs.render(cam, make_scene(), output="brightness_temperature")
    air = torch.tensor([t_atm, t_atm + 10.0], dtype=torch.float64)
    warm = rs.render(cam, make_scene(air_temperature=air), output="brightness_temperature")
    assert torch.equal(warm[0], base[0])
    # the table method scales the reflected-sky term, the direct one a per-image sky table: same image
    direct = rs.render(cam, make_scene(air_temperature=air), method="direct")
    table = rs.render(cam, make_scene(air_temperature=air))
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
        make_scene(sky=10.0, air_temperature=290.0)
    with pytest.raises(ValueError, match="air_temperature"):
        make_scene(air_temperature=400.0)


@pytest.mark.parametrize("method", ["table", "direct"])
def test_sea_temperature_gradient_matches_central_difference(method):
    """d(image)/dT_sea includes how the band-effective water index moves with T_sea (its Planck
    weights): autograd against a float64 central difference, at 1e-6 relative. (With the index
    fitted from a detached temperature the gradient was 3.2e-4 off.)"""
    cams = make_cams(12, 16, pitch_deg=-6.0)

    def img(t):
        return rs.render(cams, make_scene(wind_speed=7.0, sea_temperature=t, sky=smooth_sky), method=method)

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
    cams = make_cams(8, 10)
    scene = make_scene(wind_speed=5.0, sea_temperature=280.0, sky=smooth_sky)
    rs.render(cams, scene)
    scene.sea_temperature = 300.0
    fresh = rs.render(cams, make_scene(wind_speed=5.0, sea_temperature=300.0, sky=smooth_sky))
    assert torch.equal(rs.render(cams, scene), fresh)


def test_sun_from_zenith_takes_the_lowtran_irradiance_of_the_scene_band():
    z = torch.tensor([math.radians(30.0), math.radians(80.0)], dtype=torch.float64)
    for band in (rs.MWIR, rs.LWIR):
        sc = make_scene(wind_speed=6.0, band=band, sky="tropical", sun_zenith=z, sun_azimuth=0.0)
        want = load_solar_irradiance("tropical", band, aerosol="maritime")(z)  # the default aerosol dims the beam
        torch.testing.assert_close(sc.sun.irradiance, want, rtol=1e-12, atol=0.0)
        clear = make_scene(wind_speed=6.0, band=band, sky="tropical", sun_zenith=z, sun_azimuth=0.0, aerosol=None)
        torch.testing.assert_close(clear.sun.irradiance, load_solar_irradiance("tropical", band)(z), rtol=1e-12, atol=0.0)
        assert bool((sc.sun.irradiance < 0.97 * clear.sun.irradiance).all())
    # the irradiance is kept between reads, keyed by the fields' values: a changed field (a new
    # tensor, the same tensor changed in place, another aerosol) takes effect
    sc = make_scene(wind_speed=6.0, band=rs.MWIR, sky="tropical", sun_zenith=z.clone(), sun_azimuth=0.0)
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
        make_scene(wind_speed=6.0, sky=10.0, sun_zenith=0.5)
    with pytest.raises(ValueError, match="not both"):
        make_scene(wind_speed=6.0, sun=rs.Sun(0.5, 0.0, 1.0), sun_zenith=0.5)


def test_foam_fraction_errors():
    with pytest.raises(ValueError, match="foam"):
        make_scene(wind_speed=5.0, foam=1.5)
    with pytest.raises(ValueError, match="foam"):
        make_scene(wind_speed=5.0, foam="yes")


def test_foam_true_is_refused_and_augmentations_take_one_setting():
    """foam=True read as a whitecap fraction of 1 (a sea all foam) where a user means "on": it is a
    ValueError that points at 'auto'. An augmentation takes one foam setting for every image (a
    per-image tensor failed whenever the gate picked a subset; found in review)."""
    for make in (lambda f: make_scene(foam=f),
                 lambda f: rs.RandomSeaBackground(foam=f), lambda f: rs.RandomSeaClip(foam=f)):
        with pytest.raises(ValueError, match="'auto'"):
            make(True)
    with pytest.raises(ValueError, match="foam: one setting for every image"):
        rs.RandomSeaBackground(foam=torch.tensor([0.0, 1.0]))
    assert make_scene(foam=torch.tensor([0.0, 1.0])).foam is not None


@pytest.mark.parametrize("t", [float("inf"), float("-inf"), float("nan"), 2e9, torch.tensor([0.0, float("inf")])])
def test_scene_time_must_be_finite_within_the_wave_sampler_range(t):
    """SeaScene checks time_s at construction against WaveField.sample's [-1e9, 1e9] s (inf used to
    render NaN pixels, 1e12 used to render, NaN reported the range [-inf, inf])."""
    with pytest.raises(ValueError, match=r"time_s must lie in " + TIME_RANGE):
        seeded_scene(time_s=t)


def test_scene_time_is_checked_whenever_it_is_set():
    """render_clip and the augmentations set a copied scene's time frame by frame: that is checked too."""
    s = seeded_scene(time_s=torch.tensor([0.0, 1.0]))
    with pytest.raises(ValueError, match=r"time_s must lie in " + TIME_RANGE):
        s.time_s = torch.tensor([float("inf"), 1.0])
    with pytest.raises(ValueError, match=r"time_s: must be a float or a tensor of shape \(B,\)"):
        s.time_s = torch.zeros(2, 2)
    assert torch.equal(s.time_s, torch.tensor([0.0, 1.0]))  # a refused value is not kept


@pytest.mark.parametrize("t", ["0", ["a"], [0.0, 1.0], 1j])
def test_scene_time_must_be_a_real_number_or_tensor(t):
    with pytest.raises(ValueError, match=r"^time_s"):
        seeded_scene(time_s=t)


@pytest.mark.parametrize("bad", [float("nan"), float("inf"), -2e6])
def test_wind_direction_reports_its_real_range(bad):
    """NaN used to report [-inf, inf] (SeaScene's check) while inf reported WaveField's [-1e6, 1e6]."""
    for seed in (1, None):
        with pytest.raises(ValueError, match=r"wind_direction must lie in \[-1e\+06, 1e\+06\] rad"):
            seeded_scene(wind_direction=bad, seed=seed)


@pytest.mark.parametrize("bad", [-0.1, 5.1, float("nan"), float("inf"), float("-inf"), torch.tensor([0.2, -1.0]),
                                 np.array([0.2, 7.0])])
def test_skin_deficit_outside_0_to_5_kelvin_is_refused(bad):
    """SeaScene(skin_deficit=): a ValueError naming the argument and its range [0, 5] K for a negative, too
    large or non-finite deficit (a float, a tensor or an array per image), at construction and when set
    later (a refused value is not kept); a list, or a tensor of more than one axis, is refused like time_s;
    per image, its batch size joins the scene's."""
    with pytest.raises(ValueError, match=r"^skin_deficit must lie in \[0, 5\] K"):
        make_scene(skin_deficit=bad)
    s = make_scene(skin_deficit=torch.tensor([0.0, 0.5]))
    with pytest.raises(ValueError, match=r"^skin_deficit must lie in \[0, 5\] K"):
        s.skin_deficit = bad
    assert torch.equal(s.skin_deficit, torch.tensor([0.0, 0.5]))


def test_skin_deficit_shapes_and_batch_size():
    with pytest.raises(ValueError, match=r"^skin_deficit: give a float or a tensor of shape \(B,\)"):
        make_scene(skin_deficit=[0.1, 0.2])
    with pytest.raises(ValueError, match=r"^skin_deficit: must be a float or a tensor of shape \(B,\)"):
        make_scene(skin_deficit=torch.zeros(2, 2))
    assert make_scene(skin_deficit=torch.tensor([0.1, 0.2, 0.3])).batch_size == 3
    with pytest.raises(ValueError, match=r"wind_speed has 2, skin_deficit has 3"):
        make_scene(wind_speed=torch.tensor([5.0, 6.0]), skin_deficit=torch.tensor([0.1, 0.2, 0.3])).batch_size


def test_a_sequence_of_seeds_needs_one_per_image():
    """seed=[1] used to be copied to every image (two identical realizations)."""
    with pytest.raises(ValueError, match=r"seed: a sequence of seeds needs one per image, B = 2; got 1"):
        rs.render(small_cams(2), seeded_scene(seed=[1], wind_speed=torch.tensor([8.0, 8.0])))
    with pytest.raises(ValueError, match=r"seed: a sequence of seeds needs one per image, B = 2; got 1"):
        rs.render(small_cams(2), seeded_scene(seed=[1]))  # the scene's other fields are scalars: B from the cameras
    with pytest.raises(ValueError, match=r"seed: a sequence of seeds needs one per image, B = 2; got 3"):
        seeded_scene(seed=[1, 2, 3], wind_speed=torch.tensor([5.0, 8.0])).batch_size
    # a plain int (also as a 0-D tensor) keeps its documented meaning: image i's seed derived from (seed, i)
    derived = [int(np.random.SeedSequence((7, i)).generate_state(1, np.uint64)[0] >> 1) for i in range(2)]
    assert seeded_scene(seed=7).seeds(2) == derived
    assert seeded_scene(seed=torch.tensor(7)).seeds(2) == derived
    assert seeded_scene(seed=7).seeds(1) == [7] and seeded_scene(seed=[7]).seeds(1) == [7]


def test_numpy_integer_seeds_are_ints():
    """A shard stores wave_seed as np.int64: SeaScene(seed=shard["wave_seed"][i]) is that int seed."""
    shard = {"wave_seed": np.array([3, 5], dtype=np.int64)}
    a = rs.render(small_cams(), seeded_scene(seed=shard["wave_seed"][0], foam=False))
    assert torch.equal(a, rs.render(small_cams(), seeded_scene(seed=3, foam=False)))
    assert seeded_scene(seed=np.int64(3)).seeds(2) == seeded_scene(seed=3).seeds(2)
    assert seeded_scene(seed=shard["wave_seed"]).seeds(2) == [3, 5]
    assert seeded_scene(seed=np.array(5)).seeds(1) == [5]
    assert seeded_scene(seed=[np.int32(4), np.uint64(6)]).seeds(2) == [4, 6]
    for bad in (np.float64(3.0), np.bool_(True), True, 1.5, np.int64(-1), -1, np.array([1.0, 2.0]),
                np.array([True, False]), np.array([[1, 2]]), torch.tensor(3.0), torch.tensor([[1]])):
        with pytest.raises(ValueError, match=r"^seed"):
            seeded_scene(seed=bad)


def test_one_int_seed_gives_each_image_its_own_derived_seed():
    """seed=int with B > 1 images: image i is the realization of SeedSequence((seed, i)) (documented
    in SeaScene), so images differ from each other and from the neighbouring int seed's."""
    cams2 = make_cams(40, 12, hfov_deg=8.0, altitude_m=10.0, pitch_deg=-8.0, batch_size=2)
    pair = rs.render(cams2, make_scene(sky=horizon_sky, path=False, seed=5))
    assert float((pair[0] - pair[1]).abs().max()) > 1e-4
    derived = int(np.random.SeedSequence((5, 1)).generate_state(1, np.uint64)[0] >> 1)
    alone = rs.render(make_cams(40, 12, hfov_deg=8.0, altitude_m=10.0, pitch_deg=-8.0, batch_size=1),
                      make_scene(sky=horizon_sky, path=False, seed=[derived]))
    # the same realization: equal to rounding (a batch's nodes may be grouped differently: 1 ulp)
    torch.testing.assert_close(pair[1], alone[0], rtol=1e-12, atol=0.0)
    other = rs.render(cams2, make_scene(sky=horizon_sky, path=False, seed=6))
    assert float((pair[1] - other[0]).abs().max()) > 1e-4


def test_calm_textured_scene_says_to_drop_the_seed():
    """wind 0 with seed=: the error names wind_speed and says seed=None (it named the WaveField)."""
    with pytest.raises(ValueError, match=r"^wind_speed: .*seed=None"):
        rs.render(make_cams(8, 8), make_scene(wind_speed=0.0, seed=1))


def test_textured_scene_needs_wind_speed_and_valid_seed():
    with pytest.raises(ValueError, match="wind_speed"):
        rs.SeaScene(slopes=rs.SlopeStatistics.cox_munk(5.0), sea_temperature=290.0, seed=1)
    with pytest.raises(ValueError, match="seed"):
        make_scene(wind_speed=5.0, seed=-1)
    with pytest.raises(ValueError, match="seed"):
        make_scene(wind_speed=5.0, seed=1.5)


def test_unknown_atmosphere_names_the_scene_argument():
    with pytest.raises(ValueError, match=r"^sky: unknown atmosphere 'foo'"):
        rs.SeaScene(wind_speed=5.0, sea_temperature=290.0, sky="foo")
    with pytest.raises(ValueError, match=r"^path: unknown atmosphere 'bar'"):
        rs.SeaScene(wind_speed=5.0, sea_temperature=290.0, sky=20.0, path="bar")


def test_batch_mismatch_names_the_argument():
    cams = rs.make_camera(8, 8, batch_size=2)
    with pytest.raises(ValueError, match=r"seed has batch size 3 .* the cameras have 2 images"):
        rs.render(cams, rs.SeaScene(wind_speed=5.0, sea_temperature=290.0, seed=[1, 2, 3]))
    with pytest.raises(ValueError, match=r"the cameras have 1 image;"):  # (it said "1 images")
        rs.render(rs.make_camera(8, 8), rs.SeaScene(wind_speed=torch.tensor([5.0, 6.0]), sea_temperature=290.0))
    with pytest.raises(ValueError, match=r"seed: a sequence of seeds needs one per image, B = 2; got 3"):
        rs.SeaScene(wind_speed=torch.tensor([5.0, 6.0]), sea_temperature=290.0, seed=[1, 2, 3]).batch_size
    with pytest.raises(ValueError, match=r"wind_speed has 2, sea_temperature has 3"):
        rs.SeaScene(wind_speed=torch.tensor([5.0, 6.0]), sea_temperature=torch.tensor([290.0, 291.0, 292.0])).batch_size


@pytest.mark.parametrize("band", [(2.41e-6, 2.61e-6), (5.89e-6, 6.09e-6), (6.91e-6, 7.11e-6), (14.85e-6, 15.0e-6)],
                         ids=["centre_2.51um", "centre_5.99um", "centre_7.01um", "centre_14.93um"])
def test_auto_foam_reaches_the_edges_of_the_measured_band_ranges(band):
    """foam='auto' is Monahan's whitecap fraction for every band centred in the foam emissivity's
    measured ranges, 2.5–6 µm and 7–15 µm (scenes.md §5), up to their edges (bands centred within
    0.5 % of each): the render equals the one with that fraction given explicitly (a float64 and a
    float32 evaluation of Monahan's law: 1.5e-9 apart), and the foam is there (12 m/s: 1.8 % of the
    sea, 0.4–2 % of the radiance here)."""
    cams = rs.make_camera(8, 8, hfov_deg=10.0, altitude_m=10.0, pitch_deg=-10.0, dtype=torch.float64)

    def render(foam):
        return rs.render(cams, rs.SeaScene(wind_speed=12.0, sea_temperature=290.0, band=band, sky=5.0, path=False,
                                           foam=foam))

    auto, none = render("auto"), render(0.0)
    torch.testing.assert_close(auto, render(float(whitecap_fraction(12.0))), rtol=1e-8, atol=0)
    assert float((auto - none).abs().max() / none.max()) > 2e-3


@pytest.mark.parametrize("band", [(2.40e-6, 2.58e-6), (5.95e-6, 6.15e-6), (6.85e-6, 7.05e-6)],
                         ids=["centre_2.49um", "centre_6.05um", "centre_6.95um"])
def test_auto_foam_is_off_just_outside_the_measured_band_ranges(band):
    """foam='auto' adds whitecaps only where the foam emissivity is measured (band centres in 2.5–6 µm
    and 7–15 µm): a band centred 0.4–0.8 % outside either range renders exactly as foam=0 (a centre
    above 15 µm cannot occur: bands lie within the water index's 2.4–15 µm)."""
    cams = rs.make_camera(8, 8, hfov_deg=10.0, altitude_m=10.0, pitch_deg=-10.0, dtype=torch.float64)

    def render(foam):
        return rs.render(cams, rs.SeaScene(wind_speed=12.0, sea_temperature=290.0, band=band, sky=5.0, path=False,
                                           foam=foam))

    assert torch.equal(render("auto"), render(0.0))


@pytest.mark.parametrize("option, most", [("correlated", 0.3), ("multiscale", 0.6)])
def test_masked_shadowing_reaches_table_and_direct_renders(option, most):
    """SeaScene(shadowing="correlated" or "multiscale"): the table render matches the direct one, near
    grazing the image differs from Eq. 5's (and not far from it: the correlated option moves it by < 0.3 K,
    the multi-scale one by < 0.6 K, its largest near the horizon); anything else than
    True/False/"correlated"/"multiscale" is a ValueError naming the argument."""
    cams = make_cams(8, 12, hfov_deg=6.0, altitude_m=15.0, pitch_deg=-4.0)
    scene = make_scene(wind_speed=5.0, shadowing=option, path=False, foam=False)
    table = rs.render(cams, scene, output="brightness_temperature")
    direct = rs.render(cams, scene, method="direct", output="brightness_temperature")
    torch.testing.assert_close(table, direct, rtol=0, atol=2e-3)
    eq5 = rs.render(cams, make_scene(wind_speed=5.0, path=False, foam=False), output="brightness_temperature")
    sea = torch.isfinite(eq5) & (eq5 > 0)
    diff = (table - eq5)[sea]
    assert 0.01 < float(diff.abs().max()) < most, float(diff.abs().max())
    for bad in ("wagner", None, 2):
        with pytest.raises(ValueError, match="shadowing"):
            make_scene(shadowing=bad)


def test_wind_direction_beyond_a_full_turn_warns_of_degrees():
    """SeaScene takes the wind direction in radians (the samplers take degrees): 45.0, almost surely 45°, warns
    at the user's line, naming radians and math.radians; directions within ±2π (2π itself, in float32 too) and
    per-image tensors within it do not warn. Larger angles stay valid (a warning, not an error)."""
    with warnings.catch_warnings(record=True) as got:
        warnings.simplefilter("always")
        scene = rs.SeaScene(wind_speed=8.0, wind_direction=45.0, sea_temperature=290.0)
    assert len(got) == 1 and "radians" in str(got[0].message) and "math.radians(45)" in str(got[0].message)
    assert got[0].filename == __file__ and scene.wind_direction == 45.0
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        for wd in (1.0, 2.0 * math.pi, -2.0 * math.pi, torch.tensor([0.1, 6.0]), torch.tensor(2.0 * math.pi, dtype=torch.float32)):
            rs.SeaScene(wind_speed=8.0, wind_direction=wd, sea_temperature=290.0)

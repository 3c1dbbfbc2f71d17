"""Physics of the model, asserted identically of every backend (reference, torch64, torch32).

Facts come from the paper and ``docs/physics.md`` §13; none is a value produced by this code.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from conftest import DEG, smooth_sky

M10 = 1.218 + 0.0508j  # Hale & Querry, 10 µm
M11 = 1.153 + 0.0968j  # 11 µm


def flat_emissivity(theta: float, m: complex) -> float:
    """Fresnel emissivity of a flat surface, written out independently of both backends."""
    c = math.cos(theta)
    s2 = 1.0 - c * c
    root = np.sqrt(m * m - s2 + 0j)
    rs = abs((c - root) / (c + root)) ** 2
    rp = abs((m * m * c - root) / (m * m * c + root)) ** 2
    return 1.0 - 0.5 * (rs + rp)


GEOMETRIES = [(0.0, 0.0), (40 * DEG, 0.7), (75 * DEG, 2.0), (88 * DEG, 0.3), (89.99 * DEG, 1.2)]


@pytest.mark.parametrize("shadowing", [True, False])
def test_second_law_sky_equal_sea_gives_sea_radiance(backend, shadowing):
    """R_s ≡ R_B ⇒ R_a = R_B (paper, after Eq. 10), for isotropic and correlated anisotropic slopes."""
    for slopes in (backend.cox_munk(12.0), backend.slopes(0.3, 0.05, 0.8)):
        for th, ph in GEOMETRIES[:4]:
            ra = backend.apparent_radiance(th, ph, slopes, M11, 27.5, 27.5, shadowing=shadowing)
            np.testing.assert_allclose(ra, 27.5, rtol=max(backend.rtol, 1e-7) * 0.1)


@pytest.mark.parametrize("theta_deg", [0.0, 30.0])
def test_apparent_radiance_links_to_emissivity_when_every_facet_sees_sky(backend, theta_deg):
    """Where the sky disc covers the whole slope distribution (near nadir, moderate roughness),
    Eq. 10 with a constant sky c ≠ R_B is R_a = ε̄ R_B + (1 − ε̄) c, with ε̄ from ``emissivity``: two
    independent integrals (visible half-plane vs sky disc) must agree. Not true by construction."""
    th = theta_deg * DEG
    slopes = backend.cox_munk(5.0, anisotropic=True)
    eps = backend.emissivity(th, 0.4, slopes, M11)
    ra = backend.apparent_radiance(th, 0.4, slopes, M11, 30.0, 12.0)
    np.testing.assert_allclose(ra, eps * 30.0 + (1.0 - eps) * 12.0, rtol=max(backend.rtol, 1e-7))


def test_view_azimuth_conventions(backend):
    """r = 0: the slope density is mirror-symmetric about the upwind axis, so R(φ̂) = R(−φ̂); and
    anisotropic slopes make upwind and crosswind views differ."""
    slopes = backend.cox_munk(15.0, anisotropic=True)
    th = 85 * DEG
    r = [backend.apparent_radiance(th, ph, slopes, M11, 30.0, smooth_sky) for ph in (0.5, -0.5, 0.0, math.pi / 2)]
    np.testing.assert_allclose(r[0], r[1], rtol=max(backend.rtol, 1e-7))
    assert abs(r[2] - r[3]) > 1e-3 * r[2]


def test_no_shadowing_denominator_is_cos_view_zenith(backend):
    """Eq. 7: without shadowing the Eq. 5 denominator integrates to cos θ̂."""
    for slopes in (backend.cox_munk(20.0), backend.slopes(0.25, 0.06, -0.7)):
        for th, ph in GEOMETRIES[:4]:
            d = backend.projected_area(th, ph, slopes, shadowing=False)
            np.testing.assert_allclose(d, math.cos(backend.roundtrip(th)), rtol=backend.rtol, atol=1e-9)


def test_shadowing_adds_projected_area_smith_lambda(backend):
    """docs/physics.md §13: Smith's Λ at 85°, isotropic Cox–Munk, W = 5 → 0.185, W = 10 → 0.354."""
    th = 85 * DEG
    for w, expected in ((5.0, 0.185), (10.0, 0.354)):
        d = backend.projected_area(th, 0.0, backend.cox_munk(w))
        lam = d / math.cos(backend.roundtrip(th)) - 1.0
        assert abs(lam - expected) < 6e-4


@pytest.mark.parametrize("theta_deg", [0.0, 30.0, 60.0, 80.0])
def test_flat_sea_limit_is_fresnel(backend, theta_deg):
    """σ → 0: the emissivity is the flat Fresnel value and R_a = ε R_B + ρ R_s(θ̂)."""
    th = theta_deg * DEG
    slopes = backend.slopes(1e-5, 1e-5, 0.0)
    eps = backend.emissivity(th, 0.3, slopes, M10)
    np.testing.assert_allclose(eps, flat_emissivity(backend.roundtrip(th), M10), rtol=max(backend.rtol, 1e-6))
    ra = backend.apparent_radiance(th, 0.3, slopes, M10, 30.0, smooth_sky)
    e = flat_emissivity(backend.roundtrip(th), M10)
    expected = e * 30.0 + (1 - e) * smooth_sky(math.cos(backend.roundtrip(th)))
    np.testing.assert_allclose(ra, expected, rtol=max(backend.rtol, 1e-6))


@pytest.mark.parametrize(
    "m, e0",
    [(1.351 + 0.0046j, 0.97771), (M10, 0.98982), (M11, 0.99294), (1.111 + 0.199j, 0.98845)],
)
def test_normal_incidence_emissivity_hale_querry(backend, m, e0):
    """docs/physics.md §13: 1 − ρ₀ with ρ₀ = ((n−1)² + k²)/((n+1)² + k²) for Hale & Querry water."""
    rho = backend.fresnel_reflectance(1.0, m)
    assert abs((1 - rho) - e0) < 6e-6


@pytest.mark.parametrize("m, e85, e89", [(M10, 0.4544, 0.1152), (M11, 0.4682, 0.1194)])
def test_flat_sea_grazing_emissivity_hale_querry(backend, m, e85, e89):
    """docs/physics.md §13: flat-sea emissivity at 85° and 89°."""
    for theta, expected in ((85.0, e85), (89.0, e89)):
        rho = backend.fresnel_reflectance(math.cos(theta * DEG), m)
        assert abs((1 - rho) - expected) < 6e-5


def test_s_and_p_parts_average_to_unpolarized_and_brewster(backend):
    """ρ = (ρ_s + ρ_p)/2; ρ_p has its minimum near Brewster's angle atan(n); ρ_s > ρ_p off normal."""
    c = np.cos(np.linspace(0.0, 89.0, 90) * DEG)
    rs_ = backend.fresnel_reflectance(c, M10, "s")
    rp_ = backend.fresnel_reflectance(c, M10, "p")
    ru = backend.fresnel_reflectance(c, M10)
    np.testing.assert_allclose(ru, 0.5 * (rs_ + rp_), rtol=1e-6)
    assert np.all(rs_[1:] > rp_[1:])
    brewster = math.degrees(math.atan(1.218))
    assert abs(int(np.argmin(rp_)) - brewster) <= 1.0


def test_unnormalized_emissivity_exceeds_one_near_grazing(backend):
    """docs/physics.md §13: dividing by cos θ̂ instead of the shadowed denominator gives ≈ 1.19 at 85°,
    11 µm, W = 15 — so the library's normalized emissivity must stay below 1."""
    th, slopes = 85 * DEG, backend.cox_munk(15.0)
    eps = backend.emissivity(th, 0.0, slopes, M11)
    d = backend.projected_area(th, 0.0, slopes)
    unnormalized = eps * d / math.cos(backend.roundtrip(th))
    assert abs(unnormalized - 1.19) < 0.01
    assert eps < 1.0


def test_rough_sea_colder_than_flat_near_grazing_warmer_elsewhere(backend):
    """The paper's Fig. 3 and its Introduction: with sea and air at one temperature (sky = R_B at
    the horizon), near grazing a rough sea reflects colder sky from higher up and looks colder
    than a flat one; away from grazing the higher facet emissivity wins and it looks warmer."""
    flat = backend.slopes(1e-5, 1e-5)
    for w in (0.0, 15.0):
        rough = backend.cox_munk(w)
        for th, colder in ((89.5 * DEG, True), (80 * DEG, False)):
            r_flat = backend.apparent_radiance(th, 0.0, flat, M10, 30.0, smooth_sky)
            r_rough = backend.apparent_radiance(th, 0.0, rough, M10, 30.0, smooth_sky)
            assert (r_rough < r_flat - 0.5) if colder else (r_rough > r_flat + 0.2)


def test_slope_pdf_is_normalized(backend):
    """∫∫ p(θ, φ) dθ dφ = 1 (Eq. 1 / A7), anisotropic and correlated, by a dense midpoint sum."""
    slopes = backend.slopes(0.2, 0.05, 0.6)
    s = np.linspace(0.0, 1.0, 2001)[1:] ** 2 * 1.5  # tan θ, clustered near 0
    th = np.arctan(s)
    ph = (np.arange(720) + 0.5) * (2 * math.pi / 720)
    TH, PH = np.meshgrid(th, ph, indexing="ij")
    p = backend.slope_pdf(TH, PH, slopes)
    integral = np.trapezoid(p.sum(1) * (2 * math.pi / 720), th)
    assert abs(integral - 1.0) < 2e-4


def test_correlation_orients_the_density(backend):
    """A8: with r > 0 the slopes (s_x, s_y) are positively correlated — facets tilt along the
    diagonal φ = 45° more often than along φ = 135°."""
    slopes = backend.slopes(0.2, 0.2, 0.8)
    th = math.atan(0.2)
    p45 = backend.slope_pdf(th, 45 * DEG, slopes)
    p135 = backend.slope_pdf(th, 135 * DEG, slopes)
    assert p45 > 3 * p135


@pytest.mark.parametrize(
    "bad, match",
    [
        (dict(a=-0.1), "std_upwind"),
        (dict(b=float("nan")), "std_crosswind"),
        (dict(r=1.0), "corr"),
        (dict(th=1.7), "view_zenith"),
        (dict(th=-0.1), "view_zenith"),
        (dict(m=1.2 - 0.05j), "refractive_index"),
    ],
)
def test_bad_input_raises_value_error_naming_argument(backend, bad, match):
    a, b, r = bad.get("a", 0.1), bad.get("b", 0.1), bad.get("r", 0.0)
    th, m = bad.get("th", 0.5), bad.get("m", M10)
    with pytest.raises(ValueError, match=match):
        slopes = backend.slopes(a, b, r)
        backend.emissivity(th, 0.0, slopes, m)


def test_planck_and_brightness_temperature_round_trip(backend):
    """Band radiance is increasing in T and brightness_temperature inverts it."""
    temps = np.array([250.0, 273.15, 300.0, 310.0])
    for band in ((8e-6, 12e-6), (3e-6, 5e-6)):
        L = backend.band_radiance(temps, band)
        assert np.all(np.diff(L) > 0)
        np.testing.assert_allclose(backend.brightness_temperature(L, band), temps, rtol=1e-6)
    # Wien's displacement law: the spectral peak of a 300 K body sits at 2897.77 µm K / 300 K
    lam = np.linspace(9.0e-6, 10.3e-6, 1301)
    peak = lam[np.argmax(backend.planck_radiance(lam, 300.0))]
    assert abs(peak - 2.897771955e-3 / 300.0) < 2e-9

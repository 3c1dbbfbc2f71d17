"""Published numbers and closed forms, asserted of every backend (reference, torch64, torch32) where
the function exists in both, else of the torch code.

Each expected value here is computed in the test from first principles (constants typed in, scipy
quadrature, closed forms) or quoted from the literature; none is a value produced by this library.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import torch
from scipy import integrate

import roughsea_torch as rs

from conftest import DEG, smooth_sky

M10 = 1.218 + 0.0508j  # Hale & Querry 1973, 10 µm
M11 = 1.153 + 0.0968j  # Hale & Querry 1973, 11 µm

# CODATA 2018 (exact SI values), typed here rather than imported from the code under test
H = 6.62607015e-34
C = 299792458.0
KB = 1.380649e-23


def planck_band(T: float, lo: float, hi: float, response=None) -> float:
    """∫ r(λ) 2hc²/λ⁵ / (exp(hc/(λ k T)) − 1) dλ by adaptive quadrature [W m⁻² sr⁻¹]."""

    def f(lam: float) -> float:
        r = 1.0 if response is None else float(response(lam))
        return r * 2.0 * H * C * C / lam**5 / math.expm1(H * C / (lam * KB * T))

    return integrate.quad(f, lo, hi, epsabs=0.0, epsrel=1e-13, limit=200)[0]


@pytest.mark.parametrize("band, T", [((8e-6, 12e-6), 300.0), ((8e-6, 12e-6), 250.0), ((3e-6, 5e-6), 290.0)])
def test_band_radiance_equals_planck_integrated_with_codata_constants(backend, band, T):
    """L(T) = ∫ B_λ(T) dλ: scipy quadrature of Planck's law with the CODATA constants typed in.
    A 300 K blackbody over 8–12 µm gives about 38.5 W m⁻² sr⁻¹ (a quarter of σT⁴/π) (and 1 % of it is about 0.6 K:
    a first radiation constant 1 % off fails here by 1e-2 against a 1e-6 tolerance)."""
    expected = planck_band(T, *band)
    if band == (8e-6, 12e-6) and T == 300.0:
        assert 38.0 < expected < 39.0  # order-of-magnitude sanity of the test's own integral
    got = float(backend.band_radiance(np.array(T), band))
    assert abs(got - expected) / expected < max(backend.rtol, 1e-7)


def test_spectral_planck_equals_closed_form(backend):
    """B_λ(T) at a few (λ, T) against 2hc²λ⁻⁵/(e^{hc/λkT} − 1) with the typed constants."""
    lam = np.array([4e-6, 10e-6, 11e-6, 12e-6])
    for T in (200.0, 300.0):
        expected = 2 * H * C * C / lam**5 / np.expm1(H * C / (lam * KB * T))
        np.testing.assert_allclose(backend.planck_radiance(lam, T), expected, rtol=max(backend.rtol, 1e-9))


@pytest.mark.parametrize("m", [M10, M11, 1.351 + 0.0046j, 1.111 + 0.199j, 1.5 + 0.0j, 2.0 + 1.0j])
def test_normal_incidence_reflectance_closed_form(backend, m):
    """ρ₀ = ((n − 1)² + k²)/((n + 1)² + k²) at normal incidence, for water and for other indices."""
    n, k = m.real, m.imag
    rho0 = ((n - 1) ** 2 + k**2) / ((n + 1) ** 2 + k**2)
    got = float(backend.fresnel_reflectance(np.array(1.0), m))
    assert abs(got - rho0) < max(backend.rtol, 1e-7) * 0.1 + 1e-9


def exact_fresnel(c: float, m: complex) -> tuple[float, float]:
    s2 = 1.0 - c * c
    w = np.sqrt(m * m - s2 + 0j)
    rs_ = abs((c - w) / (c + w)) ** 2
    rp_ = abs((m * m * c - w) / (m * m * c + w)) ** 2
    return rs_, rp_


@pytest.mark.parametrize("dtype", [torch.float64, torch.float32])
def test_fresnel_emissivity_is_one_minus_fresnel_reflectance(dtype):
    """The cancellation-free facet emissivity equals 1 − ρ of the Fresnel equations written with
    complex numbers here (including 89.99°, where ε is small, and normal incidence)."""
    angles = np.array([0.0, 20.0, 45.0, 60.0, 75.0, 85.0, 89.0, 89.99])
    c = np.cos(np.radians(angles))
    for m in (M10, M11, 1.351 + 0.0046j):
        ct = torch.tensor(c, dtype=dtype)
        got = rs.fresnel_emissivity(ct, m).double().numpy()
        expected = np.array([1.0 - 0.5 * sum(exact_fresnel(float(ci), m)) for ci in ct.double().numpy()])
        np.testing.assert_allclose(got, expected, rtol=2e-6 if dtype == torch.float32 else 1e-12, atol=1e-7 if dtype == torch.float32 else 0)
    assert float(rs.fresnel_emissivity(1.0, M10)) == pytest.approx(0.98982, abs=6e-6)  # docs/physics.md §13


def smith_lambda_closed_form(theta: float, sigma_par: float) -> float:
    """Smith (1967): Λ(ν) = [e^{−ν²}/(ν √π) − erfc(ν)] / 2 with ν = cot θ̂ / (√2 σ∥)."""
    nu = 1.0 / math.tan(theta) / (math.sqrt(2.0) * sigma_par)
    return 0.5 * (math.exp(-nu * nu) / (nu * math.sqrt(math.pi)) - math.erfc(nu))


@pytest.mark.parametrize("dtype", [torch.float64, torch.float32])
def test_smith_lambda_closed_form(dtype):
    """``smith_lambda`` against Smith's closed form with σ∥² = a² cos²φ̂ + 2 r a b cos φ̂ sin φ̂ +
    b² sin²φ̂ (docs/physics.md §3), for an anisotropic correlated law at several azimuths; and the
    published values of docs/physics.md §13 (85°, isotropic Cox–Munk: W = 5 → 0.185, W = 10 → 0.354)."""
    a, b, r = 0.22, 0.09, 0.5
    s = rs.SlopeStatistics(torch.tensor(a, dtype=dtype), b, r)
    for th_deg in (50.0, 70.0, 80.0, 85.0, 88.0):
        for ph in (0.0, 0.6, math.pi / 2, 2.4):
            th = float(np.float32(th_deg * DEG)) if dtype == torch.float32 else th_deg * DEG
            sp = math.sqrt(a * a * math.cos(ph) ** 2 + 2 * r * a * b * math.cos(ph) * math.sin(ph) + b * b * math.sin(ph) ** 2)
            got = float(rs.smith_lambda(torch.tensor(th, dtype=dtype), torch.tensor(ph, dtype=dtype), s))
            want = smith_lambda_closed_form(th, sp)
            assert abs(got - want) <= (2e-5 if dtype == torch.float32 else 1e-10) * max(1.0, want), (th_deg, ph, got, want)
    for w, expected in ((5.0, 0.185), (10.0, 0.354)):
        lam = float(rs.smith_lambda(torch.tensor(85 * DEG, dtype=dtype), 0.0, rs.SlopeStatistics.cox_munk(torch.tensor(w, dtype=dtype))))
        assert abs(lam - expected) < 6e-4


def test_water_emissivity_matches_masuda_1988(backend):
    """Masuda, Takashima & Takayama 1988 (Remote Sens. Environ. 24, 313), rough-sea emissivity of
    water in the 10–12 µm window (Cox–Munk slopes, shadowing): ≈ 0.99 at nadir, ≈ 0.96–0.97 near
    60°, falling steeply beyond 70° (≈ 0.7–0.85 at 80°), and at large view angles the emissivity
    grows with wind speed (the rough sea turns facets towards the sensor). Bounds are the spread of
    their tabulated values over 0–15 m/s, not values of this code."""
    th = np.array([0.0, 60.0, 80.0]) * DEG
    eps = {w: [float(backend.emissivity(t, 0.0, backend.cox_munk(w), M11)) for t in th] for w in (5.0, 15.0)}
    for w, (e0, e60, e80) in eps.items():
        assert 0.985 <= e0 <= 0.995
        assert 0.955 <= e60 <= 0.975
        assert 0.70 <= e80 <= 0.86
        assert e0 > e60 > e80
    assert eps[15.0][2] > eps[5.0][2] + 0.02


def test_upwind_view_has_higher_emissivity_than_crosswind_near_grazing(backend):
    """Cox & Munk 1954: the upwind mean-square slope exceeds the crosswind one (3.16e-3 W against
    0.003 + 1.92e-3 W: 0.047 vs 0.032 at 15 m/s). Looking along the upwind axis the slope spread
    along the line of sight is the larger, so near grazing more visible facets tilt towards the
    sensor (smaller local incidence angle): the emissivity is higher upwind than crosswind (the
    same mechanism that makes it grow with wind at large angles, Masuda 1988). With a sky colder
    than the sea the upwind view is therefore the warmer one. At nadir the view azimuth cannot
    matter. (An axis swap of the anisotropic law flips both inequalities.)"""
    s = backend.cox_munk(15.0, anisotropic=True)
    for th_deg in (75.0, 85.0):
        up = float(backend.emissivity(th_deg * DEG, 0.0, s, M11))
        cross = float(backend.emissivity(th_deg * DEG, math.pi / 2, s, M11))
        assert up > cross + 3e-3, (th_deg, up, cross)
    r_up = float(backend.apparent_radiance(85 * DEG, 0.0, s, M11, 30.0, smooth_sky))
    r_cross = float(backend.apparent_radiance(85 * DEG, math.pi / 2, s, M11, 30.0, smooth_sky))
    assert r_up > r_cross + 0.1
    e_up, e_cross = (float(backend.emissivity(0.0, ph, s, M11)) for ph in (0.0, math.pi / 2))
    assert abs(e_up - e_cross) < max(backend.rtol, 1e-9)


def test_segelstein_table_published_values_and_consistency_with_hale_querry():
    """Segelstein 1981 (refractiveindex.info page main/H2O/Segelstein), the row at 10.000 µm:
    n = 1.193164, k = 0.050791394. Both it and Hale & Querry 1973 measure liquid water: over
    8–12 µm they agree to |Δn| < 0.03 and |Δk| < 20 % of k, and both give a normal-incidence
    emissivity ≈ 0.99 at 10 µm (0.98982 for Hale & Querry, docs/physics.md §13)."""
    m = complex(rs.water_refractive_index(torch.tensor(10e-6, dtype=torch.float64), "segelstein"))
    assert abs(m.real - 1.193164) < 1e-9 and abs(m.imag - 0.050791394) < 1e-12
    lam = torch.linspace(8e-6, 12e-6, 81, dtype=torch.float64)
    seg = rs.water_refractive_index(lam, "segelstein")
    hq = rs.water_refractive_index(lam, "hale_querry")
    assert float((seg.real - hq.real).abs().max()) < 0.03
    assert float(((seg.imag - hq.imag).abs() / hq.imag).max()) < 0.2
    e0 = 1.0 - float(rs.fresnel_reflectance(1.0, m))
    assert 0.985 < e0 < 0.995
    wl, n, k = rs.optics.water_table("segelstein")
    assert wl[0] < 3e-6 and wl[-1] > 14e-6 and np.all(np.diff(wl) > 0) and np.all(k >= 0)


@pytest.mark.parametrize("w", [0.0, 3.0, 10.0, 25.0])
def test_cox_munk_1954_slope_variances(backend, w):
    """Cox & Munk 1954, clean surface (docs/physics.md §5): isotropic σ² = 0.003 + 5.12e-3 W split
    equally (the paper's Eq. 12); anisotropic upwind a² = 3.16e-3 W, crosswind b² = 0.003 +
    1.92e-3 W, uncorrelated. At 10 m/s σ² = 0.0542 (Cox & Munk's rms slope 0.23)."""

    def var(s):  # (a², b², r) of either implementation
        if hasattr(s, "var_upwind"):
            vals = [s.var_upwind, s.var_crosswind, s.corr]
        else:
            vals = [s.std_upwind**2, s.std_crosswind**2, s.corr]
        return [float(np.asarray(v.detach() if isinstance(v, torch.Tensor) else v)) for v in vals]

    a2, b2, r = var(backend.cox_munk(w))
    tol = max(backend.rtol, 1e-9)
    assert abs(a2 - (0.003 + 5.12e-3 * w) / 2) < tol * a2 and abs(b2 - a2) < tol * a2 and r == 0.0
    a2, b2, r = var(backend.cox_munk(w, anisotropic=True))
    assert abs(a2 - 3.16e-3 * w) <= tol * max(a2, 1e-12) and abs(b2 - (0.003 + 1.92e-3 * w)) < tol * b2 and r == 0.0
    if w == 10.0:
        assert abs(var(backend.cox_munk(w))[0] * 2 - 0.0542) < 1e-6


def test_slope_statistics_accessors_are_the_covariance_entries():
    """Σ = [[a², r a b], [r a b, b²]] (docs/physics.md §2): a, b, r given are returned, σ² = a² + b²."""
    s = rs.SlopeStatistics(torch.tensor(0.3, dtype=torch.float64), 0.1, -0.4)
    assert abs(float(s.std_upwind) - 0.3) < 1e-15 and abs(float(s.std_crosswind) - 0.1) < 1e-15
    assert abs(float(s.corr) + 0.4) < 1e-15 and abs(float(s.cov) + 0.4 * 0.03) < 1e-15
    assert abs(float(s.mean_square_slope) - 0.1) < 1e-15
    assert abs(rs.SlopeStatistics(0.2, 0.05, 0.5).corr - 0.5) < 1e-15  # plain floats
    assert rs.SlopeStatistics(0.0, 0.1).corr == 0.0 and float(rs.SlopeStatistics(torch.tensor(0.0), 0.1).corr) == 0.0


def test_invalid_slope_covariance_and_zero_response_raise():
    """cov² > a² b² is no covariance matrix (|r| > 1): ValueError naming ``cov``. A response that
    is zero over the whole band has no band radiance: ValueError naming ``response``."""
    with pytest.raises(ValueError, match="cov"):
        rs.SlopeStatistics.from_variances(0.01, 0.01, 0.0101)
    rs.SlopeStatistics.from_variances(0.01, 0.04, 0.0199)  # |r| = 0.995: valid
    with pytest.raises(ValueError, match="response"):
        rs.band_radiance(300.0, (8e-6, 12e-6), lambda lam: np.zeros_like(lam))
    with pytest.raises(ValueError, match="response"):
        rs.band_radiance(300.0, (8e-6, 12e-6), (np.array([13e-6, 14e-6]), np.array([1.0, 1.0])))


def test_band_index_in_mwir_is_the_planck_weighted_average():
    """docs/physics.md §6 / ``band_refractive_index``: over 3–5 µm the least-squares fit wants k < 0, so
    the Planck-weighted average (n̄, k̄) is returned; it reproduces the band-averaged reflectance to
    3e-4 at every angle. Over 8–12 µm the fit is returned, and beats the average 20-fold."""
    mw = complex(rs.band_refractive_index((3e-6, 5e-6), 290.0))
    avg = complex(rs.band_refractive_index((3e-6, 5e-6), 290.0, method="average"))
    assert abs(mw - avg) < 1e-12
    lw = complex(rs.band_refractive_index((8e-6, 12e-6), 290.0))
    assert abs(lw - complex(rs.band_refractive_index((8e-6, 12e-6), 290.0, method="average"))) > 1e-3


def test_lwir_band_index_is_the_least_squares_optimum():
    """``band_refractive_index`` (method "fit") is documented as the (n, k ≥ 0) whose Fresnel
    reflectance best fits the band-averaged ρ̄(θ) in least squares over 0–89.9°: moving n or k by
    ±1e-5 from it must not lower the sum of squared residuals (a point that is not the optimum,
    e.g. from a Newton step of the wrong size, has a gradient and fails)."""
    c = torch.cos(torch.deg2rad(torch.linspace(0.0, 89.9, 181, dtype=torch.float64)))
    target = rs.band_reflectance(c, (8e-6, 12e-6), 290.0)
    m = complex(rs.band_refractive_index((8e-6, 12e-6), 290.0))

    def sse(n: float, k: float) -> float:
        return float(((rs.fresnel_reflectance(c, (n, k)) - target) ** 2).sum())

    best = sse(m.real, m.imag)
    d = 1e-5
    for n, k in ((m.real + d, m.imag), (m.real - d, m.imag), (m.real, m.imag + d), (m.real, max(m.imag - d, 0.0))):
        assert sse(n, k) >= best * (1 - 1e-9), (n, k)


def _rotated(var_up: float, var_cross: float, cov: float, alpha: float) -> tuple[float, float, float]:
    """Σ' = R Σ Rᵀ for a rotation of the slope field by α (counter-clockwise)."""
    c, s = math.cos(alpha), math.sin(alpha)
    R = np.array([[c, -s], [s, c]])
    S = R @ np.array([[var_up, cov], [cov, var_cross]]) @ R.T
    return float(S[0, 0]), float(S[1, 1]), float(S[0, 1])


@pytest.mark.parametrize("law, view, alpha", [
    ((0.09, 0.01, 0.0), 0.3, 0.7),  # anisotropic Gaussian
    ((0.0, 0.04, 0.0), 0.0, math.pi / 4),  # a line law: slopes only across the view (s∥ ≡ 0)
])
def test_rotating_sea_and_view_together_changes_nothing(law, view, alpha):
    """Isotropy of space: rotating the slope law (Σ → R Σ Rᵀ) and the view azimuth by the same
    angle leaves ε̄ and R_a unchanged (the sky depends on zenith only). The second case is a
    degenerate law (r = −1 after the rotation) seen perpendicular to its line, where the model
    takes the across-view variance directly."""
    F = torch.float64
    s0 = rs.SlopeStatistics.from_variances(*(torch.tensor(v, dtype=F) for v in law))
    s1 = rs.SlopeStatistics.from_variances(*(torch.tensor(v, dtype=F) for v in _rotated(*law, alpha)))
    th = torch.tensor([40.0 * DEG, 80.0 * DEG, 88.0 * DEG], dtype=F)
    for fn in (lambda s, ph: rs.emissivity(th, ph, s, M10),
               lambda s, ph: rs.apparent_radiance(th, ph, s, M10, sea_radiance=30.0, sky=smooth_sky)):
        a = fn(s0, torch.tensor(view, dtype=F))
        b = fn(s1, torch.tensor(view + alpha, dtype=F))
        torch.testing.assert_close(a, b, rtol=1e-9, atol=0)


def test_cos_incidence_beyond_one_is_an_error(backend):
    """|cos i| ≤ 1: a cosine of 1.005 is no angle; every backend raises ValueError."""
    with pytest.raises(ValueError, match="cos_incidence"):
        backend.fresnel_reflectance(np.array(1.005), M10)


def test_flat_sea_is_fresnel_exactly(backend):
    """a = b = 0 (a flat sea, no quadrature): ε = 1 − ρ(θ̂) and R_a = ε R_B + ρ R_s(θ̂), with ρ from
    the Fresnel equations written here."""
    flat = backend.slopes(0.0, 0.0)
    for th_deg in (0.0, 50.0, 85.0):
        th = backend.roundtrip(th_deg * DEG)
        rho = 0.5 * sum(exact_fresnel(math.cos(float(th)), M10))
        eps = float(backend.emissivity(th_deg * DEG, 0.4, flat, M10))
        ra = float(backend.apparent_radiance(th_deg * DEG, 0.4, flat, M10, 30.0, smooth_sky))
        tol = max(backend.rtol, 1e-9)
        assert abs(eps - (1 - rho)) < tol
        assert abs(ra - ((1 - rho) * 30.0 + rho * smooth_sky(math.cos(float(th))))) < tol * 30.0

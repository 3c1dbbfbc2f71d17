"""The expectation (roughsea_torch.expectation): the apparent radiance R_a, the emissivity ε̄ and the
projected area D of a rough sea (the paper's Eqs. 5–10, ``docs/physics.md``), Smith's Λ, and the two
reflection terms T_s, T_ρ of Eq. 10.

1. Published numbers and closed forms, asserted of every backend (reference, torch64, torch32) where
   the function exists in both, else of the torch code. Each expected value is computed in the test
   from first principles (constants typed in, scipy quadrature, closed forms) or quoted from the
   literature; none is a value produced by this library.
2. Physics of the model, asserted identically of every backend. Facts come from the paper and
   ``docs/physics.md`` §13; none is a value produced by this code.
3. The torch model against the independent numpy reference, over the range the core issue names:
   wind 0–40 m/s, σ² down to 1e-6, θ̂ 0–89.99°, a/b up to 10, |r| up to 0.9, shadowing on and off.
   Every input is rounded to float32 first, so the reference sees exactly what both torch dtypes
   see; the reference values are computed once per module (the reference takes about a second
   each). Promised relative error: 1e-6 in float64, 1e-5 in float32. Then shifted slope laws, a
   tabulated LOWTRAN7 sky (PCHIP in the reference via scipy), one sky table per batch element,
   refractive indices other than 11 µm water, the two reflection integrals of Eq. 10 on their own,
   and the link between the facet density of Eq. A7 (``slope_pdf``) and the expectation the model
   actually computes (few cases: scipy nested quadrature takes seconds with a 39-node sky table).
4. Guarantees of the torch functions themselves: gradients, dtype, batching, errors.
5. Regressions for the failures found by ``pipelines/stability.py`` (issue 6); each test fails on
   the code before its fix:

   - float32 floored cos θ̂ at 1e-7 (float64 at 1e-12): at float32(π/2) and at the float32 angle
     below it (cos θ̂ = 7.5e-8) float32 and float64 disagreed by up to 30 % on a calm sea;
   - 2 asin(clamp(x)) had a NaN gradient at |x| = 1: a sea with one rms slope 0 seen across it near
     grazing gave NaN gradients in float32;
   - without shadowing (Eq. 7) the sky terms T_ρ, T_s ~ σ/cos θ̂ cancel in R_B (1 − T_ρ) + T_s:
     float32 was off by up to 1e-4 beyond 89.999°;
   - Planck's 1/expm1(x) had a NaN gradient for a cold body (x beyond the exponent range): the sky
     of a cold body here, the band radiance itself in ``test_radiometry.py``.
"""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
import torch

import roughsea_torch as rs
import roughsea_torch.reference as ref
from roughsea_torch.expectation import Quadrature

from conftest import DEG, M4, M10, M11, M12, exact_fresnel, smooth_sky


F32, F64 = torch.float32, torch.float64


# ------------------------------------------------------------------------------------------------
# 1. Published values and closed forms
# ------------------------------------------------------------------------------------------------
def smith_lambda_closed_form(theta: float, sigma_par: float) -> float:
    """Smith (1967): Λ(ν) = [e^{−ν²}/(ν √π) − erfc(ν)] / 2 with ν = cot θ̂ / (√2 σ∥)."""
    nu = 1.0 / math.tan(theta) / (math.sqrt(2.0) * sigma_par)
    return 0.5 * (math.exp(-nu * nu) / (nu * math.sqrt(math.pi)) - math.erfc(nu))


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


# ------------------------------------------------------------------------------------------------
# 2. Physics of the model, every backend
# ------------------------------------------------------------------------------------------------
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


# ------------------------------------------------------------------------------------------------
# 3. Against the numpy reference
# ------------------------------------------------------------------------------------------------
def f32(x: float) -> float:
    return float(np.float32(x))


# (view zenith [deg], view azimuth [rad], slopes (a², b², r a b) or ("cm", W, anisotropic), shadowing)
CASES = [
    (0.0, 0.0, ("cm", 0.0, False), True),
    (30.0, 0.5, ("cm", 5.0, False), True),
    (60.0, 1.0, ("cm", 10.0, True), True),
    (75.0, 2.0, ("cm", 20.0, True), True),
    (85.0, 0.0, ("cm", 40.0, True), True),
    (88.0, 1.2, ("cm", 40.0, False), True),
    (89.0, 0.0, ("cm", 0.0, True), True),
    (89.99, 0.7, ("cm", 10.0, False), True),
    (89.99, 1.57, ("cm", 40.0, True), True),
    (45.0, 0.3, ("iso", 1e-6), True),
    (89.0, 0.3, ("iso", 1e-6), True),
    (89.99, 0.3, ("iso", 1e-6), True),
    (50.0, 1.2, ("abr", 0.3, 0.03, 0.0), True),
    (80.0, 0.4, ("abr", 0.3, 0.03, 0.9), True),
    (89.9, 2.6, ("abr", 0.03, 0.3, -0.9), True),
    (20.0, 0.8, ("abr", 0.2, 0.1, 0.9), True),
    (0.0, 0.0, ("cm", 10.0, False), False),
    (60.0, 0.9, ("cm", 20.0, True), False),
    (85.0, 0.2, ("abr", 0.2, 0.1, -0.9), False),
    (89.99, 0.0, ("cm", 5.0, False), False),
]


def make_slopes(mod, spec):
    if spec[0] == "cm":
        return mod.SlopeStatistics.cox_munk(f32(spec[1]), anisotropic=spec[2])
    if spec[0] == "iso":
        s = f32(math.sqrt(spec[1] / 2))
        return mod.SlopeStatistics(s, s, 0.0)
    return mod.SlopeStatistics(f32(spec[1]), f32(spec[2]), f32(spec[3]))


def case_inputs(case):
    th_deg, ph, spec, sh = case
    return f32(math.radians(th_deg)), f32(ph), spec, sh


@pytest.fixture(scope="module")
def reference_values():
    out = []
    for case in CASES:
        th, ph, spec, sh = case_inputs(case)
        s = make_slopes(ref, spec)
        e = float(ref.emissivity(th, ph, s, M11, shadowing=sh))
        r = float(ref.apparent_radiance(th, ph, s, M11, sea_radiance=30.0, sky=smooth_sky, shadowing=sh))
        out.append((e, r))
    return out


@pytest.mark.parametrize("dtype, rtol", [(torch.float64, 1e-6), (torch.float32, 1e-5)], ids=["float64", "float32"])
def test_torch_matches_reference_over_the_model_range(reference_values, dtype, rtol):
    th = torch.tensor([case_inputs(c)[0] for c in CASES], dtype=dtype)
    ph = torch.tensor([case_inputs(c)[1] for c in CASES], dtype=dtype)
    worst = []
    for i, case in enumerate(CASES):
        _, _, spec, sh = case_inputs(case)
        s = make_slopes(rs, spec)
        s = rs.SlopeStatistics.from_variances(
            *(torch.as_tensor(v, dtype=torch.float64).to(dtype) for v in (s.var_upwind, s.var_crosswind, s.cov))
        )
        e = rs.emissivity(th[i], ph[i], s, M11, shadowing=sh)
        r = rs.apparent_radiance(th[i], ph[i], s, M11, sea_radiance=30.0, sky=smooth_sky, shadowing=sh)
        assert e.dtype == dtype and r.dtype == dtype
        e_ref, r_ref = reference_values[i]
        err_e = abs(float(e) - e_ref) / abs(e_ref)
        err_r = abs(float(r) - r_ref) / abs(r_ref)
        worst.append((max(err_e, err_r), case))
        assert err_e <= rtol, f"emissivity {case}: {float(e)!r} vs reference {e_ref!r} (rel {err_e:.2e})"
        assert err_r <= rtol, f"apparent radiance {case}: {float(r)!r} vs reference {r_ref!r} (rel {err_r:.2e})"


def test_batched_call_equals_per_case_reference(reference_values):
    """One batched float64 call over every isotropic shadowed case equals the reference case by case."""
    idx = [i for i, c in enumerate(CASES) if c[2][0] == "cm" and not c[2][2] and c[3]]
    th = torch.tensor([case_inputs(CASES[i])[0] for i in idx], dtype=torch.float64)
    ph = torch.tensor([case_inputs(CASES[i])[1] for i in idx], dtype=torch.float64)
    w = torch.tensor([f32(CASES[i][2][1]) for i in idx], dtype=torch.float64)
    r = rs.apparent_radiance(th, ph, rs.SlopeStatistics.cox_munk(w), M11, sea_radiance=30.0, sky=smooth_sky)
    expected = torch.tensor([reference_values[i][1] for i in idx], dtype=torch.float64)
    torch.testing.assert_close(r, expected, rtol=1e-6, atol=0.0)


# Shifted slope Gaussians (the unresolved part of the two-scale sea, docs/texture.md §5): (view zenith
# [deg], view azimuth [rad], (a, b, r), mean (upwind, crosswind), shadowing)
SHIFTED = [
    (60.0, 0.7, (0.12, 0.09, 0.2), (0.08, -0.03), True),
    (80.0, 0.0, (0.10, 0.10, 0.0), (-0.05, 0.0), True),
    (85.0, 2.0, (0.15, 0.06, 0.0), (0.1, 0.1), True),
    (89.0, 0.4, (0.08, 0.05, -0.5), (0.02, -0.04), True),
    (89.9, 1.2, (0.1, 0.1, 0.0), (-0.15, 0.05), True),
    (40.0, 0.3, (0.12, 0.09, 0.0), (0.2, 0.0), False),
    (75.0, 1.0, (0.05, 0.12, 0.3), (-0.06, 0.02), False),
]


@pytest.fixture(scope="module")
def shifted_reference():
    out = []
    for th_deg, ph, (a, b, r), mu, sh in SHIFTED:
        th, ph, mu = f32(math.radians(th_deg)), f32(ph), tuple(f32(m) for m in mu)
        s = ref.SlopeStatistics(f32(a), f32(b), f32(r))
        out.append((float(ref.projected_area(th, ph, s, shadowing=sh, slope_mean=mu)),
                    float(ref.emissivity(th, ph, s, M11, shadowing=sh, slope_mean=mu)),
                    float(ref.apparent_radiance(th, ph, s, M11, sea_radiance=30.0, sky=smooth_sky, shadowing=sh, slope_mean=mu))))
    return out


@pytest.mark.parametrize("dtype, rtol", [(torch.float64, 1e-6), (torch.float32, 2e-5)], ids=["float64", "float32"])
def test_shifted_slopes_match_reference(shifted_reference, dtype, rtol):
    """SlopeStatistics.shifted (torch) against slope_mean= (reference): D, ε̄ and R_a, views 40–89.9°,
    anisotropic and correlated laws, with and without shadowing."""
    for (th_deg, ph, (a, b, r), mu, sh), expected in zip(SHIFTED, shifted_reference):
        th = torch.tensor(f32(math.radians(th_deg)), dtype=dtype)
        phi = torch.tensor(f32(ph), dtype=dtype)
        s = rs.SlopeStatistics(torch.tensor(f32(a), dtype=dtype), torch.tensor(f32(b), dtype=dtype),
                               torch.tensor(f32(r), dtype=dtype))
        s = s.shifted(torch.tensor(f32(mu[0]), dtype=dtype), torch.tensor(f32(mu[1]), dtype=dtype))
        got = (rs.projected_area(th, phi, s, shadowing=sh), rs.emissivity(th, phi, s, M11, shadowing=sh),
               rs.apparent_radiance(th, phi, s, M11, sea_radiance=30.0, sky=smooth_sky, shadowing=sh))
        for name, g, e in zip(("D", "emissivity", "R_a"), got, expected):
            assert g.dtype == dtype
            assert abs(float(g) - e) <= rtol * abs(e), f"{name} {th_deg}° μ={mu} sh={sh}: {float(g)!r} vs {e!r}"


def t64(x: float) -> torch.Tensor:
    return torch.tensor(x, dtype=F64)


@pytest.fixture(scope="module")
def lowtran_skies():
    """Two shipped LOWTRAN7 skies on their common zenith nodes: (zenith, (2, Nz) radiance)."""
    a = rs.atmosphere.load_sky("tropical", dtype=F64)
    b = rs.atmosphere.load_sky("subarctic_winter", dtype=F64)
    assert torch.equal(a.zenith, b.zenith)
    return a.zenith.numpy(), np.stack([a.radiance.numpy(), b.radiance.numpy()])


# (view zenith [deg], view azimuth, wind [m/s], index, sea radiance): one per batched sky
LOWTRAN_CASES = [(62.0, 0.4, 8.0, M12, 31.0), (86.5, 1.1, 12.0, M12, 24.0)]


@pytest.fixture(scope="module")
def lowtran_reference(lowtran_skies):
    z, rad = lowtran_skies
    return [
        float(ref.apparent_radiance(th * DEG, ph, ref.SlopeStatistics.cox_munk(w, anisotropic=True), m, rb, (z, rad[i]), epsrel=1e-9))
        for i, (th, ph, w, m, rb) in enumerate(LOWTRAN_CASES)
    ]


def test_batched_lowtran_sky_and_another_index_match_reference(lowtran_skies, lowtran_reference):
    """One torch call with a (2, Nz) table (tropical, subarctic winter: skies 3× apart at zenith),
    per-element view, wind and sea radiance, index of 12 µm water: each element equals the
    reference with its own table. Tolerance 2e-5: the C¹ PCHIP sky limits the Gauss rules
    (README, "LOWTRAN skies": 6e-6 in float64)."""
    z, rad = lowtran_skies
    th = torch.tensor([c[0] * DEG for c in LOWTRAN_CASES], dtype=F64)
    ph = torch.tensor([c[1] for c in LOWTRAN_CASES], dtype=F64)
    w = torch.tensor([c[2] for c in LOWTRAN_CASES], dtype=F64)
    rb = torch.tensor([c[4] for c in LOWTRAN_CASES], dtype=F64)
    sky = rs.TabulatedSky(torch.tensor(z), torch.tensor(rad))
    got = rs.apparent_radiance(th, ph, rs.SlopeStatistics.cox_munk(w, anisotropic=True), M12, sea_radiance=rb, sky=sky)
    assert got.shape == (2,)
    np.testing.assert_allclose(got.numpy(), lowtran_reference, rtol=2e-5)
    # the two skies differ enough that swapping the batch rows would fail
    swapped = rs.TabulatedSky(torch.tensor(z), torch.tensor(rad[::-1].copy()))
    bad = rs.apparent_radiance(th, ph, rs.SlopeStatistics.cox_munk(w, anisotropic=True), M12, sea_radiance=rb, sky=swapped)
    assert np.all(np.abs(bad.numpy() / np.array(lowtran_reference) - 1) > 1e-3)


@pytest.fixture(scope="module")
def reflection_reference():
    """(T_s, 1 − T_ρ) of the reference: R_a with R_B = 0 is T_s; with R_B = 1 and a black sky it is
    1 − T_ρ (Eq. 10 is linear in R_B and R_s)."""
    s = ref.SlopeStatistics(0.25, 0.12, 0.4)
    th, ph = 84.0 * DEG, 0.8
    t_s = float(ref.apparent_radiance(th, ph, s, M4, 0.0, smooth_sky, epsrel=1e-9))
    one_minus = float(ref.apparent_radiance(th, ph, s, M4, 1.0, 0.0, epsrel=1e-9))
    return t_s, 1.0 - one_minus


@pytest.mark.parametrize("dtype, rtol", [(torch.float64, 1e-6), (torch.float32, 1e-5)])
def test_reflection_terms_match_reference(reflection_reference, dtype, rtol):
    """``reflection_terms`` (T_s, T_ρ) of a correlated anisotropic law at 84°, 4 µm water, against
    the reference's Eq. 10 split by linearity; and R_a = R_B (1 − T_ρ) + T_s."""
    t_s_ref, t_rho_ref = reflection_reference
    s = rs.SlopeStatistics(torch.tensor(0.25, dtype=dtype), 0.12, 0.4)
    th, ph = torch.tensor(84.0 * DEG, dtype=dtype), torch.tensor(0.8, dtype=dtype)
    t_s, t_rho = rs.reflection_terms(th, ph, s, M4, sky=smooth_sky)
    assert t_s.dtype == dtype and t_rho.dtype == dtype
    assert abs(float(t_s) / t_s_ref - 1) < rtol
    assert abs(float(t_rho) / t_rho_ref - 1) < rtol
    ra = rs.apparent_radiance(th, ph, s, M4, sea_radiance=27.0, sky=smooth_sky)
    assert abs(float(ra) - (27.0 * (1 - t_rho_ref) + t_s_ref)) < rtol * 27.0


def test_expectation_uses_the_density_of_eq_a7():
    """The model's emissivity equals Eq. 10 integrated as the paper writes it, over facet normals
    (θ, φ) with ``slope_pdf`` (Eq. A7) as the weight: ε̄ = ∫∫ p cos Ω/cos θ (1 − ρ(Ω)) H(cos Ω) /
    ∫∫ p cos Ω/cos θ H(cos Ω), for a correlated anisotropic law seen off its axes. This ties the
    density's sign of r and its axes to the slope-space expectation (a density with r of the
    wrong sign, or a and b swapped, changes ε̄ here by ~1e-3)."""
    a, b, r = 0.3, 0.1, 0.6
    s = rs.SlopeStatistics(t64(a), b, r)
    th_v, ph_v = 70.0 * DEG, 0.5
    n_t, n_p = 1500, 720
    # θ on a tan-graded grid to resolve the density's peak; midpoint rule in φ (periodic)
    u = (np.arange(n_t) + 0.5) / n_t
    tan_t = np.tan(u * 1.45)  # covers slopes up to tan(1.45) ≈ 8 (> 26 σ)
    th = np.arctan(tan_t)
    dth = 1.45 / n_t * np.cos(u * 1.45) ** -2 / (1 + tan_t**2)
    ph = (np.arange(n_p) + 0.5) * (2 * math.pi / n_p)
    TH, PH = np.meshgrid(th, ph, indexing="ij")
    p = rs.slope_pdf(torch.tensor(TH), torch.tensor(PH), s).numpy()
    cos_o = np.cos(TH) * math.cos(th_v) + np.sin(TH) * math.sin(th_v) * np.cos(PH - ph_v)
    w = p * np.clip(cos_o, 0, None) / np.cos(TH) * dth[:, None] * (2 * math.pi / n_p)
    e_facet = rs.fresnel_emissivity(torch.tensor(np.clip(cos_o, 0, 1)), M4).numpy()
    eps_paper = float((w * e_facet).sum() / w.sum())
    eps_model = float(rs.emissivity(t64(th_v), ph_v, s, M4))
    assert abs(eps_model - eps_paper) < 2e-5, (eps_model, eps_paper)
    flipped = float(rs.emissivity(t64(th_v), ph_v, rs.SlopeStatistics(t64(a), b, -r), M4))
    assert abs(flipped - eps_paper) > 5e-4  # the check above can tell the sign of r


def test_sea_hit_fraction_grows_towards_grazing():
    """Eq. 10 with reflected rays that meet the sea seeing R_B: T_ρ = ∫ f̂ ρ H(cos θ') is the
    reflectance towards the sky only, so T_ρ ≤ 1 − ε̄, with equality near nadir (every reflected
    ray reaches the sky) and a strict gap near grazing on a rough sea, where some rays point down.
    Two different integrals (sky disc vs visible half-plane) of the torch code, compared with
    each other and with the reference's emissivity."""
    for th_deg, wind, gap in ((10.0, 5.0, False), (88.0, 20.0, True)):  # at 10°, W = 5 the disc edge is 6σ out
        s = rs.SlopeStatistics.cox_munk(t64(wind))
        th = t64(th_deg * DEG)
        _, t_rho = rs.reflection_terms(th, 0.3, s, M4, sky=smooth_sky)
        eps = float(rs.emissivity(th, 0.3, s, M4))
        eps_ref = float(ref.emissivity(th_deg * DEG, 0.3, ref.SlopeStatistics.cox_munk(wind), M4))
        assert abs(eps - eps_ref) < 1e-6
        if gap:
            assert float(t_rho) < (1 - eps_ref) - 1e-3
        else:
            assert abs(float(t_rho) - (1 - eps_ref)) < 1e-6


# ------------------------------------------------------------------------------------------------
# 4. Guarantees of the torch functions: gradients, dtype, batching, errors
# ------------------------------------------------------------------------------------------------
SMALL = Quadrature(outer=8, inner=8, hermite=6, width=9.0)  # gradcheck differentiates the rule itself;
# a 9σ window keeps the kinks where nodes cross the window edge at φ(9) ≈ 1e-18


@pytest.mark.parametrize("shadowing", [True, False])
def test_gradcheck_apparent_radiance(shadowing):
    """Autograd against central finite differences, float64, w.r.t. angles, slopes, index, R_B."""
    th = torch.tensor([0.3, 1.2, 1.55], dtype=torch.float64, requires_grad=True)
    ph = torch.tensor([0.1, 0.9, 2.0], dtype=torch.float64, requires_grad=True)
    a = torch.tensor(0.2, dtype=torch.float64, requires_grad=True)
    b = torch.tensor(0.08, dtype=torch.float64, requires_grad=True)
    r = torch.tensor(0.4, dtype=torch.float64, requires_grad=True)
    n = torch.tensor(1.2, dtype=torch.float64, requires_grad=True)
    k = torch.tensor(0.06, dtype=torch.float64, requires_grad=True)
    rb = torch.tensor(30.0, dtype=torch.float64, requires_grad=True)

    def f(th, ph, a, b, r, n, k, rb):
        s = rs.SlopeStatistics(a, b, r)
        return rs.apparent_radiance(th, ph, s, (n, k), sea_radiance=rb, sky=smooth_sky, shadowing=shadowing, quadrature=SMALL)

    assert torch.autograd.gradcheck(f, (th, ph, a, b, r, n, k, rb), eps=1e-6, atol=1e-6, rtol=1e-4)


def test_gradcheck_emissivity_and_projected_area():
    th = torch.tensor([0.05, 0.8, 1.5], dtype=torch.float64, requires_grad=True)
    w = torch.tensor([3.0, 12.0, 30.0], dtype=torch.float64, requires_grad=True)

    def f(th, w):
        s = rs.SlopeStatistics.cox_munk(w, anisotropic=True)
        return (
            rs.emissivity(th, 0.4, s, M10, quadrature=SMALL),
            rs.projected_area(th, 0.4, s),
        )

    assert torch.autograd.gradcheck(f, (th, w), eps=1e-6, atol=1e-6, rtol=1e-4)


EXTREMES = [
    # (view zenith, view azimuth, slopes builder) at the edges of the model's range
    (0.0, 0.0, lambda w: rs.SlopeStatistics.cox_munk(w * 0.0, anisotropic=True)),  # nadir, W = 0: a = 0
    (math.pi / 2, 0.0, lambda w: rs.SlopeStatistics.cox_munk(w)),  # exactly horizontal LOS
    (89.99 * DEG, 0.0, lambda w: rs.SlopeStatistics.isotropic(1e-6 + 0 * w)),  # calm, grazing
    (89.99 * DEG, 1.0, lambda w: rs.SlopeStatistics(0.3 + 0 * w, 0.03 + 0 * w, 0.9)),  # steep anisotropy
    (1.0, 0.3, lambda w: rs.SlopeStatistics(0 * w, 0 * w, 0.0)),  # flat sea
    (89.99 * DEG, 0.5, lambda w: rs.SlopeStatistics.cox_munk(w * 4.0, anisotropic=True)),  # 40 m/s
]


@pytest.mark.parametrize("shadowing", [True, False])
@pytest.mark.parametrize("case", range(len(EXTREMES)))
def test_values_and_gradients_finite_at_extremes(dtype, shadowing, case):
    th0, ph0, build = EXTREMES[case]
    th = torch.tensor(th0, dtype=dtype, requires_grad=True)
    ph = torch.tensor(ph0, dtype=dtype, requires_grad=True)
    w = torch.tensor(10.0, dtype=dtype, requires_grad=True)
    t_sea = torch.tensor(290.0, dtype=dtype, requires_grad=True)
    with warnings.catch_warnings():  # W = 0 with a wind gradient asked for: cox_munk warns (not a derivative
        warnings.filterwarnings("ignore", "SlopeStatistics.cox_munk")  # on the wind axis); finite all the same
        s = build(w)
    rb = rs.band_radiance(t_sea)
    ra = rs.apparent_radiance(th, ph, s, M10, sea_radiance=rb, sky=smooth_sky, shadowing=shadowing)
    eps = rs.emissivity(th, ph, s, M10, shadowing=shadowing)
    assert torch.isfinite(ra) and torch.isfinite(eps)
    if shadowing:
        assert 0.0 < eps.item() <= 1.0
    grads = torch.autograd.grad(ra + eps, (th, ph, w, t_sea), allow_unused=True)
    for g in grads:
        assert g is None or torch.isfinite(g).all()


def test_gradient_wrt_wind_finite_at_zero_wind_anisotropic():
    """a² = 3.16e-3 W: off the wind axis (φ̂ = 0.7) the model depends on a² smoothly, so dR/dW exists at
    W = 0 (cox_munk warns all the same: on the axis it does not)."""
    w = torch.tensor(0.0, dtype=torch.float64, requires_grad=True)
    with pytest.warns(UserWarning, match="is not the derivative"):
        s = rs.SlopeStatistics.cox_munk(w, anisotropic=True)
    r = rs.apparent_radiance(1.4, 0.7, s, M10, sea_radiance=30.0, sky=smooth_sky)
    (g,) = torch.autograd.grad(r, w)
    assert torch.isfinite(g) and g != 0


def test_dtype_preserved_and_broadcast_shapes(dtype):
    th = torch.linspace(0.0, 1.5, 5, dtype=dtype)[:, None]  # (5, 1)
    w = torch.tensor([2.0, 8.0, 15.0], dtype=dtype)  # (3,)
    s = rs.SlopeStatistics.cox_munk(w)
    out = rs.apparent_radiance(th, 0.2, s, M10, sea_radiance=30.0, sky=smooth_sky)
    assert out.shape == (5, 3) and out.dtype == dtype
    assert rs.emissivity(th, 0.2, s, M10).shape == (5, 3)


def test_batched_equals_looped_and_chunking_does_not_change_results():
    th = torch.linspace(0.1, 1.56, 7, dtype=torch.float64)
    ph = torch.linspace(0.0, 3.0, 7, dtype=torch.float64)
    s = rs.SlopeStatistics(torch.tensor(0.2, dtype=torch.float64), 0.07, 0.3)
    batched = rs.apparent_radiance(th, ph, s, M10, sea_radiance=30.0, sky=smooth_sky)
    looped = torch.stack([rs.apparent_radiance(th[i], ph[i], s, M10, sea_radiance=30.0, sky=smooth_sky) for i in range(7)])
    torch.testing.assert_close(batched, looped, rtol=1e-13, atol=0)
    tiny_chunks = Quadrature.default(torch.float64).with_(chunk=2048)
    chunked = rs.apparent_radiance(th, ph, s, M10, sea_radiance=30.0, sky=smooth_sky, quadrature=tiny_chunks)
    torch.testing.assert_close(batched, chunked, rtol=1e-13, atol=0)


def test_empty_batch():
    out = rs.apparent_radiance(torch.zeros(0), 0.0, rs.SlopeStatistics.cox_munk(5.0), M10, sea_radiance=30.0, sky=smooth_sky)
    assert out.shape == (0,)


def test_inputs_not_modified_in_place():
    th = torch.tensor([0.5, 1.0])
    w = torch.tensor([5.0, 9.0])
    th0, w0 = th.clone(), w.clone()
    rs.apparent_radiance(th, 0.3, rs.SlopeStatistics.cox_munk(w), M10, sea_radiance=30.0, sky=smooth_sky)
    assert torch.equal(th, th0) and torch.equal(w, w0)


@pytest.mark.skipif(not torch.cuda.is_available(), reason="needs CUDA")
def test_cuda_matches_cpu(dtype):
    th = torch.linspace(0.0, 1.5707, 33, dtype=dtype)
    s_cpu = rs.SlopeStatistics.cox_munk(torch.tensor(12.0, dtype=dtype), anisotropic=True)
    s_gpu = rs.SlopeStatistics.cox_munk(torch.tensor(12.0, dtype=dtype, device="cuda"), anisotropic=True)
    cpu = rs.apparent_radiance(th, 0.4, s_cpu, M10, sea_radiance=30.0, sky=smooth_sky)
    gpu = rs.apparent_radiance(th.cuda(), 0.4, s_gpu, M10, sea_radiance=30.0, sky=smooth_sky)
    assert gpu.device.type == "cuda"
    torch.testing.assert_close(gpu.cpu(), cpu, rtol=1e-5 if dtype == torch.float32 else 1e-12, atol=0)


@pytest.mark.parametrize(
    "call, match",
    [
        (lambda: rs.apparent_radiance(0.3, 0.0, rs.SlopeStatistics.cox_munk(3.0), M10, sea_radiance=-1.0, sky=1.0), "sea_radiance"),
        (lambda: rs.apparent_radiance(0.3, 0.0, rs.SlopeStatistics.cox_munk(3.0), M10, sea_radiance=1.0, sky=None), "sky"),
        (lambda: rs.apparent_radiance(0.3, float("nan"), rs.SlopeStatistics.cox_munk(3.0), M10, sea_radiance=1.0, sky=1.0), "view_azimuth"),
        (lambda: rs.emissivity(0.3, 0.0, rs.SlopeStatistics.cox_munk(3.0), (1.2, -0.1)), "imaginary part"),
        (lambda: rs.emissivity(0.3, 0.0, "windy", M10), "slopes"),
    ],
)
def test_clear_errors(call, match):
    with pytest.raises(ValueError, match=match):
        call()


@pytest.mark.parametrize("th_deg", [75.0, 86.0])
def test_sky_masking_against_an_independent_slope_integral(th_deg):
    """apparent_radiance(sky_masking=True): Smith's G1 of the reflected ray on the sky term, the masked
    part seeing the sea, against a plain scipy integral over slopes written here (isotropic law,
    analytic sky); the masking's own effect is resolved to 1 %, and R_s ≡ R_B still gives R_B."""
    from scipy import integrate
    from scipy.special import erfc

    sig2, rb, m = 0.02, 30.0, 1.3 + 0.02j
    sky = lambda c: 10.0 + 20.0 * (1.0 - c) ** 6  # noqa: E731
    th = math.radians(th_deg)
    st, ct = math.sin(th), math.cos(th)

    def fresnel(c):
        root = np.sqrt(m * m - (1 - c * c) + 0j)
        return 0.5 * (abs((c - root) / (c + root)) ** 2 + abs((m * m * c - root) / (m * m * c + root)) ** 2)

    def g1(rx, ry, rz):
        mu = rz / (math.hypot(rx, ry) * math.sqrt(sig2))
        lam = (math.exp(-mu * mu / 2) / math.sqrt(2 * math.pi) - mu * 0.5 * erfc(mu / math.sqrt(2))) / mu
        return 1.0 / (1.0 + lam)

    def integrand(v, u, masking):
        t = ct + st * u
        if t <= 0:
            return 0.0
        nn = math.sqrt(1 + u * u + v * v)
        n = np.array([u, v, 1.0]) / nn  # the facet normal leans towards its slope: ∝ (s, 1)
        view = np.array([st, 0.0, ct])
        c = float(n @ view)
        r = 2 * c * n - view
        if r[2] <= 0:
            return 0.0
        w = math.exp(-(u * u + v * v) / (2 * sig2)) / (2 * math.pi * sig2) * t * fresnel(c) * (sky(r[2]) - rb)
        return w * (g1(*r) if masking else 1.0)

    L = 7 * math.sqrt(sig2)
    mu = ct / (st * math.sqrt(sig2))
    D = ct * 0.5 * erfc(-mu / math.sqrt(2)) + st * math.sqrt(sig2) * math.exp(-mu * mu / 2) / math.sqrt(2 * math.pi)
    ref = {}
    for masking in (False, True):
        val, _ = integrate.dblquad(lambda v, u: integrand(v, u, masking), -L, L, -L, L, epsabs=1e-10, epsrel=1e-9)
        ref[masking] = rb + val / D
    slopes = rs.SlopeStatistics.isotropic(2 * sig2)
    got = {mk: float(rs.apparent_radiance(torch.tensor(th, dtype=torch.float64), 0.0, slopes, m, sea_radiance=rb, sky=sky,
                                          sky_masking=mk)) for mk in (False, True)}
    assert abs(got[False] / ref[False] - 1) < 1e-6
    effect_ref, effect = ref[True] - ref[False], got[True] - got[False]
    assert abs(effect_ref) > 1e-4 * rb
    assert abs(effect / effect_ref - 1) < 0.01
    same = rs.apparent_radiance(torch.tensor(th, dtype=torch.float64), 0.0, slopes, m, sea_radiance=rb, sky=rb, sky_masking=True)
    assert abs(float(same) - rb) < 1e-12 * rb


# ------------------------------------------------------------------------------------------------
# 5. Regressions found by pipelines/stability.py (issue 6)
# ------------------------------------------------------------------------------------------------
def both_dtypes(th: float, ph: float, var: tuple[float, float, float], shadowing: bool = True, sky=smooth_sky):
    """(float32 result, float64 result at the same float32-held inputs) of ε̄ and R_a."""
    out = {}
    for dtype in (F32, F64):
        t = torch.tensor(th, dtype=F32).to(dtype)
        p = torch.tensor(ph, dtype=F32).to(dtype)
        s = rs.SlopeStatistics.from_variances(*(torch.tensor(v, dtype=F32).to(dtype) for v in var))
        e = rs.emissivity(t, p, s, M11, shadowing=shadowing)
        r = rs.apparent_radiance(t, p, s, M11, sea_radiance=30.0, sky=sky, shadowing=shadowing)
        out[dtype] = (float(e), float(r))
    return out[F32], out[F64]


@pytest.mark.parametrize("var", [(0.0, 0.0, 0.0), (5e-9, 5e-9, 0.0), (0.0, 0.003, 0.0)], ids=["flat", "sigma2=1e-8", "a=0"])
@pytest.mark.parametrize("below", [0, 1], ids=["float32(pi/2)", "next float32 below"])
def test_float32_agrees_with_float64_at_the_last_float32_angles(var, below):
    """cos θ̂ of these two float32 angles is −4.4e-8 and 7.5e-8; on a calm sea ε̄ ∝ cos θ̂, so the
    floor applied to cos θ̂ must be the same in both dtypes."""
    th = float(np.nextafter(np.float32(math.pi / 2), np.float32(0.0))) if below else float(np.float32(math.pi / 2))
    (e32, r32), (e64, r64) = both_dtypes(th, 0.0, var)
    assert abs(e32 - e64) <= 1e-5 * abs(e64)
    assert abs(r32 - r64) <= 1e-5 * abs(r64)


@pytest.mark.parametrize("theta_deg", [89.999, 89.9999])
def test_gradients_finite_viewing_across_a_one_axis_slope_law(dtype, theta_deg):
    """a = 0 seen at φ̂ = π/2: the ridge exits of the sky disc land on its edge, where asin(±1)'s
    derivative is infinite; the gradient must stay finite (the branch is clamped)."""
    th = torch.tensor(theta_deg * DEG, dtype=dtype, requires_grad=True)
    ph = torch.tensor(math.pi / 2, dtype=dtype, requires_grad=True)
    vx = torch.tensor(0.0, dtype=dtype, requires_grad=True)
    vy = torch.tensor(0.01, dtype=dtype, requires_grad=True)
    r = rs.apparent_radiance(th, ph, rs.SlopeStatistics.from_variances(vx, vy, 0.0), M11, sea_radiance=30.0, sky=smooth_sky)
    grads = torch.autograd.grad(r, (th, ph, vx, vy))
    assert torch.isfinite(r) and all(torch.isfinite(g) for g in grads)
    # and right, not merely finite: ∂R_a/∂b² against a float64 central difference
    def f(v: float) -> float:
        s64 = rs.SlopeStatistics.from_variances(torch.tensor(0.0, dtype=F64), torch.tensor(v, dtype=F64), 0.0)
        return float(rs.apparent_radiance(torch.tensor(float(th.detach()), dtype=F64), math.pi / 2, s64, M11, sea_radiance=30.0, sky=smooth_sky))

    fd = (f(0.01 + 1e-6) - f(0.01 - 1e-6)) / 2e-6
    assert abs(float(grads[3]) - fd) <= (1e-5 if dtype == F64 else 2e-3) * abs(fd)


@pytest.mark.parametrize("var", [(5e-9, 5e-9, 0.0), (5e-7, 5e-7, 0.0), (0.09, 9e-8, 0.0)], ids=["s2=1e-8", "s2=1e-6", "a/b=1000"])
@pytest.mark.parametrize("theta_deg", [89.9999, 89.99999, 90.0])
def test_no_shadowing_float32_matches_float64_near_grazing(var, theta_deg):
    """Eq. 7 near grazing: T_ρ and T_s/R_B grow like σ/cos θ̂ and cancel; float32 must still give
    float64's answer at the same inputs (they are combined in float64; it was 1e-5–1e-4 off).
    At 90° (cos θ̂ ≤ 0 in float32, Eq. 7 is 0/0) ε̄ is a limit computed with rounding ~1e-4 σ∥
    that depends on the rule, so only R_a is compared there."""
    (e32, r32), (e64, r64) = both_dtypes(theta_deg * DEG, 0.4, var, shadowing=False)
    assert abs(r32 - r64) <= 2e-6 * abs(r64)
    if theta_deg < 90.0:
        assert abs(e32 - e64) <= 2e-6 * abs(e64)


def test_cold_sky_gradients_finite(dtype):
    """A sky given as the band radiance of 3–30 K (deep-space cold): B underflows to 0, and the
    gradient with respect to the sky temperature must be 0 or finite, not NaN."""
    t_sky = torch.tensor([3.0, 10.0, 30.0], dtype=dtype, requires_grad=True)
    t_sea = torch.tensor(271.0, dtype=dtype, requires_grad=True)
    sky = rs.band_radiance(t_sky)
    r = rs.apparent_radiance(torch.tensor([0.3, 1.5, 1.5706], dtype=dtype), 0.2, rs.SlopeStatistics.cox_munk(5.0), M11,
                             sea_radiance=rs.band_radiance(t_sea), sky=sky)
    g_sky, g_sea = torch.autograd.grad(r.sum(), (t_sky, t_sea))
    assert torch.isfinite(r).all() and torch.isfinite(g_sky).all() and torch.isfinite(g_sea)
    assert bool((g_sky >= 0).all()) and float(g_sea) > 0  # a warmer sky or sea never darkens the sea


@pytest.mark.parametrize("slopes", [rs.SlopeStatistics.cox_munk(0.5), rs.SlopeStatistics.cox_munk(8.0, anisotropic=True),
                                    rs.SlopeStatistics(0.2, 0.05, 0.6)], ids=["calm", "cox_munk_8", "correlated"])
def test_sky_masking_float32_agrees_with_float64_to_grazing(slopes):
    """apparent_radiance(sky_masking=True) in float32 is the float64 value to the float32 target
    (1e-5, docs/accuracy.md §1), finite, at every view zenith up to 89.9° and every azimuth."""
    th = torch.linspace(0.0, 89.9, 60, dtype=torch.float64) * (math.pi / 180)
    ph = torch.linspace(0.0, 2 * math.pi, 13, dtype=torch.float64)
    TH, PH = torch.meshgrid(th, ph, indexing="ij")
    sky = lambda c: 10.0 + 20.0 * (1.0 - c) ** 6

    def ra(t, p):
        return rs.apparent_radiance(t, p, slopes, complex(1.2, 0.05), sea_radiance=30.0, sky=sky, sky_masking=True)

    r64, r32 = ra(TH, PH), ra(TH.float(), PH.float()).double()
    assert bool(torch.isfinite(r32).all())
    assert float(((r32 - r64) / r64).abs().max()) < 1e-5


@pytest.mark.parametrize("mean", [(0.0, 0.15), (-0.1, 0.08)])
def test_shifted_thin_ridge_is_within_the_float64_target_of_a_converged_rule(mean):
    """A thin slope law (a/b = 15) under a resolved wave's tilt μ (the two-scale sea of
    docs/texture.md §5): the default float64 rule is within its target, 1e-6 (docs/accuracy.md §1),
    of a converged rule (96/96/24 nodes: 7e-11 from 160/160/32) over every azimuth and θ̂ = 40–89°.
    This is where the sky integral's outer panel is split at the exits of the shifted Gaussian ridge
    (expectation._sky_panels); the default is within 4.6e-7 here."""
    th = torch.arange(40.0, 90.0, 1.0, dtype=torch.float64) * (math.pi / 180)
    ph = torch.arange(0.0, 360.0, 15.0, dtype=torch.float64) * (math.pi / 180)
    TH, PH = torch.meshgrid(th, ph, indexing="ij")
    slopes = rs.SlopeStatistics(0.3, 0.02, 0.0).shifted(*mean)
    sky = lambda c: 10.0 + 20.0 * (1.0 - c) ** 6

    def ra(q=None):
        return rs.apparent_radiance(TH, PH, slopes, complex(1.2, 0.05), sea_radiance=30.0, sky=sky, quadrature=q)

    converged = ra(rs.Quadrature(outer=96, inner=96, hermite=24))
    assert float(((ra() - converged) / converged).abs().max()) < 1e-6


def test_black_sky_is_the_affine_end_of_eq_10():
    """A constant sky of 0 (the lower end of the accepted range, float or tensor) is accepted, and Eq. 10
    is affine in the sky radiance: R_a(R_s = 0) = 2 R_a(R_s = c) − R_a(R_s = 2c). Under a black sky
    R_a ≥ ε̄ R_B, the emissivity times the sea's radiance: the reflected rays that meet the sea
    (cos θ' < 0) add ρ R_B; near nadir on a calm sea, where none does, R_a = ε̄ R_B."""
    th = torch.linspace(0.0, 89.0, 30, dtype=torch.float64) * (math.pi / 180)
    for slopes in (rs.SlopeStatistics.cox_munk(3.0), rs.SlopeStatistics(0.2, 0.1, 0.4)):

        def ra(sky, slopes=slopes):
            return rs.apparent_radiance(th, 0.7, slopes, complex(1.2, 0.05), sea_radiance=30.0, sky=sky)

        for black in (0.0, torch.tensor(0.0, dtype=torch.float64)):
            torch.testing.assert_close(ra(black), 2 * ra(12.0) - ra(24.0), rtol=1e-12, atol=0)
        eps = rs.emissivity(th, 0.7, slopes, complex(1.2, 0.05))
        assert bool((ra(0.0) >= 30.0 * eps * (1 - 1e-8)).all())  # two quadratures, each within 1e-8
        if slopes.corr == 0.0:  # 3 m/s: no facet steep enough to send a ray into the sea near nadir
            torch.testing.assert_close(ra(0.0)[:4], 30.0 * eps[:4], rtol=1e-8, atol=0)  # θ̂ ≤ 9°


@pytest.mark.parametrize("dtype", [torch.float32, torch.float64])
@pytest.mark.parametrize("shadowing", [True, "correlated"])
def test_mean_tilt_turning_every_facet_away_approaches_the_sea_radiance(dtype, shadowing):
    """A shifted mean slope that turns more and more of the facets away from a view at 87.4° (the outer nodes
    of a textured render's along-view slope: x = −4.5 σ_a at fine footprints). What stays visible is seen at
    grazing local incidence: its emission vanishes and its mirrored rays run on into the sea, so R_a → R_B
    (2 here) and ε̄ → 0, monotonically, with finite values and gradients all the way. Where the visible
    facets leave the quadrature's Gaussian window (±7.5σ in float64, ±6σ in float32) D of Eq. 5 underflows
    (float32 from a tilt of −1.5) and the correlated masking's D_Q is exactly 0: this was 0/0 = NaN, which the
    texture volume's spectral resampling spread over a whole image. The window's truncation itself makes
    R_a reach R_B early (at −0.7: 2.0 where a window reaching the visible facets gives 1.866): a known
    approximation, ≤ 1.2 mK in first-hit renders (``facets.visible_ratio``)."""
    th = torch.acos(torch.tensor(0.04466, dtype=dtype))
    zero = torch.tensor(0.0, dtype=dtype)
    prev_r, prev_e = -math.inf, math.inf
    for tilt in (-0.3, -0.5, -0.7, -1.5, -4.0):
        m = torch.tensor(tilt, dtype=dtype, requires_grad=True)
        st = rs.SlopeStatistics.from_variances(torch.tensor(0.00685, dtype=dtype), torch.tensor(0.0126, dtype=dtype),
                                               zero).shifted(m, zero)
        r = rs.apparent_radiance(th, zero, st, sea_radiance=2.0, sky=lambda mu: 1.5 + 0 * mu, shadowing=shadowing)
        eps = rs.emissivity(th, zero, st, shadowing=shadowing)
        (g,) = torch.autograd.grad(r, m)
        rv, ev = float(r.detach()), float(eps.detach())
        assert math.isfinite(rv) and math.isfinite(ev) and bool(torch.isfinite(g)), (tilt, rv, ev, g)
        assert prev_r - 1e-5 <= rv <= 2.0 + 1e-6 and -1e-6 <= ev <= prev_e + 1e-5, (tilt, rv, ev)
        prev_r, prev_e = rv, ev
    assert prev_r == pytest.approx(2.0, abs=5e-3) and prev_e == pytest.approx(0.0, abs=5e-3)

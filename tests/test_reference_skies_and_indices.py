"""The torch model against the independent numpy reference where ``test_agreement.py`` does not go:
a tabulated LOWTRAN7 sky (PCHIP in the reference via scipy), one sky table per batch element,
refractive indices other than 11 µm water, the two reflection integrals of Eq. 10 on their own,
band radiance with a spectral response, and the link between the facet density of Eq. A7
(``slope_pdf``) and the expectation the model actually computes.

The reference evaluations are slow (scipy nested quadrature, seconds each with a 39-node sky
table): few cases, computed once per module.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import torch

import roughsea_torch as rs
import roughsea_torch.reference as ref

from conftest import DEG, smooth_sky

F64 = torch.float64
M12 = 1.111 + 0.199j  # Hale & Querry, 12 µm (k four times the 11 µm value)
M4 = 1.351 + 0.0046j  # Hale & Querry, 4 µm (nearly transparent)


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


@pytest.mark.parametrize("band", [(8e-6, 12e-6), (3e-6, 5e-6)])
def test_band_radiance_with_response_matches_reference(band):
    """Band radiance and its inverse with a callable response, torch against the reference (scipy
    quad with its own Planck function)."""
    lo, hi = band
    resp = lambda lam: np.exp(-(((np.asarray(lam) - 0.5 * (lo + hi)) / (0.3 * (hi - lo))) ** 2))  # noqa: E731
    T = np.array([260.0, 290.0, 320.0])
    want = ref.band_radiance(T, band, resp)
    got = rs.band_radiance(torch.tensor(T), band, resp).numpy()
    np.testing.assert_allclose(got, want, rtol=1e-10)
    np.testing.assert_allclose(rs.brightness_temperature(torch.tensor(want), band, resp).numpy(), T, rtol=0, atol=1e-8)


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


def test_band_radiance_with_tabulated_response_matches_reference():
    """A response given as a table (interpolated linearly, 0 outside; its nodes are kinks): torch's
    panel-per-node Gauss rule against the reference's scipy quad with the nodes as breakpoints, and
    the two inverses against each other."""
    wl = np.array([7.6e-6, 8.4e-6, 9.9e-6, 11.1e-6, 12.4e-6])
    resp = np.array([0.0, 0.8, 1.0, 0.55, 0.0])
    band = (7.5e-6, 12.5e-6)
    T = np.array([255.0, 293.0, 318.0])
    want = ref.band_radiance(T, band, (wl, resp))
    np.testing.assert_allclose(rs.band_radiance(torch.tensor(T), band, (wl, resp)).numpy(), want, rtol=1e-10)
    np.testing.assert_allclose(ref.brightness_temperature(want, band, (wl, resp)), T, rtol=0, atol=1e-8)
    np.testing.assert_allclose(rs.brightness_temperature(torch.tensor(want), band, (wl, resp)).numpy(), T, rtol=0, atol=1e-8)

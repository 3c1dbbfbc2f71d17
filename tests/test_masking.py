"""The slope-conditioned masking (roughsea_torch.masking) and the expectation's ``shadowing="correlated"``.

1. The masking function itself: the reference's quadrature with the correlation switched off gives
   Smith's closed form 1/(1 + Λ) (typed in here from Smith 1967); the torch table against the
   numpy reference's direct quadrature; facets turned towards the sensor are masked less.
2. Physics of the option, asserted of every backend (reference, torch64, torch32): the second law;
   Eq. 5 recovered where masking vanishes (small slopes, θ̂ → 0); near grazing the emissivity rises
   (the facets seen face the sensor more steeply).
3. The torch option against the numpy reference (emissivity and Eq. 10 near grazing).
4. Guarantees of the torch code: finite values and gradients at grazing, on a calm sea and with steep
   anisotropy; batching; a ValueError naming ``shadowing``.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import torch

import roughsea_torch as rs
import roughsea_torch.reference as ref
from roughsea_torch import masking
from roughsea_torch.reference import masking as ref_masking

from conftest import DEG, M11, smooth_sky

pytestmark = pytest.mark.usefixtures("one_thread")
F64 = torch.float64


def smith_lambda_closed_form(nu: float) -> float:
    """Smith (1967): Λ = [e^{−v²}/(v √π) − erfc(v)] / 2, v = ν/√2 (ν = cot θ̂ / σ∥)."""
    v = nu / math.sqrt(2.0)
    return 0.5 * (math.exp(-v * v) / (v * math.sqrt(math.pi)) - math.erfc(v))


# ------------------------------------------------------------------------------------------------
# 1. The masking function
# ------------------------------------------------------------------------------------------------
@pytest.mark.parametrize("nu", [0.15, 0.8, 2.0])
def test_uncorrelated_reference_is_smith_closed_form(nu):
    """Without the correlation, S(x, ν) = 1/(1 + Λ(ν)) for every visible facet (Smith 1967), and the
    reference's Λ is Smith's closed form."""
    lam = smith_lambda_closed_form(nu)
    assert abs(ref_masking.smith_lambda(nu) - lam) < 1e-12
    for x in (-0.9 * nu, 0.0, 1.5):
        assert abs(ref_masking.masking(x, nu, correlated=False) - 1.0 / (1.0 + lam)) < 1e-7


POINTS = [(0.05, 0.01), (0.2, 0.1), (0.2, 1.3), (0.37, 3.0), (1.0, 0.5), (2.5, 0.1), (0.012, 7.0)]


def test_torch_table_matches_reference_quadrature():
    """Q(x, ν) of the torch table (bilinear in √(x + ν), ln ν) against the reference's scipy quadrature."""
    for nu, w in POINTS:
        expected = ref_masking.masking_ratio(w - nu, nu)
        got = masking.masking_ratio(torch.tensor(w - nu, dtype=F64), torch.tensor(nu, dtype=F64))
        assert abs(float(got) - expected) < 3e-4, (nu, w, float(got), expected)


def test_facets_turned_towards_the_sensor_are_masked_less():
    """S grows with the slope towards the sensor (reference) and Q does on the torch table; it is 0 for
    facets turned away."""
    nu = 0.3
    s = [ref_masking.masking(x, nu) for x in (-0.25, 0.0, 0.5, 2.0)]
    assert all(b > a for a, b in zip(s, s[1:]))
    assert ref_masking.masking(-0.31, nu) == 0.0
    x = torch.linspace(-nu + 1e-3, 5.0, 200, dtype=F64)
    q = masking.masking_ratio(x, torch.tensor(nu, dtype=F64))
    assert bool((q[1:] >= q[:-1]).all())
    assert float(masking.masking_ratio(torch.tensor(-0.4, dtype=F64), torch.tensor(nu, dtype=F64))) == 0.0


# ------------------------------------------------------------------------------------------------
# 2. Physics of the option, every backend
# ------------------------------------------------------------------------------------------------
@pytest.mark.parametrize("option", ["correlated", "multiscale"])
@pytest.mark.parametrize("th_deg", [75.0, 88.0, 90.0])
def test_second_law_with_masking_options(backend, th_deg, option):
    """R_s ≡ R_B ⇒ R_a = R_B whatever the facet weight (both masking options; the multi-scale one's
    tests are in tests/test_multiscale_masking.py)."""
    slopes = backend.slopes(0.2, 0.12, 0.3)
    ra = backend.apparent_radiance(th_deg * DEG, 0.4, slopes, M11, 27.5, 27.5, shadowing=option)
    np.testing.assert_allclose(ra, 27.5, rtol=max(backend.rtol, 1e-7) * 0.1)


@pytest.mark.parametrize("option", ["correlated", "multiscale"])
@pytest.mark.parametrize("th_deg, sigma", [(60.0, 0.02), (5.0, 0.2)])
def test_equals_eq5_where_masking_vanishes(backend, th_deg, sigma, option):
    """Small slopes or a near-vertical view: ν = cot θ̂ / σ∥ ≥ 8, no facet is masked (the multi-scale
    factor 1 − e^{−2ν(x+ν)} is 1 wherever the Gaussian has weight), Eq. 5 is recovered."""
    slopes = backend.slopes(sigma, 0.8 * sigma, 0.1)
    th = th_deg * DEG
    e5 = backend.emissivity(th, 0.3, slopes, M11, shadowing=True)
    ec = backend.emissivity(th, 0.3, slopes, M11, shadowing=option)
    np.testing.assert_allclose(ec, e5, rtol=max(backend.rtol, 1e-7))
    r5 = backend.apparent_radiance(th, 0.3, slopes, M11, 30.0, smooth_sky, shadowing=True)
    rc = backend.apparent_radiance(th, 0.3, slopes, M11, 30.0, smooth_sky, shadowing=option)
    np.testing.assert_allclose(rc, r5, rtol=max(backend.rtol, 1e-7))


def test_seen_facets_steeper_near_grazing(backend):
    """Near grazing the option weighs facets turned towards the sensor more: they see the sea at a
    larger cos Ω, so the emissivity rises (by ~1 % at 88°, σ∥ = 0.13), and not at all at nadir."""
    slopes = backend.cox_munk(5.0)
    e5 = backend.emissivity(88 * DEG, 0.0, slopes, M11, shadowing=True)
    ec = backend.emissivity(88 * DEG, 0.0, slopes, M11, shadowing="correlated")
    assert 0.003 < ec - e5 < 0.03


# ------------------------------------------------------------------------------------------------
# 3. Torch against the reference
# ------------------------------------------------------------------------------------------------
ZERO = (0.0, 0.0)
REF_CASES = {  # (view zenith [deg], φ̂, (a, b, r), mean slope); the correlated reference takes zero means only
    "correlated": ((85.0, 0.3, (0.15, 0.12, 0.1), ZERO), (88.0, 0.0, (0.2, 0.16, 0.0), ZERO)),
    "multiscale": ((85.0, 0.3, (0.15, 0.12, 0.1), ZERO), (88.0, 0.0, (0.2, 0.16, 0.0), ZERO),
                   (87.0, 1.0, (0.1, 0.12, 0.0), (0.03, -0.05)), (86.0, 0.2, (0.1, 0.08, 0.2), (-0.06, 0.01)),
                   (90.0, 0.5, (0.12, 0.1, 0.0), ZERO),
                   (87.0, 0.0, (0.1, 0.1, 0.0), (-0.1, 0.0))),  # the last: a tilt turning the mean plane away, ν = −0.48
}
RTOL = {"correlated": {torch.float64: 2e-5, torch.float32: 4e-5},  # (the correlated table's interpolation)
        "multiscale": {torch.float64: 2e-6, torch.float32: 4e-5}}


@pytest.fixture(scope="module", params=list(REF_CASES))
def reference_values(request):
    """(option, [(ε̄, R_a)]) of the numpy reference for that option's REF_CASES (computed once)."""
    option, out = request.param, []
    for th_deg, ph, (a, b, r), mean in REF_CASES[option]:
        s = ref.SlopeStatistics(a, b, r)
        kw = dict(shadowing=option, slope_mean=mean)
        out.append((float(ref.emissivity(th_deg * DEG, ph, s, M11, **kw)),
                    float(ref.apparent_radiance(th_deg * DEG, ph, s, M11, 30.0, smooth_sky, **kw))))
    return option, out


@pytest.mark.parametrize("dtype", [torch.float64, torch.float32])
def test_masking_options_match_reference(reference_values, dtype):
    """Both masked options against the numpy reference (the multi-scale one with shifted means too)."""
    option, values = reference_values
    rtol = RTOL[option][dtype]
    for (th_deg, ph, (a, b, r), mean), (e_ref, r_ref) in zip(REF_CASES[option], values):
        s = rs.SlopeStatistics(*(torch.tensor(v, dtype=dtype) for v in (a, b, r)))
        if mean != ZERO:
            s = s.shifted(*mean)
        t = torch.tensor(th_deg * DEG, dtype=dtype)
        e = float(rs.emissivity(t, ph, s, M11, shadowing=option))
        ra = float(rs.apparent_radiance(t, ph, s, M11, sea_radiance=30.0, sky=smooth_sky, shadowing=option))
        assert abs(e / e_ref - 1.0) < rtol, (th_deg, e, e_ref)
        assert abs(ra / r_ref - 1.0) < rtol, (th_deg, ra, r_ref)


# ------------------------------------------------------------------------------------------------
# 4. Guarantees of the torch code
# ------------------------------------------------------------------------------------------------
EXTREMES = {
    "grazing": (89.99, (0.2, 0.15, 0.0)),
    "horizon": (90.0, (0.2, 0.15, 0.0)),
    "calm": (88.0, (1e-6, 1e-6, 0.0)),
    "steep_anisotropy": (87.0, (0.4, 0.04, 0.9)),
}


@pytest.mark.parametrize("case", list(EXTREMES))
def test_values_and_gradients_finite_at_extremes(dtype, case):
    th_deg, (a, b, r) = EXTREMES[case]
    th = torch.tensor([th_deg * DEG, 80 * DEG], dtype=dtype, requires_grad=True)
    ab = torch.tensor([a, b], dtype=dtype, requires_grad=True)
    s = rs.SlopeStatistics(ab[0], ab[1], torch.tensor(r, dtype=dtype))
    rb = torch.tensor(30.0, dtype=dtype, requires_grad=True)
    ra = rs.apparent_radiance(th, 0.2, s, M11, sea_radiance=rb, sky=smooth_sky, shadowing="correlated")
    eps = rs.emissivity(th, 0.2, s, M11, shadowing="correlated")
    assert ra.dtype == dtype and bool(torch.isfinite(ra).all()) and bool(torch.isfinite(eps).all())
    assert bool(((eps > 0) & (eps < 1)).all())
    (ra.sum() + eps.sum()).backward()
    for g in (th.grad, ab.grad, rb.grad):
        assert bool(torch.isfinite(g).all())


@pytest.mark.parametrize("option", ["correlated", "multiscale"])
def test_batched_equals_looped(option):
    th = torch.tensor([70.0, 85.0, 88.0], dtype=F64) * DEG
    w = torch.tensor([4.0, 9.0, 15.0], dtype=F64)
    s = rs.SlopeStatistics.cox_munk(w, anisotropic=True)
    batch = rs.apparent_radiance(th[:, None], 0.5, s, M11, sea_radiance=30.0, sky=smooth_sky, shadowing=option)
    for i in range(3):
        for j in range(3):
            one = rs.apparent_radiance(th[i], 0.5, rs.SlopeStatistics.cox_munk(w[j], anisotropic=True), M11,
                                       sea_radiance=30.0, sky=smooth_sky, shadowing=option)
            torch.testing.assert_close(batch[i, j], one, rtol=1e-12, atol=0)


@pytest.mark.parametrize("bad", ["wagner", "Correlated", None, 1, 0.5])
def test_bad_shadowing_is_a_value_error_naming_it(bad):
    s = rs.SlopeStatistics.cox_munk(5.0)
    with pytest.raises(ValueError, match="shadowing"):
        rs.emissivity(1.4, 0.0, s, M11, shadowing=bad)
    with pytest.raises(ValueError, match="shadowing"):
        rs.apparent_radiance(1.4, 0.0, s, M11, sea_radiance=30.0, sky=smooth_sky, shadowing=bad)
    with pytest.raises(ValueError, match="shadowing"):
        ref.emissivity(1.4, 0.0, ref.SlopeStatistics.cox_munk(5.0), M11, shadowing=bad)


def test_projected_area_refuses_correlated():
    """D_Q is a normalization, not a projected area: projected_area takes True/False only."""
    with pytest.raises(ValueError, match="shadowing"):
        rs.projected_area(1.4, 0.0, rs.SlopeStatistics.cox_munk(5.0), shadowing="correlated")
    with pytest.raises(ValueError, match="shadowing"):
        ref.projected_area(1.4, 0.0, ref.SlopeStatistics.cox_munk(5.0), shadowing="correlated")


def test_shipped_table_is_the_computed_one():
    """The correlated masking table ships with the package (``data/masking/masking_table.npz``, made by
    ``pipelines/make_masking_table.py``; computing it took ~10 s on every process's first correlated
    render): :func:`masking.masking_table` reads it, on the nodes the module defines, and three of its ν
    columns (the first, middle and last) equal a fresh computation of the integrals to 1e-9. A stale or
    damaged file (other nodes, other values) fails here. (The same float64 sums on another processor
    differ: 1.7e-10 between the AMD EPYC that wrote the file and an Intel Xeon, where the file's own
    machine gave 1e-12.)"""
    assert masking.TABLE_FILE.is_file()
    p, ln_nu, q = masking.masking_table()
    p0, ln0 = masking.table_nodes()
    assert torch.equal(p, p0) and torch.equal(ln_nu, ln0)
    cols = [0, ln_nu.numel() // 2, ln_nu.numel() - 1]
    _, _, fresh = masking.compute_masking_table(rows=cols)
    assert float((q[:, cols] - fresh).abs().max()) < 1e-9

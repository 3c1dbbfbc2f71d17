"""The multi-scale masking (roughsea_torch.multiscale_masking) and the expectation's ``shadowing="multiscale"``.

1. The derivation: a cascade of Smith stages (Eq. 5 for one small scale at a time, each about the tilt
   of the longer ones), computed here in plain numpy as a Markov chain on the along-view slope,
   converges to the closed-form density the package's factor Q gives; its normalization is the mean
   plane's projected area, cos θ̂ + sin θ̂ m∥, exactly.
2. Physics of the option, asserted of every backend (reference, torch64, torch32): near grazing the facets
   seen face the sensor more than Eq. 5's, so the emissivity rises, more than with the correlated masking
   (the second law, Eq. 5 where masking vanishes and batching are tests/test_masking.py's, for both options).
3. The torch option against the numpy reference (emissivity and Eq. 10, zero and shifted means, at
   the horizon, and a tilt that turns the mean plane away: the continuation below the ν floor).
4. Guarantees of the torch code: finite values and gradients at the extremes (grazing, horizon, calm
   sea, steep anisotropy, a resolved tilt turning the mean plane away), continuity through the
   horizon's limit, a ValueError naming ``shadowing``.
(Against the brute-force ray tracer: tests/test_raytrace.py and tests/renderer/test_hits.py.)
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import torch

import roughsea_torch as rs
import roughsea_torch.reference as ref
from roughsea_torch.facets import facet_geometry, prepare_inputs
from roughsea_torch.masking import masked_denominator
from roughsea_torch.multiscale_masking import multiscale_ratio

from conftest import DEG, M11, smooth_sky

pytestmark = pytest.mark.usefixtures("one_thread")
F64 = torch.float64


# ------------------------------------------------------------------------------------------------
# 1. The derivation
# ------------------------------------------------------------------------------------------------
def smith_cascade(nu: float, stages: int, step: float = 0.004) -> tuple[np.ndarray, np.ndarray]:
    """The visible along-view slope after ``stages`` Smith stages of variance 1/stages each (total 1):
    h = x + ν, the line of sight's slope plus the facet's, standardized; a ray meets a facet of the next
    scale in proportion to its projected area, h' ⁺ (Eq. 5 for that scale about the tilt h, normalized
    over the scale's Gaussian slopes). Plain numpy, on a grid of h. Returns (x, density)."""
    h = np.arange(step / 2, nu + 9.0, step)
    p = np.zeros_like(h)
    p[np.argmin(abs(h - nu))] = 1.0 / step
    v = 1.0 / stages
    kern = np.exp(-0.5 * (h[None, :] - h[:, None]) ** 2 / v) * h[None, :]  # from h[i] to h[j]
    kern /= kern.sum(1, keepdims=True)
    for _ in range(stages):
        p = p @ kern
    return h - nu, p / (p.sum() * step)


@pytest.mark.parametrize("nu", [0.25, 1.0, 2.5])
def test_cascade_of_smith_stages_converges_to_the_closed_form(nu):
    """The density of the seen slopes after many small Smith stages is φ(x) (x + ν) Q(x, ν) / ν with the
    package's Q (the moments to 1.5 %; 400 stages). One stage is Eq. 5 itself, whose mean slope differs by
    more than 5 % at ν ≤ 1 (near grazing; at ν = 2.5 the two agree): the test sees the cascade, and fails
    with Q ≡ 1 or a wrong exponent."""
    x, p = smith_cascade(nu, 400)
    q = multiscale_ratio(torch.as_tensor(x, dtype=F64), torch.tensor(nu, dtype=F64)).numpy()
    f = np.exp(-0.5 * x * x) / math.sqrt(2 * math.pi) * (x + nu) * q / nu
    dx = x[1] - x[0]
    assert abs(f.sum() * dx - 1.0) < 1e-3  # normalized: D_Q = the mean plane's projected area
    for k in (1, 2):
        m_chain, m_closed = (p * x**k).sum() * dx, (f * x**k).sum() * dx
        assert abs(m_chain - m_closed) < 0.015 * max(abs(m_closed), 0.1), (k, m_chain, m_closed)
    if nu <= 1.0:
        x1, p1 = smith_cascade(nu, 1)  # one stage: Eq. 5's visible slopes, φ(x)(x + ν)⁺ / D
        e1 = (p1 * x1).sum() * (x1[1] - x1[0])
        assert abs(e1 - (f * x).sum() * dx) > 0.05 * abs((f * x).sum() * dx)


@pytest.mark.parametrize("dtype, rtol", [(torch.float64, 1e-9), (torch.float32, 2e-5)])
@pytest.mark.parametrize("th_deg, ph, mean", [(60.0, 0.3, (0.0, 0.0)), (85.0, 1.2, (0.0, 0.0)),
                                              (88.0, 0.0, (0.04, -0.02)), (89.5, 0.7, (-0.01, 0.03)),
                                              (30.0, 2.0, (0.2, 0.1))])
def test_normalization_is_the_mean_planes_projected_area(dtype, rtol, th_deg, ph, mean):
    """D_Q = ∫ N t Q H(t) ds = cos θ̂ + sin θ̂ m∥ (every ray meets the surface once), by the expectation's own
    quadrature; Eq. 5's D = t(m)(1 + Λ) is larger by Smith's Λ (0.5–2 near grazing)."""
    s = rs.SlopeStatistics.from_variances(torch.tensor(0.0126, dtype=dtype), torch.tensor(0.0158, dtype=dtype),
                                          torch.tensor(0.002, dtype=dtype)).shifted(*mean)
    th = torch.tensor(th_deg * DEG, dtype=dtype)
    _, _, vz, va, vx, vy, cxy, mx, my = prepare_inputs(th, torch.tensor(ph, dtype=dtype), s)
    g = facet_geometry(vz, va, vx, vy, cxy, mx, my)
    q = rs.Quadrature.default(dtype)
    d = float(masked_denominator(g, q.outer, q.width, "multiscale"))
    exact = math.cos(th_deg * DEG) + math.sin(th_deg * DEG) * (mean[0] * math.cos(ph) + mean[1] * math.sin(ph))
    assert abs(d / exact - 1.0) < rtol, (d, exact)


# ------------------------------------------------------------------------------------------------
# 2. Physics of the option, every backend
# ------------------------------------------------------------------------------------------------
def test_seen_facets_face_the_sensor_more_near_grazing(backend):
    """Near grazing the short waves on the back of a long one are hidden: the facets seen are tilted
    towards the sensor, seen at larger cos Ω, so the emissivity rises above Eq. 5's (0.60 → 0.67 at 88°,
    5 m/s), more than the correlated masking's (0.61)."""
    slopes = backend.cox_munk(5.0)
    e5 = backend.emissivity(88 * DEG, 0.0, slopes, M11, shadowing=True)
    ec = backend.emissivity(88 * DEG, 0.0, slopes, M11, shadowing="correlated")
    em = backend.emissivity(88 * DEG, 0.0, slopes, M11, shadowing="multiscale")
    assert 0.03 < em - e5 < 0.15 and em > ec + 0.02, (e5, ec, em)


# ------------------------------------------------------------------------------------------------
# 4. Guarantees of the torch code
# ------------------------------------------------------------------------------------------------
EXTREMES = {
    "grazing": (89.99, (0.2, 0.15, 0.0), (0.0, 0.0)),
    "horizon": (90.0, (0.2, 0.15, 0.0), (0.0, 0.0)),
    "calm": (88.0, (1e-6, 1e-6, 0.0), (0.0, 0.0)),
    "steep_anisotropy": (87.0, (0.4, 0.04, 0.9), (0.0, 0.0)),
    "tilted_away": (87.0, (0.1, 0.1, 0.0), (-0.3, 0.0)),  # cot θ̂ + m∥ < 0: the mean plane turned away
}


@pytest.mark.parametrize("case", list(EXTREMES))
def test_values_and_gradients_finite_at_extremes(dtype, case):
    th_deg, (a, b, r), mean = EXTREMES[case]
    th = torch.tensor([th_deg * DEG, 80 * DEG], dtype=dtype, requires_grad=True)
    ab = torch.tensor([a, b], dtype=dtype, requires_grad=True)
    mu = torch.tensor(mean, dtype=dtype, requires_grad=True)
    s = rs.SlopeStatistics(ab[0], ab[1], torch.tensor(r, dtype=dtype)).shifted(mu[0], mu[1])
    rb = torch.tensor(30.0, dtype=dtype, requires_grad=True)
    ra = rs.apparent_radiance(th, 0.0, s, M11, sea_radiance=rb, sky=smooth_sky, shadowing="multiscale")
    eps = rs.emissivity(th, 0.0, s, M11, shadowing="multiscale")
    assert ra.dtype == dtype and bool(torch.isfinite(ra).all()) and bool(torch.isfinite(eps).all())
    assert bool(((eps >= 0) & (eps < 1)).all())
    (ra.sum() + eps.sum()).backward()
    for g in (th.grad, ab.grad, mu.grad, rb.grad):
        assert bool(torch.isfinite(g).all())


def test_continuous_through_the_horizon_limit():
    """ν = (cot θ̂ + m∥)/σ∥ passing through 0 (a view to the horizon, or a tilt turning the mean plane away):
    the radiance is continuous (the limit ν → 0⁺, density 2x²φ(x), continued), not a jump to R_B."""
    s0 = rs.SlopeStatistics.from_variances(torch.tensor(0.01, dtype=F64), torch.tensor(0.01, dtype=F64))
    th = torch.tensor(87.0 * DEG, dtype=F64)
    cot = 1.0 / math.tan(87.0 * DEG)
    vals = [float(rs.apparent_radiance(th, 0.0, s0.shifted(-cot + d, 0.0), M11, sea_radiance=30.0, sky=smooth_sky,
                                       shadowing="multiscale")) for d in (1e-4, 1e-6, -1e-6, -1e-4)]
    assert max(vals) - min(vals) < 1e-3 * 30.0, vals
    horizon = [float(rs.apparent_radiance(torch.tensor(t, dtype=F64), 0.3, s0, M11, sea_radiance=30.0, sky=smooth_sky,
                                          shadowing="multiscale")) for t in (math.pi / 2 - 1e-5, math.pi / 2)]
    assert abs(horizon[0] - horizon[1]) < 1e-4 * 30.0 and abs(horizon[1] - 30.0) > 0.1, horizon


@pytest.mark.parametrize("bad", ["multi-scale", "Multiscale", "smith"])
def test_bad_shadowing_is_a_value_error_naming_it(bad):
    s = rs.SlopeStatistics.cox_munk(5.0)
    with pytest.raises(ValueError, match="shadowing.*multiscale"):
        rs.apparent_radiance(1.4, 0.0, s, M11, sea_radiance=30.0, sky=smooth_sky, shadowing=bad)
    with pytest.raises(ValueError, match="shadowing"):
        ref.emissivity(1.4, 0.0, ref.SlopeStatistics.cox_munk(5.0), M11, shadowing=bad)
    with pytest.raises(ValueError, match="shadowing"):
        rs.projected_area(1.4, 0.0, s, shadowing="multiscale")

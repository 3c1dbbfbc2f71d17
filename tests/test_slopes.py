"""The slope law (roughsea_torch.slopes): Cox & Munk's variances, the covariance entries, the facet
density of Eqs. A7/A8, and the errors of an impossible law. Asserted of every backend where the
function exists in both."""

from __future__ import annotations

import math

import numpy as np
import pytest
import torch

import roughsea_torch as rs
from roughsea_torch.augmentation import RandomSeaBackground

from conftest import DEG


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


def test_invalid_slope_covariance_raises():
    """cov² > a² b² is no covariance matrix (|r| > 1): ValueError naming ``cov``."""
    with pytest.raises(ValueError, match="cov"):
        rs.SlopeStatistics.from_variances(0.01, 0.01, 0.0101)
    rs.SlopeStatistics.from_variances(0.01, 0.04, 0.0199)  # |r| = 0.995: valid


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
    "call, match",
    [
        (lambda: rs.SlopeStatistics.cox_munk(-1.0), "wind_speed"),
        (lambda: rs.SlopeStatistics(0.1, 0.1, -1.0), "corr"),
    ],
)
def test_clear_errors(call, match):
    with pytest.raises(ValueError, match=match):
        call()


def test_one_wind_range_everywhere():
    """The slope law, the scene, the wave field and the augmentations' draws accept the same winds,
    [0, 80] m/s (slopes.MAX_WIND_SPEED): the augmentation refused 40–80, cox_munk accepted 500."""
    from roughsea_torch.slopes import MAX_WIND_SPEED

    assert MAX_WIND_SPEED == rs.waves.MAX_WIND == 80.0
    for make in (lambda w: rs.SlopeStatistics.cox_munk(w), lambda w: rs.SeaScene(wind_speed=w, sea_temperature=290.0),
                 lambda w: RandomSeaBackground(wind_speed=(1.0, w))):
        make(60.0)
        with pytest.raises(ValueError, match=r"wind_speed must lie in \[0, 80\]"):
            make(90.0)


def _slope_moments(slopes: rs.SlopeStatistics) -> tuple[float, np.ndarray, np.ndarray]:
    """Mass, mean and covariance of the slopes s = tan θ (cos φ, sin φ) under slope_pdf(θ, φ),
    by a midpoint rule over (tan θ, φ) (dθ = ds / (1 + s²), out to |s| = 2, i.e. > 10 σ)."""
    n_s, n_phi, s_max = 1600, 720, 2.0
    s = (torch.arange(n_s, dtype=torch.float64) + 0.5) * (s_max / n_s)
    phi = (torch.arange(n_phi, dtype=torch.float64) + 0.5) * (2 * math.pi / n_phi)
    S, PH = torch.meshgrid(s, phi, indexing="ij")
    w = rs.slope_pdf(torch.atan(S), PH, slopes) / (1 + S * S) * (s_max / n_s) * (2 * math.pi / n_phi)
    sx, sy = S * torch.cos(PH), S * torch.sin(PH)
    mass = float(w.sum())
    mean = np.array([float((w * sx).sum()), float((w * sy).sum())]) / mass
    dx, dy = sx - mean[0], sy - mean[1]
    cov = np.array([[float((w * dx * dx).sum()), float((w * dx * dy).sum())],
                    [float((w * dx * dy).sum()), float((w * dy * dy).sum())]]) / mass
    return mass, mean, cov


@pytest.mark.parametrize("mean", [(0.05, -0.03), (-0.08, 0.0), (0.0, 0.06)])
def test_shifted_slope_pdf_has_the_mean_and_covariance_of_its_statistics(mean):
    """slope_pdf of N(s; μ, Σ): mass 1, mean slope μ, covariance Σ, for a correlated anisotropic Σ
    (the upwind and crosswind means each on their own and together)."""
    a, b, r = 0.2, 0.1, 0.3
    slopes = rs.SlopeStatistics(a, b, r).shifted(*mean)
    mass, m, cov = _slope_moments(slopes)
    assert abs(mass - 1.0) < 1e-5  # the midpoint rule: 3e-6
    np.testing.assert_allclose(m, mean, rtol=0, atol=1e-6)
    np.testing.assert_allclose(cov, [[a * a, r * a * b], [r * a * b, b * b]], rtol=0, atol=1e-6)

"""The slope law of roughsea_torch.slopes against its defining moments.

``SlopeStatistics.shifted`` gives the law N(s; μ, Σ) of the unresolved slopes under a resolved wave
(``docs/texture.md`` §5); ``slope_pdf`` is its density over facet-normal directions (θ, φ). The
numpy reference has no shifted law, so the shifted density is checked against what defines it: its
mass is 1, its mean slope is μ and its covariance is Σ.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import torch

import roughsea_torch as rs


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

"""roughsea_torch.expectation: options of the expectation (Eq. 5–10) not covered by the shared suite.

The shared suite (tests/test_published_values.py, tests/test_model_physics.py, tests/test_agreement.py)
checks the default model in both dtypes against the numpy reference; ``sky_masking`` (Smith's G1 of the
reflected ray, docs/physics.md "Masking of the reflected ray") has its float64 check in
tests/test_torch_core.py. Here: the masked model in float32.
"""

from __future__ import annotations

import math

import pytest
import torch

import roughsea_torch as rs


@pytest.mark.parametrize("slopes", [rs.SlopeStatistics.cox_munk(0.5), rs.SlopeStatistics.cox_munk(8.0, anisotropic=True),
                                    rs.SlopeStatistics(0.2, 0.05, 0.6)], ids=["calm", "cox_munk_8", "correlated"])
def test_sky_masking_float32_agrees_with_float64_to_grazing(slopes):
    """apparent_radiance(sky_masking=True) in float32 is the float64 value to the float32 target
    (1e-5, docs/accuracy.md §1), finite, at every view zenith up to 89.9° and every azimuth."""
    th = torch.linspace(0.0, 89.9, 60, dtype=torch.float64) * (math.pi / 180)
    ph = torch.linspace(0.0, 2 * math.pi, 13, dtype=torch.float64)
    TH, PH = torch.meshgrid(th, ph, indexing="ij")
    sky = lambda c: 10.0 + 20.0 * (1.0 - c) ** 6  # noqa: E731

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
    sky = lambda c: 10.0 + 20.0 * (1.0 - c) ** 6  # noqa: E731

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

        def ra(sky):
            return rs.apparent_radiance(th, 0.7, slopes, complex(1.2, 0.05), sea_radiance=30.0, sky=sky)

        for black in (0.0, torch.tensor(0.0, dtype=torch.float64)):
            torch.testing.assert_close(ra(black), 2 * ra(12.0) - ra(24.0), rtol=1e-12, atol=0)
        eps = rs.emissivity(th, 0.7, slopes, complex(1.2, 0.05))
        assert bool((ra(0.0) >= 30.0 * eps * (1 - 1e-8)).all())  # two quadratures, each within 1e-8
        if slopes.corr == 0.0:  # 3 m/s: no facet steep enough to send a ray into the sea near nadir
            torch.testing.assert_close(ra(0.0)[:4], 30.0 * eps[:4], rtol=1e-8, atol=0)  # θ̂ ≤ 9°

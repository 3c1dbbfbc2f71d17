"""Foam: whitecap law, measured foam emissivity, second law, mixture, torch vs reference, gradients."""

import math

import numpy as np
import pytest
import torch

from roughsea_torch import foam
from roughsea_torch.optics import fresnel_emissivity
from roughsea_torch.radiometry import LWIR, MWIR, band_radiance
from roughsea_torch.reference import foam as ref

DTYPES = [(torch.float64, 1e-10), (torch.float32, 1e-6)]


# -- whitecap coverage, Monahan & O'Muircheartaigh 1980 ----------------------------------------


@pytest.mark.parametrize(
    "u10, percent, digits",
    # Coverage in % as quoted, rounded, with the law: 0.99 % at 10 m/s, 3.9 % at 15 m/s,
    # 0.2 % at 6 m/s, 12 % at 21 m/s, 0.42 % at 7.8 m/s. Each is asserted to its printed digits
    # (half a unit of the last digit): a changed coefficient or exponent moves them.
    [(10.0, 0.99, 2), (15.0, 3.9, 1), (6.0, 0.2, 1), (21.0, 12.0, 0), (7.8, 0.42, 2)],
)
def test_whitecap_published_values(u10, percent, digits):
    w = foam.whitecap_fraction(torch.tensor(u10, dtype=torch.float64))
    assert abs(float(w) * 100 - percent) <= 0.5 * 10.0**-digits


def test_whitecap_zero_monotone_and_capped():
    u = torch.linspace(0.0, 60.0, 601, dtype=torch.float64)
    w = foam.whitecap_fraction(u)
    assert float(w[0]) == 0.0
    assert torch.all(torch.diff(w) >= 0)
    assert torch.all(torch.diff(w)[(u[:-1] > 0) & (u[1:] < 38.0)] > 0)  # strictly increasing below the cap
    assert float(w.max()) == 1.0
    cap = (1 / 3.84e-6) ** (1 / 3.41)
    assert float(foam.whitecap_fraction(cap * 0.999)) < 1.0 and float(foam.whitecap_fraction(cap * 1.001)) == 1.0


# -- foam emissivity, Niclòs et al. 2007 -------------------------------------------------------


@pytest.mark.parametrize("band", [LWIR, MWIR])
def test_foam_emissivity_measured_excess(band):
    """Foam minus foam-free emissivity: negligible at nadir and up to 45°, +0.04 at 65° (Niclòs 2007)."""
    th = torch.tensor([0.0, math.radians(30), math.radians(45), math.radians(65)], dtype=torch.float64)
    m = 1.218 + 0.0508j if band == LWIR else 1.351 + 0.0046j
    diff = foam.foam_emissivity(th, band) - fresnel_emissivity(torch.cos(th), m)
    np.testing.assert_allclose(diff.numpy(), [0.0, 0.0, 0.0, 0.04], atol=1e-12)


def test_foam_emissivity_values_and_angular_flattening():
    th = torch.tensor([0.0, math.radians(65), math.radians(85)], dtype=torch.float64)
    eps_f = foam.foam_emissivity(th, LWIR)
    eps_w = fresnel_emissivity(torch.cos(th), 1.218 + 0.0508j)
    assert float(eps_f[0]) == pytest.approx(0.98982, abs=5e-5)  # = water at nadir (docs/physics.md §13)
    assert float(eps_f[1]) == pytest.approx(float(eps_w[1]) + 0.04, abs=1e-12)
    assert float(eps_f[2] - eps_w[2]) == pytest.approx(0.08, abs=1e-12)  # extrapolated slope
    assert torch.all(eps_f >= eps_w) and torch.all(eps_f <= 1)
    # foam reduces the angular variation (Niclòs 2007)
    assert float(eps_f[0] - eps_f[1]) < float(eps_w[0] - eps_w[1])


def test_foam_emissivity_rejects_visible_band():
    with pytest.raises(ValueError, match="band"):
        foam.foam_emissivity(0.1, (0.4e-6, 0.7e-6))


# -- second law, hemispherical mean, mixture ---------------------------------------------------


@pytest.mark.parametrize("dtype, tol", DTYPES)
def test_second_law_sky_equals_sea(dtype, tol):
    rb = band_radiance(torch.tensor(293.0, dtype=dtype))
    th = torch.linspace(0, math.pi / 2, 19, dtype=dtype)
    e = foam.sky_hemispherical_mean(lambda mu: rb.expand(mu.shape), dtype=dtype)
    torch.testing.assert_close(e, rb, rtol=tol, atol=0)
    r = foam.foam_radiance(th, LWIR, rb, e)
    torch.testing.assert_close(r, rb.expand_as(r), rtol=tol, atol=0)
    assert r.dtype == dtype


def test_hemispherical_mean_exact_for_polynomials():
    # 2 ∫ μ^k μ dμ = 2/(k+2)
    for k in range(6):
        e = foam.sky_hemispherical_mean(lambda mu, k=k: mu**k, n=8, dtype=torch.float64)
        assert float(e) == pytest.approx(2.0 / (k + 2), rel=1e-14)
    assert float(foam.sky_hemispherical_mean(7.5)) == 7.5
    batched = foam.sky_hemispherical_mean(lambda mu: torch.stack([mu, 2 * mu]), dtype=torch.float64)
    np.testing.assert_allclose(batched.numpy(), [2 / 3, 4 / 3], rtol=1e-14)


@pytest.mark.parametrize("dtype", [torch.float32, torch.float64])
def test_mixture_end_points(dtype):
    g = torch.Generator().manual_seed(0)
    ra = torch.rand(5, generator=g, dtype=dtype) * 40
    rf = torch.rand(5, generator=g, dtype=dtype) * 40
    assert torch.equal(foam.with_foam(ra, 0.0, rf), ra)
    assert torch.equal(foam.with_foam(ra, 1.0, rf), rf)
    mid = foam.with_foam(ra, 0.25, rf)
    torch.testing.assert_close(mid, 0.75 * ra + 0.25 * rf)


# -- torch vs numpy reference ------------------------------------------------------------------


@pytest.mark.parametrize("dtype, tol", DTYPES)
def test_torch_matches_reference(dtype, tol):
    u = np.array([0.0, 0.5, 3.0, 7.0, 12.0, 25.0, 40.0])
    np.testing.assert_allclose(
        foam.whitecap_fraction(torch.tensor(u, dtype=dtype)).double().numpy(), ref.whitecap_fraction(u), rtol=tol
    )
    th = np.linspace(0, math.pi / 2, 37)
    for band in (LWIR, MWIR):
        np.testing.assert_allclose(
            foam.foam_emissivity(torch.tensor(th, dtype=dtype), band).double().numpy(),
            ref.foam_emissivity(th, band),
            rtol=tol, atol=tol,
        )
    sky = lambda mu: 11.0 + 20.0 * (1 - mu) ** 6 + 3.0 * np.exp(-5 * mu)  # noqa: E731
    tsky = lambda mu: 11.0 + 20.0 * (1 - mu) ** 6 + 3.0 * torch.exp(-5 * mu)  # noqa: E731
    e_ref = ref.sky_hemispherical_mean(sky)
    e = foam.sky_hemispherical_mean(tsky, dtype=dtype)
    assert float(e) == pytest.approx(e_ref, rel=tol)
    rb = 30.0
    r = foam.foam_radiance(torch.tensor(th, dtype=dtype), LWIR, torch.tensor(rb, dtype=dtype), e)
    np.testing.assert_allclose(r.double().numpy(), ref.foam_radiance(th, LWIR, rb, e_ref), rtol=tol)
    ra = np.linspace(5, 35, 37)
    f = np.linspace(0, 1, 37)
    np.testing.assert_allclose(
        foam.with_foam(torch.tensor(ra, dtype=dtype), torch.tensor(f, dtype=dtype), r).double().numpy(),
        ref.with_foam(ra, f, ref.foam_radiance(th, LWIR, rb, e_ref)),
        rtol=tol,
    )


# -- gradients ---------------------------------------------------------------------------------


def test_gradient_through_whitecap_fraction():
    def chain(u):
        f = foam.whitecap_fraction(u)
        rf = foam.foam_radiance(torch.tensor(1.2, dtype=torch.float64), LWIR, 30.0, 12.0)
        return foam.with_foam(torch.tensor(25.0, dtype=torch.float64), f, rf)

    for u0 in (3.0, 10.0, 20.0):
        u = torch.tensor(u0, dtype=torch.float64, requires_grad=True)
        (g,) = torch.autograd.grad(chain(u), u)
        h = 1e-3
        fd = (chain(torch.tensor(u0 + h, dtype=torch.float64)) - chain(torch.tensor(u0 - h, dtype=torch.float64))) / (2 * h)
        assert torch.isfinite(g) and float(g) != 0.0
        assert float(g) == pytest.approx(float(fd), rel=1e-6)
    u = torch.tensor(0.0, dtype=torch.float64, requires_grad=True)
    (g0,) = torch.autograd.grad(chain(u), u)
    assert float(g0) == 0.0


def test_gradcheck_foam_radiance():
    th = torch.tensor([0.2, 0.9, 1.3], dtype=torch.float64, requires_grad=True)
    rb = torch.tensor(30.0, dtype=torch.float64, requires_grad=True)
    es = torch.tensor(12.0, dtype=torch.float64, requires_grad=True)
    assert torch.autograd.gradcheck(lambda a, b, c: foam.foam_radiance(a, LWIR, b, c), (th, rb, es))


# -- errors ------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "call, name",
    [
        (lambda: foam.whitecap_fraction(-1.0), "wind_speed"),
        (lambda: foam.whitecap_fraction(float("nan")), "wind_speed"),
        (lambda: foam.whitecap_fraction(float("inf")), "wind_speed"),
        (lambda: foam.foam_emissivity(2.0, LWIR), "view_zenith"),
        (lambda: foam.foam_radiance(0.1, LWIR, -1.0, 10.0), "sea_radiance"),
        (lambda: foam.foam_radiance(0.1, LWIR, 10.0, float("nan")), "sky_irradiance_over_pi"),
        (lambda: foam.with_foam(10.0, 1.5, 10.0), "foam_fraction"),
        (lambda: foam.with_foam(-1.0, 0.5, 10.0), "apparent_radiance"),
        (lambda: foam.with_foam(1.0, 0.5, float("inf")), "foam_radiance"),
        (lambda: foam.sky_hemispherical_mean(lambda mu: mu, n=0), "n"),
        (lambda: foam.sky_hemispherical_mean(-3.0), "sky"),
    ],
)
def test_value_errors(call, name):
    with pytest.raises(ValueError, match=name):
        call()

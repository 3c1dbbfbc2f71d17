"""roughsea_torch.glitter: the number of glitter spots (Kac–Rice with the curvature moments), the spots'
weight spread, and the time-coherent glitter factor of mean 1."""

from __future__ import annotations

import math

import numpy as np
import pytest
import torch
from scipy import integrate

from roughsea_torch import glitter as G
from roughsea_torch.spectrum import elfouhaily_omnidirectional, elfouhaily_spreading

pytestmark = pytest.mark.usefixtures("one_thread")


def test_mean_abs_hessian_determinant_isotropic_closed_form():
    # isotropic: E a² = E b² = 3 m₄/8, E c² = E ab = m₄/8 → E|det H| = m₄/(2√3) (det = (m₄/4)(z² − Exp(1)))
    m4 = torch.tensor([1.0, 37.5, 2e3], dtype=torch.float64)
    got = G.mean_abs_hessian_determinant(3 * m4 / 8, 3 * m4 / 8, m4 / 8)
    torch.testing.assert_close(got, m4 / (2 * math.sqrt(3)), rtol=1e-12, atol=0)


@pytest.mark.parametrize("uu,cc,uc", [(105.8, 71.8, 29.6), (3.0, 0.5, 0.2), (1.0, 1.0, 0.05)])
def test_mean_abs_hessian_determinant_against_monte_carlo(uu, cc, uc):
    rng = np.random.default_rng(7)
    n = 2_000_000
    ab = rng.multivariate_normal([0.0, 0.0], [[uu, uc], [uc, cc]], size=n)
    c = rng.normal(0.0, math.sqrt(uc), size=n)
    d = np.abs(ab[:, 0] * ab[:, 1] - c * c)
    se = d.std() / math.sqrt(n)
    got = float(G.mean_abs_hessian_determinant(torch.tensor(uu, dtype=torch.float64), cc, uc))
    assert abs(got - d.mean()) < 4 * se, (got, d.mean(), se)


def test_curvature_moments_match_an_adaptive_quadrature_of_the_spectrum():
    wind, k_max = 8.0, 256.0

    def moment(fn):
        f = lambda lk: float(fn(math.exp(lk)))  # noqa: E731
        return integrate.quad(f, math.log(k_max) - 14.0, math.log(k_max), limit=400, epsabs=0, epsrel=1e-10)[0]

    def s(k):
        kt = torch.tensor(k, dtype=torch.float64)
        return elfouhaily_omnidirectional(kt, wind) * k, elfouhaily_spreading(kt, wind)  # S dk = S k d(ln k)

    uu = moment(lambda k: s(k)[0] * k ** 4 * (0.375 + 0.25 * s(k)[1]))
    cc = moment(lambda k: s(k)[0] * k ** 4 * (0.375 - 0.25 * s(k)[1]))
    m4 = moment(lambda k: s(k)[0] * k ** 4)
    m6 = moment(lambda k: s(k)[0] * k ** 6)
    got = G.curvature_moments(torch.tensor(wind, dtype=torch.float64), k_max=k_max)
    torch.testing.assert_close(got.uu, torch.tensor(uu, dtype=torch.float64), rtol=1e-6, atol=0)
    torch.testing.assert_close(got.cc, torch.tensor(cc, dtype=torch.float64), rtol=1e-6, atol=0)
    torch.testing.assert_close(got.uc, torch.tensor(m4 / 8, dtype=torch.float64), rtol=1e-6, atol=0)
    torch.testing.assert_close(got.third, torch.tensor(math.sqrt(5 * m6 / 16), dtype=torch.float64), rtol=1e-6, atol=0)
    # the upwind curvature exceeds the crosswind one (ECKV's Δ > 0)
    assert float(got.uu) > float(got.cc)


@pytest.mark.parametrize("count", [0.02, 0.7, 6.0, 400.0])
@pytest.mark.parametrize("spread", [1.0, 2.2])
def test_glitter_factor_has_mean_one_and_variance_spread_over_n(count, spread):
    # E g and E g² by Gauss–Hermite (exact for the log-normal's smooth integrand) against 1 and 1 + spread/N
    x, w = np.polynomial.hermite_e.hermegauss(160)
    w = w / w.sum()
    g = G.glitter_factor(torch.full((160,), count, dtype=torch.float64), torch.tensor(x), spread).numpy()
    if count >= 0.5:
        assert abs((w * g).sum() - 1.0) < 1e-10
        assert abs((w * g * g).sum() - (1.0 + spread / count)) < 1e-8 * (1.0 + spread / count)
    # by sampling the latent the renderer uses, over seeds and pixels (4M draws): the mean within 1e-3
    if count >= 6.0:
        z = torch.cat([G.glitter_latent(s, torch.arange(1_000_000), 0.3 * s) for s in range(4)])
        g = G.glitter_factor(torch.tensor(count, dtype=torch.float64), z, spread)
        assert abs(float(g.mean()) - 1.0) < 1e-3
        assert abs(float(g.var()) / (spread / count) - 1.0) < 0.02


def test_glitter_latent_is_standard_normal_reproducible_and_coherent_in_time():
    idx = torch.arange(1_000_000)
    z = G.glitter_latent(11, idx, 4.2, 0.175)
    assert abs(float(z.mean())) < 5e-3 and abs(float(z.std()) - 1.0) < 5e-3
    assert abs(float((z > 2.0).double().mean()) - 0.02275) < 1e-3  # the normal's tail
    assert abs(float((z[1:] * z[:-1]).mean())) < 5e-3  # neighbouring pixels independent
    assert torch.equal(z, G.glitter_latent(11, idx, 4.2, 0.175))
    extreme = G.glitter_latent(2 ** 63 - 1, idx, 1e9)  # the largest seed and time a scene accepts
    assert abs(float(extreme.mean())) < 5e-3 and abs(float(extreme.std()) - 1.0) < 5e-3
    assert not torch.equal(z, G.glitter_latent(12, idx, 4.2, 0.175))
    near = G.glitter_latent(11, idx, 4.2 + 0.005, 0.175)
    far = G.glitter_latent(11, idx, 4.2 + 0.5, 0.175)  # beyond two lattice steps
    assert float((z * near).mean()) > 0.99
    assert abs(float((z * far).mean())) < 5e-3
    # a pixel's factor changes continuously: no jump at the lattice's steps
    t = torch.linspace(0.0, 1.0, 2001, dtype=torch.float64)
    path = torch.stack([G.glitter_latent(3, torch.tensor([5]), float(ti)) for ti in t]).squeeze(1)
    assert float((path[1:] - path[:-1]).abs().max()) < 0.05


@pytest.mark.parametrize("dtype", [torch.float32, torch.float64])
def test_glitter_functions_follow_the_dtype_and_have_finite_gradients(dtype):
    n = torch.tensor([0.0, 1e-9, 0.3, 5.0, 1e8], dtype=dtype, requires_grad=True)
    z = torch.tensor([3.0, -2.0, 0.5, 6.0, -6.0], dtype=dtype)
    g = G.glitter_factor(n, z, 2.0)
    assert g.dtype == dtype and bool(torch.isfinite(g).all())
    (grad,) = torch.autograd.grad(g.sum(), n)
    assert bool(torch.isfinite(grad).all())
    wind = torch.tensor([2.0, 8.0, 30.0], dtype=dtype, requires_grad=True)
    m = G.curvature_moments(wind)
    e = G.mean_abs_hessian_determinant(m.uu, m.cc, m.uc)
    assert e.dtype == dtype
    (gw,) = torch.autograd.grad(e.sum(), wind)
    assert bool(torch.isfinite(gw).all())
    assert m.omega.dtype == dtype and bool((m.omega > 0).all())


def test_glitter_count_is_footprint_times_density_times_mean_abs_det():
    n = G.glitter_count(torch.tensor([8.0, 0.0]), 0.0125, 67.4)
    torch.testing.assert_close(n, torch.tensor([8.0 * 0.0125 * 67.4, 0.0]))


def test_glitter_spread_grows_as_the_cap_loosens():
    # the spots' weight spread diverges logarithmically without the cap: a smaller third derivative
    # (longer spots allowed) gives more spread; ≥ 1 always
    m = G.curvature_moments(torch.tensor(8.0, dtype=torch.float64))
    loose = G.CurvatureMoments(m.uu, m.cc, m.uc, m.third * 1e-4, m.omega)
    a, b = float(G.glitter_spread(m, 5e-3, 1.0)), float(G.glitter_spread(loose, 5e-3, 1.0))
    assert float(G.glitter_spread(m, 5e-3)) == pytest.approx(G.GLITTER_CLUSTERING * a, rel=1e-12)
    assert 1.0 < a < b


@pytest.mark.parametrize("call,match", [
    (lambda: G.glitter_factor(-1.0, 0.0), "count"),
    (lambda: G.glitter_factor(1.0, float("nan")), "latent"),
    (lambda: G.glitter_factor(1.0, 0.0, 0.5), "spread"),
    (lambda: G.glitter_latent(-1, torch.arange(3)), "seed"),
    (lambda: G.glitter_latent(1, torch.arange(3), 0.0, 0.0), "lifetime_s"),
    (lambda: G.glitter_latent(1, torch.arange(3.0)), "index"),
    (lambda: G.curvature_moments(0.0), "wind_speed"),
    (lambda: G.curvature_moments(8.0, k_max=0.5), "k_max"),
    (lambda: G.mean_abs_hessian_determinant(1.0, 1.0, 2.0), "positive definite"),
    (lambda: G.glitter_count(1.0, -0.1, 5.0), "footprint_area"),
    (lambda: G.glitter_spread(G.curvature_moments(8.0), 0.0), "ellipse_radius"),
])
def test_bad_input_raises_value_error_naming_the_argument(call, match):
    with pytest.raises(ValueError, match=match):
        call()


def test_default_hotspots_last_as_long_as_measured():
    """At the default step, a pixel's hotspots (latent above 2: its brightest 2 %) last 0.15–0.20 s
    on average, Schwering's (1991) measured MWIR hotspot lifetimes."""
    dt = 0.005
    t = torch.arange(0.0, 12.0, dt, dtype=torch.float64)
    z = G.glitter_latent(1, torch.arange(1000)[None, :], t[:, None], G.GLITTER_LIFETIME_S)  # (T, P)
    a = np.vstack([np.zeros((1, 1000)), (z > 2.0).numpy().astype(int), np.zeros((1, 1000))])
    edges = np.diff(a, axis=0)
    runs = (np.flatnonzero(edges.T.reshape(-1) == -1) - np.flatnonzero(edges.T.reshape(-1) == 1)) * dt
    assert runs.size > 1000
    assert 0.15 <= runs.mean() <= 0.20, runs.mean()

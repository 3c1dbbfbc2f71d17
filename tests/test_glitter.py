"""roughsea_torch.glitter: the number of glitter spots (Kac–Rice with the curvature moments), the spots'
weight spread, and the time-coherent glitter factor of mean 1."""

from __future__ import annotations

import functools
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
    # by sampling the latent the renderer uses, over seeds and scattered sea points (4M draws): the mean within 1e-3
    if count >= 6.0:
        z = _four_million_latents()
        g = G.glitter_factor(torch.tensor(count, dtype=torch.float64), z, spread)
        assert abs(float(g.mean()) - 1.0) < 1e-3
        assert abs(float(g.var()) / (spread / count) - 1.0) < 0.02


@functools.lru_cache(maxsize=1)
def _four_million_latents():
    return torch.cat([_scattered_latent(s, 1_000_000, 0.3 * s) for s in range(4)])


def _scattered_latent(seed, n, t, lifetime=G.GLITTER_LIFETIME_S):
    """The latent at n sea points scattered over a 20 km square with footprints of 1 cm to 1 m (log-
    uniform; nearly all pairs many footprints apart), at time t."""
    gen = torch.Generator().manual_seed(1000 + seed)
    x, y = (torch.rand(2, n, generator=gen, dtype=torch.float64) - 0.5) * 2e4
    fp = torch.exp(math.log(0.01) + math.log(100.0) * torch.rand(n, generator=gen, dtype=torch.float64))
    return G.glitter_latent(seed, x, y, fp, t, lifetime)


def test_glitter_latent_is_standard_normal_reproducible_and_coherent_in_time():
    z = _scattered_latent(11, 1_000_000, 4.2, 0.175)
    assert abs(float(z.mean())) < 5e-3 and abs(float(z.std()) - 1.0) < 5e-3
    for c, tail in ((2.0, 0.02275), (3.0, 0.00135)):  # the normal's tails
        assert abs(float((z > c).double().mean()) - tail) < 4 * math.sqrt(tail / 1e6)
    assert torch.equal(z, _scattered_latent(11, 1_000_000, 4.2, 0.175))
    gen = torch.Generator().manual_seed(5)
    x, y = (torch.rand(2, 1_000_000, generator=gen, dtype=torch.float64) - 0.5) * 2e4
    extreme = G.glitter_latent(2 ** 63 - 1, x * 500, y * 500, 1e-6, 1e9)  # the largest seed, coordinates and time
    assert abs(float(extreme.mean())) < 5e-3 and abs(float(extreme.std()) - 1.0) < 5e-3
    assert abs(float((z * _scattered_latent(12, 1_000_000, 4.2, 0.175)).mean())) < 5e-3  # another seed: independent
    near = _scattered_latent(11, 1_000_000, 4.2 + 0.005, 0.175)
    far = _scattered_latent(11, 1_000_000, 4.2 + 0.5, 0.175)  # beyond two lattice steps
    assert float((z * near).mean()) > 0.99
    assert abs(float((z * far).mean())) < 5e-3
    # a point's latent changes continuously: no jump at the lattice's steps in time
    t = torch.linspace(0.0, 1.0, 2001, dtype=torch.float64)
    path = G.glitter_latent(3, 12.3, -4.5, 0.07, t)
    assert float((path[1:] - path[:-1]).abs().max()) < 0.05


def test_glitter_latent_is_a_field_on_the_sea_at_the_footprint_scale():
    """z(x, y) at one footprint s: continuous in x, y and s (no jump at the cells' edges nor between
    the two levels blended about log₂ s); correlated between points a small fraction of s apart and
    independent beyond 4 s (the cells are between s/2 and 2s); N(0, 1) for any s, at a level boundary
    (s a power of 2) and between them."""
    s = 0.3
    xs = torch.linspace(-2.0, 2.0, 4001, dtype=torch.float64)  # 1 mm steps over 13 footprints
    line = G.glitter_latent(7, 100.0 + xs, 55.0 + 0.4 * xs, s)
    assert float((line[1:] - line[:-1]).abs().max()) < 0.05
    fps = torch.exp(torch.linspace(math.log(0.05), math.log(5.0), 4001, dtype=torch.float64))
    scale = G.glitter_latent(7, 100.0, 55.0, fps)
    assert float((scale[1:] - scale[:-1]).abs().max()) < 0.05
    gen = torch.Generator().manual_seed(2)
    x, y = (torch.rand(2, 500_000, generator=gen, dtype=torch.float64) - 0.5) * 2e4
    for fp in (0.25, 0.37, 1.0, 1.7):
        z = G.glitter_latent(9, x, y, fp, 1.3)
        assert abs(float(z.mean())) < 7e-3 and abs(float(z.std()) - 1.0) < 7e-3
        close = G.glitter_latent(9, x + 0.02 * fp, y - 0.02 * fp, fp, 1.3)
        apart = G.glitter_latent(9, x + 4.01 * fp, y, fp, 1.3)
        assert float((z * close).mean()) > 0.95
        assert abs(float((z * apart).mean())) < 7e-3


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
    (lambda: G.glitter_latent(-1, 0.0, 0.0, 1.0), "seed"),
    (lambda: G.glitter_latent(1, 0.0, 0.0, 1.0, 0.0, 0.0), "lifetime_s"),
    (lambda: G.glitter_latent(1, float("nan"), 0.0, 1.0), "x"),
    (lambda: G.glitter_latent(1, 0.0, 2e7, 1.0), "y"),
    (lambda: G.glitter_latent(1, 0.0, 0.0, 0.0), "footprint"),
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
    """At the default step, the hotspots of a sea point (latent above 2: its brightest 2 %) last
    0.15–0.20 s on average, Schwering's (1991) measured MWIR hotspot lifetimes; for points at level
    boundaries (one level, four nodes) and between them (two levels, eight nodes with their own phases)."""
    dt = 0.005
    t = torch.arange(0.0, 12.0, dt, dtype=torch.float64)
    gen = torch.Generator().manual_seed(3)
    x, y = (torch.rand(2, 1000, generator=gen, dtype=torch.float64) - 0.5) * 1e3
    fp = torch.tensor([0.5, 0.7] * 500, dtype=torch.float64)
    z = G.glitter_latent(1, x[None, :], y[None, :], fp[None, :], t[:, None], G.GLITTER_LIFETIME_S)  # (T, P)
    a = np.vstack([np.zeros((1, 1000)), (z > 2.0).numpy().astype(int), np.zeros((1, 1000))])
    edges = np.diff(a, axis=0)
    runs = (np.flatnonzero(edges.T.reshape(-1) == -1) - np.flatnonzero(edges.T.reshape(-1) == 1)) * dt
    assert runs.size > 1000
    assert 0.15 <= runs.mean() <= 0.20, runs.mean()

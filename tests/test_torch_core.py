"""Guarantees of the torch functions themselves: gradients, dtype/device, batching, errors, sky forms."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
import torch

import roughsea_torch as rs
from roughsea_torch.expectation import Quadrature

from conftest import DEG

M = 1.218 + 0.0508j
SMALL = Quadrature(outer=8, inner=8, hermite=6, width=9.0)  # gradcheck differentiates the rule itself;
# a 9σ window keeps the kinks where nodes cross the window edge at φ(9) ≈ 1e-18


def sky_t(c):
    return 11.0 + 19.0 * (1.0 - c) ** 8


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
        return rs.apparent_radiance(th, ph, s, (n, k), sea_radiance=rb, sky=sky_t, shadowing=shadowing, quadrature=SMALL)

    assert torch.autograd.gradcheck(f, (th, ph, a, b, r, n, k, rb), eps=1e-6, atol=1e-6, rtol=1e-4)


def test_gradcheck_emissivity_and_projected_area():
    th = torch.tensor([0.05, 0.8, 1.5], dtype=torch.float64, requires_grad=True)
    w = torch.tensor([3.0, 12.0, 30.0], dtype=torch.float64, requires_grad=True)

    def f(th, w):
        s = rs.SlopeStatistics.cox_munk(w, anisotropic=True)
        return (
            rs.emissivity(th, 0.4, s, M, quadrature=SMALL),
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


@pytest.mark.parametrize("dtype", [torch.float32, torch.float64])
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
    ra = rs.apparent_radiance(th, ph, s, M, sea_radiance=rb, sky=sky_t, shadowing=shadowing)
    eps = rs.emissivity(th, ph, s, M, shadowing=shadowing)
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
    r = rs.apparent_radiance(1.4, 0.7, s, M, sea_radiance=30.0, sky=sky_t)
    (g,) = torch.autograd.grad(r, w)
    assert torch.isfinite(g) and g != 0


@pytest.mark.parametrize("dtype", [torch.float32, torch.float64])
def test_dtype_preserved_and_broadcast_shapes(dtype):
    th = torch.linspace(0.0, 1.5, 5, dtype=dtype)[:, None]  # (5, 1)
    w = torch.tensor([2.0, 8.0, 15.0], dtype=dtype)  # (3,)
    s = rs.SlopeStatistics.cox_munk(w)
    out = rs.apparent_radiance(th, 0.2, s, M, sea_radiance=30.0, sky=sky_t)
    assert out.shape == (5, 3) and out.dtype == dtype
    assert rs.emissivity(th, 0.2, s, M).shape == (5, 3)


def test_batched_equals_looped_and_chunking_does_not_change_results():
    th = torch.linspace(0.1, 1.56, 7, dtype=torch.float64)
    ph = torch.linspace(0.0, 3.0, 7, dtype=torch.float64)
    s = rs.SlopeStatistics(torch.tensor(0.2, dtype=torch.float64), 0.07, 0.3)
    batched = rs.apparent_radiance(th, ph, s, M, sea_radiance=30.0, sky=sky_t)
    looped = torch.stack([rs.apparent_radiance(th[i], ph[i], s, M, sea_radiance=30.0, sky=sky_t) for i in range(7)])
    torch.testing.assert_close(batched, looped, rtol=1e-13, atol=0)
    tiny_chunks = Quadrature.default(torch.float64).with_(chunk=2048)
    chunked = rs.apparent_radiance(th, ph, s, M, sea_radiance=30.0, sky=sky_t, quadrature=tiny_chunks)
    torch.testing.assert_close(batched, chunked, rtol=1e-13, atol=0)


def test_empty_batch():
    out = rs.apparent_radiance(torch.zeros(0), 0.0, rs.SlopeStatistics.cox_munk(5.0), M, sea_radiance=30.0, sky=sky_t)
    assert out.shape == (0,)


def test_inputs_not_modified_in_place():
    th = torch.tensor([0.5, 1.0])
    w = torch.tensor([5.0, 9.0])
    th0, w0 = th.clone(), w.clone()
    rs.apparent_radiance(th, 0.3, rs.SlopeStatistics.cox_munk(w), M, sea_radiance=30.0, sky=sky_t)
    assert torch.equal(th, th0) and torch.equal(w, w0)


def test_mismatched_devices_raise():
    th = torch.tensor([0.5], device="meta")
    with pytest.raises(ValueError, match="mismatched devices"):
        rs.emissivity(th, torch.tensor([0.1]), rs.SlopeStatistics.cox_munk(5.0), M)


@pytest.mark.skipif(not torch.cuda.is_available(), reason="needs CUDA")
@pytest.mark.parametrize("dtype", [torch.float32, torch.float64])
def test_cuda_matches_cpu(dtype):
    th = torch.linspace(0.0, 1.5707, 33, dtype=dtype)
    s_cpu = rs.SlopeStatistics.cox_munk(torch.tensor(12.0, dtype=dtype), anisotropic=True)
    s_gpu = rs.SlopeStatistics.cox_munk(torch.tensor(12.0, dtype=dtype, device="cuda"), anisotropic=True)
    cpu = rs.apparent_radiance(th, 0.4, s_cpu, M, sea_radiance=30.0, sky=sky_t)
    gpu = rs.apparent_radiance(th.cuda(), 0.4, s_gpu, M, sea_radiance=30.0, sky=sky_t)
    assert gpu.device.type == "cuda"
    torch.testing.assert_close(gpu.cpu(), cpu, rtol=1e-5 if dtype == torch.float32 else 1e-12, atol=0)


@pytest.mark.parametrize(
    "call, match",
    [
        (lambda: rs.SlopeStatistics.cox_munk(-1.0), "wind_speed"),
        (lambda: rs.SlopeStatistics(0.1, 0.1, -1.0), "corr"),
        (lambda: rs.apparent_radiance(0.3, 0.0, rs.SlopeStatistics.cox_munk(3.0), M, sea_radiance=-1.0, sky=1.0), "sea_radiance"),
        (lambda: rs.apparent_radiance(0.3, 0.0, rs.SlopeStatistics.cox_munk(3.0), M, sea_radiance=1.0, sky=None), "sky"),
        (lambda: rs.apparent_radiance(0.3, float("nan"), rs.SlopeStatistics.cox_munk(3.0), M, sea_radiance=1.0, sky=1.0), "view_azimuth"),
        (lambda: rs.emissivity(0.3, 0.0, rs.SlopeStatistics.cox_munk(3.0), (1.2, -0.1)), "imaginary part"),
        (lambda: rs.emissivity(0.3, 0.0, "windy", M), "slopes"),
        (lambda: rs.band_radiance(300.0, (12.0, 8.0)), "band"),
        (lambda: rs.band_radiance(300.0, (8.0, 12.0)), "micrometres"),
        (lambda: rs.brightness_temperature(-3.0), "radiance"),
        (lambda: Quadrature(outer=0), "outer"),
        (lambda: rs.TabulatedSky([0.0, 0.5, 0.4], [1.0, 2.0, 3.0]), "ascending"),
    ],
)
def test_clear_errors(call, match):
    with pytest.raises(ValueError, match=match):
        call()


def test_sky_forms_agree():
    """Callable, (zenith, radiance) table and TabulatedSky give the same R_a; a constant sky equals
    the callable returning that constant; a batched table equals per-element calls."""
    zen = torch.linspace(0.0, math.pi / 2, 400, dtype=torch.float64)
    rad = sky_t(torch.cos(zen))
    th = torch.tensor([0.4, 1.3, 1.56], dtype=torch.float64)
    s = rs.SlopeStatistics.cox_munk(9.0)
    r_call = rs.apparent_radiance(th, 0.0, s, M, sea_radiance=30.0, sky=sky_t)
    r_tab = rs.apparent_radiance(th, 0.0, s, M, sea_radiance=30.0, sky=(zen, rad))
    torch.testing.assert_close(r_tab, r_call, rtol=2e-5, atol=0)  # table of 400 nodes vs exact
    r_const = rs.apparent_radiance(th, 0.0, s, M, sea_radiance=30.0, sky=12.0)
    r_const_fn = rs.apparent_radiance(th, 0.0, s, M, sea_radiance=30.0, sky=lambda c: 12.0 + 0.0 * c)
    torch.testing.assert_close(r_const, r_const_fn, rtol=1e-14, atol=0)
    batched = rs.TabulatedSky(zen, torch.stack([rad, rad * 0.8, rad * 1.1]))  # one table per θ̂
    r_b = rs.apparent_radiance(th, 0.0, s, M, sea_radiance=30.0, sky=batched)
    for i, f in enumerate((1.0, 0.8, 1.1)):
        one = rs.apparent_radiance(th[i], 0.0, s, M, sea_radiance=30.0, sky=(zen, rad * f))
        torch.testing.assert_close(r_b[i], one, rtol=1e-13, atol=0)
    per_state = rs.apparent_radiance(th, 0.0, s, M, sea_radiance=30.0, sky=torch.tensor([11.0, 12.0, 13.0], dtype=torch.float64))
    for i, c in enumerate((11.0, 12.0, 13.0)):
        torch.testing.assert_close(per_state[i], rs.apparent_radiance(th[i], 0.0, s, M, sea_radiance=30.0, sky=c), rtol=1e-13, atol=0)


def test_pchip_matches_scipy():
    from scipy.interpolate import PchipInterpolator

    rng = np.random.default_rng(3)
    zen = np.sort(rng.uniform(0, math.pi / 2, 12))
    rad = np.cumsum(rng.uniform(0.0, 3.0, 12)) + np.where(np.arange(12) == 6, -2.0, 0.0)  # a dip too
    q = np.linspace(zen[0], zen[-1], 777)
    expected = PchipInterpolator(zen, rad)(q)
    got = rs.TabulatedSky(torch.tensor(zen), torch.tensor(rad))(torch.cos(torch.tensor(q))).numpy()
    np.testing.assert_allclose(got, expected, rtol=1e-10, atol=1e-10)
    # the shipped LOWTRAN nodes (0.1 deg near the horizon, coarser above), queried at the nodes,
    # between them and from a batched table (the interval lookup is a bucket grid, not a search)
    sky = rs.atmosphere.load_sky("tropical", dtype=torch.float64)
    z = sky.zenith.numpy()
    qz = np.concatenate([z, 0.5 * (z[1:] + z[:-1]), rng.uniform(z[0], z[-1], 2000)])
    want = PchipInterpolator(z, sky.radiance.numpy())(qz)
    np.testing.assert_allclose(sky(torch.cos(torch.tensor(qz))).numpy(), want, rtol=1e-9)
    two = sky.with_radiance(torch.stack([sky.radiance, 0.5 * sky.radiance]))(torch.cos(torch.tensor(np.stack([qz, qz]))))
    np.testing.assert_allclose(two.numpy(), np.stack([want, 0.5 * want]), rtol=1e-9)
    # a table per leading element broadcast over a middle dim of the query: (2, 1, N) rows, (2, 3, Q)
    # queries (row i serves every query [i, j, :]; the lookup indexes each query's own row)
    rows = torch.stack([sky.radiance, 0.5 * sky.radiance])[:, None]
    qq = np.stack([np.stack([qz, qz[::-1], qz]), np.stack([qz[::-1], qz, qz])])
    got3 = sky.with_radiance(rows)(torch.cos(torch.tensor(qq))).numpy()
    for i, f in enumerate((1.0, 0.5)):
        for j in range(3):
            np.testing.assert_allclose(got3[i, j], f * PchipInterpolator(z, sky.radiance.numpy())(qq[i, j]), rtol=1e-9)


def test_band_radiance_matches_scipy_quad_with_a_tabulated_response():
    from scipy.integrate import quad

    from roughsea_torch.radiometry import _C1, _C2

    wl = np.array([7.5e-6, 8.5e-6, 10e-6, 11.5e-6, 12.5e-6])
    resp = np.array([0.0, 0.9, 1.0, 0.7, 0.0])

    def integrand(lam):
        return np.interp(lam, wl, resp) * _C1 / lam**5 / math.expm1(_C2 / (lam * 295.0))

    expected = quad(integrand, 7.5e-6, 12.5e-6, points=wl[1:-1], epsrel=1e-13, limit=200)[0]
    got = float(rs.band_radiance(torch.tensor(295.0, dtype=torch.float64), (7.5e-6, 12.5e-6), (wl, resp)))
    assert abs(got - expected) / expected < 1e-10


def test_brightness_temperature_gradient_is_inverse_slope():
    t = torch.tensor(287.0, dtype=torch.float64, requires_grad=True)
    L = rs.band_radiance(t)
    (dL,) = torch.autograd.grad(L, t)
    L2 = L.detach().requires_grad_(True)
    (dT,) = torch.autograd.grad(rs.brightness_temperature(L2), L2)
    assert abs(float(dT * dL) - 1.0) < 1e-10


def test_band_averaged_reflectance_differs_from_averaged_index():
    """docs/physics.md §6: averaging ρ over the band is not the same as ρ of the averaged (n, k)."""
    rho_band = float(rs.band_reflectance(1.0))
    rho_index = float(rs.fresnel_reflectance(1.0, rs.band_refractive_index(method="average")))
    assert rho_band > rho_index * 1.03
    assert abs(rho_band - rho_index) < 0.003


def test_water_index_interpolates_the_table():
    m = rs.water_refractive_index(torch.tensor([10e-6, 10.5e-6], dtype=torch.float64))
    assert abs(complex(m[0]) - (1.218 + 0.0508j)) < 1e-12
    from roughsea_torch.optics import water_table

    wl, n, k = water_table()
    i = int(np.searchsorted(wl, 10.5e-6))
    f = (10.5e-6 - wl[i - 1]) / (wl[i] - wl[i - 1])
    assert abs(m[1].real.item() - (n[i - 1] * (1 - f) + n[i] * f)) < 1e-12
    with pytest.raises(ValueError, match="wavelength"):
        rs.water_refractive_index(1e-6)


@pytest.mark.parametrize("band, tol", [((8e-6, 12e-6), 1.5e-4), ((3e-6, 5e-6), 3e-4)])
def test_band_refractive_index_fit_reproduces_band_averaged_reflectance(band, tol):
    """The default effective index reproduces the Planck-weighted band average of ρ(θ) at every
    angle far better than the paper's averaged (n, k) does in the LWIR (docs/physics.md §6)."""
    c = torch.cos(torch.deg2rad(torch.linspace(0.0, 89.5, 120, dtype=torch.float64)))
    target = rs.band_reflectance(c, band, 290.0)
    fit = (rs.fresnel_reflectance(c, rs.band_refractive_index(band, 290.0)) - target).abs().max()
    avg = (rs.fresnel_reflectance(c, rs.band_refractive_index(band, 290.0, method="average")) - target).abs().max()
    assert fit <= tol
    if band[0] == 8e-6:  # LWIR: the fit is what makes the difference
        assert avg > 20 * fit


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

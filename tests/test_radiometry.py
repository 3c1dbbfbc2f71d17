"""Radiometry (roughsea_torch.radiometry): Planck's law integrated over a band, with or without a
spectral response, and its inverse, the brightness temperature.

Published numbers and closed forms are asserted of every backend (reference, torch64, torch32): each
expected value is computed in the test from first principles (the CODATA constants typed in, scipy
quadrature, closed forms); none is a value produced by this library.

Brightness temperature: the per-pixel table lookup against the band-sum inversion, its errors, and the
band caches (bounded, and never keeping a response object alive). The reference inversion is
Newton's method on the band sum L(T) = Σ wᵢ B_λᵢ(T) in float64 (``_BrightnessTemperature``, the
branch used outside the table), which knows nothing of the table.

Regressions for failures found by ``pipelines/stability.py`` (issue 6), each failing on the code
before its fix: Planck's 1/expm1(x) had a NaN gradient for a cold body (x beyond the exponent range);
the brightness temperature's Newton branch divided by an underflowed dL/dT (NaN in float64 at the
smallest radiances, infinite gradients in float32), and its tabulated branch differentiated a
cancelling Hermite basis in float32 (dT/dL off by 4e-4).
"""

from __future__ import annotations

import gc
import math
import weakref

import numpy as np
import pytest
import torch

import roughsea_torch as rs
import roughsea_torch.reference as ref
from roughsea_torch import radiometry
from roughsea_torch.radiometry import _BrightnessTemperature, as_band, planck_radiance_derivative

from conftest import C, H, KB, planck_band


F32, F64 = torch.float32, torch.float64


BANDS = [(8e-6, 12e-6), (3e-6, 5e-6)]


# ------------------------------------------------------------------------------------------------
# Planck's law and the band radiance
# ------------------------------------------------------------------------------------------------
@pytest.mark.parametrize("band, T", [((8e-6, 12e-6), 300.0), ((8e-6, 12e-6), 250.0), ((3e-6, 5e-6), 290.0)])
def test_band_radiance_equals_planck_integrated_with_codata_constants(backend, band, T):
    """L(T) = ∫ B_λ(T) dλ: scipy quadrature of Planck's law with the CODATA constants typed in.
    A 300 K blackbody over 8–12 µm gives about 38.5 W m⁻² sr⁻¹ (a quarter of σT⁴/π) (and 1 % of it is about 0.6 K:
    a first radiation constant 1 % off fails here by 1e-2 against a 1e-6 tolerance)."""
    expected = planck_band(T, *band)
    if band == (8e-6, 12e-6) and T == 300.0:
        assert 38.0 < expected < 39.0  # order-of-magnitude sanity of the test's own integral
    got = float(backend.band_radiance(np.array(T), band))
    assert abs(got - expected) / expected < max(backend.rtol, 1e-7)


def test_spectral_planck_equals_closed_form(backend):
    """B_λ(T) at a few (λ, T) against 2hc²λ⁻⁵/(e^{hc/λkT} − 1) with the typed constants."""
    lam = np.array([4e-6, 10e-6, 11e-6, 12e-6])
    for T in (200.0, 300.0):
        expected = 2 * H * C * C / lam**5 / np.expm1(H * C / (lam * KB * T))
        np.testing.assert_allclose(backend.planck_radiance(lam, T), expected, rtol=max(backend.rtol, 1e-9))


def test_planck_and_brightness_temperature_round_trip(backend):
    """Band radiance is increasing in T and brightness_temperature inverts it."""
    temps = np.array([250.0, 273.15, 300.0, 310.0])
    for band in ((8e-6, 12e-6), (3e-6, 5e-6)):
        L = backend.band_radiance(temps, band)
        assert np.all(np.diff(L) > 0)
        np.testing.assert_allclose(backend.brightness_temperature(L, band), temps, rtol=1e-6)
    # Wien's displacement law: the spectral peak of a 300 K body sits at 2897.77 µm K / 300 K
    lam = np.linspace(9.0e-6, 10.3e-6, 1301)
    peak = lam[np.argmax(backend.planck_radiance(lam, 300.0))]
    assert abs(peak - 2.897771955e-3 / 300.0) < 2e-9


def test_band_radiance_matches_scipy_quad_with_a_tabulated_response():
    from scipy.integrate import quad

    from roughsea_torch.radiometry import BOLTZMANN_K, PLANCK_H, SPEED_OF_LIGHT

    C1 = 2.0 * PLANCK_H * SPEED_OF_LIGHT**2  # the radiation constants, from the public ones
    C2 = PLANCK_H * SPEED_OF_LIGHT / BOLTZMANN_K

    wl = np.array([7.5e-6, 8.5e-6, 10e-6, 11.5e-6, 12.5e-6])
    resp = np.array([0.0, 0.9, 1.0, 0.7, 0.0])

    def integrand(lam):
        return np.interp(lam, wl, resp) * C1 / lam**5 / math.expm1(C2 / (lam * 295.0))

    expected = quad(integrand, 7.5e-6, 12.5e-6, points=wl[1:-1], epsrel=1e-13, limit=200)[0]
    got = float(rs.band_radiance(torch.tensor(295.0, dtype=torch.float64), (7.5e-6, 12.5e-6), (wl, resp)))
    assert abs(got - expected) / expected < 1e-10


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


def test_zero_response_raises():
    """A response that is zero over the whole band has no band radiance: ValueError naming
    ``response``."""
    with pytest.raises(ValueError, match="response"):
        rs.band_radiance(300.0, (8e-6, 12e-6), lambda lam: np.zeros_like(lam))
    with pytest.raises(ValueError, match="response"):
        rs.band_radiance(300.0, (8e-6, 12e-6), (np.array([13e-6, 14e-6]), np.array([1.0, 1.0])))


@pytest.mark.parametrize(
    "call, match",
    [
        (lambda: rs.band_radiance(300.0, (12.0, 8.0)), "band"),
        (lambda: rs.band_radiance(300.0, (8.0, 12.0)), "micrometres"),
        (lambda: rs.band_radiance(300.0, (8000.0, 12000.0)), "nanometres"),
        (lambda: rs.brightness_temperature(-3.0), "radiance"),
    ],
)
def test_clear_errors(call, match):
    with pytest.raises(ValueError, match=match):
        call()


def test_planck_gradient_finite_for_a_cold_body():
    t = torch.tensor([1.0, 3.0, 10.0], dtype=F32, requires_grad=True)
    (g,) = torch.autograd.grad(rs.band_radiance(t).sum(), t)
    assert torch.isfinite(g).all() and bool((g >= 0).all())


# ------------------------------------------------------------------------------------------------
# The brightness temperature: the table lookup against the band-sum inversion
# ------------------------------------------------------------------------------------------------
def newton_bt(L: torch.Tensor, band) -> torch.Tensor:
    lam, w = as_band(band).nodes(F64, L.device)
    return _BrightnessTemperature.apply(L.double(), lam, w)


def band_sum_slope(T: torch.Tensor, band) -> torch.Tensor:
    lam, w = as_band(band).nodes(F64, T.device)
    return (planck_radiance_derivative(lam, T.double().unsqueeze(-1)) * w).sum(-1)


@pytest.mark.parametrize("band", BANDS, ids=["LWIR", "MWIR"])
def test_table_nodes_and_their_neighbourhood_equal_the_band_sum_inversion(band):
    """At the 0.25 K nodes the Hermite T(L) interpolates exactly, and within 1e-9 (relative) of a
    node both the value and the slope match to first order: 1e-12 K, every other node of 100–500 K
    (both table ends included)."""
    T = torch.arange(100.0, 500.0 + 0.125, 0.5, dtype=F64)
    L = rs.band_radiance(T, band)
    for scale in (1.0, 1.0 - 1e-9, 1.0 + 1e-9):
        Lq = (L * scale)[1:-1] if scale != 1.0 else L
        got = rs.brightness_temperature(Lq, band)
        want = newton_bt(Lq, band)
        assert float((got - want).abs().max()) < 1e-12 * 500, scale


@pytest.mark.parametrize("band", BANDS, ids=["LWIR", "MWIR"])
def test_between_nodes_matches_band_sum_inversion(band):
    """Between the nodes the Hermite error is O(h⁴): under 5e-9 K (LWIR) and 5e-8 K (MWIR) over sea and sky temperatures
    (200–500 K), growing towards the cold end of the table where T(L) bends most (1e-7 K LWIR,
    1.5e-6 K MWIR at 100 K). A radiance assigned to the wrong interval (the cubic of a
    neighbouring interval) is off by ~1e-3 K."""
    g = torch.Generator().manual_seed(0)
    T = torch.cat([torch.arange(100.125, 500.0, 0.25, dtype=F64), 100.0 + 400.0 * torch.rand(20000, generator=g, dtype=F64)])
    L = rs.band_radiance(T, band)
    err = (rs.brightness_temperature(L, band) - newton_bt(L, band)).abs()
    assert float(err[T >= 200.0].max()) < 5e-8
    assert float(err.max()) < 2e-6


@pytest.mark.parametrize("band", BANDS, ids=["LWIR", "MWIR"])
def test_gradient_is_the_inverse_band_sum_slope(band):
    """dT/dL = 1/(dL/dT), dL/dT = Σ wᵢ ∂B_λᵢ/∂T: exact at the nodes (1e-12), O(h³) between (1e-7)."""
    for T in (torch.arange(150.0, 450.0, 7.25, dtype=F64), torch.arange(150.1, 450.0, 7.3, dtype=F64)):
        L = rs.band_radiance(T, band).requires_grad_(True)
        (g,) = torch.autograd.grad(rs.brightness_temperature(L, band).sum(), L)
        rel = (g * band_sum_slope(T, band) - 1.0).abs().max()
        assert float(rel) < (1e-11 if float(T[0]) == 150.0 else 2e-6)
        slope = radiometry.band_radiance_slope(L.detach(), band)
        assert float((slope / band_sum_slope(T, band) - 1.0).abs().max()) < (1e-11 if float(T[0]) == 150.0 else 2e-6)


def test_brightness_temperature_gradient_is_inverse_slope():
    t = torch.tensor(287.0, dtype=torch.float64, requires_grad=True)
    L = rs.band_radiance(t)
    (dL,) = torch.autograd.grad(L, t)
    L2 = L.detach().requires_grad_(True)
    (dT,) = torch.autograd.grad(rs.brightness_temperature(L2), L2)
    assert abs(float(dT * dL) - 1.0) < 1e-10


def test_float32_lookup_matches_float64():
    """An image-sized float32 batch (shape kept) against the float64 result at the same inputs:
    within float32 rounding of T (3e-5 K at 300 K)."""
    T = torch.linspace(250.0, 320.0, 4 * 3 * 50, dtype=F64).reshape(4, 1, 3, 50)
    L32 = rs.band_radiance(T).float()
    got = rs.brightness_temperature(L32)
    assert got.shape == L32.shape and got.dtype == torch.float32
    want = newton_bt(L32.double(), (8e-6, 12e-6))
    assert float((got.double() - want).abs().max()) < 1e-4


def test_brightness_temperature_gradient_float32_matches_float64():
    """dT/dL in float32 equals float64's to 1e-5 over sea temperatures 270–310 K (the tabulated
    branch; it was 4e-4 off from differentiating a cancelling Hermite basis in float32)."""
    L64 = rs.band_radiance(torch.linspace(270.0, 310.0, 57, dtype=F64))
    grads = []
    for dtype in (F32, F64):
        L = L64.to(F32).to(dtype).requires_grad_(True)
        (g,) = torch.autograd.grad(rs.brightness_temperature(L).sum(), L)
        grads.append(g.double())
    torch.testing.assert_close(grads[0], grads[1], rtol=1e-5, atol=0)


def test_tabulated_response_and_table_edges():
    """A tabulated response: the lookup inverts its own band radiance; at and just beyond the table
    edges (100 K, 500 K) the Newton branch takes over continuously."""
    resp = (np.array([7.5e-6, 8.5e-6, 10e-6, 11.5e-6, 12.5e-6]), np.array([0.0, 0.9, 1.0, 0.7, 0.0]))
    band = rs.radiometry.SpectralBand(7.5e-6, 12.5e-6, resp)
    T = torch.tensor([99.9, 100.0, 100.1, 287.3, 499.9, 500.0, 500.1], dtype=F64)
    got = rs.brightness_temperature(rs.band_radiance(T, band), band)
    torch.testing.assert_close(got, T, rtol=0, atol=2e-6)


def test_brightness_temperature_of_the_smallest_radiances(dtype):
    """T_b(L) for L down to the smallest normal float: finite, increasing, with a finite positive
    gradient (the renderer clamps radiance to that value before converting)."""
    L = torch.tensor([torch.finfo(dtype).tiny, 1e-30, 1e-12, 1e-3], dtype=dtype, requires_grad=True)
    T = rs.brightness_temperature(L)
    (g,) = torch.autograd.grad(T.sum(), L)
    assert torch.isfinite(T).all() and bool((T[1:] > T[:-1]).all()) and bool((T > 0).all())
    assert torch.isfinite(g).all() and bool((g > 0).all())


def test_brightness_temperature_inverts_band_radiance_far_below_the_table():
    """The Newton branch (outside 100–500 K) in log space: T_b(L(T)) = T down to 2 K (float64)."""
    T = torch.tensor([2.0, 5.0, 20.0, 60.0, 99.0, 501.0, 3000.0], dtype=F64)
    torch.testing.assert_close(rs.brightness_temperature(rs.band_radiance(T)), T, rtol=1e-12, atol=0)


@pytest.mark.parametrize("bad", [-3.0, 0.0, float("nan"), float("inf")])
def test_nonpositive_radiance_raises_naming_radiance(bad):
    """A negative radiance has no brightness temperature: ValueError naming ``radiance`` and its
    range "> 0", for floats, numpy arrays and tensors (one bad value among good ones too); never a
    temperature such as the ~13 K that clamping it to the smallest float gives."""
    for x in (bad, np.array([9.0, bad]), torch.tensor([9.0, bad]), torch.tensor([9.0, bad], dtype=F64)):
        with pytest.raises(ValueError, match=r"radiance must be > 0"):
            rs.brightness_temperature(x)
        with pytest.raises(ValueError, match=r"radiance must be > 0"):
            radiometry.band_radiance_slope(x)


def test_band_caches_are_bounded_and_release_response_objects():
    """1000 distinct response objects (callables and tables; every 25th also through the
    brightness-temperature table) do not grow either cache beyond its bound, and a response object released by the caller is collected (the caches hold no strong
    reference to it); equal tabulated responses share one entry (no recomputation)."""
    radiometry._band_cache.clear()
    radiometry._bt_cache.clear()
    bound = radiometry._CACHE_SIZE
    wl = np.array([7.5e-6, 12.5e-6])
    for i in range(1000):
        if i % 2:
            class Resp:  # a fresh callable object each time
                def __call__(self, lam, i=i):
                    return np.ones_like(lam) * (1.0 + 1e-3 * i)
            resp = Resp()
        else:
            resp = (wl, np.array([1.0, 1.0 + 1e-3 * i]))
        band = rs.radiometry.SpectralBand(8e-6, 12e-6, resp)
        L = rs.band_radiance(torch.tensor([290.0]), band)
        if i % 25 == 0:  # 40 tables, more than the bound
            rs.brightness_temperature(L, band)
        assert len(radiometry._band_cache) <= bound and len(radiometry._bt_cache) <= bound

    class Resp2:
        def __call__(self, lam):
            return np.ones_like(lam)

    resp = Resp2()
    alive = weakref.ref(resp)
    band = rs.radiometry.SpectralBand(8e-6, 12e-6, resp)
    rs.brightness_temperature(rs.band_radiance(torch.tensor([290.0]), band), band)
    del band, resp
    gc.collect()
    assert alive() is None, "the band caches keep a released response object alive"

    table = (np.array([8e-6, 12e-6]), np.array([1.0, 0.5]))
    q1 = as_band((8e-6, 12e-6), table).quadrature
    q2 = as_band((8e-6, 12e-6), (table[0].copy(), table[1].copy())).quadrature
    assert q1[0] is q2[0]  # one entry for equal responses given as different objects


def test_reused_object_id_never_returns_a_stale_table():
    """Keys made of id(response) alone return another response's table once the first is
    collected and its id reused: each new callable here must get its own band radiance."""
    for scale in (1.0, 2.0, 3.0, 0.5):
        band = rs.radiometry.SpectralBand(8e-6, 12e-6, lambda lam, s=scale: np.full_like(lam, s))
        L = float(rs.band_radiance(torch.tensor(300.0, dtype=F64), band))
        flat = float(rs.band_radiance(torch.tensor(300.0, dtype=F64), (8e-6, 12e-6)))
        assert abs(L / flat - scale) < 1e-12
        T = float(rs.brightness_temperature(torch.tensor(L, dtype=F64), band))
        assert abs(T - 300.0) < 1e-9
        del band
        gc.collect()

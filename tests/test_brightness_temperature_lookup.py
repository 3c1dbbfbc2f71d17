"""Brightness temperature: the per-pixel table lookup against the band-sum inversion, its errors,
and the band caches (bounded, and never keeping a response object alive).

The reference inversion is Newton's method on the band sum L(T) = Σ wᵢ B_λᵢ(T) in float64
(``_BrightnessTemperature``, the branch used outside the table), which knows nothing of the table.
"""

from __future__ import annotations

import gc
import weakref

import numpy as np
import pytest
import torch

import roughsea_torch as rs
from roughsea_torch import radiometry
from roughsea_torch.radiometry import _BrightnessTemperature, as_band, planck_radiance_derivative

F64 = torch.float64
BANDS = [(8e-6, 12e-6), (3e-6, 5e-6)]


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


def test_float32_lookup_matches_float64():
    """An image-sized float32 batch (shape kept) against the float64 result at the same inputs:
    within float32 rounding of T (3e-5 K at 300 K)."""
    T = torch.linspace(250.0, 320.0, 4 * 3 * 50, dtype=F64).reshape(4, 1, 3, 50)
    L32 = rs.band_radiance(T).float()
    got = rs.brightness_temperature(L32)
    assert got.shape == L32.shape and got.dtype == torch.float32
    want = newton_bt(L32.double(), (8e-6, 12e-6))
    assert float((got.double() - want).abs().max()) < 1e-4


def test_tabulated_response_and_table_edges():
    """A tabulated response: the lookup inverts its own band radiance; at and just beyond the table
    edges (100 K, 500 K) the Newton branch takes over continuously."""
    resp = (np.array([7.5e-6, 8.5e-6, 10e-6, 11.5e-6, 12.5e-6]), np.array([0.0, 0.9, 1.0, 0.7, 0.0]))
    band = rs.radiometry.SpectralBand(7.5e-6, 12.5e-6, resp)
    T = torch.tensor([99.9, 100.0, 100.1, 287.3, 499.9, 500.0, 500.1], dtype=F64)
    got = rs.brightness_temperature(rs.band_radiance(T, band), band)
    torch.testing.assert_close(got, T, rtol=0, atol=2e-6)


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

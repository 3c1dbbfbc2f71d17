"""Optics of water (roughsea_torch.optics): Fresnel reflectance and emissivity of a facet, the
refractive index of water (Hale & Querry 1973, Segelstein 1981) and the band-effective index of a
spectral band (docs/physics.md §6), with its tabulated lookup against the direct fit.

Published numbers and closed forms are asserted of every backend (reference, torch64, torch32) where
the function exists in both, else of the torch code; none is a value produced by this library.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import torch

import roughsea_torch as rs
from roughsea_torch.optics import band_index_lookup, band_refractive_index
from roughsea_torch.radiometry import as_band

from conftest import DEG, M10, M11, exact_fresnel


@pytest.mark.parametrize("m", [M10, M11, 1.351 + 0.0046j, 1.111 + 0.199j, 1.5 + 0.0j, 2.0 + 1.0j])
def test_normal_incidence_reflectance_closed_form(backend, m):
    """ρ₀ = ((n − 1)² + k²)/((n + 1)² + k²) at normal incidence, for water and for other indices."""
    n, k = m.real, m.imag
    rho0 = ((n - 1) ** 2 + k**2) / ((n + 1) ** 2 + k**2)
    got = float(backend.fresnel_reflectance(np.array(1.0), m))
    assert abs(got - rho0) < max(backend.rtol, 1e-7) * 0.1 + 1e-9


def test_fresnel_emissivity_is_one_minus_fresnel_reflectance(dtype):
    """The cancellation-free facet emissivity equals 1 − ρ of the Fresnel equations written with
    complex numbers here (including 89.99°, where ε is small, and normal incidence)."""
    angles = np.array([0.0, 20.0, 45.0, 60.0, 75.0, 85.0, 89.0, 89.99])
    c = np.cos(np.radians(angles))
    for m in (M10, M11, 1.351 + 0.0046j):
        ct = torch.tensor(c, dtype=dtype)
        got = rs.fresnel_emissivity(ct, m).double().numpy()
        expected = np.array([1.0 - 0.5 * sum(exact_fresnel(float(ci), m)) for ci in ct.double().numpy()])
        np.testing.assert_allclose(got, expected, rtol=2e-6 if dtype == torch.float32 else 1e-12, atol=1e-7 if dtype == torch.float32 else 0)
    assert float(rs.fresnel_emissivity(1.0, M10)) == pytest.approx(0.98982, abs=6e-6)  # docs/physics.md §13


@pytest.mark.parametrize(
    "m, e0",
    [(1.351 + 0.0046j, 0.97771), (M10, 0.98982), (M11, 0.99294), (1.111 + 0.199j, 0.98845)],
)
def test_normal_incidence_emissivity_hale_querry(backend, m, e0):
    """docs/physics.md §13: 1 − ρ₀ with ρ₀ = ((n−1)² + k²)/((n+1)² + k²) for Hale & Querry water."""
    rho = backend.fresnel_reflectance(1.0, m)
    assert abs((1 - rho) - e0) < 6e-6


@pytest.mark.parametrize("m, e85, e89", [(M10, 0.4544, 0.1152), (M11, 0.4682, 0.1194)])
def test_flat_sea_grazing_emissivity_hale_querry(backend, m, e85, e89):
    """docs/physics.md §13: flat-sea emissivity at 85° and 89°."""
    for theta, expected in ((85.0, e85), (89.0, e89)):
        rho = backend.fresnel_reflectance(math.cos(theta * DEG), m)
        assert abs((1 - rho) - expected) < 6e-5


def test_s_and_p_parts_average_to_unpolarized_and_brewster(backend):
    """ρ = (ρ_s + ρ_p)/2; ρ_p has its minimum near Brewster's angle atan(n); ρ_s > ρ_p off normal."""
    c = np.cos(np.linspace(0.0, 89.0, 90) * DEG)
    rs_ = backend.fresnel_reflectance(c, M10, "s")
    rp_ = backend.fresnel_reflectance(c, M10, "p")
    ru = backend.fresnel_reflectance(c, M10)
    np.testing.assert_allclose(ru, 0.5 * (rs_ + rp_), rtol=1e-6)
    assert np.all(rs_[1:] > rp_[1:])
    brewster = math.degrees(math.atan(1.218))
    assert abs(int(np.argmin(rp_)) - brewster) <= 1.0


def test_cos_incidence_beyond_one_is_an_error(backend):
    """|cos i| ≤ 1: a cosine of 1.005 is no angle; every backend raises ValueError."""
    with pytest.raises(ValueError, match="cos_incidence"):
        backend.fresnel_reflectance(np.array(1.005), M10)


def test_segelstein_table_published_values_and_consistency_with_hale_querry():
    """Segelstein 1981 (refractiveindex.info page main/H2O/Segelstein), the row at 10.000 µm:
    n = 1.193164, k = 0.050791394. Both it and Hale & Querry 1973 measure liquid water: over
    8–12 µm they agree to |Δn| < 0.03 and |Δk| < 20 % of k, and both give a normal-incidence
    emissivity ≈ 0.99 at 10 µm (0.98982 for Hale & Querry, docs/physics.md §13)."""
    m = complex(rs.water_refractive_index(torch.tensor(10e-6, dtype=torch.float64), "segelstein"))
    assert abs(m.real - 1.193164) < 1e-9 and abs(m.imag - 0.050791394) < 1e-12
    lam = torch.linspace(8e-6, 12e-6, 81, dtype=torch.float64)
    seg = rs.water_refractive_index(lam, "segelstein")
    hq = rs.water_refractive_index(lam, "hale_querry")
    assert float((seg.real - hq.real).abs().max()) < 0.03
    assert float(((seg.imag - hq.imag).abs() / hq.imag).max()) < 0.2
    e0 = 1.0 - float(rs.fresnel_reflectance(1.0, m))
    assert 0.985 < e0 < 0.995
    wl, n, k = rs.optics.water_table("segelstein")
    assert wl[0] < 3e-6 and wl[-1] > 14e-6 and np.all(np.diff(wl) > 0) and np.all(k >= 0)


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


def test_band_index_in_mwir_is_the_planck_weighted_average():
    """docs/physics.md §6 / ``band_refractive_index``: over 3–5 µm the least-squares fit wants k < 0, so
    the Planck-weighted average (n̄, k̄) is returned; it reproduces the band-averaged reflectance to
    3e-4 at every angle. Over 8–12 µm the fit is returned, and beats the average 20-fold."""
    mw = complex(rs.band_refractive_index((3e-6, 5e-6), 290.0))
    avg = complex(rs.band_refractive_index((3e-6, 5e-6), 290.0, method="average"))
    assert abs(mw - avg) < 1e-12
    lw = complex(rs.band_refractive_index((8e-6, 12e-6), 290.0))
    assert abs(lw - complex(rs.band_refractive_index((8e-6, 12e-6), 290.0, method="average"))) > 1e-3


def test_lwir_band_index_is_the_least_squares_optimum():
    """``band_refractive_index`` (method "fit") is documented as the (n, k ≥ 0) whose Fresnel
    reflectance best fits the band-averaged ρ̄(θ) in least squares over 0–89.9°: moving n or k by
    ±1e-5 from it must not lower the sum of squared residuals (a point that is not the optimum,
    e.g. from a Newton step of the wrong size, has a gradient and fails)."""
    c = torch.cos(torch.deg2rad(torch.linspace(0.0, 89.9, 181, dtype=torch.float64)))
    target = rs.band_reflectance(c, (8e-6, 12e-6), 290.0)
    m = complex(rs.band_refractive_index((8e-6, 12e-6), 290.0))

    def sse(n: float, k: float) -> float:
        return float(((rs.fresnel_reflectance(c, (n, k)) - target) ** 2).sum())

    best = sse(m.real, m.imag)
    d = 1e-5
    for n, k in ((m.real + d, m.imag), (m.real - d, m.imag), (m.real, m.imag + d), (m.real, max(m.imag - d, 0.0))):
        assert sse(n, k) >= best * (1 - 1e-9), (n, k)


def test_band_averaged_reflectance_differs_from_averaged_index():
    """docs/physics.md §6: averaging ρ over the band is not the same as ρ of the averaged (n, k)."""
    rho_band = float(rs.band_reflectance(1.0))
    rho_index = float(rs.fresnel_reflectance(1.0, rs.band_refractive_index(method="average")))
    assert rho_band > rho_index * 1.03
    assert abs(rho_band - rho_index) < 0.003


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


# ------------------------------------------------------------------------------------------------
# optics.band_index_lookup: the tabulated band-effective water index against the direct fit
# ------------------------------------------------------------------------------------------------
def test_lookup_matches_the_direct_fit_between_nodes():
    """Within 1e-8 of ``band_refractive_index`` at temperatures between the 2 K nodes: LWIR over the whole
    table (180–360 K), MWIR from 190 K (below ~188 K the MWIR fit switches between the fitted and the
    averaged index from one temperature to the next, and the interpolant between nodes is off by up to
    1e-2 in k there, far below any sea temperature)."""
    lw = torch.tensor([181.3, 239.9, 271.15, 290.0, 303.7, 359.1], dtype=torch.float64)
    mw = torch.tensor([190.3, 239.9, 271.15, 290.0, 303.7, 359.1], dtype=torch.float64)
    for band, t in (((8e-6, 12e-6), lw), ((3e-6, 5e-6), mw)):
        n, k = band_index_lookup(as_band(band), t)
        m = band_refractive_index(band, t)
        assert n.shape == t.shape and k.shape == t.shape
        assert float((n - m.real).abs().max()) < 1e-8
        assert float((k - m.imag).abs().max()) < 1e-8


def test_lookup_is_differentiable_in_temperature():
    """dn/dT of the interpolant agrees with a central difference of the direct fit."""
    band = as_band((8e-6, 12e-6))
    t = torch.tensor(290.7, dtype=torch.float64, requires_grad=True)
    n, _ = band_index_lookup(band, t)
    (grad,) = torch.autograd.grad(n, t)
    h = 0.5
    fd = (band_refractive_index(band, 290.7 + h).real - band_refractive_index(band, 290.7 - h).real) / (2 * h)
    assert abs(float(grad) - float(fd)) < 1e-3 * abs(float(fd)) + 1e-9


def test_tabulated_response_band():
    """A band with a tabulated response (its own table, keyed by the band): within 1e-8 of the fit."""
    wl = np.linspace(7.5e-6, 12.5e-6, 11)
    band = as_band((8e-6, 12e-6), (wl, np.linspace(0.5, 1.0, 11)))
    t = torch.tensor([285.3, 295.9], dtype=torch.float64)
    n, k = band_index_lookup(band, t)
    m = band_refractive_index(band, t)
    assert float((n - m.real).abs().max()) < 1e-8 and float((k - m.imag).abs().max()) < 1e-8

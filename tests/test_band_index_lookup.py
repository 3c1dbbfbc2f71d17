"""``optics.band_index_lookup``: the tabulated band-effective water index against the direct fit."""

from __future__ import annotations

import numpy as np
import torch

from roughsea_torch.optics import band_index_lookup, band_refractive_index
from roughsea_torch.radiometry import as_band


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

"""roughsea_torch.foam: the default water index of the foam emissivity, by band (tests/test_foam.py holds
the rest of the module's tests)."""

from __future__ import annotations

import math

import pytest
import torch

from roughsea_torch.foam import foam_emissivity


@pytest.mark.parametrize("band, index", [((2.41e-6, 2.61e-6), 1.351 + 0.0046j), ((5.89e-6, 6.09e-6), 1.351 + 0.0046j),
                                         ((6.91e-6, 7.11e-6), 1.218 + 0.0508j), ((14.85e-6, 15.0e-6), 1.218 + 0.0508j)],
                         ids=["centre_2.51um", "centre_5.99um", "centre_7.01um", "centre_14.93um"])
def test_foam_emissivity_takes_the_bands_hale_querry_index_up_to_the_range_edges(band, index):
    """A band centred in 2.5–6 µm takes Hale & Querry's 4 µm water index, one in 7–15 µm the 10 µm
    index (the documented default), up to the ranges' edges: the emissivity equals the one with that
    index given, at every view zenith (where the foam excess is 0 and where it is not)."""
    th = torch.linspace(0.0, math.pi / 2, 19, dtype=torch.float64)
    torch.testing.assert_close(foam_emissivity(th, band), foam_emissivity(th, band, refractive_index=index),
                               rtol=1e-15, atol=0)

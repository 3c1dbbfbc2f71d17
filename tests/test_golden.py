"""The renderer's images stay what they were: every path of ``tests/golden_cases.py`` against the saved
renders, bit for bit on the torch build and CPU capability that saved them (a restructuring must not
change a single bit), within 1e-4 relative elsewhere (other CPU kernels round differently)."""

from __future__ import annotations

import pytest
import torch

import golden_cases as G

SAVED = torch.load(G.PATH, weights_only=True)
SAME_MACHINE = SAVED["stamp"] == G.stamp()


@pytest.mark.parametrize("name", list(G.CASES))
def test_golden_render(name):
    new = G.CASES[name]().detach().cpu()
    old = SAVED["renders"][name]
    assert new.shape == old.shape and new.dtype == old.dtype
    if SAME_MACHINE:
        assert torch.equal(new, old), f"{name}: max |diff| {float((new - old).abs().max()):.3g}"
    else:
        assert torch.allclose(new, old, rtol=1e-4, atol=0.0)

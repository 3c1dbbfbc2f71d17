"""The quadrature rules of the expectation (roughsea_torch.quadrature): their settings' checks. (That
the rules converge is what tests/test_expectation.py asserts against the numpy reference.)"""

from __future__ import annotations

import pytest

from roughsea_torch.quadrature import Quadrature


@pytest.mark.parametrize(
    "call, match",
    [
        (lambda: Quadrature(outer=0), "outer"),
    ],
)
def test_clear_errors(call, match):
    with pytest.raises(ValueError, match=match):
        call()

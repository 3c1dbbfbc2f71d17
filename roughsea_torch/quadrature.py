"""Accuracy control of the facet-weighted expectation: the sizes of its Gauss rules, and the rules.

:mod:`roughsea_torch.expectation` evaluates its two integrals on tensor-product Gauss rules
(Gauss–Legendre over bounded panels, Gauss–Hermite over a Gaussian); :class:`Quadrature` sets their
sizes and the Gaussian window, :func:`gauss_nodes` gives the nodes and weights (numpy's
``leggauss`` and ``hermegauss``, cached). :class:`Quadrature` is also importable from
:mod:`roughsea_torch.expectation`.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from functools import lru_cache
from typing import Any

import numpy as np
import torch

__all__ = ["Quadrature", "gauss_nodes"]


@dataclass(frozen=True)
class Quadrature:
    """Accuracy control of the expectation.

    Args:
        outer: Gauss–Legendre nodes along s∥ (both integrals), per panel: the sky integral splits
            its outer range in three panels where the Gaussian ridge leaves the sky disc when the
            slopes are anisotropic across the view (κ ≠ 0), one panel otherwise.
        inner: Gauss–Legendre nodes across the sky disc (apparent radiance).
        hermite: Gauss–Hermite nodes across s∥ (emissivity).
        width: half-width of the Gaussian window, in standard deviations (mass beyond it is
            dropped: 2·(1 − Φ(width))).
        chunk: largest number of quadrature points held at once (memory bound; results do not
            depend on it).
        split: the sky integral splits its outer panel where the Gaussian ridge leaves the sky
            disc when the conditional rms slope τ < split · |κ| · σ∥ somewhere in a chunk.

    ``Quadrature.default(dtype)`` is what every function uses when ``quadrature=None``; it meets
    a relative error of 1e-6 in float64 and 1e-5 in float32 against a converged reference over
    the model's range with a smooth sky (``pipelines/accuracy_core.py``); error against run time
    of every setting, and where it sits on the Pareto front: ``pipelines/accuracy_pareto.py``;
    the extremes, and the regimes where the default does worse (a tabulated sky's C¹ kinks, a
    sky far colder than the sea at grazing): ``pipelines/stability.py``.
    """

    outer: int = 28
    inner: int = 28
    hermite: int = 12
    width: float = 7.5
    chunk: int = 1 << 18
    split: float = 2.0

    def __post_init__(self) -> None:
        for name in ("outer", "inner", "hermite"):
            v = getattr(self, name)
            if not isinstance(v, int) or v < 1 or v > 512:
                raise ValueError(f"Quadrature.{name} must be an int in [1, 512]; got {v!r}")
        if not (1.0 <= float(self.width) <= 40.0):
            raise ValueError(f"Quadrature.width must lie in [1, 40] standard deviations; got {self.width!r}")
        if not isinstance(self.chunk, int) or self.chunk < 1024:
            raise ValueError(f"Quadrature.chunk must be an int >= 1024; got {self.chunk!r}")

    @staticmethod
    def default(dtype: torch.dtype = torch.float64) -> Quadrature:
        if dtype == torch.float32:
            return Quadrature(outer=20, inner=20, hermite=8, width=6.0)
        return Quadrature(outer=28, inner=28, hermite=12, width=7.5)

    def with_(self, **kw: Any) -> Quadrature:
        return replace(self, **kw)


@lru_cache(maxsize=64)
def _gl_np(n: int) -> tuple[np.ndarray, np.ndarray]:
    return np.polynomial.legendre.leggauss(n)


@lru_cache(maxsize=64)
def _gh_np(n: int) -> tuple[np.ndarray, np.ndarray]:
    x, w = np.polynomial.hermite_e.hermegauss(n)
    return x, w / w.sum()


def gauss_nodes(kind: str, n: int, dtype: torch.dtype, device: torch.device) -> tuple[torch.Tensor, torch.Tensor]:
    """(nodes, weights) of an n-point Gauss rule: ``kind`` "gl" Gauss–Legendre on [−1, 1] (weights sum
    to 2), else Gauss–Hermite for the standard normal weight (weights sum to 1)."""
    x, w = (_gl_np if kind == "gl" else _gh_np)(n)
    return torch.as_tensor(x, dtype=dtype, device=device), torch.as_tensor(w, dtype=dtype, device=device)

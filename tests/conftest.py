"""Backends for the shared physics suite: the numpy reference, torch float64 and torch float32.

A test written against ``backend`` calls the same public functions of either implementation with
numpy inputs and gets numpy float64 outputs back; tolerances follow the backend (``backend.rtol``
is the accuracy the backend promises against a converged answer).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
import pytest
import torch

import roughsea_torch as rs
import roughsea_torch.reference as ref

torch.manual_seed(0)


@dataclass
class Backend:
    name: str
    rtol: float
    dtype: torch.dtype | None = None

    @property
    def is_reference(self) -> bool:
        return self.dtype is None

    # -- conversion ----------------------------------------------------------------------------
    def t(self, x: Any) -> Any:
        if self.is_reference:
            return np.asarray(x, dtype=np.float64) if not isinstance(x, (complex, tuple)) else x
        if isinstance(x, (complex, tuple)) or callable(x):
            return x
        return torch.as_tensor(np.asarray(x, dtype=np.float64), dtype=self.dtype)

    def out(self, y: Any) -> np.ndarray:
        if isinstance(y, torch.Tensor):
            return y.detach().double().cpu().numpy()
        return np.asarray(y, dtype=np.float64)

    def roundtrip(self, x: Any) -> np.ndarray:
        """The value this backend actually sees for input x (float32 rounding for torch32)."""
        return self.out(self.t(x))

    # -- API -----------------------------------------------------------------------------------
    def slopes(self, a: Any, b: Any, r: Any = 0.0) -> Any:
        mod = ref if self.is_reference else rs
        return mod.SlopeStatistics(self.t(a), self.t(b), self.t(r))

    def cox_munk(self, w: Any, anisotropic: bool = False) -> Any:
        mod = ref if self.is_reference else rs
        return mod.SlopeStatistics.cox_munk(self.t(w), anisotropic=anisotropic)

    def _sky(self, sky: Any) -> Any:
        if self.is_reference or not callable(sky):
            return sky
        return lambda c: sky(c)  # the test skies are written with operators that work on both

    def emissivity(self, th, ph, slopes, m, shadowing=True):
        mod = ref if self.is_reference else rs
        return self.out(mod.emissivity(self.t(th), self.t(ph), slopes, m, shadowing=shadowing))

    def apparent_radiance(self, th, ph, slopes, m, sea_radiance, sky, shadowing=True):
        mod = ref if self.is_reference else rs
        return self.out(
            mod.apparent_radiance(
                self.t(th), self.t(ph), slopes, m, sea_radiance=self.t(sea_radiance),
                sky=self._sky(sky), shadowing=shadowing,
            )
        )

    def projected_area(self, th, ph, slopes, shadowing=True):
        mod = ref if self.is_reference else rs
        return self.out(mod.projected_area(self.t(th), self.t(ph), slopes, shadowing=shadowing))

    def fresnel_reflectance(self, c, m, polarization="unpolarized"):
        mod = ref if self.is_reference else rs
        return self.out(mod.fresnel_reflectance(self.t(c), m, polarization=polarization))

    def slope_pdf(self, th, ph, slopes):
        mod = ref if self.is_reference else rs
        return self.out(mod.slope_pdf(self.t(th), self.t(ph), slopes))

    def band_radiance(self, temperature, band, response=None):
        mod = ref if self.is_reference else rs
        return self.out(mod.band_radiance(self.t(temperature), band, response))

    def brightness_temperature(self, radiance, band, response=None):
        mod = ref if self.is_reference else rs
        return self.out(mod.brightness_temperature(self.t(radiance), band, response))

    def planck_radiance(self, wavelength, temperature):
        mod = ref if self.is_reference else rs
        return self.out(mod.planck_radiance(self.t(wavelength), self.t(temperature)))


BACKENDS = {
    "reference": Backend("reference", rtol=1e-7),
    "torch64": Backend("torch64", rtol=1e-6, dtype=torch.float64),
    "torch32": Backend("torch32", rtol=1e-5, dtype=torch.float32),
}


@pytest.fixture(params=list(BACKENDS), ids=list(BACKENDS))
def backend(request: pytest.FixtureRequest) -> Backend:
    return BACKENDS[request.param]


@pytest.fixture(params=["torch64", "torch32"])
def torch_backend(request: pytest.FixtureRequest) -> Backend:
    return BACKENDS[request.param]


def smooth_sky(c: Any) -> Any:
    """A cold, smooth sky rising towards the sea temperature at the horizon [W m⁻² sr⁻¹]."""
    return 11.0 + 19.0 * (1.0 - c) ** 8


DEG = math.pi / 180.0


@pytest.fixture(scope="module")
def one_torch_thread():
    """One torch thread for a module of small calls (~1e4 points): on a busy 2-core machine torch's
    intra-op threads turn milliseconds into seconds. Use with ``pytest.mark.usefixtures``."""
    n = torch.get_num_threads()
    torch.set_num_threads(1)
    yield
    torch.set_num_threads(n)

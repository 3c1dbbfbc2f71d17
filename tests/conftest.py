"""What the test modules share: the backends of the physics suite, fixtures, factories and closed forms.

Layout. The tests mirror the package (``docs/architecture.md``): ``tests/test_<module>.py`` tests
``roughsea_torch/<module>.py`` (a private module without its underscore: ``test_validation.py`` for
``_validation``, ``test_parallel.py`` for ``_parallel``, ``test_augmentation_checks.py`` for
``_augmentation_checks``), ``tests/renderer/test_<module>.py`` tests
``roughsea_torch/renderer/<module>.py``, and ``tests/reference/test_<module>.py`` tests the numpy
reference alone (``roughsea_torch/reference/<module>.py``). A test lives with the module whose
behaviour its assertions check: a render that checks the glint table is in
``tests/renderer/test_glint.py``, one that checks how a ``SeaScene`` argument reaches the pixels in
``tests/renderer/test_scene.py``; a test of the torch code against the numpy reference lives with the
torch module. The nets over the whole package stay at the top: ``test_architecture.py``,
``test_golden.py`` (with ``golden_cases.py`` and ``data/``) and ``test_readme.py``.

Backends. ``backend`` runs one test against the numpy reference, torch float64 and torch float32
(``torch_backend`` the two torch ones): the same public functions of either implementation with
numpy inputs, numpy float64 outputs back; tolerances follow the backend (``backend.rtol`` is the
accuracy the backend promises against a converged answer). These tests live with the module of the
function they call: ``test_expectation.py`` (``apparent_radiance``, ``emissivity``,
``projected_area``), ``test_optics.py`` (Fresnel), ``test_slopes.py`` (the slope law and its
density), ``test_radiometry.py`` (Planck, brightness temperature).

Fixtures: ``dtype`` (float32, float64), ``device`` (CPU; CUDA, skipped without a device),
``one_thread`` and ``two_threads`` (torch's intra-op threads for the test, restored afterwards; a
module of small calls takes ``pytestmark = pytest.mark.usefixtures("one_thread")``: on a busy 2-core
machine torch's threads turn milliseconds into seconds), ``crest_ensemble`` (sampled wave fields
with their crest variable, shared by ``test_waves.py`` and ``test_foam.py``).

Factories, plain functions to import (``from conftest import make_cams, make_scene``) so that helpers
and parametrize lists can use them too: ``make_cams`` (kornia cameras with the defaults most
renderer tests use), ``make_scene`` (a ``SeaScene`` with the common wind and sea temperature),
``varied_cameras`` (five cameras over the renderer's range), ``gen`` (a seeded CPU generator).
Skies: ``smooth_sky`` (a cold sky, (1 − cos)⁸) and ``horizon_sky`` ((1 − cos)⁴, the textured seas').
"""

from __future__ import annotations

import math
from contextlib import contextmanager
from dataclasses import dataclass
from typing import Any, Iterator

import numpy as np
import pytest
import torch
from scipy import integrate

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


# ------------------------------------------------------------------------------------------------
# Numbers and closed forms typed in here, never produced by the library
# ------------------------------------------------------------------------------------------------
DEG = math.pi / 180.0

# Hale & Querry 1973, refractive index of water
M4 = 1.351 + 0.0046j  # 4 µm (nearly transparent)
M10 = 1.218 + 0.0508j  # 10 µm
M11 = 1.153 + 0.0968j  # 11 µm
M12 = 1.111 + 0.199j  # 12 µm (k four times the 11 µm value)

# CODATA 2018 (exact SI values), typed here rather than imported from the code under test
H = 6.62607015e-34
C = 299792458.0
KB = 1.380649e-23

# SeaScene and WaveField: times must lie in [-1e9, 1e9] s (the regular expression of the message)
TIME_RANGE = r"\[-1e\+09, 1e\+09\] s"


def smooth_sky(c: Any) -> Any:
    """A cold, smooth sky rising towards the sea temperature at the horizon [W m⁻² sr⁻¹]."""
    return 11.0 + 19.0 * (1.0 - c) ** 8


def horizon_sky(c: Any) -> Any:
    """The textured-sea tests' sky: 10 W m⁻² sr⁻¹ at the zenith, 30 at the horizon, (1 − cos)⁴."""
    return 10.0 + 20.0 * (1.0 - c) ** 4


def planck_band(T: float, lo: float, hi: float, response=None) -> float:
    """∫ r(λ) 2hc²/λ⁵ / (exp(hc/(λ k T)) − 1) dλ by adaptive quadrature [W m⁻² sr⁻¹]."""

    def f(lam: float) -> float:
        r = 1.0 if response is None else float(response(lam))
        return r * 2.0 * H * C * C / lam**5 / math.expm1(H * C / (lam * KB * T))

    return integrate.quad(f, lo, hi, epsabs=0.0, epsrel=1e-13, limit=200)[0]


def exact_fresnel(c: float, m: complex) -> tuple[float, float]:
    """(ρ_s, ρ_p) of the Fresnel equations written with complex numbers."""
    s2 = 1.0 - c * c
    w = np.sqrt(m * m - s2 + 0j)
    rs_ = abs((c - w) / (c + w)) ** 2
    rp_ = abs((m * m * c - w) / (m * m * c + w)) ** 2
    return rs_, rp_


# ------------------------------------------------------------------------------------------------
# Fixtures: dtype, device, torch's threads
# ------------------------------------------------------------------------------------------------
DEVICES = ["cpu", pytest.param("cuda", marks=pytest.mark.skipif(not torch.cuda.is_available(), reason="no CUDA"))]


@pytest.fixture(params=[torch.float32, torch.float64], ids=["float32", "float64"])
def dtype(request: pytest.FixtureRequest) -> torch.dtype:
    """Both floating dtypes of the package."""
    return request.param


@pytest.fixture(params=DEVICES)
def device(request: pytest.FixtureRequest) -> torch.device:
    """The CPU, and CUDA where there is a device (skipped otherwise)."""
    return torch.device(request.param)


@contextmanager
def torch_threads(n: int) -> Iterator[None]:
    """torch's intra-op thread count set to ``n`` inside the block, the caller's restored after it."""
    before = torch.get_num_threads()
    torch.set_num_threads(n)
    try:
        yield
    finally:
        torch.set_num_threads(before)


@pytest.fixture
def one_thread() -> Iterator[None]:
    """One torch thread for the test: small calls (~1e4 points), for which on a busy 2-core machine
    torch's intra-op threads turn milliseconds into seconds (OpenMP spin-waiting makes the many small
    per-image ops of WaveField erratic). A module of them takes ``pytestmark =
    pytest.mark.usefixtures("one_thread")``; the thread count is restored after each test."""
    with torch_threads(1):
        yield


@pytest.fixture
def two_threads() -> Iterator[None]:
    """Two torch threads for the test (the parallel code paths: worker threads, intra-op splits)."""
    with torch_threads(2):
        yield


# ------------------------------------------------------------------------------------------------
# Factories
# ------------------------------------------------------------------------------------------------
def make_cams(h: int = 24, w: int = 32, *, hfov_deg: Any = 30.0, altitude_m: Any = 20.0, pitch_deg: Any = -5.0,
              dtype: torch.dtype = torch.float64, **pose: Any) -> Any:
    """``rs.make_camera`` with the defaults most renderer tests use: 24 × 32 pixels, a 30° field of
    view, 20 m up, looking 5° down, float64. Any other argument (``yaw_deg``, ``roll_deg``,
    ``batch_size``, ``device``) passes through; a per-image pose is a tensor (B,)."""
    return rs.make_camera(h, w, hfov_deg=hfov_deg, altitude_m=altitude_m, pitch_deg=pitch_deg, dtype=dtype, **pose)


def make_scene(**kw: Any) -> rs.SeaScene:
    """``rs.SeaScene`` with the common wind (8 m/s) and sea temperature (290 K); every keyword of
    ``SeaScene`` overrides or adds (the sky, path and foam are the scene's own defaults)."""
    return rs.SeaScene(**{"wind_speed": 8.0, "sea_temperature": 290.0, **kw})


def varied_cameras(dtype: torch.dtype, H: int = 64, W: int = 80) -> Any:
    """Five cameras: low near-horizontal, 200 m, 2 km oblique wide, 5 m grazing narrow, nadir."""
    return rs.make_camera(
        H, W,
        hfov_deg=torch.tensor([30.0, 30.0, 60.0, 10.0, 40.0]),
        altitude_m=torch.tensor([20.0, 200.0, 2000.0, 5.0, 20.0]),
        pitch_deg=torch.tensor([-3.0, -10.0, -45.0, -0.5, -89.0]),
        yaw_deg=torch.tensor([0.0, 40.0, 100.0, -30.0, 0.0]),
        roll_deg=torch.tensor([0.0, 5.0, -10.0, 2.0, 0.0]),
        dtype=dtype,
    )


def gen(seed: int) -> torch.Generator:
    """A CPU generator seeded with ``seed``."""
    return torch.Generator().manual_seed(seed)


# ------------------------------------------------------------------------------------------------
# Images for the sensor tests
# ------------------------------------------------------------------------------------------------
def eps(dtype: torch.dtype) -> float:
    return torch.finfo(dtype).eps


def uniform_image(T: float, shape, dtype, device, band=rs.LWIR) -> torch.Tensor:
    """The band radiance of a blackbody at T [K], an image of ``shape``."""
    return rs.band_radiance(torch.full(shape, T, dtype=dtype, device=device), band)


def radiance_image(dtype, device, B=2, H=32, W=40) -> torch.Tensor:
    """A (B, 1, H, W) LWIR radiance image of blackbodies between 280 and 300 K (seeded)."""
    T = 280.0 + 20.0 * torch.rand(B, 1, H, W, generator=gen(11), dtype=torch.float64)
    return rs.band_radiance(T).to(dtype=dtype, device=device)


# ------------------------------------------------------------------------------------------------
# Sampled wave fields with their crest variable (test_waves.py, test_foam.py)
# ------------------------------------------------------------------------------------------------
ENSEMBLE_WIND = 10.0  # [m/s]
ENSEMBLE_FOOTPRINTS = (0.05, 3.0, 30.0)  # [m] short (everything resolved), medium, long (14 % of X resolved)


@pytest.fixture(scope="session")
def crest_ensemble() -> dict[str, torch.Tensor]:
    """120 realizations (one seed each, U10 = 10 m/s, float32) sampled at 2048 uniform random points
    of the longest tile, each point at the three footprints (one call, one pass over the bands), on
    one torch thread."""
    n, npts = 120, 2048
    with torch_threads(1):
        field = rs.WaveField(torch.full((n,), ENSEMBLE_WIND), list(range(n)), wind_direction=0.4, dtype=torch.float32)
        gen = torch.Generator().manual_seed(0)
        side = field.bands.tile_length[0]  # band 0's period, the area of 4^o cells of band o's turned tile:
        # uniform on every tile but at the square's edges (cross terms of zero mean over seeds)
        x = (torch.rand(n, npts, generator=gen, dtype=torch.float64) * side).float()
        y = (torch.rand(n, npts, generator=gen, dtype=torch.float64) * side).float()
        k = len(ENSEMBLE_FOOTPRINTS)
        fp = torch.tensor(ENSEMBLE_FOOTPRINTS).repeat_interleave(npts).expand(n, -1)
        smp = field.sample(x.repeat(1, k), y.repeat(1, k), 1.0, footprint=fp, elevation=True, crest=True)
        out = {key: v.view(n, k, npts).double() for key, v in smp.items()}
        for name, var in (("crest", field.crest_variance), ("elevation", field.elevation_variance)):
            out[name + "_resolved_variance"] = var(fp).view(n, k, npts).double()
            out[name + "_total_variance"] = var().double()[:, None, None]
    return out

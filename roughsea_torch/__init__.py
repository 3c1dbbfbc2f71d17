"""roughsea_torch: physically based infrared radiance of a rough sea, in PyTorch.

The model is the probabilistic facet model of "A probabilistic model of the apparent radiance of a
rough sea" (the paper's Eqs. 1, 5-10, A7/A8): apparent radiance as a facet-weighted expectation
over Gaussian wave slopes, with Fresnel emission and reflection of sky radiance and a shadowing
correction. Conventions: ``docs/physics.md`` §2 (SI units, radians).

Public core::

    import roughsea_torch as rs
    slopes = rs.SlopeStatistics.cox_munk(wind_speed, anisotropic=False)
    eps = rs.emissivity(view_zenith, view_azimuth, slopes=slopes, refractive_index=1.218 + 0.0508j)
    R_a = rs.apparent_radiance(view_zenith, view_azimuth, slopes=slopes, refractive_index=...,
                               sea_radiance=R_B, sky=lambda cos_zenith: ..., shadowing=True)

``rs.reference`` holds an independent numpy implementation with the same signatures.
"""

from .expectation import Quadrature, apparent_radiance, emissivity, projected_area, reflection_terms, smith_lambda
from .optics import (
    band_reflectance,
    band_refractive_index,
    fresnel_emissivity,
    fresnel_reflectance,
    water_refractive_index,
)
from .radiometry import (
    LWIR,
    MWIR,
    SpectralBand,
    band_radiance,
    brightness_temperature,
    planck_radiance,
)
from .sky import ConstantSky, TabulatedSky
from .geometry import EARTH_RADIUS_M, ViewGeometry, make_camera, view_geometry
from .renderer import SeaRenderer, SeaScene, TableSize, release_workspace, render
from .sensitivity import pixel_derivative
from .slopes import SlopeStatistics, slope_pdf
from .waves import WaveField, elfouhaily_spectrum
from .motion import PlatformMotion, render_clip
from .sun import Sun, glint_radiance
from . import atmosphere, augmentation, clutter, dataset, foam, glitter, renderer, sensor, sun, waves, whitecaps  # noqa: E402  (submodules as attributes: rs.sensor, ...)
from .augmentation import RandomSeaBackground, RandomSeaClip, SceneSampler
from .dataset import SeaShardDataset
from .sensor import SensorModel

from ._version import __version__  # noqa: E402

__all__ = [
    "atmosphere",
    "augmentation",
    "clutter",
    "renderer",
    "foam",
    "sun",
    "waves",
    "whitecaps",
    "WaveField",
    "PlatformMotion",
    "Sun",
    "glint_radiance",
    "elfouhaily_spectrum",
    "render_clip",
    "dataset",
    "sensor",
    "EARTH_RADIUS_M",
    "LWIR",
    "MWIR",
    "ConstantSky",
    "SeaRenderer",
    "SeaScene",
    "TableSize",
    "ViewGeometry",
    "Quadrature",
    "RandomSeaBackground",
    "RandomSeaClip",
    "SceneSampler",
    "SeaShardDataset",
    "SensorModel",
    "SlopeStatistics",
    "SpectralBand",
    "TabulatedSky",
    "apparent_radiance",
    "band_radiance",
    "band_reflectance",
    "band_refractive_index",
    "brightness_temperature",
    "emissivity",
    "fresnel_emissivity",
    "fresnel_reflectance",
    "make_camera",
    "pixel_derivative",
    "planck_radiance",
    "projected_area",
    "reflection_terms",
    "release_workspace",
    "render",
    "slope_pdf",
    "smith_lambda",
    "view_geometry",
    "water_refractive_index",
]

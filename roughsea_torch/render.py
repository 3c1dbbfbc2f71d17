"""Sea scenes and the renderer: kornia cameras + scenes → infrared radiance images (B, 1, H, W).

Sea pixels get the apparent radiance of Eq. 10 at their own view angles (θ̂, φ̂); sky pixels get
the sky radiance along their own ray. Two methods:

- ``method="table"`` (default): per image, the model is evaluated only over the view angles its sea
  pixels span (read from the image's border, where the extremes of the view angles lie), at
  Chebyshev–Lobatto nodes in ζ = asinh(cos θ̂ / ε) (ε ~ the rms slope, so the boundary layer at the
  horizon, where R_a changes fastest, is resolved) and, for anisotropic slopes only, in the
  relative azimuth. The node values are resampled spectrally to one fine table per image that also
  holds, per row, the path (τ · R_a + L_path: for one camera the slant range is a function of θ̂
  alone) and, in a second block of rows, the sky radiance along the sky pixels' rays. Each pixel
  then costs its ray, its table coordinates and one bilinear ``torch.nn.functional.grid_sample``.
  Accuracy: within a few 1e-6 relative of the direct evaluation, horizon rows and sky pixels
  included (``tests/test_render.py``).
- ``method="direct"``: ``apparent_radiance``, the path and the sky at every pixel (the baseline;
  slow).

What a scene does not need is left out (measured by ``pipelines/bench_render.py``): no sky work
when no pixel sees sky; no azimuth dimension (and no per-pixel azimuth) when the slopes are
isotropic; no path rows without a path; table nodes only over the angles the sea pixels span; no
autograd graph when nothing requires grad; per-pixel temporaries for ``chunk`` images at a time
(a batch of 64 512×640 images fits in a few times its output).
"""

from __future__ import annotations

import math
import os
import threading
from dataclasses import dataclass, replace
from functools import lru_cache
from numbers import Integral, Real
from typing import Any, Callable

import numpy as np
import torch
import torch.nn.functional as F
from kornia.geometry.camera import PinholeCamera

from ._parallel import map_chunks, one_thread
from ._pixels import table_grid
from ._validation import check_finite_range, per_batch
from .expectation import Quadrature, _reflection_terms, apparent_radiance
from .clutter import TextureTable
from .geometry import EARTH_RADIUS_M, CameraGeometry, ViewGeometry, view_geometry
from .optics import band_refractive_index, split_refractive_index
from .radiometry import LWIR, SpectralBand, as_band, band_radiance, brightness_temperature
from .atmosphere import as_sky
from .sky import ConstantSky, TabulatedSky, select_sky
from .slopes import SlopeStatistics
from .waves import MAX_WIND_DIRECTION, _seeds, check_time

__all__ = ["SeaScene", "render", "SeaRenderer", "TableSize"]

DEFAULT_CHUNK = 4  # images per chunk of an expectation render (render's ``chunk``; textured scenes: 1)


def _cached_one(cache: dict, key: Any, load: Any) -> Any:
    """``cache[key]``, made by ``load()`` when missing and then the cache's only entry; under a lock,
    since renders of one scene may run side by side (``augmentation._render_frames``) and the
    value is returned as made, never read back after another thread's fill."""
    with _CACHE_LOCK:
        value = cache.get(key)
        if value is None:
            value = load()
            cache.clear()
            cache[key] = value
    return value


def images_per_chunk(scene: Any, chunk: Any = None) -> Any:
    """Images per chunk of pixels: ``chunk`` if given (render checks it), else 1 for a textured scene
    (its per-pixel work holds a dozen more full-size temporaries) and ``DEFAULT_CHUNK`` otherwise."""
    return chunk if chunk is not None else 1 if scene.seed is not None else DEFAULT_CHUNK


_CACHE_LOCK = threading.RLock()  # SeaScene's caches (skies, wave fields), filled from worker threads


def check_foam(foam: Any, per_image: bool = True) -> Any:
    """``SeaScene``'s ``foam`` argument, normalized (``None`` for none), or a ``ValueError``: ``"auto"``,
    ``False``/``None``, or a whitecap fraction in [0, 1] (a float, or (B,) with ``per_image``). ``True``
    is refused: it read as a fraction of 1 (a sea all foam), where "on" means ``"auto"``."""
    if foam is None or foam is False:
        return None
    if foam is True or (isinstance(foam, (torch.Tensor, np.ndarray)) and foam.dtype in (torch.bool, np.bool_)):
        raise ValueError("foam must be 'auto' (whitecaps from the wind), False or a fraction in [0, 1]; got True "
                         "(a bool: use 'auto' for whitecaps, 1.0 for a sea all foam)")
    if isinstance(foam, str):
        if foam != "auto":
            raise ValueError(f"foam must be 'auto', False or a fraction in [0, 1]; got {foam!r}")
        return foam
    check_finite_range("foam", foam, 0.0, 1.0)
    if not per_image and (isinstance(foam, (list, tuple)) or (isinstance(foam, (torch.Tensor, np.ndarray)) and foam.ndim > 0)):
        raise ValueError(f"foam: one setting for every image ('auto', False or a float in [0, 1]); got {foam!r} "
                         "(per-image fractions belong in a SeaScene)")
    return foam


class SeaScene:
    """What is in front of the cameras, one value per image (floats or tensors of shape (B,)).

    Args:
        slopes: explicit :class:`SlopeStatistics` (fields of shape () or (B,)); or
        wind_speed: W [m s⁻¹] at 12.5 m → Cox–Munk slopes (``anisotropic`` selects the law).
        wind_direction: world azimuth of the upwind axis x_s [rad] (from +x towards +y), in
            [−MAX_WIND_DIRECTION, MAX_WIND_DIRECTION] = [−1e6, 1e6] (as ``WaveField``).
        sea_temperature: T_sea [K] → R_B = band radiance; or
        sea_radiance: R_B [W m⁻² sr⁻¹] directly.
        band: sensor band (λ_lo, λ_hi) [m] or :class:`~roughsea_torch.radiometry.SpectralBand`.
        response: relative spectral response (see ``SpectralBand``).
        sky: sky radiance: callable of cos(zenith), (zenith, radiance) table, ``TabulatedSky``
            (radiance (Nz,) or one table per image (B, Nz)), constant or (B,) tensor, or the name
            of a shipped LOWTRAN7 atmosphere (``"midlatitude_summer"``, the default).
        refractive_index: sea index n + i k; default: water (Hale & Querry) averaged over the band
            with Planck(T_sea) × response weights (the paper's choice).
        shadowing: Eq. 5 (True) or Eq. 7.
        path: the air between sea and sensor: radiance at the sensor = τ · R_a + L_path per sea pixel,
            from its slant range and the camera's altitude (``roughsea_torch.atmosphere.load_path``;
            a camera outside the tables' 2 m – 5 km is a ``ValueError`` at render time; ranges
            beyond the tables, on a flat sea, are held at the horizon's). ``None`` (default): on
            whenever ``sky`` is a named atmosphere, off otherwise; ``False``: off; ``True`` or a name
            or an ``AtmosphericPath``: on. On by default because it matters at every range a sea
            scene spans: LWIR midlatitude summer from 20 m, τ = 0.95 at 100 m, 0.75 at 1 km, 0.05 at
            the 16 km horizon, shifting a 290 K sea by +0.2 K, +1.1 K, +4.0 K (more than a typical
            NETD of 0.05 K beyond ~20 m). With the path on, sky pixels see the sky from the camera's
            altitude (``roughsea_torch.atmosphere.load_observer_sky``): rays just above the
            depressed horizon cross the same ~16 km of surface air (from 20 m) as the sea's horizon
            row, so the image is continuous across the horizon; with it off, the sky seen from sea
            level along their ray.
        air_temperature: T_air [K] of the surface air, float or (B,); only with a named atmosphere
            (default ``None``: the atmosphere's own, e.g. 294.2 K for midlatitude summer). The
            atmosphere's temperature profile is taken as shifted so that its surface air is at
            T_air; sky and path radiance are scaled by B(T_air) / B(T_atm) (band radiances). That
            is exact where the air is optically thick (the horizon sky, long paths: radiance
            → B(T_air)) and first-order right for thin emission from near-surface air (the LWIR
            window's water vapour); it does not change the transmittance.
        seed: ``None`` (default): the expectation image, the mean over the sea's slope statistics.
            An int (Python or numpy integer, or a 0-D integer tensor), or one int per image (a
            sequence, (B,) integer tensor or array of exactly B ints; a ``ValueError`` otherwise),
            each in [0, 2**63): a textured sea, that realization of a
            :class:`~roughsea_torch.waves.WaveField` (Elfouhaily spectrum at ``wind_speed``, so
            ``wind_speed=`` is needed), rendered two-scale
            (:mod:`roughsea_torch.clutter`): waves longer than a pixel's footprint are geometry,
            the rest stays in the expectation with the slope covariance left over. With one int
            for B > 1 images, image i gets the seed derived from (seed, i); give one seed per
            image for frames that do not depend on how a batch is split.
        time_s: time of the realization [s], float or (B,) tensor, finite and in
            [−MAX_TIME_S, MAX_TIME_S] = [−1e9, 1e9] s (the range ``WaveField.sample`` accepts; checked
            whenever it is set); waves move by their dispersion relation, so one seed at successive
            times is a coherent clip.
        sun: ``None`` (default, night or an overcast sun) or a :class:`~roughsea_torch.sun.Sun`
            whose ``azimuth`` is a WORLD azimuth [rad] (from +x towards +y, like the camera's yaw)
            and ``irradiance`` the direct irradiance at the surface in the scene's band [W m⁻²]
            (fields float or (B,)): its glint is added to the sea pixels (after the path's
            transmittance); the sky stays the scene's ``sky``. On textured seas each pixel's glint is
            that of its own unresolved slopes about its resolved slope.
        sun_zenith, sun_azimuth: instead of ``sun=``, the sun's apparent zenith [rad] and world azimuth
            [rad] (floats or (B,)); its direct irradiance then comes from the shipped LOWTRAN7 table
            of the named atmosphere in the scene's band (:func:`roughsea_torch.solar.load_solar_irradiance`;
            a named ``sky`` is needed). :func:`roughsea_torch.solar.sun_position` gives them from a
            date, time and place (pvlib); note its azimuth is from north, clockwise. The sky
            then gains the sunlight that the air's aerosol scatters into it (``aerosol``).
        aerosol: the aerosol of a scene lit through ``sun_zenith=`` (LOWTRAN7's 23 km models:
            ``"maritime"``, default, or ``"rural"``; ``None``: none): it dims the sun's beam and
            scatters sunlight into the sky (:mod:`roughsea_torch.daysky`), which the sky pixels show
            in full (by view zenith and azimuth from the sun) and the sea reflects, each reflected
            ray taken at the mirror azimuth of its pixel's view (rays spread about it by the
            slopes; the sky term of Eq. 10 integrates over zenith only). The thermal sky keeps
            its tables (no aerosol). Not used with ``sun=`` or a sky that is not a named atmosphere.
        sun_masking: Smith's masking of the facets from the sun's side (default True).
        sky_masking: Smith's masking of the reflected ray on the sky term (default False, the paper's
            model; Mitsuba 3's rough surfaces include it): its masked part sees the sea.
        foam: the whitecap fraction of the sea surface: ``"auto"`` (default: Monahan &
            O'Muircheartaigh's (1980) law at ``wind_speed``, for thermal-infrared bands; none with
            ``slopes=`` or another band), a number or (B,) tensor in [0, 1], or ``False``. Foam is an
            area fraction of nearly diffuse, more emissive surface (:mod:`roughsea_torch.foam`):
            pixel = (1 − f) · sea + f · foam. In the expectation image f is the same everywhere; a
            textured sea (``seed=``) puts it on the breaking crests, a fraction f_pix per pixel from
            the resolved waves (:func:`roughsea_torch.foam.crest_foam_fraction`; its mean over
            realizations is f, and it is f where the pixel resolves no waves), and mixes
            pixel = (1 − f_pix) · (sea + texture + glint) + f_pix · foam.

    Example:
        >>> scene = SeaScene(wind_speed=torch.tensor([3.0, 12.0]), wind_direction=0.5,
        ...                  sea_temperature=290.0, sky=lambda c: 10.0 + 20.0 * (1 - c) ** 6)
        >>> scene.batch_size
        2
    """

    def __init__(
        self,
        *,
        slopes: SlopeStatistics | None = None,
        wind_speed: Any = None,
        anisotropic: bool = True,
        wind_direction: Any = 0.0,
        sea_temperature: Any = None,
        sea_radiance: Any = None,
        band: Any = LWIR,
        response: Any = None,
        sky: Any = "midlatitude_summer",
        refractive_index: Any = None,
        shadowing: bool = True,
        path: Any = None,
        air_temperature: Any = None,
        seed: Any = None,
        time_s: Any = 0.0,
        sun: Any = None,
        sun_zenith: Any = None,
        sun_azimuth: Any = 0.0,
        sun_masking: bool = True,
        sky_masking: bool = False,
        foam: Any = "auto",
        aerosol: Any = "maritime",
    ):
        if (slopes is None) == (wind_speed is None):
            raise ValueError("SeaScene: give exactly one of slopes= or wind_speed=")
        if (sea_temperature is None) == (sea_radiance is None):
            raise ValueError("SeaScene: give exactly one of sea_temperature= or sea_radiance=")
        if wind_speed is not None:
            check_finite_range("wind_speed", wind_speed, 0.0, 80.0, unit="m/s")
            slopes = SlopeStatistics.cox_munk(wind_speed, anisotropic=anisotropic)
        if not isinstance(slopes, SlopeStatistics):
            raise ValueError(f"slopes must be a SlopeStatistics; got {type(slopes).__name__}")
        check_finite_range("wind_direction", wind_direction, -MAX_WIND_DIRECTION, MAX_WIND_DIRECTION, unit="rad")
        if sea_temperature is not None:
            check_finite_range("sea_temperature", sea_temperature, 200.0, 350.0, unit="K")
        if sea_radiance is not None:
            check_finite_range("sea_radiance", sea_radiance, 0.0, unit="W m-2 sr-1")
        self.slopes = slopes
        self.wind_speed = wind_speed
        self.wind_direction = wind_direction
        self.sea_temperature = sea_temperature
        self.sea_radiance = sea_radiance
        self.band: SpectralBand = as_band(band, response)
        self.atmosphere = sky if isinstance(sky, str) else None
        if self.atmosphere is not None:  # a shipped LOWTRAN7 atmosphere, integrated over this band
            from .atmosphere import load_sky

            sky = load_sky(self.atmosphere, (self.band.lo, self.band.hi), self.band.response, dtype=torch.float64)
        self.sky = as_sky(sky)
        if path is None:
            path = self.atmosphere is not None
        if path is True:
            if self.atmosphere is None:
                raise ValueError("path=True needs a named atmosphere: give sky='<name>' or path='<name>'")
            path = self.atmosphere
        if isinstance(path, str):
            from .atmosphere import load_path

            path = load_path(path, (self.band.lo, self.band.hi), self.band.response, dtype=torch.float64)
        if path is not False and not callable(path):
            raise ValueError(f"path must be None, a bool, an atmosphere name or an AtmosphericPath; got {path!r}")
        self.path = path or None
        self._observer_skies: dict[Any, Any] = {}
        if air_temperature is not None:
            if self.atmosphere is None:
                raise ValueError("air_temperature needs a named atmosphere (sky='<name>'); scale a custom sky yourself")
            check_finite_range("air_temperature", air_temperature, 200.0, 350.0, unit="K")
            from .atmosphere import surface_air_temperature

            self._atmosphere_air_temperature = surface_air_temperature(self.atmosphere)
        self.air_temperature = air_temperature
        self.refractive_index = refractive_index
        self.shadowing = shadowing
        if seed is not None:
            if wind_speed is None:
                raise ValueError("seed: a textured sea needs wind_speed= (the wave spectrum is driven by the wind); "
                                 "seed=None renders the expectation image of slopes=")
            parsed = _seeds(seed)  # WaveField's check: ints in [0, 2**63), numpy integers too
            seed = parsed.values[0] if parsed.single else list(parsed.values)
        self.time_s = time_s  # checked by its setter
        if sun is not None:
            from .sun import Sun

            if not isinstance(sun, Sun):
                raise ValueError(f"sun must be None or a roughsea_torch.Sun; got {type(sun).__name__}")
        if sun_zenith is not None:
            if sun is not None:
                raise ValueError("SeaScene: give sun= or sun_zenith= (with sun_azimuth=), not both")
            if self.atmosphere is None:
                raise ValueError("sun_zenith: the sun's irradiance comes from a named atmosphere's LOWTRAN7 table; "
                                 "give sky='<name>', or sun=rs.Sun(zenith, azimuth, irradiance) with your own irradiance")
            check_finite_range("sun_zenith", sun_zenith, 0.0, math.pi, unit="rad")
            check_finite_range("sun_azimuth", sun_azimuth, unit="rad")
        if aerosol is not None:
            from .daysky import AEROSOLS

            if aerosol not in AEROSOLS:
                raise ValueError(f"aerosol must be None or one of {list(AEROSOLS)}; got {aerosol!r}")
        self.aerosol = aerosol
        self._day_skies: dict[Any, Any] = {}
        self._sun_cache: tuple | None = None
        self._sun = sun
        self.sun_zenith, self.sun_azimuth = sun_zenith, sun_azimuth
        self.sun_masking = sun_masking
        self.sky_masking = bool(sky_masking)
        self.foam = check_foam(foam)
        self.seed = seed
        self._wave_fields: dict[Any, Any] = {}

    @property
    def time_s(self) -> Any:
        """Time of the realization [s]: a float or (B,) tensor/array in [−MAX_TIME_S, MAX_TIME_S]."""
        return self._time_s

    @time_s.setter
    def time_s(self, value: Any) -> None:  # checked on every assignment (render_clip sets each frame's)
        if isinstance(value, (list, tuple)):
            raise ValueError("time_s: give a float or a tensor of shape (B,), one time per image; got a "
                             f"{type(value).__name__} (use torch.tensor(...))")
        check_time("time_s", value)
        if isinstance(value, (torch.Tensor, np.ndarray)) and value.ndim > 1:
            raise ValueError(f"time_s: must be a float or a tensor of shape (B,); got shape {tuple(value.shape)}")
        self._time_s = value

    @property
    def sun(self) -> Any:
        """The scene's :class:`~roughsea_torch.sun.Sun` (world azimuth), or None: the one given, or one
        at ``sun_zenith``/``sun_azimuth`` with the named atmosphere's LOWTRAN7 direct irradiance in
        the scene's band (read each time, so it follows the scene's current fields)."""
        if self._sun is not None or self.sun_zenith is None:
            return self._sun
        from .solar import load_solar_irradiance
        from .sun import Sun

        z = self.sun_zenith
        # the renderer reads the sun many times a call: keep the last one, keyed by the fields' values
        # (not when the zenith requires grad: its irradiance must join the caller's graph)
        grad = isinstance(z, torch.Tensor) and z.requires_grad
        key = None if grad else (self.atmosphere, self.aerosol, torch.is_inference_mode_enabled(),
                                 (z.dtype, z.device, tuple(z.detach().flatten().tolist())) if isinstance(z, torch.Tensor)
                                 else float(z))
        cached = self._sun_cache  # (band, key, irradiance): the band compared by identity (it is kept alive)
        if key is not None and cached is not None and cached[0] is self.band and cached[1] == key:
            irr = cached[2].clone() if isinstance(cached[2], torch.Tensor) else cached[2]
        else:
            e = load_solar_irradiance(self.atmosphere, (self.band.lo, self.band.hi), self.band.response,
                                      aerosol=self.aerosol)
            zt = z.double() if isinstance(z, torch.Tensor) else torch.tensor(float(z), dtype=torch.float64)
            irr = e(zt)
            if isinstance(z, torch.Tensor):
                irr = irr.to(z.dtype)
            self._sun_cache = None if key is None else (self.band, key, irr.clone() if isinstance(irr, torch.Tensor) else irr)
        return Sun(z, self.sun_azimuth, irr if isinstance(z, torch.Tensor) else float(irr))

    @sun.setter
    def sun(self, value: Any) -> None:
        self._sun, self.sun_zenith = value, None

    @property
    def day_sky(self) -> Any:
        """The solar-scattered sky (:class:`roughsea_torch.daysky.ScatteredSky`) of a scene lit
        through ``sun_zenith=`` with a named atmosphere and an ``aerosol``; else None."""
        if self.sun_zenith is None or self._sun is not None or self.atmosphere is None or self.aerosol is None:
            return None
        from .daysky import load_scattered_sky

        return _cached_one(self._day_skies, (self.atmosphere, self.aerosol, self.band), lambda: load_scattered_sky(
            self.atmosphere, (self.band.lo, self.band.hi), aerosol=self.aerosol, response=self.band.response))

    @property
    def observer_sky(self) -> Any:
        """The sky of the sky pixels when it is seen from the camera's altitude: with a named
        atmosphere and its own path on (``atmosphere.load_observer_sky``), continuous with the
        sea's horizon row (rays between the horizon dip and the horizontal cross the same lowest
        air); else None (the sky seen from sea level). Follows the scene's current fields."""
        if self.atmosphere is None or self.path is None or getattr(self.path, "name", None) != self.atmosphere:
            return None
        from .atmosphere import load_observer_sky

        return _cached_one(self._observer_skies, (self.atmosphere, self.band),
                           lambda: load_observer_sky(self.atmosphere, self.band, dtype=torch.float64))

    @property
    def batch_size(self) -> int:
        sizes = {
            int(v.shape[0])
            for v in (
                self.slopes.var_upwind, self.slopes.var_crosswind, self.slopes.cov, self.wind_direction,
                self.sea_temperature, self.sea_radiance, self.air_temperature, self.time_s,
            )
            if isinstance(v, torch.Tensor) and v.ndim > 0
        }
        if isinstance(self.seed, list):  # one seed per image: a list of 1 is a batch of 1, not a broadcast
            if len(sizes) == 1:
                self.seeds(next(iter(sizes)))  # ValueError naming seed, B and its length if they differ
            sizes.add(len(self.seed))
        if len(sizes) > 1:
            raise ValueError(f"SeaScene: fields disagree on the batch size: {sorted(sizes)}")
        return sizes.pop() if sizes else 1

    def seeds(self, B: int) -> list[int]:
        """One seed per image: the given ones (exactly B of them), or for one int ``seed`` with B > 1
        images, image i's from numpy's ``SeedSequence((seed, i))``."""
        if isinstance(self.seed, list):
            if len(self.seed) != B:
                raise ValueError(f"seed: a sequence of seeds needs one per image, B = {B}; got {len(self.seed)} "
                                 "(give B seeds, or one int seed for seeds derived per image)")
            return list(self.seed)
        if B == 1:
            return [int(self.seed)]
        return [int(np.random.SeedSequence((int(self.seed), i)).generate_state(1, np.uint64)[0] >> 1) for i in range(B)]

    def wave_field(self, B: int, dtype: torch.dtype, device: torch.device, sl: slice = slice(None),
                   min_band_share: float | None = None) -> Any:
        """The :class:`~roughsea_torch.waves.WaveField` of images ``sl`` (textured scenes only),
        without the bands that carry less than ``min_band_share`` of an image's slope variance and
        of its crest variable's (default ``TableSize.texture_min_band_share``, 1e-8). The last 64 (per group of images the
        renderer asks for) are kept while the scene's wind, direction and seed are unchanged (their
        random amplitudes are drawn once)."""
        from .waves import WaveField

        wind = per_batch("wind_speed", self.wind_speed, B, dtype, device)[sl]
        wd = per_batch("wind_direction", self.wind_direction, B, dtype, device)[sl]
        seeds = self.seeds(B)[sl]
        share = TableSize.texture_min_band_share if min_band_share is None else float(min_band_share)
        key = (tuple(seeds), tuple(wind.detach().cpu().tolist()), tuple(wd.detach().cpu().tolist()), dtype, str(device),
               share, wind.requires_grad or wd.requires_grad)
        wf = self._wave_fields.get(key)
        if wf is None or key[-1]:
            wf = WaveField(wind, seeds, wind_direction=wd, dtype=dtype, device=device, min_band_share=share)
            if not key[-1]:
                with _CACHE_LOCK:  # chunks of a textured render fill it from worker threads
                    if len(self._wave_fields) >= 64:
                        self._wave_fields.pop(next(iter(self._wave_fields)))
                    self._wave_fields[key] = wf
        return wf

    def resolved(self, B: int, dtype: torch.dtype, device: torch.device) -> dict[str, Any]:
        """Per-image tensors (B,): a², b², r a b, wind direction, R_B, n, k; and the sky."""
        own = self.batch_size
        if own not in (1, B):
            raise ValueError(f"SeaScene has batch size {own} but the cameras have {B}")
        if isinstance(self.seed, list):
            self.seeds(B)  # exactly B seeds, checked before any work
        vx, vy, cxy = (per_batch("slopes", v, B, dtype, device) for v in self.slopes.tensors(dtype, device))
        wd = per_batch("wind_direction", self.wind_direction, B, dtype, device)
        if self.sea_radiance is not None:
            rb = per_batch("sea_radiance", self.sea_radiance, B, dtype, device)
        else:
            t_sea = per_batch("sea_temperature", self.sea_temperature, B, dtype, device)
            rb = band_radiance(t_sea, self.band)
        m = self.refractive_index
        if m is None:  # the band-effective water index at each image's sea temperature (a lookup)
            t_idx = t_sea if self.sea_radiance is None else brightness_temperature(rb.clamp_min(1e-30), self.band)
            m = _band_index(self.band, t_idx.double())
        n, k = split_refractive_index(m, dtype, device)
        air_scale = None
        if self.air_temperature is not None:  # B(T_air) / B(T_atm): scales sky and path radiance
            t_air = per_batch("air_temperature", self.air_temperature, B, dtype, device)
            t_atm = torch.tensor(self._atmosphere_air_temperature, dtype=dtype, device=device)
            air_scale = band_radiance(t_air, self.band) / band_radiance(t_atm, self.band)
        # "sky" is the atmosphere's own; R_a is linear in the sky radiance, so the renderer
        # scales the reflected-sky term T_s and the sky pixels by air_scale instead of
        # interpolating one scaled sky table per image
        foam = None
        if self.foam == "auto":
            centre = 0.5 * (self.band.lo + self.band.hi)
            if self.wind_speed is not None and (2.5e-6 <= centre <= 6e-6 or 7e-6 <= centre <= 15e-6):
                from .foam import whitecap_fraction

                foam = whitecap_fraction(per_batch("wind_speed", self.wind_speed, B, dtype, device))
        elif self.foam is not None:
            foam = per_batch("foam", self.foam, B, dtype, device)
        if foam is not None and not bool((foam > 0).any()):
            foam = None  # no foam anywhere: leave it out
        return dict(vx=vx, vy=vy, cxy=cxy, wind_direction=wd, rb=rb, n=n.expand(B), k=k.expand(B), sky=self.sky, foam=foam,
                    air_scale=air_scale)


_INDEX_T0, _INDEX_DT, _INDEX_NT = 180.0, 2.0, 91  # the band-index table: 180-360 K every 2 K


@lru_cache(maxsize=16)
def _band_index_table(band: SpectralBand) -> tuple[torch.Tensor, torch.Tensor]:
    """n and k of the band-effective water index at 180–360 K every 2 K, (2, N_T), and their
    T-derivatives at the nodes, (2, N_T): 4th-order centred differences (2nd-order one-sided at the
    ends; the fit is smooth in T)."""
    t = _INDEX_T0 + _INDEX_DT * torch.arange(_INDEX_NT, dtype=torch.float64)
    m = band_refractive_index(band, t)
    y = torch.stack([m.real, m.imag])
    d = torch.empty_like(y)
    d[:, 2:-2] = (y[:, :-4] - 8 * y[:, 1:-3] + 8 * y[:, 3:-1] - y[:, 4:]) / (12 * _INDEX_DT)
    d[:, 1], d[:, -2] = (y[:, 2] - y[:, 0]) / (2 * _INDEX_DT), (y[:, -1] - y[:, -3]) / (2 * _INDEX_DT)
    d[:, 0] = (-3 * y[:, 0] + 4 * y[:, 1] - y[:, 2]) / (2 * _INDEX_DT)
    d[:, -1] = (3 * y[:, -1] - 4 * y[:, -2] + y[:, -3]) / (2 * _INDEX_DT)
    return y, d


def _band_index(band: SpectralBand, temperature: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
    """The band-effective water index (n, k) at T_sea [K] (a float64 tensor, any shape):
    ``band_refractive_index`` tabulated every 2 K over 180–360 K per band and read by a cubic
    Hermite interpolant, differentiable in T (within 1e-8 of the direct fit; a fit costs ~20 ms,
    a lookup ~0.1 ms). Its T-derivative is the interpolant's, so the gradient of an image with
    respect to the sea temperature includes how the Planck weights of the band move the index."""
    try:
        y, d = _band_index_table(band)
    except TypeError:  # a band with an unhashable response (e.g. arrays): fit directly
        m = band_refractive_index(band, temperature)
        return m.real, m.imag
    y, d = y.to(temperature.device), d.to(temperature.device)
    f = ((temperature - _INDEX_T0) / _INDEX_DT).clamp(0.0, _INDEX_NT - 1.0)
    i = f.detach().floor().long().clamp(max=_INDEX_NT - 2)
    s = f - i
    s2, s3 = s * s, s * s * s
    h00, h10, h01, h11 = 2 * s3 - 3 * s2 + 1, s3 - 2 * s2 + s, 3 * s2 - 2 * s3, s3 - s2
    out = h00 * y[:, i] + h10 * _INDEX_DT * d[:, i] + h01 * y[:, i + 1] + h11 * _INDEX_DT * d[:, i + 1]
    return out[0], out[1]


@dataclass(frozen=True)
class TableSize:
    """Nodes of the per-image table (Chebyshev–Lobatto) and of its fine resampling.

    Args:
        zenith: nodes in ζ = asinh(cos θ̂/ε).
        azimuth: nodes in relative azimuth (anisotropic slopes only).
        azimuth_thin: nodes in relative azimuth when some image's slope ellipse is thin (minor/major
            rms slope < 0.2: Cox–Munk below ~0.04 m/s, |r| near 1): R_a then changes sharply with
            azimuth at grazing views (views along the wind at W = 0: 2e-4 with 9 nodes, 1.5e-6 with
            33, folded; ``tests/test_render.py``).
        zenith_thin: nodes in ζ when a slope ellipse is thin (its grazing layer then changes
            sharply with azimuth, and the spans read from the cameras' border start at the
            horizon, ζ = 0): W = 0 along the wind, 1.3e-4 with 21 nodes, 7e-6 with 41.
        azimuth_day: nodes in relative azimuth when the sea reflects a scattered daytime sky
            (``SeaScene(aerosol=)``): it has the aerosol's forward-scattering peak about the sun and is
            tabulated piecewise linearly in azimuth (:mod:`roughsea_torch.daysky`), so Chebyshev
            nodes converge slowly: MWIR, sun 20° up ahead, 20 m mast at 2° down, against per-pixel
            evaluation: 7 nodes 1.9e-3, 13 2.3e-4, 25 3.7e-5. A render with every azimuth in view
            (looking down at the nadir), or with ``span="full"``, takes 2·azimuth_day − 1 nodes and
            twice ``fine_azimuth`` columns, and its texture 4·(texture_azimuth_sun − 1) + 1 nodes and
            four times ``fine_texture_azimuth`` (``tests/test_sun.py``).
        zenith_narrow: nodes in ζ when some image's slope ellipse is narrow but not thin (minor/major
            rms slope < 0.5: Cox–Munk below ~0.3 m/s): views along the wind at W = 0.05 m/s,
            2.9e-5 with 17 nodes, 1.4e-5 with 21.
        glint: Chebyshev–Lobatto nodes per axis (ζ, azimuth) of the glint's smooth factor L_sun G1 / D
            (sunny scenes without texture whose table runs over the unfolded azimuth: every scene lit
            through ``sun_zenith=`` with an aerosol, or with correlated slopes); each pixel applies
            the sharp factor P ρ t itself (the sun's ellipse probability in slope space, Fresnel and
            facet cosine at the facets that mirror the sun). An image whose table misses
            ``glint_tolerance`` of the radiance at the fine cells' centres (checked against direct
            evaluation) keeps the whole glint per pixel. In float32 the check measures float32
            evaluations, so it bounds the table's error only down to float32's own rounding of the
            glint (which near the horizon exceeds 1e-5 of the radiance at low sun and calm seas).
        glint_tolerance: see ``glint``.
        fine_zenith, fine_azimuth: rows/columns of the fine table read by ``grid_sample``.
        fine_azimuth_thin: columns of the fine table when a slope ellipse is thin (64 columns leave
            views along the wind at W = 0 at 3e-5, 128 at 7e-6).
        fine_sky: rows of the sky block of the fine table, evenly spaced in the cosine of the ray's
            zenith over the span of the image's sky pixels.
        span: ``"pixels"`` (default): nodes only over the angles the image's sea pixels span;
            ``"full"``: over every angle (θ̂ in [0°, 90°], every azimuth), for comparison.
        texture_zenith: ζ nodes of the texture (the mean table's ``zenith`` is too few for it: 21
            left 5 % of the texture's amplitude, 33 leave 0.6 %; ``tests/test_clutter.py``).
        texture: nodes in x = a/σ_a, the flat-point quantile of the resolved along-view slope
            (textured scenes, :mod:`roughsea_torch.clutter`), Chebyshev–Lobatto over
            ±``texture_width``; beyond it (|x| > 4.5: 7e-6 of the pixels) the border value.
        texture_zenith_sun: ζ nodes of the texture of a sunny scene, whose volume also carries the
            visible quantile x' = a'/σ_a of each pixel's unresolved Gaussian for the glint (read per
            pixel instead of inverted per pixel): an MWIR sea, sun 15° up ahead, against per-pixel
            evaluation: 3.8e-4 with 33 nodes, 4.8e-5 with 65 (``tests/test_sun.py``).
        texture_azimuth_sun: azimuth nodes of the texture of a sunny scene (its own, on the mean
            table's span; the mean takes ``azimuth_day`` for the scattered sky): against per-pixel
            evaluation on ten 48×64 sunny scenes (fields of view 20° and 70°, MWIR and LWIR), 9
            nodes leave the same error as 25 (the largest change 1.3e-4 of the texture's amplitude)
            and cost 0.6× the time.
        fine_texture, fine_texture_zenith, fine_texture_azimuth: the fine texture volume
            (x, ζ, azimuth) read trilinearly per sea pixel (two bilinear ``grid_sample`` and a lerp).
        texture_quadrature: (outer, inner) Gauss–Legendre nodes of the model at the texture nodes
            (the departure from the mean is the difference of two evaluations on this rule). Against
            per-pixel evaluation on seven 48×64 scenes (altitudes 3–200 m, winds 3–20 m/s, two
            sunny), as a share of the texture's amplitude: (12, 16) 2e-4 to 1.8e-2, as (20, 16)
            (2e-4 to 2.8e-2); (10, 16) up to 5.3e-2, (16, 12) up to 2.8e-2 and 9e-3 where (12, 16)
            has 1.7e-3. The x nodes (``texture``) set the worst case: 11 bring 2.8e-2 to 1.1e-2.
            Under a LOWTRAN day sky (``sun_zenith=``), glint pixels reflect the aureole about the
            sun and the departure is sharp in slope and azimuth: an MWIR sea then sits 7e-4 of
            the radiance from a converged per-pixel render; ``texture_quadrature=(20, 16)``,
            ``texture_azimuth_sun=17`` and ``fine_texture_azimuth=64`` together bring it to
            2.4e-4 (the first alone 4.5e-4, the other two 6.9e-4) at 1.7× the time of a textured
            day render (``tests/test_sun.py``, ``docs/bench_texture.md``).
        texture_quadrature_steep, texture_steep_zenith_deg: the rule of the texture nodes whose view
            zenith θ̂ is below ``texture_steep_zenith_deg`` [deg]. Looking steeply down, the texture is
            a few mK while the shifted Gaussians are narrow and reach the edge of the
            sky-reflecting disc: (12, 16) left up to 3.4e-3 K against per-pixel evaluation at 15–20 m/s
            (θ̂ < 35°, LWIR), (16, 16) 4e-4 K; from θ̂ ≈ 40° the two agree (``tests/test_clutter.py``).
        texture_quadrature_width: half-width [standard deviations] of the Gaussian window of the
            texture nodes' rule (the render's quadrature's, if narrower). The default model's 7.5
            (float64) is too wide for a 12-node rule: Gauss–Legendre on ±7.5σ misses 1 % of a
            Gaussian's mass, on ±4.5σ 1e-5 (the window drops 7e-6); looking straight down at 8 m/s
            the texture was then 0.11 K off per-pixel evaluation (float64; 0.015 K in float32, whose
            window is 6σ) against 2e-4 K now. Grazing views, where the texture is tens of mK: their
            error against per-pixel evaluation changed by 2e-4 K at most (the sweep of
            ``pipelines/texture_accuracy.py`` before and after), the images themselves by up to
            4e-3 K (20 m, pitch −20°, 3 m/s).
        texture_min_band_share: per image, the octaves of the wave field that carry less than this
            share of its slope variance (and of its crest variable's) are left out of the
            realization, their variance left to the unresolved statistics (``WaveField(...,
            min_band_share=)``): on the spectrum's low-k flank far below the peak of a light wind.
            1e-8 skips a fifth of the band lookups of the README's batch; it moves a realization by
            up to 3e-5 of the radiance (two 96×128 images, 6 and 14 m/s) to 6e-5 (eight of the
            benchmark's poses at 128×160), in the rows at the horizon, where a footprint resolves
            only the longest waves and the radiance is most sensitive to slope (1e-6 would skip
            29 % and move it by 1e-4 and 7e-4 on the same images). 0 keeps every band.

    The defaults: 17 zenith nodes are as accurate as 21 (``pipelines/accuracy_pareto.py``, renderer
    panel: 1.2e-6 against per-pixel evaluation over 9276 cases, W 2–40 m/s); 3072 fine rows keep the
    wide oblique camera of ``tests/test_render.py`` (2 km, 45° down) at 3e-7, where 2048 leave 2.3e-6.
    """

    zenith: int = 17
    azimuth: int = 7
    fine_zenith: int = 3072
    fine_azimuth: int = 64
    span: str = "pixels"
    azimuth_thin: int = 33
    fine_sky: int = 2048
    zenith_thin: int = 41
    fine_azimuth_thin: int = 128
    texture: int = 9
    texture_zenith: int = 33
    texture_zenith_sun: int = 65
    texture_width: float = 4.5
    fine_texture: int = 129
    fine_texture_zenith: int = 512
    fine_texture_azimuth: int = 16
    texture_quadrature: tuple = (12, 16)
    texture_quadrature_steep: tuple = (16, 16)
    texture_steep_zenith_deg: float = 40.0
    texture_quadrature_width: float = 4.5
    texture_min_band_share: float = 1e-8
    texture_azimuth_sun: int = 9
    zenith_narrow: int = 21
    azimuth_day: int = 25
    glint: int = 33
    glint_tolerance: float = 1e-5

    def __post_init__(self) -> None:
        if self.span not in ("pixels", "full"):
            raise ValueError(f"TableSize.span must be 'pixels' or 'full'; got {self.span!r}")
        for name in ("zenith", "azimuth", "azimuth_thin", "zenith_thin", "zenith_narrow", "azimuth_day", "texture",
                     "texture_zenith", "texture_zenith_sun", "texture_azimuth_sun", "glint"):
            if int(getattr(self, name)) < 2:
                raise ValueError(f"TableSize.{name} must be >= 2")
        for name in ("fine_zenith", "fine_azimuth", "fine_sky", "fine_azimuth_thin", "fine_texture",
                     "fine_texture_zenith", "fine_texture_azimuth"):
            if int(getattr(self, name)) < 4 * _EXT + 2:
                raise ValueError(f"TableSize.{name} must be >= {4 * _EXT + 2}")
        for name in ("texture_quadrature", "texture_quadrature_steep"):
            rule = getattr(self, name)
            if (not isinstance(rule, (tuple, list)) or len(rule) != 2
                    or not all(isinstance(v, Integral) and not isinstance(v, (bool, np.bool_)) and 1 <= v <= 512
                               for v in rule)):
                raise ValueError(f"TableSize.{name} must be (outer, inner), two ints in [1, 512]; got {rule!r}")
            object.__setattr__(self, name, tuple(int(v) for v in rule))  # hashable (tables are cached by it)
        for name, lo, hi in (("texture_steep_zenith_deg", 0.0, 90.0), ("texture_quadrature_width", 1.0, 40.0)):
            v = getattr(self, name)
            if isinstance(v, (bool, np.bool_)) or not isinstance(v, Real) or not lo <= float(v) <= hi:
                raise ValueError(f"TableSize.{name} must be a number in [{lo:g}, {hi:g}]; got {v!r}")
            object.__setattr__(self, name, float(v))
        share = self.texture_min_band_share
        if isinstance(share, bool) or not isinstance(share, (int, float)) or not 0.0 <= float(share) < 1.0:
            raise ValueError(f"TableSize.texture_min_band_share must be a number in [0, 1); got {share!r}")


_EXT = 2  # fine cells beyond each end of the node interval, so no pixel reads the clamped border


@lru_cache(maxsize=32)
def _lobatto_interp(n: int, m: int) -> tuple[np.ndarray, np.ndarray, float]:
    """Chebyshev–Lobatto nodes on [−1, 1] (ascending), the barycentric matrix that evaluates the
    interpolant on m uniform points of [−1 − e, 1 + e], and e.

    The fine grid overhangs the node interval by ``_EXT`` cells so that ``grid_sample`` never
    reads the clamped border for a pixel inside the interval; the overhang is the interpolant
    continued a hair outside [−1, 1].
    """
    if n == 1:
        return np.zeros(1), np.ones((m, 1)), 0.0
    e = 2.0 * _EXT / (m - 1 - 2 * _EXT)
    x = np.cos(np.pi * np.arange(n) / (n - 1))[::-1].copy()
    w = (-1.0) ** np.arange(n)
    w[0] *= 0.5
    w[-1] *= 0.5
    y = np.linspace(-1.0 - e, 1.0 + e, m)
    diff = y[:, None] - x[None, :]
    exact = np.isclose(diff, 0.0, atol=1e-15)
    diff[exact] = 1.0
    L = w / diff
    L = L / L.sum(1, keepdims=True)
    rows = exact.any(1)
    L[rows] = exact[rows].astype(float)
    return x, L, e


def _sky_per_image(sky: Any, B: int, dtype: torch.dtype, device: torch.device, extra_dims: int) -> Any:
    """Reshape a per-image sky (TabulatedSky (B, Nz) or constant (B,)) to broadcast over a table."""
    if isinstance(sky, TabulatedSky) and sky.radiance.ndim > 1:
        r = sky.radiance.to(device=device, dtype=dtype)
        if r.shape[0] != B:
            raise ValueError(f"sky: a batched table needs {B} rows (one per image); got {r.shape[0]}")
        return sky.with_radiance(r.reshape(B, *([1] * extra_dims), r.shape[-1]))
    if isinstance(sky, ConstantSky):
        r = torch.as_tensor(sky.radiance, dtype=dtype, device=device)
        if r.ndim > 0:
            return ConstantSky(r.reshape(B, *([1] * extra_dims)))
    return sky


def _sky_radiance_pixels(sky: Any, cos_z: torch.Tensor) -> torch.Tensor:
    """Sky radiance along rays, cos_z (B, N) → (B, N); below-horizontal rays see the horizon."""
    c = cos_z.clamp(0.0, 1.0)
    if isinstance(sky, ConstantSky):
        r = torch.as_tensor(sky.radiance, dtype=c.dtype, device=c.device)
        return (r.reshape(-1, 1) if r.ndim else r).expand_as(c)
    return sky(c)


def _masked_range(x: torch.Tensor, mask: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
    """Per-image (min, max) of x over mask, (B, H, W) → (B,), detached (±inf where mask is empty)."""
    inf = torch.tensor(math.inf, dtype=x.dtype, device=x.device)
    x = x.detach()
    return torch.where(mask, x, inf).amin((1, 2)), torch.where(mask, x, -inf).amax((1, 2))


def _wrap(x: torch.Tensor) -> torch.Tensor:
    """Angles wrapped into [−π, π)."""
    return torch.remainder(x + math.pi, 2 * math.pi) - math.pi


def _azimuth_centre(dx: torch.Tensor, dy: torch.Tensor, wind_direction: torch.Tensor, mask: torch.Tensor) -> torch.Tensor:
    """Per-image centre c (b,) of the relative azimuths φ̂ = atan2(−dy, −dx) − wind direction of the
    masked pixels: the circular mean of 2φ̂ (period π: R_a(φ̂ + π) = R_a(φ̂)) over a subsample, halved."""
    step = max(1, int(math.sqrt(dx[0].numel() / 4096)))  # ~4096 pixels suffice for a centre
    ps = torch.atan2(-dy[:, ::step, ::step], -dx[:, ::step, ::step]).detach() - wind_direction.detach()[:, None, None]
    m = mask[:, ::step, ::step]
    m = m | ~m.flatten(1).any(1)[:, None, None]  # no sea in the subsample: use all of it
    zero = torch.zeros((), dtype=dx.dtype, device=dx.device)
    return 0.5 * torch.atan2(torch.where(m, torch.sin(2 * ps), zero).sum((1, 2)), torch.where(m, torch.cos(2 * ps), zero).sum((1, 2)))


def _azimuth_coordinate(dx: torch.Tensor, dy: torch.Tensor, offset: torch.Tensor, fold: bool,
                        period: float = math.pi) -> torch.Tensor:
    """The table's azimuth coordinate of each pixel, (b, H, W), from its ray's world x, y components.

    ``fold`` (uncorrelated slopes, ``offset`` = π/2 − wind direction): ψ = |φ̂| folded into
    [0, π/2] by the mirror symmetries R_a(φ̂) = R_a(−φ̂) = R_a(π − φ̂); otherwise (``offset`` =
    π/2 − c − wind direction, c the image's centre azimuth): o = wrap_π(φ̂ − c) + π/2 ∈ [0, π),
    R_a(φ̂ + π) = R_a(φ̂) for a sky the same in every azimuth. Under a day sky, which is not,
    ``period`` = 2π (``offset`` = −c − wind direction): o = wrap_2π(φ̂ − c) + π ∈ [0, 2π)."""
    # atan2(dy, dx) is the ray's azimuth, the LOS's + π: the same modulo π. With the offset wrapped
    # into [0, P) per image, (atan2 + offset)/P + 1 lies in [0, 3): its frac is the remainder
    # (torch.remainder, a floor division, costs ~4x frac on the CPU)
    start = (1.0 + torch.remainder(offset, period) / period).to(dy.dtype)[:, None, None]
    o = torch.frac(torch.atan2(dy, dx).mul_(1.0 / period).add_(start)).mul_(period)
    return (o - math.pi / 2).abs() if fold else o


def _azimuth_ratio(c: torch.Tensor, s: torch.Tensor, fold: bool) -> torch.Tensor:
    """A cheap stand-in u for the table's azimuth coordinate (:func:`_azimuth_coordinate`), from the
    ray's components (any positive scale) along world axes turned by the offset, c ∝ cos(φ + offset),
    s ∝ sin(φ + offset); a few adds and a divide where atan2 and a remainder cost ~8× more on the
    CPU. Folded, ψ = |(φ + offset) mod π − π/2| = atan2(|c|, |s|) and u = sin ψ/(sin ψ + cos ψ)
    ∈ [0, 1]; else o = (φ + offset) mod π = atan2(|s|, c · sign s) and
    u = −cos o/(|cos o| + sin o) ∈ [−1, 1]. Both increase with the angle (:func:`_ratio_of_angle`,
    :func:`_angle_of_ratio`); a vertical ray (c = s = 0) gets u = 0."""
    if fold:
        num = c.abs()
        den = (num + s.abs()).clamp_min_(1e-30)
        return num / den
    num = c * torch.copysign(torch.ones_like(s), s)  # c · sign s (sign +1 at s = +0)
    den = (c.abs() + s.abs()).clamp_min_(1e-30)
    return -num / den


def _ratio_of_angle(t: torch.Tensor, fold: bool) -> torch.Tensor:
    """u of :func:`_azimuth_ratio` at the angle ``t`` (ψ folded, else o)."""
    sn, cs = torch.sin(t), torch.cos(t)
    return sn / (sn + cs) if fold else -cs / (cs.abs() + sn)


def _angle_of_ratio(u: torch.Tensor, fold: bool) -> torch.Tensor:
    """The angle of :func:`_azimuth_ratio`'s u, continued with slope 1 (its slope at both ends)
    beyond u's range (the fine table's overhang)."""
    uc = u.clamp(0.0, 1.0) if fold else u.clamp(-1.0, 1.0)
    ang = torch.atan2(uc, 1.0 - uc) if fold else torch.atan2(1.0 - uc.abs(), -uc)
    return ang + (u - uc)


def _barycentric(x: np.ndarray, t: torch.Tensor) -> torch.Tensor:
    """Matrix (..., m, n) evaluating the interpolant on the Chebyshev–Lobatto nodes ``x`` (n,) at the
    points ``t`` (..., m) of the node coordinate (the batched form of :func:`_lobatto_interp`)."""
    n = len(x)
    w = (-1.0) ** np.arange(n)
    w[0] *= 0.5
    w[-1] *= 0.5
    xt = torch.as_tensor(x, dtype=t.dtype, device=t.device)
    wt = torch.as_tensor(w, dtype=t.dtype, device=t.device)
    diff = t[..., None] - xt
    exact = diff.abs() < 1e-15
    L = wt / torch.where(exact, torch.ones_like(diff), diff)
    L = L / L.sum(-1, keepdim=True)
    hit = exact.any(-1, keepdim=True)
    return torch.where(hit, exact.to(L.dtype), L)




def _fold_range(a: torch.Tensor, b: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
    """Range of ψ = |wrap_π(φ)| (period π, values in [0, π/2]) over φ ∈ [a, b] (lifted, b − a < π)."""
    psi = lambda x: (torch.remainder(x + math.pi / 2, math.pi) - math.pi / 2).abs()  # noqa: E731
    pa, pb = psi(a), psi(b)
    has_zero = torch.ceil(a / math.pi) * math.pi <= b
    has_edge = torch.ceil((a - math.pi / 2) / math.pi) * math.pi + math.pi / 2 <= b
    lo = torch.where(has_zero, torch.zeros_like(a), torch.minimum(pa, pb))
    hi = torch.where(has_edge, torch.full_like(b, math.pi / 2), torch.maximum(pa, pb))
    return lo, hi


@dataclass
class _Ranges:
    """Per-image spans (B,) float64, detached: ζ of the sea pixels, the azimuth coordinate of the sea
    pixels (with the centre c of the unfolded coordinate), and the cosine of the ray's zenith of the
    sky pixels; whether an image has sea / sky pixels."""

    zeta: tuple[torch.Tensor, torch.Tensor]
    sky: tuple[torch.Tensor, torch.Tensor]
    any_sea: torch.Tensor
    any_sky: torch.Tensor
    azimuth: tuple[torch.Tensor, torch.Tensor] | None = None
    centre: torch.Tensor | None = None


def _map_nodes(fn: Any, *vals: Any) -> Any:
    """``fn`` over the tensors of ``_render_table``'s node results (a tensor, a tuple of them, a
    :class:`_Ranges` or None), several results zipped."""
    v = vals[0]
    if v is None:
        return None
    if isinstance(v, _Ranges):
        return _Ranges(**{f: _map_nodes(fn, *(getattr(x, f) for x in vals)) for f in v.__dataclass_fields__})
    if isinstance(v, tuple):
        return tuple(_map_nodes(fn, *z) for z in zip(*vals))
    return fn(*vals)


def _asinh(x: torch.Tensor) -> torch.Tensor:
    return torch.log(x + torch.sqrt(x * x + 1.0))  # 3× faster than torch.asinh on CPU


def _camera_ranges(cg: CameraGeometry, sl: slice, wd: torch.Tensor, inv_eps: torch.Tensor, iso: bool, fold: bool,
                   period: float = math.pi) -> _Ranges:
    """The spans of the images ``sl`` from the rays of their border alone (no per-pixel work).

    cos θ̂ of a sea pixel grows with −dz (the ray's local-vertical component), and dz and the LOS
    azimuth are smooth functions of the ray whose only critical points are the nadir and the zenith:
    over the image they take their extremes on its border, unless a pole is in view. The sea pixels'
    azimuths span those of the sea part of the border plus the horizon arc, which is monotone in
    azimuth between its ends on the border. Spans are widened by one border step (the sampled border
    against the continuous one). Unfolded, the coordinate o = wrap_P(φ̂ − c) + P/2 spans
    P/2 ± half the pixels' span, or all of [0, P] (``period`` P: π, or 2π under a day sky).
    """
    with torch.no_grad():
        dz, dx, dy = (t.double() for t in cg.border(sl))
        nadir, zenith = cg.poles_in_view(sl)
        B = dz.shape[0]
        sh = torch.zeros(B, dtype=torch.float64, device=dz.device) if cg.flat else cg.s_h[sl].double()
        kr = torch.ones_like(sh) if cg.flat else cg.k_r[sl].double()
        dz_min = torch.where(nadir, -torch.ones_like(sh), dz.amin(1))
        dz_max = torch.where(zenith, torch.ones_like(sh), dz.amax(1))
        any_sea = -dz_min > sh
        any_sky = dz_max > -sh - 1e-6

        def zeta(d: torch.Tensor) -> torch.Tensor:  # ζ of the sea point met by a ray of vertical component d
            cos_t = (-d) if cg.flat else kr * torch.sqrt(((-d - sh) * (-d + sh)).clamp_min(0.0))
            return torch.asinh(cos_t.clamp_min(0.0) * inv_eps.double())

        z_hi = zeta(dz_min)
        z_lo = torch.where(any_sky, torch.zeros_like(z_hi), zeta(dz_max))
        s_lo, s_hi = torch.maximum(dz_min, -sh), dz_max
        if iso:
            return _Ranges((z_lo, z_hi), (s_lo, s_hi), any_sea, any_sky)
        # the LOS azimuth along the border, lifted (unwrapped) around the loop
        phi = torch.atan2(-dy, -dx)
        steps = _wrap(torch.roll(phi, -1, 1) - phi)  # step k: from point k to k + 1 (the last closes the loop)
        lifted = torch.cat([phi[:, :1], phi[:, :1] + torch.cumsum(steps[:, :-1], 1)], 1)
        step_max = steps.abs().amax(1)
        sea_b = -dz > sh[:, None]
        inf = torch.tensor(math.inf, dtype=torch.float64, device=dz.device)
        a = torch.where(sea_b, lifted, inf).amin(1) - step_max - wd.double()
        b = torch.where(sea_b, lifted, -inf).amax(1) + step_max - wd.double()
        # a pole in view, a loop that winds around one, or a border too coarse to lift: every azimuth
        full = nadir | zenith | (steps.sum(1).abs() > math.pi) | (step_max > 0.5) | ~sea_b.any(1) | (b - a >= math.pi)
        if fold:
            lo, hi = _fold_range(torch.where(full, torch.zeros_like(a), a), torch.where(full, torch.zeros_like(b), b))
            lo = torch.where(full, torch.zeros_like(lo), lo)
            hi = torch.where(full, torch.full_like(hi, math.pi / 2), hi)
            return _Ranges((z_lo, z_hi), (s_lo, s_hi), any_sea, any_sky, (lo, hi), torch.zeros_like(lo))
        c = torch.where(full, torch.zeros_like(a), 0.5 * (a + b))
        half = 0.5 * (b - a)
        lo = torch.where(full, torch.zeros_like(a), period / 2 - half)
        hi = torch.where(full, torch.full_like(b, period), period / 2 + half)
        return _Ranges((z_lo, z_hi), (s_lo, s_hi), any_sea, any_sky, (lo, hi), c)


def _geometry_ranges(g: ViewGeometry, sl: slice, wd: torch.Tensor, inv_eps: torch.Tensor, iso: bool, fold: bool) -> _Ranges:
    """The spans of the images ``sl`` from a precomputed per-pixel :class:`ViewGeometry`."""
    with torch.no_grad():
        sea, cos, dx, dy = g.is_sea[sl], g.cos_view_zenith[sl], g._dx[sl], g._dy[sl]
        any_sea, any_sky = sea.flatten(1).any(1), (~sea).flatten(1).any(1)
        z = _masked_range(_asinh(cos.clamp_min(0.0) * inv_eps[:, None, None]), sea)
        s = _masked_range(cos, ~sea)
        out = _Ranges(tuple(v.double() for v in z), tuple(v.double() for v in s), any_sea, any_sky)
        if not iso:
            c = torch.zeros_like(wd) if fold else _azimuth_centre(dx, dy, wd, sea)
            o = _azimuth_coordinate(dx, dy, math.pi / 2 - c - wd, fold)
            out.azimuth = tuple(v.double() for v in _masked_range(o, sea))
            out.centre = c.double()
        return out


def _slant_range(cos_t: torch.Tensor, altitude: torch.Tensor, earth_radius_m: float) -> torch.Tensor:
    """Slant range [m] from a sensor at altitude h to the sea point whose LOS has local zenith
    cosine cos θ̂: the near root of (R + h)² = R² + 2 R r cos θ̂ + r², written without cancellation
    as h (2R + h) / (R cos θ̂ + √(R² cos² θ̂ + h (2R + h))) (flat sea: h / cos θ̂)."""
    c = cos_t.clamp(0.0, 1.0)
    if math.isinf(earth_radius_m):
        return altitude / c.clamp_min(1e-12)
    num = altitude * (2.0 * earth_radius_m + altitude)
    rc = earth_radius_m * c
    return num / (rc + torch.sqrt(rc * rc + num))


def _check_path_altitude(path: Any, altitude: torch.Tensor) -> None:
    """The path model's own check of the camera altitudes (a ray straight down, range = altitude,
    is valid at any altitude the tables cover), with the way out named."""
    h = altitude.detach()
    try:
        path(h, h, clamp=False)
    except ValueError as e:
        raise ValueError(f"{e}; SeaScene(path=False) renders without the air between sea and sensor") from None


def _sky_rows(sky: Any, air_scale: torch.Tensor | None, scene: SeaScene, cos_z: torch.Tensor,
              altitude: torch.Tensor) -> torch.Tensor:
    """Sky radiance seen by each camera along rays of zenith cosine ``cos_z`` (B, N) at the camera
    (down to the depressed horizon): from the camera's altitude for a named atmosphere, else the
    scene's sky (rays below the horizontal see its horizon); scaled by the air temperature."""
    B = cos_z.shape[0]
    if scene.observer_sky is not None:
        rad = scene.observer_sky(altitude.to(cos_z.dtype)[:, None], cos_z, clamp=True)
    else:
        rad = _sky_radiance_pixels(_sky_per_image(sky, B, cos_z.dtype, cos_z.device, 0), cos_z)
    if air_scale is not None:
        rad = rad * air_scale[:, None].to(rad.dtype)
    return rad


def render(
    cameras: PinholeCamera,
    scene: SeaScene,
    *,
    earth_radius_m: float = EARTH_RADIUS_M,
    method: str = "table",
    output: str = "radiance",
    table: TableSize = TableSize(),
    quadrature: Quadrature | None = None,
    geometry: ViewGeometry | None = None,
    chunk: int | None = None,
) -> torch.Tensor:
    """Render infrared images of the sea seen by a batch of kornia cameras.

    Args:
        cameras: ``kornia.geometry.camera.PinholeCamera`` (B cameras, one image size); see
            :func:`~roughsea_torch.geometry.make_camera`.
        scene: :class:`SeaScene` with fields of shape () or (B,).
        earth_radius_m: R [m]; ``float('inf')`` for a flat sea.
        method: ``"table"`` (default) or ``"direct"`` (per-pixel evaluation, the baseline).
        output: ``"radiance"`` [W m⁻² sr⁻¹] or ``"brightness_temperature"`` [K] in the scene's band.
        table: node counts of the table method.
        quadrature: accuracy control of the model (default for the dtype).
        geometry: a precomputed :func:`view_geometry` of these cameras (reused across scenes).
        chunk: images whose per-pixel temporaries are held at once (memory bound; results do not
            depend on it), an int ≥ 1 (else a ``ValueError``); default 4, and 1 for textured scenes
            (``seed=``), whose per-pixel work holds a dozen more full-size temporaries.

    Returns:
        (B, 1, H, W) tensor in the cameras' dtype and device; differentiable with respect to every
        tensor of the scene and of the cameras' pose.
    """
    if chunk is not None:
        if isinstance(chunk, bool) or not isinstance(chunk, (int, np.integer)) or chunk < 1:
            raise ValueError(f"chunk must be None or an int in [1, inf) (images per chunk); got {chunk!r}")
        chunk = int(chunk)
    # a render of one chunk (a small batch) on one intra-op thread, its preparation included: with
    # torch's second thread its many small operations ran 0.5-0.9x as fast beside a busy process
    # (roughsea_torch._parallel); larger batches spread their chunks over worker threads instead
    def call() -> torch.Tensor:
        return _render(cameras, scene, earth_radius_m=earth_radius_m, method=method, output=output, table=table,
                       quadrature=quadrature, geometry=geometry, chunk=chunk)

    ref = geometry.cos_view_zenith if geometry is not None else getattr(cameras, "intrinsics", None)
    per_chunk = images_per_chunk(scene, chunk)
    if (method == "table" and isinstance(ref, torch.Tensor) and ref.ndim > 0 and isinstance(per_chunk, int)
            and ref.shape[0] <= per_chunk):
        return one_thread(call, ref.device)
    return call()


def _render(
    cameras: PinholeCamera,
    scene: SeaScene,
    *,
    earth_radius_m: float,
    method: str,
    output: str,
    table: TableSize,
    quadrature: Quadrature | None,
    geometry: ViewGeometry | None,
    chunk: int | None,
) -> torch.Tensor:
    """:func:`render`'s body."""
    if method not in ("table", "direct"):
        raise ValueError(f"method must be 'table' or 'direct'; got {method!r}")
    chunk = images_per_chunk(scene, chunk)
    if output not in ("radiance", "brightness_temperature"):
        raise ValueError(f"output must be 'radiance' or 'brightness_temperature'; got {output!r}")
    if geometry is not None:
        B, H, W = geometry.is_sea.shape
        dtype, device = geometry.cos_view_zenith.dtype, geometry.cos_view_zenith.device
    else:
        cg = CameraGeometry(cameras, earth_radius_m)
        B, H, W, dtype, device = cg.batch_size, cg.H, cg.W, cg.dtype, cg.device
    p = scene.resolved(B, dtype, device)
    q = quadrature or Quadrature.default(dtype)
    if method == "direct":
        geom = geometry if geometry is not None else view_geometry(cameras, earth_radius_m)
        sea = geom.is_sea
        altitude = geom.altitude_m
        img = None
        if bool(sea.any()):
            p_sea = p
            if p["air_scale"] is not None:  # one scaled sky table per image
                p_sea = dict(p, sky=p["sky"].with_radiance(p["sky"].radiance.to(dtype=dtype, device=device) * p["air_scale"][:, None]),
                             air_scale=None)  # the sky itself now carries it
            img = (_sea_direct(geom, p_sea, scene, q, B, dtype, device) if scene.seed is None
                   else _sea_direct_textured(geom, cameras, p_sea, scene, q, B, dtype, device))
            if scene.path is not None:
                _check_path_altitude(scene.path, altitude)
                img = _apply_path(scene.path, img, altitude, geom.range_m, sea, p["air_scale"])
        if bool((~sea).any()):
            sky_pix = _sky_rows(p["sky"], p["air_scale"], scene, geom.cos_view_zenith.reshape(B, -1), altitude).reshape(B, H, W)
            if scene.sun is not None:
                sky_pix = sky_pix + _sun_disk_pixels(scene, B, slice(None), geom.cos_view_zenith, geom._dx, geom._dy, ~sea,
                                                     1.0 / cameras.fx.to(dtype))
            day = _day(scene, B, dtype, device)
            if day is not None:
                sky_pix = sky_pix + _day_sky_pixels(day, slice(None), geom.cos_view_zenith, geom._dx, geom._dy)
            img = sky_pix if img is None else torch.where(sea, img, sky_pix)
        img = img.reshape(B, 1, H, W)
        if output == "brightness_temperature":
            return _kelvin(img, scene.band)
        return img
    if geometry is not None:
        altitude, radius = geometry.altitude_m, getattr(geometry, "earth_radius_m", earth_radius_m)
        cg = None
    else:
        altitude, radius = cg.alt.to(dtype), earth_radius_m
    return _render_table(cg, geometry, B, H, W, dtype, device, p, scene, q, table, chunk, altitude, radius,
                         output == "brightness_temperature")[:, None]


def _relative_azimuth(geom: ViewGeometry, p: dict[str, Any]) -> torch.Tensor:
    return geom.view_azimuth - p["wind_direction"][:, None, None]


def _sea_direct(geom: ViewGeometry, p: dict[str, Any], scene: SeaScene, q: Quadrature, B: int, dtype: torch.dtype,
                device: torch.device) -> torch.Tensor:
    sea = geom.is_sea
    img_idx = torch.arange(B, device=sea.device)[:, None, None].expand_as(sea)[sea]
    th = geom.view_zenith[sea]
    ph = _relative_azimuth(geom, p)[sea]
    slopes = SlopeStatistics.from_variances(p["vx"][img_idx], p["vy"][img_idx], p["cxy"][img_idx])
    sky = select_sky(p["sky"], img_idx.cpu())
    day = _day(scene, B, dtype, device)
    if day is not None:  # the sky each pixel reflects, along its mirror azimuth
        sky = _sky_with_day(sky, day, p, img_idx, ph)
    vals = apparent_radiance(
        th, ph, slopes, (p["n"][img_idx], p["k"][img_idx]), sea_radiance=p["rb"][img_idx], sky=sky,
        shadowing=scene.shadowing, quadrature=q, sun=_relative_sun(scene, p, B, dtype, device, img_idx),
        sun_masking=scene.sun_masking, sky_masking=scene.sky_masking,
    )
    if p["foam"] is not None:
        vals = _foam_mix(vals, th, p, img_idx, scene)
    out = torch.zeros(sea.shape, dtype=vals.dtype, device=vals.device)
    return out.index_put((sea,), vals)


def _foam_radiance(theta: torch.Tensor, p: dict[str, Any], idx: Any, scene: SeaScene) -> torch.Tensor:
    """R_foam(θ̂) = ε_f R_B + (1 − ε_f) E_sky/π for the images ``idx`` (an index tensor per element of
    θ̂, or a slice with a leading image axis on θ̂)."""
    from .foam import foam_radiance, sky_hemispherical_mean

    dtype, device = theta.dtype, theta.device
    sky = select_sky(p["sky"], idx.cpu() if isinstance(idx, torch.Tensor) else idx)
    e_sky = torch.as_tensor(sky_hemispherical_mean(sky, dtype=dtype, device=device), dtype=dtype, device=device)
    if p["air_scale"] is not None:
        e_sky = e_sky * p["air_scale"][idx].to(dtype)
    day = _day(scene, p["vx"].shape[0], dtype, device)
    if day is not None:  # + the scattered sky's cosine-weighted mean, 2 ∫ <L>_φ(c) c dc (Gauss–Legendre)
        x, w = np.polynomial.legendre.leggauss(24)
        c = torch.as_tensor((x + 1) / 2, dtype=dtype, device=device)
        wc = torch.as_tensor(w, dtype=dtype, device=device) * c
        e_sky = e_sky + (day[0].azimuthal_mean(c, day[1][idx].to(dtype)[..., None]) * wc).sum(-1)
    extra = (None,) * (theta.ndim - 1) if not isinstance(idx, torch.Tensor) else ()
    if e_sky.ndim:
        e_sky = e_sky[(...,) + extra]
    return foam_radiance(theta, scene.band, p["rb"][idx][(...,) + extra].to(dtype), e_sky,
                         refractive_index=(p["n"][idx][(...,) + extra], p["k"][idx][(...,) + extra])).to(dtype)


def _foam_mix(values: torch.Tensor, theta: torch.Tensor, p: dict[str, Any], idx: torch.Tensor, scene: SeaScene,
              f: torch.Tensor | None = None) -> torch.Tensor:
    """(1 − f) · values + f · R_foam(θ̂), per element (``idx`` the image of each element); f the
    scene's whitecap fraction, or a per-element one (foam on crests, textured seas)."""
    f = p["foam"][idx].to(values.dtype) if f is None else f.to(values.dtype)
    return values + f * (_foam_radiance(theta, p, idx, scene) - values)


def _sun_disk_pixels(scene: SeaScene, B: int, idx: slice, dz: torch.Tensor, dx: torch.Tensor, dy: torch.Tensor,
                     sky: torch.Tensor, ifov: torch.Tensor) -> torch.Tensor:
    """The sun's own disk in the sky pixels of images ``idx``: L_sun = E_sun / Ω_sun (the irradiance at
    the surface: the air between the sea and the camera is neglected) times the share of each pixel
    the disk covers, an edge one pixel wide (δ = the camera's IFOV at its centre). (b, H, W)."""
    dtype, device = dz.dtype, dz.device
    z, a, e, r = (v[idx][:, None, None] for v in _sun_fields(scene, B, dtype, device))
    cos_ang = (dx * torch.sin(z) * torch.cos(a) + dy * torch.sin(z) * torch.sin(a) + dz * torch.cos(z)).clamp(-1.0, 1.0)
    ang = 2.0 * torch.asin((0.5 * torch.sqrt((2.0 - 2.0 * cos_ang).clamp_min(0.0))).clamp(max=1.0))  # no cancellation
    cover = ((r - ang) / ifov[:, None, None] + 0.5).clamp(0.0, 1.0)
    l_sun = e / (4.0 * math.pi * torch.sin(0.5 * r) ** 2)
    return torch.where(sky & (cover > 0), l_sun * cover, torch.zeros_like(dz))


def _squeeze_last(stats: SlopeStatistics) -> SlopeStatistics:
    """Shifted statistics of shape (..., 1) (one flat-point quantile each) as shape (...)."""
    return SlopeStatistics.from_variances(stats.var_upwind[..., 0], stats.var_crosswind[..., 0], stats.cov[..., 0]).shifted(
        stats.mean_upwind[..., 0], stats.mean_crosswind[..., 0])


def _sun_fields(scene: SeaScene, B: int, dtype: torch.dtype, device: torch.device) -> tuple[torch.Tensor, ...]:
    """The scene's sun as (B,) tensors: zenith, world azimuth, irradiance, radius."""
    sun = scene.sun
    return tuple(per_batch(f"sun {n}", v, B, dtype, device) for n, v in
                 (("zenith", sun.zenith), ("azimuth", sun.azimuth), ("irradiance", sun.irradiance), ("radius", sun.radius)))


def _relative_sun(scene: SeaScene, p: dict[str, Any], B: int, dtype: torch.dtype, device: torch.device,
                  idx: torch.Tensor) -> Any:
    """The scene's sun for the images ``idx`` with its azimuth from each image's upwind axis."""
    if scene.sun is None:
        return None
    from .sun import Sun

    z, a, e, r = _sun_fields(scene, B, dtype, device)
    return Sun(z[idx], a[idx] - p["wind_direction"][idx], e[idx], r[idx])


def _day(scene: SeaScene, B: int, dtype: torch.dtype, device: torch.device) -> Any:
    """(scattered sky, sun zenith (B,), sun world azimuth (B,)) of a scene whose sky gains the
    sunlight its aerosol scatters (:attr:`SeaScene.day_sky`), else None."""
    day = scene.day_sky
    if day is None:
        return None
    z, a, _, _ = _sun_fields(scene, B, dtype, device)
    return day, z, a


def _sky_with_day(sky: TabulatedSky, day: tuple, p: dict[str, Any], idx: Any, view_azimuth: torch.Tensor) -> TabulatedSky:
    """The sky the sea reflects by day, per element of ``view_azimuth`` (relative to upwind, LOS sea →
    sensor; leading dim = the images ``idx``): the thermal table plus the scattered sky at its zenith
    nodes along the mirror azimuth φ̂ + π (divided by the air-temperature scale that the sky term
    gets afterwards, which is the thermal sky's)."""
    ds, z_sun, a_sun = day
    dtype, device = view_azimuth.dtype, view_azimuth.device
    extra = (None,) * (view_azimuth.ndim - 1)
    rel = view_azimuth + math.pi - (a_sun[idx] - p["wind_direction"][idx]).to(dtype)[(...,) + extra]
    z = sky.zenith.to(dtype=dtype, device=device)
    scat = ds(torch.cos(z), rel[..., None], z_sun[idx].to(dtype)[(...,) + extra + (None,)])
    if p["air_scale"] is not None:
        scat = scat / p["air_scale"][idx].to(dtype)[(...,) + extra + (None,)]
    thermal = sky.radiance.to(dtype=dtype, device=device)
    if thermal.ndim > 1:
        thermal = thermal.reshape(thermal.shape[0], *([1] * (view_azimuth.ndim - 1)), thermal.shape[-1])
    return sky.with_radiance(thermal + scat)


def _day_sky_pixels(day: tuple, sl: Any, cos: torch.Tensor, dx: torch.Tensor, dy: torch.Tensor,
                    img: torch.Tensor | None = None) -> torch.Tensor:
    """The scattered sky along the rays of sky pixels (cos of the ray's zenith, world x/y components;
    rays below the horizontal see it at the horizontal), (b, H, W); or, with ``img`` (each pixel's image
    within ``sl``), at gathered pixels, all 1-D."""
    ds, z_sun, a_sun = day
    a, z = a_sun[sl].to(cos.dtype), z_sun[sl].to(cos.dtype)
    if img is None:
        a, z = a[:, None, None], z[:, None, None].expand_as(cos)
    else:
        a, z = a.index_select(0, img), z.index_select(0, img)
    return ds(cos.clamp(0.0, 1.0), torch.atan2(dy, dx) - a, z)


def _over_kept_pixels(keep: torch.Tensor, fn: Any, dtype: torch.dtype) -> torch.Tensor:
    """``fn(m, at)`` over the kept pixels of each image m of ``keep`` (b, H, W) bool, into (b, H, W) (0
    elsewhere); ``at(t)`` gathers a (b, H, W) field at the pixels of the call. Image by image (its sun
    and slope law are scalars), in blocks of 2¹⁶ of its kept pixels, whose temporaries stay in cache and
    in the allocator's heap (a fresh multi-megabyte temporary page-faults on every operation); every
    operation is per pixel, so blocks change no value. Gathers by index_select on flat indices
    (boolean-mask indexing costs ~4× more)."""
    b_, H, W = keep.shape
    out = torch.zeros(b_, H * W, dtype=dtype, device=keep.device)
    for m in range(b_):
        flat = keep[m].reshape(-1).nonzero().squeeze(1)
        parts = []
        for i in range(0, flat.numel(), 1 << 16):
            fl = flat[i:i + (1 << 16)]
            parts.append(fn(m, lambda t, fl=fl: t[m].reshape(-1).index_select(0, fl)))
        if parts:
            out = out.index_put((torch.full_like(flat, m), flat), parts[0] if len(parts) == 1 else torch.cat(parts))
    return out.reshape(b_, H, W)


def _upwind_los(x: torch.Tensor, y: torch.Tensor, cw: torch.Tensor, sw: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
    """(cos φ̂, sin φ̂) of the line of sight in the upwind frame, from the ray's world components x, y
    (the line of sight is −(x, y) horizontally) and the cosine and sine of the wind direction."""
    inv = torch.rsqrt((x * x + y * y).clamp_min(1e-30))
    return -(x * cw + y * sw) * inv, (x * sw - y * cw) * inv


def _glint_mask(p: dict[str, Any], sl: slice, sun: Any, cos_t: torch.Tensor, dx: torch.Tensor, dy: torch.Tensor,
                sea: torch.Tensor) -> torch.Tensor:
    """The sea pixels of images ``sl`` that can see glint (b, H, W) bool: those whose specular slope lies
    within 6 standard deviations (whitened) of the slope law, plus the sun disk's own extent (the rest
    carries less than exp(−18) = 1.5e-8 of the glint's peak), with the sun up. ``sun``: the images' sun
    relative to upwind."""
    dtype = cos_t.dtype
    per_img = [p[k][sl].to(dtype) for k in ("wind_direction", "vx", "vy", "cxy")] + [sun.zenith, sun.azimuth, sun.radius]

    def one(m: int, at: Any) -> torch.Tensor:
        wd, a2, b2, c2, sz, sa, radius = (v[m] for v in per_img)
        ct = at(cos_t).clamp(0.0, 1.0)
        st = torch.sqrt((1 - ct * ct).clamp_min(0.0))
        cph, sph = _upwind_los(at(dx), at(dy), torch.cos(wd), torch.sin(wd))
        vx_, vy_ = st * cph, st * sph
        wx, wy, wz = torch.sin(sz) * torch.cos(sa), torch.sin(sz) * torch.sin(sa), torch.cos(sz)
        qz = ct + wz
        sgx, sgy = (vx_ + wx) / qz, (vy_ + wy) / qz
        det = (a2 * b2 - c2 * c2).clamp_min(1e-30)
        d2 = (b2 * sgx * sgx - 2 * c2 * sgx * sgy + a2 * sgy * sgy) / det
        lam_min = (0.5 * (a2 + b2 - torch.sqrt((a2 - b2) ** 2 + 4 * c2 * c2))).clamp_min(1e-24)
        reach = radius * 2.0 * (1 + sgx * sgx + sgy * sgy) / qz.clamp_min(1e-6) / torch.sqrt(lam_min)
        return ((wz > 0) & (torch.sqrt(d2) - reach < 6.0)).to(dtype)

    with torch.no_grad():
        return _over_kept_pixels(sea, one, dtype) > 0


def _glint_pixels(scene: SeaScene, p: dict[str, Any], sl: slice, cos_t: torch.Tensor, dx: torch.Tensor,
                  dy: torch.Tensor, sea: torch.Tensor, tau_rows: tuple[torch.Tensor, torch.Tensor] | None,
                  resolved: tuple | None = None) -> torch.Tensor:
    """τ · R_glint at the sea pixels of images ``sl`` (b, H, W), 0 elsewhere, evaluated at the pixels that
    can see glint (:func:`_glint_mask`). On a
    textured sea (``resolved`` = each pixel's flat-point quantile x and resolved covariance) the glint
    is that of the pixel's own unresolved Gaussian about its visible resolved slope, as the sky's
    reflection is (:mod:`roughsea_torch.clutter`), so its ensemble mean is the expectation's glint
    (``resolved[0]`` may be the pair (x, x'), x' the visible quantile read from the texture volume).
    ``tau_rows`` = (τ at the fine table's sea rows (b, M_z), each pixel's fractional row (b, H, W))
    with a path, else None."""
    b_, H, W = cos_t.shape
    dtype, device = cos_t.dtype, cos_t.device
    B = p["vx"].shape[0]
    sun = _relative_sun(scene, p, B, dtype, device, torch.arange(sl.start, sl.stop, device=device))
    keep = _glint_mask(p, sl, sun, cos_t, dx, dy, sea)
    from .sun import _glint, sun_masking_factor

    # the sun's masking is Smith's G1 of the scene's total slope law (resolved waves mask the sun too):
    # one value per image
    g1 = None
    if scene.sun_masking:
        g1 = sun_masking_factor(SlopeStatistics.from_variances(p["vx"][sl], p["vy"][sl], p["cxy"][sl]), sun, dtype, device)
    per_img = [p[k][sl].to(dtype) for k in ("wind_direction", "vx", "vy", "cxy", "n", "k")]
    per_img += [sun.zenith, sun.azimuth, sun.irradiance, sun.radius]

    def one(m: int, at: Any) -> torch.Tensor:
        wd, vx, vy, cxy, n_, k_, tz, tp, e_sun, al = (v[m] for v in per_img)
        c_k, dx_k, dy_k = at(cos_t), at(dx), at(dy)
        phi = torch.atan2(-dy_k, -dx_k) - wd
        mx = my = None
        if resolved is not None:
            from .clutter import along_view, two_scale_statistics

            inv = torch.rsqrt((dx_k ** 2 + dy_k ** 2).clamp_min(1e-30))
            var_a, kap = along_view(tuple(at(c) for c in resolved[1]), -dx_k * inv, -dy_k * inv)
            # the pixel's visible quantile x', read from the texture volume where the table gives it
            x, x_vis = resolved[0] if isinstance(resolved[0], tuple) else (resolved[0], None)
            shifted = _squeeze_last(two_scale_statistics(vx.expand_as(phi), vy.expand_as(phi), cxy.expand_as(phi), phi,
                                                         c_k, at(x)[:, None], var_a, kap,
                                                         visible=None if x_vis is None else at(x_vis)[:, None]))
            (vx, vy, cxy), (mx, my) = shifted.tensors(dtype, device), shifted.mean_tensors(dtype, device)
        g = _glint(torch.acos(c_k.clamp(-1.0, 1.0)), phi, vx, vy, cxy, mx, my, n_, k_, tz, tp, e_sun, al, scene.shadowing)
        if g1 is not None:
            g = g * g1[m]
        if tau_rows is not None:  # the path's transmittance: quadratic through the table's 3 nearest rows
            tau_r, row = tau_rows
            nr = tau_r.shape[1]
            r = at(row).clamp(0.0, nr - 1.0)
            i = r.detach().round().clamp(1, nr - 2).long()
            t = r - i.to(r.dtype)
            tm, t0, tq = (tau_r[m].index_select(0, i + d) for d in (-1, 0, 1))
            g = g * (t0 + t * (0.5 * (tq - tm) + t * (0.5 * (tq + tm) - t0)))
        return g

    return _over_kept_pixels(keep, one, dtype)


def _glint_core_table(scene: SeaScene, p: dict[str, Any], sl: slice, eps: torch.Tensor, lo: torch.Tensor,
                      span_z: torch.Tensor, y_z: torch.Tensor, col_angle: Callable[[torch.Tensor], torch.Tensor],
                      y_cols: torch.Tensor, centre: torch.Tensor, shift: float, sea_cols: torch.Tensor,
                      scale_rows: torch.Tensor | None, table: TableSize, dtype: torch.dtype) -> tuple[torch.Tensor, torch.Tensor]:
    """The smooth factor L_sun G1 / D of the glint of images ``sl`` (the glint is P ρ t · L_sun G1 / D,
    ``roughsea_torch.sun._glint_sharp`` the sharp part, which :func:`_glint_sharp_pixels` evaluates per
    pixel) on the fine table's sea rows and unfolded columns (``col_angle``: the azimuth coordinate o of
    column coordinates y ∈ [−1, 1], φ̂ = ``centre`` + o − ``shift``), times ``scale_rows`` (b, M_z)
    (the path's τ, the foam's 1 − f); (b, M_z, M_o), and which images it serves (b,) bool (zero for the
    others, whose glint stays wholly per pixel).

    The factor is evaluated at ``table.glint``² Chebyshev–Lobatto nodes (in ζ over the sea rows' span,
    in azimuth over every column) and resampled spectrally. An image is served when its pixels span
    less than π in azimuth (a coordinate of period π would fold the glint, which has none; under a day
    sky the period is 2π, and the table keeps to spans below π all the same) and, at the centres of the fine cells
    of 48 rows and every other column (where bilinear reading errs most), the table's glint is within
    ``table.glint_tolerance`` of direct evaluation, relative to the radiance there (``sea_cols``, the
    sea's fine table, plus the glint).
    """
    from .sun import _glint, _glint_sharp, sun_masking_factor

    Mz, device = y_z.shape[0], lo.device
    B = p["vx"].shape[0]
    sun = _relative_sun(scene, p, B, dtype, device, torch.arange(sl.start, sl.stop, device=device))
    e = (slice(None), None, None)
    per = [p[k][sl].to(dtype)[e] for k in ("vx", "vy", "cxy", "n", "k")]
    tz, tp, e_sun, al = (v[e] for v in (sun.zenith, sun.azimuth, sun.irradiance, sun.radius))
    g1 = None
    if scene.sun_masking:
        g1 = sun_masking_factor(SlopeStatistics.from_variances(p["vx"][sl], p["vy"][sl], p["cxy"][sl]), sun, dtype,
                                device)[e]
    zero = torch.zeros((), dtype=dtype, device=device)

    def angles(zeta: torch.Tensor, o: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:  # ζ (b, R), o (b, C), float64
        th = torch.acos((eps[:, None] * torch.sinh(zeta)).clamp(0.0, 1.0)).to(dtype)[:, :, None]
        return th, (centre[:, None] + o - shift).to(dtype)[:, None, :]

    def smooth(th: torch.Tensor, ph: torch.Tensor) -> torch.Tensor:
        r = _glint(th, ph, per[0], per[1], per[2], None, None, per[3], per[4], tz, tp, e_sun, al, scene.shadowing,
                   smooth=True)
        return r if g1 is None else r * g1

    def sharp(th: torch.Tensor, ph: torch.Tensor) -> torch.Tensor:
        return _glint_sharp(torch.cos(th), torch.sin(th), torch.cos(ph), torch.sin(ph), per[0], per[1], per[2], zero, zero,
                            per[3], per[4], tz, tp, al)[0]

    n = int(table.glint)
    xg, L_rows, _ = _lobatto_interp(n, Mz)  # rows: nodes over the sea span, the fine rows' overhang two cells
    # (the factor has a kink at the horizon, ζ = 0, where the overhang below it holds θ̂ = 90°)
    xg_t = torch.as_tensor(xg, dtype=torch.float64, device=device)
    ang = col_angle(y_cols)
    a0, a1 = ang[:, 0], ang[:, -1]  # columns: nodes over every column, overhang included (it has no kink,
    # and a polynomial of this degree must not be extrapolated by the columns' coarser cells)
    th_n, ph_n = angles(lo[:, None] + span_z[:, None] * (xg_t + 1) / 2, a0[:, None] + (a1 - a0)[:, None] * (xg_t + 1) / 2)
    r_nodes = smooth(th_n, ph_n)
    L_rows = torch.as_tensor(L_rows, dtype=dtype, device=device)
    L_cols = _barycentric(xg, 2.0 * (ang - a0[:, None]) / (a1 - a0)[:, None] - 1.0).to(dtype)
    fine = L_rows @ r_nodes @ L_cols.transpose(1, 2)
    if scale_rows is not None:
        fine = fine * scale_rows[:, :, None]
    with torch.no_grad():  # the check
        i = torch.linspace(_EXT, Mz - 2 - _EXT, 48, device=device).round().long().unique()  # rows pixels read
        j = torch.arange(0, y_cols.shape[0] - 1, 2, device=device)
        th, ph = angles(lo[:, None] + span_z[:, None] * (0.5 * (y_z[i] + y_z[i + 1]) + 1) / 2,
                        col_angle(0.5 * (y_cols[j + 1] + y_cols[j])))
        r_c, s_c = smooth(th, ph), sharp(th, ph)
        if scale_rows is not None:
            r_c = r_c * (0.5 * (scale_rows[:, i] + scale_rows[:, i + 1]))[:, :, None]
        cell = lambda t: 0.25 * (t[:, i][:, :, j + 1] + t[:, i][:, :, j] + t[:, i + 1][:, :, j + 1]  # noqa: E731
                                 + t[:, i + 1][:, :, j])
        err = (cell(fine) - r_c).abs() * s_c / (cell(sea_cols).abs() + r_c.abs() * s_c)
        ok = ((err.flatten(1).amax(1) < table.glint_tolerance) & ((a1 - a0) < math.pi - 1e-3)
              & torch.isfinite(r_nodes).flatten(1).all(1))
    return torch.where(ok[:, None, None], fine, torch.zeros_like(fine)), ok


def _glint_sharp_pixels(scene: SeaScene, p: dict[str, Any], sl: slice, cos_t: torch.Tensor, dx: torch.Tensor,
                        dy: torch.Tensor, sea: torch.Tensor) -> torch.Tensor:
    """P ρ t at the sea pixels that can see glint (:func:`_glint_mask`) (b, H, W), 0 elsewhere: the
    glint's part that is sharp in the view direction (``roughsea_torch.sun._glint_sharp``, the ellipse's probability in closed form or by rays
    as it is small or not), for the pixel's line of sight, whose azimuth in the upwind frame comes from
    the ray's world components: (cos φ̂, sin φ̂) = −(dx, dy)/|(dx, dy)| turned by −wind_direction."""
    from .sun import _glint_sharp

    dtype, device = cos_t.dtype, cos_t.device
    b_, H, W = cos_t.shape
    B = p["vx"].shape[0]
    sun = _relative_sun(scene, p, B, dtype, device, torch.arange(sl.start, sl.stop, device=device))
    wd = p["wind_direction"][sl].to(dtype)
    per_img = [torch.cos(wd), torch.sin(wd), *(p[k][sl].to(dtype) for k in ("vx", "vy", "cxy", "n", "k")), sun.zenith,
               sun.azimuth, sun.radius]
    zero = torch.zeros((), dtype=dtype, device=device)

    def one(m: int, at: Any) -> torch.Tensor:
        cw, sw, vx, vy, cxy, n_, k_, tz, tp, al = (v[m] for v in per_img)
        c = at(cos_t)
        cph, sph = _upwind_los(at(dx), at(dy), cw, sw)
        return _glint_sharp(c, torch.sqrt((1.0 - c * c).clamp_min(0.0)), cph, sph, vx, vy, cxy, zero, zero, n_, k_, tz, tp,
                            al)[0]

    return _over_kept_pixels(_glint_mask(p, sl, sun, cos_t, dx, dy, sea), one, dtype)


def _sea_direct_textured(geom: ViewGeometry, cameras: PinholeCamera, p: dict[str, Any], scene: SeaScene,
                         q: Quadrature, B: int, dtype: torch.dtype, device: torch.device) -> torch.Tensor:
    """The textured sea per pixel (the baseline of the texture volume): each sea pixel's own
    footprint, resolved slope, visible slope a' and shifted expectation (:mod:`roughsea_torch.clutter`)."""
    from .clutter import footprint, pixel_resolved_slope, reconcile_scale, two_scale_statistics

    sea = geom.is_sea
    wf = scene.wave_field(B, dtype, device)
    centres = -(cameras.rotation_matrix.transpose(-1, -2) @ cameras.translation_vector)[..., 0].to(dtype)
    cos_t = geom.cos_view_zenith.clamp_min(1e-9)
    R = torch.where(sea, geom.range_m, torch.ones_like(cos_t))
    L = footprint(R, cos_t, (1.0 / cameras.fx.to(dtype))[:, None, None])
    dx, dy = geom._dx, geom._dy
    time = per_batch("time_s", scene.time_s, B, torch.float64, device)  # wave phases in float64 (TextureTable)
    smp = wf.sample(centres[:, 0, None, None] + R * dx, centres[:, 1, None, None] + R * dy, time, footprint=L,
                    elevation=False, crest=p["foam"] is not None)
    cov = wf.resolved_covariance(L)
    l_ = reconcile_scale(cov, *(p[k][:, None, None] for k in ("vx", "vy", "cxy", "wind_direction")))
    x, var_a, kap = pixel_resolved_slope(l_ * smp["slope_x"], l_ * smp["slope_y"], tuple(c * l_ * l_ for c in cov),
                                         dx, dy)
    img_idx = torch.arange(B, device=device)[:, None, None].expand_as(sea)[sea]
    th, ph = geom.view_zenith[sea], _relative_azimuth(geom, p)[sea]
    vx, vy, cxy = p["vx"][img_idx], p["vy"][img_idx], p["cxy"][img_idx]
    slopes = _squeeze_last(two_scale_statistics(vx, vy, cxy, ph, torch.cos(th), x[sea][:, None], var_a[sea], kap[sea]))
    sky = select_sky(p["sky"], img_idx.cpu())
    day = _day(scene, B, dtype, device)
    if day is not None:  # the sky each pixel reflects, along its mirror azimuth
        sky = _sky_with_day(sky, day, p, img_idx, ph)
    vals = apparent_radiance(th, ph, slopes, (p["n"][img_idx], p["k"][img_idx]), sea_radiance=p["rb"][img_idx],
                             sky=sky, shadowing=scene.shadowing, quadrature=q, sky_masking=scene.sky_masking)
    sun = _relative_sun(scene, p, B, dtype, device, img_idx)
    if sun is not None:  # the pixel's own glint, masked from the sun by the total law (sun_masking_factor)
        from .sun import glint_radiance, sun_masking_factor

        g = glint_radiance(th, ph, slopes, (p["n"][img_idx], p["k"][img_idx]), sun, scene.shadowing, False)
        if scene.sun_masking:
            g = g * sun_masking_factor(SlopeStatistics.from_variances(vx, vy, cxy), sun, dtype, device)
        vals = vals + g
    if p["foam"] is not None:  # whitecaps on the crests (foam.crest_foam_fraction)
        from .foam import crest_foam_fraction

        f = crest_foam_fraction(smp["crest"], wf.crest_variance(L), wf.crest_variance()[:, None, None],
                                p["foam"].to(dtype)[:, None, None])
        vals = _foam_mix(vals, th, p, img_idx, scene, f[sea])
    out = torch.zeros(sea.shape, dtype=vals.dtype, device=vals.device)
    return out.index_put((sea,), vals)


def _apply_path(path: Any, radiance: torch.Tensor, altitude: torch.Tensor, range_m: torch.Tensor, sea: torch.Tensor,
                air_scale: torch.Tensor | None = None) -> torch.Tensor:
    """τ · R_a + L_path at each sea pixel (other pixels unchanged); (b, H, W). ``air_scale`` (b,)
    scales L_path (SeaScene's air_temperature)."""
    h = altitude.to(radiance.dtype)[:, None, None].expand_as(radiance)
    r = torch.where(sea, range_m.to(radiance.dtype), h)  # any valid range off the sea
    tau, lp = path(h, r, clamp=True)
    if air_scale is not None:
        lp = lp * air_scale[:, None, None]
    return torch.where(sea, tau * radiance + lp, radiance)


def _render_table(
    cg: CameraGeometry | None,
    geometry: ViewGeometry | None,
    B: int,
    H: int,
    W: int,
    dtype: torch.dtype,
    device: torch.device,
    p: dict[str, Any],
    scene: SeaScene,
    q: Quadrature,
    table: TableSize,
    chunk: int,
    altitude: torch.Tensor,
    earth_radius_m: float,
    brightness: bool,
) -> torch.Tensor:
    """The table method. Per image one fine table holds, in one array read by one bilinear
    ``grid_sample`` per pixel, everything a pixel can see:

    - rows 0 … M_z − 1 (the sea): τ(ζ) · R_a(ζ, o) + L_path(ζ) over ζ = asinh(cos θ̂/ε) and the
      azimuth coordinate o. R_a comes from the model at Chebyshev–Lobatto nodes resampled spectrally
      (barycentric matrices L_z, L_o); the path is exact per row, since for one camera the slant
      range is a function of θ̂ alone. As matrices, fine = [τ L_z | L_path] · [R_a ; 1] · L_oᵀ.
    - rows M_z … M_z + M_s − 1 (the sky): the sky radiance over the cosine of the ray's zenith at
      the camera, constant along o.

    Spans come from the image's border (:func:`_camera_ranges`) or from a given ``geometry``. Images
    are processed ``chunk`` at a time, start to end (spans, model at the nodes, tables, pixels), the
    chunks spread over worker threads by :func:`~roughsea_torch._parallel.map_chunks`. With
    ``brightness`` the result is in kelvin. Returns (B, H, W).
    """
    # a textured sea's clutter depends on the view's azimuth through the resolved waves' anisotropy
    # (and is not even in it): the table then keeps an unfolded azimuth dimension
    textured = scene.seed is not None
    sunny = scene.sun is not None  # the glint is per pixel, and needs the rays' azimuths
    iso = not (textured or sunny) and bool(((p["vx"] == p["vy"]) & (p["cxy"] == 0)).all())
    # Uncorrelated anisotropic slopes (Cox–Munk): the table runs over the folded azimuth ψ ∈ [0, π/2].
    # R_a is even in φ̂ there, and as a → 0 (or b → 0) it has a kink at φ̂ = 0 (π/2), where the
    # rms slope along the view, √(a² cos²φ̂ + b² sin²φ̂), → b |sin φ̂|: folded, the kink sits at an
    # end of the node interval instead of inside it, where Chebyshev nodes cannot resolve it
    # (views along the wind at W = 0 were off by 8e-4 with 9 nodes; pipelines/accuracy_pareto.py).
    day = _day(scene, B, dtype, device)  # a day sky is not symmetric about the wind: no folding
    fold = not iso and day is None and bool((p["cxy"] == 0).all())
    # nor under a half turn (R_a(φ̂ + π) ≠ R_a(φ̂)): its unfolded coordinate runs over 2π (it ran over π,
    # and a view with every azimuth, looking down at the nadir, read the sky half a turn away: up to
    # 0.24 K off per-pixel evaluation in MWIR)
    period = 2 * math.pi if day is not None else math.pi
    # ε: a quarter of the smallest rms slope of each image, so ζ resolves the grazing layer.
    lam_min = 0.5 * (p["vx"] + p["vy"] - torch.sqrt((p["vx"] - p["vy"]) ** 2 + 4 * p["cxy"] ** 2))
    eps = (0.25 * torch.sqrt(lam_min.detach().clamp_min(0.0))).clamp(1e-4, 0.05).double()
    inv_eps = (1.0 / eps).to(dtype)
    if day is not None and cg is not None:
        # an image with every azimuth in view (looking down at the nadir; every image with span="full")
        # spreads the day sky's azimuth structure (the aureole about the sun) over the whole turn: twice the
        # mean's azimuth nodes and columns, four times the texture's nodes and columns, for the whole render
        # (so an image's pixels then depend on whether such an image shares its batch, by up to ~1e-3 K).
        # MWIR, 20 m, 8 m/s, nadir views: over four sun and wind azimuths 0.025 -> 0.0076 K, textured
        # 0.056 -> 0.016 K against per-pixel evaluation; over a wider sweep (sun zenith to 1 rad, 90° field
        # of view) up to 2.2e-2 and 3.5e-2 K remain, which more nodes reduce (TableSize.azimuth_day,
        # texture_azimuth_sun; four times these: 8.7e-3 and 6.5e-3 K at 2.4x the time)
        turn = table.span == "full"
        if not turn:
            rg_all = _camera_ranges(cg, slice(0, B), p["wind_direction"], inv_eps, False, False, 2 * math.pi)
            turn = bool((((rg_all.azimuth[1] - rg_all.azimuth[0]) > math.pi) & rg_all.any_sea).any())
        if turn:
            table = replace(table, azimuth_day=2 * (table.azimuth_day - 1) + 1, fine_azimuth=2 * table.fine_azimuth,
                            texture_azimuth_sun=4 * (table.texture_azimuth_sun - 1) + 1,
                            fine_texture_azimuth=4 * table.fine_texture_azimuth)
    lam_max = 0.5 * (p["vx"] + p["vy"] + torch.sqrt((p["vx"] - p["vy"]) ** 2 + 4 * p["cxy"] ** 2))
    thin = bool((lam_min.detach() < 0.04 * lam_max.detach()).any())  # minor/major rms slope < 0.2
    narrow = bool((lam_min.detach() < 0.25 * lam_max.detach()).any())  # minor/major rms slope < 0.5
    nz = (max(table.zenith, table.zenith_thin) if thin else max(table.zenith, table.zenith_narrow) if narrow
          else table.zenith)
    nphi = 1 if iso else max(table.azimuth, table.azimuth_thin) if thin else table.azimuth
    if day is not None:
        nphi = max(nphi, table.azimuth_day)
    xz, Lz, ez = _lobatto_interp(nz, table.fine_zenith)
    xz_t = torch.as_tensor(xz, dtype=torch.float64, device=device)
    Lz_t = torch.as_tensor(Lz, dtype=dtype, device=device)
    if not iso:
        xp, Lp, ep = _lobatto_interp(nphi, max(table.fine_azimuth, table.fine_azimuth_thin) if thin else table.fine_azimuth)
        xp_t = torch.as_tensor(xp, dtype=torch.float64, device=device)
        Lp_t = torch.as_tensor(Lp, dtype=dtype, device=device)
    Mz, Ms = table.fine_zenith, table.fine_sky
    N = Mz + Ms
    es = 2.0 * _EXT / (Ms - 1 - 2 * _EXT)
    y_z = torch.linspace(-1.0 - ez, 1.0 + ez, Mz, dtype=torch.float64, device=device)
    if scene.path is not None:
        _check_path_altitude(scene.path, altitude)
    # the table's azimuth coordinate: from cameras, without texture (whose own table reads the angle),
    # the cheap u of _azimuth_ratio, the fine columns uniform in u; else the angle
    ratio = not (iso or textured) and geometry is None and day is None
    if sunny and cg is None:
        raise ValueError("geometry=: a scene with a sun needs the cameras (its glint and disk are per pixel, the "
                         "disk sized by the pixel's field of view); call render(cameras, scene) without geometry=")
    if textured:
        if cg is None:
            raise ValueError("geometry=: a textured scene (seed=...) needs the cameras (it places waves in the world); "
                             "call render(cameras, scene) without geometry=")
        # by day the mean takes TableSize.azimuth_day azimuth nodes for the scattered sky; the texture's
        # departures from it need fewer (TableSize.texture_azimuth_sun), on the same span
        nphi_tex = min(nphi, int(table.texture_azimuth_sun)) if day is not None else nphi
        xp_tex = torch.as_tensor(_lobatto_interp(nphi_tex, int(table.fine_texture_azimuth))[0], dtype=torch.float64, device=device)
        tex = TextureTable(table, nz, nphi_tex, B, dtype, device, scene, cg)

    def nodes(sl: slice) -> dict[str, Any]:
        """Images ``sl``: spans, and the model at the nodes (the mean's, and the texture's departures
        from it), the part of the work made of many small operations: run for groups of images at
        once (fewer, larger operations), then sliced per chunk of pixels (``one``)."""
        b_ = sl.stop - sl.start
        wd = p["wind_direction"][sl]
        rg = (_geometry_ranges(geometry, sl, wd, inv_eps[sl], iso, fold) if geometry is not None
              else _camera_ranges(cg, sl, wd, inv_eps[sl], iso, fold, period))

        # ---- node spans (float64) -----------------------------------------------------------------
        lo, hi = (torch.where(rg.any_sea, v, torch.full_like(v, d)) for v, d in zip(rg.zeta, (0.0, 1.0)))
        if table.span == "full":
            lo, hi = torch.zeros_like(lo), torch.asinh(1.0 / eps[sl])
        pad = torch.clamp(1e-6 * (hi - lo), min=1e-9)
        lo, hi = lo - pad, hi + pad
        span_z = hi - lo
        th_nodes = torch.acos((eps[sl, None] * torch.sinh(lo[:, None] + span_z[:, None] * (xz_t + 1) / 2)).clamp(0.0, 1.0))
        if iso:
            ph_nodes = torch.zeros(b_, 1, dtype=dtype, device=device)
        else:
            a, b = (torch.where(rg.any_sea, v, torch.full_like(v, d)) for v, d in zip(rg.azimuth, (0.0, 1.0)))
            if table.span == "full":
                a, b = torch.zeros_like(a), torch.full_like(b, math.pi / 2 if fold else period)
            pad = torch.clamp(1e-6 * (b - a), min=1e-6)
            a, b = a - pad, b + pad
            if fold:  # ψ ∈ [0, π/2]: keep the nodes inside it (the kink stays at the interval's end)
                a, b = a.clamp_min(0.0), b.clamp_max(math.pi / 2)
            # the pixels' o = wrap_P(φ̂ − c) + P/2: nodes at φ̂ = c + o − P/2 (folded: φ̂ = o = ψ)
            shift = 0.0 if fold else period / 2

            def az_nodes(x: torch.Tensor) -> torch.Tensor:  # Lobatto nodes x ∈ [−1, 1] → φ̂ over [a, b]
                return (rg.centre[:, None] - shift + a[:, None] + (b - a)[:, None] * (x + 1) / 2).to(dtype)

            ph_nodes = az_nodes(xp_t)

        # ---- the model at the nodes; T_s, T_ρ in its working dtype: float64 without shadowing,
        # where they grow like σ∥/cos θ̂ and R_B (1 − T_ρ) + T_s cancels them (expectation._work_dtype)
        vz = th_nodes.to(dtype)[:, :, None].expand(b_, nz, nphi)
        va = ph_nodes[:, None, :].expand(b_, nz, nphi)
        slopes = SlopeStatistics.from_variances(p["vx"][sl, None, None], p["vy"][sl, None, None], p["cxy"][sl, None, None])
        if day is None:
            sky = _sky_per_image(select_sky(p["sky"], sl), b_, dtype, device, 2)
        else:  # per azimuth node: the scattered sky along the mirror azimuth
            sky = _sky_with_day(select_sky(p["sky"], sl), day, p, sl, ph_nodes[:, None, :])
        t_s, t_rho, _ = _reflection_terms(vz, va, slopes, (p["n"][sl, None, None], p["k"][sl, None, None]), sky,
                                          scene.shadowing, q, None, scene.sky_masking)
        if p["air_scale"] is not None:
            t_s = t_s * p["air_scale"][sl, None, None].to(t_s.dtype)
        rb = p["rb"][sl, None, None].to(t_s.dtype)
        coarse = (rb - rb * t_rho + t_s).to(dtype)  # R_a at the nodes (b, nz, nphi)
        out = dict(rg=rg, lo=lo, span_z=span_z, ph_nodes=ph_nodes, coarse=coarse, a=None if iso else a,
                   b=None if iso else b)
        if textured:  # the realization's departure from R_a at the nodes, per quantile of the resolved slope
            ph_tex, sky_tex = ph_nodes, sky
            if nphi_tex != nphi:  # its own azimuth nodes, and the scattered sky along their mirror azimuths
                ph_tex = az_nodes(xp_tex)
                sky_tex = _sky_with_day(select_sky(p["sky"], sl), day, p, sl, ph_tex[:, None, :])
            out["delta"], out["active"] = tex.node_values(sl, p, tex.field(sl, p), ph_tex, sky_tex, scene, q, altitude,
                                                          earth_radius_m, eps[sl], lo, span_z)
        return out

    # where the chunks of pixels are smaller than 4 images (textured scenes), the nodes first, for
    # groups of up to 4 images (their model's temporaries stay tens of MB) spread over the workers,
    # every per-image tensor then joined over the batch; otherwise each chunk its own nodes
    group = max(1, min(4, -(-B // max(1, torch.get_num_threads()))))
    node_all = None
    if chunk < group:
        parts = map_chunks(nodes, [slice(i, min(i + group, B)) for i in range(0, B, group)], device)
        node_all = {k: _map_nodes(lambda *t: torch.cat(t), *(q[k] for q in parts)) for k in parts[0]}

    def one(sl: slice) -> torch.Tensor:
        """Images ``sl``: the fine tables from the nodes' values, then the pixels; (b, H, W).
        Everything here is per image, so chunks run independently (``map_chunks``)."""
        b_ = sl.stop - sl.start
        wd = p["wind_direction"][sl]
        nd = nodes(sl) if node_all is None else {k: _map_nodes(lambda t: t[sl], v) for k, v in node_all.items()}
        rg, lo, span_z, ph_nodes, coarse, a, b = (nd[k] for k in ("rg", "lo", "span_z", "ph_nodes", "coarse", "a", "b"))
        delta = None
        if textured:
            wf = tex.field(sl, p)
            if bool(nd["active"].any()):  # the fine texture volume of the chunk (None: nothing resolved)
                delta = tex.volume(nd["delta"], sl, scene, altitude, earth_radius_m, eps[sl], lo, span_z)
        glint_tab = None  # (b,) bool: images whose glint the fine table holds (sunny, unfolded, no texture)
        # textured seas put their whitecaps on the crests, a fraction f_pix per pixel: the fine table
        # then carries the foam-free sea and the foam as two channels, mixed per pixel
        crest = textured and delta is not None and p["foam"] is not None

        # ---- the fine tables: sea rows [τ L_z | L_path] · [R_a ; 1] · L_oᵀ at ζ = lo + span (y_z + 1)/2,
        # sky rows at cos = s0 + j ds (a ray at the horizontal, cos = 0, where a sea-level sky is
        # held constant below, a kink, falls on a row); row r is read at gy = 2 r / (N − 1) − 1
        if scene.path is not None:
            cos_rows = (eps[sl, None] * torch.sinh(lo[:, None] + span_z[:, None] * (y_z + 1) / 2)).clamp(0.0, 1.0).to(dtype)
            h = altitude[sl].to(dtype)[:, None]
            tau, l_path = scene.path(h.expand_as(cos_rows), _slant_range(cos_rows, h, earth_radius_m), clamp=True)
            if p["air_scale"] is not None:
                l_path = l_path * p["air_scale"][sl, None].to(dtype)
            sea_rows = torch.cat([tau[:, :, None] * Lz_t, l_path[:, :, None].to(dtype)], -1) @ torch.cat(
                [coarse, torch.ones(b_, 1, nphi, dtype=dtype, device=device)], 1)
        else:
            sea_rows = Lz_t @ coarse  # (b, M_z, nphi)
        if p["foam"] is not None:
            # whitecaps, an area fraction f: (1 − f) · sea + f · foam, the foam exact on every fine row
            # (its emissivity has kinks in θ̂ that the nodes would smooth), through the same path
            cos_f = (eps[sl, None] * torch.sinh(lo[:, None] + span_z[:, None] * (y_z + 1) / 2)).clamp(0.0, 1.0).to(dtype)
            foam_rows = _foam_radiance(torch.acos(cos_f), p, sl, scene)
            if scene.path is not None:
                foam_rows = tau.to(dtype) * foam_rows + l_path.to(dtype)
            if not crest:
                f = p["foam"][sl].to(dtype)[:, None, None]
                sea_rows = sea_rows + f * (foam_rows[:, :, None] - sea_rows)
        s_lo, s_hi = (torch.where(rg.any_sky, v, torch.full_like(v, d)) for v, d in zip(rg.sky, (0.0, 1.0)))
        s_pad = torch.clamp(1e-6 * (s_hi - s_lo), min=1e-7)
        s_lo, s_hi = s_lo - s_pad, s_hi + s_pad
        ds = (s_hi - s_lo) * (1.0 + es) / (Ms - 1)
        s0 = s_lo - _EXT * ds
        r0 = -s0 / ds
        s0 = torch.where((r0 > 0) & (r0 < Ms - 1), s0 - (torch.ceil(r0) - r0) * ds, s0)
        has_sky = bool(rg.any_sky.any())
        if has_sky:
            s_rows = (s0[:, None] + ds[:, None] * torch.arange(Ms, dtype=torch.float64, device=device)).to(dtype)
            air = None if p["air_scale"] is None else p["air_scale"][sl]
            sky_rows = _sky_rows(select_sky(p["sky"], sl), air, scene, s_rows, altitude[sl]).to(dtype)
        else:  # no sky work when no pixel sees sky
            sky_rows = torch.zeros(b_, Ms, dtype=dtype, device=device)
        if brightness and not (textured or sunny):  # in kelvin at the azimuth nodes, before the azimuth resampling: the
            # brightness temperature is as smooth in azimuth as the radiance, and this costs
            # (M_z + M_s) × nphi conversions an image instead of one a pixel
            sea_rows = _kelvin(sea_rows, scene.band)
            if has_sky:
                sky_rows = _kelvin(sky_rows, scene.band)
        if iso:
            fine = torch.cat([sea_rows, sky_rows[:, :, None]], 1)  # (b, N, 1)
        else:  # sea rows resampled in azimuth; sky rows repeated (not through L_o, whose overhang
            # rows sum to 1 only to rounding: sky pixels may read the border columns)
            y = torch.linspace(-1.0 - ep, 1.0 + ep, Lp_t.shape[0], dtype=torch.float64, device=device)
            if ratio:  # columns uniform in u (_azimuth_ratio): the node coordinate of each, per image
                u_a, u_b = _ratio_of_angle(a, fold), _ratio_of_angle(b, fold)

                def col_angle(t: torch.Tensor) -> torch.Tensor:  # the angle o of column coordinates t ∈ [−1, 1]
                    return _angle_of_ratio(u_a[:, None] + (u_b - u_a)[:, None] * (t + 1) / 2, fold)

                L_cols = _barycentric(xp, 2.0 * (col_angle(y) - a[:, None]) / (b - a)[:, None] - 1.0).to(dtype)
                sea_cols = sea_rows @ L_cols.transpose(1, 2)
            else:  # columns uniform in the angle o

                def col_angle(t: torch.Tensor) -> torch.Tensor:
                    return a[:, None] + (b - a)[:, None] * (t + 1) / 2

                sea_cols = sea_rows @ Lp_t.T
            if sunny and not (fold or textured):  # the glint's smooth factor, where the table resolves it
                scale = None if scene.path is None else tau.to(dtype)
                if p["foam"] is not None:
                    f = 1.0 - p["foam"][sl].to(dtype)[:, None]
                    scale = f.expand(b_, Mz) if scale is None else scale * f
                r_glint, glint_tab = _glint_core_table(scene, p, sl, eps[sl], lo, span_z, y_z, col_angle, y,
                                                       rg.centre, period / 2, sea_cols, scale, table, dtype)
            fine = torch.cat([sea_cols, sky_rows[:, :, None].expand(-1, -1, Lp_t.shape[0])], 1)
        if crest:  # channel 1: the foam (sky rows alike), one grid_sample reads both
            fine = torch.stack([fine, torch.cat([foam_rows, sky_rows], 1)[:, :, None].expand_as(fine)], 1)
        elif glint_tab is not None and bool(glint_tab.any()):  # channel 1: the glint's smooth factor (0 on sky rows)
            fine = torch.stack([fine, torch.cat([r_glint, torch.zeros_like(fine[:, Mz:])], 1)], 1)
        else:
            fine = fine[:, None]

        # ---- per pixel: the table coordinates, one grid_sample
        k_sea = (2.0 / (N - 1)) * (Mz - 1) / (span_z * (1.0 + ez))  # dgy/dζ
        b_sea = -1.0 - k_sea * (lo - ez * span_z / 2)
        k_sky = (2.0 / (N - 1)) / ds
        b_sky = 2.0 * Mz / (N - 1) - 1.0 - k_sky * s0
        k_sea, b_sea, k_sky, b_sky = (v.to(dtype)[:, None, None] for v in (k_sea, b_sea, k_sky, b_sky))
        # the azimuth coordinate's offset: o = (ray azimuth + offset) mod π (folded: ψ = |o − π/2|)
        offset = None if iso else ((math.pi / 2 - wd).to(dtype) if fold else
                                   (math.pi / 2 - rg.centre - wd.double()).to(dtype) if period == math.pi else
                                   (-rg.centre - wd.double()).to(dtype))
        if not iso:  # gx = b_az + k_az · (the azimuth coordinate: its ratio stand-in u, or the angle)
            lo_a, hi_a = (u_a, u_b) if ratio else (a, b)
            k_az = (2.0 / ((hi_a - lo_a) * (1.0 + ep))).to(dtype)[:, None, None]
            b_az = ((-2.0 * lo_a / (hi_a - lo_a) - 1.0) / (1.0 + ep)).to(dtype)[:, None, None]
        if cg is not None:  # per image: (cos θ̂/ε)² = c1² (dz² − s_h²), c1 = k_r/ε, s_h the horizon dip's sine
            c1 = (inv_eps[sl] if cg.flat else cg.k_r[sl].to(dtype) * inv_eps[sl])[:, None, None]
            sh = cg.s_h[sl, None, None] if not cg.flat else torch.zeros_like(c1)
        # the main path (cameras, no texture or sun, no gradient through the rays): in place, in a
        # reused workspace (roughsea_torch._pixels)
        # (on the CPU, where fresh memory page-faults; CUDA has its caching allocator and streams)
        xy = (None if geometry is not None or textured or sunny or (not iso and not ratio) or cg.requires_grad
              or device.type != "cpu" else cg.separable_xy(sl))
        if xy is not None:
            per_image = [c1, sh, k_sea, b_sea, k_sky, b_sky] + ([] if iso else [offset, k_az, b_az])
            if torch.is_grad_enabled() and any(t.requires_grad for t in per_image):
                xy = None  # a gradient through the per-image maps (e.g. wind_direction): the general path
        if xy is not None:
            az_map = None if iso else dict(offset=offset, fold=fold, k=k_az, b=b_az)
            grid, seaf = table_grid(cg, sl, xy, c1, sh, (k_sea, b_sea), (k_sky, b_sky) if has_sky else None, az_map,
                                    fresh_grid=torch.is_grad_enabled() and fine.requires_grad)
            vals = F.grid_sample(fine, grid, mode="bilinear", padding_mode="border", align_corners=True)[:, 0]
            if vals.requires_grad or len(chunks) == 1:
                return vals
            out[sl] = vals
            return None
        if geometry is not None:
            cos, sea = geometry.cos_view_zenith[sl], geometry.is_sea[sl]
            seaf = sea.to(dtype)
            dx, dy = geometry._dx[sl], geometry._dy[sl]
            zeta = _asinh((cos * inv_eps[sl, None, None]).clamp_min(0.0))
        else:  # ζ straight from the ray's vertical component dz: cos θ̂ / ε = (k_r/ε) √((dz + s_h)(dz − s_h))
            cos, dx, dy = cg.ray_components(sl, need_xy=not (iso or ratio) or sunny)
            if ratio:  # the table's azimuth coordinate from components along axes turned by the offset
                c_t, s_t = cg.ray_components(sl, azimuth_offset=offset)
            # q = (cos θ̂/ε)² = c1² (dz² − s_h²); sky pixels (unused) and the horizon row are held at
            # a tiny q > 0, which keeps √'s gradient finite
            # the sea mask as 1/0 in the image dtype, written by the compare (a bool → float copy costs
            # ~6 compares); as bool only where the texture or the glint needs it
            seaf = torch.lt(cos.detach(), -sh.detach(), out=torch.empty(cos.shape, dtype=dtype, device=device))
            sea = seaf.bool() if (textured or sunny) else None
            q_ = torch.addcmul(-(c1 * sh) ** 2, cos, cos * (c1 * c1)).clamp_min(1e-30)
            # asinh √q as a log: torch.asinh is ~20x slower on the CPU
            zeta = torch.log(torch.sqrt(q_) + torch.sqrt(q_ + 1.0))
        gy = torch.addcmul(b_sea, zeta, k_sea)
        if has_sky:  # cos: the sky pixels' cos of the ray's zenith (dz); lerp by weight 0 or 1 is an
            # exact select, and costs an eighth of torch.where on the CPU
            gy = torch.lerp(torch.addcmul(b_sky, cos, k_sky), gy, seaf)
        if iso:
            gx = torch.zeros_like(gy)
        else:
            az = _azimuth_ratio(c_t, s_t, fold) if ratio else _azimuth_coordinate(dx, dy, offset, fold, period)
            gx = torch.addcmul(b_az, az, k_az)
        # bilinear, not bicubic: torch's bicubic is Keys' kernel with a = −0.75, which converges
        # only to first order; bilinear on the fine table is second order (~3e-7 at 3072 rows).
        # The grid is stacked in planes (b, 2, H, W) and passed as a (b, H, W, 2) view: grid_sample
        # reads it as fast, and planes stack ~4x faster than interleaved pairs.
        vals = F.grid_sample(fine, torch.stack([gx, gy], 1).permute(0, 2, 3, 1), mode="bilinear",
                             padding_mode="border", align_corners=True)
        r_vals = None
        if crest:
            vals, foam_vals = vals[:, 0], vals[:, 1]
        elif fine.shape[1] == 2:  # the glint's smooth factor, times its Gaussian core below
            vals, r_vals = vals[:, 0], vals[:, 1]
        else:
            vals = vals[:, 0]
        if day is not None and has_sky:  # the scattered sky of the sky pixels, by zenith and azimuth, at them alone
            flat = (seaf.reshape(-1) == 0).nonzero().squeeze(1)
            at = lambda t: t.reshape(-1).index_select(0, flat)  # noqa: E731
            v = _day_sky_pixels(day, sl, at(cos), at(dx), at(dy), torch.div(flat, H * W, rounding_mode="floor"))
            vals = vals.reshape(-1).index_add(0, flat, v).reshape(vals.shape)
        resolved = None
        if textured or sunny:  # cos θ̂ of the sea pixels, from q (these scenes need the cameras)
            cos_t = eps[sl, None, None].to(dtype) * torch.sqrt(q_)
        if textured and delta is not None:  # (textured: always the angle coordinate, az)
            texture, x_pix, cov_pix, *crest_var = tex.pixels(sl, p, wf, delta, cos_t, zeta, az, dx, dy, sea, lo,
                                                             span_z, a, b, altitude, earth_radius_m, eps[sl], crest=crest)
            vals = vals + texture
            resolved = (x_pix, cov_pix)
        if r_vals is not None:
            vals = vals + r_vals * _glint_sharp_pixels(scene, p, sl, cos_t, dx, dy, sea & glint_tab[:, None, None])
        if sunny and (glint_tab is None or not bool(glint_tab.all())):  # the rest per pixel
            rows = None
            if scene.path is not None:  # each pixel's fractional sea row of the fine table
                rows = (tau.to(dtype), (zeta - (lo - ez * span_z / 2).to(dtype)[:, None, None])
                        * ((Mz - 1) / (span_z * (1.0 + ez))).to(dtype)[:, None, None])
            glint = _glint_pixels(scene, p, sl, cos_t, dx, dy, sea if glint_tab is None else sea & ~glint_tab[:, None, None],
                                  rows, resolved)
            if p["foam"] is not None and not crest:
                glint = glint * (1.0 - p["foam"][sl].to(dtype))[:, None, None]
            vals = vals + glint
        if crest:  # (1 − f_pix) · (sea + texture + glint) + f_pix · foam
            from .foam import _crest_foam_fraction

            x_r, v_r, v_t = crest_var[0]
            f_pix = _crest_foam_fraction(x_r, v_r, v_t, p["foam"][sl].to(dtype)[:, None, None])
            # no foam in the sky: there f_pix would be W, and the lerp would take that share of the
            # sky pixels from the foam channel's sky rows, which lack the day's scattered sky
            # (added to the sky pixels of channel 0 above)
            vals = torch.lerp(vals, foam_vals, torch.where(sea, f_pix, torch.zeros_like(f_pix)))
        if sunny and has_sky:  # the sun's disk itself, where it is in view
            ifov = (1.0 / cg.cameras.fx.to(dtype))[sl]
            vals = vals + _sun_disk_pixels(scene, B, sl, cos, dx, dy, ~sea, ifov)
        if (textured or sunny) and brightness:  # per pixel: texture and glint are added in radiance
            vals = _kelvin(vals, scene.band)
        if vals.requires_grad or len(chunks) == 1:
            return vals
        out[sl] = vals  # written by the chunk's own thread: no serial concatenation at the end
        return None

    chunks = [slice(i, min(i + chunk, B)) for i in range(0, B, chunk)]
    out = torch.empty(B, H, W, dtype=dtype, device=device) if len(chunks) > 1 else None
    parts = map_chunks(one, chunks, device)
    if textured and tex.scaled:
        _warn_scaled()
    if parts[0] is None:
        return out
    return parts[0] if len(parts) == 1 else torch.cat(parts)


def _warn_scaled() -> None:
    """The warning of :func:`~roughsea_torch.clutter.reconcile_scale`, from the calling thread (the
    chunks run on workers) and pointing at the user's line: the first frame outside this package,
    kornia and torch (an augmentation's own call chain runs through both)."""
    import sys
    import warnings

    here = os.path.dirname(os.path.abspath(__file__))
    others = tuple(os.path.dirname(os.path.abspath(m.__file__)) for m in (torch, sys.modules.get("kornia")) if m is not None)
    frame, level = sys._getframe(1), 2  # stacklevel 2: the caller of this function
    while frame is not None and frame.f_code.co_filename.startswith((here, *others)):
        frame, level = frame.f_back, level + 1
    # one fixed text, so Python's default filter shows it once per calling line, not once a batch
    warnings.warn("SeaScene(seed=...): where a pixel's footprint resolves more slope variance in the wave spectrum than "
                  "the scene's slope law allows (ECKV against Cox-Munk: light winds, centimetre footprints), the "
                  "resolved slopes are scaled down so that the two scales still add up to SlopeStatistics "
                  "(roughsea_torch.clutter.reconcile_scale)", stacklevel=level)


def _kelvin(radiance: torch.Tensor, band: SpectralBand) -> torch.Tensor:
    """Brightness temperature [K] of band radiances that must be > 0 (``ValueError`` otherwise:
    without shadowing, Eq. 7 makes R_a negative near the horizon, which has no temperature)."""
    low = radiance.detach().amin()
    if not bool(low > 0):
        raise ValueError(f"output='brightness_temperature': a radiance of {float(low):.3g} W m-2 sr-1 (<= 0) has no "
                         "brightness temperature; without shadowing (Eq. 7) R_a goes negative near the horizon: "
                         "use shadowing=True or output='radiance'")
    return brightness_temperature(radiance, band)


class SeaRenderer(torch.nn.Module):
    """``nn.Module`` form of :func:`render`: holds the settings, ``forward(cameras, scene)``."""

    def __init__(
        self,
        earth_radius_m: float = EARTH_RADIUS_M,
        method: str = "table",
        output: str = "radiance",
        table: TableSize = TableSize(),
        quadrature: Quadrature | None = None,
    ):
        super().__init__()
        self.earth_radius_m = earth_radius_m
        self.method = method
        self.output = output
        self.table = table
        self.quadrature = quadrature

    def forward(self, cameras: PinholeCamera, scene: SeaScene) -> torch.Tensor:
        return render(
            cameras, scene, earth_radius_m=self.earth_radius_m, method=self.method, output=self.output,
            table=self.table, quadrature=self.quadrature,
        )

    def extra_repr(self) -> str:
        return f"earth_radius_m={self.earth_radius_m}, method={self.method!r}, output={self.output!r}, table={self.table}"

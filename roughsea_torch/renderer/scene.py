"""What is in front of the cameras: :class:`SeaScene` (one value per image), its checks and caches,
and :class:`SceneParameters`, the per-image tensors a render reads (resolved once per call).

Units and conventions are :class:`SeaScene`'s (SI, radians; world azimuths from +x towards +y).
"""

from __future__ import annotations

import math
import threading
import warnings
from dataclasses import dataclass
from typing import Any

import numpy as np
import torch

from .._validation import check_finite_range, parse_seeds, per_batch
from ..atmosphere import as_sky, available_atmospheres, load_observer_sky, load_path, load_sky, surface_air_temperature
from ..daysky import AEROSOLS, load_scattered_sky
from ..foam import whitecap_fraction
from ..masking import check_shadowing
from ..optics import band_index_lookup, split_refractive_index
from ..radiometry import LWIR, SpectralBand, as_band, band_radiance, brightness_temperature
from ..slopes import MAX_WIND_SPEED, SlopeStatistics
from ..solar import load_solar_irradiance
from ..sun import Sun
from ..waves import MAX_WIND_DIRECTION, WaveField, check_time
from ..whitecaps import SKIN_DEFICIT_K, check_skin_deficit
from .settings import TableSize

__all__ = ["SeaScene", "SceneParameters", "check_foam"]


@dataclass
class SceneParameters:
    """A scene's per-image values for one render of B images, in the render's dtype and device.

    Attributes:
        vx, vy, cxy: (B,) the slope covariance in the upwind frame: a², b² and r a b (Eq. 1).
        wind_direction: (B,) world azimuth of the upwind axis [rad].
        rb: (B,) R_B, the sea's blackbody band radiance [W m⁻² sr⁻¹].
        n, k: (B,) the sea's refractive index m = n + i k.
        sky: the scene's sky (a callable of cos(zenith); a ``TabulatedSky`` or ``ConstantSky`` may
            hold one row per image).
        foam: (B,) the whitecap fraction, or None where no image has foam.
        skin_deficit: (B,) ΔT_skin [K], the bulk − skin temperature of the active whitecaps.
        air_scale: (B,) B(T_air)/B(T_atm), the factor on the sky and path radiance of a named
            atmosphere whose surface air is set (``SeaScene(air_temperature=)``), or None.
    """

    vx: torch.Tensor
    vy: torch.Tensor
    cxy: torch.Tensor
    wind_direction: torch.Tensor
    rb: torch.Tensor
    n: torch.Tensor
    k: torch.Tensor
    sky: Any
    foam: torch.Tensor | None
    air_scale: torch.Tensor | None
    skin_deficit: torch.Tensor

    @property
    def batch_size(self) -> int:
        return int(self.vx.shape[0])


_CACHE_LOCK = threading.RLock()  # SeaScene's caches (skies, wave fields), filled from worker threads


def _check_atmosphere_name(argument: str, name: str) -> None:
    """``ValueError`` naming the scene's argument (``sky``, ``path``) for an unknown atmosphere."""
    known = available_atmospheres()
    if name not in known:
        raise ValueError(f"{argument}: unknown atmosphere {name!r}; available: {', '.join(known)}")


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


def _per_image_value(name: str, what: str, value: Any, check: Any) -> Any:
    """``value`` of a per-image scene argument ``name`` (a float or a (B,) tensor/array), checked by
    ``check(name, value)``; a list, a tuple or more than one axis is a ValueError naming it."""
    if isinstance(value, (list, tuple)):
        raise ValueError(f"{name}: give a float or a tensor of shape (B,), {what}; got a "
                         f"{type(value).__name__} (use torch.tensor(...))")
    check(name, value)
    if isinstance(value, (torch.Tensor, np.ndarray)) and value.ndim > 1:
        raise ValueError(f"{name}: must be a float or a tensor of shape (B,); got shape {tuple(value.shape)}")
    return value


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
        shadowing: Eq. 5 (True, default), Eq. 7 (False), "correlated": Eq. 5 with the slope-conditioned
            masking of :mod:`roughsea_torch.masking`, or "multiscale": Eq. 5 with the masking of a sea
            of many scales (:mod:`roughsea_torch.multiscale_masking`: the short waves on the back of a
            long one are hidden; near grazing the mean a ray tracer of the waves gives, to 0.05 K),
            each on emission and reflected sky (the sun's glint keeps Eq. 5). Anything else is a
            ``ValueError``.
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
        skin_deficit: ΔT_skin [K], the bulk − skin temperature, float or (B,) tensor in [0, 5] K (default
            :data:`~roughsea_torch.whitecaps.SKIN_DEFICIT_K` = 0.2 K): ``sea_temperature`` is the
            radiating skin's, a few tenths of a kelvin cooler than the water below (Jessup, Zappa & Yeh
            1997, J. Geophys. Res. 102, C10, 23145–23153: about 0.2 K, up to 0.5 K under strong cooling);
            active breaking mixes the skin away, so active whitecaps radiate at T_sea + ΔT_skin and
            residual foam at T_sea (:mod:`roughsea_torch.whitecaps`). 0: both at T_sea. Differentiable.

    Example:
        >>> scene = SeaScene(wind_speed=torch.tensor([3.0, 12.0]), wind_direction=0.5,
        ...                  sea_temperature=290.0, sky=lambda c: 10.0 + 20.0 * (1 - c) ** 6)
        >>> scene.batch_size
        2
    """

    def __init__(  # ~100 lines: the signature (23 keyword arguments) and one check or conversion per argument
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
        shadowing: bool | str = True,
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
        skin_deficit: Any = SKIN_DEFICIT_K,
    ):
        if (slopes is None) == (wind_speed is None):
            raise ValueError("SeaScene: give exactly one of slopes= or wind_speed=")
        if (sea_temperature is None) == (sea_radiance is None):
            raise ValueError("SeaScene: give exactly one of sea_temperature= or sea_radiance=")
        if wind_speed is not None:
            check_finite_range("wind_speed", wind_speed, 0.0, MAX_WIND_SPEED, unit="m/s")
            slopes = SlopeStatistics.cox_munk(wind_speed, anisotropic=anisotropic)
        if not isinstance(slopes, SlopeStatistics):
            raise ValueError(f"slopes must be a SlopeStatistics; got {type(slopes).__name__}")
        check_finite_range("wind_direction", wind_direction, -MAX_WIND_DIRECTION, MAX_WIND_DIRECTION, unit="rad")
        _warn_degrees(wind_direction)
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
            _check_atmosphere_name("sky", self.atmosphere)
            sky = load_sky(self.atmosphere, (self.band.lo, self.band.hi), self.band.response, dtype=torch.float64)
        self.sky = as_sky(sky)
        if path is None:
            path = self.atmosphere is not None
        if path is True:
            if self.atmosphere is None:
                raise ValueError("path=True needs a named atmosphere: give sky='<name>' or path='<name>'")
            path = self.atmosphere
        if isinstance(path, str):
            _check_atmosphere_name("path", path)
            path = load_path(path, (self.band.lo, self.band.hi), self.band.response, dtype=torch.float64)
        if path is not False and not callable(path):
            raise ValueError(f"path must be None, a bool, an atmosphere name or an AtmosphericPath; got {path!r}")
        self.path = path or None
        self._observer_skies: dict[Any, Any] = {}
        if air_temperature is not None:
            if self.atmosphere is None:
                raise ValueError("air_temperature needs a named atmosphere (sky='<name>'); scale a custom sky yourself")
            check_finite_range("air_temperature", air_temperature, 200.0, 350.0, unit="K")
            self._atmosphere_air_temperature = surface_air_temperature(self.atmosphere)
        self.air_temperature = air_temperature
        self.refractive_index = refractive_index
        self.shadowing = check_shadowing(shadowing)
        if seed is not None:
            if wind_speed is None:
                raise ValueError("seed: a textured sea needs wind_speed= (the wave spectrum is driven by the wind); "
                                 "seed=None renders the expectation image of slopes=")
            parsed = parse_seeds(seed)  # WaveField's check: ints in [0, 2**63), numpy integers too
            seed = parsed.values[0] if parsed.single else list(parsed.values)
        self.time_s = time_s  # checked by its setter
        if sun is not None:
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
        self.skin_deficit = skin_deficit  # checked by its setter
        self.seed = seed
        self._wave_fields: dict[Any, Any] = {}

    @property
    def time_s(self) -> Any:
        """Time of the realization [s]: a float or (B,) tensor/array in [−MAX_TIME_S, MAX_TIME_S]."""
        return self._time_s

    @time_s.setter
    def time_s(self, value: Any) -> None:  # checked on every assignment (render_clip sets each frame's)
        self._time_s = _per_image_value("time_s", "one time per image", value, check_time)

    @property
    def skin_deficit(self) -> Any:
        """ΔT_skin [K], the active whitecaps' bulk − skin temperature: a float or (B,) tensor in [0, 5] K."""
        return self._skin_deficit

    @skin_deficit.setter
    def skin_deficit(self, value: Any) -> None:  # checked on every assignment, as time_s
        self._skin_deficit = _per_image_value("skin_deficit", "one value per image", value, check_skin_deficit)

    @property
    def sun(self) -> Any:
        """The scene's :class:`~roughsea_torch.sun.Sun` (world azimuth), or None: the one given, or one
        at ``sun_zenith``/``sun_azimuth`` with the named atmosphere's LOWTRAN7 direct irradiance in
        the scene's band (read each time, so it follows the scene's current fields)."""
        if self._sun is not None or self.sun_zenith is None:
            return self._sun
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
        return _cached_one(self._observer_skies, (self.atmosphere, self.band),
                           lambda: load_observer_sky(self.atmosphere, self.band, dtype=torch.float64))

    def field_sizes(self) -> dict[str, int]:
        """The batch size each per-image argument gives, by its name (arguments of shape (B,) only;
        a sequence of seeds gives its length)."""
        fields = {"wind_speed" if self.wind_speed is not None else "slopes": (
                      self.slopes.var_upwind, self.slopes.var_crosswind, self.slopes.cov),
                  "wind_direction": (self.wind_direction,), "sea_temperature": (self.sea_temperature,),
                  "sea_radiance": (self.sea_radiance,), "air_temperature": (self.air_temperature,),
                  "time_s": (self.time_s,), "skin_deficit": (self.skin_deficit,)}
        out = {}
        for name, values in fields.items():
            for v in values:
                if isinstance(v, torch.Tensor) and v.ndim > 0:
                    out[name] = int(v.shape[0])
        if isinstance(self.seed, list):  # one seed per image: a list of 1 is a batch of 1, not a broadcast
            out["seed"] = len(self.seed)
        return out

    @property
    def batch_size(self) -> int:
        """B: the batch size of the per-image arguments (1 when every one is a scalar); a ``ValueError``
        naming them where they disagree."""
        by_name = self.field_sizes()
        others = {v for k, v in by_name.items() if k != "seed"}
        if "seed" in by_name and len(others) == 1:
            self.seeds(next(iter(others)))  # ValueError naming seed, B and its length if they differ
        sizes = set(by_name.values())
        if len(sizes) > 1:
            listing = ", ".join(f"{k} has {v}" for k, v in by_name.items())
            raise ValueError(f"SeaScene: the per-image arguments disagree on the batch size ({listing}); give each "
                             "one value per image, or a scalar for all")
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
        # (wind and direction in float64 whatever the render's dtype: the realization of a seed must not
        # depend on it; the field keeps them in float64 and makes its tiles in ``dtype``)
        wind = per_batch("wind_speed", self.wind_speed, B, torch.float64, device)[sl]
        if bool((wind.detach() == 0).any()):
            raise ValueError("wind_speed: a textured sea (SeaScene(seed=...)) needs a wind above 0 m/s; a calm sea has "
                             "no waves to draw: render it with seed=None (the expectation image)")
        wd = per_batch("wind_direction", self.wind_direction, B, torch.float64, device)[sl]
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

    def resolved(self, B: int, dtype: torch.dtype, device: torch.device) -> SceneParameters:
        """The scene's per-image tensors for a render of B images (:class:`SceneParameters`)."""
        own = self.batch_size
        if own not in (1, B):
            names = " and ".join(k for k, v in self.field_sizes().items() if v == own)
            raise ValueError(f"SeaScene: {names} {'have' if ' and ' in names else 'has'} batch size {own} (one value per "
                             f"image) but the cameras have {B} image{'s' if B != 1 else ''}; give one value per camera"
                             + (", or one int seed (seeds are then derived per image)" if "seed" in names else ""))
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
            m = band_index_lookup(self.band, t_idx.double())
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
                foam = whitecap_fraction(per_batch("wind_speed", self.wind_speed, B, dtype, device))
        elif self.foam is not None:
            foam = per_batch("foam", self.foam, B, dtype, device)
        if foam is not None and not bool((foam > 0).any()):
            foam = None  # no foam anywhere: leave it out
        return SceneParameters(vx=vx, vy=vy, cxy=cxy, wind_direction=wd, rb=rb, n=n.expand(B), k=k.expand(B), sky=self.sky,
                               foam=foam, air_scale=air_scale,
                               skin_deficit=per_batch("skin_deficit", self.skin_deficit, B, dtype, device))


def _warn_degrees(wind_direction: Any) -> None:
    """A warning, pointing at the caller's caller (the user's ``SeaScene(...)`` line), where some wind direction
    exceeds 2π in magnitude: ``SeaScene`` takes radians (the samplers and augmentations take degrees), and
    45.0 rad is almost surely 45° passed as it is. Larger angles stay valid (they wrap)."""
    big = float(torch.as_tensor(wind_direction).detach().abs().max()) if np.size(wind_direction) else 0.0
    if big > 2.0 * math.pi * (1.0 + 1e-6):
        warnings.warn(f"SeaScene(wind_direction=...): {big:g} rad is more than a full turn; wind_direction is in "
                      f"radians (world azimuth of the upwind axis). For degrees pass math.radians({big:g}).",
                      stacklevel=3)


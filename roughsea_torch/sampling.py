"""Random scene parameters: the field tables, :class:`SceneSampler` and the seeds of images and frames.

:class:`SceneSampler` draws scene and pose parameters (wind, sea and air temperature, atmosphere,
altitude, pitch, roll, yaw, field of view; the air either on its own or as the sea's temperature
plus an air–sea difference; with ``texture`` a wave seed and a time; with
``motion`` a platform's pitch, roll and heave oscillations; with ``daytime`` the sun) uniformly
from ranges the user gives. It is separate from the deterministic rendering of a draw
(:mod:`roughsea_torch.parameter_render`), as kornia separates parameter generation from the
transform. Every draw comes from a CPU ``torch.Generator`` (or the global one), so the same seed
gives the same parameters on every device; :meth:`SceneSampler.sample_indexed` gives each image
index its own stream (:func:`image_seed`), so an image does not depend on which batch, worker or
rank made it (what the dataset generator relies on). :func:`frame_parameters` turns a clip's draw
into the pose, time and noise seed of each of its frames.

Units: temperatures in K, angles in degrees (wind direction: world azimuth of the upwind axis,
from +x towards +y; the camera's yaw in the same frame), altitude and heave in m, wind speed in
m s⁻¹ at 12.5 m, times and periods in s, frame rate in Hz.
"""

from __future__ import annotations

import math
import warnings
from typing import Any, Sequence

import torch

from ._validation import check_finite_range
from .atmosphere import available_atmospheres, load_path, surface_air_temperature
from .motion import PlatformMotion
from .radiometry import LWIR, as_band
from .slopes import MAX_WIND_SPEED

__all__ = [
    "SceneSampler",
    "frame_parameters",
    "image_seed",
    "frame_noise_seed",
    "as_range",
    "SCENE_FIELDS",
    "MOTION_FIELDS",
    "SUN_FIELDS",
    "SCENE_FIELD_NAMES",
    "RENDER_FIELD_NAMES",
    "MOTION_FIELD_NAMES",
    "TIME_RANGE_S",
    "DEFAULT_TIME_S",
]

# (name, allowed range, unit, default range); one uniform is drawn per field, in this order, except for
# air_sea_difference (T_air − T_sea), which takes air_temperature's: the two exclude each other, so the
# difference adds no draw, and a sampler without it draws what the samplers before it drew
SCENE_FIELDS: tuple[tuple[str, tuple[float, float], str, Any], ...] = (
    ("wind_speed", (0.0, MAX_WIND_SPEED), "m/s", (1.0, 15.0)),
    ("wind_direction_deg", (-3600.0, 3600.0), "deg", (0.0, 360.0)),
    ("sea_temperature", (260.0, 320.0), "K", (285.0, 300.0)),
    ("air_temperature", (230.0, 330.0), "K", None),
    ("altitude_m", (0.5, 20000.0), "m", (10.0, 100.0)),
    ("pitch_deg", (-90.0, 90.0), "deg", (-10.0, -1.0)),
    ("roll_deg", (-180.0, 180.0), "deg", (-2.0, 2.0)),
    ("yaw_deg", (-3600.0, 3600.0), "deg", 0.0),
    ("hfov_deg", (0.5, 179.0), "deg", (20.0, 40.0)),
    ("air_sea_difference", (-30.0, 30.0), "K", None),
)
# the platform's oscillations of a clip (motion.PlatformMotion), drawn after the scene's fields,
# then one phase φ ∈ [0, 2π) [rad]; the defaults are a ship's first-order response to a swell
MOTION_FIELDS: tuple[tuple[str, tuple[float, float], str, Any], ...] = (
    ("pitch_amplitude_deg", (0.0, 45.0), "deg", (0.0, 2.0)),
    ("roll_amplitude_deg", (0.0, 90.0), "deg", (0.0, 4.0)),
    ("heave_amplitude_m", (0.0, 100.0), "m", (0.0, 1.0)),
    ("pitch_period_s", (0.1, 3600.0), "s", (5.0, 12.0)),
    ("roll_period_s", (0.1, 3600.0), "s", (5.0, 12.0)),
    ("heave_period_s", (0.1, 3600.0), "s", (5.0, 12.0)),
)
# the sun of day images (daytime > 0), drawn after everything else: (name, allowed range, unit, default)
SUN_FIELDS: tuple[tuple[str, tuple[float, float], str, Any], ...] = (
    ("sun_elevation_deg", (0.0, 90.0), "deg", (2.0, 60.0)),
    ("sun_azimuth_deg", (-3600.0, 3600.0), "deg", (-180.0, 180.0)),
)
TIME_RANGE_S = (0.0, 86400.0)  # allowed range of the realizations' times [s]
DEFAULT_TIME_S = (0.0, 3600.0)  # default range of the realizations' times [s]
SCENE_FIELD_NAMES = tuple(f[0] for f in SCENE_FIELDS)  # the names alone, in the order of the draws
# the scene fields a render uses: all but air_sea_difference, which a draw holds as a record (T_air − T_sea)
# (also the fields drawn, one uniform each in this order: the difference takes the air's)
RENDER_FIELD_NAMES = tuple(n for n in SCENE_FIELD_NAMES if n != "air_sea_difference")
MOTION_FIELD_NAMES = tuple(f[0] for f in MOTION_FIELDS)
_MIX = 0x9E3779B97F4A7C15  # golden-ratio constant of splitmix64
_MASK = (1 << 64) - 1


def _splitmix64(x: int) -> int:
    x = (x + _MIX) & _MASK
    x = ((x ^ (x >> 30)) * 0xBF58476D1CE4E5B9) & _MASK
    x = ((x ^ (x >> 27)) * 0x94D049BB133111EB) & _MASK
    return x ^ (x >> 31)


def image_seed(seed: int, index: int) -> int:
    """A 63-bit seed for image ``index`` of a run seeded ``seed`` (splitmix64 of both): nearby
    seeds and indices give unrelated streams."""
    return _splitmix64(_splitmix64(int(seed) & _MASK) ^ (int(index) & _MASK)) >> 1


def frame_noise_seed(noise_seed: int, frame: int) -> int:
    """The sensor-noise seed of frame ``frame`` of a clip whose ``noise_seed`` is given: the
    clip's own for frame 0 (so a clip's first frame has the noise of a still image with those
    parameters), :func:`image_seed` (noise_seed, frame) after it (temporal noise differs from frame
    to frame; the fixed pattern, seeded by the sensor, does not)."""
    return int(noise_seed) if int(frame) == 0 else image_seed(int(noise_seed), int(frame))


def as_range(name: str, value: Any, allowed: tuple[float, float], unit: str) -> tuple[float, float]:
    """A range argument as a checked ``(low, high)`` pair of floats.

    Args:
        name: the argument's name, for the error messages.
        value: a number (held fixed: low = high) or a ``(low, high)`` pair.
        allowed: the interval [a, b] the range must lie in (a field's allowed range, e.g. of
            :data:`SCENE_FIELDS`).
        unit: the unit of ``value``, for the error messages.

    Raises ``ValueError`` naming ``name`` for anything else, a bound that is not finite, an
    inverted range (low > high) or one that leaves ``allowed``.
    """
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        lo = hi = float(value)
    else:
        try:
            lo, hi = (float(v) for v in value)
        except (TypeError, ValueError):
            raise ValueError(f"{name}: give a number or a (low, high) pair [{unit}]; got {value!r}") from None
    if not (math.isfinite(lo) and math.isfinite(hi)):
        raise ValueError(f"{name}: the range must be finite; got ({lo}, {hi})")
    if lo > hi:
        raise ValueError(f"{name}: the range ({lo:g}, {hi:g}) is inverted (low > high)")
    check_finite_range(name, torch.tensor([lo, hi], dtype=torch.float64), *allowed, unit=unit)
    return lo, hi


def _check_daytime(daytime: Any) -> float:
    """``daytime`` as a float in [0, 1], or ``ValueError`` naming it."""
    if isinstance(daytime, bool) or not isinstance(daytime, (int, float)) or not (0.0 <= float(daytime) <= 1.0):
        raise ValueError(f"daytime: the probability that an image is by day must be a number in [0, 1]; got {daytime!r}")
    return float(daytime)


def _uniform(r: tuple[float, float], u: torch.Tensor) -> torch.Tensor:
    """Uniform draws in [r0, r1) from u ∈ [0, 1) (a fixed value when r0 == r1)."""
    return r[0] + (r[1] - r[0]) * u if r[1] > r[0] else torch.full(u.shape, r[0], dtype=torch.float64)


class SceneSampler:
    """Uniform draws of scene and pose parameters, one set per image (or clip).

    Each range argument is a number (held fixed) or a ``(low, high)`` pair (drawn uniformly); the
    defaults are in :data:`SCENE_FIELDS` and :data:`MOTION_FIELDS`:

    Args:
        wind_speed: W [m s⁻¹], in [0, 80] (``slopes.MAX_WIND_SPEED``, the package's one range;
            Cox–Munk was fitted up to ~14 m s⁻¹).
        wind_direction_deg: upwind azimuth [deg] in the world frame.
        sea_temperature: T_sea [K], in [260, 320].
        air_temperature: T_air [K] of the surface air, in [230, 330], drawn independently of the
            sea; ``None`` (default): each atmosphere's own surface air temperature (see
            ``SeaScene``), unless ``air_sea_difference`` is given.
        air_sea_difference: ΔT = T_air − T_sea [K], in [−30, 30]: each image's air temperature is
            its drawn sea temperature plus a ΔT drawn uniformly from this range (independent of the
            sea). Over the open sea the surface air is within a few kelvin of the water, mostly a
            little colder: ``(-3.0, 1.0)`` covers the usual cases (large positive ΔT only in warm air
            advected over cold water, large negative ones in cold-air outbreaks). ``None``
            (default): not used, and the draws are those of a sampler without this argument, bit
            for bit (ΔT takes the uniform that ``air_temperature`` would, drawn either way).
            Giving both ``air_temperature`` and ``air_sea_difference`` is a ``ValueError``, and so is
            a ΔT range that takes ``sea_temperature`` outside the air's [230, 330] K.
        altitude_m: sensor height above the sea [m], in [2, 5000] with the atmospheric path on (the
            altitudes its tables cover), in [0.5, 20000] with ``path=False`` (a camera below the
            sea, or outside the path tables, is refused here, before any work).
        pitch_deg: elevation of the optical axis [deg], in [−90, 90]; negative looks down.
        roll_deg: [deg], in [−180, 180].
        yaw_deg: azimuth of the optical axis [deg] (with a random wind direction a fixed yaw
            loses nothing).
        hfov_deg: horizontal field of view [deg], in [0.5, 179].
        atmospheres: names of shipped LOWTRAN7 atmospheres, drawn with equal probability.
        path: whether the images will be rendered with the atmospheric path between sea and sensor
            (the renderer's default); it only sets the allowed ``altitude_m``.
        band: the sensor band of the path tables (``LWIR`` default, ``MWIR`` or (λ_lo, λ_hi) [m]).
        texture: also draw, per image, a wave seed (``"wave_seed"``, int64 in [0, 2⁶²)) and the
            time of the realization (``"time_s"`` [s], float64): the renderer then draws that
            textured sea (``SeaScene(seed=..., time_s=...)``). Default False (the expectation).
        time_s: range of those times [s], within [0, 86400]; default [0, 3600), so that
            successive draws of one seed would not show the same frame.
        motion: ``None`` (default: still images), or a dict of ranges of the platform's
            oscillations for clips (keys of :data:`MOTION_FIELDS`, missing keys take the
            defaults: pitch amplitude 0–2°, roll 0–4°, heave 0–1 m, periods 5–12 s); a phase
            ``"phase_rad"`` ∈ [0, 2π) is drawn with them. The mean pose ± amplitude must stay
            within the allowed pose (pitch in [−90, 90]°, roll in [−180, 180]°, altitude − heave
            above the sea, and within the path tables with the path on).
        daytime: probability in [0, 1] that an image (clip) is by day, with the sun in its sky
            (its direct irradiance from the image's atmosphere's LOWTRAN7 table in the band, its
            glint on the sea). Default 0.0: every image by night, no sun, and no new draws (the
            draws are those of a sampler without the sun's options, bit for bit).
        sun_elevation_deg: range of the sun's elevation above the horizon [deg], within [0, 90]
            (default 2–60°).
        sun_azimuth_deg: range of the sun's azimuth [deg] (default −180–180°): relative to the
            image's camera yaw with ``sun_azimuth_relative_to_yaw`` (default True: 0 puts the sun
            straight ahead of the camera, where its glint is), else a world azimuth (from +x
            towards +y, the yaw's frame).
        sun_azimuth_relative_to_yaw: see ``sun_azimuth_deg``.

    ``sample(B, generator)`` returns a dict of CPU float64 tensors (B,) under these names (the
    ``"air_sea_difference"`` of every image, T_air − T_sea [K], also without the argument: a record,
    the renderer uses ``"air_temperature"``) plus ``"atmosphere"`` (int64 index into ``atmospheres``) and ``"noise_seed"`` (int64, for the sensor
    model's random stages). Every field is drawn on every call, fixed or not, so fixing one range
    does not change the draws of the others. The draws are made in this order: the scene fields
    (one uniform each, ``air_sea_difference`` sharing ``air_temperature``'s), the atmosphere, the noise seed, then (``texture``) the wave seed and the time, then
    (``motion``) the oscillations and the phase, then (``daytime`` > 0) whether the image is by
    day and the sun's elevation and azimuth: turning texture, motion or daytime on does not change
    the draws before theirs. With ``daytime`` > 0 the draw also holds ``"is_day"`` (bool),
    ``"sun_elevation_deg"`` and ``"sun_azimuth_deg"`` (float64 [deg]; the azimuth is the sun's
    WORLD azimuth, the relative draw plus the yaw when relative); the sun's fields are drawn for
    every image and used only where ``is_day``.

    Example:
        >>> s = SceneSampler(wind_speed=(2.0, 4.0), pitch_deg=-3.0)
        >>> p = s.sample(3, generator=torch.Generator().manual_seed(0))
        >>> bool(((p["wind_speed"] >= 2) & (p["wind_speed"] <= 4)).all()), p["pitch_deg"].tolist()
        (True, [-3.0, -3.0, -3.0])
        >>> q = SceneSampler(wind_speed=(2.0, 4.0), pitch_deg=-3.0, texture=True).sample(
        ...     3, generator=torch.Generator().manual_seed(0))
        >>> torch.equal(q["wind_speed"], p["wind_speed"]), q["wave_seed"].dtype, q["time_s"].dtype
        (True, torch.int64, torch.float64)
        >>> a = SceneSampler(sea_temperature=(285.0, 302.0), air_sea_difference=(-3.0, 1.0)).sample(
        ...     1000, generator=torch.Generator().manual_seed(0))
        >>> d = a["air_temperature"] - a["sea_temperature"]  # T_air - T_sea [K]
        >>> bool((d >= -3.0 - 1e-9).all() and (d <= 1.0 + 1e-9).all())
        True
    """

    def __init__(self, *, atmospheres: Sequence[str] | str = ("midlatitude_summer",), path: bool = True,
                 band: Any = LWIR, texture: bool = False, time_s: Any = DEFAULT_TIME_S,
                 motion: dict[str, Any] | None = None, daytime: float = 0.0,
                 sun_elevation_deg: Any = SUN_FIELDS[0][3], sun_azimuth_deg: Any = SUN_FIELDS[1][3],
                 sun_azimuth_relative_to_yaw: bool = True, **ranges: Any):
        unknown = set(ranges) - set(SCENE_FIELD_NAMES)
        if unknown:
            known = [*SCENE_FIELD_NAMES, "atmospheres", "texture", "time_s", "motion", "daytime", "sun_elevation_deg",
                     "sun_azimuth_deg", "sun_azimuth_relative_to_yaw"]
            raise ValueError(f"unknown scene parameter(s) {sorted(unknown)}; known: {known}")
        self.daytime = _check_daytime(daytime)
        self.sun_ranges = {name: as_range(name, value, allowed, unit) for (name, allowed, unit, _d), value
                           in zip(SUN_FIELDS, (sun_elevation_deg, sun_azimuth_deg))}
        if not isinstance(sun_azimuth_relative_to_yaw, bool):
            raise ValueError(f"sun_azimuth_relative_to_yaw must be True or False; got {sun_azimuth_relative_to_yaw!r}")
        self.sun_azimuth_relative_to_yaw = sun_azimuth_relative_to_yaw
        if not isinstance(path, bool):
            raise ValueError(f"path must be True or False; got {path!r}")
        if not isinstance(texture, bool):
            raise ValueError(f"texture must be True or False; got {texture!r}")
        names = [atmospheres] if isinstance(atmospheres, str) else list(atmospheres)
        if not names:
            raise ValueError("atmospheres: give at least one atmosphere name")
        known = available_atmospheres()
        for n in names:
            if n not in known:
                raise ValueError(f"atmospheres: unknown atmosphere {n!r}; available: {known}")
        self.atmospheres: tuple[str, ...] = tuple(names)
        self.atmosphere_air_temperature = torch.tensor([surface_air_temperature(n) for n in names], dtype=torch.float64)
        self.ranges: dict[str, tuple[float, float] | None] = {}
        for name, allowed, unit, default in SCENE_FIELDS:
            value = ranges.get(name, default)
            self.ranges[name] = None if value is None else as_range(name, value, allowed, unit)
        self._check_air_sea_difference()
        pitch_lo, hfov_hi = self.ranges["pitch_deg"][0], self.ranges["hfov_deg"][1]
        if pitch_lo >= 0.5 * hfov_hi:
            warnings.warn(f"pitch_deg: every draw looks up by at least {pitch_lo:g}°, half the widest field of view or more "
                          f"(hfov_deg up to {hfov_hi:g}°): an image no taller than wide then holds no sea, only sky; "
                          "negative pitches look down at the sea", UserWarning, stacklevel=2)
        self.path = path
        self.texture = texture
        self.time_s = as_range("time_s", time_s, TIME_RANGE_S, "s")
        # the camera altitudes the renderer accepts: the path tables' with the path on
        self.altitude_limits = (0.0, math.inf)
        if path:  # the atmospheric path between sea and sensor is tabulated over a band of altitudes
            band = as_band(band)
            tables = [load_path(n, (band.lo, band.hi), band.response).altitude_range_m for n in names]
            lo, hi = max(t[0] for t in tables), min(t[1] for t in tables)
            self.altitude_limits = (lo, hi)
            a, b = self.ranges["altitude_m"]
            if a < lo or b > hi:
                raise ValueError(
                    f"altitude_m: the range ({a:g}, {b:g}) m leaves [{lo:g}, {hi:g}] m, the camera altitudes of "
                    f"the atmospheric path tables (path on); keep altitude_m within [{lo:g}, {hi:g}] m, or turn "
                    f"the path off (path=False) for the full [{SCENE_FIELDS[4][1][0]:g}, {SCENE_FIELDS[4][1][1]:g}] m"
                )
        self.motion: dict[str, tuple[float, float]] | None = None
        if motion is not None:
            self.motion = self._motion_ranges(motion)

    def _check_air_sea_difference(self) -> None:
        """``ValueError`` for ``air_temperature`` and ``air_sea_difference`` given together, or for a
        difference that takes the sea's range outside the air's allowed range."""
        diff = self.ranges["air_sea_difference"]
        if diff is None:
            return
        if self.ranges["air_temperature"] is not None:
            raise ValueError("air_temperature and air_sea_difference: give one of them, not both (air_temperature "
                             "draws T_air on its own, air_sea_difference draws T_air - T_sea and adds it to each "
                             f"image's sea temperature); got air_temperature={self.ranges['air_temperature']} K and "
                             f"air_sea_difference={diff} K")
        (s_lo, s_hi), (a_lo, a_hi) = self.ranges["sea_temperature"], SCENE_FIELDS[3][1]
        if s_lo + diff[0] < a_lo or s_hi + diff[1] > a_hi:
            raise ValueError(f"air_sea_difference: sea_temperature ({s_lo:g}, {s_hi:g}) K + air_sea_difference "
                             f"({diff[0]:g}, {diff[1]:g}) K gives air temperatures in [{s_lo + diff[0]:g}, "
                             f"{s_hi + diff[1]:g}] K, outside the allowed [{a_lo:g}, {a_hi:g}] K of air_temperature; "
                             "narrow one of them")

    def _motion_ranges(self, motion: Any) -> dict[str, tuple[float, float]]:
        if not isinstance(motion, dict):
            raise ValueError(f"motion must be None or a dict of ranges with keys {list(MOTION_FIELD_NAMES)}; got {motion!r}")
        unknown = set(motion) - set(MOTION_FIELD_NAMES)
        if unknown:
            raise ValueError(f"motion: unknown key(s) {sorted(unknown)}; known: {list(MOTION_FIELD_NAMES)}")
        out = {name: as_range(name, motion.get(name, default), allowed, unit) for name, allowed, unit, default in MOTION_FIELDS}
        for name, lim, amp in (("pitch_deg", 90.0, "pitch_amplitude_deg"), ("roll_deg", 180.0, "roll_amplitude_deg")):
            lo, hi = self.ranges[name]
            a = out[amp][1]
            if lo - a < -lim or hi + a > lim:
                raise ValueError(f"{amp}: {name} ({lo:g}, {hi:g}) ± {a:g} deg leaves [{-lim:g}, {lim:g}] deg; "
                                 f"lower the amplitude or narrow {name}")
        lo, hi = self.ranges["altitude_m"]
        h = out["heave_amplitude_m"][1]
        a_lo, a_hi = self.altitude_limits
        if lo - h <= 0.0 or lo - h < a_lo or hi + h > a_hi:
            where = f"[{a_lo:g}, {a_hi:g}] m (the path tables' camera altitudes)" if self.path else "(0, inf) m (above the sea)"
            raise ValueError(f"heave_amplitude_m: altitude_m ({lo:g}, {hi:g}) ± {h:g} m leaves {where}; lower the "
                             "heave amplitude or narrow altitude_m")
        return out

    def config(self) -> dict[str, Any]:
        """The ranges as plain Python values (for metadata and configs)."""
        out: dict[str, Any] = {k: (None if v is None else list(v)) for k, v in self.ranges.items()}
        out["atmospheres"] = list(self.atmospheres)
        out["texture"] = self.texture
        out["time_s"] = list(self.time_s)
        if self.motion is not None:
            out["motion"] = {k: list(v) for k, v in self.motion.items()}
        out["daytime"] = self.daytime
        out.update({k: list(v) for k, v in self.sun_ranges.items()})
        out["sun_azimuth_relative_to_yaw"] = self.sun_azimuth_relative_to_yaw
        return out

    def sample(self, batch_size: int, generator: torch.Generator | None = None, same_on_batch: bool = False) -> dict[str, torch.Tensor]:
        """One parameter set per image: dict of CPU tensors of shape (batch_size,)."""
        if not isinstance(batch_size, int) or batch_size < 0:
            raise ValueError(f"batch_size must be an int >= 0; got {batch_size!r}")
        if generator is not None and generator.device.type != "cpu":
            raise ValueError("generator must be a CPU torch.Generator (parameters are drawn on the CPU, then moved)")
        n = 1 if same_on_batch else batch_size
        u = torch.rand(len(RENDER_FIELD_NAMES), n, generator=generator, dtype=torch.float64)
        atm = torch.randint(len(self.atmospheres), (n,), generator=generator)
        seeds = torch.randint(0, 2**62, (n,), generator=generator)
        # T_air - T_sea, when given, from the uniform an air range would take (drawn either way)
        diff_range = self.ranges["air_sea_difference"]
        diff = None if diff_range is None else _uniform(diff_range, u[RENDER_FIELD_NAMES.index("air_temperature")])
        out: dict[str, torch.Tensor] = {}
        for i, name in enumerate(RENDER_FIELD_NAMES):
            r = self.ranges[name]
            if r is not None:
                out[name] = _uniform(r, u[i])
            elif diff is not None:  # (only air_temperature may be None) the air: the sea plus the difference
                out[name] = out["sea_temperature"] + diff
            else:  # air temperature of each image's atmosphere
                out[name] = self.atmosphere_air_temperature[atm]
        # the record of T_air - T_sea: the drawn difference, else what the air and sea drawn make
        out["air_sea_difference"] = diff if diff is not None else out["air_temperature"] - out["sea_temperature"]
        out["atmosphere"] = atm
        out["noise_seed"] = seeds
        if self.texture:  # after the draws above, so that they do not change with the texture
            out["wave_seed"] = torch.randint(0, 2**62, (n,), generator=generator)
            out["time_s"] = _uniform(self.time_s, torch.rand(n, generator=generator, dtype=torch.float64))
        if self.motion is not None:
            um = torch.rand(len(MOTION_FIELDS) + 1, n, generator=generator, dtype=torch.float64)
            for i, name in enumerate(MOTION_FIELD_NAMES):
                out[name] = _uniform(self.motion[name], um[i])
            out["phase_rad"] = (2.0 * math.pi) * um[-1]
        if self.daytime > 0.0:  # last: with daytime 0 nothing is drawn, and the draws above do not depend on it
            us = torch.rand(3, n, generator=generator, dtype=torch.float64)
            out["is_day"] = us[0] < self.daytime
            out["sun_elevation_deg"] = _uniform(self.sun_ranges["sun_elevation_deg"], us[1])
            az = _uniform(self.sun_ranges["sun_azimuth_deg"], us[2])
            out["sun_azimuth_deg"] = az + out["yaw_deg"] if self.sun_azimuth_relative_to_yaw else az
        if same_on_batch:
            out = {k: v.expand(batch_size).clone() for k, v in out.items()}
        return out

    def sample_indexed(self, seed: int, indices: Sequence[int] | torch.Tensor) -> dict[str, torch.Tensor]:
        """Parameters of images ``indices`` of a run seeded ``seed``: image i's draw comes from its
        own generator (seed :func:`image_seed` (seed, i)), so it is the same in any batch."""
        idx = [int(i) for i in (indices.tolist() if isinstance(indices, torch.Tensor) else indices)]
        if not idx:
            return self.sample(0)
        rows = [self.sample(1, torch.Generator().manual_seed(image_seed(seed, i))) for i in idx]
        return {k: torch.cat([r[k] for r in rows]) for k in rows[0]}


def frame_parameters(params: dict[str, torch.Tensor], num_frames: int, frame_rate: float) -> dict[str, torch.Tensor]:
    """The per-frame fields of clips: frame t of clip b is at clip time τ_t = t / ``frame_rate``.

    Args:
        params: a :class:`SceneSampler` draw (B,), with the motion fields for a moving camera
            (without them the camera holds its mean pose) and ``time_s`` for a textured sea.
        num_frames: T ≥ 1.
        frame_rate: [Hz], > 0.

    Returns:
        dict of CPU tensors (B, T): ``pitch_deg``, ``roll_deg``, ``altitude_m`` (float64, the pose
        of :meth:`PlatformMotion.pose <roughsea_torch.motion.PlatformMotion.pose>` at τ_t, with the
        clip's amplitudes, periods and phase), ``time_s`` (float64, the wave field's time
        time_s + τ_t; τ_t when the draw has no ``time_s``), ``noise_seed`` (int64,
        :func:`frame_noise_seed`). These are everything a frame needs beyond the clip's own
        fields: :func:`render_parameters` of a clip's fields with these in place of its pose and
        time renders that frame alone.
    """
    if not isinstance(num_frames, int) or isinstance(num_frames, bool) or num_frames < 1:
        raise ValueError(f"num_frames must be an int >= 1; got {num_frames!r}")
    check_finite_range("frame_rate", frame_rate, 0.0, lo_open=True, unit="Hz")
    B = int(params["wind_speed"].shape[0])
    tau = torch.arange(num_frames, dtype=torch.float64) / float(frame_rate)  # (T,)

    def col(name: str) -> torch.Tensor:
        return params[name].detach().cpu().to(torch.float64)[:, None]

    if all(name in params for name in MOTION_FIELD_NAMES) and "phase_rad" in params and B > 0:
        motion = PlatformMotion(
            altitude_m=col("altitude_m"), pitch_deg=col("pitch_deg"), roll_deg=col("roll_deg"),
            phase_rad=col("phase_rad"), **{name: col(name) for name in MOTION_FIELD_NAMES},
        )
        pose = {k: v.expand(B, num_frames).clone() for k, v in motion.pose(tau[None, :]).items()}
    else:
        pose = {k: col(k).expand(B, num_frames).clone() for k in ("pitch_deg", "roll_deg", "altitude_m")}
    base = col("time_s") if "time_s" in params else torch.zeros(B, 1, dtype=torch.float64)
    pose["time_s"] = base + tau[None, :]
    ns = params["noise_seed"].tolist()
    pose["noise_seed"] = torch.tensor([[frame_noise_seed(s, t) for t in range(num_frames)] for s in ns],
                                      dtype=torch.int64).reshape(B, num_frames)
    return pose



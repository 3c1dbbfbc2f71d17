"""Random sea backgrounds and clips for detector training, in ``kornia.augmentation``'s conventions.

- :class:`SceneSampler` draws scene and pose parameters (wind, sea and air temperature,
  atmosphere, altitude, pitch, roll, yaw, field of view; with ``texture`` a wave seed and a time;
  with ``motion`` a platform's pitch, roll and heave oscillations) uniformly from ranges the user
  gives; it is separate from the deterministic rendering (:func:`render_parameters`,
  :func:`render_clip_parameters`), as kornia separates parameter generation from the transform.
  Every draw comes from a CPU ``torch.Generator`` (or the global one), so the same seed gives the
  same parameters on every device; :meth:`SceneSampler.sample_indexed` gives each image index its
  own stream, so an image does not depend on which batch, worker or rank made it (what the dataset
  generator relies on).
- :class:`RandomSeaBackground` is a ``kornia.augmentation.IntensityAugmentationBase2D``: ``p``,
  ``same_on_batch``, ``keepdim``, ``aug._params`` for replay (``aug(x, params=aug._params)`` gives
  the same output bit for bit, wave texture and sensor noise included), masks/boxes/keypoints pass
  through inside ``kornia.augmentation.AugmentationSequential``. It replaces its input with a
  rendered sea, or composites the user's targets onto it (alpha compositing in radiance, so the
  contrast a target shows is the physical one), and optionally runs a sensor model
  (:mod:`roughsea_torch.sensor`). By default the sea is textured: one realization of the wave
  field per image (``SeaScene(seed=...)``), its clutter around the expectation image;
  ``texture=False`` renders the expectation image (the paper's mean, Eq. 10) as before.
- :class:`RandomSeaClip` makes clips in kornia's video layouts ((B, T, C, H, W) or (B, C, T, H,
  W), as ``kornia.augmentation.VideoSequential``): one sea realization per clip advanced in time
  frame by frame, seen from a camera on a :class:`~roughsea_torch.motion.PlatformMotion` whose
  amplitudes and periods are drawn per clip. Frame-wise 2-D augmentations go after it in a
  ``VideoSequential``.

Units: temperatures in K, angles in degrees (wind direction: world azimuth of the upwind axis,
from +x towards +y; the camera's yaw in the same frame), altitude and heave in m, wind speed in
m s⁻¹ at 12.5 m, times and periods in s, frame rate in Hz, radiance in W m⁻² sr⁻¹ in the scene's
band.

Calm seas: an image with ``wind_speed`` ≤ :data:`CALM_WIND_SPEED` has no resolved waves; it is
rendered as the expectation image even with texture on (its wave seed and time are drawn and
stored, and ignored).
"""

from __future__ import annotations

import copy
import math
import os
from typing import Any, Sequence

import torch
from kornia.augmentation import IntensityAugmentationBase2D

from ._parallel import map_chunks, one_thread
from ._validation import check_finite_range
from .atmosphere import available_atmospheres, load_path, surface_air_temperature
from .expectation import Quadrature
from .geometry import EARTH_RADIUS_M, make_camera
from .motion import PlatformMotion
from .radiometry import LWIR, as_band, band_radiance, brightness_temperature
from .render import SeaScene, TableSize, images_per_chunk, check_foam, render
from .sensor import SensorModel
from .waves import check_time

__all__ = [
    "SceneSampler",
    "RandomSeaBackground",
    "RandomSeaClip",
    "render_parameters",
    "render_clip_parameters",
    "frame_parameters",
    "frame_noise_seed",
    "SCENE_FIELDS",
    "MOTION_FIELDS",
    "CALM_WIND_SPEED",
    "SUN_FIELDS",
]

# (name, allowed range, unit, default range); the order is the order of the draws
SCENE_FIELDS: tuple[tuple[str, tuple[float, float], str, Any], ...] = (
    ("wind_speed", (0.0, 40.0), "m/s", (1.0, 15.0)),
    ("wind_direction_deg", (-3600.0, 3600.0), "deg", (0.0, 360.0)),
    ("sea_temperature", (260.0, 320.0), "K", (285.0, 300.0)),
    ("air_temperature", (230.0, 330.0), "K", None),
    ("altitude_m", (0.5, 20000.0), "m", (10.0, 100.0)),
    ("pitch_deg", (-90.0, 90.0), "deg", (-10.0, -1.0)),
    ("roll_deg", (-180.0, 180.0), "deg", (-2.0, 2.0)),
    ("yaw_deg", (-3600.0, 3600.0), "deg", 0.0),
    ("hfov_deg", (0.5, 179.0), "deg", (20.0, 40.0)),
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
DEFAULT_TIME_S = (0.0, 3600.0)
# at and below this wind speed [m/s] an image is rendered as the expectation even with texture on
CALM_WIND_SPEED = 0.0
_FIELD_NAMES = tuple(f[0] for f in SCENE_FIELDS)
_MOTION_NAMES = tuple(f[0] for f in MOTION_FIELDS)
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


def _range(name: str, value: Any, allowed: tuple[float, float], unit: str) -> tuple[float, float]:
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
        wind_speed: W [m s⁻¹], in [0, 40] (Cox–Munk was fitted up to ~14 m s⁻¹).
        wind_direction_deg: upwind azimuth [deg] in the world frame.
        sea_temperature: T_sea [K], in [260, 320].
        air_temperature: T_air [K] of the surface air, in [230, 330]; ``None`` (default): each
            atmosphere's own surface air temperature (see ``SeaScene``).
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

    ``sample(B, generator)`` returns a dict of CPU float64 tensors (B,) under these names plus
    ``"atmosphere"`` (int64 index into ``atmospheres``) and ``"noise_seed"`` (int64, for the sensor
    model's random stages). Every field is drawn on every call, fixed or not, so fixing one range
    does not change the draws of the others. The draws are made in this order: the scene fields,
    the atmosphere, the noise seed, then (``texture``) the wave seed and the time, then
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
    """

    def __init__(self, *, atmospheres: Sequence[str] | str = ("midlatitude_summer",), path: bool = True,
                 band: Any = LWIR, texture: bool = False, time_s: Any = DEFAULT_TIME_S,
                 motion: dict[str, Any] | None = None, daytime: float = 0.0,
                 sun_elevation_deg: Any = SUN_FIELDS[0][3], sun_azimuth_deg: Any = SUN_FIELDS[1][3],
                 sun_azimuth_relative_to_yaw: bool = True, **ranges: Any):
        unknown = set(ranges) - set(_FIELD_NAMES)
        if unknown:
            raise ValueError(f"unknown scene parameter(s) {sorted(unknown)}; known: "
                             f"{list(_FIELD_NAMES) + ['atmospheres', 'texture', 'time_s', 'motion', 'daytime', 'sun_elevation_deg', 'sun_azimuth_deg', 'sun_azimuth_relative_to_yaw']}")
        self.daytime = _check_daytime(daytime)
        self.sun_ranges = {name: _range(name, value, allowed, unit) for (name, allowed, unit, _d), value
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
            self.ranges[name] = None if value is None else _range(name, value, allowed, unit)
        self.path = path
        self.texture = texture
        self.time_s = _range("time_s", time_s, TIME_RANGE_S, "s")
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

    def _motion_ranges(self, motion: Any) -> dict[str, tuple[float, float]]:
        if not isinstance(motion, dict):
            raise ValueError(f"motion must be None or a dict of ranges with keys {list(_MOTION_NAMES)}; got {motion!r}")
        unknown = set(motion) - set(_MOTION_NAMES)
        if unknown:
            raise ValueError(f"motion: unknown key(s) {sorted(unknown)}; known: {list(_MOTION_NAMES)}")
        out = {name: _range(name, motion.get(name, default), allowed, unit) for name, allowed, unit, default in MOTION_FIELDS}
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
        u = torch.rand(len(SCENE_FIELDS), n, generator=generator, dtype=torch.float64)
        atm = torch.randint(len(self.atmospheres), (n,), generator=generator)
        seeds = torch.randint(0, 2**62, (n,), generator=generator)
        out: dict[str, torch.Tensor] = {}
        for i, (name, *_rest) in enumerate(SCENE_FIELDS):
            r = self.ranges[name]
            if r is None:  # air temperature of each image's atmosphere
                out[name] = self.atmosphere_air_temperature[atm]
            else:
                out[name] = _uniform(r, u[i])
        out["atmosphere"] = atm
        out["noise_seed"] = seeds
        if self.texture:  # after the draws above, so that they do not change with the texture
            out["wave_seed"] = torch.randint(0, 2**62, (n,), generator=generator)
            out["time_s"] = _uniform(self.time_s, torch.rand(n, generator=generator, dtype=torch.float64))
        if self.motion is not None:
            um = torch.rand(len(MOTION_FIELDS) + 1, n, generator=generator, dtype=torch.float64)
            for i, name in enumerate(_MOTION_NAMES):
                out[name] = _uniform(self.motion[name], um[i])
            out["phase_rad"] = (2.0 * math.pi) * um[-1]
        if self.daytime > 0.0:  # last: with daytime 0 nothing is drawn, and the draws above are as before
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

    if all(name in params for name in _MOTION_NAMES) and "phase_rad" in params and B > 0:
        motion = PlatformMotion(
            altitude_m=col("altitude_m"), pitch_deg=col("pitch_deg"), roll_deg=col("roll_deg"),
            phase_rad=col("phase_rad"), **{name: col(name) for name in _MOTION_NAMES},
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


def _render_frames(
    params: dict[str, torch.Tensor],
    frames: dict[str, torch.Tensor],
    height: int,
    width: int,
    atmospheres: Sequence[str],
    band: Any,
    anisotropic: bool,
    dtype: torch.dtype,
    device: Any,
    table: TableSize,
    quadrature: Quadrature | None,
    earth_radius_m: float,
    path: bool,
    foam: Any = "auto",
) -> torch.Tensor:
    """(B, T, 1, H, W): frame t of image b from the fields of ``params`` (B,), with pose and time
    from ``frames`` (B, T). Images are grouped by atmosphere and by textured or not; a group's
    scene is built once and its wave fields reused from frame to frame. Where every render is one
    chunk of the renderer (expectation images, at most ``render.DEFAULT_CHUNK`` of them, 4) and there
    are several, the renders themselves are spread over the worker threads
    (:func:`~roughsea_torch._parallel.map_chunks`; without it each would run alone on the calling
    thread); no gradient may flow then, and the images are the same either way (the workers take
    the caller's CPU autocast too)."""
    B, T = frames["time_s"].shape
    # None: torch's default device, resolved here (it is per thread, and the renders may run on workers)
    device = torch.get_default_device() if device is None else torch.device(device)
    out = torch.empty(B, T, 1, height, width, dtype=dtype, device=device)
    atm = params["atmosphere"].cpu()
    band = as_band(band)
    textured = torch.zeros(B, dtype=torch.bool)
    if "wave_seed" in params:  # a textured draw; calm images have no resolved waves: the expectation
        textured = params["wind_speed"].detach().cpu() > CALM_WIND_SPEED
    day = torch.zeros(B, dtype=torch.bool)
    if "is_day" in params:  # a draw with daytime > 0: the sun in the sky of the day images
        day = params["is_day"].detach().cpu().to(torch.bool)
    key = atm * 4 + textured.to(atm.dtype) * 2 + day.to(atm.dtype)
    jobs = []  # (images, frame, camera, scene, whether the render is one chunk)
    for k in torch.unique(key).tolist():
        a, tex, sunny = k // 4, bool((k // 2) % 2), bool(k % 2)
        idx = (key == k).nonzero()[:, 0]

        def f(name: str, src: dict[str, torch.Tensor] = params) -> torch.Tensor:
            return src[name][idx.to(src[name].device)].to(dtype=dtype, device=device)

        sun: dict[str, Any] = {}
        if sunny:  # zenith and world azimuth [rad], computed in float64 on the CPU, then cast
            def g(name: str) -> torch.Tensor:
                return params[name].detach().cpu().to(torch.float64)[idx]

            sun = dict(sun_zenith=((90.0 - g("sun_elevation_deg")) * (math.pi / 180.0)).to(dtype=dtype, device=device),
                       sun_azimuth=(g("sun_azimuth_deg") * (math.pi / 180.0)).to(dtype=dtype, device=device))
        # the scene and the cameras on one intra-op thread: their many small operations gain little from a
        # second idle core and stall beside a busy process (roughsea_torch._parallel); the renders themselves
        # are spread below
        scene = one_thread(lambda: SeaScene(
            wind_speed=f("wind_speed"), anisotropic=anisotropic, wind_direction=f("wind_direction_deg") * (math.pi / 180.0),
            sea_temperature=f("sea_temperature"), air_temperature=f("air_temperature"), band=band,
            sky=atmospheres[a], path=None if path else False,
            seed=[int(s) for s in params["wave_seed"][idx.to(params["wave_seed"].device)].tolist()] if tex else None,
            foam=foam, **sun,
        ), device)
        pose = {name: f(name, frames) for name in ("pitch_deg", "roll_deg", "altitude_m")}
        # the wave time stays float64 (TextureTable's phases ω t): float32 rounds 1e5 s to 1/128 s
        pose["time_s"] = frames["time_s"][idx.to(frames["time_s"].device)].to(dtype=torch.float64, device=device)
        cam = dict(hfov_deg=f("hfov_deg"), yaw_deg=f("yaw_deg"))
        for t in range(T):
            frame_scene = scene
            if tex:
                frame_scene = copy.copy(scene)  # shares the sky tables and the wave-field cache
                frame_scene.time_s = pose["time_s"][:, t]
            cam_t = dict(cam, altitude_m=pose["altitude_m"][:, t], pitch_deg=pose["pitch_deg"][:, t],
                         roll_deg=pose["roll_deg"][:, t])
            jobs.append((idx, t, cam_t, frame_scene, not tex and idx.numel() <= images_per_chunk(frame_scene)))

    def run(job: tuple) -> None:
        idx, t, cam_t, frame_scene, _ = job
        cams = one_thread(lambda: make_camera(height, width, **cam_t, dtype=dtype, device=device), device)
        out[idx.to(out.device), t] = render(cams, frame_scene, earth_radius_m=earth_radius_m, table=table,
                                            quadrature=quadrature)

    grad = torch.is_grad_enabled() and any(isinstance(v, torch.Tensor) and v.requires_grad
                                           for v in (*params.values(), *frames.values()))
    if len(jobs) > 1 and all(job[-1] for job in jobs) and not grad:
        map_chunks(run, jobs, device)
    else:
        for job in jobs:
            run(job)
    return out


def render_parameters(
    params: dict[str, torch.Tensor],
    height: int,
    width: int,
    atmospheres: Sequence[str],
    *,
    band: Any = LWIR,
    anisotropic: bool = True,
    dtype: torch.dtype = torch.float32,
    device: torch.device | str | None = None,
    table: TableSize = TableSize(),
    quadrature: Quadrature | None = None,
    earth_radius_m: float = EARTH_RADIUS_M,
    path: bool = True,
    foam: Any = "auto",
) -> torch.Tensor:
    """The deterministic half: render the radiance images (B, 1, H, W) [W m⁻² sr⁻¹] that a set of
    :class:`SceneSampler` parameters describes (images sharing an atmosphere are rendered
    together; the sky and, with ``path``, the air between sea and sensor come from that
    atmosphere at each image's air temperature).

    A draw with ``"wave_seed"`` (``SceneSampler(texture=True)``) renders each image's textured sea,
    the realization of its wave seed at its ``"time_s"`` [s] (images with ``wind_speed`` ≤
    :data:`CALM_WIND_SPEED`: the expectation); without it, the expectation image. A draw with
    ``"is_day"`` (``SceneSampler(daytime=...)`` > 0) puts the sun in the sky of the images where it
    is True: ``SeaScene(sun_zenith=(90° − sun_elevation_deg), sun_azimuth=sun_azimuth_deg)`` (world
    azimuth; radians), its direct irradiance from the image's atmosphere's LOWTRAN7 table; the
    other images are by night, as without it. Motion fields, if present, are not used: a still
    image is at the mean pose. ``foam``: the scenes' whitecaps (``SeaScene(foam=)``: ``"auto"``,
    ``False`` or a fraction in [0, 1])."""
    B = int(params["wind_speed"].shape[0])
    frames = {k: params[k].detach().cpu().to(torch.float64)[:, None] for k in ("pitch_deg", "roll_deg", "altitude_m")}
    frames["time_s"] = (params["time_s"].detach().cpu().to(torch.float64) if "time_s" in params
                        else torch.zeros(B, dtype=torch.float64))[:, None]
    return _render_frames(params, frames, height, width, atmospheres, band, anisotropic, dtype, device, table,
                          quadrature, earth_radius_m, path, check_foam(foam, per_image=False))[:, 0]


def render_clip_parameters(
    params: dict[str, torch.Tensor],
    num_frames: int,
    frame_rate: float,
    height: int,
    width: int,
    atmospheres: Sequence[str],
    *,
    band: Any = LWIR,
    anisotropic: bool = True,
    dtype: torch.dtype = torch.float32,
    device: torch.device | str | None = None,
    table: TableSize = TableSize(),
    quadrature: Quadrature | None = None,
    earth_radius_m: float = EARTH_RADIUS_M,
    path: bool = True,
    foam: Any = "auto",
) -> torch.Tensor:
    """Render clips (B, T, 1, H, W) [W m⁻² sr⁻¹], kornia's video layout: clip b's frame t is its
    sea at time ``time_s`` + t / ``frame_rate`` [s] seen from the pose of :func:`frame_parameters`
    (the platform's oscillations at t / ``frame_rate``). Frame t equals :func:`render_parameters`
    of the clip's fields with that frame's pose and time (up to how images are batched); ``foam`` as
    there."""
    frames = frame_parameters(params, num_frames, frame_rate)
    return _render_frames(params, frames, height, width, atmospheres, band, anisotropic, dtype, device, table,
                          quadrature, earth_radius_m, path, check_foam(foam, per_image=False))


def _worker_stream(generator: torch.Generator, worker_id: int) -> torch.Generator:
    """A DataLoader worker's own generator: seeded by :func:`image_seed` of a number drawn from
    a copy of ``generator`` (its state as the worker received it; the original is not advanced)
    and the worker's id. Each worker gets a different stream, and the same one on every run that
    seeds ``generator`` the same way."""
    copy = torch.Generator().set_state(generator.get_state())
    base = int(torch.randint(0, 2**62, (1,), generator=copy))
    return torch.Generator().manual_seed(image_seed(base, worker_id))


def _check_input(input: Any, mode: str) -> None:
    """``ValueError`` for an input dtype that cannot carry the result, or (composite mode) an
    opacity outside [0, 1]."""
    if not isinstance(input, torch.Tensor):
        raise ValueError(f"input must be a torch.Tensor; got {type(input).__name__}")
    if input.dtype not in (torch.float32, torch.float64):
        raise ValueError(
            f"input: dtype must be torch.float32 or torch.float64; got {input.dtype}. The output has the "
            "input's dtype, and half precision cannot hold it to the sensor's resolution (float16 steps are "
            "0.25 K near 290 K, rounding by up to 0.125 K against a 0.05 K NETD, and integers above 2048, "
            "as 14-bit counts, are not exact): pass float32 and cast the output if you need it smaller"
        )
    if mode == "composite" and input.shape[-3] == 2 and input.numel():
        alpha = input.detach()[..., 1, :, :]
        lo, hi = (float(v) for v in torch.aminmax(alpha))
        if not (0.0 <= lo and hi <= 1.0):  # NaN fails too
            raise ValueError(f"alpha (input channel 1, the target's opacity) must lie in [0, 1]; got values in "
                             f"[{lo:g}, {hi:g}]")


# the per-image fields a draw may hold, each a tensor (B,); the first ones are always there
_REQUIRED_PARAMS = (*_FIELD_NAMES, "atmosphere", "noise_seed")
_PER_IMAGE_PARAMS = (*_REQUIRED_PARAMS, "wave_seed", "time_s", *_MOTION_NAMES, "phase_rad", "is_day",
                     "sun_elevation_deg", "sun_azimuth_deg")


def _check_params(params: Any, B: int, atmospheres: Sequence[str], gate_sizes: tuple[int, ...]) -> None:
    """``ValueError`` naming the field of a draw (``params``, e.g. one replayed from ``_params``) that
    does not fit an input of B images (clips): every per-image field a tensor of shape (B,), the gate
    ``"batch_prob"`` of a size in ``gate_sizes``, ``atmosphere`` an integer index into
    ``atmospheres``, ``noise_seed`` and ``wave_seed`` integers (wave seeds in [0, 2**63)), ``time_s``
    finite times in [−1e9, 1e9] s (``SeaScene``'s)."""
    if not isinstance(params, dict):
        raise ValueError(f"params must be a dict of tensors (a draw, e.g. aug._params); got {type(params).__name__}")
    missing = [k for k in _REQUIRED_PARAMS if k not in params]
    if missing:
        raise ValueError(f"params: missing {missing}; replay a draw of this augmentation (its _params)")
    for k in _PER_IMAGE_PARAMS:
        v = params.get(k)
        if v is None:
            continue
        if not isinstance(v, torch.Tensor) or v.ndim != 1:
            shape = tuple(v.shape) if isinstance(v, torch.Tensor) else type(v).__name__
            raise ValueError(f"params[{k!r}]: must be a tensor of shape (B,) = ({B},), one value per image; got {shape}")
        if v.shape[0] != B:
            raise ValueError(f"params[{k!r}]: has {v.shape[0]} values but the input has B = {B} images; replay a "
                             f"draw on an input of the batch size it was drawn for")
    gate = params.get("batch_prob")
    if gate is not None and (not isinstance(gate, torch.Tensor) or gate.numel() not in gate_sizes):
        size = gate.numel() if isinstance(gate, torch.Tensor) else type(gate).__name__
        raise ValueError(f"params['batch_prob']: must hold {' or '.join(map(str, sorted(set(gate_sizes))))} values "
                         f"for an input of B = {B} images; got {size}")
    for k in ("atmosphere", "noise_seed", "wave_seed"):
        v = params.get(k)
        if v is not None and (v.dtype.is_floating_point or v.dtype.is_complex or v.dtype == torch.bool):
            raise ValueError(f"params[{k!r}]: must have an integer dtype (int64, as drawn); got {v.dtype}")
    atm = params["atmosphere"]
    if atm.numel() and not bool(((atm >= 0) & (atm < len(atmospheres))).all()):
        raise ValueError(f"params['atmosphere']: indices must lie in [0, {len(atmospheres) - 1}] (into atmospheres="
                         f"{list(atmospheres)}); got {atm.tolist()}")
    for k in ("noise_seed", "wave_seed"):
        if k in params and bool((params[k] < 0).any()):
            raise ValueError(f"params[{k!r}]: seeds must lie in [0, 2**63); got {params[k].tolist()}")
    if "is_day" in params:  # a day draw: the sun of each day image
        missing = [k for k in ("sun_elevation_deg", "sun_azimuth_deg") if k not in params]
        if missing:
            raise ValueError(f"params: a draw with 'is_day' needs {missing} too (the sun of its day images)")
    motion = [k for k in (*_MOTION_NAMES, "phase_rad") if k in params]
    if motion and len(motion) < len(_MOTION_NAMES) + 1:  # all of the platform's motion, or none (a still pose)
        missing = [k for k in (*_MOTION_NAMES, "phase_rad") if k not in params]
        raise ValueError(f"params: a draw with platform motion needs all of its fields; missing {missing}")
    if "time_s" in params:
        check_time("params['time_s']", params["time_s"])


def _check_output_settings(mode: str, target_unit: str, sensor: Any, output: str | None,
                           generator: torch.Generator | None) -> str:
    """The output kind of these settings, or ``ValueError`` naming the bad one."""
    if mode not in ("replace", "composite"):
        raise ValueError(f"mode must be 'replace' or 'composite'; got {mode!r}")
    if target_unit not in ("temperature", "radiance"):
        raise ValueError(f"target_unit must be 'temperature' or 'radiance'; got {target_unit!r}")
    if output is None:
        output = "sensor" if sensor is not None else "radiance"
    if output not in ("radiance", "brightness_temperature", "sensor"):
        raise ValueError(f"output must be 'radiance', 'brightness_temperature' or 'sensor'; got {output!r}")
    if (output == "sensor") != (sensor is not None):
        raise ValueError("output='sensor' needs a sensor model, and a sensor model needs output='sensor'")
    if generator is not None and generator.device.type != "cpu":
        raise ValueError("generator must be a CPU torch.Generator")
    return output


class _Seas:
    """What RandomSeaBackground and RandomSeaClip share: the generator of a draw, and the stages
    after the renderer (compositing, sensor, output unit)."""

    generator: torch.Generator | None
    _call_generator: torch.Generator | None
    _worker: tuple[tuple[int, int], torch.Generator] | None

    def _generator(self) -> torch.Generator | None:
        """The generator of this draw: the one given to ``forward``, else the instance's; inside a
        DataLoader worker the instance's is replaced, on first use, by the worker's own stream
        (see :func:`_worker_stream`)."""
        if self._call_generator is not None:
            return self._call_generator
        if self.generator is None:
            return None
        info = torch.utils.data.get_worker_info()
        if info is None:
            return self.generator
        key = (os.getpid(), int(info.id))
        if self._worker is None or self._worker[0] != key:
            self._worker = (key, _worker_stream(self.generator, int(info.id)))
        return self._worker[1]

    def _finish(self, L: torch.Tensor, inp: torch.Tensor, noise_seeds: Sequence[int]) -> torch.Tensor:
        """Rendered radiance L (N, 1, H, W) → channel 0 of the output (N, 1, H, W): composited with
        the input's targets (composite mode), through the sensor (image i's noise from
        ``noise_seeds[i]``), in the output's unit."""
        dtype = L.dtype
        if self.mode == "composite":
            target = inp[:, :1].to(dtype)
            alpha = inp[:, 1:2].to(dtype)  # in [0, 1]: forward checked it
            covered = alpha > 0
            if self.target_unit == "temperature":  # Planck only where a target shows (a band sum per pixel)
                target = torch.zeros_like(L).index_put((covered,), band_radiance(target[covered], self.band))
            L = torch.where(covered, torch.lerp(L, target, alpha), L)
        if self.output == "sensor":
            gens = [torch.Generator().manual_seed(int(s)) for s in noise_seeds]
            if isinstance(self.sensor, SensorModel):  # one batched call, each image's noise from its own seed
                L = self.sensor(L, generator=gens)
            else:  # any module sensor(radiance, generator=g): image by image
                L = torch.cat([self.sensor(L[i : i + 1], generator=g) for i, g in enumerate(gens)])
        elif self.output == "brightness_temperature":
            L = brightness_temperature(L.clamp_min(torch.finfo(dtype).tiny), self.band)
        return L


class RandomSeaBackground(_Seas, IntensityAugmentationBase2D):
    """Replace images with random, physically rendered infrared sea backgrounds, or composite
    targets onto them.

    Args:
        wind_speed, wind_direction_deg, sea_temperature, air_temperature, altitude_m, pitch_deg,
            roll_deg, yaw_deg, hfov_deg, atmospheres: ranges of the scene, see :class:`SceneSampler`.
        texture: ``True`` (default): a textured sea, one realization of the wave field per image
            (``SeaScene(seed=...)``: waves longer than a pixel's footprint are geometry, the clutter
            a real camera sees at near range, around the expectation image); the wave seed
            (``params["wave_seed"]``, int64) and the time (``params["time_s"]`` [s], float64) are
            drawn after the other parameters and kept for replay. Images with ``wind_speed`` ≤
            :data:`CALM_WIND_SPEED` (a calm sea, no resolved waves) are the expectation image.
            ``False``: the expectation image (the mean over the slope statistics, Eq. 10), with
            the same parameter draws as before texture existed; also for a replayed draw that
            holds wave seeds (e.g. one of a textured augmentation's ``_params``): the setting wins.
        time_s: range of the realizations' times [s] (default [0, 3600)); see :class:`SceneSampler`.
        daytime: probability in [0, 1] that an image is by day (default 0.0: all by night, and the
            draws as before this option). A day image has the sun in its sky at an elevation drawn
            from ``sun_elevation_deg`` (default 2–60°) and an azimuth from ``sun_azimuth_deg``
            (default −180–180°; relative to the camera's yaw with ``sun_azimuth_relative_to_yaw``,
            the default, so 0 is straight ahead, where the glint is; else world): the glint of
            its LOWTRAN7 direct irradiance (in MWIR far brighter than the sea's emission) on the
            sea, textured seas included. ``params["is_day"]``, ``params["sun_elevation_deg"]`` and
            ``params["sun_azimuth_deg"]`` (world) keep the draw for replay; see :class:`SceneSampler`.
        band: sensor band (``LWIR`` default, ``MWIR`` or (λ_lo, λ_hi) [m]).
        anisotropic: Cox–Munk anisotropic (default) or isotropic slopes.
        mode: ``"replace"``: the output is the rendered sea, repeated over the input's channels
            (the input's values are not used, only its shape, dtype and device); ``"composite"``:
            the input has two channels, a target's value (channel 0, in ``target_unit``) and its
            opacity α ∈ [0, 1] (channel 1; a value outside [0, 1] is a ``ValueError``, not clamped);
            channel 0 of the output is α L_target + (1 − α) L_sea in radiance (then the sensor
            model), channel 1 is α unchanged.
        target_unit: ``"temperature"`` (blackbody temperature [K] of the target as seen at the
            sensor) or ``"radiance"`` [W m⁻² sr⁻¹].
        sensor: a sensor model (``roughsea_torch.sensor.SensorModel`` or any module
            ``sensor(radiance, generator=g)``) applied after compositing; its random stages draw
            from a generator seeded by each image's ``noise_seed``, so replays repeat the noise. A
            :class:`~roughsea_torch.sensor.SensorModel` runs once on the batch (its noise drawn
            per image from those generators); another module is called image by image.
        output: ``"radiance"``, ``"brightness_temperature"`` [K], or ``"sensor"`` (the sensor
            model's output, e.g. counts; the default when a sensor is given).
        table, quadrature, path: renderer settings (see :func:`~roughsea_torch.render.render`).
        foam: the whitecaps, as ``SeaScene(foam=)``: ``"auto"`` (default: Monahan's fraction at
            each image's wind, on the crests of a textured sea), ``False`` (none: a sea without
            whitecaps, e.g. where the model's dark whitecaps near grazing are not wanted;
            README, *Foam*) or a fraction in [0, 1]. A setting of the augmentation, not drawn.
        generator: a CPU ``torch.Generator`` used for every draw of this instance when ``forward``
            gets none; ``forward(x, generator=g)`` seeds one call. Inside a
            ``torch.utils.data.DataLoader`` worker, each worker replaces it on first use by its own
            stream, seeded from the generator's state as the worker received it and the worker's
            id: workers draw different scenes (and wave seeds), and the same ones on every run
            seeded the same way. Workers that are not persistent restart from that state every
            epoch (and so repeat their scenes); use ``persistent_workers=True`` for new scenes
            each epoch.
        p, same_on_batch, keepdim: kornia's (images not selected by ``p`` come back unchanged and
            are not rendered; ``same_on_batch`` repeats the wave seed and time too).

    Shapes: input (B, C, H, W) or (C, H, W), float32 or float64; output the same shape and dtype.
    Other dtypes are a ``ValueError`` naming ``input``: the output has the input's dtype, and
    float16 (0.25 K steps near 290 K, so rounding errors up to 0.125 K against a 0.05 K NETD;
    integers exact only up to 2048, below 14-bit counts) or bfloat16 cannot hold it to the sensor's
    resolution. Cast to float32, and the output back if needed.

    Cost: the texture adds the wave field's synthesis per image and its evaluation at near range
    (pixels whose footprint resolves waves; the far field is the expectation, at no extra cost):
    several times the expectation image's render. ``texture=False`` when the clutter is not wanted.

    Example:
        >>> aug = RandomSeaBackground(wind_speed=(2.0, 12.0), output="brightness_temperature")
        >>> x = torch.zeros(2, 1, 24, 32)
        >>> y = aug(x, generator=torch.Generator().manual_seed(0))
        >>> y.shape, bool((y > 200).all()), torch.equal(aug(x, params=aug._params), y)
        (torch.Size([2, 1, 24, 32]), True, True)
        >>> sorted(k for k in aug._params if k in ("wave_seed", "time_s"))
        ['time_s', 'wave_seed']
    """

    def __init__(
        self,
        *,
        wind_speed: Any = SCENE_FIELDS[0][3],
        wind_direction_deg: Any = SCENE_FIELDS[1][3],
        sea_temperature: Any = SCENE_FIELDS[2][3],
        air_temperature: Any = SCENE_FIELDS[3][3],
        altitude_m: Any = SCENE_FIELDS[4][3],
        pitch_deg: Any = SCENE_FIELDS[5][3],
        roll_deg: Any = SCENE_FIELDS[6][3],
        yaw_deg: Any = SCENE_FIELDS[7][3],
        hfov_deg: Any = SCENE_FIELDS[8][3],
        atmospheres: Sequence[str] | str = ("midlatitude_summer",),
        texture: bool = True,
        time_s: Any = DEFAULT_TIME_S,
        daytime: float = 0.0,
        sun_elevation_deg: Any = SUN_FIELDS[0][3],
        sun_azimuth_deg: Any = SUN_FIELDS[1][3],
        sun_azimuth_relative_to_yaw: bool = True,
        band: Any = LWIR,
        anisotropic: bool = True,
        mode: str = "replace",
        target_unit: str = "temperature",
        sensor: torch.nn.Module | None = None,
        output: str | None = None,
        table: TableSize = TableSize(),
        quadrature: Quadrature | None = None,
        path: bool = True,
        foam: Any = "auto",
        generator: torch.Generator | None = None,
        p: float = 1.0,
        same_on_batch: bool = False,
        keepdim: bool = False,
    ) -> None:
        super().__init__(p=p, same_on_batch=same_on_batch, keepdim=keepdim)
        self.sampler = SceneSampler(
            atmospheres=atmospheres, wind_speed=wind_speed, wind_direction_deg=wind_direction_deg,
            sea_temperature=sea_temperature, air_temperature=air_temperature, altitude_m=altitude_m,
            pitch_deg=pitch_deg, roll_deg=roll_deg, yaw_deg=yaw_deg, hfov_deg=hfov_deg, path=path, band=band,
            texture=texture, time_s=time_s, daytime=daytime, sun_elevation_deg=sun_elevation_deg,
            sun_azimuth_deg=sun_azimuth_deg, sun_azimuth_relative_to_yaw=sun_azimuth_relative_to_yaw,
        )
        self.output = _check_output_settings(mode, target_unit, sensor, output, generator)
        self.texture = texture
        self.band = as_band(band)
        self.anisotropic = anisotropic
        self.mode = mode
        self.target_unit = target_unit
        self.sensor = sensor
        self.table = table
        self.quadrature = quadrature
        self.path = path
        self.foam = check_foam(foam, per_image=False)
        self.generator = generator
        self._call_generator: torch.Generator | None = None
        self._worker: tuple[tuple[int, int], torch.Generator] | None = None

    def forward(self, input: torch.Tensor, params: dict[str, torch.Tensor] | None = None,
                generator: torch.Generator | None = None, **kwargs: Any) -> torch.Tensor:
        if generator is not None and generator.device.type != "cpu":
            raise ValueError("generator must be a CPU torch.Generator")
        _check_input(input, self.mode)
        self._call_generator = generator
        try:
            return super().forward(input, params=params, **kwargs)
        finally:
            self._call_generator = None

    def __batch_prob_generator__(self, batch_shape: tuple[int, ...], p: float, p_batch: float, same_on_batch: bool) -> torch.Tensor:
        g = self._generator()
        if g is None or p in (0.0, 1.0) and p_batch == 1.0:
            return super().__batch_prob_generator__(batch_shape, p, p_batch, same_on_batch)
        n = 1 if same_on_batch else batch_shape[0]
        keep = (torch.rand(n, generator=g) < p).expand(batch_shape[0])
        if p_batch < 1.0:
            keep = keep & (torch.rand(1, generator=g) < p_batch)
        return keep.to(device=self.device or torch.device("cpu"), dtype=self.dtype or torch.float32)

    def generate_parameters(self, batch_shape: tuple[int, ...]) -> dict[str, torch.Tensor]:
        return self.sampler.sample(int(batch_shape[0]), generator=self._generator(), same_on_batch=self.same_on_batch)

    def apply_transform(self, input: torch.Tensor, params: dict[str, torch.Tensor], flags: dict[str, Any],
                        transform: torch.Tensor | None = None) -> torch.Tensor:
        B, C, H, W = input.shape
        if self.mode == "composite" and C != 2:
            raise ValueError(f"input: mode='composite' needs 2 channels (target value, alpha); got {C}")
        _check_params(params, B, self.sampler.atmospheres, (1, B))  # a replayed draw too
        dtype = input.dtype  # float32 or float64 (forward refuses others)
        gate = params["batch_prob"].reshape(-1).cpu() > 0.5 if "batch_prob" in params else torch.ones(B, dtype=torch.bool)
        if gate.numel() == 1:
            gate = gate.expand(B)
        idx = gate.nonzero()[:, 0]
        out = input.clone()
        if idx.numel() == 0:
            return out
        sub = {k: v[idx.to(v.device)] for k, v in params.items() if isinstance(v, torch.Tensor) and v.ndim == 1 and v.shape[0] == B
               and (self.texture or k != "wave_seed")}  # texture=False: the expectation, whatever the draw holds
        L = render_parameters(
            sub, H, W, self.sampler.atmospheres, band=self.band, anisotropic=self.anisotropic, dtype=dtype,
            device=input.device, table=self.table, quadrature=self.quadrature, path=self.path, foam=self.foam,
        )
        # compositing and the sensor on one intra-op thread (as the scenes above)
        L = one_thread(lambda: self._finish(L, input[idx], sub["noise_seed"].tolist()), input.device).to(input.dtype)
        if self.mode == "composite":
            out[idx, :1] = L
        else:
            out[idx] = L.expand(-1, C, -1, -1)
        return out


_LAYOUTS = ("BTCHW", "BCTHW")


class RandomSeaClip(_Seas, torch.nn.Module):
    """Replace clips with random infrared sea clips (or composite per-frame targets onto them), in
    kornia's video layouts.

    Each clip is one sea realization (a wave seed drawn per clip, ``SeaScene(seed=...)``) at
    successive times: frame t at ``time_s`` + t / ``frame_rate`` [s], the waves moving by their
    dispersion relation; seen by a camera on a :class:`~roughsea_torch.motion.PlatformMotion`
    (mean pose drawn as for :class:`RandomSeaBackground`, then pitch, roll and heave oscillations
    with amplitudes and periods drawn per clip and a phase φ ∈ [0, 2π)), so the horizon moves.

    Args:
        frame_rate: [Hz], > 0 (default 25). The clip length is the input's T.
        data_format: ``"BTCHW"`` (default, ``VideoSequential``'s default) or ``"BCTHW"``
            (case-insensitive); the output keeps the input's layout.
        pitch_amplitude_deg, roll_amplitude_deg: ranges of the oscillation amplitudes [deg]
            (default 0–2°, 0–4°).
        heave_amplitude_m: range of the heave amplitude [m] (default 0–1 m); the camera must stay
            above the sea (and within the path tables' 2 m – 5 km with the path on).
        pitch_period_s, roll_period_s, heave_period_s: ranges of the periods [s] (default 5–12 s,
            a ship's response to a swell).
        texture: ``True`` (default): a textured, moving sea; ``False``: every frame is the
            expectation image of its pose (only the camera moves), also for a replayed draw that
            holds wave seeds. Clips with ``wind_speed`` ≤ :data:`CALM_WIND_SPEED` are expectation
            images too.
        time_s: range of the clips' start times [s] (default [0, 3600)).
        daytime, sun_elevation_deg, sun_azimuth_deg, sun_azimuth_relative_to_yaw: day clips, as
            :class:`RandomSeaBackground` (drawn per clip; the sun stays put over a clip, its
            relative azimuth from the clip's mean yaw).
        wind_speed, ..., hfov_deg, atmospheres, band, anisotropic, mode, target_unit, sensor,
            output, table, quadrature, path, foam, generator: as :class:`RandomSeaBackground`. In
            composite mode every frame holds its own target and opacity (C = 2). With a sensor,
            frame t's temporal noise comes from :func:`frame_noise_seed` (noise_seed, t); the fixed
            pattern is the same on every frame.
        p: probability that a clip is replaced (clips not selected come back unchanged and are not
            rendered).
        same_on_batch: every clip of the batch the same (scene, seed, time and motion).

    Shapes: input (B, T, C, H, W) (or (B, C, T, H, W) with ``data_format="BCTHW"``), float32 or
    float64; output the same shape and dtype. ``forward(x, params=None, generator=None)``; the
    draw is kept in ``self._params`` (per clip, (B,)) and ``forward(x, params=self._params)``
    replays it bit for bit; :func:`frame_parameters` gives each frame's pose, time and noise seed.

    It is not a kornia 2-D augmentation (``VideoSequential`` would apply it frame by frame with the
    same parameters, a still sea); run it before frame-wise augmentations::

        clip = RandomSeaClip(frame_rate=25.0)(torch.zeros(B, T, 1, H, W))
        clip = kornia.augmentation.VideoSequential(K.RandomHorizontalFlip(), data_format="BTCHW")(clip)

    Example:
        >>> aug = RandomSeaClip(frame_rate=10.0, output="brightness_temperature")
        >>> x = torch.zeros(1, 3, 1, 24, 32)
        >>> y = aug(x, generator=torch.Generator().manual_seed(0))
        >>> y.shape, torch.equal(aug(x, params=aug._params), y), bool((y[:, 0] != y[:, 1]).any())
        (torch.Size([1, 3, 1, 24, 32]), True, True)
    """

    def __init__(
        self,
        *,
        frame_rate: float = 25.0,
        data_format: str = "BTCHW",
        pitch_amplitude_deg: Any = MOTION_FIELDS[0][3],
        roll_amplitude_deg: Any = MOTION_FIELDS[1][3],
        heave_amplitude_m: Any = MOTION_FIELDS[2][3],
        pitch_period_s: Any = MOTION_FIELDS[3][3],
        roll_period_s: Any = MOTION_FIELDS[4][3],
        heave_period_s: Any = MOTION_FIELDS[5][3],
        wind_speed: Any = SCENE_FIELDS[0][3],
        wind_direction_deg: Any = SCENE_FIELDS[1][3],
        sea_temperature: Any = SCENE_FIELDS[2][3],
        air_temperature: Any = SCENE_FIELDS[3][3],
        altitude_m: Any = SCENE_FIELDS[4][3],
        pitch_deg: Any = SCENE_FIELDS[5][3],
        roll_deg: Any = SCENE_FIELDS[6][3],
        yaw_deg: Any = SCENE_FIELDS[7][3],
        hfov_deg: Any = SCENE_FIELDS[8][3],
        atmospheres: Sequence[str] | str = ("midlatitude_summer",),
        texture: bool = True,
        time_s: Any = DEFAULT_TIME_S,
        daytime: float = 0.0,
        sun_elevation_deg: Any = SUN_FIELDS[0][3],
        sun_azimuth_deg: Any = SUN_FIELDS[1][3],
        sun_azimuth_relative_to_yaw: bool = True,
        band: Any = LWIR,
        anisotropic: bool = True,
        mode: str = "replace",
        target_unit: str = "temperature",
        sensor: torch.nn.Module | None = None,
        output: str | None = None,
        table: TableSize = TableSize(),
        quadrature: Quadrature | None = None,
        path: bool = True,
        foam: Any = "auto",
        generator: torch.Generator | None = None,
        p: float = 1.0,
        same_on_batch: bool = False,
    ) -> None:
        super().__init__()
        check_finite_range("frame_rate", frame_rate, 0.0, lo_open=True, unit="Hz")
        fmt = data_format.upper() if isinstance(data_format, str) else data_format
        if fmt not in _LAYOUTS:
            raise ValueError(f"data_format must be 'BTCHW' or 'BCTHW' (kornia's video layouts); got {data_format!r}")
        check_finite_range("p", p, 0.0, 1.0)
        if not isinstance(same_on_batch, bool):
            raise ValueError(f"same_on_batch must be True or False; got {same_on_batch!r}")
        motion = dict(pitch_amplitude_deg=pitch_amplitude_deg, roll_amplitude_deg=roll_amplitude_deg,
                      heave_amplitude_m=heave_amplitude_m, pitch_period_s=pitch_period_s, roll_period_s=roll_period_s,
                      heave_period_s=heave_period_s)
        self.sampler = SceneSampler(
            atmospheres=atmospheres, wind_speed=wind_speed, wind_direction_deg=wind_direction_deg,
            sea_temperature=sea_temperature, air_temperature=air_temperature, altitude_m=altitude_m,
            pitch_deg=pitch_deg, roll_deg=roll_deg, yaw_deg=yaw_deg, hfov_deg=hfov_deg, path=path, band=band,
            texture=texture, time_s=time_s, motion=motion, daytime=daytime, sun_elevation_deg=sun_elevation_deg,
            sun_azimuth_deg=sun_azimuth_deg, sun_azimuth_relative_to_yaw=sun_azimuth_relative_to_yaw,
        )
        self.output = _check_output_settings(mode, target_unit, sensor, output, generator)
        self.frame_rate = float(frame_rate)
        self.data_format = fmt
        self.texture = texture
        self.band = as_band(band)
        self.anisotropic = anisotropic
        self.mode = mode
        self.target_unit = target_unit
        self.sensor = sensor
        self.table = table
        self.quadrature = quadrature
        self.path = path
        self.foam = check_foam(foam, per_image=False)
        self.generator = generator
        self.p = float(p)
        self.same_on_batch = same_on_batch
        self._params: dict[str, torch.Tensor] | None = None
        self._call_generator: torch.Generator | None = None
        self._worker: tuple[tuple[int, int], torch.Generator] | None = None

    def generate_parameters(self, batch_size: int) -> dict[str, torch.Tensor]:
        """One draw per clip: the gate (``"batch_prob"``, 1.0 for clips to replace; drawn only when
        0 < p < 1), then :meth:`SceneSampler.sample` with texture and motion."""
        g = self._generator()
        n = 1 if self.same_on_batch else batch_size
        if 0.0 < self.p < 1.0:
            keep = torch.rand(n, generator=g) < self.p
        else:
            keep = torch.full((n,), self.p == 1.0)
        params = self.sampler.sample(batch_size, generator=g, same_on_batch=self.same_on_batch)
        params["batch_prob"] = keep.expand(batch_size).to(torch.float32)
        return params

    def forward(self, input: torch.Tensor, params: dict[str, torch.Tensor] | None = None,
                generator: torch.Generator | None = None) -> torch.Tensor:
        if generator is not None and generator.device.type != "cpu":
            raise ValueError("generator must be a CPU torch.Generator")
        if not isinstance(input, torch.Tensor) or input.ndim != 5:
            shape = tuple(input.shape) if isinstance(input, torch.Tensor) else type(input).__name__
            raise ValueError(f"input must be a 5-D clip {self.data_format[0]}, {', '.join(self.data_format[1:])} "
                             f"(data_format={self.data_format!r}); got {shape}")
        x = input if self.data_format == "BTCHW" else input.transpose(1, 2)  # (B, T, C, H, W)
        B, T, C, H, W = x.shape
        if self.mode == "composite" and C != 2:
            raise ValueError(f"input: mode='composite' needs 2 channels (target value, alpha); got {C}")
        _check_input(x.reshape(B * T, C, H, W), self.mode)
        self._call_generator = generator
        try:
            if params is None:
                params = self.generate_parameters(B)
        finally:
            self._call_generator = None
        _check_params(params, B, self.sampler.atmospheres, (B,))  # a replayed draw too
        self._params = params
        out = x.clone()
        gate = (params["batch_prob"].reshape(-1).cpu() > 0.5 if "batch_prob" in params
                else torch.ones(B, dtype=torch.bool))  # no gate: every clip, as kornia's RandomSeaBackground
        idx = gate.nonzero()[:, 0]
        if idx.numel() > 0:
            sub = {k: v[idx.to(v.device)] for k, v in params.items() if isinstance(v, torch.Tensor) and v.ndim == 1
                   and v.shape[0] == B and (self.texture or k != "wave_seed")}  # texture=False: the expectation
            frames = frame_parameters(sub, T, self.frame_rate)
            L = _render_frames(sub, frames, H, W, self.sampler.atmospheres, self.band, self.anisotropic, x.dtype,
                               x.device, self.table, self.quadrature, EARTH_RADIUS_M, self.path, self.foam)
            n = idx.numel()
            L = one_thread(lambda: self._finish(L.reshape(n * T, 1, H, W), x[idx].reshape(n * T, C, H, W),  # as above
                                                frames["noise_seed"].reshape(-1).tolist()), x.device)
            L = L.to(x.dtype).reshape(n, T, 1, H, W)
            if self.mode == "composite":
                out[idx, :, :1] = L
            else:
                out[idx] = L.expand(-1, -1, C, -1, -1)
        return out if self.data_format == "BTCHW" else out.transpose(1, 2)

    def extra_repr(self) -> str:
        return (f"frame_rate={self.frame_rate:g}, data_format={self.data_format!r}, texture={self.texture}, "
                f"mode={self.mode!r}, output={self.output!r}, p={self.p:g}")

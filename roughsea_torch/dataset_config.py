"""The dataset generator's config: its defaults, its checks, and the sampler and sensor it describes.

A config is a nested dict (e.g. read from TOML; every key and its default in
:data:`DEFAULT_CONFIG`): the run (``seed``, ``num_images``, ``shard_size``, ``batch_size``,
``dtype``, ``clip_length``, ``frame_rate``), the ``camera`` size, the ``scene`` ranges and settings
(those of :class:`~roughsea_torch.sampling.SceneSampler`, plus ``band``, ``anisotropic``, ``foam``),
the ``motion`` ranges of clips and the ``sensor`` stages. :func:`resolve_config` checks every key
before any work and fills in the defaults; :func:`config_sampler` and :func:`build_sensor` give the
:class:`~roughsea_torch.sampling.SceneSampler` and :class:`~roughsea_torch.sensor.SensorModel` of a
resolved config. :mod:`roughsea_torch.dataset` renders it into shards (and re-exports
``DEFAULT_CONFIG``, ``resolve_config`` and ``build_sensor``).
"""

from __future__ import annotations

import copy
import inspect
import math
from typing import Any

import torch

from .radiometry import LWIR, MWIR, SpectralBand, as_band
from .renderer import TableSize, check_foam
from .sampling import DEFAULT_TIME_S, MOTION_FIELDS, SCENE_FIELDS, SUN_FIELDS, SceneSampler, as_range
from .sensor import DetectorNoise, FixedPatternNoise, OpticsBlur, SensorModel, ToCounts

__all__ = ["DEFAULT_CONFIG", "resolve_config", "build_sensor", "config_band", "scene_sampler", "config_sampler",
           "config_table"]

DEFAULT_CONFIG: dict[str, Any] = {
    "seed": 0,
    "num_images": 64,
    "shard_size": 16,
    "batch_size": 4,
    "dtype": "float32",
    "clip_length": 1,
    "frame_rate": 25.0,
    "camera": {"height": 512, "width": 640},
    "scene": {"atmospheres": ["midlatitude_summer"], "band": "LWIR", "anisotropic": True, "path": True,
              "foam": "auto", "texture": True, "time_s": list(DEFAULT_TIME_S),
              "daytime": 0.0, **{name: list(d) for name, _a, _u, d in SUN_FIELDS}, "sun_azimuth_relative_to_yaw": True,
              **{name: (list(d) if isinstance(d, tuple) else d) for name, _a, _u, d in SCENE_FIELDS}},
    "motion": {name: list(d) for name, _a, _u, d in MOTION_FIELDS},
    # how textured seas are rendered (TableSize fields): the flat point or the sweep near grazing,
    # the column filter, MWIR glitter by day
    "render": {"texture_hit": "flat", "texture_antialias": True, "glitter": False, "foam_trails": False},
    "sensor": {
        "blur": {"sigma_px": 0.7},
        "noise": {"netd_k": 0.05},
        "fixed_pattern": {"seed": 0},
        "counts": {"bits": 14, "temperature_range": [220.0, 340.0]},
    },
}
_BANDS = {"LWIR": LWIR, "MWIR": MWIR}
# the sensor stages a config may set, in SensorModel's order, and their classes
_STAGE_CLASSES: dict[str, type] = {"blur": OpticsBlur, "noise": DetectorNoise, "fixed_pattern": FixedPatternNoise,
                                   "counts": ToCounts}
_SENSOR_STAGES = tuple(_STAGE_CLASSES)



def config_band(name: Any) -> SpectralBand:
    """The band of a config's ``scene.band``: ``"LWIR"``, ``"MWIR"`` or ``[λ_lo, λ_hi]`` [m]; else
    ``ValueError`` naming ``scene.band``."""
    if isinstance(name, str) and name in _BANDS:
        return as_band(_BANDS[name])
    if isinstance(name, (list, tuple)) and len(name) == 2:
        return as_band((float(name[0]), float(name[1])))
    raise ValueError(f"scene.band: 'LWIR', 'MWIR' or [lambda_lo_m, lambda_hi_m]; got {name!r}")


def scene_sampler(scene: dict[str, Any], motion: dict[str, Any] | None = None) -> SceneSampler:
    """The SceneSampler of a config's ``scene`` table (its ranges, checked against the path tables
    when ``path`` is on; ``anisotropic`` aside), with the ``motion`` ranges for clips."""
    return SceneSampler(band=config_band(scene["band"]), motion=motion,
                        **{k: (tuple(v) if isinstance(v, list) else v) for k, v in scene.items()
                           if k not in ("band", "anisotropic", "foam")})


def config_sampler(cfg: dict[str, Any]) -> SceneSampler:
    """The sampler of a resolved config: with motion when it makes clips."""
    return scene_sampler(cfg["scene"], cfg["motion"] if cfg["clip_length"] > 1 else None)


def _check_keys(where: str, given: dict[str, Any], allowed: set[str]) -> None:
    """``ValueError`` naming the keys of the table ``where`` that are not ``allowed``."""
    unknown = sorted(set(given) - allowed)
    if unknown:
        raise ValueError(f"config: unknown key(s) {', '.join(f'{where}{k}' for k in unknown)}; allowed in "
                         f"{where.rstrip('.') or 'the top level'}: {sorted(allowed)}")


def resolve_config(config: dict[str, Any]) -> dict[str, Any]:
    """Check a config (e.g. read from TOML) and fill in the defaults of :data:`DEFAULT_CONFIG`.

    Every key is checked before any work starts: unknown keys, empty or inverted ranges,
    impossible poses (a camera at or below the sea), bad sizes raise ``ValueError`` naming the
    key. A sensor stage is left out by omitting its table or setting it to ``false``; the
    ``counts`` stage is required (shards hold 16-bit counts).

    Keys beyond the scene ranges: ``scene.texture`` (bool, default true: textured seas, one wave
    seed and one time per item; false: the expectation image), ``scene.time_s`` (range of the
    realizations' times [s], default [0, 3600)), ``clip_length`` (frames per item, integer ≥ 1;
    default 1: still images), ``frame_rate`` ([Hz], > 0, default 25; used by clips), and the
    ``motion`` table (ranges of the platform's oscillations for clips, keys of
    :data:`~roughsea_torch.sampling.MOTION_FIELDS`: amplitudes [deg], [m], periods [s]). The
    ``render`` table: ``texture_hit`` (``"flat"``, default, or ``"first"``: the sweep near grazing,
    7–18× the time of a flat-point image), ``texture_antialias`` (default true), ``glitter`` (default false: MWIR
    glitter by day) and ``foam_trails`` (default false: residual foam drifting and fading), the :class:`~roughsea_torch.renderer.TableSize` fields of the same names.
    Day images: ``scene.daytime`` (probability in [0, 1] that an item is by day, default 0.0: all
    by night, no sun drawn), ``scene.sun_elevation_deg`` (range [deg] within [0, 90], default
    [2, 60]), ``scene.sun_azimuth_deg`` (range [deg], default [-180, 180]; relative to the camera's
    yaw, 0 straight ahead, unless ``scene.sun_azimuth_relative_to_yaw = false``: world azimuth);
    see :class:`~roughsea_torch.sampling.SceneSampler`.
    """
    if not isinstance(config, dict):
        raise ValueError("config must be a table/dict")
    _check_keys("", config, set(DEFAULT_CONFIG))
    cfg = copy.deepcopy(DEFAULT_CONFIG)
    _resolve_run(config, cfg)
    _resolve_camera(config, cfg)
    _resolve_scene(config, cfg)
    _resolve_motion(config, cfg)
    _resolve_render(config, cfg)
    _resolve_sensor(config, cfg)
    build_sensor(cfg)  # the stages' own range checks, before any work
    return cfg


def _resolve_run(config: dict[str, Any], cfg: dict[str, Any]) -> None:
    """The top-level keys (seed, sizes, dtype, clip length, frame rate) of ``config`` into ``cfg``, checked."""
    for key in ("seed", "num_images", "shard_size", "batch_size", "dtype", "clip_length", "frame_rate"):
        if key in config:
            cfg[key] = config[key]
    for key, lo in (("seed", 0), ("num_images", 1), ("shard_size", 1), ("batch_size", 1), ("clip_length", 1)):
        v = cfg[key]
        if not isinstance(v, int) or isinstance(v, bool) or v < lo:
            raise ValueError(f"config: {key} must be an integer >= {lo}; got {v!r}")
    fr = cfg["frame_rate"]
    if not isinstance(fr, (int, float)) or isinstance(fr, bool) or not (math.isfinite(fr) and fr > 0):
        raise ValueError(f"config: frame_rate must be a number > 0 [Hz]; got {fr!r}")
    cfg["frame_rate"] = float(fr)
    if cfg["dtype"] not in ("float32", "float64"):
        raise ValueError(f"config: dtype must be 'float32' or 'float64'; got {cfg['dtype']!r}")


def _resolve_camera(config: dict[str, Any], cfg: dict[str, Any]) -> None:
    """The ``camera`` table (image height and width [px]) into ``cfg``, checked."""
    cam = config.get("camera", {})
    _check_keys("camera.", cam, set(DEFAULT_CONFIG["camera"]))
    cfg["camera"].update(cam)
    for key in ("height", "width"):
        v = cfg["camera"][key]
        if not isinstance(v, int) or isinstance(v, bool) or not 1 <= v <= 8192:
            raise ValueError(f"config: camera.{key} must be an integer in [1, 8192]; got {v!r}")


def _resolve_scene(config: dict[str, Any], cfg: dict[str, Any]) -> None:
    """The ``scene`` table into ``cfg``, checked: the band, the switches, the foam, and the ranges (by
    the SceneSampler they make)."""
    scene = config.get("scene", {})
    _check_keys("scene.", scene, set(DEFAULT_CONFIG["scene"]))
    cfg["scene"].update(scene)
    sc = cfg["scene"]
    config_band(sc["band"])
    for key in ("anisotropic", "path", "texture", "sun_azimuth_relative_to_yaw"):
        if not isinstance(sc[key], bool):
            raise ValueError(f"config: scene.{key} must be true or false; got {sc[key]!r}")
    try:
        check_foam(sc["foam"], per_image=False)  # "auto", false or one fraction (true: refused, pointing at "auto")
    except ValueError as e:
        raise ValueError(f"config: scene.{e}") from None
    try:
        scene_sampler(sc)
    except ValueError as e:
        raise ValueError(f"config: scene.{e}") from None


def _resolve_render(config: dict[str, Any], cfg: dict[str, Any]) -> None:
    """The ``render`` table into ``cfg``, checked by :class:`~roughsea_torch.renderer.TableSize` itself."""
    render = config.get("render", {})
    if not isinstance(render, dict):
        raise ValueError(f"config: render must be a table of TableSize settings; got {render!r}")
    _check_keys("render.", render, set(DEFAULT_CONFIG["render"]))
    cfg["render"].update(render)
    try:
        config_table(cfg)
    except ValueError as e:
        raise ValueError(f"config: render.{str(e).removeprefix('TableSize.')}") from None


def config_table(cfg: dict[str, Any]) -> TableSize:
    """The :class:`~roughsea_torch.renderer.TableSize` of a config's ``render`` table."""
    return TableSize(**cfg["render"])


def _resolve_motion(config: dict[str, Any], cfg: dict[str, Any]) -> None:
    """The ``motion`` table into ``cfg``, checked: for clips against the scene's poses too."""
    motion = config.get("motion", {})
    if not isinstance(motion, dict):
        raise ValueError(f"config: motion must be a table of ranges; got {motion!r}")
    _check_keys("motion.", motion, set(DEFAULT_CONFIG["motion"]))
    cfg["motion"].update(motion)
    try:
        if cfg["clip_length"] > 1:  # the ranges, and the pose ± amplitudes against the allowed poses
            scene_sampler(cfg["scene"], cfg["motion"])
        else:  # still images do not move: only the ranges themselves
            for name, allowed, unit, _d in MOTION_FIELDS:
                as_range(name, cfg["motion"][name], allowed, unit)
    except ValueError as e:
        raise ValueError(f"config: motion.{e}") from None


def _resolve_sensor(config: dict[str, Any], cfg: dict[str, Any]) -> None:
    """The ``sensor`` tables into ``cfg``, checked: a table or false per stage, counts required and at
    most 16 bits, each stage's keys among its class's arguments (the values: by build_sensor)."""
    sensor = config.get("sensor", {})
    _check_keys("sensor.", sensor, set(_SENSOR_STAGES))
    for stage in _SENSOR_STAGES:
        if stage in sensor:
            v = sensor[stage]
            cfg["sensor"][stage] = False if v is False else dict(v) if isinstance(v, dict) else v
        if cfg["sensor"][stage] is not False and not isinstance(cfg["sensor"][stage], dict):
            raise ValueError(f"config: sensor.{stage} must be a table of settings or false; got {cfg['sensor'][stage]!r}")
    if cfg["sensor"]["counts"] is False:
        raise ValueError("config: sensor.counts is required (the shards hold 16-bit counts)")
    bits = cfg["sensor"]["counts"].get("bits", 14)
    if not isinstance(bits, int) or not 1 <= bits <= 16:
        raise ValueError(f"config: sensor.counts.bits must be an integer in [1, 16] (16-bit shards); got {bits!r}")
    for stage, cls in _STAGE_CLASSES.items():
        settings = cfg["sensor"][stage]
        if settings is False:
            continue
        params = inspect.signature(cls.__init__).parameters
        _check_keys(f"sensor.{stage}.", settings, {p for p in params if p not in ("self", "band")})


def build_sensor(cfg: dict[str, Any]) -> torch.nn.Module:
    """The ``SensorModel`` of a resolved config (stages set to ``false`` are left out)."""
    band = config_band(cfg["scene"]["band"])
    stages: dict[str, Any] = {}
    for stage, cls in _STAGE_CLASSES.items():
        settings = cfg["sensor"][stage]
        if settings is False:
            stages[stage] = None
            continue
        kw = {k: (tuple(v) if isinstance(v, list) else v) for k, v in settings.items()}
        if "band" in inspect.signature(cls.__init__).parameters:
            kw["band"] = band
        try:
            stages[stage] = cls(**kw)
        except ValueError as e:
            raise ValueError(f"config: sensor.{stage}: {e}") from None
    return SensorModel(**stages)

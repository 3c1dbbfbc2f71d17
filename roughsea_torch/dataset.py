"""Sea-background datasets on disk: a validated config, a sharded generator that resumes and scales
out, and a ``torch.utils.data`` dataset that streams the shards back.

Layout of an output directory::

    config.json               the resolved config (every default filled in); a resumed or
                              distributed run must find the same one
    shard_000000.npz ...      numpy archives, one per ``shard_size`` items: ``images`` uint16
                              sensor counts, (N, H, W) for still images or (N, T, H, W) for clips
                              of T = ``clip_length`` frames; per item ``index``, every scene
                              parameter (float64), ``atmosphere`` (name), ``noise_seed`` (int64),
                              ``image_seed`` (uint64); with ``scene.texture``: ``wave_seed``
                              (int64) and ``time_s`` [s] (float64); with ``scene.daytime`` > 0:
                              ``is_day`` (bool), ``sun_elevation_deg``, ``sun_zenith_deg`` and
                              ``sun_azimuth_deg`` (the sun's WORLD azimuth) (float64 [deg]; drawn
                              for every item, used only where ``is_day``); for clips also the motion
                              parameters (``pitch_amplitude_deg``, ``roll_amplitude_deg``,
                              ``heave_amplitude_m`` [m], ``*_period_s`` [s], ``phase_rad``) and
                              per frame (N, T): ``frame_time_s`` [s], ``frame_pitch_deg``,
                              ``frame_roll_deg``, ``frame_altitude_m`` [m], ``frame_noise_seed``
    manifest_rank000.json     the shards a rank has finished (rewritten atomically per shard)
    manifest.json             all shards, written when the whole run is complete

Still images and clips. ``clip_length = 1`` (default) makes still images: a sea at the mean
pose, textured (``scene.texture = true``, the default: one wave seed and a time per image) or
the expectation image (``false``). ``clip_length = T > 1`` makes clips: one sea realization per
clip, frame t at ``time_s`` + t / ``frame_rate`` [s], seen from a camera on a
:class:`~roughsea_torch.motion.PlatformMotion` whose amplitudes and periods are drawn per clip
from the ``[motion]`` ranges (:data:`~roughsea_torch.augmentation.MOTION_FIELDS`). Every frame is
re-rendered exactly by :func:`~roughsea_torch.augmentation.render_parameters` of its item's fields
with ``pitch_deg``, ``roll_deg``, ``altitude_m``, ``time_s`` replaced by the frame's, and its
sensor noise drawn from ``frame_noise_seed`` (with the config's ``scene.band``, ``anisotropic``,
``path`` and ``foam``; ``foam = false`` leaves the whitecaps out, ``"auto"`` is the default).

Determinism: item i (image or clip) is made only from (seed, i) (its parameters, wave seed,
motion and noise streams come from
:func:`~roughsea_torch.augmentation.SceneSampler.sample_indexed`), and shard k always holds
items [k·S, (k+1)·S) rendered together, so a shard's bytes do not depend on how many workers,
ranks or restarts made it. Writes go to a temporary name and are renamed into place (atomic on
POSIX), so a killed run leaves whole shards or none; a restart makes only the missing ones.
"""

from __future__ import annotations

import copy
import hashlib
import inspect
import io
import json
import math
import os
from pathlib import Path
from typing import Any, Callable, Iterator

import numpy as np
import torch

from ._version import __version__
from .parameter_render import render_clip_parameters, render_parameters
from .radiometry import LWIR, MWIR, SpectralBand, as_band
from .render import check_foam
from .sampling import (
    DEFAULT_TIME_S,
    MOTION_FIELDS,
    SCENE_FIELDS,
    SUN_FIELDS,
    SceneSampler,
    as_range,
    frame_parameters,
    image_seed,
)
from .sensor import DetectorNoise, FixedPatternNoise, OpticsBlur, SensorModel, ToCounts

__all__ = ["DEFAULT_CONFIG", "resolve_config", "build_sensor", "generate", "SeaShardDataset", "shard_name",
           "frame_render_parameters"]

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


def shard_name(k: int) -> str:
    return f"shard_{k:06d}.npz"


def _band(name: Any) -> SpectralBand:
    if isinstance(name, str) and name in _BANDS:
        return as_band(_BANDS[name])
    if isinstance(name, (list, tuple)) and len(name) == 2:
        return as_band((float(name[0]), float(name[1])))
    raise ValueError(f"scene.band: 'LWIR', 'MWIR' or [lambda_lo_m, lambda_hi_m]; got {name!r}")


def _sampler(scene: dict[str, Any], motion: dict[str, Any] | None = None) -> SceneSampler:
    """The SceneSampler of a config's ``scene`` table (its ranges, checked against the path tables
    when ``path`` is on; ``anisotropic`` aside), with the ``motion`` ranges for clips."""
    return SceneSampler(band=_band(scene["band"]), motion=motion,
                        **{k: (tuple(v) if isinstance(v, list) else v) for k, v in scene.items()
                           if k not in ("band", "anisotropic", "foam")})


def _config_sampler(cfg: dict[str, Any]) -> SceneSampler:
    """The sampler of a resolved config: with motion when it makes clips."""
    return _sampler(cfg["scene"], cfg["motion"] if cfg["clip_length"] > 1 else None)


def _check_keys(where: str, given: dict[str, Any], allowed: set[str]) -> None:
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
    :data:`~roughsea_torch.augmentation.MOTION_FIELDS`: amplitudes [deg], [m], periods [s]).
    Day images: ``scene.daytime`` (probability in [0, 1] that an item is by day, default 0.0: all
    by night, shards as before), ``scene.sun_elevation_deg`` (range [deg] within [0, 90], default
    [2, 60]), ``scene.sun_azimuth_deg`` (range [deg], default [-180, 180]; relative to the camera's
    yaw, 0 straight ahead, unless ``scene.sun_azimuth_relative_to_yaw = false``: world azimuth);
    see :class:`~roughsea_torch.augmentation.SceneSampler`.
    """
    if not isinstance(config, dict):
        raise ValueError("config must be a table/dict")
    _check_keys("", config, set(DEFAULT_CONFIG))
    cfg = copy.deepcopy(DEFAULT_CONFIG)
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
    cam = config.get("camera", {})
    _check_keys("camera.", cam, set(DEFAULT_CONFIG["camera"]))
    cfg["camera"].update(cam)
    for key in ("height", "width"):
        v = cfg["camera"][key]
        if not isinstance(v, int) or isinstance(v, bool) or not 1 <= v <= 8192:
            raise ValueError(f"config: camera.{key} must be an integer in [1, 8192]; got {v!r}")
    scene = config.get("scene", {})
    _check_keys("scene.", scene, set(DEFAULT_CONFIG["scene"]))
    cfg["scene"].update(scene)
    sc = cfg["scene"]
    _band(sc["band"])
    for key in ("anisotropic", "path", "texture", "sun_azimuth_relative_to_yaw"):
        if not isinstance(sc[key], bool):
            raise ValueError(f"config: scene.{key} must be true or false; got {sc[key]!r}")
    try:
        check_foam(sc["foam"], per_image=False)  # "auto", false or one fraction (true: refused, pointing at "auto")
    except ValueError as e:
        raise ValueError(f"config: scene.{e}") from None
    try:
        _sampler(sc)
    except ValueError as e:
        raise ValueError(f"config: scene.{e}") from None
    motion = config.get("motion", {})
    if not isinstance(motion, dict):
        raise ValueError(f"config: motion must be a table of ranges; got {motion!r}")
    _check_keys("motion.", motion, set(DEFAULT_CONFIG["motion"]))
    cfg["motion"].update(motion)
    try:
        if cfg["clip_length"] > 1:  # the ranges, and the pose ± amplitudes against the allowed poses
            _sampler(sc, cfg["motion"])
        else:  # still images do not move: only the ranges themselves
            for name, allowed, unit, _d in MOTION_FIELDS:
                as_range(name, cfg["motion"][name], allowed, unit)
    except ValueError as e:
        raise ValueError(f"config: motion.{e}") from None
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
    build_sensor(cfg)  # the stages' own range checks, before any work
    return cfg


def build_sensor(cfg: dict[str, Any]) -> torch.nn.Module:
    """The ``SensorModel`` of a resolved config (stages set to ``false`` are left out)."""
    band = _band(cfg["scene"]["band"])
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


def _atomic_write(path: Path, write: Callable[[Any], None], crash_after_bytes: int | None = None) -> None:
    tmp = path.with_name(f".{path.name}.tmp{os.getpid()}")
    with open(tmp, "wb") as f:
        if crash_after_bytes is not None:  # testing hook: die in the middle of a write
            buf = io.BytesIO()
            write(buf)
            f.write(buf.getvalue()[:crash_after_bytes])
            f.flush()
            os._exit(137)
        write(f)
        f.flush()
        os.fsync(f.fileno())
    os.replace(tmp, path)


def _write_json(path: Path, obj: Any) -> None:
    _atomic_write(path, lambda f: f.write((json.dumps(obj, indent=1, sort_keys=True) + "\n").encode()))


def render_shard(cfg: dict[str, Any], k: int, sensor: torch.nn.Module | None = None,
                 device: torch.device | str | None = None) -> dict[str, np.ndarray]:
    """Items [k·S, (k+1)·S) of a resolved config: counts (uint16; (N, H, W), or (N, T, H, W) for
    clips) and their parameters."""
    sc = cfg["scene"]
    sampler = _config_sampler(cfg)
    S, N = cfg["shard_size"], cfg["num_images"]
    T = cfg["clip_length"]
    indices = list(range(k * S, min((k + 1) * S, N)))
    params = sampler.sample_indexed(cfg["seed"], indices)
    frames = frame_parameters(params, T, cfg["frame_rate"]) if T > 1 else None
    sensor = sensor if sensor is not None else build_sensor(cfg)
    sensor = sensor.to(device) if device is not None else sensor
    dtype = getattr(torch, cfg["dtype"])
    H, W = cfg["camera"]["height"], cfg["camera"]["width"]
    counts = np.empty((len(indices), T, H, W), dtype=np.uint16)
    bs = cfg["batch_size"]
    with torch.no_grad():
        for i in range(0, len(indices), bs):
            sub = {n: v[i : i + bs] for n, v in params.items()}
            kw = dict(band=_band(sc["band"]), anisotropic=sc["anisotropic"], dtype=dtype, device=device, path=sc["path"],
                      foam=sc["foam"])
            if T > 1:
                L = render_clip_parameters(sub, T, cfg["frame_rate"], H, W, sampler.atmospheres, **kw)
                seeds = frames["noise_seed"][i : i + bs]
            else:
                L = render_parameters(sub, H, W, sampler.atmospheres, **kw)[:, None]
                seeds = sub["noise_seed"][:, None]
            # image by image: a shard's image is then exactly what re-rendering it alone from its metadata
            # gives (the blur's convolution may differ in the last bit between batch sizes)
            for j in range(L.shape[0]):
                for t in range(T):
                    g = torch.Generator().manual_seed(int(seeds[j, t]))  # CPU draws: the same noise on any device
                    c = sensor(L[j, t : t + 1], generator=g)
                    counts[i + j, t] = c[0, 0].round().clamp(0, 65535).to(torch.int32).cpu().numpy().astype(np.uint16)
    out = {"images": counts if T > 1 else counts[:, 0], "index": np.asarray(indices, dtype=np.int64)}
    for name, *_r in SCENE_FIELDS:
        out[name] = params[name].numpy()
    out["atmosphere"] = np.asarray([sampler.atmospheres[a] for a in params["atmosphere"].tolist()])
    out["noise_seed"] = params["noise_seed"].numpy()
    out["image_seed"] = np.asarray([image_seed(cfg["seed"], i) for i in indices], dtype=np.uint64)
    for name in ("wave_seed", "time_s"):  # texture on (absent otherwise: such shards are as before texture)
        if name in params:
            out[name] = params[name].numpy()
    if "is_day" in params:  # daytime > 0 (absent otherwise: such shards are as before the sun)
        out["is_day"] = params["is_day"].numpy()
        out["sun_elevation_deg"] = params["sun_elevation_deg"].numpy()
        out["sun_zenith_deg"] = (90.0 - params["sun_elevation_deg"]).numpy()
        out["sun_azimuth_deg"] = params["sun_azimuth_deg"].numpy()
    if frames is not None:
        for name, *_r in MOTION_FIELDS:
            out[name] = params[name].numpy()
        out["phase_rad"] = params["phase_rad"].numpy()
        for name in ("time_s", "pitch_deg", "roll_deg", "altitude_m", "noise_seed"):
            out[f"frame_{name}"] = frames[name].numpy()
    return out


def frame_render_parameters(meta: dict[str, Any], frame: int | None = None) -> dict[str, torch.Tensor]:
    """The :func:`~roughsea_torch.augmentation.render_parameters` input (one image) of an item's
    metadata (as :class:`SeaShardDataset` yields it, or a shard's arrays at one index), for a
    still image or, with ``frame``, frame ``frame`` of a clip: its pose and time replaced by the
    frame's.

    Returns a dict of tensors of shape (1,): the scene fields of :data:`SCENE_FIELDS` (float64),
    ``noise_seed`` (int64: the item's, or with ``frame`` the frame's ``frame_noise_seed[frame]``,
    the seed of that frame's sensor noise); a textured item (``wave_seed`` in its metadata) also
    gives ``wave_seed`` (int64) and ``time_s`` (float64 [s], the frame's with ``frame``); a day item
    (``is_day`` in its metadata, ``scene.daytime`` > 0) also ``is_day``, ``sun_elevation_deg`` and
    ``sun_azimuth_deg`` (world). The atmosphere is NOT in it (``render_parameters`` needs it as an
    index, which depends on the atmospheres you render with): the metadata's ``"atmosphere"`` is
    its name, so add ``p["atmosphere"] = torch.tensor([atmospheres.index(meta["atmosphere"])])``."""
    p = {k: torch.tensor([float(meta[k])], dtype=torch.float64) for k, *_r in SCENE_FIELDS}
    if "wave_seed" in meta:
        p["wave_seed"] = torch.tensor([int(meta["wave_seed"])], dtype=torch.int64)
        p["time_s"] = torch.tensor([float(meta["time_s"])], dtype=torch.float64)
    p["noise_seed"] = torch.tensor([int(meta["noise_seed"])], dtype=torch.int64)
    if "is_day" in meta:  # the sun of a day item (world azimuth; the renderer uses the elevation)
        p["is_day"] = torch.tensor([bool(meta["is_day"])])
        p["sun_elevation_deg"] = torch.tensor([float(meta["sun_elevation_deg"])], dtype=torch.float64)
        p["sun_azimuth_deg"] = torch.tensor([float(meta["sun_azimuth_deg"])], dtype=torch.float64)
    if frame is not None:
        if "frame_time_s" not in meta:
            raise ValueError("frame: this item is a still image (no per-frame metadata); pass frame=None")
        n = len(meta["frame_time_s"])
        if not isinstance(frame, int) or not 0 <= frame < n:
            raise ValueError(f"frame must be an int in [0, {n}); got {frame!r}")
        for name in ("time_s", "pitch_deg", "roll_deg", "altitude_m"):
            p[name] = torch.tensor([float(meta[f"frame_{name}"][frame])], dtype=torch.float64)
        p["noise_seed"] = torch.tensor([int(meta["frame_noise_seed"][frame])], dtype=torch.int64)
    return p


def _sha256(path: Path) -> str:
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


class _ShardJobs(torch.utils.data.Dataset):
    """One item = one shard rendered and written (what DataLoader workers run in parallel)."""

    def __init__(self, cfg: dict[str, Any], out: Path, shards: list[int], crash_after_shards: int | None):
        self.cfg, self.out, self.shards, self.crash = cfg, out, shards, crash_after_shards
        self.sensor: torch.nn.Module | None = None

    def __len__(self) -> int:
        return len(self.shards)

    def __getitem__(self, i: int) -> dict[str, Any]:
        k = self.shards[i]
        if self.sensor is None:
            self.sensor = build_sensor(self.cfg)
        arrays = render_shard(self.cfg, k, self.sensor)
        path = self.out / shard_name(k)
        crash = 100 if self.crash is not None and i >= self.crash else None
        _atomic_write(path, lambda f: np.savez(f, **arrays), crash_after_bytes=crash)
        return {"shard": k, "file": path.name, "images": int(arrays["images"].shape[0]), "sha256": _sha256(path)}


def num_shards(cfg: dict[str, Any]) -> int:
    return math.ceil(cfg["num_images"] / cfg["shard_size"])


def _metadata(cfg: dict[str, Any]) -> dict[str, Any]:
    band = _band(cfg["scene"]["band"])
    return {"config": cfg, "band_m": [band.lo, band.hi], "roughsea_torch": __version__,
            "torch": torch.__version__.split("+")[0], "num_shards": num_shards(cfg),
            "units": {"images": "sensor counts (uint16); see sensor.counts for the radiance mapping",
                      "temperatures": "K", "angles": "deg", "altitude_m": "m", "wind_speed": "m/s at 12.5 m",
                      "time_s": "s", "frame_rate": "Hz", "heave_amplitude_m": "m", "periods": "s",
                      "phase_rad": "rad", "sun_elevation_deg": "deg above the horizon",
                      "sun_zenith_deg": "deg", "sun_azimuth_deg": "deg, world azimuth (from +x towards +y, as yaw_deg)"}}


def generate(
    config: dict[str, Any],
    out: str | Path,
    *,
    workers: int = 0,
    rank: int = 0,
    world_size: int = 1,
    progress: bool = True,
    crash_after_shards: int | None = None,
) -> dict[str, Any]:
    """Render a config's images into shards under ``out``; resumable and safe to run in parallel.

    Args:
        config: a config dict (validated by :func:`resolve_config`).
        out: output directory (created).
        workers: ``torch.utils.data.DataLoader`` worker processes rendering shards in parallel
            (0: in this process).
        rank, world_size: this process's part when several processes or machines share the run
            (``torchrun`` sets them): shard k belongs to rank k mod world_size; ranks write
            disjoint files.
        progress: show a tqdm bar.
        crash_after_shards: testing hook: die (``os._exit``) in the middle of writing the shard
            after this many.

    Returns:
        This rank's manifest: ``{"rank", "world_size", "shards": [{shard, file, images, sha256}]}``.
        With ``world_size == 1`` it also writes ``manifest.json``; distributed runs call
        :func:`finish` on rank 0 after a barrier.
    """
    cfg = resolve_config(config)
    if not (0 <= rank < world_size):
        raise ValueError(f"rank must lie in [0, world_size); got rank={rank}, world_size={world_size}")
    if not isinstance(workers, int) or workers < 0:
        raise ValueError(f"workers must be an int >= 0; got {workers!r}")
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    meta = _metadata(cfg)
    cfg_path = out / "config.json"
    if cfg_path.exists():
        old = json.loads(cfg_path.read_text())
        if old != json.loads(json.dumps(meta)):
            raise ValueError(f"out: {out} holds a run with another config (or library version); "
                             "resume with the same config or use another directory")
    else:
        _write_json(cfg_path, meta)
    for tmp in out.glob(".shard_*.tmp*"):  # pieces of writes a killed run left behind
        k = int(tmp.name.split("_")[1].split(".")[0])
        if k % world_size == rank:
            tmp.unlink(missing_ok=True)
    mine = [k for k in range(num_shards(cfg)) if k % world_size == rank]
    manifest_path = out / f"manifest_rank{rank:03d}.json"
    done: dict[int, dict[str, Any]] = {}
    if manifest_path.exists():
        for e in json.loads(manifest_path.read_text())["shards"]:
            if (out / e["file"]).exists():
                done[e["shard"]] = e
    for k in mine:  # a shard renamed into place but not yet in the manifest when the run died
        if k not in done and (out / shard_name(k)).exists():
            with np.load(out / shard_name(k)) as z:
                n = int(z["images"].shape[0])
            done[k] = {"shard": k, "file": shard_name(k), "images": n, "sha256": _sha256(out / shard_name(k))}
    todo = [k for k in mine if k not in done]
    manifest = {"rank": rank, "world_size": world_size, "shards": [done[k] for k in sorted(done)]}
    if todo:
        jobs = _ShardJobs(cfg, out, todo, crash_after_shards)
        loader = torch.utils.data.DataLoader(jobs, batch_size=None, num_workers=workers, shuffle=False,
                                             persistent_workers=False)
        bar = None
        if progress:
            from tqdm import tqdm  # an optional dependency (the "test" and "pipelines" extras): imported when used

            bar = tqdm(total=sum(min(cfg["shard_size"], cfg["num_images"] - k * cfg["shard_size"]) for k in todo),
                       unit="img" if cfg["clip_length"] == 1 else "clip", desc=f"rank {rank} shards", dynamic_ncols=True)
        for entry in loader:
            done[entry["shard"]] = entry
            manifest["shards"] = [done[k] for k in sorted(done)]
            _write_json(manifest_path, manifest)
            if bar is not None:
                bar.update(entry["images"])
        if bar is not None:
            bar.close()
    else:
        _write_json(manifest_path, manifest)
    if world_size == 1:
        finish(out)
    return manifest


def finish(out: str | Path) -> dict[str, Any]:
    """Merge the ranks' manifests into ``manifest.json`` once every shard exists (rank 0 calls
    it after the others are done). Raises ``RuntimeError`` listing missing shards otherwise."""
    out = Path(out)
    meta = json.loads((out / "config.json").read_text())
    entries: dict[int, dict[str, Any]] = {}
    for p in sorted(out.glob("manifest_rank*.json")):
        for e in json.loads(p.read_text())["shards"]:
            entries[e["shard"]] = e
    missing = [k for k in range(meta["num_shards"]) if k not in entries or not (out / entries[k]["file"]).exists()]
    if missing:
        raise RuntimeError(f"{out}: shards {missing[:10]}{'...' if len(missing) > 10 else ''} are missing; run the generator again to finish them")
    manifest = {"complete": True, "num_images": meta["config"]["num_images"],
                "shards": [entries[k] for k in range(meta["num_shards"])]}
    _write_json(out / "manifest.json", manifest)
    return manifest


class SeaShardDataset(torch.utils.data.IterableDataset):
    """Stream the images of a generated dataset: yields ``(image, meta)`` with ``image`` a float32
    tensor (1, H, W) of sensor counts (or radiance [W m⁻² sr⁻¹] with ``radiance=True``, inverting
    the counts stage) and ``meta`` a dict of that image's parameters (Python numbers; the
    atmosphere's name). For clips (``clip_length`` T > 1) ``image`` is (T, 1, H, W), kornia's
    BTCHW once batched, and the per-frame fields (``frame_*``) are tensors (T,).

    Shards are split over ``torch.utils.data`` workers and, when ``torch.distributed`` is
    initialised (or ``rank``/``world_size`` are given), over ranks: each reads disjoint shards.
    ``shuffle=True`` permutes the shard order and the images within a shard per epoch
    (``set_epoch``), from ``seed``.

    Args:
        root: the generator's output directory (needs ``manifest.json``: a complete run; pass
            ``allow_partial=True`` to read whatever shards exist).
    """

    def __init__(self, root: str | Path, *, radiance: bool = False, shuffle: bool = False, seed: int = 0,
                 rank: int | None = None, world_size: int | None = None, allow_partial: bool = False):
        self.root = Path(root)
        meta_path = self.root / "config.json"
        if not meta_path.exists():
            raise ValueError(f"root: {self.root} has no config.json (not a generated dataset)")
        self.meta = json.loads(meta_path.read_text())
        man = self.root / "manifest.json"
        if man.exists():
            self.shards = [e["file"] for e in json.loads(man.read_text())["shards"]]
        elif allow_partial:
            self.shards = sorted(p.name for p in self.root.glob("shard_*.npz"))
        else:
            raise ValueError(f"root: {self.root} has no manifest.json (the run is incomplete); finish it, or pass allow_partial=True")
        self.radiance = radiance
        self.shuffle = shuffle
        self.seed = seed
        self.epoch = 0
        self.rank, self.world_size = rank, world_size
        self._counts: torch.nn.Module | None = None

    def set_epoch(self, epoch: int) -> None:
        self.epoch = int(epoch)

    def __len__(self) -> int:
        cfg = self.meta["config"]
        S, N = cfg["shard_size"], cfg["num_images"]
        return sum(min(S, N - int(f[6:12]) * S) for f in self._my_shards(1, 0))

    def _my_shards(self, nworkers: int, worker: int) -> list[str]:
        rank, world = self.rank, self.world_size
        if rank is None or world is None:
            dist = torch.distributed
            if dist.is_available() and dist.is_initialized():
                rank, world = dist.get_rank(), dist.get_world_size()
            else:
                rank, world = 0, 1
        order = list(self.shards)
        if self.shuffle:
            g = torch.Generator().manual_seed(self.seed * 1_000_003 + self.epoch)
            order = [order[i] for i in torch.randperm(len(order), generator=g).tolist()]
        return order[rank * nworkers + worker :: world * nworkers]

    def __iter__(self) -> Iterator[tuple[torch.Tensor, dict[str, Any]]]:
        info = torch.utils.data.get_worker_info()
        nworkers, worker = (info.num_workers, info.id) if info is not None else (1, 0)
        for name in self._my_shards(nworkers, worker):
            with np.load(self.root / name) as z:
                arrays = {k: z[k] for k in z.files}
            n = arrays["images"].shape[0]
            order = range(n)
            if self.shuffle:
                g = torch.Generator().manual_seed(self.seed * 1_000_003 + self.epoch * 7919 + int(arrays["index"][0]))
                order = torch.randperm(n, generator=g).tolist()
            for i in order:
                img = torch.from_numpy(arrays["images"][i].astype(np.float32))
                img = img[None] if img.ndim == 2 else img[:, None]  # (1, H, W) or a clip's (T, 1, H, W)
                if self.radiance:
                    img = self._to_radiance(img)
                meta = {k: (str(v[i]) if v.dtype.kind == "U" else torch.from_numpy(v[i].copy()) if v.ndim > 1 else v[i].item())
                        for k, v in arrays.items() if k != "images"}
                yield img, meta

    def _to_radiance(self, counts: torch.Tensor) -> torch.Tensor:
        if self._counts is None:
            self._counts = build_sensor(self.meta["config"]).counts
        if counts.ndim == 4:  # a clip's frames are a batch
            return self._counts.counts_to_radiance(counts)
        return self._counts.counts_to_radiance(counts[None])[0]

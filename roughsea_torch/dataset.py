"""Sea-background datasets on disk: a sharded generator that resumes and scales out, and a
``torch.utils.data`` dataset that streams the shards back. The config they take (its defaults,
:func:`resolve_config`, :func:`build_sensor`) is :mod:`roughsea_torch.dataset_config`'s, importable
from here too.

Layout of an output directory::

    config.json               the resolved config (every default filled in); a resumed or
                              distributed run must find the same one
    shard_000000.npz ...      numpy archives, one per ``shard_size`` items: ``images`` uint16
                              sensor counts, (N, H, W) for still images or (N, T, H, W) for clips
                              of T = ``clip_length`` frames; per item ``index``, every scene
                              parameter (float64; ``air_sea_difference`` is T_air − T_sea
                              [K] of the item, drawn or not), ``atmosphere`` (name),
                              ``noise_seed`` (int64),
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
from the ``[motion]`` ranges (:data:`~roughsea_torch.sampling.MOTION_FIELDS`). Every frame is
re-rendered exactly by :func:`~roughsea_torch.parameter_render.render_parameters` of its item's fields
with ``pitch_deg``, ``roll_deg``, ``altitude_m``, ``time_s`` replaced by the frame's, and its
sensor noise drawn from ``frame_noise_seed`` (with the config's ``scene.band``, ``anisotropic``,
``path`` and ``foam``, and the ``render`` table as ``table=TableSize(**render)``; ``foam = false`` leaves the
whitecaps out, ``"auto"`` is the default).

Determinism: item i (image or clip) is made only from (seed, i) (its parameters, wave seed,
motion and noise streams come from
:func:`~roughsea_torch.sampling.SceneSampler.sample_indexed`), and shard k always holds
items [k·S, (k+1)·S) rendered together, so a shard's bytes do not depend on how many workers,
ranks or restarts made it. Writes go to a temporary name and are renamed into place (atomic on
POSIX), so a killed run leaves whole shards or none; a restart makes only the missing ones.
"""

from __future__ import annotations

import hashlib
import io
import json
import math
import os
import warnings
from pathlib import Path
from typing import Any, Callable, Iterator

import numpy as np
import torch

from ._version import __version__
from .dataset_config import DEFAULT_CONFIG, build_sensor, config_band, config_sampler, config_table, resolve_config
from .parameter_render import render_clip_parameters, render_parameters
from .sampling import MOTION_FIELDS, RENDER_FIELD_NAMES, SCENE_FIELDS, frame_parameters, image_seed

__all__ = ["DEFAULT_CONFIG", "resolve_config", "build_sensor", "generate", "SeaShardDataset", "shard_name",
           "frame_render_parameters"]


def shard_name(k: int) -> str:
    return f"shard_{k:06d}.npz"


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
    sampler = config_sampler(cfg)
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
            kw = dict(band=config_band(sc["band"]), anisotropic=sc["anisotropic"], dtype=dtype, device=device,
                      path=sc["path"], foam=sc["foam"], table=config_table(cfg))
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
    for name in ("wave_seed", "time_s"):  # texture on (absent otherwise)
        if name in params:
            out[name] = params[name].numpy()
    if "is_day" in params:  # daytime > 0 (absent otherwise)
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
    """The :func:`~roughsea_torch.parameter_render.render_parameters` input (one image) of an item's
    metadata (as :class:`SeaShardDataset` yields it, or a shard's arrays at one index), for a
    still image or, with ``frame``, frame ``frame`` of a clip: its pose and time replaced by the
    frame's.

    Returns a dict of tensors of shape (1,): the scene fields of :data:`SCENE_FIELDS` (float64;
    ``air_sea_difference`` only if the metadata holds it: shards written before it existed do not),
    ``noise_seed`` (int64: the item's, or with ``frame`` the frame's ``frame_noise_seed[frame]``,
    the seed of that frame's sensor noise); a textured item (``wave_seed`` in its metadata) also
    gives ``wave_seed`` (int64) and ``time_s`` (float64 [s], the frame's with ``frame``); a day item
    (``is_day`` in its metadata, ``scene.daytime`` > 0) also ``is_day``, ``sun_elevation_deg`` and
    ``sun_azimuth_deg`` (world). The atmosphere is NOT in it (``render_parameters`` needs it as an
    index, which depends on the atmospheres you render with): the metadata's ``"atmosphere"`` is
    its name, so add ``p["atmosphere"] = torch.tensor([atmospheres.index(meta["atmosphere"])])``."""
    p = {k: torch.tensor([float(meta[k])], dtype=torch.float64) for k, *_r in SCENE_FIELDS
         if k in RENDER_FIELD_NAMES or k in meta}
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
        # the shard's warnings go back with its entry, for generate to raise in the caller's process at
        # the caller's line (raised here, in a worker process, they pointed into multiprocessing)
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            arrays = render_shard(self.cfg, k, self.sensor)
        path = self.out / shard_name(k)
        crash = 100 if self.crash is not None and i >= self.crash else None
        _atomic_write(path, lambda f: np.savez(f, **arrays), crash_after_bytes=crash)
        return {"shard": k, "file": path.name, "images": int(arrays["images"].shape[0]), "sha256": _sha256(path),
                "warnings": [(w.category, str(w.message)) for w in caught]}


def num_shards(cfg: dict[str, Any]) -> int:
    return math.ceil(cfg["num_images"] / cfg["shard_size"])


def _metadata(cfg: dict[str, Any]) -> dict[str, Any]:
    band = config_band(cfg["scene"]["band"])
    return {"config": cfg, "band_m": [band.lo, band.hi], "roughsea_torch": __version__,
            "torch": torch.__version__.split("+")[0], "num_shards": num_shards(cfg),
            "units": {"images": "sensor counts (uint16); see sensor.counts for the radiance mapping",
                      "temperatures": "K", "angles": "deg", "altitude_m": "m", "wind_speed": "m/s at 12.5 m",
                      "time_s": "s", "frame_rate": "Hz", "heave_amplitude_m": "m", "periods": "s",
                      "phase_rad": "rad", "sun_elevation_deg": "deg above the horizon",
                      "sun_zenith_deg": "deg", "sun_azimuth_deg": "deg, world azimuth (from +x towards +y, as yaw_deg)"}}


def _open_run(out: Path, meta: dict[str, Any], rank: int, world_size: int) -> None:
    """Start or resume the run in ``out``: write its ``config.json`` (metadata ``meta``), or check that
    the one there is the same (``ValueError`` otherwise); remove the pieces of this rank's writes
    that a killed run left behind."""
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


def _finished_shards(out: Path, mine: list[int], manifest_path: Path) -> dict[int, dict[str, Any]]:
    """The manifest entries of the shards of ``mine`` already in ``out``: those of this rank's
    manifest whose file exists, and those renamed into place before the manifest was rewritten."""
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
    return done


def _progress_bar(cfg: dict[str, Any], todo: list[int], rank: int) -> Any:
    """A tqdm bar over the items of the shards ``todo``."""
    from tqdm import tqdm  # an optional dependency (the "test" and "pipelines" extras): imported when used

    return tqdm(total=sum(min(cfg["shard_size"], cfg["num_images"] - k * cfg["shard_size"]) for k in todo),
                unit="img" if cfg["clip_length"] == 1 else "clip", desc=f"rank {rank} shards", dynamic_ncols=True)


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
    _open_run(out, _metadata(cfg), rank, world_size)
    mine = [k for k in range(num_shards(cfg)) if k % world_size == rank]
    manifest_path = out / f"manifest_rank{rank:03d}.json"
    done = _finished_shards(out, mine, manifest_path)
    todo = [k for k in mine if k not in done]
    manifest = {"rank": rank, "world_size": world_size, "shards": [done[k] for k in sorted(done)]}
    if todo:
        jobs = _ShardJobs(cfg, out, todo, crash_after_shards)
        loader = torch.utils.data.DataLoader(jobs, batch_size=None, num_workers=workers, shuffle=False,
                                             persistent_workers=False)
        bar = _progress_bar(cfg, todo, rank) if progress else None
        for entry in loader:
            for category, message in entry.pop("warnings"):  # the shard's, at the caller's line (once per text)
                warnings.warn(message, category, stacklevel=2)
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

    def __getitem__(self, index: Any) -> Any:
        raise TypeError("SeaShardDataset streams its shards (an IterableDataset): iterate it (for image, meta in ds) or "
                        "wrap it in a torch.utils.data.DataLoader; it has no ds[i]")

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

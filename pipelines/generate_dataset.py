"""Generate a sea-background dataset: sharded 16-bit sensor images (or clips) + per-image metadata.

The seas are textured by default (``scene.texture = true``: one wave-field realization per image,
its seed and time [s] in the metadata); ``texture = false`` gives the expectation images.
``clip_length = T > 1`` makes clips of T frames at ``frame_rate`` [Hz] from a camera on a
moving platform (ranges in the ``[motion]`` table; ``pipelines/configs/sea_lwir_clips.toml``),
with every frame's time, pose and noise seed in the metadata. Day images: ``scene.daytime`` (the
probability that an image is by day, default 0: all by night) puts the sun in the sky at an
elevation drawn from ``scene.sun_elevation_deg`` and an azimuth from ``scene.sun_azimuth_deg``
(relative to the camera's yaw: 0 is straight ahead, where its glint is); each image's ``is_day``,
sun elevation, zenith and world azimuth are in the metadata (``pipelines/configs/sea_mwir_day.toml``:
MWIR by day, the glint of a low sun ahead). The air: ``scene.air_sea_difference`` (T_air − T_sea [K],
the shipped configs' [-3, 1]) draws each image's air temperature as its sea temperature plus a
difference; ``scene.air_temperature`` draws it on its own (not both); with neither, each atmosphere's
own surface air temperature. Each image's ``air_sea_difference`` is in the metadata.

One process (with DataLoader workers rendering shards in parallel):

    python pipelines/generate_dataset.py --config pipelines/configs/sea_lwir.toml --out data/sea_lwir --workers 2

Several processes or machines (each rank renders shards k ≡ rank mod world size; rank 0 writes
manifest.json when all are done):

    torchrun --nproc_per_node 2 pipelines/generate_dataset.py --config ... --out ...

Interrupted? Run the same command again: finished shards are kept (they were written atomically),
the missing ones are made, and the result is byte-identical to an uninterrupted run. The config
is a TOML file; ``--print-default-config`` shows every key with its default. Read the shards
back with ``roughsea_torch.dataset.SeaShardDataset``.
"""

from __future__ import annotations

import argparse
import os
import sys
import time
import tomllib
from pathlib import Path

import tomli_w
import torch

from roughsea_torch.dataset import DEFAULT_CONFIG, finish, generate, resolve_config


def default_config_toml() -> str:
    """``DEFAULT_CONFIG`` as a TOML file (what ``--config`` reads). TOML has no null: keys whose default
    is "not set" (None) are left out (an omitted key takes its default) and listed in a comment."""
    unset: list[str] = []

    def drop_none(d: dict, prefix: str = "") -> dict:
        out = {}
        for k, v in d.items():
            if v is None:
                unset.append(prefix + k)
            else:
                out[k] = drop_none(v, f"{prefix}{k}.") if isinstance(v, dict) else v
        return out

    body = tomli_w.dumps(drop_none(DEFAULT_CONFIG))
    head = "# roughsea_torch dataset config: every key with its default (python pipelines/generate_dataset.py --print-default-config)\n"
    if unset:
        head += "# not set by default (give a value to set them): " + ", ".join(unset) + "\n"
    if {"scene.air_temperature", "scene.air_sea_difference"} <= set(unset):
        head += ("# the air: scene.air_sea_difference = [low, high] K draws T_air - T_sea (e.g. [-3.0, 1.0], over the open\n"
                 "# sea), scene.air_temperature draws T_air on its own (not both); neither: each atmosphere's own\n")
    return head + "\n" + body


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--config", type=Path, help="TOML config (keys of --print-default-config; omitted keys take the defaults)")
    ap.add_argument("--out", type=Path, help="output directory")
    ap.add_argument("--workers", type=int, default=0, help="DataLoader worker processes per rank (default 0: render in this process)")
    ap.add_argument("--threads", type=int, default=None, help="torch threads per rendering process (default: torch's)")
    ap.add_argument("--num-images", type=int, default=None, help="override the config's num_images (clips, with clip_length > 1)")
    ap.add_argument("--no-progress", action="store_true")
    ap.add_argument("--print-default-config", action="store_true")
    args = ap.parse_args(argv)
    if args.print_default_config:
        print(default_config_toml(), end="")
        return 0
    if args.config is None or args.out is None:
        ap.error("--config and --out are required")
    try:
        config = tomllib.loads(args.config.read_text())
    except (OSError, tomllib.TOMLDecodeError) as e:
        ap.error(f"--config {args.config}: {e}")
    if args.num_images is not None:
        config["num_images"] = args.num_images
    try:
        resolve_config(config)  # every key checked before any work
    except ValueError as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    if args.threads:
        torch.set_num_threads(args.threads)
    world = int(os.environ.get("WORLD_SIZE", "1"))
    rank = int(os.environ.get("RANK", "0"))
    distributed = world > 1
    if distributed:
        torch.distributed.init_process_group("gloo")
    t0 = time.perf_counter()
    manifest = generate(config, args.out, workers=args.workers, rank=rank, world_size=world, progress=not args.no_progress)
    if distributed:
        torch.distributed.barrier()
        if rank == 0:
            finish(args.out)
        torch.distributed.barrier()
        torch.distributed.destroy_process_group()
    n = sum(e["images"] for e in manifest["shards"])
    T = resolve_config(config)["clip_length"]
    what = f"{n} images" if T == 1 else f"{n} clips of {T} frames"
    print(f"rank {rank}/{world}: {len(manifest['shards'])} shards, {what} in {args.out} "
          f"({time.perf_counter() - t0:.1f} s this run)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

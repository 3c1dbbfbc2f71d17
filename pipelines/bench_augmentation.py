"""On-the-fly sea backgrounds: throughput of RandomSeaBackground with the sensor model, its share of
a training step, and the dataset generator's scaling with DataLoader workers.

1. 512×640 float32 batches: images/s of the renderer alone (radiance), of the sensor model alone,
   and of ``RandomSeaBackground`` with ``SensorModel.typical_lwir()`` in replace and composite
   mode (median of ``--repeats`` runs, each timed in this process; ratios against the renderer).
2. The example training loop (``examples/train_segmentation.py``): median augmentation time and
   net step time per step, and the share of a step that sea generation costs, at the example's
   size (128×160) and at 512×640.
3. ``roughsea_torch.dataset.generate`` at 512×640 with 0 (in-process), 1 and 2 DataLoader workers:
   images/s and speed-up over 1 worker (each worker renders whole shards with one torch thread).

Writes ``--out``/bench_augmentation.md and .png.

    python pipelines/bench_augmentation.py [--repeats 5] [--device cpu] [--out docs]
"""

from __future__ import annotations

import argparse
import datetime as dt
import os
import platform
import statistics
import sys
import tempfile
import time
from pathlib import Path

import torch

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "examples"))

from roughsea_torch.augmentation import RandomSeaBackground, render_parameters  # noqa: E402
from roughsea_torch.dataset import generate  # noqa: E402
from roughsea_torch.sensor import SensorModel  # noqa: E402
from train_segmentation import make_augmentation, ship_chips, train  # noqa: E402


def median_time(fn, repeats: int, sync=lambda: None) -> float:
    fn()
    sync()
    ts = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        sync()
        ts.append(time.perf_counter() - t0)
    return statistics.median(ts)


def cpu_name() -> str:
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or "unknown CPU"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--batch", type=int, default=8)
    ap.add_argument("--device", default="cpu")
    ap.add_argument("--gen-images", type=int, default=24, help="images per generator run")
    ap.add_argument("--train-steps", type=int, default=12)
    ap.add_argument("--out", type=Path, default=ROOT / "docs")
    a = ap.parse_args()
    dev = torch.device(a.device)
    sync = (lambda: torch.cuda.synchronize()) if dev.type == "cuda" else (lambda: None)
    B, H, W = a.batch, 512, 640
    machine = (f"{cpu_name()}, {os.cpu_count()} cores, torch {torch.__version__} with {torch.get_num_threads()} threads"
               + (f", GPU {torch.cuda.get_device_name(dev)}" if dev.type == "cuda" else ""))
    lines = [f"# On-the-fly sea backgrounds ({dt.date.today().isoformat()})", "",
             f"Machine: {machine}. Command: `python pipelines/bench_augmentation.py --repeats {a.repeats} --device {a.device}`.", ""]

    # 1. throughput at 512x640
    g = torch.Generator().manual_seed(0)
    aug = RandomSeaBackground(sensor=SensorModel.typical_lwir()).to(dev)
    comp = make_augmentation().to(dev)
    x = torch.zeros(B, 1, H, W, device=dev)
    chips = ship_chips(B, H, W, torch.Generator().manual_seed(1)).to(dev)
    sampler = aug.sampler
    params = sampler.sample(B, torch.Generator().manual_seed(2))
    L = render_parameters(params, H, W, sampler.atmospheres, device=dev)
    sensor = SensorModel.typical_lwir().to(dev)

    def sensor_only():
        for i in range(B):
            sensor(L[i : i + 1], generator=torch.Generator().manual_seed(i))

    rows = [
        ("renderer only (radiance)", lambda: render_parameters(params, H, W, sampler.atmospheres, device=dev)),
        ("sensor model only", sensor_only),
        ("RandomSeaBackground + sensor, replace", lambda: aug(x, generator=g)),
        ("RandomSeaBackground + sensor, composite targets", lambda: comp(chips, generator=g)),
    ]
    times = {}
    with torch.no_grad():
        for name, fn in rows:
            times[name] = median_time(fn, a.repeats, sync)
    base = times[rows[0][0]]
    lines += [f"## 1. Throughput, {B}×{H}×{W} float32 batches on {a.device}", "",
              "| stage | ms per batch | images/s | × renderer |", "|---|---:|---:|---:|"]
    for name, t in times.items():
        lines.append(f"| {name} | {1e3 * t:.0f} | {B / t:.1f} | {t / base:.2f} |")

    # 2. share of a training step
    lines += ["", "## 2. Share of a training step (examples/train_segmentation.py)", "",
              "| image size | batch | augmentation ms/step | net fwd+bwd ms/step | sea generation share |", "|---|---:|---:|---:|---:|"]
    shares = []
    for (h, w) in ((128, 160), (H, W)):
        r = train(a.train_steps, B, h, w, seed=0, log=lambda *_: None)
        ta, tn = statistics.median(r["t_aug"][1:]), statistics.median(r["t_net"][1:])
        shares.append(((h, w), ta, tn))
        lines.append(f"| {h}×{w} | {B} | {1e3 * ta:.0f} | {1e3 * tn:.0f} | {100 * ta / (ta + tn):.0f} % |")

    # 3. generator scaling with DataLoader workers
    cfg = {"seed": 0, "num_images": a.gen_images, "shard_size": 4, "batch_size": 4, "camera": {"height": H, "width": W},
           "scene": {"atmospheres": ["midlatitude_summer", "tropical"]}}
    gen = {}
    for workers in (0, 1, 2):
        with tempfile.TemporaryDirectory() as d:
            t0 = time.perf_counter()
            generate(cfg, d, workers=workers, progress=False)
            gen[workers] = a.gen_images / (time.perf_counter() - t0)
    lines += ["", f"## 3. Dataset generator, {a.gen_images} images of {H}×{W}, shards of 4", "",
              "| DataLoader workers | images/s | × 1 worker |", "|---|---:|---:|"]
    for w_, ips in gen.items():
        label = f"0 (in-process, {torch.get_num_threads()} threads)" if w_ == 0 else f"{w_} (1 thread each)"
        lines.append(f"| {label} | {ips:.2f} | {ips / gen[1]:.2f} |")
    text = "\n".join(lines) + "\n"
    print(text)
    a.out.mkdir(parents=True, exist_ok=True)
    (a.out / "bench_augmentation.md").write_text(text)

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 3, figsize=(13, 3.6))
    names = list(times)
    axes[0].barh(range(len(names)), [B / times[n] for n in names], color="tab:blue")
    axes[0].set_yticks(range(len(names)), [n.replace("RandomSeaBackground", "RSB") for n in names], fontsize=7)
    axes[0].set_xlabel(f"images/s ({H}×{W}, batch {B})")
    labels = [f"{h}×{w}" for (h, w), _, _ in shares]
    axes[1].bar(labels, [1e3 * ta for _, ta, _ in shares], label="sea generation")
    axes[1].bar(labels, [1e3 * tn for _, _, tn in shares], bottom=[1e3 * ta for _, ta, _ in shares], label="net fwd+bwd")
    axes[1].set_ylabel("ms per training step")
    axes[1].legend(fontsize=7)
    axes[2].bar([str(k) for k in gen], list(gen.values()), color="tab:green")
    axes[2].set_xlabel("DataLoader workers (0 = in-process)")
    axes[2].set_ylabel("generator images/s")
    fig.suptitle(f"{machine}", fontsize=7)
    fig.tight_layout()
    fig.savefig(a.out / "bench_augmentation.png", dpi=110)
    print(f"wrote {a.out / 'bench_augmentation.md'} and .png")


if __name__ == "__main__":
    main()

"""On-the-fly sea backgrounds: cost of the sensor model and of RandomSeaBackground against the
renderer, at 1 and 2 threads, on an idle machine and beside a competing process; share of a
training step; the dataset generator's scaling with DataLoader workers.

1. 8×512×640 float32 batches, timed in one run, for 1 and 2 torch threads, each without and with a
   competing busy-loop process (``python -c "while True: pass"``, started here and stopped at the
   end of its block): the renderer alone (radiance; also on the batch's first 2 images, one
   chunk of the renderer), ``SensorModel.typical_lwir()`` alone (one batched call, each image's
   noise from its own seed, as ``RandomSeaBackground`` runs it), the same sensor image by image
   (how it ran before), and ``RandomSeaBackground`` with the sensor in replace and composite mode
   (the example's augmentation: three atmospheres, so three renders of one chunk each). Variants and
   thread counts are timed in turn within each repeat (so that a change of load hits them alike, and
   the thread counts are compared within one run), after ``WARMUP`` calls of each; medians of
   ``--repeats``; ratios against the renderer of the same thread count and load.
2. The example training loop (``examples/train_segmentation.py``): median augmentation time and
   net step time per step, and the share of a step that sea generation costs, at the example's
   size (128×160) and at 512×640.
3. ``roughsea_torch.dataset.generate`` at 512×640 with 0 (in-process), 1 and 2 DataLoader workers:
   images/s and speed-up over 1 worker (each worker renders whole shards with one torch thread).
4. glibc's allocator: the renderer, the sensor and ``RandomSeaBackground`` (replace) on 1 thread in
   child processes started with and without ``MALLOC_MMAP_THRESHOLD_`` and
   ``MALLOC_TRIM_THRESHOLD_`` raised to 4 GiB (freed memory is then kept and reused instead of
   handed back to the system, so a fresh full-size temporary does not page-fault), with the minor
   page faults of one call.

Writes ``--out``/bench_augmentation.md and .png.

    python pipelines/bench_augmentation.py [--repeats 5] [--device cpu] [--out docs]
"""

from __future__ import annotations

import argparse
import datetime as dt
import os
import platform
import statistics
import subprocess
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


WARMUP = 2  # calls of each stage at each thread count before timing


def median_times(fns: dict, repeats: int, sync=lambda: None, threads=(1, 2)) -> dict:
    """Median time [s] of each callable at each thread count, {threads: {name: s}}: the variants and
    thread counts timed in turn within each repeat, after ``WARMUP`` calls each, so that a change
    of machine load hits every variant alike."""
    ts = {n: {name: [] for name in fns} for n in threads}
    for n in threads:
        torch.set_num_threads(n)
        for fn in fns.values():
            for _ in range(WARMUP):
                fn()
                sync()
    for _ in range(repeats):
        for n in threads:
            torch.set_num_threads(n)
            for name, fn in fns.items():
                t0 = time.perf_counter()
                fn()
                sync()
                ts[n][name].append(time.perf_counter() - t0)
    return {n: {name: statistics.median(v) for name, v in t.items()} for n, t in ts.items()}


def busy_process() -> subprocess.Popen:
    """A competing process: one pure-Python busy loop (one core's worth of load), not pinned."""
    return subprocess.Popen([sys.executable, "-c", "while True: pass"])


def cpu_name() -> str:
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or "unknown CPU"


MALLOC_ENV = {"MALLOC_MMAP_THRESHOLD_": "4294967296", "MALLOC_TRIM_THRESHOLD_": "4294967296"}


def malloc_child(repeats: int, B: int, H: int, W: int) -> None:
    """Section 4's child: median time [s] and minor page faults of one call of each stage, 1 thread."""
    import json
    import resource

    torch.set_num_threads(1)
    aug = RandomSeaBackground(sensor=SensorModel.typical_lwir(), texture=False)
    params = aug.sampler.sample(B, torch.Generator().manual_seed(2))
    L = render_parameters(params, H, W, aug.sampler.atmospheres)
    sensor = SensorModel.typical_lwir()
    x = torch.zeros(B, 1, H, W)
    stages = {
        "renderer": lambda: render_parameters(params, H, W, aug.sampler.atmospheres),
        "sensor": lambda: sensor(L, generator=[torch.Generator().manual_seed(i) for i in range(B)]),
        "RandomSeaBackground + sensor, replace": lambda: aug(x, params=aug._params),
    }
    aug(x, generator=torch.Generator().manual_seed(0))
    out = {}
    with torch.no_grad():
        for name, fn in stages.items():
            fn()
            ts, faults = [], []
            for _ in range(repeats):
                f0 = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
                t0 = time.perf_counter()
                fn()
                ts.append(time.perf_counter() - t0)
                faults.append(resource.getrusage(resource.RUSAGE_SELF).ru_minflt - f0)
            out[name] = (statistics.median(ts), statistics.median(faults))
    print(json.dumps(out))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--batch", type=int, default=8)
    ap.add_argument("--height", type=int, default=512)
    ap.add_argument("--width", type=int, default=640)
    ap.add_argument("--device", default="cpu")
    ap.add_argument("--gen-images", type=int, default=24, help="images per generator run")
    ap.add_argument("--train-steps", type=int, default=12)
    ap.add_argument("--out", type=Path, default=ROOT / "docs")
    ap.add_argument("--texture", action=argparse.BooleanOptionalAction, default=True,
                    help="textured seas (RandomSeaBackground's default) or expectation images (--no-texture)")
    ap.add_argument("--malloc-child", action="store_true", help=argparse.SUPPRESS)
    a = ap.parse_args()
    if a.malloc_child:
        malloc_child(a.repeats, a.batch, a.height, a.width)
        return
    dev = torch.device(a.device)
    sync = (lambda: torch.cuda.synchronize()) if dev.type == "cuda" else (lambda: None)
    B, H, W = a.batch, a.height, a.width
    machine = (f"{cpu_name()}, {os.cpu_count()} cores, torch {torch.__version__} with {torch.get_num_threads()} threads"
               + (f", GPU {torch.cuda.get_device_name(dev)}" if dev.type == "cuda" else ""))
    lines = [f"# On-the-fly sea backgrounds ({dt.date.today().isoformat()})", "",
             f"Machine: {machine}. Command: `python pipelines/bench_augmentation.py --repeats {a.repeats} --batch {B} --height {H} --width {W} --device {a.device}{'' if a.texture else ' --no-texture'}`.", ""]

    # 1. sensor and augmentation against the renderer, 1 and 2 threads, without and with load
    threads0 = torch.get_num_threads()
    g = torch.Generator().manual_seed(0)
    aug = RandomSeaBackground(sensor=SensorModel.typical_lwir(), texture=a.texture).to(dev)
    comp = make_augmentation(texture=a.texture).to(dev)
    x = torch.zeros(B, 1, H, W, device=dev)
    chips = ship_chips(B, H, W, torch.Generator().manual_seed(1)).to(dev)
    sampler = aug.sampler
    params = sampler.sample(B, torch.Generator().manual_seed(2))
    L = render_parameters(params, H, W, sampler.atmospheres, device=dev)
    sensor = SensorModel.typical_lwir().to(dev)
    seeds = params["noise_seed"].tolist()

    def sensor_batched():
        sensor(L, generator=[torch.Generator().manual_seed(int(s)) for s in seeds])

    def sensor_looped():
        for i, s in enumerate(seeds):
            sensor(L[i : i + 1], generator=torch.Generator().manual_seed(int(s)))

    small = {k: v[:2] for k, v in params.items()}  # two images: one chunk of the renderer
    stages = {
        "renderer only (radiance)": lambda: render_parameters(params, H, W, sampler.atmospheres, device=dev),
        "renderer only, 2 images (one chunk)": lambda: render_parameters(small, H, W, sampler.atmospheres, device=dev),
        "sensor model only (batched)": sensor_batched,
        "sensor model only, image by image (as before)": sensor_looped,
        "RandomSeaBackground + sensor, replace": lambda: aug(x, generator=g),
        "RandomSeaBackground + sensor, composite targets": lambda: comp(chips, generator=g),
    }
    blocks = []  # (threads, loaded, {stage: seconds})
    loads = []  # the machine's 1-minute load average before and after each block (other users' jobs count)
    with torch.no_grad():
        for loaded in (False, True):
            busy = busy_process() if loaded else None
            try:
                load0 = os.getloadavg()[0]
                times = median_times(stages, a.repeats, sync)
                for threads in (1, 2):
                    blocks.append((threads, loaded, times[threads]))
                    loads.append((load0, os.getloadavg()[0]))
                    print(blocks[-1], flush=True)
            finally:
                if busy is not None:
                    busy.kill()
                    busy.wait()
    torch.set_num_threads(threads0)
    lines += [f"## 1. Sensor and augmentation against the renderer, {B}×{H}×{W} float32 batches on {a.device}", "",
              "Each load is timed in one run: its stages and both thread counts in turn within each repeat, "
              f"after {WARMUP} warm-up calls of each, medians of {a.repeats}. *Competing process*: a busy loop "
              "(`python -c \"while True: pass\"`) running beside "
              "the benchmark.", "",
              f"The load average column is the machine's 1-minute load before → after the run of each load, both "
              f"thread counts together ({os.cpu_count()} cores; other users' jobs count): far above 1 per core, "
              "absolute times are inflated and only the ratios within a load compare.", "",
              "| threads | competing process | load average | stage | ms per batch | images/s | × renderer |",
              "|---:|---|---|---|---:|---:|---:|"]
    for (threads, loaded, times), (l0, l1) in zip(blocks, loads):
        base = times["renderer only (radiance)"]
        for name, t in times.items():
            lines.append(f"| {threads} | {'yes' if loaded else 'no'} | {l0:.1f} → {l1:.1f} | {name} | {1e3 * t:.0f} | "
                         f"{B / t:.1f} | {t / base:.2f} |")
    lines += ["", "2 threads against 1 thread (time at 1 thread / time at 2 threads; above 1: 2 threads faster):", "",
              "| competing process | stage | × speed-up |", "|---|---|---:|"]
    by = {(th, ld): t for th, ld, t in blocks}
    for loaded in (False, True):
        for name in stages:
            lines.append(f"| {'yes' if loaded else 'no'} | {name} | {by[(1, loaded)][name] / by[(2, loaded)][name]:.2f} |")

    # 2. share of a training step
    lines += ["", "## 2. Share of a training step (examples/train_segmentation.py)", "",
              "| threads | image size | batch | augmentation ms/step | net fwd+bwd ms/step | sea generation share |",
              "|---:|---|---:|---:|---:|---:|"]
    shares = []
    for (h, w) in ((128, 160), (H, W)):
        r = train(a.train_steps, B, h, w, seed=0, log=lambda *_: None)
        ta, tn = statistics.median(r["t_aug"][1:]), statistics.median(r["t_net"][1:])
        shares.append(((h, w), ta, tn))
        lines.append(f"| {torch.get_num_threads()} | {h}×{w} | {B} | {1e3 * ta:.0f} | {1e3 * tn:.0f} | {100 * ta / (ta + tn):.0f} % |")

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
    # 4. glibc's allocator: freed memory kept for reuse, or handed back (and page-faulted in again)
    import json

    runs = {}
    for label, extra in (("default", {}), ("thresholds raised", MALLOC_ENV)):
        env = {k: v for k, v in os.environ.items() if k not in MALLOC_ENV}
        child = subprocess.run([sys.executable, __file__, "--malloc-child", "--repeats", str(a.repeats), "--batch", str(B),
                                "--height", str(H), "--width", str(W)], capture_output=True, text=True, check=True,
                               env=dict(env, **extra))
        runs[label] = json.loads(child.stdout.strip().splitlines()[-1])
    lines += ["", f"## 4. glibc's allocator, {B}×{H}×{W}, 1 thread, expectation images", "",
              "Child processes started with glibc's defaults and with `MALLOC_MMAP_THRESHOLD_=4294967296 "
              "MALLOC_TRIM_THRESHOLD_=4294967296` (freed memory kept for reuse instead of handed back to the "
              f"system); medians of {a.repeats}, minor page faults of one call.", "",
              "| stage | default [ms] | page faults | thresholds raised [ms] | page faults | × faster |",
              "|---|---:|---:|---:|---:|---:|"]
    for name in runs["default"]:
        (t0_, f0_), (t1_, f1_) = runs["default"][name], runs["thresholds raised"][name]
        lines.append(f"| {name} | {1e3 * t0_:.0f} | {f0_:.0f} | {1e3 * t1_:.0f} | {f1_:.0f} | {t0_ / t1_:.2f} |")
    text = "\n".join(lines) + "\n"
    print(text)
    a.out.mkdir(parents=True, exist_ok=True)
    (a.out / "bench_augmentation.md").write_text(text)

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 3, figsize=(15, 4.2), gridspec_kw={"width_ratios": [2.2, 1, 1]})
    names = list(stages)
    width = 0.8 / len(blocks)
    for k, (threads, loaded, times) in enumerate(blocks):
        axes[0].barh([i + (k - (len(blocks) - 1) / 2) * width for i in range(len(names))],
                     [1e3 * times[n] for n in names], height=width,
                     label=f"{threads} thread{'s' if threads > 1 else ''}, {'busy loop beside' if loaded else 'no busy loop'}")
    axes[0].set_yticks(range(len(names)), [n.replace("RandomSeaBackground", "RSB") for n in names], fontsize=7)
    axes[0].invert_yaxis()
    axes[0].set_xscale("log")
    axes[0].set_xlabel(f"ms per batch of {B}×{H}×{W} (log scale)")
    axes[0].legend(fontsize=7)
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

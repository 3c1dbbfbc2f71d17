"""Coarse-grained parallelism over independent chunks of work (images, groups of views).

Why not torch's own intra-op parallelism alone: every large torch operation on the CPU is an
OpenMP parallel region whose threads wait for each other at its end. When the cores are shared (a
data loader, another job, the normal case in training), a descheduled thread stalls every region,
and a renderer made of hundreds of operations ran up to 10× slower on 2 threads than on 1
(``pipelines/bench_render.py``). Setting ``OMP_WAIT_POLICY=PASSIVE`` before torch starts softens
this, but a library cannot count on it. Here independent chunks run on worker threads with one
intra-op thread each, so no operation waits for another thread: a slow thread delays only its own
chunks. The chunks are the same whatever the thread count, so results do not depend on it.

Used only on the CPU, with torch's OpenMP backend, when ``torch.get_num_threads() > 1`` and there
are at least two chunks; a lone chunk runs on the calling thread with one intra-op thread, and
otherwise (CUDA, one thread) the chunks run in order on the calling thread. The workers take the
caller's autograd mode and CPU autocast. ``torch.set_num_threads`` is per thread under OpenMP (a worker's setting
does not change the caller's); while a call runs, a thread that starts using torch for the first
time may take the workers' setting of 1 (torch keeps the last value set as the default for new
threads), which the workers restore when their chunk ends.

A lone chunk on one intra-op thread, and :func:`one_thread` for the work around the chunks that is
made of many small operations (an augmentation's scenes, cameras and compositing). Measured with
``pipelines/bench_augmentation.py`` (2 cores, 512×640 float32, 1 and 2 threads alternated): with
torch's second intra-op thread on such work, a render of 2 images (one chunk) ran 1.22× faster
than on one thread on an idle machine but 0.65× as fast beside a busy process, and the example's
compositing augmentation (8 images in three atmosphere groups, one chunk each) 1.16× and 0.63×;
now 0.99× and 0.96×, and 1.10× and 0.96× (``docs/bench_augmentation_before_70b4f89.md``,
``docs/bench_augmentation.md``). Hundreds of parallel regions each wait for a thread that the
other process has descheduled. A render of one chunk runs on one intra-op thread from start to
end (:func:`~roughsea_torch.renderer.render`). A render of several chunks leaves its own
preparation (under 2 ms) at the caller's setting: on one intra-op thread it made the workers'
chunks that followed take 1.1× as long on an idle machine, for a reason not found.
"""

from __future__ import annotations

import threading
from concurrent.futures import ThreadPoolExecutor
from functools import lru_cache
from typing import Any, Callable, Sequence, TypeVar

import torch

__all__ = ["map_chunks", "one_thread", "BLOCK", "in_blocks"]

T = TypeVar("T")
_local = threading.local()
_lock = threading.Lock()
_pools: dict[int, ThreadPoolExecutor] = {}


@lru_cache(maxsize=1)
def _openmp_backend() -> bool:
    return "ATen parallel backend: OpenMP" in torch.__config__.parallel_info()


def _pool(n: int) -> ThreadPoolExecutor:
    with _lock:
        if n not in _pools:
            _pools[n] = ThreadPoolExecutor(n, thread_name_prefix="roughsea")
        return _pools[n]


def map_chunks(fn: Callable[[Any], T], items: Sequence[Any], device: torch.device | str | None) -> list[T]:
    """``[fn(x) for x in items]``, the items spread over ``torch.get_num_threads()`` worker threads
    of one intra-op thread each (see the module docstring for when and why)."""
    n = torch.get_num_threads()
    dev = torch.device(device) if device is not None else torch.device("cpu")
    if dev.type != "cpu" or n <= 1 or len(items) == 0 or getattr(_local, "worker", False) or not _openmp_backend():
        return [fn(x) for x in items]
    if len(items) == 1:  # one chunk: on one intra-op thread (module docstring)
        return [one_thread(lambda: fn(items[0]), dev)]
    grad, inference = torch.is_grad_enabled(), torch.is_inference_mode_enabled()
    # CPU autocast is per thread too: the workers take the caller's (else they would compute in float32
    # what the caller's thread computes in bfloat16, and images would depend on the thread count)
    autocast = torch.is_autocast_enabled("cpu")
    autocast_dtype = torch.get_autocast_dtype("cpu")

    def run(x: Any) -> T:
        _local.worker = True
        # torch sets a thread's OpenMP team size lazily, on its first parallel call, to the last
        # value anyone set; trigger that first, or it would undo the setting below
        torch.get_num_threads()
        torch.set_num_threads(1)
        try:
            with (torch.inference_mode(inference), torch.set_grad_enabled(grad),
                  torch.autocast("cpu", dtype=autocast_dtype, enabled=autocast)):
                return fn(x)
        finally:
            torch.set_num_threads(n)
            _local.worker = False

    return list(_pool(n).map(run, items))


def one_thread(fn: Callable[[], T], device: torch.device | str | None) -> T:
    """``fn()`` with one intra-op thread on the CPU (the caller's setting restored after), for work
    whose few large operations gain little from a second thread on an idle machine and stall on
    shared cores (see the module docstring); elsewhere, or inside a worker, ``fn()`` as it is."""
    n = torch.get_num_threads()
    dev = torch.device(device) if device is not None else torch.device("cpu")
    if dev.type != "cpu" or n <= 1 or getattr(_local, "worker", False) or not _openmp_backend():
        return fn()
    torch.set_num_threads(1)
    try:
        return fn()
    finally:
        torch.set_num_threads(n)


BLOCK = 1 << 15  # points per block of per-point work (:func:`in_blocks`)


def in_blocks(fn: Callable[[int, int], tuple], n: int, block: int = BLOCK) -> tuple:
    """``fn(u, e)`` on the blocks [u, e) of ``n`` points, ``block`` at a time, its outputs (tensors whose last
    axis runs over the block's points) joined along that axis: per-point work done a block at a time keeps
    its temporaries in cache (serially, on the calling thread). The same values as one call on all the
    points when ``fn`` is pointwise; ``n`` = 0 calls ``fn(0, 0)`` once."""
    parts = [fn(u, min(n, u + block)) for u in range(0, max(n, 1), block)]
    return tuple(p[0] if len(p) == 1 else torch.cat(p, -1) for p in zip(*parts))

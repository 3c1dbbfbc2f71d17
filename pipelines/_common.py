"""Helpers shared by the accuracy and stability pipelines (one definition each).

- ``sky``, ``M``: the smooth cold sky and the 11 µm water index of the agreement tests;
- ``CONVERGED``: the converged torch rule that the reports measure errors against (64/64/32 nodes,
  9.5σ window; it agrees with the numpy reference to ~1e-11, checked by ``check_converged``);
- ``f32``: float64 values that float32 holds exactly, so that both dtypes see the same input;
- ``rel_err``, ``median_time``, ``machine``.
"""

from __future__ import annotations

import datetime as dt
import os
import platform
import statistics
import sys
import time
from pathlib import Path
from typing import Any, Callable

import numpy as np
import torch

import roughsea_torch as rs
import roughsea_torch.reference as ref
from roughsea_torch.expectation import Quadrature

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))
from conftest import smooth_sky as sky  # noqa: E402
from conftest import M11 as M  # noqa: E402

CONVERGED = Quadrature(outer=64, inner=64, hermite=32, width=9.5)
SEA_RADIANCE = 30.0  # R_B [W m-2 sr-1] of the accuracy cases (the smooth sky reaches it at the horizon)

__all__ = ["sky", "M", "CONVERGED", "SEA_RADIANCE", "f32", "radians", "slopes", "rel_err", "median_time", "machine", "check_converged"]


def f32(x: Any) -> torch.Tensor:
    """float64 tensor of the values float32 holds (the inputs every dtype sees identically)."""
    return torch.as_tensor(np.asarray(x, dtype=np.float64)).float().double()


def slopes(vx: torch.Tensor, vy: torch.Tensor, cxy: torch.Tensor, dtype: torch.dtype) -> rs.SlopeStatistics:
    return rs.SlopeStatistics.from_variances(vx.to(dtype), vy.to(dtype), cxy.to(dtype))


def rel_err(x: torch.Tensor, reference: torch.Tensor) -> torch.Tensor:
    """|x − ref| / |ref| in float64 (elementwise)."""
    x, reference = x.detach().double(), reference.detach().double()
    return (x - reference).abs() / reference.abs()


def median_time(fn: Callable[[], Any], repeats: int, warmup: int = 1) -> float:
    """Median wall time [s] of ``repeats`` calls after ``warmup`` calls, in this process."""
    for _ in range(warmup):
        fn()
    ts = []
    for _ in range(max(1, repeats)):
        t0 = time.perf_counter()
        fn()
        ts.append(time.perf_counter() - t0)
    return statistics.median(ts)


def machine() -> str:
    """One line: OS/kernel, CPU model, cores, torch threads, versions, date."""
    cpu = platform.processor() or platform.machine()
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    u = platform.uname()
    return (f"{u.system} {u.release} {u.machine}; CPU {cpu}, {os.cpu_count()} cores; torch {torch.__version__} "
            f"with {torch.get_num_threads()} thread(s); numpy {np.__version__}; Python {platform.python_version()}; "
            f"{dt.datetime.now().astimezone().strftime('%Y-%m-%d %H:%M %Z')}")


def check_converged(th: torch.Tensor, ph: torch.Tensor, vx: torch.Tensor, vy: torch.Tensor, cxy: torch.Tensor,
                    shadowing: bool = True, sky: Any = sky, quadrature: Quadrature = CONVERGED) -> tuple[float, float]:
    """Worst relative difference (ε̄, R_a) between a torch rule (``CONVERGED``, float64) and the numpy
    reference (nested adaptive quadrature, epsrel 1e-10, breakpoints at a sky table's nodes) at the
    given float64 points. ``sky``: a callable or a :class:`~roughsea_torch.TabulatedSky`."""
    s = slopes(vx, vy, cxy, torch.float64)
    e_t = rs.emissivity(th, ph, s, M, shadowing=shadowing, quadrature=quadrature)
    r_t = rs.apparent_radiance(th, ph, s, M, sea_radiance=SEA_RADIANCE, sky=sky, shadowing=shadowing, quadrature=quadrature)
    sky_ref = (sky.zenith.double().numpy(), sky.radiance.double().numpy()) if isinstance(sky, rs.TabulatedSky) else sky
    a, b = vx.sqrt(), vy.sqrt()
    r = torch.where(a * b > 0, cxy / (a * b).clamp_min(1e-300), torch.zeros_like(a))
    e_r, r_r = [], []
    for i in range(th.numel()):
        sr = ref.SlopeStatistics(float(a[i]), float(b[i]), float(r[i]))
        e_r.append(float(ref.emissivity(float(th[i]), float(ph[i]), sr, M, shadowing=shadowing)))
        r_r.append(float(ref.apparent_radiance(float(th[i]), float(ph[i]), sr, M, SEA_RADIANCE, sky_ref, shadowing=shadowing)))
    de = float(rel_err(e_t, torch.tensor(e_r, dtype=torch.float64)).max())
    dr = float(rel_err(r_t, torch.tensor(r_r, dtype=torch.float64)).max())
    return de, dr


def radians(deg: Any) -> torch.Tensor:
    return torch.as_tensor(np.radians(np.asarray(deg, dtype=np.float64)))


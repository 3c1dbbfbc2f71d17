"""The table renderer's per-pixel coordinates, computed in place in a reused per-thread workspace.

Why: on the CPU every fresh full-size temporary (5 MB for 4 images of 512×640 in float32) is new
memory from the system, and its first touch costs a page fault per 4 kB page; in the renderer's
chain of ~25 full-size operations per chunk that cost exceeded the arithmetic (an add measured
0.4 ms into reused memory and 1.6–2.5 ms into fresh memory; ``pipelines/bench_render.py``). Here the
chain from the camera's rays to the ``grid_sample`` grid runs in place in six planes that a thread
keeps between calls, as the CUDA caching allocator keeps device memory: one workspace per thread,
replaced when the chunk's shape, dtype or device changes (so it holds at most six (b, H, W) planes
of the last chunk rendered on that thread: 31 MB for chunks of 4 images of 512×640 in float32;
:func:`release_workspace` frees them all).

Only on the CPU, and only where no gradient flows through the pixels' coordinates (neither the
cameras' pose and intrinsics nor the per-image maps, e.g. through ``wind_direction``; or grad mode
is off): in-place operations would otherwise overwrite what autograd saved, and ``out=`` does not
record gradients. The grid passed to ``grid_sample`` is fresh memory when the table itself requires grad
(``grid_sample`` saves the grid for the table's gradient). The formulas are those of the general
path in :mod:`roughsea_torch.renderer.table` (the same table coordinates to rounding).
"""

from __future__ import annotations

import threading
from typing import Any

import torch

from ..geometry import CameraGeometry, ray_component, turned_axes

__all__ = ["release_workspace"]

_lock = threading.Lock()
_spaces: dict[int, tuple[tuple, torch.Tensor]] = {}  # thread id → (key, planes)
_PLANES = 6


def _workspace(b: int, H: int, W: int, dtype: torch.dtype, device: torch.device) -> torch.Tensor:
    """(6, b, H, W) uninitialized planes, the calling thread's, reused across calls of the same key."""
    key = (b, H, W, dtype, device, torch.is_inference_mode_enabled())
    tid = threading.get_ident()
    with _lock:
        ws = _spaces.get(tid)
        if ws is not None and ws[0] == key:
            return ws[1]
        _spaces.pop(tid, None)  # free the old planes before taking the new ones
    with torch.no_grad():
        planes = torch.empty(_PLANES, b, H, W, dtype=dtype, device=device)
    with _lock:
        _spaces[tid] = (key, planes)
        alive = {t.ident for t in threading.enumerate()}
        for t in [t for t in _spaces if t not in alive]:  # threads that have ended hold none
            del _spaces[t]
    return planes


def release_workspace() -> None:
    """Free the renderer's per-thread workspaces (six (b, H, W) planes per thread that rendered, of
    the last chunk shape it rendered). Memory only: results never depend on it."""
    with _lock:
        _spaces.clear()


def table_grid(cg: CameraGeometry, sl: slice, xy: tuple[torch.Tensor, torch.Tensor], c1: torch.Tensor,
               sh: torch.Tensor, sea_map: tuple[torch.Tensor, torch.Tensor],
               sky_map: tuple[torch.Tensor, torch.Tensor] | None, az: dict[str, Any] | None,
               fresh_grid: bool) -> tuple[torch.Tensor, torch.Tensor]:
    """The ``grid_sample`` grid (b, H, W, 2) of the table renderer for the cameras ``sl`` and the sea
    mask as 1/0 in the image dtype (b, H, W), computed in place.

    ``xy``: :meth:`CameraGeometry.separable_xy`. Per image (each (b, 1, 1)): ``c1`` = k_r/ε (1/ε for a
    flat sea) and ``sh`` the sine of the horizon dip (0 flat), so that (cos θ̂/ε)² = c1² (dz² − sh²);
    ``sea_map`` = (k, b), gy = b + k ζ for sea pixels, ζ = asinh(cos θ̂/ε); ``sky_map`` = (k, b),
    gy = b + k dz for sky pixels (None: no pixel sees sky); ``az`` None (isotropic: gx = 0) or
    {"offset": (b,), "k": , "b": , "fold": bool}, gx = b + k u with u the azimuth ratio of
    :func:`roughsea_torch.renderer.coordinates.azimuth_ratio`. The mask is workspace memory: valid until the
    thread's next call.
    """
    x, y = xy
    b_ = x.shape[0]
    ws = _workspace(b_, cg.H, cg.W, cg.dtype, cg.device)
    P0, P1, seaf, P3 = ws[0], ws[1], ws[2], ws[3]
    G = torch.empty(b_, 2, cg.H, cg.W, dtype=cg.dtype, device=cg.device) if fresh_grid else ws[4:].transpose(0, 1)
    gx, gy = G[:, 0], G[:, 1]
    A = cg.axes_cam[sl]
    # z = c1 dz, dz the unit ray's local-vertical component (c1 folded into the axis: no extra pass)
    torch.add(x * x, y * y + 1.0, out=P0).rsqrt_()
    z = ray_component((c1[:, :, 0] * A[:, 2])[:, :, None, None], x, y, P0, out=P1)
    ch = c1 * sh
    torch.lt(z, -ch, out=seaf)
    # ζ = asinh √q = ½ log(2q + 1 + 2√(q² + q)), q = z² − (c1 sh)², held at a tiny q > 0 off the
    # sea; √v as v·rsqrt(v) (torch's sqrt costs 1.7× rsqrt on the CPU). (Ops with two broadcast
    # (b, 1, 1) operands are slow on the CPU: each affine map is a mul_ and an add_.)
    torch.addcmul(-ch * ch, z, z, out=gy).clamp_min_(1e-30)
    torch.addcmul(gy, gy, gy, out=gx)
    gx.mul_(torch.rsqrt(gx, out=P3))
    gy.add_(gx).mul_(2.0).add_(1.0).log_()
    gy.mul_(0.5 * sea_map[0]).add_(sea_map[1])
    if sky_map is not None:  # sky pixels: by dz = z / c1; lerp by a weight of 0 or 1 is an exact select
        torch.mul(z, sky_map[0] / c1, out=gx).add_(sky_map[1])
        torch.lerp(gx, gy, seaf, out=gy)
    if az is None:
        gx.zero_()
    else:  # the ray's components along the world axes turned by −offset (unnormalized)
        A_t = turned_axes(A, az["offset"])
        c, s = (ray_component(A_t[:, i, :, None, None], x, y, None, out=o) for i, o in ((0, P0), (1, gx)))
        if az["fold"]:  # u = |c| / (|c| + |s|)
            c.abs_()
            s.abs_().add_(c).clamp_min_(1e-30)
            torch.div(c, s, out=gx)
            k = az["k"]
        else:  # u = −c sign s / (|c| + |s|) (sign +1 at s = +0): gx holds −u, and k changes sign
            torch.abs(s, out=P3)
            torch.copysign(torch.ones((), dtype=s.dtype, device=s.device), s, out=s).mul_(c)
            c.abs_().add_(P3).clamp_min_(1e-30)
            s.div_(c)
            k = -az["k"]
        gx.mul_(k).add_(az["b"])
    return G.permute(0, 2, 3, 1), seaf

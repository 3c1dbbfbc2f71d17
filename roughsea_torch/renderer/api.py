"""The renderer's user API: :func:`render` (kornia cameras + a :class:`~roughsea_torch.renderer.scene.SeaScene`
→ infrared images (B, 1, H, W)) and its ``nn.Module`` form :class:`SeaRenderer`.

Sea pixels get the apparent radiance of Eq. 10 at their own view angles (θ̂, φ̂); sky pixels get
the sky radiance along their own ray. Two methods:

- ``method="table"`` (default, :mod:`~roughsea_torch.renderer.table`): per image, the model is
  evaluated only over the view angles its sea pixels span, at Chebyshev–Lobatto nodes in
  ζ = asinh(cos θ̂ / ε) and, for anisotropic slopes, in the relative azimuth, resampled to one fine
  table per image that also holds the path per row and the sky along the sky pixels' rays; each
  pixel then costs its ray, its table coordinates and one bilinear ``grid_sample``. Within a few
  1e-6 relative of the direct evaluation (``tests/renderer/test_table.py``).
- ``method="direct"`` (:mod:`~roughsea_torch.renderer.direct`): ``apparent_radiance``, the path
  and the sky at every pixel (the baseline; slow).

What a scene does not need is left out: no sky work when no pixel sees sky; no azimuth dimension
when the slopes are isotropic; no path rows without a path; table nodes only over the angles the
sea pixels span; no autograd graph when nothing requires grad; per-pixel temporaries for ``chunk``
images at a time (``pipelines/bench_render.py`` measures each).
"""

from __future__ import annotations

import numpy as np
import torch
from kornia.geometry.camera import PinholeCamera

from .._parallel import one_thread
from ..expectation import Quadrature
from ..geometry import EARTH_RADIUS_M, CameraGeometry, ViewGeometry
from .direct import render_direct
from .horizon import blend_horizon
from .plan import make_plan
from .scene import SeaScene
from .settings import TableSize, images_per_chunk
from .table import render_table

__all__ = ["render", "SeaRenderer"]


def render(
    cameras: PinholeCamera,
    scene: SeaScene,
    *,
    earth_radius_m: float = EARTH_RADIUS_M,
    method: str = "table",
    output: str = "radiance",
    table: TableSize = TableSize(),
    quadrature: Quadrature | None = None,
    geometry: ViewGeometry | None = None,
    chunk: int | None = None,
    horizon: str = "area",
) -> torch.Tensor:
    """Render infrared images of the sea seen by a batch of kornia cameras.

    Args:
        cameras: ``kornia.geometry.camera.PinholeCamera`` (B cameras, one image size); see
            :func:`~roughsea_torch.geometry.make_camera`.
        scene: :class:`SeaScene` with fields of shape () or (B,).
        earth_radius_m: R [m]; ``float('inf')`` for a flat sea.
        method: ``"table"`` (default) or ``"direct"`` (per-pixel evaluation, the baseline).
        output: ``"radiance"`` [W m⁻² sr⁻¹] or ``"brightness_temperature"`` [K] in the scene's band.
        table: node counts of the table method.
        quadrature: accuracy control of the model (default for the dtype).
        geometry: a precomputed :func:`view_geometry` of these cameras (reused across scenes).
        chunk: images whose per-pixel temporaries are held at once (memory bound; results do not
            depend on it), an int ≥ 1 (else a ``ValueError``); default 4, and 1 for textured scenes
            (``seed=``), whose per-pixel work holds a dozen more full-size temporaries.
        horizon: ``"area"`` (default): a pixel the horizon crosses reads the mix of sea and sky
            weighted by the areas of its square below and above the horizon
            (:mod:`~roughsea_torch.renderer.horizon`); ``"centre"``: every pixel what its centre
            ray sees (a one-pixel step at the horizon). Sea masks (``view_geometry``) stay by the
            centre ray either way.

    Returns:
        (B, 1, H, W) tensor in the cameras' dtype and device; differentiable with respect to every
        tensor of the scene and of the cameras' pose.
    """
    if chunk is not None:
        if isinstance(chunk, bool) or not isinstance(chunk, (int, np.integer)) or chunk < 1:
            raise ValueError(f"chunk must be None or an int in [1, inf) (images per chunk); got {chunk!r}")
        chunk = int(chunk)
    # a render of one chunk (a small batch) on one intra-op thread, its preparation included: with
    # torch's second thread its many small operations ran 0.5-0.9x as fast beside a busy process
    # (roughsea_torch._parallel); larger batches spread their chunks over worker threads instead
    def call() -> torch.Tensor:
        return _render(cameras, scene, earth_radius_m=earth_radius_m, method=method, output=output, table=table,
                       quadrature=quadrature, geometry=geometry, chunk=chunk, horizon=horizon)

    ref = geometry.cos_view_zenith if geometry is not None else getattr(cameras, "intrinsics", None)
    per_chunk = images_per_chunk(scene, chunk)
    if (method == "table" and isinstance(ref, torch.Tensor) and ref.ndim > 0 and isinstance(per_chunk, int)
            and ref.shape[0] <= per_chunk):
        return one_thread(call, ref.device)
    return call()



def _render(cameras: PinholeCamera, scene: SeaScene, *, earth_radius_m: float, method: str, output: str,
            table: TableSize, quadrature: Quadrature | None, geometry: ViewGeometry | None, chunk: int | None,
            horizon: str = "area") -> torch.Tensor:
    """:func:`render`'s body: checks, the scene's per-image values, the method, the horizon's pixels."""
    if method not in ("table", "direct"):
        raise ValueError(f"method must be 'table' or 'direct'; got {method!r}")
    if horizon not in ("area", "centre"):
        raise ValueError(f"horizon must be 'area' or 'centre'; got {horizon!r}")
    chunk = images_per_chunk(scene, chunk)
    if output not in ("radiance", "brightness_temperature"):
        raise ValueError(f"output must be 'radiance' or 'brightness_temperature'; got {output!r}")
    brightness = output == "brightness_temperature"
    cg = None
    if geometry is not None:
        B, H, W = geometry.is_sea.shape
        dtype, device = geometry.cos_view_zenith.dtype, geometry.cos_view_zenith.device
    else:
        cg = CameraGeometry(cameras, earth_radius_m)
        B, H, W, dtype, device = cg.batch_size, cg.H, cg.W, cg.dtype, cg.device
    p = scene.resolved(B, dtype, device)
    q = quadrature or Quadrature.default(dtype)
    if geometry is not None:
        altitude, radius = geometry.altitude_m, getattr(geometry, "earth_radius_m", earth_radius_m)
    else:
        altitude, radius = cg.alt.to(dtype), earth_radius_m
    if method == "direct":
        img = render_direct(cameras, geometry, scene, p, q, earth_radius_m, brightness, table)
    else:
        plan = make_plan(cg, geometry, B, H, W, dtype, device, p, scene, q, table, chunk, altitude, radius, brightness)
        img = render_table(plan)[:, None]
    if horizon == "centre" or not isinstance(cameras, PinholeCamera):
        return img
    cg = cg if cg is not None else CameraGeometry(cameras, radius)
    return blend_horizon(img, cg, scene.band if brightness else None)


class SeaRenderer(torch.nn.Module):
    """``nn.Module`` form of :func:`render`: holds the settings, ``forward(cameras, scene)``."""

    def __init__(
        self,
        earth_radius_m: float = EARTH_RADIUS_M,
        method: str = "table",
        output: str = "radiance",
        table: TableSize = TableSize(),
        quadrature: Quadrature | None = None,
        horizon: str = "area",
    ):
        super().__init__()
        self.horizon = horizon
        self.earth_radius_m = earth_radius_m
        self.method = method
        self.output = output
        self.table = table
        self.quadrature = quadrature

    def forward(self, cameras: PinholeCamera, scene: SeaScene) -> torch.Tensor:
        return render(
            cameras, scene, earth_radius_m=self.earth_radius_m, method=self.method, output=self.output,
            table=self.table, quadrature=self.quadrature, horizon=self.horizon,
        )

    def extra_repr(self) -> str:
        return f"earth_radius_m={self.earth_radius_m}, method={self.method!r}, output={self.output!r}, table={self.table}, horizon={self.horizon!r}"


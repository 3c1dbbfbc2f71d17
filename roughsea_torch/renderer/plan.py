"""What a table render needs, decided once before any per-image work: :class:`RenderPlan`.

The plan names which terms are on (texture, sun and glint, the scattered day sky, foam, the path),
how the tables are laid out (the ζ scale ε, whether the azimuth coordinate is folded, its period,
whether pixels read it through the cheap ratio stand-in) and the node sets of the tables. The table
method (:mod:`roughsea_torch.renderer.table`) runs its stages over it.

A new radiance term: a module of this package that computes it (at the nodes, on the fine table or
per pixel), a flag here saying when it is on, and one call in the stage of
:mod:`~roughsea_torch.renderer.table` where it belongs.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np
import torch

from ..expectation import Quadrature
from ..geometry import CameraGeometry, ViewGeometry
from .coordinates import camera_spans
from .path import check_path_altitude
from .scene import SceneParameters, SeaScene
from .settings import FINE_OVERHANG, TableSize
from .sky_terms import DaySky, day_sky
from .spectral import lobatto_interp
from .texture import TextureTable

__all__ = ["RenderPlan", "make_plan"]


@dataclass
class RenderPlan:
    """The settings and decisions of one table render of B images of H × W pixels.

    Inputs: ``scene`` and its per-image values ``p``; the cameras' geometry ``cameras`` (None when
    the caller gave a precomputed per-pixel ``geometry``); the model's ``quadrature``; ``table`` (the
    node counts, after the day sky's extra nodes for views with every azimuth); ``chunk`` images per
    chunk of pixels; ``altitude`` (B,) [m]; ``earth_radius_m``; ``brightness`` (kelvin out).

    Terms: ``textured`` (a wave realization, :mod:`~roughsea_torch.renderer.texture`), ``sunny`` (a
    sun: glint per pixel and its disk), ``day`` (the scattered day sky, or None), foam and path as
    the scene has them (``p.foam``, ``scene.path``).

    Layout: ``iso`` (isotropic slopes: no azimuth dimension), ``fold`` (uncorrelated slopes and no
    day sky: the folded azimuth ψ ∈ [0, π/2]), ``period`` (π, or 2π under a day sky) of the unfolded
    coordinate, ``ratio`` (pixels read the azimuth through :func:`~roughsea_torch.renderer.coordinates.azimuth_ratio`),
    ``eps`` (B,) float64 and ``inv_eps`` (B,) in the render's dtype, the ζ scale; ``thin`` (some
    image's slope ellipse is thin). Nodes: ``nz``, ``nphi`` (the mean table's), Chebyshev–Lobatto
    nodes ``xz``/``xp`` (numpy, [−1, 1]) with their fine resampling matrices ``Lz``/``Lp`` and
    overhangs ``ez``/``ep``; the fine table has ``Mz`` sea rows at coordinates ``y_z`` and ``Ms`` sky
    rows (overhang ``es``). Texture: ``nphi_tex`` azimuth nodes ``xp_tex`` and its volume ``texture``.
    """

    scene: SeaScene
    p: SceneParameters
    cameras: CameraGeometry | None
    geometry: ViewGeometry | None
    B: int
    H: int
    W: int
    dtype: torch.dtype
    device: torch.device
    quadrature: Quadrature
    table: TableSize
    chunk: int
    altitude: torch.Tensor
    earth_radius_m: float
    brightness: bool
    textured: bool
    sunny: bool
    day: DaySky | None
    iso: bool
    fold: bool
    period: float
    ratio: bool
    eps: torch.Tensor
    inv_eps: torch.Tensor
    thin: bool
    nz: int
    nphi: int
    xz: np.ndarray
    xz_t: torch.Tensor
    Lz: torch.Tensor
    ez: float
    xp: np.ndarray | None
    xp_t: torch.Tensor | None
    Lp: torch.Tensor | None
    ep: float | None
    Mz: int
    Ms: int
    N: int
    es: float
    y_z: torch.Tensor
    nphi_tex: int | None = None
    xp_tex: torch.Tensor | None = None
    texture: TextureTable | None = None


def make_plan(cameras: CameraGeometry | None, geometry: ViewGeometry | None, B: int, H: int, W: int,
              dtype: torch.dtype, device: torch.device, p: SceneParameters, scene: SeaScene, quadrature: Quadrature,
              table: TableSize, chunk: int, altitude: torch.Tensor, earth_radius_m: float, brightness: bool) -> RenderPlan:
    """The :class:`RenderPlan` of a table render (its arguments as :class:`RenderPlan`'s fields).

    Raises ``ValueError`` for a camera altitude the path tables do not cover, and for a sunny or
    textured scene given a precomputed ``geometry`` instead of cameras."""
    # a textured sea's clutter depends on the view's azimuth through the resolved waves' anisotropy
    # (and is not even in it): the table then keeps an unfolded azimuth dimension
    textured = scene.seed is not None
    sunny = scene.sun is not None  # the glint is per pixel, and needs the rays' azimuths
    iso = not (textured or sunny) and bool(((p.vx == p.vy) & (p.cxy == 0)).all())
    # Uncorrelated anisotropic slopes (Cox–Munk): the table runs over the folded azimuth ψ ∈ [0, π/2].
    # R_a is even in φ̂ there, and as a → 0 (or b → 0) it has a kink at φ̂ = 0 (π/2), where the
    # rms slope along the view, √(a² cos²φ̂ + b² sin²φ̂), → b |sin φ̂|: folded, the kink sits at an
    # end of the node interval instead of inside it, where Chebyshev nodes cannot resolve it.
    day = day_sky(scene, B, dtype, device)  # a day sky is not symmetric about the wind: no folding
    fold = not iso and day is None and bool((p.cxy == 0).all())
    # nor under a half turn (R_a(φ̂ + π) ≠ R_a(φ̂)): its unfolded coordinate runs over 2π
    period = 2 * math.pi if day is not None else math.pi
    # ε: a quarter of the smallest rms slope of each image, so ζ resolves the grazing layer.
    lam_min = 0.5 * (p.vx + p.vy - torch.sqrt((p.vx - p.vy) ** 2 + 4 * p.cxy ** 2))
    eps = (0.25 * torch.sqrt(lam_min.detach().clamp_min(0.0))).clamp(1e-4, 0.05).double()
    inv_eps = (1.0 / eps).to(dtype)
    if day is not None and cameras is not None:
        table = _day_nodes_for_every_azimuth(cameras, p, inv_eps, table)
    lam_max = 0.5 * (p.vx + p.vy + torch.sqrt((p.vx - p.vy) ** 2 + 4 * p.cxy ** 2))
    thin = bool((lam_min.detach() < 0.04 * lam_max.detach()).any())  # minor/major rms slope < 0.2
    narrow = bool((lam_min.detach() < 0.25 * lam_max.detach()).any())  # minor/major rms slope < 0.5
    nz = (max(table.zenith, table.zenith_thin) if thin else max(table.zenith, table.zenith_narrow) if narrow
          else table.zenith)
    nphi = 1 if iso else max(table.azimuth, table.azimuth_thin) if thin else table.azimuth
    if day is not None:
        nphi = max(nphi, table.azimuth_day)
    xz, Lz, ez = lobatto_interp(nz, table.fine_zenith)
    xp = Lp_t = ep = xp_t = None
    if not iso:
        xp, Lp, ep = lobatto_interp(nphi, max(table.fine_azimuth, table.fine_azimuth_thin) if thin else table.fine_azimuth)
        xp_t = torch.as_tensor(xp, dtype=torch.float64, device=device)
        Lp_t = torch.as_tensor(Lp, dtype=dtype, device=device)
    Mz, Ms = table.fine_zenith, table.fine_sky
    if scene.path is not None:
        check_path_altitude(scene.path, altitude)
    # the table's azimuth coordinate: from cameras, without texture (whose own table reads the angle),
    # the cheap u of azimuth_ratio, the fine columns uniform in u; else the angle
    ratio = not (iso or textured) and geometry is None and day is None
    if sunny and cameras is None:
        raise ValueError("geometry=: a scene with a sun needs the cameras (its glint and disk are per pixel, the "
                         "disk sized by the pixel's field of view); call render(cameras, scene) without geometry=")
    plan = RenderPlan(
        scene=scene, p=p, cameras=cameras, geometry=geometry, B=B, H=H, W=W, dtype=dtype, device=device,
        quadrature=quadrature, table=table, chunk=chunk, altitude=altitude, earth_radius_m=earth_radius_m,
        brightness=brightness, textured=textured, sunny=sunny, day=day, iso=iso, fold=fold, period=period, ratio=ratio,
        eps=eps, inv_eps=inv_eps, thin=thin, nz=nz, nphi=nphi, xz=xz,
        xz_t=torch.as_tensor(xz, dtype=torch.float64, device=device), Lz=torch.as_tensor(Lz, dtype=dtype, device=device),
        ez=ez, xp=xp, xp_t=xp_t, Lp=Lp_t, ep=ep, Mz=Mz, Ms=Ms, N=Mz + Ms,
        es=2.0 * FINE_OVERHANG / (Ms - 1 - 2 * FINE_OVERHANG),
        y_z=torch.linspace(-1.0 - ez, 1.0 + ez, Mz, dtype=torch.float64, device=device))
    if textured:
        if cameras is None:
            raise ValueError("geometry=: a textured scene (seed=...) needs the cameras (it places waves in the world); "
                             "call render(cameras, scene) without geometry=")
        # by day the mean takes TableSize.azimuth_day azimuth nodes for the scattered sky; the texture's
        # departures from it need fewer (TableSize.texture_azimuth_sun), on the same span
        plan.nphi_tex = min(nphi, int(table.texture_azimuth_sun)) if day is not None else nphi
        plan.xp_tex = torch.as_tensor(lobatto_interp(plan.nphi_tex, int(table.fine_texture_azimuth))[0],
                                      dtype=torch.float64, device=device)
        plan.texture = TextureTable(table, plan.nphi_tex, scene, p, cameras, quadrature, altitude, earth_radius_m, eps,
                                    dtype, device)
    return plan


def _day_nodes_for_every_azimuth(cameras: CameraGeometry, p: SceneParameters, inv_eps: torch.Tensor,
                                 table: TableSize) -> TableSize:
    """``table`` with more azimuth nodes and columns where some image has every azimuth in view.

    An image with every azimuth in view (looking down at the nadir; every image with span="full")
    spreads the day sky's azimuth structure (the aureole about the sun) over the whole turn: twice the
    mean's azimuth nodes and columns, four times the texture's nodes and columns, for the whole render
    (so an image's pixels then depend on whether such an image shares its batch, by up to ~1e-3 K;
    ``docs/notes/table_size.md``)."""
    turn = table.span == "full"
    if not turn:
        B = p.batch_size
        rg_all = camera_spans(cameras, slice(0, B), p.wind_direction, inv_eps, False, False, 2 * math.pi)
        turn = bool((((rg_all.azimuth[1] - rg_all.azimuth[0]) > math.pi) & rg_all.any_sea).any())
    if turn:
        table = replace(table, azimuth_day=2 * (table.azimuth_day - 1) + 1, fine_azimuth=2 * table.fine_azimuth,
                        texture_azimuth_sun=4 * (table.texture_azimuth_sun - 1) + 1,
                        fine_texture_azimuth=4 * table.fine_texture_azimuth)
    return table

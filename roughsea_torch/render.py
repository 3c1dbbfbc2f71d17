"""Sea scenes and the renderer: kornia cameras + scenes → infrared radiance images (B, 1, H, W).

Sea pixels get the apparent radiance of Eq. 10 at their own view angles (θ̂, φ̂); sky pixels get
the sky radiance along their own ray. Two methods:

- ``method="table"`` (default): per image, the model is evaluated only over the view angles its sea
  pixels span, at Chebyshev–Lobatto nodes in ζ = asinh(cos θ̂ / ε) (ε ~ the rms slope, so the
  boundary layer at the horizon, where R_a changes fastest, is resolved) and, for anisotropic
  slopes only, in the relative azimuth. The two sea-temperature-free integrals (T_s, T_ρ) of
  :func:`~roughsea_torch.expectation.reflection_terms` are resampled spectrally to a fine uniform
  table and read per pixel by one bilinear ``torch.nn.functional.grid_sample``; the pixel value is
  R_B (1 − T_ρ) + T_s. Accuracy: within 2e-5 relative of the direct evaluation, horizon rows
  included (``tests/test_render.py``).
- ``method="direct"``: ``apparent_radiance`` at every sea pixel (the baseline; slow).

What a scene does not need is left out (measured by ``pipelines/bench_render.py``): no sky work
when no pixel sees sky; no azimuth dimension (and no per-pixel azimuth) when the slopes are
isotropic; table nodes only over the angles the sea pixels span; no autograd graph when nothing
requires grad; per-pixel temporaries for ``chunk`` images at a time (a batch of 64 512×640 images
fits in a few times its output).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache
from typing import Any, Callable

import numpy as np
import torch
import torch.nn.functional as F
from kornia.geometry.camera import PinholeCamera

from ._validation import check_finite_range, per_batch
from .expectation import Quadrature, _reflection_terms, apparent_radiance
from .geometry import EARTH_RADIUS_M, CameraGeometry, ViewGeometry, view_geometry
from .optics import band_refractive_index, split_refractive_index
from .radiometry import LWIR, SpectralBand, as_band, band_radiance, brightness_temperature
from .sky import ConstantSky, TabulatedSky, as_sky, select_sky
from .slopes import SlopeStatistics

__all__ = ["SeaScene", "render", "SeaRenderer", "TableSize"]


class SeaScene:
    """What is in front of the cameras, one value per image (floats or tensors of shape (B,)).

    Args:
        slopes: explicit :class:`SlopeStatistics` (fields of shape () or (B,)); or
        wind_speed: W [m s⁻¹] at 12.5 m → Cox–Munk slopes (``anisotropic`` selects the law).
        wind_direction: world azimuth of the upwind axis x_s [rad] (from +x towards +y).
        sea_temperature: T_sea [K] → R_B = band radiance; or
        sea_radiance: R_B [W m⁻² sr⁻¹] directly.
        band: sensor band (λ_lo, λ_hi) [m] or :class:`~roughsea_torch.radiometry.SpectralBand`.
        response: relative spectral response (see ``SpectralBand``).
        sky: sky radiance: callable of cos(zenith), (zenith, radiance) table, ``TabulatedSky``
            (radiance (Nz,) or one table per image (B, Nz)), constant or (B,) tensor, or the name
            of a shipped LOWTRAN7 atmosphere (``"midlatitude_summer"``, the default).
        refractive_index: sea index n + i k; default: water (Hale & Querry) averaged over the band
            with Planck(T_sea) × response weights (the paper's choice).
        shadowing: Eq. 5 (True) or Eq. 7.
        path: the air between sea and sensor: radiance at the sensor = τ · R_a + L_path per sea pixel,
            from its slant range and the camera's altitude (``roughsea_torch.atmosphere.load_path``;
            altitudes and ranges outside the tables are clamped to them). ``None`` (default): on
            whenever ``sky`` is a named atmosphere, off otherwise; ``False``: off; ``True`` or a name
            or an ``AtmosphericPath``: on. On by default because it matters at every range a sea
            scene spans: LWIR midlatitude summer from 20 m, τ = 0.95 at 100 m, 0.75 at 1 km, 0.05 at
            the 16 km horizon, shifting a 290 K sea by +0.2 K, +1.1 K, +4.0 K (more than a typical
            NETD of 0.05 K beyond ~20 m). Sky pixels see the sky table along their own ray (from
            sea level: for a high sensor the sky above it is somewhat colder; not modelled).
        air_temperature: T_air [K] of the surface air, float or (B,); only with a named atmosphere
            (default ``None``: the atmosphere's own, e.g. 294.2 K for midlatitude summer). The
            atmosphere's temperature profile is taken as shifted so that its surface air is at
            T_air; sky and path radiance are scaled by B(T_air) / B(T_atm) (band radiances). That
            is exact where the air is optically thick (the horizon sky, long paths: radiance
            → B(T_air)) and first-order right for thin emission from near-surface air (the LWIR
            window's water vapour); it does not change the transmittance.

    Example:
        >>> scene = SeaScene(wind_speed=torch.tensor([3.0, 12.0]), wind_direction=0.5,
        ...                  sea_temperature=290.0, sky=lambda c: 10.0 + 20.0 * (1 - c) ** 6)
        >>> scene.batch_size
        2
    """

    def __init__(
        self,
        *,
        slopes: SlopeStatistics | None = None,
        wind_speed: Any = None,
        anisotropic: bool = True,
        wind_direction: Any = 0.0,
        sea_temperature: Any = None,
        sea_radiance: Any = None,
        band: Any = LWIR,
        response: Any = None,
        sky: Any = "midlatitude_summer",
        refractive_index: Any = None,
        shadowing: bool = True,
        path: Any = None,
        air_temperature: Any = None,
    ):
        if (slopes is None) == (wind_speed is None):
            raise ValueError("SeaScene: give exactly one of slopes= or wind_speed=")
        if (sea_temperature is None) == (sea_radiance is None):
            raise ValueError("SeaScene: give exactly one of sea_temperature= or sea_radiance=")
        if wind_speed is not None:
            check_finite_range("wind_speed", wind_speed, 0.0, 80.0, unit="m/s")
            slopes = SlopeStatistics.cox_munk(wind_speed, anisotropic=anisotropic)
        if not isinstance(slopes, SlopeStatistics):
            raise ValueError(f"slopes must be a SlopeStatistics; got {type(slopes).__name__}")
        check_finite_range("wind_direction", wind_direction, unit="rad")
        if sea_temperature is not None:
            check_finite_range("sea_temperature", sea_temperature, 200.0, 350.0, unit="K")
        if sea_radiance is not None:
            check_finite_range("sea_radiance", sea_radiance, 0.0, unit="W m-2 sr-1")
        self.slopes = slopes
        self.wind_speed = wind_speed
        self.wind_direction = wind_direction
        self.sea_temperature = sea_temperature
        self.sea_radiance = sea_radiance
        self.band: SpectralBand = as_band(band, response)
        self.atmosphere = sky if isinstance(sky, str) else None
        if self.atmosphere is not None:  # a shipped LOWTRAN7 atmosphere, integrated over this band
            from .atmosphere import load_sky

            sky = load_sky(self.atmosphere, (self.band.lo, self.band.hi), self.band.response, dtype=torch.float64)
        self.sky = as_sky(sky)
        if path is None:
            path = self.atmosphere is not None
        if path is True:
            if self.atmosphere is None:
                raise ValueError("path=True needs a named atmosphere: give sky='<name>' or path='<name>'")
            path = self.atmosphere
        if isinstance(path, str):
            from .atmosphere import load_path

            path = load_path(path, (self.band.lo, self.band.hi), self.band.response, dtype=torch.float64)
        if path is not False and not callable(path):
            raise ValueError(f"path must be None, a bool, an atmosphere name or an AtmosphericPath; got {path!r}")
        self.path = path or None
        if air_temperature is not None:
            if self.atmosphere is None:
                raise ValueError("air_temperature needs a named atmosphere (sky='<name>'); scale a custom sky yourself")
            check_finite_range("air_temperature", air_temperature, 200.0, 350.0, unit="K")
            from .atmosphere import surface_air_temperature

            self._atmosphere_air_temperature = surface_air_temperature(self.atmosphere)
        self.air_temperature = air_temperature
        self.refractive_index = refractive_index
        self._band_index: torch.Tensor | None = None  # the band-effective water index, made on first use
        self.shadowing = shadowing

    @property
    def batch_size(self) -> int:
        sizes = {
            int(v.shape[0])
            for v in (
                self.slopes.var_upwind, self.slopes.var_crosswind, self.slopes.cov, self.wind_direction,
                self.sea_temperature, self.sea_radiance, self.air_temperature,
            )
            if isinstance(v, torch.Tensor) and v.ndim > 0
        }
        if len(sizes) > 1:
            raise ValueError(f"SeaScene: fields disagree on the batch size: {sorted(sizes)}")
        return sizes.pop() if sizes else 1

    def resolved(self, B: int, dtype: torch.dtype, device: torch.device) -> dict[str, Any]:
        """Per-image tensors (B,): a², b², r a b, wind direction, R_B, n, k; and the sky."""
        own = self.batch_size
        if own not in (1, B):
            raise ValueError(f"SeaScene has batch size {own} but the cameras have {B}")
        vx, vy, cxy = (per_batch("slopes", v, B, dtype, device) for v in self.slopes.tensors(dtype, device))
        wd = per_batch("wind_direction", self.wind_direction, B, dtype, device)
        if self.sea_radiance is not None:
            rb = per_batch("sea_radiance", self.sea_radiance, B, dtype, device)
        else:
            t_sea = per_batch("sea_temperature", self.sea_temperature, B, dtype, device)
            rb = band_radiance(t_sea, self.band)
        m = self.refractive_index
        if m is None:  # per scene, not per render: the fit depends only on the band and T_sea
            if self._band_index is None:
                t_own = self.sea_temperature if self.sea_temperature is not None else 300.0
                t_own = t_own.detach().double().cpu() if isinstance(t_own, torch.Tensor) else float(t_own)
                self._band_index = _band_index(self.band, t_own)
            m = self._band_index
        n, k = split_refractive_index(m, dtype, device)
        air_scale = None
        if self.air_temperature is not None:  # B(T_air) / B(T_atm): scales sky and path radiance
            t_air = per_batch("air_temperature", self.air_temperature, B, dtype, device)
            t_atm = torch.tensor(self._atmosphere_air_temperature, dtype=dtype, device=device)
            air_scale = band_radiance(t_air, self.band) / band_radiance(t_atm, self.band)
        # "sky" is the atmosphere's own; R_a is linear in the sky radiance, so the renderer
        # scales the reflected-sky term T_s and the sky pixels by air_scale instead of
        # interpolating one scaled sky table per image
        return dict(vx=vx, vy=vy, cxy=cxy, wind_direction=wd, rb=rb, n=n.expand(B), k=k.expand(B), sky=self.sky,
                    air_scale=air_scale)


@lru_cache(maxsize=16)
def _band_index_table(band: SpectralBand) -> tuple[torch.Tensor, torch.Tensor]:
    t = torch.arange(180.0, 362.0, 2.0, dtype=torch.float64)
    return t, band_refractive_index(band, t)


def _band_index(band: SpectralBand, temperature: Any) -> torch.Tensor:
    """The band-effective water index at T_sea [K] (float or tensor): ``band_refractive_index``
    tabulated every 2 K over 180–360 K per band and interpolated linearly (within 1.2e-6 of the
    direct fit in LWIR, 2e-7 in MWIR; a fit costs ~20 ms per call, a lookup ~0.1 ms)."""
    try:
        t, m = _band_index_table(band)
    except TypeError:  # a band with an unhashable response (e.g. arrays): fit directly
        return band_refractive_index(band, temperature)
    tq = torch.as_tensor(temperature, dtype=torch.float64)
    f = ((tq - t[0]) / (t[1] - t[0])).clamp(0.0, t.numel() - 1.0)
    i = f.floor().long().clamp(max=t.numel() - 2)
    w = (f - i).to(m.dtype)
    return m[i] * (1 - w) + m[i + 1] * w


@dataclass(frozen=True)
class TableSize:
    """Nodes of the per-image table (Chebyshev–Lobatto) and of its fine resampling.

    Args:
        zenith: nodes in ζ = asinh(cos θ̂/ε).
        azimuth: nodes in relative azimuth (anisotropic slopes only).
        azimuth_thin: nodes in relative azimuth when some image's slope ellipse is thin (minor/major
            rms slope < 0.2: Cox–Munk below ~0.04 m/s, |r| near 1): R_a then changes sharply with
            azimuth at grazing views (views along the wind at W = 0: 2e-4 with 9 nodes, 1.5e-6 with
            33, folded; ``tests/test_render.py``).
        fine_zenith, fine_azimuth: rows/columns of the fine table read by ``grid_sample``.
        span: ``"pixels"`` (default): nodes only over the angles the image's sea pixels span;
            ``"full"``: over every angle (θ̂ in [0°, 90°], every azimuth), for comparison.
    """

    zenith: int = 25
    azimuth: int = 9
    fine_zenith: int = 4096
    fine_azimuth: int = 128
    span: str = "pixels"
    azimuth_thin: int = 33

    def __post_init__(self) -> None:
        if self.span not in ("pixels", "full"):
            raise ValueError(f"TableSize.span must be 'pixels' or 'full'; got {self.span!r}")
        for name in ("zenith", "azimuth", "azimuth_thin", "fine_zenith", "fine_azimuth"):
            if int(getattr(self, name)) < 2:
                raise ValueError(f"TableSize.{name} must be >= 2")


_EXT = 2  # fine cells beyond each end of the node interval, so no pixel reads the clamped border


@lru_cache(maxsize=32)
def _lobatto_interp(n: int, m: int) -> tuple[np.ndarray, np.ndarray, float]:
    """Chebyshev–Lobatto nodes on [−1, 1] (ascending), the barycentric matrix that evaluates the
    interpolant on m uniform points of [−1 − e, 1 + e], and e.

    The fine grid overhangs the node interval by ``_EXT`` cells so that ``grid_sample`` never
    reads the clamped border for a pixel inside the interval; the overhang is the interpolant
    continued a hair outside [−1, 1].
    """
    if n == 1:
        return np.zeros(1), np.ones((m, 1)), 0.0
    e = 2.0 * _EXT / (m - 1 - 2 * _EXT)
    x = np.cos(np.pi * np.arange(n) / (n - 1))[::-1].copy()
    w = (-1.0) ** np.arange(n)
    w[0] *= 0.5
    w[-1] *= 0.5
    y = np.linspace(-1.0 - e, 1.0 + e, m)
    diff = y[:, None] - x[None, :]
    exact = np.isclose(diff, 0.0, atol=1e-15)
    diff[exact] = 1.0
    L = w / diff
    L = L / L.sum(1, keepdims=True)
    rows = exact.any(1)
    L[rows] = exact[rows].astype(float)
    return x, L, e


def _sky_per_image(sky: Any, B: int, dtype: torch.dtype, device: torch.device, extra_dims: int) -> Any:
    """Reshape a per-image sky (TabulatedSky (B, Nz) or constant (B,)) to broadcast over a table."""
    if isinstance(sky, TabulatedSky) and sky.radiance.ndim > 1:
        r = sky.radiance.to(device=device, dtype=dtype)
        if r.shape[0] != B:
            raise ValueError(f"sky: a batched table needs {B} rows (one per image); got {r.shape[0]}")
        return sky.with_radiance(r.reshape(B, *([1] * extra_dims), r.shape[-1]))
    if isinstance(sky, ConstantSky):
        r = torch.as_tensor(sky.radiance, dtype=dtype, device=device)
        if r.ndim > 0:
            return ConstantSky(r.reshape(B, *([1] * extra_dims)))
    return sky


def _sky_radiance_pixels(sky: Any, cos_z: torch.Tensor) -> torch.Tensor:
    """Sky radiance along rays, cos_z (B, N) → (B, N); below-horizontal rays see the horizon."""
    c = cos_z.clamp(0.0, 1.0)
    if isinstance(sky, ConstantSky):
        r = torch.as_tensor(sky.radiance, dtype=c.dtype, device=c.device)
        return (r.reshape(-1, 1) if r.ndim else r).expand_as(c)
    return sky(c)


def _masked_range(x: torch.Tensor, mask: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
    """Per-image (min, max) of x over mask, (B, H, W) → (B,), detached."""
    inf = torch.tensor(math.inf, dtype=x.dtype, device=x.device)
    x = x.detach()
    return torch.where(mask, x, inf).amin((1, 2)), torch.where(mask, x, -inf).amax((1, 2))


def _azimuth_offsets(
    dx: torch.Tensor, dy: torch.Tensor, wind_direction: torch.Tensor, mask: torch.Tensor
) -> tuple[torch.Tensor, torch.Tensor]:
    """Per-image centre c (b,) of the relative azimuths φ̂ = atan2(−dy, −dx) − wind direction of the
    sea pixels, and per-pixel ``wrap_π(φ̂ − c) + π/2`` ∈ [0, π) (b, H, W).

    Period π: the slope density is symmetric under s → −s, so R_a(φ̂ + π) = R_a(φ̂). The centre is
    the circular mean of 2φ̂ over a subsample of the sea pixels, halved; the per-pixel work is one
    atan2, one add of a per-image constant and one remainder.
    """
    step = max(1, int(math.sqrt(dx[0].numel() / 4096)))  # ~4096 pixels suffice for a centre
    ps = torch.atan2(-dy[:, ::step, ::step], -dx[:, ::step, ::step]).detach() - wind_direction.detach()[:, None, None]
    m = mask[:, ::step, ::step]
    m = m | ~m.flatten(1).any(1)[:, None, None]  # no sea in the subsample: use all of it
    zero = torch.zeros((), dtype=dx.dtype, device=dx.device)
    c = 0.5 * torch.atan2(torch.where(m, torch.sin(2 * ps), zero).sum((1, 2)), torch.where(m, torch.cos(2 * ps), zero).sum((1, 2)))
    k = (math.pi / 2 - c - wind_direction)[:, None, None]
    return c, torch.remainder(torch.atan2(-dy, -dx) + k, math.pi)


def _azimuth_folded(dx: torch.Tensor, dy: torch.Tensor, wind_direction: torch.Tensor) -> torch.Tensor:
    """Per pixel ψ = |wrap(φ̂)| ∈ [0, π/2], φ̂ = atan2(−dy, −dx) − wind direction wrapped to
    [−π/2, π/2) (period π): the relative azimuth folded by the mirror symmetry of uncorrelated slopes."""
    k = (math.pi / 2 - wind_direction)[:, None, None]
    return (torch.remainder(torch.atan2(-dy, -dx) + k, math.pi) - math.pi / 2).abs()


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
    chunk: int = 4,
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
        chunk: images whose per-pixel temporaries are held at once (memory bound; the model is
            evaluated for the whole batch in one call).

    Returns:
        (B, 1, H, W) tensor in the cameras' dtype and device; differentiable with respect to every
        tensor of the scene and of the cameras' pose.
    """
    if method not in ("table", "direct"):
        raise ValueError(f"method must be 'table' or 'direct'; got {method!r}")
    if output not in ("radiance", "brightness_temperature"):
        raise ValueError(f"output must be 'radiance' or 'brightness_temperature'; got {output!r}")
    if geometry is not None:
        B, H, W = geometry.is_sea.shape
        dtype, device = geometry.cos_view_zenith.dtype, geometry.cos_view_zenith.device
    else:
        cg = CameraGeometry(cameras, earth_radius_m)
        B, H, W, dtype, device = cg.batch_size, cg.H, cg.W, cg.dtype, cg.device
    p = scene.resolved(B, dtype, device)
    q = quadrature or Quadrature.default(dtype)
    if method == "direct":
        geom = geometry if geometry is not None else view_geometry(cameras, earth_radius_m)
        sea = geom.is_sea
        img = None
        if bool(sea.any()):
            p_sea = p
            if p["air_scale"] is not None:  # one scaled sky table per image
                p_sea = dict(p, sky=p["sky"].with_radiance(p["sky"].radiance.to(dtype=dtype, device=device) * p["air_scale"][:, None]))
            img = _sea_direct(geom, p_sea, scene, q)
            if scene.path is not None:
                img = _apply_path(scene.path, img, geom.altitude_m, geom.range_m, sea, p["air_scale"])
        if bool((~sea).any()):
            sky_pix = _sky_pixels(p["sky"], geom.cos_view_zenith, B, dtype, device)
            if p["air_scale"] is not None:
                sky_pix = sky_pix * p["air_scale"][:, None, None]
            img = sky_pix if img is None else torch.where(sea, img, sky_pix)
        img = img.reshape(B, 1, H, W)
    else:
        if geometry is not None:
            g = geometry

            def source(sl: slice) -> dict[str, torch.Tensor]:
                out = {"cos": g.cos_view_zenith[sl], "sea": g.is_sea[sl], "dx": g._dx[sl], "dy": g._dy[sl]}
                if scene.path is not None:
                    out["range"] = g.range_m[sl]
                return out

            altitude = g.altitude_m
        else:

            iso = bool(((p["vx"] == p["vy"]) & (p["cxy"] == 0)).all())

            def source(sl: slice) -> dict[str, torch.Tensor]:
                out = cg.pixels(sl, need_xy=not iso)
                if scene.path is not None:
                    out["range"] = cg.slant_range(out["cos"], out["sea"], out["dz"], sl)
                return out

            altitude = cg.alt.to(dtype)
        img = _render_table(source, B, H, W, dtype, device, p, scene, q, table, chunk, altitude)[:, None]
    if output == "brightness_temperature":
        return brightness_temperature(img.clamp_min(torch.finfo(dtype).tiny), scene.band)
    return img


def _relative_azimuth(geom: ViewGeometry, p: dict[str, Any]) -> torch.Tensor:
    return geom.view_azimuth - p["wind_direction"][:, None, None]


def _sea_direct(geom: ViewGeometry, p: dict[str, Any], scene: SeaScene, q: Quadrature) -> torch.Tensor:
    B = geom.is_sea.shape[0]
    sea = geom.is_sea
    img_idx = torch.arange(B, device=sea.device)[:, None, None].expand_as(sea)[sea]
    th = geom.view_zenith[sea]
    ph = _relative_azimuth(geom, p)[sea]
    slopes = SlopeStatistics.from_variances(p["vx"][img_idx], p["vy"][img_idx], p["cxy"][img_idx])
    sky = select_sky(p["sky"], img_idx.cpu())
    vals = apparent_radiance(
        th, ph, slopes, (p["n"][img_idx], p["k"][img_idx]), sea_radiance=p["rb"][img_idx], sky=sky,
        shadowing=scene.shadowing, quadrature=q,
    )
    out = torch.zeros(sea.shape, dtype=vals.dtype, device=vals.device)
    return out.index_put((sea,), vals)


def _sky_pixels(sky: Any, cos_z: torch.Tensor, B: int, dtype: torch.dtype, device: torch.device) -> torch.Tensor:
    """Sky radiance along each pixel's ray (b, H, W) for a chunk whose first image is image 0 of
    ``sky``'s batch (callers slice per-image skies)."""
    b, H, W = cos_z.shape
    return _sky_radiance_pixels(_sky_per_image(sky, b, dtype, device, 0), cos_z.reshape(b, -1)).reshape(b, H, W)


def _apply_path(path: Any, radiance: torch.Tensor, altitude: torch.Tensor, range_m: torch.Tensor, sea: torch.Tensor,
                air_scale: torch.Tensor | None = None) -> torch.Tensor:
    """τ · R_a + L_path at each sea pixel (other pixels unchanged); (b, H, W). ``air_scale`` (b,)
    scales L_path (SeaScene's air_temperature)."""
    h = altitude.to(radiance.dtype)[:, None, None].expand_as(radiance)
    r = torch.where(sea, range_m.to(radiance.dtype), h)  # any valid range off the sea
    tau, lp = path(h, r, clamp=True)
    if air_scale is not None:
        lp = lp * air_scale[:, None, None]
    return torch.where(sea, tau * radiance + lp, radiance)


def _render_table(
    source: Callable[[slice], dict[str, torch.Tensor]],
    B: int,
    H: int,
    W: int,
    dtype: torch.dtype,
    device: torch.device,
    p: dict[str, Any],
    scene: SeaScene,
    q: Quadrature,
    table: TableSize,
    chunk: int,
    altitude: torch.Tensor,
) -> torch.Tensor:
    """The table method, streaming ``chunk`` images at a time: pass 1 keeps only each pixel's table
    coordinates (and sky radiance, where sky is seen) and the per-image angle ranges; the model is
    evaluated once for the batch; pass 2 samples the tables chunk by chunk. Returns (B, H, W)."""
    iso = bool(((p["vx"] == p["vy"]) & (p["cxy"] == 0)).all())
    # Uncorrelated anisotropic slopes (Cox–Munk): the table runs over the folded azimuth ψ ∈ [0, π/2].
    # R_a is even in φ̂ there, and as a → 0 (or b → 0) it has a kink at φ̂ = 0 (π/2), where the
    # rms slope along the view, √(a² cos²φ̂ + b² sin²φ̂), → b |sin φ̂|: folded, the kink sits at an
    # end of the node interval instead of inside it, where Chebyshev nodes cannot resolve it
    # (views along the wind at W = 0 were off by 8e-4 with 9 nodes; pipelines/accuracy_pareto.py).
    fold = not iso and bool((p["cxy"] == 0).all())
    # ε: a quarter of the smallest rms slope of each image, so ζ resolves the grazing layer.
    lam_min = 0.5 * (p["vx"] + p["vy"] - torch.sqrt((p["vx"] - p["vy"]) ** 2 + 4 * p["cxy"] ** 2))
    eps = (0.25 * torch.sqrt(lam_min.detach().clamp_min(0.0))).clamp(1e-4, 0.05).double()
    inv_eps = (1.0 / eps).to(dtype)
    lam_max = 0.5 * (p["vx"] + p["vy"] + torch.sqrt((p["vx"] - p["vy"]) ** 2 + 4 * p["cxy"] ** 2))
    thin = bool((lam_min.detach() < 0.04 * lam_max.detach()).any())  # minor/major rms slope < 0.2
    nz, nphi = table.zenith, (1 if iso else max(table.azimuth, table.azimuth_thin) if thin else table.azimuth)
    xz, Lz, ez = _lobatto_interp(nz, table.fine_zenith)
    xp, Lp, ep = _lobatto_interp(nphi, 1 if iso else table.fine_azimuth)
    chunks = []
    out: torch.Tensor | None = None
    zlo, zhi, olo, ohi, centre = [], [], [], [], []
    for i in range(0, B, chunk):
        sl = slice(i, min(i + chunk, B))
        px = source(sl)
        sea = px["sea"]
        xz_ = px["cos"] * inv_eps[sl, None, None]  # the pixel's own cos θ̂ / ε (sky pixels: masked out)
        zeta = torch.log(xz_ + torch.sqrt(xz_ * xz_ + 1.0))  # asinh, 3× faster than torch.asinh on CPU
        lo, hi = _masked_range(zeta, sea)
        zlo.append(lo)
        zhi.append(hi)
        entry: dict[str, Any] = {"sl": sl, "sea": sea, "zeta": zeta, "sky": None, "range": px.get("range")}
        if fold:  # o = ψ = |φ̂| folded into [0, π/2]: R_a(φ̂) = R_a(−φ̂) = R_a(π − φ̂) when r = 0
            o = _azimuth_folded(px["dx"], px["dy"], p["wind_direction"][sl])
            a, b = _masked_range(o, sea)
            centre.append(torch.zeros_like(a))
            olo.append(a)
            ohi.append(b)
            entry["o"] = o
        elif not iso:
            c, o = _azimuth_offsets(px["dx"], px["dy"], p["wind_direction"][sl], sea)  # o ∈ [0, π): offset + π/2
            a, b = _masked_range(o, sea)
            centre.append(c)
            olo.append(a)
            ohi.append(b)
            entry["o"] = o
        if bool((~sea).any()):  # no sky work when no pixel of the chunk sees sky
            sky_vals = _sky_pixels(select_sky(p["sky"], sl), px["cos"], sl.stop - sl.start, dtype, device)
            if p["air_scale"] is not None:
                sky_vals = sky_vals * p["air_scale"][sl, None, None]
            if out is None:
                out = torch.zeros(B, H, W, dtype=dtype, device=device)
            out[sl] = sky_vals  # sky pixels land in the output now; sea pixels overwrite in pass 2
            entry["sky"] = True
        del px
        chunks.append(entry)
    any_sea = torch.cat([torch.isfinite(z) for z in zlo])
    lo = torch.where(any_sea, torch.cat(zlo), torch.zeros(B, dtype=dtype, device=device)).double()
    hi = torch.where(any_sea, torch.cat(zhi), torch.ones(B, dtype=dtype, device=device)).double()
    if table.span == "full":
        lo, hi = torch.zeros_like(lo), torch.asinh(1.0 / eps)
    pad = torch.clamp(1e-6 * (hi - lo), min=1e-9)
    lo, hi = lo - pad, hi + pad
    xz_t = torch.as_tensor(xz, dtype=torch.float64, device=device)
    zeta_n = lo[:, None] + (hi - lo)[:, None] * (xz_t + 1) / 2  # (B, nz)
    th_nodes = torch.acos((eps[:, None] * torch.sinh(zeta_n)).clamp(0.0, 1.0)).to(dtype)
    if iso:
        ph_nodes = torch.zeros(B, 1, dtype=dtype, device=device)
    else:
        c = torch.cat(centre).double()
        a = torch.where(any_sea, torch.cat(olo), torch.zeros(B, dtype=dtype, device=device)).double()
        b = torch.where(any_sea, torch.cat(ohi), torch.ones(B, dtype=dtype, device=device)).double()
        if table.span == "full":
            a, b = torch.zeros_like(a), torch.full_like(b, math.pi / 2 if fold else math.pi)
        pad = torch.clamp(1e-6 * (b - a), min=1e-6)
        a, b = a - pad, b + pad
        if fold:  # ψ ∈ [0, π/2]: keep the nodes inside it (the kink stays at the interval's end)
            a, b = a.clamp_min(0.0), b.clamp_max(math.pi / 2)
        xp_t = torch.as_tensor(xp, dtype=torch.float64, device=device)
        # the pixels' o = wrap_π(φ̂ − c) + π/2: nodes at φ̂ = c + o − π/2 (folded: φ̂ = o = ψ)
        shift = 0.0 if fold else math.pi / 2
        ph_nodes = (c[:, None] - shift + a[:, None] + (b - a)[:, None] * (xp_t + 1) / 2).to(dtype)
    vz = th_nodes[:, :, None].expand(B, nz, nphi)
    va = ph_nodes[:, None, :].expand(B, nz, nphi)
    slopes = SlopeStatistics.from_variances(p["vx"][:, None, None], p["vy"][:, None, None], p["cxy"][:, None, None])
    sky = _sky_per_image(p["sky"], B, dtype, device, 2)
    # T_s, T_ρ in the model's working dtype: float64 without shadowing, where they grow like
    # σ∥/cos θ̂ and R_B (1 − T_ρ) + T_s cancels them (expectation._work_dtype)
    t_s, t_rho, _ = _reflection_terms(vz, va, slopes, (p["n"][:, None, None], p["k"][:, None, None]), sky, scene.shadowing, q, None)
    if p["air_scale"] is not None:
        t_s = t_s * p["air_scale"][:, None, None].to(t_s.dtype)
    rb = p["rb"][:, None, None].to(t_s.dtype)
    coarse = (rb - rb * t_rho + t_s).to(dtype)  # R_a at the nodes (B, nz, nphi); linear in the node values
    Lz_t = torch.as_tensor(Lz, dtype=dtype, device=device)
    Lp_t = torch.as_tensor(Lp, dtype=dtype, device=device)
    # the fine table (Mz × Mp per image) is made per chunk in pass 2, not for the whole batch
    lo_t, span_z = lo.to(dtype), (hi - lo).to(dtype)
    if not iso:
        a_t, span_p = a.to(dtype), (b - a).to(dtype)
    while chunks:
        e = chunks.pop(0)
        sl = e["sl"]
        zs = (2.0 / (span_z * (1.0 + ez)))[sl, None, None]
        gy = torch.addcmul(((-2.0 * lo_t / span_z - 1.0) / (1.0 + ez))[sl, None, None], e["zeta"], zs)
        if iso:
            gx = torch.zeros_like(gy)
        else:
            scale = (2.0 / (span_p * (1.0 + ep)))[sl, None, None]
            shift = ((-2.0 * a_t / span_p - 1.0) / (1.0 + ep))[sl, None, None]
            gx = torch.addcmul(shift, e["o"], scale)
        # bilinear, not bicubic: torch's bicubic is Keys' kernel with a = −0.75, which converges
        # only to first order; bilinear on the fine table is second order (~1e-7 at 4096 rows).
        fine = torch.einsum("iz,bzp,jp->bij", Lz_t, coarse[sl], Lp_t)[:, None]  # (b, 1, Mz, Mp)
        vals = F.grid_sample(fine, torch.stack([gx, gy], -1), mode="bilinear", padding_mode="border", align_corners=True)[:, 0]
        del fine, gx, gy
        if scene.path is not None:
            vals = _apply_path(scene.path, vals, altitude[sl], e["range"], e["sea"],
                               None if p["air_scale"] is None else p["air_scale"][sl])
        if e["sky"] is not None:
            vals = torch.where(e["sea"], vals, out[sl])
        if out is None:
            if sl.stop - sl.start == B:
                return vals
            out = torch.empty(B, H, W, dtype=vals.dtype, device=device)
        out[sl] = vals  # chunks land in place (autograd records the slice copies)
    return out


class SeaRenderer(torch.nn.Module):
    """``nn.Module`` form of :func:`render`: holds the settings, ``forward(cameras, scene)``."""

    def __init__(
        self,
        earth_radius_m: float = EARTH_RADIUS_M,
        method: str = "table",
        output: str = "radiance",
        table: TableSize = TableSize(),
        quadrature: Quadrature | None = None,
    ):
        super().__init__()
        self.earth_radius_m = earth_radius_m
        self.method = method
        self.output = output
        self.table = table
        self.quadrature = quadrature

    def forward(self, cameras: PinholeCamera, scene: SeaScene) -> torch.Tensor:
        return render(
            cameras, scene, earth_radius_m=self.earth_radius_m, method=self.method, output=self.output,
            table=self.table, quadrature=self.quadrature,
        )

    def extra_repr(self) -> str:
        return f"earth_radius_m={self.earth_radius_m}, method={self.method!r}, output={self.output!r}, table={self.table}"

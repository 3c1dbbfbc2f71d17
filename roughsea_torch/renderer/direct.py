"""The direct method: the model evaluated at every pixel (``render(..., method="direct")``), the
baseline the table method is measured against.

Each sea pixel gets the apparent radiance of Eq. 10 at its own view angles (θ̂, φ̂), and on a
textured sea the shifted expectation about its own resolved slope at its own footprint
(:mod:`roughsea_torch.clutter`); then the glint, the foam and the path; each sky pixel the sky
along its ray, the sun's disk and the scattered day sky. Slow (every pixel runs the model's
quadrature) but free of any table error.
"""

from __future__ import annotations

import dataclasses

import torch
from kornia.geometry.camera import PinholeCamera

from .._validation import per_batch
from ..clutter import footprint, pixel_resolved_slope, reconcile_scale, two_scale_statistics
from ..expectation import Quadrature, apparent_radiance
from ..geometry import ViewGeometry, view_geometry
from ..sky import select_sky
from ..slopes import SlopeStatistics
from ..sun import glint_radiance, sun_masking_factor
from ..whitecaps import whitecap_cover
from .antialias import FOAM_TAPS, TEXTURE_TAPS, filter_columns
from .foam_terms import foam_mix, foam_mix_states
from .output import kelvin
from .path import apply_path, check_path_altitude
from .scene import SceneParameters, SeaScene
from .settings import TableSize
from .sky_terms import day_sky, day_sky_pixels, relative_sun, sky_rows, sky_with_day, sun_disk_pixels
from .texture import single_quantile, warn_eq7

__all__ = ["render_direct", "sea_direct", "sea_textured_direct"]


def render_direct(cameras: PinholeCamera, geometry: ViewGeometry | None, scene: SeaScene, p: SceneParameters,
                  q: Quadrature, earth_radius_m: float, brightness: bool, table: TableSize = TableSize()) -> torch.Tensor:
    """Every pixel of the cameras' images, (B, 1, H, W); in kelvin with ``brightness``; a textured
    sea's texture drawn with the ``table`` settings that apply per pixel (``texture_antialias``: the
    filter along the columns, :mod:`~roughsea_torch.renderer.antialias`; ``foam_trails``)."""
    geom = geometry if geometry is not None else view_geometry(cameras, earth_radius_m)
    B, H, W = geom.is_sea.shape
    dtype, device = geom.cos_view_zenith.dtype, geom.cos_view_zenith.device
    sea = geom.is_sea
    altitude = geom.altitude_m
    img = None
    if bool(sea.any()):
        p_sea = p
        if p.air_scale is not None:  # one scaled sky table per image
            p_sea = dataclasses.replace(p, sky=p.sky.with_radiance(p.sky.radiance.to(dtype=dtype, device=device)
                                                                   * p.air_scale[:, None]),
                                        air_scale=None)  # the sky itself now carries it
        img = (sea_direct(geom, p_sea, scene, q, B, dtype, device) if scene.seed is None
               else sea_textured_direct(geom, cameras, p_sea, scene, q, B, dtype, device, table))
        if scene.path is not None:
            check_path_altitude(scene.path, altitude)
            img = apply_path(scene.path, img, altitude, geom.range_m, sea, p.air_scale)
    if bool((~sea).any()):
        sky_pix = sky_rows(p.sky, p.air_scale, scene, geom.cos_view_zenith.reshape(B, -1), altitude).reshape(B, H, W)
        if scene.sun is not None:
            sky_pix = sky_pix + sun_disk_pixels(scene, B, slice(None), geom.cos_view_zenith, geom.dx, geom.dy, ~sea,
                                                1.0 / cameras.fx.to(dtype))
        day = day_sky(scene, B, dtype, device)
        if day is not None:
            sky_pix = sky_pix + day_sky_pixels(day, slice(None), geom.cos_view_zenith, geom.dx, geom.dy)
        img = sky_pix if img is None else torch.where(sea, img, sky_pix)
    img = img.reshape(B, 1, H, W)
    if brightness:
        return kelvin(img, scene.band)
    return img


def relative_azimuth(geom: ViewGeometry, p: SceneParameters) -> torch.Tensor:
    """φ̂ of every pixel: the world azimuth of its line of sight from the upwind axis [rad]."""
    return geom.view_azimuth - p.wind_direction[:, None, None]


def sea_direct(geom: ViewGeometry, p: SceneParameters, scene: SeaScene, q: Quadrature, B: int, dtype: torch.dtype,
                device: torch.device) -> torch.Tensor:
    """The expectation image's sea pixels (b, H, W), 0 elsewhere: Eq. 10 at each pixel's own view
    angles, with the glint of the scene's sun and its whitecaps."""
    sea = geom.is_sea
    img_idx = torch.arange(B, device=sea.device)[:, None, None].expand_as(sea)[sea]
    th = geom.view_zenith[sea]
    ph = relative_azimuth(geom, p)[sea]
    slopes = SlopeStatistics.from_variances(p.vx[img_idx], p.vy[img_idx], p.cxy[img_idx])
    sky = select_sky(p.sky, img_idx.cpu())
    day = day_sky(scene, B, dtype, device)
    if day is not None:  # the sky each pixel reflects, along its mirror azimuth
        sky = sky_with_day(sky, day, p, img_idx, ph)
    vals = apparent_radiance(
        th, ph, slopes, (p.n[img_idx], p.k[img_idx]), sea_radiance=p.rb[img_idx], sky=sky,
        shadowing=scene.shadowing, quadrature=q, sun=relative_sun(scene, p, B, dtype, device, img_idx),
        sun_masking=scene.sun_masking, sky_masking=scene.sky_masking,
    )
    if p.foam is not None:
        vals = foam_mix(vals, th, p, img_idx, scene)
    out = torch.zeros(sea.shape, dtype=vals.dtype, device=vals.device)
    return out.index_put((sea,), vals)


def sea_textured_direct(geom: ViewGeometry, cameras: PinholeCamera, p: SceneParameters, scene: SeaScene,
                         q: Quadrature, B: int, dtype: torch.dtype, device: torch.device,
                         table: TableSize = TableSize()) -> torch.Tensor:
    """The textured sea per pixel (the baseline of the texture volume): each sea pixel's own
    footprint, resolved slope, visible slope a' and shifted expectation (:mod:`roughsea_torch.clutter`);
    with ``table.texture_antialias`` its departure from the expectation (Eq. 10 at the pixel) and its crest-foam
    fraction filtered along the columns (:func:`~roughsea_torch.renderer.antialias.filter_columns`)."""
    sea = geom.is_sea
    wf = scene.wave_field(B, dtype, device)
    centres = -(cameras.rotation_matrix.transpose(-1, -2) @ cameras.translation_vector)[..., 0].to(dtype)
    cos_t = geom.cos_view_zenith.clamp_min(1e-9)
    R = torch.where(sea, geom.range_m, torch.ones_like(cos_t))
    L = footprint(R, cos_t, (1.0 / cameras.fx.to(dtype))[:, None, None])
    dx, dy = geom.dx, geom.dy
    time = per_batch("time_s", scene.time_s, B, torch.float64, device)  # wave phases in float64 (TextureTable)
    xw, yw = centres[:, 0, None, None] + R * dx, centres[:, 1, None, None] + R * dy
    smp = wf.sample(xw, yw, time, footprint=L, elevation=False, crest=p.foam is not None)
    cov = wf.resolved_covariance(L)
    l_ = reconcile_scale(cov, *(getattr(p, k)[:, None, None] for k in ("vx", "vy", "cxy", "wind_direction")))
    x, var_a, kap = pixel_resolved_slope(l_ * smp["slope_x"], l_ * smp["slope_y"], tuple(c * l_ * l_ for c in cov),
                                         dx, dy)
    img_idx = torch.arange(B, device=device)[:, None, None].expand_as(sea)[sea]
    th, ph = geom.view_zenith[sea], relative_azimuth(geom, p)[sea]
    vx, vy, cxy = p.vx[img_idx], p.vy[img_idx], p.cxy[img_idx]
    slopes = single_quantile(two_scale_statistics(vx, vy, cxy, ph, torch.cos(th), x[sea][:, None], var_a[sea], kap[sea]))
    if scene.shadowing is False:  # Eq. 7 divides by the mean facet's projected area e (as TextureTable._check_eq7)
        e = torch.cos(th) + torch.sin(th) * (slopes.mean_upwind * torch.cos(ph) + slopes.mean_crosswind * torch.sin(ph))
        if bool((e <= 0).any()):
            warn_eq7()
    sky = select_sky(p.sky, img_idx.cpu())
    day = day_sky(scene, B, dtype, device)
    if day is not None:  # the sky each pixel reflects, along its mirror azimuth
        sky = sky_with_day(sky, day, p, img_idx, ph)
    vals = apparent_radiance(th, ph, slopes, (p.n[img_idx], p.k[img_idx]), sea_radiance=p.rb[img_idx],
                             sky=sky, shadowing=scene.shadowing, quadrature=q, sky_masking=scene.sky_masking)
    if table.texture_antialias:  # the expectation plus the filtered departure (the table's texture volume holds the same)
        mean = apparent_radiance(th, ph, SlopeStatistics.from_variances(vx, vy, cxy), (p.n[img_idx], p.k[img_idx]),
                                 sea_radiance=p.rb[img_idx], sky=sky, shadowing=scene.shadowing, quadrature=q,
                                 sky_masking=scene.sky_masking)
        delta = torch.zeros(sea.shape, dtype=vals.dtype, device=vals.device).index_put((sea,), vals - mean)
        vals = mean + filter_columns(delta, sea, TEXTURE_TAPS)[sea]
    sun = relative_sun(scene, p, B, dtype, device, img_idx)
    if sun is not None:  # the pixel's own glint, masked from the sun by the total law (sun_masking_factor)
        g = glint_radiance(th, ph, slopes, (p.n[img_idx], p.k[img_idx]), sun, scene.shadowing, False)
        if scene.sun_masking:
            g = g * sun_masking_factor(SlopeStatistics.from_variances(vx, vy, cxy), sun, dtype, device)
        vals = vals + g
    if p.foam is not None:  # whitecaps on the crests and their residual foam (whitecaps.whitecap_cover)
        f_act, f_res = whitecap_cover(wf, xw, yw, time, L, smp["crest"], wf.crest_variance(L),
                                      wf.crest_variance()[:, None, None], p.foam.to(dtype)[:, None, None],
                                      trails=table.foam_trails)
        if table.texture_antialias:
            f_act, f_res = (filter_columns(torch.where(sea, f, torch.zeros_like(f)), sea, FOAM_TAPS) for f in (f_act, f_res))
        vals = foam_mix_states(vals, th, p, img_idx, scene, f_act[sea], f_res[sea])
    out = torch.zeros(sea.shape, dtype=vals.dtype, device=vals.device)
    return out.index_put((sea,), vals)


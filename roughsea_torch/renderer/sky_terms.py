"""The sky in a render: what sky pixels see (the sky along their ray, the sun's disk, the scattered day
sky) and the sky the sea reflects (per image, and by day along each view's mirror azimuth).

Radiances in W m⁻² sr⁻¹ in the scene's band; angles in radians, world azimuths from +x towards +y,
azimuths relative to upwind where said.
"""

from __future__ import annotations

import math
from typing import Any, NamedTuple

import torch

from .._validation import per_batch
from ..sky import ConstantSky, TabulatedSky
from ..sun import Sun
from .scene import SceneParameters, SeaScene

__all__ = ["DaySky", "day_sky", "sky_with_day", "day_sky_pixels", "sky_per_image", "sky_radiance_along", "sky_rows",
           "sun_fields", "relative_sun", "sun_disk_pixels"]


class DaySky(NamedTuple):
    """A scene's solar-scattered sky (:class:`~roughsea_torch.daysky.ScatteredSky`) with its sun's
    zenith and world azimuth [rad], (B,) each."""

    sky: Any
    sun_zenith: torch.Tensor
    sun_azimuth: torch.Tensor


def sky_per_image(sky: Any, B: int, dtype: torch.dtype, device: torch.device, extra_dims: int) -> Any:
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


def sky_radiance_along(sky: Any, cos_z: torch.Tensor) -> torch.Tensor:
    """Sky radiance along rays, cos_z (B, N) → (B, N); below-horizontal rays see the horizon."""
    c = cos_z.clamp(0.0, 1.0)
    if isinstance(sky, ConstantSky):
        r = torch.as_tensor(sky.radiance, dtype=c.dtype, device=c.device)
        return (r.reshape(-1, 1) if r.ndim else r).expand_as(c)
    return sky(c)


def sky_rows(sky: Any, air_scale: torch.Tensor | None, scene: SeaScene, cos_z: torch.Tensor,
              altitude: torch.Tensor) -> torch.Tensor:
    """Sky radiance seen by each camera along rays of zenith cosine ``cos_z`` (B, N) at the camera
    (down to the depressed horizon): from the camera's altitude for a named atmosphere, else the
    scene's sky (rays below the horizontal see its horizon); scaled by the air temperature."""
    B = cos_z.shape[0]
    if scene.observer_sky is not None:
        rad = scene.observer_sky(altitude.to(cos_z.dtype)[:, None], cos_z, clamp=True)
    else:
        rad = sky_radiance_along(sky_per_image(sky, B, cos_z.dtype, cos_z.device, 0), cos_z)
    if air_scale is not None:
        rad = rad * air_scale[:, None].to(rad.dtype)
    return rad


def sun_fields(scene: SeaScene, B: int, dtype: torch.dtype, device: torch.device) -> tuple[torch.Tensor, ...]:
    """The scene's sun as (B,) tensors: zenith, world azimuth, irradiance, radius."""
    sun = scene.sun
    return tuple(per_batch(f"sun {n}", v, B, dtype, device) for n, v in
                 (("zenith", sun.zenith), ("azimuth", sun.azimuth), ("irradiance", sun.irradiance), ("radius", sun.radius)))


def relative_sun(scene: SeaScene, p: SceneParameters, B: int, dtype: torch.dtype, device: torch.device,
                  idx: torch.Tensor) -> Any:
    """The scene's sun for the images ``idx`` with its azimuth from each image's upwind axis."""
    if scene.sun is None:
        return None
    z, a, e, r = sun_fields(scene, B, dtype, device)
    return Sun(z[idx], a[idx] - p.wind_direction[idx], e[idx], r[idx])


def day_sky(scene: SeaScene, B: int, dtype: torch.dtype, device: torch.device) -> DaySky | None:
    """The :class:`DaySky` of a scene whose sky gains the sunlight its aerosol scatters
    (:attr:`SeaScene.day_sky`), else None."""
    day = scene.day_sky
    if day is None:
        return None
    z, a, _, _ = sun_fields(scene, B, dtype, device)
    return DaySky(day, z, a)


def sky_with_day(sky: TabulatedSky, day: DaySky, p: SceneParameters, idx: Any, view_azimuth: torch.Tensor) -> TabulatedSky:
    """The sky the sea reflects by day, per element of ``view_azimuth`` (relative to upwind, LOS sea →
    sensor; leading dim = the images ``idx``): the thermal table plus the scattered sky at its zenith
    nodes along the mirror azimuth φ̂ + π (divided by the air-temperature scale that the sky term
    gets afterwards, which is the thermal sky's)."""
    ds, z_sun, a_sun = day
    dtype, device = view_azimuth.dtype, view_azimuth.device
    extra = (None,) * (view_azimuth.ndim - 1)
    rel = view_azimuth + math.pi - (a_sun[idx] - p.wind_direction[idx]).to(dtype)[(...,) + extra]
    z = sky.zenith.to(dtype=dtype, device=device)
    scat = ds(torch.cos(z), rel[..., None], z_sun[idx].to(dtype)[(...,) + extra + (None,)])
    if p.air_scale is not None:
        scat = scat / p.air_scale[idx].to(dtype)[(...,) + extra + (None,)]
    thermal = sky.radiance.to(dtype=dtype, device=device)
    if thermal.ndim > 1:
        thermal = thermal.reshape(thermal.shape[0], *([1] * (view_azimuth.ndim - 1)), thermal.shape[-1])
    return sky.with_radiance(thermal + scat)


def day_sky_pixels(day: DaySky, sl: Any, cos: torch.Tensor, dx: torch.Tensor, dy: torch.Tensor,
                    img: torch.Tensor | None = None) -> torch.Tensor:
    """The scattered sky along the rays of sky pixels (cos of the ray's zenith, world x/y components;
    rays below the horizontal see it at the horizontal), (b, H, W); or, with ``img`` (each pixel's image
    within ``sl``), at gathered pixels, all 1-D."""
    ds, z_sun, a_sun = day
    a, z = a_sun[sl].to(cos.dtype), z_sun[sl].to(cos.dtype)
    if img is None:
        a, z = a[:, None, None], z[:, None, None].expand_as(cos)
    else:
        a, z = a.index_select(0, img), z.index_select(0, img)
    return ds(cos.clamp(0.0, 1.0), torch.atan2(dy, dx) - a, z)


def sun_disk_pixels(scene: SeaScene, B: int, idx: slice, dz: torch.Tensor, dx: torch.Tensor, dy: torch.Tensor,
                     sky: torch.Tensor, ifov: torch.Tensor) -> torch.Tensor:
    """The sun's own disk in the sky pixels of images ``idx``: L_sun = E_sun / Ω_sun (the irradiance at
    the surface: the air between the sea and the camera is neglected) times the share of each pixel
    the disk covers, an edge one pixel wide (δ = the camera's IFOV at its centre). (b, H, W)."""
    dtype, device = dz.dtype, dz.device
    z, a, e, r = (v[idx][:, None, None] for v in sun_fields(scene, B, dtype, device))
    # the angle from the sun's centre by the chord |d − s| = 2 sin(ang/2) of the two unit vectors, component by
    # component: 2 − 2 cos(ang) from their dot product would cancel (in float32 its rounding, 6e-8, is an angle
    # of 6e-8/ang ≈ 1e-5 rad at the disk's edge: 0.2 % of a 30°/80 px pixel's cover, 4 % of a 3°/160 px one's)
    sx, sy, sz = torch.sin(z) * torch.cos(a), torch.sin(z) * torch.sin(a), torch.cos(z)
    chord2 = (dx - sx) ** 2 + (dy - sy) ** 2 + (dz - sz) ** 2
    ang = 2.0 * torch.asin((0.5 * torch.sqrt(chord2.clamp_min(1e-30))).clamp(max=1.0))
    cover = ((r - ang) / ifov[:, None, None] + 0.5).clamp(0.0, 1.0)
    l_sun = e / (4.0 * math.pi * torch.sin(0.5 * r) ** 2)
    return torch.where(sky & (cover > 0), l_sun * cover, torch.zeros_like(dz))


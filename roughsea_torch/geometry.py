"""Cameras (kornia ``PinholeCamera``) and per-pixel view geometry over a spherical or flat sea.

Conventions (``docs/physics.md`` §2, §8): world frame right-handed, z up, origin at sea level under
the sensor; azimuths from +x towards +y. Camera extrinsics are world → camera with OpenCV axes
(x right, y down, z forward), pixel centres at integer coordinates (kornia's convention). The sea is
a sphere of radius ``earth_radius_m`` centred at (0, 0, −R) (``float('inf')``: the plane z = 0).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import torch
from kornia.geometry.camera import PinholeCamera
from kornia.geometry.depth import unproject_meshgrid

from ._validation import check_finite_range

__all__ = ["EARTH_RADIUS_M", "make_camera", "ViewGeometry", "view_geometry"]

EARTH_RADIUS_M = 6_371_000.0


def _batch(x: Any, n: int, dtype: torch.dtype, device: torch.device | None) -> torch.Tensor:
    t = x.to(dtype=dtype, device=device) if isinstance(x, torch.Tensor) else torch.tensor(float(x), dtype=dtype, device=device)
    if t.ndim == 0:
        return t.expand(n)
    if t.shape != (n,):
        raise ValueError(f"pose arguments must be floats or tensors of shape (B,) = ({n},); got {tuple(t.shape)}")
    return t


def make_camera(
    height: int = 512,
    width: int = 640,
    hfov_deg: Any = 30.0,
    altitude_m: Any = 20.0,
    pitch_deg: Any = -3.0,
    yaw_deg: Any = 0.0,
    roll_deg: Any = 0.0,
    batch_size: int | None = None,
    *,
    dtype: torch.dtype = torch.float32,
    device: torch.device | str | None = None,
) -> PinholeCamera:
    """A batch of kornia pinhole cameras from what a sensor engineer knows.

    Args:
        height, width: image size [pixels].
        hfov_deg: horizontal field of view [deg], in (0, 179]; square pixels.
        altitude_m: height of the optical centre above the sea [m], > 0.
        pitch_deg: elevation of the optical axis [deg] in [−90, 90]; negative looks down.
        yaw_deg: azimuth of the optical axis [deg], from +x towards +y (0 looks along +x).
        roll_deg: rotation about the optical axis [deg], in [−180, 180]; positive turns the
            camera's x axis towards its y axis (right side down), so the horizon appears rotated
            counter-clockwise in the image.
        batch_size: B; inferred from tensor arguments of shape (B,) when None.

    Pose and fov arguments are floats or tensors of shape (B,); gradients flow to them through
    the extrinsics, which are built with ``torch.stack`` (no in-place writes).

    Returns:
        ``kornia.geometry.camera.PinholeCamera`` with intrinsics/extrinsics (B, 4, 4).

    Example:
        >>> cams = make_camera(48, 64, hfov_deg=30.0, altitude_m=20.0, pitch_deg=-3.0, batch_size=2)
        >>> centre = -(cams.rotation_matrix.transpose(-1, -2) @ cams.translation_vector)[..., 0]
        >>> tuple(cams.extrinsics.shape), [round(float(v), 3) + 0.0 for v in centre[0]]
        ((2, 4, 4), [0.0, 0.0, 20.0])
    """
    if not (isinstance(height, int) and isinstance(width, int) and height > 0 and width > 0):
        raise ValueError(f"height and width must be positive ints; got {height!r}, {width!r}")
    args = dict(hfov_deg=hfov_deg, altitude_m=altitude_m, pitch_deg=pitch_deg, yaw_deg=yaw_deg, roll_deg=roll_deg)
    sizes = {int(v.numel()) for v in args.values() if isinstance(v, torch.Tensor) and v.ndim > 0}
    if batch_size is None:
        batch_size = sizes.pop() if len(sizes) == 1 else 1
    if sizes - {batch_size}:
        raise ValueError(f"pose tensors disagree on the batch size: {sorted(sizes | {batch_size})}")
    check_finite_range("hfov_deg", hfov_deg, 0.0, 179.0, lo_open=True, unit="deg")
    check_finite_range("altitude_m", altitude_m, 0.0, lo_open=True, unit="m (the camera must be above the sea)")
    check_finite_range("pitch_deg", pitch_deg, -90.0, 90.0, unit="deg")
    check_finite_range("yaw_deg", yaw_deg)
    check_finite_range("roll_deg", roll_deg, -180.0, 180.0, unit="deg")
    B = batch_size
    d2r = math.pi / 180.0
    hfov = _batch(hfov_deg, B, dtype, device) * d2r
    alt = _batch(altitude_m, B, dtype, device)
    p = _batch(pitch_deg, B, dtype, device) * d2r
    y = _batch(yaw_deg, B, dtype, device) * d2r
    r = _batch(roll_deg, B, dtype, device) * d2r
    zero, one = torch.zeros_like(p), torch.ones_like(p)
    # camera axes in world coordinates
    fwd = torch.stack([torch.cos(p) * torch.cos(y), torch.cos(p) * torch.sin(y), torch.sin(p)], -1)
    right0 = torch.stack([torch.sin(y), -torch.cos(y), zero], -1)
    down0 = torch.linalg.cross(fwd, right0)
    right = torch.cos(r)[:, None] * right0 + torch.sin(r)[:, None] * down0
    down = -torch.sin(r)[:, None] * right0 + torch.cos(r)[:, None] * down0
    R = torch.stack([right, down, fwd], 1)  # rows: camera axes → world→camera rotation
    centre = torch.stack([zero, zero, alt], -1)
    t = -(R @ centre[..., None])[..., 0]
    bottom = torch.stack([zero, zero, zero, one], -1)[:, None, :]
    extrinsics = torch.cat([torch.cat([R, t[..., None]], -1), bottom], 1)
    f = (width / 2.0) / torch.tan(hfov / 2.0)
    cx = torch.full_like(f, (width - 1) / 2.0)
    cy = torch.full_like(f, (height - 1) / 2.0)
    intrinsics = torch.stack(
        [
            torch.stack([f, zero, cx, zero], -1),
            torch.stack([zero, f, cy, zero], -1),
            torch.stack([zero, zero, one, zero], -1),
            torch.stack([zero, zero, zero, one], -1),
        ],
        1,
    )
    h = torch.full((B,), float(height), dtype=dtype, device=device)
    w = torch.full((B,), float(width), dtype=dtype, device=device)
    return PinholeCamera(intrinsics, extrinsics, h, w)


@dataclass
class ViewGeometry:
    """Per-pixel view geometry, every field (B, H, W).

    Attributes:
        view_zenith: sea pixels: θ̂, zenith angle of the line of sight sea → sensor at the hit
            point, against the local vertical (which tilts with range on a sphere) [rad];
            sky pixels: zenith angle of the ray itself, the direction whose sky radiance they see
            (> π/2 for rays between the horizontal and the depressed horizon).
        view_azimuth: world azimuth of the LOS sea → sensor (sea pixels) or of the reversed ray
            (sky pixels) [rad], from +x towards +y, in (−π, π].
        is_sea: the ray meets the sea.
        range_m: slant range to the sea [m] (inf for sky pixels).
    """

    view_zenith: torch.Tensor
    view_azimuth: torch.Tensor
    is_sea: torch.Tensor
    range_m: torch.Tensor
    cos_view_zenith: torch.Tensor  # float64: cos θ̂ (sea) or cos of the ray's zenith (sky), exact near 90°


def view_geometry(
    cameras: PinholeCamera, earth_radius_m: float = EARTH_RADIUS_M, *, chunk: int = 4
) -> ViewGeometry:
    """Per-pixel view geometry of a batch of kornia cameras over the sea.

    Rays come from ``kornia.geometry.depth.unproject_meshgrid`` (pixel centres at integers) and
    are rotated to world axes. The sphere intersection is computed in float64 in a
    cancellation-free form: with P the camera relative to the Earth's centre and d the unit ray,
    b = P·d, c = |P|² − R² (written as |C|² + 2 C_z R), the near root is s = c / (−b + √(b² − c))
    and cos θ̂ = √(b² − c) / R, exact up to the horizon where it tends to 0.

    Args:
        cameras: kornia ``PinholeCamera`` with B cameras of one image size.
        earth_radius_m: R [m]; ``float('inf')`` for a flat sea.
        chunk: images processed at once (bounds the float64 temporaries).

    Returns:
        :class:`ViewGeometry` in the cameras' dtype (``cos_view_zenith`` in float64).
    """
    check_finite_range("earth_radius_m", earth_radius_m, 0.0, math.inf, lo_open=True, unit="m")
    H, W = int(cameras.height[0].item()), int(cameras.width[0].item())
    if not (torch.all(cameras.height == H) and torch.all(cameras.width == W)):
        raise ValueError("cameras: every camera of a batch must have the same image size")
    dtype = cameras.intrinsics.dtype
    dev = cameras.device()
    flat = math.isinf(earth_radius_m)
    out: dict[str, list[torch.Tensor]] = {k: [] for k in ("vz", "va", "sea", "rng", "cz")}
    for i in range(0, cameras.batch_size, chunk):
        sl = slice(i, i + chunk)
        K = cameras.camera_matrix[sl].to(torch.float64)
        Rm = cameras.rotation_matrix[sl].to(torch.float64)
        t = cameras.translation_vector[sl].to(torch.float64)  # (b, 3, 1)
        C = -(Rm.transpose(-1, -2) @ t)[..., 0]  # camera centre in world (b, 3)
        rays = unproject_meshgrid(H, W, K, normalize_points=True, device=dev, dtype=torch.float64)
        d = torch.einsum("bhwi,bij->bhwj", rays, Rm)  # world ray = Rᵀ d_cam
        dx, dy, dz = d.unbind(-1)
        cz = C[:, 2, None, None]
        if (C[:, 2] <= 0).any():
            raise ValueError("cameras: every camera centre must be above the sea (z > 0)")
        if flat:
            sea = dz < 0
            cos_t = (-dz).clamp_min(0.0)
            s = torch.where(sea, cz / torch.where(sea, -dz, torch.ones_like(dz)), torch.full_like(dz, math.inf))
        else:
            Re = earth_radius_m
            b = C[:, 0, None, None] * dx + C[:, 1, None, None] * dy + (cz + Re) * dz
            c = (C[:, 0] ** 2 + C[:, 1] ** 2 + C[:, 2] ** 2 + 2.0 * C[:, 2] * Re)[:, None, None]
            disc = b * b - c
            sea = (b < 0) & (disc >= 0)
            root = torch.sqrt(disc.clamp_min(0.0))
            s = torch.where(sea, c / torch.where(sea, root - b, torch.ones_like(b)), torch.full_like(b, math.inf))
            cos_t = root / Re
        cz_sky = dz  # cos of the ray's own zenith angle
        cos_all = torch.where(sea, cos_t, cz_sky)
        out["cz"].append(cos_all)
        out["vz"].append(torch.acos(cos_all.clamp(-1.0, 1.0)))
        out["va"].append(torch.atan2(-dy, -dx))
        out["sea"].append(sea)
        out["rng"].append(s)
    cat = {k: torch.cat(v) for k, v in out.items()}
    return ViewGeometry(
        view_zenith=cat["vz"].to(dtype),
        view_azimuth=cat["va"].to(dtype),
        is_sea=cat["sea"],
        range_m=cat["rng"].to(dtype),
        cos_view_zenith=cat["cz"],
    )

"""Cameras (kornia ``PinholeCamera``) and per-pixel view geometry over a spherical or flat sea.

Conventions (``docs/physics.md`` §2, §9): world frame right-handed, z up, origin at sea level under
the sensor; azimuths from +x towards +y. Camera extrinsics are world → camera with OpenCV axes
(x right, y down, z forward), pixel centres at integer coordinates (kornia's convention). The sea is
a sphere of radius ``earth_radius_m`` centred at (0, 0, −R) (``float('inf')``: the plane z = 0).
"""

from __future__ import annotations

import math
from typing import Any

import torch
from kornia.geometry.camera import PinholeCamera
from kornia.geometry.conversions import normalize_points_with_intrinsics
from kornia.geometry.depth import unproject_meshgrid

from ._validation import check_finite_range, per_batch

__all__ = ["EARTH_RADIUS_M", "make_camera", "ViewGeometry", "view_geometry", "CameraGeometry", "slant_range",
           "turned_axes", "ray_component"]

EARTH_RADIUS_M = 6_371_000.0


def check_pose(hfov_deg: Any, altitude_m: Any, pitch_deg: Any, yaw_deg: Any, roll_deg: Any) -> None:
    """``ValueError`` naming the field unless the pose is one :func:`make_camera` accepts: hfov in
    (0, 179] deg, altitude > 0 m, pitch in [−90, 90] deg, yaw finite, roll in [−180, 180] deg."""
    check_finite_range("hfov_deg", hfov_deg, 0.0, 179.0, lo_open=True, unit="deg")
    check_finite_range("altitude_m", altitude_m, 0.0, lo_open=True, unit="m (the camera must be above the sea)")
    check_finite_range("pitch_deg", pitch_deg, -90.0, 90.0, unit="deg")
    check_finite_range("yaw_deg", yaw_deg)
    check_finite_range("roll_deg", roll_deg, -180.0, 180.0, unit="deg")


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
    check_pose(hfov_deg, altitude_m, pitch_deg, yaw_deg, roll_deg)
    B = batch_size
    d2r = math.pi / 180.0
    hfov = per_batch("hfov_deg", hfov_deg, B, dtype, device) * d2r
    alt = per_batch("altitude_m", altitude_m, B, dtype, device)
    p = per_batch("pitch_deg", pitch_deg, B, dtype, device) * d2r
    y = per_batch("yaw_deg", yaw_deg, B, dtype, device) * d2r
    r = per_batch("roll_deg", roll_deg, B, dtype, device) * d2r
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


class ViewGeometry:
    """Per-pixel view geometry, every field (B, H, W).

    Attributes:
        cos_view_zenith: sea pixels: cos θ̂, θ̂ the zenith angle of the line of sight sea → sensor
            at the hit point, against the local vertical (which tilts with range on a sphere);
            sky pixels: cos of the zenith angle of the ray itself, the direction whose sky radiance
            they see (< 0 for rays between the horizontal and the depressed horizon).
        view_zenith: arccos of the above [rad].
        view_azimuth: world azimuth of the LOS sea → sensor (sea pixels) or of the reversed ray
            (sky pixels) [rad], from +x towards +y, in (−π, π].
        is_sea: the ray meets the sea.
        dx, dy: the unit ray's world x and y components (camera → scene); the line of sight sea →
            sensor is −(dx, dy) horizontally.
        range_m: slant range to the sea [m] (inf for sky pixels).
        altitude_m: (B,) altitude of each camera above the sea [m].

    ``view_zenith``, ``view_azimuth`` and ``range_m`` are computed on first access (a renderer of
    isotropic seas never needs the azimuth, nor one without a path model the range).
    """

    def __init__(self, cos_view_zenith, is_sea, dx, dy, rng_fn):
        self.cos_view_zenith = cos_view_zenith
        self.is_sea = is_sea
        self.dx, self.dy, self._rng_fn = dx, dy, rng_fn
        self._cache: dict[str, torch.Tensor] = {}

    @property
    def view_zenith(self) -> torch.Tensor:
        if "vz" not in self._cache:
            self._cache["vz"] = torch.acos(self.cos_view_zenith.clamp(-1.0, 1.0))
        return self._cache["vz"]

    @property
    def view_azimuth(self) -> torch.Tensor:
        if "va" not in self._cache:
            self._cache["va"] = torch.atan2(-self.dy, -self.dx)
        return self._cache["va"]

    @property
    def range_m(self) -> torch.Tensor:
        if "rng" not in self._cache:
            self._cache["rng"] = self._rng_fn()
        return self._cache["rng"]


def view_geometry(
    cameras: PinholeCamera, earth_radius_m: float = EARTH_RADIUS_M, *, chunk: int = 4
) -> ViewGeometry:
    """Per-pixel view geometry of a batch of kornia cameras over the sea.

    Rays come from ``kornia.geometry.depth.unproject_meshgrid`` (pixel centres at integers) and
    are rotated to world axes. By spherical symmetry a camera at P (relative to the Earth's centre)
    is at altitude h = |P| − R above the sea point under it, with local vertical n̂ = P/|P|. With
    d the unit ray and dz = d·n̂, b = |P| dz and c = h (2R + h), the near root of the intersection
    is s = c / (−b + √(b² − c)) and cos θ̂ = √(b² − c) / R; written as
    b² − c = (R + h)² (dz − s_h)(dz + s_h), s_h = √(h(2R + h))/(R + h) the sine of the horizon dip,
    both are free of cancellation up to the horizon, in float32 too (per-camera constants in
    float64). World azimuths use the world x, y axes (the scene is small against R).

    Args:
        cameras: kornia ``PinholeCamera`` with B cameras of one image size.
        earth_radius_m: R [m]; ``float('inf')`` for a flat sea.
        chunk: images processed at once (bounds the temporaries).

    Returns:
        :class:`ViewGeometry` in the cameras' dtype.
    """
    geo = CameraGeometry(cameras, earth_radius_m)
    parts = [geo.pixels(slice(i, i + chunk)) for i in range(0, geo.batch_size, chunk)]
    cat = lambda k: torch.cat([p[k] for p in parts]) if len(parts) > 1 else parts[0][k]  # noqa: E731
    cz, sea, dz = cat("cos"), cat("sea"), cat("dz")
    out = ViewGeometry(cz, sea, cat("dx"), cat("dy"), lambda: geo.slant_range(cz, sea, dz))
    out.altitude_m = geo.alt.to(geo.dtype)
    out.earth_radius_m = float(earth_radius_m)
    return out


def slant_range(cos_t: torch.Tensor, altitude: torch.Tensor, earth_radius_m: float) -> torch.Tensor:
    """Slant range [m] from a sensor at altitude h to the sea point whose LOS has local zenith
    cosine cos θ̂: the near root of (R + h)² = R² + 2 R r cos θ̂ + r², written without cancellation
    as h (2R + h) / (R cos θ̂ + √(R² cos² θ̂ + h (2R + h))) (flat sea: h / cos θ̂)."""
    c = cos_t.clamp(0.0, 1.0)
    if math.isinf(earth_radius_m):
        return altitude / c.clamp_min(1e-12)
    num = altitude * (2.0 * earth_radius_m + altitude)
    rc = earth_radius_m * c
    return num / (rc + torch.sqrt(rc * rc + num))


def turned_axes(A: torch.Tensor, offset: torch.Tensor) -> torch.Tensor:
    """World x and y axes turned by −``offset`` (b,) [rad], in camera axes (b, 2, 3), from ``A`` (b, 3, 3)
    (world x, y, vertical in camera axes): x' = cos o x − sin o y, y' = sin o x + cos o y, so that a
    ray's components along them have atan2 = the ray's azimuth + offset."""
    co, so = torch.cos(offset)[:, None], torch.sin(offset)[:, None]
    return torch.stack([co * A[:, 0] - so * A[:, 1], so * A[:, 0] + co * A[:, 1]], 1)


def ray_component(a: torch.Tensor, x: torch.Tensor, y: torch.Tensor, inv: torch.Tensor | None,
               out: torch.Tensor | None = None) -> torch.Tensor:
    """a · (x, y, 1) / |(x, y, 1)|: a world axis ``a`` (b, 3, ...) in camera axes against the unit ray
    of normalized image coordinates (x, y) (``inv`` = 1/|(x, y, 1)|), broadcast over (x, y); into
    ``out`` if given (the in-place renderer's workspace)."""
    res = torch.add(a[:, 0] * x + a[:, 2], a[:, 1] * y, out=out)
    return res if inv is None else (res.mul_(inv) if out is not None else res * inv)


class CameraGeometry:
    """Per-camera constants of the sea intersection, and the per-pixel geometry of any chunk of
    cameras (``pixels(slice)``), so that a renderer can stream images without holding the batch.

    See :func:`view_geometry` for the formulas.
    """

    def __init__(self, cameras: PinholeCamera, earth_radius_m: float = EARTH_RADIUS_M):
        check_finite_range("earth_radius_m", earth_radius_m, 0.0, math.inf, lo_open=True, unit="m")
        H, W = int(cameras.height[0].item()), int(cameras.width[0].item())
        if not (torch.all(cameras.height == H) and torch.all(cameras.width == W)):
            raise ValueError("cameras: every camera of a batch must have the same image size")
        self.cameras, self.H, self.W = cameras, H, W
        self.batch_size = cameras.batch_size
        self.dtype = dtype = cameras.intrinsics.dtype
        self.device = dev = cameras.device()
        self.flat = flat = math.isinf(earth_radius_m)
        self.earth_radius_m = float(earth_radius_m)
        centres = -(cameras.rotation_matrix.transpose(-1, -2) @ cameras.translation_vector)[..., 0]
        self.centres = centres  # world [m], (B, 3), differentiable in the pose
        P = centres.to(torch.float64)
        if not flat:
            P = P + torch.tensor([0.0, 0.0, earth_radius_m], dtype=torch.float64, device=dev)
        # Spherical symmetry: a camera anywhere is a camera at altitude h = |P| − R above the point
        # of the sea under it, whose local vertical is n̂ = P/|P| (flat sea: n̂ = z, h = C_z).
        alt = P[:, 2] if flat else P.norm(dim=-1) - earth_radius_m
        if bool((~(alt > 0)).any()):
            raise ValueError("cameras: every camera centre must be above the sea (altitude > 0)")
        self.alt = alt
        up = torch.nn.functional.normalize(P, dim=-1) if not flat else P.new_tensor([0.0, 0.0, 1.0]).expand_as(P)
        # world axes x, y and the local vertical, as rows, in each camera's frame
        axes = torch.stack([P.new_tensor([1.0, 0.0, 0.0]).expand_as(P), P.new_tensor([0.0, 1.0, 0.0]).expand_as(P), up], 1)
        self.axes_cam = (axes.to(cameras.rotation_matrix.dtype) @ cameras.rotation_matrix.transpose(-1, -2)).to(dtype)
        if not flat:
            Re = earth_radius_m
            self.k_r = ((Re + alt) / Re).to(dtype)  # (R + h)/R
            self.s_h = (torch.sqrt(alt * (2 * Re + alt)) / (Re + alt)).to(dtype)  # sine of the horizon dip
            self.num = (alt * (2 * Re + alt) / (Re + alt)).to(dtype)  # h (2R + h)/(R + h) [m]

    def ray_components(self, sl: slice, need_xy: bool = True,
                       azimuth_offset: torch.Tensor | None = None) -> tuple[torch.Tensor, ...]:
        """World components of the unit ray of every pixel of the cameras ``sl``, each (b, H, W): dz
        along the local vertical and, with ``need_xy``, dx and dy along world x and y (else None).
        With ``azimuth_offset`` (b,) [rad], only (c, s): the ray's components along the world x and
        y axes turned by −offset (so that atan2(s, c) = the ray's azimuth + offset), unnormalized
        (a positive scale per pixel), for the ray's azimuth alone.

        Pixel rays come from kornia's unprojection. For a pinhole without skew the normalized ray
        (x, y, 1) has x depending on the column only and y on the row only, so kornia unprojects one
        row and one column of pixel centres and each component (a·(x, y, 1))/|(x, y, 1)| is formed
        by broadcasting: no (b, H, W, 3) tensor, two full-size operations a component. With skew,
        ``unproject_meshgrid`` does it all.
        """
        H, W = self.H, self.W
        K = self.cameras.camera_matrix[sl].to(self.dtype)
        A = self.axes_cam[sl]  # (b, 3 components, 3 camera axes)
        if azimuth_offset is not None:
            A_t = turned_axes(A, azimuth_offset)
        xy = self.separable_xy(sl)
        if xy is not None:
            x, y = xy
            # 1/|(x, y, 1)|: one full-size add (not for the unnormalized turned components)
            inv = None if azimuth_offset is not None else torch.rsqrt(x * x + (y * y + 1.0))

            def comp(i: int) -> torch.Tensor:
                if i < 2 and azimuth_offset is not None:  # unnormalized, along the turned axes
                    return ray_component(A_t[:, i, :, None, None], x, y, None)
                return ray_component(A[:, i, :, None, None], x, y, inv)
        else:
            rays = unproject_meshgrid(H, W, K, normalize_points=True, device=self.device, dtype=self.dtype)

            def comp(i: int) -> torch.Tensor:
                a = A_t[:, i] if i < 2 and azimuth_offset is not None else A[:, i]
                return (rays * a[:, None, None, :]).sum(-1)

        if azimuth_offset is not None:
            return comp(0), comp(1)
        return (comp(2), comp(0), comp(1)) if need_xy else (comp(2), None, None)

    def separable_xy(self, sl: slice) -> tuple[torch.Tensor, torch.Tensor] | None:
        """Normalized image coordinates of the pixel centres of the cameras ``sl``, x (b, 1, W) by
        column and y (b, H, 1) by row, from kornia's unprojection; None for a camera with skew
        (where x depends on the row too)."""
        K = self.cameras.camera_matrix[sl].to(self.dtype)
        if not bool((K[:, 0, 1] == 0).all()):
            return None
        b_ = K.shape[0]
        u = torch.arange(self.W, dtype=self.dtype, device=self.device)
        v = torch.arange(self.H, dtype=self.dtype, device=self.device)
        row = torch.stack([u, torch.zeros_like(u)], -1).expand(b_, self.W, 2)
        col = torch.stack([torch.zeros_like(v), v], -1).expand(b_, self.H, 2)
        x = normalize_points_with_intrinsics(row, K)[..., 0][:, None, :]  # (b, 1, W)
        y = normalize_points_with_intrinsics(col, K)[..., 1][:, :, None]  # (b, H, 1)
        return x, y

    @property
    def requires_grad(self) -> bool:
        """Whether the per-pixel rays carry gradients (a pose or intrinsics that require grad)."""
        return torch.is_grad_enabled() and any(
            t.requires_grad for t in (self.axes_cam, self.cameras.intrinsics, self.alt))

    def pixels(self, sl: slice, need_xy: bool = True) -> dict[str, torch.Tensor]:
        """cos θ̂ (sea) / cos of the ray's zenith (sky), the sea mask, and the unit ray's local-vertical
        component (and, with ``need_xy``, its world x and y components), for the cameras ``sl``:
        each (b, H, W). See :meth:`ray_components`."""
        dz, dx, dy = self.ray_components(sl, need_xy)
        if self.flat:
            sea = dz < 0
            cos_t = -dz
        else:
            # b² − c = (R + h)² (dz² − s_h²): the sea is met iff −dz > s_h; cancellation-free.
            sh = self.s_h[sl, None, None]
            sea = -dz > sh
            cos_t = self.k_r[sl, None, None] * torch.sqrt(((-dz - sh) * (-dz + sh)).clamp_min(0.0))  # √(b² − c)/R
        out = {"cos": torch.where(sea, cos_t, dz), "sea": sea, "dz": dz}
        if need_xy:
            out["dx"], out["dy"] = dx, dy
        return out

    def _rays(self, sl: slice, uv: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
        """World components (dz along the local vertical, dx, dy) of the unit rays through the pixel
        coordinates ``uv`` (N, 2) of the cameras ``sl``: each (b, N)."""
        K = self.cameras.camera_matrix[sl].to(self.dtype)
        xy = normalize_points_with_intrinsics(uv.to(self.dtype).expand(K.shape[0], -1, 2), K)
        x, y = xy[..., 0], xy[..., 1]
        inv = torch.rsqrt(x * x + y * y + 1.0)
        A = self.axes_cam[sl, :, :, None]
        return tuple(ray_component(A[:, i], x, y, inv) for i in (2, 0, 1))

    def border(self, sl: slice = slice(None)) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
        """Ray components (dz, dx, dy), each (b, 2(H + W) − 4), of the pixels on the image's border,
        in order around it (top row left to right, right column, bottom row right to left, left
        column): a closed loop. A smooth function of the ray (its local-vertical component, its
        azimuth) takes its extremes over the image on this loop, unless the image contains a
        critical point of it: the nadir or the zenith (:meth:`poles_in_view`)."""
        H, W = self.H, self.W
        dev = self.device
        u = torch.arange(W, dtype=torch.float64, device=dev)
        v = torch.arange(H, dtype=torch.float64, device=dev)
        top = torch.stack([u, torch.zeros_like(u)], -1)
        right = torch.stack([torch.full_like(v[1:], W - 1.0), v[1:]], -1)
        bottom = torch.stack([u.flip(0)[1:], torch.full_like(u[1:], H - 1.0)], -1) if H > 1 else top[:0]
        left = torch.stack([torch.zeros_like(v[1:-1]), v.flip(0)[1:-1]], -1) if W > 1 else top[:0]
        return self._rays(sl, torch.cat([top, right, bottom, left])[None])

    def poles_in_view(self, sl: slice = slice(None)) -> tuple[torch.Tensor, torch.Tensor]:
        """Whether the nadir and the zenith (the local vertical through the camera) project into the
        image, or within a pixel of it: (b,) bool each."""
        K = self.cameras.camera_matrix[sl].to(torch.float64)[:, :3, :3]
        up = self.axes_cam[sl, 2].to(torch.float64)  # the local vertical in camera axes (b, 3)
        out = []
        for d in (-up, up):
            p = (K @ d[..., None])[..., 0]
            z = p[:, 2]
            zs = torch.where(z > 0, z, torch.ones_like(z))
            u, v = p[:, 0] / zs, p[:, 1] / zs
            out.append((z > 0) & (u >= -1.0) & (u <= self.W) & (v >= -1.0) & (v <= self.H))
        return out[0], out[1]

    def slant_range(self, cz: torch.Tensor, sea: torch.Tensor, dz: torch.Tensor, sl: slice = slice(None)) -> torch.Tensor:
        """Slant range [m] to the sea (inf for sky pixels) from ``pixels(sl)``'s output."""
        if self.flat:
            rng = self.alt.to(self.dtype)[sl, None, None] / torch.where(sea, -dz, torch.ones_like(dz))
        else:  # c / (√(b² − c) − b) = h(2R + h)/(R + h) / (√(dz² − s_h²) − dz)
            root = cz / self.k_r[sl, None, None]
            rng = self.num[sl, None, None] / torch.where(sea, root - dz, torch.ones_like(dz))
        return torch.where(sea, rng, torch.full_like(rng, math.inf))

"""The sun's glitter on one wave-field realization, without sampling noise: the glitter spots
themselves, found by Newton's method from ray hits and weighted by their image area.

A plain ray average needs thousands of rays per pixel where the sun glints (a ray meets the sun's
disk in its mirror about once in a thousand); this finds the spots instead (``docs/glitter.md``).

Method
------
1. **Surface.** Every band of the :class:`~roughsea_torch.waves.WaveField` as mirror facets
   (:class:`~roughsea_torch.raytrace_surface.TracedSurface` with ``k_max = inf``): the elevation η and
   the field's spectral slope s = −∇η, each band's tile interpolated bilinearly, as
   :meth:`WaveField.sample` returns them.
2. **Starts.** Rays through i.i.d. points of each pixel (:func:`~roughsea_torch.raytrace.camera_rays`)
   meet the surface first at visible points (:func:`~roughsea_torch.raytrace_surface.march_first_hits`).
3. **Newton.** From each hit, on the horizontal position x: r(x) = s(x) − s_g(x), s_g the slope whose
   facet mirrors the sun's centre ω_sun into the camera, s_g = (v + ω_sun)_xy / (v + ω_sun)_z with
   v the unit vector from the surface point (x, η(x)) to the camera; Jacobian ∂s/∂x by central
   differences (step ``fd_step_m``; s_g's own change, ~1/range per metre against curvatures of
   10–100 m⁻¹, is left out of the Jacobian, not of r); steps capped at ``max_step_m``. Converged
   points (|r| < 1e-10) are merged within ``merge_m``.
4. **Visibility.** A spot counts if the ray from the camera to it first meets the surface there
   (within 1 mm along the ray): a crest in front hides it. The sun's masking (a crest between the spot
   and the sun) is not applied.
5. **Weight.** The spot covers, to first order, the horizontal area π α² |det J_sun| / |det ∂s/∂x|
   (the sun's ellipse in slope space, :mod:`roughsea_torch.sun`, pulled back by the slope map). Its
   area is integrated instead on a grid × grid box about it, in the frame of the linearized ellipse
   (half-widths 1.5 semi-axes, at most 4.5 times the extent the third-order term allows): the share
   of the box's points whose facet mirrors the camera's ray within α of the sun's centre. The camera
   sees that area times |det ∂(u, v)/∂x| (the pixel coordinates of the surface point (x, η(x)), by
   central differences through the kornia camera). Its radiance is ρ(Ω) L_sun (Fresnel at the
   facet, L_sun = E_sun / Ω_sun), so it adds ρ L_sun × (image area in pixels²) to the mean radiance
   of the pixel it falls in. The linearized area, capped where |det ∂s/∂x| → 0 at the area the
   third-order term allows (:mod:`roughsea_torch.glitter`), is returned alongside as a check
   (``docs/glitter.md`` §2 compares the two), with the share of the glint in spots that reach their
   box's edge (elongated spots, or two spots of a pair close together).

Limits: spots on or very near a pixel edge go wholly to one pixel; a spot that is hidden only in
part counts whole or not at all; spots not reached by any Newton start are missed (the returned
``starts_per_spot`` says how well the starts cover them).
"""

from __future__ import annotations

import math
from typing import Any

import torch
from kornia.geometry.camera import PinholeCamera

from .optics import fresnel_reflectance
from .raytrace import camera_rays
from .raytrace_surface import TracedSurface, check_count, check_positive, march_first_hits
from .waves import WaveField

__all__ = ["glitter_spots"]

_BOX = 1.5  # half-width of the box about a spot, in its linearized semi-axes


def _sun_vector(zenith: float, azimuth: float, dtype: torch.dtype, device: Any) -> torch.Tensor:
    return torch.tensor([math.sin(zenith) * math.cos(azimuth), math.sin(zenith) * math.sin(azimuth), math.cos(zenith)],
                        dtype=dtype, device=device)


def _specular(surf: TracedSurface, centre: torch.Tensor, w: torch.Tensor, x: torch.Tensor, y: torch.Tensor
              ) -> tuple[torch.Tensor, ...]:
    """At points x, y (P,): η, the slope s, the specular slope s_g, and v (P, 3) towards the camera."""
    eta, sx, sy = (t[0] for t in surf(x[None], y[None]))
    v = torch.stack([centre[0] - x, centre[1] - y, centre[2] - eta], -1)
    v = v / v.norm(dim=-1, keepdim=True)
    p = v + w
    return eta, sx, sy, p[:, 0] / p[:, 2], p[:, 1] / p[:, 2], v


def _slope_jacobian(surf: TracedSurface, x: torch.Tensor, y: torch.Tensor, h: float) -> tuple[torch.Tensor, ...]:
    """∂s/∂x by central differences of step h: (∂s_x/∂x, ∂s_x/∂y, ∂s_y/∂x, ∂s_y/∂y)."""
    xs = torch.cat([x + h, x - h, x, x])
    ys = torch.cat([y, y, y + h, y - h])
    _, sx, sy = (t[0] for t in surf(xs[None], ys[None]))
    n = x.shape[0]
    d = lambda t, i, j: (t[i * n:(i + 1) * n] - t[j * n:(j + 1) * n]) / (2.0 * h)  # noqa: E731
    return d(sx, 0, 1), d(sx, 2, 3), d(sy, 0, 1), d(sy, 2, 3)


def _newton(surf: TracedSurface, centre: torch.Tensor, w: torch.Tensor, x: torch.Tensor, y: torch.Tensor,
            iterations: int, h: float, max_step: float) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
    """Newton on r(x) = s(x) − s_g(x) from (x, y); (x, y, converged)."""
    for _ in range(iterations):
        _, sx, sy, gx, gy, _ = _specular(surf, centre, w, x, y)
        rx, ry = sx - gx, sy - gy
        a, b, c, d = _slope_jacobian(surf, x, y, h)
        det = a * d - b * c
        det = torch.where(det.abs() > 1e-12, det, torch.full_like(det, 1e-12))
        dx, dy = -(d * rx - b * ry) / det, -(-c * rx + a * ry) / det
        n = torch.sqrt(dx * dx + dy * dy)
        scale = torch.clamp(max_step / n.clamp_min(1e-300), max=1.0)
        x, y = x + dx * scale, y + dy * scale
    _, sx, sy, gx, gy, _ = _specular(surf, centre, w, x, y)
    return x, y, torch.sqrt((sx - gx) ** 2 + (sy - gy) ** 2) < 1e-10


def _merge(x: torch.Tensor, y: torch.Tensor, merge_m: float) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
    """Unique points on a grid of ``merge_m``: (x, y, starts that converged to each)."""
    key = torch.stack([torch.round(x / merge_m), torch.round(y / merge_m)], -1).to(torch.int64)
    uniq, inv, counts = torch.unique(key, dim=0, return_inverse=True, return_counts=True)
    first = torch.full((uniq.shape[0],), x.shape[0], dtype=torch.int64).scatter_reduce(
        0, inv, torch.arange(x.shape[0]), reduce="amin")
    return x[first], y[first], counts


def _spot_areas(surf: TracedSurface, c: torch.Tensor, w: torch.Tensor, xs: torch.Tensor, ys: torch.Tensor,
                sgx: torch.Tensor, sgy: torch.Tensor, qz: torch.Tensor, alpha: float, h: float, third: float, grid: int
                ) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
    """Horizontal area [m²] of each spot: the share of a grid×grid box about it whose facets mirror the
    camera's ray into the sun's disk (angle to ω_sun ≤ α), times the box's area; whether the spot
    touches the box's edge; and the linearized area π α² |det J_sun| / |det ∂s/∂x| with |det ∂s/∂x| floored
    at |λ_big| λ_c (λ_c = √(aT/2), :mod:`roughsea_torch.glitter`), for comparison.

    The box: the linearized spot x₀ + M u, |u| ≤ 1, M = (∂s/∂x)⁻¹ J_sun α (SVD: semi-axes σᵢ along
    the left singular vectors), half-widths 1.5 min(σᵢ, 3 r_max), r_max = √(2a/T) the extent the
    third-order term allows (a = α √|det J_sun|, T = ``third``)."""
    a, b, cc, dd = _slope_jacobian(surf, xs, ys, h)
    js = torch.stack([torch.stack([a, b], -1), torch.stack([cc, dd], -1)], -2)  # (P, 2, 2) ∂s/∂x
    ct, st = w[2], torch.sqrt(w[0] ** 2 + w[1] ** 2)
    cp, sp = (w[0] / st, w[1] / st) if float(st) > 0 else (torch.ones_like(st), torch.zeros_like(st))
    # the disk's tangent basis e1 = (ct cp, ct sp, −st), e2 = (−sp, cp, 0) and J_sun = ∂s_g/∂u (sun.py)
    j11, j21 = (ct * cp + sgx * st) / qz, (ct * sp + sgy * st) / qz
    j12, j22 = (-sp / qz).expand_as(qz), (cp / qz).expand_as(qz)
    jsun = torch.stack([torch.stack([j11, j12], -1), torch.stack([j21, j22], -1)], -2)
    det_js = torch.linalg.det(js).abs().clamp_min(1e-300)
    det_sun = torch.linalg.det(jsun).abs()
    r_max = torch.sqrt(2.0 * alpha * torch.sqrt(det_sun) / third)
    big = torch.linalg.svdvals(js)[:, 0]
    lam_c = alpha * torch.sqrt(det_sun) / r_max  # the weak eigenvalue's floor, √(aT/2)
    lin_area = math.pi * alpha ** 2 * det_sun / torch.maximum(det_js, big * lam_c)
    m = torch.linalg.solve(js, jsun) * alpha
    U, sig, _ = torch.linalg.svd(m)
    half = _BOX * torch.minimum(sig, 3.0 * r_max[:, None])  # (P, 2)
    t = (torch.arange(grid, dtype=xs.dtype, device=xs.device) + 0.5) / grid * 2.0 - 1.0
    t1, t2 = torch.meshgrid(t, t, indexing="ij")
    off = (U[:, None, None, :, 0] * (t1[None, :, :, None] * half[:, None, None, 0:1])
           + U[:, None, None, :, 1] * (t2[None, :, :, None] * half[:, None, None, 1:2]))  # (P, g, g, 2)
    inside = []
    for i in range(0, xs.shape[0], 256):  # spots in chunks: each a grid² of surface look-ups
        sl = slice(i, i + 256)
        px, py = (xs[sl, None, None] + off[sl, ..., 0]).reshape(-1), (ys[sl, None, None] + off[sl, ..., 1]).reshape(-1)
        eta, sx, sy = (t_[0] for t_ in surf(px[None], py[None]))
        v = torch.stack([c[0] - px, c[1] - py, c[2] - eta], -1)
        v = v / v.norm(dim=-1, keepdim=True)
        n = torch.stack([sx, sy, torch.ones_like(sx)], -1)
        n = n / n.norm(dim=-1, keepdim=True)
        r = 2.0 * (v * n).sum(-1, keepdim=True) * n - v  # the camera's ray mirrored by the facet
        inside.append(((r * w).sum(-1) >= math.cos(alpha)).reshape(-1, grid, grid))
    ins = torch.cat(inside)
    box = 4.0 * half[:, 0] * half[:, 1]
    edge = ins[:, 0, :].any(-1) | ins[:, -1, :].any(-1) | ins[:, :, 0].any(-1) | ins[:, :, -1].any(-1)
    return ins.to(xs.dtype).mean((-1, -2)) * box, edge, lin_area


def _image_jacobian(cams: PinholeCamera, p: torch.Tensor, sx: torch.Tensor, sy: torch.Tensor, h: float = 1e-4) -> torch.Tensor:
    """|det ∂(u, v)/∂(x, y)| [px² m⁻²] of surface points p (P, 3) with slopes s: the pixel coordinates of
    (x, y, η(x, y)) by central differences of step h along the surface (dη = −s · dx)."""
    n = p.shape[0]
    steps = ((1, 0), (-1, 0), (0, 1), (0, -1))
    pts = torch.stack([p + torch.stack([torch.full((n,), a * h, dtype=p.dtype, device=p.device),
                                        torch.full((n,), b * h, dtype=p.dtype, device=p.device),
                                        -(a * h) * sx - (b * h) * sy], -1) for a, b in steps])  # (4, P, 3)
    uv = cams.project(pts.reshape(1, -1, 3)).reshape(4, -1, 2)
    du, dv = (uv[0] - uv[1]) / (2 * h), (uv[2] - uv[3]) / (2 * h)
    return (du[:, 0] * dv[:, 1] - du[:, 1] * dv[:, 0]).abs()


def glitter_spots(cameras: PinholeCamera, field: WaveField, sun_zenith: float, sun_azimuth: float, sun_irradiance: float,
                  refractive_index: Any, *, time_s: float = 0.0, sun_radius: float = math.radians(0.2666),
                  rays_per_pixel: int = 64, ray_seed: int = 0, iterations: int = 30, fd_step_m: float = 2e-4,
                  max_step_m: float = 0.01, merge_m: float = 2e-5, third_derivative: float = 1e3,
                  grid: int = 48
                  ) -> dict[str, Any]:
    """The glint of one realization per pixel from its glitter spots (module docstring).

    Args:
        cameras: one kornia ``PinholeCamera`` (B = 1), H × W pixels (keep it small: a near-range patch).
        field: a :class:`WaveField` of one image, float64; every band is traced.
        sun_zenith, sun_azimuth: the sun's centre [rad], azimuth in the world frame (from +x towards +y).
        sun_irradiance: E_sun [W m⁻²]; sun_radius: α [rad].
        refractive_index: the water's m = n + i k (complex or a 0-d complex tensor).
        time_s: the realization's time [s].
        rays_per_pixel: Newton starts per pixel (ray hits).
        ray_seed, iterations, fd_step_m, max_step_m, merge_m: of the starts and of Newton's method.
        third_derivative: the rms third derivative T [m⁻²] of the surface
            (:class:`~roughsea_torch.glitter.CurvatureMoments`): it sizes the box about a nearly
            degenerate spot and caps the linearized area (``_spot_areas``).
        grid: points per side of the box about each spot.

    Returns:
        dict: 'glint' (H, W) mean glint radiance of each pixel [W m⁻² sr⁻¹] from the box-integrated
        spot areas, 'linearized_glint' (H, W) the same from the linearized, capped areas; 'spots'
        (number of visible spots), 'spot_u', 'spot_v' their pixel coordinates, 'spot_x', 'spot_y'
        their world position [m], 'spot_weight' each one's radiance × image area
        [W m⁻² sr⁻¹ px²], 'spots_per_pixel' (H, W) counts, 'hidden' (spots hidden by a crest),
        'starts_per_spot' (mean Newton starts per spot), 'converged_fraction', 'edge_share' (share of
        the glint in spots that reach the edge of their box: their area may be underestimated).
    """
    S = check_count("rays_per_pixel", rays_per_pixel, 1)
    check_positive("sun_irradiance", sun_irradiance + 1e-300, "W m-2")
    if not isinstance(field, WaveField) or field.batch_size != 1 or field.dtype != torch.float64:
        raise ValueError("field must be a float64 WaveField of one image")
    if cameras.batch_size != 1:
        raise ValueError("cameras: one camera (B = 1)")
    dt, dev = torch.float64, field.device
    H, W = int(cameras.height[0].item()), int(cameras.width[0].item())
    surf = TracedSurface(field, time_s, math.inf)
    cams = PinholeCamera(cameras.intrinsics.to(dt), cameras.extrinsics.to(dt), cameras.height.to(dt), cameras.width.to(dt))
    centres, d = camera_rays(cams, S, None, ray_seed, dt)
    hits = march_first_hits(centres, d.reshape(1, -1, 3), surf)
    ok = hits["hit"][0]
    x0, y0 = hits["x"][0][ok], hits["y"][0][ok]
    c = centres[0]
    w = _sun_vector(sun_zenith, sun_azimuth, dt, dev)
    x, y, conv = _newton(surf, c, w, x0, y0, iterations, fd_step_m, max_step_m)
    xs, ys, counts = _merge(x[conv], y[conv], merge_m)
    eta, sx, sy, gx, gy, v = _specular(surf, c, w, xs, ys)
    # visibility: the camera's ray to the spot meets the surface first there
    p = torch.stack([xs, ys, eta], -1)
    dist = (p - c).norm(dim=-1)
    tr = march_first_hits(centres, ((p - c) / dist[:, None])[None], surf)
    visible = tr["hit"][0] & ((tr["t"][0] - dist).abs() < 1e-3)
    # each spot's horizontal area, integrated over a grid about it (module docstring, 5)
    q = v + w
    sgx, sgy = q[:, 0] / q[:, 2], q[:, 1] / q[:, 2]
    area_h, edge, lin_area = _spot_areas(surf, c, w, xs, ys, sgx, sgy, q[:, 2], sun_radius, fd_step_m, third_derivative,
                                         grid)
    jac_img = _image_jacobian(cams, p, sx, sy)
    n_hat = torch.stack([sx, sy, torch.ones_like(sx)], -1)
    cos_inc = (n_hat * v).sum(-1) / n_hat.norm(dim=-1)
    rho = fresnel_reflectance(cos_inc.clamp(0.0, 1.0), refractive_index)
    l_sun = sun_irradiance / (4.0 * math.pi * math.sin(0.5 * sun_radius) ** 2)
    weight = rho * l_sun * area_h * jac_img
    uv0 = cams.project(p[None])[0]
    col, row = torch.round(uv0[:, 0]).long(), torch.round(uv0[:, 1]).long()
    inside = visible & (col >= 0) & (col < W) & (row >= 0) & (row < H)
    flat = (row * W + col)[inside]
    glint = torch.zeros(H * W, dtype=dt, device=dev).index_add(0, flat, weight[inside]).reshape(H, W)
    n_pix = torch.zeros(H * W, dtype=dt, device=dev).index_add(0, flat, torch.ones_like(weight[inside])).reshape(H, W)
    return {"glint": glint, "spots": int(inside.sum()), "spot_u": uv0[inside, 0], "spot_v": uv0[inside, 1],
            "spot_x": xs[inside], "spot_y": ys[inside],
            "spot_weight": weight[inside], "spots_per_pixel": n_pix, "hidden": int((~visible).sum()),
            "starts_per_spot": float(counts.double().mean()), "converged_fraction": float(conv.double().mean()),
            "edge_share": float(weight[inside & edge].sum() / weight[inside].sum().clamp_min(1e-300)),
            "linearized_glint": torch.zeros(H * W, dtype=dt, device=dev).index_add(
                0, flat, (rho * l_sun * lin_area * jac_img)[inside]).reshape(H, W)}

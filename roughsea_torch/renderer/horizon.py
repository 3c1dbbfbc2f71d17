"""Area-weighted pixels on the horizon: a pixel that the horizon crosses reads the mix of what its
area sees, f · (sea) + (1 − f) · (sky), instead of what its centre ray sees.

A real detector element integrates the irradiance over its area, so a pixel straddling the horizon
reads the area-weighted mean of the sea below the horizon and the sky above it (the pixel's
spatial response taken as a uniform square, the usual box model of a focal-plane element). Deciding
sea or sky by the centre ray gives a hard one-pixel step at the horizon, a staircase under roll.

Geometry. A ray of normalized image coordinates (x, y) (kornia's ``normalize_points_with_intrinsics``
of the pixel coordinates (u, v), any intrinsics with or without skew) meets the sea iff
g = dz + s_h < 0, dz = n̂·(x, y, 1)/|(x, y, 1)| its local-vertical component and s_h the sine of the
horizon's dip below the local horizontal (0 on a flat sea): the same test as the renderer's sea
mask. The horizon is the curve g = 0 in the image (a conic); across one pixel it is replaced by the
line through the chord slopes, g ≈ a + p du + q dv on the pixel square du, dv ∈ [−½, ½], with
a = g at the centre, p = g(u + ½, v) − g(u − ½, v), q = g(u, v + ½) − g(u, v − ½). The area of the
square below that line has the closed form of the distribution function of a sum of two uniform
variables (a trapezoid): with P ≥ Q ≥ 0 the larger and smaller of |p|, |q|, t = −a,
s = (P + Q)/2, d = (P − Q)/2,

    f = 0 (t ≤ −s),  (t + s)²/(2PQ) (−s < t ≤ −d),  ½ + t/P (|t| < d),  1 − (s − t)²/(2PQ) (d ≤ t < s),  1 (t ≥ s).

Values. Along the image axis on which g changes most (both axes, weighted, where the horizon's
slope is within a few degrees of 45°, so that the choice does not jump), the two nearest pixel
centres on the sea side (the pixel's own if it is sea, and the next; else its two neighbours towards the sea, whose
centres are sea since the line crosses the square) give the sea value at the centroid of the
pixel's sea part by linear inter- or extrapolation along that axis; the sky value likewise at the
sky part's centroid (centroids taken along the axis, from the horizon's offset g/|∂g| at the
centre). Near the image's edge, with one centre only, that centre's value. The values come from
the centre-ray render: a profile that changes within the pixel nearest the horizon is not
resolved (``docs/scenes.md``). Radiances are mixed; brightness temperatures as the radiances they
stand for. Pixels the horizon does not cross are returned bit for bit.
"""

from __future__ import annotations

import torch
from kornia.geometry.conversions import normalize_points_with_intrinsics

from ..geometry import CameraGeometry
from ..radiometry import SpectralBand, band_radiance, brightness_temperature

__all__ = ["coverage", "sea_fraction", "horizon_pixels", "blend_horizon"]


def coverage(a: torch.Tensor, p: torch.Tensor, q: torch.Tensor) -> torch.Tensor:
    """Area fraction of the unit square du, dv ∈ [−½, ½] where a + p du + q dv < 0, exact for the
    line; any shape (broadcast), differentiable (finite gradients also where p or q is 0)."""
    P, Q = torch.maximum(p.abs(), q.abs()), torch.minimum(p.abs(), q.abs())
    t = -a
    s, d = 0.5 * (P + Q), 0.5 * (P - Q)
    one = torch.ones_like(P)
    den = torch.where(Q > 0, 2.0 * P * Q, one)
    Ps = torch.where(P > 0, P, one)
    low = (t + s).clamp_min(0.0) ** 2 / den
    high = 1.0 - (s - t).clamp_min(0.0) ** 2 / den
    mid = 0.5 + t / Ps
    f = torch.where(t <= -d, low, torch.where(t >= d, high, mid))
    f = torch.where(t <= -s, torch.zeros_like(f), torch.where(t >= s, one, f))
    return torch.where(P > 0, f, (t > 0).to(f.dtype))


def _g(cg: CameraGeometry, bi: torch.Tensor, uv: torch.Tensor) -> torch.Tensor:
    """g = dz + s_h at the pixel points ``uv`` (n, 2) of the images ``bi`` (n,): (n,)."""
    K = cg.cameras.camera_matrix.to(cg.dtype)[bi]
    xy = normalize_points_with_intrinsics(uv.to(cg.dtype)[:, None, :], K)[:, 0]
    x, y = xy[:, 0], xy[:, 1]
    a = cg.axes_cam[bi, 2]
    dz = (a[:, 0] * x + a[:, 1] * y + a[:, 2]) * torch.rsqrt(x * x + y * y + 1.0)
    return dz if cg.flat else dz + cg.s_h[bi]


def sea_fraction(cg: CameraGeometry, bi: torch.Tensor, v: torch.Tensor, u: torch.Tensor
                 ) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor, torch.Tensor]:
    """For the pixels (image ``bi``, row ``v``, column ``u``), each (n,): the area fraction f below
    the horizon (closed form, module docstring), g at the centre, and g's chord slopes (p, q) along
    u and v."""
    c = torch.stack([u, v], -1).to(cg.dtype)
    h = torch.tensor([[0.0, 0.0], [0.5, 0.0], [-0.5, 0.0], [0.0, 0.5], [0.0, -0.5]], dtype=cg.dtype, device=c.device)
    n = c.shape[0]
    g = _g(cg, bi.repeat(5), (c[None] + h[:, None]).reshape(-1, 2)).reshape(5, n)
    g0, p, q = g[0], g[1] - g[2], g[3] - g[4]
    # the fraction in float64 (the trapezoid's corners cancel in float32 when Q ≪ P)
    f = coverage(g0.double(), p.double(), q.double()).to(cg.dtype)
    return f, g0, p, q


def _crossings(Kinv: torch.Tensor, n: torch.Tensor, sh: torch.Tensor, along: int, k: torch.Tensor, length: int) -> torch.Tensor:
    """Pixel coordinates where the horizon crosses each of the lines u = k (``along`` = 1: solve for
    v) or v = k (``along`` = 0: solve for u), k (count,): (B, count, 2), NaN where it does not.

    The ray d = K⁻¹ (u, v, 1) = P + t Q along the line meets the horizon where n·d = −s_h |d|: the
    roots of (n·P + t n·Q)² = s_h² |P + t Q|² with n·d ≤ 0 (the other sign is the cone above)."""
    fixed = 1 - along
    P = Kinv[:, None, :, fixed] * k[None, :, None] + Kinv[:, None, :, 2]  # (B, count, 3)
    Q = Kinv[:, None, :, along].expand_as(P)
    nn_ = n[:, None, :]

    def dot(x: torch.Tensor, y: torch.Tensor) -> torch.Tensor:  # (a sum over a last axis of 3 is slow on the CPU)
        return x[..., 0] * y[..., 0] + x[..., 1] * y[..., 1] + x[..., 2] * y[..., 2]

    nP, nQ = dot(P, nn_), dot(Q, nn_)
    s2 = (sh * sh)[:, None]
    a = nQ * nQ - s2 * dot(Q, Q)
    b = 2.0 * (nP * nQ - s2 * dot(P, Q))
    c = nP * nP - s2 * dot(P, P)
    disc = (b * b - 4.0 * a * c).clamp_min(0.0)
    qq = -0.5 * (b + torch.copysign(disc.sqrt(), b))
    qs = torch.where(qq == 0, torch.ones_like(qq), qq)
    roots = torch.stack([torch.where(a != 0, qq / torch.where(a != 0, a, torch.ones_like(a)), torch.nan), c / qs], -1)
    nd = nP[..., None] + roots * nQ[..., None]  # n·d at the roots
    dd = (dot(P, P)[..., None] + roots * (2.0 * dot(P, Q)[..., None] + roots * dot(Q, Q)[..., None])).clamp_min(0.0).sqrt()
    good = (nd <= (0.5 * sh[:, None, None] + 1e-9) * dd) & (roots > -1.5) & (roots < length + 0.5)
    return torch.where(good, roots, torch.nan)


def horizon_pixels(cg: CameraGeometry) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
    """Indices (b, v, u) of the pixels whose square the horizon may cross, from its crossings with
    the centre line and the two edges of every column and every row (closed form,
    :func:`_crossings`): the pixels those crossings fall in. Where the horizon is within 45° of
    the rows, the pixels of column k it crosses are those between its crossings of u = k ± ½; else
    likewise by rows. No gradient; (n,) each, sorted."""
    H, W = cg.H, cg.W
    with torch.no_grad():
        K = cg.cameras.camera_matrix[:, :3, :3].double().clone()
        K[:, 0, 1] = 0.0  # the rays of kornia's normalization (the renderer's), which ignores a skew
        Kinv = torch.linalg.inv(K)
        n = cg.axes_cam[:, 2].double()
        sh = torch.zeros(K.shape[0], dtype=torch.float64, device=K.device) if cg.flat else cg.s_h.double()
        flat = []
        for along, count, length in ((1, W, H), (0, H, W)):
            lines = torch.arange(count, dtype=torch.float64, device=K.device)
            lines = torch.stack([lines - 0.5, lines, lines + 0.5], -1).reshape(-1)
            t = _crossings(Kinv, n, sh, along, lines, length)  # (B, 3 count, 2)
            bi, ki, ri = torch.nonzero(torch.isfinite(t), as_tuple=True)
            m = torch.round(t[bi, ki, ri]).long().clamp(0, length - 1)
            k = ki // 3
            v, u = (m, k) if along == 1 else (k, m)
            flat.append((bi * H + v) * W + u)
        idx = torch.unique(torch.cat(flat))
        return idx // (H * W), (idx // W) % H, idx % W


def _side_values(im: torch.Tensor, bi: torch.Tensor, v: torch.Tensor, u: torch.Tensor, g0: torch.Tensor,
                 gd: torch.Tensor, along_v: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
    """The sea and sky values of the pixels (bi, v, u) from the centres along one image axis each
    (rows where ``along_v``, else columns), g changing by ``gd`` a pixel along it: each part's value at its
    centroid along the axis, linearly inter/extrapolated from the two nearest centres on its side
    (module docstring); and whether the axis serves (both nearest centres in the image and, by the
    line, on their side)."""
    H, W = im.shape[1:]
    a = gd.abs().clamp_min(1e-30)
    # the horizon's offset from the centre towards the sea [px], and the two parts' centroids
    w_h = (g0 / a).clamp(-0.5, 0.5)
    w_c, w_k = 0.5 * (w_h + 0.5), 0.5 * (w_h - 0.5)
    with torch.no_grad():
        sea_c = g0 < 0
        to_sea = -gd.sign().long()  # index step towards the sea (g falls)
        dv, du = torch.where(along_v, to_sea, 0), torch.where(along_v, 0, to_sea)
        one = torch.ones_like(v)
        ks0, ks1 = torch.where(sea_c, 0, one), torch.where(sea_c, one, 2 * one)  # sea centres used
        kk0, kk1 = torch.where(sea_c, -one, 0), torch.where(sea_c, -2 * one, -one)  # sky centres used

        def inside(k: torch.Tensor) -> torch.Tensor:
            vv, uu = v + k * dv, u + k * du
            return (vv >= 0) & (vv < H) & (uu >= 0) & (uu < W)

        ok = (to_sea != 0) & inside(ks0) & inside(kk0) & (g0 - ks0 * a < 0) & (g0 - kk0 * a >= 0)
        i_s1, i_k1 = inside(ks1), inside(kk1)

    def at(k: torch.Tensor) -> torch.Tensor:  # differentiable: gathered from the image
        return im[bi, (v + k * dv).clamp(0, H - 1), (u + k * du).clamp(0, W - 1)]

    vs0, vs1, vk0, vk1 = at(ks0), at(ks1), at(kk0), at(kk1)
    # (held above half the smaller sample: a sun's disk in the farther sample cannot drive the
    # extrapolated value negative)
    sea = (vs0 + torch.where(i_s1, w_c - ks0, 0.0) * (vs1 - vs0)).maximum(0.5 * torch.minimum(vs0, vs1))
    sky = (vk0 + torch.where(i_k1, kk0 - w_k, 0.0) * (vk1 - vk0)).maximum(0.5 * torch.minimum(vk0, vk1))
    return sea, sky, ok


def blend_horizon(img: torch.Tensor, cg: CameraGeometry, band: SpectralBand | None = None) -> torch.Tensor:
    """``img`` (B, 1, H, W) or (B, H, W), rendered by centre rays, with the pixels the horizon
    crosses replaced by f · sea + (1 − f) · sky (module docstring); in kelvin when ``band`` is
    given (mixed as band radiances). Everything else bit for bit; the input itself untouched."""
    squeeze = img.ndim == 4
    im = img[:, 0] if squeeze else img
    bi, v, u = horizon_pixels(cg)
    if bi.numel() == 0:
        return img
    f, g0, p, q = sea_fraction(cg, bi, v, u)
    n = bi.shape[0]
    axis = torch.arange(2 * n, device=bi.device) < n  # both axes in one pass: rows, then columns
    sea2, sky2, ok2 = _side_values(im, bi.repeat(2), v.repeat(2), u.repeat(2), g0.repeat(2), torch.cat([q, p]), axis)
    (sea_v, sea_u), (sky_v, sky_u), (ok_v, ok_u) = sea2.split(n), sky2.split(n), ok2.split(n)
    # the weight of the rows' estimate: 1 where g changes faster along the rows by 20 % of the sum,
    # 0 the other way, linear between (no jump where the horizon's slope passes 45°); one axis
    # alone where the other does not serve
    w = (0.5 + (q.abs() - p.abs()) / (0.2 * (p.abs() + q.abs()).clamp_min(1e-30))).clamp(0.0, 1.0)
    w = torch.where(ok_v & ~ok_u, 1.0, torch.where(ok_u & ~ok_v, 0.0, w))
    sea = w * sea_v + (1 - w) * sea_u
    sky = w * sky_v + (1 - w) * sky_u
    if band is not None:
        mixed = brightness_temperature(f * band_radiance(sea, band) + (1 - f) * band_radiance(sky, band), band)
    else:
        mixed = f * sea + (1 - f) * sky
    own = im[bi, v, u]
    sea_c = g0.detach() < 0
    # a pixel whose square lies wholly on its centre's side (or with no centres to use) keeps its
    # value exactly
    keep = ~(ok_v | ok_u) | (f == 1) & sea_c | (f == 0) & ~sea_c
    out = im.index_put((bi, v, u), torch.where(keep, own, mixed.to(im.dtype)))
    return out[:, None] if squeeze else out

"""Where a render's pixels lie in the per-image tables: the spans of the view angles an image's sea
and sky pixels cover (read from the image's border, where the extremes lie), and the tables' two
coordinates of a pixel.

- ζ = asinh(cos θ̂ / ε), θ̂ the view zenith of the line of sight sea → sensor, ε about a quarter of
  the image's smallest rms slope: ζ resolves the layer near the horizon where R_a changes fastest.
- The azimuth coordinate of the line of sight from the upwind axis, φ̂ = atan2(−dy, −dx) − wind
  direction (dx, dy the ray's world components). For uncorrelated slopes it is folded into
  ψ = |φ̂| ∈ [0, π/2] by the mirror symmetries R_a(φ̂) = R_a(−φ̂) = R_a(π − φ̂); otherwise it is
  unfolded about the image's centre azimuth c, o = wrap_P(φ̂ − c) + P/2 with period P = π (a sky the
  same in every azimuth: R_a(φ̂ + π) = R_a(φ̂)) or P = 2π (a day sky, which is not).

Conventions: angles in radians; world azimuths from +x towards +y.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import torch

from ..geometry import CameraGeometry, ViewGeometry

__all__ = ["ViewSpans", "camera_spans", "geometry_spans", "azimuth_coordinate", "azimuth_ratio", "ratio_of_angle",
           "angle_of_ratio", "asinh_fast", "wrap_angle", "masked_range", "azimuth_centre", "fold_range"]


def masked_range(x: torch.Tensor, mask: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
    """Per-image (min, max) of x over mask, (B, H, W) → (B,), detached (±inf where mask is empty)."""
    inf = torch.tensor(math.inf, dtype=x.dtype, device=x.device)
    x = x.detach()
    return torch.where(mask, x, inf).amin((1, 2)), torch.where(mask, x, -inf).amax((1, 2))


def wrap_angle(x: torch.Tensor) -> torch.Tensor:
    """Angles wrapped into [−π, π)."""
    return torch.remainder(x + math.pi, 2 * math.pi) - math.pi


def azimuth_centre(dx: torch.Tensor, dy: torch.Tensor, wind_direction: torch.Tensor, mask: torch.Tensor) -> torch.Tensor:
    """Per-image centre c (b,) of the relative azimuths φ̂ = atan2(−dy, −dx) − wind direction of the
    masked pixels: the circular mean of 2φ̂ (period π: R_a(φ̂ + π) = R_a(φ̂)) over a subsample, halved."""
    step = max(1, int(math.sqrt(dx[0].numel() / 4096)))  # ~4096 pixels suffice for a centre
    ps = torch.atan2(-dy[:, ::step, ::step], -dx[:, ::step, ::step]).detach() - wind_direction.detach()[:, None, None]
    m = mask[:, ::step, ::step]
    m = m | ~m.flatten(1).any(1)[:, None, None]  # no sea in the subsample: use all of it
    zero = torch.zeros((), dtype=dx.dtype, device=dx.device)
    return 0.5 * torch.atan2(torch.where(m, torch.sin(2 * ps), zero).sum((1, 2)), torch.where(m, torch.cos(2 * ps), zero).sum((1, 2)))


def azimuth_coordinate(dx: torch.Tensor, dy: torch.Tensor, offset: torch.Tensor, fold: bool,
                        period: float = math.pi) -> torch.Tensor:
    """The table's azimuth coordinate of each pixel, (b, H, W), from its ray's world x, y components.

    ``fold`` (uncorrelated slopes, ``offset`` = π/2 − wind direction): ψ = |φ̂| folded into
    [0, π/2] by the mirror symmetries R_a(φ̂) = R_a(−φ̂) = R_a(π − φ̂); otherwise (``offset`` =
    π/2 − c − wind direction, c the image's centre azimuth): o = wrap_π(φ̂ − c) + π/2 ∈ [0, π),
    R_a(φ̂ + π) = R_a(φ̂) for a sky the same in every azimuth. Under a day sky, which is not,
    ``period`` = 2π (``offset`` = −c − wind direction): o = wrap_2π(φ̂ − c) + π ∈ [0, 2π)."""
    # atan2(dy, dx) is the ray's azimuth, the LOS's + π: the same modulo π. With the offset wrapped
    # into [0, P) per image, (atan2 + offset)/P + 1 lies in [0, 3): its frac is the remainder
    # (torch.remainder, a floor division, costs ~4x frac on the CPU)
    start = (1.0 + torch.remainder(offset, period) / period).to(dy.dtype)[:, None, None]
    o = torch.frac(torch.atan2(dy, dx).mul_(1.0 / period).add_(start)).mul_(period)
    return (o - math.pi / 2).abs() if fold else o


def azimuth_ratio(c: torch.Tensor, s: torch.Tensor, fold: bool) -> torch.Tensor:
    """A cheap stand-in u for the table's azimuth coordinate (:func:`azimuth_coordinate`), from the
    ray's components (any positive scale) along world axes turned by the offset, c ∝ cos(φ + offset),
    s ∝ sin(φ + offset); a few adds and a divide where atan2 and a remainder cost ~8× more on the
    CPU. Folded, ψ = |(φ + offset) mod π − π/2| = atan2(|c|, |s|) and u = sin ψ/(sin ψ + cos ψ)
    ∈ [0, 1]; else o = (φ + offset) mod π = atan2(|s|, c · sign s) and
    u = −cos o/(|cos o| + sin o) ∈ [−1, 1]. Both increase with the angle (:func:`ratio_of_angle`,
    :func:`angle_of_ratio`); a vertical ray (c = s = 0) gets u = 0."""
    if fold:
        num = c.abs()
        den = (num + s.abs()).clamp_min_(1e-30)
        return num / den
    num = c * torch.copysign(torch.ones_like(s), s)  # c · sign s (sign +1 at s = +0)
    den = (c.abs() + s.abs()).clamp_min_(1e-30)
    return -num / den


def ratio_of_angle(t: torch.Tensor, fold: bool) -> torch.Tensor:
    """u of :func:`azimuth_ratio` at the angle ``t`` (ψ folded, else o)."""
    sn, cs = torch.sin(t), torch.cos(t)
    return sn / (sn + cs) if fold else -cs / (cs.abs() + sn)


def angle_of_ratio(u: torch.Tensor, fold: bool) -> torch.Tensor:
    """The angle of :func:`azimuth_ratio`'s u, continued with slope 1 (its slope at both ends)
    beyond u's range (the fine table's overhang)."""
    uc = u.clamp(0.0, 1.0) if fold else u.clamp(-1.0, 1.0)
    ang = torch.atan2(uc, 1.0 - uc) if fold else torch.atan2(1.0 - uc.abs(), -uc)
    return ang + (u - uc)


def fold_range(a: torch.Tensor, b: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
    """Range of ψ = |wrap_π(φ)| (period π, values in [0, π/2]) over φ ∈ [a, b] (lifted, b − a < π)."""
    psi = lambda x: (torch.remainder(x + math.pi / 2, math.pi) - math.pi / 2).abs()  # noqa: E731
    pa, pb = psi(a), psi(b)
    has_zero = torch.ceil(a / math.pi) * math.pi <= b
    has_edge = torch.ceil((a - math.pi / 2) / math.pi) * math.pi + math.pi / 2 <= b
    lo = torch.where(has_zero, torch.zeros_like(a), torch.minimum(pa, pb))
    hi = torch.where(has_edge, torch.full_like(b, math.pi / 2), torch.maximum(pa, pb))
    return lo, hi


@dataclass
class ViewSpans:
    """Per-image spans (B,) float64, detached: ζ of the sea pixels, the azimuth coordinate of the sea
    pixels (with the centre c of the unfolded coordinate), and the cosine of the ray's zenith of the
    sky pixels; whether an image has sea / sky pixels."""

    zeta: tuple[torch.Tensor, torch.Tensor]
    sky: tuple[torch.Tensor, torch.Tensor]
    any_sea: torch.Tensor
    any_sky: torch.Tensor
    azimuth: tuple[torch.Tensor, torch.Tensor] | None = None
    centre: torch.Tensor | None = None


def asinh_fast(x: torch.Tensor) -> torch.Tensor:
    return torch.log(x + torch.sqrt(x * x + 1.0))  # 3× faster than torch.asinh on CPU


def camera_spans(cg: CameraGeometry, sl: slice, wd: torch.Tensor, inv_eps: torch.Tensor, iso: bool, fold: bool,
                   period: float = math.pi) -> ViewSpans:
    """The spans of the images ``sl`` from the rays of their border alone (no per-pixel work).

    cos θ̂ of a sea pixel grows with −dz (the ray's local-vertical component), and dz and the LOS
    azimuth are smooth functions of the ray whose only critical points are the nadir and the zenith:
    over the image they take their extremes on its border, unless a pole is in view. The sea pixels'
    azimuths span those of the sea part of the border plus the horizon arc, which is monotone in
    azimuth between its ends on the border. Spans are widened by one border step (the sampled border
    against the continuous one). Unfolded, the coordinate o = wrap_P(φ̂ − c) + P/2 spans
    P/2 ± half the pixels' span, or all of [0, P] (``period`` P: π, or 2π under a day sky).
    """
    with torch.no_grad():
        dz, dx, dy = (t.double() for t in cg.border(sl))
        nadir, zenith = cg.poles_in_view(sl)
        B = dz.shape[0]
        sh = torch.zeros(B, dtype=torch.float64, device=dz.device) if cg.flat else cg.s_h[sl].double()
        kr = torch.ones_like(sh) if cg.flat else cg.k_r[sl].double()
        dz_min = torch.where(nadir, -torch.ones_like(sh), dz.amin(1))
        dz_max = torch.where(zenith, torch.ones_like(sh), dz.amax(1))
        any_sea = -dz_min > sh
        any_sky = dz_max > -sh - 1e-6

        def zeta(d: torch.Tensor) -> torch.Tensor:  # ζ of the sea point met by a ray of vertical component d
            cos_t = (-d) if cg.flat else kr * torch.sqrt(((-d - sh) * (-d + sh)).clamp_min(0.0))
            return torch.asinh(cos_t.clamp_min(0.0) * inv_eps.double())

        z_hi = zeta(dz_min)
        z_lo = torch.where(any_sky, torch.zeros_like(z_hi), zeta(dz_max))
        s_lo, s_hi = torch.maximum(dz_min, -sh), dz_max
        if iso:
            return ViewSpans((z_lo, z_hi), (s_lo, s_hi), any_sea, any_sky)
        # the LOS azimuth along the border, lifted (unwrapped) around the loop
        phi = torch.atan2(-dy, -dx)
        steps = wrap_angle(torch.roll(phi, -1, 1) - phi)  # step k: from point k to k + 1 (the last closes the loop)
        lifted = torch.cat([phi[:, :1], phi[:, :1] + torch.cumsum(steps[:, :-1], 1)], 1)
        step_max = steps.abs().amax(1)
        sea_b = -dz > sh[:, None]
        inf = torch.tensor(math.inf, dtype=torch.float64, device=dz.device)
        a = torch.where(sea_b, lifted, inf).amin(1) - step_max - wd.double()
        b = torch.where(sea_b, lifted, -inf).amax(1) + step_max - wd.double()
        # a pole in view, a loop that winds around one, or a border too coarse to lift: every azimuth
        full = nadir | zenith | (steps.sum(1).abs() > math.pi) | (step_max > 0.5) | ~sea_b.any(1) | (b - a >= math.pi)
        if fold:
            lo, hi = fold_range(torch.where(full, torch.zeros_like(a), a), torch.where(full, torch.zeros_like(b), b))
            lo = torch.where(full, torch.zeros_like(lo), lo)
            hi = torch.where(full, torch.full_like(hi, math.pi / 2), hi)
            return ViewSpans((z_lo, z_hi), (s_lo, s_hi), any_sea, any_sky, (lo, hi), torch.zeros_like(lo))
        c = torch.where(full, torch.zeros_like(a), 0.5 * (a + b))
        half = 0.5 * (b - a)
        lo = torch.where(full, torch.zeros_like(a), period / 2 - half)
        hi = torch.where(full, torch.full_like(b, period), period / 2 + half)
        return ViewSpans((z_lo, z_hi), (s_lo, s_hi), any_sea, any_sky, (lo, hi), c)


def geometry_spans(g: ViewGeometry, sl: slice, wd: torch.Tensor, inv_eps: torch.Tensor, iso: bool, fold: bool) -> ViewSpans:
    """The spans of the images ``sl`` from a precomputed per-pixel :class:`ViewGeometry`."""
    with torch.no_grad():
        sea, cos, dx, dy = g.is_sea[sl], g.cos_view_zenith[sl], g.dx[sl], g.dy[sl]
        any_sea, any_sky = sea.flatten(1).any(1), (~sea).flatten(1).any(1)
        z = masked_range(asinh_fast(cos.clamp_min(0.0) * inv_eps[:, None, None]), sea)
        s = masked_range(cos, ~sea)
        out = ViewSpans(tuple(v.double() for v in z), tuple(v.double() for v in s), any_sea, any_sky)
        if not iso:
            c = torch.zeros_like(wd) if fold else azimuth_centre(dx, dy, wd, sea)
            o = azimuth_coordinate(dx, dy, math.pi / 2 - c - wd, fold)
            out.azimuth = tuple(v.double() for v in masked_range(o, sea))
            out.centre = c.double()
        return out


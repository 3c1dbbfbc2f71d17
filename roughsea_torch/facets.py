"""The view frame of the facet weighting, and the closed-form denominator of Eqs. 5 and 7.

Both the facet-weighted expectation (:mod:`roughsea_torch.expectation`, Eqs. 5–10) and the reflected
sun (:mod:`roughsea_torch.sun`) weight a facet of slope s = (s_x, s_y) by N(s; μ, Σ) · t(s) / D with

    t(s) = cos Ω / cos θ = cos θ̂ + sin θ̂ · s∥                     (Eq. 6 in slope form)

s∥ the slope along the view azimuth φ̂ and s⊥ the slope across it. This module holds what they
share:

- :class:`FacetGeometry` and :func:`facet_geometry`: the slope law in that view frame, σ∥ (rms of
  s∥), κ and τ (s⊥ = κ s∥ + τ z, the regression of s⊥ on s∥ and the conditional rms) and the mean
  slope (m∥, m⊥);
- :func:`denominator`: D, the line-of-sight projected area of the facets, in closed form

      D = e Φ(e/a) + a φ(e/a),   e = cos θ̂ + sin θ̂ m∥,  a = sin θ̂ σ∥     (shadowing, Eq. 5)
      D = e  (= cos θ̂ for zero-mean slopes)                             (no shadowing, Eq. 7)

  (with zero mean, D = cos θ̂ Φ(μ) + sin θ̂ σ∥ φ(μ), μ = cot θ̂ / σ∥: cos θ̂ (1 + Λ), Smith's Λ);
- :func:`prepare_inputs`: the argument checks and dtype/device resolution of a call on view angles,
  slope statistics and a refractive index;
- :func:`normal_pdf`, :func:`normal_cdf`: φ and Φ of the standard normal law.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import torch

from ._validation import as_tensor, check_finite_range, resolve_dtype_device
from .slopes import SlopeStatistics

__all__ = ["FacetGeometry", "facet_geometry", "denominator", "eq5_denominator", "prepare_inputs", "normal_pdf", "normal_cdf", "visible_ratio"]

_INV_SQRT_2PI = 1.0 / math.sqrt(2.0 * math.pi)
_SQRT_HALF = math.sqrt(0.5)


def normal_pdf(x: torch.Tensor) -> torch.Tensor:
    """φ(x) = exp(−x²/2) / √(2π), the standard normal density."""
    return torch.exp(-0.5 * x * x) * _INV_SQRT_2PI


def normal_cdf(x: torch.Tensor) -> torch.Tensor:
    """Φ(x) = erfc(−x/√2) / 2, the standard normal distribution function (accurate in the lower tail)."""
    return 0.5 * torch.erfc(-x * _SQRT_HALF)


@dataclass
class FacetGeometry:
    """The slope law seen in the view frame of one line of sight (tensors that broadcast together).

    Attributes:
        ct: cos θ̂ (floored at a tiny positive value, :func:`facet_geometry`).
        st: sin θ̂.
        su: σ∥, rms slope along the view azimuth.
        kappa: κ, regression of s⊥ on s∥.
        tau: τ, conditional rms of s⊥ given s∥.
        mu: m∥, mean of s∥ (0 unless the statistics are shifted).
        mv: m⊥, mean of s⊥.
    """

    ct: torch.Tensor
    st: torch.Tensor
    su: torch.Tensor
    kappa: torch.Tensor
    tau: torch.Tensor
    mu: torch.Tensor
    mv: torch.Tensor

    def _fields(self) -> tuple[torch.Tensor, ...]:
        return (self.ct, self.st, self.su, self.kappa, self.tau, self.mu, self.mv)

    def flat(self, shape: torch.Size) -> FacetGeometry:
        """Every field expanded to ``shape`` and flattened (one entry per evaluation)."""
        return FacetGeometry(*(t.expand(shape).reshape(-1) for t in self._fields()))

    def take(self, idx: torch.Tensor | slice) -> FacetGeometry:
        """The entries ``idx`` of a flat geometry."""
        return FacetGeometry(*(t[idx] for t in self._fields()))


def _floors(dtype: torch.dtype) -> tuple[float, float]:
    """(smallest cos θ̂ used, smallest rms slope used); both far below any physical effect.

    The same in every dtype, so that float32 and float64 agree at the same (float32-held) input:
    float32(π/2) lies above π/2, and on a calm sea ε̄ ∝ cos θ̂ there (``docs/notes/expectation.md``).
    """
    return 1e-12, 1e-12


def facet_geometry(vz: torch.Tensor, va: torch.Tensor, vx: torch.Tensor, vy: torch.Tensor, cxy: torch.Tensor,
                   mx: torch.Tensor | None = None, my: torch.Tensor | None = None) -> FacetGeometry:
    """The slope law N(μ, Σ) in the view frame of the line of sight (θ̂ = ``vz``, φ̂ = ``va`` [rad]).

    Σ = [[vx, cxy], [cxy, vy]] in the upwind/crosswind frame and the mean slope (mx, my) (None: zero
    mean) become σ∥² = uᵀΣu (u = (cos φ̂, sin φ̂)), κ = cov(s∥, s⊥)/σ∥², τ² = det Σ / σ∥² and
    (m∥, m⊥). cos θ̂ and σ∥ are floored at 1e-12 (grazing views, degenerate Σ).
    """
    cmin, smin = _floors(vz.dtype)
    ct = torch.cos(vz).clamp_min(cmin)
    st = torch.sin(vz).clamp(0.0, 1.0)
    c, s = torch.cos(va), torch.sin(va)
    su2 = vx * c * c + 2.0 * cxy * c * s + vy * s * s
    sv2 = vx * s * s - 2.0 * cxy * c * s + vy * c * c
    cuv = (vy - vx) * c * s + cxy * (c * c - s * s)
    det = vx * vy - cxy * cxy
    ok = su2 > smin * smin
    su2s = torch.where(ok, su2, torch.full_like(su2, smin * smin))
    kappa = torch.where(ok, cuv / su2s, torch.zeros_like(su2))
    tau2 = torch.where(ok, det / su2s, sv2)
    tau = torch.sqrt(tau2.clamp_min(smin * smin))
    if mx is None:
        mu = mv = torch.zeros_like(su2)
    else:  # the mean slope in the view frame (s∥, s⊥)
        mu, mv = mx * c + my * s, my * c - mx * s
    return FacetGeometry(ct, st, torch.sqrt(su2s), kappa, tau, mu, mv)


def denominator(g: FacetGeometry, shadowing: bool) -> torch.Tensor:
    """D of Eq. 5 (shadowing) or Eq. 7 (cos θ̂), closed form (docs/physics.md §3).

    With a mean slope m∥ along the view, t = cos θ̂ + sin θ̂ s∥ has mean e = cos θ̂ + sin θ̂ m∥ and
    D = E[t H(t)] = e Φ(e/a) + a φ(e/a), a = sin θ̂ σ∥ (Eq. 7: D = e)."""
    e = g.ct + g.st * g.mu
    if not shadowing:
        return e
    return eq5_denominator(e, g.st * g.su)


def eq5_denominator(e: torch.Tensor, a: torch.Tensor) -> torch.Tensor:
    """Eq. 5's D = e Φ(e/a) + a φ(e/a) from e = cos θ̂ + sin θ̂ m∥ and a = sin θ̂ σ∥ (:func:`denominator`)."""
    big = e > 40.0 * a  # μ > 40: Φ(μ) = 1, φ(μ) = 0 to every precision
    mu = e / torch.where(big, torch.ones_like(a), a)
    mu = torch.where(big, torch.full_like(mu, 40.0), mu)
    return torch.where(big, e, e * normal_cdf(mu) + a * normal_pdf(mu))


def visible_ratio(numerator: torch.Tensor, D: torch.Tensor) -> torch.Tensor:
    """numerator / D, the facet-weighted mean of Eq. 5, and 0 where D ≤ the dtype's smallest normal number:
    where the mean slope turns every facet of the window away from the sensor (a resolved tilt of the
    texture's outer nodes near grazing, D = 0 or underflowing), the limit of the visible facets' terms.
    Those facets are seen at grazing local incidence: their emissivity and their reflected rays into the
    sky vanish (ρ → 1, the mirrored ray runs on into the sea), so R_a → R_B; 0/0 gave NaN there. The
    expectation's quadrature window (±``Quadrature.width`` σ about the mean) reaches R_B early: once the
    visible facets lie beyond it (at 87.4°, rms 0.083, from a tilt of about −0.65) its numerators are 0,
    while a window reaching them gives R_a = 0.933 R_B at −0.7 and 0.9975 R_B at −2 (sky 0.75 R_B). Only
    the texture's outer nodes reach such tilts (≤ 1.2 mK in first-hit renders); starting the window at
    the visibility edge would remove it."""
    ok = D > torch.finfo(D.dtype).tiny
    return torch.where(ok, numerator / torch.where(ok, D, torch.ones_like(D)), torch.zeros_like(numerator))


def _check_angles(view_zenith: Any, view_azimuth: Any) -> None:
    check_finite_range("view_zenith", view_zenith, 0.0, math.pi / 2 + 1e-6, unit="rad")
    check_finite_range("view_azimuth", view_azimuth, unit="rad")


def _check_slopes(slopes: Any) -> None:
    if not isinstance(slopes, SlopeStatistics):
        raise ValueError(f"slopes must be a roughsea_torch.SlopeStatistics; got {type(slopes).__name__}")


def prepare_inputs(view_zenith: Any, view_azimuth: Any, slopes: Any, refractive_index: Any = None,
                   **extra: Any) -> tuple[Any, ...]:
    """Check and convert the arguments of a call on view angles and slope statistics.

    The dtype and device are resolved over the angles, the slope parameters, the refractive index
    (when given) and the tensors among ``extra`` (a device mismatch is reported first); then the
    angles (θ̂ in [0, π/2], φ̂ finite) and ``slopes`` (a :class:`~roughsea_torch.SlopeStatistics`)
    are checked.

    Returns:
        (dtype, device, θ̂, φ̂, vx, vy, cxy, mx, my): tensors of that dtype and device; (mx, my) is the
        mean slope, or (None, None) for zero-mean statistics; with a mean, vx, vy and cxy carry its
        batch shape too.
    """
    _check_slopes(slopes)
    tensors = dict(view_zenith=view_zenith, view_azimuth=view_azimuth, **slopes.parameters_dict())
    if refractive_index is not None:
        tensors["refractive_index"] = refractive_index
    tensors.update({k: v for k, v in extra.items() if isinstance(v, torch.Tensor)})
    dtype, device = resolve_dtype_device(**tensors)  # device mismatch is reported first
    _check_angles(view_zenith, view_azimuth)
    vz = as_tensor(view_zenith, dtype, device)
    va = as_tensor(view_azimuth, dtype, device)
    vx, vy, cxy = slopes.tensors(dtype, device)
    if slopes.has_mean:
        mx, my = slopes.mean_tensors(dtype, device)
        vx, vy, cxy = (t + 0 * (mx + my) for t in (vx, vy, cxy))  # the mean's batch shape joins
        return dtype, device, vz, va, vx, vy, cxy, mx, my
    return dtype, device, vz, va, vx, vy, cxy, None, None

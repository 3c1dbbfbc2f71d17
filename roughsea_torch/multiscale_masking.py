"""Multi-scale masking: the facet weight of a sea whose slopes are a sum of many scales
(``shadowing="multiscale"``).

Eq. 5 weights a facet of slope s by its projected area t(s) = cos θ̂ + sin θ̂ s∥ where t > 0, and
Smith's (1967) masking of an uncorrelated surface multiplies every such facet by the same
1/(1 + Λ), which cancels in the normalization. The sea is not one scale: its slope is the sum of
the slopes of many wavelengths, s = s₁ + s₂ + …, the long waves tilting the short ones. Apply Smith
scale by scale, from the longest waves down: a ray meets a long-wave facet of slope s₁ in proportion
to t(s₁)⁺ (Eq. 5 for that scale alone); on it, it meets a shorter-wave facet s₂ in proportion to
t(s₁ + s₂)⁺, normalized over s₂ (Eq. 5 about the tilt s₁), and so on. A facet is seen only if the
sum of the scales' slopes along the view faced the sensor at *every* stage, not only at the last:
the short ripples on the back of a long wave are hidden whichever way they lean. Eq. 5 applied to
the total slope is the single-stage case of this cascade.

With many scales of small variance each, the along-view slope summed from the longest scale down is a
Brownian motion in "variance time" (the cumulative variance σ∥² of the scales taken so far), each
stage weighting its paths by t(μ + s)⁺ / t(μ): the Doob h-transform with h = t, which conditions the
motion never to turn away from the sensor (the Bessel-3 process of x = cot θ̂ + s∥, Brownian motion
conditioned to stay positive). Its density at the end follows from the reflection principle:

    f(s) = (t(s) / t(m)) [N(s; m, Σ) − N(s*; m, Σ)] H(t(s)),

where m is the mean slope (the resolved tilt of a textured sea; 0 otherwise), Σ the covariance of
the scales that are cascaded, and s* the mirror image of s across the line t = 0 in the metric of Σ.
In the standardized along-view coordinate x = (s∥ − m∥)/σ∥ and ν = (cot θ̂ + m∥)/σ∥ (the line of
sight's slope over the rms slope along it, as in Smith's Λ) the image's density ratio is
exp(−2 ν (x + ν)) for any correlation across the view, so the facet weight is Eq. 5's times

    Q(x, ν) = 1 − exp(−2 ν (x + ν))   for x > −ν, ν > 0;   0 otherwise,

and its normalization is exact: D_Q = ∫ N t Q H(t) ds = t(m) = cos θ̂ + sin θ̂ m∥ (the projected area of
the mean plane: every ray meets the surface, none twice), against Eq. 5's D = t(m)(1 + Λ). Facets
leaning towards the sensor gain weight (Q → 1 for x + ν ≫ 1/ν), those near the visibility edge lose it
(Q ∝ x + ν): near grazing the seen facets face the sensor more than Eq. 5 says. At the horizon
(ν → 0⁺) the seen slopes tend to the density 2 x² φ(x) on x > 0 (facets at grazing incidence on the
mean plane carry no weight, unlike Eq. 5's), so Q takes ν no smaller than ``NU_FLOOR`` = 1e-6: ν = 0
(θ̂ = 90° on an untilted sea) gives that limit, not 0/0, and a resolved tilt that turns the mean plane
away (ν < 0, the texture's outer nodes near grazing) continues it (weight ∝ t (x + ν_floor) φ over the
facets still facing the sensor; a convention, the cascade itself sees nothing when it starts turned
away), so values stay finite and continuous and gradients finite. The gradients are not continuous:
the derivative in ν jumps at ν = ``NU_FLOOR`` (``docs/shadowing.md``).

Assumptions: the slopes are Gaussian and every scale is masked relative to the longer ones only
(Smith's uncorrelated masking within a scale); the limit of many scales is taken (a chain with one
Smith stage per octave masks somewhat less, ``docs/shadowing.md``). The along-view density is exact
whatever the scales' covariances; the across-view slopes keep their Gaussian law given the along-view
one (the mirror image in the metric of Σ) when every scale's covariance has the same shape, Σ_k ∝ Σ.
Where the spreading differs between long and short waves, the across-view law conditioned by the
cascade departs from this one (a second-order term for the radiance; not modelled). Its comparison
with a brute-force ray tracer of the package's own wave fields is in ``docs/shadowing.md``.

Sources: B. G. Smith, *Geometrical shadowing of a random rough surface*, IEEE TAP 15(5), 668–671,
1967 (the masking of one scale); the two-scale sea of E. Bruneton, F. Neyret & N. Holzschuch,
*Real-time realistic ocean lighting using seamless transitions from geometry to BRDF*, Computer
Graphics Forum 29(2), 2010 (the long waves tilt the short ones' statistics); J. L. Doob, *Conditional
Brownian motion and the boundary limits of harmonic functions*, Bull. SMF 85, 431–458, 1957
(h-transforms); D. Revuz & M. Yor, *Continuous Martingales and Brownian Motion*, Springer, 3rd ed.
1999, ch. XI (Bessel processes; the three-dimensional one as Brownian motion conditioned to stay
positive); I. Karatzas & S. E. Shreve, *Brownian Motion and Stochastic Calculus*, Springer, 2nd ed. 1991,
§2.6 (the reflection principle). The numpy reference is :func:`roughsea_torch.reference.rough_sea.masking_weight`.
"""

from __future__ import annotations

import torch

__all__ = ["multiscale_ratio", "NU_FLOOR"]

NU_FLOOR = 1e-6  # the least ν the factor takes (the limit ν → 0⁺ at the horizon and beyond)


def multiscale_ratio(x: torch.Tensor, nu: torch.Tensor) -> torch.Tensor:
    """Q(x, ν) = 1 − exp(−2 ν' (x + ν')) with ν' = max(ν, ``NU_FLOOR``) where the facet faces the sensor
    (x + ν > 0), else 0 (module docstring).

    Args:
        x: the slope along the view, standardized: (s∥ − m∥)/σ∥ [dimensionless].
        nu: ν = (cot θ̂ + m∥)/σ∥ [dimensionless] (broadcasts with ``x``).

    Returns:
        Q in [0, 1), x's dtype and device; differentiable (its gradient is finite everywhere: Q is
        continuous at the visibility edge x = −ν, where it is 0)."""
    on = (x + nu) > 0
    nf = nu.clamp_min(NU_FLOOR)
    z = torch.where(on, -2.0 * nf * (x + nf), torch.zeros_like(x))
    return torch.where(on, -torch.expm1(z), torch.zeros_like(z))

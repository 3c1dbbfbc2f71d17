"""The texture's filter along the image's columns: no one-pixel horizontal lines in the far field.

A textured pixel evaluates the resolved wave field at one point (its flat-sea point), each octave band
of the field weighted by a window of the pixel's along-view footprint f (``docs/texture.md`` §4): a
band is kept whole while its highest wavenumber lies below the pixel's Nyquist wavenumber π/f along
the view, and dropped once its lowest does. The band that straddles π/f keeps a weight of about 0.6,
and its modes above π/f fold back to just below it: point sampling aliases them (Shannon). Where
that band carries most of the resolved slope variance (light winds, whose slopes sit in waves much
shorter than a far-field footprint), the texture becomes a pattern of one-pixel-tall horizontal
lines: adjacent rows anti-correlated (−0.8 at 2 m/s, 20 to 60 rows below the horizon of a 256-row
image from 15 m; ``docs/texture.md`` §4).

The remedy here is a low-pass filter across the rows, with a zero at the rows' Nyquist frequency ν_N
(ν in cycles per pixel, ν_N = 1/2), applied to the texture's departure Δ from the expectation and to
the crest-foam fraction f, never to the expectation itself:

    Δ'[i] = (−Δ[i−2] + 4 Δ[i−1] + 10 Δ[i] + 4 Δ[i+1] − Δ[i+2]) / 16,
            H(ν) = (10 + 8 cos 2πν − 2 cos 4πν) / 16: 1 at 0, 0.98 at 1/8, 3/4 at 1/4, 0 at 1/2;
    f'[i] = (f[i−1] + 2 f[i] + f[i+1]) / 4,
            H(ν) = cos² πν: 1 at 0, 1/2 at 1/4, 0 at 1/2 (positive weights keep f a fraction in [0, 1]).

The five-tap filter (the binomial [1, 2, 1]/4 sharpened, 2·[1, 2, 1]/4 − [1, 4, 6, 4, 1]/16) keeps
more of the resolved texture below ν_N/2 than the three-tap one; the three-tap one is the MTF of a
triangle two pixels wide (the pixel's box convolved with a one-pixel blur). The weights of each sum
to 1, so the ensemble mean of a textured render is unchanged (E[Δ] = 0, E[f] = W). Along the sea's
edge (the horizon, a ship mask) they average over the sea neighbours only, renormalized. Across a row
nothing is filtered: there a pixel's footprint R δ is shorter than along the view (R δ / cos θ̂) by
cos θ̂, and the band window, which takes the longer side, keeps every resolved mode well below the
row's Nyquist frequency.

Its price is the resolved variance removed near ν_N, mostly the folded band: in the README's
textured-winds scene the texture's standard deviation falls by about half at 2 m/s and by 10–25 %
at 10 m/s (``docs/texture.md`` §4). ``TableSize(texture_antialias=False)`` turns it off. The sweep
(``TableSize(texture_hit="first")``) averages finer samples over each pixel and is not filtered.
"""

from __future__ import annotations

import torch
import torch.nn.functional as F

__all__ = ["TEXTURE_TAPS", "FOAM_TAPS", "filter_columns"]

TEXTURE_TAPS = (-1.0 / 16, 4.0 / 16, 10.0 / 16, 4.0 / 16, -1.0 / 16)  # Δ: zero at the Nyquist frequency
FOAM_TAPS = (0.25, 0.5, 0.25)  # the crest-foam fraction: positive weights, zero at the Nyquist frequency


def _shifted(t: torch.Tensor, k: int) -> torch.Tensor:
    """t moved by k rows along dim −2 (row i holds row i − k), zero-filled."""
    if k == 0:
        return t
    if k > 0:
        return F.pad(t[:, :-k], (0, 0, k, 0))
    return F.pad(t[:, -k:], (0, 0, 0, -k))


def filter_columns(values: torch.Tensor, sea: torch.Tensor, taps: tuple[float, ...]) -> torch.Tensor:
    """The symmetric filter ``taps`` (odd length, centre tap largest) along the rows' direction (dim −2)
    of ``values`` (b, H, W), over the sea pixels ``sea`` (b, H, W) bool only: out = Σ_k t_k m v / Σ_k t_k m
    (weights renormalized where a neighbour is not sea); pixels outside ``sea`` are returned unchanged.
    Same dtype and device; differentiable."""
    m = sea.to(values.dtype)
    vm = values * m
    half = len(taps) // 2
    num = sum(t * _shifted(vm, k - half) for k, t in enumerate(taps))
    den = sum(t * _shifted(m, k - half) for k, t in enumerate(taps))
    return torch.where(sea, num / torch.where(sea, den, torch.ones_like(den)), values)


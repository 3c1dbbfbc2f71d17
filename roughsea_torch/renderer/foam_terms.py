"""Whitecaps in a render: the foam's radiance R_foam(θ̂) = ε_f R_B + (1 − ε_f) S per image
(:mod:`roughsea_torch.foam`: the foam's measured emissivity ε_f, and S the sky it reflects, weighted
by its own reflectance 1 − ε_f at each incidence, the day's scattered sky included) and its mix with
the sea, (1 − f) · sea + f · foam, for a whitecap fraction f per image or per pixel.
"""

from __future__ import annotations

from typing import Any

import torch

from ..foam import foam_radiance, foam_sky_weights
from ..sky import select_sky
from .scene import SceneParameters, SeaScene
from .sky_terms import day_sky

__all__ = ["foam_radiance_of_images", "foam_mix"]


def foam_radiance_of_images(theta: torch.Tensor, p: SceneParameters, idx: Any, scene: SeaScene) -> torch.Tensor:
    """R_foam(θ̂) = ε_f R_B + (1 − ε_f) S for the images ``idx`` (an index tensor per element of
    θ̂, or a slice with a leading image axis on θ̂)."""
    dtype, device = theta.dtype, theta.device
    n_i, k_i = p.n[idx].to(dtype), p.k[idx].to(dtype)
    # S = Σ w R_s(μ): the nodes' weights per image (its own index), (..., nodes)
    mu, w = foam_sky_weights(scene.band, (n_i, k_i), dtype=dtype, device=device)
    sky = select_sky(p.sky, idx.cpu() if isinstance(idx, torch.Tensor) else idx)
    e_sky = (torch.as_tensor(sky(mu), dtype=dtype, device=device) * w).sum(-1)
    if p.air_scale is not None:
        e_sky = e_sky * p.air_scale[idx].to(dtype)
    day = day_sky(scene, p.vx.shape[0], dtype, device)
    if day is not None:  # + the scattered sky's azimuthal mean at the same nodes and weights
        e_sky = e_sky + (day[0].azimuthal_mean(mu, day[1][idx].to(dtype)[..., None]) * w).sum(-1)
    extra = (None,) * (theta.ndim - 1) if not isinstance(idx, torch.Tensor) else ()
    if e_sky.ndim:
        e_sky = e_sky[(...,) + extra]
    return foam_radiance(theta, scene.band, p.rb[idx][(...,) + extra].to(dtype), e_sky,
                         refractive_index=(p.n[idx][(...,) + extra], p.k[idx][(...,) + extra])).to(dtype)


def foam_mix(values: torch.Tensor, theta: torch.Tensor, p: SceneParameters, idx: torch.Tensor, scene: SeaScene,
              f: torch.Tensor | None = None) -> torch.Tensor:
    """(1 − f) · values + f · R_foam(θ̂), per element (``idx`` the image of each element); f the
    scene's whitecap fraction, or a per-element one (foam on crests, textured seas)."""
    f = p.foam[idx].to(values.dtype) if f is None else f.to(values.dtype)
    return values + f * (foam_radiance_of_images(theta, p, idx, scene) - values)

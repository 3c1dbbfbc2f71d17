"""Whitecaps in a render: the foam's radiances per image and their mix with the sea.

Two foam states (:mod:`roughsea_torch.whitecaps`): active whitecaps on the breaking crests, radiating at
the bulk temperature (the cool skin disrupted; ΔT_skin the scene's ``skin_deficit``, 0.2 K by default),
and residual foam at the skin's,

    R_act = ε_f R_B(T + ΔT_skin) + (1 − ε_f) S,   R_res = ε_f R_B(T) + (1 − ε_f) S

(:func:`~roughsea_torch.whitecaps.foam_state_radiances`; ε_f the foam's measured emissivity and S the sky
it reflects, weighted by its own reflectance 1 − ε_f at each incidence, the day's scattered sky included:
:mod:`roughsea_torch.foam`). The expectation image mixes their mean over the states,
R̄ = a R_act + (1 − a) R_res (a the active share, :func:`~roughsea_torch.whitecaps.active_share` at the
scene's wind; 0 for a scene given by its slopes, without a wind), with the whitecap fraction W:
(1 − W) · sea + W · R̄. A textured sea mixes each state with its own cover per pixel,
sea + f_act (R_act − sea) + f_res (R_res − sea), whose ensemble mean is the expectation's.
"""

from __future__ import annotations

from typing import Any

import torch

from .._validation import per_batch
from ..foam import foam_sky_weights
from ..sky import select_sky
from ..whitecaps import SCENE_INVERSE_WAVE_AGE, active_share, foam_state_radiances, skin_disrupted_radiance
from .scene import SceneParameters, SeaScene
from .sky_terms import day_sky

__all__ = ["foam_state_radiances_of_images", "active_share_of_images", "foam_radiance_of_images", "foam_mix", "foam_mix_states"]


def foam_state_radiances_of_images(theta: torch.Tensor, p: SceneParameters, idx: Any,
                                   scene: SeaScene) -> tuple[torch.Tensor, torch.Tensor]:
    """(R_act, R_res) at θ̂ for the images ``idx`` (an index tensor per element of θ̂, or a slice with a
    leading image axis on θ̂), module docstring."""
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
    # R_B(T + ΔT_skin) image by image (the transcendental functions' vectorized and scalar paths round
    # differently, and image i of a batch must be bitwise the image rendered alone), then per element
    # (ΔT_skin the scene's skin_deficit, per image)
    bulk = torch.cat([skin_disrupted_radiance(p.rb[i:i + 1], scene.band, p.skin_deficit[i:i + 1])
                      for i in range(p.rb.shape[0])])
    act, res = foam_state_radiances(theta, scene.band, p.rb[idx][(...,) + extra].to(dtype), e_sky,
                                    refractive_index=(p.n[idx][(...,) + extra], p.k[idx][(...,) + extra]),
                                    deficit_k=p.skin_deficit, bulk_radiance=bulk[idx][(...,) + extra].to(dtype))
    return act.to(dtype), res.to(dtype)


def active_share_of_images(p: SceneParameters, idx: Any, scene: SeaScene, like: torch.Tensor) -> torch.Tensor:
    """a per element of ``like`` (the images ``idx``, as :func:`foam_state_radiances_of_images`): the active
    share at the scene's wind (Ω_c of its wave fields), 0 for a scene without a wind (slopes=)."""
    if scene.wind_speed is None:
        return torch.zeros((), dtype=like.dtype, device=like.device)
    wind = per_batch("wind_speed", scene.wind_speed, p.vx.shape[0], torch.float64, like.device)
    a = active_share(wind, torch.full_like(wind, SCENE_INVERSE_WAVE_AGE)).to(like.dtype)[idx]
    return a[(...,) + (None,) * (like.ndim - 1)] if not isinstance(idx, torch.Tensor) else a


def foam_radiance_of_images(theta: torch.Tensor, p: SceneParameters, idx: Any, scene: SeaScene) -> torch.Tensor:
    """R̄ = a R_act + (1 − a) R_res at θ̂ for the images ``idx`` (as :func:`foam_state_radiances_of_images`):
    the foam's radiance averaged over its two states, the expectation's."""
    act, res = foam_state_radiances_of_images(theta, p, idx, scene)
    return res + active_share_of_images(p, idx, scene, res) * (act - res)


def foam_mix(values: torch.Tensor, theta: torch.Tensor, p: SceneParameters, idx: torch.Tensor, scene: SeaScene,
             f: torch.Tensor | None = None) -> torch.Tensor:
    """(1 − f) · values + f · R̄(θ̂), per element (``idx`` the image of each element); f the scene's
    whitecap fraction, or a per-element one."""
    f = p.foam[idx].to(values.dtype) if f is None else f.to(values.dtype)
    return values + f * (foam_radiance_of_images(theta, p, idx, scene) - values)


def foam_mix_states(values: torch.Tensor, theta: torch.Tensor, p: SceneParameters, idx: torch.Tensor,
                    scene: SeaScene, f_active: torch.Tensor, f_residual: torch.Tensor) -> torch.Tensor:
    """values + f_act (R_act − values) + f_res (R_res − values), per element: a textured sea's pixels
    with their active and residual foam covers (:func:`~roughsea_torch.whitecaps.whitecap_cover`)."""
    act, res = foam_state_radiances_of_images(theta, p, idx, scene)
    fa, fr = f_active.to(values.dtype), f_residual.to(values.dtype)
    return values + fa * (act - values) + fr * (res - values)

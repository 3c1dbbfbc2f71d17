"""Whitecaps in time: active breaking on the crests and the residual foam it leaves behind.

The foam cover of a textured sea's pixel (the fraction of its footprint under foam) has two states:

    f = a · B(x, t) + (1 − a) · R(x, t)                                      (:func:`whitecap_cover`)

- **Active** (stage A: the crest breaking now): B(x, t) = Φ((X_r − c)/σ_u), the probability that the
  crest variable X of the :class:`~roughsea_torch.waves.WaveField` exceeds the breaking threshold in
  the pixel's footprint given what the pixel resolves (:func:`~roughsea_torch.foam.crest_foam_fraction`:
  soft-edged, E[B] = W exactly).
- **Residual** (stage B: the foam left where crests broke, decaying and drifting with the surface):

      R(x, t) = Σⱼ wⱼ B(x − v (t − tⱼ), tⱼ),   wⱼ ∝ exp(−(t − tⱼ)/τ_R),  Σ wⱼ = 1,

  the breaking deposited at fixed epochs tⱼ = j Δ (absolute time, Δ = :data:`DEPOSIT_INTERVAL_S`)
  within :data:`DEPOSIT_WINDOW` decay times before t, carried since by the surface drift v, fading
  with the decay time τ_R. The epochs are fixed in time, so in a clip a deposit stays where it was
  laid and only drifts and fades: whitecaps form on crests, leave trails behind the crests that
  moved on (streaks along the waves' direction, the wind's), and fade over seconds.

Each B has ensemble mean W (the field is stationary: its statistics do not depend on the point or
the time), and the weights sum to 1, so E[f] = W exactly whatever a, τ_R, v or the epochs: the
ensemble mean of a textured storm stays the expectation's. Far field (nothing resolved): f = W.

Sources and numbers
-------------------
- Two stages, active (A) and residual/maturing (B): Monahan & Lu (1990, IEEE Trans. Geosci. Remote
  Sens. 28, 211–220); in airborne infrared imagery active whitecaps read bright and residual ones dark
  (Marmorino & Smith 2005, Geophys. Res. Lett. 32, L11604).
- Residual foam decays quasi-exponentially in area with decay constants of 0.5–8 s (Callaghan,
  Deane, Stokes & Ward 2012, off Martha's Vineyard): τ_R = :data:`RESIDUAL_DECAY_S` = 2 s, the
  geometric middle of that range.
- Whitecap lifetimes are exponentially distributed, about 0.3 of the breaking wave's period
  (Korinenko, Malinovsky, Dulov & Kudryavtsev, Black Sea platform video): taken here as the active
  stage's duration τ_A = 0.3 T_b, T_b the period of the waves whose crests break in this model: the
  crest variable's band k_lo–k_b (:data:`~roughsea_torch.wave_lattice.CREST_HIGHPASS` = 4 k_p to
  :data:`~roughsea_torch.wave_lattice.CREST_CUTOFF` = 25 k_p, the breaking crests' speeds
  0.2–0.5 c_p of Melville & Matusov 2002), at its geometric centre k_c = √(k_lo k_b) = 10 k_p, so by
  deep-water dispersion T_b = T_p (k_p / k_c)^½ = 0.32 T_p (T_p = 2π U10 / (g Ω_c), ECKV's k_p).
  The active share of the cover follows by Little's law for two successive stages,
  a = τ_A / (τ_A + τ_R) (:func:`active_share`; 0.35 at 15 m/s, 0.47 at 25 m/s, fully developed).
  τ_A = 1.09 s (15 m/s) and 1.81 s (25 m/s) are close to how long the crest foam itself stays at a
  point of sampled fields, 0.64 s and 1.78 s in the mean (``pipelines/whitecap_patches.py``); the
  peak's period would give 3.4 s and 5.7 s. That the video lifetime is the active stage's is this
  model's assumption.
- Foam drifts with the surface water: about 3.5 % of U10 downwind at long fetch (Wu 1975, J. Fluid
  Mech. 68, 49–70, total surface drift including the Stokes drift): :data:`DRIFT_SHARE`.

Where whitecaps are rare (W below :data:`TRAILS_FROM`, about 5 m/s) the residual foam is drawn where
the crests break now (no trails: the trails' 13 extra reads of the wave field per pixel would make a
textured render about 4× slower for foam on under 0.1 % of the sea), blending smoothly in W to the
trails at :data:`TRAILS_FULL` (about 7 m/s); E[f] = W holds throughout.

Structure inside the patches (:mod:`~roughsea_torch.foam_streaks`)
-----------------------------------------------------------------
Every indicator above thresholds X + s ν instead of X: ν the foam's streak field (an independent,
exactly N(0, 1) lattice field of a few metres, elongated along the wind from about 14 m/s, read in the
drifting surface frame), s² = κ σ_X², κ = :data:`STREAK_VARIANCE_SHARE` = 0.5. A footprint L keeps the
share r(L) of ν's variance (1 for a point, 0 from two lattice cells across); the resolved variance
given to the threshold is σ_r² + r s² and the total σ_X² + s², the variances of the sum, so E[B] = W
stays exact. At near range (decimetre footprints) the patches get soft, streaky edges and holes; at
far range ν is averaged away and only widens the soft edge (its unresolved variance). κ = 0.5
(ν's amplitude 0.7 of the crest variable's) is a choice: large enough that the patches break into
streaks, small enough that foam stays on the crests (the share of a textured storm's foam change
carried by its most-changed tenth of pixels falls from 0.55 to 0.46, against 0.29 for a uniform veil).

Radiance of the two states (:func:`foam_state_radiances`)
--------------------------------------------------------
    R_res = ε_f R_B(T) + (1 − ε_f) S,      R_act = ε_f R_B(T + ΔT_skin) + (1 − ε_f) S,

so R_act − R_res = ε_f (R_B(T + ΔT_skin) − R_B(T)) > 0: active whitecaps are brighter than residual
foam at every view angle. T is the scene's sea temperature, the radiating SKIN's; active breaking
mixes the cool skin away and the foam radiates at the bulk temperature T + ΔT_skin (a scene's
``skin_deficit``, by default :data:`SKIN_DEFICIT_K` = 0.2 K, accepted in [0, 5] K): the skin is "a few
tenths of a degree" cooler than the water below (Jessup, Zappa & Yeh 1997, J. Geophys. Res. 102, C10,
23145–23153, and Nature 385, 52–55: breaking
disrupts it, infrared imagery sees the warm wake recover over seconds), typically about 0.2 K and
up to 0.5 K under strong cooling. Both states get the measured foam emissivity ε_f and the reflected
sky S of :mod:`roughsea_torch.foam`: Marmorino & Smith (2005, Geophys. Res. Lett. 32, L11604) report
bright active and dark residual whitecaps in airborne infrared imagery and attribute the difference to
"changes in both emissivity and physical temperature", but the abstract (all that was reachable)
gives no number for either; no measurement of the emissivity of thick active foam against thin
residual foam was found, so no emissivity difference is assumed (the only part modelled is the skin
one, whose size is published). The residual's skin is taken as recovered (T): Jessup et al. see it
recover within seconds, the residual's decay time τ_R.

The ensemble mean: a pixel's foam term a B R_act + (1 − a) R R_res has mean W (a R_act + (1 − a) R_res)
(the cover is independent of the slope texture, :func:`~roughsea_torch.foam.crest_foam_fraction`), so
the expectation image mixes the foam radiance R̄ = a R_act + (1 − a) R_res with the fraction W
(``renderer/foam_terms.py``) and the textured storms' ensemble mean stays the expectation's.

Left out: an emissivity difference between active and residual foam, the evaporative cooling of
residual foam, the skin's gradual recovery within the residual, and the tilt of the foam on the
breaking face. R's deposits are discrete epochs Δ apart: at near
range a fast crest's trail shows as stamps Δ c apart, softened by the footprint's unresolved part.
"""

from __future__ import annotations

import math
from typing import Any

import torch

from ._parallel import BLOCK, in_blocks
from ._validation import check_finite_range
from .foam import crest_fraction_from_variances, foam_radiance, vanishing_crest
from .foam_streaks import resolved_amplitude, streak_lengths, streak_noise
from .radiometry import band_radiance, brightness_temperature
from .spectrum import GRAVITY
from .wave_lattice import CREST_CUTOFF, CREST_HIGHPASS

__all__ = [
    "RESIDUAL_DECAY_S",
    "ACTIVE_PERIOD_SHARE",
    "BREAKING_PERIOD_RATIO",
    "DRIFT_SHARE",
    "DEPOSIT_INTERVAL_S",
    "DEPOSIT_WINDOW",
    "TRAILS_FROM",
    "TRAILS_FULL",
    "SKIN_DEFICIT_K",
    "MAX_SKIN_DEFICIT_K",
    "STREAK_VARIANCE_SHARE",
    "SCENE_INVERSE_WAVE_AGE",
    "active_share",
    "skin_disrupted_radiance",
    "check_skin_deficit",
    "foam_state_radiances",
    "deposit_epochs",
    "foam_drift",
    "whitecap_cover",
]

RESIDUAL_DECAY_S = 2.0  # [s] τ_R, Callaghan et al. 2012: 0.5–8 s (geometric middle)
ACTIVE_PERIOD_SHARE = 0.3  # τ_A / T_b, Korinenko et al.: whitecap lifetime / breaking wave period
# T_b / T_p: the period of the crest band's centre wavenumber √(k_lo k_b), deep-water dispersion T ∝ k^(-1/2)
BREAKING_PERIOD_RATIO = (max(CREST_HIGHPASS, 1.0) * CREST_CUTOFF) ** -0.25
DRIFT_SHARE = 0.035  # surface drift / U10, Wu 1975 (long fetch)
DEPOSIT_INTERVAL_S = 0.5  # [s] Δ, the spacing of the residual foam's deposit epochs
DEPOSIT_WINDOW = 3.0  # deposits kept within this many τ_R before t (the rest, e^-3 = 5 %, renormalized away)
# The residual's trails cost 13 more reads of the wave field per pixel (about 4× a textured render). Where
# whitecaps are rare they are not drawn: below TRAILS_FROM the residual foam sits where the crests break
# now (R = B, no trails), above TRAILS_FULL it is the trails' R, in between a smoothstep blend in W (the
# cover stays continuous and differentiable in the wind, and E[f] = W throughout).
TRAILS_FROM = 1e-3  # W, about 5 m/s (Monahan & O'Muircheartaigh 1980)
TRAILS_FULL = 3e-3  # W, about 7 m/s
STREAK_VARIANCE_SHARE = 0.5  # κ: var(s ν) / σ_X², the streak field's share beside the crest variable
SKIN_DEFICIT_K = 0.2  # [K] bulk − skin temperature, disrupted by active breaking (Jessup, Zappa & Yeh 1997)
MAX_SKIN_DEFICIT_K = 5.0  # [K] the largest skin deficit accepted (SeaScene(skin_deficit=), foam_state_radiances)
SCENE_INVERSE_WAVE_AGE = 0.84  # Ω_c of a SeaScene's wave fields (fully developed, WaveField's default)


def active_share(wind_speed: torch.Tensor, inverse_wave_age: torch.Tensor,
                 decay_s: float = RESIDUAL_DECAY_S) -> torch.Tensor:
    """a = τ_A / (τ_A + τ_R), τ_A = 0.3 T_b, T_b = 0.32 T_p, T_p = 2π U10 / (g Ω_c) [s] (module docstring).

    Args:
        wind_speed: U10 [m/s] > 0, tensor (B,); inverse_wave_age: Ω_c, tensor (B,).
        decay_s: τ_R [s] > 0.

    Returns:
        a in (0, 1), (B,), differentiable in the wind.
    """
    tau_a = ACTIVE_PERIOD_SHARE * BREAKING_PERIOD_RATIO * 2.0 * math.pi * wind_speed / (GRAVITY * inverse_wave_age)
    return tau_a / (tau_a + decay_s)


def skin_disrupted_radiance(sea_radiance: torch.Tensor, band: Any,
                            deficit_k: float | torch.Tensor = SKIN_DEFICIT_K) -> torch.Tensor:
    """R_B(T + ΔT_skin) [W m⁻² sr⁻¹]: the blackbody band radiance of the bulk water that active breaking
    brings to the surface, T the brightness temperature of ``sea_radiance`` (the skin's R_B(T)) in
    ``band``, ΔT_skin = ``deficit_k`` [K] (module docstring): a float, or a tensor broadcasting with
    ``sea_radiance`` (differentiable in it). Shape, dtype and device of their broadcast; differentiable.
    Where ΔT_skin = 0 the result is ``sea_radiance`` itself, bit for bit (no round trip through the
    temperature), its derivative in ΔT_skin still dR_B/dT."""
    if not isinstance(deficit_k, torch.Tensor):
        if deficit_k == 0:  # the skin's own radiance, exactly
            return sea_radiance
        t = brightness_temperature(sea_radiance.clamp_min(1e-30), band)
        return band_radiance(t + deficit_k, band).to(sea_radiance.dtype)
    d = deficit_k.to(dtype=sea_radiance.dtype, device=sea_radiance.device)
    t = brightness_temperature(sea_radiance.clamp_min(1e-30), band)
    bulk = band_radiance(t + d, band).to(sea_radiance.dtype)
    # where ΔT = 0: R_B(T) + (R_B(T + ΔT) − R_B(T)), the skin's radiance exactly, with the derivative in ΔT
    return torch.where(d == 0, sea_radiance + (bulk - band_radiance(t, band).to(sea_radiance.dtype)), bulk)


def check_skin_deficit(name: str, deficit_k: Any) -> None:
    """``ValueError`` naming ``name`` unless ``deficit_k`` (a float or tensor) is a skin temperature deficit
    in [0, :data:`MAX_SKIN_DEFICIT_K`] K, finite."""
    check_finite_range(name, deficit_k, 0.0, MAX_SKIN_DEFICIT_K, unit="K (the bulk − skin temperature)")


def foam_state_radiances(view_zenith: torch.Tensor, band: Any, sea_radiance: torch.Tensor, sky: torch.Tensor,
                         refractive_index: Any = None, deficit_k: float | torch.Tensor = SKIN_DEFICIT_K,
                         bulk_radiance: torch.Tensor | None = None) -> tuple[torch.Tensor, torch.Tensor]:
    """(R_act, R_res) [W m⁻² sr⁻¹]: active foam ε_f R_B(T + ΔT_skin) + (1 − ε_f) S and residual foam
    ε_f R_B(T) + (1 − ε_f) S (module docstring; ε_f, S: :func:`~roughsea_torch.foam.foam_radiance`).

    Args:
        view_zenith: θ̂ [rad] in [0, π/2]; band: the sensor band (MWIR or LWIR).
        sea_radiance: R_B(T) of the skin [W m⁻² sr⁻¹] > 0; sky: S, the sky the foam reflects, ≥ 0.
        refractive_index: the water's (see :func:`~roughsea_torch.foam.foam_emissivity`).
        deficit_k: ΔT_skin [K] in [0, 5], a float or a tensor broadcasting with ``sea_radiance``.
        bulk_radiance: R_B(T + ΔT_skin) if already computed (:func:`skin_disrupted_radiance`), else None.
    All broadcast together; float32/float64 and device follow the inputs.

    Returns:
        R_act, R_res of the broadcast shape; R_act ≥ R_res (equal for ``deficit_k`` = 0).
    """
    check_skin_deficit("deficit_k", deficit_k)
    residual = foam_radiance(view_zenith, band, sea_radiance, sky, refractive_index=refractive_index)
    bulk = skin_disrupted_radiance(sea_radiance, band, deficit_k) if bulk_radiance is None else bulk_radiance
    active = foam_radiance(view_zenith, band, bulk, sky, refractive_index=refractive_index)
    return active.to(residual.dtype), residual


def foam_drift(wind_speed: torch.Tensor, wind_direction: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
    """The surface drift (v_x, v_y) [m/s] in the world frame: 3.5 % of U10 downwind (Wu 1975), the
    wind direction being the world azimuth of the UPWIND axis (the waves travel towards it + π)."""
    v = DRIFT_SHARE * wind_speed
    # cos and sin image by image: their vectorized and scalar paths round differently, and image i of a
    # batch must be bitwise the image rendered alone
    cos = torch.cat([torch.cos(wind_direction[i:i + 1]) for i in range(wind_direction.shape[0])])
    sin = torch.cat([torch.sin(wind_direction[i:i + 1]) for i in range(wind_direction.shape[0])])
    return -v * cos, -v * sin


def deposit_epochs(time_s: torch.Tensor, decay_s: float = RESIDUAL_DECAY_S, interval_s: float = DEPOSIT_INTERVAL_S,
                   window: float = DEPOSIT_WINDOW) -> tuple[torch.Tensor, torch.Tensor]:
    """The residual foam's deposit epochs tⱼ = j Δ ≤ t within ``window`` τ_R before t, and their
    weights wⱼ ∝ exp(−(t − tⱼ)/τ_R), Σ wⱼ = 1.

    Args:
        time_s: t [s], float64 tensor (B,).
        decay_s: τ_R [s] > 0; interval_s: Δ [s] > 0; window: in units of τ_R, > 0.

    Returns:
        epochs (B, J) float64 and weights (B, J) float64, J = floor(window τ_R / Δ) + 1 (the same
        for every image: the newest epoch is the last multiple of Δ at or before t).
    """
    n = int(math.floor(window * decay_s / interval_s)) + 1
    j = torch.arange(n, dtype=torch.float64, device=time_s.device)
    newest = torch.floor(time_s / interval_s) * interval_s
    epochs = newest[:, None] - interval_s * j
    # exp(−(t − tⱼ)/τ) = exp(−(t − t₀)/τ) exp(−j Δ/τ): the first factor cancels in the normalization, so the
    # weights are one (J,) row for every image (and image i of a batch is bitwise the image alone)
    w = torch.exp(-interval_s * j / decay_s)
    return epochs, (w / w.sum()).expand(time_s.shape[0], n)


def whitecap_cover(wf: Any, x: torch.Tensor, y: torch.Tensor, time_s: torch.Tensor, footprint: torch.Tensor | None,
                   crest_now: torch.Tensor, resolved_variance: torch.Tensor, total_variance: torch.Tensor,
                   whitecap_fraction: torch.Tensor, decay_s: float = RESIDUAL_DECAY_S,
                   trails: bool = True) -> tuple[torch.Tensor, torch.Tensor]:
    """The active and residual foam cover (a B, (1 − a) R) of points of a wave field (module docstring),
    each indicator thresholding the crest variable plus the drifting streak field
    (:mod:`~roughsea_torch.foam_streaks`, resolved as the footprint allows).

    Args:
        wf: the :class:`~roughsea_torch.waves.WaveField` (B images).
        x, y: the points' world coordinates [m], (B, ...), of the field's dtype and device (checked).
        time_s: t [s], float64 (B,).
        footprint: the points' footprints [m] (x's shape) or None.
        crest_now: X_r at the points at t (``wf.sample_unchecked(..., crest=True)["crest"]``).
        resolved_variance: σ_r² of X_r at the footprint, broadcasting with x; total_variance: σ_X²,
            broadcasting; whitecap_fraction: W, broadcasting (e.g. (B, 1, ...)).
        decay_s: τ_R [s].
        trails: False: the residual is the breaking now, R = B, at every W (no deposits read; the
            renderer's default, ``TableSize.foam_trails``).

    Returns:
        (f_active, f_residual), x's shape, each in [0, 1], f_active + f_residual in [0, 1], with
        E[f_active + f_residual] = W. Without trails the points are taken block by block and the streak
        field is read only where it can change the cover (:func:`_cover_now`); the values are the same.
    """
    dtype = x.dtype
    extra = (None,) * (x.ndim - 1)
    a = active_share(wf.wind_speed, wf.inverse_wave_age, decay_s).to(dtype)[(...,) + extra]
    # the drift in float64 whatever the dtype (the field keeps its wind in float64): it moves the streak field
    # by v t, which at large t (1e5–1e9 s) is far more than a streak is wide, so a velocity or direction rounded
    # to float32 would draw other streaks
    vx64, vy64 = foam_drift(wf.wind_speed, wf.wind_direction)
    vx, vy = (v.to(dtype)[(...,) + extra] for v in (vx64, vy64))
    epochs, weights = deposit_epochs(time_s, decay_s)

    # the fine structure: X + s ν, ν the drifting streak field (foam_streaks), s² = κ σ_X², of which the
    # footprint keeps the share r; the variances given to the threshold are the sum's, so E[B] = W stays exact
    v_norm = torch.sqrt(vx64 * vx64 + vy64 * vy64).clamp_min(1e-30)
    along, across = streak_lengths(wf.wind_speed)
    root_r = resolved_amplitude(footprint, across.to(dtype)[(...,) + extra])  # √r, r the share the footprint keeps
    keep = None if footprint is None else (root_r.detach() > 0).expand(x.shape)
    s2 = STREAK_VARIANCE_SHARE * total_variance
    per_nu = root_r * torch.sqrt(s2.clamp_min(1e-30))  # the lift per unit ν
    r = root_r * root_r
    v_res, v_tot = resolved_variance + r * s2, total_variance + s2
    t = ((whitecap_fraction - TRAILS_FROM) / (TRAILS_FULL - TRAILS_FROM)).clamp(0.0, 1.0)
    share = t * t * (3.0 - 2.0 * t)  # of the trails in the residual (TRAILS_FROM, TRAILS_FULL above)

    def noise(xs: torch.Tensor, ys: torch.Tensor, where: Any, below: Any) -> torch.Tensor:
        ex = (...,) + (None,) * (xs.ndim - 1)  # ν at points (B, ...) in the drifting frame, in float64 (times
        # and positions may be large)
        tn = time_s.double()[ex]
        return streak_noise(xs.double() - vx64[ex] * tn, ys.double() - vy64[ex] * tn, wf.seeds, vx64 / v_norm,
                            vy64 / v_norm, along, across, where=where, below=below).to(dtype)

    if not trails or not bool((share > 0).any()):  # no trails drawn: the residual is the breaking now
        now = _cover_now(noise, x, y, crest_now, keep, per_nu, v_res, v_tot, whitecap_fraction)
        return a * now, (1.0 - a) * now
    lift = per_nu * noise(x, y, keep, None)

    def indicator(crest: torch.Tensor) -> torch.Tensor:
        return crest_fraction_from_variances(crest + lift, v_res, v_tot, whitecap_fraction)

    now = indicator(crest_now)
    residual = torch.zeros_like(crest_now)
    for j in range(epochs.shape[1]):
        age = (time_s - epochs[:, j]).to(dtype)[(...,) + extra]
        smp = wf.sample_unchecked(x - vx * age, y - vy * age, epochs[:, j], footprint, elevation=False, crest=True,
                                  slopes=False)
        residual = residual + weights[:, j].to(dtype)[(...,) + extra] * indicator(smp["crest"])
    return a * now, (1.0 - a) * torch.lerp(now, residual, share)




_COVER_BLOCK = BLOCK  # point-evaluations per block of _cover_now (a module constant the tests vary)


def _cover_now(noise: Any, x: torch.Tensor, y: torch.Tensor, crest: torch.Tensor, keep: torch.Tensor | None,
               per_nu: Any, v_res: torch.Tensor, v_tot: torch.Tensor, w: torch.Tensor) -> torch.Tensor:
    """The indicator B = Φ of X + s ν at t (:func:`whitecap_cover` without trails), x's shape, block by block
    of points (each point's arithmetic as on the whole array, so the same values bit for bit). ν is read
    (``noise``(x, y, where, below), :func:`~roughsea_torch.foam_streaks.streak_noise` in the drifting frame)
    only where it can lift the cover off exactly 0: the cover and its derivatives are exactly 0 for
    X + s ν ≤ x₀ (:func:`~roughsea_torch.foam.vanishing_crest`), so where ν ≤ (x₀ − X)/s is certain (its
    lattice cell's bound) 0 gives the same cover; near grazing that is most points."""
    shape, b = x.shape, x.shape[0]

    def flat(t: Any) -> Any:  # (B or 1, P), or (B or 1, 1) for a value per image (broadcast, not copied)
        if not isinstance(t, torch.Tensor) or t.ndim == 0:
            return t
        if t.ndim == len(shape) and all(d == 1 for d in t.shape[1:]):
            return t.reshape(t.shape[0], 1)
        return t.expand(shape).reshape(b, -1)

    xs, ys, cs, ks, ps, vr, vt, ws = (flat(t) for t in (x, y, crest, keep, per_nu, v_res, v_tot, w))
    npts = xs.shape[1]
    if npts == 0:
        return x.new_zeros(shape)

    def block(u: int, e: int) -> tuple:
        xb, yb, cb, kb, pb, vrb, vtb, wb = (t[:, u:e] if isinstance(t, torch.Tensor) and t.ndim == 2
                                            and t.shape[1] > 1 else t for t in (xs, ys, cs, ks, ps, vr, vt, ws))
        x0 = vanishing_crest(vrb, vtb, wb, x.dtype)
        below = ((x0 - cb.detach().double()) / torch.as_tensor(pb).detach().double()).expand(xb.shape)
        lift = pb * noise(xb, yb, kb, below)
        return (crest_fraction_from_variances(cb + lift, vrb, vtb, wb),)

    return in_blocks(block, npts, max(1024, _COVER_BLOCK // max(b, 1)))[0].reshape(shape)

"""Rough-sea projected area, emissivity and apparent radiance by adaptive quadrature (reference).

Everything is computed in the paper's facet-normal coordinates (theta, phi):

  p(theta, phi)       Eq. 1 / A7-A8, density of facet normals (per rad^2)
  cos(Omega)          Eq. 6: cos(theta) cos(th) + sin(theta) sin(th) cos(phi - ph)
                      (th, ph = view zenith and azimuth of the line of sight sea -> sensor)
  f_hat(theta, phi)   Eq. 5: p cos(Omega)/cos(theta) H(pi/2 - Omega) / D,
                      D = int int p cos(Omega)/cos(theta) H(pi/2 - Omega) dtheta dphi
                      (Eq. 4/7 without H, where D = cos(th) exactly)
  cos(theta')         Eq. 9: 2 cos(Omega) cos(theta) - cos(th), zenith angle of the reflected ray
  R_a                 Eq. 10: int int f_hat {[1 - rho(Omega)] R_B + rho(Omega) R_s(theta')}

The integrals are evaluated by nested adaptive scipy quadrature with the integrand's jumps and kinks
put at integration limits and breakpoints in closed form (:mod:`roughsea_torch.reference.facet_integral`,
which describes how). A second, independent ordering ("theta_outer") is provided for cross-checks.

Shifted slope law (keyword slope_mean = (mean_upwind, mean_crosswind), default (0, 0)):
the slopes s = (s_x, s_y) = tan(theta) (cos phi, sin phi) are N(s; mu, Sigma) instead of N(s; 0, Sigma).
This is the two-scale model of docs/texture.md sec. 5: a resolved tilt mu (in the upwind/crosswind
frame) carries unresolved slopes of covariance Sigma; everything else is the paper's model as it
stands: the sky and theta' stay in the world frame, the weight is Eq. 5 (Eq. 4 without H).
mu uses the convention of s: the facet of slope mu has the normal (mu_x, mu_y, 1)/sqrt(1 + |mu|^2),
i.e. it leans towards mu (docs/physics.md sec. 2; docs/texture.md sec. 3: s = -grad(eta), the negative height
gradient; the paper's A5 writes +grad h, which for zero mean is the same law).
  * Density: p_mu(theta, phi) = N(tan(theta) (cos phi, sin phi); mu, Sigma) tan(theta) sec^2(theta),
    the Jacobian of Eq. A6/A7 (s = t (cos phi, sin phi) are polar coordinates in slope space,
    ds = t dt dphi, dt = sec^2(theta) dtheta). mu = 0 is Eq. A7/A8.
  * Normalization: D of Eq. 5 by quadrature as before; without shadowing the Eq. 4 denominator is
    int N(s; mu, Sigma) (cos th + sin th s_par) ds = cos th + sin th (mu . (cos ph, sin ph)), used in
    closed form (Eq. 7's cos th relied on p(theta, phi) = p(theta, phi + pi), which a mean breaks).
  * mu = (0, 0) (also -0.0) runs exactly the unshifted code; results are unchanged bit for bit.
  * Flat sea (a = b = 0) with a mean: one facet of slope mu, in closed form. A mean with exactly one
    rms slope 0 (a line law off the origin) is not supported (NotImplementedError).

Shared within the reference (used by :mod:`~roughsea_torch.reference.sun` and ``_selfcheck``):
:func:`check_view`, :func:`slope_arrays`, :func:`check_slope_mean`, :func:`is_shifted`,
:func:`mean_facet_weight`, :func:`numerator`, :func:`denominator`,
:func:`shifted_denominator_or_nan`.
"""

import math
import warnings

import numpy as np
from scipy import integrate

from .facet_integral import HALF_PI, TWO_PI, FacetIntegral, SkyRadiance, unique_mod_2pi
from .fresnel import as_complex_index, fresnel_scalar
from .masking import masking_curve
from .slopes import check_slope_arrays

__all__ = ["projected_area", "emissivity", "apparent_radiance"]


# ----------------------------------------------------------------------------- input handling

def check_view(view_zenith, view_azimuth):
    th = np.asarray(view_zenith, dtype=np.float64)
    ph = np.asarray(view_azimuth, dtype=np.float64)
    if np.any(np.isnan(th)) or np.any(th < 0.0) or np.any(th > HALF_PI):
        raise ValueError("view_zenith must lie in [0, pi/2]")
    if np.any(~np.isfinite(ph)):
        raise ValueError("view_azimuth must be finite")
    return th, ph


def slope_arrays(slopes):
    return check_slope_arrays(slopes.std_upwind, slopes.std_crosswind, slopes.corr)


def check_slope_mean(slope_mean):
    """slope_mean = (mean_upwind, mean_crosswind): two finite floats or arrays -> two float64 arrays."""
    try:
        mx, my = slope_mean
    except (TypeError, ValueError):
        raise ValueError("slope_mean must be a pair (mean_upwind, mean_crosswind)") from None
    mx = np.asarray(mx, dtype=np.float64)
    my = np.asarray(my, dtype=np.float64)
    if not (np.all(np.isfinite(mx)) and np.all(np.isfinite(my))):
        raise ValueError("slope_mean must be finite")
    return mx, my


def is_shifted(mean):
    return mean[0] != 0.0 or mean[1] != 0.0


def mean_facet_weight(th, ph, mean):
    """cos(Omega)/cos(theta) of the facet of slope mu: cos th + sin th (mu . (cos ph, sin ph)).

    docs/physics.md sec. 3 (linear in s). It is also the exact Eq. 4 denominator
    int N(s; mu, Sigma) (cos th + sin th s_par) ds for any Sigma (no shadowing).
    """
    return math.cos(th) + math.sin(th) * (mean[0] * math.cos(ph) + mean[1] * math.sin(ph))


def _tilted_flat_facet(th, ph, mean):
    """Flat sea tilted to the slope mu (a = b = 0, mu != 0): one facet, normal (mx, my, 1)/sqrt(1+|mu|^2).

    Returns (w, cos_omega, cos_theta_r): w = cos(Omega)/cos(theta), cos(Omega) (Eq. 6 in slope form),
    cos(theta') = 2 cos(Omega) cos(theta) - cos(th) (Eq. 9).
    """
    w = mean_facet_weight(th, ph, mean)
    cos_theta = 1.0 / math.sqrt(1.0 + mean[0] * mean[0] + mean[1] * mean[1])
    cos_omega = w * cos_theta
    return w, cos_omega, 2.0 * cos_omega * cos_theta - math.cos(th)


def masking_weight(shadowing, th, ph, a, b, r, mean=(0.0, 0.0)):
    """None (Eq. 5 or 7), or the masking factor Q(s_par) on Eq. 5's facet weight of this view and slope
    law, a function of the facet's slope along the view s_par = tan(theta) cos(phi - ph):

    - "correlated": reference.masking.masking_curve at nu = cot(th) / sigma_par (zero-mean laws only);
    - "multiscale": the cascade of Smith's masking over the sea's scales, longest first, in the limit
      of many scales: the along-view slope summed over the scales is a Brownian motion in the
      cumulative variance, and a facet is seen when the sum faced the sensor at every stage, i.e.
      cot(th) + s_par stayed > 0 all along. Weighting each stage by its projected area conditions the
      motion to stay positive (Doob's h-transform with h = cot(th) + s_par); by the reflection principle
      its end density is (h(s)/h(mu)) [N(s; mu, Sigma) - N(mirror of s; mu, Sigma)], and the ratio of
      the mirror's density to the facet's is exp(-2 (cot th + s_par)(cot th + mu_par) / sigma_par^2).
      So Q = 1 - that where cot th + s_par > 0, else 0. The model takes (cot th + mu_par) / sigma_par no
      smaller than 1e-6 (its limit at the horizon, continued beyond), and so does this reference.
    """
    if not (isinstance(shadowing, str) and shadowing in ("correlated", "multiscale")):
        return None
    c, s = math.cos(ph), math.sin(ph)
    sig = math.sqrt(max(a * a * c * c + 2.0 * r * a * b * c * s + b * b * s * s, 0.0))
    if not sig > 0.0:  # no slope along the view: nothing to condition on, Eq. 5
        return None
    cot = math.cos(th) / max(math.sin(th), 1e-300)
    if shadowing == "multiscale":
        h_mean = cot + mean[0] * c + mean[1] * s
        h0 = max(h_mean, 1e-6 * sig)

        def q(s_par):
            h = cot + s_par
            if h <= 0.0:
                return 0.0
            return -math.expm1(-2.0 * (h - h_mean + h0) * h0 / (sig * sig))

        return q
    if is_shifted(mean):
        raise NotImplementedError("shadowing='correlated' in the reference needs slope_mean = (0, 0)")
    return masking_curve(cot / sig, sig)


def check_shadowing(shadowing):
    """True, False, "correlated" or "multiscale", else ValueError."""
    if isinstance(shadowing, str) and shadowing in ("correlated", "multiscale"):
        return shadowing
    if isinstance(shadowing, (bool, np.bool_)):
        return bool(shadowing)
    raise ValueError(f"shadowing must be True, False, 'correlated' or 'multiscale'; got {shadowing!r}")


def numerator(kind, th, ph, a, b, r, shadowing, m=None, sea_radiance=None, sky=None,
               epsrel=1e-10, method="phi_outer", mean=(0.0, 0.0), epsabs=0.0):
    """Unnormalized integral of p cos(Omega)/cos(theta) [H] g over theta, phi (one scalar case)."""
    fi = FacetIntegral(th, ph, a, b, r, shadowing, kind, m, sea_radiance, sky, mean,
                       weight=masking_weight(shadowing, th, ph, a, b, r, mean))
    return fi.integral(epsrel, method, epsabs)


def _projected_area_scalar(th, ph, a, b, r, shadowing, epsrel, method, mean=(0.0, 0.0)):
    if a == 0.0 and b == 0.0:
        if is_shifted(mean):  # one tilted facet; hidden (weight 0) when it faces away
            w = mean_facet_weight(th, ph, mean)
            return max(w, 0.0) if shadowing else w
        return math.cos(th)  # flat sea: every facet horizontal, cos(Omega) = cos(th) >= 0
    # shifted, no shadowing: the exact value cos th + sin th m can be ~0; stop at 1e-14 absolute
    epsabs = 1e-14 if (is_shifted(mean) and not shadowing) else 0.0
    return numerator("area", th, ph, a, b, r, shadowing, epsrel=epsrel, method=method, mean=mean,
                      epsabs=epsabs)


def denominator(th, ph, a, b, r, shadowing, epsrel, method, mean=(0.0, 0.0)):
    """D of Eq. 5 by quadrature (shadowing) or, without shadowing, the exact Eq. 4 denominator:
    cos(th) (Eq. 7), cos th + sin th (mu . (cos ph, sin ph)) with a slope mean."""
    if shadowing:
        return _projected_area_scalar(th, ph, a, b, r, shadowing, epsrel, method, mean)
    if is_shifted(mean):
        return mean_facet_weight(th, ph, mean)
    return math.cos(th)


def shifted_denominator_or_nan(th, ph, a, b, r, shadowing, epsrel, method, mean):
    """Shifted law: the denominator, or None where the weight's integral is 0 (result NaN, 0/0):
    with shadowing no facet within the density support faces the sensor; without, the exact Eq. 4
    denominator cos th + sin th m is 0 (|.| < 1e-15)."""
    den = denominator(th, ph, a, b, r, shadowing, epsrel, method, mean)
    if den == 0.0 or (not shadowing and abs(den) < 1e-15):
        return None
    return den


# ----------------------------------------------------------------------------- public API

def projected_area(view_zenith, view_azimuth, slopes, shadowing=True, *, epsrel=1e-10,
                   method="phi_outer", slope_mean=(0.0, 0.0)):
    """Line-of-sight projected area per unit horizontal area: the denominator of Eq. 5 / Eq. 4.

    D(th, ph) = int_0^{2pi} dphi int_0^{pi/2} dtheta p(theta, phi) cos(Omega)/cos(theta) [H(pi/2 - Omega)]
    with cos(Omega) from Eq. 6 and p from Eq. A7/A8; H only when shadowing=True.
    Without shadowing the exact value is cos(th) (paper, text before Eq. 7); here it is computed by
    quadrature too, which is a check of the quadrature.

    view_zenith th [rad] in [0, pi/2], view_azimuth ph [rad] from the upwind axis, slopes:
    SlopeStatistics. Dimensionless. Broadcasts; returns a float64 array.
    epsrel: relative tolerance of the outer quadrature (inner uses epsrel/100).
    method: "phi_outer" (default) or "theta_outer" (independent ordering, for checks).
    slope_mean: (mean_upwind, mean_crosswind), the mean mu of the slope Gaussian (floats or arrays
    broadcasting with the view); p is then N(s; mu, Sigma) in (theta, phi) form (module docstring).
    Without shadowing the exact value is then cos th + sin th (mu . (cos ph, sin ph)), computed here by
    quadrature with an absolute tolerance of 1e-14 (it can be 0 or negative). (0, 0): unchanged.
    Flat sea (a = b = 0): cos(th) without quadrature; with a mean, one facet of slope mu:
    cos th + sin th (mu . (cos ph, sin ph)), clipped at 0 with shadowing.
    With shadowing=False and th = pi/2 exactly the (zero-mean) integral is 0 (cos(pi/2)); it is
    computed with an absolute tolerance of 1e-15 there.
    """
    if check_shadowing(shadowing) in ("correlated", "multiscale"):
        raise ValueError("projected_area: shadowing must be True or False")
    shadowing = check_shadowing(shadowing)
    th, ph = check_view(view_zenith, view_azimuth)
    a, b, r = slope_arrays(slopes)
    mx, my = check_slope_mean(slope_mean)
    th, ph, a, b, r, mx, my = np.broadcast_arrays(th, ph, a, b, r, mx, my)
    out = np.empty(th.shape, dtype=np.float64)
    for idx in np.ndindex(th.shape):
        t_, p_, a_, b_, r_, mx_, my_ = (float(x[idx]) for x in (th, ph, a, b, r, mx, my))
        mean = (mx_, my_)
        if (not shadowing and t_ == HALF_PI and not (a_ == 0.0 and b_ == 0.0)
                and not is_shifted(mean)):
            fi = FacetIntegral(t_, p_, a_, b_, r_, False, "area")
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", integrate.IntegrationWarning)
                out[idx] = _outer_abs(fi, 1e-15)
            continue
        out[idx] = _projected_area_scalar(t_, p_, a_, b_, r_, shadowing, epsrel, method, mean)
    return out


def _outer_abs(fi, epsabs):
    """phi-outer integral with an absolute tolerance (used only where the exact value is 0)."""
    if fi.line is not None:
        return sum(fi.theta_integral(phi0, 1e-12) for phi0 in fi.line[1])
    pts = unique_mod_2pi([fi.ph + k * HALF_PI for k in range(4)] + fi.principal_azimuths())
    return integrate.quad(fi.theta_integral, 0.0, TWO_PI, args=(1e-12,), points=pts,
                          epsabs=epsabs, epsrel=1e-10, limit=1000)[0]


def emissivity(view_zenith, view_azimuth, slopes, refractive_index, shadowing=True, *,
               epsrel=1e-10, method="phi_outer", slope_mean=(0.0, 0.0)):
    """Rough-sea emissivity (dimensionless): int int f_hat(theta, phi) [1 - rho(Omega)] dtheta dphi.

    f_hat from Eq. 5 (shadowing=True: H(pi/2 - Omega) in numerator and denominator, the denominator
    D by quadrature) or Eq. 7 (shadowing=False: denominator cos(th); facets turned away,
    cos(Omega) < 0, keep their negative weight and rho is evaluated at |cos(Omega)|).
    rho: unpolarized Fresnel reflectance for m = n + ik (k >= 0): complex, complex array or (n, k).
    Flat sea (a = b = 0): 1 - rho(cos th) without quadrature.
    shadowing=False at th = pi/2 exactly (non-flat): Eq. 7 divides by cos(pi/2) = 0 and its numerator
    integral is also 0 (odd in cos(phi - ph)); the result is NaN (0/0).
    Note: without shadowing, near grazing the numerator is a difference of terms ~rms slope that
    nearly cancel to ~cos(th); the relative accuracy is then ~1e-16 * slope / cos(th) at best.

    slope_mean = (mean_upwind, mean_crosswind): mean mu of the slope Gaussian (module docstring).
    Without shadowing the denominator is then the exact integral of the Eq. 4 weight,
    cos th + sin th (mu . (cos ph, sin ph)) (Eq. 7's cos th needs mu = 0); where it is 0, and with
    shadowing where no facet in the density support faces the sensor, the result is NaN (0/0).
    Flat sea with a mean: the one facet of slope mu, 1 - rho(|cos Omega_mu|) (NaN if it is hidden).
    """
    shadowing = check_shadowing(shadowing)
    th, ph = check_view(view_zenith, view_azimuth)
    a, b, r = slope_arrays(slopes)
    m = as_complex_index(refractive_index)
    mx, my = check_slope_mean(slope_mean)
    th, ph, a, b, r, m, mx, my = np.broadcast_arrays(th, ph, a, b, r, m, mx, my)
    out = np.empty(th.shape, dtype=np.float64)
    for idx in np.ndindex(th.shape):
        t_, p_, a_, b_, r_, mx_, my_ = (float(x[idx]) for x in (th, ph, a, b, r, mx, my))
        m_ = complex(m[idx])
        mean = (mx_, my_)
        if is_shifted(mean):
            if a_ == 0.0 and b_ == 0.0:
                w, cos_omega, _ = _tilted_flat_facet(t_, p_, mean)
                visible = w > 0.0 if shadowing else abs(w) >= 1e-15
                out[idx] = 1.0 - fresnel_scalar(abs(cos_omega), m_) if visible else math.nan
                continue
            den = shifted_denominator_or_nan(t_, p_, a_, b_, r_, shadowing, epsrel, method, mean)
            if den is None:
                out[idx] = math.nan
                continue
            num = numerator("emis", t_, p_, a_, b_, r_, shadowing, m=m_, epsrel=epsrel,
                             method=method, mean=mean)
            out[idx] = num / den
            continue
        if a_ == 0.0 and b_ == 0.0:
            out[idx] = 1.0 - fresnel_scalar(math.cos(t_), m_)
            continue
        if not shadowing and t_ == HALF_PI:
            out[idx] = math.nan
            continue
        num = numerator("emis", t_, p_, a_, b_, r_, shadowing, m=m_, epsrel=epsrel, method=method)
        out[idx] = num / denominator(t_, p_, a_, b_, r_, shadowing, epsrel, method)
    return out


def apparent_radiance(view_zenith, view_azimuth, slopes, refractive_index, sea_radiance, sky,
                      shadowing=True, *, epsrel=1e-10, method="phi_outer", slope_mean=(0.0, 0.0)):
    """Apparent radiance of the rough sea R_a, Eq. 10 (units of sea_radiance, W m^-2 sr^-1).

    R_a = int int f_hat(theta, phi) {[1 - rho(Omega)] R_B + rho(Omega) R_s(theta')} dtheta dphi,
    f_hat from Eq. 5 (or Eq. 7 when shadowing=False), cos(theta') = 2 cos(Omega) cos(theta) - cos(th)
    (Eq. 9). R_B = sea_radiance. Where cos(theta') < 0 the reflected ray goes into the sea and
    R_s is replaced by R_B (single bounce; keeps R_a = R_B when the sky equals R_B).
    sky: callable f(cos_zenith ndarray) -> radiance ndarray; or a constant; or a table
    (zenith_rad, radiance) of 1-d arrays, zenith ascending in [0, pi/2], interpolated in zenith
    angle with PchipInterpolator(extrapolate=False) and held at the end values outside the table.
    Flat sea (a = b = 0): (1 - rho(cos th)) R_B + rho(cos th) R_s(th) without quadrature.
    shadowing=False at th = pi/2 exactly (non-flat): NaN (0/0 in Eq. 7), as for emissivity().

    slope_mean = (mean_upwind, mean_crosswind): mean mu of the slope Gaussian (module docstring);
    denominator and NaN cases as in emissivity(). The sky stays in the world frame: theta' is the
    zenith angle of the reflected ray whatever mu is. Flat sea with a mean: the one facet of slope mu,
    (1 - rho) R_B + rho R_s(theta'_mu) (R_B if theta'_mu is below the horizontal; NaN if hidden).
    """
    shadowing = check_shadowing(shadowing)
    th, ph = check_view(view_zenith, view_azimuth)
    a, b, r = slope_arrays(slopes)
    m = as_complex_index(refractive_index)
    rb = np.asarray(sea_radiance, dtype=np.float64)
    sky_f = SkyRadiance(sky)
    mx, my = check_slope_mean(slope_mean)
    th, ph, a, b, r, m, rb, mx, my = np.broadcast_arrays(th, ph, a, b, r, m, rb, mx, my)
    out = np.empty(th.shape, dtype=np.float64)
    for idx in np.ndindex(th.shape):
        t_, p_, a_, b_, r_, rb_, mx_, my_ = (float(x[idx]) for x in (th, ph, a, b, r, rb, mx, my))
        m_ = complex(m[idx])
        mean = (mx_, my_)
        if is_shifted(mean):
            if a_ == 0.0 and b_ == 0.0:
                w, cos_omega, cos_tp = _tilted_flat_facet(t_, p_, mean)
                if not (w > 0.0 if shadowing else abs(w) >= 1e-15):
                    out[idx] = math.nan
                    continue
                rho = fresnel_scalar(abs(cos_omega), m_)
                r_s = rb_ if cos_tp < 0.0 else sky_f(min(cos_tp, 1.0))
                out[idx] = (1.0 - rho) * rb_ + rho * r_s
                continue
            den = shifted_denominator_or_nan(t_, p_, a_, b_, r_, shadowing, epsrel, method, mean)
            if den is None:
                out[idx] = math.nan
                continue
            num = numerator("rad", t_, p_, a_, b_, r_, shadowing, m=m_, sea_radiance=rb_,
                             sky=sky_f, epsrel=epsrel, method=method, mean=mean)
            out[idx] = num / den
            continue
        if a_ == 0.0 and b_ == 0.0:
            rho = fresnel_scalar(math.cos(t_), m_)
            out[idx] = (1.0 - rho) * rb_ + rho * sky_f(math.cos(t_))
            continue
        if not shadowing and t_ == HALF_PI:
            out[idx] = math.nan
            continue
        num = numerator("rad", t_, p_, a_, b_, r_, shadowing, m=m_, sea_radiance=rb_, sky=sky_f,
                         epsrel=epsrel, method=method)
        out[idx] = num / denominator(t_, p_, a_, b_, r_, shadowing, epsrel, method)
    return out

"""Reflected sun (glint) of the rough sea, integrated directly over the sun's disk (reference).

The sun is a uniform disk of angular radius R (``sun_radius``, default 0.004654 rad = 0.267 deg)
centred on the unit direction c (surface -> sun; zenith ``sun_zenith``, azimuth ``sun_azimuth`` from
the upwind axis, like the view azimuth). Its radiance is L_sun = E_sun / Omega_sun with
Omega_sun = 2 pi (1 - cos R) = 4 pi sin^2(R/2), E_sun = ``irradiance`` on a plane normal to the beam.

Model: Eq. 10 of the paper with R_s replaced by the sun's radiance (sky and emission left out),

    R_glint = (1/D) int N(s; mu, Sigma) t(s) H(t) rho(cos Omega) L_sun(r(s)) ds,
    t(s) = cos Omega / cos beta = cos th + sin th s_par     (docs/physics.md sec. 3),

beta the facet-normal zenith, Omega the angle between the normal n = (s_x, s_y, 1)/sqrt(1 + |s|^2)
and the line of sight v, r(s) = 2 (n.v) n - v the mirrored line of sight, L_sun(r) = L_sun inside the
disk and 0 outside, D the Eq. 5 denominator (``projected_area`` with shadowing; Eq. 4/7 without:
cos th + sin th (mu . (cos ph, sin ph))).

Direction-space form (what is integrated here). For a direction omega in the disk the only facet
with n_z > 0 that mirrors v into omega has n = h = (v + omega)/|v + omega| (h_z > 0 whenever
omega_z > 0), so s = (h_x/h_z, h_y/h_z). Jacobians:
  * slopes -> normals (gnomonic map): d(omega_h) = cos^3 beta ds;
  * normals -> reflected directions: d(omega) = 4 (h.v) d(omega_h)   (half-vector Jacobian);
hence ds = d(omega) / (4 (h.v) cos^3 beta) (checked numerically in the tests against the polygon
area of a disk's image in slope space), and with t = (h.v)/cos beta:

    R_glint = (L_sun / D) int_disk N(s(omega); mu, Sigma) rho(h.v) / (4 cos^4 beta) d(omega)  [x G1].

h.v = |v + omega|/2 > 0 for every reflected direction, so t > 0 and H(t) = 1 on all glint facets:
shadowing only enters through D. Directions of the disk with omega_z <= 0 (sun cut by the horizon)
contribute 0. The disk is parametrized exactly on the sphere, in polar coordinates about a centre p:
omega = cos(rho) p + sin(rho) (cos(psi) e1 + sin(psi) e2), d(omega) = sin(rho) drho dpsi, and for each
psi the rho-range inside the disk (omega.c >= cos R) is solved in closed form (see _disk_range).
Nested adaptive scipy quad (outer psi, inner rho).

Choice of the centre p:
  * broad law (sqrt(l_max) >= 2 R, l_max the largest covariance eigenvalue; ``centre="sun"``):
    p = c, rho in [0, R], psi in [0, 2 pi]; the integrand is smooth across the disk.
  * calm law (sqrt(l_max) < 2 R, i.e. rms slope below ~0.009; ``centre="peak"``): the density is
    a spike narrower than the disk. p = omega_mu, the mirror of v about the facet of slope mu (where
    the spike sits). If p lies inside the disk, psi in [0, 2 pi] and rho in [0, rho_exit(psi)]: the
    spike is at rho = 0 and the radial integrand is smooth, with geometric breakpoints
    rho = w 4^j (w a lower bound of the spike's angular width) so every scale gets its own panels.
    If p is outside, psi runs over the rays that meet the disk, |psi| <= asin(sin R / sin d) (d the
    angle p-c, e1 pointing to c) with breakpoints psi = 0 and +-gamma 4^-j, and rho over
    [rho_in, rho_out] with the ladder from rho_in. If d - R > 40 pi sqrt(l_max) the result is 0:
    a direction at angle alpha from omega_mu needs a slope at least (2/pi)(alpha/2) from mu, i.e.
    more than 40 rms slopes (exp(-800)). If the mean facet faces away from the sensor
    (n_mu . v <= 0) the sun-centred rule is used.
  Both centres are exact; ``centre="sun"``/``"peak"`` forces one (tests compare them).
  Flat sea (a = b = 0): one facet of slope mu (0: horizontal), closed form rho(n.v) L_sun if the
  mirrored line of sight lies in the disk (angle to c <= R, and above the horizon), else 0.
  A line law (exactly one rms slope 0) is not supported (NotImplementedError).

Sun-side masking (``sun_masking=True``): Smith's G1 of the sun direction, multiplied onto the result,
G1 = 1/(1 + Lambda). Derivation (same facet model as Eq. 5, applied towards the sun): the facets
facing the sun have projected area E[(cos th_s + sin th_s u)^+] per unit horizontal area,
u = s . (cos ph_s, sin ph_s) ~ N(mu_par, sigma_par^2) the slope along the sun azimuth; the mean plane
(the area actually lit) projects E[cos th_s + sin th_s u] = cos th_s + sin th_s mu_par. With
k = cot th_s + mu_par,  G1 = k / E[(k + (u - mu_par))^+] = 1/(1 + Lambda),
    Lambda = E[(-(cot th_s + u))^+] / k = [phi_N(m) - m (1 - Phi(m))] / m,   m = k / sigma_par,
(E[X^+] = sigma phi_N(x/sigma) + x Phi(x/sigma) for X ~ N(x, sigma^2)). mu = 0 gives Smith's
Lambda with m = cot th_s / sigma_par. k <= 0 (the mean plane turned away from the sun, in particular
th_s >= pi/2 with mu = 0): G1 = 0. Flat sea: G1 = 1 if k > 0 else 0. Not applied when False.

NaN where D is 0 or undefined, as in rough_sea: shadowing=False at th = pi/2 (zero mean), and the
shifted cases where rough_sea's denominators are 0.
"""

import math
import warnings

import numpy as np
from scipy import integrate
from scipy.special import ndtr

from .facet_integral import HALF_PI, TWO_PI
from .fresnel import as_complex_index, fresnel_scalar
from .rough_sea import (check_slope_mean, check_view, denominator, is_shifted, mean_facet_weight,
                        shifted_denominator_or_nan, slope_arrays)

__all__ = ["glint_radiance", "sun_masking_g1", "sun_solid_angle"]

SUN_RADIUS = 0.004654  # rad, 0.2667 deg
CALM_FACTOR = 2.0      # calm (peak-centred) rule when sqrt(l_max) < CALM_FACTOR * sun_radius
FAR_RMS = 40.0         # peak farther than this many (angular) rms widths outside the disk: 0


def sun_solid_angle(sun_radius=SUN_RADIUS):
    """Solid angle of a disk of angular radius R [rad] on the unit sphere: 2 pi (1 - cos R) [sr]."""
    h = math.sin(0.5 * float(sun_radius))
    return 4.0 * math.pi * h * h


def _unit(th, ph):
    st = math.sin(th)
    return (st * math.cos(ph), st * math.sin(ph), math.cos(th))


def _dot(u, w):
    return u[0] * w[0] + u[1] * w[1] + u[2] * w[2]


def _normalize(u):
    n = math.sqrt(_dot(u, u))
    return (u[0] / n, u[1] / n, u[2] / n)


def _cross(u, w):
    return (u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0])


def _mirror(v, n):
    """Mirror of the unit vector v about the unit normal n: 2 (n.v) n - v."""
    k = 2.0 * _dot(n, v)
    return (k * n[0] - v[0], k * n[1] - v[1], k * n[2] - v[2])


def _angle(u, w):
    """Angle between unit vectors, stable for small angles."""
    return math.atan2(math.sqrt(_dot(_cross(u, w), _cross(u, w))), _dot(u, w))


def _slope_of_direction(v, omega):
    """Slope s of the facet mirroring v into omega: h = (v + omega)/|v + omega|, s = h_xy / h_z.

    Returns (s_x, s_y, cos_omega = h.v, cos_beta = h_z), or None when h_z <= 0."""
    hx, hy, hz = v[0] + omega[0], v[1] + omega[1], v[2] + omega[2]
    if not hz > 0.0:
        return None
    norm = math.sqrt(hx * hx + hy * hy + hz * hz)
    return hx / hz, hy / hz, (hx * v[0] + hy * v[1] + hz * v[2]) / norm, hz / norm


def _gauss2(sx, sy, a, b, r, mx, my):
    """N(s; mu, Sigma), Sigma = [[a^2, r a b], [r a b, b^2]] (a, b > 0, |r| < 1)."""
    dx, dy = (sx - mx) / a, (sy - my) / b
    one_r2 = 1.0 - r * r
    q = (dx * dx - 2.0 * r * dx * dy + dy * dy) / one_r2
    return math.exp(-0.5 * q) / (TWO_PI * a * b * math.sqrt(one_r2))


def _lambda_g1(th_s, ph_s, a, b, r, mean):
    """Smith's G1 = 1/(1 + Lambda) of the sun direction for the slope law N(mu, Sigma) (module doc)."""
    c, s = math.cos(ph_s), math.sin(ph_s)
    mu_par = mean[0] * c + mean[1] * s
    ct, st = math.cos(th_s), math.sin(th_s)
    if st == 0.0:
        return 1.0  # sun at the zenith: every facet (n_z > 0) faces it
    k = ct / st + mu_par
    if not k > 0.0:
        return 0.0
    var = a * a * c * c + 2.0 * r * a * b * c * s + b * b * s * s
    if var <= 0.0:
        return 1.0  # flat (along the sun azimuth): one plane facing the sun
    sig = math.sqrt(var)
    m = k / sig
    # phi_N(m) - m (1 - Phi(m)) = E[(Z - m)^+] >= 0, Z ~ N(0, 1)
    tail = math.exp(-0.5 * m * m) / math.sqrt(TWO_PI) - m * ndtr(-m)
    return 1.0 / (1.0 + max(tail, 0.0) / m)


def sun_masking_g1(sun_zenith, sun_azimuth, slopes, *, slope_mean=(0.0, 0.0)):
    """Smith's sun-side masking factor G1 = 1/(1 + Lambda) (module docstring), broadcast, float64."""
    th, ph = np.asarray(sun_zenith, dtype=np.float64), np.asarray(sun_azimuth, dtype=np.float64)
    a, b, r = slope_arrays(slopes)
    mx, my = check_slope_mean(slope_mean)
    th, ph, a, b, r, mx, my = np.broadcast_arrays(th, ph, a, b, r, mx, my)
    out = np.empty(th.shape, dtype=np.float64)
    for idx in np.ndindex(th.shape):
        out[idx] = _lambda_g1(float(th[idx]), float(ph[idx]), float(a[idx]), float(b[idx]),
                              float(r[idx]), (float(mx[idx]), float(my[idx])))
    return out


def _basis(p, c):
    """Orthonormal e1, e2 perpendicular to p, e1 towards c when c is not (nearly) along p."""
    w = (c[0] - _dot(c, p) * p[0], c[1] - _dot(c, p) * p[1], c[2] - _dot(c, p) * p[2])
    if math.sqrt(_dot(w, w)) < 1e-8:
        w = (1.0, 0.0, 0.0) if abs(p[0]) < 0.9 else (0.0, 1.0, 0.0)
        w = (w[0] - _dot(w, p) * p[0], w[1] - _dot(w, p) * p[1], w[2] - _dot(w, p) * p[2])
    e1 = _normalize(w)
    return e1, _cross(p, e1)


def _disk_range(psi, pc, e1c, e2c, sin2_perp, cos_r, sin2_r):
    """rho-interval of the ray omega(rho) = cos rho p + sin rho u_psi inside the disk omega.c >= cos R.

    omega.c = A cos rho + B sin rho = M cos(rho - delta), A = p.c, B = u_psi.c, M^2 = A^2 + B^2;
    inside for |rho - delta| <= alpha, cos alpha = cos R / M. Written stably for small angles:
    M^2 - cos^2 R = sin^2 R - |c_perp|^2 + B^2 (|c_perp|^2 = 1 - A^2 = (e1.c)^2 + (e2.c)^2), so
    alpha = atan2(sqrt(M^2 - cos^2 R), cos R). Returns (lo, hi) clipped to rho >= 0, or None."""
    bb = math.cos(psi) * e1c + math.sin(psi) * e2c
    disc = sin2_r - sin2_perp + bb * bb
    if disc <= 0.0:
        return None
    alpha = math.atan2(math.sqrt(disc), cos_r)
    delta = math.atan2(bb, pc)
    lo, hi = max(delta - alpha, 0.0), delta + alpha
    if hi <= lo:
        return None
    return lo, hi


class _DiskIntegral:
    """int_disk N(s(omega)) rho(h.v) / (4 cos^4 beta) d(omega) for one geometry (no L_sun, D, G1)."""

    def __init__(self, v, c, sun_radius, a, b, r, mean, m, centre, epsrel):
        self.v, self.c = v, c
        self.R = float(sun_radius)
        self.a, self.b, self.r = a, b, r
        self.mx, self.my = mean
        self.m = m
        self.epsrel = epsrel
        tr = a * a + b * b
        det = a * a * b * b * (1.0 - r * r)
        self.lam1 = 0.5 * tr + math.sqrt(max(0.25 * tr * tr - det, 0.0))
        self.lam2 = det / self.lam1
        n_mu = _normalize((self.mx, self.my, 1.0))
        nv = _dot(n_mu, v)
        if centre == "auto":
            centre = "peak" if math.sqrt(self.lam1) < CALM_FACTOR * self.R else "sun"
        if centre == "peak" and not nv > 0.0:
            centre = "sun"
        self.centre = centre
        if centre == "sun":
            self.p = c
            self.w = None
        else:
            self.p = _normalize(_mirror(v, n_mu))
            # lower bound (rough) of the spike's angular width: slope rms sqrt(l2) times the local
            # slope -> direction scale, which is >= 2 (h.v) cos^3 beta along its narrow direction
            self.w = 2.0 * math.sqrt(self.lam2) * nv * n_mu[2] ** 3
        self.e1, self.e2 = _basis(self.p, c)
        self.pc = _dot(self.p, c)
        self.e1c, self.e2c = _dot(self.e1, c), _dot(self.e2, c)
        self.sin2_perp = self.e1c * self.e1c + self.e2c * self.e2c
        self.d = math.atan2(math.sqrt(self.sin2_perp), self.pc)  # angle p - c
        self.cos_r = math.cos(self.R)
        self.sin2_r = math.sin(self.R) ** 2

    def integrand(self, rho, psi):
        cr, sr = math.cos(rho), math.sin(rho)
        cp, sp = math.cos(psi), math.sin(psi)
        p, e1, e2 = self.p, self.e1, self.e2
        om = tuple(cr * p[i] + sr * (cp * e1[i] + sp * e2[i]) for i in range(3))
        if not om[2] > 0.0:
            return 0.0  # this part of the sun is below the horizon
        geo = _slope_of_direction(self.v, om)
        if geo is None:
            return 0.0
        sx, sy, cos_omega, cos_beta = geo
        dens = _gauss2(sx, sy, self.a, self.b, self.r, self.mx, self.my)
        if dens == 0.0:
            return 0.0
        cb2 = cos_beta * cos_beta
        return dens * fresnel_scalar(min(cos_omega, 1.0), self.m) / (4.0 * cb2 * cb2) * sr

    def _ladder(self, lo, hi):
        if self.w is None:
            return []
        pts, x = [], self.w
        while lo + x < hi:
            pts.append(lo + x)
            x *= 4.0
        return pts

    def rho_integral(self, psi):
        rng = _disk_range(psi, self.pc, self.e1c, self.e2c, self.sin2_perp, self.cos_r, self.sin2_r)
        if rng is None:
            return 0.0
        lo, hi = rng
        pts = self._ladder(lo, hi)
        with warnings.catch_warnings():
            # inner tolerance epsrel/100 can sit at the rounding level of the geometry (the
            # density's exponent for a very calm law): quad's roundoff notice is expected there
            warnings.simplefilter("ignore", integrate.IntegrationWarning)
            return integrate.quad(self.integrand, lo, hi, args=(psi,), points=pts or None,
                                  epsrel=0.01 * self.epsrel, epsabs=0.0, limit=500)[0]

    def integral(self):
        if self.centre == "peak" and self.d > self.R:  # spike outside the disk
            if self.d - self.R > FAR_RMS * math.pi * math.sqrt(self.lam1):
                return 0.0
            gam = math.asin(min(1.0, math.sin(self.R) / math.sin(self.d)))
            pts = [0.0] + [s * gam * 4.0 ** -j for j in range(1, 7) for s in (-1.0, 1.0)]
            return integrate.quad(self.rho_integral, -gam, gam, points=pts, epsrel=self.epsrel,
                                  epsabs=0.0, limit=500)[0]
        pts = [0.5 * math.pi, math.pi, 1.5 * math.pi]
        return integrate.quad(self.rho_integral, 0.0, TWO_PI, points=pts, epsrel=self.epsrel,
                              epsabs=0.0, limit=500)[0]


def _flat_glint(v, c, sun_radius, m, mean):
    """Flat sea (one facet of slope mu): rho(n.v) if the mirrored line of sight is in the disk, else 0
    (per unit L_sun; the facet's weight normalizes to 1)."""
    n = _normalize((mean[0], mean[1], 1.0))
    nv = _dot(n, v)
    if not nv > 0.0:
        return 0.0
    ref = _normalize(_mirror(v, n))
    if ref[2] > 0.0 and _angle(ref, c) <= sun_radius:
        return fresnel_scalar(min(nv, 1.0), m)
    return 0.0


def glint_radiance(view_zenith, view_azimuth, slopes, refractive_index, sun_zenith, sun_azimuth,
                   irradiance, *, shadowing=True, sun_masking=True, sun_radius=SUN_RADIUS,
                   slope_mean=(0.0, 0.0), epsrel=1e-9, centre="auto"):
    """Sun's contribution to the apparent radiance of the rough sea [W m^-2 sr^-1] (module docstring).

    view_zenith, view_azimuth: line of sight sea -> sensor [rad], azimuth from the upwind axis.
    slopes: SlopeStatistics; refractive_index: n + ik (k >= 0), complex array or (n, k).
    sun_zenith, sun_azimuth: direction surface -> sun centre [rad] (azimuth from the upwind axis).
    irradiance: E_sun [W m^-2] on a plane normal to the beam; L_sun = E_sun / (2 pi (1 - cos R)).
    shadowing: D of Eq. 5 (projected_area) if True, else Eq. 4/7. sun_masking: multiply by Smith's
    G1 of the sun direction. sun_radius R [rad]. slope_mean (mean_upwind, mean_crosswind).
    epsrel: relative tolerance of the outer quadrature (inner epsrel/100; D with the rough_sea
    default 1e-10). centre: "auto", "sun" or "peak" (the polar centre, module docstring).
    The sky and the sea's own emission are NOT included. Broadcasts; returns a float64 array.
    """
    if centre not in ("auto", "sun", "peak"):
        raise ValueError("centre must be 'auto', 'sun' or 'peak'")
    th, ph = check_view(view_zenith, view_azimuth)
    a, b, r = slope_arrays(slopes)
    m = as_complex_index(refractive_index)
    ths = np.asarray(sun_zenith, dtype=np.float64)
    phs = np.asarray(sun_azimuth, dtype=np.float64)
    if np.any(~np.isfinite(ths)) or np.any(ths < 0.0) or np.any(ths > math.pi):
        raise ValueError("sun_zenith must lie in [0, pi]")
    if np.any(~np.isfinite(phs)):
        raise ValueError("sun_azimuth must be finite")
    e_sun = np.asarray(irradiance, dtype=np.float64)
    if np.any(~np.isfinite(e_sun)) or np.any(e_sun < 0.0):
        raise ValueError("irradiance must be finite and >= 0")
    radius = float(sun_radius)
    if not 0.0 < radius < 0.1:
        raise ValueError("sun_radius must lie in (0, 0.1) rad")
    l_unit = 1.0 / sun_solid_angle(radius)
    mx, my = check_slope_mean(slope_mean)
    arrs = np.broadcast_arrays(th, ph, a, b, r, m, ths, phs, e_sun, mx, my)
    th, ph, a, b, r, m, ths, phs, e_sun, mx, my = arrs
    out = np.empty(th.shape, dtype=np.float64)
    for idx in np.ndindex(th.shape):
        t_, p_, a_, b_, r_, ts_, ps_, e_, mx_, my_ = (
            float(x[idx]) for x in (th, ph, a, b, r, ths, phs, e_sun, mx, my))
        m_ = complex(m[idx])
        mean = (mx_, my_)
        v, c = _unit(t_, p_), _unit(ts_, ps_)
        g1 = _lambda_g1(ts_, ps_, a_, b_, r_, mean) if sun_masking else 1.0
        if a_ == 0.0 and b_ == 0.0:
            if is_shifted(mean):
                w = mean_facet_weight(t_, p_, mean)
                if not (w > 0.0 if shadowing else abs(w) >= 1e-15):
                    out[idx] = math.nan
                    continue
            out[idx] = g1 * e_ * l_unit * _flat_glint(v, c, radius, m_, mean)
            continue
        if a_ == 0.0 or b_ == 0.0:
            raise NotImplementedError("glint_radiance needs both rms slopes > 0 (or both 0)")
        if is_shifted(mean):
            den = shifted_denominator_or_nan(t_, p_, a_, b_, r_, shadowing, 1e-10, "phi_outer",
                                              mean)
            if den is None:
                out[idx] = math.nan
                continue
        else:
            if not shadowing and t_ == HALF_PI:
                out[idx] = math.nan
                continue
            den = denominator(t_, p_, a_, b_, r_, shadowing, 1e-10, "phi_outer")
        if g1 == 0.0 or e_ == 0.0 or c[2] <= -math.sin(radius):
            out[idx] = 0.0  # masked, dark, or the whole disk below the horizon
            continue
        num = _DiskIntegral(v, c, radius, a_, b_, r_, mean, m_, centre, epsrel).integral()
        out[idx] = g1 * e_ * l_unit * num / den
    return out

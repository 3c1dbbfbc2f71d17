"""The nested adaptive quadrature of the facet integrals (reference, numpy/scipy).

For one geometry and one slope law, :class:`FacetIntegral` integrates the paper's facet weight
p(theta, phi) cos(Omega)/cos(theta) [H(pi/2 - Omega)] (Eqs. 5/7, density of Eq. A7/A8), times
1 - rho (emissivity) or the Eq. 10 radiance, over the facet-normal angles; :class:`SkyRadiance` is
R_s as a function of the reflected ray's cos(zenith). The model and its conventions:
:mod:`roughsea_torch.reference.rough_sea`, whose public functions normalize these integrals.

Integration: scipy.integrate.quad, nested. Default ("phi_outer"): outer integral over the facet
azimuth phi in [0, 2 pi], inner over theta. For each phi the inner theta range is cut, in closed form,
at the places where the integrand jumps or kinks:

  * shadow edge cos(Omega) = 0. Writing cos(Omega) = A cos(theta - delta) with
    A = sqrt(cos^2 th + sin^2 th cos^2(phi - ph)), delta = atan2(sin th cos(phi - ph), cos th),
    the edge is theta_s = pi/2 + delta (inside [0, pi/2) only when cos(phi - ph) < 0).
    With shadowing theta_s is the upper limit (H = 0 beyond); without it theta_s is a breakpoint
    (rho(|cos Omega|) has a kink there and the weight changes sign).
  * sky/sea edge cos(theta') = 0. Eq. 9 gives cos(theta') = A cos(2 theta - delta), so the edge is
    theta_k = pi/4 + delta/2 = theta_s / 2. For theta > theta_k the reflected ray goes into the sea
    (sees R_B).
  * for a tabulated sky, the theta where theta' crosses a table node (PCHIP knots and the clamp).
  * the density: tan(theta) is cut at N_RMS = 12 rms slopes of the slope component along phi,
    1/sqrt(q(phi)), q = E(phi, r)/(1 - r^2) (Eq. A8); the neglected mass is exp(-72).

The outer phi integral gets breakpoints at ph + k pi/2 (where the shadow/sky edges enter) and at
the principal axes of the slope covariance, plus, when the law is strongly anisotropic, a geometric
ladder alpha +- w 8^j around the major axis alpha (w = sqrt(l_min/l_max), the angular half-width of
the phi-marginal of the density).
A second, independent ordering ("theta_outer": theta outside, phi inside with the edges solved for
phi) is provided for cross-checks.

Shifted slope law (mu != 0, :mod:`roughsea_torch.reference.rough_sea`):
  * Support and breakpoints. The density is no longer centred on theta = 0, so the N_RMS cut is
    taken along each ray s = t (cos phi, sin phi): there the exponent is a Gaussian in t of centre
    t0 = B/Q, rms 1/sqrt(Q) (Q = u^T Sigma^-1 u, B = u^T Sigma^-1 mu), so theta runs over
    atan(t0 -+ N_RMS/sqrt(Q)) (clipped at 0) with a breakpoint at the peak atan(t0); rays that never
    come within N_RMS (Mahalanobis) of mu are empty. The outer phi integral keeps the breakpoints
    above and adds the mean azimuth alpha_mu = atan2(mu_y, mu_x) with a ladder alpha_mu +- w 8^j,
    w = sqrt(l_min)/|mu|: a mean |mu| >> rms makes the phi-marginal a peak of width ~rms/|mu| there.
    The theta_outer ordering uses |s| in |mu| -+ N_RMS sqrt(l_max), breakpoints at |s| = |mu| with a
    ladder, and, on each ring |s| = t, the azimuths where the ring meets the major axis through mu.

Shared within the reference (used by :mod:`~roughsea_torch.reference.rough_sea` and
:mod:`~roughsea_torch.reference.sun`): ``HALF_PI``, ``TWO_PI``, ``N_RMS``, :class:`SkyRadiance`,
:class:`FacetIntegral`, :func:`pdf_shifted_scalar`, :func:`unique_mod_2pi`.
"""

import math

import numpy as np
from scipy import integrate
from scipy.interpolate import PchipInterpolator

from .fresnel import fresnel_scalar
from .slopes import pdf_scalar

__all__ = ["HALF_PI", "TWO_PI", "N_RMS", "SkyRadiance", "FacetIntegral", "pdf_shifted_scalar", "unique_mod_2pi"]

HALF_PI = 0.5 * math.pi
TWO_PI = 2.0 * math.pi
N_RMS = 12.0  # density support: |slope along phi| < 12 rms slopes


# ----------------------------------------------------------------------------- sky radiance

class SkyRadiance:
    """Sky radiance R_s as a function of cos(zenith) of the reflected ray (W m^-2 sr^-1)."""

    def __init__(self, sky):
        self.nodes = None
        self.constant = None
        if callable(sky):
            self.kind = "callable"
            self.func = sky
        elif isinstance(sky, (tuple, list)) and len(sky) == 2:
            z = np.asarray(sky[0], dtype=np.float64)
            rad = np.asarray(sky[1], dtype=np.float64)
            if z.ndim != 1 or rad.shape != z.shape or z.size < 2:
                raise ValueError("sky table must be two 1-d arrays of equal length >= 2")
            if np.any(np.diff(z) <= 0) or z[0] < 0 or z[-1] > HALF_PI + 1e-12:
                raise ValueError("sky table zenith must be strictly ascending within [0, pi/2]")
            self.kind = "table"
            self.nodes = z
            self.values = rad
            self.interp = PchipInterpolator(z, rad, extrapolate=False)
        else:
            v = np.asarray(sky, dtype=np.float64)
            if v.ndim != 0:
                raise ValueError("sky must be a callable, a constant or a (zenith, radiance) table")
            self.kind = "constant"
            self.constant = float(v)

    def __call__(self, cos_zenith):
        if self.kind == "constant":
            return self.constant
        if self.kind == "callable":
            x = np.array([cos_zenith], dtype=np.float64)
            y = np.broadcast_to(np.asarray(self.func(x), dtype=np.float64), x.shape)
            return float(y[0])
        zen = math.acos(min(max(cos_zenith, -1.0), 1.0))
        if zen <= self.nodes[0]:
            return float(self.values[0])
        if zen >= self.nodes[-1]:
            return float(self.values[-1])
        return float(self.interp(zen))


# ----------------------------------------------------------------------------- the integrand

class FacetIntegral:
    """Scalar integrand of Eqs. 5/7 and 10 for one geometry and one slope law, and its quadrature.

    kind: "area"  integrand p cos(Omega)/cos(theta) [H]                      (Eq. 5 denominator)
          "emis"  integrand p cos(Omega)/cos(theta) [H] (1 - rho(|cos Omega|))
          "rad"   integrand p cos(Omega)/cos(theta) [H] {(1 - rho) R_B + rho R_s(theta')} (Eq. 10)
    The integrals returned are NOT normalized (divide by D, see the public functions).
    mean = (mean_upwind, mean_crosswind): mean of the slope Gaussian. (0, 0) is the paper's law and
    runs the unshifted code unchanged; otherwise the shifted density and its support/breakpoints are
    used (see the module docstring).
    """

    def __init__(self, theta_hat, phi_hat, a, b, r, shadowing, kind,
                 m=None, sea_radiance=None, sky=None, mean=(0.0, 0.0), weight=None):
        self.th = float(theta_hat)
        self.ph = float(phi_hat)
        self.ct = math.cos(self.th)
        self.st = math.sin(self.th)
        self.a, self.b, self.r = float(a), float(b), float(r)
        self.shadowing = bool(shadowing)
        self.weight = weight  # None, or a factor of the slope along the view (masking.masking_curve)
        self.kind = kind
        self.m = m
        self.R_B = None if sea_radiance is None else float(sea_radiance)
        self.sky = sky
        # degenerate slope laws: slopes along one axis only (facet normals in one vertical plane)
        if self.a > 0.0 and self.b > 0.0:
            self.line = None
        elif self.b == 0.0:
            self.line = (self.a, (0.0, math.pi))           # s_y = 0: phi = 0 or pi
        else:
            self.line = (self.b, (HALF_PI, 1.5 * math.pi))  # s_x = 0: phi = pi/2 or 3pi/2
        self.mx, self.my = float(mean[0]), float(mean[1])
        self.shifted = self.mx != 0.0 or self.my != 0.0
        if self.shifted:
            if self.line is not None:
                raise NotImplementedError("a non-zero slope_mean needs both rms slopes > 0")
            # inverse covariance Sigma^-1 = [[ixx, ixy], [ixy, iyy]] and the eigenvalues of Sigma
            one_r2 = 1.0 - self.r * self.r
            self.ixx = 1.0 / (self.a * self.a * one_r2)
            self.iyy = 1.0 / (self.b * self.b * one_r2)
            self.ixy = -self.r / (self.a * self.b * one_r2)
            self.mean_maha2 = (self.ixx * self.mx * self.mx + 2.0 * self.ixy * self.mx * self.my
                               + self.iyy * self.my * self.my)  # mu^T Sigma^-1 mu
            tr = self.a * self.a + self.b * self.b
            det = self.a * self.a * self.b * self.b * one_r2
            self.lam1 = 0.5 * tr + math.sqrt(max(0.25 * tr * tr - det, 0.0))
            self.lam2 = det / self.lam1

    # --- model pieces --------------------------------------------------------------------------
    def density(self, theta, phi):
        """p(theta, phi), Eq. A7/A8; for a degenerate (line) law the density along the line."""
        if self.shifted:
            return pdf_shifted_scalar(theta, phi, self.a, self.b, self.r, self.mx, self.my)
        if self.line is None:
            return pdf_scalar(theta, phi, self.a, self.b, self.r)
        sig = self.line[0]
        t = math.tan(theta)
        cos_t = math.cos(theta)
        # s ~ N(0, sig^2) along the line; each sign of s gives one azimuth; ds = sec^2 dtheta
        return math.exp(-0.5 * t * t / (sig * sig)) / (math.sqrt(TWO_PI) * sig * cos_t * cos_t)

    def integrand(self, theta, phi):
        cos_theta = math.cos(theta)
        cos_omega = cos_theta * self.ct + math.sin(theta) * self.st * math.cos(phi - self.ph)  # Eq. 6
        if self.shadowing and not cos_omega > 0.0:  # H(pi/2 - Omega), Eq. 5
            return 0.0
        w = self.density(theta, phi) * cos_omega / cos_theta  # Eq. 3 / 5 numerator
        if self.weight is not None:  # slope-conditioned masking; s_par = tan(theta) cos(phi - ph)
            w *= self.weight(math.tan(theta) * math.cos(phi - self.ph))
        if self.kind == "area":
            return w
        rho = fresnel_scalar(abs(cos_omega), self.m)
        if self.kind == "emis":
            return w * (1.0 - rho)
        cos_tp = 2.0 * cos_omega * cos_theta - self.ct  # Eq. 9
        if cos_tp < 0.0:
            r_s = self.R_B  # reflected ray goes into the sea: it sees the sea (docs/physics.md sec. 4)
        else:
            r_s = self.sky(min(cos_tp, 1.0))
        return w * ((1.0 - rho) * self.R_B + rho * r_s)  # Eq. 10

    def theta_max(self, phi):
        """theta where tan(theta) = N_RMS rms slopes of the slope component along azimuth phi."""
        if self.line is not None:
            return math.atan(N_RMS * self.line[0])
        a, b, r = self.a, self.b, self.r
        c, s = math.cos(phi), math.sin(phi)
        e = c * c / (a * a) + s * s / (b * b) - 2.0 * r * c * s / (a * b)  # Eq. A8
        q = e / (1.0 - r * r)
        return math.atan(N_RMS / math.sqrt(q))

    def theta_max_global(self):
        if self.line is not None:
            return math.atan(N_RMS * self.line[0])
        a, b, r = self.a, self.b, self.r
        tr = a * a + b * b
        det = a * a * b * b * (1.0 - r * r)
        lam_max = 0.5 * tr + math.sqrt(max(0.25 * tr * tr - det, 0.0))
        return math.atan(N_RMS * math.sqrt(lam_max))

    def principal_azimuths(self):
        """Azimuths of the principal axes of the slope covariance, plus, for a strongly anisotropic
        law, a geometric ladder of breakpoints around the major axis.

        The phi-marginal of the density is the angular central Gaussian
        sqrt(l1 l2) / (2 pi (l2 cos^2(phi - alpha) + l1 sin^2(phi - alpha))), a Lorentzian-like peak of
        half-width w = sqrt(l2 / l1) (l1 >= l2 the covariance eigenvalues) with 1/phi^2 tails. When w is
        small, Gauss-Kronrod nodes on [alpha, alpha + pi/2] would step over the peak; breakpoints at
        alpha +- w 8^j (j = 0, 1, ...) give quad panels matched to every scale of the peak.
        """
        if self.line is not None:
            return list(self.line[1])
        a, b, r = self.a, self.b, self.r
        alpha = 0.5 * math.atan2(2.0 * r * a * b, a * a - b * b)
        pts = [alpha + k * HALF_PI for k in range(4)]
        tr = a * a + b * b
        det = a * a * b * b * (1.0 - r * r)
        disc = math.sqrt(max(0.25 * tr * tr - det, 0.0))
        lam1 = 0.5 * tr + disc
        lam2 = det / lam1
        w = math.sqrt(lam2 / lam1)
        while w < 0.25 * math.pi:
            for axis in (alpha, alpha + math.pi):
                pts.extend([axis - w, axis + w])
            w *= 8.0
        return pts

    def ray_support(self, phi):
        """Shifted law: (theta_lo, theta_hi, peaks) of the density along the ray s = t (cos phi, sin phi).

        On the ray the exponent (s - mu)^T Sigma^-1 (s - mu) = Q t^2 - 2 B t + mu^T Sigma^-1 mu,
        Q = u^T Sigma^-1 u (= E(phi, r)/(1 - r^2), Eq. A8), B = u^T Sigma^-1 mu, u = (cos phi, sin phi):
        a Gaussian in t of centre t0 = B/Q and rms 1/sqrt(Q). The support is t0 -+ N_RMS/sqrt(Q),
        clipped to t >= 0; it is empty when the ray stays more than N_RMS (Mahalanobis) from mu.
        peaks: [atan(t0)] when t0 > 0 (a breakpoint, so quad cannot step over the peak).
        """
        c, s = math.cos(phi), math.sin(phi)
        q = self.ixx * c * c + 2.0 * self.ixy * c * s + self.iyy * s * s
        b = self.ixx * c * self.mx + self.ixy * (c * self.my + s * self.mx) + self.iyy * s * self.my
        t0 = b / q
        closest2 = self.mean_maha2 - (b * t0 if t0 > 0.0 else 0.0)  # min over t >= 0 of the exponent
        half = N_RMS / math.sqrt(q)
        if closest2 > N_RMS * N_RMS or t0 + half <= 0.0:
            return 0.0, 0.0, []
        return math.atan(max(t0 - half, 0.0)), math.atan(t0 + half), ([math.atan(t0)] if t0 > 0.0 else [])

    def mean_azimuths(self):
        """Shifted law: azimuth breakpoints around the azimuth alpha_mu of the mean slope.

        Seen from s = 0 a mean |mu| >> rms makes the phi-marginal a peak at alpha_mu of angular
        half-width ~ rms/|mu|: breakpoints at alpha_mu and alpha_mu +- w 8^j, w = sqrt(l_min)/|mu|,
        up to pi/4 (the same ladder idea as principal_azimuths). Empty for the unshifted law.
        """
        if not self.shifted:
            return []
        alpha = math.atan2(self.my, self.mx)
        pts = [alpha]
        w = math.sqrt(self.lam2) / math.hypot(self.mx, self.my)
        while w < 0.25 * math.pi:
            pts.extend([alpha - w, alpha + w])
            w *= 8.0
        return pts

    def ring_azimuths(self, theta):
        """Shifted law, theta-outer ordering: azimuth breakpoints on the ring |s| = t = tan(theta).

        A thin law has its mass along its major axis through mu, the line mu + l e1. The ring meets
        it where l^2 + 2 l (mu . e1) + |mu|^2 - t^2 = 0; breakpoints there, with a ladder of angular
        half-widths sqrt(l_min)/t 8^j up to pi/4, and at the azimuth of the line's point nearest s = 0.
        """
        t = math.tan(theta)
        alpha = 0.5 * math.atan2(2.0 * self.r * self.a * self.b, self.a * self.a - self.b * self.b)
        ex, ey = math.cos(alpha), math.sin(alpha)  # major axis e1
        proj = self.mx * ex + self.my * ey
        pts = [math.atan2(self.my - proj * ey, self.mx - proj * ex)]
        disc = proj * proj - (self.mx * self.mx + self.my * self.my) + t * t
        if disc >= 0.0 and t > 0.0:
            for lam in (-proj - math.sqrt(disc), -proj + math.sqrt(disc)):
                phi0 = math.atan2(self.my + lam * ey, self.mx + lam * ex)
                pts.append(phi0)
                w = math.sqrt(self.lam2) / t
                while w < 0.25 * math.pi:
                    pts.extend([phi0 - w, phi0 + w])
                    w *= 8.0
        return pts

    # --- phi outer, theta inner ----------------------------------------------------------------
    def theta_edges(self, phi):
        """Closed-form theta breakpoints (sorted, with the lower and upper limits) for azimuth phi."""
        c = math.cos(phi - self.ph)
        delta = math.atan2(self.st * c, self.ct)
        theta_shadow = HALF_PI + delta   # cos(Omega) = 0, Eq. 6
        theta_sky = 0.5 * theta_shadow   # cos(theta') = 0, Eq. 9
        if self.shifted:
            lower, upper, cuts = self.ray_support(phi)
        else:
            lower, upper, cuts = 0.0, self.theta_max(phi), []
        if self.shadowing:
            upper = min(upper, theta_shadow)
        if upper <= lower:
            return [lower]
        if not self.shadowing:
            cuts.append(theta_shadow)
        if self.kind == "rad":
            cuts.append(theta_sky)
            if self.sky.nodes is not None:
                amp = math.hypot(self.ct, self.st * c)
                for z in self.sky.nodes:
                    x = math.cos(z) / amp
                    if abs(x) <= 1.0:
                        g = math.acos(x)
                        cuts.extend([0.5 * (delta + g), 0.5 * (delta - g)])
        inner = sorted(x for x in cuts if lower < x < upper)
        return [lower] + inner + [upper]

    def theta_integral(self, phi, epsrel):
        edges = self.theta_edges(phi)
        total = 0.0
        for lo, hi in zip(edges[:-1], edges[1:]):
            if hi - lo < 1e-13:  # sliver (e.g. shadow edge at theta ~ 1e-16): midpoint rule is exact enough
                total += (hi - lo) * self.integrand(0.5 * (lo + hi), phi)
            else:
                total += integrate.quad(self.integrand, lo, hi, args=(phi,),
                                        epsabs=0.0, epsrel=epsrel, limit=200)[0]
        return total

    def phi_outer(self, epsrel, epsabs=0.0):
        inner_eps = max(1e-2 * epsrel, 1e-13)
        if self.line is not None:
            return sum(self.theta_integral(phi0, inner_eps) for phi0 in self.line[1])
        pts = [self.ph + k * HALF_PI for k in range(4)] + self.principal_azimuths()
        pts = unique_mod_2pi(pts + self.mean_azimuths())
        return integrate.quad(self.theta_integral, 0.0, TWO_PI, args=(inner_eps,),
                              points=pts, epsabs=epsabs, epsrel=epsrel, limit=1000)[0]

    # --- theta outer, phi inner (independent ordering, for cross-checks) --------------------------
    def phi_edges(self, theta):
        cos2, sin2 = math.cos(2.0 * theta), math.sin(2.0 * theta)
        cs = []  # values of cos(phi - ph) where something happens
        if self.st > 0.0 and math.sin(theta) > 0.0:
            cs.append(-math.cos(theta) * self.ct / (math.sin(theta) * self.st))   # cos(Omega) = 0
            if self.kind == "rad":
                cs.append(-cos2 * self.ct / (sin2 * self.st))                       # cos(theta') = 0
                if self.sky.nodes is not None:
                    for z in self.sky.nodes:
                        cs.append((math.cos(z) - cos2 * self.ct) / (sin2 * self.st))
        pts = [self.ph + k * HALF_PI for k in range(4)] + self.principal_azimuths()
        if self.shifted:
            pts += self.mean_azimuths() + self.ring_azimuths(theta)
        for c in cs:
            if -1.0 <= c <= 1.0:
                g = math.acos(c)
                pts.extend([self.ph + g, self.ph - g])
        return unique_mod_2pi(pts)

    def phi_integral(self, theta, epsrel, epsabs=0.0):
        return integrate.quad(lambda phi: self.integrand(theta, phi), 0.0, TWO_PI,
                              points=self.phi_edges(theta), epsabs=epsabs, epsrel=epsrel,
                              limit=1000)[0]

    def theta_outer(self, epsrel, epsabs=0.0):
        inner_eps = max(1e-2 * epsrel, 1e-13)
        if self.line is not None:
            return self.phi_outer(epsrel)
        lower, upper = 0.0, self.theta_max_global()
        pts = [HALF_PI - self.th]
        if self.kind == "rad":
            pts += [0.5 * (HALF_PI - self.th), 0.5 * (HALF_PI + self.th)]
            if self.sky.nodes is not None:
                for z in self.sky.nodes:
                    pts += [0.5 * (z + self.th), 0.5 * (z - self.th), 0.5 * (self.th - z)]
        axes = self.principal_azimuths()[:4]
        if self.shifted:
            # |s| of the N_RMS ellipse around mu lies within |mu| -+ N_RMS sqrt(l_max); breakpoints at
            # |s| = |mu| and a ladder |mu| +- sqrt(l_min) 8^j, and the edges along the mean azimuth
            norm = math.hypot(self.mx, self.my)
            reach = N_RMS * math.sqrt(self.lam1)
            lower, upper = math.atan(max(norm - reach, 0.0)), math.atan(norm + reach)
            pts.append(math.atan(norm))
            w = math.sqrt(self.lam2)
            while w < reach:
                pts.extend([math.atan(max(norm - w, 0.0)), math.atan(norm + w)])
                w *= 8.0
            axes = axes + [math.atan2(self.my, self.mx)]
        # theta where the shadow / sky edges cross the principal axes (where the mass is when a/b >> 1)
        for beta in axes:
            c = math.cos(beta - self.ph)
            theta_shadow = HALF_PI + math.atan2(self.st * c, self.ct)
            pts.append(theta_shadow)
            if self.kind == "rad":
                pts.append(0.5 * theta_shadow)
        pts = sorted(x for x in pts if lower < x < upper)
        if self.shifted:  # the mean azimuth can repeat an axis: drop near-duplicates (they upset quad)
            pts = [x for i, x in enumerate(pts) if i == 0 or x - pts[i - 1] > 1e-13]
        # shifted: the theta range is a bound (a circle around mu), and on its rims the ring integral can be
        # subnormal (~1e-316), where quad reports roundoff; an absolute floor of 1e-200 ends that
        inner_abs = max(10.0 * epsabs, 1e-200) if self.shifted else 0.0
        return integrate.quad(self.phi_integral, lower, upper, args=(inner_eps, inner_abs),
                              points=pts or None, epsabs=epsabs, epsrel=epsrel, limit=1000)[0]

    def integral(self, epsrel, method, epsabs=0.0):
        if method == "phi_outer":
            return self.phi_outer(epsrel, epsabs)
        if method == "theta_outer":
            return self.theta_outer(epsrel, epsabs)
        raise ValueError("method must be 'phi_outer' or 'theta_outer'")


def pdf_shifted_scalar(theta, phi, a, b, r, mx, my):
    """Density of facet normals (per rad^2) when the slopes are N(s; mu, Sigma), mu = (mx, my) != 0.

    Same change of variables as Eq. A5-A7: s = tan(theta) (cos phi, sin phi) with the facet normal
    n = (s_x, s_y, 1)/sqrt(1 + |s|^2) (polar angle theta, azimuth phi). In the slope plane these are
    polar coordinates of radius t = tan(theta): ds_x ds_y = t dt dphi = tan(theta) sec^2(theta) dtheta dphi.
    Hence
      p_mu(theta, phi) = sec^2(theta) tan(theta) / (2 pi a b sqrt(1 - r^2))
                         * exp(-[dx^2/a^2 - 2 r dx dy/(a b) + dy^2/b^2] / (2 (1 - r^2))),
      dx = tan(theta) cos(phi) - mx,  dy = tan(theta) sin(phi) - my,
    i.e. N(s; mu, Sigma) tan(theta) sec^2(theta); mu = 0 is Eq. A7/A8. Needs a, b > 0, |r| < 1;
    0 outside theta in [0, pi/2).
    """
    if not (0.0 <= theta < 0.5 * math.pi):
        return 0.0
    t = math.tan(theta)
    dx = t * math.cos(phi) - mx
    dy = t * math.sin(phi) - my
    one_r2 = 1.0 - r * r
    maha2 = (dx * dx / (a * a) - 2.0 * r * dx * dy / (a * b) + dy * dy / (b * b)) / one_r2
    cos_t = math.cos(theta)
    return (t / (cos_t * cos_t) / (2.0 * math.pi * a * b * math.sqrt(one_r2))
            * math.exp(-0.5 * maha2))


def unique_mod_2pi(values):
    """Reduce azimuths to (0, 2 pi), sort, drop near-duplicates and the end points."""
    out = []
    for v in sorted(x % TWO_PI for x in values):
        if 1e-13 < v < TWO_PI - 1e-13 and (not out or v - out[-1] > 1e-13):
            out.append(v)
    return out

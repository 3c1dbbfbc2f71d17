"""Self-checks of the numpy reference (a script, not a pytest file).

Run from the repository root:  python -m roughsea_torch.reference._selfcheck [--quick]
Prints comparisons; nothing is asserted silently. --quick skips the long tolerance table.
"""

import math
import sys
import time
import warnings

import numpy as np
from scipy import integrate, special, stats

from roughsea_torch.reference import (SlopeStatistics, apparent_radiance, band_radiance,
                                      brightness_temperature, emissivity, fresnel_reflectance,
                                      planck_radiance, projected_area, slope_pdf)
from roughsea_torch.reference.fresnel import fresnel_scalar
from roughsea_torch.reference.rough_sea import numerator

DEG = math.pi / 180.0
HQ = {"4um": complex(1.351, 0.0046), "10um": complex(1.218, 0.0508),
      "11um": complex(1.153, 0.0968), "12um": complex(1.111, 0.199)}


def sky_fn(c):
    """A smooth sky, decreasing with elevation: 30 at the horizon, 11 at the zenith (W m^-2 sr^-1)."""
    return 11.0 + 19.0 * (1.0 - c) ** 8


def header(title):
    print()
    print("=" * 100)
    print(title)
    print("=" * 100)


def closed_form_D(th, ph, a, b, r):
    """docs/physics.md sec. 3: D = cos th Phi(mu) + sin th s_par phi_N(mu), mu = cot th / s_par."""
    s_par = math.sqrt(a * a * math.cos(ph) ** 2 + 2 * r * a * b * math.cos(ph) * math.sin(ph)
                      + b * b * math.sin(ph) ** 2)
    ct, st = math.cos(th), math.sin(th)
    if s_par == 0.0:
        return ct
    mu = ct / (st * s_par) if st > 0 else math.inf
    return ct * stats.norm.cdf(mu) + st * s_par * stats.norm.pdf(mu)


def timed(f, *args, **kw):
    with warnings.catch_warnings(record=True) as wl:
        warnings.simplefilter("always")
        t0 = time.perf_counter()
        v = f(*args, **kw)
        dt = time.perf_counter() - t0
    return float(v), dt, len(wl)


# --------------------------------------------------------------------------------------- checks

def check_pdf():
    header("1. slope_pdf: normalization and equality with the transformed bivariate normal")
    laws = [("isotropic W=10", SlopeStatistics.cox_munk(10.0)),
            ("a/b = 10, r = 0", SlopeStatistics(0.2, 0.02, 0.0)),
            ("a/b = 10, r = 0.9", SlopeStatistics(0.2, 0.02, 0.9)),
            ("a = b = 7.07e-4, r = 0.9", SlopeStatistics(7.0710678e-4, 7.0710678e-4, 0.9)),
            ("a/b = 0.3, r = -0.6", SlopeStatistics(0.05, 0.15, -0.6))]
    for name, S in laws:
        a, b, r = float(S.std_upwind), float(S.std_crosswind), float(S.corr)
        f = lambda th, ph: float(slope_pdf(th, ph, S))  # noqa: E731

        def inner(ph):
            e = (math.cos(ph) ** 2 / a ** 2 + math.sin(ph) ** 2 / b ** 2
                 - 2 * r * math.cos(ph) * math.sin(ph) / (a * b)) / (1 - r * r)
            t_cut = math.atan(12.0 / math.sqrt(e))
            body = integrate.quad(f, 0.0, t_cut, args=(ph,), epsabs=0, epsrel=1e-12, limit=200)[0]
            tail = integrate.quad(f, t_cut, math.pi / 2, args=(ph,), epsabs=1e-300, epsrel=1e-10,
                                  limit=200)[0]
            return body + tail
        alpha = 0.5 * math.atan2(2 * r * a * b, a * a - b * b)
        pts = sorted((alpha + k * math.pi / 2) % (2 * math.pi) for k in range(4))
        total = integrate.quad(inner, 0.0, 2 * math.pi, points=pts, epsabs=0, epsrel=1e-11,
                               limit=500)[0]
        # also through the model's own machinery: D at th = 0 is int p dtheta dphi
        d0 = float(projected_area(0.0, 0.0, S))
        # pointwise: p(theta, phi) == N(s; 0, Sigma) * tan(theta) sec^2(theta)
        rng = np.random.default_rng(1)
        cov = [[a * a, r * a * b], [r * a * b, b * b]]
        smax = 3 * max(a, b)
        th = np.arctan(rng.uniform(0, smax, 50))
        ph = rng.uniform(0, 2 * np.pi, 50)
        s = np.stack([np.tan(th) * np.cos(ph), np.tan(th) * np.sin(ph)], axis=-1)
        ref = stats.multivariate_normal(mean=[0, 0], cov=cov).pdf(s) * np.tan(th) / np.cos(th) ** 2
        mine = slope_pdf(th, ph, S)
        ok = ref > 1e-250  # far in the tail the bivariate normal underflows to 0
        rel = np.max(np.abs(mine[ok] / ref[ok] - 1))
        print(f"  {name:26s} int p = {total:.15f} (err {total - 1:+.1e});  D(th=0) = {d0:.15f} "
              f"(err {d0 - 1:+.1e});  max |p/bivariate - 1| = {rel:.1e}")


def check_area_noshadow():
    header("2. projected_area(shadowing=False) == cos(theta_hat)")
    laws = [("iso W=10", SlopeStatistics.cox_munk(10.0)),
            ("aniso W=10", SlopeStatistics.cox_munk(10.0, anisotropic=True)),
            ("a/b=10 r=0.9", SlopeStatistics(0.2, 0.02, 0.9)),
            ("calm sigma^2=1e-6", SlopeStatistics(7.0710678e-4, 7.0710678e-4)),
            ("iso W=40", SlopeStatistics.cox_munk(40.0))]
    for name, S in laws:
        row = []
        for thd, phd in [(0, 0), (30, 20), (60, 135), (85, 250), (89.99, 33)]:
            th = thd * DEG
            d, dt, nw = timed(projected_area, th, phd * DEG, S, shadowing=False)
            row.append(f"{thd:5.2f}/{phd:3d}: {d / math.cos(th) - 1:+.1e}")
        print(f"  {name:18s} rel.err  " + "  ".join(row))


def check_area_shadow():
    header("3. projected_area(shadowing=True): quadrature (phi-outer and theta-outer) vs the closed form of docs/physics.md sec. 3")
    laws = [("iso W=10", SlopeStatistics.cox_munk(10.0)),
            ("aniso W=10", SlopeStatistics.cox_munk(10.0, anisotropic=True)),
            ("a/b=10 r=0.9", SlopeStatistics(0.2, 0.02, 0.9)),
            ("a/b=10 r=-0.9", SlopeStatistics(0.2, 0.02, -0.9)),
            ("calm sigma^2=1e-6", SlopeStatistics(7.0710678e-4, 7.0710678e-4)),
            ("iso W=40", SlopeStatistics.cox_munk(40.0)),
            ("line b=0", SlopeStatistics(0.15, 0.0))]
    worst = 0.0
    for name, S in laws:
        a, b, r = float(S.std_upwind), float(S.std_crosswind), float(S.corr)
        for thd, phd in [(60, 20), (80, 135), (85, 250), (89, 0), (89.99, 33), (90, 100)]:
            th, ph = thd * DEG, phd * DEG
            dc = closed_form_D(th, ph, a, b, r)
            d1, t1, w1 = timed(projected_area, th, ph, S, method="phi_outer")
            d2, t2, w2 = timed(projected_area, th, ph, S, method="theta_outer")
            worst = max(worst, abs(d1 / dc - 1), abs(d2 / dc - 1))
            print(f"  {name:18s} th={thd:6.2f} ph={phd:3d}  closed {dc:.15e}  phi-outer {d1 / dc - 1:+.1e}"
                  f"  theta-outer {d2 / dc - 1:+.1e}  ({t1:.2f}s/{t2:.2f}s, warnings {w1}/{w2})")
    print(f"  worst relative difference: {worst:.1e}")


def check_second_law():
    header("4. Second law: sky == sea_radiance -> R_a == sea_radiance")
    m = HQ["11um"]
    rb = 30.0
    zt = np.linspace(0, math.pi / 2, 7)
    skies = [("constant", rb), ("callable", lambda c: np.full_like(c, rb)),
             ("table", (zt, np.full_like(zt, rb)))]
    laws = [("iso W=10", SlopeStatistics.cox_munk(10.0)),
            ("a/b=10 r=0.9", SlopeStatistics(0.2, 0.02, 0.9)),
            ("calm sigma^2=1e-6", SlopeStatistics(7.0710678e-4, 7.0710678e-4)),
            ("iso W=40", SlopeStatistics.cox_munk(40.0))]
    worst = 0.0
    for name, S in laws:
        row = []
        for thd in [0.0, 60.0, 85.0, 89.99]:
            for sh in (True, False):
                for sname, sk in skies:
                    v, dt, nw = timed(apparent_radiance, thd * DEG, 0.4, S, m, rb, sk, shadowing=sh)
                    worst = max(worst, abs(v / rb - 1))
            row.append(f"{thd:5.2f}: {v / rb - 1:+.1e}")
        print(f"  {name:18s} (last sky, no shadow) " + "  ".join(row))
    print(f"  worst |R_a/R_B - 1| over all (geometry, shadowing, sky type): {worst:.1e}")


def check_facts():
    header("5. Flat-sea limit and the facts of docs/physics.md sec. 13")
    expect_n = {"4um": 0.97771, "10um": 0.98982, "11um": 0.99294, "12um": 0.98845}
    for key, m in HQ.items():
        e = 1 - float(fresnel_reflectance(1.0, m))
        e0 = 1 - ((m.real - 1) ** 2 + m.imag ** 2) / ((m.real + 1) ** 2 + m.imag ** 2)
        print(f"  normal incidence {key:4s} m={m}: 1-rho = {e:.5f} (closed {e0:.5f}, docs/physics.md {expect_n[key]:.5f})")
    flat = SlopeStatistics(0.0, 0.0)
    expect = {("10um", 85): 0.4544, ("10um", 89): 0.1152, ("11um", 85): 0.4682, ("11um", 89): 0.1194}
    for (key, thd), ex in expect.items():
        e = float(emissivity(thd * DEG, 0.0, flat, HQ[key]))
        print(f"  flat sea {key:4s} {thd} deg: emissivity = {e:.4f} ({e:.7f}); docs/physics.md {ex}")
    # emissivity of a very calm sea tends to the flat value
    calm = SlopeStatistics(1e-6, 1e-6)
    e = float(emissivity(85 * DEG, 0.0, calm, HQ["11um"]))
    print(f"  rms slope 1e-6 (quadrature), 11um, 85 deg: {e:.10f} vs flat {1 - fresnel_scalar(math.cos(85 * DEG), HQ['11um']):.10f}")
    # unnormalized emissivity (Eq. 5 numerator divided by cos th instead of D)
    S15 = SlopeStatistics.cox_munk(15.0)
    a = float(S15.std_upwind)
    th = 85 * DEG
    num = numerator("emis", th, 0.0, a, a, 0.0, True, m=HQ["11um"])
    d = float(projected_area(th, 0.0, S15))
    e_norm = float(emissivity(th, 0.0, S15, HQ["11um"]))
    print(f"  W=15 iso, 11um, 85 deg: unnormalized (num/cos th) = {num / math.cos(th):.4f}  (docs/physics.md ~1.19);"
          f" normalized (Eq. 5) = {e_norm:.4f}; no shadowing (Eq. 7) = "
          f"{float(emissivity(th, 0.0, S15, HQ['11um'], shadowing=False)):.4f}; D/cos = {d / math.cos(th):.4f}")
    for w, ex in [(5.0, 0.185), (10.0, 0.354)]:
        S = SlopeStatistics.cox_munk(w)
        lam = float(projected_area(th, 0.0, S)) / math.cos(th) - 1
        sigma = math.sqrt(0.003 + 5.12e-3 * w)
        nu = 1 / math.tan(th) / sigma
        smith = 0.5 * (math.exp(-nu * nu) / (nu * math.sqrt(math.pi)) - special.erfc(nu))
        print(f"  Smith Lambda, 85 deg, W={w:g}: D/cos - 1 = {lam:.6f}; Smith formula {smith:.6f}; docs/physics.md {ex}")


def check_misc():
    header("5b. Fresnel, Planck, band radiance, edge cases")
    # Fresnel with k = 0 vs Snell-angle textbook forms
    n = 1.33
    for deg in [0.0, 30.0, 60.0, 85.0, 89.0]:
        ti = deg * DEG
        tt = math.asin(math.sin(ti) / n)
        if deg == 0.0:
            rs = rp = ((n - 1) / (n + 1)) ** 2
        else:
            rs = (math.sin(ti - tt) / math.sin(ti + tt)) ** 2
            rp = (math.tan(ti - tt) / math.tan(ti + tt)) ** 2
        mine_s = float(fresnel_reflectance(math.cos(ti), n, "s"))
        mine_p = float(fresnel_reflectance(math.cos(ti), (n, 0.0), "p"))
        print(f"  Fresnel n=1.33 {deg:4.1f} deg: s {mine_s:.15f} vs Snell {rs:.15f}; p {mine_p:.15f} vs {rp:.15f}")
    c = np.linspace(-1, 1, 41)
    v = fresnel_reflectance(c, np.array([HQ['10um']]))
    sc = np.array([fresnel_scalar(abs(x), HQ['10um']) for x in c])
    print(f"  vectorized vs scalar Fresnel, max diff {np.max(np.abs(v - sc)):.1e}; even in cos: "
          f"{np.max(np.abs(v - v[::-1])):.1e}; rho(cos=0) = {float(fresnel_reflectance(0.0, HQ['10um'])):.15f}")
    # Planck
    b = float(planck_radiance(10e-6, 300.0))
    print(f"  planck_radiance(10 um, 300 K) = {b:.9e} W m^-2 sr^-1 m^-1")
    sigma_sb = 2 * math.pi ** 5 * 1.380649e-23 ** 4 / (15 * 6.62607015e-34 ** 3 * 299792458.0 ** 2)
    for temp in (250.0, 300.0):
        full = float(band_radiance(temp, (1e-7, 1e-2)))
        tail = 2 * 299792458.0 * 1.380649e-23 * temp / (3 * 1e-2 ** 3)  # Rayleigh-Jeans tail beyond 1 cm
        print(f"  band_radiance({temp} K, 0.1 um..1 cm) + RJ tail beyond 1 cm = {full + tail:.12f}; "
              f"sigma T^4/pi = {sigma_sb * temp ** 4 / math.pi:.12f}; rel {(full + tail) / (sigma_sb * temp ** 4 / math.pi) - 1:+.1e}")
    band = (8e-6, 12e-6)
    for temp in (270.0, 293.15, 310.0):
        L = float(band_radiance(temp, band))
        tb = float(brightness_temperature(L, band))
        print(f"  8-12 um: T = {temp} K -> L = {L:.12f} -> T_b = {tb:.12f} (err {tb - temp:+.1e} K)")
    lam_tab = np.array([7.5e-6, 8e-6, 10e-6, 12e-6, 12.5e-6])
    resp_tab = np.array([0.0, 0.8, 1.0, 0.7, 0.0])
    Lt = float(band_radiance(293.15, (7e-6, 13e-6), (lam_tab, resp_tab)))
    Lc = float(band_radiance(293.15, (7e-6, 13e-6), lambda x: np.interp(x, lam_tab, resp_tab, 0, 0)))
    print(f"  response table vs same response as a callable (no breakpoints): {Lt:.13f} vs {Lc:.13f}  rel {Lc / Lt - 1:+.1e}")
    # edge cases
    flat = SlopeStatistics(0.0, 0.0)
    m = HQ["11um"]
    print(f"  flat sea, emissivity at 0 / 90 deg: {float(emissivity(0.0, 0.0, flat, m)):.10f} / "
          f"{float(emissivity(math.pi / 2, 0.0, flat, m)):.10f}")
    S = SlopeStatistics.cox_munk(10.0)
    print(f"  th = pi/2 exactly, W=10: emissivity shadowed {float(emissivity(math.pi / 2, 0.0, S, m)):.10f}, "
          f"not shadowed {float(emissivity(math.pi / 2, 0.0, S, m, shadowing=False))}; projected_area no shadow "
          f"{float(projected_area(math.pi / 2, 0.0, S, shadowing=False)):.2e}")
    Sl = SlopeStatistics(0.2, 0.0)
    for thd in (60.0, 89.0, 89.99):
        e0 = float(emissivity(thd * DEG, 0.3, Sl, m))
        row = []
        for bb in (1e-4, 1e-6, 1e-9):
            e1 = float(emissivity(thd * DEG, 0.3, SlopeStatistics(0.2, bb, 0.5), m))
            row.append(f"b={bb:.0e}: {e1:.12f} ({e1 / e0 - 1:+.1e})")
        print(f"  a=0.2, r=0.5, crosswind rms b -> 0 vs exactly 0 (line law {e0:.12f}), {thd} deg: " + "; ".join(row))
    out = emissivity(np.array([0.0, 1.0, 1.5]), 0.0, SlopeStatistics.cox_munk(np.array([[5.0], [10.0]])), m)
    print(f"  broadcasting: emissivity(th[3], W[2,1]) shape {out.shape}")
    errs = []
    for label, fn in [("a<0", lambda: SlopeStatistics(-0.1, 0.1)),
                      ("b nan", lambda: SlopeStatistics(0.1, float('nan'))),
                      ("|r|=1", lambda: SlopeStatistics(0.1, 0.1, 1.0)),
                      ("th>pi/2", lambda: emissivity(1.6, 0.0, S, m)),
                      ("th<0", lambda: projected_area(-0.1, 0.0, S)),
                      ("k<0", lambda: emissivity(1.0, 0.0, S, 1.2 - 0.05j)),
                      ("k<0 pair", lambda: fresnel_reflectance(0.5, (1.2, -0.1)))]:
        try:
            fn()
            errs.append(f"{label}: NO ERROR")
        except ValueError as exc:
            errs.append(f"{label}: ValueError({exc})")
    print("  validation: " + "; ".join(errs))


def check_sky_table():
    header("4b. Tabulated sky (PCHIP in zenith angle): phi-outer vs theta-outer, and vs the callable it samples")
    m = HQ["11um"]
    z = np.radians(np.arange(0.0, 80.01, 5.0))  # table stops at 80 deg: held at sky(80 deg) beyond
    tab = (z, sky_fn(np.cos(z)))
    zf = np.radians(np.linspace(0.0, 90.0, 181))
    tab_fine = (zf, sky_fn(np.cos(zf)))
    for name, S in [("iso W=10", SlopeStatistics.cox_munk(10.0)),
                    ("a/b=10 r=0.9", SlopeStatistics(0.2, 0.02, 0.9))]:
        for thd in (60.0, 85.0, 89.99):
            th = thd * DEG
            r1 = float(apparent_radiance(th, 0.7, S, m, 30.0, tab))
            r2 = float(apparent_radiance(th, 0.7, S, m, 30.0, tab, method="theta_outer"))
            r3 = float(apparent_radiance(th, 0.7, S, m, 30.0, tab_fine))
            r4 = float(apparent_radiance(th, 0.7, S, m, 30.0, sky_fn))
            print(f"  {name:13s} th={thd:6.2f}  table(0..80 deg) {r1:.12f} (theta-outer {r2 / r1 - 1:+.1e});"
                  f"  0.5-deg table {r3:.12f} vs callable {r4:.12f} ({r3 / r4 - 1:+.1e})")


def check_timing():
    header("6. Timing per evaluation (default epsrel=1e-10; emissivity = numerator + denominator)")
    m = HQ["11um"]
    cases = [("iso W=10, 60 deg", SlopeStatistics.cox_munk(10.0), 60.0),
             ("iso W=10, 85 deg", SlopeStatistics.cox_munk(10.0), 85.0),
             ("sigma^2=1e-6, 85 deg", SlopeStatistics(7.0710678e-4, 7.0710678e-4), 85.0),
             ("sigma^2=1e-6, 89.99 deg", SlopeStatistics(7.0710678e-4, 7.0710678e-4), 89.99),
             ("a/b=10 r=0.9, 89.99 deg", SlopeStatistics(0.2, 0.02, 0.9), 89.99),
             ("a/b=10 r=0.9, 60 deg", SlopeStatistics(0.2, 0.02, 0.9), 60.0),
             ("iso W=40, 89.99 deg", SlopeStatistics.cox_munk(40.0), 89.99),
             ("iso W=10, 1.5706 rad", SlopeStatistics.cox_munk(10.0), 1.5706 / DEG)]
    for name, S, thd in cases:
        th = thd * DEG
        d, td, wd = timed(projected_area, th, 0.7, S)
        e, te, we = timed(emissivity, th, 0.7, S, m)
        r, tr, wr = timed(apparent_radiance, th, 0.7, S, m, 30.0, sky_fn)
        e2, te2, we2 = timed(emissivity, th, 0.7, S, m, shadowing=False)
        print(f"  {name:26s} D {td:5.2f}s  emis {te:5.2f}s  R_a {tr:5.2f}s  emis(no shadow) {te2:5.2f}s"
              f"   [D={d:.6e} e={e:.8f} R_a={r:.8f}; warnings {wd + we + wr + we2}]")


def check_table():
    header("7. emissivity and apparent radiance (sky = 11 + 19 (1 - cos)^8, R_B = 30, 11 um, ph = 0.7 rad, "
           "shadowing on) at epsrel 1e-8 and 1e-11; 'dig' = -log10(relative difference)")
    m = HQ["11um"]
    laws = [("iso W=2", SlopeStatistics.cox_munk(2.0)),
            ("iso W=10", SlopeStatistics.cox_munk(10.0)),
            ("iso W=40", SlopeStatistics.cox_munk(40.0)),
            ("aniso W=10", SlopeStatistics.cox_munk(10.0, anisotropic=True)),
            ("a/b=10 r=0.9", SlopeStatistics(0.2, 0.02, 0.9)),
            ("sigma^2=1e-6", SlopeStatistics(7.0710678e-4, 7.0710678e-4))]
    angles = [0.0, 40.0, 70.0, 80.0, 85.0, 88.0, 89.99]

    def digits(x, y):
        d = abs(x - y) / abs(y)
        return 16.0 if d == 0 else min(16.0, -math.log10(d))
    for name, S in laws:
        for thd in angles:
            th = thd * DEG
            e1 = float(emissivity(th, 0.7, S, m, epsrel=1e-8))
            e2 = float(emissivity(th, 0.7, S, m, epsrel=1e-11))
            r1 = float(apparent_radiance(th, 0.7, S, m, 30.0, sky_fn, epsrel=1e-8))
            r2 = float(apparent_radiance(th, 0.7, S, m, 30.0, sky_fn, epsrel=1e-11))
            print(f"  {name:13s} th={thd:6.2f}  emis {e1:.13f} | {e2:.13f}  dig {digits(e1, e2):4.1f}"
                  f"   R_a {r1:.12f} | {r2:.12f}  dig {digits(r1, r2):4.1f}")


def main():
    quick = "--quick" in sys.argv
    warnings.simplefilter("ignore", integrate.IntegrationWarning)
    t0 = time.perf_counter()
    check_pdf()
    check_area_noshadow()
    check_area_shadow()
    check_second_law()
    check_sky_table()
    check_facts()
    check_misc()
    check_timing()
    if not quick:
        check_table()
    print(f"\ntotal time {time.perf_counter() - t0:.0f} s")


if __name__ == "__main__":
    main()

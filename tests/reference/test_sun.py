"""The numpy reference for the reflected sun (roughsea_torch.reference.sun.glint_radiance).

Each fact is checked against something outside the disk quadrature: the polygon area of a disk's
image in slope space (the change of variables), Cox & Munk's closed form (docs/physics.md sec. 10), the
flat-sea mirror, energy conservation over all view directions computed in slope space, and Smith's
G1 recomputed from the reference's projected_area quadrature.
"""

import math

import numpy as np
import pytest
from scipy import integrate

import roughsea_torch.reference as ref
from roughsea_torch.reference.sun import _slope_of_direction, _unit

DEG = math.pi / 180.0
M4 = complex(1.351, 0.0046)  # water at 4 um, Hale & Querry (docs/physics.md sec. 6)
R_SUN = 0.004654
E_SUN = 12.0


def _rho(c):
    return float(ref.fresnel_reflectance(c, M4))


def _l_sun():
    return E_SUN / (2.0 * math.pi * (1.0 - math.cos(R_SUN)))


def _glint(*args, **kw):
    return float(ref.glint_radiance(*args, **kw)[()])


# ------------------------------------------------------------------- change of variables

def test_slope_jacobian_matches_polygon_area_of_disk_image():
    """ds = d(omega) / (4 (h.v) cos^3 beta): the integral of the right side over a disk of
    directions equals the slope-space area of the disk's image (shoelace on 4000 boundary points)."""
    v = _unit(55 * DEG, 0.4)
    c = _unit(35 * DEG, 0.4 + math.pi + 0.3)
    rad = 0.05  # a large disk, so the map is far from linear over it
    e1 = np.cross(c, (0.0, 0.0, 1.0))
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(c, e1)

    def omega(r, psi):
        return math.cos(r) * np.asarray(c) + math.sin(r) * (math.cos(psi) * e1 + math.sin(psi) * e2)

    def jac(r, psi):
        _, _, hv, cb = _slope_of_direction(v, tuple(omega(r, psi)))
        return math.sin(r) / (4.0 * hv * cb ** 3)

    area_int = integrate.dblquad(jac, 0.0, 2.0 * math.pi, 0.0, rad, epsrel=1e-11)[0]
    pts = np.array([_slope_of_direction(v, tuple(omega(rad, p)))[:2]
                    for p in np.linspace(0.0, 2.0 * math.pi, 4000, endpoint=False)])
    x, y = pts[:, 0], pts[:, 1]
    area_poly = 0.5 * abs(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)))
    assert area_int == pytest.approx(area_poly, rel=2e-6)


# ------------------------------------------------------------------- 1. Cox & Munk closed form

@pytest.mark.parametrize("sun_offset", [(0.0, 0.0), (4 * DEG, 10 * DEG)])
def test_broad_slopes_equal_cox_munk_closed_form(sun_offset):
    th, ph = 60 * DEG, 0.3
    ths, phs = 60 * DEG + sun_offset[0], ph + math.pi + sun_offset[1]  # (near-)specular
    slopes = ref.SlopeStatistics.cox_munk(10.0)
    a = float(slopes.std_upwind)
    g = _glint(th, ph, slopes, M4, ths, phs, E_SUN, shadowing=False, sun_masking=False)
    v, c = np.array(_unit(th, ph)), np.array(_unit(ths, phs))
    h = (v + c) / np.linalg.norm(v + c)
    s = h[:2] / h[2]
    n_sg = math.exp(-0.5 * float(s @ s) / a ** 2) / (2.0 * math.pi * a * a)
    closed = _rho(float(h @ v)) * E_SUN * n_sg / (4.0 * math.cos(th) * h[2] ** 4)
    assert g == pytest.approx(closed, rel=1e-3)
    assert g != pytest.approx(closed, rel=1e-9)  # the disk's finite size does show


# ------------------------------------------------------------------- 2. flat sea / calm limit

@pytest.mark.parametrize("shadowing", [False, True])
def test_calm_sea_shows_the_sun_mirror_image(shadowing):
    th, ph = 60 * DEG, 0.3
    slopes = ref.SlopeStatistics(1e-4, 0.7e-4, 0.3)
    full = _rho(math.cos(th)) * _l_sun()
    spec = _glint(th, ph, slopes, M4, th, ph + math.pi, E_SUN, shadowing=shadowing,
                  sun_masking=False)
    assert spec == pytest.approx(full, rel=1e-6)
    away = _glint(th, ph, slopes, M4, th + 2 * DEG, ph + math.pi, E_SUN, shadowing=shadowing,
                  sun_masking=False)
    assert 0.0 <= away < 1e-12 * full
    # mirror direction exactly on the disk's rim: half the disk's image is lit (rim curvature
    # makes the correction O(rms angular width / R) ~ 1e-3 at rms 1e-6)
    slopes6 = ref.SlopeStatistics(1e-6, 0.7e-6, 0.3)
    rim = _glint(th, ph, slopes6, M4, th + R_SUN, ph + math.pi, E_SUN, shadowing=shadowing,
                 sun_masking=False)
    assert rim / full == pytest.approx(0.5, abs=1e-3)


def test_flat_sea_closed_form():
    th, ph = 30 * DEG, 1.0
    flat = ref.SlopeStatistics(0.0, 0.0)
    full = _rho(math.cos(th)) * _l_sun()
    inside = _glint(th, ph, flat, M4, th + 0.9 * R_SUN, ph + math.pi, E_SUN)
    outside = _glint(th, ph, flat, M4, th + 1.1 * R_SUN, ph + math.pi, E_SUN)
    assert inside == pytest.approx(full, rel=1e-10)  # 1 - cos R in _l_sun loses ~1e-11
    assert outside == 0.0


@pytest.mark.parametrize("rms", [3e-3, 1e-2])
def test_sun_centred_and_peak_centred_rules_agree(rms):
    """The two polar centres of the disk integral (calm and broad rules) give the same number."""
    slopes = ref.SlopeStatistics(rms, 0.6 * rms, -0.4)
    args = (52 * DEG, 0.7, slopes, M4, 52 * DEG + 0.004, 0.7 + math.pi + 0.002, E_SUN)
    kw = dict(shadowing=True, sun_masking=False, slope_mean=(0.002, -0.001))
    g_sun = _glint(*args, centre="sun", **kw)
    g_peak = _glint(*args, centre="peak", **kw)
    assert g_sun > 0.0
    assert g_sun == pytest.approx(g_peak, rel=1e-8)


# ------------------------------------------------------------------- 3. energy

def test_energy_over_all_view_directions():
    """int R_glint cos(th) d(omega_view) over the upper hemisphere (shadowing and masking off).

    Without shadowing R = (1/cos th) int N(s) (n.v)/n_z rho(n.v) L_sun 1[r in disk] ds; for a fixed
    facet the mirror v -> r preserves solid angle and n.v = n.r, so swapping the integrals gives
    E_sun int N(s) (n.c)/n_z rho(n.c) ds over the facets that reflect the sun into the upper
    hemisphere (up to the disk's finite size, O(R^2)): in slope space the circle
    (s_par - tan th_s)^2 + s_perp^2 < sec^2 th_s (docs/physics.md sec. 3, with the sun for the view),
    inside which n.c > 0. (n.c)/n_z = cos th_s + sin th_s s_par (the Eq. 4 facet weight toward
    the sun), so this is E_sun cos th_s times the weighted reflectance of the lit facets.
    """
    slopes = ref.SlopeStatistics.cox_munk(5.0)
    a = float(slopes.std_upwind)
    ths = 40 * DEG
    ct, st, tt = math.cos(ths), math.sin(ths), math.tan(ths)

    def f(rr, ang):  # polar coordinates about the circle's centre (tan th_s, 0)
        sx, sy = tt + rr * math.cos(ang), rr * math.sin(ang)
        dens = math.exp(-0.5 * (sx * sx + sy * sy) / a ** 2) / (2.0 * math.pi * a * a)
        w = ct + st * sx
        return dens * w * _rho(w / math.sqrt(1.0 + sx * sx + sy * sy)) * rr

    rhs = E_SUN * integrate.dblquad(f, 0.0, 2.0 * math.pi, 0.0, 1.0 / ct, epsrel=1e-7)[0]
    x, w = np.polynomial.legendre.leggauss(12)
    th, wth = (x + 1.0) * math.pi / 4.0, w * math.pi / 4.0
    ph, wph = (x + 1.0) * math.pi / 2.0, w * math.pi / 2.0  # symmetric about the sun's plane
    TH, PH = np.meshgrid(th, ph, indexing="ij")
    g = ref.glint_radiance(TH, PH, slopes, M4, ths, 0.0, E_SUN, shadowing=False, sun_masking=False)
    lhs = 2.0 * np.sum(g * np.cos(TH) * np.sin(TH) * wth[:, None] * wph[None, :])
    assert lhs == pytest.approx(rhs, rel=1e-3)
    assert rhs / (E_SUN * ct) == pytest.approx(0.03, abs=0.01)  # ~ rho at 4 um, a sanity scale


# ------------------------------------------------------------------- 4. sun-side masking

@pytest.mark.parametrize("mean", [(0.0, 0.0), (0.05, -0.03)])
def test_sun_masking_is_smith_g1(mean):
    """G1 = (projected area of the mean plane toward the sun) / (projected area of the sun-facing
    facets), the latter from the reference's projected_area (shadowing quadrature): independent of
    the closed-form Lambda in the module."""
    slopes = ref.SlopeStatistics.cox_munk(10.0, anisotropic=True)
    th, ph = 82 * DEG, 0.5
    ths, phs = 82 * DEG, 0.5 + math.pi + 0.01  # a low sun, near-specular
    kw = dict(shadowing=True, slope_mean=mean)
    g_on = _glint(th, ph, slopes, M4, ths, phs, E_SUN, sun_masking=True, **kw)
    g_off = _glint(th, ph, slopes, M4, ths, phs, E_SUN, sun_masking=False, **kw)
    plane = math.cos(ths) + math.sin(ths) * (mean[0] * math.cos(phs) + mean[1] * math.sin(phs))
    g1 = plane / float(ref.projected_area(ths, phs, slopes, True, slope_mean=mean)[()])
    assert 0.5 < g1 < 0.95
    assert g_on / g_off == pytest.approx(g1, rel=1e-9)
    high = float(ref.sun_masking_g1(20 * DEG, phs, slopes, slope_mean=mean)[()])
    assert high == pytest.approx(1.0, abs=1e-12)


# ------------------------------------------------------------------- 5. sanity

def test_no_glint_with_sun_below_horizon_and_never_negative():
    slopes = ref.SlopeStatistics.cox_munk(8.0, anisotropic=True)
    for masking in (False, True):
        below = _glint(70 * DEG, 0.2, slopes, M4, 90 * DEG + 2 * R_SUN, 0.2 + math.pi, E_SUN,
                       sun_masking=masking)
        assert below == 0.0
    rng = np.random.default_rng(3)
    th = rng.uniform(0.0, 89.0, 8) * DEG
    ph = rng.uniform(0.0, 2.0 * math.pi, 8)
    ths = rng.uniform(0.0, 89.0, 8) * DEG
    phs = rng.uniform(0.0, 2.0 * math.pi, 8)
    g = ref.glint_radiance(th, ph, slopes, M4, ths, phs, E_SUN)
    assert np.all(np.isfinite(g)) and np.all(g >= 0.0)

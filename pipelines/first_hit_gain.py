"""Why the first-hit sweep's clutter is weaker than the ray tracer's at light wind: the texture's response
to the resolved slope, in closed form from the wave field's band covariances and the model.

The sweep's sample resolves the waves longer than its footprint F_s (band window w_o(F_s)) and averages
the model over the rest (unresolved Gaussian, covariance Σ_total − Σ_res(F_s), about the resolved slope
a). The ray tracer resolves every band with k ≤ 64 rad/m; inside a pixel the traced slopes shorter than
F_s vary from ray to ray and the pixel averages the model over them (unresolved covariance
Σ_total − Σ_traced about each ray's slope). For a resolved along-view slope a, per bin of view zenith:

    E_R(a) = E_model[R | mean a, Σ_total − Σ_res]                      (the sweep's sample)
    E_T(a) = E over s ~ N(0, Σ_traced − Σ_res) of E_model[R | mean a + s, Σ_total − Σ_traced]   (ray tracer)

The two agree if the model were a Gaussian convolution of one facet response (then splitting the
slopes at any scale gives the same function of a); it is not: Eq. 5's shadowing and the facet weight
depend on the unresolved covariance. The script prints their slopes dE/da at a = 0 (K per unit slope),
the σ they give a resolved slope of the bin's rms (σ_a of the bands the sweep resolves) over
a ~ N(0, σ_a²), their regression slopes on a over that distribution (E[dE/da], Stein's lemma), and
E_T's regression slope with each sub-footprint facet weighted by its projected area
(cos θ̂ + sin θ̂ t)₊ instead of uniformly (how uniform points of the image plane sample facets; the
hiding by crests in front left out). The ray tracer's first hits lie between the two weightings.

Usage:
    python pipelines/first_hit_gain.py [--wind 5 10 15] [--direction upwind crosswind]
    python pipelines/first_hit_gain.py --wind 5 --bands 0 16   # band by band, bins of rows 0–7 and 16–23
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

import numpy as np
import torch

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
import roughsea_torch as rs  # noqa: E402
from roughsea_torch.atmosphere import load_sky  # noqa: E402
from roughsea_torch.expectation import apparent_radiance  # noqa: E402
from roughsea_torch.optics import band_refractive_index  # noqa: E402
from roughsea_torch.quadrature import Quadrature  # noqa: E402
from roughsea_torch.radiometry import LWIR, band_radiance, brightness_temperature  # noqa: E402
from roughsea_torch.renderer.hits import sample_step  # noqa: E402
from roughsea_torch.slopes import SlopeStatistics  # noqa: E402

H, W, HFOV = 48, 64, 12.0
DIRECTIONS = {"upwind": (15.0, 0.0), "crosswind": (20.0, math.pi / 2)}
QUAD = Quadrature(outer=20, inner=20, hermite=12, width=7.5)  # the ray tracer's rule
K_TRACED = 64.0


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--wind", type=float, nargs="+", default=[5.0, 10.0, 15.0])
    ap.add_argument("--direction", choices=list(DIRECTIONS), nargs="+", default=["upwind"])
    ap.add_argument("--across", type=float, default=1.0)
    ap.add_argument("--min-step", type=float, default=1 / 32)
    ap.add_argument("--bands", type=int, nargs="*", default=None, metavar="ROW",
                    help="instead: the band-by-band table for the bins starting at these rows (first wind, direction)")
    args = ap.parse_args()
    torch.set_num_threads(1)
    if args.bands is not None:
        for r in args.bands:
            bands(args.wind[0], args.direction[0], r)
        return
    f64 = torch.float64
    sky = load_sky("midlatitude_summer", LWIR, dtype=f64)
    m = band_refractive_index(LWIR, 290.0).to(torch.complex128)
    rb = band_radiance(torch.tensor(290.0, dtype=f64), LWIR)
    gh_x, gh_w = np.polynomial.hermite_e.hermegauss(16)  # E over N(0, 1)
    gh_w = gh_w / gh_w.sum()
    print("| case | view zenith [°] | F_s [m] | σ_a res | σ_a sub-pixel traced | dE/da sweep [K] | dE/da ray [K] | "
          "σ sweep [K] | σ ray [K] | ratio | E[dE/da] sweep [K] | E[dE/da] ray [K] | ratio | "
          "E[dE/da] ray, facets by projected area [K] | ratio |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    for direction in args.direction:
        mast, wdir = DIRECTIONS[direction]
        for wind in args.wind:
            cams = rs.make_camera(H, W, hfov_deg=HFOV, altitude_m=mast, pitch_deg=-6.0)
            geo = rs.view_geometry(cams, earth_radius_m=float("inf"))
            field = rs.SeaScene(wind_speed=wind, wind_direction=wdir, seed=11, sea_temperature=290.0, time_s=3.0).wave_field(1, f64, torch.device("cpu"))
            total = SlopeStatistics.cox_munk(wind, anisotropic=True)
            edges = field.bands.k_edges
            cov_b = field.band_covariance()[0]  # (n_bands, 3) world frame
            traced = cov_b[[o for o in range(len(edges) - 1) if edges[o + 1] <= K_TRACED]].sum(0)
            delta = 2.0 * math.tan(math.radians(HFOV / 2)) / W
            for r0 in (40, 32, 24, 16, 8, 0):
                rows = slice(r0, r0 + 8)
                vz = float(geo.view_zenith[0, rows, W // 2].double().mean())
                va = float(geo.view_azimuth[0, rows, W // 2].double().mean())  # line of sight sea → sensor, world
                R = float(geo.range_m[0, rows, W // 2].double().mean())
                c = math.cos(vz)
                Fs = 2.0 * sample_step(c, 0.25, args.min_step, args.across) * R * delta / c
                res = torch.stack(field.resolved_covariance(torch.tensor([Fs], dtype=f64)), -1)[0]
                e = torch.tensor([math.cos(va), math.sin(va)], dtype=f64)
                ep = torch.tensor([-math.sin(va), math.cos(va)], dtype=f64)

                def quad_form(v, a, b):
                    return float(v[0] * a[0] * b[0] + v[2] * (a[0] * b[1] + a[1] * b[0]) + v[1] * a[1] * b[1])
                # world → slope frame (upwind, crosswind): rotate by −wdir
                cw, sw = math.cos(wdir), math.sin(wdir)

                def to_slope(v):
                    vx, vy, cxy = (float(x) for x in v)
                    up = vx * cw * cw + 2 * cxy * cw * sw + vy * sw * sw
                    cr = vx * sw * sw - 2 * cxy * cw * sw + vy * cw * cw
                    cv = (vy - vx) * cw * sw + cxy * (cw * cw - sw * sw)
                    return up, cr, cv
                tot = (float(total.var_upwind), float(total.var_crosswind), float(total.cov))
                t_up, t_cr, t_cv = to_slope(traced)
                phi = va - wdir  # LOS azimuth from upwind
                var_a = quad_form(res, e, e)
                sub = traced - res
                var_sub_a, var_sub_p = quad_form(sub, e, e), quad_form(sub, ep, ep)
                # the sweep: unresolved about (a, κ a) with Σ_total − Σ_res (along-view resolved part only
                # conditioned, as the renderer's two_scale_statistics; the across part stays unresolved)
                kap = quad_form(res, ep, e) / var_a
                a_grid = torch.tensor([-1e-3, 1e-3] + list(math.sqrt(var_a) * gh_x), dtype=f64)  # slope, then rms

                def radiance(mean_a, mean_p, var):
                    up = mean_a * math.cos(phi) - mean_p * math.sin(phi)
                    cr = mean_a * math.sin(phi) + mean_p * math.cos(phi)
                    stats = SlopeStatistics.from_variances(*(torch.full_like(up, v) for v in var)).shifted(up, cr)
                    return apparent_radiance(torch.full_like(up, vz), torch.full_like(up, phi), stats, m, rb, sky,
                                             quadrature=QUAD)
                # unresolved covariance of the sweep: Σ_total − (the along-view resolved part and its regression)
                u_sweep = tuple(tv - rv for tv, rv in zip(tot, _along_part(res, e, ep, phi, wdir)))
                Ls = radiance(a_grid, kap * a_grid, u_sweep)
                u_ray = (tot[0] - t_up, tot[1] - t_cr, tot[2] - t_cv)
                # ray: E over the sub-pixel traced slopes (along and across, independent Gauss–Hermite)
                A = a_grid[:, None, None] + math.sqrt(max(var_sub_a, 0)) * torch.tensor(gh_x, dtype=f64)[None, :, None]
                P = kap * a_grid[:, None, None] + math.sqrt(max(var_sub_p, 0)) * torch.tensor(gh_x, dtype=f64)[None, None, :]
                A, P = torch.broadcast_tensors(A, P)
                wts = torch.tensor(np.outer(gh_w, gh_w), dtype=f64)
                Lr_all = radiance(A.reshape(-1), P.reshape(-1), u_ray).reshape(A.shape)
                Lr = (Lr_all * wts).sum((1, 2))
                # the same, each traced facet weighted by its projected area seen from the camera,
                # (cos θ̂ + sin θ̂ t)₊ with t its along-view slope (facets turned away are not hit): how
                # uniform points of the image plane sample the facets (hiding by other crests left out)
                vis = (math.cos(vz) + math.sin(vz) * A).clamp_min(0.0) * wts
                vsum = vis.sum((1, 2))
                Lv = torch.where(vsum > 0, (Lr_all * vis).sum((1, 2)) / vsum.clamp_min(1e-300), Lr)  # (none seen: any)
                Ts, Tr = brightness_temperature(Ls, LWIR), brightness_temperature(Lr, LWIR)
                Tv = brightness_temperature(Lv, LWIR)
                g_s = float(Ts[1] - Ts[0]) / 2e-3
                g_r = float(Tr[1] - Tr[0]) / 2e-3
                w = torch.tensor(gh_w, dtype=f64)
                sd = lambda T: float(((T[2:] - (T[2:] * w).sum()) ** 2 * w).sum().sqrt())  # noqa: E731
                # the regression slope of the response on a over a ~ N(0, σ_a²) (Stein: E[dE/da]): how a
                # pixel's average responds to the long waves that survive its box, its sub-pixel slopes
                # spread over the whole resolved distribution
                reg = lambda T: float((T[2:] * a_grid[2:] * w).sum()) / var_a  # noqa: E731
                print(f"| {direction} {wind:g} m/s | {math.degrees(vz):.1f} | {Fs:.2f} | {math.sqrt(var_a):.3f} | "
                      f"{math.sqrt(max(var_sub_a, 0)):.3f} | {g_s:.2f} | {g_r:.2f} | {sd(Ts):.3f} | {sd(Tr):.3f} | "
                      f"{sd(Ts) / sd(Tr):.2f} | {reg(Ts):.2f} | {reg(Tr):.2f} | {reg(Ts) / reg(Tr):.2f} | "
                      f"{reg(Tv):.2f} | {reg(Ts) / reg(Tv):.2f} |")


def _along_part(res, e, ep, phi, wdir):
    """The part of the resolved covariance the sweep conditions on (the along-view component and the
    across component's regression on it), in the slope frame: σ_a² (ê + κ ê⊥)(ê + κ ê⊥)ᵀ."""
    vx, vy, cxy = (float(x) for x in res)
    var_a = vx * e[0] ** 2 + 2 * cxy * e[0] * e[1] + vy * e[1] ** 2
    cov_ap = vx * e[0] * ep[0] + cxy * (e[0] * ep[1] + e[1] * ep[0]) + vy * e[1] * ep[1]
    kap = cov_ap / var_a
    d = e + kap * ep  # world
    cw, sw = math.cos(wdir), math.sin(wdir)
    du, dc = float(d[0] * cw + d[1] * sw), float(-d[0] * sw + d[1] * cw)
    return float(var_a) * du * du, float(var_a) * dc * dc, float(var_a) * du * dc


def bands(wind: float, direction: str, rows: int) -> None:
    """Band by band, for the bin of 8 rows from ``rows``, over every mode of the field's lattice (its
    expected variance F Δk² with the bilinear factor, as :meth:`WaveField.band_covariance` sums it): the
    along-view slope variance C_o of the band, and what a pixel keeps of it in linear theory. The ray
    tracer: modes with k ≤ 64 rad/m, box-averaged over the pixel's ground footprint,
    sinc²(k∥ L/2) sinc²(k⊥ R δ/2) with L = R δ / cos θ̂. The sweep: the band window w_o(F_s)² at its
    sample footprint times the same box along the view (its pixel averages its samples over the
    depression window) and none across (a pixel reads one ground track), for min_step 1/32, 1/64,
    1/128 (across = 1)."""
    from roughsea_torch.spectrum import eckv_terms
    from roughsea_torch.wave_lattice import BandLattice

    mast, wdir = DIRECTIONS[direction]
    f64 = torch.float64
    cams = rs.make_camera(H, W, hfov_deg=HFOV, altitude_m=mast, pitch_deg=-6.0)
    geo = rs.view_geometry(cams, earth_radius_m=float("inf"))
    field = rs.SeaScene(wind_speed=wind, wind_direction=wdir, seed=11, sea_temperature=290.0,
                        time_s=3.0).wave_field(1, f64, torch.device("cpu"))
    sl = slice(rows, rows + 8)
    vz = float(geo.view_zenith[0, sl, W // 2].double().mean())
    va = float(geo.view_azimuth[0, sl, W // 2].double().mean())
    R = float(geo.range_m[0, sl, W // 2].double().mean())
    delta = 2.0 * math.tan(math.radians(HFOV / 2)) / W
    c = math.cos(vz)
    L, Lc = R * delta / c, R * delta
    lat = BandLattice(field.bands, f64, torch.device("cpu"))
    sk, dl = eckv_terms(lat.k, torch.tensor(wind, dtype=f64), torch.tensor(0.84, dtype=f64))
    cu, su = math.cos(wdir), math.sin(wdir)
    along_w, across_w = lat.kx * cu + lat.ky * su, -lat.kx * su + lat.ky * cu
    spec = sk / lat.k * (1.0 + dl * (along_w**2 - across_w**2) / lat.k**2) / (2.0 * math.pi)
    weight = torch.where(lat.mask, spec * lat.dk2, torch.zeros_like(spec)) * lat.multiplicity * lat.interp
    k_al = lat.kx * math.cos(va) + lat.ky * math.sin(va)  # along the line of sight
    k_ac = -lat.kx * math.sin(va) + lat.ky * math.cos(va)
    c_mode = weight * k_al**2  # the along-view slope variance of each mode

    def sinc2(x):
        return torch.where(x.abs() > 1e-12, (torch.sin(x) / x) ** 2, torch.ones_like(x))
    box_al, box_ac = sinc2(k_al * L / 2), sinc2(k_ac * Lc / 2)
    steps = (1 / 32, 1 / 64, 1 / 128)
    fs = [2.0 * sample_step(c, 0.25, m, 1.0) * L for m in steps]
    w2 = [field.band_weights(torch.tensor([f], dtype=f64))[0] ** 2 for f in fs]
    edges = field.bands.k_edges
    print(f"\n{direction} {wind:g} m/s, rows {rows}–{rows + 7}: view zenith {math.degrees(vz):.1f}°, range {R:.0f} m, "
          f"R δ = {Lc:.2f} m, L = R δ / cos θ̂ = {L:.1f} m; F_s = " + ", ".join(f"{f:.2f}" for f in fs)
          + " m at min_step 1/32, 1/64, 1/128\n")
    print("| band k [rad/m] | C_o along view | ray tracer keeps | sweep keeps (1/32) | (1/64) | (1/128) | "
          "sweep, box across too (1/32) |")
    print("|---|---:|---:|---:|---:|---:|---:|")
    tot = [0.0] * 5
    for o in range(len(edges) - 1):
        co = c_mode[o].sum()
        keep_r = float((c_mode[o] * box_al[o] * box_ac[o]).sum()) * (1.0 if edges[o + 1] <= K_TRACED else 0.0)
        keep_s = [float((c_mode[o] * box_al[o]).sum() * w[o]) for w in w2]
        keep_x = float((c_mode[o] * box_al[o] * box_ac[o]).sum() * w2[0][o])
        vals = [keep_r] + keep_s + [keep_x]
        for i, v in enumerate(vals):
            tot[i] += v
        if float(co) < 1e-4 * float(c_mode.sum()):
            continue
        print(f"| {edges[o]:g}–{edges[o + 1]:g} | {float(co):.2e} | " + " | ".join(f"{v:.2e}" for v in vals) + " |")
    print(f"| sum | {float(c_mode.sum()):.2e} | " + " | ".join(f"{v:.2e}" for v in tot) + " |")
    print("\n√(sweep / ray tracer) = " + ", ".join(f"{math.sqrt(v / tot[0]):.2f}" for v in tot[1:]))


if __name__ == "__main__":
    main()

"""Sun glitter of a near-range MWIR patch: the glitter spots of the realization against the renderer.

For each seed: a 24 × 24 pixel patch (0.82 mrad pixels, a 640-pixel camera with a 30° field of
view; 10 m above the sea, looking 10° down, the sun 15° above the horizon straight ahead, 8 m/s,
MWIR, E_sun = 12 W m⁻²; wind, pitch and sun elevation are options) seen

- by the brute force (:func:`roughsea_torch.raytrace_glitter.glitter_spots`: every band a mirror
  facet, the spots found by Newton's method from ray hits, each weighted by its image area), as the
  grid-integrated spot areas ('truth, box') and the linearized ones ('truth, linear');
- by the textured render (``rs.render``: the glint of the scene with the sun minus the scene without),
  with the flat-point and the first-hit texture (``TableSize.texture_hit``), each also with the renderer's
  glitter (``TableSize(glitter=True)``, one draw at t = 0);
- by the first-hit render times the glitter factor (:mod:`roughsea_torch.glitter`), N per pixel from
  the footprint, the slope density at the specular slope (the expectation's, scaled by the pixel's
  glint over the expectation's glint) and E|det H|; 32 glitter draws, their statistics averaged;
- by the expectation with the total law (Cox–Munk) and with the field's own slope variance.

Prints a markdown table: patch mean, spread/mean (std across pixels over the mean), p99/mean.

Usage:
    PYTHONPATH=. python pipelines/glitter_vs_raytrace.py [--seeds 1 2] [--rays 256] [--wind 8] [--pitch -10]
                                                         [--sun-elevation 15]
"""

from __future__ import annotations

import argparse
import math

import torch

import roughsea_torch as rs
from roughsea_torch import glitter as G
from roughsea_torch.optics import band_refractive_index
from roughsea_torch.raytrace_glitter import glitter_spots

WIND, SUN_ZENITH, E_SUN, ALT, PITCH, IFOV, N_PIX = 8.0, math.radians(75.0), 12.0, 10.0, -10.0, math.radians(30.0) / 640, 24


def stats(img: torch.Tensor) -> tuple[float, float, float]:
    v = img.flatten().double()
    m = float(v.mean())
    return m, float(v.std()) / m, float(torch.quantile(v, 0.99)) / m


def neighbours(img: torch.Tensor) -> tuple[float, float]:
    """The correlation across the patch between horizontally and between vertically adjacent pixels."""
    v = img.double()

    def corr(a: torch.Tensor, b: torch.Tensor) -> float:
        return round(float(torch.corrcoef(torch.stack([a.flatten(), b.flatten()]))[0, 1]), 2)
    return corr(v[:, 1:], v[:, :-1]), corr(v[1:], v[:-1])


def scene(seed: int | None, sun: bool) -> rs.SeaScene:
    s = rs.Sun(SUN_ZENITH, 0.0, E_SUN if sun else 0.0)
    return rs.SeaScene(wind_speed=WIND, band=rs.MWIR, sea_temperature=290.0, seed=seed, sun=s, foam=False, path=False)


def run(seed: int, rays: int) -> dict[str, tuple[float, float, float]]:
    cam = rs.make_camera(N_PIX, N_PIX, hfov_deg=math.degrees(2 * math.atan(N_PIX / 2 * math.tan(IFOV))), altitude_m=ALT,
                         pitch_deg=PITCH, dtype=torch.float64)
    field = scene(seed, True).wave_field(1, torch.float64, torch.device("cpu"))
    m_idx = band_refractive_index(rs.MWIR, 290.0)
    cm = G.curvature_moments(torch.tensor(WIND, dtype=torch.float64))
    tr = glitter_spots(cam, field, SUN_ZENITH, 0.0, E_SUN, m_idx, rays_per_pixel=rays, third_derivative=float(cm.third))
    out = {"truth, box": stats(tr["glint"]), "truth, linear": stats(tr["linearized_glint"])}
    exp = (rs.render(cam, scene(None, True)) - rs.render(cam, scene(None, False)))[0, 0].double()
    renders = {}
    for hit in ("flat", "first"):
        tab, tab_g = rs.TableSize(texture_hit=hit), rs.TableSize(texture_hit=hit, glitter=True)
        base = rs.render(cam, scene(seed, False), table=tab)
        renders[hit] = (rs.render(cam, scene(seed, True), table=tab) - base)[0, 0].double()
        out[f"render, {hit} hit"] = stats(renders[hit])
        out[f"render, {hit} hit, glitter (the renderer's, t = 0)"] = stats(
            (rs.render(cam, scene(seed, True), table=tab_g) - base)[0, 0].double())
    rnd = renders["first"]
    out["expectation (Cox–Munk)"] = stats(exp)
    # N per pixel: footprint × p(s_g) × E|det H|, p(s_g) the expectation's (total law) scaled by the pixel's glint
    H = W = N_PIX
    u, v = torch.meshgrid(torch.arange(W, dtype=torch.float64), torch.arange(H, dtype=torch.float64), indexing="xy")
    pts = cam.unproject(torch.stack([u, v], -1).reshape(1, -1, 2), torch.ones(1, H * W, 1, dtype=torch.float64))
    c = -(cam.rotation_matrix.transpose(-1, -2) @ cam.translation_vector)[0, :, 0]
    d = torch.nn.functional.normalize(pts[0] - c, dim=-1)
    ct = -d[:, 2]
    rng = ALT / ct
    area = (rng * IFOV) ** 2 / ct
    st, az = torch.sqrt(1 - ct * ct), torch.atan2(-d[:, 1], -d[:, 0])
    sl = rs.SlopeStatistics.cox_munk(WIND)
    z = torch.zeros((), dtype=torch.float64)
    p_sg, det_j = G.specular_slope_density(ct, st, torch.cos(az), torch.sin(az), z + sl.var_upwind, z + sl.var_crosswind,
                                           z + sl.cov, z, z, z + SUN_ZENITH, z)
    edet = G.mean_abs_hessian_determinant(cm.uu, cm.cc, cm.uc)
    n_exp = G.glitter_count(p_sg, area, edet).reshape(H, W)
    n_pix = n_exp * (rnd / exp).clamp_min(0.0)
    spread = G.glitter_spread(cm, float(math.radians(0.2666) * det_j.sqrt().mean()))
    draws, lag, lag_ind = [], [], []
    gx, gy = (c[i] + rng * d[:, i] for i in (0, 1))  # the pixels' flat-sea points, and their footprint across
    for g_seed in range(32):
        zl = G.glitter_latent(g_seed, gx, gy, rng * IFOV, 0.0).reshape(H, W)
        img = rnd * G.glitter_factor(n_pix, zl, spread)
        draws.append(stats(img))
        lag.append(neighbours(img))
        z_ind = G.glitter_latent(g_seed, 10.0 * torch.arange(H * W, dtype=torch.float64), 0.0, 1.0, 0.0).reshape(H, W)
        lag_ind.append(neighbours(rnd * G.glitter_factor(n_pix, z_ind, spread)))
    out["render, first hit, glitter (32 draws)"] = tuple(sum(x[i] for x in draws) / len(draws) for i in range(3))
    print(f"seed {seed}: correlation of neighbouring pixels (columns, rows), truth {neighbours(tr['glint'])}, "
          f"first-hit render {neighbours(rnd)}, its glitter (32 draws) "
          f"{tuple(round(sum(v[i] for v in lag) / len(lag), 2) for i in range(2))}, with independent pixels' latents "
          f"{tuple(round(sum(v[i] for v in lag_ind) / len(lag_ind), 2) for i in range(2))}")
    # the expectation with the field's own total slope variance (what the brute force's surface has)
    fc = field.resolved_covariance(torch.zeros(1, dtype=torch.float64))
    sf = rs.SlopeStatistics.from_variances(float(fc[0]), float(fc[1]), float(fc[2]))
    ph = az - 0.0  # wind direction 0: the world frame is the upwind frame
    g_field = rs.glint_radiance(torch.acos(ct), ph, sf, m_idx, rs.Sun(SUN_ZENITH, 0.0, E_SUN))
    g_cm = rs.glint_radiance(torch.acos(ct), ph, sl, m_idx, rs.Sun(SUN_ZENITH, 0.0, E_SUN))
    out["expectation (field's slopes)"] = stats(g_field.reshape(H, W) * (exp / g_cm.reshape(H, W)).mean())
    cnt = tr["spots_per_pixel"]
    loc = torch.nn.functional.avg_pool2d(cnt[None, None], 3, 1, 1, count_include_pad=False)[0, 0]
    ok = loc > 0.5
    fano = float((((cnt - loc) ** 2 / loc)[ok]).mean()) * 9 / 8  # 9/8: the pixel is part of its own 3 × 3 mean
    print(f"seed {seed}: spot counts' variance over their mean: {float(cnt.var() / cnt.mean()):.2f} about the patch "
          f"mean, {fano:.2f} about the 3 × 3 local mean (Poisson: 1)")
    print(f"seed {seed}: {tr['spots']} spots ({tr['spots'] / (H * W):.1f} per pixel), N model {float(n_exp.mean()):.1f} per "
          f"pixel, F(1 + κ) = {float(spread):.2f}, starts per spot {tr['starts_per_spot']:.1f}, spots touching their box "
          f"{tr['edge_share']:.0%} of the glint, hidden {tr['hidden']}", flush=True)
    return out


def main() -> None:
    global WIND, PITCH, SUN_ZENITH
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--seeds", type=int, nargs="+", default=[1, 2])
    ap.add_argument("--rays", type=int, default=256)
    ap.add_argument("--wind", type=float, default=WIND)
    ap.add_argument("--pitch", type=float, default=PITCH, help="camera pitch [deg] (negative: down)")
    ap.add_argument("--sun-elevation", type=float, default=90.0 - math.degrees(SUN_ZENITH))
    args = ap.parse_args()
    WIND, PITCH, SUN_ZENITH = args.wind, args.pitch, math.radians(90.0 - args.sun_elevation)
    print(f"wind {WIND:g} m/s, pitch {PITCH:g}°, sun {90 - math.degrees(SUN_ZENITH):g}° up\n")
    torch.set_num_threads(1)
    print("| seed | image | patch mean [W m⁻² sr⁻¹] | spread/mean | p99/mean |\n|---|---|---|---|---|")
    rows, per = [], {}
    for seed in args.seeds:
        for name, (m, s, p) in run(seed, args.rays).items():
            rows.append(f"| {seed} | {name} | {m:.2f} | {s:.2f} | {p:.2f} |")
            per.setdefault(name, []).append((m, s, p))
    print("\n".join(rows))
    print(f"\nmedian over seeds {args.seeds}:\n\n| image | patch mean | spread/mean | p99/mean |\n|---|---|---|---|")
    for name, v in per.items():
        med = torch.tensor(v).median(0).values.tolist()
        print(f"| {name} | {med[0]:.2f} | {med[1]:.2f} | {med[2]:.2f} |")


if __name__ == "__main__":
    main()

"""The ray tracer's own response to the slope the sweep resolves, against the sweep's (issue 22).

For an 8-row bin of the comparison pipeline's cameras (48×64 px over 12°, pitch −6°, LWIR, LOWTRAN
midlatitude summer, sea at 290 K, seed 11, t = 3 s), it traces sub-pixel rays to their first hits on
the field's bands with k ≤ 64 rad/m (``raytrace.trace_first_hits``), gives each ray the ray tracer's
radiance (the model on the unresolved statistics Σ_CM − Σ_traced about the traced slope at the hit, as
``raytrace.raytraced_image`` does with ``mode="two_scale"``), and reads at each hit the along-view
slope a of the field filtered at the sweep's sample footprint F_s = 2 s(θ̂) R δ / cos θ̂
(``hits.sample_step``, default settings): the slope the sweep resolves there. Then, over the bin's
rays (the hits' own distribution of a, which the first hit weights):

- β_ray: the regression slope of the ray's brightness temperature on a [K per unit slope];
- β_sweep: the same for the sweep's sample at a, the model on Σ_CM − σ_a² w wᵀ about (a, κ a) at F_s
  (the renderer's ``unresolved_statistics`` with the visible slope a, as its texture volume takes it);
- their ratio: what the sweep's node values give of the ray tracer's response to the waves it
  resolves, the gain its image has on those waves whatever its sampling;
- r: the correlation of the ray's temperature with a (how much of the ray's variance the resolved
  slope carries).

Usage:
    python pipelines/first_hit_response.py [--rays 16] [--cases upwind:5:8,16,24,32 crosswind:10:0,8]
        [--across 0.5 --min-step 0.0078125]   # the sample footprint of other sweep settings
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

import torch

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
import roughsea_torch as rs  # noqa: E402
from roughsea_torch import raytrace as rt  # noqa: E402
from roughsea_torch.atmosphere import load_sky  # noqa: E402
from roughsea_torch.clutter import unresolved_statistics  # noqa: E402
from roughsea_torch.expectation import apparent_radiance  # noqa: E402
from roughsea_torch.optics import band_refractive_index  # noqa: E402
from roughsea_torch.quadrature import Quadrature  # noqa: E402
from roughsea_torch.radiometry import LWIR, band_radiance, brightness_temperature  # noqa: E402
from roughsea_torch.renderer.hits import sample_step  # noqa: E402
from roughsea_torch.slopes import SlopeStatistics  # noqa: E402

H, W, HFOV, PITCH, T_SEA, SEED, TIME_S = 48, 64, 12.0, -6.0, 290.0, 11, 3.0
DIRECTIONS = {"upwind": (15.0, 0.0), "crosswind": (20.0, math.pi / 2)}
QUAD = Quadrature(outer=20, inner=20, hermite=12, width=7.5)  # the ray tracer's rule
K_TRACED = 64.0
DEFAULT_CASES = ("upwind:5:8,16,24,32", "upwind:10:0,16,32", "upwind:15:16", "crosswind:5:16",
                 "crosswind:10:0,8", "crosswind:15:24,32")


def to_slope_frame(vx, vy, cxy, wdir: float):
    c, s = math.cos(wdir), math.sin(wdir)
    return (vx * c * c + 2 * cxy * c * s + vy * s * s, vx * s * s - 2 * cxy * c * s + vy * c * c,
            (vy - vx) * c * s + cxy * (c * c - s * s))


def response(direction: str, wind: float, row0: int, rays: int, across: float = 1.0, min_step: float = 1 / 32) -> dict:
    f64 = torch.float64
    mast, wdir = DIRECTIONS[direction]
    cams = rs.make_camera(H, W, hfov_deg=HFOV, altitude_m=mast, pitch_deg=PITCH)
    scene = rs.SeaScene(wind_speed=wind, wind_direction=wdir, sea_temperature=T_SEA, seed=SEED, time_s=TIME_S,
                        foam=False, path=False)
    field = scene.wave_field(1, f64, torch.device("cpu"))
    tr = rt.trace_first_hits(cams, field, TIME_S, rays, K_TRACED, rows=slice(row0, row0 + 8))
    hit = tr["hit"][0]
    cz, vaw = tr["cos_view_zenith"][0][hit], tr["view_azimuth_world"][0][hit]
    x, y, sx, sy = (tr[k][0][hit] for k in ("x", "y", "slope_x", "slope_y"))
    vz = torch.acos(cz.clamp(0.0, 1.0))
    los = vaw - wdir  # line of sight (sea → sensor) from upwind
    sky = load_sky("midlatitude_summer", LWIR, dtype=f64)
    m = band_refractive_index(LWIR, T_SEA).to(torch.complex128)
    rb = band_radiance(torch.tensor(T_SEA, dtype=f64), LWIR)
    cm = SlopeStatistics.cox_munk(wind, anisotropic=True)
    tot = (float(cm.var_upwind), float(cm.var_crosswind), float(cm.cov))
    # the ray tracer's radiance of each ray: the model about the traced slope, Σ_CM − Σ_traced
    edges = field.bands.k_edges
    cov_b = field.band_covariance()[0]
    traced = cov_b[[o for o in range(len(edges) - 1) if edges[o + 1] <= K_TRACED]].sum(0)
    t_up, t_cr, t_cv = to_slope_frame(*(float(v) for v in traced), wdir)
    c, s = math.cos(wdir), math.sin(wdir)
    s_up, s_cr = sx * c + sy * s, -sx * s + sy * c
    stats = SlopeStatistics.from_variances(torch.full_like(s_up, tot[0] - t_up), torch.full_like(s_up, tot[1] - t_cr),
                                           torch.full_like(s_up, tot[2] - t_cv)).shifted(s_up, s_cr)
    T_ray = brightness_temperature(apparent_radiance(vz, los, stats, m, rb, sky, quadrature=QUAD), LWIR)
    # the slope the sweep resolves at the hit: the field at its sample footprint
    rng = tr["flat_range_m"][0][hit]
    delta = 2.0 * math.tan(math.radians(HFOV / 2)) / W
    fs = 2.0 * sample_step(cz, 0.25, min_step, across) * rng * delta / cz
    smp = field.sample(x[None], y[None], TIME_S, footprint=fs[None])
    ex, ey = torch.cos(vaw), torch.sin(vaw)
    a = smp["slope_x"][0] * ex + smp["slope_y"][0] * ey
    cx_, cy_, cxy_ = (v[0] for v in field.resolved_covariance(fs[None]))
    var_a = cx_ * ex * ex + 2 * cxy_ * ex * ey + cy_ * ey * ey
    cov_ap = (cy_ - cx_) * ex * ey + cxy_ * (ex * ex - ey * ey)
    kap = cov_ap / var_a
    # the sweep's sample at a: unresolved_statistics in the slope frame (its along-view σ_a², κ)
    sweep_stats = unresolved_statistics(torch.full_like(a, tot[0]), torch.full_like(a, tot[1]), torch.full_like(a, tot[2]),
                                        los, var_a, kap, a)
    L_sweep = apparent_radiance(vz, los, sweep_stats, m, rb, sky, quadrature=QUAD)
    T_sweep = brightness_temperature(L_sweep, LWIR)
    pix = pixel_level(tr, hit, T_ray, T_sweep)
    ac = a - a.mean()
    beta = lambda T: float(((T - T.mean()) * ac).mean() / (ac * ac).mean())  # noqa: E731
    r = float(((T_ray - T_ray.mean()) * ac).mean() / math.sqrt(float(T_ray.var(correction=0) * (ac * ac).mean())))
    return dict(vz=(math.degrees(float(vz.min())), math.degrees(float(vz.max()))), fs=float(fs.mean()),
                sigma_a=float(ac.std()), beta_ray=beta(T_ray), beta_sweep=beta(T_sweep), r=r, n=int(hit.sum()), **pix)


def pixel_level(tr: dict, hit: torch.Tensor, T_ray: torch.Tensor, T_sweep: torch.Tensor) -> dict:
    """The same rays made into pixels: each pixel the mean over its rays of (a) the ray tracer's
    temperature and (b) the sweep's model at the slope resolved at F_s at each hit — the ray tracer's
    geometry with the sweep's node values. σ of (b) / σ of (a) about the row means (each with its
    sampling variance over rays removed), per pixel and after 4×4 blocks, and the regression gain of (b)
    on (a) at both scales. (b) ≈ (a) in σ: the node values are not the cause; (b) ≈ the textured
    image's 0.8: they are."""
    h, w, S = tr["hit"][0].shape
    if int(hit.sum()) != h * w * S:
        return dict(ratio_pix=math.nan, ratio_blk=math.nan, gain_pix=math.nan, gain_blk=math.nan)
    a = T_ray.reshape(h, w, S)
    b = T_sweep.reshape(h, w, S)
    out = {}
    for name, n in (("pix", 1), ("blk", 4)):
        am = a.mean(-1).reshape(h // n, n, w // n, n).mean((1, 3))
        bm = b.mean(-1).reshape(h // n, n, w // n, n).mean((1, 3))
        # sampling variance of a block mean: the pixels' variances over rays / S, averaged over n² pixels / n²
        na = (a.var(-1) / S).reshape(h // n, n, w // n, n).mean((1, 3)) / (n * n)
        nb = (b.var(-1) / S).reshape(h // n, n, w // n, n).mean((1, 3)) / (n * n)
        nab = (((a - a.mean(-1, keepdim=True)) * (b - b.mean(-1, keepdim=True))).sum(-1) / (S - 1) / S
               ).reshape(h // n, n, w // n, n).mean((1, 3)) / (n * n)
        ac_, bc_ = am - am.mean(1, keepdim=True), bm - bm.mean(1, keepdim=True)
        shrink = 1 - 1 / am.shape[1]
        va = float((ac_ * ac_).mean() - na.mean() * shrink)
        vb = float((bc_ * bc_).mean() - nb.mean() * shrink)
        cab = float((ac_ * bc_).mean() - nab.mean() * shrink)
        out[f"ratio_{name}"] = math.sqrt(max(vb, 0.0) / va) if va > 0 else math.nan
        out[f"gain_{name}"] = cab / va if va > 0 else math.nan
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--rays", type=int, default=16)
    ap.add_argument("--across", type=float, default=1.0, help="the sweep's texture_hit_across (its footprint)")
    ap.add_argument("--min-step", type=float, default=1 / 32, help="the sweep's texture_hit_min_step")
    ap.add_argument("--cases", nargs="+", default=list(DEFAULT_CASES), metavar="DIR:WIND:ROW,ROW")
    args = ap.parse_args()
    torch.set_num_threads(1)
    print("| case | view zenith [°] | F_s [m] | σ_a at the hits | β ray [K] | β sweep [K] | β sweep / β ray | "
          "r(T ray, a) | rays | pixels: σ (b)/(a) | gain | 4×4: σ (b)/(a) | gain |")
    print("|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    for case in args.cases:
        direction, wind, rows = case.split(":")
        for row0 in (int(v) for v in rows.split(",")):
            d = response(direction, float(wind), row0, args.rays, args.across, args.min_step)
            print(f"| {direction} {float(wind):g} m/s | {d['vz'][0]:.1f}–{d['vz'][1]:.1f} | {d['fs']:.2f} | "
                  f"{d['sigma_a']:.3f} | {d['beta_ray']:.2f} | {d['beta_sweep']:.2f} | "
                  f"{d['beta_sweep'] / d['beta_ray']:.2f} | {d['r']:.2f} | {d['n']} | {d['ratio_pix']:.2f} | "
                  f"{d['gain_pix']:.2f} | {d['ratio_blk']:.2f} | {d['gain_blk']:.2f} |", flush=True)


if __name__ == "__main__":
    main()

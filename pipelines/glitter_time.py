"""How fast the brute force's glitter changes: the correlation across a patch's pixels between the
glint at t = 0 and at later times, for the spots' truth (:func:`roughsea_torch.raytrace_glitter.glitter_spots`),
for the first-hit textured render (the resolved waves alone) and for their ratio (the sub-pixel
part, which the glitter factor models). The patch of ``pipelines/glitter_vs_raytrace.py`` (8 m/s,
57 m, 80°, sun 15° up, MWIR). Prints a markdown table.

Usage:
    PYTHONPATH=. python pipelines/glitter_time.py [--seeds 1 3] [--rays 128]
"""

from __future__ import annotations

import argparse
import math

import torch

import roughsea_torch as rs
from roughsea_torch import glitter as G
from roughsea_torch.optics import band_refractive_index
from roughsea_torch.raytrace_glitter import glitter_spots

import glitter_vs_raytrace as P

TIMES = (0.0, 0.01, 0.02, 0.04, 0.08, 0.16, 0.32)


def corr(a: torch.Tensor, b: torch.Tensor) -> float:
    a, b = a.flatten() - a.mean(), b.flatten() - b.mean()
    return float((a * b).sum() / torch.sqrt((a * a).sum() * (b * b).sum()))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--seeds", type=int, nargs="+", default=[1, 3])
    ap.add_argument("--rays", type=int, default=128)
    args = ap.parse_args()
    torch.set_num_threads(1)
    cm = G.curvature_moments(torch.tensor(P.WIND, dtype=torch.float64))
    cam = rs.make_camera(P.N_PIX, P.N_PIX, hfov_deg=math.degrees(2 * math.atan(P.N_PIX / 2 * math.tan(P.IFOV))),
                         altitude_m=P.ALT, pitch_deg=P.PITCH, dtype=torch.float64)
    m = band_refractive_index(rs.MWIR, 290.0)
    tab = rs.TableSize(texture_hit="first")
    print("| seed | image | " + " | ".join(f"{t:g} s" for t in TIMES[1:]) + " |\n|---|---|" + "---|" * (len(TIMES) - 1))
    for seed in args.seeds:
        field = P.scene(seed, True).wave_field(1, torch.float64, torch.device("cpu"))
        truth, rnd = {}, {}
        for t in TIMES:
            truth[t] = glitter_spots(cam, field, P.SUN_ZENITH, 0.0, P.E_SUN, m, time_s=t, rays_per_pixel=args.rays,
                                     third_derivative=float(cm.third))["glint"]
            lit, dark = (rs.SeaScene(wind_speed=P.WIND, band=rs.MWIR, sea_temperature=290.0, seed=seed, foam=False, path=False,
                                     time_s=t, sun=rs.Sun(P.SUN_ZENITH, 0.0, e)) for e in (P.E_SUN, 0.0))
            rnd[t] = (rs.render(cam, lit, table=tab) - rs.render(cam, dark, table=tab))[0, 0].double()
        for name, f in (("truth (spots)", lambda t: truth[t]), ("render, first hit", lambda t: rnd[t]),
                        ("truth / render (sub-pixel)", lambda t: truth[t] / rnd[t])):
            print(f"| {seed} | {name} | " + " | ".join(f"{corr(f(0.0), f(t)):.2f}" for t in TIMES[1:]) + " |", flush=True)


if __name__ == "__main__":
    main()

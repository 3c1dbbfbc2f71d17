"""The first-hit texture (``TableSize(texture_hit="first")``) in the far field: textured against the
expectation image, by bands of rows, where a pixel's own footprint resolves few or no waves.

Camera: 48×64 px over 12°, a 20 m mast, pitch −2° (rows from 180 m to the horizon), looking
upwind, LWIR, brightness temperature, no path, no foam, flat earth. Per band of 4 rows: range, view
zenith, the pixels' footprint as the first hit's fade takes it (the side of the square of its area,
R δ / √cos θ̂), how many pixels resolve no band even at 0.8 × it ("far"), and textured − expectation: the worst pixel of one realization (seed 11), the
mean and per-pixel standard deviation over ``--seeds`` realizations (their mean is the bias of the
texture's ensemble mean, its standard error in brackets), for the first hit and, beside it, the
flat point (the default). Then the second law (sky = the sea's blackbody radiance R_B: every pixel
R_B) with the first hit on this camera and those of texture_vs_raytrace.py.

Usage (one thread, ~20 s):
    PYTHONPATH=. python pipelines/first_hit_far_field.py [--seeds 8] [--winds 5 15]
"""

from __future__ import annotations

import argparse
import math
import warnings

import torch

import roughsea_torch as rs

INF = float("inf")
H, W, HFOV, T_SEA = 48, 64, 12.0, 290.0


def scene(wind: float, seed, sky="midlatitude_summer") -> rs.SeaScene:
    return rs.SeaScene(wind_speed=wind, wind_direction=0.0, sea_temperature=T_SEA, seed=seed, time_s=3.0, foam=False,
                       path=False, sky=sky)


def render(cams, sc, hit: str) -> torch.Tensor:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)  # the "resolved slopes scaled down" note
        return rs.render(cams, sc, output="brightness_temperature", earth_radius_m=INF,
                         table=rs.TableSize(texture_hit=hit))[:, 0].double()


def far_field(wind: float, seeds: list[int]) -> None:
    cams1 = rs.make_camera(H, W, hfov_deg=HFOV, altitude_m=20.0, pitch_deg=-2.0)
    camsn = rs.make_camera(H, W, hfov_deg=HFOV, altitude_m=20.0, pitch_deg=-2.0, batch_size=len(seeds))
    geo = rs.view_geometry(cams1, earth_radius_m=INF)
    sea, rng, vz = geo.is_sea[0], geo.range_m[0].double(), geo.view_zenith[0].double()
    foot = rng * math.radians(HFOV) / W / torch.cos(vz).sqrt()  # (the side of the footprint's area: the fade's)
    field = scene(wind, 11).wave_field(1, torch.float64, torch.device("cpu"))
    cov = field.resolved_covariance(torch.where(sea, 0.8 * foot, torch.zeros_like(foot))[None])
    # (and not the row the horizon crosses: its sea part lies lower, where footprints resolve waves)
    far = sea & (cov[0][0] + cov[1][0] == 0) & torch.nn.functional.pad(sea[:-1], (0, 0, 1, 0))
    expct = render(cams1, scene(wind, None), "flat")[0]
    one = {hit: render(cams1, scene(wind, 11), hit)[0] - expct for hit in ("first", "flat")}
    ens = {hit: render(camsn, scene(wind, seeds), hit) - expct for hit in ("first", "flat")}
    print(f"\nwind {wind:g} m/s, textured − expectation [K]; far pixels: {int(far.sum())}, worst there: first "
          f"{float(one['first'][far].abs().max()) if far.any() else math.nan:.2e}, flat "
          f"{float(one['flat'][far].abs().max()) if far.any() else math.nan:.2e}")
    print("| rows | range [m] | view zenith [°] | footprint [m] | far | first: worst | mean (se) | sd "
          "| flat: worst | mean | sd |")
    print("|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    for r0 in range(0, H, 4):
        sl = slice(r0, r0 + 4)
        s = sea[sl]
        if not bool(s.any()):
            continue
        cells = []
        for hit in ("first", "flat"):
            d1, dn = one[hit][sl][s], ens[hit][:, sl][:, s]
            se = float(dn.mean(1).std() / math.sqrt(len(seeds))) if len(seeds) > 1 else math.nan
            mean = f"{float(dn.mean()):+.4f}" + (f" ({se:.4f})" if hit == "first" else "")
            cells += [f"{float(d1.abs().max()):.4f}", mean, f"{float(dn.std()):.4f}"]
        print(f"| {r0}–{r0 + 3} | {float(rng[sl][s].min()):.0f}–{float(rng[sl][s].max()):.0f} "
              f"| {float(vz[sl][s].mean().rad2deg()):.2f} | {float(foot[sl][s].mean()):.1f} | {int(far[sl].sum())} | "
              + " | ".join(cells) + " |")


def second_law(winds: list[float]) -> None:
    rb = float(rs.band_radiance(torch.tensor(T_SEA, dtype=torch.float64)))
    worst = 0.0
    for mast, pitch in ((20.0, -2.0), (15.0, -6.0), (15.0, -16.0), (20.0, -6.0)):
        cams = rs.make_camera(H, W, hfov_deg=HFOV, altitude_m=mast, pitch_deg=pitch)
        for wind in winds:
            worst = max(worst, float((render(cams, scene(wind, 11, sky=rb), "first") - T_SEA).abs().max()))
    print(f"\nsecond law, first hit (sky = R_B; masts 15–20 m, pitch −2° to −16°): max |T_b − {T_SEA:g} K| = {worst:.1e} K")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--seeds", type=int, default=8, help="realizations for the ensemble mean (default 8)")
    ap.add_argument("--winds", type=float, nargs="+", default=[5.0, 15.0], help="wind speeds [m/s]")
    args = ap.parse_args()
    torch.set_num_threads(1)
    seeds = list(range(1, args.seeds + 1))
    for wind in args.winds:
        far_field(wind, seeds)
    second_law(args.winds)


if __name__ == "__main__":
    main()

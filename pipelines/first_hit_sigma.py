"""The first-hit sweep's clutter σ against the ray tracer, per 8-row bin, for several sweep settings.

Re-renders the textured side of a saved ray-traced comparison (``pipelines/texture_vs_raytrace.py
--save PICKLE``; no tracing) with ``rs.TableSize(texture_hit="first", ...)`` for each setting of the
sweep (``texture_hit_across``, ``texture_hit_min_step``, ``texture_hit_step``, ``texture_hit_tracks``)
and prints, per bin at view zenith 80–88.5°, σ textured / σ ray-traced, then the issue's criteria
(σ within 0.85–1.2, 4×4-block correlation ≥ 0.8, correlation length within 30 %, σ over the seeds,
ensemble mean within 0.05 K) per setting.

Usage:
    python pipelines/first_hit_sigma.py PICKLE [--settings NAME ...] [--json out.json]
    python pipelines/first_hit_sigma.py PICKLE --time 3 [--settings NAME ...]   # cost of each setting
    python pipelines/first_hit_sigma.py PICKLE --identities [--settings NAME ...]   # far field, second law
    python pipelines/first_hit_sigma.py PICKLE --regress [--settings NAME ...]   # scaled copy or missing part?
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from pathlib import Path

import torch

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(Path(__file__).resolve().parent))
import pickle  # noqa: E402

import roughsea_torch as rs  # noqa: E402
import texture_vs_raytrace as tvr  # noqa: E402

SETTINGS = {  # name: TableSize fields of the sweep (texture_hit="first")
    "default": {},
    "across0.5": dict(texture_hit_across=0.5),
    "across2": dict(texture_hit_across=2.0),
    "min1/64": dict(texture_hit_min_step=1 / 64),
    "across0.5+min1/64": dict(texture_hit_across=0.5, texture_hit_min_step=1 / 64),
    "tracks2": dict(texture_hit_tracks=2.0),
    "tracks4": dict(texture_hit_tracks=4.0),
    "step1/8": dict(texture_hit_step=0.125),
    "min1/128": dict(texture_hit_min_step=1 / 128),
    "across0.5+min1/128": dict(texture_hit_across=0.5, texture_hit_min_step=1 / 128),
    "across0.25+min1/128": dict(texture_hit_across=0.25, texture_hit_min_step=1 / 128),
}


def in_range(b: dict) -> bool:
    return b["vz"][0] >= 80.0 - 0.3 and b["vz"][1] <= 88.5


def run(saved: dict, fields: dict) -> dict:
    tvr.TABLE = rs.TableSize(texture_hit="first", **fields)
    t0 = time.perf_counter()
    cases, ens = tvr.retexture(saved)
    out = dict(seconds=time.perf_counter() - t0, bins=[], ens=[])
    for c in cases:
        for b in c["bins"]:
            if in_range(b):
                out["bins"].append(dict(case=f"{c['direction']} {c['wind']:g} {c['pitch']:g}", vz=b["vz"],
                                        measurable=bool(b["measurable"]), ratio=b["ratio"], r_block=b["r_block"],
                                        len_ratio=b["len_tex"] / b["len_ray"] if b["measurable"] else math.nan,
                                        sigma_tex=b["sigma_tex"], sigma_ray=b["sigma_ray"]))
    for e in ens:
        for b in e["bins"]:
            if in_range(b):
                out["ens"].append(dict(case=f"{e['direction']} {e['wind']:g} {e['pitch']:g}", vz=b["vz"],
                                       ratio=b["ratio"], diff=b["diff"]))
    return out


def counts(res: dict) -> dict:
    sel = [b for b in res["bins"] if b["measurable"]]
    er = [b["ratio"] for b in res["ens"] if math.isfinite(b["ratio"])]
    return dict(sigma=sum(0.85 <= b["ratio"] <= 1.2 for b in sel), block=sum(b["r_block"] >= 0.8 for b in sel),
                length=sum(math.isfinite(b["len_ratio"]) and abs(b["len_ratio"] - 1) <= 0.3 for b in sel),
                ens_sigma=sum(0.85 <= r <= 1.2 for r in er), mean=sum(abs(b["diff"]) <= 0.05 for b in res["ens"]),
                n=len(sel), n_ens_sigma=len(er), n_ens=len(res["ens"]))


def regression(saved: dict, fields: dict) -> list[str]:
    """Per bin at 80–88.5° of the pitch −6° cases: σ textured / σ ray-traced per pixel and after 4×4 block
    averaging, the correlation at both scales and the regression gain of the textured clutter on the
    ray-traced one, cov(tex, ray) / var(ray) (the ray tracer's noise removed from its variance; a pure
    scaling of the same pattern gives gain = ratio and r = 1, a missing independent part gives gain = 1
    with ratio < 1 and r = ratio)."""
    tvr.TABLE = rs.TableSize(texture_hit="first", **fields)
    lines = ["| case | view zenith [°] | ratio pixel | ratio 4×4 | r pixel | r 4×4 | gain pixel | gain 4×4 |",
             "|---|---|---:|---:|---:|---:|---:|---:|"]
    for c in saved["cases"]:
        if c["pitch"] != tvr.PITCHES[0]:
            continue
        mast, direction = tvr.DIRECTIONS[c["direction"]]
        cams = rs.make_camera(tvr.H, tvr.W, hfov_deg=tvr.HFOV, altitude_m=mast, pitch_deg=c["pitch"])
        tex = tvr.render(cams, tvr.scene(c["wind"], direction, tvr.SEED))[0, 0].numpy()
        for b in c["bins"]:
            if not (in_range(b) and b["measurable"]):
                continue
            sl = slice(b["rows"][0], b["rows"][0] + tvr.BIN)
            a, r, nz = tvr.clutter(tex[sl]), tvr.clutter(c["ray"][sl]), c["noise"][sl]
            ba, br = tvr.clutter(tvr.blocks(a)), tvr.clutter(tvr.blocks(r))
            stats = []
            for x, y, noise in ((a, r, nz.mean() * (1 - 1 / a.shape[1])), (ba, br, tvr.blocks(nz).mean() / 16 * (1 - 1 / ba.shape[1]))):
                vx, vy, cxy = (x**2).mean(), (y**2).mean() - noise, (x * y).mean()
                stats.append((math.sqrt(vx / vy), cxy / math.sqrt(vx * vy), cxy / vy))
            (rp, cp, gp), (rb, cb, gb) = stats
            lines.append(f"| {c['direction']} {c['wind']:g} m/s | {b['vz'][0]:.1f}–{b['vz'][1]:.1f} | {rp:.2f} | {rb:.2f} | "
                         f"{cp:.2f} | {cb:.2f} | {gp:.2f} | {gb:.2f} |")
    return lines


def identities(fields: dict) -> dict:
    """The far field and second law of the sweep with these settings: max |textured − expectation| [K]
    over the sea pixels of the pipeline's far camera (20 m mast, pitch −2°) whose footprint resolves no
    band, (a) at the pixel's footprint R δ / cos θ̂ (the pipeline's criterion, made for the flat point)
    and (b) at the sweep's sample footprint 2 s(θ̂) R δ / cos θ̂ (``hits.sample_step``), each with the
    pipeline's 0.8 margin; and max |T_b − 290 K| under a sky equal to R_B."""
    from roughsea_torch.renderer.hits import sample_step

    table = rs.TableSize(texture_hit="first", **fields)
    tvr.TABLE = table
    cams = rs.make_camera(tvr.H, tvr.W, hfov_deg=tvr.HFOV, altitude_m=20.0, pitch_deg=-2.0)
    geo = rs.view_geometry(cams, earth_radius_m=tvr.INF)
    sea = geo.is_sea[0]
    cos_t = torch.cos(geo.view_zenith[0].double())
    foot = geo.range_m[0].double() * math.radians(tvr.HFOV) / tvr.W / cos_t
    width = geo.range_m[0].double() * math.radians(tvr.HFOV) / tvr.W  # R δ [m]
    step = 2.0 * sample_step(cos_t, table.texture_hit_step, table.texture_hit_min_step, table.texture_hit_across,
                             table.texture_hit_finest, width)
    out = {}
    for wind in (5.0, 15.0):
        diff = (tvr.render(cams, tvr.scene(wind, 0.0, tvr.SEED)) - tvr.render(cams, tvr.scene(wind, 0.0, None)))[0, 0]
        field = tvr.scene(wind, 0.0, tvr.SEED).wave_field(1, torch.float64, torch.device("cpu"))
        for name, f in (("pixel", foot), ("sample", foot * step)):
            cov = field.resolved_covariance(torch.where(sea, 0.8 * f, torch.zeros_like(f))[None])
            far = sea & (cov[0][0] + cov[1][0] == 0)
            out[f"{name} {wind:g}"] = (float(diff[far].abs().max()) if bool(far.any()) else math.nan, int(far.sum()))
    rb = float(rs.band_radiance(torch.tensor(tvr.T_SEA, dtype=torch.float64)))
    worst = 0.0
    for mast, direction in tvr.DIRECTIONS.values():
        cams = rs.make_camera(tvr.H, tvr.W, hfov_deg=tvr.HFOV, altitude_m=mast, pitch_deg=-6.0)
        for wind in (5.0, 15.0):
            worst = max(worst, float((tvr.render(cams, tvr.scene(wind, direction, tvr.SEED, sky=rb)) - tvr.T_SEA).abs().max()))
    out["second law"] = worst
    return out


def time_settings(names: list[str], repeats: int) -> dict:
    """Median time [s] of one 256×320 first-hit render per setting (the scene and camera of
    ``pipelines/bench_first_hit.py``: LWIR, 10 m/s upwind, 15 m mast, pitch −6°, 12°, float32), and of the
    flat point, each timed in turn ``repeats`` times after a warm-up call, one thread."""
    import warnings

    import bench_first_hit as bench

    cams = rs.make_camera(256, 320, **bench.CAMERA)
    fns = {"flat point": lambda: rs.render(cams, rs.SeaScene(**bench.SCENE))}
    for n in names:
        fns[n] = lambda kw=SETTINGS[n]: rs.render(cams, rs.SeaScene(**bench.SCENE), table=rs.TableSize(texture_hit="first", **kw))
    times = {n: [] for n in fns}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)
        for f in fns.values():
            f()
        for _ in range(repeats):
            for n, f in fns.items():
                t0 = time.perf_counter()
                f()
                times[n].append(time.perf_counter() - t0)
    return {n: sorted(v)[len(v) // 2] for n, v in times.items()}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("pickle")
    ap.add_argument("--settings", nargs="+", default=list(SETTINGS), choices=list(SETTINGS))
    ap.add_argument("--json", default=None, help="also write the results to this file")
    ap.add_argument("--time", type=int, default=0, metavar="REPEATS",
                    help="only time one 256×320 render per setting (median of REPEATS), no comparison")
    ap.add_argument("--regress", action="store_true",
                    help="only the per-pixel / 4×4 σ ratio, correlation and regression gain per bin (pitch −6°)")
    ap.add_argument("--identities", action="store_true",
                    help="only the far field and second law of each setting (no comparison)")
    args = ap.parse_args()
    torch.set_num_threads(1)
    with open(args.pickle, "rb") as fh:
        saved = pickle.load(fh)
    if args.regress:
        for n in args.settings:
            print(f"\n{n}:\n")
            print("\n".join(regression(saved, SETTINGS[n])))
        return
    if args.identities:
        print("| setting | far field, pixel footprint: 5 m/s | 15 m/s | far field, sample footprint: 5 m/s | 15 m/s | "
              "second law [K] |")
        print("|---|---:|---:|---:|---:|---:|")
        for n in args.settings:
            d = identities(SETTINGS[n])
            cells = [f"{d[k][0]:.1e} K ({d[k][1]} px)" for k in ("pixel 5", "pixel 15", "sample 5", "sample 15")]
            print(f"| {n} | " + " | ".join(cells) + f" | {d['second law']:.1e} |")
        return
    if args.time:
        med = time_settings(args.settings, args.time)
        print("| setting | 256×320 render [s] | × flat point |")
        print("|---|---:|---:|")
        for n, v in med.items():
            print(f"| {n} | {v:.2f} | {v / med['flat point']:.1f} |")
        return
    results = {}
    for name in args.settings:
        results[name] = run(saved, SETTINGS[name])
        print(f"{name}: {results[name]['seconds']:.0f} s", file=sys.stderr)
    names = list(results)
    print("| case | view zenith [°] | σ ray [K] | " + " | ".join(names) + " |")
    print("|---|---|---:|" + "---:|" * len(names))
    for i, b in enumerate(results[names[0]]["bins"]):
        cells = [tvr.fmt(results[n]["bins"][i]["ratio"]) for n in names]
        s_ray = f"{b['sigma_ray']:.3f}" if b["measurable"] else "<"
        print(f"| {b['case']} | {b['vz'][0]:.1f}–{b['vz'][1]:.1f} | {s_ray} | " + " | ".join(cells) + " |")
    print()
    print("| setting | σ in 0.85–1.2 | 4×4 r ≥ 0.8 | ℓ within 30 % | σ over seeds | mean within 0.05 K |")
    print("|---|---:|---:|---:|---:|---:|")
    for n in names:
        k = counts(results[n])
        print(f"| {n} | {k['sigma']} / {k['n']} | {k['block']} / {k['n']} | {k['length']} / {k['n']} | "
              f"{k['ens_sigma']} / {k['n_ens_sigma']} | {k['mean']} / {k['n_ens']} |")
    if args.json:
        Path(args.json).write_text(json.dumps(results, indent=1))


if __name__ == "__main__":
    main()

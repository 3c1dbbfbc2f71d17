"""Statistics of textured seas: ensemble-mean bias against view zenith, clutter against range and
wind, and foam against the sea.

1. **Ensemble mean.** ``--realizations`` independent seeds of a narrow camera 10 m above the sea
   looking 67–90° from the zenith (wind 8 m/s, analytic sky, no path), float64; per row of view
   zenith, the mean over realizations against the expectation image, with 4 standard errors of the
   sample; and the same with the naive flat-point sampling (every resolved tilt weighted equally,
   ``docs/texture.md`` §6) for comparison.
2. **Clutter against range.** The README's default LWIR scene (midlatitude summer, path on) from a
   20 m mast, 640 pixels over 30°: the standard deviation of the brightness temperature about
   the expectation image [K] per image row, against the row's slant range, for winds of 3, 6, 10 and
   15 m/s (16 realizations each), with the whitecaps on the crests (the default) and without
   (``foam=0``: the waves' slopes alone).
3. **Foam against the sea.** The brightness temperature of a sea without foam and of one wholly
   under foam at view zeniths of 60–88° (LWIR, midlatitude summer, 6 and 12 m/s).
Time (the clutter's decorrelation against wind and range): ``pipelines/clutter_time.py``.

Writes ``--out``/clutter_statistics.md and two PNGs.

Usage:
    python pipelines/clutter_statistics.py [--realizations 2048] [--out docs]
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

import torch
from tqdm.auto import tqdm

import roughsea_torch as rs
import roughsea_torch.clutter as clutter


def sky(c):
    return 10.0 + 20.0 * (1.0 - c) ** 4


def ensemble(n: int, naive: bool = False, chunk: int = 64):
    table = rs.TableSize(zenith=13, azimuth=5, texture=7)
    H, W = 48, 12

    def cams(b):
        return rs.make_camera(H, W, hfov_deg=8.0, altitude_m=10.0, pitch_deg=-7.0, batch_size=b, dtype=torch.float64)

    def scene(seed):
        return rs.SeaScene(wind_speed=8.0, sea_temperature=290.0, sky=sky, path=False, seed=seed)

    original = clutter.visible_slope
    if naive:
        clutter.visible_slope = lambda x, ct, st, sr, su, **k: sr[..., None].to(x.dtype) * x
    try:
        rows = []
        for i in tqdm(range(0, n, chunk), desc="naive" if naive else "realizations", unit="batch"):
            b = min(chunk, n - i)
            rows.append(rs.render(cams(b), scene(list(range(10_000 + i, 10_000 + i + b))), table=table)[:, 0].mean(2))
    finally:
        clutter.visible_slope = original
    per_image = torch.cat(rows)
    mean = rs.render(cams(1), scene(None), table=table)[0, 0].mean(1)
    g = rs.view_geometry(cams(1))
    sea = g.is_sea[0].all(1)
    vz = torch.rad2deg(g.view_zenith[0, :, W // 2])
    bias = per_image.mean(0) / mean - 1
    se = per_image.std(0) / math.sqrt(per_image.shape[0]) / mean
    return vz[sea], bias[sea], se[sea]


def clutter_vs_range(winds=(3.0, 6.0, 10.0, 15.0), n=16):
    H, W = 512, 640

    def cams(b=1):
        return rs.make_camera(H, W, hfov_deg=30.0, altitude_m=20.0, pitch_deg=-6.0, batch_size=b)

    g = rs.view_geometry(cams())
    rng = g.range_m[0, :, W // 2]
    sea = g.is_sea[0].all(1)
    out = {}
    for w in tqdm(winds, desc="winds"):
        sds = []
        for foam in ({}, dict(foam=0.0)):  # with the whitecaps on the crests (the default), and without
            mean = rs.render(cams(), rs.SeaScene(wind_speed=w, sea_temperature=290.0, **foam),
                             output="brightness_temperature")[0, 0]
            var = torch.zeros(H)
            for i in range(0, n, 4):
                img = rs.render(cams(4), rs.SeaScene(wind_speed=w, sea_temperature=290.0, seed=list(range(i, i + 4)),
                                                     time_s=30.0, **foam), output="brightness_temperature")[:, 0]
                var += ((img - mean) ** 2).mean((0, 2))
            sds.append((var / (n // 4)).sqrt()[sea])
        out[w] = tuple(sds)
    return rng[sea], out


def foam_against_sea(winds=(6.0, 12.0), pitches=(-30.0, -15.0, -5.0, -2.0)):
    """Brightness temperature [K] of the sea without foam and of a sea wholly under foam (expectation
    images, ``foam=0`` and ``foam=1``), LWIR, midlatitude summer with path, sea at 293 K, a narrow
    camera 20 m up; at the view zeniths the pitches give (image centre)."""
    cams = rs.make_camera(64, 8, hfov_deg=2.0, altitude_m=20.0, pitch_deg=torch.tensor(pitches, dtype=torch.float64),
                          batch_size=len(pitches), dtype=torch.float64)
    vz = torch.rad2deg(rs.view_geometry(cams).view_zenith[:, 32, 4])
    rows = []
    for w in winds:
        sea, foam = (rs.render(cams, rs.SeaScene(wind_speed=w, sea_temperature=293.0, foam=f),
                               output="brightness_temperature")[:, 0, 32, 4] for f in (0.0, 1.0))
        rows += [(w, float(z), float(a), float(b)) for z, a, b in zip(vz, sea, foam)]
    return rows


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--realizations", type=int, default=2048)
    ap.add_argument("--out", default="docs")
    args = ap.parse_args()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    vz, bias, se = ensemble(args.realizations)
    vzn, bias_n, se_n = ensemble(max(args.realizations // 4, 64), naive=True)
    textured = se > 1e-6
    lines = ["# Textured seas: statistics", "", "`python pipelines/clutter_statistics.py` "
             f"(--realizations {args.realizations})", "",
             "## Ensemble mean against the expectation image (wind 8 m/s, 10 m, analytic sky, float64)", "",
             "| view zenith [deg] | bias (relative) | 4 standard errors | naive flat-point bias |", "|---:|---:|---:|---:|"]
    for i in range(0, len(vz), 3):
        if textured[i]:
            lines.append(f"| {float(vz[i]):.2f} | {float(bias[i]):+.1e} | {4 * float(se[i]):.1e} | {float(bias_n[i]):+.1e} |")
    worst = float((bias.abs() / (4 * se).clamp_min(1e-12))[textured].max())
    lines += ["", f"Largest |bias| / (4 standard errors) over the textured rows: {worst:.2f}; largest |bias| "
              f"{float(bias.abs()[textured].max()):.1e}, largest 4 standard errors {float(4 * se[textured].max()):.1e}.", ""]
    fig, ax = plt.subplots(figsize=(6, 3.6))
    ax.fill_between(vz[textured], (-4 * se)[textured], (4 * se)[textured], color="0.85", label="±4 standard errors")
    ax.plot(vz[textured], bias[textured], "o-", ms=3, label="two-scale (visible slopes)")
    ax.plot(vzn[textured], bias_n[textured], "s--", ms=3, label="naive flat-point sampling")
    ax.axhline(1e-3, color="r", lw=0.8, ls=":")
    ax.axhline(-1e-3, color="r", lw=0.8, ls=":", label="±1e-3 (issue tolerance)")
    ax.set_xlabel("view zenith [deg]")
    ax.set_ylabel("ensemble mean / expectation − 1")
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(out / "clutter_ensemble_bias.png", dpi=120)
    print("\n".join(lines), file=sys.stderr)

    rng, sd = clutter_vs_range()
    fig, ax = plt.subplots(figsize=(6, 3.6))
    lines += ["## Clutter against range (LWIR, midlatitude summer, 20 m, 640 px over 30°)", "",
              "σ of the brightness temperature about the expectation image, per image row, 16 realizations: with the "
              "whitecaps on the crests (the default, `foam=\"auto\"`: Monahan's fraction) and without (`foam=0`, the waves' "
              "slopes alone).", "",
              "| wind [m/s] | σ at 100 m [K] | σ at 300 m [K] | σ at 1 km [K] | without foam: 100 m | 300 m | 1 km |",
              "|---:|---:|---:|---:|---:|---:|---:|"]
    for w, (v, v0) in sd.items():
        line = ax.loglog(rng, v, label=f"{w:g} m/s")[0]
        ax.loglog(rng, v0, "--", color=line.get_color(), lw=1)
        at = [float(u[(rng - r).abs().argmin()]) for u in (v, v0) for r in (100.0, 300.0, 1000.0)]
        lines.append(f"| {w:g} | " + " | ".join(f"{a:.3f}" for a in at) + " |")
    ax.set_title("solid: with whitecaps on the crests; dashed: without", fontsize=8)
    ax.set_xlabel("slant range [m]")
    ax.set_ylabel("clutter σ [K]")
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(out / "clutter_vs_range.png", dpi=120)

    lines += ["", "## Foam against the sea (LWIR, midlatitude summer, sea 293 K, 20 m, expectation images)", "",
              "Brightness temperature of the sea without foam (`foam=0`) and wholly under foam (`foam=1`): near grazing "
              "the model's foam is darker than the sea (README, *Textured seas*).", "",
              "| wind [m/s] | view zenith [deg] | sea [K] | foam [K] |", "|---:|---:|---:|---:|"]
    lines += [f"| {w:g} | {z:.1f} | {a:.2f} | {b:.2f} |" for w, z, a, b in foam_against_sea()]

    lines += ["", "How fast the clutter decorrelates in time, against wind and range: `pipelines/clutter_time.py` "
              "(docs/clutter_time.md).", ""]
    report = "\n".join(lines) + "\n"
    (out / "clutter_statistics.md").write_text(report)
    print(report)


if __name__ == "__main__":
    main()

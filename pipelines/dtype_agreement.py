"""Do float32 and float64 renders of one scene agree? A table per scene, to find thresholds and ties
that a value rounded to float32 falls on the other side of (a different realization, not rounding).

Each case renders the same scene with float32 and float64 cameras (``rs.make_camera(..., dtype=)``)
in brightness temperature and prints max and rms |T32 − T64| [K] over the image, the correlation of
the two images' clutter (each row's mean removed; "—" where an image has none), and two columns that
tell a bug from float32's own precision: the float32 render on the float64 default quadrature rule
(float32 renders use a coarser rule by default, ``Quadrature.default``), and the float64 render's own
change when the pitch moves by 1e-6° (1.7e-8 rad, below float32's rounding of a pose): where that is as
large as the float32 difference, the render itself is that sensitive (an edge), not the dtype. Expected
float32 rounding: ~1e-4 K for expectation images, up to ~1e-3–1e-2 K for textured seas; a case beyond
0.02 K max or below 0.999 correlation is flagged ``<<``. The gradient cases compare d(mean T)/d(wind
speed) by autograd (also on the float64 rule) and its per-pixel map (``rs.pixel_derivative``).

    PYTHONPATH=. python pipelines/dtype_agreement.py [--only SUBSTRING] [--random N]

and N (default 48) scenes drawn at random, compared on the float64 rule (flagged only beyond 0.02 K
and three times the float64 render's own change for the pitch step). Small cameras (48×64 to
128×160), one thread; about two minutes. Report: ``docs/dtype_agreement.md``.
"""

from __future__ import annotations

import argparse
import math
import os
import random
import sys
import time

os.environ.setdefault("OMP_NUM_THREADS", "1")

import torch  # noqa: E402

import roughsea_torch as rs  # noqa: E402

torch.set_num_threads(1)

PI = math.pi
FLAG_MAX_K, FLAG_CORR = 0.02, 0.999
Q64 = rs.Quadrature.default(torch.float64)  # the float64 default rule, to tell rounding from the float32 rule
DPITCH_DEG = 1e-6  # a float64 render's own sensitivity: pitch moved by 1.7e-8 rad (float32 rounds a pose by ~6e-8)


def cams(dtype, h=64, w=80, pitch=-6.0, alt=15.0, hfov=20.0, yaw=0.0, roll=0.0, batch=None, dpitch=0.0):
    return rs.make_camera(h, w, hfov_deg=hfov, altitude_m=alt, pitch_deg=pitch + dpitch, yaw_deg=yaw, roll_deg=roll,
                          batch_size=batch, dtype=dtype)


def clutter_corr(a: torch.Tensor, b: torch.Tensor) -> float:
    """Correlation of two (…, H, W) images after removing each row's mean (over all images)."""
    a = a.double() - a.double().mean(dim=-1, keepdim=True)
    b = b.double() - b.double().mean(dim=-1, keepdim=True)
    na, nb = a.norm(), b.norm()
    if float(na) < 1e-9 or float(nb) < 1e-9:
        return float("nan")
    return float((a * b).sum() / (na * nb))


def stats(t32: torch.Tensor, t64: torch.Tensor) -> tuple[float, float, float]:
    d = (t32.double() - t64.double()).abs()
    return float(d.max()), float(d.pow(2).mean().sqrt()), clutter_corr(t32, t64)


def still(cam_kw=None, table=None, **scene_kw):
    """A case: one render per dtype of ``SeaScene(**scene_kw)``."""
    cam_kw = cam_kw or {}
    table = table or rs.TableSize()

    def run(dtype, quadrature=None, dpitch=0.0):
        return rs.render(cams(dtype, dpitch=dpitch, **cam_kw), rs.SeaScene(**scene_kw), table=table,
                         quadrature=quadrature, output="brightness_temperature")
    return run


def clip(times, cam_kw=None, table=None, **scene_kw):
    cam_kw = cam_kw or {}
    table = table or rs.TableSize()

    def run(dtype, quadrature=None, dpitch=0.0):
        return rs.render_clip(cams(dtype, dpitch=dpitch, **cam_kw), rs.SeaScene(**scene_kw), torch.as_tensor(times),
                              table=table, quadrature=quadrature, output="brightness_temperature")
    return run


def gradient_case(wind, seed, cam_kw=None, table=None, **scene_kw):
    """d(mean T)/dW by autograd and the per-pixel map dT/dW, per dtype."""
    cam_kw = cam_kw or {}
    table = table or rs.TableSize()

    def run(dtype, quadrature=None):
        w = torch.tensor(float(wind), dtype=dtype, requires_grad=True)
        img = rs.render(cams(dtype, **cam_kw), rs.SeaScene(wind_speed=w, seed=seed, **scene_kw), table=table,
                        quadrature=quadrature, output="brightness_temperature")
        per_pixel = rs.pixel_derivative(img, w)
        (g,) = torch.autograd.grad(img.mean(), w)
        return per_pixel.detach(), float(g)
    return run


def cases():
    """Every still and clip case, in the table's order."""
    return basic_cases() + foam_sun_time_cases() + hunting_cases()


def basic_cases():
    """Wind directions, wind speeds and pitches, expectation and textured, flat and first hit, at t = 3 s (at
    t = 0 the waves' travel signs do not show: the crosswind bug of 92ae01d hid there)."""
    sea = dict(sea_temperature=290.0, time_s=3.0)
    flat, first = rs.TableSize(), rs.TableSize(texture_hit="first")
    out = []
    for wd_name, wd in [("0", 0.0), ("π/2", PI / 2), ("π", PI), ("−π/2", -PI / 2), ("3π/2", 3 * PI / 2), ("0.3", 0.3),
                        ("0.3 f32 tensor", torch.tensor(0.3, dtype=torch.float32)),
                        ("π/2 f32 tensor", torch.tensor(PI / 2, dtype=torch.float32))]:
        for seed in (None, 11):
            out.append((f"direction {wd_name}, 15 m/s, seed {seed}", still(wind_speed=15.0, wind_direction=wd,
                                                                           seed=seed, **sea)))
        out.append((f"direction {wd_name}, 15 m/s, seed 11, first hit", still(table=first, wind_speed=15.0,
                                                                               wind_direction=wd, seed=11, **sea)))
    for w in (2.0, 5.0, 10.0, 15.0, 25.0):
        for seed in (None, 11):
            out.append((f"wind {w:g} m/s, seed {seed}", still(wind_speed=w, seed=seed, wind_direction=0.3, **sea)))
        out.append((f"wind {w:g} m/s, seed 11, first hit", still(table=first, wind_speed=w, seed=11,
                                                                  wind_direction=0.3, **sea)))
    for p in (-2.0, -6.0, -16.0, -45.0):
        for seed in (None, 11):
            for tname, tab in (("flat", flat), ("first", first)):
                if seed is None and tname == "first":
                    continue
                out.append((f"pitch {p:g}°, 8 m/s, seed {seed}, {tname}",
                            still(cam_kw=dict(pitch=p), table=tab, wind_speed=8.0, seed=seed, wind_direction=PI / 2,
                                  **sea)))
    return out


def foam_sun_time_cases():
    """Foam, the sun, large times, clips and a mixed batch (the brief's list, second half)."""
    sea = dict(sea_temperature=290.0)
    flat, first = rs.TableSize(), rs.TableSize(texture_hit="first")
    out = []
    for seed in (None, 11):
        out.append((f"foam auto, 20 m/s, seed {seed}", still(wind_speed=20.0, seed=seed, foam="auto", **sea)))
        out.append((f"foam 0.3, 10 m/s, seed {seed}", still(wind_speed=10.0, seed=seed, foam=0.3, **sea)))
    out.append(("foam auto, 20 m/s, seed 11, first hit", still(table=first, wind_speed=20.0, seed=11, **sea)))
    out.append(("foam trails, 20 m/s, seed 11", still(table=rs.TableSize(foam_trails=True), wind_speed=20.0, seed=11,
                                                      **sea)))
    for seed in (None, 11):
        out.append((f"sun MWIR 75°, 6 m/s, seed {seed}",
                    still(cam_kw=dict(alt=20.0, pitch=-3.0, hfov=30.0), wind_speed=6.0, seed=seed, band=rs.MWIR,
                          sun_zenith=math.radians(75.0), sun_azimuth=0.0, **sea)))
    out.append(("sun MWIR 75°, 6 m/s, seed 11, glitter",
                still(cam_kw=dict(alt=20.0, pitch=-3.0, hfov=30.0), table=rs.TableSize(glitter=True), wind_speed=6.0,
                      seed=11, band=rs.MWIR, sun_zenith=math.radians(75.0), sun_azimuth=0.0, **sea)))
    out.append(("sun LWIR 60°, az π/2, 10 m/s, seed 11",
                still(cam_kw=dict(pitch=-10.0), wind_speed=10.0, seed=11, sun_zenith=math.radians(60.0),
                      sun_azimuth=PI / 2, wind_direction=PI / 2, **sea)))
    for t in (1e3, 1e5):
        for tab_name, tab in (("flat", flat), ("first", first)):
            out.append((f"time {t:g} s, 10 m/s, seed 11, {tab_name}", still(table=tab, wind_speed=10.0, seed=11,
                                                                           time_s=t, **sea)))
    out.append(("clip 0–0.9 s (10 frames), 10 m/s", clip(torch.arange(10) / 10.0, wind_speed=10.0, seed=11, **sea)))
    out.append(("clip at 1e5 s (4 frames), 10 m/s", clip(1e5 + torch.arange(4) / 10.0, wind_speed=10.0, seed=11,
                                                         **sea)))
    mixed = dict(wind_speed=torch.tensor([2.0, 10.0, 15.0, 25.0]), wind_direction=torch.tensor([0.0, PI / 2, PI, 0.3]),
                 sea_temperature=torch.tensor([285.0, 290.0, 295.0, 300.0]), time_s=torch.tensor([0.0, 3.0, 1e5, 7.0]))
    mixed_cam = dict(batch=4, pitch=torch.tensor([-2.0, -6.0, -16.0, -45.0]), alt=torch.tensor([10.0, 15.0, 30.0, 60.0]))
    out.append(("batch of 4 mixed, expectation", still(cam_kw=mixed_cam, **mixed)))
    out.append(("batch of 4 mixed, seeds 1–4", still(cam_kw=mixed_cam, seed=[1, 2, 3, 4], **mixed)))
    out.append(("batch of 4 mixed, seeds 1–4, first", still(cam_kw=mixed_cam, table=first, seed=[1, 2, 3, 4],
                                                            **mixed)))
    out.append(("128×160, 12 m/s, seed 11, π/2", still(cam_kw=dict(h=128, w=160), wind_speed=12.0, seed=11,
                                                      wind_direction=PI / 2, **sea)))
    out.append(("48×64 −90° nadir-ish (−89°), seed 11", still(cam_kw=dict(h=48, w=64, pitch=-89.0), wind_speed=8.0,
                                                             seed=11, **sea)))
    return out


def hunting_cases():
    """More seeds across the wind, diagonal and wrapped directions, yaw and roll, the horizon in view,
    large times with foam, the sun's disk in view, the first hit's glint, no shadowing."""
    sea = dict(sea_temperature=290.0)
    flat, first = rs.TableSize(), rs.TableSize(texture_hit="first")
    sea3 = dict(sea_temperature=290.0, time_s=3.0)
    out = []
    for seed in (1, 2, 3, 4, 5, 6):
        out.append((f"π/2, 15 m/s, seed {seed}, first hit", still(table=first, wind_speed=15.0, seed=seed,
                                                                  wind_direction=PI / 2, **sea3)))
    for wd_name, wd in (("π/4", PI / 4), ("3π/4", 3 * PI / 4), ("2π", 2 * PI), ("−π", -PI)):
        out.append((f"direction {wd_name}, 10 m/s, seed 11", still(wind_speed=10.0, seed=11, wind_direction=wd, **sea3)))
    out.append(("yaw 37°, roll 5°, 10 m/s, seed 11", still(cam_kw=dict(yaw=37.0, roll=5.0), wind_speed=10.0, seed=11, **sea3)))
    out.append(("yaw 90° (looking across a π/2 wind's upwind axis), seed 11",
                still(cam_kw=dict(yaw=90.0), wind_speed=10.0, seed=11, wind_direction=PI / 2, **sea3)))
    for p, alt in ((0.0, 15.0), (-0.5, 50.0), (-1.0, 10.0)):
        for seed in (None, 11):
            out.append((f"horizon: pitch {p:g}°, {alt:g} m, seed {seed}",
                        still(cam_kw=dict(h=128, w=160, pitch=p, alt=alt), wind_speed=10.0, seed=seed, **sea3)))
    out.append(("horizon: pitch 0°, seed 11, first", still(cam_kw=dict(h=128, w=160, pitch=0.0), table=first,
                                                          wind_speed=10.0, seed=11, **sea)))
    for t in (1e6 + 0.3, 1e8 + 0.3):
        for tab_name, tab in (("flat", flat), ("first", first), ("trails", rs.TableSize(foam_trails=True))):
            out.append((f"time {t:.10g} s, foam, 20 m/s, seed 11, {tab_name}",
                        still(cam_kw=dict(alt=10.0, pitch=-10.0), table=tab, wind_speed=20.0, seed=11, time_s=t,
                              **sea)))
    out.append(("time 1e5 s, foam trails, 20 m/s", still(table=rs.TableSize(foam_trails=True), wind_speed=20.0, seed=11,
                                                       time_s=1e5, **sea)))
    out.append(("time 1e5 s, sun MWIR glitter", still(cam_kw=dict(alt=20.0, pitch=-3.0, hfov=30.0),
                                                      table=rs.TableSize(glitter=True), wind_speed=6.0, seed=11,
                                                      band=rs.MWIR, sun_zenith=math.radians(75.0), time_s=1e5, **sea)))
    out.append(("time 1e5 s, sun MWIR, first hit", still(cam_kw=dict(alt=20.0, pitch=-3.0, hfov=30.0), table=first,
                                                         wind_speed=6.0, seed=11, band=rs.MWIR,
                                                         sun_zenith=math.radians(75.0), time_s=1e5, **sea)))
    out.append(("sun's disk in view: 3° lens 128×160, sun 3° up", still(cam_kw=dict(h=128, w=160, hfov=3.0, pitch=3.0),
                                                                      wind_speed=6.0, band=rs.MWIR,
                                                                      sun_zenith=math.radians(87.0), **sea)))
    out.append(("sun's disk in view: 30° lens, sun 4° up, seed 11", still(cam_kw=dict(hfov=30.0, pitch=-1.0),
                                                                         wind_speed=6.0, seed=11, band=rs.MWIR,
                                                                         sun_zenith=1.5, **sea)))
    out.append(("sun 4° up, seed 11, first hit", still(cam_kw=dict(hfov=30.0, pitch=-1.0), table=first, wind_speed=6.0,
                                                       seed=11, band=rs.MWIR, sun_zenith=1.5, **sea)))
    for k in range(4):  # the first hit's glint at crest silhouettes (docs/dtype_agreement.md)
        out.append((f"sun MWIR 75°, 6 m/s, seed 11, first hit, t = {0.37 * (k + 5):.2f} s",
                    still(cam_kw=dict(alt=20.0, pitch=-3.0, hfov=30.0), table=first, wind_speed=6.0, seed=11,
                          band=rs.MWIR, sun_zenith=math.radians(75.0), time_s=0.37 * (k + 5), foam=False, **sea)))
    out.append(("shadowing=False, pitch −20°, 10 m/s, seed None", still(cam_kw=dict(pitch=-20.0), wind_speed=10.0,
                                                                       shadowing=False, **sea)))
    out.append(("shadowing=False, pitch −20°, 10 m/s, seed 11", still(cam_kw=dict(pitch=-20.0), wind_speed=10.0, seed=11,
                                                                     shadowing=False, **sea)))
    out.append(("MWIR night, 10 m/s, seed 11", still(wind_speed=10.0, seed=11, band=rs.MWIR, **sea)))
    out.append(("shadowing correlated, 10 m/s, seed None", still(wind_speed=10.0, shadowing="correlated", **sea)))
    return out


def gradient_cases():
    sea = dict(sea_temperature=290.0)
    return [("dT/dW, 8 m/s, expectation", gradient_case(8.0, None, **sea)),
            ("dT/dW, 8 m/s, seed 11", gradient_case(8.0, 11, **sea)),
            ("dT/dW, 15 m/s, seed 11, π/2", gradient_case(15.0, 11, wind_direction=PI / 2, **sea)),
            ("dT/dW, 8 m/s, seed 11, first", gradient_case(8.0, 11, table=rs.TableSize(texture_hit="first"), **sea))]


def random_scenes(n: int, seed: int = 7):
    """``n`` scenes drawn at random (Python's ``random``, fixed seed): wind, direction (cardinal or any),
    pitch, altitude, yaw, time up to 2e8 s, wave seed, sun or night, flat or first hit, foam trails."""
    rng = random.Random(seed)
    for _ in range(n):
        wind, wd = rng.choice([1.5, 4.0, 8.0, 12.0, 18.0, 24.0]), rng.choice([0.0, PI / 2, PI, -PI / 2, rng.uniform(-3, 3)])
        cam_kw = dict(h=48, w=64, hfov=25.0, pitch=rng.choice([-0.5, -2.0, -5.0, -12.0, -30.0]),
                      alt=rng.choice([3.0, 10.0, 30.0, 100.0]), yaw=rng.uniform(-180, 180))
        t, wave_seed = rng.choice([0.0, 2.7, 1e4 + 0.1, 3e6 + 0.7, 2e8 + 0.3]), rng.randrange(1000)
        sun, first, trails = rng.random() < 0.4, rng.random() < 0.5, rng.random() < 0.3
        kw = dict(wind_speed=wind, wind_direction=wd, sea_temperature=290.0, seed=wave_seed, time_s=t)
        if sun:
            kw.update(band=rs.MWIR, sun_zenith=rng.uniform(0.9, 1.45), sun_azimuth=rng.uniform(-3, 3))
        table = rs.TableSize(texture_hit="first" if first else "flat", foam_trails=trails)
        name = (f"{wind:g} m/s, dir {wd:.3f}, pitch {cam_kw['pitch']:g}°, {cam_kw['alt']:g} m, yaw {cam_kw['yaw']:.0f}°, "
                f"t {t:g} s, seed {wave_seed}, {'sun' if sun else 'night'}, {'first' if first else 'flat'}"
                + (", trails" if trails else ""))
        yield name, still(cam_kw=cam_kw, table=table, **kw)


def fmt_corr(c: float) -> str:
    return "—" if math.isnan(c) else f"{c:.6f}"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--only", default="", help="run only the cases whose name contains this")
    ap.add_argument("--random", type=int, default=48, help="scenes drawn at random after the listed ones (0: none)")
    args = ap.parse_args()
    t_start = time.time()
    print(f"# torch {torch.__version__}, roughsea_torch {rs.__version__}, {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}")
    print("| case | max \\|T32 − T64\\| [K] | rms [K] | clutter corr. | max, f32 on the f64 rule [K] | max, f64 at pitch + 1e-6° [K] | T64 clutter std [K] | s |")
    print("|---|---|---|---|---|---|---|---|")
    flagged = []
    for name, run in cases():
        if args.only not in name:
            continue
        t0 = time.time()
        t64 = run(torch.float64)
        t32 = run(torch.float32)
        mx, rms, corr = stats(t32, t64)
        mx_q = stats(run(torch.float32, Q64), t64)[0]
        mx_c = stats(run(torch.float64, dpitch=DPITCH_DEG), t64)[0]
        std = float((t64 - t64.mean(dim=-1, keepdim=True)).std())
        bad = mx > FLAG_MAX_K or (not math.isnan(corr) and corr < FLAG_CORR) or not torch.isfinite(t32).all()
        if bad:
            flagged.append(name)
        print(f"| {name} | {mx:.2e} | {rms:.2e} | {fmt_corr(corr)} | {mx_q:.2e} | {mx_c:.2e} | {std:.3f} | {time.time() - t0:.1f} |"
              + (" << |" if bad else ""), flush=True)
    print()
    print("| gradient case | d(mean T)/dW f64 [K/(m/s)] | f32 − f64 | f32 on the f64 rule − f64 | per-pixel max \\|Δ\\| | per-pixel rms | map corr. | s |")
    print("|---|---|---|---|---|---|---|---|")
    for name, run in gradient_cases():
        if args.only not in name:
            continue
        t0 = time.time()
        p64, g64 = run(torch.float64)
        p32, g32 = run(torch.float32)
        g32q = run(torch.float32, Q64)[1]
        d = (p32.double() - p64).abs()
        corr = float(torch.corrcoef(torch.stack([p32.double().flatten(), p64.flatten()]))[0, 1])
        finite = bool(torch.isfinite(p32).all() and torch.isfinite(p64).all())
        print(f"| {name} | {g64:.5f} | {g32 - g64:+.1e} | {g32q - g64:+.1e} | {float(d.max()):.2e} | {float(d.pow(2).mean().sqrt()):.2e} | "
              f"{corr:.6f} | {time.time() - t0:.1f} |" + ("" if finite else " non-finite << |"), flush=True)
    if args.random:
        print()
        print(f"| random scene (on the f64 rule) | max \\|T32 − T64\\| [K] | rms [K] | clutter corr. | max, f64 at pitch + 1e-6° [K] |")
        print("|---|---|---|---|---|")
        for name, run in random_scenes(args.random):
            t64 = run(torch.float64)
            mx, rms, corr = stats(run(torch.float32, Q64), t64)
            mx_c = stats(run(torch.float64, dpitch=DPITCH_DEG), t64)[0]
            bad = (mx > FLAG_MAX_K and mx > 3 * mx_c) or (not math.isnan(corr) and corr < FLAG_CORR)
            if bad:
                flagged.append(name)
            print(f"| {name} | {mx:.2e} | {rms:.2e} | {fmt_corr(corr)} | {mx_c:.2e} |" + (" << |" if bad else ""), flush=True)
    print()
    print(f"flagged (max > {FLAG_MAX_K} K or corr < {FLAG_CORR}): {flagged if flagged else 'none'}")
    print(f"total {time.time() - t_start:.0f} s")


if __name__ == "__main__":
    sys.exit(main())

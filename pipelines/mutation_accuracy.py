"""How much does a surviving mutant of the renderer's table layout change the image?

For the mutants of ``pipelines/mutation.py`` that survive in the renderer's layout code (node spans,
node counts, culling bounds), this applies each one to a copy of the package and prints the largest
relative difference |table − per-pixel| / per-pixel over ten scenes (night: anisotropic, correlated
and wide views; day: the sun's glint in view with and without aerosol; nadir views by night and by
day; textured seas by night and by day), and, for the sweep (``TableSize(texture_hit='first')``,
which per-pixel evaluation does not do), the difference from the unmutated sweep. A mutant that
leaves these within the tests' bounds changes accuracy only; the notes in ``mutation.py`` quote the
numbers.

    python pipelines/mutation_accuracy.py "renderer/plan make_plan\\(\\) L124" "renderer/glint reachable\\(\\) L83 6.0"

Each argument is a module and a regular expression on "function() L<line> original → mutated".
One torch thread; about a minute a mutant.
"""

from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import mutation as M

ROOT = M.ROOT


def measure(sweep_ref: Path, save: bool) -> dict[str, float]:
    """The scenes' errors with the package on sys.path (run in a subprocess)."""
    import math

    import torch

    import roughsea_torch as rs

    torch.set_num_threads(1)
    f64 = torch.float64

    def cams(hw=(24, 32), **kw):
        return rs.make_camera(*hw, **{"hfov_deg": 30.0, "altitude_m": 20.0, "pitch_deg": -5.0, "dtype": f64, **kw})

    out = {}

    def case(name, c, s):
        g = rs.view_geometry(c)
        t, d = rs.render(c, s), rs.render(c, s, geometry=g, method="direct")
        out[name] = float(((t - d) / d).abs().max())

    two = {"altitude_m": torch.tensor([20.0, 150.0]), "pitch_deg": torch.tensor([-2.0, -12.0]),
           "yaw_deg": torch.tensor([10.0, -30.0]), "batch_size": 2}
    w2 = {"wind_speed": torch.tensor([4.0, 12.0]), "wind_direction": torch.tensor([0.4, 2.0]), "sea_temperature": 291.0}
    case("night_aniso", cams(**two), rs.SeaScene(**w2))
    case("night_correlated", cams(**two), rs.SeaScene(sea_temperature=291.0, slopes=rs.SlopeStatistics(0.2, 0.1, 0.4),
                                                       wind_direction=0.7))
    case("night_wide", cams(hfov_deg=60.0, pitch_deg=-20.0, yaw_deg=torch.tensor([0.0, 100.0]), batch_size=2),
         rs.SeaScene(wind_speed=6.0, sea_temperature=290.0, wind_direction=1.0))
    case("day_glint", cams(hw=(32, 40), **two), rs.SeaScene(**w2, band=rs.MWIR, sun_zenith=math.radians(70.0), sun_azimuth=0.0))
    case("day_glint_clear", cams(hw=(32, 40), **two),
         rs.SeaScene(**w2, band=rs.MWIR, sun_zenith=math.radians(70.0), sun_azimuth=0.3, aerosol=None))
    case("nadir_night", cams(hfov_deg=60.0, pitch_deg=-90.0, yaw_deg=torch.tensor([10.0, 200.0]), batch_size=2),
         rs.SeaScene(wind_speed=8.0, sea_temperature=290.0, wind_direction=0.5))
    case("nadir_day", cams(hw=(16, 16), hfov_deg=60.0, pitch_deg=-90.0, yaw_deg=torch.tensor([10.0, 200.0]), batch_size=2),
         rs.SeaScene(wind_speed=8.0, sea_temperature=290.0, band=rs.MWIR, sun_zenith=torch.tensor([0.5, 1.3], dtype=f64),
                     sun_azimuth=torch.tensor([0.3, 2.5], dtype=f64)))
    case("textured", cams(hw=(40, 12), hfov_deg=8.0, altitude_m=10.0, pitch_deg=-6.0, batch_size=2),
         rs.SeaScene(wind_speed=8.0, sea_temperature=290.0, sky="midlatitude_summer", path=False, seed=[11, 12], wind_direction=0.6))
    case("textured_day", cams(hw=(40, 16), hfov_deg=10.0, altitude_m=10.0, pitch_deg=-6.0, batch_size=1),
         rs.SeaScene(wind_speed=8.0, sea_temperature=290.0, band=rs.MWIR, sun_zenith=math.radians(65.0), sun_azimuth=0.2,
                     seed=[3], wind_direction=0.6))
    sweep = rs.render(cams(hw=(40, 12), hfov_deg=8.0, altitude_m=10.0, pitch_deg=-3.0, batch_size=1),
                      rs.SeaScene(wind_speed=10.0, sea_temperature=290.0, sky="midlatitude_summer", path=False, seed=[5],
                                  wind_direction=0.6), table=rs.TableSize(texture_hit="first"))
    if save:
        torch.save(sweep, sweep_ref)
    out["sweep_vs_unmutated"] = float(((sweep - torch.load(sweep_ref)) / torch.load(sweep_ref)).abs().max())
    return out


def run(copy: Path, sweep_ref: Path, save: bool = False) -> dict[str, float] | str:
    env = dict(os.environ, PYTHONPATH=str(copy), OMP_NUM_THREADS="1")
    code = f"import sys, json; sys.path.insert(0, {str(Path(__file__).parent)!r}); import mutation_accuracy as A; " \
           f"print(json.dumps(A.measure(__import__('pathlib').Path({str(sweep_ref)!r}), {save})))"
    r = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, cwd=tempfile.gettempdir(), check=False)
    return json.loads(r.stdout.strip().splitlines()[-1]) if r.returncode == 0 else "error: " + r.stderr.strip().splitlines()[-1]


def main() -> int:
    with tempfile.TemporaryDirectory(prefix="roughsea_mutacc_") as tmp:
        copy, ref = Path(tmp), Path(tmp) / "sweep_ref.pt"
        shutil.copytree(ROOT / M.PKG, copy / M.PKG)
        base = run(copy, ref, save=True)
        print("unmutated", json.dumps(base), flush=True)
        for arg in sys.argv[1:]:
            mod, rx = arg.split(None, 1)
            muts, srcs = M.mutants_of(mod, 10**9, 0, ROOT)
            rel, orig = M.module_path(mod), (ROOT / M.module_path(mod)).read_bytes()
            for m in muts:
                diff = f"{m.function}() L{m.line} {m.original} → {m.mutated}"
                if not re.search(rx, diff):
                    continue
                (copy / rel).write_bytes(srcs[m.index])
                try:
                    res = run(copy, ref)
                finally:
                    (copy / rel).write_bytes(orig)
                if isinstance(res, dict):
                    res = {k: f"{base[k]:.2g} → {v:.2g}" for k, v in res.items() if abs(v - base[k]) > 1e-3 * max(base[k], 1e-12)} or "unchanged"
                print(mod, "|", diff, "|", res, flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

"""Accuracy of the core model at its default settings: torch against the numpy reference and
against a converged torch rule, over the core issue's range.

1. The agreement cases of ``tests/test_expectation.py`` (wind 0–40 m/s, σ² to 1e-6, θ̂ to 89.99°,
   a/b = 10, |r| = 0.9, shadowing on/off): relative error of emissivity and apparent radiance of
   the default torch rule, float64 and float32, against the independent numpy reference.
2. A dense sweep (12 view zenith angles × 5 azimuths × 19 slope laws × shadowing on/off) against
   a converged torch rule (64/64/32 nodes, width 9.5σ; it agrees with the reference to ~1e-10)
   evaluated in float64 at the same (dtype-rounded) inputs: the worst relative error per dtype.

Writes a Markdown report to stdout and ``--out``/accuracy_core.md.

Usage:
    python pipelines/accuracy_core.py [--out docs]
"""

from __future__ import annotations

import argparse
import datetime as dt
import math
import sys
from pathlib import Path

import torch
from tqdm import tqdm

import roughsea_torch as rs
import roughsea_torch.reference as ref

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
from _common import CONVERGED, sky  # noqa: E402
from conftest import M11 as M  # noqa: E402
from test_expectation import CASES, case_inputs, make_slopes  # noqa: E402


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", type=Path, default=Path("docs"))
    args = ap.parse_args()
    lines = ["| θ̂ [deg] | φ̂ [rad] | slopes | shadowing | ε̄ reference | R_a reference | rel. err. float64 | rel. err. float32 |",
             "|---:|---:|---|---|---:|---:|---:|---:|"]
    worst = {torch.float64: 0.0, torch.float32: 0.0}
    for case in tqdm(CASES, desc="reference cases"):
        th, ph, spec, sh = case_inputs(case)
        s = make_slopes(ref, spec)
        e_ref = float(ref.emissivity(th, ph, s, M, shadowing=sh))
        r_ref = float(ref.apparent_radiance(th, ph, s, M, sea_radiance=30.0, sky=sky, shadowing=sh))
        errs = []
        for dtype in (torch.float64, torch.float32):
            st = make_slopes(rs, spec)
            st = rs.SlopeStatistics.from_variances(*(torch.as_tensor(v, dtype=torch.float64).to(dtype) for v in (st.var_upwind, st.var_crosswind, st.cov)))
            e = float(rs.emissivity(torch.tensor(th, dtype=dtype), torch.tensor(ph, dtype=dtype), st, M, shadowing=sh))
            r = float(rs.apparent_radiance(torch.tensor(th, dtype=dtype), torch.tensor(ph, dtype=dtype), st, M, sea_radiance=30.0, sky=sky, shadowing=sh))
            err = max(abs(e - e_ref) / abs(e_ref), abs(r - r_ref) / abs(r_ref))
            worst[dtype] = max(worst[dtype], err)
            errs.append(err)
        lines.append(f"| {case[0]:g} | {case[1]:g} | {spec} | {sh} | {e_ref:.9f} | {r_ref:.9f} | {errs[0]:.1e} | {errs[1]:.1e} |")

    # dense sweep against a converged torch rule
    ths = torch.tensor([math.radians(t) for t in (0, 20, 45, 60, 70, 80, 85, 88, 89, 89.5, 89.9, 89.99)], dtype=torch.float64)
    phs = torch.tensor([0.0, 0.4, 1.2, math.pi / 2, 2.5], dtype=torch.float64)
    TH, PH = torch.meshgrid(ths, phs, indexing="ij")
    laws = [("cm", w, an) for w in (0, 2, 5, 10, 20, 40) for an in (False, True)]
    laws += [("iso", 1e-6), ("iso", 1e-4), ("abr", 0.3, 0.03, 0.0), ("abr", 0.2, 0.1, 0.9), ("abr", 0.05, 0.15, -0.9),
             ("abr", 0.3, 0.03, 0.9), ("abr", 0.4, 0.04, -0.9)]
    conv = CONVERGED
    sweep = {torch.float64: [0.0, 0.0], torch.float32: [0.0, 0.0]}
    for spec in tqdm(laws, desc="sweep"):
        for sh in (True, False):
            s64 = make_slopes(rs, spec)
            for dtype in (torch.float64, torch.float32):
                # compare at the inputs the dtype can hold: near 90° the float32 rounding of θ̂
                # (4e-8 rad) is itself a 2.5e-4 change of cos θ̂, which Eq. 7 divides by
                s = rs.SlopeStatistics.from_variances(*(torch.as_tensor(v, dtype=torch.float64).to(dtype) for v in (s64.var_upwind, s64.var_crosswind, s64.cov)))
                s_r = rs.SlopeStatistics.from_variances(*(t.double() for t in (s.var_upwind, s.var_crosswind, s.cov)))
                th_r, ph_r = TH.to(dtype).double(), PH.to(dtype).double()
                e0 = rs.emissivity(th_r, ph_r, s_r, M, shadowing=sh, quadrature=conv)
                r0 = rs.apparent_radiance(th_r, ph_r, s_r, M, sea_radiance=30.0, sky=sky, shadowing=sh, quadrature=conv)
                e = rs.emissivity(TH.to(dtype), PH.to(dtype), s, M, shadowing=sh).double()
                r = rs.apparent_radiance(TH.to(dtype), PH.to(dtype), s, M, sea_radiance=30.0, sky=sky, shadowing=sh).double()
                sweep[dtype][0] = max(sweep[dtype][0], float(((e - e0).abs() / e0.abs()).max()))
                sweep[dtype][1] = max(sweep[dtype][1], float(((r - r0).abs() / r0.abs()).max()))
    n = TH.numel() * len(laws) * 2
    text = (f"Core accuracy at the default quadrature ({dt.date.today().isoformat()}; command: `python pipelines/accuracy_core.py`).\n\n"
            f"Against the numpy reference, worst relative error over {len(CASES)} cases: float64 {worst[torch.float64]:.1e}, "
            f"float32 {worst[torch.float32]:.1e} (targets 1e-6 and 1e-5).\n\n" + "\n".join(lines) + "\n\n"
            f"Against a converged rule over {n} sweep points: float64 emissivity {sweep[torch.float64][0]:.1e}, "
            f"apparent radiance {sweep[torch.float64][1]:.1e}; float32 emissivity {sweep[torch.float32][0]:.1e}, "
            f"apparent radiance {sweep[torch.float32][1]:.1e}.\n")
    print(text)
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "accuracy_core.md").write_text(text)


if __name__ == "__main__":
    main()

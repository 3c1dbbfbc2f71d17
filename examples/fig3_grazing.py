"""The paper's Fig. 3: near grazing a rough sea looks colder than a smooth one.

Sea and air at one temperature (the sky at the horizon equals the sea's blackbody radiance, as in
the paper), LWIR, LOWTRAN7 midlatitude-summer sky. Plots Z = 1 − R_a/R_B (the paper's quantity)
and the brightness-temperature deficit versus view zenith angle for a flat sea and several winds
(Cox–Munk, the paper's Eq. 12). Writes ``fig3_grazing.png`` to ``--out``.

Usage:
    python examples/fig3_grazing.py [--out outputs/examples] [--sky midlatitude_summer]
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path

import matplotlib.pyplot as plt
import torch

import roughsea_torch as rs
from roughsea_torch.sky import as_sky


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", type=Path, default=Path("outputs/examples"))
    ap.add_argument("--sky", default="midlatitude_summer")
    args = ap.parse_args()
    torch.set_default_dtype(torch.float64)
    sky = as_sky(args.sky)
    rb = float(sky(torch.tensor([0.0])))  # sea temperature = air temperature: R_B = R_s(horizon)
    t_sea = float(rs.brightness_temperature(torch.tensor(rb)))
    theta = torch.linspace(60.0, 89.9, 300)
    th = torch.deg2rad(theta)
    m = rs.band_refractive_index(rs.LWIR, t_sea)
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11, 4.2))
    cases = [("flat sea", rs.SlopeStatistics(0.0, 0.0))] + [
        (f"W = {w:g} m/s (σ² = {0.003 + 5.12e-3 * w:.3f})", rs.SlopeStatistics.cox_munk(float(w))) for w in (0, 2, 5, 10, 20)
    ]
    for label, slopes in cases:
        ra = rs.apparent_radiance(th, 0.0, slopes, m, sea_radiance=rb, sky=sky)
        ax1.plot(theta, 1.0 - ra / rb, label=label)
        ax2.plot(theta, rs.brightness_temperature(ra) - t_sea, label=label)
    ax1.set_xlabel("view zenith angle θ̂ [deg]")
    ax1.set_ylabel("Z = 1 − R_a / R_B")
    ax1.set_title(f"paper's Fig. 3 quantity (LWIR, T_sea = T_air = {t_sea:.1f} K)")
    ax2.set_xlabel("view zenith angle θ̂ [deg]")
    ax2.set_ylabel("T_b − T_sea [K]")
    ax2.set_title("apparent temperature deficit")
    for ax in (ax1, ax2):
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7)
    fig.tight_layout()
    args.out.mkdir(parents=True, exist_ok=True)
    fig.savefig(args.out / "fig3_grazing.png", dpi=110)
    print(f"wrote {args.out}/fig3_grazing.png (R_B = {rb:.3f} W m-2 sr-1, {math.degrees(0):.0f})")


if __name__ == "__main__":
    main()

"""The paper's Fig. 3: near grazing a rough sea looks colder than a smooth one.

Sea and air at one temperature (the sky at the horizon equals the sea's blackbody radiance, as in
the paper), for every shipped LOWTRAN7 atmosphere and the LWIR and MWIR bands (the paper's case is
midlatitude summer, LWIR). Plots Z = 1 − R_a/R_B (the paper's quantity) and the
brightness-temperature deficit versus view zenith angle for a flat sea and several winds (Cox–Munk,
the paper's Eq. 12). Writes ``fig3_<atmosphere>_<band>.png`` to ``--out``.

Usage:
    python examples/fig3_grazing.py [--out outputs/examples] [--atmospheres midlatitude_summer ...] [--bands LWIR MWIR]

(by default every shipped atmosphere and both bands: twelve pictures)
"""

from __future__ import annotations

import argparse
from pathlib import Path

import matplotlib.pyplot as plt
import torch

import roughsea_torch as rs
import roughsea_torch.atmosphere  # noqa: F401  (rs.atmosphere)


def plot_one(atmosphere: str, band_name: str, band: tuple[float, float], out: Path) -> Path:
    sky = rs.atmosphere.load_sky(atmosphere, band, dtype=torch.float64)
    rb = float(sky(torch.tensor([0.0])))  # sea temperature = air temperature: R_B = R_s(horizon)
    t_sea = float(rs.brightness_temperature(torch.tensor(rb), band))
    theta = torch.linspace(60.0, 89.9, 300)
    th = torch.deg2rad(theta)
    m = rs.band_refractive_index(band, t_sea)
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11, 4.2))
    cases = [("flat sea", rs.SlopeStatistics(0.0, 0.0))] + [
        (f"W = {w:g} m/s (σ² = {0.003 + 5.12e-3 * w:.3f})", rs.SlopeStatistics.cox_munk(float(w))) for w in (0, 2, 5, 10, 20)
    ]
    for label, slopes in cases:
        ra = rs.apparent_radiance(th, 0.0, slopes, m, sea_radiance=rb, sky=sky)
        ax1.plot(theta, 1.0 - ra / rb, label=label)
        ax2.plot(theta, rs.brightness_temperature(ra, band) - t_sea, label=label)
    ax1.set_xlabel("view zenith angle θ̂ [deg]")
    ax1.set_ylabel("Z = 1 − R_a / R_B")
    ax1.set_title(f"{atmosphere}, {band_name}: Z (paper's Fig. 3), T_sea = T_air(horizon) = {t_sea:.1f} K", fontsize=9)
    ax2.set_xlabel("view zenith angle θ̂ [deg]")
    ax2.set_ylabel("T_b − T_sea [K]")
    ax2.set_title("apparent temperature deficit", fontsize=9)
    for ax in (ax1, ax2):
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7)
    fig.tight_layout()
    out.mkdir(parents=True, exist_ok=True)
    path = out / f"fig3_{atmosphere}_{band_name}.png"
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", type=Path, default=Path(__file__).resolve().parents[1] / "outputs" / "examples")
    ap.add_argument("--atmospheres", nargs="+", default=None, help="default: every shipped atmosphere")
    ap.add_argument("--bands", nargs="+", default=["LWIR", "MWIR"], choices=["LWIR", "MWIR"])
    args = ap.parse_args()
    torch.set_default_dtype(torch.float64)
    names = args.atmospheres or rs.atmosphere.available_atmospheres()
    for name in names:
        for b in args.bands:
            print("wrote", plot_one(name, b, rs.LWIR if b == "LWIR" else rs.MWIR, args.out))


if __name__ == "__main__":
    main()

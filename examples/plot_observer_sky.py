"""Plot the LWIR sky seen by a sensor at 2 m, 20 m, 200 m, 2 km and 5 km (LOWTRAN7 tables).

Left: brightness temperature of the sky against the elevation angle of the ray, from the depressed
horizon (−dip) to +10°; each curve ends at its horizon with a marker: the sea's horizon value
L_path(h, r_hor) + τ·sky₀(90°) that the renderer gives the horizon row (the sky must meet it). The
dotted line is the sea-level sky (``load_sky``), which the images used for every altitude before.
Right: the same from 0° to 90°.

Writes ``observer_sky_<atmosphere>_lwir.png`` to ``--out`` (default ``outputs/examples/``).

Usage: python examples/plot_observer_sky.py [--atmosphere midlatitude_summer] [--out DIR]
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import torch  # noqa: E402

from roughsea_torch import atmosphere as atm  # noqa: E402
from roughsea_torch.radiometry import brightness_temperature  # noqa: E402

BAND = (8e-6, 12e-6)
ALTITUDES = [2.0, 20.0, 200.0, 2000.0, 5000.0]
COLORS = ["tab:blue", "tab:orange", "tab:green", "tab:red", "tab:purple"]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--atmosphere", default="midlatitude_summer", choices=list(atm.ATMOSPHERES))
    ap.add_argument("--out", type=Path, default=Path(__file__).resolve().parents[1] / "outputs" / "examples")
    args = ap.parse_args()
    f64 = torch.float64
    sky = atm.load_observer_sky(args.atmosphere, BAND, dtype=f64)
    sea_sky = atm.load_sky(args.atmosphere, BAND, dtype=f64)
    path = atm.load_path(args.atmosphere, BAND, dtype=f64)
    bt = lambda L: brightness_temperature(L, BAND).numpy()  # noqa: E731

    fig, (ax0, ax1) = plt.subplots(1, 2, figsize=(13, 5.2), gridspec_kw={"width_ratios": [1.4, 1]})
    for h, col in zip(ALTITUDES, COLORS):
        ht = torch.tensor(h, dtype=f64)
        sd = float(sky.sin_dip(ht))
        dip = math.degrees(math.asin(sd))
        # elevation from -dip to +10°, dense near the horizon
        e = np.unique(np.r_[-dip * (1 - np.geomspace(1e-4, 1, 300)), -dip, np.linspace(-dip, 10.0, 600)])
        c = torch.sin(torch.deg2rad(torch.as_tensor(e)))
        c = torch.clamp(c, min=-sd)
        ax0.plot(e, bt(sky(ht, c)), color=col, label=f"{h:g} m (dip {dip:.3f}°)")
        tau, lp = path(ht, atm.horizon_range(ht))
        hor = lp + tau * sea_sky(torch.zeros((), dtype=f64))
        ax0.plot([-dip], bt(hor.reshape(1)), "o", color=col, mfc="none", ms=8)
        e2 = np.linspace(0.0, 90.0, 901)
        c2 = torch.sin(torch.deg2rad(torch.as_tensor(e2)))
        ax1.plot(e2, bt(sky(ht, c2)), color=col, label=f"{h:g} m")
    e = np.linspace(0.0, 10.0, 300)
    ax0.plot(e, bt(sea_sky(torch.sin(torch.deg2rad(torch.as_tensor(e))))), "k:", label="sea-level sky (load_sky)")
    e2 = np.linspace(0.0, 90.0, 901)
    ax1.plot(e2, bt(sea_sky(torch.sin(torch.deg2rad(torch.as_tensor(e2))))), "k:", label="sea-level sky")
    ax0.plot([], [], "ko", mfc="none", label="sea horizon row: L_path + τ·sky₀(90°)")
    ax0.axvline(0.0, color="0.6", lw=0.8)
    ax0.set_xscale("symlog", linthresh=0.03, linscale=0.6)
    ax0.set_xlabel("elevation of the ray [deg] (symlog; negative: below the local horizontal)")
    ax0.set_ylabel("brightness temperature, 8–12 µm [K]")
    ax0.set_title(f"{args.atmosphere}: sky seen from altitude h, near the horizon", fontsize=10)
    ax0.legend(fontsize=7)
    ax0.grid(alpha=0.3)
    ax1.set_xlabel("elevation of the ray [deg]")
    ax1.set_ylabel("brightness temperature, 8–12 µm [K]")
    ax1.set_title("0–90° (LOWTRAN7, atmosphere.load_observer_sky)")
    ax1.legend(fontsize=7)
    ax1.grid(alpha=0.3)
    fig.tight_layout()
    args.out.mkdir(parents=True, exist_ok=True)
    out = args.out / f"observer_sky_{args.atmosphere}_lwir.png"
    fig.savefig(out, dpi=110)
    print(f"wrote {out}")


if __name__ == "__main__":
    main()

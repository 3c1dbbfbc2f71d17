"""How much it matters to band-average the reflectance rather than the refractive index.

The paper averages n and k over the sensor band (weights Planck × response) and uses one
effective index; ``docs/physics.md`` §6 recommends averaging the reflectance ρ(θ; m(λ)) itself.
This job measures the difference for the LWIR (8–12 µm) and MWIR (3–5 µm) bands at 290 K, as a
function of incidence angle: flat-sea emissivity both ways and the brightness-temperature error of
a flat sea under a cold sky. Writes a table to stdout and ``--out``/band_averaging.md and a plot.

Usage:
    python pipelines/band_averaging.py [--out docs]
"""

from __future__ import annotations

import argparse
import datetime as dt
from pathlib import Path

import torch

import roughsea_torch as rs


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", type=Path, default=Path("docs"))
    ap.add_argument("--temperature", type=float, default=290.0)
    args = ap.parse_args()
    T = args.temperature
    angles = [0.0, 30.0, 60.0, 75.0, 80.0, 85.0, 88.0, 89.0]
    rows = ["| band | θ [deg] | ε, averaged ρ | ε, averaged (n, k) | difference | T_b error (sky 0.5 R_B) |", "|---|---:|---:|---:|---:|---:|"]
    curves = {}
    for name, band in (("LWIR 8–12 µm", rs.LWIR), ("MWIR 3–5 µm", rs.MWIR)):
        m_eff = rs.band_refractive_index(band, T)
        c = torch.cos(torch.deg2rad(torch.tensor(angles, dtype=torch.float64)))
        rho_band = rs.band_reflectance(c, band, T)
        rho_eff = rs.fresnel_reflectance(c, m_eff)
        rb = rs.band_radiance(torch.tensor(T, dtype=torch.float64), band)
        sky = 0.5 * rb
        t_band = rs.brightness_temperature((1 - rho_band) * rb + rho_band * sky, band)
        t_eff = rs.brightness_temperature((1 - rho_eff) * rb + rho_eff * sky, band)
        for a, rb_, re_, tb, te in zip(angles, rho_band.tolist(), rho_eff.tolist(), t_band.tolist(), t_eff.tolist()):
            rows.append(f"| {name} | {a:g} | {1 - rb_:.5f} | {1 - re_:.5f} | {re_ - rb_:+.5f} | {te - tb:+.3f} K |")
        th = torch.linspace(0, 89.5, 200, dtype=torch.float64)
        cc = torch.cos(torch.deg2rad(th))
        curves[name] = (th, 1 - rs.band_reflectance(cc, band, T), 1 - rs.fresnel_reflectance(cc, m_eff), complex(m_eff))
    text = (f"Band averaging of water's reflectance vs its refractive index, T = {T:g} K, flat response, Hale & Querry "
            f"({dt.date.today().isoformat()}; command: `python pipelines/band_averaging.py`).\n\n"
            + "\n".join(f"- {k}: effective index (n, k) = ({v[3].real:.4f}, {v[3].imag:.4f})" for k, v in curves.items())
            + "\n\n" + "\n".join(rows) + "\n")
    print(text)
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "band_averaging.md").write_text(text)
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6, 4))
    for name, (th, eb, ee, _) in curves.items():
        ax.plot(th, eb, label=f"{name}: averaged ρ")
        ax.plot(th, ee, "--", label=f"{name}: averaged (n, k)")
    ax.set_xlabel("incidence angle [deg]")
    ax.set_ylabel("flat-sea emissivity")
    ax.legend(fontsize=7)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(args.out / "band_averaging.png", dpi=110)


if __name__ == "__main__":
    main()

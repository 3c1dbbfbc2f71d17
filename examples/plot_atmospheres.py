"""Plot the shipped LOWTRAN7 atmospheres: sky radiance vs zenith angle, and the sensor–sea path.

Writes PNGs to ``--out`` (default ``outputs/atmospheres/``):

- ``sky_lwir.png``, ``sky_mwir.png``: clear-sky band radiance seen from the sea vs zenith angle for
  the six model atmospheres (right: the last 10° before the horizon), with the band blackbody of
  each atmosphere's surface air temperature at 90°;
- ``fig2_midlatitude_summer_lwir.png``: the paper's Fig. 2 (midlatitude summer, 8–12 µm), with the
  LOWTRAN table nodes;
- ``path_midlatitude_summer_lwir.png``, ``path_midlatitude_summer_mwir.png``: transmittance and path
  radiance vs range for sensor altitudes from 2 m to 5 km (each curve ends at that altitude's
  horizon);
- ``path_atmospheres_lwir.png``, ``path_atmospheres_mwir.png``: the same for a 20 m sensor in each
  atmosphere.

Usage: python examples/plot_atmospheres.py [--out outputs/atmospheres]
"""

from __future__ import annotations

import argparse
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import torch  # noqa: E402

from roughsea_torch import atmosphere as atm  # noqa: E402
from roughsea_torch.radiometry import band_radiance  # noqa: E402

BANDS = {"lwir": ((8e-6, 12e-6), "LWIR 8–12 µm"), "mwir": ((3e-6, 5e-6), "MWIR 3–5 µm")}
LABELS = {
    "tropical": "tropical",
    "midlatitude_summer": "midlatitude summer",
    "midlatitude_winter": "midlatitude winter",
    "subarctic_summer": "subarctic summer",
    "subarctic_winter": "subarctic winter",
    "us_standard": "US standard 1976",
}
COLORS = dict(zip(LABELS, ["tab:red", "tab:orange", "tab:blue", "tab:green", "tab:purple", "tab:gray"]))


def sky_curve(name: str, band, theta_deg: np.ndarray) -> np.ndarray:
    sky = atm.load_sky(name, band=band, dtype=torch.float64)
    return sky(torch.cos(torch.deg2rad(torch.as_tensor(theta_deg)))).numpy()


def plot_sky(band_key: str, out: Path) -> Path:
    band, label = BANDS[band_key]
    fig, (ax, az) = plt.subplots(1, 2, figsize=(11, 4.2), gridspec_kw={"width_ratios": [1.4, 1]})
    th = np.linspace(0, 90, 901)
    tz = np.linspace(80, 90, 1001)
    for name in atm.available_atmospheres():
        c = COLORS[name]
        ax.plot(th, sky_curve(name, band, th), color=c, label=LABELS[name])
        az.plot(tz, sky_curve(name, band, tz), color=c)
        bb = float(band_radiance(atm.surface_air_temperature(name), band))
        for a in (ax, az):
            a.plot([90], [bb], marker="_", markersize=14, mew=2, color=c)
    ax.set(xlabel="zenith angle [deg]", ylabel="sky radiance [W m$^{-2}$ sr$^{-1}$]", xlim=(0, 90),
           title=f"Clear-sky radiance seen from the sea, {label} (LOWTRAN7)")
    az.set(xlabel="zenith angle [deg]", xlim=(80, 90), title="last 10° (bars: blackbody at surface air T)")
    for a in (ax, az):
        a.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="upper left")
    fig.tight_layout()
    path = out / f"sky_{band_key}.png"
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path


def plot_fig2(out: Path) -> Path:
    name = "midlatitude_summer"
    band = BANDS["lwir"][0]
    spec = atm.load_spectral(name)
    fig, ax = plt.subplots(figsize=(6.4, 4.4))
    th = np.linspace(0, 90, 1801)
    ax.plot(th, sky_curve(name, band, th), color="k", lw=1.3, label="table, PCHIP in zenith angle")
    nodes = np.degrees(spec["sky_zenith_rad"])
    ax.plot(nodes, sky_curve(name, band, nodes), "o", ms=3, color="tab:red", label="LOWTRAN7 nodes")
    ts = atm.surface_air_temperature(name)
    ax.axhline(float(band_radiance(ts, band)), ls="--", color="tab:gray",
               label=f"blackbody at surface air {ts:.1f} K")
    ax.set(xlabel="zenith angle θ' [deg]", ylabel="$R_s$ [W m$^{-2}$ sr$^{-1}$]", xlim=(0, 90), ylim=(0, 40),
           title="Sky radiance, midlatitude summer, 8–12 µm (paper Fig. 2)")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="upper left")
    fig.tight_layout()
    path = out / "fig2_midlatitude_summer_lwir.png"
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path


def _ranges(h: float, n: int = 300) -> np.ndarray:
    return h * np.exp(np.linspace(0.0, 1.0, n) * np.log(atm.horizon_range(h) / h))


def plot_path(name: str, band_key: str, out: Path) -> Path:
    band, label = BANDS[band_key]
    path = atm.load_path(name, band=band, dtype=torch.float64)
    bb = float(band_radiance(atm.surface_air_temperature(name), band))
    fig, (at, al) = plt.subplots(1, 2, figsize=(11, 4.2))
    cmap = plt.get_cmap("viridis")
    alts = [2.0, 10.0, 50.0, 200.0, 1000.0, 5000.0]
    for k, h in enumerate(alts):
        r = _ranges(h)
        tau, lp = (x.numpy() for x in path(torch.full((r.size,), h, dtype=torch.float64), torch.as_tensor(r)))
        c = cmap(k / (len(alts) - 1))
        at.plot(r / 1e3, tau, color=c, label=f"h = {h:g} m")
        al.plot(r / 1e3, lp, color=c)
    at.set(xscale="log", xlabel="range [km]", ylabel="band transmittance", ylim=(0, 1),
           title=f"Sensor–sea path, {LABELS[name]}, {label}")
    al.axhline(bb, ls="--", color="tab:gray", label="blackbody at surface air T")
    al.set(xscale="log", xlabel="range [km]", ylabel="path radiance [W m$^{-2}$ sr$^{-1}$]",
           title="path radiance (ends at each altitude's horizon)")
    for a in (at, al):
        a.grid(alpha=0.3, which="both")
    at.legend(fontsize=8)
    al.legend(fontsize=8, loc="upper left")
    fig.tight_layout()
    p = out / f"path_{name}_{band_key}.png"
    fig.savefig(p, dpi=120)
    plt.close(fig)
    return p


def plot_path_atmospheres(band_key: str, out: Path, h: float = 20.0) -> Path:
    band, label = BANDS[band_key]
    fig, (at, al) = plt.subplots(1, 2, figsize=(11, 4.2))
    r = _ranges(h)
    for name in atm.available_atmospheres():
        path = atm.load_path(name, band=band, dtype=torch.float64)
        tau, lp = (x.numpy() for x in path(torch.full((r.size,), h, dtype=torch.float64), torch.as_tensor(r)))
        at.plot(r / 1e3, tau, color=COLORS[name], label=LABELS[name])
        al.plot(r / 1e3, lp, color=COLORS[name])
    at.set(xscale="log", xlabel="range [km]", ylabel="band transmittance", ylim=(0, 1),
           title=f"Sensor at {h:g} m to the sea, {label}")
    al.set(xscale="log", xlabel="range [km]", ylabel="path radiance [W m$^{-2}$ sr$^{-1}$]",
           title=f"path radiance (horizon at {atm.horizon_range(h) / 1e3:.1f} km)")
    for a in (at, al):
        a.grid(alpha=0.3, which="both")
    at.legend(fontsize=8)
    fig.tight_layout()
    p = out / f"path_atmospheres_{band_key}.png"
    fig.savefig(p, dpi=120)
    plt.close(fig)
    return p


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", type=Path, default=Path(__file__).resolve().parents[1] / "outputs" / "atmospheres",
                    help="folder for the PNGs")
    args = ap.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    written = [plot_sky(b, args.out) for b in BANDS] + [plot_fig2(args.out)]
    written += [plot_path("midlatitude_summer", b, args.out) for b in BANDS]
    written += [plot_path_atmospheres(b, args.out) for b in BANDS]
    for p in written:
        print(f"wrote {p}")


if __name__ == "__main__":
    main()

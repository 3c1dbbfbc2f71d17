"""Foam − water brightness temperature against view angle and wind, LWIR and MWIR: writes
docs/foam_table.md.

At the surface (no path), sea 290 K, under the shipped LOWTRAN midlatitude-summer sky of each band:
the rough sea's apparent radiance (Eq. 10, anisotropic Cox–Munk slopes, looking upwind, with
shadowing) against a patch all foam (roughsea_torch.foam: ε_f R_B + (1 − ε_f) S), both as brightness
temperatures. Beside them, the numbers the foam rests on (ε_f − ε_w against Niclòs et al. 2007 and
Branch et al. 2016), the active (bulk temperature, the skin disrupted) and residual states'
rows, and the same rows of the previous model (Niclòs's excess continued linearly to
0.08 at 85°, Lambertian reflection of E_sky/π), and of the two changes apart; and the sky that a
surface of Fresnel facets with bubble-cap slopes reflects (Eq. 10 itself), beside the foam's S.

    PYTHONPATH=. python pipelines/foam_table.py [--out docs]
"""

from __future__ import annotations

import argparse
import math
import os
import sys

import numpy as np
import torch

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import roughsea_torch as rs  # noqa: E402
from roughsea_torch import foam  # noqa: E402
from roughsea_torch.atmosphere import load_sky  # noqa: E402
from roughsea_torch.optics import fresnel_emissivity  # noqa: E402
from roughsea_torch.radiometry import LWIR, MWIR, band_radiance, brightness_temperature  # noqa: E402
from roughsea_torch.whitecaps import SKIN_DEFICIT_K  # noqa: E402

from _report import write_report  # noqa: E402

SEA_K = 290.0
ANGLES = (60.0, 65.0, 70.0, 75.0, 80.0, 85.0, 87.0, 88.0, 89.0)
WINDS = (5.0, 10.0, 15.0, 20.0, 25.0)
BANDS = (("LWIR 8–12 µm", LWIR, 1.218 + 0.0508j), ("MWIR 3–5 µm", MWIR, 1.351 + 0.0046j))
D = torch.float64


def old_emissivity(th: torch.Tensor, m: complex) -> torch.Tensor:
    """The previous model: ε_w + Δ, Δ linear in θ through (0, 0), (45, 0), (65, 0.04), (90, 0.09)."""
    delta = np.interp(np.degrees(th.numpy()), [0.0, 45.0, 65.0, 90.0], [0.0, 0.0, 0.04, 0.09])
    return torch.clamp(fresnel_emissivity(torch.cos(th), m) + torch.as_tensor(delta, dtype=D), max=1.0)


def facet_sky(sky, band, m, th: torch.Tensor, var: float) -> torch.Tensor:
    """The sky radiance a surface of Fresnel facets (isotropic slope variance ``var`` per axis, shadowed)
    reflects, T_s / T_ρ of Eq. 10 (R_a = R_B (1 − T_ρ) + T_s, from two skies)."""
    sl = rs.SlopeStatistics.from_variances(*(torch.tensor([v], dtype=D) for v in (var, var, 0.0)))
    rb = band_radiance(torch.tensor(SEA_K, dtype=D), band)
    r0 = rs.apparent_radiance(th[:, None], 0.0, sl, refractive_index=m, sea_radiance=rb, sky=0.0)[:, 0]
    r1 = rs.apparent_radiance(th[:, None], 0.0, sl, refractive_index=m, sea_radiance=rb, sky=sky)[:, 0]
    return (r1 - r0) / (1.0 - r0 / rb)


def band_rows(name: str, band, m: complex) -> tuple[list[str], dict]:
    sky = load_sky("midlatitude_summer", band=band)
    bt = lambda r: brightness_temperature(r, band)  # noqa: E731
    rb = band_radiance(torch.tensor(SEA_K, dtype=D), band)
    th = torch.deg2rad(torch.tensor(ANGLES, dtype=D))
    eps_w = fresnel_emissivity(torch.cos(th), m)
    eps_new, eps_old = foam.foam_emissivity(th, band), old_emissivity(th, m)
    s_new = foam.foam_sky_radiance(sky, band, dtype=D)
    s_lam = foam.foam_sky_radiance(sky, band, reflection="lambertian", dtype=D)
    new = bt(eps_new * rb + (1 - eps_new) * s_new)
    old = bt(eps_old * rb + (1 - eps_old) * s_lam)
    delta_only = bt(eps_new * rb + (1 - eps_new) * s_lam)
    lines = [f"### {name}", "",
             f"Reflected sky S: {float(bt(s_new)):.1f} K (reciprocal, new) against {float(bt(s_lam)):.1f} K "
             f"(E_sky/π, Lambertian, old); the sky at the horizon mirror of 85° is "
             f"{float(bt(sky(torch.tensor(math.cos(math.radians(85.0)), dtype=D)))):.1f} K.", "",
             "| θ̂ [°] | ε_w flat | ε_f − ε_w new | old | measured | " + " | ".join(f"{u:g} m/s: water; foam − water new (old) [Δ only]" for u in WINDS) + " |",
             "|---|---|---|---|---|" + "---|" * len(WINDS)]
    measured = {65.0: "+0.04 (Niclòs 2007, 8–14 µm)", 85.0: "max 0.23 (Branch 2016, 8.9 µm)"}
    key = {}
    water = {}
    for u in WINDS:
        slopes = rs.SlopeStatistics.cox_munk(torch.tensor([u], dtype=D), anisotropic=True)
        water[u] = bt(rs.apparent_radiance(th[:, None], 0.0, slopes, refractive_index=m, sea_radiance=rb, sky=sky)[:, 0])
    for j, a in enumerate(ANGLES):
        cells = []
        for u in WINDS:
            w = water[u][j]
            cells.append(f"{float(w):.1f}; **{float(new[j] - w):+.1f}** ({float(old[j] - w):+.1f}) [{float(delta_only[j] - w):+.1f}]")
            key[(u, a)] = (float(new[j] - w), float(old[j] - w))
        lines.append(f"| {a:g} | {float(eps_w[j]):.3f} | {float(eps_new[j] - eps_w[j]):.3f} | "
                     f"{float(eps_old[j] - eps_w[j]):.3f} | {measured.get(a, '')} | " + " | ".join(cells) + " |")
    # the two states (roughsea_torch.whitecaps.foam_state_radiances): active foam at the bulk temperature
    rb_bulk = band_radiance(torch.tensor(SEA_K + SKIN_DEFICIT_K, dtype=D), band)
    active = bt(eps_new * rb_bulk + (1 - eps_new) * s_new)
    lines += ["", f"Active whitecaps (bulk temperature {SEA_K + SKIN_DEFICIT_K:g} K, the skin deficit of {SKIN_DEFICIT_K:g} K "
              "disrupted) and residual foam (the skin's {SEA_K:g} K), minus water [K]:".replace("{SEA_K:g}", f"{SEA_K:g}"), "",
              "| θ̂ [°] | ε_f | active − residual | " + " | ".join(f"{u:g} m/s: active; residual" for u in WINDS) + " |",
              "|---|---|---|" + "---|" * len(WINDS)]
    for j, a in enumerate(ANGLES):
        lines.append(f"| {a:g} | {float(eps_new[j]):.3f} | {float(active[j] - new[j]):+.2f} | " + " | ".join(
            f"{float(active[j] - water[u][j]):+.1f}; {float(new[j] - water[u][j]):+.1f}" for u in WINDS) + " |")
    lines += ["", "Foam alone [K]: " + ", ".join(f"{a:g}°: {float(new[j]):.1f} (old {float(old[j]):.1f})"
                                                  for j, a in enumerate(ANGLES)), ""]
    facets = {v: bt(facet_sky(sky, band, m, th, v)) for v in (0.3, 1.0)}
    lines += ["Sky reflected by Fresnel facets of bubble-cap slope variance σ² per axis (Eq. 10, shadowed) [K]: "
              + "; ".join(f"σ² = {v:g}: " + ", ".join(f"{float(t):.1f}" for t in facets[v][[0, 4, 5, 7]])
                          for v in facets) + " (at 60°, 80°, 85°, 88°).", ""]
    return lines, key


READING = """## Reading

- **What the excess rests on.** Niclòs et al. (2007, 8–14 µm): +0.04 at 65°, nothing at 45° and
  below. Branch et al. (2016, FTIR, 3.5–5.5 and 8–14 µm, 60°–85°): foam above water at every
  wavelength above 65°, the difference growing with angle to its maximum 0.23 at 8.9 µm and 85°; both
  emissivities fall steeply above 65°, foam's less. Only these abstract numbers were reachable, not
  the spectra or the band averages. The model takes 0.23 at 85° in both bands (an upper end for an
  8–12 µm average; in the MWIR only the sign is published) and interpolates between 65° and 85°
  linearly in the water's emissivity, so that foam's emissivity falls with angle, less than water's.
- **Reflection.** Foam in the thermal infrared does not scatter in volume (water absorbs within
  tens of µm); it reflects at the bubble caps' surfaces. The model's reflection is the one that
  Kirchhoff's law and reciprocity fix from the measured ε_f alone: the sky weighted by the foam's own
  reflectance at each incidence. A surface of Fresnel facets with bubble-cap slopes (σ² 0.3–1 per
  axis) reflects nearly the same sky (last line of each band), not the warm horizon a mirror would.
- **Sign.** With both changes foam stays slightly darker than the rough sea beyond ~75° (LWIR):
  −0.9 K at 80°, −2.7 K at 85°, −6.6 K at 88° at 15 m/s, against −5.2, −12.3 and −20.5 K before; in the
  MWIR within −2 K to 88°. The rough water's own emissivity near grazing is far above flat water's
  (its facets tilt towards the camera), while foam sits in the mean plane here: foam on the same
  tilted facets would read warmer still (not modelled). Darker residual foam is what airborne
  infrared imagery shows (Marmorino & Smith 2005).
- **Active and residual.** Marmorino & Smith (2005, airborne infrared) see actively breaking
  whitecaps bright and residual ones dark against the water, and attribute it to "changes in both
  emissivity and physical temperature" (their abstract; no numbers were reachable). The model keeps
  the part with a published size: breaking mixes away the cool skin, a few tenths of a kelvin below
  the bulk (Jessup, Zappa & Yeh 1997), so active foam radiates at T + 0.2 K and residual foam (its
  skin recovered within seconds) at T. Both keep the measured ε_f: no measurement of thick active
  against thin residual foam emissivity was found, so none is assumed. Active minus residual is then
  ε_f (B(T + 0.2 K) − B(T)): about +0.2 K at 60° and less towards grazing in radiance, and active foam
  is brighter than the water up to about 75° in both bands and darker beyond (the reflected sky dominates).
- The 0.23 is a spectral maximum: the [Δ only] column and the old model's column bracket what a
  smaller band-averaged excess would give.
"""


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", default="docs")
    args = ap.parse_args()
    torch.set_num_threads(1)
    head = [
        "# Foam − water near grazing (written by `pipelines/foam_table.py`)", "",
        f"At the surface (no path), sea {SEA_K:g} K, the shipped LOWTRAN midlatitude-summer sky of each band.",
        "Water: the rough sea's apparent radiance (Eq. 10, anisotropic Cox–Munk, looking upwind, shadowed).",
        "Foam: a patch all foam, ε_f R_B + (1 − ε_f) S (`roughsea_torch.foam`). Each cell: the water's",
        "brightness temperature [K]; **foam − water** with the new model; (the old model: Niclòs's excess",
        "continued linearly, 0.08 at 85°, and the Lambertian E_sky/π); [the new excess with the old,",
        "Lambertian reflection: the two changes apart]. ε_f − ε_w: the excess over flat water, new and old,",
        "beside the published numbers it rests on (the papers' abstracts: the only numbers reachable).", "",
    ]
    body, keys = [], {}
    for name, band, m in BANDS:
        lines, key = band_rows(name, band, m)
        body += lines
        keys[name] = key
    k = keys["LWIR 8–12 µm"]
    summary = ["## Key rows (15 m/s, LWIR)", "",
               "| θ̂ | foam − water new | old |", "|---|---|---|"]
    summary += [f"| {a:g}° | {k[(15.0, a)][0]:+.1f} K | {k[(15.0, a)][1]:+.1f} K |" for a in (80.0, 85.0, 88.0)]
    summary += [""]
    write_report(args.out, "foam_table.md", "\n".join(head + summary + body + [READING]))


if __name__ == "__main__":
    main()

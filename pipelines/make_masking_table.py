"""Write the correlated-masking table shipped in ``roughsea_torch/data/masking/masking_table.npz``.

``SeaScene(shadowing="correlated")`` weights each facet by Q(x, ν), the slope-conditioned masking of
:mod:`roughsea_torch.masking` (Bourlier, Berginc & Saillard 2002, for a Gaussian height autocorrelation),
tabulated on √(x + ν) × ln ν. Computing it takes ~10 s of integrals, which every process paid on its first
correlated render; the package now ships it. This job recomputes it with
:func:`roughsea_torch.masking.compute_masking_table` (float64) and writes the nodes and Q (about 0.1 MB),
with a provenance note. It is our own computation from the published model (no third-party data).

Usage:
    python pipelines/make_masking_table.py [--out roughsea_torch/data/masking/masking_table.npz]
"""

from __future__ import annotations

import argparse
import datetime as dt
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
from roughsea_torch import masking  # noqa: E402


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", type=Path, default=masking.TABLE_FILE)
    args = ap.parse_args()
    t0 = time.perf_counter()
    p, ln_nu, q = masking.compute_masking_table()
    args.out.parent.mkdir(parents=True, exist_ok=True)
    provenance = (f"roughsea_torch.masking.compute_masking_table, {dt.date.today().isoformat()}: Q(x, nu) of the "
                  "slope-conditioned masking (Bourlier, Berginc & Saillard, IEEE TAP 2002) on p = sqrt(x + nu) x ln nu, "
                  "float64; written by pipelines/make_masking_table.py")
    np.savez_compressed(args.out, p=p.numpy(), ln_nu=ln_nu.numpy(), q=q.numpy(), provenance=np.array(provenance))
    print(f"Q {tuple(q.shape)} in {time.perf_counter() - t0:.1f} s -> {args.out} ({args.out.stat().st_size / 1e3:.0f} kB)")


if __name__ == "__main__":
    main()

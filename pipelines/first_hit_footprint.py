"""Prototype (monkeypatch, nothing in the package changes): the first-hit sweep with its samples'
filter footprint decoupled from their spacing near grazing.

Today (``renderer/hits.py``) one number s(θ̂) = ``across`` · cos θ̂ / 2 clamped into [``min_step``,
``step``] sets both the spacing of the sweep's samples in depression and their band window, at the
footprint 2 s R δ / cos θ̂. Beyond cos θ̂ = 2 ``min_step`` / ``across`` (86.4° by default) the clamp
makes the footprint grow past ``across`` · R δ (2.1 R δ at 88°), and the sample's texture, built on the
unresolved statistics at that footprint, responds less to the resolved slope (``docs/texture_first_sigma.md``).
Here the footprint takes its own floor ``fp_min_step`` (< ``min_step``): samples stay ``min_step`` apart,
filtered at 2 max(``across`` cos θ̂ / 2, ``fp_min_step``) R δ / cos θ̂, and the texture volume's nodes
at the same footprints. The patch replaces ``sweep_layout`` as ``renderer.swept`` calls it (the sweep's
footprints recomputed from its sample distances) and ``TextureTable._scale``.

Usage (from the comparison pipeline's saved pickle; prints σ per bin and the criteria):
    python pipelines/first_hit_footprint.py PICKLE [--fp-min-step 0.0078125] [--fp-across 0.5] [--time 3]
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

import torch

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(Path(__file__).resolve().parent))
import roughsea_torch.renderer.swept as sx  # noqa: E402
import roughsea_torch.renderer.texture as tx  # noqa: E402
from roughsea_torch.clutter import footprint  # noqa: E402
from roughsea_torch.renderer import hits  # noqa: E402

ORIGINAL_LAYOUT = hits.sweep_layout
ORIGINAL_SCALE = tx.TextureTable._scale


def patch(fp_min_step: float, fp_across: float | None = None) -> None:
    """Filter the sweep's samples (and the volume's nodes) with the floor ``fp_min_step`` [px] and, if
    given, ``fp_across`` in place of ``across`` (the spacing keeps the table's settings)."""

    def fp_step(cos_view, step, min_step, across, finest=0.0, width=None):
        return hits.sample_step(cos_view, step, min(fp_min_step, min_step), fp_across or across, finest, width)

    def layout(field, image, centre, h, tan_g, phi, ifov, earth_radius_m, *, step, min_step, across, tracks, **kw):
        sw = ORIGINAL_LAYOUT(field, image, centre, h, tan_g, phi, ifov, earth_radius_m, step=step, min_step=min_step,
                             across=across, tracks=tracks, **kw)
        if sw is not None:
            hf = float(h.detach())
            rho = torch.sqrt(sw.r * sw.r + hf * hf)
            cos_v = hf / rho  # the flat sea's cos θ̂ at each sample, as sweep_layout takes it
            sw.footprint = footprint(rho, cos_v, ifov * 2.0 * fp_step(cos_v, step, min_step, across,
                                                                      kw.get("finest", 0.0), rho * ifov))
        return sw

    def scale(self, cos_view, width):
        return 2.0 * fp_step(cos_view, **self.hit_steps, width=width) if self.first_hit else 1.0

    sx.sweep_layout = layout
    tx.TextureTable._scale = scale


def unpatch() -> None:
    sx.sweep_layout = ORIGINAL_LAYOUT
    tx.TextureTable._scale = ORIGINAL_SCALE


def main() -> None:
    import pickle

    import first_hit_sigma as fhs

    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("pickle")
    ap.add_argument("--fp-min-step", type=float, nargs="+", default=[1 / 64, 1 / 128])
    ap.add_argument("--fp-across", type=float, default=None, help="the footprint's across (default: the table's)")
    ap.add_argument("--time", type=int, default=0, metavar="REPEATS", help="also time one 256×320 render each")
    args = ap.parse_args()
    torch.set_num_threads(1)
    with open(args.pickle, "rb") as fh:
        saved = pickle.load(fh)
    results = {"default": fhs.run(saved, {})}
    for f in args.fp_min_step:
        name = f"footprint floor 1/{1 / f:g}" + (f", across {args.fp_across:g}" if args.fp_across else "")
        patch(f, args.fp_across)
        results[name] = fhs.run(saved, {})
        if args.time:
            fhs.SETTINGS[name] = {}
            print(fhs.time_settings([name], args.time), file=sys.stderr)
        ident = fhs.identities({})
        print(f"{name}: identities {ident}", file=sys.stderr)
        unpatch()
    names = list(results)
    print("| case | view zenith [°] | " + " | ".join(names) + " |")
    print("|---|---|" + "---:|" * len(names))
    for i, b in enumerate(results["default"]["bins"]):
        print(f"| {b['case']} | {b['vz'][0]:.1f}–{b['vz'][1]:.1f} | "
              + " | ".join(fhs.tvr.fmt(results[n]["bins"][i]["ratio"]) for n in names) + " |")
    print("\n| setting | σ in 0.85–1.2 | 4×4 r ≥ 0.8 | ℓ within 30 % | σ over seeds | mean within 0.05 K |")
    print("|---|---:|---:|---:|---:|---:|")
    for n in names:
        k = fhs.counts(results[n])
        print(f"| {n} | {k['sigma']} / {k['n']} | {k['block']} / {k['n']} | {k['length']} / {k['n']} | "
              f"{k['ens_sigma']} / {k['n_ens_sigma']} | {k['mean']} / {k['n_ens']} |")


if __name__ == "__main__":
    main()

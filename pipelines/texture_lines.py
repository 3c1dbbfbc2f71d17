"""One-pixel lines in light-wind far fields, with and without the texture's column filter.

The README's textured-winds scene (``examples/textured_sea.py``: 256 × 320 pixels over 20°, a camera
15 m up looking 8° down, LWIR, midlatitude-summer sky and path, one seed per wind, no foam), rendered
with ``TableSize(texture_antialias=False)`` and with the default filter
(``roughsea_torch.renderer.antialias``). The texture is the render minus the expectation image of the
same scene; per band of rows (20–60, 60–120, 120–256 from the top) the table gives the pooled
correlation of vertically adjacent pixels (about each row's mean: −1 is a pattern of one-pixel
lines) and the ratio of the texture's standard deviation, filtered over unfiltered.

Writes ``--out``/texture_lines.md.

Usage:
    python pipelines/texture_lines.py [--out docs]
"""

from __future__ import annotations

import argparse
import warnings
from pathlib import Path

import torch

import roughsea_torch as rs

WINDS = (2.0, 5.0, 10.0, 15.0)
ROWS = ((20, 60), (60, 120), (120, 256))


def row_statistics(delta: torch.Tensor) -> tuple[list[float], list[float]]:
    """Per band of rows: the pooled adjacent-row correlation and the standard deviation."""
    r = delta - delta.mean(1, keepdim=True)
    corr, sd = [], []
    for lo, hi in ROWS:
        a, b = r[lo:hi - 1], r[lo + 1:hi]
        corr.append(float((a * b).sum() / torch.sqrt((a * a).sum() * (b * b).sum())))
        sd.append(float(r[lo:hi].std()))
    return corr, sd


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default="docs")
    args = ap.parse_args()
    torch.set_num_threads(1)
    warnings.simplefilter("ignore")
    cams = rs.make_camera(256, 320, hfov_deg=20.0, altitude_m=15.0, pitch_deg=-8.0, batch_size=len(WINDS))
    kw = dict(wind_speed=torch.tensor(WINDS), sea_temperature=290.0, foam=False)
    mean = rs.render(cams, rs.SeaScene(**kw))[:, 0]
    seeded = rs.SeaScene(**kw, seed=[1, 2, 3, 4], time_s=0.0)
    raw = rs.render(cams, seeded, table=rs.TableSize(texture_antialias=False))[:, 0] - mean
    filtered = rs.render(cams, seeded)[:, 0] - mean
    fmt = lambda v: " / ".join(f"{x:.2f}" for x in v)  # noqa: E731
    lines = ["# One-pixel lines and the texture's column filter", "", "`python pipelines/texture_lines.py`", "",
             "Rows 20–60 / 60–120 / 120–256 from the top of the README's textured-winds scene; the texture is the "
             "render minus the expectation image.", "",
             "| wind | unfiltered: adjacent-row correlation | filtered | texture σ, filtered / unfiltered |",
             "|---|---|---|---|"]
    for i, w in enumerate(WINDS):
        c0, s0 = row_statistics(raw[i])
        c1, s1 = row_statistics(filtered[i])
        lines.append(f"| {w:g} m/s | {fmt(c0)} | {fmt(c1)} | {fmt([b / a for a, b in zip(s0, s1)])} |")
    report = "\n".join(lines) + "\n"
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "texture_lines.md").write_text(report)
    print(report)


if __name__ == "__main__":
    main()

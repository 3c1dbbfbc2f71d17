"""Whitecaps forming, fading and drifting: a storm clip at near range, 15, 20 and 25 m/s.

Writes ``storm_clip.png`` to ``--out``: one row per wind, one column per frame (0 to 3 s), LWIR
brightness temperature of one realization (``SeaScene(seed=...)``, whitecaps on by default: active
on the crests; with ``TableSize(foam_trails=True)``, as here, residual foam decaying over ~2 s and
drifting downwind, ``roughsea_torch.whitecaps``),
a camera 15 m above the sea looking 8° down (ranges 60 m to the horizon), midlatitude-summer sky and path;
one colour range per row (0.5–99.5 % of its frames' sea pixels). A last column shows the foam alone
at the last frame (foam minus the same frame rendered with ``foam=False``).

Usage:
    python examples/storm_clip.py [--out docs] [--height 128] [--width 160]
"""

from __future__ import annotations

import argparse
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import torch  # noqa: E402

import roughsea_torch as rs  # noqa: E402

TRAILS = rs.TableSize(foam_trails=True)  # the residual foam of the last seconds (default: the breaking now)

TIMES = (0.0, 0.5, 1.0, 1.5, 2.0, 3.0)
WINDS = (15.0, 20.0, 25.0)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", type=Path, default=Path(__file__).resolve().parents[1] / "outputs" / "examples")
    ap.add_argument("--height", type=int, default=128)
    ap.add_argument("--width", type=int, default=160)
    args = ap.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    torch.set_num_threads(1)
    cams = rs.make_camera(args.height, args.width, hfov_deg=20.0, altitude_m=15.0, pitch_deg=-8.0, batch_size=1)
    sea = rs.view_geometry(cams).is_sea[0]
    fig, axes = plt.subplots(len(WINDS), len(TIMES) + 1, figsize=(2.6 * (len(TIMES) + 1), 2.4 * len(WINDS)),
                             constrained_layout=True)
    for r, wind in enumerate(WINDS):
        frames = [rs.render(cams, rs.SeaScene(wind_speed=wind, sea_temperature=290.0, seed=11, time_s=t),
                            output="brightness_temperature", table=TRAILS)[0, 0] for t in TIMES]
        bare = rs.render(cams, rs.SeaScene(wind_speed=wind, sea_temperature=290.0, seed=11, time_s=TIMES[-1], foam=False),
                         output="brightness_temperature", table=TRAILS)[0, 0]
        v = torch.cat([f[sea] for f in frames])
        lo, hi = float(v.quantile(0.005)), float(v.quantile(0.995))
        for c, (t, f) in enumerate(zip(TIMES, frames)):
            im = axes[r, c].imshow(f.numpy(), cmap="inferno", vmin=lo, vmax=hi)
            axes[r, c].set_title(f"{wind:g} m/s, t = {t:g} s", fontsize=8)
            axes[r, c].axis("off")
        fig.colorbar(im, ax=axes[r, len(TIMES) - 1], fraction=0.046, label="K")
        d = (frames[-1] - bare).numpy()
        im = axes[r, -1].imshow(d, cmap="RdBu_r", vmin=-3.0, vmax=3.0)
        axes[r, -1].set_title(f"foam − no foam, t = {TIMES[-1]:g} s", fontsize=8)
        axes[r, -1].axis("off")
        fig.colorbar(im, ax=axes[r, -1], fraction=0.046, label="K")
    fig.suptitle("LWIR storm clip, 15 m mast, 8° down: whitecaps on crests, residual foam fading (τ 2 s) and drifting",
                 fontsize=9)
    fig.savefig(args.out / "storm_clip.png", dpi=110)
    print(f"wrote {args.out / 'storm_clip.png'}")


if __name__ == "__main__":
    main()

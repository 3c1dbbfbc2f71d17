"""Whitecaps forming, fading and drifting: a storm clip at near range, 15, 20 and 25 m/s.

Writes ``storm_clip.png`` to ``--out``: one row per wind, one column per frame (0 to 3 s), LWIR
brightness temperature of one realization (``SeaScene(seed=...)``, whitecaps on by default: active
on the crests; with ``TableSize(foam_trails=True)``, as here, residual foam decaying over ~2 s and
drifting downwind, ``roughsea_torch.whitecaps``),
a camera 15 m above the sea looking 12° down (rows from about 40 m to 210 m: near range, where a pixel's footprint,
decimetres, resolves the foam's streaks, ``roughsea_torch.foam_streaks``), midlatitude-summer sky and path;
one colour range per row (0.5–99.5 % of its frames' sea pixels). A last column shows the foam alone
at the last frame (foam minus the same frame rendered with ``foam=False``), and a last one its foam
cover per pixel (active red, residual cyan, square-root scaled; the per-pixel method's cover, without
the column filter): the foam's structure, which the temperatures show only faintly at near range,
where foam and water differ by under 1 K (``docs/foam_table.md``).

``--rows`` also prints, per wind and frame, the band of 6 rows with the most active foam: its range,
its active and residual cover and the foam's brightness change (foam − no foam), to follow a patch.

Usage:
    python examples/storm_clip.py [--out outputs/examples] [--height 192] [--width 240] [--rows]

(``--out docs`` rewrites the repository's ``docs/storm_clip.png``)
"""

from __future__ import annotations

import argparse
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import torch  # noqa: E402

import roughsea_torch as rs  # noqa: E402
from roughsea_torch.clutter import footprint  # noqa: E402
from roughsea_torch.foam import whitecap_fraction  # noqa: E402
from roughsea_torch.whitecaps import whitecap_cover  # noqa: E402

TRAILS = rs.TableSize(foam_trails=True)  # the residual foam of the last seconds (default: the breaking now)

TIMES = (0.0, 0.5, 1.0, 1.5, 2.0, 3.0)
WINDS = (15.0, 20.0, 25.0)


def cover(cams, wind: float, t: float) -> tuple[torch.Tensor, torch.Tensor]:
    """The active and residual foam cover (whitecaps.whitecap_cover, with the trails) of each pixel's
    flat-sea point and footprint, the per-pixel method's (renderer.direct) without its column filter."""
    scene = rs.SeaScene(wind_speed=wind, sea_temperature=290.0, seed=11, time_s=t)
    geom = rs.view_geometry(cams)
    sea = geom.is_sea
    wf = scene.wave_field(1, torch.float64, torch.device("cpu"))
    centres = -(cams.rotation_matrix.transpose(-1, -2) @ cams.translation_vector)[..., 0].double()
    cos_t = geom.cos_view_zenith.double().clamp_min(1e-9)
    R = torch.where(sea, geom.range_m.double(), torch.ones_like(cos_t))
    L = footprint(R, cos_t, (1.0 / cams.fx.double())[:, None, None])
    x, y = centres[:, 0, None, None] + R * geom.dx.double(), centres[:, 1, None, None] + R * geom.dy.double()
    time = torch.tensor([t], dtype=torch.float64)
    c = wf.sample(x, y, time, footprint=L, elevation=False, crest=True)["crest"]
    w = whitecap_fraction(torch.tensor([wind], dtype=torch.float64))[:, None, None]
    fa, fr = whitecap_cover(wf, x, y, time, L, c, wf.crest_variance(L), wf.crest_variance()[:, None, None], w)
    zero = torch.zeros_like(fa)
    return torch.where(sea, fa, zero)[0], torch.where(sea, fr, zero)[0]


def print_rows(cams, wind: float, frames: list[torch.Tensor]) -> None:
    """The 6-row band with the most active cover in each frame: range, active and residual cover, and the
    foam's brightness change there (the frame minus the same frame without foam)."""
    geom = rs.view_geometry(cams)
    rng = torch.where(geom.is_sea, geom.range_m, torch.nan)[0].nanmedian(dim=1).values
    print(f"{wind:g} m/s | t [s] | rows | range [m] | active | residual | foam − no foam [K]")
    for t, f in zip(TIMES, frames):
        fa, fr = cover(cams, wind, t)
        bare = rs.render(cams, rs.SeaScene(wind_speed=wind, sea_temperature=290.0, seed=11, time_s=t, foam=False),
                         output="brightness_temperature", table=TRAILS)[0, 0]
        band = torch.nan_to_num(fa.mean(1)).unfold(0, 6, 6).mean(1)
        r = 6 * int(band.argmax())
        d = (f - bare)[r:r + 6]
        print(f"  | {t:g} | {r}–{r + 5} | {float(rng[r + 5]):.0f}–{float(rng[r]):.0f} | {float(fa[r:r + 6].mean()):.2f} | "
              f"{float(fr[r:r + 6].mean()):.2f} | {float(d[d == d].mean()):+.2f}")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", type=Path, default=Path(__file__).resolve().parents[1] / "outputs" / "examples")
    ap.add_argument("--height", type=int, default=192)
    ap.add_argument("--width", type=int, default=240)
    ap.add_argument("--rows", action="store_true", help="print the most foamy 6-row band of every frame")
    args = ap.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    torch.set_num_threads(1)
    cams = rs.make_camera(args.height, args.width, hfov_deg=20.0, altitude_m=15.0, pitch_deg=-12.0, batch_size=1)
    sea = rs.view_geometry(cams).is_sea[0]
    fig, axes = plt.subplots(len(WINDS), len(TIMES) + 2, figsize=(2.6 * (len(TIMES) + 2), 2.4 * len(WINDS)),
                             constrained_layout=True)
    for r, wind in enumerate(WINDS):
        frames = [rs.render(cams, rs.SeaScene(wind_speed=wind, sea_temperature=290.0, seed=11, time_s=t),
                            output="brightness_temperature", table=TRAILS)[0, 0] for t in TIMES]
        bare = rs.render(cams, rs.SeaScene(wind_speed=wind, sea_temperature=290.0, seed=11, time_s=TIMES[-1], foam=False),
                         output="brightness_temperature", table=TRAILS)[0, 0]
        if args.rows:
            print_rows(cams, wind, frames)
        v = torch.cat([f[sea] for f in frames])
        lo, hi = float(v.quantile(0.005)), float(v.quantile(0.995))
        for c, (t, f) in enumerate(zip(TIMES, frames)):
            im = axes[r, c].imshow(f.numpy(), cmap="inferno", vmin=lo, vmax=hi)
            axes[r, c].set_title(f"{wind:g} m/s, t = {t:g} s", fontsize=8)
            axes[r, c].axis("off")
        fig.colorbar(im, ax=axes[r, len(TIMES) - 1], fraction=0.046, label="K")
        d = (frames[-1] - bare).numpy()
        im = axes[r, -2].imshow(d, cmap="RdBu_r", vmin=-3.0, vmax=3.0)
        axes[r, -2].set_title(f"foam − no foam, t = {TIMES[-1]:g} s", fontsize=8)
        axes[r, -2].axis("off")
        fig.colorbar(im, ax=axes[r, -2], fraction=0.046, label="K")
        fa, fr = cover(cams, wind, TIMES[-1])  # red: active (bright), cyan: residual (dark), per pixel
        rgb = torch.stack([fa, fr, fr], -1).clamp(0, 1) ** 0.5
        axes[r, -1].imshow(rgb.numpy())
        axes[r, -1].set_title(f"cover: active (red), residual (cyan), t = {TIMES[-1]:g} s", fontsize=7)
        axes[r, -1].axis("off")
    fig.suptitle("LWIR storm clip, 15 m mast, 12° down: whitecaps on crests, residual foam fading (τ 2 s) and drifting",
                 fontsize=9)
    fig.savefig(args.out / "storm_clip.png", dpi=110)
    print(f"wrote {args.out / 'storm_clip.png'}")


if __name__ == "__main__":
    main()

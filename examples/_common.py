"""Small plotting helpers shared by the examples (matplotlib, Agg backend: files only)."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import torch  # noqa: E402


def colour_range(images: torch.Tensor | np.ndarray, percentiles: tuple[float, float] = (0.5, 99.5)) -> tuple[float, float]:
    """A colour range (vmin, vmax) for images: the given percentiles of their finite values, so that a
    few extreme pixels (the sun's disk, a hot target) clip to the colour bar's ends instead of
    stretching it until the sea is one colour."""
    a = images.detach().double().cpu().numpy() if isinstance(images, torch.Tensor) else np.asarray(images, float)
    a = a[np.isfinite(a)]
    lo, hi = np.percentile(a, percentiles)
    return float(lo), float(hi) if hi > lo else float(lo) + 1e-6


def save_grid(images: torch.Tensor, titles: list[str], path: Path, *, label: str, cmap: str = "inferno",
              ncols: int = 4, shared_scale: bool = True, ranges: list[tuple[float, float]] | None = None,
              note: str | None = None) -> list[tuple[float, float]]:
    """Write a (B, 1, H, W) batch as a labelled image grid with colour bars; return each panel's (vmin, vmax).

    By default every panel shares one colour range, :func:`colour_range` of all the images (values
    beyond it clip to the colour bar's ends), so panels compare at a glance. ``shared_scale=False``
    gives each panel its own :func:`colour_range`; ``ranges`` sets one (vmin, vmax) per panel. A figure
    whose panels do not share one range says so in its title (``note`` says how they are grouped)."""
    imgs = images.detach().float().cpu().numpy()[:, 0]
    n = imgs.shape[0]
    auto_shared = ranges is None and shared_scale
    if ranges is None:
        ranges = [colour_range(imgs)] * n if shared_scale else [colour_range(im) for im in imgs]
    ncols = min(ncols, n)
    nrows = (n + ncols - 1) // ncols
    h, w = imgs.shape[1:]
    fig, axes = plt.subplots(nrows, ncols, figsize=(3.6 * ncols, 3.6 * nrows * h / w + 0.9), squeeze=False)
    for i, (ax, img, title) in enumerate(zip(axes.flat, imgs, titles)):
        lo, hi = ranges[i]
        im = ax.imshow(img, cmap=cmap, vmin=lo, vmax=hi)
        ax.set_title(title, fontsize=8)
        ax.set_xticks([])
        ax.set_yticks([])
        fig.colorbar(im, ax=ax, fraction=0.046, pad=0.02).set_label(label, fontsize=7)
    for ax in list(axes.flat)[n:]:
        ax.axis("off")
    if auto_shared:
        suptitle = "one colour range for every panel (0.5–99.5 % of all pixels; beyond it, the bar's ends)"
    elif len(set(ranges[:n])) == 1:
        suptitle = note or "one colour range for every panel"
    else:
        suptitle = note or "each panel has its own colour range"
    fig.suptitle(suptitle, fontsize=9)
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return list(ranges[:n])


def save_png16(image: torch.Tensor, path: Path, lo: float, hi: float) -> None:
    """One (H, W) image as a 16-bit grayscale PNG, linear from lo (0) to hi (65535)."""
    from PIL import Image

    a = ((image.detach().double().cpu().numpy() - lo) / (hi - lo)).clip(0, 1) * 65535
    path.parent.mkdir(parents=True, exist_ok=True)
    Image.fromarray(a.round().astype(np.uint16)).save(path)

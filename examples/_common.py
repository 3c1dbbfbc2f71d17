"""Small plotting helpers shared by the examples (matplotlib, Agg backend: files only)."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import torch  # noqa: E402


def save_grid(images: torch.Tensor, titles: list[str], path: Path, *, label: str, cmap: str = "inferno",
              ncols: int = 4, shared_scale: bool = False, ranges: list[tuple[float, float]] | None = None) -> None:
    """Write a (B, 1, H, W) batch as a labelled image grid with colour bars; ``ranges``: one (vmin,
    vmax) per image (values beyond are clipped to the ends of the colour bar)."""
    imgs = images.detach().float().cpu().numpy()[:, 0]
    n = imgs.shape[0]
    ncols = min(ncols, n)
    nrows = (n + ncols - 1) // ncols
    h, w = imgs.shape[1:]
    fig, axes = plt.subplots(nrows, ncols, figsize=(3.6 * ncols, 3.6 * nrows * h / w + 0.6), squeeze=False)
    vmin, vmax = (np.nanmin(imgs), np.nanmax(imgs)) if shared_scale else (None, None)
    for i, (ax, img, title) in enumerate(zip(axes.flat, imgs, titles)):
        lo, hi = ranges[i] if ranges is not None else (vmin, vmax)
        im = ax.imshow(img, cmap=cmap, vmin=lo, vmax=hi)
        ax.set_title(title, fontsize=8)
        ax.set_xticks([])
        ax.set_yticks([])
        fig.colorbar(im, ax=ax, fraction=0.046, pad=0.02).set_label(label, fontsize=7)
    for ax in list(axes.flat)[n:]:
        ax.axis("off")
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)


def save_png16(image: torch.Tensor, path: Path, lo: float, hi: float) -> None:
    """One (H, W) image as a 16-bit grayscale PNG, linear from lo (0) to hi (65535)."""
    from PIL import Image

    a = ((image.detach().double().cpu().numpy() - lo) / (hi - lo)).clip(0, 1) * 65535
    path.parent.mkdir(parents=True, exist_ok=True)
    Image.fromarray(a.round().astype(np.uint16)).save(path)

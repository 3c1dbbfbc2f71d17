"""The examples' shared plotting helpers (examples/_common.py): what a reader sees in a figure."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest
import torch

ROOT = Path(__file__).resolve().parents[1]


def test_image_grids_share_one_robust_colour_range_by_default(tmp_path):
    """A grid shares one colour range across its panels unless told otherwise, and a few extreme pixels
    (the sun's disk in MWIR) do not set it: the sea keeps its contrast (the 5° panels of sun_glint.py
    were black but for a dot)."""
    pytest.importorskip("matplotlib")
    sys.path.insert(0, str(ROOT / "examples"))
    try:
        from _common import save_grid
    finally:
        sys.path.remove(str(ROOT / "examples"))
    g = torch.Generator().manual_seed(0)
    imgs = 290.0 + torch.randn(3, 1, 32, 40, generator=g)
    imgs[0, 0, 5, 5] = 5000.0  # the sun's disk: one pixel
    ranges = save_grid(imgs, ["a", "b", "c"], tmp_path / "grid.png", label="K")
    assert len(set(ranges)) == 1  # one range for every panel
    lo, hi = ranges[0]
    assert 280.0 < lo < 290.0 < hi < 300.0  # set by the sea, not by the disk
    assert (tmp_path / "grid.png").is_file()
    own = save_grid(imgs, ["a", "b", "c"], tmp_path / "own.png", label="K", shared_scale=False)
    assert len(set(own)) == 3


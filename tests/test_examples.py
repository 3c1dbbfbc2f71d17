"""The examples' shared plotting helpers (examples/_common.py): what a reader sees in a figure."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest
import torch

import roughsea_torch as rs

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



def test_main_job_metadata_holds_what_made_each_image(tmp_path):
    """The README's main job (examples/render_default.py, run small): metadata.json holds, per image,
    the air temperature (the atmosphere's surface air, from the LOWTRAN tables), the whitecap fraction
    (Monahan's law at the image's wind) and its wave seed, and for the run the package version and
    the table settings (they were missing: a new user's finding); the sea within [−1, 3] K of that air (it was
    drawn in 285–300 K whatever the air)."""
    import json
    import subprocess

    subprocess.run([sys.executable, str(ROOT / "examples" / "render_default.py"), "--out", str(tmp_path),
                    "--batch", "2", "--height", "24", "--width", "32"], check=True, capture_output=True)
    meta = json.loads((tmp_path / "metadata.json").read_text())
    assert meta["roughsea_torch"] == rs.__version__ and "texture_antialias" in meta["table"]
    for img in meta["images"]:
        assert img["air_temperature"] == rs.atmosphere.surface_air_temperature("midlatitude_summer")
        assert -3.0 <= img["air_temperature"] - img["sea_temperature"] <= 1.0  # as over the open sea
        w = float(rs.foam.whitecap_fraction(torch.tensor(img["wind_speed"], dtype=torch.float64)))
        assert abs(img["whitecap_fraction"] - w) < 1e-6 * max(w, 1e-6)
        assert isinstance(img["wave_seed"], int)

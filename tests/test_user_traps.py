"""What got in a new user's way (a fresh-clone trial): one unit per augmented batch, a README that is a
guide, figures whose panels share a colour range, the calm sea's wind gradient, errors that name the
argument and one wind range, warnings from DataLoader workers at the caller's line. Each test failed
on the code before its fix."""

from __future__ import annotations

import math
import re
import sys
import tempfile
import warnings
from pathlib import Path

import pytest
import torch

import roughsea_torch as rs
from roughsea_torch.augmentation import RandomSeaBackground, RandomSeaClip

ROOT = Path(__file__).resolve().parents[1]


# ---- one unit per batch ---------------------------------------------------------------------------


@pytest.mark.parametrize("cls", [RandomSeaBackground, RandomSeaClip])
def test_composite_mode_refuses_a_gate_that_would_mix_units(cls):
    """In composite mode an input is a target chip (kelvin and α): a chip left out by p < 1 came back
    beside sensor counts in one batch (means 305 K and ~7000 counts). p < 1 is refused there, naming
    p; replace mode keeps kornia's p (an unselected image is the input itself)."""
    with pytest.raises(ValueError, match=r"^p must be 1 with mode='composite'"):
        cls(mode="composite", p=0.5)
    assert cls(mode="composite", p=1.0).p == 1.0
    assert cls(mode="replace", p=0.5).p == 0.5


def test_replace_mode_leaves_unselected_images_as_they_came():
    aug = RandomSeaBackground(p=0.5, output="brightness_temperature", texture=False)
    x = torch.full((8, 1, 12, 16), -1.0)
    y = aug(x, generator=torch.Generator().manual_seed(3))
    kept = (y == -1.0).flatten(1).all(1)
    assert 0 < int(kept.sum()) < 8  # some images left out, some rendered
    assert bool((y[~kept] > 200.0).all())  # the rendered ones are sea temperatures


# ---- the README is a guide -------------------------------------------------------------------------


def test_readme_is_a_short_guide_whose_links_exist():
    """About 250 lines (it was 848, mostly history), no commit hashes, every relative link to a file
    of the repository."""
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    assert text.count("\n") < 300
    assert not re.findall(r"\b[0-9a-f]{7,40}\b(?=[^`]*?(?:commit|`))", text.split("## Data and licences")[0]), \
        "commit hashes belong in docs/history.md"
    for target in re.findall(r"\]\(([^)#:]+)(?:#[^)]*)?\)", text):
        assert (ROOT / target).exists(), f"README links to {target}, which does not exist"


# ---- figures --------------------------------------------------------------------------------------


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


# ---- the calm sea's wind gradient -------------------------------------------------------------------


def _bt(wind, anisotropic=True, method="direct"):
    # 11 columns: the middle one looks exactly upwind (yaw 0 looks along +x, the upwind axis)
    cams = rs.make_camera(9, 11, hfov_deg=15.0, altitude_m=20.0, pitch_deg=-3.0, dtype=torch.float64)
    return rs.render(cams, rs.SeaScene(wind_speed=wind, anisotropic=anisotropic, sea_temperature=290.0),
                     output="brightness_temperature", method=method)


def test_wind_gradient_at_a_calm_sea_warns_that_it_is_not_a_derivative():
    """At W = 0 the anisotropic law's upwind variance vanishes: along the wind axis autograd's wind
    gradient is 0 where a one-sided finite difference converges to about −4.7 K per m/s (the square
    root of the rms slope has no derivative to follow), and the table method's is ~1e3 K per m/s off
    the axis. Asking for it warns; W = 0.1, isotropic slopes and no gradient do not."""
    w = torch.tensor(0.0, dtype=torch.float64, requires_grad=True)
    with pytest.warns(UserWarning, match="is not the derivative"):
        img = _bt(w)
    auto = rs.pixel_derivative(img, w)[0, 0, 5, 5]
    zero = _bt(torch.tensor(0.0, dtype=torch.float64))
    fd = [float(((_bt(torch.tensor(h, dtype=torch.float64)) - zero) / h)[0, 0, 5, 5]) for h in (1e-5, 1e-6)]
    assert abs(fd[0] - fd[1]) < 1e-2 * abs(fd[1]) and abs(fd[1]) > 1.0  # the one-sided derivative exists
    assert math.isfinite(float(auto)) and abs(float(auto) - fd[1]) > 1.0  # autograd does not give it
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        _bt(torch.tensor(0.1, dtype=torch.float64, requires_grad=True))
        _bt(torch.tensor(0.0, dtype=torch.float64, requires_grad=True), anisotropic=False)
        _bt(torch.tensor(0.0, dtype=torch.float64))  # no gradient asked for


# ---- errors that name the argument, one wind range -----------------------------------------------------


def test_unknown_atmosphere_names_the_scene_argument():
    with pytest.raises(ValueError, match=r"^sky: unknown atmosphere 'foo'"):
        rs.SeaScene(wind_speed=5.0, sea_temperature=290.0, sky="foo")
    with pytest.raises(ValueError, match=r"^path: unknown atmosphere 'bar'"):
        rs.SeaScene(wind_speed=5.0, sea_temperature=290.0, sky=20.0, path="bar")


def test_batch_mismatch_names_the_argument():
    cams = rs.make_camera(8, 8, batch_size=2)
    with pytest.raises(ValueError, match=r"seed has batch size 3 .* the cameras have 2 images"):
        rs.render(cams, rs.SeaScene(wind_speed=5.0, sea_temperature=290.0, seed=[1, 2, 3]))
    with pytest.raises(ValueError, match=r"seed: a sequence of seeds needs one per image, B = 2; got 3"):
        rs.SeaScene(wind_speed=torch.tensor([5.0, 6.0]), sea_temperature=290.0, seed=[1, 2, 3]).batch_size
    with pytest.raises(ValueError, match=r"wind_speed has 2, sea_temperature has 3"):
        rs.SeaScene(wind_speed=torch.tensor([5.0, 6.0]), sea_temperature=torch.tensor([290.0, 291.0, 292.0])).batch_size


def test_one_wind_range_everywhere():
    """The slope law, the scene, the wave field and the augmentations' draws accept the same winds,
    [0, 80] m/s (slopes.MAX_WIND_SPEED): the augmentation refused 40–80, cox_munk accepted 500."""
    from roughsea_torch.slopes import MAX_WIND_SPEED

    assert MAX_WIND_SPEED == rs.waves.MAX_WIND == 80.0
    for make in (lambda w: rs.SlopeStatistics.cox_munk(w), lambda w: rs.SeaScene(wind_speed=w, sea_temperature=290.0),
                 lambda w: RandomSeaBackground(wind_speed=(1.0, w))):
        make(60.0)
        with pytest.raises(ValueError, match=r"wind_speed must lie in \[0, 80\]"):
            make(90.0)


# ---- warnings from DataLoader workers ----------------------------------------------------------------


def test_dataset_workers_warnings_point_at_the_callers_line():
    """A warning raised while a worker process renders a shard (here: the light wind's resolved slopes
    scaled to Cox–Munk) reaches the caller of generate at the caller's line; it pointed into
    multiprocessing, in the worker."""
    from roughsea_torch.dataset import generate

    cfg = {"num_images": 2, "shard_size": 1, "batch_size": 1, "camera": {"height": 12, "width": 16},
           "scene": {"wind_speed": [0.6, 0.8], "altitude_m": [2.0, 3.0], "pitch_deg": [-60.0, -50.0],
                     "hfov_deg": [20.0, 30.0], "daytime": 0.0}, "sensor": {}}
    with tempfile.TemporaryDirectory() as d, warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        generate(cfg, d, workers=1, progress=False)
    scaled = [w for w in caught if "scaled down" in str(w.message)]
    assert scaled and all(w.filename == __file__ for w in scaled)

"""The dataset generator's config (roughsea_torch.dataset_config): the printed default config is
complete and valid; the shipped configs resolve."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from roughsea_torch.dataset_config import resolve_config

ROOT = Path(__file__).resolve().parents[1]


def test_print_default_config_is_complete_and_valid():
    """``generate_dataset.py --print-default-config`` prints TOML, the format ``--config`` reads (it
    printed JSON, which tomllib refuses: found by a new user), equal to DEFAULT_CONFIG but for the keys
    whose default is "not set" (TOML has no null: left out, and named in a comment); it passes the
    config validation as is, and names every key the validation knows (an unknown key is rejected,
    so a config written from the printout is complete)."""
    import tomllib

    out = subprocess.run([sys.executable, str(ROOT / "pipelines" / "generate_dataset.py"), "--print-default-config"],
                         capture_output=True, text=True, timeout=120, cwd=ROOT)
    assert out.returncode == 0, out.stderr
    printed = tomllib.loads(out.stdout)
    from roughsea_torch.dataset import DEFAULT_CONFIG, resolve_config

    head = out.stdout.split("\n\n")[0]
    assert "scene.air_temperature" in head and "scene.air_sea_difference" in head  # the unset keys, named in the header
    printed_unset = {**printed, "scene": {**printed["scene"], "air_temperature": None, "air_sea_difference": None}}
    assert printed_unset == json.loads(json.dumps(DEFAULT_CONFIG))
    resolve_config(printed)
    with pytest.raises(ValueError, match="no_such_key"):
        resolve_config({**printed, "no_such_key": 1})


def test_mwir_day_config_resolves():
    import tomllib

    cfg = resolve_config(tomllib.loads((ROOT / "pipelines" / "configs" / "sea_mwir_day.toml").read_text()))
    sc = cfg["scene"]
    assert sc["band"] == "MWIR" and sc["daytime"] > 0 and sc["sun_elevation_deg"] == [3.0, 40.0]
    assert sc["sun_azimuth_deg"] == [-60.0, 60.0] and sc["sun_azimuth_relative_to_yaw"] is True


@pytest.mark.parametrize("name", ["sea_lwir", "sea_lwir_clips", "sea_mwir_day"])
def test_shipped_configs_draw_the_air_from_the_sea(name):
    """The shipped configs draw T_air − T_sea from [−3, 1] K (the usual air–sea difference over the open
    sea) instead of an independent air range: over their first 64 items every air temperature is
    within [−3, 1] K of its sea (an independent [283, 303] K air put 17 % of sea_lwir.toml's 256
    images more than 10 K from their sea), and the resolved config (config.json) records the key."""
    import tomllib

    from roughsea_torch.dataset_config import config_sampler

    raw = tomllib.loads((ROOT / "pipelines" / "configs" / f"{name}.toml").read_text())
    assert "air_temperature" not in raw["scene"] and raw["scene"]["air_sea_difference"] == [-3.0, 1.0]
    cfg = resolve_config(raw)
    assert cfg["scene"]["air_sea_difference"] == [-3.0, 1.0] and cfg["scene"]["air_temperature"] is None
    p = config_sampler(cfg).sample_indexed(cfg["seed"], range(64))
    d = p["air_temperature"] - p["sea_temperature"]
    assert float(d.min()) >= -3.0 - 1e-9 and float(d.max()) <= 1.0 + 1e-9


def test_air_temperature_and_air_sea_difference_together_are_refused():
    """Both keys in a config's scene table: a ValueError naming both, before any work; so is a
    difference that takes the sea's range above the air's 330 K."""
    with pytest.raises(ValueError, match=r"config: scene\.air_temperature and air_sea_difference"):
        resolve_config({"scene": {"air_temperature": [283.0, 303.0], "air_sea_difference": [-3.0, 1.0]}})
    with pytest.raises(ValueError, match=r"config: scene\.air_sea_difference: sea_temperature"):
        resolve_config({"scene": {"sea_temperature": [300.0, 320.0], "air_sea_difference": [-3.0, 15.0]}})

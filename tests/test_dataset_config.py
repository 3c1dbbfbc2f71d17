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

    assert "scene.air_temperature" in out.stdout.split("\n\n")[0]  # the unset key, named in the header comment
    printed_unset = {**printed, "scene": {**printed["scene"], "air_temperature": None}}
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

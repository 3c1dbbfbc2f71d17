"""The scene (roughsea_torch.renderer.scene, SeaScene): how its arguments reach the pixels (the sea
radiance of its own band, a spectral response, explicit slopes, air temperature, the sun from its
zenith, seeds), its defaults, and the checks of every argument, naming it and its range."""

from __future__ import annotations

import numpy as np
import pytest
import torch

import roughsea_torch as rs

from conftest import horizon_sky, make_cams, make_scene


def test_one_int_seed_gives_each_image_its_own_derived_seed():
    """seed=int with B > 1 images: image i is the realization of SeedSequence((seed, i)) (documented
    in SeaScene), so images differ from each other and from the neighbouring int seed's."""
    cams2 = make_cams(40, 12, hfov_deg=8.0, altitude_m=10.0, pitch_deg=-8.0, batch_size=2)
    pair = rs.render(cams2, make_scene(sky=horizon_sky, path=False, seed=5))
    assert float((pair[0] - pair[1]).abs().max()) > 1e-4
    derived = int(np.random.SeedSequence((5, 1)).generate_state(1, np.uint64)[0] >> 1)
    alone = rs.render(make_cams(40, 12, hfov_deg=8.0, altitude_m=10.0, pitch_deg=-8.0, batch_size=1),
                      make_scene(sky=horizon_sky, path=False, seed=[derived]))
    assert torch.equal(pair[1], alone[0])
    other = rs.render(cams2, make_scene(sky=horizon_sky, path=False, seed=6))
    assert float((pair[1] - other[0]).abs().max()) > 1e-4


def test_textured_scene_needs_wind_speed_and_valid_seed():
    with pytest.raises(ValueError, match="wind_speed"):
        rs.SeaScene(slopes=rs.SlopeStatistics.cox_munk(5.0), sea_temperature=290.0, seed=1)
    with pytest.raises(ValueError, match="seed"):
        make_scene(wind_speed=5.0, seed=-1)
    with pytest.raises(ValueError, match="seed"):
        make_scene(wind_speed=5.0, seed=1.5)

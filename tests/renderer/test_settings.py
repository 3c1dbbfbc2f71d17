"""The table's sizes (roughsea_torch.renderer.settings, TableSize): its texture rules accept what a
user writes, and refuse what is not a rule, naming it."""

from __future__ import annotations

import numpy as np
import pytest
import torch

import roughsea_torch as rs

from conftest import make_cams, make_scene


def test_texture_rules_accept_lists_and_numpy_numbers():
    """TableSize's texture rules: a list [20, 16] is kept as the tuple (it passed the check, then the
    render raised TypeError: unhashable type: 'list'); numpy integers and floats are numbers; a rule
    of a zero or a float is a ValueError naming it (found in review)."""
    t = rs.TableSize(texture_quadrature=[20, 16], texture_quadrature_steep=(np.int64(16), 16),
                     texture_quadrature_width=np.float32(4.5))
    assert t.texture_quadrature == (20, 16) and t.texture_quadrature_steep == (16, 16)
    cams = make_cams(8, 10, batch_size=1, altitude_m=15.0, dtype=torch.float32)
    assert torch.isfinite(rs.render(cams, make_scene(seed=1), table=t)).all()
    for bad in (dict(texture_quadrature=(0, 16)), dict(texture_quadrature=(2.5, 16)), dict(texture_quadrature_width=0.5)):
        with pytest.raises(ValueError, match=f"TableSize.{next(iter(bad))}"):
            rs.TableSize(**bad)


@pytest.mark.parametrize("bad", [dict(texture_hit="sideways"), dict(texture_first=1), dict(texture_hit_visibility=0.0),
                                 dict(texture_hit_visibility=1.5), dict(texture_hit_visibility=float("nan")),
                                 dict(texture_hit_lean=1), dict(texture_hit_lean="yes"), dict(texture_hit_lean=True),
                                 dict(texture_hit_lean_across=0.0),
                                 dict(texture_hit_lean_across=5.0), dict(texture_hit_foam_tilt=1),
                                 dict(texture_hit_foam_tilt="no")])
def test_first_hit_settings_out_of_range_name_themselves(bad):
    """The first hit's settings: where a pixel meets the waves ('first' or 'flat'), its texture nodes (≥ 2),
    its visibility factor (in [0.125, 1]), the patch moments' switch (a bool, and only with texture_hit='first':
    with the flat point it would be ignored), their patch width (in [0.05, 4] R δ) and the foam's tilt switch
    (a bool): anything else is a
    ValueError naming the field."""
    with pytest.raises(ValueError, match=f"TableSize.{next(iter(bad))}"):
        rs.TableSize(**bad)

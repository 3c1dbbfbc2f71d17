"""Whitecaps in renders (roughsea_torch.renderer.foam_terms): foam keeps the second law, vanishes
without wind and changes a storm's image; on a textured sea it sits on the crests, and the table
matches the per-pixel evaluation. (The foam's physics: tests/test_foam.py.)"""

from __future__ import annotations

import torch

import roughsea_torch as rs

from conftest import make_cams


def test_foam_keeps_the_second_law_and_vanishes_without_wind():
    """A sky at the sea's blackbody radiance: foam (whatever its emissivity) changes nothing; no wind,
    no foam: the default 'auto' equals foam=False bit for bit; a storm's foam changes the image."""
    rb = 30.0
    cams = make_cams(hfov_deg=20.0, pitch_deg=-4.0, batch_size=1)
    storm = rs.render(cams, rs.SeaScene(wind_speed=25.0, sea_radiance=rb, sky=rb, path=False))
    assert torch.allclose(storm[0, 0][rs.view_geometry(cams).is_sea[0]], torch.tensor(rb, dtype=torch.float64), rtol=1e-12, atol=0)
    calm = dict(wind_speed=0.0, sea_temperature=290.0)
    assert torch.equal(rs.render(cams, rs.SeaScene(**calm)), rs.render(cams, rs.SeaScene(**calm, foam=False)))
    windy = dict(wind_speed=20.0, sea_temperature=290.0)
    with_foam = rs.render(cams, rs.SeaScene(**windy), output="brightness_temperature")
    without = rs.render(cams, rs.SeaScene(**windy, foam=False), output="brightness_temperature")
    assert float((with_foam - without).abs().max()) > 0.1  # kelvin: 7 % whitecaps at 20 m/s


def test_textured_foam_sits_on_crests_keeps_the_second_law_and_matches_per_pixel_evaluation():
    """A textured storm sea puts its whitecaps on crests (foam.crest_foam_fraction), not as a uniform
    veil: the foam's change to the image concentrates in few pixels (the tenth of the sea pixels it
    changes most carry over half of the change; a uniform fraction W, as in the expectation, spreads
    it over all and gives 0.29 here). The table equals the per-pixel evaluation to 1 % of the
    texture's amplitude, and a sky at the sea's blackbody radiance leaves every pixel at R_B."""
    cams = make_cams(48, 64, pitch_deg=-8.0, batch_size=2)
    g = rs.view_geometry(cams)
    sea = g.is_sea[:, None]
    kw = dict(wind_speed=torch.tensor([14.0, 20.0]), sea_temperature=290.0, sky=lambda c: 12.0 + 18.0 * (1 - c) ** 6,
              path=False, seed=[3, 4])
    foamy = rs.render(cams, rs.SeaScene(**kw))
    bare = rs.render(cams, rs.SeaScene(**kw, foam=False))
    for i in range(2):
        d = (foamy - bare)[i][sea[i]].abs()
        top = d.sort(descending=True).values[: d.numel() // 10]
        assert float(top.sum() / d.sum()) > 0.5
    direct = rs.render(cams, rs.SeaScene(**kw), method="direct", geometry=g)
    amplitude = float((foamy - rs.render(cams, rs.SeaScene(**dict(kw, seed=None)))).abs().max())
    assert float((foamy - direct).abs()[sea].max()) < 0.015 * amplitude
    rb = 27.5
    img = rs.render(cams, rs.SeaScene(wind_speed=20.0, sea_radiance=rb, sky=rb, path=False, seed=[5, 6]))
    torch.testing.assert_close(img[sea], torch.full_like(img[sea], rb), rtol=1e-12, atol=0.0)

"""The forms a ``sky`` argument may take (roughsea_torch.atmosphere.as_sky): the name of a LOWTRAN7
atmosphere, a callable of cos(zenith), a (zenith, radiance) table, a TabulatedSky, a constant, a
table or a constant per batch element. (The LOWTRAN7 tables themselves: tests/test_lowtran.py and
tests/test_observer_sky.py.)"""

from __future__ import annotations

import math

import torch

import roughsea_torch as rs
from roughsea_torch import atmosphere as atm
from roughsea_torch.atmosphere import as_sky

from conftest import M10, smooth_sky


MLS = "midlatitude_summer"


def test_named_sky_through_the_core_sky_forms():
    sky = as_sky(MLS)
    c = torch.tensor([1.0, 0.5, 0.0])
    torch.testing.assert_close(sky(c), atm.load_sky(MLS)(c))


def test_sky_forms_agree():
    """Callable, (zenith, radiance) table and TabulatedSky give the same R_a; a constant sky equals
    the callable returning that constant; a batched table equals per-element calls."""
    zen = torch.linspace(0.0, math.pi / 2, 400, dtype=torch.float64)
    rad = smooth_sky(torch.cos(zen))
    th = torch.tensor([0.4, 1.3, 1.56], dtype=torch.float64)
    s = rs.SlopeStatistics.cox_munk(9.0)
    r_call = rs.apparent_radiance(th, 0.0, s, M10, sea_radiance=30.0, sky=smooth_sky)
    r_tab = rs.apparent_radiance(th, 0.0, s, M10, sea_radiance=30.0, sky=(zen, rad))
    torch.testing.assert_close(r_tab, r_call, rtol=2e-5, atol=0)  # table of 400 nodes vs exact
    r_const = rs.apparent_radiance(th, 0.0, s, M10, sea_radiance=30.0, sky=12.0)
    r_const_fn = rs.apparent_radiance(th, 0.0, s, M10, sea_radiance=30.0, sky=lambda c: 12.0 + 0.0 * c)
    torch.testing.assert_close(r_const, r_const_fn, rtol=1e-14, atol=0)
    batched = rs.TabulatedSky(zen, torch.stack([rad, rad * 0.8, rad * 1.1]))  # one table per θ̂
    r_b = rs.apparent_radiance(th, 0.0, s, M10, sea_radiance=30.0, sky=batched)
    for i, f in enumerate((1.0, 0.8, 1.1)):
        one = rs.apparent_radiance(th[i], 0.0, s, M10, sea_radiance=30.0, sky=(zen, rad * f))
        torch.testing.assert_close(r_b[i], one, rtol=1e-13, atol=0)
    per_state = rs.apparent_radiance(th, 0.0, s, M10, sea_radiance=30.0, sky=torch.tensor([11.0, 12.0, 13.0], dtype=torch.float64))
    for i, c in enumerate((11.0, 12.0, 13.0)):
        torch.testing.assert_close(per_state[i], rs.apparent_radiance(th[i], 0.0, s, M10, sea_radiance=30.0, sky=c), rtol=1e-13, atol=0)

"""roughsea_torch.sky: the tabulated sky's interpolant at its smallest size."""

from __future__ import annotations

import torch

import roughsea_torch as rs


def test_two_node_sky_table_is_the_straight_line_between_its_nodes():
    """A table of two angles is accepted (the documented minimum) and its PCHIP interpolant is the
    straight line in zenith angle between them (as scipy's PchipInterpolator on two points); the end
    values are held beyond the table."""
    sky = rs.TabulatedSky(torch.tensor([0.2, 1.5], dtype=torch.float64), torch.tensor([10.0, 40.0], dtype=torch.float64))
    z = torch.linspace(0.2, 1.5, 14, dtype=torch.float64)
    torch.testing.assert_close(sky(torch.cos(z)), 10.0 + 30.0 * (z - 0.2) / 1.3, rtol=1e-12, atol=1e-12)
    torch.testing.assert_close(sky(torch.cos(torch.tensor([0.0, 1.56], dtype=torch.float64))),
                               torch.tensor([10.0, 40.0], dtype=torch.float64), rtol=0, atol=1e-12)

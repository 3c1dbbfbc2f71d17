"""Sky tables (roughsea_torch.sky): the monotone PCHIP interpolant of a tabulated sky, one table or
one per batch element, and its errors."""

from __future__ import annotations

import math

import numpy as np
import pytest
import torch

import roughsea_torch as rs


def test_pchip_matches_scipy():
    from scipy.interpolate import PchipInterpolator

    rng = np.random.default_rng(3)
    zen = np.sort(rng.uniform(0, math.pi / 2, 12))
    rad = np.cumsum(rng.uniform(0.0, 3.0, 12)) + np.where(np.arange(12) == 6, -2.0, 0.0)  # a dip too
    q = np.linspace(zen[0], zen[-1], 777)
    expected = PchipInterpolator(zen, rad)(q)
    got = rs.TabulatedSky(torch.tensor(zen), torch.tensor(rad))(torch.cos(torch.tensor(q))).numpy()
    np.testing.assert_allclose(got, expected, rtol=1e-10, atol=1e-10)
    # the shipped LOWTRAN nodes (0.1 deg near the horizon, coarser above), queried at the nodes,
    # between them and from a batched table (the interval lookup is a bucket grid, not a search)
    sky = rs.atmosphere.load_sky("tropical", dtype=torch.float64)
    z = sky.zenith.numpy()
    qz = np.concatenate([z, 0.5 * (z[1:] + z[:-1]), rng.uniform(z[0], z[-1], 2000)])
    want = PchipInterpolator(z, sky.radiance.numpy())(qz)
    np.testing.assert_allclose(sky(torch.cos(torch.tensor(qz))).numpy(), want, rtol=1e-9)
    two = sky.with_radiance(torch.stack([sky.radiance, 0.5 * sky.radiance]))(torch.cos(torch.tensor(np.stack([qz, qz]))))
    np.testing.assert_allclose(two.numpy(), np.stack([want, 0.5 * want]), rtol=1e-9)
    # a table per leading element broadcast over a middle dim of the query: (2, 1, N) rows, (2, 3, Q)
    # queries (row i serves every query [i, j, :]; the lookup indexes each query's own row)
    rows = torch.stack([sky.radiance, 0.5 * sky.radiance])[:, None]
    qq = np.stack([np.stack([qz, qz[::-1], qz]), np.stack([qz[::-1], qz, qz])])
    got3 = sky.with_radiance(rows)(torch.cos(torch.tensor(qq))).numpy()
    for i, f in enumerate((1.0, 0.5)):
        for j in range(3):
            np.testing.assert_allclose(got3[i, j], f * PchipInterpolator(z, sky.radiance.numpy())(qq[i, j]), rtol=1e-9)


@pytest.mark.parametrize(
    "call, match",
    [
        (lambda: rs.TabulatedSky([0.0, 0.5, 0.4], [1.0, 2.0, 3.0]), "ascending"),
    ],
)
def test_clear_errors(call, match):
    with pytest.raises(ValueError, match=match):
        call()


def test_two_node_sky_table_is_the_straight_line_between_its_nodes():
    """A table of two angles is accepted (the documented minimum) and its PCHIP interpolant is the
    straight line in zenith angle between them (as scipy's PchipInterpolator on two points); the end
    values are held beyond the table."""
    sky = rs.TabulatedSky(torch.tensor([0.2, 1.5], dtype=torch.float64), torch.tensor([10.0, 40.0], dtype=torch.float64))
    z = torch.linspace(0.2, 1.5, 14, dtype=torch.float64)
    torch.testing.assert_close(sky(torch.cos(z)), 10.0 + 30.0 * (z - 0.2) / 1.3, rtol=1e-12, atol=1e-12)
    torch.testing.assert_close(sky(torch.cos(torch.tensor([0.0, 1.56], dtype=torch.float64))),
                               torch.tensor([10.0, 40.0], dtype=torch.float64), rtol=0, atol=1e-12)

"""The sky seen by an observer at altitude h (roughsea_torch.atmosphere.load_observer_sky).

Facts checked against LOWTRAN7 values stored by pipelines/lowtran_observer_sky.py, against the
sea-level sky and path tables, and against physics (less water vapour above 5 km: a colder sky).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import torch

from roughsea_torch import atmosphere as atm
from roughsea_torch.observer_sky import observer_tables

from conftest import torch_threads

LWIR = (8e-6, 12e-6)
MWIR = (3e-6, 5e-6)
BANDS = {"lwir": LWIR, "mwir": MWIR}
F64 = torch.float64
NAMES = [n for n in atm.ATMOSPHERES if (atm.DATA_DIR / f"observer_{n}.npz").is_file()]
# Held-out interpolation errors claimed in the docstring / README (relative, band radiance):
HELD_OUT_UP = 3.5e-3  # upward rays, cells away from LOWTRAN levels (measured max 3.0e-3)
HELD_OUT_BELOW = 1e-2  # rays below the horizontal, h >= 2 m, cells away from LOWTRAN levels, plus the
#                        dip pin x * |pin| (measured max 8.6e-3, where the tangent height crosses a
#                        LOWTRAN level, from above 1 km; <= 3.2e-3 below 1 km)
HELD_OUT_FIRST_CELL = 1.5e-2  # below the horizontal, 0 < h < 2 m (below the path tables; measured 1.2e-2)
HELD_OUT_NEAR_LEVEL = 3e-2  # cells within 10 m of a LOWTRAN level (LOWTRAN's own steps)
# The table's own dip column (LOWTRAN spectra composed: L_seg + tau_seg * S, per 5 cm-1 sample)
# against the renderer's horizon value (band values composed: L_path + tau_band * sky0_band), i.e.
# the size of the pin. Subarctic winter LWIR: the band composition itself is 0.8-1.7 % off (dry
# cold air, tau over the horizon path 0.3-0.5, a very non-grey sky spectrum).
DIP_TABLE = {"subarctic_winter": 2e-2}
DIP_TABLE_DEFAULT = 4e-3

pytestmark = [pytest.mark.skipif(not NAMES, reason="no observer-sky tables"),
              pytest.mark.usefixtures("one_thread")]


def sin_dip(h):
    h = torch.as_tensor(h, dtype=F64)
    return torch.sqrt(h * (2 * atm.EARTH_RADIUS_M + h)) / (atm.EARTH_RADIUS_M + h)


@pytest.fixture(scope="module")
def skies():
    with torch_threads(1):
        return {(n, b): atm.load_observer_sky(n, band, dtype=F64) for n in NAMES for b, band in BANDS.items()}


def test_all_six_atmospheres_shipped_within_the_size_budget():
    assert NAMES == list(atm.ATMOSPHERES)
    total = sum((atm.DATA_DIR / f"observer_{n}.npz").stat().st_size for n in NAMES)
    assert total < 4.5e6


@pytest.mark.parametrize("band", list(BANDS))
def test_lowest_node_is_the_sea_level_sky(skies, band):
    c = torch.cos(torch.linspace(0.0, math.pi / 2, 2001, dtype=F64))
    for n in NAMES:
        sky = skies[n, band]
        assert sky.altitude_range_m == (0.0, 5000.0)
        sea = atm.load_sky(n, BANDS[band], dtype=F64)
        rel = (sky(torch.zeros(()), c) / sea(c) - 1).abs().max().item()
        assert rel < 2e-4, (n, band, rel)


@pytest.mark.parametrize("band", list(BANDS))
@pytest.mark.parametrize("h", [2.0, 20.0, 200.0, 2000.0])
def test_continuous_with_the_sea_horizon_at_the_dip(skies, band, h):
    for n in NAMES:
        sky = skies[n, band]
        path = atm.load_path(n, BANDS[band], dtype=F64)
        sky0 = atm.load_sky(n, BANDS[band], dtype=F64)(torch.zeros((), dtype=F64))
        hh = torch.tensor(h, dtype=F64)
        tau, lp = path(hh, atm.horizon_range(hh))
        want = lp + tau * sky0
        c = -sin_dip(hh)
        got = sky(hh, c)
        assert abs(got.item() / want.item() - 1) < 1e-9, (n, band, h)
        # the table's own dip column (LOWTRAN's spectra composed) agrees before the pin
        table = sky._below_unpinned(hh, c)
        bound = DIP_TABLE.get(n, DIP_TABLE_DEFAULT)
        assert abs(table.item() / want.item() - 1) < bound, (n, band, h, table.item(), want.item())
        # and approaching the dip from above
        near = sky(hh, c * (1 - 1e-9))
        assert abs(near.item() / want.item() - 1) < 1e-6


def test_lowtran_held_out_values(skies):
    for n in NAMES:
        t = observer_tables(n)
        for k, band in enumerate(BANDS):
            sky = skies[n, band]
            for part in ("up", "below"):
                h = torch.as_tensor(np.array(t[f"{part}_check_altitude_m"]))
                want = np.array(t[f"{part}_check_band_radiance"][k])
                if part == "up":
                    c = torch.cos(torch.as_tensor(np.array(t["up_check_zenith_rad"])))
                    bound = HELD_OUT_UP
                else:
                    x = torch.as_tensor(np.array(t["below_check_x"]))
                    c = -x * sin_dip(h)
                    pin = (sky._dip_value(h) - sky._below_table(h, torch.ones_like(h))[2]).abs().numpy()
                    bound = np.where(h.numpy() >= 2.0, HELD_OUT_BELOW, HELD_OUT_FIRST_CELL) + x.numpy() * pin / want
                near = np.array(t[f"{part}_check_near_level"])
                # LOWTRAN itself returns NaN within ~0.5 m of a level (only there)
                assert np.all(np.isfinite(want[~near])), (n, band, part)
                rel = np.abs(sky(h, c).numpy() / want - 1)
                bound = np.broadcast_to(bound, rel.shape)
                assert np.all(rel[~near] < bound[~near]), (n, band, part, rel[~near].max())
                assert np.nanmax(rel[near]) < HELD_OUT_NEAR_LEVEL, (n, band, part, np.nanmax(rel[near]))


def test_sky_from_5km_is_colder_at_every_upward_angle(skies):
    c = torch.cos(torch.linspace(0.0, math.pi / 2, 3001, dtype=F64))
    for n in NAMES:
        sky = skies[n, "lwir"]
        high, sea = sky(torch.tensor(5000.0, dtype=F64), c), sky(torch.zeros((), dtype=F64), c)
        assert bool((high < sea).all()), n
        # colder by a margin, the most at the zenith (water vapour above 5 km is a few % of the column)
        assert (high[-1] / sea[-1]).item() < 0.5


@pytest.mark.parametrize("band", list(BANDS))
def test_continuous_at_the_local_horizontal(skies, band):
    h = torch.tensor([[2.0], [20.0], [137.0], [999.0], [1000.0], [2500.0], [4990.0]], dtype=F64)
    for n in NAMES:
        sky = skies[n, band]
        at0 = sky(h, torch.zeros((), dtype=F64))
        below = sky(h, torch.tensor(-1e-12, dtype=F64))
        above = sky(h, torch.tensor(1e-12, dtype=F64))
        assert torch.allclose(below, at0, rtol=1e-6, atol=0), n
        assert torch.allclose(above, at0, rtol=1e-6, atol=0), n
        # the below-horizontal table itself (before its pin) meets the upward table there to its
        # altitude-interpolation accuracy (away from LOWTRAN's steps just below a level)
        far = torch.tensor([[2.0], [20.0], [137.0], [2500.0]], dtype=F64)
        unpinned = sky._below_unpinned(far, torch.zeros((), dtype=F64))
        assert torch.allclose(unpinned, sky(far, torch.zeros((), dtype=F64)), rtol=5e-3, atol=0), n


def test_below_the_horizontal_warmer_towards_the_dip_for_a_mast():
    # 20 m mast, midlatitude summer LWIR: the line just above the horizon crosses ~16 km of warm air
    from roughsea_torch.radiometry import brightness_temperature

    sky = atm.load_observer_sky("midlatitude_summer", LWIR, dtype=F64)
    h = torch.tensor(20.0, dtype=F64)
    c = -sin_dip(h) * torch.linspace(0, 1, 50, dtype=F64)
    t = brightness_temperature(sky(h, c), LWIR)
    assert bool((t[1:] >= t[:-1] - 1e-9).all())  # monotone: longer paths through the warm surface air
    assert 293.8 < t[-1].item() < 294.3 and 292.3 < t[0].item() < 293.0


def test_broadcast_dtypes_and_vectorized_shape():
    sky = atm.load_observer_sky("midlatitude_summer", LWIR)
    h = torch.tensor([[2.0], [20.0], [300.0], [4000.0]])
    frac = torch.linspace(-1.0, 1.0, 33)
    c = torch.where(frac < 0, frac * sin_dip(h).float(), frac)  # (4, 33)
    out32 = sky(h, c)
    out64 = sky(h.double(), c.double())
    assert out32.dtype == torch.float32 and out64.dtype == torch.float64 and out32.shape == (4, 33)
    assert torch.allclose(out32.double(), out64, rtol=2e-5)
    loop = torch.stack([sky(h[i, 0].double(), c[i].double()) for i in range(4)])
    assert torch.allclose(loop, out64, rtol=1e-12)


def test_gradients_finite_and_match_central_differences():
    sky = atm.load_observer_sky("midlatitude_summer", MWIR, dtype=F64)
    cases = [(137.0, 0.3), (20.0, 0.9), (1500.0, 0.05), (55.0, -0.45), (2500.0, -0.8), (700.0, -0.1)]
    for h0, f in cases:
        h = torch.tensor(h0, dtype=F64, requires_grad=True)
        c0 = f if f >= 0 else f * sin_dip(h0).item()
        c = torch.tensor(c0, dtype=F64, requires_grad=True)
        gh, gc = torch.autograd.grad(sky(h, c), (h, c))
        eh, ec = 1e-4 * h0, 1e-6 if f >= 0 else 1e-4 * abs(c0)
        with torch.no_grad():
            fh = (sky(h + eh, c) - sky(h - eh, c)) / (2 * eh)
            fc = (sky(h, c + ec) - sky(h, c - ec)) / (2 * ec)
        assert abs(gh.item() - fh.item()) <= 1e-3 * abs(fh.item()) + 1e-9, (h0, f, gh.item(), fh.item())
        assert abs(gc.item() - fc.item()) <= 1e-3 * abs(fc.item()) + 1e-9, (h0, f, gc.item(), fc.item())
    # exactly at cos = 0 and at the dip: finite, both dtypes
    for dt in (torch.float32, torch.float64):
        h = torch.tensor([2.0, 20.0, 2000.0, 5000.0], dtype=dt, requires_grad=True)
        for c in (torch.zeros(4, dtype=dt), -sin_dip(h.detach()).to(dt), torch.ones(4, dtype=dt)):
            c = c.clone().requires_grad_(True)
            gh, gc = torch.autograd.grad(sky(h, c).sum(), (h, c))
            assert bool(torch.isfinite(gh).all() and torch.isfinite(gc).all())


def test_out_of_range_raises_or_clamps():
    sky = atm.load_observer_sky("midlatitude_summer", LWIR, dtype=F64)
    with pytest.raises(ValueError, match="altitude_m"):
        sky(torch.tensor(6000.0), torch.tensor(0.5))
    with pytest.raises(ValueError, match="altitude_m"):
        sky(torch.tensor(-1.0), torch.tensor(0.5))
    with pytest.raises(ValueError, match="cos_zenith"):
        sky(torch.tensor(20.0), torch.tensor(1.5))
    h = torch.tensor(20.0, dtype=F64)
    with pytest.raises(ValueError, match="cos_zenith"):
        sky(h, -1.01 * sin_dip(h))  # a ray that meets the sea
    assert torch.allclose(sky(h, -1.01 * sin_dip(h), clamp=True), sky(h, -sin_dip(h)))
    assert torch.allclose(sky(torch.tensor(9000.0, dtype=F64), 0.5, clamp=True), sky(5000.0, 0.5))
    with pytest.raises(ValueError, match="name"):
        atm.load_observer_sky("venus")


def test_dip_below_the_path_tables_lies_between_sea_level_and_2_m():
    """Below the path tables' 2 m the horizon ray from h crosses less surface air than from 2 m and
    more than from the sea surface: the sky at the dip lies between sky₀(90°) and its 2 m value."""
    sky = atm.load_observer_sky("midlatitude_summer", (8e-6, 12e-6), dtype=torch.float64)
    sky0 = float(atm.load_sky("midlatitude_summer", (8e-6, 12e-6), dtype=torch.float64)(torch.tensor(0.0)))

    def dip(h):
        R = atm.EARTH_RADIUS_M
        return float(sky(torch.tensor(h, dtype=torch.float64),
                         torch.tensor(-math.sqrt(h * (2 * R + h)) / (R + h), dtype=torch.float64)))

    top = dip(2.0)
    assert top > sky0  # 2 m of horizon path is warmer than the sea-level horizon sky (LWIR summer)
    for h in (0.5, 1.0, 1.5):
        assert sky0 <= dip(h) <= top

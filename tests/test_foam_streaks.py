"""The foam's streak field ν (roughsea_torch.foam_streaks): exactly N(0, 1) at every point (mean and
variance over many points and seeds), elongated along the wind by the stated anisotropy (its
correlation at a lag of k cells along the wind equals that at k cells across, and at one lag in metres
it is higher along than across), anchored to the drifting surface; and the whitecap cover with it
keeps E[f] = W at near-range footprints where the streaks are resolved."""

import math

import pytest
import torch

import roughsea_torch.foam_streaks as fs

from roughsea_torch.foam import whitecap_fraction
from roughsea_torch.foam_streaks import (STREAK_ANISOTROPY, STREAK_LENGTH_M, cell_bound, resolved_share, streak_lengths,
                                        streak_noise)
from roughsea_torch.waves import WaveField
from roughsea_torch.whitecaps import whitecap_cover

D = torch.float64


def _nu(x, y, seeds, wind=20.0, direction=0.7):
    b = len(seeds)
    along, across = streak_lengths(torch.full((b,), wind, dtype=D))
    c, s = torch.full((b,), math.cos(direction), dtype=D), torch.full((b,), math.sin(direction), dtype=D)
    return streak_noise(x, y, seeds, c, s, along, across)


def test_streak_noise_is_standard_normal_at_every_point():
    """Over 8 seeds × 40 000 random points of a 2 km square: mean within 0.01 (the standard error is
    0.0018), variance within 0.02 of 1, and the fourth moment within 0.1 of 3 (Gaussian, not merely
    unit variance); at 64 fixed points (cell corners, centres, edges) over 4000 seeds the variance at
    each is 1 within 0.1 (the weights' squares sum to 1 whatever the point's place in its cell). Fails
    with linear weights (1 − f, f) (planted: variance 2/3 at the cell centres)."""
    g = torch.Generator().manual_seed(3)
    x = torch.rand(8, 40000, generator=g, dtype=D) * 2000 - 1000
    y = torch.rand(8, 40000, generator=g, dtype=D) * 2000 - 1000
    nu = _nu(x, y, list(range(100, 108)))
    assert abs(float(nu.mean())) < 0.01
    assert float(nu.var()) == pytest.approx(1.0, abs=0.02)
    assert float((nu ** 4).mean()) == pytest.approx(3.0, abs=0.1)
    along, across = STREAK_LENGTH_M, STREAK_LENGTH_M / STREAK_ANISOTROPY
    f = torch.linspace(0.0, 0.99, 8, dtype=D)
    u, v = torch.meshgrid(f * along, f * across, indexing="ij")  # in the wind frame, direction 0
    seeds = list(range(4000))
    nu = streak_noise(u.reshape(1, -1).expand(4000, -1), v.reshape(1, -1).expand(4000, -1), seeds,
                      torch.ones(4000, dtype=D), torch.zeros(4000, dtype=D), torch.full((4000,), along, dtype=D),
                      torch.full((4000,), across, dtype=D))
    torch.testing.assert_close(nu.var(0), torch.ones(64, dtype=D), rtol=0, atol=0.1)


def test_streaks_are_elongated_along_the_wind():
    """At 20 m/s the cell is 2 m along the wind and 0.4 m across: the correlation at a lag of 0.3 cell
    along equals the one at 0.3 cell across (within 0.03, the sampling error), and at the same 0.3 m lag
    in metres it is much higher along (ν is a function of position over the cell: the correlation
    lengths' ratio is the anisotropy, 5); at 6 m/s the field is isotropic (equal correlations at equal
    metres). Fails with the lengths swapped (planted: along < across)."""
    g = torch.Generator().manual_seed(5)
    x = torch.rand(4, 30000, generator=g, dtype=D) * 3000
    y = torch.rand(4, 30000, generator=g, dtype=D) * 3000
    direction = 0.7
    ex, ey = math.cos(direction), math.sin(direction)
    seeds = [1, 2, 3, 4]

    def corr(dx, dy, wind):
        a, b = _nu(x, y, seeds, wind, direction), _nu(x + dx, y + dy, seeds, wind, direction)
        return float(((a - a.mean()) * (b - b.mean())).mean() / (a.std() * b.std()))

    along, across = (float(t) for t in streak_lengths(torch.tensor(20.0, dtype=D)))
    assert along / across == pytest.approx(STREAK_ANISOTROPY)
    c_al = corr(0.3 * along * ex, 0.3 * along * ey, 20.0)
    c_ac = corr(-0.3 * across * ey, 0.3 * across * ex, 20.0)
    assert c_al == pytest.approx(c_ac, abs=0.03)
    m_al, m_ac = corr(0.3 * ex, 0.3 * ey, 20.0), corr(-0.3 * ey, 0.3 * ex, 20.0)
    assert m_al > m_ac + 0.3
    i_al, i_ac = corr(0.3 * ex, 0.3 * ey, 6.0), corr(-0.3 * ey, 0.3 * ex, 6.0)
    assert i_al == pytest.approx(i_ac, abs=0.03)


def test_resolved_share_ends():
    """A point keeps all of ν's variance, a footprint of two cells across none."""
    assert resolved_share(None, torch.tensor(0.4)) == 1.0
    torch.testing.assert_close(resolved_share(torch.tensor([0.0, 0.8, 5.0]), torch.tensor(0.4)),
                               torch.tensor([1.0, 0.0, 0.0]))


def test_cover_mean_is_monahan_where_the_streaks_are_resolved():
    """E[f] = W with the streak field resolved (5 cm footprints, r = 0.996 at 20 m/s): 8 seeds × 3000
    points, within 8 % (the realization's sampling error, about 3 % here: a few large patches); the
    cover then varies on the streaks' scale (within 0.5 m along-wind neighbours differ). Fails when the
    resolved variance omits the streaks' share r κ σ_X² (planted: the mean rises to 0.140, 1.33 W)."""
    wf = WaveField(wind_speed=torch.full((8,), 20.0, dtype=D), seed=list(range(20, 28)), dtype=D)
    g = torch.Generator().manual_seed(1)
    x = torch.rand(8, 3000, generator=g, dtype=D) * 2000
    y = torch.rand(8, 3000, generator=g, dtype=D) * 2000
    t = torch.full((8,), 1.7, dtype=D)
    fp = torch.full_like(x, 0.05)
    w = float(whitecap_fraction(torch.tensor(20.0, dtype=D)))
    c = wf.sample_unchecked(x, y, t, fp, False, True)["crest"]
    fa, fr = whitecap_cover(wf, x, y, t, fp, c, wf.crest_variance(fp), wf.crest_variance()[:, None], torch.tensor(w, dtype=D))
    assert float((fa + fr).mean()) == pytest.approx(w, rel=0.08)
    assert 0.0 <= float((fa + fr).min()) and float((fa + fr).max()) <= 1.0


@pytest.mark.parametrize("dtype", [torch.float32, torch.float64])
def test_gradients_through_the_streaks_are_finite(dtype):
    """d/dx and d/d(length) of ν are finite in float32 and float64 (the weights are smooth within a cell)."""
    x = (torch.rand(2, 100, dtype=torch.float64) * 50).to(dtype).requires_grad_(True)
    ln = torch.tensor([2.0, 1.0], dtype=dtype, requires_grad=True)
    nu = streak_noise(x, x * 0.5, [1, 2], torch.ones(2, dtype=dtype), torch.zeros(2, dtype=dtype), ln, ln * 0.3)
    assert nu.dtype == dtype
    nu.sum().backward()
    assert bool(torch.isfinite(x.grad).all()) and bool(torch.isfinite(ln.grad).all())


def test_streak_noise_below_skips_only_where_nu_cannot_exceed_it():
    """streak_noise(..., below=b) returns ν bit for bit where it computes it, and 0 only where ν ≤ b
    (its lattice cell's bound cell_bound, ‖z⁺‖₂ over the cell's corners: ν = Σ w z with w ≥ 0, Σ w² = 1);
    60 000 points of 3 images (a dense lattice box, 15 m/s). With b just below each point's own ν
    nothing may be skipped; with b from −1 to 2 the skipped points have ν ≤ b, and at b = 1 over a third
    of the points are skipped. The values do not depend on the block size (streak_noise works 2¹⁵ points
    at a time; 1024 here). Fails with the cell's largest z⁺ as its bound (planted: ν exceeds it where
    several corners are alike)."""
    g = torch.Generator().manual_seed(7)
    x = torch.rand(3, 20000, generator=g, dtype=D) * 120 - 60
    y = torch.rand(3, 20000, generator=g, dtype=D) * 120 - 60
    seeds, b = [4, 5, 6], 3.0 * torch.rand(3, 20000, generator=g, dtype=D) - 1.0
    along, across = streak_lengths(torch.full((3,), 15.0, dtype=D))
    c, s = torch.full((3,), math.cos(0.4), dtype=D), torch.full((3,), math.sin(0.4), dtype=D)
    full = streak_noise(x, y, seeds, c, s, along, across)
    assert torch.equal(streak_noise(x, y, seeds, c, s, along, across, below=full - 1e-9), full)
    cut = streak_noise(x, y, seeds, c, s, along, across, below=b)
    skipped = cut != full
    assert bool((cut[skipped] == 0).all()) and bool((full[skipped] <= b[skipped]).all())
    at_one = streak_noise(x, y, seeds, c, s, along, across, below=torch.ones_like(x))
    assert float((at_one != full).double().mean()) > 0.35
    assert bool((full[at_one != full] <= 1.0).all())
    saved = fs._BLOCK
    try:
        fs._BLOCK = 1024
        assert torch.equal(streak_noise(x, y, seeds, c, s, along, across), full)
    finally:
        fs._BLOCK = saved


def test_cell_bound_closed_form():
    """cell_bound on a 2×3 node table: each cell's ‖z⁺‖₂ (times 1 + 1e-9, plus 1e-12); the last row and
    column +inf. Fails with the largest z⁺ of the cell (planted)."""
    z = torch.tensor([[1.0, -2.0, 0.5], [-1.0, 2.0, 3.0]], dtype=D)
    out = cell_bound(z).reshape(2, 3)
    norms = torch.tensor([math.sqrt(1 + 4), math.sqrt(0.25 + 4 + 9)], dtype=D)
    torch.testing.assert_close(out[0, :2], norms * (1 + 1e-9) + 1e-12, rtol=1e-15, atol=0.0)
    assert bool(torch.isposinf(out[1]).all()) and bool(torch.isposinf(out[:, 2]).all())

"""Foam on the crests of a textured sea: roughsea_torch.foam.crest_foam_fraction fed with the crest
variable of roughsea_torch.waves.WaveField (and the TextureTable hook that samples it per pixel).

What must hold (issue 12, item 3; docs/texture.md §8, §13): the ensemble mean of the pixel's foam
fraction is Monahan's W exactly, whatever the footprint; the far field is the uniform-fraction
image; the foam sits on crests; it is independent of the resolved slopes (so it does not bias the
slope texture); W = 0 means no foam; gradients are finite at the degenerate ends and right inside;
float32 agrees with float64. Plant ``σ_X`` for ``σ_u`` in the denominator of crest_foam_fraction
(f = Φ((X_r − c)/σ_X)) and the ensemble-mean tests fail by a factor of ~5 (short and medium
footprints) and ~1.5 (long).

Runs single-threaded (restored afterwards), as tests/test_waves.py, for steady timings on a shared
2-core machine.
"""

from __future__ import annotations

import math

import pytest
import torch

import roughsea_torch as rs
from roughsea_torch.clutter import footprint
from roughsea_torch.renderer.texture import TextureTable
from roughsea_torch.foam import crest_foam_fraction, whitecap_fraction
from roughsea_torch.waves import WaveField

from conftest import torch_threads

WIND = 10.0
FOOTPRINTS = (0.05, 3.0, 30.0)  # [m] short (everything resolved), medium, long (14 % of X resolved)


pytestmark = pytest.mark.usefixtures("one_thread")


@pytest.fixture(scope="module")
def ensemble():
    """120 realizations (one seed each, U10 = 10 m/s, float32) sampled at 2048 uniform random points
    of the longest tile, each point at the three footprints (one call, one pass over the bands)."""
    with torch_threads(1):
        n, npts = 120, 2048
        field = WaveField(torch.full((n,), WIND), list(range(n)), wind_direction=0.4, dtype=torch.float32)
        gen = torch.Generator().manual_seed(0)
        side = field.bands.tile_length[0]  # every tile length divides it: uniform on every tile
        x = (torch.rand(n, npts, generator=gen, dtype=torch.float64) * side).float()
        y = (torch.rand(n, npts, generator=gen, dtype=torch.float64) * side).float()
        k = len(FOOTPRINTS)
        fp = torch.tensor(FOOTPRINTS).repeat_interleave(npts).expand(n, -1)
        smp = field.sample(x.repeat(1, k), y.repeat(1, k), 1.0, footprint=fp, elevation=True, crest=True)
        out = {key: v.view(n, k, npts).double() for key, v in smp.items()}
        for name, var in (("crest", field.crest_variance), ("elevation", field.elevation_variance)):
            out[name + "_resolved_variance"] = var(fp).view(n, k, npts).double()
            out[name + "_total_variance"] = var().double()[:, None, None]
    return out


def _foam(ens: dict, name: str, w: float) -> torch.Tensor:
    return crest_foam_fraction(ens[name], ens[name + "_resolved_variance"], ens[name + "_total_variance"],
                               torch.tensor(w, dtype=torch.float64))


def _corr(a: torch.Tensor, b: torch.Tensor) -> torch.Tensor:
    """Correlation over the last dimension (one value per realization and footprint)."""
    a = a - a.mean(-1, keepdim=True)
    b = b - b.mean(-1, keepdim=True)
    return (a * b).mean(-1) / (a.pow(2).mean(-1) * b.pow(2).mean(-1)).sqrt()


W10 = float(whitecap_fraction(WIND))


# ------------------------------------------------------------------------------------------------
# 1. The variances the construction relies on
# ------------------------------------------------------------------------------------------------
@pytest.mark.parametrize("name", ["crest", "elevation"])
def test_sampled_variance_is_the_windowed_variance(ensemble, name):
    """The mean square of the sampled η and X equals elevation_variance(f) / crest_variance(f) (Σ_o
    w_o² V_o with the position-averaged bilinear factor) at every footprint, within 4 standard
    errors (from the spread across realizations) and 5 %."""
    ratio = (ensemble[name].pow(2).mean(-1) / ensemble[name + "_resolved_variance"][..., 0])  # (n, footprints)
    mean, se = ratio.mean(0) - 1.0, ratio.std(0) / math.sqrt(ratio.shape[0])
    assert bool((mean.abs() < 4 * se).all() and (mean.abs() < 0.05).all()), (mean, se)
    # the footprint removes variance, and the long footprint leaves part of X resolved
    v = ensemble[name + "_resolved_variance"][0, :, 0]
    assert bool((v[1:] < v[:-1]).all()) and float(v[-1]) > 0


def test_crest_channel_leaves_the_other_channels_unchanged():
    """sample(..., crest=True) adds a channel; elevation and slopes are bitwise those of the call
    without it (so the default texture path is untouched)."""
    field = WaveField(torch.tensor([7.0, 12.0]), [1, 2], wind_direction=torch.tensor([0.0, 1.0]))
    gen = torch.Generator().manual_seed(2)
    x, y = torch.rand(2, 3000, generator=gen) * 90, torch.rand(2, 3000, generator=gen) * 90
    fp = torch.rand(2, 3000, generator=gen) * 4
    with_crest = field.sample(x, y, 1.5, footprint=fp, crest=True)
    without = field.sample(x, y, 1.5, footprint=fp)
    assert sorted(with_crest) == ["crest", "elevation", "slope_x", "slope_y"]
    for key in without:
        assert torch.equal(with_crest[key], without[key])
    no_elev = field.sample(x, y, 1.5, footprint=fp, elevation=False, crest=True)
    assert torch.equal(no_elev["crest"], with_crest["crest"]) and "elevation" not in no_elev


# ------------------------------------------------------------------------------------------------
# 2. The ensemble mean is W exactly
# ------------------------------------------------------------------------------------------------
@pytest.mark.parametrize("name", ["crest", "elevation"])
@pytest.mark.parametrize("w", [W10, 0.1])
@pytest.mark.parametrize("i", range(len(FOOTPRINTS)), ids=[f"{f:g}m" for f in FOOTPRINTS])
def test_ensemble_mean_is_the_whitecap_fraction(ensemble, name, w, i):
    """E[f_pix] = W at short, medium and long footprints: the mean over 120 realizations (of the mean
    over 2048 points each) is W within 4 standard errors computed from the realizations, and the
    test resolves a 20 % error. (Measured at 10 m/s, W = 0.99 %: 1.055 ± 0.034, 1.055 ± 0.033,
    1.006 ± 0.007 W for 0.05, 3, 30 m; the planted σ_X-for-σ_u bug gives 5.1, 4.9, 1.5 W.)"""
    f = _foam(ensemble, name, w)[:, i]
    per = f.mean(-1) / w
    mean, se = float(per.mean()), float(per.std() / math.sqrt(per.numel()))
    assert 4 * se < 0.2, f"test too noisy: standard error {se}"
    assert abs(mean - 1.0) < 4 * se, (mean, se)


@pytest.mark.parametrize("dtype", [torch.float32, torch.float64])
def test_far_field_is_the_uniform_fraction(dtype):
    """Where the footprint is much larger than the longest band (1 km, 10 km, inf: every band's window
    is exactly 0), X_r = 0, σ_r² = 0 and f_pix = W to 1e-6 (relative); and the approach is continuous:
    at 10 m/s X's resolved part is already negligible at 300 m (|f_pix − W| < 1e-4 W), at 20 m/s
    (waves four times longer) it is not."""
    field = WaveField(torch.tensor([WIND, 20.0], dtype=torch.float64), [3, 4], dtype=dtype)
    w = whitecap_fraction(torch.tensor([WIND, 20.0], dtype=dtype))[:, None]
    gen = torch.Generator().manual_seed(4)
    x = (torch.rand(2, 1000, generator=gen, dtype=torch.float64) * 3000).to(dtype)
    y = (torch.rand(2, 1000, generator=gen, dtype=torch.float64) * 3000).to(dtype)
    for fp, tol in ((1e3, 1e-6), (1e4, 1e-6), (math.inf, 1e-6), (300.0, 1e-4)):
        rows = slice(None) if fp >= 1e3 else slice(0, 1)
        f_t = torch.tensor(fp, dtype=dtype)
        s = field.sample(x, y, 5.0, footprint=f_t, elevation=False, crest=True)
        vr = field.crest_variance(f_t)[:, None]
        f = crest_foam_fraction(s["crest"], vr, field.crest_variance()[:, None], w)
        assert f.dtype == dtype
        if fp >= 1e3:
            assert bool((s["crest"] == 0).all()) and bool((vr == 0).all())
        assert float(((f - w) / w)[rows].abs().max()) < tol, fp
        if fp == 300.0:
            assert float(((f - w) / w)[1].abs().max()) > 0.1  # 20 m/s: not vacuous


# ------------------------------------------------------------------------------------------------
# 3. Where the foam is
# ------------------------------------------------------------------------------------------------
def test_foam_sits_on_crests(ensemble):
    """Foam-weighted mean of the resolved elevation E[f η_r]/E[f]: above 1.5 σ_η at the short and
    medium footprints (measured 2.2 σ_η: the foam sits high on the crests; for η as the crest
    variable it would be 2.67 σ_η at most, the mean of the top 1 %); correlation of f_pix with η_r
    positive at every footprint, > 0.15 at the short one (0.23; with X_r 0.28, the indicator's
    Gaussian value φ(c)/√(W(1 − W)) = 0.27)."""
    f = _foam(ensemble, "crest", W10)
    eta, x = ensemble["elevation"], ensemble["crest"]
    sigma = ensemble["elevation_total_variance"][..., 0].sqrt()  # (n, 1)
    lift = ((f * eta).sum(-1) / f.sum(-1) / sigma).mean(0)
    assert bool((lift[:2] > 1.5).all()) and float(lift[2]) > 0.3, lift
    for v, short in ((eta, 0.15), (x, 0.2)):
        c = _corr(f, v)
        mean, se = c.mean(0), c.std(0) / math.sqrt(c.shape[0])
        assert bool((mean > 4 * se).all()) and float(mean[0]) > short, (mean, se)
    assert float(_corr(f, x).mean(0)[2]) > 0.7  # long footprint: f_pix smooth in X_r


def test_foam_is_independent_of_the_resolved_slope(ensemble):
    """f_pix is a function of X_r, which is uncorrelated with the slopes at the same point (X in phase
    with η, the slopes in quadrature), hence independent (jointly Gaussian): the correlations of
    f_pix with s_x, s_y and |s|² are zero within 4 standard errors and below 0.02 (so
    (1 − f_pix)·texture keeps the texture's mean)."""
    f = _foam(ensemble, "crest", W10)
    sx, sy = ensemble["slope_x"], ensemble["slope_y"]
    for v in (sx, sy, sx * sx + sy * sy):
        c = _corr(f, v)
        mean, se = c.mean(0), c.std(0) / math.sqrt(c.shape[0])
        assert bool((mean.abs() < 4 * se + 1e-3).all()) and bool((mean.abs() < 0.02).all()), (mean, se)


# ------------------------------------------------------------------------------------------------
# 4. Degenerate ends and gradients
# ------------------------------------------------------------------------------------------------
def test_no_foam_full_foam_and_no_waves():
    x = torch.tensor([-0.4, 0.0, 0.3, 5.0], dtype=torch.float64)
    vr, vt = torch.tensor(0.008, dtype=torch.float64), torch.tensor(0.01, dtype=torch.float64)
    assert torch.equal(crest_foam_fraction(x, vr, vt, 0.0), torch.zeros(4, dtype=torch.float64))
    assert torch.equal(crest_foam_fraction(x, vr, vt, 1.0), torch.ones(4, dtype=torch.float64))
    # a field without crest variance is the uniform fraction (a 1 cm/s wind: ECKV underflows to 0)
    f = crest_foam_fraction(torch.zeros(3), torch.zeros(3), torch.zeros(3), torch.tensor(0.02))
    assert torch.equal(f, torch.full((3,), 0.02))
    calm = WaveField(0.01, 0)
    s = calm.sample(torch.rand(1, 50), torch.rand(1, 50), 0.0, footprint=torch.tensor(0.01), crest=True)
    w = whitecap_fraction(torch.tensor(0.01))
    f = crest_foam_fraction(s["crest"], calm.crest_variance(torch.tensor(0.01)), calm.crest_variance(), w)
    assert float(calm.crest_variance()) == 0.0 and torch.equal(f, w.expand(1, 50))
    # below W = 1e-30 the fraction scales linearly to 0 (continuous at the switch)
    w = torch.tensor([1e-30 * (1 + 1e-9), 1e-30 * (1 - 1e-9)], dtype=torch.float64)
    a, b = crest_foam_fraction(torch.tensor(0.3, dtype=torch.float64), vr, vt, w)
    assert float(b) == pytest.approx(float(a), rel=1e-6) and 0 < float(b) < 1
    with pytest.raises(ValueError, match="whitecap_fraction"):
        crest_foam_fraction(x, vr, vt, 1.5)
    with pytest.raises(ValueError, match="resolved_variance"):
        crest_foam_fraction(x, -vr, vt, 0.1)
    with pytest.raises(ValueError, match="floor"):
        crest_foam_fraction(x, vr, vt, 0.1, floor=-1.0)


@pytest.mark.parametrize(
    "x, vr, vt, w",
    [
        ([-0.3, 0.0, 0.24, 0.4], 0.005, 0.01, 0.01),  # mid footprint
        ([0.1, 0.2, 0.24, 0.3], 0.00999, 0.01, 0.01),  # nearly everything resolved: σ_u at the floor
        ([0.1, 0.2, 0.26, 0.3], 0.0102, 0.01, 0.01),  # resolved above total: σ_u = the floor exactly
        ([0.0, 1e-3, -1e-3, 0.0], 1e-7, 0.01, 0.01),  # far field: nothing resolved
        ([0.2, 0.5, 0.7, 0.9], 0.008, 0.01, 1e-12),  # light wind: W tiny
        ([-0.2, 0.0, 0.05, 0.2], 0.008, 0.01, 0.3),  # the upper end of Monahan's range
    ],
)
def test_gradients_match_central_differences(x, vr, vt, w):
    """float64 autograd of f_pix with respect to all four inputs against central differences (step
    1e-5 relative), inside every regime: mid footprint, σ_u at the floor, resolved variance above
    the total, the far field, W = 1e-12 and W = 0.3."""
    args = [torch.tensor(v, dtype=torch.float64, requires_grad=True) for v in (x, vr, vt, w)]
    f = crest_foam_fraction(*args)
    grads = torch.autograd.grad(f.sum(), args)
    for i, g in enumerate(grads):
        assert bool(torch.isfinite(g).all())
        base = [a.detach().clone() for a in args]
        flat = base[i].reshape(-1)
        fd = torch.empty_like(flat)
        for j in range(flat.numel()):
            h = 1e-5 * abs(float(flat[j])) or 1e-7
            plus = [b.clone() for b in base]
            minus = [b.clone() for b in base]
            plus[i].reshape(-1)[j] += h
            minus[i].reshape(-1)[j] -= h
            fd[j] = (crest_foam_fraction(*plus).sum() - crest_foam_fraction(*minus).sum()) / (2 * h)
        scale = float(fd.abs().max()) + 1e-12
        assert float((g.reshape(-1) - fd).abs().max()) < 1e-5 * scale + 1e-8, (i, g, fd)


def test_gradients_are_finite_at_the_degenerate_ends():
    """W = 0, W = 1, no crest variance, nothing resolved, everything resolved (σ_u² = 0 but for the
    floor), floor = 0 with nothing unresolved: every gradient is finite (no NaN, no inf)."""
    cases = [
        (0.3, 0.008, 0.01, 0.0, {}),
        (0.3, 0.008, 0.01, 1.0, {}),
        (0.0, 0.0, 0.0, 0.05, {}),
        (0.0, 0.0, 0.01, 0.05, {}),
        (0.24, 0.01, 0.01, 0.01, {}),
        (0.24, 0.01, 0.01, 0.01, {"floor": 0.0}),
        (50.0, 0.01, 0.01, 1e-30, {}),
    ]
    for x, vr, vt, w, kw in cases:
        args = [torch.tensor(v, dtype=torch.float64, requires_grad=True) for v in (x, vr, vt, w)]
        f = crest_foam_fraction(*args, **kw)
        assert 0.0 <= float(f.detach()) <= 1.0
        grads = torch.autograd.grad(f, args)
        assert all(bool(torch.isfinite(g).all()) for g in grads), (x, vr, vt, w, kw, grads)


def test_gradient_through_the_field_and_wind():
    """d mean(f_pix)/dU10 through the whole chain (W(U10), the crest amplitudes, the cut-off k_b ∝ k_p
    and the variances) equals a float64 central difference."""
    gen = torch.Generator().manual_seed(6)
    x = torch.rand(1, 3000, generator=gen, dtype=torch.float64) * 200
    y = torch.rand(1, 3000, generator=gen, dtype=torch.float64) * 200
    fp = torch.rand(1, 3000, generator=gen, dtype=torch.float64) * 6

    def mean_foam(u: torch.Tensor) -> torch.Tensor:
        field = WaveField(u, [8], wind_direction=0.5, dtype=torch.float64)
        s = field.sample(x, y, 2.0, footprint=fp, elevation=False, crest=True)
        return crest_foam_fraction(s["crest"], field.crest_variance(fp), field.crest_variance()[:, None],
                                   whitecap_fraction(u)[:, None]).mean()

    u = torch.tensor([12.0], dtype=torch.float64, requires_grad=True)
    (grad,) = torch.autograd.grad(mean_foam(u), u)
    h = 1e-4
    fd = (mean_foam(u.detach() + h) - mean_foam(u.detach() - h)) / (2 * h)
    assert math.isfinite(float(grad)) and float(grad) > 0
    assert float(grad) == pytest.approx(float(fd), rel=1e-5)


def test_float32_agrees_with_float64():
    """Same realizations and points (|x| ≤ 30 m, where float32 rounding of the tile coordinates is
    ~1e-4 of the rms, tests/test_waves.py) in both dtypes: f_pix agrees to 2e-4 absolute (its slope
    in X_r is at most φ(0)/(0.05 σ_X) ≈ 80 per unit X at the floor)."""
    gen = torch.Generator().manual_seed(5)
    x = (torch.rand(2, 4000, generator=gen) * 2 - 1) * 30
    y = (torch.rand(2, 4000, generator=gen) * 2 - 1) * 30
    fp = torch.rand(2, 4000, generator=gen) * 5
    wind = torch.tensor([WIND, 20.0], dtype=torch.float64)
    out = []
    for dtype in (torch.float32, torch.float64):
        field = WaveField(wind, [1, 2], wind_direction=0.2, dtype=dtype)
        f_t = fp.to(dtype)
        s = field.sample(x.to(dtype), y.to(dtype), 2.0, footprint=f_t, elevation=False, crest=True)
        f = crest_foam_fraction(s["crest"], field.crest_variance(f_t), field.crest_variance()[:, None],
                                whitecap_fraction(wind.to(dtype))[:, None])
        assert f.dtype == dtype
        out.append(f.double())
    assert float((out[0] - out[1]).abs().max()) < 2e-4
    assert float(out[1].max()) > 0.5  # foam present: the comparison covers the edges


# ------------------------------------------------------------------------------------------------
# 5. The renderer's hook: TextureTable.pixels(..., crest=True)
# ------------------------------------------------------------------------------------------------
def test_texture_table_returns_the_pixels_crest(monkeypatch):
    """With crest=True the texture pass also returns (X_r, σ_r², σ_X²) per pixel: the image is bitwise
    unchanged; X_r is the field's crest variable at the pixel's flat-sea point and footprint (as the
    per-pixel path computes them, to rounding); σ_r² (tabulated on the texture's rows) is
    crest_variance at the pixel's footprint within 0.2 %; σ_X² is the field's total."""
    def sky(c):
        return 10.0 + 20.0 * (1.0 - c) ** 4

    cams = rs.make_camera(24, 16, hfov_deg=12.0, altitude_m=10.0, pitch_deg=-6.0, batch_size=2, dtype=torch.float64)
    times = torch.tensor([0.0, 2.0], dtype=torch.float64)
    # foam=False: the renderer asks for no crest, the wrapper below forces it
    scene = rs.SeaScene(wind_speed=8.0, sea_temperature=290.0, sky=sky, path=False, seed=[11, 12], time_s=times,
                        foam=False)
    reference = rs.render(cams, scene)
    captured = []
    original = TextureTable.pixels

    def with_crest(self, *args, **kwargs):
        assert kwargs.pop("crest", False) is False
        result = original(self, *args, crest=True, **kwargs)
        assert len(result) == 4
        captured.append(result[3])
        return result[:3]

    monkeypatch.setattr(TextureTable, "pixels", with_crest)
    image = rs.render(cams, scene)
    monkeypatch.undo()
    assert torch.equal(image, reference) and captured
    x_r, v_r, v_t = (torch.cat(t) for t in zip(*captured))
    assert x_r.shape == (2, 24, 16) and v_r.shape == (2, 24, 16) and v_t.shape == (2, 1, 1)

    geom = rs.view_geometry(cams)
    sea = geom.is_sea
    field = scene.wave_field(2, torch.float64, torch.device("cpu"))
    centres = -(cams.rotation_matrix.transpose(-1, -2) @ cams.translation_vector)[..., 0]
    cos_t = geom.cos_view_zenith.clamp_min(1e-9)
    R = torch.where(sea, geom.range_m, torch.ones_like(cos_t))
    L = footprint(R, cos_t, (1.0 / cams.fx)[:, None, None])
    s = field.sample(centres[:, 0, None, None] + R * geom.dx, centres[:, 1, None, None] + R * geom.dy, times,
                     footprint=L, elevation=False, crest=True)
    rms = float(s["crest"][sea].pow(2).mean().sqrt())
    assert float((x_r - s["crest"])[sea].abs().max()) < 1e-9 * rms
    direct = field.crest_variance(L)
    assert float(((v_r - direct) / direct.clamp_min(1e-30))[sea & (direct > 1e-6 * v_t)].abs().max()) < 2e-3
    torch.testing.assert_close(v_t[:, 0, 0], field.crest_variance(), rtol=0, atol=0)
    assert float((v_r / v_t)[sea].max()) > 0.5 and bool((x_r[~sea] == 0).all())
    f = crest_foam_fraction(x_r, v_r, v_t, whitecap_fraction(torch.tensor(8.0, dtype=torch.float64)))
    assert bool(((f >= 0) & (f <= 1)).all())

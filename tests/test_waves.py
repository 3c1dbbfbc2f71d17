"""The synthesized band-split sea surface (roughsea_torch.waves.WaveField): its slope covariance, its
crest variable, slopes that are −∇η, waves that travel at their phase speed, determinism, gradients
and errors. (The spectrum: tests/test_spectrum.py; the bands' windows and lattices:
tests/test_wave_bands.py, tests/test_wave_lattice.py.)

Each test asserts a fact that a wrong implementation would break; the sources of the reference values
are given next to them. The module runs single-threaded (restored afterwards): on a shared 2-core
machine OpenMP spin-waiting makes the many small per-image ops of WaveField erratic; the
determinism test switches to 2 threads itself to cover the parallel code paths.
"""

from __future__ import annotations

import math

import pytest
import torch

import roughsea_torch.waves as waves
from roughsea_torch import SeaScene
from roughsea_torch.waves import K_M, WaveBands, WaveField, dispersion

pytestmark = pytest.mark.usefixtures("one_thread")


# ------------------------------------------------------------------------------------------------
# 1. Slope covariance of the synthesized field
# ------------------------------------------------------------------------------------------------
def test_sampled_covariance_matches_band_covariance():
    """Slope moments s_x², s_y², s_x s_y of the sampled field, averaged over 4096 uniform random points
    per seed and 240 seeds, equal Σ_o band_covariance (footprint 0, i.e. every band at full weight)
    and resolved_covariance(footprint) for footprints 2, 5 and 30 cm, to 2 %, the 2 % being more than
    4 standard errors (from the spread across seeds; one realization of the default layout scatters
    by about 5 % around the expectation: ~75 independent amplitudes per band).

    The four footprints are evaluated at the same points (the points are repeated), in one call.
    Float32 only: the identity is the same in float64 (dtype agreement is tested separately)."""
    dtype = torch.float32
    n_seeds, group, npts = 240, 60, 4096
    footprints = [0.0, 0.02, 0.05, 0.3]
    gen = torch.Generator().manual_seed(1)
    est, ref = [], []  # per seed: (footprint, moment) pairs
    for start in range(0, n_seeds, group):
        field = WaveField(torch.full((group,), 10.0), list(range(start, start + group)), wind_direction=0.7, dtype=dtype)
        side = field.bands.tile_length[0]  # band 0's period, the area of 4^o cells of band o's turned tile:
        # uniform on every tile but at the square's edges (cross terms of zero mean over seeds)
        x = (torch.rand(group, npts, generator=gen, dtype=torch.float64) * side).to(dtype)
        y = (torch.rand(group, npts, generator=gen, dtype=torch.float64) * side).to(dtype)
        fp = torch.tensor(footprints, dtype=dtype).repeat_interleave(npts).expand(group, -1)
        out = field.sample(x.repeat(1, 4), y.repeat(1, 4), time_s=3.0, footprint=fp, elevation=False)
        sx = out["slope_x"].view(group, 4, npts).double()
        sy = out["slope_y"].view(group, 4, npts).double()
        est.append(torch.stack([(sx * sx).mean(-1), (sy * sy).mean(-1), (sx * sy).mean(-1)], -1))
        vx, vy, cxy = (v.view(group, 4, npts)[..., 0].double() for v in field.resolved_covariance(fp))
        ref.append(torch.stack([vx, vy, cxy], -1))
        if start == 0:
            total = field.band_covariance().sum(1).double()
            assert total.shape == (group, 3) and field.band_covariance().dtype == dtype
            torch.testing.assert_close(ref[0][:, 0], total, rtol=1e-6, atol=0)  # footprint 0: all bands
            assert abs(float(total[:, 0].mean() / total[:, 1].mean()) - 1.0) > 0.05  # anisotropic
    est, ref = torch.cat(est), torch.cat(ref)  # (n_seeds, 4 footprints, 3 moments)
    scale = torch.stack([ref[..., 0], ref[..., 1], torch.sqrt(ref[..., 0] * ref[..., 1])], -1)
    err = (est - ref) / scale  # per seed, relative to the variance scale
    mean, se = err.mean(0), err.std(0) / math.sqrt(n_seeds)
    assert bool((4 * se < 0.02).all()), f"test too noisy: standard errors {se}"
    assert bool((mean.abs() < 0.02).all()), f"relative errors {mean} (standard errors {se})"
    # the footprints do remove variance, progressively
    vx = ref[..., 0].mean(0)
    assert bool((vx[1:] < vx[:-1]).all()) and float(vx[-1]) > 0


def test_footprint_none_equals_zero_footprint():
    field = WaveField(torch.tensor([7.0, 11.0]), [3, 4], wind_direction=torch.tensor([0.0, 1.0]))
    x = torch.rand(2, 3000, generator=torch.Generator().manual_seed(3)) * 80
    a = field.sample(x, x.flip(-1), 1.0)
    b = field.sample(x, x.flip(-1), 1.0, footprint=torch.zeros(()))
    for key in a:
        assert torch.equal(a[key], b[key])


def test_sample_is_pointwise_whatever_the_order_and_the_skipped_blocks():
    """sample evaluates a band only on runs of blocks of points whose footprint reaches it, and
    windows only the blocks where w may be below 1; each point's value must not depend on which
    other points share its blocks. Points whose footprints mix 0 (every band, w = 1), inf (none)
    and values across the bands' windows, in runs and shuffled: the shuffled sample is the sample
    shuffled (bitwise), inf gives exactly 0, 0 gives the sample without footprint, and a point
    evaluated alone gives its value in the batch."""
    gen = torch.Generator().manual_seed(5)
    field = WaveField(torch.tensor([4.0, 12.0]), [8, 9], wind_direction=torch.tensor([0.3, -1.0]), dtype=torch.float64)
    n = 20_000
    x = (torch.rand(2, n, generator=gen, dtype=torch.float64) - 0.5) * 3000
    y = (torch.rand(2, n, generator=gen, dtype=torch.float64) - 0.5) * 3000
    f = torch.exp(torch.rand(2, n, generator=gen, dtype=torch.float64) * 14 - 8)  # 0.3 mm ... 400 m
    f[:, 3000:5000] = 0.0
    f[:, 9000:12000] = math.inf
    f[:, 15000:15500] = 1e-3  # a run where only the footprint's own window applies
    perm = torch.randperm(n, generator=gen)
    a = field.sample(x, y, 2.0, footprint=f, crest=True)
    b = field.sample(x[:, perm], y[:, perm], 2.0, footprint=f[:, perm], crest=True)
    none = field.sample(x[:, 3000:5000], y[:, 3000:5000], 2.0, crest=True)
    for key in a:
        assert torch.equal(a[key][:, perm], b[key]), key
        assert torch.equal(a[key][:, 9000:12000], torch.zeros(2, 3000, dtype=torch.float64)), key
        assert torch.equal(a[key][:, 3000:5000], none[key]), key
    for i in (17, 7000, 15100, 19999):
        one = field.sample(x[:, i : i + 1], y[:, i : i + 1], 2.0, footprint=f[:, i : i + 1], crest=True)
        for key in a:
            assert torch.allclose(one[key], a[key][:, i : i + 1], rtol=1e-13, atol=1e-15), (key, i)


def test_sample_does_not_depend_on_how_points_are_chunked(monkeypatch):
    """Three images of 300 000 points each: the default chunks (2**18 / 3 points, which do not start
    on 512-point blocks) against one chunk, bitwise, with a footprint that ramps across every band's
    window (so runs, windowed spans and chunk boundaries all meet part-way through blocks)."""
    gen = torch.Generator().manual_seed(8)
    field = WaveField(torch.tensor([5.0, 9.0, 14.0]), [4, 5, 6], wind_direction=torch.tensor([0.2, 1.1, -2.0]),
                      dtype=torch.float64)
    n = 300_000
    x = (torch.rand(3, n, generator=gen, dtype=torch.float64) - 0.5) * 4000
    y = (torch.rand(3, n, generator=gen, dtype=torch.float64) - 0.5) * 4000
    f = torch.logspace(-3.5, 3.5, n, dtype=torch.float64).expand(3, -1) * torch.tensor([[1.0], [0.7], [1.3]],
                                                                                        dtype=torch.float64)
    chunked = field.sample(x, y, 1.5, footprint=f, crest=True)
    monkeypatch.setattr(waves, "_CHUNK_ELEMENTS", 2**22)
    whole = field.sample(x, y, 1.5, footprint=f, crest=True)
    for key in whole:
        assert torch.equal(chunked[key], whole[key]), key


def test_min_band_share_leaves_out_the_weak_bands_and_only_them():
    """WaveField(min_band_share=s) drops, per image, the bands that carry less than s of the image's
    slope variance and of its crest variable's (shares computed here from the full field), and
    nothing else: their covariance and variances are 0, the others' unchanged, and the sample is the
    full field's minus those bands' contribution (the full field's sample at the footprint where its
    window keeps exactly those bands, 1/√2 π/k of the last one)."""
    wind = torch.tensor([3.0, 6.0, 20.0], dtype=torch.float64)
    full = WaveField(wind, [1, 2, 3], dtype=torch.float64)
    part = WaveField(wind, [1, 2, 3], dtype=torch.float64, min_band_share=1e-6)
    cov = full.band_covariance()
    slope = cov[..., 0] + cov[..., 1]
    crest = full.band_crest_variance()
    weak = (slope / slope.sum(-1, keepdim=True) < 1e-6) & (crest / crest.sum(-1, keepdim=True) < 1e-6)
    n_weak = weak.sum(-1).tolist()
    assert n_weak[0] > n_weak[1] > 0 and not bool(weak[0].all())  # 3 and 6 m/s drop different bands
    assert torch.equal(part.band_covariance()[weak], torch.zeros_like(cov[weak]))
    assert torch.equal(part.band_covariance()[~weak], cov[~weak])
    assert torch.equal(part.band_crest_variance()[~weak], crest[~weak])
    assert torch.equal(part.band_elevation_variance()[weak], torch.zeros_like(crest[weak]))
    gen = torch.Generator().manual_seed(2)
    x = (torch.rand(1, 5000, generator=gen, dtype=torch.float64) - 0.5) * 5000
    y = (torch.rand(1, 5000, generator=gen, dtype=torch.float64) - 0.5) * 5000
    f_weak = torch.full((3, 5000), 0.0, dtype=torch.float64)
    for i in range(3):
        if n_weak[i]:
            last = int(torch.nonzero(weak[i])[-1])
            assert bool(weak[i, : last + 1].all())  # a prefix: the spectrum's low-k flank
            f_weak[i] = (1.0 / math.sqrt(2.0)) * math.pi / full.bands.band_wavenumber[last]
        else:
            f_weak[i] = math.inf  # nothing dropped: nothing to subtract
    xs, ys = x.expand(3, -1), y.expand(3, -1)
    a, b = full.sample(xs, ys, 4.0, crest=True), part.sample(xs, ys, 4.0, crest=True)
    low = full.sample(xs, ys, 4.0, footprint=f_weak, crest=True)
    for key in a:
        for i in range(3):  # every image against its own dropped set
            scale = float(a[key][i].abs().max())
            assert float((a[key][i] - low[key][i] - b[key][i]).abs().max()) < 1e-9 * scale, (key, i)
            if n_weak[i]:
                assert float((a[key][i] - b[key][i]).abs().max()) > 0.0, (key, i)  # the dropped bands were not zero
    with pytest.raises(ValueError, match=r"min_band_share must be a number in \[0, 1\)"):
        WaveField(5.0, 0, min_band_share=1.0)
    with pytest.raises(ValueError, match=r"min_band_share must be a number in \[0, 1\)"):
        WaveField(5.0, 0, min_band_share=-1e-9)


# ------------------------------------------------------------------------------------------------
# 2. The crest variable and the elevation: the variances foam on crests relies on
# ------------------------------------------------------------------------------------------------
@pytest.mark.parametrize("name", ["crest", "elevation"])
def test_sampled_variance_is_the_windowed_variance(crest_ensemble, name):
    """The mean square of the sampled η and X equals elevation_variance(f) / crest_variance(f) (Σ_o
    w_o² V_o with the position-averaged bilinear factor) at every footprint, within 4 standard
    errors (from the spread across realizations) and 5 %."""
    ratio = (crest_ensemble[name].pow(2).mean(-1) / crest_ensemble[name + "_resolved_variance"][..., 0])  # (n, footprints)
    mean, se = ratio.mean(0) - 1.0, ratio.std(0) / math.sqrt(ratio.shape[0])
    assert bool((mean.abs() < 4 * se).all() and (mean.abs() < 0.05).all()), (mean, se)
    # the footprint removes variance, and the long footprint leaves part of X resolved
    v = crest_ensemble[name + "_resolved_variance"][0, :, 0]
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
# 3. Slopes are −∇η
# ------------------------------------------------------------------------------------------------
def test_slope_is_minus_gradient_of_elevation(dtype):
    """One octave on a fine tile (512 texels, highest mode θ = k·texel = 0.098): slope_x against a
    central difference of the elevation at texel centres in x and on texel lines in y (and the other
    way round for slope_y). The bilinear elevation is linear in x across a texel, so the difference
    (step ¼ texel, divided by the realized step) is its exact derivative there; it and the interpolated
    spectral slope agree to θ²/12 ≈ 0.1 % of the mode. Tolerance 0.5 % of the rms slope (2 % float32)."""
    bands = WaveBands(k_edges=(1.0, 2.0), tile_size=512)
    field = WaveField(8.0, 3, wind_direction=0.4, dtype=dtype, bands=bands)
    h = bands.tile_length[0] / bands.tile_size
    gen = torch.Generator().manual_seed(0)
    i = torch.randint(0, 512, (1, 2000), generator=gen).double()
    j = torch.randint(0, 512, (1, 2000), generator=gen).double()
    step = 0.25 * h
    tol = 0.005 if dtype == torch.float64 else 0.02

    for axis in ("x", "y"):
        x, y = ((i + 0.5) * h, j * h) if axis == "x" else (i * h, (j + 0.5) * h)
        x, y = x.to(dtype), y.to(dtype)
        s = field.sample(x, y, time_s=1.0)["slope_" + axis]
        if axis == "x":
            lo, hi = x - step, x + step
            fd = -(field.sample(hi, y, 1.0)["elevation"] - field.sample(lo, y, 1.0)["elevation"]) / (hi - lo)
        else:
            lo, hi = y - step, y + step
            fd = -(field.sample(x, hi, 1.0)["elevation"] - field.sample(x, lo, 1.0)["elevation"]) / (hi - lo)
        rms = float(s.double().pow(2).mean().sqrt())
        assert rms > 0
        assert float((s - fd).abs().max()) < tol * rms, axis


def test_slope_is_minus_gradient_default_layout():
    """All 16 default bands at random points: the derivative of the bilinear interpolant differs from
    the interpolated slope by O(θ) (θ ≤ 0.39 rad per texel); still 92 % of the rms, and −∇η, not +∇η."""
    field = WaveField(10.0, 5, wind_direction=1.0, dtype=torch.float64)
    gen = torch.Generator().manual_seed(2)
    x = torch.rand(1, 4000, generator=gen, dtype=torch.float64) * 50
    y = torch.rand(1, 4000, generator=gen, dtype=torch.float64) * 50
    step = 1e-6
    s = field.sample(x, y)
    fdx = -(field.sample(x + step, y)["elevation"] - field.sample(x - step, y)["elevation"]) / (2 * step)
    fdy = -(field.sample(x, y + step)["elevation"] - field.sample(x, y - step)["elevation"]) / (2 * step)
    for a, b in ((s["slope_x"], fdx), (s["slope_y"], fdy)):
        err = float((a - b).pow(2).mean().sqrt() / a.pow(2).mean().sqrt())
        assert err < 0.08


# ------------------------------------------------------------------------------------------------
# 4. Waves move at their phase speed, downwind
# ------------------------------------------------------------------------------------------------
@pytest.mark.parametrize("k0", [0.5, K_M])
def test_component_moves_at_phase_speed(k0):
    """A band [k0, 1.01 k0) on a tile with Δk = k0/4 holds only the lattice modes (±4, 0), (0, ±4).
    slope_x sees only the (4, 0) pair (∂/∂x of the y-modes is 0): a single plane wave along x.
    With the downwind direction along +x (wind_direction = π is the upwind axis), slope_x(x + c t, t)
    = slope_x(x, 0) for c = ω(k0)/k0, evaluated on texel nodes (no interpolation error), and not for
    travel upwind. At k0 = k_m, c is the capillary minimum ≈ 0.23 m/s."""
    bands = WaveBands(k_edges=(k0, 1.01 * k0), tile_size=128)
    field = WaveField(10.0, 7, wind_direction=math.pi, dtype=torch.float64, bands=bands)
    c = float(dispersion(torch.tensor(k0, dtype=torch.float64))) / k0
    if k0 == K_M:
        assert c == pytest.approx(0.23, abs=1e-3)
    h = bands.tile_length[0] / bands.tile_size
    shift = 5 * h  # 5 texels
    t = shift / c
    x = torch.arange(128, dtype=torch.float64)[None] * h
    y = torch.full_like(x, 3 * h)
    s0 = field.sample(x, y, 0.0)["slope_x"]
    moved = field.sample(x + shift, y, t)["slope_x"]
    scale = float(s0.abs().max())
    assert scale > 0
    torch.testing.assert_close(moved, s0, rtol=0, atol=1e-9 * scale)
    assert float((field.sample(x, y, t)["slope_x"] - s0).abs().max()) > 0.5 * scale  # it did move
    assert float((field.sample(x - shift, y, t)["slope_x"] - s0).abs().max()) > 0.5 * scale  # not upwind
    wrong_speed = field.sample(x + shift, y, 1.1 * t)["slope_x"]
    assert float((wrong_speed - s0).abs().max()) > 0.05 * scale


def test_temporal_correlation_at_fixed_points_follows_the_spectrum():
    """The clutter's time scale (``pipelines/clutter_time.py``): at fixed points, the correlation of
    slope_x against the lag τ equals the linear theory of the ECKV spectrum,
    ρ(τ) = ∫∫ F k³ cos²φ w_o(f)² cos(ω(k) τ) dk dφ / (τ = 0), each wavenumber weighted by the window of
    its band at a footprint of 0.93 m (a 1.9 mrad pixel at 100 m range, 75° from the zenith): its
    1/e time within 15 % (0.41 s sampled, 0.40 s in theory at 8 m/s; one realization scatters by a
    few per cent: ~75 amplitudes per band), and the correlation at 0.2 s within 0.1. A field whose
    waves ran 1.3× too fast (plant ``dispersion`` × 1.3 in wave_lattice) decorrelates in 0.31 s and
    fails."""

    from roughsea_torch.spectrum import elfouhaily_spectrum

    wind, f = 8.0, 0.93
    field = WaveField(torch.full((2,), wind, dtype=torch.float64), [5, 6], wind_direction=0.0, dtype=torch.float64)
    gen = torch.Generator().manual_seed(2)
    x, y = (400.0 * torch.rand(2, 2, 3000, generator=gen, dtype=torch.float64)).unbind(0)
    lags = torch.arange(0.0, 1.2, 0.02, dtype=torch.float64)
    s = torch.stack([field.sample(x, y, float(t), footprint=torch.full_like(x, f), elevation=False)["slope_x"]
                     for t in lags])  # (T, 2, N)
    rendered = torch.stack([(s[0] * s[i]).mean() for i in range(len(lags))])
    rendered = rendered / rendered[0]

    k = torch.logspace(-3.0, 3.0, 3000, dtype=torch.float64)
    phi = torch.linspace(-math.pi, math.pi, 145, dtype=torch.float64)[:-1]  # from downwind = +x here
    edges = torch.tensor(field.bands.k_edges, dtype=torch.float64)
    o = (torch.bucketize(k, edges, right=True) - 1).clamp(0, len(edges) - 2)
    k_o = torch.sqrt(edges[o] * edges[o + 1])  # the band centre each wavenumber is windowed with
    inside = (k >= edges[0]) & (k < edges[-1])
    t_ = torch.clamp((f * k_o / math.pi - 2 ** -0.5) / (2 ** 0.5 - 2 ** -0.5), 0.0, 1.0)
    w = torch.where(inside, 1.0 - t_ * t_ * (3.0 - 2.0 * t_), torch.zeros_like(k))
    density = (elfouhaily_spectrum(k[:, None], phi[None], wind) * torch.cos(phi[None]) ** 2).sum(1) * k ** 3 * w * w
    dk = torch.gradient(k)[0]
    omega = torch.sqrt(9.81 * k * (1.0 + (k / 370.0) ** 2))  # ECKV Eq. 24
    theory = torch.stack([(density * dk * torch.cos(omega * t)).sum() for t in lags])
    theory = theory / theory[0]

    def one_over_e(c: torch.Tensor) -> float:
        i = int((c < math.exp(-1)).nonzero()[0, 0])
        c0, c1 = float(c[i - 1]), float(c[i])
        return float(lags[i - 1]) + 0.02 * (c0 - math.exp(-1)) / (c0 - c1)

    t_r, t_t = one_over_e(rendered), one_over_e(theory)
    assert 0.2 < t_t < 1.0  # the theory's own scale: a fraction of a second at 100 m
    assert abs(t_r / t_t - 1.0) < 0.15, (t_r, t_t)
    assert abs(float(rendered[10] - theory[10])) < 0.1


# ------------------------------------------------------------------------------------------------
# 5. Determinism
# ------------------------------------------------------------------------------------------------
def _check_batch_equals_alone(dtype: torch.dtype, npts: int, times: tuple[float, ...]) -> None:
    seeds, winds, dirs = [11, 22, 33], [6.0, 12.0, 18.0], [0.3, 2.0, -1.0]
    # per-image arguments as float64 tensors: the same numbers as the python floats used alone
    batch = WaveField(
        torch.tensor(winds, dtype=torch.float64), seeds, wind_direction=torch.tensor(dirs, dtype=torch.float64), dtype=dtype
    )
    gen = torch.Generator().manual_seed(4)
    x = (torch.rand(3, npts, generator=gen, dtype=torch.float64) * 300 - 100).to(dtype)
    y = (torch.rand(3, npts, generator=gen, dtype=torch.float64) * 300 - 100).to(dtype)
    fp = (10 ** (torch.rand(3, npts, generator=gen, dtype=torch.float64) * 4 - 3)).to(dtype)
    alone = [WaveField(winds[i], seeds[i], wind_direction=dirs[i], dtype=dtype) for i in range(3)]
    for t in times:
        together = batch.sample(x, y, time_s=t, footprint=fp)
        for i in range(3):
            single = alone[i].sample(x[i : i + 1], y[i : i + 1], time_s=t, footprint=fp[i : i + 1])
            for key in ("elevation", "slope_x", "slope_y"):
                assert torch.equal(together[key][i : i + 1], single[key]), (key, i, t)
    for i in range(3):
        assert torch.equal(batch.band_covariance()[i], alone[i].band_covariance()[0])
    # the footprint-windowed statistics too (the renderer's node values use them; a batched matmul rounded
    # them by the batch size, and a textured image then depended on how its batch was grouped)
    for name in ("elevation_variance", "crest_variance"):
        together = getattr(batch, name)(fp)
        for i in range(3):
            assert torch.equal(together[i : i + 1], getattr(alone[i], name)(fp[i : i + 1])), (name, i)
    together = batch.resolved_covariance(fp)
    for i in range(3):
        single = alone[i].resolved_covariance(fp[i : i + 1])
        assert all(torch.equal(a[i : i + 1], b) for a, b in zip(together, single)), i


def test_batch_member_equals_image_alone_bitwise(dtype, monkeypatch):
    """Image i of a batch of 3 is bitwise the same (seed, wind, direction) rendered alone, at two
    times, with footprints; small chunks (1365 points per chunk in the batch, 4096 alone) so that the
    chunk boundaries differ between the two."""
    monkeypatch.setattr(waves, "_CHUNK_ELEMENTS", 2**12)
    _check_batch_equals_alone(dtype, 6000, (0.0, 7.25))


def test_batch_member_equals_image_alone_bitwise_two_threads(monkeypatch, two_threads):
    """Same on 2 threads, with tensors large enough for intra-op parallel splits: 40 000 points per
    image, chunks of 21 845 points in the batch (2**16 elements / 3), one chunk alone."""
    monkeypatch.setattr(waves, "_CHUNK_ELEMENTS", 2**16)
    _check_batch_equals_alone(torch.float32, 40_000, (3.5,))


def test_one_image_on_two_threads_equals_one_thread_bitwise(monkeypatch, two_threads):
    """One image on two threads: its band reads are split into a group of points per thread (grid_sample runs
    images, not points, in parallel), which must change no value: the sample, on chunks that leave a ragged
    last group, is bitwise the one-thread sample (and the wind gradient's value too)."""
    monkeypatch.setattr(waves, "_CHUNK_ELEMENTS", 5001)
    gen = torch.Generator().manual_seed(3)
    x = torch.rand(1, 12003, generator=gen, dtype=torch.float64) * 400 - 200
    y = torch.rand(1, 12003, generator=gen, dtype=torch.float64) * 400 - 200
    f = torch.rand(1, 12003, generator=gen, dtype=torch.float64) * 3

    def run() -> tuple[dict, torch.Tensor]:
        wind = torch.tensor([9.0], dtype=torch.float64, requires_grad=True)
        out = WaveField(wind, [4], wind_direction=0.7, dtype=torch.float64).sample(x, y, 2.5, footprint=f, crest=True)
        (g,) = torch.autograd.grad(out["slope_x"].sum(), wind)
        return {k: v.detach() for k, v in out.items()}, g

    two, g_two = run()
    torch.set_num_threads(1)
    one, g_one = run()
    for key in one:
        assert torch.equal(two[key], one[key]), key
    assert torch.allclose(g_two, g_one, rtol=1e-12, atol=0.0)


@pytest.mark.parametrize("extent, tol", [(1.0, 5e-5), (30.0, 1e-3)])
def test_float32_agrees_with_float64(extent, tol):
    """Same realization in both dtypes (draws float64 on the CPU, spectrum and phases float64, then
    cast): the tiles agree to ~2e-7; what remains is float32 rounding of the tile coordinate x·2/L_o,
    which grows with |x|/L_o (L = 0.196 m for the shortest band): ~1e-4 of the rms at |x| ≤ 30 m."""
    gen = torch.Generator().manual_seed(5)
    x = (torch.rand(2, 3000, generator=gen) * 2 - 1) * extent  # float32-representable coordinates
    y = (torch.rand(2, 3000, generator=gen) * 2 - 1) * extent
    kw = dict(wind_direction=torch.tensor([0.2, 1.3], dtype=torch.float64))
    wind = torch.tensor([7.0, 14.0], dtype=torch.float64)
    f32 = WaveField(wind, [1, 2], dtype=torch.float32, **kw).sample(x, y, 2.0)
    f64 = WaveField(wind, [1, 2], dtype=torch.float64, **kw).sample(x.double(), y.double(), 2.0)
    for key in f32:
        assert f32[key].dtype == torch.float32 and f64[key].dtype == torch.float64
        rms = float(f64[key].pow(2).mean().sqrt())
        assert float((f32[key].double() - f64[key]).abs().max()) < tol * rms, key


@pytest.mark.parametrize("direction", [math.pi / 2, -math.pi / 2, math.pi, 1.5 * math.pi])
def test_cardinal_wind_direction_rounded_to_float32_keeps_the_realization(direction):
    """Waves exactly across the wind tie on their travel sign (k · upwind = 0). A wind direction rounded to
    float32 (π/2 → cos = −4.4e-8) must not flip them: the realization of a seed is the same whether the
    direction comes as float64 or float32, to float32 rounding of the spectrum (it flipped the cross-wind
    waves' phases at π/2: 10 % of the elevation, 44 % of the slope across the wind)."""
    x = torch.linspace(5.0, 25.0, 1500, dtype=torch.float64)[None]
    y = 0.3 * x
    f64 = WaveField(15.0, 11, wind_direction=direction, dtype=torch.float64).sample(x, y, 3.0)
    f32dir = WaveField(15.0, 11, wind_direction=torch.tensor(direction, dtype=torch.float32).double(),
                       dtype=torch.float64).sample(x, y, 3.0)
    for key in f64:
        rms = float(f64[key].pow(2).mean().sqrt())
        assert float((f32dir[key] - f64[key]).abs().max()) < 1e-5 * rms, key


@pytest.mark.parametrize("a, b", [(-math.pi / 2, 1.5 * math.pi), (math.pi / 2, -1.5 * math.pi), (0.0, 2 * math.pi)])
def test_one_wind_direction_written_two_ways_is_one_realization(a, b):
    """A wind direction and the same direction plus 2π are one wind, so one seed draws one sea: the waves
    exactly across the wind take their travel sign from the crosswind part whatever the rounding of
    cos(direction) in float64 (cos(−π/2) = +6e-17, cos(3π/2) = −1.8e-16). With the tie at k · upwind = 0
    exactly (before 92ae01d), −π/2 and 3π/2 (and π/2, −3π/2) differed by 21 % of the elevation's rms (measured):
    2 of the 3 cases fail there (0 and 2π agreed already)."""
    x = torch.linspace(5.0, 25.0, 1500, dtype=torch.float64)[None]
    fa, fb = (WaveField(15.0, 11, wind_direction=d, dtype=torch.float64).sample(x, 0.3 * x, 3.0) for d in (a, b))
    for key in fa:
        rms = float(fa[key].pow(2).mean().sqrt())
        assert float((fa[key] - fb[key]).abs().max()) < 1e-9 * rms, key


def test_scene_field_is_the_same_realization_in_float32_and_float64():
    """``SeaScene.wave_field`` gives the same sea in a float32 and a float64 render (the scene's wind and
    direction reach the field in float64): crosswind, as the ray-tracer comparison renders it."""
    sc = SeaScene(wind_speed=15.0, wind_direction=math.pi / 2, sea_temperature=290.0, seed=11, time_s=3.0)
    x = torch.linspace(50.0, 600.0, 2000, dtype=torch.float64)[None]
    out = {dt: sc.wave_field(1, dt, torch.device("cpu")).sample(x.to(dt), (0.3 * x).to(dt), 3.0,
                                                                 footprint=torch.full_like(x, 0.5).to(dt))
           for dt in (torch.float32, torch.float64)}
    for key in out[torch.float64]:
        ref = out[torch.float64][key]
        assert float((out[torch.float32][key].double() - ref).abs().max()) < 1e-3 * float(ref.abs().max()), key


def test_seed_changes_realization_and_int_seed_equals_list():
    a = WaveField(9.0, 1, dtype=torch.float64)
    b = WaveField(9.0, [1], dtype=torch.float64)
    c = WaveField(9.0, torch.tensor([2]), dtype=torch.float64)
    x = torch.linspace(0, 30, 500, dtype=torch.float64)[None]
    assert torch.equal(a.sample(x, x)["slope_x"], b.sample(x, x)["slope_x"])
    assert not torch.allclose(a.sample(x, x)["slope_x"], c.sample(x, x)["slope_x"])


# ------------------------------------------------------------------------------------------------
# 6. Gradients
# ------------------------------------------------------------------------------------------------
def test_gradient_wrt_wind_speed_matches_central_difference():
    """d(mean square slope of the sample)/dU10 by autograd equals a float64 central difference
    (the random draws are fixed; the amplitudes √(F Δk²) are smooth in U10 at 10 m/s)."""
    gen = torch.Generator().manual_seed(6)
    x = torch.rand(2, 2000, generator=gen, dtype=torch.float64) * 100
    y = torch.rand(2, 2000, generator=gen, dtype=torch.float64) * 100
    fp = torch.full_like(x, 0.03)

    def mss(u: torch.Tensor) -> torch.Tensor:
        out = WaveField(u, [3, 4], wind_direction=0.5, dtype=torch.float64).sample(x, y, 1.0, footprint=fp)
        return (out["slope_x"] ** 2 + out["slope_y"] ** 2).mean()

    u = torch.tensor([10.0, 13.0], dtype=torch.float64, requires_grad=True)
    (grad,) = torch.autograd.grad(mss(u), u)
    assert bool(torch.isfinite(grad).all()) and bool((grad > 0).all())
    eps = 1e-4
    for i in range(2):
        du = torch.zeros(2, dtype=torch.float64)
        du[i] = eps
        fd = (mss(u.detach() + du) - mss(u.detach() - du)) / (2 * eps)
        assert float(grad[i]) == pytest.approx(float(fd), rel=1e-5)


def test_gradients_wrt_points_and_footprint_are_finite(dtype):
    gen = torch.Generator().manual_seed(7)
    x = (torch.rand(1, 500, generator=gen) * 40).to(dtype).requires_grad_()
    y = (torch.rand(1, 500, generator=gen) * 40).to(dtype).requires_grad_()
    fp = torch.cat([torch.full((1, 250), 0.02), torch.full((1, 250), math.inf)], 1).to(dtype).requires_grad_()
    wind = torch.tensor(9.0, dtype=dtype, requires_grad=True)
    out = WaveField(wind, 8, dtype=dtype).sample(x, y, 0.5, footprint=fp)
    (out["slope_x"].sum() + out["slope_y"].sum() + out["elevation"].sum()).backward()
    for t in (x, y, fp, wind):
        assert bool(torch.isfinite(t.grad).all())
    assert float(x.grad.abs().sum()) > 0 and float(wind.grad.abs()) > 0
    assert bool((out["slope_x"][:, 250:] == 0).all())  # infinite footprint: nothing resolved


# ------------------------------------------------------------------------------------------------
# 7. Errors
# ------------------------------------------------------------------------------------------------
@pytest.mark.parametrize(
    "kwargs, match",
    [
        (dict(wind_speed=0.0, seed=0), "wind_speed.*expectation"),
        (dict(wind_speed=-3.0, seed=0), r"wind_speed must lie in \(0, 80\]"),
        (dict(wind_speed=81.0, seed=0), r"wind_speed must lie in \(0, 80\]"),
        (dict(wind_speed=float("nan"), seed=0), "wind_speed"),
        (dict(wind_speed=torch.tensor([5.0, 6.0]), seed=0), "seed: an int seed"),
        (dict(wind_speed=torch.tensor([5.0, 6.0]), seed=[1, 2, 3]), r"seed, wind_speed.*batch sizes differ \(seed has 3, wind_speed has 2\)"),
        (dict(wind_speed=5.0, seed=-1), r"seed: each seed must lie in \[0, 2\*\*63\)"),
        (dict(wind_speed=5.0, seed=1.5), "seed must be an int"),
        (dict(wind_speed=5.0, seed=0, inverse_wave_age=0.5), r"inverse_wave_age must lie in \[0.84, 5\]"),
        (dict(wind_speed=5.0, seed=0, wind_direction=float("nan")), "wind_direction"),
        (dict(wind_speed=5.0, seed=0, dtype=torch.float16), "dtype"),
    ],
)
def test_constructor_errors(kwargs, match):
    with pytest.raises(ValueError, match=match):
        WaveField(**kwargs)


def test_sample_errors():
    field = WaveField(5.0, 0)
    x = torch.zeros(1, 4)
    with pytest.raises(ValueError, match=r"footprint must lie in \[0, inf\]"):
        field.sample(x, x, footprint=torch.tensor([[0.1, -0.1, 0.1, 0.1]]))
    with pytest.raises(ValueError, match=r"footprint must lie in \[0, inf\]"):
        field.sample(x, x, footprint=torch.tensor([[0.1, float("nan"), 0.1, 0.1]]))
    with pytest.raises(ValueError, match=r"footprint must lie in \[0, inf\]"):
        field.resolved_covariance(torch.tensor([-1.0]))
    with pytest.raises(ValueError, match="x must be finite"):
        field.sample(torch.tensor([[0.0, float("nan"), 0.0, 0.0]]), x)
    with pytest.raises(ValueError, match=r"x, y: must have shape \(B, \.\.\.\) with B = 1"):
        field.sample(torch.zeros(2, 4), torch.zeros(2, 4))
    with pytest.raises(ValueError, match="time_s"):
        field.sample(x, x, time_s=float("nan"))


# ------------------------------------------------------------------------------------------------
# 8. CUDA
# ------------------------------------------------------------------------------------------------
@pytest.mark.skipif(not torch.cuda.is_available(), reason="needs a CUDA device")
def test_cuda_realization_equals_cpu():
    gen = torch.Generator().manual_seed(9)
    x = torch.rand(2, 5000, generator=gen, dtype=torch.float64) * 100
    y = torch.rand(2, 5000, generator=gen, dtype=torch.float64) * 100
    fp = torch.full_like(x, 0.05)
    kw = dict(wind_direction=torch.tensor([0.1, 2.0], dtype=torch.float64), dtype=torch.float64)
    cpu = WaveField(torch.tensor([8.0, 16.0], dtype=torch.float64), [5, 6], **kw).sample(x, y, 1.5, footprint=fp)
    cuda = WaveField(torch.tensor([8.0, 16.0], dtype=torch.float64, device="cuda"), [5, 6], device="cuda", **kw).sample(
        x.cuda(), y.cuda(), 1.5, footprint=fp.cuda()
    )
    for key in cpu:
        assert cuda[key].device.type == "cuda"
        torch.testing.assert_close(cuda[key].cpu(), cpu[key], rtol=0, atol=1e-9 * float(cpu[key].abs().max()))


def _crest_gain_closed_form(k: torch.Tensor, k_p: float) -> torch.Tensor:
    """G(k) of the WaveField docstring written out: ω²/g × high pass at 4 k_p × low pass at 25 k_p."""
    q = (k / (4.0 * k_p)) ** 2
    return dispersion(k) ** 2 / 9.81 * q / torch.sqrt(1.0 + q**2) / torch.sqrt(1.0 + (k / (25.0 * k_p)) ** 4)


def test_crest_variance_peaks_at_the_breaking_scales():
    """X's variance per octave (band_crest_variance; the bands are octaves) is largest at the breaking
    crests' scales, 4–25 k_p (c ≈ 0.2–0.5 c_p: Melville & Matusov 2002; Gemmrich, Banner & Garrett
    2008), and the octave at the spectral peak holds < 5 % of that (closed form: ω⁴S flat per octave
    in the k⁻³ range, times the high pass (k_p/4k_p)⁴ ≈ 0.004 at k_p)."""
    for wind in (15.0, 25.0):
        field = WaveField(torch.tensor([wind], dtype=torch.float64), [7], dtype=torch.float64)
        k_p = 9.81 * 0.84**2 / wind**2
        v = field.band_crest_variance()[0]
        k_o = field.band_wavenumber.reshape(-1)[: v.shape[0]]
        top = int(v.argmax())
        assert 4.0 <= float(k_o[top]) / k_p <= 25.0, (wind, float(k_o[top]) / k_p)
        at_peak = int((k_o.log() - math.log(k_p)).abs().argmin())
        assert float(v[at_peak]) < 0.05 * float(v[top]), (wind, float(v[at_peak] / v[top]))


def _one_over_e(r: torch.Tensor, c: torch.Tensor) -> float:
    """First lag where the normalized correlation c(r) falls below 1/e (linear interpolation)."""
    i = int((c < math.exp(-1.0)).nonzero()[0])
    t = (c[i - 1] - math.exp(-1.0)) / (c[i - 1] - c[i])
    return float(r[i - 1] + t * (r[i] - r[i - 1]))


@pytest.mark.usefixtures("one_thread")
def test_crest_correlation_length_is_a_few_metres():
    """Whitecap patches are metres across: X's correlation length along the wind at 15 m/s (1/e of
    C(r) = ∫∫ S(k, φ) G(k)² cos(k r cos φ) k dk dφ, ECKV spectrum, closed-form G) is 1–6 m, and the
    sampled field's (8 realizations, 2 km lines, 0.25 m steps) agrees with it within 20 %."""
    wind = 15.0
    k_p = 9.81 * 0.84**2 / wind**2
    k = torch.logspace(math.log10(0.3 * k_p), math.log10(400 * k_p), 1500, dtype=torch.float64)
    phi = torch.linspace(-math.pi, math.pi, 361, dtype=torch.float64)[:-1]
    s = waves.elfouhaily_spectrum(k[:, None], phi[None, :], wind)  # (nk, nφ) [m⁴ rad⁻¹]
    wk = (k * _crest_gain_closed_form(k, k_p) ** 2 * torch.gradient(k)[0])[:, None] * s * (2 * math.pi / 360)
    r = torch.arange(0.0, 40.0, 0.25, dtype=torch.float64)
    c = torch.stack([(wk * torch.cos(k[:, None] * ri * torch.cos(phi)[None, :])).sum() for ri in r])
    length = _one_over_e(r, c / c[0])
    assert 1.0 < length < 6.0, length
    field = WaveField(torch.full((8,), wind, dtype=torch.float64), list(range(8)), dtype=torch.float64)
    x = torch.arange(0.0, 2000.0, 0.25, dtype=torch.float64).expand(8, -1)
    xs = field.sample(x, torch.zeros_like(x), 0.0, elevation=False, crest=True)["crest"]
    xs = xs - xs.mean(-1, keepdim=True)
    lags = range(r.shape[0])
    cs = torch.stack([(xs[:, : xs.shape[1] - j] * xs[:, j:]).mean() for j in lags])
    sampled = _one_over_e(r, cs / cs[0])
    assert abs(sampled / length - 1.0) < 0.2, (sampled, length)

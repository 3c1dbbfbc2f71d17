"""Whitecaps in time (roughsea_torch.whitecaps): the residual foam's deposit epochs and weights (closed
form), the cover's ensemble mean W (Monahan) whatever the footprint, the far field W exactly, the cover
in [0, 1], and its persistence: residual foam keeps a whitecap for seconds where the old instantaneous
crest cover (foam.crest_foam_fraction alone, the code before) forgets it within a wave period; and the
ensemble mean of textured storm renders with foam is the expectation image's."""

import math

import pytest
import torch

import roughsea_torch as rs
from roughsea_torch.foam import crest_foam_fraction, whitecap_fraction
from roughsea_torch.waves import WaveField
from roughsea_torch.whitecaps import (DEPOSIT_INTERVAL_S, RESIDUAL_DECAY_S, TRAILS_FROM, TRAILS_FULL, active_share,
                                     foam_state_radiances, skin_disrupted_radiance,
                                     deposit_epochs, whitecap_cover)

from conftest import make_cams

D = torch.float64


def test_deposit_epochs_are_fixed_in_time_and_exponentially_weighted():
    t = torch.tensor([3.3, 0.1, 7.0], dtype=D)
    ep, w = deposit_epochs(t)
    assert ep.shape == (3, 13)  # 3 τ_R / Δ + 1
    torch.testing.assert_close(ep[:, 0], torch.tensor([3.0, 0.0, 7.0], dtype=D))  # the last multiple of Δ ≤ t
    torch.testing.assert_close(torch.diff(ep, dim=1), torch.full((3, 12), -DEPOSIT_INTERVAL_S, dtype=D))
    torch.testing.assert_close(w.sum(-1), torch.ones(3, dtype=D))
    ratio = w[:, 1:] / w[:, :-1]  # consecutive epochs Δ apart: e^(−Δ/τ_R)
    torch.testing.assert_close(ratio, torch.full_like(ratio, math.exp(-DEPOSIT_INTERVAL_S / RESIDUAL_DECAY_S)))
    # within one interval the epochs do not move with t (a deposit stays laid)
    assert torch.equal(deposit_epochs(torch.tensor([3.01], dtype=D))[0], deposit_epochs(torch.tensor([3.49], dtype=D))[0])


def test_active_share_little_law():
    """a = τ_A/(τ_A + τ_R), τ_A = 0.3 T_b, T_b the period of the crest band's centre 10 k_p (√(4 k_p · 25 k_p)):
    T_b = T_p/√10 by deep-water dispersion; at 15 m/s, Ω = 0.84, T_p = 11.44 s, τ_A = 1.085 s, a = 0.352
    (planted: τ_A = 0.3 T_p, the peak's period, gives a = 0.632 and fails)."""
    a = active_share(torch.tensor([15.0], dtype=D), torch.tensor([0.84], dtype=D))
    tp = 2 * math.pi * 15.0 / (9.81 * 0.84)
    tau_a = 0.3 * tp / math.sqrt(10.0)
    assert float(a) == pytest.approx(tau_a / (tau_a + 2.0), rel=1e-3)
    assert float(a) == pytest.approx(0.352, abs=2e-3)


@pytest.fixture(scope="module")
def storm():
    torch.set_num_threads(1)
    wf = WaveField(wind_speed=torch.full((4,), 15.0, dtype=D), seed=[1, 2, 3, 4], dtype=D)
    g = torch.Generator().manual_seed(0)
    x = torch.rand(4, 600, generator=g, dtype=D) * 1500
    y = torch.rand(4, 600, generator=g, dtype=D) * 1500
    return wf, x, y, float(whitecap_fraction(torch.tensor(15.0, dtype=D)))


def _cover(wf, x, y, t, fp, w):
    t = torch.full((x.shape[0],), t, dtype=D)
    c = wf.sample_unchecked(x, y, t, fp, False, True)["crest"]
    fa, fr = whitecap_cover(wf, x, y, t, fp, c, wf.crest_variance(fp), wf.crest_variance()[:, None], torch.tensor(w, dtype=D))
    return fa, fr, c


def test_cover_mean_is_monahan_and_far_field_is_uniform(storm):
    """E[f] = W: 2 400 points of 4 seeds at 2 m footprints, within 12 % (measured 1.8 % off with 32 000
    points); each state in [0, 1]; a footprint resolving nothing gives W exactly."""
    wf, x, y, w = storm
    fa, fr, _ = _cover(wf, x, y, 3.3, torch.full_like(x, 2.0), w)
    f = fa + fr
    assert float(f.mean()) == pytest.approx(w, rel=0.12)
    assert float(f.min()) >= 0.0 and float(f.max()) <= 1.0 and float(fr.mean()) > 0.2 * w
    fa, fr, _ = _cover(wf, x[:, :50], y[:, :50], 3.3, torch.full((4, 50), 1e5, dtype=D), w)
    torch.testing.assert_close(fa + fr, torch.full_like(fa, w), rtol=1e-12, atol=0)


def test_residual_foam_persists(storm):
    """The cover at the same points 1 s later correlates at 0.30 (measured) against 0.14 for the
    instantaneous crest cover of the old code: whitecaps now leave foam that lasts seconds."""
    wf, x, y, w = storm
    fp = torch.full_like(x, 2.0)
    fa0, fr0, c0 = _cover(wf, x, y, 3.3, fp, w)
    fa1, fr1, c1 = _cover(wf, x, y, 4.3, fp, w)
    corr = lambda a, b: float(((a - a.mean()) * (b - b.mean())).mean() / (a.std() * b.std()))  # noqa: E731
    old = [crest_foam_fraction(c, wf.crest_variance(fp), wf.crest_variance()[:, None], w) for c in (c0, c1)]
    assert corr(fa0 + fr0, fa1 + fr1) > corr(*old) + 0.08


def test_rare_whitecaps_leave_no_trails_and_the_blend_is_continuous(storm):
    """Below TRAILS_FROM (W = 0.1 %) the residual foam is the breaking now: f_res = (1 − a) B and
    f_act = a B exactly, B the instantaneous crest cover (crest_foam_fraction, computed here); from
    TRAILS_FULL the residual is the trails' (1 s later it still correlates with now, unlike B); in
    between the residual is the smoothstep blend of the two (halfway in W: their mean, per point, the
    trails summed here from the deposit epochs and weights). Planted: the gate's share left at 1
    (trails at every W) fails the first check."""
    wf, x, y, _ = storm
    fp = torch.full_like(x, 2.0)
    a = active_share(wf.wind_speed, wf.inverse_wave_age)[:, None]
    lo = 0.5 * TRAILS_FROM
    fa, fr, c = _cover(wf, x, y, 3.3, fp, lo)
    b = crest_foam_fraction(c, wf.crest_variance(fp), _vt(wf), lo)
    torch.testing.assert_close(fa, a * b, rtol=1e-12, atol=1e-15)
    torch.testing.assert_close(fr, (1 - a) * b, rtol=1e-12, atol=1e-15)
    hi, mid = TRAILS_FULL, 0.5 * (TRAILS_FROM + TRAILS_FULL)
    _, fr_hi, _ = _cover(wf, x, y, 3.3, fp, hi)
    b_hi = crest_foam_fraction(c, wf.crest_variance(fp), _vt(wf), hi)
    assert float((fr_hi - (1 - a) * b_hi).abs().max()) > 0.05  # the trails differ from the breaking now
    _, fr_mid, _ = _cover(wf, x, y, 3.3, fp, mid)
    b_mid = crest_foam_fraction(c, wf.crest_variance(fp), _vt(wf), mid)
    assert float(fr_mid.sum()) > 0 and bool(torch.isfinite(fr_mid).all())
    # halfway the residual is the smoothstep (here 1/2) blend of the breaking now and the trails at that W
    with_trails = _residual_with_trails(wf, x, y, 3.3, fp, mid)
    torch.testing.assert_close(fr_mid, (1 - a) * 0.5 * (b_mid + with_trails), rtol=1e-10, atol=1e-14)


def _vt(wf):
    """σ_X² + s²: the threshold's total variance with the streak field (whitecaps: κ σ_X² more); at the 2 m
    footprints of these tests the streaks are averaged away (foam_streaks.resolved_share = 0 from two
    0.57 m cells across at 15 m/s), so only this variance, not ν itself, enters."""
    from roughsea_torch.whitecaps import STREAK_VARIANCE_SHARE

    return (1.0 + STREAK_VARIANCE_SHARE) * wf.crest_variance()[:, None]


def _residual_with_trails(wf, x, y, t, fp, w):
    """R (the trails alone) at W, from the deposit epochs and weights (module docstring's sum)."""
    from roughsea_torch.whitecaps import foam_drift

    t = torch.full((x.shape[0],), t, dtype=D)
    epochs, weights = deposit_epochs(t)
    vx, vy = (v[:, None] for v in foam_drift(wf.wind_speed, wf.wind_direction))
    r = torch.zeros_like(x)
    for j in range(epochs.shape[1]):
        age = (t - epochs[:, j])[:, None]
        c = wf.sample_unchecked(x - vx * age, y - vy * age, epochs[:, j], fp, False, True)["crest"]
        r = r + weights[:, j][:, None] * crest_foam_fraction(c, wf.crest_variance(fp), _vt(wf), w)
    return r


def test_textured_storm_ensemble_mean_is_the_expectation_with_foam():
    """16 realizations of a 20 m/s storm (whitecaps and residual foam on, LWIR, no path), a 15 m mast
    looking 8° down: the mean over seeds and sea pixels equals the expectation image's within 1e-3 of
    the radiance (measured −2.7e-5 for seeds 0–15 and +5.4e-4 for 16–31, opposite signs: sampling noise
    of a few large foam patches; without foam −6e-5 and −1e-4), and each row's within 1 % (measured
    2.2e-3 and 4.0e-3 with foam, 9e-4 without)."""
    cams = make_cams(24, 32, pitch_deg=-8.0, batch_size=16, hfov_deg=20.0, altitude_m=15.0)
    kw = dict(wind_speed=20.0, sea_temperature=290.0, path=False)
    tex = rs.render(cams, rs.SeaScene(**kw, seed=list(range(16)), time_s=2.3), table=rs.TableSize(foam_trails=True))
    mean = rs.render(cams, rs.SeaScene(**kw))
    sea = rs.view_geometry(cams).is_sea[:, None]
    assert abs(float(((tex - mean) * sea).sum() / (mean * sea).sum())) < 1e-3
    rows = (tex * sea).sum((0, 1, 3)) / sea.sum((0, 1, 3)).clamp_min(1)
    ref = (mean * sea).sum((0, 1, 3)) / sea.sum((0, 1, 3)).clamp_min(1)
    keep = sea.sum((0, 1, 3)) > 0
    assert float(((rows - ref).abs() / ref)[keep].max()) < 1e-2


@pytest.mark.parametrize("band", [rs.LWIR, rs.MWIR])
@pytest.mark.parametrize("dtype,tol", [(torch.float64, 1e-7), (torch.float32, 2e-4)])
def test_active_foam_is_brighter_than_residual_by_the_skin_deficit(band, dtype, tol):
    """Active whitecaps radiate at the bulk temperature (the cool skin mixed away, 0.2 K warmer), residual
    foam at the skin's: R_act − R_res = ε_f (B(T + 0.2 K) − B(T)) > 0 at every view angle, against the
    numpy reference (its own Fresnel, Planck band integral and emissivity excess); in brightness
    temperature the gap is ε_f × 0.2 K up to 40° (0.19 K at nadir LWIR, where ε_f = 0.99; near grazing
    the foam is colder, the Planck slope there smaller, and the same radiance gap reads larger in kelvin). Fails with the active state radiometrically the residual's (planted: R_act = R_res)."""
    from roughsea_torch.reference import foam as ref

    theta = torch.linspace(0.0, math.radians(89.0), 24, dtype=dtype)
    sky = 20.0 if band == rs.LWIR else 0.3
    rb = rs.band_radiance(torch.tensor(290.0, dtype=dtype), band)
    act, res = foam_state_radiances(theta, band, rb, torch.tensor(sky, dtype=dtype))
    lo_hi = tuple(band)
    want_act, want_res = ref.foam_state_radiances(theta.double().numpy(), lo_hi, 290.0, sky)
    torch.testing.assert_close(act.double(), torch.tensor(want_act), rtol=tol, atol=0)
    torch.testing.assert_close((act - res).double(), torch.tensor(want_act - want_res), rtol=50 * tol, atol=0)
    assert bool((act > res).all())
    gap = rs.brightness_temperature(act.double(), band) - rs.brightness_temperature(res.double(), band)
    eps = torch.tensor(ref.foam_emissivity(theta.double().numpy(), lo_hi))
    near = theta <= math.radians(40.0)  # where the foam's brightness temperature is near T (Planck slope alike)
    torch.testing.assert_close(gap[near], 0.2 * eps[near], rtol=0.05, atol=0)


@pytest.mark.parametrize("dtype,tol", [(torch.float64, 1e-9), (torch.float32, 1e-5)])
def test_skin_deficit_per_image_tensor_against_the_reference(dtype, tol):
    """skin_disrupted_radiance with a tensor ΔT_skin per image (0, 0.5 and 5 K, the range's ends): R_B(T + ΔT)
    of the numpy reference's Planck band integral at 290 K + ΔT; at ΔT = 0 the skin's radiance bit for bit,
    and dR/dΔT = dR_B/dT(T + ΔT) there too (a numpy central difference of the reference, to 1e-6;
    a shortcut returning the input at 0 would give 0). foam_state_radiances refuses a tensor deficit
    outside [0, 5] K, naming deficit_k."""
    from roughsea_torch.reference import planck

    band = tuple(rs.LWIR)
    rb = rs.band_radiance(torch.full((3,), 290.0, dtype=dtype), rs.LWIR)
    d = torch.tensor([0.0, 0.5, 5.0], dtype=dtype, requires_grad=True)
    bulk = skin_disrupted_radiance(rb, rs.LWIR, d)
    want = planck.band_radiance(290.0 + d.detach().double().numpy(), band)
    torch.testing.assert_close(bulk.double(), torch.tensor(want), rtol=tol, atol=0)
    assert torch.equal(bulk[0], rb[0])
    (grad,) = torch.autograd.grad(bulk.sum(), d)
    t = 290.0 + d.detach().double().numpy()
    slope = (planck.band_radiance(t + 1e-3, band) - planck.band_radiance(t - 1e-3, band)) / 2e-3
    torch.testing.assert_close(grad.double(), torch.tensor(slope), rtol=1e-6 if dtype == torch.float64 else 1e-3, atol=0)
    with pytest.raises(ValueError, match=r"^deficit_k must lie in \[0, 5\] K"):
        foam_state_radiances(torch.zeros(3, dtype=dtype), rs.LWIR, rb, torch.tensor(20.0, dtype=dtype),
                             deficit_k=torch.tensor([0.2, 0.2, 5.5], dtype=dtype))


def test_foam_state_gradients_are_finite():
    """d/dT_sea and d/dU of a textured storm's foam radiance mean, float32 and float64, at a grazing view."""
    for dtype in (torch.float32, torch.float64):
        t = torch.tensor(290.0, dtype=dtype, requires_grad=True)
        theta = torch.tensor([0.3, 1.4, 1.5690], dtype=dtype)
        act, res = foam_state_radiances(theta, rs.LWIR, rs.band_radiance(t, rs.LWIR), torch.tensor(20.0, dtype=dtype))
        u = torch.tensor([15.0], dtype=torch.float64, requires_grad=True)
        a = active_share(u, torch.tensor([0.84], dtype=torch.float64)).to(dtype)
        (res + a * (act - res)).sum().backward()
        assert torch.isfinite(t.grad) and torch.isfinite(u.grad).all() and float(t.grad) > 0


def test_textured_ensemble_mean_weights_the_two_states_as_the_expectation():
    """With an exaggerated skin deficit (4 K, so that the states differ by ~4 % of the radiance), the
    mean over 12 realizations of a 20 m/s storm's sea pixels (default covers, no trails) equals the
    expectation image's, whose foam is a R_act + (1 − a) R_res, within 1e-3 (measured 4.3e-5; the
    sampling error of the test above); an expectation with the residual's radiance alone is 4e-3 off
    (planted: a = 0 in renderer.foam_terms.active_share_of_images fails)."""
    cams = make_cams(16, 24, pitch_deg=-8.0, batch_size=12, hfov_deg=20.0, altitude_m=15.0)
    kw = dict(wind_speed=20.0, sea_temperature=290.0, path=False, skin_deficit=4.0)
    tex = rs.render(cams, rs.SeaScene(**kw, seed=list(range(40, 52)), time_s=0.7))
    mean = rs.render(cams, rs.SeaScene(**kw))
    sea = rs.view_geometry(cams).is_sea[:, None]
    assert abs(float(((tex - mean) * sea).sum() / (mean * sea).sum())) < 1e-3


@pytest.mark.parametrize("trails", [False, True])
def test_cover_of_a_seed_is_the_same_in_float32_at_large_times(trails):
    """The foam cover of one realization is a property of the sea, not of the render's dtype: float32 and
    float64 fields of one seed (20 m/s, streaks resolved: no footprint) at the same 2 000 points agree to
    float32 rounding (measured ≤ 3e-5 in cover at 0–1e8 s; bound 1e-3) at every time, including 1e6 and
    1e8 s, where the streak field has drifted 0.7 m/s × t, 5e5–5e7 streak widths. Planted (the old code):
    the drift velocity and the streaks' direction rounded to float32 moved the float32 streaks by v t ×
    6e-8: cover differences 0.2–0.5 at 1e6 s and 1.0 at 1e8 s (the other streaks), 1e-4 at t = 0; fails."""
    torch.set_num_threads(1)
    g = torch.Generator().manual_seed(0)
    x = (torch.rand(1, 2000, generator=g, dtype=D) * 100).float()  # points both dtypes hold exactly
    y = (torch.rand(1, 2000, generator=g, dtype=D) * 100).float()
    w = float(whitecap_fraction(torch.tensor(20.0, dtype=D)))
    fields = {dt: WaveField(wind_speed=20.0, wind_direction=0.7, seed=5, dtype=dt) for dt in (torch.float32, D)}

    def cover(dt, t):
        wf, xs, ys, ts = fields[dt], x.to(dt), y.to(dt), torch.tensor([t], dtype=D)
        c = wf.sample_unchecked(xs, ys, ts, None, False, True)["crest"]
        fa, fr = whitecap_cover(wf, xs, ys, ts, None, c, wf.crest_variance(), wf.crest_variance()[:, None],
                                torch.tensor(w, dtype=dt), trails=trails)
        return (fa + fr).double()

    for t in (0.0, 1e6 + 0.3, 1e8 + 0.3):
        f64 = cover(D, t)
        assert 0.05 < float(f64.mean()) < 0.2  # foam at these points: the check below is not on zeros
        assert float((cover(torch.float32, t) - f64).abs().max()) < 1e-3, t


def _full_noise(monkeypatch):
    """whitecaps' streak field read everywhere (its ``below`` dropped): the cover without the skip."""
    import roughsea_torch.whitecaps as wc
    read = wc.streak_noise
    monkeypatch.setattr(wc, "streak_noise", lambda *a, below=None, **k: read(*a, **k))


@pytest.mark.parametrize("dtype", [torch.float32, torch.float64])
def test_cover_without_trails_is_unchanged_by_skipping_the_streaks(dtype, monkeypatch):
    """Without trails whitecap_cover reads ν only where it can lift the cover off exactly 0
    (foam.vanishing_crest); the covers are bitwise those with ν read at every point, on 40 000 points at
    5–20 cm footprints (10 m/s, 2 images), where the skip leaves out many points (63 % in float32, 19 %
    in float64); and they do not depend on the block size (2¹⁵ point-evaluations; 1024 here). Fails
    with the skip's bound on erfc's argument at 8 instead of 11 (float32) or 25 instead of 28 (float64)
    (planted: covers that should be nonzero are 0)."""
    import roughsea_torch.foam_streaks as fs
    import roughsea_torch.whitecaps as wc
    wf = WaveField(wind_speed=torch.full((2,), 10.0, dtype=D), seed=[3, 4], dtype=dtype)
    g = torch.Generator().manual_seed(2)
    x = (torch.rand(2, 20000, generator=g, dtype=D) * 300).to(dtype)
    y = (torch.rand(2, 20000, generator=g, dtype=D) * 300).to(dtype)
    fp = (0.05 + 0.15 * torch.rand(2, 20000, generator=g, dtype=D)).to(dtype)
    t = torch.tensor([2.0, 3.5], dtype=D)
    c = wf.sample_unchecked(x, y, t, fp, False, True, slopes=False)["crest"]
    w = whitecap_fraction(torch.tensor(10.0, dtype=dtype))

    def cover():
        return whitecap_cover(wf, x, y, t, fp, c, wf.crest_variance(fp), wf.crest_variance()[:, None], w, trails=False)

    computed = []
    read = fs.streak_noise
    monkeypatch.setattr(wc, "streak_noise", lambda *a, **k: computed.append(read(*a, **k)) or computed[-1])
    skipped = cover()
    share = float(torch.cat([(v == 0).flatten() for v in computed]).double().mean())
    assert share > (0.5 if dtype == torch.float32 else 0.1)
    assert 0.0 < float((skipped[0] + skipped[1]).mean()) < 0.1
    monkeypatch.setattr(wc, "_COVER_BLOCK", 1024)
    blocks = cover()
    _full_noise(monkeypatch)
    full = cover()
    for s, b, f in zip(skipped, blocks, full):
        assert torch.equal(s, f) and torch.equal(b, f)


def test_first_hit_render_is_unchanged_by_skipping_the_streaks(monkeypatch):
    """A first-hit render (the sweep's samples, and the flat point's covers) with foam, 10 m/s, 15 m mast
    6° down, float32, is bitwise the render with the streak field read at every sample. An end-to-end
    guard: a bound that skips points whose cover would be below 1e-7 leaves a float32 render as it is
    (the test above catches those); fails with the bound 3 units of ν too high (planted)."""
    cams = make_cams(40, 48, hfov_deg=12.0, altitude_m=15.0, pitch_deg=-6.0, dtype=torch.float32)
    scene = rs.SeaScene(wind_speed=10.0, sea_temperature=290.0, seed=11, time_s=3.0)
    table = rs.TableSize(texture_hit="first")
    skipped = rs.render(cams, scene, table=table)
    _full_noise(monkeypatch)
    assert torch.equal(rs.render(cams, scene, table=table), skipped)

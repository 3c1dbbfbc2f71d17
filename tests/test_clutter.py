"""The two-scale textured sea (roughsea_torch.clutter, render with seed=): its ensemble mean is the
expectation image, the second law holds per realization, the far field is the expectation, the
texture table matches the per-pixel evaluation, and realizations are deterministic and
differentiable."""

import math

import numpy as np
import pytest
import torch

import roughsea_torch as rs
from roughsea_torch.clutter import unresolved_statistics, visible_slope
from roughsea_torch.expectation import apparent_radiance

def sky(c):
    return 10.0 + 20.0 * (1.0 - c) ** 4


def _mixture(th_deg, transport, n=80, dtype=torch.float64):
    """E over the resolved slope of the pixel radiance, by Gauss–Hermite over x ~ N(0, 1)."""
    th, ph = torch.tensor(math.radians(th_deg), dtype=dtype), torch.tensor(0.7, dtype=dtype)
    vx, vy, cxy = (torch.tensor(v, dtype=dtype) for v in (0.02, 0.012, 0.003))
    var_a, kap = torch.tensor(0.009, dtype=dtype), torch.tensor(0.2, dtype=dtype)
    x, w = np.polynomial.hermite_e.hermegauss(n)
    x, w = torch.tensor(x, dtype=dtype), torch.tensor(w / w.sum(), dtype=dtype)
    c, s = torch.cos(ph), torch.sin(ph)
    suu = vx * c * c + 2 * cxy * c * s + vy * s * s
    if transport:
        ap = visible_slope(x[None], torch.cos(th)[None], torch.sin(th)[None], var_a.sqrt()[None], (suu - var_a).sqrt()[None])[0]
    else:  # the naive flat-point sample: every tilt weighted equally
        ap = var_a.sqrt() * x
    stats = unresolved_statistics(vx, vy, cxy, ph, var_a, kap, ap)
    mix = (w * apparent_radiance(th, ph, stats, sea_radiance=30.0, sky=sky)).sum()
    total = apparent_radiance(th, ph, rs.SlopeStatistics.from_variances(vx, vy, cxy), sea_radiance=30.0, sky=sky)
    return float(mix / total - 1.0)


@pytest.mark.parametrize("th_deg", [40.0, 75.0, 85.0, 88.0, 89.5])
def test_visible_slope_makes_the_mixture_the_expectation(th_deg):
    """∫ N(x) R(a'(x)) dx = R_a(Σ): the Eq. 5 weighting of the resolved slope (docs/texture.md §6)."""
    assert abs(_mixture(th_deg, True)) < 2e-6


def test_naive_flat_point_sampling_is_biased_towards_grazing():
    """Without the visible-slope map the mean is off, more so towards grazing (the classic bias the
    map removes): this is what the ensemble test below would catch."""
    b75, b88 = abs(_mixture(75.0, False)), abs(_mixture(88.0, False))
    assert b75 > 1e-4 and b88 > 3 * b75


def _cams(B, H=40, W=12, pitch=-6.0, alt=10.0, dtype=torch.float64, hfov=8.0):
    return rs.make_camera(H, W, hfov_deg=hfov, altitude_m=alt, pitch_deg=pitch, batch_size=B, dtype=dtype)


def _scene(seed, **kw):
    base = dict(wind_speed=8.0, sea_temperature=290.0, sky=sky, path=False)
    base.update(kw)
    return rs.SeaScene(seed=seed, **base)


def test_ensemble_mean_equals_the_expectation_image_row_by_row():
    """Mean over 320 independent realizations (one seed each), per row of view zenith, against the
    expectation image (same table settings): consistent with zero at 4 standard errors of the
    sample, within 1e-3 relative (5e-3 beyond 88°), and the sample fine enough to see the classic
    bias of flat-point sampling (-1.1e-3 to -2.3e-3 here, 4-6 standard errors; plant
    ``visible_slope = lambda x, ct, st, sr, su: sr[..., None] * x`` to watch this test fail).
    ``pipelines/clutter_statistics.py`` runs 2048 realizations (4 standard errors < 7e-4)."""
    B, H = 320, 48
    table = rs.TableSize(zenith=13, azimuth=5, texture=7)
    cams = _cams(64, H=H, pitch=-7.0)
    img = torch.cat([rs.render(cams, _scene(list(range(1000 + i, 1064 + i))), table=table)[:, 0] for i in range(0, B, 64)])
    mean = rs.render(_cams(1, H=H, pitch=-7.0), _scene(None), table=table)[0, 0]
    g = rs.view_geometry(_cams(1, H=H, pitch=-7.0))
    sea = g.is_sea[0].all(1)
    vz = torch.rad2deg(g.view_zenith[0, :, 6])
    per_image = img.mean(2)  # (B, H): one row mean per independent realization
    bias = per_image.mean(0) / mean.mean(1) - 1.0
    se = per_image.std(0) / math.sqrt(B) / mean.mean(1)
    texture = (img - mean).std(0).mean(1) / mean.mean(1)
    rows = sea & (texture > 1e-4)  # rows where the texture is visible
    assert int(rows.sum()) >= 15
    tol = torch.where(vz <= 88.0, 1e-3, 5e-3)
    assert bool((bias.abs()[rows] < 4 * se[rows] + 1e-4).all()), (bias[rows], se[rows])
    assert bool((bias.abs()[rows] < tol[rows]).all()), (bias[rows], vz[rows])
    assert bool((4 * se[rows] < 2.5e-3).all())
    assert float(texture[rows].max()) > 3e-3  # the texture is real: 0.3 % is ~0.2 K in LWIR


def test_second_law_per_realization():
    """A sky at the sea's blackbody radiance: every pixel of every realization is R_B."""
    cams = _cams(2, pitch=-10.0)
    rb = 27.5
    img = rs.render(cams, rs.SeaScene(wind_speed=10.0, sea_radiance=rb, sky=rb, path=False, seed=[5, 6], time_s=1.5))
    g = rs.view_geometry(cams)
    assert torch.allclose(img[:, 0][g.is_sea], torch.full_like(img[:, 0][g.is_sea], rb), rtol=1e-12, atol=0)


def test_far_field_is_the_expectation_image():
    """Where the footprint is far larger than the longest waves (a narrow view of the horizon band
    from 20 m, ranges of tens of km), the textured image is the expectation image."""
    cams = rs.make_camera(16, 16, hfov_deg=0.5, altitude_m=20.0, pitch_deg=-0.15, batch_size=1, dtype=torch.float64)
    g = rs.view_geometry(cams)
    assert bool(g.is_sea.any())
    tex = rs.render(cams, _scene([3]))
    mean = rs.render(cams, _scene(None))
    # equal but for rounding: the expectation render reads its table through a cheaper azimuth
    # coordinate (renderer.coordinates.azimuth_ratio) than the textured one (the angle): 4e-12 apart here
    assert torch.allclose(tex, mean, rtol=1e-11, atol=0)
    # and the same scene seen from nearer does carry texture (the check above is not vacuous)
    near = _cams(1, pitch=-6.0)
    tex, mean = rs.render(near, _scene([3])), rs.render(near, _scene(None))
    assert float((tex - mean).abs().max() / mean.max()) > 3e-3


def test_one_int_seed_gives_each_image_its_own_derived_seed():
    """seed=int with B > 1 images: image i is the realization of SeedSequence((seed, i)) (documented
    in SeaScene), so images differ from each other and from the neighbouring int seed's."""
    cams2 = _cams(2, pitch=-8.0)
    pair = rs.render(cams2, _scene(5))
    assert float((pair[0] - pair[1]).abs().max()) > 1e-4
    derived = int(np.random.SeedSequence((5, 1)).generate_state(1, np.uint64)[0] >> 1)
    alone = rs.render(_cams(1, pitch=-8.0), _scene([derived]))
    assert torch.equal(pair[1], alone[0])
    other = rs.render(cams2, _scene(6))
    assert float((pair[1] - other[0]).abs().max()) > 1e-4


def test_texture_table_matches_per_pixel_evaluation():
    """An interpolation-accuracy check (both methods share the pixel physics of clutter.py, which the
    mixture and ensemble tests check against the expectation): the texture volume against the
    per-pixel two-scale evaluation (method='direct'): within 1.5 %
    of the texture's own amplitude at worst (0.58 % measured), 0.3 % on average (0.057 %), and
    within 3e-4 of the radiance (1.4e-4). With the mean table's 21 ζ nodes it was 5 % (texture_zenith)."""
    cams = _cams(2, H=24, W=16, pitch=-6.0, hfov=12.0)
    sc = _scene([11, 12], time_s=torch.tensor([0.0, 2.0], dtype=torch.float64))
    table = rs.render(cams, sc)
    direct = rs.render(cams, sc, method="direct")
    mean = rs.render(cams, _scene(None))
    amp = (direct - mean).abs().max()
    err = (table - direct).abs()
    assert float(amp / mean.max()) > 3e-3
    assert float(err.max()) < 0.015 * float(amp)
    assert float(err.mean()) < 0.003 * float(amp)
    assert float(err.max() / direct.max()) < 3e-4


@pytest.mark.parametrize("dtype", [torch.float64, torch.float32])
@pytest.mark.parametrize("wind,pitch,hfov,bound", [(8.0, -90.0, 30.0, 0.2), (15.0, -90.0, 30.0, 0.2),
                                                   (15.0, -70.0, 60.0, 0.12)])
def test_texture_table_matches_per_pixel_evaluation_looking_steeply_down(wind, pitch, hfov, bound, dtype):
    """Looking steeply down (20 m up, pitch −90°, 30° field of view: θ̂ < 20°) the texture is a few
    mK; the table render matches per-pixel evaluation to 0.2 of the texture's standard deviation
    (0.065–0.085 measured). At pitch −70° with a 60° field of view (θ̂ 1–49°) the nodes take both
    rules, within 0.12 (0.053 measured). Both parts of the texture nodes' rule are needed
    (TableSize.texture_quadrature_width, texture_quadrature_steep): planted, the model's own 7.5σ
    window (float64; float32's is 6σ) with the (12, 16) rule left 13–29 std at −90°; the 4.5σ
    window with (12, 16) for the steep nodes left 0.6 std at −90° and 15 m/s, and 0.20 at −70°
    (as does the mixed case with the rules swapped)."""
    cams = rs.make_camera(24, 32, hfov_deg=hfov, altitude_m=20.0, pitch_deg=pitch, dtype=dtype)

    def scene(seed):
        return rs.SeaScene(wind_speed=torch.tensor(wind, dtype=dtype), sea_temperature=290.0, wind_direction=0.3,
                           seed=seed, time_s=1.5, foam=0.0)

    table, direct = (rs.render(cams, scene(12), method=m, output="brightness_temperature").double()
                     for m in ("table", "direct"))
    mean = rs.render(cams, scene(None), output="brightness_temperature").double()
    std = float((direct - mean).std())
    assert std > 1e-3  # there is a texture to get right
    assert float((table - direct).abs().max()) < bound * std


def test_gradient_where_the_texture_nodes_take_both_rules():
    """Pitch −70° with a 60° field of view: the texture's steep and grazing nodes are evaluated apart
    and put back together; the wind gradient of the image mean matches a central difference
    (3.033e-1 both, in review) to 1e-5."""
    cams = rs.make_camera(24, 32, hfov_deg=60.0, altitude_m=20.0, pitch_deg=-70.0, dtype=torch.float64)

    def mean(w):
        return rs.render(cams, rs.SeaScene(wind_speed=w, sea_temperature=290.0, wind_direction=0.3, seed=12,
                                           time_s=1.5, foam=0.0), output="brightness_temperature").mean()

    w = torch.tensor(15.0, dtype=torch.float64, requires_grad=True)
    g, = torch.autograd.grad(mean(w), w)
    h = 1e-4
    fd = (mean(torch.tensor(15.0 + h, dtype=torch.float64)) - mean(torch.tensor(15.0 - h, dtype=torch.float64))) / (2 * h)
    assert math.isfinite(float(g)) and abs(float(g) - float(fd)) < 1e-5 * max(1.0, abs(float(fd)))


@pytest.mark.parametrize("method", ["table", "direct"])
def test_float32_renders_keep_the_wave_time_in_float64(method):
    """The wave phases ω t take the time in float64 in float32 renders too: at t = 1e6 s a float32
    time rounds to 1/16 s, and 25 Hz frames came out identical (found by a new user). Now frames
    1/25 s apart differ as in float64 (mean 7.7 mK here, the two within 1e-4 of each other), and
    float32 matches float64 to 2e-3 K (2.4e-4 measured), by the table and per pixel. render_clip
    adds the frame times in float64 too: a float32 tensor time_s of 1e6 s gives the steps of a
    Python float (it made two frames identical, found in review). Planted, the float32 time: the
    float32 step is 57 % off float64's."""
    out = {}
    for dtype in (torch.float32, torch.float64):
        cams = rs.make_camera(16, 20, hfov_deg=20.0, altitude_m=10.0, pitch_deg=-8.0, dtype=dtype)
        scene = rs.SeaScene(wind_speed=6.0, sea_temperature=290.0, seed=3, foam=0.0)
        out[dtype] = rs.render_clip(cams, scene, torch.tensor([0.0, 0.04]), start_s=1e6, method=method,
                                    output="brightness_temperature")[0, :, 0].double()
    step32 = (out[torch.float32][1] - out[torch.float32][0]).abs().mean()
    step64 = (out[torch.float64][1] - out[torch.float64][0]).abs().mean()
    assert float(step64) > 3e-3
    assert abs(float(step32 / step64) - 1.0) < 0.05
    assert float((out[torch.float32] - out[torch.float64]).abs().max()) < 2e-3
    cams = rs.make_camera(16, 20, hfov_deg=20.0, altitude_m=10.0, pitch_deg=-8.0, dtype=torch.float64)
    tensor_time = rs.SeaScene(wind_speed=6.0, sea_temperature=290.0, seed=3, foam=0.0, time_s=torch.tensor([1e6]))
    clip = rs.render_clip(cams, tensor_time, torch.tensor([0.0, 0.04, 0.08]), method=method)[0, :, 0]
    steps = (clip[1:] - clip[:-1]).abs().flatten(1).mean(1)
    assert float(steps.min()) > 0.5 * float(steps.max())


def test_realization_depends_on_seed_and_time_only():
    """Image i of a batch equals the same seed rendered alone (any batch split); other seeds or times
    give other images."""
    cams3 = _cams(3, pitch=-8.0)
    sc3 = _scene([21, 22, 23], time_s=torch.tensor([0.0, 0.5, 1.0], dtype=torch.float64))
    batch = rs.render(cams3, sc3)
    alone = rs.render(_cams(1, pitch=-8.0), _scene([22], time_s=0.5))
    assert torch.allclose(batch[1], alone[0], rtol=1e-12, atol=0)
    other = rs.render(_cams(1, pitch=-8.0), _scene([22], time_s=0.6))
    assert float((other - alone).abs().max()) > 1e-6


@pytest.mark.parametrize("threads", [1, 2])
def test_images_of_a_batch_with_their_own_winds_and_poses_equal_the_images_alone(threads):
    """The texture's nodes are evaluated for groups of images and sliced per chunk of pixels: image
    i of a batch of 5, each with its own wind, direction, altitude, pitch and roll, equals image i
    rendered alone and the batch rendered in one chunk (nodes and pixels together), to 1e-12."""
    n = torch.get_num_threads()
    torch.set_num_threads(threads)
    try:
        kw = dict(altitude_m=torch.tensor([6.0, 14.0, 9.0, 25.0, 11.0], dtype=torch.float64),
                  pitch_deg=torch.tensor([-7.0, -4.0, -9.0, -3.0, -6.0], dtype=torch.float64),
                  roll_deg=torch.tensor([0.0, 2.0, -1.5, 1.0, -3.0], dtype=torch.float64))
        cams = rs.make_camera(20, 12, hfov_deg=8.0, batch_size=5, dtype=torch.float64, **kw)
        wind = torch.tensor([5.0, 9.0, 13.0, 7.0, 11.0], dtype=torch.float64)
        wd = torch.tensor([0.0, 0.7, -1.2, 2.5, -2.9], dtype=torch.float64)
        sc = _scene([31, 32, 33, 34, 35], wind_speed=wind, wind_direction=wd)
        batch = rs.render(cams, sc)
        together = rs.render(cams, sc, chunk=5)
        assert torch.allclose(batch, together, rtol=1e-12, atol=0)
        for i in range(5):
            one = rs.make_camera(20, 12, hfov_deg=8.0, batch_size=1, dtype=torch.float64,
                                 **{k: v[i : i + 1] for k, v in kw.items()})
            alone = rs.render(one, _scene([31 + i], wind_speed=float(wind[i]), wind_direction=float(wd[i])))
            assert torch.allclose(batch[i], alone[0], rtol=1e-12, atol=0), i
    finally:
        torch.set_num_threads(n)


def test_float32_agrees_with_float64():
    c64, c32 = _cams(1, pitch=-8.0), _cams(1, pitch=-8.0, dtype=torch.float32)
    a = rs.render(c64, _scene([7], time_s=3.0))
    b = rs.render(c32, _scene([7], time_s=3.0))
    assert b.dtype == torch.float32
    assert float(((b.double() - a) / a).abs().max()) < 2e-5


def _objective(method, wind, t_sea, pitch):
    cams = rs.make_camera(12, 8, hfov_deg=8.0, altitude_m=10.0, pitch_deg=pitch, batch_size=1, dtype=torch.float64)
    sc = rs.SeaScene(wind_speed=wind, sea_temperature=t_sea, sky=sky, path=False, seed=[4], time_s=1.0)
    img = rs.render(cams, sc, method=method)
    return (img * torch.linspace(0.5, 1.5, 12, dtype=torch.float64)[:, None]).sum()


def test_gradients_flow_through_the_texture():
    """d(textured image)/d(wind, sea temperature, pitch), per pixel (method='direct'), equal to a
    central difference (1e-6; pitch 1e-4: the wave field is read bilinearly from its tiles, so the
    image is piecewise smooth in the points' positions); the table method's gradients equal the
    per-pixel ones within 0.5 % (0.06 % for pitch with 129 fine texture planes in x, 1.5 % with 33:
    the piecewise-linear x-interpolant's slope carries the pose gradient; a central difference of the table itself also moves its nodes,
    which follow the pose and the slope law, and with them its interpolation error)."""
    x = [torch.tensor(v, dtype=torch.float64, requires_grad=True) for v in (7.0, 290.0, -8.0)]
    g_direct = torch.autograd.grad(_objective("direct", *x), x)
    g_table = torch.autograd.grad(_objective("table", *x), x)
    for i, (h, rtol) in enumerate(((1e-4, 1e-6), (1e-3, 1e-6), (1e-4, 1e-4))):
        xp = [v.detach().clone() for v in x]
        xm = [v.detach().clone() for v in x]
        xp[i] += h
        xm[i] -= h
        fd = float((_objective("direct", *xp) - _objective("direct", *xm)) / (2 * h))
        assert math.isfinite(float(g_direct[i])) and math.isfinite(float(g_table[i]))
        assert abs(float(g_direct[i]) - fd) < rtol * abs(fd) + 1e-9, (i, g_direct[i], fd)
        assert abs(float(g_table[i]) - fd) < 5e-3 * abs(fd), (i, g_table[i], fd)


@pytest.mark.parametrize("which", [0, 1])
def test_gradient_of_the_table_render_with_respect_to_one_scene_parameter_alone(which):
    """d(textured table image)/d(wind) or d/d(sea temperature) with a fixed pose (only the scene
    requires grad, so the pixels' grids do not): finite, equal to the gradient taken together with
    the pitch, and to the per-pixel method's central difference within 0.5 % as above. (The texture
    volume's second read reused its grid in place whenever the grid itself needed no gradient, which
    broke the backward pass of exactly this case.)"""
    x = [torch.tensor(v, dtype=torch.float64) for v in (7.0, 290.0, -8.0)]
    x[which].requires_grad_(True)
    (g,) = torch.autograd.grad(_objective("table", *x), [x[which]])
    both = [v.detach().clone().requires_grad_(i in (which, 2)) for i, v in enumerate(x)]
    g_both = torch.autograd.grad(_objective("table", *both), [both[which]])[0]
    h = (1e-4, 1e-3)[which]
    xp = [v.detach().clone() for v in x]
    xm = [v.detach().clone() for v in x]
    xp[which] += h
    xm[which] -= h
    fd = float((_objective("direct", *xp) - _objective("direct", *xm)) / (2 * h))
    assert math.isfinite(float(g))
    assert abs(float(g) - float(g_both)) < 1e-9 * abs(float(g_both))
    assert abs(float(g) - fd) < 5e-3 * abs(fd), (float(g), fd)


def test_pose_gradient_is_finite_with_the_horizon_in_view():
    """A textured default scene (LOWTRAN sky, path, foam) with the horizon in view: d/d(pitch) of a
    weighted image sum is finite for both methods (it was NaN for both: reconcile_scale took √ of a
    zero discriminant where nothing is resolved, the sky pixels and the far field), the per-pixel
    method's equals its central difference to 1e-4 (1e-5 measured), and the table's is within 3 % of
    it (1.9 % measured: near the horizon the table's interpolation error moves with the pose)."""
    w = torch.linspace(0.5, 1.5, 16, dtype=torch.float64)[:, None]

    def objective(p, method):
        cams = rs.make_camera(16, 20, hfov_deg=20.0, dtype=torch.float64, altitude_m=10.0, pitch_deg=p)
        img = rs.render(cams, rs.SeaScene(wind_speed=6.0, sea_temperature=290.0, seed=[3], time_s=1.0), method=method)
        return (img[0, 0] * w).sum()

    assert bool((~rs.view_geometry(rs.make_camera(16, 20, hfov_deg=20.0, dtype=torch.float64, altitude_m=10.0,
                                                  pitch_deg=-5.0)).is_sea).any())
    grads = {}
    for method in ("direct", "table"):
        pitch = torch.tensor(-5.0, dtype=torch.float64, requires_grad=True)
        (grads[method],) = torch.autograd.grad(objective(pitch, method), pitch)
        assert math.isfinite(float(grads[method])), method
    h = 1e-4
    fd = float(objective(torch.tensor(-5.0 + h, dtype=torch.float64), "direct")
               - objective(torch.tensor(-5.0 - h, dtype=torch.float64), "direct")) / (2 * h)
    assert abs(float(grads["direct"]) - fd) < 1e-4 * abs(fd)
    assert abs(float(grads["table"]) - float(grads["direct"])) < 0.03 * abs(float(grads["direct"]))


def test_resolved_plus_unresolved_covariance_is_the_slope_law():
    """The synthesized slopes at a footprint (empirical, many points and seeds) plus the unresolved
    covariance the renderer uses equal SlopeStatistics (anisotropic Cox–Munk), upwind and
    crosswind, within 2 %."""
    from roughsea_torch.waves import WaveField

    wind, wd = 9.0, 0.4
    law = rs.SlopeStatistics.cox_munk(wind, anisotropic=True)
    g = torch.Generator().manual_seed(0)
    wf = WaveField(torch.full((8,), wind, dtype=torch.float64), list(range(8)), wind_direction=wd, dtype=torch.float64)
    xy = 400.0 * torch.rand(2, 8, 4000, generator=g, dtype=torch.float64)
    L = torch.full((8, 4000), 0.3, dtype=torch.float64)
    smp = wf.sample(xy[0], xy[1], 0.0, footprint=L, elevation=False)
    c, s = math.cos(wd), math.sin(wd)
    up = smp["slope_x"] * c + smp["slope_y"] * s  # to the upwind, crosswind frame
    cross = -smp["slope_x"] * s + smp["slope_y"] * c
    phi = torch.tensor(0.9, dtype=torch.float64)  # any line of sight: the split is exact for each
    cov = wf.resolved_covariance(L[:, :1])
    ex, ey = math.cos(0.9 + wd), math.sin(0.9 + wd)
    from roughsea_torch.clutter import along_view

    var_a, kap = along_view(tuple(v.mean() for v in cov), torch.tensor(ex, dtype=torch.float64), torch.tensor(ey, dtype=torch.float64))
    un = unresolved_statistics(torch.tensor(law.var_upwind), torch.tensor(law.var_crosswind), torch.tensor(0.0), phi, var_a, kap,
                               torch.tensor(0.0, dtype=torch.float64))
    # the resolved part the pixel takes as geometry is a (ê + κ ê⊥); the rest of the synthesized
    # slopes is statistical: empirical total = Var(resolved along the regression line) + Σ_u
    ea = torch.tensor([math.cos(0.9), math.sin(0.9)], dtype=torch.float64)
    w = ea + kap * torch.tensor([-math.sin(0.9), math.cos(0.9)], dtype=torch.float64)
    a = up * ea[0] + cross * ea[1]
    emp_var_a = a.var()
    total_up = emp_var_a * w[0] ** 2 + un.var_upwind
    total_cross = emp_var_a * w[1] ** 2 + un.var_crosswind
    assert abs(float(total_up / law.var_upwind) - 1) < 0.02
    assert abs(float(total_cross / law.var_crosswind) - 1) < 0.02
    assert abs(float(emp_var_a / var_a - 1)) < 0.05  # and the field has the variance the renderer assumes


def test_textured_scene_needs_wind_speed_and_valid_seed():
    with pytest.raises(ValueError, match="wind_speed"):
        rs.SeaScene(slopes=rs.SlopeStatistics.cox_munk(5.0), sea_temperature=290.0, seed=1)
    with pytest.raises(ValueError, match="seed"):
        rs.SeaScene(wind_speed=5.0, sea_temperature=290.0, seed=-1)
    with pytest.raises(ValueError, match="seed"):
        rs.SeaScene(wind_speed=5.0, sea_temperature=290.0, seed=1.5)


def test_visible_slope_grid_error_against_a_finer_grid():
    """clutter.visible_slope's default 1025-node grid against a 16-times finer one, over random
    quantiles within ±4.5, σ_a 0.01–0.21, σ_u 0.005–0.205, cos θ̂ 0.001–1 (its docstring's figures):
    median error 3e-5 σ_a, worst 1.6e-3 σ_a (grazing, σ_u ≪ σ_a, deep in the tail where the visible
    density nearly vanishes). This seeded sample of 300: median 2.7e-5 σ_a, worst 3.1e-4 σ_a; asserted
    1e-4 and 1e-3 (a 257-node grid, planted, gives 4.4e-4 and 5.0e-3)."""
    from roughsea_torch.clutter import visible_slope

    g = torch.Generator().manual_seed(0)
    n = 300
    x = torch.randn(n, 9, generator=g, dtype=torch.float64).clamp(-4.5, 4.5)
    ct = 0.001 + 0.999 * torch.rand(n, generator=g, dtype=torch.float64)
    st = torch.sqrt(1 - ct ** 2)
    sr = 0.01 + 0.2 * torch.rand(n, generator=g, dtype=torch.float64)
    su = 0.005 + 0.2 * torch.rand(n, generator=g, dtype=torch.float64)
    err = (visible_slope(x, ct, st, sr, su) - visible_slope(x, ct, st, sr, su, nodes=16385)).abs() / sr[:, None]
    assert float(err.median()) < 1e-4
    assert float(err.max()) < 1e-3


@pytest.mark.parametrize("dtype", [torch.float64, torch.float32])
def test_resolved_quantile_is_the_normalized_slope_ratio(dtype):
    """x = a/σ_a with a = s·ê, σ_a² = êᵀCê, ê = −(dx, dy)/|(dx, dy)| (the closed form, written out
    here), for random slopes, covariances (correlated, anisotropic) and ray directions of any
    length; x = 0 with a zero gradient where nothing is resolved (σ_a² of 1e-31 or 0, where
    rsqrt's derivative would overflow)."""
    from roughsea_torch.clutter import resolved_quantile

    g = torch.Generator().manual_seed(7)
    n = 2000
    sx, sy = torch.randn(2, n, generator=g, dtype=torch.float64) * 0.1
    a_ = torch.rand(n, generator=g, dtype=torch.float64) * 0.05 + 1e-4
    b_ = torch.rand(n, generator=g, dtype=torch.float64) * 0.05 + 1e-4
    r = (torch.rand(n, generator=g, dtype=torch.float64) * 2 - 1) * 0.95
    cov = (a_, b_, r * torch.sqrt(a_ * b_))
    ang = torch.rand(n, generator=g, dtype=torch.float64) * 2 * math.pi
    length = 10.0 ** (torch.rand(n, generator=g, dtype=torch.float64) * 6 - 3)
    dx, dy = length * torch.cos(ang), length * torch.sin(ang)
    ex, ey = -torch.cos(ang), -torch.sin(ang)
    want = (sx * ex + sy * ey) / torch.sqrt(cov[0] * ex * ex + 2 * cov[2] * ex * ey + cov[1] * ey * ey)
    got = resolved_quantile(*(t.to(dtype) for t in (sx, sy)), tuple(c.to(dtype) for c in cov), dx.to(dtype), dy.to(dtype))
    # float32: the inputs' own rounding, through covariances correlated up to |r| = 0.95
    tol = 1e-12 if dtype == torch.float64 else 1e-5
    assert float(((got.double() - want).abs() / (1.0 + want.abs())).max()) < tol
    for v in (0.0, 1e-31):
        c = torch.full((3,), v, dtype=dtype, requires_grad=True)
        s_ = torch.tensor(1e-16, dtype=dtype, requires_grad=True)
        x = resolved_quantile(s_, torch.zeros((), dtype=dtype), (c[0], c[1], c[2] * 0), torch.tensor(1.0, dtype=dtype),
                              torch.tensor(0.5, dtype=dtype))
        grads = torch.autograd.grad(x, (c, s_))
        assert float(x.detach()) == 0.0 and all(bool((gr == 0).all()) for gr in grads)


def test_scaling_warning_points_at_the_callers_line():
    """Where the spectrum resolves more slope variance than the slope law allows (2 m/s, a 3 m mast
    looking 30° down through a 10° lens: centimetre footprints), render() warns once, from the
    calling thread, at the caller's line (it pointed into concurrent.futures when a worker raised it)."""
    cams = rs.make_camera(32, 40, altitude_m=3.0, pitch_deg=-30.0, hfov_deg=10.0, batch_size=2)
    old = torch.get_num_threads()
    try:
        torch.set_num_threads(2)  # two chunks on the worker threads
        with pytest.warns(UserWarning, match="resolved slopes are scaled down") as rec:
            rs.render(cams, rs.SeaScene(wind_speed=2.0, sea_temperature=290.0, seed=[1, 2]))
    finally:
        torch.set_num_threads(old)
    assert len(rec) == 1 and rec[0].filename == __file__

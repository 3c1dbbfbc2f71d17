"""Textured seas in renders (roughsea_torch.renderer.texture, render with seed=): the second law per
realization, the far field is the expectation, the texture table matches the per-pixel two-scale
evaluation, realizations are deterministic (seed and time only), float32 agrees with float64, and
gradients flow through the texture. (The two-scale model itself: tests/test_clutter.py.)"""

from __future__ import annotations

import math
import warnings

import pytest
import torch

import roughsea_torch as rs
from roughsea_torch.renderer.antialias import FOAM_TAPS, filter_columns
from roughsea_torch.clutter import along_view, footprint, two_scale_statistics
from roughsea_torch.renderer.swept import _across_quantile
from roughsea_torch.renderer.texture import TextureTable
from roughsea_torch.whitecaps import whitecap_cover

from conftest import horizon_sky, make_cams, make_scene, torch_threads


def _cams(B, H=40, W=12, pitch=-6.0, alt=10.0, dtype=torch.float64, hfov=8.0):
    """The textured tests' cameras: B narrow views from 10 m, 40 × 12 pixels, looking 6° down."""
    return make_cams(H, W, hfov_deg=hfov, altitude_m=alt, pitch_deg=pitch, batch_size=B, dtype=dtype)


def _scene(seed, **kw):
    """A textured sea (seed=) under the textured tests' sky, without the path."""
    return make_scene(**{"sky": horizon_sky, "path": False, "seed": seed, **kw})


def test_second_law_per_realization():
    """A sky at the sea's blackbody radiance (and active foam at the skin's temperature, no skin deficit:
    one temperature everywhere): every pixel of every realization is R_B."""
    cams = _cams(2, pitch=-10.0)
    rb = 27.5
    img = rs.render(cams, rs.SeaScene(wind_speed=10.0, sea_radiance=rb, sky=rb, path=False, seed=[5, 6], time_s=1.5,
                                      skin_deficit=0.0))
    g = rs.view_geometry(cams)
    assert torch.allclose(img[:, 0][g.is_sea], torch.full_like(img[:, 0][g.is_sea], rb), rtol=1e-12, atol=0)


def test_far_field_is_the_expectation_image():
    """Where the footprint is far larger than the longest waves (a narrow view of the horizon band
    from 20 m, ranges of tens of km), the textured image is the expectation image."""
    cams = make_cams(16, 16, hfov_deg=0.5, pitch_deg=-0.15, batch_size=1)
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
    cams = make_cams(hfov_deg=hfov, pitch_deg=pitch, dtype=dtype)

    def scene(seed):
        return make_scene(wind_speed=torch.tensor(wind, dtype=dtype), wind_direction=0.3, seed=seed, time_s=1.5,
                          foam=0.0)

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
    cams = make_cams(hfov_deg=60.0, pitch_deg=-70.0)

    def mean(w):
        return rs.render(cams, make_scene(wind_speed=w, wind_direction=0.3, seed=12, time_s=1.5, foam=0.0),
                         output="brightness_temperature").mean()

    w = torch.tensor(15.0, dtype=torch.float64, requires_grad=True)
    g, = torch.autograd.grad(mean(w), w)
    h = 1e-4
    fd = (mean(torch.tensor(15.0 + h, dtype=torch.float64)) - mean(torch.tensor(15.0 - h, dtype=torch.float64))) / (2 * h)
    assert math.isfinite(float(g)) and abs(float(g) - float(fd)) < 1e-5 * max(1.0, abs(float(fd)))


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
    with torch_threads(threads):
        kw = dict(altitude_m=torch.tensor([6.0, 14.0, 9.0, 25.0, 11.0], dtype=torch.float64),
                  pitch_deg=torch.tensor([-7.0, -4.0, -9.0, -3.0, -6.0], dtype=torch.float64),
                  roll_deg=torch.tensor([0.0, 2.0, -1.5, 1.0, -3.0], dtype=torch.float64))
        cams = make_cams(20, 12, hfov_deg=8.0, batch_size=5, **kw)
        wind = torch.tensor([5.0, 9.0, 13.0, 7.0, 11.0], dtype=torch.float64)
        wd = torch.tensor([0.0, 0.7, -1.2, 2.5, -2.9], dtype=torch.float64)
        sc = _scene([31, 32, 33, 34, 35], wind_speed=wind, wind_direction=wd)
        batch = rs.render(cams, sc)
        together = rs.render(cams, sc, chunk=5)
        assert torch.allclose(batch, together, rtol=1e-12, atol=0)
        for i in range(5):
            one = make_cams(20, 12, hfov_deg=8.0, batch_size=1, **{k: v[i : i + 1] for k, v in kw.items()})
            alone = rs.render(one, _scene([31 + i], wind_speed=float(wind[i]), wind_direction=float(wd[i])))
            assert torch.allclose(batch[i], alone[0], rtol=1e-12, atol=0), i


def test_float32_agrees_with_float64():
    c64, c32 = _cams(1, pitch=-8.0), _cams(1, pitch=-8.0, dtype=torch.float32)
    a = rs.render(c64, _scene([7], time_s=3.0))
    b = rs.render(c32, _scene([7], time_s=3.0))
    assert b.dtype == torch.float32
    assert float(((b.double() - a) / a).abs().max()) < 2e-5


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
        cams = make_cams(16, 20, hfov_deg=20.0, altitude_m=10.0, pitch_deg=-8.0, dtype=dtype)
        scene = make_scene(wind_speed=6.0, seed=3, foam=0.0)
        out[dtype] = rs.render_clip(cams, scene, torch.tensor([0.0, 0.04]), start_s=1e6, method=method,
                                    output="brightness_temperature")[0, :, 0].double()
    step32 = (out[torch.float32][1] - out[torch.float32][0]).abs().mean()
    step64 = (out[torch.float64][1] - out[torch.float64][0]).abs().mean()
    assert float(step64) > 3e-3
    assert abs(float(step32 / step64) - 1.0) < 0.05
    assert float((out[torch.float32] - out[torch.float64]).abs().max()) < 2e-3
    cams = make_cams(16, 20, hfov_deg=20.0, altitude_m=10.0, pitch_deg=-8.0)
    tensor_time = make_scene(wind_speed=6.0, seed=3, foam=0.0, time_s=torch.tensor([1e6]))
    clip = rs.render_clip(cams, tensor_time, torch.tensor([0.0, 0.04, 0.08]), method=method)[0, :, 0]
    steps = (clip[1:] - clip[:-1]).abs().flatten(1).mean(1)
    assert float(steps.min()) > 0.5 * float(steps.max())


def _objective(method, wind, t_sea, pitch):
    cams = make_cams(12, 8, hfov_deg=8.0, altitude_m=10.0, pitch_deg=pitch, batch_size=1)
    sc = make_scene(wind_speed=wind, sea_temperature=t_sea, sky=horizon_sky, path=False, seed=[4], time_s=1.0)
    img = rs.render(cams, sc, method=method)
    return (img * torch.linspace(0.5, 1.5, 12, dtype=torch.float64)[:, None]).sum()


def test_gradients_flow_through_the_texture():
    """d(textured image)/d(wind, sea temperature, pitch), per pixel (method='direct'), equal to a
    central difference (1e-6; pitch 1e-5 with a step of 1e-5°: the wave field is read bilinearly from its
    tiles, so the image is piecewise smooth in the points' positions, and a step of 1e-4° already crosses
    texel edges: 1.6e-4 off on seed 4); the table method's gradients equal the
    per-pixel ones within 0.5 % (0.06 % for pitch with 129 fine texture planes in x, 1.5 % with 33:
    the piecewise-linear x-interpolant's slope carries the pose gradient; a central difference of the table itself also moves its nodes,
    which follow the pose and the slope law, and with them its interpolation error)."""
    x = [torch.tensor(v, dtype=torch.float64, requires_grad=True) for v in (7.0, 290.0, -8.0)]
    g_direct = torch.autograd.grad(_objective("direct", *x), x)
    g_table = torch.autograd.grad(_objective("table", *x), x)
    for i, (h, rtol) in enumerate(((1e-4, 1e-6), (1e-3, 1e-6), (1e-5, 1e-5))):
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
        cams = make_cams(16, 20, hfov_deg=20.0, altitude_m=10.0, pitch_deg=p)
        img = rs.render(cams, make_scene(wind_speed=6.0, seed=[3], time_s=1.0), method=method)
        return (img[0, 0] * w).sum()

    assert bool((~rs.view_geometry(make_cams(16, 20, hfov_deg=20.0, altitude_m=10.0, pitch_deg=-5.0)).is_sea).any())
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


def test_scaling_warning_points_at_the_callers_line(two_threads):
    """Where the spectrum resolves much more slope variance than the slope law allows (0.8 m/s, a 3 m
    mast looking 30° down through a 10° lens: centimetre footprints, resolved slopes scaled by less
    than SCALE_WARNING), render() warns once, from the calling thread, at the caller's line (it
    pointed into concurrent.futures when a worker raised it). A milder scaling (3 m/s, the same
    camera: λ ≈ 0.9) renders without a warning."""
    cams = make_cams(32, 40, altitude_m=3.0, pitch_deg=-30.0, hfov_deg=10.0, batch_size=2, dtype=torch.float32)
    with pytest.warns(UserWarning, match="resolved slopes are scaled down") as rec:  # two threads: two chunks on the workers
        rs.render(cams, make_scene(wind_speed=0.8, seed=[1, 2]))
    assert len(rec) == 1 and rec[0].filename == __file__
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        rs.render(cams, make_scene(wind_speed=3.0, seed=[1, 2]))


def test_textured_day_with_the_lowtran_day_sky_matches_per_pixel_and_keeps_the_sky():
    """A textured MWIR sea under the LOWTRAN day sky (the scattered sky differs by azimuth, so the
    mean's table takes TableSize.azimuth_day azimuth nodes and the texture its own, fewer,
    TableSize.texture_azimuth_sun): the sky pixels are the expectation image's (3.6e-8; they were
    0.6 % low: the crest-foam mix took a whitecap fraction W of each sky pixel from the foam
    channel's sky, which lacks the scattered sky), and the sea pixels match per-pixel evaluation to
    2e-3 (7.3e-4 measured, 1.0e-3 before the texture nodes' window was cut to 4.5σ; the texture's
    nodes at the mean's azimuths shifted by π/2, planted, give 4e-2). The 7e-4 is at glint pixels,
    which reflect the sky's bright aureole about the sun: there the texture's departure from the
    mean is sharp both in slope and in azimuth, and two of the texture's discretizations share it
    (against a converged per-pixel render, 80×80 quadrature, 7.0e-4): the nodes' rule
    (TableSize.texture_quadrature (20, 16) alone: 4.5e-4) and their azimuths (17 with
    fine_texture_azimuth=64 alone: 6.9e-4); both give 2.4e-4 (asserted below 4e-4; the azimuths
    alone, planted, fail) at 1.7x the time of a textured day render (docs/bench_texture.md); the
    default keeps the cheaper nodes. With an explicit rs.Sun (no day sky) the default
    gives 8e-5, with the sun behind the cameras 1.8e-5, in LWIR 2e-5."""
    cams = make_cams(hfov_deg=40.0, altitude_m=15.0, yaw_deg=torch.tensor([0.0, 30.0], dtype=torch.float64), batch_size=2)

    def scene(seed):
        return make_scene(wind_speed=torch.tensor([5.0, 10.0]), wind_direction=torch.tensor([0.4, -1.0]), band=rs.MWIR,
                          sun_zenith=math.radians(72.0), sun_azimuth=0.2, seed=seed)

    table, direct, mean = rs.render(cams, scene([1, 2])), rs.render(cams, scene([1, 2]), method="direct"), rs.render(cams, scene(None))
    sea = rs.view_geometry(cams).is_sea[:, None]
    assert bool((~sea).any()) and bool(sea.any())
    assert float(((table - mean) / mean)[~sea].abs().max()) < 1e-6
    assert float(((table - direct) / direct)[sea].abs().max()) < 2e-3
    assert float(((direct - mean) / mean)[sea].abs().max()) > 0.1  # the sea carries texture and glint
    fine = rs.TableSize(texture_quadrature=(20, 16), texture_azimuth_sun=17, fine_texture_azimuth=64)
    refined = rs.render(cams, scene([1, 2]), table=fine)
    assert float(((refined - direct) / direct)[sea].abs().max()) < 4e-4


def test_texture_table_returns_the_pixels_crest(monkeypatch):
    """With crest=True the texture pass also returns each pixel's foam fraction f_pix: the image is
    bitwise unchanged; f_pix is the active plus residual cover (whitecaps.whitecap_cover) of the field's
    crest variable at the pixel's flat-sea point and footprint (as the per-pixel path computes them), with σ_r² tabulated on the
    texture's rows (within 0.2 % of crest_variance at the footprint, so f_pix within 2e-3), in [0, 1],
    0 off the sea."""
    def sky(c):
        return 10.0 + 20.0 * (1.0 - c) ** 4

    cams = rs.make_camera(24, 16, hfov_deg=12.0, altitude_m=10.0, pitch_deg=-6.0, batch_size=2, dtype=torch.float64)
    times = torch.tensor([0.0, 2.0], dtype=torch.float64)
    # the renderer asks for no crest (foam=False), the wrapper below forces it with W = 0.2
    scene = rs.SeaScene(wind_speed=8.0, sea_temperature=290.0, sky=sky, path=False, seed=[11, 12], time_s=times,
                        foam=False)
    with torch_threads(1):
        reference = rs.render(cams, scene)
    captured = []
    original = TextureTable.pixels
    w = torch.tensor(0.2, dtype=torch.float64)  # a whitecap fraction large enough to saturate crests

    def with_crest(self, *args, **kwargs):
        assert kwargs.pop("crest", False) is False
        foam = self.p.foam
        self.p.foam = w.expand(self.B)
        try:
            result = original(self, *args, crest=True, **kwargs)
        finally:
            self.p.foam = foam
        assert len(result) == 4 and result[3] is not None
        captured.append(result[3][0] + result[3][1])  # the active and residual covers
        return result[:3] + (None,)

    monkeypatch.setattr(TextureTable, "pixels", with_crest)
    with torch_threads(1):  # the chunks one after the other: the wrapper changes the table's foam for its call
        image = rs.render(cams, scene)
    monkeypatch.undo()
    assert torch.equal(image, reference) and captured
    f_pix = torch.cat(captured)
    assert f_pix.shape == (2, 24, 16)

    geom = rs.view_geometry(cams)
    sea = geom.is_sea
    field = scene.wave_field(2, torch.float64, torch.device("cpu"))
    centres = -(cams.rotation_matrix.transpose(-1, -2) @ cams.translation_vector)[..., 0]
    cos_t = geom.cos_view_zenith.clamp_min(1e-9)
    R = torch.where(sea, geom.range_m, torch.ones_like(cos_t))
    L = footprint(R, cos_t, (1.0 / cams.fx)[:, None, None])
    xw, yw = centres[:, 0, None, None] + R * geom.dx, centres[:, 1, None, None] + R * geom.dy
    s = field.sample(xw, yw, times, footprint=L, elevation=False, crest=True)
    f_act, f_res = whitecap_cover(field, xw, yw, times, L, s["crest"], field.crest_variance(L),
                                  field.crest_variance()[:, None, None], w, trails=False)  # TableSize.foam_trails
    direct = f_act + f_res
    direct = filter_columns(torch.where(sea, direct, torch.zeros_like(direct)), sea, FOAM_TAPS)  # TableSize.texture_antialias
    assert float((f_pix - direct)[sea].abs().max()) < 2e-3
    assert bool(((f_pix >= 0) & (f_pix <= 1)).all()) and bool((f_pix[~sea] == 0).all())
    assert float(f_pix[sea].max()) > 0.3  # foam present: the comparison covers the edges


def test_textured_table_matches_per_pixel_evaluation_with_an_air_temperature():
    """A named atmosphere with its air temperature raised 6 K (the sky and path radiances scaled by
    B(T_air)/B(T_atm), scenes.md): the texture volume's reflected sky carries the same scale as the
    per-pixel evaluation (method='direct'), to the texture table's accuracy: within 1.5 % of the
    texture's own amplitude and 3e-4 of the radiance (tests/test_clutter.py's bounds)."""
    cams = rs.make_camera(24, 16, hfov_deg=12.0, altitude_m=10.0, pitch_deg=-6.0, batch_size=2, dtype=torch.float64)

    def scene(seed):
        return rs.SeaScene(wind_speed=8.0, sea_temperature=290.0, sky="midlatitude_summer", path=False,
                           air_temperature=torch.tensor([300.0, 291.0], dtype=torch.float64), seed=seed,
                           time_s=torch.tensor([0.0, 2.0], dtype=torch.float64))

    table, direct = (rs.render(cams, scene([11, 12]), method=m) for m in ("table", "direct"))
    mean = rs.render(cams, scene(None))
    amp = (direct - mean).abs().max()
    err = (table - direct).abs()
    assert float(amp / mean.max()) > 3e-3
    assert float(err.max()) < 0.015 * float(amp)
    assert float(err.max() / direct.max()) < 3e-4


def _across_view_basis(phi, cov_world, wind_direction):
    """Independently of the renderer: ê = (cos φ, sin φ), ê⊥ = ê turned +90°, and the resolved covariance C
    in that frame's axes (rotated by −wind_direction from the world), with σ_a² = êᵀCê, κ_r = ê⊥ᵀCê/σ_a² and
    the residual variance σ_r² = ê⊥ᵀCê⊥ − κ_r² σ_a² of the across-view slope given the along-view one."""
    c, s = math.cos(wind_direction), math.sin(wind_direction)
    rot = torch.tensor([[c, s], [-s, c]], dtype=torch.float64)
    C = rot @ cov_world @ rot.T
    e = torch.tensor([math.cos(phi), math.sin(phi)], dtype=torch.float64)
    ep = torch.tensor([-math.sin(phi), math.cos(phi)], dtype=torch.float64)
    var_a = e @ C @ e
    kap = (ep @ C @ e) / var_a
    return C, e, ep, var_a, kap, ep @ C @ ep - kap * kap * var_a


@pytest.mark.parametrize("phi_hat", [1.2, -0.9, 2.5])
def test_across_view_columns_put_the_resolved_residual_into_the_mean(phi_hat):
    """The first hit's across-view columns (TableSize.texture_hit_cross): at y = ±√3 the unresolved Gaussian
    is N(a (ê + κ_r ê⊥) + y σ_r ê⊥, Σ − C) exactly (Σ the total, C the resolved covariance: the residual
    c_r = y σ_r leaves the covariance and enters the mean, ê⊥ = ê turned +90°, ê the line of sight
    sea → sensor at φ̂ from upwind), built here from the closed form in the (ê, ê⊥) basis. Planted, ê⊥ with
    the other sign in ``_cross_columns``: the means miss by 2√3 σ_r ≈ 0.3 in slope, and the test fails."""
    D = torch.float64
    t = lambda v: torch.tensor(v, dtype=D)  # noqa: E731
    vx, vy, cxy, wd = t(0.0190), t(0.0140), t(0.0015), 0.4
    cov_world = torch.tensor([[0.0060, 0.0025], [0.0025, 0.0080]], dtype=D)
    C, e, ep, var_a, kap, var_r = _across_view_basis(phi_hat, cov_world, wd)
    ph, phw = t([phi_hat]), t([[phi_hat + wd]])
    cov = tuple(v.reshape(1, 1, 1) for v in (cov_world[0, 0], cov_world[1, 1], cov_world[0, 1]))
    va, kp = along_view(cov, torch.cos(phw)[:, None, :], torch.sin(phw)[:, None, :])  # (1, 1, 1)
    x = t([[0.7]])
    st = two_scale_statistics(vx, vy, cxy, ph, t([0.1]), x, va.reshape(1), kp.reshape(1), visible=x)
    moments = [torch.as_tensor(m, dtype=D).expand(1, 1) for m in (st.var_upwind, st.var_crosswind, st.cov,
                                                                   st.mean_upwind, st.mean_crosswind)]
    moments = [torch.cat([m, m], 1) for m in moments]  # the x column and the expectation's (unused here)
    out = TextureTable._cross_columns(moments, cov, phw, va, kp, lambda v: v.reshape(1), ph, 1)
    su = torch.tensor([[vx, cxy], [cxy, vy]], dtype=D) - C
    a = 0.7 * var_a.sqrt()
    for col, y in ((2, -math.sqrt(3.0)), (3, math.sqrt(3.0))):
        mean = a * (e + kap * ep) + y * var_r.sqrt() * ep
        got = [float(m[0, col]) for m in out]
        want = [float(su[0, 0]), float(su[1, 1]), float(su[0, 1]), float(mean[0]), float(mean[1])]
        assert got == pytest.approx(want, abs=1e-12), (col, got, want)
    assert float(torch.linalg.eigvalsh(su).min()) > 0  # the unresolved law stays a proper Gaussian


@pytest.mark.parametrize("dtype", [torch.float32, torch.float64])
def test_across_quantile_reads_the_residual_of_a_constructed_slope(dtype):
    """y = c_r/σ_r at the sweep's samples: a resolved slope built as s = a ê + (κ_r a + y σ_r) ê⊥ (ê = −(dx, dy)
    the horizontal direction towards the sensor, ê⊥ = ê turned +90°, a = x σ_a; κ_r, σ_r from the resolved
    covariance in closed form) gives back y, whatever the length of (dx, dy). Planted: y with the other sign
    (ê⊥ turned −90°), or the regression κ_r a left in c_r: fails."""
    wd = 0.0  # the sample's world frame is its own
    cov_world = torch.tensor([[0.0060, 0.0025], [0.0025, 0.0080]], dtype=torch.float64)
    for az in (0.3, 2.0, -2.6):
        C, e, ep, var_a, kap, var_r = _across_view_basis(az + math.pi, cov_world, wd)  # ê = −(cos az, sin az)
        y = torch.linspace(-3.0, 3.0, 13, dtype=torch.float64)
        x = torch.linspace(-2.0, 2.5, 13, dtype=torch.float64).flip(0)
        a = x * var_a.sqrt()
        s = a[:, None] * e + (kap * a + y * var_r.sqrt())[:, None] * ep
        d = torch.tensor([math.cos(az), math.sin(az)], dtype=torch.float64) * 2.5  # camera → sea, not unit
        got = _across_quantile(s[:, 0].to(dtype), s[:, 1].to(dtype), tuple(v.to(dtype) for v in (C[0, 0], C[1, 1], C[0, 1])),
                               d[0].to(dtype), d[1].to(dtype), x.to(dtype))
        tol = 1e-10 if dtype == torch.float64 else 1e-4
        torch.testing.assert_close(got.double(), y, rtol=0, atol=tol)


@pytest.mark.parametrize("hit", ["flat", "first", "direct"])
def test_textured_sea_without_shadowing_near_grazing_warns(hit):
    """Without shadowing (Eq. 7) the facet weight divides by the mean facet's projected area
    e = cos θ̂ + sin θ̂ m∥, which a resolved tilt turns ≤ 0 near grazing: a textured render 3° down from 15 m
    then holds radiances of ±8e9 W m⁻² sr⁻¹. The render says so (a UserWarning naming shadowing=False,
    pointing at the caller's line); 45° down, where every node's e stays > 0, it does not. ``method="direct"``
    (one flat-point quantile per pixel) checks its pixels' own e. (Planted: the check skipped, no warning,
    and the first case fails; for "direct": the pixel check removed, it fails.)"""
    kw = dict(wind_speed=10.0, sea_temperature=290.0, seed=3, shadowing=False)
    steep, grazing = (rs.make_camera(32, 48, hfov_deg=12.0, altitude_m=15.0, pitch_deg=p) for p in (-45.0, -3.0))
    how = dict(method="direct") if hit == "direct" else dict(table=rs.TableSize(texture_hit=hit))
    with pytest.warns(UserWarning, match="shadowing=False") as record:
        img = rs.render(grazing, rs.SeaScene(**kw), **how)
    nonsense = float(img.abs().max()) > 1e3 or float(img.min()) < 0.0  # (direct: negative radiances, to −75)
    assert record[0].filename == __file__ and nonsense  # the nonsense it warns of
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        rs.render(steep, rs.SeaScene(**kw), **how)

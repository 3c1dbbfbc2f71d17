"""The brute-force ray tracer (``roughsea_torch.raytrace``): first hits, bounds, radiometric identities.

Plants tried once each (the code edited, the tests run and seen to fail, the edit reverted):
- the march bracketing the *last* crossing into the surface before the slab's bottom instead of the
  first: ``test_first_hit_behind_a_crest`` (hit 37 m beyond the analytic point) and
  ``test_first_hit_of_descending_rays_on_a_face`` fail;
- the hit replaced by the flat-sea point (what the renderer samples): ``test_first_hit_behind_a_crest``
  (18.6 m off) and ``test_hit_facets_face_the_camera`` (27 % of the facets face away) fail;
- a mirrored ray that points into the sea taking the sky at its (negative) cos zenith instead of R_B
  (``_specular``): ``test_rays_into_the_sea_never_see_the_sky`` fails (2222 against R_B = 32.5);
- the sub-pixel points stratified (one per sub-square of the pixel) instead of i.i.d.:
  ``test_sampling_variance_estimates_the_noise`` fails (ratio 0.24: the per-pixel variance over rays
  then overstates the noise of the mean);
- the Lipschitz bound halved (``TracedSurface._bounds``):
  ``test_traced_surface_is_the_fields_bands_and_bounds_hold`` fails (finite-difference gradients
  above it). ``test_bounds_hold`` does not catch that one: the sum of the bands' largest gradients is
  2–4× the surface's largest, which is what it also checks (the bound is not wild);
- the partial-sum steps without the other bands' amplitude as slack: ``test_partial_sum_steps_find_the_same_hits``
  fails (rays step over their first crossing, hits up to 135 m further).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import torch
from kornia.geometry.camera import PinholeCamera

import roughsea_torch as rs
from roughsea_torch import raytrace as rt

T_SEA = 290.0


class Sinusoid:
    """η = A cos(k x), a height field with exact bounds (the :class:`raytrace.Surface` protocol)."""

    def __init__(self, amplitude: float, wavenumber: float, dtype=torch.float64):
        self.a, self.k = amplitude, wavenumber
        self.eta_max = torch.tensor([amplitude], dtype=dtype)
        self.lipschitz = torch.tensor([amplitude * wavenumber], dtype=dtype)
        self.dtype, self.device = dtype, torch.device("cpu")

    def __call__(self, x, y):
        eta = self.a * torch.cos(self.k * x)
        return eta, self.a * self.k * torch.sin(self.k * x), torch.zeros_like(y)


def _crest_rays(surf: Sinusoid, height: float, eps: float, deltas: list[float], crest: int = 3):
    """Rays that pass ``eps`` above crest ``crest`` (x₁ = 2π crest / k) and meet the next wave's near face at
    P = (x₁ + λ − δ, A cos(kδ)): camera centres (one per ray, on the line back at ``height``) and P."""
    lam = 2 * math.pi / surf.k
    x1 = crest * lam
    cams, dirs, targets = [], [], []
    for d in deltas:
        q = np.array([x1, 0.0, surf.a + eps])
        p = np.array([x1 + lam - d, 0.0, surf.a * math.cos(surf.k * d)])
        u = (p - q) / np.linalg.norm(p - q)
        s = (height - q[2]) / (-u[2])
        cams.append(q - s * u)
        dirs.append(u)
        targets.append(p)
    return np.array(cams), np.array(dirs), np.array(targets)


def test_first_hit_behind_a_crest():
    """Rays that clear a crest by 0.1 m, pass over the trough behind it, and first meet the next
    wave's near face at a point P known by construction; the march finds P to the tolerance."""
    surf = Sinusoid(0.5, 2 * math.pi / 10.0)
    cams, dirs, targets = _crest_rays(surf, height=12.0, eps=0.1, deltas=[1.0, 3.0, 3.5])
    for c, u, p in zip(cams, dirs, targets):
        # the construction: the segment from the camera to P stays above the surface (dense check)
        t = np.linspace(0.0, np.dot(p - c, u), 2_000_001)[:-1]
        pts = c[None] + t[:, None] * u[None]
        assert np.all(pts[:, 2] > surf.a * np.cos(surf.k * pts[:, 0])), "construction: the ray must clear the crest"
        out = rt.march_first_hits(torch.tensor(c[None]), torch.tensor(u[None, None]), surf, tolerance_m=1e-7)
        hit = np.array([out["x"].item(), out["y"].item(), out["z"].item()])
        assert np.linalg.norm(hit - p) < 2e-7
        # the flat-sea point (z = 0) lies beyond the crest, metres away: the renderer's point is not the hit
        flat = c + (c[2] / -u[2]) * u
        assert np.linalg.norm(flat[:2] - p[:2]) > 1.0
        assert out["slope_x"].item() == pytest.approx(surf.a * surf.k * math.sin(surf.k * p[0]), abs=1e-6)


def test_first_hit_of_descending_rays_on_a_face():
    """A ray aimed straight at a point of the near face (no crest in between) hits there; a ray going
    up never hits; every descending ray hits (the slab's bottom is below every trough)."""
    surf = Sinusoid(0.3, 2 * math.pi / 7.0)
    p = np.array([7.0 * 5 - 1.0, 0.0, 0.3 * math.cos(2 * math.pi / 7.0)])  # 1 m before the crest at x = 35 m
    c = np.array([0.0, 0.0, 4.0])
    u = (p - c) / np.linalg.norm(p - c)
    up = np.array([1.0, 0.0, 0.01]) / math.hypot(1.0, 0.01)
    grazing = np.array([1.0, 0.0, -1e-3]) / math.hypot(1.0, 1e-3)
    dirs = torch.tensor(np.stack([u, up, grazing])[None])
    out = rt.march_first_hits(torch.tensor(c[None]), dirs, surf)
    assert out["hit"].tolist() == [[True, False, True]]
    t = np.linspace(0.0, np.linalg.norm(p - c), 200_001)[:-1]
    pts = c[None] + t[:, None] * u[None]
    if np.all(pts[:, 2] > 0.3 * np.cos(surf.k * pts[:, 0])):  # P is the first crossing
        assert out["t"][0, 0].item() == pytest.approx(np.linalg.norm(p - c), abs=2e-7)
    g = out["z"][0, 2] - surf(out["x"][0, 2:3], out["y"][0, 2:3])[0][0]
    assert abs(g.item()) < 1e-6  # the grazing ray's hit lies on the surface


def _field(wind=10.0, seed=11, direction=0.0, dtype=torch.float64):
    scene = rs.SeaScene(wind_speed=wind, wind_direction=direction, sea_temperature=T_SEA, seed=seed, time_s=3.0,
                        foam=False, path=False)
    return scene.wave_field(1, dtype, torch.device("cpu"))


def test_traced_surface_is_the_fields_bands_and_bounds_hold():
    """The traced surface equals ``WaveField.sample`` restricted to the bands with k ≤ k_max; its
    bounds hold: |η| ≤ η_max at random points and the finite-difference gradient ≤ L."""
    field = _field(15.0, direction=0.7)
    gen = torch.Generator().manual_seed(1)
    x = (torch.rand(1, 4000, generator=gen, dtype=torch.float64) - 0.5) * 3000
    y = (torch.rand(1, 4000, generator=gen, dtype=torch.float64) - 0.5) * 3000
    for k_max, n_bands in ((64.0, 14), (1.0, 8), (math.inf, 16)):
        surf = rt.TracedSurface(field, 3.0, k_max)
        assert surf.n_traced == n_bands
        fp = None if surf.footprint is None else torch.full_like(x, surf.footprint)
        ref = field.sample(x, y, 3.0, footprint=fp)
        eta, sx, sy = surf(x, y)
        assert torch.allclose(eta, ref["elevation"], rtol=0, atol=1e-11)
        assert torch.allclose(sx, ref["slope_x"], rtol=0, atol=1e-10)
        assert torch.allclose(sy, ref["slope_y"], rtol=0, atol=1e-10)
        assert bool((eta.abs() <= surf.eta_max).all())
        h = 1e-4
        gx = (surf(x + h, y)[0] - surf(x - h, y)[0]) / (2 * h)
        gy = (surf(x, y + h)[0] - surf(x, y - h)[0]) / (2 * h)
        assert bool((torch.hypot(gx, gy) <= surf.lipschitz).all())
    low = rt.TracedSurface(field, 3.0, 0.001)  # below the lowest band: nothing traced
    assert low.n_traced == 0 and float(low.eta_max) == 0.0


def test_bounds_hold():
    """η_max and L bound the traced surface where it is largest: the bounds are at least the
    largest |η| and |∇η| found on a dense grid over one period of the longest traced band."""
    field = _field(10.0)
    surf = rt.TracedSurface(field, 3.0, 2.0)
    length = field.bands.tile_length[surf.n_traced - 1] * 2
    g = torch.linspace(0.0, length, 700, dtype=torch.float64)
    x, y = torch.meshgrid(g, g, indexing="xy")
    eta = surf(x.reshape(1, -1), y.reshape(1, -1))[0].reshape(700, 700)
    step = float(g[1] - g[0])
    grad = torch.hypot(torch.diff(eta, dim=1)[:-1], torch.diff(eta, dim=0)[:, :-1]) / step
    assert float(eta.abs().max()) <= float(surf.eta_max)
    assert float(grad.max()) <= float(surf.lipschitz)
    assert float(grad.max()) > 0.25 * float(surf.lipschitz)  # a bound, not a wild one


def test_hit_facets_face_the_camera():
    """At the first hit the traced facet faces the camera (cos θ̂ + sin θ̂ s∥ ≥ 0) and the hit lies on
    the surface; at the flat-sea point a share of the facets faces away (what the renderer samples)."""
    field = _field(10.0)
    cams = rs.make_camera(4, 6, hfov_deg=1.0, altitude_m=15.0, pitch_deg=-4.0, dtype=torch.float64)
    tr = rt.trace_first_hits(cams, field, 3.0, rays_per_pixel=16, k_max=64.0)
    assert bool(tr["hit"].all())
    cz = tr["cos_view_zenith"]
    sz = torch.sqrt(1 - cz**2)
    az = tr["view_azimuth_world"]
    facing = cz + sz * (tr["slope_x"] * torch.cos(az) + tr["slope_y"] * torch.sin(az))
    flat = cz + sz * (tr["flat_slope_x"] * torch.cos(az) + tr["flat_slope_y"] * torch.sin(az))
    assert float((facing < 0).double().mean()) <= 0.002  # spectral vs interpolated slope (module Limits)
    assert float((flat < 0).double().mean()) > 0.1
    surf = rt.TracedSurface(field, 3.0, 64.0)
    eta = surf(tr["x"].reshape(1, -1), tr["y"].reshape(1, -1))[0]
    assert float((tr["z"].reshape(1, -1) - eta).abs().max()) < 1e-6


def test_blackbody_sky_gives_sea_radiance():
    """A sky equal to the sea's blackbody radiance gives R_B at every pixel (second law), in both
    modes, sea and sky pixels alike (the horizon is in view)."""
    rb = float(rs.band_radiance(T_SEA))
    cams = rs.make_camera(6, 8, hfov_deg=6.0, altitude_m=15.0, pitch_deg=-1.0)
    for mode, k_max in (("two_scale", 64.0), ("specular", math.inf)):
        out = rt.raytraced_image(cams, 10.0, seed=3, time_s=1.0, sky=rb, rays_per_pixel=3, mode=mode, k_max=k_max)
        rad = out["radiance"].double()
        assert float(out["sky_fraction"].max()) > 0  # sky pixels are in the image
        assert torch.allclose(rad, torch.full_like(rad, rb), rtol=2e-6, atol=0), mode
        assert float((out["brightness_temperature"].double() - T_SEA).abs().max()) < 1e-3


def test_rays_into_the_sea_never_see_the_sky():
    """A sky whose radiance below the horizon (cos zenith < 0) is absurd: no pixel sees it, in either
    mode (mirrored rays that point into the sea see R_B)."""
    rb = float(rs.band_radiance(T_SEA))

    def sky(c):
        return torch.where(c < 0, torch.full_like(c, 1e4), torch.full_like(c, 10.0))

    cams = rs.make_camera(4, 6, hfov_deg=2.0, altitude_m=15.0, pitch_deg=-5.0)
    for mode, k_max in (("two_scale", 64.0), ("specular", math.inf)):
        out = rt.raytraced_image(cams, 15.0, seed=5, sky=sky, rays_per_pixel=4, mode=mode, k_max=k_max)
        assert float(out["radiance"].max()) <= rb * 1.000001, mode


def test_no_traced_waves_is_the_expectation_image():
    """With k_max below the field's lowest band nothing is traced: every ray sees the expectation at its
    flat-sea view angles, so the image is the renderer's expectation image (per-pixel evaluation,
    same quadrature, flat sea), across a yawed camera and an oblique wind. This also holds the tracer's
    own scene (R_B, band-averaged water index, LOWTRAN sky, anisotropic Cox–Munk, azimuth conventions)
    to the renderer's."""
    q = rs.Quadrature.default(torch.float64)
    cams = rs.make_camera(5, 6, hfov_deg=3e-4, altitude_m=15.0, pitch_deg=-5.0, yaw_deg=30.0, dtype=torch.float64)
    out = rt.raytraced_image(cams, 8.0, seed=2, wind_direction=1.1, rays_per_pixel=2, k_max=1e-3, quadrature=q)
    scene = rs.SeaScene(wind_speed=8.0, wind_direction=1.1, sea_temperature=T_SEA, foam=False, path=False)
    ref = rs.render(cams, scene, method="direct", quadrature=q, earth_radius_m=math.inf)
    assert torch.allclose(out["radiance"], ref, rtol=2e-6, atol=0)
    assert float(out["parallax_m"].abs().max()) < 1e-6


def test_heights_alone_leave_the_expectation_image():
    """In the two-scale model a ray's radiance depends on its direction and the slope statistics at its
    hit, not on where it hits: with the rays meeting every band up to 64 rad/m (they do move: parallax)
    but no band's slope taken (slope_k_max below the lowest band), the image is the expectation image,
    as with nothing traced."""
    q = rs.Quadrature.default(torch.float64)
    cams = rs.make_camera(5, 6, hfov_deg=3e-4, altitude_m=15.0, pitch_deg=-5.0, yaw_deg=30.0, dtype=torch.float64)
    out = rt.raytraced_image(cams, 8.0, seed=2, wind_direction=1.1, rays_per_pixel=2, k_max=64.0, slope_k_max=1e-3,
                             quadrature=q)
    scene = rs.SeaScene(wind_speed=8.0, wind_direction=1.1, sea_temperature=T_SEA, foam=False, path=False)
    ref = rs.render(cams, scene, method="direct", quadrature=q, earth_radius_m=math.inf)
    assert torch.allclose(out["radiance"], ref, rtol=2e-6, atol=0)
    assert float(out["parallax_m"].min()) > 1e-3  # the hits are not the flat-sea points
    traced = rt.raytraced_image(cams, 8.0, seed=2, wind_direction=1.1, rays_per_pixel=2, k_max=64.0, quadrature=q)
    assert float((traced["radiance"] - ref).abs().max()) > 1e-3 * float(ref.mean())  # the slopes do change it


def test_sampling_variance_estimates_the_noise():
    """radiance_var / S is the sampling variance of a pixel's mean: two ray seeds differ by about
    √(2 radiance_var / S) (i.i.d. sub-pixel points), over 768 pixels looking down at 45°, where a pixel
    spans a few short waves (stratified points would make the noise of the mean 2–3× smaller than that)."""
    cams = rs.make_camera(24, 32, hfov_deg=4.0, altitude_m=15.0, pitch_deg=-45.0)
    a = rt.raytraced_image(cams, 10.0, seed=11, rays_per_pixel=4, ray_seed=1)
    b = rt.raytraced_image(cams, 10.0, seed=11, rays_per_pixel=4, ray_seed=2)
    diff = (a["radiance"] - b["radiance"]).double()
    expected = (a["radiance_var"] + b["radiance_var"]).double() / 4
    ratio = float((diff**2).mean() / expected.mean())
    assert 0.75 < ratio < 1.3, ratio


def test_dtypes_and_checks():
    """float32 and float64 cameras give the same image (the trace is float64 either way) in their own
    dtype; bad arguments are ValueErrors that name them."""
    kw = dict(hfov_deg=1.0, altitude_m=15.0, pitch_deg=-8.0)
    c32 = rs.make_camera(3, 4, **kw)
    c64 = PinholeCamera(*(t.double() for t in (c32.intrinsics, c32.extrinsics, c32.height, c32.width)))
    o32 = rt.raytraced_image(c32, 10.0, seed=1, rays_per_pixel=2)
    o64 = rt.raytraced_image(c64, 10.0, seed=1, rays_per_pixel=2)
    assert o32["radiance"].dtype == torch.float32 and o64["radiance"].dtype == torch.float64
    assert torch.allclose(o32["radiance"].double(), o64["radiance"], rtol=1e-6, atol=0)
    cams = rs.make_camera(2, 2, **kw)
    for kwargs, name in ((dict(k_max=-1.0), "k_max"), (dict(rays_per_pixel=1), "rays_per_pixel"),
                         (dict(mode="mirror"), "mode"), (dict(sky=-3.0), "sky"), (dict(tolerance_m=0.0), "tolerance_m"),
                         (dict(min_step_m=float("nan")), "min_step_m"), (dict(max_range_m=-5.0), "max_range_m"),
                         (dict(shadowing=False), "shadowing"), (dict(shadowing="wagner"), "shadowing"),
                         (dict(slope_k_max=128.0), "slope_k_max"), (dict(slope_k_max=-1.0), "slope_k_max"),
                         (dict(k_max=math.inf, slope_k_max=4.0, mode="specular"), "slope_k_max")):
        with pytest.raises(ValueError, match=name):
            rt.raytraced_image(cams, 10.0, seed=1, **kwargs)
    with pytest.raises(ValueError, match="cameras"):  # below the crests
        rt.raytraced_image(rs.make_camera(2, 2, hfov_deg=1.0, altitude_m=3.0, pitch_deg=-8.0), 15.0, seed=1)
    with pytest.raises(ValueError, match="k_max"):  # isotropic Cox–Munk at 5 m/s: the traced upwind variance exceeds it
        rt.raytraced_image(cams, 5.0, seed=1, anisotropic=False)


def test_multiscale_masking_is_the_mean_the_ray_traced_ensemble_supports():
    """The expectation's mean near grazing against the brute-force ensemble (issue: "give the expectation the
    shadowing the ray-traced ensemble supports"). Looking across a 10 m/s wind from 20 m, 4° down (8×32 pixels
    over 6°, view zenith 85–87°), 8 realizations at 2 rays per pixel, the waves up to 64 rad/m traced and the
    shorter ones given the multi-scale masking too: the image mean of ``shadowing="multiscale"``'s expectation
    lies within 0.05 K of the ensemble's (measured +0.009 ± 0.009 K), while the paper's Eq. 5 is 0.26 K warmer
    and the correlated masking 0.20 K: near grazing the short waves on the backs of longer ones are hidden,
    which neither models."""
    seeds = list(range(300, 308))
    cams = rs.make_camera(8, 32, hfov_deg=6.0, altitude_m=20.0, pitch_deg=-4.0, batch_size=len(seeds), dtype=torch.float64)
    ray = rt.raytraced_image(cams, 10.0, seed=seeds, time_s=3.0, wind_direction=math.pi / 2, rays_per_pixel=2,
                             shadowing="multiscale")["brightness_temperature"]
    cam1 = rs.make_camera(8, 32, hfov_deg=6.0, altitude_m=20.0, pitch_deg=-4.0, dtype=torch.float64)

    def expectation(shadowing):
        sc = rs.SeaScene(wind_speed=10.0, wind_direction=math.pi / 2, sea_temperature=T_SEA, foam=False, path=False,
                         shadowing=shadowing)
        return rs.render(cam1, sc, output="brightness_temperature", earth_radius_m=math.inf)

    off = {sh: float(expectation(sh).mean() - ray.mean()) for sh in (True, "correlated", "multiscale")}
    assert abs(off["multiscale"]) < 0.05, off
    assert off[True] > 0.15 and off["correlated"] > 0.1, off


class _GlobalBoundOnly:
    """A :class:`TracedSurface` seen through the plain protocol (η, its bounds): one global step bound."""

    def __init__(self, surf):
        self.surf, self.eta_max, self.lipschitz = surf, surf.eta_max, surf.lipschitz
        self.dtype, self.device = surf.dtype, surf.device

    def __call__(self, x, y):
        return self.surf(x, y)


def test_partial_sum_steps_find_the_same_hits():
    """The march's sharper steps (from the partial sums of the bands, each with the rest's amplitude as
    slack) take fewer steps and find the same first hits as the single global Lipschitz bound."""
    field = _field(15.0)
    surf = rt.TracedSurface(field, 3.0, 64.0)
    cams = rs.make_camera(48, 64, hfov_deg=12.0, altitude_m=15.0, pitch_deg=-6.0)
    c, d = rt.camera_rays(cams, 1, rows=slice(0, 48, 6))
    d = d.reshape(1, -1, 3)[:, ::2]
    sharp = rt.march_first_hits(c, d, surf)
    plain = rt.march_first_hits(c, d, _GlobalBoundOnly(surf))
    assert bool(sharp["hit"].all()) and bool(plain["hit"].all())
    assert float((sharp["t"] - plain["t"]).abs().max()) < 2e-7
    assert float(sharp["steps"].double().mean()) < 0.85 * float(plain["steps"].double().mean())


@pytest.mark.parametrize("wind_direction", [0.0, 0.7, -2.2])
def test_unresolved_statistics_rotate_the_traced_covariance_into_the_wind_frame(wind_direction):
    """The slopes the tracer leaves to the expectation have the covariance Σ_total − R Σ_traced Rᵀ in
    the (upwind, crosswind) frame, Σ_traced the traced bands' covariance in the world frame and R the
    rotation by −(wind direction) (upwind = s·(cos w, sin w)); written here with numpy matrices."""
    traced = torch.tensor([[0.004, 0.0015, 0.0008]], dtype=torch.float64)  # (var_x, var_y, cov_xy), world
    total = rs.SlopeStatistics.cox_munk(10.0, anisotropic=True)
    got = rt._unresolved_statistics(total, traced, torch.tensor([wind_direction], dtype=torch.float64))[0].numpy()
    c, s = math.cos(wind_direction), math.sin(wind_direction)
    rot = np.array([[c, s], [-s, c]])
    sig = rot @ np.array([[0.004, 0.0008], [0.0008, 0.0015]]) @ rot.T
    want = np.array([float(total.var_upwind) - sig[0, 0], float(total.var_crosswind) - sig[1, 1], float(total.cov) - sig[0, 1]])
    np.testing.assert_allclose(got, want, rtol=1e-13, atol=1e-16)

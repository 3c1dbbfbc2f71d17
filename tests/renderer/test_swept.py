"""The first hit's whitecaps on their facets (``TableSize.texture_hit_foam_tilt``,
:mod:`roughsea_torch.renderer.swept`): the facet's incidence from its slope against explicit 3-D vectors,
the second law, and near grazing foam on the crest faces seen nearer their normal than the mean plane."""

from __future__ import annotations

import math
import warnings

import pytest
import torch

import roughsea_torch as rs
from roughsea_torch.renderer.swept import facet_cosine

F64 = torch.float64


@pytest.mark.parametrize("dtype, tol", [(torch.float64, 1e-12), (torch.float32, 2e-6)])
def test_facet_cosine_is_the_normal_dotted_with_the_line_of_sight(dtype, tol):
    """For a surface z = η(x, y) with slopes s = −∇η, the facet's normal is the cross product of its tangents
    (1, 0, ∂η/∂x) × (0, 1, ∂η/∂y), normalized; the line of sight to the sensor is (−sin θ̂ d, cos θ̂) for a ray
    along the horizontal unit vector d. Their dot product at 1000 random views and slopes (up to ±1) equals
    facet_cosine; a facet tilted towards the sensor (s · d < 0) is seen nearer its normal."""
    gen = torch.Generator().manual_seed(4)
    n = 1000
    cos_view = torch.rand(n, generator=gen, dtype=F64) * 0.999 + 0.001
    az = torch.rand(n, generator=gen, dtype=F64) * 2 * math.pi
    sx, sy = ((torch.rand(n, generator=gen, dtype=F64) * 2 - 1) for _ in range(2))
    gx, gy = -sx, -sy  # ∇η
    t1 = torch.stack([torch.ones(n, dtype=F64), torch.zeros(n, dtype=F64), gx], -1)
    t2 = torch.stack([torch.zeros(n, dtype=F64), torch.ones(n, dtype=F64), gy], -1)
    normal = torch.linalg.cross(t1, t2)
    normal = normal / normal.norm(dim=-1, keepdim=True)
    sin_view = torch.sqrt(1 - cos_view**2)
    sight = torch.stack([-sin_view * torch.cos(az), -sin_view * torch.sin(az), cos_view], -1)
    expected = (normal * sight).sum(-1)
    got = facet_cosine(*(v.to(dtype) for v in (cos_view, torch.cos(az), torch.sin(az), sx, sy)))
    assert got.dtype == dtype
    torch.testing.assert_close(got.double(), expected, rtol=0.0, atol=tol)
    towards = (sx * torch.cos(az) + sy * torch.sin(az)) < 0
    flat = facet_cosine(cos_view, torch.cos(az), torch.sin(az), torch.zeros_like(sx), torch.zeros_like(sy))
    assert bool((got.double()[towards & (sx**2 + sy**2 < 0.01)] > flat[towards & (sx**2 + sy**2 < 0.01)]).all())


def _grazing(**kw):
    cams = rs.make_camera(64, 96, hfov_deg=12.0, altitude_m=15.0, pitch_deg=-3.0, dtype=F64)
    scene = dict(wind_speed=15.0, sea_temperature=290.0, shadowing="multiscale", seed=1, path=False)
    scene.update(kw)
    return cams, scene


def test_foam_on_its_facets_keeps_the_second_law():
    """A sky at the sea's blackbody radiance and no skin deficit: foam at any incidence radiates R_B, so the
    first hit with whitecaps on their facets leaves every pixel at R_B (15 m/s, near grazing)."""
    cams, kw = _grazing(skin_deficit=0.0)
    rb = float(rs.band_radiance(torch.tensor(290.0, dtype=F64)))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        img = rs.render(cams, rs.SeaScene(**{**kw, "sea_temperature": 290.0}, sky=rb),
                        table=rs.TableSize(texture_hit="first"))
    sea = rs.view_geometry(cams).is_sea[0]
    torch.testing.assert_close(img[0, 0][sea], torch.full_like(img[0, 0][sea], rb), rtol=1e-10, atol=0.0)


def test_foam_on_crest_faces_is_seen_nearer_their_normal():
    """Near grazing (15 m/s, 15 m mast, 3° down, view zenith to 89.5°) the first hit sees foam on the crests, whose
    faces lean towards the camera. In the mean plane a foam patch is 6.6 K darker than the water at 88° and
    0.9 K at 80° (docs/foam_table.md): on its facet, seen nearer the normal, the whitecaps' darkest pixel must be
    less than half as dark (measured −7.1 → −2.4 K on 256×320 px), the pixels darkened by more than 0.5 K at most
    a third as many (8.4 % → 1.1 %), and the change positive on average over the pixels with foam. Planted, the
    facet's slope towards the sensor with the wrong sign (the facets seen further from their normal): the
    darkest pixel gets darker and the test fails. The wind gradient stays finite."""
    cams, kw = _grazing()
    sea = rs.view_geometry(cams).is_sea[0]
    wind = torch.tensor(15.0, dtype=F64, requires_grad=True)

    def render(foam, tilt, w=15.0):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            return rs.render(cams, rs.SeaScene(**{**kw, "wind_speed": w}, **({} if foam else {"foam": False})),
                             output="brightness_temperature",
                             table=rs.TableSize(texture_hit="first", texture_hit_foam_tilt=tilt))[0, 0]

    bare = render(False, True)
    plane, tilt_graph = render(True, False) - bare, render(True, True, wind) - bare
    tilt = tilt_graph.detach()
    assert float(plane[sea].min()) < -3.0  # (the case has whitecaps near the horizon)
    assert float(tilt[sea].min()) > 0.5 * float(plane[sea].min()), (tilt[sea].min(), plane[sea].min())
    assert float((tilt[sea] < -0.5).sum()) <= float((plane[sea] < -0.5).sum()) / 3
    foamy = sea & (plane.abs() > 1e-3)
    assert float((tilt - plane)[foamy].mean()) > 0
    (g,) = torch.autograd.grad(tilt_graph[sea].mean(), wind)
    assert math.isfinite(float(g))


def test_foam_on_its_facets_comes_through_the_path():
    """With the scene's atmospheric path the foam's change on its facets reaches the sensor through the path's
    transmittance τ of its line of sight: (tilt − plane) with the path over the same without it is τ at the
    pixel's view zenith (``renderer.path.path_rows``), within 3 % at 80–88° (measured ≤ 2.4 %; the pixel's samples
    span its window, nearer the horizon τ varies across it). Planted, τ left out: off by 1/τ − 1 (τ 0.68–0.95)."""
    from roughsea_torch.renderer.path import path_rows

    cams, kw = _grazing()
    geo = rs.view_geometry(cams)
    with_path = {k: v for k, v in kw.items() if k != "path"}  # (the scene's default path)
    renders = {}
    for path in (False, True):
        for tilt in (False, True):
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                renders[path, tilt] = rs.render(cams, rs.SeaScene(**(with_path if path else kw)),
                                                table=rs.TableSize(texture_hit="first", texture_hit_foam_tilt=tilt))[0, 0]
    d_free, d_path = (renders[p, True] - renders[p, False] for p in (False, True))
    ct = torch.cos(geo.view_zenith[0])
    tau, _ = path_rows(rs.SeaScene(**with_path).path, ct.reshape(1, -1), torch.tensor([[15.0]], dtype=F64), rs.EARTH_RADIUS_M)
    tau = tau.reshape(ct.shape)
    vz = torch.rad2deg(geo.view_zenith[0])
    on = (d_free.abs() > 1e-2 * d_free.abs().max()) & (vz >= 80.0) & (vz < 88.0)
    assert int(on.sum()) > 50
    assert float(tau[on].min()) < 0.97
    dev = (d_path[on] / d_free[on]) / tau[on] - 1.0
    assert float(dev.abs().max()) < 0.03, float(dev.abs().max())


def test_sea_temperature_gradient_with_foam_on_its_facets_matches_central_differences():
    """d(mean sea brightness temperature)/d(T_sea) near grazing (15 m/s, 3° down, float64) with the foam on its
    facets equals the central difference (step 1e-3 K) to 1e-7 relative (measured 5e-11): the foam's radiances at
    θ_f and θ̂ carry the sea's temperature. The tilt's own share of the derivative is 0.8 % here (0.7509 against
    0.7448 K/K without it). Planted, the foam's node radiances detached in ``_foam_tilt``: off by 0.95 % (7.1e-3 K/K), fails."""
    cams = rs.make_camera(48, 64, hfov_deg=12.0, altitude_m=15.0, pitch_deg=-3.0, dtype=F64)
    sea = rs.view_geometry(cams).is_sea[0]

    def mean_bt(t):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            scene = rs.SeaScene(wind_speed=15.0, sea_temperature=t, shadowing="multiscale", seed=1)
            img = rs.render(cams, scene, output="brightness_temperature", table=rs.TableSize(texture_hit="first"))
        return img[0, 0][sea].mean()

    t = torch.tensor(290.0, dtype=F64, requires_grad=True)
    (g,) = torch.autograd.grad(mean_bt(t), t)
    h = 1e-3
    fd = (float(mean_bt(torch.tensor(290.0 + h, dtype=F64))) - float(mean_bt(torch.tensor(290.0 - h, dtype=F64)))) / (2 * h)
    assert abs(float(g) - fd) < 1e-7 * abs(fd), (float(g), fd)

"""Whitecaps in renders (roughsea_torch.renderer.foam_terms): foam keeps the second law, vanishes
without wind and changes a storm's image; on a textured sea it sits on the crests, and the table
matches the per-pixel evaluation. (The foam's physics: tests/test_foam.py.)"""

from __future__ import annotations

import math

import numpy as np
import pytest
import torch

import roughsea_torch as rs

from conftest import make_cams


def test_foam_keeps_the_second_law_and_vanishes_without_wind():
    """A sky at the sea's blackbody radiance and no skin deficit (foam and water at one temperature):
    foam (whatever its emissivity) changes nothing; no wind, no foam: the default 'auto' equals
    foam=False bit for bit; a storm's foam changes the image."""
    rb = 30.0
    cams = make_cams(hfov_deg=20.0, pitch_deg=-4.0, batch_size=1)
    storm = rs.render(cams, rs.SeaScene(wind_speed=25.0, sea_radiance=rb, sky=rb, path=False, skin_deficit=0.0))
    assert torch.allclose(storm[0, 0][rs.view_geometry(cams).is_sea[0]], torch.tensor(rb, dtype=torch.float64), rtol=1e-12, atol=0)
    calm = dict(wind_speed=0.0, sea_temperature=290.0)
    assert torch.equal(rs.render(cams, rs.SeaScene(**calm)), rs.render(cams, rs.SeaScene(**calm, foam=False)))
    windy = dict(wind_speed=20.0, sea_temperature=290.0)
    with_foam = rs.render(cams, rs.SeaScene(**windy), output="brightness_temperature")
    without = rs.render(cams, rs.SeaScene(**windy, foam=False), output="brightness_temperature")
    assert float((with_foam - without).abs().max()) > 0.1  # kelvin: 7 % whitecaps at 20 m/s


def test_textured_foam_sits_on_crests_keeps_the_second_law_and_matches_per_pixel_evaluation():
    """A textured storm sea puts its whitecaps on crests (foam.crest_foam_fraction), not as a uniform
    veil: the foam's change to the image concentrates in few pixels (the tenth of the sea pixels it
    changes most carry over 35 % of the change: 0.42 and 0.39 measured with the streak field's soft
    edges and the patches elongated across the wind, 0.46 before that elongation, 0.55 without the
    streaks; a uniform fraction W, as in the expectation, spreads it over all and gives 0.29 here). The table equals the per-pixel evaluation to 1 % of the
    texture's amplitude, and a sky at the sea's blackbody radiance leaves every pixel at R_B."""
    cams = make_cams(48, 64, pitch_deg=-8.0, batch_size=2)
    g = rs.view_geometry(cams)
    sea = g.is_sea[:, None]
    kw = dict(wind_speed=torch.tensor([14.0, 20.0]), sea_temperature=290.0, sky=lambda c: 12.0 + 18.0 * (1 - c) ** 6,
              path=False, seed=[3, 4])
    raw = rs.TableSize(texture_antialias=False)  # the crests themselves, not their blur along the columns (renderer.antialias)
    foamy = rs.render(cams, rs.SeaScene(**kw), table=raw)
    bare = rs.render(cams, rs.SeaScene(**kw, foam=False), table=raw)
    for i in range(2):
        d = (foamy - bare)[i][sea[i]].abs()
        top = d.sort(descending=True).values[: d.numel() // 10]
        assert float(top.sum() / d.sum()) > 0.35
    direct = rs.render(cams, rs.SeaScene(**kw), method="direct", geometry=g, table=raw)
    amplitude = float((foamy - rs.render(cams, rs.SeaScene(**dict(kw, seed=None)))).abs().max())
    assert float((foamy - direct).abs()[sea].max()) < 0.025 * amplitude  # measured 1.74 % with the streak field
    rb = 27.5
    # foam and water at one temperature (no skin deficit)
    img = rs.render(cams, rs.SeaScene(wind_speed=20.0, sea_radiance=rb, sky=rb, path=False, seed=[5, 6], skin_deficit=0.0))
    torch.testing.assert_close(img[sea], torch.full_like(img[sea], rb), rtol=1e-12, atol=0.0)


def test_foam_by_day_also_reflects_the_scattered_sky():
    """By day a whitecap reflects the scattered sky as well as the thermal one: R_foam = ε_f R_B +
    (1 − ε_f) S (the mean over its active and residual states, a R_act + (1 − a) R_res) with S = ∫₀¹ ρ_f (R_s(μ) + ⟨L_day⟩_φ(μ)) μ dμ / ∫₀¹ ρ_f μ dμ, ρ_f = 1 − ε_f the foam's
    reflectance (foam.foam_sky_radiance) and ⟨L_day⟩_φ the day sky's mean over azimuth (docs/scenes.md §5). Out of a render with a whitecap fraction of 0.3 and one without
    (R = (1 − f) R_a + f R_foam), R_foam per sea pixel equals foam_radiance with E_sky computed here:
    8-point Gauss–Legendre between the two tables' zenith nodes, the azimuth mean a trapezoid over
    4001 azimuths of the scattered sky's table, to 1e-6; the day sky is 11 % of E_sky here."""
    from roughsea_torch.daysky import load_scattered_sky
    from roughsea_torch.foam import foam_emissivity, foam_radiance

    sun_z, f = math.radians(60.0), 0.3
    cams = make_cams(8, 8, hfov_deg=6.0, pitch_deg=-20.0, yaw_deg=torch.tensor([180.0]))  # the sun behind
    g = rs.view_geometry(cams)
    assert bool(g.is_sea.all())

    def scene(foam):
        return rs.SeaScene(wind_speed=3.0, sea_temperature=290.0, band=rs.MWIR, sky="midlatitude_summer", path=False,
                           sun_zenith=sun_z, sun_azimuth=0.0, foam=foam)

    with_foam, without = rs.render(cams, scene(f))[0, 0], rs.render(cams, scene(0.0))[0, 0]
    r_foam = without + (with_foam - without) / f
    thermal = scene(0.0).sky
    ds = load_scattered_sky("midlatitude_summer", rs.MWIR, aerosol="maritime")
    # μ = cos θ between every node of both tables, 8 Gauss–Legendre points in each interval
    z = np.unique(np.concatenate([thermal.zenith.numpy(), ds.view_zenith_nodes_rad, [0.0, math.pi / 2]]))
    edges = np.sort(np.cos(z))
    x, w = np.polynomial.legendre.leggauss(8)
    half, mid = 0.5 * np.diff(edges)[:, None], 0.5 * (edges[1:] + edges[:-1])[:, None]
    mu, wt = torch.tensor((mid + half * x).ravel()), torch.tensor((half * w).ravel())
    phi = torch.linspace(0.0, math.pi, 4001, dtype=torch.float64)
    day = torch.trapezoid(ds(mu[:, None].expand(-1, phi.numel()), phi.expand(mu.numel(), -1),
                             torch.full((mu.numel(), phi.numel()), sun_z, dtype=torch.float64)), phi) / math.pi
    m = rs.band_refractive_index(rs.MWIR, 290.0)
    # the foam's own reflectance 1 − ε_f(θ) weights the sky it reflects (foam.foam_sky_radiance, reciprocal)
    rho = 1.0 - foam_emissivity(torch.acos(mu), rs.MWIR, refractive_index=(m.real, m.imag))
    norm = float((wt * mu * rho).sum())
    e_day, e_thermal = float((wt * mu * rho * day).sum()) / norm, float((wt * mu * rho * thermal(mu)).sum()) / norm
    assert 0.05 < e_day / (e_day + e_thermal) < 0.2
    rb = rs.band_radiance(torch.tensor(290.0, dtype=torch.float64), rs.MWIR)
    want = foam_radiance(g.view_zenith[0], rs.MWIR, rb, e_day + e_thermal, refractive_index=(m.real, m.imag))
    # the expectation's foam is the mean over the states, a R_act + (1 − a) R_res: active foam at the bulk
    # temperature 290.2 K (skin deficit 0.2 K), a = τ_A/(τ_A + τ_R), τ_A = 0.3 · 2π U/(g Ω_c) / √10 (the period of
    # the breaking band's centre, 10 k_p), τ_R = 2 s
    rb_bulk = rs.band_radiance(torch.tensor(290.2, dtype=torch.float64), rs.MWIR)
    act = foam_radiance(g.view_zenith[0], rs.MWIR, rb_bulk, e_day + e_thermal, refractive_index=(m.real, m.imag))
    tau_a = 0.3 * 2 * math.pi * 3.0 / (9.81 * 0.84) / math.sqrt(10.0)
    want = want + tau_a / (tau_a + 2.0) * (act - want)
    torch.testing.assert_close(r_foam, want, rtol=1e-6, atol=0)


def test_foam_trails_reach_both_methods():
    """TableSize(foam_trails=True) draws the residual foam of the last seconds (whitecaps.whitecap_cover's
    trails): a 15 m/s storm differs from the default (the breaking now) by over 0.05 K somewhere, and the
    table render with trails equals the per-pixel one with trails to 2 % of the foam's own change."""
    cams = make_cams(24, 32, hfov_deg=20.0, altitude_m=15.0, pitch_deg=-8.0)
    scene = rs.SeaScene(wind_speed=15.0, sea_temperature=290.0, seed=[4], time_s=2.3, path=False)
    trails = rs.TableSize(foam_trails=True)
    kw = dict(output="brightness_temperature")
    now, with_trails = rs.render(cams, scene, **kw), rs.render(cams, scene, table=trails, **kw)
    change = float((with_trails - now).abs().max())
    assert change > 0.05
    direct = rs.render(cams, scene, method="direct", table=trails, **kw)
    assert float((with_trails - direct).abs().max()) < 0.02 * change + 2e-3


# ------------------------------------------------------------------------------------------------
# The skin deficit, a scene argument (SeaScene(skin_deficit=))
# ------------------------------------------------------------------------------------------------
SKIN_INDEX = 1.22 + 0.05j  # one refractive index for the scene and the reference (no band lookup)


def _active_share(wind: float) -> float:
    """a = τ_A / (τ_A + τ_R), τ_A = 0.3 T_p / √10, T_p = 2π U / (g Ω_c), Ω_c = 0.84, τ_R = 2 s (whitecaps)."""
    tau_a = 0.3 * 2 * math.pi * wind / (9.81 * 0.84) / math.sqrt(10.0)
    return tau_a / (tau_a + 2.0)


def _skin_scene(deficit, foam=0.3, **kw):
    """A 10 m/s night sea at 290 K under a uniform 20 W m⁻² sr⁻¹ sky, no path, a whitecap fraction ``foam``."""
    return rs.SeaScene(**{"wind_speed": 10.0, "sea_temperature": 290.0, "sky": 20.0, "path": False,
                          "refractive_index": SKIN_INDEX, "foam": foam, "skin_deficit": deficit, **kw})


def test_skin_deficit_reaches_the_render_as_the_reference_foam_mean():
    """A render's foam radiance with SeaScene(skin_deficit=d), d = 0 and 0.5 K (one image each, a (B,)
    tensor): out of a render with a whitecap fraction of 0.3 and one without (R = (1 − f) R_a + f R_foam),
    R_foam per sea pixel equals the numpy reference's a R_act + (1 − a) R_res with its own Planck band
    integral at 290 K + d, under a uniform sky S = 20 W m⁻² sr⁻¹, a = τ_A/(τ_A + τ_R) at 10 m/s
    (0.27), to 1e-7; d = 0.5 K lifts it by a ε_f (R_B(T + d) − R_B(T)) (0.07 W m⁻² sr⁻¹, 2e-3 of R_foam),
    d = 0 is the residual foam's radiance. Both methods. Fails with the argument ignored (planted:
    the default 0.2 K in renderer.foam_terms: off by 9e-4 at d = 0)."""
    from roughsea_torch.reference import foam as ref

    cams = make_cams(8, 8, hfov_deg=6.0, pitch_deg=-20.0, batch_size=2)
    g = rs.view_geometry(cams)
    assert bool(g.is_sea.all())
    d = torch.tensor([0.0, 0.5], dtype=torch.float64)
    a = _active_share(10.0)
    for method in ("table", "direct"):
        with_foam = rs.render(cams, _skin_scene(d), method=method)[:, 0]
        without = rs.render(cams, _skin_scene(d, foam=0.0), method=method)[:, 0]
        r_foam = without + (with_foam - without) / 0.3
        for i, di in enumerate(d.tolist()):
            theta = g.view_zenith[i].numpy()
            want = ref.foam_mean_radiance(theta, tuple(rs.LWIR), 290.0, 20.0, a, SKIN_INDEX, deficit_k=di)
            torch.testing.assert_close(r_foam[i], torch.tensor(want), rtol=1e-7, atol=0)
    act, res = ref.foam_state_radiances(g.view_zenith[1].numpy(), tuple(rs.LWIR), 290.0, 20.0, SKIN_INDEX, 0.5)
    assert float((a * (act - res)).min()) > 1e-3 * float(res.max())  # the deficit's lift, far above the tolerance


@pytest.mark.parametrize("dtype", [torch.float64, torch.float32])
def test_skin_deficit_gradient_is_positive_on_foam_and_a_finite_difference(dtype):
    """d(render)/d(skin_deficit), per pixel of an expectation image at 10 m/s (every sea pixel carries the
    whitecap fraction W): finite, positive (a warmer active foam) and equal to the closed form
    W a ε_f dR_B/dT(T + d) of the numpy reference (its Monahan W, foam emissivity and Planck band
    integral, dR_B/dT a central difference) to 1e-6, at d = 0.3 K and at d = 0 (the range's end, where
    the skin's radiance is kept bit for bit); the image's sum against a central (forward at 0) finite
    difference of renders. Textured (seed=): finite, ≥ 0 per pixel, positive where crests break, and
    its sum a finite difference. float64 and float32 (1e-6 → 2e-3)."""
    from roughsea_torch.reference import foam as ref
    from roughsea_torch.reference import planck

    cams = make_cams(8, 8, hfov_deg=6.0, pitch_deg=-20.0, batch_size=1, dtype=dtype)
    theta = rs.view_geometry(cams).view_zenith[0].double().numpy()
    eps_f, w, a = ref.foam_emissivity(theta, tuple(rs.LWIR), SKIN_INDEX), ref.whitecap_fraction(10.0), _active_share(10.0)
    rtol = 1e-6 if dtype == torch.float64 else 2e-3
    for d0, seed in ((0.3, None), (0.0, None), (0.3, [7])):
        d = torch.tensor([d0], dtype=dtype, requires_grad=True)
        img = rs.render(cams, _skin_scene(d, foam="auto", seed=seed))
        eye = torch.eye(img.numel(), dtype=dtype).reshape(-1, *img.shape)
        (grad,) = torch.autograd.grad(img, d, grad_outputs=eye, is_grads_batched=True)  # one row per pixel
        grad = grad.reshape(img.shape[-2:]).double()
        assert bool(torch.isfinite(grad).all()) and bool((grad >= 0).all())
        t = 290.0 + d0
        slope = (planck.band_radiance(t + 1e-3, tuple(rs.LWIR)) - planck.band_radiance(t - 1e-3, tuple(rs.LWIR))) / 2e-3
        if seed is None:
            torch.testing.assert_close(grad, torch.tensor(w * a * eps_f * slope), rtol=rtol, atol=0)
        else:
            assert float(grad.max()) > 0.1 * w * a * slope  # where crests break

        def total(x):
            with torch.no_grad():
                return float(rs.render(cams, _skin_scene(torch.tensor([x], dtype=dtype), foam="auto", seed=seed)).double().sum())
        if dtype == torch.float64:
            h, tol = (1e-2, 1e-6) if d0 > 0 else (1e-3, 1e-4)  # forward at 0: error ~ h/2 · R_B''/R_B' ~ 1e-5
        else:
            h, tol = 0.2, 2e-2  # float32 images: steps of 2e-6 W m⁻² sr⁻¹ against a change of 1e-4 per pixel
        fd = (total(d0 + h) - total(d0 - h)) / (2 * h) if d0 > 0 else (total(h) - total(0.0)) / h
        assert abs(float(grad.sum()) - fd) <= tol * abs(fd)

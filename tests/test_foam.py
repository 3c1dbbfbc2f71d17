"""Foam (roughsea_torch.foam): whitecap law, measured foam emissivity, second law, mixture, torch vs
reference, gradients; and foam on crests.

Foam on the crests of a textured sea: crest_foam_fraction fed with the crest variable of
roughsea_torch.waves.WaveField (the crest_ensemble of tests/conftest.py; the TextureTable hook that
samples it per pixel: tests/renderer/test_texture.py). What must hold (issue 12, item 3;
docs/texture.md §8, §13): the ensemble mean of the pixel's foam fraction is Monahan's W exactly,
whatever the footprint; the far field is the uniform-fraction image; the foam sits on crests; it is
independent of the resolved slopes (so it does not bias the slope texture); W = 0 means no foam;
gradients are finite at the degenerate ends and right inside; float32 agrees with float64. Plant
``σ_X`` for ``σ_u`` in the denominator of crest_foam_fraction (f = Φ((X_r − c)/σ_X)) and the
ensemble-mean tests fail by a factor of ~5 (short and medium footprints) and ~1.5 (long). These run
single-threaded (restored afterwards), as tests/test_waves.py, for steady timings on a shared 2-core
machine.
"""

import math

import numpy as np
import pytest
import torch
from scipy import ndimage

from roughsea_torch import foam
from roughsea_torch.foam import crest_foam_fraction, foam_emissivity, whitecap_fraction
from roughsea_torch.optics import fresnel_emissivity
from roughsea_torch.radiometry import LWIR, MWIR, band_radiance
from roughsea_torch.reference import foam as ref
from roughsea_torch.waves import WaveField

from conftest import ENSEMBLE_FOOTPRINTS as FOOTPRINTS
from conftest import ENSEMBLE_WIND as WIND

DTYPES = [(torch.float64, 1e-10), (torch.float32, 1e-6)]


# -- whitecap coverage, Monahan & O'Muircheartaigh 1980 ----------------------------------------


@pytest.mark.parametrize(
    "u10, percent, digits",
    # Coverage in % as quoted, rounded, with the law: 0.99 % at 10 m/s, 3.9 % at 15 m/s,
    # 0.2 % at 6 m/s, 12 % at 21 m/s, 0.42 % at 7.8 m/s. Each is asserted to its printed digits
    # (half a unit of the last digit): a changed coefficient or exponent moves them.
    [(10.0, 0.99, 2), (15.0, 3.9, 1), (6.0, 0.2, 1), (21.0, 12.0, 0), (7.8, 0.42, 2)],
)
def test_whitecap_published_values(u10, percent, digits):
    w = foam.whitecap_fraction(torch.tensor(u10, dtype=torch.float64))
    assert abs(float(w) * 100 - percent) <= 0.5 * 10.0**-digits


def test_whitecap_zero_monotone_and_capped_at_the_end_of_its_data():
    """The law over its data (to 25 m/s): 0 at calm, strictly increasing, silent; beyond, held at the
    closed form W(25) = 3.84e-6 · 25^3.41 = 0.2245 with a UserWarning (the old code went on silently to
    a sea all foam at 38.7 m/s, gradient exactly 0, no warning)."""
    import warnings

    u = torch.linspace(0.0, 25.0, 251, dtype=torch.float64)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        w = foam.whitecap_fraction(u)
    assert float(w[0]) == 0.0 and torch.all(torch.diff(w) > 0)
    cap = 3.84e-6 * 25.0**3.41
    assert cap == pytest.approx(0.2245, abs=5e-5)
    for above in (25.5, 38.7, 60.0):
        with pytest.warns(UserWarning, match=r"25 m/s.*Monahan"):
            assert float(foam.whitecap_fraction(torch.tensor(above, dtype=torch.float64))) == pytest.approx(cap, rel=1e-12)
    with pytest.warns(UserWarning, match="held"):
        np.testing.assert_allclose(ref.whitecap_fraction(np.array([10.0, 30.0])), [3.84e-6 * 10**3.41, cap], rtol=1e-12)


# -- foam emissivity, Niclòs et al. 2007 and Branch et al. 2016 ---------------------------------


@pytest.mark.parametrize("band", [LWIR, MWIR])
def test_foam_emissivity_measured_excess(band):
    """Foam minus flat-water emissivity: negligible at nadir and up to 45°, +0.04 at 65° (Niclòs 2007),
    0.23 at 85° (Branch 2016's maximum, 8.9 µm), held to 90°; between 65° and 85° linear in the water's
    emissivity (at 75°: 0.04 + 0.19 (ε_w(65°) − ε_w(75°)) / (ε_w(65°) − ε_w(85°))). The old model
    (Niclòs's slope continued) gave 0.08 at 85° and fails here."""
    deg = [0.0, 30.0, 45.0, 65.0, 75.0, 85.0, 88.0, 90.0]
    th = torch.tensor([math.radians(a) for a in deg], dtype=torch.float64)
    m = 1.218 + 0.0508j if band == LWIR else 1.351 + 0.0046j
    ew = lambda a: float(fresnel_emissivity(torch.tensor(math.cos(math.radians(a)), dtype=torch.float64), m))  # noqa: E731
    d75 = 0.04 + 0.19 * (ew(65) - ew(75)) / (ew(65) - ew(85))
    diff = foam.foam_emissivity(th, band) - fresnel_emissivity(torch.cos(th), m)
    np.testing.assert_allclose(diff.numpy(), [0.0, 0.0, 0.0, 0.04, d75, 0.23, 0.23, 0.23], atol=1e-12)


def test_foam_emissivity_values_and_angular_flattening():
    """Branch et al. 2016: the emissivity of both falls above 65°, foam's less; the difference grows
    with angle."""
    th = torch.deg2rad(torch.tensor([0.0, 65.0, 70.0, 75.0, 80.0, 85.0], dtype=torch.float64))
    eps_f = foam.foam_emissivity(th, LWIR)
    eps_w = fresnel_emissivity(torch.cos(th), 1.218 + 0.0508j)
    assert float(eps_f[0]) == pytest.approx(0.98982, abs=5e-5)  # = water at nadir (docs/physics.md §13)
    assert torch.all(eps_f >= eps_w) and torch.all(eps_f <= 1)
    assert torch.all(torch.diff(eps_f[1:]) < 0) and torch.all(torch.diff((eps_f - eps_w)[1:]) > 0)
    assert torch.all(eps_f[1] - eps_f[2:] < eps_w[1] - eps_w[2:])  # foam falls less than water


def test_foam_emissivity_rejects_visible_band():
    with pytest.raises(ValueError, match="band"):
        foam.foam_emissivity(0.1, (0.4e-6, 0.7e-6))


# -- second law, hemispherical mean, mixture ---------------------------------------------------


@pytest.mark.parametrize("dtype, tol", DTYPES)
def test_second_law_sky_equals_sea(dtype, tol):
    rb = band_radiance(torch.tensor(293.0, dtype=dtype))
    th = torch.linspace(0, math.pi / 2, 19, dtype=dtype)
    e = foam.sky_hemispherical_mean(lambda mu: rb.expand(mu.shape), dtype=dtype)
    torch.testing.assert_close(e, rb, rtol=tol, atol=0)
    r = foam.foam_radiance(th, LWIR, rb, e)
    torch.testing.assert_close(r, rb.expand_as(r), rtol=tol, atol=0)
    assert r.dtype == dtype


@pytest.mark.parametrize("reflection", ["reciprocal", "lambertian"])
@pytest.mark.parametrize("dtype, tol", DTYPES)
def test_second_law_with_the_reflected_sky(reflection, dtype, tol):
    """A sky at the sea's blackbody radiance: the sky the foam reflects is R_B (a weighted mean), so
    foam reads R_B whatever its emissivity, in both bands, for batched indices too."""
    rb = band_radiance(torch.tensor(291.0, dtype=dtype))
    th = torch.linspace(0, math.pi / 2, 19, dtype=dtype)
    for band in (LWIR, MWIR):
        s = foam.foam_sky_radiance(lambda mu: rb.expand(mu.shape), band, reflection=reflection, dtype=dtype)
        torch.testing.assert_close(foam.foam_radiance(th, band, rb, s), rb.expand(19), rtol=tol, atol=0)
    idx = (torch.tensor([1.2, 1.3, 1.35], dtype=dtype), torch.tensor([0.05, 0.01, 0.0046], dtype=dtype))
    s = foam.foam_sky_radiance(lambda mu: rb.expand(mu.shape), LWIR, idx, reflection=reflection, dtype=dtype)
    assert s.shape == ((3,) if reflection == "reciprocal" else ()) and s.dtype == dtype
    torch.testing.assert_close(s.expand(3), rb.expand(3), rtol=tol, atol=0)


def test_reciprocal_reflection_weights_the_warm_horizon():
    """The foam reflects the sky weighted by its own reflectance 1 − ε_f, which grows towards grazing:
    for a sky warming towards the horizon it reflects more than the cosine-weighted mean E_sky/π, and
    for a sky warming towards the zenith less; a constant sky gives the constant; the weights are
    ∝ (1 − ε_f(μ)) μ (checked at the nodes against the flat-water Fresnel emissivity plus Δ)."""
    horizon = lambda mu: 10.0 + 20.0 * (1 - mu) ** 4  # noqa: E731
    zenith = lambda mu: 10.0 + 20.0 * mu**4  # noqa: E731
    for sky in (horizon, zenith):
        s_r = float(foam.foam_sky_radiance(sky, LWIR, dtype=torch.float64))
        s_l = float(foam.foam_sky_radiance(sky, LWIR, reflection="lambertian", dtype=torch.float64))
        assert (s_r > s_l + 0.5) if sky is horizon else (s_r < s_l - 0.5)
    assert float(foam.foam_sky_radiance(lambda mu: torch.full_like(mu, 7.0), MWIR, dtype=torch.float64)) == pytest.approx(7.0, rel=1e-14)
    mu, w = foam.foam_sky_weights(LWIR, dtype=torch.float64)
    assert float(w.sum()) == pytest.approx(1.0, rel=1e-14) and bool((w > 0).all())
    rho = 1 - ref.foam_emissivity(np.arccos(mu.numpy()), LWIR)
    _, w_l = foam.foam_sky_weights(LWIR, reflection="lambertian", dtype=torch.float64)
    ratio = (w / w_l).numpy() / rho
    np.testing.assert_allclose(ratio, ratio[0], rtol=1e-12)


def test_hemispherical_mean_exact_for_polynomials():
    # 2 ∫ μ^k μ dμ = 2/(k+2)
    for k in range(6):
        e = foam.sky_hemispherical_mean(lambda mu, k=k: mu**k, n=8, dtype=torch.float64)
        assert float(e) == pytest.approx(2.0 / (k + 2), rel=1e-14)
    assert float(foam.sky_hemispherical_mean(7.5)) == 7.5
    batched = foam.sky_hemispherical_mean(lambda mu: torch.stack([mu, 2 * mu]), dtype=torch.float64)
    np.testing.assert_allclose(batched.numpy(), [2 / 3, 4 / 3], rtol=1e-14)


def test_mixture_end_points(dtype):
    g = torch.Generator().manual_seed(0)
    ra = torch.rand(5, generator=g, dtype=dtype) * 40
    rf = torch.rand(5, generator=g, dtype=dtype) * 40
    assert torch.equal(foam.with_foam(ra, 0.0, rf), ra)
    assert torch.equal(foam.with_foam(ra, 1.0, rf), rf)
    mid = foam.with_foam(ra, 0.25, rf)
    torch.testing.assert_close(mid, 0.75 * ra + 0.25 * rf)


# -- torch vs numpy reference ------------------------------------------------------------------


@pytest.mark.parametrize("dtype, tol", DTYPES)
def test_torch_matches_reference(dtype, tol):
    u = np.array([0.0, 0.5, 3.0, 7.0, 12.0, 20.0, 25.0])
    np.testing.assert_allclose(
        foam.whitecap_fraction(torch.tensor(u, dtype=dtype)).double().numpy(), ref.whitecap_fraction(u), rtol=tol
    )
    th = np.linspace(0, math.pi / 2, 37)
    for band in (LWIR, MWIR):
        np.testing.assert_allclose(
            foam.foam_emissivity(torch.tensor(th, dtype=dtype), band).double().numpy(),
            ref.foam_emissivity(th, band),
            rtol=tol, atol=tol,
        )
    sky = lambda mu: 11.0 + 20.0 * (1 - mu) ** 6 + 3.0 * np.exp(-5 * mu)  # noqa: E731
    tsky = lambda mu: 11.0 + 20.0 * (1 - mu) ** 6 + 3.0 * torch.exp(-5 * mu)  # noqa: E731
    e_ref = ref.sky_hemispherical_mean(sky)
    e = foam.sky_hemispherical_mean(tsky, dtype=dtype)
    assert float(e) == pytest.approx(e_ref, rel=tol)
    for band in (LWIR, MWIR):
        for reflection in ("reciprocal", "lambertian"):
            s = foam.foam_sky_radiance(tsky, band, reflection=reflection, dtype=dtype)
            assert float(s) == pytest.approx(ref.foam_sky_radiance(sky, band, reflection=reflection), rel=tol)
    m = (1.3, 0.02)
    s = foam.foam_sky_radiance(tsky, LWIR, (torch.tensor(m[0], dtype=dtype), torch.tensor(m[1], dtype=dtype)), dtype=dtype)
    assert float(s) == pytest.approx(ref.foam_sky_radiance(sky, LWIR, complex(*m)), rel=tol)
    rb = 30.0
    r = foam.foam_radiance(torch.tensor(th, dtype=dtype), LWIR, torch.tensor(rb, dtype=dtype), e)
    np.testing.assert_allclose(r.double().numpy(), ref.foam_radiance(th, LWIR, rb, e_ref), rtol=tol)
    ra = np.linspace(5, 35, 37)
    f = np.linspace(0, 1, 37)
    np.testing.assert_allclose(
        foam.with_foam(torch.tensor(ra, dtype=dtype), torch.tensor(f, dtype=dtype), r).double().numpy(),
        ref.with_foam(ra, f, ref.foam_radiance(th, LWIR, rb, e_ref)),
        rtol=tol,
    )


# -- gradients ---------------------------------------------------------------------------------


def test_gradient_through_whitecap_fraction():
    def chain(u):
        f = foam.whitecap_fraction(u)
        rf = foam.foam_radiance(torch.tensor(1.2, dtype=torch.float64), LWIR, 30.0, 12.0)
        return foam.with_foam(torch.tensor(25.0, dtype=torch.float64), f, rf)

    for u0 in (3.0, 10.0, 20.0):
        u = torch.tensor(u0, dtype=torch.float64, requires_grad=True)
        (g,) = torch.autograd.grad(chain(u), u)
        h = 1e-3
        fd = (chain(torch.tensor(u0 + h, dtype=torch.float64)) - chain(torch.tensor(u0 - h, dtype=torch.float64))) / (2 * h)
        assert torch.isfinite(g) and float(g) != 0.0
        assert float(g) == pytest.approx(float(fd), rel=1e-6)
    u = torch.tensor(0.0, dtype=torch.float64, requires_grad=True)
    (g0,) = torch.autograd.grad(chain(u), u)
    assert float(g0) == 0.0


def test_gradcheck_foam_sky_radiance():
    """Through the reflected sky: in the water's index (n, k) and the sky's level."""
    n = torch.tensor([1.22, 1.3], dtype=torch.float64, requires_grad=True)
    k = torch.tensor([0.05, 0.01], dtype=torch.float64, requires_grad=True)
    a = torch.tensor(12.0, dtype=torch.float64, requires_grad=True)
    fn = lambda n_, k_, a_: foam.foam_sky_radiance(lambda mu: a_ + 20 * (1 - mu) ** 6, LWIR, (n_, k_))  # noqa: E731
    assert torch.autograd.gradcheck(fn, (n, k, a))


def test_gradcheck_foam_radiance():
    th = torch.tensor([0.2, 0.9, 1.3], dtype=torch.float64, requires_grad=True)
    rb = torch.tensor(30.0, dtype=torch.float64, requires_grad=True)
    es = torch.tensor(12.0, dtype=torch.float64, requires_grad=True)
    assert torch.autograd.gradcheck(lambda a, b, c: foam.foam_radiance(a, LWIR, b, c), (th, rb, es))


# -- errors ------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "call, name",
    [
        (lambda: foam.whitecap_fraction(-1.0), "wind_speed"),
        (lambda: foam.whitecap_fraction(float("nan")), "wind_speed"),
        (lambda: foam.whitecap_fraction(float("inf")), "wind_speed"),
        (lambda: foam.foam_emissivity(2.0, LWIR), "view_zenith"),
        (lambda: foam.foam_radiance(0.1, LWIR, -1.0, 10.0), "sea_radiance"),
        (lambda: foam.foam_radiance(0.1, LWIR, 10.0, float("nan")), "sky_irradiance_over_pi"),
        (lambda: foam.with_foam(10.0, 1.5, 10.0), "foam_fraction"),
        (lambda: foam.with_foam(-1.0, 0.5, 10.0), "apparent_radiance"),
        (lambda: foam.with_foam(1.0, 0.5, float("inf")), "foam_radiance"),
        (lambda: foam.sky_hemispherical_mean(lambda mu: mu, n=0), "n"),
        (lambda: foam.sky_hemispherical_mean(-3.0), "sky"),
        (lambda: foam.foam_sky_radiance(lambda mu: mu, reflection="mirror"), "reflection"),
        (lambda: foam.foam_sky_radiance(lambda mu: mu, n=0), "n"),
        (lambda: foam.foam_sky_weights((0.4e-6, 0.7e-6)), "band"),
    ],
)
def test_value_errors(call, name):
    with pytest.raises(ValueError, match=name):
        call()


# -- foam on crests: roughsea_torch.foam.crest_foam_fraction on a textured sea --------------------


def _foam(ens: dict, name: str, w: float) -> torch.Tensor:
    return crest_foam_fraction(ens[name], ens[name + "_resolved_variance"], ens[name + "_total_variance"],
                               torch.tensor(w, dtype=torch.float64))


def _corr(a: torch.Tensor, b: torch.Tensor) -> torch.Tensor:
    """Correlation over the last dimension (one value per realization and footprint)."""
    a = a - a.mean(-1, keepdim=True)
    b = b - b.mean(-1, keepdim=True)
    return (a * b).mean(-1) / (a.pow(2).mean(-1) * b.pow(2).mean(-1)).sqrt()


W10 = float(whitecap_fraction(WIND))


@pytest.mark.parametrize("name", ["crest", "elevation"])
@pytest.mark.parametrize("w", [W10, 0.1])
@pytest.mark.parametrize("i", range(len(FOOTPRINTS)), ids=[f"{f:g}m" for f in FOOTPRINTS])
@pytest.mark.usefixtures("one_thread")
def test_ensemble_mean_is_the_whitecap_fraction(crest_ensemble, name, w, i):
    """E[f_pix] = W at short, medium and long footprints: the mean over 120 realizations (of the mean
    over 2048 points each) is W within 4 standard errors computed from the realizations, and the
    test resolves a 20 % error. (Measured at 10 m/s, W = 0.99 %: 1.055 ± 0.034, 1.055 ± 0.033,
    1.006 ± 0.007 W for 0.05, 3, 30 m; the planted σ_X-for-σ_u bug gives 5.1, 4.9, 1.5 W.)"""
    f = _foam(crest_ensemble, name, w)[:, i]
    per = f.mean(-1) / w
    mean, se = float(per.mean()), float(per.std() / math.sqrt(per.numel()))
    assert 4 * se < 0.2, f"test too noisy: standard error {se}"
    assert abs(mean - 1.0) < 4 * se, (mean, se)


@pytest.mark.usefixtures("one_thread")
def test_far_field_is_the_uniform_fraction(dtype):
    """Where the footprint is much larger than the longest band (1 km, 10 km, inf: every band's window
    is exactly 0), X_r = 0, σ_r² = 0 and f_pix = W to 1e-6 (relative); and the approach is continuous:
    at 10 m/s X's resolved part (breaking scales, 4–25 k_p) is already negligible at 150 m
    (|f_pix − W| < 1e-3 W), at 20 m/s (waves four times longer) it is not."""
    field = WaveField(torch.tensor([WIND, 20.0], dtype=torch.float64), [3, 4], dtype=dtype)
    w = whitecap_fraction(torch.tensor([WIND, 20.0], dtype=dtype))[:, None]
    gen = torch.Generator().manual_seed(4)
    x = (torch.rand(2, 1000, generator=gen, dtype=torch.float64) * 3000).to(dtype)
    y = (torch.rand(2, 1000, generator=gen, dtype=torch.float64) * 3000).to(dtype)
    for fp, tol in ((1e3, 1e-6), (1e4, 1e-6), (math.inf, 1e-6), (150.0, 1e-3)):
        rows = slice(None) if fp >= 1e3 else slice(0, 1)
        f_t = torch.tensor(fp, dtype=dtype)
        s = field.sample(x, y, 5.0, footprint=f_t, elevation=False, crest=True)
        vr = field.crest_variance(f_t)[:, None]
        f = crest_foam_fraction(s["crest"], vr, field.crest_variance()[:, None], w)
        assert f.dtype == dtype
        if fp >= 1e3:
            assert bool((s["crest"] == 0).all()) and bool((vr == 0).all())
        assert float(((f - w) / w)[rows].abs().max()) < tol, fp
        if fp == 150.0:
            assert float(((f - w) / w)[1].abs().max()) > 0.1  # 20 m/s: not vacuous


@pytest.mark.usefixtures("one_thread")
def test_foam_sits_on_crests(crest_ensemble):
    """Foam-weighted mean of the resolved elevation E[f η_r]/E[f]: above 0.6 σ_η at the short and
    medium footprints (measured 1.0 and 0.9 σ_η: X is the band 4–25 k_p, in phase with the short
    waves' elevation, which is a fraction of η's), positive at the long one; correlation of f_pix
    with η_r positive at every footprint, > 0.05 at the short one (0.11), with X_r > 0.2 there."""
    f = _foam(crest_ensemble, "crest", W10)
    eta, x = crest_ensemble["elevation"], crest_ensemble["crest"]
    sigma = crest_ensemble["elevation_total_variance"][..., 0].sqrt()  # (n, 1)
    lift = ((f * eta).sum(-1) / f.sum(-1) / sigma).mean(0)
    assert bool((lift[:2] > 0.6).all()) and float(lift[2]) > 0.0, lift
    for v, short in ((eta, 0.05), (x, 0.2)):
        c = _corr(f, v)
        mean, se = c.mean(0), c.std(0) / math.sqrt(c.shape[0])
        assert bool((mean > 4 * se).all()) and float(mean[0]) > short, (mean, se)
    assert float(_corr(f, x).mean(0)[2]) > 0.7  # long footprint: f_pix smooth in X_r


@pytest.mark.usefixtures("one_thread")
def test_foam_is_independent_of_the_resolved_slope(crest_ensemble):
    """f_pix is a function of X_r, which is uncorrelated with the slopes at the same point (X in phase
    with η, the slopes in quadrature), hence independent (jointly Gaussian): the correlations of
    f_pix with s_x, s_y and |s|² are zero within 4 standard errors and below 0.02 (so
    (1 − f_pix)·texture keeps the texture's mean)."""
    f = _foam(crest_ensemble, "crest", W10)
    sx, sy = crest_ensemble["slope_x"], crest_ensemble["slope_y"]
    for v in (sx, sy, sx * sx + sy * sy):
        c = _corr(f, v)
        mean, se = c.mean(0), c.std(0) / math.sqrt(c.shape[0])
        assert bool((mean.abs() < 4 * se + 1e-3).all()) and bool((mean.abs() < 0.02).all()), (mean, se)


@pytest.mark.usefixtures("one_thread")
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
@pytest.mark.usefixtures("one_thread")
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


@pytest.mark.usefixtures("one_thread")
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


@pytest.mark.usefixtures("one_thread")
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


@pytest.mark.usefixtures("one_thread")
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


@pytest.mark.parametrize("band, index", [((2.41e-6, 2.61e-6), 1.351 + 0.0046j), ((5.89e-6, 6.09e-6), 1.351 + 0.0046j),
                                         ((6.91e-6, 7.11e-6), 1.218 + 0.0508j), ((14.85e-6, 15.0e-6), 1.218 + 0.0508j)],
                         ids=["centre_2.51um", "centre_5.99um", "centre_7.01um", "centre_14.93um"])
def test_foam_emissivity_takes_the_bands_hale_querry_index_up_to_the_range_edges(band, index):
    """A band centred in 2.5–6 µm takes Hale & Querry's 4 µm water index, one in 7–15 µm the 10 µm
    index (the documented default), up to the ranges' edges: the emissivity equals the one with that
    index given, at every view zenith (where the foam excess is 0 and where it is not); so does the
    numpy reference's."""
    th = torch.linspace(0.0, math.pi / 2, 19, dtype=torch.float64)
    torch.testing.assert_close(foam_emissivity(th, band), foam_emissivity(th, band, refractive_index=index),
                               rtol=1e-15, atol=0)
    np.testing.assert_allclose(ref.foam_emissivity(th.numpy(), band), ref.foam_emissivity(th.numpy(), band, index),
                               rtol=1e-15, atol=0)


@pytest.mark.usefixtures("one_thread")
def test_whitecap_patches_are_ellipses_across_the_wind():
    """Active breakers are ellipses elongated along their crest, across the wind, with a minor/major
    axis ratio of 0.41 on average (Korinenko et al. 2024, platform video). Patches of f > 0.5 (15 m/s,
    0.25 m footprint, 96 m × 96 m of two realizations, patches of ≥ 8 cells): their mean axis ratio
    (square root of the eigenvalue ratio of the cells' coordinate covariance) lies in 0.35–0.48, and
    the major axis points across the wind in most of them. Measured 0.45, 97 % across; with the spectrum's own
    spreading (wave_lattice.CREST_DIRECTIONAL = 0) the patches are rounder, 0.6, and the test fails."""
    step, wind = 0.25, torch.tensor([15.0], dtype=torch.float64)
    g = torch.arange(0.0, 96.0, step, dtype=torch.float64)
    x, y = torch.meshgrid(g, g, indexing="ij")  # x along the wind axis (wind_direction 0)
    fp = torch.tensor(step, dtype=torch.float64)
    ratios, across = [], []
    for seed in (11, 12):
        field = WaveField(wind, [seed], dtype=torch.float64)
        c = field.sample(x[None], y[None], 0.0, footprint=fp, elevation=False, crest=True)["crest"]
        f = crest_foam_fraction(c, field.crest_variance(fp), field.crest_variance(), whitecap_fraction(wind))[0]
        lab, n = ndimage.label((f > 0.5).numpy())
        for i in range(1, n + 1):
            cells = np.argwhere(lab == i).astype(float)
            if len(cells) >= 8:
                ev, vec = np.linalg.eigh(np.cov(cells.T))
                ratios.append(math.sqrt(max(ev[0], 0.0) / ev[1]))
                across.append(abs(vec[1, 1]) > abs(vec[0, 1]))  # major axis nearer the y (crosswind) axis
    assert len(ratios) >= 30, len(ratios)
    assert 0.35 < float(np.mean(ratios)) < 0.48, np.mean(ratios)
    assert np.mean(across) > 0.7, np.mean(across)


@pytest.mark.parametrize("dtype", [torch.float32, torch.float64])
def test_vanishing_crest_is_where_the_cover_underflows_to_exactly_zero(dtype):
    """foam.vanishing_crest x₀: Φ((x − c)/σ_u) = erfc(−z/√2)/2 and its derivative are exactly 0 for
    x ≤ x₀ (erfc underflows from 10.2 in float32, 27.3 in float64; x₀ puts the argument at 11 and 28),
    over W from 1e-6 to 0.2, resolved variances from 0 to σ_X², points from a near footprint to the far
    field; and x₀ is not loose: 2 σ_u above it the cover is no longer 0.
    W = 1 and a field without crest variance (the cover W, whatever x) give +inf. Fails with the
    argument's bound at 9.5 (float32) or 26 (float64) instead (planted: nonzero covers at x₀)."""
    w = torch.tensor([1e-6, 1e-3, 0.01, 0.2], dtype=dtype)[:, None]
    v_t = torch.tensor(0.7, dtype=dtype)
    v_r = torch.linspace(0.0, 0.7, 9, dtype=dtype)[None, :]
    x0 = foam.vanishing_crest(v_r, v_t, w, dtype)
    assert x0.dtype == torch.float64 and x0.shape == (4, 9) and bool(torch.isfinite(x0).all())
    for shift in (0.0, -1e-3, -0.5, -5.0):
        x = (x0 + shift).to(dtype).requires_grad_(True)
        f = foam.crest_fraction_from_variances(x, v_r, v_t, w)
        (g,) = torch.autograd.grad(f.sum(), [x])
        assert bool((f == 0).all()) and bool((g == 0).all())
    sigma_u = torch.sqrt((v_t - v_r).clamp_min(0) + foam.CREST_FOAM_FLOOR ** 2 * v_t).double()
    above = (x0 + 2.0 * sigma_u).to(dtype)
    assert bool((foam.crest_fraction_from_variances(above, v_r, v_t, w) > 0).all())
    ends = foam.vanishing_crest(torch.tensor([0.2, 0.0], dtype=dtype), torch.tensor([0.7, 0.0], dtype=dtype),
                                torch.tensor([1.0, 0.01], dtype=dtype), dtype)
    assert bool(torch.isposinf(ends).all())

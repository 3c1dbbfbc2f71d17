"""The clutter statistics of the ray-tracer comparisons (``pipelines/texture_vs_raytrace.py``,
``pipelines/clutter_octaves.py``) on synthetic images whose answer is known: a noise-corrected σ and the
noise-free second moments of a difference of two traces recover the planted variances, correlation and
autocorrelation within their sampling error."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

PIPELINES = Path(__file__).resolve().parents[1] / "pipelines"


@pytest.fixture(scope="module")
def octaves():
    sys.path.insert(0, str(PIPELINES))
    try:
        import clutter_octaves
        yield clutter_octaves
    finally:
        sys.path.remove(str(PIPELINES))


def _field(rng, shape, rho):
    """Unit-variance Gaussian clutter with correlation ``rho`` between neighbouring columns (AR(1) along rows)."""
    x = rng.standard_normal(shape)
    for j in range(1, shape[1]):
        x[:, j] = rho * x[:, j - 1] + np.sqrt(1.0 - rho * rho) * x[:, j]
    return x


def test_added_part_recovers_the_planted_statistics(octaves):
    """T4 = resolved clutter; T64 = T4 + D with D = 0.5·(resolved) + new clutter correlated 0.4 across; each
    trace with its own sampling noise (variance twice var D, given per pixel as the pipeline receives it):
    var D, corr(D, T4) and D's autocorrelation at one pixel across and along come back as the noise-free
    planted images give them (row means removed alike), over four realizations. Removing a row's mean
    leaves white noise correlated −σ²/W across: uncorrected, that bias (−0.12 here) is what the
    autocorrelation check would catch (it did, in the first version of the pipeline)."""
    clutter = octaves.tvr.clutter
    for seed in range(4):
        rng = np.random.default_rng(seed)
        shape = (800, 32)
        t4 = 0.1 * _field(rng, shape, 0.6)
        d = 0.5 * t4 + 0.08 * _field(rng, shape, 0.4)
        cd, c4 = clutter(d), clutter(t4)
        var_d = float((cd**2).mean())
        corr = float((cd * c4).mean() / np.sqrt(var_d * (c4**2).mean()))
        acf = float((cd[:, 1:] * cd[:, :-1]).mean() / var_d)
        noise_var = 2.0 * var_d
        n4, n64 = (np.sqrt(noise_var) * rng.standard_normal(shape) for _ in range(2))
        out = octaves.added_part({"T": t4 + d + n64, "noise": np.full(shape, noise_var)},
                                 {"T": t4 + n4, "noise": np.full(shape, noise_var)})
        assert out["var"] == pytest.approx(var_d, rel=0.12)
        assert out["corr_t4"] == pytest.approx(corr, abs=0.08)
        assert out["acf_across"] == pytest.approx(acf, abs=0.06)
        assert abs(out["acf_along"]) < 0.06  # rows independent


def test_correlation_length_is_free_of_the_noise(octaves):
    """The ray trace's correlation length (``texture_vs_raytrace.correlation_length``) of a noisy image,
    given its noise variance, is that of the noise-free image, over four realizations: clutter correlated
    0.75 between neighbouring columns, white noise of twice its variance. Removing each row's mean leaves
    the noise correlated −σ²/W at every lag; uncorrected, that shortened the length (by 0.2 px here)."""
    for seed in range(4):
        rng = np.random.default_rng(10 + seed)
        shape = (800, 32)
        img = 0.1 * _field(rng, shape, 0.75)
        noise_var = 2.0 * float(octaves.tvr.clutter(img).var())
        noisy = img + np.sqrt(noise_var) * rng.standard_normal(shape)
        clean = octaves.tvr.correlation_length(img)
        assert octaves.tvr.correlation_length(noisy, np.full(shape, noise_var)) == pytest.approx(clean, abs=0.12)


def test_ensemble_sigma_ratio_removes_the_noise_and_its_interval_holds_the_planted_ratio():
    """``pipelines/ensemble_sigma.py``'s σ ratio over 16 realizations (``bin_ratio``): each realization's
    clutter scaled alike in both images (by 0.6–1.6, as realizations differ), the ray-traced one 1/1.125 of
    the textured one's and carrying white noise of 1.3 times its variance, given per pixel, as at 256 rays
    per pixel at 88°. Over four draws the ratio comes back within 0.06 of 1.125 and inside its 95 %
    bootstrap interval, an interval less than 0.3 wide; planted, the noise not removed, it reads 0.75 and fails."""
    sys.path.insert(0, str(PIPELINES))
    try:
        import ensemble_sigma
    finally:
        sys.path.remove(str(PIPELINES))
    for draw in range(4):
        rng = np.random.default_rng(40 + draw)
        images = []
        for amp in rng.uniform(0.6, 1.6, 16):
            base = 0.04 * amp * _field(rng, (8, 64), 0.3)
            sig_r = 0.04 * amp / 1.125
            noise_var = 1.3 * sig_r**2
            ray = base / 1.125 + np.sqrt(noise_var) * rng.standard_normal((8, 64))
            images.append(dict(tex=base, ray=ray, noise=np.full((8, 64), noise_var)))
        b = ensemble_sigma.bin_ratio(images, 0)
        assert b["ratio"] == pytest.approx(1.125, abs=0.06)
        assert b["lo"] <= 1.125 <= b["hi"] and b["hi"] - b["lo"] < 0.3

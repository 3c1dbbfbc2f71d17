"""Argument checks and the dtype and device of a call (roughsea_torch._validation).

The result's dtype follows numpy inputs as it follows tensors: a numpy float64 array gives a float64
result (it gave float32, silently losing 9 digits), a float32 array float32. The values are checked
too: the float64 result of a numpy float64 input must equal, to 1e-12, the float64 result of the same
numbers given as a float64 tensor, and must differ from the float32 result by more than float32
rounding allows to be invisible (so a result computed in float32 and cast up fails). Tensors on
different devices are an error; per-image arguments and finite ranges are checked with messages that
name the argument.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import torch

import roughsea_torch as rs
from roughsea_torch._validation import check_finite_range

from conftest import M10


SKY = 12.0


def calls(x):
    """Core functions of one float array x (angles in [0, 1.5] rad) or of values derived from it."""
    s = rs.SlopeStatistics.cox_munk(5.0)
    cos = torch.cos if isinstance(x, torch.Tensor) else np.cos
    return {
        "emissivity": lambda: rs.emissivity(x, 0.3, s, M10),
        "apparent_radiance": lambda: rs.apparent_radiance(x, 0.3, s, M10, sea_radiance=30.0, sky=SKY),
        "projected_area": lambda: rs.projected_area(x, 0.3, s),
        "smith_lambda": lambda: rs.smith_lambda(x, 0.3, s),
        "fresnel_reflectance": lambda: rs.fresnel_reflectance(cos(x), M10),
        "fresnel_emissivity": lambda: rs.fresnel_emissivity(cos(x), M10),
        "band_radiance": lambda: rs.band_radiance(280.0 + 10.0 * x),
        "planck_radiance": lambda: rs.planck_radiance(1e-5 * (1.0 + 0.1 * x), 290.0),
        "brightness_temperature": lambda: rs.brightness_temperature(9.0 + x),
        "slope_pdf": lambda: rs.slope_pdf(0.5 * x, 0.4, s),
    }


NAMES = list(calls(np.zeros(1)))


@pytest.mark.parametrize("name", NAMES)
def test_numpy_float64_input_gives_float64_result(name):
    x64 = np.array([0.1, 0.7 + 1e-9, 1.3])
    out = calls(x64)[name]()
    assert out.dtype == torch.float64, f"{name}: numpy float64 in, {out.dtype} out"
    ref = calls(torch.tensor(x64, dtype=torch.float64))[name]()
    np.testing.assert_allclose(out.numpy(), ref.numpy(), rtol=1e-12, atol=0)
    out32 = calls(x64.astype(np.float32))[name]()
    assert out32.dtype == torch.float32, f"{name}: numpy float32 in, {out32.dtype} out"


def test_numpy_float64_slopes_and_scalars():
    """Slope statistics built from numpy float64 arrays, and numpy float64 scalars alone, give
    float64; beside a float32 tensor a numpy scalar does not promote (torch's own rule)."""
    s = rs.SlopeStatistics.cox_munk(np.array([3.0, 9.0]))
    assert rs.emissivity(0.4, 0.0, s, M10).dtype == torch.float64
    assert rs.emissivity(np.float64(0.4), 0.0, rs.SlopeStatistics.cox_munk(5.0), M10).dtype == torch.float64
    t32 = torch.tensor([0.4], dtype=torch.float32)
    assert rs.emissivity(t32, np.float64(0.1), rs.SlopeStatistics.cox_munk(5.0), M10).dtype == torch.float32
    m = np.array([1.218 + 0.0508j])  # complex128 index → float64
    assert rs.fresnel_reflectance(0.5, m).dtype == torch.float64


def test_float64_numpy_keeps_digits_float32_would_lose():
    """Two view angles 1e-9 rad apart near 60° give different float64 emissivities (dε/dθ ~ 0.1);
    in float32 they round to the same angle."""
    s = rs.SlopeStatistics.cox_munk(5.0)
    x = np.array([math.radians(60.0), math.radians(60.0) + 1e-9])
    e = rs.emissivity(x, 0.0, s, M10)
    assert float(e[1] - e[0]) != 0.0


def test_complex_index_dtype_sets_the_precision():
    """A complex128 refractive index is float64 data, complex64 float32 (their real parts), as for
    numpy complex arrays."""
    m128 = torch.tensor(1.218 + 0.0508j, dtype=torch.complex128)
    m64 = torch.tensor(1.218 + 0.0508j, dtype=torch.complex64)
    assert rs.fresnel_reflectance(0.5, m128).dtype == torch.float64
    assert rs.fresnel_reflectance(0.5, m64).dtype == torch.float32
    assert rs.fresnel_reflectance(0.5, np.array(1.218 + 0.0508j, dtype=np.complex64)).dtype == torch.float32


def test_mismatched_devices_raise():
    th = torch.tensor([0.5], device="meta")
    with pytest.raises(ValueError, match="mismatched devices"):
        rs.emissivity(th, torch.tensor([0.1]), rs.SlopeStatistics.cox_munk(5.0), M10)


def test_per_image_arguments():
    """``per_batch``: a number or a () tensor becomes one value per image; a (B,) tensor is kept;
    any other shape is a ValueError naming the argument and the shape it must have."""
    from roughsea_torch._validation import per_batch

    F = torch.float64
    cpu = torch.device("cpu")
    assert torch.equal(per_batch("x", 2.5, 3, F, cpu), torch.full((3,), 2.5, dtype=F))
    assert torch.equal(per_batch("x", torch.tensor(1.5), 2, F, cpu), torch.full((2,), 1.5, dtype=F))
    v = torch.tensor([1.0, 2.0, 3.0])
    assert torch.equal(per_batch("x", v, 3, F, cpu), v.double())
    assert torch.equal(per_batch("x", np.array([1.0, 2.0, 3.0]), 3, F, cpu), v.double())
    with pytest.raises(ValueError, match=r"x: .*\(B,\) = \(3,\)"):
        per_batch("x", torch.ones(2), 3, F, cpu)
    with pytest.raises(ValueError, match="x"):
        per_batch("x", torch.ones(3, 1), 3, F, cpu)


def test_check_finite_range_names_non_numeric_and_complex_input():
    for x in ("a", ["a"], np.array(["a"]), [[1.0, 2.0], [3.0]]):
        with pytest.raises(ValueError, match=r"^x must be a real number or a tensor of real numbers"):
            check_finite_range("x", x)
    with pytest.raises(ValueError, match=r"^x must be real"):  # the imaginary part used to be dropped
        check_finite_range("x", np.array([1.0 + 1.0j]))

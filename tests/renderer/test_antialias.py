"""The texture's filter along the columns (roughsea_torch.renderer.antialias): its transfer function
in closed form, the sea mask, and a light-wind far field without one-pixel horizontal lines."""

from __future__ import annotations

import math
import warnings

import pytest
import torch

import roughsea_torch as rs
from conftest import make_cams
from roughsea_torch.renderer.antialias import FOAM_TAPS, TEXTURE_TAPS, filter_columns

pytestmark = pytest.mark.usefixtures("one_thread")


@pytest.mark.parametrize("nu", [0.0, 0.125, 0.25, 0.4, 0.5])
@pytest.mark.parametrize("which", ["texture", "foam"])
def test_response_in_closed_form_with_a_zero_at_nyquist(dtype, nu, which):
    """A row pattern cos(2π ν i + 0.3) (ν in cycles per pixel) comes out times H(ν) in the interior:
    the texture's five taps H = (10 + 8 cos 2πν − 2 cos 4πν)/16, the foam fraction's three
    H = cos² πν; both 1 at 0 and 0 at the Nyquist frequency 1/2 (one-pixel lines)."""
    i = torch.arange(40, dtype=dtype)
    x = torch.cos(2 * math.pi * nu * i + 0.3)[None, :, None].expand(2, 40, 3).contiguous()
    taps = TEXTURE_TAPS if which == "texture" else FOAM_TAPS
    out = filter_columns(x, torch.ones_like(x, dtype=torch.bool), taps)
    c = math.cos(2 * math.pi * nu)
    gain = (10 + 8 * c - 2 * (2 * c * c - 1)) / 16 if which == "texture" else math.cos(math.pi * nu) ** 2
    tol = 2e-5 if dtype == torch.float32 else 1e-13  # float32: cos of arguments up to 100 rad
    torch.testing.assert_close(out[:, 2:-2], gain * x[:, 2:-2], rtol=0, atol=tol)


def test_mask_edges_renormalize_and_leave_other_pixels_alone(dtype):
    """Three taps: outside the sea nothing changes; a sea pixel with one sea neighbour gets
    (2 v + v_n)/3, one with none keeps its value; the weights sum to 1 everywhere (a constant stays that
    constant, five taps too); gradients are finite and sum to 1 per output pixel."""
    v = torch.tensor([[5.0, 1.0, 2.0, 4.0, 8.0, 7.0]], dtype=dtype)[..., None].requires_grad_(True)
    sea = torch.tensor([[False, True, True, True, False, True]])[..., None]
    out = filter_columns(v, sea, FOAM_TAPS)
    want = torch.tensor([5.0, (2 * 1 + 2) / 3, (1 + 4 + 4) / 4, (2 + 8) / 3, 8.0, 7.0], dtype=dtype)
    torch.testing.assert_close(out[0, :, 0], want)
    const = filter_columns(torch.full((1, 6, 1), 3.5, dtype=dtype), sea, FOAM_TAPS)
    assert torch.equal(const, torch.full_like(const, 3.5))
    const5 = filter_columns(torch.full((1, 6, 1), 3.5, dtype=dtype), sea, TEXTURE_TAPS)
    torch.testing.assert_close(const5, torch.full_like(const5, 3.5))
    (g,) = torch.autograd.grad(out[0, 2, 0], v)
    assert bool(torch.isfinite(g).all()) and abs(float(g.sum()) - 1.0) < 1e-6


def _adjacent_row_correlation(delta: torch.Tensor, rows: slice) -> float:
    """Pooled correlation of vertically adjacent pixels of the departures from each row's mean."""
    r = delta[:, rows]
    r = r - r.mean(-1, keepdim=True)
    a, b = r[:, :-1], r[:, 1:]
    return float((a * b).sum() / torch.sqrt((a * a).sum() * (b * b).sum()))


@pytest.mark.parametrize("method", ["table", "direct"])
def test_light_wind_far_field_has_no_one_pixel_lines(method):
    """2 m/s, 15 m up, 8° down (the README's textured-winds scene, 128 rows): 30 to 60 rows below the
    horizon the unfiltered texture is dominated by the resolved band at the rows' Nyquist frequency,
    folded by point sampling (adjacent rows anti-correlated, below −0.5); filtered (the default) they
    are not (above −0.3: the filter's response is 0 at Nyquist). Three realizations; the texture is
    the render minus the expectation image of the same scene."""
    cams = make_cams(128, 160, hfov_deg=20.0, altitude_m=15.0, pitch_deg=-8.0, batch_size=3)
    kw = dict(wind_speed=2.0, sea_temperature=290.0, foam=False)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the light-wind rescaling of the resolved slopes (reconcile_scale)
        mean = rs.render(cams, rs.SeaScene(**kw), method=method)[:, 0]
        seeded = rs.SeaScene(**kw, seed=[1, 2, 3])
        raw = rs.render(cams, seeded, method=method, table=rs.TableSize(texture_antialias=False))[:, 0] - mean
        filtered = rs.render(cams, seeded, method=method)[:, 0] - mean
    far = slice(30, 60)
    assert _adjacent_row_correlation(raw, far) < -0.5
    assert _adjacent_row_correlation(filtered, far) > -0.3
    assert float(filtered[:, far].std()) > 0.0  # the filtered far field still has texture


def test_table_size_rejects_a_non_boolean_antialias():
    with pytest.raises(ValueError, match="texture_antialias"):
        rs.TableSize(texture_antialias="yes")

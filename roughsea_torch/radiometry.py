"""Planck radiance, sensor bands, band radiance and its inverse (brightness temperature).

Units (``docs/physics.md`` §2): wavelength in metres, temperature in kelvin, spectral radiance in
W m⁻² sr⁻¹ m⁻¹, band radiance in W m⁻² sr⁻¹. Constants are the exact CODATA 2018 values.
"""

from __future__ import annotations

import hashlib
import math
import weakref
from collections import OrderedDict
from dataclasses import dataclass
from functools import lru_cache
from typing import Any

import numpy as np
import torch

from ._lookup import bucket_grid, next_nodes
from ._validation import as_tensor, check_finite_range, resolve_dtype_device

__all__ = [
    "PLANCK_H",
    "SPEED_OF_LIGHT",
    "BOLTZMANN_K",
    "LWIR",
    "MWIR",
    "SpectralBand",
    "planck_radiance",
    "planck_radiance_derivative",
    "band_radiance",
    "brightness_temperature",
    "band_radiance_slope",
]

PLANCK_H = 6.62607015e-34  # J s
SPEED_OF_LIGHT = 299792458.0  # m s⁻¹
BOLTZMANN_K = 1.380649e-23  # J K⁻¹
_C1 = 2.0 * PLANCK_H * SPEED_OF_LIGHT**2  # W m² sr⁻¹ (first radiation constant, per sr)
_C2 = PLANCK_H * SPEED_OF_LIGHT / BOLTZMANN_K  # m K (second radiation constant)

LWIR = (8e-6, 12e-6)
MWIR = (3e-6, 5e-6)


def planck_radiance(wavelength: Any, temperature: Any) -> torch.Tensor:
    """Blackbody spectral radiance B_λ(T) [W m⁻² sr⁻¹ m⁻¹].

    Args:
        wavelength: λ [m], > 0.
        temperature: T [K], > 0.

    B_λ = 2 h c² λ⁻⁵ / (exp(h c / (λ k T)) − 1); ``expm1`` keeps the long-wavelength end accurate.
    """
    check_finite_range("wavelength", wavelength, 0.0, lo_open=True, unit="m")
    check_finite_range("temperature", temperature, 0.0, lo_open=True, unit="K")
    dtype, device = resolve_dtype_device(wavelength=wavelength, temperature=temperature)
    lam = as_tensor(wavelength, dtype, device)
    t = as_tensor(temperature, dtype, device)
    return _planck(lam, t)


def _planck(lam: torch.Tensor, t: torch.Tensor) -> torch.Tensor:
    # Scale to micrometres inside so float32 never sees λ⁻⁵ ~ 1e30. Written with e^{−x} so that a
    # cold body (x = hc/λkT beyond the exponent range: 10 K in float32) gives B = 0 and a zero
    # gradient, where 1/expm1(x) = 1/∞ had a NaN gradient (∞/∞); ``pipelines/stability.py``.
    lam_um = lam * 1e6
    x = (_C2 * 1e6) / (lam_um * t)
    return (_C1 * 1e24 * 1e6) * torch.exp(-x) / (lam_um**5 * -torch.expm1(-x))


def planck_radiance_derivative(lam: torch.Tensor, t: torch.Tensor) -> torch.Tensor:
    """Temperature derivative of the blackbody spectral radiance, ∂B_λ/∂T [W m⁻² sr⁻¹ m⁻¹ K⁻¹].

    Args:
        lam: wavelength λ [m] > 0, a tensor.
        t: temperature T [K] > 0, a tensor of the same dtype and device, broadcastable with ``lam``.

    ∂B_λ/∂T = B_λ · x / (T (1 − e^{−x})) with x = h c / (λ k T); 0 (not NaN) where B_λ underflows.
    Summed with a band's quadrature weights (``SpectralBand.nodes``) it gives dL/dT of
    :func:`band_radiance`. The inputs are not checked (it runs inside band sums); see
    :func:`planck_radiance` for B_λ itself on checked inputs.
    """
    lam_um = lam * 1e6
    x = (_C2 * 1e6) / (lam_um * t)
    return _planck(lam, t) * x / (t * -torch.expm1(-x))


@dataclass(frozen=True)
class SpectralBand:
    """A sensor band: wavelength limits [m] and an optional relative spectral response.

    Args:
        lo, hi: band limits λ_lo < λ_hi [m].
        response: None (flat, 1), a callable of wavelength [m] (numpy array in, numpy array out),
            or a pair (wavelength [m], response) of 1-d arrays interpolated linearly, 0 outside.
        nodes_per_panel: Gauss–Legendre nodes per panel; the band is split into panels at the
            nodes of a tabulated response so that its kinks sit at panel edges.

    The quadrature (``nodes``, ``weights``) integrates ∫ r(λ) f(λ) dλ as Σ wᵢ f(λᵢ): the response
    is folded into the weights.
    """

    lo: float
    hi: float
    response: Any = None
    nodes_per_panel: int = 24

    def __post_init__(self) -> None:
        check_finite_range("band[0]", self.lo, 0.0, lo_open=True, unit="m")
        check_finite_range("band[1]", self.hi, 0.0, lo_open=True, unit="m")
        if not self.hi > self.lo:
            raise ValueError(f"band: need lo < hi, got ({self.lo!r}, {self.hi!r}) m")
        if self.lo < 1e-7 or self.hi > 1e-3:
            raise ValueError(
                f"band: limits must be wavelengths in metres within [1e-7, 1e-3]; got ({self.lo!r}, {self.hi!r}). "
                + ("" if self.hi <= 1e-3 else "Did you pass micrometres? " if self.hi <= 100.0 else "Did you pass nanometres? ")
                + "(8-12 µm is (8e-6, 12e-6))"
            )

    @property
    def quadrature(self) -> tuple[np.ndarray, np.ndarray]:
        return _band_quadrature(self)

    def nodes(self, dtype: torch.dtype, device: torch.device) -> tuple[torch.Tensor, torch.Tensor]:
        lam, w = self.quadrature
        return (
            torch.as_tensor(lam, dtype=dtype, device=device),
            torch.as_tensor(w, dtype=dtype, device=device),
        )

    def __hash__(self) -> int:  # responses given as arrays are not hashable themselves
        return hash((self.lo, self.hi, id(self.response), self.nodes_per_panel))


_CACHE_SIZE = 32  # bands held by each cache (least recently used dropped first)
_band_cache: OrderedDict[tuple, tuple[Any, tuple[np.ndarray, np.ndarray]]] = OrderedDict()


def _band_key(band: SpectralBand) -> tuple[tuple, Any]:
    """(cache key, weak reference guard) of a band.

    A flat band or a tabulated response is keyed by value (limits, nodes and the table's bytes):
    every equal band shares one entry, whatever object carries it, and nothing is kept alive. A
    callable response can only be keyed by identity: its key holds ``id(response)`` and the guard
    a weak reference to it, so that an entry whose response was collected (and whose id may be
    reused by another object) is never returned. Callables that take no weak reference are not
    cached (guard ``False``).
    """
    resp = band.response
    head = (float(band.lo), float(band.hi), int(band.nodes_per_panel))
    if resp is None:
        return head + ("flat",), None
    if callable(resp):
        try:
            return head + ("callable", id(resp)), weakref.ref(resp)
        except TypeError:
            return head + ("callable", id(resp)), False
    try:
        wl, rv = (np.ascontiguousarray(np.asarray(a, dtype=np.float64)) for a in resp)
    except (TypeError, ValueError):
        raise ValueError("response: a table must be two 1-d arrays (wavelength ascending [m], response)")
    digest = hashlib.blake2b(wl.tobytes() + b"|" + rv.tobytes() + repr((wl.shape, rv.shape)).encode(), digest_size=16)
    return head + ("table", digest.hexdigest()), None


def _cache_get(cache: OrderedDict, key: tuple, resp: Any) -> Any:
    hit = cache.get(key)
    if hit is None:
        return None
    ref, value = hit
    if ref is not None and (ref is False or ref() is not resp):
        del cache[key]  # a collected callable whose id was reused
        return None
    cache.move_to_end(key)
    return value


def _cache_put(cache: OrderedDict, key: tuple, guard: Any, value: Any) -> None:
    if guard is False:
        return
    cache[key] = (guard, value)
    cache.move_to_end(key)
    while len(cache) > _CACHE_SIZE:
        cache.popitem(last=False)


def _band_quadrature(band: SpectralBand) -> tuple[np.ndarray, np.ndarray]:
    key, guard = _band_key(band)
    hit = _cache_get(_band_cache, key, band.response)
    if hit is not None:
        return hit
    edges = [band.lo, band.hi]
    resp = band.response
    table = None
    if resp is not None and not callable(resp):
        wl, rv = (np.asarray(a, dtype=np.float64) for a in resp)
        if wl.ndim != 1 or wl.shape != rv.shape or wl.size < 2 or np.any(np.diff(wl) <= 0):
            raise ValueError("response: a table must be two 1-d arrays (wavelength ascending [m], response)")
        if np.any(rv < 0) or not np.all(np.isfinite(rv)):
            raise ValueError("response: values must be finite and ≥ 0")
        table = (wl, rv)
        inner = wl[(wl > band.lo) & (wl < band.hi)]
        edges = sorted(set([band.lo, band.hi, *inner.tolist()]))
    x, w = _gauss_legendre(band.nodes_per_panel)
    lams, weights = [], []
    for a, b in zip(edges[:-1], edges[1:]):
        lams.append(0.5 * (a + b) + 0.5 * (b - a) * x)
        weights.append(0.5 * (b - a) * w)
    lam = np.concatenate(lams)
    wt = np.concatenate(weights)
    if table is not None:
        wt = wt * np.interp(lam, table[0], table[1], left=0.0, right=0.0)
    elif callable(resp):
        r = np.asarray(resp(lam), dtype=np.float64)
        if r.shape != lam.shape or np.any(r < 0) or not np.all(np.isfinite(r)):
            raise ValueError("response: the callable must return finite values ≥ 0 of its input's shape")
        wt = wt * r
    if not np.any(wt > 0):
        raise ValueError("response: it is zero over the whole band")
    _cache_put(_band_cache, key, guard, (lam, wt))
    return lam, wt


@lru_cache(maxsize=64)
def _gauss_legendre(n: int) -> tuple[np.ndarray, np.ndarray]:
    return np.polynomial.legendre.leggauss(n)


def as_band(band: Any, response: Any = None) -> SpectralBand:
    """A :class:`SpectralBand` from a band object or a (λ_lo, λ_hi) pair [m]."""
    if isinstance(band, SpectralBand):
        if response is not None:
            return SpectralBand(band.lo, band.hi, response, band.nodes_per_panel)
        return band
    try:
        lo, hi = band
    except (TypeError, ValueError):
        raise ValueError(f"band must be a (lambda_lo, lambda_hi) pair in metres or a SpectralBand, got {band!r}")
    return SpectralBand(float(lo), float(hi), response)


def band_radiance(temperature: Any, band: Any = LWIR, response: Any = None) -> torch.Tensor:
    """Blackbody band radiance L(T) = ∫ r(λ) B_λ(T) dλ over the band [W m⁻² sr⁻¹].

    Args:
        temperature: T [K] > 0, float or tensor of any shape.
        band: (λ_lo, λ_hi) [m] or a :class:`SpectralBand`.
        response: relative spectral response (see :class:`SpectralBand`); None = 1.
    """
    check_finite_range("temperature", temperature, 0.0, lo_open=True, unit="K")
    b = as_band(band, response)
    dtype, device = resolve_dtype_device(temperature=temperature)
    t = as_tensor(temperature, dtype, device)
    lam, w = b.nodes(dtype, device)
    return (_planck(lam, t.unsqueeze(-1)) * w).sum(-1)


def _log_band_radiance(lam: torch.Tensor, w: torch.Tensor, t: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
    """(log L(T), d log L / dT) of the band radiance L = Σ wᵢ B_λᵢ(T), in log space (float64 inputs).

    Finite for every T > 0 and every L a float can hold: at a few kelvin B underflows even float64
    (e^{−x}, x ~ 700), while its logarithm and the softmax-weighted slope do not.
    """
    lam_um = lam * 1e6
    x = (_C2 * 1e6) / (lam_um * t.unsqueeze(-1))
    one_m = -torch.expm1(-x)  # 1 − e^{−x}
    log_b = math.log(_C1 * 1e30) - 5.0 * torch.log(lam_um) - x - torch.log(one_m)
    a = torch.log(w) + log_b
    p = torch.softmax(a, -1)
    return torch.logsumexp(a, -1), (p * x / one_m).sum(-1) / t


class _BrightnessTemperature(torch.autograd.Function):
    """Inverse of the band radiance by Newton iterations on log L (float64); backward by the
    implicit-function theorem dT/dL = 1/(L · d log L/dT). Used outside the tabulated 100–500 K range.

    In log space both stay finite down to the smallest positive radiance (the direct form's dL/dT
    underflowed to 0 there: NaN temperatures in float64, infinite gradients in float32).
    """

    @staticmethod
    def forward(ctx, radiance, lam, w):  # type: ignore[override]
        log_l = torch.log(radiance.double())
        lam64, w64 = lam.double(), w.double().clamp_min(1e-300)
        # Initial guess: invert Planck at the response-weighted mean wavelength, then Newton.
        lam_um = float((lam64 * w64).sum() / w64.sum()) * 1e6
        log_arg = math.log(_C1 * 1e30) - 5.0 * math.log(lam_um) - (log_l - math.log(float(w64.sum())))
        t = (_C2 * 1e6) / (lam_um * torch.logaddexp(torch.zeros_like(log_arg), log_arg))  # log1p(e^{log_arg})
        for _ in range(60):
            f, df = _log_band_radiance(lam64, w64, t)
            step = (f - log_l) / df
            t = torch.maximum(t - step, 0.5 * t)
            if bool((step.abs() <= 1e-13 * t).all()):
                break
        ctx.save_for_backward(t, log_l, lam64, w64)
        return t.to(radiance.dtype)

    @staticmethod
    def backward(ctx, grad):  # type: ignore[override]
        t, log_l, lam64, w64 = ctx.saved_tensors
        _, dlog = _log_band_radiance(lam64, w64, t)
        return (grad.double() / (torch.exp(log_l) * dlog)).to(grad.dtype), None, None


_T_LO, _T_HI, _T_STEP = 100.0, 500.0, 0.25
_bt_cache: OrderedDict[tuple, tuple[Any, tuple[torch.Tensor, ...]]] = OrderedDict()


def _bt_table(band: SpectralBand, dtype: torch.dtype, device: torch.device) -> tuple[torch.Tensor, ...]:
    """The tabulated inverse of the band radiance, and its interval lookup.

    Band radiances L_i on a 0.25 K grid over 100–500 K with their exact slopes dT/dL = 1/(dL/dT);
    per interval, the cubic Hermite T(L) in power form in u = L − L_i:
    T = T_i + u (d1 + u (d2 + u d3)), d_k = c_k / ΔL^k, with c_k the coefficients in t = u/ΔL
    (all made in float64, then cast). Returns (L_i, T_i, d1, d2, d3, (log L_0, 1/w), start, next).

    The power form with coefficients made in float64 keeps float32 gradients dT/dL accurate: the
    Hermite basis form (2t³ − 3t² + 1) T_i + … − … T_{i+1} differentiated in float32 cancels
    terms ~T/ΔT = 10³ times larger than the result (4e-4 relative, ``pipelines/stability.py``).

    Lookup: a bucket grid uniform in log L, of width w no larger than the narrowest interval in
    log L (d log L/dT ≥ 1/T, so at most ~10⁴ buckets for any band): a bucket holds at most one
    node, and a radiance lies in its bucket's first interval ``start`` or the one after, which one
    compare with that bucket's ``next`` node decides (+∞ for the last interval). One gather and
    one compare, where a binary search (``torch.searchsorted``) took ~11 dependent steps.
    """
    key, guard = _band_key(band)
    full = key + (dtype, str(device))
    hit = _cache_get(_bt_cache, full, band.response)
    if hit is None:
        lam, w = (torch.as_tensor(a, dtype=torch.float64) for a in band.quadrature)
        T = torch.arange(_T_LO, _T_HI + _T_STEP / 2, _T_STEP, dtype=torch.float64)
        L = (_planck(lam, T[:, None]) * w).sum(-1)
        m = 1.0 / (planck_radiance_derivative(lam, T[:, None]) * w).sum(-1)  # dT/dL at the nodes
        h = L[1:] - L[:-1]
        dT = T[1:] - T[:-1]
        c1 = h * m[:-1]
        c2 = 3.0 * dT - h * (2.0 * m[:-1] + m[1:])
        c3 = -2.0 * dT + h * (m[:-1] + m[1:])
        inv_h = 1.0 / h
        d1, d2, d3 = c1 * inv_h, c2 * inv_h**2, c3 * inv_h**3
        y0, inv_w, start = bucket_grid(torch.log(L))
        nxt = next_nodes(L, start)
        hit = tuple(t.to(device=device, dtype=dtype) for t in (L, T[:-1], d1, d2, d3, torch.tensor([y0, inv_w]), nxt))
        hit = hit[:6] + (start.to(device=device), hit[6])
        _cache_put(_bt_cache, full, guard, hit)
    return hit


def _bt_lookup(L: torch.Tensor, b: SpectralBand) -> tuple[torch.Tensor, torch.Tensor, Any, tuple[torch.Tensor, ...]]:
    """Per radiance (flattened): its interval i in the T(L) table, u = L − L_i (differentiable),
    None if every radiance lies inside the table or else the boolean mask of those that do, and
    the table (:func:`_bt_table`).

    Rounding of log L (float32) can put a radiance within ~1e-7 (relative) of a node into the
    neighbouring interval; the Hermite pieces share value and slope at the node, so the value
    moves by ~1e-14 of the 0.25 K step there.
    """
    tab = _bt_table(b, L.dtype, L.device)
    Ln, y0_inv, start, nxt = tab[0], tab[5], tab[6], tab[7]
    flat = L.reshape(-1)
    Ld = flat.detach()
    inside = None
    if Ld.numel():
        lo, hi = torch.aminmax(Ld)
        if not (bool(lo >= Ln[0]) and bool(hi <= Ln[-1])):
            inside = (Ld >= Ln[0]) & (Ld <= Ln[-1])
    # index_select on flat indices: advanced indexing (Ln[i]) costs ~6× more on the CPU
    j = torch.log(Ld).sub_(y0_inv[0]).mul_(y0_inv[1]).clamp_(0.0, start.numel() - 1).long()
    i = start.index_select(0, j)
    i += Ld >= nxt.index_select(0, j)
    return i, flat - Ln.index_select(0, i), inside, tab


def brightness_temperature(radiance: Any, band: Any = LWIR, response: Any = None) -> torch.Tensor:
    """Temperature [K] of the blackbody whose band radiance equals ``radiance`` [W m⁻² sr⁻¹].

    Inverse of :func:`band_radiance`: cubic Hermite interpolation of T(L) between band radiances
    tabulated every 0.25 K over 100–500 K with their exact slopes dT/dL = 1/(dL/dT) (error O(h⁴):
    under 5e-9 K (LWIR) and 3e-8 K (MWIR) above 200 K, up to 1e-7 K (LWIR) and 1.5e-6 K (MWIR) at 100 K); Newton iterations
    in float64 outside that range. Differentiable. Per value: one log, a bucket lookup and one
    compare (:func:`_bt_table`), then the cubic.

    Raises ``ValueError`` naming ``radiance`` unless every value is > 0 (a blackbody's band
    radiance is positive; a negative radiance has no brightness temperature).
    """
    _check_radiance(radiance)
    b = as_band(band, response)
    dtype, device = resolve_dtype_device(radiance=radiance)
    L = as_tensor(radiance, dtype, device)
    i, u, inside, (_, c0, d1, d2, d3, *_rest) = _bt_lookup(L, b)
    out = c0.index_select(0, i) + u * (d1.index_select(0, i) + u * (d2.index_select(0, i) + u * d3.index_select(0, i)))
    out = out.reshape(L.shape)
    if inside is not None:
        lam, w = b.nodes(dtype, device)
        far = _BrightnessTemperature.apply(L, lam, w)
        out = torch.where(inside.reshape(L.shape), out, far)
    return out


def _check_radiance(radiance: Any) -> None:
    """``ValueError`` naming ``radiance`` unless every value is a finite number > 0."""
    if isinstance(radiance, torch.Tensor):
        if radiance.is_complex():
            raise ValueError("radiance must be real, got a complex tensor")
        v = radiance.detach()
    else:
        try:
            v = torch.as_tensor(np.asarray(radiance, dtype=np.float64))
        except (TypeError, ValueError):
            raise ValueError(f"radiance must be a number or an array of numbers > 0; got {type(radiance).__name__}")
    if v.numel() == 0:
        return
    ok = (v > 0) & (v < math.inf)  # NaN fails both
    if not bool(ok.all()):
        worst = v[~ok].flatten()[0].item()
        raise ValueError(
            f"radiance must be > 0 and finite [W m-2 sr-1] (a band radiance is positive: a negative or "
            f"zero radiance has no brightness temperature); got {worst!r}"
        )


def band_radiance_slope(radiance: Any, band: Any = LWIR, response: Any = None) -> torch.Tensor:
    """dL/dT [W m⁻² sr⁻¹ K⁻¹] of the band radiance at the brightness temperature of ``radiance``.

    The reciprocal of the slope of the same Hermite T(L) that :func:`brightness_temperature`
    interpolates (exact dT/dL at the 0.25 K nodes, O(h³) between them); outside 100–500 K the
    band sum of ∂B_λ/∂T at the Newton temperature. A per-pixel lookup, no band sum per pixel
    (what a noise model needs: NEΔL = NETD · dL/dT).
    """
    _check_radiance(radiance)
    b = as_band(band, response)
    dtype, device = resolve_dtype_device(radiance=radiance)
    L = as_tensor(radiance, dtype, device)
    i, u, inside, (_, _, d1, d2, d3, *_rest) = _bt_lookup(L, b)
    out = 1.0 / (d1.index_select(0, i) + u * (2.0 * d2.index_select(0, i) + 3.0 * u * d3.index_select(0, i)))
    out = out.reshape(L.shape)
    if inside is not None:
        lam, w = b.nodes(dtype, device)
        T = brightness_temperature(L, b)
        exact = (planck_radiance_derivative(lam, T.unsqueeze(-1)) * w).sum(-1)
        out = torch.where(inside.reshape(L.shape), out, exact)
    return out


def band_weights(
    band: SpectralBand, temperature: Any, dtype: torch.dtype, device: torch.device
) -> tuple[torch.Tensor, torch.Tensor]:
    """Wavelength nodes [m] and normalized Planck × response weights (sum 1 along the last axis)."""
    lam, w = band.nodes(dtype, device)
    t = as_tensor(temperature, dtype, device).unsqueeze(-1)
    ww = _planck(lam, t) * w
    return lam, ww / ww.sum(-1, keepdim=True)

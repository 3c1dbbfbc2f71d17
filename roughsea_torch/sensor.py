"""A camera model for rendered radiance images: optics blur, detector noise, fixed pattern, ADC, display.

Rendered images (:func:`roughsea_torch.render`) are band radiance [W m⁻² sr⁻¹], shape (B, 1, H, W).
This module turns them into what an infrared camera delivers, in kornia's layout: a functional core
(:func:`optics_blur`, :func:`detector_noise`, :func:`radiance_to_counts`, :func:`counts_to_radiance`,
:func:`to_display`) and thin ``nn.Module`` stages that hold the settings and call it, chained by
:class:`SensorModel`::

    radiance ─ OpticsBlur ─ DetectorNoise ─ FixedPatternNoise ─ ToCounts ─ ToDisplay ─▶
    [W m⁻² sr⁻¹]  (PSF)     (temporal, NETD)  (gain, offset,     [counts]   [0, 255]
                                               columns)

Conventions:
    - Images are (B, C, H, W) float32 or float64 on any device; every stage keeps dtype, device and
      shape (``ToDisplay`` can return uint8), works per image and never edits its input in place.
    - Temperatures in K (NETD and fixed-pattern offsets are temperature differences, in K, turned
      into radiance with the band's dL/dT); radiance in W m⁻² sr⁻¹ in the sensor band; blur widths
      in pixels; counts are integers held in a float tensor.
    - Randomness: the temporal noise draws from the ``generator`` passed to ``forward`` (the global
      RNG when None; a sequence of B generators gives each image its own stream in one batched
      call); the fixed pattern comes from the stage's own ``seed`` and is the same on every
      call. A generator on another device than the image is fine: the draw is made on the
      generator's device and moved, so one seed gives the same noise on CPU and CUDA.
    - Gradients flow through every stage (the rounding in :class:`ToCounts` and :class:`ToDisplay`
      by a straight-through estimator), so a sensor can sit inside a differentiable pipeline.
"""

from __future__ import annotations

import inspect
import math
from typing import Any, Sequence

import kornia
import numpy as np
import torch
from torch import nn

from ._validation import as_tensor, check_finite_range, per_batch, resolve_dtype_device
from ._parallel import one_thread
from .radiometry import LWIR, as_band, band_radiance, band_radiance_slope, planck_radiance_derivative

__all__ = [
    "optics_blur",
    "noise_equivalent_radiance",
    "detector_noise",
    "radiance_to_counts",
    "counts_to_radiance",
    "to_display",
    "OpticsBlur",
    "DetectorNoise",
    "FixedPatternNoise",
    "ToCounts",
    "ToDisplay",
    "SensorModel",
]

# The brightness temperature used for the noise of pixels colder than this (or of non-positive
# radiance): the bottom of radiometry's tabulated inverse, far below any sea or sky scene.
_T_FLOOR = 100.0
_TRUNCATE = 4.0  # Gaussian kernel half-width in σ, as scipy.ndimage.gaussian_filter's default
_SEPARABLE_ABOVE = 15  # kernels wider than this [px] are applied as two 1-D passes


# --------------------------------------------------------------------------------------------------
# helpers


def _check_image(name: str, x: Any, allow_integer: bool = False) -> torch.Tensor:
    """``x`` as a (B, C, H, W) float32/float64 tensor, or ``ValueError`` naming ``name``.

    With ``allow_integer``, integer tensors (counts straight from a camera) are converted to the
    default dtype."""
    if not isinstance(x, torch.Tensor):
        raise ValueError(f"{name} must be a torch.Tensor of shape (B, C, H, W); got {type(x).__name__}")
    if x.ndim != 4:
        raise ValueError(f"{name} must have shape (B, C, H, W); got shape {tuple(x.shape)}")
    if allow_integer and not (x.dtype.is_floating_point or x.dtype.is_complex):
        x = x.to(torch.get_default_dtype())
    if x.dtype not in (torch.float32, torch.float64):
        raise ValueError(f"{name} must be float32 or float64; got {x.dtype}")
    return x


def _check_int(name: str, x: Any, lo: int, hi: float = math.inf) -> int:
    if isinstance(x, bool) or not isinstance(x, int):
        raise ValueError(f"{name} must be an integer; got {x!r}")
    check_finite_range(name, x, lo, hi)
    return int(x)


def _check_pair(name: str, x: Any, lo: float, unit: str, lo_open: bool = False) -> tuple[float, float]:
    try:
        a, b = x
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a (low, high) pair [{unit}]; got {x!r}") from None
    check_finite_range(f"{name}[0]", a, lo, math.inf, lo_open=lo_open, hi_open=True, unit=unit)
    check_finite_range(f"{name}[1]", b, lo, math.inf, lo_open=lo_open, hi_open=True, unit=unit)
    a, b = float(a), float(b)
    if not a < b:
        raise ValueError(f"{name} must satisfy low < high; got ({a:g}, {b:g}) {unit}")
    return a, b


def _randn(shape: Sequence[int], generator: Any, dtype: torch.dtype, device: torch.device) -> torch.Tensor:
    """Standard normal draws of ``shape`` (B, ...), made on the generator's device and moved to
    ``device``.

    ``generator``: None (the global RNG), a ``torch.Generator``, or a sequence of B generators,
    one per image: image i's draws then come from ``generator[i]`` alone, exactly the values
    ``torch.randn((1, *shape[1:]), generator=generator[i])`` gives (each is drawn straight into
    its slice of one preallocated tensor), so an image's noise does not depend on its batch.
    """
    shape = tuple(shape)
    if generator is None:
        return torch.randn(shape, dtype=dtype, device=device)
    if isinstance(generator, torch.Generator):
        return torch.randn(shape, generator=generator, dtype=dtype, device=generator.device).to(device)
    gens = list(generator)
    if len(gens) != shape[0] or not all(isinstance(g, torch.Generator) for g in gens):
        raise ValueError(f"generator: give None, a torch.Generator, or a sequence of {shape[0]} torch.Generators "
                         f"(one per image); got {len(gens)} items")
    if len({g.device for g in gens}) > 1:
        raise ValueError(f"generator: the per-image generators must share one device; got {sorted({str(g.device) for g in gens})}")
    z = torch.empty(shape, dtype=dtype, device=gens[0].device if gens else device)
    for i, g in enumerate(gens):
        torch.randn(shape[1:], generator=g, dtype=dtype, device=g.device, out=z[i])
    return z.to(device)


def _band_radiance_dT(temperature: torch.Tensor, band: Any) -> torch.Tensor:
    """dL/dT of the band radiance [W m⁻² sr⁻¹ K⁻¹]: radiometry's analytic ∂B_λ/∂T summed with the
    band's quadrature weights (the same rule as :func:`band_radiance`, so it is its exact
    derivative). Wavelength nodes are taken in chunks to keep memory at a few images."""
    lam, w = as_band(band).nodes(temperature.dtype, temperature.device)
    n = lam.numel()
    chunk = max(1, min(n, (1 << 24) // max(1, temperature.numel())))
    t = temperature.unsqueeze(-1)
    out = torch.zeros_like(temperature)
    for s in range(0, n, chunk):
        out = out + (planck_radiance_derivative(lam[s:s + chunk], t) * w[s:s + chunk]).sum(-1)
    return out


def _round_ste(x: torch.Tensor) -> torch.Tensor:
    """round(x) forward, identity backward (straight-through estimator)."""
    return x + (torch.round(x) - x).detach()


def _order_statistics(x: torch.Tensor, ks: Sequence[int]) -> torch.Tensor:
    """The order statistics of rank ``ks`` (0-based) of each row of x (B, N), shape (B, len(ks)).

    Exact and linear-time. On the CPU by numpy's introselect (``argpartition``, one pass for all
    ranks; its worst case is linear), not ``torch.kthvalue``, whose CPU quickselect turns quadratic
    on descending input, which smooth images come close to (measured, torch 2.13: 0.9 s for a
    400 × 400 image decreasing smoothly along rows and columns, against 0.01 s when it increases
    along rows; over 30 s for 2²⁴ descending values). On other devices ``torch.kthvalue`` (radix
    selection). The values are gathered from ``x``, so the gradient reaches the selected pixels.
    """
    if x.device.type == "cpu":
        uniq = sorted(set(ks))
        rows = x.detach().numpy()
        idx = np.stack([np.argpartition(row, uniq)[list(ks)] for row in rows])
        return torch.gather(x, 1, torch.from_numpy(idx))
    return torch.stack([torch.kthvalue(x, k + 1, dim=-1).values for k in ks], dim=-1)


def _per_image_quantiles(x: torch.Tensor, qs: Sequence[float]) -> torch.Tensor:
    """Quantiles ``qs`` ⊂ [0, 1] of each row of x (B, N), shape (B, len(qs)): ``torch.quantile``'s
    linear interpolation between the order statistics at ⌊q(N − 1)⌋ and the next, without its
    2²⁴-element limit (see :func:`_order_statistics`)."""
    n = x.shape[-1]
    ks, fracs = [], []
    for q in qs:
        pos = q * (n - 1)
        k0 = min(int(math.floor(pos)), n - 1)
        ks += [k0, min(k0 + 1, n - 1)]
        fracs.append(pos - k0)
    v = _order_statistics(x, ks)
    frac = torch.tensor(fracs, dtype=x.dtype, device=x.device)
    return torch.lerp(v[:, 0::2], v[:, 1::2], frac)


# --------------------------------------------------------------------------------------------------
# optics


def optics_blur(image: torch.Tensor, sigma_px: Any, kernel_size: int | None = None) -> torch.Tensor:
    """Optics point-spread function as a Gaussian blur (``kornia.filters.gaussian_blur2d``).

    Args:
        image: (B, C, H, W) radiance [W m⁻² sr⁻¹] (any linear quantity).
        sigma_px: PSF standard deviation [px] ≥ 0, a float or a tensor of shape () or (B,) (one per
            image); 0 leaves an image unchanged. Differentiable with respect to a tensor sigma.
        kernel_size: odd kernel width [px]; None: 2⌈4σ_max⌉ + 1 (σ_max over the batch), capped at
            2·H − 1 (rows) and 2·W − 1 (columns), the widest a reflected border allows.

    Returns:
        (B, C, H, W), same dtype and device.

    The kernel is a sampled Gaussian normalized to sum 1 and the border is mirrored (``'reflect'``),
    so the image mean is conserved exactly for content farther than the kernel radius from the
    border, and a constant image is unchanged.
    """
    image = _check_image("image", image)
    B, _, H, W = image.shape
    check_finite_range("sigma_px", sigma_px, 0.0, math.inf, hi_open=True, unit="px")
    if kernel_size is not None:
        kernel_size = _check_int("kernel_size", kernel_size, 1)
        if kernel_size % 2 == 0:
            raise ValueError(f"kernel_size must be odd; got {kernel_size}")
    sigma = per_batch("sigma_px", sigma_px, B, image.dtype, image.device)
    if B == 0:
        return image.clone()
    s_max = float(sigma.detach().max())
    if s_max == 0.0 and not sigma.requires_grad:
        return image.clone()
    if kernel_size is None:
        k = 2 * math.ceil(_TRUNCATE * s_max) + 1
        ks = (min(k, 2 * H - 1), min(k, 2 * W - 1))
    else:
        if kernel_size > 2 * min(H, W) - 1:
            raise ValueError(
                f"kernel_size must be at most 2·min(H, W) − 1 = {2 * min(H, W) - 1} for a reflected "
                f"border on a {H}×{W} image; got {kernel_size}"
            )
        ks = (kernel_size, kernel_size)
    # kornia needs σ > 0; a σ of 1e-6 px gives exactly the unit impulse (exp(−5e11) = 0).
    s = sigma.clamp_min(1e-6)
    # up to 15 px wide, one 2-D convolution (one pass over the batch) is faster than kornia's separable
    # form, which makes two shifted multiply-adds per kernel row and column (2k passes)
    return kornia.filters.gaussian_blur2d(image, ks, torch.stack([s, s], dim=-1), border_type="reflect",
                                          separable=max(ks) > _SEPARABLE_ABOVE)


class OpticsBlur(nn.Module):
    """Optics PSF as a Gaussian blur; module form of :func:`optics_blur`.

    Args:
        sigma_px: PSF standard deviation [px] ≥ 0: a float, or a tensor of shape (B,) (one per
            image; it may require grad).
        kernel_size: odd kernel width [px] or None (automatic, see :func:`optics_blur`).

    Shape: (B, C, H, W) → (B, C, H, W).

    Example:
        >>> blur = OpticsBlur(sigma_px=1.0)
        >>> x = torch.ones(1, 1, 6, 6, dtype=torch.float64)
        >>> torch.allclose(blur(x), x)
        True
    """

    def __init__(self, sigma_px: Any = 0.7, kernel_size: int | None = None) -> None:
        super().__init__()
        check_finite_range("sigma_px", sigma_px, 0.0, math.inf, hi_open=True, unit="px")
        if isinstance(sigma_px, torch.Tensor) and sigma_px.ndim > 1:
            raise ValueError(f"sigma_px must be a float or a tensor of shape (B,); got shape {tuple(sigma_px.shape)}")
        if kernel_size is not None:
            _check_int("kernel_size", kernel_size, 1)
            if kernel_size % 2 == 0:
                raise ValueError(f"kernel_size must be odd; got {kernel_size}")
        self.sigma_px = sigma_px if isinstance(sigma_px, torch.Tensor) else float(sigma_px)
        self.kernel_size = kernel_size

    def forward(self, image: torch.Tensor) -> torch.Tensor:
        return optics_blur(image, self.sigma_px, self.kernel_size)

    def extra_repr(self) -> str:
        return f"sigma_px={self.sigma_px}, kernel_size={self.kernel_size}"


# --------------------------------------------------------------------------------------------------
# temporal noise


def noise_equivalent_radiance(netd_k: Any, temperature: Any, band: Any = LWIR) -> torch.Tensor:
    """Noise-equivalent radiance difference NEΔL = NETD · dL/dT(T) [W m⁻² sr⁻¹].

    Args:
        netd_k: noise-equivalent temperature difference [K] ≥ 0 (float or tensor broadcastable
            with ``temperature``).
        temperature: the scene temperature T [K] > 0 at which dL/dT is taken (float or tensor).
        band: (λ_lo, λ_hi) [m] or a :class:`~roughsea_torch.radiometry.SpectralBand`.

    dL/dT is the analytic derivative of :func:`~roughsea_torch.radiometry.band_radiance` (the
    band's quadrature applied to ∂B_λ/∂T), not a finite difference. Differentiable.
    """
    check_finite_range("netd_k", netd_k, 0.0, math.inf, hi_open=True, unit="K")
    check_finite_range("temperature", temperature, 0.0, math.inf, lo_open=True, hi_open=True, unit="K")
    dtype, device = resolve_dtype_device(netd_k=netd_k, temperature=temperature)
    t = as_tensor(temperature, dtype, device)
    netd = as_tensor(netd_k, dtype, device)
    return netd * _band_radiance_dT(t, band)


_SLOPE_T_MAX = 499.0  # top of the dL/dT grid [K], inside radiometry's 100–500 K table; brighter pixels: per-pixel lookup
_SLOPE_NODES = 16384  # nodes of the dL/dT grid, uniform in log L over [L(_T_FLOOR), L(_SLOPE_T_MAX)]
_slope_tables: dict[tuple, tuple[float, float, float, torch.Tensor, torch.Tensor]] = {}


def _slope_table(band: Any, dtype: torch.dtype, device: torch.device) -> tuple[float, float, float, torch.Tensor, torch.Tensor]:
    """(log L₀, 1/Δ(log L), L_max, f, Δf): dL/dT from :func:`band_radiance_slope` at radiances
    uniform in log L between the band radiances of ``_T_FLOOR`` and ``_SLOPE_T_MAX`` (made once
    per band in float64, then cast and cached per dtype and device)."""
    band = as_band(band)
    key = (band.lo, band.hi, id(band.response), band.nodes_per_panel)
    hit = _slope_tables.get(key + (dtype, str(device)))
    if hit is None:
        base = _slope_tables.get(key + (torch.float64, "cpu"))
        if base is None:
            ends = band_radiance(torch.tensor([_T_FLOOR, _SLOPE_T_MAX], dtype=torch.float64), band)
            y0, y1 = (float(v) for v in torch.log(ends))
            step = (y1 - y0) / (_SLOPE_NODES - 1)
            # clamped to the ends: exp(log L) may round just outside radiometry's table (a slow path)
            nodes = torch.exp(y0 + step * torch.arange(_SLOPE_NODES, dtype=torch.float64)).clamp(ends[0], ends[1])
            f = band_radiance_slope(nodes, band)
            df = torch.cat([f[1:] - f[:-1], f.new_zeros(1)])  # the last node's cell is empty (u = n − 1 exactly)
            base = (y0, 1.0 / step, float(ends[1]), f, df)
        hit = base[:3] + tuple(t.to(dtype=dtype, device=device) for t in base[3:])
        if band.response is None:  # a callable response is keyed by identity: not kept
            _slope_tables[key + (torch.float64, "cpu")] = base
            _slope_tables[key + (dtype, str(device))] = hit
    return hit


def _radiance_slope(radiance: torch.Tensor, band: Any, scale: float = 1.0) -> torch.Tensor:
    """``scale`` × dL/dT [W m⁻² sr⁻¹ K⁻¹] at each pixel's brightness temperature, radiances below
    that of ``_T_FLOOR`` (100 K) taken at 100 K: the noise's standard deviation per NETD.

    :func:`~roughsea_torch.radiometry.band_radiance_slope` tabulated once at radiances uniform in
    log L over 100–499 K, then read per pixel by linear interpolation in log L: the cell is an
    index computed from log L (no search) and the read two gathers and one multiply-add, where
    the per-pixel lookup costs more than the rest of the sensor model on large batches. dL/dT is
    smooth in log L (≈ L · c₂/(λT²)), so the table is within 2e-6 (LWIR) and 2e-5 (MWIR) of the
    exact band sum (``tests/test_sensor.py``). Pixels above 499 K take the per-pixel lookup.
    The grid is fixed, so a pixel's value does not depend on the rest of its batch."""
    y0, inv_step, l_max, f, df = _slope_table(band, radiance.dtype, radiance.device)
    if scale != 1.0:
        f, df = f * scale, df * scale
    x = radiance.clamp(math.exp(y0), l_max)  # below L(100 K): taken at 100 K (documented floor)
    affine = torch.tensor([-y0 * inv_step, inv_step], dtype=radiance.dtype).to(radiance.device)
    u = torch.addcmul(affine[0], torch.log(x), affine[1])  # (log L − log L₀)/Δ ∈ [0, n − 1] up to rounding
    i = u.detach().to(torch.int32).reshape(-1)
    out = torch.addcmul(f.index_select(0, i).view(u.shape), torch.frac(u), df.index_select(0, i).view(u.shape))
    if float(radiance.detach().max()) > l_max:
        out = torch.where(radiance > l_max, scale * band_radiance_slope(radiance.clamp_min(l_max), band), out)
    return out


def _noise_std(radiance: torch.Tensor, netd: torch.Tensor, band: Any,
               reference_temperature: float | None) -> torch.Tensor:
    """Per-pixel (or per-image) noise standard deviation in radiance, broadcastable to the image."""
    B = radiance.shape[0]
    if reference_temperature is not None:
        t = torch.tensor(reference_temperature, dtype=radiance.dtype, device=radiance.device)
        return netd.view(B, 1, 1, 1) * _band_radiance_dT(t, band)
    if not netd.requires_grad and B and bool((netd == netd[0]).all()):  # one NETD: folded into the table
        return _radiance_slope(radiance, band, float(netd[0]))
    return netd.view(B, 1, 1, 1) * _radiance_slope(radiance, band)


def detector_noise(
    radiance: torch.Tensor,
    netd_k: Any = 0.05,
    band: Any = LWIR,
    reference_temperature: float | None = None,
    generator: torch.Generator | Sequence[torch.Generator] | None = None,
) -> torch.Tensor:
    """Add temporal white Gaussian noise of a given NETD.

    Args:
        radiance: (B, C, H, W) band radiance [W m⁻² sr⁻¹].
        netd_k: noise-equivalent temperature difference [K] ≥ 0, a float or a (B,) tensor.
        band: the sensor band of ``radiance``.
        reference_temperature: None (default): the noise of each pixel is NETD × dL/dT at the pixel's
            own brightness temperature (pixels below 100 K, or of non-positive radiance, use 100 K),
            so its standard deviation in kelvin is the NETD everywhere; a temperature [K]: one
            standard deviation NETD × dL/dT(T_ref) for all pixels (a constant-NEΔL detector).
        generator: ``torch.Generator`` for the draws (any device); or a sequence of B generators,
            one per image (image i's draws are those ``generator[i]`` gives for that image alone,
            so a batch reproduces images noised one by one with their own seeds); None: the
            global RNG.

    Returns:
        radiance + σ·z, z ~ N(0, 1) independent per pixel, (B, C, H, W), same dtype and device.
        Differentiable in ``radiance`` (through σ as well).
    """
    radiance = _check_image("radiance", radiance)
    check_finite_range("netd_k", netd_k, 0.0, math.inf, hi_open=True, unit="K")
    if reference_temperature is not None:
        check_finite_range("reference_temperature", reference_temperature, 0.0, math.inf,
                           lo_open=True, hi_open=True, unit="K")
        reference_temperature = float(reference_temperature)
    netd = per_batch("netd_k", netd_k, radiance.shape[0], radiance.dtype, radiance.device)
    z = _randn(radiance.shape, generator, radiance.dtype, radiance.device)
    if radiance.numel() == 0:
        return radiance.clone()
    return torch.addcmul(radiance, _noise_std(radiance, netd, band, reference_temperature), z)


class DetectorNoise(nn.Module):
    """Temporal detector noise of a given NETD; module form of :func:`detector_noise`.

    Args:
        netd_k: NETD [K] ≥ 0 (float or (B,) tensor); 0.05 K is a typical uncooled microbolometer.
        band: sensor band ((λ_lo, λ_hi) [m] or SpectralBand).
        reference_temperature: None (σ at each pixel's brightness temperature) or a temperature [K]
            at which dL/dT is taken for all pixels.

    ``forward(radiance, generator=None)``: (B, C, H, W) → (B, C, H, W); ``generator`` as in
    :func:`detector_noise` (one generator, one per image, or None).
    """

    def __init__(self, netd_k: Any = 0.05, band: Any = LWIR, reference_temperature: float | None = None) -> None:
        super().__init__()
        check_finite_range("netd_k", netd_k, 0.0, math.inf, hi_open=True, unit="K")
        if reference_temperature is not None:
            check_finite_range("reference_temperature", reference_temperature, 0.0, math.inf,
                               lo_open=True, hi_open=True, unit="K")
            reference_temperature = float(reference_temperature)
        self.netd_k = netd_k if isinstance(netd_k, torch.Tensor) else float(netd_k)
        self.band = as_band(band)
        self.reference_temperature = reference_temperature

    def forward(self, radiance: torch.Tensor, generator: torch.Generator | Sequence[torch.Generator] | None = None) -> torch.Tensor:
        return detector_noise(radiance, self.netd_k, self.band, self.reference_temperature, generator)

    def extra_repr(self) -> str:
        return f"netd_k={self.netd_k}, band=({self.band.lo:g}, {self.band.hi:g}), reference_temperature={self.reference_temperature}"


# --------------------------------------------------------------------------------------------------
# fixed pattern


class FixedPatternNoise(nn.Module):
    """Residual fixed-pattern noise of a focal-plane array: per-pixel gain and offset, column stripes.

    Args:
        gain_std: standard deviation of the relative per-pixel gain error δg [1] ≥ 0.
        offset_std_k: standard deviation of the per-pixel offset [K] ≥ 0.
        column_std_k: standard deviation of the per-column offset [K] ≥ 0 (stripes, typical of
            microbolometers read out by one amplifier per column).
        band: the sensor band.
        seed: integer ≥ 0 seeding the pattern.
        reference_temperature: T_ref [K] > 0, the calibration (shutter / NUC) point: offsets in K are
            turned into radiance with dL/dT(T_ref), and gain errors act about L_ref = L(T_ref).

    The output is ``L' = L_ref + (1 + δg)(L − L_ref) + o``: a one-point non-uniformity correction
    at T_ref leaves only the offsets o there, and the gain errors grow with the distance from it.
    The pattern ``(1 + δg, o)`` is drawn once per image size from a CPU generator seeded with
    ``seed`` (in float64, then cast), cached per (H, W, dtype, device), and applied to every image
    and channel of every call: the same seed gives the same pattern on every dtype and device (to
    rounding). Another image size gets its own pattern, not a crop of a larger one. The cache is
    not part of ``state_dict`` (the seed is all it takes to rebuild it).

    Shape: (B, C, H, W) → (B, C, H, W).
    """

    def __init__(
        self,
        gain_std: float = 0.01,
        offset_std_k: float = 0.1,
        column_std_k: float = 0.05,
        band: Any = LWIR,
        seed: int = 0,
        reference_temperature: float = 300.0,
    ) -> None:
        super().__init__()
        check_finite_range("gain_std", gain_std, 0.0, 1.0, hi_open=True)
        check_finite_range("offset_std_k", offset_std_k, 0.0, math.inf, hi_open=True, unit="K")
        check_finite_range("column_std_k", column_std_k, 0.0, math.inf, hi_open=True, unit="K")
        check_finite_range("reference_temperature", reference_temperature, 0.0, math.inf,
                           lo_open=True, hi_open=True, unit="K")
        self.gain_std = float(gain_std)
        self.offset_std_k = float(offset_std_k)
        self.column_std_k = float(column_std_k)
        self.band = as_band(band)
        self.seed = _check_int("seed", seed, 0, 2**63 - 1)
        self.reference_temperature = float(reference_temperature)
        t_ref = torch.tensor(self.reference_temperature, dtype=torch.float64)
        self._l_ref = float(band_radiance(t_ref, self.band))
        self._dl_dt = float(_band_radiance_dT(t_ref, self.band))
        self._patterns: dict[tuple, tuple[torch.Tensor, ...]] = {}

    def pattern(self, height: int, width: int, dtype: torch.dtype = torch.float64,
                device: torch.device | str = "cpu") -> tuple[torch.Tensor, torch.Tensor]:
        """The pattern for an H × W image: gain 1 + δg (H, W) [1] and offset o (H, W) [W m⁻² sr⁻¹]."""
        return self._pattern(height, width, dtype, device)[:2]

    def _pattern(self, height: int, width: int, dtype: torch.dtype,
                 device: torch.device | str) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
        """(gain, offset, bias) with bias = L_ref (1 − gain) + offset [W m⁻² sr⁻¹], cached."""
        height = _check_int("height", height, 1)
        width = _check_int("width", width, 1)
        device = torch.device(device)
        key = (height, width, dtype, device)
        hit = self._patterns.get(key)
        if hit is None:
            g = torch.Generator(device="cpu").manual_seed(self.seed)
            z_gain = torch.randn(height, width, generator=g, dtype=torch.float64)
            z_pix = torch.randn(height, width, generator=g, dtype=torch.float64)
            z_col = torch.randn(width, generator=g, dtype=torch.float64)
            gain = 1.0 + self.gain_std * z_gain
            offset = (self.offset_std_k * z_pix + self.column_std_k * z_col) * self._dl_dt
            bias = self._l_ref * (1.0 - gain) + offset  # L' = gain · L + bias: one fused op per call
            hit = tuple(a.to(dtype=dtype, device=device) for a in (gain, offset, bias))
            self._patterns[key] = hit
        return hit

    def forward(self, radiance: torch.Tensor) -> torch.Tensor:
        radiance = _check_image("radiance", radiance)
        H, W = radiance.shape[-2:]
        gain, _, bias = self._pattern(H, W, radiance.dtype, radiance.device)
        return torch.addcmul(bias, gain, radiance)

    def extra_repr(self) -> str:
        return (f"gain_std={self.gain_std}, offset_std_k={self.offset_std_k}, column_std_k={self.column_std_k}, "
                f"seed={self.seed}, reference_temperature={self.reference_temperature}")


# --------------------------------------------------------------------------------------------------
# analogue-to-digital conversion


def radiance_to_counts(radiance: torch.Tensor, gain: float, offset: float, bits: int = 14,
                       rounding: bool = True) -> torch.Tensor:
    """Digital counts ``clamp(round(gain · L + offset), 0, 2^bits − 1)``.

    Args:
        radiance: (B, C, H, W) [W m⁻² sr⁻¹].
        gain: [counts per W m⁻² sr⁻¹] > 0; offset: [counts].
        bits: ADC resolution, integer in [1, 24].
        rounding: round to integers (straight-through: the gradient is ``gain`` inside the range,
            as if there were no rounding, and 0 where clamped); False keeps fractional counts.

    Returns:
        (B, C, H, W) float tensor of the input's dtype holding integer values (exact: float32 holds
        integers up to 2^24, hence the 24-bit limit).
    """
    radiance = _check_image("radiance", radiance)
    check_finite_range("gain", gain, 0.0, math.inf, lo_open=True, hi_open=True, unit="counts per W m-2 sr-1")
    check_finite_range("offset", offset, -math.inf, math.inf, lo_open=True, hi_open=True, unit="counts")
    bits = _check_int("bits", bits, 1, 24)
    scalars = torch.tensor([float(offset), float(gain)], dtype=radiance.dtype).to(radiance.device)
    c = torch.addcmul(scalars[0], radiance, scalars[1])  # gain · L + offset in one pass
    if rounding:
        c = _round_ste(c) if c.requires_grad else c.round_()
    # + 0.0: a count rounded from a tiny negative value is −0.0, which clamp keeps; counts are ≥ +0
    return c.clamp_(0.0, float(2**bits - 1)).add_(0.0) if not c.requires_grad else c.clamp(0.0, float(2**bits - 1)) + 0.0


def counts_to_radiance(counts: torch.Tensor, gain: float, offset: float) -> torch.Tensor:
    """Inverse of :func:`radiance_to_counts` inside its range: L = (counts − offset) / gain.

    Args:
        counts: (B, C, H, W) counts, float or integer (integers are converted to the default dtype).
        gain: [counts per W m⁻² sr⁻¹] > 0; offset: [counts].

    Returns:
        (B, C, H, W) radiance [W m⁻² sr⁻¹], within half a count (0.5 / gain) of the radiance that
        gave the counts when it was inside the ADC range.
    """
    counts = _check_image("counts", counts, allow_integer=True)
    check_finite_range("gain", gain, 0.0, math.inf, lo_open=True, hi_open=True, unit="counts per W m-2 sr-1")
    check_finite_range("offset", offset, -math.inf, math.inf, lo_open=True, hi_open=True, unit="counts")
    return (counts - float(offset)) / float(gain)


class ToCounts(nn.Module):
    """Analogue-to-digital conversion: radiance → counts; module form of :func:`radiance_to_counts`.

    Args:
        bits: ADC resolution, integer in [1, 24] (full scale 2^bits − 1).
        gain: [counts per W m⁻² sr⁻¹] and offset [counts]: give both, or neither to derive them
            from ``radiance_range`` or ``temperature_range``.
        radiance_range: (L_lo, L_hi) [W m⁻² sr⁻¹] mapped to counts 0 and 2^bits − 1.
        band: the sensor band (used with ``temperature_range``).
        temperature_range: (T_lo, T_hi) [K]; their band radiances are mapped to 0 and 2^bits − 1
            (used when neither gain/offset nor radiance_range is given).
        rounding: round to integer counts, with a straight-through gradient (see
            :func:`radiance_to_counts`).

    Output dtype: the input's float dtype, holding integer values (cast with ``.to(torch.int32)``
    or ``torch.uint16`` if integers are needed; float keeps the stage differentiable).

    Example:
        >>> adc = ToCounts(bits=14, temperature_range=(250.0, 330.0))
        >>> L = band_radiance(torch.tensor([[[[240.0, 250.0, 300.0, 330.0, 340.0]]]], dtype=torch.float64))
        >>> adc(L)
        tensor([[[[    0.,     0.,  8580., 16383., 16383.]]]], dtype=torch.float64)
        >>> float((adc.counts_to_radiance(adc(L)) - L)[..., 2].abs() * adc.gain) <= 0.5
        True
    """

    def __init__(
        self,
        bits: int = 14,
        gain: float | None = None,
        offset: float | None = None,
        radiance_range: tuple[float, float] | None = None,
        band: Any = LWIR,
        temperature_range: tuple[float, float] = (250.0, 330.0),
        rounding: bool = True,
    ) -> None:
        super().__init__()
        self.bits = _check_int("bits", bits, 1, 24)
        if not isinstance(rounding, bool):
            raise ValueError(f"rounding must be True or False; got {rounding!r}")
        self.rounding = rounding
        self.band = as_band(band)
        full = float(2**self.bits - 1)
        if gain is not None or offset is not None:
            if gain is None:
                raise ValueError("gain is required when offset is given")
            if offset is None:
                raise ValueError("offset is required when gain is given")
            check_finite_range("gain", gain, 0.0, math.inf, lo_open=True, hi_open=True, unit="counts per W m-2 sr-1")
            check_finite_range("offset", offset, -math.inf, math.inf, lo_open=True, hi_open=True, unit="counts")
            self.gain, self.offset = float(gain), float(offset)
        else:
            if radiance_range is not None:
                l_lo, l_hi = _check_pair("radiance_range", radiance_range, -math.inf, "W m-2 sr-1", lo_open=True)
            else:
                t_lo, t_hi = _check_pair("temperature_range", temperature_range, 0.0, "K", lo_open=True)
                lr = band_radiance(torch.tensor([t_lo, t_hi], dtype=torch.float64), self.band)
                l_lo, l_hi = float(lr[0]), float(lr[1])
            self.gain = full / (l_hi - l_lo)
            self.offset = -self.gain * l_lo

    @property
    def full_scale(self) -> int:
        """The largest count, 2^bits − 1."""
        return 2**self.bits - 1

    def forward(self, radiance: torch.Tensor) -> torch.Tensor:
        return radiance_to_counts(radiance, self.gain, self.offset, self.bits, self.rounding)

    def counts_to_radiance(self, counts: torch.Tensor) -> torch.Tensor:
        """Radiance [W m⁻² sr⁻¹] of counts (the inverse inside the range; see :func:`counts_to_radiance`)."""
        return counts_to_radiance(counts, self.gain, self.offset)

    def extra_repr(self) -> str:
        return f"bits={self.bits}, gain={self.gain:.6g}, offset={self.offset:.6g}, rounding={self.rounding}"


# --------------------------------------------------------------------------------------------------
# display


def _check_display_args(low_percentile: Any, high_percentile: Any, output_dtype: Any) -> None:
    check_finite_range("low_percentile", low_percentile, 0.0, 100.0, unit="%")
    check_finite_range("high_percentile", high_percentile, 0.0, 100.0, unit="%")
    if not float(low_percentile) < float(high_percentile):
        raise ValueError(f"low_percentile must be below high_percentile; got {low_percentile} and {high_percentile}")
    if output_dtype not in (None, torch.uint8):
        raise ValueError(f"output_dtype must be None or torch.uint8; got {output_dtype}")


def to_display(image: torch.Tensor, low_percentile: float = 1.0, high_percentile: float = 99.0,
               output_dtype: torch.dtype | None = None) -> torch.Tensor:
    """Per-image percentile stretch to 8-bit display values.

    Args:
        image: (B, C, H, W) counts or radiance (float or integer).
        low_percentile, high_percentile: percentiles [%], 0 ≤ low < high ≤ 100, computed per image
            over all its channels and pixels (linear interpolation between order statistics, as
            ``torch.quantile``, but exact at any image size: torch.quantile stops at 2²⁴ elements).
        output_dtype: None: the float dtype of the image (integer inputs: the default dtype), with
            integer values and a straight-through gradient through the rounding; or ``torch.uint8``.

    Returns:
        (B, C, H, W) values round(255 · clamp((x − p_lo) / (p_hi − p_lo), 0, 1)) ∈ {0, …, 255}:
        the low percentile and everything below it map to 0, the high one and above to 255,
        monotone in between. An image with p_hi = p_lo (e.g. constant) maps to 0 at and below p_lo
        and 255 above.
    """
    image = _check_image("image", image, allow_integer=True)
    _check_display_args(low_percentile, high_percentile, output_dtype)
    B = image.shape[0]
    if image.numel() == 0:
        return image.clone() if output_dtype is None else image.to(output_dtype)
    q = _per_image_quantiles(image.reshape(B, -1), (float(low_percentile) / 100.0, float(high_percentile) / 100.0))
    lo, hi = q[:, 0].view(B, 1, 1, 1), q[:, 1].view(B, 1, 1, 1)
    span = hi - lo
    ok = span > 0
    u = torch.where(ok, (image - lo) / torch.where(ok, span, torch.ones_like(span)),
                    torch.where(image > lo, 1.0, 0.0).to(image.dtype))
    out = _round_ste(255.0 * u.clamp(0.0, 1.0))
    return out if output_dtype is None else out.detach().to(torch.uint8)


class ToDisplay(nn.Module):
    """Per-image percentile stretch to [0, 255]; module form of :func:`to_display`.

    Args:
        low_percentile, high_percentile: [%], mapped to 0 and 255 (defaults 1 and 99).
        output_dtype: None (float with integer values) or ``torch.uint8``.

    Shape: (B, C, H, W) → (B, C, H, W).
    """

    def __init__(self, low_percentile: float = 1.0, high_percentile: float = 99.0,
                 output_dtype: torch.dtype | None = None) -> None:
        super().__init__()
        _check_display_args(low_percentile, high_percentile, output_dtype)
        self.low_percentile = float(low_percentile)
        self.high_percentile = float(high_percentile)
        self.output_dtype = output_dtype

    def forward(self, image: torch.Tensor) -> torch.Tensor:
        return to_display(image, self.low_percentile, self.high_percentile, self.output_dtype)

    def extra_repr(self) -> str:
        return f"low_percentile={self.low_percentile}, high_percentile={self.high_percentile}, output_dtype={self.output_dtype}"


# --------------------------------------------------------------------------------------------------
# composition


def _takes_generator(module: nn.Module) -> bool:
    try:
        return "generator" in inspect.signature(module.forward).parameters
    except (TypeError, ValueError):
        return False


class SensorModel(nn.Module):
    """A camera as a chain of stages: blur → noise → fixed_pattern → counts → display.

    Args:
        blur: optics stage (e.g. :class:`OpticsBlur`) or None.
        noise: temporal noise stage (e.g. :class:`DetectorNoise`) or None.
        fixed_pattern: fixed-pattern stage (e.g. :class:`FixedPatternNoise`) or None.
        counts: ADC stage (e.g. :class:`ToCounts`) or None.
        display: display stage (e.g. :class:`ToDisplay`) or None.

    Every stage is an ``nn.Module`` taking and returning (B, C, H, W) (any module works, e.g. a
    custom PSF); None leaves it out, so ``SensorModel()`` is the identity. Temporal noise comes
    before the fixed pattern because NETD is specified referred to the scene.

    ``forward(radiance, generator=None)``: ``generator`` (a ``torch.Generator`` on any device) is
    passed to every stage whose ``forward`` has a ``generator`` parameter, so a seeded generator
    makes a run reproducible bit for bit; None uses the global RNG. A sequence of B generators
    gives each image its own stream (image i's temporal noise is what ``generator[i]`` gives it
    alone) while the batch runs as one: :class:`DetectorNoise` draws each image's noise into one
    tensor; a custom stage that takes a generator is called image by image.

    Example:
        >>> sensor = SensorModel.typical_lwir()
        >>> L = band_radiance(torch.full((1, 1, 8, 8), 300.0, dtype=torch.float64))
        >>> a = sensor(L, generator=torch.Generator().manual_seed(0))
        >>> b = sensor(L, generator=torch.Generator().manual_seed(0))
        >>> a.shape, a.dtype, torch.equal(a, b), torch.equal(a, a.round())
        (torch.Size([1, 1, 8, 8]), torch.float64, True, True)
    """

    _STAGES = ("blur", "noise", "fixed_pattern", "counts", "display")

    def __init__(
        self,
        blur: nn.Module | None = None,
        noise: nn.Module | None = None,
        fixed_pattern: nn.Module | None = None,
        counts: nn.Module | None = None,
        display: nn.Module | None = None,
    ) -> None:
        super().__init__()
        for name, stage in zip(self._STAGES, (blur, noise, fixed_pattern, counts, display)):
            if stage is not None and not isinstance(stage, nn.Module):
                raise ValueError(f"{name} must be an nn.Module or None; got {type(stage).__name__}")
            setattr(self, name, stage)

    @classmethod
    def typical_lwir(cls, band: Any = LWIR, seed: int = 0) -> "SensorModel":
        """An uncooled LWIR microbolometer camera (8–12 µm), raw 14-bit output, no display stage.

        - blur σ = 0.7 px: f/1 optics on a 12–17 µm pitch; diffraction alone gives σ ≈ 0.42 λN ≈
          4 µm ≈ 0.3 px, aberrations, defocus and pixel crosstalk roughly double it.
        - NETD 50 mK at each pixel's temperature: the usual data-sheet figure of uncooled VOx
          cores at f/1 and 300 K.
        - fixed pattern: 1 % gain, 0.1 K pixel and 0.05 K column offsets about a 300 K
          calibration, a residual after factory non-uniformity correction and shutter refresh.
        - 14 bits over 220–340 K: common core output depth; the range spans a clear-sky zenith
          (≈ 240 K in 8–12 µm) to sun-warmed surfaces, at ≈ 6 mK per count near 300 K, well
          under the NETD.
        """
        return cls(
            blur=OpticsBlur(sigma_px=0.7),
            noise=DetectorNoise(netd_k=0.05, band=band),
            fixed_pattern=FixedPatternNoise(gain_std=0.01, offset_std_k=0.1, column_std_k=0.05, band=band,
                                            seed=seed, reference_temperature=300.0),
            counts=ToCounts(bits=14, band=band, temperature_range=(220.0, 340.0)),
            display=None,
        )

    def forward(self, radiance: torch.Tensor,
                generator: torch.Generator | Sequence[torch.Generator] | None = None) -> torch.Tensor:
        x = _check_image("radiance", radiance)
        per_image = generator is not None and not isinstance(generator, torch.Generator)
        if per_image:
            generator = list(generator)
            if len(generator) != x.shape[0]:
                raise ValueError(f"generator: a sequence must hold one torch.Generator per image ({x.shape[0]}); "
                                 f"got {len(generator)}")
        # one intra-op thread: the chain is a few large operations, 1.3× faster on two idle cores but
        # 2.5× slower beside a busy process, when each is a parallel region (roughsea_torch._parallel)
        return one_thread(lambda: self._chain(x, generator, per_image), x.device)

    def _chain(self, x: torch.Tensor, generator: Any, per_image: bool) -> torch.Tensor:
        for name in self._STAGES:
            stage = getattr(self, name)
            if stage is None:
                continue
            if not _takes_generator(stage):
                x = stage(x)
            elif per_image and not isinstance(stage, DetectorNoise):  # a custom stage: one image at a time
                x = torch.cat([stage(x[i : i + 1], generator=g) for i, g in enumerate(generator)])
            else:
                x = stage(x, generator=generator)
        return x

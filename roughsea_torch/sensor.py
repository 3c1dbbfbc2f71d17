"""A camera model for rendered radiance images: optics blur, detector noise, fixed pattern, ADC, display.

Rendered images (:func:`roughsea_torch.renderer.render`) are band radiance [W m⁻² sr⁻¹], shape (B, 1, H, W).
This module turns them into what an infrared camera delivers, in kornia's layout: a functional core
(:func:`optics_blur`, :func:`detector_noise`, :func:`radiance_to_counts`, :func:`counts_to_radiance`,
:func:`to_display`) and thin ``nn.Module`` stages that hold the settings and call it, chained by
:class:`SensorModel`. The random stages (:func:`detector_noise`, :class:`DetectorNoise`,
:class:`FixedPatternNoise`, :func:`noise_equivalent_radiance`) live in
:mod:`roughsea_torch.sensor_noise` and are importable from here too::

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

from ._parallel import one_thread
from ._sensor_common import check_image, check_int, check_pair, round_ste
from ._validation import check_finite_range, per_batch
from .radiometry import LWIR, as_band, band_radiance
from .sensor_noise import (  # noqa: F401  (detector_noise, noise_equivalent_radiance: re-exported)
    DetectorNoise,
    FixedPatternNoise,
    detector_noise,
    noise_equivalent_radiance,
)

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

_TRUNCATE = 4.0  # Gaussian kernel half-width in σ, as scipy.ndimage.gaussian_filter's default
_SEPARABLE_ABOVE = 15  # kernels wider than this [px] are applied as two 1-D passes


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
    image = check_image("image", image)
    B, _, H, W = image.shape
    check_finite_range("sigma_px", sigma_px, 0.0, math.inf, hi_open=True, unit="px")
    if kernel_size is not None:
        kernel_size = check_int("kernel_size", kernel_size, 1)
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
            check_int("kernel_size", kernel_size, 1)
            if kernel_size % 2 == 0:
                raise ValueError(f"kernel_size must be odd; got {kernel_size}")
        self.sigma_px = sigma_px if isinstance(sigma_px, torch.Tensor) else float(sigma_px)
        self.kernel_size = kernel_size

    def forward(self, image: torch.Tensor) -> torch.Tensor:
        return optics_blur(image, self.sigma_px, self.kernel_size)

    def extra_repr(self) -> str:
        return f"sigma_px={self.sigma_px}, kernel_size={self.kernel_size}"


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
    radiance = check_image("radiance", radiance)
    check_finite_range("gain", gain, 0.0, math.inf, lo_open=True, hi_open=True, unit="counts per W m-2 sr-1")
    check_finite_range("offset", offset, -math.inf, math.inf, lo_open=True, hi_open=True, unit="counts")
    bits = check_int("bits", bits, 1, 24)
    scalars = torch.tensor([float(offset), float(gain)], dtype=radiance.dtype).to(radiance.device)
    c = torch.addcmul(scalars[0], radiance, scalars[1])  # gain · L + offset in one pass
    if rounding:
        c = round_ste(c) if c.requires_grad else c.round_()
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
    counts = check_image("counts", counts, allow_integer=True)
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
        self.bits = check_int("bits", bits, 1, 24)
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
                l_lo, l_hi = check_pair("radiance_range", radiance_range, -math.inf, "W m-2 sr-1", lo_open=True)
            else:
                t_lo, t_hi = check_pair("temperature_range", temperature_range, 0.0, "K", lo_open=True)
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


def _order_statistics(x: torch.Tensor, ks: Sequence[int]) -> torch.Tensor:
    """The order statistics of rank ``ks`` (0-based) of each row of x (B, N), shape (B, len(ks)).

    Exact and linear-time. On the CPU by numpy's introselect (``argpartition``, one pass for all
    ranks; its worst case is linear), not ``torch.kthvalue``, whose CPU quickselect turns quadratic
    on descending input, which smooth images come close to (timings: ``docs/notes/sensor.md``). On
    other devices ``torch.kthvalue`` (radix selection). The values are gathered from ``x``, so the
    gradient reaches the selected pixels.
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
    image = check_image("image", image, allow_integer=True)
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
    out = round_ste(255.0 * u.clamp(0.0, 1.0))
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
        x = check_image("radiance", radiance)
        per_image = generator is not None and not isinstance(generator, torch.Generator)
        if per_image:
            generator = list(generator)
            if len(generator) != x.shape[0]:
                raise ValueError(f"generator: a sequence must hold one torch.Generator per image ({x.shape[0]}); "
                                 f"got {len(generator)}")
        # one intra-op thread: the chain is a few large operations, each a parallel region that stalls
        # beside a busy process (roughsea_torch._parallel; timings in docs/notes/sensor.md)
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

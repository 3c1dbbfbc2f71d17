"""The sensor model's random stages: temporal detector noise and fixed-pattern noise.

Both take band radiance [W m⁻² sr⁻¹] images (B, C, H, W) and specify their noise in kelvin,
turned into radiance with the band's dL/dT: :func:`detector_noise` / :class:`DetectorNoise` add
white Gaussian noise of a given NETD, at each pixel's own brightness temperature or at a reference
one (:func:`noise_equivalent_radiance` gives NEΔL = NETD · dL/dT); :class:`FixedPatternNoise` applies
a focal-plane array's residual per-pixel gain and offset and column stripes, drawn once from its
seed. Conventions (dtype, device, generators, gradients) are those of :mod:`roughsea_torch.sensor`,
which chains these stages in :class:`~roughsea_torch.sensor.SensorModel` and from which these names
are importable too.
"""

from __future__ import annotations

import math
from typing import Any, Sequence

import torch
from torch import nn

from ._sensor_common import check_image, check_int
from ._validation import as_tensor, check_finite_range, per_batch, resolve_dtype_device
from .radiometry import LWIR, as_band, band_radiance, band_radiance_slope, planck_radiance_derivative

__all__ = ["noise_equivalent_radiance", "detector_noise", "DetectorNoise", "FixedPatternNoise"]

# The brightness temperature used for the noise of pixels colder than this (or of non-positive
# radiance): the bottom of radiometry's tabulated inverse, far below any sea or sky scene.
_T_FLOOR = 100.0


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
    radiance = check_image("radiance", radiance)
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
        self.seed = check_int("seed", seed, 0, 2**63 - 1)
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
        height = check_int("height", height, 1)
        width = check_int("width", width, 1)
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
        radiance = check_image("radiance", radiance)
        H, W = radiance.shape[-2:]
        gain, _, bias = self._pattern(H, W, radiance.dtype, radiance.device)
        return torch.addcmul(bias, gain, radiance)

    def extra_repr(self) -> str:
        return (f"gain_std={self.gain_std}, offset_std_k={self.offset_std_k}, column_std_k={self.column_std_k}, "
                f"seed={self.seed}, reference_temperature={self.reference_temperature}")

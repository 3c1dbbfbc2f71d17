"""Synthesized, band-split random sea surfaces: the texture of the near range.

:class:`WaveField`: Gaussian random surfaces (elevation, slopes and a crest variable for the foam,
the downward acceleration of the breaking range) synthesized by an inverse discrete Fourier transform
of random Fourier amplitudes shaped by the wind-wave spectrum of Elfouhaily et al. (1997)
(:mod:`roughsea_torch.spectrum`), following Tessendorf, *Simulating ocean water*, SIGGRAPH course
notes, 2001; split into bands (:class:`~roughsea_torch.wave_bands.WaveBands`) so that each band can
be faded out where a pixel footprint no longer resolves it (``docs/texture.md`` §4–5, the two-scale
principle).

The spectrum (:func:`elfouhaily_spectrum`, :func:`dispersion`, ...) and the band layout
(:class:`WaveBands`) are importable from here too. How the field's choices came about, and what
was measured on it: ``docs/notes/wave_field.md``.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import torch
import torch.nn.functional as F_nn

from ._validation import ParsedSeeds, as_tensor, check_finite_range, check_same_device, parse_seeds, per_batch
from .spectrum import (C_M, GRAVITY, K_M, check_wave_age, check_wind_speed, dispersion, elfouhaily_omnidirectional,
                       elfouhaily_spectrum, elfouhaily_spreading)
from .spectrum import MAX_WIND, VON_KARMAN  # noqa: F401  (re-exported: roughsea_torch.waves.MAX_WIND as before)
from .wave_bands import WINDOW_HI, WINDOW_LO, WaveBands, band_window
from .wave_lattice import CREST_CUTOFF, CREST_DIRECTIONAL, CREST_HIGHPASS, BandLattice

__all__ = [
    "GRAVITY",
    "K_M",
    "C_M",
    "dispersion",
    "elfouhaily_omnidirectional",
    "elfouhaily_spreading",
    "elfouhaily_spectrum",
    "CREST_CUTOFF",
    "CREST_DIRECTIONAL",
    "CREST_HIGHPASS",
    "WaveBands",
    "WaveField",
]

MAX_TIME_S = 1e9  # [s] |time| of a realization: WaveField.sample, SeaScene(time_s=), render_clip
MAX_WIND_DIRECTION = 1e6  # [rad] |wind direction| accepted by WaveField and SeaScene
_CHUNK_ELEMENTS = 2**18  # point-evaluations per chunk in WaveField.sample
_BLOCK = 512  # points per block of the footprint's range (WaveField._sample_points)
_DOUBLED_ELEMENTS = 2**21  # elements of the doubled band tiles made in one copy (WaveField._sample_points)


def check_time(name: str, time_s: Any) -> None:
    """``ValueError`` naming ``name`` unless ``time_s`` is a number or tensor of times in
    [−MAX_TIME_S, MAX_TIME_S] [s] (finite): the times a wave field is sampled at."""
    check_finite_range(name, time_s, -MAX_TIME_S, MAX_TIME_S, unit="s")


# ---------------------------------------------------------------------------------------------
# The random surface
# ---------------------------------------------------------------------------------------------
class WaveField:
    """A batch of random sea surfaces (one per image), split into octave bands, evaluated at points.

    Args:
        wind_speed: U10 [m s⁻¹] in (0, 80]; float or tensor (B,). Differentiable (the Fourier
            amplitudes are √(F Δk²) of the spectrum at this wind; the random draws are fixed).
            0 raises: a calm sea has no texture, render the expectation alone.
        seed: an int (then B = 1; a numpy integer or 0-D integer tensor/array counts as one) or a
            sequence / 1-D integer tensor or array of B ints, each in [0, 2**63).
        wind_direction: world azimuth of the UPWIND slope axis x_s [rad] (``docs/physics.md`` §2);
            float or (B,). The waves travel DOWNWIND, towards azimuth ``wind_direction + π``.
        inverse_wave_age: Ω_c in [0.84, 5]; float or (B,).
        dtype: torch.float32 or torch.float64, the dtype of tiles and outputs.
        device: the device of tiles and outputs; default the device of the tensor arguments, else CPU.
        bands: a :class:`WaveBands` layout (default: 16 octaves, 2.45 cm … 1.6 km).
        min_band_share: leave out the bands (per image) that carry less than this share of the
            image's slope variance and less than this share of its crest variable's variance,
            in [0, 1); default 0 (every band). Left-out bands have zero amplitudes, so every
            statistic (:meth:`band_covariance`, :meth:`resolved_covariance`, the variances) is
            that of the field without them, and :meth:`sample` skips them. The set left out changes
            in steps with the wind (the gradient with respect to the wind does not see the step).
            The renderer uses ``TableSize.texture_min_band_share`` (``docs/notes/wave_field.md``).

    Synthesis (Tessendorf 2001, with two changes that make the result exact and one-way):
        For band o on its tile (length L_o, N × N texels, lattice k = Δk_o (i û_o + j v̂_o) along the
        tile's axes û_o, v̂_o, turned by α_o = ``bands.tile_angle[o]`` from the world's), every mode of
        the band's annulus gets a complex amplitude H₀(k) = W(k) √(F(k, φ) Δk_o²) where W is
        complex white noise made Hermitian, W(−k) = W(k)*, with E|W|² = 1 (so each real component of
        H₀ has variance F Δk²/2, and ⟨η²⟩ = Σ_k F Δk² exactly, summing over the whole lattice).
        Time: H(k, t) = H₀(k) exp(−i s(k) ω(k) t) with s(k) = sign(k · d) for d the downwind unit
        vector (ties on the crosswind line broken antisymmetrically). s(−k) = −s(k) keeps H
        Hermitian (real field), and each pair H(k) e^{ik·x} + H(−k) e^{−ik·x} is one wave travelling
        DOWNWIND at its phase speed ω/k (why: ``docs/notes/wave_field.md``).
        Elevation η̂ = H, slopes ŝ = −i k H (s = −∇η, ``docs/physics.md`` §2), computed spectrally.
        Field on the texels: η(x_n) = Σ_k H(k) e^{ik·x_n}, evaluated directly on the (N + 1)²
        texels of the circularly padded tile by two small matmuls (along y over the 2M + 1 = 17
        non-zero rows, along x over the M + 1 = 9 stored columns).

    Random draws:
        Image i draws its white noise on the CPU from ``torch.Generator().manual_seed(seed_i)`` in
        float64 (all bands at once, fixed order), then casts and moves it. Everything per image
        (spectrum, phases, the two matmuls) runs in a per-image loop on tensors whose shapes do not
        depend on the batch, and the batched steps afterwards are elementwise or per-sample
        (``grid_sample``; points split into chunks only along the points), so image i of a batch is
        bitwise the image rendered alone, on the same device and dtype. The spectrum, its gradient
        and the phases ω t are computed in float64 and cast, so float32 and float64 fields agree to
        float32 rounding.

    Evaluation (:meth:`sample`):
        Each band's tile is padded circularly by one texel and sampled bilinearly with
        ``grid_sample`` (align_corners=True) at (u mod L_o, v mod L_o), (u, v) the point in the tile's
        axes (turned by ``bands.tile_angle``, :class:`WaveBands`): all channels (η, s_x, s_y)
        of a band in one call, 16 calls for the default layout. Bilinear interpolation at a
        fraction u of a texel keeps a share (1 − u)² + u² + 2u(1 − u) cos θ of a mode's variance per
        axis (θ = k_axis × texel), (2 + cos θ)/3 on average over positions;
        :meth:`band_covariance` includes that factor, so it and :meth:`resolved_covariance` are
        the covariance of what :meth:`sample` returns at uniformly distributed points. What stays
        uncorrected is the texel-scale ripple of the ensemble variance about that average (its size
        for the default layout: ``docs/notes/wave_field.md``).

    Band window:
        :meth:`band_weights`: compact, C¹, one octave wide, so a band is exactly absent beyond
        1.41 π / k_o of footprint; :meth:`sample` then skips it, and only evaluates each band on
        the contiguous range of points where some image still needs it (points are processed in
        chunks). The window multiplies every channel alike (elevation, slopes, crest variable):
        what a footprint resolves of η is the same bands as of the slopes;
        :meth:`elevation_variance` and :meth:`crest_variance` are the variances of what
        :meth:`sample` returns at a footprint (position averages, like :meth:`resolved_covariance`).

    Crest variable (``sample(..., crest=True)``; where foam goes, :func:`~roughsea_torch.foam.crest_foam_fraction`):
        X = Σ_k G(k) H(k) e^{ik·x},  G(k) = (ω(k)²/g) q/√(1 + q²) / √(1 + (k/k_b)⁴) |cos φ|^p,  q = (k/k_lo)²,
        k_lo = ``CREST_HIGHPASS`` k_p = 4 k_p, k_b = ``CREST_CUTOFF`` k_p = 25 k_p, k_p = g Ω_c²/U10²
        (ECKV Eq. 3). For linear waves ∂²η/∂t² = −ω² η component by component, so X is the
        downward vertical acceleration of the surface in units of g, −a_z/g, of the waves between
        k_lo and k_b (second-order Butterworth high and low passes, half power at each): the
        breaking scales. Dimensionless, zero-mean Gaussian; each component's X is in phase with its
        elevation (X > 0 on crests) and in quadrature with its slope, so X and the slopes at a point
        are uncorrelated. Differentiable in the wind (k_lo and k_b move with k_p). Correlation
        length along the wind at 15 m/s ≈ 4.4 m (1/e) without the directional factor.

        Directional factor: φ is the angle of k from the wind axis and p = ``CREST_DIRECTIONAL`` = 1.5.
        With the spectrum's own spreading (p = 0) the patches of X above its threshold are nearly
        round (minor/major axis 0.62 on average, 10–25 m/s, 4 seeds); active breakers are ellipses
        elongated along their crest, across the wind, with axis ratio 0.41 on average (Korinenko et al.
        2024, Black Sea platform video). p weights X towards the waves travelling with the wind, whose
        crests run across it, and was chosen so that the patches' axis ratio is 0.40–0.43
        (``pipelines/whitecap_patches.py``): a calibration to that one measured shape, read as breaking
        being more wind-aligned than the waves' energy. E[f] = W holds for any p (the threshold uses
        X's own variance).

        Band limits: breaking crests travel at c ≈ 0.2–0.5 c_p (the breaking-crest length
        distribution Λ(c): Phillips 1985, J. Fluid Mech. 156; Melville & Matusov 2002, Nature 417,
        58–63; Gemmrich, Banner & Garrett 2008, J. Phys. Oceanogr. 38, 1296–1312); with
        k = (c_p/c)² k_p that is k_lo = 4 k_p (c = 0.5 c_p) and k_b = 25 k_p (c = 0.2 c_p).
        ``CREST_HIGHPASS = 0`` with ``CREST_CUTOFF = 10`` gives the former low pass (the dominant
        crests, tens of metres).

        Sources: the breaking criterion of Longuet-Higgins (1969, Proc. R. Soc. Lond. A 310,
        151–159: a crest breaks when its downward acceleration reaches g/2), made a whitecap
        probability of a Gaussian sea by Snyder & Kennedy (1983, J. Phys. Oceanogr. 13, 1482–1492)
        and Srokosz (1986, J. Phys. Oceanogr. 16, 382–385); the level comes from Monahan &
        O'Muircheartaigh's W, not from g/2. The low pass leaves out the microscale breakers that
        entrain no air (Banner & Phillips 1974, J. Fluid Mech. 65). The reasoning, and the foam
        patches measured with this variable: ``docs/notes/wave_field.md``.

    Attributes:
        batch_size (int), n_bands (int), bands (WaveBands), dtype, device,
        band_wavenumber: (n_bands,) centre wavenumbers k_o [rad m⁻¹].

    Example:
        >>> import torch
        >>> field = WaveField(10.0, seed=0)
        >>> out = field.sample(torch.zeros(1, 5), torch.linspace(0.0, 1.0, 5)[None])
        >>> sorted(out), tuple(out["slope_x"].shape)
        (['elevation', 'slope_x', 'slope_y'], (1, 5))
    """

    def __init__(
        self,
        wind_speed: Any,
        seed: Any,
        *,
        wind_direction: Any = 0.0,
        inverse_wave_age: Any = 0.84,
        dtype: torch.dtype = torch.float32,
        device: torch.device | str | None = None,
        bands: WaveBands | None = None,
        min_band_share: float = 0.0,
    ):
        if not (isinstance(min_band_share, (int, float)) and 0.0 <= float(min_band_share) < 1.0):
            raise ValueError(f"min_band_share must be a number in [0, 1); got {min_band_share!r}")
        if dtype not in (torch.float32, torch.float64):
            raise ValueError(f"dtype must be torch.float32 or torch.float64; got {dtype}")
        if bands is None:
            bands = WaveBands()
        if not isinstance(bands, WaveBands):
            raise ValueError(f"bands must be a WaveBands; got {type(bands).__name__}")
        seeds = parse_seeds(seed)
        check_wind_speed("wind_speed", wind_speed)
        check_finite_range("wind_direction", wind_direction, -MAX_WIND_DIRECTION, MAX_WIND_DIRECTION, unit="rad")
        check_wave_age(inverse_wave_age)
        tensor_device = check_same_device(
            wind_speed=wind_speed, wind_direction=wind_direction, inverse_wave_age=inverse_wave_age
        )
        self.device = torch.device(device) if device is not None else (tensor_device or torch.device("cpu"))
        self.dtype = dtype
        self.bands = bands
        self.n_bands = bands.n_bands

        batch = _batch_size(seeds, wind_speed=wind_speed, wind_direction=wind_direction, inverse_wave_age=inverse_wave_age)
        if seeds.single and batch != 1:
            raise ValueError(
                f"seed: an int seed makes a batch of 1, but the other arguments have B = {batch}; "
                "pass a sequence of B seeds"
            )
        self.batch_size = batch
        self.seeds = tuple(seeds.values)

        f64 = torch.float64
        self.wind_speed = per_batch("wind_speed", wind_speed, batch, f64, self.device)
        self.wind_direction = per_batch("wind_direction", wind_direction, batch, f64, self.device)
        self.inverse_wave_age = per_batch("inverse_wave_age", inverse_wave_age, batch, f64, self.device)
        self.band_wavenumber = torch.tensor(bands.band_wavenumber, dtype=dtype, device=self.device)
        self._lattice = BandLattice(bands, dtype, self.device)

        amplitudes, covariances, signs, gains, variances = [], [], [], [], []
        for b in range(batch):
            amp, cov, sgn, gain, var = self._lattice.image_spectrum(self.wind_speed[b], self.wind_direction[b],
                                                                    self.inverse_wave_age[b], self.seeds[b])
            amplitudes.append(amp)
            covariances.append(cov)
            signs.append(sgn)
            gains.append(gain)
            variances.append(var)
        # bands below min_band_share of the image's slope variance and of its crest variable's are
        # left out (zero amplitudes, covariance and variances: sample skips them)
        cov64, var64 = torch.stack(covariances), torch.stack(variances)  # (B, n_bands, 3), (B, n_bands, 2)
        slope = cov64[..., 0] + cov64[..., 1]
        crest = var64[..., 1]
        share = torch.maximum(slope / slope.sum(-1, keepdim=True).clamp_min(1e-300),
                              crest / crest.sum(-1, keepdim=True).clamp_min(1e-300))
        on = share.detach() >= float(min_band_share)
        self._band_on = on.cpu()  # (B, n_bands) bool
        if not bool(on.all()):
            keep = on.to(torch.float64)
            amplitudes = [a * keep[b, :, None, None].to(a.device) for b, a in enumerate(amplitudes)]
            covariances = [c * keep[b, :, None].to(c.device) for b, c in enumerate(covariances)]
            variances = [v * keep[b, :, None].to(v.device) for b, v in enumerate(variances)]
        self.min_band_share = float(min_band_share)
        cdt = torch.complex64 if dtype == torch.float32 else torch.complex128
        self._h0 = [a.to(cdt) for a in amplitudes]  # per image (n_bands, 2M+1, M+1) complex
        self._sign = signs  # per image (n_bands, 2M+1, M+1) float64 ±1 (0 outside the bands)
        self._covariance = torch.stack(covariances).to(dtype)  # (B, n_bands, 3)
        self._crest_gain = [g.to(dtype) for g in gains]  # per image (n_bands, 2M+1, M+1) real, G(k)
        # per band (B, n_bands, 2): variances of the elevation and of the crest variable
        self._variance = torch.stack(variances).to(dtype)

    # -- band statistics -------------------------------------------------------------------
    def band_weights(self, footprint: Any) -> torch.Tensor:
        """Resolved-part window w_o(f) of each band for a pixel footprint f [m] → (..., n_bands) in [0, 1].

        w_o = 1 − smoothstep(t), t = clamp((u − 2^{−1/2}) / (2^{1/2} − 2^{−1/2}), 0, 1),
        u = k_o f / π, smoothstep(t) = 3t² − 2t³, k_o the band centre. So w_o = 1 while the footprint
        is at most 0.71 × half a centre wavelength (k_o f ≤ 0.71 π), 0 from 1.41 × (k_o f ≥ 1.41 π),
        and in between it falls monotonically over exactly one octave of footprint (one octave in
        log f, hence in log k at a fixed footprint), C¹ (the smoothstep has zero slope at both
        ends). Compact support means a band is exactly off (and skipped) beyond its window.

        Args:
            footprint: f ≥ 0 [m], tensor of any shape (float accepted); 0 gives all 1, +inf all 0.
                Differentiable (the gradient is 0 where w is 0 or 1).
        """
        return band_window(self._footprint_tensor(footprint), tuple(self.bands.band_wavenumber))  # every band at once

    def band_covariance(self) -> torch.Tensor:
        """Expected world-frame slope covariance of each band, (B, n_bands, 3) = (var_x, var_y, cov_xy).

        Σ over the band's discrete modes k (whole lattice) of E|H₀(k)|² k kᵀ = F(k, φ) Δk² k kᵀ, times
        the bilinear factor (2 + cos θx)(2 + cos θy)/9 of each mode: the covariance of the band's
        slopes as :meth:`sample` returns them, averaged over positions. Not the continuous integral
        ∫ F k kᵀ d²k over the annulus: for the default layout the lattice sum (without the bilinear
        factor) is 3–6 % above it for bands above the peak (lattice points vs area, at 4–8 Δk), and
        well below it for bands on the steep low-k flank of the peak. Dimensionless;
        differentiable in wind_speed.
        """
        return self._covariance

    def resolved_covariance(self, footprint: Any) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
        """Covariance of the slopes that ``sample(..., footprint=footprint)`` returns.

        Σ_o w_o(f)² C_o (bands are disjoint in k and independent), C_o from :meth:`band_covariance`.

        Args:
            footprint: f [m] ≥ 0 (inf allowed), shape (B, ...) (a float or 0-d tensor is used for
                every image).

        Returns:
            (var_x, var_y, cov_xy), each of shape (B, ...), dimensionless world-frame slope moments.
        """
        cov = self._windowed(self._covariance, footprint)  # (B, ..., 3)
        return cov[..., 0], cov[..., 1], cov[..., 2]

    def band_elevation_variance(self) -> torch.Tensor:
        """Expected elevation variance of each band, (B, n_bands) [m²]: Σ over the band's modes of
        E|H₀(k)|² times the bilinear factor (as :meth:`band_covariance`, without k kᵀ)."""
        return self._variance[..., 0]

    def band_crest_variance(self) -> torch.Tensor:
        """Expected variance of the crest variable X in each band, (B, n_bands) [dimensionless]:
        Σ over the band's modes of E|H₀(k)|² G(k)² times the bilinear factor."""
        return self._variance[..., 1]

    def elevation_variance(self, footprint: Any = None) -> torch.Tensor:
        """Variance of the elevation that ``sample(..., footprint=footprint)`` returns [m²].

        Σ_o w_o(f)² V_o, V_o from :meth:`band_elevation_variance` (averaged over positions, like
        :meth:`resolved_covariance`).

        Args:
            footprint: None (every band at full weight: the total variance σ_η² of the synthesized
                field, shape (B,)) or f [m] ≥ 0 (inf allowed) of shape (B, ...) (a float or 0-d
                tensor is used for every image): the resolved variance σ_r²(f), shape (B, ...).
        """
        return self._windowed_variance(self._variance[..., 0], footprint)

    def crest_variance(self, footprint: Any = None) -> torch.Tensor:
        """Variance of the crest variable X that ``sample(..., footprint=footprint, crest=True)``
        returns [dimensionless]: the total σ_X² (footprint None, shape (B,)) or the resolved
        Σ_o w_o(f)² V_o^X (shape (B, ...)); arguments as :meth:`elevation_variance`."""
        return self._windowed_variance(self._variance[..., 1], footprint)

    def _windowed(self, per_band: torch.Tensor, footprint: Any) -> torch.Tensor:
        """Σ_o w_o(footprint)² · per_band[:, o, :] for per-band moments (B, n_bands, K): (B, ..., K)."""
        f = self._footprint_tensor(footprint)
        if f.ndim == 0:
            f = f.expand(self.batch_size)
        if f.shape[0] != self.batch_size:
            raise ValueError(
                f"footprint: must have shape (B, ...) with B = {self.batch_size}; got {tuple(f.shape)}"
            )
        w2 = self.band_weights(f) ** 2  # (B, ..., n_bands)
        flat = w2.reshape(self.batch_size, -1, self.n_bands)
        # image by image: a batched matmul's rounding depends on the batch size, and image i must be
        # bitwise the image alone
        out = torch.stack([torch.mm(flat[b], per_band[b]) for b in range(self.batch_size)])
        return out.reshape(*f.shape, per_band.shape[-1])

    def _windowed_variance(self, band_var: torch.Tensor, footprint: Any) -> torch.Tensor:
        if footprint is None:
            return band_var.sum(-1)
        return self._windowed(band_var[:, :, None], footprint)[..., 0]

    # -- evaluation ------------------------------------------------------------------------
    def _footprint_tensor(self, footprint: Any) -> torch.Tensor:
        if footprint is None:
            raise ValueError("footprint is required (a tensor of pixel footprints [m], ≥ 0)")
        f = as_tensor(footprint, self.dtype, self.device)
        if f.numel() and not bool((f >= 0).all()):
            bad = f.detach()[~(f.detach() >= 0)].flatten()[0].item()
            raise ValueError(f"footprint must lie in [0, inf] m and not be NaN; got {bad!r}")
        return f

    def slope_tiles(self, time_s: torch.Tensor) -> torch.Tensor:
        """The slopes of every band on its own tile at times ``time_s`` ((B,) float64 [s], checked by the
        caller), (n_bands, B, 2, N, N): (s_x, s_y) world frame, dimensionless, at texel (row i, column j) =
        tile coordinates (v, u) = (i, j) · L_o / N of band o's period L_o (``bands.tile_length``; the tile's
        axes are turned by ``bands.tile_angle``, world points map to it by ``bands.tile_units``); what :meth:`sample` reads
        bilinearly at full band weight. For filtering a band's slopes on its periodic tile (the renderer's
        patch moments, :mod:`roughsea_torch.renderer.lean`)."""
        tiles = self._tiles(time_s, elevation=False)
        n = tiles.shape[-1] - 1
        return tiles[..., :n, :n]

    def _tiles(self, time_s: torch.Tensor, elevation: bool, crest: bool = False, slopes: bool = True) -> torch.Tensor:
        """Band tiles at the given times, (n_bands, B, C, N+1, N+1); C = (η,) (s_x, s_y) (, X)."""
        tiles = []
        lat = self._lattice
        kx = lat.kx.to(self.dtype)
        ky = lat.ky.to(self.dtype)
        for b in range(self.batch_size):
            wt = lat.omega * time_s[b]  # float64 phases
            cos, sin = torch.cos(wt), torch.sin(wt)
            rot = torch.complex(cos, -self._sign[b] * sin).to(self._h0[b].dtype)  # exp(−i s ω t)
            h = self._h0[b] * rot
            minus_i_h = torch.complex(h.imag, -h.real)  # −i H
            channels = [minus_i_h * kx, minus_i_h * ky] if slopes else []
            if elevation:
                channels.insert(0, h)
            if crest:
                channels.append(h * self._crest_gain[b])  # X̂ = G(k) H
            spec = torch.stack(channels, dim=1)  # (n_bands, C, 2M+1, M+1)
            rows = torch.matmul(lat.ey, spec)  # (n_bands, C, N+1, M+1): inverse DFT along y
            field = torch.matmul(rows.real, lat.cx) - torch.matmul(rows.imag, lat.sx)  # (…, N+1, N+1)
            tiles.append(field)
        return torch.stack(tiles, dim=1)

    def sample(
        self,
        x: Any,
        y: Any,
        time_s: Any = 0.0,
        footprint: Any = None,
        elevation: bool = True,
        crest: bool = False,
    ) -> dict[str, torch.Tensor]:
        """Surface slopes (and elevation, and the crest variable) of each image's field at its points.

        Args:
            x, y: world coordinates [m], tensors of shape (B, ...) (broadcast together; row i holds
                the points of image i); finite. Gradients flow to them (pose gradients).
            time_s: time [s], float or (B,), in [−MAX_TIME_S, MAX_TIME_S] = [−1e9, 1e9] (finite).
            footprint: None (every band at full weight) or the pixel footprint f [m] per point,
                a tensor broadcastable to x, ≥ 0, inf allowed: each band is multiplied by
                :meth:`band_weights` (f). Differentiable.
            elevation: also return the elevation.
            crest: also return the crest variable X (class docstring, *Crest variable*): one more
                channel of the same band loop (no second pass over the bands).

        Returns:
            dict with 'slope_x', 'slope_y' (world-frame slopes s = −∇η, dimensionless, computed
            spectrally as −i k η̂) and, if asked, 'elevation' η [m] and 'crest' X [dimensionless];
            each of shape x.shape, in the field's dtype on its device. Every channel carries the
            same band weights w_o(f). Their covariance at uniformly spread points is
            :meth:`resolved_covariance` (f) (sum of :meth:`band_covariance` without footprint);
            the variances of η and X are :meth:`elevation_variance` (f) and :meth:`crest_variance` (f).
        """
        xt = x if isinstance(x, torch.Tensor) else torch.as_tensor(x)
        yt = y if isinstance(y, torch.Tensor) else torch.as_tensor(y)
        for name, t in (("x", xt), ("y", yt)):
            if t.device != self.device:
                raise ValueError(f"{name} is on {t.device}, the WaveField on {self.device}; move the points")
            if t.ndim == 0:
                raise ValueError(f"{name}: must have shape (B, ...) with B = {self.batch_size}; got a scalar")
        xt, yt = torch.broadcast_tensors(xt.to(self.dtype), yt.to(self.dtype))
        shape = xt.shape
        if shape[0] != self.batch_size:
            raise ValueError(f"x, y: must have shape (B, ...) with B = {self.batch_size}; got {tuple(shape)}")
        for name, t in (("x", xt), ("y", yt)):
            if t.numel() and not bool(torch.isfinite(t.detach()).all()):
                raise ValueError(f"{name} must be finite world coordinates [m] (no NaN or inf)")
        check_time("time_s", time_s)
        t_s = per_batch("time_s", time_s, self.batch_size, torch.float64, self.device)
        f = None
        if footprint is not None:
            f = self._footprint_tensor(footprint)
            try:
                f = torch.broadcast_to(f, shape)
            except RuntimeError as err:
                raise ValueError(f"footprint: shape {tuple(f.shape)} does not broadcast to x {tuple(shape)}") from err
        return self.sample_unchecked(xt, yt, t_s, f, elevation, crest)

    def sample_unchecked(self, xt: torch.Tensor, yt: torch.Tensor, t_s: torch.Tensor, f: torch.Tensor | None,
                         elevation: bool, crest: bool, slopes: bool = True) -> dict[str, torch.Tensor]:
        """:meth:`sample` without its input checks, for callers whose arguments are checked already (the
        renderer's own pixels): ``xt``, ``yt`` (B, ...) of the field's dtype and device, finite; times
        ``t_s`` (B,) float64 within ±MAX_TIME_S; footprints ``f`` of x's shape (≥ 0) or None. Returns what
        :meth:`sample` returns (without the slopes with ``slopes=False``: the elevation alone costs a
        third of the three channels); unchecked input gives unchecked output (NaN, wrong shapes)."""
        shape = xt.shape
        batch = self.batch_size
        npts = int(np.prod(shape[1:])) if len(shape) > 1 else 1
        names = (["elevation"] if elevation else []) + (["slope_x", "slope_y"] if slopes else []) + (["crest"] if crest else [])
        if npts == 0:
            return {name: xt.new_zeros(shape) for name in names}
        xy = torch.stack((xt.reshape(batch, npts), yt.reshape(batch, npts)), dim=-1)  # (B, P, 2)
        if f is not None:
            f = f.reshape(batch, npts)
        tiles = self._tiles(t_s, elevation, crest, slopes)
        acc = self._sample_points(tiles, xy, f)
        return {name: acc[:, c].reshape(shape) for c, name in enumerate(names)}

    def _sample_points(self, tiles: torch.Tensor, xy: torch.Tensor, f: torch.Tensor | None) -> torch.Tensor:
        """Σ_o w_o · bilinear(tile_o) at points xy (B, P, 2) → (B, C, P).

        Band by band, then chunk by chunk of about 2**18 point-evaluations (the temporaries stay in
        cache). Each band's tile is doubled to 2N + 1 texels per side (the period twice, circularly;
        several bands per copy, up to ``_DOUBLED_ELEMENTS``) so that its grid is ``frac(x / L_o)``
        ∈ (−1, 1) straight away: ``frac`` costs a quarter of the floor-division ``remainder``. Points beyond a band's window (w = 0) are not evaluated,
        and the window multiplies only the points where it is below 1: both found from the
        footprint's minimum and maximum over blocks of points, so the skipped work would have
        added exactly 0 or multiplied by exactly 1 (results do not depend on chunks or blocks). A
        band whose tile is zero for every image (``min_band_share``) is skipped."""
        batch, npts = xy.shape[0], xy.shape[1]
        n_ch = tiles.shape[2]
        acc = torch.zeros((batch, n_ch, npts), dtype=self.dtype, device=self.device)
        chunk = max(1024, _CHUNK_ELEMENTS // batch)
        f_all = None if f is None else f.detach()
        if f_all is not None:  # per block of points: the footprint's least and largest value over the batch
            nblk = -(-npts // _BLOCK)
            pad = nblk * _BLOCK - npts
            fb = f_all if pad == 0 else torch.cat([f_all, f_all[:, -1:].expand(batch, pad)], 1)
            fb = fb.reshape(batch, nblk, _BLOCK)
            f_min, f_max = fb.amin(dim=(0, 2)), fb.amax(dim=(0, 2))
            f_min, f_max = f_min.cpu().numpy(), f_max.cpu().numpy()
        margin = 1e-3  # the tensor window is exactly 0 (or 1) well inside these bounds
        n = tiles.shape[-1] - 1
        work = []  # (band, point runs, blocks where the window may be < 1) of the bands that add something
        for o, k_o in enumerate(self.bands.band_wavenumber):
            if not self._band_on[:, o].any():
                continue
            runs, part = [(0, npts)], None
            if f_all is not None:
                runs = _runs(f_min < WINDOW_HI * (1.0 + margin) * math.pi / k_o, npts)
                if not runs:
                    continue
                part = f_max > WINDOW_LO * (1.0 - margin) * math.pi / k_o
            work.append((o, runs, part))
        # the tiles doubled: the period twice, plus texel 2N = texel 0 (circular), a few bands per copy
        per_copy = max(1, _DOUBLED_ELEMENTS // (tiles[0].numel() // (n + 1) ** 2 * (2 * n + 1) ** 2))
        doubled: dict[int, torch.Tensor] = {}
        for i, (o, runs, part) in enumerate(work):
            if o not in doubled:
                group = [w[0] for w in work[i:i + per_copy]]
                core = tiles.index_select(0, torch.tensor(group, device=tiles.device))[..., :n, :n]
                copy = core.new_empty(core.shape[:-2] + (2 * n + 1, 2 * n + 1))
                for rows in (slice(0, n), slice(n, 2 * n)):
                    for cols in (slice(0, n), slice(n, 2 * n)):
                        copy[..., rows, cols] = core
                copy[..., 2 * n, :] = copy[..., 0, :]
                copy[..., :, 2 * n] = copy[..., :, 0]
                doubled = {g: copy[j] for j, g in enumerate(group)}
            tile = doubled[o]
            k_o = self.bands.band_wavenumber[o]
            for lo, hi in runs:
                for a in range(lo, hi, chunk):
                    e = min(hi, a + chunk)
                    grid = self.bands.tile_units(o, xy[:, a:e])
                    grid = torch.frac(grid) if grid.requires_grad else torch.frac(grid, out=grid)
                    values = _bilinear(tile, grid)  # (B, C, P')
                    flagged = None if part is None else np.flatnonzero(part[a // _BLOCK : -(-e // _BLOCK)])
                    if flagged is not None and flagged.size:  # the window where it may be below 1 (exactly 1
                        # elsewhere), one span from the first to the last flagged block of the chunk
                        u = max(a, (a // _BLOCK + int(flagged[0])) * _BLOCK)
                        v = min(e, (a // _BLOCK + int(flagged[-1]) + 1) * _BLOCK)
                        if u < v:
                            w = band_window(f[:, u:v], k_o).unsqueeze(1)
                            if values.requires_grad or w.requires_grad:
                                values = torch.cat([values[..., : u - a], values[..., u - a : v - a] * w,
                                                    values[..., v - a :]], -1)
                            else:
                                values[..., u - a : v - a] *= w
                    acc[..., a:e] += values  # in place on our own buffer; autograd records the slice
        return acc


def _bilinear(tile: torch.Tensor, grid: torch.Tensor) -> torch.Tensor:
    """``grid_sample`` (bilinear, border, align_corners) of tiles (B, C, H, W) at points grid (B, P, 2) in [−1, 1]
    → (B, C, P). grid_sample's CPU kernel runs its images in parallel, not its points: with fewer images than
    threads the points are split into that many groups, each read as an image of its own, which changes no
    value (the tile is expanded, not copied, for one image; a batch of several copies each tile once per group)."""
    batch, npts = grid.shape[0], grid.shape[1]
    k = torch.get_num_threads() // batch if grid.device.type == "cpu" else 1
    if k < 2 or npts < 2048 * k:
        return F_nn.grid_sample(tile, grid.unsqueeze(1), mode="bilinear", padding_mode="border",
                                align_corners=True).squeeze(2)
    per = -(-npts // k)
    pad = per * k - npts
    g = grid if pad == 0 else torch.cat([grid, grid[:, -1:].expand(batch, pad, 2)], 1)
    g = g.reshape(batch * k, 1, per, 2)
    t = tile[:, None].expand(batch, k, *tile.shape[1:]).reshape(batch * k, *tile.shape[1:])
    out = F_nn.grid_sample(t, g, mode="bilinear", padding_mode="border", align_corners=True)  # (B k, C, 1, per)
    out = out.reshape(batch, k, tile.shape[1], per).permute(0, 2, 1, 3).reshape(batch, tile.shape[1], per * k)
    return out[..., :npts]


def _runs(blocks: np.ndarray, npts: int, gap: int = 4) -> list[tuple[int, int]]:
    """Point ranges [a, b) covering the True blocks of ``blocks`` (blocks of ``_BLOCK`` points), runs
    less than ``gap`` blocks apart merged (fewer, larger calls), clipped to ``npts``."""
    on = np.flatnonzero(blocks)
    if on.size == 0:
        return []
    cut = np.flatnonzero(np.diff(on) > gap)
    starts = np.concatenate([on[:1], on[cut + 1]])
    ends = np.concatenate([on[cut], on[-1:]]) + 1
    return [(int(a) * _BLOCK, min(npts, int(b) * _BLOCK)) for a, b in zip(starts, ends)]


# ---------------------------------------------------------------------------------------------
# argument helpers
# ---------------------------------------------------------------------------------------------
def _batch_size(seeds: ParsedSeeds, **items: Any) -> int:
    """B from the per-image arguments: tensors/arrays of shape (B,) and the seed sequence."""
    sizes: dict[str, int] = {}
    if not seeds.single:
        sizes["seed"] = len(seeds.values)
    for name, v in items.items():
        if isinstance(v, (torch.Tensor, np.ndarray)) and v.ndim > 0:
            if v.ndim != 1:
                raise ValueError(f"{name}: must be a float or a tensor of shape (B,); got shape {tuple(v.shape)}")
            sizes[name] = int(v.shape[0])
    distinct = set(sizes.values())
    if len(distinct) > 1:
        listing = ", ".join(f"{k} has {v}" for k, v in sizes.items())
        raise ValueError(f"seed, wind_speed, wind_direction, inverse_wave_age: batch sizes differ ({listing})")
    return distinct.pop() if distinct else 1


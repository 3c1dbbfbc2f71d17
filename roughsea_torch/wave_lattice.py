"""The Fourier lattice of a band-split wave field, and the random amplitudes of one realization.

A :class:`~roughsea_torch.waves.WaveField` synthesizes each band of a :class:`~roughsea_torch.wave_bands.WaveBands`
layout on its own periodic tile (Tessendorf, *Simulating ocean water*, SIGGRAPH course notes, 2001).
:class:`BandLattice` holds what depends on the layout only: the lattice k = Δk_o (i, j) of each band's
compact half spectrum (rows i_y = −M..M, columns i_x = 0..M), the dispersion ω(k)
(:func:`~roughsea_torch.spectrum.dispersion`), the bilinear-interpolation factor of each mode, and the
matrices of the inverse DFT onto the texels of a tile. :meth:`BandLattice.image_spectrum` gives one
realization's amplitudes H₀(k) = W(k) √(F(k, φ) Δk²) from the ECKV spectrum F
(:func:`~roughsea_torch.spectrum.eckv_terms`, Elfouhaily et al. 1997) and a seeded Hermitian white
noise W, with the travel signs, the band covariances and the crest variable's gain (equations:
:class:`~roughsea_torch.waves.WaveField`).
"""

from __future__ import annotations

import math

import torch

from .spectrum import GRAVITY, dispersion, eckv_terms
from .wave_bands import WaveBands

__all__ = ["CREST_CUTOFF", "CREST_DIRECTIONAL", "CREST_HIGHPASS", "BandLattice"]

# the crest variable's band pass (WaveField docstring, *Crest variable*): breaking crests travel at
# c ≈ 0.2–0.5 c_p (Melville & Matusov 2002; Gemmrich, Banner & Garrett 2008), k = (c_p/c)² k_p
CREST_CUTOFF = 25.0  # k_b / k_p of the low pass (c ≈ 0.2 c_p)
CREST_HIGHPASS = 4.0  # k_lo / k_p of the high pass (c ≈ 0.5 c_p); 0 with CREST_CUTOFF 10 is the old low pass
# p of the crest gain's directional factor |cos φ|^p (φ from the wind axis): breaking patches elongated
# across the wind with the axis ratio measured by Korinenko et al. 2024 (0.41); 0 is the spectrum's spreading
CREST_DIRECTIONAL = 1.5


class BandLattice:
    """The lattice of every band's modes for a :class:`~roughsea_torch.wave_bands.WaveBands` layout, on
    ``device``, with the inverse-DFT matrices in ``dtype`` (float32 or float64).

    Attributes (per band o, rows i_y = −M..M, columns i_x = 0..M along the tile's axes, M = ``max_index``;
    float64 unless said):
        mask: (n_bands, 2M+1, M+1) bool, the modes of band o's annulus.
        kx, ky, k: the wavenumber vector in the world frame and its norm [rad m⁻¹] (k = 1 outside the mask).
        dk2: Δk_o² [rad² m⁻²]; omega: ω(k) [rad s⁻¹].
        multiplicity: 2 for i_x > 0 (a mode and its conjugate mirror −k), 1 for i_x = 0.
        interp: the bilinear factor (2 + cos θx)(2 + cos θy)/9 of each mode.
        ey: (N+1, 2M+1) complex, the inverse DFT along y; cx, sx: (M+1, N+1) in ``dtype``, the real
            transform along x (cosine and sine parts, weights 1 and 2).
    """

    def __init__(self, bands: WaveBands, dtype: torch.dtype, device: torch.device):
        self.n_bands = bands.n_bands
        self.dtype, self.device = dtype, device
        dev, f64 = device, torch.float64
        m = bands.max_index
        n = bands.tile_size
        iy = torch.arange(-m, m + 1, dtype=f64).view(-1, 1).expand(2 * m + 1, m + 1)
        ix = torch.arange(0, m + 1, dtype=f64).view(1, -1).expand(2 * m + 1, m + 1)
        r2 = ix**2 + iy**2
        dk = torch.tensor(bands.fundamental, dtype=f64).view(-1, 1, 1)
        ratio = torch.tensor([b / a for a, b in zip(bands.k_edges[:-1], bands.k_edges[1:])], dtype=f64).view(-1, 1, 1)
        inner2 = bands.inner_radius**2
        mask = (r2 >= inner2) & (r2 < inner2 * ratio**2)  # (n_bands, 2M+1, M+1)
        # the half plane: i_x > 0, plus i_x = 0 with both signs of i_y; the indices count along band o's tile
        # axes, turned by α_o from the world's (WaveBands.tile_angle): k = Δk_o (i_x û + i_y v̂) in the world
        # frame, û = (cos α_o, sin α_o), v̂ = (−sin α_o, cos α_o)
        alpha = torch.tensor(bands.tile_angle, dtype=f64).view(-1, 1, 1)
        ca, sa = torch.cos(alpha), torch.sin(alpha)
        kx = (ix * ca - iy * sa) * dk
        ky = (ix * sa + iy * ca) * dk
        k = torch.sqrt(r2) * dk  # the same for every turn of the tile
        self.mask = mask.to(dev)
        self.kx = kx.to(dev)
        self.ky = ky.to(dev)
        self.k = torch.where(mask, k, torch.ones_like(k)).to(dev)  # safe (no k = 0) where masked out
        self.dk2 = (dk**2).expand_as(k).to(dev)
        self.omega = dispersion(self.k)  # float64 [rad/s]
        # each stored mode with i_x > 0 stands for itself and its conjugate mirror −k
        self.multiplicity = torch.where(ix > 0, 2.0, 1.0).to(dev).expand_as(k)
        # bilinear interpolation keeps (2 + cos θx)(2 + cos θy)/9 of a mode's variance on average
        theta = 2.0 * math.pi / n
        self.interp = ((2.0 + torch.cos(theta * ix)) * (2.0 + torch.cos(theta * iy)) / 9.0).to(dev)
        # the inverse DFT evaluated on the (N+1) × (N+1) texels 0..N of the circularly padded tile
        # (texel N repeats texel 0 exactly): along y over the 2M+1 non-zero rows,
        # E[n, r] = exp(2πi i_y(r) n / N); along x a real transform over the M+1 stored columns,
        # η[n, m] = Σ_c w_c (Re Y[n, c] cos(2π c m/N) − Im Y[n, c] sin(2π c m/N)), w_0 = 1, w_c = 2
        # (the columns c > 0 stand for ±c; column 0 is real by Hermitian symmetry).
        texel = torch.arange(n + 1, dtype=f64)
        texel[-1] = 0.0
        rows = torch.arange(-m, m + 1, dtype=f64)
        phase = 2.0 * math.pi * torch.outer(texel, rows) / n
        cdt = torch.complex64 if dtype == torch.float32 else torch.complex128
        self.ey = torch.polar(torch.ones_like(phase), phase).to(cdt).to(dev)  # (N+1, 2M+1)
        cols = torch.arange(0, m + 1, dtype=f64)
        phase = 2.0 * math.pi * torch.outer(cols, texel) / n  # (M+1, N+1)
        weight = torch.where(cols > 0, 2.0, 1.0).view(-1, 1)
        self.cx = (weight * torch.cos(phase)).to(dtype).to(dev)
        self.sx = (weight * torch.sin(phase)).to(dtype).to(dev)
        self.max_index = m

    def white_noise(self, seed: int) -> torch.Tensor:
        """Hermitian complex white noise, E|W|² = 1, for all bands: (n_bands, 2M+1, M+1), CPU float64,
        drawn from ``torch.Generator().manual_seed(seed)`` (all bands at once, fixed order)."""
        m = self.max_index
        gen = torch.Generator(device="cpu").manual_seed(seed)
        z = torch.randn((self.n_bands, 2 * m + 1, 2 * m + 1, 2), generator=gen, dtype=torch.float64)
        z = torch.complex(z[..., 0], z[..., 1]) / math.sqrt(2.0)  # E|z|² = 1, rows i_y, cols i_x = −M..M
        w = (z + torch.conj(torch.flip(z, dims=(-2, -1)))) / math.sqrt(2.0)  # W(−k) = W(k)*
        return w[..., m:]  # columns i_x = 0..M

    def image_spectrum(self, wind: torch.Tensor, direction: torch.Tensor, omega_c: torch.Tensor, seed: int
                       ) -> tuple[torch.Tensor, ...]:
        """One realization: for the wind speed U10 [m s⁻¹], the upwind axis' azimuth [rad] and Ω_c (float64
        scalars on the lattice's device) and the seed, the amplitudes H₀ (complex128), band covariance
        (n_bands, 3), travel signs, the crest variable's gain G(k) (float64) and the band variances of η
        and of the crest variable (n_bands, 2) (:class:`~roughsea_torch.waves.WaveField`, *Synthesis*)."""
        s, delta = eckv_terms(self.k, wind, omega_c)
        # cos 2φ with φ the angle from the downwind (equivalently upwind) axis, from components
        cu, su = torch.cos(direction), torch.sin(direction)
        along = self.kx * cu + self.ky * su  # k · (upwind unit vector)
        across = -self.kx * su + self.ky * cu
        cos2phi = (along**2 - across**2) / self.k**2
        spec = s / self.k * (1.0 + delta * cos2phi) / (2.0 * math.pi)  # F(k, φ) [m⁴]
        var = torch.where(self.mask, spec * self.dk2, torch.zeros_like(spec))  # E|H₀|² [m²]
        positive = var > 0
        amp = torch.where(positive, torch.sqrt(torch.where(positive, var, torch.ones_like(var))), torch.zeros_like(var))
        noise = self.white_noise(seed).to(self.device)
        h0 = noise * amp
        # travel sign: +1 where k points downwind (k · upwind < 0), ties broken by the crosswind part. A tie is
        # |k · upwind| ≤ 1e-6 k, not 0: a direction rounded to float32 (π/2 → cos = −4e-8) must not flip the
        # waves across the wind (a wave that close to the cross axis has the same spectrum either way; what
        # matters is that both dtypes of a direction make the same choice)
        tie = along.abs() <= 1e-6 * self.k
        sign = torch.where(tie, torch.sign(across), torch.sign(-along))
        sign = torch.where(self.mask, sign, torch.zeros_like(sign))
        weight = var * self.multiplicity * self.interp
        cov = torch.stack(
            [
                (weight * self.kx**2).sum(dim=(-2, -1)),
                (weight * self.ky**2).sum(dim=(-2, -1)),
                (weight * self.kx * self.ky).sum(dim=(-2, -1)),
            ],
            dim=-1,
        )
        # the crest variable (WaveField docstring): G(k) = ω²/g × |2nd-order Butterworth band pass k_lo–k_b|
        # × |cos φ|^p, φ the angle of k from the wind axis
        k_p = GRAVITY * omega_c**2 / wind**2  # ECKV Eq. 3
        k_b = CREST_CUTOFF * k_p
        gain = self.omega**2 / GRAVITY * torch.rsqrt(1.0 + (self.k / k_b) ** 4)
        if CREST_HIGHPASS > 0:
            q = (self.k / (CREST_HIGHPASS * k_p)) ** 2
            gain = gain * q * torch.rsqrt(1.0 + q**2)
        if CREST_DIRECTIONAL > 0:
            gain = gain * (along.abs() / self.k) ** CREST_DIRECTIONAL
        gain = torch.where(self.mask, gain, torch.zeros_like(gain))
        variance = torch.stack([weight.sum(dim=(-2, -1)), (weight * gain**2).sum(dim=(-2, -1))], dim=-1)
        return h0, cov, sign, gain, variance

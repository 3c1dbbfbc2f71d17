"""The short waves a sweep sample holds, pre-filtered: the mean and covariance of the unresolved bands'
slopes over the sample's ground patch (LEAN mapping, applied to the wave field's bands).

Near grazing at light wind a pixel's visible surface holds only a few patches of the waves between
10 cm and a metre, and their own slopes there, not the ensemble's, set much of the clutter (finite
sampling: ``docs/subpixel_clutter.md``). The first-hit sweep (:mod:`~roughsea_torch.renderer.hits`)
resolves the waves longer than its samples' footprint F_s and leaves the rest to the expectation with
constant statistics. This module gives each sample the realization's own moments of those unresolved
waves over the patch the sample stands for: with u_o = 1 − w_o(F_s) the unresolved share of band o
(:func:`~roughsea_torch.wave_bands.band_window`) and s_o its slopes,

    μ = Σ_o u_o ⟨s_o⟩_P,    C = Σ_o u_o² (⟨s_o s_oᵀ⟩_P − ⟨s_o⟩_P ⟨s_o⟩_Pᵀ),

⟨·⟩_P the average over the patch P (bands are independent: their cross products average out, and are
left out). The renderer adds μ to the resolved slope where it reads its texture, and scales the
unresolved Gaussian's along-view variance by its patch value, both as far as the unresolved Gaussian holds
the field's bands (a factor κ ≤ 1), and weights each sample by its patch's visible projected area
(:func:`projected_area`, :func:`weighted_window`; ``TableSize.texture_hit_lean``,
:mod:`~roughsea_torch.renderer.swept`). Over all
positions E[μμᵀ] + E[C] = Σ_o u_o² C_o, the unresolved bands' own covariance: the two moments
redistribute the unresolved variance between the samples, they add none.

Method: per band, the tile's slope and slope-product fields (s_x, s_y, s_x², s_y², s_x s_y) are
low-passed with a Gaussian of standard deviation p/√12 (the second moment of a box of side p) by FFT
on the band's periodic tile, at patch sizes p = 2^j λ_o (j = −2 … 1, λ_o = 2π/k_o the band's centre
wavelength): a mip pyramid in the band's own units. A point reads the two levels about its patch's
log₂(p/λ_o) bilinearly and blends them linearly; from j = 1 to 2 the top level blends into the band's
expectation (μ_o = 0, C_o), which holds beyond (four wavelengths to a patch; a constant from j = 3 on
instead gave the same comparison with the ray tracer, bin for bin). The patch is taken isotropic, of the area of the
sweep sample's (``TableSize.texture_hit_lean_across`` · R δ across × its length along the view).

Sources: M. Olano & D. Baker, *LEAN mapping*, Proc. ACM I3D 2010, 181–188 (filtered first and second
moments of a bump map's slopes, their difference the covariance handed to the reflectance model);
J. Dupuy, E. Heitz, J.-C. Iehl, P. Poulin, F. Neyret & V. Ostromoukhov, *Linear efficient antialiased
displacement and reflectance mapping*, ACM TOG 32(6), 2013 (LEADR: the same moments under
displacement, with the masking of the visible surface); E. Bruneton, F. Neyret & N. Holzschuch,
*Real-time realistic ocean lighting using seamless transitions from geometry to BRDF*, Computer
Graphics Forum 29(2), 2010 (the ocean's slope variance filtered per pixel). The patch test against a
ray trace of the same waves is in ``docs/subpixel_clutter.md``.
"""

from __future__ import annotations

import math
from typing import Any

import torch
import torch.nn.functional as F

from ..facets import eq5_denominator
from ..wave_bands import band_window

__all__ = ["ShortWaveMoments", "variance_columns", "log_variance_quadratic", "projected_area",
           "weighted_window", "LEVELS", "CONSTANT_LEVEL", "ELL_NODE",
           "ELL_CLAMP"]

LEVELS = (-2, -1, 0, 1)  # log₂(patch / band wavelength) of the filtered tiles
CONSTANT_LEVEL = 2.0  # from here on a band's patch moments are its expectation (blended in from the top level)
ELL_NODE = math.log(2.0)  # the texture table's nodes in ℓ (the along-view unresolved variance's log scale): ±ln 2
ELL_CLAMP = math.log(3.0)  # |ℓ| beyond which the quadratic in ℓ is not extrapolated


class ShortWaveMoments:
    """The patch moments of the unresolved bands of one image of a wave field at one time.

    Args:
        field: a :class:`~roughsea_torch.waves.WaveField`; image: its image.
        time_s: the times of the field's images [s], a (B,) float64 tensor.

    Call it with world points x, y (P,) [m], their footprints (the resolved cut F_s [m]) and patch sizes p
    [m] (P,), or per row (R,) with each point's row (P,): (μ_x, μ_y, C_xx, C_yy, C_xy, V_xx, V_yy, V_xy), each
    (P,), world-frame slopes (dimensionless): the patch mean μ and covariance C of the unresolved slopes, and V = Σ_o u_o² C_o their
    expected total (μμᵀ + C averages to V over positions; C_o the band's covariance on its tile's texels,
    :meth:`band_moments`).
    """

    def __init__(self, field: Any, image: int, time_s: torch.Tensor):
        self.field, self.image = field, image
        self.dtype, self.device = field.dtype, field.device
        self.k = tuple(field.bands.band_wavenumber)
        self.length = tuple(field.bands.tile_length)
        cov = field.band_covariance()[image]  # (n_bands, 3)
        self.on = ((cov[:, 0] + cov[:, 1]).detach() > 0).tolist()
        self._means: dict[int, torch.Tensor] = {}
        self.time = time_s
        self._levels: dict[int, torch.Tensor] = {}
        self._slopes = None

    def _band_slopes(self) -> torch.Tensor:
        if self._slopes is None:  # (n_bands, 2, N, N)
            self._slopes = self.field.slope_tiles(self.time)[:, self.image]
        return self._slopes

    def levels(self, o: int) -> torch.Tensor:
        """Band ``o``'s filtered tiles, (len(LEVELS), 5, N + 1, N + 1): (⟨s_x⟩, ⟨s_y⟩, ⟨s_x²⟩, ⟨s_y²⟩,
        ⟨s_x s_y⟩) at each level, circularly padded by one texel (texel N = texel 0)."""
        if o not in self._levels:
            s = self._band_slopes()[o]  # (2, N, N) world (s_x, s_y); rows v, columns u: turned axes
            n = s.shape[-1]
            fields = torch.stack([s[0], s[1], s[0] * s[0], s[1] * s[1], s[0] * s[1]])
            spec = torch.fft.rfft2(fields)
            texel = self.length[o] / n
            ky = 2.0 * math.pi * torch.fft.fftfreq(n, d=texel, dtype=self.dtype, device=self.device)
            kx = 2.0 * math.pi * torch.fft.rfftfreq(n, d=texel, dtype=self.dtype, device=self.device)
            k2 = ky[:, None] ** 2 + kx[None, :] ** 2
            lam = 2.0 * math.pi / self.k[o]
            out = []
            for j in LEVELS:
                sig = (2.0 ** j) * lam / math.sqrt(12.0)
                out.append(torch.fft.irfft2(spec * torch.exp(-0.5 * sig * sig * k2), s=(n, n)))
            lev = torch.stack(out)  # (L, 5, N, N)
            self._levels[o] = F.pad(lev, (0, 1, 0, 1), mode="circular")
        return self._levels[o]

    def band_moments(self, o: int) -> torch.Tensor:
        """C_o = (var_x, var_y, cov_xy) of band ``o``'s slopes, the mean of their products over its tile's
        texels (what every level averages to over positions)."""
        if o not in self._means:
            s = self._band_slopes()[o]
            self._means[o] = torch.stack([s[0] * s[0], s[1] * s[1], s[0] * s[1]]).mean(dim=(-2, -1))
        return self._means[o]

    def __call__(self, x: torch.Tensor, y: torch.Tensor, footprint: torch.Tensor, patch: torch.Tensor,
                 row: torch.Tensor | None = None) -> tuple:
        """The moments at world points ``x``, ``y`` (P,) [m] whose footprints F_s and patch sizes p [m] are
        ``footprint`` and ``patch`` (R,), read at each point's ``row`` (P,) (None: R = P, one each); see
        the class docstring."""
        dtype = self.dtype
        if row is None:
            row = torch.arange(x.shape[0], device=x.device)
        n_rows = footprint.shape[0]
        zero_r = footprint.new_zeros((n_rows,), dtype=dtype)
        const = [zero_r, zero_r, zero_r]  # the same, per row, of the bands whose patches hold 4 wavelengths or more
        expected = [zero_r, zero_r, zero_r]  # Σ u² C_o per row
        nl = len(LEVELS)
        xy = torch.stack([x, y], -1)  # (P, 2)
        graph = torch.is_grad_enabled() and any(t.requires_grad for t in (x, y, footprint, patch, self._band_slopes()))
        # μ_x, μ_y and Σ u² (⟨s sᵀ⟩ − ⟨s⟩⟨s⟩ᵀ) (three) at the points read; in place where no graph is kept
        acc = x.new_zeros((5,) + x.shape, dtype=dtype)
        for o, k_o in enumerate(self.k):
            if not self.on[o]:
                continue
            u = 1.0 - band_window(footprint, k_o)  # (R,)
            if not bool((u.detach() > 0).any()):
                continue
            j = torch.log2(patch.detach() / (2.0 * math.pi / k_o))
            cov_o = self.band_moments(o)
            u2 = u * u
            far = (u.detach() > 0) & (j >= CONSTANT_LEVEL)
            for c in range(3):
                expected[c] = expected[c] + u2 * cov_o[c]
                const[c] = const[c] + torch.where(far, u2 * cov_o[c], torch.zeros_like(u2))
            near_rows = (u.detach() > 0) & (j < CONSTANT_LEVEL)
            if not bool(near_rows.any()):
                continue
            lev = self.levels(o)
            jc = (j - LEVELS[0]).clamp(0.0, float(nl))  # (R,) in levels from the first
            i0 = torch.floor(jc).clamp(max=nl - 1).long()
            for lv in torch.unique(i0[near_rows]).tolist():  # the points between levels lv and lv + 1: one read of both
                at = flat_index((near_rows & (i0 == lv)).index_select(0, row))
                if at.numel() == 0:
                    continue
                a0, a1 = int(at[0]), int(at[-1]) + 1
                span = slice(a0, a1) if a1 - a0 == at.numel() else None  # (points in sweep order: a level's run)
                pick = (lambda v: v[span]) if span is not None else (lambda v: v.index_select(0, at))  # noqa: E731
                ra = pick(row)
                t = jc.index_select(0, ra) - float(lv)
                us = u.index_select(0, ra)
                grid = torch.remainder(self.field.bands.tile_units(o, pick(xy)), 1.0).mul_(2.0).sub_(1.0).to(dtype)[None, None]
                pair = lev[lv:lv + 2].reshape(1, -1, *lev.shape[-2:])  # (1, 10 or 5, N + 1, N + 1)
                read = F.grid_sample(pair, grid, mode="bilinear", padding_mode="border", align_corners=True)[0, :, 0]
                lo = read[:5]
                if lv + 1 < nl:
                    hi = read[5:]
                else:  # beyond the top level the band's moments blend into their expectation (μ_o = 0, C_o)
                    hi = torch.cat([torch.zeros_like(lo[:2]), cov_o[:, None].to(lo.dtype).expand(3, lo.shape[1])])
                m = lo + (hi - lo) * t.clamp(0.0, 1.0)[None]
                us2 = us * us
                parts = torch.stack((us * m[0], us * m[1], us2 * (m[2] - m[0] * m[0]), us2 * (m[3] - m[1] * m[1]),
                                     us2 * (m[4] - m[0] * m[1])))
                if graph:
                    acc = acc.index_add(1, at, parts)
                elif span is not None:
                    acc[:, span] += parts
                else:
                    acc.index_add_(1, at, parts)
        return (acc[0], acc[1], *(acc[2 + c] + const[c].index_select(0, row) for c in range(3)),
                *(e.index_select(0, row) for e in expected))


def variance_columns(moments: list, ph: torch.Tensor, nx: int) -> list:
    """The texture table's node columns for ℓ = ±ln 2: the first nx node columns of ``moments`` (var_up,
    var_cr, cov, mean_up, mean_cr; φ̂ = ``ph`` (M,) each node's azimuth from upwind) with the unresolved
    covariance's along-view component scaled by e^ℓ: Σ' = A Σ A, A = I + (e^{ℓ/2} − 1) ê êᵀ (ê = (cos φ̂,
    sin φ̂) in the upwind frame; positive definite as Σ), appended to ``moments`` (2 nx more columns)."""
    c, s = torch.cos(ph)[:, None], torch.sin(ph)[:, None]
    vu, vc, cv, mu, mc = (m[:, :nx] for m in moments)
    w0, w1 = vu * c + cv * s, cv * c + vc * s  # Σ ê
    q = c * w0 + s * w1  # êᵀ Σ ê
    cols = [[], [], []]
    for ell in (-ELL_NODE, ELL_NODE):
        d = math.exp(0.5 * ell) - 1.0
        cols[0].append(vu + 2.0 * d * c * w0 + d * d * q * c * c)
        cols[1].append(vc + 2.0 * d * s * w1 + d * d * q * s * s)
        cols[2].append(cv + d * (c * w1 + s * w0) + d * d * q * c * s)
    out = [torch.cat([m] + e, 1) for m, e in zip(moments[:3], cols)]
    return out + [torch.cat([m, mean, mean], 1) for m, mean in zip(moments[3:], (mu, mc))]


def log_variance_quadratic(r_minus: torch.Tensor, r_bar: torch.Tensor, r_plus: torch.Tensor
                           ) -> tuple[torch.Tensor, torch.Tensor]:
    """(b, c) of R(ℓ) ≈ R̄ + b ℓ + c ℓ² through the node values at ℓ = −ln 2, 0, ln 2 (``r_minus``, ``r_bar``,
    ``r_plus``: the along-view unresolved variance halved, as it is, doubled; :func:`variance_columns`)."""
    return (r_plus - r_minus) / (2.0 * ELL_NODE), (0.5 * (r_plus + r_minus) - r_bar) / (ELL_NODE * ELL_NODE)


def weighted_window(wx: torch.Tensor, w: torch.Tensor, covered: torch.Tensor) -> torch.Tensor:
    """A pixel's weighted average of a quantity x over its window's covered part, times that part, from the
    window averages (:func:`~roughsea_torch.renderer.hits.visible_average`) of w x, of the weights w and of 1
    (the covered share: the window beyond the sweep counts 0): ⟨w x⟩ / ⟨w⟩ · ⟨1⟩, 0 where ⟨w⟩ = 0. With w = 1
    it is ⟨x⟩, the unweighted average."""
    ok = w > 0
    return torch.where(ok, wx / torch.where(ok, w, torch.ones_like(w)) * covered, torch.zeros_like(wx))


def projected_area(e: torch.Tensor, a: torch.Tensor) -> torch.Tensor:
    """Eq. 5's D (:func:`~roughsea_torch.facets.eq5_denominator`) from e = cos θ̂ + sin θ̂ m∥ and a = sin θ̂ σ∥,
    floored at the smallest normal number (a weight's denominator)."""
    return eq5_denominator(e, a).clamp_min(torch.finfo(e.dtype).tiny)


def flat_index(mask: torch.Tensor) -> torch.Tensor:
    """The indices of the True elements of a 1-D bool tensor."""
    return mask.nonzero().squeeze(1)

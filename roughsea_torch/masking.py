"""Slope-conditioned masking: the facet weight of Eq. 5 with the correlation between a facet's slope
and its masking (``shadowing="correlated"``).

Eq. 5 weights a facet of slope s by t(s) = cos θ̂ + sin θ̂ s∥ where t > 0. Smith's (1967) masking of
an uncorrelated surface multiplies every such facet by the same 1/(1 + Λ), which cancels in the
normalization. On a real surface a facet tilted steeply towards the sensor starts its ray well above
the neighbouring surface and is masked less than one seen at grazing. Following Bourlier, Berginc and
Saillard (IEEE TAP 2002, the Smith/Wagner shadowing with the correlation, i.e. the first term of
Rice's series of Ricciardi and Sato), the crossing rate of the ray at a horizontal distance l is
conditioned on the origin's height ξ₀ and slope γ₀ (γ = −s∥ along the view, μ = cot θ̂):

    g(l) = p(z | ξ₀, γ₀) E[(γ(l) − μ)⁺ | ξ(l) = z, ξ₀, γ₀] / P(ξ(l) < z | ξ₀, γ₀),   z = ξ₀ + μ l,
    S(x, ν) = ∫ φ(ξ₀) exp(−∫₀^∞ g dl) dξ₀ (x > −ν),    Q(x, ν) = S (1 + Λ(ν)),

for a Gaussian height autocorrelation R(l) = σ_h² exp(−l²/L²). In units σ_h = L = 1 it depends only on
ν = (cot θ̂ + m∥)/σ∥ (the line of sight's slope over the rms slope along it, with a mean slope m∥)
and x = (s∥ − m∥)/σ∥, so Q is tabulated (float64, shipped with the package: :func:`masking_table`) on
√(x + ν) ∈ [0, 4] × ln ν ∈ [ln 0.01, ln 8] and interpolated bilinearly. The option's facet weight is
t(s) Q, normalized by D_Q = E[t Q H(t)] (:func:`masked_denominator`); Q ≡ 1 would be Eq. 5 exactly.
Outside the table: ν < 0.01 (within ~0.1° of grazing) uses ν = 0.01, ν > 8 (no masking left) uses
ν = 8, x + ν > 16 uses 16, x + ν < 1e-4 uses 1e-4 (the tangent ray, where t ∝ x + ν ≈ 0). The numpy reference is :mod:`roughsea_torch.reference.masking`.

``shadowing`` everywhere takes True (Eq. 5), False (Eq. 7), "correlated" (this module) or "multiscale"
(:mod:`roughsea_torch.multiscale_masking`, whose factor :func:`facet_masking` and :func:`masked_denominator`
apply the same way): :func:`check_shadowing`.
"""

from __future__ import annotations

import math
from functools import lru_cache
from pathlib import Path
from typing import Any

import numpy as np
import torch

from .facets import FacetGeometry, normal_cdf, normal_pdf
from .multiscale_masking import multiscale_ratio

__all__ = ["SHADOWING_OPTIONS", "MASKED_OPTIONS", "check_shadowing", "facet_masking", "masking_table", "compute_masking_table", "table_nodes", "masking_ratio",
           "masked_denominator", "TABLE_FILE"]

SHADOWING_OPTIONS = (True, False, "correlated", "multiscale")
MASKED_OPTIONS = ("correlated", "multiscale")  # Eq. 5's weight times a masking factor Q of the facet's slope
NU_MIN, NU_MAX, W_MAX = 0.01, 8.0, 16.0
W_MIN = 1e-4  # Q is held below x + ν = W_MIN (the tangent ray; t ∝ x + ν weighs it out)
_N_NU, _N_P = 97, 121
_SIGMA = math.sqrt(2.0)  # rms slope of R(l) = exp(−l²)
_L_TAIL = 5.0


def check_shadowing(shadowing: Any) -> Any:
    """``shadowing`` itself if it is True, False, "correlated" or "multiscale", else a ValueError naming it."""
    if isinstance(shadowing, str) and shadowing in MASKED_OPTIONS:
        return shadowing
    if isinstance(shadowing, (bool, np.bool_)):
        return bool(shadowing)
    raise ValueError(f"shadowing must be True (Eq. 5), False (Eq. 7), 'correlated' (slope-conditioned masking) or "
                     f"'multiscale' (multi-scale masking); got {shadowing!r}")


def facet_masking(shadowing: str, x: torch.Tensor, nu: torch.Tensor) -> torch.Tensor:
    """The factor on Eq. 5's facet weight of a masked option (:data:`MASKED_OPTIONS`) at standardized
    along-view slopes ``x`` and ν (:func:`view_nu`): :func:`masking_ratio` ("correlated") or
    :func:`~roughsea_torch.multiscale_masking.multiscale_ratio` ("multiscale")."""
    return multiscale_ratio(x, nu) if shadowing == "multiscale" else masking_ratio(x, nu)


def _lambda(nu: torch.Tensor) -> torch.Tensor:
    """Smith's Λ(ν) = φ(ν)/ν − Φ(−ν), ν = μ/σ."""
    return normal_pdf(nu) / nu - normal_cdf(-nu)


def _gl(n: int, lo: float, hi: float) -> tuple[torch.Tensor, torch.Tensor]:
    x, w = np.polynomial.legendre.leggauss(n)
    x = 0.5 * (hi + lo) + 0.5 * (hi - lo) * x
    return torch.as_tensor(x, dtype=torch.float64), torch.as_tensor(0.5 * (hi - lo) * w, dtype=torch.float64)


def _l_rule() -> tuple[torch.Tensor, torch.Tensor]:
    """Nodes and weights in l: Gauss–Legendre in ln l on [1e-5, 0.5], then on [0.5, 2] and [2, 5]."""
    y, wy = _gl(64, math.log(1e-5), math.log(0.5))
    l1, w1 = torch.exp(y), wy * torch.exp(y)
    l2, w2 = _gl(24, 0.5, 2.0)
    l3, w3 = _gl(24, 2.0, _L_TAIL)
    return torch.cat([l1, l2, l3]), torch.cat([w1, w2, w3])


def _exponent(xi0: torch.Tensor, g0: torch.Tensor, mu: torch.Tensor, lam: torch.Tensor) -> torch.Tensor:
    """∫₀^∞ g dl for origins (ξ₀, γ₀) (broadcast), the line of sight's slope μ (units σ_h = L = 1)."""
    l, wl = _l_rule()
    e = torch.exp(-l * l)
    R, R1, R2 = e, -2.0 * l * e, (4.0 * l * l - 2.0) * e
    y = 2.0 * l * l
    v_xi = -torch.expm1(-y) - y * torch.exp(-y)
    v_ga = 2.0 - R1 * R1 - 0.5 * R2 * R2
    c = -R * R1 - 0.5 * R1 * R2
    xi0, g0, mu = xi0[..., None], g0[..., None], mu[..., None]
    z = xi0 + mu * l
    m_xi = R * xi0 - 0.5 * R1 * g0
    m_ga = R1 * xi0 - 0.5 * R2 * g0
    sd = torch.sqrt(v_xi)
    zs = (z - m_xi) / sd
    d = m_ga + c / v_xi * (z - m_xi) - mu
    s = torch.sqrt((v_ga - c * c / v_xi).clamp_min(1e-300))
    excess = s * normal_pdf(d / s) + d * normal_cdf(d / s)
    rate = normal_pdf(zs) / sd * excess / normal_cdf(zs).clamp_min(1e-300)
    inner = (rate * wl).sum(-1)
    tail = -lam[..., 0] * torch.special.log_ndtr(xi0[..., 0] + mu[..., 0] * _L_TAIL)
    return inner + tail


TABLE_FILE = Path(__file__).resolve().parent / "data" / "masking" / "masking_table.npz"


def table_nodes() -> tuple[torch.Tensor, torch.Tensor]:
    """(p nodes, ln ν nodes) of the table, float64: p = √(x + ν) on [0, √W_MAX], ln ν on [ln NU_MIN, ln NU_MAX]."""
    return (torch.linspace(0.0, math.sqrt(W_MAX), _N_P, dtype=torch.float64),
            torch.linspace(math.log(NU_MIN), math.log(NU_MAX), _N_NU, dtype=torch.float64))


@lru_cache(maxsize=1)
def masking_table() -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
    """(p nodes, ln ν nodes, Q[p, ν]) in float64 on the CPU, p = √(x + ν): the table shipped in
    ``data/masking/masking_table.npz`` (written by ``pipelines/make_masking_table.py`` from
    :func:`compute_masking_table`), or computed here (~10 s) if that file is missing or was made on other
    nodes."""
    p, ln_nu = table_nodes()
    if TABLE_FILE.is_file():
        with np.load(TABLE_FILE) as f:
            if (f["p"].shape == p.shape and f["ln_nu"].shape == ln_nu.shape and np.array_equal(f["p"], p.numpy())
                    and np.array_equal(f["ln_nu"], ln_nu.numpy())):
                return p, ln_nu, torch.from_numpy(f["q"].copy())
    return compute_masking_table()


def compute_masking_table(rows: Any = None) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
    """(p nodes, ln ν nodes, Q[p, ν]) computed from the module docstring's integrals (float64, CPU, ~10 s);
    ``rows``: only these indices of the ν nodes (Q then holds those columns), e.g. to check the shipped table."""
    p, ln_nu = table_nodes()
    xi0, wxi = _gl(96, -8.5, 8.5)
    wxi = wxi * normal_pdf(xi0)
    nu = torch.exp(ln_nu)
    lam = _lambda(nu)
    mu = nu * _SIGMA
    out = []
    for j in (range(_N_NU) if rows is None else rows):
        w = p * p
        g0 = -(w.clamp_min(W_MIN) - nu[j]) * _SIGMA  # γ₀ = −σ x, x = w − ν; held below W_MIN
        ex = _exponent(xi0[None, :], g0[:, None], mu[j].expand(1, 1), lam[j].expand(1, 1, 1))
        s = (torch.exp(-ex) * wxi).sum(-1)
        out.append(s * (1.0 + lam[j]))
    return p, ln_nu, torch.stack(out, dim=1)


def masking_ratio(x: torch.Tensor, nu: torch.Tensor) -> torch.Tensor:
    """Q(x, ν) = S(x, ν)(1 + Λ(ν)) of the module docstring, interpolated bilinearly in (√(x + ν), ln ν);
    0 where x ≤ −ν (facets turned away). Broadcasts; dtype and device of ``x``; differentiable."""
    p_nodes, q_nodes, table = masking_table()
    tab = table.to(dtype=x.dtype, device=x.device)
    w = x + nu
    visible = w > 0
    p = torch.sqrt(torch.where(visible, w, torch.ones_like(w)).clamp(max=W_MAX))
    p = torch.where(visible, p, torch.zeros_like(p))
    q = torch.log(nu.clamp(NU_MIN, NU_MAX))
    hp = float(p_nodes[1] - p_nodes[0])
    hq = float(q_nodes[1] - q_nodes[0])
    fp = (p / hp).clamp(0.0, _N_P - 1)
    fq = ((q - float(q_nodes[0])) / hq).clamp(0.0, _N_NU - 1)
    ip = fp.detach().floor().long().clamp(0, _N_P - 2)  # the last cell holds its upper edge (weight 1)
    iq = fq.detach().floor().long().clamp(0, _N_NU - 2)
    ap, aq = fp - ip, fq - iq
    ip, iq, ap, aq = torch.broadcast_tensors(ip, iq, ap, aq)
    t00, t10 = tab[ip, iq], tab[ip + 1, iq]
    t01, t11 = tab[ip, iq + 1], tab[ip + 1, iq + 1]
    val = (1 - ap) * ((1 - aq) * t00 + aq * t01) + ap * ((1 - aq) * t10 + aq * t11)
    return torch.where(visible, val, torch.zeros_like(val))


def view_nu(g: FacetGeometry) -> torch.Tensor:
    """ν = e / a = (cos θ̂ + sin θ̂ m∥) / (sin θ̂ σ∥), floored where a = 0 (huge: no masking)."""
    a = g.st * g.su
    e = g.ct + g.st * g.mu
    return e / a.clamp_min(torch.finfo(a.dtype).tiny)


def masked_denominator(g: FacetGeometry, nodes: int, width: float, shadowing: str = "correlated") -> torch.Tensor:
    """D_Q = ∫ N t Q H(t) ds = ∫_{−ν}^{K} φ(x)(e + a x) Q(x, ν) dx by Gauss–Legendre (``nodes``,
    window ``width`` = K standard deviations), e = cos θ̂ + sin θ̂ m∥, a = sin θ̂ σ∥, Q of ``shadowing``
    (:func:`facet_masking`; "multiscale": D_Q = e⁺ exactly, here on the numerators' own nodes so that
    their quadrature errors cancel in the ratio)."""
    a = g.st * g.su
    e = g.ct + g.st * g.mu
    nu = view_nu(g)
    K = float(width)
    xs = (-nu).clamp(-K, K)
    xg, wg = np.polynomial.legendre.leggauss(nodes)
    xg = torch.as_tensor(xg, dtype=a.dtype, device=a.device)
    wg = torch.as_tensor(wg, dtype=a.dtype, device=a.device)
    half = 0.5 * (K - xs)
    x = (0.5 * (K + xs))[..., None] + half[..., None] * xg
    t = e[..., None] + a[..., None] * x
    return (half[..., None] * wg * normal_pdf(x) * t * facet_masking(shadowing, x, nu[..., None])).sum(-1)

"""Gaussian wave-slope statistics (paper Eq. 1, A7/A8) and the Cox–Munk wind laws (Eq. 12).

Convention (``docs/physics.md`` §2): slope axes x_s = upwind, y_s = crosswind (x_s rotated by
+90°). Slope components (s_x, s_y) = tan θ (cos φ, sin φ) ~ N(0, Σ) with
Σ = [[a², r a b], [r a b, b²]]; a, b are the upwind/crosswind rms slopes, r their correlation.

Internally the statistics are held as the variances and the covariance (a², b², r a b). The model
depends smoothly on Σ, while a = √(a²) is not differentiable at a = 0 (anisotropic Cox–Munk at
zero wind has a = 0): keeping Σ keeps gradients with respect to wind speed finite there.
"""

from __future__ import annotations

import math
import warnings
from typing import Any

import torch

from ._validation import as_tensor, check_finite_range, resolve_dtype_device

__all__ = ["SlopeStatistics", "slope_pdf", "MAX_WIND_SPEED"]

# [m s⁻¹] The one range of wind speeds the package accepts, [0, 80] (SlopeStatistics.cox_munk, SeaScene,
# WaveField, the augmentations' draws). The laws are fitted over less: Cox & Munk (1954) measured up to
# ~14 m/s, Elfouhaily et al.'s spectrum (1997) is fitted to ~20 m/s, Monahan & O'Muircheartaigh's whitecap
# law (1980) to ~20–25 m/s; above that the package extrapolates them (a hurricane's 80 m/s is the bound
# where the Cox–Munk rms slope, 0.64, still describes a surface of slopes). Winds below 0 or NaN are errors.
MAX_WIND_SPEED = 80.0

Number = float | int


class SlopeStatistics:
    """Gaussian slope statistics of the sea surface (zero mean unless :meth:`shifted`).

    Args:
        std_upwind: a, rms slope along the upwind axis [dimensionless, ≥ 0]; float or tensor.
        std_crosswind: b, rms slope along the crosswind axis [dimensionless, ≥ 0].
        corr: r, correlation of the two slope components [dimensionless, |r| < 1].

    Values may be floats or tensors of any broadcastable shape (one value per sea state);
    gradients flow to tensor inputs. Build from a wind speed with :meth:`cox_munk`.

    Example:
        >>> s = SlopeStatistics.cox_munk(10.0)
        >>> round(float(s.mean_square_slope), 4)
        0.0542
    """

    def __init__(self, std_upwind: Any, std_crosswind: Any, corr: Any = 0.0):
        check_finite_range("std_upwind", std_upwind, 0.0)
        check_finite_range("std_crosswind", std_crosswind, 0.0)
        check_finite_range("corr", corr, -1.0, 1.0, lo_open=True, hi_open=True)
        self._init_variances(
            _square(std_upwind), _square(std_crosswind), _mul3(corr, std_upwind, std_crosswind)
        )

    def _init_variances(self, var_upwind: Any, var_crosswind: Any, cov: Any) -> None:
        self.var_upwind = var_upwind
        self.var_crosswind = var_crosswind
        self.cov = cov
        self.mean_upwind: Any = 0.0
        self.mean_crosswind: Any = 0.0

    def shifted(self, mean_upwind: Any, mean_crosswind: Any = 0.0) -> SlopeStatistics:
        """The same covariance about a non-zero mean slope μ = (μ_up, μ_cross) [dimensionless].

        The two-scale sea (``docs/texture.md`` §5): under a resolved wave that tilts the surface by
        μ, the unresolved slopes are N(s; μ, Σ_u) in the world (upwind, crosswind) frame, while the
        sky stays in the world frame. Every function of the model accepts such statistics (the
        facet weight of Eq. 5 and its denominator D are taken over the shifted density).
        """
        check_finite_range("mean_upwind", mean_upwind)
        check_finite_range("mean_crosswind", mean_crosswind)
        obj = SlopeStatistics.__new__(SlopeStatistics)
        obj._init_variances(self.var_upwind, self.var_crosswind, self.cov)
        obj.mean_upwind, obj.mean_crosswind = mean_upwind, mean_crosswind
        return obj

    @property
    def has_mean(self) -> bool:
        return any(isinstance(m, torch.Tensor) or m != 0.0 for m in (self.mean_upwind, self.mean_crosswind))

    @classmethod
    def from_variances(cls, var_upwind: Any, var_crosswind: Any, cov: Any = 0.0) -> SlopeStatistics:
        """Build from a², b² and the covariance r a b (the form the model uses internally)."""
        check_finite_range("var_upwind", var_upwind, 0.0)
        check_finite_range("var_crosswind", var_crosswind, 0.0)
        check_finite_range("cov", cov)
        obj = cls.__new__(cls)
        obj._init_variances(var_upwind, var_crosswind, cov)
        det = _values(var_upwind) * _values(var_crosswind) - _values(cov) ** 2
        if (det < 0).any():
            raise ValueError("cov: the covariance must satisfy cov² ≤ var_upwind · var_crosswind")
        return obj

    @classmethod
    def isotropic(cls, mean_square_slope: Any) -> SlopeStatistics:
        """Isotropic slopes with total mean-square slope σ² = a² + b² (a² = b² = σ²/2)."""
        check_finite_range("mean_square_slope", mean_square_slope, 0.0)
        half = mean_square_slope * 0.5
        return cls.from_variances(half, half, 0.0)

    @classmethod
    def cox_munk(cls, wind_speed: Any, anisotropic: bool = False) -> SlopeStatistics:
        """Cox & Munk (1954) clean-surface slope laws for a wind speed W [m s⁻¹] at 12.5 m.

        - isotropic (the paper's Eq. 12): σ² = 0.003 + 5.12·10⁻³ W, a² = b² = σ²/2;
        - anisotropic: upwind a² = 3.16·10⁻³ W, crosswind b² = 0.003 + 1.92·10⁻³ W, r = 0.

        W = 0 is not a flat sea (σ² = 0.003); a flat sea is ``SlopeStatistics(0, 0)``. The anisotropic
        law's upwind variance vanishes at W = 0, and the rms slope along a view near the wind axis with it
        as √W: asking for autograd's wind gradient there (a ``wind_speed`` tensor that requires grad,
        with a 0) warns, as it comes back finite but is not the derivative
        (``docs/gradient_accuracy.md``). W in [0, :data:`MAX_WIND_SPEED`] (a ``ValueError``
        otherwise); the laws are measured up to ~14 m/s and extrapolated above.
        """
        check_finite_range("wind_speed", wind_speed, 0.0, MAX_WIND_SPEED, unit="m/s")
        if (anisotropic and isinstance(wind_speed, torch.Tensor) and wind_speed.requires_grad and torch.is_grad_enabled()
                and bool((wind_speed.detach() == 0).any())):
            warnings.warn("SlopeStatistics.cox_munk(anisotropic=True): at wind_speed = 0 the upwind slope variance "
                          "3.16e-3 W vanishes and the rms slope along a view varies as sqrt(W) near the wind axis, "
                          "where R_a has no derivative in the wind for autograd to follow: the gradient comes back "
                          "finite but is not the derivative (0 along the wind axis where a one-sided finite "
                          "difference gives several K per m/s; up to ~1e3 K per m/s off by the table method). "
                          "Differentiate at W >= ~0.1 m/s, or take a one-sided finite difference.", stacklevel=2)
        if anisotropic:
            return cls.from_variances(3.16e-3 * wind_speed, 0.003 + 1.92e-3 * wind_speed, 0.0)
        return cls.isotropic(0.003 + 5.12e-3 * wind_speed)

    # -- derived quantities -------------------------------------------------------------------
    @property
    def std_upwind(self) -> Any:
        return _sqrt(self.var_upwind)

    @property
    def std_crosswind(self) -> Any:
        return _sqrt(self.var_crosswind)

    @property
    def corr(self) -> Any:
        denom = _sqrt(self.var_upwind * self.var_crosswind)
        if isinstance(denom, torch.Tensor):
            return torch.where(denom > 0, self.cov / torch.where(denom > 0, denom, 1.0), 0.0)
        return self.cov / denom if denom > 0 else 0.0

    @property
    def mean_square_slope(self) -> Any:
        """Total mean-square slope σ² = a² + b² [dimensionless]."""
        return self.var_upwind + self.var_crosswind

    def tensors(
        self, dtype: torch.dtype, device: torch.device
    ) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
        """(a², b², r a b) as tensors of ``dtype`` on ``device``."""
        return (
            as_tensor(self.var_upwind, dtype, device),
            as_tensor(self.var_crosswind, dtype, device),
            as_tensor(self.cov, dtype, device),
        )

    def mean_tensors(self, dtype: torch.dtype, device: torch.device) -> tuple[torch.Tensor, torch.Tensor]:
        """(μ_up, μ_cross) as tensors of ``dtype`` on ``device`` (zeros for zero-mean statistics)."""
        return as_tensor(self.mean_upwind, dtype, device), as_tensor(self.mean_crosswind, dtype, device)

    def parameters_dict(self) -> dict[str, Any]:
        d = {"var_upwind": self.var_upwind, "var_crosswind": self.var_crosswind, "cov": self.cov}
        if self.has_mean:
            d.update(mean_upwind=self.mean_upwind, mean_crosswind=self.mean_crosswind)
        return d

    def __repr__(self) -> str:
        def fmt(x: Any) -> str:
            if isinstance(x, torch.Tensor):
                return f"tensor{tuple(x.shape)}" if x.numel() > 1 else f"{x.item():.4g}"
            return f"{float(x):.4g}"

        return (
            f"SlopeStatistics(var_upwind={fmt(self.var_upwind)}, "
            f"var_crosswind={fmt(self.var_crosswind)}, cov={fmt(self.cov)}"
            + (f", mean=({fmt(self.mean_upwind)}, {fmt(self.mean_crosswind)}))" if self.has_mean else ")")
        )


def _values(x: Any) -> torch.Tensor:
    return x.detach().double() if isinstance(x, torch.Tensor) else torch.as_tensor(x, dtype=torch.float64)


def _square(x: Any) -> Any:
    return x * x


def _mul3(a: Any, b: Any, c: Any) -> Any:
    return a * b * c


def _sqrt(x: Any) -> Any:
    return torch.sqrt(x) if isinstance(x, torch.Tensor) else math.sqrt(x)


def slope_pdf(theta: Any, phi: Any, slopes: SlopeStatistics) -> torch.Tensor:
    """Density p(θ, φ) of facet-normal directions, paper Eq. A7/A8 (Eq. 1 when r = 0) [rad⁻²].

    Args:
        theta: facet-normal zenith angle θ [rad], in [0, π/2).
        phi: facet-normal azimuth φ from the upwind axis [rad].
        slopes: the slope statistics.

    Notes:
        p(θ, φ) = sec²θ tanθ · N(s; 0, Σ) with s = tanθ (cos φ, sin φ): the bivariate normal of the
        slopes times the Jacobian of (s_x, s_y) → (θ, φ). In this form the exponent is
        −½ tan²θ (b² cos²φ + a² sin²φ − 2 r a b cos φ sin φ) / det Σ, which is A8 divided by
        (1 − r²), i.e. the paper's Eq. A7. Shifted statistics use N(s; μ, Σ).
    """
    dtype, device = resolve_dtype_device(theta=theta, phi=phi, **slopes.parameters_dict())
    th = as_tensor(theta, dtype, device)
    ph = as_tensor(phi, dtype, device)
    vx, vy, cxy = slopes.tensors(dtype, device)
    mx, my = slopes.mean_tensors(dtype, device)
    det = vx * vy - cxy * cxy
    tan_t = torch.tan(th)
    sx, sy = tan_t * torch.cos(ph) - mx, tan_t * torch.sin(ph) - my  # s − μ
    quad = (vy * sx * sx + vx * sy * sy - 2.0 * cxy * sx * sy) / det
    jac = tan_t / torch.cos(th) ** 2
    return jac * torch.exp(-0.5 * quad) / (2.0 * math.pi * torch.sqrt(det))

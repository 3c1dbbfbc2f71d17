"""Per-pixel sensitivities of rendered images to scalar scene or camera parameters."""

from __future__ import annotations

import torch

__all__ = ["pixel_derivative"]


def pixel_derivative(images: torch.Tensor, parameter: torch.Tensor) -> torch.Tensor:
    """d images / d parameter, per pixel, for a scalar (or per-image (B,)) parameter.

    A Jacobian–vector product by the double-backward trick: with g(u) = Jᵀu (one reverse pass with
    a dummy cotangent u, keeping the graph), J v = ∂⟨g(u), v⟩/∂u. Forward-mode AD would be the
    direct route, but ``grid_sample`` has no forward-mode derivative in torch.

    Args:
        images: output of a differentiable computation, e.g. ``render(...)`` (B, 1, H, W).
        parameter: the tensor it was computed from (``requires_grad=True``), shape () or (B,)
            with one value per image (then each image's map is its own parameter's derivative).

    Returns:
        tensor of the shape of ``images`` [image units per parameter unit].

    Accuracy: the derivative of what was rendered, so of the method's own error too. Measured against
    a float64 finite difference of per-pixel evaluation (``pipelines/gradient_accuracy.py``,
    ``docs/gradient_accuracy.md``; the README's 48×64 scene, errors relative to the image's largest
    derivative): ``render(..., method="direct")`` in float64 to ~2e-7 (wind), 1e-10 (sea temperature,
    pitch); the table method (the default) in float64 to 5e-4 (wind), 1e-6 (sea temperature), 2.5e-3
    (pitch, at the horizon rows; 3e-6 median); in float32 to 7e-3 (wind), 3e-6 (sea temperature), 8e-3
    (pitch). For derivatives finer than the table's, render with ``method="direct"`` in float64.
    At ``wind_speed = 0`` the anisotropic slope law is not differentiable (a warning says so; see
    :meth:`~roughsea_torch.slopes.SlopeStatistics.cox_munk`).

    Example:
        >>> w = torch.tensor(3.0, requires_grad=True)
        >>> y = torch.stack([w ** 2, 3 * w])
        >>> pixel_derivative(y, w).tolist()
        [6.0, 3.0]
    """
    if not parameter.requires_grad:
        raise ValueError("parameter must require grad and be an input of the computation of images")
    u = torch.zeros_like(images, requires_grad=True)
    (g,) = torch.autograd.grad(images, parameter, grad_outputs=u, create_graph=True, allow_unused=True)
    if g is None:
        return torch.zeros_like(images)
    (jv,) = torch.autograd.grad(g, u, grad_outputs=torch.ones_like(g), allow_unused=True)
    return torch.zeros_like(images) if jv is None else jv

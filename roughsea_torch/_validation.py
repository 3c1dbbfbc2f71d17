"""Input checks shared by the torch modules: dtype/device resolution and named range errors.

Every public function validates its inputs here so that bad input raises a ``ValueError`` that
names the argument and the allowed range instead of propagating a silent NaN.
"""

from __future__ import annotations

import math
from numbers import Number
from typing import Any

import numpy as np
import torch

__all__ = ["resolve_dtype_device", "as_tensor", "check_finite_range", "check_same_device", "per_batch"]


def _tensors(items: dict[str, Any]) -> dict[str, torch.Tensor]:
    return {name: v for name, v in items.items() if isinstance(v, torch.Tensor)}


def check_same_device(**items: Any) -> torch.device | None:
    """Return the common device of the tensor arguments; ``ValueError`` naming them if they differ."""
    tensors = _tensors(items)
    devices = {name: t.device for name, t in tensors.items()}
    unique = set(devices.values())
    if len(unique) > 1:
        listing = ", ".join(f"{name} on {dev}" for name, dev in devices.items())
        raise ValueError(f"mismatched devices: {listing}; move all tensor arguments to one device")
    return next(iter(unique)) if unique else None


def _float_dtype(d: Any) -> torch.dtype | None:
    """The real floating torch dtype a tensor/numpy dtype stands for (complex → its real part);
    None for integer and boolean dtypes, which do not promote."""
    if isinstance(d, np.dtype):
        if d.kind == "c":
            return torch.float64 if d.itemsize >= 16 else torch.float32
        if d.kind != "f":
            return None
        return {2: torch.float16, 4: torch.float32}.get(d.itemsize, torch.float64)
    if d.is_complex:
        return torch.float64 if d == torch.complex128 else torch.float32
    return d if d.is_floating_point else None


def resolve_dtype_device(**items: Any) -> tuple[torch.dtype, torch.device]:
    """Working dtype and device of a call.

    The dtype is the promotion of the floating (or complex, taken as its real part) tensor and
    numpy-array arguments: a numpy float64 array gives float64, a float32 array float32, as a
    tensor would. Numpy scalars (``np.float64(0.3)``) behave as in torch's own type promotion:
    beside a tensor or array they do not promote (like Python numbers); alone they give their
    dtype, as ``torch.as_tensor`` would. Python numbers never promote. Without any of these the
    default dtype (``torch.get_default_dtype()``) is used. Devices must agree.
    """
    device = check_same_device(**items)
    strong: torch.dtype | None = None
    weak: torch.dtype | None = None
    for v in items.values():
        if isinstance(v, torch.Tensor):
            d = _float_dtype(v.dtype)
        elif isinstance(v, np.ndarray):
            d = _float_dtype(v.dtype)
        elif isinstance(v, np.generic):
            d = _float_dtype(v.dtype)
            if d is not None:
                weak = d if weak is None else torch.promote_types(weak, d)
            continue
        else:
            continue
        if d is not None:
            strong = d if strong is None else torch.promote_types(strong, d)
    dtype = strong if strong is not None else weak
    if dtype is None:
        dtype = torch.get_default_dtype()
    if dtype not in (torch.float32, torch.float64):
        raise ValueError(f"unsupported dtype {dtype}: use torch.float32 or torch.float64")
    return dtype, device if device is not None else torch.device("cpu")


def as_tensor(x: Any, dtype: torch.dtype, device: torch.device) -> torch.Tensor:
    """Tensor of ``dtype`` on ``device`` (keeps the autograd graph of tensor inputs)."""
    if isinstance(x, torch.Tensor):
        return x.to(dtype=dtype, device=device)
    return torch.as_tensor(x, dtype=dtype, device=device)


def per_batch(name: str, x: Any, n: int, dtype: torch.dtype, device: torch.device | None) -> torch.Tensor:
    """A float or a tensor of shape () or (n,) as a tensor of shape (n,): one value per image."""
    if isinstance(x, torch.Tensor):
        t = x.to(dtype=dtype, device=device)
    elif isinstance(x, np.ndarray):  # a numpy (B,) array is one value per image, as a tensor is
        t = torch.as_tensor(x, dtype=dtype, device=device)
    else:
        t = torch.tensor(float(x), dtype=dtype, device=device)
    if t.ndim == 0:
        return t.expand(n)
    if t.shape != (n,):
        raise ValueError(f"{name}: must be a float or a tensor of shape (B,) = ({n},); got {tuple(t.shape)}")
    return t


def _values(x: Any) -> torch.Tensor:
    if isinstance(x, torch.Tensor):
        return x.detach()
    if isinstance(x, np.ndarray) and np.iscomplexobj(x):  # keep the imaginary part for the check below
        return torch.as_tensor(x)
    return torch.as_tensor(x, dtype=torch.float64)


def check_finite_range(
    name: str,
    x: Any,
    lo: float = -math.inf,
    hi: float = math.inf,
    *,
    lo_open: bool = False,
    hi_open: bool = False,
    unit: str = "",
) -> None:
    """Raise ``ValueError`` naming ``name`` unless every value is a number in the given range."""
    if x is None:
        raise ValueError(f"{name} is required")
    if isinstance(x, Number) and not isinstance(x, (bool, complex)):
        vals = torch.tensor([float(x)], dtype=torch.float64)
    else:
        try:
            vals = _values(x)
        except (TypeError, ValueError, RuntimeError):  # a string, a ragged list, a complex number ...
            raise ValueError(f"{name} must be a real number or a tensor of real numbers; got {repr(x)[:80]}") from None
    if vals.is_complex():
        raise ValueError(f"{name} must be real, got a complex value")
    if vals.numel() == 0:
        return
    bad_nan = torch.isnan(vals).any().item()
    below = (vals <= lo) if lo_open else (vals < lo)
    above = (vals >= hi) if hi_open else (vals > hi)
    if bad_nan or below.any().item() or above.any().item():
        left = "(" if lo_open else "["
        right = ")" if hi_open else "]"
        worst = vals[torch.isnan(vals) | below | above].flatten()[0].item()
        suffix = f" {unit}" if unit else ""
        raise ValueError(
            f"{name} must lie in {left}{lo:g}, {hi:g}{right}{suffix} and not be NaN; got {worst!r}"
        )

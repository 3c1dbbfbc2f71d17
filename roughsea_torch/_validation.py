"""Input checks shared by the torch modules: dtype/device resolution, named range errors, seed parsing.

Every public function validates its inputs here so that bad input raises a ``ValueError`` that
names the argument and the allowed range instead of propagating a silent NaN.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from numbers import Integral, Number
from typing import Any

import numpy as np
import torch

__all__ = [
    "resolve_dtype_device",
    "as_tensor",
    "check_finite_range",
    "check_same_device",
    "per_batch",
    "ParsedSeeds",
    "parse_seeds",
]


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


@dataclass(frozen=True)
class ParsedSeeds:
    """Seeds parsed by :func:`parse_seeds`: the values, and whether one int was given (a batch of 1)."""

    values: tuple[int, ...]
    single: bool


def parse_seeds(seed: Any) -> ParsedSeeds:
    """The random seeds of a batch of wave fields: an int (a batch of 1; numpy integers and 0-D integer
    tensors/arrays count as one), or a sequence / 1-D integer tensor or array of B ints, each in
    [0, 2**63). ``ValueError`` naming ``seed`` otherwise."""
    if isinstance(seed, bool):
        raise ValueError("seed must be an int or a sequence / 1-D integer tensor of B ints; got a bool")
    if isinstance(seed, Integral):  # Python and numpy integers (np.int64 from a shard)
        values, single = [int(seed)], True
    elif isinstance(seed, torch.Tensor):
        if seed.dtype.is_floating_point or seed.dtype.is_complex or seed.dtype == torch.bool or seed.ndim > 1:
            raise ValueError(
                f"seed: a tensor of seeds must be 0-D or 1-D with an integer dtype; got {seed.dtype} of shape {tuple(seed.shape)}"
            )
        values, single = ([int(seed)], True) if seed.ndim == 0 else ([int(v) for v in seed.tolist()], False)
    elif isinstance(seed, np.ndarray) and seed.ndim == 0:  # a 0-D array is one seed, as a numpy integer
        return parse_seeds(seed[()])
    elif isinstance(seed, (Sequence, np.ndarray)) and not isinstance(seed, (str, bytes)):
        if isinstance(seed, np.ndarray) and seed.ndim != 1:
            raise ValueError(f"seed: an array of seeds must be 1-D (one per image); got shape {seed.shape}")
        items = seed.tolist() if isinstance(seed, np.ndarray) else list(seed)
        values = []
        for v in items:
            if isinstance(v, bool) or not isinstance(v, Integral):
                raise ValueError(f"seed: every seed must be an int; got {v!r}")
            values.append(int(v))
        single = False
    else:
        raise ValueError(f"seed must be an int or a sequence / 1-D integer tensor of B ints; got {type(seed).__name__}")
    if not values:
        raise ValueError("seed: need at least one seed (B ≥ 1)")
    for v in values:
        if not 0 <= v < 2**63:
            raise ValueError(f"seed: each seed must lie in [0, 2**63); got {v}")
    return ParsedSeeds(tuple(values), single)

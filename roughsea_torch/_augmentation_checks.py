"""The checks of the random-sea augmentations' inputs, replayed draws and output settings.

Each raises ``ValueError`` naming what is wrong, before any rendering: :func:`check_input` the
input tensor, :func:`check_params` a draw (one just made or one replayed from ``_params``) against
the batch, :func:`check_output_settings` the settings that decide the output's unit.
"""

from __future__ import annotations

from typing import Any, Sequence

import torch

from .sampling import MOTION_FIELD_NAMES, RENDER_FIELD_NAMES
from .waves import check_time

__all__ = ["check_input", "check_params", "check_output_settings", "check_composite_gate", "REQUIRED_PARAMS", "PER_IMAGE_PARAMS"]

# the per-image fields a draw may hold, each a tensor (B,); the first ones are always there (the air-sea
# difference, a record of T_air - T_sea that the render does not use, is not required of a replayed draw)
REQUIRED_PARAMS = (*RENDER_FIELD_NAMES, "atmosphere", "noise_seed")
PER_IMAGE_PARAMS = (*REQUIRED_PARAMS, "air_sea_difference", "wave_seed", "time_s", *MOTION_FIELD_NAMES, "phase_rad", "is_day",
                    "sun_elevation_deg", "sun_azimuth_deg")


def check_input(input: Any, mode: str) -> None:
    """``ValueError`` for an input dtype that cannot carry the result, or (composite mode) an
    opacity outside [0, 1]."""
    if not isinstance(input, torch.Tensor):
        raise ValueError(f"input must be a torch.Tensor; got {type(input).__name__}")
    if input.dtype not in (torch.float32, torch.float64):
        raise ValueError(
            f"input: dtype must be torch.float32 or torch.float64; got {input.dtype}. The output has the "
            "input's dtype, and half precision cannot hold it to the sensor's resolution (float16 steps are "
            "0.25 K near 290 K, rounding by up to 0.125 K against a 0.05 K NETD, and integers above 2048, "
            "as 14-bit counts, are not exact): pass float32 and cast the output if you need it smaller"
        )
    if mode == "composite" and input.shape[-3] == 2 and input.numel():
        alpha = input.detach()[..., 1, :, :]
        lo, hi = (float(v) for v in torch.aminmax(alpha))
        if not (0.0 <= lo and hi <= 1.0):  # NaN fails too
            raise ValueError(f"alpha (input channel 1, the target's opacity) must lie in [0, 1]; got values in "
                             f"[{lo:g}, {hi:g}]")


def check_params(params: Any, B: int, atmospheres: Sequence[str], gate_sizes: tuple[int, ...]) -> None:
    """``ValueError`` naming the field of a draw (``params``, e.g. one replayed from ``_params``) that
    does not fit an input of B images (clips): every per-image field a tensor of shape (B,), the gate
    ``"batch_prob"`` of a size in ``gate_sizes``, ``atmosphere`` an integer index into
    ``atmospheres``, ``noise_seed`` and ``wave_seed`` integers (wave seeds in [0, 2**63)), ``time_s``
    finite times in [−1e9, 1e9] s (``SeaScene``'s)."""
    if not isinstance(params, dict):
        raise ValueError(f"params must be a dict of tensors (a draw, e.g. aug._params); got {type(params).__name__}")
    missing = [k for k in REQUIRED_PARAMS if k not in params]
    if missing:
        raise ValueError(f"params: missing {missing}; replay a draw of this augmentation (its _params)")
    for k in PER_IMAGE_PARAMS:
        v = params.get(k)
        if v is None:
            continue
        if not isinstance(v, torch.Tensor) or v.ndim != 1:
            shape = tuple(v.shape) if isinstance(v, torch.Tensor) else type(v).__name__
            raise ValueError(f"params[{k!r}]: must be a tensor of shape (B,) = ({B},), one value per image; got {shape}")
        if v.shape[0] != B:
            raise ValueError(f"params[{k!r}]: has {v.shape[0]} values but the input has B = {B} images; replay a "
                             f"draw on an input of the batch size it was drawn for")
    gate = params.get("batch_prob")
    if gate is not None and (not isinstance(gate, torch.Tensor) or gate.numel() not in gate_sizes):
        size = gate.numel() if isinstance(gate, torch.Tensor) else type(gate).__name__
        raise ValueError(f"params['batch_prob']: must hold {' or '.join(map(str, sorted(set(gate_sizes))))} values "
                         f"for an input of B = {B} images; got {size}")
    for k in ("atmosphere", "noise_seed", "wave_seed"):
        v = params.get(k)
        if v is not None and (v.dtype.is_floating_point or v.dtype.is_complex or v.dtype == torch.bool):
            raise ValueError(f"params[{k!r}]: must have an integer dtype (int64, as drawn); got {v.dtype}")
    atm = params["atmosphere"]
    if atm.numel() and not bool(((atm >= 0) & (atm < len(atmospheres))).all()):
        raise ValueError(f"params['atmosphere']: indices must lie in [0, {len(atmospheres) - 1}] (into atmospheres="
                         f"{list(atmospheres)}); got {atm.tolist()}")
    for k in ("noise_seed", "wave_seed"):
        if k in params and bool((params[k] < 0).any()):
            raise ValueError(f"params[{k!r}]: seeds must lie in [0, 2**63); got {params[k].tolist()}")
    if "is_day" in params:  # a day draw: the sun of each day image
        missing = [k for k in ("sun_elevation_deg", "sun_azimuth_deg") if k not in params]
        if missing:
            raise ValueError(f"params: a draw with 'is_day' needs {missing} too (the sun of its day images)")
    motion = [k for k in (*MOTION_FIELD_NAMES, "phase_rad") if k in params]
    if motion and len(motion) < len(MOTION_FIELD_NAMES) + 1:  # all of the platform's motion, or none (a still pose)
        missing = [k for k in (*MOTION_FIELD_NAMES, "phase_rad") if k not in params]
        raise ValueError(f"params: a draw with platform motion needs all of its fields; missing {missing}")
    if "time_s" in params:
        check_time("params['time_s']", params["time_s"])


def check_output_settings(mode: str, target_unit: str, sensor: Any, output: str | None,
                          generator: torch.Generator | None) -> str:
    """The output kind of these settings, or ``ValueError`` naming the bad one."""
    if mode not in ("replace", "composite"):
        raise ValueError(f"mode must be 'replace' or 'composite'; got {mode!r}")
    if target_unit not in ("temperature", "radiance"):
        raise ValueError(f"target_unit must be 'temperature' or 'radiance'; got {target_unit!r}")
    if output is None:
        output = "sensor" if sensor is not None else "radiance"
    if output not in ("radiance", "brightness_temperature", "sensor"):
        raise ValueError(f"output must be 'radiance', 'brightness_temperature' or 'sensor'; got {output!r}")
    if (output == "sensor") != (sensor is not None):
        raise ValueError("output='sensor' needs a sensor model, and a sensor model needs output='sensor'")
    if generator is not None and generator.device.type != "cpu":
        raise ValueError("generator must be a CPU torch.Generator")
    return output


def check_composite_gate(mode: str, p: float) -> None:
    """``ValueError`` naming ``p`` for a compositing augmentation that would leave some inputs out: in
    composite mode an input is a target chip (value in the target's unit, α), so a chip left out by
    the gate would come back in that unit beside composited images in the output's unit."""
    if mode == "composite" and float(p) != 1.0:
        raise ValueError(f"p must be 1 with mode='composite' (got {p!r}): an input left out would come back as its "
                         "target chip (a temperature or radiance and an opacity) among images in the output's unit; "
                         "gate the compositing yourself, or use mode='replace' with p < 1 to mix rendered seas with "
                         "your own frames")

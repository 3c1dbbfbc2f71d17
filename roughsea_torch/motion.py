"""Clips: a sensor on a moving platform over a moving sea.

A clip is the same sea realization (``SeaScene(seed=...)``) rendered at successive times, each
frame through the cameras of that time. :class:`PlatformMotion` gives the cameras of a sensor on a
mast that pitches, rolls and heaves harmonically, the first-order response of a ship or buoy to a
swell (periods of 5–15 s and amplitudes of a few degrees are typical of a ship at sea; Lewandowski,
*The Dynamics of Marine Craft*, 2004, ch. 2), so the horizon moves in the image;
:func:`render_clip` renders the frames in one call, in kornia's video layout (B, T, C, H, W).
"""

from __future__ import annotations

import copy
import math
from dataclasses import dataclass
from typing import Any, Callable, Sequence

import torch

from ._validation import check_finite_range
from .geometry import check_pose, make_camera
from .renderer import render
from .waves import check_time

__all__ = ["PlatformMotion", "render_clip"]


@dataclass(frozen=True)
class PlatformMotion:
    """A sensor on a harmonically moving mast; :meth:`cameras` gives its kornia cameras at a time.

    Args:
        height, width, hfov_deg: image size [pixels] and horizontal field of view [deg].
        altitude_m: mean height of the optical centre above the sea [m].
        pitch_deg, yaw_deg, roll_deg: the mean pose [deg] (as :func:`~roughsea_torch.make_camera`).
        pitch_amplitude_deg, roll_amplitude_deg: amplitudes of the oscillations [deg], ≥ 0.
        heave_amplitude_m: amplitude of the vertical motion [m], ≥ 0, below ``altitude_m``.
        pitch_period_s, roll_period_s, heave_period_s: their periods [s], > 0.
        phase_rad: phase offset of all three [rad] (e.g. one per platform).

    Floats or (B,) tensors (one platform per image); pitch(t) = pitch + A_p sin(2π t / T_p + φ),
    roll(t) = roll + A_r sin(2π t / T_r + φ + π/2), altitude(t) = altitude + A_h sin(2π t / T_h + φ).
    """

    height: int = 512
    width: int = 640
    hfov_deg: Any = 30.0
    altitude_m: Any = 20.0
    pitch_deg: Any = -3.0
    yaw_deg: Any = 0.0
    roll_deg: Any = 0.0
    pitch_amplitude_deg: Any = 1.0
    roll_amplitude_deg: Any = 2.0
    heave_amplitude_m: Any = 0.5
    pitch_period_s: Any = 6.0
    roll_period_s: Any = 9.0
    heave_period_s: Any = 7.0
    phase_rad: Any = 0.0

    def __post_init__(self) -> None:
        for name in ("pitch_amplitude_deg", "roll_amplitude_deg", "heave_amplitude_m"):
            check_finite_range(name, getattr(self, name), 0.0)
        for name in ("pitch_period_s", "roll_period_s", "heave_period_s"):
            check_finite_range(name, getattr(self, name), 0.0, lo_open=True, unit="s")
        check_finite_range("phase_rad", self.phase_rad, unit="rad")
        check_finite_range("height", self.height, 1.0, unit="px")
        check_finite_range("width", self.width, 1.0, unit="px")
        check_pose(self.hfov_deg, self.altitude_m, self.pitch_deg, self.yaw_deg, self.roll_deg)  # make_camera's
        low = torch.as_tensor(self.altitude_m, dtype=torch.float64) - torch.as_tensor(self.heave_amplitude_m, dtype=torch.float64)
        if bool((low <= 0).any()):
            raise ValueError("heave_amplitude_m: must stay below altitude_m (the sensor must stay above the sea)")
        # the pose ± amplitude must stay within make_camera's ranges at every time, checked here (where the
        # amplitude can be named) rather than at the first frame that leaves them
        for mean, amp, lim in (("pitch_deg", "pitch_amplitude_deg", 90.0), ("roll_deg", "roll_amplitude_deg", 180.0)):
            m = torch.as_tensor(getattr(self, mean), dtype=torch.float64)
            a = torch.as_tensor(getattr(self, amp), dtype=torch.float64)
            if bool(((m - a) < -lim).any() or ((m + a) > lim).any()):
                raise ValueError(f"{amp}: {mean} ± {amp} must stay within [{-lim:g}, {lim:g}] deg (the cameras' "
                                 f"range); got {mean} = {m.tolist()}, {amp} = {a.tolist()}")

    def pose(self, time_s: Any) -> dict[str, Any]:
        """Pitch, roll [deg] and altitude [m] at ``time_s`` [s] (float or (B,), in [−1e9, 1e9])."""
        check_time("time_s", time_s)
        t = time_s

        def osc(amp: Any, period: Any, extra: float = 0.0) -> Any:
            arg = 2.0 * math.pi * t / period + self.phase_rad + extra
            return amp * (torch.sin(arg) if isinstance(arg, torch.Tensor) else math.sin(arg))

        return dict(
            pitch_deg=self.pitch_deg + osc(self.pitch_amplitude_deg, self.pitch_period_s),
            roll_deg=self.roll_deg + osc(self.roll_amplitude_deg, self.roll_period_s, math.pi / 2),
            altitude_m=self.altitude_m + osc(self.heave_amplitude_m, self.heave_period_s),
        )

    def cameras(self, time_s: Any, batch_size: int | None = None, *, dtype: torch.dtype = torch.float32,
                device: Any = None) -> Any:
        """The kornia ``PinholeCamera`` batch at ``time_s`` [s]."""
        return make_camera(self.height, self.width, hfov_deg=self.hfov_deg, yaw_deg=self.yaw_deg,
                           batch_size=batch_size, dtype=dtype, device=device, **self.pose(time_s))


def render_clip(
    cameras: PlatformMotion | Callable[[float], Any] | Any,
    scene: Any,
    times_s: Sequence[float] | torch.Tensor,
    *,
    start_s: Any = None,
    progress: bool = False,
    **render_kwargs: Any,
) -> torch.Tensor:
    """Render a clip: the scene's sea at each time, seen by the cameras of that time.

    Args:
        cameras: a :class:`PlatformMotion`, a callable ``time_s → PinholeCamera``, or fixed
            kornia cameras (a still sensor).
        scene: a :class:`~roughsea_torch.SeaScene`; with ``seed=`` the sea moves (one realization
            advanced by the dispersion relation), without it every frame is the expectation image.
        times_s: frame times [s], T of them (e.g. ``torch.arange(T) / fps``): a number, or a
            1-D sequence / tensor of real numbers (a 2-D one is a ``ValueError``, not flattened).
            They are also the times at which ``cameras`` (a motion or callable) are posed.
        start_s: the sea's time at ``times_s`` = 0 (float or (B,), e.g. a different start per
            image): frame t shows the sea at ``start_s + times_s[t]``; default the scene's ``time_s``.
        progress: a tqdm progress bar over the frames.
        **render_kwargs: passed to :func:`~roughsea_torch.renderer.render` (``output=`` ...).

    Returns:
        (B, T, 1, H, W), kornia's video layout (``VideoSequential(data_format="BTCHW")``).

    Times: ``start_s``, ``times_s`` and every frame's ``start_s + times_s[t]`` must be finite and
    within [−1e9, 1e9] s (``roughsea_torch.waves.MAX_TIME_S``, the range ``SeaScene(time_s=)`` and
    ``WaveField.sample`` accept), else a ``ValueError`` naming the argument.
    """
    check_time("times_s", times_s)
    times = torch.as_tensor(times_s.detach() if isinstance(times_s, torch.Tensor) else times_s, dtype=torch.float64)
    if times.ndim > 1 or times.numel() == 0:
        raise ValueError(f"times_s: must be a non-empty 1-D sequence of times [s]; got shape {tuple(times.shape)}")
    times = times.reshape(-1)
    if start_s is not None:
        check_time("start_s", start_s)
    base = scene.time_s if start_s is None else start_s
    base64 = base.detach().double().cpu() if isinstance(base, torch.Tensor) else torch.as_tensor(base, dtype=torch.float64)
    check_time("start_s + times_s" if start_s is not None else "scene.time_s + times_s",
               base64.reshape(-1, 1) + times)  # every frame's time
    frames = []
    it = times.tolist()
    if progress:
        from tqdm.auto import tqdm  # an optional dependency: imported when a progress bar is asked for

        it = tqdm(it, desc="frames", unit="frame")
    for t in it:
        cams = cameras.cameras(t) if isinstance(cameras, PlatformMotion) else cameras(t) if callable(cameras) else cameras
        frame_scene = copy.copy(scene)  # shares the sky tables and the wave-field cache
        # in float64 (a float32 start of 1e6 s would round 25 Hz frames onto each other)
        frame_scene.time_s = base.to(torch.float64) + t if isinstance(base, torch.Tensor) else base + t
        frames.append(render(cams, frame_scene, **render_kwargs))
    return torch.stack(frames, 1)

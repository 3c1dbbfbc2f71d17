"""Render a :class:`~roughsea_torch.sampling.SceneSampler` draw: the deterministic half of the
random seas.

:func:`render_parameters` renders still images (B, 1, H, W) and :func:`render_clip_parameters`
clips (B, T, 1, H, W) [W m⁻² sr⁻¹] from a draw's fields; both go through :func:`render_frames`,
which groups the images by atmosphere, by textured or not and by day or night, builds each group's
:class:`~roughsea_torch.renderer.SeaScene` once and renders it frame by frame. A draw rendered again
gives the same images bit for bit (what replaying an augmentation's ``_params`` and re-rendering a
dataset item from its metadata rely on).

Units: as :mod:`roughsea_torch.sampling` (angles in degrees, altitude in m, times in s); the
scenes take radians, converted here; radiance in W m⁻² sr⁻¹ in the scene's band.

Calm seas: an image with ``wind_speed`` ≤ :data:`CALM_WIND_SPEED` has no resolved waves; it is
rendered as the expectation image even when its draw holds a wave seed.
"""

from __future__ import annotations

import copy
import math
from dataclasses import dataclass
from typing import Any, Sequence

import torch

from ._parallel import map_chunks, one_thread
from .expectation import Quadrature
from .geometry import EARTH_RADIUS_M, make_camera
from .radiometry import LWIR, SpectralBand, as_band
from .renderer import SeaScene, TableSize, check_foam, images_per_chunk, render
from .sampling import frame_parameters

__all__ = ["render_parameters", "render_clip_parameters", "render_frames", "CALM_WIND_SPEED"]

# at and below this wind speed [m/s] an image is rendered as the expectation even with texture on
CALM_WIND_SPEED = 0.0


@dataclass(frozen=True)
class _FrameJob:
    """One render of :func:`render_frames`: frame ``frame`` of the images ``images`` of a group."""

    images: torch.Tensor  # (N,) int64 indices into the batch
    frame: int
    camera: dict[str, Any]  # make_camera's field of view and pose, (N,) each
    scene: SeaScene  # the group's scene at the frame's time
    one_chunk: bool  # the render is one chunk of the renderer (then several may run side by side)


def _take(src: dict[str, torch.Tensor], name: str, idx: torch.Tensor, dtype: torch.dtype,
          device: torch.device) -> torch.Tensor:
    """Field ``name`` of the images ``idx``, in the render's dtype and device."""
    return src[name][idx.to(src[name].device)].to(dtype=dtype, device=device)


def _groups(params: dict[str, torch.Tensor], B: int) -> list[tuple[torch.Tensor, int, bool, bool]]:
    """The images of a draw that share a scene: ``(indices, atmosphere index, textured, by day)`` per
    group, in the order of ``atmosphere * 4 + textured * 2 + day``. Textured: the draw has wave
    seeds and the image's wind is above :data:`CALM_WIND_SPEED`; by day: its ``is_day``."""
    atm = params["atmosphere"].cpu()
    textured = torch.zeros(B, dtype=torch.bool)
    if "wave_seed" in params:  # a textured draw; calm images have no resolved waves: the expectation
        textured = params["wind_speed"].detach().cpu() > CALM_WIND_SPEED
    day = torch.zeros(B, dtype=torch.bool)
    if "is_day" in params:  # a draw with daytime > 0: the sun in the sky of the day images
        day = params["is_day"].detach().cpu().to(torch.bool)
    key = atm * 4 + textured.to(atm.dtype) * 2 + day.to(atm.dtype)
    return [((key == k).nonzero()[:, 0], k // 4, bool((k // 2) % 2), bool(k % 2)) for k in torch.unique(key).tolist()]


def _group_scene(params: dict[str, torch.Tensor], idx: torch.Tensor, sky: str, textured: bool, sunny: bool,
                 band: SpectralBand, anisotropic: bool, path: bool, foam: Any, dtype: torch.dtype,
                 device: torch.device) -> SeaScene:
    """The scene of the images ``idx`` of one group (one atmosphere ``sky``; a wave seed each when
    ``textured``; the sun of their draw when ``sunny``)."""
    sun: dict[str, Any] = {}
    if sunny:  # zenith and world azimuth [rad], computed in float64 on the CPU, then cast
        def g(name: str) -> torch.Tensor:
            return params[name].detach().cpu().to(torch.float64)[idx]

        sun = dict(sun_zenith=((90.0 - g("sun_elevation_deg")) * (math.pi / 180.0)).to(dtype=dtype, device=device),
                   sun_azimuth=(g("sun_azimuth_deg") * (math.pi / 180.0)).to(dtype=dtype, device=device))

    def f(name: str) -> torch.Tensor:
        return _take(params, name, idx, dtype, device)

    # the scene (and below, the cameras) on one intra-op thread: their many small operations gain little
    # from a second idle core and stall beside a busy process (roughsea_torch._parallel); the renders
    # themselves are spread by render_frames
    return one_thread(lambda: SeaScene(
        # (the drawn degrees wrapped into [0, 360): the same direction, and SeaScene warns of more than a turn)
        wind_speed=f("wind_speed"), anisotropic=anisotropic,
        wind_direction=torch.remainder(f("wind_direction_deg"), 360.0) * (math.pi / 180.0),
        sea_temperature=f("sea_temperature"), air_temperature=f("air_temperature"), band=band,
        sky=sky, path=None if path else False,
        seed=[int(s) for s in params["wave_seed"][idx.to(params["wave_seed"].device)].tolist()] if textured else None,
        foam=foam, **sun,
    ), device)


def _frame_jobs(scene: SeaScene, params: dict[str, torch.Tensor], frames: dict[str, torch.Tensor], idx: torch.Tensor,
                textured: bool, dtype: torch.dtype, device: torch.device) -> list[_FrameJob]:
    """The renders of one group, a frame each: its cameras at the frame's pose and, for a textured
    sea, its scene at the frame's time (a shallow copy sharing the sky tables and wave fields)."""
    pose = {name: _take(frames, name, idx, dtype, device) for name in ("pitch_deg", "roll_deg", "altitude_m")}
    # the wave time stays float64 (TextureTable's phases ω t): float32 rounds 1e5 s to 1/128 s
    pose["time_s"] = frames["time_s"][idx.to(frames["time_s"].device)].to(dtype=torch.float64, device=device)
    cam = {name: _take(params, name, idx, dtype, device) for name in ("hfov_deg", "yaw_deg")}
    jobs = []
    for t in range(frames["time_s"].shape[1]):
        frame_scene = scene
        if textured:
            frame_scene = copy.copy(scene)  # shares the sky tables and the wave-field cache
            frame_scene.time_s = pose["time_s"][:, t]
        cam_t = dict(cam, altitude_m=pose["altitude_m"][:, t], pitch_deg=pose["pitch_deg"][:, t],
                     roll_deg=pose["roll_deg"][:, t])
        one_chunk = not textured and idx.numel() <= images_per_chunk(frame_scene)
        jobs.append(_FrameJob(idx, t, cam_t, frame_scene, one_chunk))
    return jobs


def render_frames(
    params: dict[str, torch.Tensor],
    frames: dict[str, torch.Tensor],
    height: int,
    width: int,
    atmospheres: Sequence[str],
    band: Any,
    anisotropic: bool,
    dtype: torch.dtype,
    device: Any,
    table: TableSize,
    quadrature: Quadrature | None,
    earth_radius_m: float,
    path: bool,
    foam: Any = "auto",
) -> torch.Tensor:
    """(B, T, 1, H, W) [W m⁻² sr⁻¹]: frame t of image b from the fields of ``params`` (B,), with pose
    and time from ``frames`` (B, T) (``pitch_deg``, ``roll_deg``, ``altitude_m``, ``time_s``, as
    :func:`~roughsea_torch.sampling.frame_parameters` gives them). Images are grouped by atmosphere,
    by textured or not and by day or night; a group's scene is built once and its wave fields
    reused from frame to frame. Where every render is one chunk of the renderer (expectation
    images, at most ``render.DEFAULT_CHUNK`` of them, 4) and there are several, the renders
    themselves are spread over the worker threads (:func:`~roughsea_torch._parallel.map_chunks`;
    without it each would run alone on the calling thread); no gradient may flow then, and the
    images are the same either way (the workers take the caller's CPU autocast too). ``foam`` is
    not checked here (:func:`render_parameters` checks it)."""
    B, T = frames["time_s"].shape
    # None: torch's default device, resolved here (it is per thread, and the renders may run on workers)
    device = torch.get_default_device() if device is None else torch.device(device)
    out = torch.empty(B, T, 1, height, width, dtype=dtype, device=device)
    band = as_band(band)
    jobs: list[_FrameJob] = []
    for idx, a, textured, sunny in _groups(params, B):
        scene = _group_scene(params, idx, atmospheres[a], textured, sunny, band, anisotropic, path, foam, dtype, device)
        jobs += _frame_jobs(scene, params, frames, idx, textured, dtype, device)

    def run(job: _FrameJob) -> None:
        cams = one_thread(lambda: make_camera(height, width, **job.camera, dtype=dtype, device=device), device)
        out[job.images.to(out.device), job.frame] = render(cams, job.scene, earth_radius_m=earth_radius_m, table=table,
                                                           quadrature=quadrature)

    grad = torch.is_grad_enabled() and any(isinstance(v, torch.Tensor) and v.requires_grad
                                           for v in (*params.values(), *frames.values()))
    if len(jobs) > 1 and all(job.one_chunk for job in jobs) and not grad:
        map_chunks(run, jobs, device)
    else:
        for job in jobs:
            run(job)
    return out


def render_parameters(
    params: dict[str, torch.Tensor],
    height: int,
    width: int,
    atmospheres: Sequence[str],
    *,
    band: Any = LWIR,
    anisotropic: bool = True,
    dtype: torch.dtype = torch.float32,
    device: torch.device | str | None = None,
    table: TableSize = TableSize(),
    quadrature: Quadrature | None = None,
    earth_radius_m: float = EARTH_RADIUS_M,
    path: bool = True,
    foam: Any = "auto",
) -> torch.Tensor:
    """The deterministic half: render the radiance images (B, 1, H, W) [W m⁻² sr⁻¹] that a set of
    :class:`SceneSampler` parameters describes (images sharing an atmosphere are rendered
    together; the sky and, with ``path``, the air between sea and sensor come from that
    atmosphere at each image's air temperature).

    A draw with ``"wave_seed"`` (``SceneSampler(texture=True)``) renders each image's textured sea,
    the realization of its wave seed at its ``"time_s"`` [s] (images with ``wind_speed`` ≤
    :data:`CALM_WIND_SPEED`: the expectation); without it, the expectation image. A draw with
    ``"is_day"`` (``SceneSampler(daytime=...)`` > 0) puts the sun in the sky of the images where it
    is True: ``SeaScene(sun_zenith=(90° − sun_elevation_deg), sun_azimuth=sun_azimuth_deg)`` (world
    azimuth; radians), its direct irradiance from the image's atmosphere's LOWTRAN7 table; the
    other images are by night, as without it. Motion fields, if present, are not used: a still
    image is at the mean pose. ``foam``: the scenes' whitecaps (``SeaScene(foam=)``: ``"auto"``,
    ``False`` or a fraction in [0, 1])."""
    B = int(params["wind_speed"].shape[0])
    frames = {k: params[k].detach().cpu().to(torch.float64)[:, None] for k in ("pitch_deg", "roll_deg", "altitude_m")}
    frames["time_s"] = (params["time_s"].detach().cpu().to(torch.float64) if "time_s" in params
                        else torch.zeros(B, dtype=torch.float64))[:, None]
    return render_frames(params, frames, height, width, atmospheres, band, anisotropic, dtype, device, table,
                         quadrature, earth_radius_m, path, check_foam(foam, per_image=False))[:, 0]


def render_clip_parameters(
    params: dict[str, torch.Tensor],
    num_frames: int,
    frame_rate: float,
    height: int,
    width: int,
    atmospheres: Sequence[str],
    *,
    band: Any = LWIR,
    anisotropic: bool = True,
    dtype: torch.dtype = torch.float32,
    device: torch.device | str | None = None,
    table: TableSize = TableSize(),
    quadrature: Quadrature | None = None,
    earth_radius_m: float = EARTH_RADIUS_M,
    path: bool = True,
    foam: Any = "auto",
) -> torch.Tensor:
    """Render clips (B, T, 1, H, W) [W m⁻² sr⁻¹], kornia's video layout: clip b's frame t is its
    sea at time ``time_s`` + t / ``frame_rate`` [s] seen from the pose of :func:`frame_parameters`
    (the platform's oscillations at t / ``frame_rate``). Frame t equals :func:`render_parameters`
    of the clip's fields with that frame's pose and time (up to how images are batched); ``foam`` as
    there."""
    frames = frame_parameters(params, num_frames, frame_rate)
    return render_frames(params, frames, height, width, atmospheres, band, anisotropic, dtype, device, table,
                         quadrature, earth_radius_m, path, check_foam(foam, per_image=False))

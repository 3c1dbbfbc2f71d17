"""Random sea backgrounds and clips for detector training, in ``kornia.augmentation``'s conventions.

- :class:`RandomSeaBackground` is a ``kornia.augmentation.IntensityAugmentationBase2D``: ``p``,
  ``same_on_batch``, ``keepdim``, ``aug._params`` for replay (``aug(x, params=aug._params)`` gives
  the same output bit for bit, wave texture and sensor noise included), masks/boxes/keypoints pass
  through inside ``kornia.augmentation.AugmentationSequential``. It replaces its input with a
  rendered sea, or composites the user's targets onto it (alpha compositing in radiance, so the
  contrast a target shows is the physical one), and optionally runs a sensor model
  (:mod:`roughsea_torch.sensor`). By default the sea is textured: one realization of the wave
  field per image (``SeaScene(seed=...)``), its clutter around the expectation image;
  ``texture=False`` renders the expectation image (the paper's mean, Eq. 10).
- :class:`RandomSeaClip` makes clips in kornia's video layouts ((B, T, C, H, W) or (B, C, T, H,
  W), as ``kornia.augmentation.VideoSequential``): one sea realization per clip advanced in time
  frame by frame, seen from a camera on a :class:`~roughsea_torch.motion.PlatformMotion` whose
  amplitudes and periods are drawn per clip. Frame-wise 2-D augmentations go after it in a
  ``VideoSequential``.
- :class:`RandomSeaBase` holds what the two share: their scene, rendering and output arguments
  (each with its default and its check, written once), the generator of a draw, and the stages
  after the renderer (compositing, sensor, output unit).

The parameters are drawn by :class:`SceneSampler` (:mod:`roughsea_torch.sampling`, with the field
tables :data:`SCENE_FIELDS`, :data:`MOTION_FIELDS`, :data:`SUN_FIELDS` and the per-frame fields
:func:`frame_parameters`) and rendered by :func:`render_parameters` and
:func:`render_clip_parameters` (:mod:`roughsea_torch.parameter_render`), as kornia separates
parameter generation from the transform; these names are importable from here too.

Units: temperatures in K, angles in degrees (wind direction: world azimuth of the upwind axis,
from +x towards +y; the camera's yaw in the same frame), altitude and heave in m, wind speed in
m s⁻¹ at 12.5 m, times and periods in s, frame rate in Hz, radiance in W m⁻² sr⁻¹ in the scene's
band.

Calm seas: an image with ``wind_speed`` ≤ :data:`CALM_WIND_SPEED` has no resolved waves; it is
rendered as the expectation image even with texture on (its wave seed and time are drawn and
stored, and ignored).
"""

from __future__ import annotations

import inspect
import os
from typing import Any, Callable, Sequence

import torch
from kornia.augmentation import IntensityAugmentationBase2D

from ._augmentation_checks import check_composite_gate, check_input, check_output_settings, check_params
from ._parallel import one_thread
from ._validation import check_finite_range
from .expectation import Quadrature
from .geometry import EARTH_RADIUS_M
from .parameter_render import CALM_WIND_SPEED, render_clip_parameters, render_frames, render_parameters
from .radiometry import LWIR, as_band, band_radiance, brightness_temperature
from .renderer import TableSize, check_foam
from .sampling import (  # noqa: F401  (re-exported: users import these names from here)
    DEFAULT_TIME_S,
    MOTION_FIELDS,
    SCENE_FIELDS,
    SUN_FIELDS,
    TIME_RANGE_S,
    SceneSampler,
    frame_noise_seed,
    frame_parameters,
    image_seed,
)
from .sensor import SensorModel

__all__ = [
    "SceneSampler",
    "RandomSeaBackground",
    "RandomSeaClip",
    "render_parameters",
    "render_clip_parameters",
    "frame_parameters",
    "frame_noise_seed",
    "SCENE_FIELDS",
    "MOTION_FIELDS",
    "CALM_WIND_SPEED",
    "SUN_FIELDS",
]


def _worker_stream(generator: torch.Generator, worker_id: int) -> torch.Generator:
    """A DataLoader worker's own generator: seeded by :func:`image_seed` of a number drawn from
    a copy of ``generator`` (its state as the worker received it; the original is not advanced)
    and the worker's id. Each worker gets a different stream, and the same one on every run that
    seeds ``generator`` the same way."""
    copy = torch.Generator().set_state(generator.get_state())
    base = int(torch.randint(0, 2**62, (1,), generator=copy))
    return torch.Generator().manual_seed(image_seed(base, worker_id))


class RandomSeaBase:
    """What :class:`RandomSeaBackground` and :class:`RandomSeaClip` share: their scene, rendering
    and output arguments (those of ``_set_up``, each class adding its own), the generator of a
    draw, and the stages after the renderer (compositing, sensor, output unit).

    Shared keyword arguments (every one has the same default in both classes):
        wind_speed, wind_direction_deg, sea_temperature, air_temperature, air_sea_difference,
            altitude_m, pitch_deg, roll_deg, yaw_deg, hfov_deg, atmospheres: ranges of the scene (a
            number, held fixed, or a ``(low, high)`` pair, drawn uniformly; defaults in
            :data:`SCENE_FIELDS`), see :class:`SceneSampler`. The air [K]: by default each
            atmosphere's own surface air temperature; ``air_temperature`` draws it on its own;
            ``air_sea_difference`` (T_air − T_sea [K], e.g. ``(-3.0, 1.0)``, the usual range over the
            open sea) draws it as each image's sea temperature plus a difference, so that air and
            sea stay a few kelvin apart. Not both (``ValueError``). ``params["air_sea_difference"]``
            records T_air − T_sea of every image (the render uses ``params["air_temperature"]``).
        texture: ``True`` (default): a textured sea, one realization of the wave field per image
            (``SeaScene(seed=...)``: waves longer than a pixel's footprint are geometry, the clutter
            a real camera sees at near range, around the expectation image); the wave seed
            (``params["wave_seed"]``, int64) and the time (``params["time_s"]`` [s], float64) are
            drawn after the other parameters and kept for replay. Images with ``wind_speed`` ≤
            :data:`CALM_WIND_SPEED` (a calm sea, no resolved waves) are the expectation image.
            ``False``: the expectation image (the mean over the slope statistics, Eq. 10); no wave
            seed or time is drawn, and the draws made before them (in :class:`SceneSampler`'s
            order) are the same either way. Also for a replayed draw that holds wave seeds (e.g.
            one of a textured augmentation's ``_params``): the setting wins.
        time_s: range of the realizations' times [s] (default [0, 3600)); see :class:`SceneSampler`.
        daytime: probability in [0, 1] that an image is by day (default 0.0: all by night, and no
            sun drawn). A day image has the sun in its sky at an elevation drawn from
            ``sun_elevation_deg`` (default 2–60°) and an azimuth from ``sun_azimuth_deg`` (default
            −180–180°; relative to the camera's yaw with ``sun_azimuth_relative_to_yaw``, the
            default, so 0 is straight ahead, where the glint is; else world): the glint of its
            LOWTRAN7 direct irradiance (in MWIR far brighter than the sea's emission) on the sea,
            textured seas included. ``params["is_day"]``, ``params["sun_elevation_deg"]`` and
            ``params["sun_azimuth_deg"]`` (world) keep the draw for replay; see
            :class:`SceneSampler`.
        sun_elevation_deg, sun_azimuth_deg, sun_azimuth_relative_to_yaw: see ``daytime``.
        band: sensor band (``LWIR`` default, ``MWIR`` or (λ_lo, λ_hi) [m]).
        anisotropic: Cox–Munk anisotropic (default) or isotropic slopes.
        mode: ``"replace"`` (default): the output is the rendered sea, repeated over the input's
            channels (the input's values are not used, only its shape, dtype and device);
            ``"composite"``: the input has two channels, a target's value (channel 0, in
            ``target_unit``) and its opacity α ∈ [0, 1] (channel 1; a value outside [0, 1] is a
            ``ValueError``, not clamped); channel 0 of the output is α L_target + (1 − α) L_sea in
            radiance (then the sensor model), channel 1 is α unchanged.
        target_unit: ``"temperature"`` (default: blackbody temperature [K] of the target as seen at
            the sensor) or ``"radiance"`` [W m⁻² sr⁻¹].
        sensor: a sensor model (``roughsea_torch.sensor.SensorModel`` or any module
            ``sensor(radiance, generator=g)``) applied after compositing; its random stages draw
            from a generator seeded by each image's ``noise_seed``, so replays repeat the noise. A
            :class:`~roughsea_torch.sensor.SensorModel` runs once on the batch (its noise drawn
            per image from those generators); another module is called image by image.
        output: ``"radiance"``, ``"brightness_temperature"`` [K], or ``"sensor"`` (the sensor
            model's output, e.g. counts); default: ``"sensor"`` when a sensor is given, else
            ``"radiance"``.
        table, quadrature, path: renderer settings (see :func:`~roughsea_torch.render.render`).
        foam: the whitecaps, as ``SeaScene(foam=)``: ``"auto"`` (default: Monahan's fraction at
            each image's wind, on the crests of a textured sea), ``False`` (none: a sea without
            whitecaps, e.g. where the model's dark whitecaps near grazing are not wanted;
            README, *Foam*) or a fraction in [0, 1]. A setting of the augmentation, not drawn.
        generator: a CPU ``torch.Generator`` used for every draw of this instance when ``forward``
            gets none; ``forward(x, generator=g)`` seeds one call. Inside a
            ``torch.utils.data.DataLoader`` worker, each worker replaces it on first use by its own
            stream, seeded from the generator's state as the worker received it and the worker's
            id: workers draw different scenes (and wave seeds), and the same ones on every run
            seeded the same way. Workers that are not persistent restart from that state every
            epoch (and so repeat their scenes); use ``persistent_workers=True`` for new scenes
            each epoch.
    """

    generator: torch.Generator | None
    _call_generator: torch.Generator | None
    _worker: tuple[tuple[int, int], torch.Generator] | None

    def _set_up(
        self,
        motion: dict[str, Any] | None,
        /,
        *,
        wind_speed: Any = SCENE_FIELDS[0][3],
        wind_direction_deg: Any = SCENE_FIELDS[1][3],
        sea_temperature: Any = SCENE_FIELDS[2][3],
        air_temperature: Any = SCENE_FIELDS[3][3],
        air_sea_difference: Any = SCENE_FIELDS[9][3],
        altitude_m: Any = SCENE_FIELDS[4][3],
        pitch_deg: Any = SCENE_FIELDS[5][3],
        roll_deg: Any = SCENE_FIELDS[6][3],
        yaw_deg: Any = SCENE_FIELDS[7][3],
        hfov_deg: Any = SCENE_FIELDS[8][3],
        atmospheres: Sequence[str] | str = ("midlatitude_summer",),
        texture: bool = True,
        time_s: Any = DEFAULT_TIME_S,
        daytime: float = 0.0,
        sun_elevation_deg: Any = SUN_FIELDS[0][3],
        sun_azimuth_deg: Any = SUN_FIELDS[1][3],
        sun_azimuth_relative_to_yaw: bool = True,
        band: Any = LWIR,
        anisotropic: bool = True,
        mode: str = "replace",
        target_unit: str = "temperature",
        sensor: torch.nn.Module | None = None,
        output: str | None = None,
        table: TableSize = TableSize(),
        quadrature: Quadrature | None = None,
        path: bool = True,
        foam: Any = "auto",
        generator: torch.Generator | None = None,
    ) -> None:
        """Check and keep the shared arguments (documented in the class); ``motion``: the ranges of
        a clip's platform motion (``SceneSampler(motion=)``), None for still images."""
        self.sampler = SceneSampler(
            atmospheres=atmospheres, wind_speed=wind_speed, wind_direction_deg=wind_direction_deg,
            sea_temperature=sea_temperature, air_temperature=air_temperature,
            air_sea_difference=air_sea_difference, altitude_m=altitude_m,
            pitch_deg=pitch_deg, roll_deg=roll_deg, yaw_deg=yaw_deg, hfov_deg=hfov_deg, path=path, band=band,
            texture=texture, time_s=time_s, motion=motion, daytime=daytime, sun_elevation_deg=sun_elevation_deg,
            sun_azimuth_deg=sun_azimuth_deg, sun_azimuth_relative_to_yaw=sun_azimuth_relative_to_yaw,
        )
        self.output = check_output_settings(mode, target_unit, sensor, output, generator)
        self.texture = texture
        self.band = as_band(band)
        self.anisotropic = anisotropic
        self.mode = mode
        self.target_unit = target_unit
        self.sensor = sensor
        self.table = table
        self.quadrature = quadrature
        self.path = path
        self.foam = check_foam(foam, per_image=False)
        self.generator = generator
        self._call_generator = None
        self._worker = None

    def _generator(self) -> torch.Generator | None:
        """The generator of this draw: the one given to ``forward``, else the instance's; inside a
        DataLoader worker the instance's is replaced, on first use, by the worker's own stream
        (see :func:`_worker_stream`)."""
        if self._call_generator is not None:
            return self._call_generator
        if self.generator is None:
            return None
        info = torch.utils.data.get_worker_info()
        if info is None:
            return self.generator
        key = (os.getpid(), int(info.id))
        if self._worker is None or self._worker[0] != key:
            self._worker = (key, _worker_stream(self.generator, int(info.id)))
        return self._worker[1]

    def _selected(self, params: dict[str, torch.Tensor], B: int) -> tuple[torch.Tensor, dict[str, torch.Tensor]]:
        """The images (clips) a draw of B replaces, those its gate ``"batch_prob"`` selects (all
        without a gate), and their per-image fields; with ``texture=False`` without the wave seeds
        (the expectation, whatever the draw holds)."""
        gate = params["batch_prob"].reshape(-1).cpu() > 0.5 if "batch_prob" in params else torch.ones(B, dtype=torch.bool)
        if gate.numel() == 1:
            gate = gate.expand(B)
        idx = gate.nonzero()[:, 0]
        sub = {k: v[idx.to(v.device)] for k, v in params.items() if isinstance(v, torch.Tensor) and v.ndim == 1
               and v.shape[0] == B and (self.texture or k != "wave_seed")}
        return idx, sub

    def _finish(self, L: torch.Tensor, inp: torch.Tensor, noise_seeds: Sequence[int]) -> torch.Tensor:
        """Rendered radiance L (N, 1, H, W) → channel 0 of the output (N, 1, H, W): composited with
        the input's targets (composite mode), through the sensor (image i's noise from
        ``noise_seeds[i]``), in the output's unit."""
        dtype = L.dtype
        if self.mode == "composite":
            target = inp[:, :1].to(dtype)
            alpha = inp[:, 1:2].to(dtype)  # in [0, 1]: forward checked it
            covered = alpha > 0
            if self.target_unit == "temperature":  # Planck only where a target shows (a band sum per pixel)
                target = torch.zeros_like(L).index_put((covered,), band_radiance(target[covered], self.band))
            L = torch.where(covered, torch.lerp(L, target, alpha), L)
        if self.output == "sensor":
            gens = [torch.Generator().manual_seed(int(s)) for s in noise_seeds]
            if isinstance(self.sensor, SensorModel):  # one batched call, each image's noise from its own seed
                L = self.sensor(L, generator=gens)
            else:  # any module sensor(radiance, generator=g): image by image
                L = torch.cat([self.sensor(L[i : i + 1], generator=g) for i, g in enumerate(gens)])
        elif self.output == "brightness_temperature":
            L = brightness_temperature(L.clamp_min(torch.finfo(dtype).tiny), self.band)
        return L

    def _paste(self, out: torch.Tensor, idx: torch.Tensor, L: torch.Tensor) -> None:
        """Write the finished images L (N, [T,] 1, H, W) into ``out[idx]``: into channel 0 in
        composite mode (channel 1, the opacity, stays), into every channel in replace mode."""
        if self.mode == "composite":
            out[idx, ..., :1, :, :] = L
        else:
            out[idx] = L.expand(*L.shape[:-3], out.shape[-3], -1, -1)


# the shared keyword arguments, as RandomSeaBase._set_up declares them
_SHARED = [q for q in inspect.signature(RandomSeaBase._set_up).parameters.values() if q.kind is q.KEYWORD_ONLY]


def _check_keywords(cls: type, shared: dict[str, Any]) -> None:
    """A constructor's ``**shared`` holds only shared arguments: else the ``TypeError`` Python gives
    for an unknown keyword argument."""
    names = {q.name for q in _SHARED}
    for k in shared:
        if k not in names:
            raise TypeError(f"{cls.__name__}.__init__() got an unexpected keyword argument {k!r}")


def _lists_shared_arguments(init: Callable[..., None]) -> Callable[..., None]:
    """Give a constructor ``__init__(self, *, <own>, p, ..., **shared)`` the signature that names
    the shared arguments (with their defaults) just before ``p``, for ``inspect.signature`` and
    ``help``; the constructor itself is unchanged."""
    own = list(inspect.signature(init).parameters.values())
    at = [q.name for q in own].index("p")
    params = own[:at] + _SHARED + [q for q in own[at:] if q.kind is not q.VAR_KEYWORD]
    init.__signature__ = inspect.signature(init).replace(parameters=params)  # type: ignore[attr-defined]
    return init


class RandomSeaBackground(RandomSeaBase, IntensityAugmentationBase2D):
    """Replace images with random, physically rendered infrared sea backgrounds, or composite
    targets onto them.

    Args:
        p, same_on_batch, keepdim: kornia's (images not selected by ``p`` come back unchanged and
            are not rendered; ``same_on_batch`` repeats the wave seed and time too). In
            ``mode="replace"`` an unselected image is the input image itself (e.g. a real frame, in
            whatever unit the caller keeps it; set ``output`` to match). In ``mode="composite"`` the
            input is a target chip (value, α), not an image, and a chip left out would come back in
            the target's unit next to images in the output's: ``p`` must be 1 there (a
            ``ValueError`` otherwise), so every image of a batch is in one unit.
        wind_speed, ..., generator: the scene, rendering and output arguments shared with
            :class:`RandomSeaClip`, described in :class:`RandomSeaBase` (the scene ranges, ``texture``
            and ``time_s``, ``daytime`` and the sun's ranges, ``band``, ``anisotropic``, ``mode``,
            ``target_unit``, ``sensor``, ``output``, ``table``, ``quadrature``, ``path``, ``foam``,
            ``generator``).

    Shapes: input (B, C, H, W) or (C, H, W), float32 or float64; output the same shape and dtype.
    Other dtypes are a ``ValueError`` naming ``input``: the output has the input's dtype, and
    float16 (0.25 K steps near 290 K, so rounding errors up to 0.125 K against a 0.05 K NETD;
    integers exact only up to 2048, below 14-bit counts) or bfloat16 cannot hold it to the sensor's
    resolution. Cast to float32, and the output back if needed.

    Cost: the texture adds the wave field's synthesis per image and its evaluation at near range
    (pixels whose footprint resolves waves; the far field is the expectation, at no extra cost):
    several times the expectation image's render. ``texture=False`` when the clutter is not wanted.

    Example:
        >>> aug = RandomSeaBackground(wind_speed=(2.0, 12.0), output="brightness_temperature")
        >>> x = torch.zeros(2, 1, 24, 32)
        >>> y = aug(x, generator=torch.Generator().manual_seed(0))
        >>> y.shape, bool((y > 200).all()), torch.equal(aug(x, params=aug._params), y)
        (torch.Size([2, 1, 24, 32]), True, True)
        >>> sorted(k for k in aug._params if k in ("wave_seed", "time_s"))
        ['time_s', 'wave_seed']
    """

    @_lists_shared_arguments
    def __init__(self, *, p: float = 1.0, same_on_batch: bool = False, keepdim: bool = False, **shared: Any) -> None:
        _check_keywords(type(self), shared)
        super().__init__(p=p, same_on_batch=same_on_batch, keepdim=keepdim)
        self._set_up(None, **shared)
        check_composite_gate(self.mode, p)

    def forward(self, input: torch.Tensor, params: dict[str, torch.Tensor] | None = None,
                generator: torch.Generator | None = None, **kwargs: Any) -> torch.Tensor:
        if generator is not None and generator.device.type != "cpu":
            raise ValueError("generator must be a CPU torch.Generator")
        check_input(input, self.mode)
        self._call_generator = generator
        try:
            return super().forward(input, params=params, **kwargs)
        finally:
            self._call_generator = None

    def __batch_prob_generator__(self, batch_shape: tuple[int, ...], p: float, p_batch: float, same_on_batch: bool) -> torch.Tensor:
        g = self._generator()
        if g is None or p in (0.0, 1.0) and p_batch == 1.0:
            return super().__batch_prob_generator__(batch_shape, p, p_batch, same_on_batch)
        n = 1 if same_on_batch else batch_shape[0]
        keep = (torch.rand(n, generator=g) < p).expand(batch_shape[0])
        if p_batch < 1.0:
            keep = keep & (torch.rand(1, generator=g) < p_batch)
        return keep.to(device=self.device or torch.device("cpu"), dtype=self.dtype or torch.float32)

    def generate_parameters(self, batch_shape: tuple[int, ...]) -> dict[str, torch.Tensor]:
        return self.sampler.sample(int(batch_shape[0]), generator=self._generator(), same_on_batch=self.same_on_batch)

    def apply_transform(self, input: torch.Tensor, params: dict[str, torch.Tensor], flags: dict[str, Any],
                        transform: torch.Tensor | None = None) -> torch.Tensor:
        B, C, H, W = input.shape
        if self.mode == "composite" and C != 2:
            raise ValueError(f"input: mode='composite' needs 2 channels (target value, alpha); got {C}")
        check_params(params, B, self.sampler.atmospheres, (1, B))  # a replayed draw too
        idx, sub = self._selected(params, B)
        out = input.clone()
        if idx.numel() == 0:
            return out
        L = render_parameters(
            sub, H, W, self.sampler.atmospheres, band=self.band, anisotropic=self.anisotropic, dtype=input.dtype,
            device=input.device, table=self.table, quadrature=self.quadrature, path=self.path, foam=self.foam,
        )
        # compositing and the sensor on one intra-op thread (as the scenes: roughsea_torch._parallel)
        L = one_thread(lambda: self._finish(L, input[idx], sub["noise_seed"].tolist()), input.device).to(input.dtype)
        self._paste(out, idx, L)
        return out


_LAYOUTS = ("BTCHW", "BCTHW")


class RandomSeaClip(RandomSeaBase, torch.nn.Module):
    """Replace clips with random infrared sea clips (or composite per-frame targets onto them), in
    kornia's video layouts.

    Each clip is one sea realization (a wave seed drawn per clip, ``SeaScene(seed=...)``) at
    successive times: frame t at ``time_s`` + t / ``frame_rate`` [s], the waves moving by their
    dispersion relation; seen by a camera on a :class:`~roughsea_torch.motion.PlatformMotion`
    (mean pose drawn as for :class:`RandomSeaBackground`, then pitch, roll and heave oscillations
    with amplitudes and periods drawn per clip and a phase φ ∈ [0, 2π)), so the horizon moves.

    Args:
        frame_rate: [Hz], > 0 (default 25). The clip length is the input's T.
        data_format: ``"BTCHW"`` (default, ``VideoSequential``'s default) or ``"BCTHW"``
            (case-insensitive); the output keeps the input's layout.
        pitch_amplitude_deg, roll_amplitude_deg: ranges of the oscillation amplitudes [deg]
            (default 0–2°, 0–4°).
        heave_amplitude_m: range of the heave amplitude [m] (default 0–1 m); the camera must stay
            above the sea (and within the path tables' 2 m – 5 km with the path on).
        pitch_period_s, roll_period_s, heave_period_s: ranges of the periods [s] (default 5–12 s,
            a ship's response to a swell).
        p: probability that a clip is replaced (clips not selected come back unchanged and are not
            rendered).
        same_on_batch: every clip of the batch the same (scene, seed, time and motion).
        wind_speed, ..., generator: the scene, rendering and output arguments shared with
            :class:`RandomSeaBackground`, described in :class:`RandomSeaBase`. In a clip:
            ``texture=False`` makes every frame the expectation image of its pose (only the camera
            moves), also for a replayed draw that holds wave seeds, and clips with ``wind_speed`` ≤
            :data:`CALM_WIND_SPEED` are expectation images too; ``time_s`` is the range of the
            clips' start times [s]; the sun (``daytime`` ...) is drawn per clip and stays put over
            it, its relative azimuth from the clip's mean yaw; in composite mode every frame holds
            its own target and opacity (C = 2); with a sensor, frame t's temporal noise comes from
            :func:`frame_noise_seed` (noise_seed, t), and the fixed pattern is the same on every
            frame.

    Shapes: input (B, T, C, H, W) (or (B, C, T, H, W) with ``data_format="BCTHW"``), float32 or
    float64; output the same shape and dtype. ``forward(x, params=None, generator=None)``; the
    draw is kept in ``self._params`` (per clip, (B,)) and ``forward(x, params=self._params)``
    replays it bit for bit; :func:`frame_parameters` gives each frame's pose, time and noise seed.

    It is not a kornia 2-D augmentation (``VideoSequential`` would apply it frame by frame with the
    same parameters, a still sea); run it before frame-wise augmentations::

        clip = RandomSeaClip(frame_rate=25.0)(torch.zeros(B, T, 1, H, W))
        clip = kornia.augmentation.VideoSequential(K.RandomHorizontalFlip(), data_format="BTCHW")(clip)

    Example:
        >>> aug = RandomSeaClip(frame_rate=10.0, output="brightness_temperature")
        >>> x = torch.zeros(1, 3, 1, 24, 32)
        >>> y = aug(x, generator=torch.Generator().manual_seed(0))
        >>> y.shape, torch.equal(aug(x, params=aug._params), y), bool((y[:, 0] != y[:, 1]).any())
        (torch.Size([1, 3, 1, 24, 32]), True, True)
    """

    @_lists_shared_arguments
    def __init__(
        self,
        *,
        frame_rate: float = 25.0,
        data_format: str = "BTCHW",
        pitch_amplitude_deg: Any = MOTION_FIELDS[0][3],
        roll_amplitude_deg: Any = MOTION_FIELDS[1][3],
        heave_amplitude_m: Any = MOTION_FIELDS[2][3],
        pitch_period_s: Any = MOTION_FIELDS[3][3],
        roll_period_s: Any = MOTION_FIELDS[4][3],
        heave_period_s: Any = MOTION_FIELDS[5][3],
        p: float = 1.0,
        same_on_batch: bool = False,
        **shared: Any,
    ) -> None:
        _check_keywords(type(self), shared)
        super().__init__()
        check_finite_range("frame_rate", frame_rate, 0.0, lo_open=True, unit="Hz")
        fmt = data_format.upper() if isinstance(data_format, str) else data_format
        if fmt not in _LAYOUTS:
            raise ValueError(f"data_format must be 'BTCHW' or 'BCTHW' (kornia's video layouts); got {data_format!r}")
        check_finite_range("p", p, 0.0, 1.0)
        if not isinstance(same_on_batch, bool):
            raise ValueError(f"same_on_batch must be True or False; got {same_on_batch!r}")
        motion = dict(pitch_amplitude_deg=pitch_amplitude_deg, roll_amplitude_deg=roll_amplitude_deg,
                      heave_amplitude_m=heave_amplitude_m, pitch_period_s=pitch_period_s, roll_period_s=roll_period_s,
                      heave_period_s=heave_period_s)
        self._set_up(motion, **shared)
        check_composite_gate(self.mode, p)
        self.frame_rate = float(frame_rate)
        self.data_format = fmt
        self.p = float(p)
        self.same_on_batch = same_on_batch
        self._params: dict[str, torch.Tensor] | None = None

    def generate_parameters(self, batch_size: int) -> dict[str, torch.Tensor]:
        """One draw per clip: the gate (``"batch_prob"``, 1.0 for clips to replace; drawn only when
        0 < p < 1), then :meth:`SceneSampler.sample` with texture and motion."""
        g = self._generator()
        n = 1 if self.same_on_batch else batch_size
        if 0.0 < self.p < 1.0:
            keep = torch.rand(n, generator=g) < self.p
        else:
            keep = torch.full((n,), self.p == 1.0)
        params = self.sampler.sample(batch_size, generator=g, same_on_batch=self.same_on_batch)
        params["batch_prob"] = keep.expand(batch_size).to(torch.float32)
        return params

    def forward(self, input: torch.Tensor, params: dict[str, torch.Tensor] | None = None,
                generator: torch.Generator | None = None) -> torch.Tensor:
        if generator is not None and generator.device.type != "cpu":
            raise ValueError("generator must be a CPU torch.Generator")
        if not isinstance(input, torch.Tensor) or input.ndim != 5:
            shape = tuple(input.shape) if isinstance(input, torch.Tensor) else type(input).__name__
            raise ValueError(f"input must be a 5-D clip {self.data_format[0]}, {', '.join(self.data_format[1:])} "
                             f"(data_format={self.data_format!r}); got {shape}")
        x = input if self.data_format == "BTCHW" else input.transpose(1, 2)  # (B, T, C, H, W)
        B, T, C, H, W = x.shape
        if self.mode == "composite" and C != 2:
            raise ValueError(f"input: mode='composite' needs 2 channels (target value, alpha); got {C}")
        check_input(x.reshape(B * T, C, H, W), self.mode)
        self._call_generator = generator
        try:
            if params is None:
                params = self.generate_parameters(B)
        finally:
            self._call_generator = None
        check_params(params, B, self.sampler.atmospheres, (B,))  # a replayed draw too
        self._params = params
        out = x.clone()
        idx, sub = self._selected(params, B)  # no gate: every clip, as kornia's RandomSeaBackground
        if idx.numel() > 0:
            self._paste(out, idx, self._render_clips(sub, x[idx], T))
        return out if self.data_format == "BTCHW" else out.transpose(1, 2)

    def _render_clips(self, sub: dict[str, torch.Tensor], x: torch.Tensor, T: int) -> torch.Tensor:
        """The finished clips (n, T, 1, H, W) of the draw ``sub`` (n,), whose inputs are x (n, T, C, H, W)."""
        n, _, C, H, W = x.shape
        frames = frame_parameters(sub, T, self.frame_rate)
        L = render_frames(sub, frames, H, W, self.sampler.atmospheres, self.band, self.anisotropic, x.dtype,
                          x.device, self.table, self.quadrature, EARTH_RADIUS_M, self.path, self.foam)
        # compositing and the sensor on one intra-op thread, as RandomSeaBackground
        L = one_thread(lambda: self._finish(L.reshape(n * T, 1, H, W), x.reshape(n * T, C, H, W),
                                            frames["noise_seed"].reshape(-1).tolist()), x.device)
        return L.to(x.dtype).reshape(n, T, 1, H, W)

    def extra_repr(self) -> str:
        return (f"frame_rate={self.frame_rate:g}, data_format={self.data_format!r}, texture={self.texture}, "
                f"mode={self.mode!r}, output={self.output!r}, p={self.p:g}")

"""Random sea backgrounds for detector training, in ``kornia.augmentation``'s conventions.

- :class:`SceneSampler` draws scene and pose parameters (wind, sea and air temperature,
  atmosphere, altitude, pitch, roll, yaw, field of view) uniformly from ranges the user gives; it
  is separate from the deterministic rendering (:func:`render_parameters`), as kornia separates
  parameter generation from the transform. Every draw comes from a CPU ``torch.Generator`` (or the
  global one), so the same seed gives the same parameters on every device;
  :meth:`SceneSampler.sample_indexed` gives each image index its own stream, so an image does not
  depend on which batch, worker or rank made it (what the dataset generator relies on).
- :class:`RandomSeaBackground` is a ``kornia.augmentation.IntensityAugmentationBase2D``: ``p``,
  ``same_on_batch``, ``keepdim``, ``aug._params`` for replay (``aug(x, params=aug._params)`` gives
  the same output bit for bit, sensor noise included), masks/boxes/keypoints pass through inside
  ``kornia.augmentation.AugmentationSequential``. It replaces its input with a rendered sea, or
  composites the user's targets onto it (alpha compositing in radiance, so the contrast a target
  shows is the physical one), and optionally runs a sensor model
  (:mod:`roughsea_torch.sensor`).

Units: temperatures in K, angles in degrees (wind direction: world azimuth of the upwind axis,
from +x towards +y; the camera's yaw in the same frame), altitude in m, wind speed in m s⁻¹ at
12.5 m, radiance in W m⁻² sr⁻¹ in the scene's band.
"""

from __future__ import annotations

import math
import os
from typing import Any, Sequence

import torch
from kornia.augmentation import IntensityAugmentationBase2D

from ._validation import check_finite_range
from .expectation import Quadrature
from .geometry import EARTH_RADIUS_M, make_camera
from .radiometry import LWIR, as_band, band_radiance, brightness_temperature
from .render import SeaScene, TableSize, render
from .sensor import SensorModel

__all__ = ["SceneSampler", "RandomSeaBackground", "render_parameters", "SCENE_FIELDS"]

# (name, allowed range, unit, default range); the order is the order of the draws
SCENE_FIELDS: tuple[tuple[str, tuple[float, float], str, Any], ...] = (
    ("wind_speed", (0.0, 40.0), "m/s", (1.0, 15.0)),
    ("wind_direction_deg", (-3600.0, 3600.0), "deg", (0.0, 360.0)),
    ("sea_temperature", (260.0, 320.0), "K", (285.0, 300.0)),
    ("air_temperature", (230.0, 330.0), "K", None),
    ("altitude_m", (0.5, 20000.0), "m", (10.0, 100.0)),
    ("pitch_deg", (-90.0, 90.0), "deg", (-10.0, -1.0)),
    ("roll_deg", (-180.0, 180.0), "deg", (-2.0, 2.0)),
    ("yaw_deg", (-3600.0, 3600.0), "deg", 0.0),
    ("hfov_deg", (0.5, 179.0), "deg", (20.0, 40.0)),
)
_FIELD_NAMES = tuple(f[0] for f in SCENE_FIELDS)
_MIX = 0x9E3779B97F4A7C15  # golden-ratio constant of splitmix64
_MASK = (1 << 64) - 1


def _splitmix64(x: int) -> int:
    x = (x + _MIX) & _MASK
    x = ((x ^ (x >> 30)) * 0xBF58476D1CE4E5B9) & _MASK
    x = ((x ^ (x >> 27)) * 0x94D049BB133111EB) & _MASK
    return x ^ (x >> 31)


def image_seed(seed: int, index: int) -> int:
    """A 63-bit seed for image ``index`` of a run seeded ``seed`` (splitmix64 of both): nearby
    seeds and indices give unrelated streams."""
    return _splitmix64(_splitmix64(int(seed) & _MASK) ^ (int(index) & _MASK)) >> 1


def _range(name: str, value: Any, allowed: tuple[float, float], unit: str) -> tuple[float, float]:
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        lo = hi = float(value)
    else:
        try:
            lo, hi = (float(v) for v in value)
        except (TypeError, ValueError):
            raise ValueError(f"{name}: give a number or a (low, high) pair [{unit}]; got {value!r}") from None
    if not (math.isfinite(lo) and math.isfinite(hi)):
        raise ValueError(f"{name}: the range must be finite; got ({lo}, {hi})")
    if lo > hi:
        raise ValueError(f"{name}: the range ({lo:g}, {hi:g}) is inverted (low > high)")
    check_finite_range(name, torch.tensor([lo, hi], dtype=torch.float64), *allowed, unit=unit)
    return lo, hi


class SceneSampler:
    """Uniform draws of scene and pose parameters, one set per image.

    Each argument is a number (held fixed) or a ``(low, high)`` pair (drawn uniformly); the
    defaults are in :data:`SCENE_FIELDS`:

    Args:
        wind_speed: W [m s⁻¹], in [0, 40] (Cox–Munk was fitted up to ~14 m s⁻¹).
        wind_direction_deg: upwind azimuth [deg] in the world frame.
        sea_temperature: T_sea [K], in [260, 320].
        air_temperature: T_air [K] of the surface air, in [230, 330]; ``None`` (default): each
            atmosphere's own surface air temperature (see ``SeaScene``).
        altitude_m: sensor height above the sea [m], in [2, 5000] with the atmospheric path on (the
            altitudes its tables cover), in [0.5, 20000] with ``path=False`` (a camera below the
            sea, or outside the path tables, is refused here, before any work).
        pitch_deg: elevation of the optical axis [deg], in [−90, 90]; negative looks down.
        roll_deg: [deg], in [−180, 180].
        yaw_deg: azimuth of the optical axis [deg] (with a random wind direction a fixed yaw
            loses nothing).
        hfov_deg: horizontal field of view [deg], in [0.5, 179].
        atmospheres: names of shipped LOWTRAN7 atmospheres, drawn with equal probability.
        path: whether the images will be rendered with the atmospheric path between sea and sensor
            (the renderer's default); it only sets the allowed ``altitude_m``.
        band: the sensor band of the path tables (``LWIR`` default, ``MWIR`` or (λ_lo, λ_hi) [m]).

    ``sample(B, generator)`` returns a dict of CPU float64 tensors (B,) under these names plus
    ``"atmosphere"`` (int64 index into ``atmospheres``) and ``"noise_seed"`` (int64, for the sensor
    model's random stages). Every field is drawn on every call, fixed or not, so fixing one range
    does not change the draws of the others.

    Example:
        >>> s = SceneSampler(wind_speed=(2.0, 4.0), pitch_deg=-3.0)
        >>> p = s.sample(3, generator=torch.Generator().manual_seed(0))
        >>> bool(((p["wind_speed"] >= 2) & (p["wind_speed"] <= 4)).all()), p["pitch_deg"].tolist()
        (True, [-3.0, -3.0, -3.0])
    """

    def __init__(self, *, atmospheres: Sequence[str] | str = ("midlatitude_summer",), path: bool = True,
                 band: Any = LWIR, **ranges: Any):
        unknown = set(ranges) - set(_FIELD_NAMES)
        if unknown:
            raise ValueError(f"unknown scene parameter(s) {sorted(unknown)}; known: {list(_FIELD_NAMES) + ['atmospheres']}")
        if not isinstance(path, bool):
            raise ValueError(f"path must be True or False; got {path!r}")
        from .atmosphere import available_atmospheres, load_path, surface_air_temperature

        names = [atmospheres] if isinstance(atmospheres, str) else list(atmospheres)
        if not names:
            raise ValueError("atmospheres: give at least one atmosphere name")
        known = available_atmospheres()
        for n in names:
            if n not in known:
                raise ValueError(f"atmospheres: unknown atmosphere {n!r}; available: {known}")
        self.atmospheres: tuple[str, ...] = tuple(names)
        self.atmosphere_air_temperature = torch.tensor([surface_air_temperature(n) for n in names], dtype=torch.float64)
        self.ranges: dict[str, tuple[float, float] | None] = {}
        for name, allowed, unit, default in SCENE_FIELDS:
            value = ranges.get(name, default)
            self.ranges[name] = None if value is None else _range(name, value, allowed, unit)
        self.path = path
        if path:  # the atmospheric path between sea and sensor is tabulated over a band of altitudes
            band = as_band(band)
            tables = [load_path(n, (band.lo, band.hi), band.response).altitude_range_m for n in names]
            lo, hi = max(t[0] for t in tables), min(t[1] for t in tables)
            a, b = self.ranges["altitude_m"]
            if a < lo or b > hi:
                raise ValueError(
                    f"altitude_m: the range ({a:g}, {b:g}) m leaves [{lo:g}, {hi:g}] m, the camera altitudes of "
                    f"the atmospheric path tables (path on); keep altitude_m within [{lo:g}, {hi:g}] m, or turn "
                    f"the path off (path=False) for the full [{SCENE_FIELDS[4][1][0]:g}, {SCENE_FIELDS[4][1][1]:g}] m"
                )

    def config(self) -> dict[str, Any]:
        """The ranges as plain Python values (for metadata and configs)."""
        out: dict[str, Any] = {k: (None if v is None else list(v)) for k, v in self.ranges.items()}
        out["atmospheres"] = list(self.atmospheres)
        return out

    def sample(self, batch_size: int, generator: torch.Generator | None = None, same_on_batch: bool = False) -> dict[str, torch.Tensor]:
        """One parameter set per image: dict of CPU tensors of shape (batch_size,)."""
        if not isinstance(batch_size, int) or batch_size < 0:
            raise ValueError(f"batch_size must be an int >= 0; got {batch_size!r}")
        if generator is not None and generator.device.type != "cpu":
            raise ValueError("generator must be a CPU torch.Generator (parameters are drawn on the CPU, then moved)")
        n = 1 if same_on_batch else batch_size
        u = torch.rand(len(SCENE_FIELDS), n, generator=generator, dtype=torch.float64)
        atm = torch.randint(len(self.atmospheres), (n,), generator=generator)
        seeds = torch.randint(0, 2**62, (n,), generator=generator)
        out: dict[str, torch.Tensor] = {}
        for i, (name, *_rest) in enumerate(SCENE_FIELDS):
            r = self.ranges[name]
            if r is None:  # air temperature of each image's atmosphere
                out[name] = self.atmosphere_air_temperature[atm]
            else:
                out[name] = r[0] + (r[1] - r[0]) * u[i] if r[1] > r[0] else torch.full((n,), r[0], dtype=torch.float64)
        out["atmosphere"] = atm
        out["noise_seed"] = seeds
        if same_on_batch:
            out = {k: v.expand(batch_size).clone() for k, v in out.items()}
        return out

    def sample_indexed(self, seed: int, indices: Sequence[int] | torch.Tensor) -> dict[str, torch.Tensor]:
        """Parameters of images ``indices`` of a run seeded ``seed``: image i's draw comes from its
        own generator (seed :func:`image_seed` (seed, i)), so it is the same in any batch."""
        idx = [int(i) for i in (indices.tolist() if isinstance(indices, torch.Tensor) else indices)]
        if not idx:
            return self.sample(0)
        rows = [self.sample(1, torch.Generator().manual_seed(image_seed(seed, i))) for i in idx]
        return {k: torch.cat([r[k] for r in rows]) for k in rows[0]}


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
) -> torch.Tensor:
    """The deterministic half: render the radiance images (B, 1, H, W) [W m⁻² sr⁻¹] that a set of
    :class:`SceneSampler` parameters describes (images sharing an atmosphere are rendered
    together; the sky and, with ``path``, the air between sea and sensor come from that
    atmosphere at each image's air temperature)."""
    B = int(params["wind_speed"].shape[0])
    out = torch.empty(B, 1, height, width, dtype=dtype, device=device)
    atm = params["atmosphere"].cpu()
    band = as_band(band)
    for a in torch.unique(atm).tolist():
        idx = (atm == a).nonzero()[:, 0]

        def f(name: str) -> torch.Tensor:
            return params[name][idx.to(params[name].device)].to(dtype=dtype, device=device)

        cams = make_camera(
            height, width, hfov_deg=f("hfov_deg"), altitude_m=f("altitude_m"), pitch_deg=f("pitch_deg"),
            yaw_deg=f("yaw_deg"), roll_deg=f("roll_deg"), dtype=dtype, device=device,
        )
        scene = SeaScene(
            wind_speed=f("wind_speed"), anisotropic=anisotropic, wind_direction=f("wind_direction_deg") * (math.pi / 180.0),
            sea_temperature=f("sea_temperature"), air_temperature=f("air_temperature"), band=band,
            sky=atmospheres[a], path=None if path else False,
        )
        img = render(cams, scene, earth_radius_m=earth_radius_m, table=table, quadrature=quadrature)
        out[idx.to(out.device)] = img
    return out


def _worker_stream(generator: torch.Generator, worker_id: int) -> torch.Generator:
    """A DataLoader worker's own generator: seeded by :func:`image_seed` of a number drawn from
    a copy of ``generator`` (its state as the worker received it; the original is not advanced)
    and the worker's id. Each worker gets a different stream, and the same one on every run that
    seeds ``generator`` the same way."""
    copy = torch.Generator().set_state(generator.get_state())
    base = int(torch.randint(0, 2**62, (1,), generator=copy))
    return torch.Generator().manual_seed(image_seed(base, worker_id))


def _check_input(input: Any, mode: str) -> None:
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


class RandomSeaBackground(IntensityAugmentationBase2D):
    """Replace images with random, physically rendered infrared sea backgrounds, or composite
    targets onto them.

    Args:
        wind_speed, wind_direction_deg, sea_temperature, air_temperature, altitude_m, pitch_deg,
            roll_deg, yaw_deg, hfov_deg, atmospheres: ranges of the scene, see :class:`SceneSampler`.
        band: sensor band (``LWIR`` default, ``MWIR`` or (λ_lo, λ_hi) [m]).
        anisotropic: Cox–Munk anisotropic (default) or isotropic slopes.
        mode: ``"replace"``: the output is the rendered sea, repeated over the input's channels
            (the input's values are not used, only its shape, dtype and device); ``"composite"``:
            the input has two channels, a target's value (channel 0, in ``target_unit``) and its
            opacity α ∈ [0, 1] (channel 1; a value outside [0, 1] is a ``ValueError``, not clamped);
            channel 0 of the output is α L_target + (1 − α) L_sea in radiance (then the sensor
            model), channel 1 is α unchanged.
        target_unit: ``"temperature"`` (blackbody temperature [K] of the target as seen at the
            sensor) or ``"radiance"`` [W m⁻² sr⁻¹].
        sensor: a sensor model (``roughsea_torch.sensor.SensorModel`` or any module
            ``sensor(radiance, generator=g)``) applied after compositing; its random stages draw
            from a generator seeded by each image's ``noise_seed``, so replays repeat the noise. A
            :class:`~roughsea_torch.sensor.SensorModel` runs once on the batch (its noise drawn
            per image from those generators); another module is called image by image.
        output: ``"radiance"``, ``"brightness_temperature"`` [K], or ``"sensor"`` (the sensor
            model's output, e.g. counts; the default when a sensor is given).
        table, quadrature, path: renderer settings (see :func:`~roughsea_torch.render.render`).
        generator: a CPU ``torch.Generator`` used for every draw of this instance when ``forward``
            gets none; ``forward(x, generator=g)`` seeds one call. Inside a
            ``torch.utils.data.DataLoader`` worker, each worker replaces it on first use by its own
            stream, seeded from the generator's state as the worker received it and the worker's
            id: workers draw different scenes, and the same ones on every run seeded the same way.
            Workers that are not persistent restart from that state every epoch (and so repeat
            their scenes); use ``persistent_workers=True`` for new scenes each epoch.
        p, same_on_batch, keepdim: kornia's (images not selected by ``p`` come back unchanged and
            are not rendered).

    Shapes: input (B, C, H, W) or (C, H, W), float32 or float64; output the same shape and dtype.
    Other dtypes are a ``ValueError`` naming ``input``: the output has the input's dtype, and
    float16 (0.25 K steps near 290 K, so rounding errors up to 0.125 K against a 0.05 K NETD;
    integers exact only up to 2048, below 14-bit counts) or bfloat16 cannot hold it to the sensor's
    resolution. Cast to float32, and the output back if needed.

    Example:
        >>> aug = RandomSeaBackground(wind_speed=(2.0, 12.0), output="brightness_temperature")
        >>> x = torch.zeros(2, 1, 24, 32)
        >>> y = aug(x, generator=torch.Generator().manual_seed(0))
        >>> y.shape, bool((y > 200).all()), torch.equal(aug(x, params=aug._params), y)
        (torch.Size([2, 1, 24, 32]), True, True)
    """

    def __init__(
        self,
        *,
        wind_speed: Any = SCENE_FIELDS[0][3],
        wind_direction_deg: Any = SCENE_FIELDS[1][3],
        sea_temperature: Any = SCENE_FIELDS[2][3],
        air_temperature: Any = SCENE_FIELDS[3][3],
        altitude_m: Any = SCENE_FIELDS[4][3],
        pitch_deg: Any = SCENE_FIELDS[5][3],
        roll_deg: Any = SCENE_FIELDS[6][3],
        yaw_deg: Any = SCENE_FIELDS[7][3],
        hfov_deg: Any = SCENE_FIELDS[8][3],
        atmospheres: Sequence[str] | str = ("midlatitude_summer",),
        band: Any = LWIR,
        anisotropic: bool = True,
        mode: str = "replace",
        target_unit: str = "temperature",
        sensor: torch.nn.Module | None = None,
        output: str | None = None,
        table: TableSize = TableSize(),
        quadrature: Quadrature | None = None,
        path: bool = True,
        generator: torch.Generator | None = None,
        p: float = 1.0,
        same_on_batch: bool = False,
        keepdim: bool = False,
    ) -> None:
        super().__init__(p=p, same_on_batch=same_on_batch, keepdim=keepdim)
        self.sampler = SceneSampler(
            atmospheres=atmospheres, wind_speed=wind_speed, wind_direction_deg=wind_direction_deg,
            sea_temperature=sea_temperature, air_temperature=air_temperature, altitude_m=altitude_m,
            pitch_deg=pitch_deg, roll_deg=roll_deg, yaw_deg=yaw_deg, hfov_deg=hfov_deg, path=path, band=band,
        )
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
        self.band = as_band(band)
        self.anisotropic = anisotropic
        self.mode = mode
        self.target_unit = target_unit
        self.sensor = sensor
        self.output = output
        self.table = table
        self.quadrature = quadrature
        self.path = path
        self.generator = generator
        self._call_generator: torch.Generator | None = None
        self._worker: tuple[tuple[int, int], torch.Generator] | None = None

    def forward(self, input: torch.Tensor, params: dict[str, torch.Tensor] | None = None,
                generator: torch.Generator | None = None, **kwargs: Any) -> torch.Tensor:
        if generator is not None and generator.device.type != "cpu":
            raise ValueError("generator must be a CPU torch.Generator")
        _check_input(input, self.mode)
        self._call_generator = generator
        try:
            return super().forward(input, params=params, **kwargs)
        finally:
            self._call_generator = None

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
        dtype = input.dtype  # float32 or float64 (forward refuses others)
        gate = params["batch_prob"].reshape(-1).cpu() > 0.5 if "batch_prob" in params else torch.ones(B, dtype=torch.bool)
        if gate.numel() == 1:
            gate = gate.expand(B)
        idx = gate.nonzero()[:, 0]
        out = input.clone()
        if idx.numel() == 0:
            return out
        sub = {k: v[idx.to(v.device)] for k, v in params.items() if isinstance(v, torch.Tensor) and v.ndim == 1 and v.shape[0] == B}
        L = render_parameters(
            sub, H, W, self.sampler.atmospheres, band=self.band, anisotropic=self.anisotropic, dtype=dtype,
            device=input.device, table=self.table, quadrature=self.quadrature, path=self.path,
        )
        if self.mode == "composite":
            target = input[idx, :1].to(dtype)
            alpha = input[idx, 1:2].to(dtype)  # in [0, 1]: forward checked it
            covered = alpha > 0
            if self.target_unit == "temperature":  # Planck only where a target shows (a band sum per pixel)
                target = torch.zeros_like(L).index_put((covered,), band_radiance(target[covered], self.band))
            L = torch.where(covered, torch.lerp(L, target, alpha), L)
        if self.output == "sensor":
            gens = [torch.Generator().manual_seed(int(s)) for s in sub["noise_seed"].tolist()]
            if isinstance(self.sensor, SensorModel):  # one batched call, each image's noise from its own seed
                L = self.sensor(L, generator=gens)
            else:  # any module sensor(radiance, generator=g): image by image
                L = torch.cat([self.sensor(L[i : i + 1], generator=g) for i, g in enumerate(gens)])
        elif self.output == "brightness_temperature":
            L = brightness_temperature(L.clamp_min(torch.finfo(dtype).tiny), self.band)
        L = L.to(input.dtype)
        if self.mode == "composite":
            out[idx, :1] = L
        else:
            out[idx] = L.expand(-1, C, -1, -1)
        return out

"""Golden renders: small images over every path of the renderer, saved once and compared bit for bit.

A safety net for restructuring (moving code without changing what it computes): each case renders
through the public API only, so the cases survive any reorganization of the package. The saved
tensors live in ``tests/data/golden_renders.pt`` with the torch version and CPU capability that made
them; ``tests/test_golden.py`` compares a fresh render with ``torch.equal`` on a machine of the same
torch build and CPU capability (float results depend on both), and within a few float32 ulps
elsewhere.

Re-make the file (only when a change is meant to alter the images, and say so in the commit)::

    python tests/golden_cases.py --save
"""

from __future__ import annotations

import argparse
import math
import os
import platform
import sys
from typing import Callable

import torch

import roughsea_torch as rs
from roughsea_torch.augmentation import RandomSeaBackground, RandomSeaClip

PATH = os.path.join(os.path.dirname(os.path.abspath(__file__)), "data", "golden_renders.pt")


def _cams(h: int = 24, w: int = 32, dtype: torch.dtype = torch.float32, **kw) -> object:
    kw.setdefault("hfov_deg", 20.0)
    kw.setdefault("altitude_m", 15.0)
    kw.setdefault("pitch_deg", -4.0)
    return rs.make_camera(h, w, dtype=dtype, **kw)


def _night_table(dtype: torch.dtype) -> torch.Tensor:
    cams = _cams(dtype=dtype, batch_size=2, pitch_deg=torch.tensor([-2.0, -9.0]), yaw_deg=torch.tensor([0.0, 70.0]))
    scene = rs.SeaScene(wind_speed=torch.tensor([4.0, 11.0]), wind_direction=0.3, sea_temperature=290.0, foam=False)
    return rs.render(cams, scene)


def _night_direct() -> torch.Tensor:
    cams = _cams(12, 16, dtype=torch.float64, pitch_deg=-3.0)
    scene = rs.SeaScene(wind_speed=7.0, wind_direction=1.0, sea_temperature=288.0)
    return rs.render(cams, scene, method="direct")


def _correlated_geometry() -> torch.Tensor:
    """Correlated slopes (the unfolded azimuth coordinate), a given view geometry, a flat sea."""
    cams = _cams(dtype=torch.float64, pitch_deg=-6.0, yaw_deg=30.0)
    geom = rs.view_geometry(cams, float("inf"))
    slopes = rs.SlopeStatistics(torch.tensor(0.15), torch.tensor(0.09), torch.tensor(0.3))
    scene = rs.SeaScene(slopes=slopes, sea_temperature=291.0, sky=lambda c: 12.0 + 18.0 * (1.0 - c) ** 6)
    return rs.render(cams, scene, geometry=geom, earth_radius_m=float("inf"))


def _isotropic_eq7_kelvin() -> torch.Tensor:
    """Isotropic slopes, a constant sky, Eq. 7 with sky masking, in kelvin, flat sea, no path."""
    cams = _cams(dtype=torch.float64, pitch_deg=-3.0)
    scene = rs.SeaScene(wind_speed=6.0, anisotropic=False, sea_temperature=285.0, sky=20.0, shadowing=True,
                        sky_masking=True, foam=0.01)
    geom = rs.view_geometry(cams, float("inf"))
    return rs.render(cams, scene, earth_radius_m=float("inf"), output="brightness_temperature", geometry=geom)


def _air_and_chunks() -> torch.Tensor:
    """Air temperature scaling, a tabulated atmosphere, six images in chunks of two (worker threads)."""
    cams = _cams(16, 20, dtype=torch.float32, batch_size=6, pitch_deg=torch.linspace(-1.0, -30.0, 6),
                 altitude_m=torch.linspace(5.0, 200.0, 6))
    scene = rs.SeaScene(wind_speed=torch.linspace(2.0, 14.0, 6), sea_temperature=torch.linspace(280.0, 300.0, 6),
                        air_temperature=torch.linspace(282.0, 305.0, 6), sky="tropical")
    return rs.render(cams, scene, chunk=2)


def _textured(dtype: torch.dtype) -> torch.Tensor:
    """A textured storm with whitecaps on the crests."""
    cams = _cams(24, 32, dtype=dtype, pitch_deg=-8.0, altitude_m=12.0, yaw_deg=20.0)
    scene = rs.SeaScene(wind_speed=15.0, wind_direction=0.2, sea_temperature=290.0, seed=11, time_s=2.5)
    return rs.render(cams, scene)


def _textured_direct() -> torch.Tensor:
    cams = _cams(12, 16, dtype=torch.float64, pitch_deg=-10.0, altitude_m=10.0)
    scene = rs.SeaScene(wind_speed=9.0, sea_temperature=289.0, seed=[5], foam=False)
    return rs.render(cams, scene, method="direct")


def _day(texture: bool) -> torch.Tensor:
    """MWIR by day, sun ahead (glint, the scattered sky); a grazing view and a view down at the nadir."""
    cams = _cams(16, 20, dtype=torch.float64, batch_size=2, pitch_deg=torch.tensor([-5.0, -90.0]), hfov_deg=30.0)
    scene = rs.SeaScene(wind_speed=8.0, wind_direction=0.4, sea_temperature=292.0, band=rs.MWIR, sun_zenith=1.2,
                        sun_azimuth=0.1, seed=3 if texture else None, time_s=1.0)
    return rs.render(cams, scene)


def _explicit_sun() -> torch.Tensor:
    """An explicit Sun, correlated slopes, the sun's disk in view, float32."""
    cams = _cams(24, 32, dtype=torch.float32, pitch_deg=2.0, hfov_deg=40.0)
    slopes = rs.SlopeStatistics(torch.tensor(0.14), torch.tensor(0.1), torch.tensor(-0.2))
    sun = rs.Sun(math.radians(88.0), 0.0, 30.0)
    scene = rs.SeaScene(slopes=slopes, sea_temperature=290.0, band=rs.MWIR, sun=sun, sky="us_standard")
    return rs.render(cams, scene)


def _gradient() -> torch.Tensor:
    """Value and gradient of a table render with respect to wind speed and pitch."""
    wind = torch.tensor(8.0, dtype=torch.float64, requires_grad=True)
    pitch = torch.tensor(-3.0, dtype=torch.float64, requires_grad=True)
    wd = torch.tensor(0.5, dtype=torch.float64, requires_grad=True)
    cams = rs.make_camera(12, 16, hfov_deg=15.0, altitude_m=20.0, pitch_deg=pitch, dtype=torch.float64)
    img = rs.render(cams, rs.SeaScene(wind_speed=wind, wind_direction=wd, sea_temperature=290.0))
    gw, gp, gd = torch.autograd.grad(img.sum(), [wind, pitch, wd])
    return torch.cat([img.detach().flatten(), gw.reshape(1), gp.reshape(1), gd.reshape(1)])


def _textured_gradient() -> torch.Tensor:
    wind = torch.tensor(10.0, dtype=torch.float64, requires_grad=True)
    cams = _cams(12, 16, dtype=torch.float64, pitch_deg=-10.0)
    img = rs.render(cams, rs.SeaScene(wind_speed=wind, sea_temperature=290.0, seed=2))
    (gw,) = torch.autograd.grad(img.mean(), [wind])
    return torch.cat([img.detach().flatten(), gw.reshape(1)])


def _direct_day_textured() -> torch.Tensor:
    """Per pixel: a textured MWIR day with whitecaps on the crests and the air temperature."""
    cams = _cams(12, 16, dtype=torch.float64, pitch_deg=-3.0, hfov_deg=30.0, altitude_m=20.0)
    scene = rs.SeaScene(wind_speed=16.0, sea_temperature=292.0, band=rs.MWIR, sun_zenith=1.3, sun_azimuth=0.2,
                        seed=6, air_temperature=296.0)
    day = rs.SeaScene(wind_speed=16.0, sea_temperature=292.0, band=rs.MWIR, sun_zenith=1.3, sun_azimuth=0.2)
    return torch.cat([rs.render(cams, scene, method="direct").flatten(), rs.render(cams, day, method="direct").flatten()])


def _wind_direction_gradient() -> torch.Tensor:
    wd = torch.tensor(0.5, dtype=torch.float32, requires_grad=True)
    cams = _cams(12, 16, pitch_deg=-2.0)
    img = rs.render(cams, rs.SeaScene(wind_speed=8.0, wind_direction=wd, sea_temperature=290.0))
    (g,) = torch.autograd.grad(img.sum(), [wd])
    return torch.cat([img.detach().flatten(), g.reshape(1)])


def _steep_and_grazing_textured() -> torch.Tensor:
    """Texture nodes on both quadrature rules (steep and grazing views in one image), one sky per image."""
    cams = _cams(24, 32, dtype=torch.float64, batch_size=2, pitch_deg=-70.0, hfov_deg=60.0, altitude_m=20.0)
    scene = rs.SeaScene(wind_speed=15.0, sea_temperature=290.0, seed=[9, 10], sky=torch.tensor([18.0, 22.0]))
    return rs.render(cams, scene)


def _span_full_day() -> torch.Tensor:
    """span='full' by day, with the air temperature."""
    cams = _cams(12, 16, dtype=torch.float64, pitch_deg=-4.0)
    scene = rs.SeaScene(wind_speed=6.0, sea_temperature=290.0, band=rs.MWIR, sun_zenith=1.0, sun_azimuth=2.0,
                        air_temperature=290.0)
    return rs.render(cams, scene, table=rs.TableSize(span="full"))


def _per_image_skies() -> torch.Tensor:
    """One constant sky per image, and one sky table per image, without a path."""
    cams = _cams(12, 16, dtype=torch.float32, batch_size=2, pitch_deg=-1.0)
    a = rs.render(cams, rs.SeaScene(wind_speed=5.0, sea_temperature=290.0, sky=torch.tensor([15.0, 25.0])))
    zen = torch.linspace(0.0, math.pi / 2, 30, dtype=torch.float64)
    rad = torch.stack([10.0 + 20.0 * (1 - torch.cos(zen)) ** 5, 14.0 + 15.0 * (1 - torch.cos(zen)) ** 3])
    b = rs.render(cams, rs.SeaScene(wind_speed=5.0, sea_temperature=290.0, sky=rs.TabulatedSky(zen, rad)))
    return torch.cat([a.flatten(), b.flatten()])


def _light_wind_close() -> torch.Tensor:
    """A light wind seen from 2 m, steeply: the resolved slopes are reconciled with Cox–Munk (a warning)."""
    import warnings

    cams = _cams(12, 16, dtype=torch.float32, pitch_deg=-50.0, altitude_m=2.0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        near = rs.render(cams, rs.SeaScene(wind_speed=1.0, sea_temperature=290.0, seed=1))
    far = rs.render(_cams(12, 16, pitch_deg=-0.3, hfov_deg=4.0, altitude_m=300.0),
                    rs.SeaScene(wind_speed=3.0, sea_temperature=290.0, seed=1))  # no node resolves a wave
    return torch.cat([near.flatten(), far.flatten()])


def _module_kelvin_textured() -> torch.Tensor:
    cams = _cams(16, 20, dtype=torch.float32, pitch_deg=-15.0)
    scene = rs.SeaScene(wind_speed=5.0, sea_temperature=286.0, seed=4, foam=0.02)
    return rs.SeaRenderer(output="brightness_temperature")(cams, scene)


def _clip() -> torch.Tensor:
    motion = rs.PlatformMotion(16, 20, hfov_deg=20.0, altitude_m=15.0, pitch_deg=-5.0)
    scene = rs.SeaScene(wind_speed=10.0, sea_temperature=290.0, seed=8, time_s=100.0)
    return rs.render_clip(motion, scene, torch.tensor([0.0, 0.04, 0.5]))


def _augmentation() -> torch.Tensor:
    """A textured augmentation batch (day and night), its replay, and a clip."""
    aug = RandomSeaBackground(output="brightness_temperature", daytime=0.5, band=rs.MWIR)
    x = torch.zeros(3, 1, 16, 20)
    y = aug(x, generator=torch.Generator().manual_seed(5))
    replay = aug(x, params={k: v.clone() for k, v in aug._params.items()})
    clip = RandomSeaClip(output="radiance")(torch.zeros(1, 2, 1, 12, 16),
                                                           generator=torch.Generator().manual_seed(2))
    return torch.cat([y.flatten(), replay.flatten(), clip.flatten().to(y.dtype)])


CASES: dict[str, Callable[[], torch.Tensor]] = {
    "night_table_f32": lambda: _night_table(torch.float32),
    "night_table_f64": lambda: _night_table(torch.float64),
    "night_direct": _night_direct,
    "correlated_geometry": _correlated_geometry,
    "isotropic_eq7_kelvin": _isotropic_eq7_kelvin,
    "air_and_chunks": _air_and_chunks,
    "textured_f32": lambda: _textured(torch.float32),
    "textured_f64": lambda: _textured(torch.float64),
    "textured_direct": _textured_direct,
    "day": lambda: _day(False),
    "day_textured": lambda: _day(True),
    "explicit_sun": _explicit_sun,
    "gradient": _gradient,
    "textured_gradient": _textured_gradient,
    "module_kelvin_textured": _module_kelvin_textured,
    "direct_day_textured": _direct_day_textured,
    "span_full_day": _span_full_day,
    "wind_direction_gradient": _wind_direction_gradient,
    "steep_and_grazing_textured": _steep_and_grazing_textured,
    "per_image_skies": _per_image_skies,
    "light_wind_close": _light_wind_close,
    "clip": _clip,
    "augmentation": _augmentation,
}


def render_all() -> dict[str, torch.Tensor]:
    return {name: fn().detach().cpu() for name, fn in CASES.items()}


def stamp() -> dict[str, str]:
    """What the bits depend on besides the code: torch's build, the CPU kernels it dispatches to, and the
    CPU's maker (Intel and AMD processors of the same capability, AVX512, round a few float32 values
    differently: 1e-5 W m⁻² sr⁻¹, through vendor-specific library paths)."""
    return {"torch": str(torch.__version__), "cpu_capability": torch.backends.cpu.get_cpu_capability(),
            "cpu_vendor": _cpu_vendor()}


def _cpu_vendor() -> str:
    """The CPU's vendor_id of /proc/cpuinfo (e.g. GenuineIntel, AuthenticAMD), or platform.processor()."""
    try:
        with open("/proc/cpuinfo", encoding="utf-8") as fh:
            for line in fh:
                if line.startswith("vendor_id"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor()


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--save", action="store_true", help=f"write {PATH}")
    args = ap.parse_args(argv)
    out = render_all()
    if args.save:
        os.makedirs(os.path.dirname(PATH), exist_ok=True)
        torch.save({"stamp": stamp(), "renders": out}, PATH)
        print(f"wrote {PATH}: {sum(v.numel() * v.element_size() for v in out.values()) / 1e6:.2f} MB")
        return 0
    saved = torch.load(PATH)
    bad = [k for k, v in out.items() if not torch.equal(v, saved["renders"][k])]
    print("bitwise equal" if not bad else f"differ: {bad}")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())

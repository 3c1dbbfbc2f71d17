"""Cameras and the per-pixel geometry (roughsea_torch.geometry): make_camera's pose (the roll seen as
the horizon's tilt), the view angles and ranges on a flat and a spherical earth, the horizon's
depression, and the checks of their arguments."""

from __future__ import annotations

import math

import numpy as np
import pytest
import torch

import roughsea_torch as rs

from conftest import DEG

F64 = torch.float64


def test_horizon_depression_and_distance_on_a_sphere():
    """docs/physics.md §9: at h = 20 m the horizon is depressed by √(2h/R) = 0.1436° and lies √(2hR) ≈ 16 km
    away. A camera pitched to the horizon: the first sea row is the one just below it, and the
    sea pixel farthest away is at ≈ the horizon distance."""
    h, R = 20.0, 6_371_000.0
    dip = math.degrees(math.sqrt(2 * h / R))
    H = 2001
    cams = rs.make_camera(H, 3, hfov_deg=0.6, altitude_m=h, pitch_deg=-dip, dtype=torch.float64)
    geom = rs.view_geometry(cams, earth_radius_m=R)
    col = geom.is_sea[0, :, 1]
    first = int(torch.nonzero(col)[0])
    f = float(cams.fx[0])
    elev = lambda row: -dip + math.degrees(math.atan(((H - 1) / 2 - row) / f))  # noqa: E731
    row_deg = math.degrees(math.atan(1 / f))  # one row [deg]
    # the sea starts at the depressed horizon, 0.1436° below the horizontal (docs/physics.md §9)
    assert elev(first) <= -0.1436 + row_deg and elev(first - 1) > -0.1436 - row_deg
    far = float(geom.range_m[0, first, 1])
    assert abs(far - math.sqrt(2 * h * R)) / math.sqrt(2 * h * R) < 0.02
    assert float(geom.view_zenith[0, first, 1]) > 89.9 * DEG  # LOS tangent at the horizon


def test_flat_sea_geometry_is_the_plane():
    cams = rs.make_camera(33, 5, hfov_deg=20.0, altitude_m=50.0, pitch_deg=-30.0, dtype=torch.float64)
    geom = rs.view_geometry(cams, earth_radius_m=float("inf"))
    centre = geom.view_zenith[0, 16, 2]
    assert abs(float(centre) - 60 * DEG) < 1e-12  # optical axis 30° below horizontal → θ̂ = 60°
    assert abs(float(geom.range_m[0, 16, 2]) - 50.0 / math.sin(30 * DEG)) < 1e-9
    sphere = rs.view_geometry(cams)
    # on a sphere the local vertical at the hit tilts away from the camera: θ̂ grows, slightly
    assert float(sphere.view_zenith[0, 16, 2]) > float(centre)
    assert float(sphere.view_zenith[0, 16, 2]) - float(centre) < 1e-4


def test_los_azimuth_points_back_to_the_camera():
    """A camera with yaw 0 looks along +x: the LOS sea → sensor of its central pixel points to −x."""
    cams = rs.make_camera(11, 11, hfov_deg=20.0, altitude_m=10.0, pitch_deg=-20.0, yaw_deg=0.0, dtype=torch.float64)
    az = float(rs.view_geometry(cams).view_azimuth[0, 5, 5])
    assert abs(abs(az) - math.pi) < 1e-9
    cams = rs.make_camera(11, 11, hfov_deg=20.0, altitude_m=10.0, pitch_deg=-20.0, yaw_deg=90.0, dtype=torch.float64)
    az = float(rs.view_geometry(cams).view_azimuth[0, 5, 5])
    assert abs(az + math.pi / 2) < 1e-9


def horizon_tilt_deg(cams) -> float:
    """Angle [deg] of the horizon in the image, counter-clockwise as seen (image y points down):
    a least-squares line through the first sea row of every column."""
    sea = rs.view_geometry(cams).is_sea[0].numpy()
    H, W = sea.shape
    cols, rows = [], []
    for x in range(W):
        ys = np.nonzero(sea[:, x])[0]
        if 0 < ys.size < H:
            cols.append(x)
            rows.append(ys[0] - 0.5)  # the edge lies between the last sky and the first sea pixel
    slope = np.polyfit(cols, rows, 1)[0]
    return -math.degrees(math.atan(slope))


@pytest.mark.parametrize("roll", [0.0, 10.0, -25.0])
def test_camera_roll_tilts_the_horizon_by_the_roll_angle(roll):
    """A camera rolled by ρ about its optical axis sees the horizon rotated by ρ in the image
    (make_camera: positive roll turns it counter-clockwise). Measured from the sea mask of a
    level 30°-fov camera (the horizon's curvature over 30° is far below a pixel)."""
    cams = rs.make_camera(240, 320, hfov_deg=30.0, altitude_m=20.0, pitch_deg=0.0, roll_deg=roll, dtype=F64)
    assert abs(horizon_tilt_deg(cams) - roll) < 0.3


@pytest.mark.parametrize(
    "call, match",
    [
        (lambda: rs.make_camera(8, 8, altitude_m=0.0), "altitude_m"),
        (lambda: rs.make_camera(8, 8, pitch_deg=95.0), "pitch_deg"),
        (lambda: rs.make_camera(8, 8, hfov_deg=0.0), "hfov_deg"),
        (lambda: rs.view_geometry(rs.make_camera(8, 8), earth_radius_m=-1.0), "earth_radius_m"),
    ],
)
def test_camera_and_geometry_errors(call, match):
    with pytest.raises(ValueError, match=match):
        call()

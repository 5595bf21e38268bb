"""The LED wall's inner frustum against rays cast by hand: from the entrance pupil through the corners
of a pinhole sensor (f_pin behind the pupil, the image inverted) onto a flat wall (a plane) and a
curved wall (a vertical cylinder, solved as a quadratic), with the camera panned, tilted and rolled."""

from __future__ import annotations

import math

import numpy as np
import pytest

from physcam.live.frames import TrackedFrame
from physcam.live.frustum import frustum_frames, wall_from_usd, write_frustum_usd, write_wall

W, H, F_PIN, PUPIL = 27.99, 19.22, 40.0, 85.0  # mm
FILM = (0.3, -0.5, 2.5)  # m, OpenTrackIO stage (Z up)
POSE = (12.0, 4.0, -3.0)  # pan, tilt, roll degrees


def _r(pan, tilt, roll):
    """Rz(pan) Rx(tilt) Ry(roll) written out again here, by the right-hand rule."""
    p, t, r = map(math.radians, (pan, tilt, roll))
    rz = np.array([[math.cos(p), -math.sin(p), 0], [math.sin(p), math.cos(p), 0], [0, 0, 1]])
    rx = np.array([[1, 0, 0], [0, math.cos(t), -math.sin(t)], [0, math.sin(t), math.cos(t)]])
    ry = np.array([[math.cos(r), 0, math.sin(r)], [0, 1, 0], [-math.sin(r), 0, math.cos(r)]])
    return rz @ rx @ ry


def _hand_rays(overscan=0.0):
    """Pupil and unit directions (OpenTrackIO stage, metres) through the sensor's four corners."""
    R = _r(*POSE)
    right, forward, up = R[:, 0], R[:, 1], R[:, 2]  # the camera's axes on the stage at this pose
    film = np.array(FILM)
    pupil = film + forward * PUPIL / 1000.0
    rays = []
    # corners of the upright image, counter-clockwise from bottom-left; the sensor point sits f_pin
    # behind the pupil, mirrored, and the ray runs from it through the pupil
    for u, v in ((-1, -1), (1, -1), (1, 1), (-1, 1)):
        du, dv = u * W / 2 * (1 + overscan), v * H / 2 * (1 + overscan)
        sensor_pt = pupil - forward * F_PIN / 1000.0 - right * du / 1000.0 - up * dv / 1000.0
        d = pupil - sensor_pt
        rays.append(d / np.linalg.norm(d))
    return pupil, np.array(rays)


def _to_usd_cm(p):
    return np.array([p[0], p[2], -p[1]]) * 100.0


def _frame():
    return TrackedFrame(translation_m=FILM, rotation_deg=POSE, pinhole_focal_length_mm=F_PIN, sensor_mm=(W, H),
                        entrance_pupil_mm=PUPIL)


def test_flat_wall_corners_match_hand_cast_rays(tmp_path):
    wall = wall_from_usd(write_wall(tmp_path / "flat.usda", kind="flat", width_m=14, height_m=6, distance_m=5.0))
    fr = frustum_frames([_frame()], wall, overscan=0.0, samples_per_edge=1)[0]
    pupil, rays = _hand_rays()
    t = (5.0 - pupil[1]) / rays[:, 1]  # the plane y = 5 m
    corners = pupil + t[:, None] * rays
    assert fr.missed == 0
    assert np.allclose(fr.footprint, [_to_usd_cm(c) for c in corners], atol=1e-3)  # 0.01 mm


def test_curved_wall_corners_match_hand_cast_rays(tmp_path):
    wall = wall_from_usd(write_wall(tmp_path / "curved.usda", kind="curved", width_m=16, height_m=6, radius_m=7.0,
                                    segments=1024))
    fr = frustum_frames([_frame()], wall, overscan=0.25, samples_per_edge=4)[0]
    pupil, rays = _hand_rays(overscan=0.25)
    # |(p + t d)_xy| = R: a quadratic in t, the far root (the camera is inside the cylinder)
    a = rays[:, 0] ** 2 + rays[:, 1] ** 2
    b = 2 * (pupil[0] * rays[:, 0] + pupil[1] * rays[:, 1])
    c = pupil[0] ** 2 + pupil[1] ** 2 - 7.0 ** 2
    t = (-b + np.sqrt(b * b - 4 * a * c)) / (2 * a)
    corners = pupil + t[:, None] * rays
    got = fr.footprint[::4]  # every fourth point is a corner
    assert fr.missed == 0 and len(fr.footprint) == 16
    # 1024 facets over 131 degrees: the chords sag 0.09 mm inside the circle
    assert np.allclose(got, [_to_usd_cm(c) for c in corners], atol=0.05)
    # the points between the corners lie on the wall too
    on = fr.footprint / 100.0
    assert np.allclose(np.hypot(on[:, 0], on[:, 2]), 7.0, atol=2e-4)


def test_latency_widens_by_the_turn_in_that_time(tmp_path):
    wall = wall_from_usd(write_wall(tmp_path / "flat.usda", kind="flat", width_m=40, height_m=20, distance_m=5.0))
    frames = [TrackedFrame(time_ns=i * 41_666_667, rate=24, translation_m=(0, 0, 1.5), rotation_deg=(i * 1.0, 0, 0),
                           pinhole_focal_length_mm=F_PIN, sensor_mm=(W, H), entrance_pupil_mm=0.0) for i in range(3)]
    fr = frustum_frames(frames, wall, overscan=0.0, latency_s=0.1, samples_per_edge=1)
    omega = math.radians(1.0) / 0.041666667  # rad/s
    half = math.atan(W / 2 / F_PIN)
    assert fr[0].pad_deg == pytest.approx(math.degrees(omega * 0.1), rel=1e-6)
    assert fr[0].widen[0] == pytest.approx(math.tan(half + omega * 0.1) / math.tan(half), rel=1e-6)


def test_the_frustum_is_written_as_time_samples(tmp_path):
    pytest.importorskip("pxr")
    from pxr import Usd, UsdGeom

    wall = wall_from_usd(write_wall(tmp_path / "flat.usda", kind="flat", distance_m=5.0))
    frames = [TrackedFrame(time_ns=i * 41_666_667, rate=24, translation_m=FILM, rotation_deg=(i, 0, 0),
                           pinhole_focal_length_mm=F_PIN, sensor_mm=(W, H), entrance_pupil_mm=PUPIL) for i in range(4)]
    fr = frustum_frames(frames, wall, overscan=0.1, samples_per_edge=2)
    out = write_frustum_usd(tmp_path / "frustum.usda", fr, meters_per_unit=0.01, fps=24)
    stage = Usd.Stage.Open(str(out))
    curve = UsdGeom.BasisCurves(stage.GetPrimAtPath("/Frustum/Footprint"))
    assert curve.GetPointsAttr().GetTimeSamples() == [0.0, 1.0, 2.0, 3.0]
    assert np.allclose(np.array(curve.GetPointsAttr().Get(2.0)), fr[2].footprint, atol=1e-3)
    # the projection camera looks from the pupil along the camera's view
    cam = UsdGeom.Camera(stage.GetPrimAtPath("/Frustum/ProjectionCamera"))
    m = np.array(cam.ComputeLocalToWorldTransform(Usd.TimeCode(2.0)))
    view = -m[2, :3]
    assert np.allclose(m[3, :3], fr[2].pupil, atol=1e-6)
    assert np.allclose(view, fr[2].rotation @ [0, 0, -1.0], atol=1e-6)

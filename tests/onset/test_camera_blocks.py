"""Camera blocks: FOV recomputed from the UsdGeomCamera and RenderMan values and from Gf.Camera."""

import math

import pytest

from physcam.export.renderman import renderman_camera_values
from physcam.export.usdgeom import shutter_interval, usdgeom_camera_values
from physcam.onset.report import solve_lens_report
from physcam.optics.sensors import Sensor, find_sensor

from _thin_lens import fov_deg, image_distance_at_mark


@pytest.fixture(params=[(1.0, "ALEXA 35"), (2.0, "35mm anamorphic"), (1.0, "Super 16")])
def report(request):
    sq, name = request.param
    return solve_lens_report(focal_length_mm=40.0, sensor=find_sensor(name), fstop=2.8, focus_mm=2500.0,
                             squeeze=sq)


@pytest.mark.parametrize("mpu", [0.01, 1.0, 0.0254])
def test_usd_block_fov_matches_gf_camera(report, mpu):
    from pxr import Gf

    v = usdgeom_camera_values(report, mpu)
    hfov = math.degrees(2 * math.atan(v["horizontalAperture"] / (2 * v["focalLength"])))
    vfov = math.degrees(2 * math.atan(v["verticalAperture"] / (2 * v["focalLength"])))
    # the block is the best-match pinhole: the thin lens's framing at its 2.5 m mark, a pinhole s'
    # from the film (hand-solved), which is also the report's FOV at focus
    s_img = image_distance_at_mark(40.0, 2500.0)
    w, h = report.sensor.width_mm * report.squeeze, report.sensor.height_mm
    assert hfov == pytest.approx(fov_deg(w, s_img), abs=1e-9) == pytest.approx(report.hfov_focus_deg, abs=1e-9)
    assert vfov == pytest.approx(fov_deg(h, s_img), abs=1e-9) == pytest.approx(report.vfov_focus_deg, abs=1e-9)
    cam = Gf.Camera()
    cam.focalLength = v["focalLength"]
    cam.horizontalAperture = v["horizontalAperture"]
    cam.verticalAperture = v["verticalAperture"]
    assert cam.GetFieldOfView(Gf.Camera.FOVHorizontal) == pytest.approx(report.hfov_focus_deg, abs=1e-4)
    assert cam.GetFieldOfView(Gf.Camera.FOVVertical) == pytest.approx(report.vfov_focus_deg, abs=1e-4)
    # the aperture diameter focalLength / fStop is the lens's f / N
    assert v["focalLength"] / v["fStop"] == pytest.approx(mm_tenths(40.0 / 2.8, mpu), rel=1e-12)
    # scene units: focus distance in metres * 1/mpu
    assert v["focusDistance"] * mpu * 1000 == pytest.approx(report.object_distance_mm)


def mm_tenths(mm, mpu):
    """mm as tenths of a scene unit of ``mpu`` metres (docs/conventions.md), by hand."""
    return mm / (100.0 * mpu)


def test_usd_units_hand_values():
    r = solve_lens_report(focal_length_mm=50.0, sensor=Sensor("x", "x", 36.0, 24.0), fstop=2.0, focus_mm=3000.0)
    cm = usdgeom_camera_values(r, 0.01)
    m = usdgeom_camera_values(r, 1.0)
    pin = image_distance_at_mark(50.0, 3000.0)  # 50.862 mm: the thin lens's framing at 3 m
    assert cm["focalLength"] == pytest.approx(pin) and m["focalLength"] == pytest.approx(pin / 100.0)
    assert cm["horizontalAperture"] == pytest.approx(36.0) and m["horizontalAperture"] == pytest.approx(0.36)
    # the default clipping range is 100 mm to 10 km (usdgeom_camera_values): 10 cm .. 1e6 cm, 0.1 m .. 1e4 m
    assert cm["clippingRange"] == pytest.approx((10.0, 1e6)) and m["clippingRange"] == pytest.approx((0.1, 1e4))


def test_renderman_block_fov(report):
    rm = renderman_camera_values(report)
    fov = math.radians(rm["Projection"]["fov"])
    l, r, b, t = rm["ScreenWindow"]
    # the screen window spans tan(fov/2) per unit: width of the frame in angle
    hfov = math.degrees(2 * math.atan((r - l) / 2 * math.tan(fov / 2)))
    vfov = math.degrees(2 * math.atan((t - b) / 2 * math.tan(fov / 2)))
    s_img = image_distance_at_mark(40.0, 2500.0)
    assert hfov == pytest.approx(fov_deg(report.sensor.width_mm * report.squeeze, s_img), abs=1e-9)
    assert vfov == pytest.approx(fov_deg(report.sensor.height_mm, s_img), abs=1e-9)
    f = rm["Format"]
    assert f["pixelaspect"] == report.squeeze
    assert f["xres"] * f["pixelaspect"] / f["yres"] == pytest.approx((r - l) / (t - b), rel=2e-3)


def test_shutter_interval():
    assert shutter_interval(180.0) == (0.0, 0.5)
    assert shutter_interval(172.8, "centered") == pytest.approx((-0.24, 0.24))
    assert shutter_interval(360.0, "end") == (-1.0, 0.0)


def test_focus_distance_is_measured_from_the_entrance_pupil():
    # technical model, pupil 95 mm in front of the film, mark 2 m: the camera sits at the pupil,
    # so focusDistance = 2000 - 95 mm = 190.5 cm at metersPerUnit 0.01 (RenderMan likewise)
    r = solve_lens_report(focal_length_mm=50.0, sensor=Sensor("x", "x", 36.0, 24.0), fstop=2.0, focus_mm=2000.0,
                          model="technical", h1_mm=80.0, h2_mm=60.0, pupil_mm=95.0)
    assert usdgeom_camera_values(r, 0.01)["focusDistance"] == pytest.approx(190.5)
    assert renderman_camera_values(r, 1.0)["Projection"]["focalDistance"] == pytest.approx(1.905)


@pytest.mark.parametrize("shift", [(3.0, -2.0), (-1.5, 0.75)])
def test_sensor_shift_moves_the_usd_frustum_and_the_renderman_window_alike(shift):
    # Gf.Camera's frustum window (tangents at unit distance) from the USD block must equal the
    # RenderMan screen window scaled by tan(fov/2) of its unit side.
    from pxr import Gf

    r = solve_lens_report(focal_length_mm=50.0, sensor=Sensor("x", "x", 36.0, 24.0), fstop=2.0, focus_mm=3000.0)
    v = usdgeom_camera_values(r, 0.01, shift_mm=shift)
    cam = Gf.Camera()
    cam.focalLength = v["focalLength"]
    cam.horizontalAperture, cam.verticalAperture = v["horizontalAperture"], v["verticalAperture"]
    cam.horizontalApertureOffset, cam.verticalApertureOffset = v["horizontalApertureOffset"], v["verticalApertureOffset"]
    win = cam.frustum.GetWindow()
    rm = renderman_camera_values(r, 0.01, shift_mm=shift)
    t = math.tan(math.radians(rm["Projection"]["fov"]) / 2)
    l, rr, b, top = (x * t for x in rm["ScreenWindow"])
    assert (win.GetMin()[0], win.GetMax()[0], win.GetMin()[1], win.GetMax()[1]) == pytest.approx((l, rr, b, top),
                                                                                                   abs=1e-6)

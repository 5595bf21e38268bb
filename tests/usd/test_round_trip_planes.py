"""A camera written from a technical report reads back as the same report (pupil, planes, s)."""

import pytest

from physcam.export.usdgeom import usdgeom_camera_values
from physcam.lens.library import load_lens
from physcam.onset.report import solve_lens_report
from physcam.optics.sensors import Sensor, find_sensor
from physcam.usd.author import author_from_report, new_stage
from physcam.usd.read import read_camera

FF = Sensor("ff", "36x24", 36.0, 24.0)
F32 = 1e-5  # USD stores float attributes in 32 bits


def _round_trip(report, mpu=0.01):
    stage = new_stage(mpu)
    author_from_report(stage, "/Cam", report)
    return stage, read_camera(stage, "/Cam").report()


def test_prescription_report_round_trips_pupil_planes_and_s():
    r = solve_lens_report(focal_length_mm=None, sensor=find_sensor("ALEXA 35"), fstop=2.8, focus_mm=3000.0,
                          lens=load_lens("dgauss_50mm"))
    _, back = _round_trip(r)
    assert back.model == "technical"
    assert back.entrance_pupil_from_film_mm == pytest.approx(r.entrance_pupil_from_film_mm, rel=F32)
    assert back.h1_from_film_mm == pytest.approx(r.h1_from_film_mm, rel=F32)
    assert back.object_distance_mm == pytest.approx(r.object_distance_mm, rel=F32)
    assert back.pivot_camera_space_mm[2] == pytest.approx(r.pivot_camera_space_mm[2], rel=F32)


def test_practical_report_keeps_its_pupil_estimate():
    r = solve_lens_report(focal_length_mm=35.0, sensor=FF, fstop=4.0, focus_mm=2500.0, sensor_front_mm=180.0,
                          lens_length_mm=90.0)
    _, back = _round_trip(r)
    assert r.entrance_pupil_from_film_mm == pytest.approx(180.0 - 0.4 * 90.0)
    assert back.entrance_pupil_from_film_mm == pytest.approx(r.entrance_pupil_from_film_mm, rel=F32)
    assert back.object_distance_mm == pytest.approx(r.object_distance_mm, rel=F32)


@pytest.mark.parametrize("mpu", [0.01, 1.0])
def test_no_pupil_falls_back_to_h1_everywhere(mpu):
    # technical model without a pupil: the eye sits at H1 (the thin-lens pupil) for the report's
    # camera block and for the USD camera alike; focusDistance = mark - H1
    r = solve_lens_report(focal_length_mm=50.0, sensor=FF, fstop=2.0, focus_mm=2000.0, model="technical",
                          h1_mm=80.0, h2_mm=60.0)
    assert r.entrance_pupil_from_film_mm is None
    block = usdgeom_camera_values(r, mpu)["focusDistance"]
    assert block * mpu * 1000 == pytest.approx(2000.0 - 80.0)
    stage, back = _round_trip(r, mpu)
    geom = stage.GetPrimAtPath("/Cam/Camera").GetAttribute("focusDistance").Get()
    assert geom == pytest.approx(block, rel=F32)
    assert back.h1_from_film_mm == pytest.approx(80.0, rel=F32)

"""Sensors against the shared reference table; entrance pupil and pivot by hand."""

import csv
import math
from pathlib import Path

import numpy as np
import pytest

from physcam import InputError
from physcam.onset.pupil import entrance_pupil_practical, pivot_camera_space, pivot_world
from physcam.optics.sensors import find_sensor, sensors

REF = Path(__file__).resolve().parents[1] / "data" / "sensor_formats.csv"  # copy of shared/reference/formats


def test_every_sensor_matches_reference_table():
    rows = {r["format"]: r for r in csv.DictReader(REF.open())}
    for s in sensors():
        if s.camera and s.name not in rows:  # the camera table's formats: tests/onset/test_camera_table.py
            continue
        r = rows[s.name]
        assert s.width_mm == float(r["width_mm"]) and s.height_mm == float(r["height_mm"])
        assert s.diagonal_mm == pytest.approx(float(r["diagonal_mm"]), abs=6e-4)
        assert s.diagonal_mm / 1500 == pytest.approx(float(r["coc_d_over_1500_mm"]), abs=6e-5)


@pytest.mark.parametrize("alias, width", [("ALEXA 35", 27.99), ("alexa-35", 27.99), ("S35", 24.89),
                                          ("mini lf", 36.7), ("Super 16", 12.52), ("VENICE 2", 35.94)])
def test_aliases(alias, width):
    assert find_sensor(alias).width_mm == width


def test_pupil_practical_and_pivot():
    # film-to-front 250, lens 150 long, pupil 0.4 of it behind the front: 250 - 60 = 190
    assert entrance_pupil_practical(250.0, 150.0) == pytest.approx(190.0)
    assert entrance_pupil_practical(250.0, 150.0, 0.3) == pytest.approx(205.0)
    assert pivot_camera_space(190.0) == (0.0, 0.0, -190.0)
    # camera turned 90 deg about +Y (looks down -X), at (100, 50, 0) cm: pivot 19 cm along -X
    c, s = math.cos(math.pi / 2), math.sin(math.pi / 2)
    m = np.array([[c, 0, -s, 0], [0, 1, 0, 0], [s, 0, c, 0], [100, 50, 0, 1]])
    p = pivot_world(190.0, m, mm_per_unit=10.0)
    assert p == pytest.approx((100 - 19.0, 50.0, 0.0), abs=1e-9)
    with pytest.raises(InputError):
        entrance_pupil_practical(100.0, 150.0)
    with pytest.raises(InputError):
        entrance_pupil_practical(250.0, 150.0, 1.5)

"""Issue 39 item 9: the Python API reads distances and sensors as the command line does.

`focus_mm="2m"`, `"10ft"`, `"infinity"` and `sensor="ALEXA 35"` failed in the Python API though the
CLI takes them. The numbers: 10 ft is 3048 mm by definition (0.3048 m, international foot); ALEXA 35's
4.6K 3:2 open gate is 27.99 x 19.22 mm (ARRI's published figures, as the sensor table holds them).
"""

from __future__ import annotations

import math

import pytest

from physcam.analysis.distortion.field import real_distortion
from physcam.analysis.defocus.real_dof import real_depth_of_field
from physcam.lens.library import load_lens
from physcam.onset.report import solve_lens_report
from physcam.optics.focusing import focus
from physcam.optics.state import camera_state

pytestmark = pytest.mark.filterwarnings("ignore::physcam.errors.PhysCamWarning")
DGAUSS = load_lens("dgauss_50mm")


def test_report_takes_names_and_distances_with_units():
    r = solve_lens_report(focal_length_mm="50mm", sensor="ALEXA 35", fstop=2.8, focus_mm="10ft", near_mm=None)
    assert r.focus_from_film_mm == 3048.0
    assert (r.sensor.width_mm, r.sensor.height_mm) == (27.99, 19.22)
    same = solve_lens_report(focal_length_mm=50.0, sensor="ALEXA 35", fstop=2.8, focus_mm=3048.0)
    assert r.dof == same.dof
    assert math.isinf(solve_lens_report(lens=DGAUSS, sensor="S35", focus_mm="infinity").focus_from_film_mm)
    r = solve_lens_report(focal_length_mm=50.0, sensor="S35", fstop=4.0, near_mm="2.5m", far_mm="4m")
    assert r.measured == {"near_from_film_mm": 2500.0, "far_from_film_mm": 4000.0}
    assert solve_lens_report(focal_length_mm=50.0, sensor="S35", fstop=4.0, focus_mm="hyperfocal").solved["focus"] \
        == "hyperfocal"


def test_analyses_take_distances_with_units():
    assert camera_state(DGAUSS, focus_mm="2m").focus_from_film_mm == 2000.0
    assert math.isinf(camera_state(DGAUSS, focus_mm="infinity").focus_from_film_mm)
    assert focus(DGAUSS, "10ft").focus_from_film_mm == 3048.0
    assert real_distortion(DGAUSS, [10.0], focus_mm="2m").points == real_distortion(DGAUSS, [10.0],
                                                                                   focus_mm=2000.0).points
    a = real_depth_of_field(camera_state(DGAUSS, focus_mm="3m", fstop=5.6), coc_mm=0.02, grid=32)
    b = real_depth_of_field(camera_state(DGAUSS, focus_mm=3000.0, fstop=5.6), coc_mm=0.02, grid=32)
    assert a == b


def test_a_bad_string_is_a_clear_error():
    from physcam.errors import PhysCamError

    with pytest.raises(PhysCamError, match="cannot read"):
        solve_lens_report(focal_length_mm=50.0, sensor="S35", fstop=4.0, focus_mm="three metres")
    with pytest.raises(PhysCamError):
        solve_lens_report(focal_length_mm=50.0, sensor="no such camera", fstop=4.0, focus_mm="3m")

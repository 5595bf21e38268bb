"""What an f-number means with a bladed iris (docs/conventions.md): the polygon has the area of the
round iris of f/N. Checked against the regular polygon's area in closed form, (n / 2) sin(2 pi / n)
R^2 for corner radius R (Euclid; any geometry table), and against the lens's widest iris."""

from __future__ import annotations

import math

import pytest

from physcam.export.blender import iris_corner_semi
from physcam.lens.library import load_lens
from physcam.optics.paraxial import STOP_OPENING_TOLERANCE
from physcam.optics.state import camera_state
from physcam.trace.aperture import Aperture


@pytest.mark.parametrize("blades", [3, 5, 6, 7, 9, 12])
def test_the_polygon_has_the_round_iris_area(blades):
    """Corners at sqrt(pi / A) of the round iris: (n / 2) sin(2 pi / n) k^2 = pi."""
    k = Aperture(blades).equal_area_scale()
    assert blades / 2 * math.sin(2 * math.pi / blades) * k * k == pytest.approx(math.pi, rel=1e-6)
    assert Aperture(0).equal_area_scale() == 1.0


def test_the_blender_shaders_iris_corner_radius():
    """The double Gauss at f/4 with 6 blades: the corners 1.0996 times f/4's round iris out; at f/2.03
    (its file's stop) the corners stop at the widest iris, the file's stop opened 5 %; round: f/4's."""
    lens = load_lens("dgauss_50mm")
    st = camera_state(lens, focus_mm=3000.0, fstop=4.0, sensor_mm=(36.0, 24.0), aperture=Aperture(6))
    assert iris_corner_semi(st) == pytest.approx(st.stop_semi_diameter * 1.0996361, rel=1e-6)
    wide = camera_state(lens, focus_mm=3000.0, fstop=2.05, sensor_mm=(36.0, 24.0), aperture=Aperture(6))
    file_stop = lens.surfaces[lens.stop_index].semi_diameter
    assert iris_corner_semi(wide) == pytest.approx(file_stop * (1 + STOP_OPENING_TOLERANCE))
    round_ = camera_state(lens, focus_mm=3000.0, fstop=4.0, sensor_mm=(36.0, 24.0))
    assert iris_corner_semi(round_) == round_.stop_semi_diameter

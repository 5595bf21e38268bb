"""The tracer of a camera (physcam.trace.camera_tracer): what it holds and what it answers, against numbers
worked independently of it (closed forms of the iris and of pbrt-v4's camera-ray weight) and against the
tracer's own modules asked directly."""

import math

import numpy as np
import pytest

from physcam.errors import WrongTypeError
from physcam.lens.library import load_lens
from physcam.optics.state import camera_state
from physcam.trace.aperture import Aperture
from physcam.trace.camera_tracer import camera_tracer
from physcam.trace.pupil_bounds import PupilBounds
from physcam.trace.surfaces import surface_table


@pytest.fixture(scope="module")
def dgauss():
    return load_lens("dgauss_50mm")


def test_a_bladed_iris_is_traced_to_the_corners_of_the_round_iris_area(dgauss):
    """A regular n-gon of circumradius R has area (n/2) R^2 sin(2 pi/n); of the area of the round iris of
    radius r when R = r sqrt(2 pi / (n sin(2 pi / n))) (docs/conventions.md: an f-number with blades)."""
    cam = camera_state(dgauss, focus_mm=2000.0, fstop=8.0, aperture=Aperture(6))
    t = camera_tracer(cam)
    n = 6
    corners = cam.stop_semi_diameter * math.sqrt(2 * math.pi / (n * math.sin(2 * math.pi / n)))
    assert t.lens.surfaces[t.lens.stop_index].semi_diameter == pytest.approx(corners, rel=1e-5)
    assert t.aperture is cam.aperture and t.film_z == cam.film_z
    # the rest of the lens is the camera's focused prescription, untouched
    others = [i for i in range(len(t.lens.surfaces)) if i != t.lens.stop_index]
    assert [t.lens.surfaces[i] for i in others] == [cam.focused.surfaces[i] for i in others]


def test_the_film_side_table_is_the_focused_lens_stopped_in_the_table(dgauss):
    """Two routes to one table: the tracer stops the prescription, surface_table can stop the table."""
    cam = camera_state(dgauss, focus_mm=1500.0, fstop=4.0)
    t = camera_tracer(cam)
    ref = surface_table(cam.focused, reverse=True, stop_semi_diameter=cam.stop_semi_diameter, coating="none")
    for name in ("vertex_z", "ax", "ay", "az", "aspheric", "semi_diameter", "kind", "disp_before", "disp_after",
                 "r_scale", "index"):
        np.testing.assert_array_equal(getattr(t.film_side_table, name), getattr(ref, name), err_msg=name)
    assert t.film_side_table is t.film_side_table  # made once, kept


def test_the_centre_weight_is_pbrts_cos4_weight_where_every_ray_passes(dgauss):
    """pbrt-v4's RealisticCamera weight cos^4(theta) A / d^2 (d the film to rear vertex distance, A the aimed
    rectangle's area), averaged over a 16 x 16 grid of cell centres of a 0.2 mm square on the axis: at f/8
    every one of those rays passes, so the mean is this sum worked in numpy."""
    cam = camera_state(dgauss, focus_mm=2000.0, fstop=8.0)
    t = camera_tracer(cam)
    z_rear = t.lens.vertex_z[-1]
    h = 0.1
    square = PupilBounds(np.array([-1.0, 1.0]), np.array([-1.0, 1.0]), np.tile([-h, h, -h, h], (2, 2, 1)), z_rear)
    d = t.film_z - z_rear
    u = (np.arange(16) + 0.5) / 16 * 2 * h - h
    px, py = np.meshgrid(u, u)
    cos_t = d / np.sqrt(px**2 + py**2 + d**2)
    expected = np.mean(cos_t**4) * (2 * h) ** 2 / d**2
    assert t.centre_weight(square, samples=16) == pytest.approx(expected, rel=1e-12)


def test_stopping_down_narrows_the_exit_pupil(dgauss):
    """The exit pupil's rectangle at the film centre shrinks as the f-stop rises (f/2.8 -> 4 -> 8), in
    proportion to the stop's semi-diameter to first order (paraxial: the pupils image the stop)."""
    widths, stops = [], []
    for n in (2.8, 4.0, 8.0):
        cam = camera_state(dgauss, focus_mm=3000.0, fstop=n)
        b = camera_tracer(cam).exit_pupil_bounds(1.0, 1.0, nx=3, ny=3, samples=48)
        x0, x1, _, _ = b.rect_at(0.0, 0.0)
        widths.append(float(x1 - x0))
        stops.append(cam.stop_semi_diameter)
    assert widths[0] > widths[1] > widths[2]
    # one sample spacing of growth either side (pupil_bounds' module notes): 10 % at f/8 here
    assert widths[2] / widths[1] == pytest.approx(stops[2] / stops[1], rel=0.1)


def test_the_tracer_needs_a_camera(dgauss):
    with pytest.raises(WrongTypeError, match="camera"):
        camera_tracer(dgauss)

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


def _six_blades_and_round(fstop=4.0):
    """The double Gauss at f/4 (its round iris well inside the widest, so the corners are not capped),
    with a 6-blade iris and round."""
    lens = load_lens("dgauss_50mm")
    kw = dict(focus_mm=3000.0, fstop=fstop, sensor_mm=(36.0, 24.0))
    return camera_state(lens, aperture=Aperture(6), **kw), camera_state(lens, **kw)


def test_the_camera_states_corner_radius_is_the_shaders():
    """One rule (CameraState.iris_corner_semi) behind the Blender shader's corner radius."""
    hexa, round_ = _six_blades_and_round()
    assert hexa.iris_corner_semi == iris_corner_semi(hexa) == pytest.approx(hexa.stop_semi_diameter * 1.0996361, rel=1e-6)
    assert round_.iris_corner_semi == round_.stop_semi_diameter


def test_a_bladed_bokeh_passes_the_round_iris_light():
    """An on-axis point light's bokeh samples the front element uniformly, so the share of its rays that
    pass is the pupil's area: a 6-blade iris at f/4 passes as many as the round f/4 iris (equal areas,
    closed form above). The hexagon inscribed in the round iris (the analyses' old convention) passed
    (3 sqrt(3) / 2) / pi = 0.827 of them."""
    from physcam.analysis.defocus.bokeh import bokeh_image

    hexa, round_ = _six_blades_and_round()
    got = [bokeh_image(c, 1000.0, 0.0, 0.0, rays=100_000, pixels=48).rays_passed for c in (hexa, round_)]
    assert got[0] / got[1] == pytest.approx(1.0, abs=0.01)


def test_a_bladed_psf_pupil_has_the_round_iris_area():
    """The PSF's pupil (the real pupil's grid, cell-area weights, edges refined) of a 6-blade iris at f/4
    has the round f/4 pupil's area (old convention: 0.827 of it)."""
    from physcam.analysis.image_quality._pupil import _Tracer, make_fields, pupil_box, setup, trace_pupils

    areas = []
    for cam in _six_blades_and_round():
        st = setup(cam)
        tracer = _Tracer(st)
        fl = make_fields(st, [0.0], cam.lens.wavelength_nm)[0]
        pt = trace_pupils(st, [(fl, 64, pupil_box(st, fl, tracer))], tracer)[0]
        areas.append(float(pt.weight.sum()) * pt.cell_mm ** 2)
    assert areas[0] / areas[1] == pytest.approx(1.0, abs=0.01)

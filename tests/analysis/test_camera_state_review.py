"""Findings of the camera-state review (issue 28): a CameraState path must never differ silently from
the lens-and-keywords path, nor turn a bad argument into a Python exception."""

import sys

import pytest

from physcam.errors import InputError, MissingExtraError, WrongTypeError
from physcam.lens.library import load_lens
from physcam.optics.state import camera_state


@pytest.fixture(scope="module")
def canon():
    return load_lens("canon_rf_85mm_f1_2")


def test_a_focused_state_with_another_focus_method_is_refused_not_refocused(canon):
    from physcam.analysis.distortion.stmap import distortion_field

    st = camera_state(canon, focus_mm=900.0, fstop=4.0, sensor_mm=(36.0, 24.0))
    with pytest.raises(InputError, match="focused already"):
        distortion_field(st, width_px=96, height_px=64, maps=False, method="unit")


def test_the_lens_diagram_of_a_state_is_at_the_states_wavelength(canon):
    from physcam.analysis.lens_cards.diagram import lens_diagram

    blue = 486.1327
    got = lens_diagram(camera_state(canon, focus_mm=900.0, fstop=4.0, wavelengths_nm=[blue]))
    with pytest.warns(DeprecationWarning, match=r"lens_diagram\(lens, focus_mm=, fstop=...\) is now"):  # until 0.3
        want = lens_diagram(canon, focus_mm=900.0, fstop=4.0, wavelength_nm=blue)
    assert got.gaussian.wavelength_nm == blue and got.gaussian.efl == want.gaussian.efl


def test_an_iris_shape_that_is_not_one_is_refused_when_the_state_is_made(canon):
    with pytest.raises(WrongTypeError, match="aperture must be an iris shape"):
        camera_state(canon, focus_mm=2000.0, fstop=4.0, aperture=6)


def test_an_explicit_default_sensor_next_to_a_states_own_is_refused(canon):
    from physcam.analysis.image_quality.illumination import relative_illumination
    from physcam.data.default_sensor import DEFAULT_SENSOR_HEIGHT_MM, DEFAULT_SENSOR_WIDTH_MM

    st = camera_state(canon, sensor_mm=(36.0, 24.0))
    with pytest.raises(InputError, match="sensor"):
        relative_illumination(st, sensor_width_mm=float("24.89"), sensor_height_mm=float("18.66"), grid=16)
    assert (float("24.89"), float("18.66")) == (DEFAULT_SENSOR_WIDTH_MM, DEFAULT_SENSOR_HEIGHT_MM)


def test_a_defocus_camera_refuses_a_second_sensor_next_to_the_states(canon):
    from physcam.analysis.defocus.kernels import defocus_camera

    st = camera_state(canon, focus_mm=2000.0, fstop=4.0, sensor_mm=(36.0, 24.0))
    with pytest.raises(InputError, match="own sensor"):
        defocus_camera(st, sensor_width_mm=24.89, width=64, height=36)


def test_cbor_without_the_live_extra_is_said_as_a_missing_extra(monkeypatch):
    from physcam.live.sample import decode_sample

    monkeypatch.setitem(sys.modules, "cbor2", None)
    with pytest.raises(MissingExtraError, match=r"pip install 'physcam\[live\]'"):
        decode_sample(b"\xa0", "cbor", validate=False)


def test_a_lens_centre_offset_that_is_not_numbers_is_an_input_error():
    from physcam.export.tde4 import _offset_cm

    with pytest.raises(InputError, match="two numbers"):
        _offset_cm(("a", 0))

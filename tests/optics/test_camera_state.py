"""CameraState (physcam.optics.state): the lens focused and stopped once, checked once, taken first by
the image-quality analyses (issue 28 item 0).

Oracles: the iris rule's own function (optics.focusing.iris_semi_diameter), the f-number ratio of
internal focusing (optics.focusing.f_number_ratio), the real-ray paraxial image plane
(trace.paraxial_image_z, Richardson-extrapolated axis crossings of traced rays), and the definition
of the f-number at infinity (EFL / entrance-pupil diameter = N).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from physcam.errors import InputError, OpticsError, WrongTypeError
from physcam.lens.library import load_lens
from physcam.optics.focusing import f_number_ratio, iris_semi_diameter
from physcam.optics.state import CameraState, camera_state

DGAUSS = load_lens("dgauss_50mm")
ZUIKO = load_lens("zuiko_18mm_f3_5")  # internal focusing


@pytest.mark.parametrize("lens, mark, n", [(DGAUSS, 2000.0, 4.0), (ZUIKO, 450.0, 4.0), (ZUIKO, math.inf, 8.0)])
def test_one_iris_rule_and_the_f_number_at_the_focus(lens, mark, n):
    s = camera_state(lens, focus_mm=mark, fstop=n)
    assert s.stop_semi_diameter == iris_semi_diameter(lens, n)  # the one rule, sized at infinity focus
    want = n if math.isinf(mark) else n * f_number_ratio(lens, mark)
    assert s.f_number_at_focus == pytest.approx(want, rel=1e-6)
    assert s.focus_from_film_mm == mark and s.lens_name == lens.name


def test_infinity_film_plane_is_the_real_ray_paraxial_image():
    from physcam.trace import paraxial_image_z

    s = camera_state(DGAUSS)
    assert s.at_infinity and s.object_z == -math.inf
    assert s.film_z == pytest.approx(paraxial_image_z(DGAUSS), abs=1e-6)


@settings(max_examples=25, deadline=None)
@given(st.floats(2.0, 22.0))
def test_at_infinity_efl_over_the_pupil_is_the_fstop(n):
    s = camera_state(DGAUSS, fstop=n)
    assert s.gaussian.efl / (2 * s.entrance_pupil_radius) == pytest.approx(n, rel=1e-9)


def test_the_analyses_take_the_state_first_and_agree_with_the_old_door():
    from physcam.analysis.image_quality.mtf import mtf
    from physcam.analysis.image_quality.wavefront import wavefront

    s = camera_state(DGAUSS, focus_mm=2000.0, fstop=4.0)
    a = mtf(s, 14.0, frequencies=[10, 20, 40], pupil_samples=64)
    with pytest.warns(DeprecationWarning, match=r"mtf\(lens, focus_mm=, fstop=...\) is now mtf\(camera_state"):
        b = mtf(DGAUSS, 14.0, frequencies=[10, 20, 40], pupil_samples=64, fstop=4.0, focus_mm=2000.0)
    assert list(a.tangential) == list(b.tangential) and list(a.sagittal) == list(b.sagittal)
    with pytest.warns(DeprecationWarning, match=r"wavefront\(lens, focus_mm=, fstop=...\) is now"):
        old = wavefront(DGAUSS, 0.0, pupil_samples=32, fstop=4.0, focus_mm=2000.0)
    assert wavefront(s, 0.0, pupil_samples=32).rms_waves == old.rms_waves
    with pytest.raises(InputError, match="carries its own"):
        mtf(s, 0.0, frequencies=[10], fstop=8.0)


def test_bad_input_is_one_sentence():
    with pytest.raises(InputError, match="f-stop"):
        camera_state(DGAUSS, fstop=0.2)
    with pytest.raises(OpticsError):
        camera_state(DGAUSS, focus_mm=10.0)  # inside the lens's closest focus
    with pytest.raises(InputError, match="sensor"):
        camera_state(DGAUSS, sensor_mm=(0.0, 24.0))
    for bad in (36.0, (36.0,), "36x24", (36.0, 24.0, 1.0), np.array(36.0), np.float64(36.0)):
        with pytest.raises(InputError, match=r"sensor_mm takes the sensor's \(width, height\) in mm"):
            camera_state(DGAUSS, sensor_mm=bad)
    with pytest.raises(InputError, match="weight"):
        camera_state(DGAUSS, wavelengths_nm=[486.1, 587.6], weights=[1.0])
    with pytest.raises(WrongTypeError):
        camera_state("dgauss_50mm")
    assert isinstance(camera_state(DGAUSS, sensor_mm=(36, 24)), CameraState)


#: (zoom position, EFL at infinity, tolerance mm): focal lengths asked for, and the wide end (encoder 0), which the patent's
#: own label gives as 72.1 mm (US 5,537,259 via the lens file's source note: "72.1-194.01 mm")
@pytest.mark.parametrize("zoom, efl, tol", [("100mm", 100.0, 1e-4), ("135mm", 135.0, 1e-4), (0.0, 72.1, 0.05)])
def test_the_zoom_slot_beside_the_focus(zoom, efl, tol):
    """Issue 43 leaves a zoom position beside the focus (issue 45's phase 2 fills it): a zoom lens's camera
    at a focal length asked for has that EFL at infinity (the zoom position solved on the paraxial EFL,
    physcam.optics.zoom), keeps the position it was given, and a prime refuses any."""
    lens = load_lens("canon_ef_70_200mm_f2_8_zoom")
    cam = camera_state(lens, focus_mm=math.inf, fstop=4.0, zoom=zoom, sensor="S35")
    assert cam.zoom == zoom
    assert cam.at_mark.focal_length_mm == pytest.approx(efl, abs=tol)  # mm
    near = camera_state(lens, focus_mm=3000.0, fstop=4.0, zoom=zoom, sensor="S35")
    assert near.zoom == zoom and near.focus_from_film_mm == 3000.0
    with pytest.raises(InputError, match="not a zoom lens"):
        camera_state(load_lens("dgauss_50mm"), focus_mm=2000.0, fstop=4.0, zoom=0.5)

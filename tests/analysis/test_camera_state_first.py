"""The camera state first (issue 28): the distortion field, the real depth of field, the lens
comparison, the defocus camera, the lens diagram, the thin-lens gap and the light-field camera take
a :class:`physcam.optics.state.CameraState` or a Prescription with its own focus and f-stop.

Oracle: the same function through its old door (a Prescription with ``focus_mm`` / ``fstop``), which
sizes the iris by :func:`physcam.optics.focusing.iris_semi_diameter` through the same one rule, so a
state and its equivalent arguments give identical results; and the rule itself (the state's stop
semi-diameter is ``iris_semi_diameter(lens, N)``). Giving a state and a focus or f-stop is an
InputError; anything but a state or a Prescription is a WrongTypeError.
"""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

from physcam.errors import InputError, WrongTypeError
from physcam.lens.library import load_lens
from physcam.optics.focusing import iris_semi_diameter
from physcam.optics.state import camera_state

DGAUSS = load_lens("dgauss_50mm")
MARK, N = 2000.0, 4.0
STATE = camera_state(DGAUSS, focus_mm=MARK, fstop=N)


def _old_door(name):
    """``name``'s pre-issue-43 door (the lens and its camera keywords): it warns until physcam 0.3."""
    return pytest.warns(DeprecationWarning, match=rf"{name}\(lens, .*\) is now {name}\((camera_state|as_designed)\(lens")


def test_distortion_field_at_a_stop_is_the_same_through_either_door():
    from physcam.analysis.distortion.stmap import distortion_field

    kw = dict(width_px=48, height_px=32, maps=False)
    a = distortion_field(camera_state(DGAUSS, focus_mm=MARK, fstop=N, sensor_mm=(36.0, 24.0)), **kw)
    with _old_door("distortion_field"):
        b = distortion_field(DGAUSS, focus_mm=MARK, fstop=N, sensor_width_mm=36.0, sensor_height_mm=24.0, **kw)
    assert a.fstop == b.fstop == N
    assert np.array_equal(a.traced_ideal_px, b.traced_ideal_px) and a.residual_px == b.residual_px
    # a state made without an f-stop maps chief rays, as a Prescription without one does
    with pytest.warns(DeprecationWarning, match=r"distortion_field\(camera, sensor_width_mm=.*give them to the camera"):
        c = distortion_field(camera_state(DGAUSS, focus_mm=MARK), sensor_width_mm=36.0, sensor_height_mm=24.0, **kw)
    with _old_door("distortion_field"):
        d = distortion_field(DGAUSS, focus_mm=MARK, sensor_width_mm=36.0, sensor_height_mm=24.0, **kw)
    assert c.fstop is None and np.array_equal(c.traced_ideal_px, d.traced_ideal_px)
    with pytest.raises(InputError, match="carries its own"):
        distortion_field(STATE, fstop=2.8, sensor_width_mm=36.0, sensor_height_mm=24.0, **kw)
    with pytest.raises(InputError, match="sensor"):
        distortion_field(STATE, **kw)  # no sensor in the state, none given
    with pytest.raises(WrongTypeError):
        distortion_field("dgauss_50mm", sensor_width_mm=36.0, sensor_height_mm=24.0, **kw)


def test_real_blur_is_the_same_through_either_door():
    from physcam.analysis.defocus.real_dof import blur_diameter_mm, real_depth_of_field

    a = blur_diameter_mm(STATE, 1000.0, image_height_mm=5.0)
    with _old_door("blur_diameter_mm"):
        b = blur_diameter_mm(DGAUSS, 1000.0, focus_mm=MARK, fstop=N, image_height_mm=5.0)
    assert a == b > 0
    with pytest.raises(InputError, match="carries its own"):
        real_depth_of_field(STATE, focus_mm=MARK, coc_mm=0.03)
    with _old_door("real_depth_of_field"), pytest.raises(InputError, match="focus_mm and fstop"):
        real_depth_of_field(DGAUSS, fstop=N, coc_mm=0.03)
    with pytest.raises(InputError, match="focus mark"):
        blur_diameter_mm(camera_state(DGAUSS, fstop=N), 1000.0)  # a state at infinity has no finite mark
    with pytest.raises(WrongTypeError):
        real_depth_of_field(object(), coc_mm=0.03)


def test_defocus_camera_is_the_same_through_either_door():
    from physcam.analysis.defocus.kernels import defocus_camera

    s = camera_state(DGAUSS, focus_mm=MARK, fstop=2.8, sensor_mm=(36.0, 24.0))
    a = defocus_camera(s, width=128, height=72)
    with _old_door("defocus_camera"):
        b = defocus_camera(DGAUSS, focus_mm=MARK, fstop=2.8, sensor_width_mm=36.0, width=128, height=72)
    assert a.key() == b.key()  # every input the kernels depend on
    assert (a.film_z, a.stop_semi, a.pinhole_mm, a.pupil_from_film_mm) == (b.film_z, b.stop_semi, b.pinhole_mm,
                                                                           b.pupil_from_film_mm)
    assert a.stop_semi == iris_semi_diameter(DGAUSS, 2.8)  # the one rule
    from physcam.trace.aperture import Aperture

    six = defocus_camera(camera_state(DGAUSS, focus_mm=MARK, fstop=2.8, sensor_mm=(36.0, 24.0), aperture=Aperture(6)),
                         width=128, height=72)  # the state's iris shape
    with _old_door("defocus_camera"):
        old_six = defocus_camera(DGAUSS, focus_mm=MARK, fstop=2.8, sensor_width_mm=36.0, width=128, height=72,
                                 aperture=6)
    assert six.key() == old_six.key() != a.key()
    with pytest.raises(InputError, match="carries its own"):
        defocus_camera(s, fstop=2.8, width=128, height=72)
    with pytest.raises(InputError, match="sensor"):
        defocus_camera(STATE, width=128, height=72)
    with pytest.raises(WrongTypeError):
        defocus_camera([1, 2], focus_mm=MARK, fstop=2.8, sensor_width_mm=36.0, width=128, height=72)


def test_lens_diagram_is_the_same_through_either_door():
    from physcam.analysis.lens_cards.diagram import lens_diagram

    a = lens_diagram(STATE, rays=3)
    with _old_door("lens_diagram"):
        b = lens_diagram(DGAUSS, focus_mm=MARK, fstop=N, rays=3)
    assert (a.fstop, a.focus_from_film_mm) == (b.fstop, b.focus_from_film_mm) == (N, MARK)
    assert a.rays == b.rays
    assert a.prescription.surfaces[DGAUSS.stop_index].semi_diameter == pytest.approx(iris_semi_diameter(DGAUSS, N),
                                                                                    rel=1e-12)
    c = lens_diagram(camera_state(DGAUSS), rays=3)  # no f-stop: the stop as in the file
    assert c.fstop is None and math.isinf(c.focus_from_film_mm) and c.rays == lens_diagram(DGAUSS, rays=3).rays
    with pytest.raises(InputError, match="carries its own"):
        lens_diagram(STATE, focus_mm=MARK)
    with pytest.warns(DeprecationWarning, match="focus_mm"):  # the old name, for one version
        assert lens_diagram(DGAUSS, focus_from_film_mm=MARK, fstop=N, rays=3).rays == b.rays
    with pytest.raises(WrongTypeError):
        lens_diagram("dgauss_50mm")


def test_light_field_camera_is_the_same_through_either_door():
    from physcam.trace.microlens import main_lens_state, microlens_array, plenoptic_camera

    arr = microlens_array(5, 5, 1.0, 1.0, focal_length_mm=0.2)
    s = main_lens_state(DGAUSS, arr, focus_mm=1000.0, fstop=N)
    a = plenoptic_camera(s, arr)
    b = plenoptic_camera(DGAUSS, arr, focus_mm=1000.0, fstop=N)
    assert (a.z_sensor, a.stop_semi_diameter) == (b.z_sensor, b.stop_semi_diameter)
    assert a.main.surfaces == b.main.surfaces
    assert s.focus_from_film_mm == 1000.0 - arr.sensor_offset_mm  # the mark from the array, the main lens's film
    with pytest.raises(InputError, match="carries its own"):
        plenoptic_camera(s, arr, fstop=2.8)
    with pytest.raises(InputError, match="carries its own"):
        plenoptic_camera(s, arr, film_to_lens_mm=40.0)
    with pytest.raises(WrongTypeError):
        main_lens_state("dgauss_50mm", arr, focus_mm=1000.0)


def test_lens_measurements_are_the_same_through_either_door():
    from physcam.onset.lens_compare import lens_measurements
    from physcam.optics.sensors import find_sensor

    ff = find_sensor("FF")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        a = lens_measurements(STATE, sensor=ff, rays=4000)
        b = lens_measurements(DGAUSS, focus_mm=MARK, fstop=N, sensor=ff, rays=4000)
    a.pop("_curves"), b.pop("_curves")
    assert a == b and a["fstop"] == N
    with pytest.raises(InputError, match="carries its own"):
        lens_measurements(STATE, fstop=N, sensor=ff)
    with pytest.raises(WrongTypeError):
        lens_measurements("dgauss_50mm", focus_mm=MARK, fstop=N, sensor=ff)


def test_thin_lens_gap_takes_the_reports_camera_state():
    from physcam.onset.thin_lens_gap import thin_lens_gap
    from physcam.onset.report import solve_lens_report
    from physcam.optics.sensors import find_sensor

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        r = solve_lens_report(focal_length_mm=None, lens=DGAUSS, sensor=find_sensor("Super 35"), fstop=8.0,
                              focus_mm=MARK)
    def old():
        return pytest.warns(DeprecationWarning, match=r"thin_lens_gap\(report, lens\): .*call thin_lens_gap\(report\)")

    with old():
        a = thin_lens_gap(r, camera_state(DGAUSS, focus_mm=MARK, fstop=8.0))
    with old():
        b = thin_lens_gap(r, DGAUSS)
    assert a.bokeh == b.bokeh == thin_lens_gap(r).bokeh and a.hfov_difference_pct == b.hfov_difference_pct
    with old(), pytest.raises(InputError, match="not the report's"):
        thin_lens_gap(r, STATE)  # f/4, the report's f/8
    with old(), pytest.raises(WrongTypeError):
        thin_lens_gap(r, "dgauss_50mm")


def test_the_old_doors_warning_names_a_call_that_works():
    """The DeprecationWarning of an old door spells the new call with camera_state's own keywords: the
    sensor's two sizes are one ``sensor_mm=(width, height)`` there (a user who followed ``sensor_width_mm=`` got a
    TypeError; one who wrote ``sensor_mm=36.0`` for it got another, now a sentence)."""
    from physcam.analysis.distortion.stmap import distortion_field

    kw = dict(width_px=48, height_px=32, maps=False)
    with pytest.warns(DeprecationWarning) as caught:
        old = distortion_field(DGAUSS, focus_mm=MARK, sensor_width_mm=36.0, sensor_height_mm=24.0, **kw)
    (message,) = [str(w.message) for w in caught if issubclass(w.category, DeprecationWarning)]
    assert "is now distortion_field(camera_state(lens, focus_mm=, sensor_mm=(width, height)...))" in message, message
    assert "sensor_width_mm" not in message.split("is now", 1)[1], message
    with pytest.raises(InputError, match=r"sensor_mm takes the sensor's \(width, height\)"):
        camera_state(DGAUSS, focus_mm=MARK, sensor_mm=36.0)  # the width alone, as sensor_width_mm took it
    new = distortion_field(camera_state(DGAUSS, focus_mm=MARK, sensor_mm=(36.0, 24.0)), **kw)  # the call it names
    assert np.array_equal(old.traced_ideal_px, new.traced_ideal_px)


def test_an_old_door_without_a_focus_names_as_designed_and_gives_its_numbers():
    """Without a focus mark or a film plane the old form is the lens as its file focuses it (each analysis puts
    the film by its own rule): the warning names :func:`physcam.optics.state.as_designed`, whose camera gives
    the same blur off the design wavelength, where ``camera_state`` (film at the design wavelength's image) differs."""
    from physcam.analysis.image_quality.spot import spot_diagram
    from physcam.optics.state import as_designed

    with pytest.warns(DeprecationWarning, match=r"is now spot_diagram\(as_designed\(lens, fstop=\.\.\.\)\)") as caught:
        old = spot_diagram(DGAUSS, fstop=N, wavelength_nm=486.1327)
    assert len([w for w in caught if issubclass(w.category, DeprecationWarning)]) == 1
    new = spot_diagram(as_designed(DGAUSS, fstop=N), wavelength_nm=486.1327)
    assert old.film_z_mm == new.film_z_mm and old.fields[0].rms_radius_um == new.fields[0].rms_radius_um
    other = spot_diagram(camera_state(DGAUSS, fstop=N), wavelength_nm=486.1327)
    assert other.film_z_mm != old.film_z_mm  # why the warning does not name camera_state here

"""Exporters take one CameraState (issue 28): a state and the equivalent (lens, focus, f-stop, sensor)
write the same files; a state with its own focus given again, or neither a state nor a lens, is an
error with a sentence; the old keyword ``focus_from_film_mm`` still works for one version."""

from __future__ import annotations

import math
import warnings

import pytest

from physcam.errors import InputError, WrongTypeError
from physcam.export.blender import bake_camera, osl_camera_shader, write_blender_camera
from physcam.export.blender_compare import compare_bokeh
from physcam.export.opencv_distortion import fit_opencv_pinhole
from physcam.export.pbrt import pbrt_thick_lens
from physcam.lens.library import load_lens
from physcam.optics.focusing import focus, iris_semi_diameter
from physcam.optics.state import camera_state
from physcam.trace.aperture import Aperture

SENSOR = (24.0, 18.0)


@pytest.mark.parametrize("slug, mark, fstop, aperture", [
    ("navarro_anamorphic_2x", 4000.0, 4.0, None),  # internal focus, cylinders
    ("canon_rf_85mm_f1_2", 1500.0, None, Aperture(7, 10.0, 0.2)),  # the file's stop: "open"
    ("zeiss_distagon_35mm_f4", math.inf, 8.0, None),  # unit focus, at infinity
])
def test_a_camera_state_writes_the_same_osl_as_its_lens_focus_and_stop(slug, mark, fstop, aperture):
    lens = load_lens(slug)
    state = camera_state(lens, focus_mm=mark, fstop=fstop, sensor_mm=SENSOR, aperture=aperture)
    by_state = osl_camera_shader(state, dispersion=True)
    with pytest.warns(DeprecationWarning, match=r"is now osl_camera_shader\(camera_state\(lens"):  # until physcam 0.3
        by_lens = osl_camera_shader(lens, focus_mm=mark, fstop=fstop, sensor_width_mm=SENSOR[0],
                                    sensor_height_mm=SENSOR[1], aperture=aperture, dispersion=True)
    assert by_state == by_lens
    assert (", open;" in by_state) == (fstop is None)  # the header names the stop as the lens path did


def test_write_blender_camera_from_a_state_writes_the_same_files(tmp_path):
    lens = load_lens("dgauss_50mm")
    kw = dict(resolution=(360, 270), name="cam")
    a = write_blender_camera(camera_state(lens, focus_mm=2000.0, fstop=4.0, sensor_mm=SENSOR), tmp_path / "a", **kw)
    # the pre-issue-43 form (out_dir first, the lens and its keywords), until physcam 0.3
    with pytest.warns(DeprecationWarning, match="the old order goes"), \
            pytest.warns(DeprecationWarning, match="camera_state"):
        b = write_blender_camera(tmp_path / "b", lens, focus_mm=2000.0, fstop=4.0, sensor_width_mm=SENSOR[0],
                                 sensor_height_mm=SENSOR[1], **kw)
    assert [p.name for p in a] == [p.name for p in b] == ["cam.osl", "setup_cam.py"]
    for pa, pb in zip(a, b):
        assert pa.read_text() == pb.read_text()


def test_the_state_is_baked_as_physcams_focus_and_iris():
    """Independently: physcam's focus solution at the mark and the one iris rule at f/4."""
    lens = load_lens("zuiko_18mm_f3_5")  # internal focus
    b = bake_camera(camera_state(lens, focus_mm=450.0, fstop=4.0, sensor_mm=SENSOR))
    st = focus(lens, 450.0)
    assert b.film_z == st.film_z
    assert b.lens.vertex_z == pytest.approx(st.prescription.vertex_z, abs=0)
    assert b.lens.surfaces[b.lens.stop_index].semi_diameter == iris_semi_diameter(lens, 4.0)
    assert (b.sensor_width_mm, b.sensor_height_mm, b.focus_mm, b.fstop) == (24.0, 18.0, 450.0, 4.0)


def test_giving_a_state_and_its_settings_again_is_an_input_error():
    lens = load_lens("dgauss_50mm")
    state = camera_state(lens, focus_mm=2000.0, fstop=4.0, sensor_mm=SENSOR)
    for kw in (dict(focus_mm=3000.0), dict(fstop=2.8), dict(sensor_width_mm=36.0, sensor_height_mm=24.0)):
        with pytest.raises(InputError, match="CameraState carries its own"):
            osl_camera_shader(state, **kw)
    with pytest.raises(InputError, match="needs a sensor"):
        osl_camera_shader(camera_state(lens, focus_mm=2000.0))
    with pytest.raises(InputError, match="CameraState carries its own"):
        pbrt_thick_lens(state, 3000.0)
    with pytest.raises(InputError, match="CameraState carries its own"):
        pbrt_thick_lens(state, aperture_diameter_mm=10.0)
    with pytest.raises(InputError, match="CameraState carries its own"):
        fit_opencv_pinhole(state, 36.0, 24.0, 1920, 1080)
    with pytest.raises(InputError, match="CameraState carries its own"):
        fit_opencv_pinhole(state, image_width_px=1920, image_height_px=1080, method="unit")
    with pytest.raises(InputError, match="CameraState carries its own"):  # before any Blender is looked for
        compare_bokeh(state, focus_mm=2000.0, light_mm=700.0, blender_python="/nonexistent/python")


def test_neither_a_state_nor_a_lens_is_a_wrong_type_error(tmp_path):
    for call in (lambda: osl_camera_shader("dgauss_50mm", focus_mm=2000.0, sensor_width_mm=36.0, sensor_height_mm=24.0),
                 lambda: bake_camera({"focus_mm": 2000.0}),
                 lambda: write_blender_camera(tmp_path, "dgauss_50mm", focus_mm=2000.0),
                 lambda: pbrt_thick_lens("dgauss_50mm", 2000.0),
                 lambda: fit_opencv_pinhole(None, 36.0, 24.0, 1920, 1080),
                 lambda: compare_bokeh("dgauss_50mm", focus_mm=2000.0, fstop=4.0, light_mm=700.0)):
        with pytest.raises(WrongTypeError, match="CameraState"):
            call()


def test_pbrt_thick_lens_of_a_state_is_pbrts_refocus_of_physcams_focus():
    """The state stands for the lens pbrt gets from `export pbrt`: physcam's focus at the mark (its back
    focus the last thickness), the iris of the one rule, the film diagonal of the state's sensor."""
    lens = load_lens("dgauss_50mm")
    state = camera_state(lens, focus_mm=2000.0, fstop=2.8, sensor_mm=(36.0, 24.0))
    by_hand = pbrt_thick_lens(focus(lens, 2000.0).prescription, focus_mm=2000.0,
                              aperture_diameter_mm=2.0 * iris_semi_diameter(lens, 2.8),
                              film_diagonal_mm=math.hypot(36.0, 24.0))
    assert pbrt_thick_lens(state) == by_hand
    with pytest.raises(InputError, match="finite"):
        pbrt_thick_lens(camera_state(lens, fstop=2.8))


def test_focus_from_film_mm_still_works_with_a_deprecation_warning():
    lens = load_lens("dgauss_50mm")
    new = pbrt_thick_lens(lens, focus_mm=2000.0)
    with pytest.warns(DeprecationWarning, match="focus_mm"):
        old = pbrt_thick_lens(lens, focus_from_film_mm=2000.0)
    assert old == new == pbrt_thick_lens(lens, 2000.0)
    with pytest.warns(DeprecationWarning, match="focus_from_film_mm goes in physcam 0.3"):
        cam_old = fit_opencv_pinhole(lens, 36.0, 24.0, 960, 640, focus_from_film_mm=3000.0)
    assert cam_old == fit_opencv_pinhole(lens, 36.0, 24.0, 960, 640, focus_mm=3000.0)
    with pytest.raises(InputError, match="give focus_mm, not both"):
        pbrt_thick_lens(lens, focus_mm=2000.0, focus_from_film_mm=2000.0)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # the new name warns about nothing
        pbrt_thick_lens(lens, focus_mm=2000.0)


def test_fit_opencv_pinhole_of_a_state_is_the_fit_at_its_mark_and_sensor():
    lens = load_lens("navarro_anamorphic_2x")
    state = camera_state(lens, focus_mm=4000.0, sensor_mm=(24.0, 18.0))
    assert fit_opencv_pinhole(state, image_width_px=960, image_height_px=720) == \
        fit_opencv_pinhole(lens, 24.0, 18.0, 960, 720, focus_mm=4000.0)


def _old_door_shader(lens):
    with pytest.warns(DeprecationWarning, match=r"is now osl_camera_shader\(camera_state\(lens"):  # until physcam 0.3
        return osl_camera_shader(lens, focus_mm=2000.0, sensor_width_mm=36.0, sensor_height_mm=24.0, aperture=6)


def test_the_iris_shape_in_the_state_or_beside_it_is_the_same_iris():
    """A six-blade iris in the state, or a number of blades (the shader's shorthand) given with a round
    state or with the lens: one six-blade iris in the shader. (A state holds an iris shape, not a
    number: camera_state refuses 6, which the ray analyses could not trace.)"""
    from physcam.trace.aperture import Aperture

    lens = load_lens("dgauss_50mm")
    kw = dict(focus_mm=2000.0, sensor_mm=(36.0, 24.0))
    texts = {osl_camera_shader(camera_state(lens, aperture=Aperture(6), **kw)),
             osl_camera_shader(camera_state(lens, **kw), aperture=6),
             _old_door_shader(lens)}
    assert len(texts) == 1
    assert f"#define AP_WEDGE {2 * math.pi / 6!r}\n" in texts.pop()

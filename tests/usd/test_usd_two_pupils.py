"""An anamorphic's two entrance pupils in USD and in Unreal's lens file (issue 49).

The oracle is the hand y-u trace of each meridian (tests/_anamorphic_yu.py); written stages are checked
by usd-core's validators."""

from __future__ import annotations

import math

import pytest

from physcam.lens.library import load_lens
from physcam.onset.report import solve_lens_report
from physcam.optics.sensors import find_sensor

from _anamorphic_yu import hand_pupils_from_film

pxr = pytest.importorskip("pxr")
from pxr import Usd  # noqa: E402

from physcam.usd.author import spec_from_report, write_camera  # noqa: E402
from physcam.usd.read import read_camera  # noqa: E402
from physcam.usd.validate import validation_errors  # noqa: E402

LP = "lens:main:"


def _report(slug, mark=3000.0):
    return solve_lens_report(focal_length_mm=None, sensor=find_sensor("ALEXA 35"), fstop=2.8, focus_mm=mark,
                             lens=load_lens(slug))


@pytest.mark.filterwarnings("ignore::UserWarning")
def test_usd_carries_the_pan_pivot_beside_the_eye(tmp_path):
    x, y = hand_pupils_from_film("neil_front_anamorphic_2x", 3000.0)
    out = write_camera(tmp_path / "neil.usda", spec_from_report(_report("neil_front_anamorphic_2x")))
    stage = Usd.Stage.Open(str(out))
    assert validation_errors(stage) == []
    cam = stage.GetPrimAtPath("/Cameras/Camera")
    assert cam.GetAttribute(LP + "entrancePupilDistance").Get() == pytest.approx(y, abs=0.01)
    attr = cam.GetAttribute(LP + "horizontalEntrancePupilDistance")
    assert attr.Get() == pytest.approx(x, abs=0.01) and x - y > 20.0
    # a schema attribute of PhysicalCameraLensAPI (no custom attribute): its definition carries the doc
    doc = cam.GetPrimDefinition().GetAttributeDefinition(LP + "horizontalEntrancePupilDistance").GetDocumentation()
    assert not attr.IsCustom() and "pivot of a pan" in doc
    assert read_camera(stage, "/Cameras/Camera").spec.horizontal_entrance_pupil_mm == pytest.approx(x, abs=0.01)
    # the companion camera's eye stays the vertical pupil
    geom = stage.GetPrimAtPath("/Cameras/Camera/Camera")
    eye_cm = -geom.GetAttribute("xformOp:translate").Get()[2]
    assert eye_cm * 10.0 == pytest.approx(y, abs=0.01)


@pytest.mark.filterwarnings("ignore::UserWarning")
def test_a_spherical_lens_authors_one_pupil(tmp_path):
    out = write_camera(tmp_path / "dg.usda", spec_from_report(_report("dgauss_50mm")))
    stage = Usd.Stage.Open(str(out))
    assert validation_errors(stage) == []
    cam = stage.GetPrimAtPath("/Cameras/Camera")
    assert cam.GetAttribute(LP + "entrancePupilDistance").HasAuthoredValue()
    assert not cam.GetAttribute(LP + "horizontalEntrancePupilDistance").HasAuthoredValue()


@pytest.mark.filterwarnings("ignore::UserWarning")
def test_unreal_nodal_offset_is_the_vertical_pupil_and_the_file_says_where_the_pan_pivot_is():
    from physcam.export.unreal import parse_parameter_table, unreal_lens_file

    marks = [math.inf, 3000.0]
    doc = unreal_lens_file(load_lens("neil_front_anamorphic_2x"), 24.89, 18.66, image_width_px=512,
                           image_height_px=384, focus_marks_mm=marks)
    nodal = next(t for t in doc["cameraParameterTables"] if t["parameterName"] == "NodalOffsetTable")
    header, rows = parse_parameter_table(nodal)
    for row, mark, m in zip(rows, marks, doc["physcam"]["marks"]):
        x, y = hand_pupils_from_film("neil_front_anamorphic_2x", mark)
        assert row[header.index("Tz")] * 10.0 == pytest.approx(y, abs=0.01)
        assert m["entrance_pupil_horizontal_from_film_mm"] == pytest.approx(x, abs=0.01)
    note = next(e["value"] for e in doc["metadata"]["userMetadata"] if e["name"] == "physcam.nodalOffset")
    assert "horizontal (X, pan)" in note


@pytest.mark.filterwarnings("ignore::UserWarning")
def test_a_focus_pull_animates_both_pupils(tmp_path):
    from physcam.usd.animate import FocusKey, write_animated_camera

    slug, keys = "neil_front_anamorphic_2x", [FocusKey(1, 3000.0), FocusKey(25, 1500.0)]
    out = write_animated_camera(tmp_path / "pull.usda", keys, sensor=find_sensor("ALEXA 35"), lens=load_lens(slug),
                                fstop=2.8)
    stage = Usd.Stage.Open(str(out))
    assert validation_errors(stage) == []
    cam = stage.GetPrimAtPath("/Cameras/Camera")
    for k in keys:
        x, y = hand_pupils_from_film(slug, k.focus_mm)
        assert cam.GetAttribute(LP + "horizontalEntrancePupilDistance").Get(k.frame) == pytest.approx(x, abs=0.01)
        assert cam.GetAttribute(LP + "entrancePupilDistance").Get(k.frame) == pytest.approx(y, abs=0.01)


@pytest.mark.filterwarnings("ignore::UserWarning")
def test_a_shot_with_a_vendor_anamorphic_has_both_pupils_and_loses_the_second_with_a_spherical(tmp_path):
    from physcam.usd.author import CameraSpec
    from physcam.usd.kit import refresh_shot, write_body_file, write_shot, write_vendor_lens

    slug = "neil_front_anamorphic_2x"
    lens_f = write_vendor_lens(tmp_path / "lens.usda", load_lens(slug), focus_mm=3000.0, fstop=2.8)
    body_f = write_body_file(tmp_path / "body.usda", CameraSpec.of(sensor_width_mm=27.99, sensor_height_mm=19.22))
    shot = write_shot(tmp_path / "shot.usda", body_f, lens_f)
    x, y = hand_pupils_from_film(slug, 3000.0)
    stage = Usd.Stage.Open(str(shot))
    assert validation_errors(stage) == []
    cam = stage.GetPrimAtPath("/Cameras/Shot")
    assert cam.GetAttribute(LP + "horizontalEntrancePupilDistance").Get() == pytest.approx(x, abs=0.01)
    assert cam.GetAttribute(LP + "entrancePupilDistance").Get() == pytest.approx(y, abs=0.01)
    del cam, stage
    # the lens file now holds a spherical lens: the refreshed shot keeps no stale pan pivot
    write_vendor_lens(lens_f, load_lens("dgauss_50mm"), focus_mm=3000.0, fstop=2.8, force=True)
    refresh_shot(shot)
    stage = Usd.Stage.Open(str(shot))
    stage.Reload()
    cam = stage.GetPrimAtPath("/Cameras/Shot")
    assert cam.GetAttribute(LP + "entrancePupilDistance").Get() < 100.0
    assert cam.GetAttribute(LP + "horizontalEntrancePupilDistance").Get() is None

"""A lens file from a maker's characterization CSV without an entrance pupil invents none (first-day
walkthrough, round 9: it kept the thin-lens pupil at the default 3 m focus, 50.86 mm for a 50 mm lens).

Oracle: the thin lens worked by hand (tests/_thin_lens.py): focused at a mark D from the film, a thin
lens (and its pupil) sits s' = (D - sqrt(D^2 - 4 f D)) / 2 in front of the film. The lens file leaves the
pupil unauthored and says so; the shot that composes it puts its film s' behind the pupil at the
shot's own focus, in scene units (cm here).
"""

from __future__ import annotations

import pytest

from physcam.cli import main
from physcam.usd.author import CameraSpec
from physcam.usd.kit import write_body_file, write_shot
from physcam.usd.read import open_stage, read_camera
from physcam.usd.validate import validation_errors

from _thin_lens import image_distance_at_mark

PUPIL_UNKNOWN_KEY = "physcam:entrancePupil"  # the lens prim's customData saying the pupil is unknown


def test_a_csv_without_pupil_writes_none_and_the_shot_computes_it(tmp_path, capsys):
    csv = tmp_path / "maker.csv"
    csv.write_text("date,focal_length_mm,fstop\n2026-03-01,50,2.8\n", encoding="utf-8")
    lens_f = tmp_path / "lens.usda"
    assert main(["usd", "kit", "lens", str(lens_f), "--characterizations", str(csv)]) == 0
    stage = open_stage(lens_f)
    assert not validation_errors(stage)
    lens = stage.GetPrimAtPath("/Lens")
    for variant in ("d2026_03_01", "current"):
        lens.GetVariantSets().GetVariantSet("characterization").SetVariantSelection(variant)
        assert not lens.GetAttribute("lens:main:entrancePupilDistance").HasAuthoredValue()
        assert "unknown" in lens.GetCustomDataByKey(PUPIL_UNKNOWN_KEY)
    assert "entrance pupil is left unknown" in capsys.readouterr().err

    body_f = write_body_file(tmp_path / "body.usda", CameraSpec.of(sensor_width_mm=24.89, sensor_height_mm=18.66))
    shot = write_shot(tmp_path / "shot.usda", body_f, lens_f, overrides={"focus_mm": 2000.0})
    s = open_stage(shot)
    assert not validation_errors(s)
    assert read_camera(s, "/Cameras/Shot").spec.entrance_pupil_mm is None  # unknown: not the schema's 50 mm
    op = s.GetPrimAtPath("/Cameras/Shot").GetAttribute("xformOp:translate:pupilToFilm").Get()
    assert op[2] == pytest.approx(image_distance_at_mark(50.0, 2000.0) / 10.0, rel=1e-9)  # 5.1317 cm, not 5.086


def test_a_csv_with_a_pupil_keeps_it(tmp_path):
    csv = tmp_path / "maker.csv"
    csv.write_text("date,focal_length_mm,fstop,entrance_pupil_mm\n2026-03-01,50,2.8,97.5\n", encoding="utf-8")
    lens_f = tmp_path / "lens.usda"
    assert main(["usd", "kit", "lens", str(lens_f), "--characterizations", str(csv)]) == 0
    stage = open_stage(lens_f)
    lens = stage.GetPrimAtPath("/Lens")
    assert lens.GetAttribute("lens:main:entrancePupilDistance").Get() == pytest.approx(97.5)
    assert lens.GetCustomDataByKey(PUPIL_UNKNOWN_KEY) is None


def test_a_datasheet_without_pupil_writes_none(tmp_path, capsys):
    """`usd write` of a datasheet (H1, H2, no --pupil): the report says the pupil is unknown, and so does
    the file (it used to write H1 as the pupil); the camera is still placed at H1, 90 mm = 9 cm."""
    import json

    f = tmp_path / "sheet.usda"
    assert main(["usd", "write", str(f), "--focal", "50", "--model", "technical", "--h1", "90", "--h2", "60",
                 "--fstop", "2.8", "--focus", "3m", "--sensor", "S35"]) == 0
    stage = open_stage(f)
    assert not validation_errors(stage)
    cam = stage.GetPrimAtPath("/Cameras/Camera")
    assert not cam.GetAttribute("lens:main:entrancePupilDistance").HasAuthoredValue()
    assert "unknown" in cam.GetCustomDataByKey(PUPIL_UNKNOWN_KEY)
    assert cam.GetAttribute("xformOp:translate:pupilToFilm").Get()[2] == pytest.approx(9.0)
    capsys.readouterr()
    assert main(["usd", "read", str(f), "--json"]) == 0
    report = json.loads(capsys.readouterr().out)["report"]
    assert report["entrance_pupil_source"] == "unknown" and report["entrance_pupil_from_film_mm"] is None

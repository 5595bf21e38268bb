"""Animated cameras (issue 9): a focus pull's time samples follow the lens's breathing."""

from __future__ import annotations

import json

import pytest
from pxr import Usd, UsdGeom

from physcam.cli import main
from physcam.errors import InputError, LensFileError, PhysCamError
from physcam.usd.read import open_stage

from _thin_lens import image_distance_at_mark

MARKS = [5000.0 + (1000.0 - 5000.0) * i / 47 for i in range(48)]  # 5 m to 1 m over 48 frames


def _csv(tmp_path, rows, header="frame,focus"):
    f = tmp_path / "pull.csv"
    f.write_text(header + "\n" + "\n".join(rows) + "\n")
    return f


def test_focus_pull_samples_match_lens_breathing(tmp_path, capsys):
    """Done when: a focus pull from 5 m to 1 m over 48 frames writes time samples whose per-frame
    focal length and pupil match `physcam lens breathing` at each mark."""
    marks = _csv(tmp_path, [f"{i + 1},{m:.6f}mm" for i, m in enumerate(MARKS)])
    out = tmp_path / "pull.usda"
    assert main(["usd", "animate", str(out), "--lens", "dgauss_50mm", "--marks", str(marks), "--sensor", "FF",
                 "--fstop", "2.8", "--position", "0,150,500"]) == 0
    capsys.readouterr()
    assert main(["lens", "breathing", "dgauss_50mm", "--focus", *[f"{m:.6f}mm" for m in MARKS], "--json"]) == 0
    rows = json.loads(capsys.readouterr().out)["rows"]
    stage = open_stage(out)
    geom = UsdGeom.Camera(stage.GetPrimAtPath("/Cameras/Camera/Camera"))
    cam = stage.GetPrimAtPath("/Cameras/Camera")
    film = UsdGeom.Xformable(cam).ComputeLocalToWorldTransform(Usd.TimeCode(1)).ExtractTranslation()
    assert geom.GetFocalLengthAttr().GetNumTimeSamples() == 48
    for i, row in enumerate(rows):
        t = Usd.TimeCode(i + 1)
        assert row["focus_from_film_mm"] == pytest.approx(MARKS[i])
        # mm at metersPerUnit 0.01; float32 storage
        assert geom.GetFocalLengthAttr().Get(t) == pytest.approx(row["breathing_focal_length_mm"], rel=3e-6)  # float32, chosen within 24 ulps to keep the FOV exact
        assert cam.GetAttribute("lens:main:entrancePupilDistance").Get(t) == pytest.approx(
            row["entrance_pupil_from_film_mm"], rel=1e-6)
        # the eye follows the pupil while the film stays put
        eye = UsdGeom.Xformable(geom).ComputeLocalToWorldTransform(t).ExtractTranslation()
        assert (film[2] - eye[2]) * 10.0 == pytest.approx(row["entrance_pupil_from_film_mm"], rel=1e-9)
        assert UsdGeom.Xformable(cam).ComputeLocalToWorldTransform(t).ExtractTranslation() == pytest.approx(film)
    # breathing: at 1 m the picture is tighter than at 5 m
    assert geom.GetFocalLengthAttr().Get(48) > geom.GetFocalLengthAttr().Get(1)


def test_thin_lens_iris_and_focus_pull(tmp_path):
    """A thin 35 mm lens: the pinhole is s' at each mark (hand-solved), and an fstop column pulls the iris."""
    marks = _csv(tmp_path, ["1,3m,2.8", "2,2.5m,4", "3,2m,5.6"], header="frame,focus,fstop")
    out = tmp_path / "thin.usda"
    assert main(["usd", "animate", str(out), "--focal", "35", "--marks", str(marks), "--sensor", "ALEXA 35"]) == 0
    stage = open_stage(out)
    geom = UsdGeom.Camera(stage.GetPrimAtPath("/Cameras/Camera/Camera"))
    cam = stage.GetPrimAtPath("/Cameras/Camera")
    for frame, mark, n in ((1, 3000.0, 2.8), (2, 2500.0, 4.0), (3, 2000.0, 5.6)):
        assert geom.GetFocalLengthAttr().Get(frame) == pytest.approx(image_distance_at_mark(35.0, mark), rel=3e-6)  # float32, chosen within 24 ulps to keep the FOV exact
        assert cam.GetAttribute("lens:main:fStop").Get(frame) == pytest.approx(n, rel=1e-6)
        # the exposure follows the iris pull: exposure:fStop is the T-stop, N for a lens of transmittance 1
        assert geom.GetExposureFStopAttr().Get(frame) == pytest.approx(n, rel=1e-6)


def test_bad_marks_name_file_and_line(tmp_path):
    from physcam.usd.animate import FocusKey, read_focus_marks, write_animated_camera
    from physcam.optics.sensors import find_sensor

    bad = _csv(tmp_path, ["1,3m", "2,three metres"])
    with pytest.raises(LensFileError, match=r"pull.csv:3"):
        read_focus_marks(bad)
    # an f-stop that is not one, frames going back, a row cut short: each names its line
    for rows, header, said in ((["1,3m,2.8", "2,2m,nan"], "frame,focus,fstop", "f-stop must be a finite number"),
                               (["1,3m,2.8", "2,2m,-4"], "frame,focus,fstop", "f-stop must be greater than 0"),
                               (["1,3m", "2,2m", "2,1m"], "frame,focus", "frame 2 does not follow frame 2"),
                               (["1,3m,2.8", "2"], "frame,focus,fstop", "this row has fewer values than the header.s 3")):
        line = len(rows) + 1
        with pytest.raises(LensFileError, match=rf"pull.csv:{line}: {said}"):
            read_focus_marks(_csv(tmp_path, rows, header=header))
    with pytest.raises(InputError, match="increase"):
        write_animated_camera(tmp_path / "x.usda", [FocusKey(2, 3000.0), FocusKey(1, 2000.0)],
                              sensor=find_sensor("FF"), focal_length_mm=50.0, fstop=2.8)


def test_a_marks_value_the_lens_refuses_names_file_and_line(tmp_path, capsys):
    """A value read well but refused by the lens (an f-stop faster than it opens, a zoom position outside its
    range) was one line without the file and line (a review found it); now it names both, in the library and
    the command. The keys read from a file still equal keys made by hand (where they came from is not compared)."""
    from physcam.lens.library import load_lens
    from physcam.optics.sensors import find_sensor
    from physcam.usd.animate import FocusKey, read_focus_marks, write_animated_camera

    iris = _csv(tmp_path, ["1,3m,2.8", "12,3m,1.0", "13,3m,4"], header="frame,focus,fstop")
    keys = read_focus_marks(iris)
    assert keys[1] == FocusKey(12.0, 3000.0, 1.0) and (keys[1].source, keys[1].line) == (str(iris), 3)
    with pytest.raises(LensFileError, match=r"pull.csv:3: f/1 is faster than this lens opens"):
        write_animated_camera(tmp_path / "x.usda", keys, sensor=find_sensor("S35"), lens=load_lens("dgauss_50mm"))
    zoom = _csv(tmp_path, ["1,3m,90mm", "12,3m,70mm"], header="frame,focus,zoom")
    assert main(["usd", "animate", str(tmp_path / "z.usda"), "--marks", str(zoom), "--lens",
                 "canon_ef_70_200mm_f2_8_zoom", "--sensor", "S35", "--fstop", "4"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "pull.csv:3: 70 mm is outside the zoom range" in err[0], err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["pull.csv"]
    with pytest.raises(PhysCamError, match="faster than this lens opens") as info:  # keys made by hand: no line
        write_animated_camera(tmp_path / "y.usda", [FocusKey(1, 3000.0, 1.0)], sensor=find_sensor("S35"),
                              lens=load_lens("dgauss_50mm"))
    assert not isinstance(info.value, LensFileError)


def test_an_anamorphic_pulls_pinhole_squeeze_is_sampled_per_frame(tmp_path, capsys):
    """An anamorphic's best-match squeeze breathes with focus: each frame's ``lens:main:pinholeSqueeze`` is
    `physcam report`'s pinhole squeeze at that mark, as the focal length beside it is (a reader rebuilding the
    companion from the PhysicalCamera at frame 2 got frame 1's squeeze)."""
    marks = _csv(tmp_path, ["1,3m", "2,1.5m"])
    out = tmp_path / "ana.usda"
    assert main(["usd", "animate", str(out), "--lens", "navarro_anamorphic_2x", "--marks", str(marks),
                 "--sensor", "ALEXA 35", "--fstop", "4"]) == 0
    stage = open_stage(out)
    cam = stage.GetPrimAtPath("/Cameras/Camera")
    squeezes = []
    for frame, mark in ((1, "3m"), (2, "1.5m")):
        capsys.readouterr()
        assert main(["report", "--lens", "navarro_anamorphic_2x", "--focus", mark, "--fstop", "4",
                     "--sensor", "ALEXA 35", "--json"]) == 0
        pinhole = json.loads(capsys.readouterr().out)["pinhole"]
        squeezes.append(pinhole["squeeze"])
        assert cam.GetAttribute("lens:main:pinholeSqueeze").Get(frame) == pytest.approx(pinhole["squeeze"], rel=1e-6)
        assert cam.GetAttribute("lens:main:pinholeFocalLength").Get(frame) == pytest.approx(
            pinhole["focal_length_mm"], rel=1e-6)
    assert abs(squeezes[1] - squeezes[0]) > 1e-4  # the case (100 x the tolerance): the squeeze does breathe between the marks

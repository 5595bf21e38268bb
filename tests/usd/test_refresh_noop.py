"""`physcam usd refresh` of a current camera changes nothing, and a stale one's refresh rewrites only what
changed (a user review, round 8: a pipeline diffs its USD files; a refresh of an up-to-date camera rewrote
float digits: focalLength 50.862263 -> 50.86238, shutter:close 0.5 -> 0.5000000149011612, the film's
translate 5.086232538105614 -> 5.086232376098633, read back through 32-bit attributes and recomputed)."""

import json

import pytest

from physcam.cli import main
from physcam.usd.read import open_stage
from physcam.usd.validate import validation_errors

from pxr import Usd  # noqa: E402

from _thin_lens import image_distance_at_mark  # noqa: E402

WRITES = {  # cameras `physcam usd write` authors from double values, refreshed through float32 ones
    "thin 50 mm, ALEXA 35": ["--focal", "50", "--fstop", "2.8", "--focus", "3m", "--sensor", "ALEXA 35"],
    "dgauss_50mm, metres": ["--lens", "dgauss_50mm", "--fstop", "2.8", "--focus", "3m", "--sensor", "ALEXA 35",
                            "--meters-per-unit", "1"],
}


@pytest.mark.parametrize("case", WRITES)
def test_refreshing_a_current_camera_leaves_the_file_as_it_was(tmp_path, capsys, case):
    cam = tmp_path / "cam.usda"
    assert main(["usd", "write", str(cam), *WRITES[case]]) == 0
    written = cam.read_bytes()
    capsys.readouterr()
    assert main(["usd", "check", str(cam)]) == 0
    assert main(["usd", "refresh", str(cam)]) == 0
    assert cam.read_bytes() == written
    assert f"companion camera current; nothing to recompute, {cam} not rewritten" in capsys.readouterr().out
    assert main(["usd", "refresh", str(cam), "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["written"] is False and doc["changed"] == [] and doc["stale"] is False
    assert cam.read_bytes() == written


def test_a_stale_refresh_rewrites_only_what_changed_and_says_what(tmp_path, capsys):
    """The f-stop of a thin 50 mm camera focused at 3 m set to 4 in the file: the refresh changes the iris
    (50 / 4 = 12.5 mm), the companion's T-stop (4, transmittance 1) and its f-stop (the working f-number
    of the best-match pinhole, 4 s'/f with s' the thin lens's image distance at the 3 m mark, by hand), and
    names those three; every other line of the file keeps its digits, but the inputs hash."""
    cam = tmp_path / "cam.usda"
    assert main(["usd", "write", str(cam), *WRITES["thin 50 mm, ALEXA 35"]]) == 0
    stage = Usd.Stage.Open(str(cam))
    stage.GetPrimAtPath("/Cameras/Camera").GetAttribute("lens:main:fStop").Set(4.0)
    stage.GetRootLayer().Save()
    edited = cam.read_text().splitlines()
    capsys.readouterr()
    assert main(["usd", "check", str(cam)]) == 1
    capsys.readouterr()
    assert main(["usd", "refresh", str(cam), "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    after = cam.read_text().splitlines()
    differ = [b for a, b in zip(edited, after) if a != b]
    assert len(after) == len(edited) and len(differ) == 4, differ  # (before: 10, shutter:close among them)
    assert sum("companionInputs" in line for line in differ) == 1
    assert doc["written"] is True and doc["stale"] is False
    got = {c["attribute"]: c["after"] for c in doc["changed"]}
    assert set(got) == {"/Cameras/Camera.lens:main:iris", "/Cameras/Camera/Camera.exposure:fStop",
                        "/Cameras/Camera/Camera.fStop"}
    assert got["/Cameras/Camera.lens:main:iris"] == pytest.approx(12.5, rel=1e-7)
    assert got["/Cameras/Camera/Camera.exposure:fStop"] == pytest.approx(4.0, rel=1e-7)
    assert got["/Cameras/Camera/Camera.fStop"] == pytest.approx(4.0 * image_distance_at_mark(50.0, 3000.0) / 50.0,
                                                                 rel=1e-6)
    assert not validation_errors(open_stage(cam))
    assert main(["usd", "refresh", str(cam)]) == 0  # now current: a second refresh is a no-op
    assert "not rewritten" in capsys.readouterr().out and cam.read_text().splitlines() == after


def test_a_camera_without_a_companion_gets_one(tmp_path, capsys):
    """Refresh still writes a companion a file lacks (the no-op rule reads an existing one's inputs hash)."""
    cam = tmp_path / "cam.usda"
    assert main(["usd", "write", str(cam), *WRITES["thin 50 mm, ALEXA 35"]]) == 0
    stage = Usd.Stage.Open(str(cam))
    stage.RemovePrim("/Cameras/Camera/Camera")
    stage.GetRootLayer().Save()
    capsys.readouterr()
    assert main(["usd", "refresh", str(cam), "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    added = {c["attribute"]: c["after"] for c in doc["changed"] if c["before"] is None}
    assert doc["written"] is True and doc["stale"] is False
    assert added["/Cameras/Camera/Camera.focalLength"] == pytest.approx(image_distance_at_mark(50.0, 3000.0), rel=3e-6)
    assert main(["usd", "check", str(cam)]) == 0
    assert not validation_errors(open_stage(cam))

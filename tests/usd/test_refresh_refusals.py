"""`physcam usd check/refresh` of cameras they cannot recompute right say so in one line, naming the file
(first-day walkthrough, round 9): a camera written by a `usd write --lens` from before the lens was stored (no
<camera>/Prescription) would be refreshed as a thin lens. An animated camera (a keyed focus and f-stop) is
checked and refreshed time code by time code since round 10 (tests/usd/test_refresh_animated.py, which also
holds the samples that are still refused).

Oracle: the files themselves, edited with usd-core (the stored lens removed, a layout's move), and the
file's bytes, which a refusal leaves as they were.
"""

from __future__ import annotations

from physcam.cli import main

from pxr import Sdf, Usd  # noqa: E402

CAM = "/Cameras/Camera"


def _refused(capsys, action, f):
    before = f.read_bytes()
    capsys.readouterr()
    assert main(["usd", action, str(f)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and str(f) in err, err
    assert f.read_bytes() == before
    return err


def test_a_lens_camera_without_its_stored_lens_is_refused(tmp_path, capsys):
    f = tmp_path / "old.usda"
    assert main(["usd", "write", str(f), "--lens", "dgauss_50mm", "--fstop", "2.8", "--focus", "3m", "--sensor",
                 "S35"]) == 0
    layer = Sdf.Layer.FindOrOpen(str(f))  # as usd write wrote it before the lens was stored
    cam = layer.GetPrimAtPath(CAM)
    del cam.nameChildren["Prescription"]
    cam.attributes["lens:main:fStop"].default = 4.0  # the stop edited: the companion is stale
    layer.Save()
    err = _refused(capsys, "refresh", f)
    assert f"{CAM}/Prescription is missing" in err and "Double Gauss 50mm" in err
    assert f"physcam usd write {f} --lens NAME" in err


def test_a_moving_camera_with_a_still_lens_is_checked_and_refreshed(tmp_path, capsys):
    """A layout's move (time-sampled xformOp:translate) is not an input of the lens: check and refresh
    treat the camera as still (the review of round 9 found the move refused)."""
    f = tmp_path / "move.usda"
    assert main(["usd", "write", str(f), "--focal", "50", "--fstop", "2.8", "--focus", "3m", "--sensor", "S35"]) == 0
    stage = Usd.Stage.Open(str(f))
    cam = stage.GetPrimAtPath(CAM)
    op = next(a for a in cam.GetAttributes() if a.GetName() == "xformOp:translate")
    op.Set((0.0, 0.0, 0.0), 1.0)
    op.Set((100.0, 0.0, 0.0), 24.0)
    cam.GetAttribute("lens:main:fStop").Set(4.0)  # the stop edited: the companion is stale
    stage.Save()
    capsys.readouterr()
    assert main(["usd", "check", str(f)]) == 1  # stale, not refused
    assert main(["usd", "refresh", str(f)]) == 0
    assert main(["usd", "check", str(f)]) == 0
    after = Usd.Stage.Open(str(f))
    moved = after.GetPrimAtPath(CAM).GetAttribute("xformOp:translate")
    assert moved.GetNumTimeSamples() == 2 and tuple(moved.Get(24.0)) == (100.0, 0.0, 0.0)


def test_a_path_with_no_prim_is_a_one_line_error(tmp_path, capsys):
    f = tmp_path / "cam.usda"
    assert main(["usd", "write", str(f), "--focal", "50", "--fstop", "2.8", "--focus", "3m", "--sensor", "S35"]) == 0
    for action in ("check", "refresh"):
        capsys.readouterr()
        assert main(["usd", action, str(f), "--path", "/Nope"]) == 2
        err = capsys.readouterr().err.strip()
        assert len(err.splitlines()) == 1 and "/Nope" in err and "Traceback" not in err, err

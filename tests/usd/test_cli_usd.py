"""``physcam usd``: write/read/kit through the real CLI entry point (in-process)."""

import json
import re

from physcam.cli import main


def test_write_read_force(tmp_path, capsys):
    f = tmp_path / "a.usda"
    assert main(["usd", "write", str(f), "--focal", "50", "--fstop", "2.8", "--focus", "3m",
                 "--sensor-width", "36", "--sensor-height", "24", "--meters-per-unit", "1"]) == 0
    assert main(["usd", "write", str(f), "--focal", "85", "--fstop", "2.8", "--focus", "3m"]) == 2
    assert "already exists" in capsys.readouterr().err
    capsys.readouterr()
    assert main(["usd", "read", str(f), "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["usd"]["camera"]["focal_length_mm"] == 50.0
    assert data["report"]["focal_length_mm"] == 50.0
    # the pinhole model keeps 50 mm; the UsdGeomCamera holds 50 mm in tenths of a metre
    focals = sorted(float(v) for v in re.findall(r"float focalLength = ([0-9.e-]+)", f.read_text()))
    assert abs(focals[0] - 0.5) < 1e-6 and focals[1] == 50.0


def test_kit_and_foreign_file(tmp_path, capsys):
    k = tmp_path / "kit.usda"
    assert main(["usd", "kit", "previs", str(k)]) == 0
    foreign = tmp_path / "x.usda"
    foreign.write_text('#usda 1.0\ndef Xform "A" {}\n')
    assert main(["usd", "read", str(foreign)]) == 2
    assert "found 0 PhysicalCamera prims" in capsys.readouterr().err
    assert main(["usd", "read", str(foreign), "--path", "/A"]) == 2
    assert "/A: is a Xform, not a PhysicalCamera" in capsys.readouterr().err


def test_write_applies_sensor_shift_flags(tmp_path, capsys):
    """Issue 8.1: --shift-x/--shift-y reach the file. A 2 mm right / -1.5 mm down shift on a
    36 x 24 mm gate at metersPerUnit 0.01 is 2.0 / -1.5 tenths of a cm on the UsdGeomCamera
    (docs/conventions.md), and the PhysicalCamera sensor shift is (2, -1.5) mm."""
    from pxr import Usd, UsdGeom

    f = tmp_path / "shift.usda"
    assert main(["usd", "write", str(f), "--focal", "50", "--fstop", "2.8", "--focus", "3m",
                 "--sensor-width", "36", "--sensor-height", "24", "--shift-x", "2", "--shift-y=-1.5"]) == 0
    stage = Usd.Stage.Open(str(f))
    geom = [UsdGeom.Camera(p) for p in stage.Traverse() if p.IsA(UsdGeom.Camera)]
    assert len(geom) == 1
    assert geom[0].GetHorizontalApertureOffsetAttr().Get() == 2.0
    assert geom[0].GetVerticalApertureOffsetAttr().Get() == -1.5
    capsys.readouterr()
    assert main(["usd", "read", str(f), "--json"]) == 0
    cam = json.loads(capsys.readouterr().out)["usd"]["camera"]
    assert cam["shift_mm"] == [2.0, -1.5]


def test_write_refuses_zero_fps_without_traceback(tmp_path, capsys):
    """Issue 8: `usd write ... --fps 0` raised ZeroDivisionError; now one line and exit 2."""
    f = tmp_path / "fps.usda"
    assert main(["usd", "write", str(f), "--focal", "35", "--fstop", "2.8", "--focus", "3m", "--fps", "0"]) == 2
    err = capsys.readouterr().err
    assert "frames per second" in err and "Traceback" not in err
    assert not f.exists()

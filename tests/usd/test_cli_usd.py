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

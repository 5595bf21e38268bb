"""Blender found from anywhere (issue 26 item 4): the order of the places looked in, what each
gives, and the command that runs a script under a Python with bpy or under the blender program."""

from __future__ import annotations

import stat
import subprocess
import sys
from pathlib import Path

import pytest

from physcam.errors import InputError
from physcam.export.blender_runner import SCRIPT_ARGS, find_blender


def _exe(path: Path, body: str) -> Path:
    path.write_text(body)
    path.chmod(path.stat().st_mode | stat.S_IEXEC)
    return path


def test_the_order_of_the_places_looked_in(tmp_path, monkeypatch):
    py = _exe(tmp_path / "python3", "#!/bin/sh\n")
    (tmp_path / "bin").mkdir()
    blender = _exe(tmp_path / "bin" / "blender", "#!/bin/sh\n")
    monkeypatch.delenv("PHYSCAM_BLENDER_PYTHON", raising=False)
    monkeypatch.setenv("PATH", str(tmp_path / "bin"))
    assert find_blender(str(py)).source == "--blender-python"
    assert find_blender(None, config_value=str(py)).source == "the user config's blender_python"
    r = find_blender(None)
    assert (r.kind, r.path, r.source) == ("blender", str(blender), "the blender program on PATH")
    monkeypatch.setenv("PHYSCAM_BLENDER_PYTHON", str(py))
    assert find_blender(None, config_value=str(blender)).source == "PHYSCAM_BLENDER_PYTHON"
    with pytest.raises(InputError, match="not a file"):
        find_blender(str(tmp_path / "nowhere"))


def test_without_any_blender_the_error_says_how_to_get_one(tmp_path, monkeypatch):
    monkeypatch.delenv("PHYSCAM_BLENDER_PYTHON", raising=False)
    monkeypatch.setenv("PATH", str(tmp_path))
    import physcam.export.blender_runner as br

    monkeypatch.setattr(br, "__file__", str(tmp_path / "a" / "b" / "c" / "blender_runner.py"))
    with pytest.raises(InputError, match="--blender-python"):
        find_blender(None)


def test_a_script_gets_its_arguments_either_way(tmp_path):
    """The same script, run as `python SCRIPT ARGS` and as a blender program would run it
    (`blender --background ... --python SCRIPT -- ARGS`: here a stand-in that passes its arguments on)."""
    script = tmp_path / "s.py"
    script.write_text(SCRIPT_ARGS + "print(ARGS)\n")
    fake = _exe(tmp_path / "blender", f"#!/bin/sh\nexec {sys.executable} \"$6\" \"$@\"\n")
    for runner in (find_blender(sys.executable), find_blender(str(fake))):
        out = subprocess.run(runner.command(script, "a", "b c"), capture_output=True, text=True, check=True).stdout
        assert out.strip().endswith("['a', 'b c']"), (runner, out)
    assert find_blender(str(fake)).command(script, "x")[:3] == [str(fake), "--background", "--factory-startup"]

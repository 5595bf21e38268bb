"""The thin-lens note printed by the exports follows ``--units`` (round 22 review: ``export rib --units ft`` said
``focus 10' 0"`` in its summary line and "focus 3.05 m ... a light 1.52 m" in its note; ``export mitsuba`` too).

The gap is measured at lights at half and twice the focus distance (physcam.onset.thin_lens_gap), so a 10 ft mark
has lights at 5 ft and 20 ft exactly (1524 and 6096 mm): under ``--units ft`` the note says ``focus 10' 0"``,
``a light 5' 0"`` and ``a light 20' 0"``, and no metres; under ``m`` it is as before (3 figures: 3.05 m, 1.52 m,
6.1 m). The files written keep metres whatever ``--units`` says: they are byte for byte the same under both.
"""

from __future__ import annotations

import re

import pytest

from physcam.cli import main

ARGS = ["--lens", "dgauss_50mm", "--focus", "10ft", "--fstop", "4", "--sensor", "S35", "--force"]
METRES = re.compile(r"\d m\b")


def _note(out: str) -> str:
    notes = [ln for ln in out.splitlines() if "note: a thin-lens camera is not" in ln]
    assert len(notes) == 1, out
    return notes[0]


@pytest.mark.parametrize("kind", ["rib", "mitsuba"])
def test_the_thin_lens_note_follows_units_and_the_files_keep_metres(kind, capsys, tmp_path):
    files = {}
    for units in ("m", "ft"):
        out_path = tmp_path / units / ("cam.rib" if kind == "rib" else "scene")
        out_path.parent.mkdir()
        extra = ["--width-px", "320"] if kind == "mitsuba" else []
        capsys.readouterr()
        assert main(["export", kind, "-o", str(out_path), *ARGS, *extra, "--units", units]) == 0
        note = _note(capsys.readouterr().out)
        if units == "ft":
            assert "focus 10' 0\":" in note and "a light 5' 0\" from" in note and "a light 20' 0\" from" in note
            assert not METRES.search(note), note
        else:
            assert "focus 3.05 m:" in note and "a light 1.52 m from" in note and "a light 6.1 m from" in note
        paths = [out_path] if kind == "rib" else sorted(out_path.iterdir())
        files[units] = {p.name: p.read_bytes() for p in paths}
    assert files["m"] == files["ft"]
    assert any(b"focus 3.05 m" in v for v in files["ft"].values())

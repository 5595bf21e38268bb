"""CSV follows ``--units`` in every command that takes it (docs/cli.md "Units"; round 22 review: only dof-table did).

Each command is run three ways in-process: ``--json`` (millimetres always), ``--csv`` and ``--csv --units ft``.
Under ``ft`` the scene distances are decimal feet, each the JSON's millimetres / 304.8 (the international foot,
exactly 304.8 mm), in a column named ``*_ft``; the columns that are scene distances are listed here by hand from
the commands' own tables (a focus mark, near and far limits, depth of field, hyperfocal, a close focus, a light's
distance: what they print with ``format_distance``) and every other column (a focal length, a pupil, the back
focus: inside the camera, mm as engraved) is the metric CSV's cell for cell. Under ``m`` the CSV is the JSON's rows
as they are (unchanged from before). dof-table (which had its own rule) writes what the shared rule writes, byte
for byte, so the two cannot drift.
"""

from __future__ import annotations

import csv
import io
import json
from pathlib import Path

import pytest

from physcam.cli import main
from physcam.cli._output import csv_text, print_csv

META = Path(__file__).resolve().parents[1] / "data" / "camera-metadata" / "red"
RED = [str(META / "A001_C066_0303LZ_001.frames.csv"), str(META / "A001_C066_0303LZ_001.static.csv")]

#: command line, where its JSON keeps the rows, the columns that are scene distances (by hand, from its table)
CASES = {
    "compare": (["compare", "dgauss_50mm", "--focus", "2m", "--fstop", "4", "--sensor", "S35", "--rays", "1000"],
                lambda d: d["lenses"],
                {"focus_from_film", "near_from_film", "far_from_film", "dof_total", "hyperfocal_from_film",
                 "closest_focus", "minimum_object_distance", "breathing_near", "bokeh_light_from_film"}),
    "lens breathing": (["lens", "breathing", "dgauss_50mm", "--sensor", "S35"], lambda d: d["rows"],
                       {"focus_from_film"}),
    "breathing-real": (["breathing-real", "dgauss_50mm", "--focus", "2m", "--focus", "inf", "--sensor", "S35"],
                       lambda d: d["rows"], {"focus_from_film"}),
    "distortion --across-focus": (["distortion", "dgauss_50mm", "--across-focus", "1m,inf", "--resolution",
                                   "320x180"], lambda d: d["rows"], {"focus_from_film"}),
    "export unreal": (["export", "unreal", "dgauss_50mm", "-o", "{tmp}/d.ulens", "--width-px", "320", "--height-px",
                       "180", "--focus", "2m", "--focus", "inf", "--force"],
                      lambda d: d["lens_file"]["physcam"]["marks"], {"focus_from_film"}),
    "metadata report": (["metadata", "report", *RED], lambda d: d["frames"],
                        {"focus_from_film", "near_from_film", "far_from_film", "hyperfocal_from_film",
                         "focus_from_pupil"}),
}


def _run(capsys, argv) -> str:
    capsys.readouterr()
    assert main(argv) == 0
    return capsys.readouterr().out


def _csv(text) -> list[dict]:
    return list(csv.DictReader(io.StringIO(text)))


@pytest.mark.parametrize("name", list(CASES))
def test_csv_gives_scene_distances_in_feet_under_units_ft(name, capsys, tmp_path, monkeypatch):
    monkeypatch.setenv("HOME", str(tmp_path))  # no user config: metres unless --units says
    monkeypatch.setenv("XDG_CONFIG_HOME", str(tmp_path))
    argv, rows_of, scene = CASES[name]
    argv = [a.replace("{tmp}", str(tmp_path)) for a in argv]
    rows = rows_of(json.loads(_run(capsys, [*argv, "--json"])))
    metric = _csv(_run(capsys, [*argv, "--csv"]))
    feet = _csv(_run(capsys, [*argv, "--csv", "--units", "ft"]))
    assert len(rows) == len(metric) == len(feet) > 0
    assert {c[:-3] for c in feet[0] if c.endswith("_ft")} == scene
    assert not {c for c in metric[0] if c.endswith("_ft")}
    assert {f"{s}_mm" for s in scene} <= set(metric[0])  # metric: the JSON's names, in mm
    for row, m, f in zip(rows, metric, feet):
        for col, cell in f.items():
            if col.endswith("_ft"):
                mm = row[col[:-3] + "_mm"]
                assert (cell == "") if mm is None else float(cell) == pytest.approx(mm / 304.8, rel=1e-12), col
            else:
                assert cell == m[col], col


def test_compare_focus_in_feet_by_hand(capsys):
    """2 m is 2000 / 304.8 = 6.5616797900... ft; the entrance pupil (inside the lens) stays in mm."""
    out = _csv(_run(capsys, ["compare", "dgauss_50mm", "--focus", "2m", "--fstop", "4", "--sensor", "S35",
                             "--rays", "1000", "--units", "ft", "--csv"]))
    assert float(out[0]["focus_from_film_ft"]) == pytest.approx(6.561679790026247, rel=1e-15)
    assert 40.0 < float(out[0]["entrance_pupil_from_film_mm"]) < 60.0 and float(out[0]["efl_mm"]) > 50.0


@pytest.mark.parametrize("argv", [
    ["dof-table", "--focal", "50", "--fstops", "2.8,4", "--focus", "2m,10ft,inf,hyperfocal", "--sensor", "S35"],
    ["dof-table", "--lens", "dgauss_50mm", "--fstops", "4", "--focus", "1m,inf", "--sensor", "S35"],
    ["dof-table", "--focal", "40", "--fstops", "2.8", "--focus", "3m,inf", "--sensor", "anamorphic-35",
     "--squeeze", "2"],
])
def test_dof_table_csv_is_the_shared_rule(argv, capsys, tmp_path, monkeypatch):
    """dof-table's --csv is byte for byte the shared rule's (cli/_output.csv_in_units) on its JSON rows, in feet
    and in metres (its own conversion, cli/dof_table.csv_rows, gave these very bytes: round 22 replaced it)."""
    monkeypatch.setenv("HOME", str(tmp_path))
    monkeypatch.setenv("XDG_CONFIG_HOME", str(tmp_path))
    rows = json.loads(_run(capsys, [*argv, "--json"]))["rows"]
    for units in ("ft", "m"):
        got = _run(capsys, [*argv, "--csv", "--units", units])
        print_csv(rows, units=units)
        assert got == capsys.readouterr().out
    assert _run(capsys, [*argv, "--csv"]) == csv_text(rows)

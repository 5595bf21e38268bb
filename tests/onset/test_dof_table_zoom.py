"""physcam.onset.dof_table.dof_table of a zoom lens at a zoom position (round 10: the function had no zoom while
`physcam dof-table --zoom` had one).

Oracles: the on-set report of the same lens at the same zoom, focus and stop, computed by calling the report's
function directly on the zoom lens's prescription at that position (physcam.optics.zoom.at_zoom); the thin-lens
depth of field worked by hand with each position's own Gaussian data (EFL, front principal plane and f-number at
the focus: the datasheet model's formulas, tests/cli/test_zoom_analyses.py), so two positions' tables differ as
their EFLs predict; the command's --json.
"""

from __future__ import annotations

import json

import pytest

from physcam.cli import main
from physcam.errors import InputError
from physcam.lens.library import load_lens
from physcam.onset.dof_table import dof_table

CANON = "canon_ef_70_200mm_f2_8_zoom"  # a zoom with a paraxial range of about 72-194 mm
C = 0.025


@pytest.fixture(scope="module")
def canon():
    return load_lens(CANON)


def test_a_cell_is_the_report_of_that_lens_zoom_focus_and_stop(canon):
    from physcam.onset.report import report_camera, solve_report
    from physcam.optics.zoom import at_zoom

    d = dof_table(lens=canon, zoom="135mm", sensor="S35", fstops=[2.8, 4], focus_marks_mm=["3m", 5000.0], coc=C)
    lens = at_zoom(canon, "135mm")
    for row in d["rows"]:
        r = solve_report(report_camera(lens=lens, sensor="S35", fstop=row["fstop"], focus_mm=row["focus_from_film_mm"],
                                       coc=C))
        assert row["near_from_film_mm"] == pytest.approx(r.dof.near_from_film_mm, rel=1e-12)
        assert row["far_from_film_mm"] == pytest.approx(r.dof.far_from_film_mm, rel=1e-12)
        assert row["hyperfocal_from_film_mm"] == pytest.approx(r.dof.hyperfocal_from_film_mm, rel=1e-12)
        assert row["focal_length_mm"] == pytest.approx(r.focal_length_mm, rel=1e-12)
    assert d["zoom"]["encoder"] == pytest.approx(0.5, abs=0.01) and d["zoom"]["efl_mm"] == pytest.approx(135.0)
    assert d["zoom"]["asked"] == "135mm" and "at 135.0 mm" in d["lens"]


def test_two_zoom_positions_differ_as_the_thin_lens_formula_with_each_efl_predicts(canon):
    from physcam.optics.focusing import f_number_ratio, technical_planes
    from physcam.optics.zoom import at_zoom

    totals = {}
    for pos in ("100mm", "180mm"):
        (row,) = dof_table(lens=canon, zoom=pos, sensor="S35", fstops=[4], focus_marks_mm=[5000.0], coc=C)["rows"]
        tp = technical_planes(at_zoom(canon, pos), 5000.0, fstop=4.0)
        f, n = tp.efl_mm, 4.0 * f_number_ratio(at_zoom(canon, pos), 5000.0)
        s, h = 5000.0 - tp.h1_from_film_mm, f * f / (n * C)  # subject and hyperfocal from H1
        near, far = h * s / (h + s - f), h * s / (h - s + f)
        assert row["near_from_film_mm"] == pytest.approx(near + tp.h1_from_film_mm, rel=1e-6)
        assert row["far_from_film_mm"] == pytest.approx(far + tp.h1_from_film_mm, rel=1e-6)
        totals[pos] = (row["total_mm"], far - near)
    assert totals["100mm"][0] / totals["180mm"][0] == pytest.approx(totals["100mm"][1] / totals["180mm"][1], rel=1e-6)
    assert totals["100mm"][0] > 2.5 * totals["180mm"][0]  # about (180/100)^2: a longer focal length, less depth


def test_the_function_and_the_command_give_the_same_zoomed_table(canon, capsys):
    assert main(["dof-table", "--lens", CANON, "--zoom", "0.25", "--sensor", "S35", "--coc", "0.025", "--fstops",
                 "2.8", "--focus", "3m,hyperfocal", "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    api = dof_table(lens=canon, zoom="0.25", sensor="S35", coc=0.025, fstops=[2.8], focus_marks_mm=["3m", "hyperfocal"])
    assert json.loads(json.dumps(api)) == {k: v for k, v in doc.items() if k not in ("schema", "version", "units")}


@pytest.mark.parametrize("lens, focal, zoom, words", [
    (CANON, None, "300mm", ["outside the zoom range", "mm"]),
    (CANON, None, 1.5, ["encoder value lies from 0 to 1"]),
    ("dgauss_50mm", None, "50mm", ["is not a zoom lens"]),
    (None, 50.0, "0.5", ["takes a zoom lens"]),
])
def test_a_zoom_it_cannot_take_is_one_sentence(lens, focal, zoom, words):
    with pytest.raises(InputError) as e:
        dof_table(focal, lens=None if lens is None else load_lens(lens), zoom=zoom, sensor="S35", fstops=[2.8],
                  focus_marks_mm=["3m"])
    msg = str(e.value)
    assert "\n" not in msg and all(w in msg for w in words), msg

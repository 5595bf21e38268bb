"""The dof-table card's chart and the table are one code path (round 10: the command built the chart's cells
with its own report call beside the function's loop): the chart asks physcam.onset.dof_table.dof_cells, the
function the table's rows come from.

Oracles: the table's rows (`physcam dof-table --json`) at the chart's own stops and marks, and the report of
the zoom lens at that position called directly (physcam.optics.zoom.at_zoom), for the card of a zoomed lens.
"""

from __future__ import annotations

import json

import pytest

from physcam.cli import build_parser, main
from physcam.cli.dof_table import _card_chart


def _args(*argv):
    return build_parser().parse_args(["dof-table", *argv])


def test_the_cells_function_gives_the_tables_rows(capsys):
    from physcam.onset.dof_table import dof_cells

    argv = ["--focal", "50", "--sensor", "ALEXA 35 3.3K 6:5", "--squeeze", "format", "--coc", "0.025", "--fstops",
            "2,5.6", "--focus", "1.5m,hyperfocal"]
    assert main(["dof-table", *argv, "--json"]) == 0
    rows = json.loads(capsys.readouterr().out)["rows"]
    cell = dof_cells(50, sensor="ALEXA 35 3.3K 6:5", squeeze="format", coc=0.025)
    for row in rows:
        r = cell(row["fstop"], row["focus"] or row["focus_from_film_mm"])
        far = None if r.dof.far_is_infinite else r.dof.far_from_film_mm
        assert (r.dof.near_from_film_mm, far) == (row["near_from_film_mm"], row["far_from_film_mm"])
        assert r.dof_horizontal.near_from_film_mm == row["near_horizontal_from_film_mm"]


def test_the_card_chart_of_a_zoomed_lens_is_the_tables_lens_at_that_zoom(capsys):
    from physcam.lens.library import load_lens
    from physcam.onset.report import report_camera, solve_report
    from physcam.optics.zoom import at_zoom

    argv = ["--lens", "canon_ef_70_200mm_f2_8_zoom", "--zoom", "135mm", "--sensor", "S35", "--coc", "0.025",
            "--fstops", "2.8,4", "--focus", "3m,5m"]
    assert main(["dof-table", *argv, "--json"]) == 0
    rows = json.loads(capsys.readouterr().out)["rows"]
    report, data = _card_chart(_args(*argv), [2.8, 4.0])  # the chart's report: the first stop at the middle mark, 5 m
    direct = solve_report(report_camera(lens=at_zoom(load_lens("canon_ef_70_200mm_f2_8_zoom"), "135mm"), sensor="S35",
                                        fstop=2.8, focus_mm=5000.0, coc=0.025))
    assert report.focal_length_mm == pytest.approx(direct.focal_length_mm, rel=1e-12)
    assert report.dof.near_from_film_mm == pytest.approx(direct.dof.near_from_film_mm, rel=1e-12)
    assert (report.dof.near_from_film_mm, report.dof.far_from_film_mm) == (rows[1]["near_from_film_mm"],
                                                                         rows[1]["far_from_film_mm"])
    assert sorted(data["hyperfocal"]) == [2.8, 4.0]
    assert data["hyperfocal"][4.0] == pytest.approx(rows[-1]["hyperfocal_from_film_mm"], rel=1e-12)

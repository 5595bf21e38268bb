"""Issue 39 item 9: the DOF card is one A4 or Letter page, its table's words fit their cells, and its chart
draws only stops the table has.

It cut "hyperfocal distanc" in its first column, charted f/1 beside a table of f/1.4 to f/16 (the chart
picked its own stops around the first), and was 8.27 in wide by however tall the table made it.
Page sizes: ISO 216 A4 210 x 297 mm, ANSI Letter 8.5 x 11 in (612 x 792 PDF points)."""

from __future__ import annotations

import re

import pytest

from physcam.cli import build_parser, main
from physcam.cli.dof_table import _card_chart, build, card_figure

pytestmark = pytest.mark.slow


def _args(*argv):
    args = build_parser().parse_args(["dof-table", *argv])
    return args


@pytest.mark.parametrize("page, points", [("a4", (595.28, 841.89)), ("letter", (612.0, 792.0))])
def test_the_card_is_one_page_of_that_size(tmp_path, page, points):
    out = tmp_path / "card.pdf"
    assert main(["dof-table", "--focal", "35", "--sensor", "S35", "-o", str(out), "--page", page]) == 0
    data = out.read_bytes()
    box = [float(v) for v in re.search(rb"/MediaBox\s*\[\s*([\d.\s]+)\]", data).group(1).split()]
    assert box[2:] == pytest.approx(points, abs=0.01)
    assert len(re.findall(rb"/Type\s*/Page[^s]", data)) == 1


def test_every_word_fits_its_cell_and_the_chart_has_only_the_tables_stops():
    args = _args("--focal", "35", "--sensor", "S35")  # the default stops: f/1.4 to f/16, eight of them
    d = build(args)
    fig = card_figure(d, chart=_card_chart(args, d["fstops"]))
    fig.canvas.draw()
    r = fig.canvas.get_renderer()
    table = next(a for a in fig.axes if a.tables).tables[0]
    for (row, col), cell in table.get_celld().items():
        box, text = cell.get_window_extent(r), cell.get_text().get_window_extent(r)
        assert text.width <= box.width and text.height <= box.height, cell.get_text().get_text()
    heads = [c.get_text().get_text() for (row, col), c in table.get_celld().items() if row == 0 and col > 0]
    chart = next(a for a in fig.axes if a.get_legend() is not None)
    drawn = [t.get_text() for t in chart.get_legend().get_texts() if t.get_text().startswith("f/")]
    assert drawn and set(drawn) <= set(heads)
    assert drawn[0] == heads[0] and drawn[-1] == heads[-1]


@pytest.mark.parametrize("page", ["a4", "letter"])
def test_an_anamorphic_card_says_the_horizontal_limits_and_they_fit(page):
    """Issue 49 item 4: with a desqueeze every cell adds the limits across the frame (CoC c / 0.5 for a 2x
    thin lens: 2.588 m and 3.572 m at f/2.8 and 3 m, worked by hand in tests/cli/test_dof_table_anamorphic.py),
    and every word still fits its cell on the page."""
    from test_dof_table_anamorphic import _limits

    args = _args("--focal", "50", "--sensor", "ALEXA 35 3.3K 6:5", "--squeeze", "format", "--coc", "0.025")
    d = build(args)
    fig = card_figure(d, chart=_card_chart(args, d["fstops"]), page=page)
    fig.canvas.draw()
    r = fig.canvas.get_renderer()
    table = next(a for a in fig.axes if a.tables).tables[0]
    for (row, col), cell in table.get_celld().items():
        box, text = cell.get_window_extent(r), cell.get_text().get_window_extent(r)
        assert text.width <= box.width and text.height <= box.height, cell.get_text().get_text()
    cells = {(row, col): c.get_text().get_text() for (row, col), c in table.get_celld().items()}
    col = next(c for (row, c), t in cells.items() if row == 0 and t == "f/2.8")
    row = next(rw for (rw, c), t in cells.items() if c == 0 and t == "3.000 m")
    near_h, far_h = _limits(0.025 / 0.5)
    assert cells[(row, col)].splitlines()[3:] == [f"↔ {near_h / 1000:.3f} m", f"↔ {far_h / 1000:.3f} m"]
    assert any("across it (anamorphic, squeeze 2" in t.get_text() for t in fig.texts)

"""The spot figure laid out in one pass, with or without its context line (the shot: f-stop, focus; issue 47,
round 21).

``physcam spot -o`` drew the figure laid out (``tight_layout``), then added the context line and laid it out
again (``physcam.cli._output.save_plot``): two passes over every tick label, 25-40 ms of a cold command.
``SpotDiagram.plot(context=...)`` draws the line with the panels and lays them out once, from the margins
where two passes end: one pass from matplotlib's default margins lands short with equal-aspect panels (the
line inside the x labels; without the line, as the library's ``plot()`` on main, the x labels below the
figure's edge at two to four fields: the docstring of ``SpotDiagram._lay_out``). The files' pixels are
therefore not main's; what a reader needs of the layout is checked here on lenses and field counts apart
from the one the margins were taken from, with matplotlib's own text extents as drawn: the figure in
physcam's style (``figure_problems``: no text outside it), the line under every panel with its labels and
clear of every other text, the figure's title clear of the panels' titles; and the command writes exactly
that figure (the same PNG bytes as the library's call). The numbers drawn are the spot's (--json unchanged).
"""

import pytest

from physcam.analysis.image_quality.spot import spot_diagram
from physcam.cli import main
from physcam.figures import figure_problems
from physcam.lens.library import load_lens
from physcam.optics.state import as_designed

CONTEXT = "wide open, focused at infinity"
#: Clearance asked for (pixels at the figure's 100 dpi): main's two passes leave 9-16 px on these.
CLEAR_PX = 5.0


def _overlap(a, b) -> bool:
    return a.x0 < b.x1 and b.x0 < a.x1 and a.y0 < b.y1 and b.y0 < a.y1


@pytest.mark.parametrize("name, fields", [
    ("dgauss_50mm", (0.0, 5.0)), ("zuiko_18mm_f3_5", (0.0, 10.0, 20.0)), ("canon_rf_85mm_f1_2", (0.0,)),
    ("tessar_50mm_f2_8", (0.0, 5.0, 10.0, 15.0)), ("sonnar_50mm_f1_5", (0.0, 8.0)),
])
def test_the_context_line_and_the_titles_keep_clear(name, fields):
    fig = spot_diagram(as_designed(load_lens(name)), fields, rings=8, refine=3).plot(None, context=CONTEXT)
    assert figure_problems(fig) == []  # (drawn: the extents below are as drawn)
    renderer = fig.canvas.get_renderer()
    line = [t for t in fig.texts if t.get_text() == CONTEXT]
    assert len(line) == 1
    box = line[0].get_window_extent(renderer)
    for ax in fig.axes:
        assert ax.get_tightbbox(renderer).y0 - box.y1 >= CLEAR_PX  # under each panel, its labels included
    texts = [t for t in fig.findobj(lambda a: hasattr(a, "get_window_extent") and hasattr(a, "get_text"))
             if t is not line[0] and t.get_visible() and t.get_text().strip()]
    assert len(texts) > 10
    assert not any(_overlap(box, t.get_window_extent(renderer)) for t in texts)
    title = fig._suptitle.get_window_extent(renderer)
    for ax in fig.axes:
        assert title.y0 - ax.title.get_window_extent(renderer).y1 >= CLEAR_PX


@pytest.mark.parametrize("name, fields", [
    ("dgauss_50mm", (0.0, 5.0)), ("zuiko_18mm_f3_5", (0.0, 10.0, 20.0)), ("canon_rf_85mm_f1_2", (0.0, 80.0)),
    ("sonnar_50mm_f1_5", (0.0, 5.0, 10.0, 15.0)),
])
def test_without_a_context_line_the_labels_stay_inside_the_figure(name, fields):
    fig = spot_diagram(as_designed(load_lens(name)), fields, rings=8, refine=3).plot(None)
    assert figure_problems(fig) == []  # main: the x labels 2-6 px below the figure's edge
    renderer = fig.canvas.get_renderer()
    for ax in fig.axes:
        assert ax.get_tightbbox(renderer).y0 >= CLEAR_PX
        assert fig._suptitle.get_window_extent(renderer).y0 - ax.title.get_window_extent(renderer).y1 >= CLEAR_PX


def test_the_command_writes_the_figure_with_its_context_line(tmp_path, capsys):
    cli = tmp_path / "cli.png"
    assert main(["spot", "--lens", "dgauss_50mm", "--rings", "8", "--fstop", "4", "-o", str(cli)]) == 0
    capsys.readouterr()
    res = spot_diagram(as_designed(load_lens("dgauss_50mm"), fstop=4.0), (0.0, 5.0), rings=8)
    lib = res.plot(tmp_path / "lib.png", context="f/4, focused at infinity")
    assert cli.read_bytes() == lib.read_bytes()

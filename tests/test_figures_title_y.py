"""Titles placed once (``physcam.figures.title_y``, issue 47 round 21) are where matplotlib's own placement
leaves them, so the pictures are the same.

matplotlib places each title at every layout pass and draw (``Axes._update_title_position``, matplotlib
3.11): it starts it at y = 1.0 (axes fraction) and moves it up only (a) above the x axis's tick labels or
label when they are at the top ("top" or "unknown" tick position, or the label at the top), or (b) above the
y axis's offset text when that is shown and meets the title, or (c) when the title's bottom is below the
top of the axes (of its twins and aligned axes too). An offset text can meet the title during a layout
pass, before the axes have their final place, and so move the margins: ``title_y`` leaves an axes with an
offset on its y axis (or top ticks, or a twin) to matplotlib (checked on axes made to have each). On the
figures that pass ``y=title_y(ax)`` (the spot diagram, the lens comparison), drawn as they are saved over
lenses and field counts, every title is placed once and none of (a)-(c) holds, so matplotlib would have left
each at 1.0; their PNG bytes equal the previous ones' (the round's notes, docs/performance.md)."""

from __future__ import annotations

import pytest

from physcam.analysis.image_quality.spot import spot_diagram
from physcam.cli.compare import compare_figure, measure_lens
from physcam.figures import SAVE_DPI, TITLE_Y, figure_problems, new_figure, title_y
from physcam.lens.library import load_lens
from physcam.optics.sensors import find_sensor
from physcam.optics.state import as_designed


def _titles_where_matplotlib_leaves_them(fig) -> int:
    assert figure_problems(fig) == []  # drawn, in the style
    renderer = fig.canvas.get_renderer()
    checked = 0
    for ax in fig.axes:
        if not ax.get_title():
            continue
        assert ax.title.get_position()[1] == TITLE_Y
        assert ax._twinned_axes.get_siblings(ax) == [ax] and not ax.child_axes  # nothing else to clear
        assert ax.xaxis.get_ticks_position() not in ("top", "unknown")  # (a)
        assert ax.xaxis.get_label_position() != "top"
        title = ax.title.get_window_extent(renderer)
        offset = ax.yaxis.offsetText
        if offset.get_visible() and offset.get_text():  # (b)
            assert not offset.get_window_extent(renderer).overlaps(title)
        assert title.y0 >= ax.get_window_extent(renderer).y1  # (c)
        checked += 1
    return checked


@pytest.mark.parametrize("name, fields", [("dgauss_50mm", (0.0, 5.0)), ("zuiko_18mm_f3_5", (0.0, 10.0, 20.0)),
                                          ("canon_rf_85mm_f1_2", (0.0, 80.0))])  # 80 deg: an undefined panel
def test_spot_titles(name, fields):
    res = spot_diagram(as_designed(load_lens(name)), fields, rings=8, refine=3)
    assert _titles_where_matplotlib_leaves_them(res.plot(None)) == len(fields)
    assert _titles_where_matplotlib_leaves_them(res.plot(None, context="wide open")) == len(fields)


def test_compare_titles():
    sensor = find_sensor("S35")
    rows = [measure_lens(load_lens(n), focus_mm=2000.0, fstop=2.8, sensor=sensor, coc=None, light_mm=None,
                         rays=2000) for n in ("dgauss_50mm", "sonnar_50mm_f1_5", "tessar_50mm_f2_8")]
    curves = [r.pop("_curves") for r in rows]
    for n, r in zip(("dgauss_50mm", "sonnar_50mm_f1_5", "tessar_50mm_f2_8"), rows):
        r["name"] = n
    assert _titles_where_matplotlib_leaves_them(compare_figure(rows, curves, sensor=sensor, dpi=SAVE_DPI)) == 6


def test_title_y_leaves_to_matplotlib_what_it_might_move():
    fig = new_figure(figsize=(6.0, 2.0))
    plain, tiny, top, twinned = fig.subplots(1, 4)
    for ax in (plain, top, twinned):
        ax.plot([0.0, 1.0], [-3.0, 2.0])
    tiny.plot([0.0, 1.0], [0.0, 3e-7])  # the y axis's ticks need an offset text ("1e-7")
    top.xaxis.tick_top()
    twinned.twinx()
    assert title_y(plain) == TITLE_Y
    assert title_y(tiny) is None and title_y(top) is None and title_y(twinned) is None

"""A lens card in feet (new-user review, round 22): lengths inside the camera stay in millimetres, and the
focus axes' tick labels never run into each other.

docs/cli.md: "Lengths inside the camera (focal length, principal planes, pupil, CoC, sensor) stay in
millimetres". The card in feet printed the double Gauss's entrance pupil as 2" (rounded to 1/8 inch: 50.8 mm,
against the metric card's 49.5 mm), the Neil anamorphic's two pupils as 6 3/4" and 5 3/8", and the zoom page's
pupil curve in inches. Oracles: the y-u trace by hand of tests/_anamorphic_yu.py (each pupil from the lens
file's own numbers) and optiland's zoom pupils (tests/data/optiland_zoom.json).

The focus axes: the card in feet printed ``16' 5"9' 10 1/8"`` under its breathing panel, and the metric card
left its 10 m tick without a label though it had room. :func:`physcam.figures.figure_problems` now finds tick
labels that overlap as drawn; every page of these cards, in metres and in feet, has none, and the metric
breathing axis labels every mark the review found there.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest

from _anamorphic_yu import hand_pupils_from_film
from _draft_cards import draft_card
from physcam.figures import figure_problems

OPTILAND = json.loads((Path(__file__).parents[2] / "data" / "optiland_zoom.json").read_text())["lenses"]


def _row(ax, label):
    """The texts right of ``label`` on a table drawn as text (the key numbers, the anamorphic numbers)."""
    texts = sorted(ax.texts, key=lambda t: (-round(t.get_position()[1], 6), t.get_position()[0]))
    y = next(t.get_position()[1] for t in texts if t.get_text() == label)
    return [t.get_text() for t in texts if t.get_position()[1] == y and t.get_text() != label]


def test_the_key_numbers_give_the_pupil_in_mm_in_feet_too():
    card = draft_card("dgauss_50mm")  # focused at infinity
    hand = hand_pupils_from_film("dgauss_50mm", math.inf)[1]
    for units in ("m", "ft"):
        fig = card.figure(units=units, dpi=30)
        key = next(a for a in fig.axes if a.get_title(loc="left") == "key numbers")
        assert _row(key, "  in front of film") == [f"{hand:.1f} mm"], units


def test_the_anamorphic_page_gives_both_pupils_in_mm_in_feet_too():
    """Both from the one film plane, as the hand trace (and the report) give them: the X pupil was measured from
    the X meridian's own paraxial focus, 170.7 mm against 170.6 mm."""
    card = draft_card("neil_front_anamorphic_2x")
    hx, hy = hand_pupils_from_film("neil_front_anamorphic_2x", math.inf)
    fig = card.extra_page("anamorphic", units="ft", dpi=30)
    ax = next(a for a in fig.axes if a.get_label() == "anamorphic numbers")
    assert _row(ax, "pupil in front of film") == [f"{hx:.1f} mm", f"{hy:.1f} mm"]


def test_the_zoom_pages_pupil_curve_is_in_mm_in_feet_too():
    card = draft_card("canon_ef_70_200mm_f2_8_zoom")
    fig = card.extra_page("zoom", units="ft", dpi=30)
    ax = next(a for a in fig.axes if a.get_label() == "zoom entrance pupil")
    assert ax.get_ylabel() == "in front of the film (mm)"
    tab = [r for r in card.zoom_page.positions if r.tabulated]
    dots = ax.get_lines()[2].get_ydata()  # the tabulated positions' pupils
    for y, r, ref in zip(dots, tab, OPTILAND["canon_ef_70_200mm_f2_8_zoom"]):
        assert y == pytest.approx(r.front_vertex_to_film_mm - ref["ep_from_front_vertex_mm"], rel=1e-3)


@pytest.mark.parametrize("slug", ["dgauss_50mm", "neil_front_anamorphic_2x", "canon_ef_70_200mm_f2_8_zoom"])
@pytest.mark.parametrize("units", ["m", "ft"])
def test_no_tick_labels_overlap_on_any_page(slug, units):
    """The review's cards (the double Gauss, the anamorphic's four focus axes, the zoom page's breathing):
    before, in feet, figure_problems found 1 overlap on the double Gauss and 12 on the anamorphic page."""
    card = draft_card(slug)
    for name in card.pages:
        fig = card.figure(units=units, dpi=40) if name == "main" else card.extra_page(name, units=units, dpi=40)
        assert figure_problems(fig) == [], (name, units)


def test_the_metric_breathing_axis_labels_ten_metres():
    fig = draft_card("dgauss_50mm").figure(units="m", dpi=40)
    figure_problems(fig)  # drawn
    ax = next(a for a in fig.axes if a.get_label() == "breathing")
    shown = [t.get_text() for t in ax.get_xticklabels() if t.get_visible()]
    assert shown[:3] == ["∞", "10", "5"]


def test_figure_problems_finds_overlapping_tick_labels():
    """Two labels on ticks 1 % of the axis apart overlap; the same labels at the ends do not."""
    from physcam.figures import figure_style, new_figure

    with figure_style():
        for ticks, bad in (([0.0, 0.01], True), ([0.0, 1.0], False)):
            fig = new_figure(figsize=(4, 3))
            ax = fig.add_subplot(1, 1, 1)
            ax.set_xlim(0, 1)
            ax.set_xticks(ticks, ["9' 10 1/8\"", "16' 5\""])
            ax.set_xlabel("focus mark (ft)")
            ax.set_yticks([])
            problems = [p for p in figure_problems(fig) if "overlap" in p]
            assert bool(problems) == bad, problems

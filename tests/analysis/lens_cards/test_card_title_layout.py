"""The lens card's section title stays clear of the key numbers panel (a first-day review: on a short lens
the equal-aspect section box shrank to the middle of its cell and its left-set title ran into "key
numbers"). Checked on the rendered page: the title's box against the key panel's tight box (its title and
every row), for the shortest and the longest bundled lens and a single singlet in the TOML format."""

from __future__ import annotations

import pytest

from _draft_cards import draft_card
from physcam.analysis.lens_cards.card import lens_card
from physcam.lens.library import list_lenses, load_lens

SINGLET = """format = "physcam-lens/1"

[lens]
name = "Singlet"
focal_length = 50.0
max_fstop = 4.0

[[surface]]
kind = "spherical"
radius = 25.84
thickness = 4.0
semi_diameter = 9.0
medium = { glass = "N-BK7", catalog = "SCHOTT" }

[[surface]]
kind = "stop"
radius = 0
thickness = 10.0
semi_diameter = 6.5
medium = "air"
"""


def _by_track():
    return sorted((load_lens(r.slug).total_track, r.slug) for r in list_lenses("bundled"))


@pytest.mark.parametrize("which", ["shortest", "longest", "singlet"])
def test_section_title_does_not_run_into_the_key_numbers(which, tmp_path):
    if which == "singlet":
        (tmp_path / "singlet.toml").write_text(SINGLET)
        card = lens_card(load_lens(str(tmp_path / "singlet.toml")), quality="draft")
    else:
        card = draft_card(_by_track()[0 if which == "shortest" else -1][1])
    fig = card.figure(dpi=40)
    fig.canvas.draw()
    r = fig.canvas.get_renderer()
    axes = {ax.get_label(): ax for ax in fig.axes}
    title = axes["diagram"]._left_title
    assert title.get_text().startswith("lens section")
    t, key = title.get_window_extent(r), axes["key numbers"].get_tightbbox(r)
    assert not t.overlaps(key), (which, t, key)
    assert t.x1 < key.x0  # the title ends left of the panel, on the same band of the page

"""The lens card (issue 32): one page for every bundled lens, with every panel.

Each lens's card is rendered small (draft quality, 30 dpi). Checked for every bundled lens: every page
drawn (the main page, a second for a zoom or an anamorphic lens) with every panel's axes present, the
page size stated (A4 210 x 297 mm, Letter 8.5 x 11 in: ISO 216 and ANSI), no text outside the page
(a lens's name, notes and numbers differ, so each lens's pages are drawn), and key numbers against
independent values: the EFL from the paraxial y-u trace of physcam.optics.paraxial, and the image
circle at least the sensor it covers when the real chief ray at the corner passes.

The PDF (one page per card page, counted in the file) is written for one lens of each kind of card:
a spherical prime, an aspheric prime, a zoom and an anamorphic lens. That suffices: writing the PDF is
the same code for every lens (:func:`save_lens_card` hands the figures every lens's pages are drawn
from above to matplotlib's PdfPages); only which pages a card has varies, and those kinds cover every
set of pages a bundled lens's card can have.
"""

from __future__ import annotations

import re

import pytest

from _draft_cards import draft_card
from physcam.analysis.lens_cards.card import PAGES, PANELS, lens_card, save_lens_card
from physcam.lens.library import list_lenses, load_lens

pytestmark = pytest.mark.slow

LENSES = [r.slug for r in list_lenses()]


def _pages_wanted(lens) -> list[str]:
    """One page, and a second for a zoom (across its range) or an anamorphic (its two meridians)."""
    return ["main"] + (["zoom"] if lens.zoom is not None else []) + (["anamorphic"] if lens.squeeze != 1.0 else [])


def test_page_sizes_are_a4_and_letter():
    w, h = PAGES["a4"]
    assert (w * 25.4, h * 25.4) == pytest.approx((210.0, 297.0))
    assert PAGES["letter"] == (8.5, 11.0)


@pytest.mark.parametrize("slug", LENSES)
def test_every_bundled_lens_has_a_card_with_every_panel(slug):
    from physcam.figures import figure_problems, pyplot
    from physcam.optics.paraxial import gaussian

    lens = load_lens(slug)
    card = draft_card(slug)
    assert card.key["efl_mm"] == pytest.approx(gaussian(lens).efl, rel=1e-12)
    assert card.key["image_circle_mm"] > 0
    assert card.pages == _pages_wanted(lens)
    figs = card.figures(dpi=30)
    try:
        assert len(figs) == len(card.pages)
        assert set(PANELS) <= {ax.get_label() for ax in figs[0].axes}
        for name, fig in zip(card.pages, figs):
            assert tuple(fig.get_size_inches()) == pytest.approx(PAGES["a4"]), name
            assert figure_problems(fig) == [], name
    finally:
        for fig in figs:
            pyplot().close(fig)


# one lens per kind of card: spherical prime, aspheric prime, zoom (two pages), anamorphic (two pages)
KINDS = ["dgauss_50mm", "sigma_50mm_f1_4_art", "canon_ef_70_200mm_f2_8_zoom", "navarro_anamorphic_2x"]


def test_the_kinds_cover_every_set_of_pages_a_bundled_card_has():
    assert {tuple(_pages_wanted(load_lens(s))) for s in LENSES} <= {tuple(_pages_wanted(load_lens(s))) for s in KINDS}
    assert any(s.kind == "aspheric" for s in load_lens(KINDS[1]).surfaces)


@pytest.mark.parametrize("slug", KINDS)
def test_the_pdf_has_one_page_per_card_page(slug, tmp_path):
    lens = load_lens(slug)
    card = draft_card(slug)
    data = save_lens_card(card, tmp_path / "card.pdf", dpi=30).read_bytes()
    assert data.startswith(b"%PDF")
    assert len(re.findall(rb"/Type\s*/Page[^s]", data)) == len(_pages_wanted(lens)) == len(card.pages)


def test_letter_page_and_png(tmp_path):
    card = lens_card(load_lens("dgauss_50mm"), quality="draft", page="letter", focus_mm=2000.0)
    png = save_lens_card(card, tmp_path / "card.png", dpi=40)
    from PIL import Image

    with Image.open(png) as im:
        assert im.size == (round(8.5 * 40), round(11.0 * 40))
    assert card.to_dict()["focus_from_film_mm"] == 2000.0


def test_bad_page_is_refused():
    from physcam.errors import InputError

    with pytest.raises(InputError, match="page must be one of"):
        lens_card(load_lens("dgauss_50mm"), page="a3", quality="draft")

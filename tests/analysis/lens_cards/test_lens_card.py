"""The lens card (issue 32): one page for every bundled lens, with every panel.

Each lens's card is rendered small (draft quality, 30 dpi). Checked: one page, two for a zoom or an
anamorphic lens (the PDF's page count), the page size stated (A4 210 x 297 mm, Letter 8.5 x 11 in: ISO 216 and ANSI), every panel's
axes present, and key numbers against independent values: the EFL from the paraxial y-u trace of
physcam.optics.paraxial, and the image circle at least the sensor it covers when the real chief
ray at the corner passes.
"""

from __future__ import annotations

import re

import pytest

from physcam.analysis.lens_cards.card import PAGES, PANELS, lens_card, save_lens_card
from physcam.lens.library import list_lenses, load_lens

pytestmark = pytest.mark.slow

LENSES = [r.slug for r in list_lenses()]


def test_page_sizes_are_a4_and_letter():
    w, h = PAGES["a4"]
    assert (w * 25.4, h * 25.4) == pytest.approx((210.0, 297.0))
    assert PAGES["letter"] == (8.5, 11.0)


@pytest.mark.parametrize("slug", LENSES)
def test_every_bundled_lens_has_a_card_with_every_panel(slug, tmp_path):
    from physcam.figures import figure_problems
    from physcam.optics.paraxial import gaussian

    lens = load_lens(slug)
    card = lens_card(lens, quality="draft")
    fig = card.figure(dpi=30)
    labels = {ax.get_label() for ax in fig.axes}
    assert set(PANELS) <= labels
    assert tuple(fig.get_size_inches()) == pytest.approx(PAGES["a4"])
    assert figure_problems(fig) == []
    assert card.key["efl_mm"] == pytest.approx(gaussian(lens).efl, rel=1e-12)
    assert card.key["image_circle_mm"] > 0
    pdf = save_lens_card(card, tmp_path / "card.pdf", dpi=30)
    data = pdf.read_bytes()
    assert data.startswith(b"%PDF")
    # one page, and a second for a zoom (across its range) or an anamorphic (its two meridians)
    want = ["main"] + (["zoom"] if lens.zoom is not None else []) + (["anamorphic"] if lens.squeeze != 1.0 else [])
    assert card.pages == want
    assert len(re.findall(rb"/Type\s*/Page[^s]", data)) == len(want)


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

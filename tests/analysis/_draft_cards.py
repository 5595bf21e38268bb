"""The draft lens card of a bundled lens, computed once per test process (pyproject.toml's pythonpath).

A card holds numbers (a dataclass of the analyses' results); each test draws its own figures or files from
it and none changes it, so the tests of tests/analysis that read the same lens's default draft card share
one: the lens cards' pages, layout and close-focus tests, and the MTF's spectrum words.
"""

from __future__ import annotations

import functools


@functools.cache
def draft_card(slug: str):
    """``lens_card(load_lens(slug), quality="draft")``, once per process."""
    from physcam.analysis.lens_cards.card import lens_card
    from physcam.lens.library import load_lens

    return lens_card(load_lens(slug), quality="draft")

"""The numbers the docs give of the bundled lens library, held to the library itself (new-user review, round 22:
README.md said "a library of 30 ... two anamorphics" when 51 lenses, three of them anamorphic, were bundled).

The oracle counts the lens files with ``tomllib`` (not physcam's loader): every ``*.toml`` of the bundled
folder, the zooms by their ``[zoom]`` table, the anamorphics by a ``[lens] squeeze`` other than 1.
"""

from __future__ import annotations

import re
import tomllib
from importlib import resources
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
WORDS = {"one": 1, "two": 2, "three": 3, "four": 4, "five": 5, "six": 6, "seven": 7, "eight": 8, "nine": 9, "ten": 10}


def _library():
    files = [f for f in resources.files("physcam.data").joinpath("lenses").iterdir() if f.name.endswith(".toml")]
    docs = [tomllib.loads(f.read_text(encoding="utf-8")) for f in files]
    return {"lenses": len(docs), "zooms": sum("zoom" in d for d in docs),
            "anamorphics": sum(d["lens"].get("squeeze", 1.0) != 1.0 for d in docs)}


def _number(text: str) -> int:
    return int(text) if text.isdigit() else WORDS[text.lower()]


#: (page, pattern, what each group counts): a sentence of the page stating the library's numbers
STATEMENTS = [
    ("README.md", r"ships a library of (\w+) of them \([^)]*?(\w+) zooms, (\w+) anamorphics\)",
     ("lenses", "zooms", "anamorphics")),
    ("docs/lens-library.md", r"physcam bundles (\w+) lenses, (\w+) of them zooms", ("lenses", "zooms")),
    ("docs/lens-library.md", r"The library has (\w+) anamorphics", ("anamorphics",)),
    ("docs/lens-formats.md", r"holds (\w+) lenses: (\w+) zooms", ("lenses", "zooms")),
]


def test_the_oracle_counts_the_library_physcam_lists():
    from physcam.lens.library import list_lenses, load_lens

    counted = _library()
    bundled = list_lenses("bundled")
    assert len(bundled) == counted["lenses"]
    assert sum(load_lens(r.slug).is_anamorphic for r in bundled) == counted["anamorphics"]


@pytest.mark.parametrize("page, pattern, what", STATEMENTS, ids=[f"{p} {w}" for p, _, w in STATEMENTS])
def test_the_docs_state_the_bundled_librarys_numbers(page, pattern, what):
    text = " ".join((ROOT / page).read_text(encoding="utf-8").split())  # sentences wrapped across lines
    m = re.search(pattern, text)
    assert m, f"{page} no longer says {pattern!r}: keep a statement of the library's numbers, or change this test"
    counted = _library()
    assert {w: _number(g) for w, g in zip(what, m.groups())} == {w: counted[w] for w in what}

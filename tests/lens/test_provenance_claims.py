"""A lens file that says its numbers were compared with the primary source must say with what and how
(issue 44): the source names the example, table or page, ``checked``/``checked_by`` say when and by
whom, and one ``checks`` line starting ``primary source:`` names that place and the numbers compared.

The records below are written here by hand (a made-up transcription of a patent example), not taken
from physcam's output; each test removes one piece and expects the sentence that names it.
"""

import dataclasses
import re
from pathlib import Path

import pytest

from physcam.lens.check import check
from physcam.lens.library import find_lens, list_lenses, load_lens
from physcam.lens.provenance import Provenance, primary_source_claim_gaps, provenance_of

from patent_stated import PATENT_STATED

BACKED = Provenance(
    source="US 9,999,999 (Example Co.), example 2 (Table 2)",
    source_url="https://patents.google.com/patent/US9999999B2/en",
    licence="CC0-1.0",
    transcribed="2026-11-28",
    transcribed_by="a contributor",
    primary_source_checked=True,
    checked="2026-11-28",
    checked_by="a second contributor",
    checks=(
        "primary source: every radius, gap, nd and Vd of Table 2 against the file: r1 52.310 against 52.310, "
        "d1 6.20 against 6.20, nd 1.88300 against 1.88300, Vd 40.80 against 40.80 (all 31 rows equal)",
        "EFL: the patent's stated 51.10 mm against paraxial 51.100 mm",
    ),
)


def test_a_backed_claim_has_no_gaps():
    assert primary_source_claim_gaps(BACKED) == []


@pytest.mark.parametrize("change, words", [
    ({"source": "US 9,999,999 (Example Co.)"}, "does not name the example, table or page"),
    ({"checked_by": None}, "checked and checked_by"),
    ({"checks": ("EFL: the patent's stated 51.10 mm against paraxial 51.100 mm",)}, "no checks line"),
    ({"checks": ("primary source: Table 2 compared",)}, "no checks line"),  # no numbers, no comparison
    ({"checks": ("primary source: not reached; Table 2 of the patent is 51.10 against 51.100",)}, "not reached"),
])
def test_each_missing_piece_is_named(change, words):
    gaps = primary_source_claim_gaps(dataclasses.replace(BACKED, **change))
    assert len(gaps) == 1 and words in gaps[0]


def test_a_book_page_and_a_design_revision_are_places():
    book = dataclasses.replace(BACKED, source="W. J. Smith, Modern Lens Design (1st ed., 1992), p. 312",
                               source_url=None, checks=("primary source: the table on p. 312 against the file: "
                                                        "r1 58.950 against 58.950, nd 1.670 against 1.670",))
    design = dataclasses.replace(BACKED, source="Beloved Lens Co. design BL-50, revision C", source_url=None,
                                 checks=("primary source: revision C's table against the file: r1 24.84 against "
                                         "24.84 ... (every row equal)",))
    assert primary_source_claim_gaps(book) == [] == primary_source_claim_gaps(design)


def test_a_patent_claim_and_column_are_places():
    # an old patent prints its one example as a claim's table or in a column, unnumbered otherwise
    claim = dataclasses.replace(BACKED, source="US 2,701,982 (P. Angenieux), the table of claim 4 (column 3)",
                                checks=("primary source: claim 4's table against the file: R1 +164.13 against "
                                        "164.13 (every row equal)",))
    assert primary_source_claim_gaps(claim) == []
    unplaced = dataclasses.replace(claim, source="US 2,701,982 (P. Angenieux), in a claim")
    assert len(primary_source_claim_gaps(unplaced)) == 1


def test_no_claim_no_gaps():
    assert primary_source_claim_gaps(dataclasses.replace(BACKED, primary_source_checked=False, checks=())) == []
    assert primary_source_claim_gaps(Provenance()) == []


@pytest.mark.parametrize("rec", list_lenses("bundled"), ids=lambda r: r.slug)
def test_every_bundled_record_backs_what_it_claims(rec):
    """A bundled lens marked checked names its source's place and the compared values; one not
    marked checked says the primary source was not reached (tests/lens/test_library.py), so no
    bundled file may carry a bare claim."""
    prov = provenance_of(load_lens(rec.slug))
    assert primary_source_claim_gaps(prov) == []
    if prov.primary_source_checked:  # a bundled lens also says where its source can be read
        assert prov.source_url and any(c.startswith("primary source:") for c in prov.checks)


def _claiming(tmp_path, slug="tessar_50mm_f2_8"):
    text = Path(find_lens(slug).path).read_text()
    assert "primary_source_checked = false" in text
    path = tmp_path / f"{slug}_claimed.toml"
    path.write_text(text.replace("primary_source_checked = false", "primary_source_checked = true"))
    return path


def test_lens_check_warns_of_a_claim_the_record_does_not_back(tmp_path):
    # the bundled Tessar says "primary source: not reached"; flipping only the flag is a bare claim
    (f,) = [f for f in check(_claiming(tmp_path)) if f.code == "provenance_check_unstated"]
    assert f.severity == "warning" and "not reached" in f.message
    assert f.values["gaps"] == ["a checks line says the primary source was not reached"]
    assert not [f for f in check("tessar_50mm_f2_8") if f.code == "provenance_check_unstated"]


def test_lens_check_accepts_a_backed_claim(tmp_path):
    path = _claiming(tmp_path)
    text = path.read_text().replace(
        '"primary source: not reached.',
        '"primary source: embodiment 1 against the file: r1 18.95 against 18.95 (made up for this test)", "x:', 1)
    path.write_text(text)
    codes = {f.code for f in check(path)}
    assert "provenance_check_unstated" not in codes and "provenance_unchecked" not in codes


@pytest.mark.parametrize("slug", sorted(PATENT_STATED))
def test_the_stated_numbers_in_the_file_are_the_sources(slug):
    """[lens] focal_length and max_fstop, and the stated EFL its checks line compares, are the numbers
    tests/lens/patent_stated.py typed from the transcriptions of the patents' tables, not physcam's
    paraxial values (which differ in the last digits: 49.993 against the stated 49.99)."""
    want = PATENT_STATED[slug]
    p = load_lens(slug)
    assert p.metadata.focal_length == want["efl"] and p.metadata.max_fstop == want["fno"]
    (line,) = [c for c in provenance_of(p).checks if c.startswith("EFL:")]
    stated = re.search(r"stated focal length \(as transcribed\) (\d+(?:\.\d+)?) mm against paraxial (\d+\.\d+)", line)
    assert float(stated.group(1)) == want["efl"]

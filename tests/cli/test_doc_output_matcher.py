"""The doc-output matcher (tests/cli/_doc_output.py) on cases worked by hand: it must be able to fail."""

from __future__ import annotations

from _doc_output import block_rule, compare

PRINTED = """Double Gauss: MTF at f/2.8
  film: best focus for 40 lp/mm, +56.1 um from the paraxial image plane
height mm  field deg  40 S  40 T
     0.00       0.00  0.897 0.897
     7.77      8.80   0.641 0.512
"""


def test_numbers_within_one_unit_of_the_last_shown_digit():
    assert compare(["  film: best focus for 40 lp/mm, +56.1 um from the paraxial image plane"], PRINTED) == []
    assert compare(["film: best focus for 40 lp/mm, +56.2 um from the paraxial image plane"], PRINTED) == []
    bad = compare(["film: best focus for 40 lp/mm, +66 um from the paraxial image plane"], PRINTED)
    assert bad == ["shows +66 where the command prints +56.1: 'film: best focus for 40 lp/mm, +66 um from the "
                   "paraxial image plane'"]
    assert compare(["0.00 0.00 0.32 0.32"], PRINTED) != []  # the 0.32 where 0.897 is printed


def test_order_gaps_ellipses_and_table_rows():
    assert compare(["Double Gauss: ...", "...", "7.77 8.80 0.641 0.512"], PRINTED) == []
    assert compare(["7.77 8.80 0.641 0.512", "0.00 0.00 0.897 0.897"], PRINTED) != []  # out of order
    assert compare(["a line it never printed"], PRINTED) == ["not printed (in this order): 'a line it never printed'"]


def test_a_block_states_its_tolerance_or_why_it_is_not_compared():
    assert block_rule("<!-- doc-output: numbers within 2 % (Monte Carlo rays) -->") == (True, 0.02)
    assert block_rule("<!-- doc-output: unchecked (the port is chosen by the system) -->") == (False, None)
    assert block_rule("some prose") == (True, None)
    assert compare(["7.77 8.80 0.65 0.52"], PRINTED, rel_tol=0.02) == []


def test_warnings_are_looked_for_on_stderr():
    err = "physcam: warning: real chief rays give 140.0° x 89.4°; the pinhole field is 97.6°\n"
    shown = ["physcam: warning: real chief rays give 140.0° x 89.4°; the pinhole", "field is 97.6°",
             "Double Gauss: MTF at f/2.8"]
    assert compare(shown, PRINTED, err) == []
    assert compare(["physcam: warning: real chief rays give 141.0° x 89.4°"], PRINTED, err) != []

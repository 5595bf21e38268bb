"""Feet and inches typed with typographic marks, as a phone's keyboard types them (round 22 review).

iOS and Android keyboards turn ``'`` and ``"`` into ’ and ” ("smart punctuation"); typesetters write the prime
′ and double prime ″ (Unicode's charts annotate U+2032 "minutes, feet" and U+2033 "seconds, inches"). Every
distance physcam reads goes through ``physcam.units.parse_distance``, so each front end is checked here once
with the real component: the parser, ``physcam report``, a lens-set file read by ``physcam hyperfocal``.
The expected millimetres are worked by hand from the international foot and inch (1 in = 25.4 mm exactly,
1 ft = 12 in): 10 ft 6 in = 126 in = 3200.4 mm; 20 ft = 6096 mm; 6 in = 152.4 mm; 9 ft 10 1/8 in =
118.125 in = 3000.375 mm; 1 ft 2 in = 14 in = 355.6 mm.
"""

from __future__ import annotations

import json

import pytest

from physcam.cli import main
from physcam.errors import UnitError
from physcam.units import parse_distance, plain_marks
from _typed_distances import TYPED


@pytest.mark.parametrize("text, mm", TYPED)
def test_typographic_feet_and_inches_are_read_by_hand_values(text, mm):
    assert parse_distance(text) == pytest.approx(mm, rel=1e-12)


def test_plain_marks_maps_exactly_the_six_marks():
    assert plain_marks("’|‘|′|”|“|″") == "'|'|'|\"|\"|\""
    assert plain_marks("3m 450mm 2.5 cm") == "3m 450mm 2.5 cm"  # nothing else changes


@pytest.mark.parametrize("text", ["x’", "’6", "10’6”7", "10”6’", "‘10’"])
def test_nonsense_with_marks_is_refused_quoting_what_was_typed(text):
    with pytest.raises(UnitError) as exc:
        parse_distance(text, name="focus distance")
    assert repr(text) in str(exc.value)


def test_report_reads_a_phone_typed_focus(capsys):
    """`physcam report --focus "10’6”"` (refused before the fix: "cannot read focus distance") marks 3200.4 mm."""
    for typed in ("10’6”", "10′6″", "10’ 6”"):
        capsys.readouterr()
        assert main(["report", "--focal", "50", "--fstop", "2.8", "--focus", typed, "--json"]) == 0
        assert json.loads(capsys.readouterr().out)["focus_from_film_mm"] == pytest.approx(3200.4, rel=1e-12)


def test_a_lens_set_file_reads_typographic_close_focus(capsys, tmp_path):
    """A lens set typed on a phone: `50 T1.3 20’` was refused ("set3.txt, line 4: cannot read close focus")."""
    f = tmp_path / "set3.txt"
    f.write_text("# set3\n25 T1.3 10”\n35 T1.3 1′ 2″\n50 T1.3 20’\n", encoding="utf-8")
    assert main(["hyperfocal", "--lens-set", str(f), "--fstops", "2.8", "--sensor", "S35", "--json"]) == 0
    lenses = json.loads(capsys.readouterr().out)["lenses"]
    assert [x["close_focus_mm"] for x in lenses] == pytest.approx([254.0, 355.6, 6096.0], rel=1e-12)

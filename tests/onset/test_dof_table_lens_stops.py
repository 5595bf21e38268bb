"""The f-stops of a depth-of-field table of a real lens (new-user review, round 22).

`physcam dof-table --lens tessar_50mm_f2_8 --focus 2m` failed on its own default f/1.4 ("faster than this
lens opens"), which the user never typed; a typed f-stop faster than the lens stays refused. And
`--fstops T2.8` read a T-stop as f/2.8, where `report --fstop T2` refuses it.

Oracles: the engraved widest stops of the lenses' names (Tessar f/2.8, Cooke triplet f/4.5), optiland's
paraxial f-number of the double Gauss (tests/data/optiland_library.json, f/2.030: its file's stop is
slower than the engraved f/2), the default stops of docs/cli.md (f/1.4 to f/16 in full stops), and
`physcam compare`'s wide-open f-stop for the same lens.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from physcam.cli import main

FULL_STOPS = [1.4, 2.0, 2.8, 4.0, 5.6, 8.0, 11.0, 16.0]  # docs/cli.md: "Defaults: f/1.4 to f/16 in full stops"


def _table(capsys, *argv):
    assert main(["dof-table", *argv, "--sensor", "S35", "--focus", "2m", "--json"]) == 0
    out = capsys.readouterr()
    return json.loads(out.out), out.err


@pytest.mark.parametrize("lens, first", [("tessar_50mm_f2_8", []), ("cooke_triplet_50mm_f4_5", [4.5])])
def test_the_default_stops_start_at_the_engraved_widest_with_a_note(capsys, lens, first):
    """Tessar f/2.8: f/2.8 to f/16 (f/1.4 and f/2 left out); the f/4.5 triplet: f/4.5 first, then the full
    stops from f/5.6 (f/4 left out too). The note says so on stderr and in the JSON."""
    d, err = _table(capsys, "--lens", lens)
    wide = first[0] if first else 2.8
    assert d["fstops"] == first + [n for n in FULL_STOPS if n >= wide]
    left_out = ", ".join(f"f/{n:g}" for n in FULL_STOPS if n < wide)
    assert d["notes"] == [f"the lens opens only to f/{wide:g}: the default f-stops start there, wide open "
                          f"({left_out} left out)"]
    assert f"physcam: note: {d['notes'][0]}" in err


def test_a_file_slower_than_its_engraving_starts_at_its_own_stop_as_compare_does(capsys):
    """The double Gauss is engraved f/2 but its file's stop gives f/2.030 (optiland): the table starts at
    f/2.03, which is the f-stop `physcam compare` compares it at when asked for f/1.4 (wide open)."""
    from physcam.lens.library import load_lens
    from physcam.onset.lens_compare import fstop_for_comparison

    optiland = json.loads((Path(__file__).resolve().parents[1] / "data" / "optiland_library.json").read_text())
    paraxial = optiland["lenses"]["dgauss_50mm"]["y"]["f_number"]
    d, _ = _table(capsys, "--lens", "dgauss_50mm")
    assert d["fstops"] == [round(paraxial, 2), 2.8, 4.0, 5.6, 8.0, 11.0, 16.0]
    wide, notes = fstop_for_comparison(load_lens("dgauss_50mm"), 1.4)
    assert notes and d["fstops"][0] == pytest.approx(wide, rel=1e-3)


def test_a_thin_lens_and_a_fast_lens_keep_every_default_stop(capsys):
    assert _table(capsys, "--focal", "50")[0]["fstops"] == FULL_STOPS
    d, err = _table(capsys, "--lens", "arri_zeiss_master_prime_50mm")  # f/1.24 in its file
    assert d["fstops"] == FULL_STOPS and d["notes"] == [] and "note: the lens opens" not in err


def test_a_typed_stop_faster_than_the_lens_is_still_refused(capsys):
    assert main(["dof-table", "--lens", "tessar_50mm_f2_8", "--sensor", "S35", "--focus", "2m",
                 "--fstops", "1.4,2.8"]) == 2
    assert "f/1.4 is faster than this lens opens" in capsys.readouterr().err


def test_the_functions_default_is_the_commands(capsys):
    """dof_table(lens=...) without fstops: the same stops and note as the command without --fstops."""
    from physcam.lens.library import load_lens
    from physcam.onset.dof_table import dof_table

    api = dof_table(lens=load_lens("tessar_50mm_f2_8"), sensor="S35", focus_marks_mm=["2m"])
    d, _ = _table(capsys, "--lens", "tessar_50mm_f2_8")
    assert api["fstops"] == d["fstops"] == [2.8, 4.0, 5.6, 8.0, 11.0, 16.0] and api["notes"] == d["notes"]


@pytest.mark.parametrize("command", [["dof-table", "--focal", "50", "--sensor", "S35", "--focus", "2m"],
                                     ["hyperfocal", "--focal", "50", "--sensor", "S35"]])
def test_a_t_stop_in_the_list_is_refused_as_the_report_refuses_it(capsys, command):
    """A T-stop (transmission) is not the geometric f-number: `report --fstop T2` says so; so do the lists.
    "f/2.8" is the f-number written as engraved, and is read."""
    assert main(["report", "--focal", "50", "--sensor", "S35", "--focus", "2m", "--fstop", "T2.8"]) == 2
    said = capsys.readouterr().err.split("error: ", 1)[1].split(": ", 1)[1]
    assert main([*command, "--fstops", "2,T2.8"]) == 2
    err = capsys.readouterr().err
    assert "f/2.8" not in err and said in err  # the report's own words: "f-stop must be a number, got 'T2.8': ..."
    assert main([*command, "--fstops", "f/2.8", "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    stops = doc["fstops"] if command[0] == "dof-table" else [s["fstop"] for s in doc["lenses"][0]["stops"]]
    assert stops == [2.8]

"""A stop typed as it is engraved ("T2.8", "f/2.8") gets the number to type instead (round 8: a 1st AC's
first day). The oracle is the text typed: the number in it, and --tstop named only for a T."""

from __future__ import annotations

import pytest

from physcam.cli import main

BASE = ["report", "--focal", "50", "--focus", "3m", "--sensor", "S35"]


@pytest.mark.parametrize("option, typed, number, tstop_named", [
    ("--fstop", "T2.8", "2.8", True),
    ("--fstop", "f/2.8", "2.8", False),
    ("--fstop", "F 5.6", "5.6", False),
    ("--tstop", "T2.8", "2.8", False),
])
def test_an_engraved_stop_is_answered_with_the_number_to_type(capsys, option, typed, number, tstop_named):
    extra = ["--near", "2.5m"] if option == "--tstop" else []
    assert main([*BASE, *extra, option, typed]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and f"write the number alone, {number}" in err
    assert ("a T-stop is --tstop" in err) == tstop_named


def test_a_word_that_is_no_stop_gets_no_hint(capsys):
    assert main([*BASE, "--fstop", "fast"]) == 2
    err = capsys.readouterr().err
    assert "must be a number, got 'fast'" in err and "write the number" not in err


def test_a_t_stop_alone_says_how_to_give_the_f_stop(capsys, tmp_path):
    """A matchmove artist's notes say T2.8 and no f-stop: `usd write --tstop 2.8` was told only to
    "give the f-stop (--fstop) or a measured near/far limit" (round 8)."""
    for argv in (["report", *BASE[1:]], ["usd", "write", str(tmp_path / "never.usda"), "--focal", "50", "--focus", "3m"]):
        assert main([*argv, "--tstop", "2.8"]) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and "a T-stop alone (--tstop 2.8)" in err and "--fstop 2.8 takes the T-stop" in err
    assert not (tmp_path / "never.usda").exists()

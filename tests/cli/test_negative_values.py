"""A value that starts with a minus is a value (a new user's first day, round 8).

A matchmove artist's camera tilted down 5 degrees is `--rotate -5,30,0`; argparse took that for an
unknown option and said "expected one argument" (only `--rotate=-5,30,0` worked). The oracle is the
`=` spelling, which argparse has always read as a value, and the numbers typed.
"""

from __future__ import annotations

import json

import pytest

from physcam.cli import build_parser, main


@pytest.mark.parametrize("option, value, dest, expected", [
    ("--rotate", "-5,30,0", "rotate", (-5.0, 30.0, 0.0)),
    ("--position", "-10,150,-500", "position", (-10.0, 150.0, -500.0)),
])
def test_a_shot_tilted_down_reads_its_negative_numbers(option, value, dest, expected):
    argv = ["usd", "kit", "shot", "sh010.usda", "--body", "b.usda", "--lens", "l.usda"]
    spaced = build_parser(argv).parse_args([*argv, option, value])
    joined = build_parser(argv).parse_args([*argv, f"{option}={value}"])
    assert getattr(spaced, dest) == getattr(joined, dest) == expected


def test_a_negative_shift_with_an_exponent_is_the_same_as_with_equals(capsys):
    base = ["report", "--focal", "50", "--fstop", "2.8", "--focus", "3m", "--sensor", "S35", "--json"]
    docs = []
    for shift in (["--shift-y", "-1.5e-1"], ["--shift-y=-1.5e-1"]):
        assert main([*base, *shift]) == 0
        docs.append(json.loads(capsys.readouterr().out))
    assert docs[0] == docs[1]
    assert "-0.15" in json.dumps(docs[0]["cameras"])


def test_a_negative_focus_is_refused_for_what_it_is(capsys):
    assert main(["report", "--focal", "50", "--fstop", "2.8", "--focus", "-3m"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "focus distance must be greater than 0" in err
    assert "expected one argument" not in err

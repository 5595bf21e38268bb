"""Hostile input an outside review tried (issue 24 item 12): each is refused with one line,
``physcam: error: ...``, exit 2, never a traceback, and a long name is shortened in that line.

The instances: a lens name, lens path, input or output path of 256+ characters (the system's
limit is 255 bytes a name, ENAMETOOLONG), a folder where a file is written, ``bokeh
--rays/--pixels/--blades`` with a 400-digit number, ``mtf --frequency 1e-320`` (a subnormal: the
pupil grid it asked for overflowed to infinity), a config TOML and a lens TOML nested 5000 deep
(Python's tomllib recurses once a level: RecursionError).
"""

from __future__ import annotations

import pytest

from physcam.cli import main

LONG = "a" * 300  # longer than NAME_MAX (255 bytes) on every POSIX file system physcam runs on
HUGE = "9" * 400
DEEP = 5000
#: an error line quotes a shortened name: start, end and the count, not all 300 characters
MAX_LINE = 400


def refused(capsys, argv) -> str:
    """Run ``physcam argv``: it must exit 2 with one ``physcam: error:`` line; returns that line."""
    try:
        rc = main(argv)
    except BaseException as exc:  # noqa: BLE001 - the point: nothing escapes main()
        pytest.fail(f"physcam {' '.join(a[:40] for a in argv)} raised {exc.__class__.__name__}: {str(exc)[:200]}")
    err = capsys.readouterr().err
    lines = err.strip().splitlines()
    assert rc == 2, (rc, err[-500:])
    assert len(lines) == 1 and lines[0].startswith("physcam: error:"), err[-1000:]
    assert "Traceback" not in err
    return lines[0]


@pytest.fixture
def here(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("PHYSCAM_CONFIG", "")
    return tmp_path


LONG_NAMES = [
    ["lens", "show", "--lens", LONG],
    ["report", "--lens", LONG, "--fstop", "4", "--focus", "3m"],
    ["lens", "show", "--lens", LONG + ".toml"],
    ["lens", "show", "--lens", f"{LONG}/lens.toml"],
    ["usd", "check", LONG + ".usda"],
    ["usd", "write", "--focal", "50", "--fstop", "2.8", "--focus", "3m", LONG + ".usda"],
    ["distortion", "--lens", "dgauss_50mm", "--resolution", "64x48", "--stmap", f"{LONG}/maps"],
]


@pytest.mark.parametrize("argv", LONG_NAMES, ids=lambda a: " ".join(x[:12] for x in a))
def test_a_name_of_300_characters_is_one_shortened_line(capsys, here, argv):
    line = refused(capsys, argv)
    assert len(line) < MAX_LINE, line
    assert "characters)" in line, line
    assert LONG not in line


def test_a_folder_given_as_the_file_to_write_is_one_line(capsys, here):
    (here / "shot.usda").mkdir()
    line = refused(capsys, ["usd", "write", "--focal", "50", "--fstop", "2.8", "--focus", "3m", "shot.usda", "--force"])
    assert "shot.usda" in line


@pytest.mark.parametrize("option", ["--rays", "--pixels", "--blades"])
def test_bokeh_with_a_400_digit_number_is_refused(capsys, here, option):
    line = refused(capsys, ["bokeh", "--lens", "dgauss_50mm", option, HUGE])
    assert option in line and "whole number from" in line and "(400 characters)" in line


def test_mtf_at_a_subnormal_frequency_is_refused(capsys, here):
    # 1e-320 lp/mm is below the smallest normal double (2.2e-308): the grid it needs is infinite
    line = refused(capsys, ["mtf", "--lens", "dgauss_50mm", "--frequency", "1e-320"])
    assert "--frequency" in line and "1e-320" in line


@pytest.mark.parametrize("nested", ["[" * DEEP + "]" * DEEP, "{a = " * DEEP + "1" + "}" * DEEP],
                         ids=["arrays", "inline tables"])
def test_a_config_nested_5000_deep_is_refused_naming_it(capsys, here, monkeypatch, nested):
    cfg = here / "deep.toml"
    cfg.write_text(f"sensor = {nested}\n")
    monkeypatch.setenv("PHYSCAM_CONFIG", str(cfg))
    line = refused(capsys, ["report", "--focal", "50", "--fstop", "2.8", "--focus", "3m"])
    assert "deep.toml" in line and "too deeply" in line


def test_a_lens_file_nested_5000_deep_is_refused(capsys, here):
    (here / "deep_lens.toml").write_text("name = " + "[" * DEEP + "]" * DEEP + "\n")
    line = refused(capsys, ["lens", "show", "--lens", "deep_lens.toml"])
    assert "deep_lens.toml" in line or "too deeply" in line


def test_short_names_stay_whole():
    from physcam.cli import SHOWN_NAME_CHARS, short_name

    assert short_name("shot.usda") == "shot.usda"
    assert short_name("b" * SHOWN_NAME_CHARS) == "b" * SHOWN_NAME_CHARS
    s = short_name("c" * 1000 + ".usda")
    assert len(s) < 2 * SHOWN_NAME_CHARS and s.endswith("c.usda (1005 characters)")

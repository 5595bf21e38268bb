"""Sane bounds on the circle of confusion and the focal length (round 22 review).

``report --coc 1e-300`` printed a 300-digit hyperfocal distance, ``--coc 5m`` a hyperfocal of 10 m from a 5 m blur,
``--focal 0.001`` "hyperfocal 0.0 mm". One range each, in the library (physcam.optics.coc.require_coc: 0.001 to
1 mm; physcam.optics.thinlens.require_focal_length: 1 mm to 100 m; their sources in the constants' comments), read
by every option, the config, the on-set report, close-up lenses and the page (tests/serve/test_onset_js.py):
outside, one line and exit 2. Inside, the edges are answered, with the thin-lens hyperfocal worked by hand.
"""

from __future__ import annotations

import json
import math

import pytest

from physcam.cli import main
from physcam.errors import InputError


def _refused(capsys, argv) -> str:
    """Exit 2 and one line on stderr (argparse's, or a PhysCamError from the handler)."""
    capsys.readouterr()
    try:
        rc = main(argv)
    except SystemExit as exc:
        rc = exc.code
    err = capsys.readouterr().err
    assert rc == 2 and err.count("\n") == 1 and err.startswith("physcam: error: "), err
    return err


REPORT = ["report", "--focal", "50", "--fstop", "2", "--focus", "3m", "--sensor", "S35"]


@pytest.mark.parametrize("coc", ["1e-300", "5m", "0.0009", "1.001", "0.9um", "2mm"])
def test_a_coc_out_of_range_is_one_line(capsys, coc):
    err = _refused(capsys, [*REPORT, f"--coc={coc}"])
    assert "argument --coc: circle of confusion" in err and "out of range" in err


@pytest.mark.parametrize("argv", [
    ["hyperfocal", "--focal", "50", "--coc", "5m"],
    ["diopter", "--focal", "50", "--fstop", "4", "--focus", "1m", "--coc", "1e-300"],
    ["compare", "dgauss_50mm", "--coc", "5m"],
])
def test_every_coc_option_is_the_one_definition(capsys, argv):
    assert "out of range" in _refused(capsys, argv)


def test_the_edges_are_answered_with_the_hand_hyperfocal(capsys):
    """--coc 1 (mm), f = 50 mm, N = 2: H = f^2 / (N c) + f = 2500 / 2 + 50 = 1300 mm from H1, whose image lies
    s' = H f / (H - f) = 1300 x 50 / 1250 = 52 mm behind H2: the mark is 1352 mm from the film. --coc 0.001:
    H = 2500 / 0.002 + 50 = 1 250 050 mm, s' = 1 250 050 x 50 / 1 250 000 = 50.002 mm."""
    for coc, mark in (("1", 1352.0), ("1um", 1250050.0 + 1250050.0 * 50 / 1250000.0)):
        capsys.readouterr()
        assert main([*REPORT, "--coc", coc, "--json"]) == 0
        d = json.loads(capsys.readouterr().out)
        assert d["dof"]["hyperfocal_from_film_mm"] == pytest.approx(mark, rel=1e-12)


@pytest.mark.parametrize("focal", ["0.001", "0.999", "0.5mm", "1e-300"])
def test_a_focal_length_shorter_than_any_lens_is_one_line(capsys, focal):
    err = _refused(capsys, ["report", "--focal", focal, "--fstop", "2", "--focus", "3m"])
    assert "argument --focal: focal length" in err and "shorter than any camera lens" in err


@pytest.mark.parametrize("argv", [
    ["hyperfocal", "--focal", "35,0.5"],
    ["diopter", "--focal", "0.5", "--fstop", "4", "--focus", "1m"],
    ["dof-table", "--focal", "0.5", "--fstops", "2", "--focus", "3m"],  # read by the library's ThinLens
])
def test_every_focal_option_refuses_it(capsys, argv):
    assert "shorter than any camera lens" in _refused(capsys, argv)


def test_one_millimetre_is_a_focal_length(capsys):
    """f = 1 mm, N = 2, d/1500 on Super 35 (c = hypot(24.89, 18.66) / 1500): H = f^2 / (N c) + f from H1."""
    assert main(["report", "--focal", "1", "--fstop", "2", "--focus", "3m", "--sensor", "S35", "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    c = math.hypot(24.89, 18.66) / 1500.0
    h = 1.0 / (2.0 * c) + 1.0
    assert d["dof"]["hyperfocal_from_film_mm"] == pytest.approx(h + h / (h - 1.0), rel=1e-9)


def test_the_library_keeps_the_bounds_itself():
    from physcam.onset.diopter import close_up
    from physcam.optics.coc import circle_of_confusion, parse_coc
    from physcam.optics.lens_model import ThinLens
    from physcam.optics.state import camera_state

    for bad in (1e-300, 5000.0, "5000mm", "0.0001mm"):
        with pytest.raises(InputError, match="out of range"):
            circle_of_confusion(24.89, 18.66, bad)
    with pytest.raises(InputError, match="out of range"):
        parse_coc("5m")
    with pytest.raises(InputError, match="shorter than any camera lens"):
        ThinLens(0.001)
    with pytest.raises(InputError, match="out of range"):
        camera_state(ThinLens(50.0), focus_mm="hyperfocal", fstop=2.0, coc=1e-300)
    with pytest.raises(InputError, match="shorter than any camera lens"):
        close_up(0.5, 4.0, 0.025, 1000.0, 1.0)
    with pytest.raises(InputError, match="out of range"):
        close_up(50.0, 4.0, 5000.0, 1000.0, 1.0)
    assert circle_of_confusion(24.89, 18.66, 0.001) == (0.001, "user")
    assert circle_of_confusion(24.89, 18.66, 1.0) == (1.0, "user")


def test_the_config_coc_is_bounded_too(capsys, tmp_path, monkeypatch):
    cfg = tmp_path / "physcam.toml"
    monkeypatch.setenv("PHYSCAM_CONFIG", str(cfg))
    for text in ("coc = 5.0\n", 'coc = "5m"\n'):
        cfg.write_text(text)
        err = _refused(capsys, REPORT)
        assert "coc:" in err and "out of range" in err

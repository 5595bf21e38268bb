"""``physcam lens zoom`` and ``--zoom`` (issue 45): the table, its JSON, the figure, and one-line refusals."""

from __future__ import annotations

import json

import pytest

from physcam.cli import main


def _run(capsys, *argv):
    rc = main(list(argv))
    out, err = capsys.readouterr()
    return rc, out, err


def test_zoom_json_has_a_row_per_position(capsys):
    rc, out, _ = _run(capsys, "lens", "zoom", "--lens", "nikon_af_s_70_200mm_f2_8e_zoom", "--json")
    doc = json.loads(out)
    assert rc == 0 and doc["schema"] == "physcam.lens_zoom" and doc["positions"] == 3
    tab = [r for r in doc["rows"] if r["tabulated"]]
    # the transcription's focal lengths, 71.5 / 135.0 / 196.0 mm
    assert [round(r["efl_mm"], 1) for r in tab] == [71.5, 135.0, 196.0]


def test_zoom_at_a_focal_length(capsys):
    rc, out, _ = _run(capsys, "lens", "show", "--lens", "canon_ef_70_200mm_f2_8_zoom", "--zoom", "100mm", "--json")
    doc = json.loads(out)
    assert rc == 0 and doc["zoom"]["efl_mm"] == pytest.approx(100.0, rel=1e-9)
    assert doc["meridians"]["y"]["efl"] == pytest.approx(100.0, rel=1e-9)


def test_report_takes_the_zoom(capsys):
    rc, out, _ = _run(capsys, "report", "--lens", "laikin_zoom_15_150mm", "--zoom", "50mm", "--fstop", "4",
                      "--focus", "3m", "--json")
    assert rc == 0
    assert json.loads(out)["focal_length_mm"] == pytest.approx(50.0, rel=1e-6)


@pytest.mark.parametrize("argv, words", [
    (("lens", "show", "--lens", "canon_ef_70_200mm_f2_8_zoom", "--zoom", "70mm"), "72.12 to 193.91 mm"),
    (("lens", "zoom", "--lens", "dgauss_50mm"), "not a zoom lens"),
    (("lens", "show", "--lens", "dgauss_50mm", "--zoom", "0.5"), "not a zoom lens"),
    (("lens", "zoom", "--lens", "laikin_zoom_15_150mm", "--steps", "1"), "--steps"),
    (("report", "--lens", "laikin_zoom_15_150mm", "--zoom", "1.5"), "0 to 1"),
])
def test_bad_zoom_input_is_one_line_and_exit_2(capsys, argv, words):
    rc, _, err = _run(capsys, *argv)
    assert rc == 2 and err.count("\n") == 1 and words in err and "Traceback" not in err


def test_zoom_figure_is_written_once(capsys, tmp_path):
    out = tmp_path / "zoom.png"
    rc, text, _ = _run(capsys, "lens", "zoom", "--lens", "laikin_zoom_15_150mm", "-o", str(out))
    assert rc == 0 and out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and "image shift" in text
    rc, _, err = _run(capsys, "lens", "zoom", "--lens", "laikin_zoom_15_150mm", "-o", str(out))
    assert rc == 2 and "exists" in err

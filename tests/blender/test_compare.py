"""`physcam compare blender` (issue 10.4): the same point light through physcam's tracer and Cycles,
one figure and one JSON table of measured agreement."""

import json

import pytest

from physcam.cli import main

from _blender import require_blender

pytestmark = pytest.mark.slow


def test_compare_blender_writes_figure_and_agreeing_table(tmp_path, monkeypatch, capsys):
    monkeypatch.setenv("PHYSCAM_BLENDER_PYTHON", require_blender().path)
    out = tmp_path / "cmp"
    assert main(["compare", "blender", "dgauss_50mm", "--focus", "2m", "--fstop", "2.8", "--light", "0.7m",
                 "--blades", "6", "--blade-angle", "15", "-o", str(out), "--json"]) == 0
    table = json.loads(capsys.readouterr().out)
    from _documents import check_document

    assert check_document(table) == "physcam.compare_blender"
    d = table["measured"]["equivalent_diameter_mm"]
    assert d["ratio"] == pytest.approx(1.0, abs=0.03)  # the 3 % on the bokeh size
    assert table["measured"]["corners"] == {"cycles": 6, "physcam": 6}
    assert (out / "compare.png").read_bytes()[:4] == b"\x89PNG"
    assert json.loads((out / "compare.json").read_text())["measured"] == table["measured"]
    assert main(["compare", "blender", "dgauss_50mm", "--focus", "2m", "--fstop", "2.8", "--light", "0.7m",
                 "-o", str(out)]) == 2  # no clobber without --force

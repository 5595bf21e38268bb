"""Issue 39 item 8: the tables a script prints into a doc page are what the script prints today.

docs/lens-report.md's real-ray depth-of-field table comes from scripts/real_dof_table.py; its rows are
recomputed here (three of the ten: a second each) and compared as the doc commands' shown output is
(tests/cli/_doc_output.py: each number within one unit in its last digit)."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import pytest
from _doc_output import compare

pytestmark = pytest.mark.slow

REPO = Path(__file__).resolve().parents[2]


def _script(name):
    spec = importlib.util.spec_from_file_location(name, REPO / "scripts" / f"{name}.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


@pytest.mark.parametrize("name, fstop, mark", [("dgauss_50mm", 2.8, 3000.0), ("zeiss_distagon_35mm_f4", 4.0, 2000.0),
                                               ("sonnar_50mm_f1_5", 2.0, 2000.0)])
def test_real_dof_table_rows(name, fstop, mark):
    page = (REPO / "docs" / "lens-report.md").read_text(encoding="utf-8")
    head = f"| {name} | f/{fstop:g} | {mark / 1000:g} |"
    shown = [line for line in page.splitlines() if line.startswith(head)]
    assert len(shown) == 1, head
    assert compare(shown, _script("real_dof_table").row(name, fstop, mark)) == []

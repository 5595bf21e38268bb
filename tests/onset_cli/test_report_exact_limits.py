"""A report whose measured near and far limits solve both the focus and the f-stop (two limits, two
unknowns) prints no check of one limit against the other (zero by construction: the first-day review saw
"predicted − measured +0.0 mm" and "agree to 0.0%"); an over-determined one (the focus given) still does.
No signed figure of the table reads as a negative zero. The JSON keeps its keys; the phone page's solver
(onset.js, run by node) leaves out the same note."""

from __future__ import annotations

import json
import shutil
import subprocess
from pathlib import Path

import pytest
from hypothesis import given, settings, strategies as st

from physcam.cli import main
from physcam.onset.table import signed

EXACT = ["report", "--focal", "50", "--near", "2.5m", "--far", "4m", "--sensor", "S35"]
OVER = ["report", "--focal", "50", "--near", "2.5m", "--far", "4m", "--focus", "3m", "--sensor", "S35"]
STATIC = Path(__file__).resolve().parents[2] / "src" / "physcam" / "serve" / "static"
NODE_HARNESS = Path(__file__).resolve().parents[1] / "serve" / "_onset_node.js"


def _run(argv, capsys):
    assert main(argv) == 0
    return capsys.readouterr().out


def test_exactly_determined_limits_print_no_self_check(capsys):
    text = _run(EXACT, capsys)
    assert "(solved)" in text and "predicted − measured" not in text and "agree to" not in text
    doc = json.loads(_run(EXACT + ["--json"], capsys))
    assert {"far_error_mm", "consistency", "fstop", "focus_from_film_mm"} <= set(doc["solved"])  # keys kept
    assert doc["solved"]["far_error_mm"] == pytest.approx(0.0, abs=1e-6)  # what the table leaves out: zero
    assert not any("agree to" in n for n in doc["notes"])


def test_over_determined_limits_still_print_their_check(capsys):
    text = _run(OVER, capsys)
    assert "far limit: predicted − measured" in text and "near and far limits agree to" in text


@settings(max_examples=200, deadline=None)
@given(st.floats(-1e-2, 1e-2, allow_nan=False), st.integers(1, 3))
def test_signed_never_a_negative_zero(v, digits):
    s = signed(v, digits)
    assert s[0] in "+-" and float(s) == pytest.approx(round(v, digits), abs=10 ** -digits)
    assert not (s.startswith("-") and float(s) == 0.0)


def test_anamorphic_focus_error_is_not_a_negative_zero(capsys):
    text = _run(["report", "--lens", "neil_front_anamorphic_2x", "--focus", "3m", "--fstop", "4", "--sensor", "S35"],
                capsys)
    (row,) = [ln for ln in text.splitlines() if ln.startswith("focus error")]
    assert "-0.000" not in row and "+0.000 mm" in row


@pytest.mark.skipif(shutil.which("node") is None, reason="node is not installed")
def test_the_page_leaves_out_the_same_note(capsys):
    from physcam.cli.sensors import sensor_document
    from physcam.optics.sensors import sensors

    setups = [{"focal": "50", "near": "2.5m", "far": "4m", "sensor": "S35"},
              {"focal": "50", "near": "2.5m", "far": "4m", "focus": "3m", "sensor": "S35"}]
    job = {"sensors": [sensor_document(s) for s in sensors()], "setups": setups}
    out = subprocess.run(["node", str(NODE_HARNESS), str(STATIC)], input=json.dumps(job), capture_output=True,
                         text=True, check=True, timeout=60)
    exact, over = json.loads(out.stdout)
    assert exact["ok"] and over["ok"]
    assert "fstop" in exact["body"]["solved"] and "consistency" in exact["body"]["solved"]  # keys as the CLI's
    assert not any("agree to" in n for n in exact["body"]["notes"])
    cli = json.loads(_run(OVER + ["--json"], capsys))["notes"]
    agree = [n for n in cli if "agree to" in n]
    assert len(agree) == 1 and agree[0] in over["body"]["notes"]  # the over-determined note, as the CLI's

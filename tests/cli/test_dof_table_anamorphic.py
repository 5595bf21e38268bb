"""dof-table with a desqueeze (issue 49 item 4): the format's desqueeze from the camera table, the
horizontal and vertical limits and fields.

Oracle: the thin lens worked by hand (tests/_thin_lens.py). Focused at a mark D from the film, the
lens sits s' = (D - sqrt(D^2 - 4 f D)) / 2 in front of the film and the subject s = D - s' in front of
it; with H = f^2 / (N c) + f the limits from the lens are s (H - f) / (H + s - 2 f) and
s (H - f) / (H - s) (the exact thin-lens forms, docs/lens-report.md), and from the film s' more.
A 2x anamorphic desqueezes the blur to half as wide as tall, so across the frame the CoC is c / 0.5
(docs/anamorphic.md); the desqueezed picture is 2 w wide: hfov = 2 atan(2 w / 2 s').
"""

from __future__ import annotations

import json
import math

import pytest

from physcam.cli import main

from _documents import check_document
from _thin_lens import image_distance_at_mark

F, N, C, MARK = 50.0, 2.8, 0.025, 3000.0
W, H_ = 20.22, 16.95  # ALEXA 35 3.3K 6:5, a 2x anamorphic format in the camera table


def _limits(c):
    v = image_distance_at_mark(F, MARK)
    s, hyper = MARK - v, F * F / (N * c) + F
    return s * (hyper - F) / (hyper + s - 2 * F) + v, s * (hyper - F) / (hyper - s) + v


def _table(capsys, *extra):
    assert main(["dof-table", "--focal", "50", "--sensor", "ALEXA 35 3.3K 6:5", "--fstops", "2.8", "--focus", "3m",
                 "--coc", "0.025", "--json", *extra]) == 0
    doc = json.loads(capsys.readouterr().out)
    check_document(doc)
    return doc


def test_the_formats_desqueeze_gives_both_limits_and_both_fields(capsys):
    doc = _table(capsys, "--squeeze", "format")
    assert doc["squeeze"] == 2.0 and doc["dof_aspect"] == pytest.approx(0.5)
    row = doc["rows"][0]
    near, far = _limits(C)
    assert (row["near_from_film_mm"], row["far_from_film_mm"]) == pytest.approx((near, far), rel=1e-9)
    near_h, far_h = _limits(C / 0.5)
    assert (row["near_horizontal_from_film_mm"], row["far_horizontal_from_film_mm"]) == pytest.approx(
        (near_h, far_h), rel=1e-9)
    assert row["total_horizontal_mm"] == pytest.approx(far_h - near_h, rel=1e-9)  # 984 mm against 482 mm
    v = image_distance_at_mark(F, MARK)
    assert row["hfov_deg"] == pytest.approx(math.degrees(2 * math.atan(2 * W / (2 * v))), rel=1e-9)  # 43.36
    assert row["vfov_deg"] == pytest.approx(math.degrees(2 * math.atan(H_ / (2 * v))), rel=1e-9)  # 18.92
    # --squeeze 2 says the same as the format's desqueeze
    assert _table(capsys, "--squeeze", "2")["rows"] == doc["rows"]


def test_a_spherical_table_has_one_set_of_limits(capsys):
    row = _table(capsys)["rows"][0]
    assert "near_horizontal_from_film_mm" not in row
    assert row["hfov_deg"] == pytest.approx(math.degrees(2 * math.atan(W / (2 * image_distance_at_mark(F, MARK)))))


def test_the_text_table_prints_the_horizontal_limits_and_the_fields(capsys):
    assert main(["dof-table", "--focal", "50", "--sensor", "ALEXA 35 3.3K 6:5", "--fstops", "2.8", "--focus", "3m",
                 "--coc", "0.025", "--squeeze", "format"]) == 0
    out = capsys.readouterr().out
    near_h, far_h = _limits(C / 0.5)
    assert f"{near_h / 1000:.3f} m - {far_h / 1000:.3f} m" in out  # 2.588 m - 3.572 m
    assert "horizontal (across the frame): squeeze 2" in out and "43.36" in out and "18.92" in out


@pytest.mark.parametrize("sensor", ["ALEXA 35", "Super 35"])
def test_a_format_without_a_desqueeze_is_refused_in_one_line(capsys, sensor):
    assert main(["dof-table", "--focal", "50", "--sensor", sensor, "--squeeze", "format", "--focus", "3m"]) == 2
    err = capsys.readouterr().err
    assert "no anamorphic desqueeze" in err and "--squeeze S" in err and "Traceback" not in err

"""physcam.onset.dof_table.dof_table: the Python function of `physcam dof-table` (first-day walkthrough,
round 9: a pipeline TD found the command and no function).

Oracles: the thin lens worked by hand (tests/_thin_lens.py): focused at a mark D from the film the lens
sits s' = (D - sqrt(D^2 - 4 f D)) / 2 in front of the film, the subject s = D - s' in front of it; with
H = f^2 / (N c) + f the limits from the lens are s (H - f) / (H + s - 2 f) and s (H - f) / (H - s), from the
film s' more (docs/lens-report.md); and the command's own ``--json``, which must carry the same numbers.
"""

from __future__ import annotations

import json
import math

import pytest

from physcam.cli import main
from physcam.errors import InputError

from _thin_lens import image_distance_at_mark

F, C = 35.0, 0.025


def _by_hand(n, mark):
    v = image_distance_at_mark(F, mark)
    s, hyper = mark - v, F * F / (n * C) + F
    return s * (hyper - F) / (hyper + s - 2 * F) + v, s * (hyper - F) / (hyper - s) + v


def test_the_function_gives_the_thin_lens_limits_worked_by_hand():
    from physcam.onset.dof_table import dof_table

    d = dof_table(F, sensor="S35", fstops=[2.8, 4], focus_marks_mm=[2000.0, "3m", math.inf], coc=C)
    assert [r["fstop"] for r in d["rows"]] == [2.8, 2.8, 2.8, 4.0, 4.0, 4.0]
    for r in d["rows"]:
        if r["focus"] == "infinity":  # s -> inf: the near limit H - f from the lens, the lens f from the film
            assert r["far_from_film_mm"] is None and r["far_is_infinite"]
            assert r["near_from_film_mm"] == pytest.approx(F * F / (r["fstop"] * C) + F, rel=1e-9)
            continue
        near, far = _by_hand(r["fstop"], r["focus_from_film_mm"])
        assert (r["near_from_film_mm"], r["far_from_film_mm"]) == pytest.approx((near, far), rel=1e-9)
        assert r["total_mm"] == pytest.approx(far - near, rel=1e-9)
    assert [r["focus_from_film_mm"] for r in d["rows"][:2]] == pytest.approx([2000.0, 3000.0])
    assert d["coc_mm"] == C and d["sensor"]["width_mm"] == pytest.approx(24.89)


def test_the_function_and_the_command_give_the_same_table(capsys):
    """The same options, the same dict: the command's --json is the function's result in a document."""
    from physcam.onset.dof_table import dof_table

    assert main(["dof-table", "--focal", "50", "--sensor", "ALEXA 35 3.3K 6:5", "--squeeze", "2", "--coc", "0.025",
                 "--fstops", "2,5.6", "--focus", "1.5m,10ft,hyperfocal,inf", "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    api = dof_table(50, sensor="ALEXA 35 3.3K 6:5", squeeze=2, coc=0.025, fstops=[2, 5.6],
                    focus_marks_mm=["1.5m", "10ft", "hyperfocal", math.inf])
    payload = {k: v for k, v in doc.items() if k not in ("schema", "version", "units")}
    assert json.loads(json.dumps(api)) == payload
    assert "near_horizontal_from_film_mm" in api["rows"][0]  # the anamorphic's horizontal limits too


def test_the_defaults_are_the_commands():
    from physcam.cli import dof_table as command
    from physcam.onset import dof_table as api

    assert command.DEFAULT_FSTOPS == api.DEFAULT_FSTOPS
    assert command.DEFAULT_FOCUS == ",".join(api.DEFAULT_FOCUS)


def test_the_formats_squeeze_is_the_commands(capsys):
    """squeeze="format" is --squeeze format: ALEXA 35 3.3K 6:5 is a 2x anamorphic format in the camera table."""
    from physcam.onset.dof_table import dof_table

    assert main(["dof-table", "--focal", "50", "--sensor", "ALEXA 35 3.3K 6:5", "--squeeze", "format", "--fstops", "2.8",
                 "--focus", "3m", "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    api = dof_table(50, sensor="ALEXA 35 3.3K 6:5", squeeze="format", fstops=[2.8], focus_marks_mm=["3m"])
    assert api["squeeze"] == doc["squeeze"] == 2.0
    assert api["rows"] == doc["rows"]


@pytest.mark.parametrize("kwargs, words", [
    (dict(focal_length_mm=50, squeeze="format"), r"gives Super 35 .* no anamorphic desqueeze"),
    (dict(), "give either a focal length"),
    (dict(focal_length_mm=35, focus_marks_mm=[-1.0]), "focus mark"),
    (dict(focal_length_mm=35, fstops=[]), "1 to 24 f-stops"),
    (dict(focal_length_mm=35, fstops=["f/2.8"]), "an f-stop of the table is a positive number"),
    (dict(focal_length_mm=35, fstops=[None]), "an f-stop of the table is a positive number"),
    (dict(focal_length_mm=35, fstops=[math.nan]), "an f-stop of the table is a positive number"),
    (dict(focal_length_mm=35, fstops=object()), "fstops: give a number"),
])
def test_bad_input_is_an_input_error(kwargs, words):
    from physcam.onset.dof_table import dof_table

    with pytest.raises(InputError, match=words):
        dof_table(sensor="S35", **kwargs)


def test_one_mark_one_stop_and_numpy_numbers_are_what_a_list_of_them_gives():
    """A single mark or stop is a one-entry table ("2m" was read letter by letter), and numpy's numbers
    are distances and f-stops like Python's (np.int64(2000) was refused as "not a distance")."""
    import numpy as np

    from physcam.onset.dof_table import dof_table

    want = dof_table(50, sensor="S35", fstops=[2.8], focus_marks_mm=[2000.0])["rows"]
    assert dof_table(50, sensor="S35", fstops=2.8, focus_marks_mm="2m")["rows"] == want
    for marks in (np.array([2000]), np.array([2000.0], dtype=np.float32)):
        assert dof_table(50, sensor="S35", fstops=np.array([2.8]), focus_marks_mm=marks)["rows"] == want


def test_the_docs_example_runs():
    """docs/cli.md's Python example of the table (its ``>>>`` block naming dof_table) gives what it shows."""
    import doctest
    import re
    from pathlib import Path

    text = (Path(__file__).resolve().parents[2] / "docs" / "cli.md").read_text(encoding="utf-8")
    block = next(b for b in re.findall(r"```python\n(.*?)```", text, re.DOTALL) if "dof_table(" in b)
    test = doctest.DocTestParser().get_doctest(block, {}, "cli.md dof_table", "docs/cli.md", 0)
    runner = doctest.DocTestRunner()
    runner.run(test)
    assert runner.summarize(verbose=False) == (0, 5)


def test_a_real_lens_table_has_its_full_reports_limits_and_fields():
    """A table's cells skip the real-ray field of view (nothing of the table reads it): each row of a
    traced lens still holds its full report's limits, hyperfocal and paraxial field (solve_lens_report)."""
    import warnings

    from physcam.errors import PhysCamWarning
    from physcam.lens.library import load_lens
    from physcam.onset.dof_table import dof_cells, dof_table
    from physcam.onset.report import solve_lens_report
    from physcam.optics.sensors import find_sensor

    lens, sensor = load_lens("dgauss_50mm"), find_sensor("S35")
    d = dof_table(lens=lens, sensor=sensor, fstops=[2.8, 8], focus_marks_mm=[1500.0, 4000.0], coc=C)
    cells = [(n, m) for n in (2.8, 8) for m in (1500.0, 4000.0)]
    for (n, m), row in zip(cells, d["rows"]):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", PhysCamWarning)
            full = solve_lens_report(focal_length_mm=None, lens=lens, sensor=sensor, fstop=n, focus_mm=m, coc=C)
        assert full.real_fov is not None  # the full report traces it
        assert (row["near_from_film_mm"], row["far_from_film_mm"], row["hyperfocal_from_film_mm"], row["hfov_deg"]) == \
            (full.dof.near_from_film_mm, full.dof.far_from_film_mm, full.dof.hyperfocal_from_film_mm, full.hfov_focus_deg)
        assert dof_cells(lens=lens, sensor=sensor, coc=C)(n, m).dof == full.dof

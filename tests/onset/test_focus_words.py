"""Focus at infinity and at the hyperfocal distance, the magnification's sign, feet and inches, and the
DOF table against the lens report (issue 15). Closed forms worked by hand; the table is checked
against `physcam report` run separately for every cell."""

from __future__ import annotations

import json
import math

import pytest
from hypothesis import given
from hypothesis import strategies as st

from physcam.cli import main
from physcam.onset.report import HYPERFOCAL, solve_lens_report
from physcam.optics.sensors import find_sensor
from physcam.optics.dof import dof_limits
from physcam.units import format_distance, inch_fraction_for, parse_distance

S35 = find_sensor("Super 35")


# ---- s -> infinity ---------------------------------------------------------------------------
@given(st.floats(8, 400), st.floats(0.7, 32), st.floats(0.005, 0.06))
def test_focus_at_infinity_is_the_limit_of_the_exact_form(f, n, c):
    """near(s) = h s / (h + s - f) -> h as s grows; far is infinite beyond the hyperfocal distance."""
    h = f * f / (n * c)
    near, far = dof_limits(f, n, c, math.inf)
    assert near == pytest.approx(h, rel=1e-12) and math.isinf(far)
    for s in (1e3 * h, 1e6 * h):
        near_s, far_s = dof_limits(f, n, c, s)
        assert near_s == pytest.approx(h * s / (h + s - f), rel=1e-12)  # the finite form, by hand
        assert 0 <= h - near_s <= h * (h - f) / s * (1 + 1e-9)  # h - near = h (h - f) / (s + h - f)
        assert math.isinf(far_s)


def test_report_focused_at_infinity():
    """Thin lens at infinity: H1 lies f in front of the film, so the near limit is h + f from the film,
    the magnification 0; the JSON has null for the infinite focus and object distance."""
    f, n = 50.0, 2.8
    r = solve_lens_report(focal_length_mm=f, sensor=S35, fstop=n, focus_mm=math.inf, coc=0.025)
    h = f * f / (n * 0.025)
    assert r.dof.near_from_film_mm == pytest.approx(h + f, rel=1e-12)
    assert r.dof.far_is_infinite and r.magnification == 0.0
    assert r.hfov_focus_deg == pytest.approx(r.hfov_inf_deg)
    d = json.loads(json.dumps(r.to_dict(), allow_nan=False))
    assert d["focus_from_film_mm"] is None and d["focus_is_infinite"] and d["object_distance_mm"] is None


def test_report_focused_at_the_hyperfocal_distance():
    """Practical: the subject plane at H = f^2/(Nc) + f from H1, the mark H + s'(H); near limit H/2
    from H1. Technical: the mark is H + the datasheet H1."""
    f, n, c = 35.0, 4.0, 0.025
    H = f * f / (n * c) + f
    r = solve_lens_report(focal_length_mm=f, sensor=S35, fstop=n, focus_mm=HYPERFOCAL, coc=c)
    assert r.object_distance_mm == pytest.approx(H, rel=1e-12)
    assert r.focus_from_film_mm == pytest.approx(H + H * f / (H - f), rel=1e-12)
    assert r.dof.near_mm == pytest.approx(H / 2, rel=1e-12) and r.dof.far_is_infinite
    t = solve_lens_report(focal_length_mm=f, sensor=S35, fstop=n, focus_mm=HYPERFOCAL, coc=c, model="technical",
                          h1_mm=40.0, h2_mm=36.0)
    assert t.focus_from_film_mm == pytest.approx(H + 40.0, rel=1e-12)


def test_hyperfocal_of_a_real_lens_is_a_fixed_point():
    """With a prescription the planes move with focus: at the hyperfocal mark the lens's own EFL and H1
    (refocused there) put the subject plane exactly at H(EFL)."""
    from physcam.lens.library import load_lens
    from physcam.optics.dof import hyperfocal_distance

    lens = load_lens("dgauss_50mm")
    r = solve_lens_report(focal_length_mm=None, lens=lens, sensor=S35, fstop=4.0, focus_mm=HYPERFOCAL)
    again = solve_lens_report(focal_length_mm=None, lens=lens, sensor=S35, fstop=4.0, focus_mm=r.focus_from_film_mm)
    H = hyperfocal_distance(again.focal_length_mm, 4.0, again.coc_mm)
    assert again.focus_from_film_mm - again.h1_from_film_mm == pytest.approx(H, rel=1e-8)
    assert again.dof.far_is_infinite and r.dof.far_is_infinite


@pytest.mark.parametrize("f, n", [(18.0, 2.0), (24.0, 2.8), (50.0, 16.0), (85.0, 4.0), (135.0, 11.0)])
def test_far_limit_at_the_hyperfocal_focus_is_infinite(f, n):
    """Found by a reviewer: the solved mark landed ~1e-12 short of H and the exact form gave a far limit
    of 6.7e16 m. A focus within HYPERFOCAL_RTOL of H counts as H."""
    r = solve_lens_report(focal_length_mm=f, sensor=S35, fstop=n, focus_mm=HYPERFOCAL)
    assert r.dof.far_is_infinite and r.dof.to_dict()["far_from_film_mm"] is None


def test_far_limit_next_to_the_hyperfocal_distance():
    """Within a millionth of H the far limit is infinite; beyond that, the exact form h s / (H - s)."""
    from physcam.optics.dof import HYPERFOCAL_RTOL

    f, n, c = 50.0, 4.0, 0.025
    h = f * f / (n * c)
    H = h + f
    for gap in (1e-12, 1e-9, 6e-8, 0.9 * HYPERFOCAL_RTOL):  # 6e-8: a float32 focus distance
        assert math.isinf(dof_limits(f, n, c, H * (1 - gap))[1])
    for gap in (2 * HYPERFOCAL_RTOL, 1e-3, 0.1):
        s = H * (1 - gap)
        assert dof_limits(f, n, c, s)[1] == pytest.approx(h * s / (H - s), rel=1e-6)


@pytest.mark.parametrize("fstop", [5.6, 8.0, 11.0])
def test_a_real_lens_reports_one_hyperfocal_mark_at_every_focus(fstop):
    """The hyperfocal mark of a real lens is the fixed point that --focus hyperfocal sets, whatever
    focus the report is for (reviewer: three values 0.2-1.3 mm apart for one lens and f-stop)."""
    from physcam.lens.library import load_lens

    lens = load_lens("dgauss_50mm")
    hyp = solve_lens_report(focal_length_mm=None, lens=lens, sensor=S35, fstop=fstop, focus_mm=HYPERFOCAL)
    assert hyp.dof.far_is_infinite
    for mark in (600.0, 2000.0, math.inf):
        r = solve_lens_report(focal_length_mm=None, lens=lens, sensor=S35, fstop=fstop, focus_mm=mark)
        assert r.dof.hyperfocal_from_film_mm == hyp.focus_from_film_mm
        # the pair is consistent: H from H1 of the lens focused at the mark, plus that H1
        assert r.dof.hyperfocal_mm + hyp.h1_from_film_mm == pytest.approx(hyp.focus_from_film_mm, rel=1e-12)


@pytest.mark.parametrize("name, ratio", [("neil_front_anamorphic_2x", 0.5), ("navarro_anamorphic_2x", 1.0)])
def test_an_anamorphic_lens_reports_one_horizontal_hyperfocal_mark_at_every_focus(name, ratio):
    """The horizontal limits use c / (the blur aspect at the focus); their hyperfocal mark is the fixed
    point with the aspect at the mark, so it too is the same at every focus (review finding). A front
    anamorphic's blur is half as wide as tall (CoC 2c: the mark about half as far); a rear one's is round."""
    import warnings

    from physcam.lens.library import load_lens

    lens = load_lens(name)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the neil lens does not cover Super 35's corners
        marks = [solve_lens_report(focal_length_mm=None, lens=lens, sensor=S35, fstop=8.0, focus_mm=m).dof_horizontal
                 for m in (1500.0, 3000.0, 10000.0, math.inf)]
        v = solve_lens_report(focal_length_mm=None, lens=lens, sensor=S35, fstop=8.0, focus_mm=3000.0).dof
    assert len({d.hyperfocal_from_film_mm for d in marks}) == 1
    assert marks[0].hyperfocal_from_film_mm == pytest.approx(ratio * v.hyperfocal_from_film_mm, rel=0.05)


@pytest.mark.parametrize("kw", [
    # an f-number solved from measured limits, faster than the lens opens (f/1.34 on an f/2 lens)
    dict(lens="dgauss_50mm", focus_mm=2000.0, near_mm=1960.0, far_mm=2042.0),
    # a hyperfocal mark closer than the lens can focus (479 mm; closest focus 562 mm)
    dict(lens="nikkor_fisheye_16mm_f2_8", fstop=22.0, focus_mm=2000.0, sensor="FF"),
])
def test_reports_that_worked_before_the_fixed_point_still_work(kw):
    """Review finding: the hyperfocal mark's side computation must not fail a report. Where the lens has
    no hyperfocal mark the report says so and gives H + H1 at its focus, as before."""
    import warnings

    from physcam.lens.library import load_lens
    from physcam.optics.sensors import find_sensor

    kw = dict(kw)
    lens = load_lens(kw.pop("lens"))
    sensor = find_sensor(kw.pop("sensor", "Super 35"))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        r = solve_lens_report(focal_length_mm=None, lens=lens, sensor=sensor, **kw)
    assert math.isfinite(r.dof.hyperfocal_from_film_mm) and r.dof.hyperfocal_from_film_mm > 0
    if "fstop" in kw:
        assert any("no hyperfocal mark here" in n for n in r.notes)
        assert r.dof.hyperfocal_from_film_mm == pytest.approx(r.dof.hyperfocal_mm + r.h1_from_film_mm, rel=1e-12)


def test_magnification_has_the_gaussian_engines_sign():
    """m = -f/(s - f) (Newton's form, image inverted) in the report equals the paraxial engine's lateral
    magnification that `physcam lens show` prints, for the same lens and mark."""
    from physcam.lens.library import load_lens
    from physcam.optics import focusing, paraxial

    lens = load_lens("dgauss_50mm")
    r = solve_lens_report(focal_length_mm=None, lens=lens, sensor=S35, fstop=2.8, focus_mm=2000.0)
    st_ = focusing.focus(lens, 2000.0)
    g = paraxial.gaussian(st_.prescription, object_z=st_.object_z, film_z=st_.film_z)
    assert r.magnification < 0
    assert r.magnification == pytest.approx(g.magnification, rel=1e-6)


def test_coc_with_units_and_a_value_matching_a_convention_keeps_its_name(capsys):
    assert main(["report", "--focal", "50", "--fstop", "2.8", "--focus", "3m", "--coc", "25um", "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["coc_mm"] == pytest.approx(0.025) and d["coc_convention"] == "cine"
    assert main(["report", "--focal", "50", "--fstop", "2.8", "--focus", "3m", "--coc", "0.0231mm", "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["coc_mm"] == pytest.approx(0.0231) and d["coc_convention"] == "user"


# ---- feet and inches -------------------------------------------------------------------------
@given(st.floats(1.0, 1e6))
def test_feet_and_inches_read_back_within_half_a_step(mm):
    """Printed to 1/8 inch below 10 ft and to the inch beyond, read back within half of that."""
    text = format_distance(mm, "ft")
    step = 25.4 / inch_fraction_for(mm)
    assert abs(parse_distance(text) - mm) <= step / 2 + 1e-9, text


@pytest.mark.parametrize("text, mm", [("9' 10 1/8\"", 3000.375), ("4' 6 3/8\"", 1381.125), ("0' 11 3/4\"", 298.45),
                                      ("3/8\"", 9.525), ("10'", 3048.0), ("-1' 2\"", -355.6)])
def test_fractional_inches_parse(text, mm):
    assert parse_distance(text) == pytest.approx(mm, abs=1e-9)


def test_format_distance_examples():
    # the DOFMaster example near limit 8' 9" (50 mm f/4 at 10 ft, c 0.03): 2664.6 mm
    assert format_distance(2664.6, "ft") == "8' 8 7/8\""
    assert format_distance(3048.0, "ft") == "10' 0\""
    assert format_distance(12000.0, "ft") == "39' 4\""
    assert format_distance(2814.2) == "2.814 m" and format_distance(450.0) == "450.0 mm"
    assert format_distance(math.inf, "ft") == "∞"


# ---- the DOF table ---------------------------------------------------------------------------
ARGS = ["--focal", "35", "--sensor", "S35", "--coc", "cine"]


def _json(capsys, argv):
    assert main(argv) == 0
    return json.loads(capsys.readouterr().out)


def test_dof_table_equals_the_report_cell_by_cell(capsys):
    fstops, marks = ["2", "2.8", "5.6"], ["1m", "3m", "10ft", "hyperfocal", "inf"]
    t = _json(capsys, ["dof-table", *ARGS, "--fstops", ",".join(fstops), "--focus", ",".join(marks), "--json"])
    assert len(t["rows"]) == len(fstops) * len(marks)
    rows = iter(t["rows"])
    for n in fstops:
        for m in marks:
            row = next(rows)
            r = _json(capsys, ["report", *ARGS, "--fstop", n, "--focus", m, "--json"])["dof"]
            assert row["fstop"] == float(n)
            assert row["near_from_film_mm"] == r["near_from_film_mm"]
            assert row["far_from_film_mm"] == r["far_from_film_mm"]
            assert row["total_mm"] == r["total_mm"]
            assert row["hyperfocal_from_film_mm"] == r["hyperfocal_from_film_mm"]


def test_dof_table_of_a_real_lens_equals_its_report(capsys):
    t = _json(capsys, ["dof-table", "--lens", "dgauss_50mm", "--sensor", "S35", "--fstops", "2.8,8", "--focus",
                       "1m,hyperfocal", "--json"])
    for row in t["rows"]:
        focus = "hyperfocal" if row["focus"] == "hyperfocal" else f"{row['focus_from_film_mm']}mm"
        r = _json(capsys, ["report", "--lens", "dgauss_50mm", "--sensor", "S35", "--fstop", f"{row['fstop']}",
                           "--focus", focus, "--json"])
        assert row["near_from_film_mm"] == r["dof"]["near_from_film_mm"]
        assert row["focal_length_mm"] == r["focal_length_mm"]


def test_feet_output_is_the_metric_output_converted(capsys):
    """Every feet-and-inches cell reads back to the metric cell within half its step; the CSV in feet is
    the millimetres / 304.8."""
    import csv
    import io
    import re

    argv = ["dof-table", *ARGS, "--fstops", "2,4,8", "--focus", "2ft,5ft,8ft,3m,12ft,30ft,hyperfocal"]
    metric = _json(capsys, [*argv, "--json"])
    assert main([*argv, "--units", "ft"]) == 0
    lines = capsys.readouterr().out.splitlines()
    grid = [ln for ln in lines[2:] if " - " in ln][: len(metric["focus"])]
    nm = len(metric["focus"])
    for i, line in enumerate(grid):
        cells = re.findall(r"(\d+' \d+(?: \d+/\d+)?\"|∞) - (\d+' \d+(?: \d+/\d+)?\"|∞)", line)
        assert len(cells) == 3, line
        for j, (near, far) in enumerate(cells):
            row = metric["rows"][j * nm + i]
            for text, mm in ((near, row["near_from_film_mm"]), (far, row["far_from_film_mm"])):
                if mm is None:
                    assert text == "∞"
                    continue
                step = 25.4 / inch_fraction_for(mm)
                assert abs(parse_distance(text) - mm) <= step / 2 + 1e-9, (text, mm)
    assert main([*argv, "--units", "ft", "--csv"]) == 0
    feet = list(csv.DictReader(io.StringIO(capsys.readouterr().out)))
    for ft_row, row in zip(feet, metric["rows"]):
        for key in ("near_from_film", "far_from_film", "hyperfocal_from_film", "focus_from_film"):
            mm = row[f"{key}_mm"]
            assert (ft_row[f"{key}_ft"] == "") if mm is None else float(ft_row[f"{key}_ft"]) == pytest.approx(
                mm / 304.8, rel=1e-15)


@pytest.mark.parametrize("mm, text", [(31.75, '1 1/4"'), (9.525, '3/8"'), (298.45, '11 3/4"'), (-31.75, '-1 1/4"'),
                                      (304.8, "1' 0\""), (-355.6, "-1' 2\"")])
def test_under_a_foot_is_inches_alone_as_a_puller_writes_it(mm, text):
    """1.25 in x 25.4 = 31.75 mm is written 1 1/4", not 0' 1 1/4" (a first-day review); a foot and more keep feet."""
    assert format_distance(mm, "ft") == text
    assert parse_distance(text) == pytest.approx(mm, abs=1e-9)

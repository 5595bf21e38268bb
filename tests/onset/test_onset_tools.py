"""What a focus puller asks beyond depth of field: frame size at the subject, exposure in stops, split
focus, close-up lenses and hyperfocal tables, against published tables and hand-worked cases."""

from __future__ import annotations

import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from physcam.errors import InputError
from physcam.onset.diopter import COMMON_DIOPTERS, close_up
from physcam.onset.exposure import ExposureSetting, compensate, exposure_time_s, stops_between_settings
from physcam.onset.framing import frame_at_distance, frame_at_focus
from physcam.onset.hyperfocal import hyperfocal_table
from physcam.onset.report import solve_report
from physcam.onset.request import report_camera
from physcam.optics.sensors import custom_sensor, find_sensor
from physcam.onset.split_focus import split_focus

FF = custom_sensor(36.0, 24.0)


# --- frame at the subject ------------------------------------------------------------------------
def test_frame_at_focus_by_hand():
    # 50 mm thin lens, subject 5050 mm from H1: s' = 50 x 5050 / 5000 = 50.5 mm, |m| = 0.01, the 36 x 24 gate
    # spans 3600 x 2400 mm there; the mark is s + s' = 5100.5 mm from the film
    r = solve_report(report_camera(sensor=FF, focal_length_mm=50.0, fstop=2.8, focus_mm=5100.5))
    fr = frame_at_focus(r)
    assert fr.width_mm == pytest.approx(3600.0, rel=1e-9) and fr.height_mm == pytest.approx(2400.0, rel=1e-9)
    assert frame_at_distance(r, 10100.0).width_mm == pytest.approx(7200.0, rel=1e-9)  # twice as far, twice as wide
    sq = solve_report(report_camera(sensor=FF, focal_length_mm=50.0, fstop=2.8, focus_mm=5100.5, squeeze=2.0))
    assert frame_at_focus(sq).width_mm == pytest.approx(7200.0, rel=1e-9)  # desqueezed
    inf = solve_report(report_camera(sensor=FF, focal_length_mm=50.0, fstop=2.8, focus_mm=math.inf))
    assert frame_at_focus(inf) is None
    assert r.to_dict()["frame_at_focus"]["width_mm"] == pytest.approx(3600.0, rel=1e-9)


# --- exposure -------------------------------------------------------------------------------------
#: RED KOMODO Operation Guide (955-0190, "Exposure conversions", 23.98 fps, i.e. 24000/1001: the table's
#: 1/47.95 is 180 deg at 23.976 fps): shutter angle -> 1/x s
RED_TABLE = [(360.0, 23.98), (288.0, 29.97), (180.0, 47.95), (172.8, 49.95), (144.0, 59.94), (90.0, 95.90),
             (45.0, 191.81), (22.5, 383.62)]


@pytest.mark.parametrize("angle, one_over", RED_TABLE)
def test_exposure_time_equals_reds_table(angle, one_over):
    assert 1.0 / exposure_time_s(angle, 24000 / 1001) == pytest.approx(one_over, abs=0.006)


def test_stops_by_hand():
    base = ExposureSetting(fps=24, shutter_deg=180, tstop=2 * math.sqrt(2), ei=800, nd=0.0)
    assert stops_between_settings(base, ExposureSetting(48, 180, 2 * math.sqrt(2), 800))["stops"] == pytest.approx(-1)
    assert stops_between_settings(base, ExposureSetting(24, 90, 2 * math.sqrt(2), 800))["stops"] == pytest.approx(-1)
    assert stops_between_settings(base, ExposureSetting(24, 180, 4.0, 800))["stops"] == pytest.approx(-1)
    assert stops_between_settings(base, ExposureSetting(24, 180, 2 * math.sqrt(2), 1600))["stops"] == pytest.approx(1)
    assert stops_between_settings(base, ExposureSetting(24, 180, 2 * math.sqrt(2), 800, nd=0.9))["stops"] == \
        pytest.approx(-3)
    # 24 -> 48 fps at 180 deg: open one stop, T2.8 -> T2 (2.83 / sqrt 2)
    assert compensate(base, ExposureSetting(48, 180, 2 * math.sqrt(2), 800)).tstop == pytest.approx(2.0)
    assert compensate(base, ExposureSetting(24, 180, 2 * math.sqrt(2), 3200), "nd").nd == pytest.approx(0.6)
    with pytest.raises(InputError):
        compensate(base, ExposureSetting(48, 180, 2 * math.sqrt(2), 800), "nd")  # darker: no ND gives light back
    with pytest.raises(InputError):
        ExposureSetting(shutter_deg=400)


@settings(max_examples=60, deadline=None)
@given(fps=st.floats(1, 240), angle=st.floats(5, 360), t=st.floats(0.7, 22), ei=st.floats(100, 12800),
       nd=st.floats(0, 2.4), control=st.sampled_from(["tstop", "ei", "shutter"]))
def test_compensation_restores_the_exposure(fps, angle, t, ei, nd, control):
    a = ExposureSetting(24.0, 180.0, 2.8, 800.0, 0.0)
    b = ExposureSetting(fps, angle, t, ei, nd)
    try:
        c = compensate(a, b, control)
    except InputError:
        return  # e.g. a shutter beyond 360 degrees, a T-stop beyond the range: refused
    assert stops_between_settings(a, c)["stops"] == pytest.approx(0.0, abs=1e-9)


# --- split focus ----------------------------------------------------------------------------------
def test_split_focus_needs_the_stop_issue_39_names():
    # issue 39: `report --focal 50 --near 2.5m --far 4m --fstop 4` on Super 35: "the stop the chosen CoC needs
    # (f/9.5 here)"
    sf = split_focus(sensor=find_sensor("S35"), focal_length_mm=50.0, near_mm=2500.0, far_mm=4000.0, fstop=4.0)
    assert round(sf.fstop_needed, 1) == 9.5 and sf.given_holds is False
    # focus at the harmonic mean of the limits about H1 (thin lens: H1 moves with focus, so check the limits)
    at_need = solve_report(report_camera(sensor=find_sensor("S35"), focal_length_mm=50.0, fstop=sf.fstop_needed,
                                        focus_mm=sf.focus_from_film_mm))
    assert at_need.dof.near_from_film_mm == pytest.approx(2500.0, rel=1e-9)
    assert at_need.dof.far_from_film_mm == pytest.approx(4000.0, rel=1e-9)
    assert sf.given.dof.near_from_film_mm > 2500.0 and sf.given.dof.far_from_film_mm < 4000.0  # f/4 holds less


# --- close-up lenses ------------------------------------------------------------------------------
@pytest.mark.parametrize("p", COMMON_DIOPTERS)
def test_a_diopter_at_infinity_focuses_at_one_over_its_power(p):
    cu = close_up(50.0, 2.8, 0.025, math.inf, p)
    assert cu.subject_from_lens_mm == pytest.approx(1000.0 / p)
    assert cu.focal_length_mm == pytest.approx(1.0 / (1 / 50.0 + p / 1000.0))
    assert cu.subject_from_film_mm == pytest.approx(1000.0 / p + 50.0)


def _blur(f_c, aperture, film, u):
    """Blur diameter on the film of a point u in front of the combined thin lens (similar triangles)."""
    v = 1.0 / (1.0 / f_c - 1.0 / u)
    return aperture * abs(v - film) / v


def test_diopter_limits_by_tracing_the_blur():
    # +2 on a 35 mm at f/4 focused at 1.5 m, c = 0.025: the near and far limits are where a point's blur circle
    # on the film is c, the film s' behind the lens and the pupil f / N wide (found here by bisection)
    f, n, c, mark, p = 35.0, 4.0, 0.025, 1500.0, 2.0
    cu = close_up(f, n, c, mark, p)
    s = (mark + math.sqrt(mark * mark - 4 * mark * f)) / 2
    film = f * s / (s - f)
    f_c = 1 / (1 / f + p / 1000)

    def limit(lo, hi):
        for _ in range(200):
            mid = (lo + hi) / 2
            if (_blur(f_c, f / n, film, mid) > c) == (_blur(f_c, f / n, film, lo) > c):
                lo = mid
            else:
                hi = mid
        return (lo + hi) / 2

    u = cu.subject_from_lens_mm
    assert cu.near_from_film_mm - film == pytest.approx(limit(u / 2, u), rel=1e-9)
    assert cu.far_from_film_mm - film == pytest.approx(limit(u * 2, u), rel=1e-9)


# --- hyperfocal tables ----------------------------------------------------------------------------
def test_hyperfocal_table_by_hand():
    # H = f^2 / (N c) + f = 35^2 / (11 x 0.03) + 35 = 3747.12 mm from H1 (physcam.optics.dof's doctest value),
    # marked from the film H + s'(H), the near limit H / 2 from H1
    rows = hyperfocal_table([35.0, 50.0], [2.8, 11.0], sensor=FF, coc=0.03)
    h = 35.0 ** 2 / (11 * 0.03) + 35.0
    mark, near = rows[0]["marks"][11.0]
    s_img = 35.0 * h / (h - 35.0)
    assert mark == pytest.approx(h + s_img, rel=1e-9) and near == pytest.approx(h / 2 + s_img, rel=1e-9)
    assert rows[1]["marks"][2.8][0] > rows[1]["marks"][11.0][0] > rows[0]["marks"][11.0][0]


# --- lens sets --------------------------------------------------------------------------------------
def test_a_lens_set_is_read_as_written():
    from physcam.onset.lens_set import parse_lens_set

    s = parse_lens_set("# S4/i\n18 T2 9in\n25mm T2.0 9in # wide\n100 2 2ft 6in\n75 T2\n", name="S4/i")
    assert [x.focal_length_mm for x in s.lenses] == [18.0, 25.0, 100.0, 75.0]
    assert s.lenses[0].close_focus_mm == pytest.approx(9 * 25.4) and s.lenses[2].close_focus_mm == pytest.approx(762.0)
    assert s.lenses[1].name == "wide" and s.lenses[3].close_focus_mm is None and s.lenses[2].tstop == 2.0
    with pytest.raises(InputError, match="line 2"):
        parse_lens_set("50 T2\nfifty T2\n", where="set.txt")
    with pytest.raises(InputError, match="T-stop"):
        parse_lens_set("50 T0.1\n")


def test_hyperfocal_command_equals_the_report(capsys, tmp_path):
    import json

    from physcam.cli import main

    f = tmp_path / "primes.txt"
    f.write_text("# my primes\n25 T2 9in\n50 T1.4 18in # hero\n", encoding="utf-8")
    assert main(["hyperfocal", "--lens-set", str(f), "--fstops", "1.4,2.8,8", "--sensor", "S35", "--coc", "cine",
                 "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["lens_set"] == "my primes"
    l25, l50 = d["lenses"]
    assert [s["fstop"] for s in l25["stops"]] == [2.8, 8.0]  # f/1.4 is faster than the 25's T2: left out
    assert [s["fstop"] for s in l50["stops"]] == [1.4, 2.8, 8.0]
    # the report's own hyperfocal focus: H = f^2 / (N c) + f from H1, marked H + s'(H) from the film
    h = 25.0 ** 2 / (2.8 * 0.025) + 25.0
    assert l25["stops"][0]["hyperfocal_mark_mm"] == pytest.approx(h + 25.0 * h / (h - 25.0), rel=1e-12)


def test_diopter_command(capsys):
    import json

    from physcam.cli import main

    assert main(["diopter", "--focal", "50", "--fstop", "2.8", "--focus", "inf", "--sensor", "S35", "--coc", "cine",
                 "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    one = next(c for c in d["close_ups"] if c["diopter"] == 1.0)
    # +1 on a 50 mm at infinity: the subject 1 m in front of the lens, the lens 50 mm in front of the film
    assert one["subject_from_film_mm"] == pytest.approx(1050.0) and one["magnification"] == pytest.approx(-0.05)
    assert d["coc_mm"] == 0.025 and d["coc_convention"] == "cine"

"""The lens report: film-plane conversions, both models, inversions, camera blocks."""

import json
import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from physcam import InputError, OpticsError, SensorError
from physcam.errors import PhysCamWarning
from physcam.onset.report import solve_lens_report
from physcam.optics.sensors import Sensor, find_sensor

FF = Sensor("ff", "36x24", 36.0, 24.0)


def test_practical_marked_distance_is_s_plus_s_prime():
    r = solve_lens_report(focal_length_mm=50.0, sensor=FF, fstop=4.0, focus_mm=3048.0, coc=0.03)
    # hand: s^2 - D s + D f = 0 -> s = (3048 + sqrt(3048^2 - 4*3048*50)) / 2
    s = (3048 + math.sqrt(3048**2 - 4 * 3048 * 50)) / 2
    assert r.object_distance_mm == pytest.approx(s, rel=1e-12)
    assert r.object_distance_mm + r.image_distance_mm == pytest.approx(3048.0)
    # near/far from the film = limits from H1 plus H1's distance s' from the film
    h = 50**2 / (4 * 0.03)
    near_h1 = h * s / (h + s - 50)
    assert r.dof.near_from_film_mm == pytest.approx(near_h1 + r.image_distance_mm, rel=1e-12)
    assert r.coc_convention == "full-frame"  # 0.03 mm is the full-frame convention's value: named so


def test_technical_model_conversion_and_focus_error():
    # Datasheet: H1 80 mm and H2 60 mm in front of the flange; PL flange 52 mm.
    r = solve_lens_report(focal_length_mm=50.0, sensor=FF, fstop=2.0, focus_mm=2000.0, model="technical",
                          h1_mm=80.0, h2_mm=60.0, pupil_mm=95.0, reference_plane="flange",
                          flange_focal_distance_mm=52.0)
    s = 2000.0 - (52.0 + 80.0)
    assert r.object_distance_mm == pytest.approx(s)
    s_img = s * 50 / (s - 50)
    assert r.image_distance_mm == pytest.approx(s_img)
    assert r.focus_error_mm == pytest.approx(52.0 + 60.0 - s_img)
    assert r.entrance_pupil_from_film_mm == pytest.approx(147.0)
    assert r.h1_from_film_mm == pytest.approx(132.0)


def test_coc_default_and_named():
    r = solve_lens_report(focal_length_mm=50.0, sensor=FF, fstop=4.0, focus_mm=3000.0)
    assert r.coc_convention == "d/1500"
    assert r.coc_mm == pytest.approx(math.hypot(36, 24) / 1500)
    r = solve_lens_report(focal_length_mm=50.0, sensor=FF, fstop=4.0, focus_mm=3000.0, coc="cine")
    assert r.coc_mm == 0.025
    with pytest.raises(InputError, match="d/1500"):
        solve_lens_report(focal_length_mm=50.0, sensor=FF, fstop=4.0, focus_mm=3000.0, coc="zeis")


def test_inverse_effective_fstop_and_tstop_drift():
    fwd = solve_lens_report(focal_length_mm=35.0, sensor=FF, fstop=5.6, focus_mm=2500.0, coc=0.025)
    inv = solve_lens_report(focal_length_mm=35.0, sensor=FF, focus_mm=2500.0, coc=0.025,
                            near_mm=fwd.dof.near_from_film_mm, tstop=4.0)
    assert inv.fstop == pytest.approx(5.6, rel=1e-9)
    assert inv.solved["tstop_drift_stops"] == pytest.approx(2 * math.log2(5.6 / 4.0))


def test_inverse_coc():
    fwd = solve_lens_report(focal_length_mm=85.0, sensor=FF, fstop=2.8, focus_mm=4000.0, coc=0.02)
    inv = solve_lens_report(focal_length_mm=85.0, sensor=FF, fstop=2.8, focus_mm=4000.0,
                            near_mm=fwd.dof.near_from_film_mm)
    assert inv.coc_mm == pytest.approx(0.02, rel=1e-9)
    assert inv.coc_convention == "solved"


def test_inverse_focus_from_bracket_and_consistency():
    fwd = solve_lens_report(focal_length_mm=50.0, sensor=FF, fstop=4.0, focus_mm=3000.0, coc=0.03)
    inv = solve_lens_report(focal_length_mm=50.0, sensor=FF, coc=0.03,
                            near_mm=fwd.dof.near_from_film_mm, far_mm=fwd.dof.far_from_film_mm)
    assert inv.focus_from_film_mm == pytest.approx(3000.0, rel=1e-9)
    assert inv.fstop == pytest.approx(4.0, rel=1e-9)
    assert inv.solved["consistency"] == pytest.approx(0.0, abs=1e-9)
    # an inconsistent far limit shows up in the consistency figure
    bad = solve_lens_report(focal_length_mm=50.0, sensor=FF, coc=0.03, focus_mm=3000.0,
                            near_mm=fwd.dof.near_from_film_mm, far_mm=fwd.dof.far_from_film_mm * 1.1)
    assert bad.solved["consistency"] > 0.05


def test_focus_from_one_limit_with_fstop():
    fwd = solve_lens_report(focal_length_mm=50.0, sensor=FF, fstop=4.0, focus_mm=3000.0, coc=0.03)
    inv = solve_lens_report(focal_length_mm=50.0, sensor=FF, fstop=4.0, coc=0.03, near_mm=fwd.dof.near_from_film_mm)
    assert inv.focus_from_film_mm == pytest.approx(3000.0, rel=1e-9)


def test_anamorphic_horizontal_fov_and_coc():
    r = solve_lens_report(focal_length_mm=50.0, sensor=Sensor("a", "a", 22.0, 18.59), fstop=2.8,
                          focus_mm=3000.0, squeeze=2.0, coc=0.025)
    assert r.hfov_inf_deg == pytest.approx(math.degrees(2 * math.atan(44.0 / 100.0)))
    assert r.vfov_inf_deg == pytest.approx(math.degrees(2 * math.atan(18.59 / 100.0)))
    # a thin lens given a squeeze is a front anamorphic: its blur is 1/2 as wide as tall desqueezed,
    # so the horizontal limits take c / (1/2) and are deeper (tests/onset/test_anamorphic_dof.py)
    assert r.dof_horizontal.coc_mm == pytest.approx(0.05)
    assert r.dof_horizontal.far_mm - r.dof_horizontal.near_mm > r.dof.far_mm - r.dof.near_mm


@pytest.mark.parametrize("kwargs, err", [
    (dict(focus_mm=30.0, fstop=2.0), OpticsError),
    (dict(focus_mm=3000.0, fstop=0.0), InputError),
    (dict(focus_mm=3000.0, fstop=-2.0), InputError),
    (dict(focus_mm=3000.0, fstop=float("nan")), InputError),
    (dict(focus_mm=-float("inf"), fstop=2.0), InputError),
    (dict(focus_mm="hyperfocal"), InputError),  # the hyperfocal distance needs the f-stop
    (dict(focus_mm=3000.0, fstop=2.0, coc=0.0), InputError),
    (dict(focus_mm=3000.0, near_mm=3500.0), InputError),
    (dict(focus_mm=3000.0, far_mm=2500.0, fstop=2.0, coc=0.03), InputError),
    (dict(focus_mm=3000.0), InputError),
    (dict(focus_mm=3000.0, fstop=2.0, model="technical"), InputError),
])
def test_bad_input_is_a_clear_error(kwargs, err):
    with pytest.raises(err):
        solve_lens_report(focal_length_mm=50.0, sensor=FF, **kwargs)


def test_unknown_sensor_suggests():
    with pytest.raises(SensorError, match="ALEXA 35"):
        find_sensor("ALEXA 53")


def test_json_is_strict_and_versioned():
    r = solve_lens_report(focal_length_mm=24.0, sensor=FF, fstop=11.0, focus_mm=5000.0, coc=0.03)
    assert r.dof.far_is_infinite
    d = json.loads(json.dumps(r.to_dict(), allow_nan=False))
    assert d["schema"] == "physcam.lens_report" and d["version"] == 3
    assert d["dof"]["far_mm"] is None and d["dof"]["far_is_infinite"] is True


@given(st.floats(12, 200), st.floats(1.4, 22), st.floats(1.2, 80))
@settings(max_examples=150, deadline=None)
def test_report_forward_then_inverse(f, N, k):
    D = 4 * f * k
    fwd = solve_lens_report(focal_length_mm=f, sensor=FF, fstop=N, focus_mm=D, coc=0.03)
    assert fwd.dof.near_from_film_mm < D < fwd.dof.far_from_film_mm
    inv = solve_lens_report(focal_length_mm=f, sensor=FF, focus_mm=D, coc=0.03, near_mm=fwd.dof.near_from_film_mm)
    assert math.isclose(inv.fstop, N, rel_tol=1e-6)


def test_report_from_a_lens_prescription():
    # dgauss.50mm: EFL 50.3582 mm (three independent optics programs, issue 3); unit focusing
    # keeps the EFL; focused by the lens itself, the technical model's focus error vanishes.
    from physcam.lens.library import load_lens

    lens = load_lens("dgauss.50mm")
    r = solve_lens_report(focal_length_mm=None, sensor=FF, fstop=2.8, focus_mm=2000.0, lens=lens)
    assert r.model == "technical" and r.lens_name == lens.name
    assert r.focal_length_mm == pytest.approx(50.3582, abs=1e-3)
    assert r.focus_error_mm == pytest.approx(0.0, abs=1e-6)
    assert r.object_distance_mm + r.h1_from_film_mm == pytest.approx(2000.0)
    assert r.entrance_pupil_source == "prescription"


def test_anamorphic_lens_uses_its_own_x_focal_length():
    # navarro_anamorphic_2x is nominally 2x; its X and Y effective focal lengths differ by less.
    # The report's horizontal field at infinity must be what the X meridian images there: 2 atan(w / 2 EFL_x),
    # EFL_x of the lens focused at infinity (issue 39: not at the report's mark)
    from physcam.lens.library import load_lens
    from physcam.optics import paraxial

    lens = load_lens("navarro_anamorphic_2x")
    gate = find_sensor("35mm anamorphic")
    r = solve_lens_report(focal_length_mm=None, sensor=gate, focus_mm=3000.0, lens=lens)
    efl_x = paraxial.gaussian(lens, axis="x").efl
    assert r.hfov_inf_deg == pytest.approx(math.degrees(2 * math.atan(gate.width_mm / (2 * efl_x))), rel=1e-9)
    assert 1.8 < r.squeeze < 2.0
    # no f-stop given: wide open, which for this prescription is slower than the engraved T3
    assert r.fstop >= paraxial.gaussian(lens).f_number - 1e-9


def test_lens_without_engraved_fstop_opens_at_its_stop():
    from physcam.lens.library import load_lens
    from physcam.optics import paraxial

    lens = load_lens("dgauss_77deg_3_5201mm")
    # its image circle does not cover Super 16: the report says so (PhysCamWarning); its stop is still the file's
    with pytest.warns(PhysCamWarning, match="outside the lens's image circle"):
        r = solve_lens_report(focal_length_mm=None, sensor=find_sensor("Super 16"), focus_mm=1000.0, lens=lens)
    assert r.fstop == pytest.approx(paraxial.gaussian(lens).f_number)


def test_huge_far_limit_is_refused_not_overflowed():
    with pytest.raises(InputError, match="1000 km"):
        solve_lens_report(focal_length_mm=50.0, sensor=FF, fstop=4.0, focus_mm=3000.0, far_mm=1e308)
    # a large but finite far limit inverts without overflow: h = (s - f) / (1 - s/F)
    r = solve_lens_report(focal_length_mm=50.0, sensor=FF, fstop=4.0, focus_mm=3000.0, far_mm=1e8)
    assert math.isfinite(r.coc_mm) and r.coc_mm > 0


def test_focus_from_one_limit_solves_nothing_else():
    # one limit + f-stop + CoC convention give the focus; they cannot also give a CoC
    r = solve_lens_report(focal_length_mm=50.0, sensor=FF, fstop=4.0, near_mm=1000.0)
    assert set(r.solved) == {"focus_from_film_mm"}
    assert r.coc_convention == "d/1500"


def test_technical_fov_at_focus_uses_where_the_film_is():
    # H2 60 mm in front of the film: the film sits 60 mm behind H2 whatever s' the mark implies
    r = solve_lens_report(focal_length_mm=50.0, sensor=FF, fstop=2.0, focus_mm=2000.0, model="technical",
                          h1_mm=80.0, h2_mm=60.0)
    assert r.hfov_focus_deg == pytest.approx(math.degrees(2 * math.atan(36.0 / 120.0)))


def test_fisheye_report_gives_the_real_ray_field_and_warns():
    """Issue 8.2: `report --lens nikkor_fisheye_16mm_f2_8 --focus 3m --sensor FF` said 97.7 deg
    horizontal; traced chief rays give about 140 deg (the issue's independent oracle). The report
    now gives both, says which is which, and warns."""
    import json

    from physcam.errors import PhysCamWarning
    from physcam.lens.library import load_lens

    with pytest.warns(PhysCamWarning, match="real chief rays give 140"):
        r = solve_lens_report(focal_length_mm=None, sensor=find_sensor("FF"), focus_mm=3000.0,
                              lens=load_lens("nikkor_fisheye_16mm_f2_8"))
    d = json.loads(json.dumps(r.to_dict()))
    assert d["fov_deg"]["real"]["horizontal"] == pytest.approx(140.0, abs=0.5)
    assert d["fov_deg"]["focus"]["horizontal"] == pytest.approx(97.6, abs=0.2)  # the pinhole's
    assert d["fov_deg"]["real_differs"] is True and "definition" in d["fov_deg"]
    assert any("real chief rays" in n for n in d["notes"])


def test_rectilinear_lens_real_field_agrees_and_does_not_warn():
    import warnings

    from physcam.errors import PhysCamWarning
    from physcam.lens.library import load_lens

    with warnings.catch_warnings():
        warnings.simplefilter("error", PhysCamWarning)
        r = solve_lens_report(focal_length_mm=None, sensor=find_sensor("FF"), focus_mm=3000.0,
                              lens=load_lens("dgauss_50mm"))
    # barrel distortion of about 1 %: real and pinhole fields within the 2 % tolerance
    assert r.real_fov["horizontal_deg"] == pytest.approx(r.hfov_focus_deg, rel=0.02)
    assert not r.real_fov_differs


@pytest.mark.parametrize("lens_name", ["nikkor_fisheye_16mm_f2_8", "dgauss_50mm"])
def test_a_report_without_the_real_field_is_the_full_report_less_it(lens_name):
    """real_fov=False (a depth-of-field chart's cells) leaves out the traced field, its note and its warning;
    every other number is the full report's. The chart's cells, solved so, have the full reports' limits."""
    import warnings

    from physcam.cli.report import dof_chart_solver
    from physcam.lens.library import load_lens
    from physcam.onset.report import solve_report
    from physcam.onset.request import report_camera

    inputs = dict(focal_length_mm=None, sensor=find_sensor("FF"), focus_mm=3000.0, fstop=4.0, lens=load_lens(lens_name))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PhysCamWarning)  # the fisheye's (test_fisheye_report_gives_the_real_ray_field...)
        full = solve_report(report_camera(**inputs))
    with warnings.catch_warnings():
        warnings.simplefilter("error", PhysCamWarning)
        lean = solve_report(report_camera(**inputs), real_fov=False)
    assert full.real_fov is not None and lean.real_fov is None
    a, b = full.to_dict(), lean.to_dict()
    for d in (a, b):
        d["fov_deg"].pop("real"), d["fov_deg"].pop("real_differs")
        d["notes"] = [n for n in d["notes"] if "real chief rays" not in n]
    assert a == b
    solve = dof_chart_solver(None, full)
    for fstop, mark in ((2.8, 1000.0), (8.0, 2500.0), (16.0, 9000.0)):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", PhysCamWarning)
            expected = solve_lens_report(**dict(inputs, fstop=fstop, focus_mm=mark)).dof
        assert solve(fstop, mark).dof == expected


def test_a_flange_distance_only_moves_offsets_given_from_the_flange():
    """Datasheet offsets are in front of their reference plane (docs/conventions.md): from the film, a
    flange focal distance given beside them changes nothing; from the flange, H1 = FFD + offset (by hand:
    52 + 10 = 62 mm). The request and solvers of issue 28 keep this."""
    from physcam.onset.report import solve_lens_report
    from physcam.optics.sensors import find_sensor

    s = find_sensor("ALEXA 35")
    film = solve_lens_report(focal_length_mm=50, fstop=2.8, focus_mm=3000, sensor=s, model="technical", h1_mm=60,
                             h2_mm=45, flange_focal_distance_mm=52)
    assert film.h1_from_film_mm == 60.0 and film.flange_focal_distance_mm is None
    flange = solve_lens_report(focal_length_mm=50, fstop=2.8, focus_mm=3000, sensor=s, model="technical", h1_mm=10,
                               h2_mm=-5, flange_focal_distance_mm=52, reference_plane="flange")
    assert flange.h1_from_film_mm == 62.0 and flange.h2_from_film_mm == 47.0 and flange.flange_focal_distance_mm == 52

"""`physcam export pbrt` (issue 13, part 2): pbrt-v4's thick-lens focusing worked by hand on dgauss
(tests/export/_pbrt.py: a vector Snell tracer in pbrt's lens space and a y-nu paraxial trace, written
from the book's description, not from physcam), checked on every bundled spherical lens; the files'
units (metres in the scene, mm in the .dat) and fov convention (the shorter image axis); refusals."""

from __future__ import annotations

import json
import math
import warnings

import pytest

from _pbrt import paraxial_cardinal_points, parse_scene, read_dat, thick_lens_film_distance
from _thin_lens import image_distance_at_mark
from physcam.cli import main
from physcam.errors import ExportError

#: pbrt-v4's own dgauss.50mm lens file (pbrt-v3/v4 scenes; the bundled dgauss_50mm is read from it),
#: its last thickness 0 as pbrt's files give it (pbrt replaces it when it focuses).
DGAUSS_DAT = """\
# radius thickness eta aperture-diameter
29.475 3.76 1.67 25.2
84.83 0.12 1 25.2
19.275 4.025 1.67 23
40.77 3.275 1.699 23
12.75 5.705 1 18
0 4.5 0 17.1
-14.495 1.18 1.603 17
40.77 6.065 1.658 20
-20.385 0.19 1 20
437.065 3.22 1.717 20
-39.73 0 1 20
"""


def _lens_from_dat(text, name="dgauss"):
    from physcam.lens.formats import pbrt

    return pbrt.loads(text, name=name)


def test_thick_lens_on_dgauss_worked_by_hand():
    """physcam's pbrt_thick_lens against the method worked in the test: the same two rays traced by
    the test's Snell tracer (to 1e-9 mm), and the paraxial cardinal points of a y-nu trace (the rays
    are 0.035 mm from the axis: their aberration is below a micrometre)."""
    from physcam.export.pbrt import pbrt_thick_lens

    rows = read_dat(DGAUSS_DAT)
    lens = _lens_from_dat(DGAUSS_DAT)
    for D in (2000.0, 750.0, 1.0e5):
        got = pbrt_thick_lens(lens, D, film_diagonal_mm=35.0)
        hand, p_rear, f_rear, p_front, f_front = thick_lens_film_distance(rows, D, 35.0)
        assert got.ray_height_mm == pytest.approx(0.035, rel=1e-15)
        assert (got.rear_principal_z_mm, got.rear_focal_z_mm, got.front_principal_z_mm, got.front_focal_z_mm) == \
            pytest.approx((p_rear, f_rear, p_front, f_front), abs=1e-9)
        assert got.film_distance_mm == pytest.approx(hand, abs=1e-9)
        assert got.file_film_distance_mm == 0.0 and got.delta_mm == pytest.approx(hand, abs=1e-9)
        # paraxial (y-nu) cardinal points: the same thick lens, and the same focus to well under a micrometre
        pr, fr, pf, ff = paraxial_cardinal_points(rows)
        assert got.efl_mm == pytest.approx(fr - pr, abs=1e-4)
        assert (p_rear, f_rear, p_front, f_front) == pytest.approx((pr, fr, pf, ff), abs=1e-4)
        from _pbrt import _focus

        assert got.film_distance_mm == pytest.approx(_focus(rows, D, pr, fr, pf), abs=1e-4)


def test_pbrt_refuses_a_subject_it_cannot_focus():
    from physcam.export.pbrt import pbrt_thick_lens

    lens = _lens_from_dat(DGAUSS_DAT)
    with pytest.raises(ExportError, match="pbrt cannot focus.*Coefficient must be positive"):
        pbrt_thick_lens(lens, 150.0)  # closer than 4 f: no real conjugate
    with pytest.raises(ExportError, match="extremely small"):
        pbrt_thick_lens(lens, 2000.0, film_diagonal_mm=35.0, aperture_diameter_mm=0.01)  # rays 0.035 mm out


def _spherical_lenses():
    from physcam.lens.library import list_lenses, load_lens

    out = []
    for rec in list_lenses():
        key = getattr(rec, "key", None) or getattr(rec, "slug", None) or rec.name
        lens = load_lens(key)
        if not lens.is_anamorphic and all(s.kind in ("spherical", "stop", "flat") for s in lens.surfaces):
            out.append(key)
    return out


SPHERICAL = _spherical_lenses()


def test_the_bundled_spherical_lenses():
    assert len(SPHERICAL) >= 15 and "dgauss_50mm" in SPHERICAL and "canon_rf_85mm_f1_2" not in SPHERICAL


@pytest.mark.parametrize("key", SPHERICAL)
def test_every_spherical_lens_pbrt_film_distance_next_to_physcams(key, tmp_path, capsys):
    """Each bundled spherical lens: the CLI writes the .dat (or, with flat surfaces, refuses it and
    still reports pbrt's method on the exact lens); the test's own tracer reproduces pbrt's film
    distance from the written file; pbrt's film lies within a micrometre-scale of physcam's
    exact focus, and the plane it focuses lands where the test's paraxial trace puts it."""
    from physcam.export.pbrt import pbrt_focus_comparison
    from physcam.lens.library import load_lens
    from physcam.onset.report import solve_lens_report
    from physcam.optics.sensors import find_sensor
    from physcam.optics.focusing import focus

    lens = load_lens(key)
    D = 3000.0
    sensor = find_sensor("ALEXA 35")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        report = solve_lens_report(focal_length_mm=None, sensor=sensor, focus_mm=D, lens=lens)
        cmp = pbrt_focus_comparison(report, lens)
    flats = [i for i, s in enumerate(lens.surfaces) if s.kind == "flat"]
    assert cmp.writable == (not flats)
    diag = cmp.film_diagonal_mm
    assert diag == pytest.approx(sensor.diagonal_mm)
    if flats:
        st = focus(lens, D)
        rows = [(0.0 if s.kind in ("stop", "flat") else s.radius, s.thickness, s.medium.nd, 2 * s.semi_diameter)
                for s in st.prescription.surfaces]
    else:
        rc = main(["export", "pbrt", "-o", str(tmp_path), "--lens", key, "--focus", "3m", "--sensor", "ALEXA 35",
                   "--camera", "realistic", "--json"])
        out, err = capsys.readouterr()
        assert rc == 0, err
        js = json.loads(out)
        rows = read_dat((tmp_path / f"{key}.dat").read_text())
        diag = js["values"]["film"]["diagonal"]  # the written film's (its width is the sensor's)
        cmp = pbrt_focus_comparison(report, lens, film_diagonal_mm=diag)
        assert js["focus"]["pbrt_film_distance_mm"] == pytest.approx(cmp.pbrt_film_distance_mm, abs=1e-12)
    hand, *_ = thick_lens_film_distance(rows, D, diag, flats=flats)
    assert cmp.pbrt_film_distance_mm == pytest.approx(hand, abs=1e-7)
    assert cmp.difference_mm == pytest.approx(hand - cmp.physcam_film_distance_mm, abs=1e-7)
    # physcam's exact (paraxial) focus: the test's y-nu trace of the same rows focuses the mark there
    pr, fr, pf, _ = paraxial_cardinal_points(rows)
    from _pbrt import _focus

    assert cmp.physcam_film_distance_mm == pytest.approx(_focus(rows, D, pr, fr, pf), abs=1e-6)
    assert abs(cmp.difference_mm) < 2e-3  # rays 0.034 mm off the axis: aberration at the micrometre scale
    # where pbrt's plane of focus lands: the test's paraxial conjugate of pbrt's film. pbrt moved the lens
    # delta toward the subject (its principal planes to pr - delta, pf - delta; the film stays at z = 0)
    delta = hand - rows[-1][1]
    s_img = delta - pr  # rear principal plane to the film
    s = 1.0 / (1.0 / (fr - pr) - 1.0 / s_img)  # front principal plane to the subject
    landed = s - (pf - delta)  # the subject's distance in front of the film
    assert cmp.pbrt_focus_from_film_mm == pytest.approx(landed, rel=1e-6)


def _scene(path):
    return {d: (t, p) for d, t, p in parse_scene(path.read_text())}


@pytest.mark.parametrize("sensor, fov_axis", [(("36", "24"), "vertical"), (("24", "36"), "horizontal")])
def test_thin_lens_units_and_fov_convention(tmp_path, capsys, sensor, fov_axis):
    """The perspective camera of a 50 mm f/2.8 thin lens at 2 m, by hand: fov across the shorter
    image axis at the pinhole s'; lensradius = f / 2N and focaldistance = D - s' in metres."""
    w, h = float(sensor[0]), float(sensor[1])
    rc = main(["export", "pbrt", "-o", str(tmp_path), "--focal", "50", "--fstop", "2.8", "--focus", "2m",
               "--sensor-width", sensor[0], "--sensor-height", sensor[1], "--resolution", "1200", "--json"])
    out, err = capsys.readouterr()
    assert rc == 0, err
    js = json.loads(out)
    assert list(js["written"]) == ["perspective"]
    sc = _scene(tmp_path / "thin_50mm_perspective.pbrt")
    film, cam = sc["Film"][1], sc["Camera"]
    assert sc["Camera"][0] == "perspective"
    xres, yres = film["xresolution"], film["yresolution"]
    assert (xres, yres) == (1200, round(1200 * h / w))
    s_img = image_distance_at_mark(50.0, 2000.0)
    short = min(w, w * yres / xres)  # pbrt-v4: the screen window's unit is the shorter image side
    assert cam[1]["fov"] == pytest.approx(math.degrees(2 * math.atan(short / 2 / s_img)), abs=1e-10)
    assert js["values"]["perspective"]["fov_axis"] == fov_axis
    assert cam[1]["lensradius"] == pytest.approx(50.0 / 2.8 / 2 / 1000.0, rel=1e-12)  # metres
    assert cam[1]["focaldistance"] == pytest.approx((2000.0 - s_img) / 1000.0, rel=1e-12)
    # the film pbrt derives from the diagonal (RealisticCamera: width = diagonal / sqrt(1 + aspect^2))
    assert film["diagonal"] / math.sqrt(1 + (yres / xres) ** 2) == pytest.approx(w, rel=1e-12)


def test_realistic_camera_units(tmp_path, capsys):
    """dgauss at f/4, 1.5 m: focusdistance is the mark in metres from the film; aperturediameter the stop's
    diameter in mm for f/4 (a paraxial ray from infinity at height f/2N grazes it, in the test's y-nu
    trace of the written .dat); the film diagonal (mm) spans the sensor's width."""
    rc = main(["export", "pbrt", "-o", str(tmp_path), "--lens", "dgauss_50mm", "--fstop", "4", "--focus", "1.5m",
               "--sensor-width", "36", "--sensor-height", "24", "--resolution", "1500", "--json"])
    out, err = capsys.readouterr()
    assert rc == 0, err
    js = json.loads(out)
    sc = _scene(tmp_path / "dgauss_50mm_realistic.pbrt")
    typ, cam = sc["Camera"]
    assert typ == "realistic" and cam["lensfile"] == "dgauss_50mm.dat"
    assert cam["focusdistance"] == pytest.approx(1.5, rel=1e-15)
    rows = read_dat((tmp_path / "dgauss_50mm.dat").read_text())
    # y-nu marginal ray from infinity at the entrance pupil's rim, height EFL / 2N, to the stop
    pr, fr, _, _ = paraxial_cardinal_points(rows)
    efl = fr - pr
    y, nu = efl / 8.0, 0.0
    for i, (r, t, eta, _) in enumerate(rows):
        if r == 0.0:
            assert 2 * abs(y) == pytest.approx(cam["aperturediameter"], rel=1e-9)
            break
        n_i = 1.0 if i == 0 or rows[i - 1][2] == 0 else rows[i - 1][2]
        n_t = 1.0 if eta == 0 else eta
        nu -= y * (n_t - n_i) / r
        y += nu / n_t * t
    film = sc["Film"][1]
    assert film["diagonal"] / math.sqrt(1 + (film["yresolution"] / film["xresolution"]) ** 2) == pytest.approx(36.0)
    assert (tmp_path / "dgauss_50mm_perspective.pbrt").exists()
    # the .dat's last thickness is physcam's exact back focus at the mark; the snippet's comment gives pbrt's
    assert rows[-1][1] == pytest.approx(js["focus"]["physcam_film_distance_mm"], abs=1e-12)
    assert f"{js['focus']['pbrt_film_distance_mm']:.6f} mm behind" in (tmp_path / "dgauss_50mm_realistic.pbrt").read_text()


def test_internal_focus_lens_is_written_at_its_focus_gaps(tmp_path, capsys):
    """zuiko 18 mm focuses internally: the .dat holds the gaps at the mark, so pbrt's unit refocus is a
    sub-micrometre correction; from its infinity gaps pbrt would extend the whole lens instead."""
    rc = main(["export", "pbrt", "-o", str(tmp_path), "--lens", "zuiko_18mm_f3_5", "--focus", "0.5m", "--json",
               "--camera", "realistic"])
    out, err = capsys.readouterr()
    assert rc == 0, err
    c = json.loads(out)["focus"]
    assert c["method"] == "internal" and abs(c["difference_mm"]) < 1e-3
    assert c["unit_focus_film_distance_mm"] is not None
    assert abs(c["unit_focus_efl_mm"] - c["efl_mm"]) > 0.01  # a different lens: the focus group did not move


@pytest.mark.parametrize("argv, words", [
    (["--lens", "canon_rf_85mm_f1_2", "--focus", "2m"], ["pbrt", "asphere", "export blender"]),
    (["--lens", "navarro_anamorphic_2x", "--focus", "2m"], ["pbrt", "cylinder", "export rib"]),
    (["--lens", "sonnar_50mm_f1_5", "--focus", "2m"], ["pbrt", "flat", "radius of 0", "--camera perspective"]),
    (["--focal", "50", "--fstop", "2", "--focus", "2m", "--camera", "realistic"], ["realistic", "prescription"]),
    (["--lens", "neil_front_anamorphic_2x", "--focus", "2m", "--camera", "perspective"], ["pbrt", "export rib"]),
    (["--lens", "dgauss_50mm", "--focal", "50", "--focus", "2m"], ["--lens", "--focal"]),
    (["--lens", "nikkor_fisheye_16mm_f2_8", "--focus", "2m"], ["pbrt", "flat"]),  # no warning line before it
    (["--lens", "dgauss_50mm", "--fstop", "1.4", "--focus", "2m"], ["faster"]),
    (["--lens", "dgauss_50mm", "--focus", "15cm"], ["cannot focus"]),
    (["--focal", "50", "--fstop", "2"], ["--focus"]),
])
def test_refusals_name_pbrt_and_what_can(tmp_path, capsys, argv, words):
    assert main(["export", "pbrt", "-o", str(tmp_path / "out"), *argv]) == 2
    err = capsys.readouterr().err
    assert err.startswith("physcam: error:") and err.count("\n") == 1
    for w in words:
        assert w in err
    assert not (tmp_path / "out").exists()


def test_aspheric_lens_still_has_pbrts_thin_lens(tmp_path, capsys):
    rc = main(["export", "pbrt", "-o", str(tmp_path), "--lens", "canon_rf_85mm_f1_2", "--focus", "2m", "--camera",
               "perspective"])
    assert rc == 0
    assert sorted(p.name for p in tmp_path.iterdir()) == ["canon_rf_85mm_f1_2_perspective.pbrt",
                                                          "physcam-manifest.json"]  # written whole (issue 40)


def test_no_clobber_without_force_and_nothing_half_written(tmp_path, capsys):
    argv = ["export", "pbrt", "-o", str(tmp_path), "--lens", "dgauss_50mm", "--focus", "2m"]
    assert main(argv) == 0
    (tmp_path / "dgauss_50mm_perspective.pbrt").unlink()
    before = (tmp_path / "dgauss_50mm.dat").read_text()
    assert main(argv[:-1] + ["3m"]) == 2  # the .dat exists: nothing is written, not even the missing file
    assert "already exists" in capsys.readouterr().err
    assert not (tmp_path / "dgauss_50mm_perspective.pbrt").exists()
    assert (tmp_path / "dgauss_50mm.dat").read_text() == before
    assert main(argv[:-1] + ["3m", "--force"]) == 0
    assert (tmp_path / "dgauss_50mm.dat").read_text() != before


def test_text_output_names_both_film_distances(tmp_path, capsys):
    assert main(["export", "pbrt", "-o", str(tmp_path), "--lens", "fisheye_10mm", "--focus", "2m"]) == 0
    out = capsys.readouterr().out
    assert "physcam" in out and "pbrt's thick lens" in out and "plane of focus lands" in out

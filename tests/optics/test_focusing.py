"""Focusing from a film-plane mark, close-focus limits, technical planes and breathing."""

from __future__ import annotations

import math

import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from _gauss_lenses import dgauss, thin_lens, thin_pair
from physcam.errors import InputError, OpticsError
from physcam.optics import focusing
from physcam.optics.paraxial import gaussian

# Published dgauss.50mm figures (see test_paraxial): f, H1 from V1, H2 from V2, BFL, track
F, ZH1, H2V2, BFL, TRACK = 50.3582, 23.2357, -14.2523, 36.1059, 32.04
HIATUS = (TRACK + H2V2) - ZH1  # z_H2 - z_H1


def unit_image_distance(mark, f, hiatus):
    """s' from H2 for a mark D from the film: s + s' = D - hiatus, 1/s + 1/s' = 1/f (thin-lens algebra)."""
    t = mark - hiatus
    return (t - math.sqrt(t * t - 4 * f * t)) / 2


def test_unit_focus_thin_lens_closed_form():
    f, mark = 50.0, 1000.0
    stt = focusing.focus(thin_lens(f), mark)
    s2 = (mark - math.sqrt(mark**2 - 4 * f * mark)) / 2
    assert stt.method == "unit"
    assert stt.back_focus_mm == pytest.approx(s2, rel=1e-12)
    assert stt.object_distance_mm == pytest.approx(mark - s2, rel=1e-12)
    assert stt.extension_mm == pytest.approx(s2 - f, rel=1e-9)
    assert 1 / stt.object_distance_mm + 1 / stt.back_focus_mm == pytest.approx(1 / f, rel=1e-12)


@pytest.mark.parametrize("mark", [300.0, 600.0, 1000.0, 3048.0, 20000.0])
def test_unit_focus_dgauss_from_published_cardinal_points(mark):
    stt = focusing.focus(dgauss(), mark)
    s2 = unit_image_distance(mark, F, HIATUS)
    assert stt.back_focus_mm == pytest.approx(s2 + H2V2, abs=2e-3)
    assert stt.film_z - stt.object_z == pytest.approx(mark, abs=1e-9)  # the mark is from the film plane
    assert stt.extension_mm == pytest.approx(s2 + H2V2 - BFL, abs=2e-3)


def test_infinity_focus_puts_the_film_at_the_rear_focal_point():
    stt = focusing.focus(dgauss(), math.inf)
    assert stt.back_focus_mm == pytest.approx(BFL, abs=1e-3)
    assert stt.extension_mm == 0.0


def test_unit_focus_closer_than_one_to_one_names_the_closest_focus():
    near = 4 * F + HIATUS
    assert focusing.closest_focus(dgauss()) == pytest.approx(near, abs=5e-3)
    with pytest.raises(OpticsError, match=rf"closest real focus .* is {near:.1f} mm from the film"):
        focusing.focus(dgauss(), 150.0)


@pytest.mark.parametrize("slug", ["fisheye_10mm", "tessar_50mm_f2_8", "dgauss_50mm"])
def test_unit_focus_reaches_the_closest_focus_it_names(slug):
    # closest_focus is the 1:1 conjugate, where the focus quadratic's discriminant is zero: a rounding
    # error below zero refused the very mark closest_focus names (fisheye_10mm, tessar_50mm_f2_8)
    from physcam.lens.library import load_lens

    lens = load_lens(slug)
    near = focusing.closest_focus(lens, method="unit")
    st = focusing.focus(lens, near, method="unit")
    g = gaussian(lens)
    assert st.back_focus_mm - st.back_focus_infinity_mm == pytest.approx(g.efl, rel=1e-6)  # 1:1: s' = 2f, extension f
    with pytest.raises(OpticsError, match="closest real focus"):
        focusing.focus(lens, near * (1 - 1e-6), method="unit")


def test_a_lens_longer_than_its_one_to_one_conjugate_focuses_closest_with_the_subject_at_its_first_vertex():
    # a stop 150 mm in front of a thin f = 50 mm lens: the 1:1 subject (2 f = 100 mm in front of the
    # lens) would be 50 mm behind the stop, inside the lens (the Laikin zoom at 15 mm is such a lens).
    # Worked by hand: the closest subject is at the stop, s = 150 mm from the lens, s' = 1 / (1/50 -
    # 1/150) = 75 mm, mark s + s' = 225 mm (the old answer, 4 f = 200 mm, is not reachable)
    from _gauss_lenses import stop, thin_lens_surfaces
    from physcam.lens.prescription import Prescription

    lens = Prescription((stop(150.0),) + tuple(thin_lens_surfaces(50.0)))
    assert focusing.closest_focus(lens) == pytest.approx(225.0, rel=1e-9)
    st_ = focusing.focus(lens, 225.0 * (1 + 1e-9))
    assert st_.object_distance_mm == pytest.approx(0.0, abs=1e-6)
    assert st_.back_focus_mm == pytest.approx(75.0, rel=1e-6)
    with pytest.raises(OpticsError, match="inside the lens"):
        focusing.focus(lens, 225.0 * (1 - 1e-6))


def test_unit_focus_with_limited_travel():
    # 5 mm of extension: s' = f + 5 -> s = f s'/(s' - f); the mark adds the hiatus
    s2 = F + 5.0
    near = F * s2 / 5.0 + s2 + HIATUS
    with pytest.raises(OpticsError, match=f"closest focus is {near:.1f} mm"):
        focusing.focus(dgauss(), near - 20.0, max_extension_mm=5.0)
    assert focusing.focus(dgauss(), near + 20.0, max_extension_mm=5.0).extension_mm < 5.0


def test_internal_focus_thin_pair_closed_form():
    # Two thin lenses d apart; the gap shrinks toward the close point, interpolated in 1/distance.
    f1, f2, d, close, d_close = 60.0, 90.0, 20.0, 500.0, 14.0
    lens = thin_pair(f1, f2, d, focus=(close, d_close))
    mark = 1200.0
    stt = focusing.focus(lens, mark)
    assert stt.method == "internal"
    obj = stt.object_distance_mm
    alpha = close / obj
    gap = d + alpha * (d_close - d)
    assert stt.alpha == pytest.approx(alpha, rel=1e-9)
    assert stt.prescription.surfaces[2].thickness == pytest.approx(gap, rel=1e-9)
    # thin-lens imaging, lens by lens
    s1 = 1 / (1 / f1 - 1 / obj)
    s2 = 1 / (1 / f2 - 1 / (gap - s1))
    assert stt.back_focus_mm == pytest.approx(s2, rel=1e-9)
    assert obj + gap + s2 == pytest.approx(mark, rel=1e-9)


def test_internal_focus_close_limit():
    f1, f2, d, close, d_close = 60.0, 90.0, 20.0, 500.0, 14.0
    lens = thin_pair(f1, f2, d, focus=(close, d_close))
    s1 = 1 / (1 / f1 - 1 / close)
    s2 = 1 / (1 / f2 - 1 / (d_close - s1))
    near = close + d_close + s2
    assert focusing.closest_focus(lens) == pytest.approx(near, rel=1e-12)
    at_near = focusing.focus(lens, near)
    assert at_near.alpha == pytest.approx(1.0, abs=1e-9)
    with pytest.raises(OpticsError, match=f"closest focus is {near:.1f} mm from the film plane"):
        focusing.focus(lens, near - 50.0)
    # the same lens can still be unit-focused closer
    assert focusing.focus(lens, near - 50.0, method="unit").method == "unit"


def test_focus_bad_input():
    with pytest.raises(InputError, match="positive distance"):
        focusing.focus(dgauss(), -3.0)
    with pytest.raises(InputError, match="positive distance"):
        focusing.focus(dgauss(), float("nan"))
    with pytest.raises(InputError, match="no focus groups"):
        focusing.focus(dgauss(), 1000.0, method="internal")
    with pytest.raises(InputError, match="focus method"):
        focusing.focus(dgauss(), 1000.0, method="helical")


def test_technical_planes_at_infinity_from_published_figures():
    tp = focusing.technical_planes(dgauss(), math.inf, 52.0)
    z_film = TRACK + BFL
    assert tp.efl_mm == pytest.approx(F, abs=1e-3)
    assert tp.back_focus_mm == pytest.approx(BFL, abs=1e-3)
    assert tp.h1_from_film_mm == pytest.approx(z_film - ZH1, abs=1e-3)
    assert tp.h2_from_film_mm == pytest.approx(BFL - H2V2, abs=1e-3)
    assert tp.entrance_pupil_from_film_mm == pytest.approx(z_film - 19.9465, abs=1e-3)
    assert tp.entrance_pupil_from_flange_mm == pytest.approx(z_film - 19.9465 - 52.0, abs=1e-3)
    assert tp.h1_from_flange_mm == pytest.approx(tp.h1_from_film_mm - 52.0, abs=1e-12)
    assert tp.to_dict()["focus_from_film_mm"] is None  # infinity is null in JSON


def test_technical_planes_at_a_mark_unit_focus():
    mark = 2000.0
    tp = focusing.technical_planes(dgauss(), mark)
    s2 = unit_image_distance(mark, F, HIATUS)
    assert tp.h2_from_film_mm == pytest.approx(s2, abs=2e-3)
    assert tp.h1_from_film_mm == pytest.approx(s2 + HIATUS, abs=2e-3)  # z_H1 = z_H2 - hiatus
    s = mark - HIATUS - s2
    assert tp.magnification == pytest.approx(-s2 / s, rel=1e-4)
    assert tp.flange_focal_distance_mm is None and tp.h1_from_flange_mm is None


def test_breathing_thin_lens_stop_at_lens():
    # stop at a thin lens: the chief ray is undeviated, tan(half HFOV) = (w/2) / s'
    f, w = 50.0, 36.0
    rows = focusing.breathing_table(thin_lens(f), [math.inf, 1000.0, 500.0], sensor_width_mm=w)
    assert rows[0].hfov_deg == pytest.approx(math.degrees(2 * math.atan(w / 2 / f)), rel=1e-12)
    for r in rows[1:]:
        s2 = (r.focus_from_film_mm - math.sqrt(r.focus_from_film_mm**2 - 4 * f * r.focus_from_film_mm)) / 2
        assert r.hfov_deg == pytest.approx(math.degrees(2 * math.atan(w / 2 / s2)), rel=1e-12)
        assert r.breathing_focal_length_mm == pytest.approx(s2, rel=1e-12)
        assert r.efl_mm == pytest.approx(f, rel=1e-12)
    assert rows[2].fov_change_pct < rows[1].fov_change_pct < 0


def test_breathing_default_table_of_an_internal_focus_lens_ends_at_the_close_point():
    lens = thin_pair(60.0, 90.0, 20.0, focus=(500.0, 14.0))
    rows = focusing.breathing_table(lens)
    assert math.isinf(rows[0].focus_from_film_mm)
    assert rows[-1].focus_from_film_mm == pytest.approx(focusing.closest_focus(lens), rel=1e-12)
    # the focal length changes with the gap: closed form of the thin pair at the close gap
    assert rows[-1].efl_mm == pytest.approx(60.0 * 90.0 / (150.0 - 14.0), rel=1e-9)
    assert rows[0].efl_mm == pytest.approx(60.0 * 90.0 / (150.0 - 20.0), rel=1e-9)


@settings(max_examples=40, deadline=None)
@given(st.floats(250.0, 1e5))
def test_focused_image_lies_on_the_film(mark):
    p = dgauss()
    assume(mark > focusing.closest_focus(p) + 1.0)
    stt = focusing.focus(p, mark)
    g = gaussian(stt.prescription, object_z=stt.object_z)
    assert g.z_image == pytest.approx(stt.film_z, abs=1e-7)
    assert stt.film_z - stt.object_z == pytest.approx(mark, rel=1e-12)


@settings(max_examples=40, deadline=None)
@given(st.floats(600.0, 1e6))
def test_internal_focus_solution_satisfies_the_mark(mark):
    lens = thin_pair(60.0, 90.0, 20.0, focus=(500.0, 14.0))
    assume(mark > focusing.closest_focus(lens))
    stt = focusing.focus(lens, mark)
    assert 0.0 <= stt.alpha <= 1.0
    assert stt.object_distance_mm + stt.prescription.total_track + stt.back_focus_mm == pytest.approx(mark, rel=1e-8)
    g = gaussian(stt.prescription, object_z=stt.object_z)
    assert g.z_image == pytest.approx(stt.film_z, abs=1e-6)


# --- the best-match pinhole (issue 9.6): one definition, checked three independent ways ----------
def test_pinhole_of_dgauss_at_1_5_m_is_the_issue_figure():
    """The issue's oracle: with the eye at the entrance pupil the exact framing match of dgauss.50mm
    focused 1.5 m from the film is a 52.048 mm pinhole (EFL 50.358 is 3.25 % wide)."""
    from physcam.lens.library import load_lens

    planes = focusing.technical_planes(load_lens("dgauss_50mm"), 1500.0)
    assert planes.pinhole_focal_length_mm == pytest.approx(52.048, abs=1e-3)
    assert focusing.technical_planes(load_lens("dgauss_50mm"), math.inf).pinhole_focal_length_mm == pytest.approx(
        planes.efl_mm, rel=1e-12)


def test_pinhole_equals_pupil_formula_and_breathing_focal_length():
    """f_pin from the chief ray equals n (film - exit pupil) / (n' m_p) from the pupils, and the
    breathing table's framing focal length (w/2) / tan(HFOV/2), three separate computations."""
    from physcam.lens.library import load_lens

    for slug, mark in (("dgauss_50mm", 1500.0), ("zeiss_distagon_35mm_f4", 800.0), ("canon_rf_85mm_f1_2", 2000.0)):
        lens = load_lens(slug)
        st = focusing.focus(lens, mark)
        g = gaussian(st.prescription, object_z=st.object_z, film_z=st.film_z)
        pupils = g.object_index * (g.z_film - g.z_exit_pupil) / (g.image_index * g.pupil_magnification)
        assert g.pinhole_focal_length == pytest.approx(pupils, rel=1e-9), slug
        row = focusing.breathing_table(lens, [mark], sensor_width_mm=36.0)[0]
        assert g.pinhole_focal_length == pytest.approx(row.breathing_focal_length_mm, rel=1e-9), slug


def test_pinhole_against_real_rays():
    """Real rays: a point 5 mrad off axis at the 1.5 m mark, imaged by dgauss focused there, lands
    at u * f_pin on the film, u the angle seen from the entrance pupil (small field: within 1e-3)."""
    import numpy as np

    from physcam.lens.library import load_lens
    from physcam.trace import RayBatch, trace_to_film

    lens = load_lens("dgauss_50mm")
    st = focusing.focus(lens, 1500.0)
    g = gaussian(st.prescription, object_z=st.object_z, film_z=st.film_z)
    u = 0.005
    y_obj = u * (g.z_entrance_pupil - st.object_z)
    # a small pencil around the chief ray, through the entrance pupil's centre region
    k = np.linspace(-0.5, 0.5, 11)
    px, py = np.meshgrid(k, k)
    aim = np.stack([px.ravel(), py.ravel(), np.full(px.size, g.z_entrance_pupil)], axis=1)
    start = np.array([0.0, y_obj, st.object_z])
    rays = RayBatch.from_arrays(np.broadcast_to(start, aim.shape), aim - start)
    out = trace_to_film(st.prescription, rays, st.film_z, clip=False)
    assert out.ok.all()
    image_height = -float(np.mean(out.y))  # the image is inverted
    assert image_height / u == pytest.approx(g.pinhole_focal_length, rel=1e-3)

"""Gaussian optics: published figures, hand-worked closed forms, invariants."""

from __future__ import annotations

import math

import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from _gauss_lenses import dgauss, reversed_lens, scaled_lens, stop, thin_lens, thin_lens_surfaces, thin_pair
from physcam.errors import InputError, OpticsError
from physcam.lens.prescription import AIR, Medium, Prescription, Surface
from physcam.optics.glass import LINE_F_NM, refractive_index
from physcam.optics.paraxial import field_angle, gaussian, gaussian_xy, paraxial_trace

# ---------------------------------------------------------------------------
# Acceptance: pbrt dgauss.50mm.dat, three independent optics programs agree.
# ---------------------------------------------------------------------------


def test_dgauss_published_first_order_data():
    g = gaussian(dgauss())
    tol = 1e-3
    assert g.efl == pytest.approx(50.3582, abs=tol)
    assert g.bfl == pytest.approx(36.1059, abs=tol)
    assert g.relative_to("front_principal_plane", "front_vertex") == pytest.approx(23.2357, abs=tol)
    assert g.relative_to("rear_principal_plane", "rear_vertex") == pytest.approx(-14.2523, abs=tol)
    assert g.relative_to("entrance_pupil", "front_vertex") == pytest.approx(19.9465, abs=tol)
    assert g.entrance_pupil_diameter == pytest.approx(24.8051, abs=tol)
    assert g.relative_to("exit_pupil", "rear_vertex") == pytest.approx(-17.7714, abs=tol)
    assert g.exit_pupil_diameter == pytest.approx(26.5385, abs=tol)
    # derived from the same published figures
    assert g.f_number == pytest.approx(50.3582 / 24.8051, abs=1e-4)
    assert g.pupil_magnification == pytest.approx(26.5385 / 24.8051, abs=1e-4)
    assert g.relative_to("rear_focal_point", "rear_vertex") == pytest.approx(36.1059, abs=tol)


def test_dgauss_positions_from_film_and_flange():
    # film at F' (infinity focus): film z = track + BFL; published figures only
    track = 32.04
    g = gaussian(dgauss(), flange_focal_distance_mm=52.0)
    z_film = track + 36.1059
    assert g.in_front_of("entrance_pupil", "film") == pytest.approx(z_film - 19.9465, abs=1e-3)
    assert g.in_front_of("front_principal_plane", "film") == pytest.approx(z_film - 23.2357, abs=1e-3)
    assert g.in_front_of("rear_principal_plane", "film") == pytest.approx(36.1059 + 14.2523, abs=1e-3)
    assert g.in_front_of("entrance_pupil", "flange") == pytest.approx(z_film - 19.9465 - 52.0, abs=1e-3)
    assert g.positions("film")["film"] == 0.0
    assert g.positions("film")["object"] is None  # infinitely far
    with pytest.raises(InputError, match="flange focal distance"):
        gaussian(dgauss()).in_front_of("entrance_pupil", "flange")
    with pytest.raises(InputError, match="reference plane"):
        g.relative_to("entrance_pupil", "mount")


def test_dgauss_nodal_points_equal_principal_points_in_air():
    g = gaussian(dgauss())
    assert g.z_front_nodal_point == pytest.approx(g.z_front_principal_plane, abs=1e-12)
    assert g.z_rear_nodal_point == pytest.approx(g.z_rear_principal_plane, abs=1e-12)


def test_dgauss_magnification_and_working_fnumber_at_finite_conjugate():
    # Newton/Gauss with the published f and H: object 1000 mm in front of H1
    f, zh = 50.3582, 23.2357
    s = 1000.0
    g = gaussian(dgauss(), object_z=zh - s)
    s2 = s * f / (s - f)
    assert g.magnification == pytest.approx(-s2 / s, rel=1e-4)
    assert g.relative_to("object", "front_vertex") == pytest.approx(zh - s)
    assert g.z_image - g.z_rear_principal_plane == pytest.approx(s2, rel=1e-5)
    # working f-number = (1 - m / m_p) N  (Smith 6.9; Kingslake "effective f-number")
    n, mp = 50.3582 / 24.8051, 26.5385 / 24.8051
    assert g.working_f_number == pytest.approx((1 + (s2 / s) / mp) * n, rel=1e-4)


def test_fstop_scales_the_stop_and_both_pupils():
    g = gaussian(dgauss(), fstop=4.0)
    assert g.f_number == pytest.approx(4.0, rel=1e-12)
    assert g.entrance_pupil_diameter == pytest.approx(50.3582 / 4.0, abs=1e-3)
    assert g.exit_pupil_diameter == pytest.approx(50.3582 / 4.0 * 26.5385 / 24.8051, abs=1e-3)
    assert g.relative_to("entrance_pupil", "front_vertex") == pytest.approx(19.9465, abs=1e-3)
    gaussian(dgauss(), fstop=2.0)  # engraved f/2 (file stop is f/2.03): allowed
    with pytest.raises(OpticsError, match="widest aperture is f/2.03"):
        gaussian(dgauss(), fstop=1.4)


# ---------------------------------------------------------------------------
# Hand-worked closed forms
# ---------------------------------------------------------------------------


def test_thick_lens_lensmaker_with_thickness():
    # Hecht, Optics, 6.2: 1/f = (n-1)[1/R1 - 1/R2 + (n-1) d / (n R1 R2)],
    # h1 = -f (n-1) d / (n R2) from V1, h2 = -f (n-1) d / (n R1) from V2
    r1, r2, d, n = 40.0, -60.0, 8.0, 1.6
    p = Prescription((stop(0.0, 5.0), Surface(r1, d, Medium(n, 0.0), 10.0), Surface(r2, 0.0, AIR, 10.0)))
    f = 1.0 / ((n - 1) * (1 / r1 - 1 / r2 + (n - 1) * d / (n * r1 * r2)))
    h1 = -f * (n - 1) * d / (n * r2)
    h2 = -f * (n - 1) * d / (n * r1)
    g = gaussian(p)
    assert g.efl == pytest.approx(f, rel=1e-12)
    assert g.z_front_principal_plane == pytest.approx(h1, rel=1e-12)
    assert g.relative_to("rear_principal_plane", "rear_vertex") == pytest.approx(h2, rel=1e-12)
    assert g.bfl == pytest.approx(f + h2, rel=1e-12)
    assert g.ffl == pytest.approx(f - h1, rel=1e-12)


def test_thick_lens_dispersion_at_the_f_line():
    r1, r2, d = 50.0, -50.0, 6.0
    nd, vd = 1.5168, 64.17
    p = Prescription((stop(0.0, 5.0), Surface(r1, d, Medium(nd, vd), 10.0), Surface(r2, 0.0, AIR, 10.0)))
    n = float(refractive_index(nd, vd, LINE_F_NM))
    f = 1.0 / ((n - 1) * (1 / r1 - 1 / r2 + (n - 1) * d / (n * r1 * r2)))
    assert gaussian(p, wavelength_nm=LINE_F_NM).efl == pytest.approx(f, rel=1e-12)
    assert gaussian(p, wavelength_nm=LINE_F_NM).efl < gaussian(p).efl  # blue focuses shorter


def test_thin_lens_pair():
    # Smith 4.3: f = f1 f2 / (f1 + f2 - d), BFL = f (f1 - d) / f1, FFL = f (f2 - d) / f2
    f1, f2, d = 80.0, -120.0, 20.0
    g = gaussian(thin_pair(f1, f2, d))
    f = f1 * f2 / (f1 + f2 - d)
    assert g.efl == pytest.approx(f, rel=1e-12)
    assert g.bfl == pytest.approx(f * (f1 - d) / f1, rel=1e-12)
    assert g.ffl == pytest.approx(f * (f2 - d) / f2, rel=1e-12)


def test_entrance_pupil_of_a_stop_behind_a_thin_lens():
    # a stop a = 10 mm behind a thin lens of f = 50 mm (a < f): the entrance pupil is the lens's virtual image
    # of the stop, a f / (f - a) behind the lens, magnified f / (f - a)
    f, a, semi = 50.0, 10.0, 3.0
    g = gaussian(thin_lens(f, stop_gap=a, stop_semi=semi))
    assert g.z_entrance_pupil == pytest.approx(a * f / (f - a), rel=1e-12)
    assert g.entrance_pupil_diameter == pytest.approx(2 * semi * f / (f - a), rel=1e-12)
    # the exit pupil is the stop itself (nothing behind it)
    assert g.z_exit_pupil == pytest.approx(a, abs=1e-12)
    assert g.exit_pupil_diameter == pytest.approx(2 * semi, rel=1e-12)
    assert g.pupil_magnification == pytest.approx((f - a) / f, rel=1e-12)


def test_single_surface_into_glass_nodal_points_at_centre_of_curvature():
    # one refracting sphere, air -> n: H = H' = vertex, N = N' = centre of curvature,
    # f = R / (n - 1) in object space, f' = n R / (n - 1)  (Smith 3.2)
    r, n = 30.0, 1.5
    p = Prescription((stop(0.0, 4.0), Surface(r, 0.0, Medium(n, 0.0), 10.0)))
    g = gaussian(p)
    assert g.front_focal_length == pytest.approx(r / (n - 1), rel=1e-12)
    assert g.rear_focal_length == pytest.approx(n * r / (n - 1), rel=1e-12)
    assert g.z_front_principal_plane == pytest.approx(0.0, abs=1e-12)
    assert g.z_rear_principal_plane == pytest.approx(0.0, abs=1e-12)
    assert g.z_front_nodal_point == pytest.approx(r, rel=1e-12)
    assert g.z_rear_nodal_point == pytest.approx(r, rel=1e-12)


def test_cylindrical_element_has_power_only_in_its_meridian():
    # a spherical thin lens (f_s) in contact with a plano-convex cylinder in X (R, n):
    # X power 1/f_s + (n-1)/R; Y power 1/f_s
    fs, r, n = 100.0, 25.0, 1.5
    surfaces = thin_lens_surfaces(fs) + [
        Surface(r, 0.0, Medium(n, 0.0), 5.0, "cylindrical_x"),
        Surface(0.0, 0.0, AIR, 5.0, "flat"),
        stop(0.0),
    ]
    p = Prescription(tuple(surfaces), squeeze=2.0)
    g = gaussian_xy(p)
    assert g["x"].efl == pytest.approx(1.0 / (1.0 / fs + (n - 1) / r), rel=1e-12)
    assert g["y"].efl == pytest.approx(fs, rel=1e-12)
    # the same cylinder turned 90 degrees swaps the meridians
    q = Prescription(tuple(Surface(s.radius, s.thickness, s.medium, s.semi_diameter, "cylindrical_y") if s.kind == "cylindrical_x" else s for s in surfaces))
    assert gaussian(q, axis="y").efl == pytest.approx(g["x"].efl, rel=1e-12)
    assert gaussian(q, axis="x").efl == pytest.approx(fs, rel=1e-12)


def test_afocal_meridian_is_an_optics_error():
    p = Prescription((Surface(25.0, 0.0, Medium(1.5, 0.0), 5.0, "cylindrical_x"), Surface(0.0, 0.0, AIR, 5.0, "flat"), stop(0.0)))
    assert gaussian(p, axis="x").efl == pytest.approx(50.0)
    with pytest.raises(OpticsError, match="afocal in the Y meridian"):
        gaussian(p, axis="y")


def test_field_angle_at_infinity_is_atan_h_over_f():
    g = gaussian(dgauss())
    ang = field_angle(dgauss(), 18.0, g.z_film)
    assert abs(ang) == pytest.approx(math.atan(18.0 / 50.3582), abs=1e-5)


def test_bad_input_is_reported():
    with pytest.raises(InputError, match="meridian"):
        gaussian(dgauss(), axis="z")
    bad = Prescription((stop(0.0), Surface(float("nan"), 1.0, Medium(1.5, 0.0), 5.0), Surface(-20.0, 0.0, AIR, 5.0)))
    with pytest.raises(InputError, match="NaN|nan"):
        gaussian(bad)
    with pytest.raises(InputError, match="wavelength"):
        gaussian(dgauss(), wavelength_nm=float("inf"))
    with pytest.raises(InputError, match="in front of"):
        gaussian(dgauss(), object_z=5.0)


# ---------------------------------------------------------------------------
# Properties
# ---------------------------------------------------------------------------


@st.composite
def random_lenses(draw):
    """2-4 singlets in air with a stop between two of them; positive glass thicknesses."""
    n_el = draw(st.integers(2, 4))
    stop_at = draw(st.integers(0, n_el))
    surfaces = []
    radius = st.one_of(st.floats(15.0, 400.0), st.floats(-400.0, -15.0))
    for e in range(n_el):
        if e == stop_at:
            surfaces.append(stop(draw(st.floats(0.5, 10.0)), 3.0))
        n = draw(st.floats(1.45, 1.9))
        surfaces.append(Surface(draw(radius), draw(st.floats(1.0, 10.0)), Medium(n, draw(st.floats(20.0, 80.0))), 5.0))
        surfaces.append(Surface(draw(radius), draw(st.floats(0.5, 20.0)), AIR, 5.0))
    if stop_at == n_el:
        surfaces.append(stop(0.0, 3.0))
    else:
        surfaces[-1] = Surface(surfaces[-1].radius, 0.0, AIR, 5.0)
    return Prescription(tuple(surfaces))


def _has_power(p):
    try:
        g = gaussian(p)
    except OpticsError:
        return False
    return abs(g.efl) < 1e5


@settings(max_examples=60, deadline=None)
@given(random_lenses(), st.floats(-0.2, 0.2), st.floats(-0.2, 0.2), st.floats(-5, 5), st.floats(-5, 5))
def test_lagrange_invariant_is_conserved(p, ua, ub, ya, yb):
    ys_a, nus_a = paraxial_trace(p, ya, ua)
    ys_b, nus_b = paraxial_trace(p, yb, ub)
    h0 = ua * yb - ub * ya  # n u ybar - n ubar y in object space (n = 1)
    for y1, nu1, y2, nu2 in zip(ys_a, nus_a, ys_b, nus_b):
        assert nu1 * y2 - nu2 * y1 == pytest.approx(h0, rel=1e-9, abs=1e-9)


@settings(max_examples=60, deadline=None)
@given(random_lenses(), st.sampled_from(["d", "F", "C"]))
def test_reversing_the_lens_swaps_front_and_back_focal_lengths(p, line):
    wl = {"d": 587.5618, "F": 486.1327, "C": 656.2725}[line]
    assume(_has_power(p))
    g = gaussian(p, wavelength_nm=wl)
    r = gaussian(reversed_lens(p), wavelength_nm=wl)
    assert r.efl == pytest.approx(g.efl, rel=1e-9)
    assert r.ffl == pytest.approx(g.bfl, rel=1e-9, abs=1e-9)
    assert r.bfl == pytest.approx(g.ffl, rel=1e-9, abs=1e-9)
    # the entrance pupil of one is the exit pupil of the other (mirrored about the middle)
    track = p.total_track
    assert r.z_entrance_pupil == pytest.approx(track - g.z_exit_pupil, rel=1e-9, abs=1e-9)
    assert r.entrance_pupil_diameter == pytest.approx(g.exit_pupil_diameter, rel=1e-9)


@settings(max_examples=60, deadline=None)
@given(random_lenses(), st.floats(0.1, 10.0))
def test_scaling_the_lens_scales_every_length(p, k):
    assume(_has_power(p))
    g = gaussian(p)
    s = gaussian(scaled_lens(p, k))
    for name in ("efl", "bfl", "ffl", "z_front_principal_plane", "z_rear_principal_plane", "z_entrance_pupil",
                 "z_exit_pupil", "entrance_pupil_diameter", "exit_pupil_diameter", "z_rear_focal_point"):
        assert getattr(s, name) == pytest.approx(k * getattr(g, name), rel=1e-9, abs=1e-9)
    assert s.f_number == pytest.approx(g.f_number, rel=1e-9)
    assert s.pupil_magnification == pytest.approx(g.pupil_magnification, rel=1e-9)


@settings(max_examples=40, deadline=None)
@given(random_lenses(), st.floats(50.0, 5000.0))
def test_finite_conjugate_magnification_matches_newton(p, s):
    # Newton: m = -f / x with x the object distance from F (object space in air)
    assume(_has_power(p))
    g0 = gaussian(p)
    assume(g0.efl > 0)
    z_obj = g0.z_front_focal_point - s
    assume(z_obj < -1.0)
    g = gaussian(p, object_z=z_obj)
    assert g.magnification == pytest.approx(-g0.efl / s, rel=1e-8)
    assert g.z_image - g0.z_rear_focal_point == pytest.approx(g0.efl**2 / s, rel=1e-7, abs=1e-9)


def test_media_indices_follow_the_lens_and_wavelength_asked_about():
    """The indices are remembered by the surfaces' identity (paraxial._BY_SURFACES): a lens with another glass,
    another wavelength, or more lenses than the memo holds, each gets its own indices (the glass's own formula)."""
    from physcam._record import replace
    from physcam.optics.glass import medium_index
    from physcam.optics.paraxial import _BY_SURFACES_MAX, media_indices

    lens = dgauss()
    first = media_indices(lens)
    assert first == [1.0] + [float(medium_index(s.medium, lens.wavelength_nm)) for s in lens.surfaces]
    i = next(k for k, s in enumerate(lens.surfaces) if s.medium != AIR)
    other = replace(lens, surfaces=tuple(replace(s, medium=Medium(nd=1.9, vd=20.0)) if k == i else s
                                         for k, s in enumerate(lens.surfaces)))
    assert media_indices(other)[i + 1] == pytest.approx(float(medium_index(Medium(nd=1.9, vd=20.0), lens.wavelength_nm)))
    assert media_indices(other)[i + 1] != first[i + 1] and media_indices(lens) == first
    assert media_indices(lens, LINE_F_NM) == [1.0] + [float(medium_index(s.medium, LINE_F_NM)) for s in lens.surfaces]
    many = [scaled_lens(lens, 1.0 + k / 1000) for k in range(_BY_SURFACES_MAX + 5)]  # past the memo: the oldest go
    assert all(media_indices(m) == first for m in many) and media_indices(lens) == first


def test_gaussian_answers_remembered_follow_the_lens_and_arguments():
    """Solves are remembered by the prescription's identity and the arguments (paraxial._GAUSSIAN): a repeat is
    the same answer; another film plane, object, stop, meridian, wavelength or lens gets its own (a thin lens's
    closed forms: image at 1/s' = 1/f + 1/s, stop scaling the pupil); past the memo's size the answers stay right."""
    from physcam.optics.paraxial import _GAUSSIAN_MAX

    f = 50.0
    lens = thin_lens(f)
    g = gaussian(lens)
    assert gaussian(lens) is g and g.efl == pytest.approx(f, rel=1e-12)
    near = gaussian(lens, object_z=-200.0)
    assert near.z_image == pytest.approx(1.0 / (1.0 / f - 1.0 / 200.0), rel=1e-12) and gaussian(lens).z_image == g.z_image
    assert gaussian(lens, film_z=60.0).z_film == 60.0 and gaussian(lens, film_z=61.0).z_film == 61.0
    half = gaussian(lens, stop_semi_diameter=0.5 * g.stop_semi_diameter)
    assert half.entrance_pupil_diameter == pytest.approx(0.5 * g.entrance_pupil_diameter, rel=1e-12)
    assert gaussian(lens, wavelength_nm=LINE_F_NM).wavelength_nm == LINE_F_NM and gaussian(lens, axis="x").axis == "x"
    assert math.copysign(1.0, gaussian(lens, film_z=-0.0).z_film) == -1.0  # -0.0 is not 0.0's answer
    assert math.copysign(1.0, gaussian(lens, film_z=0.0).z_film) == 1.0
    many = [scaled_lens(lens, 1.0 + k / 1000) for k in range(_GAUSSIAN_MAX + 5)]
    assert all(gaussian(m).efl == pytest.approx(f * (1.0 + k / 1000), rel=1e-9) for k, m in enumerate(many))
    assert gaussian(thin_lens(2 * f)).efl == pytest.approx(2 * f, rel=1e-12) and gaussian(lens).efl == g.efl

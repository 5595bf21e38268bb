"""The Blender extension's exit-pupil ellipses (physcam.export.blender_pupil) hold every ray the lens
passes, and little else. The oracle is physcam's tracer run the plain way: a dense grid of aim points
around the ellipse the shader would sample, traced through the lens state the shader traces (the two
tabulated focus states blended as it blends them) with the iris stopped to the f-number (no
stand-in for the stop), at random focus, f-stop and film radius."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from physcam.errors import InputError
from physcam.export.blender_focus import focus_table
from physcam.export.blender_pupil import (RADIAL_MAX_MM, interpolated_area, interpolated_ellipse, iris_levels,
                                         level_bracket)
from physcam.lens.library import load_lens
from physcam.optics.sensors import sensors
from physcam.optics.focusing import focus

from _dense_pupil import passing_aims

pytestmark = pytest.mark.slow


@pytest.fixture(scope="module", params=["dgauss_50mm", "canon_rf_85mm_f1_2"])
def table(request):
    """(lens, focus table, its focus states): unit focusing, and internal focusing (the groups move)."""
    lens = load_lens(request.param)
    ft = focus_table(lens)
    return lens, ft, [focus(lens, float(m)).prescription for m in ft.marks_mm]


def _shader_ellipse(ft, k0, fw, rho, s):
    """(cx, ax, ay) as the shader reads the table: both focus states' ellipses blended, grown between them."""
    e0 = interpolated_ellipse(ft.radial[k0], ft.levels, rho, s)
    e1 = interpolated_ellipse(ft.radial[k0 + 1], ft.levels, rho, s)
    cx, ax, ay = (1 - fw) * e0 + fw * e1
    bump = fw * (1 - fw) * abs(e1[0] - e0[0])
    return cx, ax + bump, ay + bump


def _passing(q, film_z, rho, s, cx, ax, ay, n=160):
    """(passing rays outside the ellipse, passing rays, aim points inside it) on an n x n grid 1.3x the ellipse."""
    gx, gy = np.meshgrid(cx + ((np.arange(n) + 0.5) / n * 2 - 1) * 1.3 * ax, ((np.arange(n) + 0.5) / n * 2 - 1) * 1.3 * ay)
    gx, gy = gx.ravel(), gy.ravel()
    ok = passing_aims(q, film_z, rho, s, gx, gy)
    inside = ((gx - cx) / ax) ** 2 + (gy / ay) ** 2 <= 1
    return int((ok & ~inside).sum()), int(ok.sum()), int(inside.sum()), int((ok & inside).sum())


@settings(max_examples=25)
@given(k=st.floats(0.0, 0.999), fw=st.floats(0.0, 1.0), log_n=st.floats(0.0, 1.0), rho=st.floats(0.0, 20.0))
def test_every_passing_ray_is_in_the_ellipse(table, k, fw, log_n, rho):
    """No ray the lens passes (at the blended focus, f-number from wide open to f/64, film radius up to
    20 mm) aims outside the ellipse the shader samples."""
    lens, ft, states = table
    k0 = int(k * (len(states) - 1))
    n = ft.fstop_min * (64.0 / ft.fstop_min) ** log_n
    s = ft.iris_k / n
    q = states[k0].with_surfaces([dataclasses.replace(a, thickness=(1 - fw) * a.thickness + fw * b.thickness)
                                  for a, b in zip(states[k0].surfaces, states[k0 + 1].surfaces)])
    film_z = (1 - fw) * ft.film_z[k0] + fw * ft.film_z[k0 + 1]
    cx, ax, ay = _shader_ellipse(ft, k0, fw, rho, s)
    outside, passing, _, _ = _passing(q, film_z, rho, s, cx, ax, ay)
    assert outside == 0, (lens.name, k0, fw, n, rho, passing)


def test_every_passing_ray_past_full_frame_is_in_the_ellipse(table):
    """At infinity focus (a traced mark), film radii 22-32 mm (65 mm and IMAX frames), wide open and at
    the last iris level: every ray the lens passes, on a dense grid over the rear element's half
    (y >= 0), aims inside the ellipse the shader samples. The double Gauss's rear surface bows toward
    the film, so a point 27 mm off axis aims its passing rays up to 10.6 mm off axis on the rear
    vertex plane, past the rear element's 10 mm: the tables searched only the element's square there
    and put the ellipse short of the set (65 % of the rays outside at 27.3 mm wide open) or found none."""
    lens, ft, states = table
    q, film_z = states[0], ft.film_z[0]
    r = 1.3 * q.surfaces[-1].semi_diameter
    gx, gy = np.meshgrid(np.linspace(-r, r, 480), np.linspace(0.0, r, 240))
    gx, gy = gx.ravel(), gy.ravel()
    lost = []
    for s in (ft.levels[0], ft.levels[-1]):
        for rho in np.arange(22.0, 32.01, 0.5).tolist():
            cx, ax, ay = interpolated_ellipse(ft.radial[0], ft.levels, rho, s)
            ok = passing_aims(q, film_z, rho, s, gx, gy)
            out = int((ok & (((gx - cx) / ax) ** 2 + (gy / ay) ** 2 > 1)).sum())
            if out:
                lost.append((round(s, 3), rho, out, int(ok.sum())))
    assert not lost, (lens.name, lost)


def test_stopped_down_nearly_every_sample_passes(table):
    """At f/5.6 and f/16 from the axis to 15 mm, over 0.95 of the ellipse's aim points pass (issue 41:
    the Canon RF 85 at f/8 wasted 96 % of the samples of the old rectangles)."""
    lens, ft, states = table
    for n in (5.6, 16.0):
        for rho in (0.0, 7.0, 15.0):
            s = ft.iris_k / n
            cx, ax, ay = _shader_ellipse(ft, 10, 0.0, rho, s)
            _, _, inside, hit = _passing(states[10], ft.film_z[10], rho, s, cx, ax, ay, n=120)
            print(f"{lens.name} f/{n} rho {rho}: {hit / inside:.3f} of the samples pass")
            assert hit / inside > 0.95


def test_the_passing_area_where_the_iris_alone_bounds_it(table):
    """Where the table gives the passing set's area (the shader then redraws missed aims and weighs the
    ray by that area), it is the dense trace's within 0.5 %: wide open to f/32, the axis to 20 mm. Near the
    axis the iris alone bounds the set, so the area is known there at every stop, f/2.8 too (trusted per
    cell: a wider level whose set other surfaces cut no longer withdraws it)."""
    lens, ft, states = table
    k0 = 12
    q, film_z = states[k0], ft.film_z[k0]
    known = 0
    for n in (ft.fstop_min, 2.8, 4.0, 5.6, 11.0, 32.0):
        for rho in (0.0, 5.0, 10.0, 15.0, 20.0):
            s = ft.iris_k / n
            area = interpolated_area(ft.radial[k0], ft.levels, rho, s)
            if rho == 0.0 and n >= 2.8:
                assert area > 0, (lens.name, n)
            if area < 0:
                continue  # another surface clips the set there: one aim per ray, weighed by the ellipse
            known += 1
            cx, ax, ay = interpolated_ellipse(ft.radial[k0], ft.levels, rho, s)
            _, passing, _, _ = _passing(q, film_z, rho, s, cx, ax, ay, n=400)
            dense = passing / 400**2 * (2 * 1.3 * ax) * (2 * 1.3 * ay)
            assert area == pytest.approx(dense, rel=0.005), (lens.name, n, rho)
    assert known >= 15


def test_the_passing_area_where_other_surfaces_cut_the_set(table):
    """Issue 41: wide open and off axis, surfaces other than the iris cut the passing set (vignetting). The
    table knows its area there too now (the rim found where the cut and the iris meet, the grid zoomed
    onto a set narrow in either direction, the area a cubic in rho, levels a third of a stop apart), so
    the shader redraws missed aims over most of a full frame (film radius to 21.6 mm) at f/2.8 and f/4,
    where main's table knew it only within 5.5-7 mm of the axis at f/2.8 (0.25-0.35 of the radii) and
    every other ray of the frame took one aim (2-16 % of them missed). Where it is known from 12 mm
    out (at f/2.8 other surfaces cut the set there), the area is a dense trace's within 0.5 %."""
    lens, ft, states = table
    k0 = 12
    q, film_z = states[k0], ft.film_z[k0]
    rhos = np.arange(0.0, 21.65, 0.4)
    checked = 0
    for n in (2.8, 4.0):
        s = ft.iris_k / n
        areas = np.array([interpolated_area(ft.radial[k0], ft.levels, rho, s) for rho in rhos])
        print(f"{lens.name} f/{n}: area known at {np.mean(areas >= 0):.2f} of the film radii")
        assert np.mean(areas >= 0) > 0.75, (lens.name, n)
        for rho in (12.0, 15.0, 18.0, 21.0):
            area = interpolated_area(ft.radial[k0], ft.levels, rho, s)
            if area < 0:
                continue
            cx, ax, ay = interpolated_ellipse(ft.radial[k0], ft.levels, rho, s)
            _, passing, _, _ = _passing(q, film_z, rho, s, cx, ax, ay, n=400)
            dense = passing / 400**2 * (2 * 1.3 * ax) * (2 * 1.3 * ay)
            checked += 1
            assert area == pytest.approx(dense, rel=0.005), (lens.name, n, rho)
    assert checked >= 5


def test_a_failed_check_withdraws_only_the_cells_it_lies_on():
    """Worked by hand on 4 levels x 5 radii (step 1 mm): a check failing at a mid point (film radius
    2.5, iris between the first two levels) withdraws that one cell; one at a node and a level (film
    radius 1, the third level) the four cells around it; one below the last level the "below" cell;
    an entry where nothing passes the four cells it is a corner of."""
    from physcam.export.blender_pupil import _trusted_cells

    levels = np.array([4.0, 3.0, 2.0, 1.0])
    lit = np.ones((4, 5), dtype=bool)
    ok = _trusted_cells(levels, [(2.5, 3.5)], lit, 1.0)
    assert (~ok).sum() == 1 and not ok[0, 2]
    ok = _trusted_cells(levels, [(1.0, 2.0)], lit, 1.0)
    assert sorted(zip(*np.nonzero(~ok))) == [(1, 0), (1, 1), (2, 0), (2, 1)]
    ok = _trusted_cells(levels, [(3.2, 0.5)], lit, 1.0)
    assert sorted(zip(*np.nonzero(~ok))) == [(3, 3)]
    ok = _trusted_cells(levels, [(3.2, 0.5), (2.5, 3.5), (1.0, 2.0)], lit, 1.0)  # together: the union of the three
    assert sorted(zip(*np.nonzero(~ok))) == [(0, 2), (1, 0), (1, 1), (2, 0), (2, 1), (3, 3)]
    dark = lit.copy()
    dark[2, 2] = False
    ok = _trusted_cells(levels, [], dark, 1.0)
    assert sorted(zip(*np.nonzero(~ok))) == [(1, 1), (1, 2), (2, 1), (2, 2)]


def test_the_table_reaches_every_sensors_corner():
    """Every sensor of ``physcam sensors`` (IMAX 15/70 the largest, 87.9 mm diagonal) fits the table."""
    assert max(math.hypot(s.width_mm, s.height_mm) / 2 for s in sensors()) <= RADIAL_MAX_MM


def test_iris_levels_and_their_bracket():
    levels = iris_levels(9.0, 8.55)
    assert levels[0] == 9.0 and levels[1] == 8.55 and levels[-1] == pytest.approx(8.55 / 16)
    assert level_bracket(levels, 9.0) == (0, 0.0, 1.0)
    assert level_bracket(levels, 8.55)[0] in (0, 1)
    l0, lw, shrink = level_bracket(levels, levels[-1] / 2)
    assert (l0, lw, shrink) == (len(levels) - 2, 1.0, 0.5)
    with pytest.raises(InputError):
        iris_levels(8.0, 9.0)


def test_the_ellipse_holds_the_spot_behind_a_cover_glass():
    """The Sony Zeiss 55 f/1.8 ends in a flat cover glass 1 mm in front of the film: rays from a
    film point cross the rear-vertex plane in a spot ~0.56 mm wide (d / N), under one step of a grid
    over the 46 mm rear element. Every ray a dense trace (201 x 201 aims over +-0.8 mm about the
    point straight ahead) finds passing at f/1.86 and f/5.6, on the axis and 10 mm out, lies in the
    table's ellipse; the ellipse's half width on the axis wide open is d / (2N) (paraxial marginal
    ray in air) within 10 %."""
    from physcam.export.blender_pupil import radial_pupil_table
    from physcam.optics.focusing import gaussian_at_focus

    lens = load_lens("sony_zeiss_55mm_f1_8_za")
    st_ = focus(lens, math.inf)
    q, film_z = st_.prescription, st_.film_z
    semi = q.surfaces[q.stop_index].semi_diameter
    levels = iris_levels(semi * 1.02, semi)
    table = radial_pupil_table(q, film_z, levels)
    n_open = gaussian_at_focus(lens, math.inf).f_number
    d = film_z - q.vertex_z[-1]
    assert table[1, 0, 1] == pytest.approx(d / (2 * n_open), rel=0.1)
    u = np.linspace(-0.8, 0.8, 201)
    for n in (n_open, 5.6):
        s = semi * n_open / n
        for rho in (0.0, 10.0):
            gx, gy = [a.ravel() for a in np.meshgrid(rho + u, u)]
            ok = passing_aims(q, film_z, rho, s, gx, gy)
            cx, ax, ay = interpolated_ellipse(table, levels, rho, s)
            assert ok.sum() > 100 and ax > 0 and ay > 0
            assert (((gx[ok] - cx) / ax) ** 2 + (gy[ok] / ay) ** 2 <= 1).all(), (n, rho)


def test_the_rim_area_of_a_regular_polygon():
    """The batched shoelace area (both halves from the y >= 0 half) against a regular polygon's closed form
    n/2 R^2 sin(2 pi / n): two rims in one call, their points shuffled, one rim empty."""
    from physcam.export.blender_pupil_sets import _polygon_areas

    rng = np.random.default_rng(3)
    k, xs, ys, want = [], [], [], []
    for rim, (cx, r, m) in enumerate([(1.5, 2.0, 13), (None, None, 0), (-4.0, 0.7, 40)]):
        if not m:
            want.append(0.0)
            continue
        th = np.pi * rng.permutation(m) / (m - 1)  # m points from 0 to pi: a regular 2(m - 1)-gon
        k += [rim] * m
        xs.append(cx + r * np.cos(th))
        ys.append(r * np.sin(th))
        n = 2 * (m - 1)
        want.append(n / 2 * r * r * math.sin(2 * math.pi / n))
    k = np.array(k)
    got = _polygon_areas(k, np.concatenate(xs), np.concatenate(ys), np.searchsorted(k, np.arange(4)))
    np.testing.assert_allclose(got, want, rtol=1e-12, atol=0)


@settings(max_examples=30, deadline=None)
@given(seed=st.integers(0, 2**32 - 1))
def test_the_batched_reading_is_the_shaders(seed):
    """The whole-array readings the table is grown and checked with give the shader's reading
    (interpolated_ellipse, interpolated_area) at every film and iris radius: the ellipse to the last
    bit, the area to rounding."""
    from physcam.export.blender_pupil import N_LEVEL, N_RADIAL, _areas_at, _ellipses_at

    rng = np.random.default_rng(seed)
    levels = iris_levels(12.0, 10.0)
    table = rng.uniform(0.1, 20.0, (N_LEVEL, N_RADIAL, 5))
    table[..., 3] = np.where(rng.random((N_LEVEL, N_RADIAL)) < 0.1, -1.0, table[..., 3])
    rhos = list(rng.uniform(0, RADIAL_MAX_MM, 20)) + [0.0, RADIAL_MAX_MM]
    ss = list(rng.uniform(levels[-1] / 3, levels[0], 20)) + [float(levels[0]), float(levels[-1])]
    e = _ellipses_at(table, levels, rhos, ss)
    a = _areas_at(table, levels, rhos, ss)
    for i, (rho, s) in enumerate(zip(rhos, ss)):
        assert e[i].tolist() == interpolated_ellipse(table, levels, rho, s).tolist()
        assert a[i] == pytest.approx(interpolated_area(table, levels, rho, s), rel=1e-13, abs=0)


@settings(max_examples=25, deadline=None)
@given(st.lists(st.floats(allow_nan=False, allow_infinity=False, width=64) | st.floats(-1e4, 1e4).map(round)
                | st.sampled_from([0.0, -0.0, 1e-4, 9.99999999e-5, 1e9, 999999999.5, 1.5e9, 1e16, 5e-324,
                                   1.00004999e-4, 1.0001e-4, 0.99999999951, 2.9999999949, 9999999.995, 9999999.5,
                                   12345678.9, 99999999.95, -1.0, 1.0])
                | st.tuples(st.integers(-10**6, 10**6), st.floats(-0.011, 0.011)).map(lambda t: t[0] + t[1]),
                min_size=1, max_size=40))
def test_the_shaders_data_lines_write_each_number_as_its_nine_digit_repr(values):
    """Every number of a data line (the pupil table's 154,000 among them) is osl_number of its nine-digit
    rounding (a float32 exactly; the repr of that double, ".0" on an integer), whatever the shortcut
    the line writer takes for the common case."""
    from physcam.export.blender_focus import _arr32
    from physcam.export.osl import osl_number

    want = ", ".join(osl_number(float(format(v, ".9g"))) for v in values)
    assert _arr32("T", values, "N") == f"    float T[N] = {{{want}}};"


def test_levels_that_share_the_centres_aims_sample_a_region_holding_their_sets(table):
    """The centre's normalisation traces one region per pair of levels (the wider one's ellipse at the
    film centre): it holds every aim a dense trace finds passing at the narrower level's iris."""
    from physcam.export.blender_pupil import _centre_ellipses

    lens, ft, states = table
    q = states[0]
    st_ = focus(lens, float(ft.marks_mm[0]))
    shared = _centre_ellipses(ft.radial[0])
    assert (shared[1::2] == ft.radial[0][0::2, 0, :3][: len(shared[1::2])]).all()
    for k in (1, 7, len(ft.levels) - 1):
        cx, ax, ay = shared[k]
        u = np.linspace(-1.0, 1.0, 121)
        gx, gy = [a.ravel() for a in np.meshgrid(u * ft.radial[0][k, 0, 1] * 1.2, u * ft.radial[0][k, 0, 2] * 1.2)]
        ok = passing_aims(q, st_.film_z, 0.0, float(ft.levels[k]), gx, gy)
        assert ok.sum() > 100
        assert (np.abs(gx[ok] - cx) <= ax).all() and (np.abs(gy[ok]) <= ay).all(), k


def test_the_centres_normalisation_is_a_dense_traces(table):
    """The shader's normalisation at the traced marks (the first and the last: infinity and the closest focus),
    ``focus_table``'s closed form for the centre's disk of passing aims (blender_focus._centre_disk_norms), against
    physcam's camera rays from the film centre, the iris stopped to the level: their mean weight over a 512 x 512
    grid of aims on the square about the table's ellipse at the film centre (any region that holds the passing
    aims has the same mean, camera_rays' weight being its area times cos^4 / d^2 per aim). Within 5e-4: the dense
    grid's own error (a lattice's count of the cells inside a disk) is up to 1.7e-4 at 512 x 512 here, and 3e-5 at
    1024 x 1024 on a square 1.02 times the disk (docs/performance.md); the 64 x 64 grid the closed form replaced
    was 0.3-0.7 % off."""
    from physcam.trace.pupil_bounds import PupilBounds
    from physcam.trace.trace import camera_rays

    lens, ft, states = table
    m = 512
    u = (np.arange(m) + 0.5) / m
    uv = np.stack([a.ravel() for a in np.meshgrid(u, u)], axis=1)
    for k in (0, len(ft.marks_mm) - 1):
        st_ = focus(lens, float(ft.marks_mm[k]))
        q = st_.prescription
        for lv in (0, 1, 9, len(ft.levels) - 1):
            want = float(ft.norm[k][lv])
            cx, ax, ay = ft.radial[k][lv, 0, :3]  # the table's ellipse at the film centre holds the passing aims
            h = max(abs(cx) + ax, ay)
            rect = np.broadcast_to(np.array([-h, h, -h, h]), (2, 2, 4)).copy()
            bounds = PupilBounds(np.array([-1.0, 1.0]), np.array([-1.0, 1.0]), rect, float(q.vertex_z[-1]))
            cr = camera_rays(q, np.zeros((uv.shape[0], 2)), uv, st_.film_z, bounds=bounds,
                             stop_semi_diameter=float(ft.levels[lv]))
            dense = float(np.mean(np.where(cr.ok, cr.weight, 0.0)))
            assert abs(want / dense - 1) < 5e-4, (k, lv, want, dense)

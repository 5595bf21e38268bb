"""The extension's pupil and normalisation tables between the marks where they are traced
(physcam.export.blender_focus.fill_pupil_tables, issue 47): a cubic in the focus index through the four
traced marks about a mark, its ellipses and rectangles grown by the cubic's difference from the line.
Oracles: polynomials worked by hand (Lagrange's cubic reproduces any cubic, the line any line), the
tracer's rays at interpolated marks (tests/export/test_blender_pupil.py, whose tables are now filled),
and exact focus solves for the internal-focus film slope that replaced two bisections per mark."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from physcam.errors import InputError
from physcam.export.blender_focus import fill_pupil_tables, focus_axis, focus_geometry, pupil_marks
from physcam.export.blender_pupil import cell_area
from physcam.lens.library import load_lens
from physcam.optics.focusing import closest_focus, focus


def test_the_traced_marks_by_hand():
    assert pupil_marks(32, 4).tolist() == [0, 4, 8, 12, 16, 20, 24, 28, 31]
    assert pupil_marks(12, 2).tolist() == [0, 2, 4, 6, 8, 10, 11]
    assert pupil_marks(12, 3).tolist() == [0, 3, 6, 9, 11]
    assert pupil_marks(5, 1).tolist() == [0, 1, 2, 3, 4]
    for bad in (0, -1, 1.5, True):
        with pytest.raises(InputError):
            pupil_marks(32, bad)


def _radial(values_per_mark):
    """A (marks, 2 levels, 3 radii, 5) table: cx, ax, ay, area, slope, from per-mark (cx, ax, ay, area, slope)."""
    v = np.asarray(values_per_mark, dtype=float)
    return np.broadcast_to(v[:, None, None, :], (len(v), 2, 3, 5)).copy()


@settings(max_examples=40, deadline=None)
@given(c=st.lists(st.floats(-0.5, 0.5), min_size=4, max_size=4), n=st.sampled_from([12, 32]),
       stride=st.sampled_from([2, 3, 4]))
def test_a_cubic_in_the_index_comes_back_exact_and_its_ellipses_only_grow(c, n, stride):
    """Every column a cubic in the index: the filled tables are the cubic at every mark (centre, area,
    slope, norm), and the axes at least the cubic's (grown by |cubic - line|, scaled by 1 + d_cx / ax)."""
    x = np.arange(n, dtype=float) / n
    cubic = c[0] + c[1] * x + c[2] * x**2 + c[3] * x**3
    exact = np.stack([5.0 + cubic, 2.0 + cubic, 1.5 + 0.5 * cubic, 3.0 + cubic, 0.1 + cubic], axis=1)
    traced = pupil_marks(n, stride)
    radial, rects, stopped, norm = fill_pupil_tables(traced, n, radial=_radial(exact[traced]),
                                                     norm=exact[traced, 3:4])
    assert rects is None and stopped is None
    assert np.allclose(radial[:, 0, 0, [0, 4]], exact[:, [0, 4]], atol=1e-9)
    assert np.allclose(cell_area(radial[:, 0, 0, 3]), exact[:, 3], atol=1e-9)
    assert np.allclose(norm[:, 0], exact[:, 3], atol=1e-9)
    assert (radial[..., 1] >= exact[:, None, None, 1] - 1e-9).all()
    assert (radial[..., 2] >= exact[:, None, None, 2] - 1e-9).all()


@settings(max_examples=30, deadline=None)
@given(a=st.floats(-1.0, 1.0), b=st.floats(-0.05, 0.05), stride=st.sampled_from([2, 4]))
def test_a_line_is_filled_without_growth(a, b, stride):
    """Where the table is linear in the index the cubic is the line: nothing grows."""
    n = 32
    k = np.arange(n, dtype=float)
    exact = np.stack([5.0 + a + b * k, 2.0 + b * k, 1.5 + b * k, 3.0 + b * k, 0.1 + 0 * k], axis=1)
    traced = pupil_marks(n, stride)
    radial, _, _, _ = fill_pupil_tables(traced, n, radial=_radial(exact[traced]))
    assert np.allclose(radial[:, 0, 0], exact, atol=1e-9)


def test_an_area_untrusted_at_a_traced_mark_is_untrusted_where_the_cubic_reads_it():
    """A cell's area weighs rays at a filled mark only where every traced mark its cubic reads trusts it
    (the sign of blender_pupil's area column); the traced marks keep their own."""
    n, stride = 32, 4
    traced = pupil_marks(n, stride)
    tab = _radial(np.tile([5.0, 2.0, 1.5, 3.0, 0.1], (len(traced), 1)))
    tab[3, 1, 2, 3] = -1.0 - 3.0  # traced mark 12, level 1, radius 2: untrusted, area 3
    radial, _, _, _ = fill_pupil_tables(traced, n, radial=tab)
    untrusted = radial[:, 1, 2, 3] < 0
    # the marks whose cubic reads traced mark 12: the intervals 0-4 and 4-8 (their cubic: marks 0, 4, 8, 12),
    # 8-12 (4..16), 12-16 (8..20) and 16-20 (12..24), and mark 12 itself
    assert np.flatnonzero(untrusted).tolist() == [1, 2, 3, 5, 6, 7, 9, 10, 11, 12, 13, 14, 15, 17, 18, 19]
    assert np.allclose(np.where(radial[..., 3] < 0, -1.0 - radial[..., 3], radial[..., 3]), 3.0)
    assert (radial[:, 0, :, 3] > 0).all() and (radial[:, 1, :2, 3] > 0).all()


def test_an_area_that_bends_between_traced_marks_is_not_trusted():
    """Where the cubic and the line through the traced marks differ by more than AREA_TOLERANCE (0.4 %) the
    area is withdrawn (the shader then weighs by the sampled region, no bias); a smooth area keeps it."""
    n = 32
    traced = pupil_marks(n, 4)
    k = traced.astype(float)
    area = 3.0 + 0.002 * (k - 16.0) ** 2  # a parabola: the line between marks 4 apart is off by 0.008 mm^2 (0.27 %)
    tab = _radial(np.stack([5.0 + 0 * k, 2.0 + 0 * k, 1.5 + 0 * k, area, 0 * k], axis=1))
    radial, _, _, _ = fill_pupil_tables(traced, n, radial=tab)
    assert (radial[..., 3] > 0).all()
    bent = _radial(np.stack([5.0 + 0 * k, 2.0 + 0 * k, 1.5 + 0 * k, 3.0 + 0.01 * (k - 16.0) ** 2, 0 * k], axis=1))
    radial, _, _, _ = fill_pupil_tables(traced, n, radial=bent)  # off by 0.04 mm^2 at mid-interval: withdrawn
    assert (radial[pupil_marks(n, 4), :, :, 3] > 0).all()
    assert (radial[[2, 14, 30], :, :, 3] < 0).all()


def test_rectangles_between_traced_marks_hold_both_neighbours():
    """An anamorphic's exit-pupil rectangle at a filled mark holds both traced neighbours' (they step by
    window samples as the lens focuses); empty only where both are, the other's next to an empty one."""
    n = 12
    traced = pupil_marks(n, 2)
    rects = np.zeros((len(traced), 1, 3, 4))
    rects[:, 0, 0] = [[-1.0 - 0.1 * (i % 2), 1.0, -2.0, 2.0] for i in range(len(traced))]  # steps in x0
    rects[:3, 0, 1] = [-1.0, 1.0, -1.0, 1.0]  # empty from traced mark 6 on
    _, out, _, _ = fill_pupil_tables(traced, n, rects=rects)
    for i in sorted(set(range(n)) - set(traced.tolist())):
        j = np.searchsorted(traced, i) - 1
        a, b = rects[j, 0, 0], rects[j + 1, 0, 0]
        assert out[i, 0, 0, 0] <= min(a[0], b[0]) and out[i, 0, 0, 1] >= max(a[1], b[1])
    assert out[5, 0, 1].tolist() == [-1.0, 1.0, -1.0, 1.0]  # between mark 4 (full) and 6 (empty)
    assert np.array_equal(out[traced], rects)  # the traced marks keep their own, the last one too
    assert (out[7:, 0, 1] == 0).all() and (out[:, 0, 2] == 0).all()


@pytest.mark.parametrize("slug", ["canon_rf_85mm_f1_2", "navarro_anamorphic_2x", "dgauss_50mm", "telephoto_250mm"])
def test_the_film_slope_is_the_difference_of_exact_solves(slug):
    """The film plane's slope per index step, now without focus solves past the first mark (closed form
    for unit focusing, the groups' gaps and the paraxial image for internal focusing), against the
    second-order difference of physcam's exact focus solves 1e-3 steps apart (round 7's way; one-sided
    at the last mark, the 1:1 conjugate for the unit-focusing two): within 2e-5 mm per step (the
    tables' film-plane budget is 0.002 mm)."""
    lens = load_lens(slug)
    axis = focus_axis(closest_focus(lens), 32)
    _, slope, _ = focus_geometry(lens, axis)

    def film(x):
        return focus(lens, axis.mark(x)).film_z

    eps = 1e-3
    for k in (1, 9, 30, 31):
        if k == axis.n - 1:
            ref = (3 * film(k) - 4 * film(k - eps) + film(k - 2 * eps)) / (2 * eps)
        else:
            ref = (film(k + eps) - film(k - eps)) / (2 * eps)
        assert slope[k] == pytest.approx(ref, abs=2e-5), (slug, k)


def _dense_passing(q, film_z, rho, s, cx, ax, ay, reach, n):
    """(aim x, aim y, passing) of an n x n grid of aims on the rear vertex plane over ``reach`` times the
    ellipse (cx, ax, ay), traced from the film point (rho, 0) through the focused lens ``q`` with the
    iris at semi-diameter ``s``: the dense trace the tables are checked against."""
    from physcam.trace.rays import OK, RayBatch
    from physcam.trace.trace import trace_through

    u = (np.arange(n) + 0.5) / n * 2 - 1
    gx, gy = np.meshgrid(cx + u * reach * ax, u * reach * ay)
    gx, gy = gx.ravel(), gy.ravel()
    rays = RayBatch.from_arrays(np.broadcast_to([rho, 0.0, film_z], (gx.size, 3)),
                                np.stack([gx - rho, gy, np.full(gx.size, q.vertex_z[-1] - film_z)], axis=1),
                                q.wavelength_nm)
    trace_through(q, rays, reverse=True, clip=True, stop_semi_diameter=s, in_place=True)
    return gx, gy, rays.flag == OK


@pytest.mark.slow
def test_a_filled_mark_holds_the_rays_at_the_frame_edge_stopped_far_down(dgauss_table):
    """The double Gauss at filled mark 1 (between traced 0 and 2; round 8: 0 and 4), a film point 26.6 mm off axis (past full
    frame: 65 mm and IMAX sensors) at iris radius 0.267 mm (half the last level, about f/46): the tracer's
    passing rays (dense aim grid, the real stop) all lie in the ellipse the shader samples. The pupil
    table grows this entry at some marks and not others (blender_pupil._grow); filled by the cubic alone
    it held 71 % of them (before _roughness). At least 500 passing rays are checked: the grid spans 6 x 6
    semi-axes, so n^2 pi / 36 of its rays fall in the ellipse and the passing count is that times the entry's
    sampling efficiency (passing area over the ellipse's). The table of 2026-11-28 traced at mark 1 itself
    has 0.13 there (458 passing of a 200^2 grid's 3480; filled, 0.21), the finer table of issue 41's round 8
    filled 0.125 (436), so the grid is 300^2 (7860 in the ellipse): 500 bounds the rays checked, not the
    efficiency."""
    from physcam.export.blender_pupil import interpolated_ellipse
    from physcam.trace.camera_tracer import CameraTracer

    lens = load_lens("dgauss_50mm")
    ft = dgauss_table
    st = focus(lens, float(ft.marks_mm[1]))
    q = CameraTracer(st.prescription, st.film_z).lens
    rho, s = 26.583333333333332, ft.levels[-1] / 2
    cx, ax, ay = interpolated_ellipse(ft.radial[1], ft.levels, rho, s)
    gx, gy, ok = _dense_passing(q, st.film_z, rho, s, cx, ax, ay, 3.0, 300)
    inside = ((gx - cx) / ax) ** 2 + (gy / ay) ** 2 <= 1
    assert ok.sum() > 500
    assert (ok & ~inside).sum() == 0


def test_an_entry_that_jumps_between_traced_marks_keeps_a_sane_ellipse():
    """An entry whose axes jump from mark to mark (the pupil table's growth comes and goes) makes the
    cubic dip below zero between traced marks: the filled axes stay at least the line's and within the
    growth the rule allows (a dip once scaled an ellipse to 1e11 mm: every sample wasted)."""
    n = 32
    traced = pupil_marks(n, 4)
    ax = np.array([3.0, 0.02, 0.02, 3.0, 3.0, 0.02, 0.02, 3.0, 3.0])  # the centre jumps with it
    tab = _radial(np.stack([5.0 + ax, ax, ax, 0.5 + 0 * ax, 0 * ax], axis=1))
    radial, _, _, _ = fill_pupil_tables(traced, n, radial=tab)
    assert np.isfinite(radial).all()
    assert (radial[..., 1:3] >= 0.02 - 1e-12).all()
    assert radial[..., 1:3].max() < 100.0  # 17 mm here; 1.8e10 mm before the axes were kept above the line


@pytest.fixture(scope="module")
def dgauss_table():
    """The double Gauss's focus table as the extension builds it (pupil tables traced at marks 0, 2, 4, 8, ...)."""
    from physcam.export.blender_focus import focus_table

    return focus_table(load_lens("dgauss_50mm"))


def test_the_band_the_infinity_mark_distrusts_is_trusted_at_the_marks_about_2_5_m(dgauss_table):
    """Issue 41, round 9: the infinity mark distrusts the area at f/2.8 over film radii 8.6-10.9 mm; filled
    marks 1-3 (2.5-10 m, the outdoor scene's 2.5 m focus reads marks 1 and 2) inherited it, so the area
    weighed rays over 0.89 of a full frame's film radii (main) where every mark traced trusts 0.945 (the
    rho-interpolation misses at 9.8-11 mm at marks 1 and 2 themselves). Now the first interval's middle is
    traced and a filled mark that a traced one's distrust would withdraw is checked as a traced one is."""
    from physcam.export.blender_pupil import interpolated_area

    ft = dgauss_table
    assert 1.0 < ft.axis.index(2500.0) < 2.0
    s = ft.iris_k / 2.8
    rhos = np.arange(0.0, 21.65, 0.1)
    for k in (1, 2, 3):
        known = np.array([interpolated_area(ft.radial[k], ft.levels, r, s) for r in rhos]) >= 0
        assert known.mean() > 0.93, (k, known.mean())  # main: 0.889
        assert known[(rhos > 8.65) & (rhos < 9.75)].all(), k


@pytest.mark.parametrize("k", [1, 3])
def test_the_area_a_filled_mark_trusts_in_that_band_is_a_dense_traces(dgauss_table, k):
    """Where filled marks 1 and 3 now weigh rays by the area (f/2.8, film radius 8.8-9.6 mm, where main
    withdrew it), it is the tracer's passing area within 0.5 % (AREA_TOLERANCE 0.4 % and the grid's own
    error): a 400 x 400 grid of aims over 1.3x the shader's ellipse, through the lens focused at that mark
    with the iris stopped to f/2.8."""
    from physcam.export.blender_pupil import interpolated_area, interpolated_ellipse
    from physcam.trace.camera_tracer import CameraTracer

    ft = dgauss_table
    st = focus(load_lens("dgauss_50mm"), float(ft.marks_mm[k]))
    q = CameraTracer(st.prescription, st.film_z).lens
    s, n = ft.iris_k / 2.8, 400
    for rho in (8.8, 9.2, 9.6):
        area = interpolated_area(ft.radial[k], ft.levels, rho, s)
        assert area > 0, (k, rho)
        cx, ax, ay = interpolated_ellipse(ft.radial[k], ft.levels, rho, s)
        _, _, ok = _dense_passing(q, st.film_z, rho, s, cx, ax, ay, 1.3, n)
        assert not ok.reshape(n, n)[[0, -1]].any() and not ok.reshape(n, n)[:, [0, -1]].any()  # the set lies inside
        dense = ok.sum() / n**2 * (2 * 1.3 * ax) * (2 * 1.3 * ay)
        print(f"mark {k} rho {rho}: table {area:.4f} mm^2, dense {dense:.4f} mm^2 ({area / dense - 1:+.2%})")
        assert area == pytest.approx(dense, rel=0.005), (k, rho)


def test_a_traced_ellipse_that_pokes_out_grows_only_the_marks_about_it():
    """The growth a traced mark's ellipse needs beyond its neighbours' interpolation (here 5 % at traced mark
    24, near closest focus) grows the filled marks whose cubic reads that mark, not the whole focus range:
    the marks of intervals 0-16 (their cubics read marks 0-20 only) keep the
    traced ellipse exactly (main grew every filled mark by the worst such poke anywhere: issue 41, round 10)."""
    n, stride = 32, 4
    traced = pupil_marks(n, stride)
    tab = _radial(np.tile([5.0, 2.0, 1.5, 3.0, 0.1], (len(traced), 1)))
    tab[6, :, :, 1:3] *= 1.05  # traced mark 24 (index 6 of 0, 4, ..., 28, 31)
    radial, _, _, _ = fill_pupil_tables(traced, n, radial=tab)
    filled = sorted(set(range(n)) - set(traced.tolist()))
    cubic_reads_24 = [i for i in filled if i > 16]  # the intervals 16-20 (cubic 12..24) .. 28-31 (20..31)
    for i in filled:
        if i in cubic_reads_24:
            assert (radial[i, :, :, 1] > 2.0 * 1.0001).all(), i  # grown (by the cubic's bend and the poke)
        else:
            assert np.allclose(radial[i, :, :, 1:3], [2.0, 1.5], atol=1e-12), i


def test_a_filled_marks_ellipse_is_near_the_one_traced_there(dgauss_table):
    """The double Gauss at filled mark 1 (the outdoor benchmark's 2.5 m focus reads marks 1 and 2), f/2.8, film
    radius 0-21.6 mm (full frame): the ellipse the shader samples against the one a table traced at that
    mark gives (physcam's tracer at the mark's focus state). Every aim the larger ellipse misses is a dark
    sample where the area is not trusted and a redraw outside the sampler's strata where it is: the filled
    ellipse was 6.5 % larger on average (up to 13 %) when every filled mark took the growth of the worst
    traced mark anywhere in the focus range (outdoor f/2.8 needed 39 samples for the built-in's 32 noise
    against 32 with every mark traced); now 3.6 % (up to 8 %). And never smaller than the traced one."""
    from physcam.export.blender_pupil import interpolated_ellipse, radial_pupil_table
    from physcam.trace.camera_tracer import CameraTracer

    ft = dgauss_table
    st = focus(load_lens("dgauss_50mm"), float(ft.marks_mm[1]))
    traced = radial_pupil_table(CameraTracer(st.prescription, st.film_z).lens, st.film_z, ft.levels)
    s = ft.iris_k / 2.8
    ratio = []
    for rho in np.arange(0.0, 21.65, 0.2):
        cx, ax, ay = interpolated_ellipse(ft.radial[1], ft.levels, rho, s)
        tcx, tax, tay = interpolated_ellipse(traced, ft.levels, rho, s)
        ratio.append(ax * ay / (tax * tay))
    ratio = np.array(ratio)
    print(f"filled / traced ellipse area at mark 1, f/2.8: mean {ratio.mean():.4f}, max {ratio.max():.4f}")
    assert ratio.min() >= 1.0 - 1e-9
    assert ratio.mean() < 1.045  # main: 1.065


@pytest.mark.parametrize("k", [1, 2])
def test_the_band_where_other_surfaces_begin_to_cut_the_set_is_trusted_and_a_dense_traces(dgauss_table, k):
    """Issue 41 item 8: at f/2.8 (iris radius 6.20 mm, between the levels 6.79 and 6.05 mm) other surfaces
    begin to cut the double Gauss's passing set at film radii 9.8-11.0 mm, and the cubic in iris radius
    between those levels missed the traced area there by 0.25-0.64 %: marks 1 and 2 (the outdoor scene's
    2.5 m focus reads them) weighed no ray by the area over 0.055 of a full frame's film radii (main: trusted
    0.945). With a level between the two the area is trusted at every film radius to 21.6 mm, and there it
    is the tracer's passing area within 0.5 % (AREA_TOLERANCE 0.4 % and the grid's own error): a 300 x 300
    grid of aims over 1.3x the shader's ellipse, through the lens focused at that mark, iris at f/2.8."""
    from physcam.export.blender_pupil import interpolated_area, interpolated_ellipse
    from physcam.trace.camera_tracer import CameraTracer

    ft = dgauss_table
    s = ft.iris_k / 2.8
    rhos = np.arange(0.0, 21.65, 0.1)
    known = np.array([interpolated_area(ft.radial[k], ft.levels, r, s) for r in rhos]) >= 0
    assert known.all(), rhos[~known].tolist()  # main: 9.8-10.9 mm not
    st = focus(load_lens("dgauss_50mm"), float(ft.marks_mm[k]))
    q = CameraTracer(st.prescription, st.film_z).lens
    n = 300
    for rho in (9.9, 10.4, 10.9):
        area = interpolated_area(ft.radial[k], ft.levels, rho, s)
        cx, ax, ay = interpolated_ellipse(ft.radial[k], ft.levels, rho, s)
        _, _, ok = _dense_passing(q, st.film_z, rho, s, cx, ax, ay, 1.3, n)
        assert not ok.reshape(n, n)[[0, -1]].any() and not ok.reshape(n, n)[:, [0, -1]].any()  # the set lies inside
        dense = ok.sum() / n**2 * (2 * 1.3 * ax) * (2 * 1.3 * ay)
        assert area == pytest.approx(dense, rel=0.005), (k, rho)

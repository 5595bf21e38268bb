"""The pupil tables' rims found along lines from each film point's chief aim (physcam.export.blender_pupil_sets
._LineSets) against the oracle, physcam's tracer run the plain way on a dense grid of aims with the iris
stopped to each radius: on a prime (the double Gauss), a fisheye (the Nikkor 16 mm), a zoom (the Canon
70-200 at its long end), a lens whose sets other surfaces cut wide open (the Canon RF 85 at 1 m: clip
edges) and one whose film lies 1.0 mm behind its rear vertex (the ARRI Signature 58 mm: its chief aims found by
the window fan, round 20), every film radius node the lines serve and four iris radii from the widest to the
last level.

Tolerances. The area: the shader weighs a ray by the tabulated area only in the cells where the table's
reading matches the traced areas within AREA_TOLERANCE (0.4 %), which assumes the traced areas are the
dense trace's to well under that; the aim grids they replace were within 0.4 % (module notes) and the lines
are held to the same 0.4 % here. The ellipse: the shader draws aims only inside it, so a passing aim
outside is light lost; every dense passing aim must lie in the ellipse fitted to the rim (before the
table grows it to hold the interpolations, which only widens it)."""

from __future__ import annotations

import numpy as np
import pytest

from physcam.export.blender_pupil import AREA_TOLERANCE, _PassingSets, iris_levels
from physcam.export.blender_pupil_sets import _chief_aims, _fits, _rear_boxes
from physcam.lens.library import load_lens
from physcam.lens.zoom import prescription_at
from physcam.optics.focusing import focus

from _dense_pupil import passing_aims

pytestmark = pytest.mark.slow


def _dense(q, film_z, rho, s, box, n=300):
    """(area mm^2 both halves, passing aims x, y) of an n x n/2 grid of aims over box (x0, x1, y1), y >= 0."""
    x0, x1, y1 = box
    gx, gy = np.meshgrid(x0 + (np.arange(n) + 0.5) / n * (x1 - x0), (np.arange(n // 2) + 0.5) / (n // 2) * y1)
    gx, gy = gx.ravel(), gy.ravel()
    ok = passing_aims(q, film_z, rho, s, gx, gy)
    return 2 * ok.sum() / gx.size * (x1 - x0) * y1, gx[ok], gy[ok]


@pytest.mark.parametrize("name, zoom_u, distance_mm", [("dgauss_50mm", None, 2500.0),
                                                      ("nikkor_fisheye_16mm_f2_8", None, float("inf")),
                                                      ("canon_ef_70_200mm_f2_8_zoom", 1.0, 3000.0),
                                                      ("canon_rf_85mm_f1_2", None, 1000.0),
                                                      ("arri_signature_prime_58mm_ex1", None, float("inf"))])
def test_the_lines_rims_are_the_dense_traces(name, zoom_u, distance_mm):
    lens = load_lens(name)
    if zoom_u is not None:
        lens = prescription_at(lens, zoom_u)
    st = focus(lens, distance_mm)
    q, film_z = st.prescription, st.film_z
    semi = q.surfaces[q.stop_index].semi_diameter
    levels = iris_levels(semi * 1.03, semi)
    sets = _PassingSets(q, film_z, levels, "auto", lines=True)
    sets.need(levels)
    node = sets.lines.points < 37  # film radius nodes (1.22 mm apart) the lines serve
    served, first = sets.lines.points[node], sets.lines.first[node]
    assert served.size >= 12, served
    checked = []
    for p, i0 in list(zip(served, first))[:: max(1, served.size // 5)]:
        # the widest iris radius the lines serve there (other surfaces may cut the wider ones' sets: aim grids),
        # the last level and one halfway between
        last = np.flatnonzero(sets.radii == levels[-1])[0]
        for i in (i0, (i0 + last) // 2, last):
            s = sets.radii[i]
            k = sets.index[p, i]
            assert k >= 0
            x, y, _ = sets.rims.points([k])
            cx, ax, ay, area = _fits(sets.rims, np.array([k]))[0]
            pad = 0.25 * ax
            dense, ox, oy = _dense(q, film_z, sets.rhos[p], s, (cx - ax - pad, cx + ax + pad, ay + pad))
            assert ox.size > 1000
            assert area == pytest.approx(dense, rel=AREA_TOLERANCE), (name, sets.rhos[p], s)
            assert (((ox - cx) / ax) ** 2 + (oy / ay) ** 2 <= 1).all(), (name, sets.rhos[p], s)
            checked.append(area / dense - 1)
    print(name, f"largest area difference {max(np.abs(checked)):.4f} over {len(checked)} rims")


def test_where_the_stop_radius_flattens_toward_a_clip_the_lines_give_way():
    """The Angenieux f/1 focused at 342 mm, film radius 33.6 mm: along the lines toward the frame's edge the
    stop radius nearly stops rising before another surface cuts them (5.0 to 5.8 mm over the last samples),
    so a quadratic through the samples put the rim at iris radius 5.36 mm 5 % short of the dense trace's (the
    area 2 % short, 455 passing aims outside the ellipse). There the two quadratics about the rim disagree and
    the aim grids take that radius and every wider one; every radius the lines still serve is the dense
    trace's."""
    lens = load_lens("angenieux_us2701982_100mm_f1")
    st = focus(lens, 342.0)
    q, film_z = st.prescription, st.film_z
    semi = q.surfaces[q.stop_index].semi_diameter
    levels = iris_levels(semi * 1.03, semi)
    sets = _PassingSets(q, film_z, levels, "auto", finer=True, lines=True)
    fine = np.sort(np.concatenate([levels, np.sqrt(levels[:-1] * levels[1:])]))[::-1]
    sets.need(fine)
    p = int(np.argmin(np.abs(sets.rhos - 33.61)))
    (g,) = np.flatnonzero(sets.lines.points == p)
    first = sets.lines.first[g]
    assert sets.radii[first] < 5.36  # the doubted radius went to the grids
    for i in np.flatnonzero(np.isin(sets.radii, fine) & (np.arange(sets.radii.size) >= first))[::3]:
        s, k = sets.radii[i], sets.index[p, i]
        cx, ax, ay, area = _fits(sets.rims, np.array([k]))[0]
        dense, ox, oy = _dense(q, film_z, sets.rhos[p], s, (cx - 1.25 * ax, cx + 1.25 * ax, 1.25 * ay))
        assert area == pytest.approx(dense, rel=AREA_TOLERANCE), s
        assert (((ox - cx) / ax) ** 2 + (oy / ay) ** 2 <= 1).all(), s


@pytest.mark.parametrize("name, distance_mm", [("arri_signature_prime_58mm_ex1", float("inf")),
                                               ("sony_zeiss_55mm_f1_8_za", 1710.0),
                                               ("dgauss_50mm", 2500.0)])
def test_the_chief_aim_is_found_where_the_chief_ray_passes(name, distance_mm):
    """The lines start from each film point's chief aim (its ray crosses the stop's centre), found from a fan of
    41 meridional aims across the rear element. The ARRI Signature 58 mm's and the Sony Zeiss 55 mm's film lies
    1.0 mm behind the rear vertex: a film point's passing spot there is under one step of that fan (1.1 mm), at
    most one of its aims passes and none brackets the chief aim, so until round 20 none of their film points
    was on lines (every radius on aim grids, 7 grids a point off axis). Oracle: at every film radius node, a
    dense meridional fan (40,001 aims across the rear element's box, the iris stopped to 0.1 mm: the
    passing interval is then a few hundred aims wide on the double Gauss, about ten on the ARRI) finds a
    passing aim exactly where a chief aim is returned, and the ray toward it passes with the iris stopped to
    1e-6 mm (it crosses the stop at its centre). The double Gauss, whose fan brackets every chief aim, is
    the control: its chief aims are the fan's as before."""
    st = focus(load_lens(name), distance_mm)
    q, film_z = st.prescription, st.film_z
    rhos = np.arange(37) * 44.0 / 36
    boxes = _rear_boxes(q, film_z, rhos, q.surfaces[-1].semi_diameter)
    c, _ = _chief_aims(q, film_z, rhos, boxes, 20.0 * q.surfaces[q.stop_index].semi_diameter * 1.1, "auto")
    assert np.isfinite(c).sum() >= 20, c
    for rho, b, ck in zip(rhos, boxes, c):
        gx = np.linspace(b[0], b[1], 40001)
        lit = passing_aims(q, film_z, rho, 0.1, gx, np.zeros(gx.size)).any()
        assert lit == np.isfinite(ck), (name, rho, ck)
        if lit:
            assert passing_aims(q, film_z, rho, 1e-6, [ck], [0.0])[0], (name, rho, ck)

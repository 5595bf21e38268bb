"""The iris levels the extension's pupil tables add where the area's cubic in iris radius misses
(physcam.export.blender_pupil._refined_levels), and only inside the lens's image circle (_in_circle).
Oracles: an area that grows as the iris radius squared (the iris's image, no other surface cutting it),
which the shader's Hermite cubic between two levels (slopes 2 k s) and its Catmull-Rom cubic across film
radii (a constant) reproduce exactly, so the only miss is the one planted; and physcam's chief ray
(aim_from_film: aimed from the film through the stop's centre by Newton's method, clipped by every clear
aperture, as the lens cards' field_limit_deg is from the object side), a computation the tables do not use."""

from __future__ import annotations

import math

import numpy as np
import pytest

from physcam.export.blender_pupil import (AREA_TOLERANCE, N_RADIAL, RADIAL_MAX_MM, _check_axes, _in_circle,
                                         _refined_levels)

STEP = RADIAL_MAX_MM / (N_RADIAL - 1)
LEVELS = np.array([2.0, 1.6, 1.3])
K = 0.7  # the passing area is K s^2 (mm^2) at iris radius s, at every film radius


def _table():
    """A (levels, radii, 5) table of the area K s^2: cx, ax, ay (unused by the area), area, slope 2 K s."""
    t = np.zeros((len(LEVELS), N_RADIAL, 5))
    t[..., 1:3] = 1.0
    t[..., 3] = K * LEVELS[:, None] ** 2
    t[..., 4] = 2 * K * LEVELS[:, None]
    return t


def _checks(dark_from=math.inf, miss_at=None):
    """The traced areas at the table's check points (film radius x checked iris radius), K s^2, with nothing
    passing at the smallest iris checked from film radius ``dark_from`` on (the chief ray cut there) and the
    area 2 % over the cubic's (5 x AREA_TOLERANCE) at the first interval's middle at film radius ``miss_at``."""
    rhos, checked = _check_axes(LEVELS)
    want = K * np.tile(checked**2, (rhos.size, 1))
    want[rhos >= dark_from - 1e-9, -1] = 0.0
    mid = int(np.flatnonzero(np.isclose(checked, math.sqrt(LEVELS[0] * LEVELS[1])))[0])
    if miss_at is not None:
        row = int(np.flatnonzero(np.isclose(rhos, miss_at))[0])
        want[row, mid] *= 1 + 5 * AREA_TOLERANCE
    return want.ravel()


def _added(*checks):
    out = _refined_levels(LEVELS, [_table()] * len(checks), list(checks))
    return sorted(set(np.round(out, 12)) - set(np.round(LEVELS, 12)))


def test_an_area_the_cubic_reproduces_adds_no_level():
    assert _added(_checks()) == []
    assert _added(_checks(dark_from=20 * STEP)) == []


@pytest.mark.parametrize("miss_at", [0.0, 10 * STEP, 19.5 * STEP, 43 * STEP / 2])
def test_a_miss_inside_the_image_circle_adds_the_intervals_middle(miss_at):
    # the circle ends between film radii 21.5 and 22 steps: a miss on the cell that holds its edge counts too
    assert _added(_checks(dark_from=22 * STEP, miss_at=miss_at)) == [pytest.approx(math.sqrt(2.0 * 1.6))]
    assert _added(_checks(miss_at=miss_at)) == [pytest.approx(math.sqrt(2.0 * 1.6))]


@pytest.mark.parametrize("miss_at", [22.5 * STEP, 30 * STEP, RADIAL_MAX_MM])
def test_a_miss_outside_the_image_circle_adds_no_level(miss_at):
    """Round 10 added a level for a miss at any film radius up to RADIAL_MAX_MM; past where the chief ray
    is cut (here 22 steps, 26.9 mm) a stopped-down picture is black, and the miss adds nothing."""
    assert _added(_checks(dark_from=22 * STEP, miss_at=miss_at)) == []
    assert _added(_checks(miss_at=miss_at)) == [pytest.approx(math.sqrt(2.0 * 1.6))]  # a lens that covers it


def test_the_circle_is_the_smallest_of_the_lens_focus_marks():
    """A miss at 30 steps at a mark whose circle reaches past it counts only if every mark's does: the
    lens covers a sensor at every focus inside the smallest circle (the infinity mark's, for unit focusing)."""
    assert _added(_checks(dark_from=22 * STEP), _checks(dark_from=34 * STEP, miss_at=30 * STEP)) == []
    assert _added(_checks(dark_from=32 * STEP), _checks(dark_from=34 * STEP, miss_at=30 * STEP)) != []


def test_in_circle_by_hand():
    rhos = np.array([0.0, 0.5, 1.0, 1.5, 2.0, 2.5]) * STEP
    assert _in_circle(rhos, [True] * 6).all()
    # dark from 1.5 steps: the cell from node 1 to node 2 holds the edge, its checks up to node 2 count
    assert _in_circle(rhos, [True, True, True, False, False, False]).tolist() == [True] * 5 + [False]
    # dark from node 2: the cell from node 1 to 2 holds the edge
    assert _in_circle(rhos, [[True] * 6, [True] * 4 + [False] * 2]).tolist() == [True] * 5 + [False]


def _chief_ray_cut(q, film_z: float, up_to: float) -> float:
    """The first film radius (mm, every 0.02 mm from the axis to ``up_to``; inf if none) whose chief ray, aimed
    from the film through the stop's centre (physcam.analysis._chief.aim_from_film, Newton's method), does not
    pass every clear aperture."""
    from physcam.analysis._chief import aim_from_film
    from physcam.trace.rays import RayBatch
    from physcam.trace.trace import trace_through

    hs = np.arange(1, int(up_to / 0.02) + 1) * 0.02
    aimed = aim_from_film(q, np.stack([np.zeros(hs.size), hs], axis=1), film_z, wavelength_nm=q.wavelength_nm,
                          backend="numpy")
    ok = aimed.ok.copy()
    rays = trace_through(q, RayBatch.from_arrays(aimed.start[ok], aimed.direction[ok], q.wavelength_nm), reverse=True,
                         clip=True, backend="numpy")
    ok[ok] = rays.ok & (rays.N < 0)
    return float(hs[~ok].min()) if not ok.all() else math.inf


@pytest.mark.parametrize("slug", ["cooke_triplet_50mm_f4_5"])  # the double Gauss too (cut 27.04, dark 28.11 mm), 2 s
def test_the_circle_the_table_sees_is_where_the_chief_ray_is_cut(slug):
    """The first film radius where nothing passes at a table's smallest iris radius (half its last level) is
    where physcam's chief ray is cut (aimed through the stop's centre, clipped by every clear aperture: the
    lens card's image circle, field_limit_deg, seen from the film), at infinity focus: not before it, and
    within a film radius step (STEP, 1.22 mm) after it: half of it the checks' spacing, the rest the smallest
    iris's reach (rays up to 1/32 of the stop's radius from its centre still pass just past the chief ray's cut:
    the table's set is 1 % of its area 0.46 mm past the double Gauss's cut, 9 % 0.30 mm past the triplet's)."""
    from physcam.export.blender_pupil import iris_levels, radial_pupil_table
    from physcam.lens.library import load_lens
    from physcam.optics.state import camera_state
    from physcam.trace.camera_tracer import CameraTracer

    st = camera_state(load_lens(slug), focus_mm=math.inf)
    q = CameraTracer(st.focused, st.film_z).lens
    stop = q.surfaces[q.stop_index].semi_diameter
    levels = iris_levels(stop, stop)
    checks = []
    radial_pupil_table(q, st.film_z, levels, checks=checks)
    rhos, checked = _check_axes(levels)
    lit = checks[0].reshape(rhos.size, checked.size)[:, -1] > 0
    first_dark = rhos[~lit].min()
    cut = _chief_ray_cut(q, st.film_z, first_dark)
    print(f"{slug}: chief ray cut from {cut:.2f} mm, table's first dark film radius {first_dark:.2f} mm")
    assert lit[rhos < cut].all()
    assert cut <= first_dark <= cut + STEP

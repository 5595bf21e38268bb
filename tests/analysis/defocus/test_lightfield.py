"""Issue 13.4: raw light fields, sub-aperture views and refocusing behind a microlens array.

The camera: dgauss.50mm at f/5.6 focused at 0.8 m from the sensor, 77 x 77 thin lenslets of pitch
40 um and f = 0.224 mm (f/5.6: the sub-image of the exit pupil about fills a lenslet's 9 x 9 pixels).

Closed form of the disparity (worked by hand; the module docstring of physcam.analysis.defocus.lightfield
derives it): with the exit pupil D in front of the array, the sensor b = f_mu behind it and n
pixels per lenslet, a subject imaged D' behind the exit pupil shifts by -(D / (n b)) (1 - D/D')
lenslets from one sub-aperture view to the next. D and D' come from the paraxial (Gaussian) data of
the focused lens, physcam.optics.paraxial, tested against published values elsewhere.
"""

from __future__ import annotations

import numpy as np
import pytest

from physcam.analysis.defocus.lightfield import (checkerboard, light_field_figure, refocus, render_plane, render_planes,
                                         render_point, subaperture_views, view_disparity, view_mask)
from physcam.errors import InputError
from physcam.lens.library import load_lens
from physcam.optics.paraxial import gaussian
from physcam.trace.microlens import microlens_array, plenoptic_camera, subimage_centres

N_PX = 9
PITCH = 0.04
F_MU = 0.224


@pytest.fixture(scope="module")
def cam():
    a = microlens_array(77, 77, 77 * PITCH, 77 * PITCH, focal_length_mm=F_MU)
    return plenoptic_camera(load_lens("dgauss_50mm"), a, focus_mm=800.0, fstop=5.6, pixels_per_lenslet=N_PX)


def _closed_form_slope(cam, distance_mm):
    """-(D / (n b)) (1 - D / D'), D and D' from the exit pupil (paraxial), b = f_mu."""
    z0 = cam.z_sensor - distance_mm
    g = gaussian(cam.main, object_z=z0, film_z=cam.z_array)
    D = cam.z_array - g.z_exit_pupil
    Dp = g.z_image - g.z_exit_pupil
    return -(D / (N_PX * F_MU)) * (1.0 - D / Dp)


def _view_slopes(views, k=3):
    """The measured shift (lenslets per view step) of the light's centroid along the central row of
    views (x) and the central column (y)."""
    c = (views.shape[0] - 1) // 2
    u = np.arange(-k, k + 1)
    rows, cols = np.indices(views.shape[2:])
    xs = [(cols * views[c, c + i]).sum() / views[c, c + i].sum() for i in u]
    ys = [(rows * views[c + j, c]).sum() / views[c + j, c].sum() for j in u]
    return np.polyfit(u, xs, 1)[0], np.polyfit(u, ys, 1)[0]


def test_a_point_in_focus_lands_under_one_lenslet(cam):
    """A point 0.8 m from the sensor is imaged on the array's central lenslet (77 is odd: it sits
    on the axis): every ray that reaches the sensor lands in that lenslet's cell, and the light fills
    the exit pupil's image, a disk of diameter XP b / D (second moment d^2/8)."""
    lf = render_point(cam, 800.0, rays=200_000)
    raw = lf.raw
    ny, nx = raw.shape
    c0 = (nx - N_PX) // 2
    under = raw[c0:c0 + N_PX, c0:c0 + N_PX].sum()
    assert lf.rays_used > 50_000
    assert under / raw.sum() == pytest.approx(1.0, abs=1e-12)
    g = gaussian(cam.main, film_z=cam.z_array)
    stop = cam.main.surfaces[cam.main.stop_index].semi_diameter
    xp = g.exit_pupil_diameter * cam.stop_semi_diameter / stop
    D = cam.z_array - g.z_exit_pupil
    disk_px = xp * F_MU / D / (PITCH / N_PX)
    rr, cc = np.indices(raw.shape) + 0.5
    w = raw / raw.sum()
    cy, cx = (rr * w).sum(), (cc * w).sum()
    m2 = (((rr - cy) ** 2 + (cc - cx) ** 2) * w).sum() - 2.0 / 12.0  # minus the pixels' own variance
    assert (cx, cy) == pytest.approx((nx / 2, ny / 2), abs=0.02)
    assert np.sqrt(8.0 * m2) == pytest.approx(disk_px, rel=0.03)


@pytest.mark.slow
def test_views_of_points_at_two_depths_shift_by_the_closed_form(cam):
    """A point nearer than the focus (0.5 m) and one farther (5 m): their sub-aperture views shift
    in opposite directions by -(D / (n b)) (1 - D/D') lenslets per view step, within 3 % each (the
    real lens's spherical aberration is the rest) and 2 % on their difference."""
    near, far = (render_point(cam, d, rays=300_000) for d in (500.0, 5000.0))
    measured = []
    for lf in (near, far):
        sx, sy = _view_slopes(subaperture_views(cam, lf.raw))
        assert sx == pytest.approx(sy, rel=0.01)  # the same in x and y
        measured.append((sx + sy) / 2)
    expected = [_closed_form_slope(cam, d) for d in (500.0, 5000.0)]
    assert expected[0] < -1.0 and expected[1] > 1.0  # opposite ways, over a lenslet per view
    assert measured[0] == pytest.approx(expected[0], rel=0.03)
    assert measured[1] == pytest.approx(expected[1], rel=0.03)
    assert measured[0] - measured[1] == pytest.approx(expected[0] - expected[1], rel=0.02)
    assert view_disparity(cam, 500.0) == pytest.approx(expected[0], rel=1e-12)
    assert view_disparity(cam, 800.0) == pytest.approx(0.0, abs=1e-9)


@pytest.mark.slow
def test_refocusing_is_sharpest_at_the_subjects_disparity(cam):
    """Shift-and-add over the views: the near point's refocused image is most compact (least second
    moment) at the slope the closed form gives for its distance, and a lenslet or so wide there."""
    views = subaperture_views(cam, render_point(cam, 500.0, rays=300_000).raw)
    rows, cols = np.indices(views.shape[2:])

    def spread(s):
        im = refocus(views, s, mask=view_mask(cam))
        w = im / im.sum()
        cy, cx = (rows * w).sum(), (cols * w).sum()
        return (((rows - cy) ** 2 + (cols - cx) ** 2) * w).sum()

    slopes = np.linspace(-2.2, 0.0, 45)
    best = slopes[int(np.argmin([spread(s) for s in slopes]))]
    assert best == pytest.approx(view_disparity(cam, 500.0), abs=0.1)
    sharp = spread(view_disparity(cam, 500.0))
    assert sharp < 1.0 and spread(0.0) > 8 * sharp  # sharp, against the array's own focus


def test_plane_in_focus_central_view_is_the_board_upside_down(cam):
    """A checkerboard 0.8 m from the sensor, in focus on the array: the central view (one pixel per
    lenslet) shows the board, rotated 180 degrees like any film image: its grey top-left square
    lands bottom-right."""
    board = checkerboard(4, 8)  # 4 x 4 squares, grey top-left
    g = gaussian(cam.main, object_z=cam.z_sensor - 800.0, film_z=cam.z_array)
    width = 77 * PITCH / abs(g.magnification) * 0.9  # the board fills 90 % of the array
    lf = render_plane(cam, board, 800.0, width, spp=2)
    v = subaperture_views(cam, lf.raw)[N_PX // 2, N_PX // 2]
    n = v.shape[0]
    q = n // 8  # sample the middle of each square (each square is ~ 0.9 n / 4 lenslets)
    centres = [int(n / 2 + (k - 1.5) * 0.9 * n / 4) for k in range(4)]
    seen = np.array([[v[r - q // 2:r + q // 2 + 1, c - q // 2:c + q // 2 + 1].mean() for c in centres]
                     for r in centres])
    expected = np.array([[board[8 * i + 4, 8 * j + 4] for j in range(4)] for i in range(4)])[::-1, ::-1]
    bright = seen.max()
    assert seen / bright == pytest.approx(expected, abs=0.08)


def test_nearer_plane_hides_the_farther(cam):
    """Occlusion: a white plane in front of a grey one; where both are behind a pixel, it sees white."""
    white, grey = np.ones((4, 4)), np.full((4, 4), 0.5)
    lf = render_planes(cam, [(grey, 3000.0, 2000.0), (white, 800.0, 500.0)], spp=1)
    only_grey = render_plane(cam, grey, 3000.0, 2000.0, spp=1)
    c = lf.raw.shape[0] // 2
    centre = slice(c - 20, c + 21)
    assert lf.raw[centre, centre].mean() == pytest.approx(2.0 * only_grey.raw[centre, centre].mean(), rel=0.05)


def test_bad_inputs_are_refused(cam, tmp_path):
    with pytest.raises(InputError):
        render_point(cam, 10.0)  # inside the camera
    with pytest.raises(InputError):
        render_point(cam, 800.0, rays=0)
    with pytest.raises(InputError):
        render_plane(cam, "board", 800.0, 100.0)
    with pytest.raises(InputError):
        render_plane(cam, np.full((2, 2), np.nan), 800.0, 100.0)
    with pytest.raises(InputError):
        subaperture_views(cam, np.zeros((5, 5)))
    with pytest.raises(InputError):
        refocus(np.zeros((3, 3, 4)), 0.5)
    with pytest.raises(InputError):
        refocus(np.zeros((3, 3, 4, 4)), float("nan"))


def test_figure_is_written(cam, tmp_path):
    lf = render_point(cam, 500.0, rays=20_000)
    path = light_field_figure(lf, refocus_slopes=[("at 0.5 m", view_disparity(cam, 500.0))], path=tmp_path / "lf.png")
    assert path.stat().st_size > 1000


def test_subimage_centres_drift_outward_as_c_times_1_plus_b_over_d(cam):
    """Thin lenslets: the exit pupil's centre seen through lenslet c lands at c (1 + b / D)."""
    cx, cy = subimage_centres(cam)
    g = gaussian(cam.main, film_z=cam.z_array)
    m = 1.0 + F_MU / (cam.z_array - g.z_exit_pupil)
    lx, ly = cam.array.centres(*np.meshgrid(np.arange(77), np.arange(77)))
    assert cx == pytest.approx(lx * m, abs=1e-12) and cy == pytest.approx(ly * m, abs=1e-12)

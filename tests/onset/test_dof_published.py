"""Depth of field against published figures and hand-worked closed forms."""

import math

import pytest

from physcam.optics import dof, thinlens

FT = 304.8
IN = 25.4


def test_dofmaster_50mm_f4_10ft():
    # DOFMaster (dofmaster.com) example: 50 mm, f/4, subject 10 ft, c = 0.03 mm:
    # near 8 ft 9 in, far 11 ft 8 in (DOFMaster measures the subject distance from the lens).
    near, far = dof.dof_limits(50.0, 4.0, 0.03, 10 * FT)
    assert near == pytest.approx(8 * FT + 9 * IN, abs=0.5 * IN)
    assert far == pytest.approx(11 * FT + 8 * IN, abs=0.5 * IN)


def test_army_field_manual_hyperfocal():
    # The US Army field manual figure quoted in issue 2 (hand-worked here, as the manual itself was
    # not at hand): a 2-inch (50 mm class) lens at f/8 with a
    # 0.002 in circle of confusion has a hyperfocal distance of about 20.8 ft, the f^2/(N c)
    # figure: (2 in)^2 / (8 x 0.002 in) = 250 in = 20.83 ft. physcam's H adds f.
    f = 2 * IN
    H = dof.hyperfocal_distance(f, 8.0, 0.002 * IN)
    assert (H - f) / FT == pytest.approx(20.83, abs=0.01)
    assert H / FT == pytest.approx(20.83 + 2 / 12, abs=0.01)


def test_hyperfocal_focus_gives_infinite_far_and_half_near():
    # Exact forms: focused at H = h + f, the far limit is infinite and the near limit is H/2.
    f, N, c = 35.0, 11.0, 0.03
    H = dof.hyperfocal_distance(f, N, c)
    near, far = dof.dof_limits(f, N, c, H)
    assert math.isinf(far)
    assert near == pytest.approx(H / 2, rel=1e-12)


def test_seed_error_far_limit_reaches_infinity_at_H_not_H_plus_f():
    # Seed 000 pairs H = f^2/(Nc) + f with forms expecting h: its far limit became infinite
    # at s = h + 2f. The exact far limit is finite just inside H = h + f.
    f, N, c = 18.0, 16.0, 0.03
    H = dof.hyperfocal_distance(f, N, c)
    _, far = dof.dof_limits(f, N, c, H - 1.0)
    assert math.isfinite(far)
    _, far = dof.dof_limits(f, N, c, H)
    assert math.isinf(far)


def test_hand_worked_near_far():
    # f = 100, N = 2, c = 0.05 -> h = 100^2/(0.1) = 100000; s = 10000:
    # near = h s / (h + s - f) = 1e9 / 109900 = 9099.181..., far = 1e9 / 90100 = 11098.779...
    near, far = dof.dof_limits(100.0, 2.0, 0.05, 10000.0)
    assert near == pytest.approx(1e9 / 109900.0, rel=1e-12)
    assert far == pytest.approx(1e9 / 90100.0, rel=1e-12)


def test_focus_from_bracket_is_harmonic_mean():
    # 1/near + 1/far = 2/s: 2 * 3000 * 6000 / 9000 = 4000
    assert dof.focus_for_dof_limits(3000.0, 6000.0) == pytest.approx(4000.0)
    assert dof.focus_for_dof_limits(3000.0, math.inf) == pytest.approx(6000.0)


def test_macro_one_to_one():
    # Marked 4f from the film: s = s' = 2f, magnification 1 (Hecht 5.2.3).
    s = thinlens.object_distance_for_marked(50.0, 200.0)
    assert s == pytest.approx(100.0)
    assert thinlens.magnification(50.0, s) == pytest.approx(1.0)
    # 1:2 macro: s = 3f = 150, s' = 1.5 f = 75, mark = 225
    s = thinlens.object_distance_for_marked(50.0, 225.0)
    assert s == pytest.approx(150.0)
    assert thinlens.magnification(50.0, s) == pytest.approx(0.5)


def test_fov_full_frame_50mm():
    # 36 mm wide, 50 mm: 2 atan(0.36) = 39.5978 degrees (standard lens tables quote 39.6)
    assert math.degrees(thinlens.field_of_view(36.0, 50.0)) == pytest.approx(39.5978, abs=1e-4)
    # focused at 1:1 the film sits 2f behind: field narrows to 2 atan(36/200)
    assert math.degrees(thinlens.field_of_view(36.0, 50.0, 100.0)) == pytest.approx(
        math.degrees(2 * math.atan(0.18)), abs=1e-9)


@pytest.mark.parametrize("bad", [-1.0, 0.0])
def test_inside_focal_length_refused(bad):
    from physcam import OpticsError

    with pytest.raises(OpticsError):
        dof.dof_limits(50.0, 2.0, 0.03, 50.0 + bad)

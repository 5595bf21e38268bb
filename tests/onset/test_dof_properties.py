"""Hypothesis properties of the DOF forms and their inversions."""

import math

from hypothesis import assume, given, settings
from hypothesis import strategies as st

from physcam.optics import dof

focal = st.floats(8.0, 300.0)
fnum = st.floats(1.0, 32.0)
coc = st.floats(0.005, 0.06)


@given(focal, fnum, coc, st.floats(1.5, 200.0))
def test_near_focus_far_ordered(f, N, c, k):
    s = f * k * 2
    near, far = dof.dof_limits(f, N, c, s)
    assert 0 < near < s < far


@given(focal, fnum, coc, st.floats(2.0, 100.0), st.floats(1.01, 2.0))
def test_dof_grows_with_fstop(f, N, c, k, r):
    s = f * k * 2
    n1, f1 = dof.dof_limits(f, N, c, s)
    n2, f2 = dof.dof_limits(f, N * r, c, s)
    assert n2 <= n1 and f2 >= f1
    assert (f2 - n2) > (f1 - n1) or math.isinf(f2)


@given(focal, fnum, coc, st.floats(2.0, 100.0))
@settings(max_examples=200)
def test_fstop_round_trip_from_near(f, N, c, k):
    s = f * k * 2
    near, far = dof.dof_limits(f, N, c, s)
    h = dof.hyperfocal_parameter_from_near(f, s, near)
    assert math.isclose(dof.f_number_for_dof(f, c, h), N, rel_tol=1e-7)
    assert math.isclose(dof.coc_for_dof(f, N, h), c, rel_tol=1e-7)
    if math.isfinite(far):
        assume(far < 1e12)
        assert math.isclose(dof.focus_for_dof_limits(near, far), s, rel_tol=1e-7)

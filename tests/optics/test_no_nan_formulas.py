"""Every public formula of physcam.optics answers with a number or a PhysCamError (trust review,
issue 24 item 7: 205 of 3,910 random calls answered NaN or raised ZeroDivisionError, ValueError or
OverflowError; ``thinlens.image_distance(50, inf)`` was NaN, not 50).

Each function is called with every combination hypothesis draws from typical values, 0, negative
numbers, infinities, NaN, the largest and smallest floats. The answer must be a finite number (or a
documented infinity: a far limit, a subject at infinity), or a PhysCamError; never NaN, never another
exception.
"""

from __future__ import annotations

import inspect
import math

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from physcam.errors import PhysCamError
from physcam.onset import pupil
from physcam.optics import coc, dof, thinlens

FUNCTIONS = ([getattr(m, n) for m in (thinlens, dof) for n in m.__all__ if callable(getattr(m, n))]
             + [coc.circle_of_confusion, pupil.entrance_pupil_practical, pupil.pivot_camera_space])
#: (function, index of the result) that may be +inf, and when
MAY_BE_INFINITE = {("dof_limits", 1), ("object_distance_for_marked", 0)}

NUMBERS = st.one_of(
    st.floats(min_value=0.01, max_value=1e5),  # the values people give
    st.sampled_from([0.0, -1.0, -50.0, math.inf, -math.inf, math.nan, 1e308, 5e-324, 1e-320, 2.0, 50.0, 3000.0]),
    st.floats(allow_nan=True, allow_infinity=True),
)


def _results(out):
    return out if isinstance(out, tuple) else (out,)


@pytest.mark.parametrize("fn", FUNCTIONS, ids=lambda f: f.__name__)
@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(data=st.data())
def test_a_number_or_a_physcam_error(fn, data):
    params = [p for p in inspect.signature(fn).parameters.values() if p.default is p.empty]
    args = [data.draw(NUMBERS, label=p.name) for p in params]
    try:
        out = fn(*args)
    except PhysCamError:
        return
    for i, v in enumerate(_results(out)):
        if isinstance(v, str):  # circle_of_confusion's convention name
            continue
        v = float(v)
        assert not math.isnan(v), f"{fn.__name__}{tuple(args)} gave NaN"
        if math.isinf(v):
            assert (fn.__name__, i) in MAY_BE_INFINITE and v > 0, f"{fn.__name__}{tuple(args)} gave {v}"


def test_arrays_too():
    """The formulas broadcast: one bad element of an array is the same clear error."""
    with pytest.raises(PhysCamError):
        dof.hyperfocal_distance(np.array([50.0, 35.0]), np.array([2.8, 0.0]), 0.03)
    near, far = dof.dof_limits(50.0, 2.8, 0.03, np.array([3000.0, math.inf]))
    assert np.isfinite(near).all() and far[1] == math.inf


def test_the_reviews_examples_worked_by_hand():
    assert thinlens.image_distance(50.0, math.inf) == 50.0  # the focal plane
    assert thinlens.magnification(50.0, math.inf) == 0.0
    assert thinlens.object_distance_for_marked(50.0, math.inf) == math.inf
    with pytest.raises(PhysCamError, match="f-number must be above 0"):
        dof.hyperfocal_distance(50.0, 0.0, 0.025)
    # focused at infinity, the near limit is h = f^2 / (N c) itself (and h from it recovers h)
    h = 50.0 ** 2 / (2.8 * 0.03)
    assert dof.dof_limits(50.0, 2.8, 0.03, math.inf)[0] == pytest.approx(h, rel=1e-12)
    assert dof.hyperfocal_parameter_from_near(50.0, math.inf, h) == pytest.approx(h, rel=1e-12)

"""The anamorphic lenses' exit-pupil rectangles (physcam.export.blender_focus._rect_tables) traced at a quarter of
the film nodes and mirrored, against physcam's pupil bounds traced at every node (physcam.trace.pupil_bounds
.stopped_pupil_bounds, the same aims and window search): a prescription is symmetric about the planes x = 0 and
y = 0, so the two agree to the rounding of the aims' places (mm; 5e-15 measured on the three anamorphics of the
extension's tests at every traced focus mark), and the same nodes are empty."""

from __future__ import annotations

import numpy as np
import pytest

from physcam.export.blender_focus import GRID_HALF_MM, STOP_LEVELS, _rect_tables
from physcam.lens.library import load_lens
from physcam.optics.focusing import closest_focus, focus
from physcam.trace.camera_tracer import CameraTracer

pytestmark = pytest.mark.slow


@pytest.mark.parametrize("name, near", [("panavision_rear_anamorphic_1_3x", True), ("navarro_anamorphic_2x", False)])
def test_the_mirrored_rectangles_are_the_whole_grids(name, near):
    lens = load_lens(name)
    st = focus(lens, closest_focus(lens) * 1.0001 if near else float("inf"))
    tracer = CameraTracer(st.prescription, st.film_z)
    semi_file = tracer.lens.surfaces[tracer.lens.stop_index].semi_diameter
    semi_max = 1.03 * semi_file
    b, rects, stopped = _rect_tables(tracer, semi_max, GRID_HALF_MM)
    whole = tracer.stopped_pupil_bounds([float(semi_file * (f * semi_max / semi_file)) for f in (1.0,) + STOP_LEVELS],
                                        GRID_HALF_MM, GRID_HALF_MM, nx=9, ny=9, samples=48)
    assert np.array_equal(b.xs, whole[0].xs) and np.array_equal(b.ys, whole[0].ys)
    for got, want in zip([rects, *stopped], [w.rects for w in whole]):
        assert ((got[..., 1] > got[..., 0]) == (want[..., 1] > want[..., 0])).all()
        assert (want[..., 1] > want[..., 0]).sum() > 20
        np.testing.assert_allclose(got, want, rtol=0, atol=1e-12)

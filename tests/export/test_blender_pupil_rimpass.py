"""The compiled rim pass of the extension's pupil tables (physcam.trace.kernels._rimpass, picked by
physcam.trace.kernels.rim_pass when the tables trace with numba) finds the rims the numpy pass finds
(physcam.export.blender_pupil_sets._rims, the reference that tests/export/test_blender_pupil*.py hold against
dense traces): the same points in the same order, so the same areas, ellipses and trust, on a lens's real
aim grids. Both run in this process on the same grids, IEEE arithmetic without contraction on both sides,
so the comparison is exact: any difference is a different point, not rounding."""

from __future__ import annotations

import numpy as np
import pytest

from physcam.export.blender_pupil import _PassingSets, iris_levels
from physcam.export.blender_pupil_sets import _grid_rims
from physcam.lens.library import load_lens
from physcam.optics.focusing import focus
from physcam.trace.kernels import numba_available, rim_pass

pytestmark = pytest.mark.skipif(not numba_available(), reason="numba is not installed")


@pytest.mark.parametrize("name, distance_mm", [("dgauss_50mm", 2500.0), ("canon_rf_85mm_f1_2", 1000.0)])
def test_the_compiled_rims_are_the_numpy_passs_bit_for_bit(name, distance_mm):
    """Every rim at every radius the sets are traced at (the first call of a table), then a random half of
    them (a later call, which finds only the rims not found yet): the double Gauss, unit focusing, and the
    Canon RF 85 wide open (cat's eyes: other surfaces clip, so the halved clip edges are read too)."""
    lens = load_lens(name)
    st = focus(lens, distance_mm)
    q = st.prescription
    levels = iris_levels(q.surfaces[q.stop_index].semi_diameter * 1.05, q.surfaces[q.stop_index].semi_diameter)
    sets = _PassingSets(q, st.film_z, levels, "numba")
    everything = np.ones((sets.rhos.size, sets.radii.size), dtype=bool)
    half = np.random.default_rng(5).random(everything.shape) < 0.5
    for wanted in (everything, half):
        (i_np, r_np), (i_nb, r_nb) = (_grid_rims(sets.grids, sets.radii, wanted, sets.rhos.size, b)
                                      for b in ("numpy", "numba"))
        assert (i_np == i_nb).all()
        for field in ("x", "y", "cuts", "area"):
            a, b = getattr(r_np, field), getattr(r_nb, field)
            assert a.shape == b.shape and a.tobytes() == b.tobytes(), field
        assert r_np.x.size > 10_000 and (r_np.area > 0).sum() > 100  # real rims, not two empty sets
    assert sets.grids[4][0].size > 100  # halved clip edges: other surfaces cut the sets


def test_the_compiled_pass_is_picked_only_where_the_tables_trace_with_numba():
    assert rim_pass("numpy") is None
    assert rim_pass("numba") is not None

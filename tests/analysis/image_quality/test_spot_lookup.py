"""The spot's edge refinement looks a level's cells up in a dense table of its grid (issue 47, round 21: the
default spot's bookkeeping 49 -> 40 ms with the C kernel), or by binary search of sorted keys where that grid
is too large (``DENSE_CELLS``). The two are independent lookups of the same cells: with ``dense_cells=0``
every level takes the sorted keys (what every level did before), and both must give the same samples, ray for
ray, on beams whose edges cross the grid everywhere (a pass/fail pattern made here, with holes, per field).
(Real lenses' spots: their rays, weights and --json hashed equal to main's, the round's notes; the refinement's
own rule is checked against a dense reference in test_spot_clipped.py.)
"""

import numpy as np
import pytest

from physcam.analysis.image_quality.spot import _refined_samples
from physcam.trace import CLIPPED, OK


def _pattern(f, u, v):
    """A beam per field: an off-centre ellipse with a ring cut out and a bar across (edges in every direction)."""
    cx = 0.1 * f
    r2 = ((u - cx) / 0.9) ** 2 + (v / 0.7) ** 2
    ok = (r2 < 1.0) & ~((r2 > 0.25) & (r2 < 0.36)) & ~(np.abs(v - 0.2 * f + 0.1) < 0.03)
    return np.where(ok, OK, CLIPPED).astype(np.uint8), u + f, v


@pytest.mark.parametrize("rings, refine, fields", [(6, 4, 1), (9, 5, 3), (16, 3, 2), (5, 7, 2)])
def test_dense_and_sorted_lookups_give_the_same_samples(rings, refine, fields):
    dense = _refined_samples(_pattern, rings, refine, fields)
    sparse = _refined_samples(_pattern, rings, refine, fields, dense_cells=0)
    assert len(dense) == len(sparse) == fields
    for a, b in zip(dense, sparse):
        for x, y in zip(a, b):
            assert np.array_equal(x, y)
    assert sum(w.size for w, *_ in dense) > fields * 3 * rings * rings  # the edges were refined


"""RayBatch owns writable arrays whatever it is built from (issue 8: `bokeh --rays 1` crashed in
the JIT kernel on a read-only one-ray column from a broadcast start point)."""

import numpy as np
import pytest

from physcam.lens.library import load_lens
from physcam.trace import RayBatch, trace_to_film


@pytest.mark.parametrize("n", [1, 2, 7])
@pytest.mark.parametrize("backend", ["numba", "numpy"])
def test_broadcast_start_points_trace(n, backend):
    src = np.array([0.0, 0.0, -1000.0])
    d = np.tile([0.0, 0.0, 1.0], (n, 1))
    rays = RayBatch.from_arrays(np.broadcast_to(src, (n, 3)), d)
    assert all(c.flags.writeable and c.flags.c_contiguous for c in rays.columns())
    out = trace_to_film(load_lens("dgauss_50mm"), rays, backend=backend)
    # an axial ray from 1 m in front of the lens images on the axis
    assert out.ok.all() and np.allclose(out.x, 0.0) and np.allclose(out.y, 0.0)

"""The compiled rim passes of the extension's pupil tables (the C pass, physcam/trace/kernels/_rimpass.c, and numba's,
physcam.trace.kernels._rimpass; picked by physcam.trace.kernels.rim_pass) find the rims the numpy pass finds
(physcam.export.blender_pupil_sets._rims, the reference that tests/export/test_blender_pupil*.py hold against
dense traces): the same points in the same order, so the same areas, ellipses and trust, on a lens's real
aim grids, on made grids at the edge cases (nothing passing, everything passing, passing only on the grid's
edge, several rims per grid, every clip-edge branch) and on random grids (hypothesis). All run in this process
on the same grids, IEEE arithmetic without contraction on every side, so the comparison is exact: any
difference is a different point, not rounding. A compiled pass this install lacks is skipped, with the reason.
(The zip the same bytes whichever pass runs: tests/export/test_blender_extension_build.py, the pooled build.)"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from physcam.export.blender_pupil import _PassingSets, iris_levels
from physcam.export.blender_pupil_sets import _GRID, _TOWARD, _grid_rims, _n_passing, _rims, _rims_compiled
from physcam.lens.library import load_lens
from physcam.optics.focusing import focus
from physcam.trace import kernels
from physcam.trace.kernels import c_available, numba_available, rim_pass

needs_c = pytest.mark.skipif(not c_available(), reason="the C kernel (and its rim pass) is not built")
needs_numba = pytest.mark.skipif(not numba_available(), reason="numba is not installed")
#: the compiled passes, by the backend that picks them
PASSES = [pytest.param("c", marks=needs_c), pytest.param("numba", marks=needs_numba)]


def _same_rims(a, b):
    """The two _RimSets hold the same points, cuts and areas, byte for byte."""
    for field in ("x", "y", "cuts", "area"):
        u, v = getattr(a, field), getattr(b, field)
        assert u.shape == v.shape and u.tobytes() == v.tobytes(), field


_SETS: dict = {}


def _sets(name, distance_mm):
    """A lens's passing sets at its own iris levels (traced once a session: the grids, not the pass, cost)."""
    if name not in _SETS:
        lens = load_lens(name)
        st_ = focus(lens, distance_mm)
        q = st_.prescription
        levels = iris_levels(q.surfaces[q.stop_index].semi_diameter * 1.05, q.surfaces[q.stop_index].semi_diameter)
        _SETS[name] = _PassingSets(q, st_.film_z, levels, "c" if c_available() else "numpy")
    return _SETS[name]


@pytest.mark.parametrize("compiled", PASSES)
@pytest.mark.parametrize("name, distance_mm", [("dgauss_50mm", 2500.0), ("canon_rf_85mm_f1_2", 1000.0)])
def test_the_compiled_rims_are_the_numpy_passs_bit_for_bit(name, distance_mm, compiled):
    """Every rim at every radius the sets are traced at (the first call of a table), then a random half of
    them (a later call, which finds only the rims not found yet): the double Gauss, unit focusing, and the
    Canon RF 85 wide open (cat's eyes: other surfaces clip, so the halved clip edges are read too)."""
    sets = _sets(name, distance_mm)
    everything = np.ones((sets.rhos.size, sets.radii.size), dtype=bool)
    half = np.random.default_rng(5).random(everything.shape) < 0.5
    for wanted in (everything, half):
        (i_np, r_np), (i_c, r_c) = (_grid_rims(sets.grids, sets.radii, wanted, sets.rhos.size, b)
                                    for b in ("numpy", compiled))
        assert (i_np == i_c).all()
        _same_rims(r_np, r_c)
        assert r_np.x.size > 10_000 and (r_np.area > 0).sum() > 100  # real rims, not two empty sets
    assert sets.grids[4][0].size > 100  # halved clip edges: other surfaces cut the sets


def test_the_compiled_pass_follows_the_tracers_backend(monkeypatch):
    """"numpy" (and PHYSCAM_BACKEND=numpy) takes the numpy pass; "c" the C pass; "numba" numba's; "auto" the C pass
    where it is built (no JIT code to load), else numba's once numba is loaded, else the numpy pass."""
    assert rim_pass("numpy") is None
    monkeypatch.setenv("PHYSCAM_BACKEND", "numpy")
    assert rim_pass("auto") is None
    if c_available():
        c_pass = kernels._load_c()._C.rim_points
        assert rim_pass("c") is c_pass
        monkeypatch.setenv("PHYSCAM_BACKEND", "c")
        assert rim_pass("auto") is c_pass
        monkeypatch.delenv("PHYSCAM_BACKEND")
        assert rim_pass("auto") is c_pass
    if numba_available():
        assert rim_pass("numba") not in (None, rim_pass("c") if c_available() else None)
        monkeypatch.setenv("PHYSCAM_BACKEND", "numba")
        assert rim_pass("auto") is rim_pass("numba")


# ---- made grids: the numpy pass against each compiled one -------------------------------------------------------

NY, NX = _GRID // 2, _GRID
RADII = np.array([3.0, 2.5, 2.0, 1.5, 1.0, 0.5])  # descending, as the tables' iris radii


def _uses(oks, rads, radii, ranges):
    """The ``uses`` of blender_pupil_sets._rims (grid of _trace, first and end radius index) for grids of these
    pass flags and stop radii (grids x NY x NX), on boxes of their own (x0, y0 and the steps differ per grid)."""
    uses = []
    for g, (ok, rad, (r0, r1)) in enumerate(zip(oks, rads, ranges)):
        dx, dy = 0.37 + 0.011 * g, 0.29 - 0.007 * g
        x0, y0 = -6.1 + 0.5 * g, 0.5 * dy
        gx = np.broadcast_to(x0 + np.arange(NX) * dx, (NY, NX)).ravel()
        gy = np.broadcast_to((y0 + np.arange(NY) * dy)[:, None], (NY, NX)).ravel()
        ok, rad = ok.ravel(), rad.ravel()
        n_in = _n_passing(radii, np.where(ok, rad, np.inf)).astype(np.int16)
        uses.append(((gx, gy, ok, rad, dx, dy, 0.0, n_in), r0, r1))
    return uses


def _edges(uses, rng):
    """A clip edge (key, passing and clipped fractions, stop radius at the last passing point) for every pair of
    a passing sample and a clipped neighbour (blender_pupil_sets._clip_edges' keys, of made fractions: stop radii
    under, over and exactly at an iris radius, so both branches of the rim point and the boundary between are
    taken)."""
    okg = np.stack([u[0][2] for u in uses]).reshape(-1, NY, NX)
    keys = []
    for d, (ca, cb, _) in enumerate(_TOWARD):
        g, jj, ii = np.nonzero(okg[(slice(None),) + ca] & ~okg[(slice(None),) + cb])
        keys.append((g * 3 + d) * (NY * NX) + jj * NX + ii)
    key = np.sort(np.concatenate(keys)).astype(np.int64)
    lo = rng.choice([0.0, 0.25, 0.5, 0.9375], key.size)
    r_lo = np.where(rng.random(key.size) < 0.5, rng.choice(RADII, key.size), rng.uniform(0.5, 3.0, key.size))
    return key, lo, lo + 0.0625, r_lo


def _check(uses, radii, wanted, edges, compiled):
    """The compiled pass's rims (``rim_pass(compiled)``) are the numpy pass's, byte for byte; the numpy rims."""
    ref = _rims(uses, edges, radii, wanted)
    got = _rims_compiled(uses, edges, radii, wanted, rim_pass(compiled))
    _same_rims(ref, got)
    return ref


def _disk(centre_x, r_clip=np.inf):
    """Pass flags and stop radii of a disk-like set: the stop radius grows with the distance from (centre_x, 0),
    and samples past ``r_clip`` of it are clipped by another surface."""
    j, i = np.mgrid[0:NY, 0:NX]
    d = np.hypot(i - centre_x, j) * 0.2
    return d < r_clip, d


@pytest.mark.parametrize("compiled", PASSES)
def test_made_grids_edge_cases(compiled):
    """Nothing passing (every rim empty), everything passing (only the grid's edge makes points: a step out),
    passing only on the grid's edge (its three sides), and several rims a grid over three grids with their own
    radius ranges, cat's eyes among them (clip edges on both branches); each at every radius and at some."""
    rng = np.random.default_rng(47)
    none = (np.zeros((NY, NX), dtype=bool), np.full((NY, NX), 9.0))
    every = (np.ones((NY, NX), dtype=bool), np.full((NY, NX), 0.25))
    rim = np.zeros((NY, NX), dtype=bool)
    rim[:, 0] = rim[:, -1] = rim[-1, :] = True
    edge = (rim, np.where(rim, 1.25, 9.0))
    disk, cats = _disk(NX / 2), _disk(NX / 3, r_clip=2.2)
    cases = {  # name: (grids, each one's radius range, expected rims with points at every radius)
        "nothing passes": ([none, none], [(0, 6), (2, 4)], 0),
        "everything passes": ([every], [(0, 6)], 6),
        "the grid's edge": ([edge], [(1, 5)], 3),  # stop radius 1.25: it passes at 3.0, 2.5, 2.0, 1.5
        "several rims": ([disk, cats, edge], [(0, 6), (1, 4), (0, 6)], None),
    }
    for name, (grids, ranges, n_full) in cases.items():
        uses = _uses([g[0] for g in grids], [g[1] for g in grids], RADII, ranges)
        edges = _edges(uses, rng)
        for wanted in (np.ones((len(grids), RADII.size), dtype=bool), rng.random((len(grids), RADII.size)) < 0.5):
            rims = _check(uses, RADII, wanted, edges, compiled)
            full = np.diff(rims.cuts) > 0
            assert full.size == sum(r1 - r0 for r0, r1 in ranges), name
            if n_full is not None and wanted.all():
                assert full.sum() == n_full, name
        if name == "several rims":
            assert full.sum() > 4 and edges[0].size > 50  # rims on every grid, clip edges read


@needs_c
def test_no_grids_have_no_rims():
    """The C pass on zero grids (a table whose every film point the lines serve): no points, one cut at 0."""
    c = kernels._load_c()._C
    z = np.zeros(0)
    zi = np.zeros(0, dtype=np.int64)
    pts, cuts = c.rim_points(np.zeros((0, NY, NX), dtype=bool), np.zeros((0, NY, NX)), np.zeros((0, NY, NX), dtype=np.int64),
                             z, z, z, z, zi, zi, zi, np.zeros((0, RADII.size), dtype=bool), RADII, zi, z, z, z, 0)
    assert pts.shape == (0, 4) and cuts.tolist() == [0]


@needs_c
def test_the_c_pass_refuses_what_would_index_past_its_arrays():
    """A pair toward a clipped neighbour whose clip edge is not in the table (the numpy pass's IndexError), and a
    radius range past the radii, are errors, not reads or writes past an array."""
    c = kernels._load_c()._C
    ok, rad = _disk(NX / 3, r_clip=2.2)
    uses = _uses([ok], [rad], RADII, [(0, 6)])
    ok = np.stack([u[0][2] for u in uses]).reshape(-1, NY, NX)
    rad = np.stack([u[0][3] for u in uses]).reshape(-1, NY, NX)
    n_in = np.stack([u[0][7] for u in uses]).reshape(-1, NY, NX).astype(np.int64)
    f, i = (lambda *v: np.array(v, dtype=float)), (lambda *v: np.array(v, dtype=np.int64))
    wanted, e = np.ones((1, RADII.size), dtype=bool), np.zeros(0)
    with pytest.raises(IndexError, match="clip edge"):
        c.rim_points(ok, rad, n_in, f(0), f(0), f(1), f(1), i(0), i(6), i(0), wanted, RADII, i(), e, e, e, 6)
    with pytest.raises(ValueError, match="radius indices"):
        c.rim_points(ok, rad, n_in, f(0), f(0), f(1), f(1), i(0), i(7), i(0), wanted, RADII, i(), e, e, e, 7)
    with pytest.raises(ValueError, match="float64"):
        c.rim_points(ok, rad.astype(np.float32), n_in, f(0), f(0), f(1), f(1), i(0), i(6), i(0), wanted, RADII, i(), e,
                     e, e, 6)


@needs_c
@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), n_grids=st.integers(1, 3), p_ok=st.floats(0.0, 1.0),
       on_radii=st.booleans())
def test_random_grids_give_the_numpy_rims(seed, n_grids, p_ok, on_radii):
    """Random grids (pass flags at any density, stop radii random or exactly on the iris radii, where a rim point's
    fraction is 0, -0.0 or NaN, as np.clip keeps them), random radius ranges and wanted rims: the C pass's rims
    (and numba's, where installed) are the numpy pass's, byte for byte."""
    rng = np.random.default_rng(seed)
    oks = rng.random((n_grids, NY, NX)) < p_ok
    rads = rng.choice(RADII, (n_grids, NY, NX)) if on_radii else rng.uniform(0.2, 3.5, (n_grids, NY, NX))
    ranges = [tuple(sorted(rng.integers(0, RADII.size + 1, 2))) for _ in range(n_grids)]
    uses = _uses(oks, rads, RADII, ranges)
    wanted, edges = rng.random((n_grids, RADII.size)) < 0.7, _edges(uses, rng)
    for compiled in ("c", "numba") if numba_available() else ("c",):
        _check(uses, RADII, wanted, edges, compiled)

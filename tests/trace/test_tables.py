"""Packed surface tables are cached safely, and the compiled-kernel cache is keyed by version and sources."""

import gc
import hashlib
import os
from dataclasses import replace

import numpy as np
import pytest

import physcam
from physcam.lens.library import load_lens
from physcam.trace import RayBatch, trace_through
from physcam.trace.kernels import get_kernel
from physcam.trace.kernels._layout import ETA, N1, N2, pack, set_wavelength
from physcam.trace.surfaces import surface_table
from physcam.trace import tables
from physcam.trace.tables import clear_table_cache, packed_table
from physcam.trace.trace import trace_packed


def test_the_cached_table_is_the_packed_surface_table():
    lens = load_lens("canon_rf_85mm_f1_2")
    for kw in (dict(), dict(reverse=True), dict(stop_semi_diameter=5.0, coating="multi")):
        p = packed_table(lens, **kw)
        S, kinds = pack(surface_table(lens, **kw))
        np.testing.assert_array_equal(p.S, S)
        np.testing.assert_array_equal(p.kinds, kinds)
        W = S.copy()
        set_wavelength(W, 486.1327)
        np.testing.assert_array_equal(p.at_wavelength(486.1327), W)


def test_keys_separate_what_changes_the_table_and_share_what_does_not():
    clear_table_cache()  # identity below: no table of this lens evicted by earlier tests
    lens = load_lens("dgauss_50mm")
    p = packed_table(lens)
    assert packed_table(lens) is p
    twin = replace(lens)  # an equal prescription, another object: found by value
    assert twin is not lens and twin == lens
    assert packed_table(twin) is p
    others = [packed_table(lens, reverse=True), packed_table(lens, stop_semi_diameter=4.0),
              packed_table(lens, coating="single"), packed_table(lens, dtype=np.float32)]
    assert len({id(o) for o in others + [p]}) == 5
    assert packed_table(lens, dtype=np.float32).S.dtype == np.float32
    # None means the lens file's coating: the same table as naming it
    assert packed_table(lens, coating=None) is packed_table(lens, coating="none")


def test_a_new_lens_never_gets_a_dead_lens_table(monkeypatch):
    """ids of freed objects are reused by CPython: the weak reference must tell them apart. The cache
    keeps one lens here (with its 64 none of the 40 lenses this test made was ever freed, so no id
    came back and the test passed with the weak-reference check taken out), so each lens frees the
    one before it and some get its id (2-18 of 40 in five runs): each must still get its own table.
    The heap the session made before is frozen (``gc.freeze``): each collection looks at this test's
    objects only (40 full collections of a whole session's heap were this test's 11 s)."""
    monkeypatch.setattr(tables, "MAX_LENSES", 1)
    clear_table_cache()
    base = load_lens("dgauss_50mm")
    seen, reused = set(), 0
    gc.freeze()
    try:
        for k in range(200):
            s = list(base.surfaces)
            s[0] = replace(s[0], thickness=3.0 + 0.01 * k)
            surfaces = tuple(s)
            packed_table(base)  # takes the cache's one place: the lens before is freed here
            lens = replace(base, surfaces=surfaces)
            reused += id(lens) in seen
            seen.add(id(lens))
            p = packed_table(lens)
            np.testing.assert_array_equal(p.table.vertex_z, np.asarray(lens.vertex_z))
            del lens, p, surfaces
            gc.collect()
    finally:
        gc.unfreeze()
        clear_table_cache()
    assert reused > 0  # the case under test happened


def test_tracing_does_not_modify_a_table():
    lens = load_lens("dgauss_50mm")
    S, kinds = pack(surface_table(lens))
    S0 = S.copy()
    rays = RayBatch.collimated([0.0, 1.0], [2.0, 3.0], -1.0)
    trace_packed(get_kernel("auto"), rays, S, kinds, clip=True, fresnel=True, end_z=70.0)
    np.testing.assert_array_equal(S, S0)
    p = packed_table(lens)
    W = p.at_wavelength(rays.wavelength_nm[0]).copy()
    trace_through(lens, rays, end_z=70.0, fresnel=True)
    np.testing.assert_array_equal(p.at_wavelength(rays.wavelength_nm[0]), W)
    assert np.isnan(p.S[:, [N1, N2, ETA]]).sum() == 0  # the base table stays without indices (zeros)


def test_repeated_calls_give_the_answer_of_a_fresh_table():
    lens = load_lens("navarro_anamorphic_2x")
    rng = np.random.default_rng(5)
    rays = RayBatch.from_arrays(np.c_[rng.uniform(-5, 5, (50, 2)), np.full(50, -3.0)],
                                np.c_[rng.normal(0, 0.05, (50, 2)), np.ones(50)], 610.0)
    first = trace_through(lens, rays, end_z=200.0, fresnel=True, backend="numpy")
    S, kinds = pack(surface_table(lens))
    fresh = trace_packed(get_kernel("numpy"), rays.copy(), S, kinds, clip=True, fresnel=True, end_z=200.0)
    again = trace_through(lens, rays, end_z=200.0, fresnel=True, backend="numpy")
    for a, b, c in zip(first.columns(), fresh.columns(), again.columns()):
        np.testing.assert_array_equal(a, b)
        np.testing.assert_array_equal(a, c)


def test_jit_cache_is_keyed_by_version_and_every_kernel_source():
    pytest.importorskip("numba")
    from physcam.trace.kernels import _jitcache, _numba

    here = os.path.dirname(_jitcache.__file__)
    h = hashlib.sha256(f"physcam {physcam.__version__}\n".encode())
    for name in sorted(os.listdir(here)):
        if name.endswith(".py"):
            h.update(name.encode())
            with open(os.path.join(here, name), "rb") as f:
                h.update(hashlib.sha256(f.read()).digest())
    assert _jitcache.source_stamp() == h.hexdigest()
    # the kernels' cache uses physcam's locator, so its index carries that stamp (numba ignores an
    # index whose stamp differs: code from another version or source is recompiled, never loaded)
    cache = _numba.variant(True, False, False, False)._cache
    assert type(cache._impl.locator).__name__ == "PhysCamLocator"
    assert cache._cache_file._source_stamp == _jitcache.source_stamp()
    assert "_layout.py" in os.listdir(here)  # the column layout is part of the stamp

"""No NaN or inf leaves the tracer: every ray flagged OK has finite position, direction and
weights, and a lost ray has weight 0 (issue 8, item 9). Lenses from the bundled library, rays
from anywhere, including extreme and degenerate starts; both kernels."""

import math
from functools import lru_cache

import numpy as np
import pytest
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

from physcam.errors import InputError
from physcam.lens.library import list_lenses, load_lens
from physcam.trace import OK, RayBatch, camera_rays, trace_through, trace_to_film
from physcam.trace.kernels import c_available, get_kernel
from physcam.trace.kernels._layout import pack
from physcam.trace.surfaces import surface_table
from physcam.trace.trace import trace_packed

SLUGS = [r.slug for r in list_lenses()]
BACKENDS = ["numba", "numpy"] + (["c"] if c_available() else [])  # the C kernel where built
EXTREME = [0.0, -0.0, 1e-300, -1e-300, 5e-324, 1e-160, 1e154, -1e154, 1e200, -1e300, 1.7e308, -1.7e308]


@lru_cache(maxsize=None)
def lens(slug):
    return load_lens(slug)


def coord(scale=60.0):
    return st.one_of(st.floats(-scale, scale), st.sampled_from(EXTREME),
                     st.floats(allow_nan=False, allow_infinity=False))


def check(out):
    ok = out.flag == OK
    for a in (out.x, out.y, out.z, out.L, out.M, out.N, out.weight, out.weight_sp):
        assert np.isfinite(a[ok]).all()
    assert (out.weight[~ok] == 0).all() and (out.weight_sp[~ok] == 0).all()
    # every ray keeps finite numbers, lost or not (a lost ray keeps its last finite state)
    for a in (out.x, out.y, out.z, out.L, out.M, out.N):
        assert np.isfinite(a).all()
    # the s and p throughputs stay between 0 and the starting weight (1 here)
    assert (out.weight_s[ok] >= -1e-12).all() and (out.weight_p[ok] >= -1e-12).all()


SETTINGS = settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])


@SETTINGS
@given(slug=st.sampled_from(SLUGS), backend=st.sampled_from(BACKENDS),
       rays=st.lists(st.tuples(coord(), coord(), coord(200.0), coord(1.0), coord(1.0), coord(1.0),
                               st.floats(380.0, 780.0)), min_size=1, max_size=8),
       reverse=st.booleans(), clip=st.booleans(), fresnel=st.booleans(),
       end=st.one_of(st.none(), coord(300.0)))
def test_trace_through_any_ray_is_finite_or_flagged(slug, backend, rays, reverse, clip, fresnel, end):
    r = np.array(rays)
    assume((np.abs(r[:, 3:6]).max(axis=1) > 0).all())
    batch = RayBatch.from_arrays(r[:, :3], r[:, 3:6], r[:, 6])
    assert np.isfinite(np.column_stack([batch.L, batch.M, batch.N])).all()
    np.testing.assert_allclose(batch.L**2 + batch.M**2 + batch.N**2, 1.0, rtol=0, atol=1e-12)
    out = trace_through(lens(slug), batch, reverse=reverse, clip=clip, fresnel=fresnel, end_z=end,
                        coating="single", backend=backend)
    check(out)


@SETTINGS
@given(slug=st.sampled_from(SLUGS), backend=st.sampled_from(BACKENDS),
       xy=st.lists(st.tuples(coord(), coord(), coord(0.5), coord(0.5)), min_size=1, max_size=8),
       wl=st.floats(380.0, 780.0), fresnel=st.booleans())
def test_trace_to_film_any_ray_is_finite_or_flagged(slug, backend, xy, wl, fresnel):
    p = np.array(xy)
    L = lens(slug)
    batch = RayBatch.from_arrays(np.column_stack([p[:, 0], p[:, 1], np.full(len(p), -5.0)]),
                                 np.column_stack([p[:, 2], p[:, 3], np.ones(len(p))]), wl)
    out = trace_to_film(L, batch, L.vertex_z[-1] + 40.0, fresnel=fresnel, backend=backend)
    check(out)


@SETTINGS
@given(slug=st.sampled_from(SLUGS), backend=st.sampled_from(BACKENDS),
       film=st.lists(st.tuples(coord(), coord(), st.floats(0, 1), st.floats(0, 1)), min_size=1, max_size=8),
       gap=st.one_of(st.floats(1e-6, 200.0), st.sampled_from([1e-300, 1e-160, 5e-324, 1e200])),
       fresnel=st.booleans())
def test_camera_rays_any_sample_is_finite_or_flagged(slug, backend, film, gap, fresnel):
    L = lens(slug)
    f = np.array(film)
    film_z = L.vertex_z[-1] + gap
    assume(film_z > L.vertex_z[-1])
    cam = camera_rays(L, f[:, :2], f[:, 2:], film_z, fresnel=fresnel, backend=backend)
    check(cam.lens_rays)
    assert np.isfinite(cam.origin[cam.ok]).all() and np.isfinite(cam.direction[cam.ok]).all()
    assert np.isfinite(cam.weight).all()


@pytest.mark.parametrize("backend", BACKENDS)
def test_degenerate_batches_built_by_hand_are_flagged(backend):
    # RayBatch's constructor does not validate (from_arrays does): NaN, inf, a zero direction,
    # a zero or NaN wavelength and an infinite weight must all come out flagged with weight 0.
    nan, inf = math.nan, math.inf
    cols = np.array([
        # x,   y,    z,    L,   M,   N,   wl,     w
        [0.0, 1.0, -5.0, 0.0, 0.0, 1.0, 587.56, 1.0],  # a good ray
        [nan, 1.0, -5.0, 0.0, 0.0, 1.0, 587.56, 1.0],
        [0.0, inf, -5.0, 0.0, 0.0, 1.0, 587.56, 1.0],
        [0.0, 1.0, -5.0, 0.0, 0.0, 0.0, 587.56, 1.0],  # zero direction
        [0.0, 1.0, -5.0, 0.0, nan, 1.0, 587.56, 1.0],
        [0.0, 1.0, -5.0, 0.0, 0.0, 1.0, 0.0, 1.0],  # zero wavelength
        [0.0, 1.0, -5.0, 0.0, 0.0, 1.0, nan, 1.0],
        [0.0, 1.0, -5.0, 0.0, 0.0, 1.0, 587.56, inf],
    ])
    n = len(cols)
    lens_ = lens("dgauss_50mm")
    for mono in (True, False):
        c = cols.copy()
        if not mono:
            c[0, 6] = 550.0
        batch = RayBatch(*(np.ascontiguousarray(c[:, k]) for k in range(8)), flag=np.zeros(n, dtype=np.uint8))
        out = trace_through(lens_, batch, end_z=80.0, fresnel=True, backend=backend)
        assert out.flag[0] == OK and out.weight[0] > 0
        assert (out.flag[1:] != OK).all() and (out.weight[1:] == 0).all()
        # no surface rows at all, only the end plane (how trace_path finishes)
        S, kinds = pack(surface_table(lens_))
        empty = trace_packed(get_kernel(backend), batch.copy(), S[:0], kinds[:0], clip=True, fresnel=False,
                             end_z=80.0)
        assert empty.flag[0] == OK and (empty.flag[1:] != OK).all() and (empty.weight[1:] == 0).all()


def test_from_arrays_normalises_huge_and_tiny_directions():
    b = RayBatch.from_arrays([[0, 0, 0], [0, 0, 0]], [[1e300, 1e300, 0.0], [3e-310, 0.0, 4e-310]])
    np.testing.assert_allclose(b.L, [math.sqrt(0.5), 0.6], rtol=1e-12)
    np.testing.assert_allclose(b.M, [math.sqrt(0.5), 0.0], rtol=1e-12)
    np.testing.assert_allclose(b.N, [0.0, 0.8], rtol=1e-12)
    with pytest.raises(InputError):
        RayBatch.from_arrays([[0, 0, 0]], [[0.0, 0.0, 0.0]])
    with pytest.raises(InputError):
        RayBatch.from_arrays([[0, math.inf, 0]], [[0.0, 0.0, 1.0]])


@SETTINGS
@given(slug=st.sampled_from(SLUGS),
       rays=st.lists(st.tuples(coord(), coord(), coord(200.0), coord(1.0), coord(1.0), coord(1.0),
                               st.floats(380.0, 780.0)), min_size=1, max_size=8),
       clip=st.booleans(), fresnel=st.booleans())
def test_both_kernels_flag_extreme_rays_alike(slug, rays, clip, fresnel):
    r = np.array(rays)
    assume((np.abs(r[:, 3:6]).max(axis=1) > 0).all())
    batch = RayBatch.from_arrays(r[:, :3], r[:, 3:6], r[:, 6])
    b = trace_through(lens(slug), batch, clip=clip, fresnel=fresnel, end_z=250.0, backend="numpy")
    for be in BACKENDS[:1] + BACKENDS[2:]:  # each compiled kernel against the numpy kernel
        a = trace_through(lens(slug), batch, clip=clip, fresnel=fresnel, end_z=250.0, backend=be)
        np.testing.assert_array_equal(a.flag, b.flag)
        for u, v in zip(a.columns()[:9], b.columns()[:9]):
            np.testing.assert_allclose(u, v, rtol=1e-12, atol=1e-9)

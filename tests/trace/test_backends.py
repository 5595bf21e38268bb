"""The numba and numpy kernels give the same rays; properties that hold for any ray."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from physcam.errors import BackendError
from physcam.lens.prescription import Medium, Prescription, Surface
from physcam.trace import RayBatch, trace_through, trace_to_film
from physcam.trace.kernels import c_available as kernels_c_available
from physcam.trace.kernels import resolve_backend

from _trace_lenses import DGAUSS_ROWS, build_pbrt

ABBE = [47.0, 0, 47.0, 30.0, 0, 0, 38.0, 57.0, 0, 48.0, 0]


def mixed_lens():
    """A made-up lens exercising every surface kind (asphere, conic, cylinders, flat, stop)."""
    return Prescription(
        (
            Surface(40.0, 4.0, Medium(1.62, 58.0), 14.0, "aspheric", conic=-0.5, aspheric=(-1e-5, 2e-8)),
            Surface(-120.0, 2.0, Medium(), 14.0, "aspheric", conic=3.0),
            Surface(0.0, 3.0, Medium(), 9.0, "stop"),
            Surface(60.0, 3.0, Medium(1.7, 30.0), 11.0, "cylindrical_x"),
            Surface(0.0, 2.0, Medium(1.5, 64.0), 11.0, "flat"),
            Surface(-80.0, 30.0, Medium(), 11.0, "cylindrical_y"),
        )
    )


def random_rays(n, seed, spread=16.0):
    rng = np.random.default_rng(seed)
    p = np.stack([rng.uniform(-spread, spread, n), rng.uniform(-spread, spread, n), np.full(n, -3.0)], axis=1)
    d = np.stack([rng.normal(0, 0.15, n), rng.normal(0, 0.15, n), np.ones(n)], axis=1)
    return RayBatch.from_arrays(p, d, rng.uniform(420, 680, n))


@pytest.mark.parametrize("lens_factory", [lambda: build_pbrt(DGAUSS_ROWS, abbe=ABBE), mixed_lens])
@pytest.mark.parametrize("fresnel", [False, True])
def test_numba_and_numpy_agree(lens_factory, fresnel):
    lens = lens_factory()
    rays = random_rays(3000, 11)
    kw = dict(end_z=80.0, fresnel=fresnel, coating="single", chunk_size=1000)
    a = trace_through(lens, rays, backend="numba", **kw)
    b = trace_through(lens, rays, backend="numpy", **kw)
    np.testing.assert_array_equal(a.flag, b.flag)
    assert 0 < a.ok.sum() < len(rays)  # some pass, some are lost
    for u, v in zip(a.columns()[:9], b.columns()[:9]):  # weight_sp too
        np.testing.assert_allclose(u, v, rtol=0, atol=1e-12)


def test_monochrome_fast_path_matches_per_ray_indices():
    lens = build_pbrt(DGAUSS_ROWS, abbe=ABBE)
    rays = random_rays(500, 3, spread=10.0)
    rays.wavelength_nm[:] = 486.1327
    mono = trace_through(lens, rays, end_z=70.0, fresnel=True)  # one wavelength: precomputed indices
    rays.wavelength_nm[-1] = 500.0  # now two wavelengths: per-ray indices
    mixed = trace_through(lens, rays, end_z=70.0, fresnel=True)
    for u, v in zip(mono.columns()[:6], mixed.columns()[:6]):
        np.testing.assert_array_equal(u[:-1], v[:-1])


def test_unknown_backend_is_refused():
    with pytest.raises(BackendError):
        resolve_backend("cuda")


@settings(max_examples=40, deadline=None)
@given(
    x=st.floats(-30, 30), y=st.floats(-30, 30), l=st.floats(-0.6, 0.6), m=st.floats(-0.6, 0.6),
    wl=st.floats(380, 760), backend=st.sampled_from(["numba", "numpy"]),
)
def test_any_ray_comes_out_finite_unit_and_flagged(x, y, l, m, wl, backend):
    lens = mixed_lens()
    rays = RayBatch.from_arrays([[x, y, -3.0]], [[l, m, 1.0]], wl)
    out = trace_through(lens, rays, end_z=60.0, fresnel=True, backend=backend)
    for a in out.columns()[:8]:
        assert np.isfinite(a).all()
    assert abs(out.L[0] ** 2 + out.M[0] ** 2 + out.N[0] ** 2 - 1.0) < 1e-12
    assert 0.0 <= out.weight[0] <= 1.0
    assert (out.weight[0] == 0.0) == (out.flag[0] != 0)


@settings(max_examples=30, deadline=None)
@given(h=st.floats(0.0, 10.0), phi=st.floats(0, 6.2831), wl=st.floats(420, 680))
def test_rotational_symmetry_of_a_spherical_lens(h, phi, wl):
    # A rotationally symmetric lens maps a ray at (h, 0) and the same ray rotated by phi to
    # image points related by the same rotation.
    lens = build_pbrt(DGAUSS_ROWS, abbe=ABBE)
    rays = RayBatch.collimated([h, h * np.cos(phi)], [0.0, h * np.sin(phi)], -1.0, wavelength_nm=wl)
    out = trace_to_film(lens, rays, 68.0)
    assert out.flag[0] == out.flag[1]
    if out.flag[0] == 0:
        assert out.x[1] == pytest.approx(out.x[0] * np.cos(phi), abs=1e-9)
        assert out.y[1] == pytest.approx(out.x[0] * np.sin(phi), abs=1e-9)


@pytest.mark.skipif(not kernels_c_available(), reason="the C kernel is not built")
@settings(max_examples=30, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), n=st.integers(1, 700), mixed=st.booleans(), clip=st.booleans(),
       reverse=st.booleans(), lens_factory=st.sampled_from([lambda: build_pbrt(DGAUSS_ROWS, abbe=ABBE), mixed_lens]))
def test_the_c_kernel_gives_the_numpy_kernels_rays_bit_for_bit(seed, n, mixed, clip, reverse, lens_factory):
    """Any rays (positions past the rims, steep directions, one wavelength or each ray's own, forward or
    reversed, clipped or not) through a lens of every surface kind: the C kernel's flags, positions,
    directions, both Fresnel weights and optical paths are the numpy reference's bit for bit (the C kernel
    keeps its order of operations and contracts nothing; docs/ray-tracing.md, "Three kernels")."""
    from physcam.trace.kernels import get_kernel
    from physcam.trace.tables import packed_table
    from physcam.trace.trace import trace_packed

    lens = lens_factory()
    rng = np.random.default_rng(seed)
    z0, sign = (-3.0, 1.0) if not reverse else (lens.vertex_z[-1] + 3.0, -1.0)
    p = np.stack([rng.uniform(-25, 25, n), rng.uniform(-25, 25, n), np.full(n, z0)], axis=1)
    d = np.stack([rng.normal(0, 0.4, n), rng.normal(0, 0.4, n), np.full(n, sign)], axis=1)
    rays = RayBatch.from_arrays(p, d, rng.uniform(380, 760, n) if mixed else 587.6)
    table = packed_table(lens, reverse=reverse, coating="single")
    out = []
    for backend in ("c", "numpy"):
        r = rays.copy()
        opl = np.zeros(n)
        trace_packed(get_kernel(backend), r, table.S, table.kinds, clip=clip, fresnel=True,
                     end_z=-40.0 if reverse else 80.0, opl=opl)
        out.append(r.columns() + (opl,))
    for u, v in zip(*out):
        np.testing.assert_array_equal(u, v)


def test_the_c_backend_names_the_fix_when_it_is_not_built(monkeypatch):
    """Asked for by name where the extension was not built (an install from source without a C compiler):
    one BackendError that says how to get it and which backends give the same rays meanwhile."""
    from physcam.trace import kernels

    monkeypatch.setattr(kernels, "_c_kernel", None)
    monkeypatch.setattr(kernels, "_c_error", "ModuleNotFoundError: No module named 'physcam.trace.kernels._ckernel'")
    with pytest.raises(BackendError, match=r"not built in this install.*C compiler.*backend='numpy'"):
        kernels.resolve_backend("c")
    monkeypatch.setenv("PHYSCAM_BACKEND", "c")
    with pytest.raises(BackendError, match="not built"):
        kernels.get_kernel("auto")


def _dgauss_rays(n, seed=7):
    lens = build_pbrt(DGAUSS_ROWS, abbe=ABBE)
    rng = np.random.default_rng(seed)
    p = np.stack([rng.uniform(-10, 10, n), rng.uniform(-10, 10, n), np.full(n, -3.0)], axis=1)
    d = np.stack([rng.normal(0, 0.1, n), rng.normal(0, 0.1, n), np.ones(n)], axis=1)
    return lens, RayBatch.from_arrays(p, d, 587.6)


@pytest.mark.skipif(not kernels_c_available(), reason="the C kernel is not built")
def test_a_forked_child_traces_after_its_parent_traced_on_threads(monkeypatch):
    """A process that traced a large batch on threads (the C kernel's pool, "auto" in the core install) and then
    forks (multiprocessing's default on Linux before Python 3.14): the child has none of the parent's trace
    threads, so the pool it copied must not be used: it traces on its own and gets the parent's rays. Before
    the fork hook the child waited for ever on the first threaded batch (round 21's review)."""
    import os
    import signal

    from physcam.trace import kernels

    if not hasattr(os, "fork"):
        pytest.skip("no fork on this platform")
    monkeypatch.setattr(kernels, "LOAD_AWARE", False)
    kernels.set_threads(2)
    try:
        lens, rays = _dgauss_rays(100_000)
        parent = trace_through(lens, rays.copy(), backend="c")
        assert kernels._pool is not None  # the batch went through the thread pool
        pid = os.fork()
        if pid == 0:  # the child: a second threaded batch, within 20 s or SIGALRM ends it
            code = 1
            try:
                signal.alarm(20)
                child = trace_through(lens, rays.copy(), backend="c")
                code = 0 if all(np.array_equal(u, v) for u, v in zip(child.columns(), parent.columns())) else 3
            finally:
                os._exit(code)
        _, status = os.waitpid(pid, 0)
        assert os.WIFEXITED(status) and os.WEXITSTATUS(status) == 0, f"the forked child ended with status {status}"
    finally:
        kernels.set_threads(None)


def test_the_reported_kernel_follows_physcam_backend(monkeypatch):
    """``loaded_backend`` (what ``python -m physcam.trace.kernels`` prints as "auto") names the kernel a forced
    ``PHYSCAM_BACKEND`` traces with, and refuses a name tracing would refuse."""
    from physcam.trace import kernels

    monkeypatch.setenv("PHYSCAM_BACKEND", "numpy")
    assert kernels.loaded_backend() == "numpy"
    monkeypatch.setenv("PHYSCAM_BACKEND", "bogus")
    with pytest.raises(BackendError, match="PHYSCAM_BACKEND='bogus'"):
        kernels.loaded_backend()


def test_auto_traces_a_float32_optical_path_as_the_numpy_kernel_does(monkeypatch):
    """An optical path array in float32 (the C kernel adds float64 only): "auto" gives it to the numpy kernel,
    which traces it as before the C kernel, instead of raising."""
    from physcam.trace.kernels import get_kernel
    from physcam.trace.tables import packed_table
    from physcam.trace.trace import trace_packed

    monkeypatch.delenv("PHYSCAM_BACKEND", raising=False)
    lens, rays = _dgauss_rays(2000)
    table = packed_table(lens, coating="single")
    out = []
    for backend in ("auto", "numpy"):
        r, opl = rays.copy(), np.zeros(2000, np.float32)
        trace_packed(get_kernel(backend), r, table.S, table.kinds, clip=True, fresnel=False, end_z=80.0, opl=opl)
        out.append(r.columns() + (opl,))
    for u, v in zip(*out):
        np.testing.assert_array_equal(u, v)

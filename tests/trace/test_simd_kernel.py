"""The blocked kernels, the numba JIT kernel and the compiled C kernel, against the numpy reference; their
serial and parallel paths; the JIT kernel's machine code; the C kernel's instruction sets and float32 against
the JIT kernel's; single precision against double (docs/ray-tracing.md, "The SIMD kernel", "Three kernels")."""

import platform
import re

import numpy as np
import pytest

from physcam.lens.library import list_lenses, load_lens
from physcam.trace import RayBatch, camera_rays, paraxial_image_z, trace_through
from physcam.trace.kernels import c_available, numba_available

needs_numba = pytest.mark.skipif(not numba_available(), reason="numba is not installed")
needs_c = pytest.mark.skipif(not c_available(), reason="the C kernel is not built")
#: the blocked kernels held to the numpy reference, each skipped where this install lacks it
COMPILED = [pytest.param("numba", marks=needs_numba), pytest.param("c", marks=needs_c)]

SLUGS = [r.slug for r in list_lenses()]
EPS = np.finfo(np.float64).eps


def random_rays(lens, n, seed, mixed):
    rng = np.random.default_rng(seed)
    sd = lens.surfaces[0].semi_diameter
    p = np.stack([rng.uniform(-1.2 * sd, 1.2 * sd, n), rng.uniform(-1.2 * sd, 1.2 * sd, n), np.full(n, -2.0)], axis=1)
    d = np.stack([rng.normal(0, 0.2, n), rng.normal(0, 0.2, n), np.ones(n)], axis=1)
    return RayBatch.from_arrays(p, d, rng.uniform(400, 700, n) if mixed else 550.0)


@pytest.mark.parametrize("backend", COMPILED)
@pytest.mark.parametrize("slug", SLUGS)
def test_geometry_is_bitwise_the_reference_and_fresnel_weights_within_a_few_ulps(slug, backend):
    # The geometry keeps IEEE semantics in the same order of operations as the numpy kernel, so
    # flags, positions and directions are identical; only the JIT kernel's Fresnel weights are contracted
    # to FMA: each surface's update then differs by a few units in the last place (relative 1e-15 per
    # surface), here bounded by 4 eps per surface. The C kernel contracts nothing (built with
    # -ffp-contract=off): its weights are the reference's bit for bit.
    lens = load_lens(slug)
    nsurf = len(lens.surfaces)
    for mixed, reverse in ((False, False), (True, False), (True, True)):
        rays = random_rays(lens, 1500, 7, mixed)
        if reverse:
            rays.z[:] = lens.vertex_z[-1] + 2.0
            rays.N[:] *= -1.0
        kw = dict(reverse=reverse, end_z=-50.0 if reverse else lens.vertex_z[-1] + 40.0, fresnel=True,
                  coating="single")
        a = trace_through(lens, rays, backend=backend, **kw)
        b = trace_through(lens, rays, backend="numpy", **kw)
        np.testing.assert_array_equal(a.flag, b.flag)
        for u, v in zip(a.columns()[:6], b.columns()[:6]):
            np.testing.assert_array_equal(u, v)
        for u, v in zip((a.weight, a.weight_sp), (b.weight, b.weight_sp)):
            if backend == "c":
                np.testing.assert_array_equal(u, v)
            else:
                np.testing.assert_allclose(u, v, rtol=4 * nsurf * EPS, atol=4 * nsurf * EPS)


@pytest.mark.parametrize("backend", COMPILED)
def test_serial_and_parallel_paths_agree_bit_for_bit_at_block_edges(backend):
    """Serial and threaded runs of a batch (block ranges on two threads, whatever the cores this process may
    use: set_threads) give identical rays at every block edge."""
    from physcam.trace import kernels
    from physcam.trace.kernels import c_kernel, jit_kernel
    from physcam.trace.tables import packed_table

    kernels.set_threads(2)  # threaded even where this process may use one core
    try:
        _serial_and_parallel(backend, c_kernel, jit_kernel, packed_table)
    finally:
        kernels.set_threads(None)


def _serial_and_parallel(backend, c_kernel, jit_kernel, packed_table):

    jit = jit_kernel() if backend == "numba" else c_kernel()
    BLOCK = 256  # both kernels' block (_numba.BLOCK, _ckernel.BLOCK)

    lens = load_lens("canon_rf_85mm_f1_2")  # aspheres: Newton iterations per block
    p = packed_table(lens)
    for n in (0, 1, BLOCK - 1, BLOCK, BLOCK + 1, 3 * BLOCK + 17):
        rays = random_rays(lens, n, n, True)
        outs = []
        for serial_below in (1 << 40, 0):
            r = rays.copy()
            opl = np.zeros(n)
            jit(*r.columns(), p.S, p.kinds, True, True, 120.0, True, False, serial_below, opl)
            outs.append((r, opl))
        for u, v in zip(outs[0][0].columns() + (outs[0][1],), outs[1][0].columns() + (outs[1][1],)):
            np.testing.assert_array_equal(u, v)


@pytest.mark.parametrize("backend", COMPILED)
@pytest.mark.parametrize("mixed", [False, True])
def test_blocks_whose_rays_all_stopped_end_as_the_reference(mixed, backend):
    """A block whose every ray has stopped leaves the surface loop early (no pass changes a stopped lane):
    blocks of rays that all miss the first surface's rim, or all stop at a later one, among live blocks,
    with the optical path and Fresnel weights on, end as the numpy kernel leaves them (flags, positions,
    directions and the optical path bit for bit; a stopped ray's weights untouched past its stop)."""
    from physcam.trace.kernels import get_kernel
    from physcam.trace.tables import packed_table
    from physcam.trace.trace import trace_packed

    BLOCK = 256

    lens = load_lens("canon_rf_85mm_f1_2")  # aspheres: a stopped block skips their Newton steps too
    sd = lens.surfaces[0].semi_diameter
    rng = np.random.default_rng(3)
    n = 4 * BLOCK + 17
    pos = np.stack([rng.uniform(-0.8 * sd, 0.8 * sd, n), rng.uniform(-0.8 * sd, 0.8 * sd, n), np.full(n, -2.0)], axis=1)
    d = np.stack([rng.normal(0, 0.05, n), rng.normal(0, 0.05, n), np.ones(n)], axis=1)
    pos[BLOCK:2 * BLOCK, 0] = np.linspace(1.5, 3.0, BLOCK) * sd  # block 1: every ray past the front rim
    pos[2 * BLOCK:3 * BLOCK, 0] = 0.9 * sd  # block 2: inside the front rim, aimed outward, stopped further in
    pos[2 * BLOCK:3 * BLOCK, 1] *= 0.1
    d[2 * BLOCK:3 * BLOCK, 0] = 0.2
    rays = RayBatch.from_arrays(pos, d, rng.uniform(400, 700, n) if mixed else 550.0)
    p = packed_table(lens, coating="single")
    outs = []
    for be in (backend, "numpy"):
        r = rays.copy()
        opl = np.zeros(r.x.shape[0])
        trace_packed(get_kernel(be), r, p.S, p.kinds, clip=True, fresnel=True, end_z=lens.vertex_z[-1] + 40.0,
                     opl=opl)
        outs.append((r, opl))
    (a, opl_a), (b, opl_b) = outs
    assert (a.flag[BLOCK:2 * BLOCK] != 0).all() and (a.flag[2 * BLOCK:3 * BLOCK] != 0).all()
    assert (a.flag[:BLOCK] == 0).any() and (a.z[2 * BLOCK:3 * BLOCK] > -2.0).all()  # block 2 stopped past the first surface
    np.testing.assert_array_equal(a.flag, b.flag)
    for u, v in zip(a.columns()[:6] + (opl_a,), b.columns()[:6] + (opl_b,)):
        np.testing.assert_array_equal(u, v)
    stopped = slice(BLOCK, 2 * BLOCK)
    np.testing.assert_array_equal(a.weight[stopped], b.weight[stopped])
    nsurf = len(lens.surfaces)
    np.testing.assert_allclose(a.weight, b.weight, rtol=4 * nsurf * EPS, atol=4 * nsurf * EPS)


def _fresh_asm(fn, *args):
    import numba

    from physcam.trace.kernels import _numba as K

    opts = K._FMA_OPTS if fn is K._fresnel_pass else K._OPTS
    f = numba.njit(**(opts | {"cache": False}))(fn.py_func)  # cached code cannot be inspected
    f(*args)
    return f.inspect_asm(f.signatures[0])


@needs_numba
@pytest.mark.skipif(platform.machine() not in ("x86_64", "AMD64"), reason="x86 assembly")
def test_hot_loops_compile_to_packed_sqrt_and_division():
    from physcam.trace.kernels import _numba as K

    import llvmlite.binding as llvm

    feats = llvm.get_host_cpu_features()
    if not feats.get("avx2", False):
        pytest.skip("no AVX2 on this CPU")
    buf = np.zeros(K._NCOL * K.BLOCK)
    one = 1.0
    for fn, args, ops in ((K._intersect_quadric, (buf, K.BLOCK, one, one, one, one), ("vsqrtpd", "vdivpd")),
                          (K._refract, (buf, K.BLOCK), ("vsqrtpd", "vmulpd")),
                          (K._fresnel_pass, (buf, K.BLOCK, one), ("vdivpd", "vfmadd")),
                          (K._normalise, (buf, K.BLOCK), ("vsqrtpd", "vdivpd"))):
        asm = _fresh_asm(fn, *args)
        for op in ops:
            assert re.search(rf"\b{op}\w*\s+[^\n]*%[yz]mm", asm), f"{fn.__name__}: no packed {op} on ymm/zmm"
    # the geometry is never contracted: no FMA in the refraction pass
    assert not re.search(r"\bvf(n)?m(add|sub)\w*pd", _fresh_asm(K._refract, buf, K.BLOCK))


@pytest.mark.parametrize("slug", ["dgauss_50mm", "canon_rf_85mm_f1_2", "navarro_anamorphic_2x", "fisheye_10mm"])
def test_single_precision_stays_within_the_documented_error(slug):
    # docs/ray-tracing.md: float32 film positions within 0.2 um of float64 on every bundled lens
    # (measured worst 0.06 um), the same flags; camera-ray directions within 1 arcsec
    lens = load_lens(slug)
    film = paraxial_image_z(lens)
    rng = np.random.default_rng(3)
    n = 20000
    r = 0.95 * lens.surfaces[0].semi_diameter * np.sqrt(rng.random(n))
    ph = 2 * np.pi * rng.random(n)
    rays = RayBatch.collimated(r * np.cos(ph), r * np.sin(ph), -1.0, direction=(0.0, 0.03, 1.0))
    a = trace_through(lens, rays, end_z=film, fresnel=True)
    b = trace_through(lens, rays.astype(np.float32), end_z=film, fresnel=True)
    assert b.x.dtype == np.float32 and b.weight_sp.dtype == np.float32
    ok = a.ok & b.ok
    assert (a.flag != b.flag).sum() <= 2 and ok.sum() > 100
    assert np.hypot(a.x[ok] - b.x[ok], a.y[ok] - b.y[ok]).max() < 2e-4
    np.testing.assert_allclose(b.weight[ok], a.weight[ok], rtol=1e-5, atol=1e-6)
    fxy, uv = rng.uniform(-8, 8, (2000, 2)), rng.random((2000, 2))
    ref = camera_rays(lens, fxy, uv, film)
    cam = camera_rays(lens, fxy, uv, film, precision="single")
    assert cam.direction.dtype == np.float32
    ok = ref.ok & cam.ok
    assert (ref.ok != cam.ok).sum() <= 2 and ok.any()
    sin = np.linalg.norm(np.cross(ref.direction[ok], cam.direction[ok].astype(float)), axis=1)
    assert np.degrees(sin.max()) * 3600 < 1.0


# ---- the C kernel: every instruction set, float32 against the JIT kernel, any rays -------------------

def _isa_levels():
    if not c_available():
        return []
    from physcam.trace.kernels import _c

    return list(_c.isa_levels())


def _trace_with_path(lens, rays, backend, **kw):
    """``rays`` traced by ``backend`` with Fresnel weights and each leg's optical path (the variant with every
    feature but the ones ``rays`` choose: one wavelength or each ray's own, float64 or float32)."""
    from physcam.trace.kernels import get_kernel
    from physcam.trace.tables import packed_table
    from physcam.trace.trace import trace_packed

    p = packed_table(lens, coating="single", dtype=rays.x.dtype)
    r = rays.copy()
    opl = np.zeros(len(r))
    trace_packed(get_kernel(backend), r, p.S, p.kinds, clip=kw.get("clip", True), fresnel=True,
                 end_z=kw.get("end_z", lens.vertex_z[-1] + 40.0), opl=opl)
    return r, opl


#: one lens of each feature (even aspheres and their Newton solve; cylinders, flats and aspheres of an
#: anamorphic; a fisheye's steep rays; a plain double Gauss)
FEATURE_SLUGS = ["canon_rf_85mm_f1_2", "navarro_anamorphic_2x", "fisheye_10mm", "dgauss_50mm"]


@needs_c
@pytest.mark.parametrize("isa", _isa_levels())
def test_every_instruction_set_of_the_c_kernel_gives_the_reference_rays_bit_for_bit(isa):
    """Each instruction set the build has and this CPU runs (baseline, AVX2, AVX-512 on x86-64) traces the
    numpy reference's rays bit for bit in float64: flags, positions, directions, both Fresnel weights and the
    optical path, on a lens of each feature, one wavelength and each ray's own (packed and scalar IEEE
    operations round alike; nothing is contracted). The default level runs every bundled lens above."""
    from physcam.trace.kernels import _c

    before = _c.isa()
    _c.set_isa(isa)
    try:
        for slug in FEATURE_SLUGS:
            lens = load_lens(slug)
            for mixed in (False, True):
                rays = random_rays(lens, 700, 5, mixed)
                a, opl_a = _trace_with_path(lens, rays, "c")
                b, opl_b = _trace_with_path(lens, rays, "numpy")
                assert 0 < a.ok.sum() < len(a)
                for u, v in zip(a.columns() + (opl_a,), b.columns() + (opl_b,)):
                    np.testing.assert_array_equal(u, v, err_msg=f"{slug} {isa} mixed={mixed}")
    finally:
        _c.set_isa(before)


@needs_c
@needs_numba
@pytest.mark.parametrize("slug", SLUGS)
def test_the_c_kernel_traces_float32_as_the_jit_kernel(slug):
    """Single precision: the C kernel types float32 as numba does (every constant in the rays' precision), so
    its flags, positions, directions and optical path are the JIT kernel's bit for bit on every bundled lens,
    one wavelength and each ray's own; the Fresnel weights, which numba contracts to FMA, within a few float32
    ulps per surface. (The numpy kernel promotes some float32 steps to float64: its float32 rays differ from
    both by up to 4e-5 mm, docs/ray-tracing.md.)"""
    lens = load_lens(slug)
    nsurf = len(lens.surfaces)
    eps32 = float(np.finfo(np.float32).eps)
    for mixed in (False, True):
        rays = random_rays(lens, 600, 9, mixed).astype(np.float32)
        a, opl_a = _trace_with_path(lens, rays, "c")
        b, opl_b = _trace_with_path(lens, rays, "numba")
        assert a.x.dtype == np.float32
        np.testing.assert_array_equal(a.flag, b.flag)
        for u, v in zip(a.columns()[:6] + (opl_a,), b.columns()[:6] + (opl_b,)):
            np.testing.assert_array_equal(u, v)
        for u, v in zip((a.weight, a.weight_sp), (b.weight, b.weight_sp)):
            np.testing.assert_allclose(u, v, rtol=4 * nsurf * eps32, atol=4 * nsurf * eps32)


@needs_c
def test_strided_columns_and_a_table_of_another_precision_give_the_same_rays():
    """The C kernel reads its arrays through the buffer protocol with their strides: columns that are views
    into one (n, 10) array trace as contiguous ones. A float64 table under float32 rays (a mix the numba
    kernel would trace in mixed precision, and no physcam caller makes) goes to the numpy kernel: its answer."""
    from physcam.trace.kernels import get_kernel
    from physcam.trace.tables import packed_table

    lens = load_lens("canon_rf_85mm_f1_2")
    p = packed_table(lens, coating="single")
    rays = random_rays(lens, 600, 4, True)
    ref = rays.copy()
    get_kernel("numpy")(*ref.columns(), p.S, p.kinds, True, True, 120.0, True, False)
    block = np.stack([c.astype(np.float64) for c in rays.columns()], axis=1)  # (n, 10): strided columns
    cols = [block[:, i] for i in range(9)] + [block[:, 9].astype(np.uint8)]
    get_kernel("c")(*cols, p.S, p.kinds, True, True, 120.0, True, False)
    for u, v in zip(cols, ref.columns()):
        np.testing.assert_array_equal(u, v)
    r32 = rays.astype(np.float32)
    a, b = r32.copy(), r32.copy()
    get_kernel("c")(*a.columns(), p.S, p.kinds, True, True, 120.0, True, False)
    get_kernel("numpy")(*b.columns(), p.S, p.kinds, True, True, 120.0, True, False)
    for u, v in zip(a.columns(), b.columns()):
        np.testing.assert_array_equal(u, v)


@needs_c
def test_the_c_kernel_releases_the_gil_while_it_traces():
    """Python runs on another thread while the C kernel traces (else its block ranges on threads would run
    one after another): a thread traces 1e6 rays through a lens with aspheres (about 0.1-0.5 s) while the
    main thread sleeps 10 ms from the moment the trace began; waking needs the GIL, so the main thread wakes
    before the trace ends only if the C call gave the GIL up (a build without Py_BEGIN_ALLOW_THREADS wakes
    after, checked)."""
    import threading
    import time

    from physcam.trace.kernels import _c
    from physcam.trace.tables import packed_table

    lens = load_lens("canon_rf_85mm_f1_2")
    p = packed_table(lens, coating="single")
    a = random_rays(lens, 1_000_000, 2, True)
    nb = (len(a) + _c.BLOCK - 1) // _c.BLOCK
    cols = a.columns()
    started = threading.Event()
    times = {}

    def work():
        started.set()
        _c.trace_blocks(*cols, p.S, p.kinds, True, True, 120.0, True, False, None, 0, nb)
        times["end"] = time.perf_counter()

    t = threading.Thread(target=work)
    t.start()
    started.wait()
    time.sleep(0.01)
    times["woke"] = time.perf_counter()
    t.join()
    assert times["woke"] < times["end"]
    assert (a.flag == 0).sum() > 1000

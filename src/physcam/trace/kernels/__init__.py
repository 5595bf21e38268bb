"""Kernel dispatch: ``backend="auto" | "c" | "numba" | "numpy"``.

The only module that imports numba. The three kernels have the signature of :func:`._numpy.trace_rays`
(its optional ``opl``: each leg's optical path added to a float64 array, the same in all, for the wavefront
analyses) and give the same rays: identical flags, positions and directions, Fresnel weights within a few
units in the last place (the numba kernel's; the C kernel's are the numpy kernel's bit for bit)
(docs/ray-tracing.md, "Three kernels"; tests/trace/test_simd_kernel.py). The C kernel (:mod:`._c`) is the
numba kernel's blocked passes compiled ahead of time when physcam is installed (setup.py: an optional
extension, so an install without a C compiler has the other two); the numba kernel is the ``fast`` extra.
Set ``PHYSCAM_BACKEND=c`` (or ``numba``, ``numpy``) to force one; ``python -m physcam.trace.kernels`` says
which this install has and which "auto" traces with (:func:`loaded_backend`).

"auto" rents a kernel that costs nothing to load, the C kernel where built (else the numpy kernel), and
loads numba only when that pays: rent-or-buy on what numba would save (:func:`_rent`). With the numpy
kernel that is its whole time: importing numba and loading the cached JIT kernel cost about 0.2 s once per
process, more than a short command's whole tracing work in the numpy kernel (a spot diagram, a distortion
curve: 10-40 ms). With the C kernel it is the part of the C kernel's time the JIT kernel would save
(:data:`C_RAY_SURFACE_S` times :data:`C_EXCESS`, by instruction set: 10 % at AVX-512, 40 % at AVX2), so
numba loads only after seconds of tracing. So "auto" runs the rented kernel while the rent it has paid
stays under :data:`NUMPY_BUDGET_S` and the call at hand's under :data:`NUMPY_CALL_MAX_S`; the first call
past either loads numba, and from then on (or whenever numba is already loaded) every call uses the JIT
kernel. Since the kernels agree, the answer does not depend on which one ran. Before
numba's disk cache holds compiled kernels (the first commands after an install or upgrade), making
the JIT kernel ready means compiling it (:data:`NUMBA_COMPILE_S`, :func:`numba_load_cost`), and the
budgets grow in proportion: a job the numpy kernel does faster than the compile stays in numpy.

The C kernel runs large batches as the JIT kernel does (:func:`run_blocks`), with no variants to compile.
The JIT kernel is one compiled variant per feature set (``_numba.variant``: one wavelength or each
ray's own, optical path, Fresnel weights, aspheres), each compiled on first use with the passes it
calls only; :func:`set_compile_reporter` hears about a compile as it happens. It runs on the calling
thread below :data:`SERIAL_BELOW` rays (and, with :data:`LOAD_AWARE`, at any size while the machine
is busy) and otherwise splits the batch's blocks into one range per thread (:func:`threads`), each
traced without the GIL: a thread costs tens of microseconds to wake, and on a busy machine waits for
a core (benchmarks/small_calls.py). Serial and threaded runs give identical rays. Compiled kernels
are cached on disk under a key that includes physcam's version and a hash of the kernel sources
(:mod:`._jitcache`).

The Blender extension's pupil tables have a compiled rim pass too (:func:`rim_pass`): the rim points of their aim
grids, the numpy pass's bit for bit, compiled because that pass was half of a table's CPU. Two ports of it: in C
(``_rimpass.c``, built into the C kernel's module, :func:`._c.rim_points`), which "auto" takes where the C kernel
is built, and numba's (:mod:`._rimpass`, in the same disk cache as the JIT kernel), where only numba is. Both run
as fast (round 22, docs/performance.md); the C one has no JIT code to load, so a process that traces with the C
kernel never loads numba for its rims.
"""

from __future__ import annotations

import os

from ...errors import BackendError

__all__ = ["BACKENDS", "SERIAL_BELOW", "backend_for_job", "c_available", "c_kernel", "get_kernel", "loaded_backend",
           "resolve_backend", "numba_available", "jit_kernel", "run_blocks",
           "numba_load_cost", "rim_pass", "set_compile_reporter", "set_threads", "threads"]

BACKENDS = ("auto", "c", "numba", "numpy")
#: Batches smaller than this run the JIT kernel serially (measured crossover, docs/performance.md).
SERIAL_BELOW = 1024
#: "auto" before numba is loaded: the numpy kernel's cost per ray and surface, and per surface and
#: call (dgauss_50mm on this machine, 5e5 rays in slices of 2^14: 32-38 ns per ray and surface, one
#: wavelength or three with the optical path, at load 3.5; ~25 us of numpy calls per surface)
NUMPY_RAY_SURFACE_S = 40e-9
NUMPY_SURFACE_S = 30e-6
#: What loading numba costs a process before its first traced ray: ``import numba``, the kernel
#: module and the first variant's target initialisation and cache load (0.18 + 0.05 + 0.16 s of CPU
#: at load 14, 2026-11-28; 0.33-0.38 s at load 3.9, 2026-11-26; docs/performance.md)
NUMBA_LOAD_S = 0.35
#: "auto" runs the numpy kernel while the numpy work of the process, the call at hand included,
#: stays under this: as much as loading numba costs (rent until the rent paid would have bought:
#: never more than twice the cheaper choice, whatever work follows); and one call estimated above
#: ``NUMPY_CALL_MAX_S`` loads numba at once. Both scale with :func:`numba_load_cost` (a cold JIT
#: cache). Issue 47: at a third of the load cost, the ghost and relative-illumination commands
#: (0.12-0.18 s of numpy work) loaded numba for nothing.
NUMPY_BUDGET_S = NUMBA_LOAD_S
NUMPY_CALL_MAX_S = NUMBA_LOAD_S
#: "auto" with the C kernel (where built): its CPU per ray and surface by the instruction set it runs, and the
#: part of that the JIT kernel saves (benchmarks/trace.py, dgauss_50mm, 1e6 rays, one thread, each kernel
#: paired with the JIT kernel on this machine: 18.7 against 19.7 M rays/s at AVX-512, 12.4 against 19.6 at
#: AVX2, 6.4 against 19.0 at the x86-64 baseline; docs/performance.md, "Round 21: the C kernel"). "auto"
#: rents the C kernel and counts as rent only what numba would have saved, so numba loads once that reaches
#: its load cost: after about 3.5 s of the C kernel's work at AVX-512, 0.9 s at AVX2, 0.5 s at the baseline.
C_RAY_SURFACE_S = {"avx512": 4.5e-9, "avx2": 6.7e-9, "baseline": 13e-9}
C_EXCESS = {"avx512": 0.1, "avx2": 0.4, "baseline": 0.67}
#: Large batches too run serially while the machine is busy (1-minute load average above the
#: cores numba uses, plus 0.5): numba's parallel loop splits the blocks statically, so with other
#: processes on the cores it waits for its slowest thread (benchmarks/small_calls.py measured the
#: parallel kernel 2-5x slower than the serial one under load, up to 1e6 rays).
LOAD_AWARE = True
#: What compiling a variant of the JIT kernel costs when numba's disk cache does not hold it yet
#: (the first traced command after installing or upgrading physcam): the variant a bokeh or an MTF
#: chart uses, CPU seconds on this machine (docs/performance.md, "The first traced command")
NUMBA_COMPILE_S = 4.0
_numba_kernel = None
_numba_error: str | None = None
_rent_paid = 0.0
_load_seen = (-1.0, False)  # (monotonic time of the last look, busy then)
_threads_set: int | None = None
_threads_default: int | None = None


def set_threads(n: int | None) -> None:
    """Threads the compiled kernels run large batches on (None: numba's ``NUMBA_NUM_THREADS``, the cores)."""
    global _threads_set
    if n is not None and (isinstance(n, bool) or not isinstance(n, int) or n < 1):
        raise BackendError(f"threads must be a whole number from 1, got {n!r}")
    _threads_set = n


def threads() -> int:
    """Threads the compiled kernels use for a large batch (:func:`set_threads`; by default numba's
    ``NUMBA_NUM_THREADS``: the cores this process may use)."""
    if _threads_set is not None:
        return _threads_set
    global _threads_default
    if _threads_default is None:
        import sys

        numba = sys.modules.get("numba")  # never imported for this: the C kernel runs without numba
        try:
            _threads_default = max(1, int(numba.config.NUMBA_NUM_THREADS))
        except AttributeError:  # numba not loaded: its setting, else the cores this process may use (numba's default)
            try:
                _threads_default = max(1, int(os.environ.get("NUMBA_NUM_THREADS") or len(os.sched_getaffinity(0))))
            except (AttributeError, ValueError):
                _threads_default = os.cpu_count() or 1
    return _threads_default


def set_compile_reporter(fn) -> None:
    """``fn(done, total)`` is called while numba compiles a kernel variant (the first use after an
    install or upgrade): ``(0, total)`` when it starts, then after each pass, ``(total, total)`` at
    the end; None for silence (the default). The ``"compile"`` reporter of :mod:`physcam.progress`
    (``physcam`` shows it as "compiling the ray tracer (once)" with a progress bar on a terminal)."""
    from ...progress import set_reporter

    set_reporter("compile", fn)


def _busy() -> bool:
    """Whether other work occupies the cores (looked up at most once a second)."""
    global _load_seen
    import time

    now = time.monotonic()
    if now - _load_seen[0] > 1.0:
        try:
            busy = os.getloadavg()[0] > threads() + 0.5
        except (OSError, AttributeError):  # no load average on this platform
            busy = False
        _load_seen = (now, busy)
    return _load_seen[1]


def numba_load_cost() -> float:
    """What making the JIT kernel ready costs this process (CPU seconds): :data:`NUMBA_LOAD_S` when
    numba's disk cache holds compiled kernels of this physcam (:func:`._jitcache.is_warm`), else
    :data:`NUMBA_COMPILE_S`; 0 once loaded."""
    if _numba_kernel is not None:
        return 0.0
    from . import _jitcache

    return NUMBA_LOAD_S if _jitcache.is_warm() else NUMBA_COMPILE_S


_pool = None


def _forget_pool() -> None:
    """In a forked child: a fork copies only the forking thread, so the parent's pool names trace threads the
    child does not have and would wait for them for ever; the child starts its own pool when it needs one."""
    global _pool
    _pool = None


if hasattr(os, "register_at_fork"):
    os.register_at_fork(after_in_child=_forget_pool)


def run_blocks(f, args, n: int, block: int, serial_below: int) -> None:
    """Run ``f(*args, b0, b1)`` over the ``n`` rays' blocks of ``block``: on the calling thread below
    ``serial_below`` rays (or with fewer than two blocks or threads), else one range of blocks per thread
    (:func:`threads`), the first on the calling thread. Both compiled kernels trace a range without the GIL,
    and a ray's answer does not depend on its block's range: serial and threaded runs give identical rays."""
    nb = (n + block - 1) // block
    k = min(threads(), nb)
    if n < serial_below or k < 2:
        f(*args, 0, nb)
        return
    global _pool
    if _pool is None:
        from concurrent.futures import ThreadPoolExecutor

        _pool = ThreadPoolExecutor(max_workers=max(1, threads() - 1), thread_name_prefix="physcam-trace")
    cuts = [nb * i // k for i in range(k + 1)]
    futures = [_pool.submit(f, *args, cuts[i], cuts[i + 1]) for i in range(1, k)]
    f(*args, cuts[0], cuts[1])
    for fut in futures:
        fut.result()


class _CompiledKernel:
    """What the two compiled kernels share: called with the numpy kernel's signature, a batch runs on the calling
    thread below :data:`SERIAL_BELOW` rays (and at any size while the machine is busy, :data:`LOAD_AWARE`), else
    on threads (:func:`run_blocks`); each kernel's ``run`` takes the threshold."""

    def __call__(self, x, y, z, L, M, N, wl, w, wd, flag, S, kinds, clip, fresnel, end_z, has_end, mono, opl=None):
        below = SERIAL_BELOW
        if x.shape[0] >= below and LOAD_AWARE and _busy():
            below = x.shape[0] + 1
        self.run(x, y, z, L, M, N, wl, w, wd, flag, S, kinds, clip, fresnel, end_z, has_end, mono, below, opl)


class _CKernel(_CompiledKernel):
    """The compiled C kernel (:mod:`._c`) with the numpy kernel's signature: large batches as one range of
    blocks per thread as the JIT kernel's (:func:`run_blocks`, :data:`SERIAL_BELOW`, :data:`LOAD_AWARE`)."""

    def __init__(self):
        from . import _c

        self._C = _c
        self.isa = _c.isa  # the instruction set it runs ("avx512", "avx2", "baseline")

    def run(self, x, y, z, L, M, N, wl, w, wd, flag, S, kinds, clip, fresnel, end_z, has_end, mono, serial_below,
            opl=None):
        """Trace in place (the JIT kernel's :meth:`_JitKernel.run`; an empty ``opl`` is no optical path)."""
        C = self._C
        opl = opl if opl is not None and opl.shape[0] else None
        if C.mixed_precision(x, S) or (opl is not None and opl.dtype.char != "d"):
            # (inputs the C kernel does not take and the numpy kernel does: a table not in the rays' precision,
            # an optical path not in float64; no physcam caller makes them)
            from ._numpy import trace_rays

            return trace_rays(x, y, z, L, M, N, wl, w, wd, flag, S, kinds, clip, fresnel, end_z, has_end, mono, opl)
        args = (x, y, z, L, M, N, wl, w, wd, flag, S, kinds, clip, fresnel, end_z, has_end, mono, opl)
        run_blocks(C.trace_range, args, x.shape[0], C.BLOCK, serial_below)


_c_kernel = None
_c_error: str | None = None


def _load_c():
    """The C kernel, or None where the extension was not built (:data:`_c_error` says why)."""
    global _c_kernel, _c_error
    if _c_kernel is None and _c_error is None:
        try:
            _c_kernel = _CKernel()
        except ImportError as exc:
            _c_error = f"{type(exc).__name__}: {exc}"
    return _c_kernel


def c_available() -> bool:
    """Whether this install has the compiled C kernel (built when physcam was installed: docs/install.md)."""
    return _load_c() is not None


def c_kernel():
    """The C kernel's ``run`` (the signature of :func:`jit_kernel`'s), None where it was not built. For
    benchmarks and tests."""
    k = _load_c()
    return None if k is None else k.run


class _JitKernel(_CompiledKernel):
    """The JIT kernel with the numpy kernel's signature: picks the variant (``_numba.variant``) of the
    call's features, compiles or loads it on first use (telling the compile reporter), and runs a
    batch of :data:`SERIAL_BELOW` rays or more as one range of blocks per thread (module notes)."""

    def __init__(self):
        import numpy as np

        from . import _numba

        self._K = _numba
        self._no_opl = np.empty(0)
        self._variants: dict = {}  # (features, ray and table dtypes) -> the variant, compiled or loaded for them
        self._asphere: dict = {}  # kinds' bytes -> whether they hold an even asphere

    def run(self, x, y, z, L, M, N, wl, w, wd, flag, S, kinds, clip, fresnel, end_z, has_end, mono, serial_below,
            opl=None):
        """Trace in place; below ``serial_below`` rays on the calling thread alone (the signature of
        the one parallel kernel this replaces: an empty ``opl`` is no optical path)."""
        with_opl = opl is not None and opl.shape[0] > 0
        kb = kinds.tobytes()  # whether the table holds aspheres, by the kinds' bytes (a few us less than a reduction)
        asphere = self._asphere.get(kb)
        if asphere is None:
            asphere = self._asphere[kb] = bool(kinds.shape[0] and kinds.max() >= 3)
        key = (bool(mono), with_opl, bool(fresnel), asphere, x.dtype.char, S.dtype.char)
        f = self._variants.get(key)
        if f is None:
            f = self._K.variant(*key[:4])
        args = (x, y, z, L, M, N, wl, w, wd, flag, S, kinds, bool(clip), float(end_z), bool(has_end),
                opl if with_opl else self._no_opl)
        if key not in self._variants:
            self._first_call(f, key[:4], args)
            self._variants[key] = f
        run_blocks(f, args, x.shape[0], self._K.BLOCK, serial_below)

    def _first_call(self, f, key, args) -> None:
        """Compile (or load from numba's disk cache) variant ``f`` for these argument types by a call on
        no block, telling the compile reporter about each pass numba compiles."""
        from numba.core import event

        from . import _jitcache

        passes = set(self._K.variant_passes(*key))
        total = len(passes) + 1
        state = {"done": 0, "started": False}
        from ...progress import reporter as _reporter

        reporter = _reporter("compile")

        class Progress(event.Listener):
            def on_start(self, ev):
                if not state["started"]:
                    state["started"] = True
                    if reporter is not None:
                        reporter(0, total)

            def on_end(self, ev):
                name = getattr(ev.data.get("dispatcher"), "py_func", None)
                if name is not None and name.__name__ in passes:
                    state["done"] = min(total - 1, state["done"] + 1)
                    if reporter is not None:
                        reporter(state["done"], total)

        with _jitcache.compile_lock(), event.install_listener("numba:compile", Progress()):
            f(*args, 0, 0)
        if state["started"] or not _jitcache.is_warm():  # compiled now, or loaded from a cache left unmarked
            _jitcache.mark_compiled()
        if state["started"] and reporter is not None:
            reporter(total, total)


def _load_numba():
    global _numba_kernel, _numba_error
    if _numba_kernel is None and _numba_error is None:
        try:
            from . import _jitcache

            _jitcache.install()
            _numba_kernel = _JitKernel()
        except Exception as exc:  # ImportError, or numba failing to initialise
            _numba_error = f"{type(exc).__name__}: {exc}"
    return _numba_kernel


def numba_available() -> bool:
    return _load_numba() is not None


def jit_kernel():
    """The JIT kernel with the one parallel kernel's signature (the numpy kernel's, then
    ``serial_below`` and ``opl``: an empty float64 array for no optical path), loading numba; None
    when numba is unavailable. For benchmarks and tests."""
    k = _load_numba()
    return None if k is None else k.run


def _rent(n: int, rows: int) -> tuple[float, object]:
    """What a call of ``n`` rays through ``rows`` rows (and the end plane) costs "auto" before numba loads,
    and the kernel that traces it then: the numpy kernel's time (:data:`NUMPY_RAY_SURFACE_S`,
    :data:`NUMPY_SURFACE_S`) and None (the numpy kernel), or where the C kernel is built the part of its time
    the JIT kernel would save (:data:`C_RAY_SURFACE_S` times :data:`C_EXCESS`, by the instruction set it
    runs) and the C kernel."""
    c = _load_c()
    if c is None:
        return (rows + 1) * (NUMPY_SURFACE_S + n * NUMPY_RAY_SURFACE_S), None
    isa = c.isa()
    return (rows + 1) * n * C_RAY_SURFACE_S.get(isa, C_RAY_SURFACE_S["baseline"]) * C_EXCESS.get(isa, 1.0), c


def _auto(x, y, z, L, M, N, wl, w, wd, flag, S, kinds, clip, fresnel, end_z, has_end, mono, opl=None):
    """The "auto" kernel: the C kernel (or, where it was not built, the numpy kernel) until numba pays for
    its loading, then the JIT kernel (module notes)."""
    global _rent_paid
    k = _numba_kernel
    if k is None:
        est, rented = _rent(x.shape[0], kinds.shape[0])
        if _numba_error is None:
            # a cold JIT cache: compiling costs more than loading (scale >= 1); a call numpy takes even at
            # scale 1 (a report's few chief rays) does not look at the cache (_jitcache: hashlib, the sources)
            small = est < NUMPY_CALL_MAX_S and _rent_paid + est < NUMPY_BUDGET_S
            scale = 1.0 if small else numba_load_cost() / NUMBA_LOAD_S
            if est < NUMPY_CALL_MAX_S * scale and _rent_paid + est < NUMPY_BUDGET_S * scale:
                _rent_paid += est
            else:
                k = _load_numba()
        if k is None:
            if rented is not None:
                return rented(x, y, z, L, M, N, wl, w, wd, flag, S, kinds, clip, fresnel, end_z, has_end, mono, opl)
            from ._numpy import trace_rays

            return trace_rays(x, y, z, L, M, N, wl, w, wd, flag, S, kinds, clip, fresnel, end_z, has_end, mono, opl)
    return k(x, y, z, L, M, N, wl, w, wd, flag, S, kinds, clip, fresnel, end_z, has_end, mono, opl)


def backend_for_job(backend: str, ray_surfaces: float) -> str:
    """The backend for a job whose whole size is known before it starts: ``ray_surfaces`` ray-surface
    intersections in all (a bokeh: its rays times the surfaces plus the film).

    "c" (where the C kernel is built) or "numpy" when ``backend`` is "auto" (and ``PHYSCAM_BACKEND`` does
    not say otherwise), numba is not loaded yet and the job's rent (:func:`_rent`: the numpy kernel's time,
    or the part of the C kernel's that numba would save), with the rent this process has paid so far, stays
    under what loading numba costs (:data:`NUMBA_LOAD_S`); ``backend`` unchanged otherwise, so a process
    that keeps tracing pays for numba once its rent would have paid for it. Either way the rays are the
    same (module notes).
    """
    global _rent_paid
    if backend != "auto" or os.environ.get("PHYSCAM_BACKEND", "auto") != "auto" or _numba_kernel is not None:
        return backend
    c = _load_c()
    if c is None:
        est = ray_surfaces * NUMPY_RAY_SURFACE_S
    else:
        est = _rent(int(ray_surfaces), 0)[0]
    if _numba_error is not None:  # numba cannot load: the rent is all there is
        return "numpy" if c is None else "c"
    if _rent_paid + est < numba_load_cost():
        _rent_paid += est
        return "numpy" if c is None else "c"
    return backend


def loaded_backend() -> str:
    """The kernel "auto" traces with in this process now: the one ``PHYSCAM_BACKEND`` names (raising
    :class:`~physcam.errors.BackendError` as tracing would, for a name it does not know or a kernel this install
    lacks), else "numba" once loaded, else "c" where the C kernel is built, else "numpy"
    (``python -m physcam.trace.kernels`` prints it with what this install has)."""
    env = os.environ.get("PHYSCAM_BACKEND", "auto")
    if env != "auto":  # forced: that kernel, or its BackendError (an unknown name, a kernel not here)
        if env not in BACKENDS:
            raise BackendError(f"PHYSCAM_BACKEND={env!r} is not one of {', '.join(BACKENDS)}")
        return resolve_backend(env)
    if _numba_kernel is not None:
        return "numba"
    return "c" if c_available() else "numpy"


def resolve_backend(backend: str = "auto") -> str:
    """The concrete backend name ("c", "numba" or "numpy") for ``backend``: "auto" resolves to numba where
    it loads (this loads it: for jobs known to be large), else to the C kernel where built, else numpy."""
    if backend not in BACKENDS:
        raise BackendError(f"unknown tracing backend {backend!r}; use one of {', '.join(BACKENDS)}")
    if backend == "auto":
        backend = os.environ.get("PHYSCAM_BACKEND", "auto")
        if backend not in BACKENDS:
            raise BackendError(f"PHYSCAM_BACKEND={backend!r} is not one of {', '.join(BACKENDS)}")
    if backend == "auto":
        if numba_available():
            return "numba"
        return "c" if c_available() else "numpy"
    if backend == "c" and not c_available():
        raise BackendError(f"the c backend is not built in this install ({_c_error}): reinstall physcam from a "
                           "platform wheel, or from source with a C compiler present (pip install --force-reinstall "
                           "--no-deps physcam), or trace with backend='numpy' (the same rays) or 'numba' (pip install "
                           "'physcam[fast]')")
    if backend == "numba" and not numba_available():
        if _numba_error.startswith(("ModuleNotFoundError", "ImportError")) and "numba" in _numba_error:
            raise BackendError("the numba backend needs physcam's 'fast' extra (numba is not installed): "
                               "pip install 'physcam[fast]', or trace with the numpy kernels (the same rays, slower: "
                               "backend='numpy' or PHYSCAM_BACKEND=numpy)")
        raise BackendError(f"the numba backend is unavailable ({_numba_error}); use backend='numpy'")
    return backend


def rim_pass(backend: str = "auto"):
    """The compiled rim pass of the Blender extension's pupil tables for ``backend`` (both give the numpy pass's
    points bit for bit): the C pass (:func:`._c.rim_points`) for "c", numba's (``_rimpass.rim_points``) for
    "numba"; for "auto" the C pass where the C kernel is built (as fast as numba's, with no JIT code to load:
    docs/performance.md, round 22), else numba's once this process has loaded numba; None (the numpy pass) for
    "numpy" and where neither is. ``PHYSCAM_BACKEND`` forces one as it does the tracer."""
    if backend == "auto" and os.environ.get("PHYSCAM_BACKEND", "auto") == "auto":
        backend = "c" if c_available() else ("numba" if _numba_kernel is not None else "numpy")
    else:
        backend = resolve_backend(backend)
    if backend == "c":
        return _load_c()._C.rim_points
    if backend != "numba" or _load_numba() is None:
        return None
    global _rim_points
    if _rim_points is None:
        from . import _rimpass

        _rim_points = _locked_first(_rimpass.rim_points)
    return _rim_points


def _locked_first(fn):
    """``fn`` (a JIT function, or a Python function calling some) with its first call in this process under
    :func:`._jitcache.compile_lock`: that call compiles its JIT code or loads it from the disk cache
    (:mod:`._jitcache` says why); later calls run unlocked."""
    first = [True]

    def call(*args):
        if first[0]:
            from . import _jitcache

            with _jitcache.compile_lock():
                out = fn(*args)
            first[0] = False
            return out
        return fn(*args)

    return call


_rim_points = None


def get_kernel(backend: str = "auto"):
    """The ``trace_rays`` function of ``backend`` ("auto": the C or numpy kernel until numba pays, module notes)."""
    if backend == "auto":
        env = os.environ.get("PHYSCAM_BACKEND", "auto")
        if env == "auto":
            return _numba_kernel if _numba_kernel is not None else _auto
        backend = resolve_backend(backend)  # PHYSCAM_BACKEND, checked (its message names the variable)
    backend = resolve_backend(backend)
    if backend == "numba":
        return _load_numba()
    if backend == "c":
        return _load_c()
    from ._numpy import trace_rays

    return trace_rays

"""Kernel dispatch: ``backend="auto" | "numba" | "numpy"``.

The only module that imports numba. Both kernels have the signature of :func:`._numpy.trace_rays`
and give the same rays: identical flags, positions and directions, Fresnel weights within a few
units in the last place (docs/ray-tracing.md, tests/trace/test_simd_kernel.py). Set
``PHYSCAM_BACKEND=numpy`` (or ``numba``) to force one.

"auto" loads numba lazily, when it pays: importing numba and loading the cached JIT kernel cost
about 0.2 s once per process, more than a short command's whole tracing work in the numpy kernel
(a spot diagram, a distortion curve: 10-40 ms). So "auto" runs the numpy kernel while the work it
has done (estimated from rays x surfaces, :data:`NUMPY_RAY_SURFACE_S`, :data:`NUMPY_SURFACE_S`)
stays under :data:`NUMPY_BUDGET_S` and the call at hand under :data:`NUMPY_CALL_MAX_S`; the first
call past either loads numba, and from then on (or whenever numba is already loaded) every call
uses the JIT kernel. Since the kernels agree, the answer does not depend on which one ran.

The JIT kernel runs on the calling thread below :data:`SERIAL_BELOW` rays (and, with
:data:`LOAD_AWARE`, at any size while the machine is busy) and on numba's thread pool otherwise:
waking the pool costs a few microseconds on an idle machine and, on a busy one, up to a scheduler
time slice (milliseconds) while a worker waits for a core (benchmarks/small_calls.py). Serial and
parallel give identical rays. Compiled kernels are cached on disk under a key that includes
physcam's version and a hash of the kernel sources (:mod:`._jitcache`).
"""

from __future__ import annotations

import os

from ...errors import BackendError

__all__ = ["BACKENDS", "SERIAL_BELOW", "backend_for_job", "get_kernel", "resolve_backend", "numba_available", "jit_kernel"]

BACKENDS = ("auto", "numba", "numpy")
#: Batches smaller than this run the JIT kernel serially (measured crossover, docs/performance.md).
SERIAL_BELOW = 1024
#: "auto" before numba is loaded: the numpy kernel's cost per ray and surface, and per surface and
#: call (dgauss_50mm on this machine: 1.3-2.2 M rays/s through 11 surfaces; ~25 us of numpy calls
#: per surface), the numpy work allowed in all (about half of what loading numba costs) and in one call
NUMPY_RAY_SURFACE_S = 60e-9
NUMPY_SURFACE_S = 30e-6
NUMPY_BUDGET_S = 0.1
NUMPY_CALL_MAX_S = 0.04
#: What loading numba costs a process before its first traced ray: ``import numba`` and the first
#: call's target initialisation (0.115 s + 0.14 s on this machine, idle; docs/performance.md)
NUMBA_LOAD_S = 0.25
#: Large batches too run serially while the machine is busy (1-minute load average above the
#: cores numba uses, plus 0.5): numba's parallel loop splits the blocks statically, so with other
#: processes on the cores it waits for its slowest thread (benchmarks/small_calls.py measured the
#: parallel kernel 2-5x slower than the serial one under load, up to 1e6 rays).
LOAD_AWARE = True
_numba_kernel = None
_numba_error: str | None = None
_numpy_spent = 0.0
_load_seen = (-1.0, False)  # (monotonic time of the last look, busy then)


def _busy() -> bool:
    """Whether other work occupies the cores (looked up at most once a second)."""
    global _load_seen
    import time

    now = time.monotonic()
    if now - _load_seen[0] > 1.0:
        try:
            import numba

            busy = os.getloadavg()[0] > numba.get_num_threads() + 0.5
        except (OSError, AttributeError):  # no load average on this platform
            busy = False
        _load_seen = (now, busy)
    return _load_seen[1]


def _load_numba():
    global _numba_kernel, _numba_error
    if _numba_kernel is None and _numba_error is None:
        try:
            from . import _jitcache

            _jitcache.install()
            from ._numba import trace_rays

            def trace_rays_auto(x, y, z, L, M, N, wl, w, wd, flag, S, kinds, clip, fresnel, end_z, has_end, mono):
                below = SERIAL_BELOW
                if x.shape[0] >= below and LOAD_AWARE and _busy():
                    below = x.shape[0] + 1
                trace_rays(x, y, z, L, M, N, wl, w, wd, flag, S, kinds, clip, fresnel, end_z, has_end, mono, below)

            trace_rays_auto.jit = trace_rays
            _numba_kernel = trace_rays_auto
        except Exception as exc:  # ImportError, or numba failing to initialise
            _numba_error = f"{type(exc).__name__}: {exc}"
    return _numba_kernel


def numba_available() -> bool:
    return _load_numba() is not None


def jit_kernel():
    """The numba dispatcher itself (``trace_rays`` with the trailing ``serial_below`` argument),
    loading numba; None when numba is unavailable. For benchmarks and tests."""
    k = _load_numba()
    return None if k is None else k.jit


def _auto(x, y, z, L, M, N, wl, w, wd, flag, S, kinds, clip, fresnel, end_z, has_end, mono):
    """The "auto" kernel: numpy until numba pays for its loading, then the JIT kernel (module notes)."""
    global _numpy_spent
    k = _numba_kernel
    if k is None:
        if _numba_error is None:
            est = (kinds.shape[0] + 1) * (NUMPY_SURFACE_S + x.shape[0] * NUMPY_RAY_SURFACE_S)
            if est < NUMPY_CALL_MAX_S and _numpy_spent + est < NUMPY_BUDGET_S:
                _numpy_spent += est
                k = None
            else:
                k = _load_numba()
        if k is None:
            from ._numpy import trace_rays

            return trace_rays(x, y, z, L, M, N, wl, w, wd, flag, S, kinds, clip, fresnel, end_z, has_end, mono)
    return k(x, y, z, L, M, N, wl, w, wd, flag, S, kinds, clip, fresnel, end_z, has_end, mono)


def backend_for_job(backend: str, ray_surfaces: float) -> str:
    """The backend for a job whose whole size is known before it starts: ``ray_surfaces`` ray-surface
    intersections in all (a bokeh: its rays times the surfaces plus the film).

    "numpy" when ``backend`` is "auto" (and ``PHYSCAM_BACKEND`` does not say otherwise), numba is
    not loaded yet and the numpy kernel would do the whole job (:data:`NUMPY_RAY_SURFACE_S` per
    intersection) in less time than loading numba takes (:data:`NUMBA_LOAD_S`); ``backend``
    unchanged otherwise. Either way the rays are the same (module notes).
    """
    if backend != "auto" or os.environ.get("PHYSCAM_BACKEND", "auto") != "auto" or _numba_kernel is not None:
        return backend
    return "numpy" if ray_surfaces * NUMPY_RAY_SURFACE_S < NUMBA_LOAD_S else backend


def resolve_backend(backend: str = "auto") -> str:
    """The concrete backend name ("numba" or "numpy") for ``backend``."""
    if backend not in BACKENDS:
        raise BackendError(f"unknown tracing backend {backend!r}; use one of {', '.join(BACKENDS)}")
    if backend == "auto":
        backend = os.environ.get("PHYSCAM_BACKEND", "auto")
        if backend not in BACKENDS:
            raise BackendError(f"PHYSCAM_BACKEND={backend!r} is not one of {', '.join(BACKENDS)}")
    if backend == "auto":
        return "numba" if numba_available() else "numpy"
    if backend == "numba" and not numba_available():
        if _numba_error.startswith(("ModuleNotFoundError", "ImportError")) and "numba" in _numba_error:
            raise BackendError("the numba backend needs physcam's 'fast' extra (numba is not installed): "
                               "pip install 'physcam[fast]', or use backend='numpy' (the same rays, slower)")
        raise BackendError(f"the numba backend is unavailable ({_numba_error}); use backend='numpy'")
    return backend


def get_kernel(backend: str = "auto"):
    """The ``trace_rays`` function of ``backend`` ("auto": numpy until numba pays, module notes)."""
    if backend == "auto":
        env = os.environ.get("PHYSCAM_BACKEND", "auto")
        if env == "auto":
            return _numba_kernel if _numba_kernel is not None else _auto
        backend = env
    if resolve_backend(backend) == "numba":
        return _load_numba()
    from ._numpy import trace_rays

    return trace_rays

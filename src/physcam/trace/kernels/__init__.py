"""Kernel dispatch: ``backend="auto" | "numba" | "numpy"``.

The only module that imports numba (lazily: on the first trace that needs it, so commands that
never trace do not pay the ~0.1 s import). "auto" uses the JIT kernel when numba imports, else
the numpy kernel; both have the signature of :func:`._numpy.trace_rays` and give the same answers
to the tolerance in docs/ray-tracing.md (tests/trace/test_backends.py). Set
``PHYSCAM_BACKEND=numpy`` to force the fallback.

The JIT kernel runs on the calling thread below :data:`SERIAL_BELOW` rays and on numba's thread
pool above: waking the pool costs a few microseconds on an idle machine and, on a busy one,
up to a scheduler time slice (milliseconds) while a worker waits for a core
(benchmarks/small_calls.py). Compiled kernels are cached on disk under a key that includes
physcam's version and a hash of the kernel sources (:mod:`._jitcache`).
"""

from __future__ import annotations

import os

from ...errors import BackendError

__all__ = ["BACKENDS", "SERIAL_BELOW", "get_kernel", "resolve_backend", "numba_available"]

BACKENDS = ("auto", "numba", "numpy")
#: Batches smaller than this run the JIT kernel serially (measured crossover, docs/performance.md).
SERIAL_BELOW = 4096
_numba_kernel = None
_numba_error: str | None = None


def _load_numba():
    global _numba_kernel, _numba_error
    if _numba_kernel is None and _numba_error is None:
        try:
            from . import _jitcache

            _jitcache.install()
            from ._numba import trace_rays

            def trace_rays_auto(x, y, z, L, M, N, wl, w, wd, flag, S, kinds, clip, fresnel, end_z, has_end, mono):
                trace_rays(x, y, z, L, M, N, wl, w, wd, flag, S, kinds, clip, fresnel, end_z, has_end, mono,
                           SERIAL_BELOW)

            trace_rays_auto.jit = trace_rays
            _numba_kernel = trace_rays_auto
        except Exception as exc:  # ImportError, or numba failing to initialise
            _numba_error = f"{type(exc).__name__}: {exc}"
    return _numba_kernel


def numba_available() -> bool:
    return _load_numba() is not None


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
        raise BackendError(f"the numba backend is unavailable ({_numba_error}); use backend='numpy'")
    return backend


def get_kernel(backend: str = "auto"):
    """The ``trace_rays`` function of ``backend``."""
    if backend == "auto" and _numba_kernel is not None and "PHYSCAM_BACKEND" not in os.environ:
        return _numba_kernel  # the common case, without the checks (per-call overhead)
    if resolve_backend(backend) == "numba":
        return _load_numba()
    from ._numpy import trace_rays

    return trace_rays

"""Kernel dispatch: ``backend="auto" | "numba" | "numpy"``.

The only module that imports numba. "auto" uses the JIT kernel when numba imports, else the
numpy kernel; both have the signature of :func:`._numpy.trace_rays` and give the same answers
(tests/trace/test_backends.py). Set ``PHYSCAM_BACKEND=numpy`` to force the fallback.
"""

from __future__ import annotations

import os

from ...errors import BackendError

__all__ = ["BACKENDS", "get_kernel", "resolve_backend", "numba_available"]

BACKENDS = ("auto", "numba", "numpy")
_numba_kernel = None
_numba_error: str | None = None


def _load_numba():
    global _numba_kernel, _numba_error
    if _numba_kernel is None and _numba_error is None:
        try:
            from ._numba import trace_rays

            _numba_kernel = trace_rays
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
    if resolve_backend(backend) == "numba":
        return _load_numba()
    from ._numpy import trace_rays

    return trace_rays

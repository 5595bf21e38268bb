"""How far long library work has got, for the front end that shows it (the CLI's progress bars).

The library reports, the front end decides how to show it: a reporter per kind of work is a
function ``fn(done, total)``, set with :func:`set_reporter` (None: silence, the default, as for
any Python caller). Kinds: ``"compile"``, numba compiling a variant of the JIT tracing kernel
(:mod:`physcam.trace.kernels`: ``(0, total)`` when it starts, a step per pass, ``(total, total)``
at the end). This module imports nothing, so a front end can set reporters without loading the
library's numerical modules.
"""

from __future__ import annotations

__all__ = ["KINDS", "set_reporter", "reporter"]

KINDS = ("compile",)
_REPORTERS: dict = {}


def set_reporter(kind: str, fn) -> None:
    """Report ``kind`` of work to ``fn(done, total)`` (None: report it to no one)."""
    if kind not in KINDS:
        from .errors import InputError

        raise InputError(f"unknown kind of progress {kind!r}; kinds: {', '.join(KINDS)}")
    if fn is not None and not callable(fn):
        from .errors import WrongTypeError

        raise WrongTypeError(f"a progress reporter must be callable as fn(done, total), got {type(fn).__name__}")
    _REPORTERS[kind] = fn


def reporter(kind: str):
    """The reporter of ``kind`` (None when no one listens)."""
    return _REPORTERS.get(kind)

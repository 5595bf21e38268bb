"""How far long library work has got, for the front end that shows it (the CLI's progress bars).

The library reports, the front end decides how to show it: a reporter per kind of work is a
function ``fn(done, total)``, set with :func:`set_reporter` (None: silence, the default, as for
any Python caller). Kinds: ``"compile"``, numba compiling a variant of the JIT tracing kernel
(:mod:`physcam.trace.kernels`: ``(0, total)`` when it starts, a step per pass, ``(total, total)``
at the end). This module imports nothing but ``os`` and ``threading``, so a front end can set reporters without loading
the library's numerical modules. It also keeps the rule by which a library process that forks workers and a
front end's display thread stay out of each other's way (:data:`FORK_LOCK`, :func:`quiet_thread`).
"""

from __future__ import annotations

import os as _os
import threading as _threading

__all__ = ["KINDS", "FORK_LOCK", "set_reporter", "reporter", "quiet_thread", "others_quiet"]

KINDS = ("compile",)
_REPORTERS: dict = {}
#: Held by a process while it forks worker processes, and taken by a front end's display thread
#: (:func:`quiet_thread`) before it starts drawing: a fork never copies a display half started (a display
#: thread holds the console's locks while it draws, which a forked child would inherit held).
FORK_LOCK = _threading.Lock()
_QUIET: set = set()  # the idents of the threads registered by quiet_thread that have not ended
if hasattr(_os, "register_at_fork"):  # a forked child has none of them (and may reuse their idents)
    _os.register_at_fork(after_in_child=_QUIET.clear)


def quiet_thread(thread):
    """Register ``thread`` (not started yet) as quiet: it waits (a timer) and takes :data:`FORK_LOCK` before it
    does anything else, so a fork while it waits copies nothing half done (:func:`others_quiet`). Returns it."""
    if not isinstance(thread, _threading.Thread):
        from .errors import WrongTypeError

        raise WrongTypeError(f"quiet_thread takes a threading.Thread, got {type(thread).__name__}")
    run = thread.run

    def quiet_run():
        _QUIET.add(_threading.get_ident())
        try:
            run()
        finally:
            _QUIET.discard(_threading.get_ident())

    thread.run = quiet_run
    return thread


def others_quiet() -> bool:
    """Whether every thread but the calling one is quiet (:func:`quiet_thread`): a process may fork then, holding
    :data:`FORK_LOCK` until the fork is done."""
    me = _threading.get_ident()
    return all(t.ident == me or t.ident in _QUIET for t in _threading.enumerate())


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

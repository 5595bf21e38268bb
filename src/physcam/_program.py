"""Whether this process is the ``physcam`` program: set by :func:`start` (called by
:func:`physcam.cli.run` and ``python -m physcam``), never by the library.

A module of its own (nothing imported) so that the program can say so at start without importing
what reads it (:mod:`physcam.figures`, which a report never needs: issue 43's start-up).
"""

RUNNING = False

#: The program's first threshold of the cyclic garbage collector (CPython's default: 700 container
#: objects allocated and not freed). Start-up builds some 18,000 long-lived objects (modules, classes,
#: functions, the sensor and glass tables): at 700 a `physcam report --lens` ran 24 young, 3 middle and
#: one full collection, each scanning what the last ones kept. Cycles are still collected, every 50,000
#: allocations; the library, imported, leaves the caller's setting alone (issue 43, docs/performance.md).
GC_THRESHOLD = 50_000


def start() -> None:
    """Mark this process as the program (:data:`RUNNING`) and set the collector's first threshold
    (:data:`GC_THRESHOLD`; the older generations' thresholds stay as they are)."""
    import gc

    global RUNNING
    RUNNING = True
    gc.set_threshold(GC_THRESHOLD, *gc.get_threshold()[1:])


#: Freed memory glibc's malloc keeps at the top of the heap in the program (M_TOP_PAD; glibc's default
#: 128 KiB). The numpy analyses make and free arrays of 0.1-10 MB by the thousand: at the default the heap
#: shrank and grew again 559 times in a cold `physcam mtf --lens dgauss_50mm` (brk calls), each page
#: faulted in anew (57,000 minor faults, 0.2-0.25 s of system time); with 64 MB, 12 brk calls and 22,000
#: faults, the same peak memory (docs/performance.md, issue 47 round 18).
HEAP_TOP_PAD = 64 << 20
_roomy: bool | None = None  # None: not asked yet in the program


def roomy_heap() -> bool:
    """In the program only (:data:`RUNNING`; a library caller's allocator is left alone), on glibc:
    keep :data:`HEAP_TOP_PAD` bytes of freed memory at the heap's top (``mallopt(M_TOP_PAD)``) before
    an analysis makes its large arrays. Called by the analyses that do (ctypes, 4 ms to import, stays
    off a report's path); asked once per process, whatever the answer. True when the setting is in force."""
    global _roomy
    if _roomy is not None or not RUNNING:
        return bool(_roomy)
    _roomy = False
    import os
    import sys

    try:
        if sys.platform.startswith("linux") and os.confstr("CS_GNU_LIBC_VERSION").startswith("glibc"):
            import ctypes

            _roomy = ctypes.CDLL("libc.so.6").mallopt(-2, HEAP_TOP_PAD) == 1  # M_TOP_PAD is -2 in glibc's malloc.h
    except (OSError, ValueError, AttributeError):
        pass
    return _roomy


def finish() -> None:
    """The program has answered and is about to exit (``sys.exit``): skip CPython's collection before
    the module teardown, which scans every object start-up built (about 5 ms of a ``physcam report``). The
    interpreter still finalises what is left after the teardown; physcam has no finalisers, and exit
    handlers (``atexit``: temporary folders, numba, matplotlib) have run before either collection."""
    import gc

    gc.disable()

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


def finish() -> None:
    """The program has answered and is about to exit (``sys.exit``): skip CPython's collection before
    the module teardown, which scans every object start-up built (about 5 ms of a ``physcam report``). The
    interpreter still finalises what is left after the teardown; physcam has no finalisers, and exit
    handlers (``atexit``: temporary folders, numba, matplotlib) have run before either collection."""
    import gc

    gc.disable()

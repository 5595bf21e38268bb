"""The compiled C kernel (``_ckernel``, built from ``_ckernel.c`` when physcam is installed) with the numpy
kernel's signature: the numba kernel's blocked passes compiled ahead of time, so tracing with it costs no
JIT load or compile (docs/ray-tracing.md, "Three kernels"; docs/install.md, "The fast path"). The same module
holds the Blender extension's rim pass in C (``_rimpass.c``: :func:`rim_points`, the signature of
:func:`._rimpass.rim_points`).

Imported only through :mod:`physcam.trace.kernels`, which also splits large batches into one range of blocks
per thread for it (:func:`physcam.trace.kernels.run_blocks`, the numba kernel's way: identical rays serial or
threaded; the C code releases the GIL). A table whose dtype is not the rays' (a mix no physcam caller makes)
goes to the numpy kernel: the C kernel traces in the rays' precision only.
"""

from __future__ import annotations

# ImportError where the extension was not built: the caller says how to get it. (Absolute: the extension has
# no .py source for the architecture tests to find.)
# isa: the instruction set the kernel runs, the widest this CPU has of the build's ("avx512", "avx2" on x86-64
# with GCC; else "baseline"); set_isa picks another of isa_levels() (tests: each gives the same rays)
from physcam.trace.kernels._ckernel import (  # noqa: F401  (compiled)
    BLOCK,
    isa,
    isa_levels,
    rim_counts,
    rim_write,
    set_isa,
    trace_blocks,
)


def trace_range(x, y, z, L, M, N, wl, w, wd, flag, S, kinds, clip, fresnel, end_z, has_end, mono, opl, b0, b1):
    """Blocks ``b0`` .. ``b1`` of the batch (the numba variants' ``(..., opl, b0, b1)`` shape, ``opl`` empty
    for none), on the calling thread without the GIL."""
    trace_blocks(x, y, z, L, M, N, wl, w, wd, flag, S, kinds, bool(clip), bool(fresnel), float(end_z),
                 bool(has_end), bool(mono), opl, b0, b1)


def mixed_precision(x, S) -> bool:
    """Whether the table's precision differs from the rays' (the numpy kernel traces those)."""
    return x.dtype != S.dtype


def rim_points(ok, rad, n_in, x0, y0, dx, dy, r0, r1, first_r0, wanted, radii, e_key, e_lo, e_hi, e_rad, n_rims):
    """(points, cuts): the rim points of the grids as :func:`._rimpass.rim_points` finds them (its arguments, as
    C-ordered int64, float64 and bool arrays; the numpy pass's points bit for bit), by the C pass: each rim's rows
    counted, then every point written in its rim's next row, each call without the GIL."""
    import numpy as np

    args = (ok, rad, n_in, x0, y0, dx, dy, r0, r1, first_r0, wanted, radii, e_key, e_lo, e_hi, e_rad)
    cuts = np.empty(n_rims + 1, dtype=np.int64)
    rim_counts(*args, cuts)
    out = np.empty((int(cuts[-1]), 4))
    rim_write(*args, cuts, out)
    return out, cuts

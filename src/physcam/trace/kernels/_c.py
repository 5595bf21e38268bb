"""The compiled C kernel (``_ckernel``, built from ``_ckernel.c`` when physcam is installed) with the numpy
kernel's signature: the numba kernel's blocked passes compiled ahead of time, so tracing with it costs no
JIT load or compile (docs/ray-tracing.md, "Three kernels"; docs/install.md, "The fast path").

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
from physcam.trace.kernels._ckernel import BLOCK, isa, isa_levels, set_isa, trace_blocks  # noqa: F401  (compiled)


def trace_range(x, y, z, L, M, N, wl, w, wd, flag, S, kinds, clip, fresnel, end_z, has_end, mono, opl, b0, b1):
    """Blocks ``b0`` .. ``b1`` of the batch (the numba variants' ``(..., opl, b0, b1)`` shape, ``opl`` empty
    for none), on the calling thread without the GIL."""
    trace_blocks(x, y, z, L, M, N, wl, w, wd, flag, S, kinds, bool(clip), bool(fresnel), float(end_z),
                 bool(has_end), bool(mono), opl, b0, b1)


def mixed_precision(x, S) -> bool:
    """Whether the table's precision differs from the rays' (the numpy kernel traces those)."""
    return x.dtype != S.dtype

"""Packed instructions in the JIT kernel's passes: a markdown table for docs/ray-tracing.md.

Run:  .venv/bin/python benchmarks/kernel_asm.py

Each pass of ``physcam.trace.kernels._numba`` is compiled afresh (numba cannot show the assembly
of cached code) for float64 and float32 scratch arrays, and its assembly (``inspect_asm``) is
searched for AVX instructions: how many use 512-bit (zmm) registers, how many packed (``ps``/``pd``)
ones use 256-bit (ymm) registers, the packed arithmetic by mnemonic, and the scalar square roots
and divisions (the epilogue of a block shorter than the vector width).
"""

import re
from collections import Counter

import llvmlite.binding as llvm
import numba
import numpy as np

from physcam.lens.library import load_lens
from physcam.trace.kernels import _numba as K
from physcam.trace.kernels._layout import pack, set_wavelength
from physcam.trace.surfaces import surface_table

ARITH = ("vsqrt", "vdiv", "vfmadd", "vfmsub", "vfnmadd", "vfnmsub", "vmul", "vadd", "vsub")


def passes(dt, S, s_asph):
    buf = np.zeros(K._NCOL * K.BLOCK, dtype=dt)
    m, f = K.BLOCK, dt(1.0)
    SS = S.astype(dt)
    return {
        "_intersect_plane": (buf, m, f), "_intersect_quadric": (buf, m, f, f, f, f), "_far_cap": (buf, m, f, f, f, f),
        "_newton_asphere": (buf, m, SS, s_asph, f), "_move_and_clip": (buf, m, f, True),
        "_normal_quadric": (buf, m, f, f, f, f), "_normalise": (buf, m), "_fill_n1": (buf, SS, 1, m),
        "_refract": (buf, m), "_fresnel_pass": (buf, m, f), "_to_plane": (buf, m, f)}


def main() -> None:
    lens = load_lens("canon_rf_85mm_f1_2")  # has even aspheres
    S, kinds = pack(surface_table(lens))
    set_wavelength(S, 587.5618)
    s_asph = int(np.flatnonzero(kinds == 3)[0])
    print(f"CPU {llvm.get_host_cpu_name()}, numba {numba.__version__}")
    print("| pass | precision | zmm instructions | ymm packed | packed arithmetic | scalar sqrt/div |")
    print("| --- | --- | --- | --- | --- | --- |")
    for dt in (np.float64, np.float32):
        for name, args in passes(dt, S, s_asph).items():
            g = getattr(K, name)
            opts = K._FMA_OPTS if name == "_fresnel_pass" else K._OPTS
            f = numba.njit(**(opts | {"cache": False}))(g.py_func)
            f(*args)
            asm = f.inspect_asm(f.signatures[0])
            c = Counter(re.findall(r"^\s+(v[a-z0-9]+)\s+.*?%([xyz])mm", asm, re.M))
            zmm = sum(v for (o, r), v in c.items() if r == "z")
            ymm = sum(v for (o, r), v in c.items() if r == "y" and o.endswith(("ps", "pd")))
            ops = Counter()
            for (o, r), v in c.items():
                if r in "yz" and o.startswith(ARITH) and o.endswith(("ps", "pd")):
                    ops[o] += v
            arith = ", ".join(f"{o} {v}" for o, v in sorted(ops.items()))
            scalar = len(re.findall(r"vsqrts[sd]|vdivs[sd]", asm))
            print(f"| `{name}` | {dt.__name__} | {zmm} | {ymm} | {arith} | {scalar} |")


if __name__ == "__main__":
    main()

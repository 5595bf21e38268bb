"""Compile physcam's JIT ray-tracing kernels into numba's disk cache ahead of use: `make test` runs it
beside its installs, so the suite's processes load the kernels instead of compiling them.

physcam compiles a kernel variant (physcam.trace.kernels._numba.variant: one wavelength or each ray's
own, optical path, Fresnel weights, aspheres; float64 or float32 rays) on its first use and caches it
on disk (trace/kernels/_jitcache.py). A fresh clone's cache is empty: the suite's first processes
(both xdist workers, the extension build's two processes, subprocesses started meanwhile) each compiled
the variants they met, the same ones side by side, and each of them judged numba "cold" for its whole
life, so physcam's "auto" backend kept batches on the slower numpy kernel (kernels.numba_load_cost).
tests/trace alone took 103.7 s CPU from an empty cache and 59.5 s from a warm one (2026-11-29).

Every feature set is compiled for float64 rays, and for float32 the one-wavelength sets without optical
path (what single-precision camera rays use) and the sets without optical path or Fresnel weights (the
defocus fans, one wavelength or three): 22 variants. Each is compiled by the JIT kernel's first call on a few rays and a bundled lens's
packed table (the double Gauss; the Canon RF 85 mm for aspheres), the call every traced command makes. Then
the Blender extension's rim pass (physcam.trace.kernels._rimpass), by one pupil table of the double Gauss.
Usage: ``python scripts/compile_jit.py`` (a second run loads the 22 variants in a few seconds).
"""

from __future__ import annotations

import itertools
import sys
import time

import numpy as np


def _rays(dtype, mono: bool):
    from physcam.trace.rays import RayBatch

    wl = 587.5618 if mono else np.array([486.1327, 587.5618, 656.2725, 587.5618])
    rays = RayBatch.collimated(np.array([0.0, 1.0, 2.0, 3.0]), np.zeros(4), -1.0, wavelength_nm=wl)
    return rays.astype(dtype) if dtype != np.float64 else rays


def main() -> int:
    from physcam.lens.library import load_lens
    from physcam.trace import kernels
    from physcam.trace.tables import packed_table

    if not kernels.numba_available():
        print("compile_jit: numba is not installed: nothing to compile")
        return 0
    kernel = kernels.get_kernel("numba")
    lenses = {False: load_lens("dgauss_50mm"), True: load_lens("canon_rf_85mm_f1_2")}
    t0, n = time.process_time(), 0
    for asphere, mono, opl, fresnel in itertools.product((False, True), repeat=4):
        # float32: camera rays (one wavelength, no optical path) and defocus fans (either mode, no Fresnel)
        for dtype in (np.float64, np.float32) if not opl and (mono or not fresnel) else (np.float64,):
            table = packed_table(lenses[asphere], dtype=dtype)
            assert (table.kinds.max() >= 3) == asphere  # the variant asked for: aspheres in the table or none
            rays = _rays(dtype, mono)
            S = table.at_wavelength(float(rays.wavelength_nm[0])) if mono else table.S
            kernel(*rays.columns(), S, table.kinds, True, fresnel, 0.0, False, mono,
                   np.zeros(rays.x.shape[0]) if opl else None)
            n += 1
    # the Blender extension's compiled rim pass (kernels.rim_pass), by the pupil table that calls it: one signature
    from physcam.export.blender_pupil import iris_levels, radial_pupil_table
    from physcam.optics.focusing import focus

    st = focus(lenses[False], 2500.0)
    stop = st.prescription.surfaces[st.prescription.stop_index].semi_diameter
    radial_pupil_table(st.prescription, st.film_z, iris_levels(stop, stop), backend="numba")
    print(f"compile_jit: {n} kernel variants and the pupil tables' rim pass compiled or loaded in "
          f"{time.process_time() - t0:.1f} s CPU")
    return 0


if __name__ == "__main__":
    sys.exit(main())

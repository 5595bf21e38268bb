"""Column layout of the packed surface array shared by the kernels (no numba import here)."""

from __future__ import annotations

import numpy as np

VZ, AX, AY, AZ, CV, CK, SEMI, NBA, NBB, NAA, NAB, RSC, UNIT, N1, N2, ETA, A4 = range(17)
N_COLS = A4 + 7

OK, MISSED, CLIPPED, TIR = 0, 1, 2, 3

#: Newton iteration for an even asphere: stop when the step is below this (mm), or fail.
NEWTON_TOL = 1e-12
NEWTON_MAX_ITER = 40


def pack(table):
    """(float64 (n, N_COLS) array, int64 kinds) from a :class:`~physcam.trace.surfaces.SurfaceTable`."""
    n = len(table)
    s = np.zeros((n, N_COLS), dtype=np.float64)
    s[:, VZ] = table.vertex_z
    s[:, AX] = table.ax
    s[:, AY] = table.ay
    s[:, AZ] = table.az
    s[:, CV] = table.curvature
    s[:, CK] = table.conic
    s[:, SEMI] = table.semi_diameter
    s[:, NBA] = table.n_before_a
    s[:, NBB] = table.n_before_b
    s[:, NAA] = table.n_after_a
    s[:, NAB] = table.n_after_b
    s[:, RSC] = table.r_scale
    s[:, A4:] = table.aspheric
    # 1 where the quadric gradient (ax x, ay y, az z - 1) is already a unit vector on the surface:
    # spheres, cylinders (|grad|^2 = c (c r^2 - 2 z) + 1 = 1) and planes; conics need normalising.
    s[:, UNIT] = ((table.kind <= 1) | ((table.kind == 2) & (table.conic == 0.0))).astype(np.float64)
    return np.ascontiguousarray(s), np.ascontiguousarray(table.kind, dtype=np.int64)


def set_wavelength(S, wavelength_nm: float) -> None:
    """Fill the N1, N2, ETA columns for a batch of one wavelength (the kernels' ``mono`` path).

    Same arithmetic as the per-ray path (n = A + B * (1 / lambda^2), eta = n1 / n2), so both
    paths give bit-identical rays.
    """
    with np.errstate(divide="ignore", over="ignore", invalid="ignore"):
        il2 = np.float64(1.0) / (np.float64(wavelength_nm) * np.float64(wavelength_nm))
        S[:, N1] = S[:, NBA] + S[:, NBB] * il2
        S[:, N2] = S[:, NAA] + S[:, NAB] * il2
        S[:, ETA] = S[:, N1] / S[:, N2]

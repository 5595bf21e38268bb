"""Column layout of the packed surface array shared by the kernels (no numba import here; numpy only
when a table is packed, so the constants load without it)."""

from __future__ import annotations

VZ, AX, AY, AZ, CV, CK, SEMI, RSC, UNIT, N1, N2, ETA, SB, SA = range(14)
#: 9 dispersion coefficients (a0 a1 a2 B1 B2 B3 C1 C2 C3, :func:`physcam.optics.glass.evaluate`)
#: of the medium before (from NB) and after (from NA) each surface; SB, SA are 1 where that
#: medium has Sellmeier terms.
NB = 14
NA = NB + 9
A4 = NA + 9
N_COLS = A4 + 7

OK, MISSED, CLIPPED, TIR = 0, 1, 2, 3

#: Newton iteration for an even asphere: stop when the step is below this (mm), or fail.
NEWTON_TOL = 1e-12
NEWTON_MAX_ITER = 40


def pack(table):
    """(float64 (n, N_COLS) array, int64 kinds) from a :class:`~physcam.trace.surfaces.SurfaceTable`."""
    import numpy as np

    n = len(table)
    s = np.zeros((n, N_COLS), dtype=np.float64)
    s[:, VZ] = table.vertex_z
    s[:, AX] = table.ax
    s[:, AY] = table.ay
    s[:, AZ] = table.az
    s[:, CV] = table.curvature
    s[:, CK] = table.conic
    s[:, SEMI] = table.semi_diameter
    s[:, NB:NB + 9] = table.disp_before
    s[:, NA:NA + 9] = table.disp_after
    s[:, SB] = (table.disp_before[:, 3:6] != 0.0).any(axis=1)
    s[:, SA] = (table.disp_after[:, 3:6] != 0.0).any(axis=1)
    s[:, RSC] = table.r_scale
    s[:, A4:] = table.aspheric
    # 1 where the quadric gradient (ax x, ay y, az z - 1) is already a unit vector on the surface:
    # spheres, cylinders (|grad|^2 = c (c r^2 - 2 z) + 1 = 1) and planes; conics need normalising.
    s[:, UNIT] = ((table.kind <= 1) | ((table.kind == 2) & (table.conic == 0.0))).astype(np.float64)
    return np.ascontiguousarray(s), np.ascontiguousarray(table.kind, dtype=np.int64)


def index_rows(S, first, flag, wavelength_nm):
    """Index of one medium per row at one wavelength: the arithmetic of
    :func:`physcam.optics.glass.evaluate` (and of the kernels' per-ray path), so all agree bitwise."""
    import numpy as np

    lam = np.float64(wavelength_nm)
    l2 = (lam / 1000.0) * (lam / 1000.0)
    u = 1.0 / l2
    c = S[:, first:first + 9]
    n = c[:, 0] + (c[:, 1] + c[:, 2] * u) * u
    sq = np.sqrt(1.0 + c[:, 3] * l2 / (l2 - c[:, 6]) + c[:, 4] * l2 / (l2 - c[:, 7]) + c[:, 5] * l2 / (l2 - c[:, 8]))
    return np.where(S[:, flag] != 0.0, n + sq, n)


def set_wavelength(S, wavelength_nm: float) -> None:
    """Fill the N1, N2, ETA columns for a batch of one wavelength (the kernels' ``mono`` path).

    Same arithmetic as the per-ray path (:func:`index_rows`, eta = n1 / n2), so both paths give
    bit-identical rays.
    """
    import numpy as np

    with np.errstate(divide="ignore", over="ignore", invalid="ignore"):
        S[:, N1] = index_rows(S, NB, SB, wavelength_nm)
        S[:, N2] = index_rows(S, NA, SA, wavelength_nm)
        S[:, ETA] = S[:, N1] / S[:, N2]

"""The compiled rim pass of the Blender extension's pupil tables: the rim points of traced aim grids.

The same points, in the same order and by the same IEEE operations, as the numpy pass in
:func:`physcam.export.blender_pupil_sets._rims` (the reference; its notes have the geometry): per grid,
toward +x, -x and +y, every pair of neighbouring samples where one passes at an iris radius and the
other does not gives a rim point at that radius (the stop radius interpolated to it, or the halved
clip edge), and every passing sample on the grid's edge a point a step out. The numpy pass builds
each point in whole arrays and then sorts the 250,000 points of a table by rim; this one loops over
the pairs twice (count the points per rim, then write each in its rim's slot), so no sort and none
of the gathers. Imported only through :mod:`physcam.trace.kernels` (:func:`~physcam.trace.kernels.rim_pass`),
cached on disk as the tracer's kernels are (:mod:`._jitcache`). ``_rimpass.c`` is the same loops in C, built into
the C kernel's module (:func:`._c.rim_points`, this signature): "auto" takes that one where it is built, and this
one for "numba" (``backend`` or ``PHYSCAM_BACKEND``) or where only numba is.
"""

from __future__ import annotations

import numba as nb
import numpy as np

from . import _jitcache

_CACHE = _jitcache.install()  # before any @njit below: cache keyed by version and sources (else none)
#: IEEE arithmetic (no contraction): the points are the numpy pass's bit for bit
_OPTS = dict(fastmath=False, error_model="numpy", nogil=True, cache=_CACHE)

# toward +x, -x, +y (blender_pupil_sets._TOWARD): the view's rows and columns less, the sample's (a) and
# the neighbour's (b) offsets in the grid, the step's direction
_DIRS = np.array([[0, 1, 0, 0, 0, 1, 1, 0], [0, 1, 0, 1, 0, 0, -1, 0], [1, 0, 0, 0, 1, 0, 0, 1]], dtype=np.int64)


@nb.njit(**_OPTS)
def _first_at_least(a, v):
    """The first index of the ascending ``a`` whose value is at least ``v`` (np.searchsorted's left side)."""
    lo, hi = 0, a.shape[0]
    while lo < hi:
        mid = (lo + hi) >> 1
        if a[mid] < v:
            lo = mid + 1
        else:
            hi = mid
    return lo


@nb.njit(**_OPTS)
def _spans(n_in, r0, r1, span):
    """Each pair's (and edge sample's) radius index range [lo, hi) of :func:`_write`, marked in ``span``
    (+1 at lo, -1 at hi per grid: a rim's points are the running sum at its radius)."""
    n_grid, ny, nx = n_in.shape
    for g in range(n_grid):
        for d in range(3):
            less_j, less_i, ja0, ia0 = _DIRS[d, 0], _DIRS[d, 1], _DIRS[d, 2], _DIRS[d, 3]
            jb0, ib0 = _DIRS[d, 4], _DIRS[d, 5]
            for jj in range(ny - less_j):
                for ii in range(nx - less_i):
                    lo, hi = max(n_in[g, jj + jb0, ii + ib0], r0[g]), min(n_in[g, jj + ja0, ii + ia0], r1[g])
                    if hi > lo:
                        span[g, lo] += 1
                        span[g, hi] -= 1
        for e in range(3):
            for c in range(ny if e < 2 else nx):
                jj = c if e < 2 else ny - 1
                ii = 0 if e == 0 else (nx - 1 if e == 1 else c)
                lo, hi = r0[g], min(n_in[g, jj, ii], r1[g])
                if hi > lo:
                    span[g, lo] += 1
                    span[g, hi] -= 1


@nb.njit(**_OPTS)
def _write(ok, rad, n_in, x0, y0, dx, dy, r0, r1, first_r0, w_at, w_idx, radii, e_key, e_lo, e_hi, e_rad, cur, out):
    """Every rim point of every grid written to ``out[cur[k]]`` (x, y, xa, ya), ``cur[k]`` advanced: each
    pair's (or edge sample's) points at the wanted radius indices ``w_idx[w_at[g, lo]:w_at[g, hi]]`` of
    its grid g (k = first_r0[g] + the radius index), in the numpy pass's order within each rim."""
    n_grid, ny, nx = ok.shape
    for g in range(n_grid):
        for d in range(3):
            less_j, less_i, ja0, ia0 = _DIRS[d, 0], _DIRS[d, 1], _DIRS[d, 2], _DIRS[d, 3]
            jb0, ib0, sx, sy = _DIRS[d, 4], _DIRS[d, 5], _DIRS[d, 6], _DIRS[d, 7]
            step = sx * dx[g] + sy * dy[g]
            for jj in range(ny - less_j):
                for ii in range(nx - less_i):
                    ja, ia, jb, ib = jj + ja0, ii + ia0, jj + jb0, ii + ib0
                    lo, hi = max(n_in[g, jb, ib], r0[g]), min(n_in[g, ja, ia], r1[g])
                    if hi <= lo:
                        continue
                    ra = rad[g, ja, ia]
                    r_e, e1, e_mid = np.inf, 1.0, 1.0
                    if ok[g, jb, ib]:
                        rate = 1.0 / (rad[g, jb, ib] - ra)
                    else:
                        at = _first_at_least(e_key, (g * 3 + d) * (ny * nx) + jj * nx + ii)
                        r_e, rate = e_rad[at], e_lo[at] / (e_rad[at] - ra)
                        e1, e_mid = e_hi[at], 0.5 * (e_lo[at] + e_hi[at])
                    if sx != 0:
                        base, other = x0[g] + ia * dx[g], y0[g] + ja * dy[g]
                    else:
                        base, other = y0[g] + ja * dy[g], x0[g] + ia * dx[g]
                    for w in range(w_at[g, lo], w_at[g, hi]):
                        i = w_idx[w]
                        s = radii[i]
                        f = (s - ra) * rate  # clipped to [0, 1] as np.clip does (NaN and -0.0 kept)
                        if f < 0.0:
                            f = 0.0
                        elif f > 1.0:
                            f = 1.0
                        fa = f
                        if not s < r_e:
                            f, fa = e1, e_mid
                        k = first_r0[g] + i
                        p = cur[k]
                        cur[k] = p + 1
                        if sx != 0:
                            out[p, 0], out[p, 1], out[p, 2], out[p, 3] = base + step * f, other, base + step * fa, other
                        else:
                            out[p, 0], out[p, 1], out[p, 2], out[p, 3] = other, base + step * f, other, base + step * fa
        for e in range(3):  # past the grid's edge (column 0, column nx - 1, row ny - 1): a step out
            for c in range(ny if e < 2 else nx):
                jj = c if e < 2 else ny - 1
                ii = 0 if e == 0 else (nx - 1 if e == 1 else c)
                lo, hi = r0[g], min(n_in[g, jj, ii], r1[g])
                if hi <= lo:
                    continue
                bx, by = x0[g] + ii * dx[g], y0[g] + jj * dy[g]
                ex = -1 * dx[g] if e == 0 else (1 * dx[g] if e == 1 else 0.0)
                ey = 1 * dy[g] if e == 2 else 0.0
                for w in range(w_at[g, lo], w_at[g, hi]):
                    k = first_r0[g] + w_idx[w]
                    p = cur[k]
                    cur[k] = p + 1
                    out[p, 0], out[p, 1], out[p, 2], out[p, 3] = bx + ex, by + ey, bx + ex / 2, by + ey / 2


def rim_points(ok, rad, n_in, x0, y0, dx, dy, r0, r1, first_r0, wanted, radii, e_key, e_lo, e_hi, e_rad, n_rims):
    """(points, cuts): the rim points (columns x, y, xa, ya) of the grids (``ok``, ``rad``, ``n_in``: (grids,
    ny, nx) bool, float64, int64) rim after rim, rim k's rows ``cuts[k]`` to ``cuts[k + 1]``, in the numpy
    pass's order (blender_pupil_sets._rims: its arguments, as C-ordered int64, float64 and bool arrays)."""
    n_grid, n_rad = wanted.shape
    # the wanted radius indices grid after grid (w_idx), and per grid how many lie below each radius index
    w_idx = np.nonzero(wanted)[1].astype(np.int64)
    w_at = np.zeros((n_grid, n_rad + 1), dtype=np.int64)
    np.cumsum(wanted, axis=1, out=w_at[:, 1:])
    w_at += np.concatenate([[0], np.cumsum(w_at[:-1, -1])])[:, None]
    span = np.zeros((n_grid, n_rad + 1), dtype=np.int64)
    _spans(n_in, r0, r1, span)
    # a rim's points: the running sum of the spans at its radius (the rims: each grid's radii r0 to r1)
    count = np.where(wanted, np.cumsum(span[:, :-1], axis=1), 0)
    own = (np.arange(n_rad) >= r0[:, None]) & (np.arange(n_rad) < r1[:, None])
    cuts = np.zeros(n_rims + 1, dtype=np.int64)
    np.cumsum(count[own], out=cuts[1:])
    out = np.empty((int(cuts[-1]), 4))
    _write(ok, rad, n_in, x0, y0, dx, dy, r0, r1, first_r0, w_at, w_idx, radii, e_key, e_lo, e_hi, e_rad,
           cuts[:-1].copy(), out)
    return out, cuts

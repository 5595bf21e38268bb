"""The JIT kernel: rays in blocks, each block traced surface by surface.

Same algorithm, order of operations and answers as :mod:`._numpy` (see that module and
docs/ray-tracing.md for the maths). Imported only through :mod:`physcam.trace.kernels`.

Layout: ``prange`` over blocks of :data:`BLOCK` rays; for each surface an inner loop over the
block's rays. One ray through eleven surfaces is a long chain of dependent square roots and
divisions (latency-bound); looping over independent rays innermost lets the CPU overlap them,
which measured about 2x faster than one ray through all surfaces per iteration.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from ._layout import A4, AX, AY, AZ, CK, CV, ETA, N1, N2, NA, NB, NEWTON_MAX_ITER, NEWTON_TOL, SA, SB
from ._layout import CLIPPED, MISSED, RSC, SEMI, TIR, UNIT, VZ

_FLAT, _STOP, _QUADRIC, _ASPHERE = 0, 1, 2, 3

#: Rays per block: 9 float64 columns x 256 rays stay in the L1 cache.
BLOCK = 256


@nb.njit(inline="always", fastmath=False)
def _index(S, s, c, flag, l2, u):
    """physcam.optics.glass.evaluate, same order of operations (9 coefficients from column c)."""
    n = S[s, c] + (S[s, c + 1] + S[s, c + 2] * u) * u
    if S[s, flag] != 0.0:
        n = n + math.sqrt(1.0 + S[s, c + 3] * l2 / (l2 - S[s, c + 6]) + S[s, c + 4] * l2 / (l2 - S[s, c + 7])
                          + S[s, c + 5] * l2 / (l2 - S[s, c + 8]))
    return n


@nb.njit(parallel=True, fastmath=False, cache=True, nogil=True)
def trace_rays(x, y, z, L, M, N, wl, w, wd, flag, S, kinds, clip, fresnel, end_z, has_end, mono):
    """Trace rays in place through the rows of ``S`` (tracing order), then to the plane ``end_z``."""
    ns = S.shape[0]
    n = x.shape[0]
    nblocks = (n + BLOCK - 1) // BLOCK
    for blk in nb.prange(nblocks):
        i0 = blk * BLOCK
        i1 = min(n, i0 + BLOCK)
        uu = np.empty(i1 - i0)
        ll = np.empty(i1 - i0)
        for i in range(i0, i1):
            # -- a live ray's weights must be finite (else MISSED, weight 0). A NaN/inf position
            # or direction needs no test here: it makes the first hit point or incidence cosine
            # NaN/inf, which the surface loop flags. The wavelength of a mixed batch is checked
            # below; a one-wavelength batch's in trace_packed.
            v = w[i] + wd[i]
            if flag[i] == 0 and not (v - v == 0.0):
                flag[i] = MISSED
                w[i] = 0.0
                wd[i] = 0.0
            if not mono:
                l2 = (wl[i] / 1000.0) * (wl[i] / 1000.0)
                ll[i - i0] = l2
                uu[i - i0] = 1.0 / l2
                if flag[i] == 0 and not (wl[i] > 0.0 and uu[i - i0] - uu[i - i0] == 0.0):
                    flag[i] = MISSED
                    w[i] = 0.0
                    wd[i] = 0.0
        for s in range(ns):
            kd = kinds[s]
            vz = S[s, VZ]
            ax = S[s, AX]
            ay = S[s, AY]
            az = S[s, AZ]
            sd2 = S[s, SEMI] * S[s, SEMI]
            unit = S[s, UNIT] != 0.0
            rsc = S[s, RSC]
            cv = S[s, CV]
            ck1 = (1.0 + S[s, CK]) * cv * cv
            for i in range(i0, i1):
                if flag[i] != 0:
                    continue
                px = x[i]
                py = y[i]
                pz = z[i]
                dx = L[i]
                dy = M[i]
                dz = N[i]
                qz = pz - vz
                # -- intersection: nearest-vertex root of ax x^2 + ay y^2 + az z^2 - 2 z = 0
                if kd <= _STOP:
                    if dz == 0.0:
                        flag[i] = MISSED
                        w[i] = 0.0
                        wd[i] = 0.0
                        continue
                    t = -qz / dz
                else:
                    a = ax * dx * dx + ay * dy * dy + az * dz * dz
                    b = ax * px * dx + ay * py * dy + az * qz * dz - dz
                    c = ax * px * px + ay * py * py + az * qz * qz - 2.0 * qz
                    disc = b * b - a * c
                    if disc < 0.0:
                        flag[i] = MISSED
                        w[i] = 0.0
                        wd[i] = 0.0
                        continue
                    sq = math.sqrt(disc)
                    den = -b - sq if b >= 0.0 else -b + sq
                    if den == 0.0:
                        flag[i] = MISSED
                        w[i] = 0.0
                        wd[i] = 0.0
                        continue
                    t = c / den
                    # nearest root on the far cap (back of a sphere): use the vertex branch,
                    # where az * z < 1 (see the numpy kernel)
                    if az * (qz + t * dz) >= 1.0:
                        if a == 0.0:
                            flag[i] = MISSED
                            w[i] = 0.0
                            wd[i] = 0.0
                            continue
                        t = den / a
                        if not az * (qz + t * dz) < 1.0:
                            flag[i] = MISSED
                            w[i] = 0.0
                            wd[i] = 0.0
                            continue
                dsr = 0.0
                if kd == _ASPHERE:
                    # -- Newton iteration on g(t) = z(t) - sag(r(t)), started at the conic root
                    conv = False
                    for _it in range(NEWTON_MAX_ITER):
                        X = px + t * dx
                        Y = py + t * dy
                        Z = qz + t * dz
                        r2 = X * X + Y * Y
                        arg = 1.0 - ck1 * r2
                        if arg < 0.0:
                            break
                        sa = math.sqrt(arg)
                        sag = cv * r2 / (1.0 + sa)
                        dsr = cv / sa
                        p = r2 * r2
                        q = r2
                        for j in range(7):
                            aj = S[s, A4 + j]
                            sag = sag + aj * p
                            dsr = dsr + (2.0 * j + 4.0) * aj * q
                            p = p * r2
                            q = q * r2
                        g = Z - sag
                        gp = dz - dsr * (X * dx + Y * dy)
                        if gp == 0.0:
                            break
                        dt = g / gp
                        t = t - dt
                        if abs(dt) < NEWTON_TOL:
                            conv = True
                            break
                    X = px + t * dx
                    Y = py + t * dy
                    r2 = X * X + Y * Y
                    arg = 1.0 - ck1 * r2
                    if not conv or arg < 0.0:
                        flag[i] = MISSED
                        w[i] = 0.0
                        wd[i] = 0.0
                        continue
                    dsr = cv / math.sqrt(arg)
                    q = r2
                    for j in range(7):
                        dsr = dsr + (2.0 * j + 4.0) * S[s, A4 + j] * q
                        q = q * r2
                hx = px + t * dx
                hy = py + t * dy
                hz = pz + t * dz
                # -- clip at the clear semi-diameter (and the stop). One comparison also catches a
                # hit point that is not finite (overflow or 0/0 on huge or degenerate input): NaN
                # fails every comparison. hz needs no test: a NaN/inf t makes hx NaN/inf too, and
                # with a finite t, hz lies on the surface near its vertex.
                r2 = hx * hx + hy * hy
                if not (r2 <= sd2):
                    if not (r2 - r2 == 0.0):
                        flag[i] = MISSED
                        w[i] = 0.0
                        wd[i] = 0.0
                        continue
                    if clip:
                        flag[i] = CLIPPED
                        w[i] = 0.0
                        wd[i] = 0.0
                        continue
                x[i] = hx
                y[i] = hy
                z[i] = hz
                if kd == _STOP:
                    continue
                if mono:
                    n1 = S[s, N1]
                    n2 = S[s, N2]
                    eta = S[s, ETA]
                else:
                    n1 = _index(S, s, NB, SB, ll[i - i0], uu[i - i0])
                    n2 = _index(S, s, NA, SA, ll[i - i0], uu[i - i0])
                    eta = n1 / n2
                if n1 == n2:
                    continue
                # -- unit surface normal, pointing to -z at the vertex
                if kd == _FLAT:
                    gx = 0.0
                    gy = 0.0
                    gz = -1.0
                elif kd == _QUADRIC:
                    gx = ax * hx
                    gy = ay * hy
                    gz = az * (hz - vz) - 1.0
                else:
                    gx = dsr * hx
                    gy = dsr * hy
                    gz = -1.0
                if not unit:
                    inv = 1.0 / math.sqrt(gx * gx + gy * gy + gz * gz)
                    gx = gx * inv
                    gy = gy * inv
                    gz = gz * inv
                ci = dx * gx + dy * gy + dz * gz
                if ci < 0.0:
                    gx = -gx
                    gy = -gy
                    gz = -gz
                    ci = -ci
                # -- Snell's law in vector form; total internal reflection
                kk = 1.0 - eta * eta * (1.0 - ci * ci)
                if not (kk >= 0.0):
                    # kk < 0 with a finite normal: TIR; NaN/inf (a degenerate normal, 0/0): MISSED.
                    # A finite normal and kk >= 0 give a finite refracted direction.
                    flag[i] = TIR if (kk < 0.0 and ci - ci == 0.0) else MISSED
                    w[i] = 0.0
                    wd[i] = 0.0
                    continue
                ct = math.sqrt(kk)
                if fresnel:
                    # s and p separately (see _numpy.py): w = (A + B) / 2, wd = (A - B) / 2
                    ec = eta * ci
                    et = eta * ct
                    sm = (ec - ct) * (ci + et)
                    pm = (ci - et) * (ec + ct)
                    sp = (ec + ct) * (ci + et)
                    q = rsc / (sp * sp)
                    rs = sm * sm * q
                    if not rs < 1.0:
                        rs = 1.0
                    rp = pm * pm * q
                    if not rp < 1.0:
                        rp = 1.0
                    hsum = 1.0 - 0.5 * (rs + rp)
                    hdif = 0.5 * (rp - rs)
                    w0 = w[i]
                    d0 = wd[i]
                    w[i] = w0 * hsum + d0 * hdif
                    wd[i] = w0 * hdif + d0 * hsum
                f = ct - eta * ci
                L[i] = eta * dx + f * gx
                M[i] = eta * dy + f * gy
                N[i] = eta * dz + f * gz
        if has_end:
            for i in range(i0, i1):
                if flag[i] != 0:
                    continue
                if N[i] == 0.0:
                    flag[i] = MISSED
                    w[i] = 0.0
                    wd[i] = 0.0
                    continue
                t = (end_z - z[i]) / N[i]
                hx = x[i] + t * L[i]
                hy = y[i] + t * M[i]
                if not (math.isfinite(hx) and math.isfinite(hy)):
                    flag[i] = MISSED
                    w[i] = 0.0
                    wd[i] = 0.0
                    continue
                x[i] = hx
                y[i] = hy
                z[i] = end_z

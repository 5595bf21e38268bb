"""The vectorised numpy kernel: the surfaces in a loop, all live rays at once.

Same signature and answers as the JIT kernel. Per surface:

1. Intersection: the root nearest the vertex of the quadric ax x^2 + ay y^2 + az z^2 - 2 z = 0
   along p + t d, written t = c / (-b - sign(b) sqrt(b^2 - a c)) so it stays exact as the
   curvature goes to 0 (a plane). Sequential tracing: t may be negative (virtual propagation).
2. Even asphere: Newton iteration on g(t) = z(t) - sag(r(t)) from the conic root.
3. Clipping at the clear semi-diameter (and the stop).
4. Refraction: Snell's law in vector form, t = eta d + (cos t - eta cos i) n with n the unit
   normal on the side the ray travels to (Hecht, *Optics*, §4.4; Welford, *Aberrations of Optical
   Systems*, §4.3); total internal reflection when 1 - eta^2 (1 - cos^2 i) < 0.
5. Fresnel: s and p transmittances carried separately (see :mod:`physcam.trace.fresnel`):
   the weight is the mean of the s and p throughputs, ``wd`` half their difference.

Rays that start non-finite, or whose hit point or incidence cosine is not finite (overflow on
huge inputs, a degenerate normal), are flagged MISSED; the checks ride on the clipping and TIR
comparisons (NaN fails every comparison), so the common path pays nothing extra.

Rays that fail keep their last finite position and direction, get weight 0 and a flag.
"""

from __future__ import annotations

import numpy as np

from ._layout import A4, AX, AY, AZ, CK, CV, NA, NB, NEWTON_MAX_ITER, NEWTON_TOL, RSC, SA, SB, SEMI, UNIT, VZ
from ._layout import ETA, N1, N2
from ._layout import CLIPPED, MISSED, TIR

_FLAT, _STOP, _QUADRIC, _ASPHERE = 0, 1, 2, 3
#: Rays per slice: the per-surface temporaries (a few dozen arrays of this length, 128 KiB each)
#: stay in the L2 cache: 5e5 rays through dgauss_50mm, 32 ns per ray and surface against 62 in
#: slices of 2^18 (docs/ray-tracing.md).
SLICE = 1 << 14


def _index(S, s, c, flag, l2, u):
    """physcam.optics.glass.evaluate per ray, same order of operations (9 coefficients from column c)."""
    n = S[s, c] + (S[s, c + 1] + S[s, c + 2] * u) * u
    if S[s, flag] != 0.0:
        n = n + np.sqrt(1.0 + S[s, c + 3] * l2 / (l2 - S[s, c + 6]) + S[s, c + 4] * l2 / (l2 - S[s, c + 7])
                        + S[s, c + 5] * l2 / (l2 - S[s, c + 8]))
    return n


def trace_rays(x, y, z, L, M, N, wl, w, wd, flag, S, kinds, clip, fresnel, end_z, has_end, mono, opl=None):
    """Trace rays in place through the rows of ``S`` (tracing order), then to the plane ``end_z``.

    ``opl`` (float64, one per ray), if given: each leg's optical path n (p' - p) . d = n t |d|^2
    to each row of ``S`` (n the index before it; t < 0 on a virtual leg counts negative) is added
    to it in place, for the rays that reach the row inside its clear aperture (not the leg to
    ``end_z``). Large batches go through in slices of :data:`SLICE` rays."""
    n = x.shape[0]
    if n > SLICE:
        for a in range(0, n, SLICE):
            b = slice(a, min(n, a + SLICE))
            trace_rays(x[b], y[b], z[b], L[b], M[b], N[b], wl[b], w[b], wd[b], flag[b], S, kinds, clip, fresnel,
                       end_z, has_end, mono, None if opl is None else opl[b])
        return
    # One piece on purpose (issue 28): one pass per surface over the whole batch of live rays, the
    # steps (module notes 1-5) in the numba kernel's order so that the two backends give
    # the same answers. The steps share ten live-ray arrays that shrink as rays fail (``fail``
    # rebinds them); helpers would have to take and hand back all ten at every step.
    # a live ray must start with finite weights and a usable wavelength (else MISSED, weight 0)
    # (the numba kernel's test: finite weights, a wavelength > 0 with a finite 1/l^2; a non-finite
    # position or direction is caught at the first surface)
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        v = w + wd
        u = 1.0 / ((wl / 1000.0) * (wl / 1000.0))
        unusable = (flag == 0) & ~((v - v == 0.0) & (wl > 0.0) & (u - u == 0.0))
    if unusable.any():
        flag[unusable] = MISSED
        w[unusable] = 0.0
        wd[unusable] = 0.0
    live = np.flatnonzero(flag == 0)
    px, py, pz = x[live], y[live], z[live]
    dx, dy, dz = L[live], M[live], N[live]
    with np.errstate(divide="ignore", over="ignore"):
        l2 = (wl[live] / 1000.0) * (wl[live] / 1000.0)
        il2 = 1.0 / l2
    wt = w[live].copy()
    wdt = wd[live].copy()

    def fail(bad, code):
        nonlocal live, px, py, pz, dx, dy, dz, il2, l2, wt, wdt
        if not bad.any():
            return
        j = live[bad]
        x[j], y[j], z[j] = px[bad], py[bad], pz[bad]
        L[j], M[j], N[j] = dx[bad], dy[bad], dz[bad]
        flag[j] = code
        w[j] = 0.0
        wd[j] = 0.0
        keep = ~bad
        live = live[keep]
        px, py, pz, dx, dy, dz, il2, l2, wt, wdt = (
            a[keep] for a in (px, py, pz, dx, dy, dz, il2, l2, wt, wdt))

    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        for s in range(S.shape[0]):
            if live.size == 0:
                break
            kd = int(kinds[s])
            qz = pz - S[s, VZ]
            if kd <= _STOP:
                fail(dz == 0.0, MISSED)
                qz = pz - S[s, VZ]
                t = -qz / dz
            else:
                ax, ay, az = S[s, AX], S[s, AY], S[s, AZ]
                a = ax * dx * dx + ay * dy * dy + az * dz * dz
                b = ax * px * dx + ay * py * dy + az * qz * dz - dz
                c = ax * px * px + ay * py * py + az * qz * qz - 2.0 * qz
                disc = b * b - a * c
                sq = np.sqrt(np.maximum(disc, 0.0))
                # the forward crossing (numba kernel, _intersect_quadric): f falls through zero
                # (np.where costs several multiplications' time; these give the same numbers)
                sgn = (dz >= 0.0) * 2.0 - 1.0
                same = b * sgn >= 0.0
                if not same.any():
                    num, den = c, -b + sgn * sq
                elif same.all():
                    num, den = -b - sgn * sq, a
                else:
                    num = np.where(same, -b - sgn * sq, c)
                    den = np.where(same, a, -b + sgn * sq)
                t = num / den
                bad = (disc < 0.0) | (den == 0.0) | ~(az * (qz + t * dz) < 1.0)
                if bad.any():
                    fail(bad, MISSED)
                    t = t[~bad]
                    qz = pz - S[s, VZ]
            if kd == _ASPHERE:
                cv = S[s, CV]
                ck1 = (1.0 + S[s, CK]) * cv * cv
                coef = S[s, A4:]
                done = np.zeros(live.size, dtype=bool)
                broken = np.zeros(live.size, dtype=bool)
                for _it in range(NEWTON_MAX_ITER):
                    X = px + t * dx
                    Y = py + t * dy
                    Z = qz + t * dz
                    r2 = X * X + Y * Y
                    arg = 1.0 - ck1 * r2
                    sa = np.sqrt(arg)
                    sag = cv * r2 / (1.0 + sa)
                    dsr = cv / sa
                    p = r2 * r2
                    q = r2
                    for j in range(7):
                        sag = sag + coef[j] * p
                        dsr = dsr + (2.0 * j + 4.0) * coef[j] * q
                        p = p * r2
                        q = q * r2
                    g = Z - sag
                    gp = dz - dsr * (X * dx + Y * dy)
                    step = ~done & ~broken
                    broken |= step & ((arg < 0.0) | (gp == 0.0))
                    step &= ~broken
                    dt = np.where(step, g / gp, 0.0)
                    t = t - dt
                    done |= step & (np.abs(dt) < NEWTON_TOL)
                    if (done | broken).all():
                        break
                bad = ~done
                X = px + t * dx
                Y = py + t * dy
                r2 = X * X + Y * Y
                arg = 1.0 - ck1 * r2
                bad |= arg < 0.0
                dsr = cv / np.sqrt(arg)
                q = r2
                for j in range(7):
                    dsr = dsr + (2.0 * j + 4.0) * coef[j] * q
                    q = q * r2
                if bad.any():
                    fail(bad, MISSED)
                    t = t[~bad]
                    dsr = dsr[~bad]
            nx_ = px + t * dx
            ny_ = py + t * dy
            nz_ = pz + t * dz
            if opl is not None:
                leg = t * (dx * dx + dy * dy + dz * dz)
            # clip; the same comparison catches a hit point that is not finite (overflow or 0/0
            # on huge or degenerate input): 0 * inf is NaN, which fails every comparison
            r2 = nx_ * nx_ + ny_ * ny_  # (hz: see the numba kernel)
            bad = ~(r2 - r2 == 0.0)
            if clip:
                sd = S[s, SEMI]
                clipped = ~bad & ~(r2 <= sd * sd)
            if bad.any():
                fail(bad, MISSED)
                keep = ~bad
                nx_, ny_, nz_ = nx_[keep], ny_[keep], nz_[keep]
                if kd == _ASPHERE:
                    dsr = dsr[keep]
                if opl is not None:
                    leg = leg[keep]
                if clip:
                    clipped = clipped[keep]
            if clip and clipped.any():
                fail(clipped, CLIPPED)
                keep = ~clipped
                nx_, ny_, nz_ = nx_[keep], ny_[keep], nz_[keep]
                if kd == _ASPHERE:
                    dsr = dsr[keep]
                if opl is not None:
                    leg = leg[keep]
            px, py, pz = nx_, ny_, nz_
            if opl is not None:
                n1 = px.dtype.type(S[s, N1]) if mono else _index(S, s, NB, SB, l2, il2)
                opl[live] += n1 * leg
            if kd == _STOP:
                continue
            if mono:
                # one wavelength: the indices are the row's numbers (scalars: the same products as
                # arrays of them), and a surface between equal indices changes nothing
                # at the rays' precision (a float32 table's scalar squared in float32 moved 1681 of 2000
                # single-precision rays by up to 1.9e-6 mm against the array kernel before it)
                dt = px.dtype.type
                n1, n2, eta = dt(S[s, N1]), dt(S[s, N2]), dt(S[s, ETA])
                if n1 == n2:
                    continue
                same = None
            else:
                if opl is None:
                    n1 = _index(S, s, NB, SB, l2, il2)
                n2 = _index(S, s, NA, SA, l2, il2)
                eta = n1 / n2
                same = n1 == n2
                if not same.any():
                    same = None
            if kd == _FLAT:
                gx = np.zeros_like(px)
                gy = np.zeros_like(px)
                gz = np.full_like(px, -1.0)
            elif kd == _QUADRIC:
                gx = S[s, AX] * px
                gy = S[s, AY] * py
                gz = S[s, AZ] * (pz - S[s, VZ]) - 1.0
            else:
                gx = dsr * px
                gy = dsr * py
                gz = np.full_like(px, -1.0)
            if S[s, UNIT] == 0.0:
                inv = 1.0 / np.sqrt(gx * gx + gy * gy + gz * gz)
                gx = gx * inv
                gy = gy * inv
                gz = gz * inv
            ci = dx * gx + dy * gy + dz * gz
            sgn = 1.0 - (ci < 0.0) * 2.0
            gx, gy, gz, ci = gx * sgn, gy * sgn, gz * sgn, ci * sgn
            kk = 1.0 - eta * eta * (1.0 - ci * ci)
            # kk < 0 with a finite normal: TIR; NaN/inf (a degenerate normal, 0/0): MISSED.
            # A finite normal and kk >= 0 give a finite refracted direction. (``same`` None: no
            # ray between equal indices; the spectral arrays are filtered with the rays.)
            bad = ~(kk >= 0.0) if same is None else ~(kk >= 0.0) & ~same
            if bad.any():
                tir = bad & (kk < 0.0) & (ci - ci == 0.0)
                fail(tir, TIR)
                keep = ~tir
                arrays = (gx, gy, gz, ci, kk, bad) if mono else (n1, n2, gx, gy, gz, ci, eta, kk, bad)
                arrays = [a[keep] for a in arrays]
                bad = arrays[-1]
                fail(bad, MISSED)
                keep = ~bad
                arrays = [a[keep] for a in arrays[:-1]]
                if mono:
                    gx, gy, gz, ci, kk = arrays
                else:
                    n1, n2, gx, gy, gz, ci, eta, kk = arrays
                    same = None if same is None else n1 == n2
            ct = np.sqrt(kk)
            f = ct - eta * ci
            ox = eta * dx + f * gx
            oy = eta * dy + f * gy
            oz = eta * dz + f * gz
            if same is not None:
                ox = np.where(same, dx, ox)
                oy = np.where(same, dy, oy)
                oz = np.where(same, dz, oz)
            if fresnel:
                # s and p carried separately: with A, B the s- and p-polarised throughputs,
                # wt = (A + B) / 2 and wdt = (A - B) / 2; per surface A *= Ts, B *= Tp, i.e.
                # wt' = wt (Ts + Tp)/2 + wdt (Ts - Tp)/2 and wdt' = wt (Ts - Tp)/2 + wdt (Ts + Tp)/2.
                # r_s = (eta ci - ct) / (eta ci + ct), r_p = (ci - eta ct) / (ci + eta ct) over one
                # common denominator; R clipped to 1 (coating factor; 0/0 at grazing incidence).
                ec = eta * ci
                et = eta * ct
                sm = (ec - ct) * (ci + et)
                pm = (ci - et) * (ec + ct)
                sp = (ec + ct) * (ci + et)
                q = S[s, RSC] / (sp * sp)
                rs = sm * sm * q
                rs = np.fmin(rs, 1.0)  # (the same as np.where(rs < 1.0, rs, 1.0), NaN included)
                rp = np.fmin(pm * pm * q, 1.0)
                hsum = 1.0 - 0.5 * (rs + rp)
                hdif = 0.5 * (rp - rs)
                if same is None:
                    wt, wdt = wt * hsum + wdt * hdif, wt * hdif + wdt * hsum
                else:
                    wt, wdt = (np.where(same, wt, wt * hsum + wdt * hdif), np.where(same, wdt, wt * hdif + wdt * hsum))
            dx, dy, dz = ox, oy, oz
        if has_end and live.size:
            fail(dz == 0.0, MISSED)
            t = (end_z - pz) / dz
            nx_ = px + t * dx
            ny_ = py + t * dy
            bad = ~(np.isfinite(nx_) & np.isfinite(ny_))
            if bad.any():
                fail(bad, MISSED)
                nx_, ny_ = nx_[~bad], ny_[~bad]
            px, py = nx_, ny_
            pz = np.full_like(px, end_z)
    x[live], y[live], z[live] = px, py, pz
    L[live], M[live], N[live] = dx, dy, dz
    w[live] = wt
    wd[live] = wdt

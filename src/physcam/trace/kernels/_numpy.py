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
5. Fresnel: unpolarised transmittance (see :mod:`physcam.trace.fresnel`).

Rays that fail keep their last finite position and direction, get weight 0 and a flag.
"""

from __future__ import annotations

import numpy as np

from ._layout import A4, AX, AY, AZ, CK, CV, NAA, NAB, NBA, NBB, NEWTON_MAX_ITER, NEWTON_TOL, RSC, SEMI, UNIT, VZ
from ._layout import ETA, N1, N2
from ._layout import CLIPPED, MISSED, TIR

_FLAT, _STOP, _QUADRIC, _ASPHERE = 0, 1, 2, 3


def trace_rays(x, y, z, L, M, N, wl, w, flag, S, kinds, clip, fresnel, end_z, has_end, mono):
    """Trace rays in place through the rows of ``S`` (tracing order), then to the plane ``end_z``."""
    live = np.flatnonzero(flag == 0)
    px, py, pz = x[live], y[live], z[live]
    dx, dy, dz = L[live], M[live], N[live]
    il2 = 1.0 / (wl[live] * wl[live])
    wt = w[live].copy()

    def fail(bad, code):
        nonlocal live, px, py, pz, dx, dy, dz, il2, wt
        if not bad.any():
            return
        j = live[bad]
        x[j], y[j], z[j] = px[bad], py[bad], pz[bad]
        L[j], M[j], N[j] = dx[bad], dy[bad], dz[bad]
        flag[j] = code
        w[j] = 0.0
        keep = ~bad
        live = live[keep]
        px, py, pz, dx, dy, dz, il2, wt = (a[keep] for a in (px, py, pz, dx, dy, dz, il2, wt))

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
                den = np.where(b >= 0.0, -b - sq, -b + sq)
                t = c / den
                # The root nearest in t may lie on the far cap of the quadric (the back of a
                # sphere met first by a ray starting far from the vertex): the surface is the
                # branch through the vertex, where az * z < 1; take the other root there.
                far_side = az * (qz + t * dz) >= 1.0
                t = np.where(far_side, den / a, t)
                bad = (disc < 0.0) | (den == 0.0) | (far_side & ((a == 0.0) | ~(az * (qz + t * dz) < 1.0)))
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
            if clip:
                sd = S[s, SEMI]
                bad = nx_ * nx_ + ny_ * ny_ > sd * sd
                if bad.any():
                    fail(bad, CLIPPED)
                    keep = ~bad
                    nx_, ny_, nz_ = nx_[keep], ny_[keep], nz_[keep]
                    if kd == _ASPHERE:
                        dsr = dsr[keep]
            px, py, pz = nx_, ny_, nz_
            if kd == _STOP:
                continue
            if mono:
                n1 = np.full_like(px, S[s, N1])
                n2 = np.full_like(px, S[s, N2])
                eta = np.full_like(px, S[s, ETA])
            else:
                n1 = S[s, NBA] + S[s, NBB] * il2
                n2 = S[s, NAA] + S[s, NAB] * il2
                eta = n1 / n2
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
            sgn = np.where(ci < 0.0, -1.0, 1.0)
            gx, gy, gz, ci = gx * sgn, gy * sgn, gz * sgn, ci * sgn
            kk = 1.0 - eta * eta * (1.0 - ci * ci)
            same = n1 == n2
            bad = (kk < 0.0) & ~same
            if bad.any():
                fail(bad, TIR)
                keep = ~bad
                n1, n2, gx, gy, gz, ci, eta, kk, same = (
                    a[keep] for a in (n1, n2, gx, gy, gz, ci, eta, kk, same)
                )
            ct = np.sqrt(kk)
            if fresnel:
                # unpolarised R = (rs^2 + rp^2) / 2 over one common denominator
                # r_s = (eta ci - ct) / (eta ci + ct), r_p = (ci - eta ct) / (ci + eta ct)
                ec = eta * ci
                et = eta * ct
                sm = (ec - ct) * (ci + et)
                pm = (ci - et) * (ec + ct)
                sp = (ec + ct) * (ci + et)
                rr = np.minimum(0.5 * (sm * sm + pm * pm) / (sp * sp) * S[s, RSC], 1.0)
                wt = np.where(same, wt, wt * (1.0 - rr))
            f = ct - eta * ci
            dx = np.where(same, dx, eta * dx + f * gx)
            dy = np.where(same, dy, eta * dy + f * gy)
            dz = np.where(same, dz, eta * dz + f * gz)
        if has_end and live.size:
            fail(dz == 0.0, MISSED)
            t = (end_z - pz) / dz
            px = px + t * dx
            py = py + t * dy
            pz = np.full_like(px, end_z)
    x[live], y[live], z[live] = px, py, pz
    L[live], M[live], N[live] = dx, dy, dz
    w[live] = wt

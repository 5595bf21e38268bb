"""The JIT kernel: blocks of rays, surfaces in the outer loop, rays in branch-free inner loops.

Same algorithm, order of operations and answers as :mod:`._numpy` (the reference; see that
module and docs/ray-tracing.md for the maths). The geometry keeps IEEE semantics, so rays agree
with the reference bit for bit; only the Fresnel weights are contracted to fused multiply-adds,
where a last-bit difference stays one (docs/ray-tracing.md, "The SIMD kernel", has the error
analysis). Imported only through :mod:`physcam.trace.kernels`.

Layout (structure of arrays, like the branch-free C loop of docs/performance.md): a block of
:data:`BLOCK` rays is copied into a scratch array of columns (position, direction, weights,
flag, intersection parameter, normal ...) small enough for the L1 cache. For each surface a few
passes run over the block, each a loop in which every lane does the same operations: a lost ray
is not skipped but masked (its lane computes like the others and a select keeps its last state),
so LLVM compiles the loops to packed AVX2/AVX-512 instructions (``vsqrtpd``, ``vdivpd`` on 4 or 8
rays at once). Whatever depends on the surface only (its kind, whether its normal needs
normalising, clipping, Fresnel, the wavelength mode) picks which passes run, outside the ray loops.
Two rare cases are handled per block, not per ray: the far root of a quadric (the back of a
sphere met first; a fix-up pass runs only when some lane needs it) and the Newton iteration of an
even asphere (all lanes step together; it stops when no lane of the block still moves).

A kernel is one **variant** per feature set (one wavelength or each ray's own, optical path,
Fresnel weights, even aspheres: :func:`variant`), so a command compiles only the passes it uses
(numba compiles whatever a function calls, reached or not: the one kernel that took these as
arguments compiled every pass, 9-12 s of CPU on first use). A variant traces a range of blocks on
the calling thread without the GIL; :mod:`physcam.trace.kernels` runs large batches as one range
per thread (numba's ``prange`` would add its parallel compiler, 2-3 s more at first use). It takes
float64 or float32 rays and table: the working precision follows the arrays.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np
from numba.core import types
from numba.extending import overload

from . import _jitcache

_CACHE = _jitcache.install()  # before any @njit below: cache keyed by version and sources (else none)

from ._layout import A4, AX, AY, AZ, CK, CV, ETA, N1, N2, NA, NB, NEWTON_MAX_ITER, NEWTON_TOL, SA, SB  # noqa: E402
from ._layout import CLIPPED, MISSED, RSC, SEMI, TIR, UNIT, VZ  # noqa: E402

_FLAT, _STOP, _QUADRIC, _ASPHERE = 0, 1, 2, 3

#: Rays per block: 21 scratch columns x 256 rays x 8 bytes = 42 KiB (float64), inside a 48 KiB L1.
BLOCK = 256
# Scratch columns, each BLOCK long. Newton's state (ACT, CONV) reuses CI, CT, and dz/dr of an
# asphere (DS) reuses UPD: each is consumed before the pass that writes the other.
(_PX, _PY, _PZ, _DX, _DY, _DZ, _W, _WD, _CD, _T, _L2, _U, _N1, _N2, _ETA, _GX, _GY, _GZ, _CI, _CT,
 _UPD) = range(21)
_NCOL = 21
_ACT, _CONV, _DS = _CI, _CT, _UPD

#: every kernel function: IEEE arithmetic (no contraction, no reassociation), no Python error
#: checks (a division by zero gives inf in a masked lane instead of raising), GIL released
_OPTS = dict(fastmath=False, error_model="numpy", nogil=True, cache=_CACHE)
#: the Fresnel weights only: contraction to FMA allowed
_FMA_OPTS = dict(fastmath={"contract"}, error_model="numpy", nogil=True, cache=_CACHE)


# Constants take the scratch array's element type, ``F = buf.dtype.type`` (float64 or float32), so
# float32 kernels stay float32 (a typed constructor: cheaper to compile than an inlined overload).


def _newton_rel_tol(arr):  # pragma: no cover - replaced by the overload inside jitted code
    """Relative part of the Newton step tolerance: 0 in float64 (the reference's absolute
    NEWTON_TOL), 8 float32 ulps of t in float32, whose t cannot resolve 1e-12 mm."""
    raise NotImplementedError


@overload(_newton_rel_tol, inline="always")
def _newton_rel_tol_impl(arr):
    dt = arr.dtype if isinstance(arr, types.Array) else arr
    if dt == types.float32:
        return lambda arr: np.float32(8.0 * 2.0**-23)
    return lambda arr: np.float64(0.0)


#: absolute Newton tolerance in float32 (mm), where NEWTON_TOL is below one ulp of any t
NEWTON_TOL_F32 = 1e-6


# ---- intersection ----------------------------------------------------------------------------

@nb.njit(**_OPTS)
def _intersect_plane(buf, m, vz):
    """t to the plane z = vz into column T; a live ray parallel to it misses."""
    B = BLOCK
    F = buf.dtype.type  # constants in the working precision (float64 or float32)
    zero = F(0.0)
    miss = F(MISSED)
    for k in range(m):
        dz = buf[_DZ * B + k]
        cd = buf[_CD * B + k]
        buf[_T * B + k] = -(buf[_PZ * B + k] - vz) / dz
        buf[_CD * B + k] = miss if ((cd == zero) & (dz == zero)) else cd


@nb.njit(**_OPTS)
def _intersect_quadric(buf, m, vz, ax, ay, az):
    """The forward-crossing root of ax x^2 + ay y^2 + az z^2 - 2 z = 0 into column T (module notes,
    "Which root"): f = that quadric along the ray, a t^2 + 2 b t + c, falls through zero (the ray goes
    from the medium before the surface into the one after it) at t = (-b - s sq) / a with s the sign
    of the ray's dz, computed without cancellation as c / (-b + s sq) when b s < 0. A crossing on the
    far cap (az z >= 1, the back of a sphere) is no crossing of the surface: MISSED."""
    B = BLOCK
    F = buf.dtype.type  # constants in the working precision (float64 or float32)
    zero = F(0.0)
    one = F(1.0)
    two = F(2.0)
    miss = F(MISSED)
    for k in range(m):
        px = buf[_PX * B + k]
        py = buf[_PY * B + k]
        qz = buf[_PZ * B + k] - vz
        dx = buf[_DX * B + k]
        dy = buf[_DY * B + k]
        dz = buf[_DZ * B + k]
        cd = buf[_CD * B + k]
        a = ax * dx * dx + ay * dy * dy + az * dz * dz
        b = ax * px * dx + ay * py * dy + az * qz * dz - dz
        c = ax * px * px + ay * py * py + az * qz * qz - two * qz
        disc = b * b - a * c
        sq = math.sqrt(max(disc, zero))
        sgn = one if dz >= zero else -one
        same = b * sgn >= zero
        num = -b - sgn * sq if same else c
        den = a if same else -b + sgn * sq
        t = num / den
        live = cd == zero
        bad = (disc < zero) | (den == zero) | (not (az * (qz + t * dz) < one))
        buf[_T * B + k] = t
        buf[_CD * B + k] = miss if (live & bad) else cd


@nb.njit(**_OPTS)
def _newton_asphere(buf, m, S, s, vz):
    """Refine t on an even asphere: Newton on g(t) = z(t) - sag(r(t)) from the conic root, all
    lanes in step (a lane stops moving once converged or broken); then dz/dr at the hit point into
    column DS, and lanes that did not converge flagged MISSED (as the numpy kernel)."""
    B = BLOCK
    F = buf.dtype.type  # constants in the working precision (float64 or float32)
    zero = F(0.0)
    one = F(1.0)
    rel = _newton_rel_tol(buf)
    tol = F(NEWTON_TOL) if rel == zero else F(NEWTON_TOL_F32)
    miss = F(MISSED)
    cv = S[s, CV]
    ck1 = (one + S[s, CK]) * cv * cv
    a4 = S[s, A4]
    a6 = S[s, A4 + 1]
    a8 = S[s, A4 + 2]
    a10 = S[s, A4 + 3]
    a12 = S[s, A4 + 4]
    a14 = S[s, A4 + 5]
    a16 = S[s, A4 + 6]
    # (2 j + 4) A_(2j+4): the products of the numpy kernel's ((2.0 * j + 4.0) * coef[j])
    c4 = F(4.0) * a4
    c6 = F(6.0) * a6
    c8 = F(8.0) * a8
    c10 = F(10.0) * a10
    c12 = F(12.0) * a12
    c14 = F(14.0) * a14
    c16 = F(16.0) * a16
    nact = np.int32(0)
    for k in range(m):
        live = buf[_CD * B + k] == zero
        buf[_ACT * B + k] = one if live else zero
        buf[_CONV * B + k] = zero
        nact += np.int32(live)
    for _it in range(NEWTON_MAX_ITER):
        if nact == 0:
            break
        nact = np.int32(0)
        for k in range(m):
            act = buf[_ACT * B + k] != zero
            dx = buf[_DX * B + k]
            dy = buf[_DY * B + k]
            dz = buf[_DZ * B + k]
            t = buf[_T * B + k]
            X = buf[_PX * B + k] + t * dx
            Y = buf[_PY * B + k] + t * dy
            Z = (buf[_PZ * B + k] - vz) + t * dz
            r2 = X * X + Y * Y
            arg = one - ck1 * r2
            sa = math.sqrt(arg)
            sag = cv * r2 / (one + sa)
            dsr = cv / sa
            # sum A_2i r^2i and its derivative, term by term as the numpy kernel
            p = r2 * r2
            q = r2
            sag = sag + a4 * p
            dsr = dsr + c4 * q
            p = p * r2
            q = q * r2
            sag = sag + a6 * p
            dsr = dsr + c6 * q
            p = p * r2
            q = q * r2
            sag = sag + a8 * p
            dsr = dsr + c8 * q
            p = p * r2
            q = q * r2
            sag = sag + a10 * p
            dsr = dsr + c10 * q
            p = p * r2
            q = q * r2
            sag = sag + a12 * p
            dsr = dsr + c12 * q
            p = p * r2
            q = q * r2
            sag = sag + a14 * p
            dsr = dsr + c14 * q
            p = p * r2
            q = q * r2
            sag = sag + a16 * p
            dsr = dsr + c16 * q
            g = Z - sag
            gp = dz - dsr * (X * dx + Y * dy)
            broken = (arg < zero) | (gp == zero)
            step = act & (not broken)
            dt = g / gp
            dt = dt if step else zero
            conv = step & (abs(dt) < tol + rel * abs(t))
            buf[_T * B + k] = t - dt
            still = step & (not conv)
            buf[_ACT * B + k] = one if still else zero
            buf[_CONV * B + k] = one if conv else buf[_CONV * B + k]
            nact += np.int32(still)
    for k in range(m):
        t = buf[_T * B + k]
        X = buf[_PX * B + k] + t * buf[_DX * B + k]
        Y = buf[_PY * B + k] + t * buf[_DY * B + k]
        r2 = X * X + Y * Y
        arg = one - ck1 * r2
        dsr = cv / math.sqrt(arg)
        q = r2
        dsr = dsr + c4 * q
        q = q * r2
        dsr = dsr + c6 * q
        q = q * r2
        dsr = dsr + c8 * q
        q = q * r2
        dsr = dsr + c10 * q
        q = q * r2
        dsr = dsr + c12 * q
        q = q * r2
        dsr = dsr + c14 * q
        q = q * r2
        dsr = dsr + c16 * q
        buf[_DS * B + k] = dsr
        cd = buf[_CD * B + k]
        bad = (cd == zero) & ((buf[_CONV * B + k] == zero) | (arg < zero))
        buf[_CD * B + k] = miss if bad else cd


# ---- hit point, clipping -------------------------------------------------------------------

@nb.njit(**_OPTS)
def _move_and_clip(buf, m, sd2, clip):
    """Live lanes to their hit point p + t d; clip outside the semi-diameter. The same comparison
    catches a hit point that is not finite (overflow, 0/0): NaN fails it (MISSED, not CLIPPED)."""
    B = BLOCK
    F = buf.dtype.type  # constants in the working precision (float64 or float32)
    zero = F(0.0)
    miss = F(MISSED)
    clipped = F(CLIPPED)
    for k in range(m):
        cd = buf[_CD * B + k]
        live = cd == zero
        t = buf[_T * B + k]
        px = buf[_PX * B + k]
        py = buf[_PY * B + k]
        pz = buf[_PZ * B + k]
        hx = px + t * buf[_DX * B + k]
        hy = py + t * buf[_DY * B + k]
        hz = pz + t * buf[_DZ * B + k]
        r2 = hx * hx + hy * hy
        finite = r2 - r2 == zero
        ok = live & finite & ((r2 <= sd2) | (not clip))
        buf[_PX * B + k] = hx if ok else px
        buf[_PY * B + k] = hy if ok else py
        buf[_PZ * B + k] = hz if ok else pz
        buf[_CD * B + k] = cd if (ok | (not live)) else (clipped if finite else miss)


# ---- surface normals (pointing to -z at the vertex) ----------------------------------------

@nb.njit(**_OPTS)
def _normal_flat(buf, m):
    B = BLOCK
    F = buf.dtype.type  # constants in the working precision (float64 or float32)
    zero = F(0.0)
    one = F(1.0)
    for k in range(m):
        buf[_GX * B + k] = zero
        buf[_GY * B + k] = zero
        buf[_GZ * B + k] = -one


@nb.njit(**_OPTS)
def _normal_quadric(buf, m, vz, ax, ay, az):
    """Gradient (ax x, ay y, az z - 1) of the quadric: already a unit vector on spheres and cylinders."""
    B = BLOCK
    F = buf.dtype.type  # constants in the working precision (float64 or float32)
    one = F(1.0)
    for k in range(m):
        buf[_GX * B + k] = ax * buf[_PX * B + k]
        buf[_GY * B + k] = ay * buf[_PY * B + k]
        buf[_GZ * B + k] = az * (buf[_PZ * B + k] - vz) - one


@nb.njit(**_OPTS)
def _normal_asphere(buf, m):
    """(dz/dr x, dz/dr y, -1) with dz/dr (per unit r) from the Newton pass."""
    B = BLOCK
    F = buf.dtype.type  # constants in the working precision (float64 or float32)
    one = F(1.0)
    for k in range(m):
        ds = buf[_DS * B + k]
        buf[_GX * B + k] = ds * buf[_PX * B + k]
        buf[_GY * B + k] = ds * buf[_PY * B + k]
        buf[_GZ * B + k] = -one


@nb.njit(**_OPTS)
def _normalise(buf, m):
    B = BLOCK
    F = buf.dtype.type  # constants in the working precision (float64 or float32)
    one = F(1.0)
    for k in range(m):
        gx = buf[_GX * B + k]
        gy = buf[_GY * B + k]
        gz = buf[_GZ * B + k]
        inv = one / math.sqrt(gx * gx + gy * gy + gz * gz)
        buf[_GX * B + k] = gx * inv
        buf[_GY * B + k] = gy * inv
        buf[_GZ * B + k] = gz * inv


# ---- refractive indices ---------------------------------------------------------------------

@nb.njit(**_OPTS)
def _fill_const(buf, m, n1, n2, eta):
    """One wavelength: the surface's indices for every lane."""
    B = BLOCK
    for k in range(m):
        buf[_N1 * B + k] = n1
        buf[_N2 * B + k] = n2
        buf[_ETA * B + k] = eta


@nb.njit(inline="always", **_OPTS)
def _fill_index(buf, col, S, s, c, flag, m):
    """Index of one medium per lane into column ``col``: the arithmetic and order of
    :func:`physcam.optics.glass.evaluate` and ``_layout.index_rows``, so a mixed-wavelength batch
    gets bit for bit the indices of the one-wavelength path."""
    B = BLOCK
    F = buf.dtype.type  # constants in the working precision (float64 or float32)
    a0 = S[s, c]
    a1 = S[s, c + 1]
    a2 = S[s, c + 2]
    one = F(1.0)
    if S[s, flag] != 0.0:
        b1 = S[s, c + 3]
        b2 = S[s, c + 4]
        b3 = S[s, c + 5]
        c1 = S[s, c + 6]
        c2 = S[s, c + 7]
        c3 = S[s, c + 8]
        for k in range(m):
            u = buf[_U * B + k]
            l2 = buf[_L2 * B + k]
            buf[col * B + k] = (a0 + (a1 + a2 * u) * u) + math.sqrt(
                one + b1 * l2 / (l2 - c1) + b2 * l2 / (l2 - c2) + b3 * l2 / (l2 - c3))
    else:
        for k in range(m):
            u = buf[_U * B + k]
            buf[col * B + k] = a0 + (a1 + a2 * u) * u


@nb.njit(**_OPTS)
def _fill_n1(buf, S, s, m):
    """Index before the surface per lane (the column is a constant here, so LLVM sees that the
    loop's reads and writes do not overlap and vectorises it)."""
    _fill_index(buf, _N1, S, s, NB, SB, m)


@nb.njit(**_OPTS)
def _fill_n2(buf, S, s, m):
    """Index after the surface per lane."""
    _fill_index(buf, _N2, S, s, NA, SA, m)


@nb.njit(**_OPTS)
def _fill_eta(buf, m):
    B = BLOCK
    for k in range(m):
        buf[_ETA * B + k] = buf[_N1 * B + k] / buf[_N2 * B + k]


# ---- refraction, Fresnel --------------------------------------------------------------------

@nb.njit(**_OPTS)
def _refract(buf, m):
    """Snell's law in vector form, t = eta d + (cos t - eta cos i) n, with the normal turned to the
    side the ray travels to; TIR where 1 - eta^2 (1 - cos^2 i) < 0 (a NaN there, from a degenerate
    normal, is MISSED). Leaves cos i, cos t and whether the lane refracted for :func:`_fresnel_pass`."""
    B = BLOCK
    F = buf.dtype.type  # constants in the working precision (float64 or float32)
    zero = F(0.0)
    one = F(1.0)
    miss = F(MISSED)
    tir_code = F(TIR)
    for k in range(m):
        cd = buf[_CD * B + k]
        live = cd == zero
        dx = buf[_DX * B + k]
        dy = buf[_DY * B + k]
        dz = buf[_DZ * B + k]
        gx = buf[_GX * B + k]
        gy = buf[_GY * B + k]
        gz = buf[_GZ * B + k]
        eta = buf[_ETA * B + k]
        same = buf[_N1 * B + k] == buf[_N2 * B + k]
        ci = dx * gx + dy * gy + dz * gz
        flip = ci < zero
        gx = -gx if flip else gx
        gy = -gy if flip else gy
        gz = -gz if flip else gz
        ci = -ci if flip else ci
        kk = one - eta * eta * (one - ci * ci)
        good = (kk >= zero) | same
        tir = live & (not good) & (kk < zero) & (ci - ci == zero)
        upd = live & good & (not same)
        ct = math.sqrt(max(kk, zero))
        f = ct - eta * ci
        buf[_DX * B + k] = eta * dx + f * gx if upd else dx
        buf[_DY * B + k] = eta * dy + f * gy if upd else dy
        buf[_DZ * B + k] = eta * dz + f * gz if upd else dz
        buf[_CD * B + k] = tir_code if tir else (miss if (live & (not good)) else cd)
        buf[_CI * B + k] = ci
        buf[_CT * B + k] = ct
        buf[_UPD * B + k] = one if upd else zero


@nb.njit(**_FMA_OPTS)
def _fresnel_pass(buf, m, rsc):
    """Fresnel s and p transmission of one surface on the weights of the lanes that refracted
    (numpy kernel): with A, B the s and p throughputs, w = (A + B) / 2 and wd = (A - B) / 2; R
    clipped to 1. Contracted to FMA: no decision depends on these numbers (docs/ray-tracing.md)."""
    B = BLOCK
    F = buf.dtype.type  # constants in the working precision (float64 or float32)
    zero = F(0.0)
    one = F(1.0)
    half = F(0.5)
    for k in range(m):
        eta = buf[_ETA * B + k]
        ci = buf[_CI * B + k]
        ct = buf[_CT * B + k]
        upd = buf[_UPD * B + k] != zero
        ec = eta * ci
        et = eta * ct
        sm = (ec - ct) * (ci + et)
        pm = (ci - et) * (ec + ct)
        sp = (ec + ct) * (ci + et)
        qq = rsc / (sp * sp)
        rs = sm * sm * qq
        rs = rs if rs < one else one
        rp = pm * pm * qq
        rp = rp if rp < one else one
        hsum = one - half * (rs + rp)
        hdif = half * (rp - rs)
        w0 = buf[_W * B + k]
        d0 = buf[_WD * B + k]
        buf[_W * B + k] = w0 * hsum + d0 * hdif if upd else w0
        buf[_WD * B + k] = w0 * hdif + d0 * hsum if upd else d0


@nb.njit(**_OPTS)
def _to_plane(buf, m, end_z):
    """Live lanes on to the plane z = end_z; a ray parallel to it, or landing at inf/NaN, misses."""
    B = BLOCK
    F = buf.dtype.type  # constants in the working precision (float64 or float32)
    zero = F(0.0)
    miss = F(MISSED)
    for k in range(m):
        cd = buf[_CD * B + k]
        live = cd == zero
        px = buf[_PX * B + k]
        py = buf[_PY * B + k]
        pz = buf[_PZ * B + k]
        dz = buf[_DZ * B + k]
        t = (end_z - pz) / dz
        hx = px + t * buf[_DX * B + k]
        hy = py + t * buf[_DY * B + k]
        ok = live & (dz != zero) & (hx - hx == zero) & (hy - hy == zero)
        buf[_PX * B + k] = hx if ok else px
        buf[_PY * B + k] = hy if ok else py
        buf[_PZ * B + k] = end_z if ok else pz
        buf[_CD * B + k] = miss if (live & (not ok)) else cd


# ---- optical path ------------------------------------------------------------------------------

@nb.njit(**_OPTS)
def _add_path_const(buf, m, n1, opl, i0):
    """Add n (p' - p) . d = n t |d|^2 of this leg (one index ``n1``) to ``opl`` for the lanes still
    live after the surface's hit and clip (the numpy kernel's order of operations)."""
    B = BLOCK
    F = buf.dtype.type  # constants in the working precision (float64 or float32)
    zero = F(0.0)
    for k in range(m):
        dx = buf[_DX * B + k]
        dy = buf[_DY * B + k]
        dz = buf[_DZ * B + k]
        leg = n1 * (buf[_T * B + k] * (dx * dx + dy * dy + dz * dz))
        live = buf[_CD * B + k] == zero
        opl[i0 + k] += np.float64(leg) if live else 0.0


@nb.njit(**_OPTS)
def _add_path(buf, m, opl, i0):
    """:func:`_add_path_const` with each lane's index before the surface (column N1)."""
    B = BLOCK
    F = buf.dtype.type  # constants in the working precision (float64 or float32)
    zero = F(0.0)
    for k in range(m):
        dx = buf[_DX * B + k]
        dy = buf[_DY * B + k]
        dz = buf[_DZ * B + k]
        leg = buf[_N1 * B + k] * (buf[_T * B + k] * (dx * dx + dy * dy + dz * dz))
        live = buf[_CD * B + k] == zero
        opl[i0 + k] += np.float64(leg) if live else 0.0


# ---- the kernel: blocks of rays through every surface, one variant per feature set -------------

#: The passes a variant calls beyond the common ones, by feature (what :func:`variant_passes` lists).
_COMMON = ("_intersect_plane", "_intersect_quadric", "_move_and_clip", "_normal_flat", "_normal_quadric",
           "_normalise", "_refract", "_to_plane")


def variant_passes(mono: bool, opl: bool, fresnel: bool, asphere: bool) -> tuple[str, ...]:
    """The pass functions the variant ``(mono, opl, fresnel, asphere)`` compiles (module notes)."""
    out = list(_COMMON)
    out += ["_fill_const"] if mono else ["_fill_n1", "_fill_n2", "_fill_eta"]
    if opl:
        out += ["_add_path_const"] if mono else ["_add_path"]
    if fresnel:
        out.append("_fresnel_pass")
    if asphere:
        out += ["_newton_asphere", "_normal_asphere"]
    return tuple(out)


def _build(MONO, OPL, FRESNEL, ASPHERE):
    """The kernel for one feature set: one wavelength (``MONO``: indices from the table's columns) or
    each ray's own, each leg's optical path added (``OPL``), Fresnel weights (``FRESNEL``), even
    aspheres in the table (``ASPHERE``). The flags are the closure's constants, so numba prunes the
    branches they close before typing: a variant compiles only the passes it calls
    (:func:`variant_passes`), and numba's cache keys each variant by them. The same passes in the
    same order as the one kernel that took them as arguments: the same rays, bit for bit."""

    @nb.njit(**_OPTS)
    def trace_blocks(x, y, z, L, M, N, wl, w, wd, flag, S, kinds, clip, end_z, has_end, opl, b0, b1):
        """Trace blocks ``b0`` .. ``b1`` of :data:`BLOCK` rays in place through every row of ``S`` (and
        add each leg's optical path to ``opl`` with ``OPL``), one block at a time in a scratch array."""
        B = BLOCK
        n = x.shape[0]
        buf = np.empty(_NCOL * BLOCK, dtype=x.dtype)
        F = buf.dtype.type  # constants in the working precision (float64 or float32)
        zero = F(0.0)
        one = F(1.0)
        thousand = F(1000.0)
        miss = F(MISSED)
        ez = F(end_z)
        for blk in range(b0, b1):
            i0 = blk * B
            m = min(B, n - i0)
            for k in range(m):
                buf[_PX * B + k] = x[i0 + k]
                buf[_PY * B + k] = y[i0 + k]
                buf[_PZ * B + k] = z[i0 + k]
                buf[_DX * B + k] = L[i0 + k]
                buf[_DY * B + k] = M[i0 + k]
                buf[_DZ * B + k] = N[i0 + k]
                buf[_W * B + k] = w[i0 + k]
                buf[_WD * B + k] = wd[i0 + k]
                buf[_CD * B + k] = flag[i0 + k]
            # a live ray must start with finite weights (and, mixed wavelengths, a usable wavelength:
            # > 0 with a finite 1/l^2); a NaN/inf position or direction makes the first hit point or
            # incidence cosine NaN/inf, which the passes flag
            for k in range(m):
                v = buf[_W * B + k] + buf[_WD * B + k]
                cd = buf[_CD * B + k]
                good = v - v == zero
                if not MONO:
                    lam = wl[i0 + k] / thousand
                    l2 = lam * lam
                    u = one / l2
                    buf[_L2 * B + k] = l2
                    buf[_U * B + k] = u
                    good = good & (wl[i0 + k] > zero) & (u - u == zero)
                buf[_CD * B + k] = miss if ((cd == zero) & (not good)) else cd
            for s in range(S.shape[0]):
                # every lane of the block stopped: no pass changes a stopped lane, so the rest of the
                # surfaces would leave the block as it is (a pupil grid's aims mostly die at the rear rim)
                alive = False
                for k in range(m):
                    if buf[_CD * B + k] == zero:
                        alive = True
                        break
                if not alive:
                    break
                kd = kinds[s]
                vz = S[s, VZ]
                ax = S[s, AX]
                ay = S[s, AY]
                az = S[s, AZ]
                if kd <= _STOP:
                    _intersect_plane(buf, m, vz)
                else:
                    _intersect_quadric(buf, m, vz, ax, ay, az)
                    if ASPHERE:
                        if kd == _ASPHERE:
                            _newton_asphere(buf, m, S, s, vz)
                _move_and_clip(buf, m, S[s, SEMI] * S[s, SEMI], clip)
                if OPL:
                    if MONO:
                        _add_path_const(buf, m, S[s, N1], opl, i0)
                    else:
                        _fill_n1(buf, S, s, m)
                        _add_path(buf, m, opl, i0)
                # the stop, and in one-wavelength batches a surface between equal media, bend nothing
                if kd == _STOP:
                    continue
                if MONO:
                    if S[s, N1] == S[s, N2]:
                        continue
                    _fill_const(buf, m, S[s, N1], S[s, N2], S[s, ETA])
                else:
                    if not OPL:
                        _fill_n1(buf, S, s, m)
                    _fill_n2(buf, S, s, m)
                    _fill_eta(buf, m)
                if kd == _FLAT:
                    _normal_flat(buf, m)
                elif kd == _QUADRIC:
                    _normal_quadric(buf, m, vz, ax, ay, az)
                else:
                    if ASPHERE:
                        _normal_asphere(buf, m)
                if S[s, UNIT] == zero:
                    _normalise(buf, m)
                _refract(buf, m)
                if FRESNEL:
                    _fresnel_pass(buf, m, S[s, RSC])
            if has_end:
                _to_plane(buf, m, ez)
            for k in range(m):
                cd = buf[_CD * B + k]
                lost = (cd != zero) & (flag[i0 + k] == 0)
                x[i0 + k] = buf[_PX * B + k]
                y[i0 + k] = buf[_PY * B + k]
                z[i0 + k] = buf[_PZ * B + k]
                L[i0 + k] = buf[_DX * B + k]
                M[i0 + k] = buf[_DY * B + k]
                N[i0 + k] = buf[_DZ * B + k]
                w[i0 + k] = zero if lost else buf[_W * B + k]
                wd[i0 + k] = zero if lost else buf[_WD * B + k]
                flag[i0 + k] = np.uint8(cd)

    return trace_blocks


_VARIANTS: dict = {}


def variant(mono: bool, opl: bool, fresnel: bool, asphere: bool):
    """The numba dispatcher of one feature set (built once per process; compiled, or loaded from the
    disk cache, at its first call): ``(x, y, z, L, M, N, wl, w, wd, flag, S, kinds, clip, end_z,
    has_end, opl, b0, b1)``, blocks ``b0`` to ``b1`` (an empty float64 ``opl`` without ``opl``)."""
    key = (bool(mono), bool(opl), bool(fresnel), bool(asphere))
    f = _VARIANTS.get(key)
    if f is None:
        f = _VARIANTS[key] = _build(*key)
    return f

"""One ray of one wavelength at a time, in Python floats: the numpy kernel's steps without numpy.

The on-set report traces three chief rays (from the film's edge, top and corner, issue 43);
importing numpy for them costs more than the whole report (docs/performance.md). :func:`rows`
flattens a prescription as :func:`physcam.trace.surfaces.surface_table`, ``kernels._layout.pack``
and ``set_wavelength`` do, and :func:`trace_ray` repeats :mod:`physcam.trace.kernels._numpy`'s
one-wavelength path step by step in the same order of operations (IEEE double arithmetic, square
roots correctly rounded in both), so a ray comes out as the kernel's does (``tests/trace/
test_single_ray.py`` compares them). No Fresnel weights and no optical path: what aiming needs.

A float operation numpy would turn into inf or NaN raises here (a division by zero, the square
root of a negative number); :func:`trace_ray` reports such a ray as lost, like the kernel's flags.
"""

from __future__ import annotations

import math
from typing import NamedTuple

from ..errors import WrongTypeError, require_finite, require_positive, require_type
from ..lens.prescription import Prescription
from ..optics.glass import dispersion, medium_dispersion
from .kernels._layout import CLIPPED, MISSED, NEWTON_MAX_ITER, NEWTON_TOL, OK, TIR

__all__ = ["Row", "rows", "trace_ray"]

_FLAT, _STOP, _QUADRIC, _ASPHERE = 0, 1, 2, 3


class Row(NamedTuple):
    """One surface in tracing order (the columns of ``kernels._layout`` the one-wavelength path reads)."""

    kind: int
    vz: float
    ax: float
    ay: float
    az: float
    cv: float
    ck: float
    semi: float
    unit: bool  # the quadric gradient is already a unit vector (spheres, cylinders, planes)
    n1: float
    n2: float
    eta: float
    aspheric: tuple  # A4 .. A16, seven terms


def _index(coefficients, lam: float) -> float:
    """``kernels._layout.index_rows`` for one row: :func:`physcam.optics.glass.evaluate`'s arithmetic."""
    a0, a1, a2, b1, b2, b3, c1, c2, c3 = coefficients
    l2 = (lam / 1000.0) * (lam / 1000.0)
    u = 1.0 / l2
    n = a0 + (a1 + a2 * u) * u
    if b1 != 0.0 or b2 != 0.0 or b3 != 0.0:
        n = n + math.sqrt(1.0 + b1 * l2 / (l2 - c1) + b2 * l2 / (l2 - c2) + b3 * l2 / (l2 - c3))
    return n


def rows(lens: Prescription, wavelength_nm: float, *, reverse: bool = False) -> tuple[Row, ...]:
    """The surfaces of ``lens`` in tracing order (film side first when ``reverse``) with their indices
    at ``wavelength_nm``: :func:`~physcam.trace.surfaces.surface_table` (no stop override, no coating)."""
    require_type("lens", lens, Prescription, "physcam.lens.library.load_lens(name)")
    wavelength_nm = require_positive("wavelength", wavelength_nm, unit="nm")
    media = (dispersion(1.0, 0.0),) + tuple(medium_dispersion(s.medium) for s in lens.surfaces)
    index = [_index(m.coefficients, float(wavelength_nm)) for m in media]
    out = []
    for i, (s, vz) in enumerate(zip(lens.surfaces, lens.vertex_z)):
        c, k, asph = s.curvature, 0.0, (0.0,) * 7
        ax = ay = az = cv = 0.0
        if s.kind == "stop":
            kind = _STOP
        elif c == 0.0:
            kind = _FLAT
        else:
            cv, k, kind = c, s.conic, _QUADRIC
            if s.kind == "cylindrical_x":
                ax, ay, az = c, 0.0, c
            elif s.kind == "cylindrical_y":
                ax, ay, az = 0.0, c, c
            else:
                ax, ay, az = c, c, (1.0 + s.conic) * c
            if s.kind == "aspheric" and any(a != 0.0 for a in s.aspheric):
                kind = _ASPHERE
                asph = (tuple(float(a) for a in s.aspheric) + (0.0,) * 7)[:7]
        n1, n2 = (index[i + 1], index[i]) if reverse else (index[i], index[i + 1])
        unit = kind <= _STOP or (kind == _QUADRIC and k == 0.0)
        out.append(Row(kind, float(vz), ax, ay, az, cv, k, float(s.semi_diameter), unit, n1, n2, n1 / n2, asph))
    return tuple(out[::-1]) if reverse else tuple(out)


def _asphere_t(r: Row, px, py, qz, dx, dy, dz, t):
    """(t, dsr) of the even asphere's Newton iteration from the conic root ``t``, or None if it fails."""
    cv, coef = r.cv, r.aspheric
    ck1 = (1.0 + r.ck) * cv * cv
    done = False
    for _ in range(NEWTON_MAX_ITER):
        X, Y, Z = px + t * dx, py + t * dy, qz + t * dz
        r2 = X * X + Y * Y
        arg = 1.0 - ck1 * r2
        if arg < 0.0:
            return None
        sa = math.sqrt(arg)
        sag = cv * r2 / (1.0 + sa)
        dsr = cv / sa
        p, q = r2 * r2, r2
        for j in range(7):
            sag = sag + coef[j] * p
            dsr = dsr + (2.0 * j + 4.0) * coef[j] * q
            p = p * r2
            q = q * r2
        gp = dz - dsr * (X * dx + Y * dy)
        if gp == 0.0:
            return None
        dt = (Z - sag) / gp
        t = t - dt
        if abs(dt) < NEWTON_TOL:
            done = True
            break
    if not done:
        return None
    X, Y = px + t * dx, py + t * dy
    r2 = X * X + Y * Y
    arg = 1.0 - ck1 * r2
    if arg < 0.0:
        return None
    dsr = cv / math.sqrt(arg)
    q = r2
    for j in range(7):
        dsr = dsr + (2.0 * j + 4.0) * coef[j] * q
        q = q * r2
    return t, dsr


def _step(r: Row, px, py, pz, dx, dy, dz, clip: bool):
    """One surface: (flag, x, y, z, L, M, N) after it; a lost ray keeps its last position."""
    qz = pz - r.vz
    dsr = 0.0
    if r.kind <= _STOP:
        if dz == 0.0:
            return MISSED
        t = -qz / dz
    else:
        a = r.ax * dx * dx + r.ay * dy * dy + r.az * dz * dz
        b = r.ax * px * dx + r.ay * py * dy + r.az * qz * dz - dz
        c = r.ax * px * px + r.ay * py * py + r.az * qz * qz - 2.0 * qz
        disc = b * b - a * c
        sq = math.sqrt(max(disc, 0.0))
        sgn = 1.0 if dz >= 0.0 else -1.0
        same = b * sgn >= 0.0
        num, den = (-b - sgn * sq, a) if same else (c, -b + sgn * sq)
        if disc < 0.0 or den == 0.0:
            return MISSED
        t = num / den
        if not (r.az * (qz + t * dz) < 1.0):
            return MISSED
        if r.kind == _ASPHERE:
            hit = _asphere_t(r, px, py, qz, dx, dy, dz, t)
            if hit is None:
                return MISSED
            t, dsr = hit
    nx, ny, nz = px + t * dx, py + t * dy, pz + t * dz
    r2 = nx * nx + ny * ny
    if not (r2 - r2 == 0.0):
        return MISSED
    if clip and not (r2 <= r.semi * r.semi):
        return CLIPPED
    if r.kind == _STOP or r.n1 == r.n2:  # the kernel keeps the direction where the index does not change
        return OK, nx, ny, nz, dx, dy, dz
    if r.kind == _FLAT:
        gx, gy, gz = 0.0, 0.0, -1.0
    elif r.kind == _QUADRIC:
        gx, gy, gz = r.ax * nx, r.ay * ny, r.az * (nz - r.vz) - 1.0
    else:
        gx, gy, gz = dsr * nx, dsr * ny, -1.0
    if not r.unit:
        inv = 1.0 / math.sqrt(gx * gx + gy * gy + gz * gz)
        gx, gy, gz = gx * inv, gy * inv, gz * inv
    ci = dx * gx + dy * gy + dz * gz
    sgn = -1.0 if ci < 0.0 else 1.0
    gx, gy, gz, ci = gx * sgn, gy * sgn, gz * sgn, ci * sgn
    eta = r.eta
    kk = 1.0 - eta * eta * (1.0 - ci * ci)
    if not (kk >= 0.0):
        return TIR if kk < 0.0 and ci - ci == 0.0 else MISSED
    f = math.sqrt(kk) - eta * ci
    return OK, nx, ny, nz, eta * dx + f * gx, eta * dy + f * gy, eta * dz + f * gz


def trace_ray(surface_rows, x: float, y: float, z: float, dx: float, dy: float, dz: float, *, clip: bool):
    """Trace one ray (start point in lens space, mm; a unit direction) through ``surface_rows``
    (:func:`rows`): (flag, x, y, z, L, M, N) after the last one, flag ``OK`` or why it was lost
    (``MISSED``, ``CLIPPED``, ``TIR``; then the other six are None)."""
    if type(surface_rows) is not tuple or not all(type(r) is Row for r in surface_rows):
        raise WrongTypeError(f"surface_rows must be physcam.trace.single.rows(lens, wavelength_nm), got "
                             f"{type(surface_rows).__name__}")
    if not all(type(v) is float for v in (x, y, z, dx, dy, dz)):
        x, y, z, dx, dy, dz = (require_finite(n, v, error=WrongTypeError) for n, v in
                               zip(("x", "y", "z", "dx", "dy", "dz"), (x, y, z, dx, dy, dz)))
    for r in surface_rows:
        try:
            out = _step(r, x, y, z, dx, dy, dz, clip)
        except (ZeroDivisionError, ValueError, OverflowError):  # where numpy gives inf or NaN
            out = MISSED
        if type(out) is int:
            return out, None, None, None, None, None, None
        _, x, y, z, dx, dy, dz = out
    return OK, x, y, z, dx, dy, dz

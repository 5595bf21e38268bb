"""Chief rays from a few film points, aimed one at a time in Python floats (no numpy).

The on-set report's real field of view traces three chief rays (issue 43: a report must start
fast, and numpy's import alone costs more than the report). :func:`film_chief_directions` is
:func:`physcam.analysis._chief.aim_from_film` for one ray at a time: the same Newton iteration
(finite-difference Jacobian, backtracking while a step would lose the ray, given up when the error
stops halving) through :mod:`physcam.trace.single`, which repeats the numpy kernel's arithmetic. The
continuation a wide lens's steep rays may need is not repeated here: when a ray does not converge
by Newton alone, the answer is None and the caller takes the numpy path, which would then find it.
"""

from __future__ import annotations

import math

from ..lens.prescription import Prescription
from ..trace.kernels._layout import OK
from ..trace.single import rows, trace_ray

__all__ = ["AIM_TOL_MM", "AIM_MAX_ITER", "film_chief_directions", "unit"]

#: Aiming stops when the ray meets the stop plane within this distance of its centre (mm); both aimers.
AIM_TOL_MM = 1e-9
AIM_MAX_ITER = 20


def unit(dx: float, dy: float, dz: float) -> tuple[float, float, float]:
    """``RayBatch.from_columns``'s normalisation: scaled by the largest component first, then by the norm."""
    big = max(max(abs(dx), abs(dy)), abs(dz))
    dx, dy, dz = dx / big, dy / big, dz / big
    norm = math.sqrt(dx * dx + dy * dy + dz * dz)
    return dx / norm, dy / norm, dz / norm


def _newton(trace, scale: float):
    """``_chief._newton`` for one ray from (0, 0): (u, v, converged)."""
    eps = 1e-6 * scale
    u = v = 0.0

    def probe(uu, vv):
        return trace(uu, vv), trace(uu + eps, vv), trace(uu, vv + eps)

    (rx, ry, good), (ax, ay, ga), (bx, by, gb) = probe(u, v)
    alive = good
    err = math.hypot(rx, ry) if good else math.inf
    slow = 0
    for _ in range(AIM_MAX_ITER):
        if not (alive and err > AIM_TOL_MM):
            break
        j11, j21 = (ax - rx) / eps, (ay - ry) / eps
        j12, j22 = (bx - rx) / eps, (by - ry) / eps
        det = j11 * j22 - j12 * j21
        if not (ga and gb and abs(det) > 1e-300):
            break
        du = (j22 * rx - j12 * ry) / det
        dv = (-j21 * rx + j11 * ry) / det
        step, pending = 1.0, True
        for _ in range(9):  # backtrack while a step would lose the ray
            t = probe(u - step * du, v - step * dv)
            if t[0][2]:
                u, v = u - step * du, v - step * dv
                (rx, ry, good), (ax, ay, ga), (bx, by, gb) = t
                pending = False
                break
            step = 0.5 * step
        alive = not pending
        new = math.hypot(rx, ry) if good else math.inf
        slow = slow + 1 if new > 0.5 * err else 0
        alive = alive and slow < 4
        err = new
    return u, v, math.isfinite(err) and err <= AIM_TOL_MM * 10


def film_chief_directions(lens: Prescription, film_xy, film_z: float, wavelength_nm: float):
    """The aimed chief ray of each film point (x, y) on the plane ``film_z`` (mm, lens space) as
    (flag, L, M, N) after tracing it back out through ``lens`` with clipping (``aim_from_film`` then
    ``trace_through(..., reverse=True, clip=True)``), or None when a ray needs the numpy path."""
    from ..errors import InputError, require_finite, require_positive, require_type
    from ..optics.paraxial import gaussian

    require_type("lens", lens, Prescription, "physcam.lens.library.load_lens(name)")
    film_z, wl = require_finite("film_z", film_z), require_positive("wavelength", wavelength_nm, unit="nm")
    try:
        film_xy = [(require_finite("film x", x), require_finite("film y", y)) for x, y in film_xy]
    except (TypeError, ValueError):
        raise InputError(f"film points must be (x, y) pairs in mm, got {film_xy!r:.60}") from None
    k = lens.stop_index
    back = rows(lens.with_surfaces(lens.surfaces[k:]), wl, reverse=True)
    whole = rows(lens, wl, reverse=True)
    zk = lens.vertex_z[k]
    z_aim = gaussian(lens, wavelength_nm=wl).z_exit_pupil
    if not (film_z - z_aim > 1e-3):  # exit pupil at or behind the film: aim at the rear vertex plane
        z_aim = lens.vertex_z[-1]
    dz = z_aim - film_z
    scale = max(1.0, lens.surfaces[-1].semi_diameter)
    out = []
    for px, py in film_xy:
        def trace(uu, vv, px=px, py=py):
            flag, x, y, *_ = trace_ray(back, px, py, film_z - zk, *unit(uu - px, vv - py, dz), clip=False)
            return (x, y, True) if flag == OK else (0.0, 0.0, False)

        u, v, ok = _newton(trace, scale)
        if not ok:
            return None
        d = (u - px, v - py, dz)
        norm = math.sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2])
        flag, *_, L, M, N = trace_ray(whole, px, py, film_z, *unit(d[0] / norm, d[1] / norm, d[2] / norm), clip=True)
        out.append((flag, L, M, N))
    return out

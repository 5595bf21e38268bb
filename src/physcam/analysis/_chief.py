"""Chief rays found with real rays: aimed so that they pass through the centre of the stop.

Shared by the distortion, illumination, colour and breathing analyses. A chief ray is by
definition the ray of a field point through the centre of the aperture stop (Smith, *Modern
Optical Engineering*, 4th ed., 3.5; Kingslake & Johnson, *Lens Design Fundamentals*, 7.1). The
paraxial entrance (exit) pupil gives a first guess; real pupils are displaced and distorted, so
the ray is *aimed*: a 2-D Newton iteration (finite-difference Jacobian) on the ray's start point
(forward, object at infinity) or on its aim point on the exit-pupil plane (reverse, from a film
point) drives the ray's (x, y) on the stop plane to (0, 0).

Wide fields: the paraxial guess of a steep ray may itself fail (it misses a surface or is totally
reflected, as in a fisheye's front group), so Newton has nowhere to start. Such rays are found by
*continuation*: from the axis (whose chief ray is the axis itself), the field angle (or the film
point) is stepped out to the one asked for, each step's Newton starting from the previous
solution extrapolated linearly; a failed step is halved, a good one doubled. The chief ray is
then the one on the branch connected to the axis, and a ray is reported not ``ok`` only where
that branch ends (the chief ray is totally reflected or misses a surface). Tracing reuses :mod:`physcam.trace`
on the lens cut at the stop (``surfaces[:stop + 1]`` forward, ``surfaces[stop:]`` reverse, whose z origin is then
the stop vertex).

Lengths in mm, lens space (docs/conventions.md). Nothing here returns NaN: a ray that cannot
be aimed (missed, clipped, total internal reflection, no convergence) is reported by ``ok``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from ..lens.geometry import sag
from ..lens.prescription import Prescription, takes_prescription
from ._chief_float import AIM_MAX_ITER, AIM_TOL_MM

__all__ = ["AimedRays", "aim_from_infinity", "aim_from_film", "field_direction", "start_plane_z", "chief_ray_passes",
           "field_limit_deg", "widest_passing_deg", "clamp_note"]

@dataclass
class AimedRays:
    """Chief rays: start points and directions (n, 3) that pass the stop centre; ``ok`` per ray."""

    start: np.ndarray
    direction: np.ndarray
    ok: np.ndarray
    stop_miss_mm: np.ndarray  # distance from the stop centre where the aimed ray crosses the stop plane


def field_direction(angle_rad, axis: str = "y") -> np.ndarray:
    """Unit directions (n, 3) of collimated light at field ``angle_rad`` in the ``axis``-Z meridian.

    A positive angle travels toward +axis: the light comes from the -axis side of the scene, and
    its (inverted) image forms on the +axis side of the film.
    """
    a = np.atleast_1d(np.asarray(angle_rad, dtype=np.float64))
    d = np.zeros((a.size, 3))
    d[:, 0 if axis == "x" else 1] = np.sin(a)
    d[:, 2] = np.cos(a)
    return d


@takes_prescription
def start_plane_z(lens: Prescription) -> float:
    """A plane in front of the first surface's whole clear aperture (mm, lens space)."""
    s = lens.surfaces[0]
    return -1.0 - max(abs(sag(s, s.semi_diameter, "x")), abs(sag(s, s.semi_diameter, "y")), 0.0)


def _newton(residual, u, v, scale, max_iter: int = AIM_MAX_ITER):
    """Solve residual(u, v) = (0, 0) per ray; returns u, v, ok, |residual|.

    The finite-difference Jacobian is traced together with each point (one tracer call of 3n
    rays per iteration). A step that would lose the ray (miss, total reflection) is halved, up
    to 8 times; a ray with no step left that keeps it, or whose error has not halved in four
    iterations in a row, is given up.
    """
    n = u.size
    eps = 1e-6 * scale

    def probe(uu, vv):
        rx, ry, g = residual(np.concatenate([uu, uu + eps, uu]), np.concatenate([vv, vv, vv + eps]))
        return rx[:n], ry[:n], g[:n], rx[n:2 * n], ry[n:2 * n], g[n:2 * n], rx[2 * n:], ry[2 * n:], g[2 * n:]

    rx, ry, good, ax, ay, ga, bx, by, gb = probe(u, v)
    alive = good.copy()
    err = np.where(good, np.hypot(rx, ry), np.inf)
    slow = np.zeros(n, dtype=int)  # iterations in a row that did not halve the error
    for _ in range(max_iter):
        todo = alive & (err > AIM_TOL_MM)
        if not todo.any():
            break
        j11, j21 = (ax - rx) / eps, (ay - ry) / eps
        j12, j22 = (bx - rx) / eps, (by - ry) / eps
        det = j11 * j22 - j12 * j21
        usable = todo & ga & gb & (np.abs(det) > 1e-300)
        alive &= usable | ~todo
        if not usable.any():
            break
        safe = np.where(usable, det, 1.0)
        du = np.where(usable, (j22 * rx - j12 * ry) / safe, 0.0)
        dv = np.where(usable, (-j21 * rx + j11 * ry) / safe, 0.0)
        step = np.where(usable, 1.0, 0.0)
        pending = usable.copy()
        for _ in range(9):  # backtrack while a step would lose the ray
            t = probe(u - step * du, v - step * dv)
            took = pending & t[2]
            if took.any():
                u = np.where(took, u - step * du, u)
                v = np.where(took, v - step * dv, v)
                rx, ry, good, ax, ay, ga, bx, by, gb = (np.where(took, new, old) for new, old in
                                                        zip(t, (rx, ry, good, ax, ay, ga, bx, by, gb)))
            pending &= ~took
            if not pending.any():
                break
            step = np.where(pending, 0.5 * step, step)
        alive &= ~pending
        new = np.where(good, np.hypot(rx, ry), np.inf)
        slow = np.where(new > 0.5 * err, slow + 1, 0)
        alive &= slow < 4  # not converging: give up (continuation takes over)
        err = new
    ok = np.isfinite(err) & (err <= AIM_TOL_MM * 10)
    return u, v, ok, np.where(np.isfinite(err), err, 0.0)


def _continuation(residual_t, n: int, scale: float, *, min_step: float = 2e-3, max_rounds: int = 200):
    """Solve residual_t(u, v, t, idx) = 0 at t = 1 for rays ``idx`` by continuation from t = 0.

    At t = 0 every ray is the axis, whose solution is u = v = 0. Returns u, v, ok, |residual|.
    """
    t = np.zeros(n)
    u, v = np.zeros(n), np.zeros(n)
    su, sv = np.zeros(n), np.zeros(n)  # du/dt, dv/dt from the last two solutions
    dt = np.full(n, 0.25)
    done = np.zeros(n, dtype=bool)
    dead = np.zeros(n, dtype=bool)
    err = np.zeros(n)
    for _ in range(max_rounds):
        act = np.flatnonzero(~done & ~dead)
        if act.size == 0:
            break
        tt = np.minimum(t[act] + dt[act], 1.0)
        h = tt - t[act]
        u0, v0 = u[act] + su[act] * h, v[act] + sv[act] * h
        uu, vv, good, e = _newton(lambda a, b: residual_t(a, b, tt, act), u0, v0, scale, max_iter=8)
        g, b = act[good], act[~good]
        su[g] = (uu[good] - u[g]) / h[good]
        sv[g] = (vv[good] - v[g]) / h[good]
        u[g], v[g], t[g], err[g] = uu[good], vv[good], tt[good], e[good]
        dt[g] = np.minimum(2.0 * dt[g], 0.5)
        done[g] = tt[good] >= 1.0
        dt[b] *= 0.5
        dead[b] = dt[b] < min_step
    return u, v, done, err


@takes_prescription
def aim_from_infinity(
    lens: Prescription, directions, *, wavelength_nm: float, backend: str = "auto"
) -> AimedRays:
    """Chief rays of collimated beams along ``directions`` (n, 3), starting on :func:`start_plane_z`."""
    from ..optics.paraxial import gaussian_xy
    from ..trace import RayBatch, trace_through

    d = np.atleast_2d(np.asarray(directions, dtype=np.float64))
    if d.ndim != 2 or d.shape[1] != 3 or not np.isfinite(d).all():
        raise InputError(f"directions must be finite (n, 3) vectors, got shape {d.shape}")
    d = d / np.linalg.norm(d, axis=1)[:, None]
    if (d[:, 2] <= 1e-6).any():
        raise InputError("field directions must travel toward the film (field angle below 90 degrees)")
    k = lens.stop_index
    front = lens.with_surfaces(lens.surfaces[: k + 1])
    z0 = start_plane_z(lens)
    g = gaussian_xy(lens, wavelength_nm=wavelength_nm)
    # paraxial guess: the ray crosses the axis at the entrance pupil (per meridian for anamorphics)
    u = -(g["x"].z_entrance_pupil - z0) * d[:, 0] / d[:, 2]
    v = -(g["y"].z_entrance_pupil - z0) * d[:, 1] / d[:, 2]

    def trace(uu, vv, dd):  # uu, vv may hold several copies of the rays (Newton's probes)
        dd = np.tile(dd, (uu.size // dd.shape[0], 1))
        pos = np.stack([uu, vv, np.full(uu.size, z0)], axis=1)
        out = trace_through(front, RayBatch.from_arrays(pos, dd, wavelength_nm), clip=False, backend=backend)
        return out.x, out.y, out.ok

    scale = max(1.0, lens.surfaces[0].semi_diameter)
    u, v, ok, err = _newton(lambda uu, vv: trace(uu, vv, d), u, v, scale)
    bad = np.flatnonzero(~ok)
    if bad.size:  # continuation in field angle from the axis, keeping the azimuth
        theta = np.arccos(np.clip(d[bad, 2], -1.0, 1.0))
        phi = np.arctan2(d[bad, 1], d[bad, 0])

        def residual_t(uu, vv, t, idx):
            a = t * theta[idx]
            dd = np.stack([np.sin(a) * np.cos(phi[idx]), np.sin(a) * np.sin(phi[idx]), np.cos(a)], axis=1)
            return trace(uu, vv, dd)

        cu, cv, cok, cerr = _continuation(residual_t, bad.size, scale)
        u[bad], v[bad], ok[bad], err[bad] = cu, cv, cok, cerr
    start = np.stack([u, v, np.full(u.size, z0)], axis=1)
    return AimedRays(start, d, ok, err)


@takes_prescription
def aim_from_film(
    lens: Prescription, film_xy, film_z: float, *, wavelength_nm: float, backend: str = "auto"
) -> AimedRays:
    """Chief rays leaving film points ``film_xy`` (n, 2) on the plane ``film_z`` toward the scene.

    The returned directions point toward -z (film to scene); trace them with ``reverse=True``.
    """
    from ..optics.paraxial import gaussian
    from ..trace import RayBatch, trace_through

    p = np.atleast_2d(np.asarray(film_xy, dtype=np.float64))
    if p.ndim != 2 or p.shape[1] != 2 or not np.isfinite(p).all():
        raise InputError(f"film points must be finite (n, 2) coordinates in mm, got shape {p.shape}")
    k = lens.stop_index
    back = lens.with_surfaces(lens.surfaces[k:])
    zk = lens.vertex_z[k]  # the cut lens has its first vertex (the stop) at z = 0
    z_rear = lens.vertex_z[-1]
    z_aim = gaussian(lens, wavelength_nm=wavelength_nm).z_exit_pupil
    if not (film_z - z_aim > 1e-3):  # exit pupil at or behind the film: aim at the rear vertex plane
        z_aim = z_rear
    dz = z_aim - film_z

    def trace(uu, vv, q):  # uu, vv may hold several copies of the rays (Newton's probes)
        q = np.tile(q, (uu.size // q.shape[0], 1))
        pos = np.stack([q[:, 0], q[:, 1], np.full(uu.size, film_z - zk)], axis=1)
        dirn = np.stack([uu - q[:, 0], vv - q[:, 1], np.full(uu.size, dz)], axis=1)
        out = trace_through(back, RayBatch.from_arrays(pos, dirn, wavelength_nm), reverse=True, clip=False,
                            backend=backend)
        return out.x, out.y, out.ok

    scale = max(1.0, lens.surfaces[-1].semi_diameter)
    u, v, ok, err = _newton(lambda uu, vv: trace(uu, vv, p), np.zeros(p.shape[0]), np.zeros(p.shape[0]), scale)
    bad = np.flatnonzero(~ok)
    if bad.size:  # continuation in film height from the axis
        pb = p[bad]
        cu, cv, cok, cerr = _continuation(lambda uu, vv, t, idx: trace(uu, vv, t[:, None] * pb[idx]), bad.size, scale)
        u[bad], v[bad], ok[bad], err[bad] = cu, cv, cok, cerr
    start = np.stack([p[:, 0], p[:, 1], np.full(p.shape[0], film_z)], axis=1)
    dirn = np.stack([u - p[:, 0], v - p[:, 1], np.full(p.shape[0], dz)], axis=1)
    dirn /= np.linalg.norm(dirn, axis=1)[:, None]
    return AimedRays(start, dirn, ok, err)


def field_angles_deg(fields_deg, max_field_deg, n_fields: int, half_diagonal_mm: float, efl_mm: float) -> np.ndarray:
    """The field angles (degrees) an analysis evaluates.

    ``fields_deg`` as given (each within +-89 degrees), or else ``n_fields`` (2 to 200) from
    0 to ``max_field_deg``, by default the sensor corner: atan(half diagonal / EFL).
    """
    import math

    from ..errors import InputError, require_finite

    if fields_deg is not None:
        fields = np.array([require_finite("field angle", f) for f in np.atleast_1d(fields_deg)], dtype=float)
        if fields.size == 0 or (np.abs(fields) >= 89).any():
            raise InputError("give field angles between -89 and 89 degrees")
        return fields
    if isinstance(n_fields, bool) or not isinstance(n_fields, (int, np.integer)) or not 2 <= n_fields <= 200:
        raise InputError(f"n_fields must be a whole number from 2 to 200, got {n_fields!r}")
    top = max_field_deg
    if top is None:
        top = math.degrees(math.atan(half_diagonal_mm / abs(efl_mm)))
    top = require_finite("max field", top)
    if not 0 < top < 89:
        raise InputError(f"max field must lie between 0 and 89 degrees, got {top:g}")
    return np.linspace(0.0, top, int(n_fields))


@takes_prescription
def chief_ray_passes(lens: Prescription, fields_deg, axis: str = "y", *, wavelength_nm: float,
                     backend: str = "auto") -> np.ndarray:
    """Whether the aimed chief ray of each field angle (degrees, ``axis``-Z meridian) goes through
    every clear aperture of ``lens`` (clipping at each rim and the stop)."""
    from ..trace import RayBatch, trace_through

    aimed = aim_from_infinity(lens, field_direction(np.radians(fields_deg), axis), wavelength_nm=wavelength_nm,
                              backend=backend)
    out = trace_through(lens, RayBatch.from_arrays(aimed.start, aimed.direction, wavelength_nm), clip=True,
                        backend=backend)
    return aimed.ok & out.ok


@takes_prescription
def field_limit_deg(lens: Prescription, axis: str = "y", *, max_deg: float = 89.0, wavelength_nm: float,
                    tol_deg: float = 0.01, backend: str = "auto") -> float:
    """The largest field angle (degrees, up to ``max_deg``) up to which the aimed chief rays pass.

    Scans from the axis in steps of at most 1 degree to the first field whose chief ray does not
    pass, then bisects between it and the last that does to ``tol_deg``. Returns ``max_deg`` when
    every field passes. Raises :class:`OpticsError` when not even the axial ray passes.
    """
    from ..errors import OpticsError

    if not 0.0 < max_deg < 90.0:
        raise InputError(f"the field limit is searched below 90 degrees, got {max_deg:g}")
    if not tol_deg > 0.0:
        raise InputError(f"tol_deg must be > 0, got {tol_deg:g}")
    grid = np.linspace(0.0, max_deg, max(2, int(np.ceil(max_deg)) + 1))
    lo = hi = None
    for a in range(0, grid.size, 10):  # in chunks from the axis, up to the first field that fails
        ok = chief_ray_passes(lens, grid[a:a + 10], axis, wavelength_nm=wavelength_nm, backend=backend)
        if not ok.all():
            i = a + int(np.argmin(ok))
            if i == 0:
                raise OpticsError(f"no chief ray passes {lens.name!r} on the axis")
            lo, hi = float(grid[i - 1]), float(grid[i])
            break
    if lo is None:
        return float(max_deg)
    bracket = [lo, hi]
    bisect_together(lambda mids: chief_ray_passes(lens, mids, axis, wavelength_nm=wavelength_nm, backend=backend),
                    [bracket], tol_deg)
    return bracket[0]


def bisect_together(passes, brackets, tol: float, depth: int = 10) -> None:
    """Bisect each bracket [x that passes, x that fails] of ``brackets`` in place until shorter than ``tol``
    (``passes(xs)``: a bool per x; each x's answer its own). Every midpoint the next ``depth`` steps can reach
    is asked in one batch (a step asks one ray; a tracer call costs about the same for one ray or a
    thousand), then the steps are taken by those answers: the same midpoints, computed alike, as one step
    at a time."""
    while True:
        open_ = [e for e in brackets if abs(e[1] - e[0]) > tol]
        if not open_:
            return
        reach = []  # every (passing, failing) bracket the next steps can hold

        def grow(inside, outside, left):
            if left and abs(outside - inside) > tol:
                reach.append((inside, outside))
                mid = 0.5 * (inside + outside)
                grow(mid, outside, left - 1)
                grow(inside, mid, left - 1)

        for e in open_:
            grow(e[0], e[1], depth)
        known = dict(zip(reach, passes(np.array([0.5 * (i + o) for i, o in reach]))))
        for e in open_:
            while (e[0], e[1]) in known and abs(e[1] - e[0]) > tol:
                e[int(not known[(e[0], e[1])])] = 0.5 * (e[0] + e[1])


def widest_passing_deg(passes, good_deg: float, bad_deg: float, *, tol_deg: float = 0.01) -> float:
    """The widest field (degrees) between ``good_deg`` (where ``passes(field)`` is true) and
    ``bad_deg`` (where it is false) at which ``passes`` still holds, bisected to ``tol_deg``.

    The analyses share it to clamp their default field range to what the lens images, each with
    its own test (a chief ray at every wavelength, light through the lens), and say so in a note
    (:func:`clamp_note`).
    """
    from ..errors import require_finite, require_positive

    if not callable(passes):
        raise InputError(f"passes must be a function of the field angle, got {type(passes).__name__}")
    lo, hi = require_finite("good field", good_deg), require_finite("bad field", bad_deg)
    tol_deg = require_positive("tolerance", tol_deg, unit="deg")
    while hi - lo > tol_deg:
        mid = 0.5 * (lo + hi)
        if passes(mid):
            lo = mid
        else:
            hi = mid
    return lo


def clamp_note(axis: str, what: str, top_deg: float, asked_deg: float) -> str:
    """The note an analysis adds when it clamps its default field range to what the lens images."""
    from ..errors import require_finite

    if axis not in ("x", "y") or not isinstance(what, str):
        raise InputError(f"clamp_note takes a meridian 'x' or 'y' and a text, got {axis!r}, {what!r}")
    top_deg, asked_deg = require_finite("field", top_deg), require_finite("field", asked_deg)
    return (f"{axis.upper()} meridian: {what} pass only up to {top_deg:.2f} deg (the default range reaches "
            f"{asked_deg:.2f} deg, the sensor corner): fields clamped to {top_deg:.2f} deg")

"""Chief rays found with real rays: aimed so that they pass through the centre of the stop.

Shared by the distortion, illumination, colour and breathing analyses. A chief ray is by
definition the ray of a field point through the centre of the aperture stop (Smith, *Modern
Optical Engineering*, 4th ed., 3.5; Kingslake & Johnson, *Lens Design Fundamentals*, 7.1). The
paraxial entrance (exit) pupil gives a first guess; real pupils are displaced and distorted, so
the ray is *aimed*: a 2-D Newton iteration (finite-difference Jacobian) on the ray's start point
(forward, object at infinity) or on its aim point on the exit-pupil plane (reverse, from a film
point) drives the ray's (x, y) on the stop plane to (0, 0). Tracing reuses :mod:`physcam.trace`
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
from ..lens.prescription import Prescription

__all__ = ["AimedRays", "aim_from_infinity", "aim_from_film", "field_direction", "start_plane_z"]

#: Aiming stops when the ray meets the stop plane within this distance of its centre (mm).
AIM_TOL_MM = 1e-9
AIM_MAX_ITER = 40


@dataclass
class AimedRays:
    """Chief rays: start points and directions (n, 3) that pass the stop centre; ``ok`` per ray."""

    start: np.ndarray
    direction: np.ndarray
    ok: np.ndarray
    stop_miss_mm: np.ndarray  # distance from the stop centre where the aimed ray crosses the stop plane


def field_direction(angle_rad, axis: str = "y") -> np.ndarray:
    """Unit directions (n, 3) of collimated light at field ``angle_rad`` in the ``axis``-Z meridian.

    A positive angle travels toward +axis (so its image forms at -axis: the image is inverted).
    """
    a = np.atleast_1d(np.asarray(angle_rad, dtype=np.float64))
    d = np.zeros((a.size, 3))
    d[:, 0 if axis == "x" else 1] = np.sin(a)
    d[:, 2] = np.cos(a)
    return d


def start_plane_z(lens: Prescription) -> float:
    """A plane in front of the first surface's whole clear aperture (mm, lens space)."""
    s = lens.surfaces[0]
    return -1.0 - max(abs(sag(s, s.semi_diameter, "x")), abs(sag(s, s.semi_diameter, "y")), 0.0)


def _newton(residual, u, v, scale):
    """Solve residual(u, v) = (0, 0) per ray; returns u, v, ok, |residual|."""
    n = u.size
    ok = np.ones(n, dtype=bool)
    eps = 1e-6 * scale
    err = np.full(n, np.inf)
    for _ in range(AIM_MAX_ITER):
        rx, ry, good = residual(u, v)
        err = np.where(good, np.hypot(rx, ry), np.inf)
        todo = good & (err > AIM_TOL_MM)
        if not todo.any():
            break
        ax, ay, ga = residual(u + eps, v)
        bx, by, gb = residual(u, v + eps)
        j11, j21 = (ax - rx) / eps, (ay - ry) / eps
        j12, j22 = (bx - rx) / eps, (by - ry) / eps
        det = j11 * j22 - j12 * j21
        usable = todo & ga & gb & (np.abs(det) > 1e-300)
        safe = np.where(usable, det, 1.0)
        du = np.where(usable, (j22 * rx - j12 * ry) / safe, 0.0)
        dv = np.where(usable, (-j21 * rx + j11 * ry) / safe, 0.0)
        # a damped step when a full one would leave the lens
        u2, v2 = u - du, v - dv
        _, _, g2 = residual(u2, v2)
        half = usable & ~g2
        u = np.where(usable & g2, u2, np.where(half, u - 0.5 * du, u))
        v = np.where(usable & g2, v2, np.where(half, v - 0.5 * dv, v))
    ok &= np.isfinite(err) & (err <= AIM_TOL_MM * 10)
    return u, v, ok, np.where(np.isfinite(err), err, 0.0)


def aim_from_infinity(
    lens: Prescription, directions, *, wavelength_nm: float, backend: str = "auto"
) -> AimedRays:
    """Chief rays of collimated beams along ``directions`` (n, 3), starting on :func:`start_plane_z`."""
    from ..optics.paraxial import gaussian_xy
    from ..trace import RayBatch, trace_through

    d = np.atleast_2d(np.asarray(directions, dtype=np.float64))
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

    def residual(uu, vv):
        pos = np.stack([uu, vv, np.full(uu.size, z0)], axis=1)
        out = trace_through(front, RayBatch.from_arrays(pos, d, wavelength_nm), clip=False, backend=backend)
        return out.x, out.y, out.ok

    u, v, ok, err = _newton(residual, u, v, max(1.0, lens.surfaces[0].semi_diameter))
    start = np.stack([u, v, np.full(u.size, z0)], axis=1)
    return AimedRays(start, d, ok, err)


def aim_from_film(
    lens: Prescription, film_xy, film_z: float, *, wavelength_nm: float, backend: str = "auto"
) -> AimedRays:
    """Chief rays leaving film points ``film_xy`` (n, 2) on the plane ``film_z`` toward the scene.

    The returned directions point toward -z (film to scene); trace them with ``reverse=True``.
    """
    from ..optics.paraxial import gaussian
    from ..trace import RayBatch, trace_through

    p = np.atleast_2d(np.asarray(film_xy, dtype=np.float64))
    k = lens.stop_index
    back = lens.with_surfaces(lens.surfaces[k:])
    zk = lens.vertex_z[k]  # the cut lens has its first vertex (the stop) at z = 0
    z_rear = lens.vertex_z[-1]
    z_aim = gaussian(lens, wavelength_nm=wavelength_nm).z_exit_pupil
    if not (film_z - z_aim > 1e-3):  # exit pupil at or behind the film: aim at the rear vertex plane
        z_aim = z_rear
    dz = z_aim - film_z

    def residual(uu, vv):
        pos = np.stack([p[:, 0], p[:, 1], np.full(uu.size, film_z - zk)], axis=1)
        dirn = np.stack([uu - p[:, 0], vv - p[:, 1], np.full(uu.size, dz)], axis=1)
        out = trace_through(back, RayBatch.from_arrays(pos, dirn, wavelength_nm), reverse=True, clip=False,
                            backend=backend)
        return out.x, out.y, out.ok

    u, v, ok, err = _newton(residual, np.zeros(p.shape[0]), np.zeros(p.shape[0]),
                            max(1.0, lens.surfaces[-1].semi_diameter))
    start = np.stack([p[:, 0], p[:, 1], np.full(p.shape[0], film_z)], axis=1)
    dirn = np.stack([u - p[:, 0], v - p[:, 1], np.full(p.shape[0], dz)], axis=1)
    dirn /= np.linalg.norm(dirn, axis=1)[:, None]
    return AimedRays(start, dirn, ok, err)


def field_angles_deg(fields_deg, max_field_deg, n_fields: int, half_diagonal_mm: float, efl_mm: float) -> np.ndarray:
    """The field angles (degrees) an analysis evaluates.

    ``fields_deg`` as given (each within +-89 degrees), or else ``n_fields`` (at least 2) from
    0 to ``max_field_deg``, by default the sensor corner: atan(half diagonal / EFL).
    """
    import math

    from ..errors import InputError, require_finite

    if fields_deg is not None:
        fields = np.array([require_finite("field angle", f) for f in np.atleast_1d(fields_deg)], dtype=float)
        if fields.size == 0 or (np.abs(fields) >= 89).any():
            raise InputError("give field angles between -89 and 89 degrees")
        return fields
    top = max_field_deg
    if top is None:
        top = math.degrees(math.atan(half_diagonal_mm / abs(efl_mm)))
    top = require_finite("max field", top)
    if not 0 < top < 89:
        raise InputError(f"max field must lie between 0 and 89 degrees, got {top:g}")
    return np.linspace(0.0, top, max(2, int(n_fields)))

"""Where a lens stopped to an f-number images a point: the centroid of its blur on the film.

A chief ray says where the centre of a small stop sends an object point; at a working aperture the
aberrations (coma, the field's own curvature against a flat film) spread the point into a blur
whose energy centroid lies elsewhere by up to a pixel or so on a wide lens (issue 24: the Zuiko
18 mm's chief-ray map misses its f/4 centroids by 0.59 px RMS on a 2048-pixel frame). The
centroid is what a tracker, a chart detector or a compositor's eye locks onto, so distortion at a
stop is measured on it (Smith, *Modern Optical Engineering*, 4th ed., 10.4: centroid distortion).

Method: from each object point (a finite point, or a direction for an object at infinity), rays
are sent toward points on the entrance-pupil plane; the lens's own stop at the iris size clips
them. A coarse pilot grid on a square centred where the real chief ray crosses that plane, larger
than the paraxial entrance pupil (``overfill``: real pupils shift and grow off axis, and the square
doubles until no passing ray touches its edge), finds the box that holds each point's beam; a fine
regular grid over that box gives the centroid as the mean film position of the rays that pass
(the grid is uniform in the pupil plane, so each passing ray stands for the same area of the beam,
as in the FFT pupil sampling of the image-quality analyses).

Lengths in mm, lens space (docs/conventions.md).
"""

from __future__ import annotations

import numpy as np

from ..errors import OpticsError

__all__ = ["image_centroids", "image_moments", "PUPIL_GRID"]

#: Pupil samples per side of the square grid laid over each beam's own box on the pupil plane.
PUPIL_GRID = 32
#: Samples per side of the coarse grid that finds each beam's box first.
PILOT_GRID = 12
#: Object points traced per tracer call (bounds memory: PUPIL_GRID^2 rays each).
POINTS_PER_CALL = 2048


def _grid(k: int) -> np.ndarray:
    """Cell centres (k * k, 2) of a k x k grid on [-1, 1]^2."""
    u = (np.arange(k) + 0.5) / k * 2.0 - 1.0
    x, y = np.meshgrid(u, u)
    return np.stack([x.ravel(), y.ravel()], axis=1)


def _trace(q, film_z, objects, at_infinity, centre, half, z_ep, iris, wl, backend, grid):
    """Rays from each object toward ``centre + half * grid`` on the pupil plane: film (n, m, 2), ok (n, m)."""
    from ..trace import RayBatch, trace_to_film
    from ._chief import start_plane_z

    n, m = len(objects), len(grid)
    target = np.empty((n, m, 3))
    target[..., :2] = centre[:, None, :] + half[:, None, :] * grid[None, :, :]
    target[..., 2] = z_ep
    if at_infinity:  # objects are unit directions: start on a plane in front of the lens
        d = np.broadcast_to(objects[:, None, :], (n, m, 3))
        z0 = start_plane_z(q)
        start = target + d * ((z0 - z_ep) / d[..., 2])[..., None]
    else:
        start = np.broadcast_to(objects[:, None, :], (n, m, 3))
        d = target - start
    out = trace_to_film(q, RayBatch.from_arrays(start.reshape(-1, 3), d.reshape(-1, 3), wl), film_z, clip=True,
                        stop_semi_diameter=iris, fresnel=False, backend=backend)
    return np.stack([out.x, out.y], axis=1).reshape(n, m, 2), out.ok.reshape(n, m)


def _beam_boxes(q, film_z, objects, at_infinity, crossing, z_ep, radius, iris, wl, backend):
    """(centre, half sizes) (n, 2) each of the box on the pupil plane that holds each point's beam."""
    k = PILOT_GRID
    pilot = _grid(k)
    half = np.full((len(objects), 2), radius)
    for _ in range(4):  # grow the square until no passing ray touches its edge
        _, ok = _trace(q, film_z, objects, at_infinity, crossing, half, z_ep, iris, wl, backend, pilot)
        if not ok.any(axis=1).all():
            raise OpticsError("no ray of an object point passes the stop at this f-stop: the field is vignetted there")
        edge = (np.abs(pilot) > 1.0 - 1.5 / k).any(axis=1)
        if not (ok & edge[None, :]).any():
            break
        half *= 2.0
    else:
        raise OpticsError("the beam through the stop is wider than 16 entrance pupils: cannot sample it")
    cell = 2.0 / k  # one pilot cell around the passing ones, so the box holds the whole beam
    lo = np.where(ok[..., None], pilot[None], np.inf).min(axis=1) - cell
    hi = np.where(ok[..., None], pilot[None], -np.inf).max(axis=1) + cell
    return crossing + half * (lo + hi) / 2, half * (hi - lo) / 2


def image_moments(q, film_z: float, objects, *, at_infinity: bool, crossing, z_ep: float, pupil_radius: float,
                  stop_semi_diameter: float, wavelength_nm: float, backend: str = "auto", overfill: float = 2.0,
                  grid: int = PUPIL_GRID, energy_fraction: float | None = None):
    """(centroids (n, 2) mm, second moments E[r^2] (n,) mm^2 about them) of the blurs of object points
    imaged on the film by ``q`` (a focused lens) with its stop at ``stop_semi_diameter`` (module notes).

    ``objects``: (n, 3) object points in lens space, or with ``at_infinity`` unit directions of the
    light; ``crossing``: (n, 2) where each point's real chief ray crosses the entrance-pupil plane
    ``z_ep``; ``pupil_radius``: the paraxial entrance pupil's radius at that iris; ``grid``: pupil
    samples per side of each beam's box. With ``energy_fraction`` a third array: the radius (mm) about
    each centroid that holds that fraction of the rays. Raises :class:`OpticsError` for a point no ray
    of which reaches the film."""
    objects = np.atleast_2d(np.asarray(objects, dtype=float))
    crossing = np.atleast_2d(np.asarray(crossing, dtype=float))
    fine = _grid(grid)
    cen = np.empty((len(objects), 2))
    m2 = np.empty(len(objects))
    radius = np.empty(len(objects))
    for i0 in range(0, len(objects), POINTS_PER_CALL):
        sl = slice(i0, i0 + POINTS_PER_CALL)
        args = (q, film_z, objects[sl], at_infinity)
        centre, half = _beam_boxes(*args, crossing[sl], z_ep, pupil_radius * overfill, stop_semi_diameter,
                                   wavelength_nm, backend)
        film, ok = _trace(*args, centre, half, z_ep, stop_semi_diameter, wavelength_nm, backend, fine)
        count = ok.sum(axis=1)
        if not (count > 0).all():
            raise OpticsError("no ray of an object point passes the stop at this f-stop: the field is vignetted there")
        c = np.where(ok[..., None], film, 0.0).sum(axis=1) / count[:, None]
        d2 = ((film - c[:, None, :]) ** 2).sum(axis=2)
        cen[sl], m2[sl] = c, np.where(ok, d2, 0.0).sum(axis=1) / count
        if energy_fraction is not None:
            r = np.sort(np.where(ok, np.sqrt(d2), np.inf), axis=1)
            k = np.maximum(np.ceil(energy_fraction * count).astype(int) - 1, 0)
            radius[sl] = r[np.arange(len(k)), k]
    return (cen, m2) if energy_fraction is None else (cen, m2, radius)


def image_centroids(q, film_z: float, objects, **kwargs) -> np.ndarray:
    """Film centroids (n, 2) mm of object points (arguments as :func:`image_moments`)."""
    return image_moments(q, film_z, objects, **kwargs)[0]

"""The pupil tables' oracle in the tests: physcam's tracer run the plain way, with no table, search or stop
probe of the extension's (physcam.export.blender_pupil, blender_pupil_sets): rays from a film point toward
aim points, every clear aperture clipping and the iris stopped to one radius."""

from __future__ import annotations

import numpy as np

from physcam.trace.rays import OK, RayBatch
from physcam.trace.trace import trace_through


def passing_aims(q, film_z: float, rho: float, s: float, gx, gy) -> np.ndarray:
    """Which rays from film point (``rho``, 0) at ``film_z`` toward the aims (``gx``, ``gy``) on the rear vertex
    plane (mm) pass the focused prescription ``q`` with its iris at radius ``s`` (mm): a boolean per aim."""
    gx, gy = np.asarray(gx, dtype=float), np.asarray(gy, dtype=float)
    rays = RayBatch.from_arrays(np.broadcast_to([rho, 0.0, film_z], (gx.size, 3)),
                                np.stack([gx - rho, gy, np.full(gx.size, q.vertex_z[-1] - film_z)], axis=1),
                                q.wavelength_nm)
    trace_through(q, rays, reverse=True, clip=True, stop_semi_diameter=s, in_place=True)
    return rays.flag == OK

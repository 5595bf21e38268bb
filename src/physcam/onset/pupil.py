"""Entrance pupil and the parallax-free (nodal) rotation pivot.

Parallax-free pans and tilts rotate about the entrance pupil (often called the
"nodal point" on set). Without a datasheet it is estimated from a tape measure:
it lies a fraction (0.3-0.5, default 0.4) of the lens length behind the front of
the lens (seed 000, Appendix G; R. Kingslake, *Optics in Photography*, ch. 6, on
the entrance pupil as the centre of perspective).

Distances are in front of the film plane (docs/conventions.md). Camera space is
USD's: the camera looks down -Z with +Y up, origin at the film plane centre.
"""

from __future__ import annotations

from ..errors import InputError, require_finite, require_positive

__all__ = ["entrance_pupil_practical", "pivot_camera_space", "pivot_world"]


def entrance_pupil_practical(sensor_to_lens_front_mm: float, lens_length_mm: float, fraction: float = 0.4) -> float:
    """Entrance pupil distance in front of the film plane, estimated from a tape measure.

    ``sensor_to_lens_front_mm``: film-plane mark to the front of the lens;
    ``lens_length_mm``: the barrel length; ``fraction``: how far behind the front, as a
    fraction of the lens length, the pupil is assumed to lie.

    >>> entrance_pupil_practical(250.0, 150.0)
    190.0
    """
    front = require_positive("sensor-to-lens-front distance", sensor_to_lens_front_mm)
    length = require_positive("lens length", lens_length_mm)
    frac = require_finite("pupil fraction", fraction)
    if not 0.0 <= frac <= 1.0:
        raise InputError(f"pupil fraction must lie between 0 and 1 of the lens length, got {frac:g}")
    if length > front:
        raise InputError(
            f"lens length {length:g} mm is longer than the film-to-lens-front distance {front:g} mm; "
            "measure the film mark to the front of the lens"
        )
    return front - frac * length


def pivot_camera_space(pupil_from_film_mm: float) -> tuple[float, float, float]:
    """The pivot in camera space (mm): on the optical axis, ``pupil_from_film_mm`` along -Z."""
    p = require_finite("entrance pupil distance", pupil_from_film_mm)
    return (0.0, 0.0, -p)


def pivot_world(pupil_from_film_mm: float, camera_to_world, mm_per_unit: float = 10.0):
    """The pivot as a world-space point for a camera transform.

    ``camera_to_world`` is a 4x4 matrix in USD's row-vector convention
    (p_world = p_camera @ M, translation in the last row), in world units;
    ``mm_per_unit`` converts the pivot's millimetres to those units (10 for centimetres).
    """
    import numpy as np

    m = np.asarray(camera_to_world, dtype=float)
    if m.shape != (4, 4) or not np.all(np.isfinite(m)):
        raise InputError("camera transform must be a finite 4x4 matrix")
    x, y, z = pivot_camera_space(pupil_from_film_mm)
    p = np.array([x, y, z, 1.0]) / np.array([mm_per_unit, mm_per_unit, mm_per_unit, 1.0]) @ m
    return tuple(float(v) for v in p[:3] / p[3])

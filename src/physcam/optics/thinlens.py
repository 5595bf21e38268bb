"""Thin-lens (Gaussian) imaging: conjugates, magnification, field of view.

Gaussian imaging law 1/f = 1/s + 1/s' with s measured from the front principal
plane H1 toward the subject and s' from the rear principal plane H2 toward the
film (docs/conventions.md). Source: E. Hecht, *Optics*, 5th ed., §5.2.3 (thin-lens
equation) and §5.2.3 Eq. 5.26 (transverse magnification m = -s'/s; physcam reports
its magnitude, the image is inverted).

All functions broadcast over numpy arrays; lengths in mm, angles in radians unless
the name says ``_deg``.
"""

from __future__ import annotations

import numpy as np

from ..errors import OpticsError

__all__ = [
    "image_distance",
    "object_distance",
    "magnification",
    "object_distance_for_marked",
    "minimum_marked_distance",
    "field_of_view",
]


def image_distance(focal_length, object_distance):
    """s' = s f / (s - f): image distance behind H2 for an object ``object_distance`` in front of H1.

    Raises :class:`OpticsError` when the object is at or inside the focal length
    (no real image).

    >>> float(image_distance(50.0, 100.0))
    100.0
    """
    f = np.asarray(focal_length, dtype=float)
    s = np.asarray(object_distance, dtype=float)
    if np.any(s <= f):
        raise OpticsError("the subject is at or inside the focal length: no real image forms on the film")
    out = s * f / (s - f)
    return out if out.ndim else float(out)


def object_distance(focal_length, image_distance_):
    """s = s' f / (s' - f), the inverse of :func:`image_distance`."""
    return image_distance(focal_length, image_distance_)  # the law is symmetric in s and s'


def magnification(focal_length, object_distance):
    """|m| = s'/s = f / (s - f), the size on the film over the size of the subject."""
    f = np.asarray(focal_length, dtype=float)
    s = np.asarray(object_distance, dtype=float)
    if np.any(s <= f):
        raise OpticsError("the subject is at or inside the focal length: no real image forms on the film")
    out = f / (s - f)
    return out if out.ndim else float(out)


def minimum_marked_distance(focal_length, hiatus=0.0):
    """Closest subject a lens of focal length f can image: object-to-image distance 4f (+ hiatus).

    At that distance s = s' = 2f and the magnification is 1 (Hecht §5.2.3).
    """
    return 4.0 * np.asarray(focal_length, dtype=float) + hiatus


def object_distance_for_marked(focal_length, marked_distance, hiatus=0.0):
    """Object distance s (from H1) of a subject marked ``marked_distance`` from the film plane.

    On set the focus mark is measured from the film plane to the subject; that length is
    s + s' + hiatus, where the hiatus is the H1-to-H2 separation (0 for a thin lens,
    positive when H1 lies in front of H2). Solving s + s f/(s - f) = D - hiatus gives
    s = (L + sqrt(L^2 - 4 L f)) / 2 with L = D - hiatus (the larger root: the subject is
    in front of the lens). Needs L >= 4 f.

    >>> round(float(object_distance_for_marked(50.0, 200.0)), 6)  # 1:1 macro: s = s' = 2f
    100.0
    """
    f = np.asarray(focal_length, dtype=float)
    L = np.asarray(marked_distance, dtype=float) - hiatus
    disc = L * L - 4.0 * L * f
    if np.any(disc < -1e-9 * L * L) or np.any(L <= 0):
        closest = float(np.max(4.0 * f + hiatus))
        raise OpticsError(
            f"focus mark {float(np.min(np.asarray(marked_distance))):.6g} mm is closer than this lens can focus: "
            f"the closest mark for a {float(np.max(f)):g} mm thin lens is {closest:.6g} mm from the film plane (4f)"
        )
    out = 0.5 * (L + np.sqrt(np.maximum(disc, 0.0)))
    return out if out.ndim else float(out)


def field_of_view(size, focal_length, object_distance=None):
    """Angular field of view (radians) across a film dimension ``size`` (mm).

    At infinity focus: 2 atan(size / 2f). Focused at ``object_distance`` s (from H1),
    the film sits s' behind H2 and the field seen from H1 narrows to 2 atan(size / 2s')
    (focus breathing of a unit-focusing lens). Source: Hecht §5.7 (field stop and
    angular field); thin lens, so the pupils sit at the principal planes.

    >>> round(float(np.degrees(field_of_view(36.0, 50.0))), 4)
    39.5978
    """
    size = np.asarray(size, dtype=float)
    if object_distance is None:
        d = np.asarray(focal_length, dtype=float)
    else:
        d = image_distance(focal_length, object_distance)
    return 2.0 * np.arctan(size / (2.0 * np.asarray(d, dtype=float)))

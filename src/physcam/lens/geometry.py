"""Surface shape: sag of spheres, conics, even aspheres and cylinders.

Sag z(r) is measured from the surface vertex along +z (toward the film).
Source: the even-asphere sag equation, e.g. Zemax OpticStudio manual, "Even Asphere".
"""

from __future__ import annotations

import math

__all__ = ["sag"]


def sag(surface, h: float, axis: str = "y") -> float:
    """Sag (mm) of ``surface`` at height ``h`` (mm) in the ``axis`` meridian ("x" or "y").

    A cylinder in X has curvature only in the X-Z meridian; in Y it is flat.
    """
    try:
        c = surface.curvature_x if axis == "x" else surface.curvature_y
    except AttributeError:
        from ..errors import WrongTypeError

        raise WrongTypeError(f"surface must be a physcam Surface, got {type(surface).__name__}") from None
    if surface.kind == "aspheric":
        c = surface.curvature
    k = surface.conic
    if c == 0.0:
        z = 0.0
    else:
        arg = 1.0 - (1.0 + k) * c * c * h * h
        z = c * h * h / (1.0 + math.sqrt(max(arg, 0.0)))
    r2 = h * h
    p = r2 * r2
    for a in surface.aspheric:
        z += a * p
        p *= r2
    return z

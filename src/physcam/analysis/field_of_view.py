"""The widest field whose chief ray passes a lens (object at infinity).

Angles in degrees.
"""

from __future__ import annotations

from ..errors import InputError, require_finite, require_positive
from ..lens.prescription import Prescription

__all__ = ["chief_ray_field_limit"]


def chief_ray_field_limit(
    lens: Prescription,
    axis: str = "y",
    *,
    max_deg: float = 89.0,
    tol_deg: float = 0.01,
    wavelength_nm: float | None = None,
    backend: str = "auto",
) -> float:
    """The widest field angle (degrees, object at infinity, ``axis``-Z meridian) whose aimed chief
    ray passes every clear aperture of ``lens``, to ``tol_deg``; ``max_deg`` (below 90) if all do.

    Scans out from the axis in 1-degree steps to the first field that fails, then bisects.
    """
    from ._chief import field_limit_deg

    if axis not in ("x", "y"):
        raise InputError(f"axis must be 'x' or 'y', got {axis!r}")
    wl = lens.wavelength_nm if wavelength_nm is None else require_positive("wavelength", wavelength_nm, unit="nm")
    return field_limit_deg(lens, axis, max_deg=require_finite("max_deg", max_deg), wavelength_nm=wl,
                           tol_deg=require_finite("tol_deg", tol_deg), backend=backend)

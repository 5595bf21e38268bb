"""Field of view from real chief rays, and the widest field whose chief ray passes a lens.

The paraxial field of view, 2 atan(h / f) at infinity, is the pinhole a renderer would use; a
real lens maps angles differently (distortion, pupil aberration), and a fisheye maps far more
than 180 degrees onto the film. :func:`real_field_of_view` answers with real rays: from the
film edge (w/2, 0), the film top (0, h/2) and the corner (w/2, h/2) the chief ray is aimed
backward through the centre of the stop (:func:`physcam.analysis._chief.aim_from_film`, with
continuation from the axis when the paraxial aim fails) and traced out of the lens with
clipping at every clear aperture. Its direction in object space makes the real half angle
theta = atan2(sqrt(L^2 + M^2), -N) with the axis toward the scene: an angle, not a tangent,
so a half angle beyond 90 degrees (light from behind the front vertex) is answered as it is.
Full angles are 2 theta (the lens is symmetric about its meridians).

For a lens focused at a finite mark the chief ray's object-space direction is the angle as
seen from the (real) entrance pupil, where the chief ray crosses the axis; this is what a
renderer's pinhole at the entrance pupil needs (docs/conventions.md).

The paraxial figures come from :func:`physcam.optics.paraxial.field_angle` (the paraxial chief
ray through the stop centre to the same film points, X meridian for the width, Y for the
height; the diagonal from both tangents), so they equal the on-set report's 2 atan(w / 2f) at
infinity. A film point outside the lens's image circle (its chief ray is clipped, misses or is
totally reflected) gets ``None`` and a ``reason``. Angles in degrees, lengths in mm.
"""

from __future__ import annotations

import math

from ..._record import field_names, record
from ...errors import InputError, renamed_parameter, require_finite, require_positive, require_type
from ...lens.prescription import Prescription, takes_prescription

__all__ = ["RealFieldOfView", "real_field_of_view", "real_field_of_view_focused", "chief_ray_field_limit",
           "DIFFERS_PCT"]

#: Real and paraxial fields of view "differ" when any full angle differs by more than this (percent).
DIFFERS_PCT = 1.0


@record
class RealFieldOfView:
    """Full fields of view (degrees) of a sensor behind a lens, from real chief rays and paraxially.

    ``horizontal_deg``, ``vertical_deg``, ``diagonal_deg`` are ``None`` where the film point
    (edge, top, corner) lies outside the lens's image circle: ``not_covered`` names them and
    ``reason`` says why. ``*_difference_pct`` = 100 (real / paraxial - 1); ``differs_from_paraxial``
    is true when any of them exceeds :data:`DIFFERS_PCT` in size.
    """

    lens_name: str
    sensor_width_mm: float
    sensor_height_mm: float
    focus_from_film_mm: float | None  # None when a film plane was given instead of a focus mark
    film_z_mm: float
    wavelength_nm: float
    horizontal_deg: float | None
    vertical_deg: float | None
    diagonal_deg: float | None
    paraxial_horizontal_deg: float
    paraxial_vertical_deg: float
    paraxial_diagonal_deg: float
    horizontal_difference_pct: float | None
    vertical_difference_pct: float | None
    diagonal_difference_pct: float | None
    differs_from_paraxial: bool
    not_covered: tuple[str, ...] = ()
    reason: str | None = None

    @property
    def covered(self) -> bool:
        """True when the chief rays of the edge, the top and the corner all pass."""
        return not self.not_covered

    def to_dict(self) -> dict:
        d = {k: getattr(self, k) for k in field_names(self)}
        d["not_covered"] = list(self.not_covered)
        if d["focus_from_film_mm"] is not None and math.isinf(d["focus_from_film_mm"]):
            d["focus_from_film_mm"] = None
            d["focus_is_infinite"] = True
        d["definition"] = ("full angles in degrees of the real chief rays from the film edge, top and corner, "
                           "seen from the entrance pupil; paraxial from the paraxial chief ray")
        return d


@takes_prescription
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
    from .._chief import field_limit_deg

    if axis not in ("x", "y"):
        raise InputError(f"axis must be 'x' or 'y', got {axis!r}")
    wl = lens.wavelength_nm if wavelength_nm is None else require_positive("wavelength", wavelength_nm, unit="nm")
    return field_limit_deg(lens, axis, max_deg=require_finite("max_deg", max_deg), wavelength_nm=wl,
                           tol_deg=require_finite("tol_deg", tol_deg), backend=backend)


@renamed_parameter("focus_from_film_mm", "focus_mm")
@takes_prescription
def real_field_of_view(
    lens: Prescription,
    sensor_width_mm: float,
    sensor_height_mm: float,
    *,
    focus_mm: float = math.inf,
    method: str = "auto",
    film_z: float | None = None,
    wavelength_nm: float | None = None,
    backend: str = "auto",
) -> RealFieldOfView:
    """Real (chief-ray) and paraxial full fields of view of a ``sensor_width_mm`` x
    ``sensor_height_mm`` sensor behind ``lens`` (module notes).

    The lens is focused at ``focus_mm`` (mm in front of the film plane, default
    infinity; ``method`` as :func:`physcam.optics.focusing.focus`: auto, unit, internal).
    Alternatively ``film_z`` (mm, lens space) puts the film plane behind the lens as given,
    without focusing it. ``wavelength_nm`` defaults to the lens's design wavelength.

    Never returns NaN: a film point whose chief ray does not pass gives ``None`` with a reason.
    Raises :class:`InputError` for bad sizes, :class:`OpticsError` when the lens forms no image or
    cannot focus at the mark.
    """
    from ...optics import focusing

    if not isinstance(lens, Prescription):
        raise InputError(f"expected a physcam Prescription, got {type(lens).__name__}")
    w = require_positive("sensor width", sensor_width_mm)
    h = require_positive("sensor height", sensor_height_mm)
    wl = lens.wavelength_nm if wavelength_nm is None else require_positive("wavelength", wavelength_nm, unit="nm")
    mark: float | None
    if film_z is not None:
        if not math.isinf(float(focus_mm)):
            raise InputError("give either focus_mm or film_z, not both")
        fz = require_finite("film_z", film_z)
        if fz <= lens.vertex_z[-1]:
            raise InputError(f"the film plane (z = {fz:g} mm) must lie behind the last vertex "
                             f"(z = {lens.vertex_z[-1]:g} mm)")
        focused, mark = lens, None
    else:
        st = focusing.focus(lens, focus_mm, method=method, axis="y", wavelength_nm=wl)
        focused, fz, mark = st.prescription, st.film_z, float(focus_mm)
    return real_field_of_view_focused(lens, focused, fz, w, h, mark=mark, wavelength_nm=wl, backend=backend)


def real_field_of_view_focused(lens: Prescription, focused: Prescription, film_z: float, sensor_width_mm: float,
                               sensor_height_mm: float, *, mark: float | None, wavelength_nm=None,
                               backend: str = "auto") -> RealFieldOfView:
    """:func:`real_field_of_view` of ``lens`` already focused (``focused``, its film plane at ``film_z``,
    lens space, for the focus ``mark`` from the film; None: a film plane placed by hand): what the
    on-set report asks of its camera's own focus solution."""
    from ...optics import paraxial

    require_type("lens", lens, Prescription, "physcam.lens.library.load_lens(name)")
    require_type("focused", focused, Prescription, "physcam.optics.focusing.focus(lens, mark).prescription")
    w, h = require_positive("sensor width", sensor_width_mm), require_positive("sensor height", sensor_height_mm)
    fz = require_finite("film_z", film_z)
    wl = lens.wavelength_nm if wavelength_nm is None else require_positive("wavelength", wavelength_nm, unit="nm")
    # paraxial: tangents of the paraxial chief rays to the edge (X) and the top (Y)
    tx = math.tan(abs(paraxial.field_angle(focused, w / 2.0, fz, "x", wl)))
    ty = math.tan(abs(paraxial.field_angle(focused, h / 2.0, fz, "y", wl)))
    par = (2.0 * math.degrees(math.atan(tx)), 2.0 * math.degrees(math.atan(ty)),
           2.0 * math.degrees(math.atan(math.hypot(tx, ty))))

    names = ("horizontal", "vertical", "diagonal")
    pts = ((w / 2.0, 0.0), (0.0, h / 2.0), (w / 2.0, h / 2.0))
    real = _real_full_angles(focused, pts, fz, float(wl), backend)
    ok = [r is not None for r in real]
    diff = [None if r is None else 100.0 * (r / p - 1.0) for r, p in zip(real, par)]
    missing = tuple(n for n, good in zip(names, ok) if not good)
    reason = None
    if missing:
        where = ", ".join(f"{n} ({x:g}, {y:g}) mm" for n, (x, y), good in zip(names, pts, ok) if not good)
        reason = (f"the chief ray from the film {where} does not pass {lens.name!r} (clipped, missed or totally "
                  f"reflected): the point lies outside the lens's image circle")
    return RealFieldOfView(
        lens.name, w, h, mark, float(fz), float(wl), real[0], real[1], real[2], par[0], par[1], par[2],
        diff[0], diff[1], diff[2], any(d is not None and abs(d) > DIFFERS_PCT for d in diff), missing, reason)


def _real_full_angles(focused: Prescription, pts, film_z: float, wl: float, backend: str) -> list:
    """2 theta (degrees) of the chief ray from each film point, None where it does not pass: in Python
    floats when Newton alone aims every ray (:mod:`physcam.analysis._chief_float`, no numpy import; the
    default backend only), else with the tracer (continuation from the axis, any backend)."""
    from .._chief_float import film_chief_directions

    rays = film_chief_directions(focused, pts, film_z, wl) if backend == "auto" else None
    if rays is not None:
        return [2.0 * math.degrees(math.atan2(math.hypot(L, M), -N)) if flag == 0 else None for flag, L, M, N in rays]
    import numpy as np

    from ...trace import RayBatch, trace_through
    from .._chief import aim_from_film

    aimed = aim_from_film(focused, np.array(pts), film_z, wavelength_nm=wl, backend=backend)
    out = trace_through(focused, RayBatch.from_arrays(aimed.start, aimed.direction, wl), reverse=True, clip=True,
                        backend=backend)
    half = np.degrees(np.arctan2(np.hypot(out.L, out.M), -out.N))
    return [float(2.0 * a) if good else None for a, good in zip(half, aimed.ok & out.ok)]

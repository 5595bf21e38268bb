"""UsdGeomCamera attribute values for a lens report, in the stage's units.

UsdGeomCamera (OpenUSD ``pxr/usd/usdGeom/schema.usda``, class Camera) stores
``focalLength``, ``horizontalAperture``, ``verticalAperture`` and the aperture
offsets in **tenths of a scene unit**, and ``focusDistance`` and ``clippingRange``
in **scene units**, where one scene unit is ``metersPerUnit`` metres. At the common
``metersPerUnit = 0.01`` (centimetres) tenths of a unit are millimetres. The seed
document's "multiply mm apertures by 10" is wrong for every stage; this module
converts through :func:`mm_to_scene_units` only.

No ``pxr`` import here: the values are plain numbers that ``physcam.usd`` writes.
"""

from __future__ import annotations

import math

from ..onset.report import takes_report
from ..errors import InputError, require_positive

__all__ = [
    "DEFAULT_METERS_PER_UNIT",
    "require_meters_per_unit",
    "mm_to_scene_units",
    "mm_to_tenths_of_scene_unit",
    "shutter_interval",
    "focus_distance_from_pupil_mm",
    "pinhole_fstop",
    "usdgeom_camera_values",
]

DEFAULT_METERS_PER_UNIT = 0.01


def require_meters_per_unit(meters_per_unit) -> float:
    """``meters_per_unit`` as a float in 1e-6..1e6 (micrometres to megametres), else InputError."""
    mpu = require_positive("metersPerUnit", meters_per_unit, unit="")
    if not 1e-6 <= mpu <= 1e6:
        raise InputError(f"metersPerUnit must lie between 1e-6 and 1e6 (0.01 = centimetres), got {mpu:g}")
    return mpu


def mm_to_scene_units(mm: float, meters_per_unit: float = DEFAULT_METERS_PER_UNIT) -> float:
    """Millimetres as scene units of ``meters_per_unit`` metres.

    >>> mm_to_scene_units(1500.0, 0.01), mm_to_scene_units(1500.0, 1.0)
    (150.0, 1.5)
    """
    return mm / (1000.0 * require_meters_per_unit(meters_per_unit))


def mm_to_tenths_of_scene_unit(mm: float, meters_per_unit: float = DEFAULT_METERS_PER_UNIT) -> float:
    """Millimetres as tenths of a scene unit (UsdGeomCamera lens and filmback units).

    >>> mm_to_tenths_of_scene_unit(50.0, 0.01), mm_to_tenths_of_scene_unit(50.0, 1.0)
    (50.0, 0.5)
    """
    return 10.0 * mm_to_scene_units(mm, meters_per_unit)


def shutter_interval(shutter_angle_deg: float = 180.0, phase: str = "start") -> tuple[float, float]:
    """(open, close) in frames relative to the frame time, from a rotary shutter angle.

    The shutter is open for angle/360 of a frame. ``phase`` "start" opens on the frame
    (0, angle/360); "centered" straddles it (-angle/720, angle/720); "end" closes on it.
    """
    a = require_positive("shutter angle", shutter_angle_deg, unit="deg")
    if a > 360.0:
        raise InputError(f"shutter angle must be at most 360 degrees, got {a:g}")
    d = a / 360.0
    if phase == "start":
        return (0.0, d)
    if phase == "centered":
        return (-d / 2.0, d / 2.0)
    if phase == "end":
        return (-d, 0.0)
    raise InputError(f"shutter phase must be start, centered or end, got {phase!r}")


@takes_report
def focus_distance_from_pupil_mm(report) -> float:
    """Distance (mm) from the entrance pupil to the plane of sharp focus; s from H1 without a pupil."""
    if report.entrance_pupil_from_film_mm is None:
        return report.object_distance_mm
    return report.focus_from_film_mm - report.entrance_pupil_from_film_mm


@takes_report
def pinhole_fstop(report) -> float:
    """The f-number a renderer's camera needs beside the best-match pinhole's focal length so that
    focalLength / fStop is the lens's entrance-pupil diameter (EFL / N): depth of field then
    matches, since defocus blur seen from the pupil depends only on that diameter and the focus. The
    diameter is the one at this focus (an internal-focus lens's iris seen through its focused front)."""
    return report.pinhole[0] / report.aperture_diameter_mm


@takes_report
def usdgeom_camera_values(
    report,
    meters_per_unit: float = DEFAULT_METERS_PER_UNIT,
    *,
    clipping_range_mm: tuple[float, float] = (100.0, 1.0e7),
    shift_mm: tuple[float, float] = (0.0, 0.0),
    shutter_angle_deg: float = 180.0,
    shutter_phase: str = "start",
    projection: str = "perspective",
) -> dict:
    """UsdGeomCamera attribute name -> value for a :class:`~physcam.onset.report.LensReport`.

    The camera is the lens's **best-match pinhole** (``report.pinhole``; docs/lens-report.md):
    ``focalLength`` frames like the lens at its focus (s' for a thin lens, breathing included for
    a prescription), and ``fStop`` is set so that focalLength / fStop is the entrance-pupil
    diameter EFL / N (:func:`pinhole_fstop`), so a renderer's thin-lens blur, which depends on
    that aperture diameter and the focus distance, matches the lens's.
    Anamorphic lenses: the horizontal aperture is the *desqueezed* film width
    (width x squeeze), so a spherical CG camera sees the de-squeezed field of view;
    the squeeze itself is not an aperture offset (seed 000's note is wrong there).
    ``focusDistance`` is measured from the camera's centre of projection, the entrance pupil,
    where physcam places the camera prim (``physcam.usd``): focus mark minus the pupil's
    distance from the film. Without a known pupil it is the Gaussian object distance s from
    H1 (for the practical thin lens the two agree: the pupil sits at the principal plane).
    ``shift_mm`` is a sensor (lens) shift on the film, in mm, becoming the aperture offsets.
    """
    near_mm, far_mm = clipping_range_mm
    require_positive("near clipping distance", near_mm)
    if not far_mm > near_mm:
        raise InputError("the far clipping distance must be beyond the near one")
    t = lambda mm: mm_to_tenths_of_scene_unit(mm, meters_per_unit)  # noqa: E731
    su = lambda mm: mm_to_scene_units(mm, meters_per_unit)  # noqa: E731
    if projection not in ("perspective", "orthographic"):
        raise InputError(f"projection must be perspective or orthographic, got {projection!r}")
    f_pin, sq = report.pinhole
    open_, close = shutter_interval(shutter_angle_deg, shutter_phase)
    values = {
        "projection": projection,
        "focalLength": t(f_pin),
        "horizontalAperture": t(report.sensor.width_mm * sq),
        "verticalAperture": t(report.sensor.height_mm),
        "horizontalApertureOffset": t(shift_mm[0] * sq),
        "verticalApertureOffset": t(shift_mm[1]),
        "focusDistance": su(focus_distance_from_pupil_mm(report)),
        "fStop": pinhole_fstop(report),
        "clippingRange": (su(near_mm), su(far_mm)),
        "shutter:open": open_,
        "shutter:close": close,
    }
    for k, v in values.items():
        if isinstance(v, float) and not math.isfinite(v):
            raise InputError(f"UsdGeomCamera {k} came out {v}")
    return values

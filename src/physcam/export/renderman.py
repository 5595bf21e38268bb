"""RenderMan camera parameters (Format, ScreenWindow, PxrCamera) for a lens report.

RenderMan's perspective projection is field-of-view driven: ``fov`` spans the
screen window's shorter side, whose default is [-a, a, -1, 1] for a frame aspect
a >= 1 (RenderMan Interface Specification 3.2, "Camera": ScreenWindow default and
``Projection "perspective" "fov"``). physcam writes the screen window explicitly in
that convention. Anamorphic: the image is the squeezed plate, so ``Format`` carries
pixel aspect = squeeze and the frame aspect is the de-squeezed one. ``focalLength``
and ``focalDistance`` are in scene units (PxrCamera's depth of field uses them with
``fStop``), ``focalDistance`` being measured from the entrance pupil (the camera's centre
of projection; see :func:`physcam.export.usdgeom.focus_distance_from_pupil_mm`).
"""

from __future__ import annotations

import math

from ..onset.report import takes_report
from ..errors import InputError
from .usdgeom import DEFAULT_METERS_PER_UNIT, focus_distance_from_pupil_mm, mm_to_scene_units, pinhole_fstop

__all__ = ["renderman_camera_values"]


@takes_report
def renderman_camera_values(
    report,
    meters_per_unit: float = DEFAULT_METERS_PER_UNIT,
    *,
    xres: int = 2048,
    shift_mm: tuple[float, float] = (0.0, 0.0),
    clipping_range_mm: tuple[float, float] = (100.0, 1.0e7),
) -> dict:
    """Format, ScreenWindow, Clipping and PxrCamera parameters for ``report``.

    The camera is the lens's best-match pinhole, as for UsdGeomCamera (``focalLength``, ``fov``,
    and ``fStop`` such that focalLength / fStop is the entrance-pupil diameter).
    ``xres`` is the horizontal pixel count of the (squeezed) image; ``yres`` follows
    from the film aspect. ``shift_mm`` (sensor shift in film mm) moves the screen window.
    """
    if int(xres) < 1:
        raise InputError(f"xres must be a positive pixel count, got {xres}")
    w, h = report.sensor.width_mm, report.sensor.height_mm
    f, sq = report.pinhole  # the best-match pinhole (see usdgeom_camera_values)
    yres = max(1, round(int(xres) * h / w))
    aspect = (w * sq) / h  # de-squeezed frame aspect
    if aspect >= 1.0:
        unit_half_mm = h / 2.0  # screen-window unit = half the film height
        window = [-aspect, aspect, -1.0, 1.0]
    else:
        unit_half_mm = w * sq / 2.0
        window = [-1.0, 1.0, -1.0 / aspect, 1.0 / aspect]
    fov = math.degrees(2.0 * math.atan(unit_half_mm / f))
    dx, dy = shift_mm[0] * sq / unit_half_mm, shift_mm[1] / unit_half_mm
    window = [window[0] + dx, window[1] + dx, window[2] + dy, window[3] + dy]
    su = lambda mm: mm_to_scene_units(mm, meters_per_unit)  # noqa: E731
    return {
        "Format": {"xres": int(xres), "yres": int(yres), "pixelaspect": sq},
        "ScreenWindow": window,
        "Clipping": [su(clipping_range_mm[0]), su(clipping_range_mm[1])],
        "Projection": {
            "name": "PxrCamera",
            "fov": fov,
            "fStop": pinhole_fstop(report),
            "focalLength": su(f),
            "focalDistance": su(focus_distance_from_pupil_mm(report)),
        },
    }

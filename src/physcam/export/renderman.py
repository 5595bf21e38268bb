"""RenderMan camera parameters (Format, ScreenWindow, PxrCamera) for a lens report, and RIB
camera blocks (:func:`rib_camera_values`, :func:`rib_camera_block`; docs/renderman-pbrt.md).

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
from ..errors import ExportError, InputError, require_finite, require_positive
from ._codetext import hash_comment
from .usdgeom import DEFAULT_METERS_PER_UNIT, focus_distance_from_pupil_mm, mm_to_scene_units, pinhole_fstop

__all__ = ["renderman_camera_values", "rib_camera_values", "rib_camera_block", "shutter_opening_curve"]


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


# --------------------------------------------------------------------------------------------
# RIB camera blocks (issue 13): the PxrCamera projection of RenderMan 22+ and the legacy
# REYES form of seed 002 (Projection "perspective", DepthOfField, Hider "hidden").

#: RenderMan's limits for the aperture's roundness and density (seed 002: "legal values are from -1 to 1").
_UNIT_RANGE = (-1.0, 1.0)


def shutter_opening_curve(opentime: float, closetime: float) -> list[float]:
    """RenderMan's ``shutteropening`` control points [c1 c2 d1 d2 e1 e2 f1 f2] for seed 002's ramps.

    The shutter opens linearly from 0 at time 0 to full at ``opentime`` (fractions of the
    shutter interval), stays open until ``closetime`` and closes linearly until 1. RenderMan
    draws the opening as a cubic Bezier from (0, 0) to (opentime, 1) with control points (c1, c2),
    (d1, d2), and the closing from (closetime, 1) to (1, 0) with (e1, e2), (f1, f2) (RenderMan
    "Shutter" page, rmanwiki REN22/REN24). Control points at the thirds of each ramp make the
    Bezier exactly that straight ramp. ``physcam.usd.author`` writes these as ri:shutteropening.
    """
    o = require_finite("shutter opening time", opentime)
    c = require_finite("shutter closing time", closetime)
    if not 0.0 <= o <= c <= 1.0:
        raise InputError(f"shutter opening (open, close) needs 0 <= open <= close <= 1, got ({o:g}, {c:g})")
    return [o / 3.0, 1.0 / 3.0, 2.0 * o / 3.0, 2.0 / 3.0,
            c + (1.0 - c) / 3.0, 2.0 / 3.0, c + 2.0 * (1.0 - c) / 3.0, 1.0 / 3.0]


def _aperture(aperture) -> tuple[int, float, float, float]:
    try:
        nsides, angle, roundness, density = aperture
    except (TypeError, ValueError):
        raise InputError("aperture must be (nsides, angle_deg, roundness, density)") from None
    if isinstance(nsides, bool) or not isinstance(nsides, (int, float)) or int(nsides) != nsides \
            or not 0 <= nsides <= 64:
        raise InputError(f"aperture nsides must be a whole number of blades 0..64 (below 3: round), got {nsides!r}")
    angle = require_finite("aperture angle", angle)
    for name, v in (("roundness", roundness), ("density", density)):
        if not _UNIT_RANGE[0] <= require_finite(f"aperture {name}", v) <= _UNIT_RANGE[1]:
            raise InputError(f"aperture {name} must lie between -1 and 1 (RenderMan's range), got {v:g}")
    return int(nsides), float(angle), float(roundness), float(density)


@takes_report
def rib_camera_values(
    report,
    meters_per_unit: float = DEFAULT_METERS_PER_UNIT,
    *,
    xres: int = 2048,
    shift_mm: tuple[float, float] = (0.0, 0.0),
    clipping_range_mm: tuple[float, float] = (100.0, 1.0e7),
    shutter_angle_deg: float = 180.0,
    shutter_phase: str = "start",
    shutter_opening: tuple[float, float] = (0.0, 1.0),
    aperture: tuple = (7, 0.0, 0.0, 0.0),
) -> dict:
    """Everything a RIB camera block says for ``report``: :func:`renderman_camera_values` plus
    ``Shutter`` (from the rotary shutter angle, in frames), the aperture shape
    (nsides, angle in degrees, roundness, density; seed 002; ``fStop`` is N, the bladed iris having
    the area of the round iris of f/N, docs/conventions.md), the shutter opening ramps and
    ``dofaspect`` (width / height of the defocus blur in the desqueezed picture: the lens
    report's ``dof_aspect``, 1 / squeeze for a thin anamorphic, the entrance pupil's X / Y
    diameter for a prescription). Lengths in scene units of ``meters_per_unit`` metres.
    """
    from .usdgeom import shutter_interval

    near_mm, far_mm = clipping_range_mm
    if not far_mm > require_positive("near clipping distance", near_mm):
        raise InputError("the far clipping distance must be beyond the near one")
    v = renderman_camera_values(report, meters_per_unit, xres=xres, shift_mm=shift_mm,
                                clipping_range_mm=clipping_range_mm)
    nsides, angle, roundness, density = _aperture(aperture)
    o, c = shutter_opening
    proj = v["Projection"]
    proj.update({
        "dofaspect": float(report.dof_aspect),
        "apertureNSides": nsides,
        "apertureAngle": angle,
        "apertureRoundness": roundness,
        "apertureDensity": density,
        "shutterOpenTime": float(o),
        "shutterCloseTime": float(c),
        "shutteropening": shutter_opening_curve(o, c),
    })
    v["Shutter"] = list(shutter_interval(shutter_angle_deg, shutter_phase))
    for key, val in (("ScreenWindow", v["ScreenWindow"]), ("Clipping", v["Clipping"]),
                     ("fov", proj["fov"]), ("fStop", proj["fStop"]), ("focalLength", proj["focalLength"]),
                     ("focalDistance", proj["focalDistance"])):
        for x in (val if isinstance(val, list) else [val]):
            require_finite(f"RIB {key}", x, error=ExportError)
    if not proj["focalDistance"] > 0:
        raise ExportError(f"the plane of focus lies behind the camera (focalDistance {proj['focalDistance']:g}); "
                          "RenderMan needs it in front of the entrance pupil")
    return v


def _num(x) -> str:
    """A RIB number: integers bare, floats as the shortest text that reads back the same (repr)."""
    if isinstance(x, int) and not isinstance(x, bool):
        return str(x)
    return repr(float(x))


def _arr(xs) -> str:
    return "[" + " ".join(_num(x) for x in xs) + "]"


def rib_camera_block(values: dict, *, legacy: bool = False, comments=()) -> str:
    """RIB text of a :func:`rib_camera_values` dict.

    Default: RenderMan 22+ ``Projection "PxrCamera"`` with its typed parameters (fov, fStop,
    focalLength, focalDistance, dofaspect, the aperture and the shutter opening; the common
    projection parameters of rmanwiki "Camera Projection Defaults"). ``legacy``: the REYES form
    of RenderMan 13-20 (seed 002): ``Projection "perspective" "fov"``, ``DepthOfField fstop
    focallength focaldistance`` (RI Spec 3.2: lens diameter = focallength / fstop, both lengths in
    camera-space units) and ``Hider "hidden" "aperture" [...] "shutteropening" [open close]``.
    The legacy hider has no ``dofaspect``, so an oval (anamorphic) blur is refused there.
    ``comments``: lines written as ``#`` comments after the ``##RenderMan RIB`` header.
    """
    from ..errors import require_type

    require_type("values", values, dict, "build them with rib_camera_values(report, ...)")
    try:
        fmt_, win, clip, shutter, proj = (values["Format"], values["ScreenWindow"], values["Clipping"],
                                          values["Shutter"], values["Projection"])
        aperture = [proj["apertureNSides"], proj["apertureAngle"], proj["apertureRoundness"], proj["apertureDensity"]]
    except (KeyError, TypeError):
        raise InputError("values must come from rib_camera_values (Format, ScreenWindow, Clipping, Shutter, "
                         "Projection with the aperture and shutter parameters)") from None
    lines = ["##RenderMan RIB"]
    lines += [f"# {hash_comment(c)}".rstrip() for text in comments for c in str(text).splitlines()]
    lines.append(f"Format {fmt_['xres']} {fmt_['yres']} {_num(fmt_['pixelaspect'])}")
    lines.append("ScreenWindow " + " ".join(_num(x) for x in win))
    lines.append("Clipping " + " ".join(_num(x) for x in clip))
    lines.append("Shutter " + " ".join(_num(x) for x in shutter))
    if legacy:
        if abs(proj["dofaspect"] - 1.0) > 1e-6:
            raise ExportError(
                f"legacy RIB (Hider \"hidden\", DepthOfField) cannot hold this lens's oval defocus blur "
                f"(dofaspect {proj['dofaspect']:.4g}): it has no dofaspect; write the PxrCamera form (drop --legacy), "
                "which has one")
        lines.append(f"Projection \"perspective\" \"fov\" [{_num(proj['fov'])}]")
        lines.append(f"DepthOfField {_num(proj['fStop'])} {_num(proj['focalLength'])} {_num(proj['focalDistance'])}")
        lines.append(f"Hider \"hidden\" \"aperture\" {_arr(aperture)} \"shutteropening\" "
                     f"{_arr([proj['shutterOpenTime'], proj['shutterCloseTime']])}")
    else:
        params = [("float fov", proj["fov"]), ("float fStop", proj["fStop"]), ("float focalLength", proj["focalLength"]),
                  ("float focalDistance", proj["focalDistance"]), ("float dofaspect", proj["dofaspect"]),
                  ("int apertureNSides", proj["apertureNSides"]), ("float apertureAngle", proj["apertureAngle"]),
                  ("float apertureRoundness", proj["apertureRoundness"]),
                  ("float apertureDensity", proj["apertureDensity"]),
                  ("float shutterOpenTime", proj["shutterOpenTime"]),
                  ("float shutterCloseTime", proj["shutterCloseTime"])]
        lines.append("Projection \"PxrCamera\"")
        lines += [f"    \"{decl}\" [{_num(val)}]" for decl, val in params]
        lines.append(f"    \"float[8] shutteropening\" {_arr(proj['shutteropening'])}")
    return "\n".join(lines) + "\n"

"""Write a PhysicalCamera and its companion UsdGeomCamera.

A camera physcam writes is a ``PhysicalCamera`` prim (the body, with one
``PhysicalCameraSensorAPI:main`` and one ``PhysicalCameraLensAPI:main``), a lens
model prim it points at (``<camera>/Pinhole`` or ``<camera>/Orthographic``), and a
child ``UsdGeomCamera`` named ``Camera`` that every Hydra delegate and renderer can
use. The two are written from the same numbers:

* physical values in **millimetres** (hardware does not change with the scene);
* ``UsdGeomCamera`` values in the stage's units through
  :func:`physcam.export.usdgeom.usdgeom_camera_values`: focal length and apertures
  in tenths of a scene unit, focus and clipping distances in scene units
  (``metersPerUnit``; docs/conventions.md);
* Hydra's ``lensDistortion:*`` when a fitted model is given (a real lens's traced distortion,
  :mod:`physcam.analysis.distortion.field`);
* ``exposure:*``, ``shutter:open/close`` (in time codes, from the stage's
  ``timeCodesPerSecond``) and RenderMan's ``ri:aperture*``, ``ri:shutterOpenTime``,
  ``ri:shutterCloseTime``, ``ri:shutteropening`` (hdPrman's camera tokens; seed 002).

Transform: the body's origin is the centre of the film plane. Its ops are
``translate`` (where the entrance pupil is), ``rotateXYZ`` (pan/tilt/roll about
the pupil) and ``translate:pupilToFilm`` (0, 0, +p), so rotations pivot about the
no-parallax point. The companion camera's eye sits back on the pupil, and its
``focusDistance`` is measured from there to the plane of sharp focus, so that plane
lands where the focus mark says (for a thin lens this is the Gaussian object
distance s).
"""

from __future__ import annotations

import math
import struct

from ..errors import ExportError, InputError, WrongTypeError, require_finite, require_positive, require_type
from ..export._codetext import usd_text
from ..export.renderman import shutter_opening_curve  # re-exported: the one copy of seed 002's ramps
from .plugin import ensure_registered, require_stage
from .spec import (BLENDER_PROPERTY, DEFAULT_CAMERA_PATH, LENS_INSTANCE, RENDER_CAMERA_NAME, SENSOR_INSTANCE,
                   CameraSpec, report_for_spec, spec_from_report)

__all__ = [
    "CameraSpec",
    "DEFAULT_CAMERA_PATH",
    "LENS_INSTANCE",
    "SENSOR_INSTANCE",
    "author_camera",
    "author_from_report",
    "spec_from_report",
    "new_stage",
    "save_stage",
    "write_camera",
    "report_for_spec",
    "shutter_opening_curve",
    "author_render_settings",
    "render_camera_values",
    "sample_render_camera",
    "sampled_render_values",
    "SAMPLED_RENDER_ATTRIBUTES",
    "iris_mm",
    "author_anamorphic_distortion",
    "author_prescription",
]

def new_stage(meters_per_unit: float = 0.01, fps: float = 24.0, up_axis: str = "Y"):
    """An in-memory stage with physcam's metadata: metersPerUnit, upAxis, time codes per second."""
    ensure_registered()
    from pxr import Usd, UsdGeom

    from ..export.usdgeom import require_meters_per_unit

    mpu = require_meters_per_unit(meters_per_unit)
    rate = require_positive("frames per second", fps, unit="")
    if rate > 1000.0:
        raise InputError(f"frames per second must be at most 1000, got {rate:g}")
    if up_axis not in ("Y", "Z"):
        raise InputError(f"up axis must be Y or Z, got {up_axis!r}")
    stage = Usd.Stage.CreateInMemory()
    UsdGeom.SetStageMetersPerUnit(stage, mpu)
    UsdGeom.SetStageUpAxis(stage, up_axis)
    stage.SetTimeCodesPerSecond(rate)
    stage.SetFramesPerSecond(rate)
    return stage


def _eye_from_film(spec: CameraSpec, report) -> float:
    """Where the camera (its centre of projection) sits, in front of the film: the entrance
    pupil, or the front principal plane when no pupil is known (the thin-lens pupil), the same
    fallback as :func:`physcam.export.usdgeom.focus_distance_from_pupil_mm`."""
    if spec.entrance_pupil_mm is not None:
        return spec.entrance_pupil_mm
    if report is None:
        report = report_for_spec(spec)
    if report.entrance_pupil_from_film_mm is not None:
        return report.entrance_pupil_from_film_mm
    return report.h1_from_film_mm


def _f32(x: float) -> float:
    return struct.unpack("f", struct.pack("f", x))[0]


def _f32_steps(x, steps):
    """The float32 rounding of each ``x`` moved by each of ``steps`` float32 steps (a new last axis), as
    float64: the float32 values beside ``x`` (adjacent float32 values differ by one in their bit pattern)."""
    import numpy as np

    bits = np.asarray(x, dtype=np.float32).view(np.int32)[..., None] + np.asarray(steps, dtype=np.int32)
    return bits.view(np.float32).astype(np.float64)


def fov_preserving_float32(focal: float, width: float, height: float, k: int = 24) -> tuple[float, float, float]:
    """Float32 values of (focal length, horizontal, vertical aperture) that keep the two ratios.

    UsdGeomCamera stores these as 32-bit floats; rounding each on its own moves the field
    of view by up to ~3e-6 degrees. The field of view depends only on aperture / focal
    length, so this picks, within ``k`` float32 steps of the focal length, the value
    whose best-rounded apertures give ratios closest to the exact ones (each value stays
    within a few ulps, ~1e-6 relative, of its exact value). The first of equals wins; the
    2k + 1 candidates are weighed as arrays (a live take writes one camera a frame).
    """
    import numpy as np

    rw, rh = width / focal, height / focal
    fc = _f32_steps(_f32(focal), np.arange(-k, k + 1))
    rows = np.arange(fc.size)
    picks = []
    for r in (rw, rh):
        c = _f32_steps(r * fc, (-1, 0, 1))  # the aperture's float32 rounding and its neighbours, per focal
        picks.append(c[rows, np.argmin(np.abs(c / fc[:, None] - r), axis=1)])
    cw, ch = picks
    best = int(np.argmin(np.maximum(np.abs(cw / fc - rw) / rw, np.abs(ch / fc - rh) / rh)))
    return float(fc[best]), float(cw[best]), float(ch[best])


def _set(prim, name, type_name, value, custom=False):
    attr = prim.GetAttribute(name)
    if not attr:
        attr = prim.CreateAttribute(name, type_name, custom)
    attr.Set(value)
    _check_stored(prim, name, attr.Get())
    return attr


def _check_stored(prim, name, stored) -> None:
    """No NaN or inf leaves physcam: check the value as USD stored it (float attributes hold
    32 bits, so a finite double can overflow there)."""
    try:
        values = list(stored) if hasattr(stored, "__len__") and not isinstance(stored, str) else [stored]
    except TypeError:
        return
    for v in values:
        if isinstance(v, float) and not math.isfinite(v):
            raise InputError(f"{prim.GetPath()}.{name} would be stored as {v}: the value is out of range "
                             "(check metersPerUnit and the distances)")


ALL_PARTS = ("body", "sensor", "lens", "render")


def author_camera(stage, path: str, spec: CameraSpec, *, position=(0.0, 0.0, 0.0),
                  rotate_xyz_deg=(0.0, 0.0, 0.0), report=None, parts=ALL_PARTS, lens_distortion=None,
                  opencv_distortion=None):
    """Author ``spec`` at ``path`` on ``stage`` (its current edit target); return the PhysicalCamera prim.

    ``position``: where the entrance pupil is, in scene units in the parent's space;
    ``rotate_xyz_deg``: rotation about the pupil (degrees, XYZ order).
    ``report``: the lens report of ``spec`` when the caller has one (else it is solved).
    Works inside a variant edit context, so kits and lens libraries reuse it.
    ``parts`` limits what is written: "body" (transform, shutter), "sensor", "lens"
    (lens API and lens model prim), "render" (the companion UsdGeomCamera); a body file
    and a lens file each write their own parts and a shot composes them.
    ``lens_distortion``: a fitted radial model
    (:class:`physcam.analysis.distortion.field.StandardDistortion`, or its ``usd_attributes()`` dict),
    written as Hydra's ``lensDistortion:*`` on the companion UsdGeomCamera.
    """
    bad = set(parts) - set(ALL_PARTS)
    if bad:
        raise InputError(f"unknown camera parts {sorted(bad)}; use {', '.join(ALL_PARTS)}")
    ensure_registered()
    from pxr import Sdf, UsdGeom

    from ..export.usdgeom import mm_to_scene_units

    require_stage(stage)
    spec = require_type("spec", spec, CameraSpec, "build one with CameraSpec(...) or spec_from_report").checked()
    sdf_path = Sdf.Path()
    # checked as text first: Sdf.Path() of an ill-formed string prints USD's own warning on stderr
    if isinstance(path, str) and Sdf.Path.IsValidPathString(path)[0]:
        sdf_path = Sdf.Path(path)
    if sdf_path.isEmpty or not sdf_path.IsAbsolutePath() or not sdf_path.IsPrimPath():
        raise ExportError(f"camera path {path!r} is not an absolute prim path such as /Cameras/Hero")
    existing = stage.GetPrimAtPath(sdf_path)
    if existing and existing.GetTypeName() not in ("", "PhysicalCamera"):
        raise ExportError(
            f"prim {sdf_path} is a {existing.GetTypeName()}, not a PhysicalCamera; choose another camera path"
        )
    mpu = UsdGeom.GetStageMetersPerUnit(stage)
    su = lambda mm: mm_to_scene_units(mm, mpu)  # noqa: E731
    if report is None and spec.projection == "perspective":
        report = report_for_spec(spec)
    eye = _eye_from_film(spec, report)

    for parent in reversed(sdf_path.GetParentPath().GetPrefixes()):
        if not stage.GetPrimAtPath(parent):
            UsdGeom.Xform.Define(stage, parent)
    cam = stage.DefinePrim(sdf_path, "PhysicalCamera")
    if not stage.GetDefaultPrim():
        stage.SetDefaultPrim(stage.GetPrimAtPath(sdf_path.GetPrefixes()[0]))
    if "sensor" in parts:
        cam.ApplyAPI("PhysicalCameraSensorAPI", SENSOR_INSTANCE)
    if "lens" in parts:
        cam.ApplyAPI("PhysicalCameraLensAPI", LENS_INSTANCE)
    if "body" in parts:
        _author_body(cam, spec, position, rotate_xyz_deg, su(eye))
    if "sensor" in parts:
        _author_sensor(cam, spec)
    if "lens" in parts:
        # a lens file (no body to place) whose characterization gives no pupil: none is invented (a
        # thin-lens pupil at the spec's focus, the default 3 m when the maker gave none); the shot that
        # composes it computes the pupil at its own focus (read_camera reads it as unknown)
        # (a datasheet without --pupil likewise: the camera is placed at H1, the report's fallback, but
        # entrancePupilDistance is not claimed)
        unknown = (("body" not in parts and spec.entrance_pupil_mm is None)
                   or (report is not None and report.entrance_pupil_source == "unknown"))
        _author_lens(stage, cam, spec, None if unknown else eye, su)
    if "render" in parts:
        geom = author_render_camera(stage, sdf_path, spec, report=report, lens_distortion=lens_distortion,
                                    opencv_distortion=opencv_distortion)
        if {"body", "sensor", "lens"} <= set(parts):
            # what the companion was computed from, for `physcam usd check` (physcam.usd.kit.check_shot)
            from .read import companion_inputs

            geom.GetPrim().SetCustomDataByKey("physcam:companionInputs", companion_inputs(stage, str(sdf_path)))
    return cam


def _author_body(cam, spec, position, rotate_xyz_deg, eye_su):
    from pxr import Gf, Sdf

    _set(cam, "flangeDistance", Sdf.ValueTypeNames.Float, spec.flange_distance_mm)
    _set(cam, "shutterOpen", Sdf.ValueTypeNames.Float, spec.shutter_open_s)
    _set(cam, "shutterDuration", Sdf.ValueTypeNames.Float, spec.shutter_duration_s)
    _set(cam, "shutterOpening", Sdf.ValueTypeNames.Float2, Gf.Vec2f(*spec.shutter_opening))
    _set(cam, "iris", Sdf.ValueTypeNames.Float, iris_mm(spec))
    author_transform(cam, position, rotate_xyz_deg, eye_su)


def iris_mm(spec) -> float:
    """The schema's ``iris``: the entrance pupil's diameter at this focus, focal length / f-number there
    (with ``shutterBlades`` the equal-area diameter: the blades' polygon has this circle's area,
    docs/conventions.md)."""
    spec = require_type("spec", spec, CameraSpec, "build one with CameraSpec(...)")
    return spec.focal_length_mm / (spec.fstop if spec.fstop_at_focus is None else spec.fstop_at_focus)


def author_transform(cam, position, rotate_xyz_deg, eye_su: float) -> None:
    """Place the body: translate to ``position`` (where the entrance pupil goes), rotate there,
    then ``translate:pupilToFilm`` (0, 0, +eye) back to the film plane, so pans and tilts pivot
    about the entrance pupil. ``eye_su`` is the pupil's distance in front of the film, in scene units."""
    from pxr import Gf, UsdGeom

    xf = UsdGeom.Xformable(cam)
    xf.ClearXformOpOrder()
    xf.AddTranslateOp().Set(Gf.Vec3d(*map(float, position)))
    xf.AddRotateXYZOp().Set(Gf.Vec3f(*map(float, rotate_xyz_deg)))
    xf.AddTranslateOp(opSuffix="pupilToFilm").Set(Gf.Vec3d(0.0, 0.0, eye_su))


def _author_sensor(cam, spec):
    from pxr import Gf, Sdf

    sp = f"sensor:{SENSOR_INSTANCE}:"
    _set(cam, sp + "aperture", Sdf.ValueTypeNames.Float2, Gf.Vec2f(spec.sensor_width_mm, spec.sensor_height_mm))
    _set(cam, sp + "shift", Sdf.ValueTypeNames.Float2, Gf.Vec2f(*spec.shift_mm))
    _set(cam, sp + "enlarge", Sdf.ValueTypeNames.Float2, Gf.Vec2f(*spec.enlarge))
    _set(cam, sp + "handedness", Sdf.ValueTypeNames.Float, float(spec.handedness))
    _set(cam, sp + "circleOfConfusion", Sdf.ValueTypeNames.Float, spec.coc_mm)
    _set(cam, sp + "iso", Sdf.ValueTypeNames.Float, spec.iso)
    if spec.sensor_name:
        cam.SetCustomDataByKey("physcam:sensorName", usd_text(spec.sensor_name, "sensor name"))


#: customData on a lens file's camera whose entrance pupil is not known (entrancePupilDistance unauthored)
PUPIL_UNKNOWN_KEY = "physcam:entrancePupil"
PUPIL_UNKNOWN = ("unknown: the lens's characterization or datasheet gives no entrance pupil, so none is written; "
                 "the camera is placed at the thin-lens pupil at its focus (a datasheet's: its front principal "
                 "plane H1); give the pupil (entrance_pupil_mm, --pupil) to know it")


def _author_lens(stage, cam, spec, eye, su):
    """The lens API's values and the lens model prim; ``eye`` None: the pupil is unknown, not authored."""
    from pxr import Gf, Sdf

    sdf_path = cam.GetPath()
    lp = f"lens:{LENS_INSTANCE}:"
    _set(cam, lp + "fStop", Sdf.ValueTypeNames.Float, spec.fstop)
    _set(cam, lp + "iris", Sdf.ValueTypeNames.Float, iris_mm(spec))
    if eye is None:
        cam.SetCustomDataByKey(PUPIL_UNKNOWN_KEY, PUPIL_UNKNOWN)
    else:
        _set(cam, lp + "entrancePupilDistance", Sdf.ValueTypeNames.Float, eye)
    if spec.horizontal_entrance_pupil_mm is not None:  # an anamorphic's pan pivot (docs/anamorphic.md)
        _set(cam, lp + "horizontalEntrancePupilDistance", Sdf.ValueTypeNames.Float, spec.horizontal_entrance_pupil_mm)
    if spec.principal_planes_mm is not None:
        _set(cam, lp + "frontPrincipalPlaneDistance", Sdf.ValueTypeNames.Float, spec.principal_planes_mm[0])
        _set(cam, lp + "rearPrincipalPlaneDistance", Sdf.ValueTypeNames.Float, spec.principal_planes_mm[1])
    if spec.pinhole_focal_length_mm is not None:
        _set(cam, lp + "pinholeFocalLength", Sdf.ValueTypeNames.Float, spec.pinhole_focal_length_mm)
        _set(cam, lp + "pinholeSqueeze", Sdf.ValueTypeNames.Float,
             spec.squeeze if spec.pinhole_squeeze is None else spec.pinhole_squeeze)
    if spec.aperture_distance_mm is not None:  # the physical stop; unknown for a datasheet: not authored
        _set(cam, lp + "apertureDistance", Sdf.ValueTypeNames.Float, spec.aperture_distance_mm)
    _set(cam, lp + "shutterBlades", Sdf.ValueTypeNames.UInt, int(spec.aperture_blades))
    _set(cam, lp + "apertureAngle", Sdf.ValueTypeNames.Float, spec.aperture_angle_deg)
    _set(cam, lp + "apertureRoundness", Sdf.ValueTypeNames.Float, spec.aperture_roundness)
    _set(cam, lp + "apertureDensity", Sdf.ValueTypeNames.Float, spec.aperture_density)
    _set(cam, lp + "clippingRange", Sdf.ValueTypeNames.Float2,
         Gf.Vec2f(su(spec.clipping_mm[0]), su(spec.clipping_mm[1])))
    if spec.projection == "perspective":
        model = stage.DefinePrim(sdf_path.AppendChild("Pinhole"), "PhysicalCameraLensModelPinhole")
        _set(model, "focalLength", Sdf.ValueTypeNames.Float, spec.focal_length_mm)
    else:
        model = stage.DefinePrim(sdf_path.AppendChild("Orthographic"), "PhysicalCameraLensModelOrthographic")
        _set(model, "magnification", Sdf.ValueTypeNames.Float, spec.magnification)
        # the focal length still drives depth of field; kept on the lens model's custom data
        model.SetCustomDataByKey("physcam:focalLength", float(spec.focal_length_mm))
    _set(model, "focusDistance", Sdf.ValueTypeNames.Float, spec.focus_mm)
    _set(model, "squeeze", Sdf.ValueTypeNames.Float, spec.squeeze)
    _set(model, "transmittance", Sdf.ValueTypeNames.Float, spec.transmittance)
    if spec.lens_name:
        model.SetCustomDataByKey("physcam:lensName", usd_text(spec.lens_name, "lens name"))
    cam.GetRelationship(lp + "lensModel") or cam.CreateRelationship(lp + "lensModel", False)
    cam.GetRelationship(lp + "lensModel").SetTargets([model.GetPath()])


def sample_render_camera(geom, spec: CameraSpec, report, meters_per_unit: float, time_codes_per_second: float,
                         time: float, *, where: str = "camera") -> float:
    """Time-sample a companion UsdGeomCamera ``geom`` at ``time`` from ``spec`` (one frame of a moving
    camera): focal length, apertures, f-stop, focus distance and its translate (the eye, in front of
    the film), from :func:`render_camera_values`. Returns the eye distance (mm from the film)."""
    values, eye = sampled_render_values(spec, report, meters_per_unit, time_codes_per_second, where=where)
    prim = geom.GetPrim()
    for name, value in values.items():
        prim.GetAttribute(name).Set(value, time)
    return eye


#: the companion's attributes an animated camera time-samples (:func:`sample_render_camera`), the
#: translate its first transform op
SAMPLED_RENDER_ATTRIBUTES = ("focalLength", "horizontalAperture", "verticalAperture", "fStop", "exposure:fStop",
                             "focusDistance", "xformOp:translate")


def sampled_render_values(spec: CameraSpec, report, meters_per_unit: float, time_codes_per_second: float, *,
                          where: str = "camera") -> tuple[dict, float]:
    """(companion attribute -> value, eye distance in mm from the film) of one frame of an animated camera:
    the :data:`SAMPLED_RENDER_ATTRIBUTES` of :func:`render_camera_values`, the T-stop as authored, and the
    translate that puts the eye (entrance pupil) in front of the film."""
    from pxr import Gf

    from ..export.usdgeom import mm_to_scene_units

    values, eye = render_camera_values(spec, report, meters_per_unit, time_codes_per_second, where=where)
    out = {name: values[name] for name in SAMPLED_RENDER_ATTRIBUTES[:4]}
    out["exposure:fStop"] = spec.t_stop  # the T-stop, as authored
    out["focusDistance"] = values["focusDistance"]
    out["xformOp:translate"] = Gf.Vec3d(0.0, 0.0, -mm_to_scene_units(eye, meters_per_unit))
    return out, eye


def render_camera_values(spec: CameraSpec, report, meters_per_unit: float, time_codes_per_second: float, *,
                         where: str = "camera") -> tuple[dict, float]:
    """(UsdGeomCamera attribute -> value, eye distance in front of the film in mm) of ``spec``'s companion.

    The one computation of the companion's numbers, shared by :func:`author_render_camera` and the
    animated cameras (:mod:`physcam.usd.animate`, per frame): the best-match pinhole in the stage's
    units, apertures divided by ``enlarge``, float32 values that keep the field of view exact,
    focus distance from the eye, shutter in time codes.
    """
    from ..export.usdgeom import mm_to_scene_units, mm_to_tenths_of_scene_unit, usdgeom_camera_values

    spec = require_type("spec", spec, CameraSpec, "build one with CameraSpec(...)")
    mpu = meters_per_unit
    su = lambda mm: mm_to_scene_units(mm, mpu)  # noqa: E731
    tenths = lambda mm: mm_to_tenths_of_scene_unit(mm, mpu)  # noqa: E731
    tcps = require_finite("time codes per second", time_codes_per_second)
    if spec.projection == "perspective":
        if report is None:
            report = report_for_spec(spec)
        values = usdgeom_camera_values(report, mpu, clipping_range_mm=spec.clipping_mm, shift_mm=spec.shift_mm)
        eye = _eye_from_film(spec, report)
        # from the eye (entrance pupil) to the plane of sharp focus, so that plane lands on the mark
        values["focusDistance"] = su(spec.focus_mm - eye)
    else:
        eye = _eye_from_film(spec, None)
        m, sq = spec.magnification, spec.squeeze
        values = {
            "projection": "orthographic",
            "focalLength": tenths(spec.focal_length_mm),
            "horizontalAperture": tenths(spec.sensor_width_mm * sq / m),
            "verticalAperture": tenths(spec.sensor_height_mm / m),
            "horizontalApertureOffset": tenths(spec.shift_mm[0] * sq / m),
            "verticalApertureOffset": tenths(spec.shift_mm[1] / m),
            "focusDistance": su(spec.focus_mm - eye),
            "fStop": spec.fstop,
            "clippingRange": (su(spec.clipping_mm[0]), su(spec.clipping_mm[1])),
        }
    # enlarge: the imaged region is the sensor divided by it (the shift stays in film mm)
    values["horizontalAperture"] /= spec.enlarge[0]
    values["verticalAperture"] /= spec.enlarge[1]
    if spec.projection == "perspective":
        values["focalLength"], values["horizontalAperture"], values["verticalAperture"] = fov_preserving_float32(
            values["focalLength"], values["horizontalAperture"], values["verticalAperture"])
    values["shutter:open"] = spec.shutter_open_s * tcps
    values["shutter:close"] = (spec.shutter_open_s + spec.shutter_duration_s) * tcps
    for k, v in values.items():
        if isinstance(v, float) and not math.isfinite(v):
            raise ExportError(f"{where}/{RENDER_CAMERA_NAME}: {k} came out {v}; check the camera's numbers")

    return values, eye


#: Omniverse RTX's OpenCV-pinhole lens distortion API (docs/unreal-omniverse.md) and its attribute types.
OMNI_OPENCV_API = "OmniLensDistortionOpenCvPinholeAPI"


def _author_omni_opencv(prim, opencv) -> None:
    """Apply Omniverse's OpenCV-pinhole distortion API with a fitted model's attributes
    (:class:`physcam.export.opencv_distortion.OpenCvPinhole`)."""
    from pxr import Gf, Sdf

    prim.AddAppliedSchema(OMNI_OPENCV_API)
    for name, value in opencv.usd_attributes().items():
        if name.endswith(":model"):
            _set(prim, name, Sdf.ValueTypeNames.Token, str(value), custom=True)
        elif name.endswith(":imageSize"):
            _set(prim, name, Sdf.ValueTypeNames.Int2, Gf.Vec2i(int(value[0]), int(value[1])), custom=True)
        else:
            _set(prim, name, Sdf.ValueTypeNames.Float, require_finite(name, value, error=ExportError), custom=True)


def author_render_camera(stage, cam_path, spec: CameraSpec, *, report=None, lens_distortion=None,
                         opencv_distortion=None):
    """Write ``<cam_path>/Camera``, the UsdGeomCamera that matches ``spec`` in the stage's units.

    With ``opencv_distortion`` (an :class:`~physcam.export.opencv_distortion.OpenCvPinhole` fitted
    to the lens at this focus and sensor) the camera gets Omniverse RTX's
    ``OmniLensDistortionOpenCvPinholeAPI`` (fx, fy, cx, cy in pixels with the image size, k1..k6,
    p1, p2; docs/unreal-omniverse.md).
    With ``lens_distortion`` (see :func:`author_camera`) the camera also gets Hydra's
    ``lensDistortion:type``/``k1``/``k2``/``center``/``anaSq``/``asym``/``scale`` attributes
    (``HdCameraTokens``; hdPrman passes them to PxrCamera). They are not UsdGeomCamera schema
    attributes in usd-core, so they are written as custom attributes, like ``ri:*``.
    """
    from pxr import Gf, Sdf, UsdGeom

    from ..export.usdgeom import mm_to_scene_units

    mpu = UsdGeom.GetStageMetersPerUnit(stage)
    su = lambda mm: mm_to_scene_units(mm, mpu)  # noqa: E731
    if spec.projection == "perspective" and report is None:
        report = report_for_spec(spec)
    values, eye = render_camera_values(spec, report, mpu, stage.GetTimeCodesPerSecond(), where=f"{cam_path}")

    geom = UsdGeom.Camera.Define(stage, Sdf.Path(str(cam_path)).AppendChild(RENDER_CAMERA_NAME))
    geom.CreateProjectionAttr(values["projection"])
    geom.CreateFocalLengthAttr(values["focalLength"])
    geom.CreateHorizontalApertureAttr(values["horizontalAperture"])
    geom.CreateVerticalApertureAttr(values["verticalAperture"])
    geom.CreateHorizontalApertureOffsetAttr(values["horizontalApertureOffset"])
    geom.CreateVerticalApertureOffsetAttr(values["verticalApertureOffset"])
    geom.CreateFocusDistanceAttr(values["focusDistance"])
    geom.CreateFStopAttr(values["fStop"])
    geom.CreateClippingRangeAttr(Gf.Vec2f(*values["clippingRange"]))
    geom.CreateShutterOpenAttr(values["shutter:open"])
    geom.CreateShutterCloseAttr(values["shutter:close"])
    geom.CreateExposureTimeAttr(spec.shutter_duration_s)
    geom.CreateExposureFStopAttr(spec.t_stop)  # photometric: the T-stop
    geom.CreateExposureIsoAttr(spec.iso)
    prim = geom.GetPrim()
    # the defocus blur's aspect in the desqueezed picture (hdPrman reads ri:dofaspect off the camera)
    dof_aspect = spec.dof_aspect if spec.dof_aspect is not None else 1.0 / spec.squeeze
    _set(prim, "ri:dofaspect", Sdf.ValueTypeNames.Float, float(dof_aspect), custom=True)
    _set(prim, "ri:apertureNSides", Sdf.ValueTypeNames.Int, int(spec.aperture_blades), custom=True)
    _set(prim, "ri:apertureAngle", Sdf.ValueTypeNames.Float, spec.aperture_angle_deg, custom=True)
    _set(prim, "ri:apertureRoundness", Sdf.ValueTypeNames.Float, spec.aperture_roundness, custom=True)
    _set(prim, "ri:apertureDensity", Sdf.ValueTypeNames.Float, spec.aperture_density, custom=True)
    _set(prim, "ri:shutterOpenTime", Sdf.ValueTypeNames.Float, spec.shutter_opening[0], custom=True)
    _set(prim, "ri:shutterCloseTime", Sdf.ValueTypeNames.Float, spec.shutter_opening[1], custom=True)
    _set(prim, "ri:shutteropening", Sdf.ValueTypeNames.FloatArray,
         shutter_opening_curve(*spec.shutter_opening), custom=True)
    # Blender's USD importer reads no iris from a UsdGeomCamera (and no UsdRenderSettings); it keeps
    # userProperties:* as custom properties on the camera, where a script or physcam's extension reads them
    _set(prim, BLENDER_PROPERTY + "apertureBlades", Sdf.ValueTypeNames.Int, int(spec.aperture_blades), custom=True)
    _set(prim, BLENDER_PROPERTY + "apertureAngle", Sdf.ValueTypeNames.Float, spec.aperture_angle_deg, custom=True)
    _set(prim, BLENDER_PROPERTY + "dofAspect", Sdf.ValueTypeNames.Float, float(dof_aspect), custom=True)
    if lens_distortion is not None:
        _author_lens_distortion(prim, lens_distortion)
    if opencv_distortion is not None:
        _author_omni_opencv(prim, opencv_distortion)
    if report is not None and report.real_fov is not None:
        # say which field of view this camera shows, and what the real lens shows (issue 8)
        real = {k: report.real_fov[f"{k}_deg"] for k in ("horizontal", "vertical", "diagonal")}
        prim.SetCustomDataByKey("physcam:fieldOfView", {
            "pinholeDeg": Gf.Vec3d(report.hfov_focus_deg, report.vfov_focus_deg, report.dfov_focus_deg),
            "realChiefRaysDeg": Gf.Vec3d(*(-1.0 if v is None else v for v in real.values())),
            "realDiffers": bool(report.real_fov_differs),
        })
        if report.real_fov_differs:
            prim.SetDocumentation(
                "A pinhole: it frames the lens's centre at this focus, not its edges. The real lens's chief rays "
                f"cover {', '.join('not covered' if v is None else f'{v:.1f}' for v in real.values())} degrees "
                "(horizontal, vertical, diagonal; -1 in customData means not covered); render with the "
                "prescription for the real field.")
    xf = UsdGeom.Xformable(prim)
    xf.ClearXformOpOrder()
    xf.AddTranslateOp().Set(Gf.Vec3d(0.0, 0.0, -su(eye)))
    if spec.handedness == -1.0:  # a left-handed frame: the image is mirrored left to right
        xf.AddScaleOp(opSuffix="handedness").Set(Gf.Vec3f(-1.0, 1.0, 1.0))
    return geom


#: Hydra's lens distortion parameters and their USD value types (HdCameraTokens, "standard" model).
LENS_DISTORTION_TYPES = {
    "lensDistortion:type": "Token",
    "lensDistortion:k1": "Float",
    "lensDistortion:k2": "Float",
    "lensDistortion:center": "Float2",
    "lensDistortion:anaSq": "Float",
    "lensDistortion:asym": "Float2",
    "lensDistortion:scale": "Float",
}


def _author_lens_distortion(prim, lens_distortion):
    from pxr import Gf, Sdf

    values = lens_distortion.usd_attributes() if hasattr(lens_distortion, "usd_attributes") else dict(lens_distortion)
    unknown = set(values) - set(LENS_DISTORTION_TYPES)
    if unknown:
        raise ExportError(f"unknown lens distortion attributes {sorted(unknown)}; use {', '.join(LENS_DISTORTION_TYPES)}")
    for name, value in values.items():
        kind = LENS_DISTORTION_TYPES[name]
        if kind == "Token":
            v = str(value)
        elif kind == "Float2":
            v = Gf.Vec2f(*(require_finite(name, x, error=ExportError) for x in value))
        else:
            v = require_finite(name, value, error=ExportError)
        _set(prim, name, getattr(Sdf.ValueTypeNames, kind), v, custom=True)


#: the companion camera's attributes of a 3DE4 anamorphic fit: ``physcam:tde4AnamorphicDegree4:*`` (and 6)
TDE4_ANAMORPHIC_PREFIX = "physcam:tde4AnamorphicDegree"


def author_anamorphic_distortion(prim, fits) -> None:
    """3DE4 Anamorphic - Standard fits (:class:`physcam.analysis.distortion.anamorphic.TDE4Anamorphic`) as
    custom attributes on the companion camera ``prim``, one group per degree,
    ``physcam:tde4AnamorphicDegree<d>:``: ``model``, ``focalLength`` (mm, the Y pinhole), ``filmback`` (mm,
    the desqueezed one), ``pixelAspect`` (f_y / f_x), ``parameterNames`` and ``parameters`` (3DE's names and
    values, distorted to undistorted), ``rmsResidualPx``, ``maxResidualPx`` and ``plateSizePx`` (the frame
    the residuals are in). USD has no anamorphic lensDistortion; these carry 3DE's own model
    (docs/anamorphic.md). Groups of degrees not in ``fits`` are removed."""
    from pxr import Gf, Sdf, Vt

    from ..analysis.distortion.anamorphic import TDE4Anamorphic, tde4_anamorphic_parameter_names

    if isinstance(fits, (str, bytes)) or not hasattr(fits, "__iter__"):
        raise WrongTypeError("fits must be a list of 3DE4 anamorphic fits "
                             "(physcam.usd.kit.prescription_anamorphic_distortion(lens, ...))")
    fits = [require_type("fit", f, TDE4Anamorphic, "physcam.analysis.distortion.anamorphic.fit_tde4_anamorphic(...)")
            for f in fits]
    kept = set()
    for fit in fits:
        c = fit.coefficients
        degree = int(c["degree"])
        p = f"{TDE4_ANAMORPHIC_PREFIX}{degree}:"
        kept.add(p)
        names = tde4_anamorphic_parameter_names(degree)
        values = [require_finite(n, c[n], error=ExportError) for n in names]
        T = Sdf.ValueTypeNames
        _set(prim, p + "model", T.String, fit.model, custom=True)
        _set(prim, p + "focalLength", T.Double, require_finite("focal length", c["focal_length_mm"], error=ExportError),
             custom=True)
        _set(prim, p + "filmback", T.Double2, Gf.Vec2d(fit.sensor_mm[0] * c["pixel_aspect"], fit.sensor_mm[1]),
             custom=True)
        _set(prim, p + "pixelAspect", T.Double, require_finite("pixel aspect", c["pixel_aspect"], error=ExportError),
             custom=True)
        _set(prim, p + "parameterNames", T.StringArray, Vt.StringArray(names), custom=True)
        _set(prim, p + "parameters", T.DoubleArray, Vt.DoubleArray(values), custom=True)
        _set(prim, p + "rmsResidualPx", T.Double, float(fit.rms_residual_px), custom=True)
        _set(prim, p + "maxResidualPx", T.Double, float(fit.max_residual_px), custom=True)
        _set(prim, p + "plateSizePx", T.Int2, Gf.Vec2i(*map(int, fit.size_px)), custom=True)
    for prop in prim.GetAuthoredPropertyNames():
        if prop.startswith(TDE4_ANAMORPHIC_PREFIX) and prop[:prop.index(":", len(TDE4_ANAMORPHIC_PREFIX)) + 1] not in kept:
            prim.RemoveProperty(prop)


def author_from_report(stage, path: str, report, *, position=(0.0, 0.0, 0.0), rotate_xyz_deg=(0.0, 0.0, 0.0),
                       lens_distortion=None, **body):
    """Author the camera of a :class:`~physcam.onset.report.LensReport` (see :func:`author_camera`)."""
    return author_camera(stage, path, spec_from_report(report, **body), position=position,
                         rotate_xyz_deg=rotate_xyz_deg, report=report, lens_distortion=lens_distortion)


RENDER_SETTINGS_PATH = "/Render/Settings"


def author_render_settings(stage, camera_path, spec: CameraSpec, *, resolution=None, overscan: float = 0.0,
                           path: str = RENDER_SETTINGS_PATH):
    """A ``UsdRenderSettings`` prim for the companion camera at ``camera_path``.

    ``pixelAspectRatio`` is the squeeze (the film's pixels are squeezed; the picture is shown
    desqueezed), ``resolution`` the film's pixel grid (default 2048 wide, height from the sensor's
    aspect), so resolution x pixelAspectRatio has the camera's desqueezed aperture aspect;
    ``overscan`` (a fraction, 0.1 = 10 % wider and taller) becomes ``dataWindowNDC``
    (-o/2, -o/2, 1 + o/2, 1 + o/2): pixels beyond the display window, for distortion and
    stabilisation margins, without changing the camera's framing (UsdRender, "Render Settings").
    """
    from pxr import Gf, Sdf, UsdRender

    require_stage(stage)
    spec = require_type("spec", spec, CameraSpec, "build one with CameraSpec(...)")
    o = require_finite("overscan", overscan)
    if not 0.0 <= o <= 1.0:
        raise InputError(f"overscan must lie between 0 and 1 (a fraction of the frame), got {o:g}")
    w_px = 2048 if not resolution else int(resolution[0])
    h_px = int(resolution[1]) if resolution and len(resolution) > 1 else max(
        1, round(w_px * spec.sensor_height_mm / spec.sensor_width_mm))
    settings = UsdRender.Settings.Define(stage, Sdf.Path(path))
    settings.CreateResolutionAttr(Gf.Vec2i(w_px, h_px))
    settings.CreatePixelAspectRatioAttr(float(spec.squeeze))
    settings.CreateAspectRatioConformPolicyAttr(UsdRender.Tokens.expandAperture)
    settings.CreateDataWindowNDCAttr(Gf.Vec4f(-o / 2, -o / 2, 1 + o / 2, 1 + o / 2))
    settings.CreateCameraRel().SetTargets([Sdf.Path(str(camera_path))])
    camera = stage.GetPrimAtPath(str(camera_path))
    if camera:  # for importers that read no UsdRenderSettings (Blender: docs/blender.md)
        _set(camera, BLENDER_PROPERTY + "resolution", Sdf.ValueTypeNames.Int2, Gf.Vec2i(w_px, h_px), custom=True)
    return settings


def _usd_dict(d: dict) -> dict:
    """A JSON-like dict as USD customData can hold it: None dropped, lists of dicts as numbered sub-dicts."""
    out = {}
    for k, v in d.items():
        if v is None or (isinstance(v, list) and not v):
            continue
        if isinstance(v, dict):
            v = _usd_dict(v)
        elif isinstance(v, list) and v and isinstance(v[0], dict):
            v = {str(i): _usd_dict(x) for i, x in enumerate(v)}
        elif isinstance(v, list):
            v = [usd_text(x, k) for x in v] if any(isinstance(x, str) for x in v) else [float(x) for x in v]
        elif isinstance(v, str):
            v = usd_text(v, k)
        out[usd_text(k, "key")] = v
    return out


def save_stage(stage, file, *, force: bool = False):
    """Validate ``stage`` (usd-core's validators), then write its root layer to ``file`` atomically.

    The root layer gets USD's ``fallbackPrimTypes`` for physcam's schema types, so the file
    composes and places its cameras the same in a process without physcam's plugin.

    The layer is exported to text in memory and written with :func:`physcam.io.atomic_write`
    (temporary file in the same folder, then rename; crate is exported by USD into such a
    temporary, :func:`physcam.io.staged`); an existing file is kept unless ``force``. Returns the
    Path. ``.usda`` writes text; ``.usd``/``.usdc`` write crate.
    """
    from ..io import atomic_write, check_writable, staged
    from ..usd_names import usd_layer_format
    from .validate import check_stage

    p = check_writable(file, force=force)
    fmt = usd_layer_format(p)
    # schema fallback types (the root layer's fallbackPrimTypes): a process without physcam's
    # plugin reads a PhysicalCamera as an Xform, so the body's transform still places the
    # companion UsdGeomCamera (docs/usd.md, "Without the plugin")
    stage.WriteFallbackPrimTypes()
    check_stage(stage)
    if fmt == "usda":
        return atomic_write(p, stage.GetRootLayer().ExportToString(), force=force)
    # binary crate: USD exports into a temporary next to the target (named for it, this host and this
    # process: a killed writer's is removed by the next write, physcam.io), which is then renamed
    with staged(p, force=force, suffix=".usdc") as tmp:
        if not stage.GetRootLayer().Export(str(tmp)):
            raise ExportError(f"USD could not write {p}")
    return p


def author_prescription(stage, path, rx, focus_mm: float):
    """Author ``rx`` as a ``PhysicalCameraLensModelPrescription`` at ``path`` (surfaces scene side to film side,
    one array element per surface; docs/usd.md, "Lens models"), focused ``focus_mm`` in front of the film;
    return the prim."""
    from pxr import Sdf

    from ..lens.prescription import require_prescription

    require_stage(stage)
    require_prescription(rx, "rx")
    require_positive("focus distance", focus_mm)
    if not isinstance(path, (str, Sdf.Path)) or not Sdf.Path.IsValidPathString(str(path))[0] \
            or not Sdf.Path(str(path)).IsAbsolutePath():
        raise ExportError(f"lens model path {path!r} is not an absolute prim path such as /Lens/Prescription")

    prim = stage.DefinePrim(path, "PhysicalCameraLensModelPrescription")
    S = rx.surfaces
    T = Sdf.ValueTypeNames
    vals = {
        "radius": (T.DoubleArray, [s.radius for s in S]),
        "thickness": (T.DoubleArray, [s.thickness for s in S]),
        "nd": (T.DoubleArray, [s.medium.nd for s in S]),
        "vd": (T.DoubleArray, [s.medium.vd for s in S]),
        "semiDiameter": (T.DoubleArray, [s.semi_diameter for s in S]),
        "surfaceKind": (T.TokenArray, [s.kind for s in S]),
        "conic": (T.DoubleArray, [s.conic for s in S]),
        "asphericCoefficients": (T.DoubleArray,
                                 [a for s in S for a in (list(s.aspheric) + [0.0] * 7)[:7]]),
        "glass": (T.StringArray, [usd_text(s.medium.glass or "", "glass name") for s in S]),
        "lensName": (T.String, usd_text(rx.name, "lens name")),
        "maker": (T.String, usd_text(rx.metadata.maker or "", "lens maker")),
        "source": (T.String, usd_text(rx.metadata.source or "", "lens source")),
        "nominalFocalLength": (T.Float, float(rx.metadata.focal_length or 0.0)),
        "designWavelength": (T.Double, float(rx.wavelength_nm)),
        "squeeze": (T.Float, float(rx.squeeze)),
        "focusDistance": (T.Float, float(focus_mm)),
    }
    if rx.focus is not None:
        vals["focusCloseDistance"] = (T.Double, float(rx.focus.close_distance))
        vals["focusGapSurface"] = (T.IntArray, [g.surface for g in rx.focus.gaps])
        vals["focusGapThicknessInfinity"] = (T.DoubleArray, [g.thickness_infinity for g in rx.focus.gaps])
        vals["focusGapThicknessClose"] = (T.DoubleArray, [g.thickness_close for g in rx.focus.gaps])
    for name, (t, v) in vals.items():
        prim.CreateAttribute(name, t, False).Set(v)
    return prim


def write_camera(file, spec: CameraSpec, *, force: bool = False, path: str = DEFAULT_CAMERA_PATH,
                 meters_per_unit: float = 0.01, fps: float = 24.0, up_axis: str = "Y",
                 position=(0.0, 0.0, 0.0), rotate_xyz_deg=(0.0, 0.0, 0.0), report=None, lens_distortion=None,
                 opencv_distortion=None, render_settings: bool = True, resolution=None, overscan: float = 0.0,
                 thin_lens_gap: dict | None = None, anamorphic_distortion=(), prescription=None):
    """Write a one-camera layer to ``file`` (see :func:`author_camera`), with a ``UsdRenderSettings``
    for its companion camera (:func:`author_render_settings`) unless ``render_settings`` is false;
    return the Path. ``thin_lens_gap`` (:meth:`physcam.onset.thin_lens_gap.ThinLensGap.to_dict`) is kept
    in the companion camera's customData ``physcam:thinLensGap``: how far it is from the real lens.
    ``anamorphic_distortion``: 3DE4 anamorphic fits for the companion (:func:`author_anamorphic_distortion`).
    ``prescription``: the real lens ``spec`` was solved from, kept as ``<path>/Prescription`` beside the
    pinhole that renders, so ``physcam usd refresh`` solves the lens again at an edited f-stop, focus or
    sensor (:func:`physcam.usd.kit.refresh_shot`)."""
    stage = new_stage(meters_per_unit, fps, up_axis)
    author_camera(stage, path, spec, position=position, rotate_xyz_deg=rotate_xyz_deg, report=report,
                  lens_distortion=lens_distortion, opencv_distortion=opencv_distortion)
    if prescription is not None:
        from pxr import Sdf

        from .read import companion_inputs

        author_prescription(stage, Sdf.Path(path).AppendChild("Prescription"), prescription, spec.focus_mm)
        companion = stage.GetPrimAtPath(f"{path}/{RENDER_CAMERA_NAME}")  # its inputs now hold the lens too
        companion.SetCustomDataByKey("physcam:companionInputs", companion_inputs(stage, path))
    if thin_lens_gap is not None:
        companion = stage.GetPrimAtPath(f"{path}/{RENDER_CAMERA_NAME}")
        companion.SetCustomDataByKey("physcam:thinLensGap", _usd_dict(thin_lens_gap))
    if anamorphic_distortion:
        author_anamorphic_distortion(stage.GetPrimAtPath(f"{path}/{RENDER_CAMERA_NAME}"), anamorphic_distortion)
    if render_settings:
        author_render_settings(stage, f"{path}/{RENDER_CAMERA_NAME}", spec, resolution=resolution, overscan=overscan)
    return save_stage(stage, file, force=force)

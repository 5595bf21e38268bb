"""Read a PhysicalCamera prim (composed: variants, references, layers) back into physcam values.

:func:`read_camera` returns a :class:`CameraReading`: the :class:`~physcam.usd.author.CameraSpec`
(millimetres), which lens model the lens's ``lensModel`` relationship chose, the
prescription when that model is a ``PhysicalCameraLensModelPrescription``, and the
lens report (:func:`CameraReading.report`). Values come from the composed stage,
so the selected variants and the strongest layer win. A prim that is not a
PhysicalCamera, or a lens that points nowhere, raises
:class:`~physcam.errors.ExportError` naming the prim.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from ..errors import ExportError, require_finite, require_type
from .spec import LENS_INSTANCE, SENSOR_INSTANCE, CameraSpec
from .plugin import ensure_registered, require_prim, require_stage

__all__ = ["CameraReading", "find_cameras", "only_camera", "open_stage", "read_camera", "read_prescription", "composed_prescription",
           "companion_inputs", "companion_inputs_hash"]


@dataclass(frozen=True)
class CameraReading:
    """What a PhysicalCamera prim says, in physcam's units (mm)."""

    path: str
    spec: CameraSpec
    lens_model_path: str
    lens_model_type: str
    prescription: object | None = None
    variants: dict = field(default_factory=dict)

    def report(self):
        """The on-set lens report of this camera (practical thin-lens model)."""
        from .spec import report_for_spec

        return report_for_spec(self.spec)

    def to_dict(self) -> dict:
        return {
            "path": self.path,
            "lens_model": {"path": self.lens_model_path, "type": self.lens_model_type},
            "variants": dict(self.variants),
            "camera": self.spec.values(),
            "has_prescription": self.prescription is not None,
        }


def open_stage(file):
    """Open ``file`` as a USD stage, or raise :class:`ExportError` saying why not."""
    ensure_registered()
    from pathlib import Path

    from pxr import Tf, Usd

    p = Path(file)
    if not p.is_file():
        raise ExportError(f"{p}: no such USD file")
    if p.suffix.lower() not in (".usda", ".usd", ".usdc", ".usdz"):
        raise ExportError(f"{p}: not a USD file (a USD file name ends in .usda, .usd, .usdc or .usdz)")
    try:
        stage = Usd.Stage.Open(str(p))
    except Tf.ErrorException as exc:
        last = " ".join(str(exc).strip().splitlines()[-1].split())
        raise ExportError(f"{p}: USD cannot read it ({last[:160]})") from None
    if stage is None:
        raise ExportError(f"{p}: USD cannot open it")
    return stage


def find_cameras(stage) -> list[str]:
    """Paths of every PhysicalCamera prim on ``stage`` (composed, active, defined)."""
    ensure_registered()
    require_stage(stage)
    from pxr import Usd

    t = Usd.SchemaRegistry.GetTypeFromSchemaTypeName("PhysicalCamera")
    return [str(p.GetPath()) for p in stage.Traverse() if p.IsA(t)]


def only_camera(stage, verb: str) -> str:
    """The path of the stage's one PhysicalCamera, for ``verb`` (read, check, refresh); otherwise an
    :class:`ExportError` saying what the stage holds: several (name one with --path), or none (and
    its plain UsdGeomCamera prims, which physcam does not read as PhysicalCameras)."""
    from pxr import UsdGeom

    cams = find_cameras(stage)
    if len(cams) == 1:
        return cams[0]
    layer = stage.GetRootLayer()  # the file, when the stage is one: the error names it
    where = "" if layer.anonymous else f"{layer.realPath or layer.identifier}: "
    if cams:
        raise ExportError(f"{where}found {len(cams)} PhysicalCamera prims ({_listed(cams)}); name the one to {verb} "
                          "(--path)")
    plain = [str(p.GetPath()) for p in stage.Traverse() if p.IsA(UsdGeom.Camera)]
    also = (f"; its UsdGeomCamera prims ({_listed(plain)}) are plain cameras, not PhysicalCameras (physcam usd "
            "write makes one from the lens report's values)") if plain else ""
    raise ExportError(f"{where}found 0 PhysicalCamera prims: no physical camera to {verb}{also}")


def _listed(paths: list[str], most: int = 5) -> str:
    return ", ".join(paths[:most]) + (f" and {len(paths) - most} more" if len(paths) > most else "")


def _at(attr, time=None):
    """``attr``'s value at the time code ``time`` (a Usd.TimeCode), or its default value when ``time`` is None."""
    return attr.Get() if time is None else attr.Get(time)


def _get(prim, name, what, time=None):
    attr = prim.GetAttribute(name)
    if not attr:
        raise ExportError(f"{prim.GetPath()}: has no {name} attribute; {what}")
    v = _at(attr, time)
    if v is None:
        raise ExportError(f"{prim.GetPath()}: {name} has no value; {what}")
    return v


def _pair(prim, name: str, default, time=None):
    attr = prim.GetAttribute(name)
    v = _at(attr, time) if attr else None
    return default if v is None else (float(v[0]), float(v[1]))


def _optional(prim, name: str, time=None):
    """An authored float attribute's value (at ``time``, default the default value), or None when it is not
    authored."""
    attr = prim.GetAttribute(name)
    if not attr or not attr.HasAuthoredValue():
        return None
    return float(_at(attr, time))


def _fstop_at_focus(prim, lp: str, focal_mm: float, time=None):
    """The f-number at the focus from the lens's ``iris`` (focal length / iris) when it differs from its
    ``fStop`` beyond float32 rounding (an internal-focus lens: physcam.onset.report), else None."""
    iris, n = _optional(prim, lp + "iris", time), _optional(prim, lp + "fStop", time)
    if iris is None or n is None or not iris > 0:
        return None
    at_focus = focal_mm / iris
    return at_focus if abs(at_focus - n) > 1e-5 * n else None


def _principal_planes(prim, lp: str, time=None):
    """(H1, H2) in front of the film when both are authored, else None (a thin lens)."""
    a = prim.GetAttribute(lp + "frontPrincipalPlaneDistance")
    b = prim.GetAttribute(lp + "rearPrincipalPlaneDistance")
    h1 = _at(a, time) if a else None
    h2 = _at(b, time) if b else None
    if (h1 is None) != (h2 is None):
        raise ExportError(f"{prim.GetPath()}: author both {lp}frontPrincipalPlaneDistance and "
                          f"{lp}rearPrincipalPlaneDistance, or neither")
    return None if h1 is None else (float(h1), float(h2))


def _instance(prim, schema: str, preferred: str) -> str:
    names = [s.split(":", 1)[1] for s in prim.GetAppliedSchemas() if s.startswith(schema + ":")]
    if not names:
        raise ExportError(f"{prim.GetPath()}: no {schema} is applied; apply {schema}:{preferred}")
    return preferred if preferred in names else names[0]


def read_prescription(model_prim):
    """A :class:`~physcam.lens.prescription.Prescription` from a PhysicalCameraLensModelPrescription prim."""
    from ..errors import LensFileError
    from ..lens.prescription import Focus, LensMetadata, Medium, Prescription, Surface, VariableGap

    require_prim(model_prim, "model_prim")
    where = f"{model_prim.GetPath()}"
    arrays = {n: list(model_prim.GetAttribute(n).Get() or []) for n in
              ("radius", "thickness", "nd", "vd", "semiDiameter", "surfaceKind", "conic", "asphericCoefficients",
               "glass")}
    n = len(arrays["radius"])
    if n == 0:
        raise ExportError(f"{where}: the prescription has no surfaces (radius is empty)")
    for key in ("thickness", "nd", "vd", "semiDiameter", "surfaceKind"):
        if len(arrays[key]) != n:
            raise ExportError(f"{where}: {key} has {len(arrays[key])} values for {n} surfaces")
    conic = arrays["conic"] or [0.0] * n
    asph = arrays["asphericCoefficients"] or [0.0] * (7 * n)
    glass = arrays["glass"] or [""] * n
    if len(conic) != n or len(asph) != 7 * n or len(glass) != n:
        raise ExportError(f"{where}: conic, glass need one value per surface and asphericCoefficients 7 per surface")
    surfaces = []
    for i in range(n):
        a = tuple(asph[7 * i: 7 * i + 7])
        while a and a[-1] == 0.0:
            a = a[:-1]
        surfaces.append(Surface(
            radius=float(arrays["radius"][i]), thickness=float(arrays["thickness"][i]),
            medium=Medium(float(arrays["nd"][i]), float(arrays["vd"][i]), glass[i] or None),
            semi_diameter=float(arrays["semiDiameter"][i]), kind=str(arrays["surfaceKind"][i]),
            conic=float(conic[i]), aspheric=a,
        ))
    focus = None
    close = model_prim.GetAttribute("focusCloseDistance").Get() or 0.0
    if close > 0:
        idx = list(model_prim.GetAttribute("focusGapSurface").Get() or [])
        t_inf = list(model_prim.GetAttribute("focusGapThicknessInfinity").Get() or [])
        t_close = list(model_prim.GetAttribute("focusGapThicknessClose").Get() or [])
        if not len(idx) == len(t_inf) == len(t_close):
            raise ExportError(f"{where}: focusGapSurface and the focus gap thicknesses differ in length")
        focus = Focus(float(close), tuple(VariableGap(int(i), float(a), float(b)) for i, a, b in zip(idx, t_inf, t_close)))
    meta = LensMetadata(
        name=model_prim.GetAttribute("lensName").Get() or model_prim.GetName(),
        maker=model_prim.GetAttribute("maker").Get() or None,
        source=model_prim.GetAttribute("source").Get() or None,
        focal_length=(model_prim.GetAttribute("nominalFocalLength").Get() or None),
    )
    rx = Prescription(
        surfaces=tuple(surfaces), metadata=meta, focus=focus,
        squeeze=float(model_prim.GetAttribute("squeeze").Get()),
        wavelength_nm=float(model_prim.GetAttribute("designWavelength").Get()),
    )
    try:
        return rx.validate()
    except LensFileError as exc:
        raise ExportError(f"{where}: {exc}") from None


def read_camera(stage, path: str | None = None, *, time: float | None = None) -> CameraReading:
    """Read the PhysicalCamera at ``path`` (default: the only one on the stage), its values at time code
    ``time`` (default: the authored default values, what a still camera holds; an animated camera's
    time-sampled focus and f-stop at one frame with a time code)."""
    ensure_registered()
    require_stage(stage)
    from pxr import Sdf, Usd, UsdGeom

    from ..export.usdgeom import mm_to_scene_units

    if path is None:
        path = only_camera(stage, "read")
    t = None if time is None else Usd.TimeCode(require_finite("time code", time))
    prim = stage.GetPrimAtPath(Sdf.Path(path)) if Sdf.Path.IsValidPathString(path) else None
    if not prim:
        raise ExportError(f"{path}: no prim at that path")
    if not prim.IsA(Usd.SchemaRegistry.GetTypeFromSchemaTypeName("PhysicalCamera")):
        kind = prim.GetTypeName() or "typeless prim"
        raise ExportError(f"{path}: is a {kind}, not a PhysicalCamera")
    applied = {a.split(":", 1)[0] for a in prim.GetAppliedSchemas()}
    has_sensor, has_lens = "PhysicalCameraSensorAPI" in applied, "PhysicalCameraLensAPI" in applied
    if has_lens and not has_sensor:
        raise ExportError(f"{prim.GetPath()} holds only a lens (no sensor): a lens file to reference from a shot "
                          "with a body (physcam.usd.kit.write_shot), not a whole camera")
    if has_sensor and not has_lens:
        raise ExportError(f"{prim.GetPath()} holds only a body and sensor (no lens): a body file to reference from "
                          "a shot with a lens (physcam.usd.kit.write_shot), not a whole camera")
    s = _instance(prim, "PhysicalCameraSensorAPI", SENSOR_INSTANCE)
    ln = _instance(prim, "PhysicalCameraLensAPI", LENS_INSTANCE)
    sp, lp = f"sensor:{s}:", f"lens:{ln}:"
    targets = prim.GetRelationship(lp + "lensModel").GetForwardedTargets() if prim.GetRelationship(lp + "lensModel") \
        else []
    if not targets:
        raise ExportError(f"{path}: {lp}lensModel points at no lens model; target a PhysicalCameraLensModel* prim")
    model = stage.GetPrimAtPath(targets[0])
    if not model:
        raise ExportError(f"{path}: {lp}lensModel points at {targets[0]}, which does not exist")
    mtype = model.GetTypeName()
    rx = None
    if mtype == "PhysicalCameraLensModelPinhole":
        focal = float(_get(model, "focalLength", "author the focal length in mm", t))
        projection, magnification = "perspective", 1.0
    elif mtype == "PhysicalCameraLensModelOrthographic":
        focal = float(model.GetCustomDataByKey("physcam:focalLength") or 50.0)
        projection, magnification = "orthographic", float(_get(model, "magnification", "author it", t))
    elif mtype == "PhysicalCameraLensModelPrescription":
        from ..optics.paraxial import gaussian

        rx = read_prescription(model)
        focal = float(gaussian(rx).efl)
        projection, magnification = "perspective", 1.0
    else:
        raise ExportError(f"{path}: {lp}lensModel points at {model.GetPath()}, a {mtype or 'typeless prim'}, "
                          "not a PhysicalCameraLensModel")
    mpu = UsdGeom.GetStageMetersPerUnit(stage)
    clip = _get(prim, lp + "clippingRange", "author it in scene units", t)
    to_mm = 1.0 / mm_to_scene_units(1.0, mpu)
    aperture = _get(prim, sp + "aperture", "author the sensor size in mm", t)
    shift = _get(prim, sp + "shift", "", t)
    opening = _get(prim, "shutterOpening", "", t)
    spec = CameraSpec.of(
        focal_length_mm=focal,
        sensor_width_mm=float(aperture[0]),
        sensor_height_mm=float(aperture[1]),
        fstop=float(_get(prim, lp + "fStop", "author the f-stop", t)),
        focus_mm=float(_get(model, "focusDistance", "author the focus distance in mm", t)),
        coc_mm=float(_get(prim, sp + "circleOfConfusion", "", t)),
        squeeze=float(_get(model, "squeeze", "", t)),
        entrance_pupil_mm=_optional(prim, lp + "entrancePupilDistance", t),  # unauthored: unknown, not the fallback
        horizontal_entrance_pupil_mm=_optional(prim, lp + "horizontalEntrancePupilDistance", t),
        principal_planes_mm=_principal_planes(prim, lp, t),
        pinhole_focal_length_mm=_optional(prim, lp + "pinholeFocalLength", t),
        pinhole_squeeze=_optional(prim, lp + "pinholeSqueeze", t),
        fstop_at_focus=_fstop_at_focus(prim, lp, focal, t),
        shift_mm=(float(shift[0]), float(shift[1])),
        iso=float(_get(prim, sp + "iso", "", t)),
        transmittance=float(_get(model, "transmittance", "", t)),
        flange_distance_mm=float(_get(prim, "flangeDistance", "", t)),
        aperture_distance_mm=_optional(prim, lp + "apertureDistance", t),
        enlarge=_pair(prim, sp + "enlarge", (1.0, 1.0), t),
        handedness=float(_get(prim, sp + "handedness", "", t)) if prim.GetAttribute(sp + "handedness")
        and prim.GetAttribute(sp + "handedness").Get() is not None else 1.0,
        shutter_open_s=float(_get(prim, "shutterOpen", "", t)),
        shutter_duration_s=float(_get(prim, "shutterDuration", "", t)),
        shutter_opening=(float(opening[0]), float(opening[1])),
        aperture_blades=int(_get(prim, lp + "shutterBlades", "", t)),
        aperture_angle_deg=float(_get(prim, lp + "apertureAngle", "", t)),
        aperture_roundness=float(_get(prim, lp + "apertureRoundness", "", t)),
        aperture_density=float(_get(prim, lp + "apertureDensity", "", t)),
        clipping_mm=(float(clip[0]) * to_mm, float(clip[1]) * to_mm),
        projection=projection,
        magnification=magnification,
        lens_name=(model.GetCustomDataByKey("physcam:lensName") or (rx.name if rx else None)),
        sensor_name=prim.GetCustomDataByKey("physcam:sensorName"),
    )
    try:
        spec = spec.checked()
    except Exception as exc:
        raise ExportError(f"{path}: {exc}") from None
    variants = {}
    for p in [prim, *prim.GetAllChildren()][:1]:
        vsets = p.GetVariantSets()
        for name in vsets.GetNames():
            variants[name] = vsets.GetVariantSelection(name)
    return CameraReading(str(prim.GetPath()), spec, str(model.GetPath()), mtype, rx, variants)


def composed_prescription(stage, path):
    """The prescription a composed camera's lens carries (a PhysicalCameraLensModelPrescription
    among its children, as in a vendor lens file shown through its pinhole), or None."""
    require_stage(stage)
    prim = stage.GetPrimAtPath(str(path))
    for child in prim.GetChildren():
        if child.GetTypeName() == "PhysicalCameraLensModelPrescription":
            return read_prescription(child)
    return None


def companion_inputs_hash(spec, prescription=None) -> str:
    """SHA-256 (hex) of everything a companion camera is computed from: the composed camera's
    values and, when the lens carries one, its prescription."""
    import hashlib
    import json
    from dataclasses import asdict

    require_type("spec", spec, CameraSpec, "the composed camera: physcam.usd.read.read_camera(stage).spec")
    camera = spec.values()
    if camera.get("horizontal_entrance_pupil_mm") is None:  # files written before the field hash as they did
        camera.pop("horizontal_entrance_pupil_mm", None)
    doc = {"camera": camera}
    if prescription is not None:
        doc["prescription"] = [asdict(s) for s in prescription.surfaces]
        doc["focus"] = None if prescription.focus is None else asdict(prescription.focus)
    text = json.dumps(doc, sort_keys=True, default=str)
    return hashlib.sha256(text.encode()).hexdigest()


def companion_inputs(stage, path, *, time: float | None = None) -> str:
    """The hash of what the companion of the PhysicalCamera ``path`` is computed from, as the stage
    composes now (read back, so float32 storage is what is hashed), at time code ``time`` (default: its
    default values; a keyed lens with no default value, a DCC's samples only: its first time code)."""
    return companion_inputs_hash(read_camera(stage, path, time=time).spec, composed_prescription(stage, path))

"""The "Physical Cameras for USD" proposal's pipeline use cases, built from physcam cameras.

* :func:`write_lens_file`: a lens library entry, one file per lens, with one
  ``characterization`` variant per measuring day plus ``current`` (a copy of the
  latest, selected by default) ("Interesting Looking Models").
* :func:`write_body_file` and :func:`write_shot`: bodies and lenses in their own files,
  referenced together per shot, with shot-level overrides ("Likeable Puppets").
* :func:`write_previs_kit`: one file, eight ``setup`` variants (Doll House, Over The
  Shoulder, Out in the Desert, ...) ("Bellam Blvd Previs").
* :func:`write_vendor_lens`: a vendor's lens file with the real prescription and a
  best-match pinhole, a ``lensModel`` variant choosing which renders ("Beloved Lens Co").

Every file is validated with usd-core's validators and written atomically
(:func:`physcam.usd.author.save_stage`). Lengths in mm (docs/usd.md).
"""

from __future__ import annotations

import math

from ..data.default_sensor import DEFAULT_SENSOR_HEIGHT_MM, DEFAULT_SENSOR_WIDTH_MM
from ..errors import ExportError, InputError, require_type
from ..export._codetext import printable_line
from ..lens.prescription import takes_prescription
from ..usd_names import usd_layer_format
from .author import (LENS_INSTANCE, SENSOR_INSTANCE, CameraSpec, author_camera, author_prescription, author_render_camera,
                     new_stage, save_stage)
from .float32_values import _same_value, _same_view, _shown_value
from .keyed_lens import (_author_samples, _keyed_time_codes, _refuse_samples_not_followed, _remove_left_samples,
                         _samples_solved, _stale_samples, _still_time, time_code_text)
from .read import companion_inputs, companion_inputs_hash, composed_prescription
from .solved_lens import _lens_derived_values, _lens_solved
from .plugin import ensure_registered

__all__ = [
    "PREVIS_SETUPS",
    "SHOT_OVERRIDES",
    "best_match_pinhole",
    "write_body_file",
    "write_lens_file",
    "write_previs_kit",
    "write_shot",
    "write_vendor_lens",
    "check_shot",
    "refresh_shot",
    "companion_inputs_hash",
    "prescription_opencv",
    "prescription_anamorphic_distortion",
]

LENS_PRIM = "/Lens"
BODY_PRIM = "/Body"

#: The previs kit's eight setups: variant name -> camera (mm, f-numbers; focus from the film plane).
PREVIS_SETUPS: dict[str, CameraSpec] = {
    "DollHouse": CameraSpec.of(focal_length_mm=24.0, fstop=16.0, focus_mm=300.0, sensor_width_mm=23.6,
                               sensor_height_mm=15.6, coc_mm=0.02, clipping_mm=(10.0, 1.0e5)),
    "OverTheShoulder": CameraSpec.of(focal_length_mm=50.0, fstop=2.8, focus_mm=1500.0, sensor_width_mm=24.89,
                                     sensor_height_mm=18.66, coc_mm=0.025),
    "OutInTheDesert": CameraSpec.of(focal_length_mm=24.0, fstop=11.0, focus_mm=20000.0, sensor_width_mm=24.89,
                                    sensor_height_mm=18.66, coc_mm=0.025, clipping_mm=(500.0, 1.0e8)),
    "CloseUp": CameraSpec.of(focal_length_mm=85.0, fstop=2.0, focus_mm=1000.0, sensor_width_mm=24.89,
                             sensor_height_mm=18.66, coc_mm=0.025),
    "WideMaster": CameraSpec.of(focal_length_mm=18.0, fstop=5.6, focus_mm=4000.0, sensor_width_mm=24.89,
                                sensor_height_mm=18.66, coc_mm=0.025),
    "LongLens": CameraSpec.of(focal_length_mm=200.0, fstop=4.0, focus_mm=30000.0, sensor_width_mm=24.89,
                              sensor_height_mm=18.66, coc_mm=0.025, clipping_mm=(1000.0, 1.0e8)),
    "Anamorphic": CameraSpec.of(focal_length_mm=50.0, fstop=2.8, focus_mm=3000.0, sensor_width_mm=22.0,
                                sensor_height_mm=18.6, squeeze=2.0, coc_mm=0.025, aperture_blades=11),
    "TopDownPlan": CameraSpec.of(projection="orthographic", magnification=0.002, focal_length_mm=50.0,
                                 focus_mm=10000.0, sensor_width_mm=36.0, sensor_height_mm=24.0,
                                 clipping_mm=(100.0, 1.0e6)),
}

#: Where a previs setup's camera stands (mm, Y up) and how it turns (degrees, XYZ): the plan view
#: looks straight down (-Y) from 10 m; the others stand at the origin looking down -Z.
PREVIS_PLACEMENT: dict[str, tuple[tuple[float, float, float], tuple[float, float, float]]] = {
    "TopDownPlan": ((0.0, 10000.0, 0.0), (-90.0, 0.0, 0.0)),
}

#: CameraSpec fields a shot may override, and the schema attributes each one writes.
SHOT_OVERRIDES = {
    "fstop": "lens", "focus_mm": "lens", "transmittance": "lens", "aperture_blades": "lens",
    "aperture_angle_deg": "lens", "aperture_roundness": "lens", "aperture_density": "lens",
    "clipping_mm": "lens",
    "shift_mm": "sensor", "iso": "sensor", "coc_mm": "sensor",
    "shutter_open_s": "body", "shutter_duration_s": "body", "shutter_opening": "body",
}


def _stage(meters_per_unit, fps):
    return new_stage(meters_per_unit, fps)


def write_lens_file(file, characterizations: dict, *, force: bool = False, meters_per_unit: float = 0.01,
                    fps: float = 24.0):
    """One lens, one file: ``characterizations`` maps a date ("2026-03-01") to the lens's CameraSpec that day.

    Only the lens part is written (lens API, lens model). Variant set
    ``characterization`` holds one variant per date (names get a ``d`` prefix, USD
    variant names cannot start with a digit... they can, but ``-`` is not allowed,
    so ``2026-03-01`` becomes ``d2026_03_01``) and ``current``, a copy of the latest
    date, selected by default. Returns the Path.
    """
    ensure_registered()
    if not isinstance(characterizations, dict) or not characterizations:
        raise InputError("a lens file needs a dict of at least one characterization (date -> CameraSpec)")
    for date, spec in characterizations.items():
        require_type(f"characterization {date!r}", spec, CameraSpec, "date -> CameraSpec of the lens that day")
    stage = _stage(meters_per_unit, fps)
    prim = stage.DefinePrim(LENS_PRIM, "PhysicalCamera")
    stage.SetDefaultPrim(prim)
    vset = prim.GetVariantSets().AddVariantSet("characterization")
    dates = sorted(characterizations)
    entries = [(_variant_name(d), characterizations[d]) for d in dates]
    names = [n for n, _ in entries]
    clash = sorted({d for d in dates if names.count(_variant_name(d)) > 1})
    if clash:
        raise InputError(f"the dates {', '.join(printable_line(d, limit=40) for d in clash)} make one variant name "
                         f"{_variant_name(clash[0])!r}: give each measuring day a distinct date")
    entries.append(("current", characterizations[dates[-1]]))
    for name, spec in entries:
        vset.AddVariant(name)
        vset.SetVariantSelection(name)
        with vset.GetVariantEditContext():
            author_camera(stage, LENS_PRIM, spec, parts=("lens",))
    vset.SetVariantSelection("current")
    prim.SetCustomDataByKey("physcam:currentIs", _variant_name(dates[-1]))
    return save_stage(stage, file, force=force)


def _variant_name(date: str) -> str:
    """``d`` + the date with every character but ASCII letters and digits made ``_``: a USD variant
    name (Sdf's variant identifiers take letters, digits, ``_``, ``-`` and ``|``; ``str.isalnum`` also
    passes Unicode digits such as a superscript two that Sdf refuses with an error of its own)."""
    return "d" + "".join(c if c.isascii() and c.isalnum() else "_" for c in str(date))


def write_body_file(file, spec: CameraSpec, *, force: bool = False, meters_per_unit: float = 0.01,
                    fps: float = 24.0):
    """A camera body (flange, shutter, transform pivot) with its sensor, at ``/Body``."""
    stage = _stage(meters_per_unit, fps)
    author_camera(stage, BODY_PRIM, spec, parts=("body", "sensor"))
    return save_stage(stage, file, force=force)


def write_shot(file, body_file, lens_file, *, overrides: dict | None = None, lens_variant: str | None = None,
               path: str = "/Cameras/Shot", position=(0.0, 0.0, 0.0), rotate_xyz_deg=(0.0, 0.0, 0.0),
               force: bool = False, meters_per_unit: float = 0.01, fps: float = 24.0):
    """A shot layer: ``path`` references the body and the lens files; the shot's overrides are local.

    The composed camera is read back, ``overrides`` (CameraSpec fields listed in
    :data:`SHOT_OVERRIDES`) are applied as shot-layer opinions, and the companion
    UsdGeomCamera is written from the composed result (:func:`refresh_shot` recomputes it
    later; :func:`check_shot` says when it is stale). ``lens_variant`` pins a characterization
    (for archiving); the default keeps the lens file's selection ("current").

    Units: the referenced files may use other ``metersPerUnit`` than the shot. Every length in
    physcam's schema is in mm except the lens's ``clippingRange`` and the transform; the shot
    re-authors both in its own unit (the clipping range read from each file in that file's
    unit), so a metre shot composes centimetre files correctly.

    A lens with a prescription (a vendor lens file) is evaluated at the shot's focus and f-stop
    on the body's sensor: EFL, principal planes, entrance pupil and best-match pinhole become
    shot opinions, and the lens distortion is fitted for the body's sensor.
    """
    from pathlib import Path

    from pxr import Sdf, Usd, UsdGeom

    overrides = dict(overrides or {})
    unknown = set(overrides) - set(SHOT_OVERRIDES)
    if unknown:
        raise InputError(f"cannot override {sorted(unknown)} per shot; choose from {', '.join(sorted(SHOT_OVERRIDES))}")
    out = Path(file).resolve()
    if not Sdf.Path.IsValidPathString(path) or not Sdf.Path(path).IsAbsolutePath():
        raise ExportError(f"shot camera path {path!r} is not an absolute prim path such as /Cameras/Shot")
    sources = {}
    for f, prim_path in ((lens_file, LENS_PRIM), (body_file, BODY_PRIM)):
        p = Path(f)
        if not p.is_file():
            raise ExportError(f"{p}: no such file to reference")
        sources[prim_path] = _file_units(p, prim_path)
    # an in-memory layer that carries the output path, so relative references resolve from its folder
    layer = Sdf.Find(str(out)) or Sdf.Layer.New(Sdf.FileFormat.FindByExtension("usda"), str(out))
    layer.Clear()
    stage = Usd.Stage.Open(layer)
    UsdGeom.SetStageMetersPerUnit(stage, meters_per_unit)
    UsdGeom.SetStageUpAxis(stage, "Y")
    stage.SetTimeCodesPerSecond(fps)
    stage.SetFramesPerSecond(fps)
    for parent in reversed(Sdf.Path(path).GetParentPath().GetPrefixes()):
        UsdGeom.Xform.Define(stage, parent)
    cam = stage.DefinePrim(path, "PhysicalCamera")
    stage.SetDefaultPrim(stage.GetPrimAtPath(Sdf.Path(path).GetPrefixes()[0]))
    refs = cam.GetReferences()
    for f, prim_path in ((lens_file, LENS_PRIM), (body_file, BODY_PRIM)):  # lens listed first: stronger
        refs.AddReference(Path(_relpath(Path(f).resolve(), out.parent)).as_posix(), Sdf.Path(prim_path))
    if lens_variant is not None:
        vsets = cam.GetVariantSets()
        names = vsets.GetVariantSet("characterization").GetVariantNames() \
            if "characterization" in vsets.GetNames() else []
        if lens_variant not in names and _variant_name(lens_variant) in names:
            lens_variant = _variant_name(lens_variant)  # the measuring day as the CSV wrote it: 2026-03-01
        if lens_variant not in names:
            raise ExportError(f"{path}: lens file {lens_file} has no characterization variant {lens_variant!r}"
                              f" (it has {', '.join(names) or 'none'})")
        vsets.GetVariantSet("characterization").SetVariantSelection(lens_variant)
    try:
        # the clipping range in mm, read from the lens file in its own unit (issue 9: a metre shot
        # read a centimetre file's 10 cm near clip as 10 m)
        lens_mpu, lens_clip_mm = sources[LENS_PRIM]
        if lens_clip_mm is not None and lens_mpu != meters_per_unit and "clipping_mm" not in overrides:
            overrides["clipping_mm"] = lens_clip_mm
        spec = _read_spec(stage, path).replaced(**overrides).checked()
        # only what the shot overrides becomes a shot-layer opinion: everything else stays with the
        # referenced body and lens files (and their variants), so switching a characterization in the
        # shot still switches the lens
        _author_overrides(stage, cam, spec, overrides)
        # the shot places the camera: its transform pivots about the (composed) entrance pupil
        _author_placement(cam, spec, position, rotate_xyz_deg)
        _author_shot_companion(stage, path)
        return save_stage(stage, out, force=force)
    finally:
        layer.Clear()


def _file_units(p, prim_path):
    """(metersPerUnit, clipping range in mm or None) of the camera prim ``prim_path`` in file ``p``."""
    from pxr import Usd, UsdGeom

    from ..export.usdgeom import mm_to_scene_units

    stage = Usd.Stage.Open(str(p))
    if stage is None:
        raise ExportError(f"{p}: USD cannot open it")
    mpu = UsdGeom.GetStageMetersPerUnit(stage)
    prim = stage.GetPrimAtPath(prim_path)
    if not prim:
        raise ExportError(f"{p}: has no {prim_path} prim to reference (write it with physcam.usd.kit)")
    clip = prim.GetAttribute(f"lens:{LENS_INSTANCE}:clippingRange")
    clip_mm = None
    if clip and clip.HasAuthoredValue():
        v = clip.Get()
        clip_mm = (float(v[0]) / mm_to_scene_units(1.0, mpu), float(v[1]) / mm_to_scene_units(1.0, mpu))
    return mpu, clip_mm


def _read_spec(stage, path):
    from .read import read_camera

    return read_camera(stage, path).spec


def _author_shot_companion(stage, path, time: float | None = None) -> str:
    """(Re)compute the shot's companion UsdGeomCamera from the composed camera; return the inputs hash.

    With a prescription the lens is re-evaluated at the composed focus and f-stop on the composed
    (body's) sensor; its derived lens values are written as shot opinions and its distortion is
    fitted for that sensor. The hash of every input (:func:`companion_inputs_hash`) is stored
    as ``customData physcam:companionInputs`` on the companion, for :func:`check_shot`. ``time``: the
    time code whose values a keyed lens without default values gives its still part (:func:`_still_time`).
    """
    from pxr import Sdf

    from .author import _eye_from_film, author_anamorphic_distortion, iris_mm

    spec, rx, report, derived = _lens_solved(stage, path, time)
    cam = stage.GetPrimAtPath(path)
    distortion, opencv, anamorphic = None, None, []
    if derived is not None:
        _author_lens_derived(stage, cam, derived)
        if time is None:  # else the model's focal length is keyed, with no default to give it
            _author_model_focal_length(stage, cam, derived.focal_length_mm)
        distortion = prescription_distortion(rx, spec.sensor_width_mm, spec.sensor_height_mm, focus_mm=spec.focus_mm)
        anamorphic = prescription_anamorphic_distortion(rx, spec.sensor_width_mm, spec.sensor_height_mm,
                                                        focus_mm=spec.focus_mm)
        opencv = prescription_opencv(rx, spec.sensor_width_mm, spec.sensor_height_mm, focus_mm=spec.focus_mm)
    # values derived from the composed lens, rewritten every time: the iris (the entrance pupil at the focus,
    # f / N but for an internal-focus lens, whose f-number moves: iris_mm) and the film's place behind the
    # pupil, so the pupil stays where the shot put it when the lens file changes
    (cam.GetAttribute(f"lens:{LENS_INSTANCE}:iris") or cam.CreateAttribute(
        f"lens:{LENS_INSTANCE}:iris", Sdf.ValueTypeNames.Float)).Set(iris_mm(spec))
    _move_film_behind_pupil(cam, _eye_from_film(spec, report))
    geom = author_render_camera(stage, Sdf.Path(path), spec, report=report, lens_distortion=distortion,
                                opencv_distortion=opencv)
    author_anamorphic_distortion(geom.GetPrim(), anamorphic)  # none: a stale one from another lens goes
    if report is not None and geom.GetPrim().GetCustomDataByKey("physcam:thinLensGap") is not None:
        from ..onset.thin_lens_gap import thin_lens_gap
        from .author import _usd_dict

        # usd write's account of the thin lens against the real one, at the stop and focus now authored
        geom.GetPrim().SetCustomDataByKey("physcam:thinLensGap", _usd_dict(thin_lens_gap(report).to_dict()))
    digest = companion_inputs(stage, path, time=time)
    geom.GetPrim().SetCustomDataByKey("physcam:companionInputs", digest)
    return digest


def _move_film_behind_pupil(cam, pupil_mm: float) -> None:
    """Keep the shot's placement (the entrance pupil where it was put) when the pupil's distance
    from the film changed: rewrite the ``translate:pupilToFilm`` op in the shot's unit."""
    from pxr import Gf, UsdGeom

    from ..export.usdgeom import mm_to_scene_units

    op = cam.GetAttribute("xformOp:translate:pupilToFilm")
    if op:
        op.Set(Gf.Vec3d(0.0, 0.0, mm_to_scene_units(pupil_mm, UsdGeom.GetStageMetersPerUnit(cam.GetStage()))))


def _author_model_focal_length(stage, cam, efl_mm: float) -> None:
    """The pinhole model's ``focalLength`` is the lens's EFL at the focus (an internal-focus lens's moves
    with it, as ``usd animate`` samples it); a shot's opinion over a referenced model."""
    targets = cam.GetRelationship(f"lens:{LENS_INSTANCE}:lensModel").GetForwardedTargets()
    model = stage.GetPrimAtPath(targets[0]) if targets else None
    if model and model.GetTypeName() == "PhysicalCameraLensModelPinhole":
        attr = model.GetAttribute("focalLength")
        if not _same_value(attr.Get(), float(efl_mm)):  # no shot opinion where the lens file says it already
            attr.Set(float(efl_mm))


def _author_lens_derived(stage, cam, spec) -> None:
    """Lens values a prescription gives at the shot's focus, as shot opinions."""
    from pxr import Sdf

    F = Sdf.ValueTypeNames.Float
    lp = f"lens:{LENS_INSTANCE}:"
    values = _lens_derived_values(spec)
    stop = cam.GetAttribute(lp + "apertureDistance")  # no shot opinion where the lens file says it already
    if lp + "apertureDistance" in values and stop and _same_value(stop.Get(), values[lp + "apertureDistance"]):
        del values[lp + "apertureDistance"]
    for name, v in values.items():
        (cam.GetAttribute(name) or cam.CreateAttribute(name, F)).Set(v)
    if spec.horizontal_entrance_pupil_mm is None and cam.GetAttribute(lp + "horizontalEntrancePupilDistance"):
        cam.GetAttribute(lp + "horizontalEntrancePupilDistance").Clear()  # a lens with one pupil now


def check_shot(file, path: str | None = None) -> dict:
    """Is a shot's companion camera current? Returns ``{"path", "stale", "stored", "current", "units"}``.

    ``stale`` is true when the companion was computed from other inputs than the composed camera
    now has (a lens file's ``current`` characterization changed, a body file was edited, ...),
    or carries no stored hash. ``units`` lists referenced files whose metersPerUnit differs from
    the shot's (composed correctly by :func:`write_shot`, worth knowing). An animated camera adds
    ``time_codes`` (its lens's keys) and ``stale_samples`` (``{"time", "attributes", "left"}``: a keyed
    time code's stale derived samples, or with ``left`` true a deleted key's own samples, which
    :func:`refresh_shot` removes; docs/usd.md).
    """
    return _checked(file, path, "check")


def _checked(file, path, action: str) -> dict:
    """:func:`check_shot`'s answer; ``action`` the command the user ran (check, or refresh, which checks first),
    which its errors name."""
    from pxr import Sdf, UsdGeom

    from .read import only_camera, open_stage

    stage = open_stage(file)
    stage.Reload()  # the referenced files as they are on disk now, not as this process cached them
    if path is None:
        path = only_camera(stage, action)  # its error names the file
    times, left = _refuse_what_cannot_be_followed(stage, path, file, action)
    geom = stage.GetPrimAtPath(Sdf.Path(path).AppendChild("Camera"))
    if not geom:
        raise ExportError(f"{path}: has no companion camera to check")
    samples = _stale_samples(stage, path, _samples_solved(stage, path, file, action, times)) if times else []
    current = companion_inputs(stage, path, time=_still_time(stage, path, times))
    stored = geom.GetCustomDataByKey("physcam:companionInputs")
    mpu = UsdGeom.GetStageMetersPerUnit(stage)
    units = []
    for ref_layer in stage.GetUsedLayers():
        if ref_layer == stage.GetRootLayer() or ref_layer.anonymous:
            continue
        lm = ref_layer.pseudoRoot.GetInfo("metersPerUnit") if ref_layer.pseudoRoot.HasInfo("metersPerUnit") else None
        if lm is not None and float(lm) != mpu:
            units.append({"file": ref_layer.identifier, "meters_per_unit": float(lm)})
    reasons = []
    if stored != current:
        reasons.append("the companion carries no inputs hash (written by hand or by an older physcam)" if stored is None
                       else "the camera's composed values (its body, lens or shot opinions) changed since the companion "
                            "was computed")
    if left:
        t = time_code_text(left[0]["time"])
        reasons.append(f"{len(left)} time code{'s' * (len(left) != 1)} hold{'s' * (len(left) == 1)} samples left from "
                       f"a deleted key (first {t}: {len(left[0]['attributes'])} derived attributes)")
    if samples:
        first = samples[0]
        reasons.append(f"{len(samples)} of its time codes {'is' if len(samples) == 1 else 'are'} stale (first {time_code_text(first['time'])}: "
                       f"{', '.join(first['attributes'])})")
    return {"path": path, "stale": bool(reasons), "stored": stored, "current": current,
            "meters_per_unit": mpu, "units": units, "reason": "; ".join(reasons) or None,
            "time_codes": times, "stale_samples": sorted(samples + left, key=lambda d: d["time"])}


def _refuse_what_cannot_be_followed(stage, path, file, action: str) -> tuple[list[float], list[dict]]:
    """The camera's keyed time codes (:func:`_keyed_time_codes`) and the samples a deleted key left
    (:func:`~physcam.usd.keyed_lens._left_samples`) after the refusals: not a camera (:func:`_refuse_not_a_camera`),
    samples check and refresh cannot follow (:func:`_refuse_samples_not_followed`)."""
    _refuse_not_a_camera(stage, path, file)
    times = _keyed_time_codes(stage, path)
    return times, _refuse_samples_not_followed(stage, path, file, action, times)


def _refuse_not_a_camera(stage, path, file) -> None:
    """ExportError naming the file when ``path`` holds no prim or one that is not a PhysicalCamera (checked before
    its attributes, whose time samples would be named otherwise)."""
    from pxr import Usd

    prim = stage.GetPrimAtPath(str(path))
    if not prim:
        raise ExportError(f"{file}: no prim at {path}")
    if not prim.IsA(Usd.SchemaRegistry.GetTypeFromSchemaTypeName("PhysicalCamera")):
        raise ExportError(f"{file}: {path} is a {prim.GetTypeName() or 'typeless prim'}, not a PhysicalCamera")


def refresh_shot(file, path: str | None = None) -> dict:
    """Recompute a shot's companion camera from the composed camera, in place, when it is stale; return
    check_shot's answer after, with ``written`` (whether the file was rewritten) and ``changed`` (each
    attribute of the camera whose value changed: ``attribute``, ``before``, ``after``; None for an
    attribute added or removed).

    A current camera (:func:`check_shot`) is left untouched: nothing is written, so a refresh that has
    nothing to do does not change the file (a pipeline diffs its USD files). A stale one is recomputed,
    and a recomputed value equal to the file's at the precision of the float32 values it is computed
    from (:func:`_same_value`; the companion's field of view, :func:`_same_view`) keeps the file's
    digits: reading the camera back through 32-bit attributes moves doubles by a few 1e-8, and
    :func:`~physcam.usd.author.fov_preserving_float32` may pick another float32 triple of one view.
    """
    from pxr import Sdf, Usd

    from .read import only_camera

    ensure_registered()
    from .read import open_stage

    open_stage(file)  # the same checks and messages as read and check
    layer = Sdf.Layer.FindOrOpen(str(file))
    stage = Usd.Stage.Open(layer)
    stage.Reload()  # the shot and its referenced files as they are on disk now
    if path is None:
        path = only_camera(stage, "refresh")  # its error names the file
    times, left = _refuse_what_cannot_be_followed(stage, path, file, "refresh")
    now = None  # no companion yet: write it
    if stage.GetPrimAtPath(Sdf.Path(path).AppendChild("Camera")):
        now = _checked(file, path, "refresh")
        if not now["stale"]:
            return dict(now, written=False, changed=[])
    _refuse_lens_not_stored(stage, path, file)
    layer = stage.GetRootLayer()
    changed = []
    if now is None or now["stored"] != now["current"]:  # the still camera (its default values) is stale
        before, root = _composed_values(stage, path), _authored_values(layer, path)
        notes = _companion_notes(stage, path)
        _author_shot_companion(stage, path, _still_time(stage, path, times))
        changed = _keep_equal_values(layer, before, _composed_values(stage, path), path, root)
        _keep_equal_notes(stage, path, notes)
    if times:  # a keyed lens: sample by sample
        changed += _author_samples(stage, path, file, times)
    changed += _remove_left_samples(stage, left)  # the refresh's own samples at a deleted key's time code
    save_stage(stage, file, force=True)
    return dict(check_shot(file, path), written=True, changed=changed)


def _refuse_lens_not_stored(stage, path, file) -> None:
    """ExportError when the camera was written from a real lens (its companion shows the lens's traced field,
    ``physcam:fieldOfView``) by a ``usd write --lens`` older than the stored lens (``<path>/Prescription``):
    a refresh would solve a thin lens in its place."""
    from pxr import Sdf

    geom = stage.GetPrimAtPath(Sdf.Path(str(path)).AppendChild("Camera"))
    if composed_prescription(stage, path) is not None or not geom or geom.GetCustomDataByKey("physcam:fieldOfView") is None:
        return
    model = stage.GetPrimAtPath(Sdf.Path(str(path)).AppendChild("Pinhole"))
    name = model.GetCustomDataByKey("physcam:lensName") if model else None
    raise ExportError(f"{file}: {path} was written from a real lens{f' ({name})' if name else ''} by a physcam "
                      f"that did not store it ({path}/Prescription is missing), so a refresh cannot solve it again: "
                      f"write it again with `physcam usd write {file} --lens NAME --focus ... --fstop ... --force`")


#: the companion's customData entries of numbers that a refresh recomputes (author_render_camera, usd write)
_COMPANION_NOTES = ("physcam:fieldOfView", "physcam:thinLensGap")


def _companion_notes(stage, path) -> dict:
    from pxr import Sdf

    geom = stage.GetPrimAtPath(Sdf.Path(path).AppendChild("Camera"))
    return {key: geom.GetCustomDataByKey(key) for key in _COMPANION_NOTES} if geom else {}


def _same_note(a, b) -> bool:
    """Whether two customData values (numbers, vectors, text, nested dicts) are equal at float32 precision."""
    if isinstance(a, dict) and isinstance(b, dict):
        return a.keys() == b.keys() and all(_same_note(a[n], b[n]) for n in a)
    return _same_value(a, b)


def _keep_equal_notes(stage, path, before: dict) -> None:
    """Give back the file's digits to each recomputed companion note equal to it (:func:`_same_note`): the
    fields of view a refresh recomputes from 32-bit attributes move in the 8th digit."""
    from pxr import Sdf

    geom = stage.GetPrimAtPath(Sdf.Path(path).AppendChild("Camera"))
    for key, old in before.items():
        if old is not None and _same_note(old, geom.GetCustomDataByKey(key)):
            geom.SetCustomDataByKey(key, old)


def _authored_values(layer, path) -> dict:
    """Attribute path -> its default value, of every attribute the layer authors at or below ``path``."""
    from pxr import Sdf

    out = {}

    def visit(p):
        if p.IsPropertyPath():
            spec = layer.GetAttributeAtPath(p)
            if spec and spec.HasDefaultValue():
                out[str(p)] = spec.default

    layer.Traverse(Sdf.Path(path), visit)
    return out


def _composed_values(stage, path) -> dict:
    """Attribute path -> its composed default value, of every attribute at or below ``path`` whose value comes
    from an authored default (in any layer: a shot's sublayers and references included)."""
    from pxr import Usd

    out = {}
    for prim in Usd.PrimRange(stage.GetPrimAtPath(str(path))):
        for a in prim.GetAttributes():
            if a.GetResolveInfo(Usd.TimeCode.Default()).GetSource() == Usd.ResolveInfoSourceDefault:
                out[str(a.GetPath())] = a.Get()
    return out


def _restore_root_default(layer, name: str, old) -> None:
    """Give the root layer back its default value ``old`` of the attribute ``name``; ``old`` None: the root layer
    had none (the value came from another layer), so the refresh's opinion goes, and its spec if nothing else
    is left on it."""
    spec = layer.GetAttributeAtPath(name)
    if not spec:
        return
    if old is not None:
        if spec.default != old:
            spec.default = old
    elif spec.HasDefaultValue():
        spec.ClearDefaultValue()
        layer.RemovePropertyIfHasOnlyRequiredFields(spec)


def _keep_equal_values(layer, before: dict, after: dict, path, root: dict) -> list[dict]:
    """Give back the file's value to every recomputed attribute equal to it (:func:`_same_value`,
    :func:`_same_view`; ``before`` and ``after`` the composed values, :func:`_composed_values`; ``root`` the root
    layer's before, :func:`_authored_values`, which a kept attribute is restored to); return the changes left, as
    the refresh reports them."""
    from pxr import Sdf

    geom = str(Sdf.Path(path).AppendChild("Camera"))
    keep = {n for n in after if n in before and _same_value(before[n], after[n])}
    if _same_view(before, after, geom):
        keep |= {f"{geom}.{n}" for n in ("focalLength", "horizontalAperture", "verticalAperture")}
    changed = []
    for name in sorted(set(before) | set(after)):
        if name in keep:
            _restore_root_default(layer, name, root.get(name))
            continue
        old, new = before.get(name), after.get(name)
        if old is None or new is None or old != new:
            changed.append({"attribute": name, "before": _shown_value(old), "after": _shown_value(new)})
    return changed


def _shot_attributes(spec, su):
    """CameraSpec field -> [(on the lens model?, attribute, USD type name, value)] a shot may override."""
    from pxr import Gf, Sdf

    F, F2, U = Sdf.ValueTypeNames.Float, Sdf.ValueTypeNames.Float2, Sdf.ValueTypeNames.UInt
    lp, sp = f"lens:{LENS_INSTANCE}:", f"sensor:{SENSOR_INSTANCE}:"
    return {
        "fstop": [(False, lp + "fStop", F, spec.fstop), (False, lp + "iris", F, spec.focal_length_mm / spec.fstop)],
        "focus_mm": [(True, "focusDistance", F, spec.focus_mm)],
        "transmittance": [(True, "transmittance", F, spec.transmittance)],
        "aperture_blades": [(False, lp + "shutterBlades", U, int(spec.aperture_blades))],
        "aperture_angle_deg": [(False, lp + "apertureAngle", F, spec.aperture_angle_deg)],
        "aperture_roundness": [(False, lp + "apertureRoundness", F, spec.aperture_roundness)],
        "aperture_density": [(False, lp + "apertureDensity", F, spec.aperture_density)],
        "clipping_mm": [(False, lp + "clippingRange", F2, Gf.Vec2f(su(spec.clipping_mm[0]), su(spec.clipping_mm[1])))],
        "shift_mm": [(False, sp + "shift", F2, Gf.Vec2f(*spec.shift_mm))],
        "iso": [(False, sp + "iso", F, spec.iso)],
        "coc_mm": [(False, sp + "circleOfConfusion", F, spec.coc_mm)],
        "shutter_open_s": [(False, "shutterOpen", F, spec.shutter_open_s)],
        "shutter_duration_s": [(False, "shutterDuration", F, spec.shutter_duration_s)],
        "shutter_opening": [(False, "shutterOpening", F2, Gf.Vec2f(*spec.shutter_opening))],
    }


def _author_overrides(stage, cam, spec, overrides) -> None:
    from pxr import UsdGeom

    from ..export.usdgeom import mm_to_scene_units

    mpu = UsdGeom.GetStageMetersPerUnit(stage)
    table = _shot_attributes(spec, lambda mm: mm_to_scene_units(mm, mpu))
    assert set(table) == set(SHOT_OVERRIDES)
    targets = cam.GetRelationship(f"lens:{LENS_INSTANCE}:lensModel").GetTargets()
    for field in overrides:
        for on_model, name, type_name, value in table[field]:
            if on_model:
                if not targets:
                    raise ExportError(f"{cam.GetPath()}: the lens has no lensModel to override {name} on")
                prim = stage.OverridePrim(targets[0])
            else:
                prim = cam
            attr = prim.GetAttribute(name) or prim.CreateAttribute(name, type_name)
            attr.Set(value)


def _author_placement(cam, spec, position, rotate_xyz_deg) -> None:
    from pxr import UsdGeom

    from ..export.usdgeom import mm_to_scene_units
    from .author import _eye_from_film, author_transform

    eye = mm_to_scene_units(_eye_from_film(spec, None), UsdGeom.GetStageMetersPerUnit(cam.GetStage()))
    author_transform(cam, position, rotate_xyz_deg, eye)


def _relpath(target, start) -> str:
    import os

    return os.path.relpath(target, start)


def write_previs_kit(file, setups: dict | None = None, *, default: str = "OverTheShoulder", force: bool = False,
                     path: str = "/PrevisKit", meters_per_unit: float = 0.01, fps: float = 24.0):
    """One file, one camera, a ``setup`` variant per entry of ``setups`` (default :data:`PREVIS_SETUPS`)."""
    setups = dict(PREVIS_SETUPS if setups is None else setups)
    if default not in setups:
        raise InputError(f"default setup {default!r} is not one of {', '.join(setups)}")
    stage = _stage(meters_per_unit, fps)
    prim = stage.DefinePrim(path, "PhysicalCamera")
    stage.SetDefaultPrim(stage.GetPrimAtPath(prim.GetPath().GetPrefixes()[0]))
    vset = prim.GetVariantSets().AddVariantSet("setup")
    from ..export.usdgeom import mm_to_scene_units

    for name, spec in setups.items():
        if not isinstance(name, str) or not name.isascii() or not name.replace("_", "").isalnum():
            raise InputError(f"setup name {printable_line(name, limit=60)!r} must be ASCII letters, digits and "
                             "underscores")
        vset.AddVariant(name)
        vset.SetVariantSelection(name)
        position, rotation = PREVIS_PLACEMENT.get(name, ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0)))
        with vset.GetVariantEditContext():
            author_camera(stage, path, spec, position=tuple(mm_to_scene_units(v, meters_per_unit) for v in position),
                          rotate_xyz_deg=rotation)
    vset.SetVariantSelection(default)
    return save_stage(stage, file, force=force)


def best_match_pinhole(prescription, *, focus_mm: float, fstop: float | None, sensor_width_mm: float,
                       sensor_height_mm: float, coc_mm: float = 0.03):
    """(CameraSpec, report of the real lens) for ``prescription`` focused at ``focus_mm``.

    The same camera ``physcam usd write --lens`` writes (:func:`physcam.usd.author.spec_from_report`
    of the lens report): the lens's EFL, principal planes and entrance pupil, and its
    best-match pinhole, the one definition physcam uses everywhere (docs/lens-report.md):
    a pinhole at the entrance pupil with focal length (exit pupil to film) / pupil
    magnification frames like the lens at this focus, breathing included. The companion
    UsdGeomCamera is that pinhole. f-stop None: the lens wide open, as the lens report decides.
    """
    from ..onset.report import report_camera, solve_report
    from ..optics.sensors import Sensor
    from .author import spec_from_report

    sensor = Sensor(key="custom", name=f"{sensor_width_mm:g} x {sensor_height_mm:g} mm",
                    width_mm=sensor_width_mm, height_mm=sensor_height_mm)
    report = solve_report(report_camera(focal_length_mm=None, sensor=sensor, fstop=fstop, focus_mm=focus_mm, coc=coc_mm,
                           lens=prescription))
    return spec_from_report(report), report


def prescription_distortion(prescription, sensor_width_mm: float = DEFAULT_SENSOR_WIDTH_MM,
                            sensor_height_mm: float = DEFAULT_SENSOR_HEIGHT_MM, *,
                            focus_mm: float = math.inf):
    """Hydra's "standard" lensDistortion fitted to ``prescription``'s real chief rays over the whole
    frame at the shot's focus ``focus_mm`` (:func:`physcam.analysis.distortion.models.fit_usd_standard`
    on a 2048-pixel-wide frame of the sensor, default Super 35, 24.89 x 18.66 mm). Where the lens
    does not cover the frame's corners, the radial fit of
    :mod:`physcam.analysis.distortion.field` (object at infinity, fields up to what passes) is used, with a warning.
    """
    import warnings

    from ..analysis.distortion.models import fit_usd_standard, samples_from_field
    from ..analysis.distortion.stmap import distortion_field
    from ..errors import OpticsError, PhysCamWarning
    from ..optics.state import camera_state

    w_px = 2048
    h_px = max(16, min(8192, round(w_px * sensor_height_mm / sensor_width_mm)))
    try:
        from ..optics.state import camera_state

        field = distortion_field(camera_state(prescription, focus_mm=focus_mm, sensor_mm=(sensor_width_mm,
                                                                                          sensor_height_mm)),
                                 width_px=w_px, height_px=h_px, maps=False)
    except OpticsError as e:
        from ..analysis.distortion.field import real_distortion

        warnings.warn(f"lensDistortion: {e}; fitted radially at infinity instead", PhysCamWarning, stacklevel=2)
        return real_distortion(prescription, sensor_width_mm=sensor_width_mm, sensor_height_mm=sensor_height_mm).fit
    fit = fit_usd_standard(samples_from_field(field))
    if not fit.acceptable:
        warnings.warn(f"lensDistortion: the standard model misses the traced rays by up to {fit.max_residual_px:.2g} px "
                      f"on a {w_px}-pixel-wide frame (written anyway; ST-maps are exact: physcam distortion --stmap"
                      + ("; an anamorphic's 3DE4 model is written beside it" if prescription.is_anamorphic else "") + ")",
                      PhysCamWarning, stacklevel=2)
    return fit


@takes_prescription
def prescription_anamorphic_distortion(prescription, sensor_width_mm: float, sensor_height_mm: float, *,
                                       focus_mm: float = math.inf) -> list:
    """3DE4 Anamorphic - Standard, Degree 4 and 6 (:func:`physcam.analysis.distortion.anamorphic.fit_tde4_anamorphic`)
    fitted to an anamorphic ``prescription``'s traced chief rays over the whole frame at ``focus_mm``, on the
    2048-pixel-wide frame :func:`prescription_distortion` traces; ``[]`` for a spherical lens, and, with a
    warning, for one whose field does not cover the frame (its corners are not imaged)."""
    import warnings

    if not prescription.is_anamorphic:
        return []
    from ..analysis.distortion.anamorphic import fit_tde4_anamorphic
    from ..analysis.distortion.models import samples_from_field
    from ..analysis.distortion.stmap import distortion_field
    from ..errors import OpticsError, PhysCamWarning
    from ..optics.state import camera_state

    w_px = 2048
    h_px = max(16, min(8192, round(w_px * sensor_height_mm / sensor_width_mm)))
    try:
        camera = camera_state(prescription, focus_mm=focus_mm, sensor_mm=(sensor_width_mm, sensor_height_mm))
        field = distortion_field(camera, width_px=w_px, height_px=h_px, maps=False)
    except OpticsError as e:
        warnings.warn(f"3DE4 anamorphic distortion not written: {e}", PhysCamWarning, stacklevel=2)
        return []
    samples = samples_from_field(field)
    return [fit_tde4_anamorphic(samples, degree) for degree in (4, 6)]


def prescription_opencv(prescription, sensor_width_mm: float, sensor_height_mm: float, *, focus_mm: float,
                        resolution=None):
    """The OpenCV pinhole + distortion fitted to ``prescription`` at ``focus_mm`` on this sensor
    (:func:`physcam.export.opencv_distortion.fit_opencv_pinhole`), for Omniverse's distortion API.
    ``resolution``: (W,) or (W, H) pixels; default 4096 wide, H from the sensor's aspect."""
    from ..export.opencv_distortion import fit_opencv_pinhole

    w_px = 4096 if not resolution else int(resolution[0])
    h_px = int(resolution[1]) if resolution and len(resolution) > 1 else max(16, round(w_px * sensor_height_mm /
                                                                                        sensor_width_mm))
    return fit_opencv_pinhole(prescription, sensor_width_mm, sensor_height_mm, w_px, h_px,
                              focus_mm=focus_mm)


def write_vendor_lens(file, prescription, *, focus_mm: float, fstop: float | None = None,
                      sensor_width_mm: float = DEFAULT_SENSOR_WIDTH_MM, sensor_height_mm: float = DEFAULT_SENSOR_HEIGHT_MM,
                      coc_mm: float = 0.03,
                      use: str = "pinhole", force: bool = False, meters_per_unit: float = 0.01, fps: float = 24.0):
    """A vendor lens file: ``/Lens`` with a Prescription model, its best-match Pinhole, and a ``lensModel`` variant.

    The file holds **lens opinions only** (the lens API and the two lens models): no body, no
    sensor, no transform and no companion camera, so a shot that references it beside a body
    file (:func:`write_shot`) keeps the body's sensor, ISO, flange and placement, and computes
    the companion camera and the lens distortion for that body's sensor. ``sensor_width_mm``
    and ``sensor_height_mm`` only choose the sensor of the lens report the pinhole is solved
    with (the best-match pinhole itself does not depend on the sensor; default Super 35, 24.89 x 18.66 mm,
    :data:`physcam.data.default_sensor.DEFAULT_SENSOR`).

    ``use`` ("pinhole" or "prescription") is the default variant: it sets the lens's
    ``lensModel`` relationship, i.e. which model renders.
    """
    from pxr import Sdf

    if use not in ("pinhole", "prescription"):
        raise InputError(f"use must be pinhole or prescription, got {use!r}")
    spec, _report = best_match_pinhole(prescription, focus_mm=focus_mm, fstop=fstop,
                                       sensor_width_mm=sensor_width_mm, sensor_height_mm=sensor_height_mm,
                                       coc_mm=coc_mm)
    stage = _stage(meters_per_unit, fps)
    cam = author_camera(stage, LENS_PRIM, spec, parts=("lens",))
    rx_prim = author_prescription(stage, Sdf.Path(LENS_PRIM).AppendChild("Prescription"), prescription, focus_mm)
    pin = stage.GetPrimAtPath(Sdf.Path(LENS_PRIM).AppendChild("Pinhole"))
    rel_name = f"lens:{LENS_INSTANCE}:lensModel"
    cam.GetRelationship(rel_name).ClearTargets(True)  # the variant decides
    vset = cam.GetVariantSets().AddVariantSet("lensModel")
    for name, target in (("pinhole", pin.GetPath()), ("prescription", rx_prim.GetPath())):
        vset.AddVariant(name)
        vset.SetVariantSelection(name)
        with vset.GetVariantEditContext():
            cam.GetRelationship(rel_name).SetTargets([target])
    vset.SetVariantSelection(use)
    return save_stage(stage, file, force=force)


# ------------------------------------------------------------------ characterization variants (issue 18)
#: Namespace of the measured data a characterization variant holds on ``/Lens`` (docs/characterize.md).
CHARACTERIZATION_NS = "physcam:characterization:"


def _variant_identifier(name) -> str:
    import re

    require_type("variant name", name, str, "letters, digits and underscores, e.g. run_20260301T080000Z_3fa2c1")
    if not re.fullmatch(r"[A-Za-z_][A-Za-z0-9_]{0,127}", name) or name == "current":
        raise InputError(f"a characterization variant name is letters, digits and underscores, starting with a "
                         f"letter, and not 'current'; got {name!r}")
    return name


def _open_detached(file):
    """A stage on an anonymous copy of ``file``'s layer: edits stay in memory until saved, and no
    layer this process (or USD's registry) holds open for ``file`` is touched or reused."""
    from pxr import Sdf, Usd

    layer = Sdf.Layer.OpenAsAnonymous(str(file))
    if layer is None:
        raise ExportError(f"{file}: USD cannot open it")
    return Usd.Stage.Open(layer)


def _author_measured(prim, measured: dict) -> None:
    """``measured`` name -> finite numbers (double[]), texts (string[]) or one text (string)."""
    from pxr import Sdf

    T = Sdf.ValueTypeNames
    for name, values in measured.items():
        if isinstance(values, str):
            prim.CreateAttribute(CHARACTERIZATION_NS + name, T.String, True).Set(values)
            continue
        values = list(values)
        if all(isinstance(v, str) for v in values) and values:
            prim.CreateAttribute(CHARACTERIZATION_NS + name, T.StringArray, True).Set(values)
            continue
        nums = []
        for v in values:
            if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
                raise InputError(f"measured value {name!r} must be finite numbers or texts, got {v!r}")
            nums.append(float(v))
        prim.CreateAttribute(CHARACTERIZATION_NS + name, T.DoubleArray, True).Set(nums)


def add_characterization(file, variant: str, spec: CameraSpec, measured: dict, *, meters_per_unit: float = 0.01,
                         fps: float = 24.0):
    """Add variant ``variant`` to the ``characterization`` set of the lens file ``file`` and make ``current``
    a copy of it ("Interesting Looking Models": new values become a variant, current is set to the latest).

    The file is created (as :func:`write_lens_file` lays it out) when missing. Inside the variant:
    the lens of ``spec`` (lens API and model, as :func:`write_lens_file` writes it) and, on ``/Lens``,
    the custom attributes ``physcam:characterization:NAME`` of ``measured`` (NAME -> finite numbers
    (double[]), texts (string[]) or one text (string); file names are texts, relative to the lens
    file, not asset paths: USD's validator resolves asset paths and the files may move with the
    library). Earlier variants are not touched; ``current`` is rewritten and stays
    selected; ``customData physcam:currentIs`` names ``variant``. A variant of that name already in
    the file is an :class:`ExportError`. Returns the Path.
    """
    from pathlib import Path

    require_type("lens file", file, (str, Path), "a .usda/.usdc path")
    variant = _variant_identifier(variant)
    require_type("spec", spec, CameraSpec, "the lens's CameraSpec (best_match_pinhole)")
    require_type("measured", measured, dict, "name -> list of numbers or texts")
    for name in measured:
        if not isinstance(name, str) or not name.replace("_", "").isalnum():
            raise InputError(f"a measured value's name is letters, digits and underscores, got {name!r}")
    ensure_registered()
    p = Path(file)
    if p.exists():
        stage = _open_detached(p)
        prim = stage.GetPrimAtPath(LENS_PRIM)
        if not prim or prim.GetTypeName() != "PhysicalCamera":
            raise ExportError(f"{p}: has no PhysicalCamera {LENS_PRIM} (not a physcam lens file)")
    else:
        stage = _stage(meters_per_unit, fps)
        prim = stage.DefinePrim(LENS_PRIM, "PhysicalCamera")
        stage.SetDefaultPrim(prim)
    vset = prim.GetVariantSets().AddVariantSet("characterization")
    if variant in vset.GetVariantNames():
        raise ExportError(f"{p}: already has a characterization variant {variant!r}; earlier variants are kept as "
                          "they are")
    layer = stage.GetRootLayer()
    if "current" in vset.GetVariantNames():  # the old copy goes; the new one is a copy of the new variant
        vs_spec = layer.GetPrimAtPath(LENS_PRIM).variantSets.get("characterization")
        if vs_spec is not None and "current" in vs_spec.variants:
            vs_spec.RemoveVariant(vs_spec.variants["current"])
    for name in (variant, "current"):
        vset.AddVariant(name)
        vset.SetVariantSelection(name)
        with vset.GetVariantEditContext():
            author_camera(stage, LENS_PRIM, spec, parts=("lens",))
            _author_measured(stage.GetPrimAtPath(LENS_PRIM), measured)
    vset.SetVariantSelection("current")
    prim.SetCustomDataByKey("physcam:currentIs", variant)
    return save_stage(stage, p, force=True)


def read_characterizations(file) -> dict:
    """The characterization variants of a lens file: ``{"current_is": name, "selection": name, "variants":
    {name: {measured name: value}}}`` (``current`` included), read from a detached copy of the file."""
    from pathlib import Path

    require_type("lens file", file, (str, Path), "a .usda/.usdc path")
    ensure_registered()
    if not Path(file).is_file():
        raise ExportError(f"{file}: no such lens file")
    stage = _open_detached(file)
    prim = stage.GetPrimAtPath(LENS_PRIM)
    if not prim:
        raise ExportError(f"{file}: has no {LENS_PRIM} prim (not a physcam lens file)")
    vset = prim.GetVariantSets().GetVariantSet("characterization")
    names = list(vset.GetVariantNames()) if prim.GetVariantSets().HasVariantSet("characterization") else []
    selection = vset.GetVariantSelection() if names else None
    out = {}
    for name in names:
        vset.SetVariantSelection(name)
        vals = {}
        for attr in prim.GetAttributes():
            if attr.GetName().startswith(CHARACTERIZATION_NS) and attr.HasAuthoredValue():
                v = attr.Get()
                if hasattr(v, "__len__") and not isinstance(v, str):
                    v = list(v)
                vals[attr.GetName()[len(CHARACTERIZATION_NS):]] = v
        out[name] = vals
    return {"current_is": prim.GetCustomDataByKey("physcam:currentIs"), "selection": selection, "variants": out}


def characterization_target(file, variant: str) -> dict:
    """Check, before a characterization is measured, that variant ``variant`` can be added to the lens
    file ``file`` (:func:`add_characterization`'s rules: the name, a physcam lens file or none yet, a new
    variant); return ``{"exists": bool, "focal_length_mm": float | None}``: the lens's focal length as
    the file composes it now (its lens model's ``focalLength``, a prescription's effective focal
    length; None without a file or a lens model), for checking that a measurement is of this lens."""
    from pathlib import Path

    require_type("lens file", file, (str, Path), "a .usda/.usdc path")
    variant = _variant_identifier(variant)
    p = Path(file)
    usd_layer_format(p, what="a lens file's name")
    if not p.exists():
        if not p.parent.is_dir():
            raise ExportError(f"{p}: its folder {p.parent} does not exist")
        return {"exists": False, "focal_length_mm": None}
    if variant in read_characterizations(p)["variants"]:
        raise ExportError(f"{p}: already has a characterization variant {variant!r}: give another --variant")
    ensure_registered()
    stage = _open_detached(p)  # held: a prim outlives no stage
    prim = stage.GetPrimAtPath(LENS_PRIM)
    if not prim or prim.GetTypeName() != "PhysicalCamera":
        raise ExportError(f"{p}: has no PhysicalCamera {LENS_PRIM} (not a physcam lens file)")
    rel = prim.GetRelationship(f"lens:{LENS_INSTANCE}:lensModel")
    targets = rel.GetForwardedTargets() if rel else []
    model = stage.GetPrimAtPath(targets[0]) if targets else None
    focal = None
    if model and model.GetTypeName() == "PhysicalCameraLensModelPrescription":
        from ..optics.paraxial import gaussian
        from .read import read_prescription

        focal = float(gaussian(read_prescription(model)).efl)
    elif model and model.GetAttribute("focalLength") and model.GetAttribute("focalLength").HasAuthoredValue():
        focal = float(model.GetAttribute("focalLength").Get())
    return {"exists": True, "focal_length_mm": focal}


__all__ += ["add_characterization", "read_characterizations", "characterization_target", "CHARACTERIZATION_NS"]

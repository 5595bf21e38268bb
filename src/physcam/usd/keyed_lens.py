"""A keyed lens (a focus pull, an f-stop ramp: time samples of the Pinhole's ``focusDistance``, the lens's ``fStop``,
a thin lens's ``focalLength``) as ``usd check`` and ``usd refresh`` follow it (:func:`physcam.usd.kit.check_shot`):
its time codes, the lens solved at each (:mod:`physcam.usd.solved_lens`), the derived samples compared and
rewritten there, and the samples they refuse to follow. Lengths in mm (docs/usd.md).
"""

from __future__ import annotations

from ..errors import ExportError
from .author import LENS_INSTANCE
from .float32_values import _same_value, _same_view, _shown_value
from .read import composed_prescription
from .solved_lens import _LENS_DERIVED, _lens_derived_values, _lens_model, _lens_solved


def time_code_text(t: float) -> str:
    """A USD time code as text that names it exactly: an integral one as an integer (``1234567``), another as
    the shortest decimal that reads back to the same double (``123456.5``), never rounded to a neighbour."""
    t = float(t)
    return str(int(t)) if t.is_integer() else repr(t)


def _keyed_inputs(stage, cam) -> list:
    """The attributes an animation keys: the lens model's focus, the lens's f-stop, and the model's focal length
    unless the lens is stored (a prescription's focal length at the focus is derived, :func:`_sampled_derived`:
    the refresh's own samples of it are not keys)."""
    model = _lens_model(stage, cam)
    attrs = [cam.GetAttribute(f"lens:{LENS_INSTANCE}:fStop")]
    if model is not None:
        attrs.append(model.GetAttribute("focusDistance"))
        if composed_prescription(stage, str(cam.GetPath())) is None:
            attrs.append(model.GetAttribute("focalLength"))
    return [a for a in attrs if a]


def _keyed_time_codes(stage, path) -> list[float]:
    """The time codes of the camera at ``path``'s keyed lens (every time sample of its focus distance,
    f-stop and focal length), in order; [] for a still lens (a camera that only moves included)."""
    cam = stage.GetPrimAtPath(str(path))
    if not cam:
        raise ExportError(f"no prim at {path}")
    return sorted({float(t) for a in _keyed_inputs(stage, cam) for t in a.GetTimeSamples()})


def _has_default_lens(stage, cam) -> bool:
    """Whether every keyed input also has an authored default value (the still camera a check hashes)."""
    from pxr import Usd

    return all(a.GetResolveInfo(Usd.TimeCode.Default()).GetSource() == Usd.ResolveInfoSourceDefault
               for a in _keyed_inputs(stage, cam))


def _still_time(stage, path, times) -> float | None:
    """The time code whose values the still part of the camera at ``path`` (what its companion's default values
    and inputs hash are computed from) is read at: None (the default values) for a still lens or a keyed one
    with default values; the first of ``times`` for keys with no default value (a DCC export's samples only),
    so a change to the camera's other inputs (ISO, shutter, clipping range) is still seen."""
    if not times or _has_default_lens(stage, stage.GetPrimAtPath(str(path))):
        return None
    return times[0]


def _sampled_derived(stage, path, time: float) -> dict:
    """Attribute path -> the value a refresh authors at time code ``time`` of an animated camera: the lens
    values a stored prescription gives there (the pinhole model's ``focalLength`` the EFL), the iris, and
    the companion's :data:`~physcam.usd.author.SAMPLED_RENDER_ATTRIBUTES` (``usd animate``'s per frame)."""
    from pxr import Sdf, UsdGeom

    from .author import iris_mm, sampled_render_values

    spec, _rx, report, derived = _lens_solved(stage, path, time)
    cam = stage.GetPrimAtPath(path)
    out = {}
    if derived is not None:
        out.update({f"{path}.{n}": v for n, v in _lens_derived_values(derived).items()})
        model = _lens_model(stage, cam)
        if model is not None and model.GetTypeName() == "PhysicalCameraLensModelPinhole":
            out[f"{model.GetPath()}.focalLength"] = float(derived.focal_length_mm)
    out[f"{path}.lens:{LENS_INSTANCE}:iris"] = iris_mm(spec)
    body_iris = cam.GetAttribute("iris")  # the body's own, used only when no lens is applied (the schema): kept in
    if body_iris and body_iris.GetNumTimeSamples():  # step where usd animate keys it, else left as it is (still)
        out[f"{path}.iris"] = iris_mm(spec)
    stage_ = cam.GetStage()
    values, _eye = sampled_render_values(spec, report, UsdGeom.GetStageMetersPerUnit(stage_),
                                         stage_.GetTimeCodesPerSecond(), where=path)
    geom = Sdf.Path(path).AppendChild("Camera")
    out.update({f"{geom}.{n}": v for n, v in values.items()})
    return out


def _samples_solved(stage, path, file, action: str, times) -> dict:
    """Time code -> :func:`_sampled_derived` for each of ``times``; an ExportError naming the file, the camera
    and the time code of a sample whose lens cannot be solved (a focus inside the lens's close focus, ...)."""
    from ..errors import PhysCamError

    out = {}
    for t in times:
        try:
            out[t] = _sampled_derived(stage, path, t)
        except PhysCamError as e:
            raise ExportError(f"{file}: {path} at time code {time_code_text(t)}: {e}; usd {action} cannot solve this sample") \
                from None
    return out


def _derived_names(stage, path) -> set:
    """The attribute paths :func:`_sampled_derived` gives values of (some may be left out for a lens without
    them: a second pupil, an unknown stop)."""
    from pxr import Sdf

    from .author import SAMPLED_RENDER_ATTRIBUTES

    cam = stage.GetPrimAtPath(str(path))
    out = {f"{path}.lens:{LENS_INSTANCE}:iris", f"{path}.iris"}
    out |= {f"{Sdf.Path(path).AppendChild('Camera')}.{n}" for n in SAMPLED_RENDER_ATTRIBUTES}
    if composed_prescription(stage, path) is not None:
        out |= {f"{path}.{n}" for n in _LENS_DERIVED}
        model = _lens_model(stage, cam)
        if model is not None:
            out.add(f"{model.GetPath()}.focalLength")
    return out


def _refuse_samples_not_followed(stage, path, file, action: str, times) -> list[dict]:
    """ExportError naming the file and a time-sampled attribute of the camera at ``path`` (or of its children) that
    check and refresh cannot follow, still lens or keyed (``times``, :func:`_keyed_time_codes`): one that is neither
    a keyed input, a thin lens's pupil or stop read at each keyed time code, a layout's move (the camera's
    ``xformOp:*``), nor one the refresh derives (:func:`_derived_names`); a derived one keyed at a time code where
    the lens is not, unless that time code holds exactly the refresh's own samples (:func:`_left_samples`, which
    are returned); and a lens
    solved from a real lens the file does not store (``usd animate --lens`` samples its pupils and pinhole but
    keeps no prescription to solve them again)."""
    cam = stage.GetPrimAtPath(str(path))
    keyed = {str(a.GetPath()) for a in _keyed_inputs(stage, cam)}
    derived = _derived_names(stage, path)
    lp = f"lens:{LENS_INSTANCE}:"
    stored = composed_prescription(stage, path) is not None
    read_at_time = set() if stored or not times else {f"{path}.{lp}entrancePupilDistance", f"{path}.{lp}apertureDistance"}
    left = _left_samples(stage, path, file, action, times, derived | read_at_time, derived)
    left_times = {d["time"] for d in left}
    attrs = [a for prim in (cam, *cam.GetChildren()) for a in prim.GetAttributes()]
    for a in sorted(attrs, key=lambda a: str(a.GetPath()) in derived):  # a hand key on another attribute named first
        name = str(a.GetPath())
        if not a.GetNumTimeSamples() or name in keyed | read_at_time:
            continue
        if a.GetPrim() == cam and a.GetName().startswith("xformOp"):
            continue  # the layout's move: not an input of the lens
        if name in derived:
            _refuse_unkeyed_samples(a, file, action, [*times, *left_times])
            continue
        if times and not stored and a.GetName() in _LENS_DERIVED:
            raise ExportError(f"{file}: {name} is animated from a real lens that the file does not store "
                              f"(usd animate --lens): usd {action} cannot solve it again; write the animation "
                              f"again with `physcam usd animate {file} --marks CSV ... --force`")
        n = a.GetNumTimeSamples()
        raise ExportError(f"{file}: {name} is animated ({n} time sample{'s' * (n != 1)}): usd {action} "
                          "follows a keyed focus, f-stop and focal length sample by sample, not this attribute")
    return left


def _samples_at(cam) -> dict:
    """Time code -> the attribute paths of the camera ``cam`` and its children (its lens model, its companion)
    holding a time sample there, the camera's own ``xformOp:*`` (the layout's move) left out."""
    out: dict = {}
    for prim in (cam, *cam.GetChildren()):
        for a in prim.GetAttributes():
            if prim == cam and a.GetName().startswith("xformOp"):
                continue
            for t in a.GetTimeSamples():
                out.setdefault(float(t), set()).add(str(a.GetPath()))
    return out


def _left_samples(stage, path, file, action: str, times, written, derived) -> list[dict]:
    """``[{"time", "attributes", "left": True}]`` of each time code no lens input is keyed at whose samples are
    the ones usd animate or the refresh wrote at a key of this camera: of the attributes of ``written`` (the
    derived ones, a thin lens's pupils) sampled at its keyed ``times``, every ``derived`` one (what a refresh
    writes at a key the artist added) and no other attribute (with or without usd animate's pupils: the
    samples a deleted key left; a set with one more attribute, or without one the refresh derives, is an
    artist's, refused by the caller). An
    ExportError naming the layer when one of them is authored in a layer weaker than the file's root layer
    (a sublayer, a referenced file): the refresh writes only the root layer."""
    if not times:
        return []
    from pxr import Sdf

    at = _samples_at(stage.GetPrimAtPath(str(path)))
    keyed_set = set().union(*(at.get(t, set()) for t in times)) & written
    root = stage.GetRootLayer()
    out = []
    for t in sorted(set(at) - set(times)):
        if not keyed_set or not (keyed_set & derived) <= at[t] <= keyed_set:
            continue
        for name in sorted(at[t]):
            layer = _sample_layer(stage.GetAttributeAtPath(Sdf.Path(name)), t)
            if layer is not None and layer != root:
                tc = time_code_text(t)
                raise ExportError(f"{file}: {name} holds a sample at time code {tc}, left from a deleted key, in "
                                  f"{layer.identifier}: usd refresh writes only {root.identifier}; remove the "
                                  f"samples at time code {tc} in that layer (or key the lens there) and run it again")
        out.append({"time": t, "attributes": sorted(at[t]), "left": True})
    return out


def _sample_layer(attr, t: float):
    """The layer whose time samples ``attr`` composes (the strongest spec holding any), or None."""
    for spec in attr.GetPropertyStack():
        if spec.layer.GetNumTimeSamplesForPath(spec.path):
            return spec.layer if t in spec.layer.ListTimeSamplesForPath(spec.path) else None
    return None


def _remove_left_samples(stage, left) -> list[dict]:
    """Remove, in the root layer, the samples of ``left`` (:func:`_left_samples`); return the removals as the
    refresh reports its changes (``after`` None), each with its ``time``."""
    from pxr import Sdf

    changed = []
    for d in left:
        for name in d["attributes"]:
            attr = stage.GetAttributeAtPath(Sdf.Path(name))
            before = attr.Get(d["time"])
            attr.ClearAtTime(d["time"])
            changed.append({"attribute": name, "time": d["time"], "before": _shown_value(before), "after": None})
    return changed


def _refuse_unkeyed_samples(attr, file, action: str, times) -> None:
    """ExportError naming a derived attribute keyed at a time code where the lens is not, ``times`` the lens's and
    those whose samples a deleted key left (:func:`_left_samples`): an artist's key, which the refresh does not
    delete."""
    unkeyed = sorted(set(map(float, attr.GetTimeSamples())) - set(times))
    if unkeyed:
        t = time_code_text(unkeyed[0])
        raise ExportError(f"{file}: {attr.GetPath()} is keyed at time code {t}, where the lens's focus, f-stop and "
                          f"focal length are not: usd {action} deletes no hand keys; remove the samples at time code {t} "
                          "(or key the lens there) and run it again")


def _stale_samples(stage, path, expected: dict) -> list[dict]:
    """``[{"time", "attributes"}]`` of each time code where an attribute of ``expected`` (time code ->
    :func:`_sampled_derived`) differs from the file at float32 precision (the companion's field of view:
    :func:`_same_view`), each with ``left`` False; a derived sample at a time code no input is keyed at is
    refused before or is a deleted key's (:func:`_refuse_samples_not_followed`)."""
    from pxr import Sdf

    geom = str(Sdf.Path(path).AppendChild("Camera"))
    out = []
    for t, values in expected.items():
        now = {n: stage.GetAttributeAtPath(Sdf.Path(n)).Get(t) for n in values}
        bad = [n for n in sorted(values) if now[n] is None or not _same_value(now[n], values[n])]
        if _same_view(now, values, geom):
            bad = [n for n in bad if n not in {f"{geom}.{v}" for v in ("focalLength", "horizontalAperture",
                                                                       "verticalAperture")}]
        if bad:
            out.append({"time": t, "attributes": bad, "left": False})
    return sorted(out, key=lambda d: d["time"])


def _author_samples(stage, path, file, times) -> list[dict]:
    """Rewrite, at every keyed time code, each derived attribute stale at one of them (:func:`_stale_samples`;
    an attribute that is sampled at all is sampled at every keyed time code; it has none at other time codes,
    :func:`_refuse_samples_not_followed`); a sample equal to the recomputed value at float32 precision keeps the file's digits. Returns the
    changes as the refresh reports them, each with its ``time``."""
    from pxr import Sdf

    expected = _samples_solved(stage, path, file, "refresh", times)
    names = {n for d in _stale_samples(stage, path, expected) for n in d["attributes"]}
    # a derived attribute that is sampled is sampled at every keyed time code: at a key the artist added, also
    # where its value between the old keys happens to be right (else the key, deleted later, would leave a
    # partial set of refresh's samples, which a refresh refuses as hand keys: _left_samples)
    for n in {n for t in times for n in expected[t]} - names:
        attr = stage.GetAttributeAtPath(Sdf.Path(n))
        samples = set(attr.GetTimeSamples()) if attr else set()
        if samples and not samples >= set(times):
            names.add(n)
    geom = str(Sdf.Path(path).AppendChild("Camera"))
    view = {f"{geom}.{v}" for v in ("focalLength", "horizontalAperture", "verticalAperture")}
    names = sorted(names | view if names & view else names)  # one field of view: its three values together
    attrs = {n: stage.GetAttributeAtPath(Sdf.Path(n)) for n in names}
    had = {n: {float(t) for t in a.GetTimeSamples()} for n, a in attrs.items()}
    olds = {t: {n: a.Get(t) for n, a in attrs.items()} for t in times}  # all read before any is written
    kept = {}
    for t in times:
        old = olds[t]
        keep = {n for n in names if t in had[n] and _same_value(old[n], expected[t].get(n))}
        if view <= attrs.keys() and all(t in had[n] for n in view) and _same_view(old, expected[t], geom):
            keep |= view
        kept[t] = keep | {n for n in names if expected[t].get(n) is None}
    # samples in the layer refresh writes replace a weaker layer's (a sublayer's) whole set of an attribute:
    # where that layer holds none of an attribute yet, every keyed time code is written there, the kept ones
    # with the value they compose to now
    layer = stage.GetEditTarget().GetLayer()
    whole = {n for n in names if any(n not in kept[t] for t in times)
             and not layer.ListTimeSamplesForPath(Sdf.Path(n))}
    changed = []
    for t in times:
        for n in names:
            if n in kept[t]:
                if n in whole and olds[t][n] is not None:
                    attrs[n].Set(olds[t][n], t)
                continue
            old, new = olds[t][n], expected[t][n]
            attrs[n].Set(new, t)
            if old is None or not _same_value(old, new):
                changed.append({"attribute": n, "time": t, "before": _shown_value(old), "after": _shown_value(new)})
    return sorted(changed, key=lambda c: (c["attribute"], c["time"]))

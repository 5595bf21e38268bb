"""Animated cameras: focus pulls and iris pulls as USD time samples, breathing included.

A focus puller's marks per frame (a CSV, or a list of :class:`FocusKey`) become time samples on
one camera. At every frame the lens is solved again at that mark (and f-stop): for a prescription
its Gaussian optics focused there (unit or internal focusing, :mod:`physcam.optics.focusing`),
for a thin lens the practical model. What changes with focus is time-sampled:

* the lens model's ``focusDistance`` and ``focalLength`` (the EFL: it changes with internal
  focusing), the lens's ``fStop``, ``iris``, ``entrancePupilDistance``, ``pinholeFocalLength``,
  ``pinholeSqueeze`` (an anamorphic's squeeze breathes too), principal planes and ``apertureDistance``
  (the stop moves with unit focusing);
* the companion UsdGeomCamera's ``focalLength`` (the best-match pinhole: breathing), apertures
  (float32 values that keep the field of view exact), ``fStop``, ``focusDistance`` and its
  translate: the eye follows the entrance pupil while the body, and so the film plane, stays
  where it was placed (the body's ``translate:pupilToFilm`` is the first frame's pupil).

A zoom lens (docs/zoom.md) is taken at each key's zoom position (a ``zoom`` column: a focal length
with its unit, ``135mm``, or the encoder value 0..1; else the ``zoom`` argument, else its first
tabulated position) and focused there, so a zoom over the take ramps the same attributes: the EFL and
the companion camera's ``focalLength``, the entrance pupil, and, with the iris wide open (no f-stop
given), the f-number as the stop's size and the pupil change along the zoom. The zoom encoder is
time-sampled too, as the custom attribute ``physcam:zoomEncoder`` on the camera (0..1, 0 the first
tabulated position).

Frames are USD time codes; the stage's timeCodesPerSecond is the frame rate. Each key is one
frame: USD interpolates linearly between samples, which breathing is not, so give a mark per
frame (the CSV of a focus-pull recording is). Lengths in mm (docs/conventions.md).
"""

from __future__ import annotations

import contextlib
import warnings
from dataclasses import dataclass, field
from pathlib import Path

from ..errors import ExportError, InputError, LensFileError, PhysCamError, PhysCamWarning, require_finite, require_positive
from ..lens.zoom import prescription_at

__all__ = ["FocusKey", "read_focus_marks", "write_animated_camera", "ntsc_rate"]

#: The camera prim's time-sampled zoom encoder of a zoom lens (module notes).
ZOOM_ENCODER_ATTR = "physcam:zoomEncoder"

#: The most frames one animated camera holds (a 10-minute take at 48 fps), bounded before any work.
MAX_FRAMES = 28_800


@dataclass(frozen=True)
class FocusKey:
    """One frame: its number, the focus mark from the film plane (mm), an f-stop (None: unchanged) and a
    zoom lens's position (a focal length ``"135mm"`` or an encoder value 0..1; None: unchanged); ``source``
    and ``line``: where :func:`read_focus_marks` read it, named by an error about its values (not compared)."""

    frame: float
    focus_mm: float
    fstop: float | None = None
    zoom: str | float | None = None
    source: str | None = field(default=None, compare=False)
    line: int | None = field(default=None, compare=False)


@contextlib.contextmanager
def _from_key(k: FocusKey):
    """An error about ``k``'s values (an f-stop the lens does not open to, a zoom outside its range) named by
    the file and line the key was read from, where it was read from one (``physcam usd animate``'s CSV)."""
    try:
        yield
    except LensFileError:
        raise
    except PhysCamError as exc:
        if k.source is None:
            raise
        raise LensFileError(str(exc), k.source, k.line) from None


def read_focus_marks(path) -> list[FocusKey]:
    """Keys from a CSV with columns ``frame``, ``focus`` (a distance with units, ``5m``, ``16ft``; bare
    numbers are mm) and optionally ``fstop`` (an iris pull) and ``zoom`` (a zoom lens's position:
    ``135mm`` or an encoder value 0..1). Errors name the file and line."""
    import csv

    from ..units import parse_distance

    p = Path(path)
    try:
        text = p.read_text(encoding="utf-8-sig")
    except OSError as exc:
        raise LensFileError(f"cannot read the focus marks: {exc.strerror or exc}", str(p)) from None
    rows = csv.DictReader(text.splitlines())
    cols = set(rows.fieldnames or ())
    if not {"frame", "focus"} <= cols:
        raise LensFileError("the focus-mark CSV needs 'frame' and 'focus' columns (and optionally 'fstop', 'zoom')",
                            str(p), 1)
    unknown = cols - {"frame", "focus", "fstop", "zoom"}
    if unknown:
        raise LensFileError(f"unknown columns {sorted(unknown)}; use frame, focus, fstop, zoom", str(p), 1)
    keys = []
    for line, row in enumerate(rows, start=2):
        if row.get("frame") is None or row.get("focus") is None:
            raise LensFileError(f"this row has fewer values than the header's {len(rows.fieldnames)} columns", str(p),
                                line)
        try:
            frame = require_finite("frame", float(row["frame"]))
            focus = parse_distance(row["focus"], name="focus mark")
            fstop = None if not (row.get("fstop") or "").strip() else require_positive("f-stop", float(row["fstop"]),
                                                                                        unit="")
            if keys and frame <= keys[-1].frame:
                raise InputError(f"frame {frame:g} does not follow frame {keys[-1].frame:g}: frames must increase")
        except (ValueError, TypeError, InputError) as exc:
            raise LensFileError(str(exc) if isinstance(exc, InputError) else f"not a number: {exc}", str(p), line) \
                from None
        zoom = (row.get("zoom") or "").strip() or None
        keys.append(FocusKey(frame, focus, fstop, zoom, source=str(p), line=line))
        if len(keys) > MAX_FRAMES:
            raise LensFileError(f"more than {MAX_FRAMES} frames in one camera", str(p), line)
    if not keys:
        raise LensFileError("no focus marks", str(p))
    return keys


def _check_keys(keys) -> list[FocusKey]:
    from ..errors import WrongTypeError

    if isinstance(keys, (str, bytes)) or not hasattr(keys, "__iter__"):
        raise WrongTypeError("keys must be a list of FocusKey (physcam.usd.animate.read_focus_marks)")
    keys = list(keys)
    if not all(isinstance(k, FocusKey) for k in keys):
        raise WrongTypeError("keys must be a list of FocusKey (physcam.usd.animate.read_focus_marks)")
    if not keys:
        raise InputError("give at least one focus mark")
    if len(keys) > MAX_FRAMES:
        raise InputError(f"at most {MAX_FRAMES} frames in one camera, got {len(keys)}")
    frames = [k.frame for k in keys]
    if any(b <= a for a, b in zip(frames, frames[1:])):
        raise InputError("frames must increase from one key to the next")
    return keys


def ntsc_rate(fps) -> float:
    """``fps`` as the stage's timeCodesPerSecond: an NTSC rate given to two or three decimals (23.976 or
    23.98, 29.97, 59.94, 119.88: :func:`physcam.frame_rates.exact_frame_rate`) is the exact N x 1000/1001
    (24000/1001 = 23.976023...), as a recording of a
    stream at that rate writes it (:func:`physcam.live.frames.rate_fraction`), so the two line up frame
    for frame; other rates are kept as given."""
    from ..frame_rates import exact_frame_rate

    rate = require_finite("frames per second", fps)
    if rate <= 0:
        raise InputError(f"frames per second must be > 0, got {rate:g}")
    fr = exact_frame_rate(rate)
    return fr.numerator / fr.denominator if fr.denominator == 1001 else rate


def write_animated_camera(file, keys, *, sensor, lens=None, focal_length_mm: float | None = None,
                          fstop: float | None = None, coc=None, path: str = "/Cameras/Camera",
                          meters_per_unit: float = 0.01, fps: float = 24.0, shutter_angle_deg: float = 180.0,
                          position=(0.0, 0.0, 0.0), rotate_xyz_deg=(0.0, 0.0, 0.0), force: bool = False,
                          zoom=None):
    """Write a camera whose focus (and iris, and a zoom lens's zoom) follow ``keys``, one time sample per
    key; return the Path.

    ``lens`` (a Prescription) or ``focal_length_mm`` (a thin lens); ``sensor`` a
    :class:`~physcam.optics.sensors.Sensor`; ``fstop`` for keys without their own (with a
    prescription and no f-stop at all: wide open); ``zoom`` a zoom lens's position for keys without
    their own (module notes).
    """
    from pxr import Sdf, UsdGeom

    from ..export.usdgeom import require_meters_per_unit
    from ..onset.report import report_camera, solve_report
    from .author import author_camera, iris_mm, new_stage, sample_render_camera, save_stage, spec_from_report

    keys = _check_keys(keys)
    if (lens is None) == (focal_length_mm is None):
        raise InputError("give either a lens prescription or a focal length")
    if not 0.0 < require_finite("shutter angle", shutter_angle_deg) <= 360.0:
        raise InputError(f"shutter angle must be in (0, 360] degrees, got {shutter_angle_deg:g}")
    mpu = require_meters_per_unit(meters_per_unit)
    rate = ntsc_rate(fps)

    zooms = _zoom_encoders(keys, lens, zoom)
    frames = []
    seen_notes: set[str] = set()
    for k, u in zip(keys, zooms):
        with warnings.catch_warnings(record=True) as caught, _from_key(k):
            warnings.simplefilter("always", PhysCamWarning)
            report = solve_report(report_camera(focal_length_mm=focal_length_mm, sensor=sensor,
                                                 fstop=k.fstop if k.fstop is not None else fstop, focus_mm=k.focus_mm,
                                                 coc=coc, lens=lens if u is None else prescription_at(lens, u)))
        for w in caught:  # say each approximation once, not once per frame
            if str(w.message) not in seen_notes:
                seen_notes.add(str(w.message))
                warnings.warn(str(w.message), PhysCamWarning, stacklevel=2)
        spec = spec_from_report(report, shutter_duration_s=shutter_angle_deg / 360.0 / rate)
        frames.append((k.frame, report, spec))

    stage = new_stage(mpu, rate)
    stage.SetStartTimeCode(keys[0].frame)
    stage.SetEndTimeCode(keys[-1].frame)
    _, report0, spec0 = frames[0]
    cam = author_camera(stage, path, spec0, report=report0, position=position, rotate_xyz_deg=rotate_xyz_deg)
    model = stage.GetPrimAtPath(Sdf.Path(path).AppendChild("Pinhole"))
    geom = UsdGeom.Camera(stage.GetPrimAtPath(Sdf.Path(path).AppendChild("Camera")))
    lp = "lens:main:"

    def sample(prim, name, value, time):
        attr = prim.GetAttribute(name)
        if not attr:
            raise ExportError(f"{prim.GetPath()}.{name} was not authored on the first frame")
        attr.Set(value, time)

    for frame, report, spec in frames:
        t = float(frame)
        eye = spec.entrance_pupil_mm
        sample(model, "focalLength", spec.focal_length_mm, t)
        sample(model, "focusDistance", spec.focus_mm, t)
        for prim, name, value in ((cam, lp + "fStop", spec.fstop), (cam, lp + "iris", iris_mm(spec)),
                                  (cam, "iris", iris_mm(spec)),
                                  (cam, lp + "entrancePupilDistance", eye)):
            sample(prim, name, value, t)
        optional = {lp + "pinholeFocalLength": spec.pinhole_focal_length_mm, lp + "pinholeSqueeze":
                    spec.pinhole_squeeze, lp + "apertureDistance":
                    spec.aperture_distance_mm, lp + "horizontalEntrancePupilDistance": spec.horizontal_entrance_pupil_mm}
        if spec.principal_planes_mm is not None:
            optional[lp + "frontPrincipalPlaneDistance"] = spec.principal_planes_mm[0]
            optional[lp + "rearPrincipalPlaneDistance"] = spec.principal_planes_mm[1]
        for name, value in optional.items():
            if value is not None and cam.GetAttribute(name):
                sample(cam, name, value, t)
        sample_render_camera(geom, spec, report, mpu, rate, t, where=path)
    if zooms[0] is not None:
        attr = cam.CreateAttribute(ZOOM_ENCODER_ATTR, Sdf.ValueTypeNames.Double, custom=True)
        attr.SetDocumentation("the zoom lens's position: physcam's normalised zoom encoder, 0 the first tabulated "
                              "position, 1 the last (docs/zoom.md)")
        for (frame, _, _), u in zip(frames, zooms):
            attr.Set(float(u), float(frame))
    return save_stage(stage, file, force=force)


def _zoom_encoders(keys, lens, zoom) -> list:
    """Each key's zoom encoder value on a zoom ``lens`` (its own, else the last key's, else ``zoom``,
    else the first tabulated position); Nones for any other lens, which refuses a zoom position."""
    if lens is None or lens.zoom is None:
        if zoom is not None or any(k.zoom is not None for k in keys):
            raise InputError("a zoom position needs a zoom lens (a prescription with a zoom table, docs/zoom.md)")
        return [None] * len(keys)
    from ..optics.zoom import zoom_encoder

    out, held = [], zoom_encoder(lens, 0.0 if zoom is None else zoom)
    for k in keys:
        if k.zoom is not None:
            with _from_key(k):
                held = zoom_encoder(lens, k.zoom)
        out.append(held)
    return out

"""A recorded stream as a time-sampled USD camera and a per-frame lens report.

Each :class:`~physcam.live.frames.TrackedFrame` is solved as an on-set lens report
(:func:`physcam.onset.report.solve_lens_report`, the practical model with the streamed entrance
pupil and best-match pinhole) and written as one USD time sample through physcam's own authoring
(:func:`physcam.usd.author.author_camera` for the first frame, then the companion's
:func:`physcam.usd.author.sampled_render_values` per frame, as :mod:`physcam.usd.animate` does for
a focus pull); the take's samples go into the layer in one ``Sdf.ChangeBlock`` at the end
(:class:`_TimeSamples`: the same file, byte for byte, as a ``Usd.Attribute.Set`` per sample):

* the PhysicalCamera body's transform: ``translate`` (where the entrance pupil is),
  ``rotateZXY`` = (tilt, pan, -roll) and ``translate:pupilToFilm``, so the film plane lands where
  the tracker put the sensor. The stage is Y-up: OpenTrackIO's Z-up stage (x, y, z) is USD's
  (x, z, -y), which turns its intrinsic pan-tilt-roll into USD's ``rotateZXY`` op exactly, and a
  camera at zero rotation looks along the stage's +Y (OpenTrackIO) = USD's -Z, a USD camera's own
  view direction;
* the lens: ``fStop``, ``iris``, ``entrancePupilDistance``, ``pinholeFocalLength``, the lens model's
  ``focalLength`` and ``focusDistance`` (mm, from the film plane); an anamorphic's horizontal pupil
  (``physcam:horizontalEntrancePupilOffset`` in the stream, or the named lens's) as
  ``horizontalEntrancePupilDistance``, at the eye for a frame with one pupil;
* the companion UsdGeomCamera: ``focalLength`` (the best-match pinhole), apertures, ``fStop``,
  ``focusDistance`` (from the pupil), ``exposure:fStop`` (the T-stop) and its eye on the pupil;
* the anamorphic squeeze and lens shift: ``physcam:live:anamorphicSqueeze`` (the lens model's
  ``squeeze`` too), ``physcam:live:projectionOffset`` and ``physcam:live:distortionOffset``
  (OpenLensIO's ΔP and ΔC, mm, x right, y down, as streamed), and the PhysicalCamera's
  ``sensor:main:shift`` / the companion's aperture offsets (physcam's shift, + right, + up:
  (-ΔPx, ΔPy));
* distortion: the streamed Brown-Conrady coefficients as custom attributes on the PhysicalCamera
  (``physcam:live:distortion*``, OpenTrackIO's millimetre form) and, on the companion, Omniverse's
  ``OmniLensDistortionOpenCvPinholeAPI`` (OpenCV's normalised form, :mod:`physcam.live.lens_data`);
* ``physcam:live:sequenceNumber``, ``physcam:live:timecode`` and ``physcam:live:sourceId`` say which
  sample each time came from; ``physcam:live:carriedOver`` names the values that sample left out and
  took from an earlier sample of the same source, ``physcam:live:defaulted`` those taken from the
  command line (:func:`solve_frames`; the camera's customData ``physcam:live:carryOver`` says so).

Times: a sample's time code is (its timestamp - the first's) x the stage's timeCodesPerSecond (the
stream's sample rate), computed with exact fractions; samples without timestamps use their
sequence numbers. Each source keeps its own time line (:func:`solve_frames`); a recording writes
one source (:mod:`physcam.live.take`), and :func:`absent_frames` counts the frames its line lacks.
The file is written once, atomically, when the recording ends.

The focal length that drives depth of field is the lens's nominal focal length when the stream's
static data gives one, else the pinhole focal length (a thin lens focused at D frames with s', a
few per cent more than f at portrait distances; the report says which it used).
"""

from __future__ import annotations

import csv
import io
import json
import math
import warnings
from dataclasses import dataclass
from fractions import Fraction

from ..errors import ExportError, InputError, PhysCamError, PhysCamWarning, require_finite, require_type
from .frames import HORIZONTAL_PUPIL_KEY, TrackedFrame
from .lens_data import opentrackio_to_opencv

__all__ = ["MAX_RECORDED_FRAMES", "SolvedFrame", "solve_frames", "frame_problem", "time_codes", "time_line",
           "absent_frames",
           "write_recording_usd", "lens_report_rows", "write_lens_report", "CARRIED_VALUES"]

#: the most frames one recording keeps (ten minutes at 240 fps)
MAX_RECORDED_FRAMES = 144_000
REPORT_COLUMNS = ("frame", "time_code", "timecode", "sequence_number", "focus_from_film_mm",
                  "pinhole_focal_length_mm", "dof_focal_length_mm", "fstop", "tstop", "entrance_pupil_from_film_mm",
                  "near_from_film_mm", "far_from_film_mm", "hyperfocal_from_film_mm", "hfov_deg", "vfov_deg",
                  "dfov_deg", "coc_mm", "x_m", "y_m", "z_m", "pan_deg", "tilt_deg", "roll_deg", "source_id",
                  "carried_over", "defaulted", "squeeze", "projection_offset_x_mm", "projection_offset_y_mm",
                  "focus_from_pupil_mm", "from_encoders", "entrance_pupil_horizontal_from_film_mm")


@dataclass(frozen=True)
class SolvedFrame:
    """A tracked frame, its USD time code and its lens report; ``carried``: the OpenTrackIO values the
    frame left out and took from an earlier sample of the same source; ``defaulted``: those it took
    from the caller's defaults (the command line) because its source never sent them."""

    frame: TrackedFrame
    time_code: float
    report: object
    carried: tuple[str, ...] = ()
    defaulted: tuple[str, ...] = ()
    #: the values this frame's lens encoders gave through the FIZ table (OpenTrackIO names)
    from_encoders: tuple[str, ...] = ()
    #: (anamorphic squeeze, projection offset mm (x right, y down), distortion offset mm) it used
    squeeze: float = 1.0
    projection_offset_mm: tuple[float, float] = (0.0, 0.0)
    distortion_offset_mm: tuple[float, float] = (0.0, 0.0)
    #: an anamorphic's horizontal (X) entrance pupil in front of the film (mm), the pan pivot, streamed
    #: (:data:`physcam.live.frames.HORIZONTAL_PUPIL_KEY`) or from the named lens; None: one pupil
    entrance_pupil_horizontal_mm: float | None = None


#: the values a frame may leave out: (key, OpenTrackIO name, TrackedFrame attribute)
CARRIED_VALUES = (("pinhole", "pinholeFocalLength", "pinhole_focal_length_mm"), ("fstop", "fStop", "fstop"),
                  ("focus", "focusDistance", "focus_from_film_mm"), ("tstop", "tStop", "tstop"),
                  ("pupil", "entrancePupilOffset", "entrance_pupil_mm"),
                  ("sensor", "activeSensorPhysicalDimensions", "sensor_mm"),
                  ("nominal", "nominalFocalLength", "nominal_focal_length_mm"),
                  ("squeeze", "anamorphicSqueeze", "squeeze"), ("projection", "projectionOffset", "projection_offset_mm"),
                  ("distortion_offset", "distortionOffset", "distortion_offset_mm"),
                  ("pupil_x", HORIZONTAL_PUPIL_KEY, "entrance_pupil_horizontal_mm"))
CARRY_OVER_NOTE = ("a value a sample leaves out is carried over from the latest earlier sample of the same source "
                   "(sourceId, sourceNumber), never from another source; physcam:live:carriedOver names them per "
                   "time sample, physcam:live:defaulted those given on the command line")
#: the largest values a recorded frame may hold: lengths 1000 km (mm), positions 1000 km (m), a
#: million degrees; USD keeps the lens and rotations as 32-bit floats, far above these
MAX_LENGTH_MM = 1e9
MAX_POSITION_M = 1e6
MAX_ANGLE_DEG = 1e6
_FLOAT32_MAX = 3.4028234663852886e38


def frame_problem(frame: TrackedFrame, pinhole_mm=None) -> str | None:
    """Why ``frame`` cannot be recorded (a value beyond the limits above, a distortion whose
    normalised OpenCV form overflows a 32-bit float), or None."""
    require_type("frame", frame, TrackedFrame, "physcam.live.frames.frame_from_sample(sample)")
    if pinhole_mm is not None:
        pinhole_mm = require_finite("pinhole focal length", pinhole_mm)
    lengths = (("pinholeFocalLength", frame.pinhole_focal_length_mm), ("focusDistance", frame.focus_from_film_mm),
               ("entrancePupilOffset", frame.entrance_pupil_mm), ("nominalFocalLength", frame.nominal_focal_length_mm),
               (HORIZONTAL_PUPIL_KEY, frame.entrance_pupil_horizontal_mm))
    lengths += tuple(("activeSensorPhysicalDimensions", v) for v in (frame.sensor_mm or ()))
    for name, v in lengths:
        if v is not None and not abs(v) <= MAX_LENGTH_MM:
            return f"{name} {v:g} mm is beyond {MAX_LENGTH_MM / 1e6:g} km"
    for v in frame.translation_m:
        if not abs(v) <= MAX_POSITION_M:
            return f"a translation of {v:g} m is beyond {MAX_POSITION_M / 1e3:g} km from the stage origin"
    for v in frame.rotation_deg:
        if not abs(v) <= MAX_ANGLE_DEG:
            return f"a rotation of {v:g} degrees is beyond {MAX_ANGLE_DEG:g} degrees"
    if frame.distortion is not None and pinhole_mm is not None:
        try:
            cv = opentrackio_to_opencv(frame.distortion, pinhole_mm)
        except InputError:
            return None  # a model OpenCV's form cannot express: the companion camera gets none
        if any(not abs(v) <= _FLOAT32_MAX for v in cv.values()):
            return "the distortion's OpenCV coefficients overflow a 32-bit float"
    return None


def _frames(frames) -> list[TrackedFrame]:
    if isinstance(frames, (str, bytes)) or not hasattr(frames, "__iter__"):
        from ..errors import WrongTypeError

        raise WrongTypeError("frames must be a list of TrackedFrame (physcam.live.frames.frame_from_sample)")
    frames = list(frames)
    for f in frames:
        require_type("frame", f, TrackedFrame, "physcam.live.frames.frame_from_sample(sample)")
    if not frames:
        raise InputError("no frames were recorded")
    if len(frames) > MAX_RECORDED_FRAMES:
        raise InputError(f"at most {MAX_RECORDED_FRAMES} frames in one recording, got {len(frames)}")
    return frames


def time_codes(frames, rate=None) -> tuple[list[float], Fraction]:
    """(USD time code of each frame, time codes per second): from timestamps when every frame has one,
    else from sequence numbers, else frame order; ``rate`` overrides the stream's sample rate."""
    from .frames import rate_fraction

    frames = _frames(frames)
    fr = rate_fraction(rate) if rate is not None else next((f.rate for f in frames if f.rate is not None), None)
    if fr is None:
        raise InputError("the stream gives no sample rate; give the frame rate (--fps)")
    if all(f.time_ns is not None for f in frames):
        t0 = int(frames[0].time_ns)
        # integer-nanosecond stamps of a rational rate land within 1e-6 of a frame: snap to 1e-6
        # (dt / 1e9 s) * fr in integers: Python's int / int is correctly rounded, as float(Fraction) is,
        # without a Fraction made per frame
        q = fr if isinstance(fr, Fraction) else Fraction(fr)  # a rate given as a float: its exact value
        num, den = q.numerator, 1_000_000_000 * q.denominator
        codes = [round((int(f.time_ns) - t0) * num / den, 6) for f in frames]
    elif all(f.sequence_number is not None for f in frames):
        s0 = frames[0].sequence_number
        codes = [float(f.sequence_number - s0) for f in frames]
    else:
        codes = [float(i) for i in range(len(frames))]
    return codes, fr


def _nearest(n: int, num: int, den: int) -> int:
    """round(n * num / den) in integers (den > 0), ties to even as round(Fraction) does: a frame's place
    from its timestamp without a Fraction made per frame."""
    q, r = divmod(n * num, den)
    return q + (2 * r > den or (2 * r == den and q % 2 == 1))


def absent_frames(frames, rate=None) -> int:
    """How many frames of one source's time line, between the first and the last of ``frames``, the
    frames do not hold: a frame lasts 1 / rate s, ``rate`` the stream's sample rate (``sampleRate``;
    else the ``rate`` given). Each frame's place on the line is, in this order of preference, its
    ``sampleTimestamp`` (rounded to the nearest frame), its timecode (:func:`~physcam.live.frames.timecode_index`,
    drop-frame counted), its ``sequenceNumber``; frames with none of them count nothing (0).

    A gap of g frame periods between two neighbours holds g - 1 absent frames, whatever took them
    (never sent, lost on the network, refused): 18 absent frames are 18, in one gap or several.
    """
    from .frames import rate_fraction, timecode_index

    frames = _frames(frames)
    fr = next((f.rate for f in frames if f.rate is not None), None)
    fr = rate_fraction(rate) if fr is None and rate is not None else fr
    if fr is not None and all(f.time_ns is not None for f in frames):
        t0 = int(frames[0].time_ns)
        q = fr if isinstance(fr, Fraction) else Fraction(fr)
        num, den = q.numerator, 1_000_000_000 * q.denominator
        places = {_nearest(int(f.time_ns) - t0, num, den) for f in frames}
    elif fr is not None and all(f.timecode is not None for f in frames):
        places = {timecode_index(f.timecode, fr, f.drop_frame) for f in frames}
    elif all(f.sequence_number is not None for f in frames):
        places = {f.sequence_number for f in frames}
    else:
        return 0
    return max(places) - min(places) + 1 - len(places)


def time_line(frames, codes) -> set[int]:
    """The indexes of the frames on their sources' time lines: per source (``sourceId``,
    ``sourceNumber``), the longest run of its frames, in arrival order, whose time codes increase
    (the first of equal ones kept; of runs equally long, the one whose time codes stay lowest). One
    frame a day ahead is left out, not the frames after it; a clock that goes back is followed where
    more frames follow it. Longest increasing subsequence by
    patience sorting, O(n log n) (Knuth, TAOCP vol. 3, 5.1.4; Fredman 1975)."""
    import bisect

    frames = [] if isinstance(frames, (list, tuple)) and not frames else _frames(frames)
    if isinstance(codes, (str, bytes)) or not hasattr(codes, "__len__") or len(codes) != len(frames):
        raise InputError("codes must be a list of time codes, one per frame (time_codes(frames))")
    per_source: dict = {}
    for i, f in enumerate(frames):
        per_source.setdefault(f.source, []).append(i)
    keep: set[int] = set()
    for idx in per_source.values():
        tails, tail_at, before = [], [], {}
        for i in idx:
            k = bisect.bisect_left(tails, codes[i])
            if k < len(tails) and tails[k] == codes[i]:
                continue  # an equal time code: the first one stays
            before[i] = tail_at[k - 1] if k else None
            if k == len(tails):
                tails.append(codes[i])
                tail_at.append(i)
            else:
                tails[k], tail_at[k] = codes[i], i
        i = tail_at[-1] if tail_at else None
        while i is not None:
            keep.add(i)
            i = before[i]
    return keep


def solve_frames(frames, *, sensor=None, rate=None, focal_length_mm=None, fstop=None, focus_mm=None,
                 coc=None, refused: list | None = None, lens=None, fiz=None) -> list[SolvedFrame]:
    """Each frame with its time code and lens report (module notes).

    Values a frame does not carry come from the latest earlier frame **of the same source** (its
    ``sourceId`` and ``sourceNumber``), else from these defaults: ``sensor`` (a
    :class:`~physcam.optics.sensors.Sensor`) when the stream's static data gives no sensor size,
    ``focal_length_mm`` (pinhole), ``fstop``, ``focus_mm`` (from the film plane); each
    :class:`SolvedFrame` names them (``carried``, ``defaulted``). Each source keeps its own time line
    (:func:`time_line`): a frame off it (a time code that goes back, or one far ahead that the
    frames after it do not follow) is dropped with a warning; another source's clock, a day ahead or
    behind, never drops a frame.

    ``fiz`` (a :class:`~physcam.live.fiz.FizTable`) turns a frame's ``lens.encoders`` into the focus
    mark, f-stop and focal length it does not send itself (``from_encoders`` names them); ``lens`` (a
    :class:`~physcam.lens.prescription.Prescription`) solves a frame that sends no pinhole focal
    length through the named lens at its focus: breathing pinhole, entrance pupil and squeeze from
    the prescription, as ``physcam lens breathing`` computes them (a zoom lens at the frame's
    ``lens.encoders.zoom``, else its first tabulated position). The anamorphic squeeze
    (``static.camera.anamorphicSqueeze``) widens the horizontal field: F / squeeze is the horizontal
    focal length.

    A frame that cannot be solved (a value out of range, :func:`frame_problem`, or one its source
    never gave) raises, unless ``refused`` is a list: then it is left out, ``(index, reason)`` is
    appended there, and its values are not carried over to later frames.
    """
    from ..optics.sensors import Sensor, custom_sensor

    frames = _frames(frames)
    if sensor is not None:
        require_type("sensor", sensor, Sensor, "physcam.optics.sensors.find_sensor(name)")
    if refused is not None and not isinstance(refused, list):
        raise InputError(f"refused must be a list to append the refused frames to, got {type(refused).__name__}")
    codes, _ = time_codes(frames, rate)
    defaults = {"pinhole": focal_length_mm, "fstop": fstop, "focus": focus_mm, "tstop": None, "pupil": None,
                "sensor": None if sensor is None else (sensor.width_mm, sensor.height_mm), "nominal": None,
                "squeeze": None, "projection": None, "distortion_offset": None, "pupil_x": None}
    if lens is not None:
        from ..lens.prescription import Prescription

        require_type("lens", lens, Prescription, "physcam.lens.library.load_lens(name)")
    if fiz is not None:
        from .fiz import FizTable

        require_type("fiz", fiz, FizTable, "physcam.live.fiz.read_fiz_table(file)")
    held: dict = {}  # per source: the values its frames sent, the latest of each
    sensors: dict = {}
    out: list[SolvedFrame] = []
    on_line = time_line(frames, codes)
    skipped = 0
    for i, (f, t) in enumerate(zip(frames, codes)):
        mine = held.setdefault(f.source, {})
        sent = {key: getattr(f, attr) for key, _, attr in CARRIED_VALUES if getattr(f, attr) is not None}
        try:
            encoded = _from_encoders(f, fiz, sent)
        except PhysCamError as exc:
            if refused is None:
                raise type(exc)(f"frame {i}: {exc}") from None
            refused.append((i, f"frame {i}: {exc}"))
            continue
        sent.update(encoded)
        if i not in on_line:
            skipped += 1
            mine.update(sent)
            continue
        last, carried, defaulted = dict(defaults), [], []
        for key, name, _ in CARRIED_VALUES:
            if key in sent:
                last[key] = sent[key]
            elif key in mine:
                last[key] = mine[key]
                carried.append(name)
            elif defaults[key] is not None:
                defaulted.append(name)
        try:
            report = _solve_one(f, last, sensor, sensors, coc, custom_sensor, lens)
        except PhysCamError as exc:
            where = f"frame {i} (timecode {f.timecode})" if f.timecode else f"frame {i}"
            if refused is None:
                raise type(exc)(f"{where}: {exc}") from None
            refused.append((i, f"{where}: {exc}"))
            continue
        mine.update(sent)
        names = dict((k, n) for k, n, _ in CARRIED_VALUES)
        out.append(SolvedFrame(f, t, report, tuple(carried), tuple(defaulted),
                               tuple(names[k] for k in encoded), float(report.pinhole[1]),
                               tuple(last["projection"] or (0.0, 0.0)), tuple(last["distortion_offset"] or (0.0, 0.0)),
                               _pupil_x(report, last)))
    if skipped:
        warnings.warn(f"{skipped} samples lay off their source's time line (a time code going back, or ahead of "
                      "the frames after it) and were left out", PhysCamWarning, stacklevel=2)
    return out


def _pupil_x(report, last) -> float | None:
    """The frame's horizontal pupil: the named lens's when the report was solved through it (its
    vertical pupil is then the lens's too), else the streamed one (carried over like the others)."""
    if report.entrance_pupil_horizontal_from_film_mm is not None:
        return float(report.entrance_pupil_horizontal_from_film_mm)
    return None if last["pupil_x"] is None else float(last["pupil_x"])


def _from_encoders(f, fiz, sent) -> dict:
    """The values frame ``f``'s encoders give through the FIZ table ``fiz`` that it does not send."""
    if fiz is None or not f.encoders:
        return {}
    out = {}
    enc = f.encoders
    if "focus" in enc and "focus" not in sent and fiz.has("focus"):
        mark = fiz.focus_mm(enc["focus"])
        if not math.isfinite(mark):
            raise InputError("the focus encoder reads infinity; physcam records a focus mark in front of the film")
        out["focus"] = mark
    if "iris" in enc and "fstop" not in sent and fiz.has("iris"):
        out["fstop"] = fiz.fstop(enc["iris"])
    if "zoom" in enc and "nominal" not in sent and fiz.has("zoom"):
        out["nominal"] = fiz.focal_length_mm(enc["zoom"])
    return out


def _solve_one(f, last, sensor, sensors, coc, custom_sensor, lens=None):
    """The lens report of frame ``f`` with the values ``last`` (its own, carried over or defaults);
    with ``lens`` and no streamed pinhole, the prescription's at the frame's focus."""
    from ..onset.report import report_camera, solve_report

    need_pinhole = lens is None or last["pinhole"] is not None
    missing = [n for n, k in (("a pinhole focal length (pinholeFocalLength, --focal, --lens)", "pinhole"),
                              ("an f-stop (fStop, --fstop)", "fstop"),
                              ("a focus distance (focusDistance, --focus)", "focus"),
                              ("a sensor size (static.camera.activeSensorPhysicalDimensions, --sensor)", "sensor"))
               if last[k] is None and (k != "pinhole" or need_pinhole)]
    if missing:
        raise InputError(f"the stream does not give {', '.join(missing)}; give it on the command line")
    problem = frame_problem(f, None if last["pinhole"] is None else float(last["pinhole"]))
    if problem:
        raise InputError(problem)
    key = tuple(last["sensor"])
    if key not in sensors:
        sensors[key] = sensor if sensor is not None and (sensor.width_mm, sensor.height_mm) == key \
            else custom_sensor(*key)
    tstop = last["tstop"]
    if tstop is not None and tstop < last["fstop"]:
        tstop = None  # a T-stop faster than the f-stop is not physical; the report would refuse it
    if last["pinhole"] is None:  # the named lens at this focus: its breathing, pupil and squeeze
        lens = _at_zoom_encoder(lens, f.encoders)
        return solve_report(report_camera(focal_length_mm=None, sensor=sensors[key], fstop=float(last["fstop"]),
                                          focus_mm=float(last["focus"]), coc=coc, tstop=tstop, lens=lens))
    pin = float(last["pinhole"])
    sq = 1.0 if last["squeeze"] is None else float(last["squeeze"])
    f_dof = float(last["nominal"]) if last["nominal"] is not None else pin
    return solve_report(report_camera(focal_length_mm=f_dof, sensor=sensors[key], fstop=float(last["fstop"]),
                         focus_mm=float(last["focus"]), coc=coc, tstop=tstop,
                         pupil_mm=None if last["pupil"] is None else float(last["pupil"]),
                         pinhole_focal_length_mm=pin, squeeze=sq, pinhole_squeeze=sq))


def _at_zoom_encoder(lens, encoders):
    """A zoom lens at the frame's OpenTrackIO zoom encoder (0 wide, 1 tele), else at its first
    tabulated position; any other lens as it is (docs/zoom.md)."""
    if getattr(lens, "zoom", None) is None:
        return lens
    from ..lens.zoom import prescription_at
    from .camera import physcam_zoom

    z = (encoders or {}).get("zoom")
    return prescription_at(lens, 0.0 if z is None else physcam_zoom(lens, z))


def _usd_from_stage(v, mpu):
    """OpenTrackIO stage metres (x, y, z; Z-up) as USD scene units on a Y-up stage: (x, z, -y)."""
    return (v[0] / mpu, v[2] / mpu, -v[1] / mpu)


def write_recording_usd(file, solved, *, rate=None, meters_per_unit: float = 0.01, path: str = "/Cameras/Camera",
                        resolution=(4096, None), force: bool = False):
    """Write the solved frames (:func:`solve_frames`) as one time-sampled camera (module notes); return the Path."""
    return _write_recording(file, solved, rate=rate, meters_per_unit=meters_per_unit, path=path,
                            resolution=resolution, force=force, batch=True)


class _TimeSamples:
    """A take's time samples, per attribute, written into the stage's root layer at the end in one
    ``Sdf.ChangeBlock`` (``Sdf.Layer.SetTimeSample``: the layer casts each value to its attribute's
    type, as ``Usd.Attribute.Set`` does). Round 13: about 25 ``Usd.Attribute.Set`` calls a frame,
    each a change notice of its own, took 14 s of CPU for 10,000 frames (docs/performance.md). An
    attribute without a spec in the layer yet (a schema's, first sampled) gets it from
    ``Usd.Attribute.Set`` at once, so specs are made as and in the order they were before.
    ``batch=False`` sets each sample through USD at once: the writer as it was."""

    def __init__(self, stage, batch: bool = True):
        self.layer, self.batch = stage.GetRootLayer(), batch
        self.samples: dict = {}  # id of the attribute object -> (attribute, [(time, value)])

    def set(self, attr, value, time) -> None:
        """``attr.Set(value, time)``, gathered (the writer passes the same attribute objects each frame)."""
        held = self.samples.get(id(attr))
        if held is not None:
            held[1].append((time, value))
        elif not self.batch or not self.layer.GetAttributeAtPath(attr.GetPath()):
            attr.Set(value, time)  # (no spec yet: made here, in its turn)
            if self.batch:
                self.samples[id(attr)] = (attr, [])
        else:
            self.samples[id(attr)] = (attr, [(time, value)])

    def write(self) -> None:
        from pxr import Sdf

        paths = [(attr.GetPath(), samples) for attr, samples in self.samples.values()]
        with Sdf.ChangeBlock():
            for path, samples in paths:
                for time, value in samples:
                    self.layer.SetTimeSample(path, time, value)
        self.samples.clear()


def _write_recording(file, solved, *, rate, meters_per_unit, path, resolution, force, batch):
    """:func:`write_recording_usd`, its samples written in one batch or each through USD (:class:`_TimeSamples`)."""
    from .. import usd as _usd  # noqa: F401  (one line naming the 'usd' extra when usd-core is missing)
    from pxr import Sdf

    from ..export.usdgeom import require_meters_per_unit
    from ..usd.author import author_camera, new_stage, save_stage, spec_from_report

    if isinstance(solved, (str, bytes)) or not hasattr(solved, "__iter__"):
        from ..errors import WrongTypeError

        raise WrongTypeError("solved must be a list of SolvedFrame (physcam.live.record.solve_frames)")
    solved = list(solved)
    for s in solved:
        require_type("solved frame", s, SolvedFrame, "physcam.live.record.solve_frames(frames)")
    if not solved:
        raise InputError("no frames to write")
    _, fr = time_codes([s.frame for s in solved], rate)
    tcps = float(fr)
    if tcps > 1000.0:  # new_stage's bound; record at a lower rate would misplace samples
        raise InputError(f"the stream's sample rate {tcps:g} fps is above USD stage rates physcam writes (1000)")
    mpu = require_meters_per_unit(meters_per_unit)
    shutter = 0.5 / tcps

    stage = new_stage(mpu, tcps, up_axis="Y")
    stage.SetStartTimeCode(solved[0].time_code)
    stage.SetEndTimeCode(solved[-1].time_code)
    s0 = solved[0]
    spec0 = spec_from_report(s0.report, shutter_duration_s=shutter, shift_mm=_shift(s0))
    cam = author_camera(stage, path, spec0, report=s0.report)
    cam.SetCustomDataByKey("physcam:source", "OpenTrackIO stream recorded by physcam live record")
    cam.SetCustomDataByKey("physcam:live:carryOver", CARRY_OVER_NOTE)
    samples = _TimeSamples(stage, batch)
    _sample_frames(stage, cam, Sdf.Path(path), solved, samples, mpu, tcps, shutter, resolution)
    samples.write()
    return save_stage(stage, file, force=force)


def _sample_frames(stage, cam, path, solved, samples, mpu, tcps, shutter, resolution):
    """Every frame's time samples of the recording's camera ``cam`` (module notes) into ``samples``."""
    import numpy as np
    from pxr import Gf, Sdf, UsdGeom, Vt

    from ..export.usdgeom import mm_to_scene_units
    from ..usd.author import iris_mm, sampled_render_values, spec_from_report
    from .frames import rotation_matrix

    su = lambda mm: mm_to_scene_units(mm, mpu)  # noqa: E731
    put = samples.set
    model = stage.GetPrimAtPath(path.AppendChild("Pinhole"))
    geom = UsdGeom.Camera(stage.GetPrimAtPath(path.AppendChild("Camera")))
    # the body: pupil position, OpenTrackIO's rotation as rotateZXY, back to the film plane
    body = UsdGeom.Xformable(cam)
    body.ClearXformOpOrder()
    op_pupil = body.AddTranslateOp().GetAttr()
    op_rot = body.AddRotateZXYOp().GetAttr()
    op_film = body.AddTranslateOp(opSuffix="pupilToFilm").GetAttr()
    lp = "lens:main:"
    names = {n: cam.GetAttribute(lp + n) for n in ("fStop", "iris", "entrancePupilDistance", "pinholeFocalLength")}
    body_iris = cam.GetAttribute("iris")
    a_seq = cam.CreateAttribute("physcam:live:sequenceNumber", Sdf.ValueTypeNames.Int64, True)
    a_tc = cam.CreateAttribute("physcam:live:timecode", Sdf.ValueTypeNames.String, True)
    a_src = cam.CreateAttribute("physcam:live:sourceId", Sdf.ValueTypeNames.String, True)
    a_carried = cam.CreateAttribute("physcam:live:carriedOver", Sdf.ValueTypeNames.StringArray, True)
    a_default = cam.CreateAttribute("physcam:live:defaulted", Sdf.ValueTypeNames.StringArray, True)
    a_model = cam.CreateAttribute("physcam:live:distortionModel", Sdf.ValueTypeNames.String, True)
    a_radial = cam.CreateAttribute("physcam:live:distortionRadial", Sdf.ValueTypeNames.DoubleArray, True)
    a_tang = cam.CreateAttribute("physcam:live:distortionTangential", Sdf.ValueTypeNames.DoubleArray, True)
    a_squeeze = cam.CreateAttribute("physcam:live:anamorphicSqueeze", Sdf.ValueTypeNames.Double, True)
    a_proj = cam.CreateAttribute("physcam:live:projectionOffset", Sdf.ValueTypeNames.Double2, True)
    a_doff = cam.CreateAttribute("physcam:live:distortionOffset", Sdf.ValueTypeNames.Double2, True)
    a_shift = cam.GetAttribute("sensor:main:shift")
    a_pupil_x = None  # an anamorphic's pan pivot; a frame with one pupil has it at the eye
    if any(s.entrance_pupil_horizontal_mm is not None for s in solved):
        a_pupil_x = cam.GetAttribute(lp + "horizontalEntrancePupilDistance") \
            or cam.CreateAttribute(lp + "horizontalEntrancePupilDistance", Sdf.ValueTypeNames.Float)
    a_model_squeeze, a_focal, a_focus = (model.GetAttribute(n) for n in ("squeeze", "focalLength", "focusDistance"))
    companion, companion_attrs = geom.GetPrim(), {}
    omni = None
    c = np.array([[1.0, 0, 0], [0, 0, 1.0], [0, -1.0, 0]])  # OpenTrackIO stage -> USD Y-up
    arrays: dict = {}  # a take names the same few carried or defaulted values frame after frame

    def names_array(names: tuple):
        """``Vt.StringArray(list(names))``, one per distinct tuple (each time sample is copied from it)."""
        a = arrays.get(names)
        if a is None:
            a = arrays[names] = Vt.StringArray(list(names))
        return a

    for s in solved:
        f, t, report = s.frame, s.time_code, s.report
        spec = spec_from_report(report, shutter_duration_s=shutter, shift_mm=_shift(s))
        eye = spec.entrance_pupil_mm
        put(a_squeeze, float(s.squeeze), t)
        put(a_proj, Gf.Vec2d(*s.projection_offset_mm), t)
        put(a_doff, Gf.Vec2d(*s.distortion_offset_mm), t)
        if a_shift:
            put(a_shift, Gf.Vec2f(*spec.shift_mm), t)
        put(a_model_squeeze, float(spec.squeeze), t)
        rot = c @ rotation_matrix(*f.rotation_deg) @ c.T
        film = np.array(_usd_from_stage(f.translation_m, mpu))
        pupil = film + rot @ np.array([0.0, 0.0, -su(eye)])
        put(op_pupil, Gf.Vec3d(*map(float, pupil)), t)
        pan, tilt, roll = f.rotation_deg
        put(op_rot, Gf.Vec3f(tilt, pan, -roll), t)
        put(op_film, Gf.Vec3d(0.0, 0.0, su(eye)), t)
        put(a_focal, spec.focal_length_mm, t)
        put(a_focus, spec.focus_mm, t)
        put(names["fStop"], spec.fstop, t)
        put(names["iris"], iris_mm(spec), t)
        put(body_iris, iris_mm(spec), t)
        put(names["entrancePupilDistance"], eye, t)
        if a_pupil_x is not None:
            put(a_pupil_x, float(eye if s.entrance_pupil_horizontal_mm is None else s.entrance_pupil_horizontal_mm), t)
        if names["pinholeFocalLength"]:
            put(names["pinholeFocalLength"], report.pinhole[0], t)
        values, _ = sampled_render_values(spec, report, mpu, tcps, where=str(path))  # the companion's frame
        for name, value in values.items():
            if name not in companion_attrs:
                companion_attrs[name] = companion.GetAttribute(name)
            put(companion_attrs[name], value, t)
        if f.sequence_number is not None:
            put(a_seq, int(f.sequence_number), t)
        if f.timecode is not None:
            put(a_tc, f.timecode, t)
        if f.source_id is not None:
            put(a_src, str(f.source_id), t)
        put(a_carried, names_array(s.carried), t)
        put(a_default, names_array(s.defaulted), t)
        if f.distortion is not None:
            d = f.distortion
            put(a_model, str(d.get("model", "Brown-Conrady D-U")), t)
            put(a_radial, Vt.DoubleArray([float(v) for v in d.get("radial", [])]), t)
            put(a_tang, Vt.DoubleArray([float(v) for v in d.get("tangential", [])]), t)
            omni = _omni_sample(companion, omni, d, report, resolution, t, put)


def _shift(solved: SolvedFrame) -> tuple[float, float]:
    """physcam's lens shift (mm, + right, + up: the view moves) of OpenLensIO's projection offset
    ΔP (where the optical axis lands, x right, y down): (-ΔPx, ΔPy)."""
    dx, dy = solved.projection_offset_mm
    return (-dx + 0.0, dy + 0.0)


def _omni_sample(prim, attrs, distortion, report, resolution, t, put):
    """One time sample of Omniverse's OpenCV-pinhole distortion on the companion camera (normalised
    coefficients, pixels of a ``resolution`` image), given to ``put(attribute, value, time)``;
    skipped for models it cannot express."""
    from .. import usd as _usd  # noqa: F401  (one line naming the 'usd' extra when usd-core is missing)
    from pxr import Gf, Sdf

    from ..usd.author import OMNI_OPENCV_API

    f_pin = report.pinhole[0]
    try:
        cv = opentrackio_to_opencv(distortion, f_pin)
    except InputError:
        return attrs
    s = report.sensor
    w_px = int(resolution[0])
    h_px = int(resolution[1]) if resolution[1] is not None else max(16, round(w_px * s.height_mm / s.width_mm))
    pfx = "omni:lensdistortion:opencvPinhole:"
    if attrs is None:
        prim.AddAppliedSchema(OMNI_OPENCV_API)
        prim.CreateAttribute("omni:lensdistortion:model", Sdf.ValueTypeNames.Token, True).Set("opencvPinhole")
        prim.CreateAttribute(pfx + "imageSize", Sdf.ValueTypeNames.Int2, True).Set(Gf.Vec2i(w_px, h_px))
        attrs = {k: prim.CreateAttribute(pfx + k, Sdf.ValueTypeNames.Float, True)
                 for k in ("fx", "fy", "cx", "cy", "k1", "k2", "k3", "p1", "p2")}
    values = dict(cv, fx=f_pin * w_px / s.width_mm, fy=f_pin * h_px / s.height_mm, cx=w_px / 2.0, cy=h_px / 2.0)
    for k, a in attrs.items():
        put(a, float(values[k]), t)
    return attrs


def _num(v):
    return None if v is None or (isinstance(v, float) and not math.isfinite(v)) else v


def lens_report_rows(solved) -> list[dict]:
    """One dict per solved frame with :data:`REPORT_COLUMNS` (mm, degrees; a far limit at infinity is None)."""
    rows = []
    for i, s in enumerate(solved):
        require_type("solved frame", s, SolvedFrame, "physcam.live.record.solve_frames(frames)")
        f, r = s.frame, s.report
        rows.append({
            "frame": i, "time_code": s.time_code, "timecode": f.timecode, "sequence_number": f.sequence_number,
            "focus_from_film_mm": r.focus_from_film_mm, "pinhole_focal_length_mm": r.pinhole[0],
            "dof_focal_length_mm": r.focal_length_mm, "fstop": r.fstop, "tstop": r.tstop,
            "entrance_pupil_from_film_mm": r.entrance_pupil_from_film_mm,
            "near_from_film_mm": r.dof.near_from_film_mm, "far_from_film_mm": _num(r.dof.far_from_film_mm),
            "hyperfocal_from_film_mm": r.dof.hyperfocal_from_film_mm, "hfov_deg": r.hfov_focus_deg,
            "vfov_deg": r.vfov_focus_deg, "dfov_deg": r.dfov_focus_deg, "coc_mm": r.coc_mm,
            "x_m": f.translation_m[0], "y_m": f.translation_m[1], "z_m": f.translation_m[2],
            "pan_deg": f.rotation_deg[0], "tilt_deg": f.rotation_deg[1], "roll_deg": f.rotation_deg[2],
            "source_id": f.source_id, "carried_over": list(s.carried), "defaulted": list(s.defaulted),
            "squeeze": s.squeeze, "projection_offset_x_mm": s.projection_offset_mm[0],
            "projection_offset_y_mm": s.projection_offset_mm[1],
            "focus_from_pupil_mm": None if r.entrance_pupil_from_film_mm is None
            else r.focus_from_film_mm - r.entrance_pupil_from_film_mm,
            "from_encoders": list(s.from_encoders),
            "entrance_pupil_horizontal_from_film_mm": s.entrance_pupil_horizontal_mm,
        })
    return rows


def write_lens_report(file, solved, *, force: bool = False):
    """The per-frame lens report as CSV (``.csv``) or JSON (any other suffix); written atomically."""
    from pathlib import Path

    from ..io import atomic_write

    p = Path(file) if isinstance(file, (str, Path)) else None
    if p is None:
        raise InputError(f"the lens report needs a file name, got {file!r}")
    rows = lens_report_rows(solved)
    if p.suffix.lower() == ".csv":
        buf = io.StringIO()
        w = csv.DictWriter(buf, fieldnames=REPORT_COLUMNS, lineterminator="\n")
        w.writeheader()
        for row in rows:
            w.writerow({k: ("" if v is None else ";".join(v) if isinstance(v, list) else v) for k, v in row.items()})
        return atomic_write(p, buf.getvalue(), force=force)
    if p.suffix.lower() != ".json":
        raise ExportError(f"{p}: the lens report is written as .csv or .json")
    try:
        _, fr = time_codes([s.frame for s in solved])
        rate = {"num": fr.numerator, "denom": fr.denominator}
    except InputError:
        rate = None
    sensor = solved[0].report.sensor
    doc = {"schema": "physcam.live_lens_report", "version": 1, "rate": rate,
           "sensor_mm": [sensor.width_mm, sensor.height_mm],
           "units": {"length": "mm", "angle": "degree", "position": "m (OpenTrackIO stage, Z up)"},
           "reference": "distances *_from_film_mm are in front of the film plane; far_from_film_mm null = infinity",
           "carry_over": CARRY_OVER_NOTE,
           "frames": rows}
    return atomic_write(p, json.dumps(doc, indent=1, allow_nan=False) + "\n", force=force)

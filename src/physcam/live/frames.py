"""One tracked frame in physcam's units, to and from an OpenTrackIO sample.

:class:`TrackedFrame` is what a sample says about the camera at one instant, in physcam's units
(mm, degrees, seconds as integer nanoseconds); :func:`frame_from_sample` reads it out of a
validated sample and :func:`sample_from_frame` writes one. OpenTrackIO's units (schema 1.0.1
descriptions): ``focusDistance`` and ``entrancePupilOffset`` in metres, ``pinholeFocalLength`` in mm,
transforms in metres and degrees.

Reference planes (docs/conventions.md): ``entrancePupilOffset`` is measured from the nominal image
plane (the film), positive toward the object, i.e. physcam's ``entrance_pupil_from_film_mm``;
``focusDistance`` is read as the focus mark, from the film plane (the schema says only "focus
distance/position of the lens"; the image plane is the reference it gives the pupil offset).

Two entrance pupils (an anamorphic lens, docs/anamorphic.md): the standard ``entrancePupilOffset``
carries the **vertical** (Y meridian) pupil, the tilt pivot and the eye physcam renders from; the
horizontal (X meridian) pupil, the pan pivot, rides in the sample's top-level ``custom`` object as
``"physcam:horizontalEntrancePupilOffset"`` (metres, the same plane and sign). OpenTrackIO 1.0.1 has no
field for a second pupil; its schema leaves the sample's top level open (the official
complete_dynamic_example carries a ``custom`` object there), while ``lens`` allows no extra keys and its
``custom`` array is coefficients whose meaning each producer and consumer must negotiate. A reader
that knows nothing of the key ignores it and sees one pupil.

A zoom lens: each sample carries the zoom position as ``lens.encoders.zoom`` (0 wide angle, 1
telephoto, as the schema orders it) and its focal length as ``pinholeFocalLength``; the static
``nominalFocalLength`` is left out (the schema: "undefined in the case of a zoom lens") and the
lens's focal length range, ``[shortest, longest]`` mm, rides with ``static`` in the same top-level
``custom`` object as ``"physcam:focalLengthRange"`` (``static.lens`` allows no extra keys).

Transforms: OpenTrackIO's stage is right-handed and Z-up, Y forward (toward the LED wall), X to
camera right; rotations are intrinsic Z-X-Y, ``[pan, tilt, roll]`` in degrees, each by the right-hand
rule (pan turns +X toward +Y, tilt +Y toward +Z, roll +Z toward +X; camdkit's axis figure). A list
of transforms composes in order, the last placing the camera sensor (film plane centre). Scales
are composed too; the camera's orientation is the rotation left after removing them.
"""

from __future__ import annotations

import functools
import math
import re
import uuid
from dataclasses import dataclass, field, replace
from fractions import Fraction

import numpy as np

from ..errors import InputError, require_finite, require_type
from ..frame_rates import exact_frame_rate
from .sample import PROTOCOL_VERSION, shown

#: the key of the horizontal (X) entrance pupil in a sample's top-level ``custom`` object (module notes)
HORIZONTAL_PUPIL_KEY = "physcam:horizontalEntrancePupilOffset"

#: the key of a zoom lens's focal length range, ``[shortest, longest]`` mm, in the top-level ``custom``
#: object of a sample that carries ``static`` (module notes)
FOCAL_RANGE_KEY = "physcam:focalLengthRange"

#: the most radial (and tangential) distortion coefficients a frame keeps: a recording holds each
#: frame, and a 64 KiB sample could otherwise carry thousands
MAX_DISTORTION_TERMS = 16

__all__ = ["TrackedFrame", "rate_fraction", "rational", "timecode_fields", "timecode_index", "rotation_matrix", "pan_tilt_roll",
           "compose_transforms", "frame_from_sample", "parse_timecode", "sample_from_frame", "static_block", "new_source_id"]


@dataclass(frozen=True)
class TrackedFrame:
    """The camera at one instant (module notes). ``time_ns``: PTP-style timestamp in nanoseconds
    (None when the sample has none); ``translation_m`` (x, y, z) of the film plane centre on the
    Z-up stage; ``rotation_deg`` (pan, tilt, roll); lens values in mm; ``None`` where not sent;
    ``source_id`` and ``source_number``: the sample's ``sourceId`` and ``sourceNumber``."""

    time_ns: int | None = None
    sequence_number: int | None = None
    timecode: str | None = None
    rate: Fraction | None = None
    translation_m: tuple[float, float, float] = (0.0, 0.0, 0.0)
    rotation_deg: tuple[float, float, float] = (0.0, 0.0, 0.0)
    pinhole_focal_length_mm: float | None = None
    focus_from_film_mm: float | None = None
    fstop: float | None = None
    tstop: float | None = None
    entrance_pupil_mm: float | None = None
    distortion: dict | None = None
    sensor_mm: tuple[float, float] | None = None
    nominal_focal_length_mm: float | None = None
    notes: tuple[str, ...] = field(default_factory=tuple)
    source_id: str | None = None
    source_number: int | None = None
    #: ``static.camera.anamorphicSqueeze`` (1 spherical): the horizontal focal length is F / squeeze
    squeeze: float | None = None
    #: ``lens.projectionOffset`` and ``lens.distortionOffset`` (mm on the sensor, OpenLensIO's x right,
    #: y down): where the optical axis and the distortion centre land relative to the frame centre
    projection_offset_mm: tuple[float, float] | None = None
    distortion_offset_mm: tuple[float, float] | None = None
    #: ``lens.encoders`` (normalised 0-1: focus 0 infinity, iris 0 open, zoom 0 wide), keys present only
    encoders: dict | None = None
    #: the sample's ``timing.timecode.dropFrame``
    drop_frame: bool = False
    #: an anamorphic's horizontal (X) entrance pupil in front of the film (mm), the pan pivot;
    #: ``entrance_pupil_mm`` is then the vertical (Y) one. None: one pupil (module notes)
    entrance_pupil_horizontal_mm: float | None = None
    #: a zoom lens's (shortest, longest) focal length, mm (custom ``physcam:focalLengthRange``, module notes)
    focal_range_mm: tuple[float, float] | None = None

    @property
    def source(self) -> tuple:
        """The stream this frame came from: (``sourceId``, ``sourceNumber``)."""
        return (self.source_id, self.source_number)


def rate_fraction(rate) -> Fraction:
    """A frame rate as an exact fraction (:func:`physcam.frame_rates.exact_frame_rate`: NTSC rates, 23.976 or
    23.98, 29.97, 59.94, 119.88, become N*1000/1001, others the nearest fraction with a denominator up to
    1001); a Fraction is taken as it is.

    >>> rate_fraction(23.976), rate_fraction(25), rate_fraction(Fraction(30000, 1001))
    (Fraction(24000, 1001), Fraction(25, 1), Fraction(30000, 1001))
    """
    if isinstance(rate, Fraction):
        fr = rate
    else:
        r = require_finite("frame rate", rate)
        if r <= 0:
            raise InputError(f"frame rate must be > 0, got {r:g}")
        fr = exact_frame_rate(r)
    if not 0 < fr.numerator <= 10000 * fr.denominator:  # 0 < fr <= 10000 (a denominator is > 0), in integers
        raise InputError(f"frame rate must lie in (0, 10000] fps, got {float(fr):g}")
    return fr


def rational(rate) -> dict:
    """OpenTrackIO's rational ``{"num", "denom"}`` of a frame rate."""
    fr = rate_fraction(rate)
    return {"num": fr.numerator, "denom": fr.denominator}


_DROP_COUNTS = {Fraction(30000, 1001): 2, Fraction(60000, 1001): 4}


@functools.lru_cache(maxsize=64)
def _clock(num: int, den: int) -> tuple[int, Fraction, int, int]:
    """The timecode of the sample rate num/den: (samples per timecode frame k, the timecode's rate, its
    nominal frames per second, the frame numbers drop-frame counting skips each minute: 2 at 30000/1001,
    4 at 60000/1001, SMPTE ST 12-1; 0 where the rate has no drop-frame form). Remembered per rate (by
    its integers: a Fraction's hash is a modular inverse): every sample sent and every timecode read
    asks it again, of the stream's one rate."""
    fr = Fraction(num, den)
    nominal = math.ceil(fr - Fraction(1, 10**6))
    k = max(1, math.ceil(nominal / 60))  # samples per timecode frame
    tc_rate = fr / k
    return k, tc_rate, math.ceil(nominal / k), _DROP_COUNTS.get(tc_rate, 0)


def _timecode_clock(fr: Fraction) -> tuple[int, Fraction, int, int]:
    """:func:`_clock` of the sample rate ``fr`` (a :func:`rate_fraction`)."""
    return _clock(fr.numerator, fr.denominator)


_TIMECODE = re.compile(r"(\d{1,2}):(\d{2}):(\d{2})([:;.])(\d{1,3})")
_SUB_FRAME = re.compile(r"(.+[:;]\d{1,3})\.(\d{1,3})")


def parse_timecode(text, rate, drop_frame: bool = False) -> int:
    """The timecode frame count of ``text`` ("HH:MM:SS:FF", ";" before FF for drop-frame) at ``rate``:
    the number of timecode frames since 00:00:00:00 (a drop-frame label's skipped numbers not counted)."""
    return _frame_count(text, _timecode_clock(rate_fraction(rate)), drop_frame)


def _frame_count(text, clock, drop_frame: bool) -> int:
    """:func:`parse_timecode` at the rate whose :func:`_clock` is ``clock``."""
    _, tc_rate, per_s, drop_count = clock
    m = _TIMECODE.fullmatch(str(text).strip())
    if not m:
        raise InputError(f"a timecode is HH:MM:SS:FF, got {text!r:.40}")
    h, mi, se, ff = int(m.group(1)), int(m.group(2)), int(m.group(3)), int(m.group(5))
    drop = drop_frame or m.group(4) == ";"
    if h > 23 or mi > 59 or se > 59 or ff >= per_s:
        raise InputError(f"timecode {text} is out of range at {per_s} frames a second")
    d = drop_count if drop else 0
    if drop and not d:
        raise InputError(f"drop-frame timecode exists at 30000/1001 and 60000/1001 fps, not {tc_rate}")
    if d and se == 0 and ff < d and mi % 10:
        raise InputError(f"timecode {text} names a frame drop-frame counting skips")
    minutes = 60 * h + mi
    return (minutes * 60 + se) * per_s + ff - d * (minutes - minutes // 10)


def timecode_index(text, rate, drop_frame: bool = False) -> int:
    """The sample number since 00:00:00:00 of a timecode text as :class:`TrackedFrame` keeps it
    ("HH:MM:SS:FF", ";" before FF for drop-frame, ".N" after it for the sub-frame above 60 fps) at the
    stream's sample ``rate``: :func:`parse_timecode`'s frame count times the samples per timecode
    frame, plus the sub-frame."""
    clock = _timecode_clock(rate_fraction(rate))
    k = clock[0]
    m = _SUB_FRAME.fullmatch(str(text).strip())
    label, sub = (m.group(1), int(m.group(2))) if m else (text, 0)
    if sub >= k:
        raise InputError(f"timecode {text} has a sub-frame beyond the {k} samples of a timecode frame")
    return _frame_count(label, clock, drop_frame) * k + sub


def timecode_fields(frame: int, rate, *, start: int = 0, drop_frame: bool = False) -> dict:
    """SMPTE timecode of the ``frame``-th sample at ``rate``, ``start`` timecode frames after
    00:00:00:00 (:func:`parse_timecode`), drop-frame counting when ``drop_frame`` (SMPTE ST 12-1:
    the first 2 (4 at 59.94) frame numbers of each minute not divisible by ten are skipped).

    The timecode counts at the nominal integer rate; above 60 fps it counts frame pairs (or larger
    groups) and ``subFrame`` numbers the samples within one (the schema allows 120 frames a second).
    """
    fr = rate_fraction(rate)
    if isinstance(frame, bool) or not isinstance(frame, (int, np.integer)) or frame < 0:
        raise InputError(f"frame must be a whole number >= 0, got {shown(frame)}")
    if isinstance(start, bool) or not isinstance(start, (int, np.integer)) or start < 0:
        raise InputError(f"the start timecode must be a whole number of frames >= 0, got {shown(start)}")
    k, tc_rate, per_s, drop_count = _timecode_clock(fr)
    d = drop_count if drop_frame else 0
    if drop_frame and not d:
        raise InputError(f"drop-frame timecode exists at 30000/1001 and 60000/1001 fps, not {tc_rate}")
    f, sub = divmod(int(frame), k)
    f += int(start)
    if d:  # a drop-frame count to the label's frame number (skipped numbers added back)
        per_10 = per_s * 600 - 9 * d
        tens, rest = divmod(f, per_10)
        f += 9 * d * tens + (d * ((rest - d) // (per_s * 60 - d)) if rest >= d else 0)
    total_s, frames = divmod(f, per_s)
    out = {"hours": (total_s // 3600) % 24, "minutes": (total_s // 60) % 60, "seconds": total_s % 60,
           "frames": frames, "frameRate": {"num": tc_rate.numerator, "denom": tc_rate.denominator}}
    if k > 1:
        out["subFrame"] = sub
    if drop_frame:
        out["dropFrame"] = True
    return out


def _timecode_text(tc: dict) -> str:
    sep = ";" if tc.get("dropFrame") else ":"
    text = f"{tc['hours']:02d}:{tc['minutes']:02d}:{tc['seconds']:02d}{sep}{tc['frames']:02d}"
    return text + (f".{tc['subFrame']}" if "subFrame" in tc else "")


def rotation_matrix(pan_deg, tilt_deg, roll_deg) -> np.ndarray:
    """3 x 3 rotation of intrinsic Z-X-Y angles (pan about Z, tilt about X, roll about Y; right-hand
    rule): R = Rz(pan) Rx(tilt) Ry(roll), columns the camera's axes on the Z-up stage."""
    p, t, r = (math.radians(require_finite(n, v)) for n, v in (("pan", pan_deg), ("tilt", tilt_deg),
                                                                 ("roll", roll_deg)))
    cp, sp, ct, st, cr, sr = math.cos(p), math.sin(p), math.cos(t), math.sin(t), math.cos(r), math.sin(r)
    rz = np.array([[cp, -sp, 0.0], [sp, cp, 0.0], [0.0, 0.0, 1.0]])
    rx = np.array([[1.0, 0.0, 0.0], [0.0, ct, -st], [0.0, st, ct]])
    ry = np.array([[cr, 0.0, sr], [0.0, 1.0, 0.0], [-sr, 0.0, cr]])
    return rz @ rx @ ry


def pan_tilt_roll(matrix) -> tuple[float, float, float]:
    """(pan, tilt, roll) degrees of a rotation matrix, the inverse of :func:`rotation_matrix`
    (tilt in [-90, 90]; at +-90 the pan takes the whole turn and roll is 0)."""
    m = np.asarray(matrix, dtype=float)
    if m.shape != (3, 3) or not np.all(np.isfinite(m)):
        raise InputError("a rotation is a finite 3 x 3 matrix")
    t = math.asin(max(-1.0, min(1.0, m[2, 1])))
    if abs(m[2, 1]) < 1.0 - 1e-12:
        p = math.atan2(-m[0, 1], m[1, 1])
        r = math.atan2(-m[2, 0], m[2, 2])
    else:  # gimbal lock: pan and roll turn about the same axis
        p = math.atan2(m[1, 0], m[0, 0])
        r = 0.0
    return math.degrees(p), math.degrees(t), math.degrees(r)


def _pair(name, value) -> tuple[float, float]:
    if not isinstance(value, (tuple, list)) or len(value) != 2:
        raise InputError(f"{name} must be a pair of numbers, got {value!r:.60}")
    return require_finite(name, value[0]), require_finite(name, value[1])


def _vec(obj, keys, default=0.0):
    if not isinstance(obj, dict):
        return (default,) * len(keys)
    return tuple(require_finite(k, obj.get(k, default)) for k in keys)


def compose_transforms(transforms) -> tuple[tuple, tuple, tuple[str, ...]]:
    """(translation m, (pan, tilt, roll) deg, notes) of the camera from an OpenTrackIO ``transforms``
    list (module notes). One transform is read as it is, exactly; a chain is composed as 4 x 4 matrices."""
    if not isinstance(transforms, list) or not transforms or not all(isinstance(t, dict) for t in transforms):
        raise InputError("transforms must be a non-empty list of transform objects")
    if len(transforms) == 1 and "scale" not in transforms[0]:
        t = transforms[0]
        return _vec(t.get("translation"), "xyz"), _vec(t.get("rotation"), ("pan", "tilt", "roll")), ()
    m = np.eye(4)
    for t in transforms:
        a = np.eye(4)
        a[:3, :3] = rotation_matrix(*_vec(t.get("rotation"), ("pan", "tilt", "roll")))
        a[:3, :3] = a[:3, :3] @ np.diag(_vec(t.get("scale"), "xyz", 1.0))
        a[:3, 3] = _vec(t.get("translation"), "xyz")
        m = m @ a
    rot = m[:3, :3]
    u, s, vt = np.linalg.svd(rot)
    notes = ()
    if np.linalg.det(rot) <= 0 or not np.all(np.isfinite(s)) or s.min() <= 0:
        raise InputError("the composed transforms do not give a right-handed camera orientation")
    if np.ptp(s) > 1e-9:
        notes = (f"the transforms scale the camera by {', '.join(f'{v:g}' for v in s)}; its orientation is "
                 "the rotation without the scale",)
    return tuple(float(v) for v in m[:3, 3]), pan_tilt_roll(u @ vt), notes


def frame_from_sample(sample, *, static=None) -> TrackedFrame:
    """The :class:`TrackedFrame` of a validated OpenTrackIO sample (module notes for units and planes).

    ``static``: the last ``static`` block seen on the stream, for the sensor size and nominal focal
    length when this sample carries none.
    """
    require_type("sample", sample, dict)
    timing = sample.get("timing", {})
    lens = sample.get("lens", {})
    st = sample.get("static") or static or {}
    time_ns = None
    if "sampleTimestamp" in timing:
        ts = timing["sampleTimestamp"]
        time_ns = int(ts["seconds"]) * 1_000_000_000 + int(ts["nanoseconds"])
    rate = None
    if "sampleRate" in timing:
        rate = Fraction(timing["sampleRate"]["num"], timing["sampleRate"]["denom"])
    tc = _timecode_text(timing["timecode"]) if "timecode" in timing else None
    translation, rotation, notes = ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0), ())
    if "transforms" in sample:
        translation, rotation, notes = compose_transforms(sample["transforms"])
    dims = st.get("camera", {}).get("activeSensorPhysicalDimensions")

    def mm(name):  # metres to mm; a value the conversion overflows is refused, never made infinite
        v = lens.get(name)
        if v is None:
            return None
        out = float(v) * 1000.0
        if not math.isfinite(out):
            raise InputError(f"lens.{name} {v!r} m is beyond any distance in millimetres")
        return out
    distortion = None
    if lens.get("distortion"):
        distortion = dict(lens["distortion"][0])
        for key in ("radial", "tangential"):
            if len(distortion.get(key, ())) > MAX_DISTORTION_TERMS:
                raise InputError(f"lens.distortion[0].{key} has {len(distortion[key])} coefficients; physcam keeps "
                                 f"at most {MAX_DISTORTION_TERMS} (no lens model uses more)")
    sq = st.get("camera", {}).get("anamorphicSqueeze")
    squeeze = None if not sq else require_finite("anamorphicSqueeze", sq["num"] / sq["denom"])
    if squeeze is not None and not 0.1 <= squeeze <= 10.0:
        raise InputError(f"static.camera.anamorphicSqueeze {squeeze:g} is outside 0.1 to 10")

    def offset(name):
        v = lens.get(name)
        return None if v is None else (require_finite(name, v["x"]), require_finite(name, v["y"]))
    encoders = {k: float(v) for k, v in lens["encoders"].items()} if lens.get("encoders") else None
    custom = sample.get("custom")
    pupil_x = custom.get(HORIZONTAL_PUPIL_KEY) if isinstance(custom, dict) else None
    if pupil_x is not None:
        if isinstance(pupil_x, bool) or not isinstance(pupil_x, (int, float)):
            raise InputError(f"custom.{HORIZONTAL_PUPIL_KEY} must be a number of metres, got {shown(pupil_x)}")
        pupil_x = require_finite(HORIZONTAL_PUPIL_KEY, float(pupil_x) * 1000.0)
    return TrackedFrame(
        focal_range_mm=_focal_range(custom),
        entrance_pupil_horizontal_mm=pupil_x,
        squeeze=squeeze, projection_offset_mm=offset("projectionOffset"),
        distortion_offset_mm=offset("distortionOffset"), encoders=encoders,
        drop_frame=bool(timing.get("timecode", {}).get("dropFrame", False)),
        time_ns=time_ns, sequence_number=timing.get("sequenceNumber"), timecode=tc, rate=rate,
        translation_m=translation, rotation_deg=rotation,
        pinhole_focal_length_mm=lens.get("pinholeFocalLength"), focus_from_film_mm=mm("focusDistance"),
        fstop=lens.get("fStop"), tstop=lens.get("tStop"), entrance_pupil_mm=mm("entrancePupilOffset"),
        distortion=distortion,
        sensor_mm=None if not dims else (float(dims["width"]), float(dims["height"])),
        nominal_focal_length_mm=st.get("lens", {}).get("nominalFocalLength"),
        notes=notes, source_id=sample.get("sourceId"), source_number=sample.get("sourceNumber"),
    )


def _focal_range(custom) -> tuple[float, float] | None:
    """A sample's ``custom`` zoom focal length range (module notes), checked; None when absent."""
    v = custom.get(FOCAL_RANGE_KEY) if isinstance(custom, dict) else None
    if v is None:
        return None
    if (not isinstance(v, list) or len(v) != 2
            or any(isinstance(x, bool) or not isinstance(x, (int, float)) for x in v)):
        raise InputError(f"custom.{FOCAL_RANGE_KEY} must be [shortest, longest] focal lengths in mm, got {shown(v)}")
    lo, hi = (require_finite(FOCAL_RANGE_KEY, float(x)) for x in v)
    if not 0.0 < lo <= hi:
        raise InputError(f"custom.{FOCAL_RANGE_KEY} must hold 0 < shortest <= longest, got {shown(v)}")
    return (lo, hi)


def new_source_id() -> str:
    """A fresh ``urn:uuid:`` for a stream's ``sourceId``."""
    return f"urn:uuid:{uuid.uuid4()}"


def static_block(*, sensor_mm, rate, lens_name=None, nominal_focal_length_mm=None, squeeze: float = 1.0,
                 shutter_angle_deg: float | None = None, resolution=None, label: str | None = None) -> dict:
    """OpenTrackIO's ``static`` object for physcam's camera: sensor size (mm), capture rate, lens
    and tracker identification (physcam sends as the tracker)."""
    from .. import __version__

    w, h = _pair("sensor size (mm)", sensor_mm)
    cam = {"activeSensorPhysicalDimensions": {"width": w, "height": h}, "captureFrameRate": rational(rate)}
    # the effective squeeze of a real anamorphic breathes (1.9645 for a 2x at 3 m): kept to 1e-6
    sq = Fraction(require_finite("squeeze", squeeze)).limit_denominator(1_000_000)
    cam["anamorphicSqueeze"] = {"num": sq.numerator, "denom": sq.denominator}
    if shutter_angle_deg is not None:
        cam["shutterAngle"] = require_finite("shutter angle", shutter_angle_deg)
    if resolution is not None:
        cam["activeSensorResolution"] = {"width": int(resolution[0]), "height": int(resolution[1])}
    if label:
        cam["label"] = str(label)[:1023]
    out = {"camera": cam, "tracker": {"make": "physcam", "model": "physcam live", "firmwareVersion": __version__}}
    lens = {}
    if lens_name:
        lens["model"] = str(lens_name)[:1023]
    if nominal_focal_length_mm is not None:
        lens["nominalFocalLength"] = require_finite("nominal focal length", nominal_focal_length_mm)
    if lens:
        out["lens"] = lens
    return out


def sample_from_frame(frame: TrackedFrame, *, source_id: str, sequence_number: int, frame_index: int | None = None,
                      source_number: int = 1, static: dict | None = None, status: str = "physcam",
                      start_timecode: int = 0) -> dict:
    """An OpenTrackIO sample carrying ``frame`` (module notes); ``frame_index`` numbers the timecode
    (default ``sequence_number``) from ``start_timecode`` (timecode frames, :func:`parse_timecode`;
    drop-frame when ``frame.drop_frame``), ``static`` is included when given."""
    require_type("frame", frame, TrackedFrame, "build one with TrackedFrame(...)")
    if isinstance(sequence_number, bool) or not isinstance(sequence_number, int) or not 0 <= sequence_number < 2**32:
        raise InputError(f"sequence number must be a whole number 0..2^32-1, got {shown(sequence_number)}")
    timing = {"mode": "internal", "sequenceNumber": sequence_number}
    if frame.time_ns is not None:
        timing["sampleTimestamp"] = {"seconds": frame.time_ns // 1_000_000_000,
                                     "nanoseconds": frame.time_ns % 1_000_000_000}
    if frame.rate is not None:
        timing["sampleRate"] = rational(frame.rate)
        timing["timecode"] = timecode_fields(sequence_number if frame_index is None else frame_index, frame.rate,
                                             start=start_timecode, drop_frame=frame.drop_frame)
    lens = {}
    m = lambda v: v / 1000.0  # noqa: E731 - mm to metres
    if frame.pinhole_focal_length_mm is not None:
        lens["pinholeFocalLength"] = float(frame.pinhole_focal_length_mm)
    if frame.focus_from_film_mm is not None and math.isfinite(frame.focus_from_film_mm):
        lens["focusDistance"] = m(float(frame.focus_from_film_mm))
    if frame.fstop is not None:
        lens["fStop"] = float(frame.fstop)
    if frame.tstop is not None:
        lens["tStop"] = float(frame.tstop)
    if frame.entrance_pupil_mm is not None:
        lens["entrancePupilOffset"] = m(float(frame.entrance_pupil_mm))
    if frame.distortion is not None:
        lens["distortion"] = [dict(frame.distortion)]
    for key, v in (("projectionOffset", frame.projection_offset_mm), ("distortionOffset", frame.distortion_offset_mm)):
        if v is not None:
            lens[key] = {"x": float(v[0]), "y": float(v[1])}
    if frame.encoders:
        lens["encoders"] = {k: float(v) for k, v in frame.encoders.items()}
    x, y, z = (float(v) for v in frame.translation_m)
    pan, tilt, roll = (float(v) for v in frame.rotation_deg)
    out = {
        "protocol": {"name": "OpenTrackIO", "version": list(PROTOCOL_VERSION)},
        "sampleId": f"urn:uuid:{uuid.uuid4()}",
        "sourceId": source_id,
        "sourceNumber": int(source_number),
        "tracker": {"status": status, "recording": False},
        "timing": timing,
        "lens": lens,
        "transforms": [{"id": "Camera", "translation": {"x": x, "y": y, "z": z},
                        "rotation": {"pan": pan, "tilt": tilt, "roll": roll}}],
    }
    custom = {}
    if frame.entrance_pupil_horizontal_mm is not None:
        custom[HORIZONTAL_PUPIL_KEY] = m(float(frame.entrance_pupil_horizontal_mm))
    if static and frame.focal_range_mm is not None:
        custom[FOCAL_RANGE_KEY] = [float(v) for v in frame.focal_range_mm]
    if custom:
        out["custom"] = custom
    if static:
        out["static"] = static
    return out


def with_time(frame: TrackedFrame, t0_ns: int, index: int) -> TrackedFrame:
    """``frame`` stamped as the ``index``-th sample after ``t0_ns`` at its rate (exact nanoseconds)."""
    rate = frame.rate or Fraction(24)
    return replace(frame, time_ns=int(t0_ns) + (index * 1_000_000_000 * rate.denominator) // rate.numerator)

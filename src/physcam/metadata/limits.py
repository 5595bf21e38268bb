"""What a real camera can record: every value of a read clip checked against a physical range, and its
timecode against running backwards, before anything is shown or converted (docs/camera-metadata.md).

A reading outside its range is a corrupt file or a field misread, never a camera setting: it is
refused with the file, the line (a Mo-Sys packet's index) and the range, so nothing downstream
("validated" OpenTrackIO, a USD camera, ``metadata show``) ever carries it. The ranges:

* stops (T and f): 0.5 to 1000; 0.5 is the f-number of an aplanatic lens filling the half space
  in air (N = 1 / (2 sin theta), theta < 90 degrees; Kingslake, *Lens Design Fundamentals*, ch. 1);
* focus distance (mm from the film): more than 0 and at most 100 km;
* focal length: more than 0 and at most 10 m; the entrance pupil within 10 m of the film;
* frame rate: more than 0 and at most 10000 fps (physcam.live's bound); shutter angle more than
  0 and at most 360 degrees; exposure time more than 0 and at most an hour; ISO 1 to 10^7;
* squeeze 0.1 to 10 (physcam.live's bound); pixels 1 to 10^6 each way; active area up to 1 m.

A timecode that goes back (other than through midnight) means the file holds several takes one
after another (a concatenated recording): refused, naming each place a take starts, so the file
can be split there. With the clip's frame rate known, a timecode must be a time at that rate
(frames 00 to the nominal rate - 1, seconds and minutes below 60, hours below 24) and each frame's
must follow the last by one frame (a drop-frame timecode, :attr:`ClipRecord.drop_frame`, counted as
SMPTE ST 12-1 drops it: numbers 00 and 01 of each minute but every tenth skipped at 29.97 fps, 00 to
03 at 59.94, so a day is 2,589,408 frames at 29.97; drop-frame at another rate is refused): a
skip is a dropped or deleted row, which would shift every later frame onto the wrong plate frame,
or a frame rate the timecode was not counted at (a 25 fps clip with a 24 fps timecode skips a frame
every second). Both are refused at the line where they happen.
"""

from __future__ import annotations

import math
from fractions import Fraction

from ..errors import MetadataError, require_type
from .record import ClipRecord

__all__ = ["FRAME_RANGES", "STATIC_RANGES", "check_record"]

#: per-frame field -> (lowest, highest, lowest allowed itself, unit, what)
FRAME_RANGES = {"focus_mm": (0.0, 1e8, False, "mm", "focus distance"),
                "tstop": (0.5, 1000.0, True, "", "T-stop"), "fstop": (0.5, 1000.0, True, "", "f-stop"),
                "focal_length_mm": (0.0, 1e4, False, "mm", "focal length"),
                "entrance_pupil_mm": (-1e4, 1e4, True, "mm", "entrance pupil")}
STATIC_RANGES = {"frame_rate": (0.0, 1e4, False, "fps", "frame rate"),
                 "shutter_angle_deg": (0.0, 360.0, False, "degrees", "shutter angle"),
                 "exposure_time_s": (0.0, 3600.0, False, "s", "exposure time"),
                 "iso": (1.0, 1e7, True, "", "ISO"), "squeeze": (0.1, 10.0, True, "", "squeeze"),
                 "nominal_focal_length_mm": (0.0, 1e4, False, "mm", "nominal focal length")}
#: most takes named in the refusal of a concatenated file
_NAMED = 5


def _outside(value, lo, hi, closed) -> bool:
    v = float(value)
    return not (math.isfinite(v) and v <= hi and (v >= lo if closed else v > lo))


def _range_text(lo, hi, closed, unit) -> str:
    u = f" {unit}" if unit else ""
    return f"{'from' if closed else 'more than'} {lo:g}{u} {'to' if closed else 'and at most'} {hi:g}{u}"


def _where(record):
    return record.files[0] if len(record.files) == 1 else " + ".join(record.files)


def check_record(record) -> ClipRecord:
    """``record`` unchanged when every value lies in its range and the timecode never runs back
    (module notes); else a MetadataError naming the file, the line and the range."""
    record = require_type("record", record, ClipRecord, "physcam.metadata.load(paths)")
    path = _where(record)
    for name, (lo, hi, closed, unit, what) in STATIC_RANGES.items():
        v = getattr(record, name)
        if v is not None and _outside(v, lo, hi, closed):
            raise MetadataError(f"the clip's {what} {float(v):g} is outside {_range_text(lo, hi, closed, unit)}: "
                                "not a value a camera records (a corrupt file or a misread field)", path)
    for name, v in (("resolution_px", record.resolution_px), ("active_area_mm", record.active_area_mm)):
        hi = 1e6 if name == "resolution_px" else 1000.0
        if v is not None and any(_outside(x, 0.0, hi, False) for x in v):
            raise MetadataError(f"the clip's {name} {v} is outside (0, {hi:g}] each way", path)
    mosys = record.source == "mosys"
    for f in record.frames:
        for name, (lo, hi, closed, unit, what) in FRAME_RANGES.items():
            v = getattr(f, name)
            if v is not None and _outside(v, lo, hi, closed):
                where = f"packet {f.line}: " if mosys else ""
                raise MetadataError(f"{where}{what} {float(v):g}{' ' + unit if unit else ''} is outside "
                                    f"{_range_text(lo, hi, closed, unit)}: not a value a lens records (a corrupt "
                                    "file or a misread field)", record.files[0], None if mosys else f.line)
    _check_timecode_fields(record)
    _check_timecode(record)
    _check_timecode_steps(record)
    return record


def _nominal(rate) -> int:
    return math.ceil(Fraction(rate) - Fraction(1, 10**6))


def _where_in_file(record, f) -> tuple[str, int | None]:
    return (f"packet {f.line}: ", None) if record.source == "mosys" else ("", f.line)


#: the nominal rates at which drop-frame timecode exists, and the frame numbers it skips each minute
#: (SMPTE ST 12-1: 2 at 30000/1001, 4 at 60000/1001)
_DROP = {Fraction(30000, 1001): 2, Fraction(60000, 1001): 4}


def _drops(record) -> int:
    """Frame numbers the clip's timecode skips each minute but every tenth: 0 unless drop-frame."""
    if not record.drop_frame:
        return 0
    d = _DROP.get(Fraction(record.frame_rate))
    if d is None:
        raise MetadataError(f"a drop-frame timecode at {float(record.frame_rate):g} fps: drop-frame counting "
                            "exists at 29.97 and 59.94 fps (30000/1001, 60000/1001; SMPTE ST 12-1) only",
                            record.files[0])
    return d


def _check_timecode_fields(record) -> None:
    if record.frame_rate is None:
        return
    n = _nominal(record.frame_rate)
    d = _drops(record)
    for f in record.frames:
        if f.timecode is None:
            continue
        h, m, s, ff = _tc_key(f.timecode)
        if h > 23 or m > 59 or s > 59 or ff >= n:
            where, line = _where_in_file(record, f)
            raise MetadataError(f"{where}timecode {f.timecode} is not a time at the clip's {float(record.frame_rate):g} "
                                f"fps: frames run 00 to {n - 1:02d}, seconds and minutes 00 to 59, hours 00 to 23",
                                record.files[0], line)
        if d and s == 0 and ff < d and m % 10:
            where, line = _where_in_file(record, f)
            raise MetadataError(f"{where}timecode {f.timecode} names a frame number drop-frame counting skips "
                                f"(frames 00 to {d - 1:02d} of each minute but every tenth; SMPTE ST 12-1)",
                                record.files[0], line)


def _tc_count(tc: str, nominal: int, drops: int = 0) -> int:
    """Frames since midnight of ``tc``; drop-frame counting (``drops`` > 0, :func:`_drops`) skips frame
    numbers 0..drops-1 of each minute but every tenth (SMPTE ST 12-1)."""
    h, m, s, f = _tc_key(tc)
    minutes = h * 60 + m
    return (minutes * 60 + s) * nominal + f - drops * (minutes - minutes // 10)


def _check_timecode_steps(record) -> None:
    if record.frame_rate is None:
        return
    n = _nominal(record.frame_rate)
    d = _drops(record)
    day = _tc_count("24:00:00:00", n, d)  # a drop-frame day: 2,589,408 frames at 29.97 (not 2,592,000)
    prev = None
    for f in record.frames:
        if f.timecode is None:
            continue
        if prev is not None:
            step = (_tc_count(f.timecode, n, d) - _tc_count(prev.timecode, n, d)) % day
            if step > 1:
                where, line = _where_in_file(record, f)
                raise MetadataError(f"{where}the timecode skips {step - 1} frame{'s' if step > 2 else ''} from "
                                    f"{prev.timecode} to {f.timecode} at the clip's {float(record.frame_rate):g} fps"
                                    f"{' drop-frame' if d else ''}: a dropped or deleted row, or a frame rate the "
                                    "timecode was not counted at", record.files[0], line)
        prev = f


def _tc_key(tc: str) -> tuple[int, ...]:
    return tuple(int(p) for p in tc.replace(";", ":").replace(".", ":").split(":"))


def _check_timecode(record) -> None:
    backs = []
    prev = None
    for f in record.frames:
        if f.timecode is None:
            continue
        key = _tc_key(f.timecode)
        if prev is not None and key < prev[0] and not (prev[0][0] == 23 and key[0] == 0):  # midnight goes on
            backs.append((prev[1], f))
        prev = (key, f)
    if not backs:
        return
    unit = "packet" if record.source == "mosys" else "line"
    starts = ", ".join(f"{unit} {f.line} ({a.timecode} -> {f.timecode})" for a, f in backs[:_NAMED])
    more = f" and {len(backs) - _NAMED} more" if len(backs) > _NAMED else ""
    raise MetadataError(f"the timecode runs back {len(backs)} time{'s' if len(backs) > 1 else ''}: the file holds "
                        f"{len(backs) + 1} takes one after another (concatenated recordings?); takes start at "
                        f"{starts}{more}: split the file there and give one take", record.files[0])

"""Canon cinema cameras: a static CSV (one row) and a per-frame CSV.

Per-frame columns: ``Timecode`` (H:MM:SS:FF), ``FocusPosition`` (the focus distance as the 8 hex
digits of a big-endian IEEE 754 float, in metres: camdkit's reading; "3F000000" = 0.5 m),
``FocalLength`` (a fraction in mm: "180/10" = 18 mm), ``ApertureNumber`` (a fraction: "45/10" = 4.5)
with ``ApertureMode`` (2: the number is a T-number, 1: an f-number), ``ExposureTime`` (a fraction,
the shutter angle in degrees: "18000/100" = 180), ``PhotographicSensitivity`` (ISO + 0x80000000 when
``PhotographicSensitivityMode`` is 1).

Static columns: ``ShotNumber`` (the clip name), ``LensSqueezeFactor`` (0: 1x, 1: 1.33x, 2: 2x, 3: 1.8x),
``Width`` / ``Height`` (pixels), ``Timescale`` and ``Duration`` (the clip's length in timescale
units; not a frame rate, which neither file carries).
"""

from __future__ import annotations

import struct

from ..errors import MetadataError, require_type
from ._text import number, read_text, require_columns, rows, timecode
from .record import ClipRecord, FrameSample

__all__ = ["sniff", "read"]

FRAME_COLUMNS = ("Timecode", "FocusPosition", "FocalLength", "ApertureNumber", "ApertureMode")
STATIC_COLUMNS = ("LensSqueezeFactor", "Timescale", "Duration")
SQUEEZE = {0: 1.0, 1: 1.33, 2: 2.0, 3: 1.8}


def sniff(head: str) -> str | None:
    require_type("head", head, str, "the first bytes of a metadata file")
    cols = head.split(",")
    if "FocusPosition" in cols and "ApertureNumber" in cols:
        return "frames"
    if "LensSqueezeFactor" in cols and "Timescale" in cols:
        return "static"
    return None


def _float_hex(path, line, text):
    t = (text or "").strip()
    if not t:
        return None
    try:
        v = struct.unpack(">f", bytes.fromhex(t))[0]
    except (ValueError, struct.error):
        raise MetadataError(f"FocusPosition {t!r} is not 8 hex digits of a 32-bit float", path, line) from None
    return number(path, line, "FocusPosition", repr(v))


def _frame(path, line, r) -> FrameSample:
    stop = number(path, line, "ApertureNumber", r["ApertureNumber"])
    mode = r["ApertureMode"].strip()
    if mode not in ("1", "2"):
        raise MetadataError(f"ApertureMode {mode!r} is neither 1 (f-number) nor 2 (T-number)", path, line)
    focus_m = _float_hex(path, line, r["FocusPosition"])
    return FrameSample(line=line, timecode=timecode(path, line, r["Timecode"]),
                       focus_mm=None if focus_m is None else focus_m * 1000.0,
                       tstop=stop if mode == "2" else None, fstop=stop if mode == "1" else None,
                       focal_length_mm=number(path, line, "FocalLength", r["FocalLength"]))


def read(frames_path, static_path=None) -> ClipRecord:
    """The clip of a Canon per-frame CSV and, when given, its static CSV (module notes)."""
    header, data = rows(frames_path, read_text(frames_path))
    require_columns(frames_path, header, FRAME_COLUMNS, "a Canon per-frame CSV")
    if not data:
        raise MetadataError("no frame rows after the header", frames_path, 2)
    frames = [_frame(frames_path, line, r) for line, r in data]
    line0, r0 = data[0]
    static: dict = {}
    shutter = number(frames_path, line0, "ExposureTime", r0.get("ExposureTime", ""))
    static["shutter_angle_deg"] = shutter
    if r0.get("PhotographicSensitivityMode", "").strip() == "1":
        iso = number(frames_path, line0, "PhotographicSensitivity", r0.get("PhotographicSensitivity", ""))
        static["iso"] = None if iso is None else int(iso) - 0x80000000
    if static_path is not None:
        sh, sd = rows(static_path, read_text(static_path))
        require_columns(static_path, sh, STATIC_COLUMNS, "a Canon static CSV")
        if len(sd) != 1:
            raise MetadataError(f"{len(sd)} rows where a Canon static CSV has one", static_path, 2)
        line, s = sd[0]
        code = number(static_path, line, "LensSqueezeFactor", s["LensSqueezeFactor"])
        if code is not None and int(code) not in SQUEEZE:
            raise MetadataError(f"LensSqueezeFactor {int(code)} is not one of 0-3", static_path, line)
        static["squeeze"] = None if code is None else SQUEEZE[int(code)]
        w, h = number(static_path, line, "Width", s.get("Width", "")), number(static_path, line, "Height",
                                                                               s.get("Height", ""))
        static["resolution_px"] = (int(w), int(h)) if w and h else None
        static["clip_name"] = s.get("ShotNumber") or None
    files = (str(frames_path),) + ((str(static_path),) if static_path is not None else ())
    return ClipRecord(source="canon", files=files, frames=tuple(frames), camera_make="Canon",
                      notes=("FocusPosition read as metres (camdkit's reading of Canon's float)",), **static)

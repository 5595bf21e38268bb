"""Canon cinema cameras: a static CSV (one row) and a per-frame CSV.

Per-frame columns: ``Timecode`` (H:MM:SS:FF), ``FocusPosition`` (the focus distance as the 8 hex
digits of a big-endian IEEE 754 float, in metres: camdkit's reading; "3F000000" = 0.5 m; an older
export, camdkit's first Canon sample of 2022-08-30, writes the float's 32 bits as one decimal
integer instead: "1055286886" = 0x3EE66666 = 0.45 m. Eight characters are read as hex, as the
current export writes them; a whole number of 9 or 10 digits below 2^32 as the decimal form: a
focus between 1e-30 m and 1e30 m has bits above 10^8, so the two forms cannot be confused),
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
from ._text import header_columns, lacking_columns, number, require_columns, rows, single_row, timecode
from .record import ClipRecord, FrameSample

__all__ = ["sniff", "read"]

FRAME_COLUMNS = ("Timecode", "FocusPosition", "FocalLength", "ApertureNumber", "ApertureMode")
STATIC_COLUMNS = ("LensSqueezeFactor", "Timescale", "Duration")
SQUEEZE = {0: 1.0, 1: 1.33, 2: 2.0, 3: 1.8}


#: The columns a Canon per-frame header needs (one of each group), and columns only this layout has
LAYOUT_GROUPS = (("FocusPosition",), ("ApertureNumber",))
LAYOUT_MARKERS = ("FocusPosition", "ApertureNumber")


def sniff(head: str) -> str | None:
    require_type("head", head, str, "the first bytes of a metadata file")
    cols = header_columns(head)
    if not lacking_columns(cols, LAYOUT_GROUPS):
        return "frames"
    if "LensSqueezeFactor" in cols and "Timescale" in cols:
        return "static"
    return None


def _float_bits(path, line, text, decimal: list):
    """The float of Canon's FocusPosition: 8 hex digits, or (older exports) the bits as a decimal integer."""
    t = (text or "").strip()
    if not t:
        return None
    if len(t) != 8 and t.isdigit() and len(t) in (9, 10) and int(t) < 2**32:
        bits = int(t).to_bytes(4, "big")
        decimal.append(line)
    else:
        try:
            bits = bytes.fromhex(t)
        except ValueError:
            bits = b""
        if len(t) != 8 or len(bits) != 4:
            raise MetadataError(f"FocusPosition {t!r} is neither 8 hex digits nor the decimal integer of a 32-bit "
                                "float", path, line)
    return number(path, line, "FocusPosition", repr(struct.unpack(">f", bits)[0]))


def _frame(path, line, r, decimal) -> FrameSample:
    stop = number(path, line, "ApertureNumber", r["ApertureNumber"])
    mode = r["ApertureMode"].strip()
    if mode not in ("1", "2"):
        raise MetadataError(f"ApertureMode {mode!r} is neither 1 (f-number) nor 2 (T-number)", path, line)
    focus_m = _float_bits(path, line, r["FocusPosition"], decimal)
    return FrameSample(line=line, timecode=timecode(path, line, r["Timecode"]),
                       focus_mm=None if focus_m is None else focus_m * 1000.0,
                       tstop=stop if mode == "2" else None, fstop=stop if mode == "1" else None,
                       focal_length_mm=number(path, line, "FocalLength", r["FocalLength"]))


def read(frames_path, static_path=None) -> ClipRecord:
    """The clip of a Canon per-frame CSV and, when given, its static CSV (module notes)."""
    header, data = rows(frames_path)
    require_columns(frames_path, header, FRAME_COLUMNS, "a Canon per-frame CSV")
    frames, decimal, first = [], [], None
    for line, r in data:
        first = first or (line, r)
        frames.append(_frame(frames_path, line, r, decimal))
    if first is None:
        raise MetadataError("no frame rows after the header", frames_path, 2)
    line0, r0 = first
    static: dict = {}
    shutter = number(frames_path, line0, "ExposureTime", r0.get("ExposureTime", ""))
    static["shutter_angle_deg"] = shutter
    if r0.get("PhotographicSensitivityMode", "").strip() == "1":
        iso = number(frames_path, line0, "PhotographicSensitivity", r0.get("PhotographicSensitivity", ""))
        static["iso"] = None if iso is None else int(iso) - 0x80000000
    if static_path is not None:
        _, line, s = single_row(static_path, "a Canon static CSV", STATIC_COLUMNS)
        code = number(static_path, line, "LensSqueezeFactor", s["LensSqueezeFactor"])
        if code is not None and int(code) not in SQUEEZE:
            raise MetadataError(f"LensSqueezeFactor {int(code)} is not one of 0-3", static_path, line)
        static["squeeze"] = None if code is None else SQUEEZE[int(code)]
        w, h = number(static_path, line, "Width", s.get("Width", "")), number(static_path, line, "Height",
                                                                               s.get("Height", ""))
        static["resolution_px"] = (int(w), int(h)) if w and h else None
        static["clip_name"] = s.get("ShotNumber") or None
    files = (str(frames_path),) + ((str(static_path),) if static_path is not None else ())
    notes = ("FocusPosition read as metres (camdkit's reading of Canon's float)",)
    if decimal:
        notes += (f"FocusPosition written as the float's bits in decimal (an older Canon export) on {len(decimal)} "
                  "rows, read as such",)
    return ClipRecord(source="canon", files=files, frames=tuple(frames), camera_make="Canon", notes=notes, **static)


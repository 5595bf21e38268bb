"""ARRI Meta Extract (AME) CSV: one tab-separated row per frame of an ALEXA clip (a copy saved with commas
or semicolons is read alike: the delimiter is the one with which the header has AME's columns).

Fields read (AME 4.4 column names; one row per recorded frame):

* ``Master TC`` (HH:MM:SS:FF; the column appears twice, the first is read), ``Index``;
  ``Master TC Drop Frame`` ("yes": the timecode is counted drop-frame, SMPTE ST 12-1, whether its
  text has ``;`` or ``:`` before the frames; a ``;`` timecode is drop-frame whatever the column says);
* ``Lens Distance Unit`` ("Meter" or "Feet") and ``Lens Focus Distance`` in that unit, the lens
  data system's (LDS) focus mark from the film plane; converted to mm (1 ft = 304.8 mm).
  A value in feet-and-inches notation (``12'6"``) under "Meter" is refused. A lens that reports
  no focus (no unit or an empty cell) leaves the focus absent and the clip's notes count the
  frames; a file without the ``Lens Focus Distance`` column leaves it absent too and the notes
  say the column is missing (not that the lens reported none); timecode, iris and focal length
  are kept;
* ``Lens Iris``: the T-stop as a whole-stop marking plus tenths ("1.4 + 7/10" = T1.4 and 7/10
  of a stop = T1.80); ``Lens Linear Iris``, the same in 1/1000 stop with 1000 = T1
  (T = 2^((L - 1000) / 2000), camdkit's reading), is preferred when present (finer);
* ``Lens Focal Length`` (mm), ``Lens Model``, ``Lens Serial Number``, ``Lens Squeeze``;
* ``Camera Model``, ``Camera Serial Number``, ``Camera Family``, ``Project FPS``, ``Shutter Angle``
  (degrees), ``Exposure Time`` ("20.000 ms"), ``Exposure Index ASA``, ``Image Width`` / ``Height``.

The sensor area the recorded pixels cover is not in the file; for ALEXA LF it comes from ARRI's
published formats table (LF 16:9 HD and UHD: 31.68 x 17.82 mm, LF Open Gate: 36.70 x 25.54 mm) and
``active_area_source`` says so; other cameras leave it None.
"""

from __future__ import annotations

import re

from ..errors import MetadataError, require_type
from ._text import FOOT_MM, exact_rate, header_columns, lacking_columns, number, require_columns, rows, stop_from_marking, timecode
from .record import ClipRecord, FrameSample

__all__ = ["sniff", "read"]

REQUIRED = ("Master TC",)
#: (camera family, recorded width, height) -> active area (mm), ARRI ALEXA LF formats and resolutions
ACTIVE_AREA_MM = {("ALEXALF", 1920, 1080): (31.68, 17.82), ("ALEXALF", 3840, 2160): (31.68, 17.82),
                  ("ALEXALF", 4448, 3096): (36.70, 25.54)}
_FT_IN = re.compile(r"""^\s*(\d+(?:\.\d+)?)\s*'\s*(?:(\d+(?:\.\d+)?)\s*"?)?\s*$""")


#: The columns an AME header needs (one of each group; :func:`physcam.metadata.detect_file` names what lacks),
#: and columns only this layout has
LAYOUT_GROUPS = (("Master TC",), ("Lens Focus Distance", "Lens Focal Length", "Lens Iris"))
LAYOUT_MARKERS = ("Master TC", "Lens Linear Iris", "Camera Clip Name")


#: The delimiters an AME header is read with: Meta Extract writes tabs; a copy saved again by a spreadsheet
#: (or exported with another setting) has commas or, in locales with a decimal comma, semicolons
DELIMITERS = ("\t", ",", ";")
#: a decimal comma between two digits (a semicolon-separated copy's numbers)
_DECIMAL_COMMA = re.compile(r"(\d),(\d)")


def delimiter_of(head: str) -> str | None:
    """The delimiter with which ``head`` (the file's first line) is an AME header, or None."""
    for d in DELIMITERS:
        if d in head and not lacking_columns(header_columns(head, d), LAYOUT_GROUPS):
            return d
    return None


def sniff(head: str) -> bool:
    """True when ``head`` (the file's first line) is an AME header, tab-, comma- or semicolon-separated."""
    require_type("head", head, str, "the first bytes of a metadata file")
    return delimiter_of(head) is not None


def _delimiter(head: str) -> str:
    """The delimiter of the file's header line ``head`` (:func:`delimiter_of`); tab, Meta Extract's own, when
    none fits (the reader then names the columns it lacks)."""
    return delimiter_of(head) or "\t"


def _focus_mm(path, line, unit, text):
    t = (text or "").strip()
    if t in ("", "--"):
        return None
    ft_in = _FT_IN.match(t) or ('"' in t and re.match(r'^\s*(\d+(?:\.\d+)?)\s*"\s*$', t))
    if unit == "Meter":
        if ft_in or "'" in t or '"' in t:
            raise MetadataError(f"focus {t!r} is in feet and inches where the Lens Distance Unit says metres",
                                path, line)
        return number(path, line, "focus distance", t) * 1000.0
    if ft_in and "'" in t:
        return (float(ft_in.group(1)) * 12 + float(ft_in.group(2) or 0)) * 25.4
    return number(path, line, "focus distance", t) * FOOT_MM


def _tstop(path, line, row):
    lin = row.get("Lens Linear Iris", "")
    marked = stop_from_marking(path, line, "Lens Iris", row.get("Lens Iris", ""))  # read, so a corrupt cell is said
    if lin not in ("", "--"):
        v = number(path, line, "Lens Linear Iris", lin)
        return 2.0 ** ((v - 1000.0) / 2000.0)
    return marked


def _frame(path, line, r, no_unit: list) -> FrameSample:
    unit = r.get("Lens Distance Unit", "").strip()
    focus_text = r.get("Lens Focus Distance", "")
    if unit in ("", "--"):
        focus = None
        if focus_text.strip() not in ("", "--"):
            no_unit.append(line)  # a focus without its unit: not guessed
    elif unit not in ("Meter", "Feet"):
        raise MetadataError(f"Lens Distance Unit {unit!r} is neither Meter nor Feet", path, line)
    else:
        focus = _focus_mm(path, line, unit, focus_text)
    return FrameSample(line=line, timecode=timecode(path, line, r["Master TC"]), focus_mm=focus,
                       tstop=_tstop(path, line, r),
                       focal_length_mm=number(path, line, "focal length", r.get("Lens Focal Length", "")))


def _drop_frame(path, line, text, semicolon: int | None) -> bool:
    """Drop-frame: the first row's ``Master TC Drop Frame`` says "yes", or a timecode has ``;`` before its
    frames (``semicolon``: the line of the first; SMPTE's drop-frame notation, whatever the column says)."""
    t = (text or "").strip().lower()
    if t not in ("", "--", "yes", "no"):
        raise MetadataError(f"Master TC Drop Frame {text.strip()!r} is neither yes nor no", path, line)
    return t == "yes" or semicolon is not None


def read(path) -> ClipRecord:
    """The clip of one AME CSV (module notes), read row by row."""
    picked = {}

    def pick(head: str) -> str:  # the delimiter from the header line rows reads: the file's first line read once
        picked["delimiter"] = _delimiter(head)
        return picked["delimiter"]

    header, data = rows(path, pick)
    require_columns(path, header, REQUIRED, "an ARRI Meta Extract CSV")
    if picked["delimiter"] == ";":  # a decimal-comma locale's copy: "4,812" is 4.812, "1,4 + 7/10" is 1.4 + 7/10
        data = ((line, {k: _DECIMAL_COMMA.sub(r"\1.\2", v) for k, v in r.items()}) for line, r in data)
    frames, no_unit, first, semicolon = [], [], None, None
    for line, r in data:
        if first is None:
            first = (line, r)
        frames.append(_frame(path, line, r, no_unit))
        if semicolon is None and ";" in (frames[-1].timecode or ""):
            semicolon = line
    if first is None:
        raise MetadataError("no frame rows after the header", path, 2)
    line, first = first
    drop = _drop_frame(path, line, first.get("Master TC Drop Frame"), semicolon)
    g = lambda k: (first.get(k) or "").strip() or None  # noqa: E731
    num = lambda k: number(path, line, k, first.get(k, ""))  # noqa: E731
    w, h = num("Image Width"), num("Image Height")
    res = (int(w), int(h)) if w and h else None
    area = ACTIVE_AREA_MM.get((g("Camera Family"), *res)) if res else None
    fps = num("Project FPS")
    exp = g("Exposure Time")
    exposure_s = number(path, line, "Exposure Time", exp.split()[0]) / 1000.0 if exp and exp.endswith("ms") else None
    lens_model = g("Lens Model")
    iso = num("Exposure Index ASA")
    return ClipRecord(
        source="arri", files=(str(path),), frames=tuple(frames), clip_name=g("Camera Clip Name"),
        camera_make="ARRI", camera_model=g("Camera Model"), camera_serial=g("Camera Serial Number"),
        sensor_name=g("Camera Family"), resolution_px=res, active_area_mm=area,
        active_area_source="ARRI ALEXA LF formats and resolutions table" if area else None,
        lens_make="ARRI" if lens_model and lens_model.startswith("ARRI ") else None, lens_model=lens_model,
        lens_serial=g("Lens Serial Number"),
        squeeze=num("Lens Squeeze"), frame_rate=exact_rate(fps) if fps else None, drop_frame=drop,
        shutter_angle_deg=num("Shutter Angle"), exposure_time_s=exposure_s,
        iso=int(iso) if iso is not None else None,
        notes=_notes(frames, no_unit, first, "Lens Focus Distance" in header))


def _notes(frames, no_unit, first, focus_column: bool) -> tuple[str, ...]:
    if not focus_column:  # the column itself is missing (an edited copy, or an export without lens data)
        return (f"no 'Lens Focus Distance' column: the file records no focus distance on any of its "
                f"{len(frames)} frames; timecode, iris and focal length kept",)
    unit = (first.get("Lens Distance Unit") or "").strip()
    if unit in ("Meter", "Feet"):
        notes = [f"focus distances recorded in {'metres' if unit == 'Meter' else 'feet'}, converted to mm"]
    else:
        notes = []
    absent = sum(f.focus_mm is None for f in frames)
    if absent:
        why = (f"{len(no_unit)} of them give a Lens Focus Distance without a Lens Distance Unit (first at line "
               f"{no_unit[0]}), not guessed" if no_unit else "the lens reported no focus")
        notes.append(f"{absent} of {len(frames)} frames have no focus distance ({why}): focus left absent; "
                     "timecode, iris and focal length kept")
    return tuple(notes)

"""Sony VENICE: the per-frame CSV and the clip's NonRealTimeMeta XML (``...M01.xml``).

CSV columns: ``Timecode`` (HH:MM:SS:FF), ``Clip Name``, ``Lens Model`` (the lens attributes code),
``Lens Serial``, ``Focal Length (mm)``, ``Aperture`` (T-stop as a whole-stop marking plus tenths:
"T 2 3/10" = T2 and 3/10 stop = T2.22), ``Focus Distance (ft)`` (decimal feet from the film plane,
converted at 304.8 mm/ft; a ``Focus Distance (m)`` column is read as metres), ``Camera Model``.

XML (Sony NonRealTimeMeta, namespace ``urn:schemas-professionalDisc:nonRealTimeMeta:ver.2.10``):
``Duration`` (frames, checked against the CSV's rows), ``VideoFrame@captureFps`` ("24.00p"),
``VideoLayout@pixel`` / ``@numOfVerticalLine`` (recorded pixels), ``Camera@manufacturer``,
``@modelName``, ``@serialNo``, ``Lens@modelName``, and the AcquisitionRecord items
``ShutterSpeedAngle`` (1/100 degree), ``ISOSensitivity``, ``AnamorphicLensSqueezeRatio`` (x 100).
The sensor area is not in either file: ``active_area_mm`` stays None.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from fractions import Fraction

from ..errors import MetadataError, require_type
from ._text import FOOT_MM, exact_rate, header_columns, lacking_columns, number, read_text, rows, stop_from_marking, timecode
from .record import ClipRecord, FrameSample

__all__ = ["sniff", "read"]

NS = {"nrt": "urn:schemas-professionalDisc:nonRealTimeMeta:ver.2.10"}
COLUMNS = ("Timecode", "Focal Length (mm)", "Aperture")


#: The columns a VENICE per-frame CSV header needs (one of each group; "Focus Distance (" a prefix: its unit
#: follows), and columns only this layout has
LAYOUT_GROUPS = (("Timecode",), ("Focus Distance (",), ("Aperture",))
LAYOUT_MARKERS = ("Focal Length (mm)", "Camera Tilt", "Camera Roll")


def sniff(head: str) -> str | None:
    """"csv" or "xml" when ``head`` (the first 2 kB) is a VENICE export, else None."""
    require_type("head", head, str, "the first bytes of a metadata file")
    if "NonRealTimeMeta" in head:
        return "xml"
    if not lacking_columns(header_columns(head.splitlines()[0] if head else ""), LAYOUT_GROUPS):
        return "csv"
    return None


def _focus_column(path, header):
    for name, scale in (("Focus Distance (ft)", FOOT_MM), ("Focus Distance (m)", 1000.0)):
        if name in header:
            return name, scale
    raise MetadataError("unknown column layout for a VENICE CSV: no 'Focus Distance (ft)' or '(m)' column", path, 1)


def _frames(path):
    header, data = rows(path)
    missing = [c for c in COLUMNS if c not in header]
    if missing:
        raise MetadataError(f"unknown column layout for a VENICE CSV: no {', '.join(map(repr, missing))} column",
                            path, 1)
    col, scale = _focus_column(path, header)
    out, first = [], None
    for line, r in data:
        first = first or r
        f = number(path, line, "focus distance", r[col])
        out.append(FrameSample(line=line, timecode=timecode(path, line, r["Timecode"]),
                               focus_mm=None if f is None else f * scale,
                               tstop=stop_from_marking(path, line, "Aperture", r["Aperture"]),
                               focal_length_mm=number(path, line, "focal length", r["Focal Length (mm)"])))
    if first is None:
        raise MetadataError("no frame rows after the header", path, 2)
    return out, first


def _xml(path) -> tuple[dict, int | None]:
    try:
        root = ET.fromstring(read_text(path))
    except ET.ParseError as exc:
        raise MetadataError(f"not well-formed XML ({exc})", path, exc.position[0]) from None
    if not root.tag.endswith("NonRealTimeMeta"):
        raise MetadataError("unknown layout: the root element is not NonRealTimeMeta", path, 1)

    def attr(tag, name):
        e = root.find(f".//nrt:{tag}", NS)
        v = None if e is None else (e.get(name) or "").strip()
        return v or None

    def item(name):
        e = root.find(f".//nrt:Item[@name='{name}']", NS)
        return None if e is None else e.get("value")

    def num(text, what):
        return None if text is None else number(path, None, what, text)

    fps = attr("VideoFrame", "captureFps")
    w, h = attr("VideoLayout", "pixel"), attr("VideoLayout", "numOfVerticalLine")
    shutter, squeeze, iso = item("ShutterSpeedAngle"), item("AnamorphicLensSqueezeRatio"), item("ISOSensitivity")
    duration = attr("Duration", "value")
    return {"camera_make": attr("Camera", "manufacturer"), "camera_model": attr("Camera", "modelName"),
            "camera_serial": attr("Camera", "serialNo"), "lens_model": attr("Lens", "modelName"),
            "frame_rate": None if fps is None else exact_rate(Fraction(fps.rstrip("pi"))),
            "resolution_px": (int(w), int(h)) if w and h else None,
            "shutter_angle_deg": None if shutter is None else num(shutter, "ShutterSpeedAngle") / 100.0,
            "squeeze": None if squeeze is None else num(squeeze, "AnamorphicLensSqueezeRatio") / 100.0,
            "iso": None if iso is None else int(num(iso, "ISOSensitivity"))}, \
        (None if duration is None else int(num(duration, "Duration")))


def read(csv_path, xml_path=None) -> ClipRecord:
    """The clip of a VENICE CSV and, when given, its XML (module notes)."""
    frames, first = _frames(csv_path)
    static, duration = _xml(xml_path) if xml_path is not None else ({}, None)
    if duration is not None and duration != len(frames):
        raise MetadataError(f"Duration says {duration} frames, {csv_path} has {len(frames)} rows", xml_path, None)
    static.setdefault("camera_model", first.get("Camera Model") or None)
    if static.get("lens_model") is None:
        static["lens_model"] = first.get("Lens Model") or None
    files = (str(csv_path),) + ((str(xml_path),) if xml_path is not None else ())
    return ClipRecord(source="venice", files=files, frames=tuple(frames), clip_name=first.get("Clip Name") or None,
                      lens_serial=first.get("Lens Serial") or None,
                      notes=(f"focus distances recorded as {_focus_column(csv_path, first)[0]!r}, converted to mm",),
                      **static)

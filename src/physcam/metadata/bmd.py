"""Blackmagic RAW: the text the RAW SDK's ``ExtractMetadata`` sample prints.

A "Clip Metadata" section and one "Frame N Metadata" section per frame, each of ``key: value``
lines. Clip keys read: ``manufacturer``, ``camera_type``, ``camera_id`` (serial), ``clip_number``,
``lens_type`` (the lens model), ``anamorphic`` ("2x") with ``anamorphic_enable``,
``crop_size`` (recorded pixels). Frame keys: ``aperture`` ("T2.3": a T-stop; "f/2.8" an f-stop),
``focal_length`` ("50mm"), ``distance`` ("991mm", the focus distance), ``sensor_rate``
("48,1," = 48/1 fps), ``shutter_value`` ("180°"), ``iso``, ``timecode`` when present.
The sensor area is not in the file: ``active_area_mm`` stays None.
"""

from __future__ import annotations

import re
from fractions import Fraction

from ..errors import MetadataError, require_type
from ._text import lines, number, timecode
from .record import ClipRecord, FrameSample

__all__ = ["sniff", "read"]

_FRAME = re.compile(r"^Frame (\d+) Metadata$")
_LINE = re.compile(r"^([^:]+): ?(.*)$")


def sniff(head: str) -> bool:
    require_type("head", head, str, "the first bytes of a metadata file")
    return any(line.strip() == "Clip Metadata" for line in head.splitlines()[:5]) or \
        any(_FRAME.match(line.strip()) for line in head.splitlines()[:5])


def _sections(path):
    clip, frames, cur = {}, [], None
    for n, raw in lines(path):
        line = raw.strip()
        if not line:
            continue
        if line == "Clip Metadata":
            cur = clip
        elif _FRAME.match(line):
            frames.append({"_line": n})
            cur = frames[-1]
        elif (m := _LINE.match(line)) and cur is not None:
            cur[m.group(1).strip()] = (m.group(2).strip(), n)
        else:
            raise MetadataError(f"unknown layout: {line[:40]!r} is neither a section heading nor 'key: value'",
                                path, n)
    return clip, frames


def _unit(path, d, key, suffix):
    v = d.get(key)
    if v is None:
        return None
    text, line = v
    if not text.endswith(suffix):
        raise MetadataError(f"{key} {text!r} does not end in {suffix!r}", path, line)
    return number(path, line, key, text[: -len(suffix)])


def _frame(path, d) -> FrameSample:
    stop = d.get("aperture")
    t = f = None
    if stop is not None:
        text, line = stop
        if text.startswith("T"):
            t = number(path, line, "aperture", text[1:])
        elif text.lower().startswith(("f/", "f")):
            f = number(path, line, "aperture", text.lower().lstrip("f/"))
        else:
            raise MetadataError(f"aperture {text!r} is neither a T- nor an f-stop", path, line)
    tc = d.get("timecode")
    return FrameSample(line=d["_line"], timecode=None if tc is None else timecode(path, tc[1], tc[0]),
                       focus_mm=_unit(path, d, "distance", "mm"), tstop=t, fstop=f,
                       focal_length_mm=_unit(path, d, "focal_length", "mm"))


def read(path) -> ClipRecord:
    """The clip of one ExtractMetadata text (module notes)."""
    clip, frames = _sections(path)
    if not frames:
        raise MetadataError("no 'Frame N Metadata' section", path, None)
    samples = [_frame(path, d) for d in frames]
    g = lambda k: (clip.get(k) or (None,))[0] or None  # noqa: E731
    first = frames[0]
    rate = None
    if "sensor_rate" in first:
        text, line = first["sensor_rate"]
        parts = [p for p in text.split(",") if p.strip()]
        try:
            rate = Fraction(int(parts[0]), int(parts[1]))
        except (ValueError, IndexError, ZeroDivisionError):
            raise MetadataError(f"sensor_rate {text!r} is not 'num,denom,'", path, line) from None
    squeeze = None
    if g("anamorphic_enable") == "1" and g("anamorphic"):
        squeeze = _unit(path, clip, "anamorphic", "x")
    elif g("anamorphic_enable") == "0":
        squeeze = 1.0
    crop = [p for p in (g("crop_size") or "").split(",") if p.strip()]
    iso = first.get("iso")
    return ClipRecord(source="bmd", files=(str(path),), frames=tuple(samples), clip_name=g("clip_number"),
                      camera_make=g("manufacturer"), camera_model=g("camera_type"), camera_serial=g("camera_id"),
                      resolution_px=(int(crop[0]), int(crop[1])) if len(crop) == 2 else None,
                      lens_model=g("lens_type"), squeeze=squeeze, frame_rate=rate,
                      shutter_angle_deg=_unit(path, first, "shutter_value", "°"),
                      iso=None if iso is None else int(number(path, iso[1], "iso", iso[0])))

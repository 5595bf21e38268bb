"""ARRI Reference Tool (ART) JSON: ARRI's current metadata export (``art-cmd``), schema
``https://www.arri.com/schema/json/metadata_output/v2-*``.

One JSON object: ``arriJsonHeader`` (the schema URI, the software), ``descriptiveMetadataSets`` and
``clipBasedMetadataSets`` (lists of ``{metadataSetName, metadataSetPayload}``: per clip) and
``frameBasedMetadata.frames`` (one ``{frameNo, frameBasedMetadataSets}`` per frame, each set by its
name). Read (units of ARRI's ``camera/lens_state/v1-0-1`` set; cross-checked on ARRI's ALEXA LF
sample clips, whose ARRI Meta Extract CSV of the same day gives the same lens in readable units):

* ``Lens State`` per frame: ``lensFocusDistanceMetric`` in mm from the film plane (-1 infinity, 0
  not available), else ``lensFocusDistanceImperial`` in 1/1000 inch; ``lensIris`` in 1/1000 stop
  with 1000 = T1, as AME's ``Lens Linear Iris`` (2667 = T1.78 = AME's "1.4 + 7/10"): T = 2^((L -
  1000) / 2000), negative values not available; ``lensFocalLength`` in micrometres (0 not
  available); ``lensEntrancePupilOffset`` in micrometres (-1 not known, camdkit's note);
* ``Sensor State`` per frame: ``exposureTime`` ("1/50" s) and ``sensorSampleRate`` ("24" fps),
  whose product x 360 is the shutter angle; ``exposureIndex`` (ISO);
* ``Project Rate`` (``timebase``, ``dropframe``) is the frame rate; ``Clip Info``'s
  ``clipStartFrameNumber`` is the first frame's timecode counted in frames at that rate (as AME's
  ``Master TC Frame Count``: 1176223 at 24 fps is AME's 13:36:49:07), so frame ``frameNo`` has
  timecode start + frameNo; a frame's own ``timecode`` text is read when the export writes one. A
  start below 0 or past a day's frames (it would wrap to another time of day) is refused.
  ``clipDuration`` is checked against the frames;
* ``Camera Device`` (model, serial), ``Lens Device`` (``lensModel``, ``lensSerialNumber``,
  ``lensSqueezeFactor`` "4/3" or "2"), ``Image Size``'s ``storedSize`` (pixels), ``Sensor Device``'s
  ``sensorName``. The sensor area is ARRI's formats table for the ALEV III A2X sensor (ALEXA LF,
  Mini LF: 4448 x 3096 px Open Gate = 36.70 x 25.54 mm, 3840 x 2160 and 1920 x 1080 = 31.68 x
  17.82 mm); the export's ``sensorDimensions`` is not read (0 in ARRI's sample, unit unpublished).

A focus at infinity (-1) or not available is left absent and the notes count the frames; a
drop-frame project rate gives no derived timecode (the notes say so) and marks the clip drop-frame.
A ``timebase`` of "23.976" (29.97, 59.94) is the exact 24000/1001 (30000/1001, 60000/1001), as every
reader's rate (:func:`._text.exact_rate`).
"""

from __future__ import annotations

import json
import math
from fractions import Fraction
from pathlib import Path

from ..errors import MetadataError, require_type
from ._text import exact_rate, read_text, timecode
from .record import ClipRecord, FrameSample

__all__ = ["sniff", "read", "MAX_JSON_BYTES"]

#: the largest ART JSON physcam reads (an hour at 24 fps is ~60 MB; parsing takes about 10x in memory)
MAX_JSON_BYTES = 300_000_000
INCH_MM = 25.4  # exact (1959)
#: (sensorName, stored width, height) -> active area mm: ARRI's ALEXA LF formats and resolutions table
ACTIVE_AREA_MM = {("ALEV III A2X", 1920, 1080): (31.68, 17.82), ("ALEV III A2X", 3840, 2160): (31.68, 17.82),
                  ("ALEV III A2X", 4448, 3096): (36.70, 25.54)}


def sniff(head: str) -> bool:
    """True when ``head`` (the file's first bytes) opens an ART JSON export."""
    require_type("head", head, str, "the first bytes of a metadata file")
    return head.lstrip().startswith("{") and '"arriJsonHeader"' in head


def _load(p: Path) -> dict:
    def no_constant(name):
        raise ValueError(f"{name} is not a JSON number")

    try:
        doc = json.loads(read_text(p, MAX_JSON_BYTES), parse_constant=no_constant)
    except json.JSONDecodeError as exc:
        raise MetadataError(f"not well-formed JSON ({exc.msg})", p, exc.lineno) from None
    except (ValueError, RecursionError) as exc:
        raise MetadataError(f"not ARRI JSON ({exc})", p) from None
    uri = doc.get("arriJsonHeader", {}).get("jsonSchemaUri", "") if isinstance(doc, dict) else ""
    if not isinstance(uri, str) or "/metadata_output/v2" not in uri:
        raise MetadataError(f"unknown ARRI JSON layout {str(uri)[:80]!r}: physcam reads metadata_output v2", p, 1)
    return doc


def _sets(p: Path, doc: dict, key: str) -> dict:
    out = {}
    items = doc.get(key, [])
    if not isinstance(items, list):
        raise MetadataError(f"{key} is not a list of metadata sets", p)
    for s in items:
        if isinstance(s, dict) and isinstance(s.get("metadataSetPayload"), dict):
            out.setdefault(str(s.get("metadataSetName")), s["metadataSetPayload"])
    return out


def _int(p, where, name, v):
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
        raise MetadataError(f"{where}: {name} {str(v)[:40]!r} is not a number", p)
    return v


def _rational(p, where, name, text) -> Fraction | None:
    if text in (None, ""):
        return None
    try:
        v = Fraction(str(text))
    except (ValueError, ZeroDivisionError):
        raise MetadataError(f"{where}: {name} {str(text)[:40]!r} is not a number or a ratio", p) from None
    return v


def _focus_mm(p, where, lens: dict) -> tuple[float | None, str | None]:
    """(focus mm, why absent)."""
    if "lensFocusDistanceMetric" in lens:
        v = _int(p, where, "lensFocusDistanceMetric", lens["lensFocusDistanceMetric"])
        scale = 1.0
    elif "lensFocusDistanceImperial" in lens:
        v = _int(p, where, "lensFocusDistanceImperial", lens["lensFocusDistanceImperial"])
        scale = INCH_MM / 1000.0
    else:
        return None, "not recorded"
    if v == -1:
        return None, "at infinity (-1)"
    if v == 0:
        return None, "not available (0)"
    return v * scale, None


def _frame(p, i, fr, start, rate) -> tuple[FrameSample, str | None]:
    where = f"frame {i}"
    if not isinstance(fr, dict) or not isinstance(fr.get("frameBasedMetadataSets", {}), dict):
        raise MetadataError(f"{where} is not a frame object", p)
    sets = fr.get("frameBasedMetadataSets", {})
    lens = sets.get("Lens State") or {}
    focus, why = _focus_mm(p, where, lens)
    iris = lens.get("lensIris")
    tstop = None
    if iris is not None and _int(p, where, "lensIris", iris) > 0:
        tstop = 2.0 ** ((iris - 1000.0) / 2000.0)
    fl = lens.get("lensFocalLength")
    focal = None if fl is None or _int(p, where, "lensFocalLength", fl) <= 0 else fl / 1000.0
    epo = lens.get("lensEntrancePupilOffset")
    pupil = None if epo is None or _int(p, where, "lensEntrancePupilOffset", epo) == -1 else epo / 1000.0
    tc = fr.get("timecode")
    if tc is None and start is not None:
        n = _int(p, where, "frameNo", fr.get("frameNo", i))
        tc = _timecode_text(int(start) + int(n), rate)
    elif tc is not None:
        tc = timecode(p, None, str(tc))
    return FrameSample(line=i, timecode=tc, focus_mm=focus, tstop=tstop, focal_length_mm=focal,
                       entrance_pupil_mm=pupil), why


def _start_frame(p, start, rate: Fraction) -> int:
    """``clipStartFrameNumber``: a whole number of frames since midnight, below a day's at the nominal rate
    (86,400 x 24 at 24 fps); a negative or larger one would wrap to another time of day, so it is refused."""
    day = 86400 * math.ceil(rate - Fraction(1, 10**6))
    if start != int(start) or not 0 <= start < day:
        raise MetadataError(f"Clip Info: clipStartFrameNumber {start!r} is not a frame of the day (a whole number "
                            f"from 0 to {day - 1} at the project rate {float(rate):g} fps): the first frame's "
                            "timecode would wrap to another time", p)
    return int(start)


def _timecode_text(count: int, rate: Fraction) -> str:
    """Non-drop-frame HH:MM:SS:FF of ``count`` frames since midnight at the nominal integer rate."""
    per_s = math.ceil(rate - Fraction(1, 10**6))
    s, f = divmod(count, per_s)
    return f"{(s // 3600) % 24:02d}:{(s // 60) % 60:02d}:{s % 60:02d}:{f:02d}"


def read(path) -> ClipRecord:
    """The clip of one ART JSON export (module notes)."""
    p = Path(path)
    doc = _load(p)
    desc, clip = _sets(p, doc, "descriptiveMetadataSets"), _sets(p, doc, "clipBasedMetadataSets")
    frames = (doc.get("frameBasedMetadata") or {}).get("frames")
    if not isinstance(frames, list) or not frames:
        raise MetadataError("no frameBasedMetadata.frames: no per-frame metadata", p)
    project = clip.get("Project Rate", {})
    rate = _rational(p, "Project Rate", "timebase", project.get("timebase"))
    drop = project.get("dropframe", False)
    if not isinstance(drop, bool):
        raise MetadataError(f"Project Rate: dropframe {str(drop)[:40]!r} is not true or false", p)
    info = clip.get("Clip Info", {})
    start = info.get("clipStartFrameNumber")
    notes = []
    if start is not None and (rate is None or rate <= 0 or drop):
        start = None
        notes.append("no timecode derived: the project rate is missing or drop-frame")
    elif start is not None:
        start = _start_frame(p, _int(p, "Clip Info", "clipStartFrameNumber", start), rate)
    duration = info.get("clipDuration")
    if duration is not None and duration != len(frames):
        raise MetadataError(f"Clip Info says {duration} frames, frameBasedMetadata holds {len(frames)}", p)
    samples, absent = [], {}
    for i, fr in enumerate(frames):
        s, why = _frame(p, i, fr, start, rate)
        samples.append(s)
        if why:
            absent.setdefault(why, []).append(i)
    notes += [f"focus {why} on {len(idx)} of {len(frames)} frames (first: frame {idx[0]}): left absent"
              for why, idx in absent.items()]
    notes.append("read from ARRI Reference Tool JSON; frame N is frameNo N (the line column counts frames)")
    return ClipRecord(source="arri", files=(str(p),), frames=tuple(samples), notes=tuple(notes),
                      drop_frame=drop,
                      **_static(p, desc, clip, frames, rate, doc.get("arriJsonHeader")))


def _clip_of(header) -> str | None:
    """The clip name of the header's ``mxfFileName`` (".../B003C003_180327_R1ZA.%07d.ari")."""
    name = header.get("mxfFileName") if isinstance(header, dict) else None
    return str(name).replace("\\", "/").rsplit("/", 1)[-1].split(".")[0] or None if name else None


def _static(p, desc, clip, frames, rate, doc_header) -> dict:
    cam, lens = desc.get("Camera Device", {}), desc.get("Lens Device", {})
    size = (clip.get("Image Size") or {}).get("storedSize") or {}
    w, h = size.get("width"), size.get("height")
    res = (int(w), int(h)) if isinstance(w, int) and isinstance(h, int) and w > 0 and h > 0 else None
    sensor = (clip.get("Sensor Device") or {}).get("sensorName")
    area = ACTIVE_AREA_MM.get((sensor, *res)) if res else None
    state = ((frames[0] or {}).get("frameBasedMetadataSets") or {}).get("Sensor State") or {}
    exposure = _rational(p, "frame 0", "exposureTime", state.get("exposureTime"))
    sample_rate = _rational(p, "frame 0", "sensorSampleRate", state.get("sensorSampleRate"))
    squeeze = _rational(p, "Lens Device", "lensSqueezeFactor", lens.get("lensSqueezeFactor"))
    iso = state.get("exposureIndex", (clip.get("Sensor State") or {}).get("exposureIndex"))
    model = lens.get("lensModel") or None
    text = lambda v: None if v in (None, "") else str(v)  # noqa: E731
    return {"camera_make": "ARRI", "camera_model": text(cam.get("cameraModel")),
            "camera_serial": text(cam.get("cameraSerialNumber")), "sensor_name": text(sensor),
            "resolution_px": res, "active_area_mm": area,
            "active_area_source": "ARRI ALEXA LF formats and resolutions table" if area else None,
            "lens_make": "ARRI" if model and str(model).startswith("ARRI ") else None, "lens_model": text(model),
            "lens_serial": text(lens.get("lensSerialNumber")),
            "squeeze": None if squeeze is None else float(squeeze),
            "frame_rate": exact_rate(rate),
            "shutter_angle_deg": float(360 * exposure * sample_rate) if exposure and sample_rate else None,
            "exposure_time_s": None if exposure is None else float(exposure),
            "iso": int(_int(p, "Sensor State", "exposureIndex", iso)) if iso is not None else None,
            "clip_name": text((desc.get("Slate Info") or {}).get("clipName")) or _clip_of(doc_header)}

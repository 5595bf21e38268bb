"""RED: REDline's CSV exports, ``--printMeta 3`` (static, one row) and ``--printMeta 5`` (per frame).

Per-frame fields (``--printMeta 5``): ``FrameNo``, ``Timecode`` (HH:MM:SS:FF), ``Aperture`` (the
lens's stop as RED shows it, labelled F in the static export: read as ``fstop``), ``Focus Distance``
(mm, from the film plane), ``Focal Length`` (mm), and ``Cooke Metadata``: the Cooke /i ``Kd``
lens-data bytes as slash-separated hex, decoded by :mod:`.cooke` (its T-stop becomes ``tstop``,
its entrance pupil ``entrance_pupil_mm``). Acceleration and rotation (the camera's IMU) are not read.

Static fields (``--printMeta 3``): ``Clip Name``, ``Camera Model``, ``Camera PIN`` (serial),
``Sensor Name``, ``Frame Width`` / ``Frame Height`` (pixels), ``FPS``, ``Total Frames``,
``Shutter (deg)``, ``Shutter (ms)``, ``ISO``, ``Lens Brand``, ``Lens Name``, ``Lens Serial Number``,
``Pixel Aspect Ratio`` (the squeeze). The recorded pixels are a window of the sensor at its native
photosite pitch (RED's published pitches: MONSTRO 8K VV, HELIUM 8K S35...), which gives
``active_area_mm``.
"""

from __future__ import annotations

from ..errors import MetadataError, require_type
from . import cooke
from ._text import exact_rate, header_columns, lacking_columns, number, require_columns, rows, single_row, timecode
from .record import ClipRecord, FrameSample

__all__ = ["sniff", "read"]

FRAME_COLUMNS = ("FrameNo", "Timecode", "Aperture", "Focus Distance", "Focal Length")
STATIC_COLUMNS = ("Clip Name", "Camera Model", "Sensor Name", "Frame Width", "Frame Height", "FPS")
#: photosite pitch (micrometres) of RED sensors, from RED's published sensor sizes
PITCH_UM = {"MONSTRO 8K VV": 5.0, "HELIUM 8K S35": 3.65, "GEMINI 5K S35": 6.0, "KOMODO 6K S35": 4.4,
            "RAPTOR 8K VV": 5.0, "DRAGON": 5.0}


#: The columns a REDline frames header needs (one of each group), and columns only this layout has
LAYOUT_GROUPS = (("FrameNo",), ("Focus Distance",))
LAYOUT_MARKERS = ("FrameNo",)


def sniff(head: str) -> str | None:
    """"frames" or "static" when ``head`` is a REDline header, else None."""
    require_type("head", head, str, "the first bytes of a metadata file")
    cols = header_columns(head)
    if not lacking_columns(cols, LAYOUT_GROUPS):
        return "frames"
    if "Camera PIN" in cols and "Sensor Name" in cols:
        return "static"
    return None


def _frames(path):
    header, data = rows(path)
    require_columns(path, header, FRAME_COLUMNS, "a REDline --printMeta 5 CSV")
    out = []
    for line, r in data:
        ck = None
        if r.get("Cooke Metadata"):
            ck = cooke.decode(cooke.parse_hex(path, line, r["Cooke Metadata"]), path, line)
        out.append(FrameSample(line=line, timecode=timecode(path, line, r["Timecode"]),
                               focus_mm=number(path, line, "focus distance", r["Focus Distance"]),
                               fstop=number(path, line, "aperture", r["Aperture"]),
                               tstop=None if ck is None else ck.t_stop,
                               focal_length_mm=number(path, line, "focal length", r["Focal Length"]),
                               entrance_pupil_mm=None if ck is None else ck.entrance_pupil_mm, cooke=ck))
    if not out:
        raise MetadataError("no frame rows after the header", path, 2)
    return out


def _static(path) -> dict:
    _, line, r = single_row(path, "a REDline --printMeta 3 CSV", STATIC_COLUMNS)
    g = lambda k: (r.get(k) or "").strip() or None  # noqa: E731
    num = lambda k: number(path, line, k, r.get(k, ""))  # noqa: E731
    w, h, fps = num("Frame Width"), num("Frame Height"), num("FPS")
    res = (int(w), int(h)) if w and h else None
    pitch = PITCH_UM.get(g("Sensor Name") or "")
    total = num("Total Frames")
    return {"clip_name": g("Clip Name"), "camera_model": g("Camera Model"), "camera_serial": g("Camera PIN"),
            "sensor_name": g("Sensor Name"), "resolution_px": res,
            "active_area_mm": (res[0] * pitch / 1000.0, res[1] * pitch / 1000.0) if res and pitch else None,
            "active_area_source": "RED's published photosite pitch of the sensor" if res and pitch else None,
            "lens_make": g("Lens Brand"), "lens_model": g("Lens Name"), "lens_serial": g("Lens Serial Number"),
            "squeeze": num("Pixel Aspect Ratio"), "nominal_focal_length_mm": _mm(path, line, g("Focal Length")),
            "frame_rate": exact_rate(fps) if fps else None,
            "shutter_angle_deg": num("Shutter (deg)"),
            "exposure_time_s": None if num("Shutter (ms)") is None else num("Shutter (ms)") / 1000.0,
            "iso": None if num("ISO") is None else int(num("ISO")),
            "_total": None if total is None else (int(total), line)}


def _mm(path, line, text):
    """"40mm" as 40.0; None when empty."""
    if text is None:
        return None
    return number(path, line, "focal length", text.removesuffix("mm"))


def read(frames_path, static_path=None) -> ClipRecord:
    """The clip of a REDline frames CSV and, when given, its static CSV (module notes)."""
    frames = _frames(frames_path)
    static = _static(static_path) if static_path is not None else {}
    total = static.pop("_total", None)
    if total is not None and total[0] != len(frames):
        raise MetadataError(f"Total Frames says {total[0]}, the frames file {frames_path} has {len(frames)} rows",
                            static_path, total[1])
    files = (str(frames_path),) + ((str(static_path),) if static_path is not None else ())
    return ClipRecord(source="red", files=files, frames=tuple(frames), camera_make="RED",
                      notes=("Aperture (fstop) is REDline's column; tstop and the entrance pupil are the Cooke /i "
                             "lens data's",),
                      **static)

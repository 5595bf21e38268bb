"""A clip's camera metadata in physcam's units: static values and per-frame samples.

Lengths are millimetres, angles degrees, frame rates exact fractions. A value the source file
does not carry is ``None`` (never filled in from a default). Distances are the lens's focus
mark: from the film (image) plane, as lens scales are engraved (docs/conventions.md).
Each reader's module docstring says what its source's fields mean and how they were converted.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field
from fractions import Fraction

__all__ = ["CookeData", "TrackerPose", "FrameSample", "ClipRecord", "timecode_frames"]


@dataclass(frozen=True)
class CookeData:
    """One Cooke /i packed lens-data response (the ``Kd`` command, Cooke /i protocol v3.0 s. 5),
    decoded from its bytes. Distances are the 24-bit fields in the lens's display units (1 mm when
    metric, 0.1 inch when imperial; ``*_mm`` assumes metric, module notes of :mod:`.cooke`);
    ``t_stop`` is the TT field / 100; ``zoom_mm`` is None for a prime (the field is 0)."""

    focus_distance_mm: float | None
    t_stop: float
    zoom_mm: float | None
    hyperfocal_mm: float | None
    near_mm: float | None
    far_mm: float | None
    horizontal_fov_raw: int
    entrance_pupil_mm: float
    normalized_zoom_raw: int
    serial: str | None


@dataclass(frozen=True)
class TrackerPose:
    """A camera tracker's pose for one frame (Mo-Sys F4). ``translation`` (x, y, height) in the
    F4 linear unit / 1000 (module notes of :mod:`.mosys`); ``rotation_deg`` (pan, tilt, roll);
    ``encoders``: normalised lens encoders 0..1 (focus, zoom, iris; None when not sent);
    ``lens_fields``: the float lens fields by F4 axis id name (raw, as sent)."""

    translation: tuple[float, float, float]
    rotation_deg: tuple[float, float, float]
    status: str | None = None
    encoders: dict = field(default_factory=dict)
    lens_fields: dict = field(default_factory=dict)


@dataclass(frozen=True, slots=True)
class FrameSample:
    """One frame: ``line`` is where it is in its file (CSV line, or F4 packet index); ``timecode``
    as the file prints it (HH:MM:SS:FF); ``focus_mm`` from the film plane; ``tstop`` / ``fstop``
    as the file labels them; ``focal_length_mm`` as recorded (a zoom's current focal length)."""

    line: int
    timecode: str | None = None
    focus_mm: float | None = None
    tstop: float | None = None
    fstop: float | None = None
    focal_length_mm: float | None = None
    entrance_pupil_mm: float | None = None
    cooke: CookeData | None = None
    tracker: TrackerPose | None = None


@dataclass(frozen=True)
class ClipRecord:
    """Everything a clip's metadata files say (module notes). ``source``: the reader (arri, red,
    venice, canon, bmd, mosys); ``files``: what was read; ``resolution_px``: the recorded image
    (width, height) in pixels; ``active_area_mm``: the sensor area those pixels cover, when the
    file or the camera maker's published format table gives it (``active_area_source`` says
    which); ``frame_rate``: frames per second; ``drop_frame``: the timecode is counted drop-frame (SMPTE
    ST 12-1; the file says so, or its timecodes carry ``;`` before the frames); ``shutter_angle_deg``; ``squeeze``: anamorphic
    squeeze; ``notes``: what the reader says about its reading."""

    source: str
    files: tuple[str, ...]
    frames: tuple[FrameSample, ...]
    clip_name: str | None = None
    camera_make: str | None = None
    camera_model: str | None = None
    camera_serial: str | None = None
    sensor_name: str | None = None
    resolution_px: tuple[int, int] | None = None
    active_area_mm: tuple[float, float] | None = None
    active_area_source: str | None = None
    lens_make: str | None = None
    lens_model: str | None = None
    lens_serial: str | None = None
    nominal_focal_length_mm: float | None = None
    squeeze: float | None = None
    frame_rate: Fraction | None = None
    drop_frame: bool = False
    shutter_angle_deg: float | None = None
    exposure_time_s: float | None = None
    iso: int | None = None
    notes: tuple[str, ...] = ()

    def static_dict(self) -> dict:
        """The static values as plain JSON types (frame rate as a float and a "num/denom" text)."""
        d = {k: v for k, v in asdict(self).items() if k != "frames"}
        d["files"] = list(self.files)
        d["notes"] = list(self.notes)
        for k in ("resolution_px", "active_area_mm"):
            d[k] = None if d[k] is None else list(d[k])
        fr = self.frame_rate
        d["frame_rate"] = None if fr is None else float(fr)
        d["frame_rate_exact"] = None if fr is None else f"{fr.numerator}/{fr.denominator}"
        d["frame_count"] = len(self.frames)
        return d

    def frame_rows(self) -> list[dict]:
        """One flat dict per frame: the sample's values, then ``cooke_*`` and ``tracker_*`` columns."""
        rows = []
        for i, f in enumerate(self.frames):
            row = {"frame": i, "line": f.line, "timecode": f.timecode, "focus_mm": f.focus_mm, "tstop": f.tstop,
                   "fstop": f.fstop, "focal_length_mm": f.focal_length_mm, "entrance_pupil_mm": f.entrance_pupil_mm}
            if f.cooke is not None:  # a distance at infinity (all bits set) is an empty cell / null
                row.update({f"cooke_{k}": (None if isinstance(v, float) and not math.isfinite(v) else v)
                            for k, v in asdict(f.cooke).items()})
            if f.tracker is not None:
                t = f.tracker
                row.update({"tracker_x": t.translation[0], "tracker_y": t.translation[1],
                            "tracker_height": t.translation[2], "tracker_pan_deg": t.rotation_deg[0],
                            "tracker_tilt_deg": t.rotation_deg[1], "tracker_roll_deg": t.rotation_deg[2],
                            "tracker_status": t.status})
                row.update({f"tracker_encoder_{k}": v for k, v in t.encoders.items()})
                row.update({f"tracker_{k}": v for k, v in t.lens_fields.items()})
            rows.append(row)
        return rows


def timecode_frames(timecode: str, rate) -> int:
    """Frames since 00:00:00:00 of a non-drop-frame ``HH:MM:SS:FF`` timecode at ``rate`` fps
    (the nominal integer rate counts the frames: 23.976 counts 24)."""
    from ..errors import InputError, require_type

    require_type("timecode", timecode, str, '"HH:MM:SS:FF"')
    try:
        h, m, s, f = (int(p) for p in timecode.replace(";", ":").split(":"))
    except ValueError:
        raise InputError(f"timecode {timecode!r} is not HH:MM:SS:FF") from None
    nominal = math.ceil(Fraction(rate) - Fraction(1, 10**6))
    return ((h * 60 + m) * 60 + s) * nominal + f

"""A :class:`~physcam.metadata.record.ClipRecord` as tracked frames, per-frame lens reports, an
animated USD camera and OpenTrackIO samples, through ``physcam.live`` (needs the ``live`` extra;
USD the ``usd`` extra).

* :func:`tracked_frames`: one :class:`~physcam.live.frames.TrackedFrame` per recorded frame, its
  sequence number the frame's index (one USD time sample per frame), the tracker pose (Mo-Sys)
  with its translation read as metres (camdkit's reading of F4).
* :func:`solve`: the on-set lens report of each frame (:func:`physcam.onset.report.solve_lens_report`)
  with the recorded focus mark and stop, on the named lens (its breathing: FOV at the focus) or a
  thin lens of the recorded focal length. When the file gives a T-stop and no f-stop, depth of
  field uses the T-stop as the f-number (the common on-set practice; DOF a little deeper than
  with the true f-number), and each report's notes say so.
* :func:`write_usd`: the solved frames through :func:`physcam.live.record.write_recording_usd`
  (the authoring ``physcam live record`` uses), then the clip and the plate on the camera prim:
  customData ``physcam:source``, ``physcam:clip`` (the static values as JSON text; ``drop_frame`` only
  when true) and
  ``physcam:plate``: a dictionary of ``path`` (as given, a string: a plate that is not there yet or a
  ``####`` sequence pattern is no unresolvable asset for USD's validators) and ``firstFrame`` /
  ``lastFrame``. With a plate frame range the camera is authored on the plate's frame numbers
  (time code ``firstFrame`` + index: frame 1001 of the plate is time code 1001, start and end time
  codes the range), else on the clip's frame indices from 0.
* :func:`opentrackio_samples`: OpenTrackIO 1.0.1 samples, validated against the shipped schema.
  Each sample with a recorded focal length and focus carries ``pinholeFocalLength``: the image
  distance s' of a thin lens of that focal length focused at the mark (s + s' = mark, 1/s + 1/s' =
  1/f; Hecht, *Optics* 5th ed., 5.2.3), the pinhole ``physcam live send --clip`` gives a prime
  through :func:`physcam.live.camera.with_optics`; a zoom's focal length thus reaches every
  sample. The static ``nominalFocalLength`` is the lens's printed focal length: a prime's (one
  focal length over the clip), absent for a zoom (OpenTrackIO 1.0.1: "undefined in the case of a
  zoom lens"). The file's timecodes need a frame rate: a clip with timecodes and no rate (a RED
  frames CSV without its static CSV) is refused unless ``rate`` is given, never sent without them.
"""

from __future__ import annotations

from dataclasses import replace
from fractions import Fraction

from ..errors import InputError, MetadataError, OpticsError, require_type
from .record import ClipRecord, timecode_frames

__all__ = ["tracked_frames", "solve", "write_usd", "opentrackio_samples", "dof_stop"]

TSTOP_AS_F = "depth of field from the recorded T-stop (the file gives no f-stop)"


def _record(record) -> ClipRecord:
    return require_type("record", record, ClipRecord, "physcam.metadata.load(paths)")


def dof_stop(sample, default=None) -> tuple[float | None, str | None]:
    """(f-number for depth of field, note): the f-stop, else the T-stop (noted), else ``default``."""
    from .record import FrameSample

    require_type("sample", sample, FrameSample, "a frame of physcam.metadata.load(paths).frames")
    if sample.fstop is not None:
        return sample.fstop, None
    if sample.tstop is not None:
        return sample.tstop, TSTOP_AS_F
    return default, None


def tracked_frames(record, *, rate=None) -> list:
    """One :class:`~physcam.live.frames.TrackedFrame` per frame (module notes); ``rate`` when the file has none."""
    from ..live.frames import TrackedFrame, rate_fraction

    record = _record(record)
    fr = record.frame_rate if record.frame_rate is not None else (None if rate is None else rate_fraction(rate))
    out = []
    for i, f in enumerate(record.frames):
        t = f.tracker
        out.append(TrackedFrame(
            sequence_number=i, timecode=f.timecode, rate=fr, drop_frame=record.drop_frame,
            translation_m=(0.0, 0.0, 0.0) if t is None else tuple(float(v) for v in t.translation),
            rotation_deg=(0.0, 0.0, 0.0) if t is None else tuple(float(v) for v in t.rotation_deg),
            focus_from_film_mm=f.focus_mm, fstop=f.fstop, tstop=f.tstop, entrance_pupil_mm=f.entrance_pupil_mm,
            sensor_mm=record.active_area_mm, nominal_focal_length_mm=record.nominal_focal_length_mm,
            source_id=f"physcam:metadata:{record.source}:{record.clip_name or 'clip'}", source_number=1))
    return out


def _sensor_of(record, sensor):
    from ..optics.sensors import Sensor, custom_sensor

    if record.active_area_mm is not None:
        return custom_sensor(*record.active_area_mm)
    if sensor is None:
        raise InputError(f"the {record.source} file gives no sensor size; give the sensor (--sensor)")
    return require_type("sensor", sensor, Sensor, "physcam.optics.sensors.find_sensor(name)")


def solve(record, *, sensor=None, lens=None, coc=None, focal_length_mm=None, fstop=None, rate=None) -> list:
    """Each frame with its lens report, as :class:`physcam.live.record.SolvedFrame` (module notes).

    ``sensor``: when the file gives no sensor area; ``lens``: a Prescription (its breathing),
    else a thin lens of the recorded focal length (``focal_length_mm`` when the file has none);
    ``fstop``: when the file has no stop. A frame without a focus distance is refused."""
    record = _record(record)
    s = _sensor_of(record, sensor)
    frames = tracked_frames(record, rate=rate)
    squeeze = record.squeeze if record.squeeze else 1.0
    import warnings

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        out = _solve_frames(record, frames, s, lens, coc, focal_length_mm, fstop, squeeze)
    _warn_once(caught)
    return out


def _warn_once(caught) -> None:
    """Re-issue the warnings of many frames once each kind (the first 40 characters), with a count."""
    import warnings

    kinds: dict = {}
    for w in caught:
        kinds.setdefault((w.category, str(w.message)[:40]), []).append(w)
    for (cat, _), ws in kinds.items():
        more = f" (and {len(ws) - 1} more frames like it)" if len(ws) > 1 else ""
        warnings.warn(f"{ws[0].message}{more}", cat, stacklevel=3)


def _solve_frames(record, frames, s, lens, coc, focal_length_mm, fstop, squeeze):
    from ..onset.report import report_camera, solve_report

    from ..live.record import SolvedFrame

    cache: dict = {}
    out = []
    for i, (f, tf) in enumerate(zip(record.frames, frames)):
        where = f"{record.files[0]}: frame {i} (line {f.line})"
        n, note = dof_stop(f, fstop)
        focal = None if lens is not None else (f.focal_length_mm or record.nominal_focal_length_mm or focal_length_mm)
        missing = [w for w, v in (("focus distance", f.focus_mm), ("stop (give --fstop)", n),
                                  ("focal length (give --focal or --lens)", focal if lens is None else 1.0)) if v is None]
        if missing:
            raise MetadataError(f"frame {i} records no {' and no '.join(missing)}", record.files[0],
                                f.line if record.source != "mosys" else None)
        tstop = f.tstop if f.tstop is not None and f.tstop >= n else None
        key = (f.focus_mm, n, tstop, focal, f.entrance_pupil_mm)
        if key not in cache:
            try:
                cache[key] = solve_report(report_camera(
                    focal_length_mm=focal, sensor=s, fstop=n, focus_mm=f.focus_mm, coc=coc, tstop=tstop,
                    squeeze=squeeze, lens=lens,
                    pupil_mm=None if lens is not None else f.entrance_pupil_mm))
            except (InputError, OpticsError) as exc:
                raise type(exc)(f"{where}: {exc}") from None
        report = cache[key]
        if note:
            report = replace(report, notes=tuple(report.notes) + (note,))
        defaulted = tuple(n for n, v in (("fStop", f.fstop is None and f.tstop is None),
                                         ("pinholeFocalLength", lens is None and f.focal_length_mm is None
                                          and record.nominal_focal_length_mm is None)) if v)
        out.append(SolvedFrame(tf, float(i), report, (), defaulted, squeeze=squeeze))
    return out


def _plate_dict(plate, plate_frames):
    if plate is None:
        if plate_frames is not None:
            raise InputError("--plate-frames needs --plate PATH")
        return None
    d = {"path": str(plate)}
    if plate_frames is not None:
        a, b = plate_frames
        if b < a:
            raise InputError(f"plate frames {a}-{b}: the last frame is before the first")
        d["firstFrame"], d["lastFrame"] = int(a), int(b)
    return d


def write_usd(file, record, solved, *, plate=None, plate_frames=None, meters_per_unit: float = 0.01,
              path: str = "/Cameras/Camera", force: bool = False):
    """The solved frames (:func:`solve`) as one animated PhysicalCamera and companion camera, with
    the clip and plate on the camera prim (module notes); return the Path."""
    import json
    import tempfile
    from pathlib import Path

    from .. import usd as _usd  # noqa: F401  (one line naming the 'usd' extra when usd-core is missing)

    from pxr import Usd

    from ..export._codetext import printable_line
    from ..io import check_writable
    from ..usd_names import usd_layer_format
    from ..live.record import write_recording_usd
    from ..usd.author import save_stage

    record = _record(record)
    plate_d = _plate_dict(plate, plate_frames)
    if plate_d and "firstFrame" in plate_d and plate_d["lastFrame"] - plate_d["firstFrame"] + 1 != len(solved):
        n = plate_d["lastFrame"] - plate_d["firstFrame"] + 1
        raise InputError(f"the plate's {n} frames do not match the clip's {len(solved)} frames")
    p = check_writable(file, force=force)
    usd_layer_format(p)
    rate = solved[0].frame.rate if solved else None
    if plate_d and "firstFrame" in plate_d:  # the plate's frame numbers are the time codes
        solved = [replace(s, time_code=float(plate_d["firstFrame"] + i)) for i, s in enumerate(solved)]
    with tempfile.TemporaryDirectory(prefix="physcam-metadata-") as tmp:
        first = write_recording_usd(Path(tmp) / "take.usda", solved, rate=rate, meters_per_unit=meters_per_unit,
                                    path=path)
        stage = Usd.Stage.Open(str(first))
        cam = stage.GetPrimAtPath(path)
        cam.SetCustomDataByKey("physcam:source", printable_line(f"{record.source} camera metadata read by physcam "
                                                                f"metadata usd ({', '.join(Path(f).name for f in record.files)})"))
        # values the file gives; drop_frame only when true (a non-drop clip's camera stays as before round 22)
        static = {k: v for k, v in record.static_dict().items()
                  if v is not None and k != "notes" and (k != "drop_frame" or v)}
        cam.SetCustomDataByKey("physcam:clip", json.dumps(static, sort_keys=True))
        if plate_d:
            cam.SetCustomDataByKey("physcam:plate", plate_d)
        return save_stage(stage, p, force=force)


def _timecode(tc: str, rate: Fraction, drop_frame: bool = False) -> dict | None:
    """OpenTrackIO's timecode object of the file's ``HH:MM:SS:FF`` (None above 120 fps), with
    ``dropFrame`` true when the clip's timecode is drop-frame (OpenTrackIO 1.0.1 ``timing.timecode``)."""
    if tc is None or rate is None or rate > 120:
        return None
    h, m, s, f = (int(x) for x in tc.replace(";", ":").split(":"))
    out = {"hours": h, "minutes": m, "seconds": s, "frames": f,
           "frameRate": {"num": rate.numerator, "denom": rate.denominator}}
    if drop_frame:
        out["dropFrame"] = True
    return out


def opentrackio_samples(record, *, rate=None) -> list[dict]:
    """The clip as OpenTrackIO 1.0.1 samples (the first with the static block), each validated
    against the shipped schema; the file's timecodes, its focal length as each sample's pinhole,
    its lens encoders (Mo-Sys) and its identity (module notes)."""
    from ..live.frames import sample_from_frame
    from ..live.sample import validate_sample

    record = _record(record)
    frames = tracked_frames(record, rate=rate)
    fr = frames[0].rate if frames else None
    if fr is None and any(f.timecode is not None for f in record.frames):
        raise MetadataError(f"the {record.source} clip records timecodes but no frame rate, and OpenTrackIO's "
                            "timecode needs one: give the frame rate (--fps), or the file that carries it (a RED "
                            "clip's --printMeta 3 static CSV)", record.files[0])
    if fr is not None and fr > 120 and any(f.timecode is not None for f in record.frames):
        raise MetadataError(f"the clip's frame rate {float(fr):g} fps is above OpenTrackIO's timecode rates "
                            "(120 fps at most): its timecodes cannot be sent", record.files[0])
    static = _static(record, fr) if frames else None
    out = []
    for i, (f, tf) in enumerate(zip(record.frames, frames)):
        tf = replace(tf, pinhole_focal_length_mm=_pinhole(record, i, f))
        s = sample_from_frame(tf, source_id=_source_urn(record), sequence_number=i,
                              static=static if i == 0 else None, status=f"physcam metadata ({record.source})")
        tc = _timecode(f.timecode, tf.rate, record.drop_frame)
        if tc is not None:
            s["timing"]["timecode"] = tc
        elif "timecode" in s["timing"]:
            del s["timing"]["timecode"]  # the file gave none: never one counted from zero
        if f.tracker is not None and f.tracker.encoders:
            s["lens"]["encoders"] = dict(f.tracker.encoders)
        if f.tracker is not None and f.tracker.status:
            s["tracker"]["status"] = f.tracker.status
        out.append(validate_sample(s))
    return out


def _pinhole(record, i, f) -> float | None:
    """The pinhole of a thin lens of the frame's focal length focused at its mark (module notes), or None."""
    from ..optics.thinlens import image_distance, object_distance_for_marked

    focal = f.focal_length_mm
    if focal is None or f.focus_mm is None:
        return None
    try:
        return float(image_distance(focal, object_distance_for_marked(focal, f.focus_mm)))
    except (InputError, OpticsError) as exc:
        raise MetadataError(f"frame {i}: a {focal:g} mm lens cannot focus at the recorded {f.focus_mm:g} mm ({exc})",
                            record.files[0], f.line if record.source != "mosys" else None) from None


def _source_urn(record) -> str:
    import uuid

    return f"urn:uuid:{uuid.uuid5(uuid.NAMESPACE_URL, 'physcam-metadata:' + '|'.join(record.files))}"


def _static(record, rate):
    from ..live.frames import static_block

    focals = {f.focal_length_mm for f in record.frames} - {None}
    # the printed focal length of a prime; a zoom (the focal length changes over the clip) has none
    nominal = None if len(focals) > 1 else (record.nominal_focal_length_mm or (focals.pop() if focals else None))
    if record.active_area_mm is None or rate is None:
        out = {}
        if nominal is not None or record.lens_model:
            out["lens"] = {}
    else:
        out = static_block(sensor_mm=record.active_area_mm, rate=rate, lens_name=record.lens_model,
                           nominal_focal_length_mm=nominal, squeeze=record.squeeze or 1.0,
                           shutter_angle_deg=record.shutter_angle_deg, resolution=record.resolution_px,
                           label=record.clip_name)
    cam = out.setdefault("camera", {})
    for key, v in (("make", record.camera_make), ("model", record.camera_model),
                   ("serialNumber", record.camera_serial)):
        if v:
            cam[key] = str(v)[:1023]
    lens = out.setdefault("lens", {})
    for key, v in (("make", record.lens_make), ("model", record.lens_model), ("serialNumber", record.lens_serial)):
        if v:
            lens[key] = str(v)[:1023]
    if nominal is not None:
        lens["nominalFocalLength"] = float(nominal)
    out.setdefault("tracker", {"make": "physcam", "model": "physcam metadata"})
    return {k: v for k, v in out.items() if v}


def frame_count_from_timecodes(record) -> int | None:
    """Frames spanned by the first and last timecode (inclusive), or None without both or a rate."""
    r = _record(record)
    a, b = r.frames[0].timecode, r.frames[-1].timecode
    if a is None or b is None or r.frame_rate is None:
        return None
    return timecode_frames(b, r.frame_rate) - timecode_frames(a, r.frame_rate) + 1

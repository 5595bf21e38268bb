"""OpenTrackIO samples from physcam's own camera and lens: a take, frame by frame.

For each frame the lens is solved at that frame's focus mark and f-stop
(:func:`physcam.onset.report.solve_lens_report`; with a prescription its Gaussian optics focused
there, so the pinhole focal length breathes and the entrance pupil moves) and the sample carries:
``pinholeFocalLength`` (the best-match pinhole, mm), ``focusDistance`` (the mark from the film plane,
m), ``fStop`` and ``tStop``, ``entrancePupilOffset`` (m in front of the film; an anamorphic's vertical
pupil, its horizontal one in ``custom``, :mod:`physcam.live.frames`), the distortion of a
prescription at that focus (:func:`physcam.live.lens_data.distortion_for_sample`), timing (exact
timestamps at the frame rate, timecode from a start label, drop-frame when asked, sequence number) and
the camera transform. The ``static`` block (sensor size, capture rate, anamorphic squeeze, lens,
tracker) rides on the first sample, once a second after, and whenever the squeeze changes.

Anamorphic lenses: ``pinholeFocalLength`` is the **vertical** pinhole F (the unsqueezed meridian) and
``static.camera.anamorphicSqueeze`` the lens's effective squeeze at that focus (F_y / F_x, which
breathes a little), so the horizontal focal length a consumer computes, F / squeeze, frames the
width as :func:`physcam.analysis.breathing` does (Unreal's CineCamera takes the filmback width times
its squeeze factor over the focal length). Lens shift: ``shift_mm`` (physcam's convention, + right
and + up: the view moves that way, as ``report --shift-x/--shift-y``) is sent as
``lens.projectionOffset`` = (-shift_x, +shift_y), OpenLensIO's perspective offset ΔP: where the
optical axis lands on the sensor, mm from the centre, x right, y down (OpenLensIO 1.0.1 section
1.5); ``distortionOffset`` (ΔC) is 0 because physcam's distortion is centred on that axis.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from fractions import Fraction

from ..errors import InputError, require_finite, require_type
from .frames import HORIZONTAL_PUPIL_KEY, TrackedFrame, new_source_id, rate_fraction, sample_from_frame, static_block, with_time
from .sample import shown

__all__ = ["CameraMove", "camera_frames", "camera_samples", "frames_to_samples", "with_optics"]

#: the most frames one generated take holds (an hour at 240 fps is 864,000; a demo needs far fewer)
MAX_TAKE_FRAMES = 1_000_000


@dataclass(frozen=True)
class CameraMove:
    """A simple move, linear in time: the film plane starts at ``start_m`` (OpenTrackIO stage, metres,
    Z up) and travels at ``velocity_m_s``; the camera starts at ``start_deg`` (pan, tilt, roll) and
    turns at ``rate_deg_s``."""

    start_m: tuple[float, float, float] = (0.0, 0.0, 1.5)
    velocity_m_s: tuple[float, float, float] = (0.0, 0.0, 0.0)
    start_deg: tuple[float, float, float] = (0.0, 0.0, 0.0)
    rate_deg_s: tuple[float, float, float] = (0.0, 0.0, 0.0)

    def at(self, t_s: float):
        pos = tuple(float(a + v * t_s) for a, v in zip(self.start_m, self.velocity_m_s))
        rot = tuple(float(a + v * t_s) for a, v in zip(self.start_deg, self.rate_deg_s))
        return pos, rot


def camera_frames(*, sensor, frames: int, rate, focus_mm, fstop=None, lens=None, focal_length_mm=None,
                  focus_to_mm=None, tstop=None, move: CameraMove | None = None, distortion: bool = True,
                  t0_ns: int | None = None, shift_mm=(0.0, 0.0), drop_frame: bool = False) -> list[TrackedFrame]:
    """The take's frames (module notes): ``frames`` frames at ``rate``, focus pulled linearly from
    ``focus_mm`` to ``focus_to_mm`` (mm from the film; default: held), ``lens`` (a Prescription) or a
    thin lens of ``focal_length_mm``; ``t0_ns`` the first timestamp (default now); ``shift_mm`` the
    lens shift (+ right, + up); ``drop_frame``: drop-frame timecode (29.97, 59.94)."""
    from ..optics.sensors import Sensor

    require_type("sensor", sensor, Sensor, "physcam.optics.sensors.find_sensor(name)")
    if isinstance(frames, bool) or not isinstance(frames, int) or not 1 <= frames <= MAX_TAKE_FRAMES:
        raise InputError(f"frames must be a whole number 1..{MAX_TAKE_FRAMES}, got {shown(frames)}")
    fr = rate_fraction(rate)
    move = CameraMove() if move is None else require_type("move", move, CameraMove)
    if (lens is None) == (focal_length_mm is None):
        raise InputError("give either a lens prescription or a focal length")
    f0 = require_finite("focus distance", focus_mm)
    f1 = f0 if focus_to_mm is None else require_finite("focus distance to pull to", focus_to_mm)
    from .frames import _pair, timecode_fields

    sx, sy = _pair("lens shift (mm)", shift_mm)
    offsets = {} if sx == 0.0 and sy == 0.0 else {"projection_offset_mm": (-sx, sy), "distortion_offset_mm": (0.0, 0.0)}
    if drop_frame:
        timecode_fields(0, fr, drop_frame=True)  # refuses a rate without drop-frame counting
    t0 = time.time_ns() if t0_ns is None else int(t0_ns)
    out: list[TrackedFrame] = []
    cache: dict = {}
    for i in range(frames):
        u = i / (frames - 1) if frames > 1 else 0.0
        mark = f0 + (f1 - f0) * u
        if mark not in cache:
            cache[mark] = _optics_at(sensor, mark, lens, focal_length_mm, fstop, tstop, distortion)
        rep, dist = cache[mark]
        pos, rot = move.at(i / float(fr))
        pupil = rep.entrance_pupil_from_film_mm
        out.append(with_time(TrackedFrame(
            squeeze=float(rep.pinhole[1]), drop_frame=bool(drop_frame), **offsets, rate=fr, translation_m=pos, rotation_deg=rot, pinhole_focal_length_mm=rep.pinhole[0],
            focus_from_film_mm=rep.focus_from_film_mm, fstop=rep.fstop, tstop=rep.tstop,
            entrance_pupil_mm=pupil if pupil is not None else rep.h1_from_film_mm, distortion=dist,
            entrance_pupil_horizontal_mm=rep.entrance_pupil_horizontal_from_film_mm,
            sensor_mm=(sensor.width_mm, sensor.height_mm),
            nominal_focal_length_mm=rep.focal_length_mm), t0, i))
    return out


def _optics_at(sensor, mark, lens, focal_length_mm, fstop, tstop, distortion):
    """(lens report, OpenTrackIO distortion or None) of the lens (or thin lens) focused at ``mark``."""
    from ..onset.report import report_camera, solve_report

    rep = solve_report(report_camera(focal_length_mm=focal_length_mm, sensor=sensor, fstop=fstop, focus_mm=mark,
                        tstop=tstop, lens=lens))
    dist = None
    if lens is not None and distortion:
        from .lens_data import distortion_for_sample

        dist, _ = distortion_for_sample(lens, sensor.width_mm, sensor.height_mm, mark)
    return rep, dist


def with_optics(samples, *, lens=None, focal_length_mm=None, distortion: bool = True):
    """Yield ``samples`` (OpenTrackIO dicts, e.g. a recorded clip's,
    :func:`physcam.metadata.convert.opentrackio_samples`) with the optics of ``lens`` (a
    Prescription) or a thin lens of ``focal_length_mm`` at each sample's ``focusDistance``, as
    :func:`camera_frames` sends them: ``pinholeFocalLength``, ``entrancePupilOffset``, the lens's
    distortion and (a lens) its squeeze (``static`` re-sent when it changes). The sensor is the
    stream's ``static.camera.activeSensorPhysicalDimensions``; a sample without a focus distance is
    passed on as it is. The pinhole and pupil do not depend on the stop: the lens is solved wide
    open (a thin lens at f/8) and the sample's own stops are sent unchanged."""
    from ..optics.sensors import custom_sensor

    if (lens is None) == (focal_length_mm is None):
        raise InputError("give either a lens prescription or a focal length")
    static, sent_squeeze, cache = None, None, {}
    for s in samples:
        static = s.get("static") or static
        dims = ((static or {}).get("camera") or {}).get("activeSensorPhysicalDimensions")
        lens_d = s.get("lens") or {}
        if dims is None or "focusDistance" not in lens_d:
            yield s
            continue
        mark = lens_d["focusDistance"] * 1000.0
        key = (dims["width"], dims["height"], mark)
        if key not in cache:  # a lens wide open, a thin lens at f/8: the stop changes neither pinhole nor pupil
            cache[key] = _optics_at(custom_sensor(dims["width"], dims["height"]), mark, lens, focal_length_mm,
                                    None if lens is not None else 8.0, None, distortion)
        rep, dist = cache[key]
        out = dict(s, lens=dict(lens_d, pinholeFocalLength=float(rep.pinhole[0])))
        pupil = rep.entrance_pupil_from_film_mm if rep.entrance_pupil_from_film_mm is not None else rep.h1_from_film_mm
        out["lens"]["entrancePupilOffset"] = float(pupil) / 1000.0
        prior = s.get("custom")
        if prior is None or isinstance(prior, dict):  # this lens's pupils replace the ones the clip carried
            custom = {k: v for k, v in (prior or {}).items() if k != HORIZONTAL_PUPIL_KEY}
            if rep.entrance_pupil_horizontal_from_film_mm is not None:  # an anamorphic's pan pivot (frames.py)
                custom[HORIZONTAL_PUPIL_KEY] = float(rep.entrance_pupil_horizontal_from_film_mm) / 1000.0
            if custom or prior is not None:
                out["custom"] = custom
        if dist is not None:
            out["lens"]["distortion"] = [dist]
        sq = Fraction(float(rep.pinhole[1])).limit_denominator(1_000_000)  # as static_block keeps it
        squeeze = {"num": sq.numerator, "denom": sq.denominator}
        if lens is not None and squeeze != sent_squeeze:  # a thin lens keeps the stream's squeeze
            cam = dict(static["camera"], anamorphicSqueeze=squeeze)
            out["static"] = dict(out.get("static") or static, camera=cam)
            static, sent_squeeze = out["static"], squeeze
        yield out


def frames_to_samples(frames, *, source_id: str | None = None, static_every: int | None = None,
                      lens_name: str | None = None, shutter_angle_deg: float | None = None, start_timecode: int = 0):
    """Yield an OpenTrackIO sample per frame (:func:`physcam.live.frames.sample_from_frame`), with the
    ``static`` block on the first and every ``static_every``-th sample (default: once a second) and
    whenever the frame's anamorphic squeeze differs from the last one sent; the timecode starts
    ``start_timecode`` timecode frames after midnight (:func:`physcam.live.frames.parse_timecode`)."""
    sid = new_source_id() if source_id is None else source_id
    sent_squeeze = None
    for i, f in enumerate(frames):
        require_type("frame", f, TrackedFrame)
        every = static_every if static_every is not None else max(1, math.ceil(float(f.rate or 24)))
        static = None
        squeeze = 1.0 if f.squeeze is None else f.squeeze
        if (i % every == 0 or squeeze != sent_squeeze) and f.sensor_mm is not None:
            static = static_block(sensor_mm=f.sensor_mm, rate=f.rate or 24, lens_name=lens_name,
                                  nominal_focal_length_mm=f.nominal_focal_length_mm, squeeze=squeeze,
                                  shutter_angle_deg=shutter_angle_deg)
            sent_squeeze = squeeze
        yield sample_from_frame(f, source_id=sid, sequence_number=i % 2**32, frame_index=i, static=static,
                                start_timecode=start_timecode)


def camera_samples(**kwargs) -> list[dict]:
    """The samples of :func:`camera_frames` (same keywords) as a list of dicts."""
    lens = kwargs.get("lens")
    name = getattr(lens, "name", None)
    start = kwargs.pop("start_timecode", 0)
    return list(frames_to_samples(camera_frames(**kwargs), lens_name=name, start_timecode=start))

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

A zoom lens (docs/zoom.md) is taken at each frame's zoom position (:func:`physcam.lens.zoom.prescription_at`),
moved linearly in physcam's encoder u from ``zoom`` to ``zoom_to`` as a zoom motor runs, and focused
there: ``pinholeFocalLength`` is that position's best-match pinhole at the frame's focus, the
zoom encoder rides in ``lens.encoders.zoom`` (OpenTrackIO's 0 wide, 1 tele: u or 1 - u, whichever
end is wide), and ``static`` carries no ``nominalFocalLength`` (undefined for a zoom in the schema)
but the focal length range in the sample's ``custom`` (:data:`physcam.live.frames.FOCAL_RANGE_KEY`).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from fractions import Fraction

from ..errors import InputError, require_finite, require_type
from ..lens.prescription import require_prescription, takes_prescription
from ..lens.zoom import prescription_at
from .frames import FOCAL_RANGE_KEY, HORIZONTAL_PUPIL_KEY, TrackedFrame, new_source_id, rate_fraction, sample_from_frame, static_block, with_time
from .sample import shown

__all__ = ["CameraMove", "camera_frames", "camera_samples", "frames_to_samples", "with_optics", "zoom_path",
           "opentrackio_zoom", "physcam_zoom", "focal_range"]

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
                  t0_ns: int | None = None, shift_mm=(0.0, 0.0), drop_frame: bool = False, zoom=None,
                  zoom_to=None) -> list[TrackedFrame]:
    """The take's frames (module notes): ``frames`` frames at ``rate``, focus pulled linearly from
    ``focus_mm`` to ``focus_to_mm`` (mm from the film; default: held), ``lens`` (a Prescription) or a
    thin lens of ``focal_length_mm``; ``t0_ns`` the first timestamp (default now); ``shift_mm`` the
    lens shift (+ right, + up); ``drop_frame``: drop-frame timecode (29.97, 59.94); a zoom lens's
    ``zoom`` (a focal length ``"135mm"`` or encoder value, :func:`physcam.optics.zoom.zoom_encoder`;
    default its first tabulated position) zoomed linearly in the encoder to ``zoom_to`` (module notes)."""
    from ..optics.sensors import Sensor

    require_type("sensor", sensor, Sensor, "physcam.optics.sensors.find_sensor(name)")
    if isinstance(frames, bool) or not isinstance(frames, int) or not 1 <= frames <= MAX_TAKE_FRAMES:
        raise InputError(f"frames must be a whole number 1..{MAX_TAKE_FRAMES}, got {shown(frames)}")
    fr = rate_fraction(rate)
    move = CameraMove() if move is None else require_type("move", move, CameraMove)
    if (lens is None) == (focal_length_mm is None):
        raise InputError("give either a lens prescription or a focal length")
    u0, u1 = zoom_path(lens, zoom, zoom_to)
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
        zu = None if u0 is None else u0 + (u1 - u0) * u
        if (mark, zu) not in cache:
            cache[mark, zu] = _optics_at(sensor, mark, lens if zu is None else prescription_at(lens, zu),
                                         focal_length_mm, fstop, tstop, distortion)
        rep, dist = cache[mark, zu]
        zoomed = {} if zu is None else {"encoders": {"zoom": opentrackio_zoom(lens, zu)},
                                         "focal_range_mm": focal_range(lens)}
        pos, rot = move.at(i / float(fr))
        pupil = rep.entrance_pupil_from_film_mm
        out.append(with_time(TrackedFrame(
            squeeze=float(rep.pinhole[1]), drop_frame=bool(drop_frame), **offsets, rate=fr, translation_m=pos, rotation_deg=rot, pinhole_focal_length_mm=rep.pinhole[0],
            focus_from_film_mm=rep.focus_from_film_mm, fstop=rep.fstop, tstop=rep.tstop,
            entrance_pupil_mm=pupil if pupil is not None else rep.h1_from_film_mm, distortion=dist,
            entrance_pupil_horizontal_mm=rep.entrance_pupil_horizontal_from_film_mm,
            sensor_mm=(sensor.width_mm, sensor.height_mm), **zoomed,
            nominal_focal_length_mm=None if zu is not None else rep.focal_length_mm), t0, i))
    return out


def zoom_path(lens, zoom, zoom_to) -> tuple[float | None, float | None]:
    """(first, last) encoder value of a zoom lens's move (None, None for a prime; :func:`camera_frames`)."""
    if lens is not None:
        require_prescription(lens)
    if lens is None or lens.zoom is None:
        if zoom is not None or zoom_to is not None:
            what = "a thin lens" if lens is None else repr(lens.name)
            raise InputError(f"a zoom position needs a zoom lens; {what} has no zoom table (docs/zoom.md)")
        return None, None
    from ..optics.zoom import zoom_encoder

    u0 = zoom_encoder(lens, 0.0 if zoom is None else zoom)
    return u0, u0 if zoom_to is None else zoom_encoder(lens, zoom_to)


@takes_prescription
def _wide_end_first(lens) -> bool:
    """True when the zoom lens's encoder 0 (its first tabulated position) is its wide end."""
    from ..optics.zoom import efl_at

    return efl_at(lens, 0.0) < efl_at(lens, 1.0)


@takes_prescription
def opentrackio_zoom(lens, encoder: float) -> float:
    """OpenTrackIO's ``lens.encoders.zoom`` (0 wide angle, 1 telephoto; schema 1.0.1) of the zoom lens at
    physcam's encoder value (0 its first tabulated position, docs/zoom.md)."""
    u = float(encoder)
    return u if _wide_end_first(lens) else 1.0 - u


@takes_prescription
def physcam_zoom(lens, opentrackio_encoder: float) -> float:
    """physcam's encoder value of OpenTrackIO's zoom encoder (the inverse of :func:`opentrackio_zoom`)."""
    return opentrackio_zoom(lens, opentrackio_encoder)


@takes_prescription
def focal_range(lens) -> tuple[float, float]:
    """(shortest, longest) paraxial EFL of a zoom lens at infinity focus (mm; at its two ends, the EFL
    running monotonically along the zoom, :func:`physcam.optics.zoom.encoder_for_focal_length`)."""
    from ..optics.zoom import efl_at

    a, b = efl_at(lens, 0.0), efl_at(lens, 1.0)
    return (min(a, b), max(a, b))


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


def with_optics(samples, *, lens=None, focal_length_mm=None, distortion: bool = True, zooms=None):
    """Yield ``samples`` (OpenTrackIO dicts, e.g. a recorded clip's,
    :func:`physcam.metadata.convert.opentrackio_samples`) with the optics of ``lens`` (a
    Prescription) or a thin lens of ``focal_length_mm`` at each sample's ``focusDistance``, as
    :func:`camera_frames` sends them: ``pinholeFocalLength``, ``entrancePupilOffset``, the lens's
    distortion and (a lens) its squeeze (``static`` re-sent when it changes). The sensor is the
    stream's ``static.camera.activeSensorPhysicalDimensions``; a sample without a focus distance is
    passed on as it is. The pinhole and pupil do not depend on the stop: the lens is solved wide
    open (a thin lens at f/8) and the sample's own stops are sent unchanged.

    A zoom ``lens`` is taken at each sample's zoom position: ``zooms``, one per sample (a focal length
    ``"135mm"`` or an encoder value, :func:`physcam.optics.zoom.zoom_encoder`; None: its first
    tabulated position), sent as ``lens.encoders.zoom`` with the focal length range in ``custom``
    beside ``static`` (module notes)."""
    from ..optics.sensors import custom_sensor

    if (lens is None) == (focal_length_mm is None):
        raise InputError("give either a lens prescription or a focal length")
    zoom_lens = lens is not None and getattr(lens, "zoom", None) is not None
    if zooms is not None and not zoom_lens:
        zoom_path(lens, "zoom", None)  # refuses zoom positions for a prime, in its words
    zooms = iter(zooms) if zooms is not None else None
    static, sent_squeeze, cache = None, None, {}
    encoders: dict = {}  # a clip's zoom positions, each solved once for the samples that repeat it
    for s in samples:
        zu = None
        if zoom_lens:
            z = next(zooms, None) if zooms is not None else None
            if not isinstance(z, (str, float, int, type(None))) or isinstance(z, bool):
                zu = zoom_path(lens, z, None)[0]  # refuses it, in its words
            elif (type(z), z) not in encoders:  # 1 and "1" are two forms: each its own entry
                zu = encoders[type(z), z] = zoom_path(lens, z, None)[0]
            else:
                zu = encoders[type(z), z]
        static = s.get("static") or static
        dims = ((static or {}).get("camera") or {}).get("activeSensorPhysicalDimensions")
        lens_d = s.get("lens") or {}
        if dims is None or "focusDistance" not in lens_d:
            yield s
            continue
        mark = lens_d["focusDistance"] * 1000.0
        key = (dims["width"], dims["height"], mark, zu)
        if key not in cache:  # a lens wide open, a thin lens at f/8: the stop changes neither pinhole nor pupil
            cache[key] = _optics_at(custom_sensor(dims["width"], dims["height"]), mark,
                                    lens if zu is None else prescription_at(lens, zu), focal_length_mm,
                                    None if lens is not None else 8.0, None, distortion)
        rep, dist = cache[key]
        out = dict(s, lens=dict(lens_d, pinholeFocalLength=float(rep.pinhole[0])))
        if zu is not None:
            out["lens"]["encoders"] = dict(lens_d.get("encoders") or {}, zoom=opentrackio_zoom(lens, zu))
        pupil = rep.entrance_pupil_from_film_mm if rep.entrance_pupil_from_film_mm is not None else rep.h1_from_film_mm
        out["lens"]["entrancePupilOffset"] = float(pupil) / 1000.0
        prior = s.get("custom")
        if prior is None or isinstance(prior, dict):  # this lens's pupils replace the ones the clip carried
            custom = {k: v for k, v in (prior or {}).items() if k != HORIZONTAL_PUPIL_KEY}
            if rep.entrance_pupil_horizontal_from_film_mm is not None:  # an anamorphic's pan pivot (frames.py)
                custom[HORIZONTAL_PUPIL_KEY] = float(rep.entrance_pupil_horizontal_from_film_mm) / 1000.0
            if zu is not None and s.get("static"):
                custom[FOCAL_RANGE_KEY] = list(focal_range(lens))
            if custom or prior is not None:
                out["custom"] = custom
        if zu is not None and "nominalFocalLength" in ((out.get("static") or {}).get("lens") or {}):
            out["static"] = _without_nominal(out["static"])  # a zoom has none (schema 1.0.1)
        if dist is not None:
            out["lens"]["distortion"] = [dist]
        sq = Fraction(float(rep.pinhole[1])).limit_denominator(1_000_000)  # as static_block keeps it
        squeeze = {"num": sq.numerator, "denom": sq.denominator}
        if lens is not None and squeeze != sent_squeeze:  # a thin lens keeps the stream's squeeze
            cam = dict(static["camera"], anamorphicSqueeze=squeeze)
            out["static"] = dict(out.get("static") or static, camera=cam)
            static, sent_squeeze = out["static"], squeeze
        yield out


def _without_nominal(static: dict) -> dict:
    """``static`` without ``lens.nominalFocalLength`` (and without an emptied ``lens``)."""
    lens = {k: v for k, v in static["lens"].items() if k != "nominalFocalLength"}
    out = {k: v for k, v in static.items() if k != "lens"}
    if lens:
        out["lens"] = lens
    return out


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

"""``physcam live``: OpenTrackIO camera tracking in and out, recording to USD, the LED-wall frustum (docs/live.md)."""

from __future__ import annotations

import sys

from ._common import distance, focal_length, focus, number, numbers, usd_file, whole
from ._live_record import resolve_sensor_opt as _resolve_sensor_opt
from ._live_record import source_id
from ._output import add_output_options, document, emit_json

EPILOG = """\
examples:
  physcam live validate take.json sample.cbor
  physcam live record --port 55555 --duration 30 take.usda --report take.csv
  physcam live send --lens dgauss_50mm --sensor "ALEXA 35" --focus 2m --focus-to 5m --fstop 2.8 --frames 96
  physcam live send --lens navarro_anamorphic_2x --focus 3m --fps 29.97 --timecode "01:00:00;00" --print
  physcam live record take.usda --lens dgauss_50mm --fiz fiz.csv --count 48
  physcam live recover take.usda.journal
  physcam live play take.usda --port 55555
  physcam live send --clip tests/data/camera-metadata/arri/B001C001_180327_R1ZA.mov.csv --frames 2 --print
  physcam live play --clip tests/data/camera-metadata/arri/B001C001_180327_R1ZA.mov.csv --rate 0
  physcam live wall wall.usda --kind curved --radius 8 --width 14
  physcam live frustum take.usda --wall wall.usda frustum.usda --overscan 10 --latency-ms 40
  physcam live frustum take.usda --wall wall.usda frustum.usda --overscan 10 --overscan-mode ndisplay
Receivers stop after --duration seconds or --count samples, or on Ctrl-C, SIGTERM or SIGHUP; the file is\nwritten then. While it records, the take is kept in a journal beside the file (take.usda.journal):\nphyscam live recover writes a take whose recorder was killed or whose disk was full.
"""


def _port(text):
    import argparse

    try:
        v = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"port must be a whole number 0..65535, got {text!r}") from None
    if not 0 <= v <= 65535:
        raise argparse.ArgumentTypeError(f"port must be a whole number 0..65535, got {text!r}")
    return v


def _count(text):
    import argparse

    try:
        v = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"count must be a whole number >= 1, got {text!r}") from None
    if not 1 <= v <= 10_000_000:
        raise argparse.ArgumentTypeError(f"count must be a whole number 1..10000000, got {text!r}")
    return v


def _network_args(p, *, receive: bool) -> None:
    p.add_argument("--port", type=_port, default=55555,
                   help="UDP port (default 55555, OpenTrackIO's)" + ("; 0: a free one, said on stderr" if receive else ""))
    p.add_argument("--multicast", type=whole("multicast source number", lo=0), default=None, metavar="N",
                   help="use the multicast group 239.135.1.N of source number N instead of unicast")
    p.add_argument("--interface", default="127.0.0.1",
                   help="network interface address for multicast (default 127.0.0.1, the loopback)")
    if receive:
        p.add_argument("--host", default="0.0.0.0", help="unicast address to listen on (default all)")
        p.add_argument("--modulus", choices=("256", "255", "auto"), default="256",
                       help="Fletcher-16 modulus: 256 (current reference code, default), 255 (1.0.0 page), auto")
    else:
        p.add_argument("--host", default="127.0.0.1", help="unicast destination (default 127.0.0.1)")
        p.add_argument("--cbor", action="store_true", help="send CBOR payloads (default JSON)")
    p.add_argument("--duration", type=number("duration", lo=0.0, hi=86400.0), default=None, metavar="S",
                   help="stop after S seconds (default: receivers run until Ctrl-C or --count)")


def _sensor_args(p) -> None:
    p.add_argument("--sensor", help="sensor name (see physcam sensors)")
    p.add_argument("--sensor-width", type=distance("sensor width"), help="sensor width, with --sensor-height")
    p.add_argument("--sensor-height", type=distance("sensor height"), help="sensor height, with --sensor-width")


def _clip_arg(p) -> None:
    p.add_argument("--clip", nargs="+", metavar="FILE",
                   help="a recorded clip's camera metadata files (ARRI, RED, VENICE, Canon, Blackmagic, Mo-Sys; "
                        "docs/camera-metadata.md), sent frame by frame at its frame rate with its timecodes")


def _record_parser(s) -> None:
    r = s.add_parser("record", help="record a stream into a time-sampled USD camera (and a lens report)")
    r.add_argument("file", type=usd_file, help="output .usda/.usd/.usdc")
    _network_args(r, receive=True)
    r.add_argument("--count", type=_count, default=None, help="stop once the source recorded has this many samples")
    r.add_argument("--report", metavar="FILE", help="also write the per-frame lens report (.csv or .json)")
    _sensor_args(r)
    r.add_argument("--focal", type=focal_length(), help="pinhole focal length when the stream has none")
    r.add_argument("--lens", help="bundled lens name or prescription file: a frame without a pinhole focal length "
                                  "is solved through it at its focus (breathing, entrance pupil, squeeze)")
    r.add_argument("--fiz", metavar="CSV", help="encoder calibration table (axis,encoder,value rows; docs/live.md): "
                                                "lens.encoders to focus, f-stop and focal length")
    r.add_argument("--fstop", type=number("f-stop", positive=True), help="f-stop when the stream has none")
    r.add_argument("--focus", type=focus("focus distance", allow_inf=False),
                   help="focus mark when the stream has none (units ok; hyperfocal with --focal and --fstop)")
    r.add_argument("--fps", type=number("frame rate", positive=True, hi=1000.0),
                   help="time codes per second (default: the stream's sample rate)")
    r.add_argument("--meters-per-unit", type=number("meters per unit", positive=True), default=0.01,
                   help="stage unit (default 0.01: centimetres)")
    r.add_argument("--path", default="/Cameras/Camera", help="camera prim path")
    r.add_argument("--source", type=source_id, metavar="ID",
                   help="record the source with this sourceId (urn:uuid:...; default: the source that sent the "
                        "most samples, the first heard of those tied); the others are named in the summary")
    r.add_argument("--force", action="store_true", help="overwrite existing files")
    add_output_options(r, what="the summary")
    r.set_defaults(handler=run_record, output_args=("file", "report"))


def _recover_parser(s) -> None:
    rc = s.add_parser("recover", help="write the take an unfinished journal holds (a recorder killed, a full disk)",
                      description="Write the take kept in a journal (FILE.journal, written beside the output while "
                                  "physcam live record runs) as live record would have: the USD camera and the "
                                  "report it names, under their names or the first free ones beside them. The "
                                  "options given override the recording's own (docs/live.md).")
    rc.add_argument("journal", help="the journal, e.g. take.usda.journal")
    rc.add_argument("-o", "--output", dest="file", default=None, type=usd_file,
                    help="output .usda/.usd/.usdc (default: the recording's, beside the journal)")
    rc.add_argument("--report", metavar="FILE", help="the lens report (default: the recording's, if it asked one)")
    _sensor_args(rc)
    rc.add_argument("--focal", type=focal_length(), help="pinhole focal length when the stream has none")
    rc.add_argument("--lens", help="bundled lens name or prescription file (as live record)")
    rc.add_argument("--fiz", metavar="CSV", help="encoder calibration table (as live record)")
    rc.add_argument("--fstop", type=number("f-stop", positive=True), help="f-stop when the stream has none")
    rc.add_argument("--focus", type=focus("focus distance", allow_inf=False), help="focus mark when the stream has none")
    rc.add_argument("--fps", type=number("frame rate", positive=True, hi=1000.0), help="time codes per second")
    rc.add_argument("--meters-per-unit", type=number("meters per unit", positive=True), default=None,
                    help="stage unit (default: the recording's)")
    rc.add_argument("--path", default=None, help="camera prim path (default: the recording's)")
    rc.add_argument("--source", type=source_id, metavar="ID", help="record this sourceId (default: the recording's rule)")
    rc.add_argument("--force", action="store_true", help="overwrite existing files")
    add_output_options(rc, what="the summary")
    rc.set_defaults(handler=run_recover, output_args=("file", "report"))


def register(sub) -> None:
    import argparse

    p = sub.add_parser("live", help="OpenTrackIO camera tracking: validate, record to USD, send, LED-wall frustum",
                       description="Live camera metadata (OpenTrackIO 1.0.1): validate samples, record a stream "
                                   "as a time-sampled USD camera with a per-frame lens report, send physcam's camera "
                                   "or a recording out, and the LED wall's inner frustum (docs/live.md).",
                       epilog=EPILOG, formatter_class=argparse.RawDescriptionHelpFormatter)
    s = p.add_subparsers(dest="live_command", metavar="ACTION")

    v = s.add_parser("validate", help="validate OpenTrackIO samples (JSON or CBOR files) against the 1.0.1 schema")
    v.add_argument("files", nargs="+", help="sample files: .json (one sample, or one per line) or .cbor")
    add_output_options(v, what="the results")
    v.set_defaults(handler=run_validate)

    _record_parser(s)
    _recover_parser(s)

    se = s.add_parser("send", help="stream physcam's camera and lens as OpenTrackIO (a focus pull, a pan), or a "
                                   "recorded clip's camera metadata")
    _clip_arg(se)
    se.add_argument("--lens", help="bundled lens name or prescription file (breathing, pupil, distortion)")
    se.add_argument("--focal", type=focal_length(), help="or a thin lens of this focal length")
    from ._common import add_sensor_options

    add_sensor_options(se)
    se.add_argument("--focus", type=focus("focus distance", allow_inf=False), default=None,
                    help="focus mark (default 3m; units ok; or hyperfocal at --fstop)")
    se.add_argument("--focus-to", type=focus("focus distance to pull to", allow_inf=False),
                    help="pull focus to this mark (units ok; or hyperfocal)")
    se.add_argument("--zoom", default=None, metavar="POSITION",
                    help="a zoom lens's position: a focal length with its unit (135mm, the paraxial EFL) or the "
                         "encoder value 0..1 (default: its first tabulated position; a clip: each frame's "
                         "recorded focal length, this where it records none)")
    se.add_argument("--zoom-to", default=None, metavar="POSITION",
                    help="zoom to this position over the take, linearly in the encoder (docs/zoom.md)")
    se.add_argument("--fstop", type=number("f-stop", positive=True), help="f-stop (a lens: default wide open)")
    se.add_argument("--tstop", type=number("T-stop", positive=True), help="marked T-stop")
    se.add_argument("--fps", type=number("frame rate", positive=True, hi=1000.0), default=None,
                    help="sample rate (default 24, a clip's own; 23.976 is 24000/1001)")
    se.add_argument("--frames", type=_count, default=None,
                    help="samples in the take (default 48; a clip: all its frames, or its first N)")
    se.add_argument("--position", type=numbers("position", 3), default=(0.0, 0.0, 1.5), metavar="X,Y,Z",
                    help="film plane on the stage, metres, Z up (default 0,0,1.5)")
    se.add_argument("--pan-rate", type=number("pan rate", lo=-3600.0, hi=3600.0), default=0.0,
                    help="degrees per second")
    se.add_argument("--shift-x", metavar="MM", type=distance("horizontal lens shift"), default=0.0,
                    help="lens shift on the film (mm; + right), sent as projectionOffset")
    se.add_argument("--shift-y", metavar="MM", type=distance("vertical lens shift"), default=0.0,
                    help="lens shift on the film (mm; + up; write negative values as --shift-y=-0.8)")
    se.add_argument("--timecode", default=None, metavar="HH:MM:SS:FF",
                    help="timecode of the first sample (default 00:00:00:00; ';' before FF for drop-frame)")
    se.add_argument("--drop-frame", action="store_true",
                    help="drop-frame timecode (29.97 and 59.94 fps; sets timecode.dropFrame)")
    se.add_argument("--print", action="store_true", help="print the samples as JSON lines instead of sending")
    _network_args(se, receive=False)
    se.set_defaults(handler=run_send)

    pl = s.add_parser("play", help="send a recorded USD camera or a lens report back out as OpenTrackIO")
    pl.add_argument("file", nargs="?", help="a USD file with a PhysicalCamera, or a lens report .json written by "
                                           "record (or --clip)")
    _clip_arg(pl)
    pl.add_argument("--lens", help="with --clip: bundled lens name or prescription file (breathing, pupil, distortion)")
    pl.add_argument("--focal", type=focal_length(), help="with --clip: or a thin lens of this focal length")
    pl.add_argument("--zoom", default=None, metavar="POSITION",
                    help="with --clip and a zoom --lens: the position of frames that record no focal length")
    pl.add_argument("--path", default=None, help="camera prim path (default: the only PhysicalCamera)")
    pl.add_argument("--rate", type=number("rate", lo=0.0, hi=100000.0), default=None,
                    help="samples per second (default the file's rate; 0 as fast as possible)")
    _sensor_args(pl)
    _network_args(pl, receive=False)
    pl.set_defaults(handler=run_play)

    w = s.add_parser("wall", help="write an LED wall mesh (flat or curved) for the frustum")
    w.add_argument("file", type=usd_file, help="output .usda/.usd/.usdc")
    w.add_argument("--kind", choices=("flat", "curved"), default="flat", help="flat plane or cylinder arc")
    w.add_argument("--width", type=number("width", positive=True, hi=1000.0), default=12.0,
                   help="metres (a curved wall: arc length)")
    w.add_argument("--height", type=number("height", positive=True, hi=1000.0), default=5.0, help="metres")
    w.add_argument("--distance", type=number("distance", positive=True, hi=1000.0), default=6.0,
                   help="flat: metres in front of the stage origin (+Y)")
    w.add_argument("--radius", type=number("radius", positive=True, hi=1000.0), default=8.0,
                   help="curved: metres from the stage origin")
    w.add_argument("--segments", type=_count, default=96, help="curved: facets along the arc (default 96)")
    w.add_argument("--meters-per-unit", type=number("meters per unit", positive=True), default=0.01,
                   help="stage unit (default 0.01)")
    w.add_argument("--force", action="store_true", help="overwrite")
    w.set_defaults(handler=run_wall, output_args=("file",))

    f = s.add_parser("frustum", help="the LED wall's inner frustum per frame of a tracked camera")
    f.add_argument("camera", help="a USD file with the tracked PhysicalCamera (e.g. from live record)")
    f.add_argument("output", help="output .usda/.usd/.usdc (projection camera and footprint polygon)")
    f.add_argument("--wall", required=True, help="USD file with the LED wall mesh")
    f.add_argument("--wall-path", default=None, help="the wall's Mesh prim path (default: the only Mesh)")
    f.add_argument("--path", default=None, help="camera prim path (default: the only PhysicalCamera)")
    f.add_argument("--overscan", type=number("overscan", lo=0.0, hi=1000.0), default=10.0, metavar="PCT",
                   help="inner frustum margin, percent of the half-widths (default 10)")
    f.add_argument("--overscan-mode", choices=("tangent", "ndisplay"), default="tangent",
                   help="tangent: the half-widths' tangents grow by the overscan (OpenLensIO's image-plane "
                        "overscan, default); ndisplay: the half-angles grow by it, as Unreal's nDisplay does")
    f.add_argument("--latency-ms", type=number("latency", lo=0.0, hi=10000.0), default=0.0,
                   help="tracking latency: half-angles widen by the camera's turn in this time")
    f.add_argument("--samples-per-edge", type=_count, default=8, help="footprint points per frame edge (1..256)")
    f.add_argument("--force", action="store_true", help="overwrite")
    add_output_options(f, what="the per-frame footprints")
    f.set_defaults(handler=run_frustum)

    p.set_defaults(handler=lambda args: p.print_help() or 0)


# --- validate ------------------------------------------------------------------------------
def _read_samples(path):
    """(label, payload bytes, encoding) of each sample in a file: .cbor one CBOR item; JSON one
    object, or one per line."""
    from pathlib import Path

    from ..errors import InputError

    p = Path(path)
    try:
        data = p.read_bytes()
    except OSError as exc:
        raise InputError(f"cannot read {p}: {exc.strerror or exc}") from None
    if len(data) > 64 * 1024 * 1024:
        raise InputError(f"{p}: larger than 64 MiB")
    if p.suffix.lower() == ".cbor":
        return [(str(p), data, "cbor")]
    text = data.strip()
    lines = text.splitlines()
    if len(lines) > 1 and all(x.strip().startswith(b"{") and x.strip().endswith(b"}") for x in lines if x.strip()):
        return [(f"{p}:{i}", x, "json") for i, x in enumerate(lines, start=1) if x.strip()]
    return [(str(p), data, "json")]


def run_validate(args) -> int:
    _needs_live()
    from ..errors import InputError
    from ..live.sample import SampleError, decode_sample
    results = []
    for f in args.files:
        for label, payload, enc in _read_samples(f):
            try:
                decode_sample(payload, enc)
                results.append({"sample": label, "valid": True, "problems": []})
            except SampleError as exc:
                results.append({"sample": label, "valid": False, "problems": [p.to_dict() for p in exc.problems]})
    bad = sum(not r["valid"] for r in results)
    if args.json:
        emit_json(document("live_validate", {"samples": results, "invalid": bad}, units={}))
    else:
        for r in results:
            print(f"{r['sample']}: {'valid' if r['valid'] else 'INVALID'}")
            for pr in r["problems"]:
                print(f"  {pr['path']}: {pr['message']} (rule: {pr['rule']})")
    if bad:
        raise InputError(f"{bad} of {len(results)} samples are not valid OpenTrackIO 1.0.1")
    return 0


# --- record --------------------------------------------------------------------------------
def _needs_live() -> None:
    """The OpenTrackIO commands need the 'live' extra (schema validation, CBOR): say so up front."""
    from ..extras import require_extra

    require_extra("live", "OpenTrackIO (physcam live)")


def _needs_usd(what: str) -> None:
    """Say up front, in one line, that a command writing or reading USD needs the 'usd' extra (before a
    take is received or any work is done)."""
    from ..extras import require_extra

    require_extra("usd", what)


def run_record(args) -> int:
    _needs_live()
    _needs_usd("recording a take to USD (physcam live record)")
    from ._live_record import run_record as record

    return record(args)


def run_recover(args) -> int:
    _needs_live()
    _needs_usd("recovering a take to USD (physcam live recover)")
    from ._live_record import run_recover as recover

    return recover(args)


# --- send and play ---------------------------------------------------------------------------
def _sender(args):
    from ..live.receiver import multicast_group
    from ..live.sender import Sender

    host = multicast_group(args.multicast) if args.multicast is not None else args.host
    return Sender(host, args.port, encoding="cbor" if args.cbor else "json", interface=args.interface)


def _stream(args, samples, rate) -> int:
    """Send (or with --print, write) ``samples`` at ``rate``; with --multicast N each is of source number N, the
    number OpenTrackIO ties to the group 239.135.1.N (a sample said source 1 whatever group it went to)."""
    import json

    if getattr(args, "multicast", None) is not None:
        samples = ({**sm, "sourceNumber": args.multicast} for sm in samples)
    if getattr(args, "print", False):
        n = 0
        for sm in samples:
            sys.stdout.write(json.dumps(sm, separators=(",", ":"), allow_nan=False) + "\n")
            n += 1
        return n
    if args.port == 0:
        from ..errors import InputError

        raise InputError("the destination port must be 1..65535")
    with _sender(args) as snd:
        n = snd.stream(samples, rate, duration_s=args.duration)
    print(f"sent {n} samples to {snd.host}:{snd.port}", file=sys.stderr)
    return n


def _clip_samples(args) -> tuple[list, float]:
    """(samples, frame rate) of the ``--clip`` files (:func:`physcam.metadata.convert.opentrackio_samples`),
    with the optics of ``--lens`` or a thin lens of ``--focal`` (else of the clip's nominal focal
    length) at each frame's focus (:func:`physcam.live.camera.with_optics`)."""
    import dataclasses

    from ..errors import InputError
    from ..live.camera import with_optics
    from ..metadata import load
    from ..metadata.convert import opentrackio_samples

    if args.lens is not None and args.focal is not None:
        raise InputError("give either --lens or --focal, not both")
    record = load(args.clip)
    sensor = _resolve_sensor_opt(args)
    if record.active_area_mm is None and sensor is not None:
        record = dataclasses.replace(record, active_area_mm=(sensor.width_mm, sensor.height_mm))
    samples = opentrackio_samples(record, rate=getattr(args, "fps", None))
    rate = samples[0]["timing"].get("sampleRate") if samples else None
    if rate is None:
        raise InputError(f"the {record.source} clip gives no frame rate; give it (--fps)")
    if getattr(args, "frames", None) is not None:
        samples = samples[: args.frames]
    lens = focal = None
    if args.lens:
        from ..lens.library import load_lens

        lens = load_lens(args.lens)
    else:
        focal = args.focal or samples[0].get("static", {}).get("lens", {}).get("nominalFocalLength")
    if lens is not None or focal is not None:
        samples = with_optics(samples, lens=lens, focal_length_mm=focal,
                              zooms=clip_zooms(record, lens, getattr(args, "zoom", None), len(samples)))
    return samples, rate["num"] / rate["denom"]


def clip_zooms(record, lens, fallback, count: int):
    """The zoom position of each of a clip's first ``count`` frames on the zoom ``lens``: its recorded
    focal length (the paraxial EFL, docs/zoom.md), else ``fallback`` (``--zoom``); None for a prime."""
    from ..errors import InputError

    if getattr(lens, "zoom", None) is None:
        if fallback is not None:
            raise InputError("--zoom takes a zoom lens (--lens NAME of a zoom; docs/zoom.md)")
        return None
    return [fallback if f.focal_length_mm is None else f"{f.focal_length_mm!r}mm" for f in record.frames[:count]]


#: send's options that describe a generated take: a clip brings its own
_TAKE_OPTIONS = (("focus", "--focus"), ("focus_to", "--focus-to"), ("fstop", "--fstop"), ("tstop", "--tstop"),
                 ("timecode", "--timecode"), ("drop_frame", "--drop-frame"), ("pan_rate", "--pan-rate"),
                 ("shift_x", "--shift-x"), ("shift_y", "--shift-y"), ("zoom_to", "--zoom-to"))


def _send_clip(args) -> int:
    from ..errors import InputError

    given = [flag for name, flag in _TAKE_OPTIONS if getattr(args, name) not in (None, False, 0.0)]
    if args.position != (0.0, 0.0, 1.5):
        given.append("--position")
    if given:
        raise InputError(f"{', '.join(given)} describe a generated take; --clip sends the clip's own values")
    samples, rate = _clip_samples(args)
    _stream(args, samples, rate)
    return 0


def run_send(args) -> int:
    _needs_live()
    from ..errors import InputError
    from ..live.camera import CameraMove, camera_frames, frames_to_samples
    from .report import resolve_sensor

    if args.clip:
        return _send_clip(args)
    args.focus = 3000.0 if args.focus is None else args.focus
    args.fps = 24.0 if args.fps is None else args.fps
    args.frames = 48 if args.frames is None else args.frames
    args.timecode = "00:00:00:00" if args.timecode is None else args.timecode
    if (args.lens is None) == (args.focal is None):
        raise InputError("give either --lens or --focal")
    lens = None
    if args.lens:
        from ..lens.library import load_lens

        lens = load_lens(args.lens)
    if args.duration is not None:  # do not build frames that would never be sent
        args.frames = max(1, min(args.frames, int(args.duration * args.fps) + 1))
    if args.frames > 100_000:
        raise InputError("at most 100000 frames per take from the command line")
    move = CameraMove(start_m=args.position, rate_deg_s=(args.pan_rate, 0.0, 0.0))
    sensor = resolve_sensor(args)
    from ._common import resolve_focus

    args.focus, args.focus_to = (resolve_focus(v, lens=lens, focal_length_mm=args.focal, fstop=args.fstop,
                                               sensor=sensor, args=args) for v in (args.focus, args.focus_to))
    from ..live.frames import parse_timecode

    drop = args.drop_frame or ";" in args.timecode
    start = parse_timecode(args.timecode, args.fps, drop)
    frames = camera_frames(sensor=sensor, frames=args.frames, rate=args.fps, focus_mm=args.focus,
                           focus_to_mm=args.focus_to, fstop=args.fstop, tstop=args.tstop, lens=lens,
                           focal_length_mm=args.focal, move=move, shift_mm=(args.shift_x, args.shift_y),
                           drop_frame=drop, zoom=args.zoom, zoom_to=args.zoom_to)
    samples = frames_to_samples(frames, lens_name=getattr(lens, "name", None), start_timecode=start)
    _stream(args, samples, float(frames[0].rate))
    return 0


def _frames_from_report(path):
    import json
    from fractions import Fraction

    from ..errors import InputError
    from ..live.frames import TrackedFrame, rate_fraction

    try:
        doc = json.loads(open(path, encoding="utf-8").read())
    except (OSError, ValueError) as exc:
        raise InputError(f"{path}: not a lens report JSON ({exc})") from None
    if not isinstance(doc, dict) or doc.get("schema") != "physcam.live_lens_report" or not isinstance(
            doc.get("frames"), list) or not doc["frames"]:
        raise InputError(f"{path}: not a lens report written by physcam live record")
    out = []
    rows = doc["frames"]
    try:
        r = doc.get("rate")
        rate = rate_fraction(Fraction(int(r["num"]), int(r["denom"])) if isinstance(r, dict) else 24)
        sensor = doc.get("sensor_mm")
        sensor = (float(sensor[0]), float(sensor[1])) if isinstance(sensor, list) and len(sensor) == 2 else None
        for r in rows:
            out.append(TrackedFrame(
                time_ns=int(round(float(r["time_code"]) / float(rate) * 1e9)), rate=Fraction(rate),
                timecode=r.get("timecode"), sequence_number=r.get("sequence_number"),
                translation_m=(float(r["x_m"]), float(r["y_m"]), float(r["z_m"])),
                rotation_deg=(float(r["pan_deg"]), float(r["tilt_deg"]), float(r["roll_deg"])),
                pinhole_focal_length_mm=float(r["pinhole_focal_length_mm"]),
                focus_from_film_mm=float(r["focus_from_film_mm"]), fstop=float(r["fstop"]),
                tstop=None if r.get("tstop") is None else float(r["tstop"]),
                entrance_pupil_mm=None if r.get("entrance_pupil_from_film_mm") is None
                else float(r["entrance_pupil_from_film_mm"]), sensor_mm=sensor))
    except (KeyError, TypeError, ValueError) as exc:
        raise InputError(f"{path}: a frame lacks {exc}") from None
    return out


def run_play(args) -> int:
    _needs_live()
    import dataclasses

    from ..errors import InputError
    from ..live.camera import frames_to_samples

    if (args.file is None) == (args.clip is None):
        raise InputError("give the file to play, or a clip's metadata files with --clip")
    if args.clip:
        samples, rate = _clip_samples(args)
        _stream(args, samples, rate if args.rate is None else args.rate)
        return 0
    if args.lens is not None or args.focal is not None or args.zoom is not None:
        raise InputError("--lens, --focal and --zoom go with --clip: a recording carries its own lens values")
    name = str(args.file).lower()
    if name.endswith((".usda", ".usd", ".usdc")):
        from ..live.usd_io import frames_from_usd

        frames = frames_from_usd(args.file, args.path)
    elif name.endswith(".json"):
        frames = _frames_from_report(args.file)
    else:
        raise InputError(f"{args.file}: play reads a USD camera (.usda/.usd/.usdc) or a lens report (.json)")
    sensor = _resolve_sensor_opt(args)
    if sensor is not None:
        frames = [dataclasses.replace(f, sensor_mm=(sensor.width_mm, sensor.height_mm)) for f in frames]
    rate = float(frames[0].rate or 24) if args.rate is None else args.rate
    _stream(args, frames_to_samples(frames), rate)
    return 0


# --- wall and frustum -------------------------------------------------------------------------
def run_wall(args) -> int:
    _needs_usd("an LED wall mesh (physcam live wall)")
    from ..live.frustum import write_wall

    if args.segments > 4096:
        from ..errors import InputError

        raise InputError("at most 4096 segments")
    out = write_wall(args.file, kind=args.kind, width_m=args.width, height_m=args.height, distance_m=args.distance,
                     radius_m=args.radius, segments=args.segments, meters_per_unit=args.meters_per_unit,
                     force=args.force)
    print(f"wrote {out}")
    return 0


def run_frustum(args) -> int:
    _needs_usd("the inner frustum (physcam live frustum)")
    from ..errors import InputError
    from ..live.frustum import MAX_SAMPLES_PER_EDGE, frustum_frames, wall_from_usd, write_frustum_usd
    from ..live.usd_io import frames_from_usd

    if args.samples_per_edge > MAX_SAMPLES_PER_EDGE:
        raise InputError(f"at most {MAX_SAMPLES_PER_EDGE} samples per edge")
    from ..io import check_writable

    check_writable(args.output, force=args.force)
    frames = frames_from_usd(args.camera, args.path)
    wall = wall_from_usd(args.wall, args.wall_path)
    fr = frustum_frames(frames, wall, overscan=args.overscan / 100.0, latency_s=args.latency_ms / 1000.0,
                        samples_per_edge=args.samples_per_edge, overscan_mode=args.overscan_mode)
    rate = float(frames[0].rate or 24)
    out = write_frustum_usd(args.output, fr, meters_per_unit=wall.meters_per_unit, fps=min(rate, 1000.0),
                            force=args.force)
    missed = sum(f.missed for f in fr)
    if args.json:
        emit_json(document("live_frustum", {
            "file": str(out), "overscan_mode": args.overscan_mode,
            "frames": [{"time_code": f.time_code, "widen": list(f.widen),
                                          "latency_margin_deg": f.pad_deg, "missed_rays": f.missed,
                                          "footprint": f.footprint.tolist()} for f in fr]},
            units={"length": "scene units of the wall's stage", "angle": "degree"}))
    else:
        print(f"wrote the inner frustum of {len(fr)} frames to {out}"
              + (f"; {missed} edge rays missed the wall" if missed else ""))
    return 0

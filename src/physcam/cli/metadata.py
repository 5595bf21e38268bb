"""``physcam metadata``: camera metadata recorded with real clips (docs/camera-metadata.md)."""

from __future__ import annotations

from ._common import LENS_HELP, add_sensor_options, add_units_option, focal_length, number, usd_file
from ._output import add_output_options, document, emit_json
from .report import add_coc_option

EPILOG = """\
examples:
  physcam metadata show B001C001_180327_R1ZA.mov.csv
  physcam metadata show A001_C066_0303LZ_001.frames.csv A001_C066_0303LZ_001.static.csv --json
  physcam metadata report B001C001_180327_R1ZA.mov.csv --csv
  physcam metadata usd B001C001_180327_R1ZA.mov.csv -o shot.usda --plate plates/B001C001.####.exr --plate-frames 1001-1500
  physcam metadata opentrackio B001C001_180327_R1ZA.mov.csv -o take.jsonl
  physcam metadata opentrackio zoom_clip.csv --lens canon_ef_70_200mm_f2_8_zoom -o take.jsonl
Formats are told from the files' content: ARRI Meta Extract, REDline, Sony VENICE, Canon,
Blackmagic RAW ExtractMetadata, Mo-Sys F4. Give the files of one clip together.
"""


def _frame_range(text):
    import argparse

    a, sep, b = str(text).partition("-")
    try:
        first, last = int(a), int(b)
    except ValueError:
        raise argparse.ArgumentTypeError(f"plate frames must be FIRST-LAST (1001-1500), got {text!r}") from None
    if not sep or first < 0 or last < first:
        raise argparse.ArgumentTypeError(f"plate frames must be FIRST-LAST with FIRST <= LAST, got {text!r}")
    return first, last


def _clip_args(p) -> None:
    p.add_argument("clip", nargs="+", metavar="FILE",
                   help="the clip's metadata file(s): one export, or the files of one clip together")


def _solve_args(p) -> None:
    p.add_argument("--lens", default=None, metavar="NAME_OR_FILE",
                   help=LENS_HELP + "; optional: without it a thin lens of the recorded focal length")
    add_sensor_options(p)
    p.add_argument("--focal", type=focal_length(), default=None,
                   help="focal length when the file records none (mm, or with units)")
    p.add_argument("--fstop", type=number("f-stop", positive=True), default=None,
                   help="f-stop when the file records no stop")
    p.add_argument("--fps", type=number("frame rate", positive=True, hi=1000.0), default=None,
                   help="frame rate when the file records none")
    add_coc_option(p)


def register(sub) -> None:
    import argparse

    p = sub.add_parser("metadata", help="camera metadata of real clips: show, lens report, USD, OpenTrackIO",
                       description="Read the per-frame lens metadata cameras record (ARRI, RED with Cooke /i, Sony "
                                   "VENICE, Canon, Blackmagic RAW, Mo-Sys F4) and turn it into lens reports, an "
                                   "animated USD camera or OpenTrackIO samples (docs/camera-metadata.md).",
                       epilog=EPILOG, formatter_class=argparse.RawDescriptionHelpFormatter)
    s = p.add_subparsers(dest="metadata_command", metavar="ACTION")

    sh = s.add_parser("show", help="the clip's static values and per-frame samples")
    _clip_args(sh)
    add_output_options(sh, csv=True, what="the clip")
    sh.set_defaults(handler=run_show)

    r = s.add_parser("report", help="the on-set lens report of every frame (DOF, hyperfocal, FOV with breathing)")
    _clip_args(r)
    _solve_args(r)
    add_units_option(r)
    add_output_options(r, csv=True, what="the report")
    r.set_defaults(handler=run_report)

    u = s.add_parser("usd", help="one animated PhysicalCamera (focus and iris pulls, breathing, tracker pose)")
    _clip_args(u)
    u.add_argument("-o", "--output", dest="file", required=True, type=usd_file, help="output .usda/.usd/.usdc")
    _solve_args(u)
    u.add_argument("--plate", default=None, metavar="PATH", help="the plate (image sequence or movie) shot with it")
    u.add_argument("--plate-frames", type=_frame_range, default=None, metavar="FIRST-LAST",
                   help="the plate's frame range (one plate frame per clip frame; the first at time code 0)")
    u.add_argument("--meters-per-unit", type=number("meters per unit", positive=True), default=0.01,
                   help="stage unit (default 0.01: centimetres)")
    u.add_argument("--force", action="store_true", help="overwrite an existing file")
    add_output_options(u, what="the file written")
    u.set_defaults(handler=run_usd, output_args=("file",))

    o = s.add_parser("opentrackio", help="the samples as OpenTrackIO 1.0.1 JSON, validated")
    _clip_args(o)
    o.add_argument("-o", "--output", dest="file", default=None,
                   help="write the samples here, one JSON sample per line (default: standard output)")
    o.add_argument("--fps", type=number("frame rate", positive=True, hi=1000.0), default=None,
                   help="frame rate when the file records none")
    o.add_argument("--lens", default=None, metavar="NAME_OR_FILE",
                   help=LENS_HELP + "; optional: its optics at each frame's focus (a zoom: at each frame's recorded "
                                    "focal length), as physcam live send --clip sends them")
    o.add_argument("--zoom", default=None, metavar="POSITION",
                   help="with a zoom --lens: the position of frames that record no focal length (135mm or 0..1)")
    add_sensor_options(o)
    o.add_argument("--force", action="store_true", help="overwrite an existing file")
    o.set_defaults(handler=run_opentrackio, output_args=("file",))
    p.set_defaults(handler=lambda args: p.print_help() or 0)


def _load(args):
    from ..errors import InputError
    from ..metadata import load

    rec = load(args.clip)
    fps = getattr(args, "fps", None)
    if fps is not None and rec.frame_rate is not None and abs(float(rec.frame_rate) - fps) > 1e-3:
        # --fps stands in for a rate the file lacks; over a recorded one it would be silently ignored
        raise InputError(f"the {rec.source} file records {float(rec.frame_rate):g} fps, not --fps {fps:g}; drop --fps")
    return rec


def _clip(rec) -> str:
    """The clip as a title names it: arri clip B001C001, or canon clip when the files name none (not
    "canon clip : ...")."""
    return f"{rec.source} clip" + (f" {rec.clip_name}" if rec.clip_name else "")


def clip_notes(per_frame) -> list[str]:
    """The notes of a clip's frames (one tuple a frame), one per kind: notes that differ only in their
    numbers (the diffraction note's working f-number along a focus pull) are one note, the first such
    frame's, saying on how many frames it came in how many versions (a 500-frame clip printed 21
    diffraction notes)."""
    import re

    def kind(note: str) -> str:
        return re.sub(r"\d+(?:\.\d+)?", "#", note)

    first: dict[str, str] = {}
    versions: dict[str, set] = {}
    frames: dict[str, int] = {}
    for notes in per_frame:
        for k in {kind(n) for n in notes}:
            frames[k] = frames.get(k, 0) + 1
        for n in notes:
            first.setdefault(kind(n), n)
            versions.setdefault(kind(n), set()).add(n)
    return sorted(n if len(versions[k]) == 1 else
                  f"{n} (the first frame's: {len(versions[k])} versions of this note on {frames[k]} frames, "
                  "their numbers vary)" for k, n in first.items())


def _m(v, units):
    from ..units import format_distance

    return "inf" if v is None else format_distance(v, units)


def run_show(args) -> int:
    from ._output import Table, print_csv, print_table

    rec = _load(args)
    static, rows = rec.static_dict(), rec.frame_rows()
    if args.json:
        emit_json(document("metadata_show", {"clip": static, "frames": rows},
                           units={"length": "mm", "angle": "degree", "time": "s", "rate": "frames per second"}))
        return 0
    if args.csv:
        print_csv(rows)
        return 0
    t = Table(_clip(rec), ["value", "recorded"])
    for k, v in static.items():
        if k not in ("frame_rate_exact",):
            t.add_row(k, "-" if v is None else (", ".join(map(str, v)) if isinstance(v, list) else v))
    print_table(t)
    cols = ["frame", "timecode", "focus_mm", "tstop", "fstop", "focal_length_mm"]
    f = Table(f"{len(rows)} frames", cols, justify=["right", "left"] + ["right"] * 4)
    for row in rows:
        f.add_row(*("-" if row[c] is None else (f"{row[c]:.4g}" if isinstance(row[c], float) else row[c])
                    for c in cols))
    print_table(f)
    return 0


def _solve(args, rec):
    from ..errors import InputError
    from ..metadata.convert import solve
    from .report import resolve_sensor

    lens = None
    if args.lens is not None:
        from ..lens.library import load_lens

        lens = load_lens(args.lens)
    given = args.sensor is not None or args.sensor_width is not None or args.sensor_height is not None
    sensor = None
    if rec.active_area_mm is None or given:
        sensor = resolve_sensor(args)
    if given and rec.active_area_mm is not None:
        raise InputError(f"the {rec.source} file gives the sensor area "
                         f"({rec.active_area_mm[0]:g} x {rec.active_area_mm[1]:g} mm); drop --sensor")
    return solve(rec, sensor=sensor, lens=lens, coc=args.coc, focal_length_mm=args.focal, fstop=args.fstop,
                 rate=args.fps), lens


def run_report(args) -> int:
    from ..live.record import lens_report_rows
    from ._common import units_of
    from ._output import Table, print_csv, print_table

    rec = _load(args)
    solved, lens = _solve(args, rec)
    rows = lens_report_rows(solved)
    s = solved[0].report.sensor
    notes = clip_notes([x.report.notes for x in solved])
    if args.json:
        emit_json(document("metadata_report", {
            "clip": rec.static_dict(), "lens": args.lens, "model": "prescription" if lens is not None else "thin lens",
            "sensor_mm": [s.width_mm, s.height_mm], "notes": notes, "frames": rows}))
        return 0
    u = units_of(args)
    if args.csv:
        print_csv(rows, units=u)
        return 0
    what = f"lens {args.lens}" if lens is not None else "a thin lens of the recorded focal length"
    cols = ["frame", "timecode", "focus", "stop", "near", "far", "hyperfocal", "hfov_deg"]
    t = Table(f"{_clip(rec)}: {what}, sensor {s.width_mm:g} x {s.height_mm:g} mm", cols,
              justify=["right", "left"] + ["right"] * 6)
    for r in rows:
        t.add_row(r["frame"], r["timecode"] or "-", _m(r["focus_from_film_mm"], u), f"{r['fstop']:.3g}",
                  _m(r["near_from_film_mm"], u), _m(r["far_from_film_mm"], u), _m(r["hyperfocal_from_film_mm"], u),
                  f"{r['hfov_deg']:.2f}")
    print_table(t)
    for n in notes[:3]:
        print(f"note: {n}")
    if len(notes) > 3:
        print(f"note: and {len(notes) - 3} more notes (--json lists them)")
    return 0


def run_usd(args) -> int:
    from ..extras import require_extra
    from ..io import check_writable

    require_extra("usd", "USD cameras (physcam metadata usd)")
    check_writable(args.file, force=args.force)
    rec = _load(args)
    solved, _ = _solve(args, rec)
    from ..metadata.convert import write_usd

    out = write_usd(args.file, rec, solved, plate=args.plate, plate_frames=args.plate_frames,
                    meters_per_unit=args.meters_per_unit, force=args.force)
    summary = {"file": str(out), "frames": len(solved), "source": rec.source, "clip_name": rec.clip_name,
               "first_timecode": rec.frames[0].timecode, "last_timecode": rec.frames[-1].timecode,
               "plate": args.plate, "plate_frames": None if args.plate_frames is None else list(args.plate_frames),
               "tracker_pose": any(f.tracker is not None for f in rec.frames)}
    if args.json:
        emit_json(document("metadata_usd", summary))
    else:
        print(f"wrote {out}: {len(solved)} frames of {_clip(rec)}" + (f", plate {args.plate}" if args.plate else ""))
    return 0


def run_opentrackio(args) -> int:
    import json
    import sys

    from ..extras import require_extra

    require_extra("live", "OpenTrackIO samples (physcam metadata opentrackio)")
    from ..io import atomic_write, check_writable
    from ..metadata.convert import opentrackio_samples

    if args.file is not None:
        check_writable(args.file, force=args.force)
    import dataclasses

    from ._live_record import resolve_sensor_opt

    record = _load(args)
    sensor = resolve_sensor_opt(args)
    if record.active_area_mm is None and sensor is not None:
        record = dataclasses.replace(record, active_area_mm=(sensor.width_mm, sensor.height_mm))
    samples = opentrackio_samples(record, rate=args.fps)
    if args.lens is not None:  # the named lens's optics at each frame (docs/zoom.md, docs/live.md)
        from ..errors import InputError
        from ..lens.library import load_lens

        if record.active_area_mm is None:
            raise InputError(f"the {record.source} clip gives no sensor size: give the sensor (--sensor) for the "
                             "lens's optics")
        from ..live.camera import with_optics
        from ..live.sample import validate_sample
        from .live import clip_zooms

        lens = load_lens(args.lens)
        samples = [validate_sample(s) for s in with_optics(
            samples, lens=lens, zooms=clip_zooms(record, lens, args.zoom, len(samples)))]
    elif args.zoom is not None:
        from ..errors import InputError

        raise InputError("--zoom takes a zoom lens (--lens NAME of a zoom; docs/zoom.md)")
    text = "".join(json.dumps(s, allow_nan=False, separators=(",", ":")) + "\n" for s in samples)
    if args.file is None:
        sys.stdout.write(text)
    else:
        atomic_write(args.file, text, force=args.force)
        print(f"wrote {len(samples)} OpenTrackIO 1.0.1 samples to {args.file} (validated)")
    return 0

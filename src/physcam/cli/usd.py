"""``physcam usd``: write, read and build PhysicalCamera USD files (docs/usd.md)."""

from __future__ import annotations

from ._common import FOCUS_HELP, add_sensor_options, add_units_option, coc_of, distance, focal_length, focus, number, numbers, usd_file, whole
from ._output import add_output_options, document, emit_json
from .report import add_coc_option, resolve_sensor

EPILOG = """\
examples:
  physcam usd write shot.usda --focal 50 --fstop 2.8 --focus 3m --sensor "ALEXA 35"
  physcam usd write cam_m.usda --focal 35 --focus 10ft --fstop 4 --meters-per-unit 1
  physcam usd read shot.usda --json
  physcam usd kit previs kit.usda
  physcam usd kit vendor dgauss50.usda --lens dgauss.50mm --focus 1.5m --fstop 4
Other USD applications see the schema with PXR_PLUGINPATH_NAME set to the folder
that `physcam usd plugin-path` prints.
"""


#: The body's rotateXYZ, as a camera operator says it (docs/usd.md, "Transform").
ROTATE_HELP = ("tilt (X), pan (Y) and roll (Z) about the entrance pupil, degrees, applied X then Y then Z "
               "(rotateXYZ): -5,30,0 tilts 5 down and pans 30 to the left")


def register(sub) -> None:
    import argparse

    p = sub.add_parser("usd", help="PhysicalCamera USD files: write, read, kits",
                       description="Write and read PhysicalCamera USD cameras (with a companion UsdGeomCamera).",
                       epilog=EPILOG, formatter_class=argparse.RawDescriptionHelpFormatter)
    s = p.add_subparsers(dest="usd_command", metavar="ACTION")

    w = s.add_parser("write", help="write the USD camera of a lens report")
    w.add_argument("file", type=usd_file, help="output .usda/.usd/.usdc")
    from .report import add_report_arguments

    add_report_arguments(w)  # brings --meters-per-unit and --shutter-angle with it
    from ._common import add_lenient

    add_lenient(w)
    _stage_args(w, units=False)
    w.add_argument("--path", default="/Cameras/Camera", help="camera prim path (default /Cameras/Camera)")
    w.add_argument("--orthographic", action="store_true", help="orthographic (telecentric) camera")
    w.add_argument("--magnification", type=number("magnification"), default=1.0,
                   help="orthographic: image size / object size (default 1)")
    w.add_argument("--blades", type=whole("blade count", lo=0), default=7, help="iris blades (RenderMan apertureNSides; default 7)")
    w.add_argument("--enlarge", type=numbers("enlarge", 2, positive=True), default=(1.0, 1.0), metavar="EX,EY",
                   help="image a region of the sensor enlarged EX,EY times (a tile: 2,2 with --shift-x/-y)")
    w.add_argument("--handedness", type=whole("handedness"), choices=(1, -1), default=1,
                   help="1 right-handed (default), -1 left-handed: a mirrored image")
    w.add_argument("--resolution", type=_pixels, default=None, metavar="W[,H]",
                   help="image size in pixels for the render settings and, with --lens, Omniverse's OpenCV "
                        "distortion (default 2048 and 4096 wide, height from the sensor's aspect)")
    w.add_argument("--overscan", type=number("overscan", lo=0.0, hi=100.0), default=0.0, metavar="PCT",
                   help="render beyond the frame by this percentage (UsdRenderSettings dataWindowNDC)")
    w.add_argument("--position", type=numbers("position", 3), default=(0.0, 0.0, 0.0), metavar="X,Y,Z",
                   help="where the entrance pupil goes, in scene units (--meters-per-unit)")
    w.add_argument("--rotate", type=numbers("rotation", 3), default=(0.0, 0.0, 0.0), metavar="RX,RY,RZ",
                   help=ROTATE_HELP)
    w.set_defaults(handler=run_write, output_args=("file",))

    r = s.add_parser("read", help="read a PhysicalCamera back into a lens report")
    r.add_argument("file", help="a USD file (.usda, .usd, .usdc)")
    r.add_argument("--path", default=None, help="camera prim path (default: the only PhysicalCamera)")
    add_units_option(r)
    add_output_options(r, what="the camera and its lens report (values as written in the file)")
    r.set_defaults(handler=run_read)

    k = s.add_parser("kit", help="the proposal's use cases: previs kit, vendor lens, lens library, body, shot",
                     description="Write the files of the proposal's use cases (docs/usd.md).",
                     epilog=KIT_EPILOG, formatter_class=argparse.RawDescriptionHelpFormatter)
    k.add_argument("kind", choices=("previs", "vendor", "lens", "body", "shot"), help="which use case to write")
    k.add_argument("file", type=usd_file, help="output .usda/.usd/.usdc")
    k.add_argument("--lens", help="vendor: bundled lens name or prescription file; shot: the lens file to reference")
    k.add_argument("--body", help="shot: the body file to reference")
    k.add_argument("--characterizations", metavar="CSV",
                   help="lens: a CSV with a date column and CameraSpec lens columns (focal_length_mm, fstop, "
                        "entrance_pupil_mm, transmittance, ...), one row per measuring day")
    k.add_argument("--focus", type=focus("focus distance"),
                   help=f"vendor, shot: focus mark from the film plane ({FOCUS_HELP}; a USD focus is finite)")
    k.add_argument("--fstop", type=number("f-stop", positive=True), help="vendor, shot: f-stop (vendor default: wide open)")
    add_sensor_options(k)
    k.add_argument("--flange", type=distance("flange focal distance"), help="body: flange focal distance (default 52 mm)")
    k.add_argument("--iso", type=number("ISO", positive=True), help="body: exposure index (default 100)")
    add_coc_option(k, "body: ")
    k.add_argument("--shutter-angle", type=number("shutter angle", positive=True), default=None,
                   help="body: degrees (default 180)")
    k.add_argument("--position", type=numbers("position", 3), default=(0.0, 0.0, 0.0), metavar="X,Y,Z",
                   help="shot: where the entrance pupil goes, in scene units")
    k.add_argument("--rotate", type=numbers("rotation", 3), default=(0.0, 0.0, 0.0), metavar="RX,RY,RZ",
                   help="shot: " + ROTATE_HELP)
    k.add_argument("--variant", help="shot: pin a lens characterization variant, by its name (d2026_03_01) or its "
                   "measuring day (2026-03-01); default the lens file's current")
    _stage_args(k)
    add_lenient(k)
    k.set_defaults(handler=run_kit, output_args=("file",))

    a = s.add_parser("animate", help="a focus (and iris) pull as time samples, breathing included",
                     description="Write a camera whose focus and f-stop follow marks per frame (docs/usd.md).",
                     epilog="example:\n  physcam usd animate pull.usda --lens dgauss_50mm --marks pull.csv "
                            "--sensor \"ALEXA 35\" --fstop 2.8\n"
                            "pull.csv has columns frame,focus[,fstop][,zoom]; focus with units (5m, 16ft; bare = mm); zoom "
                            "a focal length (135mm) or encoder 0..1 (a zoom lens).",
                     formatter_class=argparse.RawDescriptionHelpFormatter)
    a.add_argument("file", help="output .usda/.usd/.usdc")
    a.add_argument("--marks", required=True, metavar="CSV", help="focus marks per frame: frame,focus[,fstop]")
    a.add_argument("--lens", help="bundled lens name or prescription file (breathing from the real lens)")
    a.add_argument("--focal", type=focal_length(), help="or a thin lens of this focal length")
    a.add_argument("--fstop", type=number("f-stop", positive=True), help="f-stop for frames without one")
    a.add_argument("--zoom", default=None, metavar="POSITION",
                   help="a zoom lens's position for frames without a zoom column: a focal length with its unit "
                        "(135mm) or the encoder value 0..1 (docs/zoom.md)")
    add_coc_option(a)
    add_sensor_options(a)
    a.add_argument("--shutter-angle", type=number("shutter angle", positive=True), default=180.0,
                   help="degrees (default 180)")
    a.add_argument("--path", default="/Cameras/Camera", help="camera prim path")
    a.add_argument("--position", type=numbers("position", 3), default=(0.0, 0.0, 0.0), metavar="X,Y,Z",
                   help="where the first frame's entrance pupil goes, in scene units (the film stays there)")
    a.add_argument("--rotate", type=numbers("rotation", 3), default=(0.0, 0.0, 0.0), metavar="RX,RY,RZ",
                   help=ROTATE_HELP)
    _stage_args(a)
    add_lenient(a)
    a.set_defaults(handler=run_animate, output_args=("file",))

    c = s.add_parser("check", help="is a shot's companion camera current with its body and lens files?")
    c.add_argument("file", help="a shot (or any camera file physcam wrote)")
    c.add_argument("--path", default=None, help="camera prim path (default: the only PhysicalCamera)")
    add_output_options(c, what="the check")
    # exit 1 when stale is the default now (docs/cli.md, "Exit status"); the old flag keeps scripts running
    c.add_argument("--exit-code", action="store_true", help=argparse.SUPPRESS)
    c.set_defaults(handler=run_check)

    f = s.add_parser("refresh", help="recompute a shot's companion camera from its body and lens files (in place)")
    f.add_argument("file", help="a shot (or any camera file physcam wrote), rewritten in place")
    f.add_argument("--path", default=None, help="camera prim path (default: the only PhysicalCamera)")
    add_output_options(f, what="what was recomputed")
    f.set_defaults(handler=run_refresh)

    pp = s.add_parser("plugin-path", help="print the schema plugin folder for PXR_PLUGINPATH_NAME")
    pp.set_defaults(handler=run_plugin_path)
    p.set_defaults(handler=lambda args: (p.print_help(), 0)[1])


KIT_EPILOG = """\
examples:
  physcam usd kit previs kit.usda
  physcam usd kit vendor dgauss50.usda --lens dgauss_50mm --focus 1.5m --fstop 4
  physcam usd kit lens darling24.usda --characterizations darling24.csv
  physcam usd kit body alexa35.usda --sensor "ALEXA 35" --flange 44 --iso 800
  physcam usd kit shot sh010.usda --body alexa35.usda --lens dgauss50.usda --focus 2m --fstop 2.8 \\
      --position 0,150,500 --rotate 0,35,0
  physcam usd check sh010.usda          # stale after a lens or body file changed?
  physcam usd refresh sh010.usda        # recompute the companion camera
"""


def _pixels(text):
    import argparse

    try:
        v = tuple(int(x) for x in str(text).split(","))
    except ValueError:
        raise argparse.ArgumentTypeError(f"resolution must be W or W,H in whole pixels, got {text!r}") from None
    if len(v) not in (1, 2) or not all(16 <= x <= 65536 for x in v):
        raise argparse.ArgumentTypeError(f"resolution must be 16 to 65536 pixels, got {text!r}")
    return v


def _stage_args(p, units: bool = True) -> None:
    if units:
        p.add_argument("--meters-per-unit", type=number("metersPerUnit"), default=0.01,
                       help="stage metersPerUnit (default 0.01: centimetres)")
    p.add_argument("--fps", type=_time_code_rate, default=24.0,
                   help="timeCodesPerSecond (default 24; 23.976, 29.97, 59.94 are the exact N x 1000/1001)")
    p.add_argument("--force", action="store_true", help="overwrite an existing file")
    add_output_options(p, what="what was written")


def _time_code_rate(text) -> float:
    """--fps as the stage's timeCodesPerSecond: an NTSC rate to three decimals is N x 1000/1001, as usd animate,
    live record and metadata usd write it, so every physcam file of a 23.976 shot lines up (ntsc_rate)."""
    from ..usd.animate import ntsc_rate

    return ntsc_rate(number("frames per second", positive=True)(text))


def run_write(args) -> int:
    from ..usd.author import spec_from_report, write_camera
    from .report import solve_from_args

    from ..export.usdgeom import shutter_interval

    shutter_interval(args.shutter_angle)  # validates 0 < angle <= 360
    report = solve_from_args(args)
    _finite_focus(report.focus_from_film_mm)
    spec = spec_from_report(report, projection="orthographic" if args.orthographic else "perspective",
                            magnification=args.magnification, aperture_blades=args.blades,
                            shutter_duration_s=args.shutter_angle / 360.0 / args.fps,
                            shift_mm=(args.shift_x, args.shift_y), enlarge=args.enlarge,
                            handedness=float(args.handedness))
    distortion = opencv = None
    anamorphic = []
    if getattr(args, "lens", None) and not args.orthographic:  # a prescription-backed report: its real distortion
        from ..usd.kit import prescription_anamorphic_distortion, prescription_distortion, prescription_opencv

        lens = args.loaded_lens  # the lens the report solved (a zoom at --zoom)
        distortion = prescription_distortion(lens, report.sensor.width_mm, report.sensor.height_mm,
                                             focus_mm=report.focus_from_film_mm)
        opencv = prescription_opencv(lens, report.sensor.width_mm, report.sensor.height_mm,
                                     focus_mm=report.focus_from_film_mm, resolution=args.resolution)
        anamorphic = prescription_anamorphic_distortion(lens, report.sensor.width_mm, report.sensor.height_mm,
                                                        focus_mm=report.focus_from_film_mm)
    from .report import thin_lens_gap_from_args

    gap = None if args.orthographic else thin_lens_gap_from_args(args, report)
    path = write_camera(args.file, spec, force=args.force, path=args.path, meters_per_unit=args.meters_per_unit,
                        fps=args.fps, report=report if not args.orthographic else None, lens_distortion=distortion,
                        opencv_distortion=opencv, resolution=args.resolution, overscan=args.overscan / 100.0,
                        thin_lens_gap=gap and gap.to_dict(), anamorphic_distortion=anamorphic,
                        prescription=None if args.orthographic else getattr(args, "loaded_lens", None),
                        position=args.position, rotate_xyz_deg=args.rotate)
    if gap is not None and not getattr(args, "json", False):
        print(f"note: {gap.summary()}")
    return _done(args, path, extra={"thin_lens_gap": gap and gap.to_dict()})


def _finite_focus(mm) -> None:
    """USD cameras carry a finite focus distance (PhysicalCamera's focusDistance, UsdGeomCamera's)."""
    import math

    from ..errors import InputError

    if mm is not None and math.isinf(mm):
        raise InputError("a USD camera's focus distance is finite: give the focus mark (e.g. --focus 1000m) "
                         "or --focus hyperfocal")


def _done(args, path, name: str = "usd_written", extra=None) -> int:
    if getattr(args, "json", False):
        emit_json(document(name, {"written": str(path), **(extra or {})}))
    else:
        print(f"wrote {path}")
    return 0


def as_written(v):
    """A value read from a USD float attribute as its author wrote it: the shortest decimal that is the
    same float32 (2.8, not 2.799999952316284). Values that are not float32 numbers pass unchanged."""
    import math

    if isinstance(v, (tuple, list)):
        return type(v)(as_written(x) for x in v)
    if isinstance(v, float) and math.isfinite(v):
        import numpy as np

        f32 = np.float32(v)
        if float(f32) == v:
            return float(np.format_float_positional(f32, unique=True, trim="-"))
    return v


def reading_as_written(reading):
    """A :class:`~physcam.usd.read.CameraReading` whose camera values print as written (:func:`as_written`)."""
    import dataclasses

    spec = reading.spec
    clean = {k: as_written(v) for k, v in spec.values().items() if isinstance(v, (float, tuple))}
    return dataclasses.replace(reading, spec=spec.replaced(**clean))


def run_read(args) -> int:
    from ..units import format_distance
    from ..usd.read import open_stage, read_camera
    from ._common import units_of

    reading = reading_as_written(read_camera(open_stage(args.file), args.path))
    report = reading.report()
    if args.json:
        emit_json(document("usd_read", {
            "usd": reading.to_dict(),
            "report": report.to_dict() if reading.spec.projection == "perspective" else None}))
        return 0
    s = reading.spec
    units = units_of(args)
    print(f"{reading.path}: {s.focal_length_mm:.4g} mm f/{s.fstop:.3g} focus {format_distance(s.focus_mm, units)} "
          f"sensor {s.sensor_width_mm:g} x {s.sensor_height_mm:g} mm ({reading.lens_model_type})")
    if s.projection == "orthographic":
        # a telecentric view: no field angle; the sensor images sensor / magnification of the scene
        print(f"  orthographic: magnification {s.magnification:g}, images {s.sensor_width_mm * s.squeeze / s.magnification:g}"
              f" x {s.sensor_height_mm / s.magnification:g} mm of the scene")
    else:
        pin, _ = report.pinhole
        print(f"  pinhole {pin:.4f} mm: hfov {report.hfov_focus_deg:.4f} deg, vfov {report.vfov_focus_deg:.4f} deg "
              f"at focus; DOF from film {format_distance(report.dof.near_from_film_mm, units)} to "
              f"{format_distance(report.dof.far_from_film_mm, units)}; CoC {report.coc_mm:.4g} mm "
              f"({report.coc_convention})")
    for k, v in reading.variants.items():
        print(f"  variant {k} = {v}")
    return 0


def run_kit(args) -> int:
    from ..errors import InputError
    from ..usd import kit

    kind = args.kind
    allowed = {
        "previs": set(),
        "vendor": {"lens", "focus", "fstop", "sensor", "sensor_width", "sensor_height", "lenient"},
        "lens": {"characterizations"},
        "body": {"sensor", "sensor_width", "sensor_height", "flange", "iso", "shutter_angle", "coc"},
        "shot": {"lens", "body", "focus", "fstop", "position", "rotate", "variant"},
    }[kind]
    given = {k for k in ("lens", "body", "characterizations", "focus", "fstop", "sensor", "sensor_width",
                         "sensor_height", "flange", "iso", "shutter_angle", "variant", "coc")
             if getattr(args, k) is not None}
    given |= {k for k in ("position", "rotate") if getattr(args, k) != (0.0, 0.0, 0.0)}
    given |= {"lenient"} if args.lenient else set()
    if given - allowed:
        flags = ", ".join("--" + k.replace("_", "-") for k in sorted(given - allowed))
        raise InputError(f"usd kit {kind} does not use {flags}")
    common = dict(force=args.force, meters_per_unit=args.meters_per_unit, fps=args.fps)
    if kind == "previs":
        path = kit.write_previs_kit(args.file, **common)
    elif kind == "vendor":
        missing = [f for f, v in (("--lens", args.lens), ("--focus", args.focus)) if not v]
        if missing:
            raise InputError(f"physcam usd kit vendor needs {' and '.join(missing)}")
        from ..lens.library import load_lens

        sensor = resolve_sensor(args)
        lens = load_lens(args.lens, lenient=args.lenient)
        from ._common import resolve_focus

        args.focus = resolve_focus(args.focus, lens=lens, fstop=args.fstop, sensor=sensor, args=args)
        _finite_focus(args.focus)
        path = kit.write_vendor_lens(args.file, lens, focus_mm=args.focus,
                                     fstop=args.fstop,
                                     sensor_width_mm=sensor.width_mm, sensor_height_mm=sensor.height_mm, **common)
    elif kind == "lens":
        if not args.characterizations:
            raise InputError("physcam usd kit lens needs --characterizations CSV (date, focal_length_mm, ...)")
        days = _read_characterizations(args.characterizations)
        path = kit.write_lens_file(args.file, days, **common)
        unknown = [d for d, spec in days.items() if spec.entrance_pupil_mm is None]
        if unknown:
            from ._common import note

            note(f"{path}: no entrance_pupil_mm for {', '.join(sorted(unknown))}: the entrance pupil is left "
                 "unknown (not written); a shot composing the lens places its camera at the thin-lens pupil at "
                 "the shot's focus")
    elif kind == "body":
        from ..usd.author import CameraSpec

        from ..optics.coc import circle_of_confusion

        sensor = resolve_sensor(args)
        coc, _ = circle_of_confusion(sensor.width_mm, sensor.height_mm, coc_of(args))
        body = dict(sensor_width_mm=sensor.width_mm, sensor_height_mm=sensor.height_mm, sensor_name=sensor.name,
                    coc_mm=coc)
        if args.flange is not None:
            body["flange_distance_mm"] = args.flange
        if args.iso is not None:
            body["iso"] = args.iso
        if args.shutter_angle is not None:
            from ..export.usdgeom import shutter_interval

            shutter_interval(args.shutter_angle)  # validates 0 < angle <= 360
            body["shutter_duration_s"] = args.shutter_angle / 360.0 / args.fps
        path = kit.write_body_file(args.file, CameraSpec.of(**body), **common)
    else:
        if not args.body or not args.lens:
            raise InputError("physcam usd kit shot needs --body FILE and --lens FILE")
        overrides = {}
        if args.focus is not None:
            if isinstance(args.focus, str):  # hyperfocal: the shot's lens and body are in the files
                raise InputError("usd kit shot takes a focus mark (the lens and body are files); "
                                 "`physcam report --lens ... --focus hyperfocal` gives the mark")
            _finite_focus(args.focus)
            overrides["focus_mm"] = args.focus
        if args.fstop is not None:
            overrides["fstop"] = args.fstop
        path = kit.write_shot(args.file, args.body, args.lens, overrides=overrides, lens_variant=args.variant,
                              position=args.position, rotate_xyz_deg=args.rotate, **common)
    if kind == "vendor" and args.json:  # what the file says, read back: the lens and its best-match pinhole
        from ..usd.read import open_stage

        stage = open_stage(path)
        lens = stage.GetPrimAtPath(kit.LENS_PRIM)
        values = {a.GetName(): a.Get() for a in lens.GetAttributes() if a.HasAuthoredValue()}
        emit_json(document("usd_kit_vendor", {
            "written": str(path),
            "lens": {k: (as_written(list(v)) if hasattr(v, "__len__") and not isinstance(v, str) else as_written(v))
                     for k, v in values.items()},
            "variants": {n: lens.GetVariantSets().GetVariantSelection(n) for n in lens.GetVariantSets().GetNames()}}))
        return 0
    return _done(args, path)


def _read_characterizations(csv_path) -> dict:
    """date -> CameraSpec from a CSV: a ``date`` column and CameraSpec field columns (numbers)."""
    import csv
    import dataclasses
    from pathlib import Path

    from ..errors import InputError, LensFileError
    from ..usd.author import CameraSpec

    p = Path(csv_path)
    try:
        text = p.read_text(encoding="utf-8-sig")
    except OSError as exc:
        raise InputError(f"cannot read {p}: {exc.strerror or exc}") from None
    from ..usd.spec import CAMERA_VALUES

    numeric = {n for n in (*CAMERA_VALUES, *(f.name for f in dataclasses.fields(CameraSpec)[1:]))
               if n not in ("projection", "lens_name", "sensor_name") and not n.endswith("_mm")
               or n in ("focal_length_mm", "entrance_pupil_mm", "focus_mm", "aperture_distance_mm",
                        "pinhole_focal_length_mm")}
    numeric -= {"principal_planes_mm", "shift_mm", "clipping_mm", "shutter_opening"}
    out = {}
    rows = csv.DictReader(text.splitlines())
    if not rows.fieldnames or "date" not in rows.fieldnames:
        raise LensFileError("the characterization CSV needs a 'date' column", str(p), 1)
    unknown = set(rows.fieldnames) - numeric - {"date", "lens_name"}
    if unknown:
        raise LensFileError(f"unknown columns {sorted(unknown)}; use date, lens_name and lens fields such as "
                            "focal_length_mm, fstop, entrance_pupil_mm, transmittance, focus_mm", str(p), 1)
    for line, row in enumerate(rows, start=2):
        values = {}
        for k, v in row.items():
            if k in ("date", "lens_name") or v in (None, ""):
                continue
            try:
                values[k] = int(v) if k == "aperture_blades" else float(v)
            except ValueError:
                raise LensFileError(f"column {k}: {v!r} is not a number", str(p), line) from None
        if not row.get("date"):
            raise LensFileError("a row without a date", str(p), line)
        try:
            out[row["date"]] = CameraSpec.of(lens_name=row.get("lens_name") or None, **values).checked()
        except InputError as exc:
            raise LensFileError(str(exc), str(p), line) from None
    if not out:
        raise LensFileError("no characterization rows", str(p))
    return out


def run_animate(args) -> int:
    from ..errors import InputError
    from ..usd.animate import read_focus_marks, write_animated_camera

    if (args.lens is None) == (args.focal is None):
        raise InputError("give the lens (--lens NAME) or a thin lens's focal length (--focal MM)")
    lens = None
    if args.lens:
        from ..lens.library import load_lens

        lens = load_lens(args.lens, lenient=args.lenient)
    coc = coc_of(args)
    keys = read_focus_marks(args.marks)
    path = write_animated_camera(args.file, keys, sensor=resolve_sensor(args), lens=lens,
                                 focal_length_mm=args.focal, fstop=args.fstop, coc=coc, path=args.path,
                                 meters_per_unit=args.meters_per_unit, fps=args.fps,
                                 shutter_angle_deg=args.shutter_angle, position=args.position,
                                 rotate_xyz_deg=args.rotate, force=args.force, zoom=args.zoom)
    if args.json:
        emit_json(document("usd_animate", {"written": str(path), "frames": len(keys), "first": keys[0].frame,
                                           "last": keys[-1].frame}))
    else:
        print(f"wrote {path} ({len(keys)} frames, {keys[0].frame:g} to {keys[-1].frame:g})")
    return 0


def run_check(args) -> int:
    from ..usd.keyed_lens import time_code_text
    from ..usd.kit import check_shot

    res = check_shot(args.file, args.path)
    rc = 1 if res["stale"] else 0  # a checker: 1 when it finds a problem (docs/cli.md, "Exit status")
    if args.json:
        d = dict(res)
        d["file_units"] = d.pop("units")  # the layers' metersPerUnit notes (the document's own "units" say mm)
        emit_json(document("usd_check", d))
        return rc
    state = f"STALE: {res['reason']}; run physcam usd refresh {args.file}" if res["stale"] else "current"
    n = len(res["time_codes"])
    keyed = f" ({n} keyed time code{'s' * (n != 1)})" if n else ""
    print(f"{res['path']}: companion camera{keyed} {state}")
    for sample in res["stale_samples"]:
        t = time_code_text(sample["time"])
        why = f"stale, left from a deleted key at time code {t}:" if sample["left"] else "stale"
        print(f"  time code {t}: {why} {', '.join(sample['attributes'])}")
    for u in res["units"]:
        print(f"  note: {u['file']} is in metersPerUnit {u['meters_per_unit']:g}, the shot in "
              f"{res['meters_per_unit']:g} (composed in the shot's unit)")
    return rc


def run_refresh(args) -> int:
    from ..usd.keyed_lens import time_code_text
    from ..usd.kit import refresh_shot

    res = refresh_shot(args.file, args.path)
    if args.json:
        d = dict(res)
        d["file_units"] = d.pop("units")  # as usd check
        emit_json(document("usd_refresh", d))
    elif not res["written"]:
        print(f"{res['path']}: companion camera current; nothing to recompute, {args.file} not rewritten")
    else:
        n = len(res["changed"])
        print(f"{res['path']}: companion camera recomputed; {n} value{'s' * (n != 1)} changed"
              + (":" if n else " (the inputs hash only)"))
        for c in res["changed"]:
            at = f" at time code {time_code_text(c['time'])}" if "time" in c else ""
            print(f"  {c['attribute']}{at}: {_shown(c['before'])} -> {_shown(c['after'])}")
    return 0


def _shown(v) -> str:
    """A refreshed attribute's value for people: numbers as %g, lists in parentheses, none as '(none)'."""
    if v is None:
        return "(none)"
    if isinstance(v, list):
        return "(" + ", ".join(f"{x:.9g}" for x in v) + ")"
    return f"{v:.9g}" if isinstance(v, float) else str(v)


def run_plugin_path(args) -> int:
    from ..usd.plugin import PLUGIN_DIR

    print(PLUGIN_DIR)
    return 0

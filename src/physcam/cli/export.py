"""``physcam export``: lens data for other tools (Unreal lens files, OpenCV/Omniverse pinholes,
Blender Cycles OSL lens cameras)."""

from __future__ import annotations

from ._common import FOCUS_HELP, add_units_option, focus, number
from ._output import add_output_options, document, emit_json, print_csv


def _sensor(p) -> None:
    from .analyze import _sensor as add
    from .lens import add_lenient

    add(p)
    add_lenient(p)  # every export takes a lens


def _common(p) -> None:
    p.add_argument("lens", metavar="NAME_OR_FILE", help="bundled lens name (see `physcam lenses`) or a lens file")
    _sensor(p)
    p.add_argument("--width-px", type=int, required=True, metavar="PX", help="image width in pixels")
    p.add_argument("--height-px", type=int, required=True, metavar="PX", help="image height in pixels")


def register(sub) -> None:
    p = sub.add_parser("export", help="lens data for Unreal (lens file) and OpenCV/Omniverse (pinhole + distortion)",
                       description="Export a real lens as an Unreal Engine lens file (.ulens JSON) or as fitted "
                                   "OpenCV pinhole intrinsics and distortion (Omniverse's opencvPinhole lens API).")
    s = p.add_subparsers(dest="export_command", metavar="FORMAT")

    u = s.add_parser("unreal", help="write an Unreal Engine lens file (.ulens JSON, Camera Calibration plugin)")
    _common(u)
    u.add_argument("-o", "--output", required=True, metavar="FILE", help="the lens file to write (.ulens or .json)")
    u.add_argument("--focus", type=focus("focus distance"), action="append", metavar="D",
                   help=f"focus mark from the film plane (repeat; default: infinity to the closest focus; {FOCUS_HELP}; "
                        "hyperfocal wide open)")
    u.add_argument("--force", action="store_true", help="overwrite an existing file")
    add_units_option(u)
    add_output_options(u, csv=True, what="the lens file's marks")
    u.set_defaults(handler=run_unreal)

    o = s.add_parser("opencv", help="print OpenCV pinhole intrinsics and distortion fitted to real rays")
    _common(o)
    o.add_argument("--focus", type=focus("focus distance"), default=float("inf"), metavar="D",
                   help=f"focus mark from the film plane (default infinity; {FOCUS_HELP}; hyperfocal wide open)")
    o.add_argument("--terms", choices=("k1", "k1k2", "k1k2k3", "rational"), default="k1k2k3",
                   help="distortion terms to fit (default k1k2k3)")
    add_units_option(o)
    add_output_options(o, what="the fitted camera")
    o.set_defaults(handler=run_opencv)

    b = s.add_parser("blender", help="write a Blender Cycles OSL lens camera (shader + set-up script)",
                     description="Write <lens>.osl, an OSL camera shader tracing real rays through the focused lens, "
                                 "and setup_<lens>.py, which makes the scene camera use it "
                                 "(`blender --python setup_<lens>.py`). See docs/blender.md.")
    b.add_argument("lens", metavar="NAME_OR_FILE", help="bundled lens name (see `physcam lenses`) or a lens file")
    b.add_argument("--focus", type=focus("focus distance"), required=True, metavar="D",
                   help=f"focus mark from the film plane ({FOCUS_HELP})")
    b.add_argument("--fstop", type=number("f-number", positive=True), default=None, metavar="N",
                   help="working f-number (default: the lens wide open)")
    _sensor(b)
    b.add_argument("--blades", type=number("blade count", lo=0, hi=64), default=None, metavar="N",
                   help="iris blades (3 or more: a polygonal aperture; default round)")
    b.add_argument("--blade-angle", type=number("blade angle"), default=0.0, metavar="DEG",
                   help="angle of the first iris vertex from +x, degrees (default 0)")
    b.add_argument("--roundness", type=number("roundness", lo=-1, hi=1), default=0.0, metavar="R",
                   help="iris roundness, -1..1 (0 straight blades, 1 a circle)")
    b.add_argument("--density", type=number("aperture density", lo=-1, hi=1), default=0.0, metavar="D",
                   help="bokeh brightness slope across the aperture, -1..1 (0 flat, > 0 bright rim)")
    b.add_argument("--dispersion", action="store_true", help="trace one wavelength per ray (chromatic aberration)")
    b.add_argument("--fresnel", action="store_true", help="include unpolarised Fresnel losses (uncoated surfaces)")
    b.add_argument("--width-px", type=int, default=1920, metavar="PX",
                   help="render width in pixels (height follows the sensor aspect; default 1920)")
    b.add_argument("-o", "--output", required=True, metavar="DIR", help="folder to write the shader and script into")
    b.add_argument("--force", action="store_true", help="overwrite existing files")
    add_output_options(b, what="what was written")
    add_units_option(b)
    b.add_argument("--builtin", action="store_true",
                   help="also write builtin_<lens>.py: Blender's own camera matched to the lens at this focus "
                        "(best-match pinhole, aperture, focus distance; faster, no real-lens optics)")
    b.set_defaults(handler=run_blender)
    p.set_defaults(handler=lambda args: (p.print_help(), 0)[1])


def _prepare(args):
    """Resolve the sensor (args.sensor_width/height), load the lens and resolve --focus (hyperfocal:
    the lens at --fstop, or wide open)."""
    from ..lens.library import load_lens
    from ..onset.sensors import custom_sensor
    from ._common import resolve_focus
    from .analyze import _resolve_sensor

    _resolve_sensor(args)
    lens = load_lens(args.lens, lenient=args.lenient)
    if getattr(args, "focus", None) is not None:
        args.focus = resolve_focus(args.focus, lens=lens, fstop=getattr(args, "fstop", None),
                                   sensor=custom_sensor(args.sensor_width, args.sensor_height), args=args)
    return lens


def _mark(mm: float, units: str = "m") -> str:
    from ..units import format_distance

    return format_distance(mm, units)


def run_unreal(args) -> int:
    from ..export.unreal import unreal_lens_file
    from ..io import atomic_write, check_writable

    check_writable(args.output, force=args.force)
    lens = _prepare(args)
    data = unreal_lens_file(lens, args.sensor_width, args.sensor_height, image_width_px=args.width_px,
                            image_height_px=args.height_px, focus_marks_mm=args.focus)
    import json

    atomic_write(args.output, json.dumps(data, indent=2, allow_nan=False) + "\n", force=args.force)
    pc = data["physcam"]
    if args.json:
        emit_json(document("export_unreal", {"written": str(args.output), "lens_file": data}))
        return 0
    if args.csv:
        print_csv(pc["marks"])
        return 0
    from ._common import units_of
    from ._output import Table, print_table

    units = units_of(args)
    print(f"wrote {args.output}: Unreal lens file of {pc['lens']} on {args.sensor_width:g} x {args.sensor_height:g} mm, "
          f"{args.width_px} x {args.height_px} px")
    t = Table(None, ("focus", "Fx", "Fy", "K1", "K2", "K3", "pupil cm", "resid px"), justify=["right"] * 8)
    for m in pc["marks"]:
        f = m["focus_from_film_mm"]
        t.add_row(_mark(float("inf") if f is None else f, units), f"{m['pinhole_focal_length_x_mm'] / args.sensor_width:.5f}",
                  f"{m['pinhole_focal_length_y_mm'] / args.sensor_height:.5f}", f"{m['k1']:.6f}", f"{m['k2']:.6f}",
                  f"{m['k3']:.6f}", f"{m['entrance_pupil_from_film_mm'] / 10.0:.3f}", f"{m['max_residual_px']:.4f}")
    print_table(t)
    notes = sorted({n for m in pc["marks"] for n in m["notes"]})
    for n in notes:
        print(f"note: {n}")
    return 0


def run_opencv(args) -> int:
    from ..export.opencv_distortion import OMNI_API_SCHEMA, fit_opencv_pinhole

    lens = _prepare(args)
    cam = fit_opencv_pinhole(lens, args.sensor_width, args.sensor_height, args.width_px, args.height_px,
                             focus_from_film_mm=args.focus, terms=args.terms)
    if args.json:
        emit_json(document("export_opencv", cam.to_dict(), units={"length": "mm", "image": "pixel"}))
        return 0
    from ._common import units_of

    print(f"{cam.lens_name}: OpenCV pinhole at focus {_mark(cam.focus_from_film_mm, units_of(args))} on "
          f"{cam.sensor_width_mm:g} x {cam.sensor_height_mm:g} mm, {cam.image_width_px} x {cam.image_height_px} px")
    print(f"  fx {cam.fx:.4f}  fy {cam.fy:.4f}  cx {cam.cx:.4f}  cy {cam.cy:.4f}  (px; pinhole "
          f"{cam.pinhole_focal_length_x_mm:.4f} mm at the entrance pupil, {cam.entrance_pupil_from_film_mm:.3f} mm "
          "in front of the film)")
    print("  " + "  ".join(f"{k} {getattr(cam, k):.6g}" for k in ("k1", "k2", "k3", "k4", "k5", "k6", "p1", "p2")))
    print(f"  fit ({cam.terms}) over {cam.n_points} traced points: max residual {cam.max_residual_px:.4f} px, "
          f"rms {cam.rms_residual_px:.4f} px")
    print(f"  Omniverse: apiSchemas = [\"{OMNI_API_SCHEMA}\"], omni:lensdistortion:opencvPinhole:* (--json for all)")
    for n in cam.notes:
        print(f"  note: {n}")
    return 0


def run_blender(args) -> int:
    import time
    from pathlib import Path

    from ..errors import InputError
    from ..export.blender import write_blender_camera
    from ..trace.aperture import Aperture

    t0 = time.perf_counter()
    lens = _prepare(args)
    if not 16 <= args.width_px <= 65536:
        raise InputError(f"--width-px must lie in 16..65536, got {args.width_px}")
    if args.blades is not None and args.blades != int(args.blades):
        raise InputError(f"--blades must be a whole number, got {args.blades:g}")
    aperture = None
    if args.blades is not None or args.roundness or args.density:
        aperture = Aperture(int(args.blades or 0), args.blade_angle, args.roundness, args.density)
    w = int(args.width_px)
    h = max(1, int(round(w * args.sensor_height / args.sensor_width)))
    osl, setup = write_blender_camera(args.output, lens, focus_mm=args.focus, fstop=args.fstop,
                                      sensor_width_mm=args.sensor_width, sensor_height_mm=args.sensor_height,
                                      aperture=aperture, dispersion=args.dispersion, fresnel=args.fresnel,
                                      resolution=(w, h), name=Path(args.lens).stem, force=args.force)
    builtin = None
    if args.builtin:
        builtin = _write_builtin(args, lens, w, Path(args.output) / f"builtin_{Path(args.lens).stem}.py")
    data = {"lens": lens.name, "shader": str(osl), "setup": str(setup), "builtin": builtin and str(builtin),
            "focus_from_film_mm": None
            if args.focus == float("inf") else args.focus, "fstop": args.fstop, "sensor_mm": [args.sensor_width,
            args.sensor_height], "resolution": [w, h], "dispersion": args.dispersion, "fresnel": args.fresnel,
            "seconds": round(time.perf_counter() - t0, 3)}
    if args.json:
        emit_json(document("export_blender", data, units={"length": "mm", "time": "s", "image": "pixel"}))
        return 0
    from ._common import units_of

    print(f"wrote {osl} and {setup}: {lens.name} focused at {_mark(args.focus, units_of(args))}"
          f"{'' if args.fstop is None else f', f/{args.fstop:g}'} on {args.sensor_width:g} x {args.sensor_height:g} mm, "
          f"{w} x {h} px")
    print(f"  in Blender: blender your.blend --python {setup}  (Cycles, CPU, OSL)")
    if builtin is not None:
        print(f"  or Blender's own camera, matched: blender your.blend --python {builtin}")
    return 0


def _write_builtin(args, lens, width_px: int, path):
    """Blender's built-in camera matched to the lens report at this focus (physcam.export.blender_camera)."""
    import math

    from ..errors import InputError
    from ..export.blender_camera import blender_camera_script, blender_camera_values
    from ..io import atomic_write
    from ..onset.report import solve_lens_report
    from ..onset.sensors import custom_sensor

    if math.isinf(args.focus):
        raise InputError("--builtin needs a finite focus mark (the built-in camera's focus distance); "
                         "give e.g. --focus 1000m")
    report = solve_lens_report(focal_length_mm=None, sensor=custom_sensor(args.sensor_width, args.sensor_height),
                               fstop=args.fstop, focus_mm=args.focus, lens=lens)
    blades = int(args.blades or 0)
    values = blender_camera_values(report, resolution_x=width_px, blades=blades if blades >= 3 else 0,
                                   blade_rotation_deg=args.blade_angle)
    return atomic_write(path, blender_camera_script(values), force=args.force)

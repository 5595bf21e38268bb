"""``physcam export``: lens data for other tools (Unreal lens files, OpenCV/Omniverse pinholes,
Blender Cycles OSL lens cameras)."""

from __future__ import annotations

from ._common import distance, number, print_json


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
    p.add_argument("--json", action="store_true", help="print JSON instead of a table")


def register(sub) -> None:
    p = sub.add_parser("export", help="lens data for Unreal (lens file) and OpenCV/Omniverse (pinhole + distortion)",
                       description="Export a real lens as an Unreal Engine lens file (.ulens JSON) or as fitted "
                                   "OpenCV pinhole intrinsics and distortion (Omniverse's opencvPinhole lens API).")
    s = p.add_subparsers(dest="export_command", metavar="FORMAT")

    u = s.add_parser("unreal", help="write an Unreal Engine lens file (.ulens JSON, Camera Calibration plugin)")
    _common(u)
    u.add_argument("-o", "--output", required=True, metavar="FILE", help="the lens file to write (.ulens or .json)")
    u.add_argument("--focus", type=distance("focus distance", allow_inf=True), action="append", metavar="D",
                   help="focus mark from the film plane (repeat; default: infinity to the closest focus)")
    u.add_argument("--force", action="store_true", help="overwrite an existing file")
    u.set_defaults(handler=run_unreal)

    o = s.add_parser("opencv", help="print OpenCV pinhole intrinsics and distortion fitted to real rays")
    _common(o)
    o.add_argument("--focus", type=distance("focus distance", allow_inf=True), default=float("inf"), metavar="D",
                   help="focus mark from the film plane (default infinity)")
    o.add_argument("--terms", choices=("k1", "k1k2", "k1k2k3", "rational"), default="k1k2k3",
                   help="distortion terms to fit (default k1k2k3)")
    o.set_defaults(handler=run_opencv)

    b = s.add_parser("blender", help="write a Blender Cycles OSL lens camera (shader + set-up script)",
                     description="Write <lens>.osl, an OSL camera shader tracing real rays through the focused lens, "
                                 "and setup_<lens>.py, which makes the scene camera use it "
                                 "(`blender --python setup_<lens>.py`). See docs/blender.md.")
    b.add_argument("lens", metavar="NAME_OR_FILE", help="bundled lens name (see `physcam lenses`) or a lens file")
    b.add_argument("--focus", type=distance("focus distance", allow_inf=True), required=True, metavar="D",
                   help="focus mark from the film plane (e.g. 3m, 10ft, inf)")
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
    b.add_argument("--json", action="store_true", help="print JSON instead of text")
    b.add_argument("--builtin", action="store_true",
                   help="also write builtin_<lens>.py: Blender's own camera matched to the lens at this focus "
                        "(best-match pinhole, aperture, focus distance; faster, no real-lens optics)")
    b.set_defaults(handler=run_blender)
    _register_mitsuba(s)
    p.set_defaults(handler=lambda args: (p.print_help(), 0)[1])


def _prepare(args):
    from ..lens.library import load_lens
    from .analyze import _resolve_sensor

    _resolve_sensor(args)
    return load_lens(args.lens, lenient=args.lenient)


def _mark(mm: float) -> str:
    return "∞" if mm == float("inf") else f"{mm / 1000.0:g} m"


def run_unreal(args) -> int:
    from ..export.unreal import unreal_lens_file
    from ..io import atomic_write, check_writable

    check_writable(args.output, force=args.force)
    lens = _prepare(args)
    data = unreal_lens_file(lens, args.sensor_width, args.sensor_height, image_width_px=args.width_px,
                            image_height_px=args.height_px, focus_marks_mm=args.focus)
    import json

    atomic_write(args.output, json.dumps(data, indent=2, allow_nan=False) + "\n", force=args.force)
    if args.json:
        print_json(data)
        return 0
    pc = data["physcam"]
    print(f"wrote {args.output}: Unreal lens file of {pc['lens']} on {args.sensor_width:g} x {args.sensor_height:g} mm, "
          f"{args.width_px} x {args.height_px} px")
    print(f"  {'focus':>8} {'Fx':>8} {'Fy':>8} {'K1':>10} {'K2':>10} {'K3':>10} {'pupil cm':>9} {'resid px':>9}")
    for m in pc["marks"]:
        f = m["focus_from_film_mm"]
        print(f"  {_mark(float('inf') if f is None else f):>8} {m['pinhole_focal_length_x_mm'] / args.sensor_width:8.5f} "
              f"{m['pinhole_focal_length_y_mm'] / args.sensor_height:8.5f} {m['k1']:10.6f} {m['k2']:10.6f} "
              f"{m['k3']:10.6f} {m['entrance_pupil_from_film_mm'] / 10.0:9.3f} {m['max_residual_px']:9.4f}")
    notes = sorted({n for m in pc["marks"] for n in m["notes"]})
    for n in notes:
        print(f"  note: {n}")
    return 0


def run_opencv(args) -> int:
    from ..export.opencv_distortion import OMNI_API_SCHEMA, fit_opencv_pinhole

    lens = _prepare(args)
    cam = fit_opencv_pinhole(lens, args.sensor_width, args.sensor_height, args.width_px, args.height_px,
                             focus_from_film_mm=args.focus, terms=args.terms)
    if args.json:
        print_json(cam.to_dict())
        return 0
    print(f"{cam.lens_name}: OpenCV pinhole at focus {_mark(cam.focus_from_film_mm)} on "
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
        print_json(data)
        return 0
    print(f"wrote {osl} and {setup}: {lens.name} focused at {_mark(args.focus)}"
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


# --- physcam export mitsuba (Mitsuba 3 thinlens sensor; docs/mitsuba.md) ----------------------------
def _register_mitsuba(s) -> None:
    from .lens import add_lenient
    from .report import add_report_arguments

    m = s.add_parser("mitsuba", help="write a Mitsuba 3 thinlens sensor (scene XML and dict JSON) matching the lens report",
                     description="Write <name>.xml (a Mitsuba 3 scene holding the sensor; <include> it or load it with "
                                 "mi.load_file) and <name>.json (the same sensor as a mi.load_dict dictionary) for the "
                                 "lens report of these options: the field of view of the focused lens and its "
                                 "entrance pupil, so framing and defocus match the real lens (docs/mitsuba.md).")
    add_report_arguments(m)  # --lens/--focal, --fstop, --focus, the sensor, --meters-per-unit, --shutter-angle
    add_lenient(m)
    m.add_argument("--width-px", type=int, default=1920, metavar="PX",
                   help="film width in pixels (height follows the sensor aspect; default 1920)")
    m.add_argument("--spp", type=int, default=64, metavar="N", help="samples per pixel of the sampler (default 64)")
    m.add_argument("--fps", type=number("frames per second", positive=True), default=24.0,
                   help="frame rate for the shutter interval in seconds (default 24)")
    m.add_argument("--name", default="camera", help="file name stem of the two files (default camera)")
    m.add_argument("-o", "--output", required=True, metavar="DIR", help="folder to write <name>.xml and <name>.json into")
    m.add_argument("--force", action="store_true", help="overwrite existing files")
    m.add_argument("--json", action="store_true", help="print what was written as JSON")
    m.set_defaults(handler=run_mitsuba)


def run_mitsuba(args) -> int:
    import json
    from pathlib import Path

    from ..errors import InputError
    from ..export.mitsuba import mitsuba_camera_values, mitsuba_scene_dict, mitsuba_scene_xml
    from ..io import atomic_write, check_writable
    from .report import solve_from_args

    name = str(args.name)
    if not name or name in (".", "..") or "/" in name or "\\" in name or "\0" in name:
        raise InputError(f"--name must be a plain file name stem, got {name!r}")
    if not str(args.output):
        raise InputError("--output must name a folder")
    xml_path, json_path = Path(args.output) / f"{name}.xml", Path(args.output) / f"{name}.json"
    for path in (xml_path, json_path):
        check_writable(path, force=args.force)
    report = solve_from_args(args)
    values = mitsuba_camera_values(report, width_px=args.width_px, meters_per_unit=args.meters_per_unit,
                                   spp=args.spp, shutter_angle_deg=args.shutter_angle, fps=args.fps,
                                   shift_mm=(args.shift_x, args.shift_y))
    atomic_write(xml_path, mitsuba_scene_xml(values), force=args.force)
    atomic_write(json_path, json.dumps(mitsuba_scene_dict(values), indent=2, allow_nan=False) + "\n", force=args.force)
    if args.json:
        print_json({"xml": str(xml_path), "json": str(json_path), **values})
        return 0
    sn, pc = values["sensor"], values["physcam"]
    print(f"wrote {xml_path} and {json_path}: Mitsuba 3 thinlens for {pc['lens'] or 'a thin lens'} "
          f"({pc['focal_length_mm']:g} mm f/{pc['fstop']:g}) at {_mark(pc['focus_from_film_mm'])}")
    print(f"  fov {sn['fov']:.4f} deg (x; infinity focus would be {pc['hfov_infinity_deg']:.4f}), aperture_radius "
          f"{sn['aperture_radius']:.6g}, focus_distance {sn['focus_distance']:.6g} (scene units of "
          f"{pc['meters_per_unit']:g} m), film {sn['film']['width']} x {sn['film']['height']} px")
    for n in pc["notes"]:
        print(f"  note: {n}")
    return 0

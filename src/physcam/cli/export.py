"""``physcam export``: lens data for other tools (Unreal lens files, OpenCV/Omniverse pinholes,
Blender Cycles OSL lens cameras, RenderMan RIB camera blocks, pbrt-v4 cameras)."""

from __future__ import annotations

import shlex
import sys

from ._common import (FOCUS_HELP, FOLDER_FORCE_HELP, add_lens_argument, add_units_option, focal_length, focus, number, numbers,
                      whole)
from ._output import add_output_options, document, emit_json, print_csv


def _sensor(p) -> None:
    from .analyze import _sensor as add
    from ._common import add_lenient

    add(p)
    add_lenient(p)  # every export takes a lens


def _common(p) -> None:
    add_lens_argument(p)
    _sensor(p)
    p.add_argument("--width-px", type=whole("width in pixels", lo=0), required=True, metavar="PX", help="image width in pixels")
    p.add_argument("--height-px", type=whole("height in pixels", lo=0), required=True, metavar="PX", help="image height in pixels")


def register(sub) -> None:
    p = sub.add_parser("export", help="lens data for Unreal, OpenCV/Omniverse, Blender, RenderMan (RIB) and pbrt-v4",
                       description="Export a real lens as an Unreal Engine lens file (.ulens JSON), fitted OpenCV "
                                   "pinhole intrinsics and distortion (Omniverse's opencvPinhole lens API), a Blender "
                                   "Cycles OSL camera, a RenderMan RIB camera block or pbrt-v4 cameras.")
    s = p.add_subparsers(dest="export_command", metavar="FORMAT")

    u = s.add_parser("unreal", help="write an Unreal Engine lens file (.ulens JSON, Camera Calibration plugin)")
    _common(u)
    u.add_argument("-o", "--output", required=True, metavar="FILE", help="the lens file to write (.ulens or .json)")
    u.add_argument("--focus", type=focus("focus distance"), action="append", metavar="D",
                   help=f"focus mark from the film plane (repeat; default: infinity to the closest focus; {FOCUS_HELP}; "
                        "hyperfocal wide open)")
    u.add_argument("--zoom", action="append", default=None, metavar="POSITION",
                   help="a zoom lens's position (repeat; a focal length with its unit, 135mm, or the encoder value "
                        "0..1; default: its tabulated positions): the lens file is a focus x zoom grid (docs/zoom.md)")
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
    add_lens_argument(b)
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
    b.add_argument("--width-px", type=whole("width in pixels", lo=0), default=1920, metavar="PX",
                   help="render width in pixels (height follows the sensor aspect; default 1920)")
    b.add_argument("-o", "--output", required=True, metavar="DIR",
                   help="folder to write the shader and script into (written whole, with a physcam-manifest.json)")
    b.add_argument("--force", action="store_true", help=FOLDER_FORCE_HELP)
    add_output_options(b, what="what was written")
    add_units_option(b)
    b.add_argument("--builtin", action="store_true",
                   help="also write builtin_<lens>.py: Blender's own camera matched to the lens at this focus "
                        "(best-match pinhole, aperture, focus distance; faster, no real-lens optics)")
    b.set_defaults(handler=run_blender, output_folders=("output",))
    e = s.add_parser("blender-extension", help="write the physcam Blender extension (physcam-<version>.zip)",
                     description="Write DIR/physcam-<version>.zip, a Blender 4.2+ extension: a Camera Properties "
                                 "panel with real lenses whose focus and f-stop animate in Cycles. Install it with "
                                 "`blender --command extension install-file -r user_default -e ZIP`. See docs/blender.md.")
    e.add_argument("-o", "--output", required=True, metavar="DIR", help="folder to write the zip into")
    e.add_argument("--lens", action="append", default=None, metavar="LENS",
                   help="a lens to ship (bundled name or a lens file; repeat; default every bundled lens)")
    e.add_argument("--workers", type=whole("workers", lo=1, hi=256), default=None, metavar="N",
                   help="processes computing the lenses' tables at once (default: one per core)")
    e.add_argument("--force", action="store_true", help="overwrite an existing zip")
    add_output_options(e, what="what was written")
    e.set_defaults(handler=run_blender_extension)
    _register_rib(s)
    _register_pbrt(s)
    _register_mitsuba(s)
    p.set_defaults(handler=lambda args: (p.print_help(), 0)[1])


def _prepare(args):
    """Resolve the sensor (args.sensor_width/height), load the lens and resolve --focus (hyperfocal:
    the lens at --fstop, or wide open)."""
    from ..lens.library import load_lens
    from ..optics.sensors import custom_sensor
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
                            image_height_px=args.height_px, focus_marks_mm=args.focus, zoom_positions=args.zoom)
    import json

    atomic_write(args.output, json.dumps(data, indent=2, allow_nan=False) + "\n", force=args.force)
    pc = data["physcam"]
    if args.json:
        emit_json(document("export_unreal", {"written": str(args.output), "lens_file": data}))
        return 0
    from ._common import units_of

    if args.csv:
        print_csv(pc["marks"], units=units_of(args))
        return 0
    from ._output import Table, print_table

    units = units_of(args)
    print(f"wrote {args.output}: Unreal lens file of {pc['lens']} on {args.sensor_width:g} x {args.sensor_height:g} mm, "
          f"{args.width_px} x {args.height_px} px")
    zoomed = any(m["zoom_encoder"] is not None for m in pc["marks"])
    head = ("zoom mm",) * zoomed + ("focus", "Fx", "Fy", "K1", "K2", "K3", "pupil cm", "resid px")
    t = Table(None, head, justify=["right"] * len(head))
    for m in pc["marks"]:
        f = m["focus_from_film_mm"]
        t.add_row(*(f"{m['zoom_focal_length_mm']:.2f}",) * zoomed, _mark(float("inf") if f is None else f, units), f"{m['pinhole_focal_length_x_mm'] / args.sensor_width:.5f}",
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
    from ..optics.state import camera_state

    state = camera_state(lens, focus_mm=args.focus, sensor_mm=(args.sensor_width, args.sensor_height))
    cam = fit_opencv_pinhole(state, image_width_px=args.width_px, image_height_px=args.height_px, terms=args.terms)
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
    from ..lens.library import load_lens
    from ..trace.aperture import Aperture
    from ._common import camera_from_args, output_folder, relocated

    t0 = time.perf_counter()
    if not 16 <= args.width_px <= 65536:
        raise InputError(f"--width-px must lie in 16..65536, got {args.width_px}")
    if args.blades is not None and args.blades != int(args.blades):
        raise InputError(f"--blades must be a whole number, got {args.blades:g}")
    aperture = None
    if args.blades is not None or args.roundness or args.density:
        aperture = Aperture(int(args.blades or 0), args.blade_angle, args.roundness, args.density)
    lens = load_lens(args.lens, lenient=args.lenient)
    camera = camera_from_args(args, lens, aperture=aperture)  # the one camera: focus, iris, sensor
    sw, sh = camera.sensor_mm
    w = int(args.width_px)
    h = max(1, int(round(w * sh / sw)))
    out = Path(args.output)
    builtin = gap = None
    with output_folder(out, force=args.force, command="export blender") as tmp:  # the folder is written whole
        osl, setup = write_blender_camera(camera, tmp, dispersion=args.dispersion, fresnel=args.fresnel,
                                          resolution=(w, h), name=Path(args.lens).stem)
        if args.builtin:
            builtin, gap = _write_builtin(args, camera, w, tmp / f"builtin_{Path(args.lens).stem}.py")
    osl, setup = relocated([osl, setup], tmp, out)
    if builtin is not None:
        builtin = relocated([builtin], tmp, out)[0]
    focus = camera.focus_from_film_mm
    data = {"lens": lens.name, "shader": str(osl), "setup": str(setup), "builtin": builtin and str(builtin),
            "focus_from_film_mm": None if focus == float("inf") else focus, "fstop": args.fstop,
            "sensor_mm": [sw, sh], "resolution": [w, h], "dispersion": args.dispersion, "fresnel": args.fresnel,
            "thin_lens_gap": gap and gap.to_dict(), "seconds": round(time.perf_counter() - t0, 3)}
    if args.json:
        emit_json(document("export_blender", data, units={"length": "mm", "time": "s", "image": "pixel"}))
        return 0
    from ._common import units_of

    print(f"wrote {osl} and {setup}: {lens.name} focused at {_mark(focus, units_of(args))}"
          f"{'' if args.fstop is None else f', f/{args.fstop:g}'} on {sw:g} x {sh:g} mm, {w} x {h} px")
    # the commands are for pasting into a shell: a path with a space stays one word
    print(f"  in Blender: blender your.blend --python {shlex.quote(str(setup))}  (Cycles, CPU, OSL)")
    if builtin is not None:
        print(f"  or Blender's own camera, matched: blender your.blend --python {shlex.quote(str(builtin))}")
        print(f"  note: {gap.summary(units_of(args))}")
    return 0


def run_blender_extension(args) -> int:
    import time

    from ..export.blender_extension import build_extension

    t0 = time.perf_counter()
    names = []

    def progress(name):  # one line per lens on stderr: the whole library takes minutes
        names.append(name)
        print(f"  {name}: {time.perf_counter() - t0:.0f} s", file=sys.stderr, flush=True)

    path = build_extension(args.output, lenses=args.lens, force=args.force, progress=progress, workers=args.workers)
    data = {"zip": str(path), "lenses": names, "seconds": round(time.perf_counter() - t0, 3)}
    if args.json:
        emit_json(document("export_blender_extension", data, units={"time": "s"}))
        return 0
    print(f"wrote {path}: {len(names)} lens{'' if len(names) == 1 else 'es'}")
    print(f"  install: blender --command extension install-file -r user_default -e {shlex.quote(str(path))}")
    return 0


def _write_builtin(args, camera, width_px: int, path):
    """Blender's built-in camera matched to the lens report of ``camera`` (physcam.export.blender_camera)."""
    import math

    from ..errors import InputError
    from ..export.blender_camera import blender_camera_script, blender_camera_values
    from ..io import atomic_write
    from ..onset.report import report_camera, solve_report
    from ..optics.sensors import custom_sensor

    if math.isinf(camera.focus_from_film_mm):
        raise InputError("--builtin needs a finite focus mark (the built-in camera's focus distance); "
                         "give e.g. --focus 1000m")
    from ..onset.thin_lens_gap import thin_lens_gap

    # the report's camera: this lens at this focus on this sensor (its focus solution shared), wide open
    # without --fstop as the report says it
    report = solve_report(report_camera(focal_length_mm=None, sensor=custom_sensor(*camera.sensor_mm), fstop=args.fstop,
                                        focus_mm=camera.focus_from_film_mm, lens=camera.lens))
    blades = int(args.blades or 0)
    values = blender_camera_values(report, resolution_x=width_px, blades=blades if blades >= 3 else 0,
                                   blade_rotation_deg=args.blade_angle)
    gap = thin_lens_gap(report)
    values["thin_lens_gap"] = gap.to_dict()
    path = atomic_write(path, blender_camera_script(values, comments=[gap.summary()]), force=args.force)
    return path, gap


# --- RenderMan RIB and pbrt-v4 (issue 13; docs/renderman-pbrt.md) ---------------------------------------------
RIB_EPILOG = """\
examples:
  physcam export rib -o cam.rib --focal 40 --fstop 2.8 --focus 2.5m --sensor "35mm anamorphic" --squeeze 2
  physcam export rib -o cam.rib --lens dgauss_50mm --fstop 4 --focus 2m --sensor "ALEXA 35" --meters-per-unit 1
  physcam export rib -o old.rib --focal 50 --fstop 2 --focus 3m --legacy --blades 6 --shutter-opening 0.25,0.75
"""

PBRT_EPILOG = """\
examples:
  physcam export pbrt -o pbrt/ --lens dgauss_50mm --fstop 2.8 --focus 2m --sensor "ALEXA 35"
  physcam export pbrt -o pbrt/ --focal 35 --fstop 2 --focus 3m --camera perspective
"""


def _register_rib(s) -> None:
    import argparse

    from ._common import add_lenient
    from .report import add_report_arguments

    r = s.add_parser("rib", help="write a RenderMan RIB camera block (PxrCamera, or the legacy Hider form)",
                     description="Write the RIB camera of a lens report: Format (pixel aspect = squeeze), "
                                 "ScreenWindow (with the sensor shift), Clipping, Shutter and Projection "
                                 "\"PxrCamera\" (fov, fStop, focalLength, focalDistance in scene units, dofaspect, "
                                 "aperture shape, shutter opening); --legacy writes RenderMan 13-20's form "
                                 "(Projection \"perspective\", DepthOfField, Hider \"hidden\"). See docs/renderman-pbrt.md.",
                     epilog=RIB_EPILOG, formatter_class=argparse.RawDescriptionHelpFormatter)
    r.add_argument("-o", "--output", required=True, metavar="FILE", help="the RIB file to write (.rib)")
    add_report_arguments(r)  # --lens or --focal, the sensor, --meters-per-unit, --shutter-angle, --shift-x/-y
    add_lenient(r)
    _camera_look(r, blades_default=7)
    r.add_argument("--resolution", type=whole("resolution", lo=0), default=2048, metavar="PX",
                   help="image width in pixels (the squeezed plate; height from the sensor aspect; default 2048)")
    r.add_argument("--legacy", action="store_true",
                   help='RenderMan 13-20: Projection "perspective", DepthOfField and Hider "hidden" (seed 002)')
    r.add_argument("--force", action="store_true", help="overwrite an existing file")
    add_output_options(r, what="the written path and the RIB numbers")
    add_units_option(r)
    r.set_defaults(handler=run_rib)


def _camera_look(p, blades_default) -> None:
    p.add_argument("--blades", type=number("blade count", lo=0, hi=64), default=blades_default, metavar="N",
                   help=f"iris blades (apertureNSides; below 3 round; default {blades_default})")
    p.add_argument("--blade-angle", type=number("blade angle"), default=0.0, metavar="DEG",
                   help="aperture polygon angle, degrees (apertureAngle; default 0)")
    p.add_argument("--roundness", type=number("roundness", lo=-1, hi=1), default=0.0, metavar="R",
                   help="iris roundness -1..1 (0 straight blades, 1 a circle; default 0)")
    p.add_argument("--density", type=number("aperture density", lo=-1, hi=1), default=0.0, metavar="D",
                   help="bokeh brightness slope -1..1 (0 flat, > 0 bright rim; default 0)")
    p.add_argument("--shutter-opening", type=numbers("shutter opening", 2), default=(0.0, 1.0), metavar="OPEN,CLOSE",
                   help="fractions of the shutter interval where the shutter is fully open and starts closing "
                        "(seed 002; default 0,1: instantaneous)")


def _thin_lens_gap(args, report):
    from .report import thin_lens_gap_from_args

    return thin_lens_gap_from_args(args, report)


def _report(args):
    """The lens report of the command's arguments (a focus mark, or one solved from --near/--far)."""
    from ._common import note
    from .report import solve_from_args

    report = solve_from_args(args)
    if getattr(args, "sensor_defaulted", False):  # the report keeps it in its notes; an export says it on stderr
        note(next(n for n in report.notes if n.startswith("no --sensor given")))
    return report


def run_rib(args) -> int:
    from ..errors import InputError
    from ..export.renderman import rib_camera_block, rib_camera_values
    from ..export.usdgeom import focus_distance_from_pupil_mm
    from ..io import atomic_write, check_writable

    check_writable(args.output, force=args.force)
    if not 16 <= args.resolution <= 65536:
        raise InputError(f"--resolution must lie in 16..65536 pixels, got {args.resolution}")
    if args.blades != int(args.blades):
        raise InputError(f"--blades must be a whole number, got {args.blades:g}")
    with _warnings_after_success():
        report = _report(args)
        if report.focus_is_infinite:
            raise InputError("a RIB camera's focalDistance is finite: give the focus mark (e.g. --focus 1000m) "
                             "or --focus hyperfocal")
        values = rib_camera_values(report, args.meters_per_unit, xres=args.resolution,
                                   shift_mm=(args.shift_x, args.shift_y), shutter_angle_deg=args.shutter_angle,
                                   shutter_opening=args.shutter_opening,
                                   aperture=(int(args.blades), args.blade_angle, args.roundness, args.density))
        lens = report.lens_name or f"{report.focal_length_mm:g} mm thin lens"
        pupil = report.entrance_pupil_from_film_mm if report.entrance_pupil_from_film_mm is not None \
            else report.h1_from_film_mm
        mpu = args.meters_per_unit
        comments = [
            f"physcam: {'legacy (RenderMan 13-20)' if args.legacy else 'PxrCamera (RenderMan 22+)'} camera for {lens}, "
            f"f/{report.fstop:.3g}, focus mark {report.focus_from_film_mm / 1000.0:g} m from the film, on "
            f"{report.sensor.name} ({report.sensor.width_mm:g} x {report.sensor.height_mm:g} mm), squeeze "
            f"{report.squeeze:g}",
            f"scene unit = {mpu:g} m; the camera is the lens's best-match pinhole ({report.pinhole[0]:.6g} mm) at the "
            f"entrance pupil, {pupil / (1000.0 * mpu):.6g} units in front of the film; focalDistance is measured "
            "from there",
            "fov spans the screen window's shorter side (the ScreenWindow unit); Shutter is in frames",
        ]
        gap = _thin_lens_gap(args, report)
        if gap is not None:
            comments.append(gap.summary())
        text = rib_camera_block(values, legacy=args.legacy, comments=comments)
        path = atomic_write(args.output, text, force=args.force)
    proj = values["Projection"]
    if args.json:
        emit_json(document("export_rib", {
            "written": str(path), "form": "legacy" if args.legacy else "PxrCamera", "meters_per_unit": mpu,
            "rib": values, "focus_from_pupil_mm": focus_distance_from_pupil_mm(report),
            "fov_deg": {"horizontal": report.hfov_focus_deg, "vertical": report.vfov_focus_deg},
            "thin_lens_gap": gap and gap.to_dict()},
            units={"length": "mm", "angle": "degree", "rib": "scene units of meters_per_unit m"}))
        return 0
    from ._common import units_of

    print(f"wrote {path}: {'legacy RIB' if args.legacy else 'PxrCamera'} for {lens} at f/{report.fstop:.3g}, "
          f"focus {_mark(report.focus_from_film_mm, units_of(args))}")
    f = values["Format"]
    print(f"  Format {f['xres']} x {f['yres']} pixel aspect {f['pixelaspect']:g}; fov {proj['fov']:.4f} deg "
          f"(shorter side); fStop {proj['fStop']:.4g}, focalLength {proj['focalLength']:.6g}, focalDistance "
          f"{proj['focalDistance']:.6g} (units of {mpu:g} m); dofaspect {proj['dofaspect']:.4g}")
    if gap is not None:
        print(f"  note: {gap.summary(units_of(args))}")
    return 0


def _register_pbrt(s) -> None:
    import argparse

    from ._common import add_lenient

    b = s.add_parser("pbrt", help="write pbrt-v4 cameras: the lens .dat with a realistic camera, and the thin lens",
                     description="Write pbrt-v4 files for a lens report: <lens>.dat (the lens focused at the mark) and "
                                 "<lens>_realistic.pbrt (Film + Camera \"realistic\"), <lens>_perspective.pbrt (the thin "
                                 "lens: fov, lensradius, focaldistance). Reports the film distance pbrt's own thick-lens "
                                 "focusing will choose next to physcam's. Scene in metres. See docs/renderman-pbrt.md.",
                     epilog=PBRT_EPILOG, formatter_class=argparse.RawDescriptionHelpFormatter)
    b.add_argument("-o", "--output", required=True, metavar="DIR",
                   help="folder to write the files into (written whole, with a physcam-manifest.json)")
    b.add_argument("--lens", metavar="NAME_OR_FILE", help="a real lens (bundled name or prescription file)")
    b.add_argument("--focal", metavar="MM", type=focal_length(),
                   help="or a thin lens of this focal length (mm): the perspective camera only")
    b.add_argument("--fstop", metavar="N", type=number("f-stop", positive=True),
                   help="f-stop (geometric f-number; with --lens default wide open)")
    b.add_argument("--focus", metavar="DIST", type=focus("focus distance", allow_inf=False), required=True,
                   help="focus mark, film plane to subject (e.g. 2m, 7ft; or hyperfocal at --fstop)")
    from ._common import add_sensor_options
    from .report import add_coc_option

    add_sensor_options(b)
    add_coc_option(b, "for the DOF comparison: ")
    add_lenient(b)
    b.add_argument("--camera", choices=("both", "realistic", "perspective"), default="both",
                   help="which pbrt camera to write (default both; a thin lens --focal has only perspective)")
    b.add_argument("--resolution", type=whole("resolution", lo=0), default=1920, metavar="PX",
                   help="film width in pixels (height from the sensor aspect; default 1920)")
    b.add_argument("--force", action="store_true", help=FOLDER_FORCE_HELP)
    add_output_options(b, what="the written paths and pbrt's numbers")
    add_units_option(b)
    b.set_defaults(handler=run_pbrt, output_folders=("output",))


class _warnings_after_success:
    """Hold physcam's warnings until the command has succeeded: a refusal stays one line on stderr."""

    def __enter__(self):
        import warnings

        self._ctx = warnings.catch_warnings(record=True)
        self._caught = self._ctx.__enter__()
        warnings.simplefilter("always")
        return self

    def __exit__(self, *exc):
        import warnings

        self._ctx.__exit__(*exc)
        if exc[0] is None:
            seen = set()
            for w in self._caught:
                if str(w.message) not in seen:
                    seen.add(str(w.message))
                    warnings.showwarning(w.message, w.category, w.filename, w.lineno)
        return False


def _slug(text: str) -> str:
    import re
    from pathlib import Path

    p = Path(text)
    stem = p.stem if p.suffix.lower() in (".toml", ".dat", ".json", ".zmx", ".txt", ".seq") else p.name
    slug = re.sub(r"[^A-Za-z0-9_+-]+", "_", stem).strip("_")
    return slug[:80] or "lens"


def run_pbrt(args) -> int:
    from ..errors import InputError
    from ..export.pbrt import check_pbrt_lens, write_pbrt_camera
    from ..onset.report import report_camera, solve_report
    from ._common import coc_of, output_folder, relocated
    from .report import resolve_sensor

    if not 16 <= args.resolution <= 65536:
        raise InputError(f"--resolution must lie in 16..65536 pixels, got {args.resolution}")
    if (args.lens is None) == (args.focal is None):
        raise InputError("give a lens (--lens NAME) or a thin lens's focal length (--focal MM), one of them")
    lens = None
    if args.lens:
        from ..lens.library import load_lens

        lens = load_lens(args.lens, lenient=args.lenient)
    cameras = {"both": ("realistic", "perspective") if lens is not None else ("perspective",),
               "realistic": ("realistic",), "perspective": ("perspective",)}[args.camera]
    if lens is not None and ("realistic" in cameras or lens.is_anamorphic):
        check_pbrt_lens(lens)  # before anything is solved: what pbrt cannot hold is refused first
    if "realistic" in cameras and lens is None:
        raise InputError("pbrt-v4's realistic camera traces a lens prescription: give a lens (--lens NAME); "
                         "a thin lens (--focal) has only the perspective camera (--camera perspective)")
    with _warnings_after_success():
        if lens is None and args.fstop is None:
            raise InputError("give the f-stop of the thin lens (--fstop)")
        report = solve_report(report_camera(focal_length_mm=args.focal, sensor=resolve_sensor(args), fstop=args.fstop,
                               focus_mm=args.focus, coc=coc_of(args), lens=lens))
        name = _slug(args.lens) if args.lens else f"thin_{report.focal_length_mm:g}mm".replace(".", "_")
        with output_folder(args.output, force=args.force, command="export pbrt") as tmp:  # written whole
            out = write_pbrt_camera(report, tmp, lens, name=name, xres=args.resolution, cameras=cameras)
        out["written"] = dict(zip(out["written"], relocated(out["written"].values(), tmp, args.output)))
    if args.json:
        emit_json(document("export_pbrt", out, units={"length": "mm", "angle": "degree",
                                                      "pbrt": "metres (scene), mm (lens .dat)"}))
        return 0
    print(f"wrote {', '.join(out['written'].values())}")
    v = out["values"]
    film = v["film"]
    print(f"  Film {film['xresolution']} x {film['yresolution']}, diagonal {film['diagonal']:.4f} mm "
          f"({film['width_mm']:.4g} x {film['height_mm']:.4g} mm); scene in metres")
    if "perspective" in v:
        p = v["perspective"]
        print(f"  perspective: fov {p['fov']:.4f} deg ({p['fov_axis']}), lensradius {p['lensradius']:.6g} m, "
              f"focaldistance {p['focaldistance']:.6g} m (from the entrance pupil)")
    if "realistic" in v:
        r = v["realistic"]
        c = out["focus"]
        print(f"  realistic: aperturediameter {r['aperturediameter']:.4f} mm (the stop at f/{report.fstop:.3g}), "
              f"focusdistance {r['focusdistance']:.6g} m (from the film)")
        print(f"  film distance (last vertex to film): physcam {c['physcam_film_distance_mm']:.6f} mm, pbrt's thick "
              f"lens {c['pbrt_film_distance_mm']:.6f} mm, difference {c['difference_mm']:+.2e} mm")
        landed = c["pbrt_focus_from_film_mm"]
        if landed is None:
            print("  pbrt's film lies inside the focal length: its plane of focus is beyond infinity")
        else:
            print(f"  pbrt's plane of focus lands {landed / 1000.0:.6f} m from the film ({c['focus_shift_mm']:+.3f} mm); "
                  f"near limit {_shift(c['near_shift_mm'])}, far limit {_shift(c['far_shift_mm'])}")
        if c["unit_focus_film_distance_mm"] is not None:
            print(f"  given this lens at its infinity gaps pbrt would extend it instead: film "
                  f"{c['unit_focus_film_distance_mm']:.4f} mm behind the lens, EFL {c['unit_focus_efl_mm']:.4f} mm "
                  f"(focus groups: {c['efl_mm']:.4f} mm)")
    for n in out["notes"]:
        print(f"  note: {n}")
    return 0


def _shift(v) -> str:
    return "unchanged (at infinity)" if v is None else f"{v:+.3f} mm"


# --- physcam export mitsuba (Mitsuba 3 thinlens sensor; docs/mitsuba.md) ----------------------------
def _register_mitsuba(s) -> None:
    from ._common import add_lenient
    from .report import add_report_arguments

    m = s.add_parser("mitsuba", help="write a Mitsuba 3 thinlens sensor (scene XML and dict JSON) matching the lens report",
                     description="Write <name>.xml (a Mitsuba 3 scene holding the sensor; <include> it or load it with "
                                 "mi.load_file) and <name>.json (the same sensor as a mi.load_dict dictionary) for the "
                                 "lens report of these options: the field of view of the focused lens and its "
                                 "entrance pupil, so framing and defocus match the real lens (docs/mitsuba.md).")
    add_report_arguments(m)  # --lens/--focal, --fstop, --focus, the sensor, --meters-per-unit, --shutter-angle
    add_lenient(m)
    m.add_argument("--width-px", type=whole("width in pixels", lo=0), default=1920, metavar="PX",
                   help="film width in pixels (height follows the sensor aspect; default 1920)")
    m.add_argument("--spp", type=whole("samples per pixel", lo=0), default=64, metavar="N", help="samples per pixel of the sampler (default 64)")
    m.add_argument("--fps", type=number("frames per second", positive=True), default=24.0,
                   help="frame rate for the shutter interval in seconds (default 24)")
    m.add_argument("--name", default="camera", help="file name stem of the two files (default camera)")
    m.add_argument("-o", "--output", required=True, metavar="DIR",
                   help="folder to write <name>.xml and <name>.json into (written whole, with a physcam-manifest.json)")
    m.add_argument("--force", action="store_true", help=FOLDER_FORCE_HELP)
    add_output_options(m, what="what was written")
    add_units_option(m)
    m.set_defaults(handler=run_mitsuba, output_folders=("output",))


def _mitsuba_files(args, xml_path, json_path) -> tuple:
    """Solve the report of ``args``, write the scene XML and dict JSON, return the camera values and the thin-lens
    gap (or None)."""
    import json

    from ..errors import InputError
    from ..export.mitsuba import mitsuba_camera_values, mitsuba_scene_dict, mitsuba_scene_xml
    from ..io import atomic_write

    report = _report(args)
    if report.focus_is_infinite:
        raise InputError("a Mitsuba thinlens sensor's focus_distance is finite: give the focus mark (e.g. --focus "
                         "1000m) or --focus hyperfocal")
    values = mitsuba_camera_values(report, width_px=args.width_px, meters_per_unit=args.meters_per_unit,
                                   spp=args.spp, shutter_angle_deg=args.shutter_angle, fps=args.fps,
                                   shift_mm=(args.shift_x, args.shift_y))
    gap = _thin_lens_gap(args, report)
    values["thin_lens_gap"] = gap and gap.to_dict()
    if gap is not None:
        values["physcam"]["notes"].append(gap.summary())
    atomic_write(xml_path, mitsuba_scene_xml(values))
    atomic_write(json_path, json.dumps(mitsuba_scene_dict(values), indent=2, allow_nan=False) + "\n")
    return values, gap


def run_mitsuba(args) -> int:
    from pathlib import Path

    from ..errors import InputError
    from ._common import output_folder

    name = str(args.name)
    if not name or name in (".", "..") or "/" in name or "\\" in name or "\0" in name:
        raise InputError(f"--name must be a plain file name stem, got {name!r}")
    if not str(args.output):
        raise InputError("--output must name a folder")
    xml_path, json_path = Path(args.output) / f"{name}.xml", Path(args.output) / f"{name}.json"
    with output_folder(args.output, force=args.force, command="export mitsuba") as tmp:  # written whole
        values, gap = _mitsuba_files(args, tmp / xml_path.name, tmp / json_path.name)
    if args.json:
        emit_json(document("export_mitsuba", {"xml": str(xml_path), "json": str(json_path), **values},
                           units={"length": "mm", "angle": "degree", "sensor": "scene units of meters_per_unit m"}))
        return 0
    from ._common import units_of

    sn, pc = values["sensor"], values["physcam"]
    print(f"wrote {xml_path} and {json_path}: Mitsuba 3 thinlens for {pc['lens'] or 'a thin lens'} "
          f"({pc['focal_length_mm']:g} mm f/{pc['fstop']:g}) at {_mark(pc['focus_from_film_mm'], units_of(args))}")
    print(f"  fov {sn['fov']:.4f} deg (x; infinity focus would be {pc['hfov_infinity_deg']:.4f}), aperture_radius "
          f"{sn['aperture_radius']:.6g}, focus_distance {sn['focus_distance']:.6g} (scene units of "
          f"{pc['meters_per_unit']:g} m), film {sn['film']['width']} x {sn['film']['height']} px")
    notes = list(pc["notes"])
    if gap is not None:  # the files' notes, the thin-lens gap's last: printed in --units (the files keep metres)
        notes[-1] = gap.summary(units_of(args))
    for n in notes:
        print(f"  note: {n}")
    return 0

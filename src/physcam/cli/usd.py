"""``physcam usd``: write, read and build PhysicalCamera USD files (docs/usd.md)."""

from __future__ import annotations

from ._common import distance, number

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


def register(sub) -> None:
    import argparse

    p = sub.add_parser("usd", help="PhysicalCamera USD files: write, read, kits",
                       description="Write and read PhysicalCamera USD cameras (with a companion UsdGeomCamera).",
                       epilog=EPILOG, formatter_class=argparse.RawDescriptionHelpFormatter)
    s = p.add_subparsers(dest="usd_command", metavar="ACTION")

    w = s.add_parser("write", help="write the USD camera of a lens report")
    w.add_argument("file", help="output .usda/.usd/.usdc")
    from .report import add_report_arguments

    add_report_arguments(w)  # brings --meters-per-unit and --shutter-angle with it
    _stage_args(w, units=False)
    w.add_argument("--path", default="/Cameras/Camera", help="camera prim path (default /Cameras/Camera)")
    w.add_argument("--orthographic", action="store_true", help="orthographic (telecentric) camera")
    w.add_argument("--magnification", type=number("magnification"), default=1.0,
                   help="orthographic: image size / object size (default 1)")
    w.add_argument("--blades", type=int, default=7, help="iris blades (RenderMan apertureNSides; default 7)")
    w.set_defaults(handler=run_write)

    r = s.add_parser("read", help="read a PhysicalCamera back into a lens report")
    r.add_argument("file")
    r.add_argument("--path", default=None, help="camera prim path (default: the only PhysicalCamera)")
    r.add_argument("--json", action="store_true", help="print JSON")
    r.set_defaults(handler=run_read)

    k = s.add_parser("kit", help="the proposal's use cases: previs kit, vendor lens file")
    k.add_argument("kind", choices=("previs", "vendor"))
    k.add_argument("file")
    k.add_argument("--lens", help="vendor: bundled lens name or prescription file")
    k.add_argument("--focus", type=distance("focus distance"), help="vendor: focus mark for the best-match pinhole")
    k.add_argument("--fstop", type=number("f-stop"), help="vendor: f-stop (default the lens's maximum)")
    _stage_args(k)
    k.set_defaults(handler=run_kit)

    pp = s.add_parser("plugin-path", help="print the schema plugin folder for PXR_PLUGINPATH_NAME")
    pp.set_defaults(handler=run_plugin_path)
    p.set_defaults(handler=lambda args: (p.print_help(), 0)[1])


def _stage_args(p, units: bool = True) -> None:
    if units:
        p.add_argument("--meters-per-unit", type=number("metersPerUnit"), default=0.01,
                       help="stage metersPerUnit (default 0.01: centimetres)")
    p.add_argument("--fps", type=number("frames per second", positive=True), default=24.0, help="timeCodesPerSecond (default 24)")
    p.add_argument("--force", action="store_true", help="overwrite an existing file")
    p.add_argument("--json", action="store_true", help="print what was written as JSON")


def run_write(args) -> int:
    from ..usd.author import spec_from_report, write_camera
    from .report import solve_from_args

    from ..export.usdgeom import shutter_interval

    shutter_interval(args.shutter_angle)  # validates 0 < angle <= 360
    report = solve_from_args(args)
    spec = spec_from_report(report, projection="orthographic" if args.orthographic else "perspective",
                            magnification=args.magnification, aperture_blades=args.blades,
                            shutter_duration_s=args.shutter_angle / 360.0 / args.fps,
                            shift_mm=(args.shift_x, args.shift_y))
    distortion = None
    if getattr(args, "lens", None) and not args.orthographic:  # a prescription-backed report: its real distortion
        from ..lens.library import load_lens
        from ..usd.kit import prescription_distortion

        distortion = prescription_distortion(load_lens(args.lens), report.sensor.width_mm, report.sensor.height_mm)
    path = write_camera(args.file, spec, force=args.force, path=args.path, meters_per_unit=args.meters_per_unit,
                        fps=args.fps, report=report if not args.orthographic else None, lens_distortion=distortion)
    return _done(args, path)


def _done(args, path) -> int:
    if getattr(args, "json", False):
        from ._common import print_json

        print_json({"written": str(path)})
    else:
        print(f"wrote {path}")
    return 0


def run_read(args) -> int:
    from ..usd.read import open_stage, read_camera

    reading = read_camera(open_stage(args.file), args.path)
    report = reading.report()
    if args.json:
        from ._common import print_json

        print_json({"usd": reading.to_dict(), "report": report.to_dict()})
        return 0
    s = reading.spec
    print(f"{reading.path}: {s.focal_length_mm:.4g} mm f/{s.fstop:.3g} focus {s.focus_mm:.6g} mm "
          f"sensor {s.sensor_width_mm:g} x {s.sensor_height_mm:g} mm ({reading.lens_model_type})")
    print(f"  hfov {report.hfov_inf_deg:.4f} deg, vfov {report.vfov_inf_deg:.4f} deg; "
          f"DOF from film {report.dof.near_from_film_mm:.1f} mm to "
          f"{'inf' if report.dof.far_is_infinite else f'{report.dof.far_from_film_mm:.1f} mm'}")
    for k, v in reading.variants.items():
        print(f"  variant {k} = {v}")
    return 0


def run_kit(args) -> int:
    from ..errors import InputError
    from ..usd import kit

    if args.kind == "previs":
        path = kit.write_previs_kit(args.file, force=args.force, meters_per_unit=args.meters_per_unit, fps=args.fps)
    else:
        if not args.lens or args.focus is None:
            raise InputError("physcam usd kit vendor needs --lens and --focus")
        from ..lens.library import load_lens

        path = kit.write_vendor_lens(args.file, load_lens(args.lens), focus_mm=args.focus, fstop=args.fstop,
                                     force=args.force, meters_per_unit=args.meters_per_unit, fps=args.fps)
        if args.json:  # what the file says, read back: the matched pinhole, the variant, the distortion fit
            from ..usd.read import open_stage, read_camera
            from ._common import print_json

            stage = open_stage(path)
            geom = stage.GetPrimAtPath(f"{kit.LENS_PRIM}/Camera")
            distortion = {a.GetName().split(":", 1)[1]: a.Get() for a in geom.GetAttributes()
                          if a.GetName().startswith("lensDistortion:")} if geom else {}
            distortion = {k: (list(v) if hasattr(v, "__len__") and not isinstance(v, str) else v)
                          for k, v in distortion.items()}
            print_json({"written": str(path), "usd": read_camera(stage, kit.LENS_PRIM).to_dict(),
                        "lens_distortion": distortion})
            return 0
    return _done(args, path)


def run_plugin_path(args) -> int:
    from ..usd.plugin import PLUGIN_DIR

    print(PLUGIN_DIR)
    return 0

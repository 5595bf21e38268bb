"""``physcam illumination|colour|breathing-real|ghosts LENS``: real-ray analyses (docs/analyses.md).

``physcam distortion`` lives in :mod:`physcam.cli.distortion` and shares this module's options.

Top-level commands, like ``physcam spot`` and ``physcam bokeh``. Each prints a table, or JSON
with ``--json``, and writes a plot with ``-o FILE.png`` (never over a file unless ``--force``).
"""

from __future__ import annotations

import math

from ._common import distance, number, print_json
from .lens import add_lenient, mark_repaired


def _common(p, plot_help: str) -> None:
    p.add_argument("lens", metavar="NAME_OR_FILE", help="bundled lens name (see `physcam lenses`) or a lens file")
    add_lenient(p)
    p.add_argument("--json", action="store_true", help="print as JSON")
    p.add_argument("-o", "--output", metavar="FILE.png", help=plot_help)
    p.add_argument("--force", action="store_true", help="overwrite an existing output file")


def _sensor(p) -> None:
    p.add_argument("--sensor", metavar="NAME", help='sensor or gate name, e.g. "ALEXA 35" (default full frame 36x24)')
    p.add_argument("--sensor-width", type=distance("sensor width"), default=None, metavar="MM",
                   help="sensor width with --sensor-height (instead of --sensor)")
    p.add_argument("--sensor-height", type=distance("sensor height"), default=None, metavar="MM",
                   help="sensor height with --sensor-width")


def _resolve_sensor(args) -> None:
    """Fill args.sensor_width/height (mm) from --sensor NAME, or the pair, or full frame 36x24."""
    from .report import resolve_sensor

    if not hasattr(args, "sensor_width"):
        return
    s = resolve_sensor(args, default="Full Frame")
    args.sensor_width, args.sensor_height = s.width_mm, s.height_mm


def register(sub) -> None:
    p = sub.add_parser("illumination", help="relative illumination against field (vignetting, cos^4 from real rays)")
    _common(p, "write the relative illumination plot")
    p.add_argument("--field", type=number("field angle"), action="append", metavar="DEG",
                   help="field angle in degrees (repeat; default: from the axis to the sensor corner)")
    p.add_argument("--max-field", type=number("max field"), default=None, metavar="DEG",
                   help="widest field angle in degrees (default: the sensor corner)")
    p.add_argument("--fstop", type=number("f-stop"), default=None, help="stop the lens down to this f-number")
    p.add_argument("--grid", type=int, default=200, help="rays per side of the sampling grid (16-2000, default 200)")
    p.add_argument("--fresnel", action="store_true", help="include Fresnel losses at every surface")
    _sensor(p)
    p.set_defaults(handler=run_illumination)

    p = sub.add_parser("colour", aliases=["color"], help="longitudinal and lateral colour (F, d, C and more)")
    _common(p, "write the chromatic aberration plot")
    p.add_argument("--field", type=number("field angle"), action="append", metavar="DEG",
                   help="field angle in degrees (repeat; default: from the axis to the sensor corner)")
    p.add_argument("--max-field", type=number("max field"), default=None, metavar="DEG",
                   help="widest field angle in degrees (default: the sensor corner)")
    p.add_argument("--wavelength", type=number("wavelength"), action="append", metavar="NM",
                   help="extra wavelength to report (repeat); F and C are always included")
    _sensor(p)
    p.set_defaults(handler=run_colour)

    p = sub.add_parser("breathing-real", help="focus breathing from real chief rays against the paraxial table")
    _common(p, "write the breathing plot")
    p.add_argument("--focus", type=distance("focus distance", allow_inf=True), action="append", metavar="DIST",
                   help="focus mark from the film (repeat; units ok: 2m, 6ft, inf)")
    p.add_argument("--method", choices=("auto", "unit", "internal"), default="auto",
                   help="focusing: unit (whole lens moves) or internal (focus groups); auto: internal when the lens has groups")
    _sensor(p)
    p.set_defaults(handler=run_breathing)

    p = sub.add_parser("ghosts", help="double-bounce ghost paths ranked by intensity, and a ghost image")
    _common(p, "write the ghost image of a point light")
    p.add_argument("--field", type=number("field angle"), default=10.0, metavar="DEG",
                   help="field angle of the light (degrees, Y meridian; default 10)")
    p.add_argument("--coating", choices=("none", "single", "multi"), default=None,
                   help="coating model (default: the lens file's, else none)")
    p.add_argument("--rays", type=int, default=200_000, help="rays per ghost path for the image")
    p.add_argument("--top", type=int, default=10, help="how many ranked paths to print")
    p.add_argument("--pixels", type=int, default=256, help="ghost image width in pixels (8 to 4096; default 256)")
    _sensor(p)
    p.set_defaults(handler=run_ghosts)


def _prepare(args):
    from ..io import check_writable
    from ..lens.library import load_lens

    if args.output:
        check_writable(args.output, force=args.force)
    _resolve_sensor(args)
    args.loaded_lens = load_lens(args.lens, lenient=args.lenient)
    return args.loaded_lens


def _finish(args, res) -> None:
    if args.output:
        res.plot(args.output, force=args.force)
    if args.json:
        print_json(mark_repaired(res.to_dict(), args.loaded_lens))
    elif args.output:
        print(f"wrote {args.output}")


def _resolution(text: str):
    """``WxH`` in whole pixels (argparse type)."""
    import argparse

    parts = str(text).lower().replace("×", "x").split("x")
    try:
        w, h = (int(v) for v in parts)
    except ValueError:
        raise argparse.ArgumentTypeError(f"resolution must be WIDTHxHEIGHT in pixels, e.g. 2048x1366, got {text!r}")
    return w, h


def run_illumination(args) -> int:
    from ..analysis.illumination import relative_illumination
    from ..optics.paraxial import stop_semi_diameter_for_fstop

    lens = _prepare(args)
    sd = None if args.fstop is None else stop_semi_diameter_for_fstop(lens, args.fstop)
    res = relative_illumination(lens, args.field, max_field_deg=args.max_field, grid=args.grid, fresnel=args.fresnel,
                                stop_semi_diameter=sd, sensor_width_mm=args.sensor_width,
                                sensor_height_mm=args.sensor_height)
    if not args.json:
        print(f"{res.lens_name}: relative illumination at {res.wavelength_nm:g} nm"
              + (f", f/{args.fstop:g}" if args.fstop else ""))
        print(f"  {'axis':>4} {'field deg':>9} {'RI':>7} {'cos^4':>7} {'vignet.':>7} {'height mm':>9}")
        for p in res.points:
            print(f"  {p.axis:>4} {p.field_deg:9.3f} {p.relative_illumination:7.4f} {p.cos4:7.4f} "
                  f"{p.vignetting_factor:7.4f} {p.film_height_mm:9.3f}")
    _finish(args, res)
    return 0


def run_colour(args) -> int:
    from ..analysis.colour import chromatic_aberration
    from ..optics.glass import LINE_C_NM, LINE_D_NM, LINE_F_NM

    lens = _prepare(args)
    wls = (LINE_F_NM, LINE_D_NM, LINE_C_NM) + tuple(args.wavelength or ())
    res = chromatic_aberration(lens, args.field, wavelengths_nm=wls, max_field_deg=args.max_field,
                               sensor_width_mm=args.sensor_width, sensor_height_mm=args.sensor_height)
    if not args.json:
        print(f"{res.lens_name}: chromatic aberration (EFL {res.efl_mm:.3f} mm at {res.reference_nm:g} nm)")
        print(f"  longitudinal colour C - F: paraxial {res.longitudinal_paraxial_mm * 1e3:.2f} um, "
              f"real ({res.zone:.3g} zone) {res.longitudinal_real_mm * 1e3:.2f} um")
        if res.media:
            print(f"  uncertainty (one sigma, P_gF of normal-line glasses): C - F +-{res.longitudinal_uncertainty_mm * 1e3:.2f}"
                  f" um, focus-shift curve 400-700 nm up to +-{res.curve_uncertainty_mm * 1e3:.1f} um")
            print("  dispersion models:")
            for m in res.media:
                print(f"    surfaces {','.join(str(i) for i in m['surfaces'])}: {m['description']}")
        for w, zp, zr in zip(res.wavelengths_nm, res.paraxial_focus_z_mm, res.real_focus_z_mm):
            print(f"    {w:9.4f} nm  paraxial focus z {zp:10.4f} mm  real zone focus z {zr:10.4f} mm")
        print("  lateral colour F - C on the film:")
        for p in res.lateral:
            print(f"    field {p.field_deg:7.3f} deg  {p.lateral_colour_um:9.3f} um")
        for n in res.notes:
            print(f"  note: {n}")
    _finish(args, res)
    return 0


def run_breathing(args) -> int:
    from ..analysis.breathing_real import real_breathing

    lens = _prepare(args)
    res = real_breathing(lens, args.focus, sensor_width_mm=args.sensor_width, sensor_height_mm=args.sensor_height,
                         method=args.method)
    if not args.json:
        print(f"{res.lens_name}: focus breathing ({res.method} focusing), sensor "
              f"{res.sensor_mm[0]:g} x {res.sensor_mm[1]:g} mm")
        print(f"  {'focus mm':>10} {'HFOV par':>9} {'HFOV real':>9} {'DFOV real':>9} {'chg par %':>9} {'chg real %':>10}")
        for r in res.rows:
            f = "∞" if math.isinf(r.focus_from_film_mm) else f"{r.focus_from_film_mm:.0f}"
            dfov = "-" if r.dfov_real_deg is None else f"{r.dfov_real_deg:.3f}"
            print(f"  {f:>10} {r.hfov_paraxial_deg:9.3f} {r.hfov_real_deg:9.3f} {dfov:>9} "
                  f"{r.change_paraxial_pct:9.3f} {r.change_real_pct:10.3f}")
    _finish(args, res)
    return 0


def run_ghosts(args) -> int:
    from ..analysis.ghosts import ghost_analysis

    lens = _prepare(args)
    res = ghost_analysis(lens, args.field, coating=args.coating, image_rays=args.rays if args.output else 0,
                         pixels=args.pixels, sensor_width_mm=args.sensor_width, sensor_height_mm=args.sensor_height)
    if not args.json:
        print(f"{res.lens_name}: {len(res.paths)} double-bounce ghost paths, light at {res.field_deg:g} deg, "
              f"coating {res.coating}")
        print(f"  {'rank':>4} {'surfaces':>9} {'rel. flux':>10} {'RMS r mm':>9} {'centroid y mm':>13}")
        for n, g in enumerate(res.paths[: args.top], start=1):
            c = "-" if g.centroid_y_mm is None else f"{g.centroid_y_mm:.3f}"
            r = "-" if g.rms_radius_mm is None else f"{g.rms_radius_mm:.3f}"
            print(f"  {n:4d} {g.i:4d}->{g.j:<4d} {g.relative_flux:10.3e} {r:>9} {c:>13}")
    _finish(args, res)
    return 0

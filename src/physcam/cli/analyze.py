"""``physcam illumination|colour|breathing-real|ghosts LENS``: real-ray analyses (docs/analyses.md).

``physcam distortion`` lives in :mod:`physcam.cli.distortion` and shares this module's options.

Top-level commands, like ``physcam spot`` and ``physcam bokeh``. Each prints a table (``--csv``
for its rows), or JSON with ``--json``, and writes a plot with ``-o FILE.png`` (never over a file
unless ``--force``). The sensor is the one default (Super 35, 24.89 x 18.66 mm) unless given. Without ``--field``
or ``--max-field`` the fields reach the sensor corner, clamped (with a note) to what the lens
images, as ``physcam distortion`` does.
"""

from __future__ import annotations


from ._common import add_lens_argument, FOCUS_HELP, add_sensor_options, add_units_option, focus, hidden_alias, number, whole, figure_file
from ._output import add_output_options, document, emit_json, print_csv
from ._common import add_lenient, mark_repaired
from .lens import WAVE_UNITS

#: How each analysis names its document (``physcam.NAME``), its rows (for --csv) and its units.
DOCS = {"illumination": ("illumination", "points"), "colour": ("colour", "lateral"),
        "breathing-real": ("breathing_real", "rows"), "ghosts": ("ghosts", "paths"),
        "distortion": ("distortion", "points")}


def _common(p, plot_help: str) -> None:
    add_lens_argument(p)
    add_lenient(p)
    add_output_options(p, csv=True, what="the analysis")
    p.add_argument("-o", "--output", metavar="FILE.png", type=figure_file, help=plot_help)
    p.add_argument("--force", action="store_true", help="overwrite an existing output file")


def _sensor(p) -> None:
    add_sensor_options(p)


def _resolve_sensor(args) -> None:
    """Fill args.sensor_width/height (mm) from --sensor NAME, or the pair, or the default sensor."""
    from ._common import resolve_sensor

    if not hasattr(args, "sensor_width"):
        return
    s = resolve_sensor(args)
    args.sensor_width, args.sensor_height = s.width_mm, s.height_mm
    args.sensor_name = s.name


def register(sub) -> None:
    p = sub.add_parser("illumination", help="relative illumination against field (vignetting, cos^4 from real rays)")
    _common(p, "write the relative illumination plot")
    p.add_argument("--field", type=number("field angle"), action="append", metavar="DEG",
                   help="field angle in degrees (repeat; default: from the axis to the sensor corner, clamped to "
                        "what the lens images)")
    p.add_argument("--max-field", type=number("max field"), default=None, metavar="DEG",
                   help="widest field angle in degrees (default: the sensor corner, clamped to what the lens images)")
    p.add_argument("--fstop", type=number("f-stop"), default=None, help="stop the lens down to this f-number")
    p.add_argument("--grid", type=whole("grid", lo=0), default=200, metavar="N",
                   help="rays per side of the sampling grid (16-2000, default 200)")
    p.add_argument("--fresnel", action="store_true", help="include Fresnel losses at every surface")
    _sensor(p)
    p.set_defaults(handler=run_illumination)

    p = sub.add_parser("colour", aliases=["color"], help="longitudinal and lateral colour (F, d, C and more)")
    _common(p, "write the chromatic aberration plot")
    p.add_argument("--field", type=number("field angle"), action="append", metavar="DEG",
                   help="field angle in degrees (repeat; default: from the axis to the sensor corner, clamped to "
                        "what the lens images)")
    p.add_argument("--max-field", type=number("max field"), default=None, metavar="DEG",
                   help="widest field angle in degrees (default: the sensor corner, clamped to what the lens images)")
    p.add_argument("--wavelength", type=number("wavelength"), action="append", metavar="NM",
                   help="extra wavelength to report (repeat); F and C are always included")
    _sensor(p)
    p.set_defaults(handler=run_colour)

    p = sub.add_parser("breathing-real", help="focus breathing from real chief rays against the paraxial table")
    _common(p, "write the breathing plot")
    p.add_argument("--focus", type=focus("focus distance"), action="append", metavar="DIST",
                   help=f"focus mark from the film (repeat; default: infinity to the closest focus; {FOCUS_HELP}; "
                        "hyperfocal wide open)")
    p.add_argument("--focus-method", choices=("auto", "unit", "internal"), default="auto",
                   help="focusing: unit (whole lens moves) or internal (focus groups); auto: internal when the lens has groups")
    hidden_alias(p, "--method", "focus_method", choices=("auto", "unit", "internal"))
    _sensor(p)
    add_units_option(p)
    p.set_defaults(handler=run_breathing)

    p = sub.add_parser("ghosts", help="double-bounce ghost paths ranked by intensity, and a ghost image")
    _common(p, "write the ghost image of a point light")
    p.add_argument("--field", type=number("field angle"), default=None, metavar="DEG",
                   help="field angle of the light (degrees, Y meridian; default 10, clamped to what the lens lets "
                        "through)")
    p.add_argument("--coating", choices=("none", "single", "multi"), default=None,
                   help="coating model (default: the lens file's, else none)")
    p.add_argument("--rays", type=whole("rays", lo=0), default=200_000, metavar="N",
                   help="rays per ghost path for the image (with -o; default 200000)")
    p.add_argument("--top", type=whole("top", lo=0), default=10, metavar="N", help="how many ranked paths to print (default 10)")
    p.add_argument("--pixels", type=whole("pixels", lo=0), default=256, metavar="PX",
                   help="ghost image width in pixels (8 to 4096; default 256)")
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


def _camera(args, fstop=None):
    """The one camera state of an analysis command: the lens (``_prepare``), focused at infinity, its iris
    at ``fstop`` (None: as the file stops it), on the command's sensor."""
    from ..optics.state import camera_state

    lens = _prepare(args)
    return camera_state(lens, fstop=fstop, sensor_mm=(args.sensor_width, args.sensor_height))


def _finish(args, res, command: str) -> None:
    """The plot (-o), then JSON, CSV or the notes and the written file for people."""
    name, rows = DOCS[command]
    if args.output:
        from ._output import save_plot

        from ._common import units_of

        save_plot(res, args.output, force=args.force, context=plot_context(args), units=units_of(args))
    d = mark_repaired(res.to_dict(), args.loaded_lens)
    if getattr(args, "sensor_name", None):
        d["sensor"] = args.sensor_name
    if getattr(args, "zoom_block", None) is not None:  # a zoom lens at --zoom (docs/zoom.md)
        d["zoom"] = args.zoom_block
    if args.json:
        emit_json(document(name, d, units=WAVE_UNITS))
        return
    if args.csv:
        return
    for n in d.get("notes", ()):
        print(f"note: {n}")
    if args.output:
        print(f"wrote {args.output}")


def plot_context(args) -> str:
    """What a plot is of, for its footer: f-stop, focus, sensor (those the command was given)."""
    from ..units import format_distance
    from ._common import units_of

    parts = []
    if getattr(args, "fstop", None):
        parts.append(f"f/{args.fstop:g}")
    focus = getattr(args, "focus", None)
    if isinstance(focus, float):
        parts.append(f"focus {format_distance(focus, units_of(args))}")
    if getattr(args, "sensor_name", None):
        parts.append(f"{args.sensor_name} ({args.sensor_width:g} x {args.sensor_height:g} mm)")
    return ", ".join(parts)


def _csv(args, res, command: str) -> bool:
    """With --csv: print the analysis's rows (as in its JSON) and say so."""
    if args.csv and not args.json:
        from ._common import units_of

        print_csv(res.to_dict()[DOCS[command][1]], units=units_of(args) if hasattr(args, "units") else "m")
        return True
    return False


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
    from ..analysis.image_quality.illumination import relative_illumination
    from ._output import Table, print_table

    state = _camera(args, fstop=args.fstop)
    res = relative_illumination(state, args.field, max_field_deg=args.max_field, grid=args.grid, fresnel=args.fresnel)
    if not (args.json or _csv(args, res, "illumination")):
        t = Table(f"{res.lens_name}: relative illumination at {res.wavelength_nm:g} nm"
                  + (f", f/{args.fstop:g}" if args.fstop else "") + f", {args.sensor_name}",
                  ("axis", "field deg", "RI", "cos^4", "vignet.", "height mm"), justify=["right"] * 6)
        for p in res.points:
            t.add_row(p.axis, f"{p.field_deg:.3f}", f"{p.relative_illumination:.4f}", f"{p.cos4:.4f}",
                      f"{p.vignetting_factor:.4f}", f"{p.film_height_mm:.3f}")
        print_table(t)
    _finish(args, res, "illumination")
    return 0


def run_colour(args) -> int:
    from ..analysis.image_quality.colour import chromatic_aberration
    from ..optics.glass import LINE_C_NM, LINE_D_NM, LINE_F_NM
    from ._output import Table, print_table

    # the lens as designed: colour's film is the paraxial focus of its reference line (d), camera_state's
    # is its design wavelength's (the two differ for a lens not designed at d; found in review)
    from ..optics.state import as_designed

    lens = _prepare(args)
    wls = (LINE_F_NM, LINE_D_NM, LINE_C_NM) + tuple(args.wavelength or ())
    res = chromatic_aberration(as_designed(lens, sensor_mm=(args.sensor_width, args.sensor_height)), args.field,
                               wavelengths_nm=wls, max_field_deg=args.max_field)
    if not (args.json or _csv(args, res, "colour")):
        print(f"{res.lens_name}: chromatic aberration (EFL {res.efl_mm:.3f} mm at {res.reference_nm:g} nm), "
              f"{args.sensor_name}")
        print(f"  longitudinal colour C - F: paraxial {res.longitudinal_paraxial_mm * 1e3:.2f} µm, "
              f"real ({res.zone:.3g} zone) {res.longitudinal_real_mm * 1e3:.2f} µm")
        if res.media:
            print(f"  uncertainty (one sigma, P_gF of normal-line glasses): C - F +-{res.longitudinal_uncertainty_mm * 1e3:.2f}"
                  f" µm, focus-shift curve 400-700 nm up to +-{res.curve_uncertainty_mm * 1e3:.1f} µm")
            print("  dispersion models:")
            for m in res.media:
                print(f"    surfaces {','.join(str(i) for i in m['surfaces'])}: {m['description']}")
        t = Table("focus per wavelength (lens space z, mm)", ("wavelength nm", "paraxial focus z", "real zone focus z"),
                  justify=["right"] * 3)
        for w, zp, zr in zip(res.wavelengths_nm, res.paraxial_focus_z_mm, res.real_focus_z_mm):
            t.add_row(f"{w:.4f}", f"{zp:.4f}", f"{zr:.4f}")
        print_table(t)
        t = Table("lateral colour F - C on the film", ("field deg", "lateral colour µm"), justify=["right"] * 2)
        for p in res.lateral:
            t.add_row(f"{p.field_deg:.3f}", f"{p.lateral_colour_um:.3f}")
        print_table(t)
    _finish(args, res, "colour")
    return 0


def run_breathing(args) -> int:
    from ..analysis.framing.breathing_real import real_breathing
    from ..units import format_distance
    from ._common import resolve_focus, units_of
    from ._output import Table, print_table

    lens = _prepare(args)
    from ..optics.sensors import custom_sensor

    marks = None if args.focus is None else resolve_focus(
        args.focus, lens=lens, sensor=custom_sensor(args.sensor_width, args.sensor_height), args=args)
    res = real_breathing(lens, marks, sensor_width_mm=args.sensor_width, sensor_height_mm=args.sensor_height,
                         method=args.focus_method)
    if not (args.json or _csv(args, res, "breathing-real")):
        units = units_of(args)
        t = Table(f"{res.lens_name}: focus breathing ({res.method} focusing), {args.sensor_name} "
                  f"{res.sensor_mm[0]:g} x {res.sensor_mm[1]:g} mm",
                  ("focus", "HFOV par", "HFOV real", "DFOV real", "chg par %", "chg real %"), justify=["right"] * 6)
        for r in res.rows:
            dfov = "-" if r.dfov_real_deg is None else f"{r.dfov_real_deg:.3f}"
            t.add_row(format_distance(r.focus_from_film_mm, units), f"{r.hfov_paraxial_deg:.3f}",
                      f"{r.hfov_real_deg:.3f}", dfov, f"{r.change_paraxial_pct:.3f}", f"{r.change_real_pct:.3f}")
        print_table(t)
    _finish(args, res, "breathing-real")
    return 0


def run_ghosts(args) -> int:
    from ..analysis.image_quality.ghosts import ghost_analysis
    from ._output import Table, print_table

    state = _camera(args)
    res = ghost_analysis(state, args.field, coating=args.coating, image_rays=args.rays if args.output else 0,
                         pixels=args.pixels)
    if not (args.json or _csv(args, res, "ghosts")):
        t = Table(f"{res.lens_name}: {len(res.paths)} double-bounce ghost paths, light at {res.field_deg:g} deg, "
                  f"coating {res.coating}", ("rank", "surfaces", "rel. flux", "RMS r mm", "centroid y mm"),
                  justify=["right"] * 5)
        for n, g in enumerate(res.paths[: args.top], start=1):
            c = "-" if g.centroid_y_mm is None else f"{g.centroid_y_mm:.3f}"
            r = "-" if g.rms_radius_mm is None else f"{g.rms_radius_mm:.3f}"
            t.add_row(str(n), f"{g.i}->{g.j}", f"{g.relative_flux:.3e}", r, c)
        print_table(t)
    _finish(args, res, "ghosts")
    return 0

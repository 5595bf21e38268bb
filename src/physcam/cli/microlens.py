"""``physcam microlens``: light-field cameras. ``insert`` writes a main lens with a microlens array
as ISET lens JSON (lenstool's ``insertmicrolens``); ``render`` traces it and draws the raw light
field, sub-aperture views and refocused pictures (docs/microlens.md)."""

from __future__ import annotations

from ._common import add_lens_argument, add_units_option, distance, focus, number, figure_file
from ._output import add_output_options, document, emit_json

EPILOG = """\
examples:
  physcam microlens insert --lens dgauss_50mm --microlens-focal 0.224 --xdim 77 --ydim 77 \\
      --film-width 3.08 --film-height 3.08 --focus 0.8m -o dgauss_lf.json
  physcam microlens render --lens dgauss_lf.json --fstop 5.6 --point 0.5m --point 5m -o points.png
  physcam microlens render --lens dgauss_lf.json --fstop 5.6 --plane 0.8m --plane-width 120mm -o plane.png
"""

#: limits of a render asked for on the command line (memory and time stay bounded)
MAX_CLI_RAYS = 5_000_000
MAX_CLI_SPP = 64
MAX_CLI_PIXELS = 4_000_000


def _count(name, lo, hi):
    import argparse

    def parse(text):
        try:
            v = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{name} must be a whole number, got {text!r}") from None
        if not lo <= v <= hi:
            raise argparse.ArgumentTypeError(f"{name} must lie between {lo} and {hi}, got {text!r}")
        return v

    parse.__name__ = name
    return parse


def register(sub) -> None:
    import argparse

    from ._common import add_lenient

    p = sub.add_parser("microlens", help="light-field cameras: insert a microlens array (ISET JSON), render raw "
                                         "light fields, sub-aperture views and refocused pictures",
                       description="Microlens arrays in front of the sensor (ISET3D / lenstool insertmicrolens).",
                       epilog=EPILOG, formatter_class=argparse.RawDescriptionHelpFormatter)
    s = p.add_subparsers(dest="microlens_command", metavar="ACTION")

    i = s.add_parser("insert", help="write a main lens with a microlens array as ISET lens JSON",
                     description="Write ISET lens JSON holding the main lens and a 'microlens' block "
                                 "(dimensions, lenslet surfaces, offsets), as lenstool insertmicrolens does, plus "
                                 "physcam's record of the film size, film-to-lens distance and sensor offset.")
    add_lens_argument(i, metavar="MAIN_LENS", help="the main lens: bundled name or lens file")
    i.add_argument("--microlens", metavar="NAME_OR_FILE", help="the lenslet as a prescription (lens file, mm)")
    i.add_argument("--microlens-focal", type=distance("lenslet focal length"), metavar="MM",
                   help="or an ideal thin lenslet of this focal length")
    i.add_argument("--xdim", type=_count("--xdim", 1, 4096), default=16, help="lenslets across X (default 16)")
    i.add_argument("--ydim", type=_count("--ydim", 1, 4096), default=16, help="lenslets across Y (default 16)")
    i.add_argument("--film-width", type=distance("film width"), default=20.0, metavar="MM",
                   help="film (sensor) width the array spans (default 20 mm)")
    i.add_argument("--film-height", type=distance("film height"), default=20.0, metavar="MM",
                   help="film (sensor) height the array spans (default 20 mm)")
    i.add_argument("--film-to-lens", type=distance("film-to-lens distance"), default=None, metavar="MM",
                   help="main lens rear vertex to the film (sensor) (lenstool's --filmtolens; default 50 mm "
                        "unless --focus)")
    i.add_argument("--focus", type=focus("focus distance", allow_inf=False), default=None, metavar="D",
                   help="instead of --film-to-lens: focus the main lens so a subject D in front of the sensor is "
                        "sharp on the array")
    i.add_argument("--sensor-offset", type=distance("sensor offset"), default=None, metavar="MM",
                   help="lenslet rear vertex to the sensor (default: the lenslet's back focal distance)")
    i.add_argument("-o", "--output", required=True, metavar="FILE", help="the ISET lens JSON to write")
    i.add_argument("--force", action="store_true", help="overwrite an existing file")
    add_output_options(i, what="a summary")
    add_units_option(i)
    add_lenient(i)
    i.set_defaults(handler=run_insert)

    r = s.add_parser("render", help="render the raw light field of points or a textured plane, its sub-aperture "
                                    "views and refocused pictures",
                     description="Trace a lens with a microlens array (the ISET JSON of `physcam microlens insert`) "
                                 "and draw the raw light field, sub-aperture views and, per point, the picture "
                                 "refocused on it (shift-and-add).")
    add_lens_argument(r, metavar="LENS_WITH_MICROLENS", help="an ISET lens JSON with a microlens block")
    r.add_argument("--fstop", type=number("f-number", positive=True), default=None,
                   help="stop the main lens to this f-number (default: its file's stop)")
    r.add_argument("--focus", type=focus("focus distance", allow_inf=False), default=None, metavar="D",
                   help="refocus the main lens on a subject D in front of the sensor (default: the file's "
                        "film-to-lens distance)")
    r.add_argument("--pixels-per-lenslet", type=_count("--pixels-per-lenslet", 1, 32), default=9, metavar="N",
                   help="sensor pixels under a lenslet, per side (default 9)")
    r.add_argument("--point", type=distance("point distance"), action="append", metavar="D",
                   help="a point light on the axis D in front of the sensor (repeat for several)")
    r.add_argument("--plane", type=distance("plane distance"), default=None, metavar="D",
                   help="a checkerboard plane D in front of the sensor")
    r.add_argument("--plane-width", type=distance("plane width"), default=None, metavar="MM",
                   help="the checkerboard's width (default: what the sensor sees at that distance)")
    r.add_argument("--rays", type=_count("--rays", 1000, MAX_CLI_RAYS), default=300_000, metavar="N",
                   help="rays per point (default 300000)")
    r.add_argument("--spp", type=_count("--spp", 1, MAX_CLI_SPP), default=4, metavar="N",
                   help="rays per sensor pixel for the plane (default 4)")
    r.add_argument("--seed", type=_count("--seed", 0, 2**31 - 1), default=0, help="random seed (default 0)")
    r.add_argument("-o", "--output", metavar="FILE", type=figure_file, help="draw the figure to FILE (.png, .svg or .pdf)")
    r.add_argument("--force", action="store_true", help="overwrite an existing figure")
    add_output_options(r, what="the numbers")
    add_units_option(r)
    add_lenient(r)
    r.set_defaults(handler=run_render)
    p.set_defaults(handler=lambda args: (p.print_help(), 0)[1])


def _array_from(p, info, *, check=True):
    """The trace-layer MicrolensArray of a lens file's microlens block."""
    from ..errors import InputError
    from ..trace.microlens import microlens_array

    missing = [k for k in ("film_width_mm", "film_height_mm") if info[k] is None]
    if missing:
        raise InputError(f"lens {p.name!r}: the microlens block does not say the film size ({', '.join(missing)}); "
                         "write it with `physcam microlens insert`")
    return microlens_array(info["count_x"], info["count_y"], info["film_width_mm"], info["film_height_mm"],
                           focal_length_mm=info["thin_focal_length_mm"], lenslet=info["lenslet"],
                           sensor_offset_mm=info["sensor_offset_mm"], offsets_mm=info["offsets_mm"])


def _summary(cam) -> dict:
    """Numbers that say whether the array suits the main lens: the sub-image (the exit pupil seen
    through a lenslet) against the pitch (Ng 2005: equal f-numbers fill the sensor without overlap)."""
    from ..optics.paraxial import gaussian

    a = cam.array
    file_stop = cam.main.surfaces[cam.main.stop_index].semi_diameter
    g = gaussian(cam.main, film_z=cam.z_array)
    D = cam.z_array - g.z_exit_pupil
    xp = g.exit_pupil_diameter * cam.stop_semi_diameter / file_stop
    sub = xp * a.sensor_offset_mm / D
    return {"lens": cam.main.name, "lenslets": [a.count_x, a.count_y], "pitch_mm": [a.pitch_x, a.pitch_y],
            "lenslet": a.lenslet.name if a.lenslet is not None else f"thin, f = {a.focal_length_mm:g} mm",
            "sensor_offset_mm": a.sensor_offset_mm, "film_to_lens_mm": cam.film_to_lens_mm,
            "exit_pupil_to_array_mm": D, "exit_pupil_diameter_mm": xp,
            "subimage_diameter_mm": sub, "subimage_over_pitch": sub / min(a.pitch_x, a.pitch_y),
            "f_number_image_side": D / xp, "f_number_lenslet": a.sensor_offset_mm / min(a.pitch_x, a.pitch_y),
            "matched_fstop": g.f_number * file_stop / cam.stop_semi_diameter * sub / min(a.pitch_x, a.pitch_y)}


def run_insert(args) -> int:
    from ..errors import InputError
    from ..io import atomic_write, check_writable
    from ..lens.formats import iset
    from ..lens.library import load_lens
    from ..trace.microlens import main_lens_state, microlens_array, plenoptic_camera

    if (args.microlens is None) == (args.microlens_focal is None):
        raise InputError("give the lenslet: --microlens NAME_OR_FILE or --microlens-focal MM (one of them)")
    if args.focus is not None and args.film_to_lens is not None:
        raise InputError("give either --focus or --film-to-lens, not both")
    if not str(args.output):
        raise InputError("--output must name a file")
    check_writable(args.output, force=args.force)
    main = load_lens(args.lens, lenient=args.lenient)
    lenslet = load_lens(args.microlens, lenient=args.lenient) if args.microlens is not None else None
    array = microlens_array(args.xdim, args.ydim, args.film_width, args.film_height, focal_length_mm=args.microlens_focal,
                            lenslet=lenslet, sensor_offset_mm=args.sensor_offset)
    if args.focus is not None:
        from ..optics.sensors import custom_sensor
        from ._common import resolve_focus

        args.focus = resolve_focus(args.focus, lens=main, sensor=custom_sensor(args.film_width, args.film_height),
                                   args=args)
        cam = plenoptic_camera(main_lens_state(main, array, focus_mm=args.focus), array)
    else:
        cam = plenoptic_camera(main, array, film_to_lens_mm=50.0 if args.film_to_lens is None else args.film_to_lens)
    if cam.main.surfaces[:-1] != main.surfaces[:-1]:
        raise InputError(f"lens {main.name!r} focuses internally: give --film-to-lens for its infinity gaps instead "
                         "of --focus (ISET keeps one set of gaps)")
    out = iset.with_microlens(main, lenslet, count_x=args.xdim, count_y=args.ydim, film_width_mm=args.film_width,
                              film_height_mm=args.film_height,
                              film_to_lens_mm=cam.film_to_lens_mm if args.film_to_lens is None else args.film_to_lens,
                              sensor_offset_mm=array.sensor_offset_mm, thin_focal_length_mm=args.microlens_focal)
    text = iset.dumps(out)
    atomic_write(args.output, text, force=args.force)
    info = {"written": str(args.output), **_summary(cam)}
    if args.json:
        emit_json(document("microlens_insert", info))
        return 0
    print(f"wrote {args.output}: {out.name}")
    print(f"  {args.xdim} x {args.ydim} lenslets, pitch {array.pitch_x * 1000:.4g} x {array.pitch_y * 1000:.4g} µm, "
          f"sensor {array.sensor_offset_mm:.4g} mm behind the array, {cam.film_to_lens_mm:.4f} mm behind the lens")
    print(f"  sub-image (exit pupil through a lenslet) {info['subimage_diameter_mm'] * 1000:.4g} µm = "
          f"{info['subimage_over_pitch']:.3f} x the pitch at the file's stop; f/{info['matched_fstop']:.3g} "
          "makes it one pitch (Ng 2005: the sub-images then tile the sensor)")
    return 0


def run_render(args) -> int:
    import math

    from ..analysis.defocus.lightfield import (checkerboard, light_field_figure, render_plane, render_point, view_disparity)
    from ..errors import InputError
    from ..io import check_writable
    from ..lens.formats.iset import microlens_of
    from ..lens.library import load_lens
    from ..trace.microlens import main_lens_state, plenoptic_camera

    if not args.point and args.plane is None:
        raise InputError("nothing to render: give --point D (one or more) or --plane D")
    if args.point and args.plane is not None:
        raise InputError("render points or a plane, not both at once")
    if args.plane_width is not None and args.plane is None:
        raise InputError("--plane-width belongs to --plane")
    if args.force and not args.output:
        raise InputError("--force overwrites the figure (--output); without it there is nothing to overwrite")
    if args.output:
        check_writable(args.output, force=args.force)
    p = load_lens(args.lens, lenient=args.lenient)
    info = microlens_of(p)
    if info is None:
        raise InputError(f"lens {p.name!r} has no microlens array; add one with `physcam microlens insert`")
    array = _array_from(p, info)
    n = args.pixels_per_lenslet
    if array.count_x * array.count_y * n * n > MAX_CLI_PIXELS:
        raise InputError(f"{array.count_x * n} x {array.count_y * n} sensor pixels is more than {MAX_CLI_PIXELS}; "
                         "lower --pixels-per-lenslet")
    if args.focus is not None:
        from ..optics.sensors import custom_sensor
        from ._common import resolve_focus

        args.focus = resolve_focus(args.focus, lens=p, fstop=args.fstop, args=args,
                                   sensor=custom_sensor(array.film_width_mm, array.film_height_mm))
        state = main_lens_state(p, array, focus_mm=args.focus, fstop=args.fstop)  # the one camera state
        cam = plenoptic_camera(state, array, pixels_per_lenslet=n)
    else:
        if info["film_to_lens_mm"] is None:
            raise InputError(f"lens {p.name!r} does not say its film-to-lens distance; give --focus")
        cam = plenoptic_camera(p, array, film_to_lens_mm=info["film_to_lens_mm"], fstop=args.fstop,
                               pixels_per_lenslet=n)
    from ..units import format_distance
    from ._common import units_of

    units = units_of(args)
    slopes = []
    if args.point:
        field = None
        for d in args.point:
            lf = render_point(cam, d, rays=args.rays, seed=args.seed)
            if field is None:
                field = lf
            else:
                field.raw += lf.raw
                field.rays_traced += lf.rays_traced
                field.rays_used += lf.rays_used
            slopes.append((f"refocused at {format_distance(d, units)}", view_disparity(cam, d)))
        if len(args.point) > 1:
            field.subject = "points at " + ", ".join(format_distance(d, units) for d in args.point) + " from the sensor"
    else:
        width = args.plane_width
        if width is None:  # what the sensor sees at that distance, through the main lens's EFL
            from ..optics.paraxial import gaussian

            g = gaussian(cam.main)
            width = 1.2 * array.film_width_mm * max(args.plane - cam.z_sensor + g.z_front_principal_plane, g.efl) / g.efl
        field = render_plane(cam, checkerboard(8, 16), args.plane, width, spp=args.spp, seed=args.seed)
        slopes.append((f"refocused at {format_distance(args.plane, units)}", view_disparity(cam, args.plane)))
    data = {**_summary(cam), **field.to_dict(),
            "refocus": [{"label": lab, "slope_lenslets_per_view": s} for lab, s in slopes]}
    if not math.isfinite(data["total"]):
        raise InputError("the render came out non-finite; check the lens and distances")
    if args.output:
        light_field_figure(field, refocus_slopes=slopes, path=args.output, force=args.force)
    if args.json:
        emit_json(document("microlens_render", data))
        return 0
    used = "on the sensor" if args.point else "met the plane"
    print(f"{field.subject}: {data['rays_traced']} rays traced, {data['rays_used']} {used} "
          f"({data['resolution'][0]} x {data['resolution'][1]} px, {n} per lenslet)")
    for lab, s in slopes:
        print(f"  {lab}: views shift {s:+.4f} lenslets per view step (closed form)")
    if args.output:
        print(f"  wrote {args.output}")
    return 0

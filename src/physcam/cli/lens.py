"""``physcam lenses`` and ``physcam lens show|diagram|breathing``: real lenses from the command line.

Examples::

  physcam lenses
  physcam lens show dgauss.50mm --focus 2m --fstop 2.8 --flange 52
  physcam lens show my_lens.zmx --json
  physcam lens diagram navarro_anamorphic_2x --axis x -o navarro_x.svg
  physcam lens breathing canon_rf_85mm_f1_2 --sensor "Super 35" -o breathing.png

Distances in the output are millimetres. ``show`` gives every cardinal point from
the front vertex and rear vertex (signed, + toward the film) and from the film
plane and flange (distance in front, + toward the subject); see docs/conventions.md.
"""

from __future__ import annotations

from ._common import distance, number


def register(sub) -> None:
    p = sub.add_parser("lenses", help="list the bundled lens library (focal length, f-number, format)")
    p.add_argument("--json", action="store_true", help="print as JSON")
    p.set_defaults(handler=run_lenses)

    lens = sub.add_parser("lens", help="Gaussian data, diagram and focus breathing of one lens (bundled name or file)")
    lsub = lens.add_subparsers(dest="lens_command", metavar="ACTION")
    lens.set_defaults(handler=lambda args: (lens.print_help(), 0)[1])

    def common(q, fstop=True, focus=True):
        q.add_argument("lens", metavar="NAME_OR_FILE", help="bundled lens name (see `physcam lenses`) or a lens file")
        if focus:
            q.add_argument("--focus", type=distance("focus distance", allow_inf=True), default=float("inf"),
                           help="focus mark from the film plane, e.g. 2m, 6ft, inf (default inf)")
        if fstop:
            q.add_argument("--fstop", type=number("f-number"), default=None,
                           help="evaluate the pupils at this f-number (default: the stop in the file)")
        q.add_argument("--wavelength", type=number("wavelength"), default=None, metavar="NM",
                       help="wavelength in nm (default: the lens's design wavelength, d line 587.56)")
        q.add_argument("--focus-method", choices=("auto", "unit", "internal"), default="auto",
                       help="unit (whole lens moves) or internal (focus groups); auto: internal when the lens has groups")

    s = lsub.add_parser("show", help="print the Gaussian (paraxial) data of a lens")
    common(s)
    s.add_argument("--flange", type=distance("flange focal distance"), default=None, metavar="FFD",
                   help="flange focal distance (e.g. 52mm for PL) to give positions from the flange too")
    s.add_argument("--json", action="store_true", help="print as JSON")
    s.set_defaults(handler=run_show)

    d = lsub.add_parser("diagram", help="draw elements, stop, rays and cardinal points to PNG/SVG/PDF")
    common(d)
    d.add_argument("-o", "--output", required=True, metavar="FILE", help="output file (.png, .svg or .pdf)")
    d.add_argument("--axis", choices=("x", "y"), default="y", help="meridian to draw (x shows anamorphic cylinders)")
    d.add_argument("--field", type=number("field angle"), default=None, metavar="DEG",
                   help="half field angle of the off-axis rays in degrees (default: widest unvignetted)")
    d.add_argument("--force", action="store_true", help="overwrite an existing file")
    d.set_defaults(handler=run_diagram)

    b = lsub.add_parser("breathing", help="focal length and field of view against focus (table, optional plot)")
    common(b, fstop=False, focus=False)
    b.add_argument("--at", "--focus", dest="at", type=distance("focus distance", allow_inf=True), nargs="+",
                   default=None, metavar="D",
                   help="focus marks from the film plane, one or more (default: infinity down to the closest focus)")
    g = b.add_mutually_exclusive_group()
    g.add_argument("--sensor", default=None, help="sensor name for the horizontal width (see `physcam sensors`)")
    g.add_argument("--sensor-width", type=distance("sensor width"), default=None, metavar="W",
                   help="sensor width (default 36mm)")
    b.add_argument("-o", "--output", default=None, metavar="FILE", help="also plot to this file (.png, .svg, .pdf)")
    b.add_argument("--force", action="store_true", help="overwrite an existing plot")
    b.add_argument("--json", action="store_true", help="print as JSON")
    b.set_defaults(handler=run_breathing)


def _fmt(v, nd=3):
    import math

    if v is None:
        return "-"
    if isinstance(v, float) and math.isinf(v):
        return "∞"
    return f"{v:.{nd}f}"


def _json_float(v):
    import math

    return None if (v is None or (isinstance(v, float) and not math.isfinite(v))) else v


def run_lenses(args) -> int:
    from ..errors import PhysCamError
    from ..lens.library import list_lenses, load_lens
    from ..optics.paraxial import gaussian
    from ._common import console, print_json

    out = []
    for rec in list_lenses():
        d = rec.to_dict()
        try:
            g = gaussian(load_lens(rec.slug))
            d["efl_mm"], d["f_number"] = g.efl, g.f_number
        except PhysCamError:  # a listing must not stop at one odd lens
            d["efl_mm"], d["f_number"] = None, None
        out.append(d)
    if args.json:
        print_json(out)
        return 0
    from rich.table import Table

    t = Table(title="bundled lenses (paraxial EFL and f-number at the d line, stop as in the file)")
    t.add_column("name (for physcam lens)", no_wrap=True)
    for col in ("EFL mm", "f/"):
        t.add_column(col, justify="right", no_wrap=True)
    t.add_column("format", no_wrap=True)
    t.add_column("lens and notes", overflow="fold")
    for d in out:
        notes = []
        if d["anamorphic"]:
            notes.append(f"anamorphic {d['squeeze']:g}x")
        if d["has_focus_groups"]:
            notes.append("internal focus")
        if d["corrected"]:
            notes.append("corrected")
        t.add_row(d["slug"], _fmt(d["efl_mm"], 2), _fmt(d["f_number"], 2), d["original_format"] or "-",
                  "; ".join([d["name"], *notes]))
    console().print(t)
    return 0


def _load(name):
    from ..lens.library import load_lens

    return load_lens(name)


def _meridians(p):
    return ("x", "y") if p.is_anamorphic else ("y",)


def run_show(args) -> int:
    from ..optics import focusing, paraxial
    from ._common import console, print_json

    p = _load(args.lens)
    st = focusing.focus(p, args.focus, method=args.focus_method, wavelength_nm=args.wavelength)
    data = {
        a: paraxial.gaussian(st.prescription, axis=a, wavelength_nm=args.wavelength, fstop=args.fstop,
                             object_z=st.object_z, film_z=st.film_z, flange_focal_distance_mm=args.flange)
        for a in _meridians(p)
    }
    focus_info = {
        "focus_from_film_mm": _json_float(st.focus_from_film_mm),
        "method": st.method,
        "object_distance_from_front_vertex_mm": _json_float(st.object_distance_mm),
        "back_focus_mm": st.back_focus_mm,
        "back_focus_infinity_mm": st.back_focus_infinity_mm,
        "extension_mm": st.extension_mm,
        "focus_group_travel_fraction": st.alpha,
        "focused_meridian": st.axis,
    }
    if args.json:
        print_json({"lens": p.name, "squeeze": p.squeeze, "focus": focus_info,
                    "meridians": {a: g.to_dict() for a, g in data.items()}})
        return 0
    from rich.table import Table

    con = console()
    g0 = data["y"]
    con.print(f"{p.name}  (wavelength {g0.wavelength_nm:g} nm, focus {_fmt(st.focus_from_film_mm, 0)} mm from the film, "
              f"{st.method} focusing, back focus {st.back_focus_mm:.3f} mm)")
    t = Table(title="first-order data (mm)")
    t.add_column("quantity")
    for a in data:
        t.add_column(f"{a.upper()} meridian", justify="right")
    rows = [
        ("effective focal length", "efl"), ("front focal length (F to first vertex)", "ffl"),
        ("back focal length (last vertex to F')", "bfl"), ("f-number (infinity)", "f_number"),
        ("working f-number", "working_f_number"), ("magnification", "magnification"),
        ("entrance pupil diameter", "entrance_pupil_diameter"), ("exit pupil diameter", "exit_pupil_diameter"),
        ("pupil magnification", "pupil_magnification"),
    ]
    for label, attr in rows:
        t.add_row(label, *[_fmt(getattr(g, attr), 4) for g in data.values()])
    con.print(t)
    refs = [("front_vertex", "from front vertex (+ toward film)"), ("rear_vertex", "from rear vertex (+ toward film)"),
            ("film", "in front of film (+ toward subject)")]
    if args.flange is not None:
        refs.append(("flange", "in front of flange (+ toward subject)"))
    for a, g in data.items():
        t = Table(title=f"positions, {a.upper()} meridian (mm)")
        t.add_column("point")
        for _, label in refs:
            t.add_column(label, justify="right")
        pos = {ref: g.positions(ref) for ref, _ in refs}
        for point in paraxial.CARDINAL_POINTS:
            t.add_row(point.replace("_", " "), *[_fmt(pos[ref][point]) for ref, _ in refs])
        con.print(t)
    return 0


def run_diagram(args) -> int:
    from ..analysis.diagram import save_lens_diagram

    p = _load(args.lens)
    path = save_lens_diagram(p, args.output, force=args.force, axis=args.axis, focus_from_film_mm=args.focus,
                             fstop=args.fstop, field_deg=args.field, wavelength_nm=args.wavelength)
    print(f"wrote {path}")
    return 0


def run_breathing(args) -> int:
    from ..optics import focusing
    from ._common import console, print_json

    p = _load(args.lens)
    width, sensor_name = 36.0, "36 mm wide"
    if args.sensor:
        from ..onset.sensors import find_sensor

        s = find_sensor(args.sensor)
        width, sensor_name = s.width_mm, s.name
    elif args.sensor_width is not None:
        width, sensor_name = args.sensor_width, f"{args.sensor_width:g} mm wide"
    rows = focusing.breathing_table(p, args.at, sensor_width_mm=width, method=args.focus_method,
                                    wavelength_nm=args.wavelength)
    path = None
    if args.output:
        from ..analysis.breathing_plot import save_breathing_plot

        path = save_breathing_plot(rows, args.output, force=args.force, title=f"{p.name}: focus breathing",
                                   sensor_width_mm=width)
    if args.json:
        print_json({"lens": p.name, "sensor_width_mm": width, "rows": [r.to_dict() for r in rows],
                    "plot": None if path is None else str(path)})
        return 0
    from rich.table import Table

    t = Table(title=f"{p.name}: focus breathing, {sensor_name} sensor (horizontal field, X meridian)")
    for col in ("focus from film (mm)", "EFL (mm)", "HFOV (deg)", "framing focal length (mm)", "magnification",
                "back focus (mm)", "entrance pupil from film (mm)", "FOV change (%)"):
        t.add_column(col, justify="right")
    for r in rows:
        t.add_row(_fmt(r.focus_from_film_mm, 0), _fmt(r.efl_mm, 3), _fmt(r.hfov_deg, 3),
                  _fmt(r.breathing_focal_length_mm, 3), _fmt(r.magnification, 4), _fmt(r.back_focus_mm, 3),
                  _fmt(r.entrance_pupil_from_film_mm, 2), _fmt(r.fov_change_pct, 2))
    con = console()
    con.print(t)
    if path is not None:
        con.print(f"wrote {path}")
    return 0

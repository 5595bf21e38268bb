"""``physcam lenses`` and ``physcam lens show|diagram|breathing``: real lenses from the command line.

Examples::

  physcam lenses
  physcam lens show --lens dgauss_50mm --focus 2m --fstop 2.8 --flange 52
  physcam lens show --lens my_lens.zmx --json
  physcam lens diagram --lens navarro_anamorphic_2x --axis x -o navarro_x.svg
  physcam lens breathing --lens canon_rf_85mm_f1_2 --sensor "Super 35" -o breathing.png --units ft
  physcam lens check --lens my_lens.toml --sensor "Super 35"
  physcam lens fix --lens my_lens.toml -o my_lens_fixed.toml --apply
  physcam lens pack --lens my_lens.toml --focus 2m -o my_lens.lens.zip
  physcam lens add my_lens.lens.zip
  physcam lens zoom --lens nikon_af_s_70_200mm_f2_8e_zoom -o zoom.png

Distances in the output are millimetres. ``show`` gives every cardinal point from
the front vertex and rear vertex (signed, + toward the film) and from the film
plane and flange (distance in front, + toward the subject); see docs/conventions.md.
"""

from __future__ import annotations

from ..errors import PhysCamError
from ._common import (add_lenient, add_lens_argument, FOCUS_HELP, add_sensor_options, add_units_option, distance, focus,
                      hidden_alias, mark_repaired, number, whole, figure_file)
from ._output import add_output_options
from ._zoom import add_zoom_option, at_zoom_named, register_zoom, zoom_info, zoomed


def register(sub) -> None:
    p = sub.add_parser("lenses", help="list the lens library, bundled and yours (focal length, f-number, source, "
                                      "licence)")
    p.add_argument("--library", choices=("all", "bundled", "user"), default="all",
                   help="which lenses: all (default), the bundled ones, or yours (installed with `physcam lens add`)")
    add_output_options(p, csv=True, what="the library")
    p.set_defaults(handler=run_lenses)

    lens = sub.add_parser("lens", help="Gaussian data, diagram and focus breathing of one lens (bundled name or file)")
    lsub = lens.add_subparsers(dest="lens_command", metavar="ACTION")
    lens.set_defaults(handler=lambda args: (lens.print_help(), 0)[1])

    def common(q, fstop=True, with_focus=True):
        add_lens_argument(q)
        if with_focus:
            q.add_argument("--focus", type=focus("focus distance"), default=float("inf"),
                           help=f"focus mark from the film plane (default infinity; {FOCUS_HELP})")
        if fstop:
            q.add_argument("--fstop", type=number("f-number"), default=None,
                           help="evaluate the pupils at this f-number (default: the stop in the file)")
        q.add_argument("--wavelength", type=number("wavelength"), default=None, metavar="NM",
                       help="wavelength in nm (default: the lens's design wavelength, d line 587.56)")
        q.add_argument("--focus-method", choices=("auto", "unit", "internal"), default="auto",
                       help="unit (whole lens moves) or internal (focus groups); auto: internal when the lens has groups")
        add_lenient(q)
        add_zoom_option(q)

    s = lsub.add_parser("show", help="print the Gaussian (paraxial) data of a lens")
    common(s)
    s.add_argument("--flange", type=distance("flange focal distance"), default=None, metavar="FFD",
                   help="flange focal distance (e.g. 52mm for PL) to give positions from the flange too")
    add_units_option(s)
    add_output_options(s, csv=True, what="the Gaussian data")
    s.set_defaults(handler=run_show)

    d = lsub.add_parser("diagram", help="draw elements, stop, rays and cardinal points to PNG/SVG/PDF")
    common(d)
    d.add_argument("-o", "--output", required=True, metavar="FILE", type=figure_file, help="output file (.png, .svg or .pdf)")
    d.add_argument("--axis", choices=("x", "y"), default="y", help="meridian to draw (x shows anamorphic cylinders)")
    d.add_argument("--field", type=number("field angle"), default=None, metavar="DEG",
                   help="half field angle of the off-axis rays in degrees (default: widest unvignetted)")
    d.add_argument("--force", action="store_true", help="overwrite an existing file")
    add_units_option(d)
    d.set_defaults(handler=run_diagram)

    b = lsub.add_parser("breathing", help="focal length and field of view against focus (table, optional plot)")
    common(b, fstop=False, with_focus=False)
    b.add_argument("--focus", dest="at", type=focus("focus distance"), nargs="+", default=None, metavar="D",
                   help=f"focus marks from the film plane, one or more (default: infinity down to the closest focus; "
                        f"{FOCUS_HELP}; hyperfocal wide open)")
    hidden_alias(b, "--at", "at", type=focus("focus distance"), nargs="+")
    add_sensor_options(b)
    b.add_argument("-o", "--output", default=None, metavar="FILE", type=figure_file, help="also plot to this file (.png, .svg, .pdf)")
    b.add_argument("--force", action="store_true", help="overwrite an existing plot")
    add_units_option(b)
    add_output_options(b, csv=True, what="the breathing table")
    b.set_defaults(handler=run_breathing)

    k = lsub.add_parser("card", help="one page per lens (A4 or Letter): section, MTF, distortion, illumination, "
                                     "breathing, bokeh, key numbers",
                        description="The lens card: one printed page (A4 or US Letter, portrait) with the lens section "
                                    "and rays, the MTF chart at 10/20/40 lp/mm (sagittal and tangential) wide open and "
                                    "stopped down, distortion and relative illumination against image height, focus "
                                    "breathing, bokeh at the centre, middle and corner of the sensor wide open, and the "
                                    "key numbers (docs/lens-card.md).")
    add_lens_argument(k)
    k.add_argument("--focus", type=focus("focus distance"), default=float("inf"),
                   help=f"focus mark from the film plane for the section, MTF, distortion, illumination and bokeh "
                        f"(default infinity; {FOCUS_HELP})")
    k.add_argument("--stopped", type=number("f-number", positive=True), default=8.0, metavar="FSTOP",
                   help="the stopped-down MTF chart's f-number (default 8)")
    add_sensor_options(k)
    k.add_argument("--page", choices=("a4", "letter"), default="a4", help="page size, portrait (default a4)")
    k.add_argument("--draft", action="store_true", help="fewer fields and rays: a quick look (seconds)")
    k.add_argument("--dpi", type=whole("dpi", lo=30, hi=600), default=150, help="resolution of a PNG (default 150)")
    k.add_argument("-o", "--output", required=True, metavar="FILE", type=figure_file, help="output file (.pdf, .png or .svg)")
    k.add_argument("--force", action="store_true", help="overwrite an existing file")
    add_units_option(k)
    add_lenient(k)
    add_zoom_option(k)
    add_output_options(k, what="the card's numbers")
    k.set_defaults(handler=run_card)

    c = lsub.add_parser("check", help="report what is inconsistent in a lens file or lens archive (surface, file line, "
                                      "numbers)")
    add_lens_argument(c, help="bundled lens name, a lens file (read without validation) or a lens archive "
                              "(NAME.lens.zip: also its members, checksums, provenance and USD file)")
    c.add_argument("--sensor", default=None,
                   help="also trace the on-axis beam, vignetting and image circle at this sensor's corner "
                        "(see `physcam sensors`)")
    c.add_argument("--strict", action="store_true",
                   help="exit 1 on warnings too (default: exit 1 only when the lens has an error)")
    add_output_options(c, what="the findings")
    c.set_defaults(handler=run_check)

    f = lsub.add_parser("fix", help="propose (and with --apply write) the repairs of a lens file, with a diff")
    add_lens_argument(f, metavar="FILE", help="lens file to repair (any supported format)")
    f.add_argument("-o", "--output", required=True, metavar="FIXED",
                   help="where to write the repaired lens (.toml: physcam's format; .dat, .json, .zmx also work)")
    f.add_argument("--apply", action="store_true", help="write the repaired file (without it: only show the repairs)")
    f.add_argument("--force", action="store_true", help="overwrite an existing output file")
    add_output_options(f, what="the repairs")
    f.set_defaults(handler=run_fix)

    _register_archives(lsub)
    register_zoom(lsub, add_lens_argument, add_sensor_options, add_output_options, number)


def _register_archives(lsub) -> None:
    """``lens pack`` and ``lens add``: lens archives (docs/lens-library.md)."""
    k = lsub.add_parser("pack", help="publish a lens as one archive: prescription, USD lens file, lens card, provenance",
                        description="Write a lens archive (docs/lens-library.md): the prescription with its provenance "
                                    "(lens.toml), a USD vendor lens file with the detailed model, its best-match pinhole "
                                    "and characterization variants (lens.usda), the lens card (card.pdf) and the "
                                    "provenance record (provenance.json), listed with checksums in manifest.json.")
    add_lens_argument(k)
    k.add_argument("-o", "--output", required=True, metavar="ARCHIVE", help="the archive to write (NAME.lens.zip)")
    k.add_argument("--slug", default=None, help="the lens's name in a library (default: made from the lens name)")
    k.add_argument("--focus", type=focus("focus distance"), default=float("inf"),
                   help=f"focus mark from the film plane of the USD pinhole and the card (default infinity; {FOCUS_HELP})")
    k.add_argument("--fstop", type=number("f-stop", positive=True), default=None,
                   help="f-stop of the USD pinhole (default: wide open)")
    add_sensor_options(k)
    k.add_argument("--characterizations", metavar="CSV", default=None,
                   help="measuring runs as USD characterization variants: a CSV with a `variant` (or `date`) column and "
                        "one column per measured value (numbers or text)")
    k.add_argument("--source", default=None, help="the primary source, when the lens file's [provenance] gives none")
    k.add_argument("--licence", default=None, metavar="SPDX",
                   help="the file's licence (an SPDX identifier such as CC-BY-4.0), when the lens file gives none")
    k.add_argument("--draft", action="store_true", help="a quick lens card (fewer fields and rays)")
    k.add_argument("--force", action="store_true", help="overwrite an existing archive")
    add_units_option(k)
    add_lenient(k)
    add_output_options(k, what="what was written")
    k.set_defaults(handler=run_pack)

    a = lsub.add_parser("add", help="install a lens archive into your lens library (after `physcam lens check` "
                                    "finds no error)",
                        description="Check a lens archive as `physcam lens check` does and, when it has no error, "
                                    "install it into your lens library: $PHYSCAM_LENS_LIBRARY, else "
                                    "$XDG_DATA_HOME/physcam/lenses, else ~/.local/share/physcam/lenses, one folder per "
                                    "lens. Its name then works wherever a lens is asked for.")
    a.add_argument("archive", metavar="ARCHIVE", help="the lens archive (NAME.lens.zip, from `physcam lens pack`)")
    a.add_argument("--force", action="store_true", help="replace an installed lens of the same name")
    add_output_options(a, what="what was installed")
    a.set_defaults(handler=run_add)


#: Units of documents that carry wavelengths too.
WAVE_UNITS = {"length": "mm", "angle": "degree", "wavelength": "nm"}


def load_lens_arg(name, lenient: bool = False):
    """The lens a command was given, loaded strictly or (``lenient``) repaired on load."""
    from ..lens.library import load_lens

    return load_lens(name, lenient=lenient)


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


def lenses_document(library: str = "all") -> list[dict]:
    """The library's lenses as ``physcam lenses --json`` prints them (and ``physcam serve`` answers)."""
    from ..errors import PhysCamError
    from ..lens.library import list_lenses, load_lens
    from ..optics.paraxial import gaussian

    out = []
    for rec in list_lenses(library):
        d = rec.to_dict()
        try:
            g = gaussian(load_lens(rec.slug))
            d["efl_mm"], d["f_number"] = g.efl, g.f_number
        except PhysCamError:  # a listing must not stop at one odd lens
            d["efl_mm"], d["f_number"] = None, None
        out.append(d)
    return out


def _lens_notes(d: dict) -> list[str]:
    notes = []
    if d["anamorphic"]:
        notes.append(f"anamorphic {d['squeeze']:g}x")
    if d["has_focus_groups"]:
        notes.append("internal focus")
    if d["t_stop"] is not None:
        notes.append(f"T{d['t_stop']:g}")
    if d["corrected"]:
        notes.append("corrected")
    if d["primary_source_checked"] is False:
        notes.append("not checked against its source")
    if d["library"] == "user":
        notes.append("your library")
    return notes


def run_lenses(args) -> int:
    from ._output import Table, document, emit_json, print_csv, print_table

    out = lenses_document(getattr(args, "library", "all"))
    if args.json:
        emit_json(document("lenses", {"lenses": out}))
        return 0
    if args.csv:
        print_csv(out)
        return 0
    t = Table("lens library (paraxial EFL and f-number at the d line, stop as in the file)",
              ("name (for physcam lens)", "EFL mm", "f/", "lens and notes", "source", "licence"),
              justify=("left", "right", "right", "left", "left", "left"))
    for d in out:
        t.add_row(d["slug"], _fmt(d["efl_mm"], 2), _fmt(d["f_number"], 2), "; ".join([d["name"], *_lens_notes(d)]),
                  d["source"] or "-", d["licence"] or "-")
    print_table(t)
    return 0


def _load(args):
    return zoomed(load_lens_arg(args.lens, getattr(args, "lenient", False)), args)


def _meridians(p):
    return ("x", "y") if p.is_anamorphic else ("y",)


def show_data(args):
    """What ``physcam lens show`` computes: (lens, focus state, {meridian: GaussianData}, focus block)."""
    from ..optics import focusing, paraxial
    from ..optics.state import camera_state
    from ._common import resolve_focus

    p = _load(args)
    args.focus = resolve_focus(args.focus, lens=p, fstop=args.fstop, args=args)
    st = focusing.focus(p, args.focus, method=args.focus_method, wavelength_nm=args.wavelength)
    iris = None if args.fstop is None else camera_state(p, fstop=args.fstop).stop_semi_diameter  # the one iris rule
    data = {
        a: paraxial.gaussian(st.prescription, axis=a, wavelength_nm=args.wavelength, stop_semi_diameter=iris,
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
    return p, st, data, focus_info


def show_document(args) -> dict:
    """The document ``physcam lens show --json`` prints (and ``physcam serve`` answers)."""
    p, _, data, focus_info = show_data(args)
    doc = _show_document(p, data, focus_info)
    if zoom_info(args, p) is not None:
        doc["zoom"] = zoom_info(args, p)
    return doc


def _show_document(p, data, focus_info) -> dict:
    from ._output import document

    from ..lens.provenance import provenance_of

    return document("lens_show", mark_repaired({"lens": p.name, "squeeze": p.squeeze, "focus": focus_info,
                                                "provenance": provenance_of(p).to_dict(),
                                                "meridians": {a: g.to_dict() for a, g in data.items()},
                                                "points": show_points(data)}, p),
                    units=WAVE_UNITS)


#: The columns of ``physcam lens show --csv``: (key, reference plane of GaussianData.positions).
POINT_COLUMNS = (("from_front_vertex_mm", "front_vertex"), ("from_rear_vertex_mm", "rear_vertex"),
                 ("in_front_of_film_mm", "film"), ("in_front_of_flange_mm", "flange"))


def show_points(data) -> list[dict]:
    """The positions table of ``lens show`` as flat rows (``--csv``; ``points`` in its JSON): one per meridian
    and cardinal point, its distance from each reference plane (from the front vertex it is lens-space z;
    vertices: + toward the film; film and flange: in front, + toward the subject; ``None`` at infinity or
    without --flange)."""
    from ..optics import paraxial

    out = []
    for a, g in data.items():
        pos = {ref: g.positions(ref) for _, ref in POINT_COLUMNS if ref != "flange" or g.flange_focal_distance is not None}
        for point in paraxial.CARDINAL_POINTS:
            row = {"meridian": a, "point": point}
            for key, ref in POINT_COLUMNS:
                row[key] = pos[ref][point] if ref in pos else None
            out.append(row)
    return out


def run_show(args) -> int:
    from ..optics import paraxial
    from ..units import format_distance
    from ._common import units_of
    from ._output import Table, emit_json, print_table

    p, st, data, focus_info = show_data(args)
    if args.json:
        doc = _show_document(p, data, focus_info)
        if zoom_info(args, p) is not None:
            doc["zoom"] = zoom_info(args, p)
        emit_json(doc)
        return 0
    if args.csv:
        from ._output import print_csv

        print_csv(show_points(data), units=units_of(args))
        return 0
    g0 = data["y"]
    print(f"{p.name}  (wavelength {g0.wavelength_nm:g} nm, focus {format_distance(st.focus_from_film_mm, units_of(args))} "
          f"from the film, {st.method} focusing, back focus {st.back_focus_mm:.3f} mm)")
    _print_provenance(p)
    t = Table("first-order data (mm; magnification < 0: an inverted image)", ["quantity"])
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
    print_table(t)
    refs = [("front_vertex", "from front vertex (+ toward film)"), ("rear_vertex", "from rear vertex (+ toward film)"),
            ("film", "in front of film (+ toward subject)")]
    if args.flange is not None:
        refs.append(("flange", "in front of flange (+ toward subject)"))
    for a, g in data.items():
        t = Table(f"positions, {a.upper()} meridian (mm)", ["point"])
        for _, label in refs:
            t.add_column(label, justify="right")
        pos = {ref: g.positions(ref) for ref, _ in refs}
        for point in paraxial.CARDINAL_POINTS:
            t.add_row(point.replace("_", " "), *[_fmt(pos[ref][point]) for ref, _ in refs])
        print_table(t)
    return 0


def _print_provenance(p) -> None:
    """The lines ``lens show`` prints above its tables: where the lens's numbers come from, its licence."""
    from ..lens.provenance import provenance_of

    prov = provenance_of(p)
    if prov.source is None and prov.licence is None:
        return
    checked = {True: "; every number checked against it", False: "; numbers not checked against it"}
    print(f"source: {prov.source or 'not given'}{checked.get(prov.primary_source_checked, '')}")
    print(f"licence: {prov.licence or 'not given'}")


def diagram_options(args) -> dict:
    """The keyword arguments ``physcam lens diagram`` gives :func:`physcam.analysis.lens_cards.diagram.lens_diagram`
    (``--focus hyperfocal`` resolved to its mark for the lens and f-stop)."""
    from ._common import HYPERFOCAL, resolve_focus

    if args.focus == HYPERFOCAL:
        args.focus = resolve_focus(args.focus, lens=_load(args), fstop=args.fstop, args=args)
    return dict(axis=args.axis, focus_mm=args.focus, fstop=args.fstop, field_deg=args.field,
                wavelength_nm=args.wavelength)


def run_diagram(args) -> int:
    from ..analysis.lens_cards.diagram import save_lens_diagram
    from ..optics.state import camera_state
    from ._common import units_of

    p = _load(args)
    opts = diagram_options(args)
    cam = camera_state(p, focus_mm=opts.pop("focus_mm"), fstop=opts.pop("fstop"))  # the one camera state
    path = save_lens_diagram(cam, args.output, force=args.force, units=units_of(args), **opts)
    print(f"wrote {path}")
    return 0


def run_card(args) -> int:
    """``physcam lens card``: the one-page lens card (:mod:`physcam.analysis.lens_cards.card`)."""
    from ..analysis.lens_cards.card import card_files, card_pages, lens_card, save_lens_card
    from ..io import check_writable
    from ._common import resolve_focus, resolve_sensor, units_of
    from ._output import document, emit_json

    check_writable(args.output, force=args.force)  # before the seconds of work
    lens = load_lens_arg(args.lens, args.lenient)
    for f in card_files(card_pages(lens), args.output):  # a PNG's or SVG's further pages beside it: none written over
        check_writable(f, force=args.force)
    p = at_zoom_named(lens, args)  # the zoom lens at --zoom (a prime given --zoom is refused here)
    sensor = resolve_sensor(args)
    (mark,) = resolve_focus([args.focus], lens=p, sensor=sensor, args=args)
    # a zoom lens's card: page 1 at --zoom (named so in its title), its zoom page the whole range
    card = lens_card(lens, focus_mm=mark, sensor_width_mm=sensor.width_mm, sensor_height_mm=sensor.height_mm,
                     sensor_name=sensor.name, stopped_fstop=args.stopped, page=args.page,
                     quality="draft" if args.draft else "full",
                     zoom=None if args.zoom_block is None else args.zoom_block["encoder"])
    path = save_lens_card(card, args.output, force=args.force, units=units_of(args), dpi=args.dpi)
    files = [str(f) for f in card_files(card, path)]
    if args.json:
        emit_json(document("lens_card", {**card.to_dict(), "output": str(path), "files": files,
                                         "zoom": args.zoom_block}))
        return 0
    for f in files:
        print(f"wrote {f}")
    return 0


def run_breathing(args) -> int:
    from ..optics import focusing
    from ..units import format_distance
    from ._common import resolve_focus, resolve_sensor, units_of
    from ._output import Table, document, emit_json, print_csv, print_table

    p = _load(args)
    if args.sensor_width is not None and args.sensor_height is None and args.sensor is None:
        if not args.sensor_width >= 0.1:  # the table needs only the width (scripts give it alone)
            from ..errors import InputError

            raise InputError(f"sensor width must be at least 0.1 mm, got {args.sensor_width:g} mm")
        width, sensor_name, sensor = args.sensor_width, f"{args.sensor_width:g} mm wide", None
    else:
        sensor = resolve_sensor(args)
        width, sensor_name = sensor.width_mm, sensor.name
    marks = resolve_focus(args.at, lens=p, sensor=sensor, args=args) if args.at is not None else None
    rows = focusing.breathing_table(p, marks, sensor_width_mm=width, method=args.focus_method,
                                    wavelength_nm=args.wavelength)
    units = units_of(args)
    path = None
    if args.output:
        from ..analysis.framing.breathing_plot import save_breathing_plot

        path = save_breathing_plot(rows, args.output, force=args.force,
                                   title=f"{p.name}: focus breathing, {sensor_name} ({width:g} mm wide)",
                                   sensor_width_mm=width, units=units)
    if args.json:
        emit_json(document("lens_breathing", mark_repaired(
            {"lens": p.name, "sensor": sensor_name, "sensor_width_mm": width, "rows": [r.to_dict() for r in rows],
             "plot": None if path is None else str(path), "zoom": zoom_info(args, p)}, p)))
        return 0
    if args.csv:
        print_csv([r.to_dict() for r in rows], units=units)
        return 0
    if p.is_anamorphic:
        _print_breathing_per_axis(p, rows, sensor_name, units)
        return 0
    t = Table(f"{p.name}: focus breathing, {sensor_name} sensor (horizontal field, X meridian)",
              ("focus from film", "EFL (mm)", "HFOV (deg)", "framing focal length (mm)", "magnification",
               "back focus (mm)", "entrance pupil from film (mm)", "FOV change (%)"), justify=["right"] * 8)
    for r in rows:
        t.add_row(format_distance(r.focus_from_film_mm, units), _fmt(r.efl_mm, 3), _fmt(r.hfov_deg, 3),
                  _fmt(r.breathing_focal_length_mm, 3), _fmt(r.magnification, 4), _fmt(r.back_focus_mm, 3),
                  _fmt(r.entrance_pupil_from_film_mm, 2), _fmt(r.fov_change_pct, 2))
    print_table(t)
    if path is not None:
        print(f"wrote {path}")
    return 0


def _print_breathing_per_axis(p, rows, sensor_name, units) -> None:
    """An anamorphic lens's breathing: horizontal (X) and vertical (Y) framing focal lengths and pupils."""
    from ..units import format_distance
    from ._output import Table, print_table

    t = Table(f"{p.name}: focus breathing per axis, {sensor_name} sensor (X horizontal, Y vertical meridian)",
              ("focus from film", "framing f H (mm)", "framing f V (mm)", "squeeze", "HFOV (deg)",
               "pupil H (mm)", "pupil V (mm)", "FOV change (%)"), justify=["right"] * 8)
    for r in rows:
        t.add_row(format_distance(r.focus_from_film_mm, units), _fmt(r.breathing_focal_length_mm, 3),
                  _fmt(r.vertical_breathing_focal_length_mm, 3), _fmt(r.breathing_squeeze, 4), _fmt(r.hfov_deg, 3),
                  _fmt(r.entrance_pupil_from_film_mm, 2), _fmt(r.vertical_entrance_pupil_from_film_mm, 2),
                  _fmt(r.fov_change_pct, 2))
    print_table(t)


# ---- lens check / lens fix ----------------------------------------------------------------
def run_check(args) -> int:
    from ..errors import LensFileError
    from ..lens.check import check
    from ._common import console
    from ._output import document, emit_json

    if args.sensor:
        from ..optics.sensors import find_sensor

        find_sensor(args.sensor)  # an unknown name is refused before any work
    from ..analysis.lens_cards.probes import ray_probes
    from ..usd.lens_archive import check_archive, is_archive

    if is_archive(args.lens):
        findings = check_archive(args.lens, probes=ray_probes(args.sensor))
    else:
        findings = check(args.lens, probes=ray_probes(args.sensor))
    unreadable = next((f for f in findings if f.code in ("unreadable", "archive_unreadable")), None)
    if unreadable is not None:  # no such lens, or not a lens file at all: bad input (exit 2), not a finding
        raise LensFileError(unreadable.message, path=None, line=None)
    # a checker: exit 1 when it finds an error in the lens (docs/cli.md, "Exit status"); warnings too with --strict
    failing = ("error", "warning") if args.strict else ("error",)
    rc = 1 if any(f.severity in failing for f in findings) else 0
    if args.json:
        emit_json(document("lens_check", {
            "lens": args.lens, "findings": [f.to_dict() for f in findings],
            "counts": {s: sum(f.severity == s for f in findings) for s in ("error", "warning", "note")}}))
        return rc
    con = console()
    if not findings:
        con.print(f"{args.lens}: no findings")
        return 0
    for f in findings:
        con.print(str(f), soft_wrap=True)
    counts = {s: sum(f.severity == s for f in findings) for s in ("error", "warning", "note")}
    tail = ""
    if counts["error"]:
        tail = f"; `physcam lens fix --lens {args.lens} -o FIXED.toml` proposes repairs"
    con.print(f"{counts['error']} error(s), {counts['warning']} warning(s), {counts['note']} note(s){tail}",
              soft_wrap=True)
    return rc


def _diff(a, b, lines) -> list[str]:
    """Human-readable per-surface differences between two prescriptions of the same surfaces."""
    out = []
    for i, (s, t) in enumerate(zip(a.surfaces, b.surfaces)):
        where = f"surface {i}" + (f" (line {lines[i]})" if i < len(lines) and lines[i] is not None else "")
        if s.semi_diameter != t.semi_diameter:
            out.append(f"{where}: clear diameter {2 * s.semi_diameter:g} -> {2 * t.semi_diameter:g} mm")
        if s.thickness != t.thickness:
            out.append(f"{where}: thickness {s.thickness:g} -> {t.thickness:g} mm")
    return out


def run_fix(args) -> int:
    import dataclasses

    from ..io import check_writable
    from ..lens.check import read_raw
    from ..lens.formats import write_lens
    from ..lens.formats._common import json_text
    from ..lens.repair import paraxial_f_number, propose, with_corrections
    from ._common import console
    from ._output import document, emit_json

    if args.apply:
        check_writable(args.output, force=args.force)
    raw = read_raw(args.lens)
    q, repairs = propose(raw.prescription)
    diff = _diff(raw.prescription, q, raw.lines)
    written = None
    if repairs and args.apply:
        q = with_corrections(q, repairs)
        extras = dict(q.extras)
        extras.setdefault("provenance.original_file", json_text(str(args.lens)))
        extras.setdefault("provenance.original_format", json_text(raw.format))
        q = dataclasses.replace(q, extras=tuple(sorted(extras.items())))
        q.validate(str(args.lens), list(raw.lines))
        written = str(write_lens(q, args.output, force=args.force))
    elif not repairs:
        raw.prescription.validate(str(args.lens), list(raw.lines))  # nothing to repair: say if still unbuildable
    if args.json:
        emit_json(document("lens_fix", {
            "lens": args.lens, "repairs": [r.to_dict() for r in repairs], "diff": diff,
            "f_number_before": _finite(paraxial_f_number, raw.prescription),
            "f_number_after": _finite(paraxial_f_number, q), "written": written}))
        return 0
    con = console()
    if not repairs:
        con.print(f"{args.lens}: nothing to repair")
        return 0
    for n, r in enumerate(repairs, 1):
        con.print(f"repair {n}: {r.message}", soft_wrap=True)
    con.print("diff:")
    for line in diff:
        con.print(f"  {line}", soft_wrap=True)
    con.print(f"wrote {written}" if written else f"dry run: add --apply to write {args.output}")
    return 0


# ---- lens pack / lens add -------------------------------------------------------------------
def _read_runs(csv_path) -> dict:
    """variant -> {measured name: number or text} from the CSV of ``lens pack --characterizations``."""
    import csv
    import re
    from pathlib import Path

    from ..errors import InputError, LensFileError

    p = Path(csv_path)
    try:
        rows = list(csv.DictReader(p.read_text(encoding="utf-8-sig").splitlines()))
    except (OSError, UnicodeDecodeError, csv.Error) as exc:
        raise InputError(f"cannot read {p}: {exc}") from None
    out = {}
    for line, row in enumerate(rows, start=2):
        label = row.get("variant") or row.get("date")
        if not label:
            raise LensFileError("a row without a variant (or date)", str(p), line)
        name = label if "variant" in row else "d" + re.sub(r"[^A-Za-z0-9]", "_", label)
        values = {}
        for k, v in row.items():
            if k in ("variant", "date") or v in (None, ""):
                continue
            if not re.fullmatch(r"[A-Za-z0-9_]+", k or ""):
                raise LensFileError(f"column {k!r}: a measured value's name is letters, digits and underscores", str(p), 1)
            try:
                values[k] = float(v)
            except ValueError:
                values[k] = v
        out[name] = values
    if not out:
        raise LensFileError("no characterization rows", str(p))
    return out


def run_pack(args) -> int:
    """``physcam lens pack``: the lens archive (:func:`physcam.usd.lens_archive.pack_lens`)."""
    from ..io import check_writable
    from ..usd.lens_archive import read_manifest, pack_lens
    from ._common import resolve_focus, resolve_sensor
    from ._output import document, emit_json

    check_writable(args.output, force=args.force)  # before the seconds of work
    p = at_zoom_named(load_lens_arg(args.lens, args.lenient), args)  # a zoom's card at --zoom, named so in its title
    sensor = resolve_sensor(args)
    (mark,) = resolve_focus([args.focus], lens=p, sensor=sensor, args=args)
    runs = _read_runs(args.characterizations) if args.characterizations else None
    path = pack_lens(p, args.output, slug=args.slug, focus_mm=mark, fstop=args.fstop, sensor=sensor,
                     characterizations=runs, source=args.source, licence=args.licence, draft=args.draft,
                     force=args.force)
    m = read_manifest(path)
    if args.json:
        emit_json(document("lens_pack", {"archive": str(path), "slug": m["slug"], "lens": m["name"],
                                         "files": m["files"], "characterizations": m["characterizations"]}))
        return 0
    print(f"wrote {path}: lens {m['slug']!r} ({m['name']}), {', '.join(m['files'])} and manifest.json")
    return 0


def run_add(args) -> int:
    """``physcam lens add``: check a lens archive and install it (:func:`physcam.usd.lens_archive.add_lens`)."""
    from ..usd.lens_archive import add_lens
    from ._output import document, emit_json

    slug, folder = add_lens(args.archive, force=args.force)
    if args.json:
        emit_json(document("lens_add", {"archive": args.archive, "slug": slug, "folder": str(folder)}))
        return 0
    print(f"installed {slug} into {folder} (`physcam lens show --lens {slug}`)")
    return 0


def _finite(fn, p):
    import math

    try:
        v = fn(p)
    except (ArithmeticError, ValueError, LookupError, PhysCamError):
        return None
    return v if isinstance(v, float) and math.isfinite(v) else None

"""``physcam report``: the on-set lens report (practical and technical models)."""

from __future__ import annotations

from ._common import FOCUS_HELP, coc_value, distance, focal_length, focus, number, figure_file

EPILOG = """\
distances accept units as said on set: 3m, 10ft, 6in, 450mm, 10'6" (a bare focus, near or far is mm,
or feet under --units ft or units = "ft" in the user config; lengths inside the camera are mm);
--focus also takes hyperfocal and infinity. Focus, near, far and --sensor-front are measured
from the film plane; --h1/--h2/--pupil are distances in front of the reference plane
(--reference film|flange). --units ft prints scene distances in feet and inches.

examples:
  physcam report --focal 50 --fstop 2.8 --focus 3m --sensor "ALEXA 35"
  physcam report --focal 35 --fstop 4 --focus hyperfocal --units ft
  physcam report --focal 35 --focus 10ft --near 8ft --coc 0.025 --tstop 2.8   (solve f-stop)
  physcam report --focal 50 --near 2.5m --far 4m --fstop 4 --sensor S35         (solve focus)
  physcam report --model technical --focal 50.36 --fstop 2 --focus 2m --h1 46.24 --h2 51.69 --pupil 49.53
  physcam report --lens dgauss_50mm --fstop 2.8 --focus 2m                     (planes from the lens)
  physcam report --lens dgauss_50mm --fstop 2.8 --focus 3m --dof real           (and limits from real rays)
"""


def register(sub) -> None:
    import argparse

    p = sub.add_parser(
        "report",
        help="on-set lens report: DOF, FOV, hyperfocal, pivot, USD and RenderMan cameras",
        description="Solve the on-set lens report (thin-lens practical model or datasheet technical model).",
        epilog=EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    add_report_arguments(p)
    from ._common import add_lenient

    add_lenient(p)
    from ._common import add_units_option
    from ._output import add_output_options

    add_units_option(p)
    add_output_options(p, what="the report")
    p.add_argument("--cameras", action="store_true", help="also print the UsdGeomCamera and RenderMan blocks")
    g = p.add_argument_group("depth of field from real rays (with --lens)")
    g.add_argument("--dof", choices=("model", "real"), default="model",
                   help="real: also find near and far by tracing the lens (where its blur reaches the CoC), at the "
                        "centre and at a field point, beside the model's (docs/lens-report.md)")
    g.add_argument("--dof-field", metavar="MM", type=distance("field image height"), default=None,
                   help="the field point's image height on the film, mm (default half the sensor's half diagonal)")
    g.add_argument("--blur", choices=("moment", "energy"), default="energy",
                   help="the real blur's size: energy = the diameter holding --energy-fraction of the light "
                        "(default), moment = the second-moment diameter sqrt(8 E[r^2])")
    g.add_argument("--energy-fraction", metavar="F", type=number("energy fraction"), default=0.8,
                   help="fraction of the light within the blur diameter (default 0.8)")
    g.add_argument("--focusing", choices=("collimated", "paraxial"), default="collimated",
                   help="where the real lens's film sits: collimated = its best focus at the mark, as a lens "
                        "technician sets it (default); paraxial = at the mark's paraxial image (Gaussian optics)")
    p.add_argument("--plot", metavar="FILE", type=figure_file, help="draw the depth-of-field chart (near and far against focus, a band per "
                                                  "stop) to FILE (.png, .svg or .pdf; in feet with --units ft)")
    p.add_argument("--force", action="store_true", help="overwrite an existing --plot file")
    p.set_defaults(handler=run)


def add_report_arguments(p) -> None:
    g = p.add_argument_group("lens and sensor")
    g.add_argument("--lens", metavar="NAME_OR_FILE",
                   help="a real lens (bundled name or prescription file): fills the technical model from it")
    from ._zoom import add_zoom_option

    add_zoom_option(g)
    g.add_argument("--focal", metavar="MM", type=focal_length(), help="focal length (mm)")
    g.add_argument("--fstop", metavar="N", type=number("f-stop"), help="f-stop (geometric f-number); solved from --near/--far if omitted (with --lens: wide open)")
    g.add_argument("--tstop", metavar="T", type=number("T-stop"), help="marked T-stop, compared with the effective f-stop")
    g.add_argument("--focus", metavar="DIST", type=focus("focus distance"),
                   help=f"focus mark, film plane to subject ({FOCUS_HELP})")
    from ._common import add_sensor_options

    add_sensor_options(g, what="group")
    g.add_argument("--squeeze", metavar="S", type=number("squeeze"), default=1.0, help="anamorphic squeeze (default 1)")
    add_coc_option(g)
    g = p.add_argument_group("measured depth of field (inverse solve)")
    g.add_argument("--near", metavar="DIST", type=distance("near limit", scene=True),
                   help="measured near limit, from the film plane")
    g.add_argument("--far", metavar="DIST", type=distance("far limit", allow_inf=True, scene=True),
                   help="measured far limit (or inf)")
    g = p.add_argument_group("model")
    g.add_argument("--model", choices=("practical", "technical"), default="practical",
                   help="practical = thin lens; technical = datasheet principal planes")
    g.add_argument("--h1", metavar="DIST", type=distance("H1 offset"), help="front principal plane, in front of the reference")
    g.add_argument("--h2", metavar="DIST", type=distance("H2 offset"), help="rear principal plane, in front of the reference")
    g.add_argument("--pupil", metavar="DIST", type=distance("entrance pupil offset"),
                   help="entrance pupil, in front of the reference plane (technical)")
    g.add_argument("--reference", choices=("film", "flange"), default="film",
                   help="plane the datasheet offsets are measured from")
    g.add_argument("--flange", metavar="MM", type=distance("flange focal distance"),
                   help="flange focal distance (e.g. 52 for PL, 44 for LPL) when --reference flange")
    g.add_argument("--sensor-front", metavar="DIST", type=distance("sensor-to-lens-front distance"),
                   help="tape measure: film mark to the front of the lens (practical pupil estimate)")
    g.add_argument("--lens-length", metavar="DIST", type=distance("lens length"), help="physical lens length")
    g.add_argument("--pupil-fraction", metavar="F", type=number("pupil fraction"), default=None,
                   help="with --sensor-front: entrance pupil this fraction of the lens length behind its front "
                        "(default 0.4)")
    g = p.add_argument_group("cameras")
    g.add_argument("--meters-per-unit", metavar="MPU", type=number("metersPerUnit"), default=0.01,
                   help="scene unit for USD/RenderMan values (default 0.01 = cm)")
    g.add_argument("--shutter-angle", metavar="DEG", type=number("shutter angle"), default=180.0, help="degrees (default 180)")
    g.add_argument("--shift-x", metavar="MM", type=distance("horizontal sensor shift"), default=0.0,
                   help="horizontal lens/sensor shift on the film (mm; + right): aperture offsets, screen window")
    g.add_argument("--shift-y", metavar="MM", type=distance("vertical sensor shift"), default=0.0,
                   help="vertical lens/sensor shift on the film (mm; + up; write negative values as --shift-y=-2)")


def add_coc_option(p, extra: str = "") -> None:
    """--coc: a convention name or a value with units (the one definition)."""
    p.add_argument("--coc", type=coc_value, default=None, metavar="COC",
                   help=f"{extra}circle of confusion: d/1500 (default, or `coc` in the user config), d/1000, d/1730, "
                        "cine (0.025 mm) or a value from 0.001 to 1 mm (0.025, 25um, 0.025mm; a bare number is mm)")


def resolve_sensor(args, default: str | None = None, *, quiet: bool = False):
    """The sensor a command was given (:func:`physcam.cli._common.resolve_sensor`)."""
    from ._common import resolve_sensor as resolve

    return resolve(args, default, quiet=quiet)


def solve_from_args(args):
    """The lens report of the command's options: the camera built once at the door
    (:func:`physcam.onset.request.report_camera`), then its report; ``args.report_inputs`` keeps them."""
    from ..errors import InputError
    from ..onset.report import report_camera, solve_report

    lens = None
    if getattr(args, "lens", None):
        from ..lens.library import load_lens

        from ._zoom import zoomed

        lens = zoomed(load_lens(args.lens, lenient=getattr(args, "lenient", False)), args)
        args.loaded_lens = lens
        if args.focal is not None:
            raise InputError("give either --lens or --focal: the lens sets its own focal length")
    elif args.focal is None:
        raise InputError("give the focal length, e.g. --focal 50, or a lens with --lens NAME")
    if getattr(args, "pupil_fraction", None) is not None and getattr(args, "sensor_front", None) is None:
        raise InputError("--pupil-fraction places the tape-measure pupil estimate: it needs --sensor-front and "
                         "--lens-length")
    from ._common import coc_of

    coc = coc_of(args)
    sensor = resolve_sensor(args, quiet=True)  # the report says it in its notes
    args.report_inputs = report_camera(**_request_inputs(args, lens, sensor, coc))
    report = solve_report(args.report_inputs)
    if getattr(args, "sensor_note", ""):  # a bare camera name: which format it is and how to name another
        from .._record import replace

        report = replace(report, notes=report.notes + (args.sensor_note,))
    if getattr(args, "sensor_defaulted", False):
        from .._record import replace

        report = replace(report, notes=report.notes + (
            f"no --sensor given: {sensor.name}, {sensor.width_mm:g} x {sensor.height_mm:g} mm "
            f"({args.sensor_default_source}; give --sensor to change it)",))
    return report


def dof_chart_solver(args, report):
    """``solve(fstop, focus_mm)`` for :func:`physcam.onset.dof_plot.dof_chart_figure`: the report of the
    camera of ``report`` (after :func:`solve_from_args`) at another stop and focus mark, with the report's
    CoC and sensor and no measured limits, so that the chart and the report agree at the report's own
    cell. The cameras share the lens model, so a prescription focuses at each mark once; a cell's report
    leaves out the real-ray field of view (the chart reads its depth of field: ``real_fov=False``)."""
    from .._record import replace

    from ..onset.report import solve_report
    from ..optics.state import camera_state

    cam, refs = report.camera, replace(report.references, tstop=None)

    def solve(fstop, focus_mm):
        at = camera_state(cam.lens_model, focus_mm=focus_mm, fstop=fstop, sensor=cam.sensor, squeeze=cam.squeeze,
                          zoom=cam.zoom)
        return solve_report(at, coc=report.coc_mm, references=refs, real_fov=False)

    return solve


def _request_inputs(args, lens, sensor, coc) -> dict:
    """The report's inputs from the parsed options (the inputs of physcam.onset.request.report_camera)."""
    return dict(
        focal_length_mm=args.focal,
        sensor=sensor,
        fstop=args.fstop,
        focus_mm=args.focus,
        coc=coc,
        near_mm=args.near,
        far_mm=args.far,
        tstop=args.tstop,
        squeeze=args.squeeze,
        model=args.model,
        h1_mm=args.h1,
        h2_mm=args.h2,
        pupil_mm=args.pupil,
        reference_plane=args.reference,
        flange_focal_distance_mm=args.flange,
        sensor_front_mm=args.sensor_front,
        lens_length_mm=args.lens_length,
        pupil_fraction=0.4 if getattr(args, "pupil_fraction", None) is None else args.pupil_fraction,
        lens=lens,
    )


def thin_lens_gap_from_args(args, report):
    """How far a renderer's thin-lens camera of ``report`` is from the prescription the command loaded
    (:func:`physcam.onset.thin_lens_gap.thin_lens_gap`), or None for a thin lens or a datasheet."""
    if getattr(args, "loaded_lens", None) is None:
        return None
    from ..onset.thin_lens_gap import thin_lens_gap

    return thin_lens_gap(report)


def camera_blocks(report, args) -> dict:
    from ..export.renderman import renderman_camera_values
    from ..export.usdgeom import usdgeom_camera_values

    mpu = args.meters_per_unit
    shift = (getattr(args, "shift_x", 0.0), getattr(args, "shift_y", 0.0))
    fov = report.fov_dict()  # (not the whole to_dict: the serve page asks it per keystroke, issue 47)
    calc = report
    if report.focus_is_infinite:  # every value but the focus distance is that of a far, finite focus
        from .._record import replace

        from ..onset.report import MAX_DISTANCE_MM

        # (the camera moved to that mark for these values only: no focus is solved, nothing else asks it)
        far = replace(report.camera, focus_from_film_mm=MAX_DISTANCE_MM)
        calc = replace(report, camera=far, object_distance_mm=MAX_DISTANCE_MM)
    blocks = {
        "meters_per_unit": mpu,
        "camera": "the best-match pinhole at the entrance pupil (docs/lens-report.md)",
        "fov_deg": {"pinhole": fov["focus"], "real": fov["real"]},
        "usd_geom_camera": usdgeom_camera_values(calc, mpu, shutter_angle_deg=args.shutter_angle, shift_mm=shift),
        "renderman": renderman_camera_values(calc, mpu, shift_mm=shift),
        "notes": [],
    }
    if report.real_fov_differs:
        blocks["notes"].append("these cameras are pinholes: they show the pinhole field of view, not the real "
                               "lens's (see fov_deg.real); distortion this strong needs a real-lens camera")
    if report.focus_is_infinite:
        blocks["usd_geom_camera"]["focusDistance"] = None
        blocks["renderman"]["focalDistance"] = None
        blocks["notes"].append("focus at infinity: the cameras' focus distance is infinite (null here); "
                               "a renderer that needs a number takes its largest focus distance")
    return blocks


def real_dof_block(report, args) -> dict:
    """The real-ray depth of field (:func:`physcam.analysis.defocus.real_dof.real_depth_of_field`) at the centre and
    at a field point, beside the model's, for ``physcam report --dof real``."""
    from ..analysis.defocus.real_dof import real_depth_of_field
    from ..errors import InputError, OpticsError

    lens = getattr(args, "loaded_lens", None)
    if lens is None:
        raise InputError("--dof real traces a prescription: give the lens (--lens NAME or file)")
    if report.focus_is_infinite:
        raise InputError("--dof real needs a finite focus mark (the limits of a lens focused at infinity are its "
                         "hyperfocal parameter and infinity)")
    h = report.sensor.diagonal_mm / 4 if args.dof_field is None else args.dof_field
    model = report.dof
    out = {"measure": args.blur, "energy_fraction": args.energy_fraction if args.blur == "energy" else None,
           "focusing": args.focusing,
           "model": {"near_from_film_mm": model.near_from_film_mm,
                     "far_from_film_mm": None if model.far_is_infinite else model.far_from_film_mm}}
    for key, height in (("centre", 0.0), ("field", h)):
        try:
            r = real_depth_of_field(report.stopped_camera(), coc_mm=report.coc_mm, image_height_mm=height,
                                    measure=args.blur,
                                    energy_fraction=args.energy_fraction, focusing=args.focusing)
            d = r.to_dict()
            if not (r.far_is_infinite or model.far_is_infinite):
                d["model_deeper_pct"] = (model.total_mm / r.total_mm - 1.0) * 100.0
                d["band_shift_mm"] = 0.5 * (r.near_from_film_mm + r.far_from_film_mm - model.near_from_film_mm
                                            - model.far_from_film_mm)
                d["real_deeper_pct"] = (r.total_mm / model.total_mm - 1.0) * 100.0
            out[key] = d
        except OpticsError as exc:
            out[key] = {"image_height_mm": height, "error": str(exc)}
    out["definition"] = ("near and far where the traced blur (measure) on the film equals the CoC; focusing: "
                         "collimated = the film at the lens's best focus for the mark, paraxial = at the mark's "
                         "paraxial image; band_shift_mm: the real band's middle minus the model's (- nearer); "
                         "real_deeper_pct: the real total depth over the model's, minus 1, in percent; "
                         "model_deeper_pct: the model's over the real one, minus 1")
    return out


def band_words(d: dict) -> str:
    """The real band against the model's, in words: "31 mm nearer, 10 % deeper" (a real-ray result's dict)."""
    shift, deeper = d["band_shift_mm"], d["real_deeper_pct"]
    where = "where the model puts it" if abs(shift) < 0.5 else f"{abs(shift):.0f} mm {'nearer' if shift < 0 else 'farther'}"
    depth = "as deep" if abs(deeper) < 0.5 else f"{abs(deeper):.0f} % {'deeper' if deeper > 0 else 'shallower'}"
    return f"real band {where}, {depth} than the model"


def _real_rows(real, units) -> list[tuple]:
    """Table rows of :func:`real_dof_block` (none without ``--dof real``)."""
    if real is None:
        return []
    from ..units import format_distance

    rows = []
    for key in ("centre", "field"):
        d = real[key]
        where = "centre" if key == "centre" else f"field {d['image_height_mm']:.1f} mm"
        if "error" in d:
            rows.append((f"real-ray DOF ({where})", "none: " + d["error"].split(": ")[-1], ""))
            continue
        far = "infinity" if d["far_is_infinite"] else format_distance(d["far_from_film_mm"], units)
        value = f"{format_distance(d['near_from_film_mm'], units)} / {far}"
        if d.get("band_shift_mm") is not None:
            value += f"  ({band_words(d)})"
        rows.append((f"real-ray near / far ({where})", value, "film plane"))
    if rows:
        focusing = ("collimated: the lens's best focus at the mark" if real["focusing"] == "collimated" else
                    "paraxial: the film at the mark's paraxial image")
        shift = real["centre"].get("film_shift_mm")
        if shift is not None and real["focusing"] == "collimated":
            focusing += (f", the film {abs(shift) * 1e3:.0f} µm {'behind' if shift > 0 else 'in front of'} "
                         "the mark's paraxial image")
        rows.append(("real-ray focusing", focusing, ""))
    return rows


def report_document(report, cams, args) -> dict:
    """The document ``physcam report --json`` prints (and ``physcam serve`` answers): the report's
    ``to_dict()`` with the camera blocks, marked when the lens was repaired on load."""
    d = report.to_dict()
    d["cameras"] = cams
    if getattr(args, "loaded_lens", None) is not None:
        from ._common import mark_repaired

        d = mark_repaired(d, args.loaded_lens)
    return d


def run(args) -> int:
    from ._common import console, print_json

    if args.force and not args.plot:
        from ..errors import InputError

        raise InputError("--force overwrites the --plot file; without --plot there is nothing to overwrite")
    from ._common import units_of

    report = solve_from_args(args)
    cams = camera_blocks(report, args) if args.json or args.cameras else None  # (the table prints none)
    units = units_of(args)
    real = real_dof_block(report, args) if args.dof == "real" else None
    if args.plot:
        from ..onset.dof_plot import plot_dof_chart

        plot_dof_chart(report, dof_chart_solver(args, report), args.plot, force=args.force, units=units)
    if args.json:
        doc = report_document(report, cams, args)
        if real is not None:
            doc["dof_real"] = real
        print_json(doc)
        return 0
    from ..onset.table import report_rows, report_title
    from ._output import Table, print_table

    t = Table(report_title(report), ("quantity", "value", "measured from"))
    for r in report_rows(report, units, notes=False):
        t.add_row(*r)
    for r in _real_rows(real, units):
        t.add_row(*r)
    print_table(t)
    for n in report.notes:
        print(f"note: {n}")
    if args.cameras:
        print_json(cams)
    if args.plot:
        console(stderr=True).print(f"wrote {args.plot}")
    return 0

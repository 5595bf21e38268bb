"""``physcam diopter``: close-up lenses (+0.5, +1, +2, +3 ...) on a lens at its focus mark: where the subject
then is and its depth of field (physcam.onset.diopter, thin lenses in contact)."""

from __future__ import annotations

from ._common import FOCUS_HELP, add_sensor_options, add_units_option, focal_length, focus, list_items, number

EPILOG = """\
examples:
  physcam diopter --focal 50 --fstop 2.8 --focus inf           # +0.5, +1, +2, +3 with the lens at infinity
  physcam diopter --focal 85 --fstop 4 --focus 1m --diopters 1,2 --sensor "ALEXA 35" --json
"""


def _diopters(text):
    one = number("diopter", positive=True)
    return [one(t.lstrip("+")) for t in list_items(text, "diopters", "0.5,1,2,3")]


def register(sub) -> None:
    import argparse

    from ._output import add_output_options
    from .report import add_coc_option

    p = sub.add_parser("diopter", help="close-up lenses on a lens: the subject distance and depth of field of each",
                       description="Close-up lenses (diopters) in front of a thin lens focused at a mark: where the "
                                   "subject sharp on the film then is (from the film plane) and its near and far limits "
                                   "at the CoC of the sensor. The diopter is taken in contact with the lens (1/f = "
                                   "1/f_lens + P); the pupil keeps its diameter.", epilog=EPILOG,
                       formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--focal", required=True, type=focal_length(), metavar="MM", help="focal length (mm)")
    p.add_argument("--fstop", required=True, type=number("f-stop", positive=True), metavar="N", help="f-stop")
    p.add_argument("--focus", required=True, type=focus("focus mark"), metavar="DIST",
                   help=f"the lens's focus mark, from the film plane ({FOCUS_HELP})")
    p.add_argument("--diopters", type=_diopters, default=[0.5, 1.0, 2.0, 3.0], metavar="LIST",
                   help="close-up lenses in dioptres, comma-separated (default 0.5,1,2,3)")
    add_sensor_options(p)
    add_coc_option(p)
    add_units_option(p)
    add_output_options(p, what="the close-up table")
    p.set_defaults(handler=run)


def run(args) -> int:
    from ..onset.diopter import close_up
    from ..onset.report import solve_report
    from ..onset.request import report_camera
    from ..units import format_distance
    from ._common import coc_of, resolve_sensor, units_of
    from ._output import Table, document, emit_json, print_table

    sensor = resolve_sensor(args)
    base = solve_report(report_camera(sensor=sensor, focal_length_mm=args.focal, fstop=args.fstop,
                                      focus_mm=args.focus, coc=coc_of(args)))
    mark = base.focus_from_film_mm  # a mark as typed, or the hyperfocal distance's
    rows = [close_up(args.focal, args.fstop, base.coc_mm, mark, p) for p in args.diopters]
    if args.json:
        emit_json(document("diopter", {"focal_length_mm": args.focal, "fstop": args.fstop,
                                       "focus_from_film_mm": None if base.focus_is_infinite else base.focus_from_film_mm,
                                       "coc_mm": base.coc_mm, "coc_convention": base.coc_convention,
                                       "sensor": sensor.name, "close_ups": [r.to_dict() for r in rows]}))
        return 0
    units = units_of(args)

    def d(mm):
        return "∞" if mm is None else format_distance(mm, units)

    t = Table(f"close-up lenses on {args.focal:g} mm f/{args.fstop:g}, "
              f"focus mark {d(None if base.focus_is_infinite else mark)}, "
              f"CoC {base.coc_mm:.4f} mm ({base.coc_convention})",
              ("diopter", "subject", "near", "far", "depth of field", "magnification"),
              justify=("left", "right", "right", "right", "right", "right"))
    for r in rows:
        x = r.to_dict()
        t.add_row(f"+{r.diopter:g}", d(x["subject_from_film_mm"]), d(x["near_from_film_mm"]), d(x["far_from_film_mm"]),
                  d(x["depth_of_field_mm"]), f"1:{1 / abs(r.magnification):.1f}")
    print_table(t)
    return 0

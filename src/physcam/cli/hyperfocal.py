"""``physcam hyperfocal``: the hyperfocal table of a lens set (or focal lengths) at a row of stops: the mark
that holds infinity and its near limit, per lens and stop (physcam.onset.hyperfocal, .lens_set)."""

from __future__ import annotations

from ._common import add_sensor_options, add_units_option, list_items

EPILOG = """\
examples:
  physcam hyperfocal --focal 18,25,35,50 --sensor "ALEXA 35" --coc cine
  physcam hyperfocal --lens-set primes.txt --fstops 2.8,4,5.6,8 --units ft
(a lens set: one lens a line, 'focal T-stop close-focus', e.g. '50 T2 20in'; docs/lens-report.md)
"""

DEFAULT_FSTOPS = (2.0, 2.8, 4.0, 5.6, 8.0, 11.0, 16.0)


def _focals(text):
    from ._common import focal_length

    one = focal_length()
    return [one(t) for t in list_items(text, "focal lengths", "18,25,35,50")]


def register(sub) -> None:
    import argparse

    from ._output import add_output_options
    from .dof_table import _fstops
    from .report import add_coc_option

    p = sub.add_parser("hyperfocal", help="hyperfocal table of a lens set: the mark that holds infinity, per lens and "
                                          "stop", epilog=EPILOG, formatter_class=argparse.RawDescriptionHelpFormatter,
                       description="Each lens's hyperfocal focus mark (from the film plane) and near limit at each stop; "
                                   "stops faster than a set lens's T-stop are left out for that lens.")
    g = p.add_mutually_exclusive_group(required=True)
    g.add_argument("--lens-set", metavar="FILE", help="a lens set file: one lens a line, 'focal T-stop close-focus'")
    g.add_argument("--focal", type=_focals, metavar="LIST", help="focal lengths (mm), comma-separated")
    p.add_argument("--fstops", type=_fstops, default=list(DEFAULT_FSTOPS), metavar="LIST",
                   help="stops (f-numbers), comma-separated (default 2,2.8,4,5.6,8,11,16)")
    add_sensor_options(p)
    add_coc_option(p)
    add_units_option(p)
    add_output_options(p, what="the table")
    p.set_defaults(handler=run)


def run(args) -> int:
    from ..onset.hyperfocal import hyperfocal_table
    from ..onset.lens_set import LensSet, SetLens, read_lens_set
    from ..units import format_distance
    from ._common import coc_of, resolve_sensor, units_of
    from ._output import Table, document, emit_json, print_table

    lens_set = read_lens_set(args.lens_set) if args.lens_set else LensSet(
        "focal lengths", tuple(SetLens(f) for f in args.focal))
    sensor = resolve_sensor(args)
    coc = coc_of(args)
    rows = []
    for lens in lens_set.lenses:
        stops = [n for n in args.fstops if lens.tstop is None or n >= lens.tstop * (1 - 1e-9)]
        table = hyperfocal_table([lens.focal_length_mm], stops, sensor=sensor, coc=coc)[0] if stops else None
        rows.append((lens, stops, table))
    if args.json:
        out = []
        for lens, stops, table in rows:
            out.append({**lens.to_dict(), "coc_mm": None if table is None else table["coc_mm"],
                        "coc_convention": None if table is None else table["coc_convention"],
                        "stops": [{"fstop": n, "hyperfocal_mark_mm": table["marks"][n][0],
                                   "near_from_film_mm": table["marks"][n][1]} for n in stops]})
        emit_json(document("hyperfocal", {"lens_set": lens_set.name, "sensor": sensor.name, "lenses": out}))
        return 0
    units = units_of(args)
    coc_text = next((f"{t['coc_mm']:.4f} mm ({t['coc_convention']})" for _, _, t in rows if t), "")
    t = Table(f"hyperfocal marks from the film plane (near limit below), {sensor.name}, CoC {coc_text}",
              ("lens", *(f"f/{n:g}" for n in args.fstops)), justify=("left", *("right",) * len(args.fstops)))
    for lens, stops, table in rows:
        cells = [format_distance(table["marks"][n][0], units) if n in stops else "—" for n in args.fstops]
        t.add_row(lens.label, *cells)
        near = [format_distance(table["marks"][n][1], units) if n in stops else "" for n in args.fstops]
        t.add_row("  near", *near)
    print_table(t)
    return 0

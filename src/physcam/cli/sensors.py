"""``physcam sensors``: the sensor and film-gate table, filtered by maker, format and size."""

from __future__ import annotations

from ._common import distance

EPILOG = """\
examples:
  physcam sensors                      # every sensor and film gate
  physcam sensors ARRI                 # by maker (or any words of the name: "ALEXA 35", "open gate")
  physcam sensors --maker Sony --min-width 30
  physcam sensors --format 16:9 --csv  # for a spreadsheet
  physcam sensors "Mini LF"            # one name or alias: that sensor
  physcam sensors FX6                  # a camera: every recording format it has (use one with --sensor)
  physcam sensors --maker Canon 4K     # a maker's 4K formats
"""


def register(sub) -> None:
    import argparse

    from ._output import add_output_options

    p = sub.add_parser("sensors", help="list known sensors and film gates (names usable with --sensor); filter them",
                       description="The sensor and film-gate table (active area in mm); filter it by words of the "
                                   "name, maker, format and width.", epilog=EPILOG,
                       formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("name", nargs="*", metavar="WORDS",
                   help="a sensor name or alias (shows that sensor), or words every listed sensor's name, maker or "
                        "aliases contain, e.g. ARRI, \"open gate\"")
    p.add_argument("--maker", metavar="MAKER", help="only this maker: ARRI, RED, Sony, Canon, Blackmagic, Panasonic, Fujifilm, DJI, or film (film gates)")
    p.add_argument("--format", dest="fmt", metavar="TEXT",
                   help="only names containing this format text, e.g. \"open gate\", 16:9, 4-perf")
    p.add_argument("--min-width", type=distance("minimum width"), default=None, metavar="MM",
                   help="only sensors at least this wide (mm; units ok)")
    p.add_argument("--max-width", type=distance("maximum width"), default=None, metavar="MM",
                   help="only sensors at most this wide (mm; units ok)")
    add_output_options(p, csv=True, what="the sensors")
    p.set_defaults(handler=run)


def sensor_document(s) -> dict:
    """One sensor as ``physcam sensors --json`` lists it (and ``physcam serve`` answers)."""
    return s.to_dict()


def select(args) -> list:
    """The sensors ``args`` ask for: one exact name or alias, else every match of the filters."""
    from ..errors import SensorError
    from ..optics.sensors import filter_sensors, find_sensor

    query = " ".join(args.name or ()) if isinstance(args.name, (list, tuple)) else (args.name or "")
    filters = (getattr(args, "maker", None), getattr(args, "fmt", None), getattr(args, "min_width", None),
               getattr(args, "max_width", None))
    if query and all(f is None for f in filters):
        try:
            return [find_sensor(query)]  # an exact name or alias
        except SensorError:
            pass
    rows = filter_sensors(query, maker=filters[0], fmt=filters[1], min_width_mm=filters[2], max_width_mm=filters[3])
    if not rows:
        if query and all(f is None for f in filters):
            find_sensor(query)  # raises with the closest names
        raise SensorError("no sensor matches; `physcam sensors` lists them all (makers: ARRI, RED, Sony, Canon, "
                          "Blackmagic, Panasonic, film)")
    return rows


def run(args) -> int:
    from ._output import Table, document, emit_json, print_csv, print_table

    rows = select(args)
    if args.json:
        emit_json(document("sensors", {"sensors": [sensor_document(s) for s in rows]}, units={"length": "mm"}))
        return 0
    if args.csv:
        print_csv([s.to_dict() for s in rows])
        return 0
    t = Table("sensors, film gates and camera formats (active area, mm)",
              ("name", "maker", "width", "height", "diagonal", "aspect", "anamorphic", "aliases"),
              justify=("left", "left", "right", "right", "right", "right", "left", "left"))
    for s in rows:
        t.add_row(s.name, s.maker, f"{s.width_mm:.2f}", f"{s.height_mm:.2f}", f"{s.diagonal_mm:.2f}",
                  f"{s.aspect:.3f}", ", ".join(f"{q:g}x" for q in s.anamorphic), ", ".join(s.aliases))
    print_table(t)
    return 0

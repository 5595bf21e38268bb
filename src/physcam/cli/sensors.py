"""``physcam sensors``: the sensor and film-gate table."""

from __future__ import annotations


def register(sub) -> None:
    p = sub.add_parser("sensors", help="list known sensors and film gates (names usable with --sensor)")
    p.add_argument("--json", action="store_true", help="print as JSON")
    p.add_argument("name", nargs="?", help="show one sensor (name or alias)")
    p.set_defaults(handler=run)


def sensor_document(s) -> dict:
    """One sensor as ``physcam sensors --json`` prints it (and ``physcam serve`` answers)."""
    return {"key": s.key, "name": s.name, "width_mm": s.width_mm, "height_mm": s.height_mm,
            "diagonal_mm": s.diagonal_mm, "aliases": list(s.aliases), "kind": s.kind, "source": s.source}


def run(args) -> int:
    from ..onset.sensors import find_sensor, sensors
    from ._common import console, print_json

    rows = [find_sensor(args.name)] if args.name else list(sensors())
    if args.json:
        print_json([sensor_document(s) for s in rows])
        return 0
    from rich.table import Table

    t = Table(title="sensors and film gates (mm)")
    for col in ("name", "width", "height", "diagonal", "aliases"):
        t.add_column(col)
    for s in rows:
        t.add_row(s.name, f"{s.width_mm:.2f}", f"{s.height_mm:.2f}", f"{s.diagonal_mm:.2f}", ", ".join(s.aliases))
    console().print(t)
    return 0

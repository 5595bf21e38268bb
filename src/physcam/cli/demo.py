"""``physcam demo``: the main job on the bundled default lens and sensor.

Writes a complete lens report for a default setup into a folder and prints it:
``report.json`` (the versioned report with its camera blocks), ``report.txt`` (the
table), ``dof.png`` (the depth-of-field zone), plus what later stages add (lens data,
diagram, USD camera, bokeh and spot diagram).
"""

from __future__ import annotations

DEFAULTS = {
    "focal": 50.0,
    "fstop": 2.8,
    "focus": 3000.0,
    "sensor": "ALEXA 35",
}


def register(sub) -> None:
    p = sub.add_parser("demo", help="run the main job on the default lens and sensor, writing a folder of outputs")
    p.add_argument("--out", default="demo-output", help="folder to write (default demo-output)")
    p.add_argument("--force", action="store_true", help="overwrite files already in the folder")
    p.add_argument("--json", action="store_true", help="print the list of written files as JSON")
    p.set_defaults(handler=run)


def _args():
    from argparse import Namespace

    return Namespace(
        focal=DEFAULTS["focal"], fstop=DEFAULTS["fstop"], tstop=None, focus=DEFAULTS["focus"],
        lens=None, sensor=DEFAULTS["sensor"], sensor_width=None, sensor_height=None, squeeze=1.0, coc=None,
        near=None, far=None, model="practical", h1=None, h2=None, pupil=None, reference="film", flange=None,
        sensor_front=None, lens_length=None, pupil_fraction=0.4, meters_per_unit=0.01, shutter_angle=180.0,
    )


def run(args) -> int:
    import json
    from pathlib import Path

    from ..io import atomic_write
    from ..onset.dof_plot import plot_dof_zone
    from ..onset.table import report_table
    from ._common import console, print_json
    from .report import camera_blocks, solve_from_args

    out = Path(args.out)
    ns = _args()
    report = solve_from_args(ns)
    written = []
    d = report.to_dict()
    d["cameras"] = camera_blocks(report, ns)
    written.append(atomic_write(out / "report.json", json.dumps(d, indent=2, allow_nan=False) + "\n",
                                force=args.force))
    con = console()
    with con.capture() as cap:
        con.print(report_table(report))
    table_text = cap.get()
    written.append(atomic_write(out / "report.txt", table_text, force=args.force))
    written.append(plot_dof_zone(report, out / "dof.png", force=args.force))
    if args.json:
        print_json({"out": str(out), "files": [str(p) for p in written]})
        return 0
    print(table_text, end="")
    err = console(stderr=True)
    for p in written:
        err.print(f"wrote {p}")
    return 0

"""``physcam exposure``: a change of frame rate, shutter angle, ND, EI or T-stop, in stops, and what
compensates it (physcam.onset.exposure)."""

from __future__ import annotations

from ._common import number

EPILOG = """\
examples:
  physcam exposure --fps 24 --to-fps 48                  # high speed: -1 stop, and the T-stop that gives it back
  physcam exposure --tstop 2.8 --to-nd 0.9 --compensate ei
  physcam exposure --shutter 180 --to-shutter 90 --ei 800 --to-ei 1600 --json
"""

CONTROLS = ("fps", "shutter", "tstop", "ei", "nd")
FIELDS = {"fps": "fps", "shutter": "shutter_deg", "tstop": "tstop", "ei": "ei", "nd": "nd"}


def register(sub) -> None:
    import argparse

    from ._output import add_output_options

    p = sub.add_parser("exposure", help="exposure changes in stops (frame rate, shutter angle, ND, EI, T-stop) and "
                                        "what compensates them",
                       description="How much a new camera setting brightens (+) or darkens (-) the picture, in stops, "
                                   "and the T-stop (or ND, EI, shutter) that gives the old exposure back. Settings not "
                                   "changed with --to-... stay as they are.",
                       epilog=EPILOG, formatter_class=argparse.RawDescriptionHelpFormatter)
    defaults = {"fps": 24.0, "shutter": 180.0, "tstop": 2.8, "ei": 800.0, "nd": 0.0}
    helps = {"fps": "frame rate", "shutter": "shutter angle (degrees)", "tstop": "T-stop", "ei": "exposure index (ISO)",
             "nd": "ND optical density (0.3 per stop)"}
    for k in CONTROLS:
        p.add_argument(f"--{k}", type=number(helps[k]), default=defaults[k], metavar="X",
                       help=f"{helps[k]} now (default {defaults[k]:g})")
        p.add_argument(f"--to-{k}", type=number(helps[k]), default=None, metavar="X", help=f"the new {helps[k]}")
    p.add_argument("--compensate", choices=("tstop", "nd", "ei", "shutter"), default="tstop",
                   help="the control that gives the old exposure back (default tstop)")
    add_output_options(p, what="the exposure change")
    p.set_defaults(handler=run)


def run(args) -> int:
    from ..errors import InputError
    from ..onset.exposure import ExposureSetting, compensate, stops_between_settings
    from ._output import Table, document, emit_json, print_table

    now = ExposureSetting(**{FIELDS[k]: getattr(args, k) for k in CONTROLS})
    new = ExposureSetting(**{FIELDS[k]: getattr(args, k) if getattr(args, f"to_{k}") is None else getattr(args, f"to_{k}")
                             for k in CONTROLS})
    if now == new:
        raise InputError("nothing changes: give the new setting with --to-fps, --to-shutter, --to-tstop, --to-ei or "
                         "--to-nd")
    change = stops_between_settings(now, new)
    try:
        fix = compensate(now, new, args.compensate)
        fix_error = None
    except InputError as exc:
        fix, fix_error = None, str(exc)
    if args.json:
        emit_json(document("exposure", {"from": now.to_dict(), "to": new.to_dict(), "stops": change["stops"],
                                        "stops_by_control": change["parts"], "compensate": args.compensate,
                                        "compensated": None if fix is None else fix.to_dict(),
                                        "compensation_refused": fix_error},
                           units={"time": "s", "angle": "degree", "stops": "EV (factor 2)"}))
        return 0
    t = Table("exposure change", ("", "now", "new", "stops"), justify=("left", "right", "right", "right"))
    rows = (("frame rate", f"{now.fps:g} fps", f"{new.fps:g} fps", None),
            ("shutter", f"{now.shutter_deg:g}°  1/{1 / now.exposure_time_s:.1f} s",
             f"{new.shutter_deg:g}°  1/{1 / new.exposure_time_s:.1f} s", change["parts"]["time"]),
            ("T-stop", f"T{now.tstop:.2g}", f"T{new.tstop:.2g}", change["parts"]["tstop"]),
            ("EI", f"{now.ei:g}", f"{new.ei:g}", change["parts"]["ei"]),
            ("ND", f"{now.nd:.1f}", f"{new.nd:.1f}", change["parts"]["nd"]))
    for name, a, b, st in rows:
        t.add_row(name, a, b, "" if st is None else f"{st + 0.0:+.2f}")
    t.add_row("total", "", "", f"{change['stops']:+.2f}")
    print_table(t)
    if fix is None:
        print(f"compensate with {args.compensate}: {fix_error}")
    else:
        what = {"tstop": f"T{fix.tstop:.2f}", "nd": f"ND {fix.nd:.2f}", "ei": f"EI {fix.ei:.0f}",
                "shutter": f"{fix.shutter_deg:.1f}° shutter"}[args.compensate]
        print(f"same exposure as now: {what}")
    return 0

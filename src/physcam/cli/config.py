"""``physcam config show``: the user config (defaults set once: sensor, CoC, units, output folder)."""

from __future__ import annotations

EPILOG = """\
The config is a TOML file: $PHYSCAM_CONFIG when set, else ~/.config/physcam/config.toml
($XDG_CONFIG_HOME/physcam/config.toml). Every key is optional; options on the command line win:

  sensor = "ALEXA 35"      # the sensor when no --sensor is given (default Super 35)
  coc = "d/1500"           # circle of confusion: d/1500, d/1000, d/1730, cine or a value (25um)
  units = "ft"             # distances printed in ft (feet and inches) or m
  output_dir = "~/shots"   # relative output files (-o, --plot, usd files) are written here
"""


def register(sub) -> None:
    import argparse

    from ._output import add_output_options

    p = sub.add_parser("config", help="the user config: default sensor, CoC, units, output folder (config show)",
                       description="Show the user config (docs/cli.md): where it is read from and the defaults it "
                                   "sets.", epilog=EPILOG, formatter_class=argparse.RawDescriptionHelpFormatter)
    s = p.add_subparsers(dest="config_command", metavar="ACTION")
    show = s.add_parser("show", help="print the config file's path and every default (its value and where it comes from)",
                        epilog=EPILOG, formatter_class=argparse.RawDescriptionHelpFormatter)
    add_output_options(show, csv=True, what="the config")
    show.set_defaults(handler=run_show)
    p.set_defaults(handler=lambda args: (p.print_help(), 0)[1])


def effective() -> dict:
    """Each key's value in effect and where it comes from (the config file, or physcam's default)."""
    from ._common import DEFAULT_SENSOR
    from ._config import load_config

    cfg = load_config()
    builtin = {"sensor": DEFAULT_SENSOR, "coc": "d/1500", "units": "m", "output_dir": None, "blender_python": None,
               "glass_catalogs": None}
    out = {}
    for key, default in builtin.items():
        v = getattr(cfg, key)
        given = v is not None
        v = list(v) if isinstance(v, tuple) else v
        out[key] = {"value": (str(v) if key == "output_dir" and given else v) if given else default,
                    "source": str(cfg.path) if given else "default"}
    from ._config import KEYS

    rows = [{"key": k, "value": v["value"], "source": v["source"], "meaning": KEYS[k]} for k, v in out.items()]
    return {"path": None if cfg.path is None else str(cfg.path), "exists": cfg.exists, "settings": out, "rows": rows}


def run_show(args) -> int:
    from ._output import Table, document, emit_json, print_table

    d = effective()
    if args.json:
        emit_json(document("config", d, units={}))
        return 0
    if args.csv:
        from ._output import print_csv

        print_csv(d["rows"])
        return 0
    where = d["path"] or "(none: PHYSCAM_CONFIG is empty)"
    print(f"config file: {where}" + ("" if d["exists"] else "  (not there: physcam's defaults apply)"))
    t = Table(None, ("key", "value", "from", "meaning"))
    for r in d["rows"]:
        t.add_row(r["key"], "-" if r["value"] is None else str(r["value"]), r["source"], r["meaning"])
    print_table(t)
    return 0

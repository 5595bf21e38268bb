"""Helpers shared by the CLI commands: the rules every command keeps, one place each.

A new command complies by using these (docs/cli.md, "Writing a command"):

- distances: :func:`distance` (units as said on set; a bare number is mm); a scene distance (a
  focus mark, a measured near or far limit) with ``scene=True``: a bare number then follows
  the unit system (:data:`BARE_RULE`, resolved by :func:`resolve_bare_distances` after parsing);
- a focus: :func:`focus` as the option's type (distances, ``hyperfocal``, ``infinity``) and
  :func:`resolve_focus` in the handler, which turns ``hyperfocal`` into a mark;
- printed distances: :func:`add_units_option` and :func:`units_of` with
  :func:`physcam.units.format_distance` (``--units m|ft``, default from the user config);
- a sensor: :func:`add_sensor_options` and :func:`resolve_sensor` (one default, said in a note);
- a circle of confusion: :func:`coc_value` as the type and :func:`coc_of` (config default);
- a renamed option: :func:`hidden_alias` keeps the old spelling working, unlisted;
- a command that uses its lens as a camera's: list it in :data:`CAMERA_COMMANDS` (a
  finite-conjugate design is then refused in one line when loaded, :func:`lens_use`);
- notes for people: :func:`note` (printed on stderr after the command succeeds);
- JSON, tables and CSV: :mod:`physcam.cli._output`.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import re
import sys
import threading

from ..data.default_sensor import DEFAULT_SENSOR, DEFAULT_SENSOR_LABEL
from ..errors import PhysCamError
from ..progress import FORK_LOCK, quiet_thread
from ..units import UNIT_SYSTEMS, parse_distance

# DEFAULT_SENSOR: the sensor every command uses when none is given (and the user config names none);
# one constant with the Python API's defaults (physcam.data.default_sensor).
#: ``--focus hyperfocal``: the value :func:`focus` returns for it (resolved by :func:`resolve_focus`).
HYPERFOCAL = "hyperfocal"
#: Words read as an infinite focus.
INFINITY_WORDS = ("inf", "infinity", "∞")
#: What every focus option's help ends with.
FOCUS_HELP = "units ok: 2m, 6ft, 10'6\"; or hyperfocal, infinity"


#: The one rule for a bare number given as a scene distance (a focus mark, a measured near or far limit),
#: on the command line and on ``physcam serve``'s page alike: it is read in the unit system's unit,
#: millimetres under ``m`` (the default) and feet under ``ft`` (``--units ft``, or ``units = "ft"`` in the
#: user config; a note says so). A bare number closer than the lens focuses is refused with "did you mean
#: 3m?". Lengths inside the camera (focal length, sensor, offsets) are always millimetres.
BARE_RULE = "a bare scene distance is millimetres, or feet under --units ft or units = \"ft\" in the user config"
_BARE = re.compile(r"^\s*[+-]?(?:\d+(?:\.\d*)?|\.\d+)(?:[eE][+-]?\d+)?\s*$")


class BareDistance(float):
    """A scene distance typed as a bare number: a float of its millimetres under :data:`BARE_RULE` (``unit``
    "mm" until :func:`resolve_bare_distances` reads it in feet), with the text typed (``text``)."""

    text: str
    unit: str

    def __new__(cls, mm: float, text: str, unit: str = "mm"):
        obj = super().__new__(cls, mm)
        obj.text, obj.unit = str(text).strip(), unit
        return obj

    def __reduce__(self):  # copies and pickles keep what was typed
        return (BareDistance, (float(self), self.text, self.unit))


def distance(name: str, allow_inf: bool = False, *, scene: bool = False):
    """An argparse type reading a distance with units (bare number = mm); ``scene``: a bare number follows
    :data:`BARE_RULE` (returned as a :class:`BareDistance`)."""

    def parse(text):
        v = as_argument(lambda t: parse_distance(t, name=name, allow_inf=allow_inf), text)
        return BareDistance(v, text) if scene and _BARE.match(str(text)) else v

    parse.__name__ = name
    return parse


def focal_length(name: str = "focal length"):
    """An argparse type reading a focal length (a distance with units, a bare number mm) within the library's one
    range (:func:`physcam.optics.thinlens.require_focal_length`: 1 mm to 100 m); outside it, argparse's one line."""
    read = distance(name)

    def parse(text):
        from ..optics.thinlens import require_focal_length

        return as_argument(lambda t: require_focal_length(read(t), name), text)

    parse.__name__ = name
    return parse


def resolve_bare_distances(args) -> None:
    """After parsing: every scene distance typed as a bare number (:class:`BareDistance`) read by
    :data:`BARE_RULE`: under feet (``--units ft`` or the config's ``units``) its number becomes feet, and a
    note says so; under metres it stays millimetres."""
    if args is None:
        return
    bare = [(k, v) for k, v in vars(args).items()
            if isinstance(v, BareDistance) or (isinstance(v, list) and any(isinstance(x, BareDistance) for x in v))]
    if not bare or units_of(args) != "ft":
        return

    def feet(v):
        return BareDistance(float(v.text) * 304.8, v.text, "ft") if isinstance(v, BareDistance) else v

    for k, v in bare:
        setattr(args, k, [feet(x) for x in v] if isinstance(v, list) else feet(v))
    where = "--units ft" if getattr(args, "units", None) == "ft" else 'units = "ft" in the user config'
    typed = ", ".join(f"--{k.replace('_', '-')} {x.text}" for k, v in bare
                      for x in (v if isinstance(v, list) else [v]) if isinstance(x, BareDistance))
    note(f"a bare number is feet here ({where}): {typed} read in feet; write mm or m to say otherwise")


def bare_hint(args, message: str) -> str:
    """" (did you mean 3m?)" when a command failed because a lens cannot focus that close and a scene distance
    was typed as a bare number read as millimetres (:data:`BARE_RULE`); else ""."""
    if args is None or not any(w in message for w in ("can focus", "cannot focus", "inside the focal length",
                                                      "no real image", "in front of the lens")):
        return ""
    for k, v in vars(args).items():
        for x in (v if isinstance(v, list) else [v]):
            if isinstance(x, BareDistance) and x.unit == "mm" and float(x) < 1000.0:
                return (f" (--{k.replace('_', '-')} {x.text} is {x.text} mm: a bare number is millimetres; "
                        f"did you mean {x.text}m?)")
    return ""


#: Whole-number options take at most this many characters (a 400-digit count is refused by length
#: before Python builds the integer, and no count overflows a float downstream).
WHOLE_MAX_CHARS = 19
#: The default bounds of :func:`whole`: every integer a float64 holds exactly.
WHOLE_LIMIT = 2**53


def _shown(text) -> str:
    """A refused value as an error shows it: repr, shortened past 40 characters."""
    r = repr(text)
    return r if len(r) <= 40 else f"{r[:28]}...{r[-8:]} ({len(str(text))} characters)"


def _bound(v: int) -> str:
    return "2**53" if v == WHOLE_LIMIT else "-2**53" if v == -WHOLE_LIMIT else str(v)


def as_argument(read, text):
    """``read(text)``, the library's reading of an option's text, as an argparse type: its
    :class:`~physcam.errors.PhysCamError` becomes argparse's one line (exit 2) as the command line is read."""
    try:
        return read(text)
    except PhysCamError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


def figure_file(text: str) -> str:
    """The argparse type of a figure's file name (``-o``, ``--plot``): one ending .png, .svg or .pdf
    (:func:`physcam.figures.figure_format`), else refused as the command line is read (exit 2), not after
    the command's seconds of work."""
    from ..figures import figure_format

    as_argument(figure_format, text)
    return text


def usd_file(text: str) -> str:
    """The argparse type of a USD file physcam writes: one ending .usda, .usd or .usdc in any case
    (:func:`physcam.usd_names.usd_layer_format`), refused as the command line is read (exit 2), before the
    command's work and usd-core's import."""
    from ..usd_names import usd_layer_format

    as_argument(usd_layer_format, text)
    return text


def whole(name: str, *, lo: int | None = None, hi: int | None = None):
    """An argparse type reading a whole number (``12``, ``1_000``) within ``lo``..``hi`` (default:
    the integers a float holds exactly, +-2**53). Every integer option uses it, never bare ``int``:
    ``int`` reads a 400-digit count that later overflows a float (issue 24 item 12)."""
    lo_, hi_ = (-WHOLE_LIMIT if lo is None else lo), (WHOLE_LIMIT if hi is None else hi)
    span = f"a whole number from {_bound(lo_)} to {_bound(hi_)}"

    def parse(text):
        t = str(text).strip()
        try:
            if len(t) > WHOLE_MAX_CHARS:
                raise ValueError
            v = int(t, 10)
        except ValueError:
            if t.lstrip("+-").replace("_", "").isdigit():
                raise argparse.ArgumentTypeError(f"{name} must be {span}, got {_shown(text)}") from None
            raise argparse.ArgumentTypeError(f"{name} must be {span}, got {_shown(text)}") from None
        if not lo_ <= v <= hi_:
            raise argparse.ArgumentTypeError(f"{name} must be {span}, got {_shown(text)}")
        return v

    parse.__name__ = name
    parse.physcam_whole = (lo_, hi_)  # the contract test finds integer options by this
    return parse


_ENGRAVED_STOP = re.compile(r"\s*(?:([tT])|[fF]\s*/?)\s*(\d+(?:\.\d+)?)\s*")


def _stop_hint(name: str, text) -> str:
    """What to type instead of a stop written as engraved ("T2.8", "f/2.8"), for an f-stop option."""
    m = _ENGRAVED_STOP.fullmatch(str(text)) if name in ("f-stop", "f-number", "T-stop") else None
    if m is None:
        return ""
    return (f": write the number alone, {m.group(2)}"
            + (" (a T-stop is --tstop where the command takes one; the f-stop is the geometric f-number)"
               if m.group(1) and name != "T-stop" else ""))


def _finite(name: str, text) -> float:
    """``text`` as a finite, normal float (or 0): NaN, infinities and subnormals (``1e-320``, below
    2.2e-308, where 1/x overflows and precision is lost) are refused."""
    try:
        v = float(text)
    except (ValueError, TypeError):
        raise argparse.ArgumentTypeError(f"{name} must be a number, got {_shown(text)}{_stop_hint(name, text)}") \
            from None
    if not math.isfinite(v):
        raise argparse.ArgumentTypeError(f"{name} must be a finite number, got {_shown(text)}")
    if v != 0.0 and abs(v) < sys.float_info.min:
        raise argparse.ArgumentTypeError(f"{name} is out of range: it must be 0 or at least {sys.float_info.min:.3g} "
                                         f"in size, got {_shown(text)}")
    return v


def number(name: str, *, positive: bool = False, lo: float | None = None, hi: float | None = None):
    """An argparse type reading a finite number (no subnormals: :func:`_finite`); ``positive`` requires
    > 0, ``lo``/``hi`` bound it."""

    def parse(text):
        v = _finite(name, text)
        if positive and not v > 0:
            raise argparse.ArgumentTypeError(f"{name} must be greater than 0, got {_shown(text)}")
        if (lo is not None and v < lo) or (hi is not None and v > hi):
            bound = (f"lie between {lo:g} and {hi:g}" if lo is not None and hi is not None
                     else f"be at least {lo:g}" if lo is not None else f"be at most {hi:g}")
            raise argparse.ArgumentTypeError(f"{name} must {bound}, got {_shown(text)}")
        return v

    parse.__name__ = name
    return parse


def numbers(name: str, count: int, *, positive: bool = False):
    """An argparse type reading ``count`` comma-separated finite numbers ("X,Y" or "X,Y,Z")."""
    labels = ",".join("XYZW"[:count])

    def parse(text):
        try:
            v = tuple(_finite(name, x) for x in str(text).split(","))
        except argparse.ArgumentTypeError:
            raise argparse.ArgumentTypeError(f"{name} must be {count} finite numbers {labels}, got {_shown(text)}") \
                from None
        if len(v) != count or not all(x > 0 or not positive for x in v):
            kind = "positive" if positive else "finite"
            raise argparse.ArgumentTypeError(f"{name} must be {count} {kind} numbers {labels}, got {text!r}")
        return v

    parse.__name__ = name
    return parse


def focus(name: str = "focus distance", *, allow_inf: bool = True, hyperfocal: bool = True):
    """An argparse type for a focus mark: a distance with units, ``infinity`` (``inf``) and
    ``hyperfocal`` (returned as :data:`HYPERFOCAL`, for :func:`resolve_focus`)."""

    def parse(text):
        t = str(text).strip().lower()
        if hyperfocal and t in (HYPERFOCAL, "hyper", "hyperfocal distance"):
            return HYPERFOCAL
        if t in INFINITY_WORDS:
            if not allow_inf:
                raise argparse.ArgumentTypeError(f"{name} must be finite here, got {text!r}")
            return math.inf
        try:
            v = parse_distance(text, name=name)
        except PhysCamError as exc:
            raise argparse.ArgumentTypeError(f"{exc}; or hyperfocal, infinity" if hyperfocal else str(exc)) from None
        return BareDistance(v, text) if _BARE.match(str(text)) else v  # BARE_RULE, resolved after parsing

    parse.__name__ = name
    parse.physcam_focus = {"infinity": allow_inf, "hyperfocal": hyperfocal}  # the contract test finds focus options
    return parse


def list_items(text, what: str, example: str) -> list[str]:
    """The comma-separated items of an option's ``text``, stripped; an empty list or an empty item
    (``2,,4``) is an argparse error naming ``what`` (with ``example`` of a good list)."""
    parts = [t.strip() for t in str(text).split(",")]
    if not any(parts):
        raise argparse.ArgumentTypeError(f"give {what} separated by commas, e.g. {example}")
    if not all(parts):
        raise argparse.ArgumentTypeError(f"{text!r} has an empty item: give {what} separated by single commas")
    return parts


def focus_list(name: str = "focus distances"):
    """An argparse type for comma-separated focus marks (each as :func:`focus`)."""
    one = focus(name)

    def parse(text):
        return [one(t) for t in list_items(text, name, "1m,2m,5m,hyperfocal,inf")]

    parse.__name__ = name
    parse.physcam_focus = dict(one.physcam_focus, list=True)
    return parse


def resolve_focus(value, *, lens=None, focal_length_mm=None, fstop=None, sensor=None, coc=None, args=None):
    """A focus option's value as a mark in mm from the film (``inf`` stays ``inf``).

    :data:`HYPERFOCAL` becomes the hyperfocal mark of the lens (a prescription, focused there)
    or thin lens of ``focal_length_mm`` at ``fstop`` (a lens: wide open when None) for the
    circle of confusion of ``sensor`` (default: :func:`resolve_sensor` of ``args``) and ``coc``
    (default: the user config's). A list is resolved element by element.
    """
    if isinstance(value, (list, tuple)):
        return [resolve_focus(v, lens=lens, focal_length_mm=focal_length_mm, fstop=fstop, sensor=sensor, coc=coc,
                              args=args) for v in value]
    if value != HYPERFOCAL:
        return value
    from ..errors import InputError
    from ..optics.coc import named_circle_of_confusion
    from ..optics.lens_model import ThinLens, lens_model_of

    if lens is None and focal_length_mm is None:
        raise InputError("--focus hyperfocal needs a lens or a focal length")
    model = lens_model_of(lens) if lens is not None else ThinLens(focal_length_mm)
    fstop = fstop if fstop is not None else model.wide_open()  # a lens: wide open
    if fstop is None:
        raise InputError("focus at the hyperfocal distance needs the f-stop (--fstop), and no measured near/far "
                         "limits (they solve the focus themselves)")
    if sensor is None:
        sensor = resolve_sensor(args)
    from ..optics.thinlens import require_f_number

    fstop = require_f_number("f-stop", fstop)
    c, name = named_circle_of_confusion(sensor.width_mm, sensor.height_mm, coc if coc is not None else coc_of(args))
    mark = model.hyperfocal_mark(fstop, c)  # the lens model keeps its focus there: the camera asks it again
    from ..units import format_distance

    note(f"hyperfocal focus: {format_distance(mark, units_of(args))} from the film at f/{fstop:.3g}, "
         f"CoC {c:.4g} mm ({name}, {sensor.name})")
    return mark


def camera_from_args(args, lens, *, aperture=None):
    """The one camera of a command (issue 43): ``lens`` at ``--focus`` (``hyperfocal`` resolved for
    ``--fstop`` and the sensor), its iris at ``--fstop`` (None: as its file stops it) with the iris shape
    ``aperture``, on the command's sensor (:func:`resolve_sensor`: ``--sensor`` or the pair, else the
    default). ``args.sensor_width``/``sensor_height``/``sensor_name`` and ``args.focus`` are set to what
    the camera holds."""
    from ..optics.state import camera_state

    sensor = resolve_sensor(args)
    args.sensor_width, args.sensor_height, args.sensor_name = sensor.width_mm, sensor.height_mm, sensor.name
    fstop = getattr(args, "fstop", None)
    args.focus = resolve_focus(getattr(args, "focus", None), lens=lens, fstop=fstop, sensor=sensor, args=args)
    return camera_state(lens, focus_mm=args.focus, fstop=fstop, sensor=sensor, aperture=aperture)


def coc_value(text):
    """A --coc value (:func:`physcam.optics.coc.parse_coc`): a convention name stays text, a length
    becomes a float in mm; a malformed length is argparse's error."""
    from ..optics.coc import parse_coc

    return as_argument(parse_coc, text)


def coc_of(args):
    """The circle of confusion a command was given (--coc), else the user config's, else None."""
    v = getattr(args, "coc", None)
    if v is not None:
        return v
    from ._config import load_config

    return load_config().coc


# ---- units -----------------------------------------------------------------------------------
def add_units_option(p) -> None:
    """``--units m|ft``: the unit system distances are printed in (tables, CSV, plots)."""
    from ..units import unit_system

    p.add_argument("--units", type=unit_system, choices=UNIT_SYSTEMS, default=None,
                   help="print distances in metres (m, metres, meters) or feet and inches (ft, feet, foot: to 1/8 "
                        "inch below 10 ft); "
                        "default m, or `units` in the user config (physcam config show); JSON stays in mm")


def units_of(args) -> str:
    """The unit system for printed distances: --units, else the user config's, else metres."""
    u = getattr(args, "units", None)
    if u is not None:
        return u
    from ._config import load_config

    return load_config().units or "m"


# ---- sensors ---------------------------------------------------------------------------------
def add_sensor_options(p, *, what: str = "") -> None:
    """--sensor NAME or --sensor-width/--sensor-height: the one set of sensor options."""
    g = p.add_argument_group("sensor") if what == "" else p
    g.add_argument("--sensor", metavar="NAME",
                   help=f'sensor or gate name, e.g. "ALEXA 35" or S35 (see `physcam sensors`); default {DEFAULT_SENSOR_LABEL}, '
                        "or `sensor` in the user config")
    g.add_argument("--sensor-width", type=distance("sensor width"), default=None, metavar="MM",
                   help="a custom sensor's width, with --sensor-height (instead of --sensor)")
    g.add_argument("--sensor-height", type=distance("sensor height"), default=None, metavar="MM",
                   help="a custom sensor's height, with --sensor-width")


def resolve_sensor(args, default: str | None = None, *, quiet: bool = False):
    """The sensor a command was given: --sensor NAME, or --sensor-width with --sensor-height (a
    bounded custom sensor), else the default (the user config's ``sensor``, else
    :data:`DEFAULT_SENSOR`), which a note on stderr names (unless ``quiet``: the command says it
    itself). Sets ``args.sensor_defaulted``."""
    from ..errors import InputError
    from ..optics.sensors import camera_name_note, custom_sensor, find_sensor

    name = getattr(args, "sensor", None)
    sw, sh = getattr(args, "sensor_width", None), getattr(args, "sensor_height", None)
    custom = sw is not None or sh is not None
    if name is not None and custom:
        raise InputError("give either --sensor NAME or --sensor-width/--sensor-height, not both")
    if args is not None:
        args.sensor_defaulted = False
    if name is not None:
        s = find_sensor(name)
        said = camera_name_note(name)  # a bare camera name ("ALEXA 35") is its full sensor: say so
        if args is not None:
            args.sensor_note = said
        if said and not quiet:
            note(said)
        return s
    if custom:
        if sw is None or sh is None:
            raise InputError("give both --sensor-width and --sensor-height")
        return custom_sensor(sw, sh)
    from ._config import load_config

    cfg = load_config()
    chosen = default or cfg.sensor or DEFAULT_SENSOR
    s = find_sensor(chosen)
    where = "the user config's sensor" if (default is None and cfg.sensor) else "the default"
    if args is not None:
        args.sensor_defaulted = True
        args.sensor_default_source = where
    how = "give --sensor to change it" if hasattr(args, "sensor") else "`sensor` in the user config changes it"
    if not quiet:
        note(f"no --sensor given: {s.name}, {s.width_mm:g} x {s.height_mm:g} mm ({where}; {how})")
    return s


# ---- option names ----------------------------------------------------------------------------
def hidden_alias(p, flag: str, dest: str, **kwargs) -> None:
    """Keep an old option spelling working without listing it in --help (scripts that use it
    keep running); ``kwargs`` as the option it stands for (type, choices, action...)."""
    p.add_argument(flag, dest=dest, default=argparse.SUPPRESS, help=argparse.SUPPRESS, **kwargs)


# ---- the lens: one grammar ---------------------------------------------------------------------
#: A command's lens, everywhere: ``--lens NAME_OR_FILE`` (repeated for commands that take several).
LENS_HELP = "bundled lens name (see `physcam lenses`) or a lens file"
#: The release that drops the positional lens (docs/CHANGELOG.md).
POSITIONAL_LENS_REMOVED_IN = "0.3"


def add_lens_argument(p, *, dest: str = "lens", many: bool = False, metavar: str = "NAME_OR_FILE",
                      help: str = LENS_HELP) -> None:
    """``--lens`` for a command that needs a lens (``many``: one or more, ``--lens A --lens B``). The old
    positional spelling keeps working for one release, with a note (:func:`merge_lens_argument`)."""
    p.add_argument("--lens", dest=dest, action="append" if many else "store", default=None, metavar=metavar,
                   help=help + (" (repeat for several)" if many else "") + "; required")
    p.add_argument("_lens_positional", nargs="*", default=[], help=argparse.SUPPRESS, metavar="")
    p.add_argument("--glass-catalog", dest="glass_catalog", action="append", default=None, metavar="FILE.agf",
                   help="a Zemax .agf glass catalogue searched after the lens file's own (repeat for several; "
                        "adds to the config's glass_catalogs)")
    p.add_argument("--strict-glass", dest="strict_glass", action="store_true",
                   help="a Zemax file's glass must be in the catalogues its GCAT line lists (or their makers' legacy "
                        "glasses), as OpticStudio requires; by default another bundled catalogue holding the same "
                        "name is used, with a warning")
    p.set_defaults(_lens_dest=dest, _lens_many=many)


#: Commands that use their lens as a camera's (focus marks from the film, depth of field, a camera
#: to render, record or export), and what for: a finite-conjugate design (a relay, a microscope
#: objective) is refused when they load it (:func:`physcam.lens.library.require_camera_lens`).
CAMERA_COMMANDS = {
    "report": "a camera lens report", "dof-table": "a depth-of-field table", "usd": "a USD camera",
    "export": "a camera export", "live": "a tracked camera", "metadata": "a per-frame lens report",
    "compare": "a camera lens comparison", "characterize": "a camera lens characterization",
    "distortion": "distortion against the film (ST-maps, fitted camera models)",
}


def add_lenient(parser) -> None:
    """The --lenient flag of every command that takes a lens."""
    parser.add_argument("--lenient", action="store_true",
                        help="load a lens file that is not buildable as written with its impossible parts repaired as "
                             "`physcam lens fix` would (one warning line per repair; results marked as repaired)")


def mark_repaired(d, lens):
    """JSON output ``d`` with ``lens_repaired`` and ``lens_repairs`` when ``lens`` was repaired on load."""
    from ..lens.library import repairs_of

    reps = repairs_of(lens)
    if reps and isinstance(d, dict):
        d = dict(d)
        d["lens_repaired"] = True
        d["lens_repairs"] = reps
    return d


def lens_use(args):
    """The context the command's handler runs in: :func:`physcam.lens.library.camera_use` for a
    :data:`CAMERA_COMMANDS` command, so every lens it loads must be a camera lens; else none."""
    import contextlib

    what = CAMERA_COMMANDS.get(getattr(args, "command", None))
    if what is None or not getattr(args, getattr(args, "_lens_dest", None) or "lens", None):
        return contextlib.nullcontext()  # no lens named: nothing to refuse (and no lens code at start-up)
    from ..lens.library import camera_use

    return camera_use(what)


def use_glass_catalogs(args) -> list[str]:
    """Make the config's ``glass_catalogs`` and the run's ``--glass-catalog`` files the user glass
    catalogues, in that order, and ``--strict-glass`` the rule for lens files' glasses (every run
    starts with none left over); their names."""
    from ._config import load_config

    paths = list(load_config().glass_catalogs or ()) + list(getattr(args, "glass_catalog", None) or ())
    strict = bool(getattr(args, "strict_glass", False))
    if not paths and not strict and "physcam.lens.catalog" not in sys.modules:
        return []  # nothing to add and nothing left over: the report starts without the glass code
    from ..lens.catalog import use_catalog_files

    return use_catalog_files(paths, strict=strict)


def merge_lens_argument(args, parser) -> None:
    """After parsing: a positional lens (the old spelling) becomes ``--lens`` with a note; a command that
    needs a lens and got none is a usage error naming ``--lens``."""
    dest = getattr(args, "_lens_dest", None)
    if dest is None:
        return
    old = list(getattr(args, "_lens_positional", []) or [])
    given = getattr(args, dest)
    many = getattr(args, "_lens_many", False)
    if old:
        if given:
            parser.error("give the lens once, with --lens NAME_OR_FILE")
        if len(old) > 1 and not many:
            parser.error(f"unrecognized arguments: {' '.join(old[1:])}")
        setattr(args, dest, old if many else old[0])
        note(f"a lens named without --lens is deprecated: write --lens {old[0]} "
             f"(physcam {POSITIONAL_LENS_REMOVED_IN} will refuse the old form)")
    elif not given:
        parser.error("give the lens: --lens NAME_OR_FILE (a bundled name from `physcam lenses`, or a lens file)")


# ---- a folder of outputs written as a whole --------------------------------------------------
#: ``--force`` of a command whose ``-o DIR`` is written whole (:func:`output_folder`).
FOLDER_FORCE_HELP = "replace the folder if physcam wrote it whole (it has a physcam-manifest.json) or it is empty"

def output_folder(folder, *, force: bool, command: str):
    """A command's output folder written as a whole (:func:`physcam.io.staged_folder`): a context
    yielding the private temporary folder to fill; on success it is put at ``folder`` in one rename
    with its ``physcam-manifest.json`` (``about``: the command and physcam's version). Without
    ``force`` an existing ``folder`` is refused; with it, only one physcam wrote whole (or an empty one)
    is replaced, never a folder of the user's own files. Checked at once, before any work."""
    from .. import __version__
    from ..io import staged_folder

    return staged_folder(folder, force=force, about={"command": f"physcam {command}", "physcam_version": __version__})


def relocated(paths, tmp, folder) -> list:
    """``paths`` written under the temporary folder ``tmp``, as they are named once it is published
    at ``folder`` (same types: str stays str)."""
    from pathlib import Path

    out = []
    for p in paths:
        q = Path(folder) / Path(p).relative_to(tmp)
        out.append(str(q) if isinstance(p, str) else q)
    return out


# ---- notes -----------------------------------------------------------------------------------
_NOTES: list[str] = []


def note(message: str) -> None:
    """A remark for people (a default taken, a range clamped): printed on stderr as
    ``physcam: note: ...`` once the command has succeeded; dropped when it fails."""
    if message not in _NOTES:
        _NOTES.append(message)


def take_notes() -> list[str]:
    """The notes so far, emptying the list."""
    out = list(_NOTES)
    _NOTES.clear()
    return out


def print_json(obj) -> None:
    """``obj`` as JSON on stdout, whole or not at all (serialised before the first byte is written)."""
    sys.stdout.write(json.dumps(obj, indent=2, allow_nan=False) + "\n")


def console(stderr: bool = False):
    """A rich Console with markup and highlighting off (user text is never interpreted)."""
    from rich.console import Console

    return Console(stderr=stderr, markup=False, highlight=False, emoji=False)


#: The rich Progress on screen (one at a time: rich allows one live display), shared by the bars
#: that nest (a compile inside a chart's bar, a command's bar over the slow-command spinner), and
#: whether this run shows progress at all (main(): not with --json or --csv).
_LIVE: list = []
_LIVE_LOCK = threading.RLock()
SHOW_PROGRESS = True
#: A command still running after this many seconds gets a spinner with its elapsed time, unless a
#: bar of its own is up (``PHYSCAM_PROGRESS_AFTER`` overrides it; tests use 0).
PROGRESS_AFTER_S = 2.0


def _stdout_is_terminal() -> bool:
    """Whether standard output shares the terminal the bars are drawn on: its lines then go through
    rich (above the bar); to a pipe or file they go as they are."""
    try:
        return sys.stdout.isatty()
    except (AttributeError, ValueError):
        return False


class progress_bar:
    """A rich progress bar on stderr for long jobs, shown only to a person at a terminal.

    Use as a context manager; the object is a ``progress(done, total)`` callback. Bars opened while
    another is up join its display as a line of their own.
    """

    def __init__(self, description: str, enabled: bool = True):
        self.enabled = enabled and SHOW_PROGRESS and sys.stderr.isatty()
        self.description = description
        self._progress = None
        self._task = None
        self._own = False

    def __enter__(self):
        if self.enabled:
            with _LIVE_LOCK:
                return self._enter()
        return self

    def _enter(self):
        if _LIVE:
            self._progress = _LIVE[-1]
        else:
            from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn, TimeRemainingColumn

            self._progress = Progress(TextColumn("{task.description}"), BarColumn(),
                                      TextColumn("{task.percentage:>3.0f}%"), TimeRemainingColumn(),
                                      TimeElapsedColumn(), console=console(stderr=True), transient=True,
                                      redirect_stdout=_stdout_is_terminal())
            self._progress.__enter__()
            self._own = True
            _LIVE.append(self._progress)
        self._task = self._progress.add_task(self.description, total=None)
        return self

    def __call__(self, done, total):
        if self._progress is not None:
            self._progress.update(self._task, completed=done, total=total)

    def __exit__(self, *exc):
        with _LIVE_LOCK:
            self._exit(*exc)
        return False

    def _exit(self, *exc):
        if self._progress is not None:
            self._progress.remove_task(self._task)
            if self._own:
                _LIVE.remove(self._progress)
                self._progress.__exit__(*exc)
            self._progress = None


class _CompileProgress:
    """The JIT compile reporter (``physcam.trace.kernels.set_compile_reporter``): "compiling the ray
    tracer (once)" as a bar while numba compiles a kernel variant."""

    def __init__(self):
        self._bar = None

    def __call__(self, done, total):
        if self._bar is None and done < total:
            self._bar = progress_bar("compiling the ray tracer (once)").__enter__()
        if self._bar is not None:
            self._bar(done, total)
            if done >= total:
                self._bar.__exit__(None, None, None)
                self._bar = None


class slow_command_progress:
    """A spinner with the elapsed time for a command still running after :data:`PROGRESS_AFTER_S`
    (started by a timer thread, stopped at the end; nothing when a bar of the command's own is up,
    when stderr is not a terminal, or with --json/--csv)."""

    def __init__(self, name: str):
        self.name = name
        self._timer = None
        self._bar = None
        self._lock = threading.Lock()
        self._done = False

    def _start(self):
        with FORK_LOCK, self._lock:  # (never while this process forks workers: physcam.progress.FORK_LOCK)
            if self._done or _LIVE:
                return
            self._bar = progress_bar(f"physcam {self.name}").__enter__()

    def __enter__(self):
        if SHOW_PROGRESS and sys.stderr.isatty():
            after = os.environ.get("PHYSCAM_PROGRESS_AFTER")
            try:
                delay = PROGRESS_AFTER_S if after is None else max(0.0, float(after))
            except ValueError:
                delay = PROGRESS_AFTER_S
            # quiet: a build that forks workers may fork while it waits; it draws only outside the fork
            self._timer = quiet_thread(threading.Timer(delay, self._start))
            self._timer.daemon = True
            self._timer.start()
        return self

    def __exit__(self, *exc):
        if self._timer is not None:
            self._timer.cancel()
        with self._lock:
            self._done = True
            if self._bar is not None:
                self._bar.__exit__(*exc)
                self._bar = None
        return False

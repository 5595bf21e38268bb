"""The ``physcam`` command line.

Each subcommand lives in its own module of this package and exposes
``register(subparsers)``; :func:`main` discovers them, so adding a command is
adding a module. Handlers import heavy libraries (numpy, matplotlib, USD) inside
their bodies so ``physcam --help`` and ``physcam report`` start fast.

Shared rules (sensors, focus, units, notes, JSON documents, tables, CSV, the user config) live
in :mod:`physcam.cli._common`, :mod:`physcam.cli._output` and :mod:`physcam.cli._config`.

Errors: a :class:`~physcam.errors.PhysCamError` prints one line on stderr and exits 2;
a failing standard output (disk full) prints one line and exits 2; a path the system refuses (a
name too long, a folder where a file was wanted, no permission) prints one line naming it
(shortened) and exits 2; input nested too deeply to read (RecursionError) prints one line and
exits 2; a closed pipe exits 0; anything else is a bug and shows a traceback (exit 1).

The ``physcam`` program is :func:`run`: :func:`main`, then the exit. Once numba's compiler has
been initialised (a command that traced enough rays to load the JIT kernel), the interpreter's
module teardown costs 80-100 ms on this machine (docs/performance.md), a sixth of such a
command's run, and once matplotlib is loaded (a figure command) 9-13 ms, a fiftieth of a cold
``lens diagram``; :func:`run` then exits the process directly, after the exit handlers have run,
unreachable objects have been finalised and the output streams flushed.
"""

from __future__ import annotations

import argparse
import importlib
import os
import re
import sys

from .. import __version__
from ..errors import PhysCamError, PhysCamWarning

__all__ = ["main", "build_parser"]


#: Command modules in --help order; modules not listed follow alphabetically.
COMMAND_ORDER = ("report", "dof_table", "sensors", "lens", "trace", "analyze", "distortion", "compare", "usd", "demo",
                 "config")

#: Option destinations that name files a command writes: a relative path there goes into the user
#: config's ``output_dir`` when it sets one. A command whose positional argument is an output file
#: lists it with ``parser.set_defaults(output_args=("file",))``; one whose output is a folder written
#: whole (``physcam.io.staged_folder``) names that destination in ``output_folders`` too.
OUTPUT_DESTS = ("output", "plot", "stmap", "out")
#: Commands that check their own outputs against their inputs (their handlers call
#: ``physcam.io.refuse_inputs_as_outputs`` themselves): the generic check leaves them alone.
OWN_OUTPUT_CHECK = ("calibrate", "defocus", "defocus-kernels")
#: Destinations that select what runs (subcommand names, kinds), never a file read.
_NOT_PATHS = ("command", "handler", "kind", "output_args", "output_folders")


#: (command, a word people type after it) -> where that lives: said after argparse's "invalid choice"
_ELSEWHERE = {("export", "usd"): "USD cameras are written by `physcam usd write` (docs/usd.md)"}


#: A word that starts with a minus and a digit is a value, never an option (physcam has no option
#: named -<digit>): argparse's own rule takes only plain negative numbers, so `--rotate -5,30,0` (a
#: camera tilted down), `--shift-x -1.5e-1` or `--focus -3m` were "expected one argument".
_NEGATIVE_VALUE = re.compile(r"-\.?\d.*", re.DOTALL)


class _Parser(argparse.ArgumentParser):
    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self._negative_number_matcher = _NEGATIVE_VALUE

    def error(self, message):  # usage errors: one line, exit 2 (argparse's own code)
        for (command, word), where in _ELSEWHERE.items():
            if self.prog.endswith(f" {command}") and f"invalid choice: '{word}'" in message:
                message += f"; {where}"
        self.exit(2, f"physcam: error: {message}\n")

    def _get_formatter(self):
        """argparse's formatter at the width argparse gives it, measured without importing shutil (its
        formatter imports it for ``get_terminal_size``: 4 ms of every command's start, issue 43)."""
        return self.formatter_class(prog=self.prog, width=_terminal_columns() - 2)


def _terminal_columns() -> int:
    """``shutil.get_terminal_size().columns``: $COLUMNS when a positive number, else the terminal's, else 80."""
    try:
        columns = int(os.environ["COLUMNS"])
    except (KeyError, ValueError):
        columns = 0
    if columns <= 0:
        try:
            columns = os.get_terminal_size(sys.__stdout__.fileno()).columns or 80
        except (AttributeError, ValueError, OSError):
            columns = 80
    return columns


class _StoreOnce(argparse._StoreAction):
    """A single-value option: given twice, it is a usage error naming it (argparse would keep the last
    silently: `physcam mtf --field 0 --field 14` reported 14 degrees alone)."""

    def __call__(self, parser, namespace, values, option_string=None):
        seen = getattr(namespace, "_options_given", None)
        if seen is None:
            seen = set()
            setattr(namespace, "_options_given", seen)
        if self.dest in seen:
            parser.error(f"{option_string} was given twice: give it once (options that take several values "
                         "say so in --help)")
        seen.add(self.dest)
        super().__call__(parser, namespace, values, option_string)


def _single_value_options_once(parser) -> None:
    """Make every single-value option of ``parser`` and its subcommands a :class:`_StoreOnce`."""
    for action in parser._actions:
        if type(action) is argparse._StoreAction and action.option_strings:
            action.__class__ = _StoreOnce
        elif isinstance(action, argparse._SubParsersAction):
            for sub in dict.values(action._name_parser_map):
                _single_value_options_once(sub)


#: Each command and the module that registers it: a run of one command builds only its parser (the
#: start-up goal, docs/performance.md); ``physcam --help`` and anything else build them all.
#: tests/cli/test_cli_contract.py checks this table against what the modules register.
COMMAND_MODULES = {
    "report": "report", "dof-table": "dof_table", "sensors": "sensors", "lenses": "lens", "lens": "lens",
    "spot": "trace", "bokeh": "trace", "illumination": "analyze", "colour": "analyze", "color": "analyze",
    "breathing-real": "analyze", "ghosts": "analyze", "distortion": "distortion", "compare": "compare",
    "usd": "usd", "demo": "demo", "config": "config", "calibrate": "calibrate", "characterize": "characterize",
    "defocus": "defocus", "defocus-kernels": "defocus", "export": "export", "live": "live",
    "metadata": "metadata", "microlens": "microlens", "mtf": "mtf", "psf": "psf", "serve": "serve",
    "exposure": "exposure", "hyperfocal": "hyperfocal", "diopter": "diopter",
    "farm": "farm", "farm-task": "farm",
}


def build_parser(argv: list[str] | None = None) -> argparse.ArgumentParser:
    """physcam's parser: every command's, or (``argv`` naming a command first) only that command's."""
    parser = _Parser(
        prog="physcam",
        description="Physical cameras for film and VFX: on-set lens reports, real lens prescriptions, "
        "real-ray analyses and USD cameras.",
        epilog="Run `physcam COMMAND --help` for a command's options; `physcam demo` for a tour.",
    )
    parser.add_argument("--version", action="version", version=f"physcam {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    first = argv[0] if argv else None
    if first in COMMAND_MODULES:
        names = [COMMAND_MODULES[first]]
    else:
        import pkgutil  # only for the whole list (a command named first loads its own module alone)

        names = [m.name for m in pkgutil.iter_modules(__path__) if not m.name.startswith("_")]
    # --help lists commands in the order people use them: on set, lenses, rays, USD, the demo
    order = {name: i for i, name in enumerate(COMMAND_ORDER)}
    for name in sorted(names, key=lambda n: (order.get(n, len(order)), n)):
        module = importlib.import_module(f"{__name__}.{name}")
        register = getattr(module, "register", None)
        if register is not None:
            register(sub)
    _single_value_options_once(parser)
    return parser


def _silence_stdout() -> None:
    """Point stdout at /dev/null so the interpreter's final flush cannot fail a second time."""
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
    except (OSError, ValueError, AttributeError):
        pass


def _show_warning(message, category, filename, lineno, file=None, line=None):
    """physcam's warnings as one line for people: ``physcam: warning: ...`` on stderr."""
    import warnings

    if issubclass(category, PhysCamWarning):
        print(f"physcam: warning: {message}", file=sys.stderr)
    else:
        sys.stderr.write(warnings.formatwarning(message, category, filename, lineno, line))


def _into_output_dir(args) -> None:
    """Relative output paths go into the user config's ``output_dir`` (when it sets one)."""
    from ._config import load_config

    folder = load_config().output_dir
    if folder is None:
        return
    for dest in OUTPUT_DESTS + tuple(getattr(args, "output_args", ())):
        v = getattr(args, dest, None)
        if isinstance(v, str) and v and not os.path.isabs(v):
            setattr(args, dest, str(folder / v))


def _refuse_outputs_that_are_inputs(args) -> None:
    """No output may overwrite an input (docs/cli.md, "Hostile input"): every other argument that
    names an existing file or folder is an input to :func:`physcam.io.refuse_inputs_as_outputs`. A command
    writing nothing has nothing to check (and does not import physcam.io: 9 ms of a report's start-up)."""
    if getattr(args, "command", None) in OWN_OUTPUT_CHECK:
        return
    outs = set(OUTPUT_DESTS) | set(getattr(args, "output_args", ()))
    whole = set(getattr(args, "output_folders", ()))
    files, folders, inputs = [], [], []
    for dest, value in vars(args).items():
        if dest in _NOT_PATHS or dest.endswith("_command") or dest.startswith("_"):
            continue
        paths = [v for v in (value if isinstance(value, (list, tuple)) else [value]) if isinstance(v, (str, os.PathLike))]
        (folders if dest in whole else files if dest in outs else inputs).extend(paths)
    if not any(files) and not any(folders):
        return
    from ..io import refuse_inputs_as_outputs

    refuse_inputs_as_outputs(inputs, files, folders=folders)


def _progress(args):
    """Progress for people at a terminal (none with --json or --csv): the JIT compile's bar
    ("compiling the ray tracer (once)") and a spinner for a command still running after 2 s."""
    from . import _common
    from ..progress import set_reporter

    _common.SHOW_PROGRESS = not (getattr(args, "json", False) or getattr(args, "csv", False))
    set_reporter("compile", _common._CompileProgress() if _common.SHOW_PROGRESS else None)
    sub = next((v for k, v in vars(args).items() if k.endswith("_command") and isinstance(v, str)), None)
    name = " ".join(v for v in (getattr(args, "command", None), sub) if isinstance(v, str))
    return _common.slow_command_progress(name or "working")


def main(argv: list[str] | None = None) -> int:
    """Run the command line; returns the exit status (0 done, 2 refused input or unwritable output)."""
    import warnings

    from ._common import take_notes

    warnings.showwarning = _show_warning
    take_notes()  # a fresh list for this run (tests call main() repeatedly in one process)
    argv = list(sys.argv[1:] if argv is None else argv)
    parser = build_parser(argv)
    if len(argv) > 1 and argv[0] == "compare" and argv[1].startswith("-") and argv[1] not in ("-h", "--help"):
        argv.insert(1, "lenses")  # `physcam compare --lens A --lens B` is `compare lenses ...` (as `compare A B`)
    try:
        args = parser.parse_args(argv)
        from ._common import merge_lens_argument

        merge_lens_argument(args, parser)
    except SystemExit as exc:  # --help, --version, usage errors: argparse has printed its line
        return exc.code if isinstance(exc.code, int) else 2
    if not getattr(args, "handler", None):
        parser.print_help()
        return 0
    try:
        from ._common import resolve_bare_distances

        resolve_bare_distances(args)  # a bare scene distance in the unit system's unit (BARE_RULE)
        _into_output_dir(args)
        _refuse_outputs_that_are_inputs(args)
        from ._common import lens_use, use_glass_catalogs

        use_glass_catalogs(args)
        with lens_use(args), _progress(args):  # a camera command refuses a finite-conjugate lens
            rc = int(args.handler(args) or 0)
        sys.stdout.flush()  # a full disk or closed pipe shows here, inside the error handling
        for n in take_notes():  # defaults taken, ranges clamped: said once the command has worked
            print(f"physcam: note: {n}", file=sys.stderr)
        return rc
    except PhysCamError as exc:
        from ._common import bare_hint

        msg = str(exc).splitlines()[0] if str(exc) else exc.__class__.__name__
        print(f"physcam: error: {msg}{bare_hint(args, msg)}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("physcam: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:  # `physcam lenses | head`: the reader has gone, nothing is wrong
        _silence_stdout()
        return 0
    except RecursionError:
        print("physcam: error: the input is nested too deeply to read (a file or value inside a file)",
              file=sys.stderr)
        return 2
    except OSError as exc:
        import errno

        if getattr(exc, "filename", None) is not None:  # a path the system refused
            print(f"physcam: error: {_refused_path(exc)}", file=sys.stderr)
            return 2
        output_errors = {errno.ENOSPC, errno.EIO, errno.EDQUOT, errno.EFBIG}
        if exc.errno not in output_errors:
            raise
        # the output stream itself failed (e.g. `physcam lenses > /dev/full`)
        _silence_stdout()
        print(f"physcam: error: cannot write the output: {exc.strerror or exc}", file=sys.stderr)
        return 2


#: Longest file name shown whole in an error line; longer ones are shortened (start ... end).
SHOWN_NAME_CHARS = 80


def short_name(name) -> str:
    """``name`` for an error line: whole up to :data:`SHOWN_NAME_CHARS`, else its start and end with
    the count of characters left out (a 300-character path stays readable on one line)."""
    text = os.fsdecode(name) if isinstance(name, (bytes, os.PathLike)) else str(name)
    text = text.encode("utf-8", "backslashreplace").decode("utf-8")  # undecodable bytes shown, not raised
    if len(text) <= SHOWN_NAME_CHARS:
        return text
    head, tail = SHOWN_NAME_CHARS // 2, SHOWN_NAME_CHARS // 4
    return f"{text[:head]}...{text[-tail:]} ({len(text)} characters)"


def _refused_path(exc: OSError) -> str:
    """One line for an OSError about a path: which path, and the system's reason."""
    import errno

    why = exc.strerror or exc.__class__.__name__
    if exc.errno == errno.ENAMETOOLONG:
        why += " (a file name is at most 255 bytes, a path 4096)"
    return f"cannot use {short_name(exc.filename)}: {why}"


def run() -> None:
    """The ``physcam`` program: :func:`main`, then exit with its status (module notes). It ends the
    process: from Python, call :func:`main` instead."""
    from .. import _program

    _program.start()  # RUNNING (matplotlib without its docstring tables and 3-D toolkit: figures._lean_import), gc
    # numpy's BLAS on one thread unless the user says otherwise (before numpy loads): the program's linear
    # algebra is small (a Zernike fit of a few thousand pupil samples), where OpenBLAS's second thread
    # spins and doubles the CPU time (`mtf --field 0`: 0.85 -> 0.5 s, the same output; docs/performance.md)
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
    code = main()
    if "numba" in sys.modules or "matplotlib" in sys.modules:
        _exit_without_teardown(code)
    _program.finish()
    sys.exit(code)


def _exit_without_teardown(code: int) -> None:
    """Run the exit handlers, finalise what is unreachable, flush stdout and stderr, then end the
    process without the interpreter's module teardown (what ``sys.exit`` does, less that teardown)."""
    import atexit
    import gc

    run_exitfuncs = getattr(atexit, "_run_exitfuncs", None)
    if run_exitfuncs is None:  # pragma: no cover - another Python implementation: the normal exit
        sys.exit(code)
    run_exitfuncs()
    gc.collect()  # closes (and so flushes) file objects nothing refers to any more
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except (OSError, ValueError):  # a closed pipe or stream: nothing more can be said
            pass
    os._exit(code)


if __name__ == "__main__":  # pragma: no cover
    run()

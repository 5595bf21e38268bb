"""The ``physcam`` command line.

Each subcommand lives in its own module of this package and exposes
``register(subparsers)``; :func:`main` discovers them, so adding a command is
adding a module. Handlers import heavy libraries (numpy, matplotlib, USD) inside
their bodies so ``physcam --help`` and ``physcam report`` start fast.

Errors: a :class:`~physcam.errors.PhysCamError` prints one line on stderr and exits 2;
a failing standard output (disk full) prints one line and exits 2; a closed pipe exits 0;
anything else is a bug and shows a traceback (exit 1).
"""

from __future__ import annotations

import argparse
import importlib
import os
import pkgutil
import sys

from .. import __version__
from ..errors import PhysCamError, PhysCamWarning

__all__ = ["main", "build_parser"]


#: Command modules in --help order; modules not listed follow alphabetically.
COMMAND_ORDER = ("report", "sensors", "lens", "trace", "analyze", "distortion", "usd", "demo")


class _Parser(argparse.ArgumentParser):
    def error(self, message):  # usage errors: one line, exit 2 (argparse's own code)
        self.exit(2, f"physcam: error: {message}\n")


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(
        prog="physcam",
        description="Physical cameras for film and VFX: on-set lens reports, real lens prescriptions, "
        "real-ray analyses and USD cameras.",
        epilog="Run `physcam COMMAND --help` for a command's options; `physcam demo` for a tour.",
    )
    parser.add_argument("--version", action="version", version=f"physcam {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    names = [m.name for m in pkgutil.iter_modules(__path__) if not m.name.startswith("_")]
    # --help lists commands in the order people use them: on set, lenses, rays, USD, the demo
    order = {name: i for i, name in enumerate(COMMAND_ORDER)}
    for name in sorted(names, key=lambda n: (order.get(n, len(order)), n)):
        module = importlib.import_module(f"{__name__}.{name}")
        register = getattr(module, "register", None)
        if register is not None:
            register(sub)
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


def main(argv: list[str] | None = None) -> int:
    """Run the command line; returns the exit status (0 done, 2 refused input or unwritable output)."""
    import warnings

    warnings.showwarning = _show_warning
    parser = build_parser()
    try:
        args = parser.parse_args(argv)
    except SystemExit as exc:  # --help, --version, usage errors: argparse has printed its line
        return exc.code if isinstance(exc.code, int) else 2
    if not getattr(args, "handler", None):
        parser.print_help()
        return 0
    try:
        rc = int(args.handler(args) or 0)
        sys.stdout.flush()  # a full disk or closed pipe shows here, inside the error handling
        return rc
    except PhysCamError as exc:
        msg = str(exc).splitlines()[0] if str(exc) else exc.__class__.__name__
        print(f"physcam: error: {msg}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("physcam: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:  # `physcam lenses | head`: the reader has gone, nothing is wrong
        _silence_stdout()
        return 0
    except OSError as exc:
        import errno

        output_errors = {errno.ENOSPC, errno.EIO, errno.EDQUOT, errno.EFBIG}
        if exc.errno not in output_errors or getattr(exc, "filename", None) is not None:
            raise
        # the output stream itself failed (e.g. `physcam lenses > /dev/full`)
        _silence_stdout()
        print(f"physcam: error: cannot write the output: {exc.strerror or exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())

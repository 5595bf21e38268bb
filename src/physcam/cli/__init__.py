"""The ``physcam`` command line.

Each subcommand lives in its own module of this package and exposes
``register(subparsers)``; :func:`main` discovers them, so adding a command is
adding a module. Handlers import heavy libraries (numpy, matplotlib, USD) inside
their bodies so ``physcam --help`` and ``physcam report`` start fast.

Errors: a :class:`~physcam.errors.PhysCamError` prints one line on stderr and exits 2;
anything else is a bug and shows a traceback (exit 1).
"""

from __future__ import annotations

import argparse
import importlib
import pkgutil
import sys

from .. import __version__
from ..errors import PhysCamError

__all__ = ["main", "build_parser"]


#: Command modules in --help order; modules not listed follow alphabetically.
COMMAND_ORDER = ("report", "sensors", "lens", "trace", "analyze", "usd", "demo")


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


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    if not getattr(args, "handler", None):
        parser.print_help()
        return 0
    try:
        return int(args.handler(args) or 0)
    except PhysCamError as exc:
        msg = str(exc).splitlines()[0] if str(exc) else exc.__class__.__name__
        print(f"physcam: error: {msg}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("physcam: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:
        return 0


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())

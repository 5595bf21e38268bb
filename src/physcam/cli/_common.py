"""Helpers shared by the CLI commands: unit parsing types, JSON and table output."""

from __future__ import annotations

import argparse
import json
import math
import sys

from ..errors import PhysCamError
from ..units import parse_distance


def distance(name: str, allow_inf: bool = False):
    """An argparse type reading a distance with units (bare number = mm)."""

    def parse(text):
        try:
            return parse_distance(text, name=name, allow_inf=allow_inf)
        except PhysCamError as exc:
            raise argparse.ArgumentTypeError(str(exc)) from None

    parse.__name__ = name
    return parse


def number(name: str, *, positive: bool = False, lo: float | None = None, hi: float | None = None):
    """An argparse type reading a finite number; ``positive`` requires > 0, ``lo``/``hi`` bound it."""

    def parse(text):
        try:
            v = float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{name} must be a number, got {text!r}") from None
        if not math.isfinite(v):
            raise argparse.ArgumentTypeError(f"{name} must be a finite number, got {text!r}")
        if positive and not v > 0:
            raise argparse.ArgumentTypeError(f"{name} must be greater than 0, got {text!r}")
        if (lo is not None and v < lo) or (hi is not None and v > hi):
            raise argparse.ArgumentTypeError(f"{name} must lie between {lo:g} and {hi:g}, got {text!r}")
        return v

    parse.__name__ = name
    return parse


def numbers(name: str, count: int, *, positive: bool = False):
    """An argparse type reading ``count`` comma-separated finite numbers ("X,Y" or "X,Y,Z")."""
    labels = ",".join("XYZW"[:count])

    def parse(text):
        try:
            v = tuple(float(x) for x in str(text).split(","))
        except ValueError:
            raise argparse.ArgumentTypeError(f"{name} must be {count} numbers {labels}, got {text!r}") from None
        if len(v) != count or not all(math.isfinite(x) and (x > 0 or not positive) for x in v):
            kind = "positive" if positive else "finite"
            raise argparse.ArgumentTypeError(f"{name} must be {count} {kind} numbers {labels}, got {text!r}")
        return v

    parse.__name__ = name
    return parse


def coc_value(text):
    """A --coc value: a convention name stays text, a number becomes a float (mm)."""
    if text is None:
        return None
    try:
        return float(text)
    except ValueError:
        return text


def print_json(obj) -> None:
    json.dump(obj, sys.stdout, indent=2, allow_nan=False)
    sys.stdout.write("\n")


def console(stderr: bool = False):
    """A rich Console with markup and highlighting off (user text is never interpreted)."""
    from rich.console import Console

    return Console(stderr=stderr, markup=False, highlight=False, emoji=False)


class progress_bar:
    """A rich progress bar on stderr for long jobs, shown only to a person at a terminal.

    Use as a context manager; the object is a ``progress(done, total)`` callback.
    """

    def __init__(self, description: str, enabled: bool = True):
        self.enabled = enabled and sys.stderr.isatty()
        self.description = description
        self._progress = None
        self._task = None

    def __enter__(self):
        if self.enabled:
            from rich.progress import BarColumn, Progress, TextColumn, TimeRemainingColumn

            self._progress = Progress(TextColumn("{task.description}"), BarColumn(),
                                      TextColumn("{task.percentage:>3.0f}%"), TimeRemainingColumn(),
                                      console=console(stderr=True), transient=True)
            self._progress.__enter__()
            self._task = self._progress.add_task(self.description, total=None)
        return self

    def __call__(self, done, total):
        if self._progress is not None:
            self._progress.update(self._task, completed=done, total=total)

    def __exit__(self, *exc):
        if self._progress is not None:
            self._progress.__exit__(*exc)
        return False

"""Distances as people say them on set, converted to millimetres.

physcam works in millimetres inside (docs/conventions.md). At the edges (CLI,
files) a distance may carry a unit: ``3m``, ``10ft``, ``6in``, ``450mm``,
``2.5 cm``, ``10'6"`` (feet and inches). A bare number is millimetres.
"""

from __future__ import annotations

import math
import re

from .errors import UnitError

__all__ = ["MM_PER_UNIT", "parse_distance", "format_feet_inches", "mm_to", "to_mm"]

#: Millimetres in one of each accepted unit.
MM_PER_UNIT: dict[str, float] = {
    "mm": 1.0,
    "cm": 10.0,
    "m": 1000.0,
    "km": 1.0e6,
    "in": 25.4,
    "inch": 25.4,
    "inches": 25.4,
    '"': 25.4,
    "ft": 304.8,
    "foot": 304.8,
    "feet": 304.8,
    "'": 304.8,
    "um": 1.0e-3,
    "µm": 1.0e-3,
}

_NUMBER = r"[+-]?(?:\d+(?:\.\d*)?|\.\d+)(?:[eE][+-]?\d+)?"
_SIMPLE = re.compile(rf"^\s*({_NUMBER})\s*([a-zA-Zµ'\"]*)\s*$")
_FEET_INCHES = re.compile(rf"^\s*({_NUMBER})\s*(?:ft|feet|foot|')\s*({_NUMBER})\s*(?:in|inch|inches|\")?\s*$")


def to_mm(value: float, unit: str) -> float:
    """``value`` in ``unit`` (a key of :data:`MM_PER_UNIT`) as millimetres."""
    if not isinstance(unit, str):
        raise UnitError(f"a unit is a name such as 'mm', 'm' or 'ft', got {unit!r}")
    try:
        return float(value) * MM_PER_UNIT[unit.lower() if unit not in ("'", '"') else unit]
    except KeyError:
        raise UnitError(f"unknown unit {unit!r}; use one of mm, cm, m, in, ft") from None


def mm_to(value_mm: float, unit: str) -> float:
    """Millimetres as ``unit``."""
    return float(value_mm) / to_mm(1.0, unit)


def parse_distance(text, *, name: str = "distance", allow_inf: bool = False) -> float:
    """Read a distance such as ``3m``, ``10ft``, ``6in``, ``450mm`` or ``10'6"``; return mm.

    A bare number is millimetres. ``inf`` (or ``infinity``) is accepted only with
    ``allow_inf``. Raises :class:`~physcam.errors.UnitError` naming ``name`` otherwise.

    >>> parse_distance("10ft")
    3048.0
    >>> parse_distance("10'6\\"")
    3200.4
    """
    if isinstance(text, (int, float)) and not isinstance(text, bool):
        v = float(text)
    else:
        s = str(text).strip()
        if s.lower() in ("inf", "infinity", "∞"):
            if allow_inf:
                return math.inf
            raise UnitError(f"{name} must be finite, got {s!r}")
        m = _FEET_INCHES.match(s)
        if m:
            v = float(m.group(1)) * 304.8 + float(m.group(2)) * 25.4
        else:
            m = _SIMPLE.match(s)
            if not m:
                raise UnitError(
                    f"cannot read {name} {s!r}: write a number with an optional unit, e.g. 3m, 10ft, 6in, 450mm"
                )
            unit = m.group(2) or "mm"
            v = to_mm(float(m.group(1)), unit)
    if math.isnan(v) or (math.isinf(v) and not allow_inf):
        raise UnitError(f"{name} must be a finite number, got {text!r}")
    return v


def format_feet_inches(value_mm: float) -> str:
    """Millimetres as feet and inches to the nearest inch, e.g. ``8' 9\"``; ``inf`` as ``∞``."""
    if math.isinf(value_mm):
        return "∞"
    total_in = round(value_mm / 25.4)
    sign = "-" if total_in < 0 else ""
    ft, inch = divmod(abs(total_in), 12)
    return f"{sign}{ft}' {inch}\""

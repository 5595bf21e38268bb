"""Distances as people say them on set, converted to millimetres.

physcam works in millimetres inside (docs/conventions.md). At the edges (CLI,
files) a distance may carry a unit: ``3m``, ``10ft``, ``6in``, ``450mm``,
``2.5 cm``, ``10'6"``, ``9' 10 1/8"`` (feet and inches, fractional inches too). A bare
number is millimetres. The feet and inch marks may be typographic, as a phone's keyboard types them
(``10’6”``) or as a typesetter sets them (primes, ``10′6″``): :func:`plain_marks`.

Printed distances follow a *unit system* (``--units``): ``m`` (metres, millimetres below one
metre) or ``ft`` (feet and inches, to the nearest 1/8 inch below 10 feet and the nearest inch
beyond, as focus marks are written on set): :func:`format_distance`.
"""

from __future__ import annotations

import math
import re

from .errors import UnitError, require_type

__all__ = ["MM_PER_UNIT", "UNIT_SYSTEMS", "unit_system", "plain_marks", "parse_distance", "format_feet_inches", "format_distance", "mm_to", "to_mm",
           "inch_fraction_for"]

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
#: inches as a number, a whole number and a fraction ("6 1/2") or a fraction alone ("3/8")
_INCHES = r"(?:(\d+(?:\.\d*)?)(?:\s+(\d+)/(\d+))?|(\d+)/(\d+))"
#: (patterns compiled by ``re`` when a distance in feet is first read: a metric one never needs them; a sign
#: before inches alone, -1 1/4", as before feet)
_FEET_INCHES = rf"^\s*(?:[+-](?=[\d.]))?(?:({_NUMBER})\s*(?:ft|feet|foot|'))?\s*(?:{_INCHES}\s*(?:in|inch|inches|\"))?\s*$"
_FEET_BARE_INCHES = rf"^\s*({_NUMBER})\s*(?:ft|feet|foot|')\s*{_INCHES}\s*$"

#: Typographic foot and inch marks, read as ``'`` and ``"``: the right and left single quotation marks
#: (U+2019, U+2018: what the "smart punctuation" of iOS and Android keyboards makes of ``'``) and the prime
#: (U+2032, the typesetter's foot mark); the right and left double quotation marks (U+201D, U+201C) and the
#: double prime (U+2033, the inch mark). Unicode's code charts annotate U+2032 "minutes, feet" and U+2033
#: "seconds, inches".
_MARKS = str.maketrans("\u2019\u2018\u2032\u201d\u201c\u2033", "'" * 3 + '"' * 3)

#: The unit systems distances are printed in (``--units``): metric or feet and inches.
UNIT_SYSTEMS = ("m", "ft")
#: The spellings people type for a unit system ("--units feet"), each read as its system's name.
UNIT_SYSTEM_WORDS = {"m": "m", "metre": "m", "metres": "m", "meter": "m", "meters": "m",
                     "ft": "ft", "foot": "ft", "feet": "ft"}


def unit_system(text: str) -> str:
    """The unit system (:data:`UNIT_SYSTEMS`) a spelling names: "feet", "foot", "ft" give "ft"; "metres",
    "meters", "m" give "m" (case and spaces ignored); any other text comes back as typed, for the caller
    to refuse with the choices."""
    return UNIT_SYSTEM_WORDS.get(text.strip().lower(), text) if isinstance(text, str) else text


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


def plain_marks(text: str) -> str:
    """``text`` with its typographic foot and inch marks (:data:`_MARKS`) made ``'`` and ``"``, and two foot
    marks in a row made one inch mark (``6''`` or ``6’’`` is 6 inches: the typewriter's way of writing the
    double prime; a phone's keyboard makes ``''`` typed into ``’’``). serve's page reads marks by the same rule
    (``plainMarks`` in serve/static/onset.js).

    >>> print(plain_marks("10’6”"), plain_marks("10′ 6″"), plain_marks("10'6''"))
    10'6" 10' 6" 10'6"
    """
    return require_type("text", text, str).translate(_MARKS).replace("''", '"')


def parse_distance(text, *, name: str = "distance", allow_inf: bool = False) -> float:
    """Read a distance such as ``3m``, ``10ft``, ``6in``, ``450mm`` or ``10'6"``; return mm.

    A bare number is millimetres; feet and inch marks may be typographic (``10’6”``, ``10′6″``:
    :func:`plain_marks`). ``inf`` (or ``infinity``) is accepted only with ``allow_inf``.
    Raises :class:`~physcam.errors.UnitError` naming ``name`` otherwise.

    >>> parse_distance("10ft")
    3048.0
    >>> parse_distance("10'6\\"")
    3200.4
    """
    if isinstance(text, (int, float)) and not isinstance(text, bool):
        v = float(text)
    else:
        s = str(text).strip()
        t = s if s.isascii() and "''" not in s else plain_marks(s)  # refusals quote what was typed, s
        if s.lower() in ("inf", "infinity", "∞"):
            if allow_inf:
                return math.inf
            raise UnitError(f"{name} must be finite, got {s!r}")
        m = re.match(_FEET_INCHES, t) if any(c in t for c in "'\"/") or re.search(r"\d\s*(ft|feet|foot)\s*\d", t) \
            else None
        m = m or (re.match(_FEET_BARE_INCHES, t) if "/" in t else None)
        if m and (m.group(1) is not None or any(g is not None for g in m.groups()[1:])):
            # a sign belongs to the whole distance: -1' 2" is -(1 foot 2 inches)
            v = abs(float(m.group(1) or 0.0)) * 304.8 + _inches(*m.groups()[1:]) * 25.4
            if t.lstrip().startswith("-"):
                v = -v
        else:
            m = _SIMPLE.match(t)
            if not m:
                raise UnitError(
                    f"cannot read {name} {s!r}: write a number with an optional unit, e.g. 3m, 10ft, 6in, 450mm"
                )
            unit = m.group(2) or "mm"
            v = to_mm(float(m.group(1)), unit)
    if math.isnan(v) or (math.isinf(v) and not allow_inf):
        raise UnitError(f"{name} must be a finite number, got {text!r}")
    return v


def _inches(whole, num, den, fnum, fden) -> float:
    """Inches from the groups of ``_INCHES`` (none given is 0)."""
    v = float(whole) if whole is not None else 0.0
    for n, d in ((num, den), (fnum, fden)):
        if n is not None:
            if int(d) == 0:
                raise UnitError(f"a fraction of an inch needs a denominator above 0, got {n}/{d}")
            v += int(n) / int(d)
    return v


def inch_fraction_for(value_mm: float) -> int:
    """The inch fraction a distance is written to on set: 8 (1/8 inch) below 10 feet, else 1 (whole inches)."""
    return 8 if abs(value_mm) < 10 * 304.8 else 1


def format_feet_inches(value_mm: float, fraction: int = 1) -> str:
    """Millimetres as feet and inches to the nearest ``1/fraction`` inch, e.g. ``8' 9\"`` or
    ``4' 6 3/8\"`` (fraction 8), inches alone under a foot (``1 1/4\"``, not ``0' 1 1/4\"``); ``inf`` as
    ``∞``. Fractions are reduced (4/8 is 1/2).

    >>> print(format_feet_inches(3048.0), format_feet_inches(1381.125, fraction=8))
    10' 0" 4' 6 3/8"
    """
    import fractions

    if math.isinf(value_mm):
        return "∞"
    if isinstance(fraction, bool) or not isinstance(fraction, int) or fraction < 1:
        raise UnitError(f"an inch fraction is a whole number >= 1 (8 for eighths), got {fraction!r}")
    steps = round(value_mm / 25.4 * fraction)
    sign = "-" if steps < 0 else ""
    whole_in, part = divmod(abs(steps), fraction)
    ft, inch = divmod(whole_in, 12)
    frac = "" if part == 0 else f" {fractions.Fraction(part, fraction)}"
    if ft == 0:  # under a foot, inches alone, as a puller writes it: 1 1/4", 3/8"
        return f"{sign}{frac.strip() if inch == 0 and frac else f'{inch}{frac}'}\""
    return f"{sign}{ft}' {inch}{frac}\""


def format_distance(value_mm: float, units: str = "m", *, digits: int = 3) -> str:
    """A distance for people in a unit system (:data:`UNIT_SYSTEMS`): ``m`` gives metres with
    ``digits`` decimals from one metre up and whole millimetres (one decimal) below; ``ft``
    gives feet and inches (:func:`format_feet_inches` with :func:`inch_fraction_for`).
    Infinity is ``∞``.

    >>> print(format_distance(2814.2), "|", format_distance(450.0), "|", format_distance(2814.2, "ft"))
    2.814 m | 450.0 mm | 9' 2 3/4"
    """
    if units not in UNIT_SYSTEMS:
        raise UnitError(f"units must be one of {', '.join(UNIT_SYSTEMS)}, got {units!r}")
    v = float(value_mm)
    if math.isinf(v):
        return "∞"
    if units == "ft":
        return format_feet_inches(v, inch_fraction_for(v))
    if abs(v) >= 1000.0:
        return f"{v / 1000.0:.{digits}f} m"
    return f"{v:.1f} mm"

"""Circle of confusion: named conventions, one dispatcher.

The acceptable blur on the film depends on how the picture will be seen; the
conventions below are the ones camera departments actually quote.

- ``d/1500`` (default): sensor diagonal / 1500, the "modern Zeiss" rule, 0.029 mm on a
  36x24 frame (Wikipedia "Zeiss formula"; "Circle of confusion", table convention).
- ``d/1000``: diagonal / 1000, the traditional Zeiss rule.
- ``cine``: 0.025 mm (0.001 in), the American Cinematographer Manual's 35 mm motion
  picture value (ACM 1986, quoted by DOFMaster): "Super 35 cine", what pullers' apps default to.
- ``full-frame``: 0.03 mm, the full-frame (36 x 24) still value of DOFMaster and Canon.
- ``16mm``: 0.015 mm, the ACM's 16 mm motion picture value (quoted by DOFMaster).
- a number: the user's own value in mm, from :data:`MIN_COC_MM` to :data:`MAX_COC_MM` (:func:`require_coc`).

See ``reference/formats/coc_conventions.csv`` in the shared data for sources.
"""

from __future__ import annotations

import math

from ..errors import InputError, require_positive

__all__ = ["COC_CONVENTIONS", "DEFAULT_COC_CONVENTION", "MIN_COC_MM", "MAX_COC_MM", "require_coc",
           "circle_of_confusion", "named_circle_of_confusion", "parse_coc"]

#: name -> (description, function of (width_mm, height_mm) -> coc_mm)
COC_CONVENTIONS = {
    "d/1500": ("sensor diagonal / 1500 (modern Zeiss)", lambda w, h: math.hypot(w, h) / 1500.0),
    "d/1000": ("sensor diagonal / 1000 (traditional Zeiss)", lambda w, h: math.hypot(w, h) / 1000.0),
    "d/1730": ("sensor diagonal / 1730 ('Zeiss formula')", lambda w, h: math.hypot(w, h) / 1730.0),
    "cine": ("0.025 mm fixed, Super 35 cine (ACM 1986, 35 mm motion picture)", lambda w, h: 0.025),
    "full-frame": ("0.03 mm fixed, full frame 36 x 24 (DOFMaster, Canon)", lambda w, h: 0.03),
    "16mm": ("0.015 mm fixed, 16 mm cine (ACM 1986)", lambda w, h: 0.015),
}
_ALIASES = {"zeiss": "d/1500", "modern": "d/1500", "traditional": "d/1000", "acm": "cine", "0.025": "cine",
            "s35": "cine", "super35": "cine", "ff": "full-frame", "fullframe": "full-frame", "0.03": "full-frame",
            "s16": "16mm", "0.015": "16mm"}

DEFAULT_COC_CONVENTION = "d/1500"

#: The circles of confusion a person may give (mm). The values camera departments use run from 0.0127 mm
#: (1/2000 in, Panavision's "hard look") to 0.0508 mm (1/500 in, heavy diffusion; Panaflex User's Manual) and
#: 0.05 mm (historic 35 mm tables); the diagonal rules give 0.0084 mm (Super 16, d/1730) to 0.088 mm (IMAX 15/70,
#: d/1000), the widest format in the shared reference/formats tables. 1 um is a third of the finest photosite in
#: the camera table (2.99 um, LUMIX GH6) and about the Airy disk of an f/0.75 lens (2.44 x 0.55 um x 0.75); 1 mm is
#: 11 times IMAX's d/1000 and three times 8 x 10 in sheet film's (0.33 mm). Beyond them a value is a slip
#: (``--coc 5m``, ``1e-300``) whose hyperfocal distance means nothing.
MIN_COC_MM = 0.001
MAX_COC_MM = 1.0


def require_coc(value, name: str = "circle of confusion") -> float:
    """``value`` (mm) as a float if a circle of confusion may be that (:data:`MIN_COC_MM` to :data:`MAX_COC_MM`),
    else an :class:`InputError` in one line."""
    c = require_positive(name, value)
    if not MIN_COC_MM <= c <= MAX_COC_MM:
        raise InputError(f"{name} {c:g} mm is out of range: give {MIN_COC_MM:g} mm (1 um) to {MAX_COC_MM:g} mm "
                         f"(0.025 mm is Super 35 cine), or a convention such as d/1500")
    return c


def circle_of_confusion(width_mm: float, height_mm: float, convention: str | float | None = None):
    """(coc_mm, convention_name) for a sensor of ``width_mm`` x ``height_mm``.

    ``convention`` is a name from :data:`COC_CONVENTIONS`, a number (user value, mm) or
    ``None`` for the default ``d/1500``. Unknown names raise :class:`InputError` listing
    the choices.

    >>> c, name = circle_of_confusion(36.0, 24.0)
    >>> round(c, 4), name
    (0.0288, 'd/1500')
    """
    w = require_positive("sensor width", width_mm)
    h = require_positive("sensor height", height_mm)
    if convention is None:
        convention = DEFAULT_COC_CONVENTION
    if isinstance(convention, (int, float)):
        return require_coc(convention), "user"
    key = str(convention).strip().lower()
    key = _ALIASES.get(key, key)
    if key in COC_CONVENTIONS:
        return COC_CONVENTIONS[key][1](w, h), key
    try:
        value = float(key.removesuffix("mm"))
    except ValueError:
        import difflib

        close = difflib.get_close_matches(key, list(COC_CONVENTIONS), n=3, cutoff=0.3)
        hint = f" (did you mean {', '.join(close)}?)" if close else ""
        raise InputError(
            f"unknown circle-of-confusion convention {convention!r}{hint}; "
            f"use one of {', '.join(COC_CONVENTIONS)} or a value in mm"
        ) from None
    return require_coc(value), "user"


def named_circle_of_confusion(width_mm: float, height_mm: float, convention: str | float | None = None):
    """:func:`circle_of_confusion`, where a value that is one of the named conventions for this sensor
    (to float32 precision, as a USD file stores it) keeps that convention's name instead of "user"."""
    c, name = circle_of_confusion(width_mm, height_mm, convention)
    if name != "user" or not isinstance(convention, (int, float)):
        return c, name
    for key, (_, rule) in COC_CONVENTIONS.items():
        v = rule(width_mm, height_mm)
        if abs(c - v) <= 1e-6 * v:
            return c, key
    return c, name


def parse_coc(text):
    """A circle of confusion as written by a person: a convention name (``d/1500``, ``cine``, ...)
    stays text (checked by :func:`circle_of_confusion` against the sensor); a number with an
    optional unit (``0.025``, ``25um``, ``0.025mm``; a bare number is mm) becomes a float in mm, within
    :func:`require_coc`'s bounds. A malformed length or one out of bounds is an InputError; None stays None."""
    from ..units import parse_distance

    if text is None:
        return None
    if str(text).strip().lower() in COC_CONVENTIONS or str(text).strip().lower() in _ALIASES:
        return str(text).strip()  # a name, though it starts with a digit ("16mm")
    try:
        value = float(text)
    except ValueError:
        value = None
    if value is not None:
        return require_coc(value)
    t = str(text).strip()
    if t and (t[0].isdigit() or t[0] in ".+-") and "/" not in t:
        return require_coc(parse_distance(t, name="circle of confusion"))
    return text

"""A focus puller's lens set: their primes with the T-stop and close focus engraved on each.

A set is text, one lens a line, as a puller writes it on the lens case:

    # Cooke S4/i, the B-camera kit
    18  T2  9in
    25  T2  9in
    50  T2  20in
    100 T2  2ft 6in

focal length (a bare number is mm), the wide-open T-stop (``T2``, ``2``) and the close focus (a
distance from the film plane, units as typed; optional), an optional name after ``#`` at the line's
end. The page keeps a set on the phone; ``physcam hyperfocal --lens-set FILE`` reads one. A T-stop is
photometric (transmission included), the report's f-stop geometric: the hyperfocal table of a set
takes the stops it is given as f-numbers, and says so.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

from ..errors import InputError
from ..optics.thinlens import require_f_number

__all__ = ["SetLens", "LensSet", "parse_lens_set", "read_lens_set"]


@dataclass(frozen=True)
class SetLens:
    focal_length_mm: float
    tstop: float | None = None  # wide open (None: not given)
    close_focus_mm: float | None = None  # from the film plane
    name: str = ""

    @property
    def label(self) -> str:
        t = "" if self.tstop is None else f" T{self.tstop:g}"
        return f"{self.focal_length_mm:g} mm{t}" + (f" {self.name}" if self.name else "")

    def to_dict(self) -> dict:
        return {"focal_length_mm": self.focal_length_mm, "tstop": self.tstop, "close_focus_mm": self.close_focus_mm,
                "name": self.name or None}


@dataclass(frozen=True)
class LensSet:
    name: str
    lenses: tuple[SetLens, ...]

    def to_dict(self) -> dict:
        return {"name": self.name, "lenses": [x.to_dict() for x in self.lenses]}


_LINE = re.compile(r"^\s*(?P<focal>\S+?)(?:\s*mm)?\s+[tT]?(?P<t>[\d.]+)(?:\s+(?P<close>[^#]+?))?\s*(?:#\s*(?P<name>.*))?$")


def parse_lens_set(text: str, *, name: str = "lens set", where: str = "<text>") -> LensSet:
    """The set written in ``text`` (module notes); a bad line is an InputError naming ``where`` and the line."""
    from ..units import parse_distance

    lenses = []
    for n, raw in enumerate(str(text).splitlines(), 1):
        line = raw.strip()
        if not line or line.startswith("#"):
            continue
        m = _LINE.match(line)
        if not m:
            raise InputError(f"{where}, line {n}: write a lens as 'focal T-stop close-focus', e.g. '50 T2 20in', got "
                             f"{raw.strip()!r}")
        try:
            f = parse_distance(m["focal"], name="focal length")
            t = require_f_number("T-stop", float(m["t"]))
            close = None if not m["close"] else parse_distance(m["close"].strip(), name="close focus")
        except (InputError, ValueError) as exc:
            raise InputError(f"{where}, line {n}: {exc}") from None
        if not 1.0 <= f <= 2000.0:
            raise InputError(f"{where}, line {n}: focal length {f:g} mm is not a camera lens's")
        if close is not None and close <= 0:
            raise InputError(f"{where}, line {n}: close focus must be a positive distance from the film")
        lenses.append(SetLens(f, t, close, (m["name"] or "").strip()))
    if not lenses:
        raise InputError(f"{where}: no lens in the set; write one a line, e.g. '50 T2 20in'")
    return LensSet(name, tuple(lenses))


def read_lens_set(path) -> LensSet:
    """The set in the text file ``path`` (its name: the first comment line, else the file's stem)."""
    p = Path(path)
    try:
        text = p.read_text(encoding="utf-8")
    except OSError as exc:
        raise InputError(f"cannot read the lens set {p}: {exc.strerror or exc}") from None
    first = next((ln.strip().lstrip("#").strip() for ln in text.splitlines() if ln.strip()), "")
    return parse_lens_set(text, name=first if text.lstrip().startswith("#") and first else p.stem, where=str(p))

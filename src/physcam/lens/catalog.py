"""A small optical-glass catalogue: name -> (nd, Vd).

Enough to read Zemax files that name catalogue glasses and to label media in
physcam's TOML; any other glass can be given by its (nd, Vd) directly. Indices are
at the helium d line (587.5618 nm), Abbe numbers Vd = (nd - 1) / (nF - nC).

Sources (values as printed, 5 decimals for nd, 2 for Vd):
- SCHOTT optical glass data sheets / "Optical Glass" catalogue (2017-2023 editions)
  for the N-, F and SF types.
- OHARA optical glass catalogue for the S- types.
- Corning HPFS 7980 and Heraeus Suprasil data sheets for fused silica; Zemax's
  MISC catalogue entries F_SILICA and CAF2 use the same values.

Names are matched case-insensitively; an unknown name raises :class:`InputError`
listing the closest known names.
"""

from __future__ import annotations

import difflib
from dataclasses import dataclass

from ..errors import InputError

__all__ = ["CatalogGlass", "GLASSES", "find_glass", "glass_names"]


@dataclass(frozen=True, slots=True)
class CatalogGlass:
    """One catalogue glass: ``nd`` at 587.5618 nm, Abbe number ``vd``, maker."""

    name: str
    nd: float
    vd: float
    maker: str


_TABLE = [
    # SCHOTT
    ("N-BK7", 1.51680, 64.17, "SCHOTT"),
    ("N-BK10", 1.49782, 66.95, "SCHOTT"),
    ("N-K5", 1.52249, 59.48, "SCHOTT"),
    ("N-FK5", 1.48749, 70.41, "SCHOTT"),
    ("N-PK51", 1.52855, 76.98, "SCHOTT"),
    ("N-BAK4", 1.56883, 55.98, "SCHOTT"),
    ("N-BAF10", 1.67003, 47.11, "SCHOTT"),
    ("N-SK4", 1.61272, 58.63, "SCHOTT"),
    ("N-SK16", 1.62041, 60.32, "SCHOTT"),
    ("N-SSK8", 1.61773, 49.83, "SCHOTT"),
    ("N-LAK8", 1.71300, 53.83, "SCHOTT"),
    ("N-LAK9", 1.69100, 54.71, "SCHOTT"),
    ("N-LAK22", 1.65113, 55.89, "SCHOTT"),
    ("N-LAF2", 1.74397, 44.85, "SCHOTT"),
    ("N-LASF9", 1.85025, 32.17, "SCHOTT"),
    ("F2", 1.62004, 36.37, "SCHOTT"),
    ("N-F2", 1.62005, 36.43, "SCHOTT"),
    ("N-SF2", 1.64769, 33.82, "SCHOTT"),
    ("N-SF5", 1.67270, 32.25, "SCHOTT"),
    ("N-SF6", 1.80518, 25.36, "SCHOTT"),
    ("N-SF8", 1.68894, 31.31, "SCHOTT"),
    ("N-SF10", 1.72828, 28.53, "SCHOTT"),
    ("N-SF11", 1.78472, 25.68, "SCHOTT"),
    ("N-SF57", 1.84666, 23.78, "SCHOTT"),
    # OHARA
    ("S-BSL7", 1.51633, 64.14, "OHARA"),
    ("S-FPL51", 1.49700, 81.54, "OHARA"),
    ("S-TIH6", 1.80518, 25.42, "OHARA"),
    ("S-TIH53", 1.84666, 23.78, "OHARA"),
    # crystals and silica
    ("F_SILICA", 1.45846, 67.82, "Corning/Heraeus"),
    ("CAF2", 1.43385, 94.99, "crystal"),
]

#: Upper-case name -> glass.
GLASSES: dict[str, CatalogGlass] = {n.upper(): CatalogGlass(n, nd, vd, m) for n, nd, vd, m in _TABLE}


def glass_names() -> list[str]:
    """The catalogue's glass names, as printed by their makers."""
    return [g.name for g in GLASSES.values()]


def find_glass(name: str) -> CatalogGlass:
    """The catalogue glass called ``name`` (case-insensitive); :class:`InputError` if unknown."""
    key = str(name).strip().upper()
    try:
        return GLASSES[key]
    except KeyError:
        close = difflib.get_close_matches(key, list(GLASSES), n=3, cutoff=0.6)
        hint = f"; did you mean {', '.join(GLASSES[c].name for c in close)}?" if close else ""
        raise InputError(
            f"unknown glass {name!r}{hint} (give the medium as nd and Vd instead, "
            f"or use one of: {', '.join(glass_names())})"
        ) from None

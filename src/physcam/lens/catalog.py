"""A small optical-glass catalogue: name -> (nd, Vd) and, where known, the maker's Sellmeier formula.

Enough to read Zemax files that name catalogue glasses and to label media in
physcam's TOML; any other glass can be given by its (nd, Vd) directly. Indices are
at the helium d line (587.5618 nm), Abbe numbers Vd = (nd - 1) / (nF - nC).

Sources (values as printed, 5 decimals for nd, 2 for Vd):
- SCHOTT optical glass data sheets / "Optical Glass" catalogue (2017-2023 editions)
  for the N-, F and SF types.
- OHARA optical glass catalogue for the S- types.
- Corning HPFS 7980 and Heraeus Suprasil data sheets for fused silica; Zemax's
  MISC catalogue entries F_SILICA and CAF2 use the same values.

Sellmeier coefficients (B1, B2, B3, C1, C2, C3; n^2 - 1 = sum B_i l^2 / (l^2 - C_i), l in um,
C in um^2) are the makers' published values, copied by a script (not typed) from the catalogue
spreadsheets SCHOTT.xls (SCHOTT optical glass catalogue, 2018) and OHARA.xlsx ("Recommended
glasses"), as redistributed in the PyPI package opticalglass 1.1.1 (data/ folder); fused silica
and CaF2 from I. H. Malitson, JOSA 55, 1205 (1965) and Appl. Opt. 2, 1103 (1963). S-BSL7 and
S-TIH6 were not in that OHARA sheet and have no formula here (they get the normal-line model).
:func:`physcam.optics.glass.dispersion` uses them.

Names are matched case-insensitively; an unknown name raises :class:`InputError`
listing the closest known names.
"""

from __future__ import annotations

import difflib
from dataclasses import dataclass

from ..errors import InputError

__all__ = ["CatalogGlass", "GLASSES", "find_glass", "glass_names", "match_glass"]


@dataclass(frozen=True, slots=True)
class CatalogGlass:
    """One catalogue glass: ``nd`` at 587.5618 nm, Abbe number ``vd``, maker."""

    name: str
    nd: float
    vd: float
    maker: str
    sellmeier: tuple[float, float, float, float, float, float] | None = None  # B1 B2 B3 C1 C2 C3 (um^2)


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
_SELLMEIER = {
    "N-BK7": (1.03961212, 0.231792344, 1.01046945, 0.00600069867, 0.0200179144, 103.560653),
    "N-BK10": (0.888308131, 0.328964475, 0.984610769, 0.00516900822, 0.0161190045, 99.7575331),
    "N-K5": (1.08511833, 0.199562005, 0.930511663, 0.00661099503, 0.024110866, 111.982777),
    "N-FK5": (0.844309338, 0.344147824, 0.910790213, 0.00475111955, 0.0149814849, 97.8600293),
    "N-PK51": (1.15610775, 0.153229344, 0.785618966, 0.00585597402, 0.0194072416, 140.537046),
    "N-BAK4": (1.28834642, 0.132817724, 0.945395373, 0.00779980626, 0.0315631177, 105.965875),
    "N-BAF10": (1.5851495, 0.143559385, 1.08521269, 0.00926681282, 0.0424489805, 105.613573),
    "N-SK4": (1.32993741, 0.228542996, 0.988465211, 0.00716874107, 0.0246455892, 100.886364),
    "N-SK16": (1.34317774, 0.241144399, 0.994317969, 0.00704687339, 0.0229005, 92.7508526),
    "N-SSK8": (1.44857867, 0.117965926, 1.06937528, 0.00869310149, 0.0421566593, 111.300666),
    "N-LAK8": (1.33183167, 0.546623206, 1.19084015, 0.00620023871, 0.0216465439, 82.5827736),
    "N-LAK9": (1.46231905, 0.344399589, 1.15508372, 0.00724270156, 0.0243353131, 85.4686868),
    "N-LAK22": (1.14229781, 0.535138441, 1.04088385, 0.00585778594, 0.0198546147, 100.834017),
    "N-LAF2": (1.80984227, 0.15729555, 1.0930037, 0.0101711622, 0.0442431765, 100.687748),
    "N-LASF9": (2.00029547, 0.298926886, 1.80691843, 0.0121426017, 0.0538736236, 156.530829),
    "F2": (1.34533359, 0.209073176, 0.937357162, 0.00997743871, 0.0470450767, 111.886764),
    "N-F2": (1.39757037, 0.159201403, 1.2686543, 0.00995906143, 0.0546931752, 119.248346),
    "N-SF2": (1.47343127, 0.163681849, 1.36920899, 0.0109019098, 0.0585683687, 127.404933),
    "N-SF5": (1.52481889, 0.187085527, 1.42729015, 0.011254756, 0.0588995392, 129.141675),
    "N-SF6": (1.77931763, 0.338149866, 2.08734474, 0.0133714182, 0.0617533621, 174.01759),
    "N-SF8": (1.55075812, 0.209816918, 1.46205491, 0.0114338344, 0.0582725652, 133.24165),
    "N-SF10": (1.62153902, 0.256287842, 1.64447552, 0.0122241457, 0.0595736775, 147.468793),
    "N-SF11": (1.73759695, 0.313747346, 1.89878101, 0.013188707, 0.0623068142, 155.23629),
    "N-SF57": (1.87543831, 0.37375749, 2.30001797, 0.0141749518, 0.0640509927, 177.389795),
    "S-FPL51": (1.17010505, 0.0475710783, 0.763832445, 0.00616203924, 0.0263372876, 141.882642),
    "S-TIH53": (1.87904886, 0.369719775, 2.33730863, 0.014412177, 0.063881799, 182.66818),
    "F_SILICA": (0.6961663, 0.4079426, 0.8974794, 0.0684043**2, 0.1162414**2, 9.896161**2),
    "CAF2": (0.5675888, 0.4710914, 3.8484723, 0.050263605**2, 0.1003909**2, 34.649040**2),
}

GLASSES: dict[str, CatalogGlass] = {
    n.upper(): CatalogGlass(n, nd, vd, m, _SELLMEIER.get(n)) for n, nd, vd, m in _TABLE
}


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


def match_glass(nd: float, vd: float, tol_nd: float, tol_vd: float) -> CatalogGlass | None:
    """The one catalogue glass with a dispersion formula within (``tol_nd``, ``tol_vd``) of
    (nd, Vd), or None when none or several match."""
    hits = [g for g in GLASSES.values()
            if g.sellmeier is not None and abs(g.nd - nd) <= tol_nd and abs(g.vd - vd) <= tol_vd]
    return hits[0] if len(hits) == 1 else None

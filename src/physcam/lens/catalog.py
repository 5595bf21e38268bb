"""Optical-glass catalogues: the makers' own (SCHOTT, OHARA, HOYA, CDGM, HIKARI, SUMITA), their
legacy glasses (SCHOTT_LEGACY, OHARA_LEGACY, HIKARI_LEGACY, HOYA_LEGACY), a small MISC one, and
any Zemax ``.agf`` catalogue a user names; glasses found by name, searched in order.

The makers' catalogues are JSON files in ``physcam/data/glass`` written by
``scripts/build_glass_catalogs.py`` from the makers' spreadsheets (editions and licence notes in
``data/glass/SOURCES.md``): per glass the Zemax formula number and coefficients
(:mod:`physcam.lens.glassformulas`), nd and Vd as printed, the printed C/d/F/g indices, the
wavelength span, the 10 mm internal transmission and a mark for glasses kept from the previous
edition. The legacy catalogues (``scripts/build_legacy_glass_catalogs.py``) hold what those sheets lack and older catalogues carry: SCHOTT's obsolete glasses (SK16, F15,
SK1, BK7...) and B 270 from Zemax's 2008 SCHOTT.AGF, OHARA's glasses from its 2019 .agf (LAH64,
FPL51...), HIKARI's E- glasses from Zemax's HIKARI.AGF, HOYA's obsolete ones from its 2022
.agf, each with the maker's ``status``. No
file is read at import: a catalogue loads on its first lookup. MISC holds fused silica (as
F_SILICA and SILICA) and CaF2 (I. H. Malitson, JOSA 55, 1205 (1965); Appl. Opt. 2, 1103 (1963)),
the names Zemax's MISC catalogue uses.

Search order (:func:`find_glass`): the catalogues asked for (a Zemax file's ``GCAT`` line, in its
order, as OpticStudio searches them), then the user's catalogues (:func:`use_catalog_files`,
``--glass-catalog``); with none asked for, the user's then every current built-in one. A glass in
none of them raises :class:`GlassNotFound` naming the catalogues searched, the nearest names and
any other catalogue that holds the glass. A lens file's glass goes further
(:func:`resolve_glass`, issue 40 item 15): to the legacy catalogue of a maker the file names
(OpticStudio's own SCHOTT.AGF carries SCHOTT's obsolete glasses), then, unless strict
(:func:`strict_glass`, ``--strict-glass``), to every other bundled catalogue; the reader says in
one warning which glass came from where, never substituting another glass.

:data:`GLASSES` is the set of common glasses physcam identifies by (nd, Vd) alone
(:func:`match_glass`, used for lens files that give numbers without names): the ~30 glasses of
physcam's earlier table, kept small so that a near-identical glass of another maker does not
make every match ambiguous.
"""

from __future__ import annotations

import contextlib
import contextvars
import json
from collections.abc import Mapping

from pathlib import Path

from ..errors import InputError, require_type
from .catalog_glass import CatalogGlass

__all__ = ["CatalogGlass", "GlassNotFound", "BUILTIN_CATALOGS", "LEGACY", "GLASSES", "find_glass", "glass_names",
           "match_glass", "catalog", "use_catalog_files", "user_catalogs", "register_catalog", "resolve_glass",
           "strict_glass", "range_note"]

BUILTIN_CATALOGS = ("SCHOTT", "OHARA", "HOYA", "CDGM", "HIKARI", "SUMITA", "MISC", "SCHOTT_LEGACY", "OHARA_LEGACY",
                    "HIKARI_LEGACY", "HOYA_LEGACY")
#: A maker's catalogue -> the bundled catalogue of its legacy glasses (module notes).
LEGACY = {"SCHOTT": "SCHOTT_LEGACY", "OHARA": "OHARA_LEGACY", "HIKARI": "HIKARI_LEGACY", "HOYA": "HOYA_LEGACY"}
#: What each legacy catalogue is (data/glass/SOURCES.md), for the reader's warning.
LEGACY_SOURCE = {"SCHOTT_LEGACY": "SCHOTT's glasses from Zemax's SCHOTT.AGF of 2008",
                 "OHARA_LEGACY": "OHARA's glasses from its .agf catalogue of 2019",
                 "HIKARI_LEGACY": "HIKARI's glasses from Zemax's HIKARI.AGF",
                 "HOYA_LEGACY": "HOYA's glasses from its .agf catalogue of 2022"}
_CURRENT = tuple(c for c in BUILTIN_CATALOGS if c not in LEGACY.values())
_STRICT: contextvars.ContextVar[bool | None] = contextvars.ContextVar("physcam_strict_glass", default=None)
_STRICT_RUN = [False]  # the run's setting (use_catalog_files), seen by every thread, as the user catalogues are


class GlassNotFound(InputError):
    """A glass name in none of the catalogues searched."""


_MISC = {
    "F_SILICA": CatalogGlass("F_SILICA", 1.45846, 67.82, "MISC", 2,
                             (0.6961663, 0.0684043**2, 0.4079426, 0.1162414**2, 0.8974794, 9.896161**2), (210.0, 3710.0)),
    "CAF2": CatalogGlass("CAF2", 1.43385, 94.99, "MISC", 2,
                         (0.5675888, 0.050263605**2, 0.4710914, 0.1003909**2, 3.8484723, 34.649040**2), (230.0, 9700.0)),
    "SILICA": CatalogGlass("SILICA", 1.45846, 67.82, "MISC", 2,
                           (0.6961663, 0.0684043**2, 0.4079426, 0.1162414**2, 0.8974794, 9.896161**2), (210.0, 3710.0)),
}
# OHARA glasses physcam named before whose data is not in the OHARA sheet: nd and Vd only
# (OHARA catalogue), so they take the normal-line model.
_EXTRA = {"OHARA": [CatalogGlass("S-BSL7", 1.51633, 64.14, "OHARA"), CatalogGlass("S-TIH6", 1.80518, 25.42, "OHARA")]}
_BUILTIN: dict[str, dict[str, CatalogGlass]] = {"MISC": _MISC}
_USER: dict[str, dict[str, CatalogGlass]] = {}  # name -> glasses, in the order given


def _load_builtin(name: str) -> dict[str, CatalogGlass]:
    text = (Path(__file__).parent.parent / "data" / "glass" / f"{name}.json").read_text(encoding="utf-8")
    out = {}
    for g in json.loads(text)["glasses"]:
        out.setdefault(g["name"].upper(), CatalogGlass(
            g["name"], g["nd"], g["vd"], name, g["formula"], tuple(g["coefficients"]),
            tuple(g["range_nm"]) if "range_nm" in g else None, g.get("published"),
            tuple(tuple(p) for p in g.get("transmission_10mm", ())), bool(g.get("previous", False)),
            float(g.get("dpgf", 0.0)), g.get("status")))
    for g in _EXTRA.get(name, ()):
        out.setdefault(g.name.upper(), g)
    for key, g in list(out.items()):  # OHARA's sheet writes "S-TIL 2", its .agf and Zemax files "S-TIL2"
        out.setdefault(key.replace(" ", ""), g)
    return out


def catalog(name: str) -> dict[str, CatalogGlass] | None:
    """The glasses of catalogue ``name`` (upper-case name -> glass), or None when physcam has no
    such catalogue (user catalogues first)."""
    key = str(name).strip().upper()
    if key in _USER:
        return _USER[key]
    if key not in _BUILTIN and key in BUILTIN_CATALOGS:
        _BUILTIN[key] = _load_builtin(key)
    return _BUILTIN.get(key)


def register_catalog(name: str, glasses: dict[str, CatalogGlass]) -> None:
    """Add a user catalogue (searched after a file's own catalogues, before the built-in ones)."""
    require_type("name", name, str, 'a catalogue name, e.g. "MYGLASS"')
    require_type("glasses", glasses, Mapping, "a dict of glass name -> CatalogGlass (physcam.lens.agf.read_agf)")
    for key, glass in glasses.items():
        require_type(f"glass {key!r}", glass, CatalogGlass, "a physcam.lens.catalog_glass.CatalogGlass")
    _USER[name.strip().upper()] = {str(k).strip().upper(): g for k, g in glasses.items()}


def use_catalog_files(paths, *, strict: bool = False) -> list[str]:
    """Make the ``.agf`` files ``paths`` the user catalogues (replacing earlier ones) and set
    whether lens files keep to their own catalogue list (``strict``, :func:`resolve_glass`); their
    names. Nothing changes when a file is refused."""
    from .agf import read_agf

    read = [read_agf(p) for p in paths or ()]
    _USER.clear()
    for name, glasses in read:
        register_catalog(name, glasses)
    _STRICT_RUN[0] = bool(strict)
    return [name for name, _ in read]


@contextlib.contextmanager
def strict_glass(on: bool = True):
    """Within the block (this thread or task), a lens file's glass comes only from the catalogues it
    names (and their makers' legacy ones), as OpticStudio refuses others (:func:`resolve_glass`);
    ``on=False`` lifts a run's ``--strict-glass`` there."""
    token = _STRICT.set(bool(on))
    try:
        yield
    finally:
        _STRICT.reset(token)


def user_catalogs() -> list[str]:
    """Names of the user catalogues in search order."""
    return list(_USER)


def _order(catalogs) -> list[str]:
    asked = [str(c).strip().upper() for c in (catalogs or ())]
    rest = list(_USER) + ([] if asked else list(_CURRENT))
    return list(dict.fromkeys(asked + rest))


def find_glass(name: str, catalogs=None) -> CatalogGlass:
    """The glass ``name`` (case-insensitive) from the first catalogue holding it, searching
    ``catalogs`` (e.g. a Zemax file's GCAT list) then the user's; :class:`GlassNotFound` if none."""
    key = str(name).strip().upper()
    order = _order(catalogs)
    missing = []
    for cat in order:
        glasses = catalog(cat)
        if glasses is None:
            missing.append(cat)
        elif key in glasses:
            return glasses[key]
    raise GlassNotFound(_not_found(name, key, order, missing))


def resolve_glass(name: str, catalogs=None, *, strict: bool | None = None) -> tuple[CatalogGlass, str | None]:
    """(glass, how) of a lens file's glass ``name`` with its catalogue list ``catalogs`` (Zemax's
    GCAT line): ``how`` is None when :func:`find_glass` finds it there (or in the user's
    catalogues), "legacy" when it comes from the legacy catalogue of a maker the list names (of
    any maker when the list is empty), "unlisted" when from another bundled catalogue, which
    ``strict`` (default: :func:`strict_glass`, ``--strict-glass``) refuses as OpticStudio does.
    :class:`GlassNotFound` when none holds it. Never another glass than the one named."""
    try:
        return find_glass(name, catalogs), None
    except GlassNotFound as exc:
        refused = exc
    key = str(name).strip().upper()
    asked = [str(c).strip().upper() for c in (catalogs or ())]
    if strict is None:
        strict = _STRICT_RUN[0] if _STRICT.get() is None else _STRICT.get()
    strict = bool(strict)
    legacy = [LEGACY[c] for c in asked if c in LEGACY] if asked else list(LEGACY.values())
    steps = [(c, "legacy") for c in legacy]
    if asked and not strict:
        steps += [(c, "unlisted") for c in _CURRENT + tuple(LEGACY.values()) if c not in asked and c not in legacy]
    for cat, how in steps:
        glasses = catalog(cat)
        if glasses is not None and key in glasses:
            return glasses[key], how
    if strict:
        raise GlassNotFound(f"{refused} (--strict-glass keeps to the file's catalogues, as OpticStudio does)")
    order = list(dict.fromkeys(_order(catalogs) + [c for c, _ in steps]))
    raise GlassNotFound(_not_found(name, key, order, [c for c in order if catalog(c) is None]))


def range_note(glass: CatalogGlass, wavelength_nm: float) -> str | None:
    """Why ``glass`` should not be used at ``wavelength_nm`` ("its range is 400-410 nm"), or None
    when its stated range (an .agf's LD line, the span a maker tabulates) holds it or is unknown."""
    require_type("glass", glass, CatalogGlass, "a catalogue glass, e.g. find_glass('N-BK7')")
    require_type("wavelength_nm", wavelength_nm, (int, float), "a wavelength in nm, e.g. 780.0")
    if glass.range_nm is None:
        return None
    lo, hi = glass.range_nm
    if lo <= wavelength_nm <= hi:
        return None
    return f"{glass.name} ({glass.maker}) states {lo:g}-{hi:g} nm"


def _not_found(name, key, order, missing) -> str:
    searched = [c for c in order if c not in missing]
    known = {}
    for cat in searched:
        for k, g in catalog(cat).items():
            known.setdefault(k, g.name)
    import difflib

    close = difflib.get_close_matches(key, list(known), n=3, cutoff=0.6)
    msg = f"unknown glass {name!r}: not in {', '.join(searched) or 'any catalogue'}"
    if missing:
        msg += f" ({', '.join(missing)} {'is' if len(missing) == 1 else 'are'} not available: "
        msg += "give it with --glass-catalog FILE.agf)"
    elsewhere = [c for c in BUILTIN_CATALOGS if c not in order and key in (catalog(c) or {})]
    if elsewhere:
        msg += f"; {name} is in {elsewhere[0]}, which was not searched (add it to the file's GCAT line)"
    if close:
        msg += f"; nearest names: {', '.join(known[c] for c in close)}"
    return msg + "; or give the medium as nd and Vd"


_COMMON = ("SCHOTT", ["N-BK7", "N-BK10", "N-K5", "N-FK5", "N-PK51", "N-BAK4", "N-BAF10", "N-SK4", "N-SK16",
                      "N-SSK8", "N-LAK8", "N-LAK9", "N-LAK22", "N-LAF2", "N-LASF9", "F2", "N-F2", "N-SF2", "N-SF5",
                      "N-SF6", "N-SF8", "N-SF10", "N-SF11", "N-SF57"]), \
    ("OHARA", ["S-BSL7", "S-FPL51", "S-TIH6", "S-TIH53"]), ("MISC", ["F_SILICA", "CAF2"])


class _Common(Mapping):
    """:data:`GLASSES`: upper-case name -> glass for the common set, loaded on first use."""

    _table: dict | None = None

    def _get(self) -> dict:
        if _Common._table is None:
            _Common._table = {n: catalog(cat)[n] for cat, names in _COMMON for n in names if n in catalog(cat)}
        return _Common._table

    def __getitem__(self, key):
        return self._get()[key]

    def __iter__(self):
        return iter(self._get())

    def __len__(self):
        return len(self._get())


GLASSES: Mapping[str, CatalogGlass] = _Common()


def glass_names() -> list[str]:
    """The common glasses' names (:data:`GLASSES`), as printed by their makers."""
    return [g.name for g in GLASSES.values()]


#: (name, nd, Vd) of the common glasses with a formula, as the built-in catalogues give them
#: (tests/lens/test_catalog_common.py checks them against the catalogues): a medium of nd and Vd far
#: from all of them needs no catalogue read to say so (issue 43: a report's start-up).
_COMMON_ND_VD = (("N-BK7", 1.5168, 64.17), ("N-BK10", 1.49782, 66.95), ("N-K5", 1.52249, 59.48),
                 ("N-FK5", 1.48749, 70.41), ("N-PK51", 1.52855, 76.98), ("N-BAK4", 1.56883, 55.98),
                 ("N-BAF10", 1.67003, 47.11), ("N-SK4", 1.61272, 58.63), ("N-SK16", 1.62041, 60.32),
                 ("N-SSK8", 1.61773, 49.83), ("N-LAK8", 1.713, 53.83), ("N-LAK9", 1.691, 54.71),
                 ("N-LAK22", 1.65113, 55.89), ("N-LAF2", 1.74397, 44.85), ("N-LASF9", 1.85025, 32.17),
                 ("F2", 1.62004, 36.37), ("N-F2", 1.62005, 36.43), ("N-SF2", 1.64769, 33.82),
                 ("N-SF5", 1.67271, 32.25), ("N-SF6", 1.80518, 25.36), ("N-SF8", 1.68894, 31.31),
                 ("N-SF10", 1.72828, 28.53), ("N-SF11", 1.78472, 25.68), ("N-SF57", 1.84666, 23.78),
                 ("S-FPL51", 1.497, 81.54), ("S-TIH53", 1.84666, 23.78), ("F_SILICA", 1.45846, 67.82),
                 ("CAF2", 1.43385, 94.99))


def match_glass(nd: float, vd: float, tol_nd: float, tol_vd: float) -> CatalogGlass | None:
    """The one common glass (:data:`GLASSES`) with a formula within (``tol_nd``, ``tol_vd``) of
    (nd, Vd), or None when none or several match."""
    built_in = _Common._table is None and not any(cat in _USER for cat, _ in _COMMON)
    if built_in and not any(abs(n - nd) <= tol_nd and abs(v - vd) <= tol_vd for _, n, v in _COMMON_ND_VD):
        return None  # none near: the common glasses' catalogues (SCHOTT, OHARA) stay unread
    hits = [g for g in GLASSES.values()
            if g.formula is not None and abs(g.nd - nd) <= tol_nd and abs(g.vd - vd) <= tol_vd]
    return hits[0] if len(hits) == 1 else None

"""The lens library: published prescriptions shipped in ``physcam/data/lenses``, and the user's.

Each bundled lens is a physcam lens TOML with its provenance record in the ``[provenance]``
table (:mod:`physcam.lens.provenance`: primary source, transcription, checks, assumptions,
licence, and any correction made, with the reason). The user's library holds the lenses installed
with ``physcam lens add ARCHIVE`` (:func:`user_library_dir`, one folder per lens holding its
``lens.toml``); they load by name like bundled ones, and a bundled name always wins.

>>> from physcam.lens.library import list_lenses, load_lens
>>> lens = load_lens("dgauss.50mm")            # slug, name, alias or a file path
>>> [r.slug for r in list_lenses()][:2]        # doctest: +SKIP
"""

from __future__ import annotations

import contextlib
import contextvars
import math
import re
from functools import lru_cache
from pathlib import Path

from .._record import field_names, record
from ..errors import InputError, LensFileError
from .prescription import Prescription, takes_prescription

__all__ = ["LensRecord", "list_lenses", "load_lens", "find_lens", "library_dir", "user_library_dir", "load_repaired",
           "repairs_of", "bundled_lens_named", "REPAIRED_KEY", "camera_use", "require_camera_lens", "USER_LIBRARY_ENV", "USER_LENS_FILE"]

#: Environment variable naming the user's lens library folder (overrides the XDG data folder).
USER_LIBRARY_ENV = "PHYSCAM_LENS_LIBRARY"
#: The prescription file inside an installed lens's folder.
USER_LENS_FILE = "lens.toml"

#: ``extras`` key of a lens loaded with ``lenient=True`` that needed repairs (JSON list of messages).
REPAIRED_KEY = "provenance.repaired_on_load"

_FILE_SUFFIXES = (".toml", ".dat", ".json", ".zmx")

#: Set inside :func:`camera_use`: what the lenses loaded there are for ("a camera lens report").
_CAMERA_USE: contextvars.ContextVar[str | None] = contextvars.ContextVar("physcam_camera_use", default=None)


@contextlib.contextmanager
def camera_use(what: str):
    """Inside this block :func:`load_lens` refuses a finite-conjugate design (:func:`require_camera_lens`,
    ``what`` saying what needs a camera lens). The CLI runs its camera commands (report, USD
    cameras, DOF tables, exports, live, metadata) inside it: one place instead of one per command."""
    token = _CAMERA_USE.set(what)
    try:
        yield
    finally:
        _CAMERA_USE.reset(token)


@takes_prescription
def require_camera_lens(p: Prescription, label: str | None = None, what: str = "a camera lens") -> Prescription:
    """``p`` when it images an object at infinity, as a camera lens does; else :class:`InputError`
    in one line: a finite-conjugate design (a relay, a microscope objective: its file gives an
    object distance, :attr:`Prescription.object_distance_mm`) has no depth of field, focus marks
    or camera. ``label`` names it (the file), ``what`` what needs the camera lens."""
    d = p.object_distance_mm
    if math.isinf(d):
        return p
    raise InputError(f"{label or repr(p.name)} is a finite-conjugate design (object {d:g} mm in front): {what} needs "
                     "an infinite-conjugate lens (`physcam lens show` and `physcam trace` read it)")


@record(slots=True)
class LensRecord:
    """What ``physcam lenses`` lists about one lens of the library (lengths in mm)."""

    slug: str  # file stem (bundled) or folder name (user library), the canonical short name
    name: str
    maker: str | None
    focal_length: float | None  # nominal (engraved), mm
    max_fstop: float | None
    squeeze: float
    anamorphic: bool
    surfaces: int
    has_focus_groups: bool
    original_format: str | None  # pbrt, iset, seed-toml, ...
    original_file: str | None
    source: str | None  # the primary source (patent and example, book and page, ...)
    corrected: bool  # the bundled copy differs from the original file (see notes)
    aliases: tuple[str, ...]
    path: str
    licence: str | None = None  # the file's licence (SPDX identifier, NOASSERTION when unresolved)
    primary_source_checked: bool | None = None  # every number compared with the primary source itself
    t_stop: float | None = None  # the maker's stated T-stop wide open
    minimum_object_distance: float | None = None  # the maker's close focus, mm from the film plane
    library: str = "bundled"  # "bundled" (shipped with physcam) or "user" (installed with `physcam lens add`)

    def to_dict(self) -> dict:
        return {k: (list(v) if isinstance(v, tuple) else v) for k, v in
                ((f, getattr(self, f)) for f in field_names(self))}


def library_dir() -> Path:
    """Folder of the bundled lens TOML files."""
    return Path(__file__).parent.parent / "data" / "lenses"  # what importlib.resources.files gives, without it


def _key(s: str) -> str:
    """Loose match key: lower case, runs of non-alphanumerics as one '_'."""
    return re.sub(r"[^a-z0-9]+", "_", s.lower()).strip("_")


@lru_cache(maxsize=None)
def _bundled(slug: str) -> Prescription:
    """The bundled lens in ``<slug>.toml`` (read once per process)."""
    from .formats import read_lens

    return read_lens(library_dir() / f"{slug}.toml", "physcam")


@lru_cache(maxsize=1)
def _slugs() -> frozenset[str]:
    """The bundled lenses' slugs, exactly as their files are named (so a differently cased name on a
    case-insensitive file system never takes the slug path)."""
    return frozenset(p.stem for p in library_dir().glob("*.toml"))


def user_library_dir() -> Path:
    """The user's lens library: ``$PHYSCAM_LENS_LIBRARY`` when set, else ``$XDG_DATA_HOME/physcam/lenses``,
    else ``~/.local/share/physcam/lenses`` (the XDG Base Directory default). It need not exist."""
    import os

    if os.environ.get(USER_LIBRARY_ENV):
        return Path(os.environ[USER_LIBRARY_ENV]).expanduser()
    base = os.environ.get("XDG_DATA_HOME") or os.path.join(os.path.expanduser("~"), ".local", "share")
    return Path(base) / "physcam" / "lenses"


def _record(slug: str, path: Path, p: Prescription, library: str) -> LensRecord:
    from .provenance import provenance_of

    m, prov = p.metadata, provenance_of(p)
    return LensRecord(
        slug=slug, name=m.name, maker=m.maker, focal_length=m.focal_length, max_fstop=m.max_fstop,
        squeeze=p.squeeze, anamorphic=p.is_anamorphic, surfaces=len(p.surfaces), has_focus_groups=p.focus is not None,
        original_format=prov.original_format, original_file=prov.original_file, source=m.source,
        corrected=bool(prov.corrections), aliases=prov.aliases, path=str(path), licence=m.licence,
        primary_source_checked=prov.primary_source_checked, t_stop=m.t_stop,
        minimum_object_distance=m.minimum_object_distance, library=library)


@lru_cache(maxsize=1)
def _bundled_index() -> tuple[tuple[LensRecord, Prescription], ...]:
    out = []
    for path in sorted(library_dir().glob("*.toml")):
        p = _bundled(path.stem)
        out.append((_record(path.stem, path, p, "bundled"), p))
    return tuple(out)


@lru_cache(maxsize=256)
def _user_lens(path: str, mtime_ns: int, size: int) -> Prescription:
    from .formats import read_lens

    return read_lens(path, "physcam")


def _user_index() -> tuple[tuple[LensRecord, Prescription], ...]:
    """The user's installed lenses (read again whenever a lens file changes). A folder whose lens
    does not load is left out of the listing (``physcam lens check`` on its file says why)."""
    import warnings

    from ..errors import PhysCamError, PhysCamWarning

    root = user_library_dir()
    if not root.is_dir():
        return ()
    bundled = _slugs()
    out = []
    for folder in sorted(root.iterdir()):
        f = folder / USER_LENS_FILE
        if folder.name.startswith(".") or folder.name in bundled or not f.is_file():
            continue
        try:
            st = f.stat()
            p = _user_lens(str(f), st.st_mtime_ns, st.st_size)
        except (OSError, PhysCamError) as exc:
            warnings.warn(f"user lens library: {f} is left out ({exc})", PhysCamWarning, stacklevel=3)
            continue
        out.append((_record(folder.name, f, p, "user"), p))
    return tuple(out)


def _index() -> tuple[tuple[LensRecord, Prescription], ...]:
    """Every lens of the library: the bundled ones, then the user's."""
    return _bundled_index() + _user_index()


def list_lenses(library: str = "all") -> list[LensRecord]:
    """Records of the library's lenses: ``library`` "all" (the bundled ones sorted by slug, then the
    user's), "bundled" or "user"."""
    if library not in ("all", "bundled", "user"):
        raise InputError(f"library must be all, bundled or user, got {library!r}")
    return [rec for rec, _ in _index() if library in ("all", rec.library)]


def find_lens(name: str) -> LensRecord:
    """The lens whose slug, name or alias matches ``name`` (case and punctuation ignored): bundled
    lenses first, then the user's library.

    Raises :class:`InputError` naming the closest lenses when nothing matches.
    """
    key = _key(str(name))
    table: dict[str, LensRecord] = {}
    for rec, _ in _index():
        for label in (rec.slug, rec.name, *rec.aliases):
            table.setdefault(_key(label), rec)
    if key in table:
        return table[key]
    import difflib

    close = difflib.get_close_matches(key, list(table), n=3, cutoff=0.5)
    names = []
    for c in close:
        if table[c].slug not in names:
            names.append(table[c].slug)
    hint = f"; did you mean {', '.join(names)}?" if names else ""
    raise InputError(f"no bundled lens called {name!r}, nor one in your library{hint} (`physcam lenses` lists them; "
                     "a file path also works)")


def bundled_lens_named(*labels: str) -> LensRecord | None:
    """The bundled lens one of ``labels`` names (slug, name or alias; case and punctuation ignored), or
    None: a lens of the user's library may not take a bundled lens's name (it would never be found)."""
    keys = {_key(x) for x in labels}
    for rec in list_lenses("bundled"):
        if keys & {_key(x) for x in (rec.slug, rec.name, *rec.aliases)}:
            return rec
    return None


def repairs_of(p: Prescription) -> list[str]:
    """The repairs made when ``p`` was loaded with ``lenient=True`` ([] for a lens loaded as written)."""
    from .formats._common import extra

    return list(extra(p, REPAIRED_KEY, []))


def load_repaired(path, format: str | None = None):
    """Read a lens file without validation and repair it as ``physcam lens fix`` would.

    Returns ``(prescription, repairs)``; the prescription is validated and, when repairs were
    made, named "<name> (repaired)" and carries them in ``extras`` (:data:`REPAIRED_KEY`) and in
    ``[provenance] corrections``. Raises :class:`LensFileError` when no repair is defined.
    """
    from .._record import replace

    from .raw import read_raw
    from .formats._common import json_text
    from .repair import propose, with_corrections

    raw = read_raw(path, format)
    try:
        q, repairs = propose(raw.prescription)
    except (ArithmeticError, ValueError) as exc:
        raise LensFileError(f"no repair is defined for this lens ({exc})", str(path)) from None
    if repairs:
        q = with_corrections(q, repairs)
        extras = dict(q.extras)
        extras[REPAIRED_KEY] = json_text([r.message for r in repairs])
        q = replace(q, metadata=replace(q.metadata, name=f"{q.metadata.name} (repaired)"),
                                extras=tuple(sorted(extras.items())))
    try:
        q.validate(str(path), list(raw.lines))
    except LensFileError as exc:
        raise LensFileError(f"{exc.reason} (even after the repairs `physcam lens fix` knows: no repair is defined; "
                            "`physcam lens check` lists every problem)", exc.path, exc.line) from None
    except (ArithmeticError, ValueError) as exc:
        raise LensFileError(f"lens geometry cannot be evaluated ({exc})", str(path)) from None
    return q, repairs


def _way_forward(path: Path, s: str) -> str:
    """What to suggest after ``path`` failed to load: ``lens fix`` and ``--lenient`` only when
    :func:`load_repaired` does repair it; ``lens check`` alone when the reader read the rows but no
    repair is defined; nothing more when the reader itself refused the file (its message says why)."""
    import warnings

    from ..errors import PhysCamError
    from .raw import read_raw

    try:
        read_raw(path)
    except PhysCamError:
        return ""
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            load_repaired(path)
    except PhysCamError:
        return f"; no repair is defined for it (`physcam lens check --lens {s}` lists every problem)"
    return (f"; `physcam lens check --lens {s}` explains, `physcam lens fix --lens {s} -o FIXED.toml --apply` writes a repaired "
            "copy, --lenient (Python: load_lens(path, lenient=True)) loads it repaired")


def load_lens(name_or_path, lenient: bool = False) -> Prescription:
    """A bundled lens by slug/name/alias, or any lens file by path (format from its extension).

    A string with a path separator or a lens-file extension that names an existing file
    is read as a file; otherwise it is looked up in the library, and where no lens there has the
    name, a file of that name (``lens file.txt``, ``vendor.lens.zip`` in the current folder) is read.

    A file that does not describe a buildable lens raises :class:`LensFileError` whose message
    says how to get further (``physcam lens fix`` and ``lenient`` only where a repair is defined). With ``lenient=True`` such a file is repaired as ``physcam lens fix``
    would (:func:`load_repaired`): each repair is issued as a :class:`~physcam.errors.PhysCamWarning`
    and the lens comes back named "<name> (repaired)" with the repairs in :func:`repairs_of`.
    Inside :func:`camera_use` a finite-conjugate design is refused (:func:`require_camera_lens`).
    """
    what = _CAMERA_USE.get()
    lens = _load(name_or_path, lenient)
    return lens if what is None else require_camera_lens(lens, str(name_or_path), what)


def _read_file(p: Path, s: str, lenient: bool) -> Prescription:
    """The lens file ``p`` (named ``s`` by the caller), repaired as ``physcam lens fix`` would when ``lenient``."""
    from .formats import read_lens

    try:
        return read_lens(p)
    except LensFileError as exc:
        if not lenient:
            raise LensFileError(f"{exc.reason}{_way_forward(p, s)}", exc.path, exc.line) from None
        import warnings

        from ..errors import PhysCamWarning

        q, repairs = load_repaired(p)
        for r in repairs:
            warnings.warn(f"{s}: repaired on load: {r.message}", PhysCamWarning, stacklevel=4)
        return q


def _load(name_or_path, lenient: bool) -> Prescription:
    s = str(name_or_path)
    p = Path(s)
    looks_like_path = isinstance(name_or_path, Path) or "/" in s or "\\" in s or p.suffix.lower() in _FILE_SUFFIXES
    if p.is_file() and looks_like_path:
        return _read_file(p, s, lenient)
    if not looks_like_path and s in _slugs():
        # a slug, as the CLI is usually given it: read that one file, not the whole library (the
        # index reads every bundled lens, 25 ms). The same object the index holds;
        # tests/lens/test_library.py checks that no slug is another lens's name or alias.
        return _bundled(s)
    try:
        rec = find_lens(s)
    except InputError:
        if looks_like_path and p.suffix.lower() in _FILE_SUFFIXES:
            raise InputError(f"{s}: no such lens file, and no bundled lens of that name") from None
        if p.is_file():  # no lens of the library has the name: the file of that name here is the one meant
            return _read_file(p, s, lenient)
        raise
    for r, lens in _index():
        if r.slug == rec.slug:
            return lens
    raise AssertionError("unreachable")  # pragma: no cover

"""A lens published as one archive: prescription, USD lens file, lens card and provenance (issue 44).

A lens archive (``NAME.lens.zip``, a ZIP file; docs/lens-library.md) holds, flat:

* ``lens.toml`` — the prescription in physcam lens TOML, with its ``[provenance]`` record;
* ``lens.usda`` — the vendor lens file of the "Physical Cameras for USD" proposal (seed 001):
  ``/Lens`` with the detailed model (the prescription) and its best-match pinhole, a ``lensModel``
  variant choosing which renders (:func:`physcam.usd.kit.write_vendor_lens`), and optionally a
  ``characterization`` variant set: one variant per measuring run holding what was measured
  (``physcam:characterization:NAME`` attributes, as :func:`physcam.usd.kit.read_characterizations`
  reads them) and ``current``, a copy of the latest, selected;
* ``card.pdf`` — the lens card (:mod:`physcam.analysis.lens_cards.card`);
* ``provenance.json`` — the provenance record (:class:`physcam.lens.provenance.Provenance`), the
  one ``lens.toml`` carries, for tools that do not read TOML;
* ``manifest.json`` — ``{"format": "physcam-lens-archive/1", "slug", "name", "files": {name:
  {"size", "sha256"}}, ...}``, what the archive holds and the focus, f-stop and sensor its USD
  pinhole and card were made at.

:func:`pack_lens` writes one, :func:`check_archive` finds what is wrong with one (the lens checks of
:mod:`physcam.lens.check` on its prescription, plus the archive's own: members, checksums, the
provenance a published lens must carry, the USD file's validity and that its prescription is the
TOML's), :func:`add_lens` installs a valid one into the user's lens library
(:func:`physcam.lens.library.user_library_dir`), where :func:`physcam.lens.library.load_lens`
finds it by name.
"""

from __future__ import annotations

import datetime
import hashlib
import io
import json
import math
import re
import tempfile
import zipfile
from pathlib import Path

from ..errors import ExportError, InputError
from ..lens.check import Finding

__all__ = ["ARCHIVE_FORMAT", "MEMBERS", "pack_lens", "check_archive", "add_lens", "read_manifest", "is_archive",
           "SLUG_PATTERN"]

ARCHIVE_FORMAT = "physcam-lens-archive/1"
#: The files of an archive, every one required.
MEMBERS = ("manifest.json", "lens.toml", "lens.usda", "card.pdf", "provenance.json")
#: A slug: the lens's name in a library (lower-case letters, digits and underscores).
SLUG_PATTERN = re.compile(r"[a-z0-9][a-z0-9_]{0,63}")
#: Largest member read from an archive (a lens card is a few hundred kB, a USD lens file tens).
MAX_MEMBER_BYTES = 64 * 1024 * 1024
_ZIP_DATE = (2000, 1, 1, 0, 0, 0)  # every member's timestamp: the same lens packs to the same bytes


def is_archive(path) -> bool:
    """True when ``path`` is a file named ``*.zip`` or a ZIP file: a lens archive, or something that
    :func:`check_archive` refuses as one."""
    p = Path(path)
    return p.is_file() and (p.suffix.lower() == ".zip" or zipfile.is_zipfile(p))


def _slug(text: str) -> str:
    s = re.sub(r"[^a-z0-9]+", "_", str(text).lower()).strip("_")[:64]
    if not SLUG_PATTERN.fullmatch(s):
        raise InputError(f"cannot make a lens name (slug) from {text!r}: give --slug of letters, digits and "
                         "underscores")
    return s


def _digest(data: bytes) -> dict:
    return {"size": len(data), "sha256": hashlib.sha256(data).hexdigest()}


def _with_provenance(prescription, source: str | None, licence: str | None):
    """``prescription`` with ``source``/``licence`` filled in; InputError when a published lens would lack them."""
    import dataclasses

    m = prescription.metadata
    m = dataclasses.replace(m, source=source or m.source, licence=licence or m.licence)
    missing = [k for k in ("source", "licence") if not getattr(m, k)]
    if missing:
        raise InputError(f"lens {m.name!r} has no {' and no '.join(missing)}: a published lens names its primary "
                         "source and the file's licence (the lens file's [provenance] table, or --source and "
                         "--licence, e.g. --licence CC-BY-4.0)")
    return dataclasses.replace(prescription, metadata=m)


def pack_lens(prescription, archive, *, slug: str | None = None, focus_mm: float = math.inf,
              fstop: float | None = None, sensor=None, characterizations: dict | None = None,
              source: str | None = None, licence: str | None = None, draft: bool = False, force: bool = False):
    """Write the lens archive ``archive`` of ``prescription`` (module notes) and return its Path.

    ``focus_mm`` (from the film plane) and ``fstop`` (None: wide open) are where the USD file's
    best-match pinhole and the lens card are evaluated (a USD focus is finite: infinity is written
    as 1 km); ``sensor`` an :class:`~physcam.optics.sensors.Sensor` (default Super 35).
    ``characterizations`` maps a variant name (letters, digits, underscores; sorted, the last is
    ``current``) to what was measured that run (name -> number, numbers or text). ``source`` and
    ``licence`` fill the lens's provenance where its file gives none (a published lens must have
    both). ``draft`` makes a quick card.
    """
    from ..io import atomic_write, check_writable
    from ..lens.formats import dumps_lens
    from ..lens.prescription import require_prescription
    from ..lens.provenance import provenance_of

    require_prescription(prescription)
    check_writable(archive, force=force)
    p = _with_provenance(prescription, source, licence)
    slug = _slug(slug or p.name)
    sensor = sensor or _default_sensor()
    usd_focus = focus_mm if math.isfinite(focus_mm) else 1.0e6
    with tempfile.TemporaryDirectory(prefix="physcam-pack-") as tmp:
        files = {"lens.toml": dumps_lens(p, "physcam").encode("utf-8"),
                 "lens.usda": _usd_bytes(p, Path(tmp), usd_focus, fstop, sensor, characterizations or {}),
                 "card.pdf": _card_bytes(p, Path(tmp), focus_mm, sensor, draft),
                 "provenance.json": (json.dumps(provenance_of(p).to_dict(), indent=1, ensure_ascii=False)
                                     + "\n").encode("utf-8")}
    manifest = {"format": ARCHIVE_FORMAT, "slug": slug, "name": p.name,
                "created": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
                "physcam": _version(), "focus_mm": None if not math.isfinite(focus_mm) else focus_mm,
                "usd_focus_mm": usd_focus, "fstop": fstop,
                "sensor": {"name": sensor.name, "width_mm": sensor.width_mm, "height_mm": sensor.height_mm},
                "characterizations": sorted(characterizations or {}),
                "files": {name: _digest(data) for name, data in files.items()}}
    files = {"manifest.json": (json.dumps(manifest, indent=1, ensure_ascii=False) + "\n").encode("utf-8"), **files}
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w", compression=zipfile.ZIP_DEFLATED) as z:
        for name in MEMBERS:
            z.writestr(zipfile.ZipInfo(name, _ZIP_DATE), files[name], compress_type=zipfile.ZIP_DEFLATED)
    return atomic_write(archive, buf.getvalue(), force=force)


def _default_sensor():
    from ..optics.sensors import find_sensor

    return find_sensor("Super 35")


def _version() -> str:
    from .. import __version__

    return __version__


def _usd_bytes(p, tmp: Path, focus_mm, fstop, sensor, characterizations) -> bytes:
    from .kit import write_vendor_lens

    f = tmp / "lens.usda"
    write_vendor_lens(f, p, focus_mm=focus_mm, fstop=fstop, sensor_width_mm=sensor.width_mm,
                      sensor_height_mm=sensor.height_mm)
    if characterizations:
        _author_characterizations(f, characterizations)
    return f.read_bytes()


def _author_characterizations(file: Path, runs: dict) -> None:
    """Variant set ``characterization`` on ``/Lens`` of the vendor file ``file``: one variant per run
    with only its measured values (``physcam:characterization:NAME``; the lens's own attributes stay
    the file's local opinions, which a variant could not override) and ``current``, a copy of the
    last run, selected; ``customData physcam:currentIs`` names it (as :mod:`physcam.usd.kit` does)."""
    from .author import save_stage
    from .kit import LENS_PRIM, _author_measured, _open_detached, _variant_identifier

    names = sorted(_variant_identifier(n) for n in runs)
    stage = _open_detached(file)
    prim = stage.GetPrimAtPath(LENS_PRIM)
    vset = prim.GetVariantSets().AddVariantSet("characterization")
    for name, run in [(n, runs[n]) for n in names] + [("current", runs[names[-1]])]:
        vset.AddVariant(name)
        vset.SetVariantSelection(name)
        with vset.GetVariantEditContext():
            _author_measured(prim, {k: ([v] if isinstance(v, (int, float)) else v) for k, v in run.items()})
    vset.SetVariantSelection("current")
    prim.SetCustomDataByKey("physcam:currentIs", names[-1])
    save_stage(stage, file, force=True)


def _card_bytes(p, tmp: Path, focus_mm, sensor, draft) -> bytes:
    from ..analysis.lens_cards.card import lens_card, save_lens_card

    card = lens_card(p, focus_mm=focus_mm, sensor_width_mm=sensor.width_mm, sensor_height_mm=sensor.height_mm,
                     sensor_name=sensor.name, quality="draft" if draft else "full")
    return Path(save_lens_card(card, tmp / "card.pdf")).read_bytes()


# ---- reading and checking -------------------------------------------------------------------
def _members(archive) -> dict[str, bytes]:
    """The archive's members by name; InputError for anything that is not a flat, bounded lens archive."""
    p = Path(archive)
    try:
        with zipfile.ZipFile(p) as z:
            infos = z.infolist()
            out = {}
            for info in infos:
                name = info.filename
                if name not in MEMBERS:
                    raise InputError(f"{p}: {name!r} is not a member of a lens archive ({', '.join(MEMBERS)})")
                if info.file_size > MAX_MEMBER_BYTES:
                    raise InputError(f"{p}: {name} is {info.file_size} bytes; at most {MAX_MEMBER_BYTES} are read")
                if name in out:
                    raise InputError(f"{p}: {name} is in the archive twice")
                out[name] = z.read(info)
    except (zipfile.BadZipFile, zipfile.LargeZipFile, OSError, EOFError, ValueError, NotImplementedError) as exc:
        raise InputError(f"{p}: not a readable lens archive ({exc})") from None
    missing = [m for m in MEMBERS if m not in out]
    if missing:
        raise InputError(f"{p}: a lens archive holds {', '.join(MEMBERS)}; {', '.join(missing)} missing")
    return out


def read_manifest(archive) -> dict:
    """The archive's ``manifest.json`` (InputError when the archive or its manifest is not readable)."""
    data = _members(archive)["manifest.json"]
    try:
        doc = json.loads(data.decode("utf-8"))
    except (UnicodeDecodeError, ValueError, RecursionError):
        raise InputError(f"{archive}: manifest.json is not JSON") from None
    if not isinstance(doc, dict) or doc.get("format") != ARCHIVE_FORMAT:
        raise InputError(f"{archive}: manifest.json is not a {ARCHIVE_FORMAT} manifest")
    return doc


def check_archive(archive, *, probes=()) -> list[Finding]:
    """Findings about the lens archive ``archive`` (never raises for a bad archive: one ``error``
    finding says why it cannot be read). ``probes`` are the ray checks of :func:`physcam.lens.check.check`."""
    where = str(archive)
    try:
        files, manifest = _members(archive), read_manifest(archive)
    except InputError as exc:
        return [Finding("error", "archive_unreadable", str(exc), "not a lens archive physcam can install", file=where)]
    out = _manifest_findings(manifest, files, where)
    with tempfile.TemporaryDirectory(prefix="physcam-check-") as tmp:
        toml = Path(tmp) / "lens.toml"
        toml.write_bytes(files["lens.toml"])
        out += _lens_findings(toml, probes, f"{where}!lens.toml")
        usd = Path(tmp) / "lens.usda"
        usd.write_bytes(files["lens.usda"])
        out += _usd_findings(usd, toml, f"{where}!lens.usda")
    out += _provenance_findings(files, f"{where}!lens.toml")
    if not files["card.pdf"].startswith(b"%PDF-"):
        out.append(Finding("error", "card_not_pdf", "card.pdf is not a PDF file", "the lens card is missing",
                           file=f"{where}!card.pdf"))
    order = {"error": 0, "warning": 1, "note": 2}
    return sorted(out, key=lambda f: order[f.severity])


def _manifest_findings(manifest: dict, files: dict, where: str) -> list[Finding]:
    out = []
    slug = manifest.get("slug")
    if not isinstance(slug, str) or not SLUG_PATTERN.fullmatch(slug):
        out.append(Finding("error", "archive_slug", f"manifest slug {slug!r} is not a lens name (lower-case letters, "
                           "digits, underscores)", "it cannot be installed under that name", file=where))
    listed = manifest.get("files") if isinstance(manifest.get("files"), dict) else {}
    for name in MEMBERS[1:]:
        want = listed.get(name)
        if not isinstance(want, dict) or want.get("sha256") != _digest(files[name])["sha256"]:
            out.append(Finding("error", "archive_checksum", f"{name} does not match the manifest's SHA-256",
                               "the archive was changed or damaged after it was packed", file=where))
    return out


def _lens_findings(toml: Path, probes, where: str) -> list[Finding]:
    from ..lens.check import check

    out = []
    for f in check(toml, format="physcam", probes=probes):
        if f.code == "licence_unresolved":
            continue  # a published lens: the archive's own warning says it
        code = "archive_lens_unreadable" if f.code == "unreadable" else f.code
        out.append(Finding(f.severity, code, f.message, f.implication, f.surface, f.line, where, f.values))
    return out


def _usd_findings(usd: Path, toml: Path, where: str) -> list[Finding]:
    from ..errors import PhysCamError
    from ..lens.formats import read_lens
    from .read import composed_prescription, open_stage
    from .validate import validation_errors

    try:
        stage = open_stage(usd)
        errors = validation_errors(stage)
        rx = composed_prescription(stage, "/Lens")
        lens = read_lens(toml, "physcam")
    except (PhysCamError, ArithmeticError, ValueError) as exc:
        return [Finding("error", "usd_unreadable", str(exc).splitlines()[0], "the archive's USD lens file cannot be "
                        "used", file=where)]
    out = [Finding("error", "usd_invalid", e, "usd-core's validators refuse the lens file", file=where) for e in errors]
    if rx is None:
        out.append(Finding("error", "usd_no_prescription", "/Lens has no PhysicalCameraLensModelPrescription",
                           "the archive's USD file is not a vendor lens file (physcam lens pack writes one)", file=where))
    elif _numbers(rx) != _numbers(lens):
        out.append(Finding("error", "usd_prescription_differs", "the USD file's prescription is not lens.toml's",
                           "the two files describe different lenses", file=where))
    return out


def _numbers(p):
    return [(s.kind, s.radius, s.thickness, s.semi_diameter, s.conic, s.aspheric, s.medium.nd, s.medium.vd,
             s.medium.glass) for s in p.surfaces]


def _provenance_findings(files: dict, where: str) -> list[Finding]:
    from ..errors import PhysCamError
    from ..lens.formats import loads_lens
    from ..lens.provenance import provenance_of

    try:
        prov = provenance_of(loads_lens(files["lens.toml"].decode("utf-8"), "physcam"))
        packed = json.loads(files["provenance.json"].decode("utf-8"))
    except (PhysCamError, UnicodeDecodeError, ValueError, RecursionError):
        return []  # lens.toml's own finding says why it does not load
    out = []
    for key in ("source", "licence"):
        if not getattr(prov, key):
            out.append(Finding("error", "provenance_missing", f"[provenance] gives no {key}",
                               "a published lens names its primary source and the file's licence", file=where))
    if prov.licence and not prov.licence_resolved:
        out.append(Finding("warning", "licence_unresolved", f"licence {prov.licence}: nobody has established it",
                           "others may not be free to use or share the file", file=where))
    if packed != prov.to_dict():
        out.append(Finding("error", "provenance_differs", "provenance.json is not lens.toml's [provenance] record",
                           "the two say different things about where the numbers come from", file=where))
    return out


# ---- installing -----------------------------------------------------------------------------------
def add_lens(archive, *, force: bool = False) -> tuple[str, Path]:
    """Install the lens archive ``archive`` into the user's lens library after :func:`check_archive`
    finds no error; returns ``(slug, folder)``. The folder ``<user library>/<slug>/`` holds the
    archive's files (written as a whole, :func:`physcam.io.staged_folder`). Refused: an archive with
    errors, a slug, name or alias of a bundled lens, and an installed lens of that slug unless
    ``force`` (which replaces only a folder physcam wrote)."""
    from ..io import staged_folder
    from ..lens.formats import loads_lens
    from ..lens.library import bundled_lens_named, user_library_dir
    from ..lens.provenance import provenance_of

    findings = check_archive(archive)
    errors = [f for f in findings if f.severity == "error"]
    if errors:
        raise InputError(f"{archive}: not installed: {len(errors)} error(s), the first: {errors[0].message} "
                         f"(`physcam lens check --lens {archive}` lists them)")
    files, manifest = _members(archive), read_manifest(archive)
    slug = manifest["slug"]
    lens = loads_lens(files["lens.toml"].decode("utf-8"), "physcam")
    rec = bundled_lens_named(slug, lens.name, *provenance_of(lens).aliases)
    if rec is not None:
        raise InputError(f"{archive}: lens {slug!r} ({lens.name}) has a name of the bundled lens {rec.slug!r}; "
                         "pack it under another name (physcam lens pack --slug) and lens name")
    folder = user_library_dir() / slug
    if folder.exists() and not force:
        raise InputError(f"{folder} exists: lens {slug!r} is installed already (--force replaces it)")
    try:
        with staged_folder(folder, force=force, about={"archive": Path(archive).name, "slug": slug,
                                                         "sha256": hashlib.sha256(Path(archive).read_bytes()).hexdigest()}) as tmp:
            for name, data in files.items():
                (tmp / name).write_bytes(data)
    except ExportError as exc:
        raise InputError(f"cannot install lens {slug!r}: {exc}") from None
    return slug, folder

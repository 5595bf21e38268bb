"""physcam's own lens TOML: every field of a :class:`Prescription`, by explicit name.

Layout (docs/lens-formats.md)::

    format = "physcam-lens/1"
    [lens]        name, maker?, patent?, focal_length?, max_fstop?, t_stop?, coating?,
                  minimum_object_distance? (mm from the film plane), squeeze? (1),
                  wavelength_nm? (587.5618)
    [provenance]  source?, notes?, licence?, and the rest of the record (physcam.lens.provenance:
                  source_url, transcribed, checks, assumptions, ...; original_file, corrections,
                  aliases, ...) kept in Prescription.extras as "provenance.<key>"
    [[surface]]   kind, radius, thickness, semi_diameter, medium, conic?, aspheric?
                  medium = "air" | { nd = 1.5168, vd = 64.17, glass? = "N-BK7", catalog? = "SCHOTT",
                                     dpgf? = 0.0 } | { glass = "N-BK7", catalog? = "SCHOTT" }
    [focus]       close_distance (mm from the front vertex)
    [[focus.gap]] surface (0-based), thickness_infinity?, thickness_close
    [extras]      "key" = "JSON text"  (blocks of other formats, e.g. ISET's microlens)

``semi_diameter`` is the clear semi-diameter (half the clear aperture), all lengths in
mm. A medium given only by a glass name takes nd and Vd from
:mod:`physcam.lens.catalog` (searched in ``catalog`` first when given); an unknown name is an
error. ``dpgf`` is a model glass's P_gF deviation from the normal line.
"""

from __future__ import annotations

import json
from pathlib import Path

from ...errors import InputError, LensFileError
from ..catalog import find_glass
from ..prescription import AIR, SURFACE_KINDS, Focus, LensMetadata, Medium, Prescription, Surface, takes_prescription
from ..provenance import ORDER as PROVENANCE_ORDER, check_provenance_table
from ._common import (
    takes_text,
    MAX_SURFACES,
    focus_table,
    surface_rows,
    number,
    parse_toml,
    table,
    text_field,
    toml_key,
    toml_value,
    unknown_keys,
    validated,
)

__all__ = ["loads", "dumps", "FORMAT_TAG"]

FORMAT_TAG = "physcam-lens/1"
LENS_KEYS = ("name", "maker", "patent", "focal_length", "max_fstop", "t_stop", "coating", "minimum_object_distance",
             "squeeze", "wavelength_nm")
SURFACE_KEYS = ("kind", "radius", "thickness", "semi_diameter", "medium", "conic", "aspheric")
DEFAULT_WAVELENGTH = Prescription.__dataclass_fields__["wavelength_nm"].default


def _medium(v, where, path, ln) -> Medium:
    if v == "air":
        return AIR
    if not isinstance(v, dict):
        raise LensFileError(f"{where}: medium must be \"air\" or a table {{ nd, vd, glass }}", path, ln)
    unknown_keys(v, ("nd", "vd", "glass", "catalog", "dpgf"), f"{where} medium", path, ln)
    glass, cat = v.get("glass"), v.get("catalog")
    if (glass is not None and not isinstance(glass, str)) or (cat is not None and not isinstance(cat, str)):
        raise LensFileError(f"{where}: glass and catalog must be names (strings)", path, ln)
    dpgf = number(v.get("dpgf", 0.0), f"{where} dpgf", path, ln, length=False)
    if "nd" in v:
        nd = number(v["nd"], f"{where} nd", path, ln, length=False)
        vd = number(v.get("vd", 0.0), f"{where} vd", path, ln, length=False)
    elif glass is not None:
        try:
            g = find_glass(glass, [cat] if cat else None)
        except InputError as exc:
            raise LensFileError(f"{where}: {exc}", path, ln) from None
        nd, vd = g.nd, g.vd
        if "vd" in v:
            vd = number(v["vd"], f"{where} vd", path, ln, length=False)
    else:
        raise LensFileError(f"{where}: medium needs nd (and vd) or a catalogue glass name", path, ln)
    return Medium(nd, vd, glass, cat, dpgf)


@takes_text
def loads(text: str, path=None, name: str | None = None) -> Prescription:
    """Parse physcam lens TOML into a validated :class:`Prescription`."""
    doc = parse_toml(text, path)
    return loads_document(doc, text, path, name)


def loads_document(doc: dict, text: str, path=None, name: str | None = None) -> Prescription:
    unknown_keys(doc, ("format", "lens", "provenance", "surface", "focus", "extras"), "top level", path)
    tag = doc.get("format", FORMAT_TAG)
    if tag != FORMAT_TAG:
        raise LensFileError(f"format {tag!r} is not {FORMAT_TAG!r}", path, 1)
    lens = table(doc.get("lens", {}), "[lens]", path)
    unknown_keys(lens, LENS_KEYS, "[lens]", path)
    rows, lines = surface_rows(doc, text, path)
    surfaces = []
    for i, row in enumerate(rows):
        ln = lines[i]
        where = f"surface {i}"
        row = table(row, where, path, ln)
        unknown_keys(row, SURFACE_KEYS, where, path, ln)
        for key in ("kind", "radius", "thickness", "semi_diameter", "medium"):
            if key not in row:
                raise LensFileError(f"{where} has no {key!r}", path, ln)
        kind = row["kind"]
        if kind not in SURFACE_KINDS:
            raise LensFileError(f"{where}: unknown kind {kind!r}; use one of {', '.join(SURFACE_KINDS)}", path, ln)
        aspheric = row.get("aspheric", [])
        if not isinstance(aspheric, list) or len(aspheric) > MAX_SURFACES:
            raise LensFileError(f"{where}: aspheric must be a list [A4, A6, ...]", path, ln)
        surfaces.append(
            Surface(
                radius=number(row["radius"], f"{where} radius", path, ln),
                thickness=number(row["thickness"], f"{where} thickness", path, ln),
                medium=_medium(row["medium"], where, path, ln),
                semi_diameter=number(row["semi_diameter"], f"{where} semi_diameter", path, ln),
                kind=kind,
                conic=number(row.get("conic", 0.0), f"{where} conic", path, ln, length=False),
                aspheric=tuple(number(a, f"{where} aspheric coefficient", path, ln, length=False) for a in aspheric),
            )
        )
    focus = None
    if "focus" in doc:
        focus = _focus(table(doc["focus"], "[focus]", path), surfaces, text, path)
    prov = table(doc.get("provenance", {}), "[provenance]", path)
    check_provenance_table(prov, path)
    extras = [(f"provenance.{k}", _json(v, f"[provenance] {k}", path)) for k, v in prov.items() if k not in ("source", "notes", "licence")]
    for k, v in table(doc.get("extras", {}), "[extras]", path).items():
        if not isinstance(v, str):
            raise LensFileError(f"[extras] {k!r} must be a JSON text string", path)
        try:
            json.loads(v)
        except (ValueError, RecursionError):
            raise LensFileError(f"[extras] {k!r} is not valid JSON text", path) from None
        extras.append((k, v))
    extras.sort()
    def opt(key):
        return None if key not in lens else number(lens[key], f"[lens] {key}", path, None)
    meta = LensMetadata(
        name=text_field(lens, "name", "[lens]", path) or name or (Path(path).stem if path else "unnamed lens"),
        maker=text_field(lens, "maker", "[lens]", path),
        patent=text_field(lens, "patent", "[lens]", path),
        focal_length=opt("focal_length"),
        max_fstop=opt("max_fstop"),
        coating=text_field(lens, "coating", "[lens]", path),
        minimum_object_distance=opt("minimum_object_distance"),
        t_stop=opt("t_stop"),
        source=text_field(prov, "source", "[provenance]", path),
        notes=text_field(prov, "notes", "[provenance]", path),
        licence=text_field(prov, "licence", "[provenance]", path),
    )
    p = Prescription(
        tuple(surfaces),
        meta,
        focus,
        number(lens.get("squeeze", 1.0), "[lens] squeeze", path, None, length=False),
        number(lens.get("wavelength_nm", DEFAULT_WAVELENGTH), "[lens] wavelength_nm", path, None),
        tuple(extras),
    )
    mod, tstop = meta.minimum_object_distance, meta.t_stop
    if mod is not None and mod <= 0.0:
        raise LensFileError(f"[lens] minimum_object_distance {mod:g} must be a positive distance in mm from the film", path)
    if tstop is not None and not (meta.max_fstop or 0.5) <= tstop <= 1000.0:
        raise LensFileError(f"[lens] t_stop {tstop:g} cannot be faster than the lens's f-number "
                            f"(max_fstop {meta.max_fstop or 0.5:g}): a T-stop counts the light the glass loses", path)
    if not 200.0 <= p.wavelength_nm <= 20000.0:
        raise LensFileError(f"[lens] wavelength_nm {p.wavelength_nm:g} is not an optical wavelength in nm", path)
    return validated(p, path, lines)


def _json(v, where, path) -> str:
    try:
        return json.dumps(v, separators=(",", ":"), ensure_ascii=False, allow_nan=False)
    except (TypeError, ValueError):
        raise LensFileError(f"{where}: only strings, numbers, booleans and lists are kept", path) from None


def _focus(f: dict, surfaces, text, path) -> Focus:
    return focus_table(f, surfaces, text, path, "gap")


@takes_prescription
def dumps(p: Prescription) -> str:
    """physcam lens TOML for ``p`` (lossless: :func:`loads` gives back an equal Prescription)."""
    m = p.metadata
    out = ["# physcam lens prescription; lengths in mm, +z toward the film (docs/lens-formats.md)",
           f"format = {toml_value(FORMAT_TAG)}", "", "[lens]", f"name = {toml_value(m.name)}"]
    for key in ("maker", "patent", "focal_length", "max_fstop", "t_stop", "coating", "minimum_object_distance"):
        v = getattr(m, key)
        if v is not None:
            out.append(f"{key} = {toml_value(float(v) if isinstance(v, (int, float)) else v)}")
    if p.squeeze != 1.0:
        out.append(f"squeeze = {toml_value(float(p.squeeze))}")
    if p.wavelength_nm != DEFAULT_WAVELENGTH:
        out.append(f"wavelength_nm = {toml_value(float(p.wavelength_nm))}")
    prov, extras = {}, []
    for k, v in p.extras:
        value = json.loads(v)
        if k.startswith("provenance.") and _plain(value) and k[len("provenance."):] not in ("source", "notes", "licence"):
            prov[k[len("provenance."):]] = value
        else:
            extras.append(f"{toml_key(k)} = {toml_value(v)}")
    prov.update({key: getattr(m, key) for key in ("source", "licence", "notes") if getattr(m, key) is not None})
    if prov:
        out += ["", "[provenance]"]
        for key in sorted(prov, key=lambda k: (PROVENANCE_ORDER.index(k) if k in PROVENANCE_ORDER else 99, k)):
            out.append(_provenance_line(key, prov[key]))
    for s in p.surfaces:
        out += ["", "[[surface]]", f"kind = {toml_value(s.kind)}", f"radius = {toml_value(float(s.radius))}",
                f"thickness = {toml_value(float(s.thickness))}", f"semi_diameter = {toml_value(float(s.semi_diameter))}"]
        if s.medium == AIR:
            out.append('medium = "air"')
        else:
            parts = [f"nd = {toml_value(float(s.medium.nd))}", f"vd = {toml_value(float(s.medium.vd))}"]
            if s.medium.glass is not None:
                parts.append(f"glass = {toml_value(s.medium.glass)}")
            if s.medium.catalog is not None:
                parts.append(f"catalog = {toml_value(s.medium.catalog)}")
            if s.medium.dpgf != 0.0:
                parts.append(f"dpgf = {toml_value(float(s.medium.dpgf))}")
            out.append("medium = { " + ", ".join(parts) + " }")
        if s.conic != 0.0 or s.kind == "aspheric":
            out.append(f"conic = {toml_value(float(s.conic))}")
        if s.aspheric:
            out.append(f"aspheric = {toml_value([float(a) for a in s.aspheric])}")
    if p.focus is not None:
        out += ["", "[focus]", f"close_distance = {toml_value(float(p.focus.close_distance))}"]
        for g in p.focus.gaps:
            out += ["", "[[focus.gap]]", f"surface = {int(g.surface)}",
                    f"thickness_infinity = {toml_value(float(g.thickness_infinity))}",
                    f"thickness_close = {toml_value(float(g.thickness_close))}"]
    if extras:
        out += ["", "[extras]"] + extras
    return "\n".join(out) + "\n"


def _provenance_line(key: str, value) -> str:
    """``key = value``; a list of more than one string one item a line, so a record reads as a list."""
    if isinstance(value, list) and len(value) > 1 and all(isinstance(x, str) for x in value):
        return f"{toml_key(key)} = [\n" + "".join(f"    {toml_value(x)},\n" for x in value) + "]"
    return f"{toml_key(key)} = {toml_value(value)}"


def _plain(v) -> bool:
    if isinstance(v, (str, bool, int, float)):
        return True
    return isinstance(v, list) and all(isinstance(x, (str, bool, int, float)) for x in v) and len({type(x) for x in v}) <= 1

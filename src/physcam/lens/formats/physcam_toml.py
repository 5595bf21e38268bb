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
    [zoom]        encoder? (0..1 per position; default evenly spaced), stop_semi_diameter?,
                  close_distance? (mm from the front vertex, per position), stated_focal_length?
    [[zoom.gap]]  surface (0-based), thickness (one per position), thickness_close? (per position)
    [extras]      "key" = "JSON text"  (blocks of other formats, e.g. ISET's microlens)

A zoom lens's ``[[surface]]`` rows hold its first zoom position; with ``close_distance`` the
``[focus]`` table is not written (the focus groups are the zoom table's, position by position).

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
from ..prescription import (AIR, SURFACE_KINDS, Focus, LensMetadata, Medium, Prescription, Surface, VariableGap, Zoom,
                            ZoomGap, takes_prescription)
from ..provenance import ORDER as PROVENANCE_ORDER, check_provenance_table
from ._common import (
    takes_text,
    MAX_SURFACES,
    focus_table,
    surface_rows,
    number,
    parse_toml,
    table,
    table_lines,
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
DEFAULT_WAVELENGTH = Prescription.wavelength_nm  # the field's default (a class attribute)


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
    unknown_keys(doc, ("format", "lens", "provenance", "surface", "focus", "zoom", "extras"), "top level", path)
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
    zoom = None
    if "zoom" in doc:
        zoom = _zoom(table(doc["zoom"], "[zoom]", path), text, path)
        if zoom.close_distance is not None:
            if focus is not None:
                raise LensFileError("a zoom table with close_distance gives the focus groups position by position: "
                                    "leave out [focus]", path)
            focus = Focus(zoom.close_distance[0], tuple(VariableGap(g.surface, g.thickness[0], g.thickness_close[0])
                                                        for g in zoom.gaps if g.thickness_close is not None))
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
        zoom,
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


ZOOM_KEYS = ("encoder", "stop_semi_diameter", "close_distance", "stated_focal_length", "gap")


def _numbers(v, what, path, line) -> tuple[float, ...]:
    if not isinstance(v, list) or not v or len(v) > MAX_SURFACES:
        raise LensFileError(f"{what} must be a list of numbers, one per zoom position", path, line)
    return tuple(number(x, what, path, line, length=False) for x in v)


def _zoom(z: dict, text, path) -> Zoom:
    """The ``[zoom]`` table (module notes); positions are counted from the first gap's thicknesses."""
    unknown_keys(z, ZOOM_KEYS, "[zoom]", path)
    rows = z.get("gap")
    if not isinstance(rows, list) or not rows:
        raise LensFileError("[zoom] needs [[zoom.gap]] rows (surface, thickness = [one per position])", path)
    lines = table_lines(text, "zoom.gap", len(rows))
    gaps = []
    for k, row in enumerate(rows):
        ln = lines[k]
        row = table(row, "[[zoom.gap]]", path, ln)
        unknown_keys(row, ("surface", "thickness", "thickness_close"), "[[zoom.gap]]", path, ln)
        if "surface" not in row or "thickness" not in row:
            raise LensFileError("[[zoom.gap]] needs surface and thickness", path, ln)
        s = row["surface"]
        if isinstance(s, bool) or not isinstance(s, int):
            raise LensFileError(f"[[zoom.gap]] surface must be a 0-based surface index, got {s!r}", path, ln)
        close = row.get("thickness_close")
        gaps.append(ZoomGap(s, _numbers(row["thickness"], "[[zoom.gap]] thickness", path, ln),
                            None if close is None else _numbers(close, "[[zoom.gap]] thickness_close", path, ln)))
    n = len(gaps[0].thickness)
    if n < 2:
        raise LensFileError("a zoom table needs at least two positions", path, lines[0])
    opt = {key: None if key not in z else _numbers(z[key], f"[zoom] {key}", path, None)
           for key in ("encoder", "stop_semi_diameter", "close_distance", "stated_focal_length")}
    enc = opt["encoder"] if opt["encoder"] is not None else tuple(k / (n - 1) for k in range(n))
    return Zoom(tuple(gaps), enc, opt["stop_semi_diameter"], opt["close_distance"], opt["stated_focal_length"])


def _zoom_lines(z: Zoom) -> list[str]:
    def nums(v):
        return toml_value([float(x) for x in v])

    out = ["", "[zoom]"]
    n = z.positions
    if z.encoder != tuple(k / (n - 1) for k in range(n)):
        out.append(f"encoder = {nums(z.encoder)}")
    for key in ("stop_semi_diameter", "close_distance", "stated_focal_length"):
        if getattr(z, key) is not None:
            out.append(f"{key} = {nums(getattr(z, key))}")
    for g in z.gaps:
        out += ["", "[[zoom.gap]]", f"surface = {int(g.surface)}", f"thickness = {nums(g.thickness)}"]
        if g.thickness_close is not None:
            out.append(f"thickness_close = {nums(g.thickness_close)}")
    return out


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
    if p.focus is not None and (p.zoom is None or p.zoom.close_distance is None):
        out += ["", "[focus]", f"close_distance = {toml_value(float(p.focus.close_distance))}"]
        for g in p.focus.gaps:
            out += ["", "[[focus.gap]]", f"surface = {int(g.surface)}",
                    f"thickness_infinity = {toml_value(float(g.thickness_infinity))}",
                    f"thickness_close = {toml_value(float(g.thickness_close))}"]
    if p.zoom is not None:
        out += _zoom_lines(p.zoom)
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

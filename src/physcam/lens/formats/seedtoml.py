"""The seeds' lens TOML (the Blender "Physical Camera" extension's ``addon/lenses``).

Source: seed 003 (design notes of the extension). Layout::

    [lens]            name, patent, focal_length, max_fstop, coating, squeeze (default 1)
    [[surface]]       radius, thickness, ior, aperture, abbe_v, type?, conic?, aspheric_coeffs?
    [focus]           close_distance (mm from the front vertex)
    [[focus.variable]] surface (0-based), thickness_close

- ``aperture`` is the clear **full diameter** (physcam stores half of it).
- ``ior``/``abbe_v`` describe the medium after the surface; ``abbe_v = 0`` is air or
  a non-dispersive medium.
- ``type``: ``stop`` (radius 0), ``aspheric`` (``conic``, ``aspheric_coeffs`` =
  [A4, A6, A8(, A10)]), ``cylindrical_x``/``cylindrical_y``; otherwise radius 0 is a
  flat surface and any other radius a sphere. ``conic``/``aspheric_coeffs`` on a
  non-aspheric surface are refused (the seed's own rule).
- The thickness at infinity of a variable gap is the surface's ``thickness``.
"""

from __future__ import annotations

import warnings
from pathlib import Path

from ...errors import ExportError, LensFileError, PhysCamWarning
from ..prescription import AIR, Focus, LensMetadata, Medium, Prescription, Surface, takes_prescription
from ._common import (
    takes_text,
    MAX_SURFACES,
    focus_table,
    surface_rows,
    number,
    one_line,
    parse_toml,
    table,
    text_field,
    toml_value,
    unknown_keys,
    validated,
)

__all__ = ["loads", "dumps", "loads_document", "SURFACE_KEYS"]

LENS_KEYS = ("name", "patent", "focal_length", "max_fstop", "coating", "squeeze")
SURFACE_KEYS = ("radius", "thickness", "ior", "aperture", "abbe_v", "type", "conic", "aspheric_coeffs")
TYPES = ("stop", "aspheric", "cylindrical_x", "cylindrical_y", "spherical", "flat")


@takes_text
def loads(text: str, path=None, name: str | None = None) -> Prescription:
    """Parse seed-format lens TOML into a validated :class:`Prescription`."""
    return loads_document(parse_toml(text, path), text, path, name)


def loads_document(doc: dict, text: str, path=None, name: str | None = None) -> Prescription:
    unknown_keys(doc, ("lens", "surface", "focus"), "top level", path)
    lens = table(doc.get("lens", {}), "[lens]", path)
    unknown_keys(lens, LENS_KEYS, "[lens]", path)
    rows, lines = surface_rows(doc, text, path)
    surfaces = []
    for i, row in enumerate(rows):
        ln = lines[i]
        row = table(row, f"surface {i}", path, ln)
        unknown_keys(row, SURFACE_KEYS, f"surface {i}", path, ln)
        for key in ("radius", "thickness", "ior", "aperture"):
            if key not in row:
                raise LensFileError(f"surface {i} has no {key!r}", path, ln)
        radius = number(row["radius"], f"surface {i} radius", path, ln)
        thickness = number(row["thickness"], f"surface {i} thickness", path, ln)
        ior = number(row["ior"], f"surface {i} ior", path, ln, length=False)
        aperture = number(row["aperture"], f"surface {i} aperture (full diameter)", path, ln)
        abbe = number(row.get("abbe_v", 0.0), f"surface {i} abbe_v", path, ln, length=False)
        kind = row.get("type")
        if kind is None:
            kind = "flat" if radius == 0.0 else "spherical"
        if kind not in TYPES:
            raise LensFileError(f"surface {i}: unknown type {kind!r}; use one of {', '.join(TYPES)}", path, ln)
        if kind in ("stop", "flat") and radius != 0.0:
            raise LensFileError(f"surface {i}: a {kind} surface must have radius 0, got {radius:g}", path, ln)
        if kind == "spherical" and radius == 0.0:
            raise LensFileError(f"surface {i}: a spherical surface needs a non-zero radius", path, ln)
        conic, coeffs = 0.0, ()
        if kind == "aspheric":
            conic = number(row.get("conic", 0.0), f"surface {i} conic", path, ln, length=False)
            raw = row.get("aspheric_coeffs", [])
            if not isinstance(raw, list) or len(raw) > MAX_SURFACES:
                raise LensFileError(f"surface {i}: aspheric_coeffs must be a list [A4, A6, A8, ...]", path, ln)
            coeffs = tuple(number(a, f"surface {i} aspheric coefficient", path, ln, length=False) for a in raw)
        elif "conic" in row or "aspheric_coeffs" in row:
            raise LensFileError(f"surface {i}: conic/aspheric_coeffs need type = \"aspheric\"", path, ln)
        medium = AIR if (ior == 1.0 and abbe == 0.0) else Medium(ior, abbe)
        surfaces.append(Surface(radius, thickness, medium, aperture / 2.0, kind, conic, coeffs))
    focus = None
    if "focus" in doc:
        focus = _focus(table(doc["focus"], "[focus]", path), surfaces, text, path)
    meta = LensMetadata(
        name=text_field(lens, "name", "[lens]", path) or name or (Path(path).stem if path else "unnamed lens"),
        patent=text_field(lens, "patent", "[lens]", path),
        focal_length=None if "focal_length" not in lens else number(lens["focal_length"], "[lens] focal_length", path, None),
        max_fstop=None if "max_fstop" not in lens else number(lens["max_fstop"], "[lens] max_fstop", path, None),
        coating=text_field(lens, "coating", "[lens]", path),
    )
    squeeze = number(lens.get("squeeze", 1.0), "[lens] squeeze", path, None, length=False)
    return validated(Prescription(tuple(surfaces), meta, focus, squeeze), path, lines)


def _focus(f: dict, surfaces, text, path) -> Focus:
    return focus_table(f, surfaces, text, path, "variable")


@takes_prescription
def dumps(p: Prescription) -> str:
    """Seed-format TOML for ``p``. Maker, source and notes go to comments (not read back).

    A focus gap whose infinity thickness differs from its surface's thickness cannot be
    written (the format has no field for it): :class:`ExportError`. Glass names are dropped
    with a :class:`PhysCamWarning` (nd and Vd are kept).
    """
    if p.focus is not None:
        for g in p.focus.gaps:
            if g.thickness_infinity != p.surfaces[g.surface].thickness:
                raise ExportError(
                    f"lens {p.name!r}: focus gap after surface {g.surface} is {g.thickness_infinity:g} mm at infinity "
                    f"but the surface says {p.surfaces[g.surface].thickness:g} mm; the seed TOML keeps one value"
                )
    if any(s.medium.glass for s in p.surfaces):
        warnings.warn(f"seed TOML drops the glass names of lens {p.name!r} (keeps nd, Vd)", PhysCamWarning, stacklevel=3)
    m = p.metadata
    out = []
    for label, value in (("maker", m.maker), ("source", m.source)):
        if value:
            out.append(one_line(f"# {label}: {value}"))
    if m.notes:
        out += [one_line(f"# {line}") for line in m.notes.splitlines()]
    out.append("[lens]")
    out.append(f"name = {toml_value(m.name)}")
    for key in ("patent", "focal_length", "max_fstop", "coating"):
        v = getattr(m, key)
        if v is not None:
            out.append(f"{key} = {toml_value(v)}")
    if p.squeeze != 1.0:
        out.append(f"squeeze = {toml_value(float(p.squeeze))}")
    for s in p.surfaces:
        out += ["", "[[surface]]"]
        if s.kind not in ("spherical", "flat"):
            out.append(f"type = {toml_value(s.kind)}")
        out.append(f"radius = {toml_value(0.0 if s.is_stop else float(s.radius))}")
        out.append(f"thickness = {toml_value(float(s.thickness))}")
        out.append(f"ior = {toml_value(float(s.medium.nd))}")
        out.append(f"aperture = {toml_value(2.0 * s.semi_diameter)}")
        out.append(f"abbe_v = {toml_value(float(s.medium.vd))}")
        if s.kind == "aspheric":
            out.append(f"conic = {toml_value(float(s.conic))}")
            out.append(f"aspheric_coeffs = {toml_value([float(a) for a in s.aspheric])}")
    if p.focus is not None:
        out += ["", "[focus]", f"close_distance = {toml_value(float(p.focus.close_distance))}"]
        for g in p.focus.gaps:
            out += ["", "[[focus.variable]]", f"surface = {g.surface}",
                    f"thickness_close = {toml_value(float(g.thickness_close))}"]
    return "\n".join(out) + "\n"

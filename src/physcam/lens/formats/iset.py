"""ISET (isetlens / ISET3D) lens JSON.

Layout (isetlens ``data/lens/*.json``, seed 004)::

    {"name": ..., "description": ..., "type": ...,
     "surfaces": [{"radius", "thickness", "ior", "semi_aperture",
                   "conic_constant"?, "aspheric_coefficients"?}, ...],
     "microlens": {...}?}

Millimetres (the isetlens files are scaled copies of the pbrt lenses: the bundled
dgauss.77deg.3.5201mm has exactly the shape of pbrt's dgauss.50mm at 0.0699x, focal
length 3.52 mm). ``ior`` is the index after the surface, **0 marks the stop**;
``semi_aperture`` is the clear semi-diameter. ISET has no Abbe numbers (Vd = 0).
``aspheric_coefficients`` are read as the even terms A4, A6, ... of physcam's sag
equation (physcam.lens.geometry); a surface with a non-zero conic or any coefficient
is an even asphere.

Everything physcam does not model is kept, not dropped: top-level keys other than
``name`` and ``surfaces`` (``description``, ``type``, the ``microlens`` block, ...)
go to ``Prescription.extras`` as ``("iset.<key>", JSON)``, unknown per-surface keys
as ``("iset.surface_extras", JSON list)``, and the writer puts them back.
"""

from __future__ import annotations

import json
import warnings

from ...errors import ExportError, LensFileError, PhysCamWarning
from ..prescription import AIR, LensMetadata, Medium, Prescription, Surface, takes_prescription
from ._common import MAX_SURFACES, check_count, json_text, number, validated, takes_text

__all__ = ["loads", "dumps"]

_SURFACE_KEYS = ("radius", "thickness", "ior", "semi_aperture", "conic_constant", "aspheric_coefficients")


def _surface_lines(text: str, n: int) -> list[int | None]:
    """1-based line of each ``{"radius"`` object inside ``surfaces`` (best effort)."""
    start = text.find('"surfaces"')
    lines: list[int | None] = []
    pos = start
    while start >= 0 and len(lines) < n:
        pos = text.find('"radius"', pos + 1)
        if pos < 0:
            break
        lines.append(text.count("\n", 0, pos) + 1)
    return lines + [None] * (n - len(lines))


def _refuse_constant(token: str):
    raise ValueError(f"{token} is not a finite number")


@takes_text
def loads(text: str, path=None, name: str | None = None) -> Prescription:
    """Parse ISET lens JSON into a validated :class:`Prescription`."""
    try:
        doc = json.loads(text, parse_constant=_refuse_constant)
    except json.JSONDecodeError as exc:
        raise LensFileError(f"not valid JSON: {exc.msg}", path, exc.lineno) from None
    except (ValueError, RecursionError) as exc:
        raise LensFileError(f"not valid lens JSON: {exc}", path) from None
    if not isinstance(doc, dict):
        raise LensFileError("an ISET lens file is a JSON object with a 'surfaces' list", path, 1)
    rows = doc.get("surfaces")
    if not isinstance(rows, list):
        raise LensFileError("missing 'surfaces' list", path, 1)
    check_count(len(rows), path)
    lines = _surface_lines(text, len(rows))
    surfaces = []
    surface_extras = []
    for i, row in enumerate(rows):
        ln = lines[i]
        if not isinstance(row, dict):
            raise LensFileError(f"surface {i} is not a JSON object", path, ln)
        for key in ("radius", "thickness", "ior", "semi_aperture"):
            if key not in row:
                raise LensFileError(f"surface {i} has no {key!r}", path, ln)
        radius = number(row["radius"], f"surface {i} radius", path, ln)
        thickness = number(row["thickness"], f"surface {i} thickness", path, ln)
        ior = number(row["ior"], f"surface {i} ior", path, ln, length=False)
        semi = number(row["semi_aperture"], f"surface {i} semi_aperture", path, ln)
        conic = number(row.get("conic_constant", 0.0), f"surface {i} conic_constant", path, ln, length=False)
        coeffs = row.get("aspheric_coefficients", [])
        if not isinstance(coeffs, list) or len(coeffs) > MAX_SURFACES:
            raise LensFileError(f"surface {i}: aspheric_coefficients must be a list of numbers", path, ln)
        aspheric = tuple(number(a, f"surface {i} aspheric coefficient", path, ln, length=False) for a in coeffs)
        if ior == 0.0:
            kind, medium = "stop", AIR
        else:
            medium = AIR if ior == 1.0 else Medium(ior, 0.0)
            if conic != 0.0 or aspheric:
                kind = "aspheric"
            else:
                kind = "flat" if radius == 0.0 else "spherical"
        surfaces.append(Surface(radius, thickness, medium, semi, kind, conic, aspheric))
        surface_extras.append({k: v for k, v in row.items() if k not in _SURFACE_KEYS})
    extras = [(f"iset.{k}", json_text(v)) for k, v in doc.items() if k not in ("name", "surfaces")]
    if any(surface_extras):
        extras.append(("iset.surface_extras", json_text(surface_extras)))
    extras.sort()  # canonical order, so write(read(x)) compares equal whatever the key order
    raw_name = doc.get("name")
    if name is None:
        name = raw_name if isinstance(raw_name, str) and raw_name else "unnamed lens"
    if "name" in doc and not isinstance(raw_name, str):
        raise LensFileError("'name' must be a string", path, 1)
    p = Prescription(tuple(surfaces), LensMetadata(name=name), extras=tuple(extras))
    return validated(p, path, lines)


@takes_prescription
def dumps(p: Prescription) -> str:
    """ISET lens JSON for ``p``; :class:`ExportError` for cylinders and the squeeze.

    Abbe numbers and focus groups are dropped with a :class:`PhysCamWarning`.
    """
    for i, s in enumerate(p.surfaces):
        if s.kind.startswith("cylindrical"):
            raise ExportError(f"lens {p.name!r}: surface {i} is {s.kind}; ISET lens JSON holds no cylinders")
        if s.is_stop and not s.medium.is_air:
            raise ExportError(f"lens {p.name!r}: the stop (surface {i}) sits in glass; ISET's stop row (ior 0) is air")
    if p.squeeze != 1.0:
        raise ExportError(f"lens {p.name!r} is anamorphic (squeeze {p.squeeze:g}); ISET lens JSON cannot hold it")
    dropped = []
    if any(s.medium.vd for s in p.surfaces):
        dropped.append("Abbe numbers")
    if p.focus is not None:
        dropped.append("focus groups")
    if dropped:
        warnings.warn(f"ISET JSON drops {', '.join(dropped)} of lens {p.name!r}", PhysCamWarning, stacklevel=3)
    extras = {k[len("iset."):]: json.loads(v) for k, v in p.extras if k.startswith("iset.")}
    surface_extras = extras.pop("surface_extras", None)
    if not isinstance(surface_extras, list) or len(surface_extras) != len(p.surfaces):
        surface_extras = [{} for _ in p.surfaces]
    rows = []
    for s, more in zip(p.surfaces, surface_extras):
        ior = 0.0 if s.is_stop else s.medium.nd
        row = {"radius": 0.0 if s.is_stop else s.radius, "thickness": s.thickness, "ior": ior,
               "semi_aperture": s.semi_diameter}
        if s.kind == "aspheric":
            row["conic_constant"] = s.conic
            row["aspheric_coefficients"] = list(s.aspheric)
        if isinstance(more, dict):
            row.update(more)
        rows.append(row)
    doc = {"name": p.name}
    microlens = extras.pop("microlens", None)
    doc.update(extras)
    doc["surfaces"] = rows
    if microlens is not None:
        doc["microlens"] = microlens
    body = ",\n".join("  " + json.dumps(r, allow_nan=False) for r in rows)
    head = {k: v for k, v in doc.items() if k != "surfaces" and k != "microlens"}
    parts = ["{"]
    for k, v in head.items():
        parts.append(f" {json.dumps(k)}: {json.dumps(v, ensure_ascii=False, allow_nan=False)},")
    tail = ""
    if microlens is not None:
        tail = f',\n "microlens": {json.dumps(microlens, indent=1, ensure_ascii=False, allow_nan=False)}'
    parts.append(f' "surfaces": [\n{body}\n ]{tail}')
    parts.append("}")
    return "\n".join(parts) + "\n"

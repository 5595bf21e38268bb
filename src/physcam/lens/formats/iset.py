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

**Microlens arrays** (lenstool ``insertmicrolens``, pbrt-v4 ``omni`` camera; seed 004): a lens
file may carry ``"microlens": {"dimensions": [nx, ny], "surfaces": [...], "offsets": [[dx, dy],
...]}``, the lenslet's prescription in the same row format and one centre offset per lenslet (row
major, y then x; lenstool writes zeros; physcam reads them as mm). What lenstool takes on its
command line but does not store (film width and height, film-to-lens distance) and the omni
camera's ``microlensSensorOffset`` physcam keeps beside it in ``"physcam_microlens"``, with the focal
length of an ideal thin lenslet (whose rows are then an equivalent plano-convex glass lenslet, for
ISET). :func:`with_microlens` adds both blocks to a main lens, :func:`microlens_of` reads them back.

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

__all__ = ["loads", "dumps", "with_microlens", "microlens_of"]

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


def _block_text(value) -> str:
    """The microlens block as readable JSON: a key a line, a surface row a line, eight offsets a line
    (a 77 x 77 array has 5929 of them)."""
    def dump(v):
        return json.dumps(v, ensure_ascii=False, allow_nan=False)

    if not isinstance(value, dict) or not value:
        return json.dumps(value, indent=1, ensure_ascii=False, allow_nan=False)
    lines = []
    for k, v in value.items():
        if isinstance(v, list) and v and all(isinstance(r, dict) for r in v):
            body = ",\n".join("   " + dump(r) for r in v)
            lines.append(f"  {dump(k)}: [\n{body}\n  ]")
        elif isinstance(v, list) and len(v) > 8 and all(isinstance(r, list) for r in v):
            rows = [", ".join(dump(r) for r in v[i:i + 8]) for i in range(0, len(v), 8)]
            body = ",\n".join("   " + r for r in rows)
            lines.append(f"  {dump(k)}: [\n{body}\n  ]")
        else:
            lines.append(f"  {dump(k)}: {dump(v)}")
    return "{\n" + ",\n".join(lines) + "\n }"


def _check_writable(p: Prescription) -> None:
    """ExportError for what ISET lens JSON cannot hold (cylinders, a stop in glass, a squeeze)."""
    for i, s in enumerate(p.surfaces):
        if s.kind.startswith("cylindrical"):
            raise ExportError(f"lens {p.name!r}: surface {i} is {s.kind}; ISET lens JSON holds no cylinders")
        if s.is_stop and not s.medium.is_air:
            raise ExportError(f"lens {p.name!r}: the stop (surface {i}) sits in glass; ISET's stop row (ior 0) is air")
    if p.squeeze != 1.0:
        raise ExportError(f"lens {p.name!r} is anamorphic (squeeze {p.squeeze:g}); ISET lens JSON cannot hold it")


def _rows(p: Prescription, surface_extras=None) -> list[dict]:
    """The ``surfaces`` rows of ``p`` (unknown per-surface keys from ``surface_extras`` put back)."""
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
    return rows


@takes_prescription
def dumps(p: Prescription) -> str:
    """ISET lens JSON for ``p``; :class:`ExportError` for cylinders and the squeeze.

    Abbe numbers and focus groups are dropped with a :class:`PhysCamWarning`.
    """
    _check_writable(p)
    dropped = []
    if any(s.medium.vd for s in p.surfaces):
        dropped.append("Abbe numbers")
    if p.focus is not None:
        dropped.append("focus groups")
    if dropped:
        warnings.warn(f"ISET JSON drops {', '.join(dropped)} of lens {p.name!r}", PhysCamWarning, stacklevel=3)
    extras = {k[len("iset."):]: json.loads(v) for k, v in p.extras if k.startswith("iset.")}
    surface_extras = extras.pop("surface_extras", None)
    rows = _rows(p, surface_extras)
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
        tail = f',\n "microlens": {_block_text(microlens)}'
    parts.append(f' "surfaces": [\n{body}\n ]{tail}')
    parts.append("}")
    return "\n".join(parts) + "\n"


#: index of the glass physcam gives the plano-convex stand-in of a thin lenslet in ISET rows
THIN_LENSLET_INDEX = 1.5


def _thin_lenslet_rows(focal_length_mm: float, pitch_x: float, pitch_y: float) -> list[dict]:
    """ISET rows of a plano-convex glass lenslet (curved side to the scene) of focal length ``f``:
    R = (n - 1) f (a plano-convex lens's power is that of its curved face, whatever its thickness),
    clear semi-aperture the cell's half diagonal (the lenslet fills its square cell), centre
    thickness its sag there plus 5 %, the stop on its flat rear face."""
    import math

    n = THIN_LENSLET_INDEX
    r = (n - 1.0) * focal_length_mm
    semi = 0.5 * math.hypot(pitch_x, pitch_y)
    if semi >= r:
        raise ExportError(f"a thin lenslet of focal length {focal_length_mm:g} mm is too strong for a "
                          f"{pitch_x:g} x {pitch_y:g} mm cell to be written as glass (f/{focal_length_mm / pitch_x:.2g}); "
                          "ISET needs lenslet surfaces")
    t = 1.05 * (r - math.sqrt(r * r - semi * semi))
    return [{"radius": r, "thickness": t, "ior": n, "semi_aperture": semi},
            {"radius": 0.0, "thickness": 0.0, "ior": 1.0, "semi_aperture": semi},
            {"radius": 0.0, "thickness": 0.0, "ior": 0.0, "semi_aperture": semi}]


@takes_prescription
def with_microlens(main: Prescription, microlens: Prescription | None = None, *, count_x: int = 16,
                   count_y: int = 16, film_width_mm: float = 20.0, film_height_mm: float = 20.0,
                   film_to_lens_mm: float = 50.0, sensor_offset_mm: float | None = None,
                   thin_focal_length_mm: float | None = None, offsets_mm=None) -> Prescription:
    """``main`` with a microlens array, as lenstool's ``insertmicrolens`` writes it (module notes).

    The lenslet is ``microlens`` (a prescription) or an ideal thin lens of ``thin_focal_length_mm``.
    Defaults are lenstool's (16 x 16 lenslets over a 20 x 20 mm film, 50 mm from the main lens's rear
    vertex to the film). ``sensor_offset_mm`` (lenslet rear vertex to the sensor) defaults to the
    lenslet's back focal distance (the sensor in its focal plane). Values are checked as
    :func:`physcam.trace.microlens.microlens_array` checks them when the file is used.
    """
    import math

    from ...errors import InputError

    _check_writable(main)
    if any(k == "iset.microlens" for k, _ in main.extras):
        raise InputError(f"lens {main.name!r} already has a microlens array (lenstool refuses one inside another too)")
    for name, v in (("count_x", count_x), ("count_y", count_y)):
        if isinstance(v, bool) or not isinstance(v, int) or not 1 <= v <= 4096:
            raise InputError(f"{name} must be a whole number of lenslets from 1 to 4096, got {v!r}")
    if count_x * count_y > 500_000:
        raise InputError(f"{count_x} x {count_y} lenslets is more than physcam writes (500000: the file would "
                         "pass the 10 MB lens file limit)")
    nums = {}
    for name, v in (("film width", film_width_mm), ("film height", film_height_mm),
                    ("film-to-lens distance", film_to_lens_mm)):
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not (math.isfinite(v) and 0 < v <= 1e5):
            raise InputError(f"{name} must be a positive length in mm up to 100 m, got {v!r}")
        nums[name] = float(v)
    if (microlens is None) == (thin_focal_length_mm is None):
        raise InputError("give the lenslet either as a prescription or as a thin lens focal length, not both")
    px, py = nums["film width"] / count_x, nums["film height"] / count_y
    if microlens is not None:
        from ..prescription import require_prescription

        require_prescription(microlens, "microlens")
        _check_writable(microlens)
        if any(k == "iset.microlens" for k, _ in microlens.extras):
            raise InputError(f"microlens {microlens.name!r} has a microlens array of its own")
        rows, lenslet_name, thin = _rows(microlens), microlens.name, None
    else:
        f = thin_focal_length_mm
        if isinstance(f, bool) or not isinstance(f, (int, float)) or not (math.isfinite(f) and 0 < f <= 1e5):
            raise InputError(f"the thin lenslet's focal length must be a positive length in mm, got {f!r}")
        thin = float(f)
        rows, lenslet_name = _thin_lenslet_rows(thin, px, py), f"thin lenslet f = {thin:g} mm"
    if sensor_offset_mm is not None:
        if isinstance(sensor_offset_mm, bool) or not isinstance(sensor_offset_mm, (int, float)) \
                or not (math.isfinite(sensor_offset_mm) and 0 < sensor_offset_mm <= 1e5):
            raise InputError(f"the sensor offset must be a positive length in mm, got {sensor_offset_mm!r}")
        sensor_offset_mm = float(sensor_offset_mm)
    if offsets_mm is None:
        offsets = [[0.0, 0.0] for _ in range(count_x * count_y)]
    else:
        try:
            offsets = [[float(a), float(b)] for a, b in offsets_mm]
        except (TypeError, ValueError):
            raise InputError("offsets must be (dx, dy) pairs of numbers in mm") from None
        if len(offsets) != count_x * count_y or not all(math.isfinite(v) for o in offsets for v in o):
            raise InputError(f"offsets must be {count_x * count_y} finite (dx, dy) pairs, one per lenslet")
    block = {"dimensions": [count_x, count_y], "surfaces": rows, "offsets": offsets}
    mine = {"lenslet": lenslet_name, "thin_focal_length_mm": thin, "film_width_mm": nums["film width"],
            "film_height_mm": nums["film height"], "film_to_lens_mm": nums["film-to-lens distance"],
            "sensor_offset_mm": sensor_offset_mm,
            "note": "physcam: film size and film-to-lens as given to lenstool insertmicrolens; sensor offset (lenslet "
                    "rear vertex to sensor, omni microlensSensorOffset) null = the lenslet's back focal distance; "
                    "lengths mm"}
    extras = [(k, v) for k, v in main.extras if k not in ("iset.microlens", "iset.physcam_microlens")]
    extras += [("iset.microlens", json_text(block)), ("iset.physcam_microlens", json_text(mine))]
    extras.sort()
    from dataclasses import replace

    meta = replace(main.metadata, name=f"{main.name} w/ microlens {lenslet_name}")
    return replace(main, metadata=meta, extras=tuple(extras))


@takes_prescription
def microlens_of(p: Prescription) -> dict | None:
    """The microlens array a lens file carries (module notes), or None.

    Returns ``{"count_x", "count_y", "lenslet" (a Prescription, or None for a thin lenslet),
    "thin_focal_length_mm", "offsets_mm" (list of (dx, dy)), "film_width_mm", "film_height_mm",
    "film_to_lens_mm", "sensor_offset_mm"}``; what ``physcam_microlens`` does not say is None
    (film size, film-to-lens: give them when using the array). Raises :class:`LensFileError`
    for a malformed block.
    """
    raw = dict(p.extras)
    if "iset.microlens" not in raw:
        return None
    block = json.loads(raw["iset.microlens"])
    mine = json.loads(raw.get("iset.physcam_microlens", "{}"))
    where = f"lens {p.name!r}: microlens block"
    if not isinstance(block, dict) or not isinstance(mine, dict):
        raise LensFileError(f"{where} must be a JSON object")
    dims = block.get("dimensions")
    if (not isinstance(dims, list) or len(dims) != 2
            or not all(isinstance(d, int) and not isinstance(d, bool) and 1 <= d <= 4096 for d in dims)):
        raise LensFileError(f"{where}: 'dimensions' must be two whole numbers of lenslets (1 to 4096), got {dims!r}")
    nx, ny = dims
    if nx * ny > 500_000:
        raise LensFileError(f"{where}: {nx} x {ny} lenslets is more than 500000")
    offsets = block.get("offsets")
    if offsets is None:
        offsets = [[0.0, 0.0]] * (nx * ny)
    if not isinstance(offsets, list) or len(offsets) != nx * ny:
        raise LensFileError(f"{where}: 'offsets' must hold {nx * ny} (dx, dy) pairs")
    offs = []
    for o in offsets:
        if not isinstance(o, list) or len(o) != 2:
            raise LensFileError(f"{where}: an offset is not a (dx, dy) pair: {o!r}")
        offs.append(tuple(number(v, "microlens offset", None, None) for v in o))
    thin = mine.get("thin_focal_length_mm")
    lenslet = None
    if thin is not None:
        thin = number(thin, "thin lenslet focal length", None, None)
    else:
        lenslet = loads(json.dumps({"name": str(mine.get("lenslet") or "microlens"),
                                    "surfaces": block.get("surfaces")}))
    out = {"count_x": nx, "count_y": ny, "lenslet": lenslet, "thin_focal_length_mm": thin, "offsets_mm": offs}
    for key in ("film_width_mm", "film_height_mm", "film_to_lens_mm", "sensor_offset_mm"):
        v = mine.get(key)
        out[key] = None if v is None else number(v, key.replace("_", " "), None, None)
    return out

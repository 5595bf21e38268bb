"""Sequential Zemax OpticStudio lens files (``.zmx``, text), the subset lenses need.

Read: ``UNIT MM``, ``NAME``, ``NOTE``, and per ``SURF n`` block: ``TYPE STANDARD`` or
``TYPE EVENASPH``, ``CURV c`` (1/mm), ``DISZ t`` (mm, ``INFINITY`` on the object
surface), ``GLAS`` (a model glass ``GLAS ___BLANK 1 0 nd vd ...``, or a catalogue glass
``GLAS NAME 0 0 nd vd ...`` whose nd and Vd are taken from the line, falling back to
:mod:`physcam.lens.catalog` when the line has none), ``DIAM`` (the **semi**-diameter), ``STOP``,
``CONI k`` and ``PARM n a`` (EVENASPH: PARM 1 is the r^2 term, PARM 2..8 are
A4..A16). Surface 0 is the object, the last surface the image; the gap before the
image is the last lens thickness (distance to the film). Anything else that changes
the optics (other surface types, tilts/decentres, MIRROR, other units, a curved stop,
an r^2 asphere term, non-zero object-space index) is refused with file and line;
bookkeeping lines (``VERS``, ``MODE``, ``FLOA``, ``WAVL``, ...) are ignored. Source:
Zemax OpticStudio user manual, "ZMX file format" / "Even Asphere" surface. Files may be
UTF-8, UTF-16 with a byte-order mark, or the Windows code page OpticStudio writes ("ANSI").
A file cut short (a block without CURV/DISZ, an "image" with a thickness or glass after it,
glass before the image) is refused rather than read as a shorter, different lens.

The radius is read back as the shortest decimal whose reciprocal is the file's CURV,
so a radius written by :func:`dumps` (``CURV`` = 1/R to 17 digits) reads back equal.
"""

from __future__ import annotations

import math
import warnings
from pathlib import Path

from ...errors import ExportError, InputError, LensFileError, PhysCamWarning
from ..catalog import find_glass
from ..prescription import AIR, LensMetadata, Medium, Prescription, Surface, takes_prescription
from ._common import MAX_SURFACES, check_count, fmt, number, one_line, validated, takes_text

__all__ = ["loads", "dumps"]

# Lines that do not change a sequential lens's first- or third-order optics.
_IGNORED = {
    "VERS", "MODE", "GFAC", "GCAT", "FLOA", "FNUM", "ENPD", "OBNA", "FTYP", "ROPD", "PICB", "XFLN", "YFLN",
    "FWGN", "VDXN", "VDYN", "VCXN", "VCYN", "VANN", "WAVM", "PWAV", "WAVL", "WWGT", "POLS", "GLRS", "GSTD",
    "NSCD", "COFN", "SUMM", "BLNK", "RAIM", "PUSH", "SDMA", "FTYP", "HIDE", "SLAB", "MAZH", "CLAP", "POPS",
    "TOL", "MNUM", "MOFF", "TOLE", "COAT", "FLAP", "XFIE", "YFIE", "ZVDX", "ZVDY", "ZVCX", "ZVCY", "ZVAN",
    "MIRR", "MAZP", "DMFS", "OPDX", "RWRE", "EFFL", "CONF", "MCOP", "ENVD", "TCED", "OBSC", "SQAP",
}


def _radius(c: float) -> float:
    """Shortest decimal radius whose reciprocal is exactly ``c``; 0 for a flat surface."""
    if c == 0.0:
        return 0.0
    r = 1.0 / c
    for digits in range(1, 18):
        cand = float(f"{r:.{digits}g}")
        if cand != 0.0 and 1.0 / cand == c:
            return cand
    return r


@takes_text
def loads(text: str, path=None, name: str | None = None) -> Prescription:
    """Parse a sequential ``.zmx`` into a validated :class:`Prescription`."""
    blocks: list[dict] = []
    lens_name, notes = None, []
    cur = None
    for lineno, raw in enumerate(text.splitlines(), start=1):
        tok = raw.split()
        if not tok:
            continue
        key = tok[0].upper()
        if key == "SURF":
            if len(tok) < 2:
                raise LensFileError("SURF needs a surface number", path, lineno)
            cur = {"line": lineno, "type": "STANDARD", "curv": 0.0, "disz": 0.0, "glass": None, "diam": None,
                   "stop": False, "coni": 0.0, "parm": {}, "seen": set(), "number": tok[1]}
            blocks.append(cur)
            if len(blocks) > MAX_SURFACES + 2:
                raise LensFileError(f"more than {MAX_SURFACES} surfaces is refused", path, lineno)
            continue
        if key == "UNIT":
            if len(tok) < 2 or tok[1].upper() != "MM":
                raise LensFileError(f"lens units {tok[1] if len(tok) > 1 else '?'} not supported; set UNIT MM", path, lineno)
            continue
        if key == "NAME" and cur is None:
            lens_name = raw.split(None, 1)[1].strip() if len(tok) > 1 else None
            continue
        if key == "NOTE" and cur is None:
            notes.append(raw.split(None, 2)[2].strip() if len(tok) > 2 else "")
            continue
        if cur is None:
            continue  # header lines before the first surface
        cur["seen"].add(key)
        if key == "TYPE":
            t = tok[1].upper() if len(tok) > 1 else ""
            if t not in ("STANDARD", "EVENASPH"):
                raise LensFileError(f"surface type {t or '?'} is not supported (only STANDARD and EVENASPH)", path, lineno)
            cur["type"] = t
        elif key == "CURV":
            cur["curv"] = _num(tok, 1, "CURV", path, lineno, length=False)
        elif key == "DISZ":
            if len(tok) > 1 and tok[1].upper() == "INFINITY":
                cur["disz"] = math.inf
            else:
                cur["disz"] = _num(tok, 1, "DISZ", path, lineno)
        elif key == "DIAM":
            cur["diam"] = _num(tok, 1, "DIAM (semi-diameter)", path, lineno)
        elif key == "STOP":
            cur["stop"] = True
        elif key == "CONI":
            cur["coni"] = _num(tok, 1, "CONI", path, lineno, length=False)
        elif key == "PARM":
            n = _num(tok, 1, "PARM number", path, lineno, length=False)
            if n != int(n) or not 0 <= n <= 16:
                raise LensFileError(f"PARM number {tok[1]} is not 0..16", path, lineno)
            cur["parm"][int(n)] = _num(tok, 2, f"PARM {int(n)}", path, lineno, length=False)
            if cur["parm"][int(n)] != 0.0 and (n == 1 or n > 8):
                raise LensFileError(f"PARM {int(n)} is not supported (physcam keeps A4..A16 = PARM 2..8; "
                                    "fold an r^2 term into CURV)", path, lineno)
        elif key == "GLAS":
            cur["glass"] = _glass(tok, path, lineno)
            cur["glass_line"] = lineno
        elif key in ("DECX", "DECY", "TILTX", "TILTY", "COORD", "CBRK"):
            raise LensFileError(f"{key} (decentre/tilt) is not supported in a rotationally symmetric lens", path, lineno)
        elif key in _IGNORED or key in ("COMM", "NAME", "NOTE", "DISZ"):
            continue
        elif len(key) == 4 and key.isalpha() and key.isupper():
            continue  # other bookkeeping keywords
        else:
            raise LensFileError(f"unrecognised line {raw.strip()[:40]!r}", path, lineno)
    if len(blocks) < 3:
        raise LensFileError("a sequential lens needs an object surface, lens surfaces and an image surface", path)
    _check_complete(blocks, path)
    obj, lens_blocks = blocks[0], blocks[1:-1]
    if obj["glass"] is not None and obj["glass"] != AIR:
        raise LensFileError("the object space must be air", path, obj.get("glass_line", obj["line"]))
    check_count(len(lens_blocks), path)
    surfaces, lines = [], []
    for i, b in enumerate(lens_blocks):
        ln = b["line"]
        if not math.isfinite(b["disz"]):
            raise LensFileError("DISZ INFINITY is only allowed on the object surface", path, ln)
        if b["diam"] is None:
            raise LensFileError(
                f"surface {i + 1} has no DIAM: its clear semi-diameter is automatic in OpticStudio; physcam needs "
                "the real apertures (set the semi-diameters to fixed values before saving)", path, ln)
        medium = b["glass"] if b["glass"] is not None else AIR
        aspheric = ()
        if b["type"] == "EVENASPH":
            if b["parm"].get(1, 0.0) != 0.0:
                raise LensFileError("PARM 1 (r^2 asphere term) is not supported; fold it into CURV", path, ln)
            if any(k > 8 for k in b["parm"] if b["parm"][k] != 0.0):
                raise LensFileError("asphere terms beyond PARM 8 (A16) are not supported", path, ln)
            top = max([k for k in b["parm"] if b["parm"][k] != 0.0] + [1])
            aspheric = tuple(b["parm"].get(k, 0.0) for k in range(2, top + 1))
        radius = _radius(b["curv"])
        if b["stop"]:
            if radius != 0.0 or aspheric or b["coni"] != 0.0:
                raise LensFileError(
                    "the STOP is on a curved surface; physcam needs the stop as its own flat surface "
                    "(insert a dummy surface with STOP)", path, ln)
            kind = "stop"
        elif b["type"] == "EVENASPH" and (aspheric or b["coni"] != 0.0):
            kind = "aspheric"
        elif b["coni"] != 0.0:
            kind = "aspheric"  # a conic on a STANDARD surface
        else:
            kind = "flat" if radius == 0.0 else "spherical"
        surfaces.append(Surface(radius, b["disz"], medium, b["diam"], kind, b["coni"] if kind == "aspheric" else 0.0,
                                aspheric))
        lines.append(ln)
    if name is None:
        name = lens_name or (Path(path).stem if path is not None else "unnamed lens")
    meta = LensMetadata(name=name, notes="\n".join(notes) or None)
    return validated(Prescription(tuple(surfaces), meta), path, lines)


def _check_complete(blocks, path) -> None:
    """Refuse a file cut short: a truncated file must not load as another lens (issue 8).

    OpticStudio writes ``CURV`` and ``DISZ`` in every ``SURF`` block, object and image included;
    the image surface is the last block, in air, with nothing after it (``DISZ 0``); the light
    reaches it through air. A block missing those lines, an "image" with a thickness or a glass
    after it, or glass before it means the file ends inside the lens.
    """
    hint = "the file seems cut short (truncated); save the whole lens again"
    for b in blocks:
        missing = [k for k in ("CURV", "DISZ") if k not in b["seen"]]
        if missing:
            raise LensFileError(f"SURF {b['number']} has no {' or '.join(missing)} line: {hint}", path, b["line"])
    image, last = blocks[-1], blocks[-2]
    if image["disz"] != 0.0 or (image["glass"] is not None and image["glass"] != AIR):
        raise LensFileError(f"the last surface, SURF {image['number']}, is not an image surface (it has "
                            f"{'a thickness' if image['disz'] != 0.0 else 'glass'} after it): {hint}",
                            path, image["line"])
    if last["glass"] is not None and last["glass"] != AIR:
        raise LensFileError(f"SURF {last['number']} is followed by glass, yet the next surface is the last "
                            f"(the image cannot lie in glass): {hint}", path, last["line"])


def _num(tok, k, what, path, lineno, *, length=True) -> float:
    if len(tok) <= k:
        raise LensFileError(f"{what} needs a value", path, lineno)
    return number(tok[k], what, path, lineno, length=length)


def _glass(tok, path, lineno) -> Medium:
    if len(tok) < 2:
        raise LensFileError("GLAS needs a glass name", path, lineno)
    g = tok[1]
    if g.upper() == "MIRROR":
        raise LensFileError("MIRROR surfaces are not supported (refracting lenses only)", path, lineno)
    if g == "___BLANK":
        if len(tok) < 6:
            raise LensFileError("model glass needs 'GLAS ___BLANK 1 0 nd vd'", path, lineno)
        nd = number(tok[4], "model glass nd", path, lineno, length=False)
        vd = number(tok[5], "model glass vd", path, lineno, length=False)
        return AIR if (nd == 1.0 and vd == 0.0) else Medium(nd, vd)
    # A catalogue glass line carries the glass's own nd and Vd (GLAS NAME 0 0 nd vd ...); they are
    # what OpticStudio used, so they win over physcam's small catalogue, which fills in only when
    # the file gives none.
    file_nd = file_vd = None
    if len(tok) >= 6:
        try:
            file_nd, file_vd = float(tok[4]), float(tok[5])
        except ValueError:
            file_nd = file_vd = None
    if file_nd is not None and math.isfinite(file_nd) and file_nd > 1.0 and math.isfinite(file_vd) and file_vd >= 0:
        try:
            cat = find_glass(g)
        except InputError:
            cat = None
        if cat is not None and (abs(cat.nd - file_nd) > 5e-4 or abs(cat.vd - file_vd) > 0.5):
            warnings.warn(f"{path}:{lineno}: glass {g} has nd {file_nd:g}, Vd {file_vd:g} in the file but "
                          f"{cat.nd:g}, {cat.vd:g} in physcam's catalogue; using the file's", PhysCamWarning,
                          stacklevel=2)
        return Medium(file_nd, file_vd, g)
    try:
        cat = find_glass(g)
    except InputError as exc:
        raise LensFileError(str(exc) + "; or give its nd and Vd on the GLAS line", path, lineno) from None
    return Medium(cat.nd, cat.vd, cat.name)


@takes_prescription
def dumps(p: Prescription) -> str:
    """Sequential ``.zmx`` text for ``p``; :class:`ExportError` for cylinders and the squeeze.

    Catalogue glasses are written by name when nd and Vd match the catalogue, other media
    as model glasses. Focus groups and metadata other than the name and notes are dropped
    with a :class:`PhysCamWarning`.
    """
    for i, s in enumerate(p.surfaces):
        if s.kind.startswith("cylindrical"):
            raise ExportError(f"lens {p.name!r}: surface {i} is {s.kind}; this writer emits only rotationally "
                              "symmetric surfaces (write physcam TOML)")
    if p.squeeze != 1.0:
        raise ExportError(f"lens {p.name!r} is anamorphic; write physcam TOML instead")
    if p.focus is not None:
        warnings.warn(f"Zemax writer drops the focus groups of lens {p.name!r}", PhysCamWarning, stacklevel=3)
    out = ["VERS 190513 80 123457", "MODE SEQ", one_line(f"NAME {p.name}").rstrip(), "UNIT MM X W X CM MR CPMM"]
    if p.metadata.notes:
        out += [one_line(f"NOTE 0 {line}").rstrip() for line in p.metadata.notes.splitlines()]
    out.append(f"WAVL {fmt(p.wavelength_nm / 1000.0)}")
    out += ["SURF 0", "  TYPE STANDARD", "  CURV 0.0", "  DISZ INFINITY"]
    for i, s in enumerate(p.surfaces, start=1):
        out.append(f"SURF {i}")
        if s.is_stop:
            out.append("  STOP")
        out.append("  TYPE EVENASPH" if s.kind == "aspheric" and s.aspheric else "  TYPE STANDARD")
        c = 0.0 if (s.is_stop or s.kind == "flat" or s.radius == 0.0) else 1.0 / s.radius
        out.append(f"  CURV {fmt(c)}")
        if s.kind == "aspheric":
            out.append(f"  CONI {fmt(s.conic)}")
            for k, a in enumerate(s.aspheric, start=2):
                out.append(f"  PARM {k} {fmt(a)}")
        out.append(f"  DISZ {fmt(s.thickness)}")
        m = s.medium
        if m != AIR:
            named = None
            if m.glass is not None:
                try:
                    g = find_glass(m.glass)
                    named = g.name if (g.nd, g.vd, g.name) == (m.nd, m.vd, m.glass) else None
                except InputError:
                    named = None
            if named:
                out.append(f"  GLAS {named} 0 0 {fmt(m.nd)} {fmt(m.vd)} 0 0 0 0 0 0")
            else:
                out.append(f"  GLAS ___BLANK 1 0 {fmt(m.nd)} {fmt(m.vd)} 0 0 0 0 0 0")
        out.append(f"  DIAM {fmt(s.semi_diameter)} 1 0 0 1 \"\"")
    out += [f"SURF {len(p.surfaces) + 1}", "  TYPE STANDARD", "  CURV 0.0", "  DISZ 0.0"]
    return "\n".join(out) + "\n"

"""Sequential Zemax OpticStudio lens files (``.zmx``, text), the subset lenses need.

Read: ``UNIT MM``, ``NAME``, ``NOTE``, and per ``SURF n`` block: ``TYPE STANDARD`` or
``TYPE EVENASPH``, ``CURV c`` (1/mm), ``DISZ t`` (mm, ``INFINITY`` on the object
surface), ``GLAS``, ``DIAM`` (the **semi**-diameter), ``STOP``, ``CONI k`` and ``PARM n a``
(EVENASPH: PARM 1 is the r^2 term, PARM 2..8 are A4..A16). Surface 0 is the object, the last
surface the image; the gap before the image is the last lens thickness (distance to the film).

Glasses as OpticStudio reads them: ``GCAT A B C`` lists the catalogues searched, in order
(:func:`physcam.lens.catalog.find_glass`, plus the user's ``--glass-catalog`` files);
``GLAS NAME 0 ...`` is that catalogue glass, its data from the catalogue (the nd and Vd on the
line are placeholders OpticStudio ignores, and so does physcam; glass substitution flags too);
``GLAS ___BLANK 1 0 nd vd dPgF`` or any ``GLAS NAME 1 0 nd vd dPgF`` is a model glass. A glass
the listed catalogues lack is looked for, by its own name only, in the legacy catalogue of a
listed maker (SCHOTT's obsolete SK16, F15...), then, unless strict (``--strict-glass``, as
OpticStudio), in every other bundled catalogue (:func:`physcam.lens.catalog.resolve_glass`); one
:class:`PhysCamWarning` names each such glass and the catalogue it came from. A catalogue glass
whose stated range does not hold the design wavelength gets one warning too (OpticStudio warns;
the formula is extrapolated there). ``WAVM`` (or ``WAVL``) and ``PWAV`` give the design
wavelength (the primary). A stop on a lens face becomes a flat stop at that face's vertex, with
the face's semi-diameter; on a concave face (every negative lens of Thorlabs' files) the face
curves in front of that plane, which the lens accepts (:meth:`Prescription.validate`). Lines read
past without effect on a refracting lens are listed in :data:`SKIPPED` with the reason.

Anything else that changes the optics (other surface types, tilts/decentres, MIRROR, other
units, an r^2 asphere term, non-zero object-space index) is refused with file and line. Source:
Zemax OpticStudio user manual, "ZMX file format" / "Even Asphere" surface / "Glass catalogs".
Files may be UTF-8, UTF-16 with a byte-order mark, or the Windows code page ("ANSI").
A file cut short (a block without CURV/DISZ, an "image" with a thickness or glass after it,
glass before the image and nothing after the last surface) is refused rather than read as a
shorter, different lens; an image space in a liquid is accepted when the file goes on past the
last surface (``TOL``, ``MNUM``, ``MOFF``, ``BLNK``... lines, as OpticStudio writes them).

The radius is read back as the shortest decimal whose reciprocal is the file's CURV,
so a radius written by :func:`dumps` (``CURV`` = 1/R to 17 digits) reads back equal.

Multi-configuration files (a zoom lens): ``MNUM n active`` and the configuration editor's rows as
OpticStudio writes them, operand-major, ``THIC surface config value ...`` (a thickness per
configuration, 1-based configurations, Zemax surface numbers) and ``APER 0 config value ...``
(the system aperture per configuration, read under the file's ENPD/FNUM/OBNA kind: a tabulated stop
size). ``SDIA`` of the stop tabulates its semi-diameter directly. Thickness solves in a ``SURF``
block are applied in every configuration: ``TCOM s total`` (compensator: this thickness plus surface
s's stays ``total``) and ``TOLE s total`` (position: the thicknesses from surface s through this one
add up to ``total``); with words instead of numbers they are read as comments. The configurations
become the zoom table (:class:`~physcam.lens.prescription.Zoom`, positions in configuration order,
the lens's surfaces at configuration 1), the gaps that differ its zoom gaps. Rows that do not change
a lens's first-order optics (:data:`MC_IGNORED`: field points, vignetting, weights, ``MOFF``) are
read past; any other operand (curvature, glass, conic, a varying object distance...) is refused
with its line, since physcam's zoom moves gaps only.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import replace
from pathlib import Path

from ...errors import ExportError, InputError, LensFileError, PhysCamWarning
from ..aperture import size_stop
from ..catalog import LEGACY, LEGACY_SOURCE, GlassNotFound, find_glass, range_note, resolve_glass
from ..prescription import (AIR, OBJECT_DISTANCE_KEY, LensMetadata, Medium, Prescription, Surface, Zoom, ZoomGap,
                            takes_prescription)
from ._common import MAX_SURFACES, check_count, extra, fmt, json_text, number, one_line, validated, takes_text

__all__ = ["loads", "dumps", "SKIPPED", "MC_IGNORED"]

#: Multi-configuration operands read past: they set fields, vignetting, weights or nothing, not the lens.
MC_IGNORED = {"MOFF", "FVCX", "FVCY", "FVDX", "FVDY", "FVAN", "XFIE", "YFIE", "FLWT", "FLTP", "WLWT", "PRWV",
              "CONF", "MCOM", "NOTE", "HOLD", "TCED", "POPD"}

#: Lines read past, with the reason (docs/lens-formats.md lists them).
SKIPPED = {
    "MIRR": "mirror substrate drawing data, not a mirror surface (GLAS MIRROR is refused)",
    "HIDE": "layout visibility only",
    "POPS": "physical-optics propagation settings",
    "FLAP": "flat-aperture drawing data",
    "MEMA": "mechanical semi-aperture (drawing); physcam keeps the clear semi-diameter DIAM",
    "COAT": "coating name: physcam's coating model is per lens (Prescription.coating)",
    "XFLN": "field points: physcam analyses its own fields",
    "YFLN": "field points: physcam analyses its own fields",
    "TOL": "tolerance data",
    "MOFF": "an unused multi-configuration row",
    "BLNK": "spacer line after the surfaces",
}
# Lines after the last surface that show the file goes on (it was not cut short there).
_TAIL = {"TOL", "TOLE", "MNUM", "MOFF", "BLNK", "CONF", "MCOP", "MCOM", "DMFS", "TCED"}

# Lines that do not change a sequential lens's first- or third-order optics.
_IGNORED = {
    "VERS", "MODE", "GFAC", "GCAT", "FTYP", "ROPD", "PICB", "XFLN", "YFLN",
    "FWGN", "VDXN", "VDYN", "VCXN", "VCYN", "VANN", "WAVM", "PWAV", "WAVL", "WWGT", "POLS", "GLRS", "GSTD",
    "NSCD", "COFN", "SUMM", "BLNK", "RAIM", "PUSH", "SDMA", "FTYP", "HIDE", "SLAB", "MAZH", "CLAP", "POPS",
    "TOL", "MNUM", "MOFF", "TOLE", "COAT", "FLAP", "XFIE", "YFIE", "ZVDX", "ZVDY", "ZVCX", "ZVCY", "ZVAN",
    "MIRR", "MAZP", "DMFS", "OPDX", "RWRE", "EFFL", "CONF", "MCOP", "ENVD", "TCED", "OBSC", "SQAP",
    "MEMA",
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


def _surface_line(cur: dict, key: str, tok: list, raw: str, path, lineno: int) -> None:
    """Read one line of a ``SURF`` block into ``cur`` (refusing what changes the optics and physcam lacks)."""
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
        cur["glass"] = tok
        cur["glass_line"] = lineno
    elif key in ("TCOM", "TOLE"):
        cur["solve"] = _solve(key, tok, path, lineno)
    elif key in ("DECX", "DECY", "TILTX", "TILTY", "COORD", "CBRK"):
        raise LensFileError(f"{key} (decentre/tilt) is not supported in a rotationally symmetric lens", path, lineno)
    elif key in _IGNORED or key in ("COMM", "NAME", "NOTE", "DISZ"):
        return
    elif len(key) == 4 and key.isalpha() and key.isupper():
        return  # other bookkeeping keywords
    else:
        raise LensFileError(f"unrecognised line {raw.strip()[:40]!r}", path, lineno)


def _solve(key, tok, path, lineno):
    """(kind, Zemax surface, total, line) of a thickness solve; None for the words of a comment."""
    try:
        s, total = int(tok[1]), float(tok[2])
    except (IndexError, ValueError):
        return None
    if s < 0 or not math.isfinite(total):
        raise LensFileError(f"{key} solve needs a surface number and a finite total", path, lineno)
    return key, s, total, lineno


def _read_blocks(text: str, path):
    """The file's lines as (surface blocks, lens name, notes, header: catalogues, wavelengths, aperture)."""
    blocks: list[dict] = []
    lens_name, notes = None, []
    head = {"gcat": [], "wavm": {}, "wavl": [], "pwav": 1, "tail": False, "aperture": None, "mnum": None, "mc": []}
    cur = None
    for lineno, raw in enumerate(text.splitlines(), start=1):
        tok = raw.split()
        if not tok:
            continue
        key = tok[0].upper()
        if key in ("GCAT", "WAVM", "WAVL", "PWAV", "ENPD", "FNUM", "OBNA", "FLOA"):
            _header(key, tok, head, path, lineno)
            continue
        if key in _TAIL:
            head["tail"] = True
        if key == "MNUM":
            n = _num(tok, 1, "MNUM (number of configurations)", path, lineno, length=False)
            if n != int(n) or not 1 <= n <= 1000:
                raise LensFileError(f"MNUM {tok[1]} is not a number of configurations (1..1000)", path, lineno)
            head["mnum"] = (int(n), lineno)
            continue
        if head["mnum"] is not None and raw[:1] not in (" ", "\t") and key != "SURF":
            head["mc"].append((key, tok, lineno))
            continue
        if key == "SURF":
            head["tail"] = False
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
        _surface_line(cur, key, tok, raw, path, lineno)
    return blocks, lens_name, notes, head


def _asphere_terms(b: dict, path, ln: int) -> tuple:
    """A4.. of an EVENASPH block (PARM 2..8), trailing zeros dropped; () for a STANDARD surface."""
    if b["type"] != "EVENASPH":
        return ()
    if b["parm"].get(1, 0.0) != 0.0:
        raise LensFileError("PARM 1 (r^2 asphere term) is not supported; fold it into CURV", path, ln)
    if any(k > 8 for k in b["parm"] if b["parm"][k] != 0.0):
        raise LensFileError("asphere terms beyond PARM 8 (A16) are not supported", path, ln)
    top = max([k for k in b["parm"] if b["parm"][k] != 0.0] + [1])
    return tuple(b["parm"].get(k, 0.0) for k in range(2, top + 1))


def _lens_surfaces(lens_blocks: list, path) -> tuple[list, list]:
    """(surfaces, their file lines) of the blocks between object and image; a stop on a lens face becomes a flat
    stop at the face's vertex."""
    surfaces, lines, owner = [], [], []
    for i, b in enumerate(lens_blocks):
        ln = b["line"]
        if not math.isfinite(b["disz"]):
            raise LensFileError("DISZ INFINITY is only allowed on the object surface", path, ln)
        if b["diam"] is None:
            raise LensFileError(
                f"surface {i + 1} has no DIAM: its clear semi-diameter is automatic in OpticStudio; physcam needs "
                "the real apertures (set the semi-diameters to fixed values before saving)", path, ln)
        medium = b["glass"] if b["glass"] is not None else AIR
        aspheric = _asphere_terms(b, path, ln)
        radius = _radius(b["curv"])
        if b["stop"] and (radius != 0.0 or aspheric or b["coni"] != 0.0):
            # a stop on a lens face: a flat stop at the face's vertex, in the medium before it
            before = surfaces[-1].medium if surfaces else AIR
            surfaces.append(Surface(0.0, 0.0, before, b["diam"], "stop"))
            lines.append(ln)
            b["stop"], b["was_stop"] = False, True
        if b["stop"]:
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
        owner.append(len(surfaces) - 1)
    return surfaces, lines, owner


@takes_text
def loads(text: str, path=None, name: str | None = None) -> Prescription:
    """Parse a sequential ``.zmx`` into a validated :class:`Prescription`."""
    blocks, lens_name, notes, head = _read_blocks(text, path)
    if len(blocks) < 3:
        raise LensFileError("a sequential lens needs an object surface, lens surfaces and an image surface", path)
    found: list = []  # (catalogue glass, how it was found: None, "legacy", "unlisted")
    for b in blocks:
        if b["glass"] is not None:
            b["glass"] = _glass(b["glass"], head["gcat"], path, b["glass_line"], found)
    _check_complete(blocks, path, head["tail"])
    obj, lens_blocks = blocks[0], blocks[1:-1]
    if obj["glass"] is not None and obj["glass"] != AIR:
        raise LensFileError("the object space must be air", path, obj.get("glass_line", obj["line"]))
    check_count(len(lens_blocks), path)
    surfaces, lines, owner = _lens_surfaces(lens_blocks, path)
    if name is None:
        name = lens_name or (Path(path).stem if path is not None else "unnamed lens")
    meta = LensMetadata(name=name, notes="\n".join(notes) or None)
    extras = () if math.isinf(obj["disz"]) else ((OBJECT_DISTANCE_KEY, json_text(obj["disz"])),)
    p = Prescription(tuple(surfaces), meta, wavelength_nm=_design_wavelength(head, path), extras=extras)
    if head["mnum"] is not None and head["mnum"][0] > 1:
        p = _configurations(p, blocks, owner, head, path, lines)
    else:
        p = _sized(p, head["aperture"], obj["disz"], path)
    p = validated(p, path, lines)
    _say_glasses(found, head["gcat"], p.wavelength_nm, path)
    return p


def _say_glasses(found: list, gcat: list, wavelength_nm: float, path) -> None:
    """One warning naming the glasses taken from a catalogue the GCAT line does not list (and
    which), one for glasses used outside their stated range (module notes)."""
    where = f"{path}: " if path is not None else ""
    by_cat: dict = {}
    for g, how in found:
        if how is not None:
            by_cat.setdefault((g.maker, how), {})[g.name] = g
    if by_cat:
        listed = " ".join(gcat) or "none"
        parts = []
        for (cat, how), glasses in by_cat.items():
            names = ", ".join(f"{n}{f' ({g.status})' if g.status else ''}" for n, g in glasses.items())
            if how == "legacy":
                what = f"{LEGACY_SOURCE[cat]}, not {_MAKER_OF[cat]}'s current catalogue"
            else:
                what = f"not in GCAT {listed}; --strict-glass refuses it, as OpticStudio does"
            parts.append(f"{names} taken from {cat} ({what})")
        warnings.warn(where + "; ".join(parts), PhysCamWarning, stacklevel=4)
    outside = list(dict.fromkeys(n for n in (range_note(g, wavelength_nm) for g, _ in found) if n))
    if outside:
        warnings.warn(f"{where}the design wavelength {wavelength_nm:g} nm lies outside the stated range of "
                      f"{'; '.join(outside)}: its formula is extrapolated there", PhysCamWarning, stacklevel=4)


def _mc_values(head, path) -> dict:
    """``{(operand, number): [value per configuration]}`` of the configuration rows (module notes)."""
    n, mline = head["mnum"]
    rows: dict = {}
    for key, tok, ln in head["mc"]:
        if key in MC_IGNORED or (key in _TAIL and key not in ("MNUM",)):
            continue
        if key not in ("THIC", "APER", "SDIA"):
            raise LensFileError(f"multi-configuration operand {key} changes the lens in a way physcam's zoom does not "
                                "model (only THIC gaps, APER and the stop's SDIA are read)", path, ln)
        num = _num(tok, 1, f"{key} number", path, ln, length=False)
        cfg = _num(tok, 2, f"{key} configuration", path, ln, length=False)
        if cfg != int(cfg) or not 1 <= cfg <= n:
            raise LensFileError(f"{key} configuration {tok[2]} is not 1..{n} (MNUM {n})", path, ln)
        row = rows.setdefault((key, int(num)), [None] * n)
        row[int(cfg) - 1] = (_num(tok, 3, f"{key} value", path, ln, length=False), ln)
    for (key, num), row in rows.items():
        if None in row:
            raise LensFileError(f"{key} {num} has no value for configuration {row.index(None) + 1} of {n}", path,
                                next(r[1] for r in row if r is not None))
    return rows


def _configurations(p: Prescription, blocks, owner, head, path, lines) -> Prescription:
    """``p`` at configuration 1 with the other configurations as its zoom table (module notes)."""
    n = head["mnum"][0]
    rows = _mc_values(head, path)
    nz = len(blocks) - 1  # the image surface's Zemax number
    thick = [[b["disz"] for b in blocks] for _ in range(n)]
    for (key, num), row in rows.items():
        if key != "THIC":
            continue
        if not 0 <= num <= nz:
            raise LensFileError(f"THIC {num}: the lens has surfaces 0..{nz}", path, row[0][1])
        if num == 0 and len({v for v, _ in row}) > 1:
            raise LensFileError("THIC 0 (the object distance) changes between configurations: a zoom x focus grid in "
                                "one .zmx is not read; write a physcam zoom TOML (docs/zoom.md)", path, row[0][1])
        for c, (v, _) in enumerate(row):
            thick[c][num] = v
    for c in range(n):
        _apply_solves(thick[c], blocks, path)
    gaps = []
    for z in range(1, nz):
        values = tuple(thick[c][z] for c in range(n))
        if len(set(values)) > 1:
            gaps.append(ZoomGap(owner[z - 1], values))
    if not gaps:
        raise LensFileError(f"MNUM {n}: no gap differs between the configurations, so this is no zoom", path,
                            head["mnum"][1])
    base = p.with_thicknesses({g.surface: g.thickness[0] for g in gaps})
    stops = _stop_table(base, rows, gaps, head, n, blocks, path)
    if stops is not None:
        k = base.stop_index
        base = base.with_surfaces(s if i != k else replace(s, semi_diameter=stops[0]) for i, s in enumerate(base.surfaces))
        stops = None if len(set(stops)) == 1 else stops  # one size at every configuration: a fixed stop
    return replace(base, zoom=Zoom(tuple(gaps), tuple(c / (n - 1) for c in range(n)), stops))


def _apply_solves(t: list, blocks, path) -> None:
    """Thickness solves (TCOM, TOLE) of one configuration, in surface order, into ``t`` (by Zemax number)."""
    for j, b in enumerate(blocks):
        solve = b.get("solve")
        if solve is None:
            continue
        kind, s, total, ln = solve
        if not 0 < s <= j or (kind == "TCOM" and s == j):
            raise LensFileError(f"{kind} {s}: the solve of surface {j} refers to a surface at or after it", path, ln)
        t[j] = total - (t[s] if kind == "TCOM" else sum(t[s:j]))
        if t[j] < 0:
            raise LensFileError(f"{kind} {s} {total:g} gives surface {j} a negative thickness {t[j]:g} mm in one "
                                "configuration", path, ln)


def _stop_table(base, rows, gaps, head, n, blocks, path):
    """The stop's semi-diameter per configuration: SDIA of the stop, else APER under the file's aperture kind."""
    zemax_stop = next((k for k, b in enumerate(blocks) if b["stop"] or b.get("was_stop")), None)
    for (key, num), row in rows.items():
        if key == "SDIA" and num != zemax_stop and len({v for v, _ in row}) > 1:
            raise LensFileError(f"SDIA {num}: only the stop's semi-diameter may change between configurations",
                                path, row[0][1])
    if ("SDIA", zemax_stop) in rows:
        return tuple(v for v, _ in rows[("SDIA", zemax_stop)])
    aper = rows.get(("APER", 0))
    if aper is None:
        if head["aperture"] is None or head["aperture"][0] == "FLOA":
            return None
        values = [head["aperture"][1]] * n
        ln = head["aperture"][2]
    else:
        values, ln = [v for v, _ in aper], aper[0][1]
        if head["aperture"] is None or head["aperture"][0] == "FLOA":
            raise LensFileError("APER rows need the file's aperture kind (ENPD, FNUM or OBNA), not float by stop size",
                                path, ln)
    kind = head["aperture"][0]
    out = []
    for c in range(n):
        q = base.with_thicknesses({g.surface: g.thickness[c] for g in gaps})
        q = _sized(q, (kind, values[c], ln), blocks[0]["disz"], path)
        out.append(q.surfaces[q.stop_index].semi_diameter)
    return tuple(out)


def _sized(p: Prescription, aperture, object_distance: float, path) -> Prescription:
    """``p`` with its stop sized by the file's aperture line (:func:`physcam.lens.aperture.size_stop`);
    unchanged without one (as FLOA) or when the stop is not one surface (validation says so)."""
    if aperture is None or sum(s.is_stop for s in p.surfaces) != 1:
        return p
    kind, value, lineno = aperture
    try:
        return size_stop(p, kind, value, object_distance)
    except (InputError, ArithmeticError) as exc:
        raise LensFileError(str(exc), path, lineno) from None


def _header(key, tok, head, path, lineno) -> None:
    """GCAT (catalogues in search order), WAVM n um weight / WAVL um ... (wavelengths), PWAV n."""
    if key == "GCAT":
        head["gcat"] = [t.upper() for t in tok[1:]]
    elif key == "WAVM" and len(tok) >= 3:
        n = _num(tok, 1, "WAVM number", path, lineno, length=False)
        head["wavm"][int(n)] = _num(tok, 2, "WAVM wavelength (um)", path, lineno)
    elif key == "WAVL":
        head["wavl"] = [number(t, "WAVL wavelength (um)", path, lineno) for t in tok[1:]]
    elif key == "PWAV" and len(tok) >= 2:
        head["pwav"] = int(_num(tok, 1, "PWAV", path, lineno, length=False))
    else:
        head["aperture"] = _aperture(key, tok, path, lineno)


def _aperture(key, tok, path, lineno) -> tuple[str, float, int]:
    """(kind, value, line) of an aperture line: ENPD D, FNUM N flag, OBNA NA flag or FLOA
    (:data:`physcam.lens.aperture.APERTURE_KINDS`; the flag 0 when absent)."""
    if key == "FLOA":
        return "FLOA", 0.0, lineno
    value = _num(tok, 1, key, path, lineno, length=False)
    if key == "ENPD":
        return "ENPD", value, lineno
    flag = tok[2] if len(tok) > 2 else "0"
    if flag not in ("0", "1"):
        raise LensFileError(f"{key} flag {flag!r} is not 0 or 1", path, lineno)
    return f"{key} {flag}", value, lineno


def _design_wavelength(head, path) -> float:
    """The primary wavelength (nm): WAVM[PWAV], else the PWAV-th WAVL value, else the d line."""
    um = head["wavm"].get(head["pwav"])
    if um is None and head["wavl"]:
        um = head["wavl"][min(max(head["pwav"], 1), len(head["wavl"])) - 1]
    if um is None:
        return Prescription.__dataclass_fields__["wavelength_nm"].default
    return round(um * 1000.0, 9)


def _check_complete(blocks, path, goes_on: bool = False) -> None:
    """Refuse a file cut short: a truncated file must not load as another lens (issue 8).

    OpticStudio writes ``CURV`` and ``DISZ`` in every ``SURF`` block, object and image included;
    the image surface is the last block, with nothing after it (``DISZ 0``). A block missing
    those lines or an "image" with a thickness or a glass after it means the file ends inside the
    lens; so does glass before the image, unless the file goes on past the last surface
    (``goes_on``: TOL, MNUM, MOFF, BLNK... lines), which makes it an image space in a medium.
    """
    hint = "the file seems cut short (truncated); save the whole lens again"
    for b in blocks:
        missing = [k for k in ("CURV", "DISZ") if k not in b["seen"]]
        if missing and b is not blocks[-1]:  # surfaces follow: a block written short (by hand), not a cut
            raise LensFileError(f"SURF {b['number']} has no {' or '.join(missing)} line: every SURF block "
                                "needs both, as OpticStudio writes them (CURV 0 for a flat surface or the "
                                "stop, DISZ its distance to the next surface)", path, b["line"])
        if missing:
            raise LensFileError(f"SURF {b['number']} has no {' or '.join(missing)} line: {hint}", path, b["line"])
    image, last = blocks[-1], blocks[-2]
    if image["disz"] != 0.0 or (image["glass"] is not None and image["glass"] != AIR):
        raise LensFileError(f"the last surface, SURF {image['number']}, is not an image surface (it has "
                            f"{'a thickness' if image['disz'] != 0.0 else 'glass'} after it): {hint}",
                            path, image["line"])
    if last["glass"] is not None and last["glass"] != AIR and not goes_on:
        raise LensFileError(f"SURF {last['number']} is followed by glass, yet the next surface is the last "
                            f"and nothing follows it (an image in a medium is accepted when the file goes on past the last surface, as OpticStudio writes it): {hint}", path, last["line"])


def _num(tok, k, what, path, lineno, *, length=True) -> float:
    if len(tok) <= k:
        raise LensFileError(f"{what} needs a value", path, lineno)
    return number(tok[k], what, path, lineno, length=length)


def _glass(tok, gcat, path, lineno, found: list) -> Medium:
    """The medium of a GLAS line: a model glass (___BLANK, or solve code 1) from nd, Vd, dPgF;
    else the catalogue glass, searched in the GCAT order (the line's numbers are placeholders)
    and further (:func:`physcam.lens.catalog.resolve_glass`), noted in ``found``."""
    if len(tok) < 2:
        raise LensFileError("GLAS needs a glass name", path, lineno)
    g = tok[1]
    if g.upper() == "MIRROR":
        raise LensFileError("MIRROR surfaces are not supported (refracting lenses only)", path, lineno)
    if g == "___BLANK" or (len(tok) > 2 and tok[2] == "1"):
        if len(tok) < 6:
            raise LensFileError("model glass needs 'GLAS ___BLANK 1 0 nd vd [dPgF]'", path, lineno)
        nd = number(tok[4], "model glass nd", path, lineno, length=False)
        vd = number(tok[5], "model glass vd", path, lineno, length=False)
        dpgf = number(tok[6], "model glass dPgF", path, lineno, length=False) if len(tok) > 6 else 0.0
        return AIR if (nd == 1.0 and vd == 0.0) else Medium(nd, vd, dpgf=dpgf if vd else 0.0)
    try:
        cat, how = resolve_glass(g, gcat)
    except GlassNotFound as exc:
        raise LensFileError(str(exc), path, lineno) from None
    found.append((cat, how))
    return Medium(cat.nd, cat.vd, cat.name, cat.maker)


@takes_prescription
def dumps(p: Prescription) -> str:
    """Sequential ``.zmx`` text for ``p``; :class:`ExportError` for cylinders and the squeeze.

    Catalogue glasses are written by name (with a GCAT line naming their catalogues) when nd
    and Vd match the catalogue, other media as model glasses with their dPgF. Focus groups and metadata other than the name and notes are dropped
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
    out += ["FLOA", f"WAVL {fmt(p.wavelength_nm / 1000.0)}"]
    gcat_at = len(out)
    cats: list[str] = []
    d = extra(p, OBJECT_DISTANCE_KEY)
    out += ["SURF 0", "  TYPE STANDARD", "  CURV 0.0", f"  DISZ {'INFINITY' if d is None else fmt(d)}"]
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
            g = _named(m)
            if g is not None:
                out.append(f"  GLAS {g.name} 0 0 {fmt(m.nd)} {fmt(m.vd)} 0 0 0 0 0 0")
                cats.append(_MAKER_OF.get(g.maker, g.maker))  # OpticStudio's SCHOTT.AGF holds SCHOTT's legacy glasses
            else:
                out.append(f"  GLAS ___BLANK 1 0 {fmt(m.nd)} {fmt(m.vd)} {fmt(m.dpgf)} 0 0 0 0 0")
        out.append(f"  DIAM {fmt(s.semi_diameter)} 1 0 0 1 \"\"")
    out += [f"SURF {len(p.surfaces) + 1}", "  TYPE STANDARD", "  CURV 0.0", "  DISZ 0.0"]
    out += _mc_lines(p)
    if cats:
        out.insert(gcat_at, "GCAT " + " ".join(dict.fromkeys(cats)))
    if p.surfaces[-1].medium != AIR:
        out.append("BLNK")  # the file goes on past the image surface: an image space in a medium
    return "\n".join(out) + "\n"


_MAKER_OF = {legacy: maker for maker, legacy in LEGACY.items()}


def _mc_lines(p: Prescription) -> list[str]:
    """The configuration rows of a zoom lens (operand-major THIC, the stop's SDIA); its close-focus grid
    and uneven encoder places are dropped with a warning (a .zmx configuration has no such field)."""
    z = p.zoom
    if z is None:
        return []
    if z.close_distance is not None or z.encoder != tuple(c / (z.positions - 1) for c in range(z.positions)):
        warnings.warn(f"Zemax writer drops the zoom x focus grid and the encoder places of lens {p.name!r}",
                      PhysCamWarning, stacklevel=4)
    rows = [f"MNUM {z.positions} 1"]
    for g in z.gaps:
        rows += [f"THIC {g.surface + 1} {c + 1} {fmt(t)} 0 0 0 1 1 1 0 0 \"\" 0" for c, t in enumerate(g.thickness)]
    if z.stop_semi_diameter is not None:
        rows += [f"SDIA {p.stop_index + 1} {c + 1} {fmt(v)} 0 0 0 1 1 1 0 0 \"\" 0"
                 for c, v in enumerate(z.stop_semi_diameter)]
    return rows


def _named(m: Medium):
    """The catalogue glass a medium names, when its nd and Vd are that glass's; else None."""
    if m.glass is None:
        return None
    try:
        g = find_glass(m.glass, [m.catalog] if m.catalog else None)
    except GlassNotFound:
        return None
    return g if (g.nd, g.vd) == (m.nd, m.vd) else None

"""Zemax ``.agf`` glass catalogues (text, UTF-8, UTF-16 or the Windows code page).

Lines read (Zemax OpticStudio user manual, "Glass catalog file format"): ``NM name formula
MIL nd vd exclude status ...`` starts a glass; ``CD c1 .. c10`` its dispersion coefficients
(order of :mod:`physcam.lens.glassformulas`); ``LD min max`` its wavelength span in um;
``ED TCE ... dPgF`` its partial-dispersion deviation (4th field); ``IT lambda_um tau thickness_mm``
internal transmission rows (kept for 10 mm). Other lines (``CC``, ``GC``, ``TD``, ``OD``, ``BD``)
are comments and data physcam does not use. The catalogue's name is the file's stem.
"""

from __future__ import annotations

from pathlib import Path

from ..errors import LensFileError
from .catalog_glass import CatalogGlass
from .glassformulas import COEFFICIENT_COUNT, formula_index

__all__ = ["read_agf", "loads_agf"]


def _text(path: Path) -> str:
    data = path.read_bytes()
    if data[:2] in (b"\xff\xfe", b"\xfe\xff"):
        return data.decode("utf-16")
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError:
        return data.decode("cp1252")


def read_agf(path) -> tuple[str, dict[str, CatalogGlass]]:
    """(catalogue name, upper-case name -> glass) of the ``.agf`` file ``path``."""
    p = Path(path)
    try:
        text = _text(p)
    except OSError as exc:
        raise LensFileError(f"cannot read glass catalogue: {exc.strerror or exc}", str(p)) from None
    return p.stem.upper(), loads_agf(text, p.stem.upper(), str(p))


def _floats(tok, path, lineno, what):
    try:
        return [float(t) for t in tok]
    except ValueError:
        raise LensFileError(f"{what} line has a value that is not a number", path, lineno) from None


def loads_agf(text: str, name: str, path=None) -> dict[str, CatalogGlass]:
    """Parse ``.agf`` text of catalogue ``name``."""
    from ..errors import require_type

    require_type("text", text, str, "the .agf file's text (physcam.lens.agf.read_agf reads a file)")
    require_type("name", name, str, "the catalogue's name, e.g. 'MYGLASS'")
    rows: list[dict] = []
    for lineno, raw in enumerate(text.splitlines(), start=1):
        tok = raw.split()
        if not tok:
            continue
        key = tok[0].upper()
        if key == "NM":
            if len(tok) < 6:
                raise LensFileError("NM needs: name formula MIL nd vd", path, lineno)
            v = _floats(tok[2:6], path, lineno, "NM")
            rows.append({"name": tok[1], "formula": int(v[0]), "nd": v[2], "vd": v[3], "line": lineno,
                         "cd": None, "ld": None, "dpgf": 0.0, "it": []})
        elif not rows:
            continue
        elif key == "CD":
            rows[-1]["cd"] = _floats(tok[1:], path, lineno, "CD")
        elif key == "LD" and len(tok) >= 3:
            lo, hi = _floats(tok[1:3], path, lineno, "LD")
            rows[-1]["ld"] = (lo * 1000.0, hi * 1000.0)
        elif key == "ED" and len(tok) >= 5:
            rows[-1]["dpgf"] = _floats(tok[4:5], path, lineno, "ED")[0]
        elif key == "IT" and len(tok) >= 4:
            lam, tau, thick = _floats(tok[1:4], path, lineno, "IT")
            if thick == 10.0:
                rows[-1]["it"].append((lam * 1000.0, tau))
    return {r["name"].upper(): _glass(r, name, path) for r in rows}


def _glass(r, name, path) -> CatalogGlass:
    f = r["formula"]
    if f not in COEFFICIENT_COUNT:
        raise LensFileError(f"glass {r['name']}: dispersion formula {f} is not one of Zemax's 1-13", path, r["line"])
    if r["cd"] is None:
        raise LensFileError(f"glass {r['name']} has no CD (coefficients) line", path, r["line"])
    coefs = tuple(r["cd"][:COEFFICIENT_COUNT[f]])
    nd = float(formula_index(f, coefs, 0.5875618))
    if not nd == nd or nd <= 1.0:  # NaN or unphysical
        raise LensFileError(f"glass {r['name']}: its formula gives no index at 587.56 nm", path, r["line"])
    return CatalogGlass(r["name"], r["nd"], r["vd"], name, f, coefs, r["ld"], None, tuple(r["it"]), False, r["dpgf"])

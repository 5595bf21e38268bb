"""Zemax ``.agf`` glass catalogues (text, UTF-8, UTF-16 or the Windows code page).

Lines read (Zemax OpticStudio user manual, "Glass catalog file format"): ``NM name formula
MIL nd vd exclude status ...`` starts a glass; ``CD c1 .. c10`` its dispersion coefficients
(order of :mod:`physcam.lens.glassformulas`); ``LD min max`` its wavelength span in um;
``ED TCE ... dPgF`` its partial-dispersion deviation (4th field); ``IT lambda_um tau thickness_mm``
internal transmission rows (kept for 10 mm). Other lines (``CC``, ``GC``, ``TD``, ``OD``, ``BD``)
are comments and data physcam does not use. The catalogue's name is the file's stem.

What is refused, with file and line (issue 40 item 14): a path that is not a regular file (a
device such as ``/dev/zero``, a FIFO, a folder: refused from ``stat`` before it is opened, so
nothing blocks or grows), a file over :data:`MAX_AGF_BYTES`, text that is not UTF-8, UTF-16 (with
or without a byte-order mark) or the Windows code page, NUL bytes, a number that is not a plain
finite decimal (``nan``, ``inf``, ``1e999``), a formula number that is not one of Zemax's whole
numbers 1-13 (``2.7`` is not read as 2), a ``CD`` line with fewer coefficients than its formula
uses (a truncated Sellmeier line), a second ``CD`` line for one glass, and a range ``LD`` that is
empty or not positive. Line ends may be mixed (``\\r\\n``, ``\\n``, ``\\r``); a line of bare
numbers continues the line before it (Nikon's catalogue wraps its ``CD`` lines). Said in one
:class:`~physcam.errors.PhysCamWarning` each, the catalogue still read: a glass named twice
(both lines named; the first is used: makers' own files do it, HOYA's FD1, HIKARI's E-F2), and
the entries left out because they are no glass physcam can use (nd below 1, such as MISC's
VACUUM; no index at 587.56 nm, such as the infrared AMTIR3).
"""

from __future__ import annotations

import os
import re
import stat
import warnings
from pathlib import Path

from ..errors import LensFileError, PhysCamWarning
from .catalog_glass import CatalogGlass
from .glassformulas import COEFFICIENT_COUNT, FORMULA_NAMES, formula_index
from .prescription import MAX_INDEX

__all__ = ["read_agf", "loads_agf", "MAX_AGF_BYTES"]

#: Larger files are refused before reading (makers' catalogues are up to ~2.5 MB in UTF-16).
MAX_AGF_BYTES = 32 * 1024 * 1024
_NUMBER = re.compile(r"[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?")
_LINE_END = re.compile(r"\r\n|\r|\n")
_KINDS = ((stat.S_ISDIR, "a folder"), (stat.S_ISCHR, "a character device"), (stat.S_ISBLK, "a block device"),
          (stat.S_ISFIFO, "a FIFO (named pipe)"), (stat.S_ISSOCK, "a socket"))


def _not_regular(mode: int) -> str | None:
    """What a non-regular file is ("a FIFO (named pipe)"...), None for a regular file."""
    if stat.S_ISREG(mode):
        return None
    return next((what for test, what in _KINDS if test(mode)), "not a regular file")


def _read_bytes(p: Path) -> bytes:
    """The bytes of the regular file ``p``, at most :data:`MAX_AGF_BYTES`: stat first (a device or
    FIFO is never opened), then opened without blocking and checked again on the open file."""
    where = str(p)
    try:
        kind = _not_regular(os.stat(p).st_mode)
        if kind is None:
            fd = os.open(p, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_NOCTTY", 0)
                         | getattr(os, "O_BINARY", 0))
            try:
                st = os.fstat(fd)
                kind = _not_regular(st.st_mode)  # swapped for a FIFO between stat and open
                if kind is None and st.st_size > MAX_AGF_BYTES:
                    raise LensFileError(f"glass catalogue is {st.st_size} bytes; over {MAX_AGF_BYTES} bytes is "
                                        "refused", where)
                data = b"" if kind else _read_at_most(fd, MAX_AGF_BYTES + 1)
            finally:
                os.close(fd)
    except OSError as exc:
        raise LensFileError(f"cannot read glass catalogue: {exc.strerror or exc}", where) from None
    if kind is not None:
        raise LensFileError(f"glass catalogue is {kind}, not a regular file (a Zemax .agf text file)", where)
    if len(data) > MAX_AGF_BYTES:
        raise LensFileError(f"glass catalogue is over {MAX_AGF_BYTES} bytes; refused", where)
    return data


def _read_at_most(fd: int, limit: int) -> bytes:
    chunks, size = [], 0
    while size < limit:
        chunk = os.read(fd, min(1 << 20, limit - size))
        if not chunk:
            break
        chunks.append(chunk)
        size += len(chunk)
    return b"".join(chunks)


def _decode(data: bytes, path) -> str:
    """Text of an .agf file: UTF-16 (byte-order mark, or NUL bytes in every other place), UTF-8
    (with or without a mark), else the Windows code page (Latin-1 where cp1252 has no character)."""
    codec = None
    if data[:2] in (b"\xff\xfe", b"\xfe\xff"):
        codec = "utf-16"
    elif b"\x00" in data[:400]:
        head = data[:400]
        codec = "utf-16-le" if head[1::2].count(0) > head[0::2].count(0) else "utf-16-be"
    if codec is not None:
        try:
            text = data.decode(codec)
        except UnicodeDecodeError as exc:
            line = data[: exc.start].decode(codec, errors="ignore").count("\n") + 1
            raise LensFileError(f"not valid UTF-16 text ({exc.reason})", path, line) from None
    else:
        try:
            text = data.decode("utf-8-sig")
        except UnicodeDecodeError:
            try:
                text = data.decode("cp1252")
            except UnicodeDecodeError:
                text = data.decode("latin-1")
    if "\x00" in text:
        raise LensFileError("contains NUL bytes: not a text glass catalogue", path,
                            len(_LINE_END.split(text[: text.index("\x00")])))
    return text


def read_agf(path) -> tuple[str, dict[str, CatalogGlass]]:
    """(catalogue name, upper-case name -> glass) of the ``.agf`` file ``path`` (module notes)."""
    p = Path(path)
    text = _decode(_read_bytes(p), str(p))
    return p.stem.upper(), loads_agf(text, p.stem.upper(), str(p))


def _floats(tok, path, lineno, what):
    out = []
    for t in tok:
        if not _NUMBER.fullmatch(t):
            raise LensFileError(f"{what} line has {t[:20]!r}, which is not a number", path, lineno)
        v = float(t)
        if v != v or v in (float("inf"), float("-inf")):
            raise LensFileError(f"{what} line has {t[:20]!r}, which is not a finite number", path, lineno)
        out.append(v)
    return out


def _formula(token: str, path, lineno) -> int:
    """Zemax's formula number: a whole number 1-13, written as one ("2", or "2.0")."""
    (v,) = _floats([token], path, lineno, "NM")
    if v != int(v) or int(v) not in COEFFICIENT_COUNT:
        raise LensFileError(f"dispersion formula {token!r} is not one of Zemax's whole numbers 1-13", path, lineno)
    return int(v)


def _new_row(tok, path, lineno) -> dict:
    if len(tok) < 6:
        raise LensFileError("NM needs: name formula MIL nd vd", path, lineno)
    formula = _formula(tok[2], path, lineno)
    nd, vd = _floats([tok[4], tok[5]], path, lineno, "NM")
    return {"name": tok[1], "formula": formula, "nd": nd, "vd": vd, "line": lineno, "cd": None, "ld": None,
            "dpgf": 0.0, "it": []}


def _glass_line(row: dict, key: str, tok, path, lineno) -> None:
    """Read a CD, LD, ED or IT line into the glass ``row`` (other keys: nothing)."""
    if key == "CD":
        if row["cd"] is not None:
            raise LensFileError(f"glass {row['name']} has a second CD line", path, lineno)
        row["cd"] = _floats(tok[1:], path, lineno, "CD")
        row["cd_line"] = lineno
    elif key == "LD" and len(tok) >= 3:
        lo, hi = _floats(tok[1:3], path, lineno, "LD")
        if not 0.0 < lo < hi:
            raise LensFileError(f"glass {row['name']}: wavelength range {tok[1]}-{tok[2]} um is empty", path, lineno)
        row["ld"] = (lo * 1000.0, hi * 1000.0)
    elif key == "ED" and len(tok) >= 5:
        row["dpgf"] = _floats(tok[4:5], path, lineno, "ED")[0]
    elif key == "IT" and len(tok) >= 4:
        lam, tau, thick = _floats(tok[1:4], path, lineno, "IT")
        if thick == 10.0:
            row["it"].append((lam * 1000.0, tau))


def loads_agf(text: str, name: str, path=None) -> dict[str, CatalogGlass]:
    """Parse ``.agf`` text of catalogue ``name`` (module notes: what is refused)."""
    from ..errors import require_type

    require_type("text", text, str, "the .agf file's text (physcam.lens.agf.read_agf reads a file)")
    require_type("name", name, str, "the catalogue's name, e.g. 'MYGLASS'")
    rows: list[dict] = []
    last = None  # the keyword line a line of bare numbers continues
    for lineno, raw in enumerate(_LINE_END.split(text), start=1):
        tok = raw.split()
        if not tok:
            continue
        key = tok[0].upper()
        if _NUMBER.fullmatch(tok[0]) and last is not None:
            if last == "CD" and rows:
                rows[-1]["cd"] += _floats(tok, path, lineno, "CD")
            continue
        last = key
        if key == "NM":
            rows.append(_new_row(tok, path, lineno))
        elif rows:
            _glass_line(rows[-1], key, tok, path, lineno)
    if not rows:
        raise LensFileError("no glass (no NM line): not a Zemax .agf glass catalogue", path)
    return _catalogue(rows, name, path)


def _catalogue(rows, name, path) -> dict[str, CatalogGlass]:
    """The glasses of ``rows`` by upper-case name; one warning for names given twice, one for the
    entries left out (module notes)."""
    out: dict[str, CatalogGlass] = {}
    first_line: dict[str, int] = {}
    twice, left_out = [], []
    for r in rows:
        key = r["name"].upper()
        if key in first_line:
            twice.append(f"{r['name']} on lines {first_line[key]} and {r['line']}")
            continue
        first_line[key] = r["line"]
        glass, why = _glass(r, name, path)
        if glass is None:
            left_out.append(f"{r['name']} (line {r['line']}: {why})")
        else:
            out[key] = glass
    where = path or name
    if twice:
        warnings.warn(f"{where}: glass defined twice: {'; '.join(twice)}; the first of each is used",
                      PhysCamWarning, stacklevel=3)
    if left_out:
        warnings.warn(f"{where}: {len(left_out)} entr{'y' if len(left_out) == 1 else 'ies'} left out, no glass "
                      f"physcam can use: {', '.join(left_out)}", PhysCamWarning, stacklevel=3)
    if not out:
        raise LensFileError("no glass physcam can use in the catalogue", path)
    return out


def _glass(r, name, path) -> tuple[CatalogGlass | None, str]:
    """(the glass of row ``r``, "") or (None, why it is no usable glass); LensFileError for a cut
    coefficient line."""
    f = r["formula"]
    if r["cd"] is None:
        raise LensFileError(f"glass {r['name']} has no CD (coefficients) line", path, r["line"])
    need = COEFFICIENT_COUNT[f]
    if len(r["cd"]) < need:
        raise LensFileError(f"glass {r['name']}: its {FORMULA_NAMES[f]} formula (Zemax {f}) uses {need} coefficients, "
                            f"the CD line gives {len(r['cd'])} (cut short?)", path, r["cd_line"])
    coefs = tuple(r["cd"][:need])
    try:
        nd = float(formula_index(f, coefs, 0.5875618))
    except (ZeroDivisionError, OverflowError, ValueError, TypeError):
        nd = float("nan")
    if not (nd == nd and 1.0 < nd <= MAX_INDEX):  # NaN, complex (a negative square) or unphysical
        return None, "no index at 587.56 nm"
    if not (1.0 <= r["nd"] <= MAX_INDEX and r["vd"] >= 0.0):
        return None, f"nd {r['nd']:g} and Vd {r['vd']:g} are no glass's"
    return CatalogGlass(r["name"], r["nd"], r["vd"], name, f, coefs, r["ld"], None, tuple(r["it"]), False,
                        r["dpgf"]), ""

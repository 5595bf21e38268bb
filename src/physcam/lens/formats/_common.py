"""Helpers shared by the lens-file readers: safe text loading and checked numbers."""

from __future__ import annotations

import json
import math
from pathlib import Path

from ...errors import LensFileError
from ..prescription import Focus, Prescription, VariableGap, takes_prescription

#: Files larger than this are refused before parsing (a lens file is a few kB).
MAX_FILE_BYTES = 10 * 1024 * 1024
#: More surfaces than this is not a camera lens.
MAX_SURFACES = 500
#: Largest length (mm) accepted in a file: 1 km. Guards the geometry from overflow.
MAX_LENGTH_MM = 1.0e6


def read_text(path) -> str:
    """The file's text (UTF-8, BOM allowed); LensFileError for missing, huge or binary files."""
    p = Path(path)
    try:
        size = p.stat().st_size
    except OSError as exc:
        raise LensFileError(f"cannot read lens file: {exc.strerror or exc}", str(p)) from None
    if not p.is_file():
        raise LensFileError("not a file", str(p))
    if size > MAX_FILE_BYTES:
        raise LensFileError(f"file is {size} bytes; lens files over {MAX_FILE_BYTES} bytes are refused", str(p))
    try:
        data = p.read_bytes()
    except OSError as exc:
        raise LensFileError(f"cannot read lens file: {exc.strerror or exc}", str(p)) from None
    return decode(data, str(p))


def decode(data: bytes, path: str | None) -> str:
    if len(data) > MAX_FILE_BYTES:
        raise LensFileError(f"lens files over {MAX_FILE_BYTES} bytes are refused", path)
    try:
        if data[:2] in (b"\xff\xfe", b"\xfe\xff"):  # Zemax writes UTF-16 with a BOM
            text = data.decode("utf-16")
        else:
            text = data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        if path is not None and str(path).lower().endswith(".zmx") and b"\x00" not in data:
            text = data.decode("cp1252", errors="replace")  # OpticStudio's "ANSI" files
        elif data[:4] == b"PK\x03\x04":  # a zip: most likely a lens archive of `physcam lens pack`
            import shlex

            named = shlex.quote(str(path))
            raise LensFileError(f"a zip archive, not a lens file: a lens archive (NAME.lens.zip) is installed with "
                                f"`physcam lens add {named}` and then named by its lens (`physcam lens check {named}` "
                                f"checks it first)", path) from None
        else:
            line = data[: exc.start].count(b"\n") + 1
            raise LensFileError("not a UTF-8 text file (binary data?)", path, line) from None
    if "\x00" in text:
        raise LensFileError("contains NUL bytes; not a text lens file", path, text[: text.index("\x00")].count("\n") + 1)
    return text


def number(value, what: str, path, line, *, length: bool = True) -> float:
    """``value`` as a finite float, else LensFileError naming ``what`` at ``path:line``."""
    if isinstance(value, bool):
        raise LensFileError(f"{what} must be a number, got {value!r}", path, line)
    if isinstance(value, str):
        try:
            v = float(value)
        except ValueError:
            raise LensFileError(f"{what} must be a number, got {value!r}", path, line) from None
    elif isinstance(value, (int, float)):
        try:
            v = float(value)
        except OverflowError:
            raise LensFileError(f"{what} is too large: {value!r}", path, line) from None
    else:
        raise LensFileError(f"{what} must be a number, got {type(value).__name__}", path, line)
    if not math.isfinite(v):
        raise LensFileError(f"{what} must be a finite number, got {value!r}", path, line)
    if length and abs(v) > MAX_LENGTH_MM:
        raise LensFileError(f"{what} {v:g} mm is beyond {MAX_LENGTH_MM:g} mm; check the units", path, line)
    return v


def check_count(n: int, path, line=None) -> None:
    if n == 0:
        raise LensFileError("no surfaces found", path, line)
    if n > MAX_SURFACES:
        raise LensFileError(f"{n} surfaces; more than {MAX_SURFACES} is refused", path, line)


def validated(p: Prescription, path, lines) -> Prescription:
    """``p.validate(path, lines)``, turning arithmetic overflow into LensFileError."""
    try:
        return p.validate(None if path is None else str(path), list(lines))
    except (ArithmeticError, ValueError) as exc:
        raise LensFileError(f"lens geometry cannot be evaluated ({exc}); check the numbers", path) from None


def fmt(v: float) -> str:
    """Shortest text that reads back as the same float (``repr``), ints without '.0' noise kept."""
    return repr(float(v))


@takes_prescription
def extra(p: Prescription, key: str, default=None):
    """The decoded JSON value stored under ``key`` in ``p.extras``."""
    for k, v in p.extras:
        if k == key:
            return json.loads(v)
    return default


def json_text(value) -> str:
    """Canonical JSON text for an extras value (stable: compact separators, keys in file order)."""
    return json.dumps(value, separators=(",", ":"), ensure_ascii=False, allow_nan=False)


# ---- TOML (reading: tomllib; writing: by hand so comments and order stay readable) ----

_TOML_LINE = __import__("re").compile(r"at line (\d+)")


def parse_toml(text: str, path):
    """``tomllib.loads`` with errors as LensFileError carrying the line."""
    import tomllib

    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        m = _TOML_LINE.search(str(exc))
        raise LensFileError(f"not valid TOML: {str(exc).split(' (at')[0]}", path, int(m.group(1)) if m else None) from None
    except (RecursionError, ValueError) as exc:
        raise LensFileError(f"not valid TOML: {exc}", path) from None


def table_lines(text: str, header: str, n: int) -> list[int | None]:
    """1-based line numbers of the first ``n`` array-of-table headers ``[[header]]``."""
    import re

    pat = re.compile(r"^\s*\[\[\s*" + re.escape(header).replace(r"\.", r"\s*\.\s*") + r"\s*\]\]")
    found = [i for i, line in enumerate(text.splitlines(), start=1) if pat.match(line)]
    return (found + [None] * n)[:n]


def toml_value(v) -> str:
    """TOML text for a str, bool, int, float or list of them."""
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        return repr(v)
    if isinstance(v, str):
        return json.dumps(v, ensure_ascii=False).replace("\x7f", "\\u007f")
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(toml_value(x) for x in v) + "]"
    raise TypeError(f"cannot write {type(v).__name__} to TOML")


def toml_key(k: str) -> str:
    import re

    return k if re.fullmatch(r"[A-Za-z0-9_-]+", k) else toml_value(k)


def table(d: dict, where: str, path, line=None) -> dict:
    if not isinstance(d, dict):
        raise LensFileError(f"{where} must be a table", path, line)
    return d


def unknown_keys(d: dict, allowed, where: str, path, line=None) -> None:
    extra_keys = [k for k in d if k not in allowed]
    if extra_keys:
        raise LensFileError(
            f"{where}: unknown key {extra_keys[0]!r}; allowed keys are {', '.join(allowed)}", path, line
        )


def text_field(d: dict, key: str, where: str, path, line=None) -> str | None:
    v = d.get(key)
    if v is None:
        return None
    if not isinstance(v, str):
        raise LensFileError(f"{where}.{key} must be a string, got {v!r}", path, line)
    return v


def one_line(s: str) -> str:
    """``s`` made safe for a single comment/header line: control characters become spaces."""
    return "".join(" " if (ord(c) < 32 and c != "\t") or ord(c) == 127 or c in "\x85\u2028\u2029" else c for c in s)


def focus_table(f: dict, surfaces, text: str, path, rows_key: str) -> Focus:
    """The ``[focus]`` table of the TOML formats: ``close_distance`` and ``[[focus.<rows_key>]]``
    rows of ``surface`` (0-based) and ``thickness_close``; physcam's own rows may also carry
    ``thickness_infinity`` (the seeds' take it from the surface)."""
    unknown_keys(f, ("close_distance", rows_key), "[focus]", path)
    if "close_distance" not in f:
        raise LensFileError("[focus] needs close_distance (mm from the front vertex)", path)
    close = number(f["close_distance"], "[focus] close_distance", path, None)
    rows = f.get(rows_key, [])
    header = f"focus.{rows_key}"
    if not isinstance(rows, list):
        raise LensFileError(f"[[{header}]] must be an array of tables", path)
    row_keys = ("surface", "thickness_close") + (("thickness_infinity",) if rows_key == "gap" else ())
    lines = table_lines(text, header, len(rows))
    gaps = []
    for j, g in enumerate(rows):
        ln = lines[j]
        g = table(g, f"focus {rows_key} {j}", path, ln)
        unknown_keys(g, row_keys, f"[[{header}]]", path, ln)
        s = g.get("surface")
        if isinstance(s, bool) or not isinstance(s, int) or not 0 <= s < len(surfaces):
            raise LensFileError(
                f"focus {rows_key} {j}: surface must be a 0-based index below {len(surfaces)}, got {s!r}", path, ln)
        if "thickness_close" not in g:
            raise LensFileError(f"focus {rows_key} {j} has no thickness_close", path, ln)
        t_inf = number(g.get("thickness_infinity", surfaces[s].thickness), "thickness_infinity", path, ln)
        gaps.append(VariableGap(s, t_inf, number(g["thickness_close"], "thickness_close", path, ln)))
    return Focus(close, tuple(gaps))


def surface_rows(doc: dict, text: str, path) -> tuple[list, list[int | None]]:
    """The ``[[surface]]`` tables of a TOML lens and the file line of each (for error messages)."""
    rows = doc.get("surface")
    if not isinstance(rows, list):
        raise LensFileError("no [[surface]] tables", path)
    check_count(len(rows), path)
    return rows, table_lines(text, "surface", len(rows))


def takes_text(fn):
    """Decorator for a reader's ``loads(text, ...)``: ``text`` must be a str (the file's content),
    else :class:`~physcam.errors.WrongTypeError` (a path or bytes goes through ``load_lens``)."""
    import functools

    from ...errors import require_type

    @functools.wraps(fn)
    def checked(text, *args, **kwargs):
        require_type("text", text, str, "the file's content; read a file with physcam.lens.library.load_lens(path)")
        return fn(text, *args, **kwargs)

    return checked

"""Reading metadata text with file and line numbers: delimited rows, numbers, stop notations."""

from __future__ import annotations

import csv
import itertools
import math
import re
from fractions import Fraction
from pathlib import Path

from ..errors import MetadataError

#: the largest metadata file physcam reads (an hour of 240 fps AME rows is ~1 GB; refuse more)
MAX_BYTES = 2_000_000_000
FOOT_MM = 304.8  # international foot (1959), exact


def _check_size(p: Path, limit: int) -> None:
    try:
        size = p.stat().st_size
    except OSError as exc:
        raise MetadataError(f"cannot read it ({exc.strerror or exc})", p) from None
    if size > limit:
        raise MetadataError(f"the file is larger than {limit / 10**9:g} GB", p)


def encoding_of(head: bytes) -> str:
    """The text encoding a file's first bytes announce: "utf-16" after a UTF-16 byte-order mark (a
    spreadsheet's "Unicode text" export of a clip's CSV), else "utf-8-sig" (UTF-8, a BOM dropped)."""
    return "utf-16" if head[:2] in (b"\xff\xfe", b"\xfe\xff") else "utf-8-sig"


def not_utf8(p, byte: int, offset: int, line: int) -> MetadataError:
    """The refusal of a file whose byte at ``offset`` (on ``line``), ``byte``, is no UTF-8 character (a
    Latin-1 or Windows-1252 export writes "\u00e9" as the one byte 0xE9)."""
    return MetadataError(f"not UTF-8 text: byte 0x{byte:02X} (line {line}) is no UTF-8 character (a Latin-1 or "
                         "Windows-1252 export writes \u00e9 as 0xE9): save it as UTF-8", p, offset=offset)


def _decode_error(p: Path, encoding: str) -> MetadataError:
    """The refusal of a text file that does not decode. UTF-8: the first offending byte, found by reading the
    file again in 1 MB blocks (the text reader decodes ahead of the line it gives, so its line is not the
    byte's), with its offset and line; UTF-16: the file, not a position."""
    if encoding == "utf-16":
        return MetadataError("not UTF-16 text (a lone surrogate or an odd number of bytes)", p)
    pos, lines_before, carry = 0, 0, b""
    with open(p, "rb") as fh:
        while True:
            block = fh.read(1 << 20)
            buf = carry + block
            if pos == 0 and buf.startswith(b"\xef\xbb\xbf"):
                buf, pos = buf[3:], 3
            try:
                buf.decode("utf-8")
                carry = b""
            except UnicodeDecodeError as exc:
                if not (block and exc.reason == "unexpected end of data"):
                    return not_utf8(p, buf[exc.start], pos + exc.start,
                                    lines_before + buf[:exc.start].count(b"\n") + 1)
                carry = buf[exc.start:]  # a character cut at the block's end: decoded with the next block
            if not block:
                return MetadataError("not UTF-8 text", p)
            done = len(buf) - len(carry)
            lines_before += buf[:done].count(b"\n")
            pos += done


def read_text(path, limit: int = MAX_BYTES) -> str:
    """A small metadata file (a static CSV, an XML) as text (UTF-8, or UTF-16 with its BOM; a BOM
    dropped); a binary file or a missing one is a MetadataError. Per-frame files are read row by row
    (:func:`rows`, :func:`lines`)."""
    p = Path(path)
    _check_size(p, limit)
    try:
        data = p.read_bytes()
    except OSError as exc:
        raise MetadataError(f"cannot read it ({exc.strerror or exc})", p) from None
    encoding = encoding_of(data)
    if encoding != "utf-16" and b"\0" in data[:4096]:
        raise MetadataError("a binary file, not a metadata text export", p, 1)
    try:
        return data.decode(encoding)
    except UnicodeDecodeError as exc:
        if encoding == "utf-16":
            raise _decode_error(p, encoding) from None
        at = exc.start + (3 if data.startswith(b"\xef\xbb\xbf") else 0)
        raise not_utf8(p, data[at], at, data[:at].count(b"\n") + 1) from None


def _open_text(p: Path):
    """The file opened as text (UTF-8 or UTF-16 by its BOM, the BOM dropped, newlines kept for the csv
    module), after the size and binary checks."""
    import io

    _check_size(p, MAX_BYTES)
    try:
        fh = open(p, "rb")  # opened once: its first bytes read for the encoding, then read again as text
    except OSError as exc:
        raise MetadataError(f"cannot read it ({exc.strerror or exc})", p) from None
    try:
        head = fh.peek(4096)[:4096]
        encoding = encoding_of(head)
        if encoding != "utf-16" and b"\0" in head:
            raise MetadataError("a binary file, not a metadata text export", p, 1)
        return io.TextIOWrapper(fh, encoding=encoding, newline="")
    except BaseException:
        fh.close()
        raise


def lines(path):
    """Yield (line number, text without its line break) of a text file, read a line at a time (memory
    of one line, whatever the file's size)."""
    p = Path(path)
    n = 0
    with _open_text(p) as fh:
        try:
            for n, raw in enumerate(fh, 1):
                yield n, raw.rstrip("\r\n")
        except UnicodeDecodeError:
            raise _decode_error(p, fh.encoding) from None


def rows(path, delimiter=",") -> tuple[list[str], object]:
    """(header, rows) of a delimited file, streamed: ``rows`` yields (line, {column: cell}) one row at
    a time, so a reader keeps only what it takes from each row (memory near the file's size at
    most). A row whose field count differs from the header's (a truncated file) is an error naming
    its line; a blank line is skipped. Duplicate columns keep the first. ``delimiter``: one character, or
    a function of the file's first line (its text, without the line break) that picks it: the header is
    read once, for both."""
    p = Path(path)
    fh = _open_text(p)
    try:  # the file is closed here when the header cannot be read (or the delimiter not picked), else by the rows
        header, reader = _header(p, fh, delimiter)
    except BaseException:
        fh.close()
        raise
    data = _data_rows(p, fh, reader, header)
    next(data)  # inside its `with fh` now: a reader that drops the rows unread (a missing column) closes the file
    return header, data


def _header(p, fh, delimiter):
    """(header, csv reader positioned after it) of the open file ``fh`` (:func:`rows`)."""
    try:
        first = fh.readline()
    except UnicodeDecodeError:
        raise _decode_error(p, fh.encoding) from None
    if callable(delimiter):
        delimiter = delimiter(first.rstrip("\r\n"))
    reader = csv.reader(itertools.chain([first] if first else [], fh), delimiter=delimiter)
    try:
        header = next(reader)
    except StopIteration:
        raise MetadataError("the file is empty", p, 1) from None
    except UnicodeDecodeError:
        raise _decode_error(p, fh.encoding) from None
    except csv.Error as exc:
        raise MetadataError(f"cannot read the header ({exc})", p, 1) from None
    return [h.strip() for h in header], reader


def _data_rows(p, fh, reader, header):
    """The rows of :func:`rows`; its first ``next`` only enters the file's ``with`` (yields None)."""
    with fh:
        yield None
        try:
            for cells in reader:
                line = reader.line_num
                if not cells or (len(cells) == 1 and not cells[0].strip()):
                    continue
                if len(cells) != len(header):
                    raise MetadataError(f"{len(cells)} fields where the header has {len(header)}: the file is "
                                        "truncated or its rows do not match its header", p, line)
                row: dict = {}
                for h, c in zip(header, cells):
                    row.setdefault(h, c.strip())
                yield line, row
        except csv.Error as exc:
            raise MetadataError(f"cannot read the row ({exc})", p, reader.line_num) from None
        except UnicodeDecodeError:
            raise _decode_error(p, fh.encoding) from None


def single_row(path, what: str, columns=()) -> tuple[list[str], int, dict]:
    """(header, line, row) of a static CSV: exactly one row after its header (reading stops at the second)."""
    header, data = rows(path)
    require_columns(path, header, columns, what)
    got = []
    for item in data:
        got.append(item)
        if len(got) > 1:
            data.close()
            break
    if len(got) != 1:
        raise MetadataError(f"{'no row' if not got else 'more than one row'} where {what} has one", path,
                            got[1][0] if got else 2)
    return header, got[0][0], got[0][1]


def header_columns(first_line: str, delimiter: str = ",") -> list[str]:
    """The column names of a header line, quoted or not (a CSV a spreadsheet saved again drops or adds
    the quotes), stripped."""
    try:
        return [c.strip() for c in next(csv.reader([first_line], delimiter=delimiter), [])]
    except csv.Error:
        return []


def lacking_columns(cols, groups) -> list[tuple[str, ...]]:
    """The groups of ``groups`` (each a tuple of column names, one of which a layout needs) that none of
    ``cols`` satisfies; a name ending in "(" is a prefix (VENICE's "Focus Distance (ft)")."""
    def has(name):
        return name in cols or (name.endswith("(") and any(c.startswith(name) for c in cols))

    return [g for g in groups if not any(has(n) for n in g)]


def require_columns(path, header, columns, what: str) -> None:
    missing = [c for c in columns if c not in header]
    if missing:
        raise MetadataError(f"unknown column layout for {what}: no {', '.join(repr(c) for c in missing)} column",
                            path, 1)


def number(path, line, name, text, *, empty_none: bool = True) -> float | None:
    """A finite number from a cell; empty or "--" (not recorded) is None; anything else an error."""
    t = (text or "").strip()
    if empty_none and t in ("", "--", "n.a.", "-"):
        return None
    try:
        v = float(Fraction(t)) if "/" in t else float(t)
    except (ValueError, ZeroDivisionError):
        raise MetadataError(f"{name} {t!r} is not a number", path, line) from None
    if not math.isfinite(v):
        raise MetadataError(f"{name} {t!r} is not a finite number", path, line)
    return v


def exact_rate(fps) -> Fraction | None:
    """A file's frame rate (a number, or an exact Fraction) as the exact fraction every reader gives:
    :func:`physcam.frame_rates.exact_frame_rate`, the rule ``live send --fps``, ``live record`` and ``usd
    animate --fps`` use (an NTSC rate, 23.976 or VENICE's 23.98, 29.97, 59.94, is N x 1000/1001: SMPTE ST
    12-1's rates; any other the nearest fraction with a denominator up to 1001); a value no camera records
    (0 or negative) is kept for :mod:`.limits` to refuse. None stays None.

    >>> exact_rate(23.976), exact_rate(29.97), exact_rate(25.0), exact_rate(Fraction(30000, 1001))
    (Fraction(24000, 1001), Fraction(30000, 1001), Fraction(25, 1), Fraction(30000, 1001))
    """
    from ..frame_rates import exact_frame_rate

    return None if fps is None else exact_frame_rate(fps)


_STOP = re.compile(r"^\s*T?\s*(\d+(?:\.\d+)?)\s*(?:\+?\s*(\d+)\s*/\s*10)?\s*$")


def stop_from_marking(path, line, name, text) -> float | None:
    """A stop written as a full-stop marking plus tenths of a stop ("1.4 + 7/10", "T 2 3/10"):
    the marking N is the nearest whole stop AV = round(2 log2 N) (1, 1.4, 2, 2.8 ... are AV 0..),
    and N = 2^((AV + tenths/10) / 2) (a stop is a factor of sqrt 2 in N)."""
    t = (text or "").strip()
    if t in ("", "--"):
        return None
    m = _STOP.match(t)
    if not m:
        raise MetadataError(f"{name} {t!r} is not a stop (like 'T 2 3/10' or '1.4 + 7/10')", path, line)
    marking = float(m.group(1))
    if marking <= 0:
        raise MetadataError(f"{name} {t!r} is not a stop", path, line)
    av = round(2 * math.log2(marking))
    tenths = int(m.group(2) or 0)
    return 2.0 ** ((av + tenths / 10.0) / 2.0)


_TC = re.compile(r"^\d{1,2}:\d{2}:\d{2}[:;.]\d{2}$")


def timecode(path, line, text) -> str | None:
    t = (text or "").strip()
    if t in ("", "--"):
        return None
    if not _TC.match(t):
        raise MetadataError(f"timecode {t!r} is not HH:MM:SS:FF", path, line)
    return t if len(t.split(":")[0]) == 2 else "0" + t

"""Text from lens files and users, made safe to place in the code and scene files physcam writes.

A lens name, notes, a maker, a sensor or variant name, a path: any of them may hold a line break, a
quote, a backslash or a control character, and a file physcam writes must still parse as the
comment, string or line it was meant to be, with nothing of the text left outside. Each exporter
calls one function of this module where such text enters its output (its "door"); each function
either escapes for its language, so the text survives exactly where the language can hold it, or
raises :class:`~physcam.errors.ExportError` in one line where it cannot.

The common first step, :func:`printable_line`, keeps a text on one line: every character of the
Unicode categories Cc (controls: NUL, CR, LF, TAB, ESC, DEL, C1), Cf (format: the bidirectional
overrides of "Trojan Source", CVE-2021-42574), Cs (lone surrogates, what non-UTF-8 bytes decode to
with ``surrogateescape``), Co, Cn, Zl and Zp (U+2028, U+2029) becomes U+FFFD, so no language sees a
line end (Python's ``str.splitlines`` boundaries included) and the file always encodes as UTF-8. A tab,
white space within a line (pbrt's own lens files separate their header's words with tabs), becomes a space.
"""

from __future__ import annotations

import re
import unicodedata

from ..errors import ExportError

__all__ = ["printable_line", "osl_comment", "hash_comment", "python_docstring", "python_comment",
           "xml_comment", "xml_attribute", "pbrt_string", "nuke_file_path", "usd_text", "REPLACEMENT", "COMMENT_CHARS",
           "UNSAFE_CATEGORIES"]

#: What stands in for a character a line cannot hold (U+FFFD REPLACEMENT CHARACTER).
REPLACEMENT = "\ufffd"
#: Longest text a comment keeps (characters); a longer one is cut and ends in an ellipsis.
COMMENT_CHARS = 400
#: Unicode categories no line written (nor a query value ``physcam serve`` reads) may hold: the module notes.
UNSAFE_CATEGORIES = frozenset(("Cc", "Cf", "Cs", "Co", "Cn", "Zl", "Zp"))


def printable_line(text, *, limit: int | None = None) -> str:
    """``text`` (any object; ``str()`` of it) on one printable line: a tab becomes a space, characters of the
    categories in the module notes U+FFFD; cut to ``limit`` characters (the last an ellipsis) when given."""
    s = "".join(" " if c == "\t" else REPLACEMENT if unicodedata.category(c) in UNSAFE_CATEGORIES else c for c in str(text))
    if limit is not None and len(s) > limit:
        s = s[: limit - 1] + "\u2026"
    return s


def osl_comment(text) -> str:
    """``text`` safe inside an OSL ``//`` comment. OSL source goes through a C preprocessor (OSL
    language specification 1.x, "Preprocessing": the C99/C++ preprocessor): a ``//`` comment runs to
    the end of the line (ISO C 6.4.9), but a backslash before the line end splices the next line in
    first (C 5.1.1.2, phase 2), and the trigraph ``??/`` is a backslash (phase 1, where trigraphs are
    on). So: one printable line, ``\\`` written ``/``, and no ``??``."""
    s = printable_line(text, limit=COMMENT_CHARS).replace("\\", "/")
    return re.sub(r"\?(?=\?)", "? ", s)


def hash_comment(text) -> str:
    """``text`` safe inside a ``#`` comment that runs to the line end: RenderMan RIB (RIB spec 3.2,
    "comments": ``#`` to the end of the line), pbrt-v4 scene and ``.dat`` files (its tokenizer skips
    from ``#`` to ``\\n`` or ``\\r``), and Nuke ``.nk`` scripts (Tcl: ``#`` to the line end). One
    printable line is enough: none of them splices lines inside a comment."""
    return printable_line(text, limit=COMMENT_CHARS)


def _no_coding_cookie(s: str) -> str:
    """Break ``coding:``/``coding=``: on a script's first two lines that pattern declares the source
    encoding (PEP 263; CPython reads it before tokenizing, even inside a string), and an encoding
    such as UTF-7 would turn later text into code."""
    return re.sub(r"(?i)(coding)([:=])", r"\1 \2", s)


def python_comment(text) -> str:
    """``text`` safe in a Python ``#`` comment (Python reference, 2.1.3: to the end of the physical
    line; 2.1.2: a line ends at LF, CR or CR LF): one printable line, no encoding declaration."""
    return _no_coding_cookie(printable_line(text, limit=COMMENT_CHARS))


def python_docstring(text) -> str:
    """``text`` safe as one line of a Python ``\"\"\"`` string (Python reference, 2.4.1: a backslash
    starts an escape sequence, ``\\N{...}`` and ``\\x`` must be complete, and ``\"\"\"`` ends the
    string): one printable line with ``\\`` and ``\"`` escaped, so the string reads back as that
    line exactly; no encoding declaration (:func:`python_comment`)."""
    s = _no_coding_cookie(printable_line(text, limit=COMMENT_CHARS))
    return s.replace("\\", "\\\\").replace('"', '\\"')


def xml_comment(text) -> str:
    """``text`` safe inside an XML comment ``<!-- -->`` (XML 1.0, 2.5: a comment may not hold ``--``
    nor end in ``-``; 2.2: only Char may appear, no controls but TAB/LF/CR, no surrogates, no U+FFFE or
    U+FFFF): one printable line (which takes all of those out) with every ``-`` that precedes another
    ``-`` or ends the text followed by a space."""
    s = printable_line(text, limit=COMMENT_CHARS)
    return re.sub(r"-(?=-|$)", "- ", s)


def pbrt_string(text) -> str:
    """``text`` as the inside of a pbrt-v4 quoted string (``"string lensfile" ["..."]``): pbrt's
    tokenizer ends a string at ``"``, refuses a line break inside one and reads ``\\"`` and ``\\\\`` as
    escapes (pbrt-v4 ``src/pbrt/parser.cpp``, ``Tokenizer::Next`` and ``dequoteString``). A path's ``\\``
    is written ``/`` (pbrt takes either), ``"`` is escaped; a control character or line break is
    refused in one line (:class:`ExportError`)."""
    s = str(text).replace("\\", "/")
    if printable_line(s) != s:
        raise ExportError(f"the pbrt string {printable_line(s, limit=120)!r} holds a line break or control character: "
                          "rename it")
    return s.replace('"', '\\"')


def xml_attribute(text) -> str:
    """``text`` safe between the double quotes of an XML attribute value (XML 1.0, 2.3 AttValue: no
    ``<``, ``&`` or the delimiting ``"``; 2.4: ``>`` escaped too; 2.2: only Char): one printable
    line with ``& < > "`` written as entities."""
    s = printable_line(text)
    return s.replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;").replace('"', "&quot;")


_NUKE_REFUSED = '{}"[]$'


def nuke_file_path(path) -> str:
    """``path`` as the text between the quotes of a Nuke ``file "..."`` knob, with ``\\`` written
    ``/`` (Nuke takes either on Windows). Refused (:class:`ExportError`): ``{ } " [ ] $``, which the
    ``.nk`` parser (Tcl, "Tcl(n)" rules 4-7: quotes end a word, ``[`` runs a command, ``$`` reads a
    variable) and Nuke's file knob (it expands ``[...]`` Tcl expressions at render time) would take as
    syntax or code, and any character of :func:`printable_line`'s list (a line break, NUL, a
    surrogate of an undecodable file name), which no path written into a script should carry."""
    s = str(path).replace("\\", "/")
    bad = sorted({c for c in s if c in _NUKE_REFUSED} | ({"a control character"} if printable_line(s) != s else set()))
    if bad:
        raise ExportError(f"the path {printable_line(s, limit=120)!r} has characters a Nuke script cannot quote "
                          f"({' '.join(bad)}): rename it")
    return s


def usd_text(text, what: str) -> str:
    """``text`` as a USD string value (customData, a String attribute): USD's text format escapes
    quotes, backslashes and line breaks itself (Sdf ``TfEscapeString``/``Sdf_QuotedString``), so the
    text is kept exactly, but a NUL ends a C++ string early and a lone surrogate (an undecodable file
    name) is not UTF-8: those are refused in one line (:class:`ExportError`, naming ``what``)."""
    s = str(text)
    if "\x00" in s or any(unicodedata.category(c) == "Cs" for c in s):
        raise ExportError(f"the {what} {printable_line(s, limit=120)!r} holds a NUL or an undecodable byte, "
                          "which a USD string cannot carry: fix the text")
    return s

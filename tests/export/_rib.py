"""A small RIB reader for the tests: tokens and requests of the RenderMan Interface Bytestream
(RI Spec 3.2, "RIB binding": a request name, then numbers, quoted strings and [arrays];
``#`` starts a comment to the end of the line, ``##`` a structural comment).

Written for the tests, independent of physcam's writer: it refuses what a RIB parser would
(an unterminated string or array, a stray ``]``, a bare word where a value belongs, NaN or inf),
so a test that reads a file back checks its syntax as well as its numbers.
"""

from __future__ import annotations

import math
import re

_TOKEN = re.compile(r"""
    (?P<comment>\#[^\n]*)
  | (?P<string>"(?:[^"\\\n]|\\.)*")
  | (?P<open>\[)
  | (?P<close>\])
  | (?P<number>[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?(?![A-Za-z_]))
  | (?P<word>[A-Za-z_][A-Za-z0-9_]*)
  | (?P<space>\s+)
  | (?P<bad>.)
""", re.VERBOSE)


class RibError(ValueError):
    pass


def tokens(text: str):
    """(kind, value) pairs: 'string', 'number', 'open', 'close', 'word'; comments and blanks dropped."""
    out = []
    for m in _TOKEN.finditer(text):
        kind = m.lastgroup
        v = m.group()
        if kind in ("space", "comment"):
            continue
        if kind == "bad":
            raise RibError(f"unexpected character {v!r} at {m.start()}")
        if kind == "string":
            out.append(("string", v[1:-1]))
        elif kind == "number":
            x = float(v)
            if not math.isfinite(x):
                raise RibError(f"non-finite number {v!r}")
            out.append(("number", x))
        else:
            out.append((kind, v))
    return out


def parse(text: str) -> list[tuple[str, list]]:
    """RIB text as [(request, [arguments])]: an argument is a float, a str or a list of them."""
    if not text.startswith("##RenderMan RIB"):
        raise RibError("a RIB file starts with the ##RenderMan RIB structural comment")
    requests: list[tuple[str, list]] = []
    toks = tokens(text)
    i = 0
    while i < len(toks):
        kind, name = toks[i]
        if kind != "word" or not name[0].isupper():  # requests are capitalised: Format, ScreenWindow, ...
            raise RibError(f"expected a request name, found {kind} {name!r}")
        args: list = []
        i += 1
        while i < len(toks) and toks[i][0] != "word":
            kind, v = toks[i]
            if kind == "open":
                arr = []
                i += 1
                while i < len(toks) and toks[i][0] in ("number", "string"):
                    arr.append(toks[i][1])
                    i += 1
                if i >= len(toks) or toks[i][0] != "close":
                    raise RibError("unterminated array")
                args.append(arr)
            elif kind == "close":
                raise RibError("']' without '['")
            else:
                args.append(v)
            i += 1
        requests.append((name, args))
    return requests


def request(reqs, name: str) -> list:
    """The arguments of the only ``name`` request (fails if absent or repeated)."""
    found = [a for n, a in reqs if n == name]
    if len(found) != 1:
        raise RibError(f"expected one {name} request, found {len(found)}")
    return found[0]


def params(args: list) -> dict:
    """A parameter list ("type name" [values] ...) as {name: value or [values]}; the type is checked."""
    if len(args) % 2:
        raise RibError(f"a parameter list comes in name/value pairs, got {len(args)} items")
    out = {}
    for decl, val in zip(args[::2], args[1::2]):
        if not isinstance(decl, str) or not isinstance(val, list):
            raise RibError(f"expected \"type name\" [values], got {decl!r} {val!r}")
        parts = decl.split()
        name = parts[-1]
        if len(parts) == 2:
            typ = parts[0]
            m = re.fullmatch(r"(float|int|string|point|color)(?:\[(\d+)\])?", typ)
            if not m:
                raise RibError(f"unknown type in {decl!r}")
            count = int(m.group(2) or 1)
            if len(val) != count:
                raise RibError(f"{decl!r} declares {count} values, got {len(val)}")
            if m.group(1) == "int" and any(float(x) != int(x) for x in val):
                raise RibError(f"{decl!r} holds non-integers {val}")
        out[name] = val[0] if len(val) == 1 else val
    return out

"""What a doc page shows a command print is what it prints (issue 39 item 8): the matcher.

A ``console`` block's lines after a ``$ physcam ...`` line (up to the next ``$`` line) are that
command's shown output. Each shown line must be found in what the command printed (stdout, then
stderr), in the order shown; lines may be left out between them, and a line ``...`` says so
explicitly. Within a line ``...`` stands for any text. Whitespace runs count as one space (tables'
column widths follow their content), and a shown line may be one piece of a printed line wrapped
for the page.

**Numbers** are compared as numbers: a shown number matches a printed one that differs from it by
at most one unit in the shown number's last digit (``0.416`` matches 0.4155 to 0.4165 printed as
0.415, 0.416 or 0.417: the last digit may move between machines, nothing more), or by the relative
tolerance a page states for the block on the line before its fence::

    <!-- doc-output: numbers within 2 % (Monte Carlo rays) -->

A block whose output cannot be the same twice (a free port, a clock) says so there, and is not
compared::

    <!-- doc-output: unchecked (the port is chosen by the system) -->
"""

from __future__ import annotations

import re

NUMBER = re.compile(r"(?<![\w.])[-+−]?(?:\d+(?:\.\d+)?|\.\d+)(?:[eE][-+]?\d+)?(?![\w])")
MARK = re.compile(r"<!--\s*doc-output:\s*(unchecked|numbers within\s+([\d.]+)\s*%)[^>]*-->")


def block_rule(previous_line: str):
    """(checked, relative tolerance) of a console block from the line before its fence."""
    m = MARK.search(previous_line or "")
    if m is None:
        return True, None
    if m.group(1) == "unchecked":
        return False, None
    return True, float(m.group(2)) / 100.0


def _value(text: str) -> float:
    return float(text.replace("−", "-"))


def _last_unit(text: str) -> float:
    """One unit in the last digit of a number as written (``0.416`` -> 0.001, ``4608`` -> 1)."""
    mant = text.lstrip("+-−").split("e")[0].split("E")[0]
    exp = int(text.lower().split("e")[1]) if "e" in text.lower() else 0
    decimals = len(mant.split(".")[1]) if "." in mant else 0
    return 10.0 ** (exp - decimals)


def _pattern(shown: str):
    """A regex for one shown line (numbers captured, whitespace runs and ``...`` free) and its numbers."""
    parts, numbers, pos = [], [], 0
    text = " ".join(shown.split())
    for m in NUMBER.finditer(text):
        parts.append(_literal(text[pos:m.start()]))
        parts.append(r"([-+−]?(?:\d+(?:\.\d+)?|\.\d+)(?:[eE][-+]?\d+)?)")
        numbers.append(m.group(0))
        pos = m.end()
    parts.append(_literal(text[pos:]))
    return re.compile("".join(parts)), numbers


def _literal(text: str) -> str:
    out = []
    pieces = text.split("...")
    for i, piece in enumerate(pieces):
        if i:
            out.append(r".*?")
            piece = piece.lstrip()  # "f/2.8 ...; halved" also stands for "f/2.8, and so on); halved"
        if i < len(pieces) - 1:
            piece = piece.rstrip()
        out.append(r"\s+".join(re.escape(w) for w in piece.split(" ")))
    return "".join(out)


def compare(shown_lines, out: str, err: str = "", rel_tol=None) -> list[str]:
    """Problems (empty when the shown output is what was printed): ``out`` and ``err`` the command's stdout
    and stderr. A shown ``physcam: ...`` line (a warning, a note, an error) is looked for in stderr, any
    other line in stdout first, then in stderr (the rest of a warning wrapped for the page); each stream in
    its own order."""
    streams = [" ".join(" ".join(x.split()) for x in text.splitlines() if x.strip()) for text in (out, err)]
    pos, problems = [0, 0], []
    for line in shown_lines:
        s = line.strip()
        if not s or s == "...":
            continue
        tried = []
        for k in ((1,) if s.startswith("physcam:") else (0, 1)):
            found = _find(s, streams[k], pos[k], rel_tol)
            if found is not None:
                pos[k], wrong = found
                tried = wrong
                if not wrong:
                    break
        else:
            if not tried:
                problems.append(f"not printed (in this order): {s!r}")
                continue
        problems += [f"shows {shown} where the command prints {got}: {s!r}" for shown, got in tried]
    return problems


def _find(s: str, stream: str, pos: int, rel_tol):
    """(end, numbers that disagree) of the first place from ``pos`` where the shown line ``s`` stands in
    ``stream`` with its numbers agreeing, else of the first place it stands at all; None if nowhere."""
    rx, numbers = _pattern(s)
    first = None
    for m in rx.finditer(stream, pos):  # the first place whose numbers agree (a table's row among its like)
        wrong = [(shown, got) for shown, got in zip(numbers, m.groups()) if not _close(shown, got, rel_tol)]
        if not wrong:
            return m.end(), []
        first = first or (m.end(), wrong)
    return first


def _close(shown: str, got: str, rel_tol) -> bool:
    a, b = _value(shown), _value(got)
    tol = max(_last_unit(shown), abs(a) * rel_tol if rel_tol else 0.0)
    return abs(a - b) <= tol * (1 + 1e-9)

"""Draw the on-set report's house from the code: which modules build a ReportRequest (the front ends),
and the solvers solve_report composes, in order, as a Mermaid diagram in docs/architecture.md.

    python scripts/gen_architecture_diagram.py          # rewrite the diagram between its markers
    python scripts/gen_architecture_diagram.py --check  # exit 1 when the page's diagram is stale

Read with ``ast`` (nothing is imported): a module is a front end when its code calls
``ReportRequest(``; the solvers are the calls of ``solve_report``'s body to names that
``physcam.onset.solvers`` defines. tests/test_architecture.py runs ``--check``.
"""

from __future__ import annotations

import ast
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SRC = ROOT / "src" / "physcam"
PAGE = ROOT / "docs" / "architecture.md"
BEGIN, END = "<!-- report-diagram: begin (scripts/gen_architecture_diagram.py) -->", "<!-- report-diagram: end -->"


def _module(path: Path) -> str:
    return ".".join(path.relative_to(SRC.parent).with_suffix("").parts).removesuffix(".__init__")


def front_ends() -> list[str]:
    """Modules (outside onset/) whose code builds a ReportRequest, sorted."""
    out = []
    for path in SRC.rglob("*.py"):
        if path.parent.name == "onset":
            continue
        tree = ast.parse(path.read_text(encoding="utf-8"))
        if any(isinstance(n, ast.Call) and getattr(n.func, "id", getattr(n.func, "attr", None)) == "ReportRequest"
               for n in ast.walk(tree)):
            out.append(_module(path))
    return sorted(out)


def solvers_in_order() -> list[str]:
    """The solvers solve_report calls, in the order of its body."""
    solvers = {n.name for n in ast.parse((SRC / "onset" / "solvers.py").read_text(encoding="utf-8")).body
               if isinstance(n, ast.FunctionDef) and not n.name.startswith("_")}
    report = ast.parse((SRC / "onset" / "report.py").read_text(encoding="utf-8"))
    body = next(n for n in report.body if isinstance(n, ast.FunctionDef) and n.name == "solve_report")
    calls = [n for n in ast.walk(body) if isinstance(n, ast.Call) and isinstance(n.func, ast.Name)]
    seen = []
    for c in sorted(calls, key=lambda c: (c.lineno, c.col_offset)):
        if c.func.id in solvers and c.func.id not in seen:
            seen.append(c.func.id)
    return seen


def diagram() -> str:
    lines = ["```mermaid", "flowchart LR"]
    for m in front_ends():
        node = m.replace(".", "_")
        lines.append(f'    {node}["{m.removeprefix("physcam.")}"] --> request')
    lines.append('    request["onset.request.ReportRequest<br/>(checked once, at the door)"] --> solve')
    lines.append('    solve["onset.report.solve_report"]')
    prev = "solve"
    for i, name in enumerate(solvers_in_order()):
        lines.append(f'    {prev} --> s{i}["solvers.{name}"]')
        prev = f"s{i}"
    lines.append(f'    {prev} --> report["LensReport"]')
    lines.append("```")
    return "\n".join(lines)


def rewrite(text: str) -> str:
    block = f"{BEGIN}\n{diagram()}\n{END}"
    if BEGIN in text:
        a, b = text.index(BEGIN), text.index(END) + len(END)
        return text[:a] + block + text[b:]
    return text.rstrip() + "\n\n" + block + "\n"


def main(argv) -> int:
    text = PAGE.read_text(encoding="utf-8")
    new = rewrite(text)
    if "--check" in argv:
        if new != text:
            print("docs/architecture.md: the report diagram is stale; run python scripts/gen_architecture_diagram.py")
            return 1
        return 0
    PAGE.write_text(new, encoding="utf-8")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))

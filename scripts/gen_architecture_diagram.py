"""Draw the house from the code (issue 43): which modules build the camera (the front ends), the camera
itself, the solvers the on-set report composes in order, and the analyses and exporters that take the
camera through the one door, as a Mermaid diagram in docs/architecture.md.

    python scripts/gen_architecture_diagram.py          # rewrite the diagram between its markers
    python scripts/gen_architecture_diagram.py --check  # exit 1 when the page's diagram is stale

Read with ``ast`` (nothing is imported): a module is a front end when its code calls ``camera_state(``,
``as_designed(`` or ``report_camera(`` (outside ``optics/state.py`` and ``onset/``); the solvers are the
calls of ``solve_report``'s body to names that ``physcam.onset.solvers`` defines; the door's users are
the functions decorated ``@takes_camera``, counted per package (analysis's per package of its own). tests/test_architecture.py runs ``--check``.
"""

from __future__ import annotations

import ast
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SRC = ROOT / "src" / "physcam"
PAGE = ROOT / "docs" / "architecture.md"
BEGIN, END = "<!-- report-diagram: begin (scripts/gen_architecture_diagram.py) -->", "<!-- report-diagram: end -->"
#: The calls that build a camera: the constructor, the lens as designed, a front end's report inputs.
BUILDERS = ("camera_state", "as_designed", "report_camera")


def _module(path: Path) -> str:
    return ".".join(path.relative_to(SRC.parent).with_suffix("").parts).removesuffix(".__init__")


def _called(tree, names) -> bool:
    return any(isinstance(n, ast.Call) and getattr(n.func, "id", getattr(n.func, "attr", None)) in names
               for n in ast.walk(tree))


def front_ends() -> list[str]:
    """Modules (outside the camera's own and the report's) whose code builds a camera, sorted."""
    out = []
    for path in SRC.rglob("*.py"):
        if path.parent.name == "onset" or path == SRC / "optics" / "state.py":
            continue
        if _called(ast.parse(path.read_text(encoding="utf-8")), BUILDERS):
            out.append(_module(path))
    return sorted(out)


def door_users() -> dict[str, int]:
    """Functions decorated ``@takes_camera``, counted per package (analysis's per package of its own)."""
    out: dict[str, int] = {}
    for path in sorted(SRC.rglob("*.py")):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.FunctionDef) and any(getattr(d, "id", None) == "takes_camera"
                                                          for d in node.decorator_list):
                parts = path.relative_to(SRC).parts
                pkg = ".".join(parts[:2]) if parts[0] == "analysis" and len(parts) > 2 else parts[0]
                out[pkg] = out.get(pkg, 0) + 1
    return dict(sorted(out.items()))


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
        lines.append(f'    {node}["{m.removeprefix("physcam.")}"] --> camera')
    lines.append('    camera["optics.state.CameraState<br/>(a lens model focused, stopped, on a sensor:<br/>'
                 'built once, at the door)"]')
    lines.append('    camera --> solve["onset.report.solve_report(camera, coc, measured, references)"]')
    prev = "solve"
    for i, name in enumerate(solvers_in_order()):
        lines.append(f'    {prev} --> s{i}["solvers.{name}"]')
        prev = f"s{i}"
    lines.append(f'    {prev} --> report["LensReport (holds the camera)"]')
    for pkg, n in door_users().items():
        lines.append(f'    camera --> door_{pkg.replace(".", "_")}["{pkg}: {n} function{"s" if n != 1 else ""} '
                     'through @takes_camera"]')
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
            print("docs/architecture.md: the house diagram is stale; run python scripts/gen_architecture_diagram.py")
            return 1
        return 0
    PAGE.write_text(new, encoding="utf-8")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))

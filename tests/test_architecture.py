"""Data flows one way: measurements and prescriptions -> optics -> analyses -> exporters -> CLI.

Each sub-package may import only packages of a lower (or its own) layer; docs/architecture.md
draws the same picture. A new import that points upward fails here.
"""

import ast
from pathlib import Path

SRC = Path(__file__).resolve().parents[1] / "src"

LAYER = {
    "errors": 0, "data": 0, "extras": 0,
    "units": 1, "io": 1,
    "figures": 2,
    "lens": 3,
    "optics": 4,
    "trace": 5,
    "analysis": 6, "onset": 6,
    "export": 7,
    "usd": 8,
    "live": 8.5, "metadata": 8.5,
    "characterize": 9,
    "serve": 9,
    "cli": 10,
    "": 0,  # the root package only re-exports errors and the version
    "__main__": 11,
}


def _imports(path: Path, module: str):
    tree = ast.parse(path.read_text(encoding="utf-8"))
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom):
            if node.level:
                base = module.split(".")
                if path.name != "__init__.py":
                    base = base[:-1]
                base = base[: len(base) - (node.level - 1)]
                yield ".".join(base + ([node.module] if node.module else []))
            elif node.module:
                yield node.module
        elif isinstance(node, ast.Import):
            yield from (a.name for a in node.names)


def test_imports_point_down_the_layers():
    wrong = []
    for path in (SRC / "physcam").rglob("*.py"):
        parts = path.relative_to(SRC).with_suffix("").parts
        module = ".".join(p for p in parts if p != "__init__")
        pkg = parts[1] if len(parts) > 2 else parts[-1] if parts[-1] != "__init__" else ""
        for target in _imports(path, module):
            if not target.startswith("physcam"):
                continue
            tp = target.split(".")[1] if target.count(".") else ""
            if tp == pkg:
                continue
            if LAYER.get(tp, 99) > LAYER.get(pkg, -1):
                wrong.append(f"{module} imports {target}")
    assert not wrong, "upward imports:\n" + "\n".join(sorted(wrong))


def test_pxr_and_numba_stay_in_their_modules():
    # USD is imported only inside physcam.usd (and lazily in CLI handlers / tests); numba only
    # in the trace kernels' dispatch and JIT module.
    for path in (SRC / "physcam").rglob("*.py"):
        rel = path.relative_to(SRC / "physcam").as_posix()
        text = path.read_text(encoding="utf-8")
        if "import numba" in text or "from numba" in text:
            assert rel.startswith("trace/kernels/"), rel
        top_level_pxr = any(line.startswith(("from pxr", "import pxr")) for line in text.splitlines())
        if top_level_pxr:
            assert rel.startswith("usd/"), rel

"""Write docs/api.md, the Python API reference, from the package's own docstrings.

For every public module of physcam (no leading underscore; ``physcam.cli`` is the command line,
documented in docs/cli.md), the names it exports (``__all__``), each with its signature and the first
paragraph of its docstring. tests/test_api_reference.py fails when docs/api.md is not what this
script writes, so the reference never drifts from the code:

    .venv/bin/python scripts/gen_api_reference.py          # rewrite docs/api.md
    .venv/bin/python scripts/gen_api_reference.py --check  # exit 1 if it is out of date
"""

from __future__ import annotations

import importlib
import inspect
import pkgutil
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "docs" / "api.md"
SKIP = ("physcam.cli", "physcam.usd.plugin")  # the CLI (docs/cli.md); the plugin's files, not an API


def _first_paragraph(obj) -> str:
    doc = inspect.getdoc(obj) or ""
    para = doc.split("\n\n")[0].strip()
    return " ".join(para.split())


def _signature(obj) -> str:
    try:
        sig = str(inspect.signature(obj))
    except (TypeError, ValueError):
        return ""
    return sig if len(sig) <= 160 else sig[:157] + "...)"


def modules():
    import physcam

    yield physcam
    for info in pkgutil.walk_packages(physcam.__path__, "physcam."):
        name = info.name
        if any(part.startswith("_") for part in name.split(".")) or name.startswith(SKIP):
            continue
        try:
            yield importlib.import_module(name)
        except ImportError as exc:  # an extra that is not installed: say so in the reference
            print(f"skipped {name}: {exc}", file=sys.stderr)


def render() -> str:
    lines = ["# Python API reference", "",
             "Generated from the docstrings by `scripts/gen_api_reference.py` (do not edit by hand; "
             "`tests/test_api_reference.py` checks it is current). Every public module, the names it "
             "exports, their signatures and the first paragraph of their documentation. Units and "
             "reference planes: docs/conventions.md.", ""]
    for mod in sorted(modules(), key=lambda m: m.__name__):
        names = getattr(mod, "__all__", None)
        if not names:
            continue
        lines += [f"## `{mod.__name__}`", "", _first_paragraph(mod), ""]
        for n in names:
            obj = getattr(mod, n, None)
            if obj is None:
                continue
            if inspect.isclass(obj) or inspect.isfunction(obj):
                kind = "class" if inspect.isclass(obj) else "def"
                lines.append(f"- **`{n}`** `{kind} {n}{_signature(obj)}`  ")
                text = _first_paragraph(obj)
                lines.append(f"  {text}" if text else "  (no docstring)")
            else:
                lines.append(f"- **`{n}`** = `{type(obj).__name__}`")
        lines.append("")
    return "\n".join(lines).rstrip() + "\n"


def main(argv) -> int:
    text = render()
    if "--check" in argv:
        if not OUT.is_file() or OUT.read_text() != text:
            print("docs/api.md is out of date: run scripts/gen_api_reference.py", file=sys.stderr)
            return 1
        return 0
    OUT.write_text(text)
    print(f"wrote {OUT.relative_to(ROOT)} ({text.count(chr(10))} lines)")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))

"""Every physcam import in a ```python block of README.md and docs/ names a current module and name.

A new user copies these lines first (round 8): README's example imported ``find_sensor`` from
``physcam.onset.sensors``, a path moved to ``physcam.optics.sensors`` that answers with a
DeprecationWarning and goes in physcam 0.3. The oracle is Python's import system: each line is
imported as written, with DeprecationWarning an error.
"""

from __future__ import annotations

import importlib
import re
import warnings
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
_BLOCK = re.compile(r"```python\n(.*?)```", re.DOTALL)
_FROM = re.compile(r"^\s*from\s+(physcam[\w.]*)\s+import\s+(.+)$")
_IMPORT = re.compile(r"^\s*import\s+(physcam[\w.]*)")


def _imports():
    for page in PAGES:
        if page.name == "CHANGELOG.md":
            continue
        for block in _BLOCK.findall(page.read_text(encoding="utf-8")):
            for line in block.splitlines():
                if m := _FROM.match(line):
                    names = [n.split(" as ")[0].strip() for n in m.group(2).strip("() ").split(",")]
                    yield pytest.param(m.group(1), tuple(n for n in names if n), id=f"{page.name}:{line.strip()}")
                elif m := _IMPORT.match(line):
                    yield pytest.param(m.group(1), (), id=f"{page.name}:{line.strip()}")


@pytest.mark.parametrize("module, names", list(_imports()))
def test_a_documented_import_is_current(module, names):
    with warnings.catch_warnings():
        warnings.simplefilter("error", DeprecationWarning)
        found = importlib.import_module(module)
        missing = [n for n in names if not hasattr(found, n)]
    assert not missing, f"{module} has no {missing}"

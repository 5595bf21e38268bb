"""Old module paths of moved modules (issue 43) keep importing for one version, with a DeprecationWarning,
and give the very module at the new path."""

import importlib
import sys
import warnings

import pytest

from physcam._moved import MOVED


@pytest.mark.parametrize("old", sorted(MOVED))
def test_an_old_path_imports_the_new_module_with_a_warning(old):
    new = importlib.import_module(MOVED[old])
    sys.modules.pop(old, None)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        exec(f"import {old}")  # a plain import statement, as a user's code has
        mod = sys.modules[old]
    assert mod is new
    msgs = [str(w.message) for w in caught if issubclass(w.category, DeprecationWarning)]
    assert msgs == [f"{old} moved to {MOVED[old]}; the old path goes in physcam 0.3"]
    assert caught[0].filename == "<string>"  # the warning points at the importing line, not at importlib


def test_from_import_of_a_name_through_an_old_path():
    sys.modules.pop("physcam.onset.sensors", None)
    with pytest.warns(DeprecationWarning, match="physcam.optics.sensors"):
        from physcam.onset.sensors import Sensor
    from physcam.optics.sensors import Sensor as moved

    assert Sensor is moved


def test_no_module_of_physcam_imports_an_old_path():
    """physcam's own code imports the new paths (an old one would warn every user)."""
    import ast
    from pathlib import Path

    src = Path(__file__).resolve().parents[1] / "src"
    wrong = []
    for path in (src / "physcam").rglob("*.py"):
        parts = path.relative_to(src).with_suffix("").parts
        package = parts[:-1] if parts[-1] != "__init__" else parts[:-1]
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Import):
                names = [a.name for a in node.names]
            elif isinstance(node, ast.ImportFrom):
                base = list(package[: len(package) - node.level + 1]) if node.level else []
                mod = ".".join(base + ([node.module] if node.module else []))
                names = [mod] + [f"{mod}.{a.name}" for a in node.names]
            else:
                continue
            if any(n in MOVED for n in names):
                wrong.append(f"{path.relative_to(src)}:{node.lineno}")
    assert not wrong, wrong

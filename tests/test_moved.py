"""Old module paths of moved modules (issue 43) keep importing for one version, with a DeprecationWarning,
and give the very module at the new path."""

import importlib
import sys
import warnings

import pytest

from physcam._moved import FOLDED, MOVED


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


#: a name of each folded module (the old module whose path is now its concept's package), from its source
FOLDED_NAMES = {"physcam.analysis.distortion": "real_distortion", "physcam.analysis.defocus": "inverse_depth"}


@pytest.mark.parametrize("package", sorted(FOLDED))
def test_an_old_module_s_names_answer_from_its_package_with_a_warning(package):
    name = FOLDED_NAMES[package]
    with pytest.warns(DeprecationWarning, match=f"{package}.{name} moved to {FOLDED[package]}.{name}"):
        exec(f"from {package} import {name} as old", scope := {})
    assert scope["old"] is getattr(importlib.import_module(FOLDED[package]), name)


@pytest.mark.parametrize("package", sorted(FOLDED))
def test_a_folded_package_s_submodules_import_quietly_and_unknown_names_fail(package):
    pkg = importlib.import_module(package)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        exec(f"from {package} import {FOLDED[package].rpartition('.')[2]} as mod", scope := {})
        with pytest.raises(AttributeError, match="no attribute 'no_such_name'"):
            pkg.no_such_name  # noqa: B018
        with pytest.raises(AttributeError):
            pkg.__wrapped__  # noqa: B018  (dunders never reach the old module: inspect and pickle probe them)
    assert scope["mod"] is importlib.import_module(FOLDED[package])


def test_every_old_flat_analysis_module_answers():
    """The 38 public modules of the flat analysis/ before issue 43 split it (``git show cdf2d0b:src/physcam/
    analysis/``, less the underscored helpers) each answer: a moved path (MOVED) or a folded one (FOLDED)."""
    old = ("anamorphic_distortion blob bokeh breathing_plot breathing_real calibrate calibrate_chart calibrate_compare "
           "calibrate_flat calibrate_names calibrate_sheet centroid colour defocus defocus_exr defocus_kernels diagram "
           "distortion distortion_focus distortion_models distortion_names field_of_view ghosts huygens illumination "
           "lens_card lens_compare lens_probes lightfield mtf openlensio psf real_dof spot stmap thin_lens_gap wavefront "
           "zoom_plot").split()
    assert len(old) == 38
    kept = {"centroid"}  # still at analysis/'s own level
    missing = [m for m in old if m not in kept and f"physcam.analysis.{m}" not in {**MOVED, **FOLDED}]
    assert not missing, missing


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
            if any(n in MOVED for n in names) or _folded_name(names, src):
                wrong.append(f"{path.relative_to(src)}:{node.lineno}")
    assert not wrong, wrong


def _folded_name(names, src) -> bool:
    """Whether ``from <folded package> import name`` takes a name of the old module (not a submodule)."""
    mod, *imported = names
    if mod not in FOLDED:
        return False
    folder = src.joinpath(*mod.split("."))
    return any(not (folder / f"{n.rpartition('.')[2]}.py").exists() for n in imported)

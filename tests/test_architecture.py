"""Data flows one way: measurements and prescriptions -> optics -> analyses -> the on-set report ->
exporters -> USD -> live and camera metadata -> farm and server -> CLI.

Every sub-package (and every module at the package's root) has a layer of its own (issue 43) and may
import only packages of a lower layer, at any depth of its code: a deferred, function-level import is
an edge too. So no two packages import each other, and the package graph has no loop, which
:func:`test_no_package_level_import_loop` checks on its own. docs/architecture.md draws the same
picture. A new import that points upward fails here; a new package needs its layer here.
"""

import ast
import functools
import sys
from pathlib import Path

SRC = Path(__file__).resolve().parents[1] / "src"
# scripts/house_metrics.py measures the house (static: it reads physcam's source, imports none of it); its
# Tarjan finds the loops here too
sys.path.insert(0, str(SRC.parent / "scripts"))

from house_metrics import RoomWalkAll, strongly_connected, walk_rooms  # noqa: E402

LAYER = {
    "errors": 0, "_record": 1, "_moved": 2, "_program": 3,
    "": 4,  # the root package only re-exports errors and the version, and installs the old module paths
    "data": 5, "extras": 6, "progress": 7, "units": 8, "frame_rates": 9, "io": 10, "figures": 11, "usd_names": 12,
    "lens": 13,
    "optics": 14,
    "trace": 15,
    "analysis": 16,
    "onset": 17,
    "export": 18,
    "usd": 19,
    "live": 20,
    "metadata": 21,
    "characterize": 22,
    "serve": 23,
    "farm": 24,
    "cli": 25,
    "__main__": 26,
}


@functools.cache
def _nodes(path: Path) -> tuple:
    """Every node of ``path``'s syntax tree, in ``ast.walk``'s order: parsed and walked once for the
    module's tests, which each read all of src/physcam (this file 34.7 -> 20.2 s CPU on a loaded machine, 2026-11-29)."""
    return tuple(ast.walk(ast.parse(path.read_text(encoding="utf-8"))))


def _imports(path: Path, module: str):
    for node in _nodes(path):
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


def _package_edges():
    """(importing package, imported package, module, target) for every import between two packages."""
    for path in (SRC / "physcam").rglob("*.py"):
        parts = path.relative_to(SRC).with_suffix("").parts
        module = ".".join(p for p in parts if p != "__init__")
        pkg = parts[1] if len(parts) > 2 else parts[-1] if parts[-1] != "__init__" else ""
        for target in _imports(path, module):
            if not target.startswith("physcam"):
                continue
            tp = target.split(".")[1] if target.count(".") else ""
            if tp != pkg:
                yield pkg, tp, module, target


def test_every_package_has_a_layer_of_its_own():
    pkgs = {p.name if p.is_dir() else p.stem for p in (SRC / "physcam").iterdir()
            if (p.is_dir() and (p / "__init__.py").exists()) or (p.suffix == ".py" and p.stem != "__init__")}
    missing = sorted(pkgs - set(LAYER))
    assert not missing, f"give these packages a layer in tests/test_architecture.py: {missing}"
    values = [v for k, v in LAYER.items()]
    assert len(values) == len(set(values)), "two packages share a layer"


def test_imports_point_down_the_layers():
    wrong = [f"{module} imports {target}" for pkg, tp, module, target in _package_edges()
             if LAYER.get(tp, 99) > LAYER.get(pkg, -1)]
    assert not wrong, "upward imports:\n" + "\n".join(sorted(wrong))


#: analysis/'s packages, one concept each (issue 43), each with a layer of its own below physcam.onset: the
#: modules at analysis/'s own level (``_chief``, ``_plot``, ``_camera``, ``centroid``) are what they all share
ANALYSIS_LAYER = {
    "analysis": 0,
    "analysis.image_quality": 1,
    "analysis.distortion": 2,
    "analysis.framing": 3,
    "analysis.defocus": 4,
    "analysis.calibration": 5,
    "analysis.lens_cards": 6,
}


def _analysis_package(dotted: str) -> str:
    """analysis's package of a module path under physcam.analysis ("analysis" for its own level)."""
    parts = dotted.split(".")
    if len(parts) > 2 and (SRC / "physcam" / "analysis" / parts[2]).is_dir():
        return f"analysis.{parts[2]}"
    return "analysis"


def _analysis_edges():
    """(importing package, imported package, module, target) for every import between two of analysis's
    packages, deferred imports included."""
    for path in (SRC / "physcam" / "analysis").rglob("*.py"):
        parts = path.relative_to(SRC).with_suffix("").parts
        module = ".".join(p for p in parts if p != "__init__")
        pkg = _analysis_package(module)
        for target in _imports(path, module):
            if target.startswith("physcam.analysis") and _analysis_package(target) != pkg:
                yield pkg, _analysis_package(target), module, target


def test_every_analysis_package_has_a_layer_of_its_own():
    pkgs = {f"analysis.{p.name}" for p in (SRC / "physcam" / "analysis").iterdir() if (p / "__init__.py").exists()}
    missing = sorted(pkgs - set(ANALYSIS_LAYER))
    assert not missing, f"give these packages a layer in tests/test_architecture.py's ANALYSIS_LAYER: {missing}"
    assert len(set(ANALYSIS_LAYER.values())) == len(ANALYSIS_LAYER), "two of analysis's packages share a layer"


def test_analysis_packages_import_down_their_layers():
    wrong = [f"{module} imports {target}" for pkg, tp, module, target in _analysis_edges()
             if ANALYSIS_LAYER[tp] > ANALYSIS_LAYER[pkg]]
    assert not wrong, "upward imports between analysis's packages:\n" + "\n".join(sorted(wrong))
    graph: dict[str, set[str]] = {}
    for pkg, tp, _, _ in _analysis_edges():
        graph.setdefault(pkg, set()).add(tp)
        graph.setdefault(tp, set())
    assert graph, "no imports between analysis's packages found: the edge finder is broken"
    assert not [c for c in strongly_connected(graph) if len(c) > 1]


def test_no_package_level_import_loop():
    """Issue 43: the graph of packages (an edge for any import between two, deferred ones included) has no
    strongly connected component of more than one package."""
    graph: dict[str, set[str]] = {}
    for pkg, tp, _, _ in _package_edges():
        graph.setdefault(pkg, set()).add(tp)
        graph.setdefault(tp, set())
    loops = [" <-> ".join(c) for c in strongly_connected(graph) if len(c) > 1]
    assert not loops, "package import loops (move what both sides need below both):\n" + "\n".join(loops)


def test_the_loop_finder_finds_a_loop():
    assert [sorted(c) for c in strongly_connected({"a": {"b"}, "b": {"a"}, "c": {"a"}}) if len(c) > 1] == [["a", "b"]]
    # worked by hand: a -> b -> c -> a is one circle, d -> e -> d another, f hangs off the first; a chain of
    # 5000 modules (deeper than Python's default recursion limit of 1000) has no loop
    graph = {"a": {"b"}, "b": {"c"}, "c": {"a", "d"}, "d": {"e"}, "e": {"d"}, "f": {"a"}}
    assert sorted(strongly_connected(graph)) == [["a", "b", "c"], ["d", "e"], ["f"]]
    chain = {f"m{i}": {f"m{i + 1}"} for i in range(5000)}
    assert len(strongly_connected(chain)) == 5001


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


def _module_graph():
    """physcam's modules and the physcam modules each imports, at any depth of its code (a deferred,
    function-level import is an edge too: it hides a cycle, it does not break one). ``from pkg import
    name`` is an edge to ``pkg.name`` when that is a module, else to ``pkg``."""
    mods = {}
    for path in (SRC / "physcam").rglob("*.py"):
        parts = path.relative_to(SRC).with_suffix("").parts
        mods[".".join(p for p in parts if p != "__init__")] = path
    graph = {}
    for module, path in mods.items():
        edges = set()
        for node in _nodes(path):
            if isinstance(node, ast.ImportFrom):
                base = next(_imports_of(node, path, module))
                edges.update(f"{base}.{a.name}" if f"{base}.{a.name}" in mods else base for a in node.names)
            elif isinstance(node, ast.Import):
                edges.update(a.name for a in node.names)
        graph[module] = {t for t in edges if t in mods and t != module}
    return graph


def _imports_of(node, path, module):
    """The module a ``from ... import`` names, relative imports resolved against ``module``."""
    if node.level:
        base = module.split(".")
        if path.name != "__init__.py":
            base = base[:-1]
        base = base[: len(base) - (node.level - 1)]
        yield ".".join(base + ([node.module] if node.module else []))
    else:
        yield node.module or ""


def test_every_relative_import_names_a_module_of_physcam():
    """Issue 43 moved modules a level down: a relative import left one level short (``from ..figures`` in
    a module of analysis's packages) fails only when its function runs. Every ``from .x import`` (deferred
    ones included) must name an existing module or package of physcam."""
    mods = set()
    for path in (SRC / "physcam").rglob("*.py"):
        parts = path.relative_to(SRC).with_suffix("").parts
        mods.add(".".join(p for p in parts if p != "__init__"))
    wrong = []
    for path in (SRC / "physcam").rglob("*.py"):
        parts = path.relative_to(SRC).with_suffix("").parts
        module = ".".join(p for p in parts if p != "__init__")
        for node in _nodes(path):
            if isinstance(node, ast.ImportFrom) and node.level:
                base = next(_imports_of(node, path, module))
                if base not in mods:
                    wrong.append(f"{module}:{node.lineno} imports {base}")
    assert not wrong, "relative imports of no module:\n" + "\n".join(sorted(wrong))


def test_no_import_cycles_deferred_imports_included():
    """Issue 28: no two modules import each other, directly or round a longer circle, counting the
    imports inside functions (Tarjan's strongly connected components, iteratively)."""
    cycles = [" <-> ".join(c) for c in strongly_connected(_module_graph()) if len(c) > 1]
    assert not cycles, "import cycles (move what both sides need to the module that owns the concept):\n" + \
        "\n".join(cycles)


MAX_FUNCTION_LINES = 120  # issue 28: functions readable in one screen, split where a name explains a step


def test_no_function_outside_the_trace_kernels_is_longer_than_120_lines():
    """Every function (nested ones and methods included) in src/physcam, outside trace/kernels/ (where one
    vectorised or jitted pass per surface may stay whole), spans at most 120 lines, def to last line."""
    kernels = SRC / "physcam" / "trace" / "kernels"
    long = []
    for path in sorted((SRC / "physcam").rglob("*.py")):
        if kernels in path.parents:
            continue
        for node in _nodes(path):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                n = node.end_lineno - node.lineno + 1
                if n > MAX_FUNCTION_LINES:
                    long.append(f"{path.relative_to(SRC)}:{node.lineno} {node.name} ({n} lines)")
    assert not long, "functions over 120 lines (split where a name explains a step):\n" + "\n".join(long)


def test_the_report_diagram_is_drawn_from_the_code():
    """docs/architecture.md's diagram of the on-set report (front ends -> ReportRequest -> solvers) is
    what scripts/gen_architecture_diagram.py draws from the code now."""
    import subprocess
    import sys

    root = SRC.parent
    p = subprocess.run([sys.executable, str(root / "scripts" / "gen_architecture_diagram.py"), "--check"],
                       capture_output=True, text=True)
    assert p.returncode == 0, p.stdout + p.stderr


#: One name per concept in the public API's parameters (issue 28): a parameter whose name speaks of
#: the concept must be one of its names. Focus marks are distances from the film plane.
CONCEPT_NAMES = {
    "f-stop (the iris's setting)": (r"^(f_?stop|aperture_fstop|n_stop)$", {"fstop"}),
    "f-number (EFL over the entrance pupil, the thin-lens formulas' N)": (r"^(f_?number|fnum)$",
                                                                          {"f_number"}),
    "focus mark from the film": (r"^(focus|focus_distance.*|focus_from_.*|focus_mm|mark_mm|focus_mark.*)$",
                                 {"focus_mm", "focus_marks_mm"}),
    "stop size": (r"^(stop_.*|iris.*)$", {"stop_semi_diameter"}),
    # (Zemax's dispersion formulas are written in micrometres: lens.glassformulas keeps their unit)
    "wavelength": (r"^(wavelength.*|lambda.*|wl.*)$", {"wavelength_nm", "wavelengths_nm", "wavelength_um"}),
    "camera state": (r"^(camera_state|state|cam_state)$", {"state"}),
}


def test_one_name_per_concept_in_public_parameters():
    import importlib
    import inspect
    import re

    wrong = set()
    for path in (SRC / "physcam").rglob("*.py"):
        parts = path.relative_to(SRC).with_suffix("").parts
        module = ".".join(p for p in parts if p != "__init__")
        if any(p.startswith("_") and p != "__init__" for p in parts) or module.startswith(("physcam.cli",
                                                                                          "physcam.__main__")):
            continue
        mod = importlib.import_module(module)
        for name in getattr(mod, "__all__", ()):
            fn = getattr(mod, name, None)
            if not inspect.isfunction(fn):
                continue
            for p in inspect.signature(fn).parameters:
                for concept, (pattern, allowed) in CONCEPT_NAMES.items():
                    if re.match(pattern, p) and p not in allowed:
                        wrong.add(f"{module}.{name}({p}): {concept} is spelled {sorted(allowed)}")
    assert not wrong, "\n".join(sorted(wrong))


def test_only_the_camera_state_sizes_an_iris():
    # issue 28: an f-stop becomes a stop size in one place (optics: focusing's rule, called by the
    # camera state); every analysis, exporter and front end takes the state's stop_semi_diameter
    wrong = []
    for path in (SRC / "physcam").rglob("*.py"):
        rel = path.relative_to(SRC / "physcam")
        if rel.parts[0] == "optics":
            continue
        for node in _nodes(path):
            if isinstance(node, ast.ImportFrom) and any(a.name == "iris_semi_diameter" for a in node.names):
                wrong.append(f"{rel}:{node.lineno}")
            elif isinstance(node, ast.Attribute) and node.attr == "iris_semi_diameter":
                wrong.append(f"{rel}:{node.lineno}")
    assert not wrong, "size the iris through physcam.optics.state.camera_state: " + ", ".join(sorted(wrong))


# issue 43 ("Done when"): a focus and a stop are the camera's (physcam.optics.state.CameraState); a record
# elsewhere holds the camera, never its own copies. The names are scripts/house_metrics.py's (the issue's
# count); the allowed places are the optics models and the raw records of what a camera or a take recorded.
FOCUS_FIELD = r"^(focus|focus_mm|focus_from_film_mm|focus_distance.*|object_z|focused)$"
STOP_FIELD = r"^(fstop|f_stop|tstop|f_number|stop_semi_diameter|aperture_fstop|fstop_at_focus|iris_set)$"
FOCUS_AND_STOP_ALLOWED = ("optics/", "metadata/", "live/", "characterize/", "usd/animate.py:FocusKey")


def _class_fields(cls: ast.ClassDef) -> list[str]:
    """The fields a class body declares: annotated names (dataclasses, NamedTuples, attrs with annotations)
    and names assigned an ``attr.ib()``, ``attrs.field()`` or ``dataclasses.field()`` (attrs without them)."""
    names = []
    for s in cls.body:
        if isinstance(s, ast.AnnAssign) and isinstance(s.target, ast.Name):
            names.append(s.target.id)
        elif isinstance(s, ast.Assign) and isinstance(s.value, ast.Call):
            f = s.value.func
            callee = f.attr if isinstance(f, ast.Attribute) else getattr(f, "id", "")
            if callee in ("ib", "attrib", "field"):
                names += [t.id for t in s.targets if isinstance(t, ast.Name)]
    return names


def _classes_with_focus_and_stop(nodes, rel: str) -> list[str]:
    """The classes among a module's syntax-tree ``nodes`` declaring a focus field and a stop field."""
    import re

    out = []
    for node in nodes:
        if isinstance(node, ast.ClassDef):
            names = _class_fields(node)
            if any(re.match(FOCUS_FIELD, n) for n in names) and any(re.match(STOP_FIELD, n) for n in names):
                out.append(f"{rel}:{node.name}")
    return out


def test_no_class_outside_the_raw_records_carries_a_focus_and_a_stop():
    found = []
    for path in sorted((SRC / "physcam").rglob("*.py")):
        rel = path.relative_to(SRC / "physcam").as_posix()
        found += _classes_with_focus_and_stop(_nodes(path), rel)
    wrong = [c for c in found if not any(c.startswith(a) for a in FOCUS_AND_STOP_ALLOWED)]
    assert not wrong, ("hold the camera (physcam.optics.state.CameraState) instead of its focus and stop: "
                       + ", ".join(wrong))


def test_the_focus_and_stop_finder_finds_each_kind_of_record():
    src = ("@dataclass\nclass A:\n    focus_mm: float\n    fstop: float\n"
           "class B(NamedTuple):\n    focus_from_film_mm: float\n    f_number: float\n"
           "@attr.s\nclass C:\n    focus = attr.ib()\n    tstop = attr.ib(default=None)\n"
           "@dataclass\nclass D:\n    camera: object\n    coc_mm: float\n"
           "class E:\n    fstop = 4.0\n    focus_mm = 3000.0\n")  # class constants, not fields
    assert _classes_with_focus_and_stop(ast.walk(ast.parse(src)), "x.py") == ["x.py:A", "x.py:B", "x.py:C"]


# issue 43 ("Done when"): following `physcam export blender`'s camera settings through the code (the issue's own
# walk: everything computed from them, scripts/house_metrics.py "computed from") crossed 37 rooms (modules)
# when the issue was filed, 25 before the export asked one tracer of the camera (trace/camera_tracer.py)
# instead of walking the tracer's modules itself; at most half of 37 (18) now, and onset/ only for --builtin.
MAX_EXPORT_BLENDER_ROOMS = 37 // 2


def test_the_walk_of_export_blender_crosses_at_most_half_the_rooms():
    w = walk_rooms(RoomWalkAll, builtin=False)
    assert len(w.rooms) <= MAX_EXPORT_BLENDER_ROOMS, "export blender's walk crosses:\n" + "\n".join(w.rooms)
    assert not [r for r in w.rooms if r.startswith("physcam.onset")], w.rooms
    # the walk reaches where the settings go: the shader's writer and the camera (a broken walk crosses nothing)
    assert {"physcam.export.blender", "physcam.optics.state", "physcam.export.osl"} <= set(w.rooms)


def test_the_walk_enters_onset_when_builtin_is_asked():
    """--builtin matches Blender's own camera to the lens report (onset/): the walk must see it there."""
    assert any(r.startswith("physcam.onset.") for r in walk_rooms(RoomWalkAll, builtin=True).rooms)


def _import_module_calls(tree) -> int:
    """Calls of importlib's import_module (by name or as importlib.import_module) in a module's tree."""
    return sum(isinstance(n, ast.Call) and (getattr(n.func, "id", None) == "import_module"
                                            or getattr(n.func, "attr", None) == "import_module")
               for n in ast.walk(tree))


def test_a_package_imports_its_lazy_names_through_one_path():
    """A package whose module ``__getattr__`` imports names on first use imports them in one place (one
    import_module call): physcam.lens.formats had two, its ``__getattr__`` and ``_module`` each importing
    the same format modules (a fix to one, a missing name's message, would miss the other)."""
    counts = {}
    for init in sorted((SRC / "physcam").rglob("__init__.py")):
        tree = ast.parse(init.read_text(encoding="utf-8"))
        if any(isinstance(n, ast.FunctionDef) and n.name == "__getattr__" for n in tree.body):
            counts[str(init.relative_to(SRC))] = _import_module_calls(tree)
    assert "physcam/lens/formats/__init__.py" in counts  # the finder sees the lazy packages
    assert {k: n for k, n in counts.items() if n > 1} == {}


def test_the_lazy_import_counter_counts_both_spellings():
    tree = ast.parse("import importlib\nfrom importlib import import_module\n"
                     "def f():\n    return import_module('a')\ndef g():\n    return importlib.import_module('b')\n")
    assert _import_module_calls(tree) == 2

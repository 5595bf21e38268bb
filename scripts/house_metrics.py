"""Measure how much of physcam asks one camera object (issue 43): the numbers behind docs/architecture.md's
"The house" section, each defined here so that a before/after is reproducible.

    python scripts/house_metrics.py            # every metric, as text
    python scripts/house_metrics.py --json     # the same as one JSON document
    python scripts/house_metrics.py --only rooms,loops

Metrics (static ones read the source with ``ast``; nothing of physcam is imported for them):

* ``focus_and_stop``: classes whose body declares both a focus field and a stop field (annotated
  fields of a dataclass or NamedTuple: stored copies; a property that reads a held camera is not a
  copy). Focus: :data:`FOCUS_FIELD`; stop: :data:`STOP_FIELD`. Reported whole and outside the
  allowed places (``optics/``, the raw-data records of ``metadata/``, ``live/``, ``characterize/``
  and the USD keyframes, :data:`RAW_RECORDS`).
* ``isinstance_camera``: ``isinstance(..., CameraState)`` calls outside ``optics/state.py`` (each one
  a second door that a decorator should own).
* ``focus_calls``: calls of ``physcam.optics.focusing.focus`` (counted by ``cProfile``, the function's
  own code object) while ``solve_report`` reports one prescription, with fresh caches, for a few
  bundled lenses: one at a given mark and one at the hyperfocal mark (imports physcam).
* ``rooms``: the walk of ``physcam export blender``'s arguments. Start in the handler
  (``cli/export.py: run_blender``) with the camera settings marked (:data:`CAMERA_SETTINGS`:
  ``args.focus``, ``args.fstop``, the sensor, the iris, the render's size and options; not the lens
  file's name nor the output folder); in each function, a name assigned from a marked expression is
  marked (to a fixed point); every call with a marked argument whose callee resolves to a physcam
  function (imported at any depth, ``module.function`` or a name of the same module; a class: its
  ``__post_init__``; ``getattr(a, "b")`` reads as ``a.b``) is entered with the matching parameters
  marked. A *room* is a module the walk enters; a *climb* is a call edge between two rooms (each one
  a trip down a staircase the reader climbs back up). Two walks: "handed on" follows the marked
  values and the objects made from them as they are handed on (data read off a marked object,
  ``state.focused``, is asking the object, not a room); "computed from" follows everything computed
  from them, data read off objects too (the issue's own walk). ``--builtin`` off: the branches under
  ``if args.builtin`` are not followed. Method calls are asks of an object, not followed.
* ``loops``: package-level import loops: the graph of physcam's sub-packages with an edge for every
  import between two of them, at any depth of the code (deferred imports included); its strongly
  connected components of more than one package.
"""

from __future__ import annotations

import ast
import json
import re
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SRC = ROOT / "src" / "physcam"

FOCUS_FIELD = re.compile(r"^(focus|focus_mm|focus_from_film_mm|focus_distance.*|object_z|focused)$")
STOP_FIELD = re.compile(r"^(fstop|f_stop|tstop|f_number|stop_semi_diameter|aperture_fstop|fstop_at_focus|iris_set)$")
#: Where a class may carry its own focus and stop (issue 43's "Done when"): the optics models themselves and
#: the raw records of what a camera or a take recorded.
RAW_RECORDS = ("optics/", "metadata/", "live/", "characterize/", "usd/animate.py:FocusKey")


def _module(path: Path) -> str:
    return ".".join(path.relative_to(SRC.parent).with_suffix("").parts).removesuffix(".__init__")


def _files():
    return sorted(SRC.rglob("*.py"))


# --- classes with a focus and a stop ----------------------------------------------------------------
def focus_and_stop() -> dict:
    both = []
    for path in _files():
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if not isinstance(node, ast.ClassDef):
                continue
            names = [s.target.id for s in node.body if isinstance(s, ast.AnnAssign) and isinstance(s.target, ast.Name)]
            f = [n for n in names if FOCUS_FIELD.match(n)]
            s = [n for n in names if STOP_FIELD.match(n)]
            if f and s:
                both.append(f"{path.relative_to(SRC).as_posix()}:{node.name}")
    outside = [c for c in both if not any(c.startswith(r) or c == r for r in RAW_RECORDS)]
    return {"classes": both, "count": len(both), "outside_allowed": outside, "outside_count": len(outside)}


# --- isinstance(..., CameraState) ---------------------------------------------------------------------
def isinstance_camera() -> dict:
    hits = []
    for path in _files():
        rel = path.relative_to(SRC).as_posix()
        if rel == "optics/state.py":
            continue
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Call) and getattr(node.func, "id", None) == "isinstance" and len(node.args) == 2:
                if "CameraState" in ast.unparse(node.args[1]):
                    hits.append(f"{rel}:{node.lineno}")
    return {"branches": hits, "count": len(hits), "modules": len({h.split(":")[0] for h in hits})}


# --- focus calls per report ---------------------------------------------------------------------------
REPORT_CASES = (("dgauss_50mm", 2.8, 2000.0), ("zuiko_18mm_f3_5", 4.0, 2000.0), ("zuiko_18mm_f3_5", 4.0, "hyperfocal"),
                ("navarro_anamorphic_2x", 4.0, 3000.0))


def _report_of(lens, fstop, mark):
    """One report of ``lens`` at f/``fstop`` focused at ``mark`` on Super 35, through the API of the tree
    this script runs in (the camera when there is one, the request before issue 43)."""
    from physcam.onset import report as rep
    try:
        from physcam.optics.state import camera_state
        from physcam.optics.sensors import find_sensor
        cam = camera_state(lens, focus_mm=mark, fstop=fstop, sensor=find_sensor("S35"))
        return rep.solve_report(cam)
    except ImportError:
        from physcam.onset.sensors import find_sensor
        return rep.solve_report(rep.ReportRequest(lens=lens, sensor=find_sensor("S35"), fstop=fstop, focus_mm=mark))


def _clear_caches():
    import functools
    import gc

    for obj in gc.get_objects():
        # type(), not isinstance(): the heap may hold a weak proxy whose object is gone, and isinstance asks
        # the proxy for its __class__ (ReferenceError)
        if type(obj) is functools._lru_cache_wrapper and getattr(obj, "__module__", "").startswith("physcam"):
            obj.cache_clear()
    models = getattr(sys.modules.get("physcam.optics.lens_model"), "_MODELS", None)
    if models is not None:  # the lens models keep their focus solutions
        models.clear()


def focus_calls() -> dict:
    import cProfile
    import pstats
    import time
    import warnings

    from physcam.lens.library import load_lens

    out = []
    warnings.simplefilter("ignore")
    for name, fstop, mark in REPORT_CASES:
        lens = load_lens(name)
        _clear_caches()
        pr = cProfile.Profile()
        pr.enable()
        _report_of(lens, fstop, mark)
        pr.disable()
        n = sum(v[0] for k, v in pstats.Stats(pr).stats.items()
                if k[0].endswith("optics/focusing.py") and k[2] == "focus")
        t0, runs = time.process_time(), 5
        for _ in range(runs):
            _clear_caches()
            lens = load_lens(name)
            _report_of(lens, fstop, mark)
        out.append({"lens": name, "fstop": fstop, "focus": mark, "focus_calls": n,
                    "cpu_ms": round((time.process_time() - t0) / runs * 1000, 1)})
    return {"reports": out, "max_focus_calls": max(r["focus_calls"] for r in out)}


# --- the rooms of `physcam export blender` ------------------------------------------------------------
class _Module:
    def __init__(self, name: str, path: Path):
        self.name, self.path = name, path
        self.tree = ast.parse(path.read_text(encoding="utf-8"))
        self.defs = {n.name: n for n in self.tree.body if isinstance(n, (ast.FunctionDef, ast.ClassDef))}
        self.imports = {}  # local name -> (module, attribute or None)
        for node in ast.walk(self.tree):
            if isinstance(node, ast.ImportFrom):
                base = self._resolve(node)
                for a in node.names:
                    self.imports[a.asname or a.name] = (base, a.name)
            elif isinstance(node, ast.Import):
                for a in node.names:
                    if a.asname:
                        self.imports[a.asname] = (a.name, None)

    def _resolve(self, node) -> str:
        if not node.level:
            return node.module or ""
        base = self.name.split(".")
        if self.path.name != "__init__.py":
            base = base[:-1]
        base = base[: len(base) - (node.level - 1)]
        return ".".join(base + ([node.module] if node.module else []))


class RoomWalk:
    def __init__(self, builtin: bool):
        self.builtin = builtin
        self.mods: dict[str, _Module] = {}
        for path in _files():
            self.mods[_module(path)] = None
        self.paths = {_module(p): p for p in _files()}
        self.rooms: list[str] = []
        self.climbs: set[tuple[str, str]] = set()
        self.seen: set[tuple[str, str, tuple]] = set()

    def module(self, name: str) -> _Module | None:
        if name not in self.paths:
            return None
        if self.mods.get(name) is None:
            self.mods[name] = _Module(name, self.paths[name])
        return self.mods[name]

    def resolve(self, mod: _Module, func: ast.expr):
        """(module, def) of a call's callee, or None outside physcam."""
        if isinstance(func, ast.Name):
            if func.id in mod.defs:
                return mod, mod.defs[func.id]
            if func.id in mod.imports:
                base, attr = mod.imports[func.id]
                if attr is None:
                    return None
                target = self.module(base)
                if target is not None and attr in target.defs:
                    return target, target.defs[attr]
                sub = self.module(f"{base}.{attr}")
                return None if sub is None else None
        if isinstance(func, ast.Attribute) and isinstance(func.value, ast.Name):
            v = func.value.id
            if v in mod.imports:
                base, attr = mod.imports[v]
                target = self.module(base if attr is None else f"{base}.{attr}")
                if target is not None and func.attr in target.defs:
                    return target, target.defs[func.attr]
        return None

    def walk(self, mod: _Module, fn, marked: set[str]) -> None:
        key = (mod.name, fn.name, tuple(sorted(marked)))
        if key in self.seen:
            return
        self.seen.add(key)
        if mod.name not in self.rooms:
            self.rooms.append(mod.name)
        if isinstance(fn, ast.ClassDef):
            post = next((n for n in fn.body if isinstance(n, ast.FunctionDef) and n.name == "__post_init__"), None)
            if post is not None:
                self.walk(mod, post, {"self"})
            return
        body = list(self._statements(fn))
        marked = set(marked)
        changed = True
        while changed:  # a name assigned from a marked expression is marked
            changed = False
            for node in body:
                for target, value in self._assignments(node):
                    if self._uses(value, marked):
                        name = self._dotted(target)
                        names = [name] if name else [n.id for n in ast.walk(target) if isinstance(n, ast.Name)]
                        for n in names:
                            if n not in marked:
                                marked.add(n)
                                changed = True
        for node in body:
            if not isinstance(node, ast.Call):
                continue
            callee = self.resolve(mod, node.func)
            if callee is None:
                continue
            tmod, tfn = callee
            params = self._params(tfn)
            hit = set()
            for param, value in [*zip(params, node.args), *((k.arg, k.value) for k in node.keywords if k.arg)]:
                hit |= self._carried(value, marked, param)
            if any(k.arg is None and self._uses(k.value, marked) for k in node.keywords) or \
                    any(isinstance(a, ast.Starred) and self._uses(a, marked) for a in node.args):
                hit |= set(params)
            if not hit:
                continue
            if tmod.name != mod.name:
                self.climbs.add((mod.name, tmod.name))
            self.walk(tmod, tfn, hit)

    @staticmethod
    def _dotted(node) -> str | None:
        """``a.b.c`` of a Name or an Attribute chain over a Name (``getattr(a, "b")`` reads as ``a.b``), else None."""
        parts = []
        while True:
            if isinstance(node, ast.Attribute):
                parts.append(node.attr)
                node = node.value
            elif (isinstance(node, ast.Call) and getattr(node.func, "id", None) == "getattr" and len(node.args) >= 2
                  and isinstance(node.args[1], ast.Constant) and isinstance(node.args[1].value, str)):
                parts.append(node.args[1].value)
                node = node.args[0]
            else:
                break
        if isinstance(node, ast.Name):
            return ".".join([node.id, *reversed(parts)])
        return None

    @classmethod
    def _carried(cls, value, marked, param: str) -> set[str]:
        """The marks an argument carries into the parameter ``param``: a bare name passes its marked
        attributes (``args`` with ``args.focus`` marked marks ``param.focus``); any other marked expression
        marks the parameter whole."""
        if isinstance(value, ast.Name) and value.id not in marked:
            return {param + m[len(value.id):] for m in marked if m.startswith(value.id + ".")}
        return {param} if cls._uses(value, marked) else set()

    def _statements(self, fn):
        """The nodes of ``fn``'s body, without the branches under ``if args.builtin`` when --builtin is off."""
        stack = list(fn.body)
        while stack:
            node = stack.pop()
            if not self.builtin and isinstance(node, ast.If) and "builtin" in ast.unparse(node.test):
                stack.extend(node.orelse)
                continue
            yield node
            stack.extend(ast.iter_child_nodes(node))

    @staticmethod
    def _params(fn) -> list[str]:
        if isinstance(fn, ast.ClassDef):
            return [s.target.id for s in fn.body if isinstance(s, ast.AnnAssign) and isinstance(s.target, ast.Name)]
        a = fn.args
        return [x.arg for x in a.posonlyargs + a.args + a.kwonlyargs]

    @staticmethod
    def _assignments(node):
        if isinstance(node, ast.Assign):
            return [(t, node.value) for t in node.targets]
        if isinstance(node, (ast.AnnAssign, ast.AugAssign)) and node.value is not None:
            return [(node.target, node.value)]
        if isinstance(node, (ast.With,)):
            return [(i.optional_vars, i.context_expr) for i in node.items if i.optional_vars is not None]
        if isinstance(node, ast.For):
            return [(node.target, node.iter)]
        if isinstance(node, ast.NamedExpr):
            return [(node.target, node.value)]
        return []

    @classmethod
    def _uses(cls, expr, marked) -> bool:
        """Does ``expr`` hand on a marked value: a marked name, or a marked attribute path (``args.focus``)?
        Data read off a marked object (``state.focused``) is asking the object, not handing it on."""
        stack = [expr]
        while stack:
            n = stack.pop()
            if isinstance(n, (ast.Name, ast.Attribute, ast.Call)):
                d = cls._dotted(n)
                if d is not None:
                    if d in marked:
                        return True
                    if not isinstance(n, ast.Name):
                        continue  # an attribute chain over a name: marked or not as a whole
            stack.extend(ast.iter_child_nodes(n))
        return False


#: The camera settings of ``physcam export blender`` the walk follows (not the lens file's name, not the
#: output folder): focus, f-stop, sensor, the iris and the render's size and options.
CAMERA_SETTINGS = ("args.focus", "args.fstop", "args.sensor", "args.sensor_width", "args.sensor_height",
                   "args.blades", "args.blade_angle", "args.roundness", "args.density", "args.width_px",
                   "args.dispersion", "args.fresnel")


class RoomWalkAll(RoomWalk):
    """The walk that follows everything computed from the arguments, data read off a marked object too
    (``state.focused`` handed to the tracer is a room): the issue's own walk (37 rooms on the tree it was
    measured on)."""

    @classmethod
    def _uses(cls, expr, marked) -> bool:
        for n in ast.walk(expr):
            d = cls._dotted(n) if isinstance(n, (ast.Name, ast.Attribute, ast.Call)) else None
            if d is not None and any(d == m or d.startswith(m + ".") for m in marked):
                return True
        return False


def walk_rooms(walker=RoomWalkAll, *, builtin: bool = False) -> RoomWalk:
    """One walk of ``physcam export blender``'s camera settings (:data:`CAMERA_SETTINGS`) from
    ``cli/export.py: run_blender``: ``walker.rooms`` and ``walker.climbs`` after it (``--builtin`` off:
    its branches not followed)."""
    w = walker(builtin)
    start = w.module("physcam.cli.export")
    w.walk(start, start.defs["run_blender"], set(CAMERA_SETTINGS))
    return w


def rooms() -> dict:
    out = {}
    for kind, walker in (("handed_on", RoomWalk), ("computed_from", RoomWalkAll)):
        for builtin in (False, True):
            w = walk_rooms(walker, builtin=builtin)
            out[f"{kind}_{'with' if builtin else 'without'}_builtin"] = {
                "rooms": len(w.rooms), "climbs": len(w.climbs),
                "enters_onset": any(r.startswith("physcam.onset") for r in w.rooms),
                "room_list": w.rooms}
    return out


# --- package-level import loops -------------------------------------------------------------------------
def package_graph() -> dict[str, set[str]]:
    graph: dict[str, set[str]] = {}
    for path in _files():
        mod = _Module(_module(path), path)
        parts = mod.name.split(".")
        pkg = parts[1] if len(parts) > 1 else ""
        edges = graph.setdefault(pkg, set())
        for node in ast.walk(mod.tree):
            targets = []
            if isinstance(node, ast.ImportFrom):
                targets = [mod._resolve(node)]
            elif isinstance(node, ast.Import):
                targets = [a.name for a in node.names]
            for t in targets:
                tp = t.split(".")
                if tp[0] == "physcam" and len(tp) > 1 and tp[1] != pkg:
                    edges.add(tp[1])
    return graph


def strongly_connected(graph: dict[str, set[str]]) -> list[list[str]]:
    """The strongly connected components of ``graph`` (node -> set of nodes), each sorted, singletons
    included: Tarjan's algorithm (R. Tarjan, "Depth-first search and linear graph algorithms", SIAM J.
    Comput. 1, 1972), iteratively, so a long import chain needs no deep recursion. tests/test_architecture.py
    runs it on physcam's module and package graphs."""
    index, low, on, stack, comps = {}, {}, set(), [], []

    def enter(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        return v, iter(sorted(graph.get(v, ())))

    for root in sorted(graph):
        if root in index:
            continue
        work = [enter(root)]
        while work:
            v, it = work[-1]
            w = next(it, None)
            if w is not None:
                if w not in index:
                    work.append(enter(w))
                elif w in on:
                    low[v] = min(low[v], index[w])
                continue
            work.pop()
            if work:
                low[work[-1][0]] = min(low[work[-1][0]], low[v])
            if low[v] == index[v]:
                comps.append(sorted(_pop_component(stack, on, v)))
    return comps


def _pop_component(stack: list, on: set, v) -> list:
    """Tarjan's step at a root ``v``: pop the stack down to ``v``, one component."""
    comp = []
    while True:
        w = stack.pop()
        on.discard(w)
        comp.append(w)
        if w == v:
            return comp


def loops() -> dict:
    comps = [c for c in strongly_connected(package_graph()) if len(c) > 1]
    return {"loops": comps, "count": len(comps)}


METRICS = {"focus_and_stop": focus_and_stop, "isinstance_camera": isinstance_camera, "focus_calls": focus_calls,
           "rooms": rooms, "loops": loops}


def main(argv) -> int:
    sys.setrecursionlimit(10000)
    only = None
    if "--only" in argv:
        only = argv[argv.index("--only") + 1].split(",")
    results = {name: fn() for name, fn in METRICS.items() if only is None or name in only}
    if "--json" in argv:
        print(json.dumps(results, indent=1))
        return 0
    for name, r in results.items():
        if name == "focus_and_stop":
            print(f"classes with a focus and a stop field: {r['count']} ({r['outside_count']} outside optics/ and "
                  f"the raw records)")
            for c in r["outside_allowed"]:
                print(f"    {c}")
        elif name == "isinstance_camera":
            print(f"isinstance(..., CameraState) branches: {r['count']} in {r['modules']} modules")
        elif name == "focus_calls":
            for x in r["reports"]:
                print(f"solve_report {x['lens']} f/{x['fstop']:g} focus {x['focus']}: {x['focus_calls']} calls of "
                      f"focus, {x['cpu_ms']} ms CPU")
        elif name == "rooms":
            for k, v in r.items():
                print(f"export blender, walk {k.replace('_', ' ')}: {v['rooms']} rooms, {v['climbs']} climbs, "
                      f"enters onset/: {v['enters_onset']}")
        elif name == "loops":
            print(f"package import loops (deferred imports included): {r['count']} "
                  + " ".join("<->".join(c) for c in r["loops"]))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))

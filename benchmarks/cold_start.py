"""Benchmark: every `physcam` subcommand and the cases of issue 47, cold (a fresh process each run).

"Cold" here: a fresh Python process with physcam's own caches empty (a new working folder, a new
`--kernel-cache` where a command takes one); the OS file cache, Python's bytecode cache and numba's
JIT cache warm (what a user has from the second run on: one untimed run first). The one exception is
the `jit` cases, the first traced command after `pip install 'physcam[fast]'`: they run a fresh copy
of the source with an empty JIT cache (and `NUMBA_CACHE_DIR` at a new folder) each run: `jit` as a
user would ("auto" picks the kernel), `jit compile` with the JIT kernel forced, so numba compiles.
Each line gives the wall clock and the CPU time (user + system of the child, all its threads):
on a shared machine the wall clock follows the load, the CPU time much less.

Goals (issue 47, median of the runs): the README's MTF chart (`mtf`) under 1 s; `spot -o png`,
`compare`, `ghosts`, `lens diagram`, `illumination`, `mtf --field 0` and `bokeh` under 0.5 s each;
`jit` under 3 s of CPU; the report under 0.3 s (issue 2). Other commands are printed without a goal.

    .venv/bin/python benchmarks/cold_start.py [--runs 5] [--only mtf,bokeh] [--tree OLD --tree NEW]

`--tree DIR` (repeat) runs each case against the source tree DIR/src (PYTHONPATH) instead of the
installed physcam, the trees alternating run by run, so a before/after pair shares the machine's
load (export the old tree with `git archive COMMIT | tar -x -C DIR`); with two trees each case also
prints the median of the paired CPU differences (the second tree minus the first).
"""

from __future__ import annotations

import argparse
import os
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
ARRI = os.path.join(REPO, "tests/data/camera-metadata/arri/B001C001_180327_R1ZA.mov.csv")
SAMPLE = os.path.join(REPO, "tests/live/data/recommended_dynamic_example.json")

#: name -> (arguments after `physcam`, goal in seconds of wall clock or None); {tmp} is the run's own
#: empty folder. The issue's cases first, then one everyday line of every other subcommand.
CASES = {
    "mtf": (["mtf", "--lens", "dgauss_50mm"], 1.0),  # the README's chart: default sensor, full aperture
    "spot -o png": (["spot", "--lens", "dgauss_50mm", "-o", "{tmp}/spot.png"], 0.5),
    "compare": (["compare", "--lens", "dgauss_50mm", "--lens", "sonnar_50mm_f1_5", "--lens", "tessar_50mm_f2_8",
                 "--focus", "2m", "--fstop", "2.8", "--sensor", "S35", "-o", "{tmp}/compare.png"], 0.5),
    "ghosts": (["ghosts", "--lens", "dgauss_50mm", "--field", "10", "--top", "5"], 0.5),
    "lens diagram": (["lens", "diagram", "--lens", "dgauss_50mm", "-o", "{tmp}/dgauss.png"], 0.5),
    "illumination": (["illumination", "--lens", "dgauss_50mm"], 0.5),
    "mtf --field 0": (["mtf", "--lens", "dgauss_50mm", "--field", "0"], 0.5),
    "bokeh": (["bokeh", "--lens", "dgauss_50mm"], 0.5),
    "report": (["report", "--focal", "50", "--fstop", "2.8", "--focus", "3m", "--sensor", "ALEXA 35", "--json"], 0.3),
    # the first traced command after an install (numba's cache empty): 1e6 bokeh rays, the JIT kernel's
    # job once loaded; "jit compile" forces the JIT kernel (PHYSCAM_BACKEND=numba), so numba compiles
    "jit": (["bokeh", "--lens", "dgauss_50mm", "--rays", "1000000"], None),
    "jit compile": (["spot", "--lens", "dgauss_50mm"], None),
    # every other subcommand, one everyday line each
    "spot": (["spot", "--lens", "dgauss_50mm"], None),
    "bokeh -o png": (["bokeh", "--lens", "dgauss_50mm", "--focus", "3m", "--light", "1m", "--fstop", "4", "--blades",
                      "6", "-o", "{tmp}/bokeh.png"], None),
    "mtf vendor chart": (["mtf", "--lens", "dgauss_50mm", "--fstop", "4", "--focus", "3m", "--sensor", "FF"], None),
    "dof-table": (["dof-table", "--focal", "50", "--sensor", "S35"], None),
    "sensors": (["sensors"], None),
    "lenses": (["lenses"], None),
    "lens show": (["lens", "show", "--lens", "dgauss_50mm", "--focus", "2m", "--fstop", "2.8"], None),
    "lens breathing": (["lens", "breathing", "--lens", "zuiko_18mm_f3_5", "--sensor", "S35"], None),
    "colour": (["colour", "--lens", "tessar_50mm_f2_8", "--field", "0", "--field", "10", "--field", "20"], None),
    "breathing-real": (["breathing-real", "--lens", "dgauss_50mm", "--focus", "inf", "--focus", "2m", "--focus", "1m",
                        "--sensor", "FF"], None),
    "distortion": (["distortion", "--lens", "dgauss_50mm"], None),
    "psf": (["psf", "--lens", "dgauss_50mm", "--field", "14", "--fstop", "4"], None),
    "usd write": (["usd", "write", "{tmp}/shot.usda", "--focal", "35", "--fstop", "2.8", "--focus", "3m", "--sensor",
                   "ALEXA 35"], None),
    "config show": (["config", "show"], None),
    "export pbrt": (["export", "pbrt", "-o", "{tmp}/pbrt", "--lens", "dgauss_50mm", "--fstop", "2.8", "--focus", "2m",
                     "--sensor", "ALEXA 35"], None),
    "export rib": (["export", "rib", "-o", "{tmp}/shot.rib", "--lens", "dgauss_50mm", "--fstop", "2.8", "--focus",
                    "2m", "--sensor", "ALEXA 35"], None),
    "export blender": (["export", "blender", "--lens", "dgauss_50mm", "--focus", "2m", "--fstop", "2.8", "--sensor",
                        "ALEXA 35", "-o", "{tmp}/cams"], None),
    "export opencv": (["export", "opencv", "--lens", "dgauss_50mm", "--sensor", "FF", "--width-px", "4096",
                       "--height-px", "2731", "--json"], None),
    "export unreal": (["export", "unreal", "--lens", "dgauss_50mm", "-o", "{tmp}/dgauss.ulens", "--sensor", "ALEXA 35",
                       "--width-px", "4608", "--height-px", "3164"], None),
    "export mitsuba": (["export", "mitsuba", "--focal", "50", "--fstop", "2", "--focus", "1m", "--sensor", "FF",
                        "-o", "{tmp}/mitsuba"], None),
    "defocus-kernels": (["defocus-kernels", "--lens", "dgauss_50mm", "--focus", "2m", "--fstop", "2.8", "--resolution",
                         "640x360", "--depths", "1m,4m", "-o", "{tmp}/psf"], None),
    "metadata show": (["metadata", "show", ARRI], None),
    "metadata report": (["metadata", "report", ARRI], None),
    "live validate": (["live", "validate", SAMPLE], None),
    "microlens insert": (["microlens", "insert", "--lens", "dgauss_50mm", "--microlens-focal", "0.224", "--xdim", "77",
                          "--ydim", "77", "--film-width", "3.08", "--film-height", "3.08", "--focus", "0.8m",
                          "-o", "{tmp}/lf.json"], None),
    "characterize --dry-run": (["characterize", "--lens", "dgauss_50mm", "--focus", "1m,3m", "--dry-run", "-o",
                                "{tmp}/char"], None),
    "serve --check": (["serve", "--check", "--port", "0"], None),
    "demo": (["demo", "--out", "{tmp}/demo"], None),
}
#: Cases left out of a plain run (minutes each, or owned by other benchmarks): run them with --only.
LONG = ("demo",)
#: The goals in CPU seconds (the JIT compile: issue 47, 13.7 s before).
CPU_GOALS = {"jit": 3.0, "jit compile": 3.0}
#: Cases run with an empty JIT cache, and their environment.
COLD_JIT = {"jit": {}, "jit compile": {"PHYSCAM_BACKEND": "numba"}}


def load() -> str:
    return ", ".join(f"{v:.2f}" for v in os.getloadavg())


def child_env(src: str | None, jit_dir: str | None, extra: dict | None = None) -> dict:
    env = dict(os.environ)
    env.pop("PYTHONDONTWRITEBYTECODE", None)  # an installed program has its bytecode (docs/performance.md)
    env.pop("PHYSCAM_BACKEND", None)
    env["COLUMNS"] = "100"
    if src is not None:
        env["PYTHONPATH"] = src
    if jit_dir is not None:
        env["NUMBA_CACHE_DIR"] = jit_dir
    env.update(extra or {})
    return env


def fresh_source(tree: str | None, scratch: str) -> str:
    """A copy of the tree's ``src`` (bytecode kept, numba's cache left out): a physcam whose JIT cache is
    empty wherever it looks (trees before issue 47 keep it beside the kernels, not in NUMBA_CACHE_DIR)."""
    src = os.path.join(tree, "src") if tree is not None else os.path.join(REPO, "src")
    dest = tempfile.mkdtemp(dir=scratch)
    shutil.copytree(src, os.path.join(dest, "src"), ignore=shutil.ignore_patterns("physcam-jit"))
    return os.path.join(dest, "src")


def run_once(argv: list[str], env: dict, cwd: str) -> tuple[float, float]:
    r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    p = subprocess.run(argv, capture_output=True, env=env, cwd=cwd, stdin=subprocess.DEVNULL)
    wall = time.perf_counter() - t0
    r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    if p.returncode != 0:
        raise SystemExit(f"{' '.join(argv)} failed ({p.returncode}): {p.stderr.decode()[-800:]}")
    return wall, r1.ru_utime - r0.ru_utime + r1.ru_stime - r0.ru_stime


def measure(name: str, trees: list, runs: int, scratch: str) -> dict:
    """{tree: (walls, cpus)} for case ``name``, the trees alternating run by run."""
    args, _ = CASES[name]
    out = {t: ([], []) for t in trees}
    for k in range(runs + 1):  # run 0 warms the OS file cache, the bytecode and the JIT cache
        for t in trees:
            tmp = tempfile.mkdtemp(dir=scratch)
            cold = name in COLD_JIT
            jit_dir = tempfile.mkdtemp(dir=scratch) if cold else None
            src = fresh_source(t, scratch) if cold else (None if t is None else os.path.join(t, "src"))
            argv = [sys.executable, "-m", "physcam"] + [a.replace("{tmp}", tmp) for a in args]
            wall, cpu = run_once(argv, child_env(src, jit_dir, COLD_JIT.get(name)), tmp)
            shutil.rmtree(tmp, ignore_errors=True)
            if cold:
                shutil.rmtree(jit_dir, ignore_errors=True)
                shutil.rmtree(os.path.dirname(src), ignore_errors=True)
            if k:
                out[t][0].append(wall)
                out[t][1].append(cpu)
    return out


def machine_marks() -> str:
    """How fast this host is, for comparing figures measured on different machines: a pure-Python
    loop (``sum(range(10**6))``, best of 5) and matplotlib's import in a fresh process (CPU)."""
    loop = min(_timed(lambda: sum(range(10**6))) for _ in range(5))
    child = [sys.executable, "-c", "import time; import matplotlib.figure; print(time.process_time())"]
    mpl = min(float(subprocess.run(child, check=True, capture_output=True, text=True).stdout) for _ in range(3))
    return (f"this machine: sum(range(10**6)) {loop * 1000:.1f} ms; "
            f"import matplotlib.figure {mpl * 1000:.0f} ms CPU (best of 3, fresh processes)")


def _timed(fn) -> float:
    t0 = time.perf_counter()
    fn()
    return time.perf_counter() - t0


def _tree(path: str) -> str:
    """``path`` made absolute: the runs start in their own empty folders, where a relative ``--tree .`` would
    name nothing and Python would import the installed physcam instead (silently measuring it twice)."""
    tree = os.path.abspath(path)
    if not os.path.isfile(os.path.join(tree, "src", "physcam", "__init__.py")):
        raise SystemExit(f"--tree {path}: no src/physcam/__init__.py under {tree}")
    return tree


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=5)
    ap.add_argument("--only", default=None, help="comma-separated case names (default: all but " + ", ".join(LONG) + ")")
    ap.add_argument("--tree", action="append", default=None, metavar="DIR",
                    help="a source tree to run (DIR/src on PYTHONPATH); repeat to compare trees side by side")
    args = ap.parse_args()
    names = [n for n in CASES if n not in LONG] if args.only is None else [n.strip() for n in args.only.split(",")]
    unknown = [n for n in names if n not in CASES]
    if unknown:
        raise SystemExit(f"unknown case(s) {unknown}; cases: {', '.join(CASES)}")
    trees = [_tree(t) for t in args.tree] if args.tree else [None]
    print(f"{os.cpu_count()} cores; load average {load()} at start; {args.runs} runs per case and tree")
    print(machine_marks())
    with tempfile.TemporaryDirectory() as scratch:
        for name in names:
            res = measure(name, trees, args.runs, scratch)
            goal, cpu_goal = CASES[name][1], CPU_GOALS.get(name)
            for t in trees:
                walls, cpus = res[t]
                med, cmed = statistics.median(walls), statistics.median(cpus)
                label = name if t is None else f"{name} [{os.path.basename(os.path.normpath(t))}]"
                line = (f"{label}: wall median {med * 1000:.0f} ms ({min(walls) * 1000:.0f}-{max(walls) * 1000:.0f}), "
                        f"CPU median {cmed * 1000:.0f} ms ({min(cpus) * 1000:.0f}-{max(cpus) * 1000:.0f})")
                if goal is not None:
                    line += f"; goal {goal * 1000:.0f} ms wall: {'met' if med < goal else 'NOT met'}"
                if cpu_goal is not None:
                    line += f"; goal {cpu_goal:g} s CPU: {'met' if cmed < cpu_goal else 'NOT met'}"
                print(line + f" (load {load()})", flush=True)
            if len(trees) == 2:  # the runs were made in pairs, one of each tree: the pairs' differences
                d = [b - a for a, b in zip(res[trees[0]][1], res[trees[1]][1])]
                print(f"{name}: paired CPU difference, second tree minus first: median "
                      f"{statistics.median(d) * 1000:+.0f} ms, {sum(x < 0 for x in d)} of {len(d)} pairs faster",
                      flush=True)
    t0 = time.perf_counter()
    subprocess.run([sys.executable, "-c", "pass"], check=True)
    print(f"(bare python start-up: {(time.perf_counter() - t0) * 1000:.0f} ms; load {load()} at end)")


if __name__ == "__main__":
    main()

"""Benchmark: where a cold figure command's CPU goes, part by part (issue 47).

Each run is a fresh process that runs the command as ``python -m physcam`` does (``physcam._program.start``,
one BLAS thread, ``physcam.cli.main``, the exit without teardown), with CPU time (``time.process_time``: every
thread of the process, from the interpreter's start) summed inside named functions as the process enters them.
A function is wrapped when its module is first imported (an import hook), so the run imports nothing it would
not; a part's functions called inside one another count once (the outermost call). The parts, for the cases of
``benchmarks/cold_start.py`` that draw a figure:

- ``kernel``: the ray-tracing kernel: ``trace_rays`` of ``physcam.trace.kernels._numpy`` and
  ``physcam.trace.kernels.run_blocks`` (the compiled kernels' batches: the C kernel these commands run cold where it
  is built); ``--wrap MODULE:FUNCTION`` adds another;
- ``matplotlib import``: ``physcam.figures._lean_import``;
- ``measure``: the command's analysis (the spot's rays: ``spot_diagram``; each compared lens: ``lens_measurements``);
- ``figure``: making and laying out the figure (``SpotDiagram.plot``, ``compare_figure``), the save included;
- ``save``: drawing and encoding the file (``physcam.figures.figure_bytes``).

The kernel's share is what a faster kernel can take off a cold run: with a kernel k times faster, a run's
CPU is about total - kernel (1 - 1/k).

    .venv/bin/python benchmarks/cold_phases.py [--runs 5] [--only "spot -o png,compare"] [--tree DIR ...]

``--tree DIR`` (repeat) runs DIR/src (made absolute) instead of the installed physcam, the trees alternating
run by run; the cases and their arguments are ``benchmarks/cold_start.py``'s.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from cold_start import CASES, _tree, child_env, load, machine_marks  # noqa: E402

#: (module, attribute path, part) of the functions timed in every run.
PARTS = [
    ("physcam.trace.kernels._numpy", "trace_rays", "kernel"),
    ("physcam.trace.kernels", "run_blocks", "kernel"),
    ("physcam.figures", "_lean_import", "matplotlib import"),
    ("physcam.analysis.image_quality.spot", "spot_diagram", "measure"),
    ("physcam.onset.lens_compare", "lens_measurements", "measure"),
    ("physcam.analysis.image_quality.spot", "SpotDiagram.plot", "figure"),
    ("physcam.cli.compare", "compare_figure", "figure"),
    ("physcam.figures", "figure_bytes", "save"),
]
#: Cases drawn by default (the issue's figure rows that are not met).
DEFAULT_CASES = ("spot -o png", "compare")


def _child(parts: list[tuple[str, str, str]], argv: list[str]) -> None:
    """Run ``physcam argv`` as the program, the ``parts`` timed; print the CPU (ms) per part as JSON on stderr."""
    import importlib.abc
    import importlib.machinery
    import time

    spent: dict[str, float] = {}
    depth: dict[str, int] = {}  # per part, so functions of one part called inside one another count once

    def timed(fn, part):
        def inner(*args, **kwargs):
            depth[part] = depth.get(part, 0) + 1
            t0 = time.process_time()
            try:
                return fn(*args, **kwargs)
            finally:
                depth[part] -= 1
                if depth[part] == 0:
                    spent[part] = spent.get(part, 0.0) + time.process_time() - t0

        return inner

    def patch(module) -> None:
        for name, attr, part in parts:
            if name != module.__name__:
                continue
            owner, *path = attr.split(".")
            if len(path) == 0:
                setattr(module, owner, timed(getattr(module, owner), part))
            else:
                cls = getattr(module, owner)
                setattr(cls, path[0], timed(getattr(cls, path[0]), part))

    class Hook(importlib.abc.MetaPathFinder):
        """Wraps the parts' functions as their modules are first imported."""

        def find_spec(self, name, path=None, target=None):
            if name not in {p[0] for p in parts}:
                return None
            spec = importlib.machinery.PathFinder.find_spec(name, path)
            if spec is not None and spec.loader is not None:
                run = spec.loader.exec_module

                def exec_module(module, run=run):
                    run(module)
                    patch(module)

                spec.loader.exec_module = exec_module
            return spec

    sys.meta_path.insert(0, Hook())
    from physcam import _program

    _program.start()
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")  # as physcam.cli.run
    from physcam.cli import _exit_without_teardown, main

    code = main(argv)
    spent["total"] = time.process_time()
    sys.stderr.write("PHASES " + json.dumps({k: round(v * 1e3, 1) for k, v in spent.items()}) + "\n")
    _exit_without_teardown(code)


def run_once(src: str | None, args: list[str], wraps: list[str]) -> dict:
    with tempfile.TemporaryDirectory() as tmp:
        argv = [sys.executable, os.path.abspath(__file__), "--child", *sum((["--wrap", w] for w in wraps), []),
                "--", *[a.replace("{tmp}", tmp) for a in args]]
        p = subprocess.run(argv, capture_output=True, text=True, env=child_env(src, None), cwd=tmp,
                           stdin=subprocess.DEVNULL)
    lines = [ln for ln in p.stderr.splitlines() if ln.startswith("PHASES ")]
    if p.returncode != 0 or not lines:
        raise SystemExit(f"{' '.join(args)} failed ({p.returncode}): {p.stderr[-800:]}")
    return json.loads(lines[-1][len("PHASES "):])


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=5)
    ap.add_argument("--only", default=",".join(DEFAULT_CASES), help="comma-separated cases of cold_start.py")
    ap.add_argument("--tree", action="append", default=None, metavar="DIR")
    ap.add_argument("--wrap", action="append", default=[], metavar="MODULE:FUNCTION",
                    help="also count CPU inside this function as the kernel (e.g. a compiled kernel's trace_rays)")
    ap.add_argument("--child", action="store_true", help=argparse.SUPPRESS)
    ap.add_argument("argv", nargs="*", help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.child:
        _child(PARTS + [(*w.split(":", 1), "kernel") for w in args.wrap], args.argv)
        return
    names = [n.strip() for n in args.only.split(",")]
    trees = [_tree(t) for t in args.tree] if args.tree else [None]
    print(f"{os.cpu_count()} cores; load average {load()} at start; {args.runs} runs per case and tree")
    print(machine_marks())
    for name in names:
        runs = {t: [] for t in trees}
        for k in range(args.runs + 1):  # run 0 warms the OS file cache and the bytecode
            for t in trees:
                got = run_once(None if t is None else os.path.join(t, "src"), CASES[name][0], args.wrap)
                if k:
                    runs[t].append(got)
        for t in trees:
            label = name if t is None else f"{name} [{os.path.basename(os.path.normpath(t))}]"
            keys = ["total"] + sorted({key for r in runs[t] for key in r} - {"total"})
            med = {key: statistics.median(r.get(key, 0.0) for r in runs[t]) for key in keys}
            print(f"{label}: CPU medians (ms) " + ", ".join(f"{key} {med[key]:.0f}" for key in keys)
                  + f"; kernel share {med.get('kernel', 0.0) / med['total']:.0%} (load {load()})", flush=True)


if __name__ == "__main__":
    main()

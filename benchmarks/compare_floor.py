"""Benchmark: the least wall clock a cold `physcam compare -o png` could take on this machine (issue 47).

The issue's goal for `compare` (three lenses, the figure written) is 0.5 s of wall clock, cold. The command is
two jobs: the three lenses' measurements (the table) and the six-panel figure drawn from them. Each is timed
here alone, cold, in fresh processes (median of ``--runs``):

- ``table``: `physcam compare` without ``-o`` (interpreter, numpy, physcam, the three measurements, the table);
- ``figure``: a fresh process started as the program starts (``physcam._program.start``, one BLAS thread) that
  reads the measurements from a pickle (made once, untimed) and draws and writes the same figure with
  ``physcam.cli.compare.compare_figure`` (interpreter, numpy, matplotlib's import, the figure, the PNG);
  its ``matplotlib`` part is ``physcam.figures._lean_import`` alone;
- ``compare -o png``: the command as `benchmarks/cold_start.py` runs it.

Both jobs start with the same interpreter and numpy. However the command divided them between the machine's
two cores (a forked process drawing while the other measures), it could not finish before the longer of the
two: **max(table, figure) is the floor of its wall clock**, before the cost of handing the data over.

    .venv/bin/python benchmarks/compare_floor.py [--runs 5]
"""

from __future__ import annotations

import argparse
import os
import pickle
import resource
import statistics
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from cold_start import CASES, child_env, load, machine_marks, run_once  # noqa: E402

PROGRAM = [sys.executable, "-m", "physcam"]
#: the compare case of cold_start.py, without its figure
COMPARE = [a for a in CASES["compare"][0] if a not in ("-o", "{tmp}/compare.png")]


def _measurements(path: str) -> None:
    """What ``physcam compare`` (``COMPARE``'s lenses and settings) hands its figure, pickled to ``path``: the
    command is run in this process with its figure function replaced by one that keeps its arguments."""
    from physcam.cli import compare, main

    def keep(rows, curves, out, *, sensor, **kwargs):
        with open(path, "wb") as f:
            pickle.dump((rows, curves, sensor), f)

    drawing, compare.compare_figure = compare.compare_figure, keep
    try:
        with tempfile.TemporaryDirectory() as tmp, open(os.devnull, "w") as quiet:
            stdout, sys.stdout = sys.stdout, quiet
            try:
                code = main(COMPARE + ["-o", os.path.join(tmp, "unused.png")])
            finally:
                sys.stdout = stdout
    finally:
        compare.compare_figure = drawing
    if code or not os.path.exists(path):
        raise SystemExit(f"physcam {' '.join(COMPARE)} failed ({code})")


def _figure_child(data: str, out: str) -> None:
    """Draw the pickled measurements' figure as the program would; print the CPU (ms) of the process so far
    and of matplotlib's import."""
    from physcam import _program

    _program.start()
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")  # as physcam.cli.run
    import numpy  # noqa: F401  (the pickle's arrays)

    from physcam import figures

    with open(data, "rb") as f:
        rows, curves, sensor = pickle.load(f)
    t0 = time.process_time()
    figures._lean_import()
    t1 = time.process_time()
    from physcam.cli.compare import compare_figure

    compare_figure(rows, curves, out, sensor=sensor)
    print(f"FIGURE {time.process_time() * 1e3:.1f} {(t1 - t0) * 1e3:.1f}", flush=True)


def _figure_once(data: str, env: dict) -> tuple[float, float, float]:
    """(wall s, CPU s, matplotlib import s) of one cold figure process (CPU: user + system, as cold_start.py's)."""
    with tempfile.TemporaryDirectory() as tmp:
        r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
        t = time.perf_counter()
        p = subprocess.run([sys.executable, os.path.abspath(__file__), "--figure-child", data, f"{tmp}/c.png"],
                           capture_output=True, text=True, env=env, cwd=tmp, stdin=subprocess.DEVNULL)
        wall = time.perf_counter() - t
        r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    lines = [ln for ln in p.stdout.splitlines() if ln.startswith("FIGURE ")]
    if p.returncode or not lines:
        raise SystemExit(f"the figure process failed ({p.returncode}): {p.stderr[-800:]}")
    cpu = r1.ru_utime - r0.ru_utime + r1.ru_stime - r0.ru_stime
    return wall, cpu, float(lines[-1].split()[2]) / 1e3


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=5)
    ap.add_argument("--figure-child", nargs=2, help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.figure_child:
        _figure_child(*args.figure_child)
        return
    print(f"{os.cpu_count()} cores; load average {load()} at start; {args.runs} runs each")
    print(machine_marks())
    env = child_env(None, None)
    with tempfile.TemporaryDirectory() as scratch:
        data = os.path.join(scratch, "measurements.pickle")
        _measurements(data)
        rows = {"table": [], "figure": [], "compare -o png": []}
        mpl = []
        for k in range(args.runs + 1):  # run 0 warms the OS file cache and the bytecode
            with tempfile.TemporaryDirectory() as tmp:
                table = run_once(PROGRAM + COMPARE, env, tmp)
            figure = _figure_once(data, env)
            with tempfile.TemporaryDirectory() as tmp:
                whole = run_once(PROGRAM + [a.replace("{tmp}", tmp) for a in CASES["compare"][0]], env, tmp)
            if k:
                rows["table"].append(table)
                rows["figure"].append(figure[:2])
                rows["compare -o png"].append(whole)
                mpl.append(figure[2])
    med = {}
    for name, got in rows.items():
        wall, cpu = (statistics.median(v[i] for v in got) for i in (0, 1))
        med[name] = wall
        extra = f"; matplotlib's import {statistics.median(mpl) * 1e3:.0f} ms CPU" if name == "figure" else ""
        print(f"{name}: wall median {wall * 1e3:.0f} ms, CPU median {cpu * 1e3:.0f} ms{extra}")
    floor = max(med["table"], med["figure"])
    print(f"floor of compare -o png on two cores, max(table, figure): {floor * 1e3:.0f} ms wall; goal 500 ms: "
          f"{'reachable' if floor < 0.5 else 'NOT reachable'} (load {load()})")


if __name__ == "__main__":
    main()

"""Benchmark: `physcam report --lens` of a prescription, this tree against another, side by side (issue 43).

Each command runs in a fresh Python process, alternately from this tree and from ``--baseline`` (the
``src`` folder of another checkout, e.g. a worktree of main before issue 43: ``git worktree add
--detach /tmp/base e8024b3``), so machine load hits both alike; the figure is the CPU time (user +
system) of the child, less disturbed by other jobs than the wall clock, and its ratio. A second
table times the report alone inside each process (the lens loaded and the glass catalogue read
first), where the focus solves are. Bytecode caches are kept (PYTHONDONTWRITEBYTECODE dropped, as in
benchmarks/startup.py). A third line times the floor in the same alternation: a Python that only imports
the standard library's modules the command loads (:data:`STDLIB`; numpy was the floor until issue 43's
round 6 made the report numpy-free), and the ratio no report can beat while it loads them
(baseline / floor): what physcam's own code may cost is the command's time less the floor.

    .venv/bin/python benchmarks/report_lens.py --baseline /tmp/base/src [--runs 15] [--lens zuiko_18mm_f3_5] [--text]
"""

import argparse
import os
import resource
import statistics
import subprocess
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parents[1] / "src"
#: the standard library's modules `physcam report --lens` imports (round 7, issue 43), besides Python's start-up
STDLIB = "argparse, contextvars, csv, datetime, json, pathlib, threading, tomllib, typing, unicodedata"
#: the report alone, inside one process: the lens and its glasses loaded first (what both trees share)
INNER = r"""
import sys, time, warnings
warnings.simplefilter("ignore")
from physcam.lens.library import load_lens
from physcam.onset.report import solve_lens_report
lens = load_lens(sys.argv[1])
import physcam.optics.glass as g
for s in lens.surfaces:
    g.medium_dispersion(s.medium)
t = time.process_time()
solve_lens_report(lens=lens, sensor="S35", fstop=float(sys.argv[2]), focus_mm=float(sys.argv[3]))
print(time.process_time() - t)
"""


def env_for(src: Path) -> dict:
    env = dict(os.environ)
    env.pop("PYTHONDONTWRITEBYTECODE", None)
    env["PYTHONPATH"] = str(src)
    env["PYTHONWARNINGS"] = "ignore"
    return env


def cpu_of(argv, env) -> tuple[float, float]:
    r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    subprocess.run(argv, check=True, capture_output=True, env=env)
    wall = time.perf_counter() - t0
    r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r1.ru_utime - r0.ru_utime + r1.ru_stime - r0.ru_stime, wall


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--baseline", required=True, help="the src folder of the tree to compare with")
    ap.add_argument("--runs", type=int, default=15)
    ap.add_argument("--lens", default="zuiko_18mm_f3_5")
    ap.add_argument("--fstop", default="4")
    ap.add_argument("--focus-mm", default="2000")
    ap.add_argument("--text", action="store_true", help="time the table people read (no --json)")
    args = ap.parse_args()
    trees = {"baseline": Path(args.baseline).resolve(), "this tree": HERE}
    cmd = [sys.executable, "-m", "physcam", "report", "--lens", args.lens, "--fstop", args.fstop, "--focus",
           f"{float(args.focus_mm) / 1000:g}m", *(() if args.text else ("--json",))]
    inner = [sys.executable, "-c", INNER, args.lens, args.fstop, args.focus_mm]
    print(f"load average {', '.join(f'{v:.2f}' for v in os.getloadavg())} at start; {' '.join(cmd[2:])}")
    for name, src in trees.items():  # warm the OS file cache and the bytecode caches
        subprocess.run(cmd, check=True, capture_output=True, env=env_for(src))
    cpu = {k: [] for k in trees}
    wall = {k: [] for k in trees}
    report = {k: [] for k in trees}
    floor = []
    for _ in range(args.runs):
        floor.append(cpu_of([sys.executable, "-c", f"import {STDLIB}"], env_for(HERE))[0])
        for name, src in trees.items():
            c, w = cpu_of(cmd, env_for(src))
            cpu[name].append(c)
            wall[name].append(w)
            out = subprocess.run(inner, check=True, capture_output=True, text=True, env=env_for(src))
            report[name].append(float(out.stdout.strip().splitlines()[-1]))
    med = {k: statistics.median(v) for k, v in cpu.items()}
    rep = {k: statistics.median(v) for k, v in report.items()}
    for name in trees:
        print(f"{name:10s} physcam report --lens: CPU median {med[name] * 1000:.0f} ms (wall median "
              f"{statistics.median(wall[name]) * 1000:.0f} ms); the report alone {rep[name] * 1000:.1f} ms CPU")
    fl = statistics.median(floor)
    print(f"floor      python -c 'import {STDLIB}': CPU median {fl * 1000:.0f} ms; a report loading them is at "
          f"most {med['baseline'] / fl:.2f}x faster than the baseline")
    print(f"ratio baseline / this tree: command {med['baseline'] / med['this tree']:.2f}x, "
          f"report alone {rep['baseline'] / rep['this tree']:.2f}x over {args.runs} runs "
          f"(load {', '.join(f'{v:.2f}' for v in os.getloadavg())} at the end)")


if __name__ == "__main__":
    main()

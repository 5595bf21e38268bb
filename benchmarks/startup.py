"""Benchmark: wall time of CLI commands from process start to answer (cold processes).

Goals: `physcam report` under 0.3 s (issue 2); `physcam spot`, `physcam bokeh` and
`physcam distortion` under 0.5 s (issue 14); the vendor MTF chart (`physcam mtf`) under 1 s
(issue 27). Each command runs in a fresh Python process (the
OS file cache, numba's on-disk kernel cache and Python's bytecode cache warm: one untimed run
first). The bytecode cache is what every installed Python program has after its first run; an
environment with PYTHONDONTWRITEBYTECODE set (some CI images, this project's sandbox) would
otherwise compile physcam's modules from source in every process (40-60 ms), so the children run
without it. Plain script:

    .venv/bin/python benchmarks/startup.py [--runs 15] [--only spot,bokeh]
"""

import argparse
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time

PY = [sys.executable, "-m", "physcam"]
COMMANDS = {
    "report": (PY + ["report", "--focal", "50", "--fstop", "2.8", "--focus", "3m", "--sensor", "ALEXA 35", "--json"], 0.3),
    "spot": (PY + ["spot", "dgauss_50mm"], 0.5),
    "bokeh": (PY + ["bokeh", "dgauss_50mm"], 0.5),
    "distortion": (PY + ["distortion", "dgauss_50mm"], 0.5),
    "bokeh --rays 1000000": (PY + ["bokeh", "dgauss_50mm", "--rays", "1000000"], None),
    "spot -o png": (PY + ["spot", "dgauss_50mm", "-o", "{tmp}/spot.png", "--force"], None),
    # the vendor MTF chart (issue 27 item 5): 15 fields x 3 wavelengths, goal 1 s cold
    "mtf": (PY + ["mtf", "--lens", "dgauss_50mm", "--fstop", "4", "--focus", "3m", "--sensor", "FF"], 1.0),
}


def load() -> str:
    return ", ".join(f"{v:.2f}" for v in os.getloadavg())


def child_env() -> dict:
    env = dict(os.environ)
    env.pop("PYTHONDONTWRITEBYTECODE", None)
    return env


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=15)
    ap.add_argument("--only", default=None, help="comma-separated command names (default: all)")
    args = ap.parse_args()
    names = list(COMMANDS) if args.only is None else [n.strip() for n in args.only.split(",")]
    print(f"load average {load()} at start")
    env = child_env()
    with tempfile.TemporaryDirectory() as tmp:
        for name in names:
            argv, goal = COMMANDS[name]
            argv = [a.replace("{tmp}", tmp) for a in argv]
            subprocess.run(argv, check=True, capture_output=True, env=env)  # warm the OS file cache and the JIT cache
            times, cpu = [], []
            for _ in range(args.runs):
                r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
                t0 = time.perf_counter()
                subprocess.run(argv, check=True, capture_output=True, env=env)
                times.append(time.perf_counter() - t0)
                r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
                cpu.append(r1.ru_utime - r0.ru_utime + r1.ru_stime - r0.ru_stime)
            med = statistics.median(times)
            # CPU time (user + system, all threads) is what a command costs on a quiet machine, less
            # disturbed by other jobs than the wall clock
            line = (f"physcam {name}: median {med * 1000:.0f} ms, min {min(times) * 1000:.0f} ms, "
                    f"max {max(times) * 1000:.0f} ms over {args.runs} runs (CPU median "
                    f"{statistics.median(cpu) * 1000:.0f} ms)")
            if goal is not None:
                line += f"; goal {goal * 1000:.0f} ms: ratio {med / goal:.2f} ({'met' if med < goal else 'NOT met'})"
            print(line + f" (load {load()})")
    t0 = time.perf_counter()
    subprocess.run([sys.executable, "-c", "pass"], check=True)
    print(f"(bare python start-up: {(time.perf_counter() - t0) * 1000:.0f} ms)")


if __name__ == "__main__":
    main()

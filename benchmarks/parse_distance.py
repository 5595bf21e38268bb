"""What reading a typed distance costs, and `physcam report`'s CPU, on any physcam (PYTHONPATH=<checkout>/src).

Run:  PYTHONPATH=$PWD/src .venv/bin/python benchmarks/parse_distance.py [--calls 200000] [--runs 15]

1. ``physcam.units.parse_distance`` per call (CPU, ``time.process_time``) for the spellings people type:
   ``3m``, ``450``, ``10ft``, ``10'6"``, ``9' 10 1/8"`` (and ``10’6”`` where the checkout reads it). Goal: the
   round-22 reading of typographic marks (physcam.units.plain_marks) adds under 1 us a call.
2. ``physcam report --focal 50 --fstop 2.8 --focus 10'6" --json``: CPU (user + system, from
   ``resource.getrusage(RUSAGE_CHILDREN)``) per run, median of ``--runs``. Goal (docs/performance.md, "CLI
   start-up"): unchanged by the round.

The machine's mark (the brief's ``sum(range(10**6))`` in ms) and the load average are printed with the figures.
"""

from __future__ import annotations

import argparse
import os
import resource
import statistics
import subprocess
import sys
import time

from physcam.units import parse_distance

SPELLINGS = ["3m", "450", "10ft", "10'6\"", "9' 10 1/8\"", "10’6”"]


def mark_ms() -> float:
    t = time.perf_counter()
    sum(range(10**6))
    return (time.perf_counter() - t) * 1e3


def per_call_us(text: str, calls: int) -> float | None:
    try:
        parse_distance(text)
    except Exception:  # this checkout does not read the spelling
        return None
    t = time.process_time()
    for _ in range(calls):
        parse_distance(text)
    return (time.process_time() - t) / calls * 1e6


def report_cpu_ms(runs: int) -> list[float]:
    argv = [sys.executable, "-m", "physcam", "report", "--focal", "50", "--fstop", "2.8", "--focus", "10'6\"",
            "--json"]
    out = []
    for _ in range(runs):
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        subprocess.run(argv, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        out.append((after.ru_utime - before.ru_utime + after.ru_stime - before.ru_stime) * 1e3)
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--calls", type=int, default=200_000)
    ap.add_argument("--runs", type=int, default=15)
    a = ap.parse_args()
    print(f"mark {mark_ms():.1f} ms, load {', '.join(f'{v:.2f}' for v in os.getloadavg())}")
    for s in SPELLINGS:
        us = per_call_us(s, a.calls)
        print(f"parse_distance({s!r}): " + ("not read here" if us is None else f"{us:.2f} us CPU a call"))
    cpu = report_cpu_ms(a.runs)
    print(f"physcam report --json: CPU {statistics.median(cpu):.1f} ms median (min {min(cpu):.1f}, max {max(cpu):.1f}) "
          f"of {a.runs} runs")
    print(f"mark {mark_ms():.1f} ms, load {', '.join(f'{v:.2f}' for v in os.getloadavg())}")


if __name__ == "__main__":
    main()

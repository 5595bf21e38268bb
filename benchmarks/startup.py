"""Benchmark: wall time of `physcam report` from process start to answer.

Goal (issue 2): under 0.3 s on the 2-core reference machine. Plain script, prints figures:
    .venv/bin/python benchmarks/startup.py
"""

import statistics
import subprocess
import sys
import time

ARGV = [sys.executable, "-m", "physcam", "report", "--focal", "50", "--fstop", "2.8", "--focus", "3m",
        "--sensor", "ALEXA 35", "--json"]
GOAL_S = 0.3


def main(runs: int = 15) -> None:
    subprocess.run(ARGV, check=True, capture_output=True)  # warm the OS file cache
    times = []
    for _ in range(runs):
        t0 = time.perf_counter()
        subprocess.run(ARGV, check=True, capture_output=True)
        times.append(time.perf_counter() - t0)
    med = statistics.median(times)
    print(f"physcam report: median {med * 1000:.0f} ms, min {min(times) * 1000:.0f} ms, "
          f"max {max(times) * 1000:.0f} ms over {runs} runs")
    print(f"goal {GOAL_S * 1000:.0f} ms: ratio median/goal = {med / GOAL_S:.2f} ({'met' if med < GOAL_S else 'NOT met'})")
    t0 = time.perf_counter()
    subprocess.run([sys.executable, "-c", "pass"], check=True)
    print(f"(bare python start-up: {(time.perf_counter() - t0) * 1000:.0f} ms)")


if __name__ == "__main__":
    main()

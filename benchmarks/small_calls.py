"""Small tracer calls: per-call overhead, the serial/parallel crossover, and analyses made of many calls.

Run:  .venv/bin/python benchmarks/small_calls.py [--busy 1]

1. Per-call overhead for a cached lens (dgauss_50mm, already traced once): the public
   ``trace_to_film`` and ``trace_through(in_place=True)`` on one ray, against the JIT kernel called
   directly on the same ray (its arithmetic for one ray is ~0.1 us). Goal: overhead under 10 us.
2. The batch size below which the kernel runs on the calling thread
   (``physcam.trace.kernels.SERIAL_BELOW``): the kernel serial and on the thread pool, per size.
3. ``real_distortion`` (dgauss_50mm, 15 fields: aiming by Newton iteration, field-limit bisection,
   each step a small tracer call) and a 3-field ``spot_diagram`` (0, 5, 10 deg), warm, on the
   machine as it is and with ``--busy`` processes spinning beside it (a loaded machine).

Medians of repeated calls; the load average is printed with every block (other jobs share the
machine). Parts 1 and 2 need the kernel API of this branch; part 3 runs on any physcam
(``PYTHONPATH=<other checkout>/src`` to compare).
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import time

import numpy as np

from physcam.analysis.distortion.field import real_distortion
from physcam.analysis.image_quality.spot import spot_diagram
from physcam.lens.library import load_lens
from physcam.trace import RayBatch, paraxial_image_z, trace_through, trace_to_film

NO_OPL = np.empty(0)  # the JIT kernel's last argument: no optical path


def load() -> str:
    return ", ".join(f"{v:.2f}" for v in os.getloadavg())


def per_call(fn, n=3000, rounds=5) -> float:
    """Median over ``rounds`` of the mean time of ``n`` calls (us)."""
    fn()
    res = []
    for _ in range(rounds):
        t = time.perf_counter()
        for _ in range(n):
            fn()
        res.append((time.perf_counter() - t) / n * 1e6)
    return statistics.median(res)


def timed(fn, rounds) -> tuple[float, float]:
    """(median, max) wall time in ms of ``rounds`` calls after one warm-up call."""
    fn()
    ts = []
    for _ in range(rounds):
        t = time.perf_counter()
        fn()
        ts.append((time.perf_counter() - t) * 1e3)
    return statistics.median(ts), max(ts)


def overhead(lens, film) -> None:
    from physcam.trace.kernels import jit_kernel
    from physcam.trace.tables import packed_table

    ray = RayBatch.collimated([1.0], [0.5], -1.0)
    jit = jit_kernel()  # loads numba: from here on "auto" uses the JIT kernel
    t_film = per_call(lambda: trace_to_film(lens, ray, film))
    work = ray.copy()
    t_inplace = per_call(lambda: trace_through(lens, work, end_z=film, in_place=True))
    line = (f"  one ray, cached lens: trace_to_film {t_film:.2f} us, trace_through(in_place=True) "
            f"{t_inplace:.2f} us")
    if jit is not None:
        p = packed_table(lens)
        S = p.at_wavelength(ray.wavelength_nm[0])
        cols = work.columns()
        t_k = per_call(lambda: jit(*cols, S, p.kinds, True, False, film, True, True, 1 << 30, NO_OPL))
        line += (f", kernel alone {t_k:.2f} us -> overhead {t_film - t_k:.2f} / {t_inplace - t_k:.2f} us "
                 f"(goal 10 us)")
    print(line)


def crossover(lens, film) -> None:
    from physcam.trace import kernels
    from physcam.trace.tables import packed_table

    jit = kernels.jit_kernel()
    if jit is None:
        print("  (no serial/parallel switch in this physcam)")
        return
    p = packed_table(lens)
    rng = np.random.default_rng(0)
    print(f"  {'rays':>7} {'serial us':>10} {'parallel us':>12}  (SERIAL_BELOW = {kernels.SERIAL_BELOW})")
    for n in (16, 64, 256, 1024, 2048, 4096, 8192, 16384, 65536):
        r = 10.0 * np.sqrt(rng.random(n))
        b = RayBatch.collimated(r, np.zeros(n), -1.0)
        S = p.at_wavelength(b.wavelength_nm[0])
        res = []
        for below in (1 << 30, 0):
            def call():
                c = b.copy().columns()
                jit(*c, S, p.kinds, True, False, film, True, True, below, NO_OPL)
            copy_cost = per_call(lambda: b.copy().columns(), n=max(20, 20000 // n))
            res.append(per_call(call, n=max(20, 20000 // n)) - copy_cost)
        print(f"  {n:7d} {res[0]:10.1f} {res[1]:12.1f}")


def analyses(lens) -> None:
    d = timed(lambda: real_distortion(lens), 7)
    s = timed(lambda: spot_diagram(lens, (0.0, 5.0, 10.0)), 5)
    print(f"  distortion (15 fields): median {d[0]:.1f} ms, max {d[1]:.1f} ms | 3-field spot: median {s[0]:.1f} ms, "
          f"max {s[1]:.1f} ms | load {load()}")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--busy", type=int, default=1, help="processes spinning beside the loaded runs (default 1)")
    args = ap.parse_args()
    lens = load_lens("dgauss_50mm")
    film = paraxial_image_z(lens)
    try:  # a warm process: numba loaded ("auto" starts on numpy until numba pays for its loading)
        from physcam.trace.kernels import numba_available

        numba_available()
    except ImportError:
        pass
    trace_to_film(lens, RayBatch.collimated([1.0], [0.5], -1.0), film)
    print(f"physcam small calls, dgauss_50mm; load average {load()}")
    for label, busy in (("machine as it is", 0), (f"with {args.busy} busy process(es) beside it", args.busy)):
        procs = [subprocess.Popen([sys.executable, "-c", "while True: pass"]) for _ in range(busy)]
        try:
            time.sleep(0.5 if busy else 0.0)
            print(f"{label} (load {load()}):")
            try:
                overhead(lens, film)
                crossover(lens, film)
            except (ImportError, TypeError) as exc:  # another physcam without this API
                print(f"  (overhead and crossover need this branch's kernel API: {exc})")
            analyses(lens)
        finally:
            for p in procs:
                p.kill()
                p.wait()


if __name__ == "__main__":
    main()

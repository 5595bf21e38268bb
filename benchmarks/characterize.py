"""Characterization on Dask: the same grid on 1 and 2 local workers; speedup and scheduling overhead.

Run:  .venv/bin/python benchmarks/characterize.py [--lens dgauss_50mm] [--rays 200000]

Each worker count gets its own ``LocalCluster`` (single-threaded worker processes, numba on one
thread each, as ``physcam characterize`` starts them), warmed by a small run into a scratch folder
and by :func:`warm_worker` on every worker (imports, numba's load and first call: what a worker
pays once per process, and which a small warm-up grid alone leaves to the timed run on a worker
that got no cell of a kind), then the grid is characterized into a fresh folder. Reported:

* wall: from the first task submitted to the last result (cluster start-up shown apart);
* compute: the sum of the cells' own compute times (measured inside each task);
* overhead = 1 - compute / (workers x wall): the share of the workers' time not spent computing
  cells (scheduling, transfers, start of the first task, the idle tail); goal < 5 %;
* speedup = wall(1 worker) / wall(2 workers); goal >= 1.7 on 2 cores.

The grid (default): focus 1m:inf:4, f/2.8 and f/4, 3 fields, the lens's design wavelength, every
kind: 1 lens cell, 4 distortion (ST-maps 2048 x 1366 px on a 36 x 24 mm gate), 8 illumination
(grid 100), 24 PSF (1 000 000 rays, 64 px): 37 cells.
"""

from __future__ import annotations

import argparse
import os
import shutil
import subprocess
import tempfile
import time

from physcam.characterize import Grid, characterize, parse_focus_marks
from physcam.characterize.run import local_cluster

#: The grid's gate: full frame, as when the figures in docs/performance.md were first taken (the
#: library's default sensor is Super 35 since; 2048 x 1366 px are square pixels on 36 x 24 mm)
FULL_FRAME_MM = (36.0, 24.0)


def warm_worker(lens: str) -> None:
    """What a worker pays once: imports (matplotlib, OpenEXR, pyarrow, the analyses) and numba's load
    and first call. Run on every worker before timing, so neither worker count's figures include it
    (a small warm-up grid alone leaves a worker cold when the scheduler gives it no cell of a kind)."""
    import OpenEXR  # noqa: F401
    import matplotlib.image  # noqa: F401
    import numpy as np
    import pyarrow.parquet  # noqa: F401

    import physcam.analysis.distortion.models  # noqa: F401
    import physcam.analysis.image_quality.illumination  # noqa: F401
    import physcam.analysis.distortion.stmap  # noqa: F401
    import physcam.characterize.cells  # noqa: F401
    from physcam.lens.library import load_lens
    from physcam.trace import RayBatch, paraxial_image_z, trace_to_film

    rx = load_lens(lens)
    n = 2000
    b = RayBatch(np.zeros(n), np.linspace(-1, 1, n), np.full(n, -100.0), np.zeros(n), np.zeros(n), np.ones(n),
                 np.full(n, rx.wavelength_nm), np.ones(n), np.zeros(n, dtype=np.uint8))
    trace_to_film(rx, b, paraxial_image_z(rx), backend="numba")


def run(n_workers: int, grid: Grid, lens: str) -> dict:

    t0 = time.perf_counter()
    cluster = local_cluster(n_workers)  # as `physcam characterize` starts it
    start = time.perf_counter() - t0
    scratch = tempfile.mkdtemp(prefix="physcam-bench-warm-")
    out = tempfile.mkdtemp(prefix="physcam-bench-")
    try:
        warm = Grid(focus_mm=(2000.0,), fstops=grid.fstops[:1], fields=2, resolution=(64, 43), psf_rays=20_000,
                    psf_pixels=16, illumination_grid=16, sensor_mm=grid.sensor_mm)
        characterize([lens], warm, scratch, scheduler=cluster.scheduler_address, usd=False)
        from distributed import Client

        with Client(cluster, set_as_default=False) as client:
            client.run(warm_worker, lens)
        s = characterize([lens], grid, out, scheduler=cluster.scheduler_address, usd=False)
        assert not s.failed, s.failed
        return {"workers": s.workers, "cells": s.cells, "cluster_start_s": start, "wall_s": s.wall_s,
                "compute_s": s.compute_s, "overhead": s.overhead}
    finally:
        cluster.close()
        shutil.rmtree(scratch, ignore_errors=True)
        shutil.rmtree(out, ignore_errors=True)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--lens", default="dgauss_50mm")
    ap.add_argument("--focus", default="1m:inf:4")
    ap.add_argument("--rays", type=int, default=1_000_000)
    ap.add_argument("--resolution", default="2048x1366")
    args = ap.parse_args()
    w, h = (int(v) for v in args.resolution.split("x"))
    grid = Grid(focus_mm=parse_focus_marks(args.focus), fstops=(2.8, 4.0), fields=3, resolution=(w, h),
                psf_rays=args.rays, psf_pixels=64, illumination_grid=100, sensor_mm=FULL_FRAME_MM)
    print(f"load before: {subprocess.run(['uptime'], capture_output=True, text=True).stdout.strip()}")
    print(f"cores: {os.cpu_count()}")
    rows = [run(n, grid, args.lens) for n in (1, 2)]
    for r in rows:
        print(f"{r['workers']} worker(s): {r['cells']} cells, cluster up {r['cluster_start_s']:.1f} s, "
              f"wall {r['wall_s']:.2f} s, compute {r['compute_s']:.2f} s, overhead {100 * r['overhead']:.1f} %")
    print(f"speedup 1 -> 2 workers: {rows[0]['wall_s'] / rows[1]['wall_s']:.2f}x (goal >= 1.7)")
    print(f"load after: {subprocess.run(['uptime'], capture_output=True, text=True).stdout.strip()}")


if __name__ == "__main__":
    main()

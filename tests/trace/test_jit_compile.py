"""The first traced command after an install (issue 47): numba's disk cache empty.

A command compiles only the JIT variant it uses (the passes that variant calls: no asphere, Fresnel
or dispersion pass for a one-wavelength trace of spherical surfaces), tells the compile reporter as
it goes, leaves its code and a marker in the cache, and the next process loads it without compiling;
"auto" keeps a job that the numpy kernel does faster than the compile in numpy. Each case runs in a
fresh process with ``NUMBA_CACHE_DIR`` pointing at an empty folder (numba's own variable, which
physcam's cache honours first)."""

from __future__ import annotations

import json
import os
import subprocess
import sys

import pytest

pytest.importorskip("numba")
pytestmark = pytest.mark.slow

TRACE = """
import json, sys
import numpy as np
from physcam.lens.library import load_lens
from physcam.trace import RayBatch, kernels, trace_through
from physcam.trace.kernels import _jitcache

calls = []
kernels.set_compile_reporter(lambda done, total: calls.append((done, total)))
lens = load_lens("dgauss_50mm")
rng = np.random.default_rng(7)
r = 0.9 * lens.surfaces[0].semi_diameter * np.sqrt(rng.random(3000))
ph = 2 * np.pi * rng.random(3000)
rays = RayBatch.collimated(r * np.cos(ph), r * np.sin(ph), -1.0, direction=(0.0, 0.05, 1.0))
warm_before = _jitcache.is_warm()
cost_before = kernels.numba_load_cost()
# a small job under "auto": the numpy kernel, numba not even imported
small = trace_through(lens, rays, end_z=100.0)
auto_imported_numba = "numba" in sys.modules
jit = trace_through(lens, rays, backend="numba", end_z=100.0)
ref = trace_through(lens, rays, backend="numpy", end_z=100.0)
same = all(np.array_equal(a, b) for a, b in zip(jit.columns(), ref.columns()))
same_small = all(np.array_equal(a, b) for a, b in zip(small.columns(), ref.columns()))
from physcam.trace.kernels import _numba
print(json.dumps({"calls": calls, "warm_before": warm_before, "cost_before": cost_before,
                  "auto_imported_numba": auto_imported_numba, "same": same, "same_small": same_small,
                  "passes": list(_numba.variant_passes(True, False, False, False)),
                  "warm_after": _jitcache.is_warm(), "load_s": kernels.NUMBA_LOAD_S,
                  "compile_s": kernels.NUMBA_COMPILE_S}))
"""


def _trace(cache) -> dict:
    env = {k: v for k, v in os.environ.items() if k != "PHYSCAM_BACKEND"}
    env["NUMBA_CACHE_DIR"] = str(cache)
    p = subprocess.run([sys.executable, "-c", TRACE], capture_output=True, text=True, env=env, timeout=600)
    assert p.returncode == 0, p.stderr
    return json.loads(p.stdout)


def test_a_cold_cache_compiles_one_variant_once_and_says_so(tmp_path):
    first = _trace(tmp_path)
    assert first["warm_before"] is False and first["cost_before"] == first["compile_s"]
    assert first["auto_imported_numba"] is False and first["same_small"]
    assert first["same"]  # the JIT kernel's rays are the numpy kernel's, bit for bit
    # the reporter heard the compile: started at 0, one step per pass of the variant and the kernel itself
    total = len(first["passes"]) + 1
    calls = [tuple(c) for c in first["calls"]]
    assert calls[0] == (0, total) and calls[-1] == (total, total)
    assert all(t == total for _, t in calls) and [d for d, _ in calls] == sorted(d for d, _ in calls)
    # only that variant's passes were compiled: nothing for aspheres, Fresnel or mixed wavelengths
    files = [f for _, _, fs in os.walk(tmp_path) for f in fs]
    compiled = {f.removeprefix("_numba.").rsplit("-", 1)[0] for f in files if f.endswith(".nbi")}
    assert compiled == set(first["passes"]) | {"_build.locals.trace_blocks"}, compiled
    assert not compiled & {"_newton_asphere", "_fresnel_pass", "_fill_n1", "_add_path"}
    assert any(f.startswith("physcam-compiled-") for f in files) and first["warm_after"] is True
    # the next process loads what the first compiled: no compile, and "auto" counts the load cost
    second = _trace(tmp_path)
    assert second["calls"] == [] and second["same"]
    assert second["warm_before"] is True and second["cost_before"] == second["load_s"]

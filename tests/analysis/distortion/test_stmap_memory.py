"""An 8K ST-map pair (8192 x 4320, the largest frame physcam maps) is built and written with a peak
resident memory under 2 GiB (issue 24 item 12: it peaked at 2.3 GB, holding float64 frames whole
and every encoded file at once). Measured in a fresh process (ru_maxrss), so nothing this test
session allocated counts; benchmarks/stmap_memory.py prints the same measure with its timing."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

pytestmark = pytest.mark.slow

GOAL_BYTES = 2 * 1024**3

CHILD = r"""
import json, resource, sys, tempfile
import numpy as np
from physcam.analysis.distortion.stmap import MAX_SIDE_PX, distortion_field, write_stmaps
from physcam.lens.library import load_lens

w, h = MAX_SIDE_PX, 4320
res = distortion_field(load_lens("dgauss_50mm"), focus_mm=3000.0, sensor_width_mm=24.89,
                       sensor_height_mm=24.89 * h / w, width_px=w, height_px=h)
with tempfile.TemporaryDirectory() as d:
    names = sorted(p.name for p in write_stmaps(res, d))
print(json.dumps({"peak": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024, "names": names,
                  "shape": list(res.distortion_stmap.shape), "centre": res.distortion_stmap[h // 2, w // 2].tolist()}))
"""


def test_an_8k_stmap_pair_peaks_under_2_gib():
    out = subprocess.run([sys.executable, "-c", CHILD], capture_output=True, text=True, timeout=600)
    assert out.returncode == 0, out.stderr[-2000:]
    r = json.loads(out.stdout.strip().splitlines()[-1])
    assert r["shape"] == [4320, 8192, 3]
    assert r["names"] == ["distortion.exr", "distortion.png", "undistortion.exr", "undistortion.png"]
    # the frame's centre lies on the axis: no distortion there, so its ST value is the centre of the
    # overscanned frame (0.5, 0.5) to float32 precision
    assert r["centre"][:2] == pytest.approx([0.5, 0.5], abs=1e-3)
    assert r["peak"] < GOAL_BYTES, f"peak resident memory {r['peak'] / 1024**3:.2f} GiB"

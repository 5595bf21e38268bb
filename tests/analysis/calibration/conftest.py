"""Work the calibration tests would otherwise repeat, done once per test process.

- **ChArUco detection once per photograph.** The ChArUco photographs are calibrated many times over
  (every deliverable, a flat field, two days, a refused lens file, a killed rerun: 46 + 22 detections of
  23 distinct pictures, 0.15-0.2 s CPU each). ``physcam.analysis.calibration.chart.detect_chart`` is
  OpenCV's real detector the first time a picture (its decoded pixels, shape and type) is seen with a
  ChArUco chart; later calls with the same pixels and chart get copies of that answer. OpenCV's
  detector is deterministic, so each test sees exactly what it would detect itself, and every photograph
  is still read and checked by physcam as before (header, size, mixed modes). Checkerboards are never
  memoised: the refusal tests inject the sector detector's failures (test_calibrate_refusals.py).
- **The ChArUco renders once.** test_calibrate.py's 15 photographs and test_calibrate_refusals.py's 8 are
  the same renders (poses(n, 1), board at 12 px/mm, noise seed k): the ``charuco_photographs`` fixture renders
  each once and the modules write the files they need.
"""

from __future__ import annotations

import hashlib
import sys
from pathlib import Path

import numpy as np
import pytest

cv2 = pytest.importorskip("cv2")
sys.path.insert(0, str(Path(__file__).parents[1]))  # tests/analysis: _charts

_DETECTED: dict = {}
_RENDERED: list = []


@pytest.fixture(autouse=True)
def _detect_each_charuco_photograph_once(monkeypatch):
    from physcam.analysis.calibration import chart

    real = chart.detect_chart

    def detect_chart(image, spec):
        if not isinstance(spec, chart.ChartSpec) or spec.kind != "charuco":
            return real(image, spec)
        a = np.ascontiguousarray(image)
        key = (hashlib.sha256(a.tobytes()).hexdigest(), a.shape, a.dtype.str, spec)
        if key not in _DETECTED:
            _DETECTED[key] = real(image, spec)
        found = _DETECTED[key]
        return None if found is None else (found[0].copy(), found[1].copy())

    monkeypatch.setattr(chart, "detect_chart", detect_chart)


@pytest.fixture(scope="session")
def charuco_photographs():
    """``photographs(n)``: the first ``n`` (up to 15) of the ChArUco photographs of K_TRUE and DIST_TRUE,
    poses(15, 1) rendered by tests/analysis/_charts.py on a board at 12 px/mm, noise seed k for the k-th
    (8-bit arrays), each rendered once in the test process."""
    import _charts

    def photographs(n: int) -> list:
        poses = _charts.poses(15, 1)
        assert n <= len(poses)
        if len(_RENDERED) < n:
            board = _charts.board_image(_charts.CHARUCO, 12.0)
            _RENDERED.extend(_charts.render(_charts.CHARUCO, r, t, board=board, seed=k)
                             for k, (r, t) in enumerate(poses[len(_RENDERED):n], start=len(_RENDERED)))
        return _RENDERED[:n]

    return photographs

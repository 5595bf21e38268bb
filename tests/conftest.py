"""Test-session set-up shared by every test module."""

import atexit
import os
import tempfile

# numpy's BLAS on one thread in every process of the session (before anything loads numpy), as the
# `physcam` program runs it (physcam.cli.run): the suite's two xdist workers already keep both cores
# busy, and OpenBLAS's second thread only spins beside them (tests/analysis/image_quality and
# test_no_nan_analyses.py: 42.1 -> 31.0 s CPU side by side at load 2, the same results;
# docs/performance.md). The library's own users keep OpenBLAS's default.
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import pytest  # noqa: E402
from hypothesis import HealthCheck, settings  # noqa: E402

# Tests never read the real user's physcam config (~/.config/physcam/config.toml): every process of
# the session, subprocesses included, reads an empty config file of its own. A test of the config
# points PHYSCAM_CONFIG elsewhere with monkeypatch.
_fd, _EMPTY_CONFIG = tempfile.mkstemp(prefix="physcam-test-config-", suffix=".toml")
os.close(_fd)
os.environ["PHYSCAM_CONFIG"] = _EMPTY_CONFIG
# ... nor the real user's lens library (`physcam lens add`): every process of the session sees an
# empty one of its own, so "every lens" means the bundled ones. Tests of the user library point
# PHYSCAM_LENS_LIBRARY at a folder of their own with monkeypatch.
os.environ["PHYSCAM_LENS_LIBRARY"] = tempfile.mkdtemp(prefix="physcam-test-lenses-")


def _remove_session_folders(config=_EMPTY_CONFIG, library=os.environ["PHYSCAM_LENS_LIBRARY"]):
    """The empty config and lens library go when the process that made them ends (each xdist worker)."""
    import shutil
    shutil.rmtree(library, ignore_errors=True)
    if os.path.exists(config):
        os.remove(config)


atexit.register(_remove_session_folders)

# USD builds its schema registry once per process: register physcam's PhysicalCamera plugin
# before any test (in any xdist worker, in any order) creates a stage.
import physcam.usd  # noqa: F401  (registers the PhysicalCamera plugin on import)

# CI machines are small and shared: no per-example deadline (a JIT compile or a loaded core must
# not fail a property), and a fixed derandomised run so CI results repeat.
settings.register_profile("physcam", deadline=None, suppress_health_check=[HealthCheck.too_slow],
                          derandomize=True)
settings.load_profile("physcam")


#: Test modules run before every other: the one whose first test builds the session's extension zip
#: (two processes, the suite's longest step, which every Blender extension test waits for).
#: `make test`'s pytest-xdist (--dist worksteal) hands each worker one half of the collection in
#: order, and a worker that runs out takes the tail of the other's queue. In the folders' order the zip
#: was built wherever tests/blender came up on its worker (a fresh clone under load, 2026-11-28: 45
#: minutes into the run, at 83 % of its tests, the other worker waiting on it and on the extension tests queued
#: behind it); now it is built first while the other worker runs short tests, and the slow modules
#: follow, so what a worker takes from the other at the end is short. Whole modules move, each in its
#: own order, so a module-scoped fixture is built once.
LONG_FIRST = (
    "tests/blender/test_extension.py",
)


def pytest_collection_modifyitems(config, items):
    """Put :data:`LONG_FIRST`'s modules first, then every other module with a test marked slow, then the
    rest, each module's tests together and in their order (a stable sort on the module's rank)."""
    rank = {path: i for i, path in enumerate(LONG_FIRST)}
    slow_modules = {item.nodeid.split("::", 1)[0] for item in items if item.get_closest_marker("slow")}

    def key(item):
        module = item.nodeid.split("::", 1)[0]
        return rank.get(module, len(rank) + (module not in slow_modules))

    items.sort(key=key)


@pytest.fixture(scope="session")
def extension_zip(tmp_path_factory):
    """``physcam export blender-extension`` of ``_session.EXTENSION_LENSES``, built once per test session and shared
    by the Blender extension's tests (building it solves each lens's focus table, the slowest step). Under pytest-xdist the workers share one build: the first worker to ask builds it under a
    session lock, with two processes (`--workers`; its module runs first, :data:`LONG_FIRST`, so the build
    starts at once and the other worker runs other tests meanwhile), the other
    reads it (each worker building its own doubled the suite's slowest step; putting every test that
    uses it on one worker, xdist's loadgroup, made that worker the suite's last by a minute). Here, not
    in tests/blender/conftest.py: with --doctest-modules two conftest modules of one name collide.

    Two processes, not this one (round 20 measured this one at 4.6 s less CPU): the session's zip is the
    pooled build tests/export/test_blender_extension_build.py holds to the one-process tables, the only
    pooled build of the suite."""
    from _session import EXTENSION_LENSES, session_lock

    from physcam.cli import main

    with session_lock(tmp_path_factory, "blender-extension") as root:
        out = root / "blender-extension"
        if not list(out.glob("physcam-*.zip")):
            out.mkdir(exist_ok=True)
            from physcam.lens.library import list_lenses

            lenses = [r.slug for r in list_lenses() if r.slug in EXTENSION_LENSES]  # the library's order
            assert len(lenses) == len(EXTENSION_LENSES), set(EXTENSION_LENSES) - set(lenses)
            assert main(["export", "blender-extension", "-o", str(out), "--workers", "2",
                         *(f"--lens={slug}" for slug in lenses)]) == 0
    (zp,) = out.glob("physcam-*.zip")
    return zp


@pytest.fixture(scope="session")
def extension_user(extension_zip, tmp_path_factory):
    """The ``env`` of a Blender user folder (``BLENDER_USER_RESOURCES``) where :func:`extension_zip` is
    installed with Blender's own installer, once per session and shared by the extension's render tests
    (tests/blender/_blender.py, ``install_extension``); their scripts enable it. Under pytest-xdist the
    first worker to ask installs it under a session lock."""
    from _blender import install_extension
    from _session import session_lock

    with session_lock(tmp_path_factory, "blender-extension-user") as root:
        return install_extension(extension_zip, root / "blender-user")


# --- tests/analysis/calibration: work its tests would otherwise repeat, done once per test process (here, not in
# a conftest.py of that folder: with --doctest-modules two conftest modules of one name collide)
#
# - **ChArUco detection once per photograph.** The ChArUco photographs are calibrated many times over
#   (every deliverable, a flat field, two days, a refused lens file, a killed rerun: 46 + 22 detections of
#   23 distinct pictures, 0.15-0.2 s CPU each). ``physcam.analysis.calibration.chart.detect_chart`` is
#   OpenCV's real detector the first time a picture (its decoded pixels, shape and type) is seen with a
#   ChArUco chart; later calls with the same pixels and chart get copies of that answer. OpenCV's
#   detector is deterministic, so each test sees exactly what it would detect itself, and every photograph
#   is still read and checked by physcam as before (header, size, mixed modes). Checkerboards are not
#   memoised here: the refusal tests inject the sector detector's failures (test_calibrate_refusals.py, which
#   asks OpenCV's search of its one photograph once per image size, under the injections).
# - **The ChArUco renders once.** test_calibrate.py's 15 photographs and test_calibrate_refusals.py's 8 are
#   the same renders (poses(n, 1), board at 12 px/mm, noise seed k): the ``charuco_photographs`` fixture renders
#   each once and the modules write the files they need. tests/farm/test_farm_run.py's 5 are the first 5 of them.
# - **The checkerboard renders once.** test_calibrate.py's two shoots and test_calibrate_refusals.py's one photograph
#   are renders of one board picture (9 x 6 inner corners at 12 px/mm, 0.8 s of CPU to draw), and the refusals'
#   photograph is test_calibrate.py's first at 2 m (whole_board_poses(n, 1)'s first pose, noise seed 0): the
#   ``checker_photographs`` fixture draws the board once and renders each photograph once.
CALIBRATION_TESTS = "tests/analysis/calibration/"
#: the farm's calibrate test: its direct run in this process detects the first five ChArUco photographs (its
#: openjd tasks, other processes, run OpenCV's detector themselves)
FARM_CALIBRATION = "tests/farm/test_farm_run.py::test_openjd_calibrate"
_DETECTED: dict = {}
_RENDERED: list = []
_CHECKER_RENDERED: dict = {}


@pytest.fixture(autouse=True)
def _detect_each_charuco_photograph_once(request, monkeypatch):
    """The calibration tests' ChArUco detection once per photograph (notes above); other tests untouched."""
    if not request.node.nodeid.startswith((CALIBRATION_TESTS, FARM_CALIBRATION)):
        return
    from physcam.analysis.calibration import chart

    real = chart.detect_chart

    def detect_chart(image, spec):
        if not isinstance(spec, chart.ChartSpec) or spec.kind != "charuco":
            return real(image, spec)
        import hashlib

        import numpy as np

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
    pytest.importorskip("cv2")
    import _charts  # tests/analysis (pyproject.toml's pythonpath)

    def photographs(n: int) -> list:
        poses = _charts.poses(15, 1)
        assert n <= len(poses)
        if len(_RENDERED) < n:
            board = _charts.board_image(_charts.CHARUCO, 12.0)
            _RENDERED.extend(_charts.render(_charts.CHARUCO, r, t, board=board, seed=k)
                             for k, (r, t) in enumerate(poses[len(_RENDERED):n], start=len(_RENDERED)))
        return _RENDERED[:n]

    return photographs


@pytest.fixture(scope="session")
def checker_photographs():
    """``photographs(n, seed, K)``: the first ``n`` checkerboard photographs of a shoot through ``K`` (3 x 3) and
    DIST_TRUE, rendered by tests/analysis/_charts.py: the board (``_charts.CHECKER``) at 12 px/mm in the poses
    ``whole_board_poses(n, seed, K=K)``, noise seed k for the k-th (8-bit arrays). The board is drawn once and
    each photograph rendered once in the test process (the first ``n`` poses of a shoot are the same whatever
    ``n``: the poses are drawn in order from one generator)."""
    pytest.importorskip("cv2")
    import _charts  # tests/analysis (pyproject.toml's pythonpath)
    import numpy as np

    def photographs(n: int, seed: int, K) -> list:
        K = np.asarray(K, np.float64)
        done = _CHECKER_RENDERED.setdefault((K.tobytes(), seed), [])
        if len(done) < n:
            if "board" not in _CHECKER_RENDERED:
                _CHECKER_RENDERED["board"] = _charts.board_image(_charts.CHECKER, 12.0)
            poses = _charts.whole_board_poses(n, seed, K=K)
            done.extend(_charts.render(_charts.CHECKER, r, t, board=_CHECKER_RENDERED["board"], seed=k, K=K)
                        for k, (r, t) in enumerate(poses[len(done):n], start=len(done)))
        return done[:n]

    return photographs

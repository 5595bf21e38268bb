"""physcam farm jobs run for real (issue 48): the Open Job Description template physcam writes, run on this
machine by ``openjd run`` (openjd-cli: a session per step, a process per task), gives the very bytes
``physcam defocus`` / ``characterize`` / ``calibrate`` give run directly; a task killed with SIGKILL
mid-way and the job run again gives them too; a rerun of a finished job skips every output. Real
EXRs (OpenEXR), real Dask for the direct runs, real chart photographs (OpenCV's projection)."""

from __future__ import annotations

import json
import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("openjd.cli")
pytest.importorskip("distributed")
pytest.importorskip("OpenEXR")

from physcam.cli import main  # noqa: E402
from physcam.farm.tasklist import read_task_list  # noqa: E402

pytestmark = pytest.mark.slow

PHYSCAM = f"{sys.executable} -m physcam"  # how the farm's tasks run physcam here: this interpreter
W, H = 48, 32
CAMERA = ["--lens", "dgauss_50mm", "--focus", "2m", "--fstop", "2.8", "--sensor-width", "36", "--sensor-height", "24",
          "--tile", "16"]


def _in(folder, argv) -> int:
    old = os.getcwd()
    os.chdir(folder)
    try:
        return main(argv)
    finally:
        os.chdir(old)


def _openjd(folder, job, last_step) -> str:
    """``openjd run JOB --step LAST --run-dependencies`` in ``folder``: its log (it must succeed)."""
    p = subprocess.run([sys.executable, "-m", "openjd", "run", job, "--step", last_step, "--run-dependencies"],
                       cwd=folder, capture_output=True, text=True, timeout=900)
    assert p.returncode == 0, p.stdout[-3000:] + p.stderr[-2000:]
    return p.stdout


def _files(folder: Path, skip=("index", ".locks")) -> dict:
    """{relative path: bytes} of every file under ``folder`` (but the skipped top folders)."""
    return {p.relative_to(folder).as_posix(): p.read_bytes() for p in sorted(folder.rglob("*"))
            if p.is_file() and p.relative_to(folder).parts[0] not in skip}


def _kill_when(argv, cwd, ready, timeout=300.0):
    """Start ``argv``, wait until ``ready()`` is true, then SIGKILL its process group; True if it was
    still running (killed mid-way), False if it had finished."""
    proc = subprocess.Popen(argv, cwd=cwd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, start_new_session=True)
    t0 = time.monotonic()
    while not ready():
        if proc.poll() is not None or time.monotonic() - t0 > timeout:
            proc.kill()
            raise AssertionError(f"the task ended before it could be killed: {proc.stderr.read()[-2000:]!r}")
        time.sleep(0.005)
    running = proc.poll() is None
    os.killpg(proc.pid, signal.SIGKILL)
    proc.wait()
    return running


# ---- defocus ---------------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def shot(tmp_path_factory):
    """Four 48 x 32 frames (a near block moving over a far wall, random colours) defocused by ``physcam
    defocus in.####.exr`` directly (a Dask run, one worker): the reference bytes."""
    import OpenEXR

    d = tmp_path_factory.mktemp("shot")
    rng = np.random.default_rng(3)
    for n in (1, 2, 3, 4):
        z = np.full((H, W), 3.0)
        z[10:20, 10 + n:20 + n] = 0.6
        planes = {**{c: rng.uniform(0, 1, (H, W)) for c in "RGB"}, "Z": z}
        header = {"compression": OpenEXR.ZIP_COMPRESSION, "type": OpenEXR.scanlineimage}
        with OpenEXR.File(header, {k: np.ascontiguousarray(v, np.float32) for k, v in planes.items()}) as f:
            f.write(str(d / f"in.{n:04d}.exr"))
    assert _in(d, ["defocus", "in.####.exr", *CAMERA, "-o", "direct/d.####.exr", "--workers", "1"]) == 0
    return d, _files(d / "direct", skip=("kernels",))


def _defocus_job(folder, out, to="openjd", job="job.json", chunk="2"):
    assert _in(folder, ["farm", "--to", to, "-o", job, "--chunk", chunk, "--physcam", PHYSCAM, "--",
                        "defocus", "in.####.exr", *CAMERA, "-o", f"{out}/d.####.exr"]) == 0


def test_openjd_defocus_gives_the_direct_bytes_tracing_the_kernels_once(shot):
    """4 frames through openjd run (kernels: frame 1; frames: 2-3, 4): each EXR byte for byte as physcam
    defocus wrote it; frame 1's task traced the kernels, frames 2-4 traced none (loaded from the shared
    cache); the job run again skips all four, leaving them untouched."""
    folder, want = shot
    _defocus_job(folder, "ojd")
    log = _openjd(folder, "job.json", "frames")
    assert _files(folder / "ojd", skip=("kernels",)) == {k.replace("direct", "ojd"): v for k, v in want.items()}
    traced = {int(n): int(k) for n, k in re.findall(r"frame (\d+): wrote \S+ \((\d+) kernels traced", log)}
    assert set(traced) == {1, 2, 3, 4} and traced[1] > 0 and traced[2] == traced[3] == traced[4] == 0
    stacks = list((folder / "ojd" / "kernels").rglob("*.npz"))  # frame 1's kernels, one stack file (issue 47)
    assert len(stacks) == 1 and sum(len(np.load(stacks[0])[k]) for k in ("nodes", "direct_nodes")) == traced[1]
    mtimes = [p.stat().st_mtime_ns for p in sorted((folder / "ojd").glob("d.*.exr"))]
    again = _openjd(folder, "job.json", "frames")
    assert len(re.findall(r"frame \d: \S+ is there, skipped", again)) == 4
    assert [p.stat().st_mtime_ns for p in sorted((folder / "ojd").glob("d.*.exr"))] == mtimes


def test_a_task_killed_while_tracing_kernels_then_rerun_gives_the_same_bytes(shot):
    """The kernels task (the plain task list's first line) is SIGKILLed once its kernel stack file appears
    (the cache writes one stack per run), before its frame: the job then run through openjd run finishes
    from the kernels there and gives the direct bytes; no temporary file is left in the outputs or the
    kernel cache."""
    folder, want = shot
    _defocus_job(folder, "killed", to="tasks", job="job.txt")
    _defocus_job(folder, "killed", job="killed.json")
    (step, argv), = [t for t in read_task_list((folder / "job.txt").read_text()) if t[0] == "kernels"]
    cache = folder / "killed" / "kernels"
    assert _kill_when(argv, folder, lambda: any(cache.rglob("*.npz")))
    assert not (folder / "killed" / "d.0001.exr").exists()
    _openjd(folder, "killed.json", "frames")
    assert _files(folder / "killed", skip=("kernels",)) == {k.replace("direct", "killed"): v for k, v in want.items()}
    names = [p.name for p in (folder / "killed").rglob("*") if p.is_file()]
    assert all(re.fullmatch(r"d\.000\d\.exr|stack-\d+-[0-9a-f]+\.npz", n) for n in names), names


# ---- characterize ----------------------------------------------------------------------------------
GRID = ["--lens", "dgauss_50mm", "--focus", "1m,inf", "--fstop", "2.8,4", "--fields", "2", "--rays", "1000",
        "--psf-pixels", "8", "--grid", "16", "--resolution", "64x48"]
VOLATILE = ("run_id", "created_utc", "compute_s", "worker")


def _rows(folder: Path) -> dict:
    import pyarrow.parquet as pq

    return {p.name: {k: v for k, v in pq.read_table(p).to_pylist()[0].items() if k not in VOLATILE}
            for p in sorted((folder / "index").rglob("*.parquet"))}


def _usd_text(folder: Path) -> str:
    """The lens's USD file with its run id (the one thing two runs differ in) replaced by RUN."""
    text = (folder / "dgauss_50mm" / "dgauss_50mm.usda").read_text()
    return re.sub(r"run_\d{8}T\d{6}Z_[0-9a-f]{6}", "RUN", text)


def test_openjd_characterize_grid_gives_the_direct_bytes_after_a_kill(tmp_path):
    """1 lens x 2 marks x 2 stops (15 cells) through openjd run in chunks of 3 grid points, after the first cells
    task was SIGKILLed once its first result file was written: every result file (JSON, NPZ, ST-map EXR
    and PNG, fits, manifests) byte for byte as physcam characterize wrote it directly, the same 15 index
    rows (but run id, time, seconds and worker), and the same USD variant (but its run id)."""
    assert _in(tmp_path, ["characterize", *GRID, "-o", "direct", "--workers", "1"]) == 0
    assert _in(tmp_path, ["farm", "--to", "tasks", "-o", "job.txt", "--chunk", "3", "--physcam", PHYSCAM, "--",
                          "characterize", *GRID, "-o", "farm"]) == 0
    text = (tmp_path / "job.txt").read_text()
    run_id = re.search(r"--run-id (\S+)", text).group(1)
    first = next(argv for step, argv in read_task_list(text) if step == "cells")
    lens = tmp_path / "farm" / "dgauss_50mm"
    assert _kill_when(first, tmp_path, lambda: lens.is_dir() and any(p.is_file() for p in lens.rglob("*.json")))
    assert len(_rows(tmp_path / "farm")) < 12  # killed mid-way: points 1-3 hold 5 + 3 + 4 cells
    assert _in(tmp_path, ["farm", "--to", "openjd", "-o", "job.json", "--chunk", "3", "--physcam", PHYSCAM, "--",
                          "characterize", *GRID, "-o", "farm"]) == 0
    job = json.loads((tmp_path / "job.json").read_text())
    job = json.loads(re.sub(r"run_\d{8}T\d{6}Z_[0-9a-f]{6}", run_id, json.dumps(job)))  # the killed job's run
    (tmp_path / "job.json").write_text(json.dumps(job))
    _openjd(tmp_path, "job.json", "usd")
    direct, farm = _files(tmp_path / "direct"), _files(tmp_path / "farm")
    assert sorted(farm) == sorted(direct) and len(direct) == 26
    for name in direct:
        if not name.endswith(".usda"):
            assert farm[name] == direct[name], name
    assert _rows(tmp_path / "farm") == _rows(tmp_path / "direct") and len(_rows(tmp_path / "direct")) == 15
    assert _usd_text(tmp_path / "farm") == _usd_text(tmp_path / "direct")


# ---- calibrate -------------------------------------------------------------------------------------
def test_openjd_calibrate_gives_the_direct_deliverables_and_variant(tmp_path, charuco_photographs):
    """Five ChArUco photographs (OpenCV's projection of a known camera, tests/analysis/_charts.py; the first
    five of the calibration tests' renders, tests/conftest.py's ``charuco_photographs``): the
    calibrate and usd steps through openjd run write the deliverables byte for byte as physcam calibrate
    does (both folders written whole, manifests included) and the same USD variant (but the folder's name);
    run again, both steps find their outputs and skip."""
    cv2 = pytest.importorskip("cv2")

    (tmp_path / "charts").mkdir()
    for k, img in enumerate(charuco_photographs(5)):
        cv2.imwrite(str(tmp_path / "charts" / f"c_{k:02d}.png"), img)
    args = ["charts", "--sensor-width", "12.8", "--sensor-height", "9.6", "--chart", "charuco", "--corners", "24x18",
            "--square", "15mm", "--marker", "11mm", "--dictionary", "DICT_5X5_250", "--focus", "2m", "--bootstrap", "0",
            "--max-residual", "2",
            "--variant", "day_1"]
    assert _in(tmp_path, ["calibrate", *args, "-o", "direct", "--usd", "direct.usda"]) == 0
    assert _in(tmp_path, ["farm", "--to", "openjd", "-o", "job.json", "--physcam", PHYSCAM, "--", "calibrate", *args,
                          "-o", "farm", "--usd", "farm.usda"]) == 0
    _openjd(tmp_path, "job.json", "usd")
    direct, farm = _files(tmp_path / "direct"), _files(tmp_path / "farm")
    assert farm == direct  # the manifest too: both folders are written whole
    assert {"distortion.exr", "undistortion.exr", "calibration.json", "calibration_sheet.png",
            "physcam-manifest.json"} <= set(direct)
    usd = (tmp_path / "farm.usda").read_text()
    assert usd.replace('["farm"]', '["direct"]') == (tmp_path / "direct.usda").read_text()
    log = _openjd(tmp_path, "job.json", "usd")
    assert "written whole already, skipped" in log and "has the variant day_1, skipped" in log

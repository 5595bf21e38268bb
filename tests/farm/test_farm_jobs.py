"""physcam farm's job files, checked by the farm managers' own libraries (issue 48): the Open Job
Description template decoded and instantiated by ``openjd-model`` (its parameter-space iterator, not
physcam, cuts the chunks), the OpenCue specification made by ``pyoutline`` and its frame ranges
expanded by OpenCue's own ``FileSequence``, the plain task list's frames over several chunk sizes;
the grid points of a characterize job; and the refusals. Nothing here runs a task (test_farm_run.py)."""

from __future__ import annotations

import json
import os
import sys
import tempfile
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

sys.path.insert(0, str(Path(__file__).parents[1]))

from _documents import check_document  # noqa: E402

from physcam.cli import main  # noqa: E402
from physcam.errors import InputError  # noqa: E402
from physcam.farm.frames import chunks, parse_frames  # noqa: E402
from physcam.farm.tasklist import read_task_list  # noqa: E402

DEFOCUS = ["defocus", "shot/render.####.exr", "--lens", "dgauss_50mm", "--focus", "2m", "--fstop", "2.8",
           "-o", "dof/dof.####.exr"]
CHARACTERIZE = ["characterize", "--lens", "dgauss_50mm", "--focus", "1m,2m,inf", "--fstop", "2.8,4", "--fields", "2",
                "--rays", "1000", "--psf-pixels", "8", "--grid", "16", "--resolution", "64x48", "-o", "lib"]


def _farm(capsys, folder, to, job, *args):
    """``physcam farm --to TO -o JOB ARGS`` run in ``folder``: (exit code, stdout, stderr)."""
    old = os.getcwd()
    os.chdir(folder)
    try:
        capsys.readouterr()
        rc = main(["farm", "--to", to, "-o", job, *args])
        out, err = capsys.readouterr()
    finally:
        os.chdir(old)
    return rc, out, err


def _task_frames(text):
    """{step: [(first, last), ...]} of a task list's tasks, from each task's own --frames."""
    got = {}
    for step, argv in read_task_list(text):
        assert argv[argv.index("--step") + 1] == step
        got.setdefault(step, []).append(parse_frames(argv[argv.index("--frames") + 1]))
    return got


# ---- frame ranges --------------------------------------------------------------------------------
def test_frame_ranges_read_as_farm_managers_write_them():
    assert parse_frames("1001-1100") == (1001, 1100)
    assert parse_frames("7") == (7, 7)  # OpenJD writes a one-frame chunk so
    assert parse_frames(" 12 - 14 ") == (12, 14)
    for bad in ("1100-1001", "a-b", "", "1-2-3", "-5", "99999999999"):
        with pytest.raises(InputError):
            parse_frames(bad)


@settings(max_examples=60)
@given(first=st.integers(0, 10_000), n=st.integers(1, 400), size=st.integers(1, 500))
def test_chunks_cover_every_frame_once_in_order(first, n, size):
    """A hand property: ceil(n / size) chunks, each `size` frames but the last, every frame once, in order."""
    last = first + n - 1
    c = chunks(first, last, size)
    assert len(c) == -(-n // size)
    frames = [f for a, b in c for f in range(a, b + 1)]
    assert frames == list(range(first, last + 1))
    assert all(b - a + 1 == size for a, b in c[:-1]) and 1 <= c[-1][1] - c[-1][0] + 1 <= size


# ---- the plain task list -------------------------------------------------------------------------
@settings(max_examples=25)
@given(first=st.integers(0, 5000), n=st.integers(1, 120), size=st.integers(1, 40))
def test_task_list_runs_every_frame_exactly_once(first, n, size):
    """``--to tasks`` at several chunk sizes: the first frame alone in the kernels step, then every other
    frame exactly once, in ceil((n - 1) / size) tasks of at most ``size`` frames; each line runs
    ``physcam farm-task`` with the job's own defocus command after ``--``."""
    last = first + n - 1
    with tempfile.TemporaryDirectory() as d:
        old = os.getcwd()
        os.chdir(d)
        try:
            rc = main(["farm", "--to", "tasks", "-o", "job.txt", "--chunk", str(size), "--frames", f"{first}-{last}",
                       "--", *DEFOCUS])
            text = Path("job.txt").read_text()
        finally:
            os.chdir(old)
    assert rc == 0
    got = _task_frames(text)
    assert got["kernels"] == [(first, first)]
    rest = got.get("frames", [])
    assert len(rest) == -(-(n - 1) // size)
    frames = [f for a, b in got["kernels"] + rest for f in range(a, b + 1)]
    assert frames == list(range(first, last + 1))
    assert all(b - a + 1 <= size for a, b in rest)
    for _, argv in read_task_list(text):
        assert argv[:2] == ["physcam", "farm-task"]
        inner = argv[argv.index("--") + 1:]
        assert inner[:len(DEFOCUS)] == DEFOCUS and inner[-2:] == ["--kernel-cache", "dof/kernels"]


def test_task_list_of_a_grid_and_its_json_document(capsys, tmp_path):
    """characterize with 1 lens x 3 marks x 2 stops: grid points 1-6 in chunks of 4 (1-4, 5-6), then the USD step;
    one run id in every task; the --json document validates against its schema."""
    rc, out, err = _farm(capsys, tmp_path, "tasks", "grid.txt", "--chunk", "4", "--json", "--", *CHARACTERIZE)
    assert rc == 0, err
    doc = json.loads(out)
    check_document(doc)
    assert doc["kind"] == "characterize" and doc["frames_are"] == "grid points" and doc["tasks"] == 3
    text = (tmp_path / "grid.txt").read_text()
    assert _task_frames(text) == {"cells": [(1, 4), (5, 6)], "usd": [(1, 1)]}
    runs = {argv[argv.index("--run-id") + 1] for _, argv in read_task_list(text)}
    assert len(runs) == 1 and next(iter(runs)).startswith("run_")
    assert not (tmp_path / "lib").exists()  # checked, nothing made


# ---- Open Job Description ------------------------------------------------------------------------
def _openjd_chunks(template: dict, folder) -> dict:
    """{step name: [(first, last), ...]} as openjd-model instantiates the job and iterates each step's tasks."""
    from openjd.model import StepParameterSpaceIterator, create_job, decode_job_template, preprocess_job_parameters

    decoded = decode_job_template(template=template, supported_extensions=["TASK_CHUNKING"])
    params = preprocess_job_parameters(job_template=decoded, job_parameter_values={}, environment_templates=[],
                                       job_template_dir=Path(folder), current_working_dir=Path(folder))
    job = create_job(job_template=decoded, job_parameter_values=params)
    out = {}
    for step in job.steps:
        ranges = []
        for task in StepParameterSpaceIterator(space=step.parameterSpace):
            ranges.append(parse_frames(task["Frame"].value))
        out[step.name] = ranges
    return out


def test_openjd_template_validates_and_runs_every_frame_once(capsys, tmp_path):
    """100 frames in chunks of at most 8: openjd-model accepts the template (specification 2023-09, task
    chunking) and its iterator gives the first frame alone, then 1002-1100 each exactly once in chunks
    of at most 8; the frames step waits for the kernels step; every task runs physcam farm-task."""
    pytest.importorskip("openjd.model")
    rc, out, err = _farm(capsys, tmp_path, "openjd", "job.json", "--chunk", "8", "--frames", "1001-1100",
                         "--", *DEFOCUS)
    assert rc == 0, err
    template = json.loads((tmp_path / "job.json").read_text())
    got = _openjd_chunks(template, tmp_path)
    assert got["kernels"] == [(1001, 1001)]
    frames = [f for a, b in got["frames"] for f in range(a, b + 1)]
    assert sorted(frames) == list(range(1002, 1101)) and len(frames) == len(set(frames))
    assert max(b - a + 1 for a, b in got["frames"]) <= 8
    steps = {s["name"]: s for s in template["steps"]}
    assert steps["frames"]["dependencies"] == [{"dependsOn": "kernels"}]
    args = steps["frames"]["script"]["actions"]["onRun"]["args"]
    assert args[:6] == ["farm-task", "--step", "frames", "--frames", "{{Task.Param.Frame}}", "--cwd"]
    assert template["parameterDefinitions"][0]["default"] == "."  # the template is in the working folder


def test_openjd_refuses_text_it_would_read_as_an_expression(capsys, tmp_path):
    rc, _, err = _farm(capsys, tmp_path, "openjd", "job.json", "--frames", "1-4", "--", "defocus", "a{{b}}.####.exr",
                       "--lens", "dgauss_50mm", "--focus", "2m", "--fstop", "2.8", "-o", "o.####.exr")
    assert rc == 2 and err.count("\n") == 1 and "expression" in err
    assert not (tmp_path / "job.json").exists()


# ---- OpenCue -------------------------------------------------------------------------------------
def test_opencue_outline_names_every_frame_exactly_once(capsys, tmp_path, monkeypatch):
    """pyoutline's specification of 40 frames in chunks of 6: the kernels layer holds frame 101, the frames
    layer 102-140 with chunk 6 (OpenCue's FileSequence expands the ranges: each frame once), and depends on
    the kernels layer; the commands carry OpenCue's chunk tokens; nothing is left in the user's home
    (pyoutline's session folder)."""
    pytest.importorskip("outline")
    from FileSequence import FrameSet

    monkeypatch.setenv("HOME", str(tmp_path / "home"))

    rc, _, err = _farm(capsys, tmp_path, "opencue", "job.xml", "--chunk", "6", "--frames", "101-140",
                       "--show", "demo", "--shot", "sh010", "--user", "td", "--", *DEFOCUS)
    assert rc == 0, err
    root = ET.fromstring((tmp_path / "job.xml").read_text().split("?>", 1)[1].split(">", 1)[1])
    assert (root.findtext("show"), root.findtext("shot"), root.findtext("user")) == ("demo", "sh010", "td")
    layers = {la.get("name"): la for la in root.iter("layer")}
    assert list(layers) == ["kernels", "frames"]
    frames = []
    for name, la in layers.items():
        frames += list(FrameSet(la.findtext("range")).getAll())
        assert "--frames '#FRAME_START#-#FRAME_END#'" in la.findtext("cmd")
    assert sorted(frames) == list(range(101, 141)) and len(frames) == len(set(frames))
    assert list(FrameSet(layers["kernels"].findtext("range")).getAll()) == [101]
    assert layers["frames"].findtext("chunk") == "6"
    assert not (tmp_path / "home").exists()
    dep = root.find("depends/depend")
    assert (dep.get("type"), dep.findtext("deplayer"), dep.findtext("onlayer")) == ("LAYER_ON_LAYER", "frames",
                                                                                    "kernels")


# ---- characterize: grid points -------------------------------------------------------------------
def test_every_cell_belongs_to_one_grid_point():
    """1 lens, marks 1 m and inf, stops 2.8 and 4, 2 fields: points (1m, 2.8) (1m, 4) (inf, 2.8) (inf, 4) hold
    5, 3, 4 and 3 cells (by hand: the lens cell, a distortion cell per mark at its first stop, an
    illumination cell and 2 PSF cells per point), 15 in all, none twice."""
    pytest.importorskip("distributed")
    from physcam import __version__
    from physcam.characterize import Grid
    from physcam.characterize.run import plan_cells
    from physcam.farm.grid_tasks import grid_points, point_of
    from physcam.lens.library import load_lens

    grid = Grid(focus_mm=(1000.0, float("inf")), fstops=(2.8, 4.0), fields=2).checked()
    plan = plan_cells({"dg": load_lens("dgauss_50mm")}, grid, __version__)
    cells = plan["dg"][2]
    points = grid_points(plan, grid)
    assert points == [("dg", 1000.0, 2.8), ("dg", 1000.0, 4.0), ("dg", float("inf"), 2.8), ("dg", float("inf"), 4.0)]
    counts = [sum(point_of(c, grid) == p for c in cells) for p in points]
    assert counts == [5, 3, 4, 3] and sum(counts) == len(cells) == 15


# ---- refusals: one line, exit 2, nothing written -------------------------------------------------
@pytest.mark.parametrize("args, words", [
    (["--", *DEFOCUS, "--force"], "--force"),
    (["--", *DEFOCUS, "--workers", "2"], "--workers"),
    (["--", "report", "--focal", "50"], "runs physcam defocus, characterize, calibrate"),
    ([], "give the physcam command line"),
    (["--", "defocus", "one.exr", "--lens", "dgauss_50mm", "--focus", "2m", "--fstop", "2.8", "-o", "o.exr"],
     "sequence"),
    (["--", "defocus", "x.####.exr", "--lens", "dgauss_50mm", "--focus", "2m", "-o", "o.####.exr"],
     "the command after --: the following arguments are required: --fstop"),
    (["--frames", "1-3", "--", *CHARACTERIZE], "--frames picks the frames of a defocus job"),
    (["--", *CHARACTERIZE[:-2], "--dry-run", "-o", "lib"], "--dry-run"),
    (["--", "characterize", "--lens", "no_such_lens", "--focus", "1m", "-o", "lib"], "no_such_lens"),
    (["--", *DEFOCUS], "no frames match"),
    (["--frames", "9-3", "--", *DEFOCUS], "frame range"),
    (["--name", "a b", "--frames", "1-3", "--", *DEFOCUS], "job name"),
])
def test_bad_jobs_are_one_line_and_write_nothing(capsys, tmp_path, args, words):
    rc, out, err = _farm(capsys, tmp_path, "tasks", "job.txt", *args)
    assert rc == 2, (out, err)
    lines = [ln for ln in err.splitlines() if not ln.startswith("physcam: note:")]
    assert len(lines) == 1 and lines[0].startswith("physcam: error:") and words in lines[0], err
    assert not (tmp_path / "job.txt").exists()


def test_a_defocus_job_without_dask_names_the_defocus_sequence(capsys, tmp_path, monkeypatch):
    """A new user's `farm --to tasks -- defocus ...` without the dask extra was told that
    "characterizing on Dask (physcam characterize)" needs it (round 8)."""
    for module in ("dask", "distributed", "bokeh", "pyarrow"):
        monkeypatch.setitem(sys.modules, module, None)  # find_spec: not installed
    rc, out, err = _farm(capsys, tmp_path, "tasks", "job.txt", "--frames", "1-3", "--", *DEFOCUS)
    assert rc == 2 and err.count("physcam: error:") == 1, err
    assert "physcam farm -- defocus" in err and "characterize" not in err
    assert "pip install 'physcam[dask]'" in err and not (tmp_path / "job.txt").exists()


def test_a_task_of_another_kind_of_step_is_refused(capsys, tmp_path):
    capsys.readouterr()
    rc = main(["farm-task", "--step", "cells", "--frames", "1", "--cwd", str(tmp_path), "--", *DEFOCUS])
    err = capsys.readouterr().err
    assert rc == 2 and "a defocus job has the steps kernels, frames" in err


def test_farm_task_json_document(capsys, tmp_path):
    """A frames task whose outputs are there skips them (nothing read or traced) and says so in a document
    that validates against its schema."""
    (tmp_path / "dof").mkdir()
    for n in (7, 8):
        (tmp_path / "dof" / f"dof.{n:04d}.exr").write_bytes(b"done")
    capsys.readouterr()
    rc = main(["farm-task", "--step", "frames", "--frames", "7-8", "--cwd", str(tmp_path), "--json", "--", *DEFOCUS])
    out, err = capsys.readouterr()
    assert rc == 0, err
    doc = json.loads(out)
    check_document(doc)
    assert (doc["done"], doc["skipped"], doc["frames"], doc["kernels_traced"]) == ([], [7, 8], [7, 8], [])


def test_a_frame_that_is_not_there_fails_the_task_in_one_line(capsys, tmp_path):
    """A frames task over a frame not rendered yet: exit 2 and one line naming the frame and the file."""
    capsys.readouterr()
    rc = main(["farm-task", "--step", "frames", "--frames", "5", "--cwd", str(tmp_path), "--", *DEFOCUS])
    err = capsys.readouterr().err
    lines = [ln for ln in err.splitlines() if not ln.startswith("physcam: note:")]
    assert rc == 2 and len(lines) == 1, err
    assert lines[0].startswith("physcam: error: frame 5: ") and "render.0005.exr" in lines[0]
    assert not (tmp_path / "dof").exists()

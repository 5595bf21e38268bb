"""Issue 18: characterizing a lens library on Dask. Tiny grids (a few rays, 64-pixel maps) on one
two-worker cluster shared by the module; the numbers inside each result come from physcam's
analyses, tested where they live; here: the grid, the scheduling, resuming, concurrency, USD."""

from __future__ import annotations

import hashlib
import json
import math
import os
import signal
import subprocess
import sys
import threading

import pytest

from physcam.characterize import Grid, characterize, parse_focus_marks, read_index
from physcam.characterize.grid import MAX_CELLS, build_cells, lens_hash
from physcam.errors import ExportError, InputError
from physcam.lens.library import load_lens

INF = math.inf


def tiny(**kw) -> Grid:
    # a full-frame sensor (64 x 43 px keeps its pixels square; the fisheye covers its corners only there)
    base = dict(focus_mm=(1000.0, INF), fstops=(2.8,), fields=2, sensor_mm=(36.0, 24.0), resolution=(64, 43),
                psf_rays=4000, psf_pixels=16, illumination_grid=16, backend="numpy")
    base.update(kw)
    return Grid(**base)


@pytest.fixture(scope="module")
def cluster():
    import logging

    from distributed import LocalCluster

    c = LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=":0",
                     silence_logs=logging.CRITICAL, env={"NUMBA_NUM_THREADS": "1"})
    yield c
    c.close()


def _index_rows(folder):
    return read_index(folder).to_pylist()


def _every_cell_once(folder, grid, lenses=("dgauss_50mm",)):
    """The index holds each cell of the grid exactly once, and each row's file has the row's content hash."""
    from physcam import __version__

    want = set()
    for name in lenses:
        rx = load_lens(name)
        want |= {c.input_hash for c in build_cells(name, lens_hash(rx), grid.checked(), rx.wavelength_nm, __version__)}
    rows = _index_rows(folder)
    hashes = [r["input_hash"] for r in rows]
    assert sorted(hashes) == sorted(want)  # all there, none twice
    for r in rows:
        assert hashlib.sha256((folder / r["file"]).read_bytes()).hexdigest() == r["content_hash"], r["file"]
        assert r["physcam_version"] == __version__
    return rows


def test_focus_marks_are_even_in_dioptres():
    # 0.5 m to infinity in 8 marks: 1/d = 2 (1 - i/7) per metre, worked by hand
    marks = parse_focus_marks("0.5m:inf:8")
    want = [500.0, 3500.0 / 6, 700.0, 875.0, 3500.0 / 3, 1750.0, 3500.0, INF]
    assert marks[-1] == INF
    assert list(marks[:-1]) == pytest.approx(want[:-1], rel=1e-12)
    assert parse_focus_marks("1m,2m,inf") == (1000.0, 2000.0, INF)
    assert parse_focus_marks("1m:2m:3") == pytest.approx((1000.0, 4000.0 / 3, 2000.0))  # 1, 0.75, 0.5 per m


def test_the_grid_defaults_to_the_one_default_sensor_with_square_pixels():
    # Super 35 4-perf is 24.89 x 18.66 mm (0.980 x 0.735 in, Nuke's Film/Super35); 2048 px across it
    # keeps pixels square at 2048 x 18.66 / 24.89 = 1535.39 -> 1535 rows
    g = Grid(focus_mm=(1000.0,), fstops=(2.8,)).checked()
    assert g.sensor_mm == (24.89, 18.66) and g.resolution == (2048, 1535)
    assert Grid(focus_mm=(1000.0,), fstops=(2.8,), sensor_mm=(36.0, 24.0)).checked().resolution == (2048, 1365)
    assert Grid(focus_mm=(1000.0,), fstops=(2.8,), resolution=(512, 341)).checked().resolution == (512, 341)


def test_bad_inputs_give_one_clear_error(tmp_path):
    g = tiny()
    with pytest.raises(InputError, match="empty"):
        characterize(["dgauss_50mm"], tiny(fstops=()), tmp_path / "a")
    with pytest.raises(InputError, match="empty"):
        parse_focus_marks("")
    with pytest.raises(InputError, match="1 to 64"):
        parse_focus_marks("0.5m:inf:100000")
    big = tiny(focus_mm=parse_focus_marks("0.5m:inf:40"), fstops=(2.0, 2.8, 4.0, 5.6, 8.0), fields=20)
    with pytest.raises(InputError, match=r"cells .*--force-large"):
        characterize(["dgauss_50mm"], big, tmp_path / "b")
    assert 40 * 5 * 20 > MAX_CELLS
    with pytest.raises(InputError, match="cannot reach the Dask scheduler"):
        characterize(["dgauss_50mm"], g, tmp_path / "c", scheduler="tcp://127.0.0.1:9", connect_timeout=1.0)
    with pytest.raises(InputError, match="tcp://HOST:PORT"):
        characterize(["dgauss_50mm"], g, tmp_path / "c", scheduler="localhost")
    blocker = tmp_path / "file"
    blocker.write_text("not a folder")
    with pytest.raises(ExportError, match="cannot write into|not a folder"):
        characterize(["dgauss_50mm"], g, blocker / "lib")
    with pytest.raises(InputError, match="closest focus|too close|close"):
        characterize(["dgauss_50mm"], tiny(focus_mm=(10.0,)), tmp_path / "d")
    with pytest.raises(InputError, match="faster than this lens"):
        characterize(["dgauss_50mm"], tiny(fstops=(0.7,)), tmp_path / "d")
    assert not (tmp_path / "a").exists()  # refused before writing anything
    assert not [p for p in (tmp_path / "c").rglob("*")]  # the folder was proven writable, then left empty


def test_cli_refuses_with_one_line(tmp_path, capsys):
    from physcam.cli import main

    for argv in (["characterize", "dgauss_50mm", "--focus", "", "-o", str(tmp_path / "x")],
                 ["characterize", "dgauss_50mm", "--focus", "1m", "--fstop", "", "-o", str(tmp_path / "x")],
                 ["characterize", "dgauss_50mm", "--focus", "1m", "-o", str(tmp_path / "x"), "--scheduler",
                  "tcp://127.0.0.1:9", "--connect-timeout", "1"]):
        assert main(argv) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and err[0].startswith("physcam: error:"), err


@pytest.mark.slow
def test_a_killed_worker_loses_nothing(cluster, tmp_path):
    """A worker is killed (SIGKILL) while it computes a cell; the run still ends with every cell once."""
    from distributed import Client

    grid = tiny(focus_mm=(1000.0, 2000.0, INF), fstops=(2.8, 4.0), kinds=("psf",), psf_rays=100_000)
    killed = []
    with Client(cluster.scheduler_address, set_as_default=False) as spy:
        def kill_a_busy_worker(done, total):
            if killed:
                return
            # a worker executing a cell right now (single-threaded workers: one cell each)
            state = spy.run(lambda dask_worker: (os.getpid(), len(dask_worker.state.executing)))
            busy = [pid for pid, executing in state.values() if executing]
            if busy:
                os.kill(busy[0], signal.SIGKILL)
                killed.append(busy[0])

        s = characterize(["dgauss_50mm"], grid, tmp_path, scheduler=cluster.scheduler_address, usd=False,
                         progress=kill_a_busy_worker)
    assert killed, "no worker was busy to kill"
    assert s.failed == [] and s.computed + s.present == s.cells == 12
    _every_cell_once(tmp_path, grid)


@pytest.mark.slow
def test_an_interrupted_run_resumes_with_the_missing_cells_only(cluster, tmp_path):
    grid = tiny(kinds=("lens", "illumination", "psf"))
    n = 1 + 2 + 4
    first = characterize(["dgauss_50mm"], grid, tmp_path, scheduler=cluster.scheduler_address, limit=3)
    assert (first.computed, first.skipped, first.not_run) == (3, 0, n - 3)
    assert first.usd == [] and not (tmp_path / "dgauss_50mm" / "dgauss_50mm.usda").exists()  # grid not complete
    assert len(_index_rows(tmp_path)) == 3
    second = characterize(["dgauss_50mm"], grid, tmp_path, scheduler=cluster.scheduler_address)
    assert (second.computed, second.skipped, second.not_run) == (n - 3, 3, 0)
    assert {r["run_id"] for r in _every_cell_once(tmp_path, grid)} == {first.run_id, second.run_id}
    assert len(second.usd) == 1  # the grid is complete now: the lens file has its variant
    third = characterize(["dgauss_50mm"], grid, tmp_path, scheduler=cluster.scheduler_address)
    assert (third.computed, third.skipped, third.usd) == (0, n, [])  # nothing new recorded, no new variant


@pytest.mark.slow
def test_two_runs_into_one_folder_compute_each_cell_once(cluster, tmp_path):
    grid = tiny(kinds=("distortion", "psf"))
    results = {}

    def go(name):
        results[name] = characterize(["dgauss_50mm"], grid, tmp_path, scheduler=cluster.scheduler_address)

    threads = [threading.Thread(target=go, args=(k,)) for k in "ab"]
    for t in threads:
        t.start()
    for t in threads:
        t.join(timeout=120)
    a, b = results["a"], results["b"]
    assert a.failed == b.failed == []
    assert a.computed + b.computed == a.cells  # the cell locks: none computed twice
    assert a.computed + a.present + a.skipped == b.computed + b.present + b.skipped == a.cells
    _every_cell_once(tmp_path, grid)
    from physcam.usd.kit import read_characterizations

    usd = read_characterizations(tmp_path / "dgauss_50mm" / "dgauss_50mm.usda")
    assert len([v for v in usd["variants"] if v != "current"]) == 1  # one grid, one variant


PROBE = r"""
import json, sys
from pxr import Usd
stage = Usd.Stage.Open(sys.argv[1])
prim = stage.GetPrimAtPath("/Lens")
vset = prim.GetVariantSets().GetVariantSet("characterization")
out = {"type": str(prim.GetTypeName()), "schema_known": bool(prim.GetPrimTypeInfo().GetSchemaType()),
       "selection": vset.GetVariantSelection(), "names": list(vset.GetVariantNames()),
       "current_is": prim.GetCustomDataByKey("physcam:currentIs"), "values": {}}
for name in out["names"]:
    vset.SetVariantSelection(name)
    out["values"][name] = {
        "dioptres": list(prim.GetAttribute("physcam:characterization:focusDioptres").Get()),
        "pupil": list(prim.GetAttribute("physcam:characterization:entrancePupilDistances").Get()),
        "k1": list(prim.GetAttribute("physcam:characterization:distortionK1").Get()),
        "run": prim.GetAttribute("physcam:characterization:run").Get(),
        "fstop": prim.GetAttribute("lens:main:fStop").Get()}
print(json.dumps(out))
"""


@pytest.mark.slow
def test_lens_file_gains_a_variant_per_run_and_opens_in_plain_usd(cluster, tmp_path):
    from physcam.optics.focusing import technical_planes
    from physcam.usd.kit import read_characterizations
    from physcam.usd.plugin import PLUGIN_DIR

    lens_file = tmp_path / "dgauss_50mm" / "dgauss_50mm.usda"
    g1 = tiny(kinds=("lens", "distortion"))
    r1 = characterize(["dgauss_50mm"], g1, tmp_path, scheduler=cluster.scheduler_address)
    before = read_characterizations(lens_file)["variants"][r1.run_id]
    g2 = tiny(kinds=("lens", "distortion"), focus_mm=(700.0, 1500.0, INF), fstops=(4.0,))
    r2 = characterize(["dgauss_50mm"], g2, tmp_path, scheduler=cluster.scheduler_address)
    after = read_characterizations(lens_file)
    assert after["variants"][r1.run_id] == before  # the earlier variant untouched
    env = {"PATH": os.environ.get("PATH", ""), "PXR_PLUGINPATH_NAME": str(PLUGIN_DIR)}
    p = subprocess.run([sys.executable, "-c", PROBE, str(lens_file)], capture_output=True, text=True, env=env,
                       cwd=tmp_path, timeout=120)
    assert p.returncode == 0, p.stderr
    got = json.loads(p.stdout)
    assert got["type"] == "PhysicalCamera" and got["schema_known"]
    assert sorted(got["names"]) == sorted([r1.run_id, r2.run_id, "current"])
    assert got["selection"] == "current" and got["current_is"] == r2.run_id
    assert got["values"]["current"] == got["values"][r2.run_id]
    assert got["values"][r2.run_id]["dioptres"] == pytest.approx([1000 / 700, 1000 / 1500, 0.0])
    assert got["values"][r1.run_id]["dioptres"] == pytest.approx([1.0, 0.0])
    assert got["values"][r2.run_id]["fstop"] == pytest.approx(4.0) and got["values"][r1.run_id]["fstop"] == \
        pytest.approx(2.8)
    # the pupil positions are the Gaussian engine's, mark by mark (mm in front of the film)
    rx = load_lens("dgauss_50mm")
    want = [technical_planes(rx, m).entrance_pupil_from_film_mm for m in g2.focus_mm]
    assert got["values"][r2.run_id]["pupil"] == pytest.approx(want, rel=1e-12)


@pytest.mark.slow
def test_cli_json_summary_on_an_existing_cluster(cluster, tmp_path, capsys):
    from physcam.cli import main

    argv = ["characterize", "dgauss_50mm", "--focus", "1m:inf:2", "--fstop", "2.8", "--fields", "2", "--kinds",
            "lens,illumination", "--grid", "16", "-o", str(tmp_path), "--scheduler", cluster.scheduler_address,
            "--json", "--no-usd"]
    assert main(argv) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["cells"] == 3 and out["computed"] == 3 and out["complete"] and out["scheduler"]
    assert main(argv + ["--dry-run"]) == 0
    plan = json.loads(capsys.readouterr().out)
    assert plan["dry_run"] and plan["skipped"] == 3 and plan["computed"] == 0


@pytest.mark.slow
def test_a_local_cluster_by_default(tmp_path):
    """No --scheduler: the job starts its own LocalCluster (here one worker) and closes it."""
    s = characterize(["dgauss_50mm"], tiny(kinds=("illumination",)), tmp_path, workers=1, usd=False)
    assert (s.computed, s.workers, s.failed) == (2, 1, [])
    assert s.scheduler.startswith("tcp://127.0.0.1:") and s.dashboard.startswith("http")


def test_a_lens_file_of_dated_variants_gains_a_run_and_keeps_them(tmp_path):
    """add_characterization on a file written by write_lens_file: its date variants stay as they were."""
    from physcam.usd.author import CameraSpec
    from physcam.usd.kit import add_characterization, best_match_pinhole, read_characterizations, write_lens_file

    def dated(file):  # every authored value of /Lens and its children with the dated variant selected
        from pxr import Sdf, Usd

        stage = Usd.Stage.Open(Sdf.Layer.OpenAsAnonymous(str(file)))
        stage.GetPrimAtPath("/Lens").GetVariantSets().GetVariantSet("characterization").SetVariantSelection(
            "d2026_03_01")
        return {str(a.GetPath()): a.Get() for p in stage.Traverse() for a in p.GetAttributes() if a.HasAuthoredValue()}

    f = write_lens_file(tmp_path / "lens.usda", {"2026-03-01": CameraSpec.of(focal_length_mm=24.0, fstop=2.0)})
    before = dated(f)
    assert before["/Lens.lens:main:fStop"] == pytest.approx(2.0)
    spec, _ = best_match_pinhole(load_lens("dgauss_50mm"), focus_mm=2000.0, fstop=2.8, sensor_width_mm=36.0,
                                 sensor_height_mm=24.0)
    add_characterization(f, "run_x", spec, {"focusDioptres": [0.5], "focusLabels": ["2m"], "run": "run_x"})
    got = read_characterizations(f)
    assert got["current_is"] == "run_x" and got["selection"] == "current"
    assert got["variants"]["current"] == got["variants"]["run_x"] == {"focusDioptres": [0.5], "focusLabels": ["2m"],
                                                                        "run": "run_x"}
    assert dated(f) == before  # the dated variant unchanged
    with pytest.raises(ExportError, match="already has"):
        add_characterization(f, "run_x", spec, {"run": "again"})
    with pytest.raises(InputError, match="not 'current'"):
        add_characterization(f, "current", spec, {})


@pytest.mark.slow
def test_a_cell_the_optics_refuse_fails_alone(cluster, tmp_path, capsys):
    """A fisheye has no pinhole ST-map (docs/distortion.md): its distortion cells fail with that reason,
    the other cells finish, the lens gets no USD variant, and the command says so on one line (exit 2)."""
    from physcam.cli import main

    grid = tiny(kinds=("lens", "distortion"))
    s = characterize(["nikkor_fisheye_16mm_f2_8"], grid, tmp_path, scheduler=cluster.scheduler_address)
    # the cells finish in any order on the cluster: one refuses the fisheye's pinhole reach, the other (a
    # focus where no chief ray reaches the frame's corner) says the lens does not cover the sensor
    assert [f["kind"] for f in s.failed] == ["distortion", "distortion"]
    assert any("fisheye" in f["error"] for f in s.failed)
    assert all("fisheye" in f["error"] or "does not cover" in f["error"] for f in s.failed)
    assert s.computed == 1 and s.usd == [] and not (tmp_path / "nikkor_fisheye_16mm_f2_8" /
                                                    "nikkor_fisheye_16mm_f2_8.usda").exists()
    assert [r["kind"] for r in _index_rows(tmp_path)] == ["lens"]  # no failed cell counted as done
    argv = ["characterize", "nikkor_fisheye_16mm_f2_8", "--focus", "1m,inf", "--kinds", "lens,distortion",
            "--resolution", "64x43", "--sensor", "FF", "-o", str(tmp_path), "--scheduler", cluster.scheduler_address,
            "--json"]
    assert main(argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("physcam: error: 2 of 3 cells failed"), err


def test_local_cluster_workers_start_without_dasks_malloc_trim(monkeypatch):
    # Dask's nannies set MALLOC_TRIM_THRESHOLD_=65536 for their workers, which made physcam's PSF
    # cells 2.5x slower; physcam's local cluster leaves it unset (and keeps one numba thread). A
    # nanny copies its settings into this process's environment too: start from a clean one.
    import os

    monkeypatch.delenv("MALLOC_TRIM_THRESHOLD_", raising=False)

    from distributed import Client

    from physcam.characterize.run import local_cluster

    cluster = local_cluster(1)
    try:
        with Client(cluster, set_as_default=False) as client:
            env = next(iter(client.run(lambda: dict(os.environ)).values()))
    finally:
        cluster.close()
    assert "MALLOC_TRIM_THRESHOLD_" not in env
    assert env["NUMBA_NUM_THREADS"] == "1"


def test_light_cells_share_a_task_per_lens():
    """A lens's millisecond cells (breathing and pupils, illumination) are one Dask task, so scheduling
    does not outweigh them; ST-map and PSF cells are a task each (benchmarks/characterize.py)."""
    from physcam.characterize.grid import build_cells
    from physcam.characterize.run import task_groups
    from physcam.lens.library import load_lens

    grid = tiny(kinds=("lens", "illumination", "psf", "distortion")).checked()
    cells = []
    for name in ("dgauss_50mm", "tessar_50mm_f2_8"):
        cells += build_cells(name, name, grid, load_lens(name).wavelength_nm, "0")
    groups = task_groups(cells)
    assert sorted(c.stem + c.lens for g in groups for c in g) == sorted(c.stem + c.lens for c in cells)
    light = [g for g in groups if g[0].kind in ("lens", "illumination")]
    assert len(light) == 2 and all(len({c.lens for c in g}) == 1 for g in light)
    assert all(len(g) == 1 for g in groups if g not in light)


def test_the_index_has_a_zoom_lens_position_in_zoom_columns(tmp_path):
    """A zoom lens characterized at a position (``characterize --zoom``) says where in the index: its encoder
    value and paraxial EFL there, against a ray-transfer (ABCD) product of the lens file's gap table
    written here (tests/export/test_unreal_zoom.py's); a prime's are null. An index row written before the
    columns existed reads back with nulls there, losing nothing."""
    import tomllib
    from importlib import resources

    import pyarrow as pa
    import pyarrow.parquet as pq

    from physcam.characterize.cells import run_cell
    from physcam.lens.formats.physcam_toml import dumps
    from physcam.lens.zoom import prescription_at

    canon = "canon_ef_70_200mm_f2_8_zoom"
    doc = tomllib.loads(resources.files("physcam.data").joinpath("lenses", f"{canon}.toml").read_text(encoding="utf-8"))
    a, b, c, d, n = 1.0, 0.0, 0.0, 1.0, 1.0  # position 2 of 3 (encoder 0.5): refraction and reduced transfer
    gaps = {g["surface"]: g["thickness"][1] for g in doc["zoom"]["gap"]}
    for i, s in enumerate(doc["surface"]):
        n2 = 1.0 if s["medium"] == "air" else float(s["medium"]["nd"])
        r = s.get("radius", 0.0)
        power = 0.0 if s["kind"] in ("flat", "stop") or r == 0 else (n2 - n) / r
        c, d = c - power * a, d - power * b
        n = n2
        if i < len(doc["surface"]) - 1:
            t = float(gaps.get(i, s["thickness"])) / n
            a, b = a + t * c, b + t * d
    grid = tiny(kinds=("lens",), focus_mm=(INF,)).checked()
    rows = {}
    for name, rx in (("zoomed", prescription_at(load_lens(canon), 0.5)), ("prime", load_lens("dgauss_50mm"))):
        (cell,) = build_cells(name, lens_hash(rx), grid, rx.wavelength_nm, "0")
        res = run_cell(dumps(rx), lens_hash(rx), cell, grid, str(tmp_path), "run_test", "0")
        assert res["status"] == "computed", res["error"]
        rows[name] = res["row"]
    assert rows["zoomed"]["zoom_encoder"] == 0.5
    assert rows["zoomed"]["zoom_focal_length_mm"] == pytest.approx(-1.0 / c, rel=1e-9)  # 134.95 mm (patent: 135)
    assert rows["prime"]["zoom_encoder"] is None and rows["prime"]["zoom_focal_length_mm"] is None
    old = tmp_path / "index" / "old" / "lens" / "old.parquet"  # a row from before the zoom columns
    old.parent.mkdir(parents=True)
    legacy = {k: v for k, v in rows["prime"].items() if not k.startswith("zoom_")} | {"lens": "old"}
    pq.write_table(pa.Table.from_pylist([legacy]), old)
    got = {r["lens"]: r for r in read_index(tmp_path).to_pylist()}
    assert got.keys() == {"zoomed", "prime", "old"}
    assert got["old"]["zoom_encoder"] is None and got["old"]["content_hash"] == rows["prime"]["content_hash"]
    assert got["zoomed"]["zoom_focal_length_mm"] == rows["zoomed"]["zoom_focal_length_mm"]

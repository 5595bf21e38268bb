"""``--zoom`` on distortion (ST-maps), dof-table, lens card and characterize (issue 45): a zoom lens at one
position is a prescription, so each command at ``--zoom`` must give what it gives for the single-position
prescription built here from the bundled file's own gap table, and optiland's figures (tests/data)."""

from __future__ import annotations

import json
import math
import tomllib
from importlib import resources
from pathlib import Path

import numpy as np
import pytest

from _documents import check_document
from physcam.cli import main

CANON = "canon_ef_70_200mm_f2_8_zoom"
OPTILAND = json.loads((Path(__file__).parents[1] / "data" / "optiland_zoom.json").read_text())["lenses"]


def _run(capsys, *argv):
    rc = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return rc, out, err


def _single_position_file(tmp_path, k: int) -> Path:
    """The bundled Canon as a plain prescription at tabulated position k: its TOML without the [zoom] table,
    each zoom gap set to the table's k-th thickness (a tabulated position needs no interpolation)."""
    text = resources.files("physcam.data").joinpath("lenses", f"{CANON}.toml").read_text(encoding="utf-8")
    gaps = {g["surface"]: g["thickness"][k] for g in tomllib.loads(text)["zoom"]["gap"]}
    head, _ = text.split("\n[zoom]\n")  # the zoom table closes the file
    doc = head.split("[[surface]]")
    for n in range(1, len(doc)):  # doc[n] is surface n - 1
        if n - 1 in gaps:
            lines = doc[n].splitlines(keepends=True)
            i = next(j for j, ln in enumerate(lines) if ln.startswith("thickness"))
            lines[i] = f"thickness = {gaps[n - 1]!r}\n"
            doc[n] = "".join(lines)
    out = tmp_path / f"canon_position_{k}.toml"
    out.write_text("[[surface]]".join(doc), encoding="utf-8")
    return out


def _exr(path):
    import OpenEXR

    with OpenEXR.File(str(path), separate_channels=True) as f:
        return {c: np.array(f.channels()[c].pixels) for c in ("R", "G")}, dict(f.header())


def test_stmaps_at_a_zoom_position_are_those_of_the_single_position_prescription(tmp_path, capsys):
    single = _single_position_file(tmp_path, 1)
    a, b = tmp_path / "zoomed", tmp_path / "single"
    rc, out, err = _run(capsys, "distortion", "--lens", CANON, "--zoom", "0.5", "--focus", "3m", "--resolution", "40x30",
                        "--stmap", a, "--json")
    assert rc == 0, err
    doc = json.loads(out)
    assert check_document(doc) == "physcam.distortion_field"
    rc, out_single, err = _run(capsys, "distortion", "--lens", single, "--focus", "3m", "--resolution", "40x30",
                               "--stmap", b, "--json")
    assert rc == 0, err
    for name in ("distortion.exr", "undistortion.exr"):
        (za, ha), (zb, _) = _exr(a / name), _exr(b / name)
        for c in ("R", "G"):
            np.testing.assert_array_equal(za[c], zb[c])
        # the map's header names the zoom position: optiland's EFL at position 2 is 134.948 mm
        assert "at 134.9 mm (zoom 0.5)" in str(ha["physcamLens"])
    assert doc["zoom"]["encoder"] == 0.5
    assert doc["zoom"]["efl_mm"] == pytest.approx(OPTILAND[CANON][1]["efl_mm"], rel=1e-3)
    assert doc["pinhole_focal_length_mm"] == json.loads(out_single)["pinhole_focal_length_mm"]


def test_the_field_angle_table_at_a_focal_length(capsys):
    # at infinity the table's pinhole is the EFL (f tan theta): the position asked for, 100 mm
    rc, out, _ = _run(capsys, "distortion", "--lens", CANON, "--zoom", "100mm", "--field", "3", "--json")
    doc = json.loads(out)
    assert rc == 0 and check_document(doc) == "physcam.distortion" and doc["zoom"]["asked"] == "100mm"
    assert doc["efl_y_mm"] == pytest.approx(100.0, rel=1e-6)
    assert doc["points"][0]["paraxial_height_mm"] == pytest.approx(100.0 * math.tan(math.radians(3.0)), rel=1e-6)


def test_distortion_across_focus_at_a_zoom_position(capsys):
    rc, out, err = _run(capsys, "distortion", "--lens", CANON, "--zoom", "100mm", "--resolution", "32x24",
                        "--across-focus", "2m,inf", "--json")
    assert rc == 0, err
    d = json.loads(out)
    assert check_document(d) == "physcam.distortion_across_focus" and d["zoom"]["asked"] == "100mm"
    # at infinity the pinhole is the EFL, the 100 mm asked for; focused at 2 m it is longer (breathing)
    assert d["rows"][1]["pinhole_focal_length_mm"] == pytest.approx(100.0, rel=1e-6)
    assert d["rows"][0]["pinhole_focal_length_mm"] > 100.0


def test_dof_table_at_100mm_is_the_datasheet_computation_of_that_position(capsys):
    from physcam.lens.library import load_lens
    from physcam.lens.zoom import prescription_at
    from physcam.optics.focusing import f_number_ratio, technical_planes
    from physcam.optics.zoom import encoder_for_focal_length

    rc, out, err = _run(capsys, "dof-table", "--lens", CANON, "--zoom", "100mm", "--fstops", "4", "--focus", "3m",
                        "--coc", "0.025", "--json")
    assert rc == 0, err
    d = json.loads(out)
    assert check_document(d) == "physcam.dof_table"
    (row,) = d["rows"]
    # the position's Gaussian data: the lens at 100 mm focused at 3 m (its planes from the film plane)
    canon = load_lens(CANON)
    q = prescription_at(canon, encoder_for_focal_length(canon, 100.0))
    tp = technical_planes(q, 3000.0, fstop=4.0)
    f, n, c = tp.efl_mm, 4.0 * f_number_ratio(q, 3000.0), 0.025
    s = 3000.0 - tp.h1_from_film_mm  # subject from the front principal plane
    h = f * f / (n * c)  # hyperfocal from H1 (the convention of tests/onset/test_report.py)
    assert f == pytest.approx(100.0, rel=1e-9) and row["focal_length_mm"] == pytest.approx(f, rel=1e-9)
    assert row["near_from_film_mm"] == pytest.approx(h * s / (h + s - f) + tp.h1_from_film_mm, rel=1e-6)
    assert row["far_from_film_mm"] == pytest.approx(h * s / (h - s + f) + tp.h1_from_film_mm, rel=1e-6)
    assert "at 100.0 mm" in d["lens"] and d["zoom"]["efl_mm"] == pytest.approx(100.0, rel=1e-9)


def test_lens_card_at_a_zoom_position_has_optilands_numbers(tmp_path, capsys):
    rc, out, err = _run(capsys, "lens", "card", "--lens", "laikin_zoom_15_150mm", "--zoom", "1", "--draft",
                        "--dpi", "30", "-o", tmp_path / "card.png", "--json")
    assert rc == 0, err
    d = json.loads(out)
    assert check_document(d) == "physcam.lens_card"
    ref = OPTILAND["laikin_zoom_15_150mm"][3]
    assert d["key"]["efl_mm"] == pytest.approx(ref["efl_mm"], rel=1e-3)
    assert d["key"]["f_number"] == pytest.approx(ref["f_number"], rel=1e-3)
    assert d["key"]["entrance_pupil_diameter_mm"] == pytest.approx(ref["epd_mm"], rel=1e-3)
    assert d["zoom"]["encoder"] == 1.0 and "at 149.9 mm (zoom 1)" in d["lens"]
    assert (tmp_path / "card.png").read_bytes()[:4] == b"\x89PNG"
    # the zoom page: beside the PNG, every tabulated position at optiland's EFL, f-number and pupil; page 1 at 1
    assert d["pages"] == ["main", "zoom"] and d["files"] == [str(tmp_path / "card.png"), str(tmp_path / "card-zoom.png")]
    assert (tmp_path / "card-zoom.png").read_bytes()[:4] == b"\x89PNG"
    z = d["zoom_page"]
    assert z["card_encoder"] == 1.0 and d["anamorphic_page"] is None
    tab = [r for r in z["positions"] if r["tabulated"]]
    assert len(tab) == 4
    for r, ref in zip(tab, OPTILAND["laikin_zoom_15_150mm"]):
        assert r["efl_mm"] == pytest.approx(ref["efl_mm"], rel=1e-3)
        assert r["f_number"] == pytest.approx(ref["f_number"], rel=1e-3)
        assert r["entrance_pupil_diameter_mm"] == pytest.approx(ref["epd_mm"], rel=1e-3)
    assert [b["encoder"] for b in z["breathing"]] == [r["encoder"] for r in tab]


def test_lens_card_keeps_an_existing_further_page(tmp_path, capsys):
    (tmp_path / "card-zoom.png").write_bytes(b"mine")
    rc, out, err = _run(capsys, "lens", "card", "--lens", CANON, "--draft", "--dpi", "30", "-o", tmp_path / "card.png")
    assert rc == 2 and len(err.strip().splitlines()) == 1 and "card-zoom.png" in err
    assert not (tmp_path / "card.png").exists() and (tmp_path / "card-zoom.png").read_bytes() == b"mine"


def test_characterize_plan_has_a_lens_per_zoom_position(tmp_path, capsys):
    rc, out, err = _run(capsys, "characterize", "--lens", CANON, "--zoom", "100mm,0.5,1", "--focus", "3m,inf", "--fstop", "2.8,4",
                        "--kinds", "lens,illumination", "-o", tmp_path / "lib", "--dry-run", "--json")
    assert rc == 0, err
    d = json.loads(out)
    # 100 mm as asked, then 134.9 / 193.9 mm: optiland's EFLs of positions 2 and 3, in the slugs
    want = [f"{CANON}_zoom_100.0mm"] + [f"{CANON}_zoom_{p['efl_mm']:.1f}mm" for p in OPTILAND[CANON][1:]]
    assert d["lenses"] == want
    # zoom x focus x iris: 3 positions x (1 lens cell + 2 marks x 2 stops of illumination)
    assert d["cells"] == 3 * (1 + 2 * 2)
    assert not (tmp_path / "lib").exists()


@pytest.mark.slow
def test_characterize_over_zoom_on_dask_gives_each_positions_efl(tmp_path, capsys):
    from physcam.characterize import read_index

    out = tmp_path / "lib"
    rc, _, err = _run(capsys, "characterize", "--lens", CANON, "--zoom", "0,1", "--focus", "inf", "--kinds", "lens",
                      "-o", out, "--workers", "1", "--no-usd", "--json")
    assert rc == 0, err
    rows = read_index(out).to_pylist()
    got = {}
    for r in rows:
        cell = json.loads((out / r["file"]).read_text())
        got[r["lens"]] = cell["rows"][0]["efl_mm"]
    want = {f"{CANON}_zoom_{p['efl_mm']:.1f}mm": p["efl_mm"] for p in (OPTILAND[CANON][0], OPTILAND[CANON][2])}
    assert got.keys() == want.keys()
    for k in want:
        assert got[k] == pytest.approx(want[k], rel=1e-3)
    # the index's zoom columns: each position's encoder value and optiland's EFL there
    zoom = {r["lens"]: (r["zoom_encoder"], r["zoom_focal_length_mm"]) for r in rows}
    for u, ref in ((0.0, OPTILAND[CANON][0]), (1.0, OPTILAND[CANON][2])):
        enc, efl = zoom[f"{CANON}_zoom_{ref['efl_mm']:.1f}mm"]
        assert enc == u and efl == pytest.approx(ref["efl_mm"], rel=1e-3)


@pytest.mark.parametrize("argv, words", [
    (("distortion", "--lens", "dgauss_50mm", "--zoom", "0.5"), "not a zoom lens"),
    (("dof-table", "--lens", "dgauss_50mm", "--zoom", "50mm"), "not a zoom lens"),
    (("dof-table", "--focal", "50", "--zoom", "0.5"), "--zoom takes a zoom lens"),
    (("lens", "card", "--lens", "dgauss_50mm", "--zoom", "0.5", "-o", "never.png"), "not a zoom lens"),
    (("characterize", "--lens", "dgauss_50mm", "--zoom", "0.5", "--focus", "inf", "-o", "never", "--dry-run"),
     "not a zoom lens"),
    (("distortion", "--lens", CANON, "--zoom", "300mm"), "outside the zoom range"),
    (("characterize", "--lens", CANON, "--zoom", "0,0", "--focus", "inf", "-o", "never", "--dry-run"), "already given"),
])
def test_a_prime_or_a_bad_position_is_one_line_and_exit_2(capsys, tmp_path, monkeypatch, argv, words):
    monkeypatch.chdir(tmp_path)
    rc, _, err = _run(capsys, *argv)
    assert rc == 2 and err.count("\n") == 1 and words in err and "Traceback" not in err
    assert not any(tmp_path.iterdir())


def test_a_farm_characterize_job_has_a_grid_point_per_zoom_position(capsys, tmp_path, monkeypatch):
    from physcam.farm.frames import parse_frames
    from physcam.farm.tasklist import read_task_list

    monkeypatch.chdir(tmp_path)
    rc, out, err = _run(capsys, "farm", "--to", "tasks", "-o", "grid.txt", "--chunk", "1", "--json", "--",
                        "characterize", "--lens", CANON, "--zoom", "0,1", "--focus", "3m,inf", "--fstop", "2.8",
                        "--kinds", "lens,illumination", "--grid", "16", "-o", "lib")
    assert rc == 0, err
    tasks = read_task_list((tmp_path / "grid.txt").read_text())
    cells = [parse_frames(argv[argv.index("--frames") + 1]) for step, argv in tasks if step == "cells"]
    # 2 zoom positions x 2 focus marks x 1 stop = 4 grid points, one task each; every task keeps --zoom
    assert cells == [(k, k) for k in range(1, 5)]
    assert all(argv[argv.index("--zoom") + 1] == "0,1" for _, argv in tasks)
    assert not (tmp_path / "lib").exists()

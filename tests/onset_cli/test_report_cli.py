"""The report CLI in-process and as a subprocess: flags, units, errors, JSON, plot, demo."""

import json
import os
import subprocess
import sys

import pytest

from physcam.cli import main
from physcam.units import parse_distance


@pytest.mark.parametrize("text, mm", [("3m", 3000.0), ("10ft", 3048.0), ("6in", 152.4), ("450mm", 450.0),
                                      ("450", 450.0), ("2.5 cm", 25.0), ("10'6\"", 3200.4)])
def test_units(text, mm):
    assert parse_distance(text) == pytest.approx(mm)


def test_report_json(capsys):
    assert main(["report", "--focal", "50", "--fstop", "4", "--focus", "10ft", "--sensor-width", "36",
                 "--sensor-height", "24", "--coc", "0.03", "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["focus_from_film_mm"] == pytest.approx(3048.0)
    assert d["coc_mm"] == 0.03
    # the companion is the best-match pinhole: s' of the thin lens at its mark (tests/_thin_lens.py)
    from _thin_lens import image_distance_at_mark

    assert d["cameras"]["usd_geom_camera"]["focalLength"] == pytest.approx(
        image_distance_at_mark(50.0, d["focus_from_film_mm"]))


def test_report_table_and_plot(tmp_path, capsys):
    plot = tmp_path / "dof.png"
    assert main(["report", "--focal", "35", "--fstop", "2.8", "--focus", "3m", "--sensor", "ALEXA 35",
                 "--plot", str(plot)]) == 0
    assert plot.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert "near limit" in capsys.readouterr().out
    # no clobber without --force
    assert main(["report", "--focal", "35", "--fstop", "2.8", "--focus", "3m", "--plot", str(plot)]) == 2
    assert main(["report", "--focal", "35", "--fstop", "2.8", "--focus", "3m", "--plot", str(plot), "--force"]) == 0


@pytest.mark.parametrize("argv", [
    ["report", "--focal", "50", "--fstop", "2", "--focus", "20mm"],
    ["report", "--focal", "50", "--fstop", "-2", "--focus", "3m"],
    ["report", "--focal", "50", "--fstop", "nan", "--focus", "3m"],
    ["report", "--focal", "50", "--fstop", "2", "--focus", "3 parsecs"],
    ["report", "--focal", "50", "--fstop", "2", "--focus", "3m", "--sensor", "ALEXA 53"],
    ["report", "--focal", "50", "--focus", "3m", "--near", "4m"],
    ["report", "--focal", "50", "--fstop", "2", "--focus", "3m", "--model", "technical"],
])
def test_bad_input_one_line_exit_2(argv):
    env = dict(os.environ)
    p = subprocess.run([sys.executable, "-m", "physcam", *argv], capture_output=True, text=True, env=env)
    assert p.returncode == 2, p.stderr
    assert "Traceback" not in p.stderr
    assert len(p.stderr.strip().splitlines()) == 1
    assert p.stderr.startswith("physcam: error:")


def test_version_and_sensors(capsys):
    assert main(["--version"]) == 0
    assert capsys.readouterr().out.startswith("physcam ")
    assert main(["sensors", "--json"]) == 0
    names = [s["name"] for s in json.loads(capsys.readouterr().out)["sensors"]]
    assert "ARRI ALEXA 35 4.6K 3:2 Open Gate" in names


def test_demo_writes_outputs(tmp_path, capsys):
    out = tmp_path / "demo"
    assert main(["demo", "--out", str(out), "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    from _documents import check_document

    assert check_document(doc) == "physcam.demo"
    files = doc["files"]
    for name in ("report.json", "report.txt", "dof.png", "lens.json", "lens_diagram.png", "breathing.png",
                 "camera.usda", "spot.png", "bokeh.png"):
        assert (out / name).exists(), name
    assert (out / "lens_diagram.png").read_bytes()[:4] == b"\x89PNG"
    lens = json.loads((out / "lens.json").read_text())
    assert lens["gaussian"]["efl"] == pytest.approx(50.3582, abs=1e-3)  # published dgauss.50mm EFL
    assert all(os.path.exists(f) for f in files)
    assert json.loads((out / "report.json").read_text())["schema"] == "physcam.lens_report"
    assert "┃" not in (out / "report.txt").read_text()  # the report's plain table, no box (round 8)
    # issue 10: the demo writes the Blender cameras for the default lens
    osl = (out / "blender" / "dgauss_50mm.osl").read_text()
    assert "camera_shader_raster_position" in osl and (out / "blender" / "setup_dgauss_50mm.py").exists()
    assert (out / "blender" / "builtin_dgauss_50mm.py").exists()
    # issue 12: ST-maps of the default lens at 3 m on the ALEXA 35, its fitted models and a Nuke script
    for name in ("distortion.exr", "undistortion.exr", "brown_conrady.json", "3de4_radial_standard_degree_4.txt",
                 "physcam_stmap.nk"):
        assert (out / "distortion" / name).exists(), name
    assert check_document(json.loads((out / "distortion" / "brown_conrady.json").read_text())) == \
        "physcam.distortion_brown_conrady"
    # issue 30: a clip's recorded metadata (the bundled ARRI excerpt: 49 lines, a header and 48 frames) as one
    # animated USD camera with a time sample per frame (tests/metadata checks the values against the file)
    from pxr import Usd

    stage = Usd.Stage.Open(str(out / "clip_camera.usda"))
    cams = [p for p in stage.Traverse() if p.GetTypeName() == "PhysicalCamera"]
    assert len(cams) == 1
    focus = stage.GetPrimAtPath(cams[0].GetPath().AppendChild("Pinhole")).GetAttribute("focusDistance")
    assert len(focus.GetTimeSamples()) == 48 and len(cams[0].GetAttribute("lens:main:fStop").GetTimeSamples()) == 48
    assert main(["demo", "--out", str(out)]) == 2  # exists, no --force


def test_report_json_imports_no_heavy_library():
    # The start-up goal (benchmarks/startup.py, < 0.3 s) rests on `physcam report --json` not
    # importing numpy, matplotlib, rich tables, USD or numba; guard that structurally.
    code = ("import sys, io, contextlib\nfrom physcam.cli import main\n"
            "with contextlib.redirect_stdout(io.StringIO()):\n"
            "    main(['report', '--focal', '50', '--fstop', '2.8', '--focus', '3m', '--json'])\n"
            "heavy = [m for m in ('numpy', 'matplotlib', 'pxr', 'numba', 'rich.table') if m in sys.modules]\n"
            "print(','.join(heavy))")
    p = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert p.stdout.strip() == ""


def test_fisheye_camera_blocks_say_which_field_they_show(capsys, tmp_path):
    """Issue 8.2: the camera blocks and the USD companion carry the real-ray field and a note."""
    from pxr import Usd

    assert main(["report", "--lens", "nikkor_fisheye_16mm_f2_8", "--focus", "3m", "--sensor", "FF", "--json"]) == 0
    captured = capsys.readouterr()
    assert "physcam: warning: real chief rays give 140" in captured.err
    cams = json.loads(captured.out)["cameras"]
    assert cams["fov_deg"]["real"]["horizontal"] == pytest.approx(140.0, abs=0.5)
    assert cams["notes"] and "pinholes" in cams["notes"][0]
    f = tmp_path / "fisheye.usda"
    assert main(["usd", "write", str(f), "--lens", "nikkor_fisheye_16mm_f2_8", "--focus", "3m", "--sensor", "FF"]) == 0
    stage = Usd.Stage.Open(str(f))
    fov = stage.GetPrimAtPath("/Cameras/Camera/Camera").GetCustomDataByKey("physcam:fieldOfView")
    assert fov["realChiefRaysDeg"][0] == pytest.approx(140.0, abs=0.5) and fov["realDiffers"]


def test_the_demos_report_txt_is_the_reports_plain_table(tmp_path, capsys):
    """The demo's report.txt was a rich table captured at 80 columns: a box drawn into the file and the
    lens name, notes and pinhole row folded over lines (round 8, a new user's `physcam demo`). Oracle:
    the text `physcam report` prints, piped, for the demo's lens, stop, focus and sensor.
    (test_demo_writes_outputs writes the file itself.)"""
    from physcam.cli.demo import DEFAULTS, _args, report_text
    from physcam.cli.report import solve_from_args

    table, notes = report_text(solve_from_args(_args()))
    assert main(["report", "--lens", DEFAULTS["lens"], "--fstop", str(DEFAULTS["fstop"]),
                 "--focus", f"{DEFAULTS['focus']}mm", "--sensor", DEFAULTS["sensor"]]) == 0
    printed = capsys.readouterr().out
    written = table.plain() + notes
    assert written == printed
    assert "┃" not in written and "Double Gauss 50mm f/2 (pbrt dgauss.50mm)" in written

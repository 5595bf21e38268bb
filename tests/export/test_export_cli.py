"""`physcam export unreal|opencv`, run in-process."""

from __future__ import annotations

import json

import pytest

from physcam.cli import main
from physcam.export.opencv_distortion import fit_opencv_pinhole
from physcam.lens.library import load_lens
from physcam.optics.sensors import find_sensor


def run(capsys, *argv):
    rc = main(list(argv))
    out, err = capsys.readouterr()
    return rc, out, err


def test_opencv_json_and_table(capsys):
    rc, out, _ = run(capsys, "export", "opencv", "dgauss_50mm", "--sensor", "FF", "--width-px", "4096", "--height-px",
                     "2731", "--json")
    assert rc == 0
    d = json.loads(out)
    cam = fit_opencv_pinhole(load_lens("dgauss_50mm"), 36.0, 24.0, 4096, 2731)
    assert d["fx"] == pytest.approx(cam.fx) and d["k1"] == pytest.approx(cam.k1)
    assert d["omniverse"]["attributes"]["omni:lensdistortion:opencvPinhole:imageSize"] == [4096, 2731]
    rc, out, _ = run(capsys, "export", "opencv", "dgauss_50mm", "--sensor", "ALEXA 35", "--width-px", "4608",
                     "--height-px", "3164", "--focus", "2m")
    assert rc == 0 and "fx" in out and "OmniLensDistortionOpenCvPinholeAPI" in out


def test_unreal_writes_a_lens_file(capsys, tmp_path):
    out_path = tmp_path / "lens.ulens"
    argv = ["export", "unreal", "dgauss_50mm", "-o", str(out_path), "--sensor", "ALEXA 35", "--width-px", "4608",
            "--height-px", "3164", "--focus", "inf", "--focus", "2m"]
    rc, out, _ = run(capsys, *argv)
    assert rc == 0 and "wrote" in out
    d = json.loads(out_path.read_text())
    s = find_sensor("ALEXA 35")
    assert d["sensorDimensions"]["width"] == s.width_mm
    assert [m["focus_from_film_mm"] for m in d["physcam"]["marks"]] == [None, 2000.0]
    rc, _, err = run(capsys, *argv)  # exists: refused, one line
    assert rc == 2 and err.startswith("physcam: error:") and err.count("\n") == 1
    rc, out, _ = run(capsys, *argv, "--force", "--json")
    doc = json.loads(out)
    assert rc == 0 and doc["schema"] == "physcam.export_unreal" and doc["lens_file"]["metadata"]["type"] == "LensFile"


@pytest.mark.parametrize("extra", [["--width-px", "0", "--height-px", "100"],
                                   ["--width-px", "100", "--height-px", "100", "--sensor-width", "36"],
                                   ["--width-px", "100", "--height-px", "100", "--focus", "1mm"]])
def test_refusals_are_one_line(capsys, extra):
    rc, _, err = run(capsys, "export", "opencv", "dgauss_50mm", *extra)
    assert rc == 2 and err.startswith("physcam: error:") and err.count("\n") == 1

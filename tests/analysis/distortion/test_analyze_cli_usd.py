"""The analysis commands and the lensDistortion hook in the USD cameras."""

import json

import numpy as np
import pytest

from _forward_chief import ideal_grid_and_real
from physcam.analysis.distortion.field import real_distortion
from physcam.cli import main
from physcam.errors import ExportError
from physcam.lens.library import load_lens


@pytest.mark.parametrize("argv", [
    ["distortion", "dgauss.50mm", "--field", "0", "--field", "5", "--field", "10"],
    ["illumination", "dgauss.50mm", "--field", "0", "--field", "10", "--grid", "40", "--fstop", "4"],
    ["colour", "tessar_50mm_f2_8", "--field", "0", "--field", "8", "--wavelength", "450"],
    ["breathing-real", "dgauss.50mm", "--focus", "inf", "--focus", "1m"],
    ["ghosts", "dgauss.50mm", "--field", "5", "--top", "3"],
])
def test_commands_print_json_and_tables(argv, capsys):
    assert main(argv + ["--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["lens"]
    assert main(argv) == 0
    assert capsys.readouterr().out.strip()


def test_plots_are_written_once(tmp_path, capsys):
    out = tmp_path / "d.png"
    assert main(["distortion", "dgauss.50mm", "-o", str(out)]) == 0
    assert out.read_bytes()[:4] == b"\x89PNG"
    assert main(["distortion", "dgauss.50mm", "-o", str(out)]) == 2
    assert "already exists" in capsys.readouterr().err
    for cmd, extra in (("illumination", ["--grid", "32", "--max-field", "10"]), ("colour", ["--max-field", "10"]),
                       ("breathing-real", ["--focus", "inf", "--focus", "2m"]),
                       ("ghosts", ["--rays", "2000", "--pixels", "32"])):
        p = tmp_path / f"{cmd}.png"
        assert main([cmd, "dgauss.50mm", "-o", str(p)] + extra) == 0
        assert p.read_bytes()[:4] == b"\x89PNG"


def test_bad_input_is_one_line(capsys):
    assert main(["distortion", "dgauss.50mm", "--field", "60"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("physcam: error:") and err.count("\n") == 1


def test_usd_camera_carries_the_fitted_distortion(tmp_path, capsys):
    from pxr import Usd

    out = tmp_path / "cam.usda"
    assert main(["usd", "write", str(out), "--lens", "dgauss.50mm", "--fstop", "2.8", "--focus", "2m",
                 "--sensor-width", "36", "--sensor-height", "24"]) == 0
    stage = Usd.Stage.Open(str(out))
    cam = stage.GetPrimAtPath("/Cameras/Camera/Camera")
    assert cam.GetAttribute("lensDistortion:type").Get() == "standard"
    assert tuple(cam.GetAttribute("lensDistortion:center").Get()) == (0.0, 0.0)
    k1 = cam.GetAttribute("lensDistortion:k1").Get()
    k2 = cam.GetAttribute("lensDistortion:k2").Get()
    # fitted at the shot's focus (2 m): the written model takes ideal pinhole pixels to where the real
    # chief rays, traced forward from the 2 m plane (the oracle), land, within 0.05 px at 2048 px
    size = (2048, 1365)
    ideal, real = ideal_grid_and_real(load_lens("dgauss.50mm"), 2000.0, (36.0, 24.0), size)
    scale, centre = np.array([size[0] / 36.0, size[1] / 24.0]), np.array(size) / 2.0
    u = (ideal - centre) / scale
    rho2 = np.sum(u * u, axis=1) / 18.0 ** 2
    predicted = u * (1 + k1 * rho2 + k2 * rho2 ** 2)[:, None] * scale + centre
    assert np.hypot(*(predicted - real).T).max() < 0.05
    assert np.hypot(*(real - ideal).T).max() > 3.0  # the lens does distort
    # and not the infinity fit any more
    assert k1 != pytest.approx(real_distortion(load_lens("dgauss.50mm"), sensor_width_mm=36.0,
                                               sensor_height_mm=24.0).fit.k1, rel=1e-3)


def test_vendor_lens_file_and_bad_values(tmp_path):
    from pxr import Usd

    from physcam.usd.author import CameraSpec, new_stage, author_camera
    from physcam.usd.kit import write_body_file, write_shot, write_vendor_lens

    # the vendor file holds the lens only; a shot with a body carries the fitted distortion
    path = write_vendor_lens(tmp_path / "v.usda", load_lens("dgauss.50mm"), focus_mm=3000.0, fstop=2.8)
    body = write_body_file(tmp_path / "b.usda", CameraSpec())
    shot = write_shot(tmp_path / "s.usda", body, path)
    stage = Usd.Stage.Open(str(shot))
    cams = [p for p in stage.Traverse() if p.GetTypeName() == "Camera"]
    assert cams and cams[0].GetAttribute("lensDistortion:k1").Get() < 0  # barrel
    with pytest.raises(ExportError):
        author_camera(new_stage(), "/C", CameraSpec(), lens_distortion={"lensDistortion:k3": 0.1})
    with pytest.raises(ExportError):
        author_camera(new_stage(), "/C", CameraSpec(), lens_distortion={"lensDistortion:k1": float("nan")})

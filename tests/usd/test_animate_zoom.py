"""A zoom animated over time on the PhysicalCamera and its UsdGeomCamera (issue 45 phase 2).

The Nikon AF-S 70-200mm f/2.8E zooms from 70 to 200 mm while focus is pulled: each time sample's
f-number (wide open) is optiland's at that tabulated position (tests/data/optiland_zoom.json: the stop
is tabulated, so the f-number ramps 2.83, 2.88, 2.86), and the EFL, pinhole and entrance pupil are
physcam's paraxial optics at that zoom and focus computed here through the optics layer only. The
stage passes usd-core's validators, and reading it back (pxr, and physcam's own reader of recorded
cameras) gives what was written.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from pxr import Usd, UsdGeom

from physcam.cli import main
from physcam.lens.library import load_lens
from physcam.lens.zoom import prescription_at
from physcam.optics.focusing import technical_planes
from physcam.optics.zoom import encoder_for_focal_length
from physcam.usd.read import open_stage
from physcam.usd.validate import validation_errors

NIKON = "nikon_af_s_70_200mm_f2_8e_zoom"
ORACLE = json.loads((Path(__file__).resolve().parents[1] / "data" / "optiland_zoom.json").read_text())


def test_a_zoom_and_focus_pull_is_time_sampled_on_both_cameras(tmp_path):
    lens = load_lens(NIKON)
    marks = tmp_path / "pull.csv"
    # the three tabulated positions (encoders 0, 0.5, 1), then 100 mm between them given as a focal length
    marks.write_text("frame,focus,zoom\n1,2m,0\n2,3m,0.5\n3,5m,1\n4,5m,100mm\n")
    out = tmp_path / "zoom.usda"
    assert main(["usd", "animate", str(out), "--lens", NIKON, "--marks", str(marks), "--sensor", "Super 35"]) == 0
    stage = open_stage(out)
    assert validation_errors(stage) == []
    cam = stage.GetPrimAtPath("/Cameras/Camera")
    geom = UsdGeom.Camera(stage.GetPrimAtPath("/Cameras/Camera/Camera"))
    model = stage.GetPrimAtPath("/Cameras/Camera/Pinhole")
    u100 = encoder_for_focal_length(lens, 100.0)
    oracle = ORACLE["lenses"][NIKON]
    for frame, mark, u in ((1, 2000.0, 0.0), (2, 3000.0, 0.5), (3, 5000.0, 1.0), (4, 5000.0, u100)):
        t = Usd.TimeCode(frame)
        tp = technical_planes(prescription_at(lens, u), mark)
        assert cam.GetAttribute("physcam:zoomEncoder").Get(t) == pytest.approx(u, abs=1e-12)
        assert model.GetAttribute("focalLength").Get(t) == pytest.approx(tp.efl_mm, rel=1e-6)  # float32
        assert geom.GetFocalLengthAttr().Get(t) == pytest.approx(tp.pinhole_focal_length_mm, rel=3e-6)
        assert cam.GetAttribute("lens:main:entrancePupilDistance").Get(t) == pytest.approx(
            tp.entrance_pupil_from_film_mm, rel=1e-6)
        if frame <= 3:  # wide open at a tabulated position: optiland's f-number there (the engraving is 2.8)
            assert cam.GetAttribute("lens:main:fStop").Get(t) == pytest.approx(oracle[frame - 1]["f_number"], rel=1e-3)
    fstops = [cam.GetAttribute("lens:main:fStop").Get(Usd.TimeCode(f)) for f in (1, 2, 3)]
    assert fstops[0] < fstops[1] > fstops[2]  # the ramp: slowest in the middle of the zoom
    assert geom.GetFocalLengthAttr().GetNumTimeSamples() == 4


def test_physcams_reader_gets_back_the_zoomed_pinhole_and_pupil(tmp_path):
    """live.usd_io reads a time-sampled PhysicalCamera (what `live play` sends): the written values."""
    from physcam.live.usd_io import frames_from_usd

    lens = load_lens(NIKON)
    marks = tmp_path / "pull.csv"
    marks.write_text("frame,focus\n1,2m\n2,4m\n")
    out = tmp_path / "zoom.usda"
    assert main(["usd", "animate", str(out), "--lens", NIKON, "--marks", str(marks), "--sensor", "Super 35",
                 "--zoom", "135mm", "--fstop", "4"]) == 0
    u = encoder_for_focal_length(lens, 135.0)
    frames = frames_from_usd(out)
    assert len(frames) == 2
    for f, mark in zip(frames, (2000.0, 4000.0)):
        tp = technical_planes(prescription_at(lens, u), mark)
        assert f.pinhole_focal_length_mm == pytest.approx(tp.pinhole_focal_length_mm, rel=1e-6)
        assert f.entrance_pupil_mm == pytest.approx(tp.entrance_pupil_from_film_mm, rel=1e-6)
        assert f.fstop == pytest.approx(4.0)


def test_each_frames_iris_is_the_reports_entrance_pupil_at_that_focus(tmp_path, capsys):
    """An internal-focus zoom's iris set to f/2.8 is f/2.74 at 100 mm and 2.5 m (docs/lens-report.md, "The iris
    and the f-stop at a focus"): each frame's lens ``iris`` is the entrance pupil there, `physcam report`'s
    ``aperture_diameter_mm`` for that zoom, focus and f-stop, as `usd write` stores it, not EFL / 2.8."""
    marks = tmp_path / "pull.csv"
    frames = ((1, "2.5m", "2.8", "100mm"), (2, "5m", "5.6", "190mm"))
    marks.write_text("frame,focus,fstop,zoom\n" + "".join(",".join(map(str, f)) + "\n" for f in frames))
    out = tmp_path / "zoom.usda"
    assert main(["usd", "animate", str(out), "--lens", NIKON, "--marks", str(marks), "--sensor", "ALEXA 35"]) == 0
    stage = open_stage(out)
    cam = stage.GetPrimAtPath("/Cameras/Camera")
    for frame, focus, n, zoom in frames:
        capsys.readouterr()
        assert main(["report", "--lens", NIKON, "--zoom", zoom, "--focus", focus, "--fstop", n,
                     "--sensor", "ALEXA 35", "--json"]) == 0
        report = json.loads(capsys.readouterr().out)
        assert report["fstop_at_focus"] != pytest.approx(float(n), rel=5e-3)  # the case: the f-number moved
        for name in ("lens:main:iris", "iris"):
            assert cam.GetAttribute(name).Get(Usd.TimeCode(frame)) == pytest.approx(
                report["aperture_diameter_mm"], rel=1e-6), (frame, name)


def test_a_zoom_column_on_a_prime_is_refused(tmp_path, capsys):
    marks = tmp_path / "pull.csv"
    marks.write_text("frame,focus,zoom\n1,2m,50mm\n")
    assert main(["usd", "animate", str(tmp_path / "x.usda"), "--lens", "dgauss_50mm", "--marks", str(marks),
                 "--sensor", "FF"]) == 2
    assert "needs a zoom lens" in capsys.readouterr().err
    assert not (tmp_path / "x.usda").exists()

"""`physcam usd refresh` of a camera written from a real lens follows the PhysicalCamera's edited values (a user
review, round 8: a layout artist set `lens:main:fStop` of a `usd write --lens dgauss_50mm` camera from 2.8 to 4;
the refresh changed the companion's T-stop only, and its `fStop` and the lens's `iris` (the entrance pupil) stayed
those of f/2.8: the stale iris read back as an internal-focus lens's f-number at the focus, so renders through
the UsdGeomCamera kept the f/2.8 blur; a focus edit kept the 3 m pinhole and pupil, a sensor edit the 3 m
distortion fit of the old sensor).

Expected values are worked independently of physcam's report and focusing: the f/N entrance pupil is the EFL
over N (by hand, and physcam's paraxial pupil solve at that stop); the lens at another mark is the whole
dgauss.50mm (unit focusing) moved by Newton's x' = f^2 / x, from its Gaussian cardinal points at infinity."""

import json
import math
import shutil

import pytest

from physcam.cli import main
from physcam.lens.library import load_lens
from physcam.optics.paraxial import gaussian
from physcam.usd.read import open_stage
from physcam.usd.validate import validation_errors

from pxr import Usd  # noqa: E402

CAM, GEOM = "/Cameras/Camera", "/Cameras/Camera/Camera"
WRITE = ["--lens", "dgauss_50mm", "--fstop", "2.8", "--focus", "3m", "--sensor", "ALEXA 35"]


@pytest.fixture(scope="module")
def written(tmp_path_factory):
    cam = tmp_path_factory.mktemp("lens") / "cam.usda"
    assert main(["usd", "write", str(cam), *WRITE]) == 0
    return cam


def _edited(written, tmp_path, prim, name, value):
    cam = tmp_path / "cam.usda"
    shutil.copy(written, cam)
    stage = Usd.Stage.Open(str(cam))
    stage.GetPrimAtPath(prim).GetAttribute(name).Set(value)
    stage.GetRootLayer().Save()
    return cam


def _refresh(cam, capsys) -> dict:
    capsys.readouterr()
    assert main(["usd", "check", str(cam)]) == 1  # the edit made the companion stale
    capsys.readouterr()
    assert main(["usd", "refresh", str(cam), "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["written"] is True and doc["stale"] is False
    assert not validation_errors(open_stage(cam))
    assert main(["usd", "refresh", str(cam)]) == 0 and "not rewritten" in capsys.readouterr().out
    return {c["attribute"]: (c["before"], c["after"]) for c in doc["changed"]}


def _value(cam, prim, name):
    stage = Usd.Stage.Open(str(cam))
    v = stage.GetPrimAtPath(prim).GetAttribute(name).Get()
    return tuple(float(x) for x in v) if hasattr(v, "__len__") else float(v)


def _lens_at_mark(mark_mm):
    """(entrance pupil from the film, best-match pinhole) of dgauss.50mm focused at ``mark_mm`` from the film,
    from its cardinal points at infinity: the lens moves out by x' = f^2 / x, x the object's distance from F,
    with x + (F to F') + x' the mark; the pinhole is (exit pupil to film) / pupil magnification."""
    g = gaussian(load_lens("dgauss_50mm"))
    f = g.efl
    d = mark_mm - (g.z_rear_focal_point - g.z_front_focal_point)
    x = (d + math.sqrt(d * d - 4.0 * f * f)) / 2.0
    z_film = g.z_rear_focal_point + f * f / x
    return z_film - g.z_entrance_pupil, (z_film - g.z_exit_pupil) / g.pupil_magnification


def test_an_edited_fstop_reaches_the_companion_and_the_iris(written, tmp_path, capsys):
    cam = _edited(written, tmp_path, CAM, "lens:main:fStop", 4.0)
    changed = _refresh(cam, capsys)
    assert set(changed) == {f"{CAM}.lens:main:iris", f"{GEOM}.fStop", f"{GEOM}.exposure:fStop"}
    efl = 50.358167  # dgauss.50mm's EFL (pbrt's prescription scaled to 50 mm is 50.358 mm)
    pupil = gaussian(load_lens("dgauss_50mm"), fstop=4.0).entrance_pupil_diameter
    assert pupil == pytest.approx(efl / 4.0, rel=1e-7)  # the entrance pupil at f/4, by hand: 12.5895 mm
    assert _value(cam, CAM, "lens:main:iris") == pytest.approx(efl / 4.0, rel=1e-6)
    assert changed[f"{CAM}.lens:main:iris"][0] == pytest.approx(efl / 2.8, rel=1e-6)
    assert _value(cam, GEOM, "exposure:fStop") == pytest.approx(4.0)  # transmittance 1: T = N
    # the companion's blur: its focal length (unchanged, the best-match pinhole at 3 m, in mm at 1 cm per unit)
    # over its fStop is the f/4 entrance pupil
    focal = _value(cam, GEOM, "focalLength")
    assert focal == pytest.approx(_lens_at_mark(3000.0)[1], rel=1e-6)
    assert focal / _value(cam, GEOM, "fStop") == pytest.approx(efl / 4.0, rel=1e-6)
    stage = Usd.Stage.Open(str(cam))
    gap = stage.GetPrimAtPath(GEOM).GetCustomDataByKey("physcam:thinLensGap")
    assert gap["fstop"] == pytest.approx(4.0)  # usd write's thin-lens account, at the stop now authored


def test_an_edited_focus_moves_the_pupil_and_the_pinhole(written, tmp_path, capsys):
    cam = _edited(written, tmp_path, f"{CAM}/Pinhole", "focusDistance", 1500.0)
    changed = _refresh(cam, capsys)
    pupil_3m, _ = _lens_at_mark(3000.0)
    pupil, pinhole = _lens_at_mark(1500.0)
    assert pinhole == pytest.approx(52.048, abs=1e-3)  # docs/usd.md: the breathing 50 mm at 1.5 m
    assert _value(cam, CAM, "lens:main:entrancePupilDistance") == pytest.approx(pupil, abs=2e-5)
    assert _value(cam, GEOM, "focalLength") == pytest.approx(pinhole, rel=2e-6)
    assert _value(cam, GEOM, "focusDistance") == pytest.approx((1500.0 - pupil) / 10.0, rel=1e-6)  # cm from the eye
    assert _value(cam, GEOM, "xformOp:translate")[2] == pytest.approx(-pupil / 10.0, rel=1e-6)
    assert _value(cam, GEOM, "focalLength") / _value(cam, GEOM, "fStop") == pytest.approx(50.358167 / 2.8, rel=1e-6)
    # the whole lens moved out by the change of x': its stop and principal planes with it
    for name in ("apertureDistance", "frontPrincipalPlaneDistance", "rearPrincipalPlaneDistance"):
        before, after = changed[f"{CAM}.lens:main:{name}"]
        assert after - before == pytest.approx(pupil - pupil_3m, abs=3e-5), name
    assert {f"{GEOM}.lensDistortion:k1", f"{GEOM}.focalLength", f"{GEOM}.fStop"} <= set(changed)


def test_an_edited_sensor_refits_the_distortion(written, tmp_path, capsys):
    """The full frame (36 x 24 mm) for the ALEXA 35's 27.99 x 19.22: the companion's apertures follow at the
    same pinhole, and the radial fit, normalised to the frame, is refitted over the larger field."""
    from pxr import Gf

    cam = _edited(written, tmp_path, CAM, "sensor:main:aperture", Gf.Vec2f(36.0, 24.0))
    changed = _refresh(cam, capsys)
    pinhole = _lens_at_mark(3000.0)[1]
    focal = _value(cam, GEOM, "focalLength")  # the float32 triple of that view (fov_preserving_float32)
    assert focal == pytest.approx(pinhole, rel=2e-6)
    assert _value(cam, GEOM, "horizontalAperture") / focal == pytest.approx(36.0 / pinhole, rel=1e-6)
    assert _value(cam, GEOM, "verticalAperture") / focal == pytest.approx(24.0 / pinhole, rel=1e-6)
    before, after = changed[f"{GEOM}.lensDistortion:k1"]
    assert after < before < 0.0  # barrel distortion, more of it towards the corners of a larger frame


def test_a_zoom_camera_carries_and_fits_the_lens_at_its_zoom(tmp_path, capsys):
    """`usd write --zoom 135mm` keeps the lens at 135 mm (its EFL, from the paraxial solve of the zoom at that
    position) and fits the distortion there; before, it fitted the zoom's first position (70 mm: k1 0.00086 for
    0.0115 at 135 mm). A refresh of the current camera changes nothing."""
    from physcam.lens.zoom import prescription_at
    from physcam.optics.zoom import zoom_encoder
    from physcam.usd.read import composed_prescription

    cam = tmp_path / "zoom.usda"
    args = ["--lens", "nikon_af_s_70_200mm_f2_8e_zoom", "--zoom", "135mm", "--fstop", "4", "--focus", "5m",
            "--sensor", "ALEXA 35"]
    assert main(["usd", "write", str(cam), *args]) == 0
    zoom = load_lens("nikon_af_s_70_200mm_f2_8e_zoom")
    at = prescription_at(zoom, zoom_encoder(zoom, "135mm"))
    stage = open_stage(cam)
    assert gaussian(composed_prescription(stage, CAM)).efl == pytest.approx(135.0, rel=1e-6)
    from physcam.usd.kit import prescription_distortion

    fit = prescription_distortion(at, 27.99, 19.22, focus_mm=5000.0).coefficients["k1"]
    assert _value(cam, GEOM, "lensDistortion:k1") == pytest.approx(fit, rel=1e-5)
    written = cam.read_bytes()
    capsys.readouterr()
    assert main(["usd", "refresh", str(cam)]) == 0 and cam.read_bytes() == written

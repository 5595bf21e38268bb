"""``physcam usd``: write/read/kit through the real CLI entry point (in-process)."""

import json
import re

import pytest

from physcam.cli import main


def test_write_read_force(tmp_path, capsys):
    f = tmp_path / "a.usda"
    assert main(["usd", "write", str(f), "--focal", "50", "--fstop", "2.8", "--focus", "3m",
                 "--sensor-width", "36", "--sensor-height", "24", "--meters-per-unit", "1"]) == 0
    assert main(["usd", "write", str(f), "--focal", "85", "--fstop", "2.8", "--focus", "3m"]) == 2
    assert "already exists" in capsys.readouterr().err
    capsys.readouterr()
    assert main(["usd", "read", str(f), "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["usd"]["camera"]["focal_length_mm"] == 50.0
    assert data["report"]["focal_length_mm"] == 50.0
    # the pinhole model keeps the lens's 50 mm; the UsdGeomCamera holds the best-match pinhole, s' of
    # the thin lens at the 3 m mark, in tenths of a metre
    from _thin_lens import image_distance_at_mark

    focals = sorted(float(v) for v in re.findall(r"float focalLength = ([0-9.e-]+)", f.read_text()))
    assert abs(focals[0] - image_distance_at_mark(50.0, 3000.0) / 100.0) < 2e-6 and focals[1] == 50.0


def test_kit_and_foreign_file(tmp_path, capsys):
    k = tmp_path / "kit.usda"
    assert main(["usd", "kit", "previs", str(k)]) == 0
    foreign = tmp_path / "x.usda"
    foreign.write_text('#usda 1.0\ndef Xform "A" {}\n')
    assert main(["usd", "read", str(foreign)]) == 2
    err = capsys.readouterr().err
    assert "found 0 PhysicalCamera prims" in err
    assert f"{foreign.resolve()}: found 0" in err  # which file (a first-day review: the error did not say)
    assert main(["usd", "read", str(foreign), "--path", "/A"]) == 2
    assert "/A: is a Xform, not a PhysicalCamera" in capsys.readouterr().err


def test_write_applies_sensor_shift_flags(tmp_path, capsys):
    """Issue 8.1: --shift-x/--shift-y reach the file. A 2 mm right / -1.5 mm down shift on a
    36 x 24 mm gate at metersPerUnit 0.01 is 2.0 / -1.5 tenths of a cm on the UsdGeomCamera
    (docs/conventions.md), and the PhysicalCamera sensor shift is (2, -1.5) mm."""
    from pxr import Usd, UsdGeom

    f = tmp_path / "shift.usda"
    assert main(["usd", "write", str(f), "--focal", "50", "--fstop", "2.8", "--focus", "3m",
                 "--sensor-width", "36", "--sensor-height", "24", "--shift-x", "2", "--shift-y=-1.5"]) == 0
    stage = Usd.Stage.Open(str(f))
    geom = [UsdGeom.Camera(p) for p in stage.Traverse() if p.IsA(UsdGeom.Camera)]
    assert len(geom) == 1
    assert geom[0].GetHorizontalApertureOffsetAttr().Get() == 2.0
    assert geom[0].GetVerticalApertureOffsetAttr().Get() == -1.5
    capsys.readouterr()
    assert main(["usd", "read", str(f), "--json"]) == 0
    cam = json.loads(capsys.readouterr().out)["usd"]["camera"]
    assert cam["shift_mm"] == [2.0, -1.5]


def test_write_refuses_zero_fps_without_traceback(tmp_path, capsys):
    """Issue 8: `usd write ... --fps 0` raised ZeroDivisionError; now one line and exit 2."""
    f = tmp_path / "fps.usda"
    assert main(["usd", "write", str(f), "--focal", "35", "--fstop", "2.8", "--focus", "3m", "--fps", "0"]) == 2
    err = capsys.readouterr().err
    assert "frames per second" in err and "Traceback" not in err
    assert not f.exists()


def test_export_usd_points_to_usd_write(tmp_path, capsys):
    """`physcam export` writes every other renderer's camera; a TD typing `export usd` is told where USD lives."""
    f = tmp_path / "cam.usda"
    assert main(["export", "usd", str(f), "--focal", "50"]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and err.startswith("physcam: error: ") and "`physcam usd write`" in err, err
    assert not f.exists()


def test_write_and_animate_agree_on_an_ntsc_rate(tmp_path):
    """`--fps 23.976` is 24000/1001 time codes per second from usd write as from usd animate (and a live
    recording): a camera from one referenced beside a take from the other is not rescaled in time; the
    shutter at 180 degrees is half of 1001/24000 s."""
    from physcam.usd.read import open_stage

    marks = tmp_path / "pull.csv"
    marks.write_text("frame,focus\n1,3m\n")
    written, animated = tmp_path / "w.usda", tmp_path / "a.usda"
    assert main(["usd", "write", str(written), *BASE, "--fps", "23.976"]) == 0
    assert main(["usd", "animate", str(animated), "--focal", "50", "--fstop", "4", "--marks", str(marks),
                 "--fps", "23.976"]) == 0
    for f in (written, animated):
        stage = open_stage(f)
        assert stage.GetTimeCodesPerSecond() == 24000 / 1001, f
        assert stage.GetPrimAtPath("/Cameras/Camera").GetAttribute("shutterDuration").Get() == pytest.approx(
            0.5 * 1001 / 24000, rel=1e-7)


def _write_read(tmp_path, *flags, path=None):
    from physcam.usd.read import open_stage, read_camera

    f = tmp_path / f"w{abs(hash(flags))}.usda"
    argv = ["usd", "write", str(f), *flags]
    assert main(argv) == 0, argv
    stage = open_stage(f)
    return stage, read_camera(stage, path)


BASE = ("--focal", "50", "--fstop", "4", "--focus", "3m")


def test_every_usd_write_flag_reaches_the_file(tmp_path, capsys):
    """Issue 9.2: each flag of `physcam usd write` is written and reads back (expected values are
    the flags' own numbers, converted by hand: 3 m = 3000 mm, T = N / sqrt(t), 90 deg at 24 fps =
    1/96 s, the practical pupil 300 - 0.5 * 120 = 240 mm in front of the film)."""
    from pxr import UsdGeom

    import pytest

    s, r = _write_read(tmp_path, *BASE)
    assert (r.spec.focal_length_mm, r.spec.fstop, r.spec.focus_mm) == (50.0, 4.0, 3000.0)
    s, r = _write_read(tmp_path, *BASE, "--tstop", "4.5")
    assert r.spec.transmittance == pytest.approx((4 / 4.5) ** 2, rel=1e-6)
    geom = UsdGeom.Camera(s.GetPrimAtPath("/Cameras/Camera/Camera"))
    assert geom.GetExposureFStopAttr().Get() == pytest.approx(4.5, rel=1e-6)
    s, r = _write_read(tmp_path, *BASE, "--sensor", "ALEXA 35")
    assert (r.spec.sensor_width_mm, r.spec.sensor_height_mm) == pytest.approx((27.99, 19.22))
    s, r = _write_read(tmp_path, *BASE, "--sensor-width", "30", "--sensor-height", "20", "--squeeze", "2",
                       "--coc", "0.02")
    assert (r.spec.sensor_width_mm, r.spec.sensor_height_mm, r.spec.squeeze) == pytest.approx((30, 20, 2))
    assert r.spec.coc_mm == pytest.approx(0.02)
    s, r = _write_read(tmp_path, "--focal", "50", "--fstop", "4", "--near", "2.5m", "--far", "4m")
    # thin lens, about H1: 1/s = (1/near + 1/far) / 2 -> the mark lies between the limits
    assert 2500 < r.spec.focus_mm < 4000
    s, r = _write_read(tmp_path, *BASE, "--model", "technical", "--reference", "flange", "--flange", "44",
                       "--h1", "30", "--h2", "20", "--pupil", "50")
    assert r.spec.principal_planes_mm == pytest.approx((74.0, 64.0))
    assert r.spec.entrance_pupil_mm == pytest.approx(94.0) and r.spec.flange_distance_mm == 44.0
    s, r = _write_read(tmp_path, *BASE, "--sensor-front", "300", "--lens-length", "120", "--pupil-fraction", "0.5")
    assert r.spec.entrance_pupil_mm == pytest.approx(240.0)
    s, r = _write_read(tmp_path, *BASE, "--meters-per-unit", "1", "--shutter-angle", "90", "--fps", "24")
    assert UsdGeom.GetStageMetersPerUnit(s) == 1.0 and s.GetTimeCodesPerSecond() == 24.0
    assert r.spec.shutter_duration_s == pytest.approx(1 / 96, rel=1e-6)
    from _thin_lens import image_distance_at_mark

    assert UsdGeom.Camera(s.GetPrimAtPath("/Cameras/Camera/Camera")).GetFocalLengthAttr().Get() == \
        pytest.approx(image_distance_at_mark(50.0, 3000.0) / 100.0, rel=1e-5)  # float32, nudged to keep the FOV
    s, r = _write_read(tmp_path, *BASE, "--path", "/Rig/Hero", "--blades", "9", path="/Rig/Hero")
    assert r.spec.aperture_blades == 9
    assert s.GetPrimAtPath("/Rig/Hero/Camera").GetAttribute("ri:apertureNSides").Get() == 9
    s, r = _write_read(tmp_path, *BASE, "--orthographic", "--magnification", "0.5")
    assert (r.spec.projection, r.spec.magnification) == ("orthographic", 0.5)
    s, r = _write_read(tmp_path, *BASE, "--enlarge", "2,2", "--handedness", "-1")
    assert r.spec.enlarge == (2.0, 2.0) and r.spec.handedness == -1.0
    # the companion images half the default Super 35 gate's 24.89 mm (enlarge 2) behind the 3 m thin lens's s'
    from _thin_lens import image_distance_at_mark as sprime

    g = UsdGeom.Camera(s.GetPrimAtPath("/Cameras/Camera/Camera"))
    assert g.GetHorizontalApertureAttr().Get() / g.GetFocalLengthAttr().Get() == pytest.approx(
        24.89 / 2 / sprime(50.0, 3000.0), rel=1e-6)
    s, r = _write_read(tmp_path, "--lens", "dgauss_50mm", "--fstop", "4", "--focus", "3m")
    assert r.spec.lens_name.startswith("Double Gauss 50mm")
    assert s.GetPrimAtPath("/Cameras/Camera/Camera").GetAttribute("lensDistortion:k1")


def test_kit_cli_builds_library_body_vendor_and_shot(tmp_path, capsys):
    """Issue 9.7: the lens-library, body and shot kits have a CLI; usd check and refresh (9.5)."""
    from pxr import UsdGeom

    from physcam.usd.read import open_stage, read_camera

    csv = tmp_path / "darling24.csv"
    csv.write_text("date,focal_length_mm,fstop,entrance_pupil_mm,transmittance\n"
                   "2026-03-01,24.1,2.8,80,0.9\n2026-03-02,24.3,2.8,81,0.88\n")
    lens, body, vendor, shot = (tmp_path / n for n in ("lens.usda", "body.usda", "vendor.usda", "shot.usda"))
    assert main(["usd", "kit", "lens", str(lens), "--characterizations", str(csv)]) == 0
    assert main(["usd", "kit", "body", str(body), "--sensor", "ALEXA 35", "--flange", "44", "--iso", "800"]) == 0
    assert main(["usd", "kit", "vendor", str(vendor), "--lens", "dgauss_50mm", "--focus", "1.5m",
                 "--sensor", "S35"]) == 0
    assert main(["usd", "kit", "shot", str(shot), "--body", str(body), "--lens", str(vendor), "--focus", "2m",
                 "--fstop", "2.8", "--position", "0,150,500", "--rotate", "0,35,0"]) == 0
    stage = open_stage(shot)
    r = read_camera(stage)
    assert (r.spec.sensor_width_mm, r.spec.flange_distance_mm, r.spec.iso) == pytest.approx((27.99, 44.0, 800.0))
    assert (r.spec.focus_mm, r.spec.fstop) == pytest.approx((2000.0, 2.8))
    eye = UsdGeom.Xformable(stage.GetPrimAtPath("/Cameras/Shot/Camera")).ComputeLocalToWorldTransform(0)
    assert tuple(eye.ExtractTranslation()) == pytest.approx((0.0, 150.0, 500.0), abs=1e-6)
    capsys.readouterr()
    assert main(["usd", "check", str(shot), "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["stale"] is False
    assert main(["usd", "kit", "shot", str(shot), "--body", str(body), "--lens", str(lens), "--sensor", "FF"]) == 2
    assert "does not use --sensor" in capsys.readouterr().err


def test_read_orthographic_says_orthographic(tmp_path, capsys):
    """Issue 9.7: `usd read` printed a perspective FOV and DOF for orthographic cameras."""
    f = tmp_path / "o.usda"
    assert main(["usd", "write", str(f), "--focal", "50", "--fstop", "4", "--focus", "3m", "--orthographic",
                 "--magnification", "0.5", "--sensor-width", "36", "--sensor-height", "24"]) == 0
    capsys.readouterr()
    assert main(["usd", "read", str(f)]) == 0
    out = capsys.readouterr().out
    assert "orthographic: magnification 0.5, images 72 x 48 mm" in out and "hfov" not in out
    assert main(["usd", "read", str(f), "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["report"] is None


def test_lens_camera_carries_omniverse_opencv_distortion(tmp_path):
    """Issue 9 (Omniverse): a camera written from a prescription applies
    OmniLensDistortionOpenCvPinholeAPI. Its fx (pixels) is the companion's own focal length on the
    requested image width, and cv2.projectPoints with the authored values puts a 15-degree beam
    where physcam's real chief ray lands (independent OpenCV oracle)."""
    import math

    import cv2
    import numpy as np
    from pxr import UsdGeom

    from physcam.analysis._chief import aim_from_infinity, field_direction
    from physcam.lens.library import load_lens
    from physcam.optics.paraxial import gaussian
    from physcam.trace import trace_to_film
    from physcam.usd.read import open_stage

    f = tmp_path / "omni.usda"
    assert main(["usd", "write", str(f), "--lens", "dgauss_50mm", "--focus", "inf", "--sensor-width", "36",
                 "--sensor-height", "24", "--resolution", "3600,2400"]) == 2  # the focus must be finite
    assert main(["usd", "write", str(f), "--lens", "dgauss_50mm", "--focus", "1000m", "--sensor-width", "36",
                 "--sensor-height", "24", "--resolution", "3600,2400"]) == 0
    stage = open_stage(f)
    prim = stage.GetPrimAtPath("/Cameras/Camera/Camera")
    assert "OmniLensDistortionOpenCvPinholeAPI" in prim.GetMetadata("apiSchemas").GetAddedOrExplicitItems()
    a = lambda n: prim.GetAttribute(f"omni:lensdistortion:opencvPinhole:{n}").Get()  # noqa: E731
    assert prim.GetAttribute("omni:lensdistortion:model").Get() == "opencvPinhole"
    assert tuple(a("imageSize")) == (3600, 2400)
    focal_mm = UsdGeom.Camera(prim).GetFocalLengthAttr().Get()  # tenths of a cm = mm
    assert a("fx") == pytest.approx(focal_mm * 3600 / 36.0, rel=1e-5)
    K = np.array([[a("fx"), 0, a("cx")], [0, a("fy"), a("cy")], [0, 0, 1]], dtype=float)
    dist = np.array([a("k1"), a("k2"), a("p1"), a("p2"), a("k3"), a("k4"), a("k5"), a("k6")], dtype=float)
    lens = load_lens("dgauss_50mm")
    theta = math.radians(15.0)
    chief = aim_from_infinity(lens, field_direction(theta, "y"), wavelength_nm=lens.wavelength_nm)
    from physcam.trace import RayBatch

    film_z = gaussian(lens).z_rear_focal_point
    out = trace_to_film(lens, RayBatch.from_arrays(chief.start, chief.direction), film_z, clip=False)
    # OpenCV's object point (0, tan 15°, 1) lies below the axis (OpenCV's y points down), so its light
    # travels toward physcam's +y; the film image (inverted) lies at +y, which the upright OpenCV
    # image shows at v = cy + y px/mm (docs/unreal-omniverse.md)
    assert out.y[0] > 0
    v_real = a("cy") + out.y[0] * 2400 / 24.0
    pts, _ = cv2.projectPoints(np.array([[0.0, math.tan(theta), 1.0]]), np.zeros(3), np.zeros(3), K, dist)
    assert pts[0, 0, 1] == pytest.approx(v_real, abs=0.5)


def test_renderman_settings_and_dof_aspect(tmp_path):
    """Issue 9 (RenderMan via Hydra): ri:dofaspect for anamorphic lenses and a UsdRenderSettings
    with pixelAspectRatio = squeeze and overscan. The settings' display aspect (resolution x
    pixel aspect) equals the companion's desqueezed aperture aspect; the navarro anamorphic's
    dofaspect is its entrance pupil's X / Y diameter, computed here from the paraxial engine."""
    from pxr import UsdGeom, UsdRender

    from physcam.lens.library import load_lens
    from physcam.optics.focusing import focus
    from physcam.optics.paraxial import gaussian
    from physcam.usd.read import open_stage

    f = tmp_path / "thin.usda"
    assert main(["usd", "write", str(f), "--focal", "50", "--fstop", "2.8", "--focus", "3m", "--sensor",
                 "35mm anamorphic", "--squeeze", "2", "--overscan", "10", "--resolution", "2200"]) == 0
    stage = open_stage(f)
    settings = UsdRender.Settings(stage.GetPrimAtPath("/Render/Settings"))
    assert settings.GetPixelAspectRatioAttr().Get() == 2.0
    w, h = settings.GetResolutionAttr().Get()
    assert w == 2200 and tuple(settings.GetDataWindowNDCAttr().Get()) == pytest.approx((-0.05, -0.05, 1.05, 1.05))
    assert [str(t) for t in settings.GetCameraRel().GetTargets()] == ["/Cameras/Camera/Camera"]
    g = UsdGeom.Camera(stage.GetPrimAtPath("/Cameras/Camera/Camera"))
    assert w * 2.0 / h == pytest.approx(g.GetHorizontalApertureAttr().Get() / g.GetVerticalApertureAttr().Get(),
                                        rel=1e-3)  # whole pixels
    assert g.GetPrim().GetAttribute("ri:dofaspect").Get() == pytest.approx(0.5)  # a thin front anamorphic
    aspects = {}
    for slug in ("navarro_anamorphic_2x", "neil_front_anamorphic_2x"):
        f2 = tmp_path / f"{slug}.usda"
        assert main(["usd", "write", str(f2), "--lens", slug, "--focus", "3m", "--sensor", "35mm anamorphic"]) == 0
        stage2 = open_stage(f2)
        lens = load_lens(slug)
        st = focus(lens, 3000.0)
        gx = gaussian(st.prescription, axis="x", object_z=st.object_z, film_z=st.film_z)
        gy = gaussian(st.prescription, axis="y", object_z=st.object_z, film_z=st.film_z)
        aspects[slug] = stage2.GetPrimAtPath("/Cameras/Camera/Camera").GetAttribute("ri:dofaspect").Get()
        assert aspects[slug] == pytest.approx(gx.entrance_pupil_diameter / gy.entrance_pupil_diameter, rel=1e-6)
    # a rear anamorphic (cylinders behind the stop) has a round entrance pupil: round bokeh; a front
    # anamorphic narrows the pupil in X by about its squeeze: oval bokeh, taller than wide
    assert aspects["navarro_anamorphic_2x"] == pytest.approx(1.0)
    assert aspects["neil_front_anamorphic_2x"] == pytest.approx(0.5, abs=0.01)


def test_review_findings_on_the_kit_cli(tmp_path, capsys):
    """A new user's review: a body's CoC follows the sensor (d/1500 by default), a plan view looks
    down, usd check can gate a script, report --force without --plot is refused, and reading a
    file that is not USD says so in one clean line."""
    from pxr import Usd, UsdGeom

    from physcam.usd.read import open_stage

    body = tmp_path / "s16.usda"
    assert main(["usd", "kit", "body", str(body), "--sensor", "S16"]) == 0
    body_stage = open_stage(body)
    coc = body_stage.GetPrimAtPath("/Body").GetAttribute("sensor:main:circleOfConfusion").Get()
    assert coc == pytest.approx((12.52**2 + 7.41**2) ** 0.5 / 1500, rel=1e-6)  # Super 16 diagonal / 1500
    kit = tmp_path / "kit.usda"
    assert main(["usd", "kit", "previs", str(kit)]) == 0
    stage = open_stage(kit)
    stage.GetPrimAtPath("/PrevisKit").GetVariantSets().GetVariantSet("setup").SetVariantSelection("TopDownPlan")
    m = UsdGeom.Xformable(stage.GetPrimAtPath("/PrevisKit/Camera")).ComputeLocalToWorldTransform(Usd.TimeCode())
    assert tuple(m.TransformDir((0, 0, -1))) == pytest.approx((0.0, -1.0, 0.0), abs=1e-9)  # looks down -Y
    cam = tmp_path / "cam.usda"
    assert main(["usd", "write", str(cam), "--focal", "50", "--fstop", "2.8", "--focus", "3m"]) == 0
    capsys.readouterr()
    assert main(["usd", "check", str(cam), "--exit-code"]) == 0
    assert "current" in capsys.readouterr().out
    assert main(["report", "--focal", "50", "--fstop", "2.8", "--focus", "3m", "--force"]) == 2
    csv = tmp_path / "notusd.csv"
    csv.write_text("a,b\n1,2\n")
    capsys.readouterr()
    assert main(["usd", "read", str(csv)]) == 2
    err = capsys.readouterr().err
    assert "not a USD file" in err and len(err.strip().splitlines()) == 1


@pytest.mark.parametrize("focal, fstop", [("50", "2.8"), ("24", "4"), ("85", "4")])
def test_hyperfocal_focus_reads_back_with_an_infinite_far_limit(tmp_path, capsys, focal, fstop):
    # the focus distance is a float32 attribute: read back it lies up to 6e-8 short of H, where the
    # exact far limit was 1e9-4e10 m (review finding); within HYPERFOCAL_RTOL it is H
    f = tmp_path / "h.usda"
    assert main(["usd", "write", str(f), "--focal", focal, "--fstop", fstop, "--focus", "hyperfocal",
                 "--sensor", "S35"]) == 0
    capsys.readouterr()
    assert main(["usd", "read", str(f), "--json"]) == 0
    dof = json.loads(capsys.readouterr().out)["report"]["dof"]
    assert dof["far_is_infinite"] is True and dof["far_from_film_mm"] is None


def test_a_plain_camera_file_is_told_apart_from_a_physical_one(tmp_path, capsys):
    """A matchmove artist's plain UsdGeomCamera file got "found 0 PhysicalCamera prims (none); name the
    one to read": there was none to name (round 8). The answer names the plain cameras it holds."""
    f = tmp_path / "plain.usda"
    f.write_text('#usda 1.0\ndef Xform "cams" {\n    def Camera "shotcam" {\n    }\n}\n')
    for verb in ("read", "check", "refresh"):
        assert main(["usd", verb, str(f)]) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and "name the one" not in err
        assert f"no physical camera to {verb}" in err and "UsdGeomCamera prims (/cams/shotcam)" in err
        assert err.count("plain.usda") == 1, err  # the file named once (check and refresh named it twice)


def test_usd_write_places_the_camera_from_the_notes(tmp_path, capsys):
    """A matchmove artist's notes: the lens 150 cm up, tilted 5 degrees down, panned 30 left. `usd write`
    had no --position/--rotate (only `usd kit shot`, which needs body and lens files). Oracle: the closed
    form of rotateXYZ on the camera's -Z, (-cos 5 sin 30, -sin 5, -cos 5 cos 30), and the eye on the
    entrance pupil (here the thin lens's H1, docs/usd.md "Transform"), read by usd-core's Gf.Camera."""
    import math

    import pytest
    from pxr import Gf, Usd, UsdGeom

    s, _ = _write_read(tmp_path, *BASE, "--position", "-20,150,400", "--rotate", "-5,30,0")
    cam = UsdGeom.Camera(s.GetPrimAtPath("/Cameras/Camera/Camera")).GetCamera(Usd.TimeCode.Default())
    t, p = math.radians(5), math.radians(30)
    assert tuple(cam.transform.ExtractTranslation()) == pytest.approx((-20, 150, 400), abs=1e-9)
    look = cam.transform.TransformDir(Gf.Vec3d(0, 0, -1))
    assert tuple(look) == pytest.approx((-math.cos(t) * math.sin(p), -math.sin(t), -math.cos(t) * math.cos(p)),
                                        abs=1e-6)

"""The proposal's four use cases, built and checked through composition (usd-core)."""

import math
import struct

import pytest

from physcam.errors import ExportError, InputError
from physcam.usd.author import CameraSpec
from physcam.usd.kit import (PREVIS_SETUPS, write_body_file, write_lens_file, write_previs_kit, write_shot,
                             write_vendor_lens)
from physcam.usd.read import find_cameras, open_stage, read_camera
from physcam.usd.validate import validation_errors

from pxr import Usd, UsdGeom  # noqa: E402

from _thin_lens import image_distance_at_mark  # noqa: E402


def lens(focal, pupil, t=1.0):
    return CameraSpec(focal_length_mm=focal, entrance_pupil_mm=pupil, transmittance=t, lens_name="Darling 24")


@pytest.fixture
def library(tmp_path):
    f = tmp_path / "lenses" / "darling24.usda"
    write_lens_file(f, {"2026-03-01": lens(24.1, 80.0, 0.90), "2026-03-02": lens(24.3, 81.0, 0.88)})
    return f


def test_lens_library_current_is_latest_and_dates_selectable(library):
    stage = open_stage(library)
    assert not validation_errors(stage)
    prim = stage.GetPrimAtPath("/Lens")
    vset = prim.GetVariantSets().GetVariantSet("characterization")
    assert vset.GetVariantNames() == ["current", "d2026_03_01", "d2026_03_02"]
    assert vset.GetVariantSelection() == "current"
    model = stage.GetPrimAtPath("/Lens/Pinhole")
    assert model.GetAttribute("focalLength").Get() == pytest.approx(24.3)
    vset.SetVariantSelection("d2026_03_01")
    assert stage.GetPrimAtPath("/Lens/Pinhole").GetAttribute("focalLength").Get() == pytest.approx(24.1)
    assert prim.GetAttribute("lens:main:entrancePupilDistance").Get() == pytest.approx(80.0)


def test_shot_composes_body_and_lens_with_override(tmp_path, library):
    body = tmp_path / "bodies" / "alexa35.usda"
    write_body_file(body, CameraSpec(sensor_width_mm=27.99, sensor_height_mm=19.22, flange_distance_mm=44.0,
                                     sensor_name="ARRI ALEXA 35"))
    shot = tmp_path / "shots" / "sh010" / "camera.usda"
    write_shot(shot, body, library, overrides={"fstop": 2.8, "focus_mm": 2000.0}, position=(0, 150, 500),
               rotate_xyz_deg=(0, 35, 0))
    stage = open_stage(shot)
    assert not validation_errors(stage)
    r = read_camera(stage, "/Cameras/Shot")
    # from the body file
    assert (r.spec.sensor_width_mm, r.spec.sensor_height_mm) == pytest.approx((27.99, 19.22))
    assert r.spec.flange_distance_mm == 44.0
    # from the lens file's "current" characterization
    assert r.spec.focal_length_mm == pytest.approx(24.3) and r.spec.entrance_pupil_mm == pytest.approx(81.0)
    # the shot's overrides
    assert r.spec.fstop == pytest.approx(2.8) and r.spec.focus_mm == pytest.approx(2000.0)
    # the companion camera follows the composed values: FOV of 24.3 mm on 27.99 mm
    g = UsdGeom.Camera(stage.GetPrimAtPath("/Cameras/Shot/Camera")).GetCamera(Usd.TimeCode.Default())
    hfov = math.degrees(2 * math.atan(g.frustum.GetWindow().GetMax()[0]))
    # (the physical camera stores 32-bit floats: the closed form on those values)
    f32 = lambda x: struct.unpack("f", struct.pack("f", x))[0]  # noqa: E731
    pin = image_distance_at_mark(f32(24.3), 2000.0)  # the thin lens's framing at the 2 m mark
    assert hfov == pytest.approx(math.degrees(2 * math.atan(f32(27.99) / (2 * pin))), abs=1e-6)
    assert g.fStop == pytest.approx(2.8 * pin / f32(24.3), rel=1e-6)  # aperture f / N kept
    # the eye sits at the lens's entrance pupil, placed where the shot said
    eye = UsdGeom.Xformable(stage.GetPrimAtPath("/Cameras/Shot/Camera")).ComputeLocalToWorldTransform(
        Usd.TimeCode.Default()).ExtractTranslation()
    assert tuple(eye) == pytest.approx((0, 150, 500), abs=1e-9)
    # the referenced files stay referenced by relative paths (the shot folder can move with them)
    text = shot.read_text()
    assert "../../lenses/darling24.usda" in text and str(tmp_path) not in text


def test_shot_can_pin_a_characterization_for_archive(tmp_path, library):
    body = tmp_path / "body.usda"
    write_body_file(body, CameraSpec())
    shot = tmp_path / "shot.usda"
    write_shot(shot, body, library, lens_variant="d2026_03_01")
    assert read_camera(open_stage(shot)).spec.focal_length_mm == pytest.approx(24.1)
    with pytest.raises(ExportError, match="no characterization variant"):
        write_shot(tmp_path / "x.usda", body, library, lens_variant="d1999")
    with pytest.raises(InputError, match="cannot override"):
        write_shot(tmp_path / "y.usda", body, library, overrides={"focal_length_mm": 10})


def test_previs_kit_eight_variants(tmp_path):
    f = tmp_path / "kit.usda"
    write_previs_kit(f)
    stage = open_stage(f)
    assert not validation_errors(stage)
    prim = stage.GetPrimAtPath("/PrevisKit")
    vset = prim.GetVariantSets().GetVariantSet("setup")
    assert len(vset.GetVariantNames()) == 8
    assert {"DollHouse", "OverTheShoulder", "OutInTheDesert"} <= set(vset.GetVariantNames())
    for name, spec in PREVIS_SETUPS.items():
        vset.SetVariantSelection(name)
        r = read_camera(stage, "/PrevisKit")
        assert r.spec.projection == spec.projection
        assert r.spec.fstop == pytest.approx(spec.fstop) and r.spec.focus_mm == pytest.approx(spec.focus_mm)
        g = UsdGeom.Camera(stage.GetPrimAtPath("/PrevisKit/Camera"))
        if spec.projection == "perspective":
            assert r.spec.focal_length_mm == pytest.approx(spec.focal_length_mm)
            cam = g.GetCamera(Usd.TimeCode.Default())
            hfov = math.degrees(2 * math.atan(cam.frustum.GetWindow().GetMax()[0]))
            # the best-match pinhole of the thin lens at the setup's mark: s' (hand-solved)
            pin = image_distance_at_mark(spec.focal_length_mm, spec.focus_mm)
            exact = math.degrees(2 * math.atan(spec.sensor_width_mm * spec.squeeze / (2 * pin)))
            assert hfov == pytest.approx(exact, abs=1e-6)
        else:
            # 36 mm at magnification 0.002 images 18 m = 1800 cm = 18000 tenths of a cm
            assert g.GetHorizontalApertureAttr().Get() == pytest.approx(18000.0, rel=1e-7)
        assert not validation_errors(stage)


def test_vendor_lens_prescription_and_best_match_pinhole(tmp_path):
    from physcam.lens.library import load_lens
    from physcam.optics.paraxial import gaussian

    rx = load_lens("dgauss_50mm")
    f = tmp_path / "vendor" / "dgauss50.usda"
    write_vendor_lens(f, rx, focus_mm=1500.0, fstop=4.0)
    stage = open_stage(f)
    assert not validation_errors(stage)
    assert find_cameras(stage) == ["/Lens"]
    pin = read_camera(stage)
    assert pin.lens_model_type == "PhysicalCameraLensModelPinhole"
    # the pinhole frames what the real lens frames at the 1.5 m mark: its FOV equals the report's
    report_rx = pin.report()
    stage.GetPrimAtPath("/Lens").GetVariantSets().GetVariantSet("lensModel").SetVariantSelection("prescription")
    real = read_camera(stage)
    assert real.lens_model_type == "PhysicalCameraLensModelPrescription"
    # the prescription survives the round trip surface for surface
    assert real.prescription.surfaces == rx.surfaces
    assert real.spec.focal_length_mm == pytest.approx(gaussian(rx).efl, rel=1e-12)
    from physcam.onset.report import solve_lens_report
    from physcam.onset.sensors import Sensor

    lens_report = solve_lens_report(focal_length_mm=None, sensor=Sensor("c", "c", 36.0, 24.0), fstop=4.0,
                                    focus_mm=1500.0, coc=0.03, lens=rx)
    # issue 9.6: the best-match pinhole with the eye at the entrance pupil is 52.048 mm for dgauss
    # focused at 1.5 m (the oracle figure); the companion camera (mm at metersPerUnit 0.01)
    # is that pinhole, and the read-back report keeps it
    geom = UsdGeom.Camera(stage.GetPrimAtPath("/Lens/Camera"))
    assert geom.GetFocalLengthAttr().Get() == pytest.approx(52.048, abs=1e-3)
    assert pin.spec.pinhole_focal_length_mm == pytest.approx(52.048, abs=1e-3)
    assert report_rx.pinhole[0] == pytest.approx(lens_report.pinhole[0], rel=1e-6)  # float32 storage
    assert report_rx.hfov_focus_deg == pytest.approx(lens_report.hfov_focus_deg, abs=1e-5)
    assert report_rx.fstop == 4.0


def test_usd_write_lens_and_vendor_kit_frame_alike(tmp_path, capsys):
    """Issue 9.6: `usd write --lens` and `usd kit vendor` used two framings (EFL, 3.25 % wide, and
    s', 0.23 % tight). Both now write the one best-match pinhole, 52.048 mm for dgauss at 1.5 m."""
    from physcam.cli import main

    a, b = tmp_path / "a.usda", tmp_path / "b.usda"
    assert main(["usd", "write", str(a), "--lens", "dgauss_50mm", "--focus", "1.5m", "--fstop", "4",
                 "--sensor-width", "36", "--sensor-height", "24"]) == 0
    assert main(["usd", "kit", "vendor", str(b), "--lens", "dgauss_50mm", "--focus", "1.5m", "--fstop", "4"]) == 0
    sa, sb = open_stage(a), open_stage(b)  # keep the stages alive while their prims are read
    fa = UsdGeom.Camera(sa.GetPrimAtPath("/Cameras/Camera/Camera")).GetFocalLengthAttr().Get()
    fb = UsdGeom.Camera(sb.GetPrimAtPath("/Lens/Camera")).GetFocalLengthAttr().Get()
    assert fa == pytest.approx(52.048, abs=1e-3) and fb == pytest.approx(fa, rel=1e-6)


def test_read_errors_name_the_prim(tmp_path):
    stage = Usd.Stage.CreateInMemory()
    UsdGeom.Xform.Define(stage, "/World/NotACamera")
    with pytest.raises(ExportError, match="/World/NotACamera: is a Xform, not a PhysicalCamera"):
        read_camera(stage, "/World/NotACamera")
    cam = stage.DefinePrim("/World/Cam", "PhysicalCamera")
    with pytest.raises(ExportError, match="/World/Cam: no PhysicalCameraSensorAPI"):
        read_camera(stage, "/World/Cam")
    cam.ApplyAPI("PhysicalCameraSensorAPI", "main")
    cam.ApplyAPI("PhysicalCameraLensAPI", "main")
    with pytest.raises(ExportError, match="/World/Cam: lens:main:lensModel points at no lens model"):
        read_camera(stage, "/World/Cam")
    cam.CreateRelationship("lens:main:lensModel").SetTargets(["/World/NotACamera"])
    with pytest.raises(ExportError, match="points at /World/NotACamera, a Xform"):
        read_camera(stage, "/World/Cam")
    bad = tmp_path / "bad.usda"
    bad.write_text("#usda 1.0\ndef Xform \"A\" {\n  float x = \n")
    with pytest.raises(ExportError, match="bad.usda"):
        open_stage(bad)


def test_round_trip(tmp_path):
    from physcam.usd.author import write_camera

    spec = CameraSpec(focal_length_mm=32.0, sensor_width_mm=27.99, sensor_height_mm=19.22, fstop=2.0,
                      focus_mm=2500.0, coc_mm=0.025, squeeze=1.0, entrance_pupil_mm=110.0, shift_mm=(1.0, -0.5),
                      iso=800.0, transmittance=0.9, shutter_open_s=-0.01, shutter_duration_s=0.02,
                      shutter_opening=(0.2, 0.8), aperture_blades=9, aperture_angle_deg=12.0,
                      aperture_roundness=0.3, aperture_density=-0.2, clipping_mm=(50.0, 5.0e6),
                      lens_name="Test 32", sensor_name="ALEXA 35")
    for mpu in (0.01, 1.0):
        f = tmp_path / f"rt{mpu}.usda"
        write_camera(f, spec, meters_per_unit=mpu)
        back = read_camera(open_stage(f)).spec
        for name in spec.__dataclass_fields__:
            a, b = getattr(spec, name), getattr(back, name)
            if name == "aperture_distance_mm":
                assert b == pytest.approx(110.0)  # defaults to the pupil
            elif isinstance(a, float):
                assert b == pytest.approx(a, rel=1e-6), name  # float32 storage
            elif isinstance(a, tuple):
                assert b == pytest.approx(a, rel=1e-6), name
            else:
                assert a == b, name
        r0 = read_camera(open_stage(f)).report()
        from physcam.usd.author import report_for_spec

        assert r0.dof.near_from_film_mm == pytest.approx(report_for_spec(spec).dof.near_from_film_mm, rel=1e-5)


def test_shot_override_keeps_the_lens_switchable(tmp_path, library):
    # overriding the f-stop and focus per shot must not freeze the rest of the lens: selecting an
    # older characterization in the shot still brings that day's focal length and transmittance
    body = tmp_path / "body.usda"
    write_body_file(body, CameraSpec(sensor_width_mm=27.99, sensor_height_mm=19.22))
    shot = tmp_path / "shot.usda"
    write_shot(shot, body, library, overrides={"fstop": 2.8, "focus_mm": 2000.0})
    stage = open_stage(shot)
    prim = stage.GetPrimAtPath("/Cameras/Shot")
    prim.GetVariantSets().GetVariantSet("characterization").SetVariantSelection("d2026_03_01")
    r = read_camera(stage, "/Cameras/Shot")
    assert r.spec.focal_length_mm == pytest.approx(24.1)   # from the 03-01 characterization
    assert r.spec.transmittance == pytest.approx(0.90)
    assert r.spec.fstop == pytest.approx(2.8) and r.spec.focus_mm == pytest.approx(2000.0)  # the shot's
    layer_text = shot.read_text()
    assert "focalLength" not in layer_text.split('def Camera "Camera"')[0]  # no frozen lens model values


def test_reading_a_lens_or_body_file_says_what_it_is(tmp_path, library):
    with pytest.raises(ExportError, match="only a lens"):
        read_camera(open_stage(library))
    body = tmp_path / "body.usda"
    write_body_file(body, CameraSpec())
    with pytest.raises(ExportError, match="only a body"):
        read_camera(open_stage(body))

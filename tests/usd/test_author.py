"""Authoring: the companion UsdGeomCamera against independent numbers (Gf.Camera, closed forms)."""

import math
import os
import subprocess
import sys

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from physcam.errors import ExportError, InputError, PhysCamError
from physcam.usd import PLUGIN_DIR
from physcam.usd.author import CameraSpec, author_camera, new_stage, shutter_opening_curve, write_camera
from physcam.usd.validate import validation_errors

from _thin_lens import image_distance_at_mark

pxr = pytest.importorskip("pxr")
from pxr import Gf, Usd, UsdGeom  # noqa: E402

F32_EPS = 2.0 ** -24  # relative rounding of a 32-bit float (UsdGeomCamera's attributes are floats)


def fov_deg(size_mm, focal_mm):
    """Pinhole field of view 2 atan(size / 2f), degrees (seed 001 with its inversion corrected)."""
    return math.degrees(2.0 * math.atan(size_mm / (2.0 * focal_mm)))


def gf_camera(stage, path="/Cameras/Camera/Camera"):
    return UsdGeom.Camera(stage.GetPrimAtPath(path)).GetCamera(Usd.TimeCode.Default())


@pytest.mark.parametrize("mpu", [0.01, 1.0])
@pytest.mark.parametrize(
    "focal,w,h,squeeze",
    [(50.0, 36.0, 24.0, 1.0), (35.0, 27.99, 19.22, 1.0), (18.0, 24.89, 18.66, 1.0), (13.7, 23.76, 13.365, 1.0),
     (50.0, 22.0, 18.6, 2.0), (40.0, 27.99, 19.22, 1.8)],
)
def test_gf_camera_reproduces_fov(mpu, focal, w, h, squeeze):
    """Gf.Camera from the written UsdGeomCamera gives 2 atan(w / 2 s') to 1e-6 degrees: the
    companion is the best-match pinhole, for a thin lens at the default 3 m mark the image
    distance s' (hand-solved in tests/_thin_lens.py), not f.

    The frustum (double precision) is compared with the closed form on the exact numbers;
    Gf.Camera.GetFieldOfView returns a 32-bit float, so it is held to its own rounding.
    """
    stage = new_stage(mpu)
    spec = CameraSpec.of(focal_length_mm=focal, sensor_width_mm=w, sensor_height_mm=h, squeeze=squeeze)
    author_camera(stage, "/Cameras/Camera", spec)
    focal = image_distance_at_mark(focal, spec.focus_mm)
    cam = gf_camera(stage)
    window = cam.frustum.GetWindow()  # perspective window at unit distance: aperture / (2 focal length)
    hfov = math.degrees(2.0 * math.atan(window.GetMax()[0]))
    vfov = math.degrees(2.0 * math.atan(window.GetMax()[1]))
    # the desqueezed horizontal field of an anamorphic lens: 2 atan(squeeze w / 2f)
    assert hfov == pytest.approx(fov_deg(w * squeeze, focal), abs=1e-6)
    assert vfov == pytest.approx(fov_deg(h, focal), abs=1e-6)
    ulp = 40.0 * F32_EPS * 4  # float32 result: one ulp is 2^-24 relative, FOVs here are below 160 degrees
    assert cam.GetFieldOfView(Gf.Camera.FOVHorizontal) == pytest.approx(fov_deg(w * squeeze, focal), abs=4 * ulp)
    assert cam.GetFieldOfView(Gf.Camera.FOVVertical) == pytest.approx(fov_deg(h, focal), abs=4 * ulp)


def _f32_around(x, k):
    """The float32 nearest ``x`` and the ``k`` float32 values each side of it, walked with numpy's nextafter."""
    import numpy as np

    c = np.float32(x)
    lo, hi = [c], [c]
    for _ in range(k):
        lo.insert(0, np.nextafter(lo[0], np.float32(-np.inf)))
        hi.append(np.nextafter(hi[-1], np.float32(np.inf)))
    return [float(v) for v in lo[:-1] + hi]


@settings(max_examples=50)
@given(st.floats(0.5, 2000.0), st.floats(0.05, 40.0), st.floats(0.05, 40.0), st.integers(0, 24))
def test_fov_preserving_float32_is_the_best_candidate(focal, rw, rh, k):
    """fov_preserving_float32 against a brute force over the same candidates, one at a time: each float32
    focal within k steps, each aperture the float32 nearest its ratio (of the rounding and its two
    neighbours, the first of equals), the focal whose worse ratio error is least (the first of equals)."""
    from physcam.usd.author import fov_preserving_float32

    width, height = rw * focal, rh * focal
    rw, rh = width / focal, height / focal
    best = None
    for fc in _f32_around(focal, k):
        cw = min(_f32_around(rw * fc, 1), key=lambda w: abs(w / fc - rw))
        ch = min(_f32_around(rh * fc, 1), key=lambda h: abs(h / fc - rh))
        err = max(abs(cw / fc - rw) / rw, abs(ch / fc - rh) / rh)
        if best is None or err < best[0]:
            best = (err, (fc, cw, ch))
    assert fov_preserving_float32(focal, width, height, k) == best[1]


@pytest.mark.parametrize("mpu,focal_expected", [(0.01, 50.0), (1.0, 0.5), (0.0254, 50.0 / 2.54)])
def test_units_tenths_of_scene_unit(mpu, focal_expected):
    """50 mm is 50 tenths of a cm, 0.5 tenths of a metre, 19.685 tenths of an inch (2.54 mm each)."""
    stage = new_stage(mpu)
    author_camera(stage, "/Cameras/Camera", CameraSpec.of(focal_length_mm=50.0, focus_mm=3000.0, sensor_width_mm=36.0,
                                                          sensor_height_mm=24.0, clipping_mm=(100.0, 1.0e6)))
    g = UsdGeom.Camera(stage.GetPrimAtPath("/Cameras/Camera/Camera"))
    # float32 values chosen to keep aperture/focal exact stay within a few ulps (2e-6) of the exact ones;
    # the focal length is the best-match pinhole, s' of the 50 mm thin lens at the 3 m mark
    pin = image_distance_at_mark(50.0, 3000.0) / 50.0
    assert g.GetFocalLengthAttr().Get() == pytest.approx(focal_expected * pin, rel=2e-6)
    assert g.GetHorizontalApertureAttr().Get() == pytest.approx(36.0 * focal_expected / 50.0, rel=2e-6)
    near, far = g.GetClippingRangeAttr().Get()
    assert near == pytest.approx(0.1 / mpu, rel=1e-7) and far == pytest.approx(1000.0 / mpu, rel=1e-7)
    # thin lens at a 3 m mark: s + s' = 3000, s' = f s / (s - f) -> s = 2949.1377 mm (hand-solved quadratic)
    s = (3000.0 + math.sqrt(3000.0**2 - 4 * 50.0 * 3000.0)) / 2.0
    assert g.GetFocusDistanceAttr().Get() == pytest.approx(s / (1000.0 * mpu), rel=1e-6)
    assert not validation_errors(stage)


def test_dof_survives_unit_change():
    """Focus, pupil and eye positions scale with metersPerUnit; world focus plane lands on the mark."""
    out = {}
    for mpu in (0.01, 1.0):
        stage = new_stage(mpu)
        author_camera(stage, "/Cameras/Camera", CameraSpec.of(focus_mm=2500.0, fstop=2.8))
        g = UsdGeom.Camera(stage.GetPrimAtPath("/Cameras/Camera/Camera"))
        eye = g.ComputeLocalToWorldTransform(Usd.TimeCode.Default()).ExtractTranslation()
        film = UsdGeom.Xformable(stage.GetPrimAtPath("/Cameras/Camera")).ComputeLocalToWorldTransform(
            Usd.TimeCode.Default()).ExtractTranslation()
        # focus plane (eye + focusDistance along -Z) is 2500 mm in front of the film plane
        plane = eye[2] - g.GetFocusDistanceAttr().Get()
        out[mpu] = (film[2] - plane) * 1000.0 * mpu
        # the aperture diameter focalLength / fStop stays the lens's f / N (50 / 2.8 mm) on the pinhole
        pin = image_distance_at_mark(50.0, 2500.0)
        assert g.GetFStopAttr().Get() == pytest.approx(2.8 * pin / 50.0, rel=1e-6)
    assert out[0.01] == pytest.approx(2500.0, rel=1e-6)
    assert out[1.0] == pytest.approx(2500.0, rel=1e-6)


def test_pivot_is_the_entrance_pupil():
    """Rotating the body leaves the eye (entrance pupil) where it was: a nodal pan."""
    stage = new_stage(0.01)
    author_camera(stage, "/Cameras/Camera", CameraSpec.of(entrance_pupil_mm=120.0), position=(10.0, 20.0, 30.0),
                  rotate_xyz_deg=(15.0, 40.0, 5.0))
    eye = UsdGeom.Xformable(stage.GetPrimAtPath("/Cameras/Camera/Camera")).ComputeLocalToWorldTransform(
        Usd.TimeCode.Default()).ExtractTranslation()
    assert tuple(eye) == pytest.approx((10.0, 20.0, 30.0), abs=1e-9)
    film = UsdGeom.Xformable(stage.GetPrimAtPath("/Cameras/Camera")).ComputeLocalToWorldTransform(
        Usd.TimeCode.Default()).ExtractTranslation()
    assert (film - eye).GetLength() == pytest.approx(12.0, rel=1e-12)  # 120 mm = 12 cm


def test_exposure_shutter_and_renderman():
    stage = new_stage(0.01, fps=25.0)
    spec = CameraSpec.of(fstop=4.0, transmittance=0.81, shutter_open_s=-0.01, shutter_duration_s=0.02,
                         shutter_opening=(0.25, 0.75), aperture_blades=9, aperture_roundness=0.5, iso=800.0)
    author_camera(stage, "/Cameras/Camera", spec)
    prim = stage.GetPrimAtPath("/Cameras/Camera/Camera")
    g = UsdGeom.Camera(prim)
    assert g.GetShutterOpenAttr().Get() == pytest.approx(-0.25)  # -0.01 s at 25 fps
    assert g.GetShutterCloseAttr().Get() == pytest.approx(0.25)
    assert g.GetExposureTimeAttr().Get() == pytest.approx(0.02)
    assert g.GetExposureFStopAttr().Get() == pytest.approx(4.0 / 0.9)  # T = N / sqrt(t)
    assert g.GetExposureIsoAttr().Get() == 800.0
    assert prim.GetAttribute("ri:apertureNSides").Get() == 9
    assert prim.GetAttribute("ri:apertureRoundness").Get() == 0.5
    assert (prim.GetAttribute("ri:shutterOpenTime").Get(), prim.GetAttribute("ri:shutterCloseTime").Get()) == (
        0.25, 0.75)
    assert len(prim.GetAttribute("ri:shutteropening").Get()) == 8


@given(o=st.floats(0.0, 1.0), c=st.floats(0.0, 1.0))
def test_shutter_curve_points_lie_on_the_ramps(o, c):
    o, c = min(o, c), max(o, c)
    p = shutter_opening_curve(o, c)
    # opening ramp y = x / o and closing ramp y = (1 - x) / (1 - c) (seed 002), wherever defined
    for x, y in ((p[0], p[1]), (p[2], p[3])):
        assert 0.0 <= x <= o + 1e-12 and (o < 1e-9 or y == pytest.approx(x / o))
    for x, y in ((p[4], p[5]), (p[6], p[7])):
        assert c - 1e-12 <= x <= 1.0 and (c > 1 - 1e-9 or y == pytest.approx((1.0 - x) / (1.0 - c)))


def test_orthographic_camera():
    stage = new_stage(1.0)
    author_camera(stage, "/Cameras/Camera", CameraSpec.of(projection="orthographic", magnification=0.01,
                                                          sensor_width_mm=36.0, sensor_height_mm=24.0))
    g = UsdGeom.Camera(stage.GetPrimAtPath("/Cameras/Camera/Camera"))
    assert g.GetProjectionAttr().Get() == "orthographic"
    # 36 mm / 0.01 = 3.6 m wide = 36 tenths of a metre
    assert g.GetHorizontalApertureAttr().Get() == pytest.approx(36.0, rel=1e-7)
    assert gf_camera(stage).projection == Gf.Camera.Orthographic
    assert not validation_errors(stage)


def test_write_validates_and_refuses_to_overwrite(tmp_path):
    f = tmp_path / "cam.usda"
    write_camera(f, CameraSpec())
    assert not validation_errors(Usd.Stage.Open(str(f)))
    before = f.read_bytes()
    with pytest.raises(ExportError, match="already exists"):
        write_camera(f, CameraSpec.of(focal_length_mm=85.0))
    assert f.read_bytes() == before
    write_camera(f, CameraSpec.of(focal_length_mm=85.0), force=True)
    assert b"focalLength = 85" in f.read_bytes()
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")]  # no temp file left behind


def test_foreign_prim_is_named(tmp_path):
    stage = new_stage()
    UsdGeom.Sphere.Define(stage, "/Cameras/Ball")
    with pytest.raises(ExportError, match="/Cameras/Ball.*Sphere"):
        author_camera(stage, "/Cameras/Ball", CameraSpec())
    with pytest.raises(ExportError, match="not an absolute prim path"):
        author_camera(stage, "Cameras/x y", CameraSpec())


@pytest.mark.parametrize("bad", [dict(fstop=float("nan")), dict(focal_length_mm=-5.0), dict(sensor_width_mm=0.0),
                                 dict(aperture_roundness=2.0), dict(shutter_opening=(0.8, 0.2)),
                                 dict(clipping_mm=(10.0, 5.0)), dict(focus_mm=float("inf"))])
def test_bad_input_is_a_physcam_error(bad):
    with pytest.raises(InputError):
        author_camera(new_stage(), "/Cameras/Camera", CameraSpec.of(**bad))


def test_second_process_sees_schema_with_only_the_plugin_path(tmp_path):
    f = tmp_path / "cam.usda"
    write_camera(f, CameraSpec.of(focal_length_mm=35.0))
    code = f"""
import sys
from pxr import Usd, Sdf
assert 'physcam' not in sys.modules
stage = Usd.Stage.Open({str(f)!r})
reg = Usd.SchemaRegistry
prim = stage.GetPrimAtPath('/Cameras/Camera')
t = reg.GetTypeFromSchemaTypeName('PhysicalCamera')
assert not t.isUnknown, 'PhysicalCamera unknown'
assert prim.IsA(t) and prim.GetTypeName() == 'PhysicalCamera'
assert prim.HasAPI(reg.GetTypeFromSchemaTypeName('PhysicalCameraLensAPI'), 'main')
assert prim.GetAttribute('shutterOpen').Get() == 0.0
assert abs(prim.GetAttribute('flangeDistance').Get() - 52.0) < 1e-6
# fallback values from the schema (never authored by physcam)
assert tuple(prim.GetAttribute('sensor:main:enlarge').Get()) == (1.0, 1.0)
assert prim.GetAttribute('sensor:main:handedness').Get() == 1.0
model = stage.GetPrimAtPath('/Cameras/Camera/Pinhole')
assert model.IsA(reg.GetTypeFromSchemaTypeName('PhysicalCameraLensModel'))
assert model.GetAttribute('focalLength').Get() == 35.0
fresh = stage.DefinePrim('/Fresh', 'PhysicalCameraLensModelPinhole')
assert fresh.GetAttribute('focalLength').Get() == 50.0 and fresh.GetAttribute('focusDistance').Get() == 1000.0
print('ok')
"""
    env = {k: v for k, v in os.environ.items() if not k.startswith(("PXR_", "PYTHONPATH"))}
    env["PXR_PLUGINPATH_NAME"] = str(PLUGIN_DIR)
    res = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, cwd=tmp_path)
    assert res.returncode == 0, res.stderr
    assert res.stdout.strip() == "ok"
    # without the plugin path the same process does not know the type (the test is not vacuous)
    del env["PXR_PLUGINPATH_NAME"]
    res = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, cwd=tmp_path)
    assert res.returncode != 0 and "PhysicalCamera unknown" in res.stderr


def test_usd_errors_are_caught_as_physcam_errors(tmp_path):
    # a pipeline catching PhysCamError catches USD problems too: an existing file, no --force
    f = tmp_path / "a.usda"
    write_camera(f, CameraSpec())
    with pytest.raises(PhysCamError):
        write_camera(f, CameraSpec())


def test_enlarge_and_shift_render_a_tile():
    """Issue 9.7: enlarge is applied. enlarge (2, 2) with shift (-w/4, +h/4) images the upper-left
    quadrant: its Gf.Camera window is the upper-left quarter of the full frame's window."""
    full_stage, tile_stage = new_stage(0.01), new_stage(0.01)
    base = dict(focal_length_mm=50.0, sensor_width_mm=36.0, sensor_height_mm=24.0)
    author_camera(full_stage, "/Cameras/Camera", CameraSpec.of(**base))
    author_camera(tile_stage, "/Cameras/Camera", CameraSpec.of(**base, enlarge=(2.0, 2.0), shift_mm=(-9.0, 6.0)))
    full, tile = gf_camera(full_stage).frustum.GetWindow(), gf_camera(tile_stage).frustum.GetWindow()
    xm, ym = (full.GetMin()[0] + full.GetMax()[0]) / 2, (full.GetMin()[1] + full.GetMax()[1]) / 2
    quadrant = (full.GetMin()[0], xm, ym, full.GetMax()[1])
    got = (tile.GetMin()[0], tile.GetMax()[0], tile.GetMin()[1], tile.GetMax()[1])
    assert got == pytest.approx(quadrant, abs=1e-6)


def test_left_handed_camera_mirrors_the_image():
    """handedness -1 (seed 001: a left-handed camera) mirrors the companion: its camera-to-world
    matrix has a negative determinant and camera +X maps to world -X (body unrotated)."""
    stage = new_stage(0.01)
    author_camera(stage, "/Cameras/Camera", CameraSpec.of(handedness=-1.0))
    m = UsdGeom.Xformable(stage.GetPrimAtPath("/Cameras/Camera/Camera")).ComputeLocalToWorldTransform(
        Usd.TimeCode.Default())
    assert m.GetDeterminant() == pytest.approx(-1.0)
    assert m.TransformDir(Gf.Vec3d(1, 0, 0)) == pytest.approx(Gf.Vec3d(-1, 0, 0))
    assert not validation_errors(stage)
    with pytest.raises(InputError):
        CameraSpec.of(handedness=0.5).checked()


def test_aperture_distance_is_the_physical_stop():
    """Issue 9.7: apertureDistance is the real stop position (the proposal's 'distance from image
    plane to aperture'), not the entrance pupil: for dgauss focused at 2 m, film z minus the stop
    vertex z of the focused lens, computed here from the focused prescription's own geometry."""
    from physcam.lens.library import load_lens
    from physcam.onset.report import solve_lens_report
    from physcam.optics.sensors import find_sensor
    from physcam.optics.focusing import focus
    from physcam.usd.author import spec_from_report

    lens = load_lens("dgauss_50mm")
    st = focus(lens, 2000.0)
    stop_z = st.prescription.vertex_z[st.prescription.stop_index]
    r = solve_lens_report(focal_length_mm=None, sensor=find_sensor("FF"), focus_mm=2000.0, lens=lens)
    spec = spec_from_report(r)
    assert spec.aperture_distance_mm == pytest.approx(st.film_z - stop_z, rel=1e-12)
    assert spec.aperture_distance_mm != pytest.approx(spec.entrance_pupil_mm, rel=1e-3)
    stage = new_stage(0.01)
    cam = author_camera(stage, "/Cameras/Camera", spec, report=r)
    assert cam.GetAttribute("lens:main:apertureDistance").Get() == pytest.approx(st.film_z - stop_z, rel=1e-6)


def test_a_spec_holds_its_camera_and_the_keyword_form_answers_for_one_version(tmp_path):
    """Issue 43: the spec holds a CameraState (focus and stop are the camera's); the old keyword form
    still builds the same spec with a DeprecationWarning; the spec of a report holds the report's camera."""
    from physcam.lens.library import load_lens
    from physcam.onset.report import solve_report
    from physcam.optics.sensors import find_sensor
    from physcam.optics.state import CameraState, camera_state
    from physcam.usd.author import spec_from_report

    typed = dict(focal_length_mm=35.0, fstop=2.8, focus_mm=2000.0, sensor_width_mm=36.0, sensor_height_mm=24.0,
                 squeeze=2.0, lens_name="Darling 35", shift_mm=(1.0, -2.0))
    with pytest.warns(DeprecationWarning, match=r"CameraSpec\.of"):
        old = CameraSpec(**typed)
    new = CameraSpec.of(**typed)
    assert old == new and isinstance(new.camera, CameraState)
    # the numbers read back are the ones typed (the camera's and the spec's own)
    assert (new.focal_length_mm, new.fstop, new.focus_mm, new.squeeze) == (35.0, 2.8, 2000.0, 2.0)
    assert (new.sensor_width_mm, new.sensor_height_mm, new.lens_name, new.sensor_name) == (36.0, 24.0, "Darling 35",
                                                                                          None)
    assert new.camera.fstop == 2.8 and new.camera.focus_from_film_mm == 2000.0 and new.shift_mm == (1.0, -2.0)
    assert new.replaced(fstop=4.0).camera.fstop == 4.0 and new.replaced(fstop=4.0).focus_mm == 2000.0
    # the spec of a prescription's report holds that very camera (no copies of its focus and stop)
    cam = camera_state(load_lens("dgauss_50mm"), focus_mm=1500.0, fstop=4.0, sensor=find_sensor("S35"))
    report = solve_report(cam)
    spec = spec_from_report(report)
    assert spec.camera is cam and spec.fstop == 4.0 and spec.focus_mm == 1500.0
    assert spec.focal_length_mm == report.focal_length_mm and spec.squeeze == report.squeeze
    from physcam.usd.read import open_stage, read_camera

    back = read_camera(open_stage(write_camera(tmp_path / "cam.usda", spec))).spec
    assert back.fstop == pytest.approx(4.0, rel=F32_EPS) and back.focus_mm == pytest.approx(1500.0, rel=F32_EPS)

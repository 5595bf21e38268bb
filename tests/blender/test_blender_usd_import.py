"""Issue 9.1 with Blender's USD importer as the independent consumer: Blender has never heard of
physcam's schema, and places the companion camera where physcam put it (schema fallback types)."""

import math

import pytest

from physcam.usd.author import CameraSpec, write_camera

from _blender import run_blender
from _thin_lens import image_distance_at_mark

pytestmark = pytest.mark.slow


#: What docs/blender.md tells a user to run after File > Import > USD (the importer keeps the
#: companion camera's userProperties:physcam:* as custom properties but applies none of them).
APPLY_IMPORTED = '''
import math
def apply_physcam_properties(obj, scene):
    cam = obj.data
    n = int(cam.get("physcam:apertureBlades", 0))
    cam.dof.aperture_blades = n if n >= 3 else 0
    corner = float(cam.get("physcam:apertureAngle", 0.0))  # a corner this far from +x (RenderMan's angle)
    cam.dof.aperture_rotation = math.radians(corner + (180.0 / n if n >= 3 else 0.0))
    cam.dof.aperture_ratio = 1.0 / float(cam.get("physcam:dofAspect", 1.0))
    if "physcam:resolution" in cam:
        scene.render.resolution_x, scene.render.resolution_y = map(int, cam["physcam:resolution"])
'''


#: The two imports, each into Blender's factory start-up scene (read again before each: nothing of the first
#: reaches the second), emptied of its objects; argv[1] the placed camera, argv[2] the one with an iris and a
#: resolution. One Blender process for both: each costs about 1.3 s of CPU before its script (2026-11-29).
IMPORTS = '''
import bpy, json, sys
from mathutils import Vector


def imported(path):
    bpy.ops.wm.read_factory_settings(use_empty=False)
    for o in list(bpy.data.objects):
        bpy.data.objects.remove(o)
    bpy.ops.wm.usd_import(filepath=path)
    return [o for o in bpy.data.objects if o.type == "CAMERA"]


cams = imported(sys.argv[1])
fwd = (cams[0].matrix_world.to_3x3() @ Vector((0, 0, -1))).normalized()
placed = {"n": len(cams), "pos": list(cams[0].matrix_world.translation), "fwd": list(fwd),
          "lens": cams[0].data.lens, "sensor": cams[0].data.sensor_width}
obj = imported(sys.argv[2])[0]
scene = bpy.context.scene
before = {"blades": obj.data.dof.aperture_blades, "res": [scene.render.resolution_x, scene.render.resolution_y]}
''' + APPLY_IMPORTED + '''
apply_physcam_properties(obj, scene)
print(json.dumps({"placed": placed, "iris": {"before": before, "blades": obj.data.dof.aperture_blades,
                  "rotation": obj.data.dof.aperture_rotation, "ratio": obj.data.dof.aperture_ratio,
                  "res": [scene.render.resolution_x, scene.render.resolution_y]}}))
'''


@pytest.fixture(scope="module")
def imports(tmp_path_factory):
    """What Blender's USD importer made of the two cameras (:data:`IMPORTS`)."""
    tmp = tmp_path_factory.mktemp("usd_import")
    placed = write_camera(tmp / "cam.usda", CameraSpec.of(focal_length_mm=35.0, fstop=2.8, focus_mm=3000.0,
                                                          sensor_width_mm=36.0, sensor_height_mm=24.0),
                          position=(120.0, 150.0, -40.0), rotate_xyz_deg=(0.0, 30.0, 0.0))
    spec = CameraSpec.of(focal_length_mm=35.0, fstop=2.8, focus_mm=3000.0, sensor_width_mm=36.0, sensor_height_mm=24.0,
                         aperture_blades=6, aperture_angle_deg=15.0)
    (tmp / "iris").mkdir()  # each camera its own file cam.usda, as each test wrote it
    iris = write_camera(tmp / "iris" / "cam.usda", spec, resolution=(1234, 823))
    return run_blender(IMPORTS, placed, iris)


def test_blender_imports_the_camera_in_place(imports):
    out = imports["placed"]
    assert out["n"] == 1
    # USD (Y up, cm) (120, 150, -40) is Blender (Z up, m) (1.2, 0.4, 1.5); a 30 degree pan about
    # USD's +Y turns the view from -Z toward -X: USD (-0.5, 0, -0.866), Blender (-0.5, 0.866, 0)
    assert out["pos"] == pytest.approx([1.2, 0.4, 1.5], abs=1e-6)
    assert out["fwd"] == pytest.approx([-0.5, math.sqrt(3) / 2, 0.0], abs=1e-6)
    # the companion's focal length: the best-match pinhole, s' of the 35 mm thin lens at 3 m
    assert out["lens"] == pytest.approx(image_distance_at_mark(35.0, 3000.0), rel=1e-5)


def test_blender_keeps_the_iris_and_resolution_that_its_importer_does_not_apply(imports):
    """Blender's USD importer reads no iris or resolution (UsdGeomCamera has none; it ignores
    UsdRenderSettings): physcam writes them as userProperties, which Blender keeps on the camera, and
    the documented snippet applies them (issue 24 item 3)."""
    out = imports["iris"]
    assert out["before"]["blades"] == 0 and out["before"]["res"] != [1234, 823]  # what the importer alone gives
    assert out["blades"] == 6 and out["res"] == [1234, 823]
    assert math.degrees(out["rotation"]) == pytest.approx(15.0 + 30.0, abs=1e-4)
    assert out["ratio"] == pytest.approx(1.0)

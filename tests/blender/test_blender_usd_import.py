"""Issue 9.1 with Blender's USD importer as the independent consumer: Blender has never heard of
physcam's schema, and places the companion camera where physcam put it (schema fallback types)."""

import math

import pytest

from physcam.usd.author import CameraSpec, write_camera

from _blender import run_blender
from _thin_lens import image_distance_at_mark

pytestmark = pytest.mark.slow


def test_blender_imports_the_camera_in_place(tmp_path):
    f = write_camera(tmp_path / "cam.usda", CameraSpec.of(focal_length_mm=35.0, fstop=2.8, focus_mm=3000.0,
                                                       sensor_width_mm=36.0, sensor_height_mm=24.0),
                     position=(120.0, 150.0, -40.0), rotate_xyz_deg=(0.0, 30.0, 0.0))
    out = run_blender('''
import bpy, json, sys
for o in list(bpy.data.objects):
    bpy.data.objects.remove(o)
bpy.ops.wm.usd_import(filepath=sys.argv[1])
cams = [o for o in bpy.data.objects if o.type == "CAMERA"]
from mathutils import Vector
fwd = (cams[0].matrix_world.to_3x3() @ Vector((0, 0, -1))).normalized()
print(json.dumps({"n": len(cams), "pos": list(cams[0].matrix_world.translation), "fwd": list(fwd),
                  "lens": cams[0].data.lens, "sensor": cams[0].data.sensor_width}))
''', f)
    assert out["n"] == 1
    # USD (Y up, cm) (120, 150, -40) is Blender (Z up, m) (1.2, 0.4, 1.5); a 30 degree pan about
    # USD's +Y turns the view from -Z toward -X: USD (-0.5, 0, -0.866), Blender (-0.5, 0.866, 0)
    assert out["pos"] == pytest.approx([1.2, 0.4, 1.5], abs=1e-6)
    assert out["fwd"] == pytest.approx([-0.5, math.sqrt(3) / 2, 0.0], abs=1e-6)
    # the companion's focal length: the best-match pinhole, s' of the 35 mm thin lens at 3 m
    assert out["lens"] == pytest.approx(image_distance_at_mark(35.0, 3000.0), rel=1e-5)


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


def test_blender_keeps_the_iris_and_resolution_that_its_importer_does_not_apply(tmp_path):
    """Blender's USD importer reads no iris or resolution (UsdGeomCamera has none; it ignores
    UsdRenderSettings): physcam writes them as userProperties, which Blender keeps on the camera, and
    the documented snippet applies them (issue 24 item 3)."""
    spec = CameraSpec.of(focal_length_mm=35.0, fstop=2.8, focus_mm=3000.0, sensor_width_mm=36.0, sensor_height_mm=24.0,
                      aperture_blades=6, aperture_angle_deg=15.0)
    f = write_camera(tmp_path / "cam.usda", spec, resolution=(1234, 823))
    out = run_blender('''
import bpy, json, sys
for o in list(bpy.data.objects):
    bpy.data.objects.remove(o)
bpy.ops.wm.usd_import(filepath=sys.argv[1])
obj = [o for o in bpy.data.objects if o.type == "CAMERA"][0]
scene = bpy.context.scene
before = {"blades": obj.data.dof.aperture_blades, "res": [scene.render.resolution_x, scene.render.resolution_y]}
''' + APPLY_IMPORTED + '''
apply_physcam_properties(obj, scene)
print(json.dumps({"before": before, "blades": obj.data.dof.aperture_blades,
                  "rotation": obj.data.dof.aperture_rotation, "ratio": obj.data.dof.aperture_ratio,
                  "res": [scene.render.resolution_x, scene.render.resolution_y]}))
''', f)
    assert out["before"]["blades"] == 0 and out["before"]["res"] != [1234, 823]  # what the importer alone gives
    assert out["blades"] == 6 and out["res"] == [1234, 823]
    assert math.degrees(out["rotation"]) == pytest.approx(15.0 + 30.0, abs=1e-4)
    assert out["ratio"] == pytest.approx(1.0)

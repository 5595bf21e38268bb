"""Issue 9.1 with Blender's USD importer as the independent consumer: Blender has never heard of
physcam's schema, and places the companion camera where physcam put it (schema fallback types)."""

import math

import pytest

from physcam.usd.author import CameraSpec, write_camera

from _blender import run_blender
from _thin_lens import image_distance_at_mark

pytestmark = pytest.mark.slow


def test_blender_imports_the_camera_in_place(tmp_path):
    f = write_camera(tmp_path / "cam.usda", CameraSpec(focal_length_mm=35.0, fstop=2.8, focus_mm=3000.0,
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

"""The Blender environment `make test` builds: bpy imports, Cycles compiles and runs an OSL camera."""

import pytest

from _blender import run_blender

pytestmark = pytest.mark.slow


def test_cycles_renders_through_an_osl_camera(tmp_path):
    """An OSL camera that kills the rays of the left half of the frame, looking at a uniformly
    bright world: the left half renders black, the right half bright (the shader really ran)."""
    out = run_blender('''
import bpy, json, sys
scene = bpy.context.scene
scene.render.engine = "CYCLES"
scene.cycles.device = "CPU"
scene.cycles.shading_system = True
scene.cycles.samples = 1
scene.render.resolution_x = scene.render.resolution_y = 32
scene.render.resolution_percentage = 100
for o in list(bpy.data.objects):
    if o.type != "CAMERA":
        bpy.data.objects.remove(o)
world = bpy.data.worlds.new("W"); scene.world = world; world.use_nodes = True
world.node_tree.nodes["Background"].inputs["Strength"].default_value = 1.0
world.node_tree.nodes["Background"].inputs["Color"].default_value = (1.0, 1.0, 1.0, 1.0)
src = """
shader cam(output point position = 0, output vector direction = 0, output color throughput = 1) {
  point s = camera_shader_raster_position();
  position = point(0, 0, 0);
  direction = vector(s[0] - 0.5, s[1] - 0.5, 1.0);
  throughput = s[0] < 0.5 ? color(0) : color(1);
}
"""
t = bpy.data.texts.new("cam.osl"); t.write(src)
cam = scene.camera.data
cam.type = "CUSTOM"; cam.custom_mode = "INTERNAL"; cam.custom_shader = t
scene.render.image_settings.file_format = "OPEN_EXR"
scene.render.filepath = sys.argv[1]
bpy.ops.render.render(write_still=True)
img = bpy.data.images.load(sys.argv[1])
px = list(img.pixels)
w, h = img.size
left = [px[4 * (y * w + x)] for y in range(h) for x in range(w // 2 - 2)]
right = [px[4 * (y * w + x)] for y in range(h) for x in range(w // 2 + 2, w)]
print(json.dumps({"version": bpy.app.version_string, "left": max(left), "right": min(right)}))
''', tmp_path / "half.exr")
    assert out["version"].startswith("5.")
    assert out["left"] == 0.0 and out["right"] > 0.5

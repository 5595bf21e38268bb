"""The extension's camera frames as Blender's own: the same sensor fit (Auto, Horizontal, Vertical)
in any frame aspect. For each frame (16:9 with a 36 x 24 mm sensor; portrait 9:16 with each sensor
fit) four small lights 30 m away are placed at +-40 % of the half frame that Blender's camera shows
(``Camera.view_frame``: the rectangle the viewport draws and EEVEE renders), and rendered through the
physcam camera (Cycles, the OSL shader) and through the matched built-in camera: both put every light
where Blender's own frame puts it. (The shader used to map the whole sensor onto any frame: a 16:9
render of a 36 x 24 mm sensor was squashed 16 % vertically.)"""

from __future__ import annotations

import json

import numpy as np
import pytest

from _blender import installed_dark_scene, light_centroid, run_blender_log

pytestmark = pytest.mark.slow

LENS = "dgauss_50mm"
CASES = [("16:9, auto", 96, 54, "AUTO"), ("9:16, auto", 54, 96, "AUTO"), ("9:16, horizontal", 54, 96, "HORIZONTAL"),
         ("9:16, vertical", 54, 96, "VERTICAL")]
SPOT = 0.4  # the lights at this fraction of the half frame (the real lens distorts little there)
DIST = 30.0  # m from the camera object

FRAMING = installed_dark_scene(samples=32) + '''
scene.render.resolution_percentage = 100
mat = glow("E", 20.0)
p = cam.physcam
p.lens = sys.argv[2]; p.sensor = "CUSTOM"; p.sensor_width = 36.0; p.sensor_height = 24.0
p.focus_distance = float(sys.argv[4]); p.fstop = 8.0; p.enabled = True
spot = float(sys.argv[5])

def render(name, w, h):
    scene.render.filepath = sys.argv[6] + f"/{name}.exr"
    bpy.ops.render.render(write_still=True)
    img = bpy.data.images.load(scene.render.filepath)
    a = np.array(img.pixels[:], dtype=np.float64).reshape(h, w, 4)[..., 0]
    bpy.data.images.remove(img)
    return a.tolist()

out = {}
for label, w, h, fit in json.loads(sys.argv[3]):
    scene.render.resolution_x, scene.render.resolution_y = w, h
    cam.sensor_fit = fit
    bpy.context.view_layer.update()  # the add-on copies the fit into the shader
    for o in [o for o in bpy.data.objects if o.type == "MESH"]:
        bpy.data.objects.remove(o)
    frame = [tuple(v) for v in cam.view_frame(scene=scene)]  # camera space, on the plane z = -d
    xs, ys, d = [v[0] for v in frame], [v[1] for v in frame], -frame[0][2]
    x0, x1, y0, y1 = min(xs), max(xs), min(ys), max(ys)
    lights, expect = [], []
    for sx in (-spot, spot):
        for sy in (-spot, spot):
            u, v = 0.5 + sx / 2, 0.5 + sy / 2  # where Blender's frame puts it (0..1 from the bottom left)
            X, Y = (x0 + u * (x1 - x0)) * float(sys.argv[7]) / d, (y0 + v * (y1 - y0)) * float(sys.argv[7]) / d
            lights.append((X, Y))
            expect.append((u * w - 0.5, v * h - 0.5))
            r = 1.25 * (x1 - x0) / d / w * float(sys.argv[7])  # an image 2.5 px across: no sub-pixel binning
            bpy.ops.mesh.primitive_uv_sphere_add(radius=r, location=(X, Y, -float(sys.argv[7])), segments=24, ring_count=12)
            bpy.context.object.data.materials.append(mat)
    cam.type = "CUSTOM"
    p.debug_view = "NONE"
    osl = render("osl_" + fit, w, h)
    p.debug_view = "BUILTIN"  # the matched built-in camera (viewport, EEVEE)
    builtin = render("builtin_" + fit, w, h)
    p.debug_view = "NONE"
    out[label] = {"osl": osl, "builtin": builtin, "expect": expect, "frame_mm": [x1 - x0, y1 - y0, d],
                  "shader_fit": cam.cycles_custom["sensor_fit"], "message": p.message}
print(json.dumps(out))
'''


@pytest.fixture(scope="module")
def framing(extension_zip, extension_user, tmp_path_factory):
    tmp = tmp_path_factory.mktemp("framing")
    out, log = run_blender_log(FRAMING, extension_zip, LENS, json.dumps(CASES), DIST + 0.05, SPOT, tmp, DIST,
                               env=extension_user)
    return out, log


@pytest.mark.parametrize("case", [c[0] for c in CASES])
def test_render_viewport_and_builtin_frame_alike(framing, case):
    """Blender's frame for the case (its width and height on the film follow Blender's rule: auto fits
    the 36 mm to the frame's longer side, horizontal to its width, vertical the 24 mm to its height);
    every light lands within 0.3 px of where that frame puts it, through the physcam shader and the
    built-in camera alike."""
    out, log = framing
    res = out[case]
    label, w, h, fit = next(c for c in CASES if c[0] == case)
    fw, fh, _ = res["frame_mm"]
    # Blender's sensor fit (BKE_camera_params_compute_viewplane), in film mm at the focal length
    want_w = {"AUTO": 36.0 if w >= h else 36.0 * w / h, "HORIZONTAL": 36.0, "VERTICAL": 24.0 * w / h}[fit]
    assert fw / fh == pytest.approx(w / h, rel=1e-4)
    assert res["message"] == "" and res["shader_fit"] == {"AUTO": 0, "HORIZONTAL": 1, "VERTICAL": 2}[fit]
    err = {}
    for name in ("osl", "builtin"):
        img = np.array(res[name])
        for c, r in res["expect"]:
            gc, gr = light_centroid(img, c, r, win=4)
            print(f"{case} {name}: light at ({gc:.2f}, {gr:.2f}) px, Blender's frame ({c:.2f}, {r:.2f})")
            err[name] = max(err.get(name, 0.0), float(np.hypot(gc - c, gr - r)))
    assert err["osl"] < 0.3 and err["builtin"] < 0.3, (case, err)
    assert "Dependency cycle" not in log
    print(f"{case}: frame {fw:.4f} x {fh:.4f} (view_frame units), Blender's rule {want_w:.3f} mm wide")

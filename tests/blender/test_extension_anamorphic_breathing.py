"""The extension breathes per axis (issue 49): Cycles renders Neil's front 2x through the physcam
camera at two focus marks, with four small lights on each plane of focus, and each light lands where
that mark's framing focal length *of its own meridian* puts it, within 1 %; between the marks the X
and Y image sizes change by the hand-traced breathing of each meridian, within 1 %. The panel says
both framing focal lengths and both pivots, from the same tables.

Oracle: tests/_anamorphic_yu.py, a y-u trace by hand of the lens file in each meridian (framing focal
length = a pinhole at that meridian's entrance pupil; both pupils), through the gaps the focus solver
set. The picture is the film image, squeezed (docs/blender.md), so x on the film is f_x X / (D - p_x),
D the plane's distance from the film and p_x the X pupil's.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from _anamorphic_yu import hand_framing_focal_lengths, hand_pupils_from_film
from _blender import installed_dark_scene, light_centroid, run_blender_log

pytestmark = pytest.mark.slow

LENS = "neil_front_anamorphic_2x"
SENSOR_MM = (18.0, 13.5)
W, H = 160, 120  # square pixels on the film: 160 / 18 = 120 / 13.5
MARKS_MM = (1000.0, 5000.0)  # its closest focus is 985 mm; the squeeze breathes 2.048 -> 1.991
SPOT_MM = (2.7, 2.0)  # where the lights land on the film, mm from the centre (~30 % of the half frame)

SCENE = installed_dark_scene(samples=48) + '''
scene.render.resolution_x, scene.render.resolution_y = int(sys.argv[3]), int(sys.argv[4])
scene.render.resolution_percentage = 100
cam.type = "CUSTOM"
mat = glow("E", 50.0)
p = cam.physcam
p.lens = sys.argv[2]; p.sensor = "CUSTOM"; p.sensor_width = 18.0; p.sensor_height = 13.5; p.fstop = 8.0
p.enabled = True
mod = next(m for name, m in sys.modules.items() if name.endswith(".physcam") and hasattr(m, "on_set_numbers"))
out = {}
for mark in json.loads(sys.argv[5]):
    for o in [o for o in bpy.data.objects if o.type == "MESH"]:
        bpy.data.objects.remove(o)
    p.focus_distance = mark["focus_m"]
    bpy.context.view_layer.update()
    for X, Y, r in mark["lights"]:
        bpy.ops.mesh.primitive_uv_sphere_add(radius=r, location=(X, Y, -mark["plane_m"]), segments=24, ring_count=12)
        bpy.context.object.data.materials.append(mat)
    scene.render.filepath = sys.argv[6] + f"/m{mark['focus_m']:g}.exr"
    bpy.ops.render.render(write_still=True)
    img = bpy.data.images.load(scene.render.filepath)
    a = np.array(img.pixels[:], dtype=np.float64).reshape(scene.render.resolution_y, scene.render.resolution_x, 4)
    bpy.data.images.remove(img)
    out[str(mark["focus_m"])] = {"image": a[..., 0].tolist(), "panel": mod.on_set_numbers(cam), "message": p.message}
print(json.dumps(out))
'''


def _marks():
    """Per mark: the hand-traced framing focal lengths and pupils, and four lights on its plane of focus
    at the same angles from each meridian's pupil at every mark (metres; the camera object is the Y
    entrance pupil, docs/blender.md, so the plane of focus is the mark less that pupil in front of it):
    the angles the first mark's focal lengths image at (+-SPOT_MM)."""
    fx0, fy0 = hand_framing_focal_lengths(LENS, MARKS_MM[0])
    tx, ty = SPOT_MM[0] / fx0, SPOT_MM[1] / fy0
    marks = []
    for d in MARKS_MM:
        (fx, fy), (px, py) = hand_framing_focal_lengths(LENS, d), hand_pupils_from_film(LENS, d)
        r = 1.1 * (SENSOR_MM[1] / H) * (d - py) / fy / 1000.0  # an image ~2.2 px across
        lights = [(sx * tx * (d - px) / 1000.0, sy * ty * (d - py) / 1000.0, r) for sx in (-1, 1) for sy in (-1, 1)]
        marks.append({"focus_m": d / 1000.0, "plane_m": (d - py) / 1000.0, "lights": lights, "f": (fx, fy), "pupils": (px, py),
                      "want_mm": (fx * tx, fy * ty)})
    return marks


@pytest.fixture(scope="module")
def renders(extension_zip, extension_user, tmp_path_factory):
    tmp = tmp_path_factory.mktemp("anamorphic_breathing")
    marks = _marks()
    out, _ = run_blender_log(SCENE, extension_zip, LENS, W, H, json.dumps(marks), tmp,
                             env=extension_user)
    return marks, out


def _spans(img, want_mm):
    """Mean |x|, |y| (mm on the film, from the centre) of the four lights' centroids; rows from the bottom."""
    px = SENSOR_MM[0] / W
    xs, ys = [], []
    for sx in (-1, 1):
        for sy in (-1, 1):
            c, r = W / 2 - 0.5 + sx * want_mm[0] / px, H / 2 - 0.5 + sy * want_mm[1] / px
            gc, gr = light_centroid(img, c, r, win=5)
            xs.append(abs(gc - (W / 2 - 0.5)) * px)
            ys.append(abs(gr - (H / 2 - 0.5)) * px)
    return float(np.mean(xs)), float(np.mean(ys))


def test_each_meridian_frames_as_its_own_focal_length(renders):
    """At each mark a light lands at f_x tan(angle_x), f_y tan(angle_y): each meridian's own focal length."""
    marks, out = renders
    for m in marks:
        res = out[str(m["focus_m"])]
        assert res["message"] == ""
        x, y = _spans(np.array(res["image"]), m["want_mm"])
        print(f"{m['focus_m']} m: lights at {x:.4f} x {y:.4f} mm, the hand trace's "
              f"{m['want_mm'][0]:.4f} x {m['want_mm'][1]:.4f} mm")
        assert x == pytest.approx(m["want_mm"][0], rel=0.01) and y == pytest.approx(m["want_mm"][1], rel=0.01)


def test_between_the_marks_each_axis_breathes_as_traced(renders):
    """The same angles at both marks: the image grows by each meridian's framing focal length's ratio
    (X 6.3 %, Y 3.4 % from 1 m to 5 m), the X and Y apart."""
    marks, out = renders
    (a, b) = marks
    sa = _spans(np.array(out[str(a["focus_m"])]["image"]), a["want_mm"])
    sb = _spans(np.array(out[str(b["focus_m"])]["image"]), b["want_mm"])
    for k, axis in enumerate("XY"):
        want, got = b["f"][k] / a["f"][k], sb[k] / sa[k]
        print(f"{axis}: the render breathes x{got:.4f}, the hand trace x{want:.4f}")
        assert got == pytest.approx(want, rel=0.01)
    assert b["f"][0] / a["f"][0] - b["f"][1] / a["f"][1] > 0.02  # the meridians breathe apart: not one squeeze


def test_the_panel_says_both_meridians(renders):
    marks, out = renders
    for m in marks:
        v = out[str(m["focus_m"])]["panel"]
        fx, fy = m["f"]
        px, py = m["pupils"]
        assert v["pinhole_mm"] == pytest.approx(fy, rel=2e-3)  # the table interpolated in 1/distance
        assert v["pinhole_mm"] / v["pinhole_squeeze"] == pytest.approx(fx, rel=2e-3)
        assert v["pupil_x_from_film_mm"] == pytest.approx(px, abs=0.2)
        assert v["pupil_from_film_mm"] == pytest.approx(py, abs=0.2)

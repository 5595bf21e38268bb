"""The extension's zoom control (issue 45): a keyed zoom rendered the way a farm renders it.

The shot: the Canon 70-200 (US 5,537,259) on a 36 x 24 mm sensor, the zoom keyed at 72.118 mm (its
first tabulated position), 100 mm (between positions, on the interpolated cams) and 134.948 mm (its
second) on frames 1-3, the focus keyed so the plane of focus holds two small lights 6 m in front of
the camera object (the entrance pupil) at every frame, f/8. An artist's Blender saves it on frame 3; a
fresh Blender *without* the extension opens it and renders ``animation=True``. On every frame the
lights land at physcam's pinhole focal length at that frame's zoom and focus (the library's lens
report at :func:`physcam.optics.zoom.at_zoom`, independent of the shader) x their angle, within 1 %
(a frame at the saved frame's zoom misses by 35-87 %); at the two tabulated positions that pinhole
agrees with a hand ray-transfer-matrix trace of the lens file (tests/_zoom_abcd.py: the magnification
of the lens focused as a whole on the lights' plane) within 1 %. The panel's numbers and the built-in
camera's keyed focal length follow the same zoom.
"""

from __future__ import annotations

import json
import tomllib
from importlib import resources

import numpy as np
import pytest

from _blender import installed_dark_scene, light_centroid, run_blender_log
from _zoom_abcd import abcd_position, abcd_unit_focus_magnification

pytestmark = pytest.mark.slow

LENS = "canon_ef_70_200mm_f2_8_zoom"
SW, SH, W, H = 36.0, 24.0, 120, 80  # square pixels, 0.3 mm
DIST_MM = 6000.0  # the lights' plane, from the camera object (the entrance pupil)
X_MM = 530.0  # the lights at +-X: 6.4 mm (21 px) on the film at 72 mm, 11.9 mm at 135 mm
R_MM = 25.0  # the lights' radius: ~1 px across at 72 mm


def _doc():
    return tomllib.loads(resources.files("physcam.data").joinpath("lenses", f"{LENS}.toml").read_text(encoding="utf-8"))


def _zooms():
    """Frame 1 and 3: the first two tabulated positions, as the hand trace's EFL; frame 2 between them."""
    doc = _doc()
    return [abcd_position(doc, 0)[0], 100.0, abcd_position(doc, 1)[0]]


def _report(zoom_mm, mark_mm):
    """(pinhole focal length, entrance pupil in front of the film) mm: physcam's lens report at the zoom."""
    from physcam.lens.library import load_lens
    from physcam.onset.request import report_camera
    from physcam.onset.solvers import field_of_view, lens_at_mark
    from physcam.optics.sensors import custom_sensor
    from physcam.optics.zoom import at_zoom

    lens = at_zoom(load_lens(LENS), f"{zoom_mm!r}mm")
    inputs = report_camera(sensor=custom_sensor(SW, SH), fstop=8.0, focus_mm=mark_mm, lens=lens)
    at = lens_at_mark(inputs.camera)
    fov = field_of_view(inputs.camera, at.h2_from_film_mm, inputs.references, at)
    return fov["pinhole_focal_length_mm"], at.pupil_from_film_mm


@pytest.fixture(scope="module")
def predictions():
    """Per frame: the zoom, the focus mark (m, film to the lights' plane: 6 m + the pupil), physcam's
    pinhole there and the lights' predicted distance from the centre on the film (mm)."""
    out = []
    for z in _zooms():
        mark = DIST_MM
        for _ in range(4):  # the mark that puts the plane of focus 6 m from the pupil
            f_pin, pupil = _report(z, mark)
            mark = DIST_MM + pupil
        out.append({"zoom_mm": z, "focus_m": mark / 1000.0, "pinhole_mm": f_pin, "pupil_mm": pupil,
                    "x_mm": f_pin * X_MM / DIST_MM})
    return out


ARTIST = installed_dark_scene(samples=48) + '''
scene.render.resolution_x, scene.render.resolution_y, scene.render.resolution_percentage = int(sys.argv[3]), int(sys.argv[4]), 100
scene.render.use_border = True; scene.render.use_crop_to_border = False  # the lights' rows only
scene.render.border_min_x, scene.render.border_max_x, scene.render.border_min_y, scene.render.border_max_y = 0.0, 1.0, 0.4, 0.6
mat = glow("E", 50.0)
x, dist, r = (float(v) / 1000.0 for v in sys.argv[6:9])
for sx in (-1, 1):
    bpy.ops.mesh.primitive_uv_sphere_add(radius=r, location=(sx * x, 0.0, -dist), segments=24, ring_count=12)
    bpy.context.object.data.materials.append(mat)
p = cam.physcam
p.lens = sys.argv[5]; p.sensor = "CUSTOM"; p.sensor_width = 36.0; p.sensor_height = 24.0; p.fstop = 8.0
p.enabled = True
p.zoom_focal_length = 250.0  # beyond the lens's 72.1-193.9 mm
bad = p.message
keys = json.loads(sys.argv[9])
for frame, (z, d) in enumerate(keys, start=1):
    p.zoom_focal_length = z; p.focus_distance = d
    p.keyframe_insert("zoom_focal_length", frame=frame); p.keyframe_insert("focus_distance", frame=frame)
scene.frame_start, scene.frame_end = 1, len(keys)
scene.frame_set(len(keys))
mod = next(m for name, m in sys.modules.items() if name.endswith(".physcam") and hasattr(m, "on_set_numbers"))
panel = [mod.on_set_numbers(cam, focus_m=d, zoom_mm=z) for z, d in keys]
bpy.ops.wm.save_as_mainfile(filepath=sys.argv[2] + "/shot.blend", copy=True)  # the add-on syncs before a save
from bpy_extras import anim_utils
lens_fc = anim_utils.action_get_channelbag_for_slot(cam.animation_data.action, cam.animation_data.action_slot).fcurves.find("lens")
print(json.dumps({"bad": bad, "message": p.message, "panel": panel, "builtin_lens": [lens_fc.evaluate(f) for f in range(1, len(keys) + 1)]}))
'''

FARM = '''
import json, sys
import numpy as np
bpy.ops.wm.open_mainfile(filepath=sys.argv[1])
scene = bpy.context.scene
scene.render.filepath = sys.argv[2] + "/frame_####"
bpy.ops.render.render(animation=True)
W, H = scene.render.resolution_x, scene.render.resolution_y
frames = {}
for f in range(scene.frame_start, scene.frame_end + 1):
    img = bpy.data.images.load(sys.argv[2] + f"/frame_{f:04d}.exr")
    frames[f] = np.array(img.pixels[:], dtype=np.float64).reshape(H, W, 4)[..., 0].tolist()
    bpy.data.images.remove(img)
print(json.dumps({"frames": frames, "extension": hasattr(bpy.types.Camera, "physcam")}))
'''


@pytest.fixture(scope="module")
def renders(extension_zip, extension_user, tmp_path_factory, predictions):
    tmp = tmp_path_factory.mktemp("zoom")
    keys = [(p["zoom_mm"], p["focus_m"]) for p in predictions]
    built, _ = run_blender_log(ARTIST, extension_zip, tmp, W, H, LENS, X_MM, DIST_MM, R_MM, json.dumps(keys),
                               env=extension_user)
    (tmp / "farm").mkdir()
    farm, _ = run_blender_log(FARM, tmp / "shot.blend", tmp / "farm", env={"BLENDER_USER_RESOURCES": str(tmp / "user_farm")})
    return built, farm


def _half_span_mm(img, x_mm):
    """Half the distance (mm on the film) between the two lights' centroids, looked for about +-x_mm."""
    pitch = SW / W
    got = []
    for sx in (-1, 1):
        c, _ = light_centroid(img, W / 2 - 0.5 + sx * x_mm / pitch, H / 2 - 0.5, win=5)
        got.append(c)
    return abs(got[1] - got[0]) / 2 * pitch


def test_every_frame_frames_the_lights_at_its_own_zoom(renders, predictions):
    """Each frame (saved on frame 3, rendered by a Blender without the extension): the lights' half
    span within 1 % of physcam's pinhole at that frame's zoom and focus."""
    built, farm = renders
    assert built["message"] == ""
    assert not farm["extension"]
    assert sorted(farm["frames"]) == ["1", "2", "3"]
    for frame, pred in enumerate(predictions, start=1):
        got = _half_span_mm(np.array(farm["frames"][str(frame)]), pred["x_mm"])
        print(f"frame {frame}, zoom {pred['zoom_mm']:.3f} mm: lights at +-{got:.4f} mm, physcam's pinhole "
              f"{pred['pinhole_mm']:.3f} mm puts them at +-{pred['x_mm']:.4f} mm")
        assert got == pytest.approx(pred["x_mm"], rel=0.01)
    xs = [p["x_mm"] for p in predictions]
    assert xs[2] / xs[0] > 1.8  # the zoom moves them far more than the tolerance: no frame at another's zoom


def test_the_pinhole_agrees_with_a_hand_abcd_trace_at_the_tabulated_positions(predictions):
    """Frames 1 and 3 sit at tabulated positions 0 and 1: the lens focused as a whole on the lights'
    plane magnifies them by the hand trace's m, so x = |m| X; physcam's pinhole says f X / 6 m."""
    doc = _doc()
    for k, pred in ((0, predictions[0]), (1, predictions[2])):
        m = abcd_unit_focus_magnification(doc, k, pred["focus_m"] * 1000.0)
        print(f"position {k}: hand ABCD x = {abs(m) * X_MM:.4f} mm, physcam's pinhole {pred['x_mm']:.4f} mm")
        assert abs(m) * X_MM == pytest.approx(pred["x_mm"], rel=0.01)


def test_the_panel_and_the_builtin_camera_follow_the_zoom(renders, predictions):
    """The panel's pinhole (the table in zoom x 1/distance) and the built-in camera's keyed focal length
    at each frame: physcam's pinhole at that zoom and focus within 0.3 %. A zoom beyond the lens's
    range (its paraxial EFL from the hand trace's first to last tabulated position) is refused in one
    sentence naming the range."""
    built, _ = renders
    doc = _doc()
    lo, hi = abcd_position(doc, 0)[0], abcd_position(doc, 2)[0]
    assert built["bad"] == (f"Canon EF 70-200mm f/2.8 L (US 5,537,259) zooms from {lo:.2f} to {hi:.2f} mm (paraxial EFL "
                            "at infinity; asked 250 mm). The render keeps the last valid camera.")
    for pred, v, lens in zip(predictions, built["panel"], built["builtin_lens"]):
        assert v["pinhole_mm"] == pytest.approx(pred["pinhole_mm"], rel=3e-3)
        assert lens == pytest.approx(pred["pinhole_mm"], rel=3e-3)
        assert v["pupil_from_film_mm"] == pytest.approx(pred["pupil_mm"], abs=0.5)

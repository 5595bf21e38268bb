"""The OSL camera's ray-quadric root is the tracer's forward crossing (trace/kernels/_numba.py
``_intersect_quadric``), not the root nearest the ray's start (the shader before issue 28 item 2).

The two differ where a steep ray meets a nearly hemispherical surface twice on its near cap: the
first meeting crosses the surface backwards (from the medium after it into the one before), the
second forwards. A lens whose rear surface is a deep bowl opening toward the film (R = +8 mm, clear
semi-diameter 7.9 mm) shows it: light from the film 12 mm and more off axis comes in from beside
the bowl. physcam's tracer passes those rays; the nearest root refracted them at the backward
meeting and clipped nearly all beyond 15 mm (a numpy copy of both root rules: 4 of 225 random film
rays passed at 15-18 mm where the forward crossing passes all 225). Rendered: a uniform white world
through the baked camera; the edge of the frame is as bright as physcam's ``camera_rays`` says.
"""

from __future__ import annotations

import json
import math

import pytest

from _blender import predicted_block_brightness, run_blender
from test_blender_camera import SCENE
from physcam.export.blender import bake_camera, osl_camera_shader
from physcam.lens.library import load_lens
from physcam.optics.state import camera_state

pytestmark = pytest.mark.slow

#: A thick positive meniscus whose rear surface is a deep bowl toward the film (made up for this test).
BOWL = '''format = "physcam-lens/1"

[lens]
name = "Deep bowl rear surface (test)"
focal_length = 20.0
max_fstop = 4.0

[[surface]]
kind = "stop"
radius = 0.0
thickness = 1.0
semi_diameter = 3.0
medium = "air"

[[surface]]
kind = "spherical"
radius = 5.0
thickness = 3.0
semi_diameter = 4.9
medium = { nd = 1.5168, vd = 64.2 }

[[surface]]
kind = "spherical"
radius = 8.0
thickness = 30.0
semi_diameter = 7.9
medium = "air"
'''


def test_rays_from_beside_a_deep_bowl_pass_as_in_the_tracer(tmp_path):
    """White world, 36 x 24 px over a 36 x 24 mm film, the lens at infinity: the pixel blocks 15-17 mm
    off axis render the relative illumination physcam's camera_rays predicts (mean over the pupil
    table, float64) within 0.05 (seen 0.1249 rendered, 0.1249 predicted); the nearest-root shader
    (the old root code put back into the template) rendered 0.0016 there and fails."""
    path = tmp_path / "bowl.toml"
    path.write_text(BOWL)
    lens = load_lens(str(path))
    sw, sh, W, H = 36.0, 24.0, 36, 24
    cam = camera_state(lens, focus_mm=math.inf, sensor_mm=(sw, sh))
    b = bake_camera(cam)
    src = osl_camera_shader(cam)
    blocks = {"centre": (10, 14, 16, 20), "left": (10, 14, 0, 3), "right": (10, 14, 33, 36)}
    predicted = predicted_block_brightness(b, blocks, W, H, (sw, sh))
    (tmp_path / "cam.osl").write_text(src)
    out = run_blender(SCENE + '''
set_world(1.0)
scene.cycles.shading_system = True
scene.cycles.use_adaptive_sampling = False
text = bpy.data.texts.new("cam.osl"); text.write(open(sys.argv[1]).read())
cam = cam_obj.data
cam.type = "CUSTOM"; cam.custom_mode = "INTERNAL"; cam.custom_shader = text
scene.cycles.filter_width = 0.01   # box-like: a pixel averages its own film area
a = render(sys.argv[2] + "/white.exr", int(sys.argv[3]), int(sys.argv[4]), 256)
blocks = json.loads(sys.argv[5])
print(json.dumps({k: float(a[r0:r1, c0:c1, :3].mean()) for k, (r0, r1, c0, c1) in blocks.items()}))
''', tmp_path / "cam.osl", tmp_path, W, H, json.dumps(blocks))
    print({k: (round(out[k], 4), round(predicted[k], 4)) for k in blocks})
    assert predicted["right"] > 0.05 and predicted["left"] > 0.05  # the tracer passes light there
    for k in blocks:
        assert abs(out[k] - predicted[k]) < 0.05, (k, out[k], predicted[k])

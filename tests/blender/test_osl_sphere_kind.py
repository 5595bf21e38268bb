"""The OSL camera's shortcut for spheres (physcam.export.osl.SPHERE_KIND: a quadric with AX = AY = AZ
meets a unit direction with A = AX, and its gradient on the surface is a unit vector, so it is not
normalised again) gives the rays of the generic quadric code, in Cycles itself.

The same shader is rendered twice with the same seeds, once as written (the double Gauss's ten
spheres marked kind 4) and once with every sphere marked a generic quadric (kind 2, the code before
round 10): a world whose colour is the ray's direction plus (2, 2, 2), so each pixel is the camera
ray's weight times its direction. The two pictures agree to float32 rounding (seen: 3e-7 relative;
with the spheres' A made 1e-4 too large, 9e-6: caught), and the same pixels are dark (rays the lens
stops).

The renders keep Cycles' scene from one to the next (``use_persistent_data``, tests/blender/test_blender_camera.py's
SCENE; round 20): the direction world's OSL is compiled once (Blender's CPU 2.9 -> 1.8 s, the pictures the same bit
for bit). Persistent data is a cache, and a stale one would make the comparison pass whatever the generic code
does (the extension's ghost test saw a camera parameter kept from an earlier render, round 20): so a canary
shader, the sphere shader with its throughput times 1.001, is rendered between the two compared, and must come
out 1.001 times the first picture; the generic shader's render follows it, so a stale one would be the
canary's, 1e-3 off.
"""

from __future__ import annotations

import re

import numpy as np
import pytest

from _blender import DIRECTION_WORLD, run_blender
from test_blender_camera import SCENE
from physcam.export.blender import osl_camera_shader
from physcam.export.osl import SPHERE_KIND
from physcam.lens.library import load_lens
from physcam.optics.state import camera_state

pytestmark = pytest.mark.slow

_KIND = re.compile(r"int KIND\[N_SURF\] = \{([^}]*)\};")


def _generic(src: str) -> str:
    """The shader with its spheres marked generic quadrics (kind 2)."""
    kinds = [int(k) for k in _KIND.search(src).group(1).split(",")]
    generic = ", ".join(str(2 if k == SPHERE_KIND else k) for k in kinds)
    return _KIND.sub(f"int KIND[N_SURF] = {{{generic}}};", src)


def test_sphere_shortcut_gives_the_generic_quadrics_rays(tmp_path):
    """48 x 32 px, 2 samples, seed 0, f/2.8 focused at 2.5 m: lit pixels within 2e-6 relative of the
    generic code's, the dark pixels the same but for at most 1 % (a ray grazing a rim)."""
    lens = load_lens("dgauss_50mm")
    src = osl_camera_shader(camera_state(lens, focus_mm=2500.0, fstop=2.8, sensor_mm=(36.0, 24.0)))
    kinds = [int(k) for k in _KIND.search(src).group(1).split(",")]
    assert kinds.count(SPHERE_KIND) == 10  # every glass surface of the double Gauss is a sphere
    (tmp_path / "sphere.osl").write_text(src)
    (tmp_path / "generic.osl").write_text(_generic(src))
    assert src.count("    throughput = color(w);\n") == 1
    (tmp_path / "canary.osl").write_text(src.replace("    throughput = color(w);\n", "    throughput = color(w * 1.001);\n"))
    out = run_blender(SCENE + DIRECTION_WORLD + '''
direction_world()
scene.cycles.shading_system = True
scene.cycles.use_adaptive_sampling = False
scene.cycles.seed = 0
scene.view_settings.view_transform = "Standard"
scene.render.image_settings.color_depth = "32"
cam = cam_obj.data
cam.type = "CUSTOM"; cam.custom_mode = "INTERNAL"
pics = {}
for name in ("sphere", "canary", "generic"):  # the canary between the two compared (module notes)
    text = bpy.data.texts.new(name + ".osl"); text.write(open(sys.argv[1] + "/" + name + ".osl").read())
    cam.custom_shader = text
    pics[name] = render(sys.argv[1] + "/" + name + ".exr", 48, 32, 2)[..., :3].tolist()
print(json.dumps(pics))
''', tmp_path)
    a, b = np.array(out["sphere"]), np.array(out["generic"])
    lit_a, lit_b = a.sum(axis=2) > 0, b.sum(axis=2) > 0
    assert lit_b.mean() > 0.5  # most of the frame sees the world through the lens
    assert (lit_a != lit_b).mean() <= 0.01
    both = lit_a & lit_b
    rel = np.abs(a[both] - b[both]) / np.abs(b[both])
    print("max relative difference", float(rel.max()), "pixels lit", int(both.sum()))
    assert float(rel.max()) < 2e-6
    lit = a > 0  # the canary's render is its own: 1.001 times the sphere shader's, not the render before
    np.testing.assert_allclose(np.array(out["canary"])[lit] / a[lit], 1.001, rtol=1e-5)

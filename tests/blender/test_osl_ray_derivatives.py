"""The OSL camera hands Cycles the traced ray unchanged and the ray derivatives of Blender's own
perspective camera (docs/blender.md, Conventions): the traced ray goes to the outputs through an OSL
message, which carries no derivatives, so OSL does not carry them through the lens trace (a third of a
sample's price, docs/performance.md round 13); the direction's derivatives are the pinhole's through
the pixel at the lens's paraxial focal length.

In Cycles itself, double Gauss focused at 2.5 m, f/2.8, 48 x 32 px, 8 samples, seed 0:

- the shader as written and the shader with the traced ray written to the outputs directly (the code
  before round 13) render a world whose colour is the ray's direction plus (2, 2, 2) alike to 8 units
  in the last place of the EXR's float32 (the same bits on the Xeons of rounds 13-19; an AVX-512 Xeon
  gave up to 4 in 770 of the 4608 values: OSL's JIT fuses multiply-adds differently in different code);
- a white world through the shader with the throughput replaced by three derivatives (the output
  direction's, the traced direction's as OSL differentiates the trace itself, and the raster
  position's): at the frame's centre the output's is the pinhole's in closed form, 2 (w / 2) Dx(u) / f
  (f: physcam.optics.paraxial.gaussian's EFL), and off the axis the trace's own is within 5 % of it
  (seen: 0.03-2 %).

The renders keep Cycles' scene from one to the next (``use_persistent_data``; round 20): the direction
world's OSL is compiled once, not for each of the two compared renders (Blender's CPU 3.1 -> 2.0 s, the
pictures the same bit for bit). Persistent data is a cache, and a stale one would make the comparison pass
whatever the direct shader does (the extension's ghost test saw a camera parameter kept from an earlier
render, round 20): so a canary shader, the message shader with its throughput times 1.001, is rendered
between the two compared, and must come out 1.001 times the first picture; the direct shader's render
follows it, so a stale one would be the canary's, 1000 ulps off.
"""

from __future__ import annotations

import re

import numpy as np
import pytest

from _blender import DIRECTION_WORLD, run_blender
from test_blender_camera import SCENE
from physcam.export.blender import osl_camera_shader
from physcam.lens.library import load_lens
from physcam.optics import paraxial
from physcam.optics.state import camera_state

pytestmark = pytest.mark.slow

_OUT = re.compile(r"    float pin_f = .*?\n    direction = vector\(ray_in\[3\][^\n]*\n", re.S)
_DIRECT = ("    position = point(px * 0.001, py * 0.001, (FILM_Z - pz) * 0.001);\n"
           "    direction = vector(dx, dy, -dz);\n")
#: The canary's throughput: the message shader's picture times 1.001 (module notes)
_CANARY = "    throughput = color(w * 1.001);\n"
_DERIVS = ("    vector traced = vector(dx, dy, -dz);\n    point raster = camera_shader_raster_position();\n"
           "    vector d_raster = Dx(raster);\n"
           "    throughput = color(length(Dx(direction)), length(Dx(traced)), d_raster[0]);\n")

RUN = SCENE + DIRECTION_WORLD + '''
from cycles import osl
scene.cycles.shading_system = True
scene.cycles.use_adaptive_sampling = False
scene.cycles.seed = 0
scene.render.image_settings.color_depth = "32"
cam = cam_obj.data
cam.type = "CUSTOM"; cam.custom_mode = "INTERNAL"
pics = {}
scene.render.use_persistent_data = True  # the direction world compiled once for three renders (module notes)
direction_world()
for name in ("message", "canary", "direct", "derivs"):  # the canary between the two compared (module notes)
    if name == "derivs":
        set_world(1.0)
    text = bpy.data.texts.new(name + ".osl"); text.write(open(sys.argv[1] + "/" + name + ".osl").read())
    cam.custom_shader = text
    errors = []
    osl.update_custom_camera_shader(cam, lambda kind, msg: errors.append(msg) if "ERROR" in kind else None)
    assert not errors, (name, errors)  # else Cycles would keep the last shader that compiled
    pics[name] = render(sys.argv[1] + "/" + name + ".exr", 48, 32, 8)[..., :3].tolist()
print(json.dumps(pics))
'''


def test_traced_ray_unchanged_and_pinhole_derivatives(tmp_path):
    lens = load_lens("dgauss_50mm")
    src = osl_camera_shader(camera_state(lens, focus_mm=2500.0, fstop=2.8, sensor_mm=(36.0, 24.0)))
    assert len(_OUT.findall(src)) == 1 and src.count("    throughput = color(w);\n") == 1
    (tmp_path / "message.osl").write_text(src)
    (tmp_path / "direct.osl").write_text(_OUT.sub(_DIRECT, src))
    (tmp_path / "derivs.osl").write_text(src.replace("    throughput = color(w);\n", _DERIVS))
    (tmp_path / "canary.osl").write_text(src.replace("    throughput = color(w);\n", _CANARY))
    out = run_blender(RUN, tmp_path)
    a, b = np.array(out["message"]), np.array(out["direct"])
    assert (b.sum(axis=2) > 0).mean() > 0.5  # most of the frame sees the world through the lens
    np.testing.assert_array_max_ulp(a.astype(np.float32), b.astype(np.float32), maxulp=8)
    lit = a > 0  # the canary's render is its own: 1.001 times the message shader's, not the render before
    np.testing.assert_allclose(np.array(out["canary"])[lit] / a[lit], 1.001, rtol=1e-5)

    d = np.array(out["derivs"])  # row 0 = bottom; a pixel: the mean over its samples (lost rays: 0)
    lit = d[..., 2] > 0
    centre = d[15:17, 23:25].reshape(-1, 3)
    assert lit[15:17, 23:25].all()
    efl = paraxial.gaussian(lens).efl
    pinhole = 2.0 * 18.0 * centre[:, 2] / efl  # |d normalize(-fx / f, -fy / f, 1) / dx| at fx = fy = 0
    np.testing.assert_allclose(centre[:, 0], pinhole, rtol=2e-3)
    ys, xs = np.mgrid[0:32, 0:48]
    r = np.hypot((xs + 0.5) / 48 - 0.5, ((ys + 0.5) / 32 - 0.5) * 32 / 48)  # film radius over the width
    off = lit & (r > 0.2)
    assert off.sum() > 500
    ratio = d[off][:, 1] / d[off][:, 0]
    print("traced over pinhole derivative off axis:", float(ratio.min()), float(ratio.max()))
    assert np.all(np.abs(ratio - 1.0) < 0.05)

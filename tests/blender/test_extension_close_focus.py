"""The extension's shader at a unit-focusing lens's closest focus (its 1:1 conjugate, where the focus
tables' last interval used to miss the film plane by millimetres): the double Gauss 50 focused at
0.198 m, f/2.1, a small light on the axis at that mark renders as sharp as physcam's forward trace of
the exact focus state says (rms radius 1.00-1.03 px rendered over three seeds, 0.97 px traced). With
the tables of round 6 (marks uniform in 1/distance, linear) the shader put the film 4.26 mm off there
and the spot came out 3.4 px."""

from __future__ import annotations

import math

import numpy as np
import pytest

from _blender import installed_dark_scene, run_blender
from physcam.export.blender import bake_camera
from physcam.lens.library import load_lens
from physcam.optics.state import camera_state
from physcam.trace.rays import RayBatch
from physcam.trace.trace import trace_to_film

pytestmark = pytest.mark.slow

SLUG, MARK_MM, FSTOP = "dgauss_50mm", 198.0, 2.1
SW, SH, W, H, HALF = 36.0, 24.0, 384, 256, 12  # the render: a 24 px window about the frame's centre
LIGHT_MM = 0.05  # the light's radius: its image (about 0.45 px across) is in the trace's prediction too

SPOT = installed_dark_scene(samples=1024) + '''
scene.render.resolution_x, scene.render.resolution_y, scene.render.resolution_percentage = %d, %d, 100
scene.render.use_border = True; scene.render.use_crop_to_border = False
scene.render.border_min_x, scene.render.border_max_x = 0.5 - %d / %d, 0.5 + %d / %d
scene.render.border_min_y, scene.render.border_max_y = 0.5 - %d / %d, 0.5 + %d / %d
cam.clip_start = 0.001
p = cam.physcam
p.lens = sys.argv[3]; p.sensor = "CUSTOM"; p.sensor_width = %r; p.sensor_height = %r
p.focus_distance = float(sys.argv[4]); p.fstop = float(sys.argv[5]); p.enabled = True
bpy.ops.mesh.primitive_uv_sphere_add(radius=float(sys.argv[7]), location=(0.0, 0.0, -float(sys.argv[6])), segments=24, ring_count=12)
bpy.context.object.data.materials.append(glow("E", 1.0e6))
scene.render.filepath = sys.argv[2] + "/spot.exr"
bpy.ops.render.render(write_still=True)
img = bpy.data.images.load(scene.render.filepath)
a = np.array(img.pixels[:], dtype=np.float64).reshape(%d, %d, 4)[..., 0]
print(json.dumps({"message": p.message, "img": a.tolist()}))
''' % (W, H, HALF, W, HALF, W, HALF, H, HALF, H, SW, SH, H, W)


def _traced_rms_px(lens) -> tuple[float, float]:
    """(rms radius in px of physcam's forward trace of the light, a disk of LIGHT_MM radius on the axis
    MARK_MM in front of the film (a sphere's even glow), through the lens focused there at FSTOP, on its
    film; the entrance pupil's distance from the film, mm). 200,000 rays from random points of the disk to
    random points of the front vertex's clear disk (a fixed seed)."""
    cam = camera_state(lens, focus_mm=MARK_MM, fstop=FSTOP, sensor_mm=(SW, SH))
    b = bake_camera(cam)
    rng = np.random.default_rng(1)
    n = 200_000

    def disk(radius):
        r, a = radius * np.sqrt(rng.random(n)), 2 * np.pi * rng.random(n)
        return r * np.cos(a), r * np.sin(a)

    (sx, sy), (tx, ty) = disk(LIGHT_MM), disk(b.lens.surfaces[0].semi_diameter)
    z = b.film_z - MARK_MM
    origin = np.stack([sx, sy, np.full(n, z)], axis=1)
    d = np.stack([tx - sx, ty - sy, np.full(n, -z)], axis=1)
    res = trace_to_film(b.lens, RayBatch.from_arrays(origin, d, lens.wavelength_nm), b.film_z)
    ok = res.ok
    rms = math.sqrt(np.average(res.x[ok] ** 2 + res.y[ok] ** 2, weights=res.weight[ok]))
    return rms / (SW / W), cam.at_mark.pupil_from_film_mm


def test_a_point_at_the_closest_focus_renders_sharp(extension_zip, extension_user, tmp_path):
    """The light's rms radius in the render (about its centroid, px) equals the trace's, its 1 px box
    filter added (rms^2 + 1/6 px^2), within 0.15 px; it lands on the frame's centre within 0.15 px."""
    lens = load_lens(SLUG)
    want, pupil_mm = _traced_rms_px(lens)
    out = run_blender(SPOT, extension_zip, tmp_path, SLUG, MARK_MM / 1000.0, FSTOP, (MARK_MM - pupil_mm) / 1000.0,
                      LIGHT_MM / 1000.0, env=extension_user)
    assert out["message"] == ""
    img = np.clip(np.array(out["img"]), 0, None)
    yy, xx = np.indices(img.shape)
    cx, cy = (img * xx).sum() / img.sum(), (img * yy).sum() / img.sum()
    rms = math.sqrt((img * ((xx - cx) ** 2 + (yy - cy) ** 2)).sum() / img.sum())
    expected = math.sqrt(want ** 2 + 1 / 6)
    print(f"rms radius: rendered {rms:.3f} px, traced {want:.3f} px (with the pixel {expected:.3f}); centroid "
          f"{cx - (W / 2 - 0.5):+.3f}, {cy - (H / 2 - 0.5):+.3f} px off the centre")
    assert abs(cx - (W / 2 - 0.5)) < 0.15 and abs(cy - (H / 2 - 0.5)) < 0.15
    assert rms == pytest.approx(expected, abs=0.15)

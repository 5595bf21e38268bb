"""Benchmark: Cycles render time through physcam's real-lens OSL camera against Blender's built-in
camera matched to the same lens report, at equal samples, and the time to generate and compile
the shader. Run in the Blender environment (make blender):

    .venv-blender/bin/python benchmarks/blender_render.py [--lens dgauss_50mm] [--samples 64]
"""

from __future__ import annotations

import argparse
import glob
import runpy
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "src"))


def _scene(scene, samples, w, h):
    import bpy

    for o in list(bpy.data.objects):
        if o.type != "CAMERA":
            bpy.data.objects.remove(o)
    cam = scene.camera
    cam.location, cam.rotation_euler = (0.0, 0.0, 0.0), (0.0, 0.0, 0.0)
    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.samples = samples
    scene.cycles.use_denoising = False
    scene.render.resolution_x, scene.render.resolution_y, scene.render.resolution_percentage = w, h, 100
    world = bpy.data.worlds.new("W")
    scene.world = world
    world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.2
    for i in range(-3, 4):
        for j in range(-2, 3):
            bpy.ops.mesh.primitive_uv_sphere_add(radius=0.05, location=(0.4 * i, 0.4 * j, -2.5 - 0.3 * (i % 2)))


def _render(scene, path) -> float:
    import bpy

    scene.render.filepath = str(path)
    t0 = time.perf_counter()
    bpy.ops.render.render(write_still=True)
    return time.perf_counter() - t0


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--lens", default="dgauss_50mm")
    ap.add_argument("--samples", type=int, default=64)
    args = ap.parse_args()
    import bpy

    for p in glob.glob(bpy.utils.resource_path("LOCAL") + "/python/lib/python3*/site-packages"):
        sys.path.insert(0, p)
    from physcam.export.blender import blender_setup_script, osl_camera_shader
    from physcam.export.blender_camera import blender_camera_script, blender_camera_values
    from physcam.lens.library import load_lens
    from physcam.onset.report import solve_lens_report
    from physcam.onset.sensors import find_sensor

    lens = load_lens(args.lens)
    w, h = 320, 214
    tmp = Path(tempfile.mkdtemp())
    scene = bpy.context.scene
    _scene(scene, args.samples, w, h)
    t0 = time.perf_counter()
    src = osl_camera_shader(lens, focus_mm=2500.0, fstop=2.8, sensor_width_mm=36.0, sensor_height_mm=24.0)
    t_gen = time.perf_counter() - t0
    setup = tmp / "setup.py"
    setup.write_text(blender_setup_script(src, sensor_width_mm=36.0, sensor_height_mm=24.0, resolution=(w, h)))
    t0 = time.perf_counter()
    runpy.run_path(str(setup), run_name="physcam_setup")["apply"](scene)
    t_compile = time.perf_counter() - t0
    t_osl = _render(scene, tmp / "osl.png")
    report = solve_lens_report(focal_length_mm=None, sensor=find_sensor("FF"), fstop=2.8, focus_mm=2500.0, lens=lens)
    builtin = tmp / "builtin.py"
    builtin.write_text(blender_camera_script(blender_camera_values(report, resolution_x=w)))
    scene.camera.data.type = "PERSP"
    runpy.run_path(str(builtin), run_name="physcam_builtin")["apply"](scene)
    t_builtin = _render(scene, tmp / "builtin.png")
    print(f"lens {lens.name}, {w} x {h} px, {args.samples} samples, Cycles CPU")
    print(f"shader generation {t_gen:.2f} s, set-up and compile {t_compile:.2f} s")
    print(f"render: OSL real-lens camera {t_osl:.2f} s, built-in camera {t_builtin:.2f} s, "
          f"ratio {t_osl / t_builtin:.2f}")


if __name__ == "__main__":
    main()

"""Benchmark: Cycles render time through physcam's real-lens OSL cameras against Blender's built-in
camera matched to the same lens report, at equal samples and at EQUAL NOISE, and the time to
generate and compile the shader. Run in the Blender environment (make blender):

    .venv-blender/bin/python benchmarks/blender_render.py [--lens dgauss_50mm] [--fstop 2.8] [--samples 64]

Cameras: ``baked`` (``physcam export blender``: one focus and stop, the pupil table of the
stopped-down lens), ``extension`` (the extension's focus-table shader: focus and f-stop are
parameters, the pupil table is the open lens's) and ``builtin`` (``--builtin``'s values).

Noise: each camera renders the scene twice with different seeds; the noise is the RMS of the two
pictures' difference over sqrt(2) (Monte Carlo noise only, whatever the picture). Noise falls as
1/sqrt(samples), so a camera with noise s at n samples needs n (s / s_ref)^2 samples to match the
built-in camera's s_ref; its equal-noise time is its time per sample times that. The script checks
that law by rendering the OSL cameras again at the samples it predicts.
"""

from __future__ import annotations

import argparse
import glob
import math
import runpy
import sys
import tempfile
import time
import zipfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "src"))
FOCUS_MM = 2500.0


def _scene(scene, w, h):
    import bpy

    for o in list(bpy.data.objects):
        if o.type != "CAMERA":
            bpy.data.objects.remove(o)
    cam = scene.camera
    cam.location, cam.rotation_euler = (0.0, 0.0, 0.0), (0.0, 0.0, 0.0)
    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.use_denoising = False
    scene.cycles.use_adaptive_sampling = False
    scene.render.threads_mode = "FIXED"
    scene.render.threads = 2
    scene.render.image_settings.file_format = "OPEN_EXR"
    scene.render.resolution_x, scene.render.resolution_y, scene.render.resolution_percentage = w, h, 100
    world = bpy.data.worlds.new("W")
    scene.world = world
    world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.2
    for i in range(-3, 4):
        for j in range(-2, 3):
            bpy.ops.mesh.primitive_uv_sphere_add(radius=0.05, location=(0.4 * i, 0.4 * j, -2.5 - 0.3 * (i % 2)))
    # a floor and a back wall under a soft area light: shadows and shading that are noisy in any camera
    bpy.ops.mesh.primitive_plane_add(size=20.0, location=(0.0, -1.0, -3.0))
    bpy.ops.mesh.primitive_plane_add(size=20.0, location=(0.0, 0.0, -4.0))
    bpy.context.object.rotation_euler = (math.pi / 2, 0.0, 0.0)
    bpy.ops.object.light_add(type="AREA", location=(1.0, 2.0, -1.5))
    bpy.context.object.data.energy = 300.0
    bpy.context.object.data.size = 1.0


def _render(scene, path, samples, seed):
    """(seconds, picture as a numpy array)."""
    import bpy
    import numpy as np

    scene.cycles.samples = samples
    scene.cycles.seed = seed
    scene.render.filepath = str(path)
    t0 = time.perf_counter()
    bpy.ops.render.render(write_still=True)
    dt = time.perf_counter() - t0
    img = bpy.data.images.load(str(path))
    a = np.array(img.pixels[:], dtype=np.float64)
    bpy.data.images.remove(img)
    return dt, a


def _noise(scene, tmp, name, samples):
    """(seconds per render, noise): two renders, seeds 0 and 1."""
    t1, a = _render(scene, tmp / f"{name}_{samples}_0.exr", samples, 0)
    t2, b = _render(scene, tmp / f"{name}_{samples}_1.exr", samples, 1)
    return 0.5 * (t1 + t2), float(((a - b) ** 2).mean() ** 0.5 / math.sqrt(2))


def _cameras(lens, fstop, w, h, tmp):
    """Set-up callables per camera name."""
    import bpy

    from physcam.export.blender import blender_setup_script, osl_camera_shader
    from physcam.export.blender_camera import blender_camera_script, blender_camera_values
    from physcam.export.blender_extension import build_extension
    from physcam.onset.report import solve_lens_report
    from physcam.optics.sensors import find_sensor

    src = osl_camera_shader(lens, focus_mm=FOCUS_MM, fstop=fstop, sensor_width_mm=36.0, sensor_height_mm=24.0)
    setup = tmp / "setup.py"
    setup.write_text(blender_setup_script(src, sensor_width_mm=36.0, sensor_height_mm=24.0, resolution=(w, h)))
    slug = Path(lens.name).stem
    zp = build_extension(tmp, lenses=[ARGS.lens])
    with zipfile.ZipFile(zp) as z:
        ext_src = z.read(f"shaders/{Path(ARGS.lens).stem}__d0f0.osl").decode()
    report = solve_lens_report(focal_length_mm=None, sensor=find_sensor("FF"), fstop=fstop, focus_mm=FOCUS_MM, lens=lens)
    builtin = tmp / "builtin.py"
    builtin.write_text(blender_camera_script(blender_camera_values(report, resolution_x=w)))

    def baked(scene):
        runpy.run_path(str(setup), run_name="physcam_setup")["apply"](scene)

    def extension(scene):
        baked(scene)  # Cycles, OSL, sensor and resolution as the baked camera
        cam = scene.camera.data
        text = bpy.data.texts.new(f"{slug}_ext.osl")
        text.write(ext_src)
        cam.custom_shader = text
        from cycles import osl

        osl.update_custom_camera_shader(cam, lambda *a: None)
        cam.cycles_custom["focus_distance"] = FOCUS_MM / 1000.0
        cam.cycles_custom["fstop"] = fstop

    def builtin_cam(scene):
        scene.camera.data.type = "PERSP"
        runpy.run_path(str(builtin), run_name="physcam_builtin")["apply"](scene)

    return {"baked": baked, "extension": extension, "builtin": builtin_cam}


def main() -> None:
    global ARGS
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--lens", default="dgauss_50mm")
    ap.add_argument("--fstop", type=float, default=2.8)
    ap.add_argument("--samples", type=int, default=32)
    ARGS = args = ap.parse_args()
    import bpy

    for p in glob.glob(bpy.utils.resource_path("LOCAL") + "/python/lib/python3*/site-packages"):
        sys.path.insert(0, p)
    from physcam.lens.library import load_lens

    lens = load_lens(args.lens)
    w, h = 240, 160
    tmp = Path(tempfile.mkdtemp())
    scene = bpy.context.scene
    _scene(scene, w, h)
    cams = _cameras(lens, args.fstop, w, h, tmp)
    n = args.samples
    res = {}
    for name in ("builtin", "baked", "extension"):
        cams[name](scene)
        res[name] = _noise(scene, tmp, name, n)
    t_ref, s_ref = res["builtin"]
    print(f"lens {lens.name}, focus {FOCUS_MM / 1000:g} m, f/{args.fstop:g}, {w} x {h} px, Cycles CPU, 2 threads")
    cap = 32 * n
    print(f"| camera | time at {n} samples | noise at {n} | samples for the built-in's noise | time at equal noise "
          f"| ratio to built-in | check: noise at those samples |")
    print("| --- | --- | --- | --- | --- | --- | --- |")
    for name in ("builtin", "baked", "extension"):
        t, s = res[name]
        need = max(1, round(n * (s / s_ref) ** 2))
        if need > cap:
            print(f"| {name} | {t:.2f} s | {s:.5f} | {need} (over {cap}: not rendered) | {t / n * need:.2f} s (time per "
                  f"sample x samples) | {t / n * need / t_ref:.2f} | - |")
            continue
        if name == "builtin":
            check, t_eq = f"{s:.5f}", t
        else:
            cams[name](scene)
            t_eq, s_eq = _noise(scene, tmp, name, need)
            check = f"{s_eq:.5f} (measured, {t_eq:.2f} s)"
        print(f"| {name} | {t:.2f} s | {s:.5f} | {need} | {t_eq:.2f} s | {t_eq / t_ref:.2f} | {check} |")


if __name__ == "__main__":
    main()

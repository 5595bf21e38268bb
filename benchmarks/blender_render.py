"""Benchmark: the CPU cost of Cycles renders through physcam's real-lens OSL cameras against Blender's
built-in camera matched to the same lens report, AT EQUAL NOISE, at several f-stops on two scenes.
Run in the Blender environment (make blender):

    .venv-blender/bin/python benchmarks/blender_render.py [--lens dgauss_50mm] [--fstops 2.8 5.6 16] [--samples 32] [--repeat 3]

``--repeat N`` renders each seed N times and takes the fewest CPU seconds (every camera alike): a render's
CPU time on a shared machine moves 10-20 % between runs, its picture not at all.

Cameras: ``builtin`` (``--builtin``'s values: a thin lens at the entrance pupil), ``baked``
(``physcam export blender``: one focus and stop, the 2-D pupil table of the stopped-down lens) and
``extension`` (the extension's focus-table shader: focus and f-stop are parameters, aim points drawn
from physcam.export.blender_pupil's ellipses; ``--cameras`` picks them, default the built-in and the
extension). Scenes: ``room`` (35 diffuse spheres in front of a floor and a back wall lit by a soft
area light), ``outdoor`` (diffuse spheres at, in front of and behind the focus on a ground plane
under a sky and a sun) and ``glow`` (small glowing spheres under a dim world: nothing to shade, so
the camera's own cost per ray is most of the render's; the worst case for a traced camera).

Noise: each camera renders the scene twice with different seeds; the noise is the RMS of the two
pictures' difference over sqrt(2) (Monte Carlo noise only, whatever the picture). Noise falls as
1/sqrt(samples), so a camera with noise s at n samples needs n (s / s_ref)^2 samples to match the
built-in camera's s_ref; the script renders it again at those samples (again from the noise reached
while that is over s_ref by more than 3 %; the check column: the noise reached) and reports that
render's CPU seconds (the process's, all of Cycles' threads: the machine
may be shared, so wall time would measure the neighbours) over the built-in camera's. The built-in
camera renders with Cycles' own shading (SVM), as an artist renders it; an OSL camera switches the
whole render to OSL shading, so its ratio is also given against the built-in camera rendered with
OSL shading (the camera's own price).
"""

from __future__ import annotations

import argparse
import glob
import math
import os
import runpy
import sys
import tempfile
import time
import zipfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "src"))
FOCUS_MM = 2500.0
W, H = 240, 160


def _common(scene, strength):
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
    scene.render.resolution_x, scene.render.resolution_y, scene.render.resolution_percentage = W, H, 100
    world = bpy.data.worlds.new("W")
    scene.world = world
    world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Strength"].default_value = strength


def scene_glow(scene):
    """Small glowing spheres at the focus (2.5 m), nearer (1.2 m) and farther (6 m) under a dim world:
    the noise is the out-of-focus spheres' bokeh, what the camera's aperture sampling draws."""
    import bpy

    _common(scene, 0.05)
    mat = bpy.data.materials.new("glow")
    mat.use_nodes = True
    nt = mat.node_tree
    nt.nodes.clear()
    em = nt.nodes.new("ShaderNodeEmission")
    em.inputs["Strength"].default_value = 5.0
    nt.links.new(em.outputs[0], nt.nodes.new("ShaderNodeOutputMaterial").inputs[0])
    for z, step, r in ((-2.5, 0.4, 0.03), (-1.2, 0.2, 0.015), (-6.0, 1.0, 0.08)):
        for i in range(-3, 4):
            for j in range(-2, 3):
                bpy.ops.mesh.primitive_uv_sphere_add(radius=r, location=(step * i + 0.07 * z, step * j, z))
                bpy.context.object.data.materials.append(mat)


def scene_outdoor(scene):
    """Diffuse spheres at, in front of and behind the focus on a ground plane under a sky and a sun:
    the sky's occlusion and soft shadows, noisy in any camera."""
    import bpy

    _common(scene, 1.0)
    for z, step, r in ((-2.5, 0.4, 0.06), (-1.2, 0.2, 0.03), (-6.0, 1.0, 0.15)):
        for i in range(-3, 4):
            for j in range(-2, 3):
                bpy.ops.mesh.primitive_uv_sphere_add(radius=r, location=(step * i + 0.07 * z, step * j, z))
    bpy.ops.mesh.primitive_plane_add(size=40.0, location=(0.0, -1.2, -10.0))
    bpy.ops.object.light_add(type="SUN", rotation=(0.6, 0.3, 0.0))
    bpy.context.object.data.energy = 3.0
    bpy.context.object.data.angle = 0.05


def scene_room(scene):
    """35 diffuse spheres in front of a floor and a back wall under a soft area light and a dim world:
    shadows and shading that are noisy in any camera."""
    import bpy

    _common(scene, 0.2)
    for i in range(-3, 4):
        for j in range(-2, 3):
            bpy.ops.mesh.primitive_uv_sphere_add(radius=0.05, location=(0.4 * i, 0.4 * j, -2.5 - 0.3 * (i % 2)))
    bpy.ops.mesh.primitive_plane_add(size=20.0, location=(0.0, -1.0, -3.0))
    bpy.ops.mesh.primitive_plane_add(size=20.0, location=(0.0, 0.0, -4.0))
    bpy.context.object.rotation_euler = (math.pi / 2, 0.0, 0.0)
    bpy.ops.object.light_add(type="AREA", location=(1.0, 2.0, -1.5))
    bpy.context.object.data.energy = 300.0
    bpy.context.object.data.size = 1.0


SCENES = {"room": scene_room, "outdoor": scene_outdoor, "glow": scene_glow}


def _render(scene, path, samples, seed):
    """(CPU seconds of this process during the render, picture as a numpy array)."""
    import bpy
    import numpy as np

    scene.cycles.samples = samples
    scene.cycles.seed = seed
    scene.render.filepath = str(path)
    t0 = time.process_time()
    bpy.ops.render.render(write_still=True)
    dt = time.process_time() - t0
    img = bpy.data.images.load(str(path))
    a = np.array(img.pixels[:], dtype=np.float64)
    bpy.data.images.remove(img)
    return dt, a


REPEAT = 1  # renders of each seed timed (--repeat): the fastest is its CPU time


def _timed(scene, path, samples, seed):
    """(the fewest CPU seconds of REPEAT renders of one seed, its picture): a render's CPU time on a shared
    machine moves by 10-20 % from run to run (other processes' cache and memory traffic), the picture not at
    all (a seed's render is deterministic), so the fastest of a few is the render's own cost, as timeit takes
    the fastest of its repeats."""
    runs = [_render(scene, path, samples, seed) for _ in range(REPEAT)]
    return min(t for t, _ in runs), runs[0][1]


def _noise(scene, tmp, name, samples):
    """(CPU seconds per render, noise): two renders, seeds 0 and 1 (each timed REPEAT times)."""
    t1, a = _timed(scene, tmp / f"{name}_{samples}_0.exr", samples, 0)
    t2, b = _timed(scene, tmp / f"{name}_{samples}_1.exr", samples, 1)
    return 0.5 * (t1 + t2), float(((a - b) ** 2).mean() ** 0.5 / math.sqrt(2))


def _cameras(lens, slug, fstop, tmp, ext_src):
    """Set-up callables per camera name."""
    import bpy

    from physcam.export.blender import blender_setup_script, osl_camera_shader
    from physcam.export.blender_camera import blender_camera_script, blender_camera_values
    from physcam.onset.report import solve_lens_report
    from physcam.optics.sensors import find_sensor
    from physcam.optics.state import camera_state

    src = osl_camera_shader(camera_state(lens, focus_mm=FOCUS_MM, fstop=fstop, sensor_mm=(36.0, 24.0)))
    setup = tmp / "setup.py"
    setup.write_text(blender_setup_script(src, sensor_width_mm=36.0, sensor_height_mm=24.0, resolution=(W, H)))
    report = solve_lens_report(focal_length_mm=None, sensor=find_sensor("FF"), fstop=fstop, focus_mm=FOCUS_MM, lens=lens)
    builtin = tmp / "builtin.py"
    builtin.write_text(blender_camera_script(blender_camera_values(report, resolution_x=W)))

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
        cam.cycles_custom["aspect"] = W / H
        # the built-in camera's full-frame gate (the shader's defaults are physcam's default sensor,
        # Super 35: a smaller, less vignetted frame than the built-in camera renders)
        cam.cycles_custom["sensor_width"] = 36.0
        cam.cycles_custom["sensor_height"] = 24.0

    def builtin_cam(scene):
        scene.camera.data.type = "PERSP"
        # Cycles' own shading (SVM), as an artist renders with the built-in camera: an OSL camera
        # switches the whole render to OSL shading (about 10 % slower here), part of its price
        scene.cycles.shading_system = False
        runpy.run_path(str(builtin), run_name="physcam_builtin")["apply"](scene)

    return {"builtin": builtin_cam, "baked": baked, "extension": extension}


def _row(scene, tmp, cams, name, n, ref):
    """One camera's table row: (CPU s at n, noise at n, samples for the built-in's noise, CPU s at them,
    ratio, noise reached). The samples are predicted by 1/sqrt(samples) and rendered; while the noise
    reached is over the built-in's by more than 3 %, the prediction is made again from it (up to 3 times)."""
    t, s = _noise(scene, tmp, name, n)
    t_ref, s_ref = ref or (t, s)
    need = max(1, round(n * (s / s_ref) ** 2))
    if ref is None:
        return t, s, n, t, 1.0, s
    cams[name](scene)
    for _ in range(3):
        t_eq, s_eq = _noise(scene, tmp, name, need)
        if s_eq <= 1.03 * s_ref:
            break
        need = math.ceil(need * (s_eq / s_ref) ** 2)
    return t, s, need, t_eq, t_eq / t_ref, s_eq


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--lens", default="dgauss_50mm")
    ap.add_argument("--fstops", type=float, nargs="+", default=[2.8, 5.6, 16.0])
    ap.add_argument("--samples", type=int, default=32)
    ap.add_argument("--scenes", nargs="+", default=list(SCENES), choices=list(SCENES))
    ap.add_argument("--cameras", nargs="+", default=["builtin", "extension"], choices=["builtin", "baked", "extension"])
    ap.add_argument("--repeat", type=int, default=1,
                    help="renders of each seed timed, the fastest taken (the same for every camera; default 1)")
    args = ap.parse_args()
    global REPEAT
    REPEAT = max(1, args.repeat)
    import bpy

    for p in glob.glob(bpy.utils.resource_path("LOCAL") + "/python/lib/python3*/site-packages"):
        sys.path.insert(0, p)
    from physcam.export.blender_extension import build_extension
    from physcam.export.blender_variant import variant_source
    from physcam.lens.library import load_lens

    lens = load_lens(args.lens)
    slug = Path(args.lens).stem
    tmp = Path(tempfile.mkdtemp())
    with zipfile.ZipFile(build_extension(tmp, lenses=[args.lens])) as z:  # dispersion and Fresnel off, as the add-on writes it
        ext_src = variant_source(z.read(f"shaders/{slug}.osl").decode(), dispersion=False, fresnel=False)
    load0 = os.getloadavg()
    n = args.samples
    print(f"lens {lens.name}, focus {FOCUS_MM / 1000:g} m, {W} x {H} px, Cycles CPU, 2 threads, {n} samples, "
          f"the fastest of {REPEAT} timed render(s) per seed; "
          f"load average at the start {load0[0]:.1f} (1 min), {os.cpu_count()} CPUs")
    print("| scene | f-stop | camera | CPU s at {n} samples | noise at {n} | samples for the built-in's noise | "
          "CPU s at equal noise | ratio to built-in | ratio to built-in under OSL shading | check: noise reached |"
          .format(n=n))
    print("| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |")
    scene = bpy.context.scene
    for scene_name in args.scenes:
        SCENES[scene_name](scene)
        for fstop in args.fstops:
            cams = _cameras(lens, slug, fstop, tmp, ext_src)
            ref = None
            for name in ["builtin"] + [c for c in args.cameras if c != "builtin"]:
                cams[name](scene)
                t, s, need, t_eq, ratio, s_eq = _row(scene, tmp, cams, name, n, ref)
                if ref is None:
                    ref = (t, s)
                    # the same built-in render with OSL shading (what the OSL cameras' renders use): the
                    # camera's own price, apart from the switch of the whole render to OSL
                    scene.cycles.shading_system = True
                    t_osl = _noise(scene, tmp, "builtin_osl", n)[0]
                    scene.cycles.shading_system = False
                print(f"| {scene_name} | f/{fstop:g} | {name} | {t:.2f} | {s:.5f} | {need} | {t_eq:.2f} | "
                      f"{ratio:.2f} | {t_eq / t_osl:.2f} (built-in {t_osl:.2f}) | {s_eq:.5f} |", flush=True)
    load1 = os.getloadavg()
    print(f"load average at the end {load1[0]:.1f} (1 min), {load1[2]:.1f} (15 min)")


if __name__ == "__main__":
    main()

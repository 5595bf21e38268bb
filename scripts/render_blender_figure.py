#!/usr/bin/env python3
"""Render docs/img/blender_osl_distagon.png: a grid of small lights through physcam's real-lens OSL
camera (Zeiss Distagon 35 mm, focused at 3 m, f/4, a six-blade iris), with three lights at 0.2 m
out of focus. The grid shows the lens's barrel distortion, the near lights its hexagonal bokeh.

Run in the Blender environment (make blender):
    .venv-blender/bin/python scripts/render_blender_figure.py [--out docs/img/blender_osl_distagon.png]
"""

from __future__ import annotations

import argparse
import glob
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "src"))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default=str(ROOT / "docs" / "img" / "blender_osl_distagon.png"))
    ap.add_argument("--samples", type=int, default=512)
    args = ap.parse_args()

    import bpy

    for p in glob.glob(bpy.utils.resource_path("LOCAL") + "/python/lib/python3*/site-packages"):
        sys.path.insert(0, p)  # Cycles compiles OSL through Blender's bundled oslquery
    from physcam.export.blender import blender_setup_script, osl_camera_shader
    from physcam.lens.library import load_lens
    from physcam.optics.state import camera_state
    from physcam.trace.aperture import Aperture

    lens = load_lens("zeiss_distagon_35mm_f4")
    W, H = 480, 320
    src = osl_camera_shader(camera_state(lens, focus_mm=3000.0, fstop=4.0, sensor_mm=(36.0, 24.0)),
                            aperture=Aperture(nsides=6, roundness=0.0))
    setup = Path(tempfile.mkdtemp()) / "setup.py"
    setup.write_text(blender_setup_script(src, sensor_width_mm=36.0, sensor_height_mm=24.0, resolution=(W, H)))
    scene = bpy.context.scene
    for o in list(bpy.data.objects):
        if o.type != "CAMERA":
            bpy.data.objects.remove(o)
    cam = scene.camera
    cam.location, cam.rotation_euler = (0.0, 0.0, 0.0), (0.0, 0.0, 0.0)
    import runpy

    runpy.run_path(str(setup), run_name="physcam_setup")["apply"](scene)
    scene.cycles.samples = args.samples
    scene.cycles.use_denoising = False
    scene.view_settings.view_transform = "Standard"
    world = bpy.data.worlds.new("black")
    scene.world = world
    world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.0

    def emitter(name, rgb, strength):
        m = bpy.data.materials.new(name)
        m.use_nodes = True
        nt = m.node_tree
        nt.nodes.clear()
        em = nt.nodes.new("ShaderNodeEmission")
        em.inputs["Color"].default_value = (*rgb, 1.0)
        em.inputs["Strength"].default_value = strength
        nt.links.new(em.outputs[0], nt.nodes.new("ShaderNodeOutputMaterial").inputs[0])
        return m

    grid, near = emitter("grid", (0.9, 0.95, 1.0), 4.0), emitter("near", (1.0, 0.75, 0.4), 120.0)
    d = 3.0 - 0.05  # metres in front of the camera origin (the film centre): the focused plane, about
    for i in range(-4, 5):
        for j in range(-2, 3):
            bpy.ops.mesh.primitive_uv_sphere_add(radius=0.012, location=(0.33 * i, 0.33 * j, -d))
            bpy.context.object.data.materials.append(grid)
    for x, y in ((-0.05, -0.02), (0.0, 0.025), (0.055, -0.03)):
        bpy.ops.mesh.primitive_uv_sphere_add(radius=0.002, location=(x, y, -0.2))
        bpy.context.object.data.materials.append(near)
    scene.render.image_settings.file_format = "PNG"
    scene.render.filepath = args.out
    bpy.ops.render.render(write_still=True)
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()

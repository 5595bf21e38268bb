#!/usr/bin/env python3
"""Render the physcam Blender extension's pictures in docs/blender.md from the tests' scenes:
docs/img/blender_ext_pull_1m.png and _5m.png (a focus pull keyframed 1 m -> 5 m through the double
Gauss 50 mm at f/2.1 with a 6-blade iris: lights 1 m away on the left, 5 m away on the right) and
docs/img/blender_ext_ghosts.png (a bright light 8 degrees below the axis through the double Gauss
50 mm at f/2.8, focused at infinity, Ghosts on: fraction 0.5, intensity 10 to show them).

The extension is built for those two lenses and installed by Blender's own installer into a
temporary user folder. Run in the Blender environment (make blender):
    .venv-blender/bin/python scripts/render_extension_figures.py [--samples 256]
"""

from __future__ import annotations

import argparse
import glob
import math
import os
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "src"))
IMG = ROOT / "docs" / "img"


def _emitter(bpy, strength):
    mat = bpy.data.materials.new("E")
    mat.use_nodes = True
    nt = mat.node_tree
    nt.nodes.clear()
    em = nt.nodes.new("ShaderNodeEmission")
    em.inputs[1].default_value = strength
    nt.links.new(em.outputs[0], nt.nodes.new("ShaderNodeOutputMaterial").inputs[0])
    return mat


def _sphere(bpy, mat, loc, r):
    bpy.ops.mesh.primitive_uv_sphere_add(radius=r, location=loc, segments=32, ring_count=16)
    bpy.context.object.data.materials.append(mat)


def _reset(bpy, scene, samples, w, h):
    for o in list(bpy.data.objects):
        if o.type != "CAMERA":
            bpy.data.objects.remove(o)
    scene.world = None
    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.use_denoising = False
    scene.cycles.samples = samples
    scene.render.resolution_x, scene.render.resolution_y, scene.render.resolution_percentage = w, h, 100
    scene.render.image_settings.file_format = "PNG"
    scene.view_settings.view_transform = "Standard"
    cam = scene.camera
    cam.location, cam.rotation_euler = (0.0, 0.0, 0.0), (0.0, 0.0, 0.0)
    return cam.data


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--samples", type=int, default=256)
    ap.add_argument("--ghost-samples", type=int, default=2048)
    args = ap.parse_args()
    tmp = Path(tempfile.mkdtemp(prefix="physcam-figures-"))
    os.environ["BLENDER_USER_RESOURCES"] = str(tmp / "user")  # before bpy starts: a fresh user folder
    from physcam.export.blender_extension import build_extension

    zp = build_extension(tmp, lenses=["zeiss_distagon_35mm_f4", "dgauss_50mm"])
    import bpy

    for p in glob.glob(bpy.utils.resource_path("LOCAL") + "/python/lib/python3*/site-packages"):
        sys.path.insert(0, p)  # Cycles compiles OSL through Blender's bundled oslquery
    bpy.ops.extensions.package_install_files(filepath=str(zp), repo="user_default", enable_on_install=True)
    scene = bpy.context.scene

    # the pull: 3 x 3 lights 1 m away on the left, 3 x 3 lights 5 m away on the right
    cam = _reset(bpy, scene, args.samples, 384, 256)
    mat = _emitter(bpy, 2.0)
    for i in range(3):
        for j in range(3):
            _sphere(bpy, mat, (-0.3 + 0.07 * i, -0.07 + 0.07 * j, -1.0), 0.004)
            _sphere(bpy, mat, (0.45 + 0.35 * i, -0.35 + 0.35 * j, -5.0), 0.02)
    p = cam.physcam
    p.lens = "dgauss_50mm"
    p.fstop = 2.1
    p.blades = 6
    p.focus_distance = 1.0
    p.enabled = True
    p.keyframe_insert("focus_distance", frame=1)
    p.focus_distance = 5.0
    p.keyframe_insert("focus_distance", frame=2)
    for frame, name in ((1, "1m"), (2, "5m")):
        scene.frame_set(frame)
        scene.render.filepath = str(IMG / f"blender_ext_pull_{name}.png")
        bpy.ops.render.render(write_still=True)

    # ghosts: a bright light 8 degrees below the axis, 1 km away
    cam = _reset(bpy, scene, args.ghost_samples, 320, 214)
    cam.clip_end = 1.0e5
    th = math.radians(8.0)
    _sphere(bpy, _emitter(bpy, 10.0), (0.0, -math.sin(th) * 1000.0, -math.cos(th) * 1000.0), 20.0)
    p = cam.physcam
    p.lens = "dgauss_50mm"
    p.fstop = 2.8
    p.focus_distance = 1.0e4
    p.ghosts = True
    p.ghost_fraction = 0.5
    p.ghost_intensity = 10.0
    p.enabled = True
    scene.render.filepath = str(IMG / "blender_ext_ghosts.png")
    bpy.ops.render.render(write_still=True)
    print("wrote", *(IMG / n for n in ("blender_ext_pull_1m.png", "blender_ext_pull_5m.png",
                                          "blender_ext_ghosts.png")))


if __name__ == "__main__":
    main()

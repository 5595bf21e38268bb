"""The scene of the Cycles proofs of ``physcam defocus`` (tests/blender/test_defocus_cycles.py and
test_defocus_cycles_anamorphic.py), shared: small emissive spheres and an emissive checker plane in
a black world, no bounces, a 1 px box filter; the real-lens (OSL) renders of the spheres alone made
only in the windows their bokeh is measured in; and the pinhole renders defocused by physcam.

The spheres' real-lens render is the proofs' costliest (256 samples a pixel through the OSL camera):
it is rendered in Cycles' render border, one border per measured window, into full frames black
outside it (``use_crop_to_border`` off). Cycles seeds a pixel's samples by its place in the frame, so
every pixel of a window is the one a full-frame render gives (checked on both proofs, 2026-11-28:
the windows' pixels and every other render bit for bit the same as before), at an eighth (the
anamorphic proof: 2 windows of 84 x 84 px of 384 x 288) and a thirteenth (52 x 52 and 42 x 42 px of
320 x 180) of the pixels.
"""

from __future__ import annotations

import numpy as np

from _blender import DARK_SCENE_CAMERA_AT_FILM
from physcam.analysis.defocus.exr import read_exr
from physcam.analysis.defocus.render import defocus, inverse_depth
from physcam.analysis.distortion.stmap import apply_stmap

#: The scene, built in Blender from ``job`` (sys.argv[1], JSON): ``spheres`` [[x, y, z, r] m], glowing
#: ``strength``; ``plane`` [z, width, height] m, a checker of ``checker_scale`` squares glowing 0.5.
#: Defines ``scene``, ``cam``, ``plane``, ``settings(samples)``, ``render(path)``,
#: ``render_windows(path, windows)`` (the frame rendered only in ``windows``, each [x0, x1, y0, y1] px,
#: y down from the top row, into one file per window: path + f"_w{i}.exr") and ``render_truth()``: the
#: real-lens renders, the spheres alone at ``samples_osl`` in ``windows`` (truth_spheres_w*.exr) and the
#: full scene at ``samples_osl_full`` (truth.exr).
SCENE = '''
import json, runpy, sys
job = json.loads(sys.argv[1])
''' + DARK_SCENE_CAMERA_AT_FILM + '''cam = cam_obj

def emissive(name, strength, checker=False):
    m = bpy.data.materials.new(name); m.use_nodes = True
    nt = m.node_tree; nt.nodes.clear()
    em = nt.nodes.new("ShaderNodeEmission"); em.inputs["Strength"].default_value = strength
    if checker:
        ck = nt.nodes.new("ShaderNodeTexChecker"); ck.inputs["Scale"].default_value = job["checker_scale"]
        ck.inputs["Color1"].default_value = (1.0, 0.8, 0.5, 1.0); ck.inputs["Color2"].default_value = (0.1, 0.2, 0.4, 1.0)
        nt.links.new(ck.outputs["Color"], em.inputs["Color"])
    nt.links.new(em.outputs[0], nt.nodes.new("ShaderNodeOutputMaterial").inputs[0])
    return m

glow = emissive("glow", job["strength"])
for x, y, z, r in job["spheres"]:
    bpy.ops.mesh.primitive_uv_sphere_add(radius=r, location=(x, y, z), segments=48, ring_count=24)
    bpy.context.object.data.materials.append(glow); bpy.ops.object.shade_smooth()
bpy.ops.mesh.primitive_plane_add(size=1.0, location=(0.0, 0.0, job["plane"][0]))
plane = bpy.context.object
plane.scale = (job["plane"][1], job["plane"][2], 1.0)
plane.data.materials.append(emissive("checker", 0.5, checker=True))

def settings(samples):
    scene.cycles.use_denoising = False
    scene.render.threads_mode = "FIXED"; scene.render.threads = 2
    scene.view_settings.view_transform = "Standard"
    scene.cycles.max_bounces = 0
    scene.cycles.pixel_filter_type = "BOX"; scene.cycles.filter_width = 1.0
    scene.cycles.samples = samples
    scene.cycles.seed = 1

def render(path):
    scene.render.image_settings.media_type = "IMAGE"
    scene.render.image_settings.file_format = "OPEN_EXR"
    scene.render.image_settings.color_depth = "32"
    scene.render.filepath = path
    bpy.ops.render.render(write_still=True)

def render_windows(path, windows):
    w, h = scene.render.resolution_x, scene.render.resolution_y
    scene.render.use_border = True; scene.render.use_crop_to_border = False
    for i, (x0, x1, y0, y1) in enumerate(windows):  # Blender's border: fractions of the frame, y up
        scene.render.border_min_x, scene.render.border_max_x = x0 / w, x1 / w
        scene.render.border_min_y, scene.render.border_max_y = (h - y1) / h, (h - y0) / h
        render(path + f"_w{i}.exr")
    scene.render.use_border = False

def render_truth():  # through physcam's OSL camera (job["setup"]), its origin the film centre
    cam.location, cam.rotation_euler = (0.0, 0.0, 0.0), (0.0, 0.0, 0.0)
    runpy.run_path(job["setup"], run_name="physcam_setup")["apply"](scene)
    settings(job["samples_osl"])
    plane.hide_render = True
    render_windows(job["out"] + "/truth_spheres", job["windows"])
    plane.hide_render = False
    scene.cycles.samples = job["samples_osl_full"]
    render(job["out"] + "/truth.exr")
'''


def windows_px(centres, box, width, height, pad=2):
    """The [x0, x1, y0, y1] pixel windows (y down) that hold ``box`` px either side of each centre (as
    the proofs' measuring windows round it), ``pad`` px more, inside the frame."""
    out = []
    for cx, cy in centres:
        x, y = int(round(cx)), int(round(cy))
        out.append([max(x - box - pad, 0), min(x + box + pad, width), max(y - box - pad, 0), min(y + box + pad, height)])
    return out


def read_rgb(path) -> np.ndarray:
    """An EXR's RGB, (h, w, 3), row 0 the top."""
    e = read_exr(path)
    return np.stack([e.channels[c] for c in "RGB"], axis=2)


def read_windows(path_stem: str, windows) -> np.ndarray:
    """The full frame of :func:`render_windows`' files: each window's pixels from its own render, black
    elsewhere."""
    parts = [read_rgb(f"{path_stem}_w{i}.exr") for i in range(len(windows))]
    out = np.zeros_like(parts[0])
    for (x0, x1, y0, y1), part in zip(windows, parts):
        out[y0:y1, x0:x1] = part[y0:y1, x0:x1]
    return out


def defocused(folder, tag: str, cam, cache, stmap) -> dict:
    """The pinhole render ``pinhole{tag}.exr`` (RGB), and physcam's defocus of it by its Z pass
    ``depth{tag}.exr`` (planar, metres): undistorted and redistorted by ``stmap``."""
    rgb = read_rgb(folder / f"pinhole{tag}.exr")
    u = inverse_depth(read_exr(folder / f"depth{tag}.exr").channels["R"], cam, kind="planar", unit="m")
    sharp = defocus(rgb, u, cache)
    return {"pinhole": rgb, "physcam_undistorted": sharp, "physcam": apply_stmap(sharp, stmap)}

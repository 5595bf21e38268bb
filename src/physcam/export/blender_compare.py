"""Side by side: a point light's bokeh through physcam's own tracer and through Cycles.

``physcam compare blender LENS`` renders one small emissive sphere at a known distance through
the generated OSL camera in Blender (a crop of the film centre, the shader made for that crop) and
traces the same light through the same focused, stopped-down prescription with physcam's numba
tracer (:func:`physcam.analysis.defocus.bokeh.bokeh_image`), binned on the render's pixel grid. Both
images are measured the same way (:mod:`physcam.analysis.defocus.blob`): centroid, equivalent diameter
(the sphere's own image removed in quadrature) and iris corners. Blender is found by
:func:`physcam.export.blender_runner.find_blender` (``--blender-python``, ``PHYSCAM_BLENDER_PYTHON``,
the user config, ``blender`` on PATH, a checkout's ``.venv-blender``), and the result says which.
"""

from __future__ import annotations

import dataclasses
import json
import subprocess
import tempfile
from pathlib import Path

import numpy as np

from ..errors import InputError, OpticsError, require_positive
from ..optics.state import CameraState, takes_camera
from .blender_runner import SCRIPT_ARGS, find_blender

__all__ = ["compare_bokeh"]

_SCRIPT = SCRIPT_ARGS + '''
import glob, json, runpy, sys
import bpy
import numpy as np
for _p in glob.glob(bpy.utils.resource_path("LOCAL") + "/python/lib/python3*/site-packages"):
    sys.path.insert(0, _p)
job = json.loads(ARGS[0])
scene = bpy.context.scene
for o in list(bpy.data.objects):
    if o.type != "CAMERA":
        bpy.data.objects.remove(o)
cam = scene.camera
cam.location, cam.rotation_euler = (0.0, 0.0, 0.0), (0.0, 0.0, 0.0)   # the film centre, looking down -Z
runpy.run_path(job["setup"], run_name="physcam_setup")["apply"](scene)
world = bpy.data.worlds.new("black"); scene.world = world; world.use_nodes = True
world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.0
mat = bpy.data.materials.new("glow"); mat.use_nodes = True
nt = mat.node_tree; nt.nodes.clear()
em = nt.nodes.new("ShaderNodeEmission"); em.inputs["Strength"].default_value = 1.0
nt.links.new(em.outputs[0], nt.nodes.new("ShaderNodeOutputMaterial").inputs[0])
scene.cycles.use_denoising = False
scene.cycles.max_bounces = 0
scene.cycles.pixel_filter_type = "BOX"
scene.cycles.filter_width = 1.0
scene.cycles.samples = job["samples"]
scene.view_settings.view_transform = "Standard"
bpy.ops.mesh.primitive_uv_sphere_add(radius=job["radius_m"], location=(0.0, 0.0, -job["distance_m"]),
                                     segments=64, ring_count=32)
bpy.context.object.data.materials.append(mat)
bpy.ops.object.shade_smooth()
scene.render.image_settings.file_format = "OPEN_EXR"
scene.render.filepath = job["exr"]
bpy.ops.render.render(write_still=True)
img = bpy.data.images.load(job["exr"])
w, h = img.size
np.save(job["npy"], np.array(img.pixels[:], dtype=np.float64).reshape(h, w, 4)[:, :, 0])
print(json.dumps({"ok": True}))
'''


@takes_camera
def compare_bokeh(camera: CameraState, *, light_mm: float, aperture=None, crop_mm: float = 3.0, pixels: int = 128, samples: int = 512, rays: int = 2_000_000,
                  sphere_mm: float = 1.0, blender_python: str | None = None, timeout_s: float = 600.0,
                  config_blender: str | None = None) -> dict:
    """Render and trace a point light ``light_mm`` in front of the film with ``camera``: a
    :class:`~physcam.optics.state.CameraState` (its focus, iris set to an f-stop, and iris shape, which
    ``aperture`` replaces; its sensor is replaced by the ``crop_mm`` square); return both images and the
    measured agreement."""
    from ..analysis.defocus.blob import blob_moments, equivalent_diameter, polygon_corners
    from ..analysis.defocus.bokeh import bokeh_image
    from .blender import _state, blender_setup_script, osl_camera_shader

    if not camera.iris_set:
        raise InputError("the comparison needs an f-stop: camera_state(lens, focus_mm=..., fstop=N)")
    crop = require_positive("crop", crop_mm)
    if isinstance(pixels, bool) or not isinstance(pixels, int) or not 32 <= pixels <= 1024:
        raise InputError(f"pixels must be a whole number from 32 to 1024, got {pixels!r}")
    if isinstance(samples, bool) or not isinstance(samples, int) or not 1 <= samples <= 100_000:
        raise InputError(f"samples must be a whole number from 1 to 100000, got {samples!r}")
    d_light = require_positive("light distance", light_mm)
    sphere = require_positive("sphere diameter", sphere_mm)
    runner = find_blender(blender_python, config_value=config_blender)
    from ..optics.sensors import Sensor

    square = Sensor("custom", f"custom {crop:g} x {crop:g} mm", crop, crop)  # the crop is the frame
    state = _state(dataclasses.replace(camera, sensor=square), aperture)
    aperture = state.aperture
    src = osl_camera_shader(state)
    with tempfile.TemporaryDirectory(prefix="physcam-compare-") as tmp:
        setup = Path(tmp) / "setup.py"
        setup.write_text(blender_setup_script(src, sensor_width_mm=crop, sensor_height_mm=crop,
                                              resolution=(pixels, pixels)))
        job = {"setup": str(setup), "samples": samples, "radius_m": sphere / 2000.0, "distance_m": d_light / 1000.0,
               "exr": str(Path(tmp) / "render.exr"), "npy": str(Path(tmp) / "render.npy")}
        script = Path(tmp) / "render.py"
        script.write_text(_SCRIPT)
        p = subprocess.run(runner.command(script, json.dumps(job)), capture_output=True, text=True, timeout=timeout_s)
        if p.returncode != 0 or not Path(job["npy"]).is_file():
            tail = (p.stderr or p.stdout).strip().splitlines()[-1:] or ["no output"]
            raise OpticsError(f"Blender could not render the comparison: {tail[0][:200]}")
        rendered = np.load(job["npy"])
    h = crop / 2
    # the iris's corners reach CameraState.iris_corner_semi in the shader, and in bokeh_image's tracer
    traced = bokeh_image(state, d_light, rays=rays, pixels=pixels, extent_mm=(-h, h, -h, h), fresnel=False)
    off = bokeh_image(state, d_light, 10.0, rays=200_000, pixels=64, fresnel=False)  # the magnification there
    mag = abs(off.to_dict()["centroid_mm"][0]) / 10.0
    pitch = crop / pixels
    image = traced.image[..., 0]
    if not rendered.sum() > 0 or not image.sum() > 0:
        raise OpticsError("no light reached the crop: choose a light nearer the axis or a larger --crop")
    e = sphere * mag  # the sphere's own (sharp) image on the film
    d_render = equivalent_diameter(rendered, pitch, e)
    d_trace = equivalent_diameter(image, pitch)
    c_r, c_t = blob_moments(rendered, pitch)[:2], blob_moments(image, pitch)[:2]
    rows = {
        "equivalent_diameter_mm": {"cycles": d_render, "physcam": d_trace, "ratio": d_render / d_trace},
        "centroid_mm": {"cycles": list(c_r), "physcam": list(c_t)},
    }
    if aperture is not None and getattr(aperture, "nsides", 0) >= 3:
        # the rim's dominant harmonic is the corner count (robust to render noise, unlike local maxima)
        rows["corners"] = {"cycles": polygon_corners(rendered)[1], "physcam": polygon_corners(image)[1]}
    return {"lens": state.lens_name, "focus_from_film_mm": state.focus_from_film_mm, "fstop": state.fstop, "light_from_film_mm": d_light,
            "blender": runner.describe(), "crop_mm": crop, "pixels": pixels, "samples": samples, "sphere_image_mm": e, "measured": rows,
            "images": {"cycles": rendered, "physcam": image}}

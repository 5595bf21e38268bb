"""Run code in Blender (bpy) from the test suite.

Blender as a Python module pins numpy < 2, so it lives in its own environment that the Makefile
builds (``.venv-blender``, with physcam installed in it); tests drive it in subprocesses.
Blender is found the way physcam finds it (:func:`physcam.export.blender_runner.find_blender`:
``PHYSCAM_BLENDER_PYTHON``, the user config, ``blender`` on PATH, this checkout's
``.venv-blender``), so the tests run under a Python with bpy or under a Blender program; they skip
with the reason when there is none, which happens only outside ``make test``.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import tempfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


def blender_runner():
    """physcam's runner for this machine's Blender, or None."""
    from physcam.errors import InputError
    from physcam.export.blender_runner import find_blender

    try:
        return find_blender(None)
    except InputError:
        return None


def require_blender():
    runner = blender_runner()
    if runner is None:
        pytest.skip("Blender (bpy) is not installed: `make test` builds .venv-blender with it")
    return runner


#: Put Blender's bundled oslquery on sys.path (Cycles needs it to compile OSL camera shaders), and give
#: the script its own arguments as sys.argv[1:] however Blender was started.
OSL_PATH_PRELUDE = """
import sys, glob, bpy
sys.argv = [sys.argv[0]] + (sys.argv[sys.argv.index('--') + 1:] if '--' in sys.argv else sys.argv[1:])
for _p in glob.glob(bpy.utils.resource_path("LOCAL") + "/python/lib/python3*/site-packages"):
    if _p not in sys.path:
        sys.path.insert(0, _p)
"""


#: A scene of nothing but its camera, placed at the film centre looking down world -Z (+Y up), in a
#: black world: what the OSL renders of one lit object start from (``scene`` and ``cam_obj`` defined).
DARK_SCENE_CAMERA_AT_FILM = """
scene = bpy.context.scene
for o in list(bpy.data.objects):
    if o.type != "CAMERA":
        bpy.data.objects.remove(o)
cam_obj = scene.camera
cam_obj.location = (0.0, 0.0, 0.0)       # the film centre
cam_obj.rotation_euler = (0.0, 0.0, 0.0)  # looks down world -Z, +Y up
world = bpy.data.worlds.new("black"); scene.world = world; world.use_nodes = True
world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.0
"""

#: Enables the physcam extension installed in the user folder Blender was started with, as Blender enables
#: an installed add-on at start-up.
ENABLE_EXTENSION = """import addon_utils
addon_utils.enable("bl_ext.user_default.physcam", default_set=True)
assert hasattr(bpy.types.Camera, "physcam"), "the physcam extension is not installed in BLENDER_USER_RESOURCES"
"""

#: The start of a script run through the physcam extension installed in its Blender user folder
#: (``BLENDER_USER_RESOURCES``: the session's shared install, :func:`install_extension`; argv[1]: the zip
#: it was installed from): enabled (:data:`ENABLE_EXTENSION`), Cycles on the CPU
#: with 2 threads, no denoising, linear EXR out.
INSTALLED_EXTENSION_SCENE = """
import json, math, sys
import numpy as np
""" + ENABLE_EXTENSION + """scene = bpy.context.scene
scene.render.engine = "CYCLES"; scene.cycles.device = "CPU"; scene.cycles.use_denoising = False
scene.render.threads_mode = "FIXED"; scene.render.threads = 2
scene.view_settings.view_transform = "Standard"
scene.render.image_settings.file_format = "OPEN_EXR"
"""

#: Blender code defining ``direction_world()``: a new world whose colour is the ray's direction plus 2 (every
#: channel positive, strength 1), so that a render pictures the camera's rays. Needs ``scene`` (SCENE's).
DIRECTION_WORLD = """
def direction_world():
    world = bpy.data.worlds.new("dir"); scene.world = world; world.use_nodes = True
    nt = world.node_tree
    tc = nt.nodes.new("ShaderNodeTexCoord")   # in the world, Generated is the ray's direction
    add = nt.nodes.new("ShaderNodeVectorMath"); add.operation = "ADD"
    add.inputs[1].default_value = (2.0, 2.0, 2.0)
    nt.links.new(tc.outputs["Generated"], add.inputs[0])
    bg = nt.nodes["Background"]; bg.inputs["Strength"].default_value = 1.0
    nt.links.new(add.outputs[0], bg.inputs["Color"])
"""


#: Blender code defining ``glow(name, strength)``: a new material that only emits (white light of that
#: strength), what the lit objects of the rendered tests are made of.
GLOW_MATERIAL = """
def glow(name, strength):
    mat = bpy.data.materials.new(name); mat.use_nodes = True
    nt = mat.node_tree; nt.nodes.clear()
    em = nt.nodes.new("ShaderNodeEmission"); em.inputs["Strength"].default_value = strength
    nt.links.new(em.outputs[0], nt.nodes.new("ShaderNodeOutputMaterial").inputs[0])
    return mat
"""


def installed_dark_scene(samples: int | None = None) -> str:
    """:data:`INSTALLED_EXTENSION_SCENE`, then nothing but the camera, in no world (black): the camera
    object at the origin looking down world -Z, +Y up (with an extension's lens, the origin is its
    entrance pupil), ``cam_obj`` and ``cam`` (its data) defined, and :data:`GLOW_MATERIAL`'s ``glow``.
    With ``samples``: Cycles at that many samples a pixel, not adaptive, a 1 px box filter and no
    bounces (each pixel the light reaching it straight from the lit objects)."""
    render = "" if samples is None else f"""
scene.cycles.samples = {int(samples)}; scene.cycles.use_adaptive_sampling = False
scene.cycles.pixel_filter_type = "BOX"; scene.cycles.filter_width = 1.0; scene.cycles.max_bounces = 0"""
    return INSTALLED_EXTENSION_SCENE + render + """
for o in list(bpy.data.objects):
    if o.type != "CAMERA":
        bpy.data.objects.remove(o)
scene.world = None
cam_obj = scene.camera
cam_obj.location = (0.0, 0.0, 0.0); cam_obj.rotation_euler = (0.0, 0.0, 0.0)
cam = cam_obj.data
""" + GLOW_MATERIAL


def run_blender(script: str, *args, timeout: float = 300.0, env: dict | None = None) -> dict:
    """Run ``script`` (Python source) in Blender; it must print one JSON object on its last stdout line,
    which is returned. The source tree under test comes first on sys.path; ``env`` adds variables."""
    return run_blender_log(script, *args, timeout=timeout, env=env)[0]


def run_blender_log(script: str, *args, timeout: float = 300.0, env: dict | None = None) -> tuple[dict, str]:
    """:func:`run_blender`, and everything Blender printed (stdout, then stderr)."""
    runner = require_blender()
    own = env or {}  # the test's own variables: only a user folder the test gave is cleaned up
    env = dict(os.environ, PYTHONPATH=str(ROOT / "src") + os.pathsep + os.environ.get("PYTHONPATH", ""), **own)
    with tempfile.TemporaryDirectory(prefix="physcam-blender-") as tmp:
        # Blender's temporary files (Cycles leaves the .oso of every camera shader the scripts compile
        # themselves) go into the script's folder, removed after, unless the test chose a TMPDIR
        env.setdefault("TMPDIR", tmp)
        path = Path(tmp) / "script.py"
        path.write_text(OSL_PATH_PRELUDE + script)
        p = subprocess.run(runner.command(path, *map(str, args)), capture_output=True, text=True, timeout=timeout,
                           env=env)
    _remove_installed_extensions(own)
    if p.returncode != 0:
        raise AssertionError(f"Blender script failed (exit {p.returncode}):\n{p.stdout[-3000:]}\n{p.stderr[-3000:]}")
    lines = [ln for ln in p.stdout.strip().splitlines() if ln.startswith("{")]
    if not lines:
        raise AssertionError(f"Blender script printed no JSON:\n{p.stdout[-3000:]}\n{p.stderr[-3000:]}")
    return json.loads(lines[-1]), p.stdout + p.stderr


#: The file marking a Blender user folder shared by the session's tests (:func:`install_extension`): no run
#: removes its extensions.
SHARED_USER_MARK = ".physcam-shared-by-the-session"

#: Installs argv[1] (the zip) with Blender's own installer into the user folder Blender was started with.
_INSTALL = """
bpy.ops.extensions.package_install_files(filepath=sys.argv[1], repo="user_default", enable_on_install=True)
import json
print(json.dumps({"installed": hasattr(bpy.types.Camera, "physcam")}))
"""


def install_extension(zip_path, user: Path) -> dict:
    """Install the extension ``zip_path`` into the Blender user folder ``user`` with Blender's own installer
    (once: a folder where it is already installed is kept; the folder is marked shared first, so that no
    run, this one included, removes it); returns the ``env`` giving a run that folder.

    The extension's render tests share one install, as an artist's Blender keeps an installed extension
    from one session to the next: each of 12 runs installing its own copy wrote 111 MB and cost about
    2 s CPU and 5 s wall (2026-11-29). Installing is itself tested by tests/blender/test_extension.py."""
    env = {"BLENDER_USER_RESOURCES": str(user)}
    done = user / ".physcam-installed"
    if not done.exists():
        shutil.rmtree(user, ignore_errors=True)  # a half-made install of an interrupted run
        user.mkdir(parents=True)
        (user / SHARED_USER_MARK).touch()  # first: the run below must not remove what it installs
        out = run_blender(_INSTALL, zip_path, env=env)
        assert out["installed"], out
        done.touch()
    return env


def _remove_installed_extensions(env: dict) -> None:
    """Remove the extensions a run installed into the ``BLENDER_USER_RESOURCES`` its test gave it (``env``: the
    test's own variables, never the shell's: a user's portable Blender keeps its extensions; every test gives
    each Blender a fresh folder): the physcam extension unpacks to about 120 MB of shaders (470 MB before one
    source per lens, round 11), and a dozen 470 MB copies kept until the session ended filled a CI machine's
    disk. No test reads that folder after its Blender exits."""
    user = env.get("BLENDER_USER_RESOURCES")
    if user and not (Path(user) / SHARED_USER_MARK).exists():
        shutil.rmtree(Path(user) / "extensions", ignore_errors=True)


def light_centroid(img, c, r, win: int):
    """The centroid (column, row) of a small light in ``img`` (rows as stored), in the (2 win + 1)-pixel
    square about (c, r), negative pixels counted as 0."""
    import numpy as np

    c0, r0 = int(round(c)), int(round(r))
    a = np.clip(img[r0 - win:r0 + win + 1, c0 - win:c0 + win + 1], 0.0, None)
    yy, xx = np.mgrid[r0 - win:r0 + win + 1, c0 - win:c0 + win + 1]
    return float((a * xx).sum() / a.sum()), float((a * yy).sum() / a.sum())


def predicted_block_brightness(b, blocks: dict, w_px: int, h_px: int, sensor_mm, samples: int = 96) -> dict:
    """physcam's own prediction of a white world's brightness in pixel ``blocks`` ({name: (row0, row1,
    col0, col1)}, rows from the bottom) of a ``w_px`` x ``h_px`` render through the baked camera ``b``
    (physcam.export.blender.bake_camera): the mean camera_rays weight over a ``samples``^2 pupil grid at
    each pixel's film point, over the shader's normalisation. The picture is upright, so pixel (c, r)
    reads the film at (-(2u - 1) w/2, -(2v - 1) h/2)."""
    import numpy as np

    from physcam.trace.trace import camera_rays

    sw, sh = sensor_mm
    u = (np.arange(samples) + 0.5) / samples
    uv = np.stack([a.ravel() for a in np.meshgrid(u, u)], 1)
    predicted = {}
    for k, (r0, r1, c0, c1) in blocks.items():
        cols = np.arange(c0, c1)
        fx = -(2 * (cols + 0.5) / w_px - 1) * sw / 2
        vals = []
        for r in range(r0, r1):  # one row of the block a trace: every pixel's film point times the pupil grid
            fy = -(2 * (r + 0.5) / h_px - 1) * sh / 2
            film = np.repeat(np.stack([fx, np.full_like(fx, fy)], 1), len(uv), axis=0)
            cr = camera_rays(b.lens, film, np.tile(uv, (len(cols), 1)), b.film_z, bounds=b.bounds)
            vals.append(cr.weight.reshape(len(cols), len(uv)).mean(axis=1) / b.norm)
        predicted[k] = float(np.mean(vals))
    return predicted

"""The physcam Blender extension in Blender: installed by Blender's own extension installer into a
fresh user folder, registered, every bundled lens selectable and compiled; a keyframed focus pull
renders each frame where physcam's tracer puts the markers at that frame's focus, and its framing
changes as `physcam lens breathing` says; Blender's built-in camera (viewport, EEVEE) frames like
the OSL camera."""

from __future__ import annotations

import json

import numpy as np
import pytest

from _blender import run_blender
from physcam.cli import main
from physcam.lens.library import list_lenses, load_lens
from physcam.optics.focusing import breathing_table, focus
from physcam.trace.rays import RayBatch
from physcam.trace.trace import trace_to_film

pytestmark = pytest.mark.slow

SLUG = "zeiss_distagon_35mm_f4"
SW, SH, W, H = 36.0, 24.0, 512, 342


@pytest.fixture(scope="module")
def extension_zip(tmp_path_factory):
    out = tmp_path_factory.mktemp("ext")
    assert main(["export", "blender-extension", "-o", str(out)]) == 0
    (zp,) = out.glob("physcam-*.zip")
    return zp


INSTALL = '''
import os, json, sys
import addon_utils
zip_path, user = sys.argv[1], sys.argv[2]
repo = bpy.context.preferences.extensions.repos.get("user_default")
res = bpy.ops.extensions.package_install_files(filepath=zip_path, repo="user_default", enable_on_install=True)
import importlib
mod = None
for m in addon_utils.modules():
    if m.__name__.endswith(".physcam"):
        mod = m
installed = mod is not None and addon_utils.check(mod.__name__)[1]
scene = bpy.context.scene
scene.render.engine = "CYCLES"; scene.cycles.device = "CPU"
cam = scene.camera.data
'''


def test_installs_registers_and_every_lens_compiles(extension_zip, tmp_path):
    """Blender's installer puts the zip in a fresh user folder and enables it; the Camera panel's
    property group exists; each bundled lens, chosen in the enum, gives a compiled OSL camera."""
    out = run_blender(INSTALL + '''
p = cam.physcam
p.focus_distance = 5.0; p.fstop = 8.0
res = {"installed": bool(installed), "user_dir": bpy.utils.user_resource("EXTENSIONS"), "lenses": {}}
slugs = json.loads(sys.argv[3])
p.enabled = True
for slug in slugs:
    p.lens = slug
    res["lenses"][slug] = {"bytecode": len(cam.custom_bytecode), "message": p.message,
                           "shader": cam.custom_shader.name if cam.custom_shader else None}
print(json.dumps(res))
''', extension_zip, tmp_path, json.dumps([r.slug for r in list_lenses()]),
        env={"BLENDER_USER_RESOURCES": str(tmp_path / "user")})
    assert out["installed"], out
    assert str(tmp_path / "user") in out["user_dir"]
    assert set(out["lenses"]) == {r.slug for r in list_lenses()}
    for slug, r in out["lenses"].items():
        assert r["message"] == "" and r["bytecode"] > 0 and slug in r["shader"], (slug, r)

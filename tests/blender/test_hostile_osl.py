"""Issue 40, item 11, in a real Blender: a lens whose name holds line breaks, a trigraph, a trailing
backslash and OSL code compiles, through Blender's own OSL compiler (Cycles compiles an internal
custom camera shader when the set-up script assigns it), to the very bytecode of the same lens
with a harmless name: the name stayed a comment. Before the fix the name's second line was OSL
code (``#define N_SURF 1`` redefined an array size, and ``shader x(){}`` declared a second shader).
"""

from __future__ import annotations

import dataclasses

import pytest

from _blender import run_blender
from physcam.export.blender import _emit, bake_camera, blender_setup_script
from physcam.lens.library import load_lens
from physcam.optics.state import camera_state

pytestmark = pytest.mark.slow

EVIL = "evil \\\n#define N_SURF 1\nshader x(){}\n??/\n#define HALF_W 0.0\r\n*/ \"\"\" \\"

SCRIPT = r"""
import hashlib, json, os, re, runpy, sys, tempfile
out = {}
for label, path in (("evil", sys.argv[1]), ("plain", sys.argv[2])):
    cam = runpy.run_path(path)["apply"](bpy.context.scene)
    code = re.sub(r"/[^ \t\n{}]*tmp\w+[.]os[lo]", "SHADER", cam.data.custom_bytecode)  # Blender's temporary names
    out[label] = {"bytes": len(code), "sha": hashlib.sha256(code.encode()).hexdigest()}
out["oso_left"] = sorted(f for f in os.listdir(tempfile.gettempdir()) if f.endswith(".oso"))
print(json.dumps(out))
"""


def test_a_hostile_lens_name_compiles_to_the_harmless_names_bytecode(tmp_path):
    lens = load_lens("cooke_triplet_50mm_f4_5")
    b = bake_camera(camera_state(lens, focus_mm=2000.0, sensor_mm=(24.0, 18.0)))
    paths = []
    for label, name in (("evil", EVIL), ("plain", "harmless lens")):
        renamed = dataclasses.replace(b, lens=dataclasses.replace(b.lens, metadata=dataclasses.replace(
            b.lens.metadata, name=name)))
        src = _emit(renamed, dispersion=False, fresnel=False)
        path = tmp_path / f"setup_{label}.py"
        path.write_text(blender_setup_script(src, sensor_width_mm=24.0, sensor_height_mm=18.0,
                                             text_name="physcam_lens.osl"), encoding="utf-8")
        paths.append(path)
    own_temp = tmp_path / "blender-tmp"
    own_temp.mkdir()
    got = run_blender(SCRIPT, *paths, timeout=600, env={"TMPDIR": str(own_temp)})
    assert got["plain"]["bytes"] > 1000  # compiled
    assert got["evil"] == got["plain"]
    # Cycles leaves the .oso of an internal camera shader in the temp folder; the setup script compiles
    # in a folder of its own and removes it
    assert got["oso_left"] == [] and not list(own_temp.glob("*.oso"))

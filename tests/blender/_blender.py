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


#: The start of a script run through the installed physcam extension (argv[1]: its zip): installed with
#: Blender's own installer, Cycles on the CPU with 2 threads, no denoising, linear EXR out.
INSTALLED_EXTENSION_SCENE = """
import json, math, sys
import numpy as np
bpy.ops.extensions.package_install_files(filepath=sys.argv[1], repo="user_default", enable_on_install=True)
scene = bpy.context.scene
scene.render.engine = "CYCLES"; scene.cycles.device = "CPU"; scene.cycles.use_denoising = False
scene.render.threads_mode = "FIXED"; scene.render.threads = 2
scene.view_settings.view_transform = "Standard"
scene.render.image_settings.file_format = "OPEN_EXR"
"""


def run_blender(script: str, *args, timeout: float = 300.0, env: dict | None = None) -> dict:
    """Run ``script`` (Python source) in Blender; it must print one JSON object on its last stdout line,
    which is returned. The source tree under test comes first on sys.path; ``env`` adds variables."""
    runner = require_blender()
    env = dict(os.environ, PYTHONPATH=str(ROOT / "src") + os.pathsep + os.environ.get("PYTHONPATH", ""), **(env or {}))
    with tempfile.TemporaryDirectory(prefix="physcam-blender-") as tmp:
        path = Path(tmp) / "script.py"
        path.write_text(OSL_PATH_PRELUDE + script)
        p = subprocess.run(runner.command(path, *map(str, args)), capture_output=True, text=True, timeout=timeout,
                           env=env)
    if p.returncode != 0:
        raise AssertionError(f"Blender script failed (exit {p.returncode}):\n{p.stdout[-3000:]}\n{p.stderr[-3000:]}")
    lines = [ln for ln in p.stdout.strip().splitlines() if ln.startswith("{")]
    if not lines:
        raise AssertionError(f"Blender script printed no JSON:\n{p.stdout[-3000:]}\n{p.stderr[-3000:]}")
    return json.loads(lines[-1])

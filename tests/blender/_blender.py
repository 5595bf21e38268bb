"""Run code in Blender (bpy) from the test suite.

Blender as a Python module pins numpy < 2, so it lives in its own environment that the Makefile
builds (``.venv-blender``, with physcam installed in it); tests drive it in a subprocess.
:func:`blender_python` finds that interpreter (``PHYSCAM_BLENDER_PYTHON``, else the
repository's ``.venv-blender``); tests skip with the reason when it is not there, which happens
only outside ``make test``.
"""

from __future__ import annotations

import json
import os
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


def blender_python() -> str | None:
    exe = os.environ.get("PHYSCAM_BLENDER_PYTHON") or str(ROOT / ".venv-blender" / "bin" / "python")
    return exe if Path(exe).is_file() else None


def require_blender() -> str:
    exe = blender_python()
    if exe is None:
        pytest.skip("Blender (bpy) is not installed: `make test` builds .venv-blender with it")
    return exe


#: Put Blender's bundled oslquery on sys.path (Cycles needs it to compile OSL camera shaders).
OSL_PATH_PRELUDE = """
import sys, glob, bpy
for _p in glob.glob(bpy.utils.resource_path("LOCAL") + "/python/lib/python3*/site-packages"):
    if _p not in sys.path:
        sys.path.insert(0, _p)
"""


def run_blender(script: str, *args, timeout: float = 300.0) -> dict:
    """Run ``script`` (Python source) in the Blender environment; it must print one JSON object on
    its last stdout line, which is returned. The source tree under test comes first on sys.path."""
    exe = require_blender()
    env = dict(os.environ, PYTHONPATH=str(ROOT / "src") + os.pathsep + os.environ.get("PYTHONPATH", ""))
    p = subprocess.run([exe, "-c", OSL_PATH_PRELUDE + script, *map(str, args)], capture_output=True, text=True,
                       timeout=timeout, env=env)
    if p.returncode != 0:
        raise AssertionError(f"Blender script failed (exit {p.returncode}):\n{p.stdout[-3000:]}\n{p.stderr[-3000:]}")
    lines = [ln for ln in p.stdout.strip().splitlines() if ln.startswith("{")]
    if not lines:
        raise AssertionError(f"Blender script printed no JSON:\n{p.stdout[-3000:]}\n{p.stderr[-3000:]}")
    return json.loads(lines[-1])

"""Finding Blender to run a script in: a Python with the ``bpy`` module, or a ``blender`` program.

Order (the first that exists wins, and :attr:`BlenderRunner.source` says which): the path given
(``--blender-python``), ``$PHYSCAM_BLENDER_PYTHON``, the user config's ``blender_python``, a
``blender`` executable on ``PATH``, and last, in a source checkout, the ``.venv-blender`` that
``make blender`` builds beside it (never a folder relative to where the command runs). A path may be
a Python interpreter with ``bpy`` (run as ``python SCRIPT ARGS``) or a Blender executable (run as
``blender --background --factory-startup --python-exit-code 1 --python SCRIPT -- ARGS``); scripts
read their arguments with :data:`SCRIPT_ARGS`, which works for both.
"""

from __future__ import annotations

import os
import shutil
from dataclasses import dataclass
from pathlib import Path

from ..errors import InputError

__all__ = ["BlenderRunner", "find_blender", "SCRIPT_ARGS"]

#: Python source a script starts with to get its own arguments under either way of running it.
SCRIPT_ARGS = "import sys as _sys\nARGS = _sys.argv[_sys.argv.index('--') + 1:] if '--' in _sys.argv else _sys.argv[1:]\n"


@dataclass(frozen=True)
class BlenderRunner:
    """How to run a Python script inside Blender: ``kind`` "python" (an interpreter with bpy) or
    "blender" (the program), its ``path``, and ``source``: where it was found."""

    kind: str
    path: str
    source: str

    def command(self, script: str | Path, *args: str) -> list[str]:
        """The command line that runs ``script`` (a file) with ``args``."""
        if self.kind == "python":
            return [self.path, str(script), *map(str, args)]
        return [self.path, "--background", "--factory-startup", "--python-exit-code", "1", "--python", str(script),
                "--", *map(str, args)]

    def describe(self) -> str:
        what = "Python with bpy" if self.kind == "python" else "Blender"
        return f"{what} {self.path} (from {self.source})"


def _kind(path: Path) -> str:
    """"blender" for a Blender executable, "python" for anything else (an interpreter)."""
    return "blender" if path.name.lower().startswith("blender") else "python"


def find_blender(explicit: str | None = None, *, config_value: str | None = None) -> BlenderRunner:
    """The Blender to run scripts in (module notes); :class:`InputError` saying how to get one."""
    candidates = [(explicit, "--blender-python"), (os.environ.get("PHYSCAM_BLENDER_PYTHON"), "PHYSCAM_BLENDER_PYTHON"),
                  (config_value, "the user config's blender_python")]
    for value, source in candidates:
        if value:
            p = Path(value).expanduser()
            if not p.is_file():
                raise InputError(f"{source} names {value!r}, which is not a file: give a Python with bpy or a "
                                 "blender executable")
            return BlenderRunner(_kind(p), str(p), source)
    on_path = shutil.which("blender")
    if on_path:
        return BlenderRunner("blender", on_path, "the blender program on PATH")
    checkout = Path(__file__).resolve().parents[3] / ".venv-blender" / "bin" / "python"
    if checkout.is_file():
        return BlenderRunner("python", str(checkout), "this source checkout's .venv-blender (make blender)")
    raise InputError("no Blender found: give --blender-python PATH (a Python with bpy, or a blender executable), set "
                     "PHYSCAM_BLENDER_PYTHON or blender_python in the user config, put blender on PATH, or run "
                     "`make blender` in a source checkout")

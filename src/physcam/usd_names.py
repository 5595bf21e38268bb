"""USD file names: the layer format a file physcam writes is asked for by its name, told without importing USD.

USD tells a layer's format by its file name's extension, in any case (``shot.USDA`` is text, as ``shot.usda``;
``.usd`` and ``.usdc`` are crate). physcam's writers and the program's command lines check a name here, so the
program refuses a name it cannot write as it reads its arguments, before any work and before usd-core's import
(0.3-0.5 s): `physcam live record TAKE.USDA` was accepted at the start of a take, and its USD writer, which
knew only lower-case names, refused it at the end.
"""

from __future__ import annotations

from pathlib import Path

from .errors import ExportError

#: extension (lower case) -> the layer format physcam writes for it
WRITTEN = {".usda": "usda", ".usd": "usdc", ".usdc": "usdc"}


def usd_layer_format(path, *, what: str = "a USD file's name") -> str:
    """"usda" (text) or "usdc" (crate): the format of the USD file ``path`` names, from its extension in any
    case; :class:`~physcam.errors.ExportError` naming ``path`` (as ``what``) for any other name."""
    p = Path(path)
    fmt = WRITTEN.get(p.suffix.lower())
    if fmt is None:
        raise ExportError(f"{p}: {what} ends in .usda, .usd or .usdc")
    return fmt

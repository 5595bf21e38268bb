"""Lens file formats: read any supported file into a :class:`Prescription`, write one back.

=============  ===========================  ==========================================
format         extensions                   module
=============  ===========================  ==========================================
``physcam``    ``.toml`` (physcam-lens/1)   :mod:`.physcam_toml` (lossless, default)
``seed-toml``  ``.toml`` (``aperture`` key)  :mod:`.seedtoml` (Blender extension)
``pbrt``       ``.dat``                     :mod:`.pbrt`
``iset``       ``.json``                    :mod:`.iset`
``zemax``      ``.zmx``                     :mod:`.zemax`
=============  ===========================  ==========================================

Every reader returns a validated prescription or raises
:class:`~physcam.errors.LensFileError` with the file and line. See docs/lens-formats.md.
"""

from __future__ import annotations

import re
from pathlib import Path

from ...errors import ExportError, LensFileError
from ..prescription import Prescription, takes_prescription
from ._common import extra, read_text

__all__ = ["FORMATS", "extra", "read_lens", "loads_lens", "write_lens", "dumps_lens", "detect_format"]

#: Format name -> the name of its module in this package (imported when that format is read or
#: written: a bundled TOML lens's report loads no Zemax, pbrt, ISET or seed reader, issue 43).
_MODULE_NAMES = {"physcam": "physcam_toml", "seed-toml": "seedtoml", "pbrt": "pbrt", "iset": "iset", "zemax": "zemax"}
_EXT = {".dat": "pbrt", ".json": "iset", ".zmx": "zemax", ".toml": "physcam"}
#: Other programs' lens files physcam recognises but does not read.
_NOT_READ = {".seq": "CODE V sequence files (.seq)", ".len": "OSLO lens files (.len)",
             ".zos": "Zemax OpticStudio session files (.zos)", ".zar": "Zemax archives (.zar)"}


#: physcam TOML's first line, however the TOML is spaced or quoted (`format="physcam-lens/1"` too)
_PHYSCAM_FORMAT = re.compile(r"""^[ \t]*format[ \t]*=[ \t]*["']physcam-lens/""", re.MULTILINE)
#: keys only physcam TOML has (the seed TOML's surfaces have type, aperture and ior)
_PHYSCAM_ONLY = re.compile(r"^[ \t]*(\[provenance\]|semi_diameter[ \t]*=|medium[ \t]*=|kind[ \t]*=)", re.MULTILINE)


def detect_format(path, text: str | None = None) -> str:
    """The format of ``path`` from its extension (and, for ``.toml``, its content)."""
    ext = Path(path).suffix.lower()
    if ext in _NOT_READ:
        raise LensFileError(f"{_NOT_READ[ext]} are not read (yet); save the lens from that program as "
                            "a Zemax .zmx (sequential) file", str(path))
    fmt = _EXT.get(ext)
    if fmt is None and text is not None:
        head = text.lstrip()[:2000]
        if head.startswith("{"):
            fmt = "iset"
        elif "SURF " in head and ("UNIT" in head or "VERS" in head):
            fmt = "zemax"
        elif "[[surface]]" in text or "[lens]" in text:
            fmt = "physcam"
        else:
            fmt = "pbrt"
    if fmt is None:
        raise LensFileError(
            f"unknown lens file extension {ext or '(none)'!r}; use .toml, .dat, .json or .zmx, or pass format=",
            str(path),
        )
    if fmt == "physcam" and text is not None and not _PHYSCAM_FORMAT.search(text):
        if _PHYSCAM_ONLY.search(text):
            raise LensFileError('a physcam lens TOML (kind, semi_diameter, medium) starts with the line '
                                'format = "physcam-lens/1"; without it a .toml is read as the seed TOML '
                                "(type, aperture, ior): add it (docs/lens-formats.md)", str(path), 1)
        fmt = "seed-toml"
    return fmt


def _module(fmt: str):
    """The module of format ``fmt``, imported on first use (the one place this package imports one)."""
    from importlib import import_module

    try:
        name = _MODULE_NAMES[fmt]
    except KeyError:
        raise LensFileError(f"unknown lens format {fmt!r}; use one of {', '.join(_MODULE_NAMES)}") from None
    return import_module(f"{__name__}.{name}")


#: module name -> its format name, for ``formats.zemax`` and the like
_FORMAT_OF = {module: fmt for fmt, module in _MODULE_NAMES.items()}


def __getattr__(name: str):
    """``FORMATS`` (format name -> module with ``loads(text, path=None, name=None)`` and ``dumps(p)``)
    and the format modules themselves, imported on first use through :func:`_module`."""
    if name == "FORMATS":
        return {fmt: _module(fmt) for fmt in _MODULE_NAMES}
    if name in _FORMAT_OF:
        return _module(_FORMAT_OF[name])
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def loads_lens(text: str, format: str, path=None, name: str | None = None) -> Prescription:
    """Parse lens text of a named ``format``."""
    return _module(format).loads(text, path, name)


def read_lens(path, format: str | None = None) -> Prescription:
    """Read a lens file into a validated :class:`Prescription`.

    ``format`` is one of :data:`FORMATS`; by default it comes from the extension
    (``.toml`` files are told apart by content: physcam's own carry ``format =
    "physcam-lens/1"``). Raises :class:`LensFileError` (with path and line) for
    anything that is not a valid lens.
    """
    text = read_text(path)
    fmt = format or detect_format(path, text)
    return loads_lens(text, fmt, str(path))


@takes_prescription
def dumps_lens(p: Prescription, format: str = "physcam") -> str:
    """The text of ``p`` in ``format`` (:class:`ExportError` when the format cannot hold it). A format
    without zoom positions (pbrt, ISET, seed TOML) writes a zoom lens's first position, with a warning."""
    module = _module(format)
    if p.zoom is not None and format not in ("physcam", "zemax"):
        import warnings

        from ...errors import PhysCamWarning

        warnings.warn(f"{format} has no zoom positions: writing the first zoom position of lens {p.name!r} only "
                      "(physcam TOML or Zemax keep them)", PhysCamWarning, stacklevel=2)
    return module.dumps(p)


def write_lens(p: Prescription, path, format: str | None = None, force: bool = False) -> Path:
    """Write ``p`` to ``path`` (atomically; an existing file only with ``force``).

    ``format`` defaults from the extension (``.toml`` -> physcam's own TOML; ask for
    ``"seed-toml"`` for the Blender extension's). Raises :class:`ExportError` when the
    format cannot hold the lens (e.g. a cylinder in pbrt) or the file exists.
    """
    fmt = format or _EXT.get(Path(path).suffix.lower())
    if fmt is None:
        raise ExportError(f"cannot tell the lens format of {path}; use .toml, .dat, .json or .zmx, or pass format=")
    text = dumps_lens(p, fmt)
    from ...io import atomic_write  # (here: reading a lens, every command's start, needs none of io's imports)

    return atomic_write(path, text, force=force)

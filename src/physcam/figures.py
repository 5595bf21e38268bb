"""Figures written the physcam way: matplotlib's Agg backend, loaded lazily, files written atomically.

Every plot in physcam (DOF zone, lens diagram, breathing, spot, bokeh, analyses) is saved
through :func:`save_figure`, so the format follows the file's extension (.png, .svg, .pdf),
an existing file is kept unless ``force``, and a crash never leaves half a file.
"""

from __future__ import annotations

import io
from pathlib import Path

__all__ = ["pyplot", "save_figure", "figure_bytes"]

_FORMATS = {".png": "png", ".svg": "svg", ".pdf": "pdf"}


def pyplot():
    """matplotlib.pyplot on the non-interactive Agg backend."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def save_figure(fig, path, *, force: bool = False, dpi: int = 130) -> Path:
    """Write ``fig`` to ``path`` (.png, .svg or .pdf, from the extension) and close it.

    Raises :class:`~physcam.errors.ExportError` for another extension or an existing file
    without ``force``.
    """
    from .errors import ExportError
    from .io import atomic_write, check_writable

    p = Path(path)
    fmt = _FORMATS.get(p.suffix.lower())
    if fmt is None:
        pyplot().close(fig)
        raise ExportError(f"cannot save a figure as {p.name!r}: use a .png, .svg or .pdf file name")
    check_writable(p, force=force)
    return atomic_write(p, figure_bytes(fig, fmt, dpi=dpi), force=force)


def figure_bytes(fig, fmt: str = "svg", *, dpi: int = 130) -> bytes:
    """``fig`` drawn in memory as ``fmt`` ("png", "svg" or "pdf") and closed: what :func:`save_figure`
    writes, for a caller that sends it elsewhere (``physcam serve``)."""
    from .errors import ExportError, WrongTypeError

    if not callable(getattr(fig, "savefig", None)):
        raise WrongTypeError(f"fig must be a matplotlib Figure, got {type(fig).__name__}")
    if fmt not in _FORMATS.values():
        pyplot().close(fig)
        raise ExportError(f"cannot draw a figure as {fmt!r}: use one of png, svg, pdf")
    buf = io.BytesIO()
    try:
        fig.savefig(buf, format=fmt, dpi=dpi)
    finally:
        pyplot().close(fig)
    return buf.getvalue()

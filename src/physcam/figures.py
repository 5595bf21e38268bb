"""Figures written the physcam way: matplotlib's Agg canvas, loaded lazily, files written atomically.

Every plot in physcam (DOF zone, lens diagram, breathing, spot, bokeh, analyses) is saved
through :func:`save_figure`, so the format follows the file's extension (.png, .svg, .pdf),
an existing file is kept unless ``force``, and a crash never leaves half a file.

Figures are ``matplotlib.figure.Figure`` objects on an Agg canvas, made without
``matplotlib.pyplot``: pyplot's import (backend selection, the figure manager, the state
machine) costs 0.1-0.3 s of a command's cold start and nothing here needs it (docs/performance.md).
:func:`pyplot` returns a small stand-in with pyplot's ``subplots``, ``figure`` and ``close``;
any other attribute loads the real pyplot (Agg backend).
"""

from __future__ import annotations

import io
from pathlib import Path

__all__ = ["pyplot", "subplots", "new_figure", "save_figure", "figure_bytes"]

_FORMATS = {".png": "png", ".svg": "svg", ".pdf": "pdf"}


def new_figure(figsize=None, dpi=None, **kwargs):
    """A ``Figure`` attached to an Agg canvas (no pyplot)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=figsize, dpi=dpi, **kwargs)
    FigureCanvasAgg(fig)
    return fig


def subplots(nrows: int = 1, ncols: int = 1, *, figsize=None, dpi=None, squeeze: bool = True, **kwargs):
    """``(fig, axes)`` as ``pyplot.subplots`` gives them, on an Agg canvas."""
    fig = new_figure(figsize=figsize, dpi=dpi)
    return fig, fig.subplots(nrows, ncols, squeeze=squeeze, **kwargs)


class _AggPlot:
    """The part of pyplot physcam uses, without importing pyplot."""

    @staticmethod
    def subplots(nrows: int = 1, ncols: int = 1, **kwargs):
        return subplots(nrows, ncols, **kwargs)

    @staticmethod
    def figure(figsize=None, dpi=None, **kwargs):
        return new_figure(figsize=figsize, dpi=dpi, **kwargs)

    @staticmethod
    def close(fig=None) -> None:
        """Figures made here belong to no figure manager: dropping the last reference frees them."""
        if getattr(getattr(fig, "canvas", None), "manager", None) is not None:
            _real_pyplot().close(fig)

    def __getattr__(self, name):
        return getattr(_real_pyplot(), name)


_PLOT = _AggPlot()


def _real_pyplot():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def pyplot():
    """pyplot's ``subplots``/``figure``/``close`` on Agg canvases (anything else: the real
    ``matplotlib.pyplot`` on the non-interactive Agg backend)."""
    return _PLOT


def _skip_layout_rerun(fig) -> None:
    """After ``fig.tight_layout()`` matplotlib leaves a do-nothing placeholder layout engine, and
    ``savefig`` then draws the whole figure once more (without rendering) just to run it: for a
    spot diagram's scatter of 1e5 points that is a third of the save. Drop the placeholder; the
    layout already applied stays, and the image is the same."""
    try:
        from matplotlib.layout_engine import PlaceHolderLayoutEngine

        if isinstance(fig.get_layout_engine(), PlaceHolderLayoutEngine):
            fig._layout_engine = None
    except (ImportError, AttributeError):  # another matplotlib: it draws as it always did
        pass


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
        _PLOT.close(fig)
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
        _PLOT.close(fig)
        raise ExportError(f"cannot draw a figure as {fmt!r}: use one of png, svg, pdf")
    _skip_layout_rerun(fig)
    buf = io.BytesIO()
    try:
        fig.savefig(buf, format=fmt, dpi=dpi)
    finally:
        _PLOT.close(fig)
    return buf.getvalue()

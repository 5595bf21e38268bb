"""Figures written the physcam way: matplotlib's Agg canvas, loaded lazily, files written atomically.

Every plot in physcam (DOF zone, lens diagram, breathing, spot, bokeh, analyses) is saved
through :func:`save_figure`, so the format follows the file's extension (.png, .svg, .pdf),
an existing file is kept unless ``force``, and a crash never leaves half a file.

Figures are ``matplotlib.figure.Figure`` objects on an Agg canvas, made without
``matplotlib.pyplot``: pyplot's import (backend selection, the figure manager, the state
machine) costs 0.1-0.3 s of a command's cold start and nothing here needs it (docs/performance.md).
:func:`pyplot` returns a small stand-in with pyplot's ``subplots``, ``figure`` and ``close``;
any other attribute loads the real pyplot (Agg backend).

One style for every figure (:data:`STYLE`): DejaVu Sans at sizes that stay legible on a phone and
a printed page, the Okabe-Ito colours (:data:`PALETTE`, told apart by readers with any common
colour-vision deficiency: Okabe & Ito 2008, "Color Universal Design"), units in every axis label,
and titles that fit (:func:`fit_title`). :func:`figure_problems` lists what breaks those rules in a
drawn figure (tests/test_figures_style.py runs it on every figure).

The style never touches the caller's matplotlib settings: every physcam function that draws runs
inside :func:`figure_style` (the :func:`styled` decorator), a ``matplotlib.rc_context`` from the
figure's creation to its save, so ``matplotlib.rcParams`` is the same after a physcam call as before
it, and the caller's settings do not reach physcam's figures either (drawn from matplotlib's
defaults plus the style). For your own plots in physcam's style, draw them inside ``with
figure_style():``, or call :func:`apply_style` to set it globally (physcam itself never calls it).
"""

from __future__ import annotations

import contextlib
import functools
import io
import os
import threading
from pathlib import Path

__all__ = ["pyplot", "subplots", "new_figure", "save_figure", "figure_bytes", "figure_format", "PALETTE", "STYLE", "apply_style",
           "figure_style", "styled", "fit_title", "unbroken", "NO_BREAK", "figure_problems", "UNITLESS_WORDS"]

_FORMATS = {".png": "png", ".svg": "svg", ".pdf": "pdf"}

#: The Okabe-Ito palette (blue, vermillion, bluish green, orange, reddish purple, sky blue, yellow,
#: black): distinguishable with protanopia, deuteranopia and tritanopia (Okabe & Ito 2008).
PALETTE = ("#0072B2", "#D55E00", "#009E73", "#E69F00", "#CC79A7", "#56B4E9", "#F0E442", "#000000")

#: matplotlib settings of every physcam figure (:func:`figure_style`).
STYLE = {
    "font.family": ["DejaVu Sans"],  # the font itself: "sans-serif" would be resolved when drawn
    "font.sans-serif": ["DejaVu Sans"],
    "font.size": 8.5,
    "axes.titlesize": 9.0,
    "axes.labelsize": 8.5,
    "xtick.labelsize": 7.5,
    "ytick.labelsize": 7.5,
    "legend.fontsize": 7.0,
    "legend.framealpha": 0.85,
    "figure.titlesize": 10.0,
    "axes.grid": False,
    "grid.alpha": 0.3,
    "axes.spines.top": False,
    "axes.spines.right": False,
    "lines.linewidth": 1.4,
    "image.cmap": "viridis",
    "savefig.facecolor": "white",
    "figure.facecolor": "white",
}

#: Words that mark an axis of a dimensionless quantity (a ratio): such a label needs no unit.
UNITLESS_WORDS = ("MTF", "relative", "ratio", "fraction", "normalised", "normalized", "contrast", "count", "f-stop",
                  "f-number", "weight", "transmission")


def _style_params() -> dict:
    from cycler import cycler

    return {**STYLE, "axes.prop_cycle": cycler(color=list(PALETTE))}


def apply_style() -> None:
    """Set :data:`STYLE` and the :data:`PALETTE` colour cycle in matplotlib's global rcParams, for
    your own plots in physcam's style from now on. physcam itself never calls it (its figures are
    drawn inside :func:`figure_style`, which leaves rcParams as it found them)."""
    import matplotlib

    matplotlib.rcParams.update(_style_params())


#: Set for the ``physcam`` program (``physcam.cli.run`` sets :data:`physcam._program.RUNNING`), never by
#: the library: matplotlib is then imported without what that program never uses (:func:`_lean_import`).
PROGRAM_IMPORT = False


def _lean_import() -> None:
    """Import matplotlib for the ``physcam`` program, skipping what it never uses (issue 47,
    measured in docs/performance.md): the property tables matplotlib writes into the docstring of
    every artist class's ``set()`` as the class is made (``matplotlib.artist.kwdoc``: a third of
    matplotlib's import, 0.15 s of CPU), the signature listing those properties (0.04-0.06 s),
    its 3-D toolkit, which registering the ``3d`` projection imports with every figure, and the code of
    :data:`LAZY_MODULES` until something reads them. Only when
    matplotlib is not imported yet and :data:`PROGRAM_IMPORT` (or :data:`physcam._program.RUNNING`) is
    set; a library caller's matplotlib is left whole.

    The cycle collector is kept out of the import and then shown the door (``gc.freeze``, as
    ``physcam serve`` settles its heap): matplotlib's import makes some 75,000 objects that live as long
    as the process (modules, classes, functions), and the program's collection threshold (50,000,
    :data:`physcam._program.GC_THRESHOLD`) fell twice inside it, each collection scanning the 50,000
    made since the last (15-27 ms), and the interpreter's last collection at exit scanned them once more. Frozen, they
    are never scanned: a cold figure command takes about 0.1 s less CPU (docs/performance.md, issue 47
    round 20). What is alive then stays alive (a frozen cycle is never freed): what the command has
    made so far, which it holds to the end anyway, and the import's own few hundred objects of
    garbage."""
    import sys

    from . import _program

    if not (PROGRAM_IMPORT or _program.RUNNING) or "matplotlib.artist" in sys.modules:
        return
    import gc
    import warnings

    collecting = gc.isenabled()
    gc.disable()
    try:
        import matplotlib.artist

        matplotlib.artist.kwdoc = lambda artist: "(see the matplotlib documentation)"
        # each artist class's set() gets a signature listing its properties, found by inspecting every
        # method of the class (matplotlib.artist.ArtistInspector: 92 classes, 0.06 s of CPU); set() itself
        # takes its keywords from the class's alias map, so the program keeps only the flag it checks
        matplotlib.artist.Artist._update_set_signature_and_docstring = classmethod(_mark_set_generated)
        finder = _LazyModules()
        sys.meta_path.insert(0, finder)
        try:
            _import_projections(sys, warnings)
            import matplotlib.backends.backend_agg  # noqa: F401  (every figure's canvas)
            import matplotlib.figure  # noqa: F401
        finally:
            sys.meta_path.remove(finder)
        _png_plugin_only()
    finally:
        gc.freeze()
        if collecting:
            gc.enable()


#: Modules matplotlib imports once, with a plain ``import``, and reads only for what physcam's figures never
#: draw: TeX's glyph names (``matplotlib.dviread``'s ``fontTools.agl``, 7-10 ms of CPU). The program imports
#: them lazily: a module's code runs at its first use (docs/performance.md, "Round 10"). (dateutil's parser
#: cannot be: ``matplotlib.dates`` imports it a second time, and a second import runs a lazy module. Nor can
#: ``matplotlib.dates`` itself: importing it registers the date converters, which ``matplotlib.axes`` never
#: reads, so lazily a date axis would find none: round 21 tried it and its review found a date plot failing.)
LAZY_MODULES = ("fontTools.agl",)


class _LazyModules:
    """A meta-path finder that hands out :data:`LAZY_MODULES` through ``importlib.util.LazyLoader``
    (the standard library's lazy import: the module object now, its code at the first attribute read)."""

    def find_spec(self, name, path=None, target=None):
        if name not in LAZY_MODULES:
            return None
        import importlib.machinery
        import importlib.util

        spec = importlib.machinery.PathFinder.find_spec(name, path)
        if spec is not None and spec.loader is not None:
            spec.loader = importlib.util.LazyLoader(spec.loader)
        return spec


def _import_projections(sys, warnings) -> None:
    """matplotlib's projections without the 3-D toolkit (:func:`_lean_import`)."""
    if "mpl_toolkits.mplot3d" not in sys.modules:
        sys.modules["mpl_toolkits.mplot3d"] = None  # the projections' import of it fails: no "3d" projection
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                import matplotlib.projections  # noqa: F401
        finally:
            del sys.modules["mpl_toolkits.mplot3d"]


def _png_plugin_only() -> None:
    """Pillow's first save with a format named (matplotlib's PNG) runs ``PIL.Image.preinit``, which imports
    the BMP, GIF, JPEG and PPM plugins beside PNG's (7-14 ms of CPU). matplotlib has imported PNG's plugin
    (``matplotlib.colors`` reads its ``PngInfo``), so the program marks that first step done (:func:`_lean_import`).
    Nothing is lost: Pillow loads every plugin (``PIL.Image.init``) when asked to open or save a format it
    has not registered, as it does for any format past the first five."""
    from PIL import Image

    if getattr(Image, "_initialized", None) == 0 and "PNG" in getattr(Image, "SAVE", {}):
        Image._initialized = 1


def _mark_set_generated(cls) -> None:
    """What ``Artist.__init_subclass__`` needs of ``_update_set_signature_and_docstring`` (the flag that
    the class's ``set`` was made by matplotlib), without the signature and docstring (:func:`_lean_import`)."""
    cls.set._autogenerated_signature = True


_LOCK = threading.RLock()  # rcParams is one dict for all threads: one styled drawing at a time
_STATE = threading.local()


def _depth() -> int:
    return getattr(_STATE, "depth", 0)


@contextlib.contextmanager
def figure_style():
    """A context in which matplotlib draws physcam's figures: matplotlib's own defaults plus
    :data:`STYLE` and :data:`PALETTE`, whatever the caller's settings (a ``matplotlib.rc_context``;
    the caller's rcParams come back on leaving it). To change a setting for physcam's figures, set
    it inside this context. Nested uses cost nothing. rcParams is one dict for the whole process, so
    threads take turns: while one draws in this context, another thread's plots see physcam's
    settings, and code inside it must not wait for another thread that draws (it would wait for ever)."""
    depth = _depth()
    _STATE.depth = depth + 1
    try:
        if depth:
            yield
            return
        _lean_import()
        import matplotlib

        with _LOCK, matplotlib.rc_context():
            _rcdefaults(matplotlib)  # (keeps the backend and the other settings styles never touch)
            matplotlib.rcParams.update(_style_params())
            yield
    finally:
        _STATE.depth = max(0, _depth() - 1)


#: The settings ``matplotlib.rcdefaults()`` leaves as they are (matplotlib's style blacklist: the backend, the
#: interactive and GUI settings, the date epoch, ...; tests/test_figures_rcparams.py checks this copy against it).
RC_KEPT = frozenset({"backend", "backend_fallback", "date.epoch", "docstring.hardcopy", "figure.max_open_warning",
                     "figure.raise_window", "interactive", "savefig.directory", "timezone", "tk.window_focus", "toolbar",
                     "webagg.address", "webagg.open_in_browser", "webagg.port", "webagg.port_retries"})


def _rcdefaults(matplotlib) -> None:
    """What ``matplotlib.rcdefaults()`` does, without importing ``matplotlib.style`` for its blacklist (which
    reads matplotlib's whole style library, 9 ms of a cold figure command: issue 47)."""
    import warnings

    with warnings.catch_warnings():  # deprecated settings warned once, when matplotlib made its defaults
        warnings.simplefilter("ignore", matplotlib.MatplotlibDeprecationWarning)
        matplotlib.rcParams.clear()
        matplotlib.rcParams.update({k: v for k, v in matplotlib.rcParamsDefault.items() if k not in RC_KEPT})


def _settle(fig) -> None:
    """Fix now, in the style, what matplotlib would otherwise take from the caller's rcParams at their
    first draw of a returned figure: the first tick of each axis (later ticks copy its font, size and
    lines: ``Axis.get_major_ticks``) and the tick label size the tick spacing is worked from
    (``Axis.get_tick_space`` reads ``xtick.labelsize`` when drawing)."""
    import matplotlib

    for ax in getattr(fig, "axes", ()):
        for name, axis in getattr(ax, "_axis_map", {}).items():
            axis.get_major_ticks(1)
            axis.get_minor_ticks(1)
            kw = getattr(axis, "_major_tick_kw", None)
            if isinstance(kw, dict) and "labelsize" not in kw and f"{name}tick.labelsize" in matplotlib.rcParams:
                kw["labelsize"] = matplotlib.rcParams[f"{name}tick.labelsize"]


def styled(func):
    """Decorator: ``func`` runs inside :func:`figure_style`, so the figures it makes, draws and saves
    are physcam's while the caller's rcParams stay theirs. A Figure it returns is complete in style,
    but for what matplotlib reads only when drawing (``axes.unicode_minus``, ``text.hinting``): a
    caller who draws it under other settings draws those their way."""

    @functools.wraps(func)
    def in_style(*args, **kwargs):
        with figure_style():
            result = func(*args, **kwargs)
            if hasattr(result, "canvas") and hasattr(result, "axes"):
                _settle(result)
            return result

    return in_style


#: A space :func:`fit_title` never breaks a line at (it prints as a plain space): a label and its value.
NO_BREAK = "\u00a0"


def unbroken(text: str) -> str:
    """``text`` (a label and its value, "focus 6' 6 3/4\"") kept on one line by :func:`fit_title`."""
    return str(text).replace(" ", NO_BREAK)


def fit_title(text: str, width_in: float, *, fontsize: float | None = None, weight: str = "normal") -> str:
    """``text`` wrapped at word boundaries so that each line, set in the style's font at ``fontsize``
    points (default the title size) and ``weight``, is at most ``width_in`` inches wide (measured by
    matplotlib); never at a :data:`NO_BREAK` space (see :func:`unbroken`), which comes out as a plain space.

    Greedy: a line takes words while it fits. A run of a line's glyphs is never wider than the line (the
    glyphs are set left to right, a run's box is inside the line's), so where what is left of a paragraph
    fits on one line every line the greedy would try fits too and is not measured."""
    size = fontsize or STYLE["axes.titlesize"]
    limit = width_in * 72.0

    def width(s: str) -> float:
        return _title_width_pt(s, size, weight)

    out = []
    for para in str(text).split("\n"):
        words = para.split(" ")
        fits = len(words) == 1 or width(_greedy_join(words)) <= limit  # the rest of the paragraph fits
        line = ""
        for k, word in enumerate(words):
            trial = f"{line} {word}" if line else word
            if line and not fits and width(trial) > limit:
                out.append(line)
                line = word
                fits = width(_greedy_join(words[k:])) <= limit
            else:
                line = trial
        out.append(line)
    return "\n".join(out).replace(NO_BREAK, " ")


def _greedy_join(words: list[str]) -> str:
    """``words`` joined as :func:`fit_title` joins them when nothing breaks (an empty first word, of a
    leading space, dropped)."""
    line = ""
    for word in words:
        line = f"{line} {word}" if line else word
    return line


@functools.lru_cache(maxsize=4096)
def _title_width_pt(text: str, size, weight: str) -> float:
    """The width (points) of ``text`` set in the style's font at ``size`` (points, or a size name) and
    ``weight`` (matplotlib's text-to-path measure), remembered: titles and their trial lines repeat from
    figure to figure."""
    from matplotlib.font_manager import FontProperties
    from matplotlib.textpath import text_to_path

    prop = FontProperties(family=STYLE["font.sans-serif"], size=size, weight=weight)
    return text_to_path.get_text_width_height_descent(text, prop, ismath=False)[0]


def new_figure(figsize=None, dpi=None, **kwargs):
    """A ``Figure`` attached to an Agg canvas (no pyplot), with physcam's figure settings (size,
    white face). Axes and artists take physcam's style when made inside :func:`figure_style`
    (every physcam function that draws does so); outside it, the caller's rcParams."""
    _lean_import()
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    inside = _depth() > 0
    with figure_style():
        fig = Figure(figsize=figsize, dpi=dpi, **kwargs)
    FigureCanvasAgg(fig)
    fig._physcam_unstyled = not inside  # STRICT_ENV: a physcam figure made outside the style is a bug
    return fig


def subplots(nrows: int = 1, ncols: int = 1, *, figsize=None, dpi=None, squeeze: bool = True, **kwargs):
    """``(fig, axes)`` as ``pyplot.subplots`` gives them, on an Agg canvas: figure and axes (spines,
    grid) in physcam's style; what is drawn on them later, in the style only inside :func:`figure_style`."""
    fig = new_figure(figsize=figsize, dpi=dpi)
    with figure_style():
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


def dots(ax, x, y, sizes, color="k"):
    """``ax.scatter(x, y, s=sizes, c=color, lw=0)`` (round dots, ``sizes`` in points^2) drawn as what
    they cover on a raster canvas: each dot's area in pixels spread bilinearly over the four pixels
    around its centre and the dots composited over one another as Agg composites them
    (1 - prod(1 - coverage)), one image instead of one antialiased path per dot (a spot diagram's
    56,000 dots: 0.22 s of Agg's path rendering, issue 47). Dots under a pixel across are where
    the two agree (tests/test_figures_dots.py measures both); SVG and PDF draw the scatter itself."""
    coll = ax.scatter(x, y, s=sizes, c=color, lw=0)
    coll.__class__ = _coverage_dots_class()
    return coll


@functools.cache
def _coverage_dots_class():
    from matplotlib.backends.backend_agg import RendererAgg
    from matplotlib.collections import PathCollection

    class CoverageDots(PathCollection):
        """A scatter of round dots that an Agg canvas draws as one coverage image (:func:`dots`)."""

        def draw(self, renderer):
            if not isinstance(renderer, RendererAgg) or not self.get_visible():
                return super().draw(renderer)
            renderer.open_group("dots", self.get_gid())
            gc = renderer.new_gc()
            self._set_gc_clip(gc)
            image, x0, y0 = _coverage_image(self, renderer.points_to_pixels(1.0), self.axes.bbox)
            if image is not None:
                renderer.draw_image(gc, x0, y0, image)
            gc.restore()
            renderer.close_group("dots")
            self.stale = False

    return CoverageDots


def _coverage_image(coll, px_per_pt: float, box):
    """(RGBA image, left, bottom) of :func:`dots` over the pixels of ``box`` (display units)."""
    import numpy as np

    xy = coll.get_offset_transform().transform(coll.get_offsets())
    area = np.broadcast_to(coll.get_sizes(), (len(xy),)) * (np.pi / 4.0 * px_per_pt ** 2)  # diameter^2 pi / 4
    x0, y0 = int(np.floor(box.x0)), int(np.floor(box.y0))
    w, h = int(np.ceil(box.x1)) - x0, int(np.ceil(box.y1)) - y0
    u, v = xy[:, 0] - x0 - 0.5, xy[:, 1] - y0 - 0.5  # from the first pixel's centre
    inside = (u > -1.0) & (u < w) & (v > -1.0) & (v < h) & (area > 0)
    if w <= 0 or h <= 0 or not inside.any():
        return None, x0, y0
    u, v, area = u[inside], v[inside], area[inside]
    i, j = np.floor(u), np.floor(v)
    fu, fv = u - i, v - j
    i, j = i.astype(np.int64) + 1, j.astype(np.int64) + 1  # a border of one pixel each side, cut below
    lost = np.zeros((h + 2) * (w + 2))  # sum of log(1 - coverage) per pixel
    for di, wu in ((0, 1.0 - fu), (1, fu)):
        for dj, wv in ((0, 1.0 - fv), (1, fv)):
            cover = np.minimum(area * wu * wv, 1.0 - 1e-12)
            lost += np.bincount((j + dj) * (w + 2) + i + di, weights=np.log1p(-cover), minlength=lost.size)
    alpha = -np.expm1(lost.reshape(h + 2, w + 2)[1:-1, 1:-1])
    rgba = np.empty((h, w, 4), dtype=np.uint8)
    rgba[..., :3] = np.round(np.asarray(coll.get_facecolor()[0][:3]) * 255.0).astype(np.uint8)
    rgba[..., 3] = np.round(alpha * (255.0 * coll.get_facecolor()[0][3]))
    return rgba, x0, y0  # the first row at the bottom, as draw_image takes it


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


#: The panels' share of a figure with a context line under it (figure fractions: left, bottom, right, top):
#: :func:`context_line`.
CONTEXT_RECT = (0.0, 0.05, 1.0, 1.0)


def context_line(fig, text: str) -> None:
    """``text`` (the shot: f-stop, focus, sensor) as a line under ``fig``'s panels, so a plot says what it is
    of; lay the panels out in :data:`CONTEXT_RECT` (``fig.tight_layout(rect=CONTEXT_RECT)``) to leave it room."""
    fig.text(0.5, 0.01, text, ha="center", va="bottom", fontsize=7, color="0.3")


#: Where matplotlib leaves a title that has nothing to clear (axes fraction): :func:`title_y`.
TITLE_Y = 1.0


def title_y(ax):
    """``ax.set_title(..., y=title_y(ax))``, called once the axes holds its data: :data:`TITLE_Y` (the title
    placed once) where matplotlib's own placement would leave it there, else None (matplotlib places it).

    matplotlib places each title at every layout pass and every draw (``Axes._update_title_position``),
    laying out the y axis whole (ticks, tick labels, label) to find its offset text, and moves the title only
    above top tick labels, a top x label or an offset text ("1e-7") it meets at that moment, which can be
    during a layout pass, before the axes have their final place. An axes with none of these (x ticks and
    label at the bottom, no offset on the y axis for its ticks now, no twin) keeps its title at 1.0, and the
    picture is the same, byte for byte, for about a sixth less of a figure's CPU (a spot diagram's 25-35 ms;
    issue 47, round 21)."""
    xaxis, yaxis = ax.xaxis, ax.yaxis
    if xaxis.get_ticks_position() in ("top", "unknown") or xaxis.get_label_position() == "top":
        return None
    if ax._twinned_axes.get_siblings(ax) != [ax] or ax.child_axes:
        return None
    formatter = yaxis.get_major_formatter()
    formatter.format_ticks(yaxis.get_majorticklocs())  # (what each draw does first: its offset for these ticks)
    return None if formatter.get_offset() else TITLE_Y

#: The dots per inch figures are saved at (:func:`save_figure`, :func:`figure_bytes`). A figure laid out at the
#: dpi it is saved at (made with ``dpi=SAVE_DPI``) is measured and drawn by one renderer, which remembers its
#: text metrics (``physcam compare``'s figure: docs/performance.md, round 21).
SAVE_DPI = 130


def figure_format(path) -> str:
    """The format a figure file is written in, from its name's extension: "png", "svg" or "pdf"; an
    :class:`~physcam.errors.ExportError` for any other name (the program refuses it as it reads the
    command line, ``physcam.cli._common.figure_file``, before the command's work)."""
    from .errors import ExportError

    p = Path(path)
    fmt = _FORMATS.get(p.suffix.lower())
    if fmt is None:
        raise ExportError(f"cannot save a figure as {p.name!r}: use a .png, .svg or .pdf file name")
    return fmt


@styled
def save_figure(fig, path, *, force: bool = False, dpi: int = SAVE_DPI) -> Path:
    """Write ``fig`` to ``path`` (.png, .svg or .pdf, from the extension) and close it.

    Raises :class:`~physcam.errors.ExportError` for another extension or an existing file
    without ``force``.
    """
    from .errors import ExportError
    from .io import atomic_write, check_writable

    p = Path(path)
    try:
        fmt = figure_format(p)
    except ExportError:
        _PLOT.close(fig)
        raise
    check_writable(p, force=force)
    return atomic_write(p, figure_bytes(fig, fmt, dpi=dpi), force=force)


@styled
def figure_bytes(fig, fmt: str = "svg", *, dpi: int = SAVE_DPI, description: str | None = None) -> bytes:
    """``fig`` drawn in memory as ``fmt`` ("png", "svg" or "pdf") and closed: what :func:`save_figure`
    writes, for a caller that sends it elsewhere (``physcam serve``). ``description`` (SVG and PDF)
    goes into the file's metadata (SVG: ``dc:description``), e.g. numbers a web page reads."""
    from .errors import ExportError, WrongTypeError

    if not callable(getattr(fig, "savefig", None)):
        raise WrongTypeError(f"fig must be a matplotlib Figure, got {type(fig).__name__}")
    if fmt not in _FORMATS.values():
        _PLOT.close(fig)
        raise ExportError(f"cannot draw a figure as {fmt!r}: use one of png, svg, pdf")
    check = _StyleCheck(fig) if os.environ.get(STRICT_ENV) == "1" else None
    _skip_layout_rerun(fig)
    buf = io.BytesIO()
    try:
        meta = None if description is None or fmt == "png" else {"Description" if fmt == "svg" else "Subject":
                                                                     description}
        fig.savefig(buf, format=fmt, dpi=dpi, metadata=meta)
        if check is not None:
            check.verdict()
    finally:
        if check is not None:
            check.disconnect()
        _PLOT.close(fig)
    return buf.getvalue()


#: Set to "1" (tests/test_figures_style.py), every figure physcam saves is checked by
#: :func:`figure_problems` first, and one that breaks the style, or was made by :func:`new_figure`
#: outside :func:`figure_style` (a drawing function without :func:`styled`), raises ExportError.
STRICT_ENV = "PHYSCAM_STRICT_FIGURES"


class _StyleCheck:
    """The strict check (:data:`STRICT_ENV`) of a figure being saved: :func:`figure_problems` of the draw that
    writes it (matplotlib's ``draw_event``, at the file's dpi), not of a draw of its own before, which drew every
    figure twice; :meth:`verdict` raises ExportError on a problem, before a byte is written."""

    def __init__(self, fig):
        self.fig, self.problems = fig, None
        self.cid = fig.canvas.mpl_connect("draw_event", self._drawn)

    def _drawn(self, event) -> None:
        self.problems = _drawn_problems(self.fig, event.renderer)

    def disconnect(self) -> None:
        self.fig.canvas.mpl_disconnect(self.cid)

    def verdict(self) -> None:
        problems = figure_problems(self.fig) if self.problems is None else list(self.problems)  # (drawn: always)
        if getattr(self.fig, "_physcam_unstyled", False):
            problems.append("it was made outside physcam.figures.figure_style (a drawing function without @styled)")
        if problems:
            from .errors import ExportError

            raise ExportError("the figure breaks physcam's figure style: " + "; ".join(problems))


def _has_unit(label: str) -> bool:
    """An axis label names its unit in parentheses, or is of a ratio (:data:`UNITLESS_WORDS`)."""
    import re

    return bool(re.search(r"\([^)]*\S[^)]*\)", label)) or any(w.lower() in label.lower() for w in UNITLESS_WORDS)


def _texts(artist, ticks) -> list:
    """Every Text under ``artist``, in the order of ``artist.findobj(Text)``, an axis's ticks taken from
    ``ticks`` (id of the axis: its major and minor ticks) where given instead of asked for again; none of an
    axis whose entry is None (not drawn)."""
    from matplotlib.text import Text

    if id(artist) in ticks:
        if ticks[id(artist)] is None:  # an axis not drawn
            return []
        major, minor = ticks[id(artist)]
        children = [artist.label, artist.offsetText, *major, *minor]  # matplotlib's Axis.get_children()
    else:
        children = artist.get_children()
    out = [t for c in children for t in _texts(c, ticks)]
    if isinstance(artist, Text):
        out.append(artist)
    return out


@styled
def figure_problems(fig) -> list[str]:
    """What breaks the figure style in ``fig``, drawn (in the style, as physcam saves it): text
    (titles, labels, ticks, legends) reaching outside the figure, tick labels of one axis running into
    each other, and axes with ticks but no label or a label without a unit. Empty when none."""
    from matplotlib.figure import Figure

    from .errors import require_type

    require_type("fig", fig, Figure, "a matplotlib Figure (physcam's figures return one)")
    # laid out as drawn (ticks, constrained layout, text sizes) without rasterising a pixel: the text
    # extents are the same as after canvas.draw() (compared on the lens cards), in half the time
    fig.draw_without_rendering()
    return _drawn_problems(fig, fig.canvas.get_renderer())


def _overlapping_ticks(name, ax, major, hidden, renderer) -> list[str]:
    """The major tick labels of one side of an axis (``label1``, then ``label2``) that run into their neighbour
    as drawn: ``16' 5"9' 10 1/8"`` under a breathing plot's marks, which crowd toward close focus."""
    out = []
    for side in ("label1", "label2"):
        shown = [t for t in (getattr(tick, side) for tick in major)
                 if t.get_visible() and t.get_text().strip() and id(t) not in hidden]
        boxes = sorted(((t.get_window_extent(renderer), t) for t in shown), key=lambda p: (p[0].x0, p[0].y0))
        for (a, ta), (b, tb) in zip(boxes, boxes[1:]):
            if a.overlaps(b):
                out.append(f"{name} tick labels {ta.get_text()!r} and {tb.get_text()!r} of "
                           f"{ax.get_title(loc='left')[:40] or ax.get_title()[:40]!r} overlap")
    return out


def _drawn_problems(fig, renderer) -> list[str]:
    """:func:`figure_problems` of ``fig`` just drawn by ``renderer``."""
    import re

    box = fig.bbox
    problems = []
    hidden = set()  # tick labels of ticks outside the view: matplotlib keeps them but does not draw them
    ticks = {}  # each axis's ticks as the draw left them, asked once (each ask runs its tick locator)
    for ax in fig.axes:
        for axis in (ax.xaxis, ax.yaxis):
            if not ax.get_visible() or not ax.axison:  # an axes shown off (an image) draws no axis text:
                ticks[id(axis)] = None  # none of it is looked at (nor its ticks made and located to be skipped)
                continue
            ticks[id(axis)] = major, minor = axis.get_major_ticks(), axis.get_minor_ticks()
            lo, hi = sorted(axis.get_view_interval())
            for tick in major + minor:
                if not lo - 1e-9 * abs(hi - lo) <= tick.get_loc() <= hi + 1e-9 * abs(hi - lo):
                    hidden.update({id(tick.label1), id(tick.label2)})
    for t in _texts(fig, ticks):
        if not t.get_visible() or not t.get_text().strip() or id(t) in hidden:
            continue
        b = t.get_window_extent(renderer)
        if b.x0 < box.x0 - 1 or b.y0 < box.y0 - 1 or b.x1 > box.x1 + 1 or b.y1 > box.y1 + 1:
            problems.append(f"text {t.get_text()[:50]!r} reaches outside the figure")
    for ax in fig.axes:
        if not ax.get_visible() or not ax.axison:
            continue
        for name, axis in (("x", ax.xaxis), ("y", ax.yaxis)):
            # its major tick labels as drawn (what axis.get_ticklabels() gives after updating the ticks again)
            labels = [t for tick in ticks[id(axis)][0] for t in (tick.label1, tick.label2) if t.get_visible()]
            if not axis.get_visible() or not [t for t in labels if t.get_text()]:
                continue
            problems += _overlapping_ticks(name, ax, ticks[id(axis)][0], hidden, renderer)
            label = axis.get_label_text()
            if not label.strip():
                problems.append(f"{name} axis of {ax.get_title()[:40]!r} has tick labels but no label")
            elif not _has_unit(label):
                problems.append(f"{name} axis label {label!r} names no unit")
            elif re.search(r"\bum\b", label):
                problems.append(f"{name} axis label {label!r} writes um for µm")
    return problems

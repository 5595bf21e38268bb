"""A picture of the depth-of-field zone against distance, for a DP to read at a glance."""

from __future__ import annotations

import math

#: Millimetres per axis unit, and the axis label, per unit system (``--units``).
_AXIS = {"m": (1000.0, "m"), "ft": (304.8, "ft")}


def plot_dof_zone(report, path, *, force: bool = False, units: str = "m"):
    """Draw near, focus, far and hyperfocal on a distance axis (from the film plane); PNG, SVG or PDF.

    ``units``: ``m`` (metres) or ``ft`` (feet; the marks in feet and inches). Written atomically
    through :func:`physcam.io.atomic_write`.
    """
    from ..figures import save_figure
    from ..io import check_writable

    check_writable(path, force=force)
    return save_figure(dof_zone_figure(report, units=units), path, force=force)


def plot_title(report, units: str = "m") -> str:
    """Lens, f-stop, focus, CoC and sensor: what a depth-of-field picture is of."""
    from ..units import format_distance

    lens = report.lens_name or f"{report.focal_length_mm:g} mm"
    focus = format_distance(report.focus_from_film_mm, units)
    return (f"{lens}  f/{report.fstop:.3g}  focus {focus}  CoC {report.coc_mm:.4g} mm ({report.coc_convention})  "
            f"{report.sensor.name}")


def dof_zone_figure(report, *, size_in=(9.0, 2.6), units: str = "m"):
    """The figure :func:`plot_dof_zone` saves, as a matplotlib Figure on its own Agg canvas (no pyplot
    state, so a server can draw it in memory with :func:`physcam.figures.figure_bytes`); ``size_in``
    is (width, height) in inches (a phone screen reads a narrower one); ``units`` m or ft."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure
    from matplotlib.ticker import FuncFormatter, LogLocator

    from ..errors import UnitError
    from ..units import format_distance

    if units not in _AXIS:
        raise UnitError(f"units must be one of {', '.join(_AXIS)}, got {units!r}")
    per, label = _AXIS[units]
    d = report.dof
    near, far = d.near_from_film_mm / per, d.far_from_film_mm / per
    focus = report.focus_from_film_mm / per
    hyper = d.hyperfocal_from_film_mm / per
    finite_focus = math.isfinite(focus)
    top = max(hyper, focus if finite_focus else 0.0)
    right = top * 1.3 if math.isinf(far) else max(far, focus) * 1.4
    right = max(right, near * 2)
    fig = Figure(figsize=tuple(size_in), dpi=120)
    FigureCanvasAgg(fig)
    ax = fig.add_subplot(1, 1, 1)
    ax.axvspan(near, min(far, right), color="#9fd3a8", alpha=0.7, label="acceptably sharp")
    if report.dof_horizontal is not None:
        dh = report.dof_horizontal
        ax.axvspan(dh.near_from_film_mm / per, min(dh.far_from_film_mm / per, right), ymin=0.0, ymax=0.25,
                   color="#5b8fd6", alpha=0.6, label="horizontal (anamorphic)")
    left = min(near, focus) / 3.0
    marks = [(near, "near", "-", 0.82, "right"), (far, "far", "-", 0.28, "left"),
             (hyper, "hyperfocal", ":", 0.82, "left")]
    if finite_focus:
        marks.insert(1, (focus, "focus", "-", 0.55, "left"))
    for x, lab, style, y, ha in marks:
        if x < right:
            ax.axvline(x, color="k", ls=style, lw=1.2)
            dx = 0.98 if ha == "right" else 1.02
            ax.text(x * dx, y, f"{lab} {format_distance(x * per, units)}", transform=ax.get_xaxis_transform(), ha=ha,
                    va="center", fontsize=8, bbox=dict(boxstyle="round,pad=0.2", fc="white", ec="none", alpha=0.8))
    if math.isinf(far):
        ax.text(right, 0.5, "→ ∞", ha="right", va="center", fontsize=12)
    ax.set_xscale("log")
    ax.set_xlim(left, right)
    ax.xaxis.set_major_locator(LogLocator(base=10, subs=(1.0, 2.0, 5.0)))
    ax.xaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
    ax.xaxis.set_minor_formatter(FuncFormatter(lambda v, _: ""))
    ax.set_yticks([])
    ax.set_xlabel(f"distance from the film plane ({label}, log scale)")
    ax.set_title(plot_title(report, units), fontsize=9)
    ax.legend(loc="lower right", fontsize=7)
    fig.tight_layout()
    return fig

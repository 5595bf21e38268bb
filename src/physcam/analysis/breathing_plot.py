"""Focus breathing plot: horizontal field of view and focal length against focus mark.

The x axis is the reciprocal of the focus mark (1/m, dioptres of the mark measured
from the film plane; 1/ft in feet), so infinity sits at 0 and close focus spreads out; tick
labels give the marks in metres, or feet and inches with ``units="ft"`` (to 1/8 inch below 10 ft, as
everywhere: :func:`physcam.units.format_distance`). Rows come from
:func:`physcam.optics.focusing.breathing_table`.
"""

from __future__ import annotations

import math
from pathlib import Path

from ..errors import InputError, WrongTypeError

__all__ = ["PLOT_FORMATS", "breathing_figure", "save_breathing_plot"]

PLOT_FORMATS = ("png", "svg", "pdf")


def breathing_figure(rows, *, title: str = "focus breathing", sensor_width_mm: float | None = None,
                     units: str = "m"):
    """A matplotlib Figure (Agg canvas) of HFOV (left axis) and EFL (right axis) against 1/mark;
    ``units`` ("m" or "ft") for the focus axis."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    from ..optics.focusing import BreathingRow
    from ..units import UNIT_SYSTEMS
    from ._plot import tick_label

    if units not in UNIT_SYSTEMS:
        raise InputError(f"units must be one of {', '.join(UNIT_SYSTEMS)}, got {units!r}")
    per = 1000.0 if units == "m" else 304.8

    rows = list(rows) if isinstance(rows, (list, tuple)) else rows
    if not isinstance(rows, list) or not all(isinstance(r, BreathingRow) for r in rows):
        raise WrongTypeError("rows must be a list of BreathingRow (physcam.optics.focusing.breathing_table)")
    if not rows:
        raise InputError("no breathing rows to plot")
    x = [0.0 if math.isinf(r.focus_from_film_mm) else per / r.focus_from_film_mm for r in rows]
    fig = Figure(figsize=(7.5, 4.2))
    FigureCanvasAgg(fig)
    ax = fig.add_subplot(1, 1, 1)
    ax.plot(x, [r.hfov_deg for r in rows], marker="o", color="#1f4e79", label="horizontal FOV")
    ax.set_ylabel("horizontal field of view (deg)" + (f", {sensor_width_mm:g} mm sensor" if sensor_width_mm else ""))
    ax.set_xlabel(f"focus mark from the film plane ({'m' if units == 'm' else 'feet and inches'})")
    ticks = [r for r in rows if not math.isinf(r.focus_from_film_mm)]
    ax.set_xticks([0.0] + [per / r.focus_from_film_mm for r in ticks])
    ax.set_xticklabels(["∞"] + [tick_label(r.focus_from_film_mm, units) for r in ticks], fontsize=7)
    ax2 = ax.twinx()
    ax2.plot(x, [r.efl_mm for r in rows], marker="s", linestyle="--", color="#c0392b", label="EFL")
    ax2.set_ylabel("effective focal length (mm)")
    ax.grid(True, alpha=0.3)
    ax.set_title(title, fontsize=10)
    fig.legend(loc="lower left", bbox_to_anchor=(0.1, 0.15), fontsize=8)
    fig.tight_layout()
    return fig


def save_breathing_plot(rows, path, *, force: bool = False, **kwargs) -> Path:
    """Write the breathing plot to ``path`` (.png, .svg, .pdf) through atomic_write."""
    from ..figures import save_figure

    return save_figure(breathing_figure(rows, **kwargs), path, force=force, dpi=150)

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

from ...errors import InputError, WrongTypeError
from ...figures import styled

__all__ = ["PLOT_FORMATS", "breathing_figure", "draw_breathing", "save_breathing_plot"]

PLOT_FORMATS = ("png", "svg", "pdf")


@styled
def breathing_figure(rows, *, title: str = "focus breathing", sensor_width_mm: float | None = None,
                     units: str = "m"):
    """A matplotlib Figure (Agg canvas) of HFOV (left axis) and EFL (right axis) against 1/mark;
    ``units`` ("m" or "ft") for the focus axis."""
    from ...figures import fit_title, new_figure

    rows = _checked_rows(rows, units)
    fig = new_figure(figsize=(7.5, 4.2))
    ax = fig.add_subplot(1, 1, 1)
    draw_breathing(ax, rows, sensor_width_mm=sensor_width_mm, units=units)
    ax.set_title(fit_title(title, 7.0))
    fig.tight_layout()
    _thin_ticks(ax)  # the axes as tight_layout left them
    return fig


def _checked_rows(rows, units):
    from ...optics.focusing import BreathingRow
    from ...units import UNIT_SYSTEMS

    if units not in UNIT_SYSTEMS:
        raise InputError(f"units must be one of {', '.join(UNIT_SYSTEMS)}, got {units!r}")
    rows = list(rows) if isinstance(rows, (list, tuple)) else rows
    if not isinstance(rows, list) or not all(isinstance(r, BreathingRow) for r in rows):
        raise WrongTypeError("rows must be a list of BreathingRow (physcam.optics.focusing.breathing_table)")
    if not rows:
        raise InputError("no breathing rows to plot")
    return rows


@styled
def draw_breathing(ax, rows, *, sensor_width_mm: float | None = None, units: str = "m", legend_loc: str = "lower left"):
    """Draw breathing ``rows`` on axes ``ax``: HFOV on ``ax``, EFL on a twin axis at the right (returned)."""
    from ...figures import PALETTE
    from .._plot import tick_label

    rows = _checked_rows(rows, units)
    per = 1000.0 if units == "m" else 304.8
    x = [0.0 if math.isinf(r.focus_from_film_mm) else per / r.focus_from_film_mm for r in rows]
    ax.plot(x, [r.hfov_deg for r in rows], marker="o", color=PALETTE[0], label="horizontal FOV")
    ax.set_ylabel("horizontal field of view (deg)" + (f", {sensor_width_mm:g} mm sensor" if sensor_width_mm else ""))
    ax.set_xlabel(f"focus mark from the film plane ({'m' if units == 'm' else 'feet and inches'})")
    ticks = [r for r in rows if not math.isinf(r.focus_from_film_mm)]
    ax.set_xticks([0.0] + [per / r.focus_from_film_mm for r in ticks])
    ax.set_xticklabels(["∞"] + [tick_label(r.focus_from_film_mm, units) for r in ticks], fontsize=7)
    _thin_ticks(ax)
    ax2 = ax.twinx()
    ax2.spines["right"].set_visible(True)
    ax2.plot(x, [r.efl_mm for r in rows], marker="s", linestyle="--", color=PALETTE[1], label="EFL")
    ax2.set_ylabel("effective focal length (mm)")
    ax.grid(True)
    lines = ax.get_lines() + ax2.get_lines()
    ax.legend(lines, [ln.get_label() for ln in lines], loc=legend_loc)
    return ax2


def _thin_ticks(ax, pad_pt: float = 4.0) -> None:
    """Hide the x tick labels that would run into the last one shown, left to right, measured: each label's
    width as drawn at its size against where its tick stands on the axes as laid out now, ``pad_pt`` points
    apart at least. Marks crowd toward close focus on a 1/distance axis and feet and inches are long
    (``16' 5"`` beside ``9' 10 1/8"``), while a fraction of the span (the rule before) hid a metric card's 10 m
    with room to spare. A figure laid out again after (tight_layout) thins again."""
    fig = ax.figure
    r = fig.canvas.get_renderer()
    lo, hi = ax.get_xlim()
    box = ax.get_window_extent(r)
    scale, pad = box.width / ((hi - lo) or 1.0), pad_pt * fig.dpi / 72.0
    right = -math.inf
    for x, lab in sorted(zip(ax.get_xticks(), ax.get_xticklabels()), key=lambda p: p[0]):
        lab.set_visible(True)  # measured shown (a hidden text has no extent), then hidden if it collides
        half = 0.5 * lab.get_window_extent(r).width
        centre = box.x0 + (x - lo) * scale
        if centre - half < right + pad:
            lab.set_visible(False)
        else:
            right = centre + half


@styled
def save_breathing_plot(rows, path, *, force: bool = False, **kwargs) -> Path:
    """Write the breathing plot to ``path`` (.png, .svg, .pdf) through atomic_write."""
    from ...figures import save_figure

    return save_figure(breathing_figure(rows, **kwargs), path, force=force, dpi=150)

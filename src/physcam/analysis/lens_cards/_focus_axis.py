"""The focus-mark axis of a card's panels: 1 / mark from the film plane (infinity at 0, close focus spread
out), one tick per mark labelled in metres or feet and inches, as the breathing plot draws it
(:mod:`physcam.analysis.framing.breathing_plot`)."""

from __future__ import annotations

import math

def focus_x(mark_mm: float, units: str) -> float:
    """Where a focus mark (mm from the film plane) sits on the axis: 1 / mark in 1/m (1/ft); infinity 0."""
    per = 1000.0 if units == "m" else 304.8
    return 0.0 if math.isinf(mark_mm) else per / mark_mm


def focus_axis(ax, marks_mm, units: str) -> None:
    """Ticks at ``marks_mm`` on ``ax``'s x axis, labelled as focus marks, and the axis label."""
    from .._plot import tick_label
    from ..framing.breathing_plot import _thin_ticks

    marks = sorted(set(marks_mm), reverse=True)
    ax.set_xticks([focus_x(m, units) for m in marks])
    ax.set_xticklabels([tick_label(m, units) for m in marks], fontsize=6.5)
    _thin_ticks(ax)
    ax.set_xlabel(f"focus mark from the film plane ({'m' if units == 'm' else 'feet and inches'})")

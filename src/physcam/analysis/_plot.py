"""Matplotlib helpers for the analyses (see :mod:`physcam.figures`): Agg canvases, no pyplot."""

from __future__ import annotations

from ..figures import save_figure, subplots


def figure(width: float = 5.0, height: float = 3.6, ncols: int = 1):
    fig, axes = subplots(1, ncols, figsize=(width, height), squeeze=True)
    return fig, axes


def save(fig, path=None, force: bool = False):
    """Lay out ``fig``; write it to ``path`` and return the path, or return the figure."""
    fig.tight_layout()
    return fig if path is None else save_figure(fig, path, force=force)


# ---- scene distances on an axis (``units`` m or ft, docs/conventions.md "Printed distances") ----------
def per_unit(units: str) -> float:
    """Millimetres per axis unit: 1000 for metres, 304.8 for feet (1 ft = 304.8 mm exactly)."""
    from ..errors import UnitError
    from ..units import UNIT_SYSTEMS

    if units not in UNIT_SYSTEMS:
        raise UnitError(f"units must be one of {', '.join(UNIT_SYSTEMS)}, got {units!r}")
    return 1000.0 if units == "m" else 304.8


def unit_words(units: str) -> str:
    """How an axis label names the unit system: "m" or "feet and inches"."""
    per_unit(units)
    return "m" if units == "m" else "feet and inches"


def tick_label(value_mm: float, units: str) -> str:
    """A scene distance as a tick label: metres without the unit (``2``, ``0.5``; the axis label says m),
    or feet and inches as on a focus ring (``6' 6 3/4"``: :func:`physcam.units.format_distance`); ``∞``."""
    import math

    from ..units import format_distance

    per_unit(units)
    if math.isinf(value_mm):
        return "∞"
    return f"{value_mm / 1000.0:g}" if units == "m" else format_distance(value_mm, "ft")


def distance_ticks(ax, marks_mm, units: str, *, x_of_inf: float | None = None) -> list[float]:
    """Put scene distances ``marks_mm`` (mm) on ``ax``'s x axis in ``units``: positions in metres or
    feet, one tick at each mark labelled by :func:`tick_label`, no minor ticks; an infinite mark sits
    at ``x_of_inf`` (axis units). Returns the x positions, in the order of ``marks_mm``."""
    import math

    from matplotlib.ticker import FixedFormatter, FixedLocator, NullFormatter, NullLocator

    per = per_unit(units)
    xs = [x_of_inf if math.isinf(m) else m / per for m in marks_mm]
    ticks = sorted({(x, tick_label(m, units)) for x, m in zip(xs, marks_mm) if x is not None})
    ax.xaxis.set_major_locator(FixedLocator([x for x, _ in ticks]))
    ax.xaxis.set_major_formatter(FixedFormatter([lab for _, lab in ticks]))
    ax.xaxis.set_minor_locator(NullLocator())
    ax.xaxis.set_minor_formatter(NullFormatter())
    return xs

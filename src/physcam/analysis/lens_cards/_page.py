"""What the functions of a card's further pages (:mod:`.zoom_page`, :mod:`.anamorphic_page`) check."""

from __future__ import annotations

from ...errors import InputError, require_type


def sensor_size(sensor_mm) -> tuple[float, float]:
    """(width, height) of the sensor in mm, each positive."""
    from ...errors import require_positive

    if not (isinstance(sensor_mm, (tuple, list)) and len(sensor_mm) == 2):
        raise InputError(f"sensor_mm must be (width, height) in mm, got {sensor_mm!r}")
    return require_positive("sensor width", sensor_mm[0]), require_positive("sensor height", sensor_mm[1])


def millimetres(length_mm: float) -> str:
    """A length inside the camera (the entrance pupil in front of the film) as a card prints it: millimetres to
    0.1 mm in every unit system, as docs/cli.md says of focal length, principal planes, pupil, CoC and sensor
    (:func:`physcam.units.format_distance` in metres prints the same below 1 m; in feet it gave 1/8 inches)."""
    return f"{float(length_mm):.1f} mm"


def checked_drawing(fig, page, cls, units) -> None:
    """The arguments of a page's drawing function: a matplotlib Figure, its page, and m or ft."""
    from matplotlib.figure import Figure

    from .._plot import per_unit

    require_type("fig", fig, Figure, "a card-sized matplotlib Figure")
    require_type("page", page, cls, "the card's page (LensCard.zoom_page or .anamorphic_page)")
    per_unit(units)


def draw_distortion_curves(ax, curves, xlabel: str, *, ncol: int = 1) -> None:
    """A page's distortion panel: ``curves`` are (label, meridian points, line style, colour), each point
    with ``real_height_mm`` and ``distortion_pct``; a curve without points is left out, and a panel
    with none says so instead of drawing empty axes."""
    shown = False
    for label, pts, style, colour in curves:
        if pts:
            shown = True
            ax.plot([abs(p.real_height_mm) for p in pts], [p.distortion_pct for p in pts], style, color=colour,
                    label=label)
    if not shown:
        ax.set_axis_off()
        ax.text(0.5, 0.5, "no distortion: see the notes", transform=ax.transAxes, ha="center", fontsize=7)
        return
    ax.axhline(0.0, color="0.6", lw=0.6)
    ax.grid(True)
    ax.set_xlabel(xlabel, fontsize=7)
    ax.set_ylabel("distortion (%)")
    ax.legend(loc="best", fontsize=6, ncol=ncol)

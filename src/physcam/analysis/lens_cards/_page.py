"""What the functions of a card's further pages (:mod:`.zoom_page`, :mod:`.anamorphic_page`) check."""

from __future__ import annotations

from ...errors import InputError, require_type


def sensor_size(sensor_mm) -> tuple[float, float]:
    """(width, height) of the sensor in mm, each positive."""
    from ...errors import require_positive

    if not (isinstance(sensor_mm, (tuple, list)) and len(sensor_mm) == 2):
        raise InputError(f"sensor_mm must be (width, height) in mm, got {sensor_mm!r}")
    return require_positive("sensor width", sensor_mm[0]), require_positive("sensor height", sensor_mm[1])


def checked_drawing(fig, page, cls, units) -> None:
    """The arguments of a page's drawing function: a matplotlib Figure, its page, and m or ft."""
    from matplotlib.figure import Figure

    from .._plot import per_unit

    require_type("fig", fig, Figure, "a card-sized matplotlib Figure")
    require_type("page", page, cls, "the card's page (LensCard.zoom_page or .anamorphic_page)")
    per_unit(units)

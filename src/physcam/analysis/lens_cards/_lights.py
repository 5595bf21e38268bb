"""Where a lens card's bokeh lights stand (both its bokeh panels: the first page's and the anamorphic page's)."""

from __future__ import annotations

import math

def light_distance_mm(camera, efl_mm: float) -> float:
    """The lights' distance in front of the film plane (mm): half the camera's focus distance, or 15 focal
    lengths (``efl_mm``) when it is focused at infinity; at least 1.5 times the front vertex's distance from
    the film, so that a lens longer than that (a zoom's or an anamorphic adapter's glass) still has its
    lights in front of it."""
    focus = camera.focus_from_film_mm
    depth = 15.0 * abs(efl_mm) if math.isinf(focus) else 0.5 * focus
    if camera.film_z is not None:  # lens space: the film's z from the front vertex
        front = camera.film_z
    else:
        front = camera.lens.total_track + camera.lens.surfaces[-1].thickness
    return max(depth, 1.5 * front)

"""Hyperfocal tables for a set of lenses: the focus mark that holds infinity, per focal length and stop.

Each cell is the lens report's own hyperfocal focus (physcam.onset.report, ``focus_mm=HYPERFOCAL``):
the subject plane at H = f^2 / (N c) + f from H1, marked from the film (thin lens: H + s'(H)), the
near limit H / 2 from H1; the CoC by the sensor and convention, as in every report.
"""

from __future__ import annotations

from .report import HYPERFOCAL, solve_report
from .request import report_camera

__all__ = ["hyperfocal_table"]


def hyperfocal_table(focal_lengths_mm, fstops, *, sensor, coc=None) -> list[dict]:
    """One row per focal length: {"focal_length_mm", "coc_mm", "coc_convention", "marks": {fstop: (mark
    from the film, near limit from the film)}}."""
    rows = []
    for f in focal_lengths_mm:
        marks, rep = {}, None
        for n in fstops:
            rep = solve_report(report_camera(sensor=sensor, focal_length_mm=f, fstop=n, focus_mm=HYPERFOCAL, coc=coc))
            marks[n] = (rep.focus_from_film_mm, rep.dof.near_from_film_mm)
        rows.append({"focal_length_mm": f, "coc_mm": rep.coc_mm, "coc_convention": rep.coc_convention, "marks": marks})
    return rows

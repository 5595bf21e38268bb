"""Split focus as an answer: "focus here, at this stop" to hold a near and a far subject.

With both limits wanted, the focus lies at their harmonic mean about H1, 1/s = (1/near + 1/far) / 2,
whatever the lens and stop (physcam.optics.dof.focus_for_dof_limits), and the stop that holds both
at the CoC is N = f^2 / (c h), h the hyperfocal parameter either limit gives. Both come from the
lens report's own inverse solve (physcam.onset.report.solve_report, focus and f-stop solved from the
near and far limits); with a stop given as well, the answer adds that stop's real limits at the mark.
"""

from __future__ import annotations

import math
from typing import NamedTuple

from .report import LensReport, solve_report
from .request import INPUTS, ReportRequest, checked_inputs, report_camera

__all__ = ["SplitFocus", "split_focus"]


class SplitFocus(NamedTuple):
    focus_from_film_mm: float  # focus here
    fstop_needed: float  # at this stop (or slower)
    coc_mm: float
    coc_convention: str
    near_from_film_mm: float  # the wanted limits
    far_from_film_mm: float
    given: LensReport | None = None  # the report at the given stop, focused at the mark

    @property
    def given_holds(self) -> bool | None:
        return None if self.given is None else self.given.fstop >= self.fstop_needed * (1 - 1e-9)

    def to_dict(self) -> dict:
        g = self.given
        return {"focus_from_film_mm": self.focus_from_film_mm, "fstop_needed": self.fstop_needed,
                "coc_mm": self.coc_mm, "coc_convention": self.coc_convention,
                "near_from_film_mm": self.near_from_film_mm,
                "far_from_film_mm": None if math.isinf(self.far_from_film_mm) else self.far_from_film_mm,
                "fstop_given": None if g is None else g.fstop, "given_holds": self.given_holds,
                "given_near_from_film_mm": None if g is None else g.dof.near_from_film_mm,
                "given_far_from_film_mm": None if g is None or g.dof.far_is_infinite else g.dof.far_from_film_mm}


def split_focus(request: ReportRequest | None = None, /, **inputs) -> SplitFocus:
    """The split-focus answer for the report's inputs (the keywords of
    :func:`~physcam.onset.request.report_camera`: ``near_mm`` and ``far_mm`` are the subjects to hold, from
    the film; ``fstop``, if any, the stop the camera is at): the mark, the stop needed at the inputs' CoC
    convention, and the given stop's limits at that mark. A :class:`ReportRequest` (deprecated, issue 43)
    is read as its inputs."""
    from ..errors import InputError, require_type

    if request is not None:
        require_type("request", request, ReportRequest, "split_focus(sensor=..., near_mm=..., far_mm=..., ...)")
        inputs = {k: getattr(request, k) for k in INPUTS}
    r = checked_inputs(inputs)
    if r.near_mm is None or r.far_mm is None:
        raise InputError("split focus needs the near and the far subject (--near, --far)")
    need = solve_report(report_camera(**{**inputs, "fstop": None, "focus_mm": None, "tstop": None}))
    given = None
    if r.fstop is not None:
        given = solve_report(report_camera(**{**inputs, "focus_mm": need.focus_from_film_mm, "near_mm": None,
                                              "far_mm": None, "coc": need.coc_mm}))
    return SplitFocus(need.focus_from_film_mm, need.fstop, need.coc_mm, need.coc_convention, r.near_mm, r.far_mm,
                      given)

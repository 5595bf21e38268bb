"""The frame at the subject: how wide and how tall the picture is in the plane of sharp focus.

A thin lens of focal length f focused on a subject s from H1 images it at s' = s f / (s - f) behind
H2 with the lateral magnification m = -s' / s (negative: the image is inverted); the gate, w x h on
the film, then spans w / |m| by h / |m| in the subject plane (similar triangles through the
principal points: E. Hecht, *Optics*, 5th ed., §5.2.3). An anamorphic squeezing by ``squeeze`` sees
``squeeze`` times wider: the desqueezed width. At another distance d from H1 (a subject in front of
or behind the focus) the frame scales with d / s: the pinhole at the principal plane frames it.
"""

from __future__ import annotations

import math
from typing import NamedTuple

from ..errors import InputError, require_positive
from .report import takes_report

__all__ = ["Frame", "frame_at_focus", "frame_at_distance"]


class Frame(NamedTuple):
    """The picture's width and height (mm) in a plane ``distance_from_h1_mm`` in front of H1."""

    width_mm: float
    height_mm: float
    distance_from_h1_mm: float

    @property
    def diagonal_mm(self) -> float:
        return math.hypot(self.width_mm, self.height_mm)

    def to_dict(self) -> dict:
        return {"width_mm": self.width_mm, "height_mm": self.height_mm, "diagonal_mm": self.diagonal_mm,
                "distance_from_h1_mm": self.distance_from_h1_mm}


@takes_report
def frame_at_focus(report) -> Frame | None:
    """The frame in the plane of sharp focus of a lens report: the (desqueezed) gate over |m|; None when
    focused at infinity (no finite plane). The report's ``frame_at_focus`` in its JSON is this frame."""
    d = report.to_dict()["frame_at_focus"]
    return None if d is None else Frame(d["width_mm"], d["height_mm"], d["distance_from_h1_mm"])


@takes_report
def frame_at_distance(report, distance_from_h1_mm: float) -> Frame:
    """The frame at a subject ``distance_from_h1_mm`` in front of H1 (not the focus: then the frame is
    of the blurred subject), scaled from the frame at the focus by the pinhole at the principal plane:
    the gate times d / (H2 to film)."""
    d = require_positive("subject distance", distance_from_h1_mm)
    if d > 1e9:
        raise InputError(f"subject distance {d:g} mm is beyond 1000 km")
    f_pin = report.pinhole[0]  # H2 to the film for a thin lens or a datasheet; the best-match pinhole otherwise
    s = report.sensor
    return Frame(s.width_mm * report.squeeze * d / f_pin, s.height_mm * d / f_pin, d)

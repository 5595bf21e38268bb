"""Close-up lenses (diopters) on a prime: where it then focuses and its depth of field there.

A close-up lens of power P dioptres (1/m) is taken as a thin lens in contact with the prime's thin
lens, at its principal plane H1 (the thin-lens combination 1/f_c = 1/f + P, E. Hecht, *Optics*, 5th ed.,
§6.2.1; the few millimetres between a real diopter and the lens's principal plane are neglected,
which the makers' focusing charts also do). The prime focused on s (from its principal plane) keeps
its image distance s'; with the diopter the subject sharp on the film lies at s_d, 1/s_d = 1/s + P
(focused at infinity: 1/P, +1 at 1 m, +2 at 0.5 m). The entrance pupil keeps its diameter f / N, so
the combination works at N_c = N f_c / f, and the depth of field is the thin-lens one of f_c, N_c, c
about s_d (physcam.optics.dof). Distances ``*_from_film_mm`` add s' (the lens plane to the film).
"""

from __future__ import annotations

import math
from typing import NamedTuple

from ..errors import InputError, require_positive
from ..optics import dof as _dof
from ..optics import thinlens

__all__ = ["CloseUp", "close_up", "COMMON_DIOPTERS"]

#: The close-up lenses of a puller's kit (dioptres).
COMMON_DIOPTERS = (0.5, 1.0, 2.0, 3.0)


class CloseUp(NamedTuple):
    diopter: float
    focal_length_mm: float  # the combination's
    f_number: float  # the combination's working f-number, N f_c / f
    subject_from_lens_mm: float
    subject_from_film_mm: float
    near_from_film_mm: float
    far_from_film_mm: float  # inf when the combination's far limit is
    magnification: float

    @property
    def depth_of_field_mm(self) -> float:
        return self.far_from_film_mm - self.near_from_film_mm

    def to_dict(self) -> dict:
        inf = math.isinf(self.far_from_film_mm)
        return {"diopter": self.diopter, "focal_length_mm": self.focal_length_mm, "f_number": self.f_number,
                "subject_from_lens_mm": self.subject_from_lens_mm, "subject_from_film_mm": self.subject_from_film_mm,
                "near_from_film_mm": self.near_from_film_mm, "far_from_film_mm": None if inf else self.far_from_film_mm,
                "depth_of_field_mm": None if inf else self.depth_of_field_mm, "magnification": self.magnification}


def close_up(focal_length_mm: float, fstop: float, coc_mm: float, focus_mm: float, diopter: float) -> CloseUp:
    """A +``diopter`` close-up lens on a thin lens of ``focal_length_mm`` at ``fstop``, its focus ring at
    ``focus_mm`` (film plane to subject; ``math.inf`` for infinity), CoC ``coc_mm``."""
    from ..optics.coc import require_coc

    f = thinlens.require_focal_length(focal_length_mm)
    n = require_positive("f-stop", fstop, unit="")
    c = require_coc(coc_mm)
    p = require_positive("diopter", diopter, unit="dioptres")  # a close-up lens converges
    if p > 20.0:
        raise InputError(f"+{p:g} dioptres is a 50 mm magnifier, not a close-up lens; give the power in dioptres")
    s = thinlens.object_distance_for_marked(f, focus_mm)
    s_img = f if math.isinf(s) else thinlens.image_distance(f, s)
    power = p / 1000.0  # per mm
    f_c = 1.0 / (1.0 / f + power)
    s_d = 1.0 / ((0.0 if math.isinf(s) else 1.0 / s) + power)
    n_c = n * f_c / f
    near, far = _dof.dof_limits(f_c, n_c, c, s_d)
    return CloseUp(p, f_c, n_c, s_d, s_d + s_img, near + s_img, far + s_img, -s_img / s_d)

"""Depth of field of a thin lens, in exact form, and its inversions.

With f the focal length, N the f-number, c the circle of confusion on the film and s
the focused object distance measured from the front principal plane H1, the exact
thin-lens limits are

    h = f^2 / (N c)                       (the "hyperfocal parameter")
    H = h + f                             (hyperfocal distance, from H1)
    near = h s / (h + (s - f))
    far  = h s / (h - (s - f))            (infinite when s >= H (1 - HYPERFOCAL_RTOL))

Focused at infinity (s -> inf) the far limit is infinite and the near limit tends to h itself:
near = h / (1 + (h - f) / s) -> h. (Focused at H instead, near = H / 2.)

These follow from similar triangles with the entrance pupil (diameter f/N) at the
principal plane. Sources: Wikipedia, "Depth of field", section "Derivation of the
DOF formulae" (the forms with the hyperfocal distance H = f²/(Nc) + f); S. Ray,
*Applied Photographic Optics*, 3rd ed., §8.2; DOFMaster's calculator
(dofmaster.com/equations.html) uses the same forms. The seed document paired
H = f²/(Nc) + f with near/far forms that expect h: physcam does not (docs/lens-report.md).

The limits are reported from H1; the lens report converts them to the film plane.
Everything broadcasts over numpy arrays; lengths in mm. Every function answers with a finite
number (infinity only for a far limit, as documented) or raises a
:class:`~physcam.errors.PhysCamError`: focal length, f-number, CoC and limits above 0.
"""

from __future__ import annotations

import math

from ..errors import InputError, OpticsError
from . import _num as nx

__all__ = [
    "HYPERFOCAL_RTOL",
    "hyperfocal_distance",
    "dof_limits",
    "hyperfocal_parameter_from_near",
    "hyperfocal_parameter_from_far",
    "focus_for_dof_limits",
    "f_number_for_dof",
    "coc_for_dof",
]


_arr = nx.value
_out = nx.out

#: A focus within this fraction of the hyperfocal distance H counts as H: the far limit is
#: infinite. Focus marks solved to 1e-9 or read back from a float32 USD attribute (6e-8) land a
#: hair short of H, where the exact form gives a far limit of H / (relative gap), 1e8 H and more:
#: no scene is that deep, and printing it as a distance misleads. Within 1e-6 the far limit would be
#: over a million times H.
HYPERFOCAL_RTOL = 1e-6


def _h(f, a, b):
    """f^2 / (a b) for positive inputs, as (f / a)(f / b) so no product underflows to 0; a quotient too
    large for a float is an OpticsError (raised by :func:`_num.out` on the infinity)."""
    if type(f) is float and type(a) is float and type(b) is float:
        return (f / a) * (f / b)  # (Python floats: numpy's error state is not theirs, issue 47)
    with nx.float_errors_ignored():
        return (f / a) * (f / b)


def hyperfocal_distance(focal_length, f_number, coc):
    """Hyperfocal distance H = f²/(N c) + f, in mm from the front principal plane H1.

    Focused at H, the far limit reaches infinity and the near limit is H/2 (exactly,
    for this form). Source: Wikipedia "Hyperfocal distance", definition 1.

    >>> round(float(hyperfocal_distance(35.0, 11.0, 0.03)), 2)
    3747.12
    """
    f = nx.positive("focal length", focal_length)
    n = nx.positive("f-number", f_number, unit="")
    c = nx.positive("circle of confusion", coc)
    return _out(_h(f, n, c) + f, what="the hyperfocal distance")


def dof_limits(focal_length, f_number, coc, object_distance):
    """(near, far) limits of acceptable sharpness, in mm from H1 (exact thin-lens forms).

    ``far`` is ``inf`` when the focus is at or beyond the hyperfocal distance H, or within
    :data:`HYPERFOCAL_RTOL` of it. ``object_distance``
    may be ``inf`` (focus at infinity): then near = h = f²/(N c), the limit of the exact form.
    Raises :class:`OpticsError` if the subject is at or inside the focal length.

    DOFMaster's example, 50 mm f/4 focused 10 ft with c = 0.03 mm, gives near 8 ft 9 in
    and far 11 ft 8 in:

    >>> n, f = dof_limits(50.0, 4.0, 0.03, 3048.0)
    >>> round(n / 304.8, 3), round(f / 304.8, 3)
    (8.742, 11.681)
    """
    f = nx.positive("focal length", focal_length)
    n = nx.positive("f-number", f_number, unit="")
    c = nx.positive("circle of confusion", coc)
    s = nx.positive("focus distance", object_distance, allow_inf=True)
    if nx.any_true(s <= f):
        raise OpticsError("focus distance is at or inside the focal length: no real image forms")
    h = _out(_h(f, n, c), what="the hyperfocal parameter")
    near = h / (1.0 + (h - f) / s)  # = h s / (h + s - f), and h at s = inf
    denom = h - (s - f)  # = H - s
    finite = denom > HYPERFOCAL_RTOL * (h + f)
    far = nx.where(finite, h * s / nx.where(finite, denom, 1.0), math.inf)
    return _out(near, what="the near limit"), _out(far, allow_inf=True, what="the far limit")


def hyperfocal_parameter_from_near(focal_length, object_distance, near):
    """h = f²/(N c) recovered from a measured near limit: h = near (s - f) / (s - near).

    Distances from H1. Requires near < s.
    """
    f = nx.positive("focal length", focal_length)
    s = nx.positive("focus distance", object_distance, allow_inf=True)
    n = _arr(near)
    if nx.any_true(n <= 0) or not nx.all_true(nx.isfinite(n)):
        raise InputError("the near limit must be in front of the lens (> 0) and finite")
    if nx.any_true(n >= s):
        raise InputError("the near limit must be closer than the focus distance")
    return _out(n * (1.0 - f / s) / (1.0 - n / s), what="the hyperfocal parameter")  # = n (s - f) / (s - n)


def hyperfocal_parameter_from_far(focal_length, object_distance, far):
    """h = f²/(N c) recovered from a measured far limit: h = far (s - f) / (far - s).

    Distances from H1. Requires far > s; an infinite far limit gives no finite h.
    """
    f = nx.positive("focal length", focal_length)
    s = nx.positive("focus distance", object_distance)
    F = nx.positive("far limit", far, allow_inf=True)
    if nx.any_true(F <= s):
        raise InputError("the far limit must be beyond the focus distance")
    if not nx.all_true(nx.isfinite(F)):
        raise InputError(
            "an infinite far limit only says the focus is at or beyond the hyperfocal distance; give a near limit"
        )
    return _out((s - f) / (1.0 - s / F), what="the hyperfocal parameter")  # = F (s - f) / (F - s), no overflow


def focus_for_dof_limits(near, far):
    """Focus distance s (from H1) that puts the limits at ``near`` and ``far``.

    From the exact forms, 1/near + 1/far = 2/s, so s is their harmonic mean
    2 near far / (near + far) whatever f, N and c are. An infinite far gives s = 2 near.
    """
    n = nx.positive("near limit", near)
    F = nx.positive("far limit", far, allow_inf=True)
    if nx.any_true(F <= n):
        raise InputError("need 0 < near limit < far limit")
    fin = nx.isfinite(F)
    Ff = nx.where(fin, F, 0.0)
    s = nx.where(fin, 2.0 * n / (1.0 + n / nx.where(fin, Ff, 1.0)), 2.0 * n)  # = 2 n F / (n + F)
    return _out(s, what="the focus distance")


def f_number_for_dof(focal_length, coc, h):
    """N = f² / (c h) for a hyperfocal parameter h (see the ``*_from_near`` helpers)."""
    f = nx.positive("focal length", focal_length)
    return _out(_h(f, nx.positive("circle of confusion", coc), nx.positive("hyperfocal parameter", h)),
                what="the f-number")


def coc_for_dof(focal_length, f_number, h):
    """c = f² / (N h) for a hyperfocal parameter h."""
    f = nx.positive("focal length", focal_length)
    return _out(_h(f, nx.positive("f-number", f_number, unit=""), nx.positive("hyperfocal parameter", h)),
                what="the circle of confusion")


def stops_between(n_effective: float, n_marked: float) -> float:
    """Difference in stops from ``n_marked`` to ``n_effective``: 2 log2(N_eff / N_marked).

    Positive means the effective aperture is smaller (more DOF) than marked.
    """
    e = nx.positive("effective f-number", n_effective, unit="")
    m = nx.positive("marked f-number", n_marked, unit="")
    return _out(2.0 * (nx.log2(e) - nx.log2(m)), what="the stops between")

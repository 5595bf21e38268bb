"""Cameras from depth of field measured on a plate (or wanted): the focus from a near and a far limit,
the f-stop from limits at a known focus. Each returns the camera (physcam.optics.state.CameraState)
with what it solved said in ``camera.solved``; the report of that camera
(``solve_report(camera, measured=...)``) then checks the limits against it.

Limits are from the film plane; the thin-lens relations are about H1 (physcam.optics.dof, its
sources): 1/near + 1/far = 2/s for the focus, the hyperfocal parameter h = f^2/(N c) from either
limit for the f-stop. H1 moves with focus in the thin-lens model, so the focus is iterated.
"""

from __future__ import annotations

import math

from ..errors import InputError, OpticsError, require_type
from ..optics import dof as _dof
from ..optics.lens_model import PrincipalPlanes, lens_model_of
from ..optics.thinlens import MAX_F_NUMBER, MIN_F_NUMBER

__all__ = ["focus_from_limits", "fstop_from_limits", "hyperfocal_parameters"]


def _coc(sensor, coc) -> float:
    from ..optics.coc import circle_of_confusion

    return circle_of_confusion(sensor.width_mm, sensor.height_mm, coc)[0]


def focus_from_limits(lens, *, sensor, near_mm=None, far_mm=None, fstop=None, coc=None, squeeze=None,
                      n_ratio: float = 1.0):
    """The camera of ``lens`` (a thin lens or a datasheet) focused so that its depth of field reaches
    ``near_mm`` and ``far_mm`` (from the film): their harmonic mean about H1; or one limit with
    ``fstop`` (the lens's f-number there is ``fstop * n_ratio``). Without an f-stop the f-stop is solved
    from the same limits too (:func:`fstop_from_limits`). ``coc``: a convention or mm on ``sensor``."""
    from ..optics.state import camera_state

    model = lens_model_of(lens)
    if model.kind == "prescription":
        raise InputError("with a lens prescription, give the focus mark (--focus)")
    planes = PrincipalPlanes.of(model.at_mark(math.inf, fstop, model.squeeze))
    f, c = planes.f, _coc(sensor, coc)
    if near_mm is not None and far_mm is not None:
        s = _focus_from_bracket(near_mm, far_mm, planes.h1_at, f)
    elif fstop is not None and (near_mm is not None or far_mm is not None):
        s = _focus_from_one_limit(near_mm, far_mm, f * f / (fstop * n_ratio * c), f, planes.h1_at)
    else:
        raise InputError("give a focus distance (--focus), or measured near and far limits (--near, --far), "
                         "or one limit with the f-stop")
    mark = planes.mark_for_s(s)
    solved = (("focus_from_film_mm", mark),)
    if fstop is None:
        return fstop_from_limits(model, focus_mm=mark, sensor=sensor, near_mm=near_mm, far_mm=far_mm, coc=coc,
                                 squeeze=squeeze, n_ratio=n_ratio, solved=solved)
    from .._record import replace

    return replace(camera_state(model, focus_mm=mark, fstop=fstop, sensor=sensor, squeeze=squeeze), solved=solved)


def fstop_from_limits(lens, *, focus_mm, sensor, near_mm=None, far_mm=None, coc=None, squeeze=None,
                      marked_fstop=None, n_ratio: float = 1.0, solved: tuple = ()):
    """The camera of ``lens`` focused at ``focus_mm`` with the f-stop (the iris's setting at infinity)
    whose depth of field for ``coc`` reaches the measured ``near_mm`` (else ``far_mm``): N = f^2 / (c h)
    / (the f-number ratio at this focus), h from the limit. ``marked_fstop``: the f-stop the lens was
    set to, compared in stops (``fstop_drift_stops``)."""
    from ..optics.state import camera_state

    model = lens_model_of(lens)
    if model.kind == "prescription":
        cam = camera_state(model, focus_mm=focus_mm, sensor=sensor, squeeze=squeeze)  # the file's stop
        at, mark = cam.at_mark, cam.focus_from_film_mm
        n_ratio = at.n_ratio
    else:
        mark = float(focus_mm)
        at = model.at_mark(mark, None, model.squeeze if squeeze is None else squeeze)
    planes, c = PrincipalPlanes.of(at), _coc(sensor, coc)
    s = planes.s_for_mark(mark)
    if math.isinf(s) and not solved and far_mm is not None and math.isfinite(far_mm):
        raise InputError("with the focus at infinity the far limit is infinite; a finite far limit is impossible")
    hp_near, hp_far = hyperfocal_parameters(planes, s, near_mm, far_mm)
    n = _dof.f_number_for_dof(planes.f, c, hp_near if hp_near is not None else hp_far) / n_ratio  # the iris's
    require_possible_f_number(n)
    solved = solved + (("fstop", n),)
    if marked_fstop is not None:
        solved += (("fstop_drift_stops", _dof.stops_between(n, marked_fstop)),)
    if model.kind == "prescription":
        return cam.with_fstop(n, solved=solved, lenient=True)
    # (built at a stop the door accepts, then set to the solved one: beyond f/4096 it is still the answer)
    cam = camera_state(model, focus_mm=mark, fstop=min(n, MAX_F_NUMBER), sensor=sensor, squeeze=squeeze)
    return cam.with_fstop(n, solved=solved, lenient=True)


def require_possible_f_number(n: float, name: str = "f-stop") -> None:
    """An f-number solved from measured limits is a real one (InputError saying what to check)."""
    if not (math.isfinite(n) and n > 0):
        raise InputError(f"the measured limits give an impossible {name} ({n:g}); check --near, --far and --focus")
    if n < MIN_F_NUMBER:
        raise InputError(f"the measured limits need f/{n:.3g}, faster than any lens in air can be "
                         f"(f/{MIN_F_NUMBER:g}); check --near, --far, --focus and the CoC")


def hyperfocal_parameters(planes: PrincipalPlanes, s: float, near, far):
    """h from the near limit and from a finite far limit (None where not measured), about H1 for the
    focus s (from H1)."""
    require_type("planes", planes, PrincipalPlanes, "physcam.onset.solvers.principal_planes(camera)")
    s = float(s)
    hp_near = hp_far = None
    if near is not None and math.isinf(s):
        hp_near = planes.to_h1(near, s)  # focused at infinity the near limit is h itself (s -> inf)
        if not hp_near > 0:
            raise InputError("the near limit must lie in front of the lens")
    elif near is not None:
        hp_near = _dof.hyperfocal_parameter_from_near(planes.f, s, planes.to_h1(near, s))
    if far is not None and math.isfinite(far):
        hp_far = _dof.hyperfocal_parameter_from_far(planes.f, s, planes.to_h1(far, s))
    if hp_near is None and hp_far is None:
        raise InputError("an infinite far limit alone cannot give the aperture; measure the near limit too")
    return hp_near, hp_far


def _focus_from_bracket(near_film, far_film, h1_at, f):
    p = f  # first guess for H1's distance from the film
    for _ in range(100):
        n, F = near_film - p, far_film - p
        if n <= f:
            raise OpticsError("the measured near limit is inside the focal length")
        s = float(_dof.focus_for_dof_limits(n, F))
        p_new = h1_at(s)
        if abs(p_new - p) < 1e-10 * max(1.0, p):
            return s
        p = p_new
    raise OpticsError("could not solve the focus distance from the near/far bracket")


def _focus_from_one_limit(near_film, far_film, hp, f, h1_at):
    p = f
    for _ in range(100):
        if near_film is not None:
            n = near_film - p
            if not 0 < n < hp:
                raise InputError("the near limit lies beyond the hyperfocal parameter f^2/(N c) (focus at infinity): "
                                 "no focus gives it; check the near limit, f-stop and CoC")
            s = n * (hp - f) / (hp - n)
        else:
            F = far_film - p
            s = F * (hp + f) / (hp + F)
        p_new = h1_at(s)
        if abs(p_new - p) < 1e-10 * max(1.0, p):
            return s
        p = p_new
    raise OpticsError("could not solve the focus distance from the measured limit")

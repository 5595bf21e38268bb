"""The on-set lens report's solvers: small pure functions, each named by its optics.

:func:`physcam.onset.report.solve_report` composes them in this order; each is importable on its own
(the Blender extension, ``serve`` and the USD kits call only what they need):

* :func:`lens_at_mark`: a prescription focused at the mark (unit or internal focusing) gives the
  technical model's EFL, H1, H2, entrance pupil, stop, f-number ratio and squeeze; a thin lens or
  a datasheet passes the request through.
* :func:`principal_planes`: where H1 and H2 sit in front of the film, and how a mark maps to the
  object distance s from H1 (thin lens: s + s' = mark; datasheet: s = mark - H1).
* :func:`solve_focus`: the focus mark, given, at the hyperfocal distance, or from measured limits.
* :func:`invert_limits`: the effective f-stop or the CoC from measured near/far limits.
* :func:`depth_of_field`: near, far and hyperfocal (exact thin-lens forms about H1), and an
  anamorphic's horizontal limits.
* :func:`focus_error`, :func:`field_of_view`, :func:`entrance_pupil`: where the sharp image lies,
  the fields of view at infinity and of the best-match pinhole, the entrance pupil.

Distances ``*_from_film`` are in front of the film plane; object distances s are from H1
(docs/conventions.md). Formulas: physcam.optics.thinlens and physcam.optics.dof (their sources).
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass, replace
from typing import NamedTuple

from ..errors import InputError, OpticsError, require_type
from ..optics import dof as _dof
from ..optics import thinlens
from .pupil import entrance_pupil_practical
from .request import HYPERFOCAL, MIN_F_NUMBER, ReportRequest

__all__ = ["DepthOfField", "LensState", "PrincipalPlanes", "lens_at_mark", "principal_planes", "solve_focus",
           "invert_limits", "depth_of_field", "focus_error", "field_of_view", "entrance_pupil"]


#: The solvers' arguments by name: the type each must be, and where one comes from.
_MADE_BY = {"req": ("ReportRequest", "physcam.onset.request.ReportRequest(sensor=..., ...)"),
            "state": ("LensState", "physcam.onset.solvers.lens_at_mark(request)"),
            "planes": ("PrincipalPlanes", "physcam.onset.solvers.principal_planes(state)"),
            "focus_solution": ("Focus", "physcam.onset.solvers.solve_focus(...)"),
            "ap": ("Aperture", "physcam.onset.solvers.invert_limits(...)")}


def _typed(fn):
    """Decorator: each argument named in :data:`_MADE_BY` must be of its type (WrongTypeError)."""
    names = fn.__code__.co_varnames[:fn.__code__.co_argcount]  # positional parameters, in order

    @functools.wraps(fn)
    def checked(*args, **kwargs):
        for name, value in (*zip(names, args), *kwargs.items()):
            if name in _MADE_BY:
                cls, hint = _MADE_BY[name]
                require_type(name, value, globals()[cls], hint)
        return fn(*args, **kwargs)

    return checked


def finite_or_none(v: float | None):
    return None if v is None or math.isinf(v) else v


@dataclass(frozen=True)
class DepthOfField:
    """Limits of acceptable sharpness for one circle of confusion.

    ``*_mm`` are from the front principal plane H1, ``*_from_film_mm`` from the film plane;
    ``far`` is ``inf`` when focused at or beyond the hyperfocal distance.
    """

    coc_mm: float
    hyperfocal_mm: float
    hyperfocal_from_film_mm: float
    near_mm: float
    far_mm: float
    near_from_film_mm: float
    far_from_film_mm: float

    @property
    def total_mm(self) -> float:
        return self.far_mm - self.near_mm

    @property
    def far_is_infinite(self) -> bool:
        return math.isinf(self.far_mm)

    def to_dict(self) -> dict:
        return {
            "coc_mm": self.coc_mm,
            "hyperfocal_mm": self.hyperfocal_mm,
            "hyperfocal_from_film_mm": self.hyperfocal_from_film_mm,
            "near_mm": self.near_mm,
            "far_mm": finite_or_none(self.far_mm),
            "total_mm": finite_or_none(self.total_mm),
            "near_from_film_mm": self.near_from_film_mm,
            "far_from_film_mm": finite_or_none(self.far_from_film_mm),
            "far_is_infinite": self.far_is_infinite,
        }


# --- the lens at the mark ----------------------------------------------------------------
class LensState(NamedTuple):  # a NamedTuple: made at every report, cheap to define at start-up
    """What the report's model takes from the lens at the mark (planes in front of the film): the
    request's own values for a thin lens or a datasheet; a prescription's focused Gaussian data."""

    focal_length_mm: float
    fstop: float | None
    focus_mm: float | str | None  # a prescription's hyperfocal focus is solved to a mark here
    model: str
    h1_from_film_mm: float | None
    h2_from_film_mm: float | None
    pupil_from_film_mm: float | None
    squeeze: float
    lens_name: str | None = None
    pinhole: tuple[float, float] | None = None  # (Y, X) best-match pinhole focal lengths, mm
    stop_from_film_mm: float | None = None
    n_ratio: float = 1.0  # f-number at this focus over the iris's f-stop (internal focusing)
    bellows: float | None = None  # working f-number over the f-stop
    blur_aspect: float = 1.0  # the lens's blur width over height, before desqueezing
    lens_squeeze: float = 1.0  # EFL in Y over EFL in X at this focus
    squeeze_from_lens: bool = False
    pupil_origin: str = "datasheet"
    notes: tuple[str, ...] = ()
    #: an anamorphic prescription's X-meridian (horizontal, pan) entrance pupil in front of the film;
    #: ``pupil_from_film_mm`` is then the Y meridian's (vertical, tilt). None: one pupil for both
    pupil_x_from_film_mm: float | None = None
    #: a prescription's EFL at infinity focus, (Y, X) mm: the field of view at infinity (None: the
    #: focal length, which a thin lens or a datasheet keeps at every focus)
    efl_infinity: tuple[float, float] | None = None


@_typed
def lens_at_mark(req: ReportRequest) -> LensState:
    """The lens at the mark. A prescription is focused there (physcam.optics.focusing): its EFL, H1,
    H2 and entrance pupil replace a datasheet's; without an f-stop or limits it is wide open."""
    if req.lens is None:
        ref = req.flange_focal_distance_mm if req.reference_plane == "flange" else 0.0  # offsets' plane

        def at(v):  # a datasheet offset, from the film
            return None if v is None else ref + v

        return LensState(req.focal_length_mm, req.fstop, req.focus_mm, req.model, at(req.h1_mm), at(req.h2_mm),
                         at(req.pupil_mm), req.squeeze, req.lens_name,
                         n_ratio=1.0 if req.fstop_at_focus is None else req.fstop_at_focus / req.fstop)
    from ..optics import focusing, paraxial

    lens, notes, fstop = req.lens, [], req.fstop
    if fstop is None and req.near_mm is None and req.far_mm is None:
        fstop = max(paraxial.gaussian(lens).f_number, lens.metadata.max_fstop or 0.0)  # the engraving, or slower
        notes.append(f"f-stop not given: wide open at f/{fstop:.3g}")
    mark = req.focus_mm
    if req.at_hyperfocal:
        from ..optics.coc import circle_of_confusion

        c, _ = circle_of_confusion(req.sensor.width_mm, req.sensor.height_mm, req.coc)
        mark, _ = focusing.hyperfocal_mark(lens, fstop, c)
    planes = focusing.technical_planes(lens, mark, fstop=fstop)
    notes.append(f"planes from the prescription focused at the mark ({planes.method} focusing): EFL "
                 f"{planes.efl_mm:.3f} mm, back focus {planes.back_focus_mm:.3f} mm")
    n_ratio = focusing.f_number_ratio(lens, mark)
    inf = paraxial.gaussian_xy(lens)
    state = LensState(planes.efl_mm, fstop, mark, "technical", planes.h1_from_film_mm, planes.h2_from_film_mm,
                      planes.entrance_pupil_from_film_mm, req.squeeze, req.lens_name or lens.name,
                      (planes.pinhole_focal_length_mm,) * 2, planes.stop_from_film_mm, n_ratio,
                      planes.working_f_number / planes.f_number * n_ratio, pupil_origin="prescription",
                      efl_infinity=(inf["y"].efl, inf["x"].efl))
    if lens.is_anamorphic:
        state = _anamorphic_state(req.lens, state, planes, notes)
    return state._replace(notes=tuple(notes))


def _anamorphic_state(lens, state: LensState, planes, notes: list) -> LensState:
    """An anamorphic prescription's squeeze at this focus (EFL in Y over X) and blur aspect (its
    entrance pupil's X over Y); when no squeeze was given, the lens's own frames each meridian."""
    from ..optics import focusing, paraxial

    st = focusing.focus(lens, state.focus_mm)
    gx = paraxial.gaussian(st.prescription, axis="x", object_z=st.object_z, film_z=st.film_z)
    lens_squeeze = planes.efl_mm / gx.efl
    state = state._replace(lens_squeeze=lens_squeeze, blur_aspect=focusing.pupil_aspect(lens, state.focus_mm),
                           pupil_x_from_film_mm=gx.in_front_of("entrance_pupil"))
    if abs(state.pupil_x_from_film_mm - state.pupil_from_film_mm) > 0.05:
        notes.append(f"anamorphic: two entrance pupils, horizontal (X, the pan pivot) "
                     f"{state.pupil_x_from_film_mm:.1f} mm and vertical (Y, the tilt pivot) "
                     f"{state.pupil_from_film_mm:.1f} mm in front of the film; the report's entrance pupil is "
                     "the vertical one")
    if state.squeeze != 1.0:
        return state
    notes.append(f"anamorphic: EFL {planes.efl_mm:.3f} mm (Y) and {gx.efl:.3f} mm (X), effective squeeze "
                 f"{lens_squeeze:.4f} (nominal {lens.squeeze:g})")
    return state._replace(squeeze=lens_squeeze, squeeze_from_lens=True,
                   pinhole=(planes.pinhole_focal_length_mm, gx.pinhole_focal_length))


# --- principal planes ------------------------------------------------------------------------
class PrincipalPlanes(NamedTuple):  # a NamedTuple: made at every report, cheap to define at start-up
    """Where H1 sits in front of the film, and how a focus mark D maps to the object distance s from
    H1. Thin lens (H1 = H2 = s' in front of the film): s + s' = D. Datasheet: H1 fixed, s = D - H1."""

    f: float
    h1_from_film: float | None = None  # the datasheet's H1 (None: the thin lens's, moving with focus)
    h2_from_film: float | None = None

    def h1_at(self, s: float) -> float:
        if self.h1_from_film is not None:
            return self.h1_from_film
        return self.f if math.isinf(s) else thinlens.image_distance(self.f, s)

    def s_for_mark(self, mark: float) -> float:
        if self.h1_from_film is None:
            return math.inf if math.isinf(mark) else thinlens.object_distance_for_marked(self.f, mark)
        s = mark - self.h1_from_film
        if s <= self.f:
            raise OpticsError(f"focus mark {mark:g} mm puts the subject {s:g} mm in front of H1, at or inside the "
                              f"{self.f:g} mm focal length: no real image")
        return s

    def mark_for_s(self, s: float) -> float:
        return s + self.h1_at(s)

    def to_h1(self, d_film: float, s: float) -> float:
        """A film-plane distance as a distance from H1 (for the focus s)."""
        return d_film - self.h1_at(s)


@_typed
def principal_planes(state: LensState) -> PrincipalPlanes:
    """The practical (thin lens) or technical (datasheet or prescription) planes of the lens."""
    if state.model == "practical":
        return PrincipalPlanes(state.focal_length_mm)
    return PrincipalPlanes(state.focal_length_mm, state.h1_from_film_mm, state.h2_from_film_mm)


# --- focus --------------------------------------------------------------------------------
class Focus(NamedTuple):  # a NamedTuple: made at every report, cheap to define at start-up
    """The focus: its mark from the film, the object distance s from H1 and the image distance s'
    from H2 (thin-lens s'), what was solved and said."""

    mark: float
    object_distance: float
    image_distance: float
    solved: dict
    notes: tuple[str, ...] = ()


@_typed
def solve_focus(req: ReportRequest, state: LensState, planes: PrincipalPlanes, c: float) -> Focus:
    """The focus mark as given; at the hyperfocal distance H = f^2/(N c) + f from H1 (Wikipedia,
    "Hyperfocal distance"); or from measured limits: 1/near + 1/far = 2/s about H1, or one limit with
    the f-stop (iterated, as H1 moves with focus in the thin-lens model)."""
    f, near, far, solved, notes = planes.f, req.near_mm, req.far_mm, {}, []
    mark = state.focus_mm
    if req.at_hyperfocal and req.lens is None:  # a prescription's mark is solved with the lens's own planes
        mark = planes.mark_for_s(_dof.hyperfocal_distance(f, state.fstop * state.n_ratio, c))
        solved["focus"] = HYPERFOCAL
        notes.append("focus at the hyperfocal distance (the focus mark above)")
    elif mark is None:
        if near is not None and far is not None:
            s = _solve_focus_from_bracket(near, far, planes.h1_at, f)
        elif state.fstop is not None and (near is not None or far is not None):
            hp = f * f / (state.fstop * state.n_ratio * c)
            s = _solve_focus_from_one_limit(near, far, hp, f, planes.h1_at)
        else:
            raise InputError("give a focus distance (--focus), or measured near and far limits (--near, --far), "
                             "or one limit with the f-stop")
        mark = planes.mark_for_s(s)
        solved["focus_from_film_mm"] = mark
    s = planes.s_for_mark(mark)
    s_img = f if math.isinf(s) else thinlens.image_distance(f, s)
    if math.isinf(s) and "focus_from_film_mm" not in solved and far is not None and math.isfinite(far):
        raise InputError("with the focus at infinity the far limit is infinite; a finite far limit is impossible")
    return Focus(mark, s, s_img, solved, tuple(notes))


def _solve_focus_from_bracket(near_film, far_film, h1_at, f):
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


def _solve_focus_from_one_limit(near_film, far_film, hp, f, h1_at):
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


# --- inversions from measured limits ----------------------------------------------------------
class Aperture(NamedTuple):  # a NamedTuple: made at every report, cheap to define at start-up
    """The f-stop (the iris's setting, at infinity) and the CoC, given or solved from limits."""

    fstop: float
    coc_mm: float
    coc_convention: str
    solved: dict
    notes: tuple[str, ...] = ()


@_typed
def invert_limits(req: ReportRequest, state: LensState, planes: PrincipalPlanes, focus_solution: Focus, c: float,
                  coc_name: str) -> Aperture:
    """The effective f-stop (when none is given, or the CoC is) or else the CoC from the measured
    near and/or far limits: the hyperfocal parameter h = f^2/(N c) from either limit
    (physcam.optics.dof), checked against the other when both are measured."""
    near, far, s, N, solved, notes = req.near_mm, req.far_mm, focus_solution.object_distance, state.fstop, {}, []
    one_limit_focus = "focus_from_film_mm" in focus_solution.solved and (near is None or far is None)
    if _is_split_focus(req, focus_solution) and N is not None:  # the stop is kept: what it holds, what is needed
        solved.update(_split_focus(planes, s, near, far, c, N, state.n_ratio))
        notes.append(f"split focus with the stop given: f/{N:.3g} holds less than the asked limits at this CoC "
                     f"({c:.4g} mm); they need f/{solved['fstop_needed']:.3g}" if N < solved["fstop_needed"] else
                     f"split focus: f/{N:.3g} holds the asked limits at this CoC ({c:.4g} mm); they need "
                     f"f/{solved['fstop_needed']:.3g}")
    elif (near is not None or far is not None) and not one_limit_focus:  # one limit and N made the focus
        hp_near, hp_far = _hyperfocal_parameters(planes, s, near, far)
        hp = hp_near if hp_near is not None else hp_far
        if hp_near is not None and hp_far is not None:
            solved.update(hyperfocal_parameter_from_near_mm=hp_near, hyperfocal_parameter_from_far_mm=hp_far,
                          consistency=abs(hp_far - hp_near) / hp_near)
            notes.append("near and far limits agree to {:.1%} in the hyperfocal parameter".format(solved["consistency"]))
        if N is None or req.coc is not None:
            marked, N = N, _dof.f_number_for_dof(planes.f, c, hp) / state.n_ratio  # the iris's setting
            solved["fstop"] = N
            if marked is not None:
                solved["fstop_drift_stops"] = _dof.stops_between(N, marked)
        else:
            c, coc_name = _dof.coc_for_dof(planes.f, N * state.n_ratio, hp), "solved"
            solved["coc_mm"] = c
        if far is not None and hp_near is not None:
            solved.update(_far_check(planes, s, N * state.n_ratio, c, far))
    if N is None:
        raise InputError("give the f-stop (--fstop) or a measured near/far limit to solve it")
    for name, v in (("f-stop", N), ("circle of confusion", c)):
        if not (math.isfinite(v) and v > 0):
            raise InputError(f"the measured limits give an impossible {name} ({v:g}); check --near, --far and --focus")
    if N < MIN_F_NUMBER:
        raise InputError(f"the measured limits need f/{N:.3g}, faster than any lens in air can be "
                         f"(f/{MIN_F_NUMBER:g}); check --near, --far, --focus and the CoC")
    return Aperture(N, c, coc_name, solved, tuple(notes))


def _is_split_focus(req: ReportRequest, focus_solution: Focus) -> bool:
    """Focus solved from a measured (or wanted) near and far limit: split focus."""
    return "focus_from_film_mm" in focus_solution.solved and req.near_mm is not None and req.far_mm is not None


def _split_focus(planes: PrincipalPlanes, s: float, near: float, far: float, c: float, n_given: float,
                 n_ratio: float) -> dict:
    """The stop a split focus needs to hold ``near`` to ``far`` (from the film) at the CoC ``c``: N = f^2 / (c h),
    h the hyperfocal parameter of either limit (they agree: the focus is their harmonic mean about H1)."""
    h = _dof.hyperfocal_parameter_from_near(planes.f, s, planes.to_h1(near, s))
    need = _dof.f_number_for_dof(planes.f, c, h) / n_ratio  # the iris's setting
    return {"fstop_needed": need, "fstop_needed_stops_over_given": _dof.stops_between(need, n_given)}


def _hyperfocal_parameters(planes: PrincipalPlanes, s: float, near, far):
    """h from the near limit and from a finite far limit (None where not measured)."""
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


def _far_check(planes: PrincipalPlanes, s: float, n_focus: float, c: float, far: float) -> dict:
    """The far limit the solved aperture predicts, against the measured one."""
    _, far_pred = _dof.dof_limits(planes.f, n_focus, c, s)
    pred = far_pred + planes.h1_at(s)
    both_inf = math.isinf(pred) and math.isinf(far)
    err = 0.0 if both_inf else (None if math.isinf(pred) or math.isinf(far) else pred - far)
    return {"far_predicted_from_film_mm": finite_or_none(pred), "far_error_mm": err}


# --- depth of field -------------------------------------------------------------------------
def dof_block(f, n, c, s, h1_film_at) -> DepthOfField:
    """DOF for object distance s (from H1, may be infinite); ``h1_film_at(s)`` gives H1's distance
    from the film. Exact thin-lens limits (physcam.optics.dof.dof_limits)."""
    near, far = _dof.dof_limits(f, n, c, s)
    H = _dof.hyperfocal_distance(f, n, c)
    return DepthOfField(coc_mm=c, hyperfocal_mm=H, hyperfocal_from_film_mm=H + h1_film_at(H), near_mm=near,
                        far_mm=far, near_from_film_mm=near + h1_film_at(s), far_from_film_mm=far + h1_film_at(s))


class DepthOfFieldResult(NamedTuple):  # a NamedTuple: made at every report, cheap to define at start-up
    dof: DepthOfField
    horizontal: DepthOfField | None  # an anamorphic's horizontal limits
    blur_aspect: float  # a defocused point's width over height in the desqueezed picture
    notes: tuple[str, ...] = ()


@_typed
def depth_of_field(req: ReportRequest, state: LensState, planes: PrincipalPlanes, focus_solution: Focus,
                   ap: Aperture) -> DepthOfFieldResult:
    """Near, far and hyperfocal at the f-number at this focus; an anamorphic's horizontal limits take
    c / blur aspect (docs/lens-report.md, "Anamorphic depth of field"): deeper for a front
    anamorphic, the same for a rear one. A prescription's hyperfocal distance is its hyperfocal mark."""
    n_focus, c, notes, sq = ap.fstop * state.n_ratio, ap.coc_mm, [], state.squeeze
    if abs(state.n_ratio - 1.0) > 0.005:
        notes.append(f"the iris set to f/{ap.fstop:.3g} (at infinity) makes the lens f/{n_focus:.3g} at this focus "
                     f"(internal focusing changes its EFL and entrance pupil); depth of field uses f/{n_focus:.3g}")
    dof = dof_block(planes.f, n_focus, c, focus_solution.object_distance, planes.h1_at)
    # desqueezing by sq where the lens squeezes by lens_squeeze stretches its blur by sq / lens_squeeze
    aspect = state.blur_aspect * sq / state.lens_squeeze if req.lens is not None else 1.0 / sq
    dof_h = None
    if sq != 1.0:
        dof_h = dof_block(planes.f, n_focus, c / aspect, focus_solution.object_distance, planes.h1_at)
        notes.append(_anamorphic_dof_note(sq, aspect, c, from_lens=req.lens is not None))
    if req.lens is not None:
        dof, dof_h = _hyperfocal_marks(req.lens, state, ap, dof, dof_h, aspect, notes)
    return DepthOfFieldResult(dof, dof_h, aspect, tuple(notes))


def _hyperfocal_marks(lens, state, ap, dof, dof_h, aspect, notes):
    """A real lens's principal planes move as it focuses: the hyperfocal *mark* is the one focus whose
    subject plane lies at H from H1 with the lens focused there, whatever the report's own focus; a
    lens that cannot focus there keeps H + H1 at this focus (said in a note)."""
    from ..optics.focusing import hyperfocal_mark

    try:
        mark, planes_h = hyperfocal_mark(lens, ap.fstop, ap.coc_mm)
        dof = replace(dof, hyperfocal_mm=mark - planes_h.h1_from_film_mm, hyperfocal_from_film_mm=mark)
        if dof_h is not None:
            mark, planes_h = hyperfocal_mark(lens, ap.fstop, ap.coc_mm,
                                             blur_aspect=None if state.squeeze_from_lens else aspect)
            dof_h = replace(dof_h, hyperfocal_mm=mark - planes_h.h1_from_film_mm, hyperfocal_from_film_mm=mark)
    except (OpticsError, InputError) as exc:
        notes.append(f"hyperfocal distance given as H plus H1 at this focus: the lens has no hyperfocal mark "
                     f"here ({str(exc).splitlines()[0]})")
    return dof, dof_h


def _anamorphic_dof_note(sq: float, aspect: float, c: float, *, from_lens: bool) -> str:
    """Why the horizontal limits differ from the vertical ones (or do not)."""
    source = ("the lens's entrance pupil, X over Y" if from_lens else
              "a front anamorphic's narrowed pupil, 1 / squeeze; a rear anamorphic's blur is round: give --lens")
    return (f"anamorphic {sq:g}x: a defocused point is {aspect:.3g} as wide as tall in the desqueezed picture "
            f"({source}), so the horizontal limits take the CoC c / {aspect:.3g} = {c / aspect:.4g} mm")


# --- focus error, field of view, entrance pupil -----------------------------------------------
@_typed
def focus_error(planes: PrincipalPlanes, focus_solution: Focus) -> tuple[float, float, float, tuple[str, ...]]:
    """(H1, H2 from the film, focus error, notes): where the sharp image lies in front of the film
    (+) with a datasheet's planes, H2 - s'; 0 for the thin lens, whose H2 is s' from the film."""
    if planes.h1_from_film is None:
        return focus_solution.image_distance, focus_solution.image_distance, 0.0, ()
    P2 = planes.h2_from_film
    if P2 <= 0:
        raise InputError(f"H2 must lie in front of the film plane, got {P2:g} mm; check --h2 and --reference")
    err = P2 - focus_solution.image_distance
    notes = () if abs(err) <= 1e-6 else (f"with these principal planes the sharp image lies {abs(err):.3f} mm "
                                         f"{'in front of' if err > 0 else 'behind'} the film plane",)
    return planes.h1_from_film, P2, err, notes


def _fov_deg(size, focal_or_image_distance):
    return math.degrees(2.0 * math.atan(size / (2.0 * focal_or_image_distance)))


@_typed
def field_of_view(req: ReportRequest, state: LensState, h2_film: float) -> dict:
    """The paraxial fields of view at infinity (the EFL at infinity focus: a prescription's own there, not at
    the mark) and at this focus through the best-match pinhole:
    the pinhole at the entrance pupil that frames like the lens, f_pin = n (film - exit pupil) /
    (n' m_p) (docs/lens-report.md, "The best-match pinhole"); exact per meridian for a prescription,
    H2 to the film for a thin lens or a datasheet (pupils on the principal planes)."""
    f, sq, w, h = state.focal_length_mm, state.squeeze, req.sensor.width_mm, req.sensor.height_mm
    f_inf, sq_inf = f, sq
    if state.efl_infinity is not None:  # a prescription's EFL changes with focus: the lens at infinity
        f_inf = state.efl_infinity[0]
        sq_inf = f_inf / state.efl_infinity[1] if state.squeeze_from_lens else sq
    pin_y, pin_x = state.pinhole if state.pinhole is not None else (h2_film, h2_film)
    pin_sq = pin_y / pin_x if pin_x != pin_y else sq  # an anamorphic frames each meridian by its own
    if req.pinhole_focal_length_mm is not None:
        pin_y = req.pinhole_focal_length_mm
        pin_sq = sq if req.pinhole_squeeze is None else req.pinhole_squeeze
    wd, wp = w * sq_inf, w * pin_sq
    return dict(hfov_inf_deg=_fov_deg(wd, f_inf), vfov_inf_deg=_fov_deg(h, f_inf),
                dfov_inf_deg=_fov_deg(math.hypot(wd, h), f_inf),
                hfov_focus_deg=_fov_deg(wp, pin_y), vfov_focus_deg=_fov_deg(h, pin_y),
                dfov_focus_deg=_fov_deg(math.hypot(wp, h), pin_y),
                pinhole_focal_length_mm=pin_y, pinhole_squeeze=pin_sq)


@_typed
def entrance_pupil(req: ReportRequest, state: LensState, h1_film: float) -> tuple[float | None, str, tuple]:
    """(pupil from the film, its source, notes): a datasheet's or the prescription's; a tape-measure
    estimate a fraction of the lens length behind its front; the thin lens's principal plane."""
    if state.pupil_from_film_mm is not None:
        return state.pupil_from_film_mm, state.pupil_origin, ()
    if req.sensor_front_mm is not None:
        pupil = entrance_pupil_practical(req.sensor_front_mm, req.lens_length_mm, req.pupil_fraction)
        return pupil, f"estimate: {req.pupil_fraction:g} of the lens length behind its front", ()
    if state.model == "practical":
        return h1_film, "thin lens: at the principal plane", ()
    return None, "unknown", ("no entrance pupil: give --pupil (technical) or --sensor-front and --lens-length",)

"""The on-set lens report's solvers: small pure functions of the camera, each named by its optics.

:func:`physcam.onset.report.solve_report` composes them in this order; each is importable on its own
(the Blender extension, ``serve`` and the USD kits call only what they need). The camera
(physcam.optics.state.CameraState) already holds the lens at its mark (``camera.at_mark``: EFL, H1,
H2, entrance pupil, stop, f-number ratio, squeeze), its focus and its f-stop, solved once:

* :func:`lens_at_mark`: the lens at the camera's mark, with what a USD file recorded of it
  (the f-number at the focus) taken as given.
* :func:`principal_planes`: where H1 and H2 sit in front of the film, and how a mark maps to the
  object distance s from H1 (thin lens: s + s' = mark; datasheet: s = mark - H1).
* :func:`solve_focus`: the object and image distances of the camera's mark.
* :func:`invert_limits`: the CoC from measured near/far limits (or the check of an f-stop solved from
  them, :mod:`physcam.onset.inverse`), a split focus's stop.
* :func:`depth_of_field`: near, far and hyperfocal (exact thin-lens forms about H1), and an
  anamorphic's horizontal limits.
* :func:`focus_error`, :func:`field_of_view`, :func:`entrance_pupil`: where the sharp image lies,
  the fields of view at infinity and of the best-match pinhole, the entrance pupil.

Distances ``*_from_film`` are in front of the film plane; object distances s are from H1
(docs/conventions.md). Formulas: physcam.optics.thinlens and physcam.optics.dof (their sources).
Each solver still takes its pre-issue-43 arguments (a ReportRequest first) for one version, with a
DeprecationWarning.
"""

from __future__ import annotations

import functools
import math
from typing import NamedTuple

from ..errors import InputError, OpticsError, require_type
from ..optics import dof as _dof
from ..optics import thinlens
from ..optics.lens_model import LensAtMark, PrincipalPlanes
from ..optics.state import HYPERFOCAL, CameraState
from .inverse import hyperfocal_parameters, require_possible_f_number
from .pupil import entrance_pupil_practical
from .request import MeasuredLimits, References, ReportRequest

from .._record import record, replace

__all__ = ["DepthOfField", "LensState", "PrincipalPlanes", "lens_at_mark", "principal_planes", "solve_focus",
           "invert_limits", "depth_of_field", "focus_error", "field_of_view", "entrance_pupil"]

#: The lens at the mark: what the report's model takes from it (pre-issue-43 name of
#: :class:`~physcam.optics.lens_model.LensAtMark`, which no longer carries the f-stop and the focus: the
#: camera does)
LensState = LensAtMark

#: The solvers' arguments by name: the type each must be, and where one comes from.
_MADE_BY = {"camera": ("CameraState", "physcam.optics.state.camera_state(lens, focus_mm=..., fstop=..., sensor=...)"),
            "planes": ("PrincipalPlanes", "physcam.onset.solvers.principal_planes(camera)"),
            "focus_solution": ("Focus", "physcam.onset.solvers.solve_focus(camera, planes)"),
            "ap": ("Aperture", "physcam.onset.solvers.invert_limits(...)")}


def _typed(fn):
    """Decorator: each argument named in :data:`_MADE_BY` must be of its type (WrongTypeError). A
    ReportRequest first (the pre-issue-43 form, with the LensState after it) is read as its camera, with a
    DeprecationWarning."""
    names = fn.__code__.co_varnames[:fn.__code__.co_argcount]  # positional parameters, in order
    typed = [(i, name) for i, name in enumerate(names) if name in _MADE_BY]  # (the rest are never checked)

    @functools.wraps(fn)
    def checked(*args, **kwargs):
        if args and isinstance(args[0], ReportRequest):
            args, kwargs = _old_form(fn, args, kwargs)
        for i, name in typed:  # (issue 47: the common case, an instance of the very class, at once)
            value = args[i] if i < len(args) else kwargs.get(name, _ABSENT)
            cls, hint = _MADE_BY[name]
            if value is not _ABSENT and type(value) is not _CLASSES.get(cls):
                require_type(name, value, globals()[cls], hint)
        for name, value in kwargs.items():
            if name in _MADE_BY and name not in names:
                cls, hint = _MADE_BY[name]
                require_type(name, value, globals()[cls], hint)
        return fn(*args, **kwargs)

    return checked


_ABSENT = object()
#: The classes of :data:`_MADE_BY` by name, filled when the module is loaded (``type(value) is`` them passes)
_CLASSES: dict = {}


def _old_form(fn, args, kwargs):
    """A solver's pre-issue-43 arguments (request, [lens state,] ...) as its camera-first ones."""
    import inspect
    import warnings

    warnings.warn(f"{fn.__name__}(request, ...) takes the camera now (request.inputs.camera, or "
                  "physcam.optics.state.camera_state); the request form goes in physcam 0.3", DeprecationWarning,
                  stacklevel=3)
    req, rest = args[0], list(args[1:])
    params = inspect.signature(fn).parameters
    if rest and isinstance(rest[0], LensAtMark):
        state = rest.pop(0)  # the lens state: the camera holds it
        if "at" in params:
            kwargs.setdefault("at", state)
    if fn.__name__ == "solve_focus":
        rest = rest[:1]  # (planes, c): the circle of confusion no longer solves a focus here
    inputs = req.inputs
    if "references" in params:
        kwargs.setdefault("references", inputs.references)
    if "measured" in params:
        kwargs.setdefault("measured", inputs.measured)
    return (inputs.camera, *rest), kwargs


def finite_or_none(v: float | None):
    return None if v is None or math.isinf(v) else v


@record
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
@_typed
def lens_at_mark(camera: CameraState, references: References | None = None) -> LensAtMark:
    """The lens at the camera's mark (``camera.at_mark``: a prescription focused there gives its EFL,
    H1, H2 and entrance pupil; a thin lens or a datasheet its own), with the f-number at the focus a
    USD file recorded (``references.fstop_at_focus``) taken as given."""
    at = camera.at_mark
    if references is not None and references.fstop_at_focus is not None:
        at = at._replace(n_ratio=references.fstop_at_focus / camera.fstop)
    return at


def principal_planes(at) -> PrincipalPlanes:
    """The practical (thin lens) or technical (datasheet or prescription) planes of the lens at a mark
    (a :class:`~physcam.optics.lens_model.LensAtMark`, or the camera whose it is)."""
    if isinstance(at, CameraState):
        at = at.at_mark
    require_type("at", at, LensAtMark, "a CameraState, or its at_mark")
    return PrincipalPlanes.of(at)


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
def solve_focus(camera: CameraState, planes: PrincipalPlanes, measured: MeasuredLimits | None = None) -> Focus:
    """The camera's mark as an object distance s from H1 and an image distance s' from H2, and what was
    solved to put the focus there (at the hyperfocal distance H = f^2/(N c) + f from H1, Wikipedia,
    "Hyperfocal distance"; or from measured limits, :func:`physcam.onset.inverse.focus_from_limits`)."""
    solved, notes, mark = {}, [], camera.focus_from_film_mm
    was = dict(camera.solved)
    if was.get("focus") == HYPERFOCAL and not camera.traceable:  # (a prescription's mark is its own: unsaid)
        solved["focus"] = HYPERFOCAL
        notes.append("focus at the hyperfocal distance (the focus mark above)")
    if "focus_from_film_mm" in was:
        solved["focus_from_film_mm"] = was["focus_from_film_mm"]
    s = planes.s_for_mark(mark)
    s_img = planes.f if math.isinf(s) else thinlens.image_distance(planes.f, s)
    far = None if measured is None else measured.far_mm
    if math.isinf(s) and "focus_from_film_mm" not in solved and far is not None and math.isfinite(far):
        raise InputError("with the focus at infinity the far limit is infinite; a finite far limit is impossible")
    return Focus(mark, s, s_img, solved, tuple(notes))


# --- inversions from measured limits ----------------------------------------------------------
class Aperture(NamedTuple):  # a NamedTuple: made at every report, cheap to define at start-up
    """The f-stop (the iris's setting, at infinity) and the CoC, given or solved from limits."""

    fstop: float
    coc_mm: float
    coc_convention: str
    solved: dict
    notes: tuple[str, ...] = ()


@_typed
def invert_limits(camera: CameraState, planes: PrincipalPlanes, focus_solution: Focus, c: float, coc_name: str,
                  measured: MeasuredLimits | None = None, at: LensAtMark | None = None) -> Aperture:
    """The CoC from the measured near and/or far limits (the camera's f-stop kept), or, when the camera's
    f-stop was solved from them (:func:`physcam.onset.inverse.fstop_from_limits`), that f-stop: the
    hyperfocal parameter h = f^2/(N c) from either limit (physcam.optics.dof), checked against the
    other when both are measured; a split focus (the focus solved from both limits, the stop given):
    the stop the limits need."""
    at = camera.at_mark if at is None else at
    near, far = (None, None) if measured is None else (measured.near_mm, measured.far_mm)
    s, n, solved, notes, was = focus_solution.object_distance, camera.fstop, {}, [], dict(camera.solved)
    one_limit_focus = "focus_from_film_mm" in was and (near is None or far is None)
    if "focus_from_film_mm" in was and near is not None and far is not None and "fstop" not in was:
        solved.update(_split_focus(planes, s, near, far, c, n, at.n_ratio))  # the stop is kept: what it holds
        notes.append(f"split focus with the stop given: f/{n:.3g} holds less than the asked limits at this CoC "
                     f"({c:.4g} mm); they need f/{solved['fstop_needed']:.3g}" if n < solved["fstop_needed"] else
                     f"split focus: f/{n:.3g} holds the asked limits at this CoC ({c:.4g} mm); they need "
                     f"f/{solved['fstop_needed']:.3g}")
    elif (near is not None or far is not None) and not one_limit_focus:  # one limit and N made the focus
        hp_near, hp_far = hyperfocal_parameters(planes, s, near, far)
        hp = hp_near if hp_near is not None else hp_far
        if hp_near is not None and hp_far is not None:
            solved.update(hyperfocal_parameter_from_near_mm=hp_near, hyperfocal_parameter_from_far_mm=hp_far,
                          consistency=abs(hp_far - hp_near) / hp_near)
            if "focus_from_film_mm" not in was:  # over-determined; the focus and stop solved from both: 0 by construction
                notes.append("near and far limits agree to {:.1%} in the hyperfocal parameter".format(solved["consistency"]))
        if "fstop" in was:  # solved when the camera was made
            solved.update((k, v) for k, v in camera.solved if k in ("fstop", "fstop_drift_stops"))
        else:
            c, coc_name = _dof.coc_for_dof(planes.f, n * at.n_ratio, hp), "solved"
            solved["coc_mm"] = c
        if far is not None and hp_near is not None:
            solved.update(_far_check(planes, s, n * at.n_ratio, c, far))
    require_possible_f_number(n)
    if not (math.isfinite(c) and c > 0):
        raise InputError(f"the measured limits give an impossible circle of confusion ({c:g}); check --near, --far "
                         "and --focus")
    return Aperture(n, c, coc_name, solved, tuple(notes))


def _split_focus(planes: PrincipalPlanes, s: float, near: float, far: float, c: float, n_given: float,
                 n_ratio: float) -> dict:
    """The stop a split focus needs to hold ``near`` to ``far`` (from the film) at the CoC ``c``: N = f^2 / (c h),
    h the hyperfocal parameter of either limit (they agree: the focus is their harmonic mean about H1)."""
    h = _dof.hyperfocal_parameter_from_near(planes.f, s, planes.to_h1(near, s))
    need = _dof.f_number_for_dof(planes.f, c, h) / n_ratio  # the iris's setting
    return {"fstop_needed": need, "fstop_needed_stops_over_given": _dof.stops_between(need, n_given)}


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
def depth_of_field(camera: CameraState, planes: PrincipalPlanes, focus_solution: Focus, ap: Aperture,
                   at: LensAtMark | None = None) -> DepthOfFieldResult:
    """Near, far and hyperfocal at the f-number at this focus; an anamorphic's horizontal limits take
    c / blur aspect (docs/lens-report.md, "Anamorphic depth of field"): deeper for a front
    anamorphic, the same for a rear one. A prescription's hyperfocal distance is its hyperfocal mark."""
    at = camera.at_mark if at is None else at
    n_focus, c, notes, sq = ap.fstop * at.n_ratio, ap.coc_mm, [], at.squeeze
    if abs(at.n_ratio - 1.0) > 0.005:
        notes.append(f"the iris set to f/{ap.fstop:.3g} (at infinity) makes the lens f/{n_focus:.3g} at this focus "
                     f"(internal focusing changes its EFL and entrance pupil); depth of field uses f/{n_focus:.3g}")
    dof = dof_block(planes.f, n_focus, c, focus_solution.object_distance, planes.h1_at)
    # desqueezing by sq where the lens squeezes by lens_squeeze stretches its blur by sq / lens_squeeze
    aspect = at.blur_aspect * sq / at.lens_squeeze if camera.traceable else 1.0 / sq
    dof_h = None
    if sq != 1.0:
        dof_h = dof_block(planes.f, n_focus, c / aspect, focus_solution.object_distance, planes.h1_at)
        notes.append(_anamorphic_dof_note(sq, aspect, c, from_lens=camera.traceable))
    if camera.traceable:
        dof, dof_h = _hyperfocal_marks(camera.lens, at, ap, dof, dof_h, aspect, notes)
    return DepthOfFieldResult(dof, dof_h, aspect, tuple(notes))


def _hyperfocal_marks(lens, at, ap, dof, dof_h, aspect, notes):
    """A real lens's principal planes move as it focuses: the hyperfocal *mark* is the one focus whose
    subject plane lies at H from H1 with the lens focused there, whatever the report's own focus; a
    lens that cannot focus there keeps H + H1 at this focus (said in a note)."""
    from ..optics.focusing import hyperfocal_mark

    try:
        mark, planes_h = hyperfocal_mark(lens, ap.fstop, ap.coc_mm)
        dof = replace(dof, hyperfocal_mm=mark - planes_h.h1_from_film_mm, hyperfocal_from_film_mm=mark)
        if dof_h is not None:
            mark, planes_h = hyperfocal_mark(lens, ap.fstop, ap.coc_mm,
                                             blur_aspect=None if at.squeeze_from_lens else aspect)
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
def field_of_view(camera: CameraState, h2_film: float, references: References | None = None,
                  at: LensAtMark | None = None) -> dict:
    """The paraxial fields of view at infinity (the EFL at infinity focus: a prescription's own there, not at
    the mark) and at this focus through the best-match pinhole:
    the pinhole at the entrance pupil that frames like the lens, f_pin = n (film - exit pupil) /
    (n' m_p) (docs/lens-report.md, "The best-match pinhole"); exact per meridian for a prescription,
    H2 to the film for a thin lens or a datasheet (pupils on the principal planes), or the pinhole a USD
    file recorded (``references``)."""
    at = camera.at_mark if at is None else at
    if camera.sensor is None:
        raise InputError("the field of view needs the camera's sensor: camera_state(..., sensor=...)")
    f, sq, w, h = at.focal_length_mm, at.squeeze, camera.sensor.width_mm, camera.sensor.height_mm
    f_inf, sq_inf = f, sq
    if at.efl_infinity is not None:  # a prescription's EFL changes with focus: the lens at infinity
        f_inf = at.efl_infinity[0]
        sq_inf = f_inf / at.efl_infinity[1] if at.squeeze_from_lens else sq
    pin_y, pin_x = at.pinhole if at.pinhole is not None else (h2_film, h2_film)
    pin_sq = pin_y / pin_x if pin_x != pin_y else sq  # an anamorphic frames each meridian by its own
    if references is not None and references.pinhole_focal_length_mm is not None:
        pin_y = references.pinhole_focal_length_mm
        pin_sq = sq if references.pinhole_squeeze is None else references.pinhole_squeeze
    wd, wp = w * sq_inf, w * pin_sq
    return dict(hfov_inf_deg=_fov_deg(wd, f_inf), vfov_inf_deg=_fov_deg(h, f_inf),
                dfov_inf_deg=_fov_deg(math.hypot(wd, h), f_inf),
                hfov_focus_deg=_fov_deg(wp, pin_y), vfov_focus_deg=_fov_deg(h, pin_y),
                dfov_focus_deg=_fov_deg(math.hypot(wp, h), pin_y),
                pinhole_focal_length_mm=pin_y, pinhole_squeeze=pin_sq)


@_typed
def entrance_pupil(camera: CameraState, h1_film: float, references: References | None = None,
                   at: LensAtMark | None = None) -> tuple[float | None, str, tuple]:
    """(pupil from the film, its source, notes): a datasheet's or the prescription's; a tape-measure
    estimate a fraction of the lens length behind its front; the thin lens's principal plane."""
    at = camera.at_mark if at is None else at
    if at.pupil_from_film_mm is not None:
        return at.pupil_from_film_mm, at.pupil_origin, ()
    if references is not None and references.sensor_front_mm is not None:
        pupil = entrance_pupil_practical(references.sensor_front_mm, references.lens_length_mm,
                                         references.pupil_fraction)
        return pupil, f"estimate: {references.pupil_fraction:g} of the lens length behind its front", ()
    if at.model == "practical":
        return h1_film, "thin lens: at the principal plane", ()
    return None, "unknown", ("no entrance pupil: give --pupil (technical) or --sensor-front and --lens-length",)


_CLASSES.update({name: globals()[name] for name, _ in _MADE_BY.values()})

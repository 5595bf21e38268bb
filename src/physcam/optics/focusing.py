"""Focusing a lens at a distance marked from the film plane, and focus breathing.

On set a focus mark D is the distance from the film plane (the body's Φ mark) to
the subject (docs/conventions.md). Two ways a lens reaches it:

* **unit focusing** – the whole lens moves away from the film. With the Gaussian
  object distance s from H1 and image distance s' from H2 (air on both sides),
  s + s' = D - hiatus and 1/s + 1/s' = 1/f give
  s' = (T - sqrt(T^2 - 4 f T)) / 2 with T = D - hiatus (Smith, *Modern Optical
  Engineering*, 4th ed., 2.4; the general-index form is solved below). No real
  focus exists for T < 4 f (closer than 1:1).
* **internal focusing** – the prescription's :class:`~physcam.lens.prescription.Focus`
  gaps change. As in the seed's design notes (003), each variable gap is
  interpolated linearly in reciprocal object distance between its infinity and
  close values, alpha = close_distance / d with d the object distance from the
  first vertex; then the lens-to-film distance that images the object on the film
  is solved, with d chosen so that d + glass length + back focus = D. Marks closer
  than the close calibration point raise :class:`OpticsError` naming the closest
  focus (the seed silently clamps; physcam refuses).

Focus breathing: the effective focal length and the horizontal field of view
(from the paraxial chief ray reaching the sensor edge) against the focus mark.
"""

from __future__ import annotations

import functools
import math

from .._record import asdict, record
from ..data.default_sensor import DEFAULT_SENSOR_WIDTH_MM
from ..errors import InputError, OpticsError, renamed_parameter, require_positive, require_type
from ..lens.prescription import Prescription, takes_prescription
from . import paraxial
from ._roots import bracketed_root

__all__ = [
    "FOCUS_METHODS",
    "FocusState",
    "TechnicalPlanes",
    "BreathingRow",
    "interpolated_gaps",
    "image_distance",
    "focus",
    "closest_focus",
    "CloseFocus",
    "close_focus",
    "iris_semi_diameter",
    "f_number_ratio",
    "gaussian_at_focus",
    "technical_planes",
    "EntrancePupils",
    "entrance_pupils",
    "breathing_table",
    "pupil_aspect",
    "hyperfocal_mark",
    "hyperfocal_state",
    "planes_of",
    "state_for_object",
]

FOCUS_METHODS = ("auto", "unit", "internal")

#: Default focus marks (mm from the film) of a breathing table, before the closest focus.
DEFAULT_BREATHING_MARKS = (math.inf, 10000.0, 5000.0, 3000.0, 2000.0, 1500.0, 1000.0, 700.0, 500.0, 400.0, 300.0, 250.0, 200.0)


@record
class FocusState:
    """A lens focused at a mark.

    ``prescription`` has the focused gaps and its last thickness set to
    ``back_focus_mm`` (last vertex to film). ``object_distance_mm`` is from the first
    vertex to the subject, ``focus_from_film_mm`` from the film plane (inf allowed).
    ``extension_mm`` is the back-focus change from infinity focus (the lens moving
    out for unit focusing; a residual for internal focusing). ``alpha`` is the
    fraction of the focus gaps' travel (0 at infinity, 1 at the close point).
    """

    focus_from_film_mm: float
    method: str
    axis: str
    prescription: Prescription
    object_distance_mm: float
    back_focus_mm: float
    back_focus_infinity_mm: float
    extension_mm: float
    alpha: float

    @property
    def object_z(self) -> float:
        """Lens-space z of the subject (-inf at infinity)."""
        return -self.object_distance_mm

    @property
    def film_z(self) -> float:
        """Lens-space z of the film plane."""
        return self.prescription.vertex_z[-1] + self.back_focus_mm


@record
class TechnicalPlanes:
    """What the on-set report's technical model needs, at one focus.

    Every ``*_from_film_mm`` is a distance **in front of the film plane, positive
    toward the subject** (``*_from_flange_mm`` likewise from the flange, when the
    flange focal distance is known). ``back_focus_mm`` is the last vertex to the
    film; ``efl_mm`` the effective focal length at this focus; ``hiatus_mm`` = H1 - H2
    positions (positive when H1 lies in front of H2).
    """

    focus_from_film_mm: float
    method: str
    axis: str
    wavelength_nm: float
    efl_mm: float
    h1_from_film_mm: float
    h2_from_film_mm: float
    entrance_pupil_from_film_mm: float
    exit_pupil_from_film_mm: float
    front_vertex_from_film_mm: float
    back_focus_mm: float
    hiatus_mm: float
    f_number: float
    working_f_number: float
    magnification: float
    entrance_pupil_diameter_mm: float
    pinhole_focal_length_mm: float | None = None  # the best-match pinhole at the entrance pupil (GaussianData)
    stop_from_film_mm: float | None = None  # the physical aperture stop (iris), in front of the film
    flange_focal_distance_mm: float | None = None
    h1_from_flange_mm: float | None = None
    h2_from_flange_mm: float | None = None
    entrance_pupil_from_flange_mm: float | None = None

    def to_dict(self) -> dict:
        d = asdict(self)
        return {k: (None if isinstance(v, float) and not math.isfinite(v) else v) for k, v in d.items()}


@record
class BreathingRow:
    """One focus mark of a breathing table (lengths mm, angles degrees)."""

    focus_from_film_mm: float
    efl_mm: float
    hfov_deg: float
    breathing_focal_length_mm: float  # sensor half-width / tan(half HFOV): the focal length the framing suggests
    magnification: float
    back_focus_mm: float
    fov_change_pct: float  # HFOV change from infinity focus, percent
    entrance_pupil_from_film_mm: float | None = None  # where the camera pivots at this mark (X meridian: a pan)
    #: the Y (vertical) meridian's: EFL and framing focal length (sensor half-width / tan of the Y meridian's
    #: paraxial half-field there; paraxially the Y pinhole), and its entrance pupil (a tilt's pivot). They
    #: differ from the X meridian's for an anamorphic lens; equal for a spherical one
    vertical_efl_mm: float | None = None
    vertical_breathing_focal_length_mm: float | None = None
    vertical_entrance_pupil_from_film_mm: float | None = None

    @property
    def breathing_squeeze(self) -> float | None:
        """Vertical over horizontal framing focal length: the squeeze the framing shows at this mark."""
        v = self.vertical_breathing_focal_length_mm
        return None if v is None else v / self.breathing_focal_length_mm

    def to_dict(self) -> dict:
        d = asdict(self)
        d["breathing_squeeze"] = self.breathing_squeeze
        return {k: (None if isinstance(v, float) and not math.isfinite(v) else v) for k, v in d.items()}


@takes_prescription
def focus_method(prescription: Prescription, method: str = "auto") -> str:
    """The focusing method a lens uses: "auto" resolves to "internal" (focus groups) or "unit"."""
    if method not in FOCUS_METHODS:
        raise InputError(f"focus method must be one of {', '.join(FOCUS_METHODS)}, got {method!r}")
    if method == "auto":
        return "internal" if prescription.focus is not None else "unit"
    if method == "internal" and prescription.focus is None:
        raise InputError(f"lens {prescription.name!r} has no focus groups; use unit focusing")
    return method


def _mark(focus_from_film_mm) -> float:
    if isinstance(focus_from_film_mm, str):  # "2m", "10ft", "infinity": as the command line reads it
        from ..units import parse_distance

        return _mark(parse_distance(focus_from_film_mm, name="focus distance", allow_inf=True))
    d = float(focus_from_film_mm)
    if math.isnan(d) or d <= 0:
        raise InputError(f"focus distance must be a positive distance from the film plane, got {focus_from_film_mm!r}")
    return d


@takes_prescription
def interpolated_gaps(prescription: Prescription, object_distance_mm: float) -> tuple[dict[int, float], float]:
    """Focus-group gaps for an object ``object_distance_mm`` in front of the first vertex.

    Linear in reciprocal object distance (seed 003): alpha = close_distance / d,
    clamped to [0, 1]; gap = t_inf + alpha (t_close - t_inf). Returns (gaps, alpha).
    """
    f = prescription.focus
    if f is None:
        return {}, 0.0
    alpha = 0.0 if math.isinf(object_distance_mm) else min(max(f.close_distance / object_distance_mm, 0.0), 1.0)
    return {g.surface: g.thickness_infinity + alpha * (g.thickness_close - g.thickness_infinity) for g in f.gaps}, alpha


@takes_prescription
def image_distance(prescription: Prescription, object_distance_mm: float, axis: str = "y", wavelength_nm=None) -> float:
    """Last vertex to the paraxial image (mm, + toward the film) of an axial object.

    ``object_distance_mm`` is from the first vertex to the object (inf allowed: the BFL).
    """
    a, b, c, d = paraxial.system_matrix(prescription, axis, wavelength_nm)
    n_img = paraxial.media_indices(prescription, wavelength_nm)[-1]
    if math.isinf(object_distance_mm):
        y, nu = a, c
    else:  # ray leaving the axial object with n u = 1 (object space is air)
        y, nu = a * object_distance_mm + b, c * object_distance_mm + d
    if abs(nu) < 1e-15:
        raise OpticsError("the object is at the front focal point: its image is at infinity")
    return -y * n_img / nu


def _unit_focus(p: Prescription, mark: float, axis: str, lam, max_extension_mm) -> FocusState:
    g = paraxial.gaussian(p, axis=axis, wavelength_nm=lam)
    b_inf = g.bfl
    if math.isinf(mark):
        return FocusState(mark, "unit", axis, p.with_thicknesses({len(p.surfaces) - 1: b_inf}), math.inf, b_inf, b_inf, 0.0, 0.0)
    phi = 1.0 / g.efl
    if phi <= 0:
        raise OpticsError(f"lens {p.name!r} has negative power: it forms no real image to focus")
    n2 = g.image_index
    hiatus = g.z_rear_principal_plane - g.z_front_principal_plane  # H1 -> H2 along +z
    T = mark - hiatus  # s + s' (s from H1 toward the subject, s' from H2 toward the film)
    # 1/s + n'/s' = phi with s = T - s'  ->  phi s'^2 - (phi T + n' - 1) s' + n' T = 0
    bq = phi * T + n2 - 1.0
    disc = bq * bq - 4.0 * phi * n2 * T
    if -1e-12 * bq * bq <= disc < 0:  # the 1:1 mark itself (closest_focus), a rounding error below zero
        disc = 0.0
    if T <= 0 or disc < 0:
        t_min = (1.0 + math.sqrt(n2)) ** 2 / phi  # discriminant zero: the 1:1 conjugate in air
        raise OpticsError(
            f"lens {p.name!r} cannot focus at {mark:.1f} mm from the film by unit focusing: the closest real focus "
            f"(1:1) is {t_min + hiatus:.1f} mm from the film plane"
        )
    s2 = (bq - math.sqrt(disc)) / (2.0 * phi)  # the root that tends to f' at infinity
    z_film = g.z_rear_principal_plane + s2
    back = z_film - p.vertex_z[-1]
    extension = back - b_inf
    if max_extension_mm is not None and extension > max_extension_mm + 1e-9:
        s2_max = g.rear_focal_length + max_extension_mm
        s_max = 1.0 / (phi - n2 / s2_max)
        raise OpticsError(
            f"lens {p.name!r} cannot focus at {mark:.1f} mm: with {max_extension_mm:g} mm of focus travel its closest "
            f"focus is {s_max + s2_max + hiatus:.1f} mm from the film plane"
        )
    d_obj = mark - back - p.total_track
    if d_obj <= 0:
        raise OpticsError(
            f"lens {p.name!r}: a subject {mark:.1f} mm from the film would be inside the lens once focused; "
            "mark a longer distance"
        )
    return FocusState(mark, "unit", axis, p.with_thicknesses({len(p.surfaces) - 1: back}), d_obj, back, b_inf, extension, 0.0)


def _internal_state(p: Prescription, d_obj: float, axis: str, lam):
    gaps, alpha = interpolated_gaps(p, d_obj)
    q = p.with_thicknesses(gaps)
    back = image_distance(q, d_obj, axis, lam)
    return q, back, alpha


@takes_prescription
def closest_focus(prescription: Prescription, *, method: str = "auto", axis: str = "y", wavelength_nm=None) -> float:
    """Closest focus mark (mm from the film plane).

    Internal focusing: the close calibration point of the focus groups. Unit focusing (no mechanical
    limit known): the 1:1 conjugate, (1 + sqrt(n'))^2 f + hiatus (4 f + hiatus in air), the closest
    real image; unless there the subject would be inside the lens (a lens longer than that: the
    subject (1 + sqrt(n')) f in front of H1, which lies further behind the first vertex), then the
    mark with the subject at the first vertex: s = z(H1) in front of H1, s' = n' / (1/f - 1/s) behind
    H2 (Gaussian conjugates), mark s + s' + hiatus. Marks beyond it focus; marks closer do not.
    """
    method = focus_method(prescription, method)
    if method == "internal":
        d = prescription.focus.close_distance
        q, back, _ = _internal_state(prescription, d, axis, wavelength_nm)
        return d + q.total_track + back
    g = paraxial.gaussian(prescription, axis=axis, wavelength_nm=wavelength_nm)
    if g.efl <= 0:
        raise OpticsError(f"lens {prescription.name!r} has negative power: it forms no real image to focus")
    hiatus = g.z_rear_principal_plane - g.z_front_principal_plane
    s = g.z_front_principal_plane  # the first vertex (lens space z = 0) in front of H1
    if s > (1.0 + math.sqrt(g.image_index)) * g.efl:  # the 1:1 subject would be behind the first vertex
        return s + g.image_index / (1.0 / g.efl - 1.0 / s) + hiatus
    return (1.0 + math.sqrt(g.image_index)) ** 2 * g.efl + hiatus


#: Without the maker's minimum object distance, a unit-focusing lens's breathing is drawn from this many
#: focal lengths in front of the film (about 1:8): cine primes' published close focus is 8 to 12 focal
#: lengths (a 50 mm: 0.45-0.6 m), while the 1:1 limit (4 f) is a macro's.
BREATHING_NEAR_EFL = 10.0


@record
class CloseFocus:
    """How close the lens focuses, and where that number comes from (mm from the film plane).

    ``source``: "maker" (the file's ``[lens] minimum_object_distance``), "focus groups" (the close
    position of an internal-focusing lens's variable gaps) or "unit focusing limit" (no mechanical
    limit known: the 1:1 conjugate, which no real lens of that kind reaches). ``breathing_near_mm``:
    where breathing tables and plots start by default (the MOD, the focus groups' close point, or
    :data:`BREATHING_NEAR_EFL` focal lengths, to two significant figures, for a unit-focusing lens without a
    MOD)."""

    mark_mm: float
    source: str
    words: str
    breathing_near_mm: float

    def to_dict(self) -> dict:
        return {"close_focus_from_film_mm": self.mark_mm, "source": self.source, "words": self.words,
                "breathing_near_from_film_mm": self.breathing_near_mm}


@takes_prescription
def close_focus(prescription: Prescription, *, method: str = "auto", wavelength_nm=None) -> CloseFocus:
    """The lens's close focus (:class:`CloseFocus`): the maker's minimum object distance when the file gives
    one (kept at least the focusing model's own limit), else the focusing model's limit, named as such."""
    limit = closest_focus(prescription, method=method, wavelength_nm=wavelength_nm)
    mod = prescription.metadata.minimum_object_distance
    if mod is not None:
        mark = max(float(mod), limit)
        return CloseFocus(mark, "maker", "the maker's minimum object distance" + (
            "" if mark == mod else f" ({mod:g} mm) is closer than this focusing model reaches: its limit"), mark)
    if focus_method(prescription, method) == "internal":
        return CloseFocus(limit, "focus groups", "the focus groups' close position (from the file; no MOD given)",
                          limit)
    efl = paraxial.gaussian(prescription, wavelength_nm=wavelength_nm).efl
    near = BREATHING_NEAR_EFL * efl
    near = round(near, 1 - int(math.floor(math.log10(near))))  # two significant figures, as marks are engraved
    return CloseFocus(limit, "unit focusing limit", "unit focusing limit, not the lens's MOD", max(limit, near))


def _internal_focus(p: Prescription, mark: float, axis: str, lam) -> FocusState:
    q_inf, b_inf, _ = _internal_state(p, math.inf, axis, lam)
    if math.isinf(mark):
        return FocusState(mark, "internal", axis, q_inf.with_thicknesses({len(p.surfaces) - 1: b_inf}), math.inf, b_inf, b_inf, 0.0, 0.0)
    d_close = p.focus.close_distance

    def residual(d):  # marked distance reached with the subject d in front of the first vertex, minus the mark
        q, back, _ = _internal_state(p, d, axis, lam)
        return d + q.total_track + back - mark

    r_lo = residual(d_close)
    if r_lo > 1e-9:
        raise OpticsError(
            f"lens {p.name!r} cannot focus at {mark:.1f} mm: its closest focus is {mark + r_lo:.1f} mm "
            "from the film plane (focus groups at their close position)"
        )
    hi = max(mark, d_close)
    r_hi = residual(hi)
    if r_hi < 0:
        raise OpticsError(f"lens {p.name!r}: no internal focus solution for {mark:.1f} mm from the film")
    d = bracketed_root(residual, d_close, r_lo, hi, r_hi, 1e-9 * max(1.0, hi))
    q, back, alpha = _internal_state(p, d, axis, lam)
    if back <= 0:
        raise OpticsError(f"lens {p.name!r}: at {mark:.1f} mm the image falls inside the lens (back focus {back:.2f} mm)")
    return FocusState(mark, "internal", axis, q.with_thicknesses({len(p.surfaces) - 1: back}), d, back, b_inf, back - b_inf, alpha)


@renamed_parameter("focus_from_film_mm", "focus_mm")
@takes_prescription
def focus(
    prescription: Prescription,
    focus_mm: float,
    *,
    method: str = "auto",
    axis: str = "y",
    wavelength_nm=None,
    max_extension_mm: float | None = None,
) -> FocusState:
    """Focus ``prescription`` on a subject ``focus_mm`` in front of the film plane.

    ``method``: ``"unit"`` (the lens moves), ``"internal"`` (the focus groups move,
    then the back focus is solved), ``"auto"`` (internal when the lens has focus
    groups). ``axis``: the meridian that is focused (Y, the spherical meridian of
    an anamorphic, as cinematographers focus). ``max_extension_mm`` limits unit
    focusing travel. Raises :class:`OpticsError` naming the closest focus when
    the mark is too close.
    """
    method = focus_method(prescription, method)
    mark = _mark(focus_mm)
    paraxial._axis(axis)
    if max_extension_mm is not None:
        max_extension_mm = require_positive("maximum focus extension", max_extension_mm)
    if method == "internal":
        return _internal_focus(prescription, mark, axis, wavelength_nm)
    return _unit_focus(prescription, mark, axis, wavelength_nm, max_extension_mm)


@takes_prescription
def iris_semi_diameter(prescription: Prescription, fstop: float, *, method: str = "auto") -> float:
    """The iris (aperture stop) semi-diameter, mm, of ``prescription`` set to f/``fstop``.

    The one rule every consumer follows (report, tracer, pbrt, Blender, Mitsuba, USD): the f-number
    engraved on a lens is its EFL over its entrance pupil diameter with the lens focused at infinity
    (ISO 517; Kingslake, *Lens Design Fundamentals*, 2nd ed., 6.1), in the Y meridian at the design
    wavelength. A real iris keeps its size when the lens focuses; an internal-focus lens's EFL and
    pupils change instead, so its working f-number (and its f-number at that focus) differ from
    ``fstop``. Raises :class:`OpticsError` for an f-stop faster than the lens opens."""
    inf_state = focus(prescription, math.inf, method=method)
    return paraxial.stop_semi_diameter_for_fstop(inf_state.prescription, fstop)


@renamed_parameter("focus_from_film_mm", "focus_mm")
@takes_prescription
def f_number_ratio(prescription: Prescription, focus_mm: float, *, method: str = "auto") -> float:
    """The lens's f-number at a focus mark over its f-number at infinity, for one iris.

    With the iris fixed (:func:`iris_semi_diameter`), f/N at infinity becomes f/(N x this ratio) at the
    mark: EFL over entrance pupil diameter of the lens focused there. Exactly 1 for unit focusing
    (the lens moves whole; its EFL and pupils do not change); an internal-focus lens's EFL and
    entrance pupil change with the gaps. The ratio does not depend on the iris's size (paraxial
    pupils scale with the stop)."""
    at_infinity = gaussian_at_focus(prescription, math.inf, method=method).f_number
    return gaussian_at_focus(prescription, focus_mm, method=method).f_number / at_infinity


@renamed_parameter("focus_from_film_mm", "focus_mm")
@takes_prescription
def gaussian_at_focus(
    prescription: Prescription,
    focus_mm: float = math.inf,
    *,
    axis: str = "y",
    focus_axis: str = "y",
    method: str = "auto",
    wavelength_nm=None,
    fstop=None,
    flange_focal_distance_mm=None,
) -> paraxial.GaussianData:
    """Gaussian data in the ``axis`` meridian with the lens focused (in ``focus_axis``) at the mark;
    ``fstop`` sizes the iris by :func:`iris_semi_diameter` (at infinity focus, kept at every focus)."""
    st = focus(prescription, focus_mm, method=method, axis=focus_axis, wavelength_nm=wavelength_nm)
    stop = None if fstop is None else iris_semi_diameter(prescription, fstop, method=method)
    return paraxial.gaussian(
        st.prescription,
        axis=axis,
        wavelength_nm=wavelength_nm,
        stop_semi_diameter=stop,
        object_z=st.object_z,
        film_z=st.film_z,
        flange_focal_distance_mm=flange_focal_distance_mm,
    )


@renamed_parameter("focus_from_film_mm", "focus_mm")
@takes_prescription
def technical_planes(
    prescription: Prescription,
    focus_mm: float,
    flange_focal_distance_mm: float | None = None,
    wavelength_nm: float | None = None,
    *,
    fstop: float | None = None,
    method: str = "auto",
    axis: str = "y",
) -> TechnicalPlanes:
    """EFL, H1, H2 and the entrance pupil **in front of the film plane** at a focus mark.

    For the on-set report's technical model. ``focus_mm`` is the mark
    (mm from the film plane, inf allowed); distances returned are positive toward
    the subject; ``back_focus_mm`` is last vertex to film. With
    ``flange_focal_distance_mm`` the same planes are also given from the flange.
    """
    st = focus(prescription, focus_mm, method=method, axis=axis, wavelength_nm=wavelength_nm)
    stop = None if fstop is None else iris_semi_diameter(prescription, fstop, method=method)
    return planes_of(st, stop_semi_diameter=stop, wavelength_nm=wavelength_nm,
                     flange_focal_distance_mm=flange_focal_distance_mm)


def planes_of(state: FocusState, *, stop_semi_diameter: float | None = None, wavelength_nm=None,
              flange_focal_distance_mm: float | None = None) -> TechnicalPlanes:
    """:class:`TechnicalPlanes` of a lens already focused (a :class:`FocusState`: no focus solved here),
    its iris ``stop_semi_diameter`` (None: the file's stop), in the state's own meridian."""
    require_type("state", state, FocusState, "physcam.optics.focusing.focus(lens, mark)")
    g = paraxial.gaussian(state.prescription, axis=state.axis, wavelength_nm=wavelength_nm,
                          stop_semi_diameter=stop_semi_diameter, object_z=state.object_z, film_z=state.film_z,
                          flange_focal_distance_mm=flange_focal_distance_mm)
    fl = {}
    if flange_focal_distance_mm is not None:
        fl = dict(
            h1_from_flange_mm=g.in_front_of("front_principal_plane", "flange"),
            h2_from_flange_mm=g.in_front_of("rear_principal_plane", "flange"),
            entrance_pupil_from_flange_mm=g.in_front_of("entrance_pupil", "flange"),
        )
    return TechnicalPlanes(
        focus_from_film_mm=float(state.focus_from_film_mm),
        method=state.method,
        axis=state.axis,
        wavelength_nm=g.wavelength_nm,
        efl_mm=g.efl,
        h1_from_film_mm=g.in_front_of("front_principal_plane"),
        h2_from_film_mm=g.in_front_of("rear_principal_plane"),
        entrance_pupil_from_film_mm=g.in_front_of("entrance_pupil"),
        exit_pupil_from_film_mm=g.in_front_of("exit_pupil"),
        front_vertex_from_film_mm=g.z_film - g.z_front_vertex,
        back_focus_mm=g.z_film - g.z_rear_vertex,
        hiatus_mm=g.z_rear_principal_plane - g.z_front_principal_plane,
        f_number=g.f_number,
        working_f_number=g.working_f_number,
        magnification=g.magnification,
        entrance_pupil_diameter_mm=g.entrance_pupil_diameter,
        pinhole_focal_length_mm=g.pinhole_focal_length,
        stop_from_film_mm=g.z_film - g.z_stop,
        flange_focal_distance_mm=g.flange_focal_distance,
        **fl,
    )


@takes_prescription
def breathing_table(
    prescription: Prescription,
    focus_marks_mm=None,
    *,
    sensor_width_mm: float = DEFAULT_SENSOR_WIDTH_MM,
    method: str = "auto",
    wavelength_nm=None,
) -> list[BreathingRow]:
    """Effective focal length and horizontal field of view against focus mark.

    ``focus_marks_mm``: marks from the film plane (default: infinity, 10 m, 5 m, ...
    down to the close focus of :func:`close_focus`: the MOD, the focus groups' close point, or ten focal
    lengths for a unit-focusing lens without a MOD). The horizontal field uses the X meridian (the squeezed one of
    an anamorphic) with the lens focused in Y; HFOV = 2 atan(...) of the paraxial
    chief ray reaching the sensor edge (``sensor_width_mm``/2 off axis; default the width of Super 35,
    24.89 mm: :data:`physcam.data.default_sensor.DEFAULT_SENSOR`, as the CLI).
    """
    w = require_positive("sensor width", sensor_width_mm)
    if not 1e-6 <= w <= 1000.0:  # a 5e-324 mm "sensor" has no field angle to divide by
        raise InputError(f"sensor width must lie between 1e-6 and 1000 mm, got {w:g}")
    method = focus_method(prescription, method)
    if focus_marks_mm is None:
        # from infinity to the close focus: the maker's MOD or the focus groups' close point (that mark
        # last), or for a unit-focusing lens without a MOD the default marks beyond BREATHING_NEAR_EFL focal
        # lengths (:func:`close_focus`)
        cf = close_focus(prescription, method=method, wavelength_nm=wavelength_nm)
        near = cf.breathing_near_mm
        marks = [m for m in DEFAULT_BREATHING_MARKS if m > near * (1 + 1e-9)] + [near]
    else:
        marks = [_mark(m) for m in focus_marks_mm]
        if not marks:
            raise InputError("give at least one focus distance for the breathing table")
    rows = []
    hfov0 = None
    for m in marks:
        st = focus(prescription, m, method=method, axis="y", wavelength_nm=wavelength_nm)
        gx = paraxial.gaussian(st.prescription, axis="x", wavelength_nm=wavelength_nm, object_z=st.object_z, film_z=st.film_z)
        half = abs(paraxial.field_angle(st.prescription, w / 2.0, st.film_z, "x", wavelength_nm))
        gy = paraxial.gaussian(st.prescription, axis="y", wavelength_nm=wavelength_nm, object_z=st.object_z,
                               film_z=st.film_z)
        half_y = abs(paraxial.field_angle(st.prescription, w / 2.0, st.film_z, "y", wavelength_nm))
        hfov = math.degrees(2.0 * half)
        if hfov0 is None:
            hfov0 = hfov if math.isinf(m) else gaussian_hfov_infinity(prescription, w, method, wavelength_nm)
        rows.append(
            BreathingRow(
                focus_from_film_mm=m,
                efl_mm=gx.efl,
                hfov_deg=hfov,
                breathing_focal_length_mm=(w / 2.0) / math.tan(half),
                magnification=gx.magnification,
                back_focus_mm=st.back_focus_mm,
                fov_change_pct=100.0 * (hfov / hfov0 - 1.0),
                entrance_pupil_from_film_mm=gx.in_front_of("entrance_pupil"),
                vertical_efl_mm=gy.efl,
                vertical_breathing_focal_length_mm=(w / 2.0) / math.tan(half_y),
                vertical_entrance_pupil_from_film_mm=gy.in_front_of("entrance_pupil"),
            )
        )
    return rows


@takes_prescription
def gaussian_hfov_infinity(prescription: Prescription, sensor_width_mm: float, method: str = "auto", wavelength_nm=None) -> float:
    """Horizontal field of view (degrees, X meridian) at infinity focus."""
    st = focus(prescription, math.inf, method=method, axis="y", wavelength_nm=wavelength_nm)
    return math.degrees(2.0 * abs(paraxial.field_angle(st.prescription, sensor_width_mm / 2.0, st.film_z, "x", wavelength_nm)))


@renamed_parameter("focus_from_film_mm", "focus_mm")
def pupil_aspect(prescription: Prescription, focus_mm: float) -> float:
    """An anamorphic lens's blur aspect at a focus mark: its entrance pupil's X over Y diameter (one
    round stop seen through each meridian; the ratio does not depend on the stop's size). 1 for a
    rotationally symmetric lens."""
    st = focus(prescription, focus_mm)
    gx, gy = (paraxial.gaussian(st.prescription, axis=a, object_z=st.object_z, film_z=st.film_z) for a in "xy")
    return gx.entrance_pupil_diameter / gy.entrance_pupil_diameter


@record
class EntrancePupils:
    """Both meridians' entrance pupils at one focus mark, in front of the film (mm, + toward the subject).

    An anamorphic lens images its one stop through different powers in X and Y: a front anamorphic
    (cylinders before the stop) has two entrance pupils at different places ("anamorphic mumps"); a
    rear one (cylinders behind the stop) has one place and a round pupil. A **pan** (rotation about
    the vertical axis) moves the picture horizontally: it is parallax-free about the X (horizontal)
    meridian's pupil; a **tilt** about the Y (vertical) meridian's pupil (Kingslake, *Optics in
    Photography*, ch. 6: the entrance pupil is the centre of perspective, here in each meridian).
    """

    focus_from_film_mm: float
    horizontal_from_film_mm: float  # X meridian: the pan pivot
    vertical_from_film_mm: float  # Y meridian: the tilt pivot
    horizontal_diameter_mm: float
    vertical_diameter_mm: float

    @property
    def separation_mm(self) -> float:
        """Horizontal pupil minus vertical pupil (+: the horizontal one lies nearer the subject)."""
        return self.horizontal_from_film_mm - self.vertical_from_film_mm

    def to_dict(self) -> dict:
        d = asdict(self)
        d["focus_from_film_mm"] = None if math.isinf(self.focus_from_film_mm) else self.focus_from_film_mm
        d["separation_mm"] = self.separation_mm
        d["pan_pivot_from_film_mm"] = self.horizontal_from_film_mm
        d["tilt_pivot_from_film_mm"] = self.vertical_from_film_mm
        return d


@renamed_parameter("focus_from_film_mm", "focus_mm")
def entrance_pupils(prescription: Prescription, focus_mm: float, *, method: str = "auto",
                    wavelength_nm=None) -> EntrancePupils:
    """The X and Y meridians' paraxial entrance pupils with the lens focused (in Y) at the mark, both
    from the one film plane (:class:`EntrancePupils`); equal for a rotationally symmetric lens."""
    st = focus(prescription, focus_mm, method=method, axis="y", wavelength_nm=wavelength_nm)
    g = {a: paraxial.gaussian(st.prescription, axis=a, wavelength_nm=wavelength_nm, object_z=st.object_z,
                              film_z=st.film_z) for a in "xy"}
    return EntrancePupils(float(focus_mm), g["x"].in_front_of("entrance_pupil"), g["y"].in_front_of("entrance_pupil"),
                          g["x"].entrance_pupil_diameter, g["y"].entrance_pupil_diameter)


#: The farthest hyperfocal mark solved (1000 km, the on-set report's largest distance).
_MAX_MARK_MM = 1.0e9


@takes_prescription
def state_for_object(prescription: Prescription, object_distance_mm: float, *, method: str = "auto",
                     axis: str = "y", wavelength_nm=None) -> FocusState:
    """The lens focused on a subject ``object_distance_mm`` in front of its first vertex (inf allowed):
    the inverse of :func:`focus` without its search. Internal focusing sets the gaps for that object
    (:func:`interpolated_gaps`) and the back focus at its paraxial image; unit focusing keeps the gaps
    and puts the film at the paraxial image (:func:`image_distance`). The mark is object distance +
    glass length + back focus. No limit is checked here (a subject closer than the focus groups' close
    point is a clamped state): :func:`focus` refuses marks the lens cannot reach."""
    method = focus_method(prescription, method)
    last = len(prescription.surfaces) - 1
    if method == "internal":
        q_inf, b_inf, _ = _internal_state(prescription, math.inf, axis, wavelength_nm)
        if math.isinf(object_distance_mm):
            return FocusState(math.inf, "internal", axis, q_inf.with_thicknesses({last: b_inf}), math.inf, b_inf,
                              b_inf, 0.0, 0.0)
        q, back, alpha = _internal_state(prescription, object_distance_mm, axis, wavelength_nm)
        return FocusState(object_distance_mm + q.total_track + back, "internal", axis, q.with_thicknesses({last: back}),
                          object_distance_mm, back, b_inf, back - b_inf, alpha)
    b_inf = paraxial.gaussian(prescription, axis=axis, wavelength_nm=wavelength_nm).bfl
    if math.isinf(object_distance_mm):
        return FocusState(math.inf, "unit", axis, prescription.with_thicknesses({last: b_inf}), math.inf, b_inf, b_inf,
                          0.0, 0.0)
    back = image_distance(prescription, object_distance_mm, axis, wavelength_nm)
    return FocusState(object_distance_mm + prescription.total_track + back, "unit", axis,
                      prescription.with_thicknesses({last: back}), object_distance_mm, back, b_inf, back - b_inf, 0.0)


def _reachable(prescription: Prescription, st: FocusState) -> bool:
    """Whether :func:`focus` would reach ``st`` (a state made by :func:`state_for_object`)."""
    if not (st.back_focus_mm > 0 and math.isfinite(st.focus_from_film_mm)):
        return False
    if st.method == "internal":
        return st.object_distance_mm >= prescription.focus.close_distance
    return st.object_distance_mm > 0


@functools.lru_cache(maxsize=64)  # a hyperfocal camera solves it, and every report's DOF block asks again
def hyperfocal_state(prescription: Prescription, fstop: float, coc_mm: float, *,
                     blur_aspect: float | None = 1.0) -> FocusState:
    """The lens focused at its hyperfocal mark (:func:`hyperfocal_mark`), as a :class:`FocusState`.

    Solved as a fixed point in the subject's distance d from the first vertex, where the lens's state
    needs no search (:func:`state_for_object`): d <- H(d) - z_H1(d), H = f^2/(N c) + f from H1 with f,
    H1 and the f-number of the lens focused on d (the planes move little with focus: a few steps reach
    1e-12 of d). A candidate the lens cannot reach, or beyond 1000 km, is refused as :func:`focus`
    and the report refuse it, named by the mark the planes of the previous step give."""
    from . import dof

    n = require_positive("f-stop", fstop, unit="")
    c = require_positive("circle of confusion", coc_mm)
    p, method = prescription, focus_method(prescription)
    st = state_for_object(p, math.inf, method=method)
    g_inf = paraxial.gaussian(st.prescription, object_z=st.object_z, film_z=st.film_z)
    d = math.inf
    for _ in range(100):
        g = g_inf if math.isinf(d) else paraxial.gaussian(st.prescription, object_z=st.object_z, film_z=st.film_z)
        if blur_aspect is None:
            gx = paraxial.gaussian(st.prescription, axis="x", object_z=st.object_z, film_z=st.film_z)
            aspect = gx.entrance_pupil_diameter / g.entrance_pupil_diameter
        else:
            aspect = blur_aspect
        h = dof.hyperfocal_distance(g.efl, n * (g.f_number / g_inf.f_number), c / aspect)
        mark = h + g.in_front_of("front_principal_plane")  # the candidate mark, with the planes of this step
        if not 0.0 < mark <= _MAX_MARK_MM:
            raise InputError(f"hyperfocal focus mark {mark:g} mm is beyond 1000 km; for a subject at infinity use a "
                             "far limit of inf")
        d_new = h - g.z_front_principal_plane  # the subject H in front of H1, from the first vertex
        if math.isfinite(d) and abs(d_new - d) <= 1e-12 * d_new:
            return st
        nxt = state_for_object(p, d_new, method=method)
        if not _reachable(p, nxt):
            return focus(p, mark, method=method)  # raises the lens's own "cannot focus" sentence
        st, d = nxt, d_new
    raise OpticsError(f"the hyperfocal focus of {prescription.name!r} did not settle; give the focus mark")


def hyperfocal_mark(prescription: Prescription, fstop: float, coc_mm: float, *, blur_aspect: float | None = 1.0):
    """(mark, planes at the mark): the focus mark whose subject plane lies at the hyperfocal distance
    H = f^2/(N c) + f from H1 (Wikipedia, "Hyperfocal distance"), with f and H1 of the lens focused at
    that mark (:func:`hyperfocal_state`).

    ``fstop`` is the iris's setting at infinity; the f-number at each candidate focus is ``fstop``
    times :func:`f_number_ratio` there (internal focusing). ``blur_aspect``: the CoC is ``coc_mm /
    blur_aspect`` (an anamorphic's horizontal limits); None takes the lens's own :func:`pupil_aspect`
    at each focus, so the horizontal mark too is a fixed point."""
    st = hyperfocal_state(prescription, fstop, coc_mm, blur_aspect=blur_aspect)
    return st.focus_from_film_mm, planes_of(st)

"""Lens models: what a camera asks of its lens (issue 43).

A :class:`LensModel` is the small interface every lens answers, as pbrt-v4's camera interface or
optiland's ``Optic``: at a focus mark it gives the lens's planes in front of the film
(:class:`LensAtMark`), it knows its hyperfocal mark for an f-stop and a circle of confusion, its
widest stop, and (a zoom lens) itself at a zoom position. Three implementations:

* :class:`PrescriptionLens`: a real prescription, exact. It is focused at the mark by its own
  focusing (:func:`physcam.optics.focusing.focus`: unit or internal) and traced paraxially there;
  each mark is focused once per lens model and kept (the camera that asks again gets the same
  state). A zoom position is a prescription of its own (:meth:`PrescriptionLens.at_zoom`).
* :class:`ThinLens`: the practical model, H1 = H2 at s' in front of the film, moving with focus.
* :class:`Datasheet`: the technical model, a maker's H1, H2 and entrance pupil given as distances in
  front of a reference plane (the film, or the flange ``flange_focal_distance_mm`` in front of it).

A thin lens may carry a measured entrance pupil the same way (``pupil_mm`` from ``reference_plane``).
Distances ``*_from_film_mm`` are in front of the film plane, positive toward the subject; the
subject distance s is from H1 (docs/conventions.md). Scalars only, no numpy: the on-set report of a
thin lens or a datasheet imports nothing heavier (docs/performance.md).
"""

from __future__ import annotations

import math
from typing import NamedTuple, Protocol, runtime_checkable

from ..errors import InputError, OpticsError, require_finite, require_positive
from . import thinlens
from ._memo import IdentityMemo

from .._record import field, record

__all__ = ["LensModel", "LensAtMark", "PrincipalPlanes", "ThinLens", "Datasheet", "PrescriptionLens",
           "lens_model_of", "REFERENCE_PLANES"]

#: Planes a datasheet's offsets may be measured from.
REFERENCE_PLANES = ("film", "flange")


class LensAtMark(NamedTuple):  # a NamedTuple: made for every camera, cheap to define at start-up
    """What a lens is at one focus mark (planes in front of the film, mm): what the on-set report and
    every front end read. ``model`` is "practical" (thin lens: H1 = H2 move with focus, None here) or
    "technical" (a datasheet's or a prescription's planes)."""

    focal_length_mm: float  # EFL at this focus (Y meridian)
    model: str
    h1_from_film_mm: float | None
    h2_from_film_mm: float | None
    pupil_from_film_mm: float | None
    squeeze: float  # the picture's desqueeze factor
    lens_name: str | None = None
    pinhole: tuple[float, float] | None = None  # (Y, X) best-match pinhole focal lengths, mm
    stop_from_film_mm: float | None = None
    n_ratio: float = 1.0  # f-number at this focus over the iris's f-stop (internal focusing)
    bellows: float | None = None  # working f-number over the f-stop; None: 1 + |m| (pupils equal)
    blur_aspect: float = 1.0  # the lens's blur width over height, before desqueezing
    lens_squeeze: float = 1.0  # EFL in Y over EFL in X at this focus
    squeeze_from_lens: bool = False
    pupil_origin: str = "datasheet"
    notes: tuple[str, ...] = ()
    #: a prescription's EFL at infinity focus, (Y, X) mm: the field of view at infinity (None: the
    #: focal length, which a thin lens or a datasheet keeps at every focus)
    efl_infinity: tuple[float, float] | None = None
    #: an anamorphic prescription's X-meridian (horizontal, pan) entrance pupil in front of the film;
    #: ``pupil_from_film_mm`` is then the Y meridian's (vertical, tilt). None: one pupil for both
    pupil_x_from_film_mm: float | None = None


class PrincipalPlanes(NamedTuple):  # a NamedTuple: made at every report, cheap to define at start-up
    """Where H1 sits in front of the film, and how a focus mark D maps to the object distance s from
    H1. Thin lens (H1 = H2 = s' in front of the film): s + s' = D. Datasheet: H1 fixed, s = D - H1."""

    f: float
    h1_from_film: float | None = None  # the datasheet's H1 (None: the thin lens's, moving with focus)
    h2_from_film: float | None = None

    @classmethod
    def of(cls, at: LensAtMark) -> "PrincipalPlanes":
        """The practical (thin lens) or technical (datasheet or prescription) planes of a lens at a mark."""
        if at.model == "practical":
            return cls(at.focal_length_mm)
        return cls(at.focal_length_mm, at.h1_from_film_mm, at.h2_from_film_mm)

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


@runtime_checkable
class LensModel(Protocol):
    """What every lens model answers (module notes). Marks are mm in front of the film plane."""

    kind: str  # "prescription", "thin lens" or "datasheet"

    @property
    def name(self) -> str | None: ...

    def at_mark(self, mark: float, fstop: float | None, squeeze: float) -> LensAtMark:
        """The lens focused at ``mark`` (inf: infinity), its iris at ``fstop`` (None: as built)."""

    def hyperfocal_mark(self, fstop: float, coc_mm: float, *, blur_aspect: float | None = 1.0) -> float:
        """The focus mark whose subject plane lies at the hyperfocal distance f^2/(N c) + f from H1."""

    def wide_open(self) -> float | None:
        """The widest f-stop the lens is known to open to (None: not known, give it)."""

    def at_zoom(self, zoom) -> "LensModel":
        """The lens at a zoom position (a prime refuses any)."""


def _require_no_zoom(name, zoom):
    if zoom is not None:
        raise InputError(f"{name} is not a zoom lens: drop the zoom position")


@record
class _OnTheFilm:
    """A lens whose planes are known as numbers (thin lens, datasheet): offsets from a reference plane."""

    focal_length_mm: float
    squeeze: float = 1.0
    lens_name: str | None = None
    pupil_mm: float | None = None  # the entrance pupil in front of the reference plane
    reference_plane: str = "film"
    flange_focal_distance_mm: float | None = None

    def __post_init__(self):
        f = thinlens.require_focal_length(self.focal_length_mm)
        sq = require_positive("anamorphic squeeze", self.squeeze, unit="")
        if not 0.1 <= sq <= 10.0:
            raise InputError(f"anamorphic squeeze must lie between 0.1 and 10, got {sq:g}")
        if self.reference_plane not in REFERENCE_PLANES:
            raise InputError(f"reference plane must be 'film' or 'flange', got {self.reference_plane!r}")
        out = {"focal_length_mm": f, "squeeze": sq}
        if self.reference_plane == "flange":
            if self.flange_focal_distance_mm is None:
                raise InputError("a flange reference needs the flange focal distance (e.g. 52 mm for PL, 44 mm for "
                                 "LPL)")
            out["flange_focal_distance_mm"] = require_positive("flange focal distance", self.flange_focal_distance_mm)
        if self.pupil_mm is not None:
            out["pupil_mm"] = require_finite("entrance pupil offset", self.pupil_mm)
        for k, v in out.items():
            object.__setattr__(self, k, v)

    @property
    def name(self) -> str | None:
        return self.lens_name

    def from_film(self, offset):
        """A datasheet offset (from the reference plane) as a distance in front of the film."""
        if offset is None:
            return None
        return (self.flange_focal_distance_mm if self.reference_plane == "flange" else 0.0) + offset

    def wide_open(self):
        return None

    def at_zoom(self, zoom):
        _require_no_zoom(f"a {self.kind}", zoom)
        return self

    def hyperfocal_mark(self, fstop, coc_mm, *, blur_aspect=1.0) -> float:
        """The mark whose subject lies at H = f^2/(N c) + f from H1 (Wikipedia, "Hyperfocal distance")."""
        from . import dof

        at = self.at_mark(math.inf, fstop, self.squeeze)  # (a thin lens's blur is round: no aspect)
        return PrincipalPlanes.of(at).mark_for_s(dof.hyperfocal_distance(at.focal_length_mm, fstop, coc_mm))


@record
class ThinLens(_OnTheFilm):
    """The practical model: a thin lens of ``focal_length_mm`` whose principal planes H1 = H2 sit s' in
    front of the film (so a focus mark D is s + s', docs/conventions.md); ``squeeze`` the anamorphic
    squeeze it is shot with; optionally a measured entrance pupil (``pupil_mm`` in front of
    ``reference_plane``), else the pupil is at the principal plane."""

    kind = "thin lens"

    def at_mark(self, mark, fstop, squeeze) -> LensAtMark:
        return LensAtMark(self.focal_length_mm, "practical", None, None, self.from_film(self.pupil_mm), squeeze,
                          self.lens_name)


@record
class Datasheet(_OnTheFilm):
    """The technical model: a maker's principal planes ``h1_mm``, ``h2_mm`` and entrance pupil
    ``pupil_mm`` (None: not published), each a distance in front of ``reference_plane`` ("film", or
    "flange" ``flange_focal_distance_mm`` in front of the film), at every focus."""

    h1_mm: float = field(kw_only=True)
    h2_mm: float = field(kw_only=True)
    kind = "datasheet"

    def __post_init__(self):
        super().__post_init__()
        object.__setattr__(self, "h1_mm", require_finite("H1 offset", self.h1_mm))
        object.__setattr__(self, "h2_mm", require_finite("H2 offset", self.h2_mm))

    def at_mark(self, mark, fstop, squeeze) -> LensAtMark:
        return LensAtMark(self.focal_length_mm, "technical", self.from_film(self.h1_mm), self.from_film(self.h2_mm),
                          self.from_film(self.pupil_mm), squeeze, self.lens_name)


class PrescriptionLens:
    """A real prescription as a lens model: exact, traced paraxially at each mark (module notes).

    Each focus mark is solved once (:func:`physcam.optics.focusing.focus`) and kept, with the state
    at infinity that sizes the iris: cameras of one lens model at one mark share the solution."""

    kind = "prescription"
    #: focus states kept per lens model (a DOF chart asks a few dozen marks)
    KEEP = 64

    def __init__(self, prescription, *, lens_name: str | None = None):
        from ..lens.prescription import require_prescription

        self.prescription = require_prescription(prescription)
        self.lens_name = lens_name
        self._states: dict[float, object] = {}

    def __repr__(self) -> str:
        return f"PrescriptionLens({self.prescription.name!r})"

    def __eq__(self, other) -> bool:  # one lens, one model (its kept focus solutions aside)
        if not isinstance(other, PrescriptionLens):
            return NotImplemented
        return self is other or (self.lens_name == other.lens_name and self.prescription == other.prescription)

    def __hash__(self) -> int:
        return hash((self.lens_name, self.prescription.name, len(self.prescription.surfaces)))

    @property
    def name(self) -> str:
        return self.lens_name or self.prescription.name

    @property
    def squeeze(self) -> float:
        return 1.0  # "not given": an anamorphic prescription frames each meridian by its own EFL

    def focus_state(self, mark: float):
        """The lens focused at ``mark`` (:class:`~physcam.optics.focusing.FocusState`; inf: infinity),
        solved once per lens model."""
        st = self._states.get(mark)
        if st is None:
            from .focusing import focus

            st = focus(self.prescription, mark)
            self.keep(st)
        return st

    def keep(self, state) -> None:
        """Keep a focus state solved elsewhere (a hyperfocal solve) for the marks asked later."""
        if len(self._states) >= self.KEEP:
            self._states.pop(next(k for k in self._states if not math.isinf(k)))
        self._states[state.focus_from_film_mm] = state

    def iris(self, fstop: float) -> float:
        """The iris semi-diameter (mm) for ``fstop``, by the one rule
        (:func:`physcam.optics.focusing.iris_semi_diameter`: EFL over entrance pupil at infinity focus)."""
        from . import paraxial

        return paraxial.stop_semi_diameter_for_fstop(self.focus_state(math.inf).prescription, fstop)

    def wide_open(self) -> float:
        """The engraved widest f-stop, or the file's own stop's f-number when that is slower."""
        from . import paraxial

        return max(paraxial.gaussian(self.prescription).f_number, self.prescription.metadata.max_fstop or 0.0)

    def at_zoom(self, zoom) -> "PrescriptionLens":
        """The prescription at a zoom position (the zoom table's encoder 0..1 or a focal length such as "135mm"),
        a lens model of its own; a prime refuses any."""
        if zoom is None:
            return self
        if getattr(self.prescription, "zoom", None) is None:
            _require_no_zoom(f"lens {self.prescription.name!r}", zoom)
        from ..lens.zoom import prescription_at
        from .zoom import zoom_encoder

        return PrescriptionLens(prescription_at(self.prescription, zoom_encoder(self.prescription, zoom)),
                                lens_name=self.lens_name)

    def hyperfocal_mark(self, fstop, coc_mm, *, blur_aspect=1.0) -> float:
        """The hyperfocal mark (:func:`physcam.optics.focusing.hyperfocal_state`), its state kept."""
        from .focusing import hyperfocal_state

        st = hyperfocal_state(self.prescription, fstop, coc_mm, blur_aspect=blur_aspect)
        if blur_aspect == 1.0:
            self.keep(st)
        return st.focus_from_film_mm

    def at_mark(self, mark, fstop, squeeze, *, stop_semi_diameter=None) -> LensAtMark:
        """The technical model's planes of the lens focused at ``mark``, its iris ``stop_semi_diameter``
        (None: the file's stop): EFL, H1, H2, entrance pupil, stop, f-number ratio and squeeze."""
        from . import focusing, paraxial

        st = self.focus_state(mark)
        planes = focusing.planes_of(st, stop_semi_diameter=stop_semi_diameter)
        notes = [f"planes from the prescription focused at the mark ({planes.method} focusing): EFL "
                 f"{planes.efl_mm:.3f} mm, back focus {planes.back_focus_mm:.3f} mm"]
        n_ratio = self._f_number_ratio(st)
        inf = paraxial.gaussian_xy(self.prescription)
        at = LensAtMark(planes.efl_mm, "technical", planes.h1_from_film_mm, planes.h2_from_film_mm,
                        planes.entrance_pupil_from_film_mm, squeeze, self.name,
                        (planes.pinhole_focal_length_mm,) * 2, planes.stop_from_film_mm, n_ratio,
                        planes.working_f_number / planes.f_number * n_ratio, pupil_origin="prescription",
                        efl_infinity=(inf["y"].efl, inf["x"].efl))
        if self.prescription.is_anamorphic:
            at = self._anamorphic(at, st, planes, notes)
        return at._replace(notes=tuple(notes))

    def _f_number_ratio(self, st) -> float:
        """:func:`physcam.optics.focusing.f_number_ratio` of the states this model keeps."""
        from . import paraxial

        def f_number(s):
            return paraxial.gaussian(s.prescription, object_z=s.object_z, film_z=s.film_z).f_number

        return f_number(st) / f_number(self.focus_state(math.inf))

    def _anamorphic(self, at: LensAtMark, st, planes, notes: list) -> LensAtMark:
        """An anamorphic prescription's squeeze at this focus (EFL in Y over X) and blur aspect (its
        entrance pupil's X over Y); when no squeeze was given, the lens's own frames each meridian."""
        from . import paraxial

        gx = paraxial.gaussian(st.prescription, axis="x", object_z=st.object_z, film_z=st.film_z)
        gy = paraxial.gaussian(st.prescription, axis="y", object_z=st.object_z, film_z=st.film_z)
        lens_squeeze = planes.efl_mm / gx.efl
        at = at._replace(lens_squeeze=lens_squeeze, blur_aspect=gx.entrance_pupil_diameter / gy.entrance_pupil_diameter,
                         pupil_x_from_film_mm=gx.in_front_of("entrance_pupil"))
        if abs(at.pupil_x_from_film_mm - at.pupil_from_film_mm) > 0.05:
            notes.append(f"anamorphic: two entrance pupils, horizontal (X, the pan pivot) "
                         f"{at.pupil_x_from_film_mm:.1f} mm and vertical (Y, the tilt pivot) "
                         f"{at.pupil_from_film_mm:.1f} mm in front of the film; the report's entrance pupil is "
                         "the vertical one")
        if at.squeeze != 1.0:
            return at
        notes.append(f"anamorphic: EFL {planes.efl_mm:.3f} mm (Y) and {gx.efl:.3f} mm (X), effective squeeze "
                     f"{lens_squeeze:.4f} (nominal {self.prescription.squeeze:g})")
        return at._replace(squeeze=lens_squeeze, squeeze_from_lens=True,
                           pinhole=(planes.pinhole_focal_length_mm, gx.pinhole_focal_length))


#: each prescription's lens model, by the prescription's identity (the last 64)
_MODELS = IdentityMemo(64)


def lens_model_of(lens) -> LensModel:
    """``lens`` as a lens model: a model as it is; a :class:`~physcam.lens.prescription.Prescription` as
    its :class:`PrescriptionLens` (one per prescription object, so its focus solutions are shared)."""
    if isinstance(lens, (PrescriptionLens, ThinLens, Datasheet)):
        return lens
    from ..lens.prescription import Prescription

    if isinstance(lens, Prescription):
        model = _MODELS.get(id(lens), lens)
        return model if model is not None else _MODELS.put(id(lens), lens, PrescriptionLens(lens))
    if isinstance(lens, LensModel):  # a lens model of the user's own
        return lens
    from ..errors import WrongTypeError

    raise WrongTypeError(f"lens must be a lens model (physcam.optics.lens_model.ThinLens, Datasheet, PrescriptionLens) "
                         f"or a prescription (physcam.lens.library.load_lens(name or file)), got "
                         f"{type(lens).__name__} {lens!r:.60}")

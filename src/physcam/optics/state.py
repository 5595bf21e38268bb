"""A camera state: this lens, focused here, stopped to this f-stop, on this sensor, at these
wavelengths. Made once, checked once, then handed to every analysis that needs it.

Focus is the mark's distance in front of the film plane (``focus_from_film_mm``; ``inf`` at
infinity), through the lens's own focusing (:func:`physcam.optics.focusing.focus`: unit or internal,
with breathing). The f-stop is the iris's setting, defined at infinity focus, and sizes the stop by
the one iris rule (:func:`physcam.optics.focusing.iris_semi_diameter`); the iris keeps that size at
every focus, so an internal-focus lens's f-number at the focus differs
(:attr:`CameraState.f_number_at_focus`). Lens-space positions ``*_z`` are along the axis from the
first vertex (docs/conventions.md).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import cached_property

from ..errors import InputError, OpticsError, WrongTypeError, require_finite, require_type
from ..lens.prescription import Prescription, first_argument_checked
from .thinlens import MAX_F_NUMBER, MIN_F_NUMBER, require_f_number

__all__ = ["CameraState", "camera_state", "as_camera_state", "takes_camera", "wavelengths_and_weights", "require_f_number", "MIN_F_NUMBER", "MAX_F_NUMBER"]

@dataclass(frozen=True, eq=False)
class CameraState:
    """A lens at one focus and one stop (module notes). Build it with :func:`camera_state`."""

    lens: Prescription  # as designed (its file's infinity focus)
    focused: Prescription  # with the focused gaps and back focus
    focus_from_film_mm: float  # the mark from the film plane; inf at infinity
    object_z: float  # lens space; -inf at infinity
    film_z: float  # lens space: the film plane
    fstop: float  # the iris's setting, at infinity focus (the file's paraxial f-number when none was given)
    stop_semi_diameter: float  # mm, the iris by the one rule, the same at every focus
    wavelengths_nm: tuple[float, ...] = ()
    weights: tuple[float, ...] = ()
    sensor_mm: tuple[float, float] | None = None  # width, height
    aperture: object = None  # an iris shape (physcam.trace.aperture.Aperture); None: round
    iris_set: bool = False  # True: the iris was set to an f-stop; False: the lens as its file stops it
    notes: tuple[str, ...] = field(default=())

    @property
    def lens_name(self) -> str:
        return self.lens.name

    @property
    def at_infinity(self) -> bool:
        return math.isinf(self.object_z)

    @cached_property
    def gaussian(self):
        """The focused lens's Gaussian data at this object and film (physcam.optics.paraxial), the
        file's stop: scale pupil diameters by :attr:`stop_scale`."""
        from . import paraxial

        return paraxial.gaussian(self.focused, object_z=self.object_z, film_z=self.film_z)

    @property
    def stop_scale(self) -> float:
        """The iris's semi-diameter over the file's stop semi-diameter."""
        return self.stop_semi_diameter / self.focused.surfaces[self.focused.stop_index].semi_diameter

    @property
    def entrance_pupil_z(self) -> float:
        return float(self.gaussian.z_entrance_pupil)

    @property
    def entrance_pupil_radius(self) -> float:
        """mm: the paraxial entrance pupil of the iris at this focus."""
        return float(0.5 * self.gaussian.entrance_pupil_diameter * self.stop_scale)

    @property
    def exit_pupil_z(self) -> float:
        return float(self.gaussian.z_exit_pupil)

    @property
    def f_number_at_focus(self) -> float:
        """EFL at this focus over the entrance pupil's diameter (the iris set to :attr:`fstop`)."""
        return float(self.gaussian.efl / (2.0 * self.entrance_pupil_radius))


def _fstop_and_stop(lens: Prescription, fstop) -> tuple[float, float]:
    from . import paraxial
    from .focusing import iris_semi_diameter

    if fstop is None:  # the lens as its file stops it
        return float(paraxial.gaussian(lens).f_number), float(lens.surfaces[lens.stop_index].semi_diameter)
    n = require_f_number("f-stop", fstop)
    return float(n), float(iris_semi_diameter(lens, n))


def _focused(lens: Prescription, focus_mm) -> tuple[Prescription, float, float, float]:
    """(focused lens, object z, film z, mark); None or +inf: the file's infinity focus, film at the
    paraxial image of an axial object at infinity."""
    from . import paraxial
    from .focusing import focus

    if isinstance(focus_mm, str):  # "2m", "10ft", "infinity": as the command line reads it (a bare number: mm)
        from ..units import parse_distance

        focus_mm = parse_distance(focus_mm, name="focus distance", allow_inf=True)
    if focus_mm is None or (isinstance(focus_mm, (int, float)) and not isinstance(focus_mm, bool)
                            and math.isinf(focus_mm) and focus_mm > 0):
        g = paraxial.gaussian(lens)
        return lens, -math.inf, float(g.z_rear_focal_point), math.inf
    mark = require_finite("focus distance", focus_mm)
    st = focus(lens, mark)
    return st.prescription, float(st.object_z), float(st.film_z), float(mark)


def wavelengths_and_weights(lens, wavelengths_nm, weights):
    """Validated wavelengths (nm) and weights normalised to sum 1; the first wavelength is the primary.
    ``lens``: a Prescription (default: its design wavelength) or a CameraState (default: its own)."""
    import numpy as np

    from .glass import require_wavelength

    if isinstance(lens, CameraState):
        if wavelengths_nm is None:
            wavelengths_nm, weights = lens.wavelengths_nm, lens.weights
        lens = lens.lens
    if wavelengths_nm is None:
        wls = [float(lens.wavelength_nm)]
    else:
        if isinstance(wavelengths_nm, (str, bytes)) or np.ndim(wavelengths_nm) > 1:
            raise InputError(f"wavelengths must be numbers in nm, got {wavelengths_nm!r:.60}")
        seq = np.atleast_1d(np.asarray(wavelengths_nm, dtype=object)).tolist()
        wls = [require_finite("wavelength_nm", w) for w in seq]
    if not 1 <= len(wls) <= 24:
        raise InputError(f"give 1 to 24 wavelengths, got {len(wls)}")
    for w in wls:
        if not 200.0 <= w <= 20000.0:
            raise InputError(f"wavelength {w:g} nm is outside 200-20000 nm")
        require_wavelength(w, "wavelength")
    if weights is None:
        ws = [1.0] * len(wls)
    else:
        if isinstance(weights, (str, bytes)) or np.ndim(weights) > 1:
            raise InputError(f"weights must be numbers, got {weights!r:.60}")
        ws = [require_finite("wavelength weight", w) for w in np.atleast_1d(np.asarray(weights, dtype=object)).tolist()]
        if len(ws) != len(wls):
            raise InputError(f"give one weight per wavelength: {len(wls)} wavelengths, {len(ws)} weights")
        if any(w < 0 for w in ws) or not sum(ws) > 0:
            raise InputError("wavelength weights must be >= 0 with a positive sum")
    tot = sum(ws)
    return wls, [w / tot for w in ws]


def camera_state(lens: Prescription, *, focus_mm=None, fstop=None, sensor_mm=None, wavelengths_nm=None,
                 weights=None, aperture=None) -> CameraState:
    """``lens`` focused at ``focus_mm`` (the mark from the film plane, mm or a string with units such as
    "2m", "10ft"; None, inf or "infinity": infinity), its
    iris set to ``fstop`` (None: as the file stops it), on a sensor ``sensor_mm`` (width, height; None:
    not needed), at ``wavelengths_nm`` (None: the lens's design wavelength) with ``weights``.
    Every argument is checked here, once (InputError or OpticsError with a sentence)."""
    require_type("lens", lens, Prescription, "physcam.lens.library.load_lens(name or file)")
    if aperture is not None and not all(callable(getattr(aperture, m, None)) for m in ("rim_radius", "density_at",
                                                                                       "sample")):
        # (an iris shape is physcam.trace.aperture.Aperture, a layer above: checked by what it must do)
        raise WrongTypeError(f"aperture must be an iris shape, physcam.trace.aperture.Aperture(blades, ...), or None "
                             f"(round), got {type(aperture).__name__} {aperture!r:.60}")
    stop_n, stop = _fstop_and_stop(lens, fstop)
    focused, object_z, film_z, mark = _focused(lens, focus_mm)
    if sensor_mm is not None:
        w, h = (require_finite("sensor size", v) for v in sensor_mm)
        if not (0.0 < w <= 1000.0 and 0.0 < h <= 1000.0):
            raise InputError(f"the sensor must measure between 0 and 1000 mm a side, got {w:g} x {h:g}")
        sensor_mm = (float(w), float(h))
    wls, ws = (tuple(v) for v in wavelengths_and_weights(lens, wavelengths_nm, weights))
    state = CameraState(lens, focused, mark, object_z, film_z, stop_n, stop, wls, ws, sensor_mm, aperture,
                        fstop is not None)
    if not object_z < state.entrance_pupil_z:
        raise OpticsError(f"the object lies behind the entrance pupil of {lens.name!r}: no real pupil to sample")
    return state


def as_camera_state(lens, *, focus_mm=None, fstop=None, **state) -> CameraState:
    """The door of every function that takes a camera first (issue 28): ``lens`` as it is when it is a
    :class:`CameraState` (then ``focus_mm`` and ``fstop`` must be None: an InputError), or a
    Prescription through ``camera_state(lens, focus_mm=, fstop=, **state)``."""
    if isinstance(lens, CameraState):
        if focus_mm is not None or fstop is not None:
            raise InputError("a CameraState carries its own focus and f-stop: give them to camera_state(), not here")
        return lens
    return camera_state(lens, focus_mm=focus_mm, fstop=fstop, **state)


def _require_camera(value, name: str) -> None:
    if not isinstance(value, CameraState):
        require_type(name, value, Prescription,
                     "a CameraState (physcam.optics.state.camera_state(lens, focus_mm=..., fstop=...)) or a lens "
                     "(physcam.lens.library.load_lens(name or file))")


def takes_camera(fn):
    """Decorator: the first argument is a :class:`CameraState` or a
    :class:`~physcam.lens.prescription.Prescription` (then focused and stopped from the function's
    own ``focus_mm`` and ``fstop``); anything else is a WrongTypeError with a sentence."""
    return first_argument_checked(_require_camera)(fn)

"""The camera: this lens, focused here, stopped to this f-stop, on this sensor, at these wavelengths.
Built once at the door, checked once, focus solved once; then every report, analysis and exporter
asks it (issue 43; the shape of pbrt-v4's ``RealisticCamera`` and optiland's ``Optic``).

The lens is a lens model (:mod:`physcam.optics.lens_model`: a prescription, a thin lens or a
datasheet). Focus is the mark's distance in front of the film plane (``focus_from_film_mm``; ``inf``
at infinity; "hyperfocal": the mark whose subject plane lies at the hyperfocal distance for this
f-stop and circle of confusion, solved when the camera is built), through the lens's own focusing
(:func:`physcam.optics.focusing.focus`: unit or internal, with breathing). A ``zoom`` position sits
beside the focus (a zoom prescription is a prescription per position). The f-stop is the iris's
setting, defined at infinity focus, and sizes the stop by the one iris rule
(:func:`physcam.optics.focusing.iris_semi_diameter`); the iris keeps that size at every focus, so an
internal-focus lens's f-number at the focus differs (:attr:`CameraState.f_number_at_focus`).
What the lens is at the mark (EFL, principal planes, entrance pupil, f-number ratio, pinhole,
squeeze, blur aspect: :class:`~physcam.optics.lens_model.LensAtMark`) is computed once and kept on
the camera (:attr:`CameraState.at_mark`). Lens-space positions ``*_z`` are along the axis from the
first vertex (docs/conventions.md).

Every function that takes a camera takes it through one door, :func:`takes_camera`: a camera as it
is, or a lens with the function's old keywords (``focus_mm=``, ``fstop=``, a sensor ...), which
build the camera there with a DeprecationWarning (they go in physcam 0.3).
"""

from __future__ import annotations

import functools
import math

from .._record import field, record, replace
from ..errors import InputError, OpticsError, WrongTypeError, require_finite, require_type
from .lens_model import LensModel, PrescriptionLens, lens_model_of
from .sensors import Sensor
from .thinlens import MAX_F_NUMBER, MIN_F_NUMBER, require_f_number

__all__ = ["CameraState", "camera_state", "as_designed", "as_camera_state", "takes_camera", "OfACamera", "wavelengths_and_weights",
           "require_f_number", "MIN_F_NUMBER", "MAX_F_NUMBER", "HYPERFOCAL", "DOOR_KEYWORDS"]

#: ``focus_mm=HYPERFOCAL``: focus at the hyperfocal mark of this lens, f-stop and circle of confusion.
HYPERFOCAL = "hyperfocal"
#: The keywords a function that takes a camera took before issue 43 to build one itself: now the door's
#: (:func:`takes_camera`), with a DeprecationWarning, until physcam :data:`UNTIL`.
DOOR_KEYWORDS = ("focus_mm", "focus_from_film_mm", "fstop", "sensor", "sensor_mm", "sensor_width_mm",
                 "sensor_height_mm", "aperture", "film_z", "stop_semi_diameter", "zoom")
UNTIL = "0.3"


@record
class CameraState:
    """A lens at one focus, zoom and stop, on a sensor (module notes). Build it with :func:`camera_state`.

    ``lens`` is the prescription as designed (its file's infinity focus) for a prescription camera,
    else the lens model; ``focused`` the prescription with the focused gaps and back focus (a thin
    lens or a datasheet has none: asking for it is an OpticsError naming the model). Two cameras are
    equal when every setting is (the same lens, focus, stop, sensor, light and iris shape)."""

    lens_model: LensModel
    focus_from_film_mm: float  # the mark from the film plane; inf at infinity
    fstop: float  # the iris's setting, at infinity focus (a prescription's own stop's f-number when none was given)
    sensor: Sensor | None = None
    zoom: float | None = None  # the zoom position (encoder 0..1) of a zoom lens; None: a prime
    squeeze: float = 1.0  # the picture's desqueeze factor (a prescription: 1 = its own)
    stop_semi_diameter: float | None = None  # mm, a prescription's iris by the one rule, the same at every focus
    object_z: float = -math.inf  # lens space; -inf at infinity
    film_z: float | None = None  # lens space: the film plane (a prescription camera)
    wavelengths_nm: tuple[float, ...] = ()
    weights: tuple[float, ...] = ()
    aperture: object = None  # an iris shape (physcam.trace.aperture.Aperture); None: round
    iris_set: bool = False  # True: the iris was set to an f-stop; False: the lens as its file stops it
    #: True when neither a focus nor a film plane was given: the lens as its file focuses it, and a ray
    #: analysis puts the film where its own rule says (the paraxial image at its wavelength)
    film_from_analysis: bool = False
    notes: tuple[str, ...] = field(default=())
    #: what was solved to make this camera, in order ("focus_from_film_mm": from measured limits,
    #: "focus": "hyperfocal", "fstop": from measured limits ...): the report says it
    solved: tuple[tuple[str, object], ...] = ()
    _focused: object = None  # the focused Prescription (see ``focused``)

    # --- the lens --------------------------------------------------------------------------------
    @property
    def lens(self):
        """The prescription as designed (a prescription camera), else the lens model."""
        m = self.lens_model
        return m.prescription if isinstance(m, PrescriptionLens) else m

    @property
    def focused(self):
        """The focused prescription (gaps and back focus at this mark): what a tracer traces."""
        if self._focused is None:
            raise OpticsError(f"a {self.lens_model.kind} camera has no prescription to trace: build the camera on a "
                              "lens prescription (physcam.lens.library.load_lens)")
        return self._focused

    @property
    def traceable(self) -> bool:
        return self._focused is not None

    @property
    def lens_name(self) -> str | None:
        return self.lens_model.name

    @property
    def at_infinity(self) -> bool:
        return math.isinf(self.focus_from_film_mm)

    @property
    def sensor_mm(self) -> tuple[float, float] | None:
        """(width, height) of the sensor, mm; None: no sensor given."""
        return None if self.sensor is None else (self.sensor.width_mm, self.sensor.height_mm)

    @functools.cached_property
    def at_mark(self):
        """What the lens is at this focus (:class:`~physcam.optics.lens_model.LensAtMark`: EFL, H1, H2 and
        the entrance pupil in front of the film, the f-number ratio, pinhole, squeeze, blur aspect),
        computed once."""
        m = self.lens_model
        if isinstance(m, PrescriptionLens):
            return m.at_mark(self.focus_from_film_mm, self.fstop, self.squeeze,
                             stop_semi_diameter=self.stop_semi_diameter if self.iris_set else None)
        return m.at_mark(self.focus_from_film_mm, self.fstop, self.squeeze)

    # --- a prescription camera's paraxial data ---------------------------------------------------
    @functools.cached_property
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
    def iris_corner_semi(self) -> float:
        """The stop radius (mm) the iris's corners reach: a bladed iris has the area of the round iris
        of the f-number (docs/conventions.md), so its corners lie ``aperture.equal_area_scale()``
        (:meth:`physcam.trace.aperture.Aperture.equal_area_scale`) farther out than that circle, but
        never beyond the lens's widest iris (the file's stop opened by
        :data:`~physcam.optics.paraxial.STOP_OPENING_TOLERANCE`) unless the round iris itself is wider;
        the round iris's radius (:attr:`stop_semi_diameter`) for a round one. Every tracer of a bladed
        iris draws its polygon inside this radius: the analyses, the defocus kernels, the Blender shader."""
        ap = self.aperture
        if ap is None or ap.is_circular:
            return float(self.stop_semi_diameter)
        from .paraxial import STOP_OPENING_TOLERANCE

        q = self.focused
        return ap.corner_semi(self.stop_semi_diameter, q.surfaces[q.stop_index].semi_diameter * (1 + STOP_OPENING_TOLERANCE))

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
        if not self.traceable:
            return self.fstop * self.at_mark.n_ratio
        return float(self.gaussian.efl / (2.0 * self.entrance_pupil_radius))

    # --- cameras near this one -------------------------------------------------------------------
    def with_fstop(self, fstop, *, solved: tuple = (), lenient: bool = False) -> "CameraState":
        """This camera with the iris set to ``fstop`` (the focus kept: no focus solved again). ``lenient``: an
        f-stop faster than the lens opens (solved from measured limits: it is what they say) keeps the iris as
        the file stops it instead of an OpticsError, and one slower than :data:`MAX_F_NUMBER` is kept as solved
        (a typed f-stop that slow is refused as a typo; a solved one is the answer the limits give)."""
        n = float(fstop) if lenient and math.isfinite(fstop) and fstop > MAX_F_NUMBER else require_f_number("f-stop", fstop)
        stop, iris_set = self.stop_semi_diameter, True
        if self.traceable:
            try:
                stop = self.lens_model.iris(n)
            except OpticsError:
                if not lenient:
                    raise
                iris_set = False
        cam = replace(self, fstop=float(n), stop_semi_diameter=stop, iris_set=iris_set, solved=self.solved + solved)
        cam.__dict__.pop("at_mark", None)
        cam.__dict__.pop("gaussian", None)
        return cam

    def with_aperture(self, aperture) -> "CameraState":
        """This camera with another iris shape (physcam.trace.aperture.Aperture; None: round)."""
        _require_iris_shape(aperture)
        return replace(self, aperture=aperture)


class OfACamera:
    """A result that holds the camera it was computed for (``camera``) rather than copies of its
    settings: its focus, f-stop and lens name are the camera's."""

    @property
    def fstop(self) -> float:
        """The iris's setting (at infinity focus) of the camera analysed."""
        return self.camera.fstop

    @property
    def focus_from_film_mm(self) -> float:
        """The camera's focus mark in front of the film (inf at infinity)."""
        return self.camera.focus_from_film_mm


def _require_iris_shape(aperture) -> None:
    if aperture is not None and not all(callable(getattr(aperture, m, None)) for m in ("rim_radius", "density_at",
                                                                                       "sample")):
        # (an iris shape is physcam.trace.aperture.Aperture, a layer above: checked by what it must do)
        raise WrongTypeError(f"aperture must be an iris shape, physcam.trace.aperture.Aperture(blades, ...), or None "
                             f"(round), got {type(aperture).__name__} {aperture!r:.60}")


def _sensor_of(sensor, sensor_mm) -> Sensor | None:
    """A sensor given by name, as a :class:`Sensor`, or as (width, height) mm."""
    if sensor is not None and sensor_mm is not None:
        raise InputError("give the sensor once: a Sensor (or its name) or its size in mm, not both")
    if isinstance(sensor, str):
        from .sensors import find_sensor

        return find_sensor(sensor)
    if sensor is not None:
        return require_type("sensor", sensor, Sensor, "physcam.optics.sensors.find_sensor(name) or custom_sensor(w, h)")
    if sensor_mm is None:
        return None
    try:
        pair = not isinstance(sensor_mm, (str, bytes)) and len(sensor_mm) == 2
    except TypeError:  # a number, or an array of none
        pair = False
    if not pair:
        raise InputError(f"sensor_mm takes the sensor's (width, height) in mm, e.g. sensor_mm=(36.0, 24.0), "
                         f"got {sensor_mm!r}")
    w, h = (require_finite(name, v) for name, v in zip(("sensor width", "sensor height"), sensor_mm))
    for name, v in (("sensor width", w), ("sensor height", h)):
        if not 0.0 < v <= 1000.0:
            raise InputError(f"{name} must lie between 0 and 1000 mm (the sensor must measure between 0 and 1000 mm "
                             f"a side), got {w:g} x {h:g}")
    return Sensor("custom", f"custom {w:g} x {h:g} mm", float(w), float(h))


def _mark(focus_mm) -> float | str:
    """A focus mark in mm from the film (inf at infinity), or :data:`HYPERFOCAL`; a string is read as the
    command line reads it ("2m", "10ft", "infinity", "hyperfocal"; a bare number is mm)."""
    if isinstance(focus_mm, str):
        if focus_mm.strip().lower() in (HYPERFOCAL, "hyper"):
            return HYPERFOCAL
        from ..units import parse_distance

        focus_mm = parse_distance(focus_mm, name="focus distance", allow_inf=True)
    if focus_mm is None or (isinstance(focus_mm, (int, float)) and not isinstance(focus_mm, bool)
                            and math.isinf(focus_mm) and focus_mm > 0):
        return math.inf
    return require_finite("focus distance", focus_mm)


def wavelengths_and_weights(lens, wavelengths_nm, weights):
    """Validated wavelengths (nm) and weights normalised to sum 1; the first wavelength is the primary.
    ``lens``: a Prescription (default: its design wavelength) or a CameraState (default: its own).
    numpy only for given sequences (the on-set report of a prescription does not import it)."""
    from .glass import require_wavelength

    if isinstance(lens, CameraState):
        if wavelengths_nm is None:
            wavelengths_nm, weights = lens.wavelengths_nm, lens.weights if weights is None else weights
        lens = lens.lens
    if wavelengths_nm is None:
        wls = [float(lens.wavelength_nm)]
    else:
        import numpy as np

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
        import numpy as np

        if isinstance(weights, (str, bytes)) or np.ndim(weights) > 1:
            raise InputError(f"weights must be numbers, got {weights!r:.60}")
        ws = [require_finite("wavelength weight", w) for w in np.atleast_1d(np.asarray(weights, dtype=object)).tolist()]
        if len(ws) != len(wls):
            raise InputError(f"give one weight per wavelength: {len(wls)} wavelengths, {len(ws)} weights")
        if any(w < 0 for w in ws) or not sum(ws) > 0:
            raise InputError("wavelength weights must be >= 0 with a positive sum")
    tot = sum(ws)
    return wls, [w / tot for w in ws]


def camera_state(lens, *, focus_mm=None, fstop=None, sensor=None, sensor_mm=None, zoom=None, coc=None,
                 squeeze=None, wavelengths_nm=None, weights=None, aperture=None, film_z=None,
                 stop_semi_diameter=None) -> CameraState:
    """The camera of ``lens`` (a lens model, :mod:`physcam.optics.lens_model`, or a prescription),
    checked once here (InputError or OpticsError with a sentence):

    * ``focus_mm``: the mark from the film plane, mm or a string with units ("2m", "10ft"); None, inf or
      "infinity": infinity; "hyperfocal": the hyperfocal mark for ``fstop`` and ``coc`` (a CoC
      convention or mm; default d/1500 of the sensor), solved here;
    * ``fstop``: the iris's setting at infinity focus (None: a prescription as its file stops it; a
      thin lens or a datasheet needs one); or ``stop_semi_diameter``, the iris's size in mm;
    * ``sensor``: a :class:`~physcam.optics.sensors.Sensor` or its name, or ``sensor_mm`` (width,
      height); None: not needed; ``zoom``: a zoom lens's position (encoder 0..1 or "135mm");
    * ``squeeze``: the picture's desqueeze factor (None: the lens model's own);
    * ``wavelengths_nm``/``weights`` (None: the design wavelength), ``aperture`` the iris shape;
    * ``film_z``: the film plane placed by hand in lens space (a defocused camera), mm.
    """
    return _camera(lens, False, focus_mm=focus_mm, fstop=fstop, sensor=sensor, sensor_mm=sensor_mm, zoom=zoom, coc=coc,
                   squeeze=squeeze, wavelengths_nm=wavelengths_nm, weights=weights, aperture=aperture, film_z=film_z,
                   stop_semi_diameter=stop_semi_diameter)


def as_designed(lens, *, fstop=None, sensor=None, sensor_mm=None, wavelengths_nm=None, weights=None, aperture=None,
                stop_semi_diameter=None) -> CameraState:
    """The camera of ``lens`` as its file focuses it: the object at infinity, and the film where each ray
    analysis's own rule puts it (the paraxial image at the analysis's wavelength, not at the design
    wavelength as :func:`camera_state` places it); the other arguments as :func:`camera_state`. What a
    bare lens given to an analysis is."""
    return _camera(lens, True, fstop=fstop, sensor=sensor, sensor_mm=sensor_mm, wavelengths_nm=wavelengths_nm,
                   weights=weights, aperture=aperture, stop_semi_diameter=stop_semi_diameter)


def _camera(lens, film_from_analysis: bool, *, focus_mm=None, fstop=None, sensor=None, sensor_mm=None, zoom=None,
            coc=None, squeeze=None, wavelengths_nm=None, weights=None, aperture=None, film_z=None,
            stop_semi_diameter=None) -> CameraState:
    """:func:`camera_state`; ``film_from_analysis``: the door's camera of a bare lens (no focus, no film)."""
    model = lens_model_of(lens).at_zoom(zoom)
    _require_iris_shape(aperture)
    sensor = _sensor_of(sensor, sensor_mm)
    sq = model.squeeze if squeeze is None else _squeeze(squeeze)
    mark, notes, solved = _mark(focus_mm), [], ()
    if isinstance(model, PrescriptionLens):
        return _prescription_camera(model, mark, fstop, stop_semi_diameter, film_z, sensor, zoom, coc, sq,
                                    wavelengths_nm, weights, aperture, film_from_analysis)
    if fstop is None:
        raise InputError(f"a {model.kind} camera needs the f-stop (fstop=...)")
    if stop_semi_diameter is not None or film_z is not None:
        raise InputError(f"a {model.kind} camera has no prescription: its iris and film are not placed by hand")
    n = require_f_number("f-stop", fstop)
    if mark == HYPERFOCAL:
        mark, solved = model.hyperfocal_mark(n, _coc_mm(sensor, coc)), (("focus", HYPERFOCAL),)
    return CameraState(model, mark, float(n), sensor, zoom, sq, iris_set=True, notes=tuple(notes), solved=solved)


def _squeeze(value) -> float:
    from ..errors import require_positive

    sq = require_positive("anamorphic squeeze", value, unit="")
    if not 0.1 <= sq <= 10.0:
        raise InputError(f"anamorphic squeeze must lie between 0.1 and 10, got {sq:g}")
    return sq


def _coc_mm(sensor, coc) -> float:
    """The circle of confusion (mm) of ``coc`` (a convention, a value, None: the default) on ``sensor``."""
    from .coc import circle_of_confusion

    if sensor is None:
        from ..data.default_sensor import DEFAULT_SENSOR_HEIGHT_MM, DEFAULT_SENSOR_WIDTH_MM

        return circle_of_confusion(DEFAULT_SENSOR_WIDTH_MM, DEFAULT_SENSOR_HEIGHT_MM, coc)[0]
    return circle_of_confusion(sensor.width_mm, sensor.height_mm, coc)[0]


def _prescription_camera(model: PrescriptionLens, mark, fstop, stop, film_z, sensor, zoom, coc, sq, wavelengths_nm,
                         weights, aperture, film_from_analysis) -> CameraState:
    """A prescription camera: the iris by the one rule, the focus solved once (the hyperfocal mark too)."""
    from . import paraxial

    lens = model.prescription
    if fstop is not None and stop is not None:
        raise InputError("give the stop as fstop or stop_semi_diameter, not both")
    iris_set = fstop is not None or stop is not None
    if stop is not None:
        stop = require_finite("stop semi-diameter", stop)
        if not stop > 0:
            raise InputError(f"the stop semi-diameter must be > 0 mm, got {stop:g}")
        inf = model.focus_state(math.inf)
        n = float(paraxial.gaussian(inf.prescription, object_z=inf.object_z, film_z=inf.film_z,
                                    stop_semi_diameter=stop).f_number)
    elif fstop is None:  # the lens as its file stops it
        stop = float(lens.surfaces[lens.stop_index].semi_diameter)
        try:
            n = float(paraxial.gaussian(lens).f_number)
        except OpticsError:  # an afocal lens (a plate under test) has no f-number: it is still traced
            n = math.inf
    else:
        n = float(require_f_number("f-stop", fstop))
        stop = float(model.iris(n))
    solved, notes = (), ()
    if mark == HYPERFOCAL:
        mark, solved = model.hyperfocal_mark(n, _coc_mm(sensor, coc)), (("focus", HYPERFOCAL),)
    if math.isinf(mark):  # the file's infinity focus, film at the paraxial image of an axial object at infinity
        focused, object_z = lens, -math.inf
        fz = require_finite("film plane z", film_z) if film_z is not None else _rear_focal_z(lens, film_from_analysis)
    else:
        st = model.focus_state(mark)
        focused, object_z, fz = st.prescription, float(st.object_z), float(st.film_z)
        if film_z is not None:
            fz = require_finite("film plane z", film_z)
    wls, ws = (tuple(v) for v in wavelengths_and_weights(lens, wavelengths_nm, weights))
    cam = CameraState(model, float(mark), n, sensor=sensor, zoom=zoom, squeeze=sq, stop_semi_diameter=float(stop),
                      object_z=object_z, film_z=fz, wavelengths_nm=wls, weights=ws, aperture=aperture,
                      iris_set=iris_set, film_from_analysis=film_from_analysis, notes=notes, solved=solved,
                      _focused=focused)
    if math.isfinite(object_z) and not object_z < cam.entrance_pupil_z:
        raise OpticsError(f"the object lies behind the entrance pupil of {lens.name!r}: no real pupil to sample")
    return cam


def _rear_focal_z(lens, film_from_analysis: bool):
    """The paraxial image of infinity (lens space); for an afocal lens left to the analysis (None)."""
    from . import paraxial

    try:
        return float(paraxial.gaussian(lens).z_rear_focal_point)
    except OpticsError:
        if film_from_analysis:
            return None
        raise


def as_camera_state(lens, *, focus_mm=None, fstop=None, **state) -> CameraState:
    """``lens`` as it is when it is a :class:`CameraState` (then ``focus_mm`` and ``fstop`` must be None:
    an InputError), or a lens through ``camera_state(lens, focus_mm=, fstop=, **state)``."""
    if isinstance(lens, CameraState):
        if focus_mm is not None or fstop is not None:
            raise InputError("a CameraState carries its own focus and f-stop: give them to camera_state(), not here")
        return lens
    return camera_state(lens, focus_mm=focus_mm, fstop=fstop, **state)


def _camera_at_the_door(value, given: dict, where: str) -> CameraState:
    """The camera of a function's first argument ``value`` and the camera keywords it was also given."""
    import warnings

    given = {k: v for k, v in given.items() if v is not None}
    if isinstance(value, CameraState):
        return _camera_and_keywords(value, given, where)
    if "focus_from_film_mm" in given:  # the focus mark's name before focus_mm
        if "focus_mm" in given:
            raise InputError("give focus_mm, not both focus_mm and focus_from_film_mm (its old name)")
        given["focus_mm"] = given.pop("focus_from_film_mm")
    model = lens_model_of(value)
    if given:
        # camera_state's own names: the sensor's two sizes are one sensor_mm=(width, height) there
        names = dict.fromkeys("sensor_mm" if k in ("sensor_width_mm", "sensor_height_mm") else k for k in given)
        words = ", ".join("sensor_mm=(width, height)" if k == "sensor_mm" else f"{k}=" for k in names)
        # given only as_designed's keywords (no focus, no film plane) the old form is the lens as its file focuses it
        import inspect

        door = "as_designed" if set(names) <= set(inspect.signature(as_designed).parameters) else "camera_state"
        warnings.warn(f"{where}(lens, {', '.join(f'{k}=' for k in given)}...) is now {where}({door}(lens, {words}...)): "
                      f"the camera is built once, at its door; the keywords go in physcam {UNTIL}",
                      DeprecationWarning, stacklevel=3)
    w, h = given.pop("sensor_width_mm", None), given.pop("sensor_height_mm", None)
    if (w is None) != (h is None):
        from ..data.default_sensor import DEFAULT_SENSOR_HEIGHT_MM, DEFAULT_SENSOR_WIDTH_MM

        w, h = (DEFAULT_SENSOR_WIDTH_MM if w is None else w), (DEFAULT_SENSOR_HEIGHT_MM if h is None else h)
    if w is not None:
        if "sensor_mm" in given or "sensor" in given:
            raise InputError("give the sensor once: sensor, sensor_mm or sensor_width_mm/sensor_height_mm")
        given["sensor_mm"] = (w, h)
    _corner_radius_given(given)
    return _camera(model, "focus_mm" not in given and "film_z" not in given, **given)


def _corner_radius_given(given: dict) -> None:
    """The old ray-level form (a prescription with ``stop_semi_diameter=`` and a bladed ``aperture=``) drew
    the polygon inside the radius it was given, its corners: the camera's iris is the round one of the
    polygon's area, that radius over ``aperture.equal_area_scale()`` (docs/conventions.md), so that
    :attr:`CameraState.iris_corner_semi` gives the corners back where they were."""
    ap, stop = given.get("aperture"), given.get("stop_semi_diameter")
    scale = getattr(ap, "equal_area_scale", None)
    if callable(scale) and not getattr(ap, "is_circular", True) and isinstance(stop, (int, float)) \
            and not isinstance(stop, bool) and math.isfinite(stop) and stop > 0:
        given["stop_semi_diameter"] = float(stop) / scale()


_SENSOR_WORDS = ("sensor", "sensor_mm", "sensor_width_mm", "sensor_height_mm")


def _camera_and_keywords(camera: CameraState, given: dict, where: str) -> CameraState:
    """A camera given with its pre-issue-43 keywords: its own focus and stop are an InputError; a sensor for a
    camera without one, or an iris shape, still go in (DeprecationWarning)."""
    import warnings

    owned = [k for k in given if k in ("focus_mm", "focus_from_film_mm", "film_z", "fstop", "stop_semi_diameter", "zoom")
             or (k in _SENSOR_WORDS and camera.sensor is not None)]
    if owned:
        what = [w for w, keys in (("focus", ("focus_mm", "focus_from_film_mm", "film_z", "zoom")), ("stop", ("fstop", "stop_semi_diameter")),
                                  ("sensor", _SENSOR_WORDS)) if any(k in keys for k in owned)]
        raise InputError(f"a CameraState carries its own {' and '.join(what)}: give {', '.join(owned)} to "
                         "camera_state() (or pass the lens itself), not here")
    if not given:
        return camera
    warnings.warn(f"{where}(camera, {', '.join(f'{k}=' for k in given)}...): give them to the camera "
                  f"(camera_state(..., sensor=..., aperture=...)); the keywords go in physcam {UNTIL}",
                  DeprecationWarning, stacklevel=4)
    if "aperture" in given:
        camera = camera.with_aperture(given.pop("aperture"))
    if given:
        w, h = given.pop("sensor_width_mm", None), given.pop("sensor_height_mm", None)
        if w is not None or h is not None:
            from ..data.default_sensor import DEFAULT_SENSOR_HEIGHT_MM, DEFAULT_SENSOR_WIDTH_MM

            given["sensor_mm"] = (DEFAULT_SENSOR_WIDTH_MM if w is None else w, DEFAULT_SENSOR_HEIGHT_MM if h is None else h)
        camera = replace(camera, sensor=_sensor_of(given.get("sensor"), given.get("sensor_mm")))
    return camera


def takes_camera(fn):
    """The one door (issue 43). Decorator: the function's first argument becomes a :class:`CameraState`
    before its body runs: a camera as it is; a lens model or a prescription built into one by
    :func:`camera_state` from the call's camera keywords (:data:`DOOR_KEYWORDS`: the old forms
    ``focus_mm=``, ``fstop=``, ``sensor_width_mm=`` ..., with a DeprecationWarning), or with none, the
    lens as its file focuses and stops it. A camera given with those keywords is an InputError (its
    own focus, stop and sensor); anything else first is a WrongTypeError with a sentence."""
    import inspect

    inner = inspect.unwrap(fn)
    first = inner.__code__.co_varnames[0]
    own = set(inspect.signature(inner).parameters)
    door = tuple(k for k in DOOR_KEYWORDS if k not in own)  # a keyword the function keeps is its own
    if own & (set(DOOR_KEYWORDS) - {"aperture"}):  # not yet through the door: the function builds its camera itself
        from ..lens.prescription import first_argument_checked

        return first_argument_checked(_require_camera)(fn)

    @functools.wraps(fn)
    def at_the_door(*args, **kwargs):
        if args:
            value, args = args[0], args[1:]
        elif first in kwargs:
            value = kwargs.pop(first)
        elif first == "camera" and "lens" in kwargs:  # the first parameter's pre-issue-43 name
            value = kwargs.pop("lens")
        else:
            raise WrongTypeError(f"{fn.__name__}() needs a camera first (physcam.optics.state.camera_state(lens, ...))")
        if not isinstance(value, CameraState):
            _require_lens(value, first)
        camera = _camera_at_the_door(value, {k: kwargs.pop(k) for k in door if k in kwargs}, fn.__name__)
        return fn(camera, *args, **kwargs)

    at_the_door.physcam_door = door
    return at_the_door


def _require_camera(value, name: str) -> None:
    if not isinstance(value, CameraState):
        _require_lens(value, name)


def _require_lens(value, name: str) -> None:
    if not isinstance(value, LensModel):
        from ..lens.prescription import Prescription

        require_type(name, value, Prescription,
                     "a CameraState (physcam.optics.state.camera_state(lens, focus_mm=..., fstop=...)) or a lens "
                     "(physcam.lens.library.load_lens(name or file))")

"""What the user asked the on-set lens report for, read and checked once at the door, as the camera
the report is a view of (issue 43).

Each front end (the CLI's ``report``, ``dof-table``, the exporters, ``serve``, the USD kits, the
OpenTrackIO recorder, the camera-metadata converter) hands what it was given to :func:`report_camera`,
which checks it (every check that needs no optics first, so a bad value is refused before any work
and with the same sentence everywhere) and returns the :class:`ReportInputs`: the camera (a lens
model focused and stopped; a focus or an f-stop solved from measured limits is solved here,
:mod:`physcam.onset.inverse`), the circle of confusion, the :class:`MeasuredLimits` and the
:class:`References` (figures from elsewhere the report compares or takes: a T-stop, a tape-measured
pupil, a best-match pinhole or an f-number at the focus recorded in a USD file). Then
``solve_report(inputs)``, or ``inputs.solve()``.

Distances measured on set (``focus_mm``, ``near_mm``, ``far_mm``, ``sensor_front_mm``) are from the
film plane; datasheet offsets (``h1_mm``, ``h2_mm``, ``pupil_mm``) are in front of
``reference_plane`` ("film", or "flange": ``flange_focal_distance_mm`` in front of the film)
(docs/conventions.md). :class:`ReportRequest`, the record of the same inputs before issue 43, answers
for one version (DeprecationWarning).
"""

from __future__ import annotations

import math
from types import SimpleNamespace
from typing import NamedTuple

from .._record import record
from ..errors import InputError, require_finite, require_positive, require_type
from ..optics.sensors import Sensor
from ..optics.state import HYPERFOCAL
from ..optics.thinlens import MAX_F_NUMBER, MIN_F_NUMBER, require_f_number, require_focal_length

__all__ = ["report_camera", "ReportInputs", "MeasuredLimits", "References", "ReportRequest", "INPUTS", "HYPERFOCAL",
           "DIFFRACTION_WAVELENGTH_NM", "MIN_F_NUMBER", "MAX_F_NUMBER", "MAX_DISTANCE_MM"]

#: Wavelength of the report's diffraction figures: 550 nm, near the peak of the eye's photopic
#: sensitivity (CIE V(lambda) peaks at 555 nm), the usual choice of diffraction-limit tables.
DIFFRACTION_WAVELENGTH_NM = 550.0
#: Largest finite distance the report accepts (1000 km); beyond it use infinity.
MAX_DISTANCE_MM = 1.0e9

#: What a front end may give :func:`report_camera`, and each default (the sensor is required).
INPUTS = dict(sensor=None, focal_length_mm=None, fstop=None, focus_mm=None, coc=None, near_mm=None, far_mm=None,
              tstop=None, squeeze=1.0, model="practical", h1_mm=None, h2_mm=None, pupil_mm=None,
              reference_plane="film", flange_focal_distance_mm=None, sensor_front_mm=None, lens_length_mm=None,
              pupil_fraction=0.4, lens_name=None, lens=None, pinhole_focal_length_mm=None, pinhole_squeeze=None,
              diffraction_wavelength_nm=DIFFRACTION_WAVELENGTH_NM, fstop_at_focus=None)


def require_distance(name: str, value) -> float:
    """A positive distance up to :data:`MAX_DISTANCE_MM` (mm), else InputError."""
    v = require_positive(name, value)
    if v > MAX_DISTANCE_MM:
        raise InputError(f"{name} {v:g} mm is beyond 1000 km; for a subject at infinity use a far limit of inf")
    return v


def require_focus(value) -> float:
    """A focus mark: a positive distance up to :data:`MAX_DISTANCE_MM`, or infinity."""
    if isinstance(value, (int, float)) and not isinstance(value, bool) and value == math.inf:
        return math.inf
    return require_distance("focus distance", value)


@record
class MeasuredLimits:
    """Near and far limits of acceptable sharpness measured on a plate (or wanted), from the film plane
    (mm; ``far_mm`` may be inf); either may be None."""

    near_mm: float | None = None
    far_mm: float | None = None

    def __post_init__(self):
        near, far = self.near_mm, self.far_mm
        if near is not None:
            near = require_distance("near limit", near)
        if far is not None:
            far = float(far)
            if math.isnan(far) or far <= 0:
                raise InputError(f"far limit must be a positive distance (or inf), got {self.far_mm!r}")
            far = require_distance("far limit", far) if math.isfinite(far) else far
        if near is not None and far is not None and not near < far:
            raise InputError(f"near limit {near:g} mm must be closer than far limit {far:g} mm")
        object.__setattr__(self, "near_mm", near)
        object.__setattr__(self, "far_mm", far)

    def __bool__(self) -> bool:
        return self.near_mm is not None or self.far_mm is not None


@record
class References:
    """Figures from outside the optics the report compares with or takes as given: the marked
    ``tstop``; a tape-measured entrance pupil (``sensor_front_mm`` from the film to the lens front,
    ``lens_length_mm``, the pupil ``pupil_fraction`` of the length behind the front); a best-match
    pinhole (``pinhole_focal_length_mm``, ``pinhole_squeeze``) and the f-number at the focus
    (``fstop_at_focus``) recorded elsewhere (a USD file); the wavelength of the diffraction figures."""

    tstop: float | None = None
    sensor_front_mm: float | None = None
    lens_length_mm: float | None = None
    pupil_fraction: float = 0.4
    pinhole_focal_length_mm: float | None = None
    pinhole_squeeze: float | None = None
    fstop_at_focus: float | None = None
    diffraction_wavelength_nm: float = DIFFRACTION_WAVELENGTH_NM


class ReportInputs(NamedTuple):
    """The report's inputs after the door: ``solve_report(inputs)`` takes them whole."""

    camera: object  # physcam.optics.state.CameraState
    coc: str | float | None = None
    measured: MeasuredLimits | None = None
    references: References | None = None


def report_camera(**inputs) -> ReportInputs:
    """Read and check the report's inputs (the keys of :data:`INPUTS`: a lens prescription or a focal
    length, the f-stop, the focus mark, the sensor, the CoC, measured near/far limits, the model and a
    datasheet's planes ...) and build the camera the report is a view of: focused at the mark (or the
    hyperfocal mark, or where measured limits put it), stopped to the f-stop (or the one measured limits
    need), on the sensor. InputError with a sentence for any bad value, before any optics."""
    return _camera_of(checked_inputs(inputs))


def checked_inputs(inputs: dict) -> SimpleNamespace:
    """The inputs with their defaults, read as written and checked (no optics): InputError."""
    unknown = sorted(set(inputs) - set(INPUTS))
    if unknown:
        raise TypeError(f"unexpected report input(s) {', '.join(unknown)}; the inputs are {', '.join(INPUTS)}")
    r = SimpleNamespace(**{**INPUTS, **inputs})
    if r.sensor is None:
        raise TypeError("the report needs a sensor (sensor=physcam.optics.sensors.find_sensor(name) or its name)")
    for check in (_read_as_written, _check_sensor_and_wavelength, _check_lens_or_datasheet, _check_stops, _check_distances,
                  _check_planes):
        for name, value in check(r).items():
            setattr(r, name, value)
    return r


def _at_hyperfocal(r) -> bool:
    return isinstance(r.focus_mm, str) and r.focus_mm == HYPERFOCAL


def _lens_model(r):
    """The lens model of the inputs: the prescription, a datasheet (technical) or a thin lens."""
    from ..optics.lens_model import Datasheet, PrescriptionLens, ThinLens, lens_model_of

    if r.lens is not None:
        return lens_model_of(r.lens) if r.lens_name is None else PrescriptionLens(r.lens, lens_name=r.lens_name)
    common = dict(squeeze=r.squeeze, lens_name=r.lens_name, pupil_mm=r.pupil_mm, reference_plane=r.reference_plane,
                  flange_focal_distance_mm=r.flange_focal_distance_mm)
    if r.model == "technical":
        return Datasheet(r.focal_length_mm, h1_mm=r.h1_mm, h2_mm=r.h2_mm, **common)
    return ThinLens(r.focal_length_mm, **common)


def _camera_of(r: SimpleNamespace) -> ReportInputs:
    """The camera of checked inputs (:func:`checked_inputs`), its focus or f-stop solved from measured limits."""
    from ..optics.state import camera_state
    from . import inverse

    model, notes = _lens_model(r), ()
    measured = MeasuredLimits(r.near_mm, r.far_mm) if r.near_mm is not None or r.far_mm is not None else None
    refs = References(r.tstop, r.sensor_front_mm, r.lens_length_mm, r.pupil_fraction, r.pinhole_focal_length_mm,
                      r.pinhole_squeeze, r.fstop_at_focus, r.diffraction_wavelength_nm)
    squeeze = None if r.lens is not None and r.squeeze == 1.0 else r.squeeze
    fstop = r.fstop
    if fstop is None and measured is None and r.lens is not None:  # the engraving, or slower
        fstop = model.wide_open()
        notes = (f"f-stop not given: wide open at f/{fstop:.3g}",)
    common = dict(sensor=r.sensor, coc=r.coc, squeeze=squeeze, n_ratio=_n_ratio(r))
    if measured is None and r.focus_mm is None:
        raise InputError("give a focus distance (--focus), or measured near and far limits (--near, --far), "
                         "or one limit with the f-stop")
    if fstop is None and measured is None and r.tstop is not None:  # notes that say "T2.8" and nothing else
        raise InputError(f"a T-stop alone (--tstop {r.tstop:g}) is not the f-stop depth of field needs: give "
                         f"--fstop too (the geometric f-number; with nothing better, --fstop {r.tstop:g} takes "
                         "the T-stop for it, as on-set calculators do, a little deeper than the true f-number)")
    if fstop is None and measured is None:
        raise InputError("give the f-stop (--fstop) or a measured near/far limit to solve it")
    if r.focus_mm is None:
        cam = inverse.focus_from_limits(model, near_mm=r.near_mm, far_mm=r.far_mm, fstop=fstop, **common)
    elif measured is not None and (fstop is None or r.coc is not None):
        cam = inverse.fstop_from_limits(model, focus_mm=r.focus_mm, near_mm=r.near_mm, far_mm=r.far_mm,
                                        marked_fstop=fstop, **common)
    else:
        cam = camera_state(model, focus_mm=r.focus_mm, fstop=fstop, sensor=r.sensor, coc=r.coc, squeeze=squeeze)
    if notes:
        from .._record import replace

        cam = replace(cam, notes=notes + cam.notes)
    return ReportInputs(cam, r.coc, measured, refs)


def _n_ratio(r) -> float:
    """The f-number at the focus over the f-stop, when the inputs say it (a USD file's), else 1."""
    return 1.0 if r.fstop_at_focus is None or r.fstop is None else r.fstop_at_focus / r.fstop


#: The request's distances, and whether each may be infinite: strings are read as the CLI reads them.
_DISTANCES = {"focal_length_mm": False, "focus_mm": True, "near_mm": False, "far_mm": True,
              "sensor_front_mm": False, "lens_length_mm": False}


def _read_as_written(r) -> dict:
    """What a person writes, read as the CLI reads it: a sensor name ("ALEXA 35"), distances with units
    ("2m", "10ft", "10'6\"", "infinity", "hyperfocal" for the focus). A number is millimetres; so is a bare
    number in a string (the Python API reads no user config)."""
    from ..units import parse_distance

    out = {}
    if isinstance(r.sensor, str):
        from ..optics.sensors import find_sensor

        out["sensor"] = find_sensor(r.sensor)
    for key, infinite in _DISTANCES.items():
        v = getattr(r, key)
        if not isinstance(v, str):
            continue
        if key == "focus_mm" and v.strip().lower() in (HYPERFOCAL, "hyper"):
            out[key] = HYPERFOCAL
        else:
            out[key] = parse_distance(v, name=key.removesuffix("_mm").replace("_", " "), allow_inf=infinite)
    return out


def _check_sensor_and_wavelength(r) -> dict:
    require_type("sensor", r.sensor, Sensor, "physcam.optics.sensors.find_sensor(name) or custom_sensor(w, h)")
    lam = require_positive("diffraction wavelength", r.diffraction_wavelength_nm, unit="nm")
    if not 200.0 <= lam <= 20000.0:
        raise InputError(f"diffraction wavelength must lie between 200 and 20000 nm, got {lam:g}")
    if r.sensor_front_mm is not None and r.lens_length_mm is None:
        raise InputError("the tape-measured sensor-to-lens-front distance needs the lens length too "
                         "(--lens-length): the pupil estimate sits a fraction of the lens length behind its front")
    if r.lens_length_mm is not None and r.sensor_front_mm is None:
        raise InputError("the lens length is used only with the sensor-to-lens-front distance (--sensor-front)")
    for name, v in (("sensor width", r.sensor.width_mm), ("sensor height", r.sensor.height_mm)):
        if not 0.0 < v <= 1000.0:
            raise InputError(f"{name} must lie between 0 and 1000 mm, got {v:g}")
    sq = require_positive("anamorphic squeeze", r.squeeze, unit="")
    if not 0.1 <= sq <= 10.0:
        raise InputError(f"anamorphic squeeze must lie between 0.1 and 10, got {sq:g}")
    return {"diffraction_wavelength_nm": lam, "squeeze": sq}


def _check_lens_or_datasheet(r) -> dict:
    """A prescription replaces the datasheet: refuse what would contradict it; else a focal length."""
    if r.lens is None:
        if r.focal_length_mm is None:
            raise InputError("give the focal length (--focal) or a lens (--lens)")
        return {"focal_length_mm": require_focal_length(r.focal_length_mm)}
    from ..lens.prescription import Prescription

    require_type("lens", r.lens, Prescription, "physcam.lens.library.load_lens(name or file)")
    given = [n for n, v in (("H1", r.h1_mm), ("H2", r.h2_mm), ("entrance pupil", r.pupil_mm),
                            ("sensor-to-lens-front distance", r.sensor_front_mm)) if v is not None]
    if given:
        raise InputError(f"with a lens prescription the principal planes and the pupil come from the lens; "
                         f"drop the {', '.join(given)} offset(s), or drop the lens to use a datasheet")
    if r.reference_plane != "film" or r.flange_focal_distance_mm is not None:
        raise InputError("with a lens prescription every plane is computed from the film; "
                         "the flange reference applies to datasheet offsets only")
    if r.focus_mm is None:
        raise InputError("with a lens prescription, give the focus mark (--focus)")
    for name, v in (("the f-number at the focus", r.fstop_at_focus),
                    ("the best-match pinhole", r.pinhole_focal_length_mm)):
        if v is not None:
            raise InputError(f"with a lens prescription {name} is computed from the lens")
    return {}


def _check_stops(r) -> dict:
    out = {}
    if r.model not in ("practical", "technical"):
        raise InputError(f"model must be 'practical' or 'technical', got {r.model!r}")
    if r.fstop is not None:
        out["fstop"] = require_f_number("f-stop", r.fstop)
    if r.fstop_at_focus is not None:
        if r.fstop is None:
            raise InputError("the f-number at the focus needs the f-stop it belongs to")
        out["fstop_at_focus"] = require_f_number("f-number at the focus", r.fstop_at_focus)
    if r.tstop is not None:
        out["tstop"] = require_f_number("T-stop", r.tstop)
    if r.pinhole_focal_length_mm is not None:
        out["pinhole_focal_length_mm"] = require_positive("pinhole focal length", r.pinhole_focal_length_mm)
        if r.pinhole_squeeze is not None:
            out["pinhole_squeeze"] = require_positive("pinhole squeeze", r.pinhole_squeeze, unit="")
    return out


def _check_distances(r) -> dict:
    out = {}
    limits = r.near_mm is not None or r.far_mm is not None
    if _at_hyperfocal(r) and (limits or (r.fstop is None and r.lens is None)):
        raise InputError("focus at the hyperfocal distance needs the f-stop (--fstop), and no measured near/far "
                         "limits (they solve the focus themselves)")
    if r.focus_mm is not None and not _at_hyperfocal(r):
        out["focus_mm"] = require_focus(r.focus_mm)
    limits = MeasuredLimits(r.near_mm, r.far_mm)
    out.update(near_mm=limits.near_mm, far_mm=limits.far_mm)
    return out


def _check_planes(r) -> dict:
    out = {}
    if r.reference_plane not in ("film", "flange"):
        raise InputError(f"reference plane must be 'film' or 'flange', got {r.reference_plane!r}")
    if r.reference_plane == "flange":
        if r.flange_focal_distance_mm is None:
            raise InputError("a flange reference needs the flange focal distance (e.g. 52 mm for PL, 44 mm for LPL)")
        out["flange_focal_distance_mm"] = require_positive("flange focal distance", r.flange_focal_distance_mm)
    if r.lens is not None:
        return out
    if r.model == "practical" and (r.h1_mm is not None or r.h2_mm is not None):
        raise InputError("principal-plane offsets (--h1/--h2) belong to the technical model: add --model technical")
    if r.pupil_mm is not None and r.sensor_front_mm is not None:
        raise InputError("give the entrance pupil either as a datasheet offset (--pupil) or as a tape-measure "
                         "estimate (--sensor-front/--lens-length), not both")
    if r.model == "technical" and (r.h1_mm is None or r.h2_mm is None):
        raise InputError("the technical model needs --h1 and --h2 (principal planes from the reference plane)")
    for key, name in (("h1_mm", "H1 offset"), ("h2_mm", "H2 offset"), ("pupil_mm", "entrance pupil offset")):
        if getattr(r, key) is not None:
            out[key] = require_finite(name, getattr(r, key))
    return out


class ReportRequest:
    """Deprecated (issue 43; goes in physcam 0.3): the report's inputs as one record. Use
    :func:`report_camera` (the same keywords), then ``solve_report(inputs)``, or build the camera
    yourself (:func:`physcam.optics.state.camera_state`) and call ``solve_report(camera, coc=...)``.

    Checked when it is made, as before; its inputs read as attributes (``request.focus_mm``)."""

    def __init__(self, **inputs):
        import warnings

        warnings.warn("ReportRequest(...) is now physcam.onset.request.report_camera(...) (the same keywords), or "
                      "solve_report(camera_state(lens, focus_mm=..., fstop=..., sensor=...), coc=...); ReportRequest "
                      "goes in physcam 0.3", DeprecationWarning, stacklevel=2)
        self.__dict__["_inputs"] = checked_inputs(inputs)
        self.__dict__["_made"] = None

    def __getattr__(self, name):
        try:
            return getattr(self.__dict__["_inputs"], name)
        except AttributeError:
            raise AttributeError(f"ReportRequest has no input {name!r}") from None

    def __setattr__(self, name, value):
        raise AttributeError("a ReportRequest is read-only")

    @property
    def at_hyperfocal(self) -> bool:
        return _at_hyperfocal(self._inputs)

    @classmethod
    def names(cls) -> tuple[str, ...]:
        return tuple(INPUTS)

    @property
    def inputs(self) -> ReportInputs:
        """The camera and the report's options these inputs make (built once)."""
        if self.__dict__["_made"] is None:
            self.__dict__["_made"] = _camera_of(self._inputs)
        return self.__dict__["_made"]

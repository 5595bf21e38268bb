"""What the user asked the on-set lens report for: a :class:`ReportRequest`, checked once at the door.

Each front end (the CLI's ``report``, ``dof-table``, the exporters, ``serve``, the USD kits, the
OpenTrackIO recorder) builds one request from its own input and hands it to
:func:`physcam.onset.report.solve_report`; every check that needs no optics happens here, when the
request is made, so a bad value is refused before any work and with the same sentence everywhere.

Distances measured on set (``focus_mm``, ``near_mm``, ``far_mm``, ``sensor_front_mm``) are from the
film plane; datasheet offsets (``h1_mm``, ``h2_mm``, ``pupil_mm``) are in front of
``reference_plane`` ("film", or "flange": ``flange_focal_distance_mm`` in front of the film)
(docs/conventions.md).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields

from ..errors import InputError, require_finite, require_positive, require_type
from ..optics.thinlens import MAX_F_NUMBER, MIN_F_NUMBER, require_f_number
from ..optics.sensors import Sensor

__all__ = ["ReportRequest", "HYPERFOCAL", "DIFFRACTION_WAVELENGTH_NM", "MIN_F_NUMBER", "MAX_F_NUMBER",
           "MAX_DISTANCE_MM"]

#: ``focus_mm=HYPERFOCAL``: focus at the hyperfocal distance of this lens, f-stop and CoC.
HYPERFOCAL = "hyperfocal"
#: Wavelength of the report's diffraction figures: 550 nm, near the peak of the eye's photopic
#: sensitivity (CIE V(lambda) peaks at 555 nm), the usual choice of diffraction-limit tables.
DIFFRACTION_WAVELENGTH_NM = 550.0
#: Largest finite distance the report accepts (1000 km); beyond it use infinity.
MAX_DISTANCE_MM = 1.0e9


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


@dataclass(frozen=True, kw_only=True)
class ReportRequest:
    """The lens report's inputs, as the user gave them (see the module notes for planes and units).

    ``lens`` (a :class:`~physcam.lens.prescription.Prescription`) replaces the datasheet: focal
    length, principal planes and pupil come from the lens focused at ``focus_mm``. ``fstop`` is the
    iris's setting (defined at infinity focus); ``fstop_at_focus`` the f-number at this focus when it
    is known from elsewhere (a USD file). ``pinhole_focal_length_mm``/``pinhole_squeeze``: a
    best-match pinhole known from elsewhere. Made once; checked on construction (InputError).
    """

    sensor: Sensor
    focal_length_mm: float | None = None
    fstop: float | None = None
    focus_mm: float | str | None = None
    coc: str | float | None = None
    near_mm: float | None = None
    far_mm: float | None = None
    tstop: float | None = None
    squeeze: float = 1.0
    model: str = "practical"
    h1_mm: float | None = None
    h2_mm: float | None = None
    pupil_mm: float | None = None
    reference_plane: str = "film"
    flange_focal_distance_mm: float | None = None
    sensor_front_mm: float | None = None
    lens_length_mm: float | None = None
    pupil_fraction: float = 0.4
    lens_name: str | None = None
    lens: object = None
    pinhole_focal_length_mm: float | None = None
    pinhole_squeeze: float | None = None
    diffraction_wavelength_nm: float = DIFFRACTION_WAVELENGTH_NM
    fstop_at_focus: float | None = None

    def __post_init__(self):
        for check in (_read_as_written, _check_sensor_and_wavelength, _check_lens_or_datasheet, _check_stops, _check_distances,
                      _check_planes):
            for name, value in check(self).items():
                object.__setattr__(self, name, value)

    @property
    def at_hyperfocal(self) -> bool:
        return isinstance(self.focus_mm, str) and self.focus_mm == HYPERFOCAL

    @classmethod
    def names(cls) -> tuple[str, ...]:
        return tuple(f.name for f in fields(cls))


#: The request's distances, and whether each may be infinite: strings are read as the CLI reads them.
_DISTANCES = {"focal_length_mm": False, "focus_mm": True, "near_mm": False, "far_mm": True,
              "sensor_front_mm": False, "lens_length_mm": False}


def _read_as_written(r: ReportRequest) -> dict:
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


def _check_sensor_and_wavelength(r: ReportRequest) -> dict:
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


def _check_lens_or_datasheet(r: ReportRequest) -> dict:
    """A prescription replaces the datasheet: refuse what would contradict it; else a focal length."""
    if r.lens is None:
        if r.focal_length_mm is None:
            raise InputError("give the focal length (--focal) or a lens (--lens)")
        f = require_positive("focal length", r.focal_length_mm)
        if f > 1.0e5:
            raise InputError(f"focal length {f:g} mm is beyond any camera lens; give it in mm (e.g. --focal 50)")
        return {"focal_length_mm": f}
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


def _check_stops(r: ReportRequest) -> dict:
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


def _check_distances(r: ReportRequest) -> dict:
    out = {}
    limits = r.near_mm is not None or r.far_mm is not None
    if r.at_hyperfocal and (limits or (r.fstop is None and r.lens is None)):
        raise InputError("focus at the hyperfocal distance needs the f-stop (--fstop), and no measured near/far "
                         "limits (they solve the focus themselves)")
    if r.focus_mm is not None and not r.at_hyperfocal:
        out["focus_mm"] = require_focus(r.focus_mm)
    if r.near_mm is not None:
        out["near_mm"] = require_distance("near limit", r.near_mm)
    if r.far_mm is not None:
        far = float(r.far_mm)
        if math.isnan(far) or far <= 0:
            raise InputError(f"far limit must be a positive distance (or inf), got {r.far_mm!r}")
        out["far_mm"] = require_distance("far limit", far) if math.isfinite(far) else far
    near, far = out.get("near_mm"), out.get("far_mm")
    if near is not None and far is not None and not near < far:
        raise InputError(f"near limit {near:g} mm must be closer than far limit {far:g} mm")
    return out


def _check_planes(r: ReportRequest) -> dict:
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

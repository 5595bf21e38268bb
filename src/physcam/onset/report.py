"""The on-set lens report: one solver, two models, forward and inverse inputs.

*Practical* model: a thin lens (H1 = H2) whose principal plane sits s' in front of
the film, so a focus mark D (film plane to subject) is s + s' = D, not s = D
(docs/conventions.md; seed 000's "s = marked distance" is corrected here).
*Technical* model: datasheet principal planes H1, H2 (and the entrance pupil) given
as distances in front of a reference plane (the film, or the lens flange with its
flange focal distance): s = D - H1; the image then forms s' behind H2, and the report
gives the focus error (where the sharp image lies relative to the film).

Depth of field uses the exact thin-lens forms (physcam.optics.dof) about H1 and is
reported both from H1 and from the film plane. Inputs may be forward (f-stop, CoC)
or inverse (near and/or far limits measured on a plate), in which case the report
solves the effective f-stop, the CoC or the focus distance, and says what it solved.

The focus may be infinite (``math.inf``: the far limit is infinite and the near limit is the
hyperfocal parameter h = f^2/(N c) from H1) or :data:`HYPERFOCAL` (the mark that puts the
subject plane at the hyperfocal distance H = h + f from H1, near limit H/2).

Magnification is the signed lateral magnification m = image height / object height, negative
for the inverted real image on the film (docs/conventions.md), as the Gaussian engine gives it.

Diffraction: the Airy disk's diameter to its first dark ring, 2.44 lambda N_w (Born & Wolf,
*Principles of Optics*, 8.5.2), with N_w the working f-number N (1 + m) at the focus (the
pupils taken as equal; a prescription gives its own paraxial working f-number), compared with
the CoC and the sensor's photosite pitch, and the f-stop past which the Airy disk is larger
than the CoC: N = c / (2.44 lambda (N_w / N)). Scalars only (no numpy), like the rest.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import lru_cache

from ..errors import InputError, OpticsError, require_finite, require_positive
from ..optics import _num
from ..optics import dof as _dof
from ..optics import thinlens
from ..optics.coc import circle_of_confusion
from .pupil import entrance_pupil_practical, pivot_camera_space
from .sensors import Sensor

__all__ = ["LensReport", "DepthOfField", "solve_lens_report", "takes_report", "REPORT_SCHEMA", "REPORT_VERSION",
           "HYPERFOCAL", "DIFFRACTION_WAVELENGTH_NM", "airy_diameter_mm", "fstop_airy_equals"]

#: Real (chief-ray) and pinhole fields of view may differ by this much (percent, any of horizontal,
#: vertical, diagonal) before the report warns: about what a fitted two-term radial distortion
#: model on the render camera still corrects (dgauss.50mm, barrel: 1.0 % h, 1.5 % d).
REAL_FOV_TOLERANCE_PCT = 2.0

REPORT_SCHEMA = "physcam.lens_report"
#: 2: adds ``diffraction`` and ``sensor.photosite_pitch_mm`` (every key of version 1 kept).
#: 3: magnification is signed (negative: the inverted image); a focus at infinity is null with
#: ``focus_is_infinite``, as is the object distance (issue 15).
REPORT_VERSION = 3
#: ``focus_mm=HYPERFOCAL``: focus at the hyperfocal distance of this lens, f-stop and CoC.
HYPERFOCAL = "hyperfocal"
#: Wavelength of the report's diffraction figures: 550 nm, near the peak of the eye's photopic
#: sensitivity (CIE V(lambda) peaks at 555 nm), the usual choice of diffraction-limit tables.
DIFFRACTION_WAVELENGTH_NM = 550.0
#: The Airy disk's diameter to its first dark ring is AIRY_FACTOR lambda N (2 x 1.22).
AIRY_FACTOR = 2.44


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
            "far_mm": _finite_or_none(self.far_mm),
            "total_mm": _finite_or_none(self.total_mm),
            "near_from_film_mm": self.near_from_film_mm,
            "far_from_film_mm": _finite_or_none(self.far_from_film_mm),
            "far_is_infinite": self.far_is_infinite,
        }


#: The fastest f-number a lens in air can have: N = 1 / (2 n' sin u') with sin u' <= 1 and n' = 1
#: (Abbe sine condition; Kingslake & Johnson, *Lens Design Fundamentals*, 2nd ed., 4.3).
MIN_F_NUMBER = 0.5
#: The slowest f-number accepted: pinhole cameras reach f/500 or so; beyond f/4096 a typo is likelier.
MAX_F_NUMBER = 4096.0


def _require_f_number(name: str, value) -> float:
    """``value`` as a float between :data:`MIN_F_NUMBER` and :data:`MAX_F_NUMBER`, else InputError."""
    v = require_positive(name, value, unit="")
    if not MIN_F_NUMBER <= v <= MAX_F_NUMBER:
        why = ("no lens in air is faster than f/0.5 (N = 1 / (2 sin u'), sin u' <= 1)" if v < MIN_F_NUMBER
               else f"f-numbers above {MAX_F_NUMBER:g} are not camera apertures")
        raise InputError(f"{name} {v:g} is out of range: {why}")
    return v


def _finite_or_none(v: float | None):
    return None if v is None or math.isinf(v) else v


def airy_diameter_mm(working_f_number, wavelength_nm=DIFFRACTION_WAVELENGTH_NM) -> float:
    """Diameter (mm) of the Airy disk to its first dark ring: 2.44 lambda N_w (Born & Wolf, 8.5.2)."""
    n = require_positive("working f-number", working_f_number, unit="")
    lam = require_positive("wavelength", wavelength_nm, unit="nm")
    return _num.out(AIRY_FACTOR * lam * 1e-6 * n, what="the Airy diameter")


def fstop_airy_equals(size_mm, wavelength_nm=DIFFRACTION_WAVELENGTH_NM, bellows_factor=1.0) -> float:
    """The f-stop N whose Airy disk (at working f-number N x ``bellows_factor``) is ``size_mm`` across:
    past it diffraction blurs more than ``size_mm`` (a CoC, two photosites)."""
    c = require_positive("size", size_mm)
    lam = require_positive("wavelength", wavelength_nm, unit="nm")
    k = require_positive("bellows factor", bellows_factor, unit="")
    airy_per_stop = AIRY_FACTOR * lam * 1e-6 * k  # mm of Airy disk per unit of f-number
    if airy_per_stop == 0.0:  # the wavelength times the bellows factor underflowed a float
        raise OpticsError(f"a wavelength of {wavelength_nm} nm (x bellows {bellows_factor}) is too small "
                          "for a float: no f-stop makes its Airy disk the given size")
    return _num.out(c / airy_per_stop, what="the f-stop whose Airy disk equals the size")


@dataclass(frozen=True)
class LensReport:
    """Everything the lens report knows. Lengths in mm, angles in degrees.

    Positions are distances in front of the film plane (``*_from_film_mm``) unless the
    name says otherwise; ``object_distance_mm`` is from H1, ``image_distance_mm`` from H2.
    """

    model: str
    focal_length_mm: float
    fstop: float
    sensor: Sensor
    squeeze: float
    coc_mm: float
    coc_convention: str
    focus_from_film_mm: float
    object_distance_mm: float
    image_distance_mm: float
    h1_from_film_mm: float
    h2_from_film_mm: float
    focus_error_mm: float
    magnification: float
    dof: DepthOfField
    dof_horizontal: DepthOfField | None
    hfov_inf_deg: float
    vfov_inf_deg: float
    dfov_inf_deg: float
    hfov_focus_deg: float
    vfov_focus_deg: float
    dfov_focus_deg: float
    entrance_pupil_from_film_mm: float | None
    entrance_pupil_source: str
    solved: dict = field(default_factory=dict)
    measured: dict = field(default_factory=dict)
    notes: tuple[str, ...] = ()
    lens_name: str | None = None
    reference_plane: str = "film"
    flange_focal_distance_mm: float | None = None
    tstop: float | None = None
    #: the best-match pinhole: a pinhole at the entrance pupil with this focal length (and the
    #: horizontal aperture widened by ``pinhole_squeeze``) frames like the lens at this focus.
    #: None means the thin-lens value, the distance from H2 to the film.
    pinhole_focal_length_mm: float | None = None
    pinhole_squeeze: float | None = None
    #: with a prescription: the field of view of real chief rays from the film edge, top and corner
    #: (:func:`physcam.analysis.field_of_view.real_field_of_view`, as its ``to_dict``), beside the
    #: paraxial pinhole's; None for the thin-lens and datasheet models.
    real_fov: dict | None = None
    #: the physical aperture stop (iris) in front of the film: a prescription's stop surface; the
    #: lens plane for the thin lens; None when a datasheet does not say
    stop_from_film_mm: float | None = None
    #: width over height of a defocused point's blur in the desqueezed picture: the entrance
    #: pupil's X over Y diameter (object-space blur angles scale with it); 1 for a spherical lens,
    #: 1 / squeeze for a thin lens given a squeeze (a front anamorphic's cylinders narrow the pupil in X)
    dof_aspect: float = 1.0
    #: wavelength (nm) of the diffraction figures
    diffraction_wavelength_nm: float = DIFFRACTION_WAVELENGTH_NM
    #: working over geometric f-number at this focus: a prescription's paraxial ratio; None: 1 + m
    #: (pupils taken as equal)
    bellows_factor: float | None = None
    #: the f-number at this focus for the iris set to ``fstop`` at infinity (see f_number_at_focus);
    #: None: ``fstop`` (no focusing changes it)
    fstop_at_focus: float | None = None

    # --- convenience --------------------------------------------------------
    @property
    def real_fov_differs(self) -> bool:
        """True when distortion makes the pinhole's field of view wrong by more than
        :data:`REAL_FOV_TOLERANCE_PCT` in some direction, or the sensor is not covered."""
        if not self.real_fov:
            return False
        diffs = [self.real_fov.get(f"{k}_difference_pct") for k in ("horizontal", "vertical", "diagonal")]
        return any(d is None or abs(d) > REAL_FOV_TOLERANCE_PCT for d in diffs)

    @property
    def pinhole(self) -> tuple[float, float]:
        """(focal length mm, squeeze) of the best-match pinhole (see the field notes)."""
        f = self.h2_from_film_mm if self.pinhole_focal_length_mm is None else self.pinhole_focal_length_mm
        return f, (self.squeeze if self.pinhole_squeeze is None else self.pinhole_squeeze)

    @property
    def aperture_diameter_mm(self) -> float:
        """Entrance-pupil diameter at this focus, f / N at focus (:attr:`fstop_at_focus`)."""
        return self.focal_length_mm / self.f_number_at_focus

    @property
    def f_number_at_focus(self) -> float:
        """EFL over entrance-pupil diameter at this focus, with the iris set to ``fstop`` at infinity: the
        f-number depth of field uses. ``fstop`` itself for a thin lens, a datasheet or a unit-focusing
        lens; an internal-focus prescription's own (physcam.optics.focusing.f_number_ratio)."""
        return self.fstop if self.fstop_at_focus is None else self.fstop_at_focus

    @property
    def pivot_camera_space_mm(self):
        """The parallax-free pivot in camera space (mm), or None when no pupil is known."""
        if self.entrance_pupil_from_film_mm is None:
            return None
        return pivot_camera_space(self.entrance_pupil_from_film_mm)

    @property
    def desqueezed_width_mm(self) -> float:
        return self.sensor.width_mm * self.squeeze

    @property
    def focus_is_infinite(self) -> bool:
        return math.isinf(self.focus_from_film_mm)

    # --- diffraction ------------------------------------------------------------
    @property
    def working_f_number(self) -> float:
        """N_w = N x (the bellows factor, or 1 + m)."""
        k = self.bellows_factor if self.bellows_factor is not None else 1.0 + abs(self.magnification)
        return self.fstop * k

    @property
    def airy_diameter_mm(self) -> float:
        """The Airy disk's diameter (first dark ring) on the film at the working f-number."""
        return airy_diameter_mm(self.working_f_number, self.diffraction_wavelength_nm)

    @property
    def fstop_airy_exceeds_coc(self) -> float:
        """The f-stop past which the Airy disk is larger than the circle of confusion."""
        return fstop_airy_equals(self.coc_mm, self.diffraction_wavelength_nm, self.working_f_number / self.fstop)

    def diffraction_dict(self) -> dict:
        pitch = self.sensor.pitch_um
        k = self.working_f_number / self.fstop
        airy = self.airy_diameter_mm
        p_mm = None if pitch is None else pitch * 1e-3
        return {
            "wavelength_nm": self.diffraction_wavelength_nm,
            "working_f_number": self.working_f_number,
            "airy_diameter_mm": airy,
            "coc_mm": self.coc_mm,
            "airy_to_coc": airy / self.coc_mm,
            "exceeds_coc": airy > self.coc_mm,
            "fstop_airy_exceeds_coc": self.fstop_airy_exceeds_coc,
            "photosite_pitch_mm": p_mm,
            "airy_in_photosites": None if p_mm is None else airy / p_mm,
            "fstop_airy_exceeds_two_photosites": None if p_mm is None else fstop_airy_equals(
                2 * p_mm, self.diffraction_wavelength_nm, k),
            "definition": "Airy diameter to the first dark ring, 2.44 lambda N_w; N_w the working f-number at "
                          "this focus (N (1 + m), or a prescription's own); fstop_airy_exceeds_coc: the f-stop past "
                          "which it is larger than the CoC; photosite pitch from the sensor table (null: unknown)",
        }

    def diffraction_note(self) -> str:
        d = self.diffraction_dict()
        um = 1000.0
        text = (f"diffraction ({d['wavelength_nm']:g} nm): Airy disk {d['airy_diameter_mm'] * um:.1f} um across at "
                f"f/{self.fstop:.3g} (working f/{d['working_f_number']:.3g}), {d['airy_to_coc']:.2f} of the CoC "
                f"({self.coc_mm * um:.1f} um)")
        if d["photosite_pitch_mm"] is not None:
            text += f" and {d['airy_in_photosites']:.1f} photosites ({d['photosite_pitch_mm'] * um:.2f} um)"
        verb = "exceeds" if d["exceeds_coc"] else "would exceed"
        return text + f"; it {verb} the CoC past f/{d['fstop_airy_exceeds_coc']:.3g}"

    def to_dict(self) -> dict:
        """Versioned, JSON-ready dict with stable keys; infinities become null plus a flag."""
        s = self.sensor
        return {
            "schema": REPORT_SCHEMA,
            "version": REPORT_VERSION,
            "units": {"length": "mm", "angle": "degree"},
            "reference": "distances *_from_film_mm are in front of the film plane; object distance from H1, "
            "image distance from H2",
            "model": self.model,
            "lens": self.lens_name,
            "focal_length_mm": self.focal_length_mm,
            "fstop": self.fstop,
            "tstop": self.tstop,
            "aperture_diameter_mm": self.aperture_diameter_mm,
            "fstop_at_focus": self.f_number_at_focus,
            "squeeze": self.squeeze,
            "sensor": {
                "key": s.key,
                "name": s.name,
                "width_mm": s.width_mm,
                "height_mm": s.height_mm,
                "diagonal_mm": s.diagonal_mm,
                "photosite_pitch_mm": None if s.pitch_um is None else s.pitch_um * 1e-3,
            },
            "coc_mm": self.coc_mm,
            "coc_convention": self.coc_convention,
            "focus_from_film_mm": _finite_or_none(self.focus_from_film_mm),
            "focus_is_infinite": self.focus_is_infinite,
            "object_distance_mm": _finite_or_none(self.object_distance_mm),
            "image_distance_mm": self.image_distance_mm,
            "h1_from_film_mm": self.h1_from_film_mm,
            "h2_from_film_mm": self.h2_from_film_mm,
            "reference_plane": self.reference_plane,
            "flange_focal_distance_mm": self.flange_focal_distance_mm,
            "focus_error_mm": self.focus_error_mm,
            "magnification": self.magnification,
            "dof": self.dof.to_dict(),
            "dof_horizontal": None if self.dof_horizontal is None else self.dof_horizontal.to_dict(),
            "pinhole": {"focal_length_mm": self.pinhole[0], "squeeze": self.pinhole[1],
                        "definition": "the pinhole at the entrance pupil that frames like the lens at this focus: "
                                      "f = (exit pupil to film) / pupil magnification; s' for a thin lens"},
            "fov_deg": {
                "infinity": {"horizontal": self.hfov_inf_deg, "vertical": self.vfov_inf_deg,
                             "diagonal": self.dfov_inf_deg},
                "focus": {"horizontal": self.hfov_focus_deg, "vertical": self.vfov_focus_deg,
                          "diagonal": self.dfov_focus_deg},
                "definition": "infinity and focus: the paraxial (pinhole) field; real: chief rays traced through "
                              "the prescription from the film edge, top and corner (null where not covered)",
                "real": None if self.real_fov is None else {
                    "horizontal": self.real_fov["horizontal_deg"], "vertical": self.real_fov["vertical_deg"],
                    "diagonal": self.real_fov["diagonal_deg"],
                    "difference_pct": {k: self.real_fov[f"{k}_difference_pct"]
                                       for k in ("horizontal", "vertical", "diagonal")},
                    "not_covered": list(self.real_fov["not_covered"]), "reason": self.real_fov["reason"]},
                "real_differs": self.real_fov_differs,
            },
            "entrance_pupil_from_film_mm": self.entrance_pupil_from_film_mm,
            "stop_from_film_mm": self.stop_from_film_mm,
            "dof_aspect": self.dof_aspect,
            "entrance_pupil_source": self.entrance_pupil_source,
            "pivot_camera_space_mm": None if self.pivot_camera_space_mm is None else list(self.pivot_camera_space_mm),
            "solved": dict(self.solved),
            "measured": {k: _finite_or_none(v) if isinstance(v, float) else v for k, v in self.measured.items()},
            "notes": list(self.notes),
            "diffraction": self.diffraction_dict(),
        }


# --------------------------------------------------------------------------------------
def _fov_deg(size, focal_or_image_distance):
    return math.degrees(2.0 * math.atan(size / (2.0 * focal_or_image_distance)))


def _dof_block(f, n, c, s, h1_film_at) -> DepthOfField:
    """DOF for object distance s (from H1, may be infinite); ``h1_film_at(s)`` gives H1's distance
    from the film."""
    near, far = _dof.dof_limits(f, n, c, s)
    H = _dof.hyperfocal_distance(f, n, c)
    return DepthOfField(
        coc_mm=c,
        hyperfocal_mm=H,
        hyperfocal_from_film_mm=H + h1_film_at(H),
        near_mm=near,
        far_mm=far,
        near_from_film_mm=near + h1_film_at(s),
        far_from_film_mm=far + h1_film_at(s),
    )


def solve_lens_report(
    *,
    focal_length_mm: float,
    sensor: Sensor,
    fstop: float | None = None,
    focus_mm: float | None = None,
    coc: str | float | None = None,
    near_mm: float | None = None,
    far_mm: float | None = None,
    tstop: float | None = None,
    squeeze: float = 1.0,
    model: str = "practical",
    h1_mm: float | None = None,
    h2_mm: float | None = None,
    pupil_mm: float | None = None,
    reference_plane: str = "film",
    flange_focal_distance_mm: float | None = None,
    sensor_front_mm: float | None = None,
    lens_length_mm: float | None = None,
    pupil_fraction: float = 0.4,
    lens_name: str | None = None,
    lens=None,
    pinhole_focal_length_mm: float | None = None,
    pinhole_squeeze: float | None = None,
    diffraction_wavelength_nm: float = DIFFRACTION_WAVELENGTH_NM,
    fstop_at_focus: float | None = None,
) -> LensReport:
    """Solve the lens report.

    Distances measured on set (``focus_mm``, ``near_mm``, ``far_mm``, ``sensor_front_mm``)
    are from the film plane. Technical offsets (``h1_mm``, ``h2_mm``, ``pupil_mm``) are
    in front of ``reference_plane`` ("film" or "flange"; the flange lies
    ``flange_focal_distance_mm`` in front of the film).

    Solving rules: with a near and/or far limit measured, the report solves the focus
    (when ``focus_mm`` is missing), then the effective f-stop (when ``fstop`` is missing,
    or when both fstop and an explicit ``coc`` are given) or else the CoC. Without
    measured limits it is a forward report and ``fstop`` is required.

    ``pinhole_focal_length_mm`` (and ``pinhole_squeeze``): the best-match pinhole when it is known
    from elsewhere (a USD file written from a prescription); by default it is computed (see
    :attr:`LensReport.pinhole`).

    ``lens`` (a :class:`~physcam.lens.prescription.Prescription`) fills the technical
    model from the lens itself: its Gaussian engine, focused at ``focus_mm`` (unit or
    internal focusing), gives the effective focal length, H1, H2 and the entrance pupil
    in front of the film, so no datasheet is needed; ``focal_length_mm`` may then be None
    and ``fstop`` defaults to the lens's maximum aperture.

    ``diffraction_wavelength_nm`` (default 550): the wavelength of the diffraction figures
    (Airy disk against the CoC and the photosite pitch; see the module notes).

    The f-stop is the iris's setting, defined at infinity focus (one rule for every consumer:
    :func:`physcam.optics.focusing.iris_semi_diameter`). Depth of field uses the f-number at the
    focus (:attr:`LensReport.f_number_at_focus`): an internal-focus prescription's own, or
    ``fstop_at_focus`` when it is known from elsewhere (a USD file written from a prescription).
    """
    notes: list[str] = []
    pupil_origin = "datasheet"
    lam_diff = require_positive("diffraction wavelength", diffraction_wavelength_nm, unit="nm")
    if not 200.0 <= lam_diff <= 20000.0:
        raise InputError(f"diffraction wavelength must lie between 200 and 20000 nm, got {lam_diff:g}")
    bellows = None
    lens_pinhole = None  # (Y, X) best-match pinhole focal lengths from a prescription
    n_ratio = 1.0  # f-number at this focus over the iris's f-stop (internal focusing)
    from ..errors import require_type

    require_type("sensor", sensor, Sensor, "physcam.onset.sensors.find_sensor(name) or custom_sensor(w, h)")
    if sensor_front_mm is not None and lens_length_mm is None:
        raise InputError("the tape-measured sensor-to-lens-front distance needs the lens length too "
                         "(--lens-length): the pupil estimate sits a fraction of the lens length behind its front")
    if lens_length_mm is not None and sensor_front_mm is None:
        raise InputError("the lens length is used only with the sensor-to-lens-front distance (--sensor-front)")
    squeeze_from_lens = False
    if lens is not None:
        from ..lens.prescription import Prescription

        require_type("lens", lens, Prescription, "physcam.lens.library.load_lens(name or file)")
        given = [n for n, v in (("H1", h1_mm), ("H2", h2_mm), ("entrance pupil", pupil_mm),
                                ("sensor-to-lens-front distance", sensor_front_mm)) if v is not None]
        if given:
            raise InputError(f"with a lens prescription the principal planes and the pupil come from the lens; "
                             f"drop the {', '.join(given)} offset(s), or drop the lens to use a datasheet")
        if reference_plane != "film" or flange_focal_distance_mm is not None:
            raise InputError("with a lens prescription every plane is computed from the film; "
                             "the flange reference applies to datasheet offsets only")
        pupil_origin = "prescription"
        from ..optics.focusing import technical_planes

        from ..optics import focusing, paraxial

        if focus_mm is None:
            raise InputError("with a lens prescription, give the focus mark (--focus)")
        if fstop is None and near_mm is None and far_mm is None:
            # wide open: the engraved f-stop, unless the prescription's stop is slower
            file_n = paraxial.gaussian(lens).f_number
            fstop = max(file_n, lens.metadata.max_fstop or 0.0)
            notes.append(f"f-stop not given: wide open at f/{fstop:.3g}")
        if focus_mm == HYPERFOCAL:
            D_lens, planes = _lens_hyperfocal(lens, fstop, sensor, coc, near_mm, far_mm)
        else:
            D_lens = _require_focus(focus_mm)
            planes = technical_planes(lens, D_lens, fstop=fstop)
        focus_mm = D_lens
        focal_length_mm = planes.efl_mm
        model, reference_plane = "technical", "film"
        h1_mm, h2_mm, pupil_mm = planes.h1_from_film_mm, planes.h2_from_film_mm, planes.entrance_pupil_from_film_mm
        lens_name = lens_name or lens.name
        notes.append(
            f"planes from the prescription focused at the mark ({planes.method} focusing): EFL {planes.efl_mm:.3f} mm, "
            f"back focus {planes.back_focus_mm:.3f} mm"
        )
        lens_pinhole = (planes.pinhole_focal_length_mm, planes.pinhole_focal_length_mm)
        lens_stop = planes.stop_from_film_mm
        n_ratio = focusing.f_number_ratio(lens, D_lens)
        # the blur's width over height on the film, desqueezed by the lens's own squeeze: 1 for a
        # spherical lens; an anamorphic's entrance pupil X over Y (see _pupil_aspect)
        lens_dof_aspect, lens_squeeze = 1.0, 1.0
        bellows = planes.working_f_number / planes.f_number * n_ratio  # working f-number over the f-stop
        if lens.is_anamorphic:
            # the squeeze the lens really has at this focus: EFL in Y over EFL in X
            st = focusing.focus(lens, D_lens)
            gx = paraxial.gaussian(st.prescription, axis="x", object_z=st.object_z, film_z=st.film_z)
            lens_squeeze = planes.efl_mm / gx.efl
            lens_dof_aspect = _pupil_aspect(lens, D_lens)
        if lens.is_anamorphic and squeeze == 1.0:
            squeeze_from_lens = True
            efl_x = gx.efl
            squeeze = lens_squeeze
            lens_pinhole = (planes.pinhole_focal_length_mm, gx.pinhole_focal_length)
            notes.append(
                f"anamorphic: EFL {planes.efl_mm:.3f} mm (Y) and {efl_x:.3f} mm (X), effective squeeze "
                f"{squeeze:.4f} (nominal {lens.squeeze:g})"
            )
    if focal_length_mm is None:
        raise InputError("give the focal length (--focal) or a lens (--lens)")
    f = require_positive("focal length", focal_length_mm)
    if f > 1.0e5:
        raise InputError(f"focal length {f:g} mm is beyond any camera lens; give it in mm (e.g. --focal 50)")
    sq = require_positive("anamorphic squeeze", squeeze, unit="")
    if not 0.1 <= sq <= 10.0:
        raise InputError(f"anamorphic squeeze must lie between 0.1 and 10, got {sq:g}")
    for name, v in (("sensor width", sensor.width_mm), ("sensor height", sensor.height_mm)):
        if not 0.0 < v <= 1000.0:
            raise InputError(f"{name} must lie between 0 and 1000 mm, got {v:g}")
    if model not in ("practical", "technical"):
        raise InputError(f"model must be 'practical' or 'technical', got {model!r}")
    w, h = sensor.width_mm, sensor.height_mm
    coc_explicit = coc is not None
    c, coc_name = circle_of_confusion(w, h, coc)
    c, coc_name = _named_coc(w, h, coc, c, coc_name)
    N = None if fstop is None else _require_f_number("f-stop", fstop)
    if fstop_at_focus is not None:
        if lens is not None:
            raise InputError("with a lens prescription the f-number at the focus is computed from the lens")
        if N is None:
            raise InputError("the f-number at the focus needs the f-stop it belongs to")
        n_ratio = _require_f_number("f-number at the focus", fstop_at_focus) / N
    T = None if tstop is None else _require_f_number("T-stop", tstop)
    hyperfocal = focus_mm == HYPERFOCAL
    if hyperfocal and (N is None or near_mm is not None or far_mm is not None):
        raise InputError("focus at the hyperfocal distance needs the f-stop (--fstop), and no measured near/far "
                         "limits (they solve the focus themselves)")
    D = None if (focus_mm is None or hyperfocal) else _require_focus(focus_mm)
    near_m = None if near_mm is None else _require_distance("near limit", near_mm)
    far_m = None
    if far_mm is not None:
        far_m = float(far_mm)
        if math.isnan(far_m) or far_m <= 0:
            raise InputError(f"far limit must be a positive distance (or inf), got {far_mm!r}")
        if math.isfinite(far_m):
            far_m = _require_distance("far limit", far_m)
    if near_m is not None and far_m is not None and not near_m < far_m:
        raise InputError(f"near limit {near_m:g} mm must be closer than far limit {far_m:g} mm")

    # --- where H1, H2 and the pupil sit, and how a mark maps to s --------------------
    ffd = None
    if reference_plane not in ("film", "flange"):
        raise InputError(f"reference plane must be 'film' or 'flange', got {reference_plane!r}")
    if reference_plane == "flange":
        if flange_focal_distance_mm is None:
            raise InputError("a flange reference needs the flange focal distance (e.g. 52 mm for PL, 44 mm for LPL)")
        ffd = require_positive("flange focal distance", flange_focal_distance_mm)
    ref = ffd or 0.0

    if model == "practical" and (h1_mm is not None or h2_mm is not None):
        raise InputError("principal-plane offsets (--h1/--h2) belong to the technical model: add --model technical")
    if pupil_mm is not None and sensor_front_mm is not None:
        raise InputError("give the entrance pupil either as a datasheet offset (--pupil) or as a tape-measure "
                         "estimate (--sensor-front/--lens-length), not both")
    if model == "technical":
        if h1_mm is None or h2_mm is None:
            raise InputError("the technical model needs --h1 and --h2 (principal planes from the reference plane)")
        P1 = ref + require_finite("H1 offset", h1_mm)
        P2 = ref + require_finite("H2 offset", h2_mm)

        def h1_at(_s):
            return P1

        def s_for_mark(mark):
            s = mark - P1
            if s <= f:
                raise OpticsError(
                    f"focus mark {mark:g} mm puts the subject {s:g} mm in front of H1, at or inside the "
                    f"{f:g} mm focal length: no real image"
                )
            return s

        def mark_for_s(s):
            return s + P1

    else:
        P1 = P2 = None

        def h1_at(s):
            return f if math.isinf(s) else thinlens.image_distance(f, s)

        def s_for_mark(mark):
            return math.inf if math.isinf(mark) else thinlens.object_distance_for_marked(f, mark)

        def mark_for_s(s):
            return s + h1_at(s)

    def to_h1(d_film, s):
        """A film-plane distance as a distance from H1 (for the current focus s)."""
        return d_film - h1_at(s)

    solved: dict = {}
    measured: dict = {}
    if near_m is not None:
        measured["near_from_film_mm"] = near_m
    if far_m is not None:
        measured["far_from_film_mm"] = far_m

    # --- focus ----------------------------------------------------------------
    if hyperfocal:  # the subject plane at H = f^2/(N c) + f from H1 (Wikipedia "Hyperfocal distance")
        D = mark_for_s(_dof.hyperfocal_distance(f, N * n_ratio, c))
        solved["focus"] = HYPERFOCAL
        notes.append(f"focus at the hyperfocal distance: mark {D:.6g} mm from the film")
    if D is None:
        if near_m is not None and far_m is not None:
            # 1/near + 1/far = 2/s about H1; H1 moves with focus in the practical model,
            # so iterate the film->H1 conversion (converges in a few steps: s' ~ f).
            s = _solve_focus_from_bracket(near_m, far_m, h1_at, f)
        elif N is not None and (near_m is not None or far_m is not None):
            hp = f * f / (N * n_ratio * c)
            s = _solve_focus_from_one_limit(near_m, far_m, hp, f, h1_at)
        else:
            raise InputError(
                "give a focus distance (--focus), or measured near and far limits (--near, --far), "
                "or one limit with the f-stop"
            )
        D = mark_for_s(s)
        solved["focus_from_film_mm"] = D
    s = s_for_mark(D)
    s_img = f if math.isinf(s) else thinlens.image_distance(f, s)
    if math.isinf(s) and (near_m is not None or far_m is not None) and "focus_from_film_mm" not in solved:
        if far_m is not None and math.isfinite(far_m):
            raise InputError("with the focus at infinity the far limit is infinite; a finite far limit is impossible")

    # --- inversions from measured limits ---------------------------------------------
    # (a focus solved from one limit and the f-stop used that limit up: nothing is left to invert)
    focus_from_one_limit = "focus_from_film_mm" in solved and (near_m is None or far_m is None)
    if (near_m is not None or far_m is not None) and not focus_from_one_limit:
        hp_near = hp_far = None
        if near_m is not None and math.isinf(s):
            hp_near = to_h1(near_m, s)  # focused at infinity the near limit is h itself (s -> inf)
            if not hp_near > 0:
                raise InputError("the near limit must lie in front of the lens")
        elif near_m is not None:
            hp_near = _dof.hyperfocal_parameter_from_near(f, s, to_h1(near_m, s))
        if far_m is not None and math.isfinite(far_m):
            hp_far = _dof.hyperfocal_parameter_from_far(f, s, to_h1(far_m, s))
        hp = hp_near if hp_near is not None else hp_far
        if hp is None:
            raise InputError("an infinite far limit alone cannot give the aperture; measure the near limit too")
        if hp_near is not None and hp_far is not None:
            solved["hyperfocal_parameter_from_near_mm"] = hp_near
            solved["hyperfocal_parameter_from_far_mm"] = hp_far
            solved["consistency"] = abs(hp_far - hp_near) / hp_near
            notes.append(
                "near and far limits agree to {:.1%} in the hyperfocal parameter".format(solved["consistency"])
            )
        if N is None or coc_explicit:
            marked = N
            N = _dof.f_number_for_dof(f, c, hp) / n_ratio  # the iris's setting (at infinity)
            solved["fstop"] = N
            if marked is not None:
                solved["fstop_drift_stops"] = _dof.stops_between(N, marked)
        else:
            c = _dof.coc_for_dof(f, N * n_ratio, hp)
            coc_name = "solved"
            solved["coc_mm"] = c
        if far_m is not None and hp_near is not None:
            _, far_pred = _dof.dof_limits(f, N * n_ratio, c, s)
            pred_film = far_pred + h1_at(s)
            solved["far_predicted_from_film_mm"] = _finite_or_none(pred_film)
            solved["far_error_mm"] = (
                0.0 if math.isinf(pred_film) and math.isinf(far_m)
                else (None if math.isinf(pred_film) or math.isinf(far_m) else pred_film - far_m)
            )
    if N is None:
        raise InputError("give the f-stop (--fstop) or a measured near/far limit to solve it")
    for name, v in (("f-stop", N), ("circle of confusion", c)):
        if not (math.isfinite(v) and v > 0):
            raise InputError(f"the measured limits give an impossible {name} ({v:g}); check --near, --far and --focus")
    if N < MIN_F_NUMBER:
        raise InputError(f"the measured limits need f/{N:.3g}, faster than any lens in air can be "
                         f"(f/{MIN_F_NUMBER:g}); check --near, --far, --focus and the CoC")
    if T is not None:
        solved["tstop_drift_stops"] = _dof.stops_between(N, T)
        if T < N - 1e-9:
            notes.append("the T-stop is faster than the f-stop: a T-stop is never below the f-number")

    # --- depth of field --------------------------------------------------------
    n_focus = N * n_ratio  # the f-number at this focus: what depth of field depends on
    if abs(n_ratio - 1.0) > 0.005:
        notes.append(f"the iris set to f/{N:.3g} (at infinity) makes the lens f/{n_focus:.3g} at this focus "
                     f"(internal focusing changes its EFL and entrance pupil); depth of field uses f/{n_focus:.3g}")
    dof = _dof_block(f, n_focus, c, s, h1_at)
    dof_h = None
    # desqueezing by sq where the lens squeezes by lens_squeeze stretches its blur by sq / lens_squeeze
    blur_aspect = lens_dof_aspect * sq / lens_squeeze if lens is not None else 1.0 / sq
    if sq != 1.0:
        # A defocused point is blur_aspect as wide as tall in the desqueezed picture, so the
        # horizontal limits are where the vertical blur reaches c / blur_aspect (docs/lens-report.md,
        # "Anamorphic depth of field"): deeper for a front anamorphic, the same for a rear one.
        dof_h = _dof_block(f, n_focus, c / blur_aspect, s, h1_at)
        notes.append(_anamorphic_dof_note(sq, blur_aspect, c, from_lens=lens is not None))
    if lens is not None:
        # a real lens's principal planes move as it focuses: the hyperfocal *mark* is the one focus
        # whose subject plane lies at H from H1 with the lens focused there (the fixed point that
        # --focus hyperfocal sets), the same whatever the report's own focus; H is given from H1
        # of the lens focused there. A lens that cannot focus there keeps H + H1 at this focus.
        import dataclasses

        try:
            mark, planes_h = _lens_hyperfocal_mark(lens, N, c)
            dof = dataclasses.replace(dof, hyperfocal_mm=mark - planes_h.h1_from_film_mm,
                                      hyperfocal_from_film_mm=mark)
            if dof_h is not None:
                mark, planes_h = _lens_hyperfocal_mark(lens, N, c, blur_aspect=None if squeeze_from_lens
                                                       else blur_aspect)
                dof_h = dataclasses.replace(dof_h, hyperfocal_mm=mark - planes_h.h1_from_film_mm,
                                            hyperfocal_from_film_mm=mark)
        except (OpticsError, InputError) as exc:
            notes.append(f"hyperfocal distance given as H plus H1 at this focus: the lens has no hyperfocal mark "
                         f"here ({str(exc).splitlines()[0]})")

    # --- focus error (technical) ------------------------------------------------
    if model == "technical":
        h1_film, h2_film = P1, P2
        if P2 <= 0:
            raise InputError(f"H2 must lie in front of the film plane, got {P2:g} mm; check --h2 and --reference")
        focus_error = P2 - s_img  # where the sharp image lies, in front of the film (+)
        if abs(focus_error) > 1e-6:
            notes.append(
                f"with these principal planes the sharp image lies {abs(focus_error):.3f} mm "
                f"{'in front of' if focus_error > 0 else 'behind'} the film plane"
            )
    else:
        h1_film = h2_film = s_img
        focus_error = 0.0

    # --- the best-match pinhole and the field of view -----------------------------------
    # One definition (docs/lens-report.md, "The best-match pinhole"): the pinhole at the entrance
    # pupil that frames like the lens at this focus, f_pin = n (film - exit pupil) / (n' m_p)
    # (optics.paraxial.GaussianData.pinhole_focal_length). A prescription gives it exactly, per
    # meridian; a thin lens or a datasheet (pupils taken on the principal planes, m_p = 1) gives the
    # distance from H2 to the film, s' when the film is in focus.
    pin_y, pin_x = lens_pinhole if lens_pinhole is not None else (h2_film, h2_film)
    # an anamorphic prescription frames each meridian by its own pinhole; their ratio is the squeeze
    pin_sq = pin_y / pin_x if pin_x != pin_y else sq
    if pinhole_focal_length_mm is not None:
        if lens is not None:
            raise InputError("with a lens prescription the best-match pinhole is computed from the lens")
        pin_y = require_positive("pinhole focal length", pinhole_focal_length_mm)
        pin_sq = sq if pinhole_squeeze is None else require_positive("pinhole squeeze", pinhole_squeeze, unit="")
    wd = w * sq
    dg = math.hypot(wd, h)
    wp = w * pin_sq
    fov = dict(
        hfov_inf_deg=_fov_deg(wd, f),
        vfov_inf_deg=_fov_deg(h, f),
        dfov_inf_deg=_fov_deg(dg, f),
        hfov_focus_deg=_fov_deg(wp, pin_y),
        vfov_focus_deg=_fov_deg(h, pin_y),
        dfov_focus_deg=_fov_deg(math.hypot(wp, h), pin_y),
    )

    # --- entrance pupil -----------------------------------------------------------
    pupil, pupil_src = None, "unknown"
    if pupil_mm is not None:  # a datasheet pupil (either model), or the prescription's
        pupil, pupil_src = ref + require_finite("entrance pupil offset", pupil_mm), pupil_origin
    elif sensor_front_mm is not None and lens_length_mm is not None:
        pupil = entrance_pupil_practical(sensor_front_mm, lens_length_mm, pupil_fraction)
        pupil_src = f"estimate: {pupil_fraction:g} of the lens length behind its front"
    elif model == "practical":
        pupil, pupil_src = h1_film, "thin lens: at the principal plane"
    if pupil is None:
        notes.append("no entrance pupil: give --pupil (technical) or --sensor-front and --lens-length")

    report = LensReport(
        model=model,
        focal_length_mm=f,
        fstop=N,
        sensor=sensor,
        squeeze=sq,
        coc_mm=c,
        coc_convention=coc_name,
        focus_from_film_mm=D,
        object_distance_mm=s,
        image_distance_mm=s_img,
        h1_from_film_mm=h1_film,
        h2_from_film_mm=h2_film,
        focus_error_mm=focus_error,
        magnification=0.0 if math.isinf(s) else -f / (s - f),
        dof=dof,
        dof_horizontal=dof_h,
        entrance_pupil_from_film_mm=pupil,
        entrance_pupil_source=pupil_src,
        solved=solved,
        measured=measured,
        notes=tuple(notes),
        lens_name=lens_name,
        reference_plane=reference_plane,
        flange_focal_distance_mm=ffd,
        tstop=T,
        pinhole_focal_length_mm=pin_y,
        pinhole_squeeze=pin_sq,
        stop_from_film_mm=(lens_stop if lens is not None else (h1_film if model == "practical" else None)),
        dof_aspect=blur_aspect,
        diffraction_wavelength_nm=lam_diff,
        bellows_factor=bellows,
        fstop_at_focus=None if n_ratio == 1.0 else n_focus,
        **fov,
    )
    import dataclasses

    report = dataclasses.replace(report, notes=report.notes + (report.diffraction_note(),))
    if lens is not None:
        report = _with_real_fov(report, lens)
    _check_finite(report)
    return report


def _with_real_fov(report: LensReport, lens) -> LensReport:
    """Add the real-ray field of view of ``lens`` (issue 8: a fisheye's paraxial field is 98 deg where
    its chief rays reach 140 deg) and, when it differs from the pinhole's, a note and a warning."""
    import dataclasses
    import warnings

    from ..analysis.field_of_view import real_field_of_view
    from ..errors import PhysCamError, PhysCamWarning

    s = report.sensor
    try:
        real = real_field_of_view(lens, s.width_mm, s.height_mm, focus_from_film_mm=report.focus_from_film_mm)
    except PhysCamError as exc:
        return dataclasses.replace(report, notes=report.notes + (f"real-ray field of view not available: {exc}",))
    report = dataclasses.replace(report, real_fov=real.to_dict())
    if not report.real_fov_differs:
        return report

    def deg(v):
        return "not covered" if v is None else f"{v:.1f}°"

    msg = (f"real chief rays give {deg(real.horizontal_deg)} x {deg(real.vertical_deg)} (diagonal "
           f"{deg(real.diagonal_deg)}); the pinhole (paraxial) field is {report.hfov_focus_deg:.1f}° x "
           f"{report.vfov_focus_deg:.1f}° (diagonal {report.dfov_focus_deg:.1f}°): distortion this strong is not a "
           "pinhole, so the render camera frames the centre like the lens but not the edges")
    if real.not_covered:
        msg += f"; the sensor's {', '.join(real.not_covered)} lie outside the lens's image circle"
    warnings.warn(msg, PhysCamWarning, stacklevel=3)
    return dataclasses.replace(report, notes=report.notes + (msg,))


#: Largest finite distance the report accepts (1000 km); beyond it use infinity.
MAX_DISTANCE_MM = 1.0e9


def _require_focus(value) -> float:
    """A focus mark: a positive distance up to :data:`MAX_DISTANCE_MM`, or infinity."""
    if isinstance(value, (int, float)) and not isinstance(value, bool) and value == math.inf:
        return math.inf
    return _require_distance("focus distance", value)


def _named_coc(w, h, given, c, name):
    """A CoC value that is one of the named conventions for this sensor (to float32 precision, as a
    USD file stores it) keeps that convention's name instead of "user"."""
    from ..optics.coc import COC_CONVENTIONS

    if name != "user" or not isinstance(given, (int, float)):
        return c, name
    for key, (_, rule) in COC_CONVENTIONS.items():
        v = rule(w, h)
        if abs(c - v) <= 1e-6 * v:
            return c, key
    return c, name


def _lens_hyperfocal(lens, fstop, sensor, coc, near_mm, far_mm):
    """(mark, planes): the focus mark of ``lens`` whose subject plane is at the hyperfocal distance
    H = f^2/(N c) + f from H1, with f and H1 of the lens focused at that mark (fixed point; the
    planes move little with focus, so a few steps converge to 1e-9 of the mark)."""
    from ..optics.coc import circle_of_confusion
    from ..optics.focusing import technical_planes

    if near_mm is not None or far_mm is not None:
        raise InputError("focus at the hyperfocal distance takes no measured near/far limits")
    n = _require_f_number("f-stop", fstop)
    c, _ = circle_of_confusion(sensor.width_mm, sensor.height_mm, coc)
    mark, _ = _lens_hyperfocal_mark(lens, n, c)
    return mark, technical_planes(lens, mark, fstop=n)


@lru_cache(maxsize=64)  # a hyperfocal focus solves it, and its report's DOF block asks again
def _lens_hyperfocal_mark(lens, n: float, c: float, *, blur_aspect: float | None = 1.0):
    """(mark, planes at the mark) of :func:`_lens_hyperfocal` for f-number ``n`` and CoC ``c`` (mm).

    The planes (EFL, H1) do not depend on the f-number, so they are found without it (any f-number
    the lens can or cannot open to gives the same mark); ``n`` is the iris's setting at infinity, and
    the f-number at each candidate mark is n times the lens's f-number ratio there (internal focusing).
    ``blur_aspect``: the CoC is ``c / blur_aspect`` (an anamorphic's horizontal limits, the blur's
    width over height in the desqueezed picture); None takes the lens's own blur aspect at each mark
    (its entrance pupil's X over Y diameter, as the report does), so the horizontal mark too is a
    fixed point."""
    from ..optics.focusing import f_number_ratio, technical_planes

    mark = math.inf
    for _ in range(50):
        planes = technical_planes(lens, mark)
        aspect = _pupil_aspect(lens, mark) if blur_aspect is None else blur_aspect
        n_at = n * f_number_ratio(lens, mark)
        new = _dof.hyperfocal_distance(planes.efl_mm, n_at, c / aspect) + planes.h1_from_film_mm
        new = _require_distance("hyperfocal focus mark", new)
        if math.isfinite(mark) and abs(new - mark) <= 1e-9 * new:
            return new, technical_planes(lens, new)
        mark = new
    raise OpticsError(f"the hyperfocal focus of {lens.name!r} did not settle; give the focus mark")


def _pupil_aspect(lens, mark: float) -> float:
    """An anamorphic lens's blur aspect at focus ``mark``: its entrance pupil's X over Y diameter
    (one round stop seen through each meridian; the ratio does not depend on the stop's size)."""
    from ..optics import focusing, paraxial

    st = focusing.focus(lens, mark)
    gx, gy = (paraxial.gaussian(st.prescription, axis=a, object_z=st.object_z, film_z=st.film_z) for a in "xy")
    return gx.entrance_pupil_diameter / gy.entrance_pupil_diameter


def _anamorphic_dof_note(sq: float, aspect: float, c: float, *, from_lens: bool) -> str:
    """Why the horizontal limits differ from the vertical ones (or do not)."""
    source = ("the lens's entrance pupil, X over Y" if from_lens else
              "a front anamorphic's narrowed pupil, 1 / squeeze; a rear anamorphic's blur is round: give --lens")
    return (f"anamorphic {sq:g}x: a defocused point is {aspect:.3g} as wide as tall in the desqueezed picture "
            f"({source}), so the horizontal limits take the CoC c / {aspect:.3g} = {c / aspect:.4g} mm")


def _require_distance(name: str, value) -> float:
    v = require_positive(name, value)
    if v > MAX_DISTANCE_MM:
        raise InputError(f"{name} {v:g} mm is beyond 1000 km; for a subject at infinity use a far limit of inf")
    return v


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
                raise InputError(
                    "the near limit lies beyond the hyperfocal parameter f^2/(N c) (focus at infinity): "
                    "no focus gives it; check the near limit, f-stop and CoC"
                )
            s = n * (hp - f) / (hp - n)
        else:
            F = far_film - p
            s = F * (hp + f) / (hp + F)
        p_new = h1_at(s)
        if abs(p_new - p) < 1e-10 * max(1.0, p):
            return s
        p = p_new
    raise OpticsError("could not solve the focus distance from the measured limit")


def _check_finite(report: LensReport) -> None:
    """No NaN leaves the library; infinities only where documented (far limits)."""
    d = report.to_dict()

    def walk(x, path):
        if isinstance(x, float) and not math.isfinite(x):
            raise OpticsError(f"the report's {path} came out {x}; check the inputs")
        if isinstance(x, dict):
            for k, v in x.items():
                walk(v, f"{path}.{k}" if path else k)
        if isinstance(x, list):
            for i, v in enumerate(x):
                walk(v, f"{path}[{i}]")

    walk(d, "")


def takes_report(fn):
    """Decorator: the first argument must be a :class:`LensReport` (else WrongTypeError with a sentence)."""
    import functools

    from ..errors import require_type

    @functools.wraps(fn)
    def checked(report, *args, **kwargs):
        require_type("report", report, LensReport, "solve one with physcam.onset.report.solve_lens_report")
        return fn(report, *args, **kwargs)

    return checked

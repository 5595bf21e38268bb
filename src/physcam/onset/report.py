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

from .._record import field, record, replace
from ..errors import InputError, OpticsError, require_positive, require_type
from ..optics import _num
from ..optics import dof as _dof
from ..optics.coc import named_circle_of_confusion
from ..optics.sensors import Sensor
from ..optics.state import CameraState, OfACamera
from .pupil import pivot_camera_space
from .request import (DIFFRACTION_WAVELENGTH_NM, HYPERFOCAL, MAX_DISTANCE_MM, MAX_F_NUMBER, MIN_F_NUMBER,
                      MeasuredLimits, References, ReportInputs, ReportRequest, report_camera)
from .solvers import (DepthOfField, depth_of_field, entrance_pupil, field_of_view, finite_or_none, focus_error,
                      invert_limits, lens_at_mark, principal_planes, solve_focus)

__all__ = ["LensReport", "DepthOfField", "ReportRequest", "solve_report", "solve_lens_report", "takes_report",
           "report_camera", "MeasuredLimits", "References",
           "REPORT_SCHEMA", "REPORT_VERSION", "HYPERFOCAL", "DIFFRACTION_WAVELENGTH_NM", "MIN_F_NUMBER",
           "MAX_F_NUMBER", "MAX_DISTANCE_MM", "airy_diameter_mm", "fstop_airy_equals"]

#: Real (chief-ray) and pinhole fields of view may differ by this much (percent, any of horizontal,
#: vertical, diagonal) before the report warns: about what a fitted two-term radial distortion
#: model on the render camera still corrects (dgauss.50mm, barrel: 1.0 % h, 1.5 % d).
REAL_FOV_TOLERANCE_PCT = 2.0

REPORT_SCHEMA = "physcam.lens_report"
#: 2: adds ``diffraction`` and ``sensor.photosite_pitch_mm`` (every key of version 1 kept).
#: 3: magnification is signed (negative: the inverted image); a focus at infinity is null with
#: ``focus_is_infinite``, as is the object distance (issue 15).
REPORT_VERSION = 3
#: The Airy disk's diameter to its first dark ring is AIRY_FACTOR lambda N (2 x 1.22).
AIRY_FACTOR = 2.44


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


@record
class LensReport(OfACamera):
    """Everything the lens report knows. Lengths in mm, angles in degrees.

    Positions are distances in front of the film plane (``*_from_film_mm``) unless the
    name says otherwise; ``object_distance_mm`` is from H1, ``image_distance_mm`` from H2.
    """

    camera: CameraState  # the camera this report is a view of: lens, focus, f-stop, sensor
    model: str
    focal_length_mm: float
    squeeze: float
    coc_mm: float
    coc_convention: str
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
    reference_plane: str = "film"
    flange_focal_distance_mm: float | None = None
    #: figures from elsewhere the report compared or took (the marked T-stop, the diffraction wavelength ...)
    references: References = field(default_factory=References)
    #: the best-match pinhole: a pinhole at the entrance pupil with this focal length (and the
    #: horizontal aperture widened by ``pinhole_squeeze``) frames like the lens at this focus.
    #: None means the thin-lens value, the distance from H2 to the film.
    pinhole_focal_length_mm: float | None = None
    pinhole_squeeze: float | None = None
    #: with a prescription: the field of view of real chief rays from the film edge, top and corner
    #: (:func:`physcam.analysis.framing.field_of_view.real_field_of_view`, as its ``to_dict``), beside the
    #: paraxial pinhole's; None for the thin-lens and datasheet models.
    real_fov: dict | None = None
    #: the physical aperture stop (iris) in front of the film: a prescription's stop surface; the
    #: lens plane for the thin lens; None when a datasheet does not say
    stop_from_film_mm: float | None = None
    #: width over height of a defocused point's blur in the desqueezed picture: the entrance
    #: pupil's X over Y diameter (object-space blur angles scale with it); 1 for a spherical lens,
    #: 1 / squeeze for a thin lens given a squeeze (a front anamorphic's cylinders narrow the pupil in X)
    dof_aspect: float = 1.0
    #: working over geometric f-number at this focus: a prescription's paraxial ratio; None: 1 + m
    #: (pupils taken as equal)
    bellows_factor: float | None = None
    #: the f-number at this focus for the iris set to ``fstop`` at infinity (see f_number_at_focus);
    #: None: ``fstop`` (no focusing changes it)
    fstop_at_focus: float | None = None
    #: an anamorphic prescription's horizontal (X-meridian) entrance pupil in front of the film, the
    #: parallax-free pivot of a pan; ``entrance_pupil_from_film_mm`` is then the vertical (Y) one, the
    #: pivot of a tilt (physcam.optics.focusing.EntrancePupils). None: one pupil for both
    entrance_pupil_horizontal_from_film_mm: float | None = None

    # --- the camera's own settings, read from it (fstop, focus_from_film_mm: OfACamera) -----------
    @property
    def sensor(self) -> Sensor:
        return self.camera.sensor

    @property
    def lens_name(self) -> str | None:
        return self.camera.lens_name

    @property
    def tstop(self) -> float | None:
        """The marked T-stop the report compared (its references')."""
        return self.references.tstop

    @property
    def diffraction_wavelength_nm(self) -> float:
        """Wavelength (nm) of the diffraction figures."""
        return self.references.diffraction_wavelength_nm

    def stopped_camera(self) -> CameraState:
        """The report's camera with its iris set to the report's f-stop (what a tracer traces): the camera
        itself, or, for an f-stop solved from measured limits, the lens at that stop (an OpticsError
        when the lens cannot open to it)."""
        cam = self.camera
        if cam.iris_set or not cam.traceable:
            return cam
        from ..optics.state import camera_state

        return camera_state(cam.lens_model, focus_mm=cam.focus_from_film_mm, fstop=cam.fstop, sensor=cam.sensor,
                            squeeze=cam.squeeze, zoom=cam.zoom)

    # --- convenience --------------------------------------------------------
    @property
    def split_focus(self) -> dict | None:
        """With the focus solved from a near and a far limit and the stop given: the stop those limits need at
        this CoC beside the given one (the report's own limits are the given stop's); else None."""
        need = self.solved.get("fstop_needed")
        if need is None:
            return None
        return {"near_asked_from_film_mm": self.measured.get("near_from_film_mm"),
                "far_asked_from_film_mm": finite_or_none(self.measured.get("far_from_film_mm", math.inf)),
                "fstop_given": self.fstop, "fstop_needed": need, "holds": self.fstop >= need * (1 - 1e-9),
                "definition": "the focus between the asked near and far limits; fstop_needed holds both at this CoC; "
                              "the report's near and far limits are those of the given stop"}

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

    def entrance_pupils_dict(self) -> dict:
        """Both meridians' entrance pupils and the pivots they give (equal for a spherical lens)."""
        v = self.entrance_pupil_from_film_mm
        h = v if self.entrance_pupil_horizontal_from_film_mm is None else self.entrance_pupil_horizontal_from_film_mm
        return {"horizontal_from_film_mm": h, "vertical_from_film_mm": v,
                "separation_mm": None if v is None else h - v,
                "pan_pivot_camera_space_mm": None if h is None else list(pivot_camera_space(h)),
                "tilt_pivot_camera_space_mm": None if v is None else list(pivot_camera_space(v)),
                "definition": "horizontal: the X meridian's paraxial entrance pupil, about which a pan is "
                              "parallax-free; vertical: the Y meridian's, for a tilt; entrance_pupil_from_film_mm "
                              "and pivot_camera_space_mm are the vertical one"}

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
        text = (f"diffraction ({d['wavelength_nm']:g} nm): Airy disk {d['airy_diameter_mm'] * um:.1f} µm across at "
                f"f/{self.fstop:.3g} (working f/{d['working_f_number']:.3g}), {d['airy_to_coc']:.2f} of the CoC "
                f"({self.coc_mm * um:.1f} µm)")
        if d["photosite_pitch_mm"] is not None:
            text += f" and {d['airy_in_photosites']:.1f} photosites ({d['photosite_pitch_mm'] * um:.2f} µm)"
        verb = "exceeds" if d["exceeds_coc"] else "would exceed"
        return text + f"; it {verb} the CoC past f/{d['fstop_airy_exceeds_coc']:.3g}"

    def fov_dict(self) -> dict:
        """The fields of view of :meth:`to_dict` (``fov_deg``): at infinity, the best-match pinhole's at this
        focus, and the real chief rays' (None without a prescription)."""
        return {
            "infinity": {"horizontal": self.hfov_inf_deg, "vertical": self.vfov_inf_deg,
                         "diagonal": self.dfov_inf_deg},
            "focus": {"horizontal": self.hfov_focus_deg, "vertical": self.vfov_focus_deg,
                      "diagonal": self.dfov_focus_deg},
            "definition": "infinity: the paraxial field of the lens focused at infinity (a prescription's EFL "
                          "there); focus: the best-match pinhole's at this focus; real: chief rays traced through "
                          "the prescription from the film edge, top and corner (null where not covered)",
            "real": None if self.real_fov is None else {
                "horizontal": self.real_fov["horizontal_deg"], "vertical": self.real_fov["vertical_deg"],
                "diagonal": self.real_fov["diagonal_deg"],
                "difference_pct": {k: self.real_fov[f"{k}_difference_pct"]
                                   for k in ("horizontal", "vertical", "diagonal")},
                "not_covered": list(self.real_fov["not_covered"]), "reason": self.real_fov["reason"]},
            "real_differs": self.real_fov_differs,
        }

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
            "focus_from_film_mm": finite_or_none(self.focus_from_film_mm),
            "focus_is_infinite": self.focus_is_infinite,
            "object_distance_mm": finite_or_none(self.object_distance_mm),
            "image_distance_mm": self.image_distance_mm,
            "h1_from_film_mm": self.h1_from_film_mm,
            "h2_from_film_mm": self.h2_from_film_mm,
            "reference_plane": self.reference_plane,
            "flange_focal_distance_mm": self.flange_focal_distance_mm,
            "focus_error_mm": self.focus_error_mm,
            "magnification": self.magnification,
            "frame_at_focus": _frame_dict(self),
            "dof": self.dof.to_dict(),
            "dof_horizontal": None if self.dof_horizontal is None else self.dof_horizontal.to_dict(),
            "split_focus": self.split_focus,
            "pinhole": {"focal_length_mm": self.pinhole[0], "squeeze": self.pinhole[1],
                        "definition": "the pinhole at the entrance pupil that frames like the lens at this focus: "
                                      "f = (exit pupil to film) / pupil magnification; s' for a thin lens"},
            "fov_deg": self.fov_dict(),
            "entrance_pupil_from_film_mm": self.entrance_pupil_from_film_mm,
            "stop_from_film_mm": self.stop_from_film_mm,
            "dof_aspect": self.dof_aspect,
            "entrance_pupil_source": self.entrance_pupil_source,
            "pivot_camera_space_mm": None if self.pivot_camera_space_mm is None else list(self.pivot_camera_space_mm),
            "entrance_pupils": self.entrance_pupils_dict(),
            "solved": dict(self.solved),
            "measured": {k: finite_or_none(v) if isinstance(v, float) else v for k, v in self.measured.items()},
            "notes": list(self.notes),
            "diffraction": self.diffraction_dict(),
        }


def _frame_dict(report) -> dict | None:
    """The picture's (desqueezed) width and height in the plane of sharp focus, the gate over |m|
    (physcam.onset.framing), or None focused at infinity."""
    m = report.magnification
    if m == 0.0 or math.isinf(report.object_distance_mm):
        return None
    w, h = report.sensor.width_mm * report.squeeze / abs(m), report.sensor.height_mm / abs(m)
    return {"width_mm": w, "height_mm": h, "diagonal_mm": math.hypot(w, h),
            "distance_from_h1_mm": report.object_distance_mm}


# --------------------------------------------------------------------------------------
def solve_report(camera, *, coc=None, measured: MeasuredLimits | None = None,
                 references: References | None = None, real_fov: bool = True) -> LensReport:
    """The lens report of ``camera`` (:class:`~physcam.optics.state.CameraState`: a lens model focused
    and stopped on a sensor): a view of the camera, composed of the solvers of
    :mod:`physcam.onset.solvers` in the order the optics needs them.

    ``coc``: the circle of confusion, a convention ("d/1500", "cine" ...) or mm (None: d/1500).
    ``measured``: near/far limits measured on a plate (:class:`~physcam.onset.request.MeasuredLimits`):
    the report solves the CoC from them (the camera's f-stop kept), or, when the camera's f-stop or
    focus was solved from them (:mod:`physcam.onset.inverse`), checks them against it.
    ``references``: figures from elsewhere (:class:`~physcam.onset.request.References`: the marked
    T-stop, a tape-measured pupil, a USD file's pinhole). The f-stop is the iris's setting, defined at
    infinity focus (:func:`physcam.optics.focusing.iris_semi_diameter`); depth of field uses the
    f-number at the focus (:attr:`LensReport.f_number_at_focus`). A :class:`ReportRequest` first (the
    pre-issue-43 form) or the :class:`~physcam.onset.request.ReportInputs` of
    :func:`~physcam.onset.request.report_camera` is read as its camera and options.
    ``real_fov`` False leaves out the real-ray field of view of a traceable lens (its chief rays traced, about
    three quarters of such a report's time; the paraxial field stays), for callers that read other numbers
    of many reports: a depth-of-field chart's cells (:func:`physcam.onset.dof_plot.dof_chart_data`).
    """
    if isinstance(camera, (ReportRequest, ReportInputs)):  # the inputs of a front end, whole
        camera, coc, measured, references = camera.inputs if isinstance(camera, ReportRequest) else camera
    require_type("camera", camera, CameraState, "physcam.optics.state.camera_state(lens, focus_mm=..., fstop=..., "
                 "sensor=...), or physcam.onset.request.report_camera(...) from a front end's inputs")
    if camera.sensor is None:
        raise InputError("the lens report needs the camera's sensor: camera_state(..., sensor=...)")
    refs = References() if references is None else require_type("references", references, References)
    if measured is not None:
        require_type("measured", measured, MeasuredLimits, "physcam.onset.request.MeasuredLimits(near_mm, far_mm)")
    at = lens_at_mark(camera, refs)  # the lens at the mark, solved when the camera was made
    planes = principal_planes(at)
    w, h = camera.sensor.width_mm, camera.sensor.height_mm
    c, coc_name = named_circle_of_confusion(w, h, coc)
    focus = solve_focus(camera, planes, measured)
    ap = invert_limits(camera, planes, focus, c, coc_name, measured, at)
    solved, notes = {**focus.solved, **ap.solved}, [*camera.notes, *at.notes, *focus.notes, *ap.notes]
    if refs.tstop is not None:
        solved["tstop_drift_stops"] = _dof.stops_between(ap.fstop, refs.tstop)
        if refs.tstop < ap.fstop - 1e-9:
            notes.append("the T-stop is faster than the f-stop: a T-stop is never below the f-number")
    dof = depth_of_field(camera, planes, focus, ap, at)
    h1_film, h2_film, error, error_notes = focus_error(planes, focus)
    pupil, pupil_src, pupil_notes = entrance_pupil(camera, h1_film, refs, at)
    s, n_focus, model = focus.object_distance, ap.fstop * at.n_ratio, camera.lens_model
    report = LensReport(
        camera=camera, model=at.model, focal_length_mm=at.focal_length_mm, squeeze=at.squeeze, coc_mm=ap.coc_mm,
        coc_convention=ap.coc_convention, object_distance_mm=s, image_distance_mm=focus.image_distance,
        h1_from_film_mm=h1_film, h2_from_film_mm=h2_film, focus_error_mm=error,
        magnification=0.0 if math.isinf(s) else -at.focal_length_mm / (s - at.focal_length_mm),
        dof=dof.dof, dof_horizontal=dof.horizontal, entrance_pupil_from_film_mm=pupil,
        entrance_pupil_source=pupil_src, solved=solved, measured=_measured(measured),
        notes=(*notes, *dof.notes, *error_notes, *pupil_notes),
        reference_plane=getattr(model, "reference_plane", "film"),
        flange_focal_distance_mm=model.flange_focal_distance_mm if getattr(model, "reference_plane", "film") == "flange"
        else None, references=refs,
        stop_from_film_mm=at.stop_from_film_mm if camera.traceable else (h1_film if at.model == "practical" else None),
        dof_aspect=dof.blur_aspect, bellows_factor=at.bellows, fstop_at_focus=None if at.n_ratio == 1.0 else n_focus,
        entrance_pupil_horizontal_from_film_mm=at.pupil_x_from_film_mm if pupil_src == "prescription" else None,
        **field_of_view(camera, h2_film, refs, at))
    report = replace(report, notes=report.notes + (report.diffraction_note(),))
    if camera.traceable and real_fov:
        report = _with_real_fov(report, camera)
    _check_finite(report)
    return report


def solve_lens_report(**inputs) -> LensReport:
    """The report from keyword inputs (the inputs of :func:`~physcam.onset.request.report_camera`:
    distances on set from the film plane, datasheet offsets from the reference plane):
    ``solve_report(report_camera(**inputs))``."""
    return solve_report(report_camera(**inputs))


def _measured(measured: MeasuredLimits | None) -> dict:
    """The limits measured on set, from the film plane."""
    out = {}
    if measured is not None and measured.near_mm is not None:
        out["near_from_film_mm"] = measured.near_mm
    if measured is not None and measured.far_mm is not None:
        out["far_from_film_mm"] = measured.far_mm
    return out


def _with_real_fov(report: LensReport, camera: CameraState) -> LensReport:
    """Add the real-ray field of view of the camera's lens at its mark (issue 8: a fisheye's paraxial
    field is 98 deg where its chief rays reach 140 deg) and, when it differs from the pinhole's, a note
    and a warning. The lens focused at the mark is the camera's own solution (no focus solved again)."""
    import warnings

    from ..analysis.framing.field_of_view import real_field_of_view_focused
    from ..errors import PhysCamError, PhysCamWarning

    s = report.sensor
    st = camera.lens_model.focus_state(report.focus_from_film_mm)
    try:
        real = real_field_of_view_focused(camera.lens, st.prescription, st.film_z, s.width_mm, s.height_mm,
                                          mark=report.focus_from_film_mm)
    except PhysCamError as exc:
        return replace(report, notes=report.notes + (f"real-ray field of view not available: {exc}",))
    report = replace(report, real_fov=real.to_dict())
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
    warnings.warn(msg, PhysCamWarning, stacklevel=_caller_level())
    return replace(report, notes=report.notes + (msg,))


def _caller_level() -> int:
    """The warnings stack level of the first caller outside ``physcam.onset`` (the user's line)."""
    import sys

    frame, level = sys._getframe(1), 1
    while frame.f_back is not None and frame.f_globals.get("__name__", "").startswith("physcam.onset"):
        frame, level = frame.f_back, level + 1
    return level


def _check_finite(report: LensReport) -> None:
    """No NaN leaves the library; infinities only where documented (far limits). The numbers are checked
    in one pass; the first bad one is named by a second, only then (``physcam serve`` checks a report per
    keystroke: building each value's path cost a third of the check, issue 47)."""
    d = report.to_dict()
    if _all_finite(d):
        return

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


def _all_finite(doc) -> bool:
    """Whether every float in ``doc`` (dicts and lists, nested) is finite."""
    isfinite, stack = math.isfinite, [doc]
    while stack:
        x = stack.pop()
        if isinstance(x, float):
            if not isfinite(x):
                return False
        elif isinstance(x, dict):
            stack.extend(x.values())
        elif isinstance(x, list):
            stack.extend(x)
    return True


def takes_report(fn):
    """Decorator: the first argument must be a :class:`LensReport` (else WrongTypeError with a sentence)."""
    import functools

    from ..errors import require_type

    @functools.wraps(fn)
    def checked(report, *args, **kwargs):
        require_type("report", report, LensReport, "solve one with physcam.onset.report.solve_lens_report")
        return fn(report, *args, **kwargs)

    return checked

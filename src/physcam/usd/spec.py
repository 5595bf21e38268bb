"""The camera as physcam's USD files hold it: :class:`CameraSpec` (every value of the PhysicalCamera
schema, in millimetres), the schema's instance names, and the on-set report of a spec and back.

Shared by the writer (:mod:`physcam.usd.author`) and the reader (:mod:`physcam.usd.read`), so neither
imports the other for it.
"""

from __future__ import annotations

import dataclasses
import math
import warnings
from dataclasses import dataclass, fields

from ..data.default_sensor import DEFAULT_SENSOR_HEIGHT_MM, DEFAULT_SENSOR_WIDTH_MM
from ..errors import InputError, require_finite, require_positive, require_type
from ..optics.state import CameraState

#: the keyword form of CameraSpec goes in this version
UNTIL = "0.3"

__all__ = ["CameraSpec", "CAMERA_VALUES", "DEFAULT_CAMERA_PATH", "LENS_INSTANCE", "SENSOR_INSTANCE", "RENDER_CAMERA_NAME",
           "BLENDER_PROPERTY", "report_for_spec", "spec_from_report"]

DEFAULT_CAMERA_PATH = "/Cameras/Camera"
SENSOR_INSTANCE = "main"
LENS_INSTANCE = "main"
RENDER_CAMERA_NAME = "Camera"
#: the namespace of the companion camera's properties for importers that keep USD's userProperties
#: (Blender imports ``userProperties:physcam:apertureBlades`` as the custom property ``physcam:apertureBlades``)
BLENDER_PROPERTY = "userProperties:physcam:"


#: The numbers of the camera a :class:`CameraSpec` holds (its lens, sensor, focus and stop), each read
#: back as a property of the spec; :meth:`CameraSpec.of` and :meth:`CameraSpec.replaced` take them.
CAMERA_VALUES = ("focal_length_mm", "sensor_width_mm", "sensor_height_mm", "fstop", "focus_mm", "squeeze",
                 "lens_name", "sensor_name")
_DEFAULT_CAMERA = dict(focal_length_mm=50.0, sensor_width_mm=DEFAULT_SENSOR_WIDTH_MM,
                       sensor_height_mm=DEFAULT_SENSOR_HEIGHT_MM, fstop=8.0, focus_mm=3000.0, squeeze=1.0,
                       lens_name=None, sensor_name=None)
#: the key of a spec's sensor known only by its size (its name then reads as None)
_NAMELESS_SENSOR = "usd: no name"


@dataclass(frozen=True, init=False)
class CameraSpec:
    """A physical camera as the PhysicalCamera schema stores it: the camera (``camera``, a
    :class:`~physcam.optics.state.CameraState`: the lens, its focus mark, its f-stop, the sensor and
    the squeeze) and the body, shutter, iris-shape and render values beside it (mm, seconds, degrees).

    ``CameraSpec(camera, **values)`` holds a camera built elsewhere (:func:`spec_from_report` holds the
    report's); ``CameraSpec.of(focal_length_mm=, fstop=, focus_mm=, sensor_width_mm=, ...)`` builds a thin
    lens camera from the schema's numbers. The camera's numbers (:data:`CAMERA_VALUES`) read back as
    properties: ``focus_mm`` is the mark in front of the film plane (the on-set mark);
    ``sensor_width_mm`` x ``sensor_height_mm``: default sensor Super 35 (24.89 x 18.66 mm), the CLI's
    (:data:`physcam.data.default_sensor.DEFAULT_SENSOR`). The keyword form of before issue 43,
    ``CameraSpec(focal_length_mm=..., fstop=..., focus_mm=...)``, still builds one, with a
    DeprecationWarning (it goes in physcam 0.3); ``CameraSpec()`` is the default camera (50 mm f/8
    at 3 m on Super 35).

    ``entrance_pupil_mm``: the pupil in front of the film plane; ``None`` uses the thin
    lens (the pupil on the principal plane, s' in front of the film).
    ``horizontal_entrance_pupil_mm``: an anamorphic's horizontal (X meridian) pupil in front of the
    film, the pan pivot (``entrance_pupil_mm`` is then the vertical one, the tilt pivot and the eye);
    ``None``: one pupil for both meridians.
    ``principal_planes_mm``: (H1, H2) in front of the film plane, from a datasheet or a
    prescription (the technical model); ``None`` for a thin lens.
    ``pinhole_focal_length_mm``, ``pinhole_squeeze``: the best-match pinhole (the companion
    camera's framing, docs/lens-report.md) when it is known from a prescription; ``None``
    computes it from the model (s' for a thin lens, H2 to film for a datasheet).
    ``clipping_mm``: near/far clipping from the eye, in mm (written in scene units).
    ``enlarge`` (ex, ey): the imaged region is the sensor divided by it (a tile of the frame: enlarge
    (2, 2) with ``shift_mm`` (-w/4, +h/4) renders the upper-left quadrant); ``handedness`` 1 for a
    right-handed camera frame, -1 for a left-handed (mirrored) one (seed 001's sensor).
    ``aperture_distance_mm``: the physical aperture stop (iris) in front of the film, when known.
    ``dof_aspect``: width / height of the defocus blur in the desqueezed picture (RenderMan's
    ``dofaspect``); None: 1 / squeeze (a front anamorphic), 1 for a spherical lens.
    ``fstop_at_focus``: the f-number at this focus of an internal-focus lens whose iris is set to
    the camera's f-stop at infinity (:attr:`physcam.onset.report.LensReport.f_number_at_focus`); the
    lens's ``iris`` (entrance pupil diameter) is focal length / it. None: the f-stop.
    ``projection``: "perspective" (a pinhole/thin-lens model) or "orthographic"
    (a telecentric model imaging ``sensor / magnification`` of the scene).
    """

    camera: CameraState
    coc_mm: float = 0.03
    entrance_pupil_mm: float | None = None
    horizontal_entrance_pupil_mm: float | None = None
    principal_planes_mm: tuple[float, float] | None = None
    pinhole_focal_length_mm: float | None = None
    pinhole_squeeze: float | None = None
    shift_mm: tuple[float, float] = (0.0, 0.0)
    enlarge: tuple[float, float] = (1.0, 1.0)
    handedness: float = 1.0
    dof_aspect: float | None = None
    fstop_at_focus: float | None = None
    iso: float = 100.0
    transmittance: float = 1.0
    flange_distance_mm: float = 52.0
    aperture_distance_mm: float | None = None
    shutter_open_s: float = 0.0
    shutter_duration_s: float = 1.0 / 48.0
    shutter_opening: tuple[float, float] = (0.0, 1.0)
    aperture_blades: int = 7
    aperture_angle_deg: float = 0.0
    aperture_roundness: float = 0.0
    aperture_density: float = 0.0
    clipping_mm: tuple[float, float] = (100.0, 1.0e7)
    projection: str = "perspective"
    magnification: float = 1.0

    def __init__(self, camera: CameraState | None = None, **values):
        old = {k: values.pop(k) for k in CAMERA_VALUES if k in values}
        if old:
            warnings.warn("CameraSpec(focal_length_mm=..., fstop=..., focus_mm=...) builds its camera from numbers: "
                          "use CameraSpec.of(...), CameraSpec(camera, ...) or spec.replaced(...); the keyword form goes in physcam "
                          f"{UNTIL}", DeprecationWarning, stacklevel=2)
            camera = _camera_of_numbers(**{**(_numbers_of(camera) if camera is not None else _DEFAULT_CAMERA), **old})
        elif camera is None:
            camera = _camera_of_numbers(**_DEFAULT_CAMERA)
        require_type("camera", camera, CameraState, "build one with physcam.optics.state.camera_state(...) or use "
                     "CameraSpec.of(focal_length_mm=..., fstop=..., focus_mm=...)")
        if camera.sensor is None:
            raise InputError("a CameraSpec's camera needs its sensor (camera_state(..., sensor=...))")
        object.__setattr__(self, "camera", camera)
        for f in fields(self)[1:]:
            object.__setattr__(self, f.name, values.pop(f.name) if f.name in values else f.default)
        if values:
            raise TypeError(f"CameraSpec got unexpected keyword arguments {sorted(values)}")

    @classmethod
    def of(cls, focal_length_mm: float = 50.0, sensor_width_mm: float = DEFAULT_SENSOR_WIDTH_MM,
           sensor_height_mm: float = DEFAULT_SENSOR_HEIGHT_MM, fstop: float = 8.0, focus_mm: float = 3000.0,
           squeeze: float = 1.0, lens_name: str | None = None, sensor_name: str | None = None,
           **values) -> "CameraSpec":
        """A spec from the schema's numbers: a thin lens camera of ``focal_length_mm`` focused at ``focus_mm``
        (from the film plane) at ``fstop`` on a ``sensor_width_mm`` x ``sensor_height_mm`` sensor (default
        Super 35, the CLI's), and the other fields' values."""
        camera = _camera_of_numbers(focal_length_mm=focal_length_mm, sensor_width_mm=sensor_width_mm,
                                    sensor_height_mm=sensor_height_mm, fstop=fstop, focus_mm=focus_mm, squeeze=squeeze,
                                    lens_name=lens_name, sensor_name=sensor_name)
        return cls(camera, **values)

    def replaced(self, **changes) -> "CameraSpec":
        """This spec with ``changes`` (the camera's numbers, :data:`CAMERA_VALUES`, or fields): a change of a
        camera number rebuilds the camera from numbers (a thin lens); the f-stop alone keeps the lens."""
        numbers = {k: changes.pop(k) for k in CAMERA_VALUES if k in changes}
        camera = self.camera
        if set(numbers) == {"fstop"} and camera.traceable:
            camera = camera.with_fstop(numbers["fstop"])
        elif numbers:
            camera = _camera_of_numbers(**{**_numbers_of(camera), **numbers})
        return dataclasses.replace(self, camera=camera, **changes)

    def values(self) -> dict:
        """Every number of the spec by name (the fields of the spec before issue 43, in their order): the
        camera's (:data:`CAMERA_VALUES`) and the fields'. What ``physcam usd read --json`` prints and the
        companion camera's inputs hash reads."""
        cam = _numbers_of(self.camera)
        out = {k: cam.pop(k) for k in ("focal_length_mm", "sensor_width_mm", "sensor_height_mm", "fstop", "focus_mm")}
        out["coc_mm"] = self.coc_mm
        out["squeeze"] = cam.pop("squeeze")
        out.update((f.name, getattr(self, f.name)) for f in fields(self)[2:])
        return {**out, **cam}  # lens_name, sensor_name last, as they were

    # --- the camera's numbers, read from it ------------------------------------------------------
    @property
    def focal_length_mm(self) -> float:
        """The lens's focal length at the mark (a prescription's EFL there), mm."""
        return self.camera.at_mark.focal_length_mm

    @property
    def fstop(self) -> float:
        """The iris's setting (at infinity focus): the camera's."""
        return self.camera.fstop

    @property
    def t_stop(self) -> float:
        """The photometric stop the companion camera's ``exposure:fStop`` carries: the f-stop over the square
        root of the lens's ``transmittance`` (T = N / sqrt(tau), as the T-stop is defined)."""
        return self.fstop / math.sqrt(self.transmittance)

    @property
    def focus_mm(self) -> float:
        """The focus mark in front of the film plane, mm: the camera's."""
        return self.camera.focus_from_film_mm

    @property
    def squeeze(self) -> float:
        """The picture's desqueeze factor at the mark: the camera's."""
        return self.camera.at_mark.squeeze

    @property
    def sensor_width_mm(self) -> float:
        return self.camera.sensor.width_mm

    @property
    def sensor_height_mm(self) -> float:
        return self.camera.sensor.height_mm

    @property
    def sensor_name(self) -> str | None:
        """The sensor's name; None for a sensor known only by its size."""
        s = self.camera.sensor
        return None if s.key == _NAMELESS_SENSOR else s.name

    @property
    def lens_name(self) -> str | None:
        return self.camera.lens_name

    def checked(self) -> "CameraSpec":
        """Return self after range checks; raise :class:`InputError` saying what to change."""
        for name in ("focal_length_mm", "sensor_width_mm", "sensor_height_mm", "fstop", "focus_mm", "coc_mm",
                     "squeeze", "iso", "flange_distance_mm", "shutter_duration_s", "magnification"):
            require_positive(name, getattr(self, name), unit="")
        require_finite("shutter_open_s", self.shutter_open_s)
        for name in ("aperture_angle_deg", "aperture_roundness", "aperture_density", "transmittance"):
            require_finite(name, getattr(self, name))
        if not 0.0 < self.transmittance <= 1.0:
            raise InputError(f"transmittance must be in (0, 1], got {self.transmittance:g}")
        for name in ("aperture_roundness", "aperture_density"):
            if not -1.0 <= getattr(self, name) <= 1.0:
                raise InputError(f"{name} must be between -1 and 1 (RenderMan's range), got {getattr(self, name):g}")
        o, c = (require_finite("shutter opening time", self.shutter_opening[0]),
                require_finite("shutter closing time", self.shutter_opening[1]))
        if not 0.0 <= o <= c <= 1.0:
            raise InputError(f"shutter opening (opentime, closetime) needs 0 <= open <= close <= 1, got ({o:g}, {c:g})")
        if isinstance(self.aperture_blades, bool) or int(self.aperture_blades) != self.aperture_blades \
                or self.aperture_blades < 0:
            raise InputError(f"aperture blades must be a whole number >= 0, got {self.aperture_blades!r}")
        near, far = (require_positive("near clipping distance", self.clipping_mm[0]),
                     require_positive("far clipping distance", self.clipping_mm[1]))
        if not far > near:
            raise InputError(f"far clipping distance {far:g} mm must be beyond the near one {near:g} mm")
        for v in self.shift_mm:
            require_finite("sensor shift", v)
        for v in self.enlarge:
            if not 0.001 <= require_finite("enlarge", v) <= 1000.0:
                raise InputError(f"enlarge must lie between 0.001 and 1000 (a magnification), got {v:g}")
        if self.dof_aspect is not None and not 0.01 <= require_finite("dof aspect", self.dof_aspect) <= 100.0:
            raise InputError(f"dof aspect must lie between 0.01 and 100, got {self.dof_aspect:g}")
        if self.handedness not in (1.0, -1.0):
            raise InputError(f"handedness is 1 (right-handed) or -1 (left-handed, mirrored), got {self.handedness!r}")
        if self.entrance_pupil_mm is not None:
            require_finite("entrance pupil distance", self.entrance_pupil_mm)
        if self.horizontal_entrance_pupil_mm is not None:
            require_finite("horizontal entrance pupil distance", self.horizontal_entrance_pupil_mm)
        if self.principal_planes_mm is not None:
            for v in self.principal_planes_mm:
                require_finite("principal plane distance", v)
        if self.aperture_distance_mm is not None:
            require_finite("aperture distance", self.aperture_distance_mm)
        if self.pinhole_focal_length_mm is not None:
            require_positive("pinhole focal length", self.pinhole_focal_length_mm)
        if self.pinhole_squeeze is not None:
            require_positive("pinhole squeeze", self.pinhole_squeeze, unit="")
        if self.projection not in ("perspective", "orthographic"):
            raise InputError(f"projection must be perspective or orthographic, got {self.projection!r}")
        return self


def _camera_of_numbers(*, focal_length_mm, sensor_width_mm, sensor_height_mm, fstop, focus_mm, squeeze, lens_name,
                       sensor_name) -> CameraState:
    """The thin lens camera of the schema's numbers (checked as :meth:`CameraSpec.checked` checks them)."""
    from ..optics.lens_model import ThinLens
    from ..optics.sensors import Sensor
    from ..optics.state import camera_state

    for name, v in (("focal_length_mm", focal_length_mm), ("sensor_width_mm", sensor_width_mm),
                    ("sensor_height_mm", sensor_height_mm), ("fstop", fstop), ("focus_mm", focus_mm),
                    ("squeeze", squeeze)):
        require_positive(name, v, unit="")
    w, h = float(sensor_width_mm), float(sensor_height_mm)
    sensor = Sensor(key=sensor_name or _NAMELESS_SENSOR, name=sensor_name or f"{w:g} x {h:g} mm", width_mm=w,
                    height_mm=h)
    return camera_state(ThinLens(float(focal_length_mm), lens_name=lens_name), focus_mm=float(focus_mm),
                        fstop=float(fstop), sensor=sensor, squeeze=float(squeeze))


def _numbers_of(camera: CameraState) -> dict:
    """The schema's numbers of ``camera`` (:data:`CAMERA_VALUES`)."""
    at, s = camera.at_mark, camera.sensor
    return dict(focal_length_mm=at.focal_length_mm, sensor_width_mm=s.width_mm, sensor_height_mm=s.height_mm,
                fstop=camera.fstop, focus_mm=camera.focus_from_film_mm, squeeze=at.squeeze,
                lens_name=camera.lens_name, sensor_name=None if s.key == _NAMELESS_SENSOR else s.name)


def report_for_spec(spec: CameraSpec):
    """The on-set :class:`~physcam.onset.report.LensReport` of ``spec``.

    With principal planes (written from a datasheet or a prescription) it is the technical
    model with those planes and the pupil; otherwise the practical thin lens, keeping the
    spec's entrance pupil when it has one.
    """
    from ..onset.report import report_camera, solve_report

    require_type("spec", spec, CameraSpec, "build one with CameraSpec.of(...) or spec_from_report")
    common = dict(focal_length_mm=spec.focal_length_mm, sensor=spec.camera.sensor, fstop=spec.fstop, focus_mm=spec.focus_mm,
                  coc=spec.coc_mm, squeeze=spec.squeeze, lens_name=spec.lens_name,
                  pinhole_focal_length_mm=spec.pinhole_focal_length_mm, pinhole_squeeze=spec.pinhole_squeeze,
                  fstop_at_focus=spec.fstop_at_focus)
    if spec.principal_planes_mm is not None:
        h1, h2 = spec.principal_planes_mm
        return solve_report(report_camera(model="technical", h1_mm=h1, h2_mm=h2, pupil_mm=spec.entrance_pupil_mm,
                             **common))
    report = solve_report(report_camera(**common))
    if spec.entrance_pupil_mm is not None:
        report = dataclasses.replace(report, entrance_pupil_from_film_mm=spec.entrance_pupil_mm,
                                     entrance_pupil_source="USD file")
    return report


def spec_from_report(report, **body) -> CameraSpec:
    """A :class:`CameraSpec` holding the report's camera, with the report's planes and pupils, plus
    body/shutter/aperture keywords of CameraSpec."""
    from ..onset.report import LensReport

    require_type("report", report, LensReport, "solve one with physcam.onset.request.solve_report(report_camera(...))")
    return CameraSpec(
        report.camera,
        coc_mm=report.coc_mm,
        entrance_pupil_mm=(report.entrance_pupil_from_film_mm if report.entrance_pupil_from_film_mm is not None
                           else report.h1_from_film_mm),
        horizontal_entrance_pupil_mm=report.entrance_pupil_horizontal_from_film_mm,
        principal_planes_mm=((report.h1_from_film_mm, report.h2_from_film_mm) if report.model == "technical"
                             else None),
        aperture_distance_mm=report.stop_from_film_mm,
        dof_aspect=report.dof_aspect if report.entrance_pupil_source == "prescription" else None,
        fstop_at_focus=report.fstop_at_focus,
        # a prescription's best-match pinhole is kept; a thin lens or datasheet recomputes its own
        pinhole_focal_length_mm=report.pinhole_focal_length_mm if report.entrance_pupil_source == "prescription"
        else None,
        pinhole_squeeze=report.pinhole_squeeze if report.entrance_pupil_source == "prescription" else None,
        flange_distance_mm=body.pop("flange_distance_mm", report.flange_focal_distance_mm or 52.0),
        # a marked T-stop is the photometric f-number: T = N / sqrt(transmittance)
        transmittance=body.pop("transmittance", _transmittance(report.fstop, report.tstop)),
        **body,
    ).checked()


def _transmittance(fstop: float, tstop: float | None) -> float:
    """Transmittance from a geometric f-number and a marked T-stop, T = N / sqrt(t) (ASC Manual, "T-stops");
    1 without a T-stop. A T-stop faster than the f-stop (t > 1) is refused."""
    if tstop is None:
        return 1.0
    t = (fstop / tstop) ** 2
    if t > 1.0 + 1e-12:
        raise InputError(f"T-stop {tstop:g} is faster than the f-stop {fstop:g}: a lens cannot transmit more than "
                         "all the light (T >= N)")
    return min(t, 1.0)

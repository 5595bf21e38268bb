"""The composed PhysicalCamera's lens solved again at its focus and f-stop, as ``usd check`` and ``usd refresh``
compute a companion camera from it (:mod:`physcam.usd.kit` for a still lens, :mod:`physcam.usd.keyed_lens` at each
time code of a keyed one): a stored prescription's on-set report there (physcam.onset.report), a thin lens's
f / N, and the lens attributes that gives. Lengths in mm (docs/usd.md).
"""

from __future__ import annotations

from .author import LENS_INSTANCE
from .read import composed_prescription


def _lens_solved(stage, path, time: float | None = None):
    """(spec, prescription, report, derived): the composed camera at time code ``time`` (default: its default
    values) as a refresh computes the companion from it. With a stored prescription the lens is solved again at
    that focus and f-stop (``report``; ``derived``, :func:`~physcam.usd.author.spec_from_report` of it, holds
    the lens values a refresh writes) and ``spec`` carries them; a thin lens's iris is f / N (``report`` and
    ``derived`` None)."""
    from .author import spec_from_report
    from .read import read_camera

    spec = read_camera(stage, path, time=time).spec
    rx = composed_prescription(stage, path)
    if rx is None or spec.projection != "perspective":
        if spec.pinhole_focal_length_mm is None:  # no lens solved at a focus (a thin lens): the iris is f / N
            spec = spec.replaced(fstop_at_focus=None)
        return spec, rx, None, None
    from ..onset.report import report_camera, solve_report
    from ..optics.sensors import Sensor

    sensor = Sensor(key="custom", name=spec.sensor_name or f"{spec.sensor_width_mm:g} x {spec.sensor_height_mm:g} mm",
                    width_mm=spec.sensor_width_mm, height_mm=spec.sensor_height_mm)
    report = solve_report(report_camera(focal_length_mm=None, sensor=sensor, fstop=spec.fstop, focus_mm=spec.focus_mm,
                                        coc=spec.coc_mm, lens=rx))
    derived = spec_from_report(report)
    spec = spec.replaced(focal_length_mm=derived.focal_length_mm, entrance_pupil_mm=derived.entrance_pupil_mm,
                         principal_planes_mm=derived.principal_planes_mm,
                         pinhole_focal_length_mm=derived.pinhole_focal_length_mm,
                         pinhole_squeeze=derived.pinhole_squeeze, squeeze=derived.squeeze,
                         fstop_at_focus=derived.fstop_at_focus)
    return spec, rx, report, derived


#: the lens attributes a refresh derives from a stored prescription (:func:`_lens_derived_values`)
_LENS_DERIVED = tuple(f"lens:{LENS_INSTANCE}:{n}" for n in (
    "entrancePupilDistance", "iris", "pinholeFocalLength", "pinholeSqueeze", "horizontalEntrancePupilDistance",
    "apertureDistance", "frontPrincipalPlaneDistance", "rearPrincipalPlaneDistance"))


def _lens_derived_values(spec) -> dict:
    """Lens attribute -> value a prescription gives at the focus (``spec``: spec_from_report of its report);
    values the lens does not have (a second pupil, an unknown stop) are left out."""
    lp = f"lens:{LENS_INSTANCE}:"
    values = {lp + "entrancePupilDistance": spec.entrance_pupil_mm, lp + "iris": spec.focal_length_mm / spec.fstop,
              lp + "pinholeFocalLength": spec.pinhole_focal_length_mm, lp + "pinholeSqueeze": spec.pinhole_squeeze,
              lp + "horizontalEntrancePupilDistance": spec.horizontal_entrance_pupil_mm,
              lp + "apertureDistance": spec.aperture_distance_mm}  # the stop moves with a unit-focusing lens
    if spec.principal_planes_mm is not None:
        values[lp + "frontPrincipalPlaneDistance"] = spec.principal_planes_mm[0]
        values[lp + "rearPrincipalPlaneDistance"] = spec.principal_planes_mm[1]
    return {name: float(v) for name, v in values.items() if v is not None}


def _lens_model(stage, cam):
    rel = cam.GetRelationship(f"lens:{LENS_INSTANCE}:lensModel")
    targets = rel.GetForwardedTargets() if rel else []
    model = stage.GetPrimAtPath(targets[0]) if targets else None
    return model if model else None

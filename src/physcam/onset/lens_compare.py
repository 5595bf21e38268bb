"""Lenses side by side (``physcam compare``): what one lens does at a focus and f-stop on a sensor.

Field of view, depth of field and hyperfocal from the on-set report; breathing from infinity to the
closest focus (physcam.optics.focusing.breathing_table); real distortion and relative illumination at
the sensor's widest field (clamped to what the lens images); the bokeh of a point light on the axis
(its equivalent diameter). Each measurement that cannot be made says why in ``notes``.
"""

from __future__ import annotations

import math

from ..optics.state import CameraState, as_designed, camera_state, takes_camera

__all__ = ["fstop_for_comparison", "lens_measurements"]

#: How far below its widest f-number a lens may be asked to open before it is compared wide open: 1 %
#: (the engraved f-stop of a lens whose file gives f/2.8003 is f/2.8).
FSTOP_SLACK = 0.01


def fstop_for_comparison(lens, fstop) -> tuple[float, list[str]]:
    """(the f-stop to compare at, notes): ``fstop``, or wide open when None or faster than the lens."""
    from ..optics import paraxial

    wide = max(paraxial.gaussian(lens).f_number, lens.metadata.max_fstop or 0.0)
    if fstop is None:
        return wide, []
    if fstop < wide * (1 - FSTOP_SLACK):
        return wide, [f"opens only to f/{wide:.3g}: compared wide open (asked f/{fstop:g})"]
    return fstop, []


def _camera(lens, focus_mm, fstop):
    """(the lens, its mark, its f-stop, a function giving its camera state): the state is made when a
    measurement asks for it, so a Prescription's stop the lens cannot open to is that measurement's note."""
    from ..errors import InputError
    from ..optics.state import as_camera_state

    if isinstance(lens, CameraState):
        cam = as_camera_state(lens, focus_mm=focus_mm, fstop=fstop)
        return cam.lens, cam.focus_from_film_mm, cam.fstop, lambda: cam
    if focus_mm is None or fstop is None:
        raise InputError("give focus_mm and fstop with a lens (or a CameraState: physcam.optics.state.camera_state)")
    return lens, focus_mm, fstop, lambda: as_camera_state(lens, focus_mm=focus_mm, fstop=fstop)


@takes_camera
def lens_measurements(lens, *, focus_mm=None, fstop=None, sensor, coc=None, light_mm=None, rays=200_000) -> dict:
    """The comparison's figures of ``lens`` (a :class:`~physcam.optics.state.CameraState`, or a
    Prescription focused at ``focus_mm``, a mark from the film, inf allowed, at ``fstop``) on
    ``sensor``; curves for the figure under ``_curves``; ``notes``."""
    from .. import _program
    from .report import report_camera, solve_report

    _program.roomy_heap()  # the program's heap keeps freed pages: the illumination's and bokeh's ray arrays
    lens, focus_mm, fstop, state = _camera(lens, focus_mm, fstop)
    r = solve_report(report_camera(focal_length_mm=None, lens=lens, sensor=sensor, fstop=fstop, focus_mm=focus_mm,
                      coc=coc))
    real = r.to_dict()["fov_deg"]["real"] or {}
    out = {
        "lens": lens.name, "efl_mm": r.focal_length_mm, "fstop": r.fstop,
        "focus_from_film_mm": None if math.isinf(focus_mm) else focus_mm,
        "hfov_deg": r.hfov_focus_deg, "vfov_deg": r.vfov_focus_deg, "dfov_deg": r.dfov_focus_deg,
        "hfov_real_deg": real.get("horizontal"),
        "near_from_film_mm": r.dof.near_from_film_mm,
        "far_from_film_mm": None if r.dof.far_is_infinite else r.dof.far_from_film_mm,
        "dof_total_mm": None if r.dof.far_is_infinite else r.dof.total_mm,
        "hyperfocal_from_film_mm": r.dof.hyperfocal_from_film_mm,
        "entrance_pupil_from_film_mm": r.entrance_pupil_from_film_mm,
    }
    curves, notes = {}, []
    _breathing(lens, focus_mm, sensor, out, curves)
    _distortion(lens, sensor, out, curves, notes)
    _illumination(lens, state, sensor, out, curves, notes)
    _bokeh(state, focus_mm, light_mm, rays, out, curves, notes)
    out["notes"] = notes
    out["_curves"] = curves
    return out


def _breathing(lens, mark, sensor, out, curves) -> None:
    """Horizontal field of view from infinity to the close focus (the MOD, the focus groups' close point, or
    ten focal lengths for a unit-focusing lens without a MOD: physcam.optics.focusing.close_focus), and at
    this focus."""
    from ..optics import focusing

    cf = focusing.close_focus(lens)
    rows = focusing.breathing_table(lens, sensor_width_mm=sensor.width_mm)
    out["closest_focus_mm"] = cf.mark_mm
    out["closest_focus_source"] = cf.source
    out["minimum_object_distance_mm"] = lens.metadata.minimum_object_distance  # the maker's, maybe beyond the model
    out["breathing_near_mm"] = cf.breathing_near_mm
    out["breathing_closest_pct"] = rows[-1].fov_change_pct
    at = focusing.breathing_table(lens, [math.inf, mark], sensor_width_mm=sensor.width_mm)
    out["breathing_at_focus_pct"] = at[-1].fov_change_pct
    curves["breathing"] = ([r_.focus_from_film_mm for r_ in rows], [r_.fov_change_pct for r_ in rows])


def _distortion(lens, sensor, out, curves, notes) -> None:
    """Real distortion at the widest field the sensor asks for (clamped to what the lens images)."""
    from ..errors import PhysCamError
    from ..analysis.distortion.field import real_distortion

    try:
        dist = real_distortion(lens, sensor_width_mm=sensor.width_mm, sensor_height_mm=sensor.height_mm)
        pts = [p for p in dist.points if p.axis == "y"]
        out["distortion_field_deg"], out["distortion_pct"] = pts[-1].field_deg, pts[-1].distortion_pct
        curves["distortion"] = ([p.field_deg for p in pts], [p.distortion_pct for p in pts])
        notes += dist.notes
    except PhysCamError as exc:
        out["distortion_field_deg"] = out["distortion_pct"] = None
        notes.append(f"distortion not measured: {exc}")


def _illumination(lens, state, sensor, out, curves, notes) -> None:
    """Relative illumination at the state's iris to the sensor corner (clamped likewise)."""
    from ..errors import PhysCamError
    from ..analysis.image_quality.illumination import relative_illumination

    try:
        camera = as_designed(lens, stop_semi_diameter=state().stop_semi_diameter,
                             sensor_mm=(sensor.width_mm, sensor.height_mm))
        ri = relative_illumination(camera, grid=64)
        pts = [p for p in ri.points if p.axis == "y"]
        out["illumination_field_deg"], out["illumination_corner"] = pts[-1].field_deg, pts[-1].relative_illumination
        out["illumination_corner_stops"] = -math.log2(max(pts[-1].relative_illumination, 1e-12))
        curves["illumination"] = ([p.field_deg for p in pts], [p.relative_illumination for p in pts])
        notes += ri.notes
    except PhysCamError as exc:
        out["illumination_field_deg"] = out["illumination_corner"] = out["illumination_corner_stops"] = None
        notes.append(f"illumination not measured: {exc}")


def _bokeh(state, mark, light_mm, rays, out, curves, notes) -> None:
    """The bokeh of a point light on the axis (default: twice the focus, or 1 m focused at infinity)."""
    import numpy as np

    from ..errors import PhysCamError
    from ..analysis.defocus.blob import equivalent_diameter
    from ..analysis.defocus.bokeh import bokeh_image

    light = light_mm if light_mm is not None else (1000.0 if math.isinf(mark) else 2.0 * mark)
    out["bokeh_light_from_film_mm"] = light
    try:
        st = state()
        camera = camera_state(st.focused, film_z=st.film_z, stop_semi_diameter=st.stop_semi_diameter)
        img = bokeh_image(camera, light, rays=rays, pixels=96, chunk=min(max(rays, 1000), 250_000))
        mono = img.image.sum(axis=2) if img.image.ndim == 3 else img.image
        x0, x1, _, _ = img.extent_mm
        out["bokeh_diameter_mm"] = equivalent_diameter(mono, pixel=(x1 - x0) / mono.shape[1])
        curves["bokeh"] = (np.asarray(mono), img.extent_mm)
    except PhysCamError as exc:
        out["bokeh_diameter_mm"] = None
        notes.append(f"bokeh not measured: {exc}")

"""A camera as the tracer sees it (issue 43): built once from a
:class:`~physcam.optics.state.CameraState`, then asked by whoever traces that camera.

:func:`camera_tracer` reads the camera once: its focused prescription with the stop at the iris's working
semi-diameter (the radius a bladed iris's corners reach,
:attr:`~physcam.optics.state.CameraState.iris_corner_semi`; the round iris's radius for a round one), its
film plane and its iris shape. A :class:`CameraTracer` of a bare prescription (no camera: a focus state of
:func:`physcam.export.blender_focus.focus_table`) holds the same three. After that its users ask it, and
do not follow the tracer's own modules: the surface tables, scene side or film side first (each made on the
first ask and kept), the exit-pupil rectangles over a film window (:func:`physcam.trace.pupil_bounds.exit_pupil_bounds`),
camera rays (:func:`physcam.trace.trace.camera_rays`, pbrt-v4's ``RealisticCamera`` weight) and their mean
weight at the film centre, the normalisation a renderer divides by.

Lengths in mm, lens space (+z toward the film, docs/conventions.md); ``film_z`` is the film plane's z.
"""

from __future__ import annotations

import dataclasses
import functools

import numpy as np

from ..errors import require_type
from ..lens.prescription import Prescription
from ..optics.state import CameraState

__all__ = ["CameraTracer", "camera_tracer"]


@dataclasses.dataclass(frozen=True, eq=False)
class CameraTracer:
    """One focused lens, stopped to its iris, in front of one film plane: what a tracer of a camera holds."""

    lens: Prescription  # focused, the stop at its working semi-diameter
    film_z: float  # mm, lens space: the film plane
    aperture: object = None  # the iris shape (physcam.trace.aperture.Aperture) drawn inside the stop; None: round

    @functools.cached_property
    def scene_side_table(self):
        """The :class:`~physcam.trace.surfaces.SurfaceTable` front to back (rays from the scene), uncoated;
        made on the first ask and kept."""
        from .surfaces import surface_table

        return surface_table(self.lens, coating="none")

    @functools.cached_property
    def film_side_table(self):
        """The :class:`~physcam.trace.surfaces.SurfaceTable` film side first (the camera rays' order),
        uncoated; made on the first ask and kept."""
        from .surfaces import surface_table

        return surface_table(self.lens, reverse=True, coating="none")

    def exit_pupil_bounds(self, film_half_width: float, film_half_height: float, *, nx: int, ny: int,
                          samples: int):
        """:func:`physcam.trace.pupil_bounds.exit_pupil_bounds` of this lens at this film plane, over the
        film rectangle of the given half sizes (mm), on an ``nx`` x ``ny`` grid of ``samples``^2 aims."""
        from .pupil_bounds import exit_pupil_bounds

        return exit_pupil_bounds(self.lens, film_half_width, film_half_height, self.film_z, nx=nx, ny=ny,
                                 samples=samples)

    def stopped_pupil_bounds(self, stop_semi_diameters, film_half_width: float, film_half_height: float, *, nx: int,
                             ny: int, samples: int, mirror: bool = False) -> list:
        """:func:`physcam.trace.pupil_bounds.stopped_pupil_bounds`: :meth:`exit_pupil_bounds` with the stop
        set to each semi-diameter of the sequence (mm; None: this tracer's own), one trace for them all
        (``mirror``: a quarter of the film nodes traced, the rest mirrored)."""
        from .pupil_bounds import stopped_pupil_bounds

        return stopped_pupil_bounds(self.lens, stop_semi_diameters, film_half_width, film_half_height, self.film_z,
                                    nx=nx, ny=ny, samples=samples, mirror=mirror)

    def iris_camera_rays(self, film_xy, pupil_samples, stop_semi_diameters, *, bounds=None):
        """:func:`physcam.trace.pupil_bounds.iris_camera_rays`: camera rays for several round irises (mm) in one
        trace, and which pass each (this tracer's iris shape is not drawn: the irises are round)."""
        from .pupil_bounds import iris_camera_rays

        return iris_camera_rays(self.lens, film_xy, pupil_samples, self.film_z, stop_semi_diameters, bounds=bounds)

    def camera_rays(self, film_xy, pupil_samples, *, bounds=None, fresnel: bool = False):
        """:func:`physcam.trace.trace.camera_rays` from this film plane through this lens and iris shape."""
        from .trace import camera_rays

        return camera_rays(self.lens, film_xy, pupil_samples, self.film_z, bounds=bounds, aperture=self.aperture,
                           fresnel=fresnel)

    def centre_weight(self, bounds, *, samples: int, fresnel: bool = False) -> float:
        """The mean camera-ray weight at the film centre over a stratified ``samples`` x ``samples`` grid
        of aims in ``bounds`` (cell centres): what a renderer divides by so that the centre renders 1."""
        u = (np.arange(samples) + 0.5) / samples
        uu, vv = [a.ravel() for a in np.meshgrid(u, u)]
        cr = self.camera_rays(np.zeros((uu.size, 2)), np.stack([uu, vv], axis=1), bounds=bounds, fresnel=fresnel)
        return float(np.mean(cr.weight))


def camera_tracer(camera: CameraState) -> CameraTracer:
    """The tracer of ``camera`` (a :class:`~physcam.optics.state.CameraState` on a prescription): its
    focused lens with the stop at :attr:`~physcam.optics.state.CameraState.iris_corner_semi`, its film
    plane and its iris shape (module notes)."""
    require_type("camera", camera, CameraState, "physcam.optics.state.camera_state(lens, focus_mm=..., fstop=...)")
    q = camera.focused
    k = q.stop_index
    semi = camera.iris_corner_semi
    if semi != q.surfaces[k].semi_diameter:
        s = list(q.surfaces)
        s[k] = dataclasses.replace(s[k], semi_diameter=semi)
        q = q.with_surfaces(s)
    return CameraTracer(q, float(camera.film_z), camera.aperture)

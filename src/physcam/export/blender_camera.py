"""Blender's built-in perspective camera that best matches a lens report (pure numbers, no bpy).

For users who want speed over optics: Cycles' and EEVEE's camera is a pinhole with a thin-lens
blur. It frames by ``lens`` (mm) over the sensor and blurs with an aperture of radius
``lens / (2 aperture_fstop)`` placed at the camera, focused ``focus_distance`` metres from the
camera (Blender manual, "Cameras": Lens, Sensor, Depth of Field). physcam authors:

* ``lens``: the **best-match pinhole** at the focus mark (docs/lens-report.md), not the EFL: like
  other renderers, Blender keeps the field of view of its ``lens`` whatever the focus, so with
  the EFL a thin lens focused at s would frame (s - f)/s too wide and blur (s - f)/s too little
  (2.5 % at 2 m for 50 mm). With the pinhole f_pin (s' for a thin lens, breathing included for a
  prescription) both match;
* ``aperture_fstop`` = N f_pin / EFL, so ``lens / aperture_fstop`` is the entrance-pupil diameter
  EFL / N: the blur angle seen from the camera, A |1/d - 1/s|, is the lens's, and on the film
  f_pin A |1/d - 1/s| is the thin lens's exact blur (``physcam.export.usdgeom.pinhole_fstop``);
* ``focus_distance``: from the camera, which physcam places at the entrance pupil: the focus
  mark minus the pupil's distance from the film, in metres. The script's ``apply`` reads the scene
  camera's place as the **film plane** (as physcam's PhysicalCamera body does) and moves the camera
  object forward to the pupil under an Empty "<camera> film plane" that keeps the film's place (run
  again, it only updates the offset); ``apply(scene, camera_at="pupil")`` leaves a camera that is
  already at the pupil where it is;
* ``sensor_width``/``sensor_height`` with ``sensor_fit`` "HORIZONTAL" (the desqueezed width for an
  anamorphic) and the render resolution of the same aspect; ``shift_x``/``shift_y`` as fractions
  of the sensor width (Blender's shift is relative to the larger frame side, the width here);
* ``aperture_blades``, ``aperture_rotation`` (radians) and ``aperture_ratio``: Cycles' polygon has a
  flat side, not a corner, toward +x at rotation 0 (its corners at +-180/N degrees: kernel
  ``regular_polygon_sample``), so a corner ``blade_rotation_deg`` from +x (physcam's and RenderMan's
  apertureAngle) is a rotation of blade_rotation_deg + 180/N; Blender's ratio above 1 stretches the
  bokeh vertically, so it is 1 / ``report.dof_aspect`` (2 for a front 2x anamorphic's tall oval
  bokeh, 1 for a rear anamorphic's round one).
"""

from __future__ import annotations

import math

from ..errors import InputError, require_finite
from ..onset.report import takes_report
from ._codetext import python_docstring
from .usdgeom import focus_distance_from_pupil_mm, pinhole_fstop

__all__ = ["blender_camera_values", "blender_camera_script", "blender_blade_rotation_deg"]


def blender_blade_rotation_deg(blades: int, corner_angle_deg: float) -> float:
    """Blender's ``aperture_rotation`` (degrees) that puts a corner of an N-blade iris ``corner_angle_deg``
    from +x: Cycles draws its polygon with a flat side toward +x at rotation 0 (module notes)."""
    a = require_finite("blade rotation", corner_angle_deg)
    return a + 180.0 / blades if blades >= 3 else a


@takes_report
def blender_camera_values(report, *, resolution_x: int = 1920, shift_mm=(0.0, 0.0), blades: int = 0,
                          blade_rotation_deg: float = 0.0) -> dict:
    """Blender camera and render settings for ``report`` (module notes): names as in bpy."""
    if isinstance(resolution_x, bool) or not isinstance(resolution_x, int) or not 16 <= resolution_x <= 65536:
        raise InputError(f"resolution_x must be a whole number of pixels from 16 to 65536, got {resolution_x!r}")
    if isinstance(blades, bool) or not isinstance(blades, int) or not (blades == 0 or 3 <= blades <= 64):
        raise InputError(f"aperture blades must be 0 (round) or 3 to 64, got {blades!r}")
    sx, sy = (require_finite("sensor shift", v) for v in shift_mm)
    f_pin, sq = report.pinhole
    w, h = report.sensor.width_mm * sq, report.sensor.height_mm
    res_y = max(1, round(resolution_x * h / w))
    return {
        "camera": {
            "type": "PERSP",
            "lens_unit": "MILLIMETERS",
            "lens": f_pin,
            "sensor_fit": "HORIZONTAL",
            "sensor_width": w,
            "sensor_height": h,
            "shift_x": sx * sq / w,
            "shift_y": sy / w,
            "dof.use_dof": True,
            "dof.focus_distance": focus_distance_from_pupil_mm(report) / 1000.0,
            "dof.aperture_fstop": pinhole_fstop(report),
            "dof.aperture_blades": blades,
            "dof.aperture_rotation": math.radians(blender_blade_rotation_deg(blades, blade_rotation_deg)),
            "dof.aperture_ratio": 1.0 / report.dof_aspect,
        },
        "render": {"resolution_x": resolution_x, "resolution_y": res_y, "pixel_aspect_x": 1.0,
                   "pixel_aspect_y": 1.0},
        "entrance_pupil_from_film_mm": report.entrance_pupil_from_film_mm,
        "notes": ["the camera object sits at the entrance pupil, "
                  f"{(report.entrance_pupil_from_film_mm or 0.0):.2f} mm in front of the film plane: apply() reads the "
                  "camera's place as the film plane and moves it there (camera_at='pupil' keeps it)"],
    }


def blender_camera_script(values: dict, *, comments=()) -> str:
    """A Python script applying :func:`blender_camera_values` to a Blender scene's camera.

    Run as ``blender --python camera.py`` or import it and call ``apply(scene)``; ``comments`` (lines)
    go into its docstring.
    """
    import json

    head = "".join("\n" + python_docstring(line) for c in comments for line in str(c).splitlines() or [""])
    return f'''"""Made by physcam: Blender's built-in camera matched to a lens report (docs/blender.md).{head}
"""
import json

VALUES = json.loads({json.dumps(json.dumps(values))})
FILM_PLANE = "physcam_film_plane"  # custom property marking the Empty that keeps the film plane's place


def _to_pupil(obj, scene):
    """The camera object forward of the film plane by the entrance pupil's distance (module notes)."""
    import bpy

    pupil_mm = VALUES["entrance_pupil_from_film_mm"] or 0.0
    bpy.context.view_layer.update()  # matrix_world is stale until the depsgraph updates
    film = obj.parent if obj.parent is not None and obj.parent.get(FILM_PLANE) else None
    if film is None:
        film = bpy.data.objects.new(obj.name + " film plane", None)
        film[FILM_PLANE] = True
        for coll in obj.users_collection:
            coll.objects.link(film)
        film_matrix = obj.matrix_world.copy()
        film.parent = obj.parent  # the film plane takes the camera's place in its hierarchy
        film.matrix_world = film_matrix
        obj.parent = film
        obj.matrix_parent_inverse.identity()
    obj.location = (0.0, 0.0, -pupil_mm / 1000.0 / (scene.unit_settings.scale_length or 1.0))
    obj.rotation_euler = (0.0, 0.0, 0.0)
    obj.scale = (1.0, 1.0, 1.0)


def apply(scene=None, camera_at="film"):
    """Set the scene camera; ``camera_at="film"``: its place is the film plane (moved to the pupil)."""
    import bpy

    scene = scene or bpy.context.scene
    if camera_at not in ("film", "pupil"):
        raise ValueError("camera_at is 'film' (the camera marks the film plane) or 'pupil'")
    if camera_at == "film":
        _to_pupil(scene.camera, scene)
    cam = scene.camera.data
    for key, value in VALUES["camera"].items():
        target = cam
        parts = key.split(".")
        for part in parts[:-1]:
            target = getattr(target, part)
        setattr(target, parts[-1], value)
    for key, value in VALUES["render"].items():
        setattr(scene.render, key, value)
    scene.render.resolution_percentage = 100
    return cam


if __name__ == "__main__":
    apply()
'''

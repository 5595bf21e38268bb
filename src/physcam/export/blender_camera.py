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
  mark minus the pupil's distance from the film, in metres;
* ``sensor_width``/``sensor_height`` with ``sensor_fit`` "HORIZONTAL" (the desqueezed width for an
  anamorphic) and the render resolution of the same aspect; ``shift_x``/``shift_y`` as fractions
  of the sensor width (Blender's shift is relative to the larger frame side, the width here);
* ``aperture_blades``, ``aperture_rotation`` (radians) and ``aperture_ratio``: Blender's ratio
  above 1 stretches the bokeh vertically, so it is 1 / ``report.dof_aspect`` (2 for a front 2x
  anamorphic's tall oval bokeh, 1 for a rear anamorphic's round one).
"""

from __future__ import annotations

import math

from ..errors import InputError, require_finite
from ..onset.report import takes_report
from .usdgeom import focus_distance_from_pupil_mm, pinhole_fstop

__all__ = ["blender_camera_values", "blender_camera_script"]


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
            "dof.aperture_rotation": math.radians(require_finite("blade rotation", blade_rotation_deg)),
            "dof.aperture_ratio": 1.0 / report.dof_aspect,
        },
        "render": {"resolution_x": resolution_x, "resolution_y": res_y, "pixel_aspect_x": 1.0,
                   "pixel_aspect_y": 1.0},
        "entrance_pupil_from_film_mm": report.entrance_pupil_from_film_mm,
        "notes": ["the camera object sits at the entrance pupil; the film plane is "
                  f"{(report.entrance_pupil_from_film_mm or 0.0):.2f} mm behind it"],
    }


def blender_camera_script(values: dict) -> str:
    """A Python script applying :func:`blender_camera_values` to a Blender scene's camera.

    Run as ``blender --python camera.py`` or import it and call ``apply(scene)``.
    """
    import json

    return f'''"""Made by physcam: Blender's built-in camera matched to a lens report (docs/blender.md)."""
import json

VALUES = json.loads({json.dumps(json.dumps(values))})


def apply(scene=None):
    import bpy

    scene = scene or bpy.context.scene
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

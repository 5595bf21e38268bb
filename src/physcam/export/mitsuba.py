"""Mitsuba 3's ``thinlens`` sensor matched to a lens report (pure numbers, no ``mitsuba`` import).

Mitsuba's thin lens (``src/sensors/thinlens.cpp``) is a pinhole of horizontal field ``fov`` with a
disk aperture of radius ``aperture_radius`` (scene units) at the camera origin; a ray for a film
point starts on the disk and passes through where the *pinhole* ray of that film point meets the
plane ``z = focus_distance``. Its field of view therefore never changes with focus: it is the
field at infinity focus when ``fov`` is computed from the focal length.

**Why not the focal length.** A point on the axis at distance d (from the camera) is drawn as a
disk. With pinhole focal length F (the film width W spans ``fov``: F = W / (2 tan(fov/2))), an
aperture of diameter A = 2 ``aperture_radius`` and focus distance s, the disk on the film has
diameter

    c_mitsuba = F A |1/d - 1/s|

(the ray from aperture point a through the focus-plane point q passes the axis at depth d when
q = a (1 - s/d); q images at F q / s on the film). A real thin lens of focal length f and entrance
pupil A, focused at s (image at s', 1/s + 1/s' = 1/f), blurs the same point into
c = A s' |1/d - 1/s| on its film (similar triangles behind the lens). Authored with F = f (the
infinity field of view) Mitsuba frames s'/f = s/(s - f) too wide and blurs s/(s - f) too little:
2.5 % for 50 mm at 2 m.

**What physcam authors.** F = the report's best-match pinhole (``report.pinhole``; s' for a thin
lens, breathing included for a prescription; docs/lens-report.md) and A = the entrance pupil
diameter f / N, so both the framing and the disk, F A |1/d - 1/s| = s' A |1/d - 1/s|, are the
lens's. Concretely:

* ``fov`` = 2 atan(W / (2 F)) in degrees with ``fov_axis`` ``"x"``: the report's horizontal field
  at focus (``hfov_focus_deg``), W the (desqueezed) film width;
* ``aperture_radius`` = f / (2 N) in scene units (the entrance pupil, not F / (2 N): scaling the
  aperture instead of the field would match the blur but not the framing);
* ``focus_distance`` = focus mark - entrance pupil distance from the film, in scene units:
  Mitsuba measures it from the camera, which physcam places at the entrance pupil
  (``to_world``: a look-at from (0, 0, -p) down -Z, +Y up, in physcam camera space, whose origin is
  the film centre; docs/conventions.md);
* the ``hdrfilm`` width and height in pixels, of the film's aspect; ``near_clip``/``far_clip``
  (10 mm and 10 km: Mitsuba's defaults are 0.01 and 10^4 *scene units*, 100 m in a centimetre
  scene) and the shutter interval in seconds (``shutter_close`` = angle / 360 / fps).

Mitsuba cannot hold everything a lens report can: its aperture is a round disk (no oval
anamorphic bokeh: refused) and ``thinlens`` has no principal-point offset (a sensor shift is
refused; ``perspective`` has one but no depth of field). A rear anamorphic (round bokeh) is
rendered desqueezed, on square pixels.
"""

from __future__ import annotations

import math

from ..errors import ExportError, InputError, require_finite, require_positive
from ..onset.report import takes_report
from ._codetext import xml_attribute, xml_comment
from .usdgeom import DEFAULT_METERS_PER_UNIT, focus_distance_from_pupil_mm, mm_to_scene_units, shutter_interval

__all__ = ["mitsuba_camera_values", "mitsuba_scene_xml", "mitsuba_scene_dict"]

#: near and far clipping distances physcam authors, mm from the camera (the entrance pupil)
CLIP_RANGE_MM = (10.0, 1.0e7)
#: most pixels across the film physcam writes (Mitsuba's own limit is memory)
MAX_WIDTH_PX = 65536


def _int_in(name: str, value, lo: int, hi: int) -> int:
    if isinstance(value, bool) or not isinstance(value, int) or not lo <= value <= hi:
        raise InputError(f"{name} must be a whole number from {lo} to {hi}, got {value!r}")
    return value


@takes_report
def mitsuba_camera_values(report, *, width_px: int = 1920, meters_per_unit: float = DEFAULT_METERS_PER_UNIT,
                          spp: int = 64, shutter_angle_deg: float = 180.0, fps: float = 24.0,
                          shift_mm=(0.0, 0.0)) -> dict:
    """The ``thinlens`` sensor for ``report`` (module notes) as plain JSON-ready numbers.

    Returns ``{"sensor": {...}, "physcam": {...}}``: ``sensor`` is Mitsuba's own dictionary
    (``mi.load_dict`` form) except ``to_world``, a row-major 4x4 matrix list
    (``mi.ScalarTransform4f(sensor["to_world"])`` turns it into Mitsuba's transform); ``physcam``
    says where the numbers come from. Lengths in the sensor are scene units of
    ``meters_per_unit`` metres. Raises :class:`ExportError` for what Mitsuba cannot render.
    """
    w_px = _int_in("width_px", width_px, 16, MAX_WIDTH_PX)
    n_spp = _int_in("spp", spp, 1, 1 << 20)
    a, d = shutter_interval(shutter_angle_deg)
    rate = require_positive("fps", fps, unit="frames per second")
    sx, sy = (require_finite("sensor shift", v) for v in shift_mm)
    if sx or sy:
        raise ExportError("Mitsuba 3's thinlens sensor has no principal-point offset, so it cannot hold a sensor "
                          f"shift ({sx:g}, {sy:g}) mm; render without --shift-x/--shift-y (its perspective sensor "
                          "can shift, but has no depth of field)")
    if not math.isfinite(report.focus_from_film_mm):
        raise ExportError("Mitsuba 3's thinlens needs a finite focus_distance; give a finite focus (e.g. 1000m)")
    if abs(report.dof_aspect - 1.0) > 1e-9:
        raise ExportError(f"Mitsuba 3's thinlens aperture is a round disk: it cannot render this lens's oval bokeh "
                          f"(width/height {report.dof_aspect:.3g}, a front anamorphic); use a renderer with an "
                          "aperture aspect (RenderMan's dofaspect, Blender's aperture_ratio)")
    su = lambda mm: mm_to_scene_units(mm, meters_per_unit)  # noqa: E731
    f_pin, sq = report.pinhole
    width_mm = report.sensor.width_mm * sq  # the desqueezed picture
    height_mm = report.sensor.height_mm
    h_px = max(1, round(w_px * height_mm / width_mm))
    fov = math.degrees(2.0 * math.atan(width_mm / (2.0 * f_pin)))
    if not 0.0 < fov < 180.0:
        raise ExportError(f"Mitsuba 3's fov must lie strictly between 0 and 180 degrees, got {fov:g}")
    pupil = report.entrance_pupil_from_film_mm or report.h1_from_film_mm
    focus_mm = focus_distance_from_pupil_mm(report)
    if not focus_mm > 0:
        raise ExportError(f"the focus plane lies {focus_mm:g} mm from the entrance pupil; Mitsuba's focus_distance "
                          "must be positive")
    ep = report.aperture_diameter_mm
    z = -su(pupil)
    sensor = {
        "type": "thinlens",
        "fov": fov,
        "fov_axis": "x",
        "aperture_radius": su(ep / 2.0),
        "focus_distance": su(focus_mm),
        "near_clip": su(CLIP_RANGE_MM[0]),
        "far_clip": su(CLIP_RANGE_MM[1]),
        "shutter_open": a / rate,
        "shutter_close": d / rate,
        "to_world": [[-1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0], [0.0, 0.0, -1.0, z], [0.0, 0.0, 0.0, 1.0]],
        "film": {"type": "hdrfilm", "width": w_px, "height": h_px},
        "sampler": {"type": "independent", "sample_count": n_spp},
    }
    vfov_rendered = math.degrees(2.0 * math.atan(math.tan(math.radians(fov) / 2.0) * h_px / w_px))
    notes = ["the camera (Mitsuba's aperture disk) sits at the entrance pupil, "
             f"{pupil:.3f} mm in front of the film plane; scene objects in physcam camera space "
             "(film centre at the origin, looking down -Z, +Y up)"]
    if sq != 1.0:
        notes.append(f"anamorphic {sq:g}x: Mitsuba renders the desqueezed picture on square pixels")
    if report.real_fov_differs:
        notes.append("thinlens is a pinhole with a blur: it shows the pinhole field of view, not the real lens's "
                     "(fov_deg.real in the lens report)")
    physcam = {
        "lens": report.lens_name,
        "meters_per_unit": meters_per_unit,
        "focal_length_mm": report.focal_length_mm,
        "fstop": report.fstop,
        "pinhole_focal_length_mm": f_pin,
        "entrance_pupil_diameter_mm": ep,
        "entrance_pupil_from_film_mm": pupil,
        "focus_from_film_mm": report.focus_from_film_mm,
        "focus_from_pupil_mm": focus_mm,
        "film_mm": [width_mm, height_mm],
        "hfov_deg": fov,
        "vfov_deg": report.vfov_focus_deg,
        "vfov_deg_rendered": vfov_rendered,
        "hfov_infinity_deg": report.hfov_inf_deg,
        "definition": "fov: the best-match pinhole at the entrance pupil (the field of the focused lens), "
                      "aperture_radius: half the entrance pupil f/N; so the defocus disk F A |1/d - 1/s| is the "
                      "lens's s' A |1/d - 1/s| (docs/mitsuba.md)",
        "notes": notes,
    }
    for k, v in sensor.items():
        if isinstance(v, float) and not math.isfinite(v):
            raise InputError(f"Mitsuba {k} came out {v}; check the report and --meters-per-unit")
    return {"sensor": sensor, "physcam": physcam}


def _num(v: float) -> str:
    return repr(float(v))


def mitsuba_scene_xml(values: dict) -> str:
    """A Mitsuba 3 scene file (XML, ``version="3.0.0"``) holding the sensor of
    :func:`mitsuba_camera_values`; load it with ``mi.load_file`` or ``<include>`` it in a scene."""
    s = _sensor_of(values)
    z = s["to_world"][2][3]
    film, sampler = s["film"], s["sampler"]
    pc = values.get("physcam", {}) if isinstance(values.get("physcam"), dict) else {}
    comment = xml_comment(f"physcam: {pc.get('lens') or 'thin lens'}; {pc.get('definition', '')}")
    floats = "".join(f'        <float name="{k}" value="{_num(s[k])}"/>\n'
                     for k in ("fov", "aperture_radius", "focus_distance", "near_clip", "far_clip", "shutter_open",
                               "shutter_close"))
    return (
        '<?xml version="1.0" encoding="utf-8"?>\n'
        f"<!-- {comment} -->\n"
        '<scene version="3.0.0">\n'
        '    <sensor type="thinlens" id="physcam_camera">\n'
        f"{floats}"
        f'        <string name="fov_axis" value="{xml_attribute(s["fov_axis"])}"/>\n'
        '        <transform name="to_world">\n'
        f'            <lookat origin="0, 0, {_num(z)}" target="0, 0, {_num(z - 1.0)}" up="0, 1, 0"/>\n'
        "        </transform>\n"
        f'        <sampler type="{xml_attribute(sampler["type"])}">\n'
        f'            <integer name="sample_count" value="{int(sampler["sample_count"])}"/>\n'
        "        </sampler>\n"
        f'        <film type="{xml_attribute(film["type"])}">\n'
        f'            <integer name="width" value="{int(film["width"])}"/>\n'
        f'            <integer name="height" value="{int(film["height"])}"/>\n'
        "        </film>\n"
        "    </sensor>\n"
        "</scene>\n"
    )


def mitsuba_scene_dict(values: dict) -> dict:
    """The scene dictionary physcam writes as JSON: ``{"type": "scene", "sensor": {...}}`` plus the
    ``physcam`` notes (``mi.load_dict`` needs ``to_world`` made a transform first; docs/mitsuba.md)."""
    s = _sensor_of(values)
    return {"type": "scene", "sensor": s, "physcam": values.get("physcam", {})}


def _sensor_of(values) -> dict:
    from ..errors import require_type

    require_type("values", values, dict, "make them with mitsuba_camera_values(report)")
    s = values.get("sensor")
    if not isinstance(s, dict) or s.get("type") != "thinlens" or not isinstance(s.get("to_world"), list):
        raise InputError("values must come from mitsuba_camera_values (a 'sensor' of type thinlens)")
    return s

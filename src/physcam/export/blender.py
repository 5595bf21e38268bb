"""A real-lens camera for Blender Cycles: one self-contained OSL camera shader per lens and focus.

:func:`osl_camera_shader` writes the OSL source of a Cycles custom camera (``camera.data.type =
"CUSTOM"``) that traces every camera ray from the film through the lens as physcam's tracer does
(:func:`physcam.trace.camera_rays`): the focused prescription (physcam's focus solution), the
surface rows of :func:`physcam.trace.surfaces.surface_table` baked as arrays sized to the lens,
the same intersections (quadric root nearest the vertex, even asphere by Newton iteration), clipping
at semi-diameters and at the stop with the aperture shape, Snell refraction, TIR, optional
per-sample wavelength with the exact index formula of :func:`physcam.optics.glass.evaluate`, and
optional unpolarised Fresnel transmission (s and p carried separately). Rays are aimed at the exit
pupil through a table of physcam's :func:`~physcam.trace.pupil_bounds.exit_pupil_bounds`, and each
carries physcam's weight cos^4(theta) A / d^2 divided by its mean at the image centre (a uniform
white scene renders 1 at the centre; the falloff elsewhere is physcam's relative illumination).

Conventions (verified by rendering, ``tests/blender/test_blender_camera.py``, docs/blender.md):

- Cycles' OSL camera space: +X right, +Y up, **+Z toward the scene** (Blender's camera object
  looks down its local -Z; the OSL frame is that frame with Z negated), lengths in scene units
  (metres at the default unit scale). physcam's lens space is x right, y up, +z toward the film,
  mm, so a lens-space point (x, y, z) becomes (x, y, film_z - z) / 1000 and a direction
  (L, M, N) becomes (L, M, -N). The camera object's origin is the film centre.
- ``camera_shader_raster_position()`` is (0, 0) at the bottom-left of the rendered image and
  (1, 1) at the top-right. The lens inverts the image, so raster (u, v) reads the film at
  (-(2u - 1) w/2, -(2v - 1) h/2): the rendered picture is upright, as on a camera's monitor.
- The render is the film image: an anamorphic's picture comes out squeezed (desqueeze in comp).

OSL works in 32-bit floats: the even-asphere Newton iteration stops at a step below
1e-5 (1 + |t|) mm instead of the float64 tracer's 1e-12 mm.
"""

from __future__ import annotations

import dataclasses
import math
import re
from pathlib import Path

import numpy as np

from ..errors import InputError, require_positive, require_type
from ..lens.prescription import Prescription
from ..optics.state import CameraState, takes_camera
from ._codetext import osl_comment, python_docstring
from .osl import WAVELENGTH_RANGE_NM, osl_array, osl_number

__all__ = ["BakedCamera", "bake_camera", "osl_camera_shader", "blender_setup_script", "write_blender_camera",
           "iris_corner_semi", "PUPIL_GRID", "WAVELENGTH_RANGE_NM"]

#: Film grid of the baked exit-pupil table (nodes per axis).
PUPIL_GRID = (9, 9)


@dataclasses.dataclass
class BakedCamera:
    """What the shader bakes in of ``camera``: the focused, stopped-down prescription and everything derived."""

    lens: Prescription  # focused, with the stop at its working semi-diameter
    film_z: float  # mm, lens space
    table: object  # SurfaceTable, film side first (tracing order)
    bounds: object  # PupilBounds on the rear vertex plane
    aperture: object  # Aperture or None
    norm: float  # mean camera_rays weight at the film centre
    sensor_width_mm: float
    sensor_height_mm: float
    camera: CameraState  # the camera baked: its focus mark (.focus_mm) and f-stop (.fstop)
    wavelength_nm: float

    @property
    def focus_mm(self) -> float:
        """The camera's focus mark in front of the film (inf at infinity)."""
        return self.camera.focus_from_film_mm

    @property
    def fstop(self) -> float | None:
        """The f-stop the shader's header names: None ("open") when the iris is the file's own stop."""
        return _fstop_label(self.camera)


def _aperture(aperture):
    from ..trace.aperture import Aperture

    if aperture is None or isinstance(aperture, Aperture):
        return aperture
    if isinstance(aperture, dict):
        try:
            return Aperture(**aperture)
        except TypeError as e:
            raise InputError(f"aperture keys are nsides, angle_deg, roundness, density ({e})") from None
    if isinstance(aperture, (tuple, list)) and 1 <= len(aperture) <= 4:
        return Aperture(*aperture)
    if isinstance(aperture, (int, np.integer)) and not isinstance(aperture, bool):
        return Aperture(int(aperture))
    raise InputError("aperture must be a physcam.trace.aperture.Aperture, a number of blades, "
                     "a tuple (blades, angle_deg, roundness, density) or a dict of those")


def _state(camera: CameraState, aperture=None) -> CameraState:
    """The camera the shader bakes (one place for :func:`bake_camera`, :func:`write_blender_camera` and
    :func:`physcam.export.blender_compare.compare_bokeh`): it needs a sensor; ``aperture`` (as in
    :func:`osl_camera_shader`) replaces its iris shape."""
    if camera.sensor_mm is None:
        raise InputError("the Blender camera needs a sensor: camera_state(lens, ..., sensor_mm=(width, height))")
    ap = _aperture(camera.aperture if aperture is None else aperture)
    return camera if ap is camera.aperture else camera.with_aperture(ap)


def _fstop_label(state: CameraState) -> float | None:
    """The f-stop the shader's header names: None ("open") when the iris is the file's own stop."""
    return state.fstop if state.iris_set else None


@takes_camera
def bake_camera(camera: CameraState, *, aperture=None, fresnel: bool = False) -> BakedCamera:
    """Tabulate what the OSL camera needs for ``camera``: a :class:`~physcam.optics.state.CameraState`
    with a sensor (see :func:`osl_camera_shader`; physcam's focus, :func:`physcam.optics.focusing.focus`:
    internal focusing when the lens has focus groups, else unit focusing). Raises
    :class:`~physcam.errors.OpticsError` for a focus closer than the lens reaches or an f-number faster
    than it opens."""
    return _bake(_state(camera, aperture), fresnel)


def iris_corner_semi(state: CameraState) -> float:
    """The stop radius (mm) the iris's corners reach in the shader and in its bokeh comparison:
    :attr:`physcam.optics.state.CameraState.iris_corner_semi` (a bladed iris has the area of the round
    iris of the f-number, docs/conventions.md)."""
    require_type("state", state, CameraState, "physcam.optics.state.camera_state(lens, focus_mm=..., fstop=..., sensor=...)")
    return state.iris_corner_semi


def _bake(state: CameraState, fresnel: bool) -> BakedCamera:
    """What the shader bakes of ``state``, asked of its tracer (:func:`physcam.trace.camera_tracer.camera_tracer`:
    the focused lens stopped to the iris's corners, the film plane, the iris shape): the surface table, the
    exit-pupil rectangles over the sensor and the mean weight at the film centre the shader divides by."""
    from ..trace.camera_tracer import camera_tracer

    tracer = camera_tracer(state)
    sw, sh = state.sensor_mm
    nx, ny = PUPIL_GRID
    bounds = tracer.exit_pupil_bounds(sw / 2, sh / 2, nx=nx, ny=ny, samples=64)
    norm = tracer.centre_weight(bounds, samples=128, fresnel=fresnel)  # a stratified 128^2 grid of aims
    if not norm > 0:
        from ..errors import OpticsError

        raise OpticsError(f"no ray from the film centre passes through {state.lens_name!r} at this focus and stop")
    return BakedCamera(tracer.lens, tracer.film_z, tracer.film_side_table, bounds, tracer.aperture, norm, sw, sh, state,
                       float(state.lens.wavelength_nm))


_num = osl_number
_arr = osl_array


def _ident(name: str) -> str:
    s = re.sub(r"[^0-9A-Za-z]+", "_", name).strip("_").lower() or "lens"
    return s if not s[0].isdigit() else "lens_" + s


@takes_camera
def osl_camera_shader(camera: CameraState, *, aperture=None, dispersion: bool = False, fresnel: bool = False) -> str:
    """OSL source of a Cycles camera shader that traces real rays through ``camera``: a
    :class:`~physcam.optics.state.CameraState` with a sensor (the lens focused at its mark, mm in front
    of the film plane, stopped to its f-stop or as its file stops it).

    ``aperture``: an :class:`~physcam.trace.aperture.Aperture` (blades, angle, roundness, density),
    a number of blades, or a tuple/dict of its fields; ``None`` the round stop (or the state's).
    ``dispersion`` samples one wavelength per ray, uniform over :data:`WAVELENGTH_RANGE_NM`, with the
    exact index of each medium, and colours it with three tent functions (peaks 450, 550, 650 nm; they
    sum to 1 at every wavelength, so white light stays white); ``fresnel`` multiplies the unpolarised
    Fresnel transmission (uncoated surfaces). The code is the template ``osl/physcam_lens.osl.in``
    with this lens's data block (:mod:`physcam.export.osl`). See the module docstring for the conventions.
    """
    _check_switches(dispersion, fresnel)
    b = bake_camera(camera, aperture=aperture, fresnel=fresnel)
    return _emit(b, dispersion=dispersion, fresnel=fresnel)


def _check_switches(dispersion, fresnel) -> None:
    if not isinstance(dispersion, bool) or not isinstance(fresnel, bool):
        raise InputError("dispersion and fresnel must be True or False")


def _emit(b: BakedCamera, *, dispersion: bool, fresnel: bool) -> str:
    """The template with the data block of one baked focus and stop."""
    from .osl import lens_data, ray_differential_define, render_template

    fno = "open" if b.fstop is None else f"f/{b.fstop:g}"
    focus_txt = "infinity" if math.isinf(b.focus_mm) else f"{b.focus_mm:g} mm"
    head = [f"// {osl_comment(b.lens.name)}: focus {focus_txt} from the film, {fno}; sensor {b.sensor_width_mm:g} x "
            f"{b.sensor_height_mm:g} mm; dispersion {'on' if dispersion else 'off'}, Fresnel "
            f"{'on' if fresnel else 'off'}."]
    defines, data = lens_data(b.table, b.aperture, b.wavelength_nm, b.bounds, dispersion=dispersion, fresnel=fresnel)
    defines += [f"#define {k} {_num(v)}" for k, v in (("HALF_W", b.sensor_width_mm / 2), ("HALF_H", b.sensor_height_mm / 2),
                                                   ("GRID_HW", b.sensor_width_mm / 2), ("GRID_HH", b.sensor_height_mm / 2))]
    defines.append(ray_differential_define(b.camera.gaussian.efl))
    data = [f"    float FILM_Z = {_num(b.film_z)};", f"    float REAR_Z = {_num(b.bounds.z_plane)};",
            f"    float NORM = {_num(b.norm)};", _arr("VZ", b.table.vertex_z, "N_SURF"),
            _arr("SEMI", b.table.semi_diameter, "N_SURF"), _arr("RECT", b.bounds.rects, "N_RECT"), *data]
    return render_template(head + defines, data)


def _resolution(resolution, sw, sh):
    if resolution is None:
        w = 1920
        return w, max(1, int(round(w * sh / sw)))
    try:
        w, h = (int(v) for v in resolution)
    except (TypeError, ValueError):
        raise InputError("resolution must be two integers (width, height) in pixels") from None
    if not (1 <= w <= 65536 and 1 <= h <= 65536):
        raise InputError(f"resolution must lie in 1..65536 pixels a side, got {w} x {h}")
    if abs((w / h) / (sw / sh) - 1.0) > 0.01:
        raise InputError(f"resolution {w} x {h} has aspect {w / h:.4f}, the sensor {sw:g} x {sh:g} mm "
                         f"{sw / sh:.4f}: the shader maps the whole sensor to the frame, so they must match")
    return w, h


_SETUP = '''"""Blender set-up for a physcam real-lens camera{title}.

Run it as ``blender --python {script}`` (or ``blender file.blend --python ...``), or import it
and call ``apply(scene)``: the scene camera (created when the scene has none) becomes a Cycles
custom OSL camera with the shader below, the sensor and resolution are set, OSL shading is
switched on and the device set to the CPU (Cycles runs OSL cameras on the CPU and OptiX only).
Generated by physcam.export.blender.blender_setup_script.
"""

import os
import shutil
import tempfile

import bpy

SENSOR_WIDTH_MM = {sw!r}
SENSOR_HEIGHT_MM = {sh!r}
RESOLUTION = {res!r}
TEXT_NAME = {text_name!r}
SHADER_PATH = {path!r}  # read at run time when set (relative to this script)
SHADER_SOURCE = {source!r}


def _source():
    if SHADER_PATH is None:
        return SHADER_SOURCE
    p = SHADER_PATH
    if not os.path.isabs(p):
        here = os.path.dirname(os.path.abspath(globals().get("__file__", "") or "."))
        p = os.path.join(here, p)
    with open(p, encoding="utf-8") as fh:
        return fh.read()


def apply(scene=None):
    """Make ``scene``'s camera (default: the current scene's) the physcam OSL camera; returns it."""
    scene = scene or bpy.context.scene
    cam_obj = scene.camera
    if cam_obj is None:
        cam_obj = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
        scene.collection.objects.link(cam_obj)
        scene.camera = cam_obj
    # Cycles with OSL first: Blender compiles a custom camera shader when it is assigned, and only
    # when the scene already renders with Cycles and OSL (else the camera stays uncompiled and black)
    r = scene.render
    r.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.shading_system = True
    r.resolution_x, r.resolution_y = RESOLUTION
    r.resolution_percentage = 100
    r.pixel_aspect_x = r.pixel_aspect_y = 1.0
    text = bpy.data.texts.get(TEXT_NAME) or bpy.data.texts.new(TEXT_NAME)
    text.clear()
    text.write(_source())
    cam = cam_obj.data
    cam.type = "CUSTOM"
    cam.custom_mode = "INTERNAL"
    # Cycles compiles the shader into a temporary .oso it never removes: compile in a folder of our own
    old_tmp, scratch = tempfile.tempdir, tempfile.mkdtemp(prefix="physcam-osl-")
    tempfile.tempdir = scratch
    try:
        cam.custom_shader = text
    finally:
        tempfile.tempdir = old_tmp
        shutil.rmtree(scratch, ignore_errors=True)
    cam.sensor_fit = "HORIZONTAL"
    cam.sensor_width = SENSOR_WIDTH_MM
    cam.sensor_height = SENSOR_HEIGHT_MM
    if not cam.custom_bytecode:
        raise RuntimeError("Blender did not compile the physcam OSL camera shader: is this Blender built with "
                           "OSL, and is its oslquery module importable?")
    return cam_obj


if __name__ == "__main__":
    apply()
'''


def blender_setup_script(shader, *, sensor_width_mm, sensor_height_mm, resolution=None,
                         text_name: str = "physcam_lens.osl") -> str:
    """Python source of a Blender script (``blender --python setup.py``; importable, ``apply(scene=None)``)
    that makes the scene camera the custom OSL camera.

    ``shader``: the OSL source (a ``str`` holding a ``shader`` declaration) embedded in the script,
    or a path (``pathlib.Path``, or a one-line ``str`` without a shader declaration) read when the script runs, relative to
    the script. ``resolution`` (w, h) px must have the sensor's aspect (1 %); default 1920 wide.
    """
    sw = require_positive("sensor width", sensor_width_mm)
    sh = require_positive("sensor height", sensor_height_mm)
    res = _resolution(resolution, sw, sh)
    if isinstance(shader, Path):
        path, source = str(shader), None
    elif isinstance(shader, str) and re.search(r"\bshader\s+\w+\s*\(", shader):
        path, source = None, shader
    elif isinstance(shader, str) and shader.strip() and "\n" not in shader.strip():
        path, source = shader.strip(), None
    else:
        raise InputError("shader must be OSL source text (with a `shader` declaration) or a path to an .osl file")
    if not isinstance(text_name, str) or not text_name.strip():
        raise InputError("text_name must be a non-empty string")
    title = f" ({python_docstring(Path(path).name)})" if path else ""
    return _SETUP.format(title=title, script="setup.py", sw=float(sw), sh=float(sh), res=res, text_name=text_name,
                         path=path, source=source)


def _camera_first(fn):
    """``write_blender_camera(out_dir, camera, ...)``, the pre-issue-43 order, still works (DeprecationWarning)."""
    import functools

    @functools.wraps(fn)
    def reordered(*args, **kwargs):
        if len(args) >= 2 and isinstance(args[0], (str, Path)) and not isinstance(args[1], (str, Path)):
            import warnings

            warnings.warn("write_blender_camera(out_dir, camera, ...) is now write_blender_camera(camera, out_dir, "
                          "...); the old order goes in physcam 0.3", DeprecationWarning, stacklevel=2)
            args = (args[1], args[0], *args[2:])
        return fn(*args, **kwargs)

    return reordered


@_camera_first
@takes_camera
def write_blender_camera(camera: CameraState, out_dir, *, aperture=None, dispersion: bool = False,
                         fresnel: bool = False, resolution=None, name: str | None = None,
                         force: bool = False) -> tuple[Path, Path]:
    """Write ``<name>.osl`` (:func:`osl_camera_shader` of ``camera``, a CameraState with a sensor) and
    ``setup_<name>.py`` (:func:`blender_setup_script`, with the shader embedded) into ``out_dir`` through
    :func:`physcam.io.atomic_write` (no overwrite without ``force``). ``name`` defaults to the lens name
    made an identifier. Returns the two paths."""
    from ..io import atomic_write, check_writable

    stem = _ident(name if name is not None else camera.lens_name)
    out = Path(out_dir)
    osl_path = out / f"{stem}.osl"
    setup_path = out / f"setup_{stem}.py"
    check_writable(osl_path, force=force)
    check_writable(setup_path, force=force)
    _check_switches(dispersion, fresnel)
    state = _state(camera, aperture)
    src = _emit(_bake(state, fresnel), dispersion=dispersion, fresnel=fresnel)
    sw, sh = state.sensor_mm
    setup = blender_setup_script(src, sensor_width_mm=sw, sensor_height_mm=sh, resolution=resolution,
                                 text_name=f"{stem}.osl")
    atomic_write(osl_path, src, force=force)
    atomic_write(setup_path, setup, force=force)
    return osl_path, setup_path

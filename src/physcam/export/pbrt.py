"""pbrt-v4 cameras for a lens report: the ``realistic`` camera (a lens ``.dat`` and a scene
snippet) and the thin-lens ``perspective`` camera; and the film distance pbrt itself will choose.

Units (pbrt-v4 ``RealisticCamera::Create`` and its constructor, ``src/pbrt/cameras.cpp``): the
lens file is in **millimetres** and pbrt divides every length by 1000, so the scene is in
**metres**; ``aperturediameter`` (the stop's diameter) and the film's ``diagonal`` are in mm,
``focusdistance`` is in metres **from the film plane** (pbrt's lens space has the film at z = 0),
which is the on-set focus mark. The perspective camera's ``lensradius`` and ``focaldistance``
are scene lengths (metres here) measured from the camera origin, which physcam puts at the
entrance pupil (docs/conventions.md); its ``fov`` spans the **shorter** image axis (pbrt-v4
``PerspectiveCamera::Create``: the screen window is [-a, a] x [-1, 1] for a frame aspect a > 1,
else [-1, 1] x [-1/a, 1/a]).

How pbrt focuses (``RealisticCamera::FocusThickLens``; Pharr, Jakob and Humphreys, *Physically
Based Rendering*, 4th ed., 5.3.3, "The Thick Lens Approximation"): it ignores the lens file's
last thickness and moves the whole lens. Two rays parallel to the axis at the height
0.001 x film diagonal (mm), one from the scene and one from the film side, are traced through
the lens; where each leaves crossing the axis is a focal point, where it reaches its entrance
height is a principal plane. The Gaussian lens equation between those planes then gives the
translation delta of the lens that images the subject (``focusdistance`` from the film) on the
film: delta = (p - z + p' - sqrt((p - z - p') (p - z - 4 f - p'))) / 2 with z = -focusdistance,
p and p' the principal planes and f = f' - p', every z in pbrt's lens space (film at 0, the
lens at negative z). The rear gap becomes the file's last thickness + delta. For a rotationally
symmetric lens this is Gaussian optics with rays 0.001 x diagonal from the axis, so it agrees
with physcam's paraxial focus up to the rays' tiny aberration (and pbrt's 32-bit floats), *if*
pbrt is given the lens with physcam's focus gaps: pbrt can only move the whole lens, so a lens
with internal focus groups written at its infinity gaps would focus by unit extension instead.
physcam writes the ``.dat`` with the gaps and back focus of its own exact focus at the mark,
runs pbrt's method on it (:func:`pbrt_thick_lens`), and reports the difference and where pbrt's
plane of focus lands (:func:`pbrt_focus_comparison`).

What a ``.dat`` cannot hold is refused (:func:`check_pbrt_lens`): aspheres and conics,
cylinders (anamorphic lenses), and flat refracting surfaces (radius 0 marks the stop; a large
stand-in radius costs either focus or pbrt's 32-bit sphere intersection). physcam's Blender
Cycles OSL camera (``physcam export blender``) traces all of those.
"""

from __future__ import annotations

import dataclasses
import math
import warnings
from dataclasses import asdict, dataclass, fields
from pathlib import Path

from ..errors import ExportError, InputError, OpticsError, renamed_parameter, require_positive
from ..lens.prescription import Prescription, require_prescription
from ..onset.report import takes_report
from ..optics.state import CameraState, camera_state, takes_camera
from ._codetext import hash_comment, pbrt_string

__all__ = [
    "PBRT_CAMERAS",
    "PbrtThickLens",
    "PbrtFocusComparison",
    "check_pbrt_lens",
    "pbrt_lens_text",
    "pbrt_thick_lens",
    "pbrt_focus_comparison",
    "pbrt_camera_values",
    "pbrt_scene_snippet",
    "write_pbrt_camera",
]

#: The pbrt-v4 cameras physcam writes.
PBRT_CAMERAS = ("realistic", "perspective")
#: pbrt's scene unit in mm: the realistic camera reads the lens file in mm and divides by 1000.
MM_PER_SCENE_UNIT = 1000.0
#: How far in front of the lens (and behind it) pbrt starts its thick-lens rays: 1 scene unit.
_RAY_START_MM = 1000.0
#: Height of pbrt's thick-lens rays as a fraction of the film diagonal (``.001f * film.Diagonal()``).
RAY_HEIGHT_PER_DIAGONAL = 1.0e-3


def _refusal(lens: Prescription) -> str | None:
    """Why a pbrt ``.dat`` cannot hold ``lens`` (None when it can); the gravest reason first."""
    surfs = list(enumerate(lens.surfaces))
    for i, s in surfs:
        if s.kind.startswith("cylindrical"):
            return (f"surface {i} is a cylinder (an anamorphic lens); pbrt's lens elements are rotationally "
                    "symmetric spheres, with no squeeze and no oval bokeh")
    if lens.squeeze != 1.0:
        return f"it is anamorphic (squeeze {lens.squeeze:g}); pbrt's lens elements are rotationally symmetric"
    for i, s in surfs:
        if s.kind == "aspheric" or s.conic or s.aspheric:
            shape = "a conic" if s.conic and not s.aspheric else "an asphere"
            return (f"surface {i} is {shape}; a .dat row holds a sphere only (radius, thickness, index, aperture), "
                    "no conic constant or aspheric terms")
    for i, s in surfs:
        if s.kind == "flat":
            return (f"surface {i} is a flat refracting surface, and a .dat radius of 0 means the aperture stop "
                    "(a huge stand-in radius would shift the focus or lose pbrt's 32-bit sphere intersection)")
    return None


def check_pbrt_lens(lens) -> Prescription:
    """``lens`` when a pbrt-v4 ``.dat`` can hold it; else :class:`ExportError` naming pbrt, the
    limitation and the renderers that can (physcam's Blender OSL camera; RenderMan for anamorphics)."""
    lens = require_prescription(lens)
    why = _refusal(lens)
    if why is None:
        return lens
    alt = "physcam's Blender Cycles OSL camera traces it exactly (`physcam export blender`)"
    if lens.is_anamorphic:
        alt += ("; RenderMan's PxrCamera gives its squeeze and oval bokeh to a thin lens "
                "(`physcam export rib --lens ...`: pixel aspect and dofaspect)")
    else:
        alt += "; pbrt's thin lens still works (`physcam export pbrt --camera perspective`)"
    raise ExportError(f"pbrt-v4's realistic camera cannot hold lens {lens.name!r}: {why}. {alt}")


def pbrt_lens_text(lens, *, comments=()) -> tuple[str, list[str]]:
    """(``.dat`` text, notes) for ``lens`` as given (its gaps and last thickness), after
    :func:`check_pbrt_lens`. Notes say what the file drops (dispersion, focus groups)."""
    from ..lens.formats import pbrt as dat

    lens = check_pbrt_lens(lens)
    if lens.metadata.notes:  # the lens file's own notes become # lines of the .dat
        safe = "\n".join(hash_comment(line) for line in lens.metadata.notes.splitlines())
        lens = dataclasses.replace(lens, metadata=dataclasses.replace(lens.metadata, notes=safe))
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        body = dat.dumps(lens)
    notes = []
    if any(s.medium.vd for s in lens.surfaces):
        notes.append("pbrt has no dispersion: the .dat holds each glass's index at the d line (nd)")
    if lens.focus is not None:
        notes.append("pbrt moves the whole lens to focus: the .dat holds the focus groups at this mark's gaps")
    notes += [str(w.message) for w in caught if "drops" not in str(w.message)]
    head = "".join(f"# {hash_comment(c)}\n" for text in comments for c in str(text).splitlines())
    return head + body, notes


@dataclass(frozen=True)
class PbrtThickLens:
    """pbrt-v4's thick-lens approximation of a lens and the film distance it chooses.

    ``*_z_mm`` are in pbrt's lens space before focusing: the film at z = 0, the lens at negative
    z (its rear vertex the ``.dat``'s last thickness in front of the film), mm. ``rear_*`` come
    from the ray entering from the scene, ``front_*`` from the ray entering from the film.
    ``film_distance_mm`` is the rear gap pbrt sets (last vertex to film): the file's last thickness
    plus ``delta_mm``, the lens's translation toward the subject.
    """

    focus_from_film_mm: float
    ray_height_mm: float
    rear_principal_z_mm: float
    rear_focal_z_mm: float
    front_principal_z_mm: float
    front_focal_z_mm: float
    efl_mm: float
    file_film_distance_mm: float
    delta_mm: float
    film_distance_mm: float

    def to_dict(self) -> dict:
        return asdict(self)


def _trace_parallel(lens, x_mm: float, z0: float, direction: float, stop_semi_diameter):
    """Trace one ray parallel to the axis at height ``x_mm`` from z = ``z0`` (physcam lens space),
    forward (+1, from the scene) or backward (-1, from the film); returns (x, z, L, N) as it leaves."""
    from ..trace import RayBatch
    from ..trace.trace import trace_through

    rays = RayBatch.collimated([x_mm], [0.0], z0, direction=(0.0, 0.0, float(direction)),
                               wavelength_nm=lens.wavelength_nm)
    out = trace_through(lens, rays, reverse=direction < 0, clip=True, stop_semi_diameter=stop_semi_diameter,
                        backend="numpy")
    if not bool(out.ok[0]) or out.L[0] == 0.0:
        side = "scene" if direction > 0 else "film"
        raise ExportError(
            f"pbrt cannot focus lens {lens.name!r}: its thick-lens ray from the {side} side, {x_mm:.4g} mm from the "
            "axis, does not leave the lens (pbrt stops with \"Unable to trace ray ... Is aperture stop extremely "
            "small?\"); open the aperture or check the lens")
    return float(out.x[0]), float(out.z[0]), float(out.L[0]), float(out.N[0])


def _pbrt_reads(lens, focus_mm, aperture_diameter_mm, film_diagonal_mm):
    """(lens as pbrt reads it, mark, aperture diameter, film diagonal) of :func:`pbrt_thick_lens`'s arguments."""
    if not isinstance(lens, CameraState):
        return (require_prescription(lens), focus_mm, aperture_diameter_mm,
                35.0 if film_diagonal_mm is None else film_diagonal_mm)
    if focus_mm is not None or aperture_diameter_mm is not None:
        raise InputError("a CameraState carries its own focus and iris: give them to camera_state(), not here")
    if film_diagonal_mm is None:
        film_diagonal_mm = 35.0 if lens.sensor_mm is None else math.hypot(*lens.sensor_mm)
    return lens.focused, lens.focus_from_film_mm, 2.0 * lens.stop_semi_diameter, film_diagonal_mm


@renamed_parameter("focus_from_film_mm", "focus_mm")
@takes_camera
def pbrt_thick_lens(lens: CameraState | Prescription, focus_mm: float | None = None, *, film_diagonal_mm: float | None = None,
                    aperture_diameter_mm: float | None = None) -> PbrtThickLens:
    """The film distance pbrt-v4 chooses for ``lens`` focused ``focus_mm`` from the film.

    ``lens``: a :class:`~physcam.optics.state.CameraState` (pbrt gets physcam's focus of the lens at
    the state's mark, its last thickness the back focus, as :func:`write_pbrt_camera` writes the
    ``.dat``, and the state's iris; ``focus_mm`` and ``aperture_diameter_mm`` stay None; the film
    diagonal defaults to its sensor's), or the Prescription as pbrt reads it (its last thickness is the
    ``.dat``'s). Its rays are traced with physcam's real-ray tracer at pbrt's height, 0.001 x
    ``film_diagonal_mm`` (default 35 mm), starting 1 m (pbrt's one scene unit) in front of the first
    vertex and behind the last one; the stop is ``aperture_diameter_mm`` across (pbrt's
    ``aperturediameter``; default the file's). See the module notes for the method. Raises
    :class:`ExportError` where pbrt stops ("Coefficient must be positive": the subject is closer than
    the lens can focus). ``focus_from_film_mm``: the old name of ``focus_mm`` (deprecated).
    """
    lens, focus_mm, aperture_diameter_mm, film_diagonal_mm = _pbrt_reads(lens, focus_mm, aperture_diameter_mm,
                                                                          film_diagonal_mm)
    if lens.is_anamorphic:
        raise ExportError(f"pbrt's thick-lens focus needs a rotationally symmetric lens; {lens.name!r} is anamorphic")
    mark = require_positive("focus distance", focus_mm)
    if math.isinf(mark):
        raise InputError("pbrt's focusdistance is a finite distance from the film; give a focus mark, "
                         "e.g. 1000m for a distant subject")
    diag = require_positive("film diagonal", film_diagonal_mm)
    stop = None
    if aperture_diameter_mm is not None:
        stop = require_positive("aperture diameter", aperture_diameter_mm) / 2.0
    x = RAY_HEIGHT_PER_DIAGONAL * diag
    zv = lens.vertex_z
    z_film = zv[-1] + lens.surfaces[-1].thickness  # pbrt's lens space: z_pbrt = z_physcam - z_film
    # from the scene: focal point F' where the ray crosses the axis, principal plane P' where it is back at x
    x1, z1, L1, N1 = _trace_parallel(lens, x, zv[0] - _RAY_START_MM, +1.0, stop)
    rear_f = z1 + (-x1 / L1) * N1 - z_film
    rear_p = z1 + ((x - x1) / L1) * N1 - z_film
    # from the film: F and P on the scene side
    x2, z2, L2, N2 = _trace_parallel(lens, x, zv[-1] + _RAY_START_MM, -1.0, stop)
    front_f = z2 + (-x2 / L2) * N2 - z_film
    front_p = z2 + ((x - x2) / L2) * N2 - z_film
    f = rear_f - rear_p
    z = -mark
    c = (front_p - z - rear_p) * (front_p - z - 4.0 * f - rear_p)
    if not f > 0 or not c > 0:
        raise ExportError(
            f"pbrt cannot focus lens {lens.name!r} at {mark:.1f} mm from the film: its thick-lens equation has no "
            "real solution (pbrt stops with \"Coefficient must be positive ... focusDistance is too short\"); the "
            "closest mark it can focus is about 4 f plus the principal planes' separation")
    delta = (front_p - z + rear_p - math.sqrt(c)) / 2.0
    t_last = lens.surfaces[-1].thickness
    return PbrtThickLens(mark, x, rear_p, rear_f, front_p, front_f, f, t_last, delta, t_last + delta)


@dataclass(frozen=True)
class PbrtFocusComparison:
    """pbrt's film distance next to physcam's exact focus, and where pbrt's plane of focus lands.

    Lengths mm. ``physcam_film_distance_mm``: last vertex to film at physcam's paraxial focus on the
    mark; ``pbrt_film_distance_mm``: the same gap after pbrt's thick-lens refocus of that lens
    (``difference_mm`` = pbrt - physcam, + means pbrt's film sits further behind the lens).
    ``pbrt_focus_from_film_mm``: the subject distance (from the film) whose paraxial image lies on
    pbrt's film, None beyond infinity. DOF limits are from the film with the report's CoC and
    f-number; ``*_shift_mm`` = pbrt - physcam. With internal focus groups, ``unit_focus_*`` give what
    pbrt would do with the lens at its infinity gaps (unit extension): back focus and EFL.
    """

    lens: str
    camera: CameraState  # physcam's camera at the report's mark and f-stop (.focus_from_film_mm, .fstop)
    coc_mm: float
    film_diagonal_mm: float
    method: str
    physcam_film_distance_mm: float
    pbrt_film_distance_mm: float
    difference_mm: float
    pbrt_focus_from_film_mm: float | None
    focus_shift_mm: float | None
    near_from_film_mm: float
    far_from_film_mm: float | None
    pbrt_near_from_film_mm: float | None
    pbrt_far_from_film_mm: float | None
    near_shift_mm: float | None
    far_shift_mm: float | None
    efl_mm: float
    aperture_diameter_mm: float
    thick_lens: PbrtThickLens
    writable: bool
    refusal: str | None = None
    unit_focus_film_distance_mm: float | None = None
    unit_focus_efl_mm: float | None = None

    @property
    def focus_from_film_mm(self) -> float:
        """The focus mark, from the film: the camera's."""
        return self.camera.focus_from_film_mm

    @property
    def fstop(self) -> float:
        return self.camera.fstop

    def to_dict(self) -> dict:
        d = {"lens": self.lens, "focus_from_film_mm": self.focus_from_film_mm, "fstop": self.fstop}
        d.update((f.name, getattr(self, f.name)) for f in fields(self) if f.name not in ("lens", "camera"))
        d["thick_lens"] = self.thick_lens.to_dict()
        d["units"] = "mm; *_from_film_mm in front of the film plane; film distances from the last vertex"
        return {k: (None if isinstance(v, float) and not math.isfinite(v) else v) for k, v in d.items()}


def _conjugate_from_film(lens, film_distance_mm: float):
    """(subject distance from the film or inf, EFL, H1 in front of the film) for ``lens`` with its
    film ``film_distance_mm`` behind the last vertex, paraxially (physcam's Gaussian engine)."""
    from ..optics import paraxial

    q = lens.with_thicknesses({len(lens.surfaces) - 1: film_distance_mm})
    g = paraxial.gaussian(q, wavelength_nm=lens.wavelength_nm)
    z_film = q.vertex_z[-1] + film_distance_mm
    s_img = (z_film - g.z_rear_principal_plane) / g.image_index
    h1 = z_film - g.z_front_principal_plane
    if not s_img > g.efl:  # the film at or inside F': the subject would lie beyond infinity
        return math.inf, g.efl, h1
    s = 1.0 / (1.0 / g.efl - 1.0 / s_img) * g.object_index
    return s + h1, g.efl, h1


def _dof_from_film(efl, fstop, coc, s, h1):
    from ..optics.dof import dof_limits

    near, far = dof_limits(efl, fstop, coc, s)
    return float(near) + h1, float(far) + h1


def _state_at_mark(report, lens) -> CameraState:
    """physcam's ``lens`` at ``report``'s mark and f-stop (its focus and its iris, in one place): the report's
    own camera when it is of this lens with its iris set (no focus solved again)."""
    cam = report.camera
    if cam.traceable and (lens is cam.lens or lens == cam.lens):
        return report.stopped_camera()
    return camera_state(lens, focus_mm=report.focus_from_film_mm, fstop=report.fstop)


@takes_report
def pbrt_focus_comparison(report, lens=None, *, film_diagonal_mm: float | None = None) -> PbrtFocusComparison:
    """pbrt-v4's focus of ``lens`` at ``report``'s mark next to physcam's, with the DOF each gives.

    ``report`` is the lens report of ``lens`` (its mark, f-number and CoC; default: its camera's lens); ``film_diagonal_mm``
    (default the sensor's diagonal) sets the height of pbrt's thick-lens rays. The lens pbrt gets is
    physcam's focus of ``lens`` at the mark (gaps and back focus), read back from its ``.dat`` text so
    the numbers are the file's; a lens a ``.dat`` cannot hold (flats) is compared on its exact
    surfaces, with ``writable`` False and the reason.
    """
    lens = report.camera.lens if lens is None else require_prescription(lens)
    if not math.isfinite(report.focus_from_film_mm):
        raise InputError("pbrt's focusdistance is finite; give a focus mark")
    return _focus_comparison(report, _state_at_mark(report, lens), film_diagonal_mm)


def _focus_comparison(report, state: CameraState, film_diagonal_mm) -> PbrtFocusComparison:
    from ..lens.formats import pbrt as dat
    from ..optics import focusing, paraxial

    lens, mark = state.lens, state.focus_from_film_mm
    diag = film_diagonal_mm if film_diagonal_mm is not None else report.sensor.diagonal_mm
    method = focusing.focus_method(lens)
    back_focus = state.focused.surfaces[-1].thickness  # physcam's exact focus: last vertex to film
    why = _refusal(lens)
    pbrt_lens = state.focused
    if why is None:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            pbrt_lens = dat.loads(dat.dumps(state.focused), name=lens.name)
    ap = 2.0 * state.stop_semi_diameter
    tl = pbrt_thick_lens(pbrt_lens, mark, film_diagonal_mm=diag, aperture_diameter_mm=ap)
    d_pbrt, efl_pbrt, h1_pbrt = _conjugate_from_film(pbrt_lens, tl.film_distance_mm)
    dof = report.dof
    far = None if dof.far_is_infinite else dof.far_from_film_mm
    p_near = p_far = None
    if math.isfinite(d_pbrt):
        try:
            p_near, p_far = _dof_from_film(efl_pbrt, report.fstop, report.coc_mm, d_pbrt - h1_pbrt, h1_pbrt)
        except OpticsError:
            p_near = p_far = None
    unit_back = unit_efl = None
    if lens.focus is not None:
        q_inf = focusing.focus(lens, math.inf).prescription
        if why is None:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                q_inf = dat.loads(dat.dumps(q_inf), name=lens.name)
        unit = pbrt_thick_lens(q_inf, mark, film_diagonal_mm=diag, aperture_diameter_mm=ap)
        unit_back = unit.film_distance_mm
        unit_efl = paraxial.gaussian(q_inf.with_thicknesses({len(q_inf.surfaces) - 1: unit_back})).efl

    def shift(a, b):
        return None if a is None or b is None or not (math.isfinite(a) and math.isfinite(b)) else a - b

    return PbrtFocusComparison(
        lens=lens.name, camera=state, coc_mm=report.coc_mm, film_diagonal_mm=diag,
        method=method, physcam_film_distance_mm=back_focus, pbrt_film_distance_mm=tl.film_distance_mm,
        difference_mm=tl.film_distance_mm - back_focus,
        pbrt_focus_from_film_mm=d_pbrt if math.isfinite(d_pbrt) else None,
        focus_shift_mm=shift(d_pbrt, mark),
        near_from_film_mm=dof.near_from_film_mm, far_from_film_mm=far,
        pbrt_near_from_film_mm=p_near, pbrt_far_from_film_mm=p_far if p_far is None or math.isfinite(p_far) else None,
        near_shift_mm=shift(p_near, dof.near_from_film_mm), far_shift_mm=shift(p_far, far),
        efl_mm=efl_pbrt, aperture_diameter_mm=ap, thick_lens=tl, writable=why is None, refusal=why,
        unit_focus_film_distance_mm=unit_back, unit_focus_efl_mm=unit_efl,
    )


def _whole(name: str, value, lo: int, hi: int) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or int(value) != value or not lo <= value <= hi:
        raise InputError(f"{name} must be a whole number of pixels {lo}..{hi}, got {value!r}")
    return int(value)


@takes_report
def pbrt_camera_values(report, lens=None, *, xres: int = 1920, cameras=PBRT_CAMERAS,
                       lensfile: str = "lens.dat") -> dict:
    """The numbers of pbrt-v4's ``Film`` and cameras for ``report`` (see the module notes for units).

    ``film``: ``xresolution`` (``xres``), ``yresolution`` (from the sensor's aspect) and ``diagonal``
    (mm), chosen so that the film pbrt derives (width = diagonal / sqrt(1 + (yres/xres)^2)) is the
    sensor's width exactly; ``height_mm`` is what pbrt's height becomes after the whole-pixel rounding.
    ``perspective`` (thin lens): ``fov`` (degrees, across the shorter image axis) of the best-match
    pinhole, ``lensradius`` (half the entrance pupil, f / 2N, in metres) and ``focaldistance`` (metres
    from the entrance pupil). ``realistic`` (needs ``lens``): ``lensfile``, ``aperturediameter`` (the
    stop's diameter for the report's f-number, mm: the round iris, which has the area of any bladed
    iris of that f-number, docs/conventions.md) and ``focusdistance`` (the mark, metres from the film).
    """
    return _camera_values(report, lens, xres=xres, cameras=cameras, lensfile=lensfile)[0]


def _realistic_state(report, lens) -> CameraState:
    """The lens state of pbrt's realistic camera: ``lens`` (a .dat can hold it) at the report's finite mark."""
    if lens is None:
        raise ExportError("pbrt-v4's realistic camera traces a lens prescription: give a lens (--lens NAME); "
                          "a thin lens (--focal) has only the perspective camera (--camera perspective)")
    lens = check_pbrt_lens(lens)
    if not math.isfinite(report.focus_from_film_mm):
        raise InputError("pbrt's focusdistance is a finite distance from the film; give a focus mark")
    return _state_at_mark(report, lens)


def _camera_values(report, lens, *, xres, cameras, lensfile) -> tuple[dict, CameraState | None]:
    """(:func:`pbrt_camera_values`, the realistic camera's lens state or None)."""
    from .usdgeom import focus_distance_from_pupil_mm

    xres = _whole("xres", xres, 16, 65536)
    if isinstance(cameras, str):
        cameras = (cameras,)
    bad = [c for c in cameras if c not in PBRT_CAMERAS]
    if bad or not cameras:
        raise InputError(f"pbrt cameras are {' and '.join(PBRT_CAMERAS)}, got {list(cameras)!r}")
    state = None
    w, h = report.sensor.width_mm, report.sensor.height_mm
    yres = max(1, round(xres * h / w))
    if yres > 65536:
        raise InputError(f"the sensor's aspect makes the image {yres} pixels tall; give fewer pixels across")
    diag = w * math.hypot(1.0, yres / xres)
    out = {
        "units": {"scene": "metres (pbrt's realistic camera divides the lens file's mm by 1000)",
                  "lens_file": "mm", "film_diagonal": "mm",
                  "fov": "degrees across the shorter image axis (pbrt-v4 PerspectiveCamera)"},
        "film": {"xresolution": xres, "yresolution": yres, "diagonal": diag, "width_mm": w,
                 "height_mm": w * yres / xres, "sensor_height_mm": h},
    }
    if "realistic" in cameras:
        state = _realistic_state(report, lens)
        out["realistic"] = {"lensfile": str(lensfile), "aperturediameter": 2.0 * state.stop_semi_diameter,
                            "focusdistance": state.focus_from_film_mm / MM_PER_SCENE_UNIT,
                            "film_distance_mm": state.focused.surfaces[-1].thickness}
    if "perspective" in cameras:
        f_pin, sq = report.pinhole
        if sq != 1.0 or report.squeeze != 1.0:
            raise ExportError(
                f"pbrt-v4's perspective camera has no anamorphic squeeze (pixel aspect) and no oval bokeh (squeeze "
                f"{report.squeeze:g}); RenderMan's PxrCamera has both (`physcam export rib`), and physcam's Blender "
                "OSL camera traces the real lens (`physcam export blender`)")
        img_w, img_h = w, w * yres / xres
        short, axis = (img_h, "vertical") if xres > yres else (img_w, "horizontal" if xres < yres else "both")
        focal_mm = focus_distance_from_pupil_mm(report)
        if not focal_mm > 0:
            raise ExportError(f"the plane of focus lies behind the entrance pupil ({focal_mm:g} mm); pbrt's "
                              "focaldistance must be positive")
        out["perspective"] = {
            "fov": math.degrees(2.0 * math.atan(short / (2.0 * f_pin))), "fov_axis": axis,
            "lensradius": report.aperture_diameter_mm / 2.0 / MM_PER_SCENE_UNIT,
            "focaldistance": focal_mm / MM_PER_SCENE_UNIT,
            "pinhole_focal_length_mm": f_pin,
            "entrance_pupil_from_film_m": None if report.entrance_pupil_from_film_mm is None
            else report.entrance_pupil_from_film_mm / MM_PER_SCENE_UNIT,
        }
    return out, state


def _num(x) -> str:
    if isinstance(x, int) and not isinstance(x, bool):
        return str(x)
    return repr(float(x))


def pbrt_scene_snippet(values: dict, camera: str, *, comments=()) -> str:
    """pbrt-v4 scene text (``Film`` and ``Camera``) of ``camera`` from :func:`pbrt_camera_values`,
    to ``Include`` before ``WorldBegin``; ``comments`` become ``#`` lines at the top."""
    from ..errors import require_type

    require_type("values", values, dict, "build them with pbrt_camera_values(report, ...)")
    if camera not in PBRT_CAMERAS:
        raise InputError(f"pbrt camera must be one of {', '.join(PBRT_CAMERAS)}, got {camera!r}")
    if camera not in values or "film" not in values:
        raise InputError(f"values has no {camera} camera; ask pbrt_camera_values for it")
    film, cam = values["film"], values[camera]
    lines = [f"# {hash_comment(c)}".rstrip() for text in comments for c in str(text).splitlines()]
    lines.append(f"Film \"rgb\" \"integer xresolution\" [{film['xresolution']}] \"integer yresolution\" "
                 f"[{film['yresolution']}] \"float diagonal\" [{_num(film['diagonal'])}]")
    if camera == "realistic":
        lensfile = pbrt_string(cam["lensfile"])
        lines.append(f"Camera \"realistic\" \"string lensfile\" [\"{lensfile}\"] "
                     f"\"float aperturediameter\" [{_num(cam['aperturediameter'])}] "
                     f"\"float focusdistance\" [{_num(cam['focusdistance'])}]")
    else:
        lines.append(f"Camera \"perspective\" \"float fov\" [{_num(cam['fov'])}] "
                     f"\"float lensradius\" [{_num(cam['lensradius'])}] "
                     f"\"float focaldistance\" [{_num(cam['focaldistance'])}]")
    return "\n".join(lines) + "\n"


@takes_report
def write_pbrt_camera(report, folder, lens=None, *, name: str = "lens", xres: int = 1920, cameras=PBRT_CAMERAS,
                      force: bool = False) -> dict:
    """Write pbrt-v4 files for ``report`` into ``folder``: ``<name>.dat`` (``lens`` focused at the mark
    by physcam) and ``<name>_realistic.pbrt`` for the realistic camera, ``<name>_perspective.pbrt`` for
    the thin lens. Every file is checked before any is written, then written atomically; existing
    files need ``force``. Returns the paths, the camera values, notes and (with a lens and the
    realistic camera) the :class:`PbrtFocusComparison`."""
    import re

    from ..io import atomic_write, check_writable
    from ..optics import focusing

    if not isinstance(name, str) or not re.fullmatch(r"[A-Za-z0-9][A-Za-z0-9_.+-]{0,99}", name):
        raise InputError(f"name must be a plain file name (letters, digits, _ . + -), got {name!r}")
    if isinstance(cameras, str):
        cameras = (cameras,)
    folder = Path(folder)
    values, state = _camera_values(report, lens, xres=xres, cameras=cameras, lensfile=f"{name}.dat")
    files: dict[str, tuple[Path, str]] = {}
    notes: list[str] = []
    comparison = None
    s = report.sensor
    head = [f"physcam: pbrt-v4 camera for {report.lens_name or f'a {report.focal_length_mm:g} mm thin lens'}, "
            f"f/{report.fstop:.3g}, focus mark {report.focus_from_film_mm / 1000.0:g} m from the film, "
            f"on {s.name} ({s.width_mm:g} x {s.height_mm:g} mm)",
            "units: the scene in metres (pbrt divides the lens file's mm by 1000); diagonal and aperture in mm",
            "Include this before WorldBegin; the camera transform (LookAt ...) comes first"]
    if "realistic" in cameras:
        text, notes = pbrt_lens_text(state.focused, comments=[
            f"{lens.name}: physcam's {focusing.focus_method(lens)} focus at {report.focus_from_film_mm:g} mm from "
            f"the film; the last thickness is the back focus {state.focused.surfaces[-1].thickness:.6g} mm",
            "pbrt refocuses it with its thick-lens approximation (physcam export pbrt reports the difference)"])
        comparison = _focus_comparison(report, state, values["film"]["diagonal"])
        files["lens"] = (folder / f"{name}.dat", text)
        files["realistic"] = (folder / f"{name}_realistic.pbrt", pbrt_scene_snippet(values, "realistic", comments=head + [
            "realistic camera: its origin is the film plane's centre, looking down +z; focusdistance is the mark "
            "from the film",
            f"pbrt will put the film {comparison.pbrt_film_distance_mm:.6f} mm behind the last vertex "
            f"(physcam's exact focus: {comparison.physcam_film_distance_mm:.6f} mm)"]))
    if "perspective" in cameras:
        p = values["perspective"]
        pupil = p["entrance_pupil_from_film_m"]
        where = ("" if pupil is None else
                 f"; it sits at the entrance pupil, {pupil:.6g} m in front of the film: "
                 f"`Translate 0 0 {-pupil:.6g}` before LookAt moves a film-placed camera there")
        files["perspective"] = (folder / f"{name}_perspective.pbrt", pbrt_scene_snippet(values, "perspective", comments=head + [
            f"thin lens: the best-match pinhole ({p['pinhole_focal_length_mm']:.6g} mm), fov across the shorter "
            f"axis ({p['fov_axis']}); lensradius = f / 2N; focaldistance from the camera origin{where}"]))
    for path, _ in files.values():
        check_writable(path, force=force)
    written = {key: str(atomic_write(path, text, force=force)) for key, (path, text) in files.items()}
    if report.real_fov_differs and "perspective" in cameras:
        notes.append("the perspective camera is a pinhole: it frames the lens's centre, not its distorted edges "
                     "(the realistic camera traces them)")
    return {"written": written, "values": values, "notes": notes,
            "focus": None if comparison is None else comparison.to_dict()}

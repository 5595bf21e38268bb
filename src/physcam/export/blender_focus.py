"""A Blender OSL camera whose focus, f-stop, sensor and iris are shader parameters.

:func:`focus_table` tabulates physcam's focus states of a lens (:func:`physcam.optics.focusing.focus`:
unit focusing moves the film, internal focusing the groups; breathing comes with them) at marks
uniform in 1/distance from infinity to the closest focus; :func:`focus_table_shader` writes the
template ``osl/physcam_lens.osl.in`` with that table, and the shader blends the two states that
bracket its ``focus_distance`` parameter (metres from the film plane), linearly in 1/distance. The
iris follows physcam's one rule (:func:`~physcam.optics.state.camera_state`'s iris, sized at
infinity focus): paraxial, so its semi-diameter is K / N with K tabulated here; it opens as far as
physcam's camera state opens it, :data:`~physcam.optics.paraxial.STOP_OPENING_TOLERANCE` beyond the
file's stop (a lens's own marked f-number, rounded, is always accepted). Where the shader aims its
rays: for a lens with rotational symmetry, the ellipses of :mod:`physcam.export.blender_pupil` per
film radius and iris size (nearly every sample passes, at every stop); for an anamorphic lens, the
exit-pupil rectangles of the lens at its widest iris and stopped to :data:`STOP_LEVELS` of it over a
film square of :data:`GRID_HALF_MM` (the shader samples the smallest that holds its iris). The
weight is normalised at the film centre of each state and iris size (the centre renders 1 at every
stop; with Fresnel on, the centre's transmission at infinity is divided out too). Keyframing the parameters
renders a focus pull or an iris change with no rebuild.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from ..data.default_sensor import DEFAULT_SENSOR_HEIGHT_MM, DEFAULT_SENSOR_WIDTH_MM
from ..errors import InputError, OpticsError, require_type
from ..lens.prescription import Prescription, takes_prescription
from ._codetext import osl_comment
from .osl import lens_data, osl_array, osl_number, render_template

__all__ = ["FocusTable", "focus_table", "focus_table_shader", "ghost_rows", "N_FOCUS", "GRID_HALF_MM", "STOP_LEVELS"]

#: Focus states tabulated (uniform in 1/distance, infinity first).
N_FOCUS = 32
#: Half size (mm) of the film square the exit-pupil table covers: a full-frame 36 x 24 mm gate's
#: half diagonal, so every sensor up to full frame (any aspect) fits.
GRID_HALF_MM = 21.7
_GRID = (9, 9)
#: Iris sizes (fractions of the open stop's semi-diameter: about 0.8, 2, 3 and 4 stops down) with their own
#: exit-pupil tables: stopped down, the shader samples the smallest tabulated pupil that holds the
#: iris's, instead of the open lens's (fewer wasted samples: less noise at equal samples).
STOP_LEVELS = (0.75, 0.5, 0.35, 0.25)
#: Aims a camera ray tries, where the passing set's area is known, before it counts as lost.
N_TRY = 8


@dataclasses.dataclass
class FocusTable:
    """physcam's focus states of one lens, film side first (the tracing order)."""

    lens: Prescription
    marks_mm: np.ndarray  # focus marks from the film plane, inf first
    inv_step_per_m: float  # spacing of the marks in 1/metres
    film_z: np.ndarray  # (n,) film plane z, lens space
    vertex_z: np.ndarray  # (n, surfaces)
    radial: np.ndarray | None  # (n, N_LEVEL, N_RADIAL, 3) pupil ellipses (blender_pupil); None: anamorphic
    rects: np.ndarray | None  # (n, ny, nx, 4) exit-pupil rectangles at the widest iris (anamorphic only)
    rects_stopped: np.ndarray | None  # (n, len(STOP_LEVELS), ny, nx, 4): the same stopped to each level
    norm: np.ndarray  # (n, N_LEVEL) mean weight at the film centre, the round iris at each of iris_levels(semi_max)
    table: object  # SurfaceTable at infinity (the rows that do not move)
    bounds: object  # PupilBounds at infinity (the 2-D grid; anamorphic only, else None)
    iris_k: float  # iris semi-diameter x f-number (mm)
    fstop_open: float  # the lens wide open (the file's stop)
    fstop_min: float  # the fastest f-stop accepted: physcam's camera state opens the iris this far
    closest_mm: float
    fresnel_loss: float  # Fresnel transmission at the film centre at infinity (uncoated)
    #: the shader's data lines already written, by name and values (the four shaders of a lens share them)
    osl_lines: dict = dataclasses.field(default_factory=dict, repr=False, compare=False)

    @property
    def semi_max(self) -> float:
        """The widest iris's semi-diameter (mm): the stop opened to :attr:`fstop_min`."""
        return self.iris_k / self.fstop_min

    @property
    def levels(self) -> np.ndarray:
        """The iris radii (mm) of the pupil and normalisation tables (:func:`~physcam.export.blender_pupil.iris_levels`)."""
        from .blender_pupil import iris_levels

        return iris_levels(self.semi_max, self.iris_k / self.fstop_open)


def _ellipse_rect(ellipse) -> np.ndarray:
    """(x0, x1, y0, y1): the rectangle around an ellipse (cx, ax, ay) on the rear vertex plane."""
    cx, ax, ay = ellipse[:3]
    return np.array([cx - ax, cx + ax, -ay, ay])


def _centre_bounds(q, ellipse):
    """A PupilBounds whose every node holds the rectangle around an ellipse (cx, ax, ay)."""
    from ..trace.pupil_bounds import PupilBounds

    rect = np.broadcast_to(_ellipse_rect(ellipse), (2, 2, 4)).copy()
    return PupilBounds(np.array([-1.0, 1.0]), np.array([-1.0, 1.0]), rect, float(q.vertex_z[-1]))


class _RayRects:
    """Bounds for camera_rays that hold one aim rectangle (x0, x1, y0, y1) per ray, in order."""

    def __init__(self, rects):
        self.rects = rects

    def rect_at(self, fx, fy):
        return tuple(self.rects[:, c] for c in range(4))


def _centre_norms(tracer, rects, levels) -> list[float]:
    """The centre's mean weight with the round iris at each tabulated iris level, aiming at
    ``rects[k]`` for level k (the 64^2 aims of :meth:`~physcam.trace.camera_tracer.CameraTracer.centre_weight`;
    levels that share a rectangle share their rays), all in one trace
    (:meth:`~physcam.trace.camera_tracer.CameraTracer.iris_camera_rays`): the shader's
    normalisation (the exit pupil's area is not quite the square of the iris's radius)."""
    m = 64
    u = (np.arange(m) + 0.5) / m
    uu, vv = [a.ravel() for a in np.meshgrid(u, u)]
    uniq, which = np.unique(np.asarray(rects, dtype=float), axis=0, return_inverse=True)
    n = uu.size
    cr, passing = tracer.iris_camera_rays(np.zeros((n * len(uniq), 2)), np.tile(np.stack([uu, vv], axis=1), (len(uniq), 1)),
                                          [float(s) for s in levels], bounds=_RayRects(np.repeat(uniq, n, axis=0)))
    w = cr.weight.reshape(len(uniq), n)
    return [float(np.mean(np.where(ok.reshape(len(uniq), n)[g], w[g], 0.0)))
            for g, ok in zip(np.ravel(which).tolist(), passing)]


@takes_prescription
def focus_table(lens: Prescription, *, n_focus: int = N_FOCUS, grid_half_mm: float = GRID_HALF_MM) -> FocusTable:
    """Tabulate ``lens``'s focus states (module notes). Raises OpticsError when the lens passes no
    ray at the film centre."""
    from ..optics.focusing import closest_focus, focus, gaussian_at_focus
    from ..optics.paraxial import STOP_OPENING_TOLERANCE
    from ..optics.state import camera_state
    from ..trace.camera_tracer import CameraTracer
    from .blender_pupil import iris_levels, radial_pupil_table

    if isinstance(n_focus, bool) or not isinstance(n_focus, int) or n_focus < 2:
        raise InputError(f"a focus table needs at least 2 states, got {n_focus!r}")
    near = closest_focus(lens) * (1 + 1e-6)  # a hair beyond: rounding must not ask closer
    step = 1000.0 / near / (n_focus - 1)  # 1/m
    marks = np.array([math.inf] + [1000.0 / (step * i) for i in range(1, n_focus)])
    marks[-1] = max(marks[-1], near)
    n_open = gaussian_at_focus(lens, math.inf).f_number * (1 + 1e-9)
    k = camera_state(lens, fstop=n_open).stop_semi_diameter * n_open  # the one iris rule, at infinity focus
    n_min = n_open / (1 + STOP_OPENING_TOLERANCE)
    levels = iris_levels(k / n_min, k / n_open)
    film_z, vz, radial, rects, stopped, norm = [], [], [], [], [], []
    for mk in marks:
        st = focus(lens, float(mk))
        tracer = CameraTracer(st.prescription, st.film_z)  # the lens at this focus state as the file stops it
        t = tracer.film_side_table
        film_z.append(st.film_z)
        vz.append(t.vertex_z)
        if lens.is_anamorphic:
            b, rect, rect_levels = _rect_tables(tracer, levels[0], grid_half_mm)
            rects.append(rect)
            stopped.append(rect_levels)
            norm.append(_centre_norms(tracer, [np.array(b.rect_at(0.0, 0.0))] * len(levels), levels))
        else:
            radial.append(radial_pupil_table(tracer.lens, st.film_z, levels))
            b = _centre_bounds(tracer.lens, radial[-1][0, 0])
            norm.append(_centre_norms(tracer, [_ellipse_rect(e) for e in radial[-1][:, 0]], levels))
        if mk == marks[0]:
            table0, bounds0 = t, (b if lens.is_anamorphic else None)
            loss = tracer.centre_weight(b, samples=64, fresnel=True) / tracer.centre_weight(b, samples=64)
    if not all(min(v) > 0 for v in norm):
        raise OpticsError(f"no ray from the film centre passes through {lens.name!r} at some focus")
    def arr(v):
        return np.array(v) if v else None

    return FocusTable(lens, marks, step, np.array(film_z), np.array(vz), arr(radial), arr(rects), arr(stopped),
                      np.array(norm), table0, bounds0, float(k), float(n_open), float(n_min), float(near), float(loss))


def _rect_tables(tracer, semi_max, grid_half_mm):
    """(PupilBounds at the widest iris, its rectangles, the rectangles at each of :data:`STOP_LEVELS`) of one
    focus state's :class:`~physcam.trace.camera_tracer.CameraTracer`."""
    nx, ny = _GRID
    q = tracer.lens
    semi_file = q.surfaces[q.stop_index].semi_diameter
    # the stop's semi-diameter as a prescription stopped to each fraction of the file's holds it
    b = tracer.stopped_pupil_bounds([float(semi_file * (semi_max / semi_file))], grid_half_mm, grid_half_mm,
                                    nx=nx, ny=ny, samples=48)[0]
    levels = tracer.stopped_pupil_bounds([float(semi_file * (f * semi_max / semi_file)) for f in STOP_LEVELS],
                                         grid_half_mm, grid_half_mm, nx=nx, ny=ny, samples=32)
    return b, b.rects, [lv.rects for lv in levels]


def _num32(x) -> str:
    """Nine significant digits: a float32 exactly (OSL computes in float32)."""
    return osl_number(float(format(float(x), ".9g")))


def _arr32(name, values, size) -> str:
    a = np.asarray(values, float).ravel()
    if not np.isfinite(a).all():
        _num32(a[~np.isfinite(a)][0])  # raises osl_number's error
    # _num32 of each, inlined (osl_number of a finite float: its repr, with ".0" when that is an integer)
    nums = [repr(float(format(v, ".9g"))) for v in a.tolist()]
    return f"    float {name}[{size}] = {{{', '.join(r if ('.' in r or 'e' in r) else r + '.0' for r in nums)}}};"


def _arr32_once(ft: FocusTable, name, values, size) -> str:
    """:func:`_arr32`, written once per focus table and values (``ft.osl_lines``)."""
    a = np.asarray(values, float)
    key = (name, size, a.shape, a.tobytes())
    if key not in ft.osl_lines:
        ft.osl_lines[key] = _arr32(name, a, size)
    return ft.osl_lines[key]


def ghost_rows(ft: FocusTable) -> tuple[list[int], list[int]]:
    """The lens's ghost paths (:func:`physcam.analysis.image_quality.ghosts.ghost_pairs` order) as the shader's rows
    (film side first): path (i, j) reflects first, from the film, at row N-1-j, then at row N-1-i."""
    from ..analysis.image_quality.ghosts import ghost_pairs

    require_type("ft", ft, FocusTable, "physcam.export.blender_focus.focus_table(lens)")
    n = len(ft.table)
    pairs = ghost_pairs(ft.lens)
    return [n - 1 - j for _, j in pairs], [n - 1 - i for i, _ in pairs]


def focus_table_shader(ft: FocusTable, *, dispersion: bool = False, fresnel: bool = False, focus_m: float = 3.0,
                       fstop: float = 0.0, sensor_mm=(DEFAULT_SENSOR_WIDTH_MM, DEFAULT_SENSOR_HEIGHT_MM),
                       pupil_mm=None) -> str:
    """The template with ``ft``'s focus table: focus, f-stop, sensor (with Blender's sensor fit and
    the frame's aspect), iris and ghosts are shader parameters (defaults from the keywords; ``fstop``
    0 is wide open). ``pupil_mm``: the entrance pupil's distance in front of the film at each focus
    state; given, the camera's origin is the entrance pupil (the film behind it), else the film plane."""
    from .blender_pupil import N_LEVEL, N_RADIAL, RADIAL_MAX_MM

    require_type("ft", ft, FocusTable, "physcam.export.blender_focus.focus_table(lens)")
    n_focus = len(ft.marks_mm)
    n = len(ft.table)
    defines, data = lens_data(ft.table, None, ft.lens.wavelength_nm, ft.bounds, dispersion=dispersion,
                              fresnel=fresnel)
    defines += ["#define PHYSCAM_FOCUS_TABLE 1", "#define PHYSCAM_APERTURE 1", "#define PHYSCAM_POLYGON 1",
                f"#define N_FOCUS {n_focus}", f"#define N_VZ_TAB {n_focus * n}", f"#define N_IRIS {N_LEVEL}",
                f"#define N_NORM_TAB {n_focus * N_LEVEL}",
                f"#define FOCUS_INV_STEP {_num32(ft.inv_step_per_m)}", f"#define IRIS_K {_num32(ft.iris_k)}",
                f"#define FSTOP_OPEN {_num32(ft.fstop_open)}", f"#define FSTOP_MIN {_num32(ft.fstop_min)}",
                f"#define SEMI_MAX {_num32(ft.semi_max)}", f"#define FOCUS_DEFAULT_M {osl_number(focus_m)}",
                f"#define FSTOP_DEFAULT {osl_number(fstop)}", f"#define SENSOR_W_DEFAULT {osl_number(sensor_mm[0])}",
                f"#define SENSOR_H_DEFAULT {osl_number(sensor_mm[1])}",
                f"#define ASPECT_DEFAULT {osl_number(sensor_mm[0] / sensor_mm[1])}"]
    if ft.radial is not None:
        defines += ["#define PHYSCAM_RADIAL_PUPIL 1", f"#define N_RAD {N_RADIAL}",
                    f"#define N_RAD_TAB {ft.radial.size}", f"#define RAD_MAX {osl_number(RADIAL_MAX_MM)}",
                    f"#define RAD_STEP {osl_number(RADIAL_MAX_MM / (N_RADIAL - 1))}", f"#define N_TRY {N_TRY}"]
        data.append(_arr32_once(ft, "RAD_TAB", ft.radial, "N_RAD_TAB"))
    else:
        defines += [f"#define N_LEVEL {1 + len(STOP_LEVELS)}",
                    f"#define N_RECT_TAB {ft.rects[0].size * n_focus * (1 + len(STOP_LEVELS))}",
                    f"#define GRID_HW {osl_number(ft.bounds.xs[-1])}", f"#define GRID_HH {osl_number(ft.bounds.ys[-1])}"]
        data += [_arr32_once(ft, "RECT_TAB", np.concatenate([ft.rects[:, None], ft.rects_stopped], axis=1), "N_RECT_TAB"),
                 osl_array("STOP_LEVEL", (1.0,) + STOP_LEVELS, "N_LEVEL")]
    # with Fresnel on, the centre's transmission at infinity is in the norm (it hardly changes with focus)
    norm = ft.norm * (ft.fresnel_loss if fresnel else 1.0)
    ga, gb = ghost_rows(ft)
    if ga:
        from ..lens.geometry import sag

        rear = ft.lens.surfaces[-1]  # the film side's first surface: its rim's depth (ghost samples aim at it)
        sags = [sag(rear, rear.semi_diameter, ax) for ax in ("x", "y")]
        defines += ["#define PHYSCAM_GHOSTS 1", f"#define N_GHOST {len(ga)}",
                    f"#define REAR_SAG_LO {_num32(min(sags + [0.0]))}", f"#define REAR_SAG_HI {_num32(max(sags + [0.0]))}",
                    f"#define FRESNEL_LOSS {_num32(ft.fresnel_loss)}"] + ([] if fresnel else ["#define PHYSCAM_SP 1"])
        data += [osl_array("GHOST_A", ga, "N_GHOST", "int"), osl_array("GHOST_B", gb, "N_GHOST", "int")]
    if pupil_mm is not None:
        if len(pupil_mm) != n_focus:
            raise InputError(f"pupil_mm needs one distance per focus state ({n_focus}), got {len(pupil_mm)}")
        defines.append("#define PHYSCAM_PUPIL_ORIGIN 1")
        data.append(_arr32("PUPIL_TAB", pupil_mm, "N_FOCUS"))
    data += [_arr32("FILM_Z_TAB", ft.film_z, "N_FOCUS"), _arr32("NORM_TAB", norm, "N_NORM_TAB"),
             _arr32("VZ_TAB", ft.vertex_z, "N_VZ_TAB"), osl_array("SEMI_OPEN", ft.table.semi_diameter, "N_SURF"),
             _arr32("IRIS_LEVEL", ft.levels, "N_IRIS")]
    head = [f"// {osl_comment(ft.lens.name)}: {n_focus} focus states from infinity to {ft.closest_mm / 1000:.3g} m "
            f"(uniform in 1/distance); dispersion {'on' if dispersion else 'off'}, Fresnel {'on' if fresnel else 'off'}."]
    return render_template(head + defines, data)

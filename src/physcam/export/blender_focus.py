"""A Blender OSL camera whose focus, f-stop, sensor and iris are shader parameters.

:func:`focus_table` tabulates physcam's focus states of a lens (:func:`physcam.optics.focusing.focus`:
unit focusing moves the film, internal focusing the groups; breathing comes with them) at marks
uniform in 1/distance from infinity to the closest focus; :func:`focus_table_shader` writes the
template ``osl/physcam_lens.osl.in`` with that table, and the shader blends the two states that
bracket its ``focus_distance`` parameter (metres from the film plane), linearly in 1/distance. The
iris follows physcam's one rule (:func:`~physcam.optics.state.camera_state`'s iris, sized at
infinity focus): paraxial, so its semi-diameter is K / N with K tabulated here. The exit-pupil
rectangles are those of the open lens and of the lens stopped to :data:`STOP_LEVELS` over a film
square of :data:`GRID_HALF_MM` (any sensor that fits it; the shader samples the smallest that holds
its iris), the weight normalised at the film centre of each state (the centre renders 1 at every
stop; with Fresnel on, the centre's transmission at infinity is divided out too). Keyframing the parameters renders a focus pull or an iris change with no rebuild.
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


@dataclasses.dataclass
class FocusTable:
    """physcam's focus states of one lens, film side first (the tracing order)."""

    lens: Prescription
    marks_mm: np.ndarray  # focus marks from the film plane, inf first
    inv_step_per_m: float  # spacing of the marks in 1/metres
    film_z: np.ndarray  # (n,) film plane z, lens space
    vertex_z: np.ndarray  # (n, surfaces)
    rects: np.ndarray  # (n, ny, nx, 4) exit-pupil rectangles of the open lens
    rects_stopped: np.ndarray  # (n, len(STOP_LEVELS), ny, nx, 4): the same with the iris at each level
    norm: np.ndarray  # (n,) mean weight at the film centre, open
    table: object  # SurfaceTable at infinity (the rows that do not move)
    bounds: object  # PupilBounds at infinity (the grid)
    iris_k: float  # iris semi-diameter x f-number (mm)
    fstop_min: float  # the lens wide open
    closest_mm: float
    fresnel_loss: float  # Fresnel transmission at the film centre at infinity (uncoated)


def _centre_norm(q, film_z, bounds, fresnel: bool = False) -> float:
    from ..trace.trace import camera_rays

    m = 64
    u = (np.arange(m) + 0.5) / m
    uu, vv = [a.ravel() for a in np.meshgrid(u, u)]
    cr = camera_rays(q, np.zeros((uu.size, 2)), np.stack([uu, vv], axis=1), film_z, bounds=bounds, fresnel=fresnel)
    return float(np.mean(cr.weight))


@takes_prescription
def focus_table(lens: Prescription, *, n_focus: int = N_FOCUS, grid_half_mm: float = GRID_HALF_MM) -> FocusTable:
    """Tabulate ``lens``'s focus states (module notes). Raises OpticsError when the lens passes no
    ray at the film centre."""
    from ..optics.focusing import closest_focus, focus, gaussian_at_focus
    from ..optics.state import camera_state
    from ..trace.pupil_bounds import exit_pupil_bounds
    from ..trace.surfaces import surface_table

    if isinstance(n_focus, bool) or not isinstance(n_focus, int) or n_focus < 2:
        raise InputError(f"a focus table needs at least 2 states, got {n_focus!r}")
    near = closest_focus(lens) * (1 + 1e-6)  # a hair beyond: rounding must not ask for closer than it reaches
    step = 1000.0 / near / (n_focus - 1)  # 1/m
    marks = np.array([math.inf] + [1000.0 / (step * i) for i in range(1, n_focus)])
    marks[-1] = max(marks[-1], near)
    film_z, vz, rects, stopped, norm = [], [], [], [], []
    nx, ny = _GRID
    for mk in marks:
        st = focus(lens, float(mk))
        q = st.prescription
        t = surface_table(q, reverse=True, coating="none")
        b = exit_pupil_bounds(q, grid_half_mm, grid_half_mm, st.film_z, nx=nx, ny=ny, samples=48)
        film_z.append(st.film_z)
        vz.append(t.vertex_z)
        rects.append(b.rects)
        stopped.append([exit_pupil_bounds(_stopped(q, f), grid_half_mm, grid_half_mm, st.film_z, nx=nx, ny=ny,
                                          samples=32).rects for f in STOP_LEVELS])
        norm.append(_centre_norm(q, st.film_z, b))
        if mk == marks[0]:
            table0, bounds0 = t, b
            loss = _centre_norm(q, st.film_z, b, fresnel=True) / norm[0]
    if not all(v > 0 for v in norm):
        raise OpticsError(f"no ray from the film centre passes through {lens.name!r} at some focus")
    n_open = gaussian_at_focus(lens, math.inf).f_number * (1 + 1e-9)
    k = camera_state(lens, fstop=n_open).stop_semi_diameter * n_open  # the one iris rule, at infinity focus
    return FocusTable(lens, marks, step, np.array(film_z), np.array(vz), np.array(rects), np.array(stopped),
                      np.array(norm), table0,
                      bounds0, float(k), float(n_open), float(near), float(loss))


def _stopped(q: Prescription, fraction: float) -> Prescription:
    """``q`` with its stop's semi-diameter times ``fraction``."""
    s = list(q.surfaces)
    k = q.stop_index
    s[k] = dataclasses.replace(s[k], semi_diameter=float(s[k].semi_diameter * fraction))
    return q.with_surfaces(s)


def _num32(x) -> str:
    """Nine significant digits: a float32 exactly (OSL computes in float32)."""
    return osl_number(float(format(float(x), ".9g")))


def _arr32(name, values, size) -> str:
    return f"    float {name}[{size}] = {{{', '.join(_num32(v) for v in np.asarray(values, float).ravel())}}};"


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
    """The template with ``ft``'s focus table: focus, f-stop, sensor, iris and ghosts are shader
    parameters (defaults from the keywords; ``fstop`` 0 is wide open). ``pupil_mm``: the entrance
    pupil's distance in front of the film at each focus state; given, the camera's origin is the
    entrance pupil (the film behind it), else the film plane."""
    require_type("ft", ft, FocusTable, "physcam.export.blender_focus.focus_table(lens)")
    n_focus = len(ft.marks_mm)
    n = len(ft.table)
    defines, data = lens_data(ft.table, None, ft.lens.wavelength_nm, ft.bounds, dispersion=dispersion,
                              fresnel=fresnel)
    defines += ["#define PHYSCAM_FOCUS_TABLE 1", "#define PHYSCAM_APERTURE 1", "#define PHYSCAM_POLYGON 1",
                f"#define N_FOCUS {n_focus}", f"#define N_VZ_TAB {n_focus * n}",
                f"#define N_LEVEL {1 + len(STOP_LEVELS)}",
                f"#define N_RECT_TAB {ft.rects[0].size * n_focus * (1 + len(STOP_LEVELS))}",
                f"#define FOCUS_INV_STEP {_num32(ft.inv_step_per_m)}", f"#define IRIS_K {_num32(ft.iris_k)}",
                f"#define FSTOP_MIN {_num32(ft.fstop_min)}", f"#define FOCUS_DEFAULT_M {osl_number(focus_m)}",
                f"#define FSTOP_DEFAULT {osl_number(fstop)}", f"#define SENSOR_W_DEFAULT {osl_number(sensor_mm[0])}",
                f"#define SENSOR_H_DEFAULT {osl_number(sensor_mm[1])}",
                f"#define GRID_HW {osl_number(ft.bounds.xs[-1])}", f"#define GRID_HH {osl_number(ft.bounds.ys[-1])}"]
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
    data += [_arr32("FILM_Z_TAB", ft.film_z, "N_FOCUS"), _arr32("NORM_TAB", norm, "N_FOCUS"),
             _arr32("VZ_TAB", ft.vertex_z, "N_VZ_TAB"), osl_array("SEMI_OPEN", ft.table.semi_diameter, "N_SURF"),
             _arr32("RECT_TAB", np.concatenate([ft.rects[:, None], ft.rects_stopped], axis=1), "N_RECT_TAB"),
             osl_array("STOP_LEVEL", (1.0,) + STOP_LEVELS, "N_LEVEL")]
    head = [f"// {osl_comment(ft.lens.name)}: {n_focus} focus states from infinity to {ft.closest_mm / 1000:.3g} m "
            f"(uniform in 1/distance); dispersion {'on' if dispersion else 'off'}, Fresnel {'on' if fresnel else 'off'}."]
    return render_template(head + defines, data)

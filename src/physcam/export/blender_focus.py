"""A Blender OSL camera whose focus, f-stop, sensor and iris are shader parameters.

:func:`focus_table` tabulates physcam's focus states of a lens (:func:`physcam.optics.focusing.focus`:
unit focusing moves the film, internal focusing the groups; breathing comes with them) at the
marks of a :class:`FocusAxis` (from infinity to the closest focus, denser toward it);
:func:`focus_table_shader` writes the template ``osl/physcam_lens.osl.in`` with that table, and the
shader finds its ``focus_distance`` parameter (metres from the film plane) among the marks and
blends the states about it (:func:`blend_weights`: the film plane a cubic Hermite with its
tabulated slopes, the vertices and the entrance pupil a Catmull-Rom cubic; docs/blender.md, "Focus
tables", has the error bound). The
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
from ..errors import InputError, OpticsError, require_positive, require_type
from ..lens.prescription import Prescription, takes_prescription
from ._codetext import osl_comment
from .osl import lens_data, osl_array, osl_number, ray_differential_define, render_template

__all__ = ["FocusAxis", "FocusTable", "blend_weights", "blended_geometry", "focus_axis", "focus_geometry", "focus_table",
           "focus_table_shader", "fill_pupil_tables", "ghost_rows", "hermite_basis", "pupil_marks", "N_FOCUS", "GRID_HALF_MM",
           "PUPIL_STRIDE", "ANAMORPHIC_PUPIL_STRIDE", "FIRST_INTERVAL_MIDDLE", "STOP_LEVELS"]

#: Focus states tabulated (infinity first, uniform in :class:`FocusAxis`'s s).
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
#: Every PUPIL_STRIDE-th focus mark (and the last) has its pupil and normalisation tables traced; the
#: marks between are interpolated (:func:`fill_pupil_tables`; docs/blender.md, "Focus tables").
PUPIL_STRIDE = 4
#: For a lens with rotational symmetry, the middle of the first interval (infinity to the first traced mark)
#: is traced too: the infinity mark distrusts area cells the finite marks trust (the double Gauss at f/2.8,
#: film radius 8.6-9.8 mm), and a filled mark is checked only against marks the cubic reads, so without it
#: marks 1-3 (2.5-10 m on the double Gauss) inherit the infinity mark's misses (issue 41, round 9).
FIRST_INTERVAL_MIDDLE = True
#: The same for an anamorphic lens: its exit-pupil rectangles step by a window sample as the lens
#: focuses (not smooth), so every other mark is traced and a mark between holds both neighbours'.
ANAMORPHIC_PUPIL_STRIDE = 2


@dataclasses.dataclass(frozen=True)
class FocusAxis:
    """Where a focus table's marks lie. A mark D (mm from the film plane) has s = sqrt(1 - C / D), C the
    lens's closest focus (:func:`~physcam.optics.focusing.closest_focus`); the marks are uniform in s
    from 1 (infinity) to s_near, the last mark ``near_mm`` (a hair beyond C, so rounding never asks
    closer), and D's place among them, the index, is (n - 1)(1 - s) / (1 - s_near). Why s: a
    unit-focusing lens's closest focus is its 1:1 conjugate, where D = 2f + hiatus + x' + f^2/x'
    (Newton, x x' = f^2; x' the film's extension) is least, so the extension grows as sqrt(D - C) and
    no polynomial in 1/D follows it there (uniform in 1/D and linear, the last interval was out by
    millimetres); in s it is smooth from infinity to 1:1."""

    closest_mm: float
    near_mm: float
    n: int

    @property
    def s_near(self) -> float:
        return math.sqrt(max(1.0 - self.closest_mm / self.near_mm, 0.0))

    def index(self, focus_mm: float) -> float:
        """The fractional index (0 at infinity, n - 1 at the last mark) of a mark ``focus_mm`` from the film."""
        s = math.sqrt(max(1.0 - self.closest_mm / focus_mm, 0.0)) if focus_mm > 0 else 1.0  # 0: infinity, as the shader
        return min(max((self.n - 1) * (1.0 - s) / (1.0 - self.s_near), 0.0), self.n - 1.0)

    def mark(self, index: float) -> float:
        """The mark (mm from the film plane; inf at index 0) at a fractional index."""
        if index <= 0:
            return math.inf
        if index >= self.n - 1:
            return self.near_mm
        a = index / (self.n - 1) * (1.0 - self.s_near)  # 1 - s
        return self.closest_mm / (a * (2.0 - a))  # C / (1 - s^2)

    @property
    def marks_mm(self) -> np.ndarray:
        return np.array([self.mark(k) for k in range(self.n)])


def focus_axis(closest_mm: float, n_focus: int) -> FocusAxis:
    """The :class:`FocusAxis` of ``n_focus`` marks down to ``closest_mm`` (mm from the film)."""
    if isinstance(n_focus, bool) or not isinstance(n_focus, int) or n_focus < 3:
        raise InputError(f"a focus table needs at least 3 states, got {n_focus!r}")
    closest = require_positive("closest focus (mm from the film)", closest_mm)
    return FocusAxis(closest, closest * (1 + 1e-6), n_focus)


def blend_weights(index: float, n: int) -> tuple[int, float, list[int], list[float]]:
    """How the shader blends the states about a fractional focus ``index`` of ``n`` states: (k0, t, taps,
    weights) with k0 the state before it and t in [0, 1] its place to the next (the pupil tables, linear).
    A table T is read at the index as sum(weights[i] * T[taps[i]]): the Catmull-Rom cubic through
    k0 - 1 .. k0 + 2 (slopes (T[k+1] - T[k-1]) / 2; at the ends the quadratic's one-sided slope). The
    film plane is the cubic Hermite with its own slopes: h00 F[k0] + h10 F'[k0] + h01 F[k0+1] + h11 F'[k0+1],
    (h00, h10, h01, h11) = (2t^3 - 3t^2 + 1, t^3 - 2t^2 + t, 3t^2 - 2t^3, t^3 - t^2)."""
    k0 = min(int(math.floor(index)), n - 2)
    t = index - k0
    h00, h10, h01, h11 = hermite_basis(t)
    taps = [k0 - 1, k0, k0 + 1, k0 + 2]
    w = [-0.5 * h10, h00 - 0.5 * h11, h01 + 0.5 * h10, 0.5 * h11]
    if k0 == 0:  # the tap before the first: the quadratic through the first three, extrapolated
        taps[0] = 2
        w[1] += 3 * w[0]
        w[2] -= 3 * w[0]
    if k0 + 2 == n:  # the tap after the last, likewise
        taps[3] = n - 3
        w[2] += 3 * w[3]
        w[1] -= 3 * w[3]
    return k0, t, taps, w


def hermite_basis(t: float) -> tuple[float, float, float, float]:
    """The cubic Hermite basis (h00, h10, h01, h11) at t in [0, 1] (unit interval)."""
    t2, t3 = t * t, t * t * t
    return 2 * t3 - 3 * t2 + 1, t3 - 2 * t2 + t, 3 * t2 - 2 * t3, t3 - t2


def blended_geometry(axis: FocusAxis, geometry, focus_mm: float) -> tuple[float, np.ndarray]:
    """(film_z, vertex_z film side first) of a table's ``geometry`` (:func:`focus_geometry`'s) at the mark
    ``focus_mm`` as the shader blends them (:func:`blend_weights`): its lines in Python."""
    require_type("axis", axis, FocusAxis, "physcam.export.blender_focus.focus_axis(closest_mm, n_focus)")
    film_z, slope, vz = geometry
    k0, t, taps, w = blend_weights(axis.index(float(focus_mm)), axis.n)
    h00, h10, h01, h11 = hermite_basis(t)
    film = h00 * film_z[k0] + h10 * slope[k0] + h01 * film_z[k0 + 1] + h11 * slope[k0 + 1]
    return float(film), sum(wi * np.asarray(vz[i]) for i, wi in zip(taps, w))


@takes_prescription
def focus_geometry(lens: Prescription, axis: FocusAxis, *, states: list | None = None
                   ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(film_z, its slope per index step, vertex_z film side first) of the plain prescription ``lens``
    focused (:func:`physcam.optics.focusing.focus`) at each of ``axis``'s marks: the focus table's
    geometry. The slope is physcam's own at infinity (a difference of exact focus solves 1e-3 index steps
    apart, one-sided), in closed form at the other marks (:func:`_unit_film_slope`, :func:`_internal_film_slope`:
    no more focus solves). ``states``: a list that receives each mark's
    :class:`~physcam.optics.focusing.FocusState` (solved once, for the caller's tables too). The marks'
    states are solved through ``lens``'s lens model (:func:`physcam.optics.lens_model.lens_model_of`), which
    keeps them: a camera state of this prescription object at a mark of the table (the extension's
    per-mark lens reports) then solves no focus again."""
    from ..optics.focusing import focus, focus_method
    from ..optics.lens_model import lens_model_of
    from ..optics.paraxial import gaussian

    require_type("axis", axis, FocusAxis, "physcam.export.blender_focus.focus_axis(closest_mm, n_focus)")
    eps = 1e-3

    def film(x):
        return focus(lens, axis.mark(x)).film_z

    internal = focus_method(lens) == "internal"
    gauss = None if internal else gaussian(lens)
    film_z, slope, vz = [], [], []
    model = lens_model_of(lens)
    for k in range(axis.n):
        st = model.focus_state(axis.mark(k))  # focus(lens, mark), kept for the lens's later camera states
        if states is not None:
            states.append(st)
        film_z.append(st.film_z)
        vz.append(np.asarray(st.prescription.vertex_z, dtype=np.float64)[::-1])  # surface_table(reverse=True)'s
        if internal and k > 0:
            slope.append(_internal_film_slope(lens, axis, k, st.object_distance_mm))
        elif k > 0:
            slope.append(_unit_film_slope(gauss, axis, k))
        elif k == 0:
            slope.append((-3 * st.film_z + 4 * film(eps) - film(2 * eps)) / (2 * eps))
        elif k == axis.n - 1:
            slope.append((3 * st.film_z - 4 * film(k - eps) + film(k - 2 * eps)) / (2 * eps))
        else:
            slope.append((film(k + eps) - film(k - eps)) / (2 * eps))
    return np.array(film_z), np.array(slope), np.array(vz)


def _mark_step(axis: FocusAxis, k: int) -> float:
    """d mark / d index (mm per index step) at the finite mark ``k``: the derivative of C / (a (2 - a))."""
    a = k / (axis.n - 1) * (1.0 - axis.s_near)
    return -axis.closest_mm * (2.0 - 2.0 * a) / (a * (2.0 - a)) ** 2 * (1.0 - axis.s_near) / (axis.n - 1)


def _unit_film_slope(g, axis: FocusAxis, k: int) -> float:
    """d film_z / d index at the finite mark ``k`` of a unit-focusing lens whose Gaussian constants at infinity
    are ``g`` (:func:`physcam.optics.paraxial.gaussian`), in closed form: the film lies s' behind H2 with
    phi s'^2 - b s' + n' T = 0, b = phi T + n' - 1, T the mark less the hiatus (the root
    :func:`physcam.optics.focusing.focus` takes, s' = (b - sqrt(b^2 - 4 phi n' T)) / (2 phi)), so
    d s' / d T = (1 - (b - 2 n') / sqrt(b^2 - 4 phi n' T)) / 2; times d mark / d index."""
    phi, n2 = 1.0 / g.efl, g.image_index
    t = axis.mark(k) - (g.z_rear_principal_plane - g.z_front_principal_plane)
    b = phi * t + n2 - 1.0
    return 0.5 * (1.0 - (b - 2.0 * n2) / math.sqrt(max(b * b - 4.0 * phi * n2 * t, 1e-300))) * _mark_step(axis, k)


def _internal_film_slope(lens: Prescription, axis: FocusAxis, k: int, d: float) -> float:
    """d film_z / d index at mark ``k`` (finite) of an internal-focusing ``lens`` whose subject lies ``d`` mm in
    front of its first vertex there, without another focus solve (a bisection): the mark is d + film_z(d)
    (film_z from the first vertex: the focus groups' gaps at d, then the paraxial image of the subject,
    as :func:`physcam.optics.focusing.focus` solves it), so d film_z / d mark = f' / (1 + f') with f' =
    d film_z / d d by differences 1e-4 d apart (central; at the last mark, the groups' close end, one-sided
    toward farther subjects), times d mark / d index (:meth:`FocusAxis.mark`: C / (a (2 - a)))."""
    from ..optics.focusing import image_distance, interpolated_gaps

    def film(x):
        q = lens.with_thicknesses(interpolated_gaps(lens, x)[0])
        return q.vertex_z[-1] + image_distance(q, x)

    h = 1e-4 * d
    if k == axis.n - 1:
        fp = (-3.0 * film(d) + 4.0 * film(d + h) - film(d + 2 * h)) / (2 * h)
    else:
        fp = (film(d + h) - film(d - h)) / (2 * h)
    return fp / (1.0 + fp) * _mark_step(axis, k)


@dataclasses.dataclass
class FocusTable:
    """physcam's focus states of one lens, film side first (the tracing order)."""

    lens: Prescription
    axis: FocusAxis  # where the marks lie
    film_z: np.ndarray  # (n,) film plane z, lens space
    film_slope: np.ndarray  # (n,) d film_z / d index at each state (the shader's cubic Hermite)
    vertex_z: np.ndarray  # (n, surfaces)
    radial: np.ndarray | None  # (n, len(levels), N_RADIAL, 5) pupil ellipses and areas (blender_pupil); None: anamorphic
    rects: np.ndarray | None  # (n, ny, nx, 4) exit-pupil rectangles at the widest iris (anamorphic only)
    rects_stopped: np.ndarray | None  # (n, len(STOP_LEVELS), ny, nx, 4): the same stopped to each level
    norm: np.ndarray  # (n, len(levels)) mean weight at the film centre, the round iris at each of levels
    table: object  # SurfaceTable at infinity (the rows that do not move)
    bounds: object  # PupilBounds at infinity (the 2-D grid; anamorphic only, else None)
    iris_k: float  # iris semi-diameter x f-number (mm)
    fstop_open: float  # the lens wide open (the file's stop)
    fstop_min: float  # the fastest f-stop accepted: physcam's camera state opens the iris this far
    closest_mm: float
    fresnel_loss: float  # Fresnel transmission at the film centre at infinity (uncoated)
    #: the shader's data lines already written, by name and values (the four shaders of a lens share them)
    osl_lines: dict = dataclasses.field(default_factory=dict, repr=False, compare=False)
    #: a zoom lens's zoom axis (:class:`physcam.export.blender_zoom.ZoomGrid`): the arrays above then
    #: hold zoom x focus blocks (:func:`physcam.export.blender_zoom.zoom_focus_table`); None: a lens without zoom
    zoom: object = None
    #: the iris radii (mm) of the pupil and normalisation tables when not :func:`~physcam.export.blender_pupil.iris_levels`'
    #: (:func:`focus_table` adds levels where the area's interpolation misses: blender_pupil._refined_levels)
    iris_radii: np.ndarray | None = None

    @property
    def marks_mm(self) -> np.ndarray:
        """The focus marks (mm from the film plane, inf first): ``axis.marks_mm``."""
        return self.axis.marks_mm

    @property
    def semi_max(self) -> float:
        """The widest iris's semi-diameter (mm): the stop opened to :attr:`fstop_min`."""
        return self.iris_k / self.fstop_min

    @property
    def levels(self) -> np.ndarray:
        """The iris radii (mm) of the pupil and normalisation tables (:func:`~physcam.export.blender_pupil.iris_levels`)."""
        from .blender_pupil import iris_levels

        if self.zoom is not None:
            return self.zoom.levels
        if self.iris_radii is not None:
            return self.iris_radii
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


#: The film centre's meridional fan of aims (:func:`_centre_disk_norms`): samples from the axis to the rear rim, then
#: rounds of a search splitting each level's bracket in 16 (to 1 / (512 x 16^4) of the rim's reach, 3e-8)
_DISK_FAN, _DISK_SPLIT, _DISK_ROUNDS = 512, 16, 4


def _centre_disk_norms(q, film_z: float, levels, backend: str) -> list[float] | None:
    """:func:`_centre_norms` of a lens with rotational symmetry in closed form, or None where its film centre's
    passing set is not a disk about the axis (then the grid estimate serves). From the film centre a lens with
    rotational symmetry passes, at each iris radius, aims on the rear vertex plane within some radius R of the
    axis; a camera ray aimed at radius r weighs cos^4(theta) A / d^2 (:func:`~physcam.trace.trace.camera_rays`:
    A the sampled region's area, d the film's distance from the rear vertex, cos(theta) = d / sqrt(d^2 + r^2)),
    so the mean weight over any region that holds the disk is (1 / d^2) times the integral of cos^4(theta) over
    it: 2 pi d^2 int_0^R r / (d^2 + r^2)^2 dr = pi R^2 / (d^2 + R^2), exactly (the 64 x 64 grid it replaces was
    within 0.3-0.7 % of a dense trace, docs/performance.md). R per level: along a fan of :data:`_DISK_FAN` aims
    from the axis (y = 0, out past the rear rim as the centre sees it) the passing aims (every other surface
    passes them and they cross the stop within the level's radius, the tracer's test) must be one run from the
    axis, and the first that fails is bracketed by :data:`_DISK_ROUNDS` rounds of :data:`_DISK_SPLIT` aims each."""
    from .blender_pupil_sets import _aims, _rear_boxes

    s = np.asarray(levels, dtype=float)
    r_rear = q.surfaces[-1].semi_diameter
    big = 20.0 * max(float(s.max()), q.surfaces[q.stop_index].semi_diameter)
    reach = 1.05 * _rear_boxes(q, film_z, [0.0], r_rear)[0][1]
    d = float(film_z - q.vertex_z[-1])

    def passing(x):  # which aims (x, 0) pass at each level: x one fan for every level, or a row per level
        ok, rad = _aims(q, film_z, np.zeros(x.size), x.ravel(), np.zeros(x.size), big, backend)
        if x.ndim == 1:
            return ok[None, :] & (rad[None, :] <= s[:, None])
        return (ok & (rad <= np.repeat(s, x.shape[1]))).reshape(x.shape)

    x = np.linspace(0.0, reach, _DISK_FAN + 1)
    p = passing(x)
    n = np.argmin(p, axis=1)  # per level the first aim that fails (0: the axis fails, or none does)
    if (n == 0).any() or ((np.arange(x.size)[None, :] < n[:, None]) != p).any():  # not one run from the axis
        return None
    lo, hi = x[n - 1], x[n]
    rows = np.arange(s.size)
    for _ in range(_DISK_ROUNDS):
        xs = lo[:, None] + (hi - lo)[:, None] * (np.arange(1, _DISK_SPLIT) / _DISK_SPLIT)[None, :]
        p = passing(xs)
        k = np.argmin(np.concatenate([p, np.zeros((s.size, 1), dtype=bool)], axis=1), axis=1)  # the first that fails
        if ((np.arange(_DISK_SPLIT - 1)[None, :] < k[:, None]) != p).any():
            return None
        edges = np.concatenate([lo[:, None], xs, hi[:, None]], axis=1)
        lo, hi = edges[rows, k], edges[rows, k + 1]
    r2 = (0.5 * (lo + hi)) ** 2
    return (math.pi * r2 / (d * d + r2)).tolist()


def _state_norms(tracer, table, levels, backend: str) -> list[float]:
    """The centre normalisation of one focus state (its tracer and radial pupil ``table``): in closed form where the
    film centre passes a disk of aims (:func:`_centre_disk_norms`), else the grid estimate over the table's centre
    ellipses (:func:`_centre_norms`)."""
    from .blender_pupil import _centre_ellipses

    return (_centre_disk_norms(tracer.lens, tracer.film_z, levels, backend)
            or _centre_norms(tracer, [_ellipse_rect(e) for e in _centre_ellipses(table)], levels))


@takes_prescription
def focus_table(lens: Prescription, *, n_focus: int = N_FOCUS, grid_half_mm: float = GRID_HALF_MM,
                pupil_stride: int | None = None) -> FocusTable:
    """Tabulate ``lens``'s focus states (module notes). The pupil and normalisation tables are traced at
    :func:`pupil_marks` (``pupil_stride`` 1: at every mark; None: :data:`PUPIL_STRIDE`, or
    :data:`ANAMORPHIC_PUPIL_STRIDE` for an anamorphic lens; :data:`FIRST_INTERVAL_MIDDLE`) and interpolated between them
    (:func:`fill_pupil_tables`). Raises OpticsError when the lens passes no ray at the film centre."""
    from ..optics.focusing import closest_focus, gaussian_at_focus
    from ..optics.paraxial import STOP_OPENING_TOLERANCE
    from ..optics.state import camera_state
    from ..trace.camera_tracer import CameraTracer
    from .blender_pupil import _tables_backend, iris_levels, refined_pupil_tables

    axis = focus_axis(closest_focus(lens), n_focus)
    states = []
    film_z, slope, vz = focus_geometry(lens, axis, states=states)
    n_open = gaussian_at_focus(lens, math.inf).f_number * (1 + 1e-9)
    k = camera_state(lens, fstop=n_open).stop_semi_diameter * n_open  # the one iris rule, at infinity focus
    n_min = n_open / (1 + STOP_OPENING_TOLERANCE)
    levels = iris_levels(k / n_min, k / n_open)
    if pupil_stride is None:
        pupil_stride = ANAMORPHIC_PUPIL_STRIDE if lens.is_anamorphic else PUPIL_STRIDE
    traced = pupil_marks(n_focus, pupil_stride)
    if FIRST_INTERVAL_MIDDLE and not lens.is_anamorphic and traced[1] > 2:  # the first interval's middle too
        traced = np.unique(np.append(traced, traced[1] // 2))
    radial, rects, stopped, norm, checks = [], [], [], [], []
    tracers = [CameraTracer(states[i].prescription, states[i].film_z) for i in traced.tolist()]  # as the file stops it
    if not lens.is_anamorphic:
        backend = _tables_backend("auto", len(tracers), len(lens.surfaces))  # refined_pupil_tables' own choice
        levels, radial = refined_pupil_tables([(t.lens, t.film_z) for t in tracers], levels, checks=checks, backend=backend)
    for i, tracer in zip(traced.tolist(), tracers):
        if lens.is_anamorphic:
            b, rect, rect_levels = _rect_tables(tracer, levels[0], grid_half_mm)
            rects.append(rect)
            stopped.append(rect_levels)
            norm.append(_centre_norms(tracer, [np.array(b.rect_at(0.0, 0.0))] * len(levels), levels))
        else:
            tab = radial[len(norm)]
            b = _centre_bounds(tracer.lens, tab[0, 0])
            norm.append(_state_norms(tracer, tab, levels, backend))
        if i == 0:
            table0, bounds0 = tracer.film_side_table, (b if lens.is_anamorphic else None)
            loss = tracer.centre_weight(b, samples=64, fresnel=True) / tracer.centre_weight(b, samples=64)
    if not all(min(v) > 0 for v in norm):
        raise OpticsError(f"no ray from the film centre passes through {lens.name!r} at some focus")
    radial, rects, stopped, norm = fill_pupil_tables(traced, n_focus, radial=radial, rects=rects, stopped=stopped,
                                                     norm=norm, checks=checks, levels=levels)
    return FocusTable(lens, axis, film_z, slope, vz, radial, rects, stopped,
                      norm, table0, bounds0, float(k), float(n_open), float(n_min), axis.near_mm, float(loss),
                      iris_radii=levels)


def pupil_marks(n: int, stride: int) -> np.ndarray:
    """The indices of the marks (of ``n``) whose pupil tables are traced: every ``stride``-th from infinity,
    and the last."""
    if isinstance(stride, bool) or not isinstance(stride, int) or stride < 1:
        raise InputError(f"the pupil tables' stride must be a whole number of marks, at least 1, got {stride!r}")
    return np.unique(np.append(np.arange(0, n, stride), n - 1))


def _interpolation_weights(traced: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray]:
    """(cubic, linear): (n, len(traced)) weights giving each of the ``n`` indices from the values at the
    ``traced`` ones (ascending, first 0, last n - 1): the cubic through the four traced indices about it
    (Lagrange; the first or last four at the ends), and the line through the two about it. A traced
    index takes its own value."""
    m = traced.size
    cubic, linear = np.zeros((n, m)), np.zeros((n, m))
    for i in range(n):
        j = min(int(np.searchsorted(traced, i, side="right")) - 1, m - 2)  # traced[j] <= i < traced[j + 1]
        if traced[j] == i:
            cubic[i, j] = linear[i, j] = 1.0
            continue
        t = (i - traced[j]) / (traced[j + 1] - traced[j])
        linear[i, j], linear[i, j + 1] = 1.0 - t, t
        start = min(max(j - 1, 0), max(m - 4, 0))
        nodes = range(start, start + min(4, m))
        for a in nodes:
            cubic[i, a] = math.prod((i - traced[b]) / (traced[a] - traced[b]) for b in nodes if b != a)
    return cubic, linear


def fill_pupil_tables(traced, n: int, *, radial=(), rects=(), stopped=(), norm=(), checks=(), levels=()):
    """(radial, rects, stopped, norm) at every one of ``n`` focus marks from the tables traced at the marks
    ``traced`` (:func:`pupil_marks`; empty sequences give None). Between traced marks each number is the
    cubic in the index through the four traced marks about it (the tables are smooth in the axis's s,
    as the film plane is), and what the shader must hold is grown by that cubic's difference from the
    line through the two about it (for a smooth table, an upper bound of the cubic's error by far):
    an ellipse (cx, ax, ay) has its axes (never below the line's) grown by d_ax, d_ay and then scaled by
    1 + d_cx / ax (then it holds every ellipse within those differences: the triangle inequality in the
    ellipse's own norm) and by its entry's :func:`_roughness`, a
    rectangle its sides moved out. A passing area is trusted (its sign, :func:`~physcam.export.blender_pupil.cell_area`)
    only where every traced table the cubic reads trusts it and the two interpolations agree within
    :data:`~physcam.export.blender_pupil.AREA_TOLERANCE`. With ``checks`` (each traced table's areas at
    :func:`~physcam.export.blender_pupil._check_points` of the iris radii ``levels``, radial_pupil_table's)
    a filled mark is checked as a traced one is instead (:func:`_filled_trust`): a cell a traced mark
    distrusts (its rho or iris interpolation misses there) is not withdrawn at every mark the cubic reads
    it from. A rectangle is empty only where the two traced about it are; next to an empty one it is the other's."""
    from .blender_pupil import AREA_TOLERANCE, cell_area

    traced = np.asarray(traced)
    cubic, linear = _interpolation_weights(traced, n)
    reads = (cubic != 0) | (linear != 0)

    def blend(w, v):
        v = np.asarray(v, dtype=float)
        return (w @ v.reshape(len(v), -1)).reshape((n,) + v.shape[1:])

    out_radial = None
    if len(radial):
        tab = np.asarray(radial, dtype=float)
        c, lin = blend(cubic, tab), blend(linear, tab)
        d = _neighbourhood_max(np.abs(c - lin)[..., :3])  # the shader's reads blend an entry with its neighbours
        c[..., 1:3] = np.maximum(c[..., 1:3], lin[..., 1:3])  # the axes never below the line (a cubic may dip)
        scale = 1.0 + d[..., 0] / c[..., 1]
        area_c, area_l = blend(cubic, cell_area(tab[..., 3])), blend(linear, cell_area(tab[..., 3]))
        untrusted = blend(reads.astype(float), tab[..., 3] < 0) > 0
        if len(checks):  # withdrawn at a traced mark the cubic reads: checked at the filled mark itself
            untrusted &= _filled_trust(traced, levels, np.maximum(area_c, 0.0), c, blend(cubic, checks),
                                       blend(linear, checks), blend(reads.astype(float), cell_area(tab[..., 3]) <= 0) > 0)
        untrusted |= np.abs(area_c - area_l) > AREA_TOLERANCE * np.maximum(np.abs(area_c), 1e-12)
        area = np.maximum(area_c, 0.0)
        scale = scale * _roughness(traced, tab, reads)
        out_radial = np.stack([c[..., 0], (c[..., 1] + d[..., 1]) * scale, (c[..., 2] + d[..., 2]) * scale,
                               np.where(untrusted, -1.0 - area, area), c[..., 4]], axis=-1)
        # where nothing passes at both traced marks about it, an entry holds a neighbour's ellipse (blender_pupil's
        # _fill), which jumps from mark to mark: the line between the two, ungrown (no ray to hold)
        dark = blend(linear, cell_area(tab[..., 3]) <= 0) > 1.0 - 1e-9
        out_radial[..., :3] = np.where(dark[..., None], lin[..., :3], out_radial[..., :3])
        out_radial[traced] = tab
    out_rects = _fill_rects(traced, n, cubic, linear, rects) if len(rects) else None
    out_stopped = _fill_rects(traced, n, cubic, linear, stopped) if len(stopped) else None
    out_norm = None
    if len(norm):
        out_norm = blend(cubic, norm)
        out_norm[traced] = np.asarray(norm, dtype=float)
    return out_radial, out_rects, out_stopped, out_norm


def _filled_trust(traced, levels, area, c, want_c, want_l, unlit) -> np.ndarray:
    """Per entry of the filled radial tables (marks, levels, radii), whether its cell is untrusted, the
    traced marks' own trust left as it is: at a filled mark the shader's area (from the filled entries
    ``area``, ellipses ``c``) is checked against the cubic in the index through the traced marks' check
    areas (``want_c``; what linear in the tables, the shader's error there is the cubic through the traced
    marks' errors), where that cubic and the line (``want_l``) agree within AREA_TOLERANCE, as
    :func:`~physcam.export.blender_pupil.radial_pupil_table` checks a traced mark; ``unlit``: nothing passes
    at a traced mark the cubic reads."""
    from .blender_pupil import AREA_TOLERANCE, _checked_trust

    table = np.concatenate([c[..., :3], area[..., None], c[..., 4:5]], axis=-1)
    doubtful = np.abs(want_c - want_l) > AREA_TOLERANCE * np.maximum(np.abs(want_c), 1e-12)
    untrusted = unlit.copy()
    for i in sorted(set(range(len(area))) - set(np.asarray(traced).tolist())):
        untrusted[i] |= ~_checked_trust(table[i], levels, np.maximum(want_c[i], 0.0), doubtful=doubtful[i])
    return untrusted


def _ellipse_reach(e, f) -> np.ndarray:
    """How far ellipses ``e`` (..., cx, ax, ay) reach out of ellipses ``f``: the largest of sqrt(((x - cx_f) /
    ax_f)^2 + (y / ay_f)^2) over 48 points of each rim of e (at most 1: e lies in f; nan-free, 1 where f is empty)."""
    th = np.linspace(0.0, 2.0 * np.pi, 48, endpoint=False)
    x = e[..., 0:1] + e[..., 1:2] * np.cos(th)
    y = e[..., 2:3] * np.sin(th)
    with np.errstate(divide="ignore", invalid="ignore"):
        r = np.sqrt(((x - f[..., 0:1]) / f[..., 1:2]) ** 2 + (y / f[..., 2:3]) ** 2).max(axis=-1)
    return np.where((f[..., 1] > 0) & (f[..., 2] > 0) & np.isfinite(r), r, 1.0)


def _roughness(traced, tab, reads) -> np.ndarray:
    """Per (mark, level, radius) entry of the filled radial tables, how much the interpolation misses where it
    can be checked (at least 1): each traced mark between the first and the last left out, the cubic and
    the line through the others there, grown as :func:`fill_pupil_tables` grows them, must hold the traced
    ellipse; a mark takes the largest factor it falls short by at the traced marks its own cubic reads
    (``reads``: (marks, traced) booleans), over the entry's neighbours (the shader blends them). The pupil
    tables' ellipses are grown where the shader's blends in film radius and iris miss a traced set, and that
    growth comes and goes from mark to mark (small sets at the frame's edge, stopped far down): a filled mark
    takes the worst of the marks about it. Not every mark's worst: that jitter of 1-4 % in the traced
    ellipses' reach, taken from the whole focus range, grew every filled ellipse 3-11 % in area on the
    double Gauss at f/2.8, and each aim the larger ellipse misses is drawn again from hashed numbers,
    outside the sampler's strata (issue 41, round 10)."""
    m = len(traced)
    per = np.ones((m,) + tab.shape[1:3])
    for j in range(1, m - 1):
        others = np.delete(traced, j)
        cubic, linear = _interpolation_weights(others - others[0], int(others[-1] - others[0]) + 1)
        row = int(traced[j] - others[0])
        c = np.tensordot(cubic[row], np.delete(tab, j, axis=0)[..., :3], axes=1)
        lin = np.tensordot(linear[row], np.delete(tab, j, axis=0)[..., :3], axes=1)
        d = _neighbourhood_max(np.abs(c - lin)[None])[0]
        c[..., 1:3] = np.maximum(c[..., 1:3], lin[..., 1:3])
        scale = 1.0 + d[..., 0] / c[..., 1]
        grown = np.stack([c[..., 0], (c[..., 1] + d[..., 1]) * scale, (c[..., 2] + d[..., 2]) * scale], axis=-1)
        per[j] = np.maximum(1.0, _ellipse_reach(tab[j, ..., :3], grown))
    worst = np.where(np.asarray(reads)[:, :, None, None], per[None], 1.0).max(axis=1)
    return _neighbourhood_max(worst[..., None])[..., 0]


def _neighbourhood_max(v: np.ndarray) -> np.ndarray:
    """Per entry of (marks, levels, radii, c) ``v``, the largest over its level and radius and their neighbours."""
    p = np.pad(v, ((0, 0), (1, 1), (1, 1), (0, 0)), mode="edge")
    n_l, n_r = v.shape[1], v.shape[2]
    return np.max([p[:, a:a + n_l, b:b + n_r] for a in range(3) for b in range(3)], axis=0)


def _fill_rects(traced, n: int, cubic, linear, rects) -> np.ndarray:
    """:func:`fill_pupil_tables`'s rectangles (x0, x1, y0, y1; (0, 0, 0, 0) empty) at every mark."""
    tab = np.asarray(rects, dtype=float)
    full = tab[..., 1] > tab[..., 0]
    c = (cubic @ tab.reshape(len(tab), -1)).reshape((n,) + tab.shape[1:])
    d = np.abs(c - (linear @ tab.reshape(len(tab), -1)).reshape(c.shape))
    grown = np.stack([c[..., 0] - d[..., 0], c[..., 1] + d[..., 1], c[..., 2] - d[..., 2], c[..., 3] + d[..., 3]], axis=-1)
    out = np.zeros_like(grown)
    reads = (cubic != 0) | (linear != 0)
    for i in range(n):
        j = min(int(np.searchsorted(traced, i, side="right")) - 1, len(traced) - 2)
        if traced[j] == i:
            out[i] = tab[j]
            continue
        every = full[reads[i]].all(axis=0)
        a, b = tab[j], tab[j + 1]
        fa, fb = full[j], full[j + 1]
        union = np.stack([np.minimum(np.where(fa, a[..., 0], np.inf), np.where(fb, b[..., 0], np.inf)),
                          np.maximum(np.where(fa, a[..., 1], -np.inf), np.where(fb, b[..., 1], -np.inf)),
                          np.minimum(np.where(fa, a[..., 2], np.inf), np.where(fb, b[..., 2], np.inf)),
                          np.maximum(np.where(fa, a[..., 3], -np.inf), np.where(fb, b[..., 3], -np.inf))], axis=-1)
        held = np.stack([np.minimum(grown[i, ..., 0], union[..., 0]), np.maximum(grown[i, ..., 1], union[..., 1]),
                         np.minimum(grown[i, ..., 2], union[..., 2]), np.maximum(grown[i, ..., 3], union[..., 3])], axis=-1)
        out[i] = np.where(every[..., None], held, np.where((fa | fb)[..., None], union, 0.0))
    out[traced] = tab  # the last mark too (it ends the last interval)
    return out


def _rect_tables(tracer, semi_max, grid_half_mm):
    """(PupilBounds at the widest iris, its rectangles, the rectangles at each of :data:`STOP_LEVELS`) of one
    focus state's :class:`~physcam.trace.camera_tracer.CameraTracer`."""
    nx, ny = _GRID
    q = tracer.lens
    semi_file = q.surfaces[q.stop_index].semi_diameter
    # the stop's semi-diameter as a prescription stopped to each fraction of the file's holds it. The widest
    # iris and the stopped ones share their rays (one trace with the stop opened, each iris's mask the
    # tracer's own test: stopped_pupil_bounds): the widest's rectangles are what a trace of it alone gives,
    # the stopped ones are sampled as finely (48 aims across, not 32) for no more rays
    b, *levels = tracer.stopped_pupil_bounds([float(semi_file * (f * semi_max / semi_file)) for f in (1.0,) + STOP_LEVELS],
                                             grid_half_mm, grid_half_mm, nx=nx, ny=ny, samples=48, mirror=True)
    return b, b.rects, [lv.rects for lv in levels]


def _num32(x) -> str:
    """Nine significant digits: a float32 exactly (OSL computes in float32)."""
    return osl_number(float(format(float(x), ".9g")))


def _arr32(name, values, size) -> str:
    a = np.asarray(values, float).ravel()
    if not np.isfinite(a).all():
        _num32(a[~np.isfinite(a)][0])  # raises osl_number's error
    # _num32 of each (osl_number of the nine-digit rounding: its repr, with ".0" when that is an
    # integer). Where "%.9g" writes a fraction without exponent (1e-4 <= |v| < 1e9) that is the repr
    # already: it strips its zeros, and no shorter decimal names the same double. All are written by
    # one format operation; the numbers that may not be such a fraction (:func:`_maybe_whole_or_exponent`),
    # most of them the tables' 0 and -1, whose literals are looked up, are written first, each on its own,
    # and where "%.9g" writes no point or an exponent the format takes the literal ("%s") instead (no
    # split of the whole text into numbers and join again: 0.13 -> 0.10 s on three lenses' 500,000 numbers)
    vals = a.tolist()
    fmts = ["%.9g"] * len(vals)
    fixed = _WHOLE
    for i in np.flatnonzero(_maybe_whole_or_exponent(a)).tolist():
        r = "%.9g" % vals[i]
        if "." not in r or "e" in r:
            vals[i], fmts[i] = fixed.get(r) or osl_number(float(r)), "%s"
    return f"    float {name}[{size}] = {{{', '.join(fmts) % tuple(vals)}}};"


def _maybe_whole_or_exponent(a: np.ndarray) -> np.ndarray:
    """Where "%.9g" may write no point or an exponent (a superset): |v| under 1e-4 (and a margin) or 1e7 and
    over (from 1e8 the nine digits hold no fraction), or within 0.01 of a whole number (below 1e7 the nine
    digits keep at least two decimals, so a fraction further off stays one)."""
    m = np.abs(a)
    return (m < 1.0001e-4) | (m >= 1e7) | (np.abs(a - np.rint(a)) < 1e-2)


#: osl_number of the whole numbers the tables hold most ("%.9g" writes them without a point).
_WHOLE = {"0": "0.0", "-0": "-0.0", "1": "1.0", "-1": "-1.0"}


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


def _zoom_defines(ft: FocusTable) -> tuple[list[str], list[str]]:
    """A zoom lens's shader defines and data lines (``ft.zoom``: :class:`physcam.export.blender_zoom.ZoomGrid`)."""
    z = ft.zoom
    nz, nf, npu = len(z.geometry_u), len(ft.marks_mm), len(z.pupil_u)
    n_iris = len(z.levels)
    defines = ["#define PHYSCAM_ZOOM 1", f"#define N_ZG {nz}", f"#define N_ZP {npu}", f"#define N_ZEFL {len(z.efl_u_mm)}",
               f"#define N_GEO_TAB {nz * nf}", f"#define ZOOM_DEFAULT_MM {_num32(z.efl_u_mm[0])}",
               f"#define RAD_ZSTRIDE {ft.radial[0].size * nf}", f"#define NORM_ZSTRIDE {nf * n_iris}",
               # the iris rule's numbers at the zoom position (the shader's locals)
               "#define IRIS_K zoom_iris_k", "#define FSTOP_OPEN zoom_fstop_open", "#define FSTOP_MIN zoom_fstop_min",
               "#define SEMI_MAX zoom_semi_max", "#define RAY_DIFF_F_MM zoom_focal_length"]
    data = [_arr32("ZOOM_EFL", z.efl_u_mm, "N_ZEFL"), _arr32("ZOOM_PU", z.pupil_u, "N_ZP"),
            _arr32("ZOOM_IRIS_K", z.iris_k, "N_ZG"), _arr32("ZOOM_FSTOP_OPEN", z.fstop_open, "N_ZG"),
            _arr32("ZOOM_FSTOP_MIN", z.fstop_min, "N_ZG")]
    return defines, data


def focus_table_shader(ft: FocusTable, *, dispersion: bool | None = False, fresnel: bool | None = False,
                       focus_m: float = 3.0, fstop: float = 0.0,
                       sensor_mm=(DEFAULT_SENSOR_WIDTH_MM, DEFAULT_SENSOR_HEIGHT_MM), pupil_mm=None) -> str:
    """The template with ``ft``'s focus table: focus, f-stop, sensor (with Blender's sensor fit and
    the frame's aspect), iris and ghosts are shader parameters (defaults from the keywords; ``fstop``
    0 is wide open). ``pupil_mm``: the entrance pupil's distance in front of the film at each focus
    state; given, the camera's origin is the entrance pupil (the film behind it), else the film plane.
    ``dispersion`` and ``fresnel`` None: the source of all four settings, each chosen by OSL's
    preprocessor from ``#define PHYSCAM_DISPERSION`` / ``PHYSCAM_FRESNEL`` lines written in front of it
    (:func:`physcam.export.blender_variant.variant_source`; the extension's one shader per lens)."""
    from ..optics import paraxial
    from .blender_pupil import N_RADIAL, RADIAL_MAX_MM

    require_type("ft", ft, FocusTable, "physcam.export.blender_focus.focus_table(lens)")
    n_focus = len(ft.marks_mm)
    n = len(ft.table)
    defines, data = lens_data(ft.table, None, ft.lens.wavelength_nm, ft.bounds, dispersion=dispersion,
                              fresnel=fresnel)
    zoom = ft.zoom is not None
    n_states = len(ft.film_z)  # n_focus, or (zoom positions x n_focus) for a zoom lens
    defines += ["#define PHYSCAM_FOCUS_TABLE 1", "#define PHYSCAM_APERTURE 1", "#define PHYSCAM_POLYGON 1",
                f"#define N_FOCUS {n_focus}", f"#define N_VZ_TAB {n_states * n}", f"#define N_IRIS {len(ft.levels)}",
                f"#define N_NORM_TAB {ft.norm.size}", f"#define FOCUS_CLOSEST_M {_num32(ft.axis.closest_mm / 1000.0)}",
                f"#define FOCUS_S_NEAR {_num32(ft.axis.s_near)}"]
    if not zoom:  # a zoom lens's iris rule changes along the zoom: _zoom_defines
        defines += [f"#define IRIS_K {_num32(ft.iris_k)}", f"#define FSTOP_OPEN {_num32(ft.fstop_open)}",
                    f"#define FSTOP_MIN {_num32(ft.fstop_min)}", f"#define SEMI_MAX {_num32(ft.semi_max)}",
                    ray_differential_define(paraxial.gaussian(ft.lens).efl)]
    defines += [f"#define FOCUS_DEFAULT_M {osl_number(focus_m)}",
                f"#define FSTOP_DEFAULT {osl_number(fstop)}", f"#define SENSOR_W_DEFAULT {osl_number(sensor_mm[0])}",
                f"#define SENSOR_H_DEFAULT {osl_number(sensor_mm[1])}",
                f"#define ASPECT_DEFAULT {osl_number(sensor_mm[0] / sensor_mm[1])}"]
    if zoom:
        zd, zdata = _zoom_defines(ft)
        defines += zd
        data += zdata
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
    norms = {f: _arr32("NORM_TAB", ft.norm * (ft.fresnel_loss if f else 1.0), "N_NORM_TAB") for f in (False, True)}
    norm = (["#ifdef PHYSCAM_FRESNEL", norms[True], "#else", norms[False], "#endif"] if fresnel is None
            else [norms[fresnel]])
    ga, gb = ghost_rows(ft)
    if ga:
        from ..lens.geometry import sag

        rear = ft.lens.surfaces[-1]  # the film side's first surface: its rim's depth (ghost samples aim at it)
        sags = [sag(rear, rear.semi_diameter, ax) for ax in ("x", "y")]
        defines += ["#define PHYSCAM_GHOSTS 1", f"#define N_GHOST {len(ga)}",
                    f"#define REAR_SAG_LO {_num32(min(sags + [0.0]))}", f"#define REAR_SAG_HI {_num32(max(sags + [0.0]))}",
                    f"#define FRESNEL_LOSS {_num32(ft.fresnel_loss)}"]
        defines += (["#ifndef PHYSCAM_FRESNEL", "#define PHYSCAM_SP 1", "#endif"] if fresnel is None
                    else [] if fresnel else ["#define PHYSCAM_SP 1"])
        data += [osl_array("GHOST_A", ga, "N_GHOST", "int"), osl_array("GHOST_B", gb, "N_GHOST", "int")]
    if pupil_mm is not None:
        if len(pupil_mm) != n_states:
            raise InputError(f"pupil_mm needs one distance per focus state ({n_states}), got {len(pupil_mm)}")
        defines.append("#define PHYSCAM_PUPIL_ORIGIN 1")
        data.append(_arr32("PUPIL_TAB", pupil_mm, "N_GEO_TAB" if zoom else "N_FOCUS"))
    data += [_arr32("FILM_Z_TAB", ft.film_z, "N_GEO_TAB" if zoom else "N_FOCUS"),
             _arr32("FILM_DZ_TAB", ft.film_slope, "N_GEO_TAB" if zoom else "N_FOCUS"), *norm,
             _arr32("VZ_TAB", ft.vertex_z, "N_VZ_TAB"), osl_array("SEMI_OPEN", ft.table.semi_diameter, "N_SURF"),
             _arr32("IRIS_LEVEL", ft.levels, "N_IRIS")]
    zoom_note = (f" at each of {len(ft.zoom.geometry_u)} zoom positions (pupil tables at {len(ft.zoom.pupil_u)})"
                 if zoom else "")
    variant = ("dispersion and Fresnel as PHYSCAM_DISPERSION and PHYSCAM_FRESNEL say (#define lines written "
               "in front of this source)" if dispersion is None or fresnel is None else
               f"dispersion {'on' if dispersion else 'off'}, Fresnel {'on' if fresnel else 'off'}")
    head = [f"// {osl_comment(ft.lens.name)}: {n_focus} focus states from infinity to {ft.closest_mm / 1000:.3g} m "
            f"(uniform in sqrt(1 - closest / distance)){zoom_note}; {variant}."]
    left = (("PHYSCAM_DISPERSION",) if dispersion is None else ()) + (("PHYSCAM_FRESNEL", "PHYSCAM_SP") if fresnel is None else ())
    return render_template(head + defines, data, left=left)

"""The engine under the wavefront, PSF and MTF analyses: real rays over the pupil of one field,
with their optical path lengths, and the optical path difference they make against the
reference sphere.

Configuration (:func:`setup`): the lens is focused at a mark from the film
(:func:`physcam.optics.focusing.focus`; infinity keeps the prescription and puts the film at
the paraxial image of infinity) and stopped down to an f-number (the stop's semi-diameter
sized by :func:`physcam.optics.focusing.iris_semi_diameter`). Pupil positions come
from the Gaussian engine of the focused lens: the paraxial entrance pupil (plane ``z_ep``,
radius ``r_ep`` at that stop) and exit pupil (``z_xp``).

Field: an object-space angle theta in the Y-Z meridian (positive light travels toward +y and
images on the +y side of the film). At infinity a collimated beam along (0, sin theta, cos
theta); at a finite distance the object point (0, -tan(theta) (z_ep - z_object), z_object),
seen under theta from the paraxial entrance pupil. The chief ray is the ray of the field
through the centre of the real stop (:mod:`physcam.analysis._chief`, Newton aiming); a field
whose chief ray cannot be aimed through the stop (it misses a surface or is totally reflected
even without rims) lies outside the lens's field.

Pupil sampling: a square grid of ``n`` x ``n`` cells on the plane of the paraxial entrance
pupil, each traced at its centre. The grid is laid over the real pupil: a coarse trace of an
overfilled square around the chief ray finds the rays that pass the stop (and its aperture
shape) and every element rim, and the grid covers their bounding square. A cell on the edge
of what passes (a neighbour differs) is traced again at 4 x 4 sub-cell centres, so the pupil's
edge (the real aperture shape, vignetting by rims) is resolved to 1/16 of a cell's area. Each
traced ray carries its cell-area share (1 or 1/16) as a quadrature weight.

Optical path: the kernels add each leg's n (p' - p) . d, signed, so virtual legs of sequential
tracing count negative (:func:`physcam.trace.trace.trace_packed` with ``opl``; one call through
every surface, two around a shaped stop).
At infinity a ray starts with n (d . (p - p_chief)), the path from the plane wavefront through
the chief ray's start. Optical path difference (Welford, *Aberrations of Optical Systems*, 9.2;
the convention of optiland 0.6.3, see docs/image-quality.md): the reference sphere is centred
on the chief ray's point on the film (or a given reference point) and passes through the
paraxial exit pupil point (0, 0, z_xp); each ray is followed along its image-space line back
to that sphere, and W = OPL(chief) - OPL(ray), in waves of the ray's wavelength. With this sign
a film moved away from the lens past the focus gives positive defocus,
W = +dz (1 - cos u') ~ dz rho^2 / (8 N^2).

Lengths in mm, lens space (docs/conventions.md); wavelengths in nm.
"""

from __future__ import annotations

import dataclasses
import math
import threading
from dataclasses import dataclass, field

import numpy as np

from ...errors import InputError, OpticsError, require_finite
from ...optics.state import CameraState

#: Smallest and largest pupil grids (cells across the pupil's bounding square).
MIN_PUPIL_SAMPLES = 16
MAX_PUPIL_SAMPLES = 1024
#: Grid chosen when the caller gives none, before the sampling rules raise it.
DEFAULT_PUPIL_SAMPLES = 64
#: Sub-cells per side traced in a cell on the pupil's edge.
EDGE_SUBSAMPLES = 4


@dataclass(frozen=True)
class Setup:
    """The pupil engine's view of a :class:`~physcam.optics.state.CameraState` (the lens focused and
    stopped once, in the optics layer), plus how to trace it (``backend``)."""

    state: CameraState
    backend: str

    # the names the pupil engine reads, each from the one state
    lens = property(lambda self: self.state.focused)  # focused
    lens_name = property(lambda self: self.state.lens_name)
    fstop = property(lambda self: self.state.fstop)
    focus_from_film_mm = property(lambda self: self.state.focus_from_film_mm)  # inf at infinity
    object_z = property(lambda self: self.state.object_z)  # -inf at infinity
    film_z = property(lambda self: self.state.film_z)  # the film plane (focus plane) in lens space
    # the radius the iris shape is drawn inside: a bladed iris's corners (the round iris's area, docs/conventions.md)
    stop_semi_diameter = property(lambda self: self.state.iris_corner_semi)
    z_ep = property(lambda self: self.state.entrance_pupil_z)
    r_ep = property(lambda self: self.state.entrance_pupil_radius)
    z_xp = property(lambda self: self.state.exit_pupil_z)
    aperture = property(lambda self: self.state.aperture)
    design_wavelength_nm = property(lambda self: float(self.state.lens.wavelength_nm))
    at_infinity = property(lambda self: self.state.at_infinity)


def setup(camera: CameraState, *, backend: str = "auto") -> Setup:
    """The pupil engine's setup of ``camera`` (a :class:`~physcam.optics.state.CameraState`: the lens
    focused and stopped once, in the optics layer) and how to trace it."""
    from ... import _program
    from ...errors import require_type

    require_type("camera", camera, CameraState, "physcam.optics.state.camera_state(lens, focus_mm=..., fstop=...)")
    _program.roomy_heap()  # the program's heap keeps freed pages: the pupils' arrays come and go by the thousand
    return Setup(camera, backend)


# --------------------------------------------------------------------------------------------
# tracing with optical path
@dataclass
class Traced:
    """Rays after the last surface (lens space) with their optical path so far and their fate."""

    x: np.ndarray
    y: np.ndarray
    z: np.ndarray
    L: np.ndarray
    M: np.ndarray
    N: np.ndarray
    opl: np.ndarray
    ok: np.ndarray
    amplitude: np.ndarray  # sqrt of the aperture density at the stop (1 for a plain stop)

    _KEYS = ("x", "y", "z", "L", "M", "N", "opl", "ok", "amplitude")

    def take(self, idx) -> "Traced":
        return Traced(*(getattr(self, k)[idx] for k in self._KEYS))


def _concat(parts) -> Traced:
    return Traced(*(np.concatenate([getattr(p, k) for p in parts]) for k in Traced._KEYS))


class _Tracer:
    """One focused, stopped-down lens: the packed table, reused for every batch.

    A batch may mix wavelengths (the kernels take each ray's own, and add each leg's optical path
    in the same call); every batch of the analyses is made as large as it can be (all wavelengths,
    all fields of a chart) to call them few times."""

    def __init__(self, st: Setup):
        from ...trace.camera_tracer import camera_tracer
        from ...trace.kernels import get_kernel
        from ...trace.kernels._layout import pack

        self.st = st
        # the camera's tracer: its lens focused and stopped to the iris's corners (st.stop_semi_diameter)
        self.table = camera_tracer(st.state).scene_side_table
        self.S, self.kinds = pack(self.table)
        self.stop_row = int(np.flatnonzero(self.table.index == st.lens.stop_index)[0])
        self.kernel = get_kernel(st.backend)
        self._n = {}

    def plan(self, rays: float) -> None:
        """Pick the kernel for a job of about ``rays`` rays through every surface, known ahead:
        the numpy kernel where it does the whole job in less time than loading numba takes
        (:func:`physcam.trace.kernels.backend_for_job`; both kernels give the same rays)."""
        from ...trace.kernels import backend_for_job, get_kernel

        self.kernel = get_kernel(backend_for_job(self.st.backend, rays * (self.S.shape[0] + 1)))

    def indices(self, wavelength_nm: float) -> tuple[np.ndarray, float]:
        """(index before each row, index of image space) at one wavelength."""
        w = float(wavelength_nm)
        if w not in self._n:
            nb = self.table.index_before(w)
            ni = float(self.table.index_after(w)[-1])
            if not (np.isfinite(nb).all() and math.isfinite(ni) and ni > 0):
                raise OpticsError(f"a medium of {self.st.lens_name!r} has no usable index at {w:g} nm")
            self._n[w] = (nb, ni)
        return self._n[w]

    def n_object(self, wavelength_nm: float) -> float:
        return float(self.indices(wavelength_nm)[0][0])

    def n_image(self, wavelength_nm: float) -> float:
        return self.indices(wavelength_nm)[1]

    def trace(self, columns, opl0, wavelengths, *, clip=True, unit=False) -> Traced:
        """Trace rays given as six columns (x, y, z of the start, the direction's x, y, z; 1-D, one
        length) with per-ray ``wavelengths`` (nm) front to back, adding n (p' - p) . d per leg.
        ``unit``: the directions are :func:`unit_directions` already (finite starts of the pupil
        grids), so the batch is made of the columns as they are."""
        from ...trace import OK, RayBatch
        from ...trace.trace import trace_packed

        wl = np.broadcast_to(np.asarray(wavelengths, dtype=float), (np.shape(columns[0])[0],))
        rest = wl  # every medium usable at every wavelength (a batch has a few; np.unique imports numpy.ma)
        while rest.size:
            self.indices(rest[0])
            rest = rest[rest != rest[0]]
        if unit:  # what RayBatch.from_columns makes of them, without normalising them again
            n = wl.shape[0]
            rays = RayBatch(*(np.ascontiguousarray(c, dtype=np.float64) for c in columns), wl.copy(), np.ones(n),
                            np.zeros(n, dtype=np.uint8))
        else:
            rays = RayBatch.from_columns(*columns, wl)
        opl = np.array(opl0, dtype=np.float64, copy=True)
        amp = np.ones(len(rays))
        # the kernel adds each leg's optical path: one call through every row, or two around a shaped stop
        shaped = clip and self.st.aperture is not None
        cut = self.stop_row + 1 if shaped else self.S.shape[0]
        trace_packed(self.kernel, rays, self.S[:cut], self.kinds[:cut], clip=clip, fresnel=False, end_z=None, opl=opl)
        if shaped:
            r = self.S[self.stop_row, 6]  # SEMI: the stop's semi-diameter at this f-stop
            dens = self.st.aperture.density_at(rays.x / r, rays.y / r)
            blocked = (rays.flag == OK) & ~(dens > 0.0)
            rays.flag[blocked] = 2  # CLIPPED
            amp = np.sqrt(np.maximum(dens, 0.0))
            trace_packed(self.kernel, rays, self.S[cut:], self.kinds[cut:], clip=clip, fresnel=False, end_z=None,
                         opl=opl)
        ok = (rays.flag == OK) & np.isfinite(opl)
        return Traced(rays.x, rays.y, rays.z, rays.L, rays.M, rays.N, opl, ok, np.where(ok, amp, 0.0))


# --------------------------------------------------------------------------------------------
# the field: object point or beam direction, and the chief ray
@dataclass(frozen=True)
class Field:
    field_deg: float
    wavelength_nm: float
    direction: np.ndarray | None  # collimated beam (at infinity)
    object_point: np.ndarray | None  # finite object
    chief_start: np.ndarray
    chief_direction: np.ndarray
    chief_ep_xy: tuple[float, float]  # where the chief ray crosses the entrance-pupil plane


def _outside(st: Setup, field_deg: float, wl: float, why: str) -> OpticsError:
    from .._chief import field_limit_deg

    try:
        lim = field_limit_deg(st.lens, "y", max_deg=89.0, wavelength_nm=wl, tol_deg=0.05, backend=st.backend)
        extra = f"; its chief rays pass up to {lim:.2f} degrees"
    except Exception:  # noqa: BLE001 - only for the message
        extra = ""
    return OpticsError(f"field {field_deg:g} degrees lies outside the field of {st.lens_name!r}: {why}{extra}")


def field_angles(fields_deg) -> list[float]:
    try:
        seq = np.atleast_1d(np.asarray(fields_deg, dtype=object)).ravel().tolist()
    except Exception:  # noqa: BLE001
        raise InputError(f"field angles must be numbers in degrees, got {fields_deg!r:.60}") from None
    if isinstance(fields_deg, (str, bytes)) or not seq:
        raise InputError(f"field angles must be numbers in degrees, got {fields_deg!r:.60}")
    out = [require_finite("field angle", f) for f in seq]
    for f in out:
        if not -89.0 < f < 89.0:
            raise InputError(f"field angle must lie between -89 and 89 degrees, got {f:g}")
    return out


def make_fields(st: Setup, fields_deg, wavelength_nm: float) -> list[Field]:
    """The beams or object points of ``fields_deg`` and their chief rays (through the centre of the stop)."""
    from .._chief import _newton, aim_from_infinity, field_direction

    fds = field_angles(fields_deg)
    th = np.radians(fds)
    wl = float(wavelength_nm)
    if st.at_infinity:
        d = field_direction(th, "y")
        aimed = aim_from_infinity(st.lens, d, wavelength_nm=wl, backend=st.backend)
        out = []
        for i, fd in enumerate(fds):
            if not bool(aimed.ok[i]):
                raise _outside(st, fd, wl, "no ray of this beam passes through the centre of the stop")
            s = aimed.start[i]
            t = (st.z_ep - s[2]) / d[i, 2]
            out.append(Field(fd, wl, d[i], None, s, d[i], (float(s[0] + t * d[i, 0]), float(s[1] + t * d[i, 1]))))
        return out
    from ...trace import RayBatch, trace_through

    objs = np.stack([np.zeros(th.size), -np.tan(th) * (st.z_ep - st.object_z), np.full(th.size, st.object_z)], axis=1)
    k = st.lens.stop_index
    front = st.lens.with_surfaces(st.lens.surfaces[: k + 1])

    def residual(uu, vv):  # aim points (uu, vv) on the entrance-pupil plane -> stop-plane x, y
        o = np.tile(objs, (uu.size // objs.shape[0], 1))
        dirn = np.stack([uu - o[:, 0], vv - o[:, 1], st.z_ep - o[:, 2]], axis=1)
        res = trace_through(front, RayBatch.from_arrays(o, dirn, wl), clip=False, backend=st.backend)
        return res.x, res.y, res.ok

    u, v, ok, _ = _newton(residual, np.zeros(th.size), np.zeros(th.size), max(1.0, st.r_ep))
    out = []
    for i, fd in enumerate(fds):
        if not bool(ok[i]):
            raise _outside(st, fd, wl, "no ray from this object point passes through the centre of the stop")
        o = objs[i]
        dirn = np.array([u[i] - o[0], v[i] - o[1], st.z_ep - o[2]])
        out.append(Field(fd, wl, None, o, o, dirn / np.linalg.norm(dirn), (float(u[i]), float(v[i]))))
    return out


def fields_at_wavelengths(st: Setup, fields_deg, wavelengths_nm, tracer: _Tracer) -> list[list[Field]]:
    """:func:`make_fields` at each wavelength, [wavelength][field]. The chief rays depend on the media's
    indices alone: a wavelength at which every medium has the index of an earlier one (a lens whose
    prescription gives no dispersion) gets that wavelength's chief rays, aimed once."""
    out, aimed = [], {}
    for w in wavelengths_nm:
        try:
            nb, ni = tracer.indices(w)
            key = nb.tobytes() + np.float64(ni).tobytes()
        except OpticsError:  # make_fields says what is wrong at this wavelength
            key = None
        if key is not None and key in aimed:
            out.append([dataclasses.replace(f, wavelength_nm=float(w)) for f in aimed[key]])
            continue
        out.append(make_fields(st, fields_deg, w))
        if key is not None:
            aimed[key] = out[-1]
    return out


def field_for_image_height(st: Setup, height_mm: float, wavelength_nm: float) -> float:
    """The field angle (degrees, Y meridian) whose chief ray meets the film at ``height_mm`` on the y axis:
    the chief ray is aimed back from the film through the centre of the stop (:func:`._chief.aim_from_film`)
    and traced out of the lens; at infinity its direction is the field, at a finite object the point
    where it meets the object plane, seen from the paraxial entrance pupil."""
    return float(fields_for_image_heights(st, [height_mm], wavelength_nm)[0])


def fields_for_image_heights(st: Setup, heights_mm, wavelength_nm: float) -> np.ndarray:
    """:func:`field_for_image_height` of several heights at once (one aiming, one trace: each ray's
    Newton iteration is its own, so the angles are those of one height at a time); the error names
    the first height outside the image circle."""
    from ...trace import RayBatch, trace_through
    from .._chief import aim_from_film

    hs = np.array([require_finite("image height", h) for h in heights_mm], dtype=float)
    out = np.zeros(hs.size)
    idx = np.flatnonzero(hs != 0.0)
    if idx.size == 0:
        return out
    aimed = aim_from_film(st.lens, np.stack([np.zeros(idx.size), hs[idx]], axis=1), st.film_z,
                          wavelength_nm=wavelength_nm, backend=st.backend)
    ok = aimed.ok.copy()
    if ok.any():
        rays = trace_through(st.lens, RayBatch.from_arrays(aimed.start[ok], aimed.direction[ok], wavelength_nm),
                             reverse=True, clip=False, backend=st.backend)
        ok[ok] = rays.ok & (rays.N < 0)
    if not ok.all():
        h = hs[idx[np.flatnonzero(~ok)[0]]]
        raise OpticsError(f"image height {h:g} mm lies outside the image circle of {st.lens_name!r}: no chief ray "
                          f"from there passes through the centre of the stop and out of the lens")
    for i, y, z, M, N in zip(idx, rays.y, rays.z, rays.M, rays.N):  # math.atan2: libm's rounding, as before
        if st.at_infinity:
            out[i] = math.degrees(math.atan2(-float(M), -float(N)))
        else:
            t = (st.object_z - z) / N
            out[i] = math.degrees(math.atan2(-float(y + t * M), st.z_ep - st.object_z))
    return out


def image_circle_radius(st: Setup, wavelength_nm: float, outside_mm: float, tol_mm: float = 0.05) -> float:
    """Largest image height (mm, below ``outside_mm``, which has no chief ray) whose chief ray
    passes out of the lens (:func:`field_for_image_height`), by bisection to ``tol_mm``."""
    lo, hi = 0.0, float(outside_mm)
    while hi - lo > tol_mm:
        mid = 0.5 * (lo + hi)
        try:
            field_for_image_height(st, mid, wavelength_nm)
            lo = mid
        except OpticsError:
            hi = mid
    return lo


def unit_directions(dx, dy, dz):
    """The directions (dx, dy, dz) normalised as :meth:`physcam.trace.RayBatch.from_columns` normalises
    them (scaled by the largest component first, then by the length), bit for bit: a beam's one
    direction is normalised once instead of once per ray."""
    big = np.maximum(np.maximum(np.abs(dx), np.abs(dy)), np.abs(dz))
    dx, dy, dz = dx / big, dy / big, dz / big
    norm = np.sqrt(dx * dx + dy * dy + dz * dz)
    return dx / norm, dy / norm, dz / norm


def _starts(st: Setup, fl: Field, n_object: float, gx: np.ndarray, gy: np.ndarray):
    """Start points and unit directions (six columns, :func:`unit_directions`) and starting optical
    paths of rays aimed at (gx, gy) on the entrance-pupil plane."""
    from .._chief import start_plane_z

    n = gx.size
    if fl.direction is not None:
        d = fl.direction
        z0 = min(st.z_ep, start_plane_z(st.lens)) - 1.0
        t = (st.z_ep - z0) / d[2]
        x, y = gx - t * d[0], gy - t * d[1]
        c = fl.chief_start  # the plane wavefront through the chief ray's start: n d . (p - p_chief)
        opl0 = n_object * ((x - c[0]) * d[0] + (y - c[1]) * d[1] + (z0 - c[2]) * d[2])
        u = unit_directions(*(np.asarray(d[k:k + 1], dtype=np.float64) for k in range(3)))
        return (x, y, np.full(n, z0), *(np.broadcast_to(v, (n,)) for v in u)), opl0
    o = fl.object_point
    start = tuple(np.broadcast_to(v, (n,)) for v in o)
    return (*start, *unit_directions(gx - o[0], gy - o[1], np.full(n, st.z_ep - o[2]))), np.zeros(n)


def _trace_groups(tracer: _Tracer, groups, *, clip=True) -> list[Traced]:
    """Trace several (field, gx, gy) groups in one batch; returns one :class:`Traced` per group."""
    if not groups:
        return []
    # by wavelength, so that the kernels see a few runs of one wavelength (trace.trace_packed)
    order = sorted(range(len(groups)), key=lambda i: groups[i][0].wavelength_nm)
    columns, opls, wls, sizes = [], [], [], []
    for fl, gx, gy in (groups[i] for i in order):
        c, o = _starts(tracer.st, fl, tracer.n_object(fl.wavelength_nm), gx, gy)
        columns.append(c)
        opls.append(o)
        wls.append(np.full(gx.size, fl.wavelength_nm))
        sizes.append(gx.size)
    res = tracer.trace([np.concatenate(c) for c in zip(*columns)], np.concatenate(opls), np.concatenate(wls),
                       clip=clip, unit=True)
    cut = np.cumsum([0] + sizes)
    out: list = [None] * len(groups)
    for j, i in enumerate(order):
        out[i] = res.take(slice(cut[j], cut[j + 1]))
    return out


# --------------------------------------------------------------------------------------------
# the pupil grid
@dataclass
class PupilTrace:
    """Rays over the real pupil of one field at one wavelength (see module notes).

    Grid: ``n`` x ``n`` cells of side ``cell_mm`` on the entrance-pupil plane, centred at
    (``cx``, ``cy``); row index along y, column along x. ``samples``: every traced ray that
    passed, with its cell (``row``, ``col``), quadrature weight (cell-area share), its grid
    coordinates (``gx``, ``gy``, mm) and the traced state after the last surface.
    """

    field: Field
    wavelength_nm: float
    n: int
    cell_mm: float
    cx: float
    cy: float
    row: np.ndarray
    col: np.ndarray
    sub: np.ndarray  # -1 for a cell's centre ray, else the sub-cell (row * EDGE_SUBSAMPLES + column) of an edge ray
    weight: np.ndarray
    gx: np.ndarray
    gy: np.ndarray
    rays: Traced
    chief: Traced
    n_image: float
    launched: int
    r_ep: float
    z_xp: float
    meta: dict = field(default_factory=dict)
    # what depends on the rays alone (the sub-cell layout, the direction slopes per reference): one dict for
    # every wavelength that shares the rays (:func:`trace_pupils` copies a trace with the same dict)
    shared: dict = field(default_factory=dict, repr=False, compare=False)


def _grid_centres(n, cell, cx, cy):
    c = (np.arange(n) + 0.5) * cell - 0.5 * n * cell
    return cx + c, cy + c


def _vignetted(st: Setup, fd: float) -> OpticsError:
    return OpticsError(f"field {fd:g} degrees of {st.lens_name!r} is fully vignetted at f/{st.fstop:.3g}: no ray of it "
                       "passes the stop and every element rim to the film")


def pupil_boxes(st: Setup, fields: list[Field], tracer: _Tracer) -> list[tuple]:
    """Per field, (x0, x1, y0, y1) on the entrance-pupil plane around every ray that passes (one coarse
    grid, overfilling the paraxial pupil and doubled while light touches its border); raise if none passes."""
    boxes: list = [None] * len(fields)
    for m, tries in ((33, 5), (129, 1)):
        half = [1.6 * st.r_ep] * len(fields)
        for _ in range(tries):
            todo = [i for i in range(len(fields)) if boxes[i] is None]
            if not todo:
                return boxes
            grids = []
            for i in todo:
                cx, cy = fields[i].chief_ep_xy
                xs = cx + np.linspace(-half[i], half[i], m)
                ys = cy + np.linspace(-half[i], half[i], m)
                gx, gy = (a.ravel() for a in np.meshgrid(xs, ys))
                grids.append((xs, ys, gx, gy))
            res = _trace_groups(tracer, [(fields[i], g[2], g[3]) for i, g in zip(todo, grids)])
            for i, (xs, ys, _, _), r in zip(todo, grids, res):
                ok = r.ok.reshape(m, m)
                if not ok.any() or ok[0].any() or ok[-1].any() or ok[:, 0].any() or ok[:, -1].any():
                    half[i] *= 2.0
                    continue
                step = xs[1] - xs[0]
                rows, cols = np.nonzero(ok)
                boxes[i] = (xs[cols.min()] - step, xs[cols.max()] + step, ys[rows.min()] - step, ys[rows.max()] + step)
    for i, b in enumerate(boxes):
        if b is None:
            raise _vignetted(st, fields[i].field_deg)
    return boxes


def pupil_box(st: Setup, fl: Field, tracer: _Tracer):
    return pupil_boxes(st, [fl], tracer)[0]


def _same_rays_key(tracer: _Tracer, fl: Field, n: int, box) -> bytes:
    """What a job's rays depend on: the grid, the field's beam or object point and chief ray, and
    every medium's index at the job's wavelength. Two jobs with the same key trace the same rays, bit
    for bit (a lens whose prescription gives no dispersion: its wavelengths differ in diffraction only)."""
    nb, ni = tracer.indices(fl.wavelength_nm)
    parts = [np.asarray([n, *box, ni], dtype=float), nb, fl.chief_start, fl.chief_direction]
    parts += [a for a in (fl.direction, fl.object_point) if a is not None]
    return b"".join(np.ascontiguousarray(a, dtype=float).tobytes() for a in parts)


#: Rays of the pupils traced last that are kept for the next call (about 100 bytes each): `physcam mtf
#: --field` asks one field's wavefront, PSF and MTF, the same rays three times. Only the last camera's
#: pupils are kept; the oldest go first.
RECENT_RAYS = 100_000
_recent: dict = {}
_recent_lock = threading.Lock()


def trace_pupils(st: Setup, jobs, tracer: _Tracer) -> list[PupilTrace]:
    """Trace each job (field, n, box) -- an ``n`` x ``n`` grid over ``box`` with the edge refined -- all
    jobs together: one batch for the cell centres, one for the edge sub-cells, one for the chief rays.
    Jobs whose rays would be the same (:func:`_same_rays_key`: the wavelengths of a lens without
    dispersion; a job of the last call on the same camera, :data:`RECENT_RAYS`) are traced once and
    share the rays, each with its own wavelength."""
    keys = [_same_rays_key(tracer, fl, n, box) for fl, n, box in jobs]
    first: dict = {}
    rep = [first.setdefault(k, j) for j, k in enumerate(keys)]
    with _recent_lock:
        if _recent.get("camera") is not st.state:
            _recent.clear()
            _recent["camera"] = st.state
        known = {j: _recent[keys[j]] for j in first.values() if keys[j] in _recent}
    todo = [j for j in sorted(first.values()) if j not in known]
    traced = dict(zip(todo, _trace_pupils([jobs[j] for j in todo], st, tracer) if todo else []))
    # kept and handed out without what later calls derive from the rays (``shared``: sub-cell arrays)
    traced.update({j: dataclasses.replace(pt, shared={}) for j, pt in known.items()})
    with _recent_lock:
        if _recent.get("camera") is st.state:
            for j in todo:
                _recent[keys[j]] = dataclasses.replace(traced[j], shared={})
            while sum(pt.rays.x.size for k, pt in _recent.items() if k != "camera") > RECENT_RAYS:
                del _recent[next(k for k in _recent if k != "camera")]
    out = []
    for (fl, _, _), r in zip(jobs, rep):
        pt = traced[r]
        out.append(pt if pt.field is fl else dataclasses.replace(pt, field=fl, wavelength_nm=fl.wavelength_nm,
                                                                 n_image=tracer.n_image(fl.wavelength_nm),
                                                                 meta=dict(pt.meta)))
    return out


def _trace_pupils(jobs, st: Setup, tracer: _Tracer) -> list[PupilTrace]:
    q = EDGE_SUBSAMPLES
    grids = []
    for fl, n, box in jobs:
        x0, x1, y0, y1 = box
        side = max(x1 - x0, y1 - y0)
        cx, cy = 0.5 * (x0 + x1), 0.5 * (y0 + y1)
        cell = side / n
        xs, ys = _grid_centres(n, cell, cx, cy)
        GX, GY = np.meshgrid(xs, ys)
        grids.append((n, cell, cx, cy, xs, ys, GX.ravel(), GY.ravel()))
    # the job ahead: every cell centre, and the edge of a round pupil (about 7 n cells) at q x q sub-cells
    tracer.plan(sum(n * n + 7 * n * q * q for _, n, _ in jobs))
    centres = _trace_groups(tracer, [(fl, g[6], g[7]) for (fl, _, _), g in zip(jobs, grids)])
    edges, subs = [], []
    off = ((np.arange(q) + 0.5) / q - 0.5)
    for (fl, n, _), g, c in zip(jobs, grids, centres):
        status = c.ok.reshape(n, n)
        pad = np.pad(status, 1, constant_values=False)  # the grid's border counts as blocked
        edge = np.zeros_like(status)
        for di in (-1, 0, 1):
            for dj in (-1, 0, 1):
                if di or dj:
                    edge |= pad[1 + di:1 + di + n, 1 + dj:1 + dj + n] != status
        er, ec = np.nonzero(edge)
        ox, oy = (a.ravel() * g[1] for a in np.meshgrid(off, off))
        sgx = (g[4][ec][:, None] + ox[None, :]).ravel()
        sgy = (g[5][er][:, None] + oy[None, :]).ravel()
        edges.append((status, edge, er, ec, sgx, sgy))
        subs.append((fl, sgx, sgy))
    subtraced = _trace_groups(tracer, subs)
    ends = np.concatenate([np.stack([fl.chief_start for fl, _, _ in jobs]),
                           np.stack([fl.chief_direction for fl, _, _ in jobs])], axis=1)
    chiefs = tracer.trace(list(ends.T), np.zeros(len(jobs)), np.array([fl.wavelength_nm for fl, _, _ in jobs]),
                          clip=False)
    out = []
    for j, ((fl, n, box), g, c, (status, edge, er, ec, sgx, sgy), sub) in enumerate(
            zip(jobs, grids, centres, edges, subtraced)):
        keep = np.flatnonzero((status & ~edge).ravel())
        sub_ok = np.flatnonzero(sub.ok)
        if keep.size + sub_ok.size == 0:
            raise _vignetted(st, fl.field_deg)
        chief = chiefs.take(slice(j, j + 1))
        if not bool(chief.ok[0]):
            raise OpticsError(f"the chief ray of field {fl.field_deg:g} degrees does not reach the film of "
                              f"{st.lens_name!r}")
        rows_all, cols_all = np.divmod(np.arange(n * n), n)
        out.append(PupilTrace(
            fl, fl.wavelength_nm, int(n), float(g[1]), float(g[2]), float(g[3]),
            np.concatenate([rows_all[keep], np.repeat(er, q * q)[sub_ok]]),
            np.concatenate([cols_all[keep], np.repeat(ec, q * q)[sub_ok]]),
            np.concatenate([np.full(keep.size, -1), np.tile(np.arange(q * q), er.size)[sub_ok]]),
            np.concatenate([np.ones(keep.size), np.full(sub_ok.size, 1.0 / (q * q))]),
            np.concatenate([g[6][keep], sgx[sub_ok]]), np.concatenate([g[7][keep], sgy[sub_ok]]),
            _concat([c.take(keep), sub.take(sub_ok)]), chief, tracer.n_image(fl.wavelength_nm),
            int(n * n + sgx.size), st.r_ep, st.z_xp,
            {"edge_cells": int(er.size), "box": tuple(float(b) for b in box)}))
    return out


# --------------------------------------------------------------------------------------------
# the wavefront on a film plane
@dataclass
class WavefrontSamples:
    """OPD (waves) of every passing ray against the reference sphere for one film plane.

    ``ref_L``, ``ref_M``: direction cosines from each ray's point on the reference sphere to the
    sphere's centre (the plane-wave component the ray stands for; they set the frequency scale)."""

    opd_waves: np.ndarray
    film_x: np.ndarray
    film_y: np.ndarray
    ref_L: np.ndarray
    ref_M: np.ndarray
    reference: tuple[float, float, float]  # centre of the reference sphere (the chief ray's film point)
    radius_mm: float
    chief_film_xy: tuple[float, float]


def chief_point(pt: PupilTrace, film_z: float) -> tuple[float, float, float]:
    c = pt.chief
    t = (film_z - c.z[0]) / c.N[0]
    return float(c.x[0] + t * c.L[0]), float(c.y[0] + t * c.M[0]), float(film_z)


def wavefront_on(pt: PupilTrace, film_z: float, reference=None) -> WavefrontSamples:
    """OPD of the pupil rays for the film at ``film_z`` (reference sphere centred on ``reference``,
    default the chief ray's film point, through the paraxial exit pupil point). The geometry (each
    ray's point on the sphere, its path difference in mm) depends on the rays alone: the wavelengths
    that share them (``pt.shared``) divide the same path difference by their own wavelength."""
    cp = chief_point(pt, film_z)
    key = (float(film_z), cp if reference is None else tuple(float(v) for v in reference), float(pt.n_image))
    last = pt.shared.get("wavefront")
    if last is None or last[0] != key:
        pt.shared["wavefront"] = last = (key, *_sphere_paths(pt, film_z, cp, reference))
    _, path, film_x, film_y, ref_l, ref_m, centre, radius = last
    return WavefrontSamples(path / (pt.wavelength_nm * 1e-6), film_x, film_y, ref_l, ref_m, centre, radius,
                            (cp[0], cp[1]))


def _sphere_paths(pt: PupilTrace, film_z: float, cp, reference):
    """(the chief ray's optical path to the reference sphere less each ray's, in mm; the rays' film x
    and y; the directions L, M from their points on the sphere to its centre; the centre; the radius)
    of :func:`wavefront_on`."""
    C = np.array(cp if reference is None else reference, dtype=float)
    E = np.array([0.0, 0.0, pt.z_xp])
    R = float(np.linalg.norm(C - E))
    if not R > 1e-9:
        raise OpticsError("the film lies on the exit pupil: no reference sphere")

    def to_sphere(r: Traced):
        wx, wy, wz = r.x - C[0], r.y - C[1], r.z - C[2]
        b = wx * r.L + wy * r.M + wz * r.N
        disc = b * b - (wx * wx + wy * wy + wz * wz - R * R)
        t = -b - np.sqrt(np.maximum(disc, 0.0))
        return t, disc >= 0.0

    tc, _ = to_sphere(pt.chief)
    t, hit = to_sphere(pt.rays)
    if not hit.all():
        raise OpticsError(f"rays of field {pt.field.field_deg:g} degrees miss the reference sphere: the wavefront "
                          "is too aberrated for a diffraction calculation (use the geometric MTF)")
    r = pt.rays
    path = (pt.chief.opl[0] + pt.n_image * tc[0]) - (r.opl + pt.n_image * t)
    # the ray's point on the sphere and the direction from it to the centre
    sx, sy = r.x + t * r.L, r.y + t * r.M
    tf = (film_z - r.z) / r.N
    return (path, r.x + tf * r.L, r.y + tf * r.M, (C[0] - sx) / R, (C[1] - sy) / R,
            (float(C[0]), float(C[1]), float(C[2])), R)


# --------------------------------------------------------------------------------------------
# the pupil function on the grid
@dataclass
class PupilFunction:
    """The pupil function on the grid (see module notes) at two resolutions.

    Cells (``n`` x ``n``): ``field`` = sum over a cell's rays of weight x amplitude x exp(-2 pi i W)
    (the cell's integral of the pupil function, for the PSF and the Strehl ratio; made on first use:
    the MTF never reads it), ``amplitude0`` the same with W = 0 (the unaberrated pupil of the same
    shape), ``opd`` the cell's mean OPD (waves), ``mask`` where light passes. Sub-cells (``n q`` x
    ``n q``, q = EDGE_SUBSAMPLES, for the MTF, :func:`sub_cell_pupil`): a binary mask (an edge ray's
    own sub-cell, a whole interior cell), the OPD (an edge ray's own, else interpolated bilinearly
    between cell means) and the aperture amplitude: an overlap of binary masks measures the sheared
    pupil's area, where products of fractional edge cells would underestimate the loss by about half
    a cell of rim.
    """

    amplitude0: np.ndarray
    opd: np.ndarray
    mask: np.ndarray
    cell_mm: float
    wavelength_nm: float
    n_image: float
    slope_x: float  # d(reference direction L)/d(pupil x), 1/mm
    slope_y: float  # d(reference direction M)/d(pupil y), 1/mm
    _pt: object = None
    _ws: object = None
    _field: np.ndarray | None = None
    _lags: dict = field(default_factory=dict)  # (axis, aberrated) -> OTF at whole sub-cell shears

    @property
    def q(self) -> int:
        return EDGE_SUBSAMPLES

    @property
    def sub_cells_across(self) -> int:
        """Sub-cells across the grid (n q)."""
        return self.mask.shape[0] * EDGE_SUBSAMPLES

    @property
    def freq_per_cell_x(self) -> float:
        """Spatial frequency (cycles/mm on the film) of a pupil shear of one cell along x (sagittal)."""
        return self.n_image * abs(self.slope_x) * self.cell_mm / (self.wavelength_nm * 1e-6)

    @property
    def freq_per_cell_y(self) -> float:
        """... along y (tangential)."""
        return self.n_image * abs(self.slope_y) * self.cell_mm / (self.wavelength_nm * 1e-6)

    @property
    def field(self) -> np.ndarray:  # the cells' complex field, made on first use
        if self._field is None:
            self._field = _cell_field(self._pt, self._ws)
        return self._field


def direction_slopes(pt: PupilTrace, ws: WavefrontSamples) -> tuple[float, float]:
    """Least-squares slopes dL/dx and dM/dy of the reference-sphere directions over the pupil grid
    (the affine map from pupil to image-space angle that sets the frequency scale)."""
    w = pt.weight * pt.rays.amplitude
    A = np.stack([np.ones_like(pt.gx), pt.gx - pt.cx, pt.gy - pt.cy], axis=1)
    sw = np.sqrt(w)[:, None]
    sx = sy = 0.0
    if pt.gx.size >= 3:
        cl, *_ = np.linalg.lstsq(A * sw, ws.ref_L * sw[:, 0], rcond=None)
        cm, *_ = np.linalg.lstsq(A * sw, ws.ref_M * sw[:, 0], rcond=None)
        sx, sy = float(cl[1]), float(cm[2])
    if not (abs(sx) > 0 and abs(sy) > 0 and math.isfinite(sx) and math.isfinite(sy)):
        raise OpticsError(f"the pupil of field {pt.field.field_deg:g} degrees is too small to set a frequency scale "
                          f"({pt.gx.size} rays pass)")
    return sx, sy


def pupil_function(pt: PupilTrace, ws: WavefrontSamples) -> PupilFunction:
    n = pt.n
    cells = pt.shared.get("cells")  # what the rays alone give (one for every wavelength that shares them)
    if cells is None:
        idx = pt.row * n + pt.col
        wa = pt.weight * pt.rays.amplitude
        a0 = np.bincount(idx, weights=wa, minlength=n * n)
        mask = a0 > 0
        pt.shared["cells"] = cells = (idx, wa, a0, mask, np.where(mask, a0, 1.0))
    idx, wa, a0, mask, den = cells
    wsum = np.bincount(idx, weights=wa * ws.opd_waves, minlength=n * n)
    wmean = np.where(mask, wsum / den, 0.0).reshape(n, n)
    # the slopes depend on the rays and the reference sphere alone: the same for every wavelength sharing them
    key = ("slopes", ws.reference)
    if key not in pt.shared:
        pt.shared[key] = direction_slopes(pt, ws)
    sx, sy = pt.shared[key]
    return PupilFunction(a0.reshape(n, n), wmean, mask.reshape(n, n), pt.cell_mm, pt.wavelength_nm, pt.n_image,
                         sx, sy, pt, ws)


def _cell_field(pt: PupilTrace, ws: WavefrontSamples) -> np.ndarray:
    """The cells' complex field of :class:`PupilFunction` (its ``field``)."""
    n = pt.n
    idx = pt.row * n + pt.col
    wa = pt.weight * pt.rays.amplitude
    ph = np.exp(-2j * np.pi * ws.opd_waves)  # a ray whose path is longer (W < 0) lags: exp(i k OPL)
    return (np.bincount(idx, weights=wa * ph.real, minlength=n * n)
            + 1j * np.bincount(idx, weights=wa * ph.imag, minlength=n * n)).reshape(n, n)


def _lerp_axis(lo: int, hi: int, q: int):
    """Along one axis, for each sub-cell of cells ``lo`` .. ``hi - 1``: the two cells whose centres it
    lies between (counted from ``lo``, clipped to those cells) and the bilinear weights (1 - f, f)."""
    c = (np.arange(lo * q, hi * q) + 0.5) / q - 0.5
    fl = np.floor(c)
    i0 = np.clip(fl.astype(int), lo, hi - 1)
    f = np.clip(c - fl, 0.0, 1.0)
    return i0 - lo, np.minimum(i0 + 1, hi - 1) - lo, 1.0 - f, f


def _lerp2(a: np.ndarray, rows, cols) -> np.ndarray:
    """Cell values ``a`` at the sub-cells, bilinearly (:func:`_lerp_axis` weights ``rows``, ``cols``).
    Separable: along rows, then along columns; the columns as rows of the transpose, taken whole and
    scaled in place (half the time of a fancy index per column), so the result is column-major."""
    i0, i1, g, f = rows
    along = g[:, None] * np.take(a, i0, axis=0) + f[:, None] * np.take(a, i1, axis=0)
    cols_first = np.ascontiguousarray(along.T)
    i0, i1, g, f = cols
    out = np.take(cols_first, i0, axis=0)
    out *= g[:, None]
    right = np.take(cols_first, i1, axis=0)
    right *= f[:, None]
    out += right
    return out.T


def _sub_cells(pt: PupilTrace) -> dict:
    """What the sub-cell pupil (:func:`sub_cell_pupil`) takes from the rays alone, made once for every
    wavelength that shares them (``pt.shared``): the box of the lit cells with one cell of margin (no
    sub-cell outside it is lit, and a lit sub-cell's bilinear OPD reads only cells within one of its
    own), the bilinear weights there, the interpolation's denominator (the weights of lit cells only),
    the edge rays' own sub-cells, and over the box of the lit sub-cells (``crop``) the aperture
    amplitude ``A`` (0 where no light passes; column-major, as the OPD)."""
    lay = pt.shared.get("sub_cells")
    if lay is not None:
        return lay
    n, q = pt.n, EDGE_SUBSAMPLES
    r0, r1 = max(int(pt.row.min()) - 1, 0), min(int(pt.row.max()) + 2, n)
    c0, c1 = max(int(pt.col.min()) - 1, 0), min(int(pt.col.max()) + 2, n)
    rows, cols = _lerp_axis(r0, r1, q), _lerp_axis(c0, c1, q)
    lit = np.zeros((r1 - r0, c1 - c0))
    lit[pt.row - r0, pt.col - c0] = 1.0
    centre = pt.sub < 0
    edge = ~centre
    amp = pt.rays.amplitude
    cell_amp = np.zeros(lit.shape)
    cell_amp[pt.row[centre] - r0, pt.col[centre] - c0] = amp[centre]
    A = np.repeat(np.repeat(cell_amp, q, axis=0), q, axis=1)
    er = (pt.row[edge] - r0) * q + pt.sub[edge] // q
    ec = (pt.col[edge] - c0) * q + pt.sub[edge] % q
    A[er, ec] = amp[edge]
    lit_rows, lit_cols = np.flatnonzero(A.any(axis=1)), np.flatnonzero(A.any(axis=0))
    crop = np.s_[lit_rows[0]:lit_rows[-1] + 1, lit_cols[0]:lit_cols[-1] + 1]
    den = _lerp2(lit, rows, cols)
    lay = {"box": np.s_[r0:r1, c0:c1], "rows": rows, "cols": cols, "lit": lit, "den": den, "divide": den > 0,
           "er": er, "ec": ec, "edge": edge, "crop": crop, "A": np.asfortranarray(A[crop])}
    pt.shared["sub_cells"] = lay
    return lay


#: The OPD phasors exp(-2 pi i m / 4096) that :func:`unit_phasors` starts from, and the values it takes at a time.
_PHASOR_STEPS = 4096
_PHASOR_TABLE = np.exp(-2j * np.pi * np.arange(_PHASOR_STEPS) / _PHASOR_STEPS)
_PHASOR_BLOCK = 16384


def unit_phasors(w: np.ndarray) -> np.ndarray:
    """exp(-2 pi i w) of a 2-D array of OPDs ``w`` (waves), in the layout of ``w``: numpy's complex
    exponential to 1e-15 in a third of its time here (libm's, about 45 ns a value, was most of an MTF
    chart's OTF). With w = (m + r) / 4096, m whole and |r| <= 1/2: exp(-2 pi i m / 4096) from a table,
    times exp(i t), t = -2 pi r / 4096, from its Taylor series to t^4 and t^3 (|t| <= pi / 4096: the
    first terms left out are below 3e-18), a block of rows at a time so the temporaries stay in the cache."""
    if w.ndim == 2 and w.strides[0] < w.strides[1]:  # column-major: the rows of the transpose
        return unit_phasors(w.T).T
    out = np.empty(w.shape, dtype=complex)
    step = max(1, _PHASOR_BLOCK // max(w.shape[-1], 1))
    for a in range(0, w.shape[0], step):
        _phasor_block(w[a:a + step], out[a:a + step])
    return out


def _phasor_block(w: np.ndarray, out: np.ndarray) -> None:
    s = w * float(_PHASOR_STEPS)  # exact: a power of two
    m = np.rint(s)
    t = s - m  # exact (the two are within 0.5 of each other)
    t *= -2.0 * np.pi / _PHASOR_STEPS
    t2 = t * t
    c = t2 * (1.0 / 24.0)  # 1 - cos t = t^2/2 - t^4/24
    np.subtract(0.5, c, out=c)
    c *= t2
    np.subtract(1.0, c, out=out.real)
    t2 *= -1.0 / 6.0  # sin t = t - t^3/6
    t2 *= t
    t2 += t
    np.copyto(out.imag, t2)
    idx = m.astype(np.int64)
    idx &= _PHASOR_STEPS - 1  # m modulo 4096 (two's complement for m < 0)
    out *= np.take(_PHASOR_TABLE, idx)


def sub_cell_pupil(pf: PupilFunction, aberrated: bool = True) -> np.ndarray:
    """P = A exp(-2 pi i W) over the sub-cells (:class:`PupilFunction`; cached per pupil), only over the
    box of the lit sub-cells: the rows and columns outside it add nothing to any lag. ``aberrated=False``:
    A alone. W: an edge ray's own OPD in its sub-cell, else the cells' mean OPD bilinearly between the
    lit cells' centres."""
    key = ("P", aberrated)
    if key not in pf._lags:
        lay = _sub_cells(pf._pt)
        if aberrated:
            num = _lerp2(lay["lit"] * pf.opd[lay["box"]], lay["rows"], lay["cols"])
            opd = np.zeros_like(num)
            np.divide(num, lay["den"], out=opd, where=lay["divide"])
            opd[lay["er"], lay["ec"]] = pf._ws.opd_waves[lay["edge"]]
            P = unit_phasors(opd[lay["crop"]])
            P *= lay["A"]
        else:
            P = lay["A"].astype(complex)
        pf._lags[key] = P
    return pf._lags[key]


def max_waves_per_cell(pf: PupilFunction) -> float:
    """Largest OPD change (waves) between neighbouring lit cells."""
    m, w = pf.mask, pf.opd
    worst = 0.0
    for a, b, ma, mb in ((w[:, 1:], w[:, :-1], m[:, 1:], m[:, :-1]), (w[1:], w[:-1], m[1:], m[:-1])):
        both = ma & mb
        if both.any():
            worst = max(worst, float(np.abs(a - b)[both].max()))
    return worst


#: Whole sub-cell lags a pupil sums one by one (a dot product over the overlap each, about 0.1 ms
#: at 700 x 400 sub-cells) before :func:`otf_lags` computes them all by FFT (1.5-4 ms per axis): a
#: chart reads 2 per frequency.
DIRECT_LAGS_MAX = 16


def otf_lags(pf: PupilFunction, axis: int, *, aberrated: bool = True) -> np.ndarray:
    """Normalised OTF at every whole sub-cell shear 0, 1, ... along ``axis`` (0: y, the tangential
    direction of a Y-meridian field; 1: x, sagittal): R[k] = sum P(u) conj(P(u - k)) / sum |P|^2 over
    the sub-cells (Goodman, *Introduction to Fourier Optics*, 6.3.1), every lag at once by FFT
    autocorrelation along the axis (Wiener-Khinchin: the inverse transform of |FFT|^2, zero-padded to
    twice the length so the correlation does not wrap), summed over the other axis. Cached per pupil.
    ``aberrated=False``: the same pupil without its OPD (the diffraction limit of that pupil)."""
    key = (axis, aberrated)
    cache = pf._lags
    if key not in cache:
        P = sub_cell_pupil(pf, aberrated)
        if axis == 1:
            P = P.T
        n, size = P.shape[0], pf.sub_cells_across
        norm = float((np.abs(P) ** 2).sum())
        F = np.fft.fft(P, n=2 * n, axis=0)
        r = np.zeros(size, dtype=complex)  # no overlap past the lit box: 0
        r[:n] = np.fft.ifft((F * F.conj()).sum(axis=1))[:n]
        # r[k] = sum P(u + k) conj(P(u)); the shear convention here is P(u) conj(P(u - k)): the same sum
        cache[key] = r / norm if norm > 0 else np.zeros(size, dtype=complex)
    return cache[key]


def _lag(pf: PupilFunction, k: int, axis: int, aberrated: bool) -> complex:
    """R[k] of :func:`otf_lags` (k < the sub-cells across), summed directly over the overlap of P and
    P shifted by k while a pupil has been asked for few lags, from the FFT of all lags after."""
    full = pf._lags.get((axis, aberrated))
    if full is not None:
        return complex(full[k])
    direct = pf._lags.setdefault(("direct", axis, aberrated), {})
    if k not in direct:
        if len(direct) >= DIRECT_LAGS_MAX:
            return complex(otf_lags(pf, axis, aberrated=aberrated)[k])
        cols = _pupil_by_columns(pf, aberrated)
        norm = pf._lags["norm", aberrated]
        m, n = cols.shape
        if not (norm > 0 and k < (m if axis == 1 else n)):  # past the lit box the shifted pupil does not overlap
            direct[k] = 0j
        elif axis == 1:  # sum P(u + k) conj(P(u)): whole columns k apart, one contiguous block each
            direct[k] = _dot(cols[:m - k], cols[k:]) / norm
        elif 2 * k <= n:  # along each column: the pairs k apart over the whole array, less those across columns
            direct[k] = (_dot(cols.reshape(-1)[:m * n - k], cols.reshape(-1)[k:])
                         - _dot(np.ascontiguousarray(cols[:-1, n - k:]), np.ascontiguousarray(cols[1:, :k]))) / norm
        else:
            rows = pf._lags.get(("rows", aberrated))
            if rows is None:
                rows = pf._lags["rows", aberrated] = np.ascontiguousarray(cols.T)
            direct[k] = _dot(rows[:n - k], rows[k:]) / norm
    return direct[k]


def _pupil_by_columns(pf: PupilFunction, aberrated: bool) -> np.ndarray:
    """The sub-cell pupil's transpose, contiguous: a column of P (one x) per row (cached per pupil,
    with sum |P|^2). P is column-major as made, so this is P's own memory."""
    key = ("columns", aberrated)
    if key not in pf._lags:
        pf._lags[key] = cols = np.ascontiguousarray(sub_cell_pupil(pf, aberrated).T)
        pf._lags["norm", aberrated] = _dot(cols, cols).real
    return pf._lags[key]


#: Values per BLAS dot product in :func:`_dot`: OpenBLAS shares a longer one (over 10 000) among threads,
#: whose waiting cost 14 times the CPU of the sum itself when the caller's BLAS is not limited to one
#: thread (the `physcam` program limits it; a Python caller may not).
_DOT_BLOCK = 8192


def _dot(a: np.ndarray, b: np.ndarray) -> complex:
    """sum conj(a) b over two C-contiguous complex arrays of one shape (BLAS's dot, in blocks)."""
    a, b = a.reshape(-1), b.reshape(-1)
    total = 0j
    for j in range(0, a.size, _DOT_BLOCK):
        total += complex(np.vdot(a[j:j + _DOT_BLOCK], b[j:j + _DOT_BLOCK]))
    return total


def shear_otf(pf: PupilFunction, shift_cells: float, axis: int, *, aberrated: bool = True) -> complex:
    """Normalised OTF at a pupil shear of ``shift_cells`` (>= 0, in cells) along ``axis``: :func:`otf_lags`
    interpolated linearly between whole sub-cell shears (a quarter cell apart, where the OTF is
    smooth: its curvature times (1/4 cell)^2 / 8 is the interpolation error)."""
    size = pf.sub_cells_across  # sub-cells across along the shear
    s = float(shift_cells) * pf.q
    k = int(math.floor(s))
    if k >= size - 1:
        return 0j if k >= size else _lag(pf, size - 1, axis, aberrated) * (k + 1 - s)
    f = s - k
    return (1.0 - f) * _lag(pf, k, axis, aberrated) + f * _lag(pf, k + 1, axis, aberrated)


def cutoff_cells(pf: PupilFunction, axis: int) -> float:
    """Shear (cells) beyond which the pupil no longer overlaps itself along ``axis``: the extent of
    the lit sub-cells along it."""
    return float(_sub_cells(pf._pt)["A"].shape[axis]) / pf.q

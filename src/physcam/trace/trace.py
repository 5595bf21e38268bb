"""Public tracing API: object space to film, and film to scene (camera rays for renderers).

Distances are mm in lens space (z = 0 at the first vertex, +z toward the film;
docs/conventions.md). ``film_z`` is the film plane's z in lens space, i.e. the last vertex z
plus the back focal distance the film sits at.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import InputError, OpticsError, require_finite
from ..lens.prescription import Prescription
from .kernels import get_kernel
from .kernels._layout import set_wavelength
from .rays import CLIPPED, OK, RayBatch
from .tables import PackedTable, packed_table

__all__ = ["DEFAULT_CHUNK", "trace_to_film", "trace_through", "trace_path", "paraxial_image_z", "CameraRays",
           "camera_rays"]

#: Rays per kernel call: bounds the numpy kernel's temporaries (about 40 arrays of this size).
DEFAULT_CHUNK = 1 << 18


def _check_rays(rays) -> RayBatch:
    from ..errors import require_type

    return require_type("rays", rays, RayBatch, "build them with physcam.trace.RayBatch.from_arrays")


def _check_lens(lens) -> Prescription:
    if not isinstance(lens, Prescription):
        raise InputError(f"expected a physcam Prescription, got {type(lens).__name__}")
    return lens


def _is_mono(wl) -> bool:
    """One wavelength the kernels can precompute indices for (else each ray computes its own; a
    wavelength they cannot use, 0, NaN or one whose 1/l^2 overflows, goes that way too and its rays
    are flagged MISSED by the kernel)."""
    n = wl.shape[0]
    if n == 0:
        return False
    if n > 1 and not wl.min() == wl.max():
        return False
    return 1e-100 < float(wl[0]) < 1e100


#: A batch with fewer runs of one wavelength than this is traced run by run: each run takes the
#: one-wavelength path (indices once per surface, not per ray: 13 % faster in the numpy kernel)
MAX_RUNS = 16


def _spans(wl, chunk_size):
    """(start, stop) of the kernel calls for wavelengths ``wl``: runs of one wavelength when there
    are few, else the whole batch; each at most ``chunk_size`` rays."""
    n = wl.shape[0]
    cuts = np.flatnonzero(wl[1:] != wl[:-1]) + 1
    edges = [0, *cuts.tolist(), n] if cuts.size < MAX_RUNS else [0, n]
    for lo, hi in zip(edges[:-1], edges[1:]):
        for a in range(lo, hi, chunk_size):
            yield a, min(hi, a + chunk_size)


def trace_packed(kernel, rays: RayBatch, S, kinds, *, clip, fresnel, end_z, chunk_size=DEFAULT_CHUNK,
                 indexed: bool = False, opl=None):
    """Trace ``rays`` in place through rows of a packed surface table (``kernels._layout.pack``).

    The low-level step under :func:`trace_through`, public for analyses that trace a lens in
    legs (ghost paths reflect between legs). ``kernel`` comes from ``kernels.get_kernel``.
    ``S`` is not modified (a one-wavelength batch gets its indices on a copy), unless ``indexed``
    says its index columns already hold the batch's one wavelength
    (:meth:`physcam.trace.tables.PackedTable.at_wavelength`). ``opl``: a float64 array, one per
    ray, to which each leg's optical path n (p' - p) . d up to each row is added in place (rays
    that stop at a row get no leg for it; the leg to ``end_z`` is not added).
    """
    has_end = end_z is not None
    ez = float(end_z) if has_end else 0.0
    cols = rays.columns()
    for a, b in _spans(rays.wavelength_nm, chunk_size):
        wl = rays.wavelength_nm[a:b]
        mono = _is_mono(wl)
        Sw = S
        if mono and not indexed:
            Sw = np.array(S, dtype=np.float64)
            set_wavelength(Sw, float(wl[0]))
            if S.dtype != np.float64:
                Sw = np.ascontiguousarray(Sw, dtype=S.dtype)
        kernel(*(c[a:b] for c in cols), Sw, kinds, bool(clip), bool(fresnel), ez, has_end, mono,
               None if opl is None else opl[a:b])
    return rays


def _run(kernel, rays: RayBatch, packed: PackedTable, rows, clip: bool, fresnel: bool, end_z, chunk_size):
    """Trace ``rays`` in place through rows ``rows`` (a slice, or None for all) of a cached table
    (one-wavelength indices cached too)."""
    has_end = end_z is not None
    ez = end_z if has_end else 0.0
    n = rays.x.shape[0]
    cols = rays.columns()
    if n <= chunk_size:
        wl = rays.wavelength_nm
        mono = _is_mono(wl)
        S = packed.at_wavelength(wl[0]) if mono else packed.S
        if rows is None:
            kernel(*cols, S, packed.kinds, clip, fresnel, ez, has_end, mono)
        else:
            kernel(*cols, S[rows], packed.kinds[rows], clip, fresnel, ez, has_end, mono)
        return rays
    if rows is None:
        rows = _ALL
    kinds = packed.kinds[rows]
    for a in range(0, n, chunk_size):
        b = min(n, a + chunk_size)
        wl = rays.wavelength_nm[a:b]
        mono = _is_mono(wl)
        S = packed.at_wavelength(wl[0]) if mono else packed.S
        kernel(*(c[a:b] for c in cols), S[rows], kinds, clip, fresnel, ez, has_end, mono)
    return rays


_ALL = slice(None)


def trace_through(
    lens: Prescription,
    rays: RayBatch,
    *,
    reverse: bool = False,
    end_z: float | None = None,
    clip: bool = True,
    fresnel: bool = False,
    coating: str | None = "none",
    stop_semi_diameter: float | None = None,
    aperture=None,
    backend: str = "auto",
    chunk_size: int = DEFAULT_CHUNK,
    in_place: bool = False,
) -> RayBatch:
    """Trace a copy of ``rays`` through every surface (front to back, or back to front when
    ``reverse``), then, if ``end_z`` is given, on to the plane z = ``end_z`` (mm, lens space).

    ``aperture`` (an :class:`~physcam.trace.aperture.Aperture`, seed 002) shapes the stop: rays
    are traced to the stop, masked and weighted there by the aperture density on the stop's
    unit disk, then traced on (a density of the float 1.0, a clear stop, leaves them as they are: a weight of 1
    changes none, and the kernel flags a live ray whose weight is not finite). ``in_place`` traces ``rays``
    itself instead of a copy.
    Rays in float32 (:meth:`RayBatch.astype`) are traced in single precision (docs/ray-tracing.md).
    Returns the rays after the last surface (or on the end plane) with flags and weights.
    """
    if type(lens) is not Prescription:
        _check_lens(lens)
    if type(rays) is not RayBatch:
        _check_rays(rays)
    if chunk_size != DEFAULT_CHUNK and chunk_size < 1:
        raise InputError(f"chunk_size must be >= 1, got {chunk_size}")
    if end_z is not None and not (type(end_z) is float and -1e308 < end_z < 1e308):
        end_z = require_finite("end_z", end_z)
    packed = packed_table(lens, reverse=reverse, stop_semi_diameter=stop_semi_diameter, coating=coating,
                          dtype=rays.x.dtype)
    out = rays if in_place else rays.copy()
    kernel = get_kernel(backend)
    clip = bool(clip)
    fresnel = bool(fresnel)
    if aperture is None:
        return _run(kernel, out, packed, None, clip, fresnel, end_z, chunk_size)
    # trace to the stop, weigh by the aperture shape there, then on through the rest
    k = packed.stop_row
    if k < 0:
        lens.stop_index  # raises LensFileError: no aperture stop to shape
    _run(kernel, out, packed, slice(0, k + 1), clip, fresnel, None, chunk_size)
    rstop = packed.table.semi_diameter[k]
    dens = aperture.density_at(out.x / rstop, out.y / rstop)
    if type(dens) is float and dens == 1.0:  # a clear stop (a probe recording the crossings): the rays as they are
        return _run(kernel, out, packed, slice(k + 1, None), clip, fresnel, end_z, chunk_size)
    live = out.flag == OK
    out.scale_weight(dens[live], live)  # polarisation-blind: scales the s and p halves alike
    blocked = live & ~((dens > 0.0) & np.isfinite(out.weight) & np.isfinite(out.weight_sp))
    out.flag[blocked] = CLIPPED
    out.weight[blocked] = 0.0
    out.weight_sp[blocked] = 0.0
    return _run(kernel, out, packed, slice(k + 1, None), clip, fresnel, end_z, chunk_size)


def trace_path(
    lens: Prescription,
    rays: RayBatch,
    *,
    end_z: float | None = None,
    clip: bool = True,
    stop_semi_diameter: float | None = None,
    backend: str = "numpy",
) -> tuple[np.ndarray, RayBatch]:
    """Trace ``rays`` front to back one surface at a time, keeping every intersection.

    Returns ``(points, rays)``: ``points`` has shape (surfaces + 1 [+ 1 with ``end_z``], n, 3),
    the start and each hit point (a lost ray repeats its last point), and the rays as they
    leave (flags tell which were lost, and :data:`OK` ones went through every surface). For a
    handful of rays (diagrams), not for throughput: the kernel runs once per surface.
    """
    _check_lens(lens)
    _check_rays(rays)
    packed = packed_table(lens, stop_semi_diameter=stop_semi_diameter, dtype=rays.x.dtype)
    kernel = get_kernel(backend)
    out = rays.copy()
    pts = [np.stack([out.x, out.y, out.z], axis=1)]
    for k in range(packed.S.shape[0]):
        _run(kernel, out, packed, slice(k, k + 1), bool(clip), False, None, DEFAULT_CHUNK)
        pts.append(np.stack([out.x, out.y, out.z], axis=1))
    if end_z is not None:
        live = out.flag == OK
        end = out.take(live)
        _run(kernel, end, packed, slice(0, 0), bool(clip), False, require_finite("end_z", end_z), DEFAULT_CHUNK)
        last = pts[-1].copy()
        last[live] = np.stack([end.x, end.y, end.z], axis=1)
        pts.append(last)
    return np.stack(pts), out


def trace_to_film(
    lens: Prescription,
    rays: RayBatch,
    film_z: float | None = None,
    **kwargs,
) -> RayBatch:
    """Trace object-space ``rays`` (z before the first vertex) through ``lens`` to the film plane.

    ``film_z`` (mm, lens space) defaults to the paraxial image plane of an object at infinity at
    the lens's design wavelength. Keyword arguments as :func:`trace_through` (``clip``,
    ``fresnel``, ``coating``, ``stop_semi_diameter``, ``backend``, ``chunk_size``).
    """
    if film_z is None:
        film_z = paraxial_image_z(_check_lens(lens))
    return trace_through(lens, rays, end_z=film_z, **kwargs)


def paraxial_image_z(lens: Prescription, wavelength_nm: float | None = None, *, backend: str = "numpy") -> float:
    """z (mm, lens space) of the paraxial image of an axial object at infinity.

    Found with real rays parallel to the axis at heights h and 2h (h = 1e-3 of the front
    semi-diameter), unclipped; their axis crossings z(h) = z0 + a h^2 + O(h^4) are
    extrapolated to h = 0 (Richardson). Agrees with the paraxial (ABCD) image plane to ~1e-9 mm.
    Raises :class:`OpticsError` for an afocal or diverging lens (no real image).
    """
    _check_lens(lens)
    wl = lens.wavelength_nm if wavelength_nm is None else require_finite("wavelength_nm", wavelength_nm)
    h = 1e-3 * lens.surfaces[0].semi_diameter
    rays = RayBatch.collimated([0.0, 0.0], [h, 2 * h], -1.0, wavelength_nm=wl)
    out = trace_through(lens, rays, clip=False, backend=backend)
    if not out.ok.all() or not (out.M < 0).all():
        raise OpticsError(f"lens {lens.name!r} forms no real image of an axial object at infinity")
    zc = out.z - out.y * out.N / out.M
    return float((4.0 * zc[0] - zc[1]) / 3.0)


@dataclass
class CameraRays:
    """Rays leaving the lens toward the scene, for a renderer.

    ``origin`` and ``direction`` are (n, 3) in physcam camera space (docs/conventions.md: origin
    at the film centre, looking down -Z, +Y up, mm); ``weight`` is the radiometric weight
    (0 for a blocked ray); ``lens_rays`` the same rays in lens space with their flags.
    """

    origin: np.ndarray
    direction: np.ndarray
    weight: np.ndarray
    lens_rays: RayBatch

    @property
    def ok(self) -> np.ndarray:
        return self.lens_rays.flag == OK

    def to_world(self, camera_to_world, mm_per_unit: float = 10.0):
        """(origin, direction) in world space for a renderer: ``camera_to_world`` is a 4x4 matrix in
        USD's row-vector convention (p_world = p_camera @ M, translation in the last row), in world
        units; ``mm_per_unit`` converts camera-space millimetres to them (10 for centimetres).
        Directions are rotated (and renormalised), not translated."""
        m = np.asarray(camera_to_world, dtype=np.float64)
        if m.shape != (4, 4) or not np.isfinite(m).all():
            raise InputError("camera_to_world must be a finite 4x4 matrix")
        mpu = require_finite("mm_per_unit", mm_per_unit)
        if mpu <= 0:
            raise InputError(f"mm_per_unit must be > 0, got {mpu:g}")
        o = self.origin / mpu @ m[:3, :3] + m[3, :3]
        d = self.direction @ m[:3, :3]
        d /= np.linalg.norm(d, axis=1, keepdims=True)
        return o, d


def camera_rays(
    lens: Prescription,
    film_xy,
    pupil_samples,
    film_z: float | None = None,
    *,
    wavelength_nm=None,
    bounds=None,
    aperture=None,
    fresnel: bool = False,
    coating: str | None = "none",
    stop_semi_diameter: float | None = None,
    backend: str = "auto",
    chunk_size: int = DEFAULT_CHUNK,
    precision: str = "double",
) -> CameraRays:
    """Film point + pupil sample -> ray leaving the front of the lens, and its weight.

    ``film_xy`` (n, 2) mm on the film plane z = ``film_z`` (default: paraxial focus at infinity);
    ``pupil_samples`` (n, 2) in [0, 1)^2 pick a point on the rectangle the ray is aimed at on
    the rear vertex plane: ``bounds`` (a :class:`~physcam.trace.pupil_bounds.PupilBounds`, per
    film point) or the rear element's bounding square. ``aperture`` (an
    :class:`~physcam.trace.aperture.Aperture`) masks and weights rays at the stop.

    Weight (pbrt-v4 ``RealisticCamera``): E = T cos^4(theta) A / d^2, with theta the ray's angle
    to the axis at the film, A the sampled rectangle's area and d the film-to-rear-vertex
    distance; T the Fresnel transmittance when ``fresnel``, times the aperture density.
    ``precision="single"`` traces in float32 (renderers' camera rays; error against double in
    docs/ray-tracing.md) and returns float32 arrays.
    """
    _check_lens(lens)
    if precision not in ("double", "single"):
        raise InputError(f"precision must be 'double' or 'single', got {precision!r}")
    fxy = np.atleast_2d(np.asarray(film_xy, dtype=np.float64))
    uv = np.atleast_2d(np.asarray(pupil_samples, dtype=np.float64))
    if fxy.shape[-1] != 2 or uv.shape[-1] != 2:
        raise InputError("film_xy and pupil_samples must have shape (n, 2)")
    fxy, uv = np.broadcast_arrays(fxy, uv)
    if not (np.isfinite(fxy).all() and np.isfinite(uv).all()):
        raise InputError("film_xy and pupil_samples must be finite numbers")
    if film_z is None:
        film_z = paraxial_image_z(lens)
    film_z = require_finite("film_z", film_z)
    z_rear = lens.vertex_z[-1]
    d = film_z - z_rear
    if d <= 0:
        raise InputError(f"the film plane (z = {film_z:g} mm) must lie behind the last vertex (z = {z_rear:g} mm)")
    n = fxy.shape[0]
    if bounds is None:
        r = lens.surfaces[-1].semi_diameter
        x0 = np.full(n, -r)
        x1 = np.full(n, r)
        y0 = np.full(n, -r)
        y1 = np.full(n, r)
    else:
        x0, x1, y0, y1 = bounds.rect_at(fxy[:, 0], fxy[:, 1])
    px = x0 + uv[:, 0] * (x1 - x0)
    py = y0 + uv[:, 1] * (y1 - y0)
    area = (x1 - x0) * (y1 - y0)
    wl = lens.wavelength_nm if wavelength_nm is None else wavelength_nm
    rays = RayBatch.from_columns(fxy[:, 0], fxy[:, 1], np.full(n, film_z), px - fxy[:, 0], py - fxy[:, 1],
                                 np.full(n, -d), wl)
    cos_t = -rays.N
    with np.errstate(over="ignore", invalid="ignore"):
        rays.weight[:] = cos_t**4 * area / (d * d)  # unpolarised at the film: weight_sp stays 0
    # a weight that overflows (a film plane a hair behind the rear vertex) cannot be traced:
    # the kernels flag such a ray MISSED with weight 0
    if precision == "single":
        # start where the ray crosses the rear vertex plane (its aim point, exact), so float32
        # meets the first surface from close by (docs/ray-tracing.md, "Single precision")
        rays.x[:] = px
        rays.y[:] = py
        rays.z[:] = z_rear
        rays = rays.astype(np.float32)

    trace_through(lens, rays, reverse=True, clip=True, fresnel=fresnel, coating=coating,
                  stop_semi_diameter=stop_semi_diameter, aperture=aperture, backend=backend,
                  chunk_size=chunk_size, in_place=True)
    origin = np.stack([rays.x, rays.y, rays.z - film_z], axis=1)
    direction = np.stack([rays.L, rays.M, rays.N], axis=1)
    return CameraRays(origin, direction, rays.weight, rays)
